//! Global assembly of generated element kernels into faer sparse matrices.
//!
//! The sparsity pattern of a form on a mesh is built once ([`MatrixAssembler::new`]),
//! together with the position in the value array of every element-matrix entry; each
//! assembly then only zeroes the values and adds the element matrices in place.

pub mod boundary;
pub mod change_of_basis;
pub mod dof_map;
pub mod kernel;
pub mod linear_problem;

use crate::assembly::dof_map::{DofMap, SystemDofs};
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::model::{Coefficients, IntoFormIndex, Model};
use crate::SparseMatrix;
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use kernel::{Accumulator, Position};

/// One block of a form on a system of DOFs: which fields, the element-matrix size and
/// the fields' offsets in the system numbering.
#[derive(Clone, Debug)]
pub(crate) struct BlockPlan {
    pub(crate) block: usize,
    pub(crate) test_field: usize,
    pub(crate) trial_field: usize,
    pub(crate) rows: usize,
    pub(crate) cols: usize,
    pub(crate) row_offset: usize,
    pub(crate) col_offset: usize,
}

/// The block plans of form `form` of `M` on `dofs` (an error if the form's arity is not
/// the one asked for, or it couples a field the system leaves out).
pub(crate) fn block_plans<M: Model>(
    form: usize,
    dofs: &SystemDofs,
    bilinear: bool,
) -> Result<Vec<BlockPlan>> {
    let info = &M::FORMS[form];
    let expected = if bilinear { 2 } else { 1 };
    if info.arity != expected {
        return Err(Error::Input(format!(
            "form `{}` of `{}` is {}, not {}",
            info.name,
            M::NAME,
            if info.arity == 2 {
                "bilinear"
            } else {
                "linear"
            },
            if bilinear { "bilinear" } else { "linear" },
        )));
    }
    info.blocks
        .iter()
        .enumerate()
        .map(|(b, block)| {
            let trial_field = block.trial_field.unwrap_or(block.test_field);
            let missing = [block.test_field, trial_field]
                .into_iter()
                .find(|&f| dofs.position(f).is_none());
            if let Some(f) = missing {
                return Err(Error::Input(format!(
                    "form `{}` couples field `{}`, which this system leaves out",
                    info.name,
                    M::FIELDS[f].name
                )));
            }
            Ok(BlockPlan {
                block: b,
                test_field: block.test_field,
                trial_field,
                rows: M::FIELDS[block.test_field].element.local_dof_count(M::CELL),
                cols: M::FIELDS[trial_field].element.local_dof_count(M::CELL),
                row_offset: dofs.offset(block.test_field).unwrap(),
                col_offset: dofs.offset(trial_field).unwrap(),
            })
        })
        .collect()
}

/// Visits `(row, column)` of every element-matrix entry of `plans` on every cell of
/// `mesh`, in assembly order (the order the generated kernels add them in). Generic,
/// not `dyn`: pattern builders call it for every entry, several times.
pub(crate) fn for_each_entry<G: Mesh>(
    mesh: &G,
    dofs: &SystemDofs,
    plans: &[BlockPlan],
    mut visit: impl FnMut(usize, usize),
) {
    let maps: Vec<_> = plans
        .iter()
        .map(|p| {
            (
                dofs.map(p.test_field).unwrap(),
                dofs.map(p.trial_field).unwrap(),
            )
        })
        .collect();
    for c in 0..mesh.cell_count() {
        let number = mesh.cell_number(c);
        for (plan, (test, trial)) in plans.iter().zip(&maps) {
            let (rows, cols) = (test.cell_dofs(number), trial.cell_dofs(number));
            for &r in rows {
                for &col in cols {
                    visit(r + plan.row_offset, col + plan.col_offset);
                }
            }
        }
    }
}

