//! The discrete variational inequality as a linear complementarity problem, and its
//! solvers (MODELS.md §1):
//!
//! ```text
//! A U − Bᵀ Λ = F,   Λ ≥ 0,   R := B U + C Λ − G ≥ 0,   Λ·R = 0
//! ```
//!
//! With `C` diagonal and positive (P0 multipliers, α > 0), `Λ = C⁻¹(G − B U)₊`, and `U`
//! minimizes the convex C¹ function `Φ(U) = ½UᵀAU − FᵀU + ½ Σ_k (G − BU)²₊,k / C_k`.
//! [`semismooth_newton`] is Newton's method on Φ (the primal–dual active set method with
//! `c_k = 1/C_k` per constraint) with an Armijo line search on Φ, so it cannot cycle;
//! the Hessian's pattern and symbolic Cholesky factorization are computed once.
//! [`quadratic_program`] solves the same problem with clarabel as an independent check,
//! and also the plain mixed method (`C = 0`). Every result carries its KKT residual.

use crate::error::{Error, Result};
use crate::linear_solve::{multiply, Cholesky};
use crate::SparseMatrix;
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use std::time::Instant;

/// `A U − Bᵀ Λ = F, 0 ≤ Λ ⊥ B U + C Λ − G ≥ 0`.
#[derive(Clone, Debug)]
pub struct Lcp {
    /// The primal matrix `A` (n × n, symmetric).
    pub a: SparseMatrix,
    /// Rows of `B` (m rows): `(column, value)` pairs.
    pub b_rows: Vec<Vec<(usize, f64)>>,
    /// Diagonal of `C` (m), ≥ 0.
    pub c: Vec<f64>,
    /// Primal right-hand side (n).
    pub f: Vec<f64>,
    /// Constraint right-hand side (m).
    pub g: Vec<f64>,
}

/// A solution of the LCP with how it was obtained.
#[derive(Clone, Debug)]
pub struct LcpSolution {
    /// Primal unknowns.
    pub u: Vec<f64>,
    /// Multipliers, ≥ 0.
    pub lambda: Vec<f64>,
    /// Iterations of the solver.
    pub iterations: usize,
    /// KKT residual ([`Lcp::kkt_residual`]).
    pub kkt_residual: f64,
    /// Wall time of the solve.
    pub seconds: f64,
    /// Number of numeric factorizations.
    pub factorizations: usize,
    /// Estimated relative rounding noise of Λ (see [`Lcp::elimination_noise`]); 0 when Λ
    /// comes from a linear solve or the QP's dual.
    pub multiplier_noise: f64,
}

impl Lcp {
    /// Number of primal unknowns.
    pub fn n(&self) -> usize {
        self.f.len()
    }

    /// Number of constraints.
    pub fn m(&self) -> usize {
        self.g.len()
    }

    /// `B u`.
    pub fn b_times(&self, u: &[f64]) -> Vec<f64> {
        self.b_rows
            .iter()
            .map(|row| row.iter().map(|&(j, v)| v * u[j]).sum())
            .collect()
    }

