//! Elements on physical cells: basis values and derivatives at a point of a cell.

use crate::element::mapping::Affine;
use fem_reference::{ElementKind, Polynomial};

/// The basis of an element with its derivatives, ready to evaluate on physical cells.
#[derive(Clone, Debug)]
pub struct PhysicalBasis {
    element: ElementKind,
    /// `derivatives[k][i]`: the k-th reference derivative of basis function i.
    derivatives: Vec<Vec<Polynomial>>,
}

impl PhysicalBasis {
    /// Derivatives up to order `max_derivative` of the element's basis.
    pub fn new(element: ElementKind, max_derivative: usize) -> Self {
        let basis = element.basis();
        let derivatives = (0..=max_derivative)
            .map(|k| basis.iter().map(|p| p.derivative(k)).collect())
            .collect();
        Self {
            element,
            derivatives,
        }
    }

    /// The element.
    pub fn element(&self) -> ElementKind {
        self.element
    }

    /// `d^k/dx^k` of the physical basis function `i` of cell `[x0, x1]` at reference
    /// point `ξ` (x = x0 + h ξ): `h^{sᵢ} Kᵏ φ̂ᵢ⁽ᵏ⁾(ξ)` with `K = 1/h` the map's inverse
    /// Jacobian ([`Affine`]) and `h^{sᵢ}` the DOF transformation of an element that is not
    /// affine-equivalent (`sᵢ = 1` for Hermite slopes, 0 for point values).
    pub fn value(&self, i: usize, derivative: usize, cell: [f64; 2], xi: f64) -> f64 {
        let map = Affine::interval(cell);
        let dof_transformation = map.jacobian()[0][0].powi(self.element.dof_scaling_power(i));
        let chain = map.inverse_jacobian()[0][0].powi(derivative as i32);
        self.derivatives[derivative][i].eval(xi) * chain * dof_transformation
    }

    /// `d^k/dx^k` of `Σ cᵢ φᵢ` on a cell at reference point `ξ`.
    pub fn evaluate(
        &self,
        coefficients: &[f64],
        derivative: usize,
        cell: [f64; 2],
        xi: f64,
    ) -> f64 {
        coefficients
            .iter()
            .enumerate()
            .map(|(i, &c)| c * self.value(i, derivative, cell, xi))
            .sum()
    }
}
