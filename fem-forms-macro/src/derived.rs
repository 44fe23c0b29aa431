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
//! 2. **Stabilization**: `B_h = … − αS`, `L_h = … − αℓ_S` stabilize, in each row (each
//!    test function's derivative, the multiplier's among them), the residual
//!    `S(u, λ; ·) − ℓ_S(·)`; it must be a multiple of the constrained field's residual
//!    `R_w` (the factor a function of the parameters and `h`), up to the other
//!    equations' residuals and their divergence (the plate's `div div Cε(θ) − sλ` is
//!    `R_w − div R_θ`). A wrong sign, a missing `ℓ_S` (or part of it) or another
//!    operator is a compile error at the term.

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
    /// Whether `a`, `ℓ` or `b` integrate over boundary parts: their boundary conditions
    /// (a Neumann load, a Robin term, a multiplier on a part) are not in the derived
    /// cell residuals and fluxes.
    pub boundary_terms: bool,
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
        if field.nonnegative {
            continue;
        }
        let m = i32::from(test_order[i]);
        let name = &field.test_name;
        // a P1 field's cell residual may vanish (Δu, div σ): its jumps still count
        if !derived.cell[i].is_empty() {
            terms.push(IndicatorTerm {
                region: Region::Cell,
                weight: weight(2 * m),
                residual: derived.cell[i].clone(),
                source: format!("h_T^{} ‖R_{name}‖² (derived)", 2 * m),
                loc: at,
                average: false,
                quadrature_degree: None,
            });
        }
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
                quadrature_degree: None,
            });
        }
    }
    Estimator {
        terms,
        natural: Vec::new(),
    }
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
    let mut boundary_terms = false;
    for m in forms[a].terms.iter().filter(|m| m.facet.is_none()) {
        // data are variable coefficients; a reduced rule integrates another operator
        if !m.data.is_empty() || m.quadrature_degree.is_some() {
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
    boundary_terms |= forms[a].terms.iter().any(|m| m.facet.is_some());
    boundary_terms |= forms[l].terms.iter().any(|m| m.facet.is_some());
    for m in forms[l].terms.iter().filter(|m| m.facet.is_none()) {
        let [v] = m.args.as_slice() else { return None };
        // a load on a derivative of v would leave a flux of its own
        if v.order() != 0 {
            return None;
        }
        cell[symbols.field_of(v.symbol)].push(strong(m, None, 1.0, [0, 0]));
    }
    if let Some(lambda) = lambda {
        let [b, _] = roles.constraint?;
        boundary_terms |= forms[b].terms.iter().any(|m| m.facet.is_some());
        for m in forms[b].terms.iter().filter(|m| m.facet.is_none()) {
            let (v, mu) = split(&forms[b], m)?;
            // B = identity on cells: a derivative of v would leave a flux of its own
            if mu.order() != 0 || v.order() != 0 || !m.data.is_empty() {
                return None;
            }
            let i = symbols.field_of(v.symbol);
            cell[i].push(strong(m, Some((lambda, v.derivative)), 1.0, [0, 0]));
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
        boundary_terms,
    })
}

/// A random point of the variables of the expansions: pseudo-random values of the
/// unknowns' derivatives and the data (from `jet`), of the parameters, `h` and the unit
/// normal (from `scalars`), and the obstacle side `s = side`. A factor allowed to
/// depend on the parameters and `h` (a weight `h_T²(t² + h_T²)`, a `1/D`) is constant
/// over the points that share `scalars`.
struct Point<'a> {
    jet: u64,
    scalars: u64,
    side: f64,
    roles: &'a Roles,
    dimension: usize,
}

/// SplitMix64 of `x`, as a number in [0, 1).
fn uniform(x: u64) -> f64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64
}

