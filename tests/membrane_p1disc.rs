//! The membrane with P2–P1disc: its multiplier mass `C_α = α Σ_T h_T² (λ, μ)_T` has one
//! dense 3 × 3 block per triangle, which the LCP solvers handle block by block. The
//! radial problem is solved by Newton and by clarabel, compared with P2–P0, and the sign
//! test of docs/mathematics.md §1 checks every multiplier value.
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

use fem_forms::lcp::{
    primal_dual_active_set, recover_multiplier, semismooth_newton, NewtonOptions,
};
#[path = "common/membranes.rs"]
mod membranes;

use fem_forms::models::membrane::membrane_p2_p1disc;
use fem_forms::models::membrane_scenes::{membrane_scene, MembraneScene, MEMBRANE_FLAT};
use fem_forms::models::report::{Outcome, Settings};
use fem_forms::obstacle::triangle::{discretize_on_triangles, solve_obstacle_on_triangles};
use fem_forms::obstacle::{ObstacleOptions, VariationalSolver};
use fem_forms::Model;
use membranes::{settings, SceneData};

fn radial() -> MembraneScene {
    membrane_scene("membrane-radial").unwrap()
}

/// `scene` solved with `pair` at N = `n` by `solver`.
fn solve(scene: &MembraneScene, pair: &str, n: usize, solver: VariationalSolver) -> Outcome {
    let request = Settings {
        solver,
        ..settings(pair, n)
    };
    membranes::solve(scene, &request).unwrap()
}

fn max_difference(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}

/// The radial problem on N = 8, 16, 32: certified KKT points, an H¹ error no worse than
/// 1.5 times P2–P0's on the same mesh, and the same u from Newton and from clarabel.
#[test]
fn radial_problem_with_p1disc_multipliers() {
    for n in [8, 16, 32] {
        let newton_outcome = solve(&radial(), "p2-p1d", n, VariationalSolver::SemismoothNewton);
        let p0 = solve(&radial(), "p2-p0", n, VariationalSolver::SemismoothNewton)
            .report
            .solve;
        let qp_outcome = solve(&radial(), "p2-p1d", n, VariationalSolver::Clarabel);
        let difference = max_difference(membranes::u(&newton_outcome), membranes::u(&qp_outcome));
        let exact_contact_force = newton_outcome.report.exact_contact_force;
        let exact_contact_area = newton_outcome.report.exact_contact_area;
        let (newton, qp) = (newton_outcome.report.solve, qp_outcome.report.solve);
        let (h1, h1_p0) = (newton.error_h1.unwrap(), p0.error_h1.unwrap());
        println!(
            "N = {n}: P2–P1disc H¹ {h1:.4e} (P2–P0 {h1_p0:.4e}), L² {:.3e}, λ error {:.3e} (P2–P0 {:.3e}), ∫λ_h {:.5} (clarabel {:.5}, P2–P0 {:.5}, exact {:.5}), Newton levels {:?}, clarabel {} iterations, KKT {:.1e} / {:.1e}, max |u_newton − u_qp| {difference:.1e}, contact area {:.4} (exact {:.4}), warnings {:?}",
            newton.error_l2.unwrap(),
            newton.error_multiplier.unwrap(),
            p0.error_multiplier.unwrap(),
            newton.total_contact_force,
            qp.total_contact_force,
            p0.total_contact_force,
            exact_contact_force.unwrap(),
            newton.levels,
            qp.iterations,
            newton.complementarity_residual,
            qp.complementarity_residual,
            newton.contact_area.unwrap(),
            exact_contact_area.unwrap(),
            newton.warnings,
        );
        assert!(
            newton.complementarity_residual < 1e-10,
            "N = {n}: KKT residual {}",
            newton.complementarity_residual
        );
        // clarabel stops at its own relative tolerances (1e-8 on gap and feasibility):
        // its KKT residual lands near 1e-10 and moves with the rounding of the assembly
        assert!(
            qp.complementarity_residual < 1e-9,
            "N = {n}: clarabel's KKT residual {}",
            qp.complementarity_residual
        );
        assert!(
            h1 <= 1.5 * h1_p0,
            "N = {n}: H¹ error {h1} against P2–P0's {h1_p0}"
        );
        assert!(
            difference < 1e-7,
            "N = {n}: max |u_newton − u_qp| = {difference}"
        );
        assert!(
            (newton.total_contact_force - qp.total_contact_force).abs() < 1e-6,
            "N = {n}: ∫λ_h {} against clarabel's {}",
            newton.total_contact_force,
            qp.total_contact_force
        );
    }
}

