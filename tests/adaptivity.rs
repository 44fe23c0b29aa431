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
use fem_forms::models::{membrane_p1, membrane_p1_p0, membrane_p2_p0, membrane_p2_p1disc};
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
    radial_by::<M>(n, tolerance, marking, false)
}

/// [`radial`], by the nodal method where `nodal` (`M` the nodal method's model).
fn radial_by<M: Model>(
    n: usize,
    tolerance: f64,
    marking: Marking,
    nodal: bool,
) -> Solved<M, TriangleMesh> {
    let mesh = TriangleMesh::rectangle(-2.0, 2.0, -2.0, 2.0, n, n, Diagonal::Right).unwrap();
    let problem = Problem::<M, TriangleMesh>::new(vec![mesh]);
    let problem = if nodal {
        problem.nodal(&radial_obstacle)
    } else {
        problem
    };
    problem
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
                ..AdaptiveOptions::default()
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
    efficiency_stays_bounded_by::<M>(tolerance, rate, false);
}

/// [`efficiency_stays_bounded`], by the nodal method where `nodal`.
fn efficiency_stays_bounded_by<M: Model>(tolerance: f64, rate: f64, nodal: bool) {
    let solved = radial_by::<M>(8, tolerance, Marking::default(), nodal);
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

/// The nodal method's estimator reads the density of its nodal forces (mass-lumped, as
/// a P1 multiplier): the same band and the P1 rate as the stabilized pair's.
#[test]
fn p1_nodal_efficiency_stays_bounded_over_an_adaptive_run() {
    efficiency_stays_bounded_by::<membrane_p1::Model>(0.08, 0.48, true);
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
        ..AdaptiveOptions::default()
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
        message.contains("beyond the adaptive loop's limit of 300") && message.contains("after"),
        "{message}"
    );
    let mut seen = 0;
    let _ = problem.solve_adaptive(options(1e-6, 300), |_| seen += 1);
    assert!(seen >= 1);
}

/// A boundary layer given to the loop is resolved whatever the estimate: at a tolerance
/// the first mesh already meets, the loop goes on refining along the layer's edges
/// (marker 1, y = −2) until they are no longer than its width, and nowhere else; a limit
/// too small for it says how many of its cells are still too long.
#[test]
fn a_boundary_layer_is_refined_to_its_width_whatever_the_estimate() {
    use fem_forms::adaptivity::BoundaryLayer;
    let mesh = TriangleMesh::rectangle(-2.0, 2.0, -2.0, 2.0, 8, 8, Diagonal::Right).unwrap();
    let problem = Problem::<membrane_p1_p0::Model, TriangleMesh>::new(vec![mesh])
        .data("f", &zero)
        .data("ψ", &radial_obstacle)
        .data("g", &radial_u)
        .boundary_data(DirichletPart::All);
    let layer = BoundaryLayer {
        width: 0.05,
        markers: vec![1],
    };
    let options = |max_dofs| AdaptiveOptions {
        tolerance: 0.9,
        max_dofs,
        boundary_layer: Some(layer.clone()),
        ..AdaptiveOptions::default()
    };
    let plain = problem
        .solve_adaptive(
            AdaptiveOptions {
                tolerance: 0.9,
                ..AdaptiveOptions::default()
            },
            |_| {},
        )
        .unwrap();
    let solved = problem.solve_adaptive(options(100_000), |_| {}).unwrap();
    assert!(solved.report.adaptive_levels.len() > plain.report.adaptive_levels.len());
    let longest = |mesh: &TriangleMesh| {
        let mut longest = [0.0f64; 5];
        for &(e, marker) in mesh.boundary_edges() {
            let [a, b] = mesh.edges()[e].map(|v| mesh.vertices()[v]);
            let m = marker as usize;
            longest[m] = longest[m].max((b[0] - a[0]).hypot(b[1] - a[1]));
        }
        longest
    };
    let (before, after) = (longest(plain.mesh()), longest(solved.mesh()));
    println!("longest boundary edge per marker: {before:?} without the layer, {after:?} with it");
    assert!(before[1] > 0.05 && after[1] <= 0.05, "{after:?}");
    // the opposite edge (marker 3) no finer than the estimate alone made it
    assert!(after[3] >= before[3], "{after:?}");
    let message = problem
        .solve_adaptive(options(400), |_| {})
        .err()
        .unwrap()
        .to_string();
    assert!(message.contains("longer than its width 0.05"), "{message}");
}

/// A solution held at zero (membrane-flat: u = 0, λ = q) has a norm of rounding size: a
/// tolerance relative to it is refused at the first level, not chased to the DOF limit.
#[test]
fn a_vanishing_solution_is_refused_at_once() {
    use fem_forms::models::families;
    use fem_forms::models::report::Settings;
    let scene = families::scene("membrane-flat").unwrap();
    let settings = Settings {
        mesh_size: Some(4),
        adaptive: Some(AdaptiveOptions {
            tolerance: 1e-2,
            ..AdaptiveOptions::default()
        }),
        ..Settings::default()
    };
    let message = families::solve(&scene, &settings).unwrap_err().to_string();
    assert!(
        message.contains("zero up to rounding") && message.contains("after 1 levels"),
        "{message}"
    );
}