    /// `Bᵀ y`.
    pub fn bt_times(&self, y: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.n()];
        for (row, &yk) in self.b_rows.iter().zip(y) {
            if yk != 0.0 {
                for &(j, v) in row {
                    out[j] += v * yk;
                }
            }
        }
        out
    }

    /// The natural size of a multiplier: `‖F‖∞ / ‖Bᵀ‖∞` (equilibrium `BᵀΛ ~ F`), so that
    /// "λ is zero" is judged against the load, not against λ itself.
    pub fn multiplier_scale(&self) -> f64 {
        let mut bt_col_sums = vec![0.0; self.n()];
        for row in &self.b_rows {
            for &(j, v) in row {
                bt_col_sums[j] += v.abs();
            }
        }
        let bt = bt_col_sums.iter().fold(0.0f64, |m, x| m.max(*x));
        let f = self.f.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        if bt > 0.0 {
            f / bt
        } else {
            0.0
        }
    }

    /// The KKT residual of `(u, λ)`, scale-invariant: the largest of
    /// - the normwise backward error of the equilibrium
    ///   `‖AU − BᵀΛ − F‖∞ / (‖A‖∞‖U‖∞ + ‖Bᵀ‖∞‖Λ‖∞ + ‖F‖∞)`,
    /// - the complementarity `max_k |min(Λ_k/Λ*, r_k)|` (`Λ*` the larger of ‖Λ‖∞ and
    ///   [`Lcp::multiplier_scale`]) with the componentwise relative
    ///   constraint residual `r_k = R_k / (Σ_j |B_kj U_j| + C_k|Λ_k| + |G_k|)`,
    /// - the infeasibilities `(−Λ_k)₊/‖Λ‖∞` and `(−r_k)₊`.
    pub fn kkt_residual(&self, u: &[f64], lambda: &[f64]) -> f64 {
        let au = multiply(&self.a, u);
        let btl = self.bt_times(lambda);
        let norm_inf = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let a_norm = row_sum_norm(&self.a);
        let mut bt_col_sums = vec![0.0; self.n()];
        for row in &self.b_rows {
            for &(j, v) in row {
                bt_col_sums[j] += v.abs();
            }
        }
        let bt_norm = norm_inf(&bt_col_sums);
        let equilibrium: f64 = au
            .iter()
            .zip(&btl)
            .zip(&self.f)
            .map(|((a, b), f)| (a - b - f).abs())
            .fold(0.0, f64::max);
        let scale = a_norm * norm_inf(u) + bt_norm * norm_inf(lambda) + norm_inf(&self.f);
        let backward = if scale > 0.0 {
            equilibrium / scale
        } else {
            equilibrium
        };
        let lambda_norm = norm_inf(lambda).max(self.multiplier_scale());
        let mut complementarity = 0.0f64;
        for (k, row) in self.b_rows.iter().enumerate() {
            let terms: f64 = row.iter().map(|&(j, v)| (v * u[j]).abs()).sum::<f64>()
                + (self.c[k] * lambda[k]).abs()
                + self.g[k].abs();
            let bu: f64 = row.iter().map(|&(j, v)| v * u[j]).sum();
            let residual = bu + self.c[k] * lambda[k] - self.g[k];
            let r = if terms > 0.0 {
                residual / terms
            } else {
                residual
            };
            let l = if lambda_norm > 0.0 {
                lambda[k] / lambda_norm
            } else {
                lambda[k]
            };
            complementarity = complementarity.max(l.min(r).abs()).max(-l).max(-r);
        }
        backward.max(complementarity)
    }
}

impl Lcp {
    /// `‖d‖∞ / ‖U‖∞` for the Newton step `d = −H⁻¹∇Φ(U)` at `U`: a forward-error
    /// certificate. The backward error alone cannot certify `U` when `A` is as badly
    /// conditioned as a thin beam's (κ ~ 1e13: a backward error of 1e-11 allows an O(1)
    /// error), and `Λ = C⁻¹(G − BU)₊` loses digits to cancellation when `C ~ αh⁵`; the
    /// step is damped by the `BᵀC⁻¹B` part of `H` and has neither problem. Needs `C > 0`.
    pub fn newton_correction(&self, u: &[f64]) -> Result<f64> {
        if self.c.iter().any(|&c| c.is_nan() || c <= 0.0) {
            return Err(Error::Input("the Newton correction needs C > 0".into()));
        }
        let hessian = Hessian::new(self);
        let bu = self.b_times(u);
        let active: Vec<bool> = (0..self.m()).map(|k| self.g[k] - bu[k] > 0.0).collect();
        let lambda: Vec<f64> = (0..self.m())
            .map(|k| (self.g[k] - bu[k]).max(0.0) / self.c[k])
            .collect();
        let au = multiply(&self.a, u);
        let btl = self.bt_times(&lambda);
        let minus_gradient: Vec<f64> = (0..self.n()).map(|i| self.f[i] + btl[i] - au[i]).collect();
        let h = hessian.matrix(self, &active);
        let d = Cholesky::analyse(&hessian.symbolic)?
            .factor(&h)?
            .solve_refined(&h, &minus_gradient, 2)?;
        let norm = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        Ok(norm(&d) / norm(u).max(f64::MIN_POSITIVE))
    }
}

fn row_sum_norm(a: &SparseMatrix) -> f64 {
    // symmetric: the largest column sum equals the largest row sum
    let (col_ptr, vals) = (a.symbolic().col_ptr(), a.val());
    (0..a.ncols())
        .map(|j| {
            vals[col_ptr[j]..col_ptr[j + 1]]
                .iter()
                .map(|v| v.abs())
                .sum::<f64>()
        })
        .fold(0.0, f64::max)
}

/// Options of the semismooth Newton method.
#[derive(Clone, Copy, Debug)]
pub struct NewtonOptions {
    /// Iteration limit (an error beyond it).
    pub max_iterations: usize,
    /// Rounds of iterative refinement of each linear solve (thin structures need 1–2).
    pub refinement_steps: usize,
    /// KKT residual accepted at convergence.
    pub tolerance: f64,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        Self {
            max_iterations: 200,
            refinement_steps: 1,
            tolerance: 1e-10,
        }
    }
}

/// A sparsity pattern built from the pattern of `A` in the leading block plus extra
/// entries, with the lookup of each entry's position in the value array.
struct Pattern {
    ptr: Vec<usize>,
    idx: Vec<usize>,
}

