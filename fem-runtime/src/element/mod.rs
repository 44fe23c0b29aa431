//! Elements on physical cells: the reference-to-physical map and its chain rule
//! ([`mapping`]; the six-node map of curved cells in [`isoparametric`]), basis values and derivatives at points of interval cells
//! ([`interval`]), and finite element functions on triangle meshes with their values,
//! gradients, Hessians, integrals and errors ([`triangle`]).

pub mod interval;
pub mod isoparametric;
pub mod mapping;
pub mod triangle;

pub use isoparametric::Isoparametric;
pub use mapping::Affine;

pub use interval::PhysicalBasis;
pub use triangle::{TriangleBasis, TriangleField};
