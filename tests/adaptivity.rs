//! A-posteriori estimates and adaptive solving on the membrane (`docs/adaptivity.md`):
//! the efficiency index against the exact radial solution, the estimate against the
//! true error over a whole adaptive run, and refinement that gathers where the solution
//! is rough.
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

#[path = "common/clamped_plate.rs"]
mod clamped_plate;

use fem_forms::adaptivity::{AdaptiveOptions, Marking};
use fem_forms::models::membrane_scenes::{
    radial_gradient, radial_multiplier, radial_obstacle, radial_u,
};
use fem_forms::models::{membrane_p1_p0, membrane_p2_p0, membrane_p2_p1disc};
use fem_forms::problem::{Exact, Problem, Solved};
use fem_forms::{Diagonal, DirichletPart, Model, TriangleMesh};

fn zero(_: &[f64]) -> f64 {
    0.0
}

fn gradient(x: &[f64]) -> [f64; 2] {
    radial_gradient(x)
}

/// The radial membrane problem on `(−2, 2)²` with model `M`, solved adaptively from an
/// `n × n` mesh to `tolerance`.
fn radial<M: Model>(n: usize, tolerance: f64, marking: Marking) -> Solved<M, TriangleMesh> {
    let mesh = TriangleMesh::rectangle(-2.0, 2.0, -2.0, 2.0, n, n, Diagonal::Right).unwrap();
    Problem::<M, TriangleMesh>::new(vec![mesh])
        .data("f", &zero)
        .data("ψ", &radial_obstacle)
        .data("g", &radial_u)
        .boundary_data(DirichletPart::All)
        .exact(Exact {
            value: &radial_u,
            gradient: Some(&gradient),
            hessian: None,
            multiplier: Some(&radial_multiplier),
        })
        .solve_adaptive(
            AdaptiveOptions {
                tolerance,
                marking,
                max_dofs: 200_000,
            },
            |_| {},
        )
        .unwrap_or_else(|e| panic!("{}: {e}", M::NAME))
}

/// Over a whole adaptive run the estimate stays within a fixed band of the true H¹
/// error (reliability and efficiency), the run ends below its tolerance, and the error
/// falls at least like `N^{-rate}` in the unknowns N (the optimal rates: ½ for P1, 1 for
/// P2, which uniform refinement misses at the kink of the free boundary).
fn efficiency_stays_bounded<M: Model>(tolerance: f64, rate: f64) {
    let solved = radial::<M>(8, tolerance, Marking::default());
    let levels = &solved.report.adaptive_levels;
    assert!(levels.len() >= 4, "{}: {levels:?}", M::NAME);
    let (indices, low, high) = efficiency_indices(levels);
    assert!(
        low > 0.5 && high < 20.0 && high / low < 5.0,
        "{}: efficiency indices {indices:?}",
        M::NAME
    );
    let last = levels.last().unwrap();
    assert!(last.estimate <= tolerance * last.energy_norm, "{last:?}");
    // the error falls with the estimate
    let first = &levels[0];
    assert!(
        last.error_energy.unwrap() < 0.5 * first.error_energy.unwrap(),
        "{levels:?}"
    );
    let observed = (first.error_energy.unwrap() / last.error_energy.unwrap()).ln()
        / (last.dofs as f64 / first.dofs as f64).ln();
    assert!(
        observed >= rate,
        "{}: rate {observed} below {rate}",
        M::NAME
    );
    assert_eq!(solved.report.estimate, Some(last.estimate));
    assert_eq!(
        solved.report.efficiency_index,
        Some(indices[indices.len() - 1])
    );
}

#[test]
fn p1_p0_efficiency_stays_bounded_over_an_adaptive_run() {
    efficiency_stays_bounded::<membrane_p1_p0::Model>(0.08, 0.48);
}

#[test]
fn p2_p0_efficiency_stays_bounded_over_an_adaptive_run() {
    efficiency_stays_bounded::<membrane_p2_p0::Model>(0.02, 0.95);
}

#[test]
fn p2_p1disc_efficiency_stays_bounded_over_an_adaptive_run() {
    efficiency_stays_bounded::<membrane_p2_p1disc::Model>(0.02, 0.95);
}

