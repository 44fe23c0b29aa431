//! The fem-forms runtime: meshes, elements on physical cells, DOF maps, sparse assembly
//! of generated kernels into faer matrices, boundary conditions and solvers.
//!
//! One module per concept, each a folder where it has parts:
//! [`mesh`] (intervals, triangles, Gmsh files, refinement, point location, boundary
//! parts, quadratic geometry of curved domains),
//! [`element`] (the affine and the isoparametric cell maps, bases on physical cells,
//! finite element functions),
//! [`assembly`] (DOF maps, the pattern built once, boundary conditions, linear problems),
//! [`lcp`] (the complementarity problem, semismooth Newton, clarabel, Cholesky with
//! low-rank updates), [`obstacle`] (a model's VI: the nested solve, the nodal method),
//! [`stabilization`] (the element constant C_I from the model's own kernels and the α
//! policy), [`multigrid`] (prolongation on nested meshes, Galerkin cycles, MG-CG),
//! [`norms`] and [`io`]. No module imports one that imports it back
//! (`tests/module_cycles.rs` checks it).
//!
//! To solve a model of your own from Rust, start from `examples/winkler_string.rs` in
//! the repository (a model file and a short program: a [`problem::Problem`] of the
//! meshes, the parameters and data by typed handle, the supports, one
//! [`problem::Problem::solve`] and its [`problem::Report`]), and the README's section
//! "Solving your own model from Rust".
//!
//! Reference elements and quadrature rules come from `fem-reference`, the same crate the
//! form compiler evaluates at compile time, and are re-exported here.
#![warn(missing_docs)]
// test models use the mathematical names (α, ℓ) next to ASCII ones
#![cfg_attr(test, allow(confusable_idents, mixed_script_confusables))]

pub mod adaptivity;
pub mod assembly;
pub mod element;
pub mod error;
pub mod io;
pub mod lcp;
pub mod mesh;
pub mod model;
pub mod multigrid;
pub mod norms;
pub mod obstacle;
pub mod problem;
pub mod stabilization;

pub use assembly::boundary::{Constraints, DirichletPart, PlateSupport, Reduction, Side};
pub use assembly::dof_map::{DofMap, DofNumbering, SystemDofs};
pub use assembly::linear_problem::{solve_linear, Factorization};
pub use assembly::{assemble_vector, kernel, MatrixAssembler};
pub use error::{Error, Result};
pub use fem_reference as reference;
pub use fem_reference::{gauss_legendre, CellKind, ElementKind, QuadratureRule};
pub use mesh::{CurvedTriangleMesh, Diagonal, IntervalMesh, Mesh, PointLocator, TriangleMesh};
pub use model::{
    BlockInfo, Coefficients, DataFn, DataId, FacetBlockInfo, FieldId, FieldInfo, FormId, FormInfo,
    Model, ParamId,
};
pub use stabilization::Alpha;

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
