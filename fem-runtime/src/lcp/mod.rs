//! The discrete variational inequality as a linear complementarity problem, and its
//! solvers (docs/mathematics.md §1):
//!
//! ```text
//! A U − Bᵀ Λ = F,   Λ ≥ 0,   R := B U + C Λ − G ≥ 0,   Λ·R = 0
//! ```
//!
//! `C` is block diagonal: small dense SPD blocks of consecutive constraints (size 1 for
//! P0 multipliers, 3 for P1disc on triangles; [`CouplingBlocks`]). With `C > 0` the
//! multipliers can be eliminated block by block: with `r = G − BU`,
//! `Λ_b = argmin_{Λ≥0} ½ΛᵀC_bΛ − Λᵀr_b` (for a block of size 1, `Λ_k = (G − BU)₊,k / C_k`),
//! and `U` minimizes the convex C¹ function
//! `Φ(U) = ½UᵀAU − FᵀU + Σ_b φ_b(r_b)`, `φ_b(r) = max_{Λ≥0} Λᵀr − ½ΛᵀC_bΛ`
//! (for size 1, `½ r₊² / C_k`), whose gradient is `AU − F − BᵀΛ`.
//! [`semismooth_newton`] is Newton's method on Φ (the primal–dual active set method with
//! `c_k = 1/C_k` per constraint for P0) with an Armijo line search on Φ, so it cannot
//! cycle; the Hessian's pattern and symbolic Cholesky factorization are computed once.
//! [`quadratic_program`] solves the same problem with clarabel as an independent check,
//! and also the plain mixed method (`C = 0`). Every result carries its KKT residual.

mod active_set;
mod blocks;
pub mod cholesky;
pub mod external;
mod factor_tree;
mod newton;
pub mod null_space;
mod qp;
mod recovery;
pub mod woodbury;

pub use active_set::primal_dual_active_set;
use blocks::*;
use newton::*;
pub use newton::{
    semismooth_newton, semismooth_newton_prepared, semismooth_newton_with, NewtonOptions,
    NewtonStep, NewtonWorkspace, StepSolver,
};
pub use qp::quadratic_program;
pub use recovery::recover_multiplier;
use recovery::*;

use crate::error::{Error, Result};
use crate::lcp::cholesky::{
    multiply, refined, residual_compensated, symmetric_gauss_seidel, Cholesky, CholeskyFactor,
};
use crate::lcp::woodbury::{LowRankTerm, WoodburySolver};
use crate::SparseMatrix;
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use std::ops::Range;
use std::sync::OnceLock;
use std::time::Instant;

/// The largest block of `C` the solvers accept: eliminating a block's multipliers
/// enumerates its 2^s faces of the orthant.
pub const MAX_BLOCK: usize = 8;

/// Room for one dense block.
const BLOCK_ENTRIES: usize = MAX_BLOCK * MAX_BLOCK;

/// The rows of `B`, stored flat (one allocation, not one per constraint: a membrane
/// on 524k triangles has 524k rows): row `k` is `b_rows[k]`, its `(column, value)` pairs.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ConstraintRows {
    ptr: Vec<usize>,
    entries: Vec<(usize, f64)>,
}

impl ConstraintRows {
    /// Rows from their start offsets (`ptr`, `m + 1` entries from 0 to `entries.len()`,
    /// nondecreasing) into `entries`.
    pub fn from_flat(ptr: Vec<usize>, entries: Vec<(usize, f64)>) -> Result<Self> {
        let valid = ptr.first() == Some(&0)
            && ptr.last() == Some(&entries.len())
            && ptr.windows(2).all(|w| w[0] <= w[1]);
        if !valid {
            return Err(Error::Input(format!(
                "row offsets of B must run from 0 to {} without decreasing",
                entries.len()
            )));
        }
        Ok(Self { ptr, entries })
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.ptr.len().saturating_sub(1)
    }

    /// Whether there are no rows.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The rows in order.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = &[(usize, f64)]> + Clone + '_ {
        self.ptr.windows(2).map(|w| &self.entries[w[0]..w[1]])
    }

    /// Every entry, row after row.
    pub fn entries(&self) -> &[(usize, f64)] {
        &self.entries
    }

    /// Where each row starts in [`ConstraintRows::entries`] (`len() + 1` offsets).
    pub fn offsets(&self) -> &[usize] {
        &self.ptr
    }
}

impl std::ops::Index<usize> for ConstraintRows {
    type Output = [(usize, f64)];
    fn index(&self, k: usize) -> &[(usize, f64)] {
        &self.entries[self.ptr[k]..self.ptr[k + 1]]
    }
}

impl From<Vec<Vec<(usize, f64)>>> for ConstraintRows {
    fn from(rows: Vec<Vec<(usize, f64)>>) -> Self {
        let mut ptr = Vec::with_capacity(rows.len() + 1);
        ptr.push(0);
        let mut entries = Vec::with_capacity(rows.iter().map(Vec::len).sum());
        for row in rows {
            entries.extend(row);
            ptr.push(entries.len());
        }
        Self { ptr, entries }
    }
}

/// `A U − Bᵀ Λ = F, 0 ≤ Λ ⊥ B U + C Λ − G ≥ 0`.
#[derive(Clone, Debug)]
pub struct Lcp {
    /// The primal matrix `A` (n × n, symmetric).
    pub a: SparseMatrix,
    /// Rows of `B` (m rows): `(column, value)` pairs.
    pub b_rows: ConstraintRows,
    /// Diagonal of `C` (m), ≥ 0.
    pub c: Vec<f64>,
    /// Off-diagonal part of `C` (empty: `C` is diagonal).
    pub c_blocks: CouplingBlocks,
    /// Primal right-hand side (n).
    pub f: Vec<f64>,
    /// Constraint right-hand side (m).
    pub g: Vec<f64>,
    /// `Some` where this process holds one part of an LCP assembled over a partition of
    /// the cells (one MPI rank's share, [`crate::obstacle::Discretization::with_constraints_on`]):
    /// every block is then this part's contribution, the whole LCP the sum over the
    /// processes, and the methods that measure the whole (the KKT and complementarity
    /// residuals, [`Lcp::multiplier_scale`], the rounding estimates) reduce over them.
    pub share: Option<Share>,
    /// Vectors of the primal unknowns (n entries each) on which `A` without its
    /// supports vanishes: an elastic body's rigid motions, restricted to the free
    /// unknowns. Read only by an algebraic multigrid preconditioner (an external solver's
    /// GAMG, `MatSetNearNullSpace`), whose coarse spaces must reproduce them; empty where
    /// its default (the constants) serves. Set by the problem's poser
    /// ([`crate::problem::Problem::near_null_space`]).
    pub near_null_space: Vec<Vec<f64>>,
}

