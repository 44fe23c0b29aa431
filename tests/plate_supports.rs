//! Plate supports on boundary edges in any direction (issue 13): the Argyris vertex DOFs
//! of the supported vertices are rotated (`Constraints::change_of_basis`,
//! docs/elements.md §6) so that the conditions become fixed DOFs.
//!
//! What can fail here: the rotated unit square must bend exactly as the unrotated one
//! (the Argyris space is invariant under rotations, so the discrete solutions agree to
//! rounding, and both match the series references); the clamped polygonal disk must
//! converge to the exact clamped circular plate; every fixed primed DOF must vanish on
//! functions that satisfy the support and every free one must not; the obstacle path
//! must give the rotated square the unrotated one's energy and contact force.
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

use fem_forms::models::kirchhoff::{kirchhoff_argyris, kirchhoff_argyris_p0};
use fem_forms::obstacle::triangle::prolong_primal_on_triangles;
use fem_forms::obstacle::{solve_nested, Discretization, ObstacleOptions};
use fem_forms::{
    solve_linear, Coefficients, Constraints, DataFn, Diagonal, DirichletPart, Factorization, Model,
    PlateSupport, SystemDofs, TriangleMesh,
};
use fem_runtime::reference::triangle::Polynomial2;
use fem_runtime::{DofMap, ElementKind};

fn unit_load(_: &[f64]) -> f64 {
    1.0
}

/// `mesh` rotated by `angle` about `centre` (same vertex numbering, cells and markers).
fn rotated(mesh: &TriangleMesh, angle: f64, centre: [f64; 2]) -> TriangleMesh {
    let (s, c) = angle.sin_cos();
    let vertices = mesh
        .vertices()
        .iter()
        .map(|p| {
            let (x, y) = (p[0] - centre[0], p[1] - centre[1]);
            [centre[0] + c * x - s * y, centre[1] + s * x + c * y]
        })
        .collect();
    let markers: Vec<(usize, usize, u32)> = mesh
        .boundary_edges()
        .iter()
        .map(|&(e, m)| {
            let [a, b] = mesh.edges()[e];
            (a, b, m)
        })
        .collect();
    TriangleMesh::new(vertices, mesh.cells().to_vec(), &markers).unwrap()
}

/// The Kirchhoff plate (Argyris, D = 1, ν = 0.3, unit load) on `mesh`, held by `support`
/// on its whole boundary, solved by `solve_linear`: the full Cartesian coefficients.
fn plate(mesh: &TriangleMesh, support: PlateSupport) -> (Vec<f64>, SystemDofs) {
    type M = kirchhoff_argyris::Model;
    let dofs = SystemDofs::new::<M>(mesh, &[0]).unwrap();
    let load: &DataFn = &unit_load;
    let coefficients = Coefficients::new::<M>(&[("D", 1.0), ("ν", 0.3)], &[("f", load)]).unwrap();
    let mut constraints = Constraints::new();
    constraints
        .support_plate::<M>(mesh, &dofs, "w", &DirichletPart::All, support)
        .unwrap();
    let w = solve_linear::<M>(
        mesh,
        &dofs,
        "a",
        "ℓ",
        &constraints,
        &coefficients,
        Factorization::Cholesky,
    )
    .unwrap();
    (w, dofs)
}

/// The value DOF of every vertex.
fn vertex_values(w: &[f64], dofs: &SystemDofs, vertices: usize) -> Vec<f64> {
    let map = dofs.map(0).unwrap();
    (0..vertices).map(|v| w[map.vertex_dofs(v).start]).collect()
}

/// The unit square rotated by 30° about its centre, clamped and simply supported: the
/// deflection at every vertex equals the unrotated square's at the same vertex to 1e-9
/// of the centre deflection (the Argyris space is rotation invariant, so the discrete
/// problems are the same one in rotated coordinates; a wrong rotation of the vertex
/// DOFs or a wrongly fixed functional breaks it by far more), and the centre deflection
/// matches Timoshenko and Woinowsky-Krieger's `0.00126532` / `0.00406235 q a⁴/D` to 1e-5
/// at N = 8 and 3e-6 at N = 16 (the references have six digits, ~4e-6 relative).
#[test]
fn the_rotated_square_bends_as_the_unrotated_one() {
    for (support, exact, n, tolerance) in [
        (PlateSupport::Clamped, 0.00126532, 8, 1e-5),
        (PlateSupport::Clamped, 0.00126532, 16, 3e-6),
        (PlateSupport::SimplySupported, 0.00406235, 8, 1e-5),
        (PlateSupport::SimplySupported, 0.00406235, 16, 3e-6),
    ] {
        let square = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, n, n, Diagonal::Right).unwrap();
        let turned = rotated(&square, std::f64::consts::PI / 6.0, [0.5, 0.5]);
        let (w, dofs) = plate(&square, support);
        let (w_turned, dofs_turned) = plate(&turned, support);
        let reference = vertex_values(&w, &dofs, square.vertex_count());
        let values = vertex_values(&w_turned, &dofs_turned, turned.vertex_count());
        let centre = square
            .vertices()
            .iter()
            .position(|p| (p[0] - 0.5).abs() < 1e-12 && (p[1] - 0.5).abs() < 1e-12)
            .unwrap();
        let w_c = values[centre];
        let largest = reference
            .iter()
            .zip(&values)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        println!(
            "{support:?} N = {n}: rotated w_c = {w_c:.10e}, unrotated {:.10e}, largest vertex difference {largest:.2e}",
            reference[centre]
        );
        assert!(
            largest < 1e-9 * w_c,
            "{support:?} N = {n}: the rotated plate differs by {largest:e}"
        );
        assert!(
            ((w_c - exact) / exact).abs() < tolerance,
            "{support:?} N = {n}: w_c = {w_c}, exact {exact}"
        );
    }
}

