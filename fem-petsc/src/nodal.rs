//! The nodal method of an obstacle problem on triangles, distributed: `min ½ uᵀKu − Fᵀu`
//! subject to `u_i ≥ ψ(x_i)` at the vertices and `u = g` on the boundary, with `K` and `F`
//! the model's energy forms `a` and `ℓ` ([`fem_runtime::Model::ENERGY`]) by its generated
//! element kernels, solved by SNESVI with the bounds on the primal unknowns.
//!
//! The cells are partitioned by PETSc's partitioner (PT-Scotch, over the cells' adjacency
//! through shared edges, as a `MATMPIADJ`); each rank assembles its own cells into a
//! preallocated `MATMPIAIJ` and the load vector (entries of rows other ranks own travel
//! at assembly). A vertex belongs to the lowest rank among its cells, and the unknowns
//! are numbered rank by rank, so each rank's rows are contiguous as PETSc lays them out.
//! The boundary values are imposed by `MatZeroRowsColumns`, which keeps `K` symmetric.

use crate::{check, solve_affine, sys, Converged, Error, Matrix, Petsc, Result, Vector};
use fem_runtime::lcp::external::CellGraph;
use fem_runtime::mesh::TriangleMesh;
use fem_runtime::model::DataFn;
use fem_runtime::Model;
use std::collections::BTreeSet;

/// A distributed solve's answer, on every rank.
#[derive(Clone, Debug)]
pub struct NodalSolution {
    /// The solution at each vertex of the mesh, in the mesh's order.
    pub values: Vec<f64>,
    /// What SNESVI reported.
    pub converged: Converged,
    /// Cells this rank assembled.
    pub cells_here: usize,
    /// Unknowns this rank owns.
    pub rows_here: usize,
}

/// `values` in an array PETSc allocated, which a `MATMPIADJ` takes over and frees.
fn petsc_array(values: &[sys::PetscInt]) -> Result<*mut sys::PetscInt> {
    let mut pointer: *mut sys::PetscInt = std::ptr::null_mut();
    let bytes = std::mem::size_of_val(values).max(1);
    // SAFETY: PetscMallocA with one array of `bytes` bytes, written below
    unsafe {
        check(
            "PetscMallocA",
            sys::PetscMallocA(
                1,
                sys::PetscBool_PETSC_FALSE,
                line!() as i32,
                c"petsc_array".as_ptr(),
                c"fem-petsc/src/nodal.rs".as_ptr(),
                bytes,
                &mut pointer as *mut *mut sys::PetscInt as *mut std::ffi::c_void,
            ),
        )?;
        std::ptr::copy_nonoverlapping(values.as_ptr(), pointer, values.len());
    }
    Ok(pointer)
}

