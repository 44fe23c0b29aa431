//! The quadratic (six-node, isoparametric) map of a curved triangle, for domains with
//! curved boundaries (docs/mathematics.md §8).
//!
//! `x(ξ) = Σ_i x_i N_i(ξ)` with the P2 Lagrange shape functions of the reference triangle
//! `(0,0), (1,0), (0,1)` in barycentric coordinates `λ₀ = 1 − ξ − η, λ₁ = ξ, λ₂ = η`:
//! `N_i = λ_i(2λ_i − 1)` at vertex `i`, `N = 4λ_iλ_j` at the node of edge `(i, j)`. Unlike
//! [`crate::element::Affine`] the Jacobian `J(ξ)` varies over the cell, so integrals take
//! `|det J|` at every quadrature point and gradients `K(ξ)ᵀ∇̂` with `K = J(ξ)⁻¹`. With
//! the edge nodes at the edge midpoints the map is affine and equals `Affine`.

/// A six-node triangle: vertices 0, 1, 2 (counter-clockwise), then the nodes of the
/// edges 0–1, 1–2, 2–0 (local edge `k` joins vertices `k` and `k + 1`, as in
/// [`crate::mesh::TriangleMesh::cell_edges`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Isoparametric {
    nodes: [[f64; 2]; 6],
}

impl Isoparametric {
    /// The map with the given nodes (shapes: six points `[x, y]`).
    pub fn new(nodes: [[f64; 2]; 6]) -> Self {
        Self { nodes }
    }

    /// Its nodes.
    pub fn nodes(&self) -> &[[f64; 2]; 6] {
        &self.nodes
    }

    /// The shape functions `N_i(ξ)` and their reference gradients `∇̂N_i(ξ)`.
    fn shape(xi: [f64; 2]) -> ([f64; 6], [[f64; 2]; 6]) {
        let l = [1.0 - xi[0] - xi[1], xi[0], xi[1]];
        // ∂λ/∂ξ and ∂λ/∂η
        let dl = [[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]];
        let mut n = [0.0; 6];
        let mut g = [[0.0; 2]; 6];
        for i in 0..3 {
            n[i] = l[i] * (2.0 * l[i] - 1.0);
            g[i] = dl[i].map(|d| (4.0 * l[i] - 1.0) * d);
            let j = (i + 1) % 3;
            n[3 + i] = 4.0 * l[i] * l[j];
            g[3 + i] = [
                4.0 * (dl[i][0] * l[j] + l[i] * dl[j][0]),
                4.0 * (dl[i][1] * l[j] + l[i] * dl[j][1]),
            ];
        }
        (n, g)
    }

    /// The physical point of reference point `ξ`.
    pub fn point(&self, xi: [f64; 2]) -> [f64; 2] {
        let (n, _) = Self::shape(xi);
        let mut x = [0.0; 2];
        for (node, ni) in self.nodes.iter().zip(n) {
            x[0] += ni * node[0];
            x[1] += ni * node[1];
        }
        x
    }

    /// The Jacobian `J(ξ) = ∂x/∂ξ`, row `r` the gradient of `x_r`.
    pub fn jacobian(&self, xi: [f64; 2]) -> [[f64; 2]; 2] {
        let (_, g) = Self::shape(xi);
        let mut j = [[0.0; 2]; 2];
        for (node, gi) in self.nodes.iter().zip(g) {
            for r in 0..2 {
                for c in 0..2 {
                    j[r][c] += node[r] * gi[c];
                }
            }
        }
        j
    }

    /// `det J(ξ)`, signed: positive where the map keeps the orientation.
    pub fn det(&self, xi: [f64; 2]) -> f64 {
        let j = self.jacobian(xi);
        j[0][0] * j[1][1] - j[0][1] * j[1][0]
    }

    /// The physical gradient of a function with reference gradient `g` at `ξ`:
    /// `K(ξ)ᵀ g` with `K = J(ξ)⁻¹` (not finite where `det J(ξ) = 0`).
    pub fn gradient(&self, xi: [f64; 2], g: [f64; 2]) -> [f64; 2] {
        let j = self.jacobian(xi);
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        // Kᵀ = (J⁻¹)ᵀ = [[j11, −j10], [−j01, j00]] / det
        [
            (j[1][1] * g[0] - j[1][0] * g[1]) / det,
            (-j[0][1] * g[0] + j[0][0] * g[1]) / det,
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::element::Affine;

    fn straight(x: [[f64; 2]; 3]) -> Isoparametric {
        let mid = |a: [f64; 2], b: [f64; 2]| [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
        Isoparametric::new([
            x[0],
            x[1],
            x[2],
            mid(x[0], x[1]),
            mid(x[1], x[2]),
            mid(x[2], x[0]),
        ])
    }

    /// With the edge nodes at the midpoints the map is the affine one: points, det and
    /// gradients agree with `Affine` everywhere.
    #[test]
    fn straight_edges_give_the_affine_map() {
        let x = [[0.3, -0.2], [2.1, 0.4], [0.7, 1.9]];
        let iso = straight(x);
        let affine = Affine::triangle(&[x[0][0], x[0][1], x[1][0], x[1][1], x[2][0], x[2][1]]);
        for xi in [[0.0, 0.0], [0.2, 0.3], [0.5, 0.5], [0.1, 0.8]] {
            let (p, q) = (iso.point(xi), affine.point(xi));
            assert!((p[0] - q[0]).abs() < 1e-14 && (p[1] - q[1]).abs() < 1e-14);
            assert!((iso.det(xi) - affine.det).abs() < 1e-13);
            let (g, h) = (iso.gradient(xi, [0.7, -1.3]), affine.gradient([0.7, -1.3]));
            assert!((g[0] - h[0]).abs() < 1e-13 && (g[1] - h[1]).abs() < 1e-13);
        }
    }

    /// The map interpolates its nodes, and its Jacobian is the derivative of `point`
    /// (central differences).
    #[test]
    fn nodes_are_interpolated_and_the_jacobian_differentiates_the_map() {
        let nodes = [
            [0.0, 0.0],
            [1.0, 0.1],
            [0.1, 1.2],
            [0.55, -0.1],
            [0.7, 0.8],
            [-0.1, 0.6],
        ];
        let iso = Isoparametric::new(nodes);
        let reference = [
            [0.0, 0.0],
            [1.0, 0.0],
            [0.0, 1.0],
            [0.5, 0.0],
            [0.5, 0.5],
            [0.0, 0.5],
        ];
        for (xi, x) in reference.iter().zip(nodes) {
            let p = iso.point(*xi);
            assert!((p[0] - x[0]).abs() < 1e-15 && (p[1] - x[1]).abs() < 1e-15);
        }
        let xi = [0.23, 0.41];
        let j = iso.jacobian(xi);
        let step = 1e-6;
        for c in 0..2 {
            let (mut a, mut b) = (xi, xi);
            a[c] += step;
            b[c] -= step;
            let (pa, pb) = (iso.point(a), iso.point(b));
            for r in 0..2 {
                let fd = (pa[r] - pb[r]) / (2.0 * step);
                assert!(
                    (fd - j[r][c]).abs() < 1e-8,
                    "J[{r}][{c}] = {} vs {fd}",
                    j[r][c]
                );
            }
        }
    }
}