/// Adds the element matrices of `plan`'s block of bilinear `form` over all cells of
/// `mesh` into `values` (entry `(i, j)` of cell `c` at
/// `positions[c·stride + offset + i·cols + j]`).
///
/// A mesh without curved cells takes the generated loop ([`Model::add_element_matrices`]);
/// on a [`crate::mesh::CurvedTriangleMesh`] each curved cell gets
/// [`Model::element_matrix_curved`] and each affine cell the affine kernel, one cell at
/// a time.
///
/// # Errors
/// Those of [`Model::element_matrix_curved`] (a block with no kernel on curved cells).
#[allow(clippy::too_many_arguments)]
pub(crate) fn add_block_matrices<M: Model, G: Mesh>(
    form: usize,
    plan: &BlockPlan,
    mesh: &G,
    coefficients: &Coefficients,
    positions: &[Position],
    stride: usize,
    offset: usize,
    values: &mut Accumulator,
) -> Result<()> {
    let (params, data) = (&coefficients.params, &coefficients.data);
    if !mesh.has_curved_cells() {
        M::add_element_matrices(
            form, plan.block, mesh, params, data, positions, stride, offset, values,
        );
        return Ok(());
    }
    let size = plan.rows * plan.cols;
    let mut local = vec![0.0; size];
    let (mut x, mut nodes, mut g) = ([0.0; 6], [0.0; 12], [0usize; 3]);
    for c in 0..mesh.cell_count() {
        if mesh.curved_cell_nodes_into(c, &mut nodes) {
            M::element_matrix_curved(form, plan.block, &nodes, params, data, &mut local)?;
        } else {
            mesh.cell_coordinates_into(c, &mut x);
            if mesh.cell_vertex_numbers_into(c, &mut g) {
                M::element_matrix_on_cell(form, plan.block, &x, &g, params, data, &mut local);
            } else {
                M::element_matrix(form, plan.block, &x, params, data, &mut local);
            }
        }
        let at = &positions[c * stride + offset..][..size];
        for (&p, &v) in at.iter().zip(&local) {
            values.add(p as usize, v);
        }
    }
    Ok(())
}

/// The fewest blocks from which [`add_form_matrices`] visits the cells once for all
/// blocks instead of once per block. Each per-block pass reads the mesh and the
/// strided positions again and scatters into the whole value array again: for the
/// Mindlin plate's 12 blocks the passes cost 3.3 µs per triangle against 0.35 µs for
/// one pass (benches/mindlin.rs, docs/mathematics.md §9), while a block or two keep the
/// generated loop, whose kernel is inlined into it.
pub const CELL_MAJOR_MIN_BLOCKS: usize = 3;

/// Adds the element matrices of all `plans` (blocks of bilinear `form`) over all cells
/// of `mesh` into `values`, entry `(i, j)` of block `b` on cell `c` at
/// `positions[c·stride + offset_b + i·cols_b + j]` with `stride` the sum of the blocks'
/// sizes and `offset_b` the sizes of the blocks before `b`.
///
/// # Errors
/// Those of [`add_block_matrices`].
pub(crate) fn add_form_matrices<M: Model, G: Mesh>(
    form: usize,
    plans: &[BlockPlan],
    mesh: &G,
    coefficients: &Coefficients,
    positions: &[Position],
    values: &mut Accumulator,
) -> Result<()> {
    let stride: usize = plans.iter().map(|p| p.rows * p.cols).sum();
    if plans.len() < CELL_MAJOR_MIN_BLOCKS {
        let mut offset = 0;
        for plan in plans {
            add_block_matrices::<M, G>(
                form,
                plan,
                mesh,
                coefficients,
                positions,
                stride,
                offset,
                values,
            )?;
            offset += plan.rows * plan.cols;
        }
        return Ok(());
    }
    let (params, data) = (&coefficients.params, &coefficients.data);
    let curved = mesh.has_curved_cells();
    let largest = plans.iter().map(|p| p.rows * p.cols).max().unwrap_or(0);
    let mut local = vec![0.0; largest];
    // the kernels take exactly the cell's vertex coordinates (and numbers)
    let dimension = G::CELL.dimension();
    let (vertices, coordinates) = (dimension + 1, (dimension + 1) * dimension);
    let (mut x_all, mut nodes, mut g_all) = ([0.0; 6], [0.0; 12], [0usize; 3]);
    let x = &mut x_all[..coordinates];
    let g = &mut g_all[..vertices];
    for c in 0..mesh.cell_count() {
        let on_curved = curved && mesh.curved_cell_nodes_into(c, &mut nodes);
        let numbered = !on_curved && {
            mesh.cell_coordinates_into(c, x);
            mesh.cell_vertex_numbers_into(c, g)
        };
        let cell = &positions[c * stride..][..stride];
        let mut offset = 0;
        for plan in plans {
            let size = plan.rows * plan.cols;
            let out = &mut local[..size];
            if on_curved {
                M::element_matrix_curved(form, plan.block, &nodes, params, data, out)?;
            } else if numbered {
                M::element_matrix_on_cell(form, plan.block, x, g, params, data, out);
            } else {
                M::element_matrix(form, plan.block, x, params, data, out);
            }
            for (&p, &v) in cell[offset..offset + size].iter().zip(out.iter()) {
                values.add(p as usize, v);
            }
            offset += size;
        }
    }
    Ok(())
}

