//! Every family through the one pipeline with PETSc as its complementarity solver
//! (`fem-forms solve SCENE --backend petsc`), under `mpirun -n N` (N = 1, 2, 3 in
//! `.ci/run`): on every rank count the answer must be the native solver's to the
//! solvers' tolerance — the energy, the total contact force ∫λ_h and the contact set's
//! measure — and certified by the same KKT residual. The scenes cover the membrane
//! (P1–P0, P2–P0, P2–P1disc whose `C` has 3 × 3 blocks, and the nodal method with its
//! bounds on the primal unknowns), the Timoshenko and Euler–Bernoulli beams, the
//! Reissner–Mindlin plate, the Kirchhoff plate (Argyris, Morley), the Winkler plate and
//! Signorini contact with its multiplier on boundary edges. Where the multiplier lives
//! on the cells of triangles, each rank assembles only its own cells (PT-Scotch's
//! partition) and the whole LCP exists only in PETSc: the ranks' rows must add up to
//! PETSc's; elsewhere every rank holds the whole LCP.

use fem_models::families;
use fem_models::report::{Outcome, Settings};
use fem_petsc::lcp::{Formulation, PetscLcpSolver};
use fem_runtime::lcp::external::External;
use fem_runtime::lcp::external::ExternalSolver;
use fem_runtime::obstacle::VariationalSolver;

/// (scene, pair, mesh size, load)
const CASES: [(&str, &str, usize, Option<f64>); 16] = [
    ("membrane-radial", "p1-p0", 8, None),
    ("membrane-radial", "p2-p0", 4, None),
    ("membrane-radial", "p2-p1d", 4, None),
    ("membrane-radial", "p1-nodal", 8, None),
    ("membrane-lshape", "p1-p0", 8, None),
    // pressed flat onto ψ = 0: the nested start is the solution, its residual rounding
    ("membrane-flat", "p1-p0", 8, None),
    ("membrane-flat", "p2-p0", 8, None),
    ("timoshenko-t1e-2", "p2-p2-p0", 64, None),
    ("bernoulli-flat", "hermite-p0", 64, Some(100.0)),
    ("mindlin-disk", "p1-p2-p0", 4, None),
    ("mindlin-ss-t1e-2", "p1-p2-p0", 8, None),
    ("kirchhoff-obstacle", "argyris-p0", 8, None),
    ("kirchhoff-obstacle", "morley-p0", 16, None),
    ("winkler-square", "argyris-p0", 8, None),
    ("signorini-patch", "p1-p0", 8, None),
    ("hertz", "p1-p0", 4, None),
];

fn solve(
    scene: &str,
    pair: &str,
    n: usize,
    load: Option<f64>,
    solver: VariationalSolver,
) -> Outcome {
    let scene = families::scene(scene).unwrap_or_else(|| panic!("scene {scene}"));
    let settings = Settings {
        pair: Some(pair.into()),
        mesh_size: Some(n),
        load,
        solver,
        ..Settings::default()
    };
    families::solve(&scene, &settings)
        .unwrap_or_else(|e| panic!("{} {pair} N = {n} by {solver:?}: {e}", scene.name))
}

fn relative(a: f64, b: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs()).max(1e-300)
}

