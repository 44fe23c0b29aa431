//! The Kirchhoff plate obstacle model on Argyris–P0 (`models/src/kirchhoff.rs`) through
//! the runtime's obstacle path (`solve_obstacle_on_triangles`), with its `boundary:`
//! condition read as the simple support `w = 0` (`DirichletPart::plate_dofs`).
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

use fem_forms::models::kirchhoff::{
    kirchhoff_argyris_p0, kirchhoff_argyris_p1disc, kirchhoff_morley_p0,
};
use fem_forms::obstacle::triangle::solve_obstacle_on_triangles;
use fem_forms::obstacle::ObstacleOptions;
use fem_forms::Model;
use fem_forms::{Coefficients, DataFn, Diagonal, TriangleMesh};

type M = kirchhoff_argyris_p0::Model;

fn zero(_: &[f64]) -> f64 {
    0.0
}

fn square(n: usize) -> TriangleMesh {
    TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, n, n, Diagonal::Right).unwrap()
}

/// The sign test of docs/mathematics.md §1 for both obstacle sides: ψ = 0 and `f = −s·q` press the
/// plate onto the obstacle everywhere, so exactly `w = 0` and `λ = q` (`DΔ²w − sλ = f`);
/// a wrong sign of b, G or the stabilization (α well inside `1/C_I`, here it matters:
/// `ℓ_S` and `S` do not cancel unless their signs agree) gives another λ or none.
/// `multipliers` is the number of multiplier DOFs on the 4×4×2 mesh (1 or 3 per cell).
fn sign_test<Model: fem_forms::Model>(alpha: f64, multipliers: usize) {
    let q = 3.0;
    for s in [1.0, -1.0] {
        let f = move |_: &[f64]| -s * q;
        let (f, psi, g): (&DataFn, &DataFn, &DataFn) = (&f, &zero, &zero);
        let c = Coefficients::new::<Model>(
            &[("D", 2.0), ("ν", 0.3), ("α", alpha), ("s", s)],
            &[("f", f), ("ψ", psi), ("g", g)],
        )
        .unwrap();
        let solution =
            solve_obstacle_on_triangles::<Model>(&[square(4)], &c, ObstacleOptions::default())
                .unwrap();
        let d = &solution.discretization;
        let lambda = solution.field(d.multiplier_field);
        assert_eq!(lambda.len(), multipliers);
        assert!(
            lambda.iter().all(|l| (l - q).abs() <= 1e-8 * q),
            "{} s = {s}: λ_h from {} to {}, expected {q}",
            Model::NAME,
            lambda.iter().cloned().fold(f64::INFINITY, f64::min),
            lambda.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
        );
        let primal = d.primal_part(&solution.values);
        let largest = primal.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(
            largest <= 1e-10,
            "{} s = {s}: |W|∞ = {largest}, expected 0",
            Model::NAME
        );
    }
}

#[test]
fn a_plate_pressed_onto_the_obstacle_everywhere_has_lambda_equal_to_the_load() {
    sign_test::<M>(1e-6, 32);
}

#[test]
fn the_argyris_p1disc_sign_test() {
    sign_test::<kirchhoff_argyris_p1disc::Model>(1e-6, 96);
}

/// Morley: `ΔΔ` of a quadratic is 0, so only the multiplier part of `S_h` is left and
/// any α > 0 is stable; α = 1 makes the `ℓ_S` term as large as the others.
#[test]
fn the_morley_p0_sign_test() {
    sign_test::<kirchhoff_morley_p0::Model>(1.0, 32);
}

