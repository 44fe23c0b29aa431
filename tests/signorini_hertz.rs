//! Hertz line contact (docs/contact.md): a half disc (R = 1, E = 1000, ν = 0.3, plane
//! strain, P = 1; its right half with a symmetry condition) pressed onto a rigid plane,
//! on meshes graded towards the contact zone, b/h = 8 … 64, against `b = √(4PR/(πE*))`,
//! `p_max = 2P/(πb)`, `p(x) = p_max √(1 − x²/b²)`; the plain method (α = 0) shown worse
//! and oscillating.
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

use fem_forms::models::signorini::{solve_hertz, Displacement, Hertz, HertzResult};

const HERTZ: Hertz = Hertz {
    radius: 1.0,
    young: 1000.0,
    poisson: 0.3,
    load: 1.0,
};

#[test]
fn hertz_formulas_match_the_quoted_values() {
    assert!((HERTZ.half_width() - 0.0340389).abs() < 1e-7);
    assert!((HERTZ.max_pressure() - 18.7027).abs() < 1e-4);
    assert_eq!(HERTZ.pressure(0.04), 0.0);
}

fn solve(b_over_h: f64, element: Displacement, alpha: Option<f64>) -> HertzResult {
    solve_hertz(HERTZ, b_over_h, element, alpha).unwrap()
}

/// The identities and the solver's certificate, on every run.
fn check_common(r: &HertzResult, what: &str) {
    let s = &r.solution;
    // the quarter carries half the resultant; a rigid vertical translation lies in V_h
    assert!(
        (s.total_contact_force[1] - 0.5).abs() <= 1e-10,
        "{what}: contact force {:?}",
        s.total_contact_force
    );
    assert!(
        (s.applied_load[1] + 0.5).abs() <= 1e-12,
        "{what}: load {:?}",
        s.applied_load
    );
    assert!(
        s.complementarity_residual <= 1e-6,
        "{what}: {}",
        s.complementarity_residual
    );
    assert!(
        s.pressure.iter().all(|&p| p >= 0.0),
        "{what}: a negative pressure"
    );
}

/// Stabilized P1–P0 with the automatic α: the pressure converges (the square-root edge
/// caps the rate at O(h)) within 1.7× of the best P0 fit, the half-width within two
/// cells, the peak within 1 %.
#[test]
fn stabilized_p1_converges_to_hertz() {
    let b = HERTZ.half_width();
    let mut errors = Vec::new();
    for b_over_h in [8.0, 16.0, 32.0, 64.0] {
        let r = solve(b_over_h, Displacement::P1, None);
        let what = format!("P1 b/h = {b_over_h}");
        check_common(&r, &what);
        let s = &r.solution;
        assert!(
            r.pressure_l2_error <= 1.7 * r.best_fit_l2_error,
            "{what}: L² error {} against the best fit {}",
            r.pressure_l2_error,
            r.best_fit_l2_error
        );
        assert!(
            (s.contact_half_width - b).abs() <= 2.0 * r.contact_h,
            "{what}: half-width {} against {b}",
            s.contact_half_width
        );
        assert!(
            (s.max_contact_pressure - HERTZ.max_pressure()).abs() <= 0.01 * HERTZ.max_pressure(),
            "{what}: peak {}",
            s.max_contact_pressure
        );
        errors.push(r.pressure_l2_error);
    }
    assert!(errors[3] < 0.3 * errors[0], "no convergence: {errors:?}");
}

/// P2–P0 is within 10 % of the best P0 fit at b/h = 32.
#[test]
fn stabilized_p2_is_close_to_the_best_fit() {
    let r = solve(32.0, Displacement::P2, None);
    check_common(&r, "P2");
    assert!(
        r.pressure_l2_error <= 1.1 * r.best_fit_l2_error,
        "P2: {} against the best fit {}",
        r.pressure_l2_error,
        r.best_fit_l2_error
    );
}

/// The plain P1–P0 method (α = 0, solved as a QP) on the same meshes: a larger error
/// and an oscillating pressure, where the stabilized one is smooth.
#[test]
fn plain_p1_p0_oscillates() {
    for b_over_h in [16.0, 64.0] {
        let plain = solve(b_over_h, Displacement::P1, Some(0.0));
        let stabilized = solve(b_over_h, Displacement::P1, None);
        check_common(&plain, "plain");
        assert!(
            plain.pressure_l2_error > 1.3 * stabilized.pressure_l2_error,
            "b/h = {b_over_h}: plain {} against stabilized {}",
            plain.pressure_l2_error,
            stabilized.pressure_l2_error
        );
        assert!(
            plain.oscillation > 3.0 * stabilized.oscillation,
            "b/h = {b_over_h}: oscillation plain {} against stabilized {}",
            plain.oscillation,
            stabilized.oscillation
        );
    }
}
