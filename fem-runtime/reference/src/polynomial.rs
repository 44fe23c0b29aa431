//! Univariate polynomials in the monomial basis, enough to represent and
//! differentiate one-dimensional reference basis functions exactly.

/// A polynomial `Σ c_k ξ^k` stored by its coefficients, lowest degree first.
#[derive(Clone, Debug, PartialEq)]
pub struct Polynomial {
    /// Coefficients `c_0, c_1, …`.
    pub coefficients: Vec<f64>,
}

impl Polynomial {
    /// The polynomial with the given coefficients (lowest degree first).
    pub fn new(coefficients: Vec<f64>) -> Self {
        Self { coefficients }
    }

    /// The constant polynomial `c`.
    pub fn constant(c: f64) -> Self {
        Self::new(vec![c])
    }

    /// The product of the linear factors `Π (ξ − r)` scaled by `scale`.
    pub fn from_roots(roots: &[f64], scale: f64) -> Self {
        let mut p = Self::constant(scale);
        for &r in roots {
            p = p.mul_linear(-r);
        }
        p
    }

    fn mul_linear(&self, c0: f64) -> Self {
        // (Σ a_k ξ^k)(ξ + c0)
        let mut out = vec![0.0; self.coefficients.len() + 1];
        for (k, &a) in self.coefficients.iter().enumerate() {
            out[k + 1] += a;
            out[k] += a * c0;
        }
        Self::new(out)
    }

    /// Value at `x` (Horner's scheme).
    pub fn eval(&self, x: f64) -> f64 {
        self.coefficients
            .iter()
            .rev()
            .fold(0.0, |acc, &c| acc * x + c)
    }

    /// The derivative of order `order`.
    pub fn derivative(&self, order: usize) -> Self {
        let mut c = self.coefficients.clone();
        for _ in 0..order {
            if c.len() <= 1 {
                return Self::constant(0.0);
            }
            c = c
                .iter()
                .enumerate()
                .skip(1)
                .map(|(k, &a)| a * k as f64)
                .collect();
        }
        Self::new(c)
    }

    /// True when every coefficient is exactly zero.
    pub fn is_zero(&self) -> bool {
        self.coefficients.iter().all(|&c| c == 0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roots_and_derivatives() {
        // (ξ − 1)(ξ − 2) = ξ² − 3ξ + 2
        let p = Polynomial::from_roots(&[1.0, 2.0], 1.0);
        assert_eq!(p.coefficients, vec![2.0, -3.0, 1.0]);
        assert_eq!(p.eval(3.0), 2.0);
        assert_eq!(p.derivative(1).coefficients, vec![-3.0, 2.0]);
        assert_eq!(p.derivative(2).coefficients, vec![2.0]);
        assert!(p.derivative(3).is_zero());
    }
}
