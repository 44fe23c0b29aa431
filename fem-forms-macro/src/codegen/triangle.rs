//! The affine-triangle backend.
//!
//! On a triangle `x = x₀ + J ξ` with constant `J`, so a physical derivative `∂^α` is a
//! fixed combination `Σ_β T_αβ(K) ∂̂^β` of reference derivatives of the same order, with
//! `K = J⁻¹` (`∂/∂x_i = Σ_a K_ai ∂/∂ξ_a`). The kernels use the tensor representation:
//! - terms without data: the reference integrals `R_βγ[i][j] = ∫_T̂ ∂̂^β φ̂ᵢ ∂̂^γ ψ̂ⱼ` are
//!   computed here, at compile time, and emitted as literals; at run time the element
//!   computes one scalar `s_βγ = |det J| Σ_terms c T_αβ T_α'γ` per reference pair and
//!   each entry is `Σ s_βγ R_βγ[i][j]` over the pairs whose literal is non-zero;
//! - terms with data: the shared quadrature loops over a triangle rule with tabulated
//!   reference derivatives, the data evaluated once per point.

use super::backend::{CellBackend, ExactPart, Rule};
use super::emit::{coefficient, float, is_symmetric, product};
use crate::analysis::{Block, Symbols, Term};
use fem_reference::triangle::{Polynomial2, TriangleRule};
use fem_reference::ElementKind;
use proc_macro2::{Ident, TokenStream};
use quote::{format_ident, quote};

/// Kernels on affine triangles.
pub struct Triangle;

/// A monomial `c · k00^e0 · k01^e1 · k10^e2 · k11^e3` in the entries of `K = J⁻¹`.
type KMonomial = (f64, [u8; 4]);

/// `T_αβ` of one physical multi-index α: the reference multi-indices β with their
/// polynomials in K.
type Transform = Vec<([u8; 2], Vec<KMonomial>)>;

/// Adds `monomials` into the polynomial `poly`, merging equal exponents.
fn add_monomials(poly: &mut Vec<KMonomial>, monomials: Vec<KMonomial>) {
    for m in monomials {
        match poly.iter_mut().find(|(_, e)| *e == m.1) {
            Some(existing) => existing.0 += m.0,
            None => poly.push(m),
        }
    }
}

/// `T_αβ` for every reference multi-index β of the same order as α.
pub(super) fn transform(alpha: [u8; 2]) -> Transform {
    // Start from the identity operator and apply ∂x = k00 ∂ξ + k10 ∂η, ∂y = k01 ∂ξ + k11 ∂η.
    let mut terms: Transform = vec![([0, 0], vec![(1.0, [0; 4])])];
    let factors: [[(usize, usize); 2]; 2] = [[(0, 0), (2, 1)], [(1, 0), (3, 1)]];
    for (axis, &count) in alpha.iter().enumerate() {
        for _ in 0..count {
            let mut next: Transform = Vec::new();
            for (beta, poly) in &terms {
                for &(k, reference_axis) in &factors[axis] {
                    let mut b = *beta;
                    b[reference_axis] += 1;
                    let shifted: Vec<KMonomial> = poly
                        .iter()
                        .map(|&(c, mut e)| {
                            e[k] += 1;
                            (c, e)
                        })
                        .collect();
                    match next.iter_mut().find(|(x, _)| *x == b) {
                        Some((_, p)) => add_monomials(p, shifted),
                        None => next.push((b, shifted)),
                    }
                }
            }
            terms = next;
        }
    }
    terms
}

