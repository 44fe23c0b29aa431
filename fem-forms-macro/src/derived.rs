//! The strong form of a model, derived from its forms by integration by parts on a
//! cell, and the two checks it allows (docs/adaptivity.md, "Derived from `a`").
//!
//! For an energy form `a` with constant coefficients (numbers, parameters, the cell
//! size), a load `ℓ` and a constraint `b` (`../shared/MODELS.md` §1), integration by
//! parts of every term `c D^α u_j D^β v_i` of `a` gives the strong operator
//! `(𝒜u)_i = Σ (−1)^{|β|} c D^{α+β} u_j`, and the residual of the equation of test
//! field `v_i`, `R_i = f_i + (B*λ)_i − (𝒜u)_i`. The boundary terms of the same
//! integration by parts are the fluxes across an edge: for `|β| = 1` (`β = e_k`) the
//! coefficient `c D^α u_j n_k` of `v` on the edge (`∂_n u` for the membrane, `σ(u)n` for
//! elasticity, `Cε(θ)n` and `q·n` for the plate); for `|β| = 2` the coefficient
//! `c D^α u_j n_k n_l` of `∂_n v` (the normal moment `M_nn`) and, after integrating the
//! tangential part along the edge, the coefficient of `v`,
//! `−c ∂_k D^α u_j n_l − ∂_s(c D^α u_j n_k τ_l)` (the Kirchhoff shear `V_n = Q_n + ∂_s
//! M_ns`).
//!
//! The checks compare polynomials by evaluating them at random points of their
//! variables (the values of every derivative of every unknown, the parameters, data,
//! `h` and a unit normal): two polynomials that agree at a dozen random points are
//! equal except on a set of measure zero, and identities such as `n_x² + n_y² = 1` and
//! `s² = 1` hold without a canonical form.
//!
//! 1. **Estimators**: each cell residual an `estimator:` declares must be a multiple of
//!    some `R_i`; each edge jump a multiple of a flux, or a jump of derivatives of lower
//!    order than the energy's (a nonconforming element's `[[∇w]]`).
//! 2. **Stabilization**: `B_h = … − αS`, `L_h = … − αℓ_S` stabilize the residual the
//!    solver sees in the multiplier's row, `(S(u, λ; 0, μ) − ℓ_S(0, μ)) / (α h^p)`; it must
//!    be a multiple of the constrained field's residual `R_w`, up to derivatives of the
//!    other equations' residuals (the plate's `div div Cε(θ) − sλ` is `R_w − div R_θ`).
//!    A wrong sign, a missing `ℓ_S` or another operator is a compile error at the term.

use crate::analysis::{Form, Symbols};
use crate::diagnostic::Diagnostic;
use crate::estimator::{Estimator, IndicatorTerm, Region};
use crate::roles::Roles;
use crate::symbolic::{ArgFactor, Expansion, Monomial};

/// The strong form of a model's primal equations.
#[derive(Clone, Debug)]
pub struct Derived {
    /// Per field, the cell residual `R_i` of the equation of its test function (empty
    /// for the multiplier), in the unknowns' symbols.
    pub cell: Vec<Expansion>,
    /// Per field, its edge fluxes (the coefficients of `v` and of `∂_n v` on an edge).
    pub fluxes: Vec<Vec<Expansion>>,
    /// Per field, the highest derivative order on its unknown in `a`.
    pub order: Vec<u8>,
}

/// The multiplier field of the model (declared `>= 0`), if any.
fn multiplier(symbols: &Symbols) -> Option<usize> {
    symbols.fields.iter().position(|f| f.nonnegative)
}

/// `(trial, test)` arguments of a term of a bilinear form: the argument of group 0 and
/// that of group 1.
fn split(form: &Form, m: &Monomial) -> Option<(ArgFactor, ArgFactor)> {
    let of = |g: usize| {
        m.args
            .iter()
            .find(|a| form.groups[g].contains(&a.symbol))
            .copied()
    };
    match m.args.len() {
        2 => Some((of(0)?, of(1)?)),
        _ => None,
    }
}

