//! Gauss–Legendre quadrature on the reference interval `[0, 1]`.

/// A quadrature rule on the reference interval `[0, 1]`: `∫₀¹ g ≈ Σ w_q g(ξ_q)`.
#[derive(Clone, Debug, PartialEq)]
pub struct QuadratureRule {
    /// Points `ξ_q` in `[0, 1]`, increasing.
    pub points: Vec<f64>,
    /// Weights `w_q`, summing to 1.
    pub weights: Vec<f64>,
}

impl QuadratureRule {
    /// The Gauss–Legendre rule that integrates polynomials of degree `degree` exactly.
    pub fn exact_for_degree(degree: usize) -> Self {
        gauss_legendre(points_for_degree(degree))
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// True for the empty rule (never produced by the constructors here).
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// `Σ w_q g(ξ_q)`.
    pub fn integrate(&self, g: impl Fn(f64) -> f64) -> f64 {
        self.points
            .iter()
            .zip(&self.weights)
            .map(|(&x, &w)| w * g(x))
            .sum()
    }
}

/// Number of Gauss–Legendre points exact for polynomials of degree `degree` (`2n − 1 ≥ degree`).
pub fn points_for_degree(degree: usize) -> usize {
    degree / 2 + 1
}

/// The `n`-point Gauss–Legendre rule mapped to `[0, 1]` (`n ≥ 1`).
///
/// Nodes are the roots of the Legendre polynomial `P_n`, found by Newton's method from
/// Tricomi's initial guesses; the recurrence is stable, so nodes and weights are accurate
/// to a few ulps for the moderate `n` used by element kernels.
///
/// # Panics
/// For `n = 0` (no rule has no points; [`points_for_degree`] never gives 0).
pub fn gauss_legendre(n: usize) -> QuadratureRule {
    assert!(n >= 1, "a Gauss–Legendre rule needs at least one point");
    let mut points = vec![0.0; n];
    let mut weights = vec![0.0; n];
    let nf = n as f64;
    for i in 0..n.div_ceil(2) {
        // Root i of P_n on [-1, 1], counted from the right end.
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (nf + 0.5)).cos();
        let mut dp = 0.0;
        for _ in 0..100 {
            let (p, d) = legendre_and_derivative(n, x);
            dp = d;
            let dx = p / d;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        let (_, d) = legendre_and_derivative(n, x);
        if d != 0.0 {
            dp = d;
        }
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        // Map [-1, 1] → [0, 1]; the weights halve.
        points[n - 1 - i] = 0.5 * (1.0 + x);
        points[i] = 0.5 * (1.0 - x);
        weights[n - 1 - i] = 0.5 * w;
        weights[i] = 0.5 * w;
    }
    QuadratureRule { points, weights }
}

fn legendre_and_derivative(n: usize, x: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, x);
    for k in 2..=n {
        let kf = k as f64;
        let p2 = ((2.0 * kf - 1.0) * x * p1 - (kf - 1.0) * p0) / kf;
        p0 = p1;
        p1 = p2;
    }
    let (pn, pn1) = if n == 0 { (1.0, 0.0) } else { (p1, p0) };
    let d = n as f64 * (x * pn - pn1) / (x * x - 1.0);
    (pn, d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integrates_monomials_exactly_up_to_its_degree() {
        for n in 1..=12 {
            let rule = gauss_legendre(n);
            assert!((rule.weights.iter().sum::<f64>() - 1.0).abs() < 1e-14);
            for k in 0..=(2 * n - 1) {
                let exact = 1.0 / (k as f64 + 1.0);
                let approx = rule.integrate(|x| x.powi(k as i32));
                assert!(
                    (approx - exact).abs() < 1e-14,
                    "n = {n}, x^{k}: {approx} vs {exact}"
                );
            }
            // and not exact one degree higher: the rule is no stronger than claimed (the
            // error (n!)⁴/((2n+1)((2n)!)³) drops below rounding for n > 4)
            if n <= 4 {
                let k = 2 * n;
                let exact = 1.0 / (k as f64 + 1.0);
                assert!((rule.integrate(|x| x.powi(k as i32)) - exact).abs() > 1e-12);
            }
        }
    }

    #[test]
    fn points_are_increasing_and_inside() {
        for n in 1..=12 {
            let rule = gauss_legendre(n);
            assert!(rule.points.windows(2).all(|w| w[0] < w[1]));
            assert!(rule.points.iter().all(|&x| x > 0.0 && x < 1.0));
        }
    }

    #[test]
    fn degree_to_points() {
        for degree in 0..20 {
            let n = points_for_degree(degree);
            // 2n − 1 ≥ degree, and n − 1 points would not do
            assert!(2 * n > degree && (n == 1 || 2 * (n - 1) - 1 < degree));
        }
    }
}