/// Meshes with fewer cells than this are assembled on the calling thread: below it the
/// rayon dispatch (a few µs per colour) is a visible share of a P1 assembly.
pub const PARALLEL_MIN_CELLS: usize = 4096;

/// Cells per chunk at least: a chunk is a run of consecutive cells assembled by one
/// thread, long enough that the generated loop runs at full speed and that on a mesh
/// numbered row by row chunk `k` and chunk `k + 2` share no vertex (two colours).
const MIN_CHUNK_CELLS: usize = 1024;

/// Chunks aimed at (fewer on small meshes): several per thread per colour, so that
/// threads finishing early take another chunk.
const TARGET_CHUNKS: usize = 32;

/// The cells of a mesh cut into chunks of consecutive cells, the chunks greedily coloured
/// so that two chunks of one colour share no mesh vertex.
///
/// Every DOF of the elements here sits on a vertex, an edge or a cell interior
/// (`dof_map`), so two cells that share a DOF share a vertex; chunks of one colour
/// therefore share no DOF, hence no matrix or vector entry, and can be added in parallel.
/// Built once per [`MatrixAssembler`]; `O(cells)` time and one `u64` per vertex.
#[derive(Clone, Debug, Default)]
pub(crate) struct CellColouring {
    /// Chunk `k` is the cells `bounds[k]..bounds[k + 1]`.
    bounds: Vec<usize>,
    /// The chunks of colour `c` are `chunks[colour_ptr[c]..colour_ptr[c + 1]]`.
    colour_ptr: Vec<usize>,
    chunks: Vec<usize>,
}

impl CellColouring {
    /// The colouring of `mesh`'s cells, or `None` where the parallel path does not apply:
    /// fewer than [`PARALLEL_MIN_CELLS`] cells, a mesh without vertex numbers, or more
    /// than 64 colours (a mesh numbered at random; the serial loop is then as fast).
    pub(crate) fn new<G: Mesh>(mesh: &G) -> Option<Self> {
        let cells = mesh.cell_count();
        if cells < PARALLEL_MIN_CELLS {
            return None;
        }
        let vertices = G::CELL.dimension() + 1;
        let mut g = [0usize; 3];
        let g = &mut g[..vertices];
        let chunk = (cells / TARGET_CHUNKS).max(MIN_CHUNK_CELLS);
        let count = cells.div_ceil(chunk);
        let bounds: Vec<usize> = (0..=count).map(|k| (k * chunk).min(cells)).collect();
        // colours used by the chunks touching each vertex so far, one bit per colour
        let mut used: Vec<u64> = Vec::new();
        let mut colour_of = Vec::with_capacity(count);
        for k in 0..count {
            let mut forbidden = 0u64;
            for c in bounds[k]..bounds[k + 1] {
                if !mesh.cell_vertex_numbers_into(c, g) {
                    return None;
                }
                for &v in g.iter() {
                    forbidden |= used.get(v).copied().unwrap_or(0);
                }
            }
            if forbidden == u64::MAX {
                return None;
            }
            let colour = forbidden.trailing_ones() as usize;
            for c in bounds[k]..bounds[k + 1] {
                mesh.cell_vertex_numbers_into(c, g);
                for &v in g.iter() {
                    if v >= used.len() {
                        used.resize(v + 1, 0);
                    }
                    used[v] |= 1 << colour;
                }
            }
            colour_of.push(colour);
        }
        let colours = colour_of.iter().max().map_or(0, |&c| c + 1);
        let mut colour_ptr = vec![0usize; colours + 1];
        for &c in &colour_of {
            colour_ptr[c + 1] += 1;
        }
        for c in 0..colours {
            colour_ptr[c + 1] += colour_ptr[c];
        }
        let mut fill = colour_ptr.clone();
        let mut chunks = vec![0; count];
        for (k, &c) in colour_of.iter().enumerate() {
            chunks[fill[c]] = k;
            fill[c] += 1;
        }
        Some(Self {
            bounds,
            colour_ptr,
            chunks,
        })
    }

