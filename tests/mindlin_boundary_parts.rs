//! Boundary conditions per field and part (`solve_obstacle_on_field_parts`): one
//! Reissner–Mindlin plate (`mindlin_stenberg`, docs/mathematics.md §9) clamped on some
//! sides and simply supported on the others, in one solve.
//!
//! The unit square clamped on x = 0 and x = 1 (θ = 0, w = 0) and simply supported on
//! y = 0 and y = 1 (w = 0, θ free: the "soft" support), D = 1, ν = 0.3, κ = 5/6, uniform
//! load q = 1, t = 1e-3, no contact (ψ far below). As t → 0 its centre deflection tends to
//! the Kirchhoff value for two opposite clamped and two simply supported edges,
//! `0.00191714 q a⁴/D` (Timoshenko & Woinowsky-Krieger tabulate 0.00192 for b/a = 1;
//! 1.91714e-3 with our Argyris elements). It lies between the fully clamped (1.26532e-3)
//! and the fully simply supported (4.06235e-3) values, so a support on the wrong sides
//! or on the wrong fields cannot pass.
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

use fem_forms::element::triangle::TriangleBasis;
use fem_forms::models::mindlin::mindlin_stenberg;
use fem_forms::obstacle::triangle::{
    dirichlet_constraints_per_field, solve_obstacle_on_field_parts, solve_obstacle_on_triangles,
    TriangleObstacleSolution,
};
use fem_forms::obstacle::ObstacleOptions;
use fem_forms::{
    Coefficients, Diagonal, DirichletPart, Model, PointLocator, SystemDofs, TriangleMesh,
};

type M = mindlin_stenberg::Model;

/// `(field, part)` pairs, as `solve_obstacle_on_field_parts` takes them.
type FieldParts = Vec<(&'static str, DirichletPart)>;

/// Kirchhoff centre deflection, two opposite edges clamped and two simply supported, in
/// `q a⁴/D`.
const KIRCHHOFF_MIXED: f64 = 0.00191714;
/// The same, all edges clamped and all simply supported (tests/mindlin.rs).
const KIRCHHOFF_CLAMPED: f64 = 0.00126532;
const KIRCHHOFF_SIMPLY_SUPPORTED: f64 = 0.00406235;

fn unit_load(_: &[f64]) -> f64 {
    1.0
}

fn far_below(_: &[f64]) -> f64 {
    -10.0
}

fn zero(_: &[f64]) -> f64 {
    0.0
}

fn coefficients() -> Coefficients<'static> {
    let params = [
        ("D", 1.0),
        ("ν", 0.3),
        ("κ", 5.0 / 6.0),
        ("t", 1e-3),
        ("β", 0.1),
        ("α", 0.1),
        ("s", 1.0),
    ];
    Coefficients::new::<M>(
        &params,
        &[("f", &unit_load), ("ψ", &far_below), ("g", &zero)],
    )
    .unwrap()
}

fn square(n: usize) -> TriangleMesh {
    TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, n, n, Diagonal::Right).unwrap()
}

/// The part named `names` on the generator square (the same markers on every N).
fn part(names: &[&str]) -> DirichletPart {
    DirichletPart::Markers(square(2).boundary_part_markers(names).unwrap())
}

/// Clamped on `clamped` (θ and w fixed), simply supported on `supported` (w only).
fn mixed_parts(clamped: &[&str], supported: &[&str]) -> FieldParts {
    let all: Vec<&str> = clamped.iter().chain(supported).copied().collect();
    vec![
        ("θ_x", part(clamped)),
        ("θ_y", part(clamped)),
        ("w", part(&all)),
    ]
}

fn solve(n: usize, parts: &[(&str, DirichletPart)]) -> TriangleObstacleSolution {
    let c = coefficients();
    let solution =
        solve_obstacle_on_field_parts::<M>(&[square(n)], &c, parts, ObstacleOptions::default())
            .unwrap();
    assert_eq!(solution.total_contact_force(), 0.0, "no contact expected");
    solution
}

fn value_at(solution: &TriangleObstacleSolution, field: &str, x: [f64; 2]) -> f64 {
    let view = solution.view(M::field(field).unwrap());
    let basis = TriangleBasis::new(view.map.element());
    view.at(&basis, &PointLocator::new(view.mesh), x).unwrap()
}

/// The largest |value| of `field`'s DOFs whose nodes satisfy `on`.
fn largest_on(
    solution: &TriangleObstacleSolution,
    field: &str,
    on: impl Fn([f64; 2]) -> bool,
) -> f64 {
    let view = solution.view(M::field(field).unwrap());
    view.map
        .nodes(view.mesh)
        .iter()
        .zip(view.coefficients)
        .filter(|(x, _)| on(**x))
        .fold(0.0, |m, (_, v)| m.max(v.abs()))
}

