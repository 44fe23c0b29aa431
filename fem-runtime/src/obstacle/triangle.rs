//! Obstacle problems on triangle meshes: the model's Dirichlet data (`boundary:`)
//! interpolated at the boundary DOFs (of the whole boundary or of a [`DirichletPart`],
//! the rest natural), nested iteration over a sequence of meshes, the
//! classical nodal-constraint method for comparison, and the solution's contact force
//! and contact area.

use crate::assembly::boundary::{Constraints, DirichletPart, PlateSupport};
use crate::assembly::dof_map::{DofMap, SystemDofs};
use crate::element::triangle::{AffineMap, TriangleBasis, TriangleField};
use crate::error::{Error, Result};
use crate::lcp::Lcp;
use crate::mesh::triangle::{CurvedTriangleMesh, PointLocator, QuadraticGeometry, TriangleMesh};
use crate::model::{Coefficients, IntoFormIndex, Model};
pub use crate::obstacle::nodal::{nodal_active_set, nodal_active_set_with, nodal_lcp};
use crate::obstacle::{
    solve_nested, solve_nested_on_hierarchy, system_forms, Discretization, ObstacleOptions,
    ObstacleSolution,
};

/// The fixed DOFs of the model's `boundary:` conditions on the whole boundary: each
/// field's boundary DOFs get its data function's value at their nodes.
pub fn dirichlet_constraints<M: Model>(
    mesh: &TriangleMesh,
    dofs: &SystemDofs,
    coefficients: &Coefficients,
) -> Result<Constraints> {
    dirichlet_constraints_on::<M>(mesh, dofs, coefficients, &DirichletPart::All)
}

/// The fixed DOFs of the model's `boundary:` conditions on `part` of the boundary
/// ([`DirichletPart::dofs`]: for P2 the midpoints of its edges, and the vertices where
/// it meets the rest, are fixed); the rest of the boundary gets the form's natural
/// condition. For a plate field (Argyris, Morley) `w = g` is the simple support with
/// `g = 0` ([`DirichletPart::plate_dofs`]); a clamped plate is supported with
/// [`Constraints::support_plate`].
///
/// # Errors
/// [`Error::Input`] when the model has a `boundary:` condition and `part` holds no
/// boundary edge of the mesh (a problem with natural conditions only, which the
/// membrane does not determine: u + constant solves it wherever contact does not hold
/// it), for boundary data that is not finite at a node, and for a plate field: data
/// that is not zero at a vertex of the part.
pub fn dirichlet_constraints_on<M: Model>(
    mesh: &TriangleMesh,
    dofs: &SystemDofs,
    coefficients: &Coefficients,
    part: &DirichletPart,
) -> Result<Constraints> {
    constraints_at_nodes::<M>(mesh, dofs, coefficients, part, &|map| map.nodes(mesh))
}

/// [`dirichlet_constraints_on`] on a curved mesh: the data are interpolated at the
/// nodes of the isoparametric DOFs ([`DofMap::curved_nodes`]), so the P2 DOF of a
/// curved boundary edge gets the data's value at the geometry's edge node (on the exact
/// boundary for [`QuadraticGeometry::circle`]), not at the straight edge's midpoint.
///
/// # Errors
/// As [`dirichlet_constraints_on`].
pub fn curved_dirichlet_constraints_on<M: Model>(
    mesh: &CurvedTriangleMesh,
    dofs: &SystemDofs,
    coefficients: &Coefficients,
    part: &DirichletPart,
) -> Result<Constraints> {
    constraints_at_nodes::<M>(mesh.mesh(), dofs, coefficients, part, &|map| {
        map.curved_nodes(mesh)
    })
}

/// An error when a connected piece of `mesh` holds no vertex of the Dirichlet `part`:
/// on that piece the natural condition holds on its whole boundary, which does not
/// determine the solution (two squares, one held, one free under f = 1 and a
/// far obstacle: u ≈ 6e15 on the free one, KKT residual 2e-16, no warning), as the
/// whole mesh without a Dirichlet part does not.
fn unheld_piece(mesh: &TriangleMesh, part: &DirichletPart) -> Result<()> {
    let (piece, count) = mesh.cell_pieces();
    if count < 2 {
        return Ok(());
    }
    // held by an edge of the part: a vertex alone holds nothing in H¹
    let mut held = vec![false; count];
    for &(e, marker) in mesh.boundary_edges() {
        if part.contains(marker) {
            held[piece[mesh.edge_cells(e).0]] = true;
        }
    }
    let Some(free) = held.iter().position(|&h| !h) else {
        return Ok(());
    };
    let cells: Vec<usize> = (0..piece.len()).filter(|&c| piece[c] == free).collect();
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for &c in &cells {
        for v in mesh.cell(c) {
            let x = mesh.vertices()[v];
            for k in 0..2 {
                lo[k] = lo[k].min(x[k]);
                hi[k] = hi[k].max(x[k]);
            }
        }
    }
    Err(Error::Input(format!(
        "the mesh falls into {count} pieces joined by no edge, and the piece of {} cells within [{}, {}] × [{}, {}] has no edge on the Dirichlet boundary (markers {}): with the natural condition on all of its boundary (a shared vertex holds nothing) the problem is not coercive there (u + constant solves it wherever contact does not hold it); give that piece a Dirichlet part, or mesh the domain as one piece (in Gmsh, a coherent geometry)",
        cells.len(),
        lo[0],
        hi[0],
        lo[1],
        hi[1],
        match part {
            DirichletPart::All => "all".to_string(),
            // the names the user chose, where the mesh has them (markers of edges in
            // several Gmsh groups are numbers of the reader's own)
            DirichletPart::Markers(m) => {
                let names: Vec<String> = mesh
                    .named_groups()
                    .iter()
                    .filter(|g| g.dimension == 1 && g.markers.iter().any(|k| m.contains(k)))
                    .map(|g| format!("`{}`", g.name))
                    .collect();
                if names.is_empty() {
                    format!("{m:?}")
                } else {
                    format!("{m:?}, of the groups {}", names.join(", "))
                }
            }
        },
    )))
}

