//! The symbolic IR: an integrand expanded into a sum of monomials.
//!
//! A monomial is `c · Π pᵢ^eᵢ · h^k · Π Dₘ^-eₘ · Π data · Π argument-derivatives`,
//! where the `Dₘ` are divisors: sums of parameter monomials that the analysis has
//! proved positive (`t² + β h²` with `β > 0` declared). The IR knows
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

/// One term `c · pᵢ^eᵢ · h^k` of a divisor: a scalar of parameters and the element size.
#[derive(Clone, Debug, PartialEq)]
pub struct DivisorTerm {
    /// The numeric coefficient.
    pub coefficient: f64,
    /// `(parameter index, exponent)`, sorted by index, no zero exponents.
    pub params: Vec<(usize, i32)>,
    /// Power of the element size `h`.
    pub h_power: i32,
}

/// A sum of [`DivisorTerm`]s that a term is divided by (positive by construction: the
/// analysis builds one only for sums it has proved positive). Its terms are sorted, so
/// equal sums compare equal.
#[derive(Clone, Debug, PartialEq)]
pub struct Divisor {
    /// The terms of the sum.
    pub terms: Vec<DivisorTerm>,
}

impl Divisor {
    /// The divisor of a scalar expansion free of arguments, data, integrals and
    /// divisors; `None` otherwise.
    pub fn of(e: &Expansion) -> Option<Self> {
        let mut terms = Vec::new();
        for m in e {
            if !m.is_scalar() || !m.divisors.is_empty() {
                return None;
            }
            terms.push(DivisorTerm {
                coefficient: m.coefficient,
                params: m.params.clone(),
                h_power: m.h_power,
            });
        }
        terms.sort_by(|a, b| (&a.params, a.h_power).cmp(&(&b.params, b.h_power)));
        Some(Self { terms })
    }

    /// Value for given parameters and `h`.
    #[cfg(test)]
    pub fn evaluate(&self, param: &dyn Fn(usize) -> f64, h: f64) -> f64 {
        self.terms
            .iter()
            .map(|t| {
                t.params
                    .iter()
                    .fold(t.coefficient * h.powi(t.h_power), |v, &(i, e)| {
                        v * param(i).powi(e)
                    })
            })
            .sum()
    }
}