/// A scene solved without its constraint (kirchhoff-square: no obstacle) has no contact
/// part in its estimate: the runtime's multiplier is 0 there, but the data ψ of the
/// model (unused) made a complementarity "defect" of 60 % of the estimate.
#[test]
fn an_unconstrained_solve_has_no_contact_part() {
    use fem_forms::models::families;
    use fem_forms::models::report::Settings;
    let scene = families::scene("kirchhoff-square").unwrap();
    for pair in ["argyris-p0", "morley-p0"] {
        let settings = Settings {
            pair: Some(pair.into()),
            mesh_size: Some(8),
            ..Settings::default()
        };
        let report = families::solve(&scene, &settings).unwrap().report.solve;
        assert_eq!(report.estimate_contact, Some(0.0), "{pair}");
        assert!(report.estimate.unwrap() > 0.0);
    }
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
                    ..AdaptiveOptions::default()
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

    /// A plate clamped on its bottom edge, simply supported on its right edge and free
    /// on the top and left ones: the estimate is its cell and interior edge indicators
    /// plus, one-sided, the normal moment `M_nn` on the simply supported edges (where w is
    /// held but ∂_n w free) and both `M_nn` and the Kirchhoff shear `V_n` on the free
    /// ones; the clamped edges take none (Morley's clamp holds the edges' mean normal
    /// derivatives only, and that is what counts). The shear term on the simply supported
    /// edges, which the support's reaction makes nonzero, is left out.
    #[test]
    fn natural_boundary_terms_follow_the_supports() {
        natural_terms_of::<kirchhoff_argyris_p0::Model>(&[("w", 0), ("w", 1)]);
        // Morley's quadratics have no Kirchhoff shear
        natural_terms_of::<kirchhoff_morley_p0::Model>(&[("w", 1)]);
    }

    /// [`natural_boundary_terms_follow_the_supports`] for the plate model `M`, whose
    /// natural fluxes are `fluxes`.
    fn natural_terms_of<M: Model>(fluxes: &[(&str, u8)]) {
        let mesh = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 4, 4, Diagonal::Right).unwrap();
        let one = |_: &[f64]| 1.0;
        let solved = Problem::<M, TriangleMesh>::new(vec![mesh.clone()])
            .param("D", 1.0)
            .param("ν", 0.3)
            .data("f", &one)
            .data("ψ", &below)
            .data("g", &zero)
            .support(DirichletPart::Markers(vec![1]), "w", Condition::Clamped)
            .support(DirichletPart::Markers(vec![2]), "w", Condition::Zero)
            .solve()
            .unwrap();
        let names: Vec<(&str, u8)> = M::NATURAL_FLUXES
            .iter()
            .map(|&(f, j)| (M::FIELDS[f].name, j))
            .collect();
        assert_eq!(names, fluxes);
        let d = &solved.solution.discretization;
        let field = |f: usize| fem_forms::element::triangle::TriangleField {
            mesh: &mesh,
            map: d.dofs.map(f).unwrap(),
            coefficients: solved.solution.field(f),
        };
        let fields = [field(0), field(1)];
        let local = |c: usize| -> Vec<Vec<f64>> {
            fields.iter().map(|f| f.reference_coefficients(c)).collect()
        };
        let data: Vec<&fem_forms::DataFn> = M::DATA
            .iter()
            .map(|&n| -> &fem_forms::DataFn {
                match n {
                    "f" => &one,
                    "ψ" => &below,
                    _ => &zero,
                }
            })
            .collect();
        let p = &solved.params;
        let mut interior = 0.0;
        for c in 0..mesh.cell_count() {
            let l = local(c);
            let l: Vec<&[f64]> = l.iter().map(Vec::as_slice).collect();
            interior += M::cell_indicator(&mesh.cell_coordinates(c), &l, p, &data).unwrap();
        }
        let position =
            |c: usize, e: usize| mesh.cell_edges(c).iter().position(|&x| x == e).unwrap();
        let (mut natural, mut supported_shear) = (0.0, 0.0);
        for (e, _) in mesh.edges().iter().enumerate() {
            let (c0, other) = mesh.edge_cells(e);
            let (l0, x0) = (local(c0), mesh.cell_coordinates(c0));
            let l0: Vec<&[f64]> = l0.iter().map(Vec::as_slice).collect();
            if let Some(c1) = other {
                let l1 = local(c1);
                let l1: Vec<&[f64]> = l1.iter().map(Vec::as_slice).collect();
                interior += M::edge_indicator(
                    &x0,
                    position(c0, e),
                    &l0,
                    &mesh.cell_coordinates(c1),
                    position(c1, e),
                    &l1,
                    p,
                    &data,
                )
                .unwrap();
                continue;
            }
            let marker = mesh.boundary_edges().iter().find(|b| b.0 == e).unwrap().1;
            for (k, &(_, j)) in M::NATURAL_FLUXES.iter().enumerate() {
                let term = M::boundary_indicator(k, &x0, position(c0, e), &l0, p, &data).unwrap();
                match (marker, j) {
                    (1, _) => {}
                    (2, 0) => supported_shear += term,
                    _ => natural += term,
                }
            }
        }
        let total = solved.estimate.unwrap().residual.powi(2);
        let has_shear = fluxes.contains(&("w", 0));
        assert!(
            natural > 1e-3 * total && (supported_shear > 1e-3 * total || !has_shear),
            "{}: {natural}, {supported_shear}, {total}",
            M::NAME
        );
        assert!(
            (total - interior - natural).abs() <= 1e-10 * total,
            "{total} against {} + {natural}",
            interior
        );
    }

    /// The estimate has the units of the energy norm: a plate 100 times stiffer under
    /// 100 times the load has the same deflection, an estimate and an error √100 times
    /// larger, and the same relative estimate and efficiency index.
    #[test]
    fn the_estimate_scales_with_the_energy_norm() {
        let solve = |scale: f64| {
            let mesh = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 8, 8, Diagonal::Right).unwrap();
            let scaled = move |x: &[f64]| scale * load(x);
            Problem::<kirchhoff_morley_p0::Model, TriangleMesh>::new(vec![mesh])
                .param("D", scale * D)
                .param("ν", 0.3)
                .data("f", &scaled)
                .data("ψ", &below)
                .data("g", &zero)
                .support(DirichletPart::All, "w", Condition::Clamped)
                .exact(Exact {
                    value: &w,
                    gradient: Some(&gradient),
                    hessian: Some(&hessian),
                    multiplier: None,
                })
                .solve()
                .unwrap()
                .report
        };
        let (one, stiff) = (solve(1.0), solve(100.0));
        let close = |a: Option<f64>, b: Option<f64>| {
            let (a, b) = (a.unwrap(), b.unwrap());
            (a - b).abs() <= 1e-6 * a.abs()
        };
        assert!(
            close(one.estimate_relative, stiff.estimate_relative)
                && close(one.efficiency_index, stiff.efficiency_index)
                && close(one.estimate.map(|e| 10.0 * e), stiff.estimate),
            "D: {one:?}\n100 D: {stiff:?}"
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

/// The Euler–Bernoulli beam on a flat obstacle (bernoulli-flat, exact solution): the
/// estimate (cell residual, jumps of the shear force `w'''` and the moment `w''` at the
/// nodes, contact terms) over an adaptive run from four cells.
mod bernoulli {
    use super::*;
    use fem_forms::models::families;
    use fem_forms::models::report::{Outcome, Settings};

    fn run(load: f64, tolerance: f64) -> fem_forms::Result<Outcome> {
        let scene = families::scenes()
            .into_iter()
            .find(|s| s.name == "bernoulli-flat")
            .unwrap();
        let settings = Settings {
            mesh_size: Some(4),
            load: Some(load),
            adaptive: Some(AdaptiveOptions {
                tolerance,
                ..AdaptiveOptions::default()
            }),
            ..Settings::default()
        };
        families::solve(&scene, &settings)
    }

    /// Hermite cubics by hand on `[a, b]` in the physical variable, DOFs `[w(a), w'(a),
    /// w(b), w'(b)]`: the `k`-th derivative at `x`.
    fn hermite(a: f64, b: f64, dofs: &[f64], x: f64, k: usize) -> f64 {
        let h = b - a;
        let t = (x - a) / h;
        let basis: [[f64; 4]; 4] = [
            [
                1.0 - 3.0 * t * t + 2.0 * t.powi(3),
                3.0 * t * t - 2.0 * t.powi(3),
                0.0,
                0.0,
            ],
            [
                h * (t - 2.0 * t * t + t.powi(3)),
                h * (-t * t + t.powi(3)),
                0.0,
                0.0,
            ],
            [
                (-6.0 + 12.0 * t) / (h * h),
                (6.0 - 12.0 * t) / (h * h),
                0.0,
                0.0,
            ],
            [(-4.0 + 6.0 * t) / h, (-2.0 + 6.0 * t) / h, 0.0, 0.0],
        ];
        let third = [
            12.0 / h.powi(3),
            6.0 / (h * h),
            -12.0 / h.powi(3),
            6.0 / (h * h),
        ];
        match k {
            0 => {
                dofs[0] * basis[0][0]
                    + dofs[1] * basis[1][0]
                    + dofs[2] * basis[0][1]
                    + dofs[3] * basis[1][1]
            }
            2 => {
                dofs[0] * basis[2][0]
                    + dofs[1] * basis[3][0]
                    + dofs[2] * basis[2][1]
                    + dofs[3] * basis[3][1]
            }
            3 => (0..4).map(|i| dofs[i] * third[i]).sum(),
            _ => unreachable!("the indicators take w'' and w'''"),
        }
    }

    fn load(x: &[f64]) -> f64 {
        1.0 + 3.0 * x[0] - x[0] * x[0]
    }

    /// A beam clamped at its left end, free or simply supported at its right end, under
    /// f = 1 without contact: the estimate is its cell and interior node indicators plus,
    /// at the right end, where the natural conditions say the shear `w'''` (free) and the
    /// moment `w''` (free and simply supported) vanish, `h³/27 w_h'''(1)² + h/3 w_h''(1)²`
    /// by hand, the simply supported end without the shear (its reaction); the clamped
    /// end takes none.
    #[test]
    fn free_and_supported_ends_take_the_natural_terms() {
        use fem_forms::models::bernoulli::Model as M;
        use fem_forms::problem::Condition;
        use fem_forms::IntervalMesh;
        let one = |_: &[f64]| 1.0;
        let far_below = |_: &[f64]| -10.0;
        let names: Vec<(&str, u8)> = M::NATURAL_FLUXES
            .iter()
            .map(|&(f, j)| (M::FIELDS[f].name, j))
            .collect();
        assert_eq!(names, [("w", 0), ("w", 1)]);
        for free in [true, false] {
            let mesh = IntervalMesh::uniform(0.0, 1.0, 6).unwrap();
            let problem = Problem::<M, IntervalMesh>::new(vec![mesh.clone()])
                .data("f", &one)
                .data("ψ", &far_below)
                .support(DirichletPart::Markers(vec![1]), "w", Condition::Clamped);
            let problem = if free {
                problem
            } else {
                problem.support(DirichletPart::Markers(vec![2]), "w", Condition::Zero)
            };
            let solved = problem.solve().unwrap();
            let views = [solved.solution.view(0), solved.solution.view(1)];
            let n = mesh.cell_count();
            let [a, b] = mesh.cell(n - 1);
            let h = b - a;
            let dofs = views[0].local(n - 1);
            let moment = hermite(a, b, &dofs, 1.0, 2);
            let shear = hermite(a, b, &dofs, 1.0, 3);
            let natural = h / 3.0 * moment * moment
                + if free {
                    h.powi(3) / 27.0 * shear * shear
                } else {
                    0.0
                };
            let data: [&fem_forms::DataFn; 2] = [&one, &far_below];
            let p = &solved.params;
            let local = |c: usize| -> Vec<Vec<f64>> {
                let hc = mesh.h(c);
                let w = views[0].local(c);
                vec![vec![w[0], w[1] * hc, w[2], w[3] * hc], views[1].local(c)]
            };
            let mut interior = 0.0;
            for c in 0..n {
                let l = local(c);
                let l: Vec<&[f64]> = l.iter().map(Vec::as_slice).collect();
                interior += M::cell_indicator(&mesh.cell(c), &l, p, &data).unwrap();
                if c > 0 {
                    let k = local(c - 1);
                    let k: Vec<&[f64]> = k.iter().map(Vec::as_slice).collect();
                    interior +=
                        M::edge_indicator(&mesh.cell(c - 1), 1, &k, &mesh.cell(c), 0, &l, p, &data)
                            .unwrap();
                }
            }
            let total = solved.estimate.unwrap().residual.powi(2);
            assert!(natural > 1e-6 * total, "free {free}: {natural} of {total}");
            assert!(
                (total - interior - natural).abs() <= 1e-9 * total,
                "free {free}: {total} against {interior} + {natural}"
            );
        }
    }

    /// The generated interval kernels of `bernoulli` against the indicators by hand
    /// (`h⁴/81 ‖f + sλ − w''''‖²` by 3-point Gauss–Legendre, and at the node
    /// `h³/27 [[w''']]² + h/3 [[w'']]²`, h the mean length), on pseudo-random cells and
    /// coefficients. The kernels take the slopes times the cell's length.
    #[test]
    fn indicators_match_the_hand_coded_ones() {
        use fem_forms::models::bernoulli::Model as M;
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut random = move |lo: f64, hi: f64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            lo + (hi - lo) * (state % 1_000_000) as f64 / 1e6
        };
        let data: [&fem_forms::DataFn; 2] = [&load, &zero];
        for _ in 0..50 {
            let a = random(-1.0, 1.0);
            let b = a + random(0.01, 1.0);
            let c = b + random(0.01, 1.0);
            let u: Vec<f64> = (0..4).map(|_| random(-2.0, 2.0)).collect();
            let w: Vec<f64> = (0..4).map(|_| random(-2.0, 2.0)).collect();
            let (lambda, mu) = ([random(0.0, 3.0)], [random(0.0, 3.0)]);
            let s = if random(0.0, 1.0) < 0.5 { -1.0 } else { 1.0 };
            let params = [0.3, s];
            let reference = |d: &[f64], h: f64| vec![d[0], d[1] * h, d[2], d[3] * h];
            let generated =
                M::cell_indicator(&[a, b], &[&reference(&u, b - a), &lambda], &params, &data)
                    .unwrap();
            let h = b - a;
            let r = |x: f64| load(&[x]) + s * lambda[0];
            let g = 0.6f64.sqrt();
            let hand = h.powi(4) / 81.0
                * h
                * (5.0 * r(a + h * 0.5 * (1.0 - g)).powi(2)
                    + 8.0 * r(a + h * 0.5).powi(2)
                    + 5.0 * r(a + h * 0.5 * (1.0 + g)).powi(2))
                / 18.0;
            assert!(
                (generated - hand).abs() <= 1e-12 * hand,
                "η_T² {generated:e} against {hand:e}"
            );
            let generated = M::edge_indicator(
                &[a, b],
                1,
                &[&reference(&u, b - a), &lambda],
                &[b, c],
                0,
                &[&reference(&w, c - b), &mu],
                &params,
                &data,
            )
            .unwrap();
            let mean = 0.5 * (c - a);
            let jump = |k: usize| hermite(a, b, &u, b, k) - hermite(b, c, &w, b, k);
            let hand = mean.powi(3) / 27.0 * jump(3).powi(2) + mean / 3.0 * jump(2).powi(2);
            assert!(
                (generated - hand).abs() <= 1e-10 * hand,
                "η_E² {generated:e} against {hand:e}"
            );
        }
        // an end other than 0 and 1 is an error, not a panic
        assert!(M::edge_indicator(
            &[0.0, 1.0],
            2,
            &[&[0.0; 4], &[0.0]],
            &[1.0, 2.0],
            0,
            &[&[0.0; 4], &[0.0]],
            &[0.3, 1.0],
            &data
        )
        .is_err());
    }

    /// A contact interval (q = 100 > 57.6): past the coarsest levels, which do not see the
    /// contact set yet, the efficiency index stays within a band, the error falls by two
    /// orders, and ∫λ_h matches the exact contact force.
    #[test]
    fn efficiency_stays_bounded_over_an_adaptive_run() {
        let outcome = run(100.0, 1e-3).unwrap();
        let report = &outcome.report.solve;
        let levels = &report.adaptive_levels;
        let resolved: Vec<_> = levels.iter().filter(|l| l.cells >= 10).copied().collect();
        let (indices, low, high) = efficiency_indices(&resolved);
        assert!(
            resolved.len() >= 8 && low > 1.0 && high < 8.0,
            "efficiency indices {indices:?}"
        );
        let (first, last) = (&levels[0], levels.last().unwrap());
        assert!(
            last.error_energy.unwrap() < 1e-2 * first.error_energy.unwrap(),
            "{levels:?}"
        );
        assert!(last.estimate <= 1e-3 * last.energy_norm);
        let exact = outcome.report.exact_contact_force.unwrap();
        assert!(
            (report.total_contact_force - exact).abs() < 1e-4 * exact,
            "∫λ_h = {} against {exact}",
            report.total_contact_force
        );
    }

    /// A point contact (q = 20): the weak constraint lets w_h dip below ψ by O(κh²) in
    /// the contact cells, so the violation part of the estimate falls only slowly
    /// there while the true error is far smaller; the loop refines the contact point
    /// until its cells' stabilization αh⁴ reaches the rounding of the gap, and then
    /// stops with an error that says which level failed and what the one before reached.
    #[test]
    fn a_point_contact_stops_at_the_rounding_limit_with_a_clear_error() {
        let message = run(20.0, 1e-4).unwrap_err().to_string();
        assert!(
            message.contains("level") && message.contains("reached an estimate of"),
            "{message}"
        );
    }
}

