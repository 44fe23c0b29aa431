//! The variational-inequality solvers on the beam scenes: exact solutions and rates,
//! locking, two independent solvers, iteration counts, the sign test of docs/mathematics.md §1,
//! stability where methods fail, and bad input.
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

#[path = "common/beams.rs"]
mod beams;

use beams::{contact_set, max_deflection, settings, solve};
use fem_forms::models::families::{self, beam::beam_scene};
use fem_forms::models::report::{Report, Settings};
use fem_forms::models::scenes::{exact_solution, scene, Beam, Obstacle, Scene, SCENES};
use fem_forms::obstacle::VariationalSolver;
use fem_forms::registry_studies::RegistryStudies;
use fem_forms::studies;
use fem_forms::IntervalMesh;

/// The report of `name` on `elements` elements at load `q`.
fn report(name: &str, elements: usize, q: f64) -> fem_forms::Result<Report> {
    Ok(solve(name, &settings(elements, q))?.report)
}

/// The report of a beam data set that is not a registry scene.
fn report_of(scene: &Scene, settings: &Settings) -> fem_forms::Result<Report> {
    Ok(families::solve(&beam_scene(scene), settings)?.report)
}

/// Least-squares slope of log(error) against log(1/h): one rate for the whole sequence,
/// robust to the oscillation caused by the free boundary moving inside the elements.
fn fitted_rate(elements: &[usize], errors: &[f64]) -> f64 {
    let x: Vec<f64> = elements.iter().map(|&n| (n as f64).ln()).collect();
    let y: Vec<f64> = errors.iter().map(|e| e.ln()).collect();
    let (mx, my) = (
        x.iter().sum::<f64>() / x.len() as f64,
        y.iter().sum::<f64>() / y.len() as f64,
    );
    let sxy: f64 = x.iter().zip(&y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = x.iter().map(|a| (a - mx).powi(2)).sum();
    -sxy / sxx
}

#[test]
fn bernoulli_flat_converges_at_the_expected_rates() {
    // The free boundary a = (72d/q)^{1/4} carries point forces that P0 multipliers resolve
    // within a cell, so the error is O(h²) in L2 and H1 (the point forces' H⁻² error),
    // below the O(h^{5/2}) that the regularity H^{7/2−ε} would allow.
    let meshes = [32, 64, 128, 256, 512, 1024];
    let flat = RegistryStudies::of("bernoulli-flat").unwrap();
    let rows = studies::convergence(&flat, "hermite-p0", &meshes).unwrap();
    let l2: Vec<f64> = rows.iter().map(|r| r.error_l2.unwrap()).collect();
    let h1: Vec<f64> = rows.iter().map(|r| r.error_h1.unwrap()).collect();
    let force: Vec<f64> = rows.iter().map(|r| r.force_error.unwrap()).collect();
    println!("L2 {l2:?}\nH1 {h1:?}\n∫λ {force:?}");
    println!("pairwise L2 rates {:.2?}", studies::rates(&l2));
    let (r2, r1, rf) = (
        fitted_rate(&meshes, &l2),
        fitted_rate(&meshes, &h1),
        fitted_rate(&meshes, &force),
    );
    println!("fitted rates: L2 {r2:.2}, H1 {r1:.2}, total force {rf:.2}");
    assert!((r2 - 2.0).abs() < 0.4, "L2 rate {r2}");
    assert!((r1 - 2.0).abs() < 0.4, "H1 rate {r1}");
    assert!(rf > 1.5, "total force rate {rf}");
    // and the contact edges are found to within two cells
    let exact = exact_solution(&scene("bernoulli-flat").unwrap(), 100.0, 0.0).unwrap();
    for &n in &meshes {
        let set = contact_set(&report("bernoulli-flat", n, 100.0).unwrap());
        // the outer edges (a coarse mesh may leave holes inside)
        let edges = [set[0][0], set[set.len() - 1][1]];
        for (k, edge) in edges.into_iter().enumerate() {
            let error = (edge - exact.contact_set[0][k]).abs();
            assert!(
                error <= 2.0 / n as f64 + 1e-12,
                "{n} elements: edge {k} off by {error}"
            );
        }
    }
}

#[test]
fn every_scene_agrees_between_pdas_and_clarabel() {
    for s in SCENES {
        for q in [1.0, 40.0, 100.0] {
            let newton = settings(128, q);
            let pdas = report(s.name, 128, q).unwrap();
            let qp = Settings {
                solver: VariationalSolver::Clarabel,
                ..newton
            };
            let clarabel = solve(s.name, &qp).unwrap().report;
            let (ep, ec) = (pdas.solve.energy.unwrap(), clarabel.solve.energy.unwrap());
            let relative = ((ep - ec) / ep).abs();
            assert!(
                relative <= 1e-7,
                "{} q = {q}: energies {ep} vs {ec} ({relative:e})",
                s.name
            );
            assert!(
                pdas.solve.complementarity_residual <= 1e-10,
                "{} q = {q}: KKT residual {:e}",
                s.name,
                pdas.solve.complementarity_residual
            );
            let (cp, cc) = (contact_set(&pdas), contact_set(&clarabel));
            if q == 1.0 {
                // the seed load never reaches the obstacle: the multiplier vanishes
                assert_eq!(pdas.solve.total_contact_force, 0.0, "{}", s.name);
                assert!(cp.is_empty() && cc.is_empty(), "{}", s.name);
                assert!(
                    clarabel.solve.total_contact_force.abs() < 1e-8,
                    "{}: {}",
                    s.name,
                    clarabel.solve.total_contact_force
                );
                // and the free beam is right: Hermite is exact at the nodes, P2 is O(h²)
                assert!(
                    pdas.solve.error_l2.unwrap() < 1e-6,
                    "{}: {:?}",
                    s.name,
                    pdas.solve.error_l2
                );
            } else {
                assert!(!cp.is_empty(), "{} q = {q} touches", s.name);
                assert_eq!(cp.len(), cc.len(), "{} q = {q}", s.name);
            }
        }
    }
}

#[test]
fn bernoulli_flat_matches_the_exact_contact_set_and_force() {
    let exact = exact_solution(&scene("bernoulli-flat").unwrap(), 100.0, 0.0).unwrap();
    let r = report("bernoulli-flat", 512, 100.0).unwrap();
    let [a, b] = contact_set(&r)[0];
    assert!((a - exact.contact_set[0][0]).abs() < 2.0 / 512.0, "{a}");
    assert!((b - exact.contact_set[0][1]).abs() < 2.0 / 512.0, "{b}");
    let force = r.solve.total_contact_force;
    assert!(((force - exact.total_contact_force) / exact.total_contact_force).abs() < 1e-3);
    // point contact regime: q = 40 touches at ½ with force q/2 − 192 d
    let r = report("bernoulli-flat", 512, 40.0).unwrap();
    let set = contact_set(&r);
    assert_eq!(set.len(), 1);
    assert!((set[0][0] - 0.5).abs() < 1e-6 && set[0][0] == set[0][1]);
    let force = r.solve.total_contact_force;
    assert!((force - (20.0 - 9.6)).abs() < 1e-3, "{force}");
}

#[test]
fn sign_test_both_sides_press_onto_the_obstacle_everywhere() {
    // docs/mathematics.md §1: ψ = 0, f = −s·q: exact u = 0, λ = q, for both s and both beams.
    for (beam, pairs) in [
        (Beam::EulerBernoulli, vec!["hermite-p0"]),
        (Beam::Timoshenko, vec!["p2-p2-p0", "p1-p1-p0-reduced"]),
    ] {
        for s in [1.0, -1.0] {
            for pair in &pairs {
                let scene = Scene {
                    name: "sign-test",
                    description: "",
                    beam,
                    obstacle: Obstacle::Constant(0.0),
                    side: s,
                    load_sign: -s,
                    thickness: 1e-2,
                    load: 1.0,
                };
                let r = Settings {
                    pair: Some(pair.to_string()),
                    ..settings(64, 7.0)
                };
                let outcome = families::solve(&beam_scene(&scene), &r).unwrap();
                let w = max_deflection(&outcome.report);
                assert!(w < 1e-9, "{beam:?} s = {s}: max |w| {w}");
                for &l in beams::lambda(&outcome) {
                    assert!(
                        (l - 7.0).abs() < 1e-6 * 7.0,
                        "{beam:?} {pair} s = {s}: λ = {l}"
                    );
                }
            }
        }
    }
}

#[test]
fn stabilized_timoshenko_does_not_lock_and_p1_full_integration_does() {
    // against the Euler–Bernoulli beam on 16 × 128 Hermite elements (the study's limit)
    let thicknesses = [1e-1, 1e-2, 1e-3, 1e-4];
    let timoshenko = families::scene("timoshenko-a").unwrap();
    let rows = fem_forms::locking::locking_study(&timoshenko, &[128], &thicknesses, None).unwrap();
    let of = |pair: &str| -> Vec<_> { rows.iter().filter(|r| r.pair == pair).collect() };
    let (p2, full) = (of("p2-p2-p0"), of("p1-p1-p0-full"));
    for r in &rows {
        println!(
            "{:<17} t = {:.0e}: max |w| {:.6e}, against Euler–Bernoulli {:+.3e}",
            r.pair, r.thickness, r.quantity, r.relative_error
        );
    }
    // the limit is the Euler–Bernoulli beam's, solved independently of the pair
    let limit = report("bernoulli-a", 2048, 100.0).unwrap();
    assert!(rows.iter().all(|r| r.limit == max_deflection(&limit)));
    // Converges to Euler–Bernoulli: the difference falls by ~t² until the mesh error floor…
    assert!(p2[1].relative_error.abs() < p2[0].relative_error.abs() / 50.0);
    // …and at fixed h it does not grow as t → 0
    for r in &p2[1..] {
        assert!(
            r.relative_error.abs() < 3e-3,
            "t = {}: {}",
            r.thickness,
            r.relative_error
        );
    }
    // P1–P1 with exact shear integration locks: its deflection collapses.
    assert!(
        full[3].quantity < 0.02 * full[0].quantity,
        "{} vs {}",
        full[3].quantity,
        full[0].quantity
    );
    assert!(full[2].quantity < 0.9 * full[2].limit);
}

#[test]
fn nested_iteration_keeps_newton_iterations_flat() {
    // Timoshenko from 32 to 32,768 elements; cold starts beside for the small meshes.
    let meshes: Vec<usize> = (5..=15).map(|k| 1 << k).collect();
    let timoshenko = RegistryStudies::of("timoshenko-a").unwrap();
    let rows = studies::iteration_counts(&timoshenko, "p2-p2-p0", &meshes, 512);
    for (n, nested, cold) in &rows {
        println!("{n:>6} elements: nested {nested:?}, cold {cold:?}");
        let nested = nested.unwrap_or_else(|| panic!("nested Newton failed at {n} elements"));
        assert!(nested <= 6, "{n} elements: {nested} iterations");
    }
    // From a cold start the active set creeps: many more iterations on the finer meshes.
    let cold_512 = rows.iter().find(|r| r.0 == 512).unwrap().2.unwrap();
    let nested_512 = rows.iter().find(|r| r.0 == 512).unwrap().1.unwrap();
    assert!(
        cold_512 > 2 * nested_512,
        "cold {cold_512} vs nested {nested_512}"
    );
}

#[test]
fn euler_bernoulli_iterations_are_flat_until_double_precision_runs_out() {
    // Hermite bending matrices have κ ~ h⁻⁴, past 1/ε near 10⁴ elements: up to 8192 the
    // nested Newton count stays flat; beyond it the solve reports failure (never a wrong answer).
    let meshes: Vec<usize> = (5..=13).map(|k| 1 << k).collect();
    let flat = RegistryStudies::of("bernoulli-flat").unwrap();
    for (n, nested, _) in studies::iteration_counts(&flat, "hermite-p0", &meshes, 0) {
        println!("{n:>6} elements: nested {nested:?}");
        let nested = nested.unwrap_or_else(|| panic!("failed at {n}"));
        assert!(nested <= 10, "{n}: {nested}");
    }
}

#[test]
fn plain_and_stabilized_multipliers_where_methods_fail() {
    let exact = exact_solution(&scene("bernoulli-flat").unwrap(), 100.0, 0.0).unwrap();
    let flat = RegistryStudies::of("bernoulli-flat").unwrap();
    let profile = |alpha| studies::multiplier_profile(&flat, "hermite-p0", 256, alpha).unwrap();
    let (plain, weak, strong) = (profile(Some(0.0)), profile(Some(1e-2)), profile(Some(1.0)));
    let contact = exact.contact_set[0];
    // hand-coded: λ = q = 100 inside the contact interval of the flat obstacle
    let exact_multiplier = studies::ExactMultiplier {
        contact,
        lambda: Box::new(|_| 100.0),
    };
    // The plain method's multiplier oscillates about the exact 100; stabilizing damps it.
    let (op, ow) = (
        studies::interior_oscillation(&plain, &exact_multiplier),
        studies::interior_oscillation(&weak, &exact_multiplier),
    );
    assert!(ow < op / 2.0, "oscillation plain {op}, α = 1e-2 {ow}");
    // Zero holes next to the contact edges: the plain method has them, α = 1 removes them.
    assert!(studies::zero_holes(&plain) > 0);
    assert_eq!(studies::zero_holes(&strong), 0);
    // The conditioning of the LCP matrix: plain worse than stabilized, and growing as h → 0.
    let stabilized = lcp_condition(32, 1.0);
    let (plain_32, plain_64) = (lcp_condition(32, 0.0), lcp_condition(64, 0.0));
    assert!(plain_32 > 100.0 * stabilized, "{plain_32} vs {stabilized}");
    assert!(plain_64 > 4.0 * plain_32);
}

#[test]
fn an_overlarge_alpha_shifts_the_contact_set() {
    let exact = exact_solution(&scene("bernoulli-flat").unwrap(), 100.0, 0.0).unwrap();
    let with = |alpha: f64| {
        let r = Settings {
            alpha: Some(alpha),
            ..settings(128, 100.0)
        };
        solve("bernoulli-flat", &r).unwrap().report
    };
    let (fitting, overlarge) = (with(1e-2), with(1e3));
    assert_eq!(
        fitting.solve.inverse_constant, 0.0,
        "w'''' vanishes on each Hermite cubic"
    );
    let h = 1.0 / 128.0;
    let edge = |r: &Report| contact_set(r)[0][0];
    assert!((edge(&fitting) - exact.contact_set[0][0]).abs() < 2.0 * h);
    assert!(
        (edge(&overlarge) - exact.contact_set[0][0]).abs() > 5.0 * h,
        "{}",
        edge(&overlarge)
    );
    assert!(overlarge.solve.error_l2.unwrap() > 10.0 * fitting.solve.error_l2.unwrap());
}

#[test]
fn bad_input_is_a_clear_error() {
    // zero or negative element length
    let e = IntervalMesh::new(vec![0.0, 0.5, 0.5, 1.0])
        .unwrap_err()
        .to_string();
    assert!(e.contains("zero length"), "{e}");
    let e = IntervalMesh::new(vec![0.0, 0.6, 0.4, 1.0])
        .unwrap_err()
        .to_string();
    assert!(e.contains("negative length"), "{e}");
    // an obstacle that contradicts the clamped ends
    let mut infeasible = scene("bernoulli-flat").unwrap();
    infeasible.obstacle = Obstacle::Constant(0.1);
    let e = report_of(&infeasible, &Settings::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("infeasible"), "{e}");
    // NaN data
    let mut nan = scene("timoshenko-a").unwrap();
    nan.obstacle = Obstacle::Constant(f64::NAN);
    let e = report_of(&nan, &Settings::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("not finite") || e.contains("NaN"), "{e}");
    let e = report("timoshenko-a", 64, f64::NAN)
        .unwrap_err()
        .to_string();
    assert!(e.contains("load") || e.contains("q ="), "{e}");
    // α < 0, α not finite, thickness ≤ 0
    for alpha in [-1.0, f64::INFINITY] {
        let r = Settings {
            alpha: Some(alpha),
            ..settings(64, 40.0)
        };
        let e = solve("bernoulli-a", &r).unwrap_err().to_string();
        assert!(e.contains("α"), "{e}");
    }
    let r = Settings {
        parameters: beams::thickness(0.0),
        ..settings(64, 40.0)
    };
    let e = solve("timoshenko-a", &r).unwrap_err().to_string();
    assert!(e.contains("thickness"), "{e}");
    // a pair of the other beam theory
    let r = Settings {
        pair: Some("hermite-p0".into()),
        ..settings(64, 40.0)
    };
    assert!(solve("timoshenko-a", &r).is_err());
    // zero elements
    assert!(report("timoshenko-a", 0, 40.0).is_err());
}

#[test]
fn saddle_point_active_set_and_multiplier_recovery_agree_with_eliminated_newton() {
    use fem_forms::lcp::{
        primal_dual_active_set, recover_multiplier, semismooth_newton, NewtonOptions,
    };
    for name in ["timoshenko-a", "bernoulli-flat"] {
        let pair = if name == "bernoulli-flat" {
            "hermite-p0"
        } else {
            "p2-p2-p0"
        };
        let alpha = if name == "bernoulli-flat" { 1e-2 } else { 1.0 };
        let d = beams::discretize(name, pair, 128, 100.0, alpha).unwrap();
        let options = NewtonOptions::default();
        let newton = semismooth_newton(&d.lcp, None, options).unwrap();
        let saddle = primal_dual_active_set(&d.lcp, None, options).unwrap();
        let recovered = recover_multiplier(&d.lcp, newton.clone(), 1).unwrap();
        let norm = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let diff = |a: &[f64], b: &[f64]| {
            a.iter()
                .zip(b)
                .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
        };
        for (label, other) in [("saddle", &saddle), ("recovered", &recovered)] {
            assert!(
                diff(&newton.u, &other.u) <= 1e-8 * norm(&newton.u),
                "{name} {label}: U"
            );
            assert!(
                diff(&newton.lambda, &other.lambda) <= 1e-6 * norm(&newton.lambda),
                "{name} {label}: Λ"
            );
            assert!(
                other.kkt_residual <= 1e-10,
                "{name} {label}: {}",
                other.kkt_residual
            );
        }
    }
}

#[test]
fn multiplier_noise_is_reported_where_the_eliminated_multiplier_loses_its_digits() {
    let coarse = report("timoshenko-a", 1024, 100.0).unwrap().solve;
    assert!(coarse.warnings.is_empty() && coarse.multiplier_noise < 1e-6);
    let fine = report("timoshenko-a", 16384, 100.0).unwrap().solve;
    assert!(
        fine.multiplier_noise > 1e-6 && !fine.warnings.is_empty(),
        "{:?}",
        fine.warnings
    );
    // the deflection, the contact set and the total force stay right
    assert!(
        (fine.total_contact_force - coarse.total_contact_force).abs()
            < 1e-2 * coarse.total_contact_force
    );
    assert!(fine.complementarity_residual <= 1e-10);
}

#[test]
fn an_inaccurate_multiplier_never_goes_unreported() {
    // On fine Hermite meshes λ_h loses digits (κ ~ h⁻⁴, C = αh⁵ near the rounding of
    // G − BU): any error in ∫λ beyond 1e-3 must come with a noise estimate covering it
    // and a warning, and a solve that cannot be trusted must fail, not return λ = 0.
    let exact = exact_solution(&scene("bernoulli-flat").unwrap(), 100.0, 0.0).unwrap();
    for n in [1024, 2048, 4096, 8192, 16384] {
        match report("bernoulli-flat", n, 100.0) {
            Ok(r) => {
                let r = r.solve;
                let error = ((r.total_contact_force - exact.total_contact_force)
                    / exact.total_contact_force)
                    .abs();
                println!(
                    "{n}: ∫λ error {error:.1e}, noise estimate {:.1e}",
                    r.multiplier_noise
                );
                if error > 1e-3 {
                    assert!(
                        r.multiplier_noise * 10.0 >= error,
                        "{n}: error {error:e}, noise {:e}",
                        r.multiplier_noise
                    );
                    assert!(!r.warnings.is_empty(), "{n}: no warning");
                }
            }
            Err(e) => println!("{n}: {e}"),
        }
    }
}

/// The beam pairs' stabilization terms `θ'''`, `w''''` vanish on each element, so the
/// element constant of `S_h` against `a`, computed from the kernels by the runtime's
/// stabilization module, is 0 for every pair (every α > 0 is stable); the same routine
/// gives 12 for `h²(u'', v'')` on P2 (fem-runtime's tests), so 0 is measured, not assumed.
#[test]
fn beam_pairs_have_a_vanishing_inverse_constant() {
    for (name, pair) in [
        ("bernoulli-a", "hermite-p0"),
        ("timoshenko-a", "p2-p2-p0"),
        ("timoshenko-a", "p1-p1-p0-reduced"),
        ("timoshenko-a", "p1-p1-p0-full"),
    ] {
        let r = Settings {
            pair: Some(pair.into()),
            ..settings(16, 1.0)
        };
        let c_i = solve(name, &r).unwrap().report.solve.inverse_constant;
        assert!(c_i.abs() < 1e-12, "{pair}: C_I = {c_i}");
    }
}

/// bernoulli-b is bernoulli-flat mirrored (pushed up by +q against w ≤ 0.05): a tester
/// found the two equal to every digit, but bernoulli-b reported no error. Its exact
/// solution is the mirror of the flat obstacle's, and its errors are bernoulli-flat's.
#[test]
fn bernoulli_b_is_measured_against_the_mirrored_exact_solution() {
    let run = |name: &str| report(name, 128, 100.0).unwrap().solve;
    let (up, down) = (run("bernoulli-b"), run("bernoulli-flat"));
    let (e_up, e_down) = (up.error_l2.unwrap(), down.error_l2.unwrap());
    assert!(
        e_up < 1e-5 && (e_up - e_down).abs() <= 1e-9 * e_down,
        "{e_up} {e_down}"
    );
    assert!((up.total_contact_force - down.total_contact_force).abs() < 1e-9);
}

/// Hand-coded for the beams: the condition number of the LCP matrix `M = B A⁻¹ Bᵀ + C`
/// of timoshenko-a (P2–P2–P0, q = 100) on `elements` elements with `alpha`: the matrix the
/// multiplier sees once U is eliminated. Its smallest eigenvalue is the discrete inf-sup
/// constant squared (in the Euclidean norm of the P0 coefficients); `C = αΣh⁴(λ, μ)`
/// lifts it for the stabilized method.
fn lcp_condition(elements: usize, alpha: f64) -> f64 {
    let d = beams::discretize("timoshenko-a", "p2-p2-p0", elements, 100.0, alpha).unwrap();
    let lcp = &d.lcp;
    let (n, m) = (lcp.n(), lcp.m());
    let mut a = nalgebra::DMatrix::<f64>::zeros(n, n);
    let (col_ptr, rows, vals) = (
        lcp.a.symbolic().col_ptr(),
        lcp.a.symbolic().row_idx(),
        lcp.a.val(),
    );
    for j in 0..n {
        for idx in col_ptr[j]..col_ptr[j + 1] {
            a[(rows[idx], j)] = vals[idx];
        }
    }
    let mut bt = nalgebra::DMatrix::<f64>::zeros(n, m);
    for (k, row) in lcp.b_rows.iter().enumerate() {
        for &(j, v) in row {
            bt[(j, k)] = v;
        }
    }
    let cholesky = a.cholesky().expect("A is positive definite");
    let a_inv_bt = cholesky.solve(&bt);
    let mut schur = bt.transpose() * a_inv_bt;
    for k in 0..m {
        schur[(k, k)] += lcp.c[k];
    }
    let eigenvalues = nalgebra::SymmetricEigen::new(schur).eigenvalues;
    let (largest, smallest) = (eigenvalues.max(), eigenvalues.min());
    if smallest > 0.0 {
        largest / smallest
    } else {
        f64::INFINITY
    }
}
