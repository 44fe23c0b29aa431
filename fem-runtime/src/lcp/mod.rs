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

pub mod cholesky;
mod factor_tree;
pub mod woodbury;

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

    /// One past the last constraint of any group (0 without groups).
    fn end(&self) -> usize {
        self.groups().map(|(k, s)| k + s).max().unwrap_or(0)
    }
}

/// One diagonal block of `C`: constraints `start..start + size`.
#[derive(Clone, Copy, Debug)]
struct Block<'a> {
    start: usize,
    size: usize,
    /// The group's `size × size` entries (empty for size 1).
    off: &'a [f64],
}

impl Block<'_> {
    fn range(&self) -> Range<usize> {
        self.start..self.start + self.size
    }

    /// `C_{start+i, start+j}` with the diagonal `c`.
    fn entry(&self, c: &[f64], i: usize, j: usize) -> f64 {
        if i == j {
            c.get(self.start + i).copied().unwrap_or(0.0)
        } else {
            self.off[i * self.size + j]
        }
    }

    /// The dense block, row-major, into `out` (`size²` entries).
    fn dense(&self, c: &[f64], out: &mut [f64]) {
        for i in 0..self.size {
            for j in 0..self.size {
                out[i * self.size + j] = self.entry(c, i, j);
            }
        }
    }

    /// The dense block restricted to the constraints `face` (indices within the block).
    fn face(&self, c: &[f64], face: &[usize], out: &mut [f64]) {
        let q = face.len();
        for (a, &i) in face.iter().enumerate() {
            for (b, &j) in face.iter().enumerate() {
                out[a * q + b] = self.entry(c, i, j);
            }
        }
    }
}

/// The blocks of `C` in order, groups of [`CouplingBlocks`] and singletons between them.
struct Blocks<'a> {
    m: usize,
    coupling: &'a CouplingBlocks,
    k: usize,
    group: usize,
}

impl<'a> Iterator for Blocks<'a> {
    type Item = Block<'a>;

    fn next(&mut self) -> Option<Block<'a>> {
        if self.k >= self.m {
            return None;
        }
        let cb = self.coupling;
        if self.group < cb.starts.len() && cb.starts[self.group] == self.k {
            let (s, o) = (cb.sizes[self.group], cb.offsets[self.group]);
            self.group += 1;
            // a group past the last constraint (rejected by `Lcp::check_shapes`) is
            // skipped rather than read out of bounds
            if self.k + s <= self.m {
                let block = Block {
                    start: self.k,
                    size: s,
                    off: &cb.values[o..o + s * s],
                };
                self.k += s;
                return Some(block);
            }
        }
        let block = Block {
            start: self.k,
            size: 1,
            off: &[],
        };
        self.k += 1;
        Some(block)
    }
}

/// In-place Cholesky factorization `a = L Lᵀ` of an `n × n` row-major matrix (L in the
/// lower triangle); false when a pivot is not positive.
fn small_cholesky(a: &mut [f64], n: usize) -> bool {
    for j in 0..n {
        let mut d = a[j * n + j];
        for k in 0..j {
            d -= a[j * n + k] * a[j * n + k];
        }
        if d.is_nan() || d <= 0.0 {
            return false;
        }
        let d = d.sqrt();
        a[j * n + j] = d;
        for i in j + 1..n {
            let mut s = a[i * n + j];
            for k in 0..j {
                s -= a[i * n + k] * a[j * n + k];
            }
            a[i * n + j] = s / d;
        }
    }
    true
}

/// Solves `L Lᵀ x = b` in place (`l` from [`small_cholesky`]).
fn small_solve(l: &[f64], n: usize, x: &mut [f64]) {
    for i in 0..n {
        let mut s = x[i];
        for k in 0..i {
            s -= l[i * n + k] * x[k];
        }
        x[i] = s / l[i * n + i];
    }
    for i in (0..n).rev() {
        let mut s = x[i];
        for k in i + 1..n {
            s -= l[k * n + i] * x[k];
        }
        x[i] = s / l[i * n + i];
    }
}

/// The inverse of an SPD `n × n` row-major matrix into `out`; false if it is not SPD.
fn small_inverse(a: &[f64], n: usize, out: &mut [f64]) -> bool {
    let mut l = [0.0; BLOCK_ENTRIES];
    l[..n * n].copy_from_slice(&a[..n * n]);
    if !small_cholesky(&mut l, n) {
        return false;
    }
    let mut x = [0.0; MAX_BLOCK];
    for j in 0..n {
        x[..n].fill(0.0);
        x[j] = 1.0;
        small_solve(&l, n, &mut x[..n]);
        for i in 0..n {
            out[i * n + j] = x[i];
        }
    }
    true
}

/// On the face `mask` of the orthant (the components in `mask` free, the others zero):
/// `x` with `C_II x_I = r_I`, and how far it is from the minimizer's KKT conditions
/// (`x_I ≥ 0` and `(Cx − r)_j ≥ 0` off I) in units of r; `None` if `C_II` is singular.
fn face_point(c: &[f64], s: usize, r: &[f64], mask: usize, x: &mut [f64]) -> Option<f64> {
    let mut face = [0usize; MAX_BLOCK];
    let q = (0..s).filter(|i| mask >> i & 1 == 1).fold(0, |q, i| {
        face[q] = i;
        q + 1
    });
    let mut l = [0.0; BLOCK_ENTRIES];
    for a in 0..q {
        for b in 0..q {
            l[a * q + b] = c[face[a] * s + face[b]];
        }
    }
    let mut y = [0.0; MAX_BLOCK];
    for a in 0..q {
        y[a] = r[face[a]];
    }
    if q > 0 {
        if !small_cholesky(&mut l, q) {
            return None;
        }
        small_solve(&l, q, &mut y[..q]);
    }
    x[..s].fill(0.0);
    let mut violation = 0.0f64;
    for a in 0..q {
        x[face[a]] = y[a];
        violation = violation.max(-y[a] * c[face[a] * s + face[a]]);
    }
    for j in (0..s).filter(|j| mask >> j & 1 == 0) {
        let dual: f64 = (0..q).map(|a| c[j * s + face[a]] * y[a]).sum::<f64>() - r[j];
        violation = violation.max(-dual);
    }
    Some(violation)
}

