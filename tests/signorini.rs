//! Signorini contact (docs/contact.md) solved end to end: the patch test (an elastic block
//! on a rigid foundation under a uniform pressure q: λ_h = q exactly on every contact
//! edge, which catches the sign inside `λ + σ_n`), vertical equilibrium (total contact
//! force = load, an identity since a rigid translation lies in V_h), complementarity,
//! the inverse constants computed from the kernels against the P1 closed form, and the
//! errors on bad input.
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

use fem_forms::models::signorini::{
    lame, solve_signorini, Displacement, Plane, SignoriniInput, SignoriniSolution,
};
use fem_forms::{Diagonal, TriangleMesh};

const Q: f64 = 2.5;

fn pressure(_x: &[f64]) -> f64 {
    Q
}

fn pulling(_x: &[f64]) -> f64 {
    -Q
}

fn no_gap(_x: &[f64]) -> f64 {
    0.0
}

/// The unit block, contact at the bottom (marker 1), pressure on the top (3), a roller
/// `u_x = 0` on the left (4).
fn block_input(element: Displacement, alpha: Option<f64>) -> SignoriniInput<'static> {
    SignoriniInput {
        young: 1000.0,
        poisson: 0.3,
        plane: Plane::Strain,
        element,
        contact: &[1],
        load: &[3],
        pressure: &pressure,
        gap: &no_gap,
        contact_direction: [0.0, -1.0],
        fixed_x: &[4],
        fixed_y: &[],
        rollers: &[],
        alpha,
        contact_centre: None,
    }
}

fn block(n: usize, diagonal: Diagonal) -> TriangleMesh {
    TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, n, n, diagonal).unwrap()
}

fn check_patch(s: &SignoriniSolution, what: &str) {
    assert!(!s.pressure.is_empty());
    for (k, &p) in s.pressure.iter().enumerate() {
        assert!(
            (p - Q).abs() <= 1e-9 * Q,
            "{what}: λ_h = {p} on contact edge {k}, expected q = {Q}"
        );
    }
    // equilibrium: the foundation carries the load
    assert!(
        (s.total_contact_force[1] + s.applied_load[1]).abs() <= 1e-10 * Q,
        "{what}: contact force {:?}, load {:?}",
        s.total_contact_force,
        s.applied_load
    );
    assert!(
        (s.applied_load[1] + Q).abs() <= 1e-12,
        "{what}: load {:?}",
        s.applied_load
    );
    assert!(
        s.complementarity_residual <= 1e-9,
        "{what}: {}",
        s.complementarity_residual
    );
    assert!(s.kkt_residual <= 1e-9, "{what}: {}", s.kkt_residual);
    assert!((s.contact_half_width - 0.5).abs() <= 1e-12);
}

#[test]
fn patch_test_p1_gives_the_pressure_exactly() {
    for diagonal in [
        Diagonal::Right,
        Diagonal::Left,
        Diagonal::Alternating,
        Diagonal::Crossed,
    ] {
        for n in [2, 5] {
            let s =
                solve_signorini(&block(n, diagonal), &block_input(Displacement::P1, None)).unwrap();
            check_patch(&s, &format!("P1 {diagonal:?} n = {n}"));
        }
    }
}

#[test]
fn patch_test_p2_gives_the_pressure_exactly() {
    for diagonal in [Diagonal::Right, Diagonal::Alternating] {
        let s = solve_signorini(&block(3, diagonal), &block_input(Displacement::P2, None)).unwrap();
        check_patch(&s, &format!("P2 {diagonal:?}"));
    }
}

/// The patch holds for every α up to `1/max C_I` (the exact solution satisfies the
/// stabilized equations: consistency), and for the plain method (α = 0, by the QP).
/// (At `α max C_I = 1.5` this mesh's Newton Hessian `A_α + B_αᵀC_α⁻¹B_α` is not positive
/// definite and semismooth Newton refuses it: an error, not a wrong answer.)
#[test]
fn patch_test_holds_for_every_alpha() {
    let mesh = block(4, Diagonal::Alternating);
    let auto = solve_signorini(&mesh, &block_input(Displacement::P1, None)).unwrap();
    let max_ci = auto.inverse_constants.iter().fold(0.0f64, |m, &c| m.max(c));
    for factor in [0.1, 0.5, 1.0] {
        let s = solve_signorini(&mesh, &block_input(Displacement::P1, Some(factor / max_ci)))
            .unwrap_or_else(|e| panic!("α C_I = {factor}: {e}"));
        check_patch(&s, &format!("α C_I = {factor}"));
    }
    let plain = solve_signorini(&mesh, &block_input(Displacement::P1, Some(0.0))).unwrap();
    for &p in &plain.pressure {
        assert!((p - Q).abs() <= 1e-6 * Q, "plain: λ_h = {p}");
    }
}

