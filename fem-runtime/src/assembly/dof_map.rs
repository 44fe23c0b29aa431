//! Degrees of freedom: per field on a mesh, and for a system of several fields.
//!
//! On an interval mesh the DOFs of a field are numbered along the mesh: vertex 0,
//! the interior DOFs of cell 0, vertex 1, … so that 1D matrices are banded. On a
//! triangle mesh: all vertex DOFs, then edge DOFs, then interior DOFs.

use crate::element::mapping::Affine;
use crate::error::{Error, Result};
use crate::mesh::{IntervalMesh, Mesh, TriangleMesh};
use crate::model::Model;
use fem_reference::{CellKind, ElementKind};

/// Meshes whose DOFs can be numbered: the link from a mesh's topology (vertices, edges,
/// cells) to the DOF map of an element on it. Kept here rather than on [`Mesh`] so that
/// meshes know nothing of elements and DOFs.
pub trait DofNumbering: Mesh {
    /// Numbers the DOFs of `element` on this mesh.
    fn dof_map(&self, element: ElementKind) -> DofMap;
}

impl DofNumbering for IntervalMesh {
    fn dof_map(&self, element: ElementKind) -> DofMap {
        DofMap::new(self, element)
    }
}

impl DofNumbering for TriangleMesh {
    fn dof_map(&self, element: ElementKind) -> DofMap {
        DofMap::on_triangles(self, element)
    }
}

/// A curved mesh numbers its DOFs as the mesh of its vertices: the DOFs belong to the
/// topology (vertices, edges, cells), not to the geometry.
impl DofNumbering for crate::mesh::CurvedTriangleMesh {
    fn dof_map(&self, element: ElementKind) -> DofMap {
        DofMap::on_triangles(self.mesh(), element)
    }
}

/// The DOFs of one field on a mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct DofMap {
    element: ElementKind,
    cell: CellKind,
    cell_dofs: Vec<usize>,
    /// DOFs per cell, kept: [`DofMap::cell_dofs`] is on every assembly's hot path.
    local: usize,
    dof_count: usize,
    per_vertex: usize,
    per_edge: usize,
    interior: usize,
}

impl DofMap {
    /// Numbers the DOFs of `element` on `mesh`.
    pub fn new(mesh: &IntervalMesh, element: ElementKind) -> Self {
        let per_vertex = element.dofs_per_vertex();
        let interior = element.interior_dof_count();
        let stride = per_vertex + interior;
        let local = element.dof_count();
        let cells = mesh.cell_count();
        let mut cell_dofs = Vec::with_capacity(cells * local);
        for c in 0..cells {
            for v in [c, c + 1] {
                cell_dofs.extend((0..per_vertex).map(|m| v * stride + m));
            }
            cell_dofs.extend((0..interior).map(|m| c * stride + per_vertex + m));
        }
        Self {
            element,
            cell: CellKind::Interval,
            cell_dofs,
            local,
            dof_count: (cells + 1) * per_vertex + cells * interior,
            per_vertex,
            per_edge: 0,
            interior,
        }
    }

    /// Numbers the DOFs of `element` on a triangle mesh. Edge DOFs run from the edge's
    /// lower-numbered vertex, and each cell lists them from its own first vertex of the
    /// edge, so neighbours agree (P3 has two per edge).
    pub fn on_triangles(mesh: &TriangleMesh, element: ElementKind) -> Self {
        let [per_vertex, per_edge, interior] = element.triangle_layout();
        let local = element.local_dof_count(CellKind::Triangle);
        let (vertices, edges, cells) = (mesh.vertex_count(), mesh.edge_count(), mesh.cell_count());
        let edge_base = vertices * per_vertex;
        let interior_base = edge_base + edges * per_edge;
        let mut cell_dofs = Vec::with_capacity(cells * local);
        for c in 0..cells {
            let v = mesh.cell(c);
            for &vertex in &v {
                cell_dofs.extend((0..per_vertex).map(|m| vertex * per_vertex + m));
            }
            let e = mesh.cell_edges(c);
            for k in 0..3 {
                let base = edge_base + e[k] * per_edge;
                let forward = v[k] < v[(k + 1) % 3];
                for m in 0..per_edge {
                    cell_dofs.push(base + if forward { m } else { per_edge - 1 - m });
                }
            }
            cell_dofs.extend((0..interior).map(|m| interior_base + c * interior + m));
        }
        Self {
            element,
            cell: CellKind::Triangle,
            cell_dofs,
            local,
            dof_count: interior_base + cells * interior,
            per_vertex,
            per_edge,
            interior,
        }
    }

