//! The reference triangle `(0,0), (1,0), (0,1)`: quadrature rules exact to any degree and
//! Lagrange bases. The form compiler tabulates and integrates these at compile time for
//! models `on triangle`.

use crate::quadrature::gauss_legendre;

/// A quadrature rule on the reference triangle: `∫_T̂ g ≈ Σ w_q g(x_q, y_q)`.
#[derive(Clone, Debug, PartialEq)]
pub struct TriangleRule {
    /// Points `(x, y)` inside the triangle.
    pub points: Vec<[f64; 2]>,
    /// Weights, summing to the area ½.
    pub weights: Vec<f64>,
}

impl TriangleRule {
    /// A collapsed (Duffy) tensor Gauss rule exact for polynomials of total degree
    /// `degree`: `x = u`, `y = v(1 − u)`, Jacobian `1 − u`, so `n ≥ (degree + 2)/2`
    /// Gauss–Legendre points per direction integrate it exactly. Not the fewest points,
    /// but exact to any degree with nothing tabulated.
    pub fn exact_for_degree(degree: usize) -> Self {
        let n = (degree + 2).div_ceil(2).max(1);
        let rule = gauss_legendre(n);
        let mut points = Vec::with_capacity(n * n);
        let mut weights = Vec::with_capacity(n * n);
        for (&u, &wu) in rule.points.iter().zip(&rule.weights) {
            for (&v, &wv) in rule.points.iter().zip(&rule.weights) {
                points.push([u, v * (1.0 - u)]);
                weights.push(wu * wv * (1.0 - u));
            }
        }
        Self { points, weights }
    }

    /// `Σ w_q g(x_q)`.
    pub fn integrate(&self, g: impl Fn([f64; 2]) -> f64) -> f64 {
        self.points
            .iter()
            .zip(&self.weights)
            .map(|(&p, &w)| w * g(p))
            .sum()
    }
}

/// A polynomial in two variables, `Σ c_ij x^i y^j` over `i + j ≤ degree`.
#[derive(Clone, Debug, PartialEq)]
pub struct Polynomial2 {
    /// `(i, j, c_ij)`.
    pub terms: Vec<(u32, u32, f64)>,
}

impl Polynomial2 {
    /// Value at `(x, y)`.
    pub fn eval(&self, [x, y]: [f64; 2]) -> f64 {
        self.terms
            .iter()
            .map(|&(i, j, c)| c * x.powi(i as i32) * y.powi(j as i32))
            .sum()
    }

    /// `∂^(a+b) / ∂x^a ∂y^b`.
    pub fn derivative(&self, a: u32, b: u32) -> Self {
        let falling = |n: u32, k: u32| -> f64 { (0..k).map(|m| (n - m) as f64).product() };
        Self {
            terms: self
                .terms
                .iter()
                .filter(|&&(i, j, _)| i >= a && j >= b)
                .map(|&(i, j, c)| (i - a, j - b, c * falling(i, a) * falling(j, b)))
                .collect(),
        }
    }
}

/// Lagrange nodes of degree `k` on the reference triangle: vertices, then edge nodes
/// (edges 0–1, 1–2, 2–0, from the first vertex), then interior nodes. `k = 0`: centroid.
pub fn lagrange_nodes(k: usize) -> Vec<[f64; 2]> {
    if k == 0 {
        return vec![[1.0 / 3.0, 1.0 / 3.0]];
    }
    let vertices = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
    let mut nodes = vertices.to_vec();
    let kf = k as f64;
    for e in 0..3 {
        let (a, b) = (vertices[e], vertices[(e + 1) % 3]);
        for m in 1..k {
            let t = m as f64 / kf;
            nodes.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
        }
    }
    for j in 1..k {
        for i in 1..k - j {
            nodes.push([i as f64 / kf, j as f64 / kf]);
        }
    }
    nodes
}

