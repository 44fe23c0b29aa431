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
    /// The number of cell `c` in the whole mesh that the DOF maps were built on: `c`
    /// itself, except in a view of some of its cells ([`CellSubset`]), whose cell `c`
    /// is the mesh's cell `cells[c]`. Assembly reads the DOF maps through it.
    #[inline]
    fn cell_number(&self, c: usize) -> usize {
        c
    }
}

/// The cells a sum over a mesh runs over: all of them, or one process's part of a
/// partition (its cells of [`crate::obstacle::Discretization::cells`]), whose sums the
/// processes then add up ([`crate::obstacle::Evaluation`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cells<'a> {
    /// Cells `0..count` of a mesh of `count` cells.
    All(usize),
    /// These cells, by their numbers in the whole mesh.
    Part(&'a [usize]),
}

impl<'a> Cells<'a> {
    /// How many cells.
    pub fn len(self) -> usize {
        match self {
            Cells::All(count) => count,
            Cells::Part(cells) => cells.len(),
        }
    }

    /// Whether there are none.
    pub fn is_empty(self) -> bool {
        self.len() == 0
    }

    /// The cells at positions `positions` of the list (`All`: the cells themselves).
    pub fn slice(self, positions: std::ops::Range<usize>) -> CellIter<'a> {
        match self {
            Cells::All(_) => CellIter::Range(positions),
            Cells::Part(cells) => CellIter::Listed(cells[positions].iter()),
        }
    }

    /// Every cell, in the list's order.
    pub fn iter(self) -> CellIter<'a> {
        self.slice(0..self.len())
    }
}

/// The cells of [`Cells::slice`], by number.
#[derive(Clone, Debug)]
pub enum CellIter<'a> {
    /// A range of cell numbers.
    Range(std::ops::Range<usize>),
    /// A run of a part's list.
    Listed(std::slice::Iter<'a, usize>),
}

impl Iterator for CellIter<'_> {
    type Item = usize;

    #[inline]
    fn next(&mut self) -> Option<usize> {
        match self {
            CellIter::Range(range) => range.next(),
            CellIter::Listed(cells) => cells.next().copied(),
        }
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        match self {
            CellIter::Range(range) => range.size_hint(),
            CellIter::Listed(cells) => cells.size_hint(),
        }
    }
}

/// Some cells of a mesh, as a mesh: what one MPI rank assembles of a partitioned mesh.
/// Its cell `c` is the mesh's cell `cells[c]` ([`Mesh::cell_number`]), so the DOF maps
/// of the whole mesh serve it, and a form assembled on it is the sum of the element
/// contributions of those cells alone: summed over a partition of the cells, the whole
/// form.
#[derive(Clone, Copy, Debug)]
pub struct CellSubset<'a, G> {
    mesh: &'a G,
    cells: Option<&'a [usize]>,
}

impl<'a, G: Mesh> CellSubset<'a, G> {
    /// The cells `cells` of `mesh` (`None`: all of them, in order).
    ///
    /// # Panics
    /// Never here; a cell number beyond the mesh's makes the accessors panic, so callers
    /// check them ([`crate::obstacle::Discretization::with_constraints_on`] does).
    pub fn new(mesh: &'a G, cells: Option<&'a [usize]>) -> Self {
        Self { mesh, cells }
    }

    /// The whole mesh.
    pub fn mesh(&self) -> &'a G {
        self.mesh
    }
}

impl<G: Mesh> Mesh for CellSubset<'_, G> {
    const CELL: CellKind = G::CELL;
    #[inline]
    fn cell_count(&self) -> usize {
        self.cells.map_or(self.mesh.cell_count(), <[usize]>::len)
    }
    #[inline]
    fn cell_number(&self, c: usize) -> usize {
        self.mesh
            .cell_number(self.cells.map_or(c, |cells| cells[c]))
    }
    #[inline]
    fn cell_coordinates_into(&self, c: usize, out: &mut [f64]) {
        self.mesh
            .cell_coordinates_into(self.cells.map_or(c, |cells| cells[c]), out)
    }
    fn diameter(&self, c: usize) -> f64 {
        self.mesh.diameter(self.cells.map_or(c, |cells| cells[c]))
    }
    fn measure(&self, c: usize) -> f64 {
        self.mesh.measure(self.cells.map_or(c, |cells| cells[c]))
    }
    #[inline]
    fn cell_vertex_numbers_into(&self, c: usize, out: &mut [usize]) -> bool {
        self.mesh
            .cell_vertex_numbers_into(self.cells.map_or(c, |cells| cells[c]), out)
    }
    fn has_curved_cells(&self) -> bool {
        self.mesh.has_curved_cells()
    }
    #[inline]
    fn curved_cell_nodes_into(&self, c: usize, out: &mut [f64]) -> bool {
        self.mesh
            .curved_cell_nodes_into(self.cells.map_or(c, |cells| cells[c]), out)
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