    /// The DOFs on the boundary of a triangle mesh (vertex and edge DOFs of boundary
    /// vertices and edges), sorted.
    pub fn boundary_dofs(&self, mesh: &TriangleMesh) -> Vec<usize> {
        if self.cell != CellKind::Triangle {
            return Vec::new();
        }
        let mut out: Vec<usize> = mesh
            .boundary_vertices()
            .into_iter()
            .flat_map(|v| (0..self.per_vertex).map(move |m| v * self.per_vertex + m))
            .collect();
        let edge_base = mesh.vertex_count() * self.per_vertex;
        for &(e, _) in mesh.boundary_edges() {
            out.extend((0..self.per_edge).map(|m| edge_base + e * self.per_edge + m));
        }
        out.sort_unstable();
        out.dedup();
        out
    }

    /// The point each DOF of a Lagrange-type element on a triangle mesh sits at (the
    /// centroid for P0).
    pub fn nodes(&self, mesh: &TriangleMesh) -> Vec<[f64; 2]> {
        if self.element == ElementKind::P1 && self.dof_count == mesh.vertex_count() {
            // DOF v is vertex v: its node is the vertex itself (mapping each cell's
            // corners took 0.03 s per 2M-cell level, on the finest level's critical path)
            return mesh.vertices().to_vec();
        }
        let reference = fem_reference::triangle::lagrange_nodes(self.element.degree());
        let mut nodes = vec![[f64::NAN; 2]; self.dof_count];
        for c in 0..mesh.cell_count() {
            let map = Affine::of(mesh, c);
            for (&dof, &xi) in self.cell_dofs(c).iter().zip(&reference) {
                nodes[dof] = map.point(xi);
            }
        }
        nodes
    }

    /// The physical node of every DOF (Lagrange elements) on a curved mesh: the
    /// reference node mapped by its cell's six-node map, so that on a curved edge the
    /// P2 edge DOF sits at the geometry's edge node (on the exact boundary for
    /// [`crate::mesh::triangle::QuadraticGeometry::circle`]), where the isoparametric
    /// basis function of that DOF is 1. Affine cells give [`DofMap::nodes`].
    pub fn curved_nodes(&self, mesh: &crate::mesh::CurvedTriangleMesh) -> Vec<[f64; 2]> {
        let reference = fem_reference::triangle::lagrange_nodes(self.element.degree());
        let mut nodes = self.nodes(mesh.mesh());
        for c in (0..mesh.mesh().cell_count()).filter(|&c| mesh.is_curved(c)) {
            let map = mesh.cell_map(c);
            for (&dof, &xi) in self.cell_dofs(c).iter().zip(&reference) {
                nodes[dof] = map.point(xi);
            }
        }
        nodes
    }

    /// The element.
    pub fn element(&self) -> ElementKind {
        self.element
    }

    /// Number of DOFs.
    pub fn dof_count(&self) -> usize {
        self.dof_count
    }

    /// Number of DOFs of one cell.
    #[inline]
    pub fn local_count(&self) -> usize {
        self.local
    }

    /// Global DOFs of cell `c`, in the element's local order.
    #[inline]
    pub fn cell_dofs(&self, c: usize) -> &[usize] {
        let n = self.local_count();
        &self.cell_dofs[c * n..(c + 1) * n]
    }

    /// The DOFs at vertex `v` (value first, then slope for Hermite); empty for P0.
    pub fn vertex_dofs(&self, v: usize) -> std::ops::Range<usize> {
        let start = match self.cell {
            CellKind::Interval => v * (self.per_vertex + self.interior),
            CellKind::Triangle => v * self.per_vertex,
        };
        start..start + self.per_vertex
    }
}

/// The DOFs of several fields of a model, stacked field after field.
#[derive(Clone, Debug)]
pub struct SystemDofs {
    fields: Vec<usize>,
    maps: Vec<DofMap>,
    offsets: Vec<usize>,
    total: usize,
}

impl SystemDofs {
    /// DOFs of the given fields of model `M` (by index, in the order given).
    pub fn new<M: Model>(mesh: &impl DofNumbering, fields: &[usize]) -> Result<Self> {
        let mut maps = Vec::new();
        let mut offsets = Vec::new();
        let mut total = 0;
        for (k, &f) in fields.iter().enumerate() {
            let info = M::FIELDS
                .get(f)
                .ok_or_else(|| Error::Input(format!("model `{}` has no field {f}", M::NAME)))?;
            if fields[..k].contains(&f) {
                return Err(Error::Input(format!("field `{}` listed twice", info.name)));
            }
            if M::CELL != mesh.cell_kind() {
                return Err(Error::Input(format!(
                    "model `{}` is posed on {} cells, the mesh has {} cells",
                    M::NAME,
                    M::CELL.name(),
                    mesh.cell_kind().name()
                )));
            }
            let map = mesh.dof_map(info.element);
            offsets.push(total);
            total += map.dof_count();
            maps.push(map);
        }
        Ok(Self {
            fields: fields.to_vec(),
            maps,
            offsets,
            total,
        })
    }