    /// Number of colours.
    pub(crate) fn colour_count(&self) -> usize {
        self.colour_ptr.len().saturating_sub(1)
    }

    /// The cell ranges of colour `c`.
    fn ranges(&self, c: usize) -> impl Iterator<Item = std::ops::Range<usize>> + '_ {
        self.chunks[self.colour_ptr[c]..self.colour_ptr[c + 1]]
            .iter()
            .map(|&k| self.bounds[k]..self.bounds[k + 1])
    }
}

/// The consecutive cells `start..start + count` of a mesh, as a mesh: the generated cell
/// loop ([`Model::add_element_matrices`]) runs on it unchanged, kernel inlined, one chunk
/// of a [`CellColouring`] at a time.
struct CellRange<'a, G> {
    mesh: &'a G,
    start: usize,
    count: usize,
}

impl<G: Mesh> Mesh for CellRange<'_, G> {
    const CELL: fem_reference::CellKind = G::CELL;
    #[inline]
    fn cell_count(&self) -> usize {
        self.count
    }
    #[inline]
    fn cell_coordinates_into(&self, c: usize, out: &mut [f64]) {
        self.mesh.cell_coordinates_into(self.start + c, out)
    }
    fn diameter(&self, c: usize) -> f64 {
        self.mesh.diameter(self.start + c)
    }
    fn measure(&self, c: usize) -> f64 {
        self.mesh.measure(self.start + c)
    }
    #[inline]
    fn cell_vertex_numbers_into(&self, c: usize, out: &mut [usize]) -> bool {
        self.mesh.cell_vertex_numbers_into(self.start + c, out)
    }
    fn has_curved_cells(&self) -> bool {
        self.mesh.has_curved_cells()
    }
    #[inline]
    fn curved_cell_nodes_into(&self, c: usize, out: &mut [f64]) -> bool {
        self.mesh.curved_cell_nodes_into(self.start + c, out)
    }
    #[inline]
    fn cell_number(&self, c: usize) -> usize {
        self.mesh.cell_number(self.start + c)
    }
}

/// A value array shared by the threads of one colour, each adding into entries no
/// other thread of that colour touches, through an [`Accumulator`] of its own.
#[derive(Clone, Copy)]
struct SharedValues {
    start: *mut f64,
    len: usize,
}

// SAFETY: the pointer is only turned into accumulators (`SharedValues::accumulator`),
// whose contract the callers keep; sending or sharing the address itself is harmless.
unsafe impl Send for SharedValues {}
unsafe impl Sync for SharedValues {}

impl SharedValues {
    fn of(values: &mut [f64]) -> Self {
        Self {
            start: values.as_mut_ptr(),
            len: values.len(),
        }
    }

    /// An accumulator over the whole array for one thread.
    ///
    /// # Safety
    /// The array must outlive the accumulator and be accessed through accumulators alone
    /// meanwhile, and no two threads may add to one entry concurrently (see
    /// `add_form_matrices_coloured`).
    unsafe fn accumulator<'a>(&self) -> Accumulator<'a> {
        // SAFETY: the caller's contract is the accumulator's.
        unsafe { Accumulator::shared(self.start, self.len) }
    }
}

