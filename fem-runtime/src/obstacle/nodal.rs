//! The classical nodal-constraint method: `A U = F` with `U_i ≥ ψ_i` at every free
//! node, solved by the primal–dual active-set method of Hintermüller, Ito and Kunisch
//! (SIAM J. Optim. 13, 2002), a semismooth Newton method. Each iteration fixes the
//! active nodes at the obstacle and solves the reduced system on the inactive ones,
//! either by a sparse Cholesky factorization or by conjugate gradients preconditioned
//! with truncated multigrid on the nested meshes (docs/multigrid.md, "The nodal method").

use crate::error::{Error, Result};
use crate::lcp::cholesky::{multiply, Cholesky};
use crate::lcp::{ConstraintRows, Lcp, LcpSolution};
use crate::multigrid::sparse::multiply_symmetric_into;
use crate::multigrid::{Multigrid, MultigridOptions};
use crate::obstacle::hierarchy::{MULTIGRID_MAX_ITERATIONS, MULTIGRID_TOLERANCE};
use crate::SparseMatrix;
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use std::time::Instant;

/// From this many free nodes on, the CLI's `--linear-solver auto` solves the nodal
/// method's steps by multigrid (with at least two coarser nested levels). Measured on
/// membrane-radial (2026-11-30, best of 3 or 5, machine shared): multigrid / Cholesky
/// steps 0.89 at 225 free nodes, 0.42 at 961, 0.38 at 3969, 0.68 at 16k, 0.67 at 65k,
/// 0.52 at 261k, 0.44 at 1M. Unlike the stabilized pairs' direct path, which updates one
/// factorization by low-rank terms, the nodal one factors anew at every step.
pub const NODAL_AUTO_MULTIGRID_UNKNOWNS: usize = 200;

/// The nodal method's active-set iteration with a Cholesky factorization per step.
///
/// `a` is the `n × n` stiffness matrix of the free nodes (symmetric positive definite,
/// both triangles stored), `f` the load and `psi` the obstacle at those nodes, `start` an
/// optional first iterate (for nested iteration; projected onto `U ≥ ψ`). The active
/// DOFs are eliminated by replacing their rows and columns with the diagonal, so the
/// sparsity pattern is fixed and one symbolic Cholesky serves every iteration.
///
/// # Errors
/// [`Error::Input`] for lengths that do not match `a`, [`Error::LinearSolve`] when a
/// reduced matrix cannot be factored, [`Error::NotConverged`] when the active set has
/// not settled after `max_iterations`.
pub fn nodal_active_set(
    a: &SparseMatrix,
    f: &[f64],
    psi: &[f64],
    start: Option<&[f64]>,
    max_iterations: usize,
) -> Result<LcpSolution> {
    nodal_active_set_with(a, f, psi, start, max_iterations, &[])
}

/// [`nodal_active_set`] with the reduced systems solved by multigrid-preconditioned CG
/// on the nested hierarchy `prolongations` (from level `l + 1` to level `l`, fine to
/// coarse, level 0 the numbering of `a`; empty: Cholesky, as [`nodal_active_set`]).
///
/// Each iteration's system keeps the active rows as `A_ii u_i = A_ii ψ_i`. The
/// hierarchy is *truncated* on the active set (Kornhuber's truncated multigrid, Numer.
/// Math. 69, 1994; Gräser and Kornhuber, J. Comput. Math. 27, 2009): the finest
/// prolongation loses its active rows, so coarse corrections vanish on the contact set
/// and do not pull the iterate off the obstacle; a coarse DOF whose whole support is
/// then active has an empty column and is removed with its row of the next
/// prolongation (exactly: it prolongs to zero). The coarse operators are Galerkin's,
/// `P̃ᵀ Ã P̃`, rebuilt each iteration. CG starts from the last iterate and stops at a
/// relative residual of [`MULTIGRID_TOLERANCE`]; a step that does not get there in
/// [`MULTIGRID_MAX_ITERATIONS`] is factored instead (counted in `factorizations`).
///
/// # Errors
/// As [`nodal_active_set`]; a prolongation whose row count is not the order of the
/// level it maps to.
pub fn nodal_active_set_with(
    a: &SparseMatrix,
    f: &[f64],
    psi: &[f64],
    start: Option<&[f64]>,
    max_iterations: usize,
    prolongations: &[SparseMatrix],
) -> Result<LcpSolution> {
    nodal_active_set_level(a, f, psi, start, max_iterations, prolongations, true)
}

