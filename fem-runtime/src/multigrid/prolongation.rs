//! Prolongation between nested triangle meshes: the coarse field evaluated at the fine
//! DOF nodes, cell by cell through the parent map, in the reduced (Dirichlet-free) DOF
//! numbering of both systems.

use crate::assembly::boundary::Reduction;
use crate::assembly::dof_map::SystemDofs;
use crate::element::mapping::Affine;
use crate::error::{Error, Result};
use crate::mesh::{PointLocator, TriangleMesh};
use crate::SparseMatrix;
use faer::sparse::SparseColMat;
use fem_reference::ElementKind;

/// Weights below this are dropped: nodal interpolation weights of P1–P3 at the nodes of
/// a uniformly refined cell are multiples of 1/8 or 1/27, so anything smaller is the
/// rounding of an exact 0 (a node on the zero line of a basis function).
const DROP: f64 = 1e-12;

/// One level of a nested hierarchy: its mesh, the DOFs of its system (all fields
/// stacked, as [`SystemDofs`] numbers them) and the elimination of its fixed DOFs.
#[derive(Clone, Copy)]
pub struct NestedLevel<'a> {
    /// The mesh.
    pub mesh: &'a TriangleMesh,
    /// The DOFs of the system on `mesh`.
    pub dofs: &'a SystemDofs,
    /// The free DOFs (the numbering of the matrices); `None`: every DOF is free.
    pub reduction: Option<&'a Reduction>,
}

impl NestedLevel<'_> {
    fn size(&self) -> usize {
        self.reduction
            .map_or(self.dofs.dof_count(), |r| r.free().len())
    }

    /// The row/column of full DOF `d`, `None` if it is fixed.
    fn reduced(&self, d: usize) -> Option<usize> {
        match self.reduction {
            Some(r) => r.free_index(d),
            None => Some(d),
        }
    }
}

/// The parent of every cell of `fine` in `coarse`: the coarse cell containing the fine
/// cell's centroid (for a nested mesh, a point strictly inside the parent).
///
/// [`TriangleMesh::refine`] returns this map already; this recovers it for
/// [`TriangleMesh::refine_uniformly`] and for meshes refined in several steps.
/// Errors when a centroid lies outside `coarse` (the meshes are not nested).
pub fn parents_by_location(coarse: &TriangleMesh, fine: &TriangleMesh) -> Result<Vec<usize>> {
    let locator = PointLocator::new(coarse);
    // The parents found last, most recent first, and the cells numbered just after the
    // last two are tried before the cell search: cells numbered row by row visit the
    // two triangles of a coarse square in turn, then those of the next square. On the
    // structured 2049² mesh (2M fine cells) only the first cell of each row is searched
    // for, and the whole takes 0.07 s instead of 0.13 s (issue 15: the finest level's
    // setup bounds the nodal solve). Any other numbering is as correct, the search
    // being only slower.
    let mut recent = [usize::MAX; 3];
    let vertices = fine.vertices();
    (0..fine.cell_count())
        .map(|c| {
            let [a, b, d] = fine.cell(c).map(|v| vertices[v]);
            let x = [(a[0] + b[0] + d[0]) / 3.0, (a[1] + b[1] + d[1]) / 3.0];
            let next = |r: usize, k: usize| r.wrapping_add(k);
            let candidates = [
                recent[0],
                recent[1],
                recent[2],
                next(recent[0], 1),
                next(recent[1], 1),
                next(recent[0], 2),
                next(recent[1], 2),
                next(recent[0], 3),
            ];
            let p = match candidates.into_iter().find(|&p| locator.contains(p, x)) {
                Some(p) => p,
                None => {
                    locator
                        .locate(x)
                        .ok_or_else(|| {
                            Error::Input(format!(
                                "fine cell {c} (centroid {x:?}) lies outside the coarse mesh: the meshes are not nested"
                            ))
                        })?
                        .0
                }
            };
            if let Some(k) = recent.iter().position(|&r| r == p) {
                recent[..=k].rotate_right(1);
            } else {
                recent.rotate_right(1);
                recent[0] = p;
            }
            Ok(p)
        })
        .collect()
}

