//! Boundary conditions as fixed DOFs, applied by eliminating them from the system.
//!
//! Elimination keeps a symmetric matrix symmetric (and SPD stays SPD), which the
//! Cholesky solve and the active-set solvers rely on.

use crate::assembly::change_of_basis::{
    resolve_group, ChangeOfBasis, DofGroup, GroupResolution, RotatedBlock, MAX_GROUP, VERTEX_DOFS,
};
use crate::assembly::dof_map::{DofMap, SystemDofs};
use crate::error::{Error, Result};
use crate::mesh::{IntervalMesh, TriangleMesh};
use crate::model::Model;
use crate::SparseMatrix;
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use fem_reference::{DofLocation, ElementKind};
use std::collections::BTreeMap;

/// An end of the interval.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// The left end.
    Left,
    /// The right end.
    Right,
}

/// The part of a triangle mesh's boundary where the Dirichlet condition holds; the rest
/// of the boundary gets the natural condition of the form (for `∫ ∇u·∇v`: homogeneous
/// Neumann, `∂u/∂n = 0`).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum DirichletPart {
    /// The whole boundary.
    #[default]
    All,
    /// The boundary edges whose marker is one of these (see
    /// [`TriangleMesh::boundary_part_markers`] to choose them by name).
    Markers(Vec<u32>),
}

impl DirichletPart {
    /// Whether boundary edges of marker `marker` belong to the part.
    pub fn contains(&self, marker: u32) -> bool {
        match self {
            DirichletPart::All => true,
            DirichletPart::Markers(m) => m.contains(&marker),
        }
    }

    /// The number of `mesh`'s boundary edges in the part.
    pub fn edge_count(&self, mesh: &TriangleMesh) -> usize {
        mesh.boundary_edges()
            .iter()
            .filter(|&&(_, m)| self.contains(m))
            .count()
    }

    /// The vertices of `mesh` where two edges of the part meet at a turning angle above
    /// 1e-8 rad (not a straight continuation) and at most `max_turn` rad, with their
    /// turning angles: where a polygon approximates a curve (docs/elements.md §6,
    /// Babuška's paradox).
    pub fn kinks(&self, mesh: &TriangleMesh, max_turn: f64) -> Vec<(usize, f64)> {
        let mut directions: Vec<Vec<[f64; 2]>> = vec![Vec::new(); mesh.vertex_count()];
        for &(e, m) in mesh.boundary_edges() {
            if self.contains(m) {
                let [a, b] = mesh.edges()[e];
                let (p, q) = (mesh.vertices()[a], mesh.vertices()[b]);
                directions[a].push([q[0] - p[0], q[1] - p[1]]);
                directions[b].push([p[0] - q[0], p[1] - q[1]]);
            }
        }
        let mut out = Vec::new();
        for (v, d) in directions.iter().enumerate() {
            if let [d1, d2] = d.as_slice() {
                // the angle between the two edges leaving v; the turn is its supplement
                let inner = (d1[0] * d2[1] - d1[1] * d2[0])
                    .abs()
                    .atan2(d1[0] * d2[0] + d1[1] * d2[1]);
                let turn = std::f64::consts::PI - inner;
                if turn > 1e-8 && turn <= max_turn {
                    out.push((v, turn));
                }
            }
        }
        out
    }

    /// For each vertex of `mesh`, whether it lies on an edge of the part (a vertex where
    /// a Dirichlet edge meets a natural one is in the part).
    pub fn vertices(&self, mesh: &TriangleMesh) -> Vec<bool> {
        let mut flags = vec![false; mesh.vertex_count()];
        for &(e, m) in mesh.boundary_edges() {
            if self.contains(m) {
                let [a, b] = mesh.edges()[e];
                flags[a] = true;
                flags[b] = true;
            }
        }
        flags
    }

    /// The DOFs of `map` (a field on `mesh`) on the part: the vertex DOFs of its edges'
    /// end points and the DOFs inside its edges (the P2 edge midpoints), sorted and
    /// unique. For [`DirichletPart::All`] these are [`DofMap::boundary_dofs`].
    pub fn dofs(&self, map: &DofMap, mesh: &TriangleMesh) -> Vec<usize> {
        let DirichletPart::Markers(_) = self else {
            return map.boundary_dofs(mesh);
        };
        let [per_vertex, per_edge, _] = map.element().triangle_layout();
        if map.local_count()
            != map
                .element()
                .local_dof_count(fem_reference::CellKind::Triangle)
            || map.dof_count() == 0
        {
            return Vec::new();
        }
        // a cell lists its DOFs as vertex 0, 1, 2, then edge k (from vertex k to
        // vertex k + 1) for k = 0, 1, 2, then its interior (DofMap::on_triangles)
        let mut out = Vec::new();
        for &(e, m) in mesh.boundary_edges() {
            if !self.contains(m) {
                continue;
            }
            let (c, _) = mesh.edge_cells(e);
            let Some(k) = mesh.local_edge(c, e) else {
                continue;
            };
            let local = map.cell_dofs(c);
            for v in [k, (k + 1) % 3] {
                out.extend_from_slice(&local[v * per_vertex..(v + 1) * per_vertex]);
            }
            let start = 3 * per_vertex + k * per_edge;
            out.extend_from_slice(&local[start..start + per_edge]);
        }
        out.sort_unstable();
        out.dedup();
        out
    }
}

/// How the edges of a [`DirichletPart`] hold a plate (a field on the Argyris or Morley
/// element), homogeneous: `w = 0` there, and for [`PlateSupport::Clamped`] also
/// `∂w/∂n = 0`. [`DirichletPart::plate_dofs`] lists the DOFs each fixes (docs/elements.md §6).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlateSupport {
    /// `w = 0`: the value and the derivatives it implies along each straight edge.
    SimplySupported,
    /// `w = 0` and `∂w/∂n = 0`: also the normal derivatives and what they imply.
    Clamped,
}

