//! A manufactured smooth solution of the clamped Kirchhoff plate (issue 13): on the unit
//! square `w = (x(1−x) y(1−y))²` vanishes with its gradient on the boundary, so it is
//! the clamped plate's deflection under `f = DΔ²w`. Solved on Argyris and Morley through
//! the runtime's linear path, with the errors measured by quadrature against the closed
//! form (not against the code's own numbers): Argyris (P5, C¹) converges at its optimal
//! O(h⁴) in the H² seminorm, O(h⁵) in H¹ and O(h⁶) in L²; Morley (P2, non-conforming) at
//! O(h) in the broken H² seminorm and O(h²) in H¹ and L².
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

#[path = "common/clamped_plate.rs"]
mod clamped_plate;

use fem_forms::models::kirchhoff::{kirchhoff_argyris, kirchhoff_morley};
use fem_forms::{
    solve_linear, Coefficients, Constraints, DataFn, Diagonal, DirichletPart, Factorization, Model,
    PlateSupport, SystemDofs, TriangleMesh,
};
use fem_runtime::element::triangle::{AffineMap, TriangleBasis, TriangleField};
use fem_runtime::reference::triangle::TriangleRule;

use clamped_plate::{load, D};

const NU: f64 = 0.3;

/// The exact deflection, its gradient and its Hessian `[w_xx, w_xy, w_yy]`.
fn exact(x: [f64; 2]) -> (f64, [f64; 2], [f64; 3]) {
    let h = clamped_plate::hessian(&x);
    (
        clamped_plate::w(&x),
        clamped_plate::gradient(&x),
        [h[0][0], h[0][1], h[1][1]],
    )
}

/// `(‖w − w_h‖_L², |w − w_h|_H¹, |w − w_h|_H²,h)` of the clamped plate on the N×N×2 mesh
/// (the H² seminorm cell by cell: the broken one for Morley).
fn errors<M: Model>(n: usize) -> [f64; 3] {
    let mesh = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, n, n, Diagonal::Right).unwrap();
    let dofs = SystemDofs::new::<M>(&mesh, &[0]).unwrap();
    let f: &DataFn = &load;
    let coefficients = Coefficients::new::<M>(&[("D", D), ("ν", NU)], &[("f", f)]).unwrap();
    let mut constraints = Constraints::new();
    constraints
        .support_plate::<M>(
            &mesh,
            &dofs,
            "w",
            &DirichletPart::All,
            PlateSupport::Clamped,
        )
        .unwrap();
    let w = solve_linear::<M>(
        &mesh,
        &dofs,
        "a",
        "ℓ",
        &constraints,
        &coefficients,
        Factorization::Cholesky,
    )
    .unwrap();
    let map = dofs.map(0).unwrap();
    let field = TriangleField {
        mesh: &mesh,
        map,
        coefficients: &w,
    };
    let basis = TriangleBasis::new(map.element());
    // the error of a degree-8 w against P5 squared: a rule of degree 16 integrates it exactly
    let rule = TriangleRule::exact_for_degree(16);
    let mut sums = [0.0; 3];
    for c in 0..mesh.cell_count() {
        let affine = AffineMap::of(&mesh, c);
        for (&xi, &weight) in rule.points.iter().zip(&rule.weights) {
            let (u, g, h) = exact(affine.point(xi));
            let value = field.value(&basis, c, xi);
            let gradient = field.gradient(&basis, &affine, c, xi);
            let hessian = field.hessian(&basis, &affine, c, xi);
            let dx = weight * affine.det.abs();
            sums[0] += dx * (u - value).powi(2);
            sums[1] += dx * ((g[0] - gradient[0]).powi(2) + (g[1] - gradient[1]).powi(2));
            sums[2] += dx
                * ((h[0] - hessian[0][0]).powi(2)
                    + 2.0 * (h[1] - hessian[0][1]).powi(2)
                    + (h[2] - hessian[1][1]).powi(2));
        }
    }
    sums.map(f64::sqrt)
}

/// Observed rates `log2(e_{N}/e_{2N})` of each norm over `sizes` (each twice the last).
fn rates<M: Model>(name: &str, sizes: &[usize]) -> Vec<[f64; 3]> {
    let errors: Vec<[f64; 3]> = sizes.iter().map(|&n| errors::<M>(n)).collect();
    eprintln!("{name}: (L², H¹, H²) errors at N = {sizes:?}: {errors:?}");
    let rates: Vec<[f64; 3]> = errors
        .windows(2)
        .map(|e| std::array::from_fn(|k| (e[0][k] / e[1][k]).log2()))
        .collect();
    eprintln!("{name}: rates {rates:?}");
    rates
}

#[test]
fn argyris_converges_at_its_optimal_rates() {
    let rates = rates::<kirchhoff_argyris::Model>("Argyris", &[2, 4, 8, 16]);
    let last = rates.last().unwrap();
    let expected = [6.0, 5.0, 4.0];
    for k in 0..3 {
        assert!(
            last[k] >= expected[k] - 0.25,
            "norm {k}: rate {} against {} ({rates:?})",
            last[k],
            expected[k]
        );
    }
}

#[test]
fn morley_converges_at_its_rates_in_the_broken_norm() {
    let rates = rates::<kirchhoff_morley::Model>("Morley", &[8, 16, 32, 64]);
    let last = rates.last().unwrap();
    let expected = [2.0, 2.0, 1.0];
    for k in 0..3 {
        assert!(
            last[k] >= expected[k] - 0.15,
            "norm {k}: rate {} against {} ({rates:?})",
            last[k],
            expected[k]
        );
    }
}
