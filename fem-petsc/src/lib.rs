//! PETSc driven from Rust: the bindings bindgen generates from Debian's `petsc.h` ([`sys`])
//! and a thin safe layer over the parts fem-forms uses — MPI through the `mpi` crate,
//! distributed vectors, preallocated `MATMPIAIJ` matrices, and SNES / SNESVI with the
//! residual and Jacobian as Rust closures.
//!
//! Safety of the layer: every PETSc object is owned by one value and destroyed on drop;
//! every call's error code becomes a [`Result`] with PETSc's own message; callbacks go
//! through `extern "C"` trampolines to a boxed closure that the SNES keeps alive, and a
//! panic inside one is caught and returned to PETSc as an error (unwinding through C is
//! undefined). A diverged or not-converged SNES is an [`Error`] naming PETSc's reason,
//! never a result (PETSc's own ex9 exits 0 on DIVERGED_MAX_IT).
//!
//! Not in the default build: the crate needs PETSc, Open MPI and libclang, so it is
//! outside the workspace's members and built through the root crate's `petsc` feature
//! (docs/petsc.md).

pub mod lcp;
mod partition;
mod shared;

use std::ffi::{c_void, CStr, CString};
use std::ops::Range;

/// The raw bindings (bindgen over `wrapper.h`).
#[allow(
    non_upper_case_globals,
    non_camel_case_types,
    non_snake_case,
    dead_code,
    missing_docs,
    clippy::all
)]
pub mod sys {
    include!(concat!(env!("OUT_DIR"), "/bindings.rs"));
}

/// A failed PETSc call, or a SNES that did not converge.
#[derive(Clone, Debug, PartialEq)]
pub struct Error {
    /// The call that failed (`VecCreateMPI`, `SNESSolve`).
    pub call: &'static str,
    /// PETSc's error code (0 for a SNES that stopped without converging).
    pub code: i32,
    /// PETSc's message, or the SNES's converged reason.
    pub message: String,
}

impl std::fmt::Display for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}: {} (PETSc error {})",
            self.call, self.message, self.code
        )
    }
}

impl std::error::Error for Error {}

impl Error {
    /// A refusal of ours at `call` (bad arguments, a SNES that did not converge): no
    /// PETSc error code.
    fn refused(call: &'static str, message: impl Into<String>) -> Self {
        Self {
            call,
            code: 0,
            message: message.into(),
        }
    }
}

/// The result of a PETSc call.
pub type Result<T> = std::result::Result<T, Error>;

/// `code` of `call` as a [`Result`], with PETSc's text for the code.
fn check(call: &'static str, code: sys::PetscErrorCode) -> Result<()> {
    if code == 0 {
        return Ok(());
    }
    let mut text: *const std::os::raw::c_char = std::ptr::null();
    // SAFETY: PetscErrorMessage stores a pointer to a static string (or leaves null)
    let message = unsafe {
        sys::PetscErrorMessage(code, &mut text, std::ptr::null_mut());
        if text.is_null() {
            "unknown error".to_string()
        } else {
            CStr::from_ptr(text).to_string_lossy().into_owned()
        }
    };
    Err(Error {
        call,
        code,
        message,
    })
}

/// PETSc initialized on MPI's world communicator (from the `mpi` crate); finalized, then
/// MPI, when dropped. One per process.
pub struct Petsc {
    universe: Option<mpi::environment::Universe>,
}

impl Petsc {
    /// Initializes MPI and PETSc, then inserts `options` (PETSc's command-line options as
    /// one string, `-snes_monitor -pc_type gamg`) into its options database.
    ///
    /// # Errors
    /// MPI was initialized already (a second `Petsc`), PETSc's initialization failed, or
    /// an option string PETSc cannot parse.
    pub fn initialize(options: &str) -> Result<Self> {
        let universe = mpi::initialize().ok_or(Error::refused(
            "MPI_Init",
            "MPI is initialized already: one Petsc per process",
        ))?;
        let world = {
            use mpi::raw::AsRaw;
            use mpi::traits::Communicator;
            let world = universe.world();
            let _ = world.rank();
            world.as_raw()
        };
        // SAFETY: PETSC_COMM_WORLD is read by PetscInitialize, which has not run yet;
        // both are pointers to Open MPI's communicator object
        unsafe {
            sys::PETSC_COMM_WORLD = std::mem::transmute::<mpi::ffi::MPI_Comm, sys::MPI_Comm>(world);
        }
        let (mut argc, mut argv) = (0, std::ptr::null_mut());
        // SAFETY: an empty argument list; no options file, no help text
        check("PetscInitialize", unsafe {
            sys::PetscInitialize(&mut argc, &mut argv, std::ptr::null(), std::ptr::null())
        })?;
        // SAFETY: PETSc is initialized; both are PETSc's own globals and handlers
        unsafe {
            // errors come back as codes with PETSc's message (each call's `check`), not
            // as a traceback: the default handler also sleeps 10 s on the other ranks,
            // during which rank 0 finalized MPI and mpirun killed the job before its
            // error line was printed
            check(
                "PetscPushErrorHandler",
                sys::PetscPushErrorHandler(
                    Some(sys::PetscReturnErrorHandler),
                    std::ptr::null_mut(),
                ),
            )?;
            // monitors (`-snes_monitor`) to standard error: standard output carries the
            // report, which must stay one JSON object with --json
            sys::PETSC_STDOUT = sys::PETSC_STDERR;
        }
        let petsc = Self {
            universe: Some(universe),
        };
        if !options.trim().is_empty() {
            petsc.insert_options(options)?;
        }
        Ok(petsc)
    }

    /// Inserts more options (`-snes_type vinewtonssls`) into PETSc's database; later
    /// solves read them.
    ///
    /// # Errors
    /// An option string PETSc cannot parse, or one with a NUL byte.
    pub fn insert_options(&self, options: &str) -> Result<()> {
        let text = CString::new(options).map_err(|_| {
            Error::refused("PetscOptionsInsertString", "the options contain a NUL byte")
        })?;
        // SAFETY: the global options database, a NUL-terminated string
        check("PetscOptionsInsertString", unsafe {
            sys::PetscOptionsInsertString(std::ptr::null_mut(), text.as_ptr())
        })
    }

    /// This process's rank in the world communicator.
    pub fn rank(&self) -> usize {
        use mpi::traits::Communicator;
        self.universe
            .as_ref()
            .map_or(0, |u| u.world().rank() as usize)
    }

    /// The number of processes.
    pub fn size(&self) -> usize {
        use mpi::traits::Communicator;
        self.universe
            .as_ref()
            .map_or(1, |u| u.world().size() as usize)
    }

    pub(crate) fn comm(&self) -> sys::MPI_Comm {
        // SAFETY: set before PetscInitialize and constant since
        unsafe { sys::PETSC_COMM_WORLD }
    }

    /// `MPI_COMM_SELF`, which PETSc's header spells as a macro bindgen drops.
    fn comm_self(&self) -> sys::MPI_Comm {
        use mpi::raw::AsRaw;
        let raw = mpi::topology::SimpleCommunicator::self_comm().as_raw();
        // SAFETY: both are pointers to Open MPI's communicator object
        unsafe { std::mem::transmute::<mpi::ffi::MPI_Comm, sys::MPI_Comm>(raw) }
    }