fn main() {
    let petsc: &'static PetscLcpSolver = Box::leak(Box::new(
        PetscLcpSolver::new("", None).expect("PETSc starts"),
    ));
    let (rank, size) = petsc.rank_and_size();
    let external = VariationalSolver::External(External(petsc));
    for (scene, pair, n, load) in CASES {
        let native = solve(scene, pair, n, load, VariationalSolver::SemismoothNewton).report;
        let before = petsc.records().len();
        let ours = solve(scene, pair, n, load, external).report;
        let (a, b) = (&native.solve, &ours.solve);
        assert_eq!(b.solver, "petsc", "{scene} {pair}");
        assert!(
            petsc.records().len() > before,
            "{scene} {pair}: PETSc solved nothing"
        );
        let case = format!("{scene} {pair} N = {n} on {size} ranks");
        match (a.energy, b.energy) {
            // an exact energy of 0 (membrane-flat) is rounding on both sides
            (Some(x), Some(y)) => assert!(
                relative(x, y) < 1e-9 || (x - y).abs() < 1e-12,
                "{case}: energy {x} and {y}"
            ),
            (x, y) => assert_eq!(x.is_some(), y.is_some(), "{case}: energy {x:?} and {y:?}"),
        }
        let (x, y) = (a.total_contact_force, b.total_contact_force);
        assert!(
            (x - y).abs() <= 1e-7 * x.abs().max(y.abs()).max(1e-12),
            "{case}: ∫λ {x} and {y}"
        );
        for (what, x, y) in [
            ("contact area", a.contact_area, b.contact_area),
            ("contact length", a.contact_length, b.contact_length),
        ] {
            assert_eq!(x, y, "{case}: {what}");
        }
        assert!(
            b.kkt_residual < 1e-8,
            "{case}: KKT residual {}",
            b.kkt_residual
        );
        // each rank assembled its own cells where the multiplier lives on them (on
        // triangles; the nodal method has its own path), and the ranks' rows are PETSc's
        let record = petsc.records().last().cloned().expect("a record");
        let on_cells = !matches!(scene, "signorini-patch" | "hertz")
            && !scene.starts_with("timoshenko")
            && !scene.starts_with("bernoulli")
            && pair != "p1-nodal";
        match record.rows_here {
            Some(rows) => {
                assert!(on_cells, "{case}: partitioned");
                let mut total = [rows as f64];
                petsc.sum(&mut total);
                let [n, m] = record.unknowns;
                let expected = match record.formulation {
                    Formulation::Mixed => n + m,
                    _ => n,
                };
                assert_eq!(total[0] as usize, expected, "{case}: the ranks' rows");
            }
            None => assert!(!on_cells, "{case}: assembled whole on every rank"),
        }
        if rank == 0 {
            println!(
                "{case}: {} formulation, {} assembly, {} ({} SNES its), energy {:?} vs {:?}, ∫λ {y:.12e} vs {x:.12e}, KKT {:.1e}",
                record.formulation.name(),
                if record.rows_here.is_some() { "partitioned" } else { "whole" },
                record.converged.reason,
                record.converged.iterations,
                b.energy,
                a.energy,
                b.kkt_residual
            );
        }
    }
    // a level without free primal unknowns (N = 1: every vertex on the boundary): Λ
    // directly, no PETSc solve (its solvers fail on empty matrices), as natively
    let native = solve(
        "membrane-radial",
        "p1-p0",
        1,
        None,
        VariationalSolver::SemismoothNewton,
    );
    let ours = solve("membrane-radial", "p1-p0", 1, None, external);
    assert_eq!(
        (
            ours.report.solve.energy,
            ours.report.solve.total_contact_force
        ),
        (
            native.report.solve.energy,
            native.report.solve.total_contact_force
        ),
        "membrane-radial N = 1"
    );
    // both formulations where both apply: the mixed one on P0 multipliers
    petsc.set_formulation(Some(Formulation::Mixed));
    for (scene, pair, n) in [
        ("membrane-radial", "p1-p0", 8),
        ("kirchhoff-obstacle", "morley-p0", 16),
    ] {
        let native = solve(scene, pair, n, None, VariationalSolver::SemismoothNewton).report;
        let ours = solve(scene, pair, n, None, external).report;
        let (x, y) = (
            native.solve.total_contact_force,
            ours.solve.total_contact_force,
        );
        assert!(
            (x - y).abs() <= 1e-7 * x.abs(),
            "{scene} {pair} mixed: ∫λ {x} and {y}"
        );
        let record = petsc.records().last().cloned().expect("a record");
        assert_eq!(record.formulation, Formulation::Mixed);
        if rank == 0 {
            println!(
                "{scene} {pair} N = {n} mixed: {} SNESVI its, ∫λ {y:.12e} vs {x:.12e}",
                record.converged.iterations
            );
        }
    }
    // the eliminated formulation where C has blocks: refused, named
    petsc.set_formulation(Some(Formulation::Eliminated));
    let scene = families::scene("membrane-radial").unwrap();
    let settings = Settings {
        pair: Some("p2-p1d".into()),
        mesh_size: Some(4),
        solver: external,
        ..Settings::default()
    };
    let refused = families::solve(&scene, &settings)
        .expect_err("refused")
        .to_string();
    assert!(refused.contains("diagonal positive C"), "{refused}");
    petsc.finalize();
    if rank == 0 {
        println!("pipeline: {} cases equal on {size} ranks", CASES.len());
    }
}