pub(super) fn k_polynomial_code(poly: &[KMonomial]) -> TokenStream {
    let names = [quote!(k00), quote!(k01), quote!(k10), quote!(k11)];
    let monomials: Vec<TokenStream> = poly
        .iter()
        .map(|&(c, e)| {
            let mut factors: Vec<TokenStream> = Vec::new();
            for (name, &n) in names.iter().zip(&e) {
                for _ in 0..n {
                    factors.push(name.clone());
                }
            }
            if c != 1.0 || factors.is_empty() {
                factors.insert(0, float(c));
            }
            product(factors)
        })
        .collect();
    quote!((#(#monomials)+*))
}

pub(super) fn t_ident(alpha: [u8; 2], beta: [u8; 2]) -> Ident {
    format_ident!("t_{}{}_{}{}", alpha[0], alpha[1], beta[0], beta[1])
}

/// `T_αβ` as code: the name of its run-time value, `None` for the identity (α = 0).
pub(super) fn t_code(alpha: [u8; 2], beta: [u8; 2]) -> Option<TokenStream> {
    (alpha != [0, 0]).then(|| {
        let ident = t_ident(alpha, beta);
        quote!(#ident)
    })
}

/// The reference basis of `element` differentiated by `beta`.
pub(super) fn derivatives(element: ElementKind, beta: [u8; 2]) -> Vec<Polynomial2> {
    element
        .triangle_basis()
        .iter()
        .map(|p| p.derivative(beta[0] as u32, beta[1] as u32))
        .collect()
}

/// The rule of a data loop or of an explicit `∫[degree=N]`: the centroid (one point)
/// for degree ≤ 1, as reduced integration means, otherwise the collapsed Gauss rule
/// exact for the degree.
pub(super) fn rule_for_degree(degree: usize) -> TriangleRule {
    if degree <= 1 {
        TriangleRule {
            points: vec![[1.0 / 3.0, 1.0 / 3.0]],
            weights: vec![0.5],
        }
    } else {
        TriangleRule::exact_for_degree(degree)
    }
}

/// The physical multi-indices the block's terms use, sorted.
pub(super) fn alphas(block: &Block) -> Vec<[u8; 2]> {
    let mut alphas: Vec<[u8; 2]> = Vec::new();
    for t in &block.terms {
        for a in [Some(t.test_derivative), t.trial_derivative]
            .into_iter()
            .flatten()
        {
            if !alphas.contains(&a) {
                alphas.push(a);
            }
        }
    }
    alphas.sort();
    alphas
}

/// A reference pair (β, γ) of constant-coefficient terms: its literal table and the
/// run-time contributions to its scalar.
struct Pair {
    beta: [u8; 2],
    gamma: Option<[u8; 2]>,
    reference: Vec<Vec<f64>>,
    scalar: Vec<TokenStream>,
}

/// The pairs of a symmetric block ([`is_symmetric`]) with each `(β, γ)`, `β ≠ γ`, merged
/// with its transpose `(γ, β)`: their scalars are equal (`s_βγ = Σ c T_αβ T_α'γ` over a
/// term set closed under swapping α and α'), so `s_βγ R_βγ + s_γβ R_γβ` is one scalar
/// times `R_βγ + R_γβ` (Kirchhoff on Argyris: 9 pairs become 6). A pair whose transpose
/// is missing is kept as it is.
fn merge_transposed_pairs(pairs: Vec<Pair>) -> Vec<Pair> {
    let mut pairs: Vec<Option<Pair>> = pairs.into_iter().map(Some).collect();
    let mut merged = Vec::new();
    for a in 0..pairs.len() {
        let Some(mut pair) = pairs[a].take() else {
            continue;
        };
        if let Some(gamma) = pair.gamma.filter(|g| *g != pair.beta) {
            let partner = pairs.iter().position(|p| {
                p.as_ref()
                    .is_some_and(|p| p.beta == gamma && p.gamma == Some(pair.beta))
            });
            if let Some(other) = partner.and_then(|b| pairs[b].take()) {
                for (row, other_row) in pair.reference.iter_mut().zip(&other.reference) {
                    for (v, w) in row.iter_mut().zip(other_row) {
                        *v += w;
                    }
                }
            }
        }
        merged.push(pair);
    }
    merged
}

impl Triangle {
    /// `R_βγ[i][j] = ∫_T̂ ∂̂^β φ̂ᵢ ∂̂^γ ψ̂ⱼ` with `rule` (`γ = None`: linear form).
    fn reference_table(
        &self,
        block: &Block,
        symbols: &Symbols,
        beta: [u8; 2],
        gamma: Option<[u8; 2]>,
        rule: &TriangleRule,
    ) -> Vec<Vec<f64>> {
        let test_element = symbols.fields[block.test_field].element;
        let trial_element = block.trial_field.map(|f| symbols.fields[f].element);
        let test_basis = derivatives(test_element, beta);
        let trial_basis = match (trial_element, gamma) {
            (Some(e), Some(g)) => derivatives(e, g),
            _ => vec![Polynomial2 {
                terms: vec![(0, 0, 1.0)],
            }],
        };
        test_basis
            .iter()
            .map(|p| {
                trial_basis
                    .iter()
                    .map(|q| rule.integrate(|x| p.eval(x) * q.eval(x)))
                    .collect()
            })
            .collect()
    }

    /// Adds one constant-coefficient term to the pairs: per (β, γ) of its transforms,
    /// the run-time factor `c · T_αβ · T_α'γ`.
    fn add_term(&self, term: &Term, block: &Block, symbols: &Symbols, pairs: &mut Vec<Pair>) {
        // Exact terms: any rule exact for the degree gives the same table.
        let rule = match term.quadrature_degree {
            Some(degree) => rule_for_degree(degree),
            None => TriangleRule::exact_for_degree(self.term_degree(term, block, symbols)),
        };
        let c = coefficient(term.coefficient, &term.params, term.h_power, &term.divisors);
        let trial_betas: Vec<[u8; 2]> = match term.trial_derivative {
            Some(d) => transform(d).into_iter().map(|(g, _)| g).collect(),
            None => vec![[0, 0]],
        };
        for (beta, _) in transform(term.test_derivative) {
            for &gamma in &trial_betas {
                let gamma_key = term.trial_derivative.map(|_| gamma);
                let index = match pairs
                    .iter()
                    .position(|p| p.beta == beta && p.gamma == gamma_key)
                {
                    Some(i) => i,
                    None => {
                        let reference =
                            self.reference_table(block, symbols, beta, gamma_key, &rule);
                        pairs.push(Pair {
                            beta,
                            gamma: gamma_key,
                            reference,
                            scalar: Vec::new(),
                        });
                        pairs.len() - 1
                    }
                };
                let mut factors = vec![c.clone()];
                factors.extend(t_code(term.test_derivative, beta));
                if let Some(d) = term.trial_derivative {
                    factors.extend(t_code(d, gamma));
                }
                pairs[index].scalar.push(product(factors));
            }
        }
    }
}

impl CellBackend for Triangle {
    fn cell_variant(&self) -> &'static str {
        "Triangle"
    }

    fn coordinates(&self) -> usize {
        6
    }

    fn coordinates_message(&self) -> &'static str {
        "a triangle has six vertex coordinates"
    }

    fn doc_suffix(&self) -> &'static str {
        " on triangles"
    }

    fn dof_count(&self, element: ElementKind) -> usize {
        element.triangle_basis().len()
    }

    fn dof_scaling(&self, _element: ElementKind, _index: usize) -> i32 {
        0
    }

    /// Each table `R_ββ` and each merged `R_βγ + R_γβ = R_βγ + R_βγᵀ` is symmetric.
    fn symmetric_entries(&self) -> bool {
        true
    }

    fn rule(&self, degree: usize) -> Rule {
        let rule = rule_for_degree(degree);
        Rule {
            points: rule.points.iter().map(|p| p.to_vec()).collect(),
            weights: rule.weights,
        }
    }

    fn geometry(&self, block: &Block) -> TokenStream {
        // Only what the terms use: h (a sqrt) and K (a division) are skipped otherwise.
        let uses_h = block.terms.iter().any(|t| {
            t.h_power != 0
                || t.divisors
                    .iter()
                    .any(|(d, _)| d.terms.iter().any(|x| x.h_power != 0))
        });
        let uses_k = alphas(block).iter().any(|a| *a != [0, 0]);
        let h_code = uses_h.then(|| {
            quote! {
                let h = {
                    let e0 = j00 * j00 + j10 * j10;
                    let e1 = j01 * j01 + j11 * j11;
                    let (dx, dy) = (x[4] - x[2], x[5] - x[3]);
                    e0.max(e1).max(dx * dx + dy * dy).sqrt()
                };
            }
        });
        let k_code = uses_k.then(|| {
            quote! {
                let inv = 1.0 / det;
                let (k00, k01, k10, k11) = (j11 * inv, -j01 * inv, -j10 * inv, j00 * inv);
            }
        });
        // |det J| = 2·area; the reference triangle's weights sum to ½.
        quote! {
            let (j00, j01) = (x[2] - x[0], x[4] - x[0]);
            let (j10, j11) = (x[3] - x[1], x[5] - x[1]);
            let det = j00 * j11 - j01 * j10;
            let area2 = det.abs();
            #k_code
            #h_code
        }
    }

    fn exact_part(&self, block: &Block, symbols: &Symbols, terms: &[&Term]) -> ExactPart {
        // Every physical multi-index used, also by data terms, needs its T_αβ.
        let mut lets: Vec<TokenStream> = Vec::new();
        for alpha in alphas(block).into_iter().filter(|a| *a != [0, 0]) {
            for (beta, poly) in transform(alpha) {
                let ident = t_ident(alpha, beta);
                let value = k_polynomial_code(&poly);
                lets.push(quote!(let #ident: f64 = #value;));
            }
        }
        let mut pairs: Vec<Pair> = Vec::new();
        let mut quadrature_points = 0;
        for &term in terms {
            if let Some(degree) = term.quadrature_degree {
                quadrature_points = quadrature_points.max(rule_for_degree(degree).points.len());
            }
            self.add_term(term, block, symbols, &mut pairs);
        }
        if is_symmetric(block) {
            pairs = merge_transposed_pairs(pairs);
        }
        let mut tables = Vec::new();
        for (n, pair) in pairs.into_iter().enumerate() {
            let s = format_ident!("s{}", n);
            let parts = &pair.scalar;
            lets.push(quote!(let #s: f64 = area2 * (#(#parts)+*);));
            tables.push((s, pair.reference));
        }
        ExactPart {
            lets,
            tables,
            quadrature_points,
        }
    }

    fn points_const(&self, rule: &Rule) -> TokenStream {
        let nq = rule.len();
        let xi = rule.points.iter().map(|p| {
            let (a, b) = (float(p[0]), float(p[1]));
            quote!([#a, #b])
        });
        quote!(const XI: [[f64; 2]; #nq] = [#(#xi),*];)
    }

    fn physical_point(&self) -> TokenStream {
        quote! {
            let xq = [
                x[0] + j00 * XI[q][0] + j01 * XI[q][1],
                x[1] + j10 * XI[q][0] + j11 * XI[q][1],
            ];
        }
    }

    fn data_argument(&self) -> TokenStream {
        quote!(&xq)
    }

    fn weight_factor(&self) -> Option<TokenStream> {
        Some(quote!(area2))
    }

    fn data_term_coefficient(&self, term: &Term) -> TokenStream {
        coefficient(term.coefficient, &term.params, term.h_power, &term.divisors)
    }

    fn table_ident(&self, element: ElementKind, derivative: [u8; 2]) -> Ident {
        format_ident!(
            "PHI_{}_D{}{}",
            element.name().to_uppercase(),
            derivative[0],
            derivative[1]
        )
    }

    fn tabulate(&self, element: ElementKind, derivative: [u8; 2], rule: &Rule) -> Vec<Vec<f64>> {
        let basis = derivatives(element, derivative);
        rule.points
            .iter()
            .map(|x| basis.iter().map(|p| p.eval([x[0], x[1]])).collect())
            .collect()
    }

    /// `Σ_β T_αβ TABLE_β[q][index]`.
    fn basis_value(
        &self,
        element: ElementKind,
        derivative: [u8; 2],
        index: TokenStream,
        table: &mut dyn FnMut(ElementKind, [u8; 2]) -> Ident,
    ) -> TokenStream {
        let parts: Vec<TokenStream> = transform(derivative)
            .into_iter()
            .map(|(beta, _)| {
                let table = table(element, beta);
                match t_code(derivative, beta) {
                    Some(t) => quote!(#t * #table[q][#index]),
                    None => quote!(#table[q][#index]),
                }
            })
            .collect();
        quote!((#(#parts)+*))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn second_derivatives_transform_as_k_outer_k() {
        // ∂xx = (k00 ∂ξ + k10 ∂η)² = k00² ∂ξξ + 2 k00 k10 ∂ξη + k10² ∂ηη
        let t = transform([2, 0]);
        let find = |b: [u8; 2]| &t.iter().find(|(x, _)| *x == b).unwrap().1;
        assert_eq!(find([2, 0]), &vec![(1.0, [2, 0, 0, 0])]);
        assert_eq!(find([1, 1]), &vec![(2.0, [1, 0, 1, 0])]);
        assert_eq!(find([0, 2]), &vec![(1.0, [0, 0, 2, 0])]);
        assert_eq!(transform([0, 1]).len(), 2);
    }

    #[test]
    fn degree_one_is_the_centroid_rule() {
        let rule = Triangle.rule(1);
        assert_eq!(rule.points, [vec![1.0 / 3.0, 1.0 / 3.0]]);
        // exact for degree 1: ∫ ξ over the reference triangle is 1/6
        let integral: f64 = rule
            .points
            .iter()
            .zip(&rule.weights)
            .map(|(p, w)| w * p[0])
            .sum();
        assert!((integral - 1.0 / 6.0).abs() < 1e-16);
        assert!(Triangle.rule(2).len() > 1);
    }
}
