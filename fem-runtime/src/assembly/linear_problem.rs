//! A linear variational problem `a(u, v) = ℓ(v)` with fixed DOFs, solved directly.

use crate::assembly::boundary::Constraints;
use crate::assembly::dof_map::SystemDofs;
use crate::assembly::{assemble_vector, MatrixAssembler};
use crate::error::Result;
use crate::lcp::cholesky::{Cholesky, LuSolver};
use crate::mesh::Mesh;
use crate::model::{Coefficients, Model};

/// Which factorization to use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Factorization {
    /// Sparse Cholesky: for symmetric positive definite forms.
    Cholesky,
    /// Sparse LU: for anything square and non-singular.
    Lu,
}

/// Solves `bilinear(u, v) = linear(v)` on the fields of `dofs` with the fixed DOFs of
/// `constraints`, on any mesh (intervals, triangles); returns the full coefficient vector
/// (Cartesian DOFs: where `constraints` rotate vertex DOFs,
/// [`Constraints::change_of_basis`], the system is solved in the rotated ones and the
/// solution mapped back).
pub fn solve_linear<M: Model>(
    mesh: &impl Mesh,
    dofs: &SystemDofs,
    bilinear: &str,
    linear: &str,
    constraints: &Constraints,
    coefficients: &Coefficients,
    factorization: Factorization,
) -> Result<Vec<f64>> {
    let a = MatrixAssembler::new::<M>(bilinear, mesh, dofs)?.assemble::<M>(mesh, coefficients)?;
    let mut b = assemble_vector::<M>(linear, mesh, dofs, coefficients)?;
    let reduction = constraints.reduction(dofs.dof_count())?;
    // plate supports on edges not along x or y: solve in the rotated vertex DOFs
    let basis = constraints.change_of_basis(dofs.dof_count())?;
    let a = if basis.is_identity() {
        a
    } else {
        basis.to_primed(&mut b);
        basis.transform_matrix(&a)?
    };
    let a_free = reduction.matrix(&a);
    let b_free = reduction.rhs(&a, &b);
    let pattern = a_free.symbolic().to_owned().expect("an owned pattern");
    let factor = match factorization {
        Factorization::Cholesky => Cholesky::analyse(&pattern)?.factor(&a_free)?,
        Factorization::Lu => LuSolver::analyse(&pattern)?.factor(&a_free)?,
    };
    let u = factor.solve_refined(&a_free, &b_free, 1)?;
    let mut u = reduction.expand(&u);
    basis.to_cartesian(&mut u);
    Ok(u)
}
