//! Complementarity solvers that live outside this crate: PETSc's SNES and SNESVI driven
//! over MPI (the `fem-petsc` crate) plugs in here, so that the one pipeline (problem,
//! nested levels, report, estimators, output) runs unchanged around it.
//!
//! An [`ExternalSolver`] receives each level's LCP
//! `A U − Bᵀ Λ = F, 0 ≤ Λ ⊥ B U + C Λ − G ≥ 0` ([`Lcp`]) and the primal start that
//! nested iteration prolonged from the coarser level, and returns `(U, Λ)`; the caller
//! checks the answer by its KKT residual as it checks its own solvers'.

use super::{Lcp, LcpSolution};
use crate::error::Result;

/// A solver of one LCP outside this crate, chosen by
/// [`crate::obstacle::VariationalSolver::External`].
pub trait ExternalSolver: Send + Sync {
    /// Its name in reports (`"petsc"`).
    fn name(&self) -> &'static str;

    /// Solves `lcp` from the primal unknowns `start` (nested iteration's prolonged
    /// solution; `None`: the solver's own start).
    ///
    /// # Errors
    /// A problem the solver does not take, and a solve that does not converge (named by
    /// the solver's reason), never an unconverged answer.
    fn solve(&self, lcp: &Lcp, start: Option<&[f64]>) -> Result<LcpSolution>;

    /// Marks the solves that follow as serving `purpose`, for the solver's own records
    /// (a report that lists its solves says which gave the answer); by default nothing.
    fn set_purpose(&self, purpose: Purpose) {
        let _ = purpose;
    }

    /// The number of solves recorded so far: a mark for [`ExternalSolver::relabel`]; by
    /// default 0 (no records).
    fn recorded(&self) -> usize {
        0
    }

    /// Marks the recorded solves `records` (marks of [`ExternalSolver::recorded`]) as
    /// serving `purpose`: a probe of the model choice that it takes as the answer; by
    /// default nothing.
    fn relabel(&self, records: std::ops::Range<usize>, purpose: Purpose) {
        let _ = (records, purpose);
    }
}

/// What an LCP solve serves, as an [`ExternalSolver`]'s records name it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Purpose {
    /// The answer: the levels of a nested solve, each level of an adaptive one, and a
    /// probe the model choice takes as its answer (relabelled).
    #[default]
    Answer,
    /// A probe of the model choice (a candidate on a coarse mesh).
    Probe,
    /// The rounding experiment's solves on the mesh moved in its last bits.
    RoundingExperiment,
}

impl Purpose {
    /// Its name in reports (`answer`, `probe`, `rounding experiment`).
    pub fn name(self) -> &'static str {
        match self {
            Purpose::Answer => "answer",
            Purpose::Probe => "probe",
            Purpose::RoundingExperiment => "rounding experiment",
        }
    }
}

/// A handle on an [`ExternalSolver`] that lives for the whole process (a solver set up
/// once by the command line, e.g. PETSc after `MPI_Init`); compared by identity.
#[derive(Clone, Copy)]
pub struct External(pub &'static dyn ExternalSolver);

impl std::fmt::Debug for External {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "External({})", self.0.name())
    }
}

impl PartialEq for External {
    fn eq(&self, other: &Self) -> bool {
        std::ptr::addr_eq(self.0, other.0)
    }
}

impl Eq for External {}