/// The prolongation `P` from `coarse` to `fine`: `(P v)_i` is the coarse function with
/// coefficients `v` evaluated at fine DOF node `i` (nodal interpolation, exact on nested
/// Lagrange spaces: the coarse space is a subspace of the fine one).
///
/// Shape: (free DOFs of `fine`) × (free DOFs of `coarse`), both in their reduced
/// numbering. Fixed coarse DOFs contribute nothing (multigrid corrections vanish
/// there); fixed fine DOFs have no row. Every field of `fine.dofs` must be a field of
/// `coarse.dofs`, with the same element; fields are prolonged separately (the matrix is
/// block diagonal over fields). `parents[c]` is the coarse cell containing fine cell `c`
/// ([`TriangleMesh::refine`] or [`parents_by_location`]).
///
/// Elements: the Lagrange ones (P0, P1, P2, P3, P1disc). For a discontinuous field on a
/// fine cell split from a coarse cell it is the restriction of the coarse polynomial.
///
/// Errors: a field or element mismatch, Hermite (not on triangles), a `parents` of the
/// wrong length or naming a cell `coarse` does not have, a reduction of another size.
pub fn prolongation(
    coarse: &NestedLevel,
    fine: &NestedLevel,
    parents: &[usize],
) -> Result<SparseMatrix> {
    if parents.len() != fine.mesh.cell_count() {
        return Err(Error::Input(format!(
            "{} parents for a fine mesh of {} cells",
            parents.len(),
            fine.mesh.cell_count()
        )));
    }
    if let Some(&p) = parents.iter().find(|&&p| p >= coarse.mesh.cell_count()) {
        return Err(Error::Input(format!(
            "parent cell {p} outside a coarse mesh of {} cells",
            coarse.mesh.cell_count()
        )));
    }
    for (name, level) in [("coarse", coarse), ("fine", fine)] {
        if let Some(r) = level.reduction {
            // the reduction's own system size, through the full vector it expands to
            let size = r.expand(&vec![0.0; r.free().len()]).len();
            let n = level.dofs.dof_count();
            if size != n {
                return Err(Error::Input(format!(
                    "the {name} level's reduction is for {size} DOFs, its system has {n}"
                )));
            }
        }
    }
    let mut triplets = Vec::new();
    let mut done = vec![false; fine.dofs.dof_count()];
    let mut values = Vec::new();
    for &field in fine.dofs.fields() {
        let map_f = fine.dofs.map(field).expect("a field of the system");
        let (Some(map_c), Some(offset_c)) = (coarse.dofs.map(field), coarse.dofs.offset(field))
        else {
            return Err(Error::Input(format!(
                "field {field} of the fine system is not part of the coarse one"
            )));
        };
        let element = map_f.element();
        if map_c.element() != element {
            return Err(Error::Input(format!(
                "field {field} is {} on the fine mesh and {} on the coarse one",
                element.name(),
                map_c.element().name()
            )));
        }
        if element == ElementKind::Hermite {
            return Err(Error::Input(
                "no prolongation for Hermite elements on triangles".into(),
            ));
        }
        let offset_f = fine.dofs.offset(field).unwrap();
        let nodes = fem_reference::triangle::lagrange_nodes(element.degree());
        let basis = element.triangle_basis();
        for (c, &p) in parents.iter().enumerate() {
            let fine_dofs = map_f.cell_dofs(c);
            // most cells bring no new node (a vertex is shared by about six): their
            // maps are not needed
            if fine_dofs.iter().all(|&dof| done[offset_f + dof]) {
                continue;
            }
            let (child, parent) = (Affine::of(fine.mesh, c), Affine::of(coarse.mesh, p));
            let coarse_dofs = map_c.cell_dofs(p);
            for (&dof, &xi) in fine_dofs.iter().zip(&nodes) {
                let d = offset_f + dof;
                if std::mem::replace(&mut done[d], true) {
                    continue;
                }
                let Some(row) = fine.reduced(d) else {
                    continue;
                };
                let eta = parent.reference_point(child.point(xi));
                values.clear();
                values.extend(basis.iter().map(|phi| phi.eval(eta)));
                for (&cd, &w) in coarse_dofs.iter().zip(&values) {
                    if w.abs() <= DROP {
                        continue;
                    }
                    if let Some(col) = coarse.reduced(offset_c + cd) {
                        triplets.push((row, col, w));
                    }
                }
            }
        }
    }
    Ok(by_columns(fine.size(), coarse.size(), &triplets))
}

