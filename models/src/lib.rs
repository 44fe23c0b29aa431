//! fem-forms model files, one DSL file per model (docs/mathematics.md has the mathematics).
//!
//! Each model declares its fields, parameters, data and the stabilized forms
//! `B_h = a − b − bᵀ − α S_h` and `L_h = ℓ − ⟨sψ, μ⟩ − α ℓ_S` of the obstacle problem.
#![warn(missing_docs)]
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

pub mod contact_scenes;
pub mod data;
pub mod euler_bernoulli;
pub mod hertz;
pub mod kirchhoff;
pub mod kirchhoff_scenes;
pub mod membrane;
pub mod membrane_scenes;
pub mod mindlin;
pub mod plate_scenes;
pub mod registry;
pub mod signorini;
pub mod timoshenko;
pub mod vector_forms;

pub use euler_bernoulli::bernoulli;
pub use membrane::{membrane_p1, membrane_p1_p0, membrane_p2_p0, membrane_p2_p1disc};
pub use timoshenko::{timoshenko_p1_full, timoshenko_p1_reduced, timoshenko_p2};
pub mod scenes;
