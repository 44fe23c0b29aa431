//! The membrane obstacle problem: the inverse-inequality constants of docs/mathematics.md, the
//! sign test with its exact solution, convergence to the exact radial solution, the
//! stabilized solve against the QP solver, and bad input.
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

#[path = "common/membranes.rs"]
mod membranes;

use fem_forms::models::data::Data;
use fem_forms::models::membrane::{membrane_p1_p0, membrane_p2_p0, membrane_p2_p1disc};
use fem_forms::models::membrane_scenes::{membrane_scene, Domain, MembraneScene, MEMBRANE_FLAT};
use fem_forms::models::report::{Report, Settings};
use fem_forms::obstacle::VariationalSolver;
use fem_forms::registry_studies::RegistryStudies;
use fem_forms::studies::rates;
use fem_forms::Model;
use membranes::{options, settings, SceneData};

fn radial() -> MembraneScene {
    membrane_scene("membrane-radial").unwrap()
}

/// The radial scene's meshes of `sizes` (N × N × 2 triangles each).
fn radial_meshes(sizes: &[usize]) -> Vec<fem_forms::TriangleMesh> {
    let scene = radial();
    sizes.iter().map(|&n| membranes::mesh(&scene, n)).collect()
}

/// `C_I` of one element of model `M` (the runtime's, from the forms `S` and `a`).
fn element_inverse_constant<M: Model>(x: &[f64; 6]) -> fem_forms::Result<f64> {
    fem_forms::stabilization::element_inverse_constant::<M>(x, &vec![0.0; M::PARAMS.len()])
}

/// `max |a − b|`.
fn max_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
}

/// Both solves converged, to the same coefficients up to 1e-9 of their size.
fn assert_same_solution(
    a: &fem_forms::obstacle::triangle::TriangleObstacleSolution,
    b: &fem_forms::obstacle::triangle::TriangleObstacleSolution,
) {
    assert!(a.kkt_residual <= 1e-10 && b.kkt_residual <= 1e-10);
    let scale = b.values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let difference = max_difference(&a.values, &b.values);
    assert!(
        difference <= 1e-9 * scale,
        "solutions differ by {difference} (scale {scale})"
    );
}

fn solve(scene: MembraneScene, pair: &str, n: usize) -> Report {
    membranes::solve(&scene, &settings(pair, n)).unwrap().report
}

/// docs/mathematics.md §1 measured `C_I` of the P2 membrane element: 48 on the equilateral
/// triangle, 96 on the right isosceles one, 240 on the 120° isosceles one; P1 has 0.
#[test]
fn inverse_constants_match_the_measured_ones() {
    let s3 = 3f64.sqrt();
    let cases = [
        ([0.0, 0.0, 1.0, 0.0, 0.5, 0.5 * s3], 48.0),
        ([0.0, 0.0, 1.0, 0.0, 0.0, 1.0], 96.0),
        ([0.0, 0.0, s3, 0.0, 0.5 * s3, 0.5], 240.0),
    ];
    for (x, expected) in cases {
        let c = element_inverse_constant::<membrane_p2_p0::Model>(&x).unwrap();
        assert!((c - expected).abs() < 1e-8 * expected, "{c} vs {expected}");
        // C_I is a property of u's element: the multiplier space does not change it
        let d = element_inverse_constant::<membrane_p2_p1disc::Model>(&x).unwrap();
        assert!((c - d).abs() < 1e-9 * c);
        // scale invariant (h² ‖Δv‖² / ‖∇v‖² has no units)
        let scaled = x.map(|v| 3.7 * v + 1.0);
        let e = element_inverse_constant::<membrane_p2_p0::Model>(&scaled).unwrap();
        assert!((c - e).abs() < 1e-8 * c);
        assert_eq!(
            element_inverse_constant::<membrane_p1_p0::Model>(&x).unwrap(),
            0.0
        );
    }
}

