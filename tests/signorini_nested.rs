//! Nested iteration for Signorini contact (issue 14, "Speed"): the nested solve ends at
//! the single-mesh solution of its finest mesh (same pressures, KKT residual at solver
//! precision), its Newton iterations on the refined levels are a few against the cold
//! (fully active) start's tens, and the accuracy-driven stop delivers a pressure whose
//! true error against Hertz's formula is within the tolerance asked for.
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

use fem_forms::models::signorini::{
    hertz_input, hertz_mesh, hertz_pressure_error, hertz_snap, solve_signorini,
    solve_signorini_nested, solve_signorini_to_accuracy, straight_boundary, AccuracyLimits,
    Displacement, Hertz, HertzData, LevelStart, NestedSignoriniSolution, Plane, SignoriniInput,
    SignoriniSolution,
};
use fem_forms::{Diagonal, TriangleMesh};

const HERTZ: Hertz = Hertz {
    radius: 1.0,
    young: 1000.0,
    poisson: 0.3,
    load: 1.0,
};

/// The Hertz coarse mesh of `hertz_mesh` at `b/h`.
fn hertz_coarse(b_over_h: f64) -> TriangleMesh {
    let b = HERTZ.half_width();
    hertz_mesh(1.0, 1.25 * b, b / b_over_h, 0.25).unwrap()
}

const Q: f64 = 2.5;

fn pressure(_: &[f64]) -> f64 {
    Q
}

fn no_gap(_: &[f64]) -> f64 {
    0.0
}

fn parabolic_gap(x: &[f64]) -> f64 {
    // the foundation curves away from the block's bottom: contact in the middle only
    0.02 * (x[0] - 0.5) * (x[0] - 0.5)
}

/// The unit block on the foundation (contact at the bottom, marker 1), pressed on its
/// top (3), roller on the left (4).
fn block_input(gap: &'static (dyn Fn(&[f64]) -> f64 + Sync)) -> SignoriniInput<'static> {
    SignoriniInput {
        young: 1000.0,
        poisson: 0.3,
        plane: Plane::Strain,
        element: Displacement::P1,
        contact: &[1],
        load: &[3],
        pressure: &pressure,
        gap,
        contact_direction: [0.0, -1.0],
        fixed_x: &[4],
        fixed_y: &[],
        rollers: &[],
        alpha: None,
        contact_centre: None,
    }
}

/// The nested solution against the cold single-mesh solve on the same finest mesh.
fn same_as_cold(nested: &NestedSignoriniSolution, cold: &SignoriniSolution, what: &str) {
    let s = &nested.solution;
    assert!(s.kkt_residual <= 1e-9, "{what}: KKT {}", s.kkt_residual);
    assert!(s.complementarity_residual <= 1e-9, "{what}");
    assert_eq!(s.pressure.len(), cold.pressure.len(), "{what}");
    let scale = cold.max_contact_pressure;
    for (k, (a, b)) in s.pressure.iter().zip(&cold.pressure).enumerate() {
        assert!(
            (a - b).abs() <= 1e-8 * scale,
            "{what}: edge {k}: nested λ = {a}, cold λ = {b}"
        );
    }
    assert!(
        (s.total_contact_force[1] + s.applied_load[1]).abs() <= 1e-10 * scale,
        "{what}: force {:?} load {:?}",
        s.total_contact_force,
        s.applied_load
    );
}

#[test]
fn nested_hertz_ends_at_the_cold_solution_in_a_few_iterations_per_level() {
    let data = HertzData::new(&HERTZ);
    let input = hertz_input(&HERTZ, Displacement::P1, None, &data);
    let snap = hertz_snap(1.0);
    let nested = solve_signorini_nested(&hertz_coarse(4.0), 2, &snap, &input).unwrap();
    assert_eq!(nested.levels.len(), 3);
    // the arc's new vertices are on the circle
    for e in &nested.solution.contact_edges {
        for [x, y] in e.ends {
            assert!((x.hypot(y - 1.0) - 1.0).abs() <= 1e-14, "({x}, {y})");
        }
    }
    // the nested solve keeps the coarse α while α max C_I stays in [0.45, 0.5]
    let s = &nested.solution;
    let largest = s.inverse_constants.iter().fold(0.0f64, |m, &c| m.max(c));
    assert!(
        (0.45..=0.5).contains(&(s.alpha * largest)),
        "{}",
        s.alpha * largest
    );
    let mut same_alpha = input;
    same_alpha.alpha = Some(s.alpha);
    let cold = solve_signorini(&nested.mesh, &same_alpha).unwrap();
    same_as_cold(&nested, &cold, "hertz");
    assert!((nested.solution.total_contact_force[1] - 0.5).abs() <= 1e-10);
    assert_eq!(nested.levels[0].start, LevelStart::Pressed);
    for (l, level) in nested.levels.iter().enumerate().skip(1) {
        assert_eq!(level.start, LevelStart::Prolongated, "level {l}");
        // measured 1–3; the cold start takes 25 on the finest mesh, 32 on the coarsest
        assert!(
            5 * level.iterations <= cold.iterations,
            "level {l}: {} iterations, cold {}",
            level.iterations,
            cold.iterations
        );
        // each uniform refinement quadruples the cells
        assert_eq!(level.cells, 4 * nested.levels[l - 1].cells);
    }
}

#[test]
fn nested_block_with_partial_contact_ends_at_the_cold_solution() {
    let input = block_input(&parabolic_gap);
    let coarse = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 4, 4, Diagonal::Alternating).unwrap();
    let nested = solve_signorini_nested(&coarse, 3, &straight_boundary, &input).unwrap();
    let cold = solve_signorini(&nested.mesh, &input).unwrap();
    // the cells keep their shapes exactly: the automatic α is the same on every level
    assert_eq!(nested.solution.alpha, cold.alpha);
    same_as_cold(&nested, &cold, "parabolic gap");
    let touching = cold.pressure.iter().filter(|&&p| p > 0.0).count();
    assert!(touching > 0 && touching < cold.pressure.len());
    for level in &nested.levels[1..] {
        assert!(
            level.iterations < cold.iterations,
            "{} against {}",
            level.iterations,
            cold.iterations
        );
    }
}

