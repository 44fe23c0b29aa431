//! The runtime's errors: every bad input is one of these, never a panic.

use thiserror::Error;

/// What can go wrong when meshing, assembling or solving.
#[derive(Clone, Debug, Error)]
pub enum Error {
    /// A mesh that cannot be used.
    #[error("invalid mesh: {0}")]
    Mesh(String),
    /// A name that the model does not declare.
    #[error("model `{model}` has no {kind} `{name}` (it has: {available})")]
    UnknownName {
        /// The model.
        model: &'static str,
        /// "parameter", "data function", "form" or "field".
        kind: &'static str,
        /// The name asked for.
        name: String,
        /// What the model does declare.
        available: String,
    },
    /// A parameter or data function left out, or given a value that cannot be used.
    #[error("invalid input: {0}")]
    Input(String),
    /// Assembled entries that are not finite (NaN or infinite data or parameters).
    #[error("non-finite entries in the assembled {what} (first in cell {cell}): check data and parameters for NaN or infinity")]
    NonFinite {
        /// "matrix" or "vector".
        what: &'static str,
        /// A cell where it happens.
        cell: usize,
    },
    /// A linear solve that failed (singular or not positive definite).
    #[error("linear solve failed: {0}")]
    LinearSolve(String),
    /// A file that cannot be read or written.
    #[error("i/o: {0}")]
    Io(String),
    /// An iterative solver that did not converge.
    #[error("{solver} did not converge: {detail}")]
    NotConverged {
        /// Which solver.
        solver: &'static str,
        /// Iterations, residuals, what was tried.
        detail: String,
    },
}

/// Result with the runtime's error.
pub type Result<T> = std::result::Result<T, Error>;