/// The clamped polygonal disk (`TriangleMesh::disk`, 6·rings boundary edges, every
/// boundary vertex a corner of two slanted clamped edges) against the exact clamped
/// circular plate `w(r) = q(a² − r²)²/(64D)`: the centre deflection `q a⁴/(64D)`
/// converges, and the deflection at every vertex follows the exact profile as closely.
/// At first order: the error halves per doubling of the rings (measured 6.6e-2, 3.0e-2,
/// 1.5e-2 relative at 4, 8, 16 rings). Each corner of the polygon fixes the whole
/// Hessian (both edges' `∂_tt`, `∂_nt`), which the polygon's own solution has there but
/// the disk's has not (its `w_rr = q a²/(8D)` on the circle): the discrete plate is held
/// too stiffly in a band of width h along the boundary. (The five conditions of the
/// circle itself at each vertex, the tangent taken from the circle, give 1.7e-2, 3.9e-3,
/// 9.2e-4: second order, the polygon's distance from the circle; docs/elements.md §6.)
#[test]
fn the_clamped_polygonal_disk_converges_to_the_circular_plate() {
    let exact = |r: f64| (1.0 - r * r).powi(2) / 64.0;
    let mut errors = Vec::new();
    for rings in [4, 8, 16] {
        let mesh = TriangleMesh::disk([0.0, 0.0], 1.0, rings).unwrap();
        let (w, dofs) = plate(&mesh, PlateSupport::Clamped);
        let values = vertex_values(&w, &dofs, mesh.vertex_count());
        let centre = (values[0] - exact(0.0)) / exact(0.0);
        let profile = mesh
            .vertices()
            .iter()
            .zip(&values)
            .map(|(p, w)| (w - exact(p[0].hypot(p[1]))).abs())
            .fold(0.0, f64::max)
            / exact(0.0);
        println!("rings {rings}: w(0) = {:.8e} (relative error {centre:.3e}), profile error {profile:.3e}", values[0]);
        assert!(
            profile < 2.0 * centre.abs() + 1e-12,
            "rings {rings}: profile {profile}"
        );
        errors.push(centre.abs());
    }
    for k in 0..2 {
        let ratio = errors[k] / errors[k + 1];
        assert!(ratio > 1.8 && ratio < 2.6, "errors {errors:?}");
    }
    assert!(errors[2] < 2e-2, "errors {errors:?}");
}

/// `Σ c x^i y^j` from `(i, j, c)`.
fn poly(terms: &[(u32, u32, f64)]) -> Polynomial2 {
    Polynomial2 {
        terms: terms.to_vec(),
    }
}

fn product(p: &Polynomial2, q: &Polynomial2) -> Polynomial2 {
    let mut terms = Vec::new();
    for &(i, j, a) in &p.terms {
        for &(k, l, b) in &q.terms {
            terms.push((i + k, j + l, a * b));
        }
    }
    Polynomial2 { terms }
}

/// The Cartesian Argyris DOFs of `p` on `mesh` (`map`): value, gradient and Hessian at
/// each vertex, and at each edge midpoint the derivative along the normal of the edge
/// oriented from its lower to its higher vertex.
fn argyris_dofs(map: &DofMap, mesh: &TriangleMesh, p: &Polynomial2) -> Vec<f64> {
    let mut out = vec![0.0; map.dof_count()];
    let derivatives = [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)];
    for (v, x) in mesh.vertices().iter().enumerate() {
        let start = map.vertex_dofs(v).start;
        for (k, &(a, b)) in derivatives.iter().enumerate() {
            out[start + k] = p.derivative(a, b).eval(*x);
        }
    }
    for c in 0..mesh.cell_count() {
        let cell = mesh.cell(c);
        for k in 0..3 {
            let (a, b) = (cell[k], cell[(k + 1) % 3]);
            let (a, b) = (a.min(b), a.max(b));
            let (x, y) = (mesh.vertices()[a], mesh.vertices()[b]);
            let t = [y[0] - x[0], y[1] - x[1]];
            let l = t[0].hypot(t[1]);
            let m = [(x[0] + y[0]) / 2.0, (x[1] + y[1]) / 2.0];
            out[map.cell_dofs(c)[3 * 6 + k]] =
                (t[1] * p.derivative(1, 0).eval(m) - t[0] * p.derivative(0, 1).eval(m)) / l;
        }
    }
    out
}