/// [`nodal_active_set_with`] for one level of a nested solve: with `last = false` (a
/// level whose solution only starts the next, finer one) the settled system is not
/// polished beyond [`MULTIGRID_TOLERANCE`] and no KKT certificate is computed
/// (`kkt_residual` is NaN). The next level's start carries an interpolation error of
/// order `h²` anyway, far above either; at 1M unknowns the polish and the certificate
/// of the level below cost about 0.2 s. `last = true` is [`nodal_active_set_with`].
///
/// # Errors
/// As [`nodal_active_set_with`].
pub fn nodal_active_set_level(
    a: &SparseMatrix,
    f: &[f64],
    psi: &[f64],
    start: Option<&[f64]>,
    max_iterations: usize,
    prolongations: &[SparseMatrix],
    last: bool,
) -> Result<LcpSolution> {
    let clock = Instant::now();
    let n = f.len();
    check_shapes(a, f, psi, start, prolongations)?;
    let diagonal = diagonal_of(a);
    let mut cholesky = None;
    // the reduced matrices are symmetric when `a` is: checked once here rather than by
    // every hierarchy (`Multigrid::new` refuses a non-symmetric matrix, whose steps are
    // then factored)
    let multigrid = !prolongations.is_empty() && {
        let asymmetry = crate::lcp::cholesky::asymmetry(a);
        asymmetry <= 1e-12
    };
    let mut u: Vec<f64> = match start {
        Some(s) => s.iter().zip(psi).map(|(&x, &p)| x.max(p)).collect(),
        None => psi.to_vec(),
    };
    // `a u` by the parallel row gather once `a` is known to be symmetric
    let times_a = |u: &[f64]| -> Vec<f64> {
        if multigrid {
            let mut y = vec![0.0; n];
            multiply_symmetric_into(a, u, &mut y);
            y
        } else {
            multiply(a, u)
        }
    };
    let mut lambda: Vec<f64> = times_a(&u).iter().zip(f).map(|(au, fi)| au - fi).collect();
    let mut active: Vec<bool> = (0..n)
        .map(|i| lambda[i] + diagonal[i] * (psi[i] - u[i]) > 0.0)
        .collect();
    let (mut factorizations, mut krylov_iterations, mut iterative_steps) = (0, 0, 0);
    // the truncated hierarchy of the last multigrid solve, updated by the next one
    let mut hierarchy: Option<Truncated> = None;
    // Once a step's CG fails (on a new hierarchy too) the level's later steps are
    // factored at once: on a strip of cells with aspect ratio 90 the point smoother
    // fails every step, and retrying made the solve 8× slower than the direct path
    // (a Gmsh mesh: 1227 CG iterations and 39 factorizations).
    let mut steps_by_multigrid = multigrid;
    for iteration in 1..=max_iterations {
        // `compact`: the exact zeros left out of the pattern (the right-diagonal P1
        // stiffness stores its diagonal couplings as 0, 28 % of the entries, and the
        // active rows and columns keep only their diagonal): every product, sweep and
        // Galerkin product of the multigrid path skips them with no change to any
        // value. The Cholesky path keeps `a`'s pattern, analysed once.
        let reduced = |compact: bool| -> Result<(SparseMatrix, Vec<f64>)> {
            Ok(reduced_system(a, f, psi, &diagonal, &active, compact))
        };
        for i in 0..n {
            if active[i] {
                u[i] = psi[i];
            }
        }
        // the last hierarchy's fine operator is not needed for its update: freed before
        // the next one is built
        if let Some(t) = hierarchy.as_mut() {
            t.mg.release_fine();
        }
        // compact only for multigrid: the factorization is analysed on the full pattern
        let (matrix, rhs) = reduced(steps_by_multigrid)?;
        // the multigrid path takes the matrix over (its finest level), so that the
        // largest matrix is not held twice; a failed one is built again to be factored
        let solved = if !steps_by_multigrid {
            Err(Some(matrix))
        } else {
            multigrid_solve(matrix, &rhs, &u, prolongations, &active, a, &mut hierarchy)
        };
        // whether `hierarchy` holds this iteration's matrix (for the polish)
        let mut current = false;
        u = match solved {
            Ok((x, iterations, holds_matrix)) => {
                krylov_iterations += iterations;
                iterative_steps += 1;
                current = holds_matrix;
                x
            }
            Err(matrix) => {
                if steps_by_multigrid {
                    steps_by_multigrid = false;
                    hierarchy = None;
                }
                let matrix = match matrix {
                    Some(m) => m,
                    None => reduced(false)?.0,
                };
                factorizations += 1;
                factored_solve(&mut cholesky, &matrix, &rhs)?
            }
        };
        let au = times_a(&u);
        for i in 0..n {
            lambda[i] = if active[i] { au[i] - f[i] } else { 0.0 };
        }
        let next: Vec<bool> = (0..n)
            .map(|i| lambda[i] + diagonal[i] * (psi[i] - u[i]) > 0.0)
            .collect();
        if next == active {
            // the settled system solved to rounding, as a factorization would
            let polished = match hierarchy.as_ref().filter(|_| last && current) {
                Some(t) => polish(&t.mg, &rhs, &mut u),
                None => Polish::Unneeded,
            };
            if polished == Polish::Failed {
                // CG cannot reach rounding here (anisotropic cells): a factorization
                // does, rather than a solution left at MULTIGRID_TOLERANCE
                hierarchy = None;
                let (matrix, rhs) = reduced(false)?;
                factorizations += 1;
                u = factored_solve(&mut cholesky, &matrix, &rhs)?;
            }
            if let Polish::Done(iterations) = polished {
                krylov_iterations += iterations;
            }
            if polished != Polish::Unneeded {
                let au = times_a(&u);
                for i in 0..n {
                    lambda[i] = if active[i] { au[i] - f[i] } else { 0.0 };
                }
            }
            // the KKT check copies `a`: the hierarchy (a matrix as large) goes first
            drop(hierarchy);
            let kkt_residual = if last {
                nodal_lcp(a, f, psi).kkt_residual(&u, &lambda)
            } else {
                f64::NAN
            };
            return Ok(LcpSolution {
                u,
                lambda,
                iterations: iteration,
                kkt_residual,
                seconds: clock.elapsed().as_secs_f64(),
                factorizations,
                low_rank_updates: 0,
                multiplier_noise: 0.0,
                iterative_steps,
                krylov_iterations,
            });
        }
        active = next;
    }
    Err(Error::NotConverged {
        solver: "nodal primal-dual active set",
        detail: format!("no fixed active set after {max_iterations} iterations"),
    })
}