/// [`add_form_matrices`] with the cells split by `colouring` (built from the same mesh):
/// the colours one after the other, the chunks of a colour in parallel on the current
/// rayon pool. Without a colouring, the serial loop.
///
/// `positions` must map two cells that share no vertex to disjoint value entries (true of
/// a pattern built by [`MatrixAssembler::new`]: an entry is a pair of DOFs of the cell).
/// Each entry then receives its terms in the same order on any number of threads (colour
/// by colour, cell by cell within a chunk), so the result is the same to the last bit,
/// one thread included; it equals the serial loop's up to rounding (the terms come in
/// another order).
///
/// # Errors
/// Those of [`add_form_matrices`], from the first failing chunk rayon reports.
pub(crate) fn add_form_matrices_coloured<M: Model, G: Mesh>(
    form: usize,
    plans: &[BlockPlan],
    mesh: &G,
    coefficients: &Coefficients,
    positions: &[Position],
    values: &mut [f64],
    colouring: Option<&CellColouring>,
) -> Result<()> {
    use rayon::prelude::*;
    let colouring = match colouring {
        // in colour order on one thread too: the same sums as on two, to the last bit
        Some(c) if c.bounds.last() == Some(&mesh.cell_count()) => c,
        _ => {
            return add_form_matrices::<M, G>(
                form,
                plans,
                mesh,
                coefficients,
                positions,
                &mut Accumulator::new(values),
            )
        }
    };
    let stride: usize = plans.iter().map(|p| p.rows * p.cols).sum();
    let shared = SharedValues::of(values);
    for colour in 0..colouring.colour_count() {
        let ranges: Vec<_> = colouring.ranges(colour).collect();
        ranges.into_par_iter().try_for_each(|range| {
            let part = CellRange {
                mesh,
                start: range.start,
                count: range.len(),
            };
            let at = &positions[range.start * stride..range.end * stride];
            // SAFETY: `shared` is `values`, borrowed mutably for this whole call and
            // touched by accumulators alone; the chunks of this colour share no vertex,
            // hence (see above) no entry of `values`: no two threads add to one element,
            // and the loop joins before the next colour starts.
            let mut out = unsafe { shared.accumulator() };
            add_form_matrices::<M, _>(form, plans, &part, coefficients, at, &mut out)
        })?;
    }
    Ok(())
}

/// Assembles one bilinear form of a model on a mesh, reusing its sparsity pattern.
///
/// Meshes of at least [`PARALLEL_MIN_CELLS`] cells are assembled in parallel on the
/// current rayon pool (cells coloured once here, see `CellColouring`), colour by colour
/// on any number of threads: the result is the same to the last bit on one thread as on
/// several.
#[derive(Clone, Debug)]
pub struct MatrixAssembler {
    form: usize,
    plans: Vec<BlockPlan>,
    symbolic: SymbolicSparseColMat<usize>,
    positions: Vec<Position>,
    colouring: Option<CellColouring>,
}