/// The clamped Timoshenko beam under f = 1 without contact (exact: `θ = x(2x−1)(x−1)/12`,
/// `w = x²(1−x)²/24 + t² x(1−x)/2`): the estimator (rotation residual, equilibrium
/// residual weighted by h²(t² + h²), node jumps of θ' and of the shear force) for t from
/// 1e-1 to 1e-4.
mod timoshenko {
    use fem_forms::models::timoshenko_p1_full::Model as P1Full;
    use fem_forms::models::timoshenko_p1_reduced::Model as P1Reduced;
    use fem_forms::models::timoshenko_p2::Model as M;
    use fem_forms::obstacle::{solve_obstacle, ObstacleOptions};
    use fem_forms::{Coefficients, DataFn, IntervalMesh, Model};

    fn load(_: &[f64]) -> f64 {
        1.0
    }

    fn far_below(_: &[f64]) -> f64 {
        -10.0
    }

    /// The efficiency indices against `(|θ − θ_h|²₁ + |w − w_h|²₁)^{1/2}` and against the
    /// energy norm `(|θ − θ_h|²₁ + t⁻²‖γ − γ_h‖²)^{1/2}`, γ = w' − θ.
    fn index(t: f64, n: usize) -> [f64; 2] {
        index_of::<M>(t, n)
    }

