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

pub use prolongation::{parents_by_location, prolongation, reduced_prolongation, NestedLevel};

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
    /// Gauss–Seidel on `a`'s pattern: hybrid (parallel blocks) on large levels.
    smoother: sparse::Smoother,
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
    /// The coarsest operator's symbolic factorization, for refactoring after updates.
    coarsest_analysis: Cholesky,
    /// `P_lᵀ` of every prolongation (row access to `P_l`), built on the first update.
    restrictions: Vec<SparseMatrix>,
    /// The sparse restriction's accumulator, marks and index list (see
    /// [`restrict_sparse`]), sized for level 1 on the first update.
    scratch: (Vec<f64>, Vec<bool>, Vec<usize>),
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
        Self::new_symmetric(a, prolongations, options)
    }

    /// [`Multigrid::new`] without its symmetry check (an `O(nnz log)` pass), for a caller
    /// whose matrices are symmetric by construction (the nodal method's reduced
    /// matrices, which are symmetric when its stiffness matrix is, checked once). The
    /// other checks stay; a non-symmetric `a` gives a non-symmetric cycle.
    pub(crate) fn new_symmetric(
        a: SparseMatrix,
        prolongations: Vec<SparseMatrix>,
        options: MultigridOptions,
    ) -> Result<Self> {
        if options.sweeps == 0 || options.coarse_corrections == 0 || a.nrows() != a.ncols() {
            return Err(Error::Input(format!(
                "multigrid of a {} × {} matrix with {} sweeps and {} coarse corrections",
                a.nrows(),
                a.ncols(),
                options.sweeps,
                options.coarse_corrections
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
                smoother: sparse::Smoother::new(&a),
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
        let coarsest_analysis = Cholesky::analyse(&pattern)?;
        let coarsest = coarsest_analysis.factor_cholesky(&a).map_err(|e| {
            Error::LinearSolve(format!("the coarsest operator (order {}): {e}", a.nrows()))
        })?;
        let inverse_diagonal = inverse_diagonal(&a, levels.len())?;
        levels.push(Level {
            smoother: sparse::Smoother::new(&a),
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
            coarsest_analysis,
            restrictions: Vec::new(),
            scratch: (Vec::new(), Vec::new(), Vec::new()),
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

    /// Adds `Q_l U S Uᵀ Q_lᵀ` to the Galerkin operator of every coarse level `l ≥ 1`
    /// (`Q_l = P_{l−1}ᵀ ⋯ P_0ᵀ`, the restriction from the fine level), i.e. keeps the
    /// coarse operators those of `A₀ + U S Uᵀ` without forming a product: `columns` are
    /// the columns of `U` (sparse, fine indices), `s` the `q × q` matrix `S` (row-major,
    /// `q` columns; its symmetric part is used). For a Newton Hessian `H = A + Bᵀ H_I B`
    /// the columns are a block's rows of `B`, a handful of nonzeros each, and so is each
    /// `Q_l u`. The fine operator is left alone: [`Multigrid::reset_fine`] replaces it
    /// and refactors the coarsest level once all terms are in.
    ///
    /// Errors: `s` not `q × q`, a column entry beyond the fine order, an entry of
    /// `Q_l u (Q_l v)ᵀ` outside level `l`'s pattern (then some levels are updated and
    /// others not: rebuild the hierarchy with [`Multigrid::new`]). For nested Lagrange
    /// spaces a column supported on one fine cell restricts to the DOFs of its ancestor
    /// cell on each level, which the Galerkin pattern couples, so this does not happen.
    pub fn add_coarse_term(&mut self, columns: &[&[(usize, f64)]], s: &[f64]) -> Result<()> {
        let q = columns.len();
        if s.len() != q * q {
            return Err(Error::Input(format!(
                "a term of {q} columns needs {} entries of S, not {}",
                q * q,
                s.len()
            )));
        }
        let n = self.levels[0].a.nrows();
        if let Some(&(i, _)) = columns.iter().flat_map(|c| c.iter()).find(|e| e.0 >= n) {
            return Err(Error::Input(format!(
                "a term with an entry in row {i} for a hierarchy of fine order {n}"
            )));
        }
        if self.levels.len() == 1 || q == 0 {
            return Ok(());
        }
        if self.restrictions.is_empty() {
            self.restrictions = self
                .levels
                .iter()
                .filter_map(|level| level.p.as_ref().map(sparse::transpose))
                .collect();
            let order = self.levels[1].a.nrows();
            self.scratch = (vec![0.0; order], vec![false; order], Vec::new());
        }
        let (dense, seen, touched) = &mut self.scratch;
        // the columns restricted to the level below, in turn
        let mut vectors: Vec<Vec<(usize, f64)>> = columns.iter().map(|c| c.to_vec()).collect();
        for l in 1..self.levels.len() {
            let restriction = &self.restrictions[l - 1];
            for vector in &mut vectors {
                restrict_sparse(restriction, vector, dense, seen, touched);
            }
            let a = &mut self.levels[l].a;
            let (symbolic, values) = a.parts_mut();
            let (col_ptr, rows) = (symbolic.col_ptr(), symbolic.row_idx());
            for (x, u) in vectors.iter().enumerate() {
                for (y, v) in vectors.iter().enumerate() {
                    let w = 0.5 * (s[x * q + y] + s[y * q + x]);
                    if w == 0.0 {
                        continue;
                    }
                    for &(j, vj) in v {
                        let column = &rows[col_ptr[j]..col_ptr[j + 1]];
                        for &(i, ui) in u {
                            let Ok(k) = column.binary_search(&i) else {
                                return Err(Error::Input(format!(
                                    "multigrid level {l}: the update has an entry ({i}, {j}) outside the Galerkin pattern"
                                )));
                            };
                            values[col_ptr[j] + k] += w * ui * vj;
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// Removes the fine DOFs `removed` from the coarse spaces of a hierarchy whose
    /// finest prolongation is truncated (rows of fixed fine DOFs empty, as
    /// `obstacle::nodal::truncated_hierarchy` makes it), without recomputing the Galerkin
    /// products: the truncated multigrid of the nodal method when a few more nodes
    /// become active between two active-set iterations.
    ///
    /// `kept[i]` says whether row `i` of the finest prolongation is in use (false for
    /// the DOFs truncated so far; updated here), and `stiffness` is the matrix whose
    /// entries among kept DOFs the coarse operators were formed from. Removing DOF `i`
    /// subtracts from every coarse level what row `i` of `P₀` contributed:
    /// `Q (e_i a_iᵀ + a_i e_iᵀ − a_ii e_i e_iᵀ) Qᵀ`, `a_i` the column `i` of `stiffness` on
    /// the DOFs still kept (one rank-two term each, [`Multigrid::add_coarse_term`]), and
    /// then empties row `i` of `P₀`. Coarse DOFs left without a kept fine DOF under them
    /// (their Galerkin row is then zero up to rounding) are decoupled with a unit
    /// diagonal: their right-hand side is exactly zero in every cycle, so they stay 0.
    /// A DOF that becomes free again may stay truncated: the cycle is then a weaker,
    /// still symmetric positive definite, preconditioner. Call
    /// [`Multigrid::replace_fine`] afterwards.
    ///
    /// Errors: sizes that do not match the hierarchy; an entry outside a coarse pattern
    /// (see [`Multigrid::add_coarse_term`]; then the hierarchy is partly updated: build a
    /// new one).
    pub(crate) fn truncate_fine(
        &mut self,
        stiffness: &SparseMatrix,
        kept: &mut [bool],
        removed: &[usize],
    ) -> Result<()> {
        let n = self.levels[0].a.nrows();
        if stiffness.nrows() != n || stiffness.ncols() != n || kept.len() != n {
            return Err(Error::Input(format!(
                "truncating a hierarchy of fine order {n} with a {} × {} stiffness and {} flags",
                stiffness.nrows(),
                stiffness.ncols(),
                kept.len()
            )));
        }
        if let Some(&i) = removed.iter().find(|&&i| i >= n) {
            return Err(Error::Input(format!(
                "truncating DOF {i} of a hierarchy of fine order {n}"
            )));
        }
        if self.levels.len() == 1 {
            for &i in removed {
                kept[i] = false;
            }
            return Ok(());
        }
        let (col_ptr, rows, vals) = (
            stiffness.symbolic().col_ptr(),
            stiffness.symbolic().row_idx(),
            stiffness.val(),
        );
        let mut column = Vec::new();
        for &i in removed {
            if !kept[i] {
                continue;
            }
            column.clear();
            let mut diagonal = 0.0;
            for k in col_ptr[i]..col_ptr[i + 1] {
                let j = rows[k];
                // exact zeros are not in the truncated operators' patterns
                if kept[j] && vals[k] != 0.0 {
                    column.push((j, vals[k]));
                    if j == i {
                        diagonal = vals[k];
                    }
                }
            }
            let unit = [(i, 1.0)];
            self.add_coarse_term(&[&unit, &column], &[diagonal, -1.0, -1.0, 0.0])?;
            kept[i] = false;
        }
        let p0 = self.levels[0].p.as_mut().expect("a coarser level");
        let (symbolic, values) = p0.parts_mut();
        for (value, &i) in values.iter_mut().zip(symbolic.row_idx()) {
            if !kept[i] {
                *value = 0.0;
            }
        }
        // and in the cached `P₀ᵀ`, whose columns are the rows of `P₀`
        if let Some(r0) = self.restrictions.first_mut() {
            let (symbolic, values) = r0.parts_mut();
            let col_ptr = symbolic.col_ptr();
            for &i in removed {
                values[col_ptr[i]..col_ptr[i + 1]].fill(0.0);
            }
        }
        // coarse DOFs with no kept fine DOF under them, level by level
        let mut alive = kept.to_vec();
        for l in 0..self.levels.len() - 1 {
            let p = self.levels[l].p.as_ref().expect("not the coarsest level");
            let (p_ptr, p_rows, p_vals) = (p.symbolic().col_ptr(), p.symbolic().row_idx(), p.val());
            let below: Vec<bool> = (0..p.ncols())
                .map(|d| (p_ptr[d]..p_ptr[d + 1]).any(|k| alive[p_rows[k]] && p_vals[k] != 0.0))
                .collect();
            if below.iter().any(|&a| !a) {
                let (symbolic, values) = self.levels[l + 1].a.parts_mut();
                let (a_ptr, a_rows) = (symbolic.col_ptr(), symbolic.row_idx());
                for j in 0..below.len() {
                    for k in a_ptr[j]..a_ptr[j + 1] {
                        let i = a_rows[k];
                        if !below[i] || !below[j] {
                            values[k] = if i == j { 1.0 } else { 0.0 };
                        }
                    }
                }
            }
            alive = below;
        }
        Ok(())
    }

    /// Takes `fine` (same order, any pattern) as the fine operator and recomputes what
    /// depends on the operators, as [`Multigrid::reset_fine`] does: the inverse
    /// diagonals of every level and the coarsest factorization (the smoothers depend on
    /// the order only).
    ///
    /// Errors: `fine` of another order, a one-level hierarchy (its factorization is of
    /// the old pattern), a level whose diagonal is not positive, a
    /// coarsest operator Cholesky refuses. The hierarchy is then unusable; its fine
    /// operator comes back with [`Multigrid::into_fine`].
    pub(crate) fn replace_fine(&mut self, fine: SparseMatrix) -> Result<()> {
        // taken in first, so that `into_fine` gives it back whatever fails below
        let (rows, columns) = (fine.nrows(), fine.ncols());
        let n = std::mem::replace(&mut self.levels[0].a, fine).nrows();
        // one level is a factorization of the old pattern
        if self.levels.len() == 1 || rows != n || columns != n {
            return Err(Error::Input(format!(
                "a fine operator of {rows} × {columns} for a hierarchy of order {n} and {} levels",
                self.levels.len()
            )));
        }
        self.refresh()
    }

    /// Frees the fine operator's values and pattern (an empty matrix of the same order
    /// stays), so that the next one can be built before [`Multigrid::replace_fine`]
    /// without both being held (issue 15, peak memory). No cycle may run until then.
    pub(crate) fn release_fine(&mut self) {
        let n = self.levels[0].a.nrows();
        self.levels[0].a = faer::sparse::SparseColMat::new(
            faer::sparse::SymbolicSparseColMat::new_checked(n, n, vec![0; n + 1], None, Vec::new()),
            Vec::new(),
        );
    }

    /// The fine operator, taken out of the hierarchy.
    pub(crate) fn into_fine(mut self) -> SparseMatrix {
        self.levels.swap_remove(0).a
    }

    /// Replaces the fine operator's values by `fine`'s (the same pattern: a Newton
    /// Hessian of the same LCP), and recomputes what depends on the operators: the
    /// inverse diagonals of every level and the numeric factorization of the coarsest
    /// one (which is tiny). Call it after the [`Multigrid::add_coarse_term`]s of a step.
    ///
    /// Errors: `fine` of another pattern or not symmetric-positive on its diagonal, a
    /// level whose diagonal is not positive, a coarsest operator Cholesky refuses.
    pub fn reset_fine(&mut self, fine: &SparseMatrix) -> Result<()> {
        let level = &mut self.levels[0];
        if fine.symbolic().col_ptr() != level.a.symbolic().col_ptr()
            || fine.symbolic().row_idx() != level.a.symbolic().row_idx()
        {
            return Err(Error::Input(
                "the new fine operator has another sparsity pattern than the hierarchy's".into(),
            ));
        }
        level.a.val_mut().copy_from_slice(fine.val());
        self.refresh()
    }

    /// Recomputes what depends on the operators' values: the inverse diagonals of every
    /// level and the numeric factorization of the coarsest one (its pattern analysed
    /// once, at construction).
    fn refresh(&mut self) -> Result<()> {
        for (l, level) in self.levels.iter_mut().enumerate() {
            level.inverse_diagonal = inverse_diagonal(&level.a, l)?;
        }
        let last = &self.levels[self.levels.len() - 1].a;
        self.coarsest = self.coarsest_analysis.factor_cholesky(last).map_err(|e| {
            Error::LinearSolve(format!(
                "the coarsest operator (order {}): {e}",
                last.nrows()
            ))
        })?;
        Ok(())
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
            // the operators are symmetric (checked by `new`, or by the caller of
            // `new_symmetric`): the row-gather product,
            // parallel on large levels, as is the restriction (bitwise the serial one)
            sparse::multiply_symmetric_into(&level.a, &here.x, &mut here.r);
            for (r, b) in here.r.iter_mut().zip(&here.b) {
                *r = b - *r;
            }
            sparse::restrict_parallel(p, &here.r, &mut below[0].b);
            self.cycle(l + 1, below)?;
            sparse::prolong_add(p, &below[0].x, &mut here.x);
        }
        self.smooth(level, here);
        Ok(())
    }

    fn smooth(&self, level: &Level, w: &mut Work) {
        for _ in 0..self.options.sweeps {
            level
                .smoother
                .symmetric_sweep(&level.a, &level.inverse_diagonal, &w.b, &mut w.x);
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
            sparse::multiply_symmetric_into(a, &p, &mut q);
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

/// `v ← Rv` for a sparse `v` (`(index, value)`, indices distinct) and `R = Pᵀ` stored by
/// columns, through the dense accumulator `dense` (all zero, left so) with its marks
/// `seen` (all false, left so) and the index list `touched`.
fn restrict_sparse(
    restriction: &SparseMatrix,
    v: &mut Vec<(usize, f64)>,
    dense: &mut [f64],
    seen: &mut [bool],
    touched: &mut Vec<usize>,
) {
    let (col_ptr, rows, vals) = (
        restriction.symbolic().col_ptr(),
        restriction.symbolic().row_idx(),
        restriction.val(),
    );
    touched.clear();
    for &(i, vi) in v.iter() {
        for k in col_ptr[i]..col_ptr[i + 1] {
            let j = rows[k];
            if !std::mem::replace(&mut seen[j], true) {
                touched.push(j);
            }
            dense[j] += vals[k] * vi;
        }
    }
    v.clear();
    for &j in touched.iter() {
        seen[j] = false;
        v.push((j, std::mem::take(&mut dense[j])));
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
