//! Poisson's equation on triangle meshes with P1, P2 and P3: each element reproduces a
//! polynomial of its degree exactly, which checks the generated kernels, the DOF maps
//! (P3's two DOFs per edge must agree between neighbours of either orientation), the
//! Dirichlet data of `boundary:` and the assembly, on meshes of every diagonal pattern
//! and after local newest-vertex refinement.
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

use fem_forms::lcp::cholesky::Cholesky;
use fem_forms::obstacle::triangle::dirichlet_constraints;
use fem_forms::{
    assemble_vector, Coefficients, DataFn, Diagonal, MatrixAssembler, Model, SystemDofs,
    TriangleMesh,
};

fem_forms::model! {
    /// −Δu = f, u = g on ∂Ω, u ∈ P1.
    pub mod poisson_p1 on triangle {
        unknowns: u: P1;
        tests: v;
        data: f: 1, g;
        boundary: u = g;
        forms: "
            a(u;v) = ∫ ∇u·∇v
            ℓ(v)   = ∫ f v
        ";
    }
}

fem_forms::model! {
    /// −Δu = f, u = g on ∂Ω, u ∈ P2.
    pub mod poisson_p2 on triangle {
        unknowns: u: P2;
        tests: v;
        data: f: 1, g;
        boundary: u = g;
        forms: "
            a(u;v) = int grad u dot grad v
            ℓ(v)   = int f v
        ";
    }
}

fem_forms::model! {
    /// −Δu = f, u = g on ∂Ω, u ∈ P3.
    pub mod poisson_p3 on triangle {
        unknowns: u: P3;
        tests: v;
        data: f: 1, g;
        boundary: u = g;
        forms: "
            a(u;v) = ∫ ∇u·∇v
            ℓ(v)   = ∫ f v
        ";
    }
}

/// Solves −Δu = f with u = g and returns the largest nodal error against `exact`.
fn largest_nodal_error<M: Model>(mesh: &TriangleMesh, f: &DataFn, exact: &DataFn) -> f64 {
    let coefficients = Coefficients::new::<M>(&[], &[("f", f), ("g", exact)]).unwrap();
    let dofs = SystemDofs::all::<M>(mesh).unwrap();
    let constraints = dirichlet_constraints::<M>(mesh, &dofs, &coefficients).unwrap();
    let k = MatrixAssembler::new::<M>("a", mesh, &dofs)
        .unwrap()
        .assemble::<M>(mesh, &coefficients)
        .unwrap();
    let l = assemble_vector::<M>("ℓ", mesh, &dofs, &coefficients).unwrap();
    let reduction = constraints.reduction(dofs.dof_count()).unwrap();
    let a = reduction.matrix(&k);
    let b = reduction.rhs(&k, &l);
    let pattern = a.symbolic().to_owned().unwrap();
    let x = Cholesky::analyse(&pattern)
        .unwrap()
        .factor(&a)
        .unwrap()
        .solve_refined(&a, &b, 1)
        .unwrap();
    let u = reduction.expand(&x);
    let nodes = dofs.map(0).unwrap().nodes(mesh);
    u.iter()
        .zip(&nodes)
        .map(|(value, x)| (value - exact(x)).abs())
        .fold(0.0, f64::max)
}

fn meshes() -> Vec<TriangleMesh> {
    let mut out: Vec<TriangleMesh> = [
        Diagonal::Right,
        Diagonal::Left,
        Diagonal::Alternating,
        Diagonal::Crossed,
    ]
    .into_iter()
    .map(|d| TriangleMesh::rectangle(-1.0, 2.0, 0.0, 1.5, 5, 4, d).unwrap())
    .collect();
    out.push(TriangleMesh::disk([0.3, -0.2], 1.3, 4).unwrap());
    out.push(TriangleMesh::l_shape(3).unwrap());
    // local refinement mixes edge orientations and shapes
    let (refined, _) = out[2].refine(&[0, 7, 8, 21]).unwrap();
    out.push(refined);
    out
}