/// On the rectangle [0, 2] × [0, 1] with cells of every orientation, rotated by 0.4 rad:
/// for the whole boundary, for two opposite sides and for one side, both supports, the
/// primed DOFs (`U' = T U`) that the constraints fix vanish for every function that
/// satisfies the support (`b r`, `b` the product of the part's side lines, squared for
/// clamped, several `r`), and every other boundary DOF is nonzero for one of them:
/// nothing is fixed that the conditions leave free, nothing they fix is left free.
#[test]
fn fixed_primed_dofs_are_the_ones_the_slanted_conditions_fix() {
    let base = TriangleMesh::rectangle(0.0, 2.0, 0.0, 1.0, 4, 3, Diagonal::Alternating).unwrap();
    let base = base.refine(&[0, 7, 20]).unwrap().0;
    let angle: f64 = 0.4;
    let mesh = rotated(&base, angle, [0.0, 0.0]);
    let (s, c) = angle.sin_cos();
    // the rotated coordinates: ξ = c x + s y, η = −s x + c y (the unrotated x, y)
    let xi = poly(&[(1, 0, c), (0, 1, s)]);
    let eta = poly(&[(1, 0, -s), (0, 1, c)]);
    let shift = |p: &Polynomial2, a: f64| {
        let mut q = p.clone();
        q.terms.push((0, 0, a));
        q
    };
    // the side lines: ξ = 0 (left, marker 4), ξ = 2 (right, 2), η = 0 (bottom, 1), η = 1 (top, 3)
    let left = xi.clone();
    let right = shift(&xi, -2.0);
    let bottom = eta.clone();
    let top = shift(&eta, -1.0);
    let r = [
        poly(&[(0, 0, 1.0), (1, 0, 0.3), (0, 1, -0.7), (1, 1, 0.2)]),
        poly(&[(0, 0, 0.5), (2, 0, -1.0), (0, 1, 0.9), (0, 2, 0.4)]),
        poly(&[(0, 0, -0.8), (1, 0, 1.1), (3, 0, 0.25), (1, 2, -0.6)]),
    ];
    let parts = [
        (
            DirichletPart::All,
            product(&product(&left, &right), &product(&bottom, &top)),
        ),
        (DirichletPart::Markers(vec![4, 2]), product(&left, &right)),
        (DirichletPart::Markers(vec![1]), bottom.clone()),
    ];
    let map = DofMap::on_triangles(&mesh, ElementKind::Argyris);
    for (part, b) in &parts {
        for support in [PlateSupport::SimplySupported, PlateSupport::Clamped] {
            let b = match support {
                PlateSupport::SimplySupported => b.clone(),
                PlateSupport::Clamped => product(b, b),
            };
            let mut constraints = Constraints::new();
            constraints
                .support_plate_field(&mesh, &map, 0, part, support)
                .unwrap();
            let basis = constraints.change_of_basis(map.dof_count()).unwrap();
            assert!(!basis.is_identity());
            let reduction = constraints.reduction(map.dof_count()).unwrap();
            let values: Vec<Vec<f64>> = r
                .iter()
                .map(|r| {
                    let mut u = argyris_dofs(&map, &mesh, &product(&b, r));
                    basis.to_primed(&mut u);
                    u
                })
                .collect();
            for d in map.boundary_dofs(&mesh) {
                let largest = values.iter().map(|u| u[d].abs()).fold(0.0, f64::max);
                let what = format!("{part:?} {support:?} DOF {d}");
                if reduction.free_index(d).is_none() {
                    assert!(largest < 1e-11, "{what} is fixed but {largest}");
                } else {
                    assert!(largest > 1e-6, "{what} is free but vanishes");
                }
            }
        }
    }
}