/// The shapes of a nodal obstacle problem: `psi`, `a` and a start of `f`'s length, each
/// prolongation's rows the order of the level it maps to.
///
/// # Errors
/// [`Error::Input`] naming the mismatch.
fn check_shapes(
    a: &SparseMatrix,
    f: &[f64],
    psi: &[f64],
    start: Option<&[f64]>,
    prolongations: &[SparseMatrix],
) -> Result<()> {
    let n = f.len();
    if psi.len() != n || a.nrows() != n || a.ncols() != n {
        return Err(Error::Input(format!(
            "nodal obstacle: {} obstacle values and a {} × {} matrix for {n} unknowns",
            psi.len(),
            a.nrows(),
            a.ncols()
        )));
    }
    if let Some(s) = start.filter(|s| s.len() != n) {
        return Err(Error::Input(format!(
            "nodal obstacle: a start of {} values for {n} unknowns",
            s.len()
        )));
    }
    let mut rows_expected = n;
    for (l, p) in prolongations.iter().enumerate() {
        if p.nrows() != rows_expected {
            return Err(Error::Input(format!(
                "nodal obstacle: prolongation {l} has {} rows for a level of order {rows_expected}",
                p.nrows()
            )));
        }
        rows_expected = p.ncols();
    }
    Ok(())
}

