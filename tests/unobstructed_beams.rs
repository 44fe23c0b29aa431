//! Unobstructed clamped beams under a uniform load against their exact solutions:
//! convergence at the expected rates, symmetric assembled matrices.
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

use fem_forms::lcp::cholesky::asymmetry;
use fem_forms::models::{bernoulli, timoshenko_p1_reduced, timoshenko_p2};
use fem_forms::norms::FieldView;
use fem_forms::{
    solve_linear, Coefficients, Constraints, DataFn, Factorization, IntervalMesh, MatrixAssembler,
    Model, Side, SystemDofs,
};

const Q: f64 = 1.0;

/// Exact Euler–Bernoulli deflection `q x²(1−x)²/24` and its derivatives 0..=2.
fn bernoulli_exact(x: f64, k: usize) -> f64 {
    match k {
        0 => Q * x * x * (1.0 - x).powi(2) / 24.0,
        1 => Q * (2.0 * x - 6.0 * x * x + 4.0 * x * x * x) / 24.0,
        _ => Q * (2.0 - 12.0 * x + 12.0 * x * x) / 24.0,
    }
}

/// Exact Timoshenko solution for `a(θ,w;η,v) = ∫θ'η' + t⁻²(w'−θ)(v'−η)`, `ℓ = ∫ q v`:
/// `θ = q x(2x−1)(x−1)/12`, `w = q x²(1−x)²/24 + q t² x(1−x)/2`.
fn timoshenko_theta(x: f64, k: usize) -> f64 {
    match k {
        0 => Q * (2.0 * x.powi(3) - 3.0 * x * x + x) / 12.0,
        _ => Q * (6.0 * x * x - 6.0 * x + 1.0) / 12.0,
    }
}

fn timoshenko_w(x: f64, k: usize, t: f64) -> f64 {
    match k {
        0 => Q * x * x * (1.0 - x).powi(2) / 24.0 + Q * t * t * x * (1.0 - x) / 2.0,
        _ => bernoulli_exact(x, 1) + Q * t * t * (1.0 - 2.0 * x) / 2.0,
    }
}

fn rates(errors: &[f64]) -> Vec<f64> {
    errors.windows(2).map(|e| (e[0] / e[1]).log2()).collect()
}

fn assert_rate(name: &str, errors: &[f64], expected: f64, tolerance: f64) {
    let r = rates(errors);
    println!("{name}: errors {errors:.3?} rates {r:.2?} (expected {expected})");
    let last = *r.last().unwrap();
    assert!(
        (last - expected).abs() <= tolerance,
        "{name}: observed rate {last:.3} not within {tolerance} of {expected} (errors {errors:?})"
    );
}

/// The clamped beam `fields` of `M` under the uniform load Q: mesh, DOFs, solution.
/// Asserts on the way that the assembled matrix is symmetric.
fn solve_clamped<M: Model>(
    n: usize,
    fields: &[&str],
    params: &[(&str, f64)],
) -> (IntervalMesh, SystemDofs, Vec<f64>) {
    let mesh = IntervalMesh::uniform(0.0, 1.0, n).unwrap();
    let dofs = SystemDofs::named::<M>(&mesh, fields).unwrap();
    let (f, psi): (&DataFn, &DataFn) = (&|_| Q, &|_| -1.0);
    let coefficients = Coefficients::new::<M>(params, &[("f", f), ("ψ", psi)]).unwrap();
    let mut constraints = Constraints::new();
    for side in [Side::Left, Side::Right] {
        for field in fields {
            constraints.clamp::<M>(&mesh, &dofs, field, side).unwrap();
        }
    }
    let a = MatrixAssembler::new::<M>("a", &mesh, &dofs)
        .unwrap()
        .assemble::<M>(&mesh, &coefficients)
        .unwrap();
    assert!(
        asymmetry(&a) < 1e-14,
        "{}: the stiffness matrix is symmetric",
        M::NAME
    );
    let u = solve_linear::<M>(
        &mesh,
        &dofs,
        "a",
        "ℓ",
        &constraints,
        &coefficients,
        Factorization::Cholesky,
    )
    .unwrap();
    (mesh, dofs, u)
}

fn solve_bernoulli(n: usize) -> (IntervalMesh, SystemDofs, Vec<f64>) {
    solve_clamped::<bernoulli::Model>(n, &["w"], &[("α", 0.0), ("s", 1.0)])
}

#[test]
fn clamped_euler_bernoulli_beam_converges_at_hermite_rates() {
    let mut errors = [Vec::new(), Vec::new(), Vec::new()];
    for n in [4, 8, 16, 32, 64] {
        let (mesh, dofs, u) = solve_bernoulli(n);
        let map = dofs.map(0).unwrap();
        let view = FieldView {
            mesh: &mesh,
            map,
            coefficients: &u,
        };
        for (k, e) in errors.iter_mut().enumerate() {
            e.push(view.error(k, &|x| bernoulli_exact(x, k), 6));
        }
        // Hermite cubics are exact at the nodes for this load (the Green's function is cubic between loads).
        let mid = view.at(0.5, 0).unwrap();
        assert!((mid - Q / 384.0).abs() < 1e-13, "w(½) = {mid}");
    }
    assert_rate("Euler–Bernoulli L2", &errors[0], 4.0, 0.15);
    assert_rate("Euler–Bernoulli H1", &errors[1], 3.0, 0.15);
    assert_rate("Euler–Bernoulli H2", &errors[2], 2.0, 0.15);
}