/// Clamped on x = 0, 1 and simply supported on y = 0, 1 at t = 1e-3: the centre
/// deflection converges to the Kirchhoff value at about O(h²) (error ratio ≥ 3 per
/// halving of h; 4 is O(h²)), below 1 % at N = 32 and 0.3 % at N = 64; the conditions
/// hold on exactly their sides (θ = 0 on the clamped sides, w = 0 on all four, θ free
/// on the simply supported ones).
#[test]
fn clamped_and_simply_supported_sides_in_one_solve_tend_to_kirchhoff() {
    let parts = mixed_parts(&["left", "right"], &["bottom", "top"]);
    let ns = [8, 16, 32, 64];
    let mut errors = Vec::new();
    for &n in &ns {
        let solution = solve(n, &parts);
        let w = value_at(&solution, "w", [0.5, 0.5]);
        let error = (w - KIRCHHOFF_MIXED) / KIRCHHOFF_MIXED;
        eprintln!("N = {n:>2}: w(½,½) = {w:.8e}, relative error {error:+.3e}");
        errors.push(error.abs());
        let on_x_sides = |x: [f64; 2]| x[0] == 0.0 || x[0] == 1.0;
        let on_y_sides = |x: [f64; 2]| x[1] == 0.0 || x[1] == 1.0;
        for field in ["θ_x", "θ_y"] {
            assert_eq!(
                largest_on(&solution, field, on_x_sides),
                0.0,
                "{field} on x = 0, 1"
            );
        }
        let w_boundary = largest_on(&solution, "w", |x| on_x_sides(x) || on_y_sides(x));
        assert_eq!(w_boundary, 0.0, "w on the boundary");
        // the soft support leaves the rotation free: θ_y = ∂w/∂y ≠ 0 along y = 0, 1
        let theta_y = largest_on(&solution, "θ_y", on_y_sides);
        assert!(
            theta_y > 1e-3,
            "N = {n}: θ_y on y = 0, 1 is at most {theta_y}"
        );
    }
    for (k, pair) in errors.windows(2).enumerate() {
        assert!(
            pair[0] >= 3.0 * pair[1],
            "N = {} → {}: errors {errors:?}",
            ns[k],
            ns[k + 1]
        );
    }
    assert!(errors[2] < 1e-2, "N = 32: error {}", errors[2]);
    assert!(errors[3] < 3e-3, "N = 64: error {}", errors[3]);
}

/// The same plate turned by 90° (clamped on y = 0, 1): the same problem up to the
/// reflection `x ↔ y`, which maps the mesh onto itself, so the same centre deflection.
/// And every field on the whole boundary is the fully clamped plate of
/// `solve_obstacle_on_triangles`, DOF for DOF; neither is the mixed value.
#[test]
fn the_parts_decide_the_solution() {
    let n = 16;
    let mixed = value_at(
        &solve(n, &mixed_parts(&["left", "right"], &["bottom", "top"])),
        "w",
        [0.5, 0.5],
    );
    let turned = value_at(
        &solve(n, &mixed_parts(&["bottom", "top"], &["left", "right"])),
        "w",
        [0.5, 0.5],
    );
    assert!(
        (mixed - turned).abs() <= 1e-10 * mixed,
        "clamped on x sides {mixed}, on y sides {turned}"
    );
    let everywhere = mixed_parts(&["left", "right", "bottom", "top"], &[]);
    let clamped = solve(n, &everywhere);
    let reference =
        solve_obstacle_on_triangles::<M>(&[square(n)], &coefficients(), ObstacleOptions::default())
            .unwrap();
    let largest = clamped
        .values
        .iter()
        .zip(&reference.values)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(largest <= 1e-14, "largest difference {largest}");
    let w_clamped = value_at(&clamped, "w", [0.5, 0.5]);
    // only w fixed everywhere: the soft simply supported plate
    let soft = value_at(&solve(n, &[("w", DirichletPart::All)]), "w", [0.5, 0.5]);
    for (name, w, kirchhoff) in [
        ("clamped", w_clamped, KIRCHHOFF_CLAMPED),
        ("simply supported", soft, KIRCHHOFF_SIMPLY_SUPPORTED),
    ] {
        assert!(
            (w - kirchhoff).abs() <= 0.05 * kirchhoff && (w - mixed).abs() >= 0.2 * mixed,
            "{name}: w(½,½) = {w}, Kirchhoff {kirchhoff}, mixed {mixed}"
        );
    }
}

/// Bad lists are errors naming the field at fault, never a solve.
#[test]
fn bad_field_parts_are_refused_with_clear_messages() {
    let mesh = square(4);
    let dofs = SystemDofs::all::<M>(&mesh).unwrap();
    let c = coefficients();
    let left = part(&["left"]);
    let cases: Vec<(FieldParts, &[&str])> = vec![
        (vec![], &["no field", "θ_x = g", "w = g"]),
        (
            vec![("φ", left.clone())],
            &["`φ`", "no such field", "`w = g`"],
        ),
        (vec![("λ", left.clone())], &["`λ`", "no boundary condition"]),
        (
            vec![
                ("w", left.clone()),
                ("θ_x", left.clone()),
                ("w", DirichletPart::All),
            ],
            &["`w`", "twice"],
        ),
        (
            vec![
                ("w", DirichletPart::All),
                ("θ_y", DirichletPart::Markers(vec![9])),
            ],
            &["`θ_y`", "[9]", "none of the mesh's 16 boundary edges"],
        ),
    ];
    for (parts, words) in cases {
        let e = match dirichlet_constraints_per_field::<M>(&mesh, &dofs, &c, &parts) {
            Ok(_) => panic!("{parts:?} was accepted"),
            Err(e) => e.to_string(),
        };
        assert!(words.iter().all(|w| e.contains(w)), "{parts:?}: {e}");
        // and the solve refuses it the same way
        let solved = solve_obstacle_on_field_parts::<M>(
            std::slice::from_ref(&mesh),
            &c,
            &parts,
            ObstacleOptions::default(),
        );
        assert!(solved.is_err(), "{parts:?} was solved");
    }
    // a part name the mesh does not have is refused where it becomes markers
    let e = mesh
        .boundary_part_markers(&["outer"])
        .unwrap_err()
        .to_string();
    assert!(e.contains("`outer`") && e.contains("`left`"), "{e}");
}