/// α = 1/(2 max C_I,E) with C_I,E from the kernels' generalized eigenvalue problem,
/// against the P1 closed form `h_E |E| (λ_L + 2μ)/|T_E|`.
#[test]
fn inverse_constants_match_the_p1_closed_form() {
    for plane in [Plane::Strain, Plane::Stress] {
        let mut input = block_input(Displacement::P1, None);
        input.plane = plane;
        let mesh = TriangleMesh::rectangle(0.0, 2.0, 0.0, 1.0, 5, 3, Diagonal::Alternating)
            .unwrap()
            .refine(&[0, 3])
            .unwrap()
            .0;
        let s = solve_signorini(&mesh, &input).unwrap();
        let (mu, lambda) = lame(input.young, input.poisson, plane).unwrap();
        let mut max = 0.0f64;
        for (e, &c) in s.contact_edges.iter().zip(&s.inverse_constants) {
            let l = e.length();
            let closed = l * l * (lambda + 2.0 * mu) / mesh.area(e.cell);
            assert!(
                (c - closed).abs() <= 1e-9 * closed,
                "C_I = {c}, closed form {closed}"
            );
            max = max.max(closed);
        }
        assert!((s.alpha - 0.5 / max).abs() <= 1e-9 * s.alpha);
    }
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let mesh = block(2, Diagonal::Right);
    let message = |input: &SignoriniInput| solve_signorini(&mesh, input).unwrap_err().to_string();
    let mut input = block_input(Displacement::P1, None);
    input.young = 0.0;
    assert!(message(&input).contains("Young"), "{}", message(&input));
    let mut input = block_input(Displacement::P1, None);
    input.poisson = 0.5;
    assert!(message(&input).contains("Poisson"), "{}", message(&input));
    let mut input = block_input(Displacement::P1, None);
    input.contact = &[9];
    assert!(
        message(&input).contains("not on the boundary"),
        "{}",
        message(&input)
    );
    let mut input = block_input(Displacement::P1, None);
    input.pressure = &pulling;
    assert!(
        message(&input).contains("rigid motion"),
        "{}",
        message(&input)
    );
    let mut input = block_input(Displacement::P1, None);
    input.alpha = Some(-1.0);
    assert!(message(&input).contains("α"), "{}", message(&input));
    // the top and the right side pressed, nothing holding the block along x: it slides
    // (frictionless contact cannot hold it; a tester's file "solved" with a 1 % error)
    let mut input = block_input(Displacement::P1, None);
    input.load = &[2, 3];
    input.fixed_x = &[];
    assert!(
        message(&input).contains("pushes it that way"),
        "{}",
        message(&input)
    );
    // a support along n_c on the contact part itself
    let mut input = block_input(Displacement::P1, None);
    input.fixed_y = &[1];
    assert!(
        message(&input).contains("also has u_y = 0"),
        "{}",
        message(&input)
    );
    // balanced sideways (left and right pressed alike) the translation is still free
    let mut input = block_input(Displacement::P1, None);
    input.load = &[2, 3, 4];
    input.fixed_x = &[];
    assert!(
        message(&input).contains("no support fixes"),
        "{}",
        message(&input)
    );
}

fn parabolic_gap(x: &[f64]) -> f64 {
    // the foundation curves away from the block's bottom: contact in the middle only
    0.02 * (x[0] - 0.5) * (x[0] - 0.5)
}

/// A non-flat initial gap: only part of Γ_C touches. Newton's answer against clarabel's
/// QP on the same LCP (an independent solver), the contact force against the load, and
/// a contact zone that is neither empty nor the whole bottom.
#[test]
fn non_flat_gap_newton_agrees_with_the_qp() {
    use fem_forms::lcp::{quadratic_program, semismooth_newton, NewtonOptions};
    use fem_forms::models::signorini::signorini_p1::{self, Model as M};
    use fem_forms::obstacle::boundary_multiplier::discretize_on_parts;
    use fem_forms::Coefficients;
    let mesh = block(8, Diagonal::Alternating);
    let mut input = block_input(Displacement::P1, None);
    input.gap = &parabolic_gap;
    let s = solve_signorini(&mesh, &input).unwrap();
    assert!(
        (s.total_contact_force[1] + s.applied_load[1]).abs() <= 1e-10 * Q,
        "{:?} {:?}",
        s.total_contact_force,
        s.applied_load
    );
    let touching = s.pressure.iter().filter(|&&p| p > 0.0).count();
    assert!(
        touching > 0 && touching < s.pressure.len(),
        "{touching} of {}",
        s.pressure.len()
    );
    assert!(s.contact_half_width < 0.5);

    let (mu, lambda) = lame(input.young, input.poisson, input.plane).unwrap();
    let coefficients = Coefficients::from_ids(
        &[
            (signorini_p1::params::μ_L, mu),
            (signorini_p1::params::λ_L, lambda),
            (signorini_p1::params::α, s.alpha),
            (signorini_p1::params::n_c_x, 0.0),
            (signorini_p1::params::n_c_y, -1.0),
        ],
        &[
            (signorini_p1::data::q, &pressure),
            (signorini_p1::data::g, &parabolic_gap),
        ],
    )
    .unwrap();
    let problem = discretize_on_parts::<M, _, _>(
        &mesh,
        &coefficients,
        &[
            (signorini_p1::facets::Γ_C, &[1]),
            (signorini_p1::facets::Γ_N, &[3]),
        ],
        &[(signorini_p1::fields::u_x, &[4])],
    )
    .unwrap();
    let n = problem.lcp.n();
    let newton = semismooth_newton(
        &problem.lcp,
        Some(&vec![-0.01; n]),
        NewtonOptions::default(),
    )
    .unwrap();
    let qp = quadratic_program(&problem.lcp).unwrap();
    let scale = qp.lambda.iter().fold(0.0f64, |m, &l| m.max(l));
    for (k, (a, b)) in newton.lambda.iter().zip(&qp.lambda).enumerate() {
        assert!(
            (a - b).abs() <= 1e-6 * scale,
            "edge {k}: Newton {a}, QP {b}"
        );
    }
    for (k, (a, b)) in newton.lambda.iter().zip(&s.pressure).enumerate() {
        assert!(
            (a - b).abs() <= 1e-9 * scale,
            "edge {k}: {a} against solve_signorini's {b}"
        );
    }
}
