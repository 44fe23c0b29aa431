//! The interval backend: kernels on `[x₀, x₁]`, `h = x₁ − x₀`, reference cell `[0, 1]`.
//!
//! Constant-coefficient terms: the reference integrals `∫₀¹ φ̂ᵢ⁽ᵏ⁾ φ̂ⱼ⁽ˡ⁾` are computed
//! at compile time, grouped by the hoisted run-time coefficient `c = κ(params) ·
//! h^{1−k−l}`, so an entry is a handful of multiply-adds. Data terms go through the
//! shared quadrature loops with Gauss–Legendre rules. Hermite slope DOFs are scaled by
//! `h` (see `ElementKind::dof_scaling_power`).

use super::backend::{CellBackend, ExactPart, Rule};
use super::emit::{coefficient, float};
use crate::analysis::{Block, Symbols, Term};
use crate::symbolic::Divisor;
use fem_reference::{ElementKind, Polynomial, QuadratureRule};
use proc_macro2::{Ident, TokenStream};
use quote::{format_ident, quote};

/// Kernels on intervals.
pub struct Interval;

/// The basis of `element` differentiated `derivative` times.
fn derivatives(element: ElementKind, derivative: u8) -> Vec<Polynomial> {
    element
        .basis()
        .iter()
        .map(|p| p.derivative(derivative as usize))
        .collect()
}

/// `∫₀¹ p q dξ`, summed from the coefficients.
fn integral_of_product(p: &Polynomial, q: &Polynomial) -> f64 {
    let mut sum = 0.0;
    for (k, a) in p.coefficients.iter().enumerate() {
        for (l, b) in q.coefficients.iter().enumerate() {
            sum += a * b / (k + l + 1) as f64;
        }
    }
    sum
}

/// Power of `h` a term's reference integral is multiplied by: the term's own power,
/// `+1` from `dx = h dξ`, `−k` per derivative from `d/dx = h⁻¹ d/dξ`.
fn h_power(term: &Term) -> i32 {
    term.h_power + 1
        - term.test_derivative[0] as i32
        - term.trial_derivative.map_or(0, |d| d[0]) as i32
}

fn gauss_rule(rule: QuadratureRule) -> Rule {
    Rule {
        points: rule.points.iter().map(|&x| vec![x]).collect(),
        weights: rule.weights,
    }
}

/// Terms with the same run-time coefficient share one table of reference integrals.
struct Group {
    params: Vec<(usize, i32)>,
    h_power: i32,
    divisors: Vec<(Divisor, i32)>,
    reference: Vec<Vec<f64>>,
}

impl Interval {
    /// `∫₀¹ D^k φ̂ᵢ D^l ψ̂ⱼ` of one term times its coefficient, added into `reference`:
    /// exactly from the polynomial coefficients, or with the explicit rule as given
    /// (reduced integration is the point of `∫[degree=N]`).
    fn add_reference_integrals(
        &self,
        term: &Term,
        block: &Block,
        symbols: &Symbols,
        reference: &mut [Vec<f64>],
    ) {
        let test_element = symbols.fields[block.test_field].element;
        let trial_element = block.trial_field.map(|f| symbols.fields[f].element);
        let test_basis = derivatives(test_element, term.test_derivative[0]);
        let trial_basis = match (trial_element, term.trial_derivative) {
            (Some(e), Some(d)) => derivatives(e, d[0]),
            _ => vec![Polynomial::constant(1.0)],
        };
        if let Some(degree) = term.quadrature_degree {
            let rule = QuadratureRule::exact_for_degree(degree);
            for (&xi, w) in rule.points.iter().zip(&rule.weights) {
                for (row, p) in reference.iter_mut().zip(&test_basis) {
                    let test_value = p.eval(xi);
                    for (entry, q) in row.iter_mut().zip(&trial_basis) {
                        *entry += term.coefficient * w * test_value * q.eval(xi);
                    }
                }
            }
        } else {
            for (row, p) in reference.iter_mut().zip(&test_basis) {
                for (entry, q) in row.iter_mut().zip(&trial_basis) {
                    *entry += term.coefficient * integral_of_product(p, q);
                }
            }
        }
    }
}