/// The obstacle path (`Discretization::with_constraints` in `solve_nested`, nested
/// start 8 → 16): the clamped unit square under Argyris–P0 pushed up by q = 5 against
/// the flat obstacle w ≤ 0.002 (the `kirchhoff-obstacle` scene), rotated by 30° about
/// its centre, has the unrotated square's energy J_h and contact force ∫λ_h to 1e-8
/// relative, with a contact set (λ_h > 0) that is not empty.
#[test]
fn the_rotated_clamped_square_meets_the_obstacle_as_the_unrotated_one() {
    type M = kirchhoff_argyris_p0::Model;
    let q = 5.0;
    let load = move |_: &[f64]| q;
    let psi = |_: &[f64]| 0.002;
    let zero = |_: &[f64]| 0.0;
    let (f, psi, g): (&DataFn, &DataFn, &DataFn) = (&load, &psi, &zero);
    let coefficients = Coefficients::new::<M>(
        &[("D", 1.0), ("ν", 0.3), ("α", 1e-6), ("s", -1.0)],
        &[("f", f), ("ψ", psi), ("g", g)],
    )
    .unwrap();
    let solve = |angle: f64| {
        let meshes: Vec<TriangleMesh> = [8, 16]
            .iter()
            .map(|&n| {
                let square =
                    TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, n, n, Diagonal::Right).unwrap();
                rotated(&square, angle, [0.5, 0.5])
            })
            .collect();
        let coefficients = &coefficients;
        let levels: Vec<_> = meshes
            .into_iter()
            .map(|mesh| {
                move || {
                    let dofs = SystemDofs::all::<M>(&mesh)?;
                    let mut constraints = Constraints::new();
                    constraints.support_plate::<M>(
                        &mesh,
                        &dofs,
                        "w",
                        &DirichletPart::All,
                        PlateSupport::Clamped,
                    )?;
                    Discretization::with_constraints::<M>(
                        &mesh,
                        coefficients,
                        dofs,
                        &constraints,
                        "B_h",
                        "L_h",
                    )
                }
            })
            .collect();
        let solution = solve_nested(
            levels,
            prolong_primal_on_triangles,
            ObstacleOptions::default(),
        )
        .unwrap();
        let energy = solution.energy::<M>(coefficients).unwrap();
        let force = solution.total_contact_force();
        let identity = solution.discretization.basis.is_identity();
        (energy, force, solution.levels.clone(), identity)
    };
    let (energy, force, levels, identity) = solve(0.0);
    let (energy_turned, force_turned, levels_turned, identity_turned) =
        solve(std::f64::consts::PI / 6.0);
    println!("unrotated: J_h = {energy:.12e}, ∫λ_h = {force:.12e}, levels {levels:?}");
    println!("rotated:   J_h = {energy_turned:.12e}, ∫λ_h = {force_turned:.12e}, levels {levels_turned:?}");
    assert!(identity && !identity_turned);
    assert!(force > 0.1 * q, "no contact: ∫λ_h = {force}");
    assert!(
        ((energy_turned - energy) / energy).abs() < 1e-8,
        "J_h {energy_turned} against {energy}"
    );
    assert!(
        ((force_turned - force) / force).abs() < 1e-8,
        "∫λ_h {force_turned} against {force}"
    );
}

/// The model is the one the issue names (guards the `type M` aliases above).
#[test]
fn the_models_have_an_argyris_deflection() {
    assert_eq!(
        kirchhoff_argyris::Model::FIELDS[0].element,
        ElementKind::Argyris
    );
    assert_eq!(
        kirchhoff_argyris_p0::Model::FIELDS[0].element,
        ElementKind::Argyris
    );
}

/// The Kirchhoff plate (as [`plate`]) on the disk of radius 1 with `rings` rings, held by
/// `support` on the polygon (`curve: false`) or on the circle it approximates
/// (`Constraints::support_plate_on_curve`, outward normal x/|x|, curvature 1): the
/// centre deflection and the constraints' warnings.
fn disk_plate(rings: usize, support: PlateSupport, curve: bool) -> (f64, Vec<String>) {
    type M = kirchhoff_argyris::Model;
    let mesh = TriangleMesh::disk([0.0, 0.0], 1.0, rings).unwrap();
    let dofs = SystemDofs::new::<M>(&mesh, &[0]).unwrap();
    let load: &DataFn = &unit_load;
    let coefficients = Coefficients::new::<M>(&[("D", 1.0), ("ν", 0.3)], &[("f", load)]).unwrap();
    let mut constraints = Constraints::new();
    let circle = |x: [f64; 2]| {
        let r = x[0].hypot(x[1]);
        ([x[0] / r, x[1] / r], 1.0)
    };
    if curve {
        constraints
            .support_plate_on_curve::<M>(
                &mesh,
                &dofs,
                "w",
                &DirichletPart::All,
                support,
                &circle,
                None,
            )
            .unwrap();
    } else {
        constraints
            .support_plate::<M>(&mesh, &dofs, "w", &DirichletPart::All, support)
            .unwrap();
    }
    let w = solve_linear::<M>(
        &mesh,
        &dofs,
        "a",
        "ℓ",
        &constraints,
        &coefficients,
        Factorization::Cholesky,
    )
    .unwrap();
    // vertex 0 is the centre
    (w[0], constraints.warnings().to_vec())
}