impl Pattern {
    /// `A`'s pattern in a `size × size` matrix, then `extra(&mut columns)` adds entries.
    fn new(a: &SparseMatrix, size: usize, extra: impl FnOnce(&mut [Vec<usize>])) -> Self {
        let (col_ptr, rows) = (a.symbolic().col_ptr(), a.symbolic().row_idx());
        let mut columns: Vec<Vec<usize>> = vec![Vec::new(); size];
        for (j, column) in columns.iter_mut().enumerate().take(a.ncols()) {
            column.extend_from_slice(&rows[col_ptr[j]..col_ptr[j + 1]]);
        }
        extra(&mut columns);
        let mut ptr = vec![0usize; size + 1];
        let mut idx = Vec::new();
        for (j, column) in columns.iter_mut().enumerate() {
            column.sort_unstable();
            column.dedup();
            idx.extend_from_slice(column);
            ptr[j + 1] = idx.len();
        }
        Self { ptr, idx }
    }

    /// Position of entry `(i, j)` (it must be in the pattern).
    fn position(&self, i: usize, j: usize) -> usize {
        let column = &self.idx[self.ptr[j]..self.ptr[j + 1]];
        self.ptr[j]
            + column
                .binary_search(&i)
                .expect("the entry is in the pattern")
    }

    /// Positions of `A`'s entries, in `A`'s storage order.
    fn positions_of(&self, a: &SparseMatrix) -> Vec<usize> {
        let (col_ptr, rows) = (a.symbolic().col_ptr(), a.symbolic().row_idx());
        (0..a.ncols())
            .flat_map(|j| {
                rows[col_ptr[j]..col_ptr[j + 1]]
                    .iter()
                    .map(move |&i| (i, j))
            })
            .map(|(i, j)| self.position(i, j))
            .collect()
    }

    fn symbolic(self) -> SymbolicSparseColMat<usize> {
        let size = self.ptr.len() - 1;
        SymbolicSparseColMat::new_checked(size, size, self.ptr, None, self.idx)
    }
}

/// A value array for `pattern` holding `A`'s entries at `positions` and zeros elsewhere.
fn values_of_a(
    pattern: &SymbolicSparseColMat<usize>,
    positions: &[usize],
    a: &SparseMatrix,
) -> Vec<f64> {
    let mut values = vec![0.0; pattern.row_idx().len()];
    for (&p, &v) in positions.iter().zip(a.val()) {
        values[p] += v;
    }
    values
}

/// The Hessian `A + Σ_{k active} b_k b_kᵀ / C_k` with a fixed pattern.
struct Hessian {
    symbolic: SymbolicSparseColMat<usize>,
    a_positions: Vec<usize>,
    /// For row k of B, the value positions of its outer product entries (i-major).
    row_positions: Vec<Vec<usize>>,
}

impl Hessian {
    fn new(lcp: &Lcp) -> Self {
        let pattern = Pattern::new(&lcp.a, lcp.n(), |columns| {
            for row in &lcp.b_rows {
                for &(i, _) in row {
                    for &(j, _) in row {
                        columns[j].push(i);
                    }
                }
            }
        });
        let a_positions = pattern.positions_of(&lcp.a);
        let row_positions = lcp
            .b_rows
            .iter()
            .map(|row| {
                row.iter()
                    .flat_map(|&(i, _)| row.iter().map(move |&(j, _)| (i, j)))
                    .map(|(i, j)| pattern.position(i, j))
                    .collect()
            })
            .collect();
        Self {
            symbolic: pattern.symbolic(),
            a_positions,
            row_positions,
        }
    }

    fn matrix(&self, lcp: &Lcp, active: &[bool]) -> SparseMatrix {
        let mut values = values_of_a(&self.symbolic, &self.a_positions, &lcp.a);
        for (k, row) in lcp.b_rows.iter().enumerate() {
            if active[k] {
                let w = 1.0 / lcp.c[k];
                let mut q = 0;
                for &(_, vi) in row {
                    for &(_, vj) in row {
                        values[self.row_positions[k][q]] += w * vi * vj;
                        q += 1;
                    }
                }
            }
        }
        SparseColMat::new(self.symbolic.clone(), values)
    }
}

impl Lcp {
    /// An error unless every `C_k > 0` (Φ and the elimination of Λ need it).
    fn require_positive_c(&self, method: &str) -> Result<()> {
        match self.c.iter().position(|&c| c.is_nan() || c <= 0.0) {
            Some(k) => Err(Error::Input(format!(
                "{method} needs C > 0 (it uses Φ and Λ = C⁻¹(G − BU)₊); C_{k} = {}: α ≤ 0 gives the plain mixed method, solve it with the QP solver",
                self.c[k]
            ))),
            None => Ok(()),
        }
    }