/// The sign test of docs/mathematics.md §1: ψ = 0, g = 0, f = −q pressing everywhere onto the
/// obstacle: exact u = 0 and λ = q, so ∫λ = 16q on (−2,2)² and the contact is total.
#[test]
fn pressing_onto_a_flat_obstacle_gives_u_zero_and_lambda_q() {
    let scene = MEMBRANE_FLAT;
    let runs = [
        ("p1-p0", VariationalSolver::SemismoothNewton),
        ("p2-p0", VariationalSolver::SemismoothNewton),
        ("p1-p0", VariationalSolver::Clarabel),
        ("p2-p0", VariationalSolver::Clarabel),
        ("p1-nodal", VariationalSolver::SemismoothNewton),
    ];
    for (pair, solver) in runs {
        let request = Settings {
            solver,
            ..settings(pair, 8)
        };
        let outcome = membranes::solve(&scene, &request).unwrap();
        let report = &outcome.report.solve;
        let largest_u = membranes::u(&outcome)
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(largest_u < 1e-8, "{pair:?} {solver:?}: u = {largest_u}");
        // the nodal method has forces at the free nodes only: their area share is
        // 16·(N−1)²/N²
        let expected = if pair == "p1-nodal" {
            48.0 * 49.0 / 64.0
        } else {
            48.0
        };
        assert!(
            (report.total_contact_force - expected).abs() < 1e-7 * expected,
            "{pair:?}: ∫λ = {}",
            report.total_contact_force
        );
        assert!(
            (report.contact_area.unwrap() - 16.0).abs() < 1e-9,
            "{pair:?}"
        );
        // the scene's exact solution gives the errors too
        assert!(report.error_h1.unwrap() < 1e-8, "{pair:?} {solver:?}");
        if pair != "p1-nodal" {
            for l in membranes::lambda(&outcome) {
                assert!((l - 3.0).abs() < 1e-6, "{pair:?} {solver:?}: λ = {l}");
            }
        }
    }
}

/// Observed rates against the exact radial solution on N = 8…64 (docs/mathematics.md §2: u ∉ H³,
/// so P2 saturates near O(h^{3/2}) in H¹; P1 is O(h) in H¹ and O(h²) in L²).
#[test]
fn radial_convergence_rates() {
    let sizes = [8, 16, 32, 64];
    let expected = [
        // (pair, H¹ rate range, L² rate at least, multiplier rate at least)
        ("p1-p0", (0.85, 1.25), 1.6, Some(0.9)),
        ("p2-p0", (1.3, 2.0), 2.0, Some(1.2)),
        ("p1-nodal", (0.85, 1.25), 1.6, None),
    ];
    for (pair, (low, high), l2_rate, multiplier_rate) in expected {
        let reports: Vec<Report> = sizes.iter().map(|&n| solve(radial(), pair, n)).collect();
        let h1: Vec<f64> = reports.iter().map(|r| r.solve.error_h1.unwrap()).collect();
        let l2: Vec<f64> = reports.iter().map(|r| r.solve.error_l2.unwrap()).collect();
        let r_h1 = rates(&h1);
        let r_l2 = rates(&l2);
        let last = |r: &[f64]| r[r.len() - 2..].iter().sum::<f64>() / 2.0;
        println!("{pair:?}: H1 {h1:?} rates {r_h1:.2?}; L2 {l2:?} rates {r_l2:.2?}");
        assert!(
            (low..=high).contains(&last(&r_h1)),
            "{pair:?}: H¹ rates {r_h1:?}"
        );
        assert!(last(&r_l2) >= l2_rate, "{pair:?}: L² rates {r_l2:?}");
        if let Some(m) = multiplier_rate {
            let e: Vec<f64> = reports
                .iter()
                .map(|r| r.solve.error_multiplier.unwrap())
                .collect();
            assert!(last(&rates(&e)) >= m, "{pair:?}: λ rates {:?}", rates(&e));
        }
        // the contact force converges to 2πA
        let force: Vec<f64> = reports
            .iter()
            .map(|r| (r.solve.total_contact_force - r.exact_contact_force.unwrap()).abs())
            .collect();
        assert!(
            force[3] < force[0] && force[3] < 2e-2 * 4.27,
            "{pair:?}: {force:?}"
        );
        for r in &reports {
            assert!(r.solve.complementarity_residual < 1e-10, "{pair:?}");
        }
    }
}

/// The stabilized P2–P0 problem solved by nested semismooth Newton and by clarabel's
/// interior-point method: the same discrete solution.
#[test]
fn newton_and_the_qp_solver_agree() {
    let request = settings("p2-p0", 16);
    let newton = membranes::solve(&radial(), &request).unwrap();
    let qp = Settings {
        solver: VariationalSolver::Clarabel,
        ..request
    };
    let qp = membranes::solve(&radial(), &qp).unwrap();
    let difference = max_difference(membranes::u(&newton), membranes::u(&qp));
    assert!(difference < 1e-7, "max |u_newton − u_qp| = {difference}");
    let force = |o: &fem_forms::models::report::Outcome| o.report.solve.total_contact_force;
    assert!((force(&newton) - force(&qp)).abs() < 1e-6);
}

fn zero(_: &[f64]) -> f64 {
    0.0
}