/// The sparsity pattern of `plans` on `mesh` (column pointers and sorted row indices,
/// no duplicates) and the position in the value array of every element-matrix entry,
/// in [`for_each_entry`] order.
///
/// A column's rows are the test DOFs of the cells that hold its DOF, from the cells
/// around every trial DOF (4 bytes per cell and local DOF), deduplicated by a stamp per
/// row and sorted (a handful per column); then each entry's position is found by a
/// binary search in its column, written in assembly order. This replaces bucketing
/// every entry by column first (at 2M P1 cells, 18M entries: 144 MB written in
/// scattered order and sorted): 96 MB less memory touched in the setup of the finest
/// level, whose first touches cost about 1 GB/s here (issue 15, `docs/multigrid.md`).
///
/// Errors: a mesh of more than `u32::MAX` cells.
fn pattern_by_incidence<G: Mesh>(
    mesh: &G,
    dofs: &SystemDofs,
    plans: &[BlockPlan],
) -> Result<(Vec<usize>, Vec<usize>, Vec<Position>)> {
    let n = dofs.dof_count();
    let cells = mesh.cell_count();
    if u32::try_from(cells).is_err() {
        return Err(Error::Input(format!(
            "a mesh of {cells} cells: the assembly numbers cells in 32 bits"
        )));
    }
    // the cells around every DOF of every trial field
    let mut trial_fields: Vec<usize> = plans.iter().map(|p| p.trial_field).collect();
    trial_fields.sort_unstable();
    trial_fields.dedup();
    let mut incidence_ptr = vec![0usize; n + 1];
    for &f in &trial_fields {
        let (map, offset) = (dofs.map(f).unwrap(), dofs.offset(f).unwrap());
        for c in 0..cells {
            for &d in map.cell_dofs(mesh.cell_number(c)) {
                incidence_ptr[offset + d + 1] += 1;
            }
        }
    }
    for j in 0..n {
        incidence_ptr[j + 1] += incidence_ptr[j];
    }
    let mut fill = incidence_ptr.clone();
    let mut incidence = vec![0u32; incidence_ptr[n]];
    for &f in &trial_fields {
        let (map, offset) = (dofs.map(f).unwrap(), dofs.offset(f).unwrap());
        for c in 0..cells {
            for &d in map.cell_dofs(mesh.cell_number(c)) {
                let slot = &mut fill[offset + d];
                incidence[*slot] = c as u32;
                *slot += 1;
            }
        }
    }
    drop(fill);
    // the columns field by field (in system order), each with the row offsets and test
    // maps of the blocks whose trial field it is
    let mut fields: Vec<usize> = dofs.fields().to_vec();
    fields.sort_by_key(|&f| dofs.offset(f));
    type Acting<'a> = Vec<(usize, &'a DofMap)>;
    let field_plans: Vec<(std::ops::Range<usize>, Acting)> = fields
        .iter()
        .map(|&f| {
            let acting = plans
                .iter()
                .filter(|p| p.trial_field == f)
                .map(|p| (p.row_offset, dofs.map(p.test_field).unwrap()))
                .collect();
            (dofs.range(f).unwrap(), acting)
        })
        .collect();
    // `stamp[r] == j` once row `r` is seen in column `j`
    let mut stamp = vec![usize::MAX; n];
    let mut col_ptr = vec![0usize; n + 1];
    // the distinct counts first, so that the pattern (kept with every matrix assembled
    // from it) is allocated to its exact size (issue 15, peak memory)
    for (range, acting) in &field_plans {
        for j in range.clone() {
            let mut distinct = 0;
            for &c in &incidence[incidence_ptr[j]..incidence_ptr[j + 1]] {
                for &(row_offset, test) in acting {
                    for &r in test.cell_dofs(mesh.cell_number(c as usize)) {
                        if std::mem::replace(&mut stamp[r + row_offset], j) != j {
                            distinct += 1;
                        }
                    }
                }
            }
            col_ptr[j + 1] = col_ptr[j] + distinct;
        }
    }
    stamp.fill(usize::MAX);
    let mut row_idx = Vec::with_capacity(col_ptr[n]);
    for (range, acting) in &field_plans {
        for j in range.clone() {
            let start = row_idx.len();
            for &c in &incidence[incidence_ptr[j]..incidence_ptr[j + 1]] {
                for &(row_offset, test) in acting {
                    for &r in test.cell_dofs(mesh.cell_number(c as usize)) {
                        if std::mem::replace(&mut stamp[r + row_offset], j) != j {
                            row_idx.push(r + row_offset);
                        }
                    }
                }
            }
            row_idx[start..].sort_unstable();
        }
    }
    drop((stamp, incidence, incidence_ptr));
    // in assembly order, so that the positions are written in sequence (scattering
    // them column by column measured slower at 2M cells: a cell's entries are written
    // from columns far apart)
    let stride: usize = plans.iter().map(|p| p.rows * p.cols).sum();
    kernel::position(row_idx.len())?;
    let mut positions = Vec::with_capacity(cells * stride);
    for_each_entry(mesh, dofs, plans, |row, col| {
        let column = &row_idx[col_ptr[col]..col_ptr[col + 1]];
        let k = column
            .binary_search(&row)
            .expect("every entry is in the pattern");
        // below row_idx.len(), checked above
        positions.push((col_ptr[col] + k) as Position);
    });
    Ok((col_ptr, row_idx, positions))
}

impl MatrixAssembler {
    /// Builds the pattern of bilinear form `form_name` of `M` on the system `dofs`.
    pub fn new<M: Model>(
        form_name: impl IntoFormIndex<M>,
        mesh: &impl Mesh,
        dofs: &SystemDofs,
    ) -> Result<Self> {
        let form = M::form(form_name)?;
        let plans = block_plans::<M>(form, dofs, true)?;
        let (col_ptr, row_idx, positions) = pattern_by_incidence(mesh, dofs, &plans)?;
        let n = dofs.dof_count();
        let symbolic = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        Ok(Self {
            form,
            plans,
            symbolic,
            positions,
            colouring: CellColouring::new(mesh),
        })
    }

    /// The sparsity pattern.
    pub fn symbolic(&self) -> &SymbolicSparseColMat<usize> {
        &self.symbolic
    }

    /// Number of stored entries.
    pub fn nonzero_count(&self) -> usize {
        self.symbolic.row_idx().len()
    }

