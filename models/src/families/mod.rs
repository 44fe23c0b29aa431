//! The model families of the registry ([`crate::family`]): each one's pairs, scenes and
//! own quantities.

pub mod beam;
pub mod kirchhoff;
pub mod membrane;
pub mod plate;