    /// `values` summed entry by entry over the ranks, in place (`MPI_Allreduce`; every
    /// rank must call it with the same length).
    pub fn sum_all(&self, values: &mut [f64]) {
        use mpi::collective::{CommunicatorCollectives, SystemOperation};
        if let Some(universe) = &self.universe {
            let send = values.to_vec();
            universe
                .world()
                .all_reduce_into(&send[..], values, SystemOperation::sum());
        }
    }

    /// `values` replaced entry by entry by their smallest over the ranks, in place
    /// (`MPI_Allreduce`; every rank must call it with the same length).
    pub fn min_all(&self, values: &mut [u64]) {
        use mpi::collective::{CommunicatorCollectives, SystemOperation};
        if let Some(universe) = &self.universe {
            let send = values.to_vec();
            universe
                .world()
                .all_reduce_into(&send[..], values, SystemOperation::min());
        }
    }

    /// Every rank's `values`, concatenated in rank order, on every rank
    /// (`MPI_Allgatherv`; every rank must call it, with a length of its own).
    pub fn gather_all<T: mpi::datatype::Equivalence + Copy + Default>(
        &self,
        values: &[T],
    ) -> Vec<T> {
        use mpi::collective::CommunicatorCollectives;
        use mpi::datatype::PartitionMut;
        use mpi::traits::Communicator;
        let Some(universe) = &self.universe else {
            return values.to_vec();
        };
        let world = universe.world();
        let mut counts = vec![0 as mpi::Count; world.size() as usize];
        world.all_gather_into(&(values.len() as mpi::Count), &mut counts[..]);
        let offsets: Vec<mpi::Count> = counts
            .iter()
            .scan(0, |at, &c| {
                let here = *at;
                *at += c;
                Some(here)
            })
            .collect();
        let total = counts.iter().map(|&c| c as usize).sum();
        let mut all = vec![T::default(); total];
        let mut partition = PartitionMut::new(&mut all[..], &counts[..], &offsets[..]);
        world.all_gather_varcount_into(values, &mut partition);
        all
    }

    /// The largest of `value` over the ranks (`MPI_Allreduce`; every rank must call it).
    pub fn max(&self, value: f64) -> f64 {
        use mpi::collective::{CommunicatorCollectives, SystemOperation};
        match &self.universe {
            Some(universe) => {
                let mut largest = 0.0;
                universe
                    .world()
                    .all_reduce_into(&value, &mut largest, SystemOperation::max());
                largest
            }
            None => value,
        }
    }

    /// The sum of `value` over the ranks (`MPI_Allreduce`; every rank must call it).
    pub fn sum(&self, value: f64) -> f64 {
        use mpi::collective::{CommunicatorCollectives, SystemOperation};
        match &self.universe {
            Some(universe) => {
                let mut total = 0.0;
                universe
                    .world()
                    .all_reduce_into(&value, &mut total, SystemOperation::sum());
                total
            }
            None => value,
        }
    }
}

impl Drop for Petsc {
    fn drop(&mut self) {
        // SAFETY: every PETSc object borrows `self`, so all are destroyed by now
        unsafe {
            sys::PetscFinalize();
        }
        // MPI_Finalize after PETSc's
        self.universe.take();
    }
}

/// Global indices as PETSc's 32-bit `PetscInt`.
///
/// # Errors
/// An index beyond `i32::MAX`.
fn petsc_ints(call: &'static str, indices: &[usize]) -> Result<Vec<sys::PetscInt>> {
    indices
        .iter()
        .map(|&i| {
            sys::PetscInt::try_from(i).map_err(|_| {
                Error::refused(call, format!("index {i} beyond PETSc's 32-bit PetscInt"))
            })
        })
        .collect()
}

/// A distributed vector (`VECMPI`): each rank owns a contiguous range of entries.
pub struct Vector<'p> {
    raw: sys::Vec,
    _petsc: std::marker::PhantomData<&'p Petsc>,
}

impl<'p> Vector<'p> {
    /// A vector of which this rank owns `local` entries (the global size is their sum).
    ///
    /// # Errors
    /// PETSc's.
    pub fn new(petsc: &'p Petsc, local: usize) -> Result<Self> {
        let local = petsc_ints("VecCreateMPI", &[local])?[0];
        let mut raw = std::ptr::null_mut();
        // SAFETY: creates a vector in `raw`
        check("VecCreateMPI", unsafe {
            sys::VecCreateMPI(petsc.comm(), local, sys::PETSC_DETERMINE, &mut raw)
        })?;
        Ok(Self {
            raw,
            _petsc: std::marker::PhantomData,
        })
    }

    /// The global indices this rank owns.
    ///
    /// # Errors
    /// PETSc's.
    pub fn ownership(&self) -> Result<Range<usize>> {
        let (mut start, mut end) = (0, 0);
        // SAFETY: a live vector
        check("VecGetOwnershipRange", unsafe {
            sys::VecGetOwnershipRange(self.raw, &mut start, &mut end)
        })?;
        Ok(start as usize..end as usize)
    }

    /// Sets (or, with `add`, adds) `values` at global `indices`, on any rank; takes
    /// effect at [`Vector::assemble`].
    ///
    /// # Errors
    /// Lengths that differ, or PETSc's.
    pub fn set(&mut self, indices: &[usize], values: &[f64], add: bool) -> Result<()> {
        if indices.len() != values.len() {
            return Err(Error::refused(
                "VecSetValues",
                format!("{} indices for {} values", indices.len(), values.len()),
            ));
        }
        let indices = petsc_ints("VecSetValues", indices)?;
        let mode = if add {
            sys::InsertMode_ADD_VALUES
        } else {
            sys::InsertMode_INSERT_VALUES
        };
        // SAFETY: arrays of the length passed
        check("VecSetValues", unsafe {
            sys::VecSetValues(
                self.raw,
                indices.len() as sys::PetscInt,
                indices.as_ptr(),
                values.as_ptr(),
                mode,
            )
        })
    }

    /// Communicates the values set for entries other ranks own.
    ///
    /// # Errors
    /// PETSc's.
    pub fn assemble(&mut self) -> Result<()> {
        // SAFETY: a live vector
        check("VecAssemblyBegin", unsafe {
            sys::VecAssemblyBegin(self.raw)
        })?;
        check("VecAssemblyEnd", unsafe { sys::VecAssemblyEnd(self.raw) })
    }

    /// The entries this rank owns, in order.
    ///
    /// # Errors
    /// PETSc's.
    pub fn local(&self) -> Result<Vec<f64>> {
        local_values(self.raw)
    }

    /// Every entry, on every rank (`VecScatterCreateToAll`).
    ///
    /// # Errors
    /// PETSc's.
    pub fn gather(&self) -> Result<Vec<f64>> {
        gather(self.raw)
    }
}

