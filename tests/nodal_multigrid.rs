//! The nodal method (p1-nodal) with its active-set steps solved by truncated multigrid
//! (issue 15; docs/multigrid.md, "The nodal method"): the same KKT-certified solution as
//! the Cholesky steps, CG iterations per step bounded independently of h, and the
//! truncated hierarchy's prolongations equal to the truncated composed ones.
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

#[path = "common/membranes.rs"]
mod membranes;

use faer::sparse::{SparseColMat, Triplet};
use fem_forms::models::report::Settings;
use fem_forms::obstacle::hierarchy::LinearSolver;
use fem_forms::obstacle::nodal::{nodal_active_set, nodal_active_set_with, truncated_hierarchy};
use fem_forms::SparseMatrix;

/// Linear interpolation from `coarse` interior nodes of a uniform 1D mesh to the
/// `2·coarse + 1` interior nodes of its refinement (Dirichlet ends removed).
fn interpolation(coarse: usize) -> SparseMatrix {
    let fine = 2 * coarse + 1;
    let mut t = Vec::new();
    for j in 0..coarse {
        t.push(Triplet::new(2 * j + 1, j, 1.0));
        t.push(Triplet::new(2 * j, j, 0.5));
        t.push(Triplet::new(2 * j + 2, j, 0.5));
    }
    SparseColMat::try_new_from_triplets(fine, coarse, &t).unwrap()
}

/// The 1D obstacle problem on `n` interior nodes of a uniform mesh of (0, 1): the
/// Laplacian's stiffness, the load −10, the obstacle −0.1 + 0.2 x at the nodes.
fn obstacle_1d(n: usize) -> (SparseMatrix, Vec<f64>, Vec<f64>) {
    let h = 1.0 / (n + 1) as f64;
    let mut t = Vec::new();
    for i in 0..n {
        t.push(Triplet::new(i, i, 2.0 / h));
        if i + 1 < n {
            t.push(Triplet::new(i, i + 1, -1.0 / h));
            t.push(Triplet::new(i + 1, i, -1.0 / h));
        }
    }
    let a = SparseColMat::try_new_from_triplets(n, n, &t).unwrap();
    let f = vec![-10.0 * h; n];
    let psi: Vec<f64> = (0..n).map(|i| -0.1 + 0.2 * (i + 1) as f64 * h).collect();
    (a, f, psi)
}

/// The report of the nodal method on `scene` at N = `n`, nested or from a cold start.
fn report(
    scene: &str,
    n: usize,
    linear_solver: LinearSolver,
    nested: bool,
) -> fem_forms::problem::Report {
    let request = Settings {
        linear_solver,
        nested,
        ..membranes::settings("p1-nodal", n)
    };
    membranes::solve(&membranes::scene(scene), &request)
        .unwrap()
        .report
        .solve
}

fn solve(n: usize, linear_solver: LinearSolver) -> (fem_forms::problem::Report, Vec<f64>) {
    let request = Settings {
        linear_solver,
        ..membranes::settings("p1-nodal", n)
    };
    let outcome = membranes::solve(&membranes::scene("membrane-radial"), &request)
        .expect("the radial membrane solves");
    let u = membranes::u(&outcome).to_vec();
    (outcome.report.solve, u)
}