/// The body of [`dirichlet_constraints_on`], with the DOF nodes of each field's map
/// given by `nodes`.
fn constraints_at_nodes<M: Model>(
    mesh: &TriangleMesh,
    dofs: &SystemDofs,
    coefficients: &Coefficients,
    part: &DirichletPart,
    nodes: &dyn Fn(&DofMap) -> Vec<[f64; 2]>,
) -> Result<Constraints> {
    let mut constraints = Constraints::new();
    if !M::DIRICHLET.is_empty() && part.edge_count(mesh) == 0 {
        return Err(Error::Input(format!(
            "the Dirichlet part of the boundary (markers {}) holds none of the mesh's {} boundary edges: with the natural condition on the whole boundary the problem is not coercive (u + constant solves it wherever contact does not hold it); choose at least one boundary part for `{}`",
            match part {
                DirichletPart::All => "all".to_string(),
                DirichletPart::Markers(m) => format!("{m:?}"),
            },
            mesh.boundary_edges().len(),
            M::DIRICHLET
                .iter()
                .map(|&(f, d)| format!("{} = {}", M::FIELDS[f].name, M::DATA[d]))
                .collect::<Vec<_>>()
                .join(", ")
        )));
    }
    if !M::DIRICHLET.is_empty() {
        unheld_piece(mesh, part)?;
    }
    for &(field, data) in M::DIRICHLET {
        let (Some(map), Some(offset)) = (dofs.map(field), dofs.offset(field)) else {
            continue;
        };
        if map.element().needs_transformation() {
            // A plate (Argyris, Morley): `w = g` on the part is the simple support,
            // which fixes derivative DOFs too (DirichletPart::plate_dofs); homogeneous
            // only, so g must vanish on the part (checked at its vertices).
            let vertices = part.vertices(mesh);
            let g = coefficients.data[data];
            let on_part = mesh.vertices().iter().zip(&vertices).filter(|(_, &on)| on);
            for (x, _) in on_part {
                let value = g(x);
                if value != 0.0 {
                    return Err(Error::Input(format!(
                        "boundary data `{}` of `{}` is {value} at ({}, {}): plate boundary conditions from a model's `boundary:` data on {} fields are homogeneous (w = 0): they fix derivatives of w, which a data function does not give; hold the plate with Constraints::support_plate_with_data, which takes the data's derivatives",
                        M::DATA[data],
                        M::FIELDS[field].name,
                        x[0],
                        x[1],
                        map.element().name()
                    )));
                }
            }
            constraints.support_plate_field(
                mesh,
                map,
                offset,
                part,
                PlateSupport::SimplySupported,
            )?;
            continue;
        }
        let nodes = nodes(map);
        let g = coefficients.data[data];
        for dof in part.dofs(map, mesh) {
            let x = nodes[dof];
            let value = g(&x);
            if !value.is_finite() {
                return Err(Error::Input(format!(
                    "boundary data `{}` of `{}` is {value} at ({}, {})",
                    M::DATA[data],
                    M::FIELDS[field].name,
                    x[0],
                    x[1]
                )));
            }
            constraints.fix_dof(offset + dof, value)?;
        }
    }
    Ok(constraints)
}

/// Assembles `bilinear`, `linear` (normally `B_h`, `L_h`) of `M` on a triangle mesh with
/// the model's Dirichlet data on the whole boundary, as an LCP.
pub fn discretize_on_triangles<M: Model>(
    mesh: &TriangleMesh,
    coefficients: &Coefficients,
    bilinear: impl IntoFormIndex<M>,
    linear: impl IntoFormIndex<M>,
) -> Result<Discretization<TriangleMesh>> {
    discretize_on_part::<M>(mesh, coefficients, &DirichletPart::All, bilinear, linear)
}

/// [`discretize_on_triangles`] with the Dirichlet data on `part` of the boundary only
/// (errors: as [`dirichlet_constraints_on`]).
pub fn discretize_on_part<M: Model>(
    mesh: &TriangleMesh,
    coefficients: &Coefficients,
    part: &DirichletPart,
    bilinear: impl IntoFormIndex<M>,
    linear: impl IntoFormIndex<M>,
) -> Result<Discretization<TriangleMesh>> {
    let dofs = SystemDofs::all::<M>(mesh)?;
    let constraints = dirichlet_constraints_on::<M>(mesh, &dofs, coefficients, part)?;
    Discretization::with_constraints::<M>(mesh, coefficients, dofs, &constraints, bilinear, linear)
}

/// Interpolates every field of `coarse_values` (on `coarse`) at the DOF nodes of `fine`
/// (a start for nested iteration; a node outside the coarse mesh, as a refined disk's
/// boundary nodes are, takes the polynomial of the nearest coarse cell continued to it).
pub fn prolong_on_triangles(
    coarse: &Discretization<TriangleMesh>,
    coarse_values: &[f64],
    fine: &Discretization<TriangleMesh>,
) -> Vec<f64> {
    prolong_fields(coarse, coarse_values, fine, true)
}

/// [`prolong_on_triangles`] for the primal fields only, the multiplier left 0: all that
/// nested iteration uses (Newton starts from the primal unknowns; it eliminates Λ), and
/// for P0 multipliers the larger half of the work.
pub fn prolong_primal_on_triangles(
    coarse: &Discretization<TriangleMesh>,
    coarse_values: &[f64],
    fine: &Discretization<TriangleMesh>,
) -> Vec<f64> {
    prolong_fields(coarse, coarse_values, fine, false)
}