impl Point<'_> {
    fn value(&self, seed: u64, kind: u64, index: usize, derivative: [u8; 2]) -> f64 {
        let key = seed.wrapping_mul(1_000_003)
            ^ (kind << 56)
            ^ ((index as u64) << 16)
            ^ (u64::from(derivative[0]) << 8)
            ^ u64::from(derivative[1]);
        uniform(key)
    }

    /// A parameter in [0.1, 0.4): clear of the singular values of the usual material
    /// formulas (ν = ½ in `1/(1 − 2ν)`, ν = 1 in `1/(1 − ν)`); the side is ±1; a unit
    /// vector's components a point of the unit circle.
    fn param(&self, p: usize) -> f64 {
        if self.roles.side == Some(p) {
            return self.side;
        }
        // a vector of parameters declared a unit vector lies on the unit circle
        for &(x, y) in &self.roles.unit {
            if p == x || p == y {
                let angle = std::f64::consts::TAU * self.value(self.scalars, 6, x, [0, 0]);
                return if p == x { angle.cos() } else { angle.sin() };
            }
        }
        0.1 + 0.3 * self.value(self.scalars, 1, p, [0, 0])
    }

    fn h(&self) -> f64 {
        0.5 + self.value(self.scalars, 2, 0, [0, 0])
    }

    fn normal(&self) -> [f64; 2] {
        if self.dimension == 1 {
            return [if self.scalars % 2 == 0 { 1.0 } else { -1.0 }, 0.0];
        }
        let angle = std::f64::consts::TAU * self.value(self.scalars, 3, 0, [0, 0]);
        [angle.cos(), angle.sin()]
    }

    /// The value of an unknown's derivative: a test function's symbol is mapped to its
    /// field's (both stand for the same jet).
    fn argument(&self, symbols: &Symbols, a: &ArgFactor) -> f64 {
        self.value(self.jet, 4, symbols.field_of(a.symbol), a.derivative) - 0.5
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
            v *= self.value(self.jet, 5, d, [0, 0]) - 0.5;
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

/// Blocks of random points: for each obstacle side `s = ±1` and each of a few draws of
/// the parameters, `h` and the normal, `per_block` draws of the unknowns and data.
fn blocks<'a>(roles: &'a Roles, dimension: usize, per_block: u64) -> Vec<Vec<Point<'a>>> {
    let mut blocks = Vec::new();
    for (k, side) in [1.0, -1.0].into_iter().enumerate() {
        for draw in 0..3u64 {
            blocks.push(
                (0..per_block)
                    .map(|jet| Point {
                        jet: 7919 * jet + 104_729 * draw + 1_299_709 * k as u64 + 17,
                        scalars: 31 * draw + 1000 * k as u64 + 3,
                        side,
                        roles,
                        dimension,
                    })
                    .collect(),
            );
        }
    }
    blocks
}

/// Whether `x` is a multiple of `y`, the factor a function of the parameters, `h`, the
/// normal and the side only (up to sign when `up_to_sign`), with `y` not zero.
fn multiple(
    symbols: &Symbols,
    roles: &Roles,
    x: &[Monomial],
    y: &[Monomial],
    up_to_sign: bool,
) -> bool {
    blocks(roles, symbols.dimension, 6).iter().all(|block| {
        let pairs: Vec<(f64, f64)> = block
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
            Region::Boundary(_) | Region::Natural(_) => true,
        };
        if !ok {
            errors.push(mismatch(symbols, term, &primal));
        }
    }
    errors
}

/// The natural boundary terms of `estimator`: each interior edge (interval: node) term
/// whose jumped quantity is a multiple of the flux `F_ij` of field `i` (the coefficient
/// of `v` for `j = 0`, of `∂_n v` for `j = 1`) applies, with its weight, one-sided on the
/// boundary edges where that test coordinate is free, since there the natural boundary
/// condition is `F_ij = 0` (a load on a boundary part has that part's own lines). Adds
/// the terms as [`Region::Natural`] and lists the coordinates in `estimator.natural`.
/// Averages and conformity jumps (Morley's `[[∇w]]`) are no fluxes: they take no term.
pub fn natural_terms(
    symbols: &Symbols,
    roles: &Roles,
    derived: &Derived,
    estimator: &mut Estimator,
) {
    let primal: Vec<usize> = (0..symbols.fields.len())
        .filter(|&i| !symbols.fields[i].nonnegative)
        .collect();
    let mut natural: Vec<(usize, u8)> = Vec::new();
    let mut terms = Vec::new();
    for term in estimator.terms(Region::Edge).filter(|t| !t.average) {
        let residual = nonvanishing(symbols, term.residual.clone());
        if residual.is_empty() {
            continue;
        }
        let flux = primal.iter().find_map(|&i| {
            derived.fluxes[i]
                .iter()
                .position(|f| multiple(symbols, roles, &residual, f, true))
                .map(|j| (i, j as u8))
        });
        let Some(coordinate) = flux else { continue };
        let k = natural
            .iter()
            .position(|&c| c == coordinate)
            .unwrap_or_else(|| {
                natural.push(coordinate);
                natural.len() - 1
            });
        terms.push(IndicatorTerm {
            region: Region::Natural(k),
            ..term.clone()
        });
    }
    estimator.terms.extend(terms);
    estimator.natural = natural;
}