/// The `rows × columns` matrix of `entries` `(row, column, value)`, none repeated (each
/// fine row is filled once), by a counting sort on the columns and a sort of each
/// column's few rows (faster than the general triplet conversion, which also sums
/// duplicates: 1.75M entries at 1M fine nodes).
fn by_columns(rows: usize, columns: usize, entries: &[(usize, usize, f64)]) -> SparseMatrix {
    let mut col_ptr = vec![0usize; columns + 1];
    for &(_, j, _) in entries {
        col_ptr[j + 1] += 1;
    }
    for j in 0..columns {
        col_ptr[j + 1] += col_ptr[j];
    }
    let mut fill = col_ptr.clone();
    let mut sorted = vec![(0usize, 0.0f64); entries.len()];
    for &(i, j, v) in entries {
        sorted[fill[j]] = (i, v);
        fill[j] += 1;
    }
    for j in 0..columns {
        sorted[col_ptr[j]..col_ptr[j + 1]].sort_unstable_by_key(|&(i, _)| i);
    }
    let (row_idx, values) = sorted.into_iter().unzip();
    SparseColMat::new(
        faer::sparse::SymbolicSparseColMat::new_checked(rows, columns, col_ptr, None, row_idx),
        values,
    )
}

/// The free–free block of a prolongation `all` between two levels with every DOF free
/// ([`prolongation`] with both reductions `None`), in the reduced numbering of `coarse`
/// (columns) and `fine` (rows): the same matrix as [`prolongation`] with both
/// reductions given (the same weights, bitwise), at the cost of one pass over `all`'s
/// entries instead of the geometry of every fine cell (about 0.1 s at 1M unknowns).
///
/// Errors: `all` of another shape than the two reductions' systems.
pub fn reduced_prolongation(
    all: &SparseMatrix,
    coarse: &Reduction,
    fine: &Reduction,
) -> Result<SparseMatrix> {
    let coarse_size = coarse.expand(&vec![0.0; coarse.free().len()]).len();
    let fine_size = fine.expand(&vec![0.0; fine.free().len()]).len();
    if all.ncols() != coarse_size || all.nrows() != fine_size {
        return Err(Error::Input(format!(
            "a prolongation of {} × {} for reductions of {fine_size} fine and {coarse_size} coarse DOFs",
            all.nrows(),
            all.ncols()
        )));
    }
    let (col_ptr, rows, vals) = (
        all.symbolic().col_ptr(),
        all.symbolic().row_idx(),
        all.val(),
    );
    let mut new_ptr = Vec::with_capacity(coarse.free().len() + 1);
    let mut new_rows = Vec::with_capacity(rows.len());
    let mut new_vals = Vec::with_capacity(rows.len());
    new_ptr.push(0);
    // both free lists increase, so the columns come in order and each column's rows stay
    // sorted
    for &d in coarse.free() {
        for k in col_ptr[d]..col_ptr[d + 1] {
            if let Some(row) = fine.free_index(rows[k]) {
                new_rows.push(row);
                new_vals.push(vals[k]);
            }
        }
        new_ptr.push(new_rows.len());
    }
    let symbolic = faer::sparse::SymbolicSparseColMat::new_checked(
        fine.free().len(),
        coarse.free().len(),
        new_ptr,
        None,
        new_rows,
    );
    Ok(SparseColMat::new(symbolic, new_vals))
}