/// Babuška's paradox, discrete form: the disk simply supported on its polygon. At each
/// polygon corner `w = 0` on both edges fixes the whole gradient, so the Argyris plate
/// converges to the CLAMPED disk `q a⁴/(64D)` (measured 1.80e-2, 1.66e-2, 1.61e-2,
/// 1.58e-2 at 4, 8, 16, 32 rings), nowhere near the simply supported disk's
/// `(5 + ν)/(1 + ν) q a⁴/(64D)` = 6.37e-2 (Timoshenko and Woinowsky-Krieger §15), nor the
/// polygons' own limit `3 q a⁴/(64D)` (w = Δw = 0). `support_plate` warns about it; it
/// does not for the square (four 90° corners) nor for a clamped polygon.
#[test]
fn a_simply_supported_polygonal_disk_converges_to_the_clamped_plate() {
    let clamped = 1.0 / 64.0;
    let simply = (5.0 + 0.3) / (1.0 + 0.3) / 64.0;
    let mut errors = Vec::new();
    for rings in [4, 8, 16] {
        let (w, warnings) = disk_plate(rings, PlateSupport::SimplySupported, false);
        println!("polygon, simply supported, rings {rings}: w(0) = {w:.8e}; {warnings:?}");
        assert!(w < 0.3 * simply, "rings {rings}: w(0) = {w}");
        assert_eq!(warnings.len(), 1, "{warnings:?}");
        assert!(warnings[0].contains("Babuška"), "{warnings:?}");
        errors.push(((w - clamped) / clamped).abs());
    }
    assert!(
        errors[0] > errors[1] && errors[1] > errors[2] && errors[2] < 0.05,
        "relative distances from the clamped plate {errors:?}"
    );
    let (_, warnings) = disk_plate(4, PlateSupport::Clamped, false);
    assert!(warnings.is_empty(), "{warnings:?}");
    type M = kirchhoff_argyris::Model;
    let square = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 4, 4, Diagonal::Right).unwrap();
    let dofs = SystemDofs::new::<M>(&square, &[0]).unwrap();
    let mut constraints = Constraints::new();
    constraints
        .support_plate::<M>(
            &square,
            &dofs,
            "w",
            &DirichletPart::All,
            PlateSupport::SimplySupported,
        )
        .unwrap();
    assert!(constraints.warnings().is_empty());
}

/// The cure: the disk held by the conditions of the circle (`support_plate_on_curve`)
/// converges to the exact circular plates at second order (the polygon's distance from
/// the circle): simply supported to `(5 + ν)/(1 + ν) q a⁴/(64D)` (relative errors
/// measured 2.9e-3, 7.5e-4, 1.9e-4 at 4, 8, 16 rings), clamped to `q a⁴/(64D)` (1.7e-2,
/// 3.9e-3, 9.2e-4; the polygon's own conditions give first order,
/// `the_clamped_polygonal_disk_converges_to_the_circular_plate`).
#[test]
fn supports_on_the_circle_converge_at_second_order() {
    for (support, exact, finest) in [
        (PlateSupport::SimplySupported, 5.3 / 1.3 / 64.0, 5e-4),
        (PlateSupport::Clamped, 1.0 / 64.0, 2e-3),
    ] {
        let errors: Vec<f64> = [4, 8, 16]
            .iter()
            .map(|&rings| {
                let (w, warnings) = disk_plate(rings, support, true);
                println!("circle, {support:?}, rings {rings}: w(0) = {w:.8e}");
                assert!(warnings.is_empty());
                ((w - exact) / exact).abs()
            })
            .collect();
        for k in 0..2 {
            let ratio = errors[k] / errors[k + 1];
            assert!(ratio > 3.3 && ratio < 5.0, "{support:?}: errors {errors:?}");
        }
        assert!(errors[2] < finest, "{support:?}: errors {errors:?}");
    }
}

/// The jet `[p, p_x, p_y, p_xx, p_xy, p_yy]` of `p` at `x`.
fn jet(p: &Polynomial2, x: [f64; 2]) -> [f64; 6] {
    [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)].map(|(a, b)| p.derivative(a, b).eval(x))
}

/// A quintic with every degree present.
fn quintic() -> Polynomial2 {
    poly(&[
        (0, 0, 0.3),
        (1, 0, 1.0),
        (0, 1, -0.5),
        (2, 1, 1.0),
        (1, 2, -0.7),
        (3, 0, 0.2),
        (4, 1, 0.5),
        (1, 4, -0.3),
        (0, 5, 0.1),
    ])
}

/// `DΔ²p` with D = 1.
fn bilaplacian(p: &Polynomial2) -> Polynomial2 {
    let mut terms = p.derivative(4, 0).terms;
    terms.extend(
        p.derivative(2, 2)
            .terms
            .iter()
            .map(|&(i, j, c)| (i, j, 2.0 * c)),
    );
    terms.extend(p.derivative(0, 4).terms);
    Polynomial2 { terms }
}

