//! Global assembly of generated element kernels into faer sparse matrices.
//!
//! The sparsity pattern of a form on a mesh is built once ([`MatrixAssembler::new`]),
//! together with the position in the value array of every element-matrix entry; each
//! assembly then only zeroes the values and adds the element matrices in place.

pub mod boundary;
pub mod dof_map;
pub mod kernel;
pub mod linear_problem;
pub mod plate_basis;

use crate::assembly::dof_map::SystemDofs;
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::model::{Coefficients, IntoFormIndex, Model};
use crate::SparseMatrix;
use faer::sparse::{SparseColMat, SymbolicSparseColMat};

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
        for (plan, (test, trial)) in plans.iter().zip(&maps) {
            let (rows, cols) = (test.cell_dofs(c), trial.cell_dofs(c));
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
    positions: &[usize],
    stride: usize,
    offset: usize,
    values: &mut [f64],
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
            values[p] += v;
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
    positions: &[usize],
    values: &mut [f64],
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
                values[p] += v;
            }
            offset += size;
        }
    }
    Ok(())
}

/// Assembles one bilinear form of a model on a mesh, reusing its sparsity pattern.
#[derive(Clone, Debug)]
pub struct MatrixAssembler {
    form: usize,
    plans: Vec<BlockPlan>,
    symbolic: SymbolicSparseColMat<usize>,
    positions: Vec<usize>,
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
        let n = dofs.dof_count();
        // Bucket the rows by column (counting sort), then sort and dedup each column:
        // O(entries), where a global sort of the keys was the cost of the whole setup.
        let mut bucket_ptr = vec![0usize; n + 1];
        for_each_entry(mesh, dofs, &plans, |_, col| bucket_ptr[col + 1] += 1);
        for j in 0..n {
            bucket_ptr[j + 1] += bucket_ptr[j];
        }
        let mut fill = bucket_ptr.clone();
        let mut bucket = vec![0usize; bucket_ptr[n]];
        for_each_entry(mesh, dofs, &plans, |row, col| {
            bucket[fill[col]] = row;
            fill[col] += 1;
        });
        let mut col_ptr = vec![0usize; n + 1];
        let mut row_idx = Vec::with_capacity(bucket.len() / 2);
        for j in 0..n {
            let column = &mut bucket[bucket_ptr[j]..bucket_ptr[j + 1]];
            column.sort_unstable();
            let mut last = usize::MAX;
            for &r in column.iter() {
                if r != last {
                    row_idx.push(r);
                    last = r;
                }
            }
            col_ptr[j + 1] = row_idx.len();
        }
        drop(bucket);
        let mut positions = Vec::with_capacity(bucket_ptr[n]);
        for_each_entry(mesh, dofs, &plans, |row, col| {
            let column = &row_idx[col_ptr[col]..col_ptr[col + 1]];
            let k = column
                .binary_search(&row)
                .expect("every entry is in the pattern");
            positions.push(col_ptr[col] + k);
        });
        let symbolic = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        Ok(Self {
            form,
            plans,
            symbolic,
            positions,
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
        add_form_matrices::<M, _>(
            self.form,
            &self.plans,
            mesh,
            coefficients,
            &self.positions,
            values,
        )?;
        if let Some(bad) = values.iter().position(|v| !v.is_finite()) {
            let cell = self.positions.iter().position(|&p| p == bad).unwrap_or(0);
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
}

/// Assembles linear form `form_name` of `M` on the system `dofs`.
pub fn assemble_vector<M: Model>(
    form_name: impl IntoFormIndex<M>,
    mesh: &impl Mesh,
    dofs: &SystemDofs,
    coefficients: &Coefficients,
) -> Result<Vec<f64>> {
    let form = M::form(form_name)?;
    let plans = block_plans::<M>(form, dofs, false)?;
    let mut out = vec![0.0; dofs.dof_count()];
    let mut local = vec![0.0; plans.iter().map(|p| p.rows).max().unwrap_or(0)];
    let mut x = [0.0; 6];
    let x = &mut x[..mesh.cell_kind().vertex_count() * mesh.cell_kind().dimension()];
    // Global vertex numbers orient the edge DOFs of transformed elements (Argyris,
    // Morley); other models ignore them (`Model::element_vector_on_cell`).
    let mut g = [0usize; 3];
    let g = &mut g[..mesh.cell_kind().vertex_count()];
    // Curved cells (a CurvedTriangleMesh) take the curved kernels.
    let mut nodes = [0.0; 12];
    for c in 0..mesh.cell_count() {
        mesh.cell_coordinates_into(c, x);
        let numbered = mesh.cell_vertex_numbers_into(c, g);
        let curved = mesh.has_curved_cells() && mesh.curved_cell_nodes_into(c, &mut nodes);
        for plan in &plans {
            let (params, data) = (&coefficients.params, &coefficients.data);
            let element = &mut local[..plan.rows];
            if curved {
                M::element_vector_curved(form, plan.block, &nodes, params, data, element)?;
            } else if numbered {
                M::element_vector_on_cell(form, plan.block, x, g, params, data, element);
            } else {
                M::element_vector(form, plan.block, x, params, data, element);
            }
            let rows = dofs.map(plan.test_field).unwrap().cell_dofs(c);
            for (&r, &v) in rows.iter().zip(&local[..plan.rows]) {
                out[r + plan.row_offset] += v;
            }
            if local[..plan.rows].iter().any(|v| !v.is_finite()) {
                return Err(Error::NonFinite {
                    what: "vector",
                    cell: c,
                });
            }
        }
    }
    Ok(out)
}