/// How the parts of an LCP held by several processes add up ([`Lcp::share`]): the
/// reductions of the solver that runs them, and `‖A‖∞` of the assembled `A` once that
/// solver has it (the parts' row sums of `|A_r|` only bound it from above: entries of
/// opposite sign from cells on two processes cancel in `A` and not in the bound).
///
/// Each constraint of a multiplier on cells (P0, P1disc) or on boundary edges (P0)
/// lives on one part, complete there: the per-constraint measures are then exact. A
/// constraint split between parts (a P1 multiplier's vertex on two edges) makes the
/// sizes of its terms (`Σ_j |B_kj U_j|`, `‖Bᵀ‖∞`) upper bounds.
#[derive(Clone)]
pub struct Share {
    solver: external::External,
    a_norm: std::sync::Arc<std::sync::OnceLock<f64>>,
}

impl Share {
    /// The share of an LCP whose parts `solver` reduces over.
    pub fn new(solver: external::External) -> Self {
        Self {
            solver,
            a_norm: Default::default(),
        }
    }

    /// The solver whose processes hold the parts.
    pub fn solver(&self) -> external::External {
        self.solver
    }

    /// Records `‖A‖∞` of the assembled `A` (the largest row sum of `|A|`), computed by a
    /// solver that assembled it; a later value is ignored.
    pub fn set_a_norm(&self, norm: f64) {
        let _ = self.a_norm.set(norm);
    }

    /// `values` summed entry by entry over the processes, in place.
    pub fn sum(&self, values: &mut [f64]) {
        self.solver.0.sum(values);
    }

    /// The largest of `value` over the processes.
    pub fn max(&self, value: f64) -> f64 {
        self.solver.0.max(value)
    }
}

impl std::fmt::Debug for Share {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Share({:?}, ‖A‖∞ {:?})", self.solver, self.a_norm.get())
    }
}

/// The off-diagonal part of a block-diagonal `C`: groups of consecutive constraints whose
/// multipliers are coupled (P1disc: the three multipliers of a triangle), each with its
/// dense symmetric block. A constraint in no group is a block of size 1. The default has
/// no groups: `C` is the diagonal [`Lcp::c`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CouplingBlocks {
    /// First constraint of each group, ascending, groups disjoint.
    starts: Vec<usize>,
    /// Size of each group, 2 to [`MAX_BLOCK`].
    sizes: Vec<usize>,
    /// Offset of each group's `s × s` row-major entries in `values`.
    offsets: Vec<usize>,
    /// The entries, zero on the diagonal (the diagonal is `Lcp::c`).
    values: Vec<f64>,
}

impl CouplingBlocks {
    /// No coupling: `C` is diagonal.
    pub fn none() -> Self {
        Self::default()
    }

    /// From the off-diagonal entries `(k, l, C_kl)` of an `m × m` matrix `C` (both `(k, l)`
    /// and `(l, k)`, duplicates summed, diagonal entries ignored): the groups are the
    /// smallest runs of consecutive constraints that no entry couples across. An error
    /// when a group is larger than [`MAX_BLOCK`] (the coupling is not block diagonal with
    /// small blocks), when `C` is not symmetric, or an entry is not finite.
    pub fn from_entries(m: usize, entries: &[(usize, usize, f64)]) -> Result<Self> {
        let mut reach: Vec<usize> = (0..m).collect();
        for &(k, l, v) in entries {
            if k >= m || l >= m {
                return Err(Error::Input(format!(
                    "an entry ({k}, {l}) of C lies outside its {m} constraints"
                )));
            }
            if !v.is_finite() {
                return Err(Error::Input(format!("C_{k},{l} = {v} is not finite")));
            }
            if k != l {
                let (low, high) = (k.min(l), k.max(l));
                reach[low] = reach[low].max(high);
            }
        }
        let mut blocks = Self::default();
        let mut group = vec![usize::MAX; m];
        let mut k = 0;
        while k < m {
            let mut end = reach[k];
            let mut j = k;
            while j <= end {
                end = end.max(reach[j]);
                j += 1;
            }
            let size = end + 1 - k;
            if size > MAX_BLOCK {
                return Err(Error::Input(format!(
                    "C couples constraints {k} to {end}: a block of {size} consecutive multipliers, more than {MAX_BLOCK}; C must be block diagonal with small blocks (the multipliers of one cell)"
                )));
            }
            if size > 1 {
                group[k..=end].fill(blocks.starts.len());
                blocks.starts.push(k);
                blocks.sizes.push(size);
                blocks.offsets.push(blocks.values.len());
                blocks.values.resize(blocks.values.len() + size * size, 0.0);
            }
            k = end + 1;
        }
        for &(k, l, v) in entries {
            if k != l {
                let b = group[k];
                let (s, start) = (blocks.sizes[b], blocks.starts[b]);
                blocks.values[blocks.offsets[b] + (k - start) * s + (l - start)] += v;
            }
        }
        for b in 0..blocks.starts.len() {
            let (s, o) = (blocks.sizes[b], blocks.offsets[b]);
            for i in 0..s {
                for j in 0..i {
                    let (x, y) = (blocks.values[o + i * s + j], blocks.values[o + j * s + i]);
                    if (x - y).abs() > 1e-10 * x.abs().max(y.abs()) {
                        let k = blocks.starts[b];
                        return Err(Error::Input(format!(
                            "C is not symmetric: C_{},{} = {x}, C_{},{} = {y}",
                            k + i,
                            k + j,
                            k + j,
                            k + i
                        )));
                    }
                    let mean = 0.5 * (x + y);
                    blocks.values[o + i * s + j] = mean;
                    blocks.values[o + j * s + i] = mean;
                }
            }
        }
        Ok(blocks)
    }

    /// True when `C` is diagonal.
    pub fn is_empty(&self) -> bool {
        self.starts.is_empty()
    }

    /// The coupled groups as `(first constraint, size)`.
    pub fn groups(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        self.starts.iter().copied().zip(self.sizes.iter().copied())
    }