    /// Fills `values` (resized to the pattern) with the assembled matrix.
    pub fn assemble_values<M: Model>(
        &self,
        mesh: &impl Mesh,
        coefficients: &Coefficients,
        values: &mut Vec<f64>,
    ) -> Result<()> {
        values.clear();
        values.resize(self.nonzero_count(), 0.0);
        add_form_matrices_coloured::<M, _>(
            self.form,
            &self.plans,
            mesh,
            coefficients,
            &self.positions,
            values,
            self.colouring.as_ref(),
        )?;
        if let Some(bad) = values.iter().position(|v| !v.is_finite()) {
            let cell = self
                .positions
                .iter()
                .position(|&p| p as usize == bad)
                .unwrap_or(0);
            let per_cell: usize = self.plans.iter().map(|p| p.rows * p.cols).sum();
            return Err(Error::NonFinite {
                what: "matrix",
                cell: cell / per_cell.max(1),
            });
        }
        Ok(())
    }

    /// The assembled matrix.
    pub fn assemble<M: Model>(
        &self,
        mesh: &impl Mesh,
        coefficients: &Coefficients,
    ) -> Result<SparseMatrix> {
        let mut values = Vec::new();
        self.assemble_values::<M>(mesh, coefficients, &mut values)?;
        Ok(SparseColMat::new(self.symbolic.clone(), values))
    }

    /// The assembled matrix, as [`MatrixAssembler::assemble`], for a pattern used once:
    /// the matrix takes the assembler's pattern over instead of a copy, and the
    /// assembler's scatter positions (one index per cell entry) are freed first (at 2M
    /// P1 cells 66 MB and 150 MB less held at once; issue 15, peak memory).
    ///
    /// # Errors
    /// As [`MatrixAssembler::assemble`].
    pub fn into_matrix<M: Model>(
        self,
        mesh: &impl Mesh,
        coefficients: &Coefficients,
    ) -> Result<SparseMatrix> {
        let mut values = Vec::new();
        self.assemble_values::<M>(mesh, coefficients, &mut values)?;
        let Self { symbolic, .. } = self;
        Ok(SparseColMat::new(symbolic, values))
    }
}

/// Assembles linear form `form_name` of `M` on the system `dofs`.
///
/// Meshes of at least [`PARALLEL_MIN_CELLS`] cells are assembled in parallel on the
/// current rayon pool (the cells coloured per call, `CellColouring`: `O(cells)`, small
/// against the kernels), colour by colour on any number of threads, so the result is the
/// same to the last bit on one thread as on several. An error
/// is the one of the serial loop (on an error the vector is assembled again serially, so
/// the cell named is the first one at fault).
pub fn assemble_vector<M: Model>(
    form_name: impl IntoFormIndex<M>,
    mesh: &impl Mesh,
    dofs: &SystemDofs,
    coefficients: &Coefficients,
) -> Result<Vec<f64>> {
    use rayon::prelude::*;
    let form = M::form(form_name)?;
    let plans = block_plans::<M>(form, dofs, false)?;
    let mut out = vec![0.0; dofs.dof_count()];
    let cells = mesh.cell_count();
    if let Some(colouring) = CellColouring::new(mesh) {
        let shared = SharedValues::of(&mut out);
        let mut failed = false;
        for colour in 0..colouring.colour_count() {
            let ranges: Vec<_> = colouring.ranges(colour).collect();
            let result = ranges.into_par_iter().try_for_each(|range| {
                // SAFETY: as in `add_form_matrices_coloured`: `out` is touched by
                // accumulators alone until the loop ends, the chunks of one colour share
                // no vertex, hence no DOF, hence no entry of `out`; colours run in
                // sequence.
                let mut sink = unsafe { shared.accumulator() };
                add_vectors::<M, _>(form, &plans, mesh, dofs, coefficients, range, &mut sink)
            });
            if result.is_err() {
                failed = true;
                break;
            }
        }
        if !failed {
            return Ok(out);
        }
        out.fill(0.0);
    }
    add_vectors::<M, _>(
        form,
        &plans,
        mesh,
        dofs,
        coefficients,
        0..cells,
        &mut Accumulator::new(&mut out),
    )?;
    Ok(out)
}

