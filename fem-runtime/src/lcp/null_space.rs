//! The motions the stiffness matrix `A` gives no energy (its null space), and whether
//! the supports, the obstacle and the load leave the variational inequality a unique
//! solution.
//!
//! A body that nothing holds (a plate simply supported on one straight edge only, whose
//! motion `w = x` vanishes there; a free plate pulled away from its obstacle) has a
//! singular `A`. Its factorization then returns the rounding's inverse, a deflection of
//! 10¹⁰ with a small KKT residual, so the solvers cannot be trusted to notice: the
//! problem is judged before it is solved.
//!
//! With `K` the null space of `A` (the motions of zero energy the supports leave), the
//! energy `½UᵀAU − FᵀU` on `{BU ≥ G}` has a minimizer, unique along `K`, only if no
//! motion `r ≠ 0` of `K` both keeps every constraint (`Br ≥ 0`: it moves away from the
//! obstacle) and costs the load nothing (`Fᵀr ≥ 0`): along such an `r` the energy falls
//! without bound (`Fᵀr > 0`, no solution) or stays flat (`Fᵀr = 0`, not unique). (The
//! condition is necessary, not sufficient: a contact set of one P0 cell leaves the tilts
//! about it free.) This is the
//! compatibility condition of semicoercive variational inequalities (Fichera; Kinderlehrer
//! and Stampacchia, *An Introduction to Variational Inequalities*, ch. II; for contact,
//! Kikuchi and Oden, *Contact Problems in Elasticity*, §6.4). Without an obstacle, any
//! `K ≠ {0}` is refused.
//!
//! `K` is found by subspace (inverse) iteration with the Cholesky factor of the Jacobi
//! scaled `Â = S A S + δ I` (`S = diag(A)^{-½}`, `δ` = [`SHIFT`]: a singular `A` has no
//! Cholesky factor, and its rounding's factor is what misleads) and a Rayleigh–Ritz
//! projection with `S A S`: a Ritz value below [`ZERO_ENERGY`] is a motion without
//! energy. The Jacobi scaling makes the test blind to the units of the DOFs (Argyris'
//! second derivatives are `h²` smaller than its values).
//!
//! A body the obstacle alone holds ([`Held::ByObstacle`]) starts pressed onto it
//! ([`pressed_start`]), and its answer is checked by the balance of the load on `K`
//! ([`unbalanced_work`]); `crate::problem` does both.

use super::cholesky::{multiply, Cholesky};
use super::Lcp;
use crate::error::{Error, Result};
use crate::SparseMatrix;
use faer::sparse::{SparseColMat, Triplet};
use nalgebra::{DMatrix, SymmetricEigen};

/// The shift `δ` of the Jacobi-scaled matrix factored: far above the rounding of a
/// singular matrix's pivots (~1e-16), so that it has a factor, and below the smallest
/// eigenvalues of the held problems measured (see [`ZERO_ENERGY`]), so that the
/// iteration still picks the null space out of them.
pub const SHIFT: f64 = 1e-10;

/// A Ritz value of the Jacobi-scaled `A` (unit diagonal) at most this is a motion
/// without energy. Measured on the coarsest meshes of the built-in scenes and examples:
/// the smallest eigenvalue of a held problem is 1e-4 to 0.1 (plates, membranes,
/// contact), 2e-7 for a Timoshenko beam of t = 1e-3, 2e-11 at t = 1e-5 and 2.4e-13 at
/// t = 1e-6 (the thinnest a beam scene accepts: the shear swamps the bending as t⁻²);
/// that of a motion without energy is at most 2.4e-16 (32 to 26 731 unknowns). At
/// t = 1e-6 a free beam's two motions were not resolved (its smallest Ritz value 3.3e-14:
/// more eigenvalues than [`BLOCK`] lie under [`SHIFT`]); the check then lets the problem
/// through to the solvers' own guards.
pub const ZERO_ENERGY: f64 = 1e-14;

/// Vectors iterated together: more than the null space of any model here (a plate's
/// three rigid motions, an elastic body's three in the plane).
const BLOCK: usize = 8;