/// Every entry of the vector `raw`, on every rank (`VecScatterCreateToAll`).
fn gather(raw: sys::Vec) -> Result<Vec<f64>> {
    let mut scatter = std::ptr::null_mut();
    let mut all = std::ptr::null_mut();
    // SAFETY: creates a scatter and a sequential vector, both destroyed below
    unsafe {
        check(
            "VecScatterCreateToAll",
            sys::VecScatterCreateToAll(raw, &mut scatter, &mut all),
        )?;
        let moved = scatter_forward(scatter, raw, all);
        let whole = Vector {
            raw: all,
            _petsc: std::marker::PhantomData,
        };
        sys::VecScatterDestroy(&mut scatter);
        moved?;
        whole.local()
    }
}

/// The `n` values at `data`, which PETSc leaves null for an empty array (a rank that
/// owns no rows), where `slice::from_raw_parts` needs a non-null pointer.
///
/// # Safety
/// `data` valid for `n` reads while the slice lives, where `n > 0`.
pub(crate) unsafe fn raw_slice<'a, T>(data: *const T, n: sys::PetscInt) -> &'a [T] {
    if n <= 0 || data.is_null() {
        &[]
    } else {
        // SAFETY: the caller's
        unsafe { std::slice::from_raw_parts(data, n as usize) }
    }
}

/// The entries of the vector `raw` this rank owns, in order.
fn local_values(raw: sys::Vec) -> Result<Vec<f64>> {
    let mut n = 0;
    let mut array: *const f64 = std::ptr::null();
    // SAFETY: the array is valid for the local size until restored
    unsafe {
        check("VecGetLocalSize", sys::VecGetLocalSize(raw, &mut n))?;
        check("VecGetArrayRead", sys::VecGetArrayRead(raw, &mut array))?;
        let values = raw_slice(array, n).to_vec();
        check(
            "VecRestoreArrayRead",
            sys::VecRestoreArrayRead(raw, &mut array),
        )?;
        Ok(values)
    }
}

/// Moves `from`'s entries into `to` by `scatter` (begin and end).
///
/// # Safety
/// Live objects; `scatter` made for vectors of `from`'s and `to`'s layouts.
unsafe fn scatter_forward(scatter: sys::VecScatter, from: sys::Vec, to: sys::Vec) -> Result<()> {
    let (insert, forward) = (
        sys::InsertMode_INSERT_VALUES,
        sys::ScatterMode_SCATTER_FORWARD,
    );
    // SAFETY: the caller's
    unsafe {
        check(
            "VecScatterBegin",
            sys::VecScatterBegin(scatter, from, to, insert, forward),
        )?;
        check(
            "VecScatterEnd",
            sys::VecScatterEnd(scatter, from, to, insert, forward),
        )
    }
}

impl Drop for Vector<'_> {
    fn drop(&mut self) {
        // SAFETY: owned
        unsafe {
            sys::VecDestroy(&mut self.raw);
        }
    }
}

/// A sparse matrix in PETSc's AIJ format (`MATMPIAIJ` on several ranks), preallocated
/// row by row: an entry outside the preallocation is an error, not a silent
/// reallocation.
pub struct Matrix<'p> {
    raw: sys::Mat,
    _petsc: std::marker::PhantomData<&'p Petsc>,
}

impl<'p> Matrix<'p> {
    /// A square matrix of which this rank owns `diagonal.len()` rows; row `i` has at
    /// most `diagonal[i]` entries in the owned columns and `off_diagonal[i]` in others.
    ///
    /// # Errors
    /// Lengths that differ, or PETSc's.
    pub fn new(petsc: &'p Petsc, diagonal: &[usize], off_diagonal: &[usize]) -> Result<Self> {
        if diagonal.len() != off_diagonal.len() {
            return Err(Error::refused(
                "MatCreateAIJ",
                "preallocations of different lengths",
            ));
        }
        let d = petsc_ints("MatCreateAIJ", diagonal)?;
        let o = petsc_ints("MatCreateAIJ", off_diagonal)?;
        let m = d.len() as sys::PetscInt;
        let mut raw = std::ptr::null_mut();
        // SAFETY: arrays of the local row count
        unsafe {
            check(
                "MatCreateAIJ",
                sys::MatCreateAIJ(
                    petsc.comm(),
                    m,
                    m,
                    sys::PETSC_DETERMINE,
                    sys::PETSC_DETERMINE,
                    0,
                    d.as_ptr(),
                    0,
                    o.as_ptr(),
                    &mut raw,
                ),
            )?;
            check(
                "MatSetOption",
                sys::MatSetOption(
                    raw,
                    sys::MatOption_MAT_NEW_NONZERO_ALLOCATION_ERR,
                    sys::PetscBool_PETSC_TRUE,
                ),
            )?;
        }
        Ok(Self {
            raw,
            _petsc: std::marker::PhantomData,
        })
    }

    /// Adds the dense block `values` (row-major, `rows.len() × columns.len()`) at global
    /// `rows` and `columns`, on any rank; takes effect at [`Matrix::assemble`].
    ///
    /// # Errors
    /// A block of the wrong size, or PETSc's (an entry outside the preallocation).
    pub fn add(&mut self, rows: &[usize], columns: &[usize], values: &[f64]) -> Result<()> {
        if values.len() != rows.len() * columns.len() {
            return Err(Error::refused(
                "MatSetValues",
                format!(
                    "{} values for a {}×{} block",
                    values.len(),
                    rows.len(),
                    columns.len()
                ),
            ));
        }
        let r = petsc_ints("MatSetValues", rows)?;
        let c = petsc_ints("MatSetValues", columns)?;
        // SAFETY: arrays of the lengths passed
        check("MatSetValues", unsafe {
            sys::MatSetValues(
                self.raw,
                r.len() as sys::PetscInt,
                r.as_ptr(),
                c.len() as sys::PetscInt,
                c.as_ptr(),
                values.as_ptr(),
                sys::InsertMode_ADD_VALUES,
            )
        })
    }

    /// Communicates the entries added for rows other ranks own.
    ///
    /// # Errors
    /// PETSc's.
    pub fn assemble(&mut self) -> Result<()> {
        // SAFETY: a live matrix
        unsafe {
            check(
                "MatAssemblyBegin",
                sys::MatAssemblyBegin(self.raw, sys::MatAssemblyType_MAT_FINAL_ASSEMBLY),
            )?;
            check(
                "MatAssemblyEnd",
                sys::MatAssemblyEnd(self.raw, sys::MatAssemblyType_MAT_FINAL_ASSEMBLY),
            )
        }
    }