fn solve_timoshenko<M: Model>(n: usize, t: f64) -> (IntervalMesh, SystemDofs, Vec<f64>) {
    solve_clamped::<M>(n, &["θ", "w"], &[("t", t), ("α", 1.0), ("s", 1.0)])
}

fn timoshenko_errors<M: Model>(t: f64, meshes: &[usize]) -> [Vec<f64>; 3] {
    let mut errors = [Vec::new(), Vec::new(), Vec::new()];
    for &n in meshes {
        let (mesh, dofs, u) = solve_timoshenko::<M>(n, t);
        let theta = &u[dofs.range(0).unwrap()];
        let w = &u[dofs.range(1).unwrap()];
        let view_w = FieldView {
            mesh: &mesh,
            map: dofs.map(1).unwrap(),
            coefficients: w,
        };
        let view_theta = FieldView {
            mesh: &mesh,
            map: dofs.map(0).unwrap(),
            coefficients: theta,
        };
        errors[0].push(view_w.error(0, &|x| timoshenko_w(x, 0, t), 6));
        errors[1].push(view_w.error(1, &|x| timoshenko_w(x, 1, t), 6));
        errors[2].push(view_theta.error(1, &|x| timoshenko_theta(x, 1), 6));
    }
    errors
}

#[test]
fn clamped_timoshenko_beam_p2_converges_for_thick_and_thin_beams() {
    // h < t (thick): the optimal P2 rates.
    let errors = timoshenko_errors::<timoshenko_p2::Model>(0.1, &[4, 8, 16, 32, 64]);
    assert_rate("Timoshenko P2 t=0.1 w L2", &errors[0], 3.0, 0.2);
    assert_rate("Timoshenko P2 t=0.1 w H1", &errors[1], 2.0, 0.2);
    assert_rate("Timoshenko P2 t=0.1 θ H1", &errors[2], 2.0, 0.2);
    // h ≫ t (thin): exactly integrated shear leaves the C¹-quadratic Kirchhoff limit,
    // so w converges at O(h²) in L2 uniformly in t (mild locking of full integration,
    // not a loss of convergence) and θ at O(h) in H1 … and the error at a fixed mesh
    // does not grow as t → 0.
    let thin = timoshenko_errors::<timoshenko_p2::Model>(1e-3, &[4, 8, 16, 32]);
    assert_rate("Timoshenko P2 t=1e-3 w L2", &thin[0], 2.0, 0.2);
    assert_rate("Timoshenko P2 t=1e-3 w H1", &thin[1], 2.0, 0.2);
    let thinner = timoshenko_errors::<timoshenko_p2::Model>(1e-5, &[4, 8, 16, 32]);
    for k in 0..3 {
        for (a, b) in thin[k].iter().zip(&thinner[k]) {
            assert!(
                b / a < 1.1,
                "error grows as t → 0: {a:e} at t = 1e-3, {b:e} at t = 1e-5"
            );
        }
    }
}

#[test]
fn timoshenko_midpoint_deflection_matches_q_over_384_plus_q_t2_over_8() {
    for t in [0.1, 0.01, 0.001] {
        let exact = Q / 384.0 + Q * t * t / 8.0;
        let errors: Vec<f64> = [16, 32, 64]
            .iter()
            .map(|&n| {
                let (mesh, dofs, u) = solve_timoshenko::<timoshenko_p2::Model>(n, t);
                let w = &u[dofs.range(1).unwrap()];
                let view = FieldView {
                    mesh: &mesh,
                    map: dofs.map(1).unwrap(),
                    coefficients: w,
                };
                (view.at(0.5, 0).unwrap() - exact).abs() / exact
            })
            .collect();
        println!("t = {t}: relative error of w(½) {errors:?}");
        assert!(
            errors[2] < 1e-3,
            "t = {t}: w(½) relative error {:e}",
            errors[2]
        );
        assert!(
            errors.windows(2).all(|e| e[1] < e[0] / 3.5 || e[1] < 1e-12),
            "t = {t}: {errors:?}"
        );
    }
}

#[test]
fn reduced_integration_p1_converges_without_locking() {
    // One-point shear integration: the P1 pair converges at O(h²) in w, L2, even for thin beams.
    for t in [1e-1, 1e-3] {
        let errors = timoshenko_errors::<timoshenko_p1_reduced::Model>(t, &[8, 16, 32, 64, 128]);
        assert_rate(
            &format!("Timoshenko P1 reduced t={t} w L2"),
            &errors[0],
            2.0,
            0.2,
        );
        assert_rate(
            &format!("Timoshenko P1 reduced t={t} θ H1"),
            &errors[2],
            1.0,
            0.2,
        );
    }
}