/// The rows, over the Argyris vertex DOFs `u, u_x, u_y, u_xx, u_xy, u_yy`, of the
/// conditions `support` imposes at both end points of a straight boundary edge of unit
/// tangent `t` and unit normal `n`: `w = 0` on the edge is `u = ∂_t u = ∂_tt u = 0` there
/// (the trace is the quintic these fix at the two ends), `∂_n w = 0` adds `∂_n u = 0`
/// and its tangential derivative `∂_t ∂_n u = nᵀHt = 0` (the normal derivative is the
/// quartic these and the edge's midpoint DOF fix). The normal second derivative `nᵀHn`
/// stays free. For `t` along x or y every row is a single DOF (± a unit row).
pub(crate) fn argyris_edge_rows(support: PlateSupport, t: [f64; 2], n: [f64; 2]) -> Vec<[f64; 6]> {
    let mut rows = vec![
        [1.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [0.0, t[0], t[1], 0.0, 0.0, 0.0],
        [0.0, 0.0, 0.0, t[0] * t[0], 2.0 * t[0] * t[1], t[1] * t[1]],
    ];
    if support == PlateSupport::Clamped {
        rows.push([0.0, n[0], n[1], 0.0, 0.0, 0.0]);
        rows.push([
            0.0,
            0.0,
            0.0,
            n[0] * t[0],
            n[0] * t[1] + n[1] * t[0],
            n[1] * t[1],
        ]);
    }
    rows
}

/// The unit tangent (from `a` to `b`) and the outward unit normal of boundary edge `e`
/// of `mesh`, snapped to the axes when within 1e-10 of one (so that an edge along x or y
/// gives exact single-DOF conditions, the fast path without a change of basis).
pub(crate) fn edge_frame(mesh: &TriangleMesh, e: usize) -> ([f64; 2], [f64; 2]) {
    let [a, b] = mesh.edges()[e];
    let (p, q) = (mesh.vertices()[a], mesh.vertices()[b]);
    let length = (q[0] - p[0]).hypot(q[1] - p[1]);
    let mut t = [(q[0] - p[0]) / length, (q[1] - p[1]) / length];
    if t[1].abs() <= 1e-10 {
        t = [t[0].signum(), 0.0];
    } else if t[0].abs() <= 1e-10 {
        t = [0.0, t[1].signum()];
    }
    // outward: away from the third vertex of the edge's cell
    let (c, _) = mesh.edge_cells(e);
    let cell = mesh.cell(c);
    let third = cell
        .iter()
        .copied()
        .find(|&v| v != a && v != b)
        .unwrap_or(a);
    let x = mesh.vertices()[third];
    let mut n = [t[1], -t[0]];
    if n[0] * (x[0] - p[0]) + n[1] * (x[1] - p[1]) > 0.0 {
        n = [-n[0], -n[1]];
    }
    (t, n)
}

/// What a plate support imposes on a field's DOFs (numbered within the field):
/// conditions on vertex DOF blocks and DOFs fixed as they are.
#[derive(Clone, Debug, Default)]
pub(crate) struct PlateConditions {
    /// `(first DOF of the vertex, vertex, row over its six DOFs)`: `row · U_v` is fixed.
    pub(crate) vertex: Vec<(usize, usize, [f64; 6])>,
    /// DOFs fixed as they are (Morley vertex values, edge normal-derivative DOFs).
    pub(crate) dofs: Vec<(usize, PlateFunctional)>,
}

/// The functional a DOF fixed as it is measures.
#[derive(Clone, Copy, Debug)]
pub(crate) enum PlateFunctional {
    /// The value at a vertex.
    Value(usize),
    /// The derivative at the midpoint of an edge along its normal `(t_y, −t_x)`, `t`
    /// the unit vector from its lower to its higher global vertex (the Argyris and
    /// Morley edge DOF, docs/elements.md §3).
    EdgeNormal(usize),
}

/// Boundary data of a plate support: a smooth function `G` near the part, given at a
/// point `x` as its jet `[G, G_x, G_y, G_xx, G_xy, G_yy]` (the order of the Argyris
/// vertex DOFs). The support then holds `w = G` on the part and, clamped, also
/// `∂_n w = ∂_n G`: every fixed functional (value, tangential and normal derivatives,
/// the curve's second derivative, the edge DOFs) gets its value at `G`. With `G` the
/// exact solution (a manufactured one) the data are exact; for data given on the
/// boundary only, extend them (e.g. constantly along the normal).
pub type PlateData<'a> = &'a dyn Fn([f64; 2]) -> [f64; 6];

/// `data`'s jet at `x`, checked finite.
fn jet(data: PlateData, x: [f64; 2]) -> Result<[f64; 6]> {
    let j = data(x);
    if j.iter().all(|v| v.is_finite()) {
        Ok(j)
    } else {
        Err(Error::Input(format!(
            "plate boundary data at ({}, {}) are not finite: [G, G_x, G_y, G_xx, G_xy, G_yy] = {j:?}",
            x[0], x[1]
        )))
    }
}

impl PlateFunctional {
    /// The functional at `data` on `mesh`.
    fn at(self, mesh: &TriangleMesh, data: PlateData) -> Result<f64> {
        match self {
            PlateFunctional::Value(v) => Ok(jet(data, mesh.vertices()[v])?[0]),
            PlateFunctional::EdgeNormal(e) => {
                let [a, b] = mesh.edges()[e];
                let (a, b) = (a.min(b), a.max(b));
                let (p, q) = (mesh.vertices()[a], mesh.vertices()[b]);
                let length = (q[0] - p[0]).hypot(q[1] - p[1]);
                let t = [(q[0] - p[0]) / length, (q[1] - p[1]) / length];
                let j = jet(data, [(p[0] + q[0]) / 2.0, (p[1] + q[1]) / 2.0])?;
                Ok(t[1] * j[1] - t[0] * j[2])
            }
        }
    }
}

impl DirichletPart {
    /// The conditions of `support` on the part's edges for the plate field `map`
    /// (errors as [`DirichletPart::plate_dofs`]).
    pub(crate) fn plate_conditions(
        &self,
        map: &DofMap,
        mesh: &TriangleMesh,
        support: PlateSupport,
    ) -> Result<PlateConditions> {
        let element = map.element();
        if !matches!(element, ElementKind::Argyris | ElementKind::Morley)
            || map.local_count() != element.local_dof_count(fem_reference::CellKind::Triangle)
        {
            return Err(Error::Input(format!(
                "plate supports (clamped, simply supported) are for Argyris and Morley fields on triangles, not {}",
                element.name()
            )));
        }
        let argyris = element == ElementKind::Argyris;
        let per_vertex = if argyris { 6 } else { 1 };
        let mut out = PlateConditions::default();
        for &(e, m) in mesh.boundary_edges() {
            if !self.contains(m) {
                continue;
            }
            let [a, b] = mesh.edges()[e];
            for v in [a, b] {
                let start = map.vertex_dofs(v).start;
                if argyris {
                    let (t, n) = edge_frame(mesh, e);
                    for row in argyris_edge_rows(support, t, n) {
                        out.vertex.push((start, v, row));
                    }
                } else {
                    out.dofs.push((start, PlateFunctional::Value(v)));
                }
            }
            if support == PlateSupport::Clamped {
                // the edge's normal-derivative DOF (a physical normal derivative whatever
                // the edge's direction), found through a cell as in `dofs`
                let (c, _) = mesh.edge_cells(e);
                if let Some(k) = mesh.local_edge(c, e) {
                    out.dofs.push((
                        map.cell_dofs(c)[3 * per_vertex + k],
                        PlateFunctional::EdgeNormal(e),
                    ));
                }
            }
        }
        Ok(out)
    }

    /// The DOFs of the plate field `map` (Argyris or Morley on `mesh`) fixed to zero by
    /// `support` on the part's edges alone, sorted and unique; for Argyris vertices on
    /// edges that are not along x or y these are DOFs of the rotated basis
    /// ([`Constraints::change_of_basis`]), the Cartesian ones elsewhere.
    ///
    /// Argyris, on every edge of the part and at both its end points: the value `u`,
    /// the tangential derivative `∂_t u` and the tangential second derivative `∂_tt u`
    /// (`u_x`, `u_xx` on an edge along x; `u_y`, `u_yy` along y); clamped also the normal
    /// derivative `∂_n u` (`u_y`, resp. `u_x`), the mixed derivative `∂_t ∂_n u` (`u_xy`)
    /// and the edge's normal-derivative DOF. These are exactly the conditions `w = 0`
    /// (and `∂_n w = 0`) on the edge imposes on the DOFs: the trace of an Argyris
    /// function on an edge is the quintic fixed by `u, ∂_t u, ∂_tt u` at its end points,
    /// and its normal derivative the quartic fixed by `∂_n u, ∂_tn u` there and the
    /// midpoint DOF. At a corner where two edges of the part meet, the union holds: on
    /// an axis-aligned square all six DOFs when both are clamped, all but `u_xy` when
    /// both are simply supported; at a corner of any other angle the union of both
    /// edges' functionals (simply supported: the value, the whole gradient and two
    /// Hessian functionals). Morley: the vertex values, clamped also the edge normal DOFs.
    ///
    /// # Errors
    /// [`Error::Input`] for another element.
    pub fn plate_dofs(
        &self,
        map: &DofMap,
        mesh: &TriangleMesh,
        support: PlateSupport,
    ) -> Result<Vec<usize>> {
        let mut constraints = Constraints::new();
        constraints.add_plate_conditions(
            mesh,
            &self.plate_conditions(map, mesh, support)?,
            0,
            None,
        )?;
        let reduction = constraints.reduction(map.dof_count())?;
        Ok((0..map.dof_count())
            .filter(|&d| reduction.free_index(d).is_none())
            .collect())
    }
}

/// Fixed DOFs with their values, and linear conditions on small groups of DOFs (the six
/// DOFs of an Argyris vertex on an edge that is not along x or y, the two components of
/// a vector field at a node of a slanted edge), which [`Constraints::change_of_basis`]
/// turns into fixed DOFs of a rotated basis.
#[derive(Clone, Debug, Default)]
pub struct Constraints {
    fixed: Vec<(usize, f64)>,
    /// `(group of global DOFs, row, value)`: `row · U_g = value`.
    combinations: Vec<(DofGroup, [f64; MAX_GROUP], f64)>,
    warnings: Vec<String>,
}

fn dot6(a: &[f64; 6], b: &[f64; 6]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The largest turning angle between consecutive edges of a simply supported Argyris
/// part that [`Constraints::support_plate`] takes for a polygon approximating a curve
/// (and warns about, [`Constraints::warnings`]): 30°. Real polygonal plates have a few
/// larger angles (90° for a rectangle, 60° for a hexagon).
pub const CURVE_TURNING_ANGLE: f64 = std::f64::consts::PI / 6.0;

/// The direction [`Constraints::hold_component`] holds a vector along.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ComponentDirection {
    /// The boundary's unit tangent at each node (`θ·t = 0`).
    Tangent,
    /// A fixed direction (`u·n = 0`).
    Fixed([f64; 2]),
}

/// The boundary curve a part of a polygonal mesh approximates, at a vertex `x` of the
/// part: `(outward unit normal, curvature)`, the curvature positive where the domain is
/// convex (`1/R` on a disk of radius R). See [`Constraints::support_plate_on_curve`].
pub type BoundaryCurve<'a> = &'a dyn Fn([f64; 2]) -> ([f64; 2], f64);

impl Constraints {
    /// No constraint.
    pub fn new() -> Self {
        Self::default()
    }

    fn vertex(mesh: &IntervalMesh, side: Side) -> usize {
        match side {
            Side::Left => 0,
            Side::Right => mesh.vertex_count() - 1,
        }
    }

    /// Fixes the DOF of `field` at the `side` vertex that measures the derivative of
    /// order `derivative` (0: value, 1: slope, Hermite only).
    fn fix<M: Model>(
        &mut self,
        mesh: &IntervalMesh,
        dofs: &SystemDofs,
        field: &str,
        side: Side,
        derivative: usize,
        value: f64,
    ) -> Result<()> {
        let f = M::field(field)?;
        let map = dofs
            .map(f)
            .ok_or_else(|| Error::Input(format!("field `{field}` is not part of this system")))?;
        let element = map.element();
        let vertex_dofs = map.vertex_dofs(Self::vertex(mesh, side));
        let k = element
            .dofs()
            .iter()
            .filter(|d| matches!(d, DofLocation::Vertex { vertex: 0, .. }))
            .position(
                |d| matches!(d, DofLocation::Vertex { derivative: o, .. } if *o == derivative),
            )
            .ok_or_else(|| {
                Error::Input(format!(
                    "field `{field}` ({}) has no {} DOF at the boundary",
                    element.name(),
                    if derivative == 0 { "value" } else { "slope" }
                ))
            })?;
        if !value.is_finite() {
            return Err(Error::Input(format!(
                "boundary value {value} for `{field}` is not finite"
            )));
        }
        let dof = dofs.offset(f).unwrap() + vertex_dofs.start + k;
        self.fixed.retain(|&(d, _)| d != dof);
        self.fixed.push((dof, value));
        Ok(())
    }

    /// `field = value` at the `side` end.
    pub fn dirichlet<M: Model>(
        &mut self,
        mesh: &IntervalMesh,
        dofs: &SystemDofs,
        field: &str,
        side: Side,
        value: f64,
    ) -> Result<()> {
        self.fix::<M>(mesh, dofs, field, side, 0, value)
    }

    /// `field' = slope` at the `side` end (C¹ elements).
    pub fn slope<M: Model>(
        &mut self,
        mesh: &IntervalMesh,
        dofs: &SystemDofs,
        field: &str,
        side: Side,
        slope: f64,
    ) -> Result<()> {
        self.fix::<M>(mesh, dofs, field, side, 1, slope)
    }

    /// Clamps `field` at the `side` end: its value, and its slope when the element has a
    /// slope DOF, are zero.
    pub fn clamp<M: Model>(
        &mut self,
        mesh: &IntervalMesh,
        dofs: &SystemDofs,
        field: &str,
        side: Side,
    ) -> Result<()> {
        self.dirichlet::<M>(mesh, dofs, field, side, 0.0)?;
        let f = M::field(field)?;
        if M::FIELDS[f].element.dofs_per_vertex() > 1 {
            self.slope::<M>(mesh, dofs, field, side, 0.0)?;
        }
        Ok(())
    }

    /// Supports the plate field `field` of `M` (Argyris or Morley) on `part` of the
    /// boundary of `mesh`: the conditions of [`DirichletPart::plate_dofs`] (values and
    /// derivatives along and, clamped, across each edge) hold with zero data. On edges
    /// along x or y they fix single Cartesian DOFs; elsewhere they are conditions on the
    /// vertex DOFs, fixed DOFs of the basis of [`Constraints::change_of_basis`]. Calls on
    /// several parts add up: a vertex where they meet gets the union of their conditions.
    ///
    /// # Errors
    /// [`Error::Input`] for an unknown field, a field not in `dofs`, a part that holds no
    /// boundary edge of `mesh` (a misspelt or foreign marker), and as
    /// [`DirichletPart::plate_dofs`].
    pub fn support_plate<M: Model>(
        &mut self,
        mesh: &TriangleMesh,
        dofs: &SystemDofs,
        field: &str,
        part: &DirichletPart,
        support: PlateSupport,
    ) -> Result<()> {
        self.support_plate_with_data::<M>(mesh, dofs, field, part, support, None)
    }

    /// [`Constraints::support_plate`] with boundary data: `w = G` on the part and,
    /// clamped, `∂_n w = ∂_n G` ([`PlateData`]; `None`: `G = 0`).
    ///
    /// # Errors
    /// As [`Constraints::support_plate`], and data that are not finite at a vertex or
    /// edge midpoint of the part (the message names the point).
    pub fn support_plate_with_data<M: Model>(
        &mut self,
        mesh: &TriangleMesh,
        dofs: &SystemDofs,
        field: &str,
        part: &DirichletPart,
        support: PlateSupport,
        data: Option<PlateData>,
    ) -> Result<()> {
        let f = M::field(field)?;
        let (Some(map), Some(offset)) = (dofs.map(f), dofs.offset(f)) else {
            return Err(Error::Input(format!(
                "field `{field}` is not part of this system"
            )));
        };
        if part.edge_count(mesh) == 0 {
            return Err(Error::Input(format!(
                "the boundary part {part:?} where `{field}` is {support:?} holds none of the mesh's {} boundary edges",
                mesh.boundary_edges().len()
            )));
        }
        self.add_plate_conditions(
            mesh,
            &part.plate_conditions(map, mesh, support)?,
            offset,
            data,
        )?;
        if map.element() == ElementKind::Argyris && support == PlateSupport::SimplySupported {
            let kinks = part.kinks(mesh, CURVE_TURNING_ANGLE);
            if let Some(&(v, turn)) = kinks.first() {
                let x = mesh.vertices()[v];
                self.warnings.push(format!(
                    "`{field}` is simply supported on a polygon that looks like a curve ({} vertices where its edges turn by at most {:.0}°, e.g. {:.2}° at ({}, {})): at every such corner w = 0 on both edges fixes the whole gradient, so the Argyris plate converges to the clamped plate, not to the simply supported one of the curve (Babuška's paradox, docs/elements.md §6); support a curved boundary with Constraints::support_plate_on_curve",
                    kinks.len(),
                    CURVE_TURNING_ANGLE.to_degrees(),
                    turn.to_degrees(),
                    x[0],
                    x[1]
                ));
            }
        }
        Ok(())
    }

    /// Adds the conditions and warnings of `other` (on the same DOFs) to these.
    ///
    /// # Errors
    /// None today; the signature leaves room for conflicting conditions.
    pub fn merge(&mut self, other: Constraints) -> Result<()> {
        for (dof, value) in other.fixed {
            self.fix_dof(dof, value)?;
        }
        self.combinations.extend(other.combinations);
        self.warnings.extend(other.warnings);
        Ok(())
    }

    /// Warnings about the supports given so far: a simply supported Argyris part that
    /// looks like a polygonal approximation of a curve (consecutive edges turning by at
    /// most [`CURVE_TURNING_ANGLE`]) converges to the wrong plate.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Supports the Argyris field `field` of `M` on `part`, a polygonal approximation
    /// of the smooth curve `curve` (its outward normal `n` and curvature `κ` at each
    /// vertex of the part; `t = (−n_y, n_x)`): the conditions of the curve, not of the
    /// polygon, at each vertex of the part. Simply supported (`w = 0` along the curve):
    /// `u = 0`, `∂_t u = 0` and `tᵀHt − κ ∂_n u = 0` (the second derivative of `w` along
    /// the curve, whose acceleration is `−κ n`); `∂_n u` and the rest stay free.
    /// Clamped (also `∂_n w = 0`): `u = 0`, `∇u = 0`, `tᵀHt = 0`, `nᵀHt = 0` and the
    /// edges' normal-derivative DOFs. The polygon's corners would fix more (the whole
    /// gradient, resp. the whole Hessian): with them the simply supported plate converges
    /// to the clamped one and the clamped one at first order only; with the curve's
    /// conditions both converge to the plate on the curved domain at second order (the
    /// polygon's distance from the curve; `tests/plate_supports.rs`). Morley fields take
    /// [`Constraints::support_plate`] (they fix values and edge DOFs only). Where a
    /// straight part meets the curve, support it with [`Constraints::support_plate`]:
    /// the vertex gets the union of both conditions.
    ///
    /// With `data` ([`PlateData`]) the conditions hold `w = G` (clamped also
    /// `∂_n w = ∂_n G`) along the curve: each fixed functional gets its value at `G`.
    ///
    /// # Errors
    /// As [`Constraints::support_plate_with_data`], a field that is not Argyris, and a
    /// normal that is zero or not finite or a curvature that is not finite at a vertex
    /// (the message names the vertex).
    // the arguments of support_plate_with_data and the curve
    #[allow(clippy::too_many_arguments)]
    pub fn support_plate_on_curve<M: Model>(
        &mut self,
        mesh: &TriangleMesh,
        dofs: &SystemDofs,
        field: &str,
        part: &DirichletPart,
        support: PlateSupport,
        curve: BoundaryCurve,
        data: Option<PlateData>,
    ) -> Result<()> {
        let f = M::field(field)?;
        let (Some(map), Some(offset)) = (dofs.map(f), dofs.offset(f)) else {
            return Err(Error::Input(format!(
                "field `{field}` is not part of this system"
            )));
        };
        if map.element() != ElementKind::Argyris {
            return Err(Error::Input(format!(
                "supports on a curve are for Argyris fields, `{field}` is {} (use support_plate)",
                map.element().name()
            )));
        }
        if part.edge_count(mesh) == 0 {
            return Err(Error::Input(format!(
                "the boundary part {part:?} where `{field}` is {support:?} holds none of the mesh's {} boundary edges",
                mesh.boundary_edges().len()
            )));
        }
        for (v, on) in part.vertices(mesh).into_iter().enumerate() {
            if !on {
                continue;
            }
            let x = mesh.vertices()[v];
            let (n, kappa) = curve(x);
            let length = n[0].hypot(n[1]);
            if !(length > 0.0 && length.is_finite() && kappa.is_finite()) {
                return Err(Error::Input(format!(
                    "the boundary curve of `{field}` at vertex {v} ({}, {}) has normal ({}, {}) and curvature {kappa}: the normal must be finite and nonzero, the curvature finite",
                    x[0], x[1], n[0], n[1]
                )));
            }
            let n = [n[0] / length, n[1] / length];
            let t = [-n[1], n[0]];
            let tt = [0.0, 0.0, 0.0, t[0] * t[0], 2.0 * t[0] * t[1], t[1] * t[1]];
            let rows: Vec<[f64; VERTEX_DOFS]> = match support {
                PlateSupport::SimplySupported => vec![
                    [1.0, 0.0, 0.0, 0.0, 0.0, 0.0],
                    [0.0, t[0], t[1], 0.0, 0.0, 0.0],
                    [0.0, -kappa * n[0], -kappa * n[1], tt[3], tt[4], tt[5]],
                ],
                PlateSupport::Clamped => vec![
                    [1.0, 0.0, 0.0, 0.0, 0.0, 0.0],
                    [0.0, 1.0, 0.0, 0.0, 0.0, 0.0],
                    [0.0, 0.0, 1.0, 0.0, 0.0, 0.0],
                    tt,
                    [
                        0.0,
                        0.0,
                        0.0,
                        n[0] * t[0],
                        n[0] * t[1] + n[1] * t[0],
                        n[1] * t[1],
                    ],
                ],
            };
            let start = offset + map.vertex_dofs(v).start;
            let j = match data {
                Some(g) => jet(g, x)?,
                None => [0.0; 6],
            };
            for row in rows {
                self.fix_vertex_combination(start, row, dot6(&row, &j))?;
            }
        }
        if support == PlateSupport::Clamped {
            // the edge DOFs; the vertex rows of the polygon are replaced by the curve's
            let mut conditions = part.plate_conditions(map, mesh, support)?;
            conditions.vertex.clear();
            self.add_plate_conditions(mesh, &conditions, offset, data)?;
        }
        Ok(())
    }

    /// [`Constraints::support_plate`] for the plate field `map` whose DOFs start at
    /// global DOF `offset`, without the check that `part` holds an edge.
    ///
    /// # Errors
    /// As [`DirichletPart::plate_dofs`].
    pub fn support_plate_field(
        &mut self,
        mesh: &TriangleMesh,
        map: &DofMap,
        offset: usize,
        part: &DirichletPart,
        support: PlateSupport,
    ) -> Result<()> {
        self.add_plate_conditions(
            mesh,
            &part.plate_conditions(map, mesh, support)?,
            offset,
            None,
        )
    }

    /// Fixes the functionals of `conditions` (on a field from global DOF `offset`) to
    /// their values at `data`, or to zero.
    fn add_plate_conditions(
        &mut self,
        mesh: &TriangleMesh,
        conditions: &PlateConditions,
        offset: usize,
        data: Option<PlateData>,
    ) -> Result<()> {
        for &(start, v, row) in &conditions.vertex {
            let value = match data {
                Some(g) => dot6(&row, &jet(g, mesh.vertices()[v])?),
                None => 0.0,
            };
            self.fix_vertex_combination(offset + start, row, value)?;
        }
        for &(d, functional) in &conditions.dofs {
            let value = match data {
                Some(g) => functional.at(mesh, g)?,
                None => 0.0,
            };
            self.fix_dof(offset + d, value)?;
        }
        Ok(())
    }

    /// Holds the component of the vector field `fields = [x, y]` (its two Lagrange
    /// component fields, same element) along `direction` at every node of `part`:
    /// `θ·t = 0` with the boundary's tangent (the hard simple support) or `u·n = 0` for a
    /// fixed `n` (a roller). Where a vertex joins two edges of the part that turn by at
    /// most [`CURVE_TURNING_ANGLE`] (a polygon approximating a curve), their tangents'
    /// mean is the curve's; at a sharper corner both tangents hold and the vector is 0
    /// there. A direction that is a coordinate axis fixes a single component DOF.
    ///
    /// # Errors
    /// Fields that are not two Lagrange fields of the same element in `dofs`, a
    /// direction that is zero or not finite, and a part holding no boundary edge.
    pub fn hold_component(
        &mut self,
        mesh: &TriangleMesh,
        dofs: &SystemDofs,
        fields: [usize; 2],
        part: &DirichletPart,
        direction: ComponentDirection,
    ) -> Result<()> {
        let (Some(map_x), Some(map_y), Some(offset_x), Some(offset_y)) = (
            dofs.map(fields[0]),
            dofs.map(fields[1]),
            dofs.offset(fields[0]),
            dofs.offset(fields[1]),
        ) else {
            return Err(Error::Input(
                "the components of a held vector are not part of this system".into(),
            ));
        };
        if map_x.element() != map_y.element() || map_x.element().needs_transformation() {
            return Err(Error::Input(format!(
                "a held vector's components are Lagrange fields of one element ({} and {} given)",
                map_x.element().name(),
                map_y.element().name()
            )));
        }
        if let ComponentDirection::Fixed(n) = direction {
            if !(n[0].is_finite() && n[1].is_finite()) || n[0] == 0.0 && n[1] == 0.0 {
                return Err(Error::Input(format!(
                    "the held direction ({}, {}) is zero or not finite",
                    n[0], n[1]
                )));
            }
        }
        let [per_vertex, per_edge, _] = map_x.element().triangle_layout();
        // every node of the part with the unit tangents of its part edges
        let mut tangents: BTreeMap<usize, Vec<[f64; 2]>> = BTreeMap::new();
        let mut edges = 0;
        for &(e, m) in mesh.boundary_edges() {
            if !part.contains(m) {
                continue;
            }
            edges += 1;
            let [a, b] = mesh.edges()[e];
            let (pa, pb) = (mesh.vertices()[a], mesh.vertices()[b]);
            let length = (pb[0] - pa[0]).hypot(pb[1] - pa[1]);
            let t = [(pb[0] - pa[0]) / length, (pb[1] - pa[1]) / length];
            let (c, _) = mesh.edge_cells(e);
            let Some(k) = mesh.local_edge(c, e) else {
                continue;
            };
            let local = map_x.cell_dofs(c);
            let mut nodes: Vec<usize> = Vec::new();
            for v in [k, (k + 1) % 3] {
                nodes.extend((v * per_vertex..(v + 1) * per_vertex).map(|j| local[j]));
            }
            let start = 3 * per_vertex + k * per_edge;
            nodes.extend((start..start + per_edge).map(|j| local[j]));
            for node in nodes {
                // the tangent's sign does not matter; keep one orientation per curve
                let list = tangents.entry(node).or_default();
                let t = match list.first() {
                    Some(s) if s[0] * t[0] + s[1] * t[1] < 0.0 => [-t[0], -t[1]],
                    _ => t,
                };
                list.push(t);
            }
        }
        if edges == 0 {
            return Err(Error::Input(format!(
                "the boundary part {part:?} where a vector's component is held holds none of the mesh's {} boundary edges",
                mesh.boundary_edges().len()
            )));
        }
        for (node, list) in tangents {
            let directions: Vec<[f64; 2]> = match direction {
                ComponentDirection::Fixed(n) => vec![n],
                ComponentDirection::Tangent => {
                    let smooth = list.windows(2).all(|w| {
                        let cos = w[0][0] * w[1][0] + w[0][1] * w[1][1];
                        cos >= CURVE_TURNING_ANGLE.cos()
                    });
                    if smooth {
                        let sum = list
                            .iter()
                            .fold([0.0, 0.0], |s, t| [s[0] + t[0], s[1] + t[1]]);
                        vec![sum]
                    } else {
                        list
                    }
                }
            };
            // the same place in the y field's numbering (one element, one numbering)
            let dof_y = offset_y + node;
            let dof_x = offset_x + node;
            for d in directions {
                let length = d[0].hypot(d[1]);
                let d = [d[0] / length, d[1] / length];
                if d[1] == 0.0 {
                    self.fix_dof(dof_x, 0.0)?;
                } else if d[0] == 0.0 {
                    self.fix_dof(dof_y, 0.0)?;
                } else {
                    self.fix_combination(&[dof_x, dof_y], &d, 0.0)?;
                }
            }
        }
        Ok(())
    }

    /// Imposes `Σ_k row[k] U[start + k] = value` on the six DOFs of an Argyris vertex
    /// (`u, u_x, u_y, u_xx, u_xy, u_yy` from global DOF `start`).
    ///
    /// # Errors
    /// [`Error::Input`] for a row or value that is not finite, or a zero row.
    pub fn fix_vertex_combination(
        &mut self,
        start: usize,
        row: [f64; VERTEX_DOFS],
        value: f64,
    ) -> Result<()> {
        let dofs: [usize; VERTEX_DOFS] = std::array::from_fn(|k| start + k);
        self.fix_combination(&dofs, &row, value)
    }

    /// Imposes `Σ_k row[k] U[dofs[k]] = value` on a group of up to [`MAX_GROUP`] DOFs
    /// (the components `θ_x`, `θ_y` of a vector field at one node: `θ·t = 0`). Every
    /// condition on a DOF of a group must name the same group.
    ///
    /// # Errors
    /// [`Error::Input`] for a row or value that is not finite, a zero row, a row of
    /// another length than `dofs`, and an empty, repeating or too large group.
    pub fn fix_combination(&mut self, dofs: &[usize], row: &[f64], value: f64) -> Result<()> {
        if row.len() != dofs.len()
            || !value.is_finite()
            || !row.iter().all(|x| x.is_finite())
            || row.iter().all(|&x| x == 0.0)
        {
            return Err(Error::Input(format!(
                "condition {row:?} = {value} on DOFs {dofs:?} is zero, not finite or of another length"
            )));
        }
        let group = DofGroup::new(dofs)?;
        let mut padded = [0.0; MAX_GROUP];
        padded[..row.len()].copy_from_slice(row);
        self.combinations.push((group, padded, value));
        Ok(())
    }

    /// The conditions on groups of DOFs (`(group, row, value)`), in the order given.
    pub fn combinations(&self) -> &[(DofGroup, [f64; MAX_GROUP], f64)] {
        &self.combinations
    }

    /// The fixed DOFs in the primed numbering and the change of basis (module
    /// [`crate::assembly::change_of_basis`]).
    fn resolve(&self, n: usize) -> Result<(Vec<(usize, f64)>, ChangeOfBasis)> {
        let mut groups: BTreeMap<DofGroup, Vec<([f64; MAX_GROUP], f64)>> = BTreeMap::new();
        for &(group, row, value) in &self.combinations {
            if let Some(&d) = group.as_slice().iter().find(|&&d| d >= n) {
                return Err(Error::Input(format!(
                    "conditioned DOF {d} outside a system of {n}"
                )));
            }
            groups.entry(group).or_default().push((row, value));
        }
        let mut group_of: BTreeMap<usize, DofGroup> = BTreeMap::new();
        for group in groups.keys() {
            for &d in group.as_slice() {
                if let Some(other) = group_of.insert(d, *group) {
                    return Err(Error::Input(format!(
                        "conditions on DOFs {:?} and on DOFs {:?} overlap at DOF {d}",
                        other.as_slice(),
                        group.as_slice()
                    )));
                }
            }
        }
        // a single DOF fixed inside a conditioned group is one more condition there
        let mut fixed = Vec::with_capacity(self.fixed.len());
        for &(d, v) in &self.fixed {
            match group_of.get(&d) {
                Some(group) => {
                    let mut row = [0.0; MAX_GROUP];
                    row[group.position(d).expect("in its group")] = 1.0;
                    groups.get_mut(group).expect("a group").push((row, v));
                }
                None => fixed.push((d, v)),
            }
        }
        let mut blocks = Vec::new();
        for (group, conditions) in groups {
            match resolve_group(group.len, &conditions)
                .map_err(|e| Error::Input(format!("DOFs {:?}: {e}", group.as_slice())))?
            {
                GroupResolution::Direct(single) => {
                    fixed.extend(single.into_iter().map(|(k, v)| (group.dofs[k], v)));
                }
                GroupResolution::Rotated(r) => {
                    fixed.extend((0..r.fixed).map(|k| (group.dofs[k], r.values[k])));
                    blocks.push(RotatedBlock { group, ..*r });
                }
            }
        }
        Ok((fixed, ChangeOfBasis::new(blocks)))
    }

    /// The change of basis of the DOFs of a system of `n` DOFs that turns the conditions
    /// on groups of DOFs into fixed DOFs: the identity where every condition of a group
    /// is a single DOF (edges along x or y, fixed as they are), a rotation of the group's
    /// DOFs elsewhere. [`Constraints::reduction`] is in its primed numbering: a system
    /// `K U = F` is to be solved as `K' U' = F'` (`K' = Rᵀ K R`,
    /// [`ChangeOfBasis::transform_matrix`]; `F' = Rᵀ F`, [`ChangeOfBasis::to_primed`])
    /// and mapped back by [`ChangeOfBasis::to_cartesian`], as `solve_linear` and the
    /// obstacle discretization do.
    ///
    /// # Errors
    /// [`Error::Input`] for DOFs outside the system, overlapping groups, and conditions
    /// on a group that contradict each other.
    pub fn change_of_basis(&self, n: usize) -> Result<ChangeOfBasis> {
        Ok(self.resolve(n)?.1)
    }

    /// Fixes global DOF `dof` to `value` (a later value for the same DOF wins).
    pub fn fix_dof(&mut self, dof: usize, value: f64) -> Result<()> {
        if !value.is_finite() {
            return Err(Error::Input(format!(
                "boundary value {value} at DOF {dof} is not finite"
            )));
        }
        self.fixed.push((dof, value));
        Ok(())
    }

    /// The DOFs fixed as they are ([`Constraints::fix_dof`], single-DOF plate conditions
    /// are in [`Constraints::combinations`]) and their values.
    pub fn fixed(&self) -> &[(usize, f64)] {
        &self.fixed
    }

    /// The elimination for a system of `n` DOFs, in the numbering of the primed DOFs of
    /// [`Constraints::change_of_basis`] (the Cartesian one where it is the identity).
    ///
    /// # Errors
    /// [`Error::Input`] for a DOF outside the system, and as
    /// [`Constraints::change_of_basis`].
    pub fn reduction(&self, n: usize) -> Result<Reduction> {
        let (fixed, _) = self.resolve(n)?;
        let mut value = vec![None; n];
        for &(d, v) in &fixed {
            *value
                .get_mut(d)
                .ok_or_else(|| Error::Input(format!("fixed DOF {d} outside a system of {n}")))? =
                Some(v);
        }
        let mut free_index = vec![usize::MAX; n];
        let mut free = Vec::new();
        for (d, v) in value.iter().enumerate() {
            if v.is_none() {
                free_index[d] = free.len();
                free.push(d);
            }
        }
        Ok(Reduction {
            value: value.into_iter().map(|v| v.unwrap_or(0.0)).collect(),
            free_index,
            free,
        })
    }
}

/// The map between a full system and its free DOFs.
#[derive(Clone, Debug)]
pub struct Reduction {
    value: Vec<f64>,
    free_index: Vec<usize>,
    free: Vec<usize>,
}

impl Reduction {
    /// Free DOFs (full numbering), increasing.
    pub fn free(&self) -> &[usize] {
        &self.free
    }

    /// The value of DOF `d` if it is fixed, 0 if it is free.
    pub fn fixed_value(&self, d: usize) -> f64 {
        self.value[d]
    }

    /// Index among the free DOFs of full DOF `d`, if it is free.
    pub fn free_index(&self, d: usize) -> Option<usize> {
        (self.free_index[d] != usize::MAX).then_some(self.free_index[d])
    }

    /// The free–free block of `a`.
    pub fn matrix(&self, a: &SparseMatrix) -> SparseMatrix {
        let n = self.free.len();
        let (col_ptrs, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
        // the free columns' lengths bound the entries: no growth by doubling, whose
        // spare capacity (up to 2×) would stay with the matrix and whose copies cost
        // peak memory (issue 15)
        let bound: usize = self
            .free
            .iter()
            .map(|&j| col_ptrs[j + 1] - col_ptrs[j])
            .sum();
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::with_capacity(bound);
        let mut values = Vec::with_capacity(bound);
        col_ptr.push(0);
        for &j in &self.free {
            for k in col_ptrs[j]..col_ptrs[j + 1] {
                let fi = self.free_index[rows[k]];
                if fi != usize::MAX {
                    row_idx.push(fi);
                    values.push(vals[k]);
                }
            }
            col_ptr.push(row_idx.len());
        }
        SparseColMat::new(
            SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx),
            values,
        )
    }

    /// The free–free block of `a`, as [`Reduction::matrix`], built in `a`'s own arrays:
    /// the full matrix and its block are never held together (at 1M unknowns each is
    /// about 120 MB; issue 15, peak memory).
    pub fn into_matrix(&self, a: SparseMatrix) -> SparseMatrix {
        let (symbolic, mut values) = a.into_parts();
        let (nrows, ncols, col_ptrs, col_nnz, mut row_idx) = symbolic.into_parts();
        if col_nnz.is_some() {
            // not compressed: the general copy
            let a = SparseColMat::new(
                SymbolicSparseColMat::new_checked(nrows, ncols, col_ptrs, col_nnz, row_idx),
                values,
            );
            return self.matrix(&a);
        }
        let n = self.free.len();
        let mut col_ptr = Vec::with_capacity(n + 1);
        col_ptr.push(0);
        // entries only move towards the front (the kept ones keep their order), so
        // writing at `w` never overwrites an entry still to be read at `k ≥ w`
        let mut w = 0;
        for &j in &self.free {
            for k in col_ptrs[j]..col_ptrs[j + 1] {
                let fi = self.free_index[row_idx[k]];
                if fi != usize::MAX {
                    row_idx[w] = fi;
                    values[w] = values[k];
                    w += 1;
                }
            }
            col_ptr.push(w);
        }
        drop(col_ptrs);
        row_idx.truncate(w);
        values.truncate(w);
        SparseColMat::new(
            SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx),
            values,
        )
    }

    /// The free part of `b − A u_fixed`.
    pub fn rhs(&self, a: &SparseMatrix, b: &[f64]) -> Vec<f64> {
        let mut full = b.to_vec();
        let (col_ptrs, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
        for (j, &v) in self.value.iter().enumerate() {
            if v != 0.0 && self.free_index[j] == usize::MAX {
                for k in col_ptrs[j]..col_ptrs[j + 1] {
                    full[rows[k]] -= vals[k] * v;
                }
            }
        }
        self.free.iter().map(|&d| full[d]).collect()
    }

    /// The full vector from the free values (fixed DOFs get their values).
    pub fn expand(&self, free_values: &[f64]) -> Vec<f64> {
        let mut full = self.value.clone();
        for (k, &d) in self.free.iter().enumerate() {
            full[d] = free_values[k];
        }
        full
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Diagonal;
    use fem_reference::triangle::Polynomial2;

    /// A mesh with cells of every orientation: alternating diagonals, then one cell
    /// bisected (hanging-free closure), so the boundary edges sit at every local position.
    fn mesh() -> TriangleMesh {
        let m = TriangleMesh::rectangle(0.0, 2.0, 0.0, 1.0, 4, 3, Diagonal::Alternating).unwrap();
        m.refine(&[0, 7, 20]).unwrap().0
    }

    #[test]
    fn every_marker_gives_the_whole_boundary() {
        let m = mesh();
        for element in [ElementKind::P1, ElementKind::P2, ElementKind::P3] {
            let map = DofMap::on_triangles(&m, element);
            let all = DirichletPart::Markers(vec![1, 2, 3, 4]).dofs(&map, &m);
            assert_eq!(all, map.boundary_dofs(&m), "{element:?}");
            assert_eq!(DirichletPart::All.dofs(&map, &m), all);
        }
        let p0 = DofMap::on_triangles(&m, ElementKind::P0);
        assert!(DirichletPart::Markers(vec![1]).dofs(&p0, &m).is_empty());
    }

    /// The DOFs of the left and right sides are exactly the DOFs whose nodes lie on
    /// them (corners included: there a Dirichlet side meets a natural one).
    #[test]
    fn a_part_holds_the_dofs_on_its_edges() {
        let m = mesh();
        let part = DirichletPart::Markers(vec![4, 2]);
        for element in [ElementKind::P1, ElementKind::P2, ElementKind::P3] {
            let map = DofMap::on_triangles(&m, element);
            let on_sides: Vec<usize> = map
                .nodes(&m)
                .iter()
                .enumerate()
                .filter(|(_, x)| x[0] == 0.0 || x[0] == 2.0)
                .map(|(d, _)| d)
                .collect();
            assert_eq!(part.dofs(&map, &m), on_sides, "{element:?}");
        }
        let vertices = part.vertices(&m);
        for (v, x) in m.vertices().iter().enumerate() {
            assert_eq!(vertices[v], x[0] == 0.0 || x[0] == 2.0, "vertex {v}");
        }
        assert_eq!(part.edge_count(&m), 6);
        assert_eq!(DirichletPart::Markers(vec![9]).edge_count(&m), 0);
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

    /// The value of the plate DOF `d` of `map` on `mesh` at the function `p`, computed
    /// from `p` (vertex derivatives; an edge DOF as the derivative along the edge's
    /// normal at its midpoint, up to sign).
    fn dof_value(map: &DofMap, mesh: &TriangleMesh, p: &Polynomial2, d: usize) -> f64 {
        let per_vertex = map.element().triangle_layout()[0];
        let vertices = mesh.vertex_count();
        if d < per_vertex * vertices {
            let x = mesh.vertices()[d / per_vertex];
            let (a, b) = [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)][d % per_vertex];
            p.derivative(a, b).eval(x)
        } else {
            let [a, b] = mesh.edges()[d - per_vertex * vertices];
            let (x, y) = (mesh.vertices()[a], mesh.vertices()[b]);
            let t = [y[0] - x[0], y[1] - x[1]];
            let l = t[0].hypot(t[1]);
            let m = [(x[0] + y[0]) / 2.0, (x[1] + y[1]) / 2.0];
            (t[1] * p.derivative(1, 0).eval(m) - t[0] * p.derivative(0, 1).eval(m)) / l
        }
    }

    /// On `[0, 2] × [0, 1]` with cells of every orientation: the DOFs `plate_dofs` fixes
    /// vanish for every function satisfying the support's conditions (`b r` with `b`
    /// vanishing on the part, squared for clamped, and several `r`), and every other
    /// boundary DOF is nonzero for one of them, so nothing is fixed that the conditions
    /// leave free and nothing they fix is left free (the condition-satisfying functions
    /// span the DOF values the conditions allow).
    #[test]
    fn plate_dofs_are_the_dofs_the_conditions_fix() {
        let m = mesh();
        let x_sides = poly(&[(1, 0, 2.0), (2, 0, -1.0)]); // x (2 − x)
        let y_sides = poly(&[(0, 1, 1.0), (0, 2, -1.0)]); // y (1 − y)
        let r = [
            poly(&[(0, 0, 1.0), (1, 0, 0.3), (0, 1, -0.7), (1, 1, 0.2)]),
            poly(&[(0, 0, 0.5), (2, 0, -1.0), (0, 1, 0.9), (0, 2, 0.4)]),
            poly(&[(0, 0, -0.8), (1, 0, 1.1), (3, 0, 0.25), (1, 2, -0.6)]),
        ];
        let parts = [
            (DirichletPart::All, product(&x_sides, &y_sides)),
            (DirichletPart::Markers(vec![4, 2]), x_sides.clone()),
            (DirichletPart::Markers(vec![1]), poly(&[(0, 1, 1.0)])),
        ];
        for element in [ElementKind::Argyris, ElementKind::Morley] {
            let map = DofMap::on_triangles(&m, element);
            for (part, b) in &parts {
                for support in [PlateSupport::SimplySupported, PlateSupport::Clamped] {
                    let b = match support {
                        PlateSupport::SimplySupported => b.clone(),
                        PlateSupport::Clamped => product(b, b),
                    };
                    let fixed = part.plate_dofs(&map, &m, support).unwrap();
                    let functions: Vec<Polynomial2> = r.iter().map(|r| product(&b, r)).collect();
                    for d in map.boundary_dofs(&m) {
                        let largest = functions
                            .iter()
                            .map(|p| dof_value(&map, &m, p, d).abs())
                            .fold(0.0, f64::max);
                        let what = format!("{element:?} {part:?} {support:?} DOF {d}");
                        if fixed.contains(&d) {
                            assert!(largest < 1e-12, "{what} is fixed but {largest}");
                        } else {
                            assert!(largest > 1e-6, "{what} is free but vanishes");
                        }
                    }
                }
            }
        }
    }

    /// A slanted edge rotates the Argyris vertex DOFs instead of being refused: on the
    /// triangle (0,0), (1,0), (0,1) clamped fixes all 21 DOFs (every corner meets two
    /// clamped edges of different directions: the whole gradient and Hessian), simply
    /// supported 5 per corner (the value, the gradient and two Hessian functionals: the
    /// right angle at the origin keeps its Cartesian `u_xy` free without a rotation, the
    /// other two are rotated). Morley takes any edge; other elements are refused.
    #[test]
    fn plate_dofs_of_slanted_edges_and_other_elements() {
        let m = TriangleMesh::new(
            vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
            vec![[0, 1, 2]],
            &[],
        )
        .unwrap();
        let argyris = DofMap::on_triangles(&m, ElementKind::Argyris);
        let clamped = DirichletPart::All
            .plate_dofs(&argyris, &m, PlateSupport::Clamped)
            .unwrap();
        assert_eq!(clamped, (0..21).collect::<Vec<_>>());
        let simply = DirichletPart::All
            .plate_dofs(&argyris, &m, PlateSupport::SimplySupported)
            .unwrap();
        assert_eq!(simply, [0, 1, 2, 3, 5, 6, 7, 8, 9, 10, 12, 13, 14, 15, 16]);
        let mut constraints = Constraints::new();
        constraints
            .support_plate_field(
                &m,
                &argyris,
                0,
                &DirichletPart::All,
                PlateSupport::SimplySupported,
            )
            .unwrap();
        let starts: Vec<usize> = constraints
            .change_of_basis(21)
            .unwrap()
            .blocks()
            .iter()
            .map(|b| b.group.dofs[0])
            .collect();
        assert_eq!(starts, [6, 12]);
        let morley = DofMap::on_triangles(&m, ElementKind::Morley);
        let fixed = DirichletPart::All
            .plate_dofs(&morley, &m, PlateSupport::Clamped)
            .unwrap();
        assert_eq!(fixed, (0..6).collect::<Vec<_>>());
        let p1 = DofMap::on_triangles(&m, ElementKind::P1);
        assert!(DirichletPart::All
            .plate_dofs(&p1, &m, PlateSupport::SimplySupported)
            .is_err());
    }
}