    /// All fields of the model.
    pub fn all<M: Model>(mesh: &impl DofNumbering) -> Result<Self> {
        let fields: Vec<usize> = (0..M::FIELDS.len()).collect();
        Self::new::<M>(mesh, &fields)
    }

    /// Fields by the names of their unknowns.
    pub fn named<M: Model>(mesh: &impl DofNumbering, names: &[&str]) -> Result<Self> {
        let fields = names
            .iter()
            .map(|n| M::field(n))
            .collect::<Result<Vec<_>>>()?;
        Self::new::<M>(mesh, &fields)
    }

    /// Total number of DOFs.
    pub fn dof_count(&self) -> usize {
        self.total
    }

    /// Position of model field `field` in this system, if it is part of it.
    pub fn position(&self, field: usize) -> Option<usize> {
        self.fields.iter().position(|&f| f == field)
    }

    /// The DOF map of model field `field`.
    pub fn map(&self, field: usize) -> Option<&DofMap> {
        self.position(field).map(|k| &self.maps[k])
    }

    /// First global DOF of model field `field`.
    pub fn offset(&self, field: usize) -> Option<usize> {
        self.position(field).map(|k| self.offsets[k])
    }

    /// Global DOF range of model field `field`.
    pub fn range(&self, field: usize) -> Option<std::ops::Range<usize>> {
        let k = self.position(field)?;
        Some(self.offsets[k]..self.offsets[k] + self.maps[k].dof_count())
    }

    /// The model fields in this system.
    pub fn fields(&self) -> &[usize] {
        &self.fields
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neighbours_share_vertex_dofs() {
        let mesh = IntervalMesh::uniform(0.0, 1.0, 3).unwrap();
        let p2 = DofMap::new(&mesh, ElementKind::P2);
        assert_eq!(p2.dof_count(), 7);
        assert_eq!(p2.cell_dofs(0), &[0, 2, 1]);
        assert_eq!(p2.cell_dofs(1), &[2, 4, 3]);
        let hermite = DofMap::new(&mesh, ElementKind::Hermite);
        assert_eq!(hermite.dof_count(), 8);
        assert_eq!(hermite.cell_dofs(1), &[2, 3, 4, 5]);
        assert_eq!(hermite.vertex_dofs(3), 6..8);
        let p0 = DofMap::new(&mesh, ElementKind::P0);
        assert_eq!(p0.dof_count(), 3);
        assert_eq!(p0.cell_dofs(2), &[2]);
        assert!(p0.vertex_dofs(1).is_empty());
        let p3 = DofMap::new(&mesh, ElementKind::P3);
        assert_eq!(p3.dof_count(), 10);
        assert_eq!(p3.cell_dofs(2), &[6, 9, 7, 8]);
    }

    /// Argyris: six DOFs per vertex, then one per edge; a cell's local DOF `6v + k` is
    /// DOF `k` of its vertex `v`, and `18 + k` the DOF of its local edge `k`, which both
    /// cells of an interior edge share whichever way they traverse it.
    #[test]
    fn argyris_numbers_vertex_blocks_and_one_dof_per_edge() {
        let mesh =
            TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 3, 2, crate::mesh::Diagonal::Alternating)
                .unwrap();
        let map = DofMap::on_triangles(&mesh, ElementKind::Argyris);
        let (vertices, edges) = (mesh.vertex_count(), mesh.edge_count());
        assert_eq!(map.local_count(), 21);
        assert_eq!(map.dof_count(), 6 * vertices + edges);
        let mut owners = vec![Vec::new(); edges];
        for c in 0..mesh.cell_count() {
            let dofs = map.cell_dofs(c);
            for (v, &vertex) in mesh.cell(c).iter().enumerate() {
                assert_eq!(
                    &dofs[6 * v..6 * v + 6],
                    &map.vertex_dofs(vertex).collect::<Vec<_>>()[..]
                );
            }
            for (k, &e) in mesh.cell_edges(c).iter().enumerate() {
                assert_eq!(dofs[18 + k], 6 * vertices + e);
                owners[e].push(c);
            }
        }
        let interior = owners.iter().filter(|o| o.len() == 2).count();
        assert_eq!(interior, edges - mesh.boundary_edges().len());
    }
}