/// Nonzero data on a clamped plate, exact: with `w = G` a quintic (in the Argyris
/// space), `f = DΔ²G` and `G` as the data of the clamped support
/// (`support_plate_with_data`: `w = G`, `∂_n w = ∂_n G`), the plate is `G` itself, the
/// rotated vertex DOFs and edge DOFs included, to rounding: on the unit square rotated
/// by 30° through `solve_linear`, and through the obstacle path (Argyris–P0, obstacle
/// above at ψ = G₂, a quadratic (the data's quadrature is exact for it), load `q`
/// pushing the plate up onto it everywhere: `w = G₂` and `λ = q`, `S_h`'s residual
/// `DΔ²w − sλ − f` vanishing), where the fixed values of
/// rotated DOFs move to the right sides of both the plate rows and the multiplier rows
/// (each cell's constraint holds with equality, so a wrong shift of a boundary cell's
/// row moves w_h). A wrong value of any fixed functional (the sign of the edge DOFs'
/// `∂_n G`, tried) breaks it.
#[test]
fn clamped_data_reproduce_a_quintic_on_the_rotated_square() {
    let g = quintic();
    let load_poly = bilaplacian(&g);
    let square = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 4, 4, Diagonal::Right).unwrap();
    let mesh = rotated(&square, std::f64::consts::PI / 6.0, [0.5, 0.5]);
    let data = |x: [f64; 2]| jet(&g, x);
    let load = move |x: &[f64]| load_poly.eval([x[0], x[1]]);
    let map = DofMap::on_triangles(&mesh, ElementKind::Argyris);
    let expected = argyris_dofs(&map, &mesh, &g);
    let scale = expected.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let compare = |w: &[f64], what: &str| {
        let largest = w
            .iter()
            .zip(&expected)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        println!("{what}: largest DOF error {largest:.2e} of {scale:.2e}");
        assert!(largest < 1e-9 * scale, "{what}: {largest}");
    };
    {
        type M = kirchhoff_argyris::Model;
        let dofs = SystemDofs::new::<M>(&mesh, &[0]).unwrap();
        let f: &DataFn = &load;
        let coefficients = Coefficients::new::<M>(&[("D", 1.0), ("ν", 0.3)], &[("f", f)]).unwrap();
        let mut constraints = Constraints::new();
        constraints
            .support_plate_with_data::<M>(
                &mesh,
                &dofs,
                "w",
                &DirichletPart::All,
                PlateSupport::Clamped,
                Some(&data),
            )
            .unwrap();
        assert!(!constraints
            .change_of_basis(dofs.dof_count())
            .unwrap()
            .is_identity());
        let w = solve_linear::<M>(
            &mesh,
            &dofs,
            "a",
            "ℓ",
            &constraints,
            &coefficients,
            Factorization::Cholesky,
        )
        .unwrap();
        compare(&w, "solve_linear");
    }
    {
        type M = kirchhoff_argyris_p0::Model;
        let q = 3.0;
        let g2 = poly(&[
            (0, 0, 0.3),
            (1, 0, 1.0),
            (0, 1, -0.5),
            (2, 0, 0.8),
            (1, 1, -0.6),
            (0, 2, 0.4),
        ]);
        let expected = argyris_dofs(&map, &mesh, &g2);
        let scale = expected.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let data = |x: [f64; 2]| jet(&g2, x);
        let pushed = move |_: &[f64]| q;
        let obstacle = {
            let g2 = g2.clone();
            move |x: &[f64]| g2.eval([x[0], x[1]])
        };
        let zero = |_: &[f64]| 0.0;
        let (f, psi, g0): (&DataFn, &DataFn, &DataFn) = (&pushed, &obstacle, &zero);
        let coefficients = Coefficients::new::<M>(
            &[("D", 1.0), ("ν", 0.3), ("α", 1e-6), ("s", -1.0)],
            &[("f", f), ("ψ", psi), ("g", g0)],
        )
        .unwrap();
        let level = || {
            let dofs = SystemDofs::all::<M>(&mesh)?;
            let mut constraints = Constraints::new();
            constraints.support_plate_with_data::<M>(
                &mesh,
                &dofs,
                "w",
                &DirichletPart::All,
                PlateSupport::Clamped,
                Some(&data),
            )?;
            Discretization::with_constraints::<M>(
                &mesh,
                &coefficients,
                dofs,
                &constraints,
                "B_h",
                "L_h",
            )
        };
        let solution = solve_nested(
            vec![level],
            prolong_primal_on_triangles,
            ObstacleOptions::default(),
        )
        .unwrap();
        let d = &solution.discretization;
        assert!(!d.basis.is_identity());
        let lambda = solution.field(d.multiplier_field);
        assert!(
            lambda.iter().all(|&l| (l - q).abs() < 1e-8 * q),
            "λ_h from {} to {}, expected {q}",
            lambda.iter().cloned().fold(f64::INFINITY, f64::min),
            lambda.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
        );
        let w = solution.field(0);
        let largest = w
            .iter()
            .zip(&expected)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        println!("obstacle path: largest DOF error {largest:.2e} of {scale:.2e}");
        assert!(largest < 1e-9 * scale, "obstacle path: {largest}");
    }
}

