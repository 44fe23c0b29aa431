//! `fem-forms solve --backend petsc`: the scene solved through the one pipeline with
//! PETSc over MPI as its complementarity solver (`fem_petsc::lcp`), in a binary built
//! with the `petsc` feature (docs/petsc.md). Every rank runs the same command and
//! assembles the same levels; each inserts its own rows into PETSc, which solves them
//! together; rank 0 alone prints the report (with PETSc's reasons and iteration counts
//! added) and writes the outputs.

use fem_forms::models::report::Report;
use fem_runtime::obstacle::VariationalSolver;

/// The backend's command-line options.
#[derive(Clone, Debug, Default)]
pub struct BackendOptions {
    /// `native` (default) or `petsc`.
    pub backend: Option<String>,
    /// PETSc's options, as one string.
    pub petsc_options: Option<String>,
    /// `eliminated` or `mixed`.
    pub petsc_formulation: Option<String>,
}

impl BackendOptions {
    /// Whether `--backend petsc` was given.
    ///
    /// # Errors
    /// An unknown backend, and PETSc's options without it.
    pub fn wants_petsc(&self) -> Result<bool, String> {
        let petsc = match self.backend.as_deref() {
            None | Some("native") => false,
            Some("petsc") => true,
            Some(other) => {
                return Err(format!(
                    "--backend {other}: unknown backend; `native` (default) or `petsc`"
                ))
            }
        };
        if !petsc && (self.petsc_options.is_some() || self.petsc_formulation.is_some()) {
            return Err(
                "--petsc-options and --petsc-formulation apply with --backend petsc".into(),
            );
        }
        Ok(petsc)
    }
}

/// PETSc started for one solve: finalized (PETSc, then MPI) when dropped, on every path.
pub struct Backend {
    #[cfg(feature = "petsc")]
    solver: &'static fem_petsc::lcp::PetscLcpSolver,
    /// Without PETSc no backend can exist ([`Backend::start`] refuses).
    #[cfg(not(feature = "petsc"))]
    never: std::convert::Infallible,
}

impl Backend {
    /// Starts MPI and PETSc with the options given; on ranks other than 0 the standard
    /// output and error are closed (rank 0 speaks for all).
    ///
    /// # Errors
    /// A binary built without the `petsc` feature, a formulation PETSc does not know,
    /// PETSc's initialization.
    pub fn start(options: &BackendOptions) -> Result<Self, String> {
        #[cfg(feature = "petsc")]
        {
            let formulation = options
                .petsc_formulation
                .as_deref()
                .map(fem_petsc::lcp::Formulation::parse)
                .transpose()
                .map_err(|e| format!("--petsc-formulation: {e}"))?;
            let solver = fem_petsc::lcp::PetscLcpSolver::new(
                options.petsc_options.as_deref().unwrap_or(""),
                formulation,
            )
            .map_err(|e| format!("--backend petsc: {e}"))?;
            let solver: &'static _ = Box::leak(Box::new(solver));
            let backend = Self { solver };
            // the launcher's variables silenced the other ranks already; this covers a
            // launcher that sets none
            if !backend.is_root() {
                silence_output();
            }
            Ok(backend)
        }
        #[cfg(not(feature = "petsc"))]
        {
            let _ = options;
            Err("--backend petsc: this fem-forms was built without PETSc; build it with `cargo build --release --features petsc` (needs Debian's petsc-dev, libclang-dev and libopenmpi-dev; docs/petsc.md)".into())
        }
    }

    /// The solver the pipeline is given.
    pub fn solver(&self) -> VariationalSolver {
        #[cfg(feature = "petsc")]
        {
            VariationalSolver::External(fem_runtime::lcp::external::External(self.solver))
        }
        #[cfg(not(feature = "petsc"))]
        {
            match self.never {}
        }
    }

    /// Whether this is rank 0, the one that prints and writes.
    pub fn is_root(&self) -> bool {
        #[cfg(feature = "petsc")]
        {
            self.solver.rank_and_size().0 == 0
        }
        #[cfg(not(feature = "petsc"))]
        {
            match self.never {}
        }
    }

    /// Adds `petsc` to the report: the ranks, the options, and per level solved the
    /// formulation, how it was assembled (`partitioned`: each rank its own cells, with
    /// rank 0's share of PETSc's rows; `whole`), SNES's converged reason, its Newton and
    /// linear iterations and time.
    pub fn describe(&self, report: &mut Report, options: &BackendOptions) {
        #[cfg(feature = "petsc")]
        {
            let levels: Vec<serde_json::Value> = self
                .solver
                .records()
                .iter()
                .map(|r| {
                    serde_json::json!({
                        "purpose": r.purpose.name(),
                        "formulation": r.formulation.name(),
                        "primal_unknowns": r.unknowns[0],
                        "multipliers": r.unknowns[1],
                        // each rank its own cells, or the whole LCP on every rank
                        "assembly": if r.rows_here.is_some() { "partitioned" } else { "whole" },
                        "rows_on_rank_0": r.rows_here,
                        "converged_reason": r.converged.reason,
                        "snes_iterations": r.converged.iterations,
                        "linear_iterations": r.converged.linear_iterations,
                        "linear_solver": r.converged.linear_solver,
                        "seconds": r.seconds,
                    })
                })
                .collect();
            let solved_nothing = levels.is_empty();
            report.set(
                "petsc",
                serde_json::json!({
                    "ranks": self.solver.rank_and_size().1,
                    "options": options.petsc_options.clone().unwrap_or_default(),
                    "levels": levels,
                }),
            );
            if solved_nothing {
                report.warn("PETSc solved nothing: the problem has no contact constraint to solve (a linear solve, done natively on every rank), or no free primal unknown (Λ = C⁻¹G₊ directly); --petsc-options did not apply");
            }
        }
        #[cfg(not(feature = "petsc"))]
        {
            let _ = (report, options);
            match self.never {}
        }
    }
}

impl Drop for Backend {
    fn drop(&mut self) {
        #[cfg(feature = "petsc")]
        self.solver.finalize();
    }
}

/// This process's rank and the number of ranks where an MPI launcher started it
/// (Open MPI's `OMPI_COMM_WORLD_RANK`/`_SIZE`, MPICH's `PMI_RANK`/`PMI_SIZE`), read
/// before MPI is initialized.
pub fn launcher_ranks() -> Option<(usize, usize)> {
    let read = |name: &str| std::env::var(name).ok()?.parse::<usize>().ok();
    [
        ("OMPI_COMM_WORLD_RANK", "OMPI_COMM_WORLD_SIZE"),
        ("PMI_RANK", "PMI_SIZE"),
    ]
    .into_iter()
    .find_map(|(rank, size)| Some((read(rank)?, read(size)?)))
}

/// Points this process's standard output and error at /dev/null.
pub fn silence_output() {
    // SAFETY: open(2) and dup2(2) on this process's own descriptors
    unsafe {
        let null = libc::open(c"/dev/null".as_ptr(), libc::O_WRONLY);
        if null >= 0 {
            libc::dup2(null, 1);
            libc::dup2(null, 2);
            libc::close(null);
        }
    }
}