/// `m` with its arguments replaced by the unknown `field`'s derivative `derivative`
/// (or none), times `sign`, with `normal` added to its normal's powers: a term of a
/// strong residual or flux.
fn strong(m: &Monomial, field: Option<(usize, [u8; 2])>, sign: f64, normal: [u8; 2]) -> Monomial {
    let mut t = m.clone();
    t.coefficient *= sign;
    t.args = field
        .map(|(symbol, derivative)| vec![ArgFactor { symbol, derivative }])
        .unwrap_or_default();
    t.integrated = false;
    t.inner_products = 0;
    t.quadrature_degree = None;
    t.facet = None;
    t.normal = [t.normal[0] + normal[0], t.normal[1] + normal[1]];
    t
}

fn plus(a: [u8; 2], b: [u8; 2]) -> [u8; 2] {
    [a[0] + b[0], a[1] + b[1]]
}

/// The unit multi-index of axis `k`.
fn unit(k: usize) -> [u8; 2] {
    if k == 0 {
        [1, 0]
    } else {
        [0, 1]
    }
}

/// The axes of a multi-index of order 2, `(k, l)` with `k ≤ l`.
fn axes(beta: [u8; 2]) -> (usize, usize) {
    match beta {
        [2, 0] => (0, 0),
        [0, 2] => (1, 1),
        _ => (0, 1),
    }
}

/// `∂_s X = −n_y ∂_x X + n_x ∂_y X` of one term with an unknown and no data (`None`
/// otherwise).
fn tangential(m: &Monomial) -> Option<Vec<Monomial>> {
    if !m.data.is_empty() {
        return None;
    }
    let [a] = m.args.as_slice() else {
        return Some(Vec::new());
    };
    let mut x = m.clone();
    x.coefficient = -x.coefficient;
    x.args = vec![ArgFactor {
        symbol: a.symbol,
        derivative: plus(a.derivative, [1, 0]),
    }];
    x.normal[1] += 1;
    let mut y = m.clone();
    y.args = vec![ArgFactor {
        symbol: a.symbol,
        derivative: plus(a.derivative, [0, 1]),
    }];
    y.normal[0] += 1;
    Some(vec![x, y])
}

/// Drops the terms whose derivative exceeds their field's element degree: they vanish
/// on every cell, as the forms' terms that [`crate::analysis`] drops; on intervals also
/// the terms with a `y` derivative or the normal's `y` component (the tangential parts
/// of a plate's flux, which are zero there).
fn nonvanishing(symbols: &Symbols, e: Expansion) -> Expansion {
    let interval = symbols.dimension == 1;
    e.into_iter()
        .filter(|m| {
            !(interval && m.normal[1] > 0)
                && m.args.iter().all(|a| {
                    let field = &symbols.fields[symbols.field_of(a.symbol)];
                    a.order() as usize <= field.element.degree()
                        && !(interval && a.derivative[1] > 0)
                })
        })
        .collect()
}