/// Adds the element vectors of `plans` (blocks of linear `form`) on the cells `cells`
/// of `mesh` into `out` (the system numbering of `dofs`).
///
/// # Errors
/// A non-finite element vector (the first cell in `cells` with one), those of
/// [`Model::element_vector_curved`].
fn add_vectors<M: Model, G: Mesh>(
    form: usize,
    plans: &[BlockPlan],
    mesh: &G,
    dofs: &SystemDofs,
    coefficients: &Coefficients,
    cells: std::ops::Range<usize>,
    out: &mut Accumulator,
) -> Result<()> {
    let mut local = [0.0; 64];
    let mut local_vec;
    let largest = plans.iter().map(|p| p.rows).max().unwrap_or(0);
    let local: &mut [f64] = if largest <= local.len() {
        &mut local[..]
    } else {
        local_vec = vec![0.0; largest];
        &mut local_vec[..]
    };
    let mut x = [0.0; 6];
    let x = &mut x[..mesh.cell_kind().vertex_count() * mesh.cell_kind().dimension()];
    // Global vertex numbers orient the edge DOFs of transformed elements (Argyris,
    // Morley); other models ignore them (`Model::element_vector_on_cell`).
    let mut g = [0usize; 3];
    let g = &mut g[..mesh.cell_kind().vertex_count()];
    // Curved cells (a CurvedTriangleMesh) take the curved kernels.
    let mut nodes = [0.0; 12];
    let maps: Vec<_> = plans
        .iter()
        .map(|p| dofs.map(p.test_field).unwrap())
        .collect();
    for c in cells {
        mesh.cell_coordinates_into(c, x);
        let numbered = mesh.cell_vertex_numbers_into(c, g);
        let curved = mesh.has_curved_cells() && mesh.curved_cell_nodes_into(c, &mut nodes);
        for (plan, map) in plans.iter().zip(&maps) {
            let (params, data) = (&coefficients.params, &coefficients.data);
            let element = &mut local[..plan.rows];
            if curved {
                M::element_vector_curved(form, plan.block, &nodes, params, data, element)?;
            } else if numbered {
                M::element_vector_on_cell(form, plan.block, x, g, params, data, element);
            } else {
                M::element_vector(form, plan.block, x, params, data, element);
            }
            let rows = map.cell_dofs(mesh.cell_number(c));
            for (&r, &v) in rows.iter().zip(&local[..plan.rows]) {
                out.add(r + plan.row_offset, v);
            }
            if local[..plan.rows].iter().any(|v| !v.is_finite()) {
                return Err(Error::NonFinite {
                    what: "vector",
                    cell: mesh.cell_number(c),
                });
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{Diagonal, TriangleMesh};

    /// The colouring covers every cell once, and two chunks of one colour share no vertex
    /// (checked directly on the vertex lists, not through the colouring's own masks).
    fn check_colouring(mesh: &TriangleMesh) -> usize {
        let colouring = CellColouring::new(mesh).expect("a mesh above the threshold");
        let mut covered = vec![0u8; mesh.cell_count()];
        let mut owner = vec![usize::MAX; mesh.vertex_count()];
        for colour in 0..colouring.colour_count() {
            owner.fill(usize::MAX);
            for (k, range) in colouring.ranges(colour).enumerate() {
                for c in range {
                    covered[c] += 1;
                    for v in mesh.cell(c) {
                        assert!(
                            owner[v] == usize::MAX || owner[v] == k,
                            "colour {colour}: chunks {} and {k} share vertex {v}",
                            owner[v]
                        );
                        owner[v] = k;
                    }
                }
            }
        }
        assert!(covered.iter().all(|&n| n == 1), "a cell missed or repeated");
        colouring.colour_count()
    }

    #[test]
    fn chunk_colouring_is_a_partition_into_vertex_disjoint_chunks() {
        // rows of 2·256 cells, chunks of 4096: neighbours conflict, every other one not
        let square =
            TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 256, 256, Diagonal::Right).unwrap();
        assert_eq!(check_colouring(&square), 2);
        let refined = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 24, 24, Diagonal::Left)
            .unwrap()
            .refine_uniformly()
            .refine_uniformly();
        assert!(check_colouring(&refined) >= 2);
        let small = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 32, 32, Diagonal::Right).unwrap();
        assert!(CellColouring::new(&small).is_none());
    }
}