/// Inverse iteration steps: each divides the block's share of non-null eigenvectors by
/// `λ/δ` (≥ 1e4 for the matrices measured).
const STEPS: usize = 3;

/// Relative slack of the constraints `Br ≥ 0` and `Fᵀr ≥ 0` in the cone test: the null
/// space is computed to ~1e-12 of its scale; a motion of that size is rounding.
const CONE_SLACK: f64 = 1e-8;

/// A coefficient of the cone LP above this is a motion, not rounding.
const NONTRIVIAL: f64 = 1e-4;

/// The null space of the symmetric positive semidefinite `a` (columns, unit
/// Euclidean norm in the Jacobi-scaled coordinates, returned in `a`'s own). At most
/// [`BLOCK`] vectors: a larger null space is reported as [`BLOCK`] of them. `None` where
/// `a` cannot be judged: not semidefinite (a negative diagonal entry, a zero diagonal
/// entry with a nonzero in its column, or no Cholesky factor of the shifted matrix: an
/// α too large), which the solvers then report.
pub fn null_space(a: &SparseMatrix) -> Option<Vec<Vec<f64>>> {
    let n = a.nrows();
    if n == 0 {
        return Some(Vec::new());
    }
    let (ptr, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    let mut diagonal = vec![0.0; n];
    let mut empty = vec![true; n];
    for j in 0..n {
        for k in ptr[j]..ptr[j + 1] {
            if vals[k] != 0.0 {
                empty[j] = false;
            }
            if rows[k] == j {
                diagonal[j] = vals[k];
            }
        }
    }
    if diagonal.iter().any(|&d| d < 0.0 || !d.is_finite()) {
        return None;
    }
    if diagonal.iter().zip(&empty).any(|(&d, &e)| d == 0.0 && !e) {
        return None;
    }
    // an empty column is a DOF no form touches: its unit vector is in the null space
    let scale: Vec<f64> = diagonal
        .iter()
        .map(|&d| if d > 0.0 { d.sqrt().recip() } else { 1.0 })
        .collect();
    let mut triplets: Vec<Triplet<usize, usize, f64>> = Vec::with_capacity(vals.len() + n);
    for j in 0..n {
        for k in ptr[j]..ptr[j + 1] {
            triplets.push(Triplet::new(
                rows[k],
                j,
                vals[k] * scale[rows[k]] * scale[j],
            ));
        }
        triplets.push(Triplet::new(j, j, SHIFT));
    }
    let shifted = SparseColMat::try_new_from_triplets(n, n, &triplets).ok()?;
    let pattern = shifted.symbolic().to_owned().ok()?;
    let factor = Cholesky::analyse(&pattern)
        .and_then(|c| c.factor_cholesky(&shifted))
        .ok()?;
    let width = BLOCK.min(n);
    let mut seed = 0x9E37_79B9_7F4A_7C15u64;
    let mut block: Vec<Vec<f64>> = (0..width)
        .map(|_| (0..n).map(|_| uniform(&mut seed)).collect())
        .collect();
    orthonormalize(&mut block);
    for _ in 0..STEPS {
        for v in &mut block {
            *v = factor.solve(v).ok()?;
        }
        orthonormalize(&mut block);
    }
    // Rayleigh–Ritz with the unshifted S A S
    let scaled_times = |v: &[f64]| -> Vec<f64> {
        let sv: Vec<f64> = v.iter().zip(&scale).map(|(x, s)| x * s).collect();
        multiply(a, &sv)
            .iter()
            .zip(&scale)
            .map(|(x, s)| x * s)
            .collect()
    };
    let images: Vec<Vec<f64>> = block.iter().map(|v| scaled_times(v)).collect();
    let width = block.len();
    let h = DMatrix::from_fn(width, width, |i, j| {
        0.5 * (dot(&block[i], &images[j]) + dot(&block[j], &images[i]))
    });
    let eigen = SymmetricEigen::new(h);
    let mut basis = Vec::new();
    for (j, &value) in eigen.eigenvalues.iter().enumerate() {
        if value <= ZERO_ENERGY {
            let y = eigen.eigenvectors.column(j);
            let scaled: Vec<f64> = (0..n)
                .map(|i| (0..width).map(|l| y[l] * block[l][i]).sum::<f64>())
                .collect();
            basis.push(scaled.iter().zip(&scale).map(|(x, s)| x * s).collect());
        }
    }
    Some(basis)
}

/// What holds the body of an LCP that [`check_held`] accepts.
#[derive(Clone, Debug, PartialEq)]
pub enum Held {
    /// The supports: `A` has no null space (or it could not be judged).
    BySupports,
    /// The obstacle alone holds the motions of this basis of `A`'s null space (vectors of
    /// `A`'s order): Newton's matrix is singular on an active set that does not hold
    /// them, such as the empty one of a start at zero ([`pressed_start`]).
    ByObstacle(Vec<Vec<f64>>),
}

/// Refuses an LCP whose solution is not unique or does not exist because of a motion
/// without energy (see the module's docs); `obstacle` false: the problem is solved
/// without its constraints, and any such motion is refused. `mesh` names the mesh in
/// the message.
///
/// # Errors
/// [`Error::Input`] saying which of the three cases holds (no obstacle; the load pulls
/// the body off; nothing acts on the motion) and how many motions the supports leave.
pub fn check_held(lcp: &Lcp, obstacle: bool, mesh: &str) -> Result<Held> {
    let Some(basis) = null_space(&lcp.a) else {
        return Ok(Held::BySupports);
    };
    if basis.is_empty() {
        return Ok(Held::BySupports);
    }
    let count = match basis.len() {
        BLOCK => format!("at least {BLOCK} motions"),
        1 => "a motion".to_string(),
        k => format!("{k} independent motions"),
    };
    let singular = format!(
        "the supports leave {count} of the body without energy (the stiffness matrix A is singular on {mesh})"
    );
    if !obstacle || lcp.m() == 0 {
        return Err(Error::Input(format!(
            "{singular} and there is no obstacle: the solution is not unique, or there is none; support the body so that it cannot move freely"
        )));
    }
    match free_motion(lcp, &basis) {
        Some(work) if work > 0.0 => Err(Error::Input(format!(
            "{singular}, and the load pulls it along one that moves away from the obstacle (the load's work on it is positive): the energy has no minimum and there is no solution; support the body, or turn the load towards the obstacle"
        ))),
        Some(_) => Err(Error::Input(format!(
            "{singular}, and one of them moves away from the obstacle (or along it) without the load acting on it: the solution is not unique; support the body so that it cannot move freely"
        ))),
        None => Ok(Held::ByObstacle(basis)),
    }
}

/// A start pressed onto the obstacle for a body it alone holds: `U₀ = −s R c`, with `Rc`
/// a motion of the null space basis `basis` that moves into every constraint it moves
/// (`(BRc)_k > 0`) and `s` twice the least that makes each of those constraints active
/// (`BU₀ < G`). Newton's first matrix `A + BᵀC⁻¹B` is then positive definite, and its
/// first step is the body pressed onto the obstacle wherever that motion reaches it
/// (the contact family's start does the same with its rigid motions). `None` where no
/// such motion exists, or all those constraints are active at zero already.
pub fn pressed_start(lcp: &Lcp, basis: &[Vec<f64>]) -> Option<Vec<f64>> {
    let k = basis.len();
    let columns: Vec<Vec<f64>> = basis.iter().map(|r| lcp.b_times(r)).collect();
    let size = |i: usize| (0..k).map(|l| columns[l][i].abs()).fold(0.0, f64::max);
    let largest = (0..lcp.m()).map(size).fold(0.0f64, f64::max);
    let moved: Vec<usize> = (0..lcp.m())
        .filter(|&i| size(i) > CONE_SLACK * largest)
        .collect();
    if moved.is_empty() {
        return None;
    }
    let c = pressing_coefficients(&columns, &moved, size)?;
    let pressed: Vec<f64> = (0..lcp.m())
        .map(|i| (0..k).map(|l| c[l] * columns[l][i]).sum())
        .collect();
    let s = moved
        .iter()
        .map(|&i| (-lcp.g[i]).max(0.0) / pressed[i])
        .fold(0.0f64, f64::max);
    if s == 0.0 {
        return None;
    }
    let n = lcp.n();
    Some(
        (0..n)
            .map(|j| -2.0 * s * (0..k).map(|l| c[l] * basis[l][j]).sum::<f64>())
            .collect(),
    )
}

/// `c` maximizing `t` subject to `(BRc)_i ≥ t·size(i)` on the rows `moved`, `t ≤ 1`,
/// `|c| ≤ 1` (clarabel), where `t` exceeds [`NONTRIVIAL`].
fn pressing_coefficients(
    columns: &[Vec<f64>],
    moved: &[usize],
    size: impl Fn(usize) -> f64,
) -> Option<Vec<f64>> {
    let k = columns.len();
    // variables (c, t); rows −BRc/size + t ≤ 0 and t ≤ 1
    let mut rows: Vec<(Vec<f64>, f64)> = moved
        .iter()
        .map(|&i| {
            let s = size(i);
            let mut row: Vec<f64> = columns.iter().map(|column| -column[i] / s).collect();
            row.push(1.0);
            (row, 0.0)
        })
        .collect();
    let mut top = vec![0.0; k + 1];
    top[k] = 1.0;
    rows.push((top.clone(), 1.0));
    let x = lp_maximizer(&rows, &top, k)?;
    (x[k] > NONTRIVIAL).then(|| x[..k].to_vec())
}

/// The maximizer of `objectiveᵀx` subject to `row·x ≤ bound` for each `(row, bound)` of
/// `rows` and `|x_l| ≤ 1` for the first `boxed` variables, by clarabel; `None` where
/// clarabel does not solve it (the checks then let the solvers judge).
fn lp_maximizer(rows: &[(Vec<f64>, f64)], objective: &[f64], boxed: usize) -> Option<Vec<f64>> {
    use clarabel::algebra::CscMatrix;
    use clarabel::solver::{DefaultSolver, IPSolver, NonnegativeConeT, SolverStatus};
    let n = objective.len();
    let count = rows.len() + 2 * boxed;
    let mut ptr = vec![0];
    let mut row_index = Vec::new();
    let mut values = Vec::new();
    for l in 0..n {
        for (i, (row, _)) in rows.iter().enumerate() {
            if row[l] != 0.0 {
                row_index.push(i);
                values.push(row[l]);
            }
        }
        if l < boxed {
            row_index.extend([rows.len() + l, rows.len() + boxed + l]);
            values.extend([1.0, -1.0]);
        }
        ptr.push(row_index.len());
    }
    let a = CscMatrix::new(count, n, ptr, row_index, values);
    let mut b: Vec<f64> = rows.iter().map(|(_, bound)| *bound).collect();
    b.resize(count, 1.0);
    let p = CscMatrix::zeros((n, n));
    let q: Vec<f64> = objective.iter().map(|o| -o).collect();
    let settings = clarabel::solver::DefaultSettingsBuilder::default()
        .verbose(false)
        .max_iter(200)
        .build()
        .ok()?;
    let cones = [NonnegativeConeT(count)];
    let mut solver = DefaultSolver::new(&p, &q, &a, &b, &cones, settings).ok()?;
    solver.solve();
    matches!(
        solver.solution.status,
        SolverStatus::Solved | SolverStatus::AlmostSolved
    )
    .then(|| solver.solution.x.clone())
}

/// How far `(U, Λ)` is from balancing the load on the motions without energy `motions`
/// (vectors of `A`'s order): testing `AU − BᵀΛ = F` with `r`, `AU` drops out, so
/// `Fᵀr + Λᵀ(Br) = 0`; the largest `|Fᵀr + ΛᵀBr|` relative to its terms' size
/// `Σ|F_i r_i| + Σ|Λ_k (Br)_k|` (0 where both vanish). An answer of a singular system
/// whose active set lost the contact that held a motion fails it, whatever its
/// residual.
pub fn unbalanced_work(lcp: &Lcp, lambda: &[f64], motions: &[Vec<f64>]) -> f64 {
    motions
        .iter()
        .map(|r| {
            let br = lcp.b_times(r);
            let load: f64 = lcp.f.iter().zip(r).map(|(f, r)| f * r).sum();
            let reaction: f64 = lambda.iter().zip(&br).map(|(l, b)| l * b).sum();
            let size: f64 = lcp.f.iter().zip(r).map(|(f, r)| (f * r).abs()).sum::<f64>()
                + lambda
                    .iter()
                    .zip(&br)
                    .map(|(l, b)| (l * b).abs())
                    .sum::<f64>();
            // the works summed over the parts of a shared LCP (the size: a bound)
            let [load, reaction, size] = match lcp.whole(vec![load, reaction, size])[..] {
                [load, reaction, size] => [load, reaction, size],
                _ => unreachable!("three sums"),
            };
            if size > 0.0 {
                (load + reaction).abs() / size
            } else {
                0.0
            }
        })
        .fold(0.0, f64::max)
}

/// The largest work `FᵀRc` of the load on a nonzero motion `Rc` of the null space
/// spanned by `basis` that keeps `BRc ≥ 0` and `FᵀRc ≥ 0` (0 where that work is
/// rounding), where one exists. The cone `{c : BRc ≥ 0, FᵀRc ≥ 0}` is nontrivial when
/// one of the `2k` LPs `max ±c_j` over it (with `|c| ≤ 1`) exceeds [`NONTRIVIAL`].
fn free_motion(lcp: &Lcp, basis: &[Vec<f64>]) -> Option<f64> {
    let k = basis.len();
    // the rounding scale of each (B R_l)_i and Fᵀ R_l: the sums of the magnitudes of
    // their terms (DOFs of different units, as Argyris', make any norm-wise bound far
    // too large for some rows)
    let row_scales: Vec<f64> = lcp
        .b_rows
        .iter()
        .map(|row| {
            basis
                .iter()
                .map(|r| row.iter().map(|&(j, v)| (v * r[j]).abs()).sum::<f64>())
                .fold(0.0f64, f64::max)
        })
        .collect();
    let largest_work = basis
        .iter()
        .map(|r| lcp.f.iter().zip(r).map(|(f, r)| (f * r).abs()).sum::<f64>())
        .fold(0.0f64, f64::max);
    let cone = Cone::new(
        basis.iter().map(|r| lcp.b_times(r)).collect(),
        basis.iter().map(|r| dot(&lcp.f, r)).collect(),
        row_scales,
        largest_work,
    );
    let nontrivial = (0..k).any(|j| {
        [1.0, -1.0].into_iter().any(|sign| {
            let mut objective = vec![0.0; k];
            objective[j] = sign;
            cone.maximum(&objective)
                .is_some_and(|value| value > NONTRIVIAL)
        })
    });
    if !nontrivial {
        return None;
    }
    // the work is scaled to the largest of one basis vector's (1 where the load does
    // no work on any)
    let work = if cone.work_scale > 0.0 {
        let unit: Vec<f64> = cone.work.iter().map(|w| w / cone.work_scale).collect();
        cone.maximum(&unit).unwrap_or(0.0)
    } else {
        0.0
    };
    Some(if work > NONTRIVIAL { work } else { 0.0 })
}

/// `{c : B R c ≥ −slack, Fᵀ R c ≥ −slack, |c| ≤ 1}` for a null-space basis `R`: the
/// columns `B R_l` and works `Fᵀ R_l`, rows scaled to a unit largest coefficient.
struct Cone {
    columns: Vec<Vec<f64>>,
    work: Vec<f64>,
    row_scales: Vec<f64>,
    work_scale: f64,
}

impl Cone {
    /// `row_scales`: per constraint, the rounding scale of `(B R_l)_i` (the largest over
    /// `l` of `Σ_j |B_ij R_jl|`); `largest_work`: that of `Fᵀ R_l`, against which a
    /// smaller work is rounding (a load balanced on the null space).
    fn new(
        columns: Vec<Vec<f64>>,
        work: Vec<f64>,
        row_scales: Vec<f64>,
        largest_work: f64,
    ) -> Self {
        let work_scale = work.iter().fold(0.0f64, |s, &w| s.max(w.abs()));
        let work_scale = if work_scale > CONE_SLACK * largest_work {
            work_scale
        } else {
            0.0
        };
        Self {
            columns,
            work,
            row_scales,
            work_scale,
        }
    }

    /// `max objectiveᵀc` over the cone; `None` where clarabel does not solve it.
    fn maximum(&self, objective: &[f64]) -> Option<f64> {
        let k = self.columns.len();
        let m = self.columns.first().map_or(0, Vec::len);
        // −B R c ≤ slack and −Fᵀ R c ≤ slack, each row scaled to a unit largest entry
        let mut rows = Vec::with_capacity(m + 1);
        for i in 0..m {
            let size = (0..k).map(|l| self.columns[l][i].abs()).fold(0.0, f64::max);
            // a constraint the null space barely moves cannot bind it
            let scale = self.row_scales[i];
            if size > CONE_SLACK * scale {
                let row = self
                    .columns
                    .iter()
                    .map(|column| -column[i] / size)
                    .collect();
                rows.push((row, CONE_SLACK * scale / size));
            }
        }
        if self.work_scale > 0.0 {
            let row = self.work.iter().map(|w| -w / self.work_scale).collect();
            rows.push((row, CONE_SLACK));
        }
        lp_maximizer(&rows, objective, k).map(|c| dot(objective, &c))
    }
}

fn dot(x: &[f64], y: &[f64]) -> f64 {
    x.iter().zip(y).map(|(a, b)| a * b).sum()
}

/// Modified Gram–Schmidt, twice (Kahan's "twice is enough"); a vector that vanishes
/// against the others is dropped.
fn orthonormalize(block: &mut Vec<Vec<f64>>) {
    for _ in 0..2 {
        let mut kept: Vec<Vec<f64>> = Vec::with_capacity(block.len());
        for mut v in block.drain(..) {
            let before = dot(&v, &v).sqrt();
            for q in &kept {
                let c = dot(q, &v);
                v.iter_mut().zip(q).for_each(|(x, q)| *x -= c * q);
            }
            let norm = dot(&v, &v).sqrt();
            if norm > 1e-10 * before && norm > 0.0 {
                v.iter_mut().for_each(|x| *x /= norm);
                kept.push(v);
            }
        }
        *block = kept;
    }
}

/// A pseudo-random number in [−1, 1) (xorshift64*): the check is reproducible.
fn uniform(state: &mut u64) -> f64 {
    *state ^= *state >> 12;
    *state ^= *state << 25;
    *state ^= *state >> 27;
    let bits = state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11;
    bits as f64 / (1u64 << 52) as f64 - 1.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 1D Laplacian on `n` nodes with `held` Dirichlet nodes removed: the free
    /// string (no node held) has the constants as its null space.
    fn laplacian(n: usize, held: bool) -> SparseMatrix {
        let mut t = Vec::new();
        for i in 0..n {
            let mut d = 0.0;
            if i > 0 {
                t.push(Triplet::new(i, i - 1, -1.0));
                d += 1.0;
            }
            if i + 1 < n {
                t.push(Triplet::new(i, i + 1, -1.0));
                d += 1.0;
            }
            if held && i == 0 {
                d += 1.0;
            }
            t.push(Triplet::new(i, i, d));
        }
        SparseColMat::try_new_from_triplets(n, n, &t).unwrap()
    }

    fn lcp(a: SparseMatrix, f: Vec<f64>, b_rows: Vec<Vec<(usize, f64)>>) -> Lcp {
        let m = b_rows.len();
        Lcp {
            a,
            b_rows: b_rows.into(),
            c: vec![1e-3; m],
            c_blocks: super::super::CouplingBlocks::none(),
            f,
            g: vec![0.0; m],
            share: None,
            near_null_space: Vec::new(),
        }
    }

    #[test]
    fn a_free_string_has_the_constants_and_a_held_one_nothing() {
        let free = null_space(&laplacian(50, false)).unwrap();
        assert_eq!(free.len(), 1);
        let r = &free[0];
        let spread = r.iter().fold(0.0f64, |m, x| m.max((x - r[0]).abs()));
        assert!(
            spread < 1e-8 * r[0].abs(),
            "not a constant: spread {spread}"
        );
        assert!(null_space(&laplacian(50, true)).unwrap().is_empty());
    }

    #[test]
    fn two_free_strings_have_two_motions_and_badly_scaled_dofs_change_nothing() {
        // two decoupled free strings, one in units 1e6 times the other's
        let n = 30;
        let mut t = Vec::new();
        for (offset, unit) in [(0, 1.0), (n, 1e12)] {
            let a = laplacian(n, false);
            for j in 0..n {
                for k in a.symbolic().col_ptr()[j]..a.symbolic().col_ptr()[j + 1] {
                    let i = a.symbolic().row_idx()[k];
                    t.push(Triplet::new(i + offset, j + offset, a.val()[k] * unit));
                }
            }
        }
        let a = SparseColMat::try_new_from_triplets(2 * n, 2 * n, &t).unwrap();
        assert_eq!(null_space(&a).unwrap().len(), 2);
    }

    #[test]
    fn an_indefinite_matrix_is_not_judged() {
        let t = [Triplet::new(0, 0, 1.0), Triplet::new(1, 1, -1.0)];
        let a = SparseColMat::try_new_from_triplets(2, 2, &t).unwrap();
        assert!(null_space(&a).is_none());
    }

    #[test]
    fn the_obstacle_holds_a_string_pushed_onto_it_not_one_pulled_off() {
        // u ≥ 0 at every node (B = I), a load pushing down holds it; up, nothing does
        let n = 20;
        let rows: Vec<Vec<(usize, f64)>> = (0..n).map(|i| vec![(i, 1.0)]).collect();
        let down = lcp(laplacian(n, false), vec![-1.0; n], rows.clone());
        assert!(matches!(
            check_held(&down, true, "test").unwrap(),
            Held::ByObstacle(_)
        ));
        let up = lcp(laplacian(n, false), vec![1.0; n], rows.clone());
        let e = check_held(&up, true, "test").unwrap_err().to_string();
        assert!(e.contains("no solution"), "{e}");
        // no load: lifted by any constant, not unique
        let none = lcp(laplacian(n, false), vec![0.0; n], rows);
        let e = check_held(&none, true, "test").unwrap_err().to_string();
        assert!(e.contains("not unique"), "{e}");
        // without the obstacle, refused whatever the load
        let e = check_held(&down, false, "test").unwrap_err().to_string();
        assert!(e.contains("no obstacle"), "{e}");
    }

    #[test]
    fn an_obstacle_at_one_node_holds_a_string_pushed_onto_it() {
        // the constraint at the middle node only: a load pushing down is held there
        let n = 21;
        let held = lcp(laplacian(n, false), vec![-1.0; n], vec![vec![(10, 1.0)]]);
        assert!(matches!(
            check_held(&held, true, "test").unwrap(),
            Held::ByObstacle(_)
        ));
        // an obstacle row that does not see the motion (a difference of two nodes)
        let blind = lcp(
            laplacian(n, false),
            vec![-1.0; n],
            vec![vec![(3, 1.0), (4, -1.0)]],
        );
        assert!(check_held(&blind, true, "test").is_err());
    }

    #[test]
    fn the_pressed_start_makes_every_constraint_the_motion_moves_active() {
        // u ≥ −½ at every node: at zero none is active; pressed, all are
        let n = 20;
        let rows: Vec<Vec<(usize, f64)>> = (0..n).map(|i| vec![(i, 1.0)]).collect();
        let mut down = lcp(laplacian(n, false), vec![-1.0; n], rows);
        down.g = vec![-0.5; n];
        let Held::ByObstacle(basis) = check_held(&down, true, "test").unwrap() else {
            panic!("the free string is held by its obstacle alone");
        };
        let start = pressed_start(&down, &basis).unwrap();
        let bu = down.b_times(&start);
        assert!(bu.iter().zip(&down.g).all(|(b, g)| b < g), "{bu:?}");
        // already active at zero: no start needed
        down.g = vec![0.5; n];
        assert!(pressed_start(&down, &basis).is_none());
    }
}