/// Argyris and Morley: the fine DOFs are the physical functionals of the coarse field
/// (values, gradients and Hessians at the vertices, normal derivatives at the edge
/// midpoints along the normal of the edge oriented from its lower to its higher global
/// vertex, docs/elements.md), not values at nodes. A nested space reproduces the coarse
/// field exactly.
fn prolong_c1(
    view: &TriangleField,
    basis: &TriangleBasis,
    locator: &PointLocator,
    fine: &Discretization<TriangleMesh>,
    map_f: &DofMap,
    out: &mut [f64],
) {
    let mesh = &fine.mesh;
    let [per_vertex, _, _] = map_f.element().triangle_layout();
    let mut hint = None;
    let mut evaluate = |x: [f64; 2]| {
        let (c, b) = locator.locate_or_nearest(x, hint)?;
        hint = Some(c);
        let map = AffineMap::of(view.mesh, c);
        let xi = [b[1], b[2]];
        Some((
            view.value(basis, c, xi),
            view.gradient(basis, &map, c, xi),
            view.hessian(basis, &map, c, xi),
        ))
    };
    for c in 0..mesh.cell_count() {
        let dofs = map_f.cell_dofs(c);
        let cell = mesh.cell(c);
        for (i, &v) in cell.iter().enumerate() {
            let Some((u, g, h)) = evaluate(mesh.vertices()[v]) else {
                continue;
            };
            let functionals = [u, g[0], g[1], h[0][0], h[0][1], h[1][1]];
            for (k, value) in functionals.iter().take(per_vertex).enumerate() {
                out[dofs[per_vertex * i + k]] = *value;
            }
        }
        for k in 0..3 {
            let (a, b) = (cell[k], cell[(k + 1) % 3]);
            let (a, b) = (a.min(b), a.max(b));
            let (pa, pb) = (mesh.vertices()[a], mesh.vertices()[b]);
            let length = (pb[0] - pa[0]).hypot(pb[1] - pa[1]);
            let t = [(pb[0] - pa[0]) / length, (pb[1] - pa[1]) / length];
            let normal = [t[1], -t[0]];
            let midpoint = [(pa[0] + pb[0]) / 2.0, (pa[1] + pb[1]) / 2.0];
            if let Some((_, g, _)) = evaluate(midpoint) {
                out[dofs[3 * per_vertex + k]] = g[0] * normal[0] + g[1] * normal[1];
            }
        }
    }
}

fn prolong_fields(
    coarse: &Discretization<TriangleMesh>,
    coarse_values: &[f64],
    fine: &Discretization<TriangleMesh>,
    multiplier: bool,
) -> Vec<f64> {
    let locator = PointLocator::new(&coarse.mesh);
    let mut out = vec![0.0; fine.dofs.dof_count()];
    for &field in fine.dofs.fields() {
        if !multiplier && field == fine.multiplier_field {
            continue;
        }
        let (Some(map_c), Some(range_c)) = (coarse.dofs.map(field), coarse.dofs.range(field))
        else {
            continue;
        };
        let view = TriangleField {
            mesh: &coarse.mesh,
            map: map_c,
            coefficients: &coarse_values[range_c],
        };
        let basis = TriangleBasis::new(map_c.element());
        let map_f = fine.dofs.map(field).unwrap();
        let offset = fine.dofs.offset(field).unwrap();
        if map_f.element().needs_transformation() {
            prolong_c1(&view, &basis, &locator, fine, map_f, &mut out[offset..]);
            continue;
        }
        let mut hint = None;
        for (dof, x) in map_f.nodes(&fine.mesh).into_iter().enumerate() {
            out[offset + dof] = match locator.locate_or_nearest(x, hint) {
                Some((c, b)) => {
                    hint = Some(c);
                    view.value(&basis, c, [b[1], b[2]])
                }
                None => 0.0,
            };
        }
    }
    out
}

/// A solved obstacle problem on a triangle mesh.
pub type TriangleObstacleSolution = ObstacleSolution<TriangleMesh>;

/// Solves the obstacle problem `B_h`, `L_h` of `M` on the last of `meshes`, each mesh
/// started from the solution on the one before (nested iteration), with the Dirichlet
/// data on the whole boundary.
pub fn solve_obstacle_on_triangles<M: Model>(
    meshes: &[TriangleMesh],
    coefficients: &Coefficients,
    options: ObstacleOptions,
) -> Result<TriangleObstacleSolution> {
    solve_obstacle_on_part::<M>(meshes, coefficients, &DirichletPart::All, options)
}

/// [`solve_obstacle_on_triangles`] with the Dirichlet data on `part` of the boundary
/// only. The part is given by markers, which refined meshes inherit from their parent
/// edges ([`TriangleMesh::refine`]), so it is the same part on every level.
pub fn solve_obstacle_on_part<M: Model>(
    meshes: &[TriangleMesh],
    coefficients: &Coefficients,
    part: &DirichletPart,
    options: ObstacleOptions,
) -> Result<TriangleObstacleSolution> {
    let (bilinear, linear) = system_forms::<M>()?;
    solve_nested_on_hierarchy(
        meshes
            .iter()
            .map(|mesh| move || discretize_on_part::<M>(mesh, coefficients, part, bilinear, linear))
            .collect(),
        prolong_primal_on_triangles,
        Some(&super::hierarchy::primal_prolongation),
        options,
    )
}

/// A solved obstacle problem on a curved triangle mesh.
pub type CurvedObstacleSolution = ObstacleSolution<CurvedTriangleMesh>;

/// Refuses a model whose elements need a per-cell DOF transformation (Argyris, Morley):
/// it is defined on affine cells only.
fn check_curved_model<M: Model>() -> Result<()> {
    match M::FIELDS
        .iter()
        .find(|f| f.element.needs_transformation())
    {
        Some(f) => Err(Error::Input(format!(
            "model `{}`: field `{}` ({}) needs a per-cell DOF transformation, which is defined on affine cells only; curved (isoparametric) cells take Lagrange elements",
            M::NAME,
            f.name,
            f.element.name()
        ))),
        None => Ok(()),
    }
}

