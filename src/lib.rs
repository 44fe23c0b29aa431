//! fem-forms: a form compiler and solver for stabilized finite element methods of
//! obstacle and contact problems of thin structures.
//!
//! This crate re-exports the runtime ([`fem_runtime`]), the `model!` macro that compiles
//! model files, and the model files of [`fem_models`].

pub use fem_models as models;
pub use fem_runtime::*;
