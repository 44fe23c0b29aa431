//! Hertz line contact (docs/contact.md) through the one pipeline: the built-in `hertz`
//! scene, a half disc (R = 1, E = 1000, ν = 0.3, plane strain, P = 1; its right half
//! with a symmetry condition) pressed onto a rigid plane, on meshes graded towards the
//! contact zone, b/h = 8 … 64, against `b = √(4PR/(πE*))`, `p_max = 2P/(πb)`,
//! `p(x) = p_max √(1 − x²/b²)`, for P0 and continuous P1 multipliers; the plain method
//! (α = 0) shown worse and oscillating.
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

#[path = "common/contact.rs"]
mod contact;

use contact::{solve_scene, Solved};
use fem_forms::models::hertz::Hertz;

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

/// The `hertz` scene with `pair` at `b/h`, α the automatic one or `alpha`.
fn solve(pair: &str, b_over_h: usize, alpha: Option<f64>) -> Solved {
    solve_scene("hertz", |s| {
        s.pair = Some(pair.into());
        s.mesh_size = Some(b_over_h);
        s.alpha = alpha;
    })
    .unwrap_or_else(|e| panic!("{pair} b/h = {b_over_h}: {e}"))
}

/// The identities and the solver's certificate, on every run; with `shape`, the peak
/// within `peak` (relative) and the half-width within two cells (not for the QP: its
/// interior-point answer leaves λ ≈ 1e-9 p_max outside the contact zone).
fn check(r: &Solved, what: &str, shape: Option<f64>) {
    // a rigid vertical translation lies in V_h: the contact force is the load P
    let force = r.quantity("total_contact_force");
    assert!(
        (force - 1.0).abs() <= 1e-10,
        "{what}: contact force {force}"
    );
    assert!((r.quantity("applied_load") - 1.0).abs() <= 1e-12, "{what}");
    assert!(
        r.report.solve.complementarity_residual <= 1e-6,
        "{what}: {}",
        r.report.solve.complementarity_residual
    );
    assert!(
        r.pressures().iter().all(|&p| p >= 0.0),
        "{what}: a negative pressure"
    );
    let Some(peak) = shape else {
        return;
    };
    let b = HERTZ.half_width();
    let h = b / r.report.mesh_size as f64;
    let width = r.quantity("contact_half_width");
    assert!(
        (width - b).abs() <= 2.0 * h,
        "{what}: half-width {width} against {b}"
    );
    let max = r.quantity("max_contact_pressure");
    assert!(
        (max / HERTZ.max_pressure() - 1.0).abs() <= peak,
        "{what}: peak {max}"
    );
}

/// `‖λ_h − p‖ / ‖p‖` over the best fit's in the multiplier's space.
fn ratio(r: &Solved) -> f64 {
    r.quantity("pressure_l2_error") / r.quantity("best_fit_l2_error")
}

/// Stabilized P1–P0 with the automatic α: the pressure converges (the square-root edge
/// caps the rate at O(h)) within 1.7× of the best P0 fit, the half-width within two
/// cells, the peak within 1 %.
#[test]
fn stabilized_p1_p0_converges_to_hertz() {
    let mut errors = Vec::new();
    for b_over_h in [8, 16, 32, 64] {
        let r = solve("p1-p0", b_over_h, None);
        let what = format!("p1-p0 b/h = {b_over_h}");
        check(&r, &what, Some(0.01));
        assert!(ratio(&r) <= 1.7, "{what}: {}", ratio(&r));
        assert_eq!(
            r.quantity("best_p0_l2_error"),
            r.quantity("best_fit_l2_error")
        );
        errors.push(r.quantity("pressure_l2_error"));
    }
    assert!(errors[3] < 0.3 * errors[0], "no convergence: {errors:?}");
}

/// P2–P0 is within 10 % of the best P0 fit at b/h = 32.
#[test]
fn stabilized_p2_p0_is_close_to_the_best_fit() {
    let r = solve("p2-p0", 32, None);
    check(&r, "p2-p0", None);
    assert!(ratio(&r) <= 1.1, "p2-p0: {}", ratio(&r));
}

/// The plain P1–P0 method (α = 0, solved as a QP) on the same meshes: a larger error
/// and an oscillating pressure, where the stabilized one is smooth.
#[test]
fn plain_p1_p0_oscillates() {
    for b_over_h in [16, 64] {
        let plain = solve("p1-p0", b_over_h, Some(0.0));
        let stabilized = solve("p1-p0", b_over_h, None);
        check(&plain, "plain", None);
        let error = |r: &Solved| r.quantity("pressure_l2_error");
        assert!(
            error(&plain) > 1.3 * error(&stabilized),
            "b/h = {b_over_h}: plain {} against stabilized {}",
            error(&plain),
            error(&stabilized)
        );
        let oscillation = |r: &Solved| r.quantity("oscillation");
        assert!(
            oscillation(&plain) > 3.0 * oscillation(&stabilized),
            "b/h = {b_over_h}: oscillation plain {} against stabilized {}",
            oscillation(&plain),
            oscillation(&stabilized)
        );
    }
}

/// A continuous P1 multiplier at b/h = 16, 32 (measured, docs/contact.md: .0161, .0120
/// against the best continuous P1 fit's .0094, .0084): within 2× of the best fit and
/// decreasing, no best P0 fit reported; the plain method (α = 0, QP) for comparison:
/// the same order (.0174, .0143), not better; P2–P1 within 1.3× of the best fit
/// (measured 1.20 at b/h = 32).
#[test]
fn a_p1_multiplier_against_the_best_p1_fit() {
    let mut errors = Vec::new();
    for b_over_h in [16, 32] {
        let r = solve("p1-p1", b_over_h, None);
        let what = format!("p1-p1 b/h = {b_over_h}");
        check(&r, &what, Some(5e-3));
        assert!((1.0..2.0).contains(&ratio(&r)), "{what}: {}", ratio(&r));
        assert!(r.quantity("best_p0_l2_error").is_nan(), "{what}");
        let plain = solve("p1-p1", b_over_h, Some(0.0));
        check(&plain, &format!("plain {what}"), None);
        let error = |r: &Solved| r.quantity("pressure_l2_error");
        assert!(
            error(&plain) >= error(&r) && error(&plain) < 1.5 * error(&r),
            "{what}: plain {} stabilized {}",
            error(&plain),
            error(&r)
        );
        errors.push(error(&r));
    }
    assert!(errors[1] < errors[0], "{errors:?}");
    let p2 = solve("p2-p1", 32, None);
    check(&p2, "p2-p1 b/h = 32", Some(5e-3));
    assert!((1.0..1.3).contains(&ratio(&p2)), "p2-p1: {}", ratio(&p2));
}
