//! The map from the reference cell to a physical cell, and the chain rule it gives for
//! derivatives: points, gradients and Hessians on physical cells from reference ones.
//! Triangle fields, DOF nodes, the interval basis and the interval norms go through it;
//! the generated kernels inline the same formulas, the interval prolongation places its
//! nodes through it, and point location inverts the map
//! through barycentric coordinates of its own.
//!
//! Reference cells: the interval `[0, 1]` and the triangle with vertices `(0,0), (1,0),
//! (0,1)`. For an affine cell `x = x₀ + J ξ`, with `K = J⁻¹`:
//! `∇φ = Kᵀ ∇̂φ̂` and `∇∇φ = Kᵀ (∇̂∇̂φ̂) K` (second derivatives of an affine map vanish).

use crate::mesh::TriangleMesh;

/// The affine map `x = x₀ + J ξ` of a cell of dimension `D` (1: an interval, 2: a
/// triangle), with `K = J⁻¹` kept for the chain rule.
///
/// The cell must not be degenerate (`det J ≠ 0`; mesh constructors refuse such cells):
/// for a degenerate one `K` is not finite, and so are gradients and Hessians.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Affine<const D: usize> {
    origin: [f64; D],
    j: [[f64; D]; D],
    k: [[f64; D]; D],
    /// `|det J|`: the cell's length, or twice its area.
    pub det: f64,
}

impl Affine<1> {
    /// The map of the interval cell `[x₀, x₁]`: `x = x₀ + (x₁ − x₀) ξ`.
    pub fn interval(cell: [f64; 2]) -> Self {
        let h = cell[1] - cell[0];
        Self {
            origin: [cell[0]],
            j: [[h]],
            k: [[1.0 / h]],
            det: h.abs(),
        }
    }
}

impl Affine<2> {
    /// The map of the triangle with vertex coordinates `x₀ y₀ x₁ y₁ x₂ y₂` (the layout of
    /// [`TriangleMesh::cell_coordinates`] and of the kernels' argument).
    pub fn triangle(x: &[f64; 6]) -> Self {
        let j = [[x[2] - x[0], x[4] - x[0]], [x[3] - x[1], x[5] - x[1]]];
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        let k = [
            [j[1][1] / det, -j[0][1] / det],
            [-j[1][0] / det, j[0][0] / det],
        ];
        Self {
            origin: [x[0], x[1]],
            j,
            k,
            det: det.abs(),
        }
    }

    /// The map of cell `c` of `mesh`.
    pub fn of(mesh: &TriangleMesh, c: usize) -> Self {
        Self::triangle(&mesh.cell_coordinates(c))
    }
}

impl<const D: usize> Affine<D> {
    /// The physical point of reference point `ξ`: `x₀ + J ξ`.
    pub fn point(&self, xi: [f64; D]) -> [f64; D] {
        std::array::from_fn(|r| self.origin[r] + (0..D).map(|c| self.j[r][c] * xi[c]).sum::<f64>())
    }

    /// The reference point of physical point `x`: `K (x − x₀)`.
    pub fn reference_point(&self, x: [f64; D]) -> [f64; D] {
        std::array::from_fn(|r| (0..D).map(|c| self.k[r][c] * (x[c] - self.origin[c])).sum())
    }

    /// The physical gradient of a function from its reference gradient: `Kᵀ ∇̂φ̂`.
    pub fn gradient(&self, g: [f64; D]) -> [f64; D] {
        std::array::from_fn(|r| (0..D).map(|c| self.k[c][r] * g[c]).sum())
    }

    /// The physical Hessian of a function from its reference Hessian: `Kᵀ Ĥ K`.
    pub fn hessian(&self, h: [[f64; D]; D]) -> [[f64; D]; D] {
        let hk: [[f64; D]; D] = std::array::from_fn(|r| {
            std::array::from_fn(|c| (0..D).map(|m| h[r][m] * self.k[m][c]).sum())
        });
        std::array::from_fn(|r| {
            std::array::from_fn(|c| (0..D).map(|m| self.k[m][r] * hk[m][c]).sum())
        })
    }

    /// The Jacobian `J` (`J[r][c] = ∂x_r/∂ξ_c`).
    pub fn jacobian(&self) -> [[f64; D]; D] {
        self.j
    }

    /// The inverse Jacobian `K = J⁻¹`.
    pub fn inverse_jacobian(&self) -> [[f64; D]; D] {
        self.k
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `φ(x, y) = x² + 3xy − y²` pulled back to the reference triangle of a skewed cell:
    /// its physical gradient and Hessian come back through the chain rule.
    #[test]
    fn chain_rule_recovers_physical_derivatives() {
        let x = [0.3, -0.2, 1.4, 0.1, 0.5, 0.9];
        let map = Affine::triangle(&x);
        let phi_grad = |p: [f64; 2]| [2.0 * p[0] + 3.0 * p[1], 3.0 * p[0] - 2.0 * p[1]];
        let phi_hess = [[2.0, 3.0], [3.0, -2.0]];
        let xi = [0.2, 0.3];
        let p = map.point(xi);
        let j = map.jacobian();
        // reference derivatives of φ̂(ξ) = φ(x₀ + Jξ): ∇̂φ̂ = Jᵀ∇φ, ∇̂∇̂φ̂ = Jᵀ H J
        let g = phi_grad(p);
        let ref_grad = [
            j[0][0] * g[0] + j[1][0] * g[1],
            j[0][1] * g[0] + j[1][1] * g[1],
        ];
        let ref_hess: [[f64; 2]; 2] = std::array::from_fn(|r| {
            std::array::from_fn(|c| {
                (0..2)
                    .map(|a| {
                        (0..2)
                            .map(|b| j[a][r] * phi_hess[a][b] * j[b][c])
                            .sum::<f64>()
                    })
                    .sum()
            })
        });
        let back = map.gradient(ref_grad);
        let back_hess = map.hessian(ref_hess);
        for r in 0..2 {
            assert!((back[r] - g[r]).abs() < 1e-12, "{back:?} {g:?}");
            for c in 0..2 {
                assert!(
                    (back_hess[r][c] - phi_hess[r][c]).abs() < 1e-12,
                    "{back_hess:?}"
                );
            }
        }
        let area = 0.5 * ((x[2] - x[0]) * (x[5] - x[1]) - (x[4] - x[0]) * (x[3] - x[1])).abs();
        assert!((map.det - 2.0 * area).abs() < 1e-14);
        let back_xi = map.reference_point(p);
        assert!((back_xi[0] - xi[0]).abs() < 1e-14 && (back_xi[1] - xi[1]).abs() < 1e-14);
        let vertex = map.point([1.0, 0.0]);
        assert!((vertex[0] - x[2]).abs() < 1e-15 && (vertex[1] - x[3]).abs() < 1e-15);
    }

    #[test]
    fn interval_map_scales_derivatives_by_the_length() {
        let map = Affine::interval([2.0, 2.5]);
        assert_eq!(map.point([0.5]), [2.25]);
        assert_eq!(map.reference_point([2.25]), [0.5]);
        assert_eq!(map.gradient([1.0]), [2.0]);
        assert_eq!(map.hessian([[1.0]]), [[4.0]]);
        assert_eq!(map.det, 0.5);
    }
}