/// Nonzero data on a simply supported plate, on the unit square rotated by 30° about
/// the origin (`ξ = c x + s y`, `η = −s x + c y` its own coordinates): the lift
/// `L = 0.2 + 0.5ξ − 0.3η + 0.4ξη` has no bending moment across the sides
/// (`M_nn(L) = 0`: `L_nn = 0` and `ΔL = 0` there), so with f = 0 and data `L` the plate
/// is `L` (in the Argyris space) to rounding; with `f = 4π⁴ sin πξ sin πη` it is
/// `sin πξ sin πη + L`, approached at N = 8 and 16 (centre relative errors measured
/// 9.3e-8 and 1.4e-9: O(h⁶); asked below 1e-8 at N = 16 and falling by more than 16).
#[test]
fn simply_supported_data_give_the_lifted_navier_plate() {
    type M = kirchhoff_argyris::Model;
    let angle = std::f64::consts::PI / 6.0;
    let (s, c) = angle.sin_cos();
    let xi = poly(&[(1, 0, c), (0, 1, s)]);
    let eta = poly(&[(1, 0, -s), (0, 1, c)]);
    let mut lift = product(&xi, &eta);
    lift.terms.iter_mut().for_each(|t| t.2 *= 0.4);
    lift.terms
        .extend(xi.terms.iter().map(|&(i, j, a)| (i, j, 0.5 * a)));
    lift.terms
        .extend(eta.terms.iter().map(|&(i, j, a)| (i, j, -0.3 * a)));
    lift.terms.push((0, 0, 0.2));
    let data = |x: [f64; 2]| jet(&lift, x);
    let pi = std::f64::consts::PI;
    let navier = move |x: [f64; 2]| {
        let (a, b) = (c * x[0] + s * x[1], -s * x[0] + c * x[1]);
        (pi * a).sin() * (pi * b).sin()
    };
    let solve = |n: usize, loaded: bool| {
        let square = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, n, n, Diagonal::Right).unwrap();
        let mesh = rotated(&square, angle, [0.0, 0.0]);
        let dofs = SystemDofs::new::<M>(&mesh, &[0]).unwrap();
        let load = move |x: &[f64]| {
            if loaded {
                4.0 * pi.powi(4) * navier([x[0], x[1]])
            } else {
                0.0
            }
        };
        let f: &DataFn = &load;
        let coefficients = Coefficients::new::<M>(&[("D", 1.0), ("ν", 0.3)], &[("f", f)]).unwrap();
        let mut constraints = Constraints::new();
        constraints
            .support_plate_with_data::<M>(
                &mesh,
                &dofs,
                "w",
                &DirichletPart::All,
                PlateSupport::SimplySupported,
                Some(&data),
            )
            .unwrap();
        let w = solve_linear::<M>(
            &mesh,
            &dofs,
            "a",
            "ℓ",
            &constraints,
            &coefficients,
            Factorization::Cholesky,
        )
        .unwrap();
        (w, mesh)
    };
    let (w, mesh) = solve(4, false);
    let map = DofMap::on_triangles(&mesh, ElementKind::Argyris);
    let expected = argyris_dofs(&map, &mesh, &lift);
    let largest = w
        .iter()
        .zip(&expected)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    println!("lift alone: largest DOF error {largest:.2e}");
    assert!(largest < 1e-10, "the lift is not reproduced: {largest}");
    let mut errors = Vec::new();
    for n in [8, 16] {
        let (w, mesh) = solve(n, true);
        let centre = [c * 0.5 - s * 0.5, s * 0.5 + c * 0.5];
        let v = mesh
            .vertices()
            .iter()
            .position(|p| (p[0] - centre[0]).abs() < 1e-12 && (p[1] - centre[1]).abs() < 1e-12)
            .unwrap();
        let map = DofMap::on_triangles(&mesh, ElementKind::Argyris);
        let exact = 1.0 + lift.eval(centre);
        let error = (w[map.vertex_dofs(v).start] - exact).abs() / exact;
        println!(
            "N = {n}: centre {:.10e}, exact {exact:.10e}, relative error {error:.2e}",
            w[map.vertex_dofs(v).start]
        );
        errors.push(error);
    }
    assert!(
        errors[1] < errors[0] && errors[1] < 1e-5,
        "errors {errors:?}"
    );
}