    /// A square matrix of which this rank owns `local` rows, preallocated for exactly the
    /// entries `declare` names to the [`Pattern`] it is given, on any rank (PETSc's
    /// `MATPREALLOCATOR`: entries of rows other ranks own are counted where they land,
    /// as one rank cannot count them from its own cells). The entries start at zero,
    /// assembled.
    ///
    /// # Errors
    /// `declare`'s, or PETSc's.
    pub fn with_pattern(
        petsc: &'p Petsc,
        local: usize,
        declare: impl FnOnce(&mut Pattern) -> Result<()>,
    ) -> Result<Self> {
        let m = petsc_ints("MatSetSizes", &[local])?[0];
        let (mut pre, mut raw) = (std::ptr::null_mut(), std::ptr::null_mut());
        // SAFETY: both matrices are created here; the preallocator is destroyed before
        // returning, the matrix owned by the result (or destroyed on an error)
        unsafe {
            let result = (|| {
                check("MatCreate", sys::MatCreate(petsc.comm(), &mut pre))?;
                check("MatSetType", sys::MatSetType(pre, c"preallocator".as_ptr()))?;
                check(
                    "MatSetSizes",
                    sys::MatSetSizes(pre, m, m, sys::PETSC_DETERMINE, sys::PETSC_DETERMINE),
                )?;
                check("MatSetUp", sys::MatSetUp(pre))?;
                declare(&mut Pattern {
                    raw: pre,
                    zeros: Vec::new(),
                })?;
                for (call, code) in [
                    (
                        "MatAssemblyBegin",
                        sys::MatAssemblyBegin(pre, sys::MatAssemblyType_MAT_FINAL_ASSEMBLY),
                    ),
                    (
                        "MatAssemblyEnd",
                        sys::MatAssemblyEnd(pre, sys::MatAssemblyType_MAT_FINAL_ASSEMBLY),
                    ),
                ] {
                    check(call, code)?;
                }
                check("MatCreate", sys::MatCreate(petsc.comm(), &mut raw))?;
                check(
                    "MatSetSizes",
                    sys::MatSetSizes(raw, m, m, sys::PETSC_DETERMINE, sys::PETSC_DETERMINE),
                )?;
                check("MatSetType", sys::MatSetType(raw, c"aij".as_ptr()))?;
                check(
                    "MatPreallocatorPreallocate",
                    sys::MatPreallocatorPreallocate(pre, sys::PetscBool_PETSC_TRUE, raw),
                )?;
                // the zeros filled in, assembled: a matrix SNES may read before its first
                // values
                check(
                    "MatAssemblyBegin",
                    sys::MatAssemblyBegin(raw, sys::MatAssemblyType_MAT_FINAL_ASSEMBLY),
                )?;
                check(
                    "MatAssemblyEnd",
                    sys::MatAssemblyEnd(raw, sys::MatAssemblyType_MAT_FINAL_ASSEMBLY),
                )?;
                check(
                    "MatSetOption",
                    sys::MatSetOption(
                        raw,
                        sys::MatOption_MAT_NEW_NONZERO_ALLOCATION_ERR,
                        sys::PetscBool_PETSC_TRUE,
                    ),
                )
            })();
            sys::MatDestroy(&mut pre);
            if let Err(e) = result {
                sys::MatDestroy(&mut raw);
                return Err(e);
            }
        }
        Ok(Self {
            raw,
            _petsc: std::marker::PhantomData,
        })
    }

    /// Declares the matrix symmetric positive definite for good (`MAT_SPD`,
    /// `MAT_SPD_ETERNAL`): MUMPS's Cholesky then factors it as `LLᵀ` without pivoting
    /// (`SYM = 1`), where as a general symmetric matrix it pivots, delays pivots and
    /// can outgrow the workspace its analysis estimated (`INFOG(1) = −9` on an adaptive
    /// membrane's Hessian at 16k unknowns on three ranks); GAMG reads it too.
    ///
    /// # Errors
    /// PETSc's.
    pub fn set_spd(&mut self) -> Result<()> {
        for option in [sys::MatOption_MAT_SPD, sys::MatOption_MAT_SPD_ETERNAL] {
            // SAFETY: a live matrix this value owns
            check("MatSetOption", unsafe {
                sys::MatSetOption(self.raw, option, sys::PetscBool_PETSC_TRUE)
            })?;
        }
        Ok(())
    }

    /// Declares `vectors` the matrix's near null space (`MatSetNearNullSpace`): the
    /// modes on which the operator without its supports vanishes (an elastic body's
    /// rigid motions), which GAMG's aggregation must reproduce on its coarse levels
    /// instead of the constants it assumes otherwise. Each vector is given whole, by
    /// PETSc's row (every rank the same vectors); each rank sets its `rows`. The vectors
    /// are orthonormalized first (modified Gram–Schmidt twice, the same on every rank), as
    /// `MatNullSpaceCreate` requires; a vector dependent on the ones before is dropped.
    ///
    /// # Errors
    /// A vector whose length is not the matrix's row count (on every rank alike), or
    /// PETSc's.
    pub fn set_near_null_space(
        &mut self,
        petsc: &'p Petsc,
        rows: &[usize],
        vectors: &[Vec<f64>],
    ) -> Result<()> {
        if vectors.is_empty() {
            return Ok(());
        }
        // the matrix's global size: the same on every rank, so that every rank refuses
        // together (a refusal on some ranks only would leave the others in the
        // collective calls below)
        let (mut global_rows, mut global_columns) = (0, 0);
        // SAFETY: a live matrix
        check("MatGetSize", unsafe {
            sys::MatGetSize(self.raw, &mut global_rows, &mut global_columns)
        })?;
        if let Some(v) = vectors.iter().find(|v| v.len() != global_rows as usize) {
            return Err(Error::refused(
                "MatSetNearNullSpace",
                format!(
                    "a near null space vector of {} entries for a matrix of {global_rows} rows",
                    v.len()
                ),
            ));
        }
        let dot = |x: &[f64], y: &[f64]| -> f64 { x.iter().zip(y).map(|(a, b)| a * b).sum() };
        let mut basis: Vec<Vec<f64>> = Vec::with_capacity(vectors.len());
        for v in vectors {
            let mut v = v.clone();
            let size = dot(&v, &v).sqrt();
            // twice: one pass leaves a nearly dependent vector (a rotation about a point
            // far from the body, nearly a translation) orthogonal only to ε / its
            // remainder, above the √ε that PETSc's MatNullSpaceCreate checks
            for _ in 0..2 {
                for b in &basis {
                    let projection = dot(&v, b);
                    for (x, y) in v.iter_mut().zip(b) {
                        *x -= projection * y;
                    }
                }
            }
            let norm = dot(&v, &v).sqrt();
            if norm > 1e-8 * size && norm > 0.0 {
                v.iter_mut().for_each(|x| *x /= norm);
                basis.push(v);
            }
        }
        if basis.is_empty() {
            return Ok(());
        }
        let mut petsc_vectors = Vec::with_capacity(basis.len());
        for b in &basis {
            let mut v = Vector::new(petsc, rows.len())?;
            let values: Vec<f64> = rows.iter().map(|&r| b[r]).collect();
            v.set(rows, &values, false)?;
            v.assemble()?;
            petsc_vectors.push(v);
        }
        let raw: Vec<sys::Vec> = petsc_vectors.iter().map(|v| v.raw).collect();
        let mut space: sys::MatNullSpace = std::ptr::null_mut();
        // SAFETY: live vectors, which the null space references (so they may drop after)
        check("MatNullSpaceCreate", unsafe {
            sys::MatNullSpaceCreate(
                petsc.comm(),
                sys::PetscBool_PETSC_FALSE,
                raw.len() as sys::PetscInt,
                raw.as_ptr(),
                &mut space,
            )
        })?;
        // SAFETY: a live matrix and null space; the matrix takes its own reference
        let set = check("MatSetNearNullSpace", unsafe {
            sys::MatSetNearNullSpace(self.raw, space)
        });
        // SAFETY: drops this function's reference
        let destroyed = check("MatNullSpaceDestroy", unsafe {
            sys::MatNullSpaceDestroy(&mut space)
        });
        set.and(destroyed)
    }