/// The rank each cell goes to: PT-Scotch over the cells' adjacency `graph` (on one rank,
/// every cell to rank 0). Every rank calls it with the same graph.
pub(crate) fn partition(petsc: &Petsc, graph: &CellGraph) -> Result<Vec<usize>> {
    let cells = graph.cell_count();
    let (rank, size) = (petsc.rank(), petsc.size());
    if size == 1 {
        return Ok(vec![0; cells]);
    }
    // the graph's rows start spread in contiguous blocks
    let start = cells * rank / size;
    let end = cells * (rank + 1) / size;
    let mut offsets = vec![0 as sys::PetscInt];
    let mut columns = Vec::new();
    for c in start..end {
        let row = &graph.neighbours[graph.offsets[c]..graph.offsets[c + 1]];
        columns.extend(row.iter().map(|&n| n as sys::PetscInt));
        offsets.push(columns.len() as sys::PetscInt);
    }
    let too_large = |_| {
        Error::refused(
            "MatCreateMPIAdj",
            "more cells than PETSc's 32-bit PetscInt holds",
        )
    };
    let (local, global) = (
        sys::PetscInt::try_from(end - start).map_err(too_large)?,
        sys::PetscInt::try_from(cells).map_err(too_large)?,
    );
    let (ia, ja) = (petsc_array(&offsets)?, petsc_array(&columns)?);
    let mut adjacency = std::ptr::null_mut();
    let mut part = std::ptr::null_mut();
    let mut is = std::ptr::null_mut();
    let mut all = std::ptr::null_mut();
    // SAFETY: the adjacency owns ia and ja from here; every object is destroyed below
    unsafe {
        check(
            "MatCreateMPIAdj",
            sys::MatCreateMPIAdj(
                petsc.comm(),
                local,
                global,
                ia,
                ja,
                std::ptr::null_mut(),
                &mut adjacency,
            ),
        )?;
        let result = (|| {
            check(
                "MatPartitioningCreate",
                sys::MatPartitioningCreate(petsc.comm(), &mut part),
            )?;
            check(
                "MatPartitioningSetAdjacency",
                sys::MatPartitioningSetAdjacency(part, adjacency),
            )?;
            check(
                "MatPartitioningSetType",
                sys::MatPartitioningSetType(part, c"ptscotch".as_ptr()),
            )?;
            check(
                "MatPartitioningSetFromOptions",
                sys::MatPartitioningSetFromOptions(part),
            )?;
            check(
                "MatPartitioningApply",
                sys::MatPartitioningApply(part, &mut is),
            )?;
            check("ISAllGather", sys::ISAllGather(is, &mut all))?;
            let mut n = 0;
            check("ISGetLocalSize", sys::ISGetLocalSize(all, &mut n))?;
            let mut indices: *const sys::PetscInt = std::ptr::null();
            check("ISGetIndices", sys::ISGetIndices(all, &mut indices))?;
            let ranks: Vec<usize> = crate::raw_slice(indices, n)
                .iter()
                .map(|&r| r as usize)
                .collect();
            check("ISRestoreIndices", sys::ISRestoreIndices(all, &mut indices))?;
            Ok(ranks)
        })();
        sys::ISDestroy(&mut all);
        sys::ISDestroy(&mut is);
        sys::MatPartitioningDestroy(&mut part);
        sys::MatDestroy(&mut adjacency);
        let ranks = result?;
        if ranks.len() != cells || ranks.iter().any(|&r| r >= size) {
            return Err(Error::refused(
                "MatPartitioningApply",
                format!(
                    "a partition of {} cells into ranks beyond {size}",
                    ranks.len()
                ),
            ));
        }
        Ok(ranks)
    }
}