/// Supports per named part on the rotated square: clamped on left and right, simply
/// supported on top and bottom, each corner the union of a clamped and a simply
/// supported edge of different directions (rotated), bends as the unrotated square
/// (every vertex to 1e-9 of w_c), whose centre deflection is Timoshenko and
/// Woinowsky-Krieger's `0.00192 q a⁴/D` (Table 29, three digits; `tests/argyris.rs`).
#[test]
fn supports_per_part_on_the_rotated_square() {
    type M = kirchhoff_argyris::Model;
    let solve = |mesh: &TriangleMesh| {
        let dofs = SystemDofs::new::<M>(mesh, &[0]).unwrap();
        let load: &DataFn = &unit_load;
        let coefficients =
            Coefficients::new::<M>(&[("D", 1.0), ("ν", 0.3)], &[("f", load)]).unwrap();
        let mut constraints = Constraints::new();
        for (names, support) in [
            (["left", "right"], PlateSupport::Clamped),
            (["top", "bottom"], PlateSupport::SimplySupported),
        ] {
            let part = DirichletPart::Markers(mesh.boundary_part_markers(&names).unwrap());
            constraints
                .support_plate::<M>(mesh, &dofs, "w", &part, support)
                .unwrap();
        }
        let w = solve_linear::<M>(
            mesh,
            &dofs,
            "a",
            "ℓ",
            &constraints,
            &coefficients,
            Factorization::Cholesky,
        )
        .unwrap();
        vertex_values(&w, &dofs, mesh.vertex_count())
    };
    let square = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 8, 8, Diagonal::Right).unwrap();
    // the rotated copy keeps the markers; the names go with them
    let turned = rotated(&square, 0.7, [0.5, 0.5])
        .with_boundary_names(&[
            ("bottom", &[1]),
            ("right", &[2]),
            ("top", &[3]),
            ("left", &[4]),
        ])
        .unwrap();
    let reference = solve(&square);
    let values = solve(&turned);
    let centre = square
        .vertices()
        .iter()
        .position(|p| (p[0] - 0.5).abs() < 1e-12 && (p[1] - 0.5).abs() < 1e-12)
        .unwrap();
    let w_c = values[centre];
    let largest = reference
        .iter()
        .zip(&values)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    println!("per part, rotated by 0.7: w_c = {w_c:.8e}, largest vertex difference {largest:.2e}");
    assert!(largest < 1e-9 * w_c, "{largest}");
    assert!(((w_c - 0.00192) / 0.00192).abs() < 4e-3, "w_c = {w_c}");
}

/// Data that two parts ask differently at their shared corner are refused (naming the
/// vertex DOFs), as are data that are not finite (naming the point).
#[test]
fn contradictory_or_non_finite_plate_data_are_refused() {
    type M = kirchhoff_argyris::Model;
    let square = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 2, 2, Diagonal::Right).unwrap();
    let mesh = rotated(&square, 0.3, [0.5, 0.5]);
    let dofs = SystemDofs::new::<M>(&mesh, &[0]).unwrap();
    let one = |_: [f64; 2]| [1.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    let two = |_: [f64; 2]| [2.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    let mut constraints = Constraints::new();
    for (marker, data) in [(1, &one as &dyn Fn([f64; 2]) -> [f64; 6]), (2, &two)] {
        constraints
            .support_plate_with_data::<M>(
                &mesh,
                &dofs,
                "w",
                &DirichletPart::Markers(vec![marker]),
                PlateSupport::SimplySupported,
                Some(data),
            )
            .unwrap();
    }
    let message = constraints
        .reduction(dofs.dof_count())
        .unwrap_err()
        .to_string();
    assert!(message.contains("contradict"), "{message}");
    let bad = |_: [f64; 2]| [0.0, 0.0, 0.0, 0.0, 0.0, f64::NAN];
    let message = Constraints::new()
        .support_plate_with_data::<M>(
            &mesh,
            &dofs,
            "w",
            &DirichletPart::All,
            PlateSupport::Clamped,
            Some(&bad),
        )
        .unwrap_err()
        .to_string();
    assert!(message.contains("not finite"), "{message}");
}

/// An Argyris plate simply supported on two sides (`w = 0` there, imposed as rows over
/// each vertex's DOFs) above an obstacle `w ≥ 0.05`: no admissible deflection exists,
/// and the solve says so naming the point, as it does for Morley's fixed value DOFs.
#[test]
fn a_simple_support_below_the_obstacle_is_infeasible() {
    use fem_forms::problem::{Condition, Problem};
    use fem_forms::{Diagonal, DirichletPart, TriangleMesh};
    let (one, above, zero) = (|_: &[f64]| 1.0, |_: &[f64]| 0.05, |_: &[f64]| 0.0);
    let mesh = TriangleMesh::rectangle(0.0, 2.0, 0.0, 1.0, 4, 2, Diagonal::Right).unwrap();
    let Err(e) = Problem::<kirchhoff_argyris_p0::Model, TriangleMesh>::new(vec![mesh])
        .param("D", 1.0)
        .param("ν", 0.3)
        .data("f", &one)
        .data("ψ", &above)
        .data("g", &zero)
        .support(DirichletPart::Markers(vec![2, 4]), "w", Condition::Zero)
        .solve()
    else {
        panic!("a plate held at 0 below an obstacle at 0.05 was solved");
    };
    let message = e.to_string();
    assert!(message.contains("infeasible"), "{message}");
}