    /// The start vector, or zero.
    fn start_vector(&self, start: Option<&[f64]>) -> Result<Vec<f64>> {
        match start {
            Some(s) if s.len() == self.n() => Ok(s.to_vec()),
            Some(s) => Err(Error::Input(format!(
                "start vector has {} entries, the problem {}",
                s.len(),
                self.n()
            ))),
            None => Ok(vec![0.0; self.n()]),
        }
    }

    /// `Λ = C⁻¹(G − BU)₊` from `bu = BU`.
    pub fn eliminated_multiplier(&self, bu: &[f64]) -> Vec<f64> {
        (0..self.m())
            .map(|k| (self.g[k] - bu[k]).max(0.0) / self.c[k])
            .collect()
    }

    /// The merit function `Φ(U) = ½UᵀAU − FᵀU + ½Σ_k (G − BU)²₊,k / C_k` from `au = AU`, `bu = BU`.
    pub fn merit(&self, u: &[f64], au: &[f64], bu: &[f64]) -> f64 {
        let quadratic: f64 = u
            .iter()
            .zip(au)
            .zip(&self.f)
            .map(|((u, au), f)| 0.5 * u * au - f * u)
            .sum();
        let penalty: f64 = (0..self.m())
            .map(|k| {
                let r = (self.g[k] - bu[k]).max(0.0);
                0.5 * r * r / self.c[k]
            })
            .sum();
        quadratic + penalty
    }

    /// Armijo backtracking on Φ from `u` along `d` (`slope = ∇Φ·d`); Φ is re-evaluated from
    /// the products `AU, Ad, BU, Bd`, so each trial is cheap. The accepted step, if any.
    fn armijo(&self, u: &[f64], au: &[f64], bu: &[f64], d: &[f64], slope: f64) -> Option<f64> {
        let ad = multiply(&self.a, d);
        let bd = self.b_times(d);
        let phi0 = self.merit(u, au, bu);
        let mut step = 1.0;
        for _ in 0..60 {
            let ut: Vec<f64> = u.iter().zip(d).map(|(u, d)| u + step * d).collect();
            let aut: Vec<f64> = au.iter().zip(&ad).map(|(a, b)| a + step * b).collect();
            let but: Vec<f64> = bu.iter().zip(&bd).map(|(a, b)| a + step * b).collect();
            // the last term forgives rounding in Φ itself
            if self.merit(&ut, &aut, &but)
                <= phi0 + 1e-4 * step * slope.min(0.0) + 1e-14 * phi0.abs()
            {
                return Some(step);
            }
            step *= 0.5;
        }
        None
    }
}

fn max_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// Semismooth Newton (primal–dual active set) on Φ with an Armijo line search, from
/// `start` (e.g. the prolonged solution of a coarser mesh) or from zero.
pub fn semismooth_newton(
    lcp: &Lcp,
    start: Option<&[f64]>,
    options: NewtonOptions,
) -> Result<LcpSolution> {
    let clock = Instant::now();
    lcp.require_positive_c("semismooth Newton")?;
    let n = lcp.n();
    let mut u = lcp.start_vector(start)?;
    let hessian = Hessian::new(lcp);
    let cholesky = Cholesky::analyse(&hessian.symbolic)?;
    let done = |u: Vec<f64>, lambda: Vec<f64>, iterations: usize, residual: f64| LcpSolution {
        u,
        lambda,
        iterations,
        kkt_residual: residual,
        seconds: clock.elapsed().as_secs_f64(),
        factorizations: iterations,
        multiplier_noise: lcp.elimination_noise(),
    };
    let mut previous_active: Option<Vec<bool>> = None;
    for iteration in 1..=options.max_iterations {
        let au = multiply(&lcp.a, &u);
        let bu = lcp.b_times(&u);
        let active: Vec<bool> = (0..lcp.m()).map(|k| lcp.g[k] - bu[k] > 0.0).collect();
        let lambda = lcp.eliminated_multiplier(&bu);
        // Converged: the active set did not change over a full step, so u is the exact
        // minimizer of the quadratic that Φ is on this active set.
        if previous_active.as_ref() == Some(&active) {
            let residual = lcp.kkt_residual(&u, &lambda);
            if residual <= options.tolerance {
                return Ok(done(u, lambda, iteration - 1, residual));
            }
        }
        let btl = lcp.bt_times(&lambda);
        let gradient: Vec<f64> = (0..n).map(|i| au[i] - lcp.f[i] - btl[i]).collect();
        let h = hessian.matrix(lcp, &active);
        let factor = cholesky.factor(&h)?;
        let minus_gradient: Vec<f64> = gradient.iter().map(|g| -g).collect();
        let d = factor.solve_refined(&h, &minus_gradient, options.refinement_steps)?;
        let slope: f64 = gradient.iter().zip(&d).map(|(g, d)| g * d).sum();
        let Some(step) = lcp.armijo(&u, &au, &bu, &d, slope) else {
            // No decrease along a Newton direction: at the minimizer up to rounding.
            let residual = lcp.kkt_residual(&u, &lambda);
            if residual <= options.tolerance.max(1e-8) {
                return Ok(done(u, lambda, iteration, residual));
            }
            return Err(Error::NotConverged {
                solver: "semismooth Newton",
                detail: format!(
                    "line search failed at iteration {iteration} with KKT residual {residual:e}"
                ),
            });
        };
        for (u, d) in u.iter_mut().zip(&d) {
            *u += step * d;
        }
        // A full step of rounding size: constraints whose gap CΛ is below the rounding
        // of G − BU (α h⁴ λ ≪ ε|ψ| on fine meshes) may flip forever without moving U.
        if step == 1.0 && max_norm(&d) <= 1e-13 * max_norm(&u) {
            let lambda = lcp.eliminated_multiplier(&lcp.b_times(&u));
            let residual = lcp.kkt_residual(&u, &lambda);
            if residual <= options.tolerance {
                return Ok(done(u, lambda, iteration, residual));
            }
        }
        previous_active = (step == 1.0).then_some(active);
    }
    let lambda = lcp.eliminated_multiplier(&lcp.b_times(&u));
    Err(Error::NotConverged {
        solver: "semismooth Newton",
        detail: format!(
            "{} iterations without a settled active set (KKT residual {:e})",
            options.max_iterations,
            lcp.kkt_residual(&u, &lambda)
        ),
    })
}