/// Adaptive P1 reaches the error of uniform refinement with fewer unknowns: the radial
/// solution's kink at the free boundary r* draws the refinement.
#[test]
fn adaptive_refinement_beats_uniform_at_equal_error() {
    type M = membrane_p1_p0::Model;
    let adaptive = radial::<M>(8, 0.05, Marking::default());
    let last = adaptive.report.adaptive_levels.last().unwrap();
    let error = last.error_energy.unwrap();
    // uniform meshes until the same error
    let mut n = 8;
    let uniform = loop {
        let mesh = TriangleMesh::rectangle(-2.0, 2.0, -2.0, 2.0, n, n, Diagonal::Right).unwrap();
        let solved = Problem::<M, TriangleMesh>::new(vec![mesh])
            .data("f", &zero)
            .data("ψ", &radial_obstacle)
            .data("g", &radial_u)
            .boundary_data(DirichletPart::All)
            .exact(Exact {
                value: &radial_u,
                gradient: Some(&gradient),
                hessian: None,
                multiplier: None,
            })
            .solve()
            .unwrap();
        if solved.report.error_h1.unwrap() <= error || n >= 256 {
            break solved.report;
        }
        n *= 2;
    };
    assert!(
        uniform.error_h1.unwrap() <= error,
        "uniform never reached {error:e}"
    );
    assert!(
        last.dofs < uniform.dofs,
        "adaptive {} unknowns against uniform {} at error {error:e}",
        last.dofs,
        uniform.dofs
    );
}

