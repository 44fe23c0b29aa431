//! Meshes: the abstraction that assembly needs (cells, their coordinates, diameters and
//! measures: geometry and topology only; DOF numbering lives in [`crate::assembly::dof_map`]),
//! interval meshes, triangle meshes (generators, validation, newest-vertex bisection,
//! point location) and Gmsh files.

pub mod gmsh;
pub mod interval;
pub mod triangle;

pub use interval::IntervalMesh;
pub use triangle::{BoundaryCurve, CurvedTriangleMesh, Diagonal, PointLocator, TriangleMesh};

use fem_reference::CellKind;

/// What assembly needs from a mesh: its cells' vertex coordinates as the element kernels
/// take them, their diameters and measures.
pub trait Mesh: Sync {
    /// The reference cell of every cell.
    const CELL: CellKind;
    /// Number of cells.
    fn cell_count(&self) -> usize;
    /// Writes the vertex coordinates of cell `c` (`x₀ x₁` or `x₀ y₀ x₁ y₁ x₂ y₂`) into `out`.
    fn cell_coordinates_into(&self, c: usize, out: &mut [f64]);
    /// Diameter of cell `c`.
    fn diameter(&self, c: usize) -> f64;
    /// Measure (length or area) of cell `c`.
    fn measure(&self, c: usize) -> f64;
    /// Writes the global vertex numbers of cell `c` into `out` and returns `true`, or
    /// returns `false` for a mesh that has none. Elements with edge DOFs oriented by
    /// global numbers (Argyris, Morley) need them.
    fn cell_vertex_numbers_into(&self, c: usize, out: &mut [usize]) -> bool {
        let _ = (c, out);
        false
    }
    /// The reference cell (`Self::CELL`, callable where the mesh type is not named).
    fn cell_kind(&self) -> CellKind {
        Self::CELL
    }
    /// Whether some cell is curved (a [`triangle::CurvedTriangleMesh`]); `false` by
    /// default, and assembly then takes the generated loop over all cells.
    fn has_curved_cells(&self) -> bool {
        false
    }
    /// For a curved cell `c`, writes the twelve coordinates of its six nodes (the order
    /// of [`crate::element::Isoparametric`]) into `out` and returns `true`; returns
    /// `false` for an affine cell (by default every cell).
    fn curved_cell_nodes_into(&self, c: usize, out: &mut [f64]) -> bool {
        let _ = (c, out);
        false
    }
}

impl Mesh for IntervalMesh {
    const CELL: CellKind = CellKind::Interval;
    fn cell_count(&self) -> usize {
        IntervalMesh::cell_count(self)
    }
    #[inline]
    fn cell_coordinates_into(&self, c: usize, out: &mut [f64]) {
        out[..2].copy_from_slice(&self.cell(c));
    }
    #[inline]
    fn cell_vertex_numbers_into(&self, c: usize, out: &mut [usize]) -> bool {
        out[..2].copy_from_slice(&[c, c + 1]);
        true
    }
    fn diameter(&self, c: usize) -> f64 {
        self.h(c)
    }
    fn measure(&self, c: usize) -> f64 {
        self.h(c)
    }
}

impl Mesh for TriangleMesh {
    const CELL: CellKind = CellKind::Triangle;
    fn cell_count(&self) -> usize {
        TriangleMesh::cell_count(self)
    }
    #[inline]
    fn cell_coordinates_into(&self, c: usize, out: &mut [f64]) {
        out[..6].copy_from_slice(&self.cell_coordinates(c));
    }
    #[inline]
    fn cell_vertex_numbers_into(&self, c: usize, out: &mut [usize]) -> bool {
        out[..3].copy_from_slice(&self.cell(c));
        true
    }
    fn diameter(&self, c: usize) -> f64 {
        self.cell_diameter(c)
    }
    fn measure(&self, c: usize) -> f64 {
        self.area(c)
    }
}