    /// [`index`] for the model `M`.
    fn index_of<M: Model>(t: f64, n: usize) -> [f64; 2] {
        let theta = |x: f64, k: usize| match k {
            0 => (2.0 * x.powi(3) - 3.0 * x * x + x) / 12.0,
            _ => (6.0 * x * x - 6.0 * x + 1.0) / 12.0,
        };
        let slope = |x: f64| {
            (2.0 * x - 6.0 * x * x + 4.0 * x.powi(3)) / 24.0 + t * t * (1.0 - 2.0 * x) / 2.0
        };
        let values = [t, 1.0, 1.0];
        let c = Coefficients::new::<M>(
            &[("t", t), ("α", 1.0), ("s", 1.0)],
            &[("f", &load), ("ψ", &far_below)],
        )
        .unwrap();
        let mesh = IntervalMesh::uniform(0.0, 1.0, n).unwrap();
        let solution =
            solve_obstacle::<M>(&mesh, &c, &["θ", "w"], ObstacleOptions::default()).unwrap();
        let data: [&DataFn; 2] = [&load, &far_below];
        let estimate =
            fem_forms::adaptivity::interval_estimate::<M>(&solution, &values, &data, Some(1.0))
                .unwrap();
        let (th, w) = (
            solution.view(M::field("θ").unwrap()),
            solution.view(M::field("w").unwrap()),
        );
        // 5-point Gauss–Legendre on each cell, points strictly inside
        let rule = fem_forms::gauss_legendre(5);
        let (mut error2, mut shear2) = (0.0, 0.0);
        for k in 0..n {
            let (a, h) = (k as f64 / n as f64, 1.0 / n as f64);
            for (&xi, &weight) in rule.points.iter().zip(&rule.weights) {
                let x = a + h * xi;
                let bending = theta(x, 1) - th.at(x, 1).unwrap();
                let deflection = slope(x) - w.at(x, 1).unwrap();
                let shear = (slope(x) - theta(x, 0)) - (w.at(x, 1).unwrap() - th.at(x, 0).unwrap());
                error2 += weight * h * (bending * bending + deflection * deflection);
                shear2 += weight * h * (bending * bending + shear * shear / (t * t));
            }
        }
        [
            estimate.residual / error2.sqrt(),
            estimate.residual / shear2.sqrt(),
        ]
    }

