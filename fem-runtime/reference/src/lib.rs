//! Reference elements and quadrature rules of fem-forms.
//!
//! This crate has no dependencies on purpose: the form compiler (`fem-forms-macro`)
//! evaluates these elements and rules at compile time to tabulate basis values as
//! constants, and the runtime (`fem-runtime`) re-exports the very same definitions,
//! so the generated kernels and the runtime can never disagree about a basis function.
#![warn(missing_docs)]

pub mod dense;
pub mod dof_transformation;
pub mod dual_basis;
pub mod polynomial;
pub mod quadrature;
pub mod reference_element;
pub mod triangle;

pub use polynomial::Polynomial;
pub use quadrature::{gauss_legendre, QuadratureRule};
pub use reference_element::{CellKind, DofLocation, ElementKind};