/// The residual estimator of the derived strong form, for `estimator: derived`: for
/// the equation of each primal field whose operator has order `2m` (`m` the highest
/// derivative on its test function in `a`), `η_T² = h_T^{2m} ‖R_i‖²`, and on interior
/// edges `h_E^{2m−1} ‖[[F_v]]‖²` for the coefficient of `v` and, for `m = 2`,
/// `h_E^{2m−3} ‖[[F_∂nv]]‖²` for that of `∂_n v` (Verfürth's weights, unit constants,
/// not scaled to the energy norm's units).
pub fn residual_estimator(
    symbols: &Symbols,
    forms: &[Form],
    roles: &Roles,
    derived: &Derived,
    at: crate::diagnostic::Loc,
) -> Estimator {
    let mut terms = Vec::new();
    let [a, _] = roles.energy.expect("derived from an energy form");
    let mut test_order = vec![0u8; symbols.fields.len()];
    for m in forms[a].terms.iter().filter(|m| m.facet.is_none()) {
        if let Some((_, v)) = split(&forms[a], m) {
            let i = symbols.field_of(v.symbol);
            test_order[i] = test_order[i].max(v.order());
        }
    }
    let weight = |power: i32| {
        let mut w = Monomial::constant(1.0, at);
        w.h_power = power;
        vec![w]
    };
    for (i, field) in symbols.fields.iter().enumerate() {
        if field.nonnegative || derived.cell[i].is_empty() {
            continue;
        }
        let m = i32::from(test_order[i]);
        let name = &field.test_name;
        terms.push(IndicatorTerm {
            region: Region::Cell,
            weight: weight(2 * m),
            residual: derived.cell[i].clone(),
            source: format!("h_T^{} ‖R_{name}‖² (derived)", 2 * m),
            loc: at,
            average: false,
        });
        for (j, flux) in derived.fluxes[i].iter().enumerate() {
            if flux.is_empty() {
                continue;
            }
            let power = 2 * m - 1 - 2 * j as i32;
            let what = if j == 0 { "v" } else { "∂_n v" };
            terms.push(IndicatorTerm {
                region: Region::Edge,
                weight: weight(power),
                residual: flux.clone(),
                source: format!("h_E^{power} ‖[[F_{name}]]‖² (derived: the coefficient of {what})"),
                loc: at,
                average: false,
            });
        }
    }
    Estimator { terms }
}

/// The strong form of the model's primal equations, where the energy form has constant
/// coefficients on the cells and the load and the constraint take no derivative of
/// data; `None` otherwise (nothing is derived or checked then).
pub fn derive(symbols: &Symbols, forms: &[Form], roles: &Roles) -> Option<Derived> {
    let [a, l] = roles.energy?;
    let fields = symbols.fields.len();
    let lambda = multiplier(symbols);
    let mut cell = vec![Expansion::new(); fields];
    let mut fluxes = vec![vec![Expansion::new(), Expansion::new()]; fields];
    let mut order = vec![0u8; fields];
    for m in forms[a].terms.iter().filter(|m| m.facet.is_none()) {
        if !m.data.is_empty() {
            return None;
        }
        let (u, v) = split(&forms[a], m)?;
        let (j, i) = (symbols.field_of(u.symbol), symbols.field_of(v.symbol));
        order[j] = order[j].max(u.order());
        let sign = if v.order() % 2 == 0 { 1.0 } else { -1.0 };
        // R_i = … − (𝒜u)_i
        cell[i].push(strong(
            m,
            Some((j, plus(u.derivative, v.derivative))),
            -sign,
            [0, 0],
        ));
        match v.order() {
            0 => {}
            1 => {
                let k = if v.derivative[0] == 1 { 0 } else { 1 };
                fluxes[i][0].push(strong(m, Some((j, u.derivative)), 1.0, unit(k)));
            }
            2 => {
                let (k, l) = axes(v.derivative);
                // a term ∂_k∂_l v: both orders of the axes when k ≠ l, each with half
                let halves: Vec<(usize, usize, f64)> = if k == l {
                    vec![(k, l, 1.0)]
                } else {
                    vec![(k, l, 0.5), (l, k, 0.5)]
                };
                for (k, l, w) in halves {
                    let moment = strong(m, Some((j, u.derivative)), w, plus(unit(k), unit(l)));
                    fluxes[i][1].push(moment);
                    // −c ∂_k D^α u n_l
                    fluxes[i][0].push(strong(
                        m,
                        Some((j, plus(u.derivative, unit(k)))),
                        -w,
                        unit(l),
                    ));
                    // −∂_s(c D^α u n_k τ_l), τ = (−n_y, n_x)
                    let (tau_sign, tau_normal) = if l == 0 {
                        (-1.0, [0, 1])
                    } else {
                        (1.0, [1, 0])
                    };
                    let along = strong(
                        m,
                        Some((j, u.derivative)),
                        -w * tau_sign,
                        plus(unit(k), tau_normal),
                    );
                    fluxes[i][0].extend(tangential(&along)?);
                }
            }
            _ => return None,
        }
    }
    for m in forms[l].terms.iter().filter(|m| m.facet.is_none()) {
        let [v] = m.args.as_slice() else { return None };
        let i = symbols.field_of(v.symbol);
        match (v.order(), m.data.is_empty()) {
            (0, _) => cell[i].push(strong(m, None, 1.0, [0, 0])),
            (_, true) => {}
            (_, false) => return None,
        }
    }
    if let Some(lambda) = lambda {
        let [b, _] = roles.constraint?;
        for m in forms[b].terms.iter().filter(|m| m.facet.is_none()) {
            let (v, mu) = split(&forms[b], m)?;
            if mu.order() != 0 || !m.data.is_empty() {
                return None;
            }
            let i = symbols.field_of(v.symbol);
            let sign = if v.order() % 2 == 0 { 1.0 } else { -1.0 };
            cell[i].push(strong(m, Some((lambda, v.derivative)), sign, [0, 0]));
        }
    }
    let cell = cell.into_iter().map(|e| nonvanishing(symbols, e)).collect();
    let fluxes = fluxes
        .into_iter()
        .map(|f| f.into_iter().map(|e| nonvanishing(symbols, e)).collect())
        .collect();
    Some(Derived {
        cell,
        fluxes,
        order,
    })
}