impl CellBackend for Interval {
    fn cell_variant(&self) -> &'static str {
        "Interval"
    }

    fn coordinates(&self) -> usize {
        2
    }

    fn coordinates_message(&self) -> &'static str {
        "an interval has two vertex coordinates"
    }

    fn doc_suffix(&self) -> &'static str {
        ""
    }

    fn dof_count(&self, element: ElementKind) -> usize {
        element.dof_count()
    }

    fn dof_scaling(&self, element: ElementKind, index: usize) -> i32 {
        element.dof_scaling_power(index)
    }

    fn rule(&self, degree: usize) -> Rule {
        gauss_rule(QuadratureRule::exact_for_degree(degree))
    }

    fn geometry(&self, _block: &Block) -> TokenStream {
        quote!(let h = x[1] - x[0];)
    }

    fn exact_part(&self, block: &Block, symbols: &Symbols, terms: &[&Term]) -> ExactPart {
        let rows = self.dof_count(symbols.fields[block.test_field].element);
        let cols = block
            .trial_field
            .map_or(1, |f| self.dof_count(symbols.fields[f].element));
        let mut groups: Vec<Group> = Vec::new();
        let mut quadrature_points = 0;
        for &term in terms {
            if let Some(degree) = term.quadrature_degree {
                quadrature_points =
                    quadrature_points.max(QuadratureRule::exact_for_degree(degree).len());
            }
            let h_power = h_power(term);
            let index = match groups.iter().position(|g| {
                g.params == term.params && g.h_power == h_power && g.divisors == term.divisors
            }) {
                Some(i) => i,
                None => {
                    groups.push(Group {
                        params: term.params.clone(),
                        h_power,
                        divisors: term.divisors.clone(),
                        reference: vec![vec![0.0; cols]; rows],
                    });
                    groups.len() - 1
                }
            };
            self.add_reference_integrals(term, block, symbols, &mut groups[index].reference);
        }
        let mut lets = Vec::new();
        let mut tables = Vec::new();
        for (g, group) in groups.into_iter().enumerate() {
            let c = format_ident!("c{}", g);
            let value = coefficient(1.0, &group.params, group.h_power, &group.divisors);
            lets.push(quote!(let #c: f64 = #value;));
            tables.push((c, group.reference));
        }
        ExactPart {
            lets,
            tables,
            quadrature_points,
        }
    }

    fn points_const(&self, rule: &Rule) -> TokenStream {
        let nq = rule.len();
        let xi = rule.points.iter().map(|p| float(p[0]));
        quote!(const XI: [f64; #nq] = [#(#xi),*];)
    }

    fn physical_point(&self) -> TokenStream {
        quote!(let xq = x[0] + h * XI[q];)
    }

    fn data_argument(&self) -> TokenStream {
        quote!(&[xq])
    }

    fn weight_factor(&self) -> Option<TokenStream> {
        None
    }

    fn data_term_coefficient(&self, term: &Term) -> TokenStream {
        coefficient(
            term.coefficient,
            &term.params,
            h_power(term),
            &term.divisors,
        )
    }

    fn table_ident(&self, element: ElementKind, derivative: [u8; 2]) -> Ident {
        format_ident!("PHI_{}_D{}", element.name().to_uppercase(), derivative[0])
    }

    fn tabulate(&self, element: ElementKind, derivative: [u8; 2], rule: &Rule) -> Vec<Vec<f64>> {
        let basis = derivatives(element, derivative[0]);
        rule.points
            .iter()
            .map(|xi| basis.iter().map(|p| p.eval(xi[0])).collect())
            .collect()
    }

    fn basis_value(
        &self,
        element: ElementKind,
        derivative: [u8; 2],
        index: TokenStream,
        table: &mut dyn FnMut(ElementKind, [u8; 2]) -> Ident,
    ) -> TokenStream {
        let table = table(element, derivative);
        quote!(#table[q][#index])
    }
}