    /// The coupled groups with their entries: `(first constraint, size, s × s row-major
    /// entries)`, zero on the diagonal (the diagonal is [`Lcp::c`]).
    pub fn blocks(&self) -> impl Iterator<Item = (usize, usize, &[f64])> + '_ {
        self.groups()
            .zip(&self.offsets)
            .map(|((k, s), &o)| (k, s, &self.values[o..o + s * s]))
    }

    /// One past the last constraint of any group (0 without groups).
    fn end(&self) -> usize {
        self.groups().map(|(k, s)| k + s).max().unwrap_or(0)
    }
}

/// The most multipliers [`Lcp::schur_complement`] forms its dense matrix for (4000: 128 MB).
pub const MAX_DENSE_MULTIPLIERS: usize = 4000;

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
    /// Newton steps solved through a low-rank update of the last factorization
    /// ([`crate::lcp::woodbury`]) instead of a new one.
    pub low_rank_updates: usize,
    /// Estimated relative rounding noise of Λ (see [`Lcp::elimination_noise`]); 0 when Λ
    /// comes from a linear solve or the QP's dual.
    pub multiplier_noise: f64,
    /// Newton steps solved by an iterative step solver
    /// ([`semismooth_newton_with`], e.g. multigrid-preconditioned CG).
    pub iterative_steps: usize,
    /// Krylov (CG) iterations over those steps.
    pub krylov_iterations: usize,
}

impl Lcp {
    /// An LCP with a diagonal `C`.
    pub fn new(
        a: SparseMatrix,
        b_rows: impl Into<ConstraintRows>,
        c: Vec<f64>,
        f: Vec<f64>,
        g: Vec<f64>,
    ) -> Self {
        Self {
            a,
            b_rows: b_rows.into(),
            c,
            c_blocks: CouplingBlocks::none(),
            f,
            g,
            share: None,
            near_null_space: Vec::new(),
        }
    }

    /// `v` summed over the processes that hold the parts of this LCP ([`Lcp::share`]);
    /// `v` itself for a whole LCP.
    pub fn whole(&self, mut v: Vec<f64>) -> Vec<f64> {
        if let Some(share) = &self.share {
            share.sum(&mut v);
        }
        v
    }

    /// The largest of `value` over the processes that hold the parts; `value` itself
    /// for a whole LCP.
    pub fn largest(&self, value: f64) -> f64 {
        self.share.as_ref().map_or(value, |share| share.max(value))
    }

    /// Number of primal unknowns.
    pub fn n(&self) -> usize {
        self.f.len()
    }

    /// Number of constraints.
    pub fn m(&self) -> usize {
        self.g.len()
    }

