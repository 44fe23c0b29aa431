//! Holding one component of a vector field on a boundary part
//! (`Constraints::hold_component`): the hard simple support's `θ·t = 0` and a roller's
//! `u·n = 0`. Checked as an identity: every vector the constrained basis can represent
//! (random free DOFs, the fixed ones at their values) satisfies the condition at every
//! node of the part, and exactly one condition is imposed per node where the boundary
//! is smooth (two at a corner, where the vector is then 0).
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

use fem_forms::assembly::boundary::ComponentDirection;
use fem_forms::models::vector_forms::rotation_shear::Model as M;
use fem_forms::{Constraints, Diagonal, DirichletPart, Model, SystemDofs, TriangleMesh};

/// A vector of the constrained space: the free primed DOFs pseudo-random, the fixed ones
/// at their values, mapped back to the Cartesian DOFs.
fn constrained_vector(constraints: &Constraints, n: usize) -> Vec<f64> {
    let reduction = constraints.reduction(n).unwrap();
    let basis = constraints.change_of_basis(n).unwrap();
    let mut x: Vec<f64> = (0..n)
        .map(|d| match reduction.free_index(d) {
            Some(k) => ((k * 7919 % 1000) as f64 / 500.0) - 1.0,
            None => reduction.fixed_value(d),
        })
        .collect();
    basis.to_cartesian(&mut x);
    x
}

/// `(boundary vertex, position)` of every boundary vertex.
fn boundary_vertices(mesh: &TriangleMesh) -> Vec<(usize, [f64; 2])> {
    let flags = DirichletPart::All.vertices(mesh);
    (0..mesh.vertex_count())
        .filter(|&v| flags[v])
        .map(|v| (v, mesh.vertices()[v]))
        .collect()
}

#[test]
fn a_roller_holds_the_component_along_its_direction_at_every_node() {
    let mesh = TriangleMesh::rectangle(0.0, 2.0, 0.0, 1.0, 6, 3, Diagonal::Right).unwrap();
    let dofs = SystemDofs::all::<M>(&mesh).unwrap();
    let [x, y] = [M::field("θ_x").unwrap(), M::field("θ_y").unwrap()];
    let bottom = DirichletPart::Markers(mesh.boundary_part_markers(&["bottom"]).unwrap());
    let n = [0.6, 0.8];
    let mut constraints = Constraints::new();
    constraints
        .hold_component(&mesh, &dofs, [x, y], &bottom, ComponentDirection::Fixed(n))
        .unwrap();
    let total = dofs.dof_count();
    let reduction = constraints.reduction(total).unwrap();
    let on_part = bottom.vertices(&mesh).iter().filter(|&&f| f).count();
    assert_eq!(total - reduction.free().len(), on_part);
    let u = constrained_vector(&constraints, total);
    let (ox, oy) = (dofs.offset(x).unwrap(), dofs.offset(y).unwrap());
    let map = dofs.map(x).unwrap();
    for (v, on) in bottom.vertices(&mesh).into_iter().enumerate() {
        let d = map.vertex_dofs(v).start;
        let along = n[0] * u[ox + d] + n[1] * u[oy + d];
        if on {
            assert!(along.abs() < 1e-14, "vertex {v}: {along}");
        } else {
            // away from the part the vector is free
            assert!(u[ox + d] != 0.0 || u[oy + d] != 0.0);
        }
    }
    // an axis fixes the single component DOF, no rotation
    let mut axis = Constraints::new();
    axis.hold_component(
        &mesh,
        &dofs,
        [x, y],
        &bottom,
        ComponentDirection::Fixed([0.0, 2.0]),
    )
    .unwrap();
    assert!(axis.change_of_basis(total).unwrap().is_identity());
    assert!(Constraints::new()
        .hold_component(
            &mesh,
            &dofs,
            [x, y],
            &bottom,
            ComponentDirection::Fixed([0.0, 0.0])
        )
        .is_err());
}

#[test]
fn the_tangential_component_vanishes_on_a_disk_and_at_square_corners() {
    // the disk: one condition per boundary vertex, along the circle's tangent
    let disk = TriangleMesh::disk([0.0, 0.0], 1.0, 4).unwrap();
    let dofs = SystemDofs::all::<M>(&disk).unwrap();
    let [x, y] = [M::field("θ_x").unwrap(), M::field("θ_y").unwrap()];
    let mut constraints = Constraints::new();
    constraints
        .hold_component(
            &disk,
            &dofs,
            [x, y],
            &DirichletPart::All,
            ComponentDirection::Tangent,
        )
        .unwrap();
    let total = dofs.dof_count();
    let boundary = boundary_vertices(&disk);
    let reduction = constraints.reduction(total).unwrap();
    assert_eq!(total - reduction.free().len(), boundary.len());
    let u = constrained_vector(&constraints, total);
    let (ox, oy) = (dofs.offset(x).unwrap(), dofs.offset(y).unwrap());
    let map = dofs.map(x).unwrap();
    for &(v, p) in &boundary {
        let d = map.vertex_dofs(v).start;
        let tangent = [-p[1], p[0]];
        let along = tangent[0] * u[ox + d] + tangent[1] * u[oy + d];
        assert!(along.abs() < 1e-12, "vertex {v} at {p:?}: {along}");
        // the normal component stays free
        assert!((p[0] * u[ox + d] + p[1] * u[oy + d]).abs() > 1e-6);
    }
    // the square: single DOFs along the sides, both at the four corners
    let square = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 4, 4, Diagonal::Right).unwrap();
    let dofs = SystemDofs::all::<M>(&square).unwrap();
    let mut constraints = Constraints::new();
    constraints
        .hold_component(
            &square,
            &dofs,
            [x, y],
            &DirichletPart::All,
            ComponentDirection::Tangent,
        )
        .unwrap();
    let total = dofs.dof_count();
    assert!(constraints.change_of_basis(total).unwrap().is_identity());
    let fixed = total - constraints.reduction(total).unwrap().free().len();
    assert_eq!(fixed, boundary_vertices(&square).len() + 4);
}