    /// `‖A‖∞`, the largest row sum of `|A|` of the assembled matrix (`MatNorm`).
    ///
    /// # Errors
    /// PETSc's.
    pub fn norm_infinity(&self) -> Result<f64> {
        let mut norm = 0.0;
        // SAFETY: a live, assembled matrix
        check("MatNorm", unsafe {
            sys::MatNorm(self.raw, sys::NormType_NORM_INFINITY, &mut norm)
        })?;
        Ok(norm)
    }

    /// `self += a x`, `x`'s entries a subset of `self`'s pattern (`MatAXPY`); both
    /// assembled.
    ///
    /// # Errors
    /// PETSc's (an entry of `x` outside `self`'s pattern).
    pub fn add_scaled(&mut self, a: f64, x: &Matrix) -> Result<()> {
        // SAFETY: live matrices of one layout
        check("MatAXPY", unsafe {
            sys::MatAXPY(self.raw, a, x.raw, sys::MatStructure_SUBSET_NONZERO_PATTERN)
        })
    }

    /// A copy (pattern and values).
    ///
    /// # Errors
    /// PETSc's.
    pub fn duplicate(&self) -> Result<Matrix<'p>> {
        let mut raw = std::ptr::null_mut();
        // SAFETY: a live matrix; the copy is owned by the result
        check("MatDuplicate", unsafe {
            sys::MatDuplicate(self.raw, sys::MatDuplicateOption_MAT_COPY_VALUES, &mut raw)
        })?;
        Ok(Matrix {
            raw,
            _petsc: std::marker::PhantomData,
        })
    }

    /// Sets every entry to zero, keeping the pattern (before a new
    /// [`Matrix::add`] and [`Matrix::assemble`]).
    ///
    /// # Errors
    /// PETSc's.
    pub fn zero_entries(&mut self) -> Result<()> {
        // SAFETY: a live matrix
        check("MatZeroEntries", unsafe { sys::MatZeroEntries(self.raw) })
    }

    /// `y = A x`.
    ///
    /// # Errors
    /// PETSc's (sizes that do not match).
    pub fn multiply(&self, x: &VectorView, y: &mut VectorView) -> Result<()> {
        // SAFETY: live objects
        check("MatMult", unsafe { sys::MatMult(self.raw, x.raw, y.raw) })
    }
}

impl Drop for Matrix<'_> {
    fn drop(&mut self) {
        // SAFETY: owned
        unsafe {
            sys::MatDestroy(&mut self.raw);
        }
    }
}

/// The entries a matrix will hold, declared to [`Matrix::with_pattern`] before any
/// value (rows of any rank).
pub struct Pattern {
    raw: sys::Mat,
    zeros: Vec<f64>,
}

impl Pattern {
    /// Declares the entries `rows × columns` (global indices).
    ///
    /// # Errors
    /// PETSc's (an index beyond the matrix).
    pub fn add(&mut self, rows: &[usize], columns: &[usize]) -> Result<()> {
        let r = petsc_ints("MatSetValues", rows)?;
        let c = petsc_ints("MatSetValues", columns)?;
        self.zeros.resize(r.len() * c.len(), 0.0);
        // SAFETY: arrays of the lengths passed
        check("MatSetValues", unsafe {
            sys::MatSetValues(
                self.raw,
                r.len() as sys::PetscInt,
                r.as_ptr(),
                c.len() as sys::PetscInt,
                c.as_ptr(),
                self.zeros.as_ptr(),
                sys::InsertMode_ADD_VALUES,
            )
        })
    }
}

/// The entries of a distributed vector that one rank reads — its own and its ghosts
/// (those of other ranks its rows couple to) — brought in by one `VecScatter` per
/// [`Ghosts::read`], instead of the whole vector.
pub struct Ghosts {
    scatter: sys::VecScatter,
    local: sys::Vec,
}

impl Ghosts {
    /// The scatter from vectors laid out as `x` to the entries `indices` (global, in the
    /// order given), on this rank.
    ///
    /// # Errors
    /// An index beyond PETSc's `PetscInt` or `x`'s size, or PETSc's.
    pub fn new(petsc: &Petsc, x: &Vector, indices: &[usize]) -> Result<Self> {
        let global = petsc_ints("ISCreateGeneral", indices)?;
        let n = global.len() as sys::PetscInt;
        let (mut is, mut local, mut scatter) = (
            std::ptr::null_mut(),
            std::ptr::null_mut(),
            std::ptr::null_mut(),
        );
        let self_comm = petsc.comm_self();
        // SAFETY: the index set copies `global`; the sequential vector and the scatter
        // are owned by the result, the index set destroyed here
        unsafe {
            check(
                "ISCreateGeneral",
                sys::ISCreateGeneral(
                    self_comm,
                    n,
                    global.as_ptr(),
                    sys::PetscCopyMode_PETSC_COPY_VALUES,
                    &mut is,
                ),
            )?;
            let created = check("VecCreateSeq", sys::VecCreateSeq(self_comm, n, &mut local))
                .and_then(|()| {
                    check(
                        "VecScatterCreate",
                        sys::VecScatterCreate(x.raw, is, local, std::ptr::null_mut(), &mut scatter),
                    )
                });
            sys::ISDestroy(&mut is);
            if let Err(e) = created {
                sys::VecDestroy(&mut local);
                return Err(e);
            }
        }
        Ok(Self { scatter, local })
    }

    /// The entries of `x` at the indices given to [`Ghosts::new`], in their order.
    ///
    /// # Errors
    /// PETSc's (a vector of another layout).
    pub fn read(&mut self, x: &VectorView) -> Result<Vec<f64>> {
        // SAFETY: live objects; the scatter was made for vectors of x's layout
        unsafe { scatter_forward(self.scatter, x.raw, self.local)? };
        local_values(self.local)
    }
}

impl Drop for Ghosts {
    fn drop(&mut self) {
        // SAFETY: owned
        unsafe {
            sys::VecScatterDestroy(&mut self.scatter);
            sys::VecDestroy(&mut self.local);
        }
    }
}

/// A vector a SNES callback sees (PETSc's, borrowed for the call).
pub struct VectorView {
    raw: sys::Vec,
}

impl VectorView {
    /// `self += a x`.
    ///
    /// # Errors
    /// PETSc's.
    pub fn axpy(&mut self, a: f64, x: &VectorView) -> Result<()> {
        // SAFETY: live vectors
        check("VecAXPY", unsafe { sys::VecAXPY(self.raw, a, x.raw) })
    }