/// `Λ = argmin_{Λ≥0} ½ΛᵀCΛ − Λᵀr` for one SPD block `c` (`s × s`, row-major) and the
/// face it lies on (`active`: the components solved for). The faces are tried from the
/// smallest: on face I, `C_II Λ_I = r_I`, and the minimizer is the face point with
/// `Λ_I ≥ 0` and `(CΛ − r)_j ≥ 0` off I (the KKT conditions, which single out the unique
/// minimizer of a strictly convex QP). Rounding can leave no face exactly feasible at a
/// kink: then the least violating one, clipped to `Λ ≥ 0`.
fn block_minimizer(c: &[f64], s: usize, r: &[f64], lambda: &mut [f64], active: &mut [bool]) {
    let mut x = [0.0; MAX_BLOCK];
    let mut best = (f64::INFINITY, 0usize);
    'search: for count in 0..=s {
        for mask in (0..1usize << s).filter(|m| m.count_ones() as usize == count) {
            if let Some(violation) = face_point(c, s, r, mask, &mut x) {
                if violation <= 0.0 {
                    best = (violation, mask);
                    break 'search;
                }
                if violation < best.0 {
                    best = (violation, mask);
                }
            }
        }
    }
    if face_point(c, s, r, best.1, &mut x).is_none() {
        x[..s].fill(0.0);
    }
    for i in 0..s {
        lambda[i] = x[i].max(0.0);
        active[i] = best.1 >> i & 1 == 1;
    }
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
    /// Newton steps solved through a low-rank update of the last factorization
    /// ([`crate::lcp::woodbury`]) instead of a new one.
    pub low_rank_updates: usize,
    /// Estimated relative rounding noise of Λ (see [`Lcp::elimination_noise`]); 0 when Λ
    /// comes from a linear solve or the QP's dual.
    pub multiplier_noise: f64,
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
        }
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

    /// An error unless the sizes of `A`, `B`, `C`, `F`, `G` fit together.
    fn check_shapes(&self) -> Result<()> {
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
        column_sums.iter().fold(0.0f64, |m, x| m.max(*x))
    }

    /// The natural size of a multiplier: `‖F‖∞ / ‖Bᵀ‖∞` (equilibrium `BᵀΛ ~ F`), so that
    /// "λ is zero" is judged against the load, not against λ itself.
    pub fn multiplier_scale(&self) -> f64 {
        let bt = self.bt_norm();
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
    ///   constraint residual `r_k = R_k / (Σ_j |B_kj U_j| + Σ_l |C_kl Λ_l| + |G_k|)`,
    /// - the infeasibilities `(−Λ_k)₊/‖Λ‖∞` and `(−r_k)₊`.
    pub fn kkt_residual(&self, u: &[f64], lambda: &[f64]) -> f64 {
        let au = multiply(&self.a, u);
        let btl = self.bt_times(lambda);
        let norm_inf = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let a_norm = row_sum_norm(&self.a);
        let bt_norm = self.bt_norm();
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
        let c_lambda = self.c_times(lambda);
        let c_terms = self.c_times_abs(lambda);
        let mut complementarity = 0.0f64;
        for (k, row) in self.b_rows.iter().enumerate() {
            let terms: f64 = row.iter().map(|&(j, v)| (v * u[j]).abs()).sum::<f64>()
                + c_terms[k]
                + self.g[k].abs();
            let bu: f64 = row.iter().map(|&(j, v)| v * u[j]).sum();
            let residual = bu + c_lambda[k] - self.g[k];
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
    /// error), and the eliminated Λ loses digits to cancellation when `C ~ αh⁵`; the
    /// step is damped by the `BᵀHB` part of the Hessian and has neither problem. Needs
    /// `C` positive definite.
    pub fn newton_correction(&self, u: &[f64]) -> Result<f64> {
        self.check_shapes()?;
        self.require_positive_c("the Newton correction")?;
        if u.len() != self.n() {
            return Err(Error::Input(format!(
                "U has {} entries, the problem {}",
                u.len(),
                self.n()
            )));
        }
        let hessian = Hessian::new(self);
        let bu = self.b_times(u);
        let (lambda, active) = self.eliminate(&bu);
        let au = multiply(&self.a, u);
        let btl = self.bt_times(&lambda);
        let minus_gradient: Vec<f64> = (0..self.n()).map(|i| self.f[i] + btl[i] - au[i]).collect();
        let h = hessian.matrix(self, &active);
        let d = Cholesky::analyse(&hessian.symbolic)?
            .factor(&h)?
            .solve_refined(&h, &minus_gradient, 2)?;
        let norm = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        // Relative to the size U has or should have: U ≡ 0 is a legitimate solution
        // (a membrane pressed flat onto ψ = 0), where ‖U‖ alone would make any rounding
        // of the step look like an O(1) correction.
        let corrected: Vec<f64> = u.iter().zip(&d).map(|(u, d)| u + d).collect();
        let scale = norm(u)
            .max(norm(&corrected))
            .max(norm(&self.f) / row_sum_norm(&self.a).max(f64::MIN_POSITIVE));
        Ok(norm(&d) / scale.max(f64::MIN_POSITIVE))
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
    /// From a given start (nested iteration): sweeps of symmetric Gauss–Seidel on the
    /// first Newton system instead of its factorization (0: factor every step).
    ///
    /// A start prolonged from a coarser mesh is off mostly near the free boundary, by
    /// mesh-size detail that a few sweeps resolve; the first exact step would spend a
    /// whole factorization on it. Measured on the membrane at 524k triangles: 8 sweeps
    /// (0.04 s) lead to the same contact set as the exact step (0.23 s), and Newton ends
    /// after 2 factorizations instead of 3. The direction is a descent direction of Φ
    /// (the sweeps apply an SPD approximate inverse), so the line search and the
    /// convergence test stay as they are; convergence is only declared after exact steps.
    pub smoothing_sweeps: usize,
    /// Solve a step through a low-rank update of the last factorization
    /// ([`crate::lcp::woodbury`]) when few constraints changed their face since it and that
    /// is estimated cheaper than factoring anew; the step is checked by its residual and
    /// factored anew if that is not at rounding level.
    ///
    /// On the membrane at 524k triangles the last exact step flips ~60 cells: the update
    /// costs 0.05 s against 0.23 s for a factorization and its solve.
    pub low_rank_updates: bool,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        Self {
            max_iterations: 200,
            refinement_steps: 1,
            tolerance: 1e-10,
            smoothing_sweeps: 0,
            low_rank_updates: true,
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

    /// `A`'s own pattern (`size ≥` A's order; the extra columns are empty).
    fn of(a: &SparseMatrix, size: usize) -> Self {
        let (col_ptr, rows) = (a.symbolic().col_ptr(), a.symbolic().row_idx());
        let mut ptr = col_ptr.to_vec();
        ptr.resize(size + 1, rows.len());
        Self {
            ptr,
            idx: rows.to_vec(),
        }
    }

    /// Position of entry `(i, j)`, if it is in the pattern.
    fn find(&self, i: usize, j: usize) -> Option<usize> {
        self.idx[self.ptr[j]..self.ptr[j + 1]]
            .binary_search(&i)
            .ok()
            .map(|k| self.ptr[j] + k)
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

/// The Hessian `A + Bᵀ H B` of Φ, `H = blockdiag(P_I C_II⁻¹ P_Iᵀ)` on each block's face
/// I, with a fixed pattern: the union over all faces, i.e. the rows of a whole block
/// coupled.
struct Hessian {
    symbolic: SymbolicSparseColMat<usize>,
    /// Where `A`'s entries go (`None`: `A`'s own pattern is the Hessian's).
    a_positions: Option<Vec<usize>>,
    /// For each entry of `B` (in [`ConstraintRows::entries`] order), the index of its
    /// column in its block's column set J.
    entry_local: Vec<usize>,
    /// Block `b`'s column count `|J|` is `widths[b]`; the value positions of its `J × J`
    /// (i-major) are `positions[position_ptr[b]..position_ptr[b + 1]]`.
    widths: Vec<usize>,
    position_ptr: Vec<usize>,
    positions: Vec<usize>,
}

impl Hessian {
    fn new(lcp: &Lcp) -> Self {
        // Each block's column set J, flat (a block of size 1 is one row of B).
        let mut column_ptr = Vec::with_capacity(lcp.m() + 1);
        column_ptr.push(0);
        let mut columns: Vec<usize> = Vec::with_capacity(lcp.b_rows.entries().len());
        for block in lcp.blocks() {
            let from = columns.len();
            for k in block.range() {
                columns.extend(lcp.b_rows[k].iter().map(|&(j, _)| j));
            }
            let set = &mut columns[from..];
            set.sort_unstable();
            let mut kept = 0;
            for i in 0..set.len() {
                if i == 0 || set[i] != set[kept - 1] {
                    set[kept] = set[i];
                    kept += 1;
                }
            }
            columns.truncate(from + kept);
            column_ptr.push(columns.len());
        }
        let block_count = column_ptr.len() - 1;
        let block_columns = |b: usize| &columns[column_ptr[b]..column_ptr[b + 1]];
        let positions_in = |pattern: &Pattern| -> Option<(Vec<usize>, Vec<usize>)> {
            let mut ptr = Vec::with_capacity(block_count + 1);
            ptr.push(0);
            // sized ahead: growing it by doubling cost half of this loop at 524k cells
            let total = (0..block_count)
                .map(|b| block_columns(b).len().pow(2))
                .sum();
            let mut positions = Vec::with_capacity(total);
            for b in 0..block_count {
                let set = block_columns(b);
                for &i in set {
                    for &j in set {
                        positions.push(pattern.find(i, j)?);
                    }
                }
                ptr.push(positions.len());
            }
            Some((ptr, positions))
        };
        // Finite element couplings usually lie inside A's pattern already (a cell's B
        // row touches the cell's own DOFs): then A's pattern is the Hessian's, and the
        // union, the costliest part of the setup, is skipped.
        let own = Pattern::of(&lcp.a, lcp.n());
        let (pattern, a_positions, (position_ptr, positions)) = match positions_in(&own) {
            Some(found) => (own, None, found),
            None => {
                let pattern = Pattern::new(&lcp.a, lcp.n(), |pattern_columns| {
                    for b in 0..block_count {
                        let set = block_columns(b);
                        for &i in set {
                            for &j in set {
                                pattern_columns[j].push(i);
                            }
                        }
                    }
                });
                let found = positions_in(&pattern).expect("the union holds every block");
                let a_positions = pattern.positions_of(&lcp.a);
                (pattern, Some(a_positions), found)
            }
        };
        let mut entry_local = Vec::with_capacity(lcp.b_rows.entries().len());
        for (b, block) in lcp.blocks().enumerate() {
            let set = block_columns(b);
            for k in block.range() {
                entry_local.extend(lcp.b_rows[k].iter().map(|&(j, _)| {
                    set.binary_search(&j)
                        .expect("the block's columns hold its rows' columns")
                }));
            }
        }
        let widths = (0..block_count)
            .map(|b| column_ptr[b + 1] - column_ptr[b])
            .collect();
        Self {
            symbolic: pattern.symbolic(),
            a_positions,
            entry_local,
            widths,
            position_ptr,
            positions,
        }
    }

    /// The Hessian on the faces `active` (per constraint, from [`Lcp::eliminate`]).
    fn matrix(&self, lcp: &Lcp, active: &[bool]) -> SparseMatrix {
        let mut values = match &self.a_positions {
            None => lcp.a.val().to_vec(),
            Some(positions) => values_of_a(&self.symbolic, positions, &lcp.a),
        };
        let offsets = lcp.b_rows.offsets();
        let entries = lcp.b_rows.entries();
        let mut inverse = [0.0; BLOCK_ENTRIES];
        let mut face = [0usize; MAX_BLOCK];
        let diagonal = lcp.c_blocks.is_empty();
        for (b, block) in lcp.blocks().enumerate() {
            if diagonal && !active[b] {
                // the common case, decided without the face machinery
                continue;
            }
            let q = lcp.face_inverse(&block, active, &mut face, &mut inverse);
            if q == 0 {
                continue;
            }
            let width = self.widths[b];
            let positions = &self.positions[self.position_ptr[b]..self.position_ptr[b + 1]];
            for a in 0..q {
                let k = block.start + face[a];
                for c in 0..q {
                    let l = block.start + face[c];
                    let w = inverse[a * q + c];
                    let (row_k, row_l) = (offsets[k]..offsets[k + 1], offsets[l]..offsets[l + 1]);
                    let local_l = &self.entry_local[row_l.clone()];
                    for (&(_, vk), &ik) in
                        entries[row_k.clone()].iter().zip(&self.entry_local[row_k])
                    {
                        for (&(_, vl), &il) in entries[row_l.clone()].iter().zip(local_l) {
                            values[positions[ik * width + il]] += w * vk * vl;
                        }
                    }
                }
            }
        }
        SparseColMat::new(self.symbolic.clone(), values)
    }
}

impl Lcp {
    /// The active face `I` of `block` under `active` (per constraint) into `face` (indices
    /// within the block) and `C_II⁻¹` into `inverse` (`q × q` row-major); returns `q`,
    /// 0 when the face is empty or `C_II` is not SPD (the solvers reject such a `C`
    /// before they get here).
    fn face_inverse(
        &self,
        block: &Block,
        active: &[bool],
        face: &mut [usize; MAX_BLOCK],
        inverse: &mut [f64; BLOCK_ENTRIES],
    ) -> usize {
        let q = block.range().filter(|&k| active[k]).fold(0, |q, k| {
            face[q] = k - block.start;
            q + 1
        });
        if q == 0 {
            return 0;
        }
        if block.size == 1 {
            inverse[0] = 1.0 / self.c[block.start];
            return 1;
        }
        let mut dense = [0.0; BLOCK_ENTRIES];
        block.face(&self.c, &face[..q], &mut dense[..q * q]);
        if small_inverse(&dense, q, inverse) {
            q
        } else {
            0
        }
    }

    /// `H(active) − H(previous)` of the Newton Hessian as `U S Uᵀ`: for each block whose
    /// face changed, its rows of `B` and the change of `P_I C_II⁻¹ P_Iᵀ`.
    fn hessian_change(&self, previous: &[bool], active: &[bool]) -> Result<LowRankTerm> {
        let mut term = LowRankTerm::new();
        let mut face = [0usize; MAX_BLOCK];
        let mut inverse = [0.0; BLOCK_ENTRIES];
        for block in self.blocks() {
            let range = block.range();
            if previous[range.clone()] == active[range.clone()] {
                continue;
            }
            let s = block.size;
            let mut change = [0.0; BLOCK_ENTRIES];
            for (sign, flags) in [(1.0, active), (-1.0, previous)] {
                let q = self.face_inverse(&block, flags, &mut face, &mut inverse);
                for a in 0..q {
                    for c in 0..q {
                        change[face[a] * s + face[c]] += sign * inverse[a * q + c];
                    }
                }
            }
            term.push_block(range.map(|k| &self.b_rows[k]), &change[..s * s])?;
        }
        Ok(term)
    }

    /// An error unless every block of `C` is positive definite (Φ and the elimination of
    /// Λ need it).
    fn require_positive_c(&self, method: &str) -> Result<()> {
        let mut dense = [0.0; BLOCK_ENTRIES];
        for block in self.blocks() {
            let k = block.start;
            if block.size == 1 {
                if self.c[k].is_nan() || self.c[k] <= 0.0 {
                    return Err(Error::Input(format!(
                        "{method} needs C > 0 (it uses Φ and Λ = C⁻¹(G − BU)₊); C_{k} = {}: α ≤ 0 gives the plain mixed method, solve it with the QP solver",
                        self.c[k]
                    )));
                }
                continue;
            }
            let s = block.size;
            block.dense(&self.c, &mut dense[..s * s]);
            if !small_cholesky(&mut dense, s) {
                return Err(Error::Input(format!(
                    "{method} needs C positive definite (it uses Φ and the eliminated Λ); its block of constraints {k} to {} is not: α ≤ 0 gives the plain mixed method, solve it with the QP solver",
                    k + s - 1
                )));
            }
        }
        Ok(())
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

    /// The eliminated multiplier from `bu = BU`: per block of `C`,
    /// `Λ_b = argmin_{Λ≥0} ½ΛᵀC_bΛ − Λᵀ(G − BU)_b` (for a block of size 1,
    /// `Λ_k = (G − BU)₊,k / C_k`). Needs `C` positive definite.
    pub fn eliminated_multiplier(&self, bu: &[f64]) -> Vec<f64> {
        self.eliminate(bu).0
    }

    /// The eliminated multiplier and, per constraint, whether it is on its block's
    /// active face (the constraints Newton's Hessian includes).
    fn eliminate(&self, bu: &[f64]) -> (Vec<f64>, Vec<bool>) {
        let m = self.m();
        let mut lambda = vec![0.0; m];
        let mut active = vec![false; m];
        if self.c_blocks.is_empty() {
            // diagonal C: the size-1 formulas in one pass, as [`Lcp::penalty`]
            for (k, (lambda, active)) in lambda.iter_mut().zip(&mut active).enumerate() {
                (*lambda, *active) = single_multiplier(self.g[k] - bu[k], self.c[k]);
            }
            return (lambda, active);
        }
        let mut dense = [0.0; BLOCK_ENTRIES];
        let mut r = [0.0; MAX_BLOCK];
        for block in self.blocks() {
            let range = block.range();
            self.block_multiplier(
                &block,
                bu,
                &mut dense,
                &mut r,
                &mut lambda[range.clone()],
                &mut active[range],
            );
        }
        (lambda, active)
    }

    /// One block's eliminated multiplier from `bu = BU`: fills `dense` with `C_b`
    /// (`s × s`), `r` with `(G − BU)_b`, and `lambda`, `active` with `Λ_b` and its
    /// active face.
    fn block_multiplier(
        &self,
        block: &Block,
        bu: &[f64],
        dense: &mut [f64],
        r: &mut [f64],
        lambda: &mut [f64],
        active: &mut [bool],
    ) {
        let (k, s) = (block.start, block.size);
        for (i, r) in r[..s].iter_mut().enumerate() {
            *r = self.g[k + i] - bu[k + i];
        }
        if s == 1 {
            dense[0] = self.c[k];
            (lambda[0], active[0]) = single_multiplier(r[0], self.c[k]);
            return;
        }
        block.dense(&self.c, &mut dense[..s * s]);
        block_minimizer(
            &dense[..s * s],
            s,
            &r[..s],
            &mut lambda[..s],
            &mut active[..s],
        );
    }

    /// The merit function `Φ(U) = ½UᵀAU − FᵀU + Σ_b max_{Λ≥0}(Λᵀr_b − ½ΛᵀC_bΛ)`,
    /// `r = G − BU` (for P0: `½Σ_k (G − BU)²₊,k / C_k`), from `au = AU`, `bu = BU`.
    pub fn merit(&self, u: &[f64], au: &[f64], bu: &[f64]) -> f64 {
        let quadratic: f64 = u
            .iter()
            .zip(au)
            .zip(&self.f)
            .map(|((u, au), f)| 0.5 * u * au - f * u)
            .sum();
        quadratic + self.penalty(bu)
    }

    /// The constraint part of [`Lcp::merit`] from `bu = BU`.
    fn penalty(&self, bu: &[f64]) -> f64 {
        if self.c_blocks.is_empty() {
            // diagonal C: the closed form in one vectorizable pass; the general per-block
            // code cost 10 ms per pass at 524k cells, and the line search evaluates this
            // for every trial
            return self
                .g
                .iter()
                .zip(bu)
                .zip(&self.c)
                .map(|((g, bu), c)| single_penalty(g - bu, *c))
                .sum();
        }
        let mut dense = [0.0; BLOCK_ENTRIES];
        let mut r = [0.0; MAX_BLOCK];
        let mut lambda = [0.0; MAX_BLOCK];
        let mut active = [false; MAX_BLOCK];
        self.blocks()
            .map(|block| {
                let k = block.start;
                if block.size == 1 {
                    // the closed form, cheaper than the general one in the line search
                    return single_penalty(self.g[k] - bu[k], self.c[k]);
                }
                let s = block.size;
                self.block_multiplier(&block, bu, &mut dense, &mut r, &mut lambda, &mut active);
                (0..s)
                    .map(|i| {
                        let c_lambda: f64 = (0..s).map(|j| dense[i * s + j] * lambda[j]).sum();
                        lambda[i] * (r[i] - 0.5 * c_lambda)
                    })
                    .sum::<f64>()
            })
            .sum()
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

/// A constraint alone in its block of `C` (`c > 0`) with `r = G − BU`: its eliminated
/// multiplier `r₊ / c` and whether it is active.
#[inline]
fn single_multiplier(r: f64, c: f64) -> (f64, bool) {
    (r.max(0.0) / c, r > 0.0)
}

/// Its share of the merit: `max_{λ≥0} (λr − ½cλ²) = ½ r₊² / c`.
#[inline]
fn single_penalty(r: f64, c: f64) -> f64 {
    let r = r.max(0.0);
    0.5 * r * r / c
}

fn max_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// What semismooth Newton needs before its first iteration and that depends only on the
/// LCP's sparsity: the Hessian's pattern and its symbolic Cholesky factorization (the
/// ordering). Built apart from the iteration so that it can be prepared on another
/// thread while a coarser level is solved (see [`crate::obstacle::solve_nested`]); the
/// symbolic factorization may even be left to finish there while Newton's first,
/// smoothed step, which needs only the pattern, runs.
pub struct NewtonWorkspace {
    hessian: Hessian,
    /// Filled by [`NewtonWorkspace::analyse`], from whichever thread asks first (the
    /// others wait for it). The error is kept as text: [`Error`] is not `Clone`.
    cholesky: OnceLock<std::result::Result<Cholesky, String>>,
    /// `(n, m)` of the LCP it was built for.
    shape: (usize, usize),
}

impl NewtonWorkspace {
    /// The Hessian pattern and symbolic factorization of `lcp`.
    pub fn new(lcp: &Lcp) -> Result<Self> {
        let workspace = Self::pattern_of(lcp)?;
        workspace.analyse()?;
        Ok(workspace)
    }

    /// The Hessian pattern of `lcp` only; the symbolic factorization follows from
    /// [`NewtonWorkspace::analyse`], called ahead (on another thread) or by Newton
    /// itself when it first factors.
    pub fn pattern_of(lcp: &Lcp) -> Result<Self> {
        lcp.check_shapes()?;
        Ok(Self {
            hessian: Hessian::new(lcp),
            cholesky: OnceLock::new(),
            shape: (lcp.n(), lcp.m()),
        })
    }

    /// The symbolic Cholesky factorization of the Hessian pattern, computed on the first
    /// call; a call while another thread computes it waits for that one.
    pub fn analyse(&self) -> Result<&Cholesky> {
        self.cholesky
            .get_or_init(|| {
                Cholesky::analyse(&self.hessian.symbolic).map_err(|e| match e {
                    Error::LinearSolve(message) => message,
                    other => other.to_string(),
                })
            })
            .as_ref()
            .map_err(|e| Error::LinearSolve(e.clone()))
    }
}

/// Semismooth Newton (primal–dual active set) on Φ with an Armijo line search, from
/// `start` (e.g. the prolonged solution of a coarser mesh) or from zero.
pub fn semismooth_newton(
    lcp: &Lcp,
    start: Option<&[f64]>,
    options: NewtonOptions,
) -> Result<LcpSolution> {
    lcp.check_shapes()?;
    lcp.require_positive_c("semismooth Newton")?;
    // the symbolic factorization follows when Newton first factors
    semismooth_newton_prepared(lcp, &NewtonWorkspace::pattern_of(lcp)?, start, options)
}

/// [`semismooth_newton`] with the pattern work done ahead in `workspace` (built by
/// [`NewtonWorkspace::new`] for this `lcp`).
pub fn semismooth_newton_prepared(
    lcp: &Lcp,
    workspace: &NewtonWorkspace,
    start: Option<&[f64]>,
    options: NewtonOptions,
) -> Result<LcpSolution> {
    let clock = Instant::now();
    lcp.check_shapes()?;
    lcp.require_positive_c("semismooth Newton")?;
    if workspace.shape != (lcp.n(), lcp.m()) {
        return Err(Error::Input(format!(
            "the Newton workspace was built for an LCP with {:?} (primal, constraint) unknowns, this one has {:?}",
            workspace.shape,
            (lcp.n(), lcp.m())
        )));
    }
    newton_iteration(lcp, workspace, start, options, clock)
}

fn newton_iteration(
    lcp: &Lcp,
    workspace: &NewtonWorkspace,
    start: Option<&[f64]>,
    options: NewtonOptions,
    clock: Instant,
) -> Result<LcpSolution> {
    let n = lcp.n();
    let mut u = lcp.start_vector(start)?;
    let hessian = &workspace.hessian;
    let mut factorizations = 0;
    let done = |u: Vec<f64>,
                lambda: Vec<f64>,
                iterations: usize,
                residual: f64,
                solves: (usize, usize)| {
        let multiplier_noise = lcp.elimination_noise(&lambda);
        LcpSolution {
            u,
            lambda,
            iterations,
            kkt_residual: residual,
            seconds: clock.elapsed().as_secs_f64(),
            factorizations: solves.0,
            low_rank_updates: solves.1,
            multiplier_noise,
        }
    };
    let mut smooth_first = start.is_some() && options.smoothing_sweeps > 0;
    let mut previous_active: Option<Vec<bool>> = None;
    // the last factored Hessian and its faces, for low-rank updates
    let mut factored: Option<(CholeskyFactor, Vec<bool>)> = None;
    let mut low_rank_updates = 0;
    for iteration in 1..=options.max_iterations {
        let au = multiply(&lcp.a, &u);
        let bu = lcp.b_times(&u);
        let (lambda, active) = lcp.eliminate(&bu);
        // Converged: the active faces did not change over a full step, so u is the exact
        // minimizer of the quadratic that Φ is on these faces.
        if previous_active.as_ref() == Some(&active) {
            let residual = lcp.kkt_residual(&u, &lambda);
            if residual <= options.tolerance {
                return Ok(done(
                    u,
                    lambda,
                    iteration - 1,
                    residual,
                    (factorizations, low_rank_updates),
                ));
            }
        }
        let btl = lcp.bt_times(&lambda);
        let gradient: Vec<f64> = (0..n).map(|i| au[i] - lcp.f[i] - btl[i]).collect();
        let h = hessian.matrix(lcp, &active);
        let minus_gradient: Vec<f64> = gradient.iter().map(|g| -g).collect();
        let smoothed = if std::mem::take(&mut smooth_first) {
            symmetric_gauss_seidel(&h, &minus_gradient, options.smoothing_sweeps)
        } else {
            None
        };
        let exact = smoothed.is_none();
        let d = match smoothed {
            Some(d) => d,
            None => {
                let reusable = factored.as_ref().filter(|_| options.low_rank_updates);
                let updated = reusable.and_then(|(factor, factored_active)| {
                    updated_solve(
                        lcp,
                        &h,
                        factor,
                        factored_active,
                        &active,
                        &minus_gradient,
                        options,
                    )
                });
                match updated {
                    Some(d) => {
                        low_rank_updates += 1;
                        d
                    }
                    None => {
                        factorizations += 1;
                        let factor = workspace.analyse()?.factor_cholesky(&h)?;
                        let d = refined(&h, &minus_gradient, options.refinement_steps, |b| {
                            factor.solve(b)
                        })?;
                        factored = Some((factor, active.clone()));
                        d
                    }
                }
            }
        };
        let slope: f64 = gradient.iter().zip(&d).map(|(g, d)| g * d).sum();
        let Some(step) = lcp.armijo(&u, &au, &bu, &d, slope) else {
            // No decrease along a Newton direction: at the minimizer up to rounding.
            let residual = lcp.kkt_residual(&u, &lambda);
            if residual <= options.tolerance.max(1e-8) {
                return Ok(done(
                    u,
                    lambda,
                    iteration,
                    residual,
                    (factorizations, low_rank_updates),
                ));
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
        if exact && step == 1.0 && max_norm(&d) <= 1e-13 * max_norm(&u) {
            let lambda = lcp.eliminated_multiplier(&lcp.b_times(&u));
            let residual = lcp.kkt_residual(&u, &lambda);
            if residual <= options.tolerance {
                return Ok(done(
                    u,
                    lambda,
                    iteration,
                    residual,
                    (factorizations, low_rank_updates),
                ));
            }
        }
        previous_active = (exact && step == 1.0).then_some(active);
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

/// Largest relative cost ([`WoodburySolver::relative_cost`]) at which a Newton step is
/// solved through a low-rank update of the last factorization rather than a new one: the
/// factorization runs at dense-kernel speed, the update's path solves do not.
const LOW_RANK_COST_LIMIT: f64 = 0.5;

/// Largest backward error `‖b − Hd‖∞ / (‖H‖∞‖d‖∞ + ‖b‖∞)` accepted from an updated
/// solve; beyond it the step is factored anew (a nearly singular capacitance matrix).
const LOW_RANK_BACKWARD_ERROR: f64 = 1e-14;

/// The Newton direction `H d = b` for the faces `active` through a low-rank update of the
/// factor of the Hessian on `factored_active`, when that is cheaper than a new
/// factorization and accurate; `None` otherwise.
fn updated_solve(
    lcp: &Lcp,
    h: &SparseMatrix,
    factor: &CholeskyFactor,
    factored_active: &[bool],
    active: &[bool],
    b: &[f64],
    options: NewtonOptions,
) -> Option<Vec<f64>> {
    let term = lcp.hessian_change(factored_active, active).ok()?;
    let cost = WoodburySolver::relative_cost(factor, &term, 1 + options.refinement_steps)?;
    if cost > LOW_RANK_COST_LIMIT {
        return None;
    }
    let solver = WoodburySolver::new(factor, term).ok()?;
    let d = refined(h, b, options.refinement_steps, |r| solver.solve(r)).ok()?;
    let residual = residual_compensated(h, &d, b);
    let backward =
        max_norm(&residual) / (row_sum_norm(h) * max_norm(&d) + max_norm(b)).max(f64::MIN_POSITIVE);
    (backward <= LOW_RANK_BACKWARD_ERROR).then_some(d)
}

impl Lcp {
    /// How many digits the eliminated multiplier `lambda` loses to cancellation: the
    /// rounding `ε‖G_b‖∞‖C_b⁻¹‖∞` of `Λ_b = C_b⁻¹(G − BU)_b` (`ε|G_k| / C_k` for P0)
    /// at its worst block among those where `lambda` is nonzero, relative to the
    /// multiplier's natural size under the load `Λ* = ‖F‖∞/‖Bᵀ‖∞`
    /// ([`Lcp::multiplier_scale`]), or to `‖lambda‖∞` where `F = 0` (contact driven by
    /// the obstacle or the boundary data alone). Near 1 the eliminated Λ is rounding
    /// noise: on fine meshes `C = αh⁵` falls below the rounding of `G − BU ≈ CΛ`.
    ///
    /// The load's scale comes first because `‖lambda‖∞` can be far larger than the
    /// multiplier's typical value (P0 multipliers resolve the point forces at a beam's
    /// contact edge as ~force/h): relative to it the noise in `∫λ` would be understated.
    ///
    /// 0 when `lambda ≡ 0`: the elimination clips every inactive constraint's Λ to an
    /// exact 0, so there is nothing to be noisy (before, the estimate divided by the load
    /// scale alone and reported ~1e302 at zero load).
    pub fn elimination_noise(&self, lambda: &[f64]) -> f64 {
        let largest = lambda.iter().fold(0.0f64, |m, l| m.max(l.abs()));
        if largest == 0.0 || !largest.is_finite() {
            return if largest == 0.0 { 0.0 } else { f64::INFINITY };
        }
        let load_scale = self.multiplier_scale();
        let scale = if load_scale > 0.0 {
            load_scale
        } else {
            largest
        };
        let carries = |range: std::ops::Range<usize>| {
            lambda
                .get(range)
                .is_some_and(|l| l.iter().any(|&l| l != 0.0))
        };
        let mut dense = [0.0; BLOCK_ENTRIES];
        let mut inverse = [0.0; BLOCK_ENTRIES];
        self.blocks()
            .filter_map(|block| {
                if !carries(block.range()) {
                    return None;
                }
                let k = block.start;
                if block.size == 1 {
                    return (self.c[k] > 0.0)
                        .then(|| f64::EPSILON * self.g[k].abs() / (self.c[k] * scale));
                }
                let s = block.size;
                block.dense(&self.c, &mut dense[..s * s]);
                if !small_inverse(&dense, s, &mut inverse) {
                    return None;
                }
                let inverse_norm = (0..s)
                    .map(|i| (0..s).map(|j| inverse[i * s + j].abs()).sum::<f64>())
                    .fold(0.0, f64::max);
                let g = self.g[block.range()]
                    .iter()
                    .fold(0.0f64, |m, g| m.max(g.abs()));
                Some(f64::EPSILON * g * inverse_norm / scale)
            })
            .fold(0.0, f64::max)
    }
}

/// The saddle-point system `[[A, −B̃ᵀ], [−B̃, D]]` of the primal–dual active set method with
/// a fixed pattern: active rows carry `B_k` and, within their block of `C`, `D_kl = −C_kl`
/// between active constraints; inactive rows `Λ_k = 0` (`B̃_k = 0`, `D_kk = −1` scaled,
/// no coupling), so one symbolic LU serves every iteration.
struct SaddlePoint {
    symbolic: SymbolicSparseColMat<usize>,
    a_positions: Vec<usize>,
    /// For row k of B: positions of (n+k, j) and (j, n+k) per entry.
    b_positions: Vec<Vec<(usize, usize)>>,
    /// For each block of C: the positions of (n+k, n+l), k and l in the block (k-major).
    block_positions: Vec<Vec<usize>>,
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
            }
            for block in lcp.blocks() {
                for k in block.range() {
                    for l in block.range() {
                        columns[n + l].push(n + k);
                    }
                }
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
        let block_positions = lcp
            .blocks()
            .map(|block| {
                block
                    .range()
                    .flat_map(|k| block.range().map(move |l| (k, l)))
                    .map(|(k, l)| pattern.position(n + k, n + l))
                    .collect()
            })
            .collect();
        Self {
            symbolic: pattern.symbolic(),
            a_positions,
            b_positions,
            block_positions,
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
            }
        }
        for (block, positions) in lcp.blocks().zip(&self.block_positions) {
            let s = block.size;
            for (i, k) in block.range().enumerate() {
                for (j, l) in block.range().enumerate() {
                    let p = positions[i * s + j];
                    if active[k] && active[l] {
                        values[p] = -block.entry(&lcp.c, i, j);
                    } else if k == l {
                        // Λ_k = 0, scaled like the row so that the matrix stays balanced
                        let scale = lcp.b_rows[k]
                            .iter()
                            .fold(0.0f64, |m, &(_, v)| m.max(v.abs()));
                        values[p] = -scale.max(lcp.c[k]).max(f64::MIN_POSITIVE);
                    }
                }
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
    lcp.check_shapes()?;
    let (n, m) = (lcp.n(), lcp.m());
    if solution.u.len() != n || solution.lambda.len() != m {
        return Err(Error::Input(format!(
            "a solution with {} primal values and {} multipliers for a problem with {n} and {m}",
            solution.u.len(),
            solution.lambda.len()
        )));
    }
    let active: Vec<bool> = solution.lambda.iter().map(|&l| l > 0.0).collect();
    let saddle = SaddlePoint::new(lcp);
    let k_matrix = saddle.matrix(lcp, &active);
    let factor = crate::lcp::cholesky::LuSolver::analyse(&saddle.symbolic)?.factor(&k_matrix)?;
    let mut rhs = lcp.f.clone();
    rhs.extend((0..m).map(|k| if active[k] { -lcp.g[k] } else { 0.0 }));
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
        let multiplier_noise = lcp.elimination_noise(&lambda);
        Ok(LcpSolution {
            u,
            lambda,
            kkt_residual: residual,
            seconds: solution.seconds + clock.elapsed().as_secs_f64(),
            factorizations: solution.factorizations + 1,
            low_rank_updates: solution.low_rank_updates,
            // the recovery helps, but with κ this large it is no guarantee: keep the estimate
            multiplier_noise,
            ..solution
        })
    } else {
        Ok(solution)
    }
}

/// The primal–dual active set method on the saddle-point system, for when eliminating
/// Λ would lose it to cancellation ([`Lcp::elimination_noise`]): Λ is an unknown of each
/// linear solve, computed from the equilibrium. The step in U is the Newton step on Φ for
/// the current active set, globalized by the same Armijo search; after a full step the
/// next active set is `{Λ_k > 0}` on the active constraints and `{R_k < 0}` on the others.
pub fn primal_dual_active_set(
    lcp: &Lcp,
    start: Option<&[f64]>,
    options: NewtonOptions,
) -> Result<LcpSolution> {
    let clock = Instant::now();
    lcp.check_shapes()?;
    lcp.require_positive_c("the saddle-point active-set method")?;
    let (n, m) = (lcp.n(), lcp.m());
    let mut u = lcp.start_vector(start)?;
    let saddle = SaddlePoint::new(lcp);
    let lu = crate::lcp::cholesky::LuSolver::analyse(&saddle.symbolic)?;
    let mut active = lcp.eliminate(&lcp.b_times(&u)).1;
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
            // R = BU + CΛ − G with Λ = 0 off the active set (for P0: R_k = B_kU − G_k there)
            let bu = lcp.b_times(&u);
            let c_lambda = lcp.c_times(&lambda);
            let next: Vec<bool> = (0..m)
                .map(|k| {
                    if active[k] {
                        lambda[k] > 0.0
                    } else {
                        bu[k] + c_lambda[k] - lcp.g[k] < 0.0
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
                        low_rank_updates: 0,
                        multiplier_noise: 0.0,
                    });
                }
            }
            two_ago = Some(std::mem::replace(&mut active, next));
        } else {
            u = u.iter().zip(&d).map(|(u, d)| u + step * d).collect();
            active = lcp.eliminate(&lcp.b_times(&u)).1;
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
/// are the LCP with `Λ` the constraint's multiplier (for `C` positive definite also
/// `Λ = C⁻¹CΛ`, the primal Λ); with `C = 0` it is the plain mixed method
/// `min ½UᵀAU − FᵀU` over `BU ≥ G`. Unlike a formulation with `C⁻¹`, nothing here grows
/// like `h⁻⁵`.
pub fn quadratic_program(lcp: &Lcp) -> Result<LcpSolution> {
    use clarabel::algebra::CscMatrix;
    use clarabel::solver::{
        DefaultSettingsBuilder, DefaultSolver, IPSolver, NonnegativeConeT, SolverStatus,
    };
    let clock = Instant::now();
    lcp.check_shapes()?;
    let (n, m) = (lcp.n(), lcp.m());
    if lcp.c.iter().any(|&c| c.is_nan() || c < 0.0) {
        return Err(Error::Input("C must be non-negative".into()));
    }
    let mut dense = [0.0; BLOCK_ENTRIES];
    for block in lcp.blocks().filter(|b| b.size > 1) {
        let s = block.size;
        block.dense(&lcp.c, &mut dense[..s * s]);
        if !small_cholesky(&mut dense, s) {
            return Err(Error::Input(format!(
                "C must be positive semidefinite, and its coupled block of constraints {} to {} is not positive definite",
                block.start,
                block.start + s - 1
            )));
        }
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
    // the entries of C by row: (k, l, C_kl) within each block, l ascending
    let c_entries: Vec<Vec<(usize, f64)>> = {
        let mut rows_of_c = vec![Vec::new(); m];
        for block in lcp.blocks() {
            for (i, k) in block.range().enumerate() {
                for (j, l) in block.range().enumerate() {
                    let v = block.entry(&lcp.c, i, j);
                    if v != 0.0 || k == l {
                        rows_of_c[k].push((l, v));
                    }
                }
            }
        }
        rows_of_c
    };
    let row_scale: Vec<f64> = (0..m)
        .map(|k| {
            let largest = lcp.b_rows[k]
                .iter()
                .map(|&(j, v)| (v * scale[j]).abs())
                .chain(c_entries[k].iter().map(|&(_, v)| v.abs()))
                .fold(0.0, f64::max);
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
        // column l of C: its rows k ≤ l (C is symmetric), ascending
        for entries in &c_entries {
            let l = p_ptr.len() - 1 - n;
            for &(k, v) in entries.iter().filter(|&&(k, _)| k <= l) {
                p_rows.push(n + k);
                p_vals.push(v);
            }
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
            for &(l, v) in &c_entries[k] {
                ti.push(k);
                tj.push(n + l);
                tv.push(-v * row_scale[k]);
            }
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
        low_rank_updates: 0,
        multiplier_noise: 0.0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::Triplet;

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
            let hessian = Hessian::new(&lcp);
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