    /// The blocks of `C` in order.
    fn blocks(&self) -> Blocks<'_> {
        Blocks {
            m: self.m(),
            coupling: &self.c_blocks,
            k: 0,
            group: 0,
        }
    }

    /// An error unless the sizes of `A`, `B`, `C`, `F`, `G` fit together: `A` is `n × n`
    /// with `n = F.len()`, `B` has `m = G.len()` rows with columns below `n`, `C` has `m`
    /// diagonal entries and its blocks end by constraint `m`.
    ///
    /// # Errors
    /// [`Error::Input`] naming the sizes that do not fit.
    pub fn check_shapes(&self) -> Result<()> {
        let (n, m) = (self.n(), self.m());
        if self.a.nrows() != n || self.a.ncols() != n {
            return Err(Error::Input(format!(
                "A is {} × {} for {n} primal unknowns",
                self.a.nrows(),
                self.a.ncols()
            )));
        }
        if self.b_rows.len() != m || self.c.len() != m {
            return Err(Error::Input(format!(
                "{} rows of B and {} diagonal entries of C for {m} constraints",
                self.b_rows.len(),
                self.c.len()
            )));
        }
        if self.b_rows.iter().flatten().any(|&(j, _)| j >= n) {
            return Err(Error::Input(format!(
                "B has a column beyond the {n} primal unknowns"
            )));
        }
        if self.c_blocks.end() > m {
            return Err(Error::Input(format!(
                "a block of C ends at constraint {}, beyond the {m} constraints",
                self.c_blocks.end()
            )));
        }
        Ok(())
    }

    /// `B u`.
    ///
    /// # Panics
    /// If `u` is shorter than a column index of `B` (`u.len() < n`); the solvers check
    /// shapes first ([`Lcp::check_shapes`] is run by each of them).
    pub fn b_times(&self, u: &[f64]) -> Vec<f64> {
        self.b_rows
            .iter()
            .map(|row| row.iter().map(|&(j, v)| v * u[j]).sum())
            .collect()
    }

    /// `Bᵀ y` (entries of `y` beyond its length count as 0; the result has length `n`).
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

    /// `C λ` (entries of `λ` beyond its length count as 0).
    pub fn c_times(&self, lambda: &[f64]) -> Vec<f64> {
        self.c_product(lambda, false)
    }

    /// `Σ_l |C_kl λ_l|` per constraint: the size of the terms that make up `(Cλ)_k`, for
    /// judging a constraint residual relative to them.
    pub fn c_times_abs(&self, lambda: &[f64]) -> Vec<f64> {
        self.c_product(lambda, true)
    }

    fn c_product(&self, lambda: &[f64], absolute: bool) -> Vec<f64> {
        let mut out = vec![0.0; self.m()];
        let value = |l: usize| lambda.get(l).copied().unwrap_or(0.0);
        for block in self.blocks() {
            for (i, k) in block.range().enumerate() {
                out[k] = block
                    .range()
                    .enumerate()
                    .map(|(j, l)| {
                        let t = block.entry(&self.c, i, j) * value(l);
                        if absolute {
                            t.abs()
                        } else {
                            t
                        }
                    })
                    .sum();
            }
        }
        out
    }

    /// `‖Bᵀ‖∞`, the largest column sum of `|B|`.
    fn bt_norm(&self) -> f64 {
        let mut column_sums = vec![0.0; self.n()];
        for &(j, v) in self.b_rows.entries() {
            column_sums[j] += v.abs();
        }
        norm_inf(&self.whole(column_sums))
    }

    /// `‖F‖∞` of the whole LCP.
    fn f_norm(&self) -> f64 {
        match &self.share {
            Some(_) => norm_inf(&self.whole(self.f.clone())),
            None => norm_inf(&self.f),
        }
    }

    /// The natural size of a multiplier: `‖F‖∞ / ‖Bᵀ‖∞` (equilibrium `BᵀΛ ~ F`), so that
    /// "λ is zero" is judged against the load, not against λ itself.
    pub fn multiplier_scale(&self) -> f64 {
        KktScales {
            a_norm: 0.0,
            bt_norm: self.bt_norm(),
            f_norm: self.f_norm(),
        }
        .multiplier_scale()
    }

    /// The complementarity part of [`Lcp::kkt_residual`]: `max_k |min(Λ_k/Λ*, r_k)|`
    /// with the infeasibilities `(−Λ_k)₊/Λ*` and `(−r_k)₊` (`Λ*`, `r_k` as there).
    ///
    /// # Panics
    /// If `u.len() != n` or `lambda.len() != m`.
    pub fn complementarity_residual(&self, u: &[f64], lambda: &[f64]) -> f64 {
        assert!(
            u.len() == self.n() && lambda.len() == self.m(),
            "complementarity_residual of (U, Λ) of lengths ({}, {}) for an LCP of ({}, {}) unknowns",
            u.len(),
            lambda.len(),
            self.n(),
            self.m()
        );
        self.complementarity_scaled(u, lambda, &self.kkt_scales())
    }

    /// [`Lcp::complementarity_residual`] with the data norms computed before.
    fn complementarity_scaled(&self, u: &[f64], lambda: &[f64], scales: &KktScales) -> f64 {
        let lambda_norm = norm_inf(lambda).max(scales.multiplier_scale());
        let u_star = if scales.a_norm > 0.0 {
            scales.f_norm / scales.a_norm
        } else {
            0.0
        };
        // each constraint's `B_k U`, `(CΛ)_k`, `G_k` and the sizes of their terms, whole
        // (summed over the parts of a shared LCP)
        let m = self.m();
        let mut sums = Vec::with_capacity(4 * m);
        sums.extend(self.b_rows.iter().map(|row| {
            row.iter()
                .map(|&(j, v)| (v * u[j]).abs() + v.abs() * u_star)
                .sum::<f64>()
        }));
        sums.extend(self.b_times(u));
        sums.extend(self.c_product(lambda, false));
        sums.extend(self.c_product(lambda, true));
        let sums = self.whole(sums);
        let (b_terms, rest) = sums.split_at(m);
        let (bu, rest) = rest.split_at(m);
        let (c_lambda, c_terms) = rest.split_at(m);
        let g: std::borrow::Cow<[f64]> = match &self.share {
            Some(_) => self.whole(self.g.clone()).into(),
            None => (&self.g[..]).into(),
        };
        let mut complementarity = 0.0f64;
        for k in 0..m {
            let terms = b_terms[k] + c_terms[k] + g[k].abs();
            let residual = bu[k] + c_lambda[k] - g[k];
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
        complementarity
    }

    /// The multiplier's Schur complement `S = B A⁻¹ Bᵀ + C` (m × m, dense, symmetric): the
    /// matrix the multiplier sees once the primal unknowns are eliminated. Its smallest
    /// eigenvalue in a norm of the multipliers is the discrete inf-sup constant squared
    /// of the plain method (`C = 0`), lifted by `C` for the stabilized one.
    ///
    /// # Errors
    /// More than [`MAX_DENSE_MULTIPLIERS`] multipliers (the matrix is dense), `A` not
    /// positive definite, and a shared LCP ([`Lcp::share`]).
    pub fn schur_complement(&self) -> Result<nalgebra::DMatrix<f64>> {
        if self.share.is_some() {
            return Err(Error::Input(
                "the Schur complement needs the whole LCP, and this process holds one part of a partitioned assembly: compute it in a native solve".into(),
            ));
        }
        let (n, m) = (self.n(), self.m());
        if m > MAX_DENSE_MULTIPLIERS {
            return Err(Error::Input(format!(
                "the Schur complement B A⁻¹ Bᵀ + C is dense: {m} multipliers are more than {MAX_DENSE_MULTIPLIERS}; take a coarser mesh"
            )));
        }
        let pattern = self
            .a
            .symbolic()
            .to_owned()
            .map_err(|e| Error::LinearSolve(format!("{e:?}")))?;
        let factor = Cholesky::analyse(&pattern)?.factor(&self.a)?;
        // the columns A⁻¹ Bᵀ e_k, then S_kl = B_k · A⁻¹ Bᵀ e_l
        let mut columns = Vec::with_capacity(m);
        for row in self.b_rows.iter() {
            let mut column = vec![0.0; n];
            for &(j, v) in row {
                column[j] += v;
            }
            columns.push(factor.solve(&column)?);
        }
        let mut s = nalgebra::DMatrix::<f64>::zeros(m, m);
        for (k, row) in self.b_rows.iter().enumerate() {
            for (l, column) in columns.iter().enumerate() {
                s[(k, l)] = row.iter().map(|&(j, v)| v * column[j]).sum();
            }
        }
        let mut dense = [0.0; MAX_BLOCK * MAX_BLOCK];
        for block in self.blocks() {
            block.dense(&self.c, &mut dense);
            for i in 0..block.size {
                for j in 0..block.size {
                    s[(block.start + i, block.start + j)] += dense[i * block.size + j];
                }
            }
        }
        // rounding leaves B A⁻¹ Bᵀ a little off symmetric
        Ok((&s + s.transpose()) * 0.5)
    }

    /// The KKT residual of `(u, λ)`, scale-invariant: the largest of
    /// - the normwise backward error of the equilibrium
    ///   `‖AU − BᵀΛ − F‖∞ / (‖A‖∞‖U‖∞ + ‖Bᵀ‖∞‖Λ‖∞ + ‖F‖∞)`,
    /// - the complementarity `max_k |min(Λ_k/Λ*, r_k)|` (`Λ*` the larger of ‖Λ‖∞ and
    ///   [`Lcp::multiplier_scale`]) with the componentwise relative
    ///   constraint residual `r_k = R_k / (Σ_j |B_kj U_j| + Σ_l |C_kl Λ_l| + |G_k| +
    ///   U* Σ_j |B_kj|)` with `U* = ‖F‖∞/‖A‖∞` the displacement scale of the load (without
    ///   that floor a constraint met exactly, `BU = G = 0` with `C = 0`, would be judged
    ///   against the rounding of its own terms and reported as 1),
    /// - the infeasibilities `(−Λ_k)₊/‖Λ‖∞` and `(−r_k)₊`.
    ///
    /// # Panics
    /// If `u.len() != n` or `lambda.len() != m`.
    ///
    /// `∞` (never certified) when `U` or `Λ` has a non-finite entry or a norm overflows.
    pub fn kkt_residual(&self, u: &[f64], lambda: &[f64]) -> f64 {
        assert!(
            u.len() == self.n() && lambda.len() == self.m(),
            "kkt_residual of (U, Λ) of lengths ({}, {}) for an LCP of ({}, {}) unknowns",
            u.len(),
            lambda.len(),
            self.n(),
            self.m()
        );
        match &self.share {
            None => {
                let au = multiply(&self.a, u);
                let btl = self.bt_times(lambda);
                self.kkt_residual_from(u, lambda, &au, &btl, &self.kkt_scales())
            }
            Some(_) => {
                // AU − BᵀΛ − F summed over the parts: the equilibrium of the whole
                let mut equilibrium = multiply(&self.a, u);
                for ((e, b), f) in equilibrium
                    .iter_mut()
                    .zip(self.bt_times(lambda))
                    .zip(&self.f)
                {
                    *e -= b + f;
                }
                let equilibrium = self.whole(equilibrium);
                let zero = vec![0.0; self.n()];
                // with AU the whole residual, BᵀΛ = 0 and F = 0; its complementarity
                // reduces itself
                self.kkt_residual_with_f(u, lambda, &equilibrium, &zero, &zero, &self.kkt_scales())
            }
        }
    }

    /// The norms of the data that [`Lcp::kkt_residual`] scales by; they do not change
    /// during a solve, so an iteration computes them once.
    pub(crate) fn kkt_scales(&self) -> KktScales {
        let a_norm = match &self.share {
            None => row_sum_norm(&self.a),
            Some(share) => match share.a_norm.get() {
                Some(&norm) => norm,
                None => norm_inf(&self.whole(row_sums(&self.a))),
            },
        };
        KktScales {
            a_norm,
            bt_norm: self.bt_norm(),
            f_norm: self.f_norm(),
        }
    }

    /// [`Lcp::kkt_residual`] from `AU`, `BᵀΛ` and the data norms that the caller already
    /// has (Newton computes the first two for its gradient): one pass over `A` fewer, and
    /// two over `B`.
    pub(crate) fn kkt_residual_from(
        &self,
        u: &[f64],
        lambda: &[f64],
        au: &[f64],
        btl: &[f64],
        scales: &KktScales,
    ) -> f64 {
        self.kkt_residual_with_f(u, lambda, au, btl, &self.f, scales)
    }

    /// [`Lcp::kkt_residual_from`] with the right side `f` of the equilibrium given.
    fn kkt_residual_with_f(
        &self,
        u: &[f64],
        lambda: &[f64],
        au: &[f64],
        btl: &[f64],
        f: &[f64],
        scales: &KktScales,
    ) -> f64 {
        debug_assert!(
            u.len() == self.n() && au.len() == self.n() && btl.len() == self.n(),
            "AU and BᵀΛ of U's length"
        );
        debug_assert_eq!(lambda.len(), self.m());
        let KktScales {
            a_norm, bt_norm, ..
        } = *scales;
        let equilibrium: f64 = au
            .iter()
            .zip(btl)
            .zip(f)
            .map(|((a, b), f)| (a - b - f).abs())
            .fold(0.0, f64::max);
        let scale = a_norm * norm_inf(u) + bt_norm * norm_inf(lambda) + scales.f_norm;
        let backward = if scale > 0.0 {
            equilibrium / scale
        } else {
            equilibrium
        };
        let lambda_norm = norm_inf(lambda).max(scales.multiplier_scale());
        let complementarity = self.complementarity_scaled(u, lambda, scales);
        let result = backward.max(complementarity);
        // An overflow in a norm (loads near f64::MAX) turns the relative residuals into
        // 0 / ∞ = 0: a point whose certificate overflowed is not certified.
        // (`f64::max` skips NaN, so a NaN in U or Λ would otherwise vanish from the norms.)
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        if [scale, lambda_norm, a_norm, bt_norm]
            .iter()
            .all(|v| v.is_finite())
            && finite(u)
            && finite(lambda)
        {
            result
        } else {
            f64::INFINITY
        }
    }
}