/// Assembles `bilinear`, `linear` (normally `B_h`, `L_h`) of `M` on a curved mesh, with
/// the Dirichlet data on `part` interpolated at the isoparametric nodes
/// ([`curved_dirichlet_constraints_on`]), as an LCP. Curved cells take the curved
/// kernels, the others the affine ones.
///
/// # Errors
/// A model with Argyris or Morley fields, and those of [`dirichlet_constraints_on`] and
/// [`Discretization::with_constraints`].
pub fn discretize_on_curved_part<M: Model>(
    mesh: &CurvedTriangleMesh,
    coefficients: &Coefficients,
    part: &DirichletPart,
    bilinear: impl IntoFormIndex<M>,
    linear: impl IntoFormIndex<M>,
) -> Result<Discretization<CurvedTriangleMesh>> {
    check_curved_model::<M>()?;
    let dofs = SystemDofs::all::<M>(mesh)?;
    let constraints = curved_dirichlet_constraints_on::<M>(mesh, &dofs, coefficients, part)?;
    Discretization::with_constraints::<M>(mesh, coefficients, dofs, &constraints, bilinear, linear)
}

/// The primal fields of `coarse_values` on the curved mesh `coarse` interpolated at the
/// isoparametric DOF nodes of `fine`, the multiplier left 0: a start for nested
/// iteration. The coarse field is evaluated in the straight cell that holds the node
/// (exact on affine cells, O(h²)-close on curved ones: a start needs no more); a node
/// outside the coarse polygon, on the arc, takes the nearest straight cell's polynomial
/// continued to it.
pub fn prolong_primal_on_curved(
    coarse: &Discretization<CurvedTriangleMesh>,
    coarse_values: &[f64],
    fine: &Discretization<CurvedTriangleMesh>,
) -> Vec<f64> {
    let locator = PointLocator::new(coarse.mesh.mesh());
    let mut out = vec![0.0; fine.dofs.dof_count()];
    for &field in fine.dofs.fields() {
        if field == fine.multiplier_field {
            continue;
        }
        let (Some(map_c), Some(range_c)) = (coarse.dofs.map(field), coarse.dofs.range(field))
        else {
            continue;
        };
        let view = TriangleField {
            mesh: coarse.mesh.mesh(),
            map: map_c,
            coefficients: &coarse_values[range_c],
        };
        let basis = TriangleBasis::new(map_c.element());
        let map_f = fine.dofs.map(field).unwrap();
        let offset = fine.dofs.offset(field).unwrap();
        let mut hint = None;
        for (dof, x) in map_f.curved_nodes(&fine.mesh).into_iter().enumerate() {
            if let Some((c, b)) = locator.locate_or_nearest(x, hint) {
                hint = Some(c);
                out[offset + dof] = view.value(&basis, c, [b[1], b[2]]);
            }
        }
    }
    out
}

/// Solves the obstacle problem `B_h`, `L_h` of `M` on curved triangles: `meshes[k]` with
/// the quadratic geometry `geometries[k]` (one per mesh, built for it; refined disks get
/// theirs from [`QuadraticGeometry::circle`]), each level started from the one before
/// (nested iteration, [`prolong_primal_on_curved`]), the Dirichlet data on the whole
/// boundary at the isoparametric nodes. Cells whose edge nodes are their edge midpoints
/// keep the affine kernels; the others take the curved ones (docs/mathematics.md §8).
///
/// The solution's [`ObstacleSolution::energy`] is assembled on the curved cells as the
/// system was; [`ObstacleSolution::total_contact_force`] and
/// [`ObstacleSolution::contact_area`] of a [`CurvedObstacleSolution`] integrate over them.
///
/// # Errors
/// Meshes and geometries of different counts, a geometry not built for its mesh, a
/// model with Argyris or Morley fields, and those of [`solve_obstacle_on_triangles`].
pub fn solve_obstacle_on_curved_triangles<M: Model>(
    meshes: &[TriangleMesh],
    geometries: &[QuadraticGeometry],
    coefficients: &Coefficients,
    options: ObstacleOptions,
) -> Result<CurvedObstacleSolution> {
    solve_obstacle_on_curved_part::<M>(
        meshes,
        geometries,
        coefficients,
        &DirichletPart::All,
        options,
    )
}

/// [`solve_obstacle_on_curved_triangles`] with the Dirichlet data on `part` of the
/// boundary only (as [`solve_obstacle_on_part`]).
///
/// # Errors
/// As [`solve_obstacle_on_curved_triangles`].
pub fn solve_obstacle_on_curved_part<M: Model>(
    meshes: &[TriangleMesh],
    geometries: &[QuadraticGeometry],
    coefficients: &Coefficients,
    part: &DirichletPart,
    options: ObstacleOptions,
) -> Result<CurvedObstacleSolution> {
    if meshes.len() != geometries.len() {
        return Err(Error::Input(format!(
            "{} meshes and {} quadratic geometries: give one geometry per mesh",
            meshes.len(),
            geometries.len()
        )));
    }
    check_curved_model::<M>()?;
    let (bilinear, linear) = system_forms::<M>()?;
    let curved = meshes
        .iter()
        .zip(geometries)
        .enumerate()
        .map(|(k, (mesh, geometry))| {
            CurvedTriangleMesh::new(mesh.clone(), geometry.clone())
                .map_err(|e| Error::Input(format!("level {k}: {e}")))
        })
        .collect::<Result<Vec<_>>>()?;
    solve_nested(
        curved
            .iter()
            .map(|mesh| {
                move || discretize_on_curved_part::<M>(mesh, coefficients, part, bilinear, linear)
            })
            .collect(),
        prolong_primal_on_curved,
        options,
    )
}