    /// Measured against the H¹ errors: 24–26 at t = 0.1, 60–63 for t = 1e-2 … 1e-4 (no
    /// drift as t → 0); against the energy norm 8–9 at t = 0.1 rising to 60 as t falls
    /// below h, where the energy norm's shear part `t⁻¹‖γ − γ_h‖` is no longer the
    /// robust norm's `‖q − q_h‖_{-1}`. The equilibrium residual `h²(t² + h²)‖q_h' + f‖²`
    /// dominates the estimate: its constant is not calibrated.
    #[test]
    fn the_estimator_is_robust_in_the_thickness() {
        let mut indices = Vec::new();
        for n in [16, 32] {
            for t in [1e-1, 1e-2, 1e-3, 1e-4] {
                indices.push((t, n, index(t, n)));
            }
        }
        for n in [16, 32] {
            let (a, b) = indices
                .iter()
                .filter(|i| i.1 == n && i.0 <= 1e-2)
                .fold((f64::INFINITY, 0.0f64), |(a, b), i| {
                    (a.min(i.2[0]), b.max(i.2[0]))
                });
            assert!(
                a > 1.0 && b < 100.0 && b / a < 1.1,
                "N = {n}: efficiency indices (t, N, [H¹, energy]) {indices:?}"
            );
        }
    }

    /// The one-point shear pair's cell indicator against the hand-coded one on a cell
    /// `(a, b)`: `h³ (t⁻²(w' − θ(m)))² + h³(t² + h²)(f + sλ)²`, `m` the midpoint (the
    /// norm's `[degree=1]`), for f = 1.
    #[test]
    fn the_reduced_pair_cell_indicator_is_the_hand_coded_one() {
        let (a, b, t, s) = (0.3, 0.55, 0.05, -1.0);
        let (theta, w, lambda) = ([0.7, -0.2], [0.01, 0.04], [2.5]);
        let data: [&DataFn; 2] = [&load, &far_below];
        let generated =
            P1Reduced::cell_indicator(&[a, b], &[&theta, &w, &lambda], &[t, 1.0, s], &data)
                .unwrap();
        let h: f64 = b - a;
        let shear = ((w[1] - w[0]) / h - 0.5 * (theta[0] + theta[1])) / (t * t);
        let hand =
            h.powi(3) * shear * shear + h.powi(3) * (t * t + h * h) * (1.0 + s * lambda[0]).powi(2);
        assert!(
            (generated - hand).abs() <= 1e-12 * hand,
            "{generated} against {hand}"
        );
    }

    /// The contact part of the P1 pairs' estimate falls under uniform refinement
    /// (`timoshenko-a` at t = 1, q = 100, in contact): the violation is weighted by the
    /// deflection's energy order (`h⁻²` for `|w|₁`), not the stabilization's (`h⁻⁴`),
    /// with which the P1 deflection's O(h²) dip between the nodes kept it at 0.021 from
    /// 256 to 4096 cells.
    #[test]
    fn the_p1_pairs_contact_part_falls_under_refinement() {
        use fem_forms::models::families;
        use fem_forms::models::report::Settings;
        let scene = families::scenes()
            .into_iter()
            .find(|s| s.name == "timoshenko-a")
            .unwrap();
        for pair in ["p1-p1-p0-reduced", "p1-p1-p0-full"] {
            let contact = |n: usize| {
                let settings = Settings {
                    pair: Some(pair.into()),
                    mesh_size: Some(n),
                    load: Some(100.0),
                    parameters: vec![("t".into(), 1.0)],
                    ..Settings::default()
                };
                let report = families::solve(&scene, &settings).unwrap().report.solve;
                assert!(report.total_contact_force > 0.0, "{pair}: no contact");
                report.estimate_contact.unwrap()
            };
            let (coarse, fine) = (contact(128), contact(512));
            assert!(fine < 0.5 * coarse, "{pair}: S {coarse} → {fine}");
        }
    }

    /// The one-point shear pair's estimator (the shear at the midpoints, `[degree=1]`):
    /// within a band of the H¹ errors for t from 1e-1 to 1e-4 (measured 3.46–3.71 on
    /// N = 16 and 32: robust), and the locking pair's (exact shear integration) follows
    /// its locked error (measured 8.2 at t = 0.1, 15.9 below: its error grows as t falls
    /// and the estimate with it).
    #[test]
    fn the_p1_pairs_estimators_follow_their_errors() {
        let mut indices = Vec::new();
        for n in [16, 32] {
            for t in [1e-1, 1e-2, 1e-3, 1e-4] {
                indices.push((t, n, index_of::<P1Reduced>(t, n)[0]));
            }
        }
        let (a, b) = indices.iter().fold((f64::INFINITY, 0.0f64), |(a, b), i| {
            (a.min(i.2), b.max(i.2))
        });
        assert!(
            a > 1.0 && b < 10.0 && b / a < 1.2,
            "reduced: efficiency indices (t, N, H¹) {indices:?}"
        );
        let locking: Vec<(f64, f64)> = [1e-1, 1e-2, 1e-3, 1e-4]
            .iter()
            .map(|&t| (t, index_of::<P1Full>(t, 16)[0]))
            .collect();
        assert!(
            locking.iter().all(|&(_, i)| i > 1.0 && i < 40.0),
            "full: efficiency indices (t, H¹) {locking:?}"
        );
    }
}

/// Signorini contact: the boundary parts' indicators (`η_Γ_C²`, `η_Γ_N²`) against
/// hand-coded ones, the patch test's vanishing estimate, and Hertz from a coarse mesh.
mod signorini {
    use super::*;
    use fem_forms::models::families;
    use fem_forms::models::report::Settings;
    use fem_forms::models::signorini::signorini_p1_p1::Model as M;

    const MU: f64 = 3.7;
    const LAMBDA: f64 = 5.3;
    const NC: [f64; 2] = [0.6, -0.8];

    fn pressure(x: &[f64]) -> f64 {
        1.0 + x[0] + 2.0 * x[1]
    }

    fn gap(_: &[f64]) -> f64 {
        0.0
    }