/// A jump of derivatives of lower order than the energy's of a nonconforming or
/// discontinuous field (`[[∇w]]` of Morley's plate element): not a flux, and allowed;
/// on a conforming field such a jump vanishes and is refused as a misspelt flux.
fn conformity_jump(symbols: &Symbols, derived: &Derived, residual: &[Monomial]) -> bool {
    use fem_reference::ElementKind;
    residual.iter().all(|m| {
        m.args.iter().all(|a| {
            let j = symbols.field_of(a.symbol);
            let nonconforming = matches!(
                symbols.fields[j].element,
                ElementKind::Morley | ElementKind::P0 | ElementKind::P1Disc
            );
            nonconforming && a.order() < derived.order[j]
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
/// residual: every row of `B_h`'s α-terms (each test function's derivative, the
/// multiplier's among them) less `L_h`'s must be a multiple of `R_w`, the factor a
/// function of the parameters and `h`, up to the other equations' residuals and their
/// divergence (triangles) or derivative (intervals). Facet stabilizations (Signorini's)
/// and models without a cell stabilization, system or multiplier are not checked.
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
    let with_alpha =
        |m: &Monomial| m.facet.is_none() && m.params.iter().any(|&(p, e)| p == alpha && e == 1);
    let rows = stabilization_rows(symbols, forms, [bh, lh], with_alpha);
    if rows.is_empty() {
        return Vec::new();
    }
    let constrained: Vec<usize> = forms[b]
        .terms
        .iter()
        .filter_map(|m| split(&forms[b], m).map(|(v, _)| symbols.field_of(v.symbol)))
        .collect();
    let Some(&w) = constrained.first() else {
        return Vec::new();
    };
    let candidates = candidates(symbols, derived, w, lambda);
    for (test, row) in &rows {
        if !fits_everywhere(symbols, roles, row, &candidates, true) {
            let origin = row[0].origin;
            let at = row_name(symbols, *test, lambda);
            return vec![Diagnostic::text(
                origin,
                format!(
                    "the stabilization does not stabilize the residual of {}: {at} of `α S` in `B_h`, less `α ℓ_S` in `L_h`, is not a multiple of `f + B*λ − 𝒜{}` derived from `a`, `ℓ` and `b`",
                    equation(symbols, w),
                    symbols.fields[w].name
                ),
            )
            .help("S_h = Σ_T h^p (𝒜u − sλ, 𝒜v − sμ)_T with `ℓ_S = Σ_T h^p (f, 𝒜v − sμ)_T` subtracted in `L_h`: look for a wrong sign, an `ℓ_S` missing from `L_h` (or part of it), or an operator that is not `a`'s")];
        }
    }
    Vec::new()
}

/// Errors for a stabilization on a boundary part (Signorini's `Σ_E h_E (λ + σ_n(u),
/// μ + σ_n(v))_E` on `Γ_C`) that does not stabilize the part's boundary equation: every
/// row of `B_h`'s α-terms on the part (each test coordinate, the multiplier's among
/// them) less `L_h`'s must be a combination, with factors of the parameters, `h` and the
/// normal, of the boundary residuals `R_i = F_i(u) − B_Γ*λ − g_i` of the primal
/// equations there: the flux of `a` (`σ(u)n` by component; also the coefficient of
/// `∂_n v`) with the system's own terms on the part, the coupling to the multiplier
/// among them, less the load's (`σ(u)n + λ n_c` on `Γ_C`). A residual that holds a direction of parameters is
/// consistent only where the direction is a unit vector: the model declares it
/// `unit: n_c;`, which the random points honour.
pub fn check_facet_stabilization(
    symbols: &Symbols,
    forms: &[Form],
    roles: &Roles,
    derived: &Derived,
) -> Vec<Diagnostic> {
    let (Some([bh, lh]), Some((Some(alpha), s, _)), Some(lambda)) =
        (roles.system, roles.stabilization, multiplier(symbols))
    else {
        return Vec::new();
    };
    let parts: Vec<usize> = forms[s].terms.iter().filter_map(|m| m.facet).collect();
    let mut errors = Vec::new();
    for part in (0..symbols.facets.len()).filter(|p| parts.contains(p)) {
        let on_part = |m: &Monomial| {
            m.facet == Some(part) && m.params.iter().any(|&(p, e)| p == alpha && e == 1)
        };
        let rows = stabilization_rows(symbols, forms, [bh, lh], on_part);
        let candidates = boundary_residuals(symbols, forms, derived, [bh, lh], (part, alpha));
        for (test, row) in &rows {
            if !fits_everywhere(symbols, roles, row, &candidates, false) {
                let at = row_name(symbols, *test, lambda);
                errors.push(
                    Diagnostic::text(
                        row[0].origin,
                        format!(
                            "the stabilization on `{}` does not stabilize the boundary equation there: {at} of `α S` in `B_h`, less `α ℓ_S` in `L_h`, is not a combination of the boundary residuals `F(u) − B*λ − g` that `a`, `b` and `ℓ` give on the part",
                            symbols.facets[part]
                        ),
                    )
                    .help("Signorini's is `Σ_E h_E (λ + σ_n(u), μ + σ_n(v))_E` with `σ_n(u) = (σ(u)·n)·n_c` and `b(v;μ) = −∫_Γ_C μ v·n_c`: look for a wrong sign or another operator; a direction of parameters in it must be a unit vector, declared `unit: n_c;`"),
                );
                break;
            }
        }
    }
    errors
}

/// The rows of a stabilization: `B_h`'s terms that `on` selects (α-terms on the cells or
/// on a part), grouped by their test coordinate (a test function's derivative, the
/// multiplier's among them) with that factor taken out, less `L_h`'s on the same
/// coordinates; each row with its vanishing terms dropped, empty rows left out.
fn stabilization_rows(
    symbols: &Symbols,
    forms: &[Form],
    [bh, lh]: [usize; 2],
    on: impl Fn(&Monomial) -> bool,
) -> Vec<(ArgFactor, Expansion)> {
    let fields = symbols.fields.len();
    // the test function's factor of a term: its argument of a test symbol
    let test_of = |m: &Monomial| m.args.iter().find(|a| a.symbol >= fields).copied();
    let mut rows: Vec<(ArgFactor, Expansion)> = Vec::new();
    for m in forms[bh].terms.iter().filter(|m| on(m)) {
        let Some(test) = test_of(m) else { continue };
        let mut t = m.clone();
        t.args.retain(|a| *a != test);
        match rows.iter_mut().find(|(c, _)| *c == test) {
            Some((_, row)) => row.push(t),
            None => rows.push((test, vec![t])),
        }
    }
    for m in forms[lh].terms.iter().filter(|m| on(m)) {
        let Some(test) = test_of(m) else { continue };
        if let Some((_, row)) = rows.iter_mut().find(|(c, _)| *c == test) {
            let mut t = m.clone();
            t.args.clear();
            t.coefficient = -t.coefficient;
            row.push(t);
        }
    }
    rows.into_iter()
        .map(|(test, row)| (test, nonvanishing(symbols, row)))
        .filter(|(_, row)| !row.is_empty())
        .collect()
}

/// Whether `row` is a combination of `candidates` at the random points of every block
/// ([`fits`]; the first candidate taking part where `first_carries`).
fn fits_everywhere(
    symbols: &Symbols,
    roles: &Roles,
    row: &[Monomial],
    candidates: &[Expansion],
    first_carries: bool,
) -> bool {
    blocks(roles, symbols.dimension, 16).iter().all(|block| {
        let target: Vec<f64> = block.iter().map(|p| p.expansion(symbols, row)).collect();
        let columns: Vec<Vec<f64>> = candidates
            .iter()
            .map(|c| block.iter().map(|p| p.expansion(symbols, c)).collect())
            .collect();
        fits(&columns, &target, first_carries)
    })
}

/// "the multiplier's row" or "the row of `v`" for a row's test coordinate.
fn row_name(symbols: &Symbols, test: ArgFactor, lambda: usize) -> String {
    let fields = symbols.fields.len();
    if test.symbol == fields + lambda {
        "the multiplier's row".to_string()
    } else {
        format!(
            "the row of `{}`",
            symbols.fields[test.symbol - fields].test_name
        )
    }
}

/// The boundary residuals of the primal equations on boundary part `part`, one per
/// field and flux: `F_i0(u) + (B_h's terms on the part) − (L_h's)` in the coefficient of
/// `v_i` (the flux of `a`, then the system's own couplings there, the multiplier's
/// `−b(v;λ)` and a Robin term, and the load), α-terms left out; and the coefficient of
/// `∂_n v_i` alone where `a` has one.
fn boundary_residuals(
    symbols: &Symbols,
    forms: &[Form],
    derived: &Derived,
    [bh, lh]: [usize; 2],
    (part, alpha): (usize, usize),
) -> Vec<Expansion> {
    let fields = symbols.fields.len();
    let on = |m: &&Monomial| {
        m.facet == Some(part) && !m.params.iter().any(|&(p, e)| p == alpha && e != 0)
    };
    let mut out = Vec::new();
    for i in (0..fields).filter(|&i| !symbols.fields[i].nonnegative) {
        let mut r = derived.fluxes[i][0].clone();
        for m in forms[bh].terms.iter().filter(on) {
            if let Some((u, v)) = split(&forms[bh], m) {
                if v.symbol == fields + i && v.order() == 0 {
                    let j = symbols.field_of(u.symbol);
                    r.push(strong(m, Some((j, u.derivative)), 1.0, [0, 0]));
                }
            }
        }
        for m in forms[lh].terms.iter().filter(on) {
            if let [v] = m.args.as_slice() {
                if v.symbol == fields + i && v.order() == 0 {
                    r.push(strong(m, None, -1.0, [0, 0]));
                }
            }
        }
        out.push(nonvanishing(symbols, r));
        if !derived.fluxes[i][1].is_empty() {
            out.push(nonvanishing(symbols, derived.fluxes[i][1].clone()));
        }
    }
    out.retain(|r| !r.is_empty());
    out
}

/// What a stabilized residual may be a combination of: the constrained field's
/// residual `R_w` first, then the other equations' residuals (without data, whose
/// derivatives are unknown) and, on intervals, their derivatives; on triangles the
/// divergence of each vector field's residuals (the plate's `div R_θ`).
fn candidates(symbols: &Symbols, derived: &Derived, w: usize, lambda: usize) -> Vec<Expansion> {
    let derivative = |r: &Expansion, axis: usize| -> Expansion {
        r.iter()
            .filter_map(|m| {
                let [a] = m.args.as_slice() else { return None };
                let mut t = m.clone();
                t.args = vec![ArgFactor {
                    symbol: a.symbol,
                    derivative: plus(a.derivative, unit(axis)),
                }];
                Some(t)
            })
            .collect()
    };
    let usable = |j: usize| {
        j != w
            && j != lambda
            && !derived.cell[j].is_empty()
            && derived.cell[j].iter().all(|m| m.data.is_empty())
    };
    let mut out = vec![derived.cell[w].clone()];
    for j in (0..symbols.fields.len()).filter(|&j| usable(j)) {
        out.push(derived.cell[j].clone());
        if symbols.dimension == 1 {
            out.push(nonvanishing(symbols, derivative(&derived.cell[j], 0)));
        }
    }
    if symbols.dimension == 2 {
        for v in 0..symbols.vectors.len() {
            let components: Vec<usize> = (0..symbols.fields.len())
                .filter(|&j| symbols.fields[j].component.is_some_and(|(c, _)| c == v))
                .collect();
            if components.len() == 2 && components.iter().all(|&j| usable(j)) {
                let mut div = Expansion::new();
                for &j in &components {
                    let axis = symbols.fields[j].component.map_or(0, |(_, a)| a);
                    div.extend(derivative(&derived.cell[j], axis));
                }
                out.push(nonvanishing(symbols, div));
            }
        }
    }
    out
}

/// Whether `target` is a linear combination of `columns` (least squares through the
/// normal equations, to 1e-8 of `target`'s size), in which the first column takes part
/// where `first_carries`.
fn fits(columns: &[Vec<f64>], target: &[f64], first_carries: bool) -> bool {
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
    // the first column (R_w) must carry the target: derivatives of the other equations
    // alone stabilize nothing of the contact equation
    if n == 0 {
        return false;
    }
    let first = x[0].abs() * columns[0].iter().map(|c| c * c).sum::<f64>().sqrt();
    scale > 0.0 && residual <= 1e-8 * scale && (!first_carries || first >= 1e-6 * scale)
}