/// The Lagrange basis of degree `k` (0–3) on the reference triangle, dual to
/// [`lagrange_nodes`]: the inverse of the Vandermonde matrix of the monomials at the nodes.
pub fn lagrange_basis(k: usize) -> Vec<Polynomial2> {
    let nodes = lagrange_nodes(k);
    let monomials: Vec<(u32, u32)> = (0..=k as u32)
        .flat_map(|total| (0..=total).map(move |j| (total - j, j)))
        .collect();
    let n = monomials.len();
    assert_eq!(n, nodes.len(), "nodes and monomials of degree {k}");
    // V[r][c] = monomial c at node r; the basis coefficients are the columns of V⁻¹.
    let mut v: Vec<Vec<f64>> = nodes
        .iter()
        .map(|&[x, y]| {
            monomials
                .iter()
                .map(|&(i, j)| x.powi(i as i32) * y.powi(j as i32))
                .collect()
        })
        .collect();
    let mut inverse: Vec<Vec<f64>> = (0..n)
        .map(|r| (0..n).map(|c| f64::from(u8::from(r == c))).collect())
        .collect();
    // Gauss–Jordan with partial pivoting (n ≤ 10)
    for col in 0..n {
        let pivot = (col..n)
            .max_by(|&a, &b| v[a][col].abs().total_cmp(&v[b][col].abs()))
            .expect("a pivot row");
        v.swap(col, pivot);
        inverse.swap(col, pivot);
        let p = v[col][col];
        for c in 0..n {
            v[col][c] /= p;
            inverse[col][c] /= p;
        }
        for r in 0..n {
            if r != col {
                let f = v[r][col];
                if f != 0.0 {
                    for c in 0..n {
                        v[r][c] -= f * v[col][c];
                        inverse[r][c] -= f * inverse[col][c];
                    }
                }
            }
        }
    }
    (0..n)
        .map(|basis| Polynomial2 {
            terms: monomials
                .iter()
                .enumerate()
                .map(|(m, &(i, j))| (i, j, inverse[m][basis]))
                .filter(|t| t.2.abs() > 1e-13)
                .collect(),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `∫_T̂ x^a y^b = a! b! / (a + b + 2)!`
    fn exact_monomial(a: u32, b: u32) -> f64 {
        let factorial = |n: u32| (1..=n).map(f64::from).product::<f64>();
        factorial(a) * factorial(b) / factorial(a + b + 2)
    }

    #[test]
    fn rules_integrate_every_monomial_up_to_their_degree() {
        for degree in 0..=14 {
            let rule = TriangleRule::exact_for_degree(degree);
            assert!((rule.weights.iter().sum::<f64>() - 0.5).abs() < 1e-15);
            assert!(rule
                .points
                .iter()
                .all(|&[x, y]| x > 0.0 && y > 0.0 && x + y < 1.0));
            for total in 0..=degree as u32 {
                for b in 0..=total {
                    let a = total - b;
                    let approx = rule.integrate(|[x, y]| x.powi(a as i32) * y.powi(b as i32));
                    let exact = exact_monomial(a, b);
                    assert!(
                        (approx - exact).abs() < 1e-15,
                        "degree {degree}: x^{a} y^{b}: {approx} vs {exact}"
                    );
                }
            }
        }
        // the degree-10 rule is not exact at degree 12: it claims no more than it has
        let rule = TriangleRule::exact_for_degree(10);
        assert!((rule.integrate(|[x, _]| x.powi(12)) - exact_monomial(12, 0)).abs() > 1e-14);
    }

    #[test]
    fn lagrange_bases_are_dual_to_their_nodes() {
        for k in 0..=3 {
            let nodes = lagrange_nodes(k);
            let basis = lagrange_basis(k);
            assert_eq!(basis.len(), (k + 1) * (k + 2) / 2);
            for (i, phi) in basis.iter().enumerate() {
                for (j, &node) in nodes.iter().enumerate() {
                    let expected = if i == j { 1.0 } else { 0.0 };
                    assert!(
                        (phi.eval(node) - expected).abs() < 1e-12,
                        "P{k}: φ_{i}(node {j})"
                    );
                }
            }
            // partition of unity and a consistent gradient
            let p = [0.21, 0.37];
            let sum: f64 = basis.iter().map(|b| b.eval(p)).sum();
            assert!((sum - 1.0).abs() < 1e-12);
            for b in &basis {
                let h = 1e-6;
                let fd = (b.eval([p[0] + h, p[1]]) - b.eval([p[0] - h, p[1]])) / (2.0 * h);
                assert!((fd - b.derivative(1, 0).eval(p)).abs() < 1e-7);
            }
        }
    }
}