    /// `η_Γ²` of local edge `edge` of the triangle `x` by hand, for the P1 displacement
    /// with vertex values `ux`, `uy` and the P1 multiplier `lambda` (vertex values):
    /// `h_E/(2μ) ∫_E |σn + t|² ds`, `t = λ n_c` on Γ_C (`contact`), `t = q n` on Γ_N,
    /// with a 4-point Gauss rule and the normal pointing away from the third vertex.
    fn by_hand(
        x: &[f64; 6],
        edge: usize,
        ux: &[f64],
        uy: &[f64],
        lambda: &[f64],
        contact: bool,
    ) -> f64 {
        let p = |i: usize| [x[2 * i], x[2 * i + 1]];
        let det = (x[2] - x[0]) * (x[5] - x[1]) - (x[4] - x[0]) * (x[3] - x[1]);
        // gradients of the barycentric coordinates
        let grad = |i: usize| {
            let (a, b) = (p((i + 1) % 3), p((i + 2) % 3));
            [(a[1] - b[1]) / det, (b[0] - a[0]) / det]
        };
        let mut g = [[0.0; 2]; 2];
        for i in 0..3 {
            let d = grad(i);
            g[0] = [g[0][0] + ux[i] * d[0], g[0][1] + ux[i] * d[1]];
            g[1] = [g[1][0] + uy[i] * d[0], g[1][1] + uy[i] * d[1]];
        }
        let eps = [
            [g[0][0], 0.5 * (g[0][1] + g[1][0])],
            [0.5 * (g[0][1] + g[1][0]), g[1][1]],
        ];
        let tr = eps[0][0] + eps[1][1];
        let sigma =
            |i: usize, j: usize| 2.0 * MU * eps[i][j] + if i == j { LAMBDA * tr } else { 0.0 };
        let (a, b, c) = (p(edge), p((edge + 1) % 3), p((edge + 2) % 3));
        let len = (b[0] - a[0]).hypot(b[1] - a[1]);
        let mut n = [(b[1] - a[1]) / len, -(b[0] - a[0]) / len];
        let mid = [0.5 * (a[0] + b[0]) - c[0], 0.5 * (a[1] + b[1]) - c[1]];
        if n[0] * mid[0] + n[1] * mid[1] < 0.0 {
            n = [-n[0], -n[1]];
        }
        let sn = [
            sigma(0, 0) * n[0] + sigma(0, 1) * n[1],
            sigma(1, 0) * n[0] + sigma(1, 1) * n[1],
        ];
        let (ga, gb) = (0.339_981_043_584_856_3, 0.861_136_311_594_052_6);
        let (wa, wb) = (0.652_145_154_862_546_1, 0.347_854_845_137_453_9);
        let mut integral = 0.0;
        for (s, w) in [(-gb, wb), (-ga, wa), (ga, wa), (gb, wb)] {
            let (s, w) = (0.5 * (1.0 + s), 0.5 * w);
            let point = [a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])];
            let t = if contact {
                let l = (1.0 - s) * lambda[edge] + s * lambda[(edge + 1) % 3];
                [l * NC[0], l * NC[1]]
            } else {
                let q = pressure(&point);
                [q * n[0], q * n[1]]
            };
            integral += w * ((sn[0] + t[0]).powi(2) + (sn[1] + t[1]).powi(2));
        }
        len / (2.0 * MU) * integral * len
    }

    /// The generated `η_Γ_C²` and `η_Γ_N²` of the P1–P1 model against [`by_hand`] on
    /// every local edge of triangles of both orientations, with a multiplier that
    /// varies along the edge and a pressure that varies in space.
    #[test]
    fn boundary_indicators_match_the_hand_coded_ones() {
        let params = [MU, LAMBDA, 0.2, NC[0], NC[1]];
        let data: [&fem_forms::DataFn; 2] = [&pressure, &gap];
        let (contact, loaded) = (M::facet_part("Γ_C").unwrap(), M::facet_part("Γ_N").unwrap());
        let cells = [
            [0.1, 0.2, 1.3, -0.1, 0.4, 0.9],
            [0.1, 0.2, 0.4, 0.9, 1.3, -0.1],
            [-1.0, 0.5, 0.2, -0.7, 0.9, 1.4],
        ];
        let (ux, uy, lambda) = ([0.3, -0.2, 0.5], [0.1, 0.7, -0.4], [1.5, 0.4, 2.2]);
        for x in &cells {
            for edge in 0..3 {
                let coefficients: [&[f64]; 3] = [&ux, &uy, &lambda];
                for (part, on_contact) in [(contact, true), (loaded, false)] {
                    let generated =
                        M::boundary_indicator(part, x, edge, &coefficients, &params, &data)
                            .unwrap();
                    let expected = by_hand(x, edge, &ux, &uy, &lambda, on_contact);
                    assert!(
                        (generated - expected).abs() <= 1e-12 * expected.abs().max(1.0),
                        "cell {x:?}, edge {edge}, contact {on_contact}: {generated} against {expected}"
                    );
                }
            }
        }
        // the natural boundary terms follow the parts: `σ(u)n` by component, whose sum
        // is the traction-free residual `h_E/(2μ) ‖σ(u)n‖²` (the contact line with λ = 0)
        assert_eq!(M::NATURAL_FLUXES, &[(0, 0), (1, 0)]);
        let natural = M::FACET_PARTS.len();
        for x in &cells {
            for edge in 0..3 {
                let coefficients: [&[f64]; 3] = [&ux, &uy, &lambda];
                let generated: f64 = (natural..natural + 2)
                    .map(|k| {
                        M::boundary_indicator(k, x, edge, &coefficients, &params, &data).unwrap()
                    })
                    .sum();
                let expected = by_hand(x, edge, &ux, &uy, &[0.0; 3], true);
                assert!(
                    (generated - expected).abs() <= 1e-12 * expected.abs().max(1.0),
                    "cell {x:?}, edge {edge}, traction-free: {generated} against {expected}"
                );
            }
        }
        let beyond = natural + M::NATURAL_FLUXES.len();
        assert!(
            M::boundary_indicator(beyond, &cells[0], 0, &[&ux, &uy, &lambda], &params, &data)
                .is_err()
        );
    }

    /// The patch test's solution (`λ_h = q`, a uniform compression) is exact for every
    /// pair: every indicator vanishes to rounding. A sign error in `σ(u)·n + λ n_c` or in
    /// `σ(u)·n + q n` would leave `2q` on every edge of Γ_C or Γ_N.
    #[test]
    fn the_patch_test_has_a_vanishing_estimate() {
        let scene = families::scene("signorini-patch").unwrap();
        for pair in ["p1-p0", "p2-p0", "p1-p1", "p2-p1"] {
            let settings = Settings {
                pair: Some(pair.into()),
                mesh_size: Some(4),
                ..Settings::default()
            };
            let report = families::solve(&scene, &settings).unwrap().report.solve;
            let relative = report.estimate_relative.unwrap();
            assert!(relative < 1e-7, "{pair}: estimate {relative:e} of ‖u_h‖_a");
        }
    }

    /// The patch test presses the whole bottom with `λ = q`: the cells of the contact
    /// edges, and those alone, are in contact with the mean multiplier `q` in the fields
    /// the charts and `--vtk` take (a boundary multiplier has no cell values of its own).
    #[test]
    fn the_contact_edges_cells_carry_the_contact_set() {
        use fem_forms::models::geometry::Fields;
        let scene = families::scene("signorini-patch").unwrap();
        for pair in ["p1-p0", "p2-p1"] {
            let settings = Settings {
                pair: Some(pair.into()),
                mesh_size: Some(4),
                load: Some(2.5),
                ..Settings::default()
            };
            let outcome = families::solve(&scene, &settings).unwrap();
            let Fields::Triangles { mesh, cell, .. } = &outcome.fields else {
                panic!("triangles")
            };
            let field = |name: &str| &cell.iter().find(|(n, _)| *n == name).unwrap().1;
            let (lambda, contact) = (field("lambda"), field("contact"));
            for c in 0..mesh.cell_count() {
                let x = mesh.cell_coordinates(c);
                let on_bottom = (0..3).filter(|&i| x[2 * i + 1].abs() < 1e-12).count() == 2;
                if on_bottom {
                    assert!((contact[c] - 1.0).abs() < 1e-12, "{pair}: cell {c}");
                    assert!((lambda[c] - 2.5).abs() < 1e-9, "{pair}: λ {}", lambda[c]);
                } else {
                    assert_eq!((contact[c], lambda[c]), (0.0, 0.0), "{pair}: cell {c}");
                }
            }
        }
    }

    /// Hertz from the coarsest graded mesh (b/h = 1): the adaptive loop reaches a
    /// smaller pressure error than the hand-graded b/h = 64 mesh with fewer unknowns,
    /// and its estimate falls at P1's optimal rate, about N^{-1/2}.
    #[test]
    fn hertz_from_a_coarse_mesh_beats_the_hand_graded_one() {
        let scene = families::scene("hertz").unwrap();
        let solve = |mesh_size: usize, tolerance: Option<f64>| {
            let settings = Settings {
                mesh_size: Some(mesh_size),
                adaptive: tolerance.map(|tolerance| AdaptiveOptions {
                    tolerance,
                    ..AdaptiveOptions::default()
                }),
                ..Settings::default()
            };
            families::solve(&scene, &settings).unwrap().report
        };
        let graded = solve(64, None);
        let adaptive = solve(1, Some(0.07));
        let error = |r: &fem_forms::models::report::Report| r.number("pressure_l2_error").unwrap();
        assert!(
            adaptive.solve.dofs < graded.solve.dofs && error(&adaptive) < error(&graded),
            "adaptive: {} unknowns, pressure error {:.4}; graded b/h = 64: {} unknowns, {:.4}",
            adaptive.solve.dofs,
            error(&adaptive),
            graded.solve.dofs,
            error(&graded)
        );
        let levels = &adaptive.solve.adaptive_levels;
        let points: Vec<(f64, f64)> = levels.iter().map(|l| (l.dofs as f64, l.estimate)).collect();
        let half = &points[points.len() / 2..];
        let (first, last) = (half[0], half[half.len() - 1]);
        let rate = -(last.1 / first.1).ln() / (last.0 / first.0).ln();
        assert!((0.4..0.7).contains(&rate), "estimate ~ N^-{rate:.2}");
    }
}

