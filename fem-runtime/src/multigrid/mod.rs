//! Geometric multigrid on a nested hierarchy, as the preconditioner of conjugate
//! gradients for SPD systems such as the Newton systems `H d = −∇Φ` (issue 15).
//!
//! Given the fine matrix `A₀` and prolongations `P_l` from level `l + 1` (coarser) to
//! level `l` ([`prolongation()`] builds them from the refinement), the coarse operators
//! are Galerkin's `A_{l+1} = P_lᵀ A_l P_l` (so an active-set term of `H` is carried to
//! every level). One cycle on level `l` for `A_l x = b`, from `x = 0`: `ν` symmetric
//! Gauss–Seidel sweeps; `γ` times { `r = b − A_l x`; the cycle on `A_{l+1} e = P_lᵀ r`;
//! `x += P_l e` }; `ν` symmetric Gauss–Seidel sweeps; on the coarsest level a sparse
//! Cholesky solve ([`crate::lcp::cholesky`]). `γ = 1` is the V-cycle, `γ = 2` the
//! W-cycle. With symmetric smoothing before and after, the cycle is a symmetric positive
//! definite operator (Hackbusch, *Multi-Grid Methods and Applications*, 1985, §10.7), so
//! it preconditions CG ([`Multigrid::pcg`]).
//!
//! All vectors of the cycle are allocated once per level when the hierarchy is built;
//! the cycle allocates only in the coarsest solve (one vector of the coarsest order).
//! `docs/multigrid.md` has the formulas and the measured iteration counts: flat on the
//! Laplacian with the V-cycle; on the membrane's Newton Hessian the V-cycle's count
//! grows slowly with the levels and the W-cycle's does not.

mod prolongation;
pub mod sparse;
#[cfg(test)]
mod tests;

pub use prolongation::{parents_by_location, prolongation, NestedLevel};

use crate::error::{Error, Result};
use crate::lcp::cholesky::{Cholesky, CholeskyFactor};
use crate::SparseMatrix;
use std::cell::RefCell;

/// Options of the cycle.
#[derive(Clone, Copy, Debug)]
pub struct MultigridOptions {
    /// Symmetric Gauss–Seidel sweeps (one forward and one backward each) before and
    /// after the coarse correction; at least 1.
    pub sweeps: usize,
    /// Coarse corrections per level, `γ`: 1 for the V-cycle, 2 for the W-cycle (each a
    /// symmetric iteration, so either preconditions CG); at least 1.
    pub coarse_corrections: usize,
}

impl Default for MultigridOptions {
    fn default() -> Self {
        Self {
            sweeps: 1,
            coarse_corrections: 1,
        }
    }
}

/// One level: its operator, `1/diag`, the prolongation from the next coarser level and
/// the cycle's vectors.
struct Level {
    a: SparseMatrix,
    inverse_diagonal: Vec<f64>,
    /// From level `l + 1`; `None` on the coarsest level.
    p: Option<SparseMatrix>,
}

/// The cycle's vectors of one level: right-hand side, iterate and residual.
struct Work {
    b: Vec<f64>,
    x: Vec<f64>,
    r: Vec<f64>,
}

/// A multigrid hierarchy ready to run cycles: the Galerkin operators of every level,
/// the Cholesky factor of the coarsest one and preallocated work vectors.
pub struct Multigrid {
    levels: Vec<Level>,
    coarsest: CholeskyFactor,
    options: MultigridOptions,
    work: RefCell<Vec<Work>>,
}

/// The result of [`Multigrid::pcg`].
#[derive(Clone, Debug)]
pub struct PcgSolution {
    /// The solution.
    pub x: Vec<f64>,
    /// CG iterations (cycles applied).
    pub iterations: usize,
    /// `‖b − A x‖ / ‖b‖` at the end (the recurrence's residual).
    pub relative_residual: f64,
}

