//! Reference elements and quadrature rules of fem-forms.
//!
//! This crate has no dependencies on purpose: the form compiler (`fem-forms-macro`)
//! evaluates these elements and rules at compile time to tabulate basis values as
//! constants, and the runtime (`fem-runtime`) re-exports the very same definitions,
//! so the generated kernels and the runtime can never disagree about a basis function.
//!
//! Elements that are not plain Lagrange can be declared as data: [`dual_basis`] builds a
//! nodal basis from DOF functionals (Argyris, Morley, Lagrange) by inverting the
//! generalized Vandermonde matrix ([`dense`]), and [`dof_transformation`] gives the
//! per-cell matrix mapping the reference basis to the physical one for elements that are
//! not affine-equivalent (`docs/elements.md`).
#![warn(missing_docs)]

pub mod dense;
pub mod dof_transformation;
pub mod dual_basis;
pub mod polynomial;
pub mod quadrature;
pub mod reference_element;
pub mod triangle;

pub use dof_transformation::{argyris_transformation, morley_transformation};
pub use dual_basis::ElementDefinition;
pub use polynomial::Polynomial;
pub use quadrature::{gauss_legendre, QuadratureRule};
pub use reference_element::{CellKind, DofLocation, ElementKind};
