//! Output: VTK unstructured grids for ParaView ([`vtk`]). Gmsh input is a mesh concern and
//! lives in [`crate::mesh::gmsh`].

pub mod vtk;