impl ObstacleSolution<CurvedTriangleMesh> {
    /// A view of model field `field` on the mesh of the vertices. Its value at
    /// reference point `ξ` of cell `c` (`TriangleField::value`) is the isoparametric
    /// field's at the physical point `x(ξ)` of the cell's six-node map
    /// (`discretization.mesh.cell_map(c)`); `TriangleField::at` and the norms locate and
    /// integrate in the straight cells, which is exact on affine cells only.
    pub fn view(&self, field: usize) -> TriangleField<'_> {
        TriangleField {
            mesh: self.discretization.mesh.mesh(),
            map: self.discretization.dofs.map(field).unwrap(),
            coefficients: self.field(field),
        }
    }

    /// `∫ λ_h` over the curved cells: the total contact force (each cell's
    /// `Σ_q w_q |det J(ξ_q)| λ_h(ξ_q)` with a rule exact for the multiplier's degree + 2,
    /// which `det J` needs).
    pub fn total_contact_force(&self) -> f64 {
        let d = &self.discretization;
        let view = self.view(d.multiplier_field);
        let basis = TriangleBasis::new(view.map.element());
        let rule = fem_reference::triangle::TriangleRule::exact_for_degree(
            view.map.element().degree() + 2,
        );
        (0..d.mesh.mesh().cell_count())
            .map(|c| {
                let map = d.mesh.cell_map(c);
                rule.points
                    .iter()
                    .zip(&rule.weights)
                    .map(|(&xi, &w)| w * map.det(xi).abs() * view.value(&basis, c, xi))
                    .sum::<f64>()
            })
            .sum()
    }

    /// Area of the contact set over the curved cells: each cell's curved measure times
    /// the share of its multiplier DOFs that are active or touching (as
    /// `contact_area` on a `TriangleMesh`).
    pub fn contact_area(&self) -> f64 {
        let mesh = &self.discretization.mesh;
        self.contact_shares()
            .iter()
            .enumerate()
            .map(|(c, s)| s * crate::mesh::Mesh::measure(mesh, c))
            .sum()
    }
}

impl ObstacleSolution<TriangleMesh> {
    /// A view of model field `field` for evaluation and norms.
    pub fn view(&self, field: usize) -> TriangleField<'_> {
        TriangleField {
            mesh: &self.discretization.mesh,
            map: self.discretization.dofs.map(field).unwrap(),
            coefficients: self.field(field),
        }
    }

    /// `∫ λ_h`: the total contact force.
    pub fn total_contact_force(&self) -> f64 {
        self.view(self.discretization.multiplier_field).integral()
    }

    /// Area of the contact set: each cell counts with the share of its multiplier DOFs
    /// that are active (λ above 1e-8 of the multiplier scale) or touching (constraint
    /// residual negligible), so holes of zero λ_h where u_h lies on ψ are filled.
    pub fn contact_area(&self) -> f64 {
        let mesh = &self.discretization.mesh;
        self.contact_shares()
            .iter()
            .enumerate()
            .map(|(c, s)| s * mesh.area(c))
            .sum()
    }

    /// For a multiplier on a boundary part, per cell: the mean of λ_h over the cell's
    /// edges on the part (the mean of their means for a corner cell with two), and the
    /// share of those edges' ends in contact (active or touching, as
    /// [`ObstacleSolution::contact_shares`]); 0 for the cells off the part.
    /// `None` for a multiplier on the cells.
    pub fn boundary_contact_cells(&self) -> Option<(Vec<f64>, Vec<f64>)> {
        let d = &self.discretization;
        let boundary = d.boundary()?;
        let lambda = self.multiplier_values();
        let active = contact_indicator(
            &d.lcp,
            &d.primal_part(&self.values),
            &d.multiplier_part(&self.values),
        );
        let cells = d.mesh.cell_count();
        let (mut mean, mut share) = (vec![0.0; cells], vec![0.0; cells]);
        let mut count = vec![0.0f64; cells];
        for (edge, &[a, b]) in boundary.edges.iter().zip(&boundary.edge_dofs) {
            mean[edge.cell] += 0.5 * (lambda[a] + lambda[b]);
            share[edge.cell] +=
                0.5 * (f64::from(u8::from(active[a])) + f64::from(u8::from(active[b])));
            count[edge.cell] += 1.0;
        }
        // a cell with two edges on the part (a corner) takes their mean
        for ((m, s), n) in mean.iter_mut().zip(&mut share).zip(&count) {
            if *n > 1.0 {
                *m /= n;
                *s /= n;
            }
        }
        Some((mean, share))
    }
}

/// The largest penetration `max(ψ − u_h, 0)` of `u` into the obstacle `psi` at the
/// sample points of [`penetration`]; NaN if any compared value is.
///
/// The stabilized pairs impose `u_h ≥ ψ` weakly, cell by cell against the multiplier
/// space (P0: on each cell's mean), so `u_h` may dip below ψ inside the contact set and
/// near its free boundary. For a smooth obstacle the dip is `O(h²)` (the interpolation
/// error of ψ on the cell: `u_h − ψ` has a nonnegative mean and a second derivative
/// bounded by ψ's); the nodal method imposes `U_i ≥ ψ_i` at the vertices, where its
/// penetration is 0 (between them, where ψ is curved, it is `O(h²)` too).
pub fn max_penetration(
    u: &TriangleField,
    psi: &(dyn Fn(&[f64]) -> f64 + Sync),
    degree: usize,
) -> f64 {
    penetration(u, psi, degree).depth
}