impl Lcp {
    /// How many digits `Λ = C⁻¹(G − BU)` loses to cancellation: `ε|G_k| / (C_k Λ*)` at its
    /// worst (Λ* the multiplier scale). Near 1 the eliminated Λ is rounding noise: on fine
    /// meshes `C = αh⁵` falls below the rounding of `G − BU ≈ CΛ`.
    pub fn elimination_noise(&self) -> f64 {
        let scale = self.multiplier_scale().max(f64::MIN_POSITIVE);
        (0..self.m())
            .filter(|&k| self.c[k] > 0.0)
            .map(|k| f64::EPSILON * self.g[k].abs() / (self.c[k] * scale))
            .fold(0.0, f64::max)
    }
}

/// The saddle-point system `[[A, −B̃ᵀ], [−B̃, D]]` of the primal–dual active set method with
/// a fixed pattern: active rows carry `B_k` and `D_kk = −C_k`, inactive rows `Λ_k = 0`
/// (`B̃_k = 0`, `D_kk = −1`), so one symbolic LU serves every iteration.
struct SaddlePoint {
    symbolic: SymbolicSparseColMat<usize>,
    a_positions: Vec<usize>,
    /// For row k of B: positions of (n+k, j) and (j, n+k) per entry, and of (n+k, n+k).
    b_positions: Vec<Vec<(usize, usize)>>,
    diagonal: Vec<usize>,
}

impl SaddlePoint {
    fn new(lcp: &Lcp) -> Self {
        let (n, m) = (lcp.n(), lcp.m());
        let pattern = Pattern::new(&lcp.a, n + m, |columns| {
            for (k, row) in lcp.b_rows.iter().enumerate() {
                for &(j, _) in row {
                    columns[j].push(n + k);
                    columns[n + k].push(j);
                }
                columns[n + k].push(n + k);
            }
        });
        let a_positions = pattern.positions_of(&lcp.a);
        let b_positions = lcp
            .b_rows
            .iter()
            .enumerate()
            .map(|(k, row)| {
                row.iter()
                    .map(|&(j, _)| (pattern.position(n + k, j), pattern.position(j, n + k)))
                    .collect()
            })
            .collect();
        let diagonal = (0..m).map(|k| pattern.position(n + k, n + k)).collect();
        Self {
            symbolic: pattern.symbolic(),
            a_positions,
            b_positions,
            diagonal,
        }
    }

    fn matrix(&self, lcp: &Lcp, active: &[bool]) -> SparseMatrix {
        let mut values = values_of_a(&self.symbolic, &self.a_positions, &lcp.a);
        for (k, row) in lcp.b_rows.iter().enumerate() {
            if active[k] {
                for (&(_, v), &(p, q)) in row.iter().zip(&self.b_positions[k]) {
                    values[p] = -v;
                    values[q] = -v;
                }
                values[self.diagonal[k]] = -lcp.c[k];
            } else {
                // Λ_k = 0, scaled like the row so that the matrix stays balanced
                let scale = row.iter().fold(0.0f64, |m, &(_, v)| m.max(v.abs()));
                values[self.diagonal[k]] = -scale.max(lcp.c[k]).max(f64::MIN_POSITIVE);
            }
        }
        SparseColMat::new(self.symbolic.clone(), values)
    }
}