    /// The view of a vector of ours.
    pub fn of(vector: &Vector) -> Self {
        Self { raw: vector.raw }
    }

    /// Every entry, on every rank.
    ///
    /// # Errors
    /// PETSc's.
    pub fn gather(&self) -> Result<Vec<f64>> {
        gather(self.raw)
    }

    /// Adds `values` at global `indices`, on any rank; takes effect at
    /// [`VectorView::assemble`].
    ///
    /// # Errors
    /// Lengths that differ, or PETSc's.
    pub fn add(&mut self, indices: &[usize], values: &[f64]) -> Result<()> {
        if indices.len() != values.len() {
            return Err(Error::refused(
                "VecSetValues",
                format!("{} indices for {} values", indices.len(), values.len()),
            ));
        }
        let indices = petsc_ints("VecSetValues", indices)?;
        // SAFETY: arrays of the length passed
        check("VecSetValues", unsafe {
            sys::VecSetValues(
                self.raw,
                indices.len() as sys::PetscInt,
                indices.as_ptr(),
                values.as_ptr(),
                sys::InsertMode_ADD_VALUES,
            )
        })
    }

    /// Communicates the values added for entries other ranks own.
    ///
    /// # Errors
    /// PETSc's.
    pub fn assemble(&mut self) -> Result<()> {
        // SAFETY: a live vector
        check("VecAssemblyBegin", unsafe {
            sys::VecAssemblyBegin(self.raw)
        })?;
        check("VecAssemblyEnd", unsafe { sys::VecAssemblyEnd(self.raw) })
    }

    /// The dot product with `other` over all ranks (`VecDot`; every rank calls it).
    ///
    /// # Errors
    /// PETSc's.
    pub fn dot(&self, other: &VectorView) -> Result<f64> {
        let mut value = 0.0;
        // SAFETY: live vectors of one layout
        check("VecDot", unsafe {
            sys::VecDot(self.raw, other.raw, &mut value)
        })?;
        Ok(value)
    }

    /// Writes the entries this rank owns, in order.
    ///
    /// # Errors
    /// `values` not of the local size, or PETSc's.
    pub fn write_local(&mut self, values: &[f64]) -> Result<()> {
        let mut n = 0;
        let mut array: *mut f64 = std::ptr::null_mut();
        // SAFETY: the array is valid for the local size until restored
        unsafe {
            check("VecGetLocalSize", sys::VecGetLocalSize(self.raw, &mut n))?;
            if n as usize != values.len() {
                return Err(Error::refused(
                    "VecGetArray",
                    format!("{} values for {n} local entries", values.len()),
                ));
            }
            check("VecGetArray", sys::VecGetArray(self.raw, &mut array))?;
            std::ptr::copy_nonoverlapping(values.as_ptr(), array, values.len());
            check(
                "VecRestoreArray",
                sys::VecRestoreArray(self.raw, &mut array),
            )
        }
    }
}

/// The residual `F(x)` of a SNES, written into its second argument.
pub type Residual<'a> = Box<dyn FnMut(&VectorView, &mut VectorView) -> Result<()> + 'a>;

/// What a converged SNES reports.
#[derive(Clone, Debug, PartialEq)]
pub struct Converged {
    /// PETSc's converged reason (`CONVERGED_FNORM_RELATIVE`).
    pub reason: String,
    /// Newton iterations.
    pub iterations: usize,
    /// Linear solver iterations over all Newton steps.
    pub linear_iterations: usize,
    /// The linear solver the options made: KSP and PC types, and the factorization's
    /// package where the PC factors (`cg + gamg`, `preonly + lu (mumps)`).
    pub linear_solver: String,
}

/// The linear solver of a solved SNES, as [`Converged::linear_solver`] names it.
///
/// # Safety
/// `snes` is a live SNES.
unsafe fn linear_solver_of(snes: sys::SNES) -> Result<String> {
    let text = |name: *const std::os::raw::c_char| {
        if name.is_null() {
            "none".to_string()
        } else {
            // SAFETY: PETSc's type names are NUL-terminated strings it owns
            unsafe { CStr::from_ptr(name) }
                .to_string_lossy()
                .into_owned()
        }
    };
    // SAFETY: the caller's live SNES; the KSP and PC it owns
    unsafe {
        let mut ksp = std::ptr::null_mut();
        check("SNESGetKSP", sys::SNESGetKSP(snes, &mut ksp))?;
        let mut pc = std::ptr::null_mut();
        check("KSPGetPC", sys::KSPGetPC(ksp, &mut pc))?;
        let (mut ksp_type, mut pc_type, mut package) =
            (std::ptr::null(), std::ptr::null(), std::ptr::null());
        check("KSPGetType", sys::KSPGetType(ksp, &mut ksp_type))?;
        check("PCGetType", sys::PCGetType(pc, &mut pc_type))?;
        // null where the PC does not factor
        check(
            "PCFactorGetMatSolverType",
            sys::PCFactorGetMatSolverType(pc, &mut package),
        )?;
        let mut name = format!("{} + {}", text(ksp_type), text(pc_type));
        if !package.is_null() {
            name.push_str(&format!(" ({})", text(package)));
        }
        Ok(name)
    }
}

/// The name of a SNES converged reason.
pub fn reason_name(reason: sys::SNESConvergedReason) -> &'static str {
    match reason {
        2 => "CONVERGED_FNORM_ABS",
        3 => "CONVERGED_FNORM_RELATIVE",
        4 => "CONVERGED_SNORM_RELATIVE",
        5 => "CONVERGED_ITS",
        6 => "BREAKOUT_INNER_ITER",
        0 => "CONVERGED_ITERATING",
        -1 => "DIVERGED_FUNCTION_DOMAIN",
        -2 => "DIVERGED_FUNCTION_COUNT",
        -3 => "DIVERGED_LINEAR_SOLVE",
        -4 => "DIVERGED_FNORM_NAN",
        -5 => "DIVERGED_MAX_IT",
        -6 => "DIVERGED_LINE_SEARCH",
        -7 => "DIVERGED_INNER",
        -8 => "DIVERGED_LOCAL_MIN",
        -9 => "DIVERGED_DTOL",
        -10 => "DIVERGED_JACOBIAN_DOMAIN",
        -11 => "DIVERGED_TR_DELTA",
        _ => "an unknown reason",
    }
}