/// Cells near the free boundary r* ≈ 0.698 are refined more than those far from it.
#[test]
fn refinement_gathers_at_the_free_boundary() {
    type M = membrane_p1_p0::Model;
    let solved = radial::<M>(8, 0.05, Marking::default());
    let mesh = solved.mesh();
    let (mut near, mut far) = (Vec::new(), Vec::new());
    for c in 0..mesh.cell_count() {
        let x = mesh.cell_coordinates(c);
        let centre = [(x[0] + x[2] + x[4]) / 3.0, (x[1] + x[3] + x[5]) / 3.0];
        let r = centre[0].hypot(centre[1]);
        let h = mesh.cell_diameter(c);
        if (r - 0.698).abs() < 0.1 {
            near.push(h);
        } else if r > 1.5 && r < 1.9 {
            far.push(h);
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    assert!(
        mean(&near) < 0.5 * mean(&far),
        "mean h near r*: {}, far: {}",
        mean(&near),
        mean(&far)
    );
}

/// A model without an estimator cannot be solved to a tolerance, and a bad tolerance
/// or a limit too small are errors that say how far the loop got.
#[test]
fn adaptive_errors_are_clear() {
    let mesh = TriangleMesh::rectangle(-2.0, 2.0, -2.0, 2.0, 4, 4, Diagonal::Right).unwrap();
    let problem = Problem::<membrane_p1_p0::Model, TriangleMesh>::new(vec![mesh])
        .data("f", &zero)
        .data("ψ", &radial_obstacle)
        .data("g", &radial_u)
        .boundary_data(DirichletPart::All);
    let options = |tolerance, max_dofs| AdaptiveOptions {
        tolerance,
        marking: Marking::default(),
        max_dofs,
    };
    let e = problem
        .solve_adaptive(options(-1.0, 1000), |_| {})
        .err()
        .unwrap();
    assert!(e.to_string().contains("not a positive number"), "{e}");
    let e = problem
        .solve_adaptive(options(1e-6, 300), |_| {})
        .err()
        .unwrap();
    let message = e.to_string();
    assert!(
        message.contains("beyond the limit of 300") && message.contains("after"),
        "{message}"
    );
    let mut seen = 0;
    let _ = problem.solve_adaptive(options(1e-6, 300), |_| seen += 1);
    assert!(seen >= 1);
}

/// On the L-shaped membrane (re-entrant corner, free boundary) the adaptive estimate
/// falls at the optimal rates N^{-1/2} (P1) and N^{-1} (P2), where uniform refinement
/// is held to N^{-1/3} by the corner; through the registry's one solve path.
#[test]
fn l_shape_estimates_fall_at_the_optimal_rates() {
    use fem_forms::models::families;
    use fem_forms::models::report::Settings;
    let scene = families::scenes()
        .into_iter()
        .find(|s| s.name == "membrane-lshape")
        .unwrap();
    for (pair, tolerance, rate) in [("p1-p0", 0.25, 0.45), ("p2-p0", 0.02, 0.9)] {
        let settings = Settings {
            pair: Some(pair.into()),
            mesh_size: Some(8),
            adaptive: Some(AdaptiveOptions {
                tolerance,
                ..AdaptiveOptions::default()
            }),
            ..Settings::default()
        };
        let outcome = families::solve(&scene, &settings).unwrap_or_else(|e| panic!("{pair}: {e}"));
        let levels = &outcome.report.solve.adaptive_levels;
        let (first, last) = (levels.first().unwrap(), levels.last().unwrap());
        let observed =
            (first.estimate / last.estimate).ln() / (last.dofs as f64 / first.dofs as f64).ln();
        assert!(
            levels.len() >= 6 && observed >= rate,
            "{pair}: rate {observed} over {} levels",
            levels.len()
        );
    }
}

/// The efficiency indices `η / ‖e‖` of the levels of an adaptive run, with their least
/// and largest.
fn efficiency_indices(levels: &[fem_forms::adaptivity::AdaptiveLevel]) -> (Vec<f64>, f64, f64) {
    let indices: Vec<f64> = levels
        .iter()
        .map(|l| l.estimate / l.error_energy.unwrap())
        .collect();
    let (low, high) = indices
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &i| (a.min(i), b.max(i)));
    (indices, low, high)
}

/// The manufactured clamped Kirchhoff plate `w = (x(1−x)y(1−y))²` under `f = DΔ²w`, its
/// obstacle far below (λ = 0): over an adaptive run the estimate (cell residual, Kirchhoff
/// shear and normal moment jumps; Morley's tangential-derivative jumps) stays within a
/// band of the true broken H² error.
mod kirchhoff {
    use super::*;
    use fem_forms::models::kirchhoff::{kirchhoff_argyris_p0, kirchhoff_morley_p0};
    use fem_forms::problem::Condition;

    use clamped_plate::{gradient, hessian, load, w, D};

    fn below(_: &[f64]) -> f64 {
        -1.0
    }

    fn run<M: Model>(n: usize, tolerance: f64) -> Vec<fem_forms::adaptivity::AdaptiveLevel> {
        let mesh = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, n, n, Diagonal::Right).unwrap();
        Problem::<M, TriangleMesh>::new(vec![mesh])
            .param("D", D)
            .param("ν", 0.3)
            .data("f", &load)
            .data("ψ", &below)
            .data("g", &zero)
            .support(DirichletPart::All, "w", Condition::Clamped)
            .exact(Exact {
                value: &w,
                gradient: Some(&gradient),
                hessian: Some(&hessian),
                multiplier: None,
            })
            .solve_adaptive(
                AdaptiveOptions {
                    tolerance,
                    marking: Marking::default(),
                    max_dofs: 100_000,
                },
                |_| {},
            )
            .unwrap_or_else(|e| panic!("{}: {e}", M::NAME))
            .report
            .adaptive_levels
    }

    fn bounded<M: Model>(n: usize, tolerance: f64) {
        let levels = run::<M>(n, tolerance);
        let (indices, low, high) = efficiency_indices(&levels);
        assert!(
            levels.len() >= 3 && low > 0.3 && high / low < 5.0,
            "{}: efficiency indices {indices:?}",
            M::NAME
        );
        let (first, last) = (&levels[0], levels.last().unwrap());
        assert!(
            last.error_energy.unwrap() < 0.3 * first.error_energy.unwrap(),
            "{levels:?}"
        );
    }

    #[test]
    fn argyris_efficiency_stays_bounded() {
        bounded::<kirchhoff_argyris_p0::Model>(2, 1e-3);
    }

    #[test]
    fn morley_efficiency_stays_bounded() {
        bounded::<kirchhoff_morley_p0::Model>(8, 0.05);
    }
}