/// Both linear solvers give the solution of the same nodal LCP: the vertex values
/// agree to the CG tolerance and both are KKT-certified; the multigrid run factors
/// nothing and its CG iterations per active-set step stay bounded as h halves.
#[test]
fn multigrid_steps_give_the_direct_solution_with_iterations_bounded_in_h() {
    let mut per_step = Vec::new();
    for n in [16, 32, 64, 128] {
        let (direct, u_direct) = solve(n, LinearSolver::Direct);
        let (multigrid, u_multigrid) = solve(n, LinearSolver::Multigrid);
        assert_eq!(direct.linear_solver, "direct");
        assert_eq!(multigrid.linear_solver, "multigrid", "N = {n}");
        assert_eq!(multigrid.factorizations, 0, "N = {n}: a step was factored");
        let scale = u_direct.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let difference = u_direct
            .iter()
            .zip(&u_multigrid)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(
            difference <= 1e-10 * scale,
            "N = {n}: the multigrid solution differs by {difference:e}"
        );
        for report in [&direct, &multigrid] {
            assert!(
                report.complementarity_residual <= 1e-11,
                "N = {n}: KKT residual {:e}",
                report.complementarity_residual
            );
        }
        assert_eq!(direct.iterations, multigrid.iterations, "N = {n}");
        per_step.push(multigrid.krylov_iterations as f64 / multigrid.iterations as f64);
    }
    // with the final polish to 1e-14 included; flat from N = 32 on (9 at N = 16, whose
    // hierarchy has two levels)
    assert!(
        per_step.iter().all(|&k| k <= 10.0) && per_step[3] <= per_step[1] + 1.0,
        "CG iterations per step {per_step:?}"
    );
}

/// A cold start has no coarser level: `--linear-solver multigrid` factors and says so.
#[test]
fn a_cold_start_without_hierarchy_is_reported() {
    let report = self::report("membrane-radial", 16, LinearSolver::Multigrid, false);
    assert_eq!(report.linear_solver, "direct");
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("no active-set step of the finest level was solved by multigrid")),
        "{:?}",
        report.warnings
    );
    let report = self::report("membrane-radial", 16, LinearSolver::Multigrid, true);
    assert!(report.warnings.iter().all(|w| !w.contains("multigrid")));
    // membrane-flat: every free node in contact, no system to solve by either solver
    let report = self::report("membrane-flat", 16, LinearSolver::Multigrid, true);
    assert_eq!(
        (
            report.linear_solver,
            report.factorizations,
            report.krylov_iterations
        ),
        ("none", 0, 0)
    );
}

/// The hierarchy truncated on a set of fine DOFs: its composed prolongation is the
/// full composed prolongation with the dropped rows zeroed, on the kept coarse columns,
/// and every removed coarse column of the full one is zero after truncation.
#[test]
fn the_truncated_hierarchy_composes_to_the_truncated_prolongation() {
    // 15 → 7 → 3 → 1 interior nodes
    let chain = vec![interpolation(7), interpolation(3), interpolation(1)];
    // a contact set: fine nodes 0..=6 and 12
    let dropped: Vec<bool> = (0..15).map(|i| i <= 6 || i == 12).collect();
    let truncated = truncated_hierarchy(&chain, &dropped);
    let dense = |p: &SparseMatrix| -> Vec<Vec<f64>> {
        let mut m = vec![vec![0.0; p.ncols()]; p.nrows()];
        let (ptr, rows, vals) = (p.symbolic().col_ptr(), p.symbolic().row_idx(), p.val());
        for j in 0..p.ncols() {
            for k in ptr[j]..ptr[j + 1] {
                m[rows[k]][j] = vals[k];
            }
        }
        m
    };
    let compose = |a: &Vec<Vec<f64>>, b: &Vec<Vec<f64>>| -> Vec<Vec<f64>> {
        a.iter()
            .map(|row| {
                (0..b[0].len())
                    .map(|j| row.iter().zip(b).map(|(x, r)| x * r[j]).sum())
                    .collect()
            })
            .collect()
    };
    let mut full = dense(&chain[0]);
    for (i, row) in full.iter_mut().enumerate() {
        if dropped[i] {
            row.iter_mut().for_each(|v| *v = 0.0);
        }
    }
    let mut reduced = dense(&truncated[0]);
    assert_eq!(reduced.len(), 15, "the finest level keeps its numbering");
    for l in 0..chain.len() {
        if l > 0 {
            full = compose(&full, &dense(&chain[l]));
            reduced = compose(&reduced, &dense(&truncated[l]));
        }
        // the kept columns of `full`, in order, are `reduced`'s columns
        let kept: Vec<usize> = (0..full[0].len())
            .filter(|&j| full.iter().any(|row| row[j] != 0.0))
            .collect();
        assert_eq!(kept.len(), reduced[0].len(), "level {}", l + 1);
        for (i, row) in full.iter().enumerate() {
            for (jr, &j) in kept.iter().enumerate() {
                assert!((row[j] - reduced[i][jr]).abs() < 1e-15, "level {}", l + 1);
            }
        }
        if l + 1 < chain.len() {
            assert!(truncated.len() > l + 1);
        }
    }
    // every fine DOF dropped: no coarse level remains
    assert!(truncated_hierarchy(&chain, &[true; 15]).is_empty());
}

