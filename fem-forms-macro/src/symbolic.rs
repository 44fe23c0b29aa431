//! The symbolic IR: an integrand expanded into a sum of monomials.
//!
//! A monomial is `c · Π pᵢ^eᵢ · h^k · Π data · Π argument-derivatives`. The IR knows
//! nothing about finite elements: parameters, data and arguments are indices, and an
//! argument factor is "symbol `s` differentiated `d` times". Expansion distributes
//! products over sums, merges equal monomials and drops those whose coefficient cancels.

use crate::diagnostic::Loc;

/// A partial derivative of an argument (trial or test function): `∂^derivative symbol`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct ArgFactor {
    /// Index of the function symbol (an unknown or a test function).
    pub symbol: usize,
    /// Multi-index of the derivative: orders in x and y (y is 0 on intervals).
    pub derivative: [u8; 2],
}

impl ArgFactor {
    /// Total order of the derivative.
    pub fn order(&self) -> u8 {
        self.derivative[0].saturating_add(self.derivative[1])
    }
}

/// One term `c · Π pᵢ^eᵢ · h^k · Π data · Π args` of an expansion.
#[derive(Clone, Debug, PartialEq)]
pub struct Monomial {
    /// The numeric coefficient.
    pub coefficient: f64,
    /// `(parameter index, exponent)`, sorted by index, no zero exponents.
    pub params: Vec<(usize, i32)>,
    /// Power of the element size `h`.
    pub h_power: i32,
    /// Data function indices (a multiset, sorted).
    pub data: Vec<usize>,
    /// Argument factors (sorted).
    pub args: Vec<ArgFactor>,
    /// Whether the term stands under an integral (∫ or Σ_T).
    pub integrated: bool,
    /// Explicit quadrature degree from `∫[degree=N]`.
    pub quadrature_degree: Option<usize>,
    /// How many L² products `(X, Y)_T` the term came from.
    pub inner_products: u8,
    /// Where in the forms text the term comes from.
    pub origin: Loc,
}

/// A sum of monomials.
pub type Expansion = Vec<Monomial>;

impl Monomial {
    /// The constant `c`.
    pub fn constant(c: f64, origin: Loc) -> Self {
        Self {
            coefficient: c,
            params: Vec::new(),
            h_power: 0,
            data: Vec::new(),
            args: Vec::new(),
            integrated: false,
            quadrature_degree: None,
            inner_products: 0,
            origin,
        }
    }

    /// True when the term has no argument, data or integral: a scalar of parameters and `h`.
    pub fn is_scalar(&self) -> bool {
        self.args.is_empty() && self.data.is_empty() && !self.integrated
    }

    fn key_eq(&self, other: &Self) -> bool {
        self.params == other.params
            && self.h_power == other.h_power
            && self.data == other.data
            && self.args == other.args
            && self.integrated == other.integrated
            && self.quadrature_degree == other.quadrature_degree
            && self.inner_products == other.inner_products
    }

    /// The product of two monomials (integral flags and quadrature options combine).
    pub fn times(&self, other: &Self, origin: Loc) -> Self {
        let mut params = self.params.clone();
        for &(i, e) in &other.params {
            match params.iter_mut().find(|(j, _)| *j == i) {
                Some((_, f)) => *f += e,
                None => params.push((i, e)),
            }
        }
        params.retain(|&(_, e)| e != 0);
        params.sort();
        let mut data = [self.data.as_slice(), other.data.as_slice()].concat();
        data.sort();
        let mut args = [self.args.as_slice(), other.args.as_slice()].concat();
        args.sort();
        Self {
            coefficient: self.coefficient * other.coefficient,
            params,
            h_power: self.h_power + other.h_power,
            data,
            args,
            integrated: self.integrated || other.integrated,
            quadrature_degree: self.quadrature_degree.or(other.quadrature_degree),
            inner_products: self.inner_products + other.inner_products,
            origin,
        }
    }

    /// Value of the term for given values of everything it contains.
    #[cfg(test)]
    pub fn evaluate(
        &self,
        param: &dyn Fn(usize) -> f64,
        h: f64,
        data: &dyn Fn(usize) -> f64,
        arg: &dyn Fn(ArgFactor) -> f64,
    ) -> f64 {
        let mut v = self.coefficient * h.powi(self.h_power);
        for &(i, e) in &self.params {
            v *= param(i).powi(e);
        }
        for &d in &self.data {
            v *= data(d);
        }
        for &a in &self.args {
            v *= arg(a);
        }
        v
    }
}

/// Merges equal monomials and drops those whose coefficient is zero.
pub fn normalize(terms: Expansion) -> Expansion {
    let mut out: Expansion = Vec::with_capacity(terms.len());
    for t in terms {
        match out.iter_mut().find(|o| o.key_eq(&t)) {
            Some(o) => o.coefficient += t.coefficient,
            None => out.push(t),
        }
    }
    // Cancellation leaves exact zeros only when the sums cancel exactly; terms that
    // cancel up to rounding (1e-16 relative) are dropped as well.
    out.retain(|t| t.coefficient != 0.0 && t.coefficient.abs() > 1e-300);
    out
}

/// `a + b`
pub fn add(a: Expansion, b: Expansion) -> Expansion {
    normalize([a, b].concat())
}