/// The forms compile to what the mathematics says: on a right isosceles cell the
/// Argyris stabilization is bounded by the bending form with `C_I ≈ 1.9e5` (h the
/// diameter; docs/mathematics.md §9 and the prototype's value), the same for both
/// multiplier spaces (the primal part of `S_h` does not see μ), and Morley's primal part
/// of `S_h` vanishes (`Δ²` of a quadratic), so its `C_I` is 0 and its `S` block between
/// multipliers is `α`-free `h⁴ s² |T|` (P0: one entry per cell).
#[test]
fn the_stabilizations_compile_to_what_the_mathematics_says() {
    use fem_forms::stabilization::element_inverse_constant;
    let x = [0.0, 0.0, 1.0, 0.0, 0.0, 1.0];
    let params = [1.0, 0.3, 1.0, -1.0];
    let argyris = element_inverse_constant::<M>(&x, &params).unwrap();
    assert!((1.8e5..2.0e5).contains(&argyris), "Argyris C_I = {argyris}");
    let p1disc = element_inverse_constant::<kirchhoff_argyris_p1disc::Model>(&x, &params).unwrap();
    assert!(
        (p1disc - argyris).abs() <= 1e-8 * argyris,
        "{p1disc} vs {argyris}"
    );
    type Morley = kirchhoff_morley_p0::Model;
    assert_eq!(
        element_inverse_constant::<Morley>(&x, &params).unwrap(),
        0.0
    );
    // the λ–μ block of S on the cell: h⁴ s² |T| with h = √2, |T| = ½
    let form = Morley::form("S").unwrap();
    let lambda = Morley::field("λ").unwrap();
    let block = Morley::FORMS[form]
        .blocks
        .iter()
        .position(|b| b.test_field == lambda && b.trial_field == Some(lambda))
        .expect("S has a λ–μ block");
    let zero_data = |_: &[f64]| 0.0;
    let data: Vec<&DataFn> = vec![&zero_data; Morley::DATA.len()];
    let mut out = [0.0];
    Morley::element_matrix(form, block, &x, &params, &data, &mut out);
    assert!((out[0] - 4.0 * 0.5).abs() < 1e-12, "{}", out[0]);
}
/// `boundary: w = g` on the Argyris field is the simple support: the DOFs the obstacle
/// discretization fixes are exactly `plate_dofs(SimplySupported)` (5 per corner, 3 per
/// other boundary vertex), and data that is not zero on the boundary is refused with
/// its name rather than imposed wrongly.
#[test]
fn the_boundary_condition_of_the_plate_is_the_homogeneous_simple_support() {
    use fem_forms::obstacle::triangle::discretize_on_triangles;
    use fem_forms::{DirichletPart, PlateSupport};
    let mesh = square(4);
    let f = |_: &[f64]| -1.0;
    let (f, psi, g): (&DataFn, &DataFn, &DataFn) = (&f, &zero, &zero);
    let params = [("D", 1.0), ("ν", 0.3), ("α", 1e-6), ("s", 1.0)];
    let c = Coefficients::new::<M>(&params, &[("f", f), ("ψ", psi), ("g", g)]).unwrap();
    let d = discretize_on_triangles::<M>(&mesh, &c, "B_h", "L_h").unwrap();
    let fixed: Vec<usize> = (0..d.dofs.dof_count())
        .filter(|&k| d.reduction.free_index(k).is_none())
        .collect();
    let expected = DirichletPart::All
        .plate_dofs(d.dofs.map(0).unwrap(), &mesh, PlateSupport::SimplySupported)
        .unwrap();
    assert_eq!(fixed, expected);
    assert_eq!(fixed.len(), 4 * 5 + 12 * 3);

    let lifted = |x: &[f64]| 1.0 + x[0];
    let g: &DataFn = &lifted;
    let c = Coefficients::new::<M>(&params, &[("f", f), ("ψ", psi), ("g", g)]).unwrap();
    let message = discretize_on_triangles::<M>(&mesh, &c, "B_h", "L_h")
        .err()
        .expect("inhomogeneous plate data is refused")
        .to_string();
    assert!(
        message.contains("`g`") && message.contains("homogeneous"),
        "{message}"
    );
}

