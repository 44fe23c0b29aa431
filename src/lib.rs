//! fem-forms: a form compiler and solver for stabilized finite element methods of
//! obstacle and contact problems of thin structures.
//!
//! This crate re-exports the runtime ([`fem_runtime`]), the `model!` macro that compiles
//! model files, and the model files and scenes of [`fem_models`]; it adds the beam scene
//! solver ([`beams`]), the studies (each kind once in [`studies`], the families' sides in [`beam_studies`] and
//! [`membrane_studies`]) and charts ([`plot`]) behind the CLI.
#![warn(missing_docs)]
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

pub mod allocator;
pub mod beam_studies;
pub mod beams;
pub mod kirchhoff;
pub mod membrane_studies;
pub mod membranes;
pub mod plates;
pub mod plot;
pub mod scene_file;
pub mod studies;

pub use fem_models as models;
pub use fem_runtime::*;