fn above(_: &[f64]) -> f64 {
    0.5
}

fn not_a_number(x: &[f64]) -> f64 {
    if x[0] > 0.9 {
        f64::NAN
    } else {
        0.0
    }
}

#[test]
fn bad_input_is_a_clear_error() {
    let error_of = |scene: &MembraneScene, request: &Settings| {
        membranes::solve(scene, request).err().unwrap().to_string()
    };
    let mut scene = radial();
    scene.obstacle = Data::Fn(above);
    scene.boundary = Data::Fn(zero);
    let error = error_of(&scene, &Settings::default());
    assert!(
        error.contains("infeasible") && error.contains("requires u ≥ ψ"),
        "{error}"
    );

    let mut scene = radial();
    scene.load = Data::Fn(not_a_number);
    let error = error_of(&scene, &Settings::default());
    assert!(
        error.contains("data `f`") && error.contains("is NaN at ("),
        "{error}"
    );

    let error = error_of(&radial(), &settings("p2-p0", 0));
    assert!(
        error.contains("mesh size 0") || error.contains("--mesh-size 0"),
        "{error}"
    );
    // no free node (the L-shape at N = 2): no contact force, printed as 0, not −0
    let lshape = membrane_scene("membrane-lshape").unwrap();
    let empty = membranes::solve(&lshape, &settings("p1-nodal", 2)).unwrap();
    let force = empty.report.solve.total_contact_force;
    assert!(force == 0.0 && force.is_sign_positive(), "{force}");
    // the multiplier space spelled in full names the same pair
    let registry = fem_forms::models::families::scene("membrane-radial").unwrap();
    let pair_of = |name| fem_forms::models::families::pair_of(&registry, Some(name));
    assert_eq!(pair_of("p2-p1disc").unwrap().name, "p2-p1d");
    assert!(pair_of("p2-p1").unwrap_err().to_string().contains("p2-p1d"));
    // beyond the memory the machine allows: refused before any work
    let error = error_of(&radial(), &settings("p2-p0", 4096));
    assert!(error.contains("GB of memory"), "{error}");
    // the machine's available memory can only lower the fixed limit
    let limit = fem_forms::problem::memory::memory_limit_bytes();
    assert!(
        limit > 0.0 && limit <= fem_forms::problem::memory::MEMORY_LIMIT_BYTES,
        "{limit}"
    );
    let with_alpha = |alpha| Settings {
        alpha: Some(alpha),
        ..settings("p2-p0", 8)
    };
    let error = error_of(&radial(), &with_alpha(-1.0));
    assert!(error.contains("α = -1"), "{error}");
    assert!(membranes::solve(&radial(), &with_alpha(f64::NAN)).is_err());
    // inside 1/C_I = 1/96 it solves; beyond it A_α is indefinite and the error says why
    let report = membranes::solve(&radial(), &with_alpha(0.009))
        .unwrap()
        .report;
    // N = 8 resolves the free boundary coarsely: u_h crossing ψ by 2% of ψ's range is
    // said, and the scene's accuracy not reached; nothing else is
    let others: Vec<&String> = report
        .solve
        .warnings
        .iter()
        .filter(|w| !w.contains("dips below ψ") && !w.contains("accuracy"))
        .collect();
    assert!(others.is_empty(), "{others:?}");
    let error = error_of(&radial(), &with_alpha(0.02));
    assert!(error.contains("outside the stability range"), "{error}");
}

/// The stability study's small version: the plain pairs have a multiplier kernel (P1–P0:
/// many modes; P2–P0: one checkerboard mode, the next value O(h) in the h-weighted
/// norm), the stabilized ones have γ ≥ α.
#[test]
fn plain_pairs_have_a_multiplier_kernel_and_stabilized_ones_do_not() {
    use fem_forms::studies::stability;
    let scene = RegistryStudies::of("membrane-radial").unwrap();
    let mut rows = stability(&scene, "p1-p0", &[4, 8]).unwrap();
    rows.extend(stability(&scene, "p2-p0", &[4, 8]).unwrap());
    for r in &rows {
        let scale = r.stabilized[1];
        assert!(r.plain[0].abs() < 1e-10 * scale, "{r:?}");
        assert!(r.stabilized[0] >= 0.999 * r.alpha, "{r:?}");
        if r.pair == "p1-p0" {
            assert!(r.plain[1].abs() < 1e-10 * scale, "{r:?}");
        } else {
            assert!(r.plain[1] > 1e-6, "{r:?}");
        }
    }
    let p2: Vec<_> = rows.iter().filter(|r| r.pair == "p2-p0").collect();
    // the second value decays like h² (inf-sup constant like h)
    let ratio = p2[0].plain[1] / p2[1].plain[1];
    assert!((2.5..6.0).contains(&ratio), "γ₂ ratio {ratio}");
}

