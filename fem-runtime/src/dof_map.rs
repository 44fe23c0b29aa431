//! Degrees of freedom: per field on a mesh, and for a system of several fields.
//!
//! On an interval mesh the DOFs of a field are numbered along the mesh: vertex 0,
//! the interior DOFs of cell 0, vertex 1, … so that 1D matrices are banded.

use crate::error::{Error, Result};
use crate::mesh::IntervalMesh;
use crate::model::Model;
use fem_reference::ElementKind;

/// The DOFs of one field on a mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct DofMap {
    element: ElementKind,
    cell_dofs: Vec<usize>,
    dof_count: usize,
    per_vertex: usize,
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
            cell_dofs,
            dof_count: (cells + 1) * per_vertex + cells * interior,
            per_vertex,
            interior,
        }
    }

    /// The element.
    pub fn element(&self) -> ElementKind {
        self.element
    }

    /// Number of DOFs.
    pub fn dof_count(&self) -> usize {
        self.dof_count
    }

    /// Global DOFs of cell `c`, in the element's local order.
    #[inline]
    pub fn cell_dofs(&self, c: usize) -> &[usize] {
        let n = self.element.dof_count();
        &self.cell_dofs[c * n..(c + 1) * n]
    }

    /// The DOFs at vertex `v` (value first, then slope for Hermite); empty for P0.
    pub fn vertex_dofs(&self, v: usize) -> std::ops::Range<usize> {
        let start = v * (self.per_vertex + self.interior);
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
    pub fn new<M: Model>(mesh: &IntervalMesh, fields: &[usize]) -> Result<Self> {
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
            let map = DofMap::new(mesh, info.element);
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
    pub fn all<M: Model>(mesh: &IntervalMesh) -> Self {
        let fields: Vec<usize> = (0..M::FIELDS.len()).collect();
        Self::new::<M>(mesh, &fields).expect("every field of a model exists once")
    }

    /// Fields by the names of their unknowns.
    pub fn named<M: Model>(mesh: &IntervalMesh, names: &[&str]) -> Result<Self> {
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
}