/// Recovers `(U, Λ)` on the active set `{Λ_k > 0}` of a converged solution from one
/// saddle-point solve, in which Λ comes from the equilibrium instead of
/// `C⁻¹(G − BU)`: on fine meshes, where `C = αh⁵` is below the rounding of `G − BU`, this is the
/// difference between a multiplier and rounding noise. Keeps the solution it was given
/// when the recovered one does not satisfy the KKT conditions as well.
pub fn recover_multiplier(
    lcp: &Lcp,
    solution: LcpSolution,
    refinement_steps: usize,
) -> Result<LcpSolution> {
    let clock = Instant::now();
    let n = lcp.n();
    let active: Vec<bool> = solution.lambda.iter().map(|&l| l > 0.0).collect();
    let saddle = SaddlePoint::new(lcp);
    let k_matrix = saddle.matrix(lcp, &active);
    let factor = crate::linear_solve::LuSolver::analyse(&saddle.symbolic)?.factor(&k_matrix)?;
    let mut rhs = lcp.f.clone();
    rhs.extend((0..lcp.m()).map(|k| if active[k] { -lcp.g[k] } else { 0.0 }));
    let x = factor.solve_refined(&k_matrix, &rhs, refinement_steps)?;
    let u = x[..n].to_vec();
    let lambda: Vec<f64> = x[n..]
        .iter()
        .zip(&active)
        .map(|(&l, &a)| if a { l.max(0.0) } else { 0.0 })
        .collect();
    let residual = lcp.kkt_residual(&u, &lambda);
    // The eliminated Λ's noise is invisible to the (backward-error) residual, so the
    // recovered solution is taken whenever it satisfies the KKT conditions to 1e-8.
    if residual <= 1e-8 {
        Ok(LcpSolution {
            u,
            lambda,
            kkt_residual: residual,
            seconds: solution.seconds + clock.elapsed().as_secs_f64(),
            factorizations: solution.factorizations + 1,
            // the recovery helps, but with κ this large it is no guarantee: keep the estimate
            multiplier_noise: lcp.elimination_noise(),
            ..solution
        })
    } else {
        Ok(solution)
    }
}