impl Multigrid {
    /// Builds the hierarchy of the symmetric positive definite `a` (both triangles
    /// stored) and `prolongations[l]` from level `l + 1` to level `l` (level 0 is `a`'s,
    /// so the list runs from fine to coarse; it may be empty: then one Cholesky solve).
    ///
    /// Errors: a non-square or non-symmetric `a` (beyond 1e-12 relative), a prolongation whose row count is not the order of the
    /// level it maps to, a level whose operator has a diagonal entry missing or not
    /// positive (not SPD), a coarsest operator Cholesky refuses, `sweeps = 0`.
    pub fn new(
        a: SparseMatrix,
        prolongations: Vec<SparseMatrix>,
        options: MultigridOptions,
    ) -> Result<Self> {
        if options.sweeps == 0 || options.coarse_corrections == 0 {
            return Err(Error::Input(format!(
                "multigrid needs at least one smoothing sweep and one coarse correction, given {} and {}",
                options.sweeps, options.coarse_corrections
            )));
        }
        if a.nrows() != a.ncols() {
            return Err(Error::Input(format!(
                "multigrid of a {} × {} matrix (not square)",
                a.nrows(),
                a.ncols()
            )));
        }
        // Gauss–Seidel reads column j as row j
        let asymmetry = crate::lcp::cholesky::asymmetry(&a);
        if asymmetry.is_nan() || asymmetry > 1e-12 {
            return Err(Error::Input(format!(
                "multigrid of a matrix that is not symmetric (largest |A_ij − A_ji| is {asymmetry:e} of its largest entry)"
            )));
        }
        let mut levels = Vec::with_capacity(prolongations.len() + 1);
        let mut a = a;
        for (l, p) in prolongations.into_iter().enumerate() {
            if p.nrows() != a.nrows() {
                return Err(Error::Input(format!(
                    "prolongation {l} has {} rows for a level of order {}",
                    p.nrows(),
                    a.nrows()
                )));
            }
            let coarse = sparse::galerkin(&a, &p);
            let inverse_diagonal = inverse_diagonal(&a, l)?;
            levels.push(Level {
                a,
                inverse_diagonal,
                p: Some(p),
            });
            a = coarse;
        }
        let pattern = a
            .symbolic()
            .to_owned()
            .map_err(|e| Error::LinearSolve(format!("the coarsest pattern: {e:?}")))?;
        let coarsest = Cholesky::analyse(&pattern)?
            .factor_cholesky(&a)
            .map_err(|e| {
                Error::LinearSolve(format!("the coarsest operator (order {}): {e}", a.nrows()))
            })?;
        let inverse_diagonal = inverse_diagonal(&a, levels.len())?;
        levels.push(Level {
            a,
            inverse_diagonal,
            p: None,
        });
        let work = levels
            .iter()
            .map(|level| {
                let n = level.a.nrows();
                Work {
                    b: vec![0.0; n],
                    x: vec![0.0; n],
                    r: vec![0.0; n],
                }
            })
            .collect();
        Ok(Self {
            levels,
            coarsest,
            options,
            work: RefCell::new(work),
        })
    }

    /// Number of levels (prolongations + 1).
    pub fn level_count(&self) -> usize {
        self.levels.len()
    }

    /// The order of each level's operator, fine to coarse.
    pub fn orders(&self) -> Vec<usize> {
        self.levels.iter().map(|l| l.a.nrows()).collect()
    }

    /// The operator of level `l` (0: the fine matrix; then the Galerkin operators).
    pub fn operator(&self, l: usize) -> Option<&SparseMatrix> {
        self.levels.get(l).map(|level| &level.a)
    }

    /// `x = M⁻¹ b`, one cycle (V or W, as the options say) from `x = 0` on the fine level.
    ///
    /// Errors: `b` or `x` not of the fine order, a coarsest solve that is not finite.
    pub fn v_cycle(&self, b: &[f64], x: &mut [f64]) -> Result<()> {
        let n = self.levels[0].a.nrows();
        if b.len() != n || x.len() != n {
            return Err(Error::Input(format!(
                "a multigrid cycle of order {n} given vectors of lengths {} and {}",
                b.len(),
                x.len()
            )));
        }
        let mut work = self.work.borrow_mut();
        work[0].b.copy_from_slice(b);
        self.cycle(0, &mut work)?;
        x.copy_from_slice(&work[0].x);
        Ok(())
    }

    /// The cycle on level `l`, whose vectors are `work[0]` (`work[k]` is level `l + k`).
    fn cycle(&self, l: usize, work: &mut [Work]) -> Result<()> {
        let level = &self.levels[l];
        let (here, below) = work.split_first_mut().expect("a work entry per level");
        let Some(p) = &level.p else {
            here.x = self.coarsest.solve(&here.b)?;
            return Ok(());
        };
        here.x.fill(0.0);
        self.smooth(level, here);
        for _ in 0..self.options.coarse_corrections {
            sparse::multiply_into(&level.a, &here.x, &mut here.r);
            for (r, b) in here.r.iter_mut().zip(&here.b) {
                *r = b - *r;
            }
            sparse::restrict(p, &here.r, &mut below[0].b);
            self.cycle(l + 1, below)?;
            sparse::prolong_add(p, &below[0].x, &mut here.x);
        }
        self.smooth(level, here);
        Ok(())
    }