/// The average `{X} = ½(X⁺ + X⁻)` on interior edges, against a hand computation: for a
/// continuous P1 `u` the average of `u` is `u` (`h_E ∫_E u² ds`), of the normal
/// derivative the mean of the two sides', and data enter an average (not a jump).
mod average {
    use fem_forms::Model;

    fem_forms::model! {
        /// A membrane with averages in its estimator.
        pub mod averaged on triangle {
            unknowns: u: P1;
            tests: v;
            data: f;
            forms: "
                a(u;v) = ∫ ∇u·∇v
                ℓ(v)   = ∫ f v
            ";
            estimator: "
                η_E² = h_E ‖{u}‖² + ‖{∇u·n + f}‖²
            ";
        }
    }

    fn f(x: &[f64]) -> f64 {
        1.0 + x[0]
    }

    #[test]
    fn an_average_is_the_mean_of_the_two_sides() {
        use averaged::Model as M;
        // two cells sharing the edge (1,0)–(0,1): local edge 1 of both
        let x = [0.0, 0.0, 1.0, 0.0, 0.0, 1.0];
        let y = [1.0, 1.0, 0.0, 1.0, 1.0, 0.0];
        let (ux, uy) = ([0.3, 1.1, -0.4], [2.0, -0.4, 1.1]);
        let eta2 = M::edge_indicator(&x, 1, &[&ux], &y, 1, &[&uy], &[], &[&f]).unwrap();
        let len = 2f64.sqrt();
        // {u}: u is 1.1 at (1,0) and −0.4 at (0,1)
        let (a, b) = (1.1, -0.4);
        let values = len * len * (a * a + a * b + b * b) / 3.0;
        // {∇u·n}: n = (1,1)/√2 out of x; ∇u = (0.8, −0.7) on x and (2.4, 0.9) on y (from
        // y's vertex (1,1) with 2.0 and its neighbours), the mean of the two
        let gx = [ux[1] - ux[0], ux[2] - ux[0]];
        let gy = [uy[0] - uy[1], uy[0] - uy[2]];
        let flux = 0.5 * ((gx[0] + gx[1]) + (gy[0] + gy[1])) / len;
        // ∫_E (flux + f)² with f = 1 + x linear along the edge: 4-point Gauss
        let (ga, gb) = (0.339_981_043_584_856_3, 0.861_136_311_594_052_6);
        let (wa, wb) = (0.652_145_154_862_546_1, 0.347_854_845_137_453_9);
        let mut fluxes = 0.0;
        for (s, w) in [(-gb, wb), (-ga, wa), (ga, wa), (gb, wb)] {
            let s = 0.5 * (1.0 + s);
            let point = [1.0 - s, s];
            fluxes += 0.5 * w * len * (flux + f(&point)).powi(2);
        }
        let expected = values + fluxes;
        assert!(
            (eta2 - expected).abs() < 1e-12 * expected,
            "{eta2} against {expected}"
        );
    }
}

/// The clamped disk plate on isoparametric cells (mindlin-disk) refines adaptively: its
/// curved boundary cells keep their quadratic edges (`CurvedTriangleMesh::refine`), the
/// energy norm takes the curved cells' own element matrices, and the loop ends below
/// its tolerance.
#[test]
fn a_curved_mesh_refines_adaptively() {
    use fem_forms::models::families;
    use fem_forms::models::report::Settings;
    let scene = families::scene("mindlin-disk").unwrap();
    let settings = Settings {
        mesh_size: Some(4),
        adaptive: Some(AdaptiveOptions {
            tolerance: 0.6,
            ..AdaptiveOptions::default()
        }),
        ..Settings::default()
    };
    let outcome = families::solve(&scene, &settings).unwrap();
    let levels = &outcome.report.solve.adaptive_levels;
    let (first, last) = (levels[0], levels[levels.len() - 1]);
    assert!(levels.len() > 3, "{} levels", levels.len());
    assert!(last.estimate <= 0.6 * last.energy_norm);
    assert!(last.estimate < 0.5 * first.estimate, "{levels:?}");
    // new boundary vertices sit on the quadratic edges (within 1e-4 of the unit circle
    // at this size), not at the chords' midpoints (1e-2 inside it)
    let fem_forms::models::geometry::Fields::Triangles { mesh, .. } = &outcome.fields else {
        panic!("triangles")
    };
    assert_eq!(mesh.cell_count(), last.cells);
    for &(e, _) in mesh.boundary_edges() {
        for v in mesh.edges()[e] {
            let p = mesh.vertices()[v];
            assert!((p[0].hypot(p[1]) - 1.0).abs() < 1e-4, "{p:?}");
        }
    }
}