/// The update of a SNES's Jacobian at `x`, written into the matrix (its entries
/// replaced; the pattern is the one preallocated).
pub type JacobianUpdate<'a, 'p> = Box<dyn FnMut(&VectorView, &mut Matrix<'p>) -> Result<()> + 'a>;

/// An objective whose gradient is the residual: the line search decreases it
/// (`SNESSetObjective`) instead of the residual's norm.
pub type Objective<'a> = Box<dyn FnMut(&VectorView) -> Result<f64> + 'a>;

/// Choices a solve makes before PETSc reads its options database, so that any option the
/// user gives (`-ksp_type cg -pc_type gamg`, `-snes_linesearch_type bt`) overrides them;
/// `None` leaves PETSc's own default.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Defaults {
    /// The Krylov method (`preonly` for a direct solve).
    pub ksp_type: Option<&'static CStr>,
    /// The preconditioner (`lu`, `cholesky`, `gamg`).
    pub pc_type: Option<&'static CStr>,
    /// The package that factors (`mumps`).
    pub factor_package: Option<&'static CStr>,
    /// The line search (`basic`: full Newton steps).
    pub line_search: Option<&'static CStr>,
    /// SNES's relative tolerance on the residual norm.
    pub rtol: Option<f64>,
    /// SNES's absolute tolerance on the residual norm (a start that is the solution
    /// already has a residual at rounding, which no relative decrease can follow); at
    /// least the smallest positive double, since PETSc's test is `‖F‖ < atol`: a problem
    /// whose solution is exactly the start (no load, nothing pressed: ‖F‖ = 0 and a
    /// scale of 0) otherwise took a zero Newton step and failed its line search.
    pub atol: Option<f64>,
    /// At least one Newton step whatever the start's residual (`SNESSetForceIteration`):
    /// the mixed formulation's absolute tolerance, scaled by `‖(F, G)‖`, stopped at the
    /// start `U = 0` of a problem whose load on the free unknowns is rounding
    /// (membrane-radial at N = 2, one free vertex, `F` ~ 10⁻¹⁶), whose equilibrium
    /// residual relative to that `F` is 1: refused by the KKT check instead of answered.
    /// Off where `(F, G) = 0`: the start is then the solution, and a forced zero step
    /// fails a backtracking line search.
    pub force_iteration: bool,
}

impl Defaults {
    /// Sets these defaults on `snes` (before `SNESSetFromOptions`).
    ///
    /// # Safety
    /// `snes` is a live SNES.
    unsafe fn apply(&self, snes: sys::SNES) -> Result<()> {
        // SAFETY: the caller's live SNES; the KSP, PC and line search it owns
        unsafe {
            let mut ksp = std::ptr::null_mut();
            check("SNESGetKSP", sys::SNESGetKSP(snes, &mut ksp))?;
            if let Some(t) = self.ksp_type {
                check("KSPSetType", sys::KSPSetType(ksp, t.as_ptr()))?;
            }
            let mut pc = std::ptr::null_mut();
            check("KSPGetPC", sys::KSPGetPC(ksp, &mut pc))?;
            if let Some(t) = self.pc_type {
                check("PCSetType", sys::PCSetType(pc, t.as_ptr()))?;
            }
            if let Some(t) = self.factor_package {
                check(
                    "PCFactorSetMatSolverType",
                    sys::PCFactorSetMatSolverType(pc, t.as_ptr()),
                )?;
            }
            if let Some(t) = self.line_search {
                let mut search = std::ptr::null_mut();
                check(
                    "SNESGetLineSearch",
                    sys::SNESGetLineSearch(snes, &mut search),
                )?;
                check(
                    "SNESLineSearchSetType",
                    sys::SNESLineSearchSetType(search, t.as_ptr()),
                )?;
            }
            if self.force_iteration {
                check(
                    "SNESSetForceIteration",
                    sys::SNESSetForceIteration(snes, sys::PetscBool_PETSC_TRUE),
                )?;
            }
            if self.rtol.is_some() || self.atol.is_some() {
                let (mut atol, mut r, mut stol, mut its, mut evaluations) = (0.0, 0.0, 0.0, 0, 0);
                check(
                    "SNESGetTolerances",
                    sys::SNESGetTolerances(
                        snes,
                        &mut atol,
                        &mut r,
                        &mut stol,
                        &mut its,
                        &mut evaluations,
                    ),
                )?;
                check(
                    "SNESSetTolerances",
                    sys::SNESSetTolerances(
                        snes,
                        self.atol.map_or(atol, |a| a.max(f64::MIN_POSITIVE)),
                        self.rtol.unwrap_or(r),
                        stol,
                        its,
                        evaluations,
                    ),
                )?;
            }
        }
        Ok(())
    }
}

/// How a SNES gets its Jacobian.
enum Jacobian<'a, 'p> {
    /// A constant matrix, copied into the working one at each callback.
    Constant(&'a Matrix<'p>),
    /// The working matrix, rewritten by the closure at each callback.
    Computed(JacobianUpdate<'a, 'p>),
}

struct Callbacks<'a, 'p> {
    residual: Residual<'a>,
    jacobian: Jacobian<'a, 'p>,
    working: Matrix<'p>,
    objective: Option<Objective<'a>>,
}

/// `result` of a callback as PETSc's error code (a panic is a user error: unwinding
/// through C is undefined).
fn callback_code(result: std::thread::Result<Result<()>>) -> sys::PetscErrorCode {
    match result {
        Ok(Ok(())) => 0,
        Ok(Err(e)) if e.code != 0 => e.code,
        _ => sys::PETSC_ERR_USER as sys::PetscErrorCode,
    }
}

unsafe extern "C" fn residual_trampoline(
    _snes: sys::SNES,
    x: sys::Vec,
    f: sys::Vec,
    context: *mut c_void,
) -> sys::PetscErrorCode {
    // SAFETY: `context` is the Callbacks the solve boxed, alive for the whole SNESSolve
    let callbacks = unsafe { &mut *(context as *mut Callbacks) };
    callback_code(std::panic::catch_unwind(std::panic::AssertUnwindSafe(
        || (callbacks.residual)(&VectorView { raw: x }, &mut VectorView { raw: f }),
    )))
}

/// The Jacobian callback. A constant Jacobian is copied into the SNES's working matrix,
/// which SNESVI's semismooth method scales in place (`vinewtonssls` forms the
/// Fischer–Burmeister Jacobian in the matrix it is given: handed the caller's own, it
/// corrupted both the Jacobian and every later residual).
unsafe extern "C" fn jacobian_trampoline(
    _snes: sys::SNES,
    x: sys::Vec,
    _jacobian: sys::Mat,
    _preconditioner: sys::Mat,
    context: *mut c_void,
) -> sys::PetscErrorCode {
    // SAFETY: `context` is the Callbacks the solve boxed, alive for the whole SNESSolve;
    // the matrices PETSc passes are its `working` one
    let callbacks = unsafe { &mut *(context as *mut Callbacks) };
    callback_code(std::panic::catch_unwind(std::panic::AssertUnwindSafe(
        || match &mut callbacks.jacobian {
            Jacobian::Constant(matrix) => check("MatCopy", unsafe {
                sys::MatCopy(
                    matrix.raw,
                    callbacks.working.raw,
                    sys::MatStructure_SAME_NONZERO_PATTERN,
                )
            }),
            Jacobian::Computed(update) => update(&VectorView { raw: x }, &mut callbacks.working),
        },
    )))
}