/// A random point of the variables of the expansions: a deterministic pseudo-random
/// value for every (kind, index, derivative), and the obstacle side `s = side`.
struct Point<'a> {
    seed: u64,
    side: f64,
    roles: &'a Roles,
    dimension: usize,
}

/// SplitMix64 of `x`, as a number in [0.5, 1.5).
fn uniform(x: u64) -> f64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    0.5 + (z >> 11) as f64 / (1u64 << 53) as f64
}

impl Point<'_> {
    fn value(&self, kind: u64, index: usize, derivative: [u8; 2]) -> f64 {
        let key = self.seed.wrapping_mul(1_000_003)
            ^ (kind << 56)
            ^ ((index as u64) << 16)
            ^ (u64::from(derivative[0]) << 8)
            ^ u64::from(derivative[1]);
        uniform(key)
    }

    fn param(&self, p: usize) -> f64 {
        if self.roles.side == Some(p) {
            self.side
        } else {
            self.value(1, p, [0, 0])
        }
    }

    fn h(&self) -> f64 {
        self.value(2, 0, [0, 0])
    }

    fn normal(&self) -> [f64; 2] {
        if self.dimension == 1 {
            return [if self.seed % 2 == 0 { 1.0 } else { -1.0 }, 0.0];
        }
        let angle = std::f64::consts::TAU * (self.value(3, 0, [0, 0]) - 0.5);
        [angle.cos(), angle.sin()]
    }

    /// The value of an unknown's derivative: the unknowns are symbols `< F`; a test
    /// function's symbol is mapped to its field's (both stand for the same jet).
    fn argument(&self, symbols: &Symbols, a: &ArgFactor) -> f64 {
        self.value(4, symbols.field_of(a.symbol), a.derivative)
    }

    fn monomial(&self, symbols: &Symbols, m: &Monomial) -> f64 {
        let mut v = m.coefficient;
        for &(p, e) in &m.params {
            v *= self.param(p).powi(e);
        }
        v *= self.h().powi(m.h_power);
        for (d, e) in &m.divisors {
            let sum: f64 = d
                .terms
                .iter()
                .map(|t| {
                    t.params
                        .iter()
                        .fold(t.coefficient * self.h().powi(t.h_power), |v, &(p, e)| {
                            v * self.param(p).powi(e)
                        })
                })
                .sum();
            v /= sum.powi(*e);
        }
        for &d in &m.data {
            v *= self.value(5, d, [0, 0]);
        }
        for a in &m.args {
            v *= self.argument(symbols, a);
        }
        let n = self.normal();
        v * n[0].powi(i32::from(m.normal[0])) * n[1].powi(i32::from(m.normal[1]))
    }

    fn expansion(&self, symbols: &Symbols, e: &[Monomial]) -> f64 {
        e.iter().map(|m| self.monomial(symbols, m)).sum()
    }
}