    fn smooth(&self, level: &Level, w: &mut Work) {
        for _ in 0..self.options.sweeps {
            sparse::gauss_seidel(&level.a, &level.inverse_diagonal, &w.b, &mut w.x, true);
            sparse::gauss_seidel(&level.a, &level.inverse_diagonal, &w.b, &mut w.x, false);
        }
    }

    /// Solves `A x = b` (`A` the fine matrix) by conjugate gradients preconditioned with
    /// one cycle per iteration, from `x = 0`, until `‖b − A x‖ ≤ tolerance ‖b‖` or
    /// `max_iterations`.
    ///
    /// Errors: `b` not of the fine order or not finite, a tolerance not in (0, 1), no
    /// convergence within `max_iterations` (the message gives the residual reached), a
    /// breakdown (`pᵀAp ≤ 0` or `rᵀz ≤ 0`: the matrix or the preconditioner not SPD).
    pub fn pcg(&self, b: &[f64], tolerance: f64, max_iterations: usize) -> Result<PcgSolution> {
        let a = &self.levels[0].a;
        let n = a.nrows();
        if b.len() != n {
            return Err(Error::Input(format!(
                "a right-hand side of length {} for a system of order {n}",
                b.len()
            )));
        }
        if !b.iter().all(|v| v.is_finite()) {
            return Err(Error::Input("the right-hand side is not finite".into()));
        }
        if !(tolerance > 0.0 && tolerance < 1.0) {
            return Err(Error::Input(format!(
                "CG tolerance {tolerance} is not in (0, 1)"
            )));
        }
        let norm_b = norm(b);
        let mut x = vec![0.0; n];
        if norm_b == 0.0 {
            return Ok(PcgSolution {
                x,
                iterations: 0,
                relative_residual: 0.0,
            });
        }
        let mut r = b.to_vec();
        let mut z = vec![0.0; n];
        let mut q = vec![0.0; n];
        self.v_cycle(&r, &mut z)?;
        let mut p = z.clone();
        let mut rz = dot(&r, &z);
        let mut relative = 1.0;
        for iteration in 1..=max_iterations {
            if rz.is_nan() || rz <= 0.0 {
                return Err(Error::LinearSolve(format!(
                    "multigrid-preconditioned CG broke down at iteration {iteration} (rᵀz = {rz:e}: the preconditioner is not positive definite)"
                )));
            }
            sparse::multiply_into(a, &p, &mut q);
            let pq = dot(&p, &q);
            if pq.is_nan() || pq <= 0.0 {
                return Err(Error::LinearSolve(format!(
                    "multigrid-preconditioned CG broke down at iteration {iteration} (pᵀAp = {pq:e}: the matrix is not positive definite)"
                )));
            }
            let alpha = rz / pq;
            for ((xi, ri), (pi, qi)) in x.iter_mut().zip(&mut r).zip(p.iter().zip(&q)) {
                *xi += alpha * pi;
                *ri -= alpha * qi;
            }
            relative = norm(&r) / norm_b;
            if relative <= tolerance {
                return Ok(PcgSolution {
                    x,
                    iterations: iteration,
                    relative_residual: relative,
                });
            }
            self.v_cycle(&r, &mut z)?;
            let rz_next = dot(&r, &z);
            let beta = rz_next / rz;
            rz = rz_next;
            for (pi, zi) in p.iter_mut().zip(&z) {
                *pi = zi + beta * *pi;
            }
        }
        Err(Error::LinearSolve(format!(
            "multigrid-preconditioned CG did not reach the relative residual {tolerance:e} in {max_iterations} iterations (it reached {relative:e})"
        )))
    }
}

/// `1 / A_jj` for every `j`, or an error naming level `l` and the bad entry.
fn inverse_diagonal(a: &SparseMatrix, l: usize) -> Result<Vec<f64>> {
    sparse::diagonal(a)
        .into_iter()
        .enumerate()
        .map(|(j, d)| match d {
            Some(d) if d > 0.0 && d.is_finite() => Ok(1.0 / d),
            _ => Err(Error::Input(format!(
                "multigrid level {l}: diagonal entry {j} is {} (the operator is not SPD)",
                d.map_or("missing".to_string(), |d| d.to_string())
            ))),
        })
        .collect()
}

fn dot(x: &[f64], y: &[f64]) -> f64 {
    x.iter().zip(y).map(|(a, b)| a * b).sum()
}

fn norm(x: &[f64]) -> f64 {
    dot(x, x).sqrt()
}