/// The diagonal of `a` (0 where it stores none).
fn diagonal_of(a: &SparseMatrix) -> Vec<f64> {
    let (col_ptr, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    (0..a.ncols())
        .map(|j| {
            (col_ptr[j]..col_ptr[j + 1])
                .find(|&k| rows[k] == j)
                .map_or(0.0, |k| vals[k])
        })
        .collect()
}

/// The system of one active-set step: `a` with the rows and columns of the `active`
/// nodes replaced by their diagonal (`u_i = ψ_i` there), and `f` less the active
/// columns times ψ. `compact`: the exact zeros left out of the pattern (the
/// right-diagonal P1 stiffness stores its diagonal couplings as 0, 28 % of the entries,
/// and the active rows and columns keep only their diagonal): every product, sweep and
/// Galerkin product of the multigrid path skips them with no change to any value. The
/// Cholesky path keeps `a`'s pattern, analysed once.
fn reduced_system(
    a: &SparseMatrix,
    f: &[f64],
    psi: &[f64],
    diagonal: &[f64],
    active: &[bool],
    compact: bool,
) -> (SparseMatrix, Vec<f64>) {
    let n = f.len();
    let (col_ptr, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    let mut rhs = f.to_vec();
    let mut new_ptr = Vec::with_capacity(n + 1);
    let mut new_rows = Vec::with_capacity(rows.len());
    let mut values = Vec::with_capacity(rows.len());
    new_ptr.push(0);
    for j in 0..n {
        for k in col_ptr[j]..col_ptr[j + 1] {
            let i = rows[k];
            if active[j] && !active[i] {
                rhs[i] -= vals[k] * psi[j];
            }
            let value = if i == j {
                diagonal[j]
            } else if active[i] || active[j] {
                0.0
            } else {
                vals[k]
            };
            if !compact || value != 0.0 || i == j {
                new_rows.push(i);
                values.push(value);
            }
        }
        new_ptr.push(new_rows.len());
    }
    for i in 0..n {
        if active[i] {
            rhs[i] = diagonal[i] * psi[i];
        }
    }
    let symbolic = SymbolicSparseColMat::new_checked(n, n, new_ptr, None, new_rows);
    (SparseColMat::new(symbolic, values), rhs)
}

/// `matrix⁻¹ rhs` by a Cholesky factorization with one step of refinement, the symbolic
/// analysis made on the first call (every matrix given has the full pattern of `A`).
fn factored_solve(
    cholesky: &mut Option<Cholesky>,
    matrix: &SparseMatrix,
    rhs: &[f64],
) -> Result<Vec<f64>> {
    if cholesky.is_none() {
        *cholesky = Some(Cholesky::analyse(
            &matrix.symbolic().to_owned().map_err(linear)?,
        )?);
    }
    let factor = cholesky.as_ref().expect("analysed above").factor(matrix)?;
    factor.solve_refined(matrix, rhs, 1)
}

fn linear(e: impl std::fmt::Debug) -> Error {
    Error::LinearSolve(format!("{e:?}"))
}

/// The LCP of the nodal method (`B = I`, `C = 0`, `G = ψ`), for its KKT residual.
pub fn nodal_lcp(a: &SparseMatrix, f: &[f64], psi: &[f64]) -> Lcp {
    nodal_lcp_on(a, f, psi, None)
}

/// [`nodal_lcp`] of one process's part of a partitioned assembly (`a`, `f` over its
/// cells alone): the constraints `U_k ≥ ψ_k` it owns (`owned[k]`; `None`: all), each
/// owned by exactly one part, so that the parts' LCPs sum to the whole one
/// ([`crate::lcp::Lcp::share`]); a constraint it does not own has an empty row and
/// `G_k = 0`.
///
/// # Panics
/// If `owned` is not one flag per unknown.
pub fn nodal_lcp_on(a: &SparseMatrix, f: &[f64], psi: &[f64], owned: Option<&[bool]>) -> Lcp {
    let n = f.len();
    let Some(owned) = owned else {
        return nodal_whole(a, f, psi);
    };
    assert_eq!(owned.len(), n, "one ownership flag per unknown");
    let mut ptr = Vec::with_capacity(n + 1);
    ptr.push(0);
    let mut entries = Vec::with_capacity(owned.iter().filter(|&&own| own).count());
    for (k, &own) in owned.iter().enumerate() {
        if own {
            entries.push((k, 1.0));
        }
        ptr.push(entries.len());
    }
    let rows = ConstraintRows::from_flat(ptr, entries).expect("offsets from 0, not decreasing");
    let g = psi
        .iter()
        .zip(owned)
        .map(|(&p, &own)| if own { p } else { 0.0 })
        .collect();
    Lcp::new(a.clone(), rows, vec![0.0; n], f.to_vec(), g)
}

/// [`nodal_lcp`] whole.
fn nodal_whole(a: &SparseMatrix, f: &[f64], psi: &[f64]) -> Lcp {
    let n = f.len();
    // `B = I` built flat: one row each, no allocation per row (1M of them at 1025²)
    let identity = ConstraintRows::from_flat((0..=n).collect(), (0..n).map(|i| (i, 1.0)).collect())
        .expect("offsets 0, 1, …, n");
    Lcp::new(
        a.clone(),
        identity,
        vec![0.0; f.len()],
        f.to_vec(),
        psi.to_vec(),
    )
}

/// A multigrid hierarchy truncated on the fixed nodes, and which fine rows of its
/// finest prolongation are still in use (`kept`: the free nodes when it was built,
/// less those truncated by updates since).
struct Truncated {
    mg: Multigrid,
    kept: Vec<bool>,
}

/// The share of the unknowns up to which the changes of the active set (new active
/// nodes, plus free nodes still truncated) are brought into the previous iteration's
/// hierarchy ([`Multigrid::truncate_fine`]) instead of building a new one. At 1M
/// unknowns a new hierarchy costs 0.13–0.16 s, the update a few µs per new active
/// node; a node freed again stays truncated (a weaker preconditioner), which the bound
/// keeps to few.
const UPDATE_LIMIT: f64 = 0.01;

/// `matrix x = rhs` by CG from `x0`, preconditioned by a V(1,1) cycle on the hierarchy
/// truncated on `active`: the previous iteration's (`previous`), updated, when the
/// active set changed on fewer than [`UPDATE_LIMIT`] of the nodes, else built anew.
/// (Reusing an earlier hierarchy *unchanged*, truncated on another active set, still
/// preconditions but measured at 1M unknowns 8 CG iterations instead of 2 after 92
/// nodes changed.) The hierarchy takes `matrix` over as its finest level (no second
/// copy) and is left in `previous`. `Ok` gives the solution, the CG iterations and
/// whether the hierarchy in `previous` now holds `matrix` (not when `x0` already
/// solves it to [`POLISH_TOLERANCE`]). `Err(None)` when no hierarchy can be built or CG does not reach
/// [`MULTIGRID_TOLERANCE`] (relative to `‖rhs‖`) even on a new one, so that the caller
/// builds the matrix again and factors it.
fn multigrid_solve(
    matrix: SparseMatrix,
    rhs: &[f64],
    x0: &[f64],
    prolongations: &[SparseMatrix],
    active: &[bool],
    stiffness: &SparseMatrix,
    previous: &mut Option<Truncated>,
) -> std::result::Result<(Vec<f64>, usize, bool), Option<SparseMatrix>> {
    let n = rhs.len();
    let mut residual = vec![0.0; n];
    multiply_symmetric_into(&matrix, x0, &mut residual);
    for (r, b) in residual.iter_mut().zip(rhs) {
        *r = b - *r;
    }
    let (norm_b, norm_r) = (norm(rhs), norm(&residual));
    // Only a start already at the polish's tolerance is returned as it is: one between
    // that and MULTIGRID_TOLERANCE still gets the hierarchy of this matrix (and a CG
    // iteration), or the settled system's polish, which needs it, would be skipped and
    // the solution left at 1e-10 instead of 1e-14.
    if norm_r <= POLISH_TOLERANCE * norm_b {
        return Ok((x0.to_vec(), 0, false));
    }
    let tolerance = (MULTIGRID_TOLERANCE * norm_b / norm_r).min(1.0);
    let mut matrix = Some(matrix);
    let mut updated = None;
    if let Some(mut t) = previous.take() {
        let newly_active: Vec<usize> = (0..n).filter(|&i| active[i] && t.kept[i]).collect();
        let stale = (0..n).filter(|&i| !active[i] && !t.kept[i]).count();
        // (a one-level hierarchy is a factorization: built anew)
        if t.mg.level_count() > 1
            && ((newly_active.len() + stale) as f64) <= UPDATE_LIMIT * n as f64
            && t.mg
                .truncate_fine(stiffness, &mut t.kept, &newly_active)
                .is_ok()
        {
            match t.mg.replace_fine(matrix.take().expect("not taken yet")) {
                Ok(()) => updated = Some(t),
                Err(_) => matrix = Some(t.mg.into_fine()),
            }
        }
    }
    let fresh = |matrix: SparseMatrix| -> std::result::Result<Truncated, Option<SparseMatrix>> {
        let hierarchy = truncated_hierarchy(prolongations, active);
        let mg = Multigrid::new_symmetric(matrix, hierarchy, MultigridOptions::default())
            .map_err(|_| None)?;
        Ok(Truncated {
            mg,
            kept: active.iter().map(|&a| !a).collect(),
        })
    };
    let solve = |t: &Truncated| -> Option<(Vec<f64>, usize)> {
        let fine =
            t.mg.operator(0)
                .expect("a multigrid hierarchy has a finest level");
        pcg(fine, &t.mg, &residual, tolerance, MULTIGRID_MAX_ITERATIONS).ok()
    };
    let (t, (d, iterations)) = match updated {
        Some(t) => match solve(&t) {
            Some(solved) => (t, solved),
            // an updated hierarchy that does not do: a new one before the factorization
            None => {
                let t = fresh(t.mg.into_fine())?;
                let solved = solve(&t).ok_or(None)?;
                (t, solved)
            }
        },
        None => {
            let t = fresh(matrix.take().expect("the hierarchy did not take it"))?;
            let solved = solve(&t).ok_or(None)?;
            (t, solved)
        }
    };
    *previous = Some(t);
    let x = x0.iter().zip(&d).map(|(x, d)| x + d).collect();
    Ok((x, iterations, true))
}

/// The relative residual to which [`polish`] takes the settled system: about what a
/// Cholesky solve with one step of refinement leaves (at 1M unknowns, 1e-10 left the
/// mean nodal error 0.3 % off the factored solution's; 1e-14 costs 4 CG iterations
/// there and matches it to 7 digits, KKT residual 1e-13).
const POLISH_TOLERANCE: f64 = 1e-14;

/// What [`polish`] did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Polish {
    /// `u` updated, in this many CG iterations.
    Done(usize),
    /// The residual was already at [`POLISH_TOLERANCE`].
    Unneeded,
    /// CG did not get there (`u` unchanged): the system must be factored.
    Failed,
}

/// CG on `mg`'s finest operator from `u` until the residual of `rhs` is
/// [`POLISH_TOLERANCE`] of `‖rhs‖`, in at most 30 iterations (4 at 1M unknowns on a
/// shape-regular mesh); `u` is updated when it got there.
fn polish(mg: &Multigrid, rhs: &[f64], u: &mut [f64]) -> Polish {
    let Some(fine) = mg.operator(0) else {
        return Polish::Failed;
    };
    let mut residual = vec![0.0; rhs.len()];
    multiply_symmetric_into(fine, u, &mut residual);
    for (r, b) in residual.iter_mut().zip(rhs) {
        *r = b - *r;
    }
    let (norm_b, norm_r) = (norm(rhs), norm(&residual));
    if norm_r <= POLISH_TOLERANCE * norm_b {
        return Polish::Unneeded;
    }
    let (d, iterations) = match pcg(fine, mg, &residual, POLISH_TOLERANCE * norm_b / norm_r, 30) {
        Ok(solved) => solved,
        Err(_) => return Polish::Failed,
    };
    for (x, d) in u.iter_mut().zip(&d) {
        *x += d;
    }
    Polish::Done(iterations)
}

/// Conjugate gradients on `a x = b` from `x = 0`, preconditioned by one cycle of
/// `preconditioner` (whose own fine operator may differ from `a`), until `‖b − a x‖ ≤ tolerance ‖b‖`. The solution and its
/// iterations, or the iterations spent when it stopped without reaching the tolerance
/// (limit, breakdown, a failed cycle).
fn pcg(
    a: &SparseMatrix,
    preconditioner: &Multigrid,
    b: &[f64],
    tolerance: f64,
    max_iterations: usize,
) -> std::result::Result<(Vec<f64>, usize), usize> {
    let n = b.len();
    let norm_b = norm(b);
    let mut x = vec![0.0; n];
    let mut r = b.to_vec();
    let mut z = vec![0.0; n];
    let mut q = vec![0.0; n];
    preconditioner.v_cycle(&r, &mut z).map_err(|_| 0usize)?;
    let mut p = z.clone();
    let mut rz = dot(&r, &z);
    for iteration in 1..=max_iterations {
        multiply_symmetric_into(a, &p, &mut q);
        let pq = dot(&p, &q);
        if !(rz > 0.0 && pq > 0.0) {
            return Err(iteration);
        }
        let alpha = rz / pq;
        for ((xi, ri), (pi, qi)) in x.iter_mut().zip(&mut r).zip(p.iter().zip(&q)) {
            *xi += alpha * pi;
            *ri -= alpha * qi;
        }
        if norm(&r) <= tolerance * norm_b {
            return Ok((x, iteration));
        }
        preconditioner.v_cycle(&r, &mut z).map_err(|_| iteration)?;
        let rz_next = dot(&r, &z);
        let beta = rz_next / rz;
        rz = rz_next;
        for (pi, zi) in p.iter_mut().zip(&z) {
            *pi = zi + beta * *pi;
        }
    }
    Err(max_iterations)
}

fn dot(x: &[f64], y: &[f64]) -> f64 {
    x.iter().zip(y).map(|(a, b)| a * b).sum()
}

fn norm(x: &[f64]) -> f64 {
    x.iter().map(|v| v * v).sum::<f64>().sqrt()
}

/// The prolongations with the rows of the `dropped` fine DOFs emptied, and on each
/// coarser level the DOFs left without an entry removed (their columns, and their rows
/// in the next prolongation): a coarse function that vanishes on every kept fine DOF
/// prolongs to zero, so removing it changes no composed prolongation. The hierarchy
/// ends above a level that loses every DOF.
pub fn truncated_hierarchy(prolongations: &[SparseMatrix], dropped: &[bool]) -> Vec<SparseMatrix> {
    // new index of each row of the current prolongation, `usize::MAX` if dropped
    // the finest level keeps its numbering: its dropped rows stay, empty
    let mut row_index: Vec<usize> = dropped
        .iter()
        .enumerate()
        .map(|(i, &d)| if d { usize::MAX } else { i })
        .collect();
    let mut rows_out = dropped.len();
    let mut out = Vec::with_capacity(prolongations.len());
    for p in prolongations {
        let (col_ptr, rows, vals) = (p.symbolic().col_ptr(), p.symbolic().row_idx(), p.val());
        let mut new_ptr = Vec::with_capacity(p.ncols() + 1);
        let mut new_rows = Vec::with_capacity(rows.len());
        let mut new_vals = Vec::with_capacity(rows.len());
        let mut column_index = vec![usize::MAX; p.ncols()];
        new_ptr.push(0);
        for j in 0..p.ncols() {
            let before = new_rows.len();
            for k in col_ptr[j]..col_ptr[j + 1] {
                let r = row_index[rows[k]];
                if r != usize::MAX {
                    new_rows.push(r);
                    new_vals.push(vals[k]);
                }
            }
            if new_rows.len() > before {
                column_index[j] = new_ptr.len() - 1;
                new_ptr.push(new_rows.len());
            }
        }
        let columns = new_ptr.len() - 1;
        if columns == 0 {
            break;
        }
        out.push(SparseColMat::new(
            SymbolicSparseColMat::new_checked(rows_out, columns, new_ptr, None, new_rows),
            new_vals,
        ));
        row_index = column_index;
        rows_out = columns;
    }
    out
}

/// The density of the nodal forces at the vertices of `mesh`, `λ_v = r_v / ∫φ_v` (the
/// force `forces[k]` of free DOF `free[k]` over a third of the area of the cells around
/// its vertex), 0 at fixed vertices; indexed by vertex, which is the P1 DOF numbering.
/// The mass-lumped multiplier of Braess (Numer. Math. 101, 2005) that the nodal
/// method's estimator reads.
pub fn force_density_at_vertices(
    mesh: &crate::mesh::TriangleMesh,
    free: &[usize],
    forces: &[f64],
) -> Vec<f64> {
    let mut vertex_area = vec![0.0; mesh.vertex_count()];
    for c in 0..mesh.cell_count() {
        for v in mesh.cell(c) {
            vertex_area[v] += mesh.area(c) / 3.0;
        }
    }
    let mut density = vec![0.0; mesh.vertex_count()];
    for (&dof, &force) in free.iter().zip(forces) {
        density[dof] = force / vertex_area[dof];
    }
    density
}