#[test]
fn each_element_reproduces_polynomials_of_its_degree() {
    let linear = |x: &[f64]| 1.0 + 2.0 * x[0] - 0.5 * x[1];
    let quadratic = |x: &[f64]| x[0] * x[0] - 2.0 * x[0] * x[1] + 0.3 * x[1] * x[1] + x[1];
    // −Δ of the quadratic: −(2 + 0.6)
    let quadratic_f = |_: &[f64]| -2.6;
    let cubic = |x: &[f64]| x[0].powi(3) + 2.0 * x[0] * x[0] * x[1] - x[1].powi(3) + x[0] * x[1];
    // −Δ(x³ + 2x²y − y³ + xy) = −(6x + 4y − 6y) = −6x + 2y
    let cubic_f = |x: &[f64]| -6.0 * x[0] + 2.0 * x[1];
    for (k, mesh) in meshes().iter().enumerate() {
        let e1 = largest_nodal_error::<poisson_p1::Model>(mesh, &|_| 0.0, &linear);
        let e2 = largest_nodal_error::<poisson_p2::Model>(mesh, &quadratic_f, &quadratic);
        let e3 = largest_nodal_error::<poisson_p3::Model>(mesh, &cubic_f, &cubic);
        assert!(e1 < 1e-11, "mesh {k}: P1 error {e1}");
        assert!(e2 < 1e-11, "mesh {k}: P2 error {e2}");
        assert!(e3 < 1e-10, "mesh {k}: P3 error {e3}");
    }
}

/// The check can fail: P2 cannot reproduce the cubic on an irregular mesh (on the
/// uniform ones it is nodally exact, a superconvergence of the regular pattern).
#[test]
fn a_lower_degree_does_not_reproduce_a_cubic() {
    let cubic = |x: &[f64]| x[0].powi(3) + 2.0 * x[0] * x[0] * x[1] - x[1].powi(3) + x[0] * x[1];
    let cubic_f = |x: &[f64]| -6.0 * x[0] + 2.0 * x[1];
    let mesh = &meshes()[4];
    let e = largest_nodal_error::<poisson_p2::Model>(mesh, &cubic_f, &cubic);
    assert!(e > 1e-5, "P2 error on a cubic {e}");
}

/// `(col_ptr, row_idx, values)` of a compressed matrix.
fn parts(a: &fem_forms::SparseMatrix) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
    (
        a.symbolic().col_ptr().to_vec(),
        a.symbolic().row_idx().to_vec(),
        a.val().to_vec(),
    )
}

/// The memory-saving paths (issue 15) build the same matrices as the copying ones:
/// `MatrixAssembler::into_matrix` as `assemble`, `Reduction::into_matrix` (in place in
/// the full matrix's arrays) as `Reduction::matrix`, entry by entry.
fn in_place_equals_copies<M: Model>(mesh: &TriangleMesh) {
    let (f, g) = (|_: &[f64]| 1.0, |x: &[f64]| 1.0 + x[0] * x[1]);
    let coefficients = Coefficients::new::<M>(&[], &[("f", &f), ("g", &g)]).unwrap();
    let dofs = SystemDofs::all::<M>(mesh).unwrap();
    let constraints = dirichlet_constraints::<M>(mesh, &dofs, &coefficients).unwrap();
    let reduction = constraints.reduction(dofs.dof_count()).unwrap();
    let assembler = MatrixAssembler::new::<M>("a", mesh, &dofs).unwrap();
    let k = assembler.assemble::<M>(mesh, &coefficients).unwrap();
    let taken = assembler.into_matrix::<M>(mesh, &coefficients).unwrap();
    assert_eq!(parts(&taken), parts(&k), "{}: assembled matrices", M::NAME);
    let a = reduction.matrix(&k);
    assert!(a.nrows() < k.nrows(), "{}: nothing eliminated", M::NAME);
    let in_place = reduction.into_matrix(taken);
    assert_eq!(
        (in_place.nrows(), in_place.ncols()),
        (a.nrows(), a.ncols()),
        "{}",
        M::NAME
    );
    assert_eq!(parts(&in_place), parts(&a), "{}: free–free blocks", M::NAME);
}

#[test]
fn in_place_assembly_and_elimination_equal_the_copies() {
    for mesh in meshes() {
        in_place_equals_copies::<poisson_p1::Model>(&mesh);
        in_place_equals_copies::<poisson_p2::Model>(&mesh);
        in_place_equals_copies::<poisson_p3::Model>(&mesh);
    }
}