/// The plain P2–P0 multiplier oscillates along a line through the contact set; the
/// stabilized one follows the exact λ.
#[test]
fn stabilization_removes_the_multiplier_oscillation() {
    use fem_forms::studies::{multiplier_profile, total_variation};
    let scene = RegistryStudies::of("membrane-radial").unwrap();
    let plain = multiplier_profile(&scene, "p2-p0", 32, Some(0.0)).unwrap();
    let stabilized = multiplier_profile(&scene, "p2-p0", 32, None).unwrap();
    let exact: Vec<(f64, f64)> = (0..=400)
        .map(|i| {
            let x = -2.0 + 4.0 * i as f64 / 400.0;
            (
                x,
                fem_forms::models::membrane_scenes::radial_multiplier(&[x, 0.0]),
            )
        })
        .collect();
    let (p, s, e) = (
        total_variation(&plain),
        total_variation(&stabilized),
        total_variation(&exact),
    );
    // variation beyond the exact one is oscillation
    assert!(
        p - e > 10.0 * (s - e).abs(),
        "plain {p}, stabilized {s}, exact {e}"
    );
    assert!((s - e).abs() < 0.15 * e, "stabilized {s}, exact {e}");
}

/// The α sweep's small version: inside 1/C_I every α solves, beyond it the solve
/// fails with the reason.
#[test]
fn the_alpha_sweep_shows_the_breakdown_at_one_over_ci() {
    use fem_forms::studies::alpha_sweep;
    let scene = RegistryStudies::of("membrane-radial").unwrap();
    let (rows, c_i) = alpha_sweep(
        &scene,
        "p2-p0",
        8,
        &[1e-4, 0.5 / 96.0, 0.9 / 96.0, 2.0 / 96.0],
    )
    .unwrap();
    assert!((c_i - 96.0).abs() < 1e-8);
    for row in &rows[..3] {
        assert!(row.result.is_ok(), "α = {}: {:?}", row.alpha, row.result);
    }
    let error = rows[3].result.as_ref().err().unwrap();
    assert!(error.contains("outside the stability range"), "{error}");
}

/// The generic work–precision study on a membrane scene (before, a beam-only study): the
/// three solvers of each mesh solve one discrete problem, so they must agree (PDAS and
/// clarabel's interior point are independent), and the error against the exact solution
/// falls at P2's rate for the radial obstacle problem (about h², u ∈ H^{5/2−ε}).
#[test]
fn the_work_precision_study_runs_on_a_membrane_scene() {
    use fem_forms::studies::{work_precision, METHODS};
    let scene = RegistryStudies::of("membrane-radial").unwrap();
    let rows = work_precision(&scene, "p2-p0", &[8, 16, 32], usize::MAX);
    assert_eq!(rows.len(), 3 * METHODS.len(), "every method on every mesh");
    let mut nested = Vec::new();
    for n in [8, 16, 32] {
        let errors: Vec<f64> = rows
            .iter()
            .filter(|w| w.size == n)
            .map(|w| w.result.as_ref().unwrap().error_l2.unwrap())
            .collect();
        for e in &errors[1..] {
            assert!((e / errors[0] - 1.0).abs() < 1e-5, "N = {n}: {errors:?}");
        }
        nested.push(errors[0]);
    }
    let observed = rates(&nested);
    assert!(observed.iter().all(|&r| r > 1.8), "L2 rates {observed:?}");
}