fem_runtime::model! {
    /// A stabilized string without an estimator: nothing to solve to a tolerance with.
    pub mod string_without_estimator on interval {
        unknowns: u: P1, λ: P0 >= 0;
        tests: v, μ;
        params: α;
        data: f, ψ;
        forms: "
            a(u;v)       = ∫ u'v'
            b(v;μ)       = ∫ v μ
            S(u,λ;v,μ)   = Σ_T h_T² (−u'' − λ, −v'' − μ)_T
            ℓ(v)         = ∫ f v
            ℓ_S(v,μ)     = Σ_T h_T² (f, −v'' − μ)_T
            G(μ)         = ∫ ψ μ
            B_h(u,λ;v,μ) = a(u;v) − b(v;λ) − b(u;μ) − α S(u,λ;v,μ)
            L_h(v,μ)     = ℓ(v) − G(μ) − α ℓ_S(v,μ)
        ";
    }
}

/// A model without `estimator:` is refused by the adaptive solve, with the reason.
#[test]
fn a_model_without_an_estimator_is_refused_a_tolerance() {
    let mesh = fem_forms::IntervalMesh::uniform(0.0, 1.0, 8).unwrap();
    let Err(e) =
        Problem::<string_without_estimator::Model, fem_forms::IntervalMesh>::new(vec![mesh])
            .data("f", &zero)
            .data("ψ", &zero)
            .solve_adaptive(AdaptiveOptions::default(), |_| {})
    else {
        panic!("solved to a tolerance without an estimator");
    };
    assert!(e.to_string().contains("declares no estimator"), "{e}");
}

/// A membrane held on its left side only (`u = 0` there, f = 1, no contact): the
/// estimate by hand, `Σ_T h_T² |T| f² + Σ_E h_E |E| [[∇u_h·n]]²` over the interior edges
/// plus `h_E |E| (∇u_h·n)²` over the bottom, right and top edges, where the natural
/// condition `∂_n u = 0` holds and the flux of the P1 solution does not vanish; the
/// clamped left edges take no term.
#[test]
fn free_edges_take_the_natural_boundary_term() {
    type M = membrane_p1_p0::Model;
    let one = |_: &[f64]| 1.0;
    let far_below = |_: &[f64]| -10.0;
    let mesh = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 4, 4, Diagonal::Right).unwrap();
    let solved = Problem::<M, TriangleMesh>::new(vec![mesh.clone()])
        .data("f", &one)
        .data("ψ", &far_below)
        .data("g", &zero)
        .boundary_data(DirichletPart::Markers(vec![4]))
        .solve()
        .unwrap();
    assert_eq!(M::NATURAL_FLUXES, &[(0, 0)]);
    let u = solved.solution.field(0);
    let gradient = |c: usize| {
        let [a, b, d] = mesh.cell(c);
        let x = mesh.cell_coordinates(c);
        let det = (x[2] - x[0]) * (x[5] - x[1]) - (x[4] - x[0]) * (x[3] - x[1]);
        let (du1, du2) = (u[b] - u[a], u[d] - u[a]);
        [
            (du1 * (x[5] - x[1]) - du2 * (x[3] - x[1])) / det,
            (du2 * (x[2] - x[0]) - du1 * (x[4] - x[0])) / det,
        ]
    };
    let mut hand = 0.0;
    for c in 0..mesh.cell_count() {
        hand += mesh.cell_diameter(c).powi(2) * mesh.area(c);
    }
    let mut natural = 0.0;
    for (e, &[p, q]) in mesh.edges().iter().enumerate() {
        let (x, y) = (mesh.vertices()[p], mesh.vertices()[q]);
        let length = (y[0] - x[0]).hypot(y[1] - x[1]);
        let n = [(y[1] - x[1]) / length, (x[0] - y[0]) / length];
        let flux = |c: usize| {
            let g = gradient(c);
            g[0] * n[0] + g[1] * n[1]
        };
        match mesh.edge_cells(e) {
            (c0, Some(c1)) => hand += length * length * (flux(c0) - flux(c1)).powi(2),
            (c0, None) if x[0] > 0.0 || y[0] > 0.0 => natural += length * length * flux(c0).powi(2),
            _ => {}
        }
    }
    assert!(natural > 1e-3 * hand, "{natural} against {hand}");
    let residual = solved.estimate.unwrap().residual;
    let expected = (hand + natural).sqrt();
    assert!(
        (residual - expected).abs() <= 1e-10 * expected,
        "{residual} against {expected} (without the natural part {})",
        hand.sqrt()
    );
}

/// Bisection appends a beam's refined cells out of order: the output fields list them by
/// position (a chart joining them in storage order crossed itself), each with its own λ.
#[test]
fn an_adaptive_beams_cells_are_output_in_order() {
    use fem_forms::models::families;
    use fem_forms::models::geometry::Fields;
    use fem_forms::models::report::Settings;
    let scene = families::scene("bernoulli-a").unwrap();
    let settings = Settings {
        pair: Some("hermite-p0".into()),
        load: Some(100.0),
        mesh_size: Some(16),
        adaptive: Some(AdaptiveOptions {
            tolerance: 1e-2,
            ..AdaptiveOptions::default()
        }),
        ..Settings::default()
    };
    let outcome = families::solve(&scene, &settings).unwrap();
    assert!(outcome.report.solve.adaptive_levels.len() >= 2);
    let Fields::Interval { cell_x, lambda, .. } = &outcome.fields else {
        panic!("a beam's fields are on an interval");
    };
    assert!(cell_x.windows(2).all(|w| w[0] < w[1]), "{cell_x:?}");
    // the contact is at ½ (the obstacle's top): λ_h lives there and nowhere near the ends
    let at = |x: f64| {
        let k = cell_x.partition_point(|&c| c < x).min(cell_x.len() - 1);
        lambda[k]
    };
    assert!(at(0.5) > 0.0 && at(0.05) == 0.0 && at(0.95) == 0.0);
}
