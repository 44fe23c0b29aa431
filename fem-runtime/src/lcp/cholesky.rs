//! Sparse direct solves with faer: Cholesky for SPD systems, LU otherwise, with the
//! symbolic factorization computed once per pattern and reused.

use crate::error::{Error, Result};
use crate::lcp::factor_tree::FactorTree;
use crate::SparseMatrix;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::solvers::{ShapeCore, SolveCore};
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LltRef, SymbolicCholesky,
    SymmetricOrdering,
};
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::SymbolicSparseColMat;
use faer::{Conj, MatMut, Side};
use std::sync::Arc;

/// `y = A x` for a sparse matrix.
pub fn multiply(a: &SparseMatrix, x: &[f64]) -> Vec<f64> {
    let mut y = vec![0.0; a.nrows()];
    let (col_ptr, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    for (j, &xj) in x.iter().enumerate() {
        if xj != 0.0 {
            for k in col_ptr[j]..col_ptr[j + 1] {
                y[rows[k]] += vals[k] * xj;
            }
        }
    }
    y
}

/// `a + b` exactly as `(sum, error)` (Knuth's TwoSum).
#[inline]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// `a · b` exactly as `(product, error)` (fused multiply-add).
#[inline]
fn two_product(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

/// `xᵀ A y` in twice the working precision (compensated products and sums, as in
/// Ogita–Rump–Oishi's Dot2): energies `½uᵀAu` of thin structures cancel terms of size
/// `‖A‖‖u‖²` that are 10¹⁰ times the result, which plain summation cannot resolve.
pub fn quadratic_form(a: &SparseMatrix, x: &[f64], y: &[f64]) -> f64 {
    let (col_ptr, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    let (mut sum, mut error) = (0.0f64, 0.0f64);
    for (j, &yj) in y.iter().enumerate() {
        for k in col_ptr[j]..col_ptr[j + 1] {
            let (p, pe) = two_product(vals[k], yj);
            let (q, qe) = two_product(x[rows[k]], p);
            let (s, se) = two_sum(sum, q);
            sum = s;
            error += se + qe + x[rows[k]] * pe;
        }
    }
    sum + error
}

/// `b − A x` in twice the working precision, rounded once at the end: the residual of
/// iterative refinement, which in plain double would carry an error `ε‖A‖‖x‖` and cap
/// the refined solution at `εκ`.
pub fn residual_compensated(a: &SparseMatrix, x: &[f64], b: &[f64]) -> Vec<f64> {
    let (col_ptr, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    let mut sum: Vec<f64> = b.to_vec();
    let mut error = vec![0.0f64; b.len()];
    for (j, &xj) in x.iter().enumerate() {
        if xj == 0.0 {
            continue;
        }
        for k in col_ptr[j]..col_ptr[j + 1] {
            let i = rows[k];
            let (p, pe) = two_product(vals[k], xj);
            let (s, se) = two_sum(sum[i], -p);
            sum[i] = s;
            error[i] += se - pe;
        }
    }
    sum.iter().zip(&error).map(|(s, e)| s + e).collect()
}

/// `xᵀ y` in twice the working precision.
pub fn dot(x: &[f64], y: &[f64]) -> f64 {
    let (mut sum, mut error) = (0.0f64, 0.0f64);
    for (&a, &b) in x.iter().zip(y) {
        let (p, pe) = two_product(a, b);
        let (s, se) = two_sum(sum, p);
        sum = s;
        error += se + pe;
    }
    sum + error
}

/// Largest `|A_ij − A_ji|` relative to the largest `|A_ij|` (0 for a symmetric matrix).
pub fn asymmetry(a: &SparseMatrix) -> f64 {
    let (col_ptr, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    let entry = |i: usize, j: usize| -> f64 {
        let r = &rows[col_ptr[j]..col_ptr[j + 1]];
        r.binary_search(&i).map_or(0.0, |k| vals[col_ptr[j] + k])
    };
    let column = |j: usize| -> (f64, f64) {
        let (mut worst, mut largest) = (0.0f64, 0.0f64);
        for k in col_ptr[j]..col_ptr[j + 1] {
            largest = largest.max(vals[k].abs());
            worst = worst.max((vals[k] - entry(j, rows[k])).abs());
        }
        (worst, largest)
    };
    let larger = |(w, l): (f64, f64), (x, m): (f64, f64)| (w.max(x), l.max(m));
    // a maximum is exact in any order: the same result on any number of threads (at
    // 1M unknowns the check costs 0.04 s on one)
    let (worst, largest) = if a.ncols() >= 16384 && rayon::current_num_threads() > 1 {
        use rayon::prelude::*;
        (0..a.ncols())
            .into_par_iter()
            .with_min_len(4096)
            .map(column)
            .reduce(|| (0.0, 0.0), larger)
    } else {
        (0..a.ncols()).map(column).fold((0.0, 0.0), larger)
    };
    if largest == 0.0 {
        0.0
    } else {
        worst / largest
    }
}

/// `sweeps` symmetric Gauss–Seidel sweeps (forward, then backward) on `A x = b` from
/// `x = 0`, for a symmetric `A` stored with both triangles: an SPD approximate inverse
/// applied to `b`. `None` if a diagonal entry is missing or not positive.
pub fn symmetric_gauss_seidel(a: &SparseMatrix, b: &[f64], sweeps: usize) -> Option<Vec<f64>> {
    let (col_ptr, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    let n = a.ncols();
    let mut diagonal = vec![0.0; n];
    for (j, d) in diagonal.iter_mut().enumerate() {
        let column = &rows[col_ptr[j]..col_ptr[j + 1]];
        *d = column
            .binary_search(&j)
            .map_or(0.0, |k| vals[col_ptr[j] + k]);
        if d.is_nan() || *d <= 0.0 {
            return None;
        }
    }
    let mut x = vec![0.0; n];
    // column j of a symmetric matrix is its row j
    let relax = |j: usize, x: &mut [f64]| {
        let mut sum = b[j];
        for k in col_ptr[j]..col_ptr[j + 1] {
            if rows[k] != j {
                sum -= vals[k] * x[rows[k]];
            }
        }
        x[j] = sum / diagonal[j];
    };
    for _ in 0..sweeps {
        for j in 0..n {
            relax(j, &mut x);
        }
        for j in (0..n).rev() {
            relax(j, &mut x);
        }
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// Runs faer's factorizations and solves on one thread from now on (process-wide).
///
/// Measured on the 2-core machines here: the supernodal Cholesky of a 260k-unknown
/// membrane matrix takes 0.20 s on one thread and 0.35–0.43 s with faer's default
/// two-thread parallelism, whose threads spend the difference yielding to each other.
/// The CLI and the benchmarks call this first; a library user decides for themselves.
pub fn factor_sequentially() {
    faer::set_global_parallelism(faer::Par::Seq);
}

/// A Cholesky factorization `A = L Lᵀ` whose symbolic part can be reused.
#[derive(Clone)]
pub struct Cholesky {
    structure: Arc<CholeskyStructure>,
}

/// The symbolic factorization and the elimination tree of its nodes.
pub(crate) struct CholeskyStructure {
    pub(crate) symbolic: SymbolicCholesky<usize>,
    /// `None` when the factor's storage is not the one [`FactorTree`] reads.
    pub(crate) tree: Option<FactorTree>,
}

impl Cholesky {
    /// The symbolic factorization of an SPD pattern (the lower triangle is read).
    pub fn analyse(pattern: &SymbolicSparseColMat<usize>) -> Result<Self> {
        Self::analyse_with(pattern, CholeskySymbolicParams::default())
    }

    /// [`Cholesky::analyse`] with a supernodal factor whatever the pattern (faer picks
    /// a simplicial one for patterns with little fill): both layouts get tested.
    #[cfg(test)]
    pub(crate) fn analyse_supernodal(pattern: &SymbolicSparseColMat<usize>) -> Result<Self> {
        Self::analyse_with(
            pattern,
            CholeskySymbolicParams {
                supernodal_flop_ratio_threshold:
                    faer::sparse::linalg::SupernodalThreshold::FORCE_SUPERNODAL,
                ..Default::default()
            },
        )
    }

    fn analyse_with(
        pattern: &SymbolicSparseColMat<usize>,
        params: CholeskySymbolicParams,
    ) -> Result<Self> {
        let symbolic = factorize_symbolic_cholesky(
            pattern.as_ref(),
            Side::Lower,
            SymmetricOrdering::Amd,
            params,
        )
        .map_err(|e| Error::LinearSolve(format!("symbolic Cholesky: {e:?}")))?;
        let tree = FactorTree::new(&symbolic);
        Ok(Self {
            structure: Arc::new(CholeskyStructure { symbolic, tree }),
        })
    }

    /// The numeric factorization of `a` (same pattern as analysed).
    pub fn factor(&self, a: &SparseMatrix) -> Result<Factor> {
        self.factor_cholesky(a).map(Factor::Cholesky)
    }

    /// [`Cholesky::factor`] without the enum: the factor whose `L` the low-rank updates of
    /// [`crate::lcp::woodbury`] read.
    pub fn factor_cholesky(&self, a: &SparseMatrix) -> Result<CholeskyFactor> {
        let symbolic = &self.structure.symbolic;
        if a.nrows() != symbolic.nrows() || a.ncols() != symbolic.nrows() {
            return Err(Error::LinearSolve(format!(
                "a {} × {} matrix for a Cholesky analysis of order {}",
                a.nrows(),
                a.ncols(),
                symbolic.nrows()
            )));
        }
        let mut values = Vec::new();
        values
            .try_reserve_exact(symbolic.len_val())
            .map_err(|_| Error::LinearSolve("out of memory for the Cholesky factor".into()))?;
        {
            use rayon::prelude::*;
            // The factor of a 1M-unknown Hessian is 600 MB of fresh pages: their first
            // touch (a fault and a zeroing each) is spread over rayon's threads, which are
            // idle while this thread factors.
            (0..symbolic.len_val())
                .into_par_iter()
                .with_min_len(1 << 16)
                .map(|_| 0.0)
                .collect_into_vec(&mut values);
        }
        let par = faer::get_global_parallelism();
        let mut scratch = MemBuffer::try_new(
            symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default()),
        )
        .map_err(|_| Error::LinearSolve("out of memory for the Cholesky workspace".into()))?;
        symbolic
            .factorize_numeric_llt(
                &mut values,
                a.as_ref(),
                Side::Lower,
                Default::default(),
                par,
                MemStack::new(&mut scratch),
                Default::default(),
            )
            .map_err(|e| {
                Error::LinearSolve(format!("the matrix is not positive definite ({e:?})"))
            })?;
        Ok(CholeskyFactor {
            structure: self.structure.clone(),
            values,
        })
    }
}

/// A numeric Cholesky factor `P A Pᵀ = L Lᵀ` (`P` the fill-reducing ordering).
pub struct CholeskyFactor {
    pub(crate) structure: Arc<CholeskyStructure>,
    /// `L`'s values in faer's layout (supernodal blocks or simplicial columns).
    pub(crate) values: Vec<f64>,
}

impl CholeskyFactor {
    fn solve_in_place(&self, x: &mut [f64]) {
        let symbolic = &self.structure.symbolic;
        let n = x.len();
        let par = faer::get_global_parallelism();
        let mut scratch = MemBuffer::new(symbolic.solve_in_place_scratch::<f64>(1, par));
        LltRef::new(symbolic, &self.values).solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(x, n, 1),
            par,
            MemStack::new(&mut scratch),
        );
    }

    /// `A⁻¹ b`; errors when `b` is not of `A`'s order or the result is not finite.
    pub fn solve(&self, b: &[f64]) -> Result<Vec<f64>> {
        check_length(b, self.structure.symbolic.nrows())?;
        let mut x = b.to_vec();
        self.solve_in_place(&mut x);
        finite(x)
    }
}

/// An LU factorization whose symbolic part can be reused.
pub struct LuSolver {
    symbolic: SymbolicLu<usize>,
}

impl LuSolver {
    /// The symbolic factorization of a pattern.
    pub fn analyse(pattern: &SymbolicSparseColMat<usize>) -> Result<Self> {
        let symbolic = SymbolicLu::try_new(pattern.as_ref())
            .map_err(|e| Error::LinearSolve(format!("symbolic LU: {e:?}")))?;
        Ok(Self { symbolic })
    }

    /// The numeric factorization of `a` (same pattern as analysed).
    pub fn factor(&self, a: &SparseMatrix) -> Result<Factor> {
        let lu = Lu::try_new_with_symbolic(self.symbolic.clone(), a.as_ref()).map_err(|e| {
            // faer reports an allocation failure through the same error type
            let detail = format!("{e:?}");
            Error::LinearSolve(if detail.contains("OutOfMemory") {
                format!(
                    "out of memory for the LU factor of order {} ({detail}): a coarser mesh needs less",
                    a.nrows()
                )
            } else {
                format!("the matrix is singular ({detail})")
            })
        })?;
        Ok(Factor::Lu(Box::new(lu)))
    }
}

/// A numeric factorization, ready to solve.
pub enum Factor {
    /// `L Lᵀ`
    Cholesky(CholeskyFactor),
    /// `P L U Q` (boxed: it is much larger than the Cholesky factor)
    Lu(Box<Lu<usize, f64>>),
}

impl Factor {
    /// `A⁻¹ b`; errors when the result is not finite (a numerically singular matrix).
    pub fn solve(&self, b: &[f64]) -> Result<Vec<f64>> {
        match self {
            Factor::Cholesky(f) => f.solve(b),
            Factor::Lu(f) => {
                check_length(b, f.nrows())?;
                let mut x = b.to_vec();
                let n = x.len();
                f.solve_in_place_with_conj(
                    Conj::No,
                    MatMut::from_column_major_slice_mut(&mut x, n, 1),
                );
                finite(x)
            }
        }
    }

    /// `A⁻¹ b` improved by `steps` rounds of iterative refinement `x += A⁻¹(b − A x)` with
    /// the residual in twice the working precision, for the badly conditioned systems of
    /// thin structures (condition ~ t⁻²h⁻²): each round gains a factor ~εκ.
    pub fn solve_refined(&self, a: &SparseMatrix, b: &[f64], steps: usize) -> Result<Vec<f64>> {
        refined(a, b, steps, |r| self.solve(r))
    }
}

/// `x = solve(b)` improved by `steps` rounds of `x += solve(b − A x)`, the residual in
/// twice the working precision: iterative refinement for any approximate inverse of `A`.
pub fn refined(
    a: &SparseMatrix,
    b: &[f64],
    steps: usize,
    solve: impl Fn(&[f64]) -> Result<Vec<f64>>,
) -> Result<Vec<f64>> {
    let mut x = solve(b)?;
    for _ in 0..steps {
        let r = residual_compensated(a, &x, b);
        let dx = solve(&r)?;
        for (x, dx) in x.iter_mut().zip(dx) {
            *x += dx;
        }
    }
    Ok(x)
}

/// An error unless the right-hand side `b` has the matrix's order `n` (the solvers would
/// panic on a mismatch).
fn check_length(b: &[f64], n: usize) -> Result<()> {
    if b.len() == n {
        Ok(())
    } else {
        Err(Error::Input(format!(
            "a right-hand side of length {} for a matrix of order {n}",
            b.len()
        )))
    }
}

/// `x`, or an error when it is not finite (a numerically singular matrix).
fn finite(x: Vec<f64>) -> Result<Vec<f64>> {
    if x.iter().all(|v| v.is_finite()) {
        Ok(x)
    } else {
        Err(Error::LinearSolve(
            "the solution is not finite: the matrix is numerically singular".into(),
        ))
    }
}

/// Solves an SPD system by sparse Cholesky.
pub fn solve_spd(a: &SparseMatrix, b: &[f64]) -> Result<Vec<f64>> {
    Cholesky::analyse(
        &a.symbolic()
            .to_owned()
            .map_err(|e| Error::LinearSolve(format!("{e:?}")))?,
    )?
    .factor(a)?
    .solve(b)
}

/// Solves a general square system by sparse LU.
pub fn solve_lu(a: &SparseMatrix, b: &[f64]) -> Result<Vec<f64>> {
    LuSolver::analyse(
        &a.symbolic()
            .to_owned()
            .map_err(|e| Error::LinearSolve(format!("{e:?}")))?,
    )?
    .factor(a)?
    .solve(b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::SparseColMat;

    /// The asymmetry of a tridiagonal matrix of order 40000 with one entry off its
    /// mirror by 0.25 (largest entry 4): 0.0625, the same on one and on two threads (the
    /// parallel reduction), and 0 once the entry is mirrored.
    #[test]
    fn asymmetry_is_the_largest_mirror_difference_on_any_thread_count() {
        let n = 40_000;
        let matrix = |skew: f64| {
            let mut t = Vec::new();
            for i in 0..n {
                t.push(faer::sparse::Triplet::new(i, i, 4.0));
                if i + 1 < n {
                    let off = if i == 31_337 { -1.0 + skew } else { -1.0 };
                    t.push(faer::sparse::Triplet::new(i, i + 1, off));
                    t.push(faer::sparse::Triplet::new(i + 1, i, -1.0));
                }
            }
            SparseColMat::try_new_from_triplets(n, n, &t).unwrap()
        };
        let skewed = matrix(0.25);
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            assert_eq!(
                pool.install(|| asymmetry(&skewed)),
                0.0625,
                "{threads} threads"
            );
            assert_eq!(pool.install(|| asymmetry(&matrix(0.0))), 0.0);
        }
    }

    /// The compensated forms recover a result that plain summation loses entirely.
    #[test]
    fn compensated_sums_resolve_cancellation() {
        let big = 1e16;
        // xᵀ y = 1e16 + 1 − 1e16 = 1
        assert_eq!(dot(&[big, 1.0, -big], &[1.0, 1.0, 1.0]), 1.0);
        // A = [[1e16, 0], [0, 1]], x = (1, 1), y = (1, 1), minus 1e16 from a third entry
        let a = SparseColMat::<usize, f64>::try_new_from_triplets(
            3,
            3,
            &[
                faer::sparse::Triplet::new(0, 0, big),
                faer::sparse::Triplet::new(1, 1, 1.0),
                faer::sparse::Triplet::new(2, 2, -big),
            ],
        )
        .unwrap();
        assert_eq!(quadratic_form(&a, &[1.0; 3], &[1.0; 3]), 1.0);
        assert_eq!(multiply(&a, &[1.0, 2.0, 0.0]), vec![big, 2.0, 0.0]);
        // b − A x with b = A x + 1 in the small entry: exact despite the 1e16 neighbours
        assert_eq!(
            residual_compensated(&a, &[1.0, 1.0, 1.0], &[big, 2.0, -big]),
            vec![0.0, 1.0, 0.0]
        );
    }

    /// A 1D Laplacian plus a diagonal shift, stored with both triangles.
    fn laplacian(n: usize, shift: f64) -> SparseMatrix {
        let mut triplets = Vec::new();
        for i in 0..n {
            triplets.push(faer::sparse::Triplet::new(i, i, 2.0 + shift));
            if i + 1 < n {
                triplets.push(faer::sparse::Triplet::new(i, i + 1, -1.0));
                triplets.push(faer::sparse::Triplet::new(i + 1, i, -1.0));
            }
        }
        SparseColMat::try_new_from_triplets(n, n, &triplets).unwrap()
    }

    /// Symmetric Gauss–Seidel converges to the Cholesky solution, each sweep count gives
    /// a descent direction (bᵀx > 0: an SPD approximate inverse), and a matrix without a
    /// positive diagonal is refused.
    #[test]
    fn symmetric_gauss_seidel_converges_and_descends() {
        let n = 40;
        let a = laplacian(n, 0.5);
        let b: Vec<f64> = (0..n).map(|i| ((i * 7) % 5) as f64 - 2.0).collect();
        let exact = solve_spd(&a, &b).unwrap();
        let mut previous = f64::INFINITY;
        for sweeps in [1, 2, 4, 8, 40] {
            let x = symmetric_gauss_seidel(&a, &b, sweeps).unwrap();
            assert!(
                dot(&b, &x) > 0.0,
                "{sweeps} sweeps: not a descent direction"
            );
            let error = x
                .iter()
                .zip(&exact)
                .fold(0.0f64, |m, (x, e)| m.max((x - e).abs()));
            assert!(
                error < previous,
                "{sweeps} sweeps: error {error} did not shrink"
            );
            previous = error;
        }
        assert!(previous < 1e-10, "40 sweeps leave an error of {previous}");
        assert!(symmetric_gauss_seidel(&laplacian(n, -2.0), &b, 1).is_none());
    }
}