/// The P2–P1disc LCP of the radial problem (N = 16) from a cold start: Newton with Λ
/// eliminated block by block, the saddle-point active-set method and the multiplier
/// recovered from one saddle-point solve agree.
#[test]
fn newton_and_the_saddle_point_method_agree_on_the_blocked_membrane_lcp() {
    type M = membrane_p2_p1disc::Model;
    let scene = radial();
    let mesh = membranes::mesh(&scene, 16);
    let data = SceneData::new(&scene);
    let coefficients = data.coefficients::<M>(membranes::alpha::<M>(&mesh));
    let d = discretize_on_triangles::<M>(&mesh, &coefficients, "B_h", "L_h").unwrap();
    let lcp = &d.lcp;
    assert_eq!(lcp.c_blocks.groups().count(), 2 * 16 * 16);
    let options = NewtonOptions::default();
    let newton = semismooth_newton(lcp, None, options).unwrap();
    let saddle = primal_dual_active_set(lcp, None, options).unwrap();
    let recovered = recover_multiplier(lcp, newton.clone(), 1).unwrap();
    let norm = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    println!(
        "cold start: Newton {} iterations, saddle point {}",
        newton.iterations, saddle.iterations
    );
    assert!(newton.kkt_residual < 1e-10 && saddle.kkt_residual < 1e-10);
    for (label, other) in [("saddle", &saddle), ("recovered", &recovered)] {
        let (du, dl) = (
            max_difference(&newton.u, &other.u),
            max_difference(&newton.lambda, &other.lambda),
        );
        assert!(du <= 1e-8 * norm(&newton.u), "{label}: U differs by {du}");
        assert!(
            dl <= 1e-6 * norm(&newton.lambda),
            "{label}: Λ differs by {dl}"
        );
    }
    // some cells are in partial contact: λ_h > 0 on part of the triangle only
    let partial = lcp
        .c_blocks
        .groups()
        .filter(|&(k, s)| {
            let on = (k..k + s).filter(|&i| newton.lambda[i] > 0.0).count();
            on > 0 && on < s
        })
        .count();
    assert!(partial > 0);
}

/// The sign test of docs/mathematics.md §1 for P2–P1disc: ψ = 0, g = 0, f = −3 pressing everywhere
/// onto the obstacle: exact u = 0 and λ = 3, so every multiplier coefficient (not only
/// the centroid values) is 3 and ∫λ = 48 on (−2,2)².
#[test]
fn pressing_onto_a_flat_obstacle_gives_u_zero_and_lambda_q() {
    let scene = MEMBRANE_FLAT;
    let n = 8;
    for solver in [
        VariationalSolver::SemismoothNewton,
        VariationalSolver::Clarabel,
    ] {
        let outcome = solve(&scene, "p2-p1d", n, solver);
        let report = &outcome.report.solve;
        let largest_u = membranes::u(&outcome)
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(largest_u < 1e-8, "{solver:?}: u = {largest_u}");
        assert!(
            (report.total_contact_force - 48.0).abs() < 1e-7 * 48.0,
            "{solver:?}: ∫λ = {}",
            report.total_contact_force
        );
        assert!(
            (report.contact_area.unwrap() - 16.0).abs() < 1e-9,
            "{solver:?}"
        );
        assert!(report.complementarity_residual < 1e-10, "{solver:?}");
        for l in membranes::lambda(&outcome) {
            assert!((l - 3.0).abs() < 1e-6, "{solver:?}: λ = {l}");
        }
    }

    // every coefficient of λ_h, from the runtime's solve with the same α
    type M = membrane_p2_p1disc::Model;
    let mesh = membranes::mesh(&scene, n);
    let data = SceneData::new(&scene);
    let coefficients = data.coefficients::<M>(membranes::alpha::<M>(&mesh));
    let solution =
        solve_obstacle_on_triangles::<M>(&[mesh], &coefficients, ObstacleOptions::default())
            .unwrap();
    let lambda = solution.field(solution.discretization.multiplier_field);
    assert_eq!(lambda.len(), 3 * 2 * n * n);
    for l in lambda {
        assert!((l - 3.0).abs() < 1e-8, "λ coefficient {l}");
    }
    let u = solution.field(M::field("u").unwrap());
    assert!(u.iter().all(|v| v.abs() < 1e-10));
    // C really is coupled: one 3 × 3 group per triangle
    let groups: Vec<(usize, usize)> = solution.discretization.lcp.c_blocks.groups().collect();
    assert_eq!(groups.len(), 2 * n * n);
    assert!(groups.iter().enumerate().all(|(t, &g)| g == (3 * t, 3)));
}