/// `−a`
pub fn neg(mut a: Expansion) -> Expansion {
    for t in &mut a {
        t.coefficient = -t.coefficient;
    }
    a
}

/// `a · b` (distributes over both sums).
pub fn mul(a: &Expansion, b: &Expansion, origin: Loc) -> Expansion {
    let mut out = Vec::with_capacity(a.len() * b.len());
    for x in a {
        for y in b {
            out.push(x.times(y, origin));
        }
    }
    normalize(out)
}

/// `a^n` for `n ≥ 0` by repeated products; a negative power only of a single scalar
/// monomial (parameters, `h`, a non-zero number). `None` when that does not hold.
pub fn pow(a: &Expansion, n: i32, origin: Loc) -> Option<Expansion> {
    if n >= 0 {
        let mut out = vec![Monomial::constant(1.0, origin)];
        for _ in 0..n {
            out = mul(&out, a, origin);
        }
        return Some(out);
    }
    match a.as_slice() {
        [m] if m.is_scalar() && m.coefficient != 0.0 => {
            let k = -n;
            Some(vec![Monomial {
                coefficient: m.coefficient.powi(-k),
                params: m.params.iter().map(|&(i, e)| (i, -e * k)).collect(),
                h_power: -m.h_power * k,
                origin,
                ..m.clone()
            }])
        }
        _ => None,
    }
}

/// Why a derivative could not be taken.
#[derive(Clone, Debug, PartialEq)]
pub enum DerivativeError {
    /// The term multiplies an argument by data, whose derivative is unknown.
    OfData(Loc),
    /// The term is a product of arguments (the product rule is not applied).
    OfProduct(Loc),
}

/// The partial derivative of order `k` along `axis` (0: x, 1: y) of an expression linear
/// in its arguments, with coefficients constant on the element (parameters, `h`, numbers).
pub fn derivative(a: &Expansion, axis: usize, k: u8) -> Result<Expansion, DerivativeError> {
    let mut out = Vec::new();
    for t in a {
        match t.args.as_slice() {
            // d/dx of a constant on the element
            [] if t.data.is_empty() => {}
            [_] if !t.data.is_empty() => return Err(DerivativeError::OfData(t.origin)),
            [] => return Err(DerivativeError::OfData(t.origin)),
            [arg] => {
                let mut t = t.clone();
                let mut derivative = arg.derivative;
                derivative[axis] = derivative[axis].saturating_add(k);
                t.args = vec![ArgFactor {
                    symbol: arg.symbol,
                    derivative,
                }];
                out.push(t);
            }
            _ => return Err(DerivativeError::OfProduct(t.origin)),
        }
    }
    Ok(out)
}

/// Value of an expansion.
#[cfg(test)]
pub fn evaluate(
    e: &Expansion,
    param: &dyn Fn(usize) -> f64,
    h: f64,
    data: &dyn Fn(usize) -> f64,
    arg: &dyn Fn(ArgFactor) -> f64,
) -> f64 {
    e.iter().map(|t| t.evaluate(param, h, data, arg)).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn arg(symbol: usize) -> Expansion {
        let mut m = Monomial::constant(1.0, Loc::default());
        m.args = vec![ArgFactor {
            symbol,
            derivative: [0, 0],
        }];
        vec![m]
    }

    fn param(i: usize) -> Expansion {
        let mut m = Monomial::constant(1.0, Loc::default());
        m.params = vec![(i, 1)];
        vec![m]
    }

    #[test]
    fn difference_of_squares_cancels() {
        let l = Loc::default();
        let (x, y) = (arg(0), arg(1));
        let plus = add(x.clone(), y.clone());
        let minus = add(x.clone(), neg(y.clone()));
        let product = mul(&plus, &minus, l);
        // (x+y)(x−y) = x² − y²: the mixed terms cancel and are dropped
        assert_eq!(product.len(), 2);
        assert!(product
            .iter()
            .all(|t| t.args.len() == 2 && t.args[0] == t.args[1]));
    }

    #[test]
    fn negative_powers_only_of_scalars() {
        let l = Loc::default();
        let t = pow(&param(0), -2, l).unwrap();
        assert_eq!(t[0].params, vec![(0, -2)]);
        assert!(pow(&arg(0), -1, l).is_none());
        assert!(pow(&add(param(0), param(1)), -1, l).is_none());
    }

    #[test]
    fn derivatives_are_linear() {
        let l = Loc::default();
        // (2t·w − θ)'' = 2t·w'' − θ''; constants vanish
        let e = add(
            add(
                mul(
                    &mul(&vec![Monomial::constant(2.0, l)], &param(0), l),
                    &arg(1),
                    l,
                ),
                neg(arg(0)),
            ),
            param(0),
        );
        let d = derivative(&e, 0, 2).unwrap();
        assert_eq!(d.len(), 2);
        assert!(d.iter().all(|t| t.args[0].derivative == [2, 0]));
        let dxy = derivative(&d, 1, 1).unwrap();
        assert!(dxy.iter().all(|t| t.args[0].derivative == [2, 1]));
        assert_eq!(
            derivative(&mul(&arg(0), &arg(1), l), 0, 1),
            Err(DerivativeError::OfProduct(l))
        );
    }
}