/// A clamped plate in the obstacle path: the runtime's `support_plate` constraints into
/// `Discretization::with_constraints`, solved by `solve_nested` (one level). With the
/// obstacle far above the unobstructed deflection it is never touched: λ_h = 0 and the
/// centre deflection is the clamped plate's `0.00126532 q a⁴/D` (to 1e-5 at N = 8, as the
/// linear solve of tests/argyris.rs; the stabilization, α = 1e-6, shifts it by far less).
#[test]
fn a_clamped_plate_below_a_distant_obstacle_bends_as_without_it() {
    use fem_forms::obstacle::triangle::prolong_primal_on_triangles;
    use fem_forms::obstacle::{solve_nested, Discretization};
    use fem_forms::{Constraints, DirichletPart, PlateSupport, SystemDofs};
    let q = 2.0;
    let d_bending = 0.5;
    let up = move |_: &[f64]| q;
    let far = |_: &[f64]| 1.0;
    let (f, psi, g): (&DataFn, &DataFn, &DataFn) = (&up, &far, &zero);
    let c = Coefficients::new::<M>(
        &[("D", d_bending), ("ν", 0.3), ("α", 1e-6), ("s", -1.0)],
        &[("f", f), ("ψ", psi), ("g", g)],
    )
    .unwrap();
    let mesh = square(8);
    let level = || {
        let dofs = SystemDofs::all::<M>(&mesh)?;
        let mut constraints = Constraints::new();
        constraints.support_plate::<M>(
            &mesh,
            &dofs,
            "w",
            &DirichletPart::All,
            PlateSupport::Clamped,
        )?;
        Discretization::with_constraints::<M>(&mesh, &c, dofs, &constraints, "B_h", "L_h")
    };
    let solution = solve_nested(
        vec![level],
        prolong_primal_on_triangles,
        ObstacleOptions::default(),
    )
    .unwrap();
    let d = &solution.discretization;
    let lambda = solution.field(d.multiplier_field);
    assert!(lambda.iter().all(|&l| l == 0.0), "contact where none is");
    let centre = mesh
        .vertices()
        .iter()
        .position(|p| (p[0] - 0.5).abs() < 1e-12 && (p[1] - 0.5).abs() < 1e-12)
        .unwrap();
    let w = solution.field(0)[d.dofs.map(0).unwrap().vertex_dofs(centre).start];
    let exact = 0.00126532 * q / d_bending;
    assert!(
        ((w - exact) / exact).abs() < 1e-5,
        "w_c = {w}, expected {exact}"
    );
}

/// The nested start of an Argyris field: prolonged to a refined mesh, a global quintic is
/// reproduced exactly (Argyris spaces are nested). The coarse DOFs are set here from the
/// definition (value, gradient, Hessian at vertices; the normal derivative at edge
/// midpoints along the edge oriented from its lower to its higher global vertex), and
/// the fine field is evaluated through the element's own transformation.
#[test]
fn the_argyris_prolongation_reproduces_a_quintic() {
    use fem_forms::element::{TriangleBasis, TriangleField};
    use fem_forms::obstacle::triangle::{discretize_on_triangles, prolong_on_triangles};
    use fem_forms::PointLocator;
    let p = |x: f64, y: f64| x.powi(5) + 2.0 * x * x * y.powi(3) - 3.0 * x * y + y.powi(4) + 0.5;
    let px = |x: f64, y: f64| 5.0 * x.powi(4) + 4.0 * x * y.powi(3) - 3.0 * y;
    let py = |x: f64, y: f64| 6.0 * x * x * y * y - 3.0 * x + 4.0 * y.powi(3);
    let pxx = |x: f64, y: f64| 20.0 * x.powi(3) + 4.0 * y.powi(3);
    let pxy = |x: f64, y: f64| 12.0 * x * y * y - 3.0;
    let pyy = |x: f64, y: f64| 12.0 * x * x * y + 12.0 * y * y;
    let coarse_mesh =
        TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 3, 2, Diagonal::Alternating).unwrap();
    let fine_mesh = coarse_mesh.refine_uniformly();
    let f = |_: &[f64]| -1.0;
    let (f, psi, g): (&DataFn, &DataFn, &DataFn) = (&f, &zero, &zero);
    let params = [("D", 1.0), ("ν", 0.3), ("α", 1e-6), ("s", 1.0)];
    let c = Coefficients::new::<M>(&params, &[("f", f), ("ψ", psi), ("g", g)]).unwrap();
    let coarse = discretize_on_triangles::<M>(&coarse_mesh, &c, "B_h", "L_h").unwrap();
    let fine = discretize_on_triangles::<M>(&fine_mesh, &c, "B_h", "L_h").unwrap();
    let map = coarse.dofs.map(0).unwrap();
    let mut values = vec![0.0; coarse.dofs.dof_count()];
    let offset = coarse.dofs.offset(0).unwrap();
    for cell in 0..coarse_mesh.cell_count() {
        let dofs = map.cell_dofs(cell);
        let vertices = coarse_mesh.cell(cell);
        for (i, &v) in vertices.iter().enumerate() {
            let [x, y] = coarse_mesh.vertices()[v];
            let at = [p(x, y), px(x, y), py(x, y), pxx(x, y), pxy(x, y), pyy(x, y)];
            for (k, value) in at.iter().enumerate() {
                values[offset + dofs[6 * i + k]] = *value;
            }
        }
        for k in 0..3 {
            let (a, b) = (vertices[k], vertices[(k + 1) % 3]);
            let (a, b) = (a.min(b), a.max(b));
            let (pa, pb) = (coarse_mesh.vertices()[a], coarse_mesh.vertices()[b]);
            let length = (pb[0] - pa[0]).hypot(pb[1] - pa[1]);
            let n = [(pb[1] - pa[1]) / length, -(pb[0] - pa[0]) / length];
            let (x, y) = ((pa[0] + pb[0]) / 2.0, (pa[1] + pb[1]) / 2.0);
            values[offset + dofs[18 + k]] = px(x, y) * n[0] + py(x, y) * n[1];
        }
    }
    let prolonged = prolong_on_triangles(&coarse, &values, &fine);
    let fine_map = fine.dofs.map(0).unwrap();
    let range = fine.dofs.range(0).unwrap();
    let field = TriangleField {
        mesh: &fine_mesh,
        map: fine_map,
        coefficients: &prolonged[range],
    };
    let basis = TriangleBasis::new(fine_map.element());
    let locator = PointLocator::new(&fine_mesh);
    for k in 0..50 {
        let (x, y) = (
            (k as f64 * 0.6180339887).fract(),
            (k as f64 * 0.7548776662).fract(),
        );
        let value = field.at(&basis, &locator, [x, y]).unwrap();
        assert!(
            (value - p(x, y)).abs() < 1e-10,
            "({x}, {y}): {value} vs {}",
            p(x, y)
        );
    }
}