/// One term `c · Π pᵢ^eᵢ · h^k · Π Dₘ^-eₘ · Π data · Π args` of an expansion.
#[derive(Clone, Debug, PartialEq)]
pub struct Monomial {
    /// The numeric coefficient.
    pub coefficient: f64,
    /// `(parameter index, exponent)`, sorted by index, no zero exponents.
    pub params: Vec<(usize, i32)>,
    /// Power of the element size `h`.
    pub h_power: i32,
    /// `(divisor, e)`: the term is divided by `divisor^e` (multiplied for `e < 0`); no
    /// zero exponents, each divisor once.
    pub divisors: Vec<(Divisor, i32)>,
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
    /// `Some(k)`: the term stands under a boundary integral `∫_Γ … ds` over facet
    /// part `k` (`Symbols::facets`); `None`: under a cell integral (or none).
    pub facet: Option<usize>,
    /// Powers of the components of the outward normal `n` (constant on a straight edge).
    pub normal: [u8; 2],
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
            divisors: Vec::new(),
            data: Vec::new(),
            args: Vec::new(),
            integrated: false,
            quadrature_degree: None,
            inner_products: 0,
            facet: None,
            normal: [0, 0],
            origin,
        }
    }

    /// True when the term has no argument, data, normal or integral: a scalar of
    /// parameters and `h`.
    pub fn is_scalar(&self) -> bool {
        self.args.is_empty() && self.data.is_empty() && !self.integrated && self.normal == [0, 0]
    }

    fn key_eq(&self, other: &Self) -> bool {
        self.params == other.params
            && self.h_power == other.h_power
            && self.divisors == other.divisors
            && self.data == other.data
            && self.args == other.args
            && self.integrated == other.integrated
            && self.quadrature_degree == other.quadrature_degree
            && self.inner_products == other.inner_products
            && self.facet == other.facet
            && self.normal == other.normal
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
        let mut divisors = self.divisors.clone();
        for (d, e) in &other.divisors {
            match divisors.iter_mut().find(|(x, _)| x == d) {
                Some((_, f)) => *f += e,
                None => divisors.push((d.clone(), *e)),
            }
        }
        divisors.retain(|&(_, e)| e != 0);
        let mut data = [self.data.as_slice(), other.data.as_slice()].concat();
        data.sort();
        let mut args = [self.args.as_slice(), other.args.as_slice()].concat();
        args.sort();
        Self {
            coefficient: self.coefficient * other.coefficient,
            params,
            h_power: self.h_power + other.h_power,
            divisors,
            data,
            args,
            integrated: self.integrated || other.integrated,
            quadrature_degree: self.quadrature_degree.or(other.quadrature_degree),
            inner_products: self.inner_products + other.inner_products,
            facet: self.facet.or(other.facet),
            normal: [
                self.normal[0].saturating_add(other.normal[0]),
                self.normal[1].saturating_add(other.normal[1]),
            ],
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
        for (d, e) in &self.divisors {
            v /= d.evaluate(param, h).powi(*e);
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

/// Merges equal monomials and drops those whose coefficient is zero, or cancels to
/// within the rounding of its summands. A non-finite one (an overflow, or an underflow
/// that [`mul`] made NaN) is kept for the definition's check to report.
pub fn normalize(terms: Expansion) -> Expansion {
    // each merged monomial with the largest magnitude among its summands
    let mut out: Vec<(Monomial, f64)> = Vec::with_capacity(terms.len());
    for t in terms {
        let size = t.coefficient.abs();
        match out.iter_mut().find(|(o, _)| o.key_eq(&t)) {
            Some((o, largest)) => {
                o.coefficient += t.coefficient;
                *largest = largest.max(size);
            }
            None => out.push((t, size)),
        }
    }
    // Cancellation leaves exact zeros only when the sums cancel exactly; terms that
    // cancel up to rounding (relative to their largest summand) are dropped as well. An
    // absolute threshold (1e-300 until a `∫ 1e-301 u v` vanished without a
    // word) would drop small constants that cancel nothing.
    out.into_iter()
        .filter(|(t, largest)| {
            let c = t.coefficient;
            !c.is_finite() || (c != 0.0 && c.abs() > CANCELLATION * largest)
        })
        .map(|(t, _)| t)
        .collect()
}

/// A merged coefficient below this fraction of its largest summand is their rounding.
const CANCELLATION: f64 = 64.0 * f64::EPSILON;

/// `c` of a product or power of non-zero coefficients, NaN where it underflowed (to 0 or
/// to a subnormal, which has lost digits): the term would vanish or be inexact without
/// a word (a `(1e-5)^100`), and the definition reports the NaN as it reports an
/// overflow.
fn representable(c: f64) -> f64 {
    if c == 0.0 || c.is_subnormal() {
        f64::NAN
    } else {
        c
    }
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
            let mut m = x.times(y, origin);
            if x.coefficient != 0.0 && y.coefficient != 0.0 {
                m.coefficient = representable(m.coefficient);
            }
            out.push(m);
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
                coefficient: representable(m.coefficient.powi(-k)),
                params: m.params.iter().map(|&(i, e)| (i, -e * k)).collect(),
                h_power: -m.h_power * k,
                divisors: m
                    .divisors
                    .iter()
                    .map(|(d, e)| (d.clone(), -e * k))
                    .collect(),
                origin,
                ..m.clone()
            }])
        }
        _ => None,
    }
}

/// `1 / a^k` (`k > 0`) of a scalar sum that the caller has proved positive, as one
/// monomial with a divisor; `None` when `a` holds arguments, data, integrals or divisors.
pub fn divide_by_sum(a: &Expansion, k: i32, origin: Loc) -> Option<Monomial> {
    let divisor = Divisor::of(a)?;
    let mut m = Monomial::constant(1.0, origin);
    m.divisors = vec![(divisor, k)];
    Some(m)
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
    fn divisors_merge_and_cancel() {
        let l = Loc::default();
        // D = p0² + p1·h²
        let mut h2 = Monomial::constant(1.0, l);
        h2.params = vec![(1, 1)];
        h2.h_power = 2;
        let sum = add(mul(&param(0), &param(0), l), vec![h2]);
        let inverse = vec![divide_by_sum(&sum, 1, l).unwrap()];
        let value = |e: &Expansion| evaluate(e, &|i| [3.0, 0.5][i], 2.0, &|_| 0.0, &|_| 0.0);
        assert!((value(&inverse) - 1.0 / (9.0 + 0.5 * 4.0)).abs() < 1e-15);
        // D⁻¹·D⁻¹ is one factor D⁻², and D⁻¹ · (1/D⁻¹) is 1
        let square = mul(&inverse, &inverse, l);
        assert_eq!(square.len(), 1);
        assert_eq!(square[0].divisors[0].1, 2);
        let back = mul(&inverse, &pow(&inverse, -1, l).unwrap(), l);
        assert!(back[0].divisors.is_empty() && back[0].coefficient == 1.0);
        // the sum in the other order is the same divisor
        let mut h2 = Monomial::constant(1.0, l);
        h2.params = vec![(1, 1)];
        h2.h_power = 2;
        let swapped = add(vec![h2], mul(&param(0), &param(0), l));
        assert_eq!(
            divide_by_sum(&swapped, 1, l).unwrap().divisors,
            inverse[0].divisors
        );
        assert!(divide_by_sum(&add(arg(0), param(0)), 1, l).is_none());
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
