//! The few sparse kernels the cycle runs, all into preallocated vectors: products with
//! `A` and `P`, restriction `Pᵀ r` without forming `Pᵀ`, Gauss–Seidel sweeps, and the
//! Galerkin triple product `PᵀAP` formed once per hierarchy.
//!
//! Public: the parallel kernels (issue 15) for the cycle to call, each equal to its
//! serial counterpart up to rounding — [`multiply_symmetric_into`],
//! [`prolong_add_transposed`], [`restrict_parallel`] and the multicolour symmetric
//! Gauss–Seidel [`Smoother`]; serial below [`PARALLEL_MIN_ROWS`] unknowns.

use crate::SparseMatrix;
use faer::sparse::{SparseColMat, SymbolicSparseColMat};

/// `y = A x` (column-oriented: exact for any `A`, symmetric or not); the reference of
/// the parallel kernels' tests.
#[cfg(test)]
pub(super) fn multiply_into(a: &SparseMatrix, x: &[f64], y: &mut [f64]) {
    let (col_ptr, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    y.fill(0.0);
    for (j, &xj) in x.iter().enumerate() {
        if xj != 0.0 {
            for k in col_ptr[j]..col_ptr[j + 1] {
                y[rows[k]] += vals[k] * xj;
            }
        }
    }
}

/// `y += P x`.
pub(super) fn prolong_add(p: &SparseMatrix, x: &[f64], y: &mut [f64]) {
    let (col_ptr, rows, vals) = (p.symbolic().col_ptr(), p.symbolic().row_idx(), p.val());
    for (j, &xj) in x.iter().enumerate() {
        for k in col_ptr[j]..col_ptr[j + 1] {
            y[rows[k]] += vals[k] * xj;
        }
    }
}

/// `y = Pᵀ r`: column `j` of `P` is row `j` of `Pᵀ`, so each entry is one gather.
pub(super) fn restrict(p: &SparseMatrix, r: &[f64], y: &mut [f64]) {
    let (col_ptr, rows, vals) = (p.symbolic().col_ptr(), p.symbolic().row_idx(), p.val());
    for (j, yj) in y.iter_mut().enumerate() {
        *yj = (col_ptr[j]..col_ptr[j + 1])
            .map(|k| vals[k] * r[rows[k]])
            .sum();
    }
}

/// The diagonal of `a`, `None` at a missing entry.
pub(super) fn diagonal(a: &SparseMatrix) -> Vec<Option<f64>> {
    let (col_ptr, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    (0..a.ncols())
        .map(|j| {
            rows[col_ptr[j]..col_ptr[j + 1]]
                .binary_search(&j)
                .ok()
                .map(|k| vals[col_ptr[j] + k])
        })
        .collect()
}

/// One Gauss–Seidel sweep on `A x = b` in place, forward or backward, for a symmetric
/// `A` stored with both triangles (column `j` read as row `j`); `inverse_diagonal` holds
/// `1 / A_jj`.
pub(super) fn gauss_seidel(
    a: &SparseMatrix,
    inverse_diagonal: &[f64],
    b: &[f64],
    x: &mut [f64],
    forward: bool,
) {
    let (col_ptr, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    let relax = |j: usize, x: &mut [f64]| {
        let mut sum = b[j];
        for k in col_ptr[j]..col_ptr[j + 1] {
            sum -= vals[k] * x[rows[k]];
        }
        // the sum above subtracted A_jj x_j too: add it back through the update
        x[j] += sum * inverse_diagonal[j];
    };
    if forward {
        (0..x.len()).for_each(|j| relax(j, x));
    } else {
        (0..x.len()).rev().for_each(|j| relax(j, x));
    }
}

/// `C = A B` (Gustavson's column-by-column product with a dense accumulator), rows of
/// each column sorted. From [`PARALLEL_MIN_ROWS`] rows or columns on (and more than one
/// thread) the columns of `C` are computed in blocks of consecutive columns on the
/// current rayon pool and concatenated: every column is the same sum in the same order
/// as in the serial loop, so the result is bitwise the same whatever the threads.
pub(super) fn product(a: &SparseMatrix, b: &SparseMatrix) -> SparseMatrix {
    use rayon::prelude::*;
    let (m, n) = (a.nrows(), b.ncols());
    // enough blocks that a thread slowed by another job is not waited for long
    let blocks = if in_parallel(m.max(n)) {
        (n / MIN_ROWS_PER_TASK).clamp(1, 32)
    } else {
        1
    };
    let parts: Vec<ProductColumns> = if blocks == 1 {
        vec![product_columns(a, b, 0..n)]
    } else {
        (0..blocks)
            .into_par_iter()
            .map(|c| product_columns(a, b, c * n / blocks..(c + 1) * n / blocks))
            .collect()
    };
    let nnz = parts.iter().map(|p| p.rows.len()).sum();
    let mut col_ptr = Vec::with_capacity(n + 1);
    let mut rows = Vec::with_capacity(nnz);
    let mut values = Vec::with_capacity(nnz);
    col_ptr.push(0);
    for part in parts {
        let offset = rows.len();
        col_ptr.extend(part.col_end.iter().map(|&e| offset + e));
        rows.extend_from_slice(&part.rows);
        values.extend_from_slice(&part.values);
    }
    SparseColMat::new(
        SymbolicSparseColMat::new_checked(m, n, col_ptr, None, rows),
        values,
    )
}

/// Columns of a product `A B`: the end of each column in `rows`/`values`.
struct ProductColumns {
    col_end: Vec<usize>,
    rows: Vec<usize>,
    values: Vec<f64>,
}

/// The columns `columns` of `A B`, with a dense accumulator over the rows they can
/// reach (the span of the first and last row of the columns of `A` they read: a narrow
/// band on a mesh numbered by position).
fn product_columns(
    a: &SparseMatrix,
    b: &SparseMatrix,
    columns: std::ops::Range<usize>,
) -> ProductColumns {
    let (a_ptr, a_rows, a_vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    let (b_ptr, b_rows, b_vals) = (b.symbolic().col_ptr(), b.symbolic().row_idx(), b.val());
    let (mut low, mut high) = (usize::MAX, 0);
    for &k in &b_rows[b_ptr[columns.start]..b_ptr[columns.end]] {
        if a_ptr[k] < a_ptr[k + 1] {
            low = low.min(a_rows[a_ptr[k]]);
            high = high.max(a_rows[a_ptr[k + 1] - 1] + 1);
        }
    }
    let span = high.saturating_sub(low);
    let mut accumulator = vec![0.0; span];
    let mut seen = vec![usize::MAX; span];
    let mut col_end = Vec::with_capacity(columns.len());
    let mut rows = Vec::new();
    let mut values = Vec::new();
    for j in columns {
        let start = rows.len();
        for kb in b_ptr[j]..b_ptr[j + 1] {
            let (k, bkj) = (b_rows[kb], b_vals[kb]);
            for ka in a_ptr[k]..a_ptr[k + 1] {
                let i = a_rows[ka];
                let local = i - low;
                if seen[local] != j {
                    seen[local] = j;
                    accumulator[local] = 0.0;
                    rows.push(i);
                }
                accumulator[local] += a_vals[ka] * bkj;
            }
        }
        rows[start..].sort_unstable();
        values.extend(rows[start..].iter().map(|&i| accumulator[i - low]));
        col_end.push(rows.len());
    }
    ProductColumns {
        col_end,
        rows,
        values,
    }
}

/// `Pᵀ`.
pub(super) fn transpose(p: &SparseMatrix) -> SparseMatrix {
    let (col_ptr, rows, vals) = (p.symbolic().col_ptr(), p.symbolic().row_idx(), p.val());
    let (m, n) = (p.nrows(), p.ncols());
    let mut count = vec![0usize; m + 1];
    for &i in rows {
        count[i + 1] += 1;
    }
    for i in 0..m {
        count[i + 1] += count[i];
    }
    let t_ptr = count.clone();
    let mut t_rows = vec![0; rows.len()];
    let mut t_vals = vec![0.0; rows.len()];
    // columns visited in order, so each row of the transpose comes out sorted
    for j in 0..n {
        for k in col_ptr[j]..col_ptr[j + 1] {
            let slot = &mut count[rows[k]];
            t_rows[*slot] = j;
            t_vals[*slot] = vals[k];
            *slot += 1;
        }
    }
    SparseColMat::new(
        SymbolicSparseColMat::new_checked(n, m, t_ptr, None, t_rows),
        t_vals,
    )
}

/// The Galerkin coarse operator `PᵀAP`, made exactly symmetric (the average with its
/// transpose removes the rounding asymmetry of the two products, which Gauss–Seidel
/// reading columns as rows would otherwise see).
pub(super) fn galerkin(a: &SparseMatrix, p: &SparseMatrix) -> SparseMatrix {
    let c = product(&transpose(p), &product(a, p));
    let t = transpose(&c);
    // same pattern: Pᵀ A P has a symmetric pattern when A does
    if t.symbolic().col_ptr() == c.symbolic().col_ptr()
        && t.symbolic().row_idx() == c.symbolic().row_idx()
    {
        let values: Vec<f64> = c
            .val()
            .iter()
            .zip(t.val())
            .map(|(x, y)| 0.5 * (x + y))
            .collect();
        let n = c.ncols();
        let symbolic = SymbolicSparseColMat::new_checked(
            n,
            n,
            c.symbolic().col_ptr().to_vec(),
            None,
            c.symbolic().row_idx().to_vec(),
        );
        SparseColMat::new(symbolic, values)
    } else {
        c
    }
}

// ---- Parallel kernels (issue 15): rows split over the current rayon pool ----
//
// Each is the gather form of a kernel above, so every entry of the result is written by
// one thread; levels below `PARALLEL_MIN_ROWS` (or a one-thread pool) take a serial loop
// over the same formula. The multigrid cycle allocates nothing per call with them.

/// Orders below this run the kernels below on the calling thread: at a few µs per
/// parallel dispatch, smaller levels (and the coarse end of every hierarchy) gain
/// nothing from a second thread.
pub const PARALLEL_MIN_ROWS: usize = 16384;

/// Rows per rayon task at least: enough work (≈ 10 µs for P1) to amortize a steal.
const MIN_ROWS_PER_TASK: usize = 4096;

/// Whether a kernel of order `n` runs in parallel.
fn in_parallel(n: usize) -> bool {
    n >= PARALLEL_MIN_ROWS && rayon::current_num_threads() > 1
}

/// `y_i = f(i)` for every `i`, in parallel on the current pool for large `y`.
fn fill_rows(y: &mut [f64], f: impl Fn(usize) -> f64 + Sync) {
    use rayon::prelude::*;
    if in_parallel(y.len()) {
        y.par_iter_mut()
            .enumerate()
            .with_min_len(MIN_ROWS_PER_TASK)
            .for_each(|(i, yi)| *yi = f(i));
    } else {
        y.iter_mut().enumerate().for_each(|(i, yi)| *yi = f(i));
    }
}

/// `y = A x` for a symmetric `A` stored with both triangles: column `i` is row `i`, so
/// `y_i = Σ_k A_ki x_k` is a gather over column `i` and the rows run in parallel.
/// Equals [`multiply_into`] up to rounding (each `y_i` summed in another order).
/// `A` square of order `x.len() = y.len()`; for a non-symmetric `A` this is `Aᵀ x`.
pub fn multiply_symmetric_into(a: &SparseMatrix, x: &[f64], y: &mut [f64]) {
    let (col_ptr, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    fill_rows(y, |i| {
        (col_ptr[i]..col_ptr[i + 1])
            .map(|k| vals[k] * x[rows[k]])
            .sum()
    });
}

/// `Pᵀ`, the argument of [`prolong_add_transposed`] (form it once per prolongation; as
/// many entries as `P`).
pub fn transpose_of(p: &SparseMatrix) -> SparseMatrix {
    transpose(p)
}

/// `y += P x` given `pt = Pᵀ` ([`transpose_of`], formed once per prolongation): column `i`
/// of `Pᵀ` is row `i` of `P`, a gather, so the fine rows run in parallel. Equals
/// [`prolong_add`] up to rounding.
pub fn prolong_add_transposed(pt: &SparseMatrix, x: &[f64], y: &mut [f64]) {
    use rayon::prelude::*;
    let (col_ptr, rows, vals) = (pt.symbolic().col_ptr(), pt.symbolic().row_idx(), pt.val());
    let row = |i: usize| -> f64 {
        (col_ptr[i]..col_ptr[i + 1])
            .map(|k| vals[k] * x[rows[k]])
            .sum()
    };
    if in_parallel(y.len()) {
        y.par_iter_mut()
            .enumerate()
            .with_min_len(MIN_ROWS_PER_TASK)
            .for_each(|(i, yi)| *yi += row(i));
    } else {
        y.iter_mut().enumerate().for_each(|(i, yi)| *yi += row(i));
    }
}

/// `y = Pᵀ r`, the coarse entries in parallel: the same sums, in the same order, as
/// [`restrict`] (equal to the last bit).
pub fn restrict_parallel(p: &SparseMatrix, r: &[f64], y: &mut [f64]) {
    let (col_ptr, rows, vals) = (p.symbolic().col_ptr(), p.symbolic().row_idx(), p.val());
    // the fine order decides whether the work is worth splitting
    if in_parallel(p.nrows()) {
        use rayon::prelude::*;
        y.par_iter_mut()
            .enumerate()
            .with_min_len(MIN_ROWS_PER_TASK / 2)
            .for_each(|(j, yj)| {
                *yj = (col_ptr[j]..col_ptr[j + 1])
                    .map(|k| vals[k] * r[rows[k]])
                    .sum()
            });
    } else {
        restrict(p, r, y);
    }
}

/// Blocks of the hybrid smoother chosen by [`Smoother::new`]: a few per thread on the
/// 2-core machines here (so that a thread delayed by another job is not waited for
/// long), few enough that the block-Jacobi coupling leaves the CG counts unchanged
/// (tested).
pub const HYBRID_BLOCKS: usize = 8;

/// A Gauss–Seidel smoother for one symmetric matrix pattern, built once per pattern:
/// lexicographic for small orders (the serial [`gauss_seidel`]), hybrid (below) for large
/// ones ([`Smoother::new`]), or multicolour ([`Smoother::coloured`]).
///
/// The hybrid one is the default: on one thread it runs at the lexicographic sweep's
/// speed and keeps its CG counts, while the multicolour sweep reads `x` out of order
/// (about 1.5–2× slower per sweep on one thread here) and, on a Hessian with an active
/// set, took 12 CG iterations where the lexicographic and hybrid ones took 10
/// (`benches/multigrid.rs -- --parallel`, docs/multigrid.md).
///
/// Multicolour: the unknowns greedily coloured so that no two of one colour are coupled
/// (`A_ij = 0` for `i ≠ j` of one colour); a sweep relaxes the colours one after the
/// other, the unknowns of a colour in parallel (they read only other colours' values).
/// That is exactly lexicographic Gauss–Seidel in the colour-sorted order, so a forward
/// sweep followed by the backward one ([`Smoother::symmetric_sweep`]) is a symmetric
/// smoother and the V-cycle stays a CG preconditioner (Saad, *Iterative Methods for
/// Sparse Linear Systems*, 2003, §12.4). The P1 graph of a right-diagonal mesh, a
/// triangular lattice, takes 3 to 4 colours this way; P2 graphs about 8 to 10.
///
/// Hybrid ([`Smoother::hybrid`]): the unknowns cut into blocks of consecutive rows, a
/// sweep is lexicographic Gauss–Seidel inside each block (in parallel) with the other
/// blocks' values from the start of the sweep (block Jacobi between blocks). The
/// forward sweep is `x += M⁻¹(b − A x)` with `M` the block diagonal of `D + L`, the
/// backward one the same with `Mᵀ`, so the pair is symmetric as well; the blocks are fixed
/// by the order, not the thread count, so the result does not depend on the pool.
#[derive(Debug)]
pub struct Smoother {
    /// The unknowns sorted by colour, increasing within a colour; empty: not multicolour.
    order: Vec<usize>,
    /// Colour `c` is `order[colour_ptr[c]..colour_ptr[c + 1]]`.
    colour_ptr: Vec<usize>,
    /// Rows per block of the hybrid smoother; 0: not hybrid.
    block: usize,
    /// The hybrid sweep's copy of `x` at its start, kept between sweeps.
    snapshot: std::sync::Mutex<Vec<f64>>,
}

impl Smoother {
    /// The smoother of `a`'s pattern (symmetric, both triangles stored): hybrid with
    /// [`HYBRID_BLOCKS`] blocks from order [`PARALLEL_MIN_ROWS`], lexicographic below.
    pub fn new(a: &SparseMatrix) -> Self {
        if a.ncols() >= PARALLEL_MIN_ROWS {
            Self::hybrid(a.ncols(), HYBRID_BLOCKS)
        } else {
            Self::lexicographic()
        }
    }

    /// The lexicographic smoother (natural order, serial) whatever the order.
    pub fn lexicographic() -> Self {
        Self {
            order: Vec::new(),
            colour_ptr: Vec::new(),
            block: 0,
            snapshot: Default::default(),
        }
    }

    /// The hybrid smoother of order `n`: `blocks` blocks of consecutive rows (at least
    /// 1), lexicographic Gauss–Seidel inside each, block Jacobi between them. Keeps one
    /// vector of order `n` (allocated at the first sweep).
    pub fn hybrid(n: usize, blocks: usize) -> Self {
        Self {
            block: n.div_ceil(blocks.max(1)).max(1),
            ..Self::lexicographic()
        }
    }

    /// The multicolour smoother whatever the order: greedy colouring in the natural
    /// order, `O(nnz)` time, `2 n` words kept.
    pub fn coloured(a: &SparseMatrix) -> Self {
        let (col_ptr, rows) = (a.symbolic().col_ptr(), a.symbolic().row_idx());
        let n = a.ncols();
        let mut colour = vec![usize::MAX; n];
        // `mark[c] == j`: colour `c` is taken by a neighbour of `j`
        let mut mark: Vec<usize> = Vec::new();
        let mut colours = 0;
        for j in 0..n {
            for &i in &rows[col_ptr[j]..col_ptr[j + 1]] {
                if i != j && colour[i] != usize::MAX {
                    mark[colour[i]] = j;
                }
            }
            let c = (0..colours).find(|&c| mark[c] != j).unwrap_or(colours);
            if c == colours {
                colours += 1;
                mark.push(usize::MAX);
            }
            colour[j] = c;
        }
        let mut colour_ptr = vec![0usize; colours + 1];
        for &c in &colour {
            colour_ptr[c + 1] += 1;
        }
        for c in 0..colours {
            colour_ptr[c + 1] += colour_ptr[c];
        }
        let mut fill = colour_ptr.clone();
        let mut order = vec![0; n];
        for (j, &c) in colour.iter().enumerate() {
            order[fill[c]] = j;
            fill[c] += 1;
        }
        Self {
            order,
            colour_ptr,
            ..Self::lexicographic()
        }
    }

    /// Number of colours (0 for the lexicographic smoother).
    pub fn colour_count(&self) -> usize {
        self.colour_ptr.len().saturating_sub(1)
    }

    /// The unknowns of colour `c`, increasing.
    pub fn colour(&self, c: usize) -> &[usize] {
        &self.order[self.colour_ptr[c]..self.colour_ptr[c + 1]]
    }

    /// One Gauss–Seidel sweep on `A x = b` in place, forward or backward (over the
    /// colours, for the multicolour smoother), `a` the matrix this smoother was built for
    /// and `inverse_diagonal` its `1 / A_jj`. The result does not depend on the number of
    /// threads.
    pub fn sweep(
        &self,
        a: &SparseMatrix,
        inverse_diagonal: &[f64],
        b: &[f64],
        x: &mut [f64],
        forward: bool,
    ) {
        if self.block > 0 {
            self.hybrid_sweep(a, inverse_diagonal, b, x, forward);
            return;
        }
        if self.order.is_empty() {
            gauss_seidel(a, inverse_diagonal, b, x, forward);
            return;
        }
        let (col_ptr, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
        let parallel = rayon::current_num_threads() > 1;
        let x = as_atomic(x);
        let relax = |j: usize| {
            let mut sum = b[j];
            for k in col_ptr[j]..col_ptr[j + 1] {
                sum -= vals[k] * f64::from_bits(x[rows[k]].load(Relaxed));
            }
            let xj = f64::from_bits(x[j].load(Relaxed)) + sum * inverse_diagonal[j];
            x[j].store(xj.to_bits(), Relaxed);
        };
        let mut run = |c: usize| {
            let unknowns = self.colour(c);
            if parallel && unknowns.len() >= 2 * MIN_ROWS_PER_TASK {
                use rayon::prelude::*;
                unknowns
                    .par_iter()
                    .with_min_len(MIN_ROWS_PER_TASK)
                    .for_each(|&j| relax(j));
            } else {
                unknowns.iter().for_each(|&j| relax(j));
            }
        };
        if forward {
            (0..self.colour_count()).for_each(&mut run);
        } else {
            (0..self.colour_count()).rev().for_each(&mut run);
        }
    }

    /// The hybrid sweep: blocks in parallel, each reading its own current values and the
    /// others' from the snapshot.
    fn hybrid_sweep(
        &self,
        a: &SparseMatrix,
        inverse_diagonal: &[f64],
        b: &[f64],
        x: &mut [f64],
        forward: bool,
    ) {
        use rayon::prelude::*;
        let (col_ptr, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
        let mut snapshot = self
            .snapshot
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        snapshot.clear();
        snapshot.extend_from_slice(x);
        let old = &snapshot[..];
        let block = self.block;
        let run = |k: usize, part: &mut [f64]| {
            let lo = k * block;
            let relax = |j: usize, part: &mut [f64]| {
                let mut sum = b[j];
                for k in col_ptr[j]..col_ptr[j + 1] {
                    let i = rows[k];
                    let xi = match i.checked_sub(lo) {
                        Some(local) if local < part.len() => part[local],
                        _ => old[i],
                    };
                    sum -= vals[k] * xi;
                }
                part[j - lo] += sum * inverse_diagonal[j];
            };
            if forward {
                (lo..lo + part.len()).for_each(|j| relax(j, part));
            } else {
                (lo..lo + part.len()).rev().for_each(|j| relax(j, part));
            }
        };
        if rayon::current_num_threads() > 1 && x.len() > block {
            x.par_chunks_mut(block)
                .enumerate()
                .for_each(|(k, part)| run(k, part));
        } else {
            x.chunks_mut(block)
                .enumerate()
                .for_each(|(k, part)| run(k, part));
        }
    }

    /// A forward sweep, then a backward one: the symmetric Gauss–Seidel step of the
    /// cycle (a symmetric operator `b ↦ x` from `x = 0`).
    pub fn symmetric_sweep(
        &self,
        a: &SparseMatrix,
        inverse_diagonal: &[f64],
        b: &[f64],
        x: &mut [f64],
    ) {
        self.sweep(a, inverse_diagonal, b, x, true);
        self.sweep(a, inverse_diagonal, b, x, false);
    }
}

use std::sync::atomic::{AtomicU64, Ordering::Relaxed};

/// `x` as atomics, so that the unknowns of one colour can be relaxed from several threads
/// while reading the others (a relaxed load or store of a `u64` is a plain move on the
/// targets here: no cost over `f64`).
fn as_atomic(x: &mut [f64]) -> &[AtomicU64] {
    const {
        assert!(std::mem::size_of::<AtomicU64>() == std::mem::size_of::<f64>());
        assert!(std::mem::align_of::<AtomicU64>() == std::mem::align_of::<f64>());
    }
    // SAFETY: same size and alignment (checked above) and every bit pattern is valid for
    // both; `x` is borrowed mutably for the lifetime of the result, so all accesses to
    // its elements go through these atomics.
    unsafe { std::slice::from_raw_parts(x.as_mut_ptr().cast::<AtomicU64>(), x.len()) }
}

#[cfg(test)]
mod parallel_tests {
    //! The parallel kernels against the serial ones on the 5-point Laplacian of a
    //! `(2^L − 1)²` grid (the P1 stiffness on right-diagonal triangles) and its Galerkin
    //! coarse operators (7-point), built here by hand, on a 2-thread pool.
    use super::*;
    use faer::sparse::Triplet;

    fn pool(threads: usize) -> rayon::ThreadPool {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
    }

    fn random_vector(n: usize, seed: u64) -> Vec<f64> {
        let mut state = seed;
        (0..n)
            .map(|_| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            })
            .collect()
    }

    /// The 5-point Laplacian on the `m × m` interior nodes (Dirichlet), plus
    /// `shift_i ≥ 0` on the diagonal (an active-set-like term).
    fn laplacian(m: usize, shift: &[f64]) -> SparseMatrix {
        let index = |i: usize, j: usize| i * m + j;
        let mut t = Vec::new();
        for i in 0..m {
            for j in 0..m {
                let k = index(i, j);
                t.push(Triplet::new(
                    k,
                    k,
                    4.0 + shift.get(k).copied().unwrap_or(0.0),
                ));
                if i > 0 {
                    t.push(Triplet::new(k, index(i - 1, j), -1.0));
                }
                if i + 1 < m {
                    t.push(Triplet::new(k, index(i + 1, j), -1.0));
                }
                if j > 0 {
                    t.push(Triplet::new(k, index(i, j - 1), -1.0));
                }
                if j + 1 < m {
                    t.push(Triplet::new(k, index(i, j + 1), -1.0));
                }
            }
        }
        SparseColMat::try_new_from_triplets(m * m, m * m, &t).unwrap()
    }

    /// P1 interpolation from the `(m − 1)/2`-grid to the `m`-grid on right-diagonal
    /// triangles: a fine node on a coarse node copies it, one on an edge (horizontal,
    /// vertical or the diagonal `(p, q)–(p + 1, q + 1)`) averages its two ends.
    // `(p + 1) / 2` beside `(p − 1) / 2`: the two ends of an edge
    #[allow(clippy::manual_div_ceil)]
    fn interpolation(m: usize) -> SparseMatrix {
        let coarse = (m - 1) / 2;
        let mut t = Vec::new();
        // node positions 1..=m on the fine grid, 0 and m + 1 the boundary
        let coarse_index = |p: usize, q: usize| -> Option<usize> {
            (p >= 1 && q >= 1 && p <= coarse && q <= coarse).then(|| (p - 1) * coarse + (q - 1))
        };
        for p in 1..=m {
            for q in 1..=m {
                let row = (p - 1) * m + (q - 1);
                let ends: Vec<(usize, usize)> = match (p % 2, q % 2) {
                    (0, 0) => vec![(p / 2, q / 2)],
                    (1, 0) => vec![((p - 1) / 2, q / 2), ((p + 1) / 2, q / 2)],
                    (0, 1) => vec![(p / 2, (q - 1) / 2), (p / 2, (q + 1) / 2)],
                    _ => vec![((p - 1) / 2, (q - 1) / 2), ((p + 1) / 2, (q + 1) / 2)],
                };
                let w = 1.0 / ends.len() as f64;
                for (a, b) in ends {
                    if let Some(col) = coarse_index(a, b) {
                        t.push(Triplet::new(row, col, w));
                    }
                }
            }
        }
        SparseColMat::try_new_from_triplets(m * m, coarse * coarse, &t).unwrap()
    }

    fn relative_difference(x: &[f64], y: &[f64]) -> f64 {
        let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        x.iter()
            .zip(y)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
            / scale
    }

    fn inverse_diagonal(a: &SparseMatrix) -> Vec<f64> {
        diagonal(a).iter().map(|d| 1.0 / d.unwrap()).collect()
    }

    fn dot(x: &[f64], y: &[f64]) -> f64 {
        x.iter().zip(y).map(|(a, b)| a * b).sum()
    }

    #[test]
    fn parallel_products_equal_the_serial_ones() {
        let m = 255;
        let a = laplacian(
            m,
            &random_vector(m * m, 3)
                .iter()
                .map(|v| v.abs())
                .collect::<Vec<_>>(),
        );
        let p = interpolation(m);
        let pt = transpose(&p);
        let coarse = galerkin(&a, &p);
        let x = random_vector(m * m, 1);
        let xc = random_vector(p.ncols(), 2);
        assert!(m * m >= PARALLEL_MIN_ROWS);
        pool(2).install(|| {
            for matrix in [&a, &coarse] {
                let n = matrix.nrows();
                let (mut serial, mut parallel) = (vec![0.0; n], vec![0.0; n]);
                multiply_into(matrix, &x[..n], &mut serial);
                multiply_symmetric_into(matrix, &x[..n], &mut parallel);
                let d = relative_difference(&serial, &parallel);
                assert!(d <= 1e-14, "A x: {d:e}");
            }
            let (mut serial, mut parallel) = (x.clone(), x.clone());
            prolong_add(&p, &xc, &mut serial);
            prolong_add_transposed(&pt, &xc, &mut parallel);
            let d = relative_difference(&serial, &parallel);
            assert!(d <= 1e-14, "x + P e: {d:e}");
            let (mut serial, mut parallel) = (vec![0.0; p.ncols()], vec![1.0; p.ncols()]);
            restrict(&p, &x, &mut serial);
            restrict_parallel(&p, &x, &mut parallel);
            assert_eq!(serial, parallel, "Pᵀ r");
        });
    }

    #[test]
    fn parallel_galerkin_products_equal_the_serial_ones_and_the_composed_products() {
        let m = 255;
        let a = laplacian(
            m,
            &random_vector(m * m, 4)
                .iter()
                .map(|v| v.abs())
                .collect::<Vec<_>>(),
        );
        // a non-nested column order too: the accumulator then spans most rows
        let p = interpolation(m);
        let q = transpose(&interpolation(m));
        let serial = pool(1).install(|| (product(&a, &p), galerkin(&a, &p), product(&q, &a)));
        let parallel = pool(2).install(|| (product(&a, &p), galerkin(&a, &p), product(&q, &a)));
        for (s, t) in [
            (&serial.0, &parallel.0),
            (&serial.1, &parallel.1),
            (&serial.2, &parallel.2),
        ] {
            assert_eq!(s.symbolic().col_ptr(), t.symbolic().col_ptr());
            assert_eq!(s.symbolic().row_idx(), t.symbolic().row_idx());
            assert_eq!(s.val(), t.val());
        }
        // (A P) x = A (P x) and (Pᵀ A P) x = Pᵀ (A (P x)), by the serial kernels
        let xc = random_vector(p.ncols(), 5);
        let mut px = vec![0.0; m * m];
        prolong_add(&p, &xc, &mut px);
        let mut apx = vec![0.0; m * m];
        multiply_into(&a, &px, &mut apx);
        let mut composed = vec![0.0; m * m];
        multiply_into(&parallel.0, &xc, &mut composed);
        let d = relative_difference(&apx, &composed);
        assert!(d <= 1e-14, "(A P) x: {d:e}");
        let mut ptapx = vec![0.0; p.ncols()];
        restrict(&p, &apx, &mut ptapx);
        let mut coarse = vec![0.0; p.ncols()];
        multiply_into(&parallel.1, &xc, &mut coarse);
        let d = relative_difference(&ptapx, &coarse);
        assert!(d <= 1e-14, "(Pᵀ A P) x: {d:e}");
    }

    #[test]
    fn colouring_separates_coupled_unknowns_and_sweeps_in_colour_order() {
        let m = 127;
        let a = laplacian(m, &[]);
        let coarse = galerkin(&a, &interpolation(m));
        for (matrix, most) in [(&a, 2), (&coarse, 4)] {
            let s = Smoother::coloured(matrix);
            assert!(
                s.colour_count() >= 2 && s.colour_count() <= most,
                "{} colours",
                s.colour_count()
            );
            let n = matrix.ncols();
            let mut colour = vec![usize::MAX; n];
            for c in 0..s.colour_count() {
                for &j in s.colour(c) {
                    assert_eq!(colour[j], usize::MAX, "unknown {j} twice");
                    colour[j] = c;
                }
            }
            let (col_ptr, rows) = (matrix.symbolic().col_ptr(), matrix.symbolic().row_idx());
            for j in 0..n {
                for &i in &rows[col_ptr[j]..col_ptr[j + 1]] {
                    assert!(
                        i == j || colour[i] != colour[j],
                        "{i} and {j} coupled, one colour"
                    );
                }
            }
            // a sweep is lexicographic Gauss–Seidel in the colour-sorted order, written
            // here as the textbook loop
            let inverse = inverse_diagonal(matrix);
            let b = random_vector(n, 5);
            let order: Vec<usize> = (0..s.colour_count())
                .flat_map(|c| s.colour(c).to_vec())
                .collect();
            let vals = matrix.val();
            let mut reference = random_vector(n, 6);
            let mut x = reference.clone();
            for forward in [true, false] {
                let mut visit = order.clone();
                if !forward {
                    visit.reverse();
                }
                for &j in &visit {
                    let mut off = 0.0;
                    let mut ajj = 0.0;
                    for k in col_ptr[j]..col_ptr[j + 1] {
                        if rows[k] == j {
                            ajj = vals[k];
                        } else {
                            off += vals[k] * reference[rows[k]];
                        }
                    }
                    reference[j] = (b[j] - off) / ajj;
                }
                pool(2).install(|| s.sweep(matrix, &inverse, &b, &mut x, forward));
                let d = relative_difference(&reference, &x);
                assert!(d <= 1e-13, "forward {forward}: {d:e}");
            }
        }
    }

    #[test]
    fn parallel_symmetric_gauss_seidel_is_symmetric_and_smooths() {
        let m = 255;
        let shift: Vec<f64> = random_vector(m * m, 7)
            .iter()
            .map(|v| 20.0 * v.abs())
            .collect();
        let a = laplacian(m, &shift);
        let coarse = galerkin(&a, &interpolation(m));
        let smoothers = |matrix: &SparseMatrix| {
            [
                Smoother::coloured(matrix),
                Smoother::hybrid(matrix.nrows(), 8),
            ]
        };
        for (matrix, s) in [&a, &coarse]
            .into_iter()
            .flat_map(|m| smoothers(m).map(|s| (m, s)))
        {
            let n = matrix.ncols();
            let inverse = inverse_diagonal(matrix);
            let apply = |b: &[f64]| {
                let mut x = vec![0.0; n];
                pool(2).install(|| s.symmetric_sweep(matrix, &inverse, b, &mut x));
                x
            };
            // xᵀ S y = yᵀ S x: S = (D − U)⁻¹ D (D − L)⁻¹ in colour order is symmetric
            let (y, z) = (random_vector(n, 11), random_vector(n, 12));
            let (sy, sz) = (apply(&y), apply(&z));
            let (zsy, ysz) = (dot(&z, &sy), dot(&y, &sz));
            let scale = dot(&y, &y).sqrt() * dot(&sz, &sz).sqrt();
            assert!(
                (zsy - ysz).abs() <= 1e-12 * scale,
                "zᵀSy = {zsy}, yᵀSz = {ysz}"
            );
            // on a random error, mostly high frequencies: the A-norm error falls at every
            // sweep and by more than half in three
            let exact = random_vector(n, 13);
            let mut b = vec![0.0; n];
            multiply_into(matrix, &exact, &mut b);
            let energy = |x: &[f64]| {
                let e: Vec<f64> = x.iter().zip(&exact).map(|(a, b)| a - b).collect();
                let mut ae = vec![0.0; n];
                multiply_into(matrix, &e, &mut ae);
                dot(&e, &ae).sqrt()
            };
            let mut x = vec![0.0; n];
            let mut errors = vec![energy(&x)];
            for _ in 0..3 {
                pool(2).install(|| s.symmetric_sweep(matrix, &inverse, &b, &mut x));
                errors.push(energy(&x));
            }
            assert!(errors.windows(2).all(|w| w[1] < w[0]), "{errors:?}");
            assert!(errors[3] <= 0.5 * errors[0], "{errors:?}");
        }
    }

    #[derive(Clone, Copy, Debug, PartialEq)]
    enum Kind {
        Serial,
        Coloured,
        Hybrid,
    }

    /// PCG on the Laplacian hierarchy (`m` down to 7) with one V(1,1) cycle per
    /// iteration: the lexicographic smoother and serial kernels, or the multicolour or
    /// hybrid (8 blocks per level) smoother and the parallel kernels. The coarsest level gets 200 symmetric
    /// sweeps (a fixed symmetric operator). Returns the iterations to 1e-10 and the
    /// final true relative residual.
    fn pcg_iterations(m: usize, shift: &[f64], kind: Kind) -> (usize, f64) {
        let coloured = kind != Kind::Serial;
        let mut levels = vec![(laplacian(m, shift), None::<(SparseMatrix, SparseMatrix)>)];
        let mut size = m;
        while size > 7 {
            let p = interpolation(size);
            let coarse = galerkin(&levels.last().unwrap().0, &p);
            levels.last_mut().unwrap().1 = Some((transpose(&p), p));
            levels.push((coarse, None));
            size = (size - 1) / 2;
        }
        let smoothers: Vec<Smoother> = levels
            .iter()
            .map(|(a, _)| match kind {
                Kind::Serial => Smoother::lexicographic(),
                Kind::Coloured => Smoother::coloured(a),
                Kind::Hybrid => Smoother::hybrid(a.nrows(), 8),
            })
            .collect();
        let inverses: Vec<Vec<f64>> = levels.iter().map(|(a, _)| inverse_diagonal(a)).collect();
        fn cycle(
            l: usize,
            levels: &[(SparseMatrix, Option<(SparseMatrix, SparseMatrix)>)],
            s: &[Smoother],
            inv: &[Vec<f64>],
            coloured: bool,
            b: &[f64],
        ) -> Vec<f64> {
            let (a, transfer) = &levels[l];
            let n = a.nrows();
            let mut x = vec![0.0; n];
            let Some((pt, p)) = transfer else {
                for _ in 0..200 {
                    s[l].symmetric_sweep(a, &inv[l], b, &mut x);
                }
                return x;
            };
            s[l].symmetric_sweep(a, &inv[l], b, &mut x);
            let mut r = vec![0.0; n];
            let mut rc = vec![0.0; p.ncols()];
            if coloured {
                multiply_symmetric_into(a, &x, &mut r);
            } else {
                multiply_into(a, &x, &mut r);
            }
            r.iter_mut().zip(b).for_each(|(ri, bi)| *ri = bi - *ri);
            if coloured {
                restrict_parallel(p, &r, &mut rc);
            } else {
                restrict(p, &r, &mut rc);
            }
            let e = cycle(l + 1, levels, s, inv, coloured, &rc);
            if coloured {
                prolong_add_transposed(pt, &e, &mut x);
            } else {
                prolong_add(p, &e, &mut x);
            }
            s[l].symmetric_sweep(a, &inv[l], b, &mut x);
            x
        }
        let a = &levels[0].0;
        let n = a.nrows();
        let b = random_vector(n, 21);
        let norm_b = dot(&b, &b).sqrt();
        let mut x = vec![0.0; n];
        let mut r = b.clone();
        let mut z = cycle(0, &levels, &smoothers, &inverses, coloured, &r);
        let mut p = z.clone();
        let mut rz = dot(&r, &z);
        let mut q = vec![0.0; n];
        for iteration in 1..=100 {
            multiply_into(a, &p, &mut q);
            let alpha = rz / dot(&p, &q);
            x.iter_mut().zip(&p).for_each(|(xi, pi)| *xi += alpha * pi);
            r.iter_mut().zip(&q).for_each(|(ri, qi)| *ri -= alpha * qi);
            if dot(&r, &r).sqrt() <= 1e-10 * norm_b {
                multiply_into(a, &x, &mut q);
                let true_residual = q
                    .iter()
                    .zip(&b)
                    .map(|(u, v)| (u - v) * (u - v))
                    .sum::<f64>()
                    .sqrt();
                return (iteration, true_residual / norm_b);
            }
            z = cycle(0, &levels, &smoothers, &inverses, coloured, &r);
            let rz_new = dot(&r, &z);
            p.iter_mut()
                .zip(&z)
                .for_each(|(pi, zi)| *pi = zi + rz_new / rz * *pi);
            rz = rz_new;
        }
        panic!("PCG did not converge in 100 iterations");
    }

    #[test]
    fn pcg_with_the_parallel_smoothers_converges_like_the_serial_one() {
        for (m, weight) in [(127, 0.0), (255, 0.0), (255, 10.0)] {
            let shift: Vec<f64> = random_vector(m * m, 31)
                .iter()
                .map(|v| if *v < -1.0 / 6.0 { 4.0 * weight } else { 0.0 })
                .collect();
            let (serial, serial_residual) = pcg_iterations(m, &shift, Kind::Serial);
            assert!(serial_residual <= 1e-9);
            assert!(serial <= 15, "serial smoother: {serial} iterations");
            for kind in [Kind::Coloured, Kind::Hybrid] {
                let (its, residual) = pool(2).install(|| pcg_iterations(m, &shift, kind));
                assert!(residual <= 1e-9, "{kind:?}: {residual:e}");
                assert!(
                    its <= serial + 3,
                    "m = {m}, w = {weight}: {kind:?} {its} against serial {serial}"
                );
                eprintln!("m = {m}, w = {weight}: CG iterations serial {serial}, {kind:?} {its}");
            }
        }
    }

    #[test]
    fn hybrid_smoother_is_lexicographic_in_one_block_and_independent_of_the_threads() {
        let m = 127;
        let a = laplacian(m, &[]);
        let n = a.ncols();
        let inverse = inverse_diagonal(&a);
        let b = random_vector(n, 41);
        let sweep = |s: &Smoother, threads: usize| {
            let mut x = random_vector(n, 42);
            pool(threads).install(|| s.symmetric_sweep(&a, &inverse, &b, &mut x));
            x
        };
        let mut lexicographic = random_vector(n, 42);
        gauss_seidel(&a, &inverse, &b, &mut lexicographic, true);
        gauss_seidel(&a, &inverse, &b, &mut lexicographic, false);
        assert_eq!(sweep(&Smoother::hybrid(n, 1), 2), lexicographic);
        let eight = Smoother::hybrid(n, 8);
        let (one, two) = (sweep(&eight, 1), sweep(&eight, 2));
        assert_eq!(one, two);
        // block Jacobi between blocks: not the lexicographic result
        assert!(relative_difference(&lexicographic, &one) > 1e-6);
    }
}
