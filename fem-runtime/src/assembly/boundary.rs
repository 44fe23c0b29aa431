//! Boundary conditions as fixed DOFs, applied by eliminating them from the system.
//!
//! Elimination keeps a symmetric matrix symmetric (and SPD stays SPD), which the
//! Cholesky solve and the active-set solvers rely on.

use crate::assembly::dof_map::{DofMap, SystemDofs};
use crate::error::{Error, Result};
use crate::mesh::{IntervalMesh, TriangleMesh};
use crate::model::Model;
use crate::SparseMatrix;
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use fem_reference::{DofLocation, ElementKind};

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
            let Some(k) = mesh.cell_edges(c).iter().position(|&x| x == e) else {
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

/// Argyris vertex DOFs (local order `u, u_x, u_y, u_xx, u_xy, u_yy`) fixed on a straight
/// boundary edge along x (`horizontal`) or along y: `w = 0` fixes the value and the first
/// and second tangential derivatives; `∂_n w = 0` the normal derivative and its tangential
/// derivative, the mixed one. The normal second derivative stays free.
fn argyris_vertex_kinds(support: PlateSupport, horizontal: bool) -> &'static [usize] {
    match (support, horizontal) {
        (PlateSupport::SimplySupported, true) => &[0, 1, 3],
        (PlateSupport::SimplySupported, false) => &[0, 2, 5],
        (PlateSupport::Clamped, true) => &[0, 1, 3, 2, 4],
        (PlateSupport::Clamped, false) => &[0, 2, 5, 1, 4],
    }
}

impl DirichletPart {
    /// The DOFs of the plate field `map` (Argyris or Morley on `mesh`) fixed to zero by
    /// `support` on the part's edges, sorted and unique.
    ///
    /// Argyris, on every edge of the part and at both its end points: the value `u`,
    /// the tangential derivative and the tangential second derivative (`u_x`, `u_xx` on
    /// an edge along x; `u_y`, `u_yy` along y); clamped also the normal derivative
    /// (`u_y`, resp. `u_x`), the mixed derivative `u_xy` (the tangential derivative of
    /// `∂_n u`) and the edge's normal-derivative DOF. These are exactly the conditions
    /// `w = 0` (and `∂_n w = 0`) on the edge imposes on the DOFs: the trace of an
    /// Argyris function on an edge is the quintic fixed by `u, ∂_t u, ∂_tt u` at its end
    /// points, and its normal derivative the quartic fixed by `∂_n u, ∂_tn u` there and
    /// the midpoint DOF. At a corner where two edges of the part meet, the union holds:
    /// all six DOFs when both are clamped, all but `u_xy` when both are simply supported.
    /// Morley: the vertex values, clamped also the edge normal DOFs.
    ///
    /// # Errors
    /// [`Error::Input`] for another element, and (Argyris) for an edge of the part that
    /// is neither along x nor along y: the vertex DOFs are Cartesian, and fixing a
    /// tangential derivative along another direction would need a rotation of them to
    /// normal/tangential components, which is not implemented.
    pub fn plate_dofs(
        &self,
        map: &DofMap,
        mesh: &TriangleMesh,
        support: PlateSupport,
    ) -> Result<Vec<usize>> {
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
        let mut out = Vec::new();
        for &(e, m) in mesh.boundary_edges() {
            if !self.contains(m) {
                continue;
            }
            let [a, b] = mesh.edges()[e];
            let kinds: &[usize] = if argyris {
                let (p, q) = (mesh.vertices()[a], mesh.vertices()[b]);
                let t = [q[0] - p[0], q[1] - p[1]];
                let length = t[0].hypot(t[1]);
                if t[1].abs() <= 1e-10 * length {
                    argyris_vertex_kinds(support, true)
                } else if t[0].abs() <= 1e-10 * length {
                    argyris_vertex_kinds(support, false)
                } else {
                    return Err(Error::Input(format!(
                        "boundary edge {e} (marker {m}) from ({}, {}) to ({}, {}) is neither along x nor along y: plate supports on Argyris fix tangential derivatives, and the vertex DOFs are x/y components (a rotation to the edge's direction is not implemented)",
                        p[0], p[1], q[0], q[1]
                    )));
                }
            } else {
                &[0]
            };
            for v in [a, b] {
                let start = map.vertex_dofs(v).start;
                out.extend(kinds.iter().map(|&k| start + k));
            }
            if support == PlateSupport::Clamped {
                // the edge's normal-derivative DOF, found through a cell as in `dofs`
                let (c, _) = mesh.edge_cells(e);
                if let Some(k) = mesh.cell_edges(c).iter().position(|&x| x == e) {
                    out.push(map.cell_dofs(c)[3 * per_vertex + k]);
                }
            }
        }
        out.sort_unstable();
        out.dedup();
        Ok(out)
    }
}

/// Fixed DOFs with their values.
#[derive(Clone, Debug, Default)]
pub struct Constraints {
    fixed: Vec<(usize, f64)>,
}

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
    /// boundary of `mesh`: the DOFs of [`DirichletPart::plate_dofs`] are fixed to zero.
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
        for d in part.plate_dofs(map, mesh, support)? {
            self.fixed.push((offset + d, 0.0));
        }
        Ok(())
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

    /// The fixed DOFs and their values.
    pub fn fixed(&self) -> &[(usize, f64)] {
        &self.fixed
    }

    /// The elimination for a system of `n` DOFs.
    pub fn reduction(&self, n: usize) -> Result<Reduction> {
        let mut value = vec![None; n];
        for &(d, v) in &self.fixed {
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
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::new();
        let mut values = Vec::new();
        col_ptr.push(0);
        let (col_ptrs, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
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

    /// Argyris needs edges along x or y (the vertex DOFs are not rotated); Morley takes
    /// any edge; other elements are refused.
    #[test]
    fn plate_dofs_refuse_slanted_edges_and_other_elements() {
        let m = TriangleMesh::new(
            vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
            vec![[0, 1, 2]],
            &[],
        )
        .unwrap();
        let argyris = DofMap::on_triangles(&m, ElementKind::Argyris);
        let message = DirichletPart::All
            .plate_dofs(&argyris, &m, PlateSupport::Clamped)
            .unwrap_err()
            .to_string();
        assert!(message.contains("neither along x nor along y"), "{message}");
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