/// What [`penetration`] measured: the largest `max(ψ − u_h, 0)` and the range of ψ over
/// the same points.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Penetration {
    /// The largest `ψ − u_h` (0 when u_h ≥ ψ everywhere sampled; NaN if any compared
    /// value is NaN).
    pub depth: f64,
    /// The smallest finite ψ sampled (`+∞` when none is finite).
    pub obstacle_min: f64,
    /// The largest finite ψ sampled (`−∞` when none is finite).
    pub obstacle_max: f64,
}

impl Penetration {
    /// `max ψ − min ψ` over the samples (0 for a flat ψ, `−∞` when no ψ was finite).
    pub fn obstacle_range(&self) -> f64 {
        self.obstacle_max - self.obstacle_min
    }
}

/// Sample points a penetration check takes over the whole mesh at least: on a mesh of
/// fewer cells than about this over 6, each cell adds a lattice of points, so that an
/// obstacle's peak between the vertices and quadrature points of a few large cells is
/// still seen (a two-triangle square under the radial ψ = √(1 − r²): ψ = −1 at
/// the corners and the quadrature points, u_h ≈ −0.24, a penetration of 1.24 at the
/// centre reported as 0). Each is an evaluation of ψ: 16k of them resolve a two-cell
/// mesh to 1/128 of its size, and a ψ of 300 terms costs about 0.4 s on them (65k took
/// 1.6 s against 0.02 s for the solve).
pub const PENETRATION_MIN_SAMPLES: usize = 1 << 14;

/// The largest lattice order of [`PENETRATION_MIN_SAMPLES`] (8k points a cell).
const PENETRATION_MAX_LATTICE: usize = 128;

/// `max(ψ − u_h, 0)` of `u` into the obstacle `psi`, and ψ's range, over the mesh
/// vertices (each cell's corners, so discontinuous fields count from every side), each
/// cell's edge midpoints and centroid, the points of the symmetric rule exact for degree
/// `degree` on every cell and, on meshes of few cells, a lattice on each cell
/// ([`PENETRATION_MIN_SAMPLES`]).
pub fn penetration(
    u: &TriangleField,
    psi: &(dyn Fn(&[f64]) -> f64 + Sync),
    degree: usize,
) -> Penetration {
    use crate::element::triangle::{over_cell_chunks, AffineMap, Tabulation};
    use crate::mesh::Cells;
    use rayon::prelude::*;
    let basis = TriangleBasis::new(u.map.element());
    let rule = fem_reference::triangle::TriangleRule::exact_for_degree(degree);
    let corners = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
    // the edge midpoints and the centroid too: where P2 and Morley fields peak between
    // the quadrature points
    let middles = [[0.5, 0.0], [0.5, 0.5], [0.0, 0.5], [1.0 / 3.0, 1.0 / 3.0]];
    let mut points: Vec<[f64; 2]> = corners
        .iter()
        .chain(&middles)
        .chain(&rule.points)
        .copied()
        .collect();
    let cells = u.mesh.cell_count().max(1);
    // the lattice order m whose (m+1)(m+2)/2 points a cell reach the minimum in all
    let order = (1..=PENETRATION_MAX_LATTICE)
        .find(|m| cells * (m + 1) * (m + 2) / 2 >= PENETRATION_MIN_SAMPLES)
        .unwrap_or(PENETRATION_MAX_LATTICE);
    if order > 2 {
        for i in 0..=order {
            for j in 0..=order - i {
                let xi = [i as f64 / order as f64, j as f64 / order as f64];
                if !corners.contains(&xi) && !middles.contains(&xi) {
                    points.push(xi);
                }
            }
        }
    }
    let table = Tabulation::new(&basis, &points);
    // ψ at each vertex once: about six cells share one, and ψ may be costly data
    let vertex_psi: Vec<f64> = u.mesh.vertices().par_iter().map(|x| psi(x)).collect();
    let none = Penetration {
        depth: 0.0,
        obstacle_min: f64::INFINITY,
        obstacle_max: f64::NEG_INFINITY,
    };
    let chunks = over_cell_chunks(Cells::All(u.mesh.cell_count()), |cells| {
        let mut found = none;
        let mut local = Vec::new();
        for c in cells {
            u.local_coefficients(c, &mut local);
            let corners = u.mesh.cell(c);
            let map = AffineMap::of(u.mesh, c);
            for (q, xi) in points.iter().enumerate() {
                let obstacle = match corners.get(q) {
                    Some(&v) => vertex_psi[v],
                    None => psi(&map.point(*xi)),
                };
                let depth = obstacle - table.value(q, &local);
                if depth.is_nan() {
                    found.depth = f64::NAN;
                    return found;
                }
                found.depth = found.depth.max(depth);
                if obstacle.is_finite() {
                    found.obstacle_min = found.obstacle_min.min(obstacle);
                    found.obstacle_max = found.obstacle_max.max(obstacle);
                }
            }
        }
        found
    });
    chunks.into_iter().fold(none, |all, chunk| Penetration {
        // `f64::max` would skip a NaN
        depth: if all.depth.is_nan() || chunk.depth.is_nan() {
            f64::NAN
        } else {
            all.depth.max(chunk.depth)
        },
        obstacle_min: all.obstacle_min.min(chunk.obstacle_min),
        obstacle_max: all.obstacle_max.max(chunk.obstacle_max),
    })
}

