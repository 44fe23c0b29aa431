//! The fem-forms runtime: meshes, elements on physical cells, DOF maps, sparse assembly
//! of generated kernels into faer matrices, boundary conditions and solvers.
//!
//! Reference elements and quadrature rules come from `fem-reference`, the same crate the
//! form compiler evaluates at compile time, and are re-exported here.
#![warn(missing_docs)]

pub mod assembly;
pub mod boundary;
pub mod complementarity;
pub mod dof_map;
pub mod element;
pub mod error;
pub mod gmsh;
pub mod kernel;
pub mod linear_problem;
pub mod linear_solve;
pub mod mesh;
pub mod model;
pub mod norms;
pub mod obstacle;
pub mod obstacle_2d;
pub mod stabilization;
pub mod triangle_field;
pub mod triangle_mesh;
pub mod vtk;
pub mod woodbury;

pub use assembly::{assemble_vector, MatrixAssembler};
pub use boundary::{Constraints, Reduction, Side};
pub use dof_map::{DofMap, SystemDofs};
pub use error::{Error, Result};
pub use fem_reference as reference;
pub use fem_reference::{gauss_legendre, CellKind, ElementKind, QuadratureRule};
pub use linear_problem::{solve_linear, Factorization};
pub use mesh::IntervalMesh;
pub use model::{BlockInfo, Coefficients, DataFn, FieldInfo, FormInfo, Model};
pub use triangle_mesh::{Diagonal, PointLocator, TriangleMesh};

/// Re-exported sparse matrix type of the assembled systems.
pub type SparseMatrix = faer::sparse::SparseColMat<usize, f64>;

#[doc(hidden)]
pub mod __private {
    pub use fem_forms_macro::model;
}

/// Compiles a model file written in the fem-forms DSL into element kernels.
///
/// See the `fem-forms-macro` crate documentation for the grammar. The generated code
/// names this crate through `$crate`, so the macro works from any crate that can name
/// `fem_runtime` (or `fem_forms`, which re-exports it).
#[macro_export]
macro_rules! model {
    ($($body:tt)*) => {
        $crate::__private::model! { @crate $crate; $($body)* }
    };
}