/// Solves the nodal obstacle problem of model `M` on `mesh`, distributed over the ranks
/// of `petsc`: `params` and `data` in the model's order (`M::PARAMS`, `M::DATA`), the
/// obstacle `psi` and the boundary values `g` at the vertices. Every rank passes the same
/// mesh and gets the whole solution back.
///
/// # Errors
/// A model without `energy:` forms, PETSc's errors, or SNESVI not converging (named).
pub fn solve_nodal<M: Model>(
    petsc: &Petsc,
    mesh: &TriangleMesh,
    params: &[f64],
    data: &[&DataFn],
    psi: &dyn Fn([f64; 2]) -> f64,
    g: &dyn Fn([f64; 2]) -> f64,
) -> Result<NodalSolution> {
    let [a, l] = M::ENERGY.ok_or(Error::refused(
        "solve_nodal",
        format!("model {} declares no energy forms", M::NAME),
    ))?;
    let rank = petsc.rank();
    let owner_of_cell = partition(petsc, &CellGraph::of(mesh))?;
    let vertices = mesh.vertex_count();
    let mut owner = vec![usize::MAX; vertices];
    for (cell, &r) in mesh.cells().iter().zip(&owner_of_cell) {
        for &v in cell {
            owner[v] = owner[v].min(r);
        }
    }
    // unknowns rank by rank, in the mesh's order within a rank
    let mut order: Vec<usize> = (0..vertices).collect();
    order.sort_by_key(|&v| (owner[v], v));
    let mut index = vec![0; vertices];
    for (i, &v) in order.iter().enumerate() {
        index[v] = i;
    }
    let first = order.iter().position(|&v| owner[v] == rank).unwrap_or(0);
    let mine: Vec<usize> = order
        .iter()
        .copied()
        .filter(|&v| owner[v] == rank)
        .collect();
    // preallocation: a row's columns are the vertices of its cells
    let mut coupled = vec![BTreeSet::new(); vertices];
    for cell in mesh.cells() {
        for &v in cell {
            if owner[v] == rank {
                coupled[v].extend(cell.iter().copied());
            }
        }
    }
    let (diagonal, off): (Vec<usize>, Vec<usize>) = mine
        .iter()
        .map(|&v| {
            let here = coupled[v].iter().filter(|&&w| owner[w] == rank).count();
            (here, coupled[v].len() - here)
        })
        .unzip();
    let mut k = Matrix::new(petsc, &diagonal, &off)?;
    let mut f = Vector::new(petsc, mine.len())?;
    let mut cells_here = 0;
    let mut matrix = [0.0; 9];
    let mut vector = [0.0; 3];
    for (c, cell) in mesh.cells().iter().enumerate() {
        if owner_of_cell[c] != rank {
            continue;
        }
        cells_here += 1;
        let coordinates = mesh.cell_coordinates(c);
        M::element_matrix(a, 0, &coordinates, params, data, &mut matrix);
        M::element_vector(l, 0, &coordinates, params, data, &mut vector);
        let rows = cell.map(|v| index[v]);
        k.add(&rows, &rows, &matrix)?;
        f.set(&rows, &vector, true)?;
    }
    k.assemble()?;
    f.assemble()?;
    let boundary = mesh.is_boundary_vertex();
    let point = |v: usize| mesh.vertices()[v];
    let mut x = Vector::new(petsc, mine.len())?;
    let mut lower = Vector::new(petsc, mine.len())?;
    let mut upper = Vector::new(petsc, mine.len())?;
    let rows: Vec<usize> = (first..first + mine.len()).collect();
    let start: Vec<f64> = mine
        .iter()
        .map(|&v| {
            if boundary[v] {
                g(point(v))
            } else {
                psi(point(v)).max(0.0)
            }
        })
        .collect();
    x.set(&rows, &start, false)?;
    let floor: Vec<f64> = mine
        .iter()
        .map(|&v| {
            if boundary[v] {
                -sys::FEM_PETSC_INFINITY
            } else {
                psi(point(v))
            }
        })
        .collect();
    lower.set(&rows, &floor, false)?;
    upper.set(&rows, &vec![sys::FEM_PETSC_INFINITY; rows.len()], false)?;
    for v in [&mut x, &mut lower, &mut upper] {
        v.assemble()?;
    }
    // u = g on the boundary: the rows and columns of K cleared, F corrected by K g
    let fixed: Vec<sys::PetscInt> = mine
        .iter()
        .zip(&rows)
        .filter(|(&v, _)| boundary[v])
        .map(|(_, &r)| r as sys::PetscInt)
        .collect();
    // SAFETY: live objects; `fixed` holds rows this rank owns
    check("MatZeroRowsColumns", unsafe {
        sys::MatZeroRowsColumns(
            k.raw,
            fixed.len() as sys::PetscInt,
            fixed.as_ptr(),
            1.0,
            x.raw,
            f.raw,
        )
    })?;
    let converged = solve_affine(
        &crate::Defaults::default(),
        &k,
        &f,
        Some((&lower, &upper)),
        &mut x,
    )?;
    let whole = x.gather()?;
    let values = (0..vertices).map(|v| whole[index[v]]).collect();
    Ok(NodalSolution {
        values,
        converged,
        cells_here,
        rows_here: mine.len(),
    })
}