/// Random points for each obstacle side `s = ±1`.
fn points<'a>(roles: &'a Roles, dimension: usize, per_side: u64) -> Vec<Vec<Point<'a>>> {
    [1.0, -1.0]
        .into_iter()
        .enumerate()
        .map(|(k, side)| {
            (0..per_side)
                .map(|seed| Point {
                    seed: seed + 1000 * k as u64 + 17,
                    side,
                    roles,
                    dimension,
                })
                .collect()
        })
        .collect()
}

/// Whether `x` is a multiple of `y` (a constant factor for each obstacle side; up to
/// sign when `up_to_sign`), with `y` not zero.
fn multiple(
    symbols: &Symbols,
    roles: &Roles,
    x: &[Monomial],
    y: &[Monomial],
    up_to_sign: bool,
) -> bool {
    points(roles, symbols.dimension, 8).iter().all(|side| {
        let pairs: Vec<(f64, f64)> = side
            .iter()
            .map(|p| (p.expansion(symbols, x), p.expansion(symbols, y)))
            .collect();
        let scale = pairs
            .iter()
            .map(|(a, b)| a.abs().max(b.abs()))
            .fold(0.0, f64::max);
        if scale == 0.0 || pairs.iter().any(|&(_, b)| b.abs() <= 1e-12 * scale) {
            return false;
        }
        let ratio = |(a, b): (f64, f64)| {
            let r = a / b;
            if up_to_sign {
                r.abs()
            } else {
                r
            }
        };
        let first = ratio(pairs[0]);
        first != 0.0
            && pairs
                .iter()
                .all(|&p| (ratio(p) - first).abs() <= 1e-9 * first.abs())
    })
}

/// The text of a term for a message: the derived residual of field `i`'s equation.
fn equation(symbols: &Symbols, i: usize) -> String {
    format!("the equation of `{}`", symbols.fields[i].test_name)
}

/// Errors for the declared estimator terms that are not what `a`, `ℓ` and `b` give:
/// a cell residual that is no multiple of an equation's residual, an edge jump that is
/// no multiple of a flux (nor a jump of lower-order derivatives). Boundary lines are
/// not checked.
pub fn check_estimator(
    symbols: &Symbols,
    roles: &Roles,
    derived: &Derived,
    estimator: &Estimator,
) -> Vec<Diagnostic> {
    let mut errors = Vec::new();
    let primal: Vec<usize> = (0..symbols.fields.len())
        .filter(|&i| !symbols.fields[i].nonnegative)
        .collect();
    for term in &estimator.terms {
        let residual = nonvanishing(symbols, term.residual.clone());
        if residual.is_empty() {
            continue;
        }
        let ok = match term.region {
            Region::Cell => primal
                .iter()
                .any(|&i| multiple(symbols, roles, &residual, &derived.cell[i], false)),
            // an average is no flux's jump: nothing to compare it with
            Region::Edge if term.average => true,
            Region::Edge => {
                conformity_jump(symbols, derived, &residual)
                    || primal.iter().any(|&i| {
                        derived.fluxes[i]
                            .iter()
                            .any(|f| multiple(symbols, roles, &residual, f, true))
                    })
            }
            Region::Boundary(_) => true,
        };
        if !ok {
            errors.push(mismatch(symbols, term, &primal));
        }
    }
    errors
}

/// A jump of derivatives of lower order than the energy's on each field (`[[∇w]]` of a
/// nonconforming plate element): not a flux, and allowed.
fn conformity_jump(symbols: &Symbols, derived: &Derived, residual: &[Monomial]) -> bool {
    residual.iter().all(|m| {
        m.args.iter().all(|a| {
            let j = symbols.field_of(a.symbol);
            a.order() < derived.order[j]
        })
    })
}