/// The primal–dual active set method on the saddle-point system, for when eliminating
/// `Λ = C⁻¹(G − BU)` would lose Λ to cancellation ([`Lcp::elimination_noise`]): Λ is an
/// unknown of each linear solve, computed from the equilibrium. The step in U is the
/// Newton step on Φ for the current active set, globalized by the same Armijo search;
/// after a full step the next active set is `{Λ_k > 0} ∪ {G_k − B_kU > 0}`.
pub fn primal_dual_active_set(
    lcp: &Lcp,
    start: Option<&[f64]>,
    options: NewtonOptions,
) -> Result<LcpSolution> {
    let clock = Instant::now();
    lcp.require_positive_c("the saddle-point active-set method")?;
    let (n, m) = (lcp.n(), lcp.m());
    let mut u = lcp.start_vector(start)?;
    let saddle = SaddlePoint::new(lcp);
    let lu = crate::linear_solve::LuSolver::analyse(&saddle.symbolic)?;
    let bu0 = lcp.b_times(&u);
    let mut active: Vec<bool> = (0..m).map(|k| lcp.g[k] - bu0[k] > 0.0).collect();
    let mut lambda: Vec<f64> = vec![0.0; m];
    let mut two_ago: Option<Vec<bool>> = None;
    for iteration in 1..=options.max_iterations {
        let k_matrix = saddle.matrix(lcp, &active);
        let factor = lu.factor(&k_matrix)?;
        let mut rhs = lcp.f.clone();
        rhs.extend((0..m).map(|k| if active[k] { -lcp.g[k] } else { 0.0 }));
        let x = factor.solve_refined(&k_matrix, &rhs, options.refinement_steps)?;
        let (u_new, lambda_new) = x.split_at(n);
        let d: Vec<f64> = u_new.iter().zip(&u).map(|(a, b)| a - b).collect();
        // Armijo on Φ along d (d is the Newton step of Φ for this active set).
        let au = multiply(&lcp.a, &u);
        let bu = lcp.b_times(&u);
        let btl = lcp.bt_times(&lcp.eliminated_multiplier(&bu));
        let slope: f64 = (0..n).map(|i| (au[i] - lcp.f[i] - btl[i]) * d[i]).sum();
        let step = lcp.armijo(&u, &au, &bu, &d, slope).unwrap_or(0.0);
        // On very fine meshes the cells at the free boundary have gaps below the rounding
        // of G − BU and flip without moving U beyond the solve's own accuracy.
        let small_step = max_norm(&d) <= 1e-10 * max_norm(u_new);
        if step == 1.0 {
            u = u_new.to_vec();
            lambda = lambda_new
                .iter()
                .zip(&active)
                .map(|(&l, &a)| if a { l } else { 0.0 })
                .collect();
            let bu = lcp.b_times(&u);
            let next: Vec<bool> = (0..m)
                .map(|k| {
                    if active[k] {
                        lambda[k] > 0.0
                    } else {
                        lcp.g[k] - bu[k] > 0.0
                    }
                })
                .collect();
            // Converged: the active set reproduces itself (U, Λ solve its equations), or
            // only constraints whose gap is at rounding level keep flipping.
            // A period-2 cycle of cells at the free boundary whose λ and gap are both at
            // rounding level is the same fixed point seen twice.
            let cycling = two_ago.as_ref() == Some(&next);
            // Λ comes from the equilibrium here, so the KKT residual certifies the point
            // whatever the active set still does.
            let certified = lcp
                .kkt_residual(&u, &lambda.iter().map(|l| l.max(0.0)).collect::<Vec<_>>())
                <= options.tolerance;
            if next == active || small_step || cycling || certified {
                let positive: Vec<f64> = lambda.iter().map(|l| l.max(0.0)).collect();
                let residual = lcp.kkt_residual(&u, &positive);
                if residual <= options.tolerance || ((small_step || cycling) && residual <= 1e-8) {
                    return Ok(LcpSolution {
                        u,
                        lambda: positive,
                        iterations: iteration,
                        kkt_residual: residual,
                        seconds: clock.elapsed().as_secs_f64(),
                        factorizations: iteration,
                        multiplier_noise: 0.0,
                    });
                }
            }
            two_ago = Some(std::mem::replace(&mut active, next));
        } else {
            u = u.iter().zip(&d).map(|(u, d)| u + step * d).collect();
            let bu = lcp.b_times(&u);
            active = (0..m).map(|k| lcp.g[k] - bu[k] > 0.0).collect();
        }
    }
    Err(Error::NotConverged {
        solver: "primal–dual active set",
        detail: format!(
            "{} iterations without a settled active set (KKT residual {:e})",
            options.max_iterations,
            lcp.kkt_residual(&u, &lambda.iter().map(|l| l.max(0.0)).collect::<Vec<_>>())
        ),
    })
}