/// The one solve of a registry scene: `scene` with `obstacle` (where given) at N =
/// `size`, load `load`, by `solver`.
fn registry_solve(
    scene: &str,
    obstacle: Option<&str>,
    pair: &str,
    size: usize,
    load: Option<f64>,
    solver: fem_forms::obstacle::VariationalSolver,
) -> fem_forms::models::report::Report {
    use fem_forms::models::families;
    use fem_forms::models::scene::Adjustment;
    let mut scene = families::scene(scene).unwrap();
    if let Some(o) = obstacle {
        families::family("kirchhoff")
            .unwrap()
            .adjust(&mut scene, &Adjustment::Obstacle(o.into()))
            .unwrap();
    }
    let settings = fem_forms::models::report::Settings {
        pair: Some(pair.into()),
        mesh_size: Some(size),
        load,
        solver,
        ..Default::default()
    };
    families::solve(&scene, &settings).unwrap().report
}

/// The CLI's obstacle solve (nested semismooth Newton) against clarabel's interior-point
/// method on the same QP, N = 8, q = 20, flat and curved obstacles: J_h, ∫λ_h and the
/// contact area agree, and both KKT residuals (computed from the solutions, not the
/// solvers' word) are small.
#[test]
fn newton_agrees_with_clarabel_on_a_small_mesh() {
    use fem_forms::obstacle::VariationalSolver;
    for obstacle in ["flat", "curved"] {
        let solve = |solver| {
            registry_solve(
                "kirchhoff-obstacle",
                Some(obstacle),
                "argyris-p0",
                8,
                Some(20.0),
                solver,
            )
        };
        let newton = solve(VariationalSolver::SemismoothNewton);
        let clarabel = solve(VariationalSolver::Clarabel);
        let (n, c) = (&newton.solve, &clarabel.solve);
        let close = |a: f64, b: f64, tolerance: f64| (a - b).abs() <= tolerance * b.abs();
        let (jn, jc) = (n.energy.unwrap(), c.energy.unwrap());
        assert!(close(jn, jc, 1e-7), "{obstacle}: J_h {jn} vs {jc}");
        assert!(
            close(n.total_contact_force, c.total_contact_force, 1e-5),
            "{obstacle}: ∫λ_h {} vs {}",
            n.total_contact_force,
            c.total_contact_force
        );
        assert_eq!(n.contact_area, c.contact_area, "{obstacle}");
        assert!(n.kkt_residual < 1e-12, "{obstacle}");
        assert!(c.kkt_residual < 1e-6, "{obstacle}");
        // nested: N = 4, 8, each level a handful of Newton steps, no cycling
        assert_eq!(n.levels.len(), 2);
        assert!(n.levels.iter().all(|l| l[1] <= 20));
    }
}