fn mismatch(symbols: &Symbols, term: &IndicatorTerm, primal: &[usize]) -> Diagnostic {
    let equations: Vec<String> = primal.iter().map(|&i| equation(symbols, i)).collect();
    let (what, help) = match term.region {
        Region::Cell => (
            format!(
                "`{}`: this residual is not a multiple of the residual `f + B*λ − 𝒜u` of {} that `a`, `ℓ` and `b` give by integration by parts",
                term.source,
                equations.join(" or ")
            ),
            "check the signs and the operator against the forms: the membrane's `a = ∫ ∇u·∇v`, `ℓ = ∫ f v`, `b = ∫ v μ` give `f + λ + Δu`",
        ),
        _ => (
            format!(
                "`{}`: this jump is not a multiple of a flux of {} that integration by parts of `a` gives on an edge",
                term.source,
                equations.join(" or ")
            ),
            "the fluxes are the coefficients of v and ∂_n v on an edge: `∇u·n` for `∫ ∇u·∇v`, `σ(u)·n` for `∫ σ(u):ε(v)`, `M_nn` and `V_n` for a plate",
        ),
    };
    Diagnostic::text(term.loc, what).help(help)
}

/// Errors for a cell stabilization that does not stabilize the constrained field's
/// residual: the multiplier's row of `B_h`'s α-terms minus `L_h`'s, over `α h^p`, must
/// be a multiple of `R_w` up to derivatives (of order ≤ 1) of the other equations'
/// residuals. Facet stabilizations (Signorini's) and models without a cell
/// stabilization, system or multiplier are not checked.
pub fn check_stabilization(
    symbols: &Symbols,
    forms: &[Form],
    roles: &Roles,
    derived: &Derived,
) -> Vec<Diagnostic> {
    let (Some([bh, lh]), Some((Some(alpha), s, _)), Some(lambda), Some([b, _])) = (
        roles.system,
        roles.stabilization,
        multiplier(symbols),
        roles.constraint,
    ) else {
        return Vec::new();
    };
    if forms[s].terms.iter().any(|m| m.facet.is_some()) {
        return Vec::new();
    }
    let fields = symbols.fields.len();
    let mu = fields + lambda;
    let with_alpha = |m: &Monomial| m.params.iter().any(|&(p, e)| p == alpha && e == 1);
    let on_mu = |m: &Monomial| {
        m.args
            .iter()
            .any(|a| a.symbol == mu && a.derivative == [0, 0])
    };
    // the stabilized residual in the multiplier's row: B_h's trial part minus L_h's data
    let mut row: Expansion = forms[bh]
        .terms
        .iter()
        .filter(|m| m.facet.is_none() && with_alpha(m) && on_mu(m))
        .map(|m| {
            let mut t = m.clone();
            t.args.retain(|a| a.symbol != mu);
            t
        })
        .collect();
    if row.is_empty() {
        return Vec::new();
    }
    let origin = row[0].origin;
    row.extend(
        forms[lh]
            .terms
            .iter()
            .filter(|m| m.facet.is_none() && with_alpha(m) && on_mu(m))
            .map(|m| {
                let mut t = m.clone();
                t.args.clear();
                t.coefficient = -t.coefficient;
                t
            }),
    );
    let constrained: Vec<usize> = forms[b]
        .terms
        .iter()
        .filter_map(|m| split(&forms[b], m).map(|(v, _)| symbols.field_of(v.symbol)))
        .collect();
    let Some(&w) = constrained.first() else {
        return Vec::new();
    };
    let p = roles.order as i32;
    // candidates: R_w, and each other primal equation's residual and its first
    // derivatives (without data: their derivatives are not known)
    let mut candidates: Vec<Expansion> = vec![derived.cell[w].clone()];
    for j in (0..fields).filter(|&j| j != w && j != lambda) {
        let r = &derived.cell[j];
        if r.is_empty() || r.iter().any(|m| !m.data.is_empty()) {
            continue;
        }
        candidates.push(r.clone());
        for axis in 0..symbols.dimension {
            let d: Expansion = r
                .iter()
                .filter_map(|m| {
                    let [a] = m.args.as_slice() else { return None };
                    let mut t = m.clone();
                    t.args = vec![ArgFactor {
                        symbol: a.symbol,
                        derivative: plus(a.derivative, unit(axis)),
                    }];
                    Some(t)
                })
                .collect();
            candidates.push(nonvanishing(symbols, d));
        }
    }
    let consistent = points(roles, symbols.dimension, 16).iter().all(|side| {
        let target: Vec<f64> = side
            .iter()
            .map(|pt| pt.expansion(symbols, &row) / (pt.param(alpha) * pt.h().powi(p)))
            .collect();
        let columns: Vec<Vec<f64>> = candidates
            .iter()
            .map(|c| side.iter().map(|pt| pt.expansion(symbols, c)).collect())
            .collect();
        fits(&columns, &target) && columns[0].iter().any(|&x| x != 0.0)
    });
    if consistent {
        return Vec::new();
    }
    vec![Diagnostic::text(
        origin,
        format!(
            "the stabilization does not stabilize the residual of {}: the multiplier's row of `α S` in `B_h`, less `α ℓ_S` in `L_h`, is not a multiple of `f + B*λ − 𝒜{}` derived from `a`, `ℓ` and `b`",
            equation(symbols, w),
            symbols.fields[w].name
        ),
    )
    .help("S_h = Σ_T h^p (𝒜u − sλ, 𝒜v − sμ)_T with `ℓ_S = Σ_T h^p (f, 𝒜v − sμ)_T` subtracted in `L_h`: look for a wrong sign, an `ℓ_S` missing from `L_h`, or an operator that is not `a`'s")]
}