/// The largest open gap under a pushing multiplier: over the cells where the multiplier
/// `multiplier` pushes (one of its coefficients on the cell above 1e-6 of its largest),
/// the smallest `side·(u_h − ψ)` at the cell's corners, edge midpoints and centroid;
/// the largest of these over such cells, 0 where every such cell touches ψ (or there
/// is none). `side` is +1 for `u ≥ ψ` (an obstacle below), −1 for `u ≤ ψ`.
///
/// A stabilized method imposes `s(u_h − ψ) = α h^k (…)` on the cells in contact: with
/// `α h^k` large against the gap (coarse meshes, or α far above `1/C_I` where C_I gives
/// no bound), λ_h pushes on cells where the structure stays clear of ψ, and the KKT
/// residual cannot show it (the discrete problem is solved exactly). This measures
/// that: a few percent of the structure's size means the contact set is not real.
/// NaN if a compared value is.
pub fn max_open_contact_gap(
    u: &TriangleField,
    multiplier: &TriangleField,
    psi: &(dyn Fn(&[f64]) -> f64 + Sync),
    side: f64,
) -> f64 {
    let largest = multiplier.coefficients.iter().cloned().fold(0.0, f64::max);
    if largest <= 0.0 {
        return 0.0;
    }
    let basis = TriangleBasis::new(u.map.element());
    let points = [
        [0.0, 0.0],
        [1.0, 0.0],
        [0.0, 1.0],
        [0.5, 0.0],
        [0.5, 0.5],
        [0.0, 0.5],
        [1.0 / 3.0, 1.0 / 3.0],
    ];
    let table = crate::element::triangle::Tabulation::new(&basis, &points);
    // on rayon's threads: at 2M cells the serial scan took 0.04 s of every report
    let widths = crate::element::triangle::over_cell_chunks(
        crate::mesh::Cells::All(u.mesh.cell_count()),
        |cells| {
            let mut widest = 0.0f64;
            let mut local = Vec::new();
            for c in cells {
                let pushing = multiplier
                    .map
                    .cell_dofs(c)
                    .iter()
                    .any(|&k| multiplier.coefficients[k] > 1e-6 * largest);
                if !pushing {
                    continue;
                }
                let map = crate::element::triangle::AffineMap::of(u.mesh, c);
                u.local_coefficients(c, &mut local);
                let mut narrowest = f64::INFINITY;
                for (q, &xi) in points.iter().enumerate() {
                    let gap = side * (table.value(q, &local) - psi(&map.point(xi)));
                    if gap.is_nan() {
                        return f64::NAN;
                    }
                    narrowest = narrowest.min(gap);
                }
                widest = widest.max(narrowest);
            }
            widest
        },
    );
    // `f64::max` would skip a NaN
    if widths.iter().any(|w| w.is_nan()) {
        return f64::NAN;
    }
    widths.into_iter().fold(0.0, f64::max)
}

/// Per constraint: active (λ_k above 1e-8 of the multiplier scale) or touching (its
/// residual `R_k` negligible against the terms it is made of).
pub fn contact_indicator(lcp: &Lcp, u: &[f64], lambda: &[f64]) -> Vec<bool> {
    let largest = lambda.iter().cloned().fold(0.0, f64::max);
    let scale = largest.max(lcp.multiplier_scale());
    use rayon::prelude::*;
    let m = lambda.len();
    // per constraint: B_k U, G_k, the sizes of their terms, (CΛ)_k and its terms' sizes,
    // summed over the parts of a shared LCP (each part holds its constraints' rows, the
    // others none)
    let mut sums: Vec<f64> = (0..m)
        .into_par_iter()
        .map(|k| {
            let row = &lcp.b_rows[k];
            row.iter().map(|&(j, v)| v * u[j]).sum::<f64>()
        })
        .collect();
    sums.extend_from_slice(&lcp.g);
    sums.par_extend((0..m).into_par_iter().map(|k| {
        let row = &lcp.b_rows[k];
        row.iter().map(|&(j, v)| (v * u[j]).abs()).sum::<f64>() + lcp.g[k].abs()
    }));
    sums.extend(lcp.c_times(lambda));
    sums.extend(lcp.c_times_abs(lambda));
    let sums = lcp.whole(sums);
    let (bu, rest) = sums.split_at(m);
    let (g, rest) = rest.split_at(m);
    let (terms, rest) = rest.split_at(m);
    let (c_lambda, c_terms) = rest.split_at(m);
    (0..m)
        .into_par_iter()
        .map(|k| {
            lambda[k] > 1e-8 * scale
                || (bu[k] + c_lambda[k] - g[k]).abs() <= 1e-6 * (terms[k] + c_terms[k])
        })
        .collect()
}