#[test]
fn nested_block_patch_keeps_the_exact_pressure() {
    let input = block_input(&no_gap);
    let coarse = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 3, 3, Diagonal::Right).unwrap();
    let nested = solve_signorini_nested(&coarse, 3, &straight_boundary, &input).unwrap();
    assert_eq!(nested.solution.pressure.len(), 24);
    for &p in &nested.solution.pressure {
        assert!((p - Q).abs() <= 1e-9 * Q, "λ_h = {p}, q = {Q}");
    }
    for level in &nested.levels[1..] {
        // λ_h = q on every level: the differences vanish
        assert!(level.pressure_change.unwrap() <= 1e-9);
        assert_eq!(level.start, LevelStart::Prolongated);
    }
}

#[test]
fn the_accuracy_driven_stop_meets_the_tolerance_against_hertz() {
    let data = HertzData::new(&HERTZ);
    let input = hertz_input(&HERTZ, Displacement::P1, None, &data);
    let snap = hertz_snap(1.0);
    for (b_over_h, tolerance) in [(2.0, 0.06), (4.0, 0.06)] {
        let solved = solve_signorini_to_accuracy(
            &hertz_coarse(b_over_h),
            &snap,
            &input,
            tolerance,
            AccuracyLimits::default(),
        )
        .unwrap();
        let last = solved.levels.last().unwrap();
        let estimate = last.estimated_error.unwrap();
        assert!(estimate <= tolerance);
        let error = hertz_pressure_error(&HERTZ, &solved.solution);
        assert!(
            error <= tolerance,
            "b/h {b_over_h} coarse: true error {error} > tolerance {tolerance} (estimate {estimate}, {} levels)",
            solved.levels.len()
        );
        // it did not stop before the estimate allowed it
        for level in &solved.levels[..solved.levels.len() - 1] {
            assert!(level.estimated_error.is_none_or(|e| e > tolerance));
        }
    }
}

#[test]
fn an_unreached_tolerance_is_an_error_naming_it() {
    let data = HertzData::new(&HERTZ);
    let input = hertz_input(&HERTZ, Displacement::P1, None, &data);
    let snap = hertz_snap(1.0);
    let coarse = hertz_coarse(2.0);
    let limits = AccuracyLimits {
        max_refinements: 2,
        max_dofs: 10_000_000,
    };
    let message = solve_signorini_to_accuracy(&coarse, &snap, &input, 0.001, limits)
        .unwrap_err()
        .to_string();
    assert!(message.contains("tolerance 1e-3"), "{message}");
    assert!(message.contains("2 refinements"), "{message}");
    let limits = AccuracyLimits {
        max_refinements: 8,
        max_dofs: 5_000,
    };
    let message = solve_signorini_to_accuracy(&coarse, &snap, &input, 0.001, limits)
        .unwrap_err()
        .to_string();
    assert!(message.contains("at most 5000 allowed"), "{message}");
    for bad in [0.0, -0.1, 1.0, f64::NAN] {
        let message = solve_signorini_to_accuracy(&coarse, &snap, &input, bad, limits)
            .unwrap_err()
            .to_string();
        assert!(message.contains("tolerance"), "{message}");
    }
    // the plain method has no Newton to nest
    let mut plain = input;
    plain.alpha = Some(0.0);
    let message = solve_signorini_nested(&coarse, 1, &snap, &plain)
        .unwrap_err()
        .to_string();
    assert!(message.contains("α"), "{message}");
}

#[test]
fn nested_p2_block_with_partial_contact_ends_at_the_cold_solution() {
    let mut input = block_input(&parabolic_gap);
    input.element = Displacement::P2;
    let coarse = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 3, 3, Diagonal::Alternating).unwrap();
    let nested = solve_signorini_nested(&coarse, 2, &straight_boundary, &input).unwrap();
    let mut same_alpha = input;
    same_alpha.alpha = Some(nested.solution.alpha);
    let cold = solve_signorini(&nested.mesh, &same_alpha).unwrap();
    same_as_cold(&nested, &cold, "P2, parabolic gap");
    for level in &nested.levels[1..] {
        assert_eq!(level.start, LevelStart::Prolongated);
        assert!(level.iterations < cold.iterations);
    }
}