/// On a small obstacle problem the multigrid path and the Cholesky path agree, also
/// from a start far from the solution, and a malformed hierarchy is refused by name.
#[test]
fn the_nodal_multigrid_solve_checks_its_hierarchy() {
    let (a, f, psi) = obstacle_1d(15);
    let chain = vec![interpolation(7), interpolation(3)];
    let direct = nodal_active_set(&a, &f, &psi, None, 50).unwrap();
    let multigrid = nodal_active_set_with(&a, &f, &psi, None, 50, &chain).unwrap();
    assert!(multigrid.krylov_iterations > 0);
    for (x, y) in direct.u.iter().zip(&multigrid.u) {
        assert!((x - y).abs() <= 1e-9, "{x} against {y}");
    }
    assert!(
        direct.u.iter().zip(&psi).any(|(u, p)| u == p),
        "contact occurs"
    );
    let wrong = vec![interpolation(3)];
    let e = nodal_active_set_with(&a, &f, &psi, None, 50, &wrong).unwrap_err();
    assert!(e.to_string().contains("prolongation 0 has 7 rows"), "{e}");
}

/// A start that already solves the settled system to between the polish's 1e-14 and
/// CG's 1e-10 is still polished: the result is the factored one to rounding, not the
/// start (which the first step used to return untouched, leaving the polish without a
/// hierarchy of its matrix).
#[test]
fn a_start_that_nearly_solves_the_system_is_still_polished() {
    // 63 → 31 → 15 → 7 → 3 interior nodes
    let n = 63;
    let (a, f, psi) = obstacle_1d(n);
    let chain = vec![
        interpolation(31),
        interpolation(15),
        interpolation(7),
        interpolation(3),
    ];
    let direct = nodal_active_set(&a, &f, &psi, None, 50).unwrap();
    let free: Vec<usize> = (0..n).filter(|&i| direct.u[i] > psi[i] + 1e-9).collect();
    assert!(
        free.len() > 4 && free.len() < n,
        "a free region and contact: {} free",
        free.len()
    );
    // the free nodes' residual `(A u − f)_i`, relative to ‖f‖₂
    let residual = |u: &[f64]| -> f64 {
        let au = fem_forms::lcp::cholesky::multiply(&a, u);
        let r: f64 = free.iter().map(|&i| (au[i] - f[i]).powi(2)).sum();
        let norm_f: f64 = f.iter().map(|x| x * x).sum();
        (r / norm_f).sqrt()
    };
    let mut start = direct.u.clone();
    start[free[free.len() / 2]] += 1e-13;
    let before = residual(&start);
    assert!(
        before > 1e-12 && before < 1e-10,
        "the start lies between the tolerances: {before:e}"
    );
    let multigrid = nodal_active_set_with(&a, &f, &psi, Some(&start), 50, &chain).unwrap();
    let after = residual(&multigrid.u);
    assert!(after <= 1e-12, "left at {after:e} (start {before:e})");
    assert!(
        multigrid.kkt_residual <= 1e-12,
        "{:e}",
        multigrid.kkt_residual
    );
}