/// `‖A‖∞`, `‖Bᵀ‖∞` and `‖F‖∞` of an [`Lcp`] ([`Lcp::kkt_scales`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct KktScales {
    a_norm: f64,
    bt_norm: f64,
    f_norm: f64,
}

impl KktScales {
    /// [`Lcp::multiplier_scale`]: `‖F‖∞ / ‖Bᵀ‖∞`, 0 without constraints.
    fn multiplier_scale(&self) -> f64 {
        if self.bt_norm > 0.0 {
            self.f_norm / self.bt_norm
        } else {
            0.0
        }
    }
}

fn norm_inf(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// The Euclidean norm of `v`, scaled by its largest entry so that entries near
/// `f64::MAX` (loads the KKT tests accept) do not overflow the sum of squares; NaN if an
/// entry is NaN.
pub(crate) fn norm2(v: &[f64]) -> f64 {
    if v.iter().any(|x| x.is_nan()) {
        return f64::NAN;
    }
    let largest = norm_inf(v);
    if largest == 0.0 || !largest.is_finite() {
        return largest;
    }
    largest * v.iter().map(|x| (x / largest).powi(2)).sum::<f64>().sqrt()
}

fn row_sum_norm(a: &SparseMatrix) -> f64 {
    norm_inf(&row_sums(a))
}

/// The row sums of `|A|` (`A` symmetric: its column sums).
fn row_sums(a: &SparseMatrix) -> Vec<f64> {
    let (col_ptr, vals) = (a.symbolic().col_ptr(), a.val());
    (0..a.ncols())
        .map(|j| {
            vals[col_ptr[j]..col_ptr[j + 1]]
                .iter()
                .map(|v| v.abs())
                .sum::<f64>()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::Triplet;

    #[test]
    fn the_scaled_euclidean_norm_does_not_overflow() {
        assert_eq!(norm2(&[3.0, 4.0]), 5.0);
        assert_eq!(norm2(&[]), 0.0);
        let big = 1e300;
        assert!((norm2(&[3.0 * big, -4.0 * big]) / (5.0 * big) - 1.0).abs() < 1e-15);
        assert_eq!(norm2(&[1.0, f64::INFINITY]), f64::INFINITY);
        assert!(norm2(&[f64::NAN, f64::INFINITY]).is_nan());
    }

    /// xorshift64*: reproducible data without a dependency.
    struct Random(u64);

    impl Random {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
        }

        /// Uniform on (−1, 1).
        fn symmetric(&mut self) -> f64 {
            2.0 * self.next() - 1.0
        }

        fn index(&mut self, n: usize) -> usize {
            ((self.next() * n as f64) as usize).min(n - 1)
        }
    }

    /// A random SPD `s × s` block `α(LLᵀ + δI)`, row-major.
    fn spd_block(random: &mut Random, s: usize, alpha: f64) -> Vec<f64> {
        let l: Vec<f64> = (0..s * s).map(|_| random.symmetric()).collect();
        let mut c = vec![0.0; s * s];
        for i in 0..s {
            for j in 0..s {
                let llt: f64 = (0..s).map(|k| l[i * s + k] * l[j * s + k]).sum();
                c[i * s + j] = alpha * (llt + if i == j { 0.2 } else { 0.0 });
            }
        }
        c
    }

    fn max_difference(a: &[f64], b: &[f64]) -> f64 {
        a.iter()
            .zip(b)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
    }

    /// A random LCP with blocks of C of sizes 3, 1, 3, 3, 1, 3 and a known solution whose
    /// blocks are fully active, inactive, and partly active (one or two of three), built
    /// backwards from `(U*, Λ*, R*)`: `F = AU* − BᵀΛ*`, `G = BU* + CΛ* − R*`. With A and C
    /// SPD the LCP has exactly this solution.
    fn blocked_lcp(seed: u64) -> (Lcp, Vec<f64>, Vec<f64>) {
        let mut random = Random(seed);
        let n = 40;
        let mut triplets = Vec::new();
        for i in 0..n {
            triplets.push(Triplet::new(i, i, 2.5));
            if i + 1 < n {
                triplets.push(Triplet::new(i, i + 1, -1.0));
                triplets.push(Triplet::new(i + 1, i, -1.0));
            }
        }
        let a = SparseMatrix::try_new_from_triplets(n, n, &triplets).unwrap();
        let sizes = [3, 1, 3, 3, 1, 3];
        // which constraints of each block carry Λ > 0
        let pattern: [&[bool]; 6] = [
            &[true, true, true],
            &[false],
            &[false, true, false],
            &[true, false, true],
            &[true],
            &[false, false, false],
        ];
        let m: usize = sizes.iter().sum();
        let mut c = vec![0.0; m];
        let mut entries = Vec::new();
        let mut lambda = vec![0.0; m];
        let mut gap = vec![0.0; m];
        let mut start = 0;
        for (&s, on) in sizes.iter().zip(pattern) {
            let block = spd_block(&mut random, s, 0.05);
            for i in 0..s {
                for j in 0..s {
                    if i == j {
                        c[start + i] = block[i * s + j];
                    } else {
                        entries.push((start + i, start + j, block[i * s + j]));
                    }
                }
                if on[i] {
                    lambda[start + i] = 0.5 + random.next();
                } else {
                    gap[start + i] = 0.1 + random.next();
                }
            }
            start += s;
        }
        let b_rows: Vec<Vec<(usize, f64)>> = (0..m)
            .map(|_| {
                let mut row: Vec<(usize, f64)> = Vec::new();
                while row.len() < 5 {
                    let j = random.index(n);
                    if row.iter().all(|&(i, _)| i != j) {
                        row.push((j, random.symmetric()));
                    }
                }
                row
            })
            .collect();
        let u: Vec<f64> = (0..n).map(|_| random.symmetric()).collect();
        let mut lcp = Lcp::new(a, b_rows, c, vec![0.0; n], vec![0.0; m]);
        lcp.c_blocks = CouplingBlocks::from_entries(m, &entries).unwrap();
        let au = multiply(&lcp.a, &u);
        let btl = lcp.bt_times(&lambda);
        lcp.f = (0..n).map(|i| au[i] - btl[i]).collect();
        let bu = lcp.b_times(&u);
        let cl = lcp.c_times(&lambda);
        lcp.g = (0..m).map(|k| bu[k] + cl[k] - gap[k]).collect();
        (lcp, u, lambda)
    }

    /// The change of the Newton Hessian between two sets of faces, as `U S Uᵀ`, is the
    /// difference of the two Hessians: blocks of size 1 and 3 whose faces grow, shrink
    /// or change.
    #[test]
    fn the_hessian_change_is_the_difference_of_the_hessians() {
        for seed in 1..8 {
            let (lcp, _, _) = blocked_lcp(seed);
            let hessian = Hessian::new(&lcp).unwrap();
            let mut random = Random(seed + 100);
            let m = lcp.m();
            let before: Vec<bool> = (0..m).map(|_| random.next() < 0.5).collect();
            let after: Vec<bool> = (0..m).map(|_| random.next() < 0.5).collect();
            let (h0, h1) = (hessian.matrix(&lcp, &before), hessian.matrix(&lcp, &after));
            let term = lcp.hessian_change(&before, &after).unwrap();
            let changed = lcp
                .blocks()
                .filter(|b| before[b.range()] != after[b.range()])
                .map(|b| b.size)
                .sum::<usize>();
            assert_eq!(
                term.rank(),
                changed,
                "seed {seed}: one column per changed row"
            );
            for _ in 0..3 {
                let x: Vec<f64> = (0..lcp.n()).map(|_| random.symmetric()).collect();
                let expected = multiply(&h1, &x);
                let h0x = multiply(&h0, &x);
                let update = term.apply(&x).unwrap();
                let scale = max_norm(&expected);
                for i in 0..lcp.n() {
                    assert!(
                        (h0x[i] + update[i] - expected[i]).abs() <= 1e-12 * scale,
                        "seed {seed}, row {i}: {} + {} vs {}",
                        h0x[i],
                        update[i],
                        expected[i]
                    );
                }
            }
        }
    }

    #[test]
    fn coupled_groups_are_found_and_bad_coupling_is_an_error() {
        let (lcp, _, _) = blocked_lcp(7);
        let groups: Vec<(usize, usize)> = lcp.c_blocks.groups().collect();
        assert_eq!(groups, vec![(0, 3), (4, 3), (7, 3), (11, 3)]);
        let sizes: Vec<usize> = lcp.blocks().map(|b| b.size).collect();
        assert_eq!(sizes, vec![3, 1, 3, 3, 1, 3]);
        // coupling across more than MAX_BLOCK constraints is not block diagonal
        let far = CouplingBlocks::from_entries(20, &[(0, 12, 1.0), (12, 0, 1.0)]);
        assert!(far.unwrap_err().to_string().contains("block diagonal"));
        let asymmetric = CouplingBlocks::from_entries(3, &[(0, 1, 1.0), (1, 0, 2.0)]);
        assert!(asymmetric.unwrap_err().to_string().contains("symmetric"));
        let outside = CouplingBlocks::from_entries(3, &[(0, 3, 1.0)]);
        assert!(outside.is_err());
        // a block that is not positive definite is refused by the eliminating solvers
        let mut bad = lcp.clone();
        bad.c_blocks = CouplingBlocks::from_entries(
            bad.m(),
            &[(0, 1, 10.0), (1, 0, 10.0), (0, 2, 0.0), (2, 0, 0.0)],
        )
        .unwrap();
        let error = semismooth_newton(&bad, None, NewtonOptions::default()).unwrap_err();
        assert!(error.to_string().contains("positive definite"), "{error}");
        assert!(quadratic_program(&bad).is_err());
        // groups beyond the constraints
        let mut short = lcp.clone();
        short.c_blocks = CouplingBlocks::from_entries(40, &[(30, 31, 1.0), (31, 30, 1.0)]).unwrap();
        assert!(semismooth_newton(&short, None, NewtonOptions::default()).is_err());
        let _ = short.kkt_residual(&vec![0.0; short.n()], &vec![0.0; short.m()]);
    }

    #[test]
    fn primal_rounding_is_the_rounding_of_the_rows_in_contact_over_their_norm() {
        // u − λ = f, 2u + cλ ≥ g: the stabilized row of a load q = 1e20 pressing onto ψ
        // with G = 2ψ + c·q, so that in contact 2u = 2ψ exactly in exact arithmetic
        let (q, psi, c) = (1e20, 0.05, 1e-4);
        let a = SparseMatrix::try_new_from_triplets(1, 1, &[Triplet::new(0, 0, 1.0)]).unwrap();
        let lcp = Lcp::new(
            a,
            vec![vec![(0, 2.0)]],
            vec![c],
            vec![-q],
            vec![2.0 * psi + c * q],
        );
        let (u, lambda) = ([psi], [psi + q]);
        let expected = f64::EPSILON * (2.0 * psi + c * (psi + q) + (2.0 * psi + c * q)) / 2.0;
        let r = lcp.primal_rounding(&u, &lambda);
        assert!(
            (r - expected).abs() <= 1e-12 * expected,
            "{r} vs {expected}"
        );
        // ~2e4·ε·1e20/2: far beyond ψ, the rows cannot resolve the obstacle
        assert!(r > psi);
        // rows out of contact do not count
        assert_eq!(lcp.primal_rounding(&u, &[0.0]), 0.0);
    }

    #[test]
    fn a_constraint_met_exactly_is_not_judged_against_its_own_rounding() {
        // u − λ = −1 against the wall u ≥ 0 with C = 0 and G = 0: u = 0, λ = 1. A
        // solver's u of 1e-17 meets the constraint to rounding (the plain
        // method's exact patch test reported with a residual of 1); u = 1e-3 does not.
        let a = SparseMatrix::try_new_from_triplets(1, 1, &[Triplet::new(0, 0, 1.0)]).unwrap();
        let lcp = Lcp::new(a, vec![vec![(0, 1.0)]], vec![0.0], vec![-1.0], vec![0.0]);
        let exact = lcp.kkt_residual(&[1e-17], &[1.0 + 1e-17]);
        assert!(exact < 1e-15, "{exact}");
        let open = lcp.kkt_residual(&[1e-3], &[1.0 + 1e-3]);
        assert!(open > 1e-4, "{open}");
    }

    #[test]
    fn a_point_whose_certificate_overflows_or_is_nan_is_not_certified() {
        let (lcp, u, lambda) = blocked_lcp(1);
        assert!(lcp.kkt_residual(&u, &lambda) < 1e-10);
        let mut nan = u.clone();
        nan[0] = f64::NAN;
        assert_eq!(lcp.kkt_residual(&nan, &lambda), f64::INFINITY);
        // a load near f64::MAX: ‖F‖ is finite, but ‖A‖‖U‖ + ‖Bᵀ‖‖Λ‖ + ‖F‖ overflows
        let mut huge = lcp.clone();
        huge.f.iter_mut().for_each(|f| *f = f64::MAX);
        let big = vec![f64::MAX / 2.0; u.len()];
        assert_eq!(huge.kkt_residual(&big, &lambda), f64::INFINITY);
    }

    #[test]
    fn newton_clarabel_and_the_saddle_point_method_agree_on_a_blocked_lcp() {
        for seed in [1, 2, 3, 4] {
            let (lcp, u_exact, lambda_exact) = blocked_lcp(seed);
            let options = NewtonOptions::default();
            let newton = semismooth_newton(&lcp, None, options).unwrap();
            let qp = quadratic_program(&lcp).unwrap();
            let saddle = primal_dual_active_set(&lcp, None, options).unwrap();
            let recovered = recover_multiplier(&lcp, newton.clone(), 1).unwrap();
            let norm = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            assert!(
                max_difference(&newton.u, &u_exact) <= 1e-10 * norm(&u_exact),
                "seed {seed}: Newton U"
            );
            assert!(
                max_difference(&newton.lambda, &lambda_exact) <= 1e-9 * norm(&lambda_exact),
                "seed {seed}: Newton Λ"
            );
            assert!(newton.kkt_residual < 1e-12, "{}", newton.kkt_residual);
            // the generalized Hessian is exact on each face: Newton converges fast
            assert!(
                newton.iterations <= 10,
                "seed {seed}: {}",
                newton.iterations
            );
            for (label, other) in [
                ("clarabel", &qp),
                ("saddle", &saddle),
                ("recovered", &recovered),
            ] {
                assert!(
                    max_difference(&newton.u, &other.u) <= 1e-8 * norm(&newton.u),
                    "seed {seed} {label}: U differs by {}",
                    max_difference(&newton.u, &other.u)
                );
                assert!(
                    max_difference(&newton.lambda, &other.lambda) <= 1e-6 * norm(&newton.lambda),
                    "seed {seed} {label}: Λ differs by {}",
                    max_difference(&newton.lambda, &other.lambda)
                );
            }
            assert!(saddle.kkt_residual < 1e-12, "{}", saddle.kkt_residual);
            assert!(lcp.kkt_residual(&u_exact, &lambda_exact) < 1e-13);
            // a wrong multiplier shows in the residual
            let mut wrong = lambda_exact.clone();
            wrong[1] *= 1.01;
            assert!(lcp.kkt_residual(&u_exact, &wrong) > 1e-4);
            println!(
                "seed {seed}: Newton {} iterations, saddle point {}, clarabel {}",
                newton.iterations, saddle.iterations, qp.iterations
            );
        }
    }

    #[test]
    fn clarabel_solves_tiny_and_huge_data_alike() {
        // The plain method (C = 0): a chain of springs pushed onto a wall at every
        // other node. The LCP is linear in (F, G): the data scaled by s scale (U, Λ) by
        // s. Unscaled, clarabel's absolute tolerances made a load of 1e-12 wrong by 14×
        // and one of 1e50 "dual infeasible" (a plain-method patch test).
        let n = 40;
        let mut triplets = Vec::new();
        for i in 0..n {
            triplets.push(Triplet::new(i, i, 2.0));
            if i + 1 < n {
                triplets.push(Triplet::new(i, i + 1, -1.0));
                triplets.push(Triplet::new(i + 1, i, -1.0));
            }
        }
        let a = SparseMatrix::try_new_from_triplets(n, n, &triplets).unwrap();
        let rows: Vec<Vec<(usize, f64)>> = (0..n).step_by(2).map(|j| vec![(j, -1.0)]).collect();
        let m = rows.len();
        // u_j ≤ ψ_j (−u_j ≥ −ψ_j) under a load pushing up, a curved wall
        let f: Vec<f64> = (0..n).map(|i| 0.01 * (1.0 + (i % 3) as f64)).collect();
        let g: Vec<f64> = (0..m)
            .map(|k| -(0.2 + 0.001 * (k as f64 - 10.0).powi(2)))
            .collect();
        let lcp = Lcp::new(a, rows, vec![0.0; m], f, g);
        let reference = quadratic_program(&lcp).unwrap();
        assert!(reference.kkt_residual < 1e-12, "{}", reference.kkt_residual);
        assert!(reference.lambda.iter().filter(|&&l| l > 0.0).count() > 2);
        let norm = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        for s in [1e-12, 1e50] {
            let mut scaled = lcp.clone();
            scaled.f.iter_mut().for_each(|f| *f *= s);
            scaled.g.iter_mut().for_each(|g| *g *= s);
            let qp = quadratic_program(&scaled).unwrap();
            assert!(qp.kkt_residual < 1e-12, "s = {s}: {}", qp.kkt_residual);
            let expected: Vec<f64> = reference.lambda.iter().map(|l| l * s).collect();
            assert!(
                max_difference(&qp.lambda, &expected) <= 1e-9 * norm(&expected),
                "s = {s}: Λ differs by {}",
                max_difference(&qp.lambda, &expected)
            );
            let expected: Vec<f64> = reference.u.iter().map(|u| u * s).collect();
            assert!(
                max_difference(&qp.u, &expected) <= 1e-9 * norm(&expected),
                "s = {s}"
            );
        }
    }

    /// The block minimizer against projected gradient descent run to convergence, and
    /// against the KKT conditions of the small QP, on random SPD 3 × 3 blocks.
    #[test]
    fn block_minimizer_is_the_minimizer() {
        let mut random = Random(11);
        let s = 3;
        let objective = |c: &[f64], r: &[f64], x: &[f64]| -> f64 {
            (0..s)
                .map(|i| {
                    let cx: f64 = (0..s).map(|j| c[i * s + j] * x[j]).sum();
                    0.5 * x[i] * cx - r[i] * x[i]
                })
                .sum()
        };
        let mut faces_seen = [0usize; 4];
        for _ in 0..2000 {
            let c = spd_block(&mut random, s, 1.0);
            let r: Vec<f64> = (0..s).map(|_| random.symmetric()).collect();
            let (mut lambda, mut active) = (vec![0.0; s], vec![false; s]);
            block_minimizer(&c, s, &r, &mut lambda, &mut active);
            faces_seen[active.iter().filter(|&&a| a).count()] += 1;
            // KKT: Λ ≥ 0, w = CΛ − r ≥ 0, Λ·w = 0
            for i in 0..s {
                let w: f64 = (0..s).map(|j| c[i * s + j] * lambda[j]).sum::<f64>() - r[i];
                assert!(lambda[i] >= 0.0);
                assert!(w >= -1e-12, "dual {w}");
                assert!((lambda[i] * w).abs() < 1e-12, "complementarity");
                if active[i] {
                    assert!(w.abs() < 1e-12, "an active component has dual {w}");
                } else {
                    assert_eq!(lambda[i], 0.0);
                }
            }
            // projected gradient with step 1/L, L ≤ the trace
            let step = 1.0 / (0..s).map(|i| c[i * s + i]).sum::<f64>();
            let mut x = vec![0.0; s];
            for _ in 0..5000 {
                let g: Vec<f64> = (0..s)
                    .map(|i| (0..s).map(|j| c[i * s + j] * x[j]).sum::<f64>() - r[i])
                    .collect();
                for i in 0..s {
                    x[i] = (x[i] - step * g[i]).max(0.0);
                }
            }
            assert!(objective(&c, &r, &lambda) <= objective(&c, &r, &x) + 1e-13);
            let smallest_eigenvalue_bound = 0.2;
            // strong convexity: |Λ − x|² ≤ 2(J(x) − J(Λ))/μ, and PG converged
            assert!(
                max_difference(&lambda, &x) < 1e-6 / smallest_eigenvalue_bound,
                "{lambda:?} vs {x:?}"
            );
        }
        // every kind of face occurred
        assert!(faces_seen.iter().all(|&count| count > 50), "{faces_seen:?}");
    }

    /// With all blocks of size 1 the general code reduces to the P0 formulas.
    #[test]
    fn size_one_blocks_are_the_diagonal_formulas() {
        let (mut lcp, _, _) = blocked_lcp(5);
        lcp.c_blocks = CouplingBlocks::none();
        let u: Vec<f64> = (0..lcp.n()).map(|i| (i as f64 * 0.37).sin()).collect();
        let bu = lcp.b_times(&u);
        let au = multiply(&lcp.a, &u);
        let lambda = lcp.eliminated_multiplier(&bu);
        let mut penalty = 0.0;
        for k in 0..lcp.m() {
            let r = (lcp.g[k] - bu[k]).max(0.0);
            assert_eq!(lambda[k], r / lcp.c[k]);
            penalty += 0.5 * r * r / lcp.c[k];
        }
        let quadratic: f64 = (0..lcp.n())
            .map(|i| 0.5 * u[i] * au[i] - lcp.f[i] * u[i])
            .sum();
        assert!((lcp.merit(&u, &au, &bu) - (quadratic + penalty)).abs() < 1e-14 * penalty.abs());
        assert_eq!(
            lcp.c_times(&lambda),
            (0..lcp.m())
                .map(|k| lcp.c[k] * lambda[k])
                .collect::<Vec<_>>()
        );
    }
}