/// Whether `target` is a linear combination of `columns` (least squares through the
/// normal equations, to 1e-8 of `target`'s size).
fn fits(columns: &[Vec<f64>], target: &[f64]) -> bool {
    let n = columns.len();
    let mut g = vec![vec![0.0; n + 1]; n];
    for i in 0..n {
        for j in 0..n {
            g[i][j] = columns[i].iter().zip(&columns[j]).map(|(a, b)| a * b).sum();
        }
        g[i][n] = columns[i].iter().zip(target).map(|(a, b)| a * b).sum();
    }
    let trace: f64 = (0..n).map(|i| g[i][i]).sum();
    for (i, row) in g.iter_mut().enumerate() {
        row[i] += 1e-14 * trace.max(f64::MIN_POSITIVE);
    }
    // Gaussian elimination with partial pivoting
    for k in 0..n {
        let pivot = (k..n)
            .max_by(|&a, &b| g[a][k].abs().total_cmp(&g[b][k].abs()))
            .unwrap_or(k);
        g.swap(k, pivot);
        if g[k][k] == 0.0 {
            continue;
        }
        let (upper, lower) = g.split_at_mut(k + 1);
        let pivot_row = &upper[k];
        for row in lower.iter_mut() {
            let f = row[k] / pivot_row[k];
            for (x, p) in row[k..].iter_mut().zip(&pivot_row[k..]) {
                *x -= f * p;
            }
        }
    }
    let mut x = vec![0.0; n];
    for k in (0..n).rev() {
        if g[k][k] == 0.0 {
            continue;
        }
        let s: f64 = (k + 1..n).map(|c| g[k][c] * x[c]).sum();
        x[k] = (g[k][n] - s) / g[k][k];
    }
    let scale = target.iter().map(|t| t * t).sum::<f64>().sqrt();
    let residual = target
        .iter()
        .enumerate()
        .map(|(r, t)| {
            let fit: f64 = (0..n).map(|c| x[c] * columns[c][r]).sum();
            (t - fit).powi(2)
        })
        .sum::<f64>()
        .sqrt();
    scale > 0.0 && residual <= 1e-8 * scale
}
