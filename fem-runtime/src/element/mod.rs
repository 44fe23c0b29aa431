//! Elements on physical cells: basis values and derivatives at points of interval cells
//! ([`interval`]), and finite element functions on triangle meshes with their values,
//! gradients, integrals and errors ([`triangle`]).

pub mod interval;
pub mod triangle;

pub use interval::PhysicalBasis;
pub use triangle::{TriangleBasis, TriangleField};