unsafe extern "C" fn objective_trampoline(
    _snes: sys::SNES,
    x: sys::Vec,
    value: *mut sys::PetscReal,
    context: *mut c_void,
) -> sys::PetscErrorCode {
    // SAFETY: `context` is the Callbacks the solve boxed, alive for the whole SNESSolve;
    // `value` is PETSc's
    let callbacks = unsafe { &mut *(context as *mut Callbacks) };
    callback_code(std::panic::catch_unwind(std::panic::AssertUnwindSafe(
        || {
            let objective = callbacks
                .objective
                .as_mut()
                .ok_or(Error::refused("SNESSetObjective", "no objective"))?;
            let v = objective(&VectorView { raw: x })?;
            // SAFETY: PETSc's pointer to the value
            unsafe { *value = v };
            Ok(())
        },
    )))
}

/// Solves `F(x) = 0` subject to `lower ≤ x ≤ upper` (SNESVI; `vinewtonrsls` unless the
/// options say otherwise) from the start in `x`, where `F` has the constant Jacobian
/// `jacobian` (a quadratic energy's gradient, as the nodal method's): `residual` writes
/// `F(x)`. Options from the database apply (`-snes_type vinewtonssls`, `-pc_type gamg`,
/// `-snes_monitor`); without bounds (`None`) it is a plain SNES.
///
/// # Errors
/// PETSc's, or a SNES that stopped without converging: its reason, named.
pub fn solve(
    jacobian: &Matrix,
    residual: Residual<'_>,
    bounds: Option<(&Vector, &Vector)>,
    x: &mut Vector,
) -> Result<Converged> {
    solve_with(&Defaults::default(), jacobian, residual, bounds, x)
}

/// [`solve`] with `defaults` in place of PETSc's own (the options still override them).
///
/// # Errors
/// Those of [`solve`].
pub fn solve_with(
    defaults: &Defaults,
    jacobian: &Matrix,
    residual: Residual<'_>,
    bounds: Option<(&Vector, &Vector)>,
    x: &mut Vector,
) -> Result<Converged> {
    let working = jacobian.duplicate()?;
    run(
        Callbacks {
            residual,
            jacobian: Jacobian::Constant(jacobian),
            working,
            objective: None,
        },
        defaults,
        bounds,
        x,
    )
}

/// [`solve_with`] for the affine `F(x) = J x − b`: `jacobian` is `J`, `right` is `b`
/// (a quadratic energy's gradient, as the nodal method's, or the mixed complementarity
/// system of an LCP).
///
/// # Errors
/// Those of [`solve`].
pub fn solve_affine(
    defaults: &Defaults,
    jacobian: &Matrix,
    right: &Vector,
    bounds: Option<(&Vector, &Vector)>,
    x: &mut Vector,
) -> Result<Converged> {
    let residual = |x: &VectorView, r: &mut VectorView| {
        jacobian.multiply(x, r)?;
        r.axpy(-1.0, &VectorView::of(right))
    };
    solve_with(defaults, jacobian, Box::new(residual), bounds, x)
}

/// Minimizes `objective` from the start in `x` by Newton's method (a plain SNES, its
/// line search on the objective; `defaults` before the options): `gradient` writes the
/// objective's gradient, `hessian` its (generalized) Hessian into `matrix`, which is
/// preallocated for every entry the Hessian can have. For convex C¹ objectives with a semismooth gradient, as the
/// multiplier-eliminated obstacle problem's Φ (docs/mathematics.md §1).
///
/// # Errors
/// PETSc's, or a SNES that stopped without converging: its reason, named.
pub fn minimize<'p>(
    defaults: &Defaults,
    objective: Objective<'_>,
    gradient: Residual<'_>,
    hessian: JacobianUpdate<'_, 'p>,
    matrix: Matrix<'p>,
    x: &mut Vector,
) -> Result<Converged> {
    // the Hessian of a convex objective, positive definite where the problem is posed
    let mut matrix = matrix;
    matrix.set_spd()?;
    run(
        Callbacks {
            residual: gradient,
            jacobian: Jacobian::Computed(hessian),
            working: matrix,
            objective: Some(objective),
        },
        defaults,
        None,
        x,
    )
}

/// The SNES of [`solve`] and [`minimize`].
fn run(
    callbacks: Callbacks<'_, '_>,
    defaults: &Defaults,
    bounds: Option<(&Vector, &Vector)>,
    x: &mut Vector,
) -> Result<Converged> {
    let mut snes = std::ptr::null_mut();
    let mut callbacks = Box::new(callbacks);
    let working = callbacks.working.raw;
    let has_objective = callbacks.objective.is_some();
    let context = &mut *callbacks as *mut Callbacks as *mut c_void;
    // SAFETY: the SNES is created, used and destroyed here; `callbacks` outlives it
    unsafe {
        let mut comm = std::ptr::null_mut();
        check(
            "PetscObjectGetComm",
            sys::PetscObjectGetComm(x.raw as sys::PetscObject, &mut comm),
        )?;
        check("SNESCreate", sys::SNESCreate(comm, &mut snes))?;
        let result = (|| {
            if bounds.is_some() {
                check(
                    "SNESSetType",
                    sys::SNESSetType(snes, c"vinewtonrsls".as_ptr()),
                )?;
            }
            let mut r = std::ptr::null_mut();
            check("VecDuplicate", sys::VecDuplicate(x.raw, &mut r))?;
            let r = Vector {
                raw: r,
                _petsc: std::marker::PhantomData,
            };
            check(
                "SNESSetFunction",
                sys::SNESSetFunction(snes, r.raw, Some(residual_trampoline), context),
            )?;
            check(
                "SNESSetJacobian",
                sys::SNESSetJacobian(snes, working, working, Some(jacobian_trampoline), context),
            )?;
            if has_objective {
                check(
                    "SNESSetObjective",
                    sys::SNESSetObjective(snes, Some(objective_trampoline), context),
                )?;
            }
            if let Some((lower, upper)) = bounds {
                check(
                    "SNESVISetVariableBounds",
                    sys::SNESVISetVariableBounds(snes, lower.raw, upper.raw),
                )?;
            }
            defaults.apply(snes)?;
            check("SNESSetFromOptions", sys::SNESSetFromOptions(snes))?;
            check(
                "SNESSolve",
                sys::SNESSolve(snes, std::ptr::null_mut(), x.raw),
            )?;
            let mut reason = 0;
            check(
                "SNESGetConvergedReason",
                sys::SNESGetConvergedReason(snes, &mut reason),
            )?;
            let (mut iterations, mut linear) = (0, 0);
            check(
                "SNESGetIterationNumber",
                sys::SNESGetIterationNumber(snes, &mut iterations),
            )?;
            check(
                "SNESGetLinearSolveIterations",
                sys::SNESGetLinearSolveIterations(snes, &mut linear),
            )?;
            let linear_solver = linear_solver_of(snes)?;
            if reason <= 0 {
                return Err(Error::refused(
                    "SNESSolve",
                    format!(
                        "did not converge: {} after {iterations} iterations",
                        reason_name(reason)
                    ),
                ));
            }
            Ok(Converged {
                reason: reason_name(reason).to_string(),
                iterations: iterations as usize,
                linear_iterations: linear as usize,
                linear_solver,
            })
        })();
        sys::SNESDestroy(&mut snes);
        result
    }
}