/// The registry's radial scene with the accuracy `accuracy` asked, discretized by
/// `pairs` only.
fn asking(name: &str, accuracy: f64, pairs: &[&'static str]) -> fem_forms::models::scene::Scene {
    let mut scene = fem_forms::models::families::scene(name).unwrap();
    scene.accuracy = Some(accuracy);
    scene.pairs = pairs.to_vec();
    scene
}

/// The Richardson estimate that picks a scene's mesh agrees with the exact error.
#[test]
fn the_accuracy_estimate_tracks_the_exact_error() {
    let scene = asking("membrane-radial", 2e-2, &["p1-p0", "p2-p0"]);
    let (rungs, cheapest) = fem_forms::accuracy::cheapest_for_accuracy(&scene).unwrap();
    assert!(cheapest.is_some());
    for r in &rungs {
        assert!(r.reached, "{r:?}");
        let exact = r.exact_l2.unwrap();
        assert!(exact <= 2e-2, "{r:?}");
        assert!(
            (0.5..2.0).contains(&(r.estimated_l2 / exact)),
            "estimate {} vs exact {exact}",
            r.estimated_l2
        );
    }
}

#[test]
fn vtk_output_names_every_field() {
    let outcome = membranes::solve(&radial(), &settings("p2-p0", 4)).unwrap();
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("fem-forms-vtk-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("radial.vtu");
    outcome.fields.write_vtu(&path).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    for name in ["\"u\"", "\"psi\"", "\"lambda\"", "\"contact\""] {
        assert!(text.contains(name), "{name} missing");
    }
    // a bad path is an error, and leaves nothing behind
    assert!(outcome
        .fields
        .write_vtu(&dir.join("missing/radial.vtu"))
        .is_err());
    std::fs::remove_dir_all(&dir).unwrap();
}

const SQUARE_MSH: &str = "$MeshFormat
4.1 0 8
$EndMeshFormat
$Entities
0 4 1 0
1 -2 -2 0 2 -2 0 0 0
2 2 -2 0 2 2 0 0 0
3 -2 2 0 2 2 0 0 0
4 -2 -2 0 -2 2 0 0 0
1 -2 -2 0 2 2 0 0 0
$EndEntities
$Nodes
2 5 1 5
2 1 0 4
1
2
3
4
-2 -2 0
2 -2 0
2 2 0
-2 2 0
2 1 0 1
5
0.3 -0.1 0
$EndNodes
$Elements
1 4 1 4
2 1 2 4
1 1 2 5
2 2 3 5
3 3 4 5
4 4 1 5
$EndElements
";

/// The radial problem on a Gmsh mesh (four triangles around an off-centre point, so
/// no symmetry), refined by newest-vertex bisection: it converges to the exact solution,
/// and a broken file is a clear error.
#[test]
fn a_gmsh_mesh_refined_uniformly_converges() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("fem-forms-msh-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("square.msh");
    std::fs::write(&path, SQUARE_MSH).unwrap();
    let mut on_file = radial();
    on_file.domain = Domain::File(path.clone());
    let errors: Vec<f64> = (3..=5)
        .map(|refinements| {
            let report = membranes::solve(&on_file, &settings("p2-p0", refinements))
                .unwrap()
                .report
                .solve;
            assert_eq!(report.cells, 4 << (2 * refinements));
            assert!(report.complementarity_residual < 1e-10);
            // the shapes are not right isosceles: C_I differs from 96, α follows it
            assert!((report.alpha.unwrap() * report.inverse_constant - 0.5).abs() < 1e-12);
            report.error_h1.unwrap()
        })
        .collect();
    let r = rates(&errors);
    assert!(
        r.iter().all(|&r| r > 1.2),
        "H¹ errors {errors:?}, rates {r:?}"
    );
    std::fs::write(&path, "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 2").unwrap();
    let error = membranes::solve(&on_file, &settings("p2-p0", 1))
        .err()
        .unwrap()
        .to_string();
    assert!(error.contains("square.msh"), "{error}");
    std::fs::write(&path, SQUARE_MSH).unwrap();
    let error = membranes::solve(&on_file, &settings("p2-p0", 9))
        .err()
        .unwrap()
        .to_string();
    assert!(error.contains("at most 8"), "{error}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The L-shaped scene (no exact solution): every pair reaches a loose target, the
/// solutions of the pairs agree with each other within their estimated errors, and the
/// membrane touches the obstacle.
#[test]
fn the_l_shape_scene_reaches_its_accuracy_with_every_pair() {
    let pairs = ["p1-p0", "p2-p0", "p1-nodal"];
    let scene = asking("membrane-lshape", 1e-2, &pairs);
    let (rungs, cheapest) = fem_forms::accuracy::cheapest_for_accuracy(&scene).unwrap();
    assert!(cheapest.is_some());
    let mut solutions = Vec::new();
    for (pair, rung) in pairs.iter().zip(&rungs) {
        assert!(rung.reached && rung.estimated_l2 <= 1e-2, "{rung:?}");
        let request = settings(pair, rung.mesh_size);
        let outcome = fem_forms::models::families::solve(&scene, &request).unwrap();
        let report = &outcome.report.solve;
        assert!(report.contact_area.unwrap() > 0.05, "{report:?}");
        assert!(report.complementarity_residual < 1e-10);
        solutions.push((rung.mesh_size, rung.estimated_l2, outcome.fields));
    }
    for k in 1..solutions.len() {
        let (na, ea, a) = &solutions[0];
        let (nb, eb, b) = &solutions[k];
        // on the coarser mesh's vertices, which the finer one has
        let (coarse, fine) = if na <= nb { (a, b) } else { (b, a) };
        let difference = fem_forms::accuracy::nested_difference(coarse, fine).unwrap();
        assert!(
            difference <= 2.0 * (ea + eb),
            "pairs 0 and {k} differ by {difference}, estimates {ea} and {eb}"
        );
    }
}

/// The nested solve builds the finest level on a second thread while the coarser levels
/// are solved: its result must be the one of solving the levels one after the other.
#[test]
fn the_pipelined_nested_solve_equals_the_sequential_one() {
    use fem_forms::obstacle::solve_lcp;
    use fem_forms::obstacle::triangle::{
        discretize_on_triangles, prolong_on_triangles, solve_obstacle_on_triangles,
    };
    type M = membrane_p2_p0::Model;
    let scene = radial();
    let meshes = radial_meshes(&[4, 8, 16]);
    let data = SceneData::new(&scene);
    let coefficients = data.coefficients::<M>(0.5 / 96.0);
    let options = options(VariationalSolver::SemismoothNewton);
    let pipelined = solve_obstacle_on_triangles::<M>(&meshes, &coefficients, options).unwrap();
    let mut previous: Option<(_, Vec<f64>)> = None;
    let mut iterations = Vec::new();
    for mesh in &meshes {
        let d = discretize_on_triangles::<M>(mesh, &coefficients, "B_h", "L_h").unwrap();
        let start = previous
            .as_ref()
            .map(|(coarse, values)| d.primal_part(&prolong_on_triangles(coarse, values, &d)));
        let solution = solve_lcp(&d.lcp, start.as_deref(), options).unwrap();
        iterations.push((mesh.cell_count(), solution.iterations));
        let values = d.full(&solution);
        previous = Some((d, values));
    }
    let (_, sequential) = previous.unwrap();
    assert_eq!(pipelined.levels, iterations);
    assert_eq!(pipelined.values.len(), sequential.len());
    let difference = max_difference(&pipelined.values, &sequential);
    assert!(
        difference <= 1e-12,
        "pipelined and sequential differ by {difference}"
    );
}

/// Gauss–Seidel sweeps in place of the first factorization of each nested level change
/// the path, not the answer: the same solution, and no more factorizations on the final
/// mesh than Newton with every step exact.
#[test]
fn smoothing_the_first_step_keeps_the_solution_and_saves_factorizations() {
    use fem_forms::lcp::NewtonOptions;
    use fem_forms::obstacle::triangle::solve_obstacle_on_triangles;
    type M = membrane_p1_p0::Model;
    let scene = radial();
    let meshes = radial_meshes(&[4, 8, 16, 32, 64]);
    let data = SceneData::new(&scene);
    let coefficients = data.coefficients::<M>(0.1);
    let smoothed = options(VariationalSolver::SemismoothNewton);
    assert!(smoothed.newton.smoothing_sweeps > 0);
    let exact = fem_forms::obstacle::ObstacleOptions {
        newton: NewtonOptions {
            smoothing_sweeps: 0,
            ..smoothed.newton
        },
        ..smoothed
    };
    let with = solve_obstacle_on_triangles::<M>(&meshes, &coefficients, smoothed).unwrap();
    let without = solve_obstacle_on_triangles::<M>(&meshes, &coefficients, exact).unwrap();
    assert_same_solution(&with, &without);
    assert!(
        with.factorizations <= without.factorizations,
        "{} factorizations with the sweeps, {} without",
        with.factorizations,
        without.factorizations
    );
    assert_eq!(
        without.factorizations + without.low_rank_updates,
        without.iterations
    );
}

/// Newton steps solved through a low-rank update of the last factorization (the cells
/// that flipped since) change the path's cost, not the answer: the same solution as
/// factoring every step, fewer factorizations, and every exact step either factored or
/// updated.
#[test]
fn low_rank_updates_keep_the_solution_and_save_factorizations() {
    use fem_forms::lcp::NewtonOptions;
    use fem_forms::obstacle::triangle::solve_obstacle_on_triangles;
    type M = membrane_p1_p0::Model;
    let scene = radial();
    let meshes = radial_meshes(&[4, 8, 16, 32, 64, 128]);
    let data = SceneData::new(&scene);
    let coefficients = data.coefficients::<M>(0.1);
    let defaults = options(VariationalSolver::SemismoothNewton);
    let options = |low_rank_updates| fem_forms::obstacle::ObstacleOptions {
        newton: NewtonOptions {
            smoothing_sweeps: 0,
            low_rank_updates,
            ..defaults.newton
        },
        ..defaults
    };
    let with = solve_obstacle_on_triangles::<M>(&meshes, &coefficients, options(true)).unwrap();
    let without = solve_obstacle_on_triangles::<M>(&meshes, &coefficients, options(false)).unwrap();
    assert_same_solution(&with, &without);
    assert_eq!(without.low_rank_updates, 0);
    assert!(with.low_rank_updates > 0, "no step was updated");
    assert!(
        with.factorizations < without.factorizations,
        "{} factorizations with updates, {} without",
        with.factorizations,
        without.factorizations
    );
    assert_eq!(with.factorizations + with.low_rank_updates, with.iterations);
}

/// A level that fails to build or solve stops the nested solve with its own error, on
/// either thread, the coarser level's first (as in the sequential order); nothing hangs.
#[test]
fn the_nested_solve_reports_the_first_failing_level() {
    use fem_forms::obstacle::solve_nested;
    use fem_forms::obstacle::triangle::{discretize_on_triangles, prolong_on_triangles};
    use fem_forms::{Error, TriangleMesh};
    type M = membrane_p1_p0::Model;
    type Level<'a> = Box<
        dyn FnOnce() -> fem_forms::Result<fem_forms::obstacle::Discretization<TriangleMesh>>
            + Send
            + 'a,
    >;
    let scene = radial();
    let meshes = radial_meshes(&[4, 8]);
    let data = SceneData::new(&scene);
    let coefficients = data.coefficients::<M>(0.5 / 48.0);
    let level = |k: usize, fails: bool| -> Level<'_> {
        let (mesh, coefficients) = (&meshes[k], &coefficients);
        Box::new(move || {
            if fails {
                Err(Error::Input(format!("level {k} fails")))
            } else {
                discretize_on_triangles::<M>(mesh, coefficients, "B_h", "L_h")
            }
        })
    };
    for pipelined in [true, false] {
        let options = fem_forms::obstacle::ObstacleOptions {
            pipelined,
            ..options(VariationalSolver::SemismoothNewton)
        };
        for (coarse_fails, fine_fails, expected) in [
            (false, true, Some("level 1 fails")),
            (true, false, Some("level 0 fails")),
            (true, true, Some("level 0 fails")),
            (false, false, None),
        ] {
            let result = solve_nested(
                vec![level(0, coarse_fails), level(1, fine_fails)],
                prolong_on_triangles,
                options,
            );
            match (result, expected) {
                (Err(e), Some(message)) => assert!(
                    e.to_string().contains(message),
                    "pipelined {pipelined}: {e} instead of {message}"
                ),
                (Ok(solution), None) => assert!(solution.kkt_residual <= 1e-10),
                (Ok(_), Some(message)) => {
                    panic!("pipelined {pipelined}: no error, expected {message}")
                }
                (Err(e), None) => panic!("pipelined {pipelined}: {e}"),
            }
        }
    }
}

/// A level builder that itself runs a nested solve (so the inner solve starts on the
/// thread that builds the outer finest level) finishes, with the same answer as alone.
#[test]
fn a_nested_solve_inside_a_level_builder_finishes() {
    use fem_forms::obstacle::solve_nested;
    use fem_forms::obstacle::triangle::{
        discretize_on_triangles, prolong_on_triangles, solve_obstacle_on_triangles,
    };
    type M = membrane_p1_p0::Model;
    let scene = radial();
    let meshes = radial_meshes(&[4, 8]);
    let data = SceneData::new(&scene);
    let coefficients = data.coefficients::<M>(0.5 / 48.0);
    let options = options(VariationalSolver::SemismoothNewton);
    let alone = solve_obstacle_on_triangles::<M>(&meshes, &coefficients, options).unwrap();
    let inner = std::sync::Mutex::new(None);
    let levels: Vec<Box<dyn FnOnce() -> _ + Send + '_>> = vec![
        Box::new(|| discretize_on_triangles::<M>(&meshes[0], &coefficients, "B_h", "L_h")),
        Box::new(|| {
            let solved = solve_obstacle_on_triangles::<M>(&meshes, &coefficients, options)?;
            *inner.lock().unwrap() = Some(solved.values);
            discretize_on_triangles::<M>(&meshes[1], &coefficients, "B_h", "L_h")
        }),
    ];
    let outer = solve_nested(levels, prolong_on_triangles, options).unwrap();
    let inner = inner.into_inner().unwrap().expect("the inner solve ran");
    for values in [&outer.values, &inner] {
        let difference = max_difference(values, &alone.values);
        assert!(difference <= 1e-12, "differs by {difference}");
    }
}

/// The nodal P1 method on the right-diagonal grid is the 5-point scheme of PETSc's SNES
/// tutorial ex9 (Bueler's radial obstacle problem): an independent solver (PETSc 3.18,
/// `ex9 -snes_type vinewtonrsls -snes_grid_sequence K -pc_type mg`, K = 2, 3, 4) printed
/// these errors `av |u-uexact|` and `|u-uexact|_inf` on the 17², 33² and 65² grids; the
/// same discrete problem must give them to the four digits printed.
#[test]
fn the_nodal_method_reproduces_petsc_ex9_errors() {
    for (n, mean, max) in fem_forms::models::membrane_scenes::PETSC_EX9_ERRORS {
        let r = solve(radial(), "p1-nodal", n).solve;
        let (m, x) = (r.error_vertex_mean.unwrap(), r.error_vertex_max.unwrap());
        assert_eq!(
            format!("{m:.3e} {x:.3e}"),
            format!("{mean:.3e} {max:.3e}"),
            "N = {n}"
        );
    }
}

/// Findings of a tester (2026-12-01), each a message that misled or a check that let a
/// run through to the kernel's out-of-memory killer.
#[test]
fn tester_findings_on_alpha_memory_and_warnings() {
    let with = |pair: &str, n: usize, alpha: Option<f64>| Settings {
        alpha,
        ..settings(pair, n)
    };
    let error_of = |request: &Settings| {
        membranes::solve(&radial(), request)
            .err()
            .unwrap()
            .to_string()
    };
    let warnings_of = |scene: &MembraneScene, request: &Settings| {
        membranes::solve(scene, request)
            .unwrap()
            .report
            .solve
            .warnings
    };
    // p2-p0 at N = 1800 was accepted with 2.3 kB a triangle (15 GB planned) and needs
    // about 4.7 kB: now refused before anything is allocated
    let error = error_of(&settings("p2-p0", 1800));
    assert!(error.contains("GB of memory"), "{error}");

    // an α so small that the stabilization is below rounding is refused by name ...
    let error = error_of(&with("p1-p0", 16, Some(1e-14)));
    assert!(
        error.contains("α = 1e-14") && error.contains("α = 0"),
        "{error}"
    );
    // the smallest α the refusal suggests is itself accepted (P2: C_I = 48)
    let error = error_of(&with("p2-p0", 4, Some(1e-16)));
    let suggested: f64 = error
        .rsplit("at least ")
        .next()
        .and_then(|t| t.split_whitespace().next())
        .and_then(|t| t.parse().ok())
        .unwrap_or_else(|| panic!("no suggestion in: {error}"));
    let accepted = membranes::solve(&radial(), &with("p2-p0", 4, Some(suggested)))
        .map(|_| ())
        .map_err(|e| e.to_string());
    assert!(
        accepted
            .as_ref()
            .map_or_else(|e| !e.contains("α = "), |_| true),
        "{suggested:e}: {accepted:?}"
    );
    // ... and one that fails only on finer meshes is named in the failure
    let error = error_of(&with("p1-p0", 32, Some(1e-13)));
    assert!(error.contains("α = 1e-13 is small"), "{error}");
    assert!(membranes::solve(&radial(), &with("p1-p0", 32, Some(0.1))).is_ok());
    // a huge α lets u_h through ψ: the warning names it rather than only "refine"
    let warnings = warnings_of(&radial(), &with("p1-p0", 32, Some(1e10)));
    assert!(
        warnings.iter().any(|w| w.contains("α = 1e10")),
        "{warnings:?}"
    );

    // u = ψ = 0 exactly: a gap of rounding size is not an "unreal contact set"
    let warnings = warnings_of(&MEMBRANE_FLAT, &settings("p1-p0", 16));
    assert!(
        warnings.iter().all(|w| !w.contains("not real")),
        "{warnings:?}"
    );

    // full contact leaves the nodal method no system to solve: no multigrid warning
    let request = Settings {
        linear_solver: fem_forms::obstacle::hierarchy::LinearSolver::Multigrid,
        ..settings("p1-nodal", 32)
    };
    let warnings = warnings_of(&MEMBRANE_FLAT, &request);
    assert!(
        warnings
            .iter()
            .all(|w| !w.contains("--linear-solver multigrid")),
        "{warnings:?}"
    );
}