/// The λ-scatter of docs/mathematics.md §9 at N = 32, q = 20, flat obstacle: raw
/// Argyris–P0 λ_h at the C_I rule strays by 17 % from its exact value q in the contact
/// interior (the oscillating tail of the free boundary's line force), its patch average
/// (the default reading) by 0.74 %. The bounds leave room on both sides.
#[test]
fn the_patch_average_cures_the_multiplier_scatter() {
    let report = registry_solve(
        "kirchhoff-obstacle",
        Some("flat"),
        "argyris-p0",
        32,
        Some(20.0),
        fem_forms::obstacle::VariationalSolver::SemismoothNewton,
    );
    let stat = |key: &str, field: &str| report.quantities[key][field].as_f64().unwrap();
    let (raw, default) = ("interior_multiplier_raw", "interior_multiplier");
    assert!(
        stat(raw, "cells") >= 100.0,
        "{} interior cells",
        stat(raw, "cells")
    );
    assert_eq!(stat(raw, "exact"), 20.0);
    assert!(
        stat(raw, "max_relative_error") > 0.08,
        "raw λ_h {}…{}",
        stat(raw, "min"),
        stat(raw, "max")
    );
    assert!(
        stat(default, "max_relative_error") < 0.02,
        "patch average {}…{}",
        stat(default, "min"),
        stat(default, "max")
    );
}

/// Observed rates of the clamped centre deflection from successive differences on
/// N = 4, 8, 16, 32 (no reference needed): Argyris above 5 (5.5–6.7 measured: a point
/// value of quintics, above the O(h⁴) of the H² error), Morley 2 (its O(h²) in the
/// deflection).
#[test]
fn the_square_plate_converges_at_the_elements_rates() {
    for (pair, low, high) in [("argyris-p0", 5.0, 7.5), ("morley-p0", 1.7, 2.2)] {
        let w: Vec<f64> = [4, 8, 16, 32]
            .iter()
            .map(|&n| {
                let newton = fem_forms::obstacle::VariationalSolver::SemismoothNewton;
                registry_solve("kirchhoff-square", None, pair, n, None, newton)
                    .number("centre_deflection")
                    .unwrap()
            })
            .collect();
        let d: Vec<f64> = w.windows(2).map(|p| (p[1] - p[0]).abs()).collect();
        for r in d.windows(2).map(|p| (p[0] / p[1]).log2()) {
            assert!(r > low && r < high, "{pair}: rate {r} from {w:?}");
        }
    }
}

/// `C_I` depends on a cell's shape, not its size: the Argyris constant of the unit right
/// triangle is that of the same triangle scaled to h = 1/64 and 1/1024, moved off the
/// origin (the element matrices in physical DOFs then spread their eigenvalues over
/// powers of h, which once broke the kernel split at h = 1/32).
#[test]
fn the_argyris_inverse_constant_does_not_depend_on_the_cell_size() {
    use fem_forms::stabilization::element_inverse_constant;
    let params = [1.0, 0.3, 1.0, -1.0];
    let unit = element_inverse_constant::<M>(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0], &params).unwrap();
    for h in [1.0 / 64.0, 1.0 / 1024.0] {
        let x = [0.3, 0.7, 0.3 + h, 0.7, 0.3, 0.7 + h];
        let small = element_inverse_constant::<M>(&x, &params).unwrap();
        assert!(
            (small - unit).abs() <= 1e-6 * unit,
            "h = {h}: C_I = {small} against {unit} at h = 1"
        );
    }
}