/// The LCP as a convex QP solved by clarabel (an interior-point method independent of
/// the Newton path): `min ½UᵀAU − FᵀU + ½ΛᵀCΛ` over `BU + CΛ ≥ G`. Its KKT conditions
/// are the LCP with `Λ` the constraint's multiplier (for `C > 0` also `Λ = C⁻¹CΛ`, the
/// primal Λ); with `C = 0` it is the plain mixed method `min ½UᵀAU − FᵀU` over `BU ≥ G`.
/// Unlike a formulation with `C⁻¹`, nothing here grows like `h⁻⁵`.
pub fn quadratic_program(lcp: &Lcp) -> Result<LcpSolution> {
    use clarabel::algebra::CscMatrix;
    use clarabel::solver::{
        DefaultSettingsBuilder, DefaultSolver, IPSolver, NonnegativeConeT, SolverStatus,
    };
    let clock = Instant::now();
    let (n, m) = (lcp.n(), lcp.m());
    if lcp.c.iter().any(|&c| c.is_nan() || c < 0.0) {
        return Err(Error::Input("C must be non-negative".into()));
    }
    let with_lambda = lcp.c.iter().any(|&c| c > 0.0);
    let nx = if with_lambda { n + m } else { n };
    // Symmetric Jacobi scaling U = D y (D = diag(A)^{-1/2}) and unit rows: thin beams
    // have diag(A) spread over many decades (t⁻²h⁻¹ against h), which stalls the
    // interior-point method unscaled.
    let (col_ptr, rows, vals) = (
        lcp.a.symbolic().col_ptr(),
        lcp.a.symbolic().row_idx(),
        lcp.a.val(),
    );
    let mut scale = vec![1.0; n];
    for j in 0..n {
        for k in col_ptr[j]..col_ptr[j + 1] {
            if rows[k] == j && vals[k] > 0.0 {
                scale[j] = 1.0 / vals[k].sqrt();
            }
        }
    }
    let row_scale: Vec<f64> = (0..m)
        .map(|k| {
            let largest = lcp.b_rows[k]
                .iter()
                .map(|&(j, v)| (v * scale[j]).abs())
                .fold(lcp.c[k], f64::max);
            if largest > 0.0 {
                1.0 / largest
            } else {
                1.0
            }
        })
        .collect();
    // P: upper triangle of blockdiag(DAD, C)
    let mut p_ptr = vec![0usize];
    let mut p_rows = Vec::new();
    let mut p_vals = Vec::new();
    for j in 0..n {
        for k in col_ptr[j]..col_ptr[j + 1] {
            if rows[k] <= j {
                p_rows.push(rows[k]);
                p_vals.push(scale[rows[k]] * vals[k] * scale[j]);
            }
        }
        p_ptr.push(p_rows.len());
    }
    if with_lambda {
        for k in 0..m {
            p_rows.push(n + k);
            p_vals.push(lcp.c[k]);
            p_ptr.push(p_rows.len());
        }
    }
    let p = CscMatrix::new(nx, nx, p_ptr, p_rows, p_vals);
    let mut q: Vec<f64> = lcp.f.iter().zip(&scale).map(|(f, d)| -f * d).collect();
    q.resize(nx, 0.0);
    // −BU − CΛ + s = −G, s ≥ 0, row k scaled by r_k
    let (mut ti, mut tj, mut tv) = (Vec::new(), Vec::new(), Vec::new());
    for (k, row) in lcp.b_rows.iter().enumerate() {
        for &(j, v) in row {
            ti.push(k);
            tj.push(j);
            tv.push(-v * scale[j] * row_scale[k]);
        }
        if with_lambda {
            ti.push(k);
            tj.push(n + k);
            tv.push(-lcp.c[k] * row_scale[k]);
        }
    }
    let b: Vec<f64> = lcp.g.iter().zip(&row_scale).map(|(g, r)| -g * r).collect();
    let a_c = CscMatrix::new_from_triplets(m, nx, ti, tj, tv);
    let settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .max_iter(400)
        .tol_gap_abs(1e-13)
        .tol_gap_rel(1e-13)
        .tol_feas(1e-13)
        .tol_ktratio(1e-10)
        // The default static regularization (1e-8) perturbs systems whose smallest
        // relative eigenvalue is ~h⁴ (bending) far more than that.
        .static_regularization_constant(1e-15)
        .static_regularization_proportional(f64::EPSILON * f64::EPSILON)
        .iterative_refinement_reltol(1e-15)
        .iterative_refinement_abstol(1e-15)
        .iterative_refinement_max_iter(40)
        .build()
        .map_err(|e| Error::Input(format!("clarabel settings: {e:?}")))?;
    let cones = [NonnegativeConeT(m)];
    let mut solver = DefaultSolver::new(&p, &q, &a_c, &b, &cones, settings)
        .map_err(|e| Error::Input(format!("clarabel rejected the problem: {e:?}")))?;
    solver.solve();
    let status = solver.solution.status;
    if !matches!(status, SolverStatus::Solved | SolverStatus::AlmostSolved) {
        let infeasible = matches!(
            status,
            SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible
        );
        return Err(if infeasible {
            Error::Input("the constraints are infeasible (clarabel found a certificate)".into())
        } else {
            Error::NotConverged {
                solver: "clarabel",
                detail: format!(
                    "status {status:?} after {} iterations",
                    solver.solution.iterations
                ),
            }
        });
    }
    let u: Vec<f64> = solver.solution.x[..n]
        .iter()
        .zip(&scale)
        .map(|(y, d)| y * d)
        .collect();
    // the multiplier of the scaled row k is Λ_k / r_k
    let lambda: Vec<f64> = solver.solution.z[..m]
        .iter()
        .zip(&row_scale)
        .map(|(z, r)| (z * r).max(0.0))
        .collect();
    let mut kkt_residual = lcp.kkt_residual(&u, &lambda);
    if with_lambda {
        // Check the result, not the solver's word (see `Lcp::newton_correction`).
        let correction = lcp.newton_correction(&u)?;
        if correction > 1e-6 {
            return Err(Error::NotConverged {
                solver: "clarabel",
                detail: format!(
                    "it reported {status:?}, but a Newton step from its point changes U by {correction:.1e} (relative): the QP is too ill-conditioned for the interior-point method in double precision at this size"
                ),
            });
        }
        kkt_residual = kkt_residual.max(correction);
    }
    Ok(LcpSolution {
        u,
        lambda,
        iterations: solver.solution.iterations as usize,
        kkt_residual,
        seconds: clock.elapsed().as_secs_f64(),
        factorizations: solver.solution.iterations as usize,
        multiplier_noise: 0.0,
    })
}
