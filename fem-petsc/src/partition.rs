//! The partition of a mesh's cells among the ranks: PETSc's partitioner (PT-Scotch) over
//! the cells' adjacency through shared facets, as a `MATMPIADJ`
//! ([`fem_runtime::lcp::external::ExternalSolver::partition`] for the pipeline, which
//! then has each rank assemble its own cells).

use crate::{check, sys, Error, Petsc, Result};
use fem_runtime::lcp::external::CellGraph;

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