/// The fixed DOFs of the model's `boundary:` conditions, each field on its own part of the
/// boundary: `parts` pairs a field (by name, one of `M::DIRICHLET`'s fields) with the
/// [`DirichletPart`] where its condition holds, as [`dirichlet_constraints_on`] imposes
/// it there; a field of `M::DIRICHLET` that is not listed gets the form's natural
/// condition on the whole boundary. A Reissner–Mindlin plate clamped on some parts and
/// simply supported ("soft") on others lists `θ_x`, `θ_y` on the clamped parts and `w`
/// on all of them.
///
/// Each part is also checked for the other fields' data (the data functions of a
/// model are shared, and [`dirichlet_constraints_on`] evaluates all of them on a part);
/// only the listed field's DOFs are kept.
///
/// # Errors
/// [`Error::Input`] (naming the field) for an empty list when `M` has boundary
/// conditions, a field the model does not declare or that has no `boundary:` condition,
/// a field listed twice, and a part that holds no boundary edge of `mesh` (a misspelt or
/// foreign marker); as [`dirichlet_constraints_on`] for the data on each part.
pub fn dirichlet_constraints_per_field<M: Model>(
    mesh: &TriangleMesh,
    dofs: &SystemDofs,
    coefficients: &Coefficients,
    parts: &[(&str, DirichletPart)],
) -> Result<Constraints> {
    let conditions = || {
        M::DIRICHLET
            .iter()
            .map(|&(f, d)| format!("`{} = {}`", M::FIELDS[f].name, M::DATA[d]))
            .collect::<Vec<_>>()
            .join(", ")
    };
    if parts.is_empty() && !M::DIRICHLET.is_empty() {
        return Err(Error::Input(format!(
            "no field of `{}` is given a boundary part: with the natural condition on the whole boundary the problem is not coercive; give at least one of {} a part",
            M::NAME,
            conditions()
        )));
    }
    let mut constraints = Constraints::new();
    let mut seen = Vec::new();
    for (name, part) in parts {
        let field = M::field(*name).map_err(|_| {
            Error::Input(format!(
                "boundary part for field `{name}`: `{}` has no such field (its boundary conditions are {})",
                M::NAME,
                conditions()
            ))
        })?;
        if !M::DIRICHLET.iter().any(|&(f, _)| f == field) {
            return Err(Error::Input(format!(
                "boundary part for field `{name}`: `{}` declares no boundary condition for it (only {})",
                M::NAME,
                conditions()
            )));
        }
        if seen.contains(&field) {
            return Err(Error::Input(format!(
                "field `{name}` is given a boundary part twice; list all its markers in one part"
            )));
        }
        seen.push(field);
        if part.edge_count(mesh) == 0 {
            return Err(Error::Input(format!(
                "the boundary part {part:?} of field `{name}` holds none of the mesh's {} boundary edges",
                mesh.boundary_edges().len()
            )));
        }
        let Some(range) = dofs.range(field) else {
            return Err(Error::Input(format!(
                "field `{name}` is not part of this system"
            )));
        };
        let on_part = dirichlet_constraints_on::<M>(mesh, dofs, coefficients, part)?;
        for &(dof, value) in on_part.fixed() {
            if range.contains(&dof) {
                constraints.fix_dof(dof, value)?;
            }
        }
        for &(group, row, value) in on_part.combinations() {
            if range.contains(&group.dofs[0]) {
                constraints.fix_combination(group.as_slice(), &row[..group.len], value)?;
            }
        }
    }
    Ok(constraints)
}

/// [`discretize_on_part`] with a part per field ([`dirichlet_constraints_per_field`]).
///
/// # Errors
/// As [`dirichlet_constraints_per_field`], and those of assembly.
pub fn discretize_on_field_parts<M: Model>(
    mesh: &TriangleMesh,
    coefficients: &Coefficients,
    parts: &[(&str, DirichletPart)],
    bilinear: impl IntoFormIndex<M>,
    linear: impl IntoFormIndex<M>,
) -> Result<Discretization<TriangleMesh>> {
    let dofs = SystemDofs::all::<M>(mesh)?;
    let constraints = dirichlet_constraints_per_field::<M>(mesh, &dofs, coefficients, parts)?;
    Discretization::with_constraints::<M>(mesh, coefficients, dofs, &constraints, bilinear, linear)
}

/// [`solve_obstacle_on_part`] with a part per field ([`dirichlet_constraints_per_field`]):
/// nested over `meshes`, whose markers refinement keeps, so each field has the same
/// part on every level.
///
/// # Errors
/// As [`dirichlet_constraints_per_field`] on each mesh, and those of the solve.
pub fn solve_obstacle_on_field_parts<M: Model>(
    meshes: &[TriangleMesh],
    coefficients: &Coefficients,
    parts: &[(&str, DirichletPart)],
    options: ObstacleOptions,
) -> Result<TriangleObstacleSolution> {
    let (bilinear, linear) = system_forms::<M>()?;
    solve_nested(
        meshes
            .iter()
            .map(|mesh| {
                move || discretize_on_field_parts::<M>(mesh, coefficients, parts, bilinear, linear)
            })
            .collect(),
        prolong_primal_on_triangles,
        options,
    )
}

#[cfg(test)]
mod open_gap_tests {
    use super::*;
    use crate::assembly::dof_map::DofMap;
    use crate::mesh::{Diagonal, TriangleMesh};
    use fem_reference::ElementKind;

    /// u = 1 − x (P1, exact), ψ = 0, λ pushing on chosen cells: the open gap is the
    /// smallest u over the pushing cells farthest from touching; u ≤ ψ the other way.
    #[test]
    fn the_open_gap_is_the_clearance_of_the_worst_pushing_cell() {
        let mesh = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 2, 2, Diagonal::Right).unwrap();
        let p1 = DofMap::on_triangles(&mesh, ElementKind::P1);
        let p0 = DofMap::on_triangles(&mesh, ElementKind::P0);
        let u: Vec<f64> = mesh.vertices().iter().map(|x| 1.0 - x[0]).collect();
        let field = TriangleField {
            mesh: &mesh,
            map: &p1,
            coefficients: &u,
        };
        let zero = |_: &[f64]| 0.0;
        let gap_with = |pushing: &[usize], side: f64| {
            let mut lambda = vec![0.0; mesh.cell_count()];
            for &c in pushing {
                lambda[c] = 2.0;
            }
            let multiplier = TriangleField {
                mesh: &mesh,
                map: &p0,
                coefficients: &lambda,
            };
            max_open_contact_gap(&field, &multiplier, &zero, side)
        };
        assert_eq!(gap_with(&[], 1.0), 0.0);
        // every cell: the left column's cells (x ≤ ½) stay at least ½ clear of ψ = 0
        let all: Vec<usize> = (0..mesh.cell_count()).collect();
        assert!((gap_with(&all, 1.0) - 0.5).abs() < 1e-14);
        // only cells touching x = 1, where u = 0 = ψ: no open gap
        let right: Vec<usize> = (0..mesh.cell_count())
            .filter(|&c| {
                mesh.cell_coordinates(c)
                    .iter()
                    .step_by(2)
                    .any(|&x| x == 1.0)
            })
            .collect();
        assert_eq!(gap_with(&right, 1.0), 0.0);
        // the obstacle above (u ≤ ψ): u − ψ ≥ 0 is a penetration, never an open gap
        assert!(gap_with(&all, -1.0) <= 0.0);
    }
}
