//! Kernel IR → Rust element kernels on affine triangles.
//!
//! On a triangle `x = x₀ + J ξ` with constant `J`, so a physical derivative `∂^α` is a
//! fixed combination `Σ_β T_αβ(K) ∂̂^β` of reference derivatives of the same order, with
//! `K = J⁻¹` (`∂/∂x_i = Σ_a K_ai ∂/∂ξ_a`). The kernels use the tensor representation:
//! - terms without data: the reference integrals `R_βγ[i][j] = ∫_T̂ ∂̂^β φ̂ᵢ ∂̂^γ ψ̂ⱼ` are
//!   computed here, at compile time, and emitted as literals; at run time the element
//!   computes one scalar `s_βγ = |det J| Σ_terms c T_αβ T_α'γ` per reference pair and
//!   each entry is `Σ s_βγ R_βγ[i][j]` over the pairs whose literal is non-zero;
//! - terms with data: a loop over a compile-time triangle rule with tabulated
//!   reference derivatives, the data evaluated once per point.

use crate::analysis::{Block, Symbols, Term};
use crate::codegen::{
    block_ident, coefficient, float, kernel_frame, literal_products, BlockCode, KernelFrame,
};
use fem_reference::triangle::{Polynomial2, TriangleRule};
use fem_reference::ElementKind;
use proc_macro2::TokenStream;
use quote::{format_ident, quote};

/// A monomial `c · k00^e0 · k01^e1 · k10^e2 · k11^e3` in the entries of `K = J⁻¹`.
type KMonomial = (f64, [u8; 4]);

/// `T_αβ` of one physical multi-index α: the reference multi-indices β with their
/// polynomials in K.
type Transform = Vec<([u8; 2], Vec<KMonomial>)>;

/// `T_αβ` for every reference multi-index β of the same order as α.
fn transform(alpha: [u8; 2]) -> Transform {
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
                        Some((_, p)) => {
                            for m in shifted {
                                match p.iter_mut().find(|(_, e)| *e == m.1) {
                                    Some(existing) => existing.0 += m.0,
                                    None => p.push(m),
                                }
                            }
                        }
                        None => next.push((b, shifted)),
                    }
                }
            }
            terms = next;
        }
    }
    terms
}

fn k_polynomial_code(poly: &[KMonomial]) -> TokenStream {
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
            let mut it = factors.into_iter();
            let first = it.next().expect("at least one factor");
            it.fold(first, |acc, f| quote!(#acc * #f))
        })
        .collect();
    quote!((#(#monomials)+*))
}

fn t_ident(alpha: [u8; 2], beta: [u8; 2]) -> proc_macro2::Ident {
    format_ident!("t_{}{}_{}{}", alpha[0], alpha[1], beta[0], beta[1])
}

/// The reference basis of `element` differentiated by `beta`.
fn derivatives(element: ElementKind, beta: [u8; 2]) -> Vec<Polynomial2> {
    element
        .triangle_basis()
        .iter()
        .map(|p| p.derivative(beta[0] as u32, beta[1] as u32))
        .collect()
}

fn factor_degree(element: ElementKind, derivative: [u8; 2]) -> usize {
    element
        .degree()
        .saturating_sub((derivative[0] + derivative[1]) as usize)
}

/// Quadrature degree that integrates the term exactly (or the explicit `∫[degree=N]`).
pub fn term_degree(term: &Term, block: &Block, symbols: &Symbols) -> usize {
    if let Some(d) = term.quadrature_degree {
        return d;
    }
    let element = |f: usize| symbols.fields[f].element;
    let mut degree = factor_degree(element(block.test_field), term.test_derivative);
    if let (Some(f), Some(d)) = (block.trial_field, term.trial_derivative) {
        degree += factor_degree(element(f), d);
    }
    degree + term.data.iter().map(|&i| symbols.data[i].1).sum::<usize>()
}

/// The element-kernel function of one block on triangles.
pub fn block_kernel(
    block: &Block,
    symbols: &Symbols,
    runtime: &TokenStream,
    form: &str,
) -> BlockCode {
    let test_element = symbols.fields[block.test_field].element;
    let trial_element = block.trial_field.map(|f| symbols.fields[f].element);
    let rows = test_element.triangle_basis().len();
    let cols = trial_element.map_or(1, |e| e.triangle_basis().len());
    let np = symbols.params.len();
    let nd = symbols.data.len();
    let name = block_ident(block, symbols);
    let mut quadrature_points = 0;

    // Every physical multi-index used needs its T_αβ.
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
    let transforms: Vec<([u8; 2], Transform)> = alphas.iter().map(|&a| (a, transform(a))).collect();
    let t_of = |alpha: [u8; 2]| &transforms.iter().find(|(a, _)| *a == alpha).unwrap().1;
    let t_lets: Vec<TokenStream> = transforms
        .iter()
        .filter(|(a, _)| *a != [0, 0])
        .flat_map(|(a, list)| {
            list.iter().map(move |(b, poly)| {
                let ident = t_ident(*a, *b);
                let value = k_polynomial_code(poly);
                quote!(let #ident: f64 = #value;)
            })
        })
        .collect();
    let t_code = |alpha: [u8; 2], beta: [u8; 2]| -> Option<TokenStream> {
        (alpha != [0, 0]).then(|| {
            let ident = t_ident(alpha, beta);
            quote!(#ident)
        })
    };

    // Constant-coefficient terms: reference pairs (β, γ) with their literal tables and
    // the run-time scalar contributions.
    struct Pair {
        beta: [u8; 2],
        gamma: Option<[u8; 2]>,
        reference: Vec<Vec<f64>>,
        scalar: Vec<TokenStream>,
    }
    let mut pairs: Vec<Pair> = Vec::new();
    let mut data_terms: Vec<&Term> = Vec::new();
    for term in &block.terms {
        if !term.data.is_empty() {
            data_terms.push(term);
            continue;
        }
        let rule = TriangleRule::exact_for_degree(term_degree(term, block, symbols));
        if term.quadrature_degree.is_some() {
            quadrature_points = quadrature_points.max(rule.points.len());
        }
        let c = coefficient(term.coefficient, &term.params, term.h_power);
        let trial_list: Vec<([u8; 2], Option<&Vec<KMonomial>>)> = match term.trial_derivative {
            Some(d) => t_of(d).iter().map(|(g, p)| (*g, Some(p))).collect(),
            None => vec![([0, 0], None)],
        };
        for (beta, _) in t_of(term.test_derivative) {
            for &(gamma, _) in &trial_list {
                let gamma_key = term.trial_derivative.map(|_| gamma);
                let index = match pairs
                    .iter()
                    .position(|p| p.beta == *beta && p.gamma == gamma_key)
                {
                    Some(i) => i,
                    None => {
                        let test_basis = derivatives(test_element, *beta);
                        let trial_basis = match (trial_element, gamma_key) {
                            (Some(e), Some(g)) => derivatives(e, g),
                            _ => vec![Polynomial2 {
                                terms: vec![(0, 0, 1.0)],
                            }],
                        };
                        let reference = test_basis
                            .iter()
                            .map(|p| {
                                trial_basis
                                    .iter()
                                    .map(|q| rule.integrate(|x| p.eval(x) * q.eval(x)))
                                    .collect()
                            })
                            .collect();
                        pairs.push(Pair {
                            beta: *beta,
                            gamma: gamma_key,
                            reference,
                            scalar: Vec::new(),
                        });
                        pairs.len() - 1
                    }
                };
                let mut factors = vec![c.clone()];
                factors.extend(t_code(term.test_derivative, *beta));
                if let Some(d) = term.trial_derivative {
                    factors.extend(t_code(d, gamma));
                }
                let mut it = factors.into_iter();
                let first = it.next().unwrap();
                pairs[index]
                    .scalar
                    .push(it.fold(first, |acc, f| quote!(#acc * #f)));
            }
        }
    }
    let scalar_lets: Vec<TokenStream> = pairs
        .iter()
        .enumerate()
        .map(|(n, pair)| {
            let s = format_ident!("s{}", n);
            let parts = &pair.scalar;
            quote!(let #s: f64 = area2 * (#(#parts)+*);)
        })
        .collect();

    // Quadrature loops for data terms, one per (data set, rule).
    let mut loops = Vec::new();
    let mut data_groups: Vec<(Vec<usize>, usize, Vec<&Term>)> = Vec::new();
    for term in data_terms {
        let degree = term_degree(term, block, symbols);
        match data_groups
            .iter_mut()
            .find(|(d, n, _)| *d == term.data && *n == degree)
        {
            Some(g) => g.2.push(term),
            None => data_groups.push((term.data.clone(), degree, vec![term])),
        }
    }
    for (data, degree, terms) in &data_groups {
        let rule = TriangleRule::exact_for_degree(*degree);
        let nq = rule.points.len();
        quadrature_points = quadrature_points.max(nq);
        let xi = rule.points.iter().map(|&[a, b]| {
            let (a, b) = (float(a), float(b));
            quote!([#a, #b])
        });
        let weights = rule.weights.iter().map(|&v| float(v));
        let mut tables = Vec::new();
        let mut tables_made: Vec<(ElementKind, [u8; 2])> = Vec::new();
        let mut table_ident =
            |element: ElementKind, beta: [u8; 2], tables: &mut Vec<TokenStream>| {
                let ident = format_ident!(
                    "PHI_{}_D{}{}",
                    element.name().to_uppercase(),
                    beta[0],
                    beta[1]
                );
                if !tables_made.contains(&(element, beta)) {
                    tables_made.push((element, beta));
                    let basis = derivatives(element, beta);
                    let n = basis.len();
                    let rows_code = rule.points.iter().map(|&x| {
                        let vals = basis.iter().map(|p| float(p.eval(x)));
                        quote!([#(#vals),*])
                    });
                    tables.push(quote! {
                        const #ident: [[f64; #n]; #nq] = [#(#rows_code),*];
                    });
                }
                ident
            };
        let data_product: TokenStream = {
            let mut it = data.iter().map(|&i| quote!(d[#i](&xq)));
            let first = it.next().expect("a data group has data");
            it.fold(first, |acc, f| quote!(#acc * #f))
        };
        // Physical derivative values of a basis at point q: Σ_β T_αβ TABLE_β[q][i].
        let mut value_code = |element: ElementKind,
                              alpha: [u8; 2],
                              index: TokenStream,
                              tables: &mut Vec<TokenStream>| {
            let parts: Vec<TokenStream> = t_of(alpha)
                .iter()
                .map(|(beta, _)| {
                    let table = table_ident(element, *beta, tables);
                    match t_code(alpha, *beta) {
                        Some(t) => quote!(#t * #table[q][#index]),
                        None => quote!(#table[q][#index]),
                    }
                })
                .collect();
            quote!((#(#parts)+*))
        };
        let mut body = Vec::new();
        for term in terms {
            let c = coefficient(term.coefficient, &term.params, term.h_power);
            let test = value_code(test_element, term.test_derivative, quote!(i), &mut tables);
            let accumulate = match (trial_element, term.trial_derivative) {
                (Some(e), Some(dv)) => {
                    let trial = value_code(e, dv, quote!(j), &mut tables);
                    quote! {
                        for i in 0..#rows {
                            let a = g * #test;
                            for j in 0..#cols {
                                k[i][j] += a * #trial;
                            }
                        }
                    }
                }
                _ => quote! {
                    for i in 0..#rows {
                        k[i][0] += g * #test;
                    }
                },
            };
            body.push(quote! {
                let g = w * (#c);
                #accumulate
            });
        }
        loops.push(quote! {
            {
                const XI: [[f64; 2]; #nq] = [#(#xi),*];
                const W: [f64; #nq] = [#(#weights),*];
                #(#tables)*
                for q in 0..#nq {
                    let xq = [
                        x[0] + j00 * XI[q][0] + j01 * XI[q][1],
                        x[1] + j10 * XI[q][0] + j11 * XI[q][1],
                    ];
                    let w = W[q] * area2 * #data_product;
                    #(#body)*
                }
            }
        });
    }

    // Entries: data part + Σ s_n R_n[i][j] over non-zero literals.
    let has_data = !loops.is_empty();
    let tables: Vec<(proc_macro2::Ident, &Vec<Vec<f64>>)> = pairs
        .iter()
        .enumerate()
        .map(|(n, pair)| (format_ident!("s{}", n), &pair.reference))
        .collect();
    let mut entries = Vec::new();
    for i in 0..rows {
        for j in 0..cols {
            let sum = literal_products(&tables, i, j);
            let value = match (has_data, sum.is_empty()) {
                (_, true) => continue,
                (false, false) => quote!(#(#sum)+*),
                (true, false) => quote!(k[#i][#j] + #(#sum)+*),
            };
            entries.push(quote!(k[#i][#j] = #value;));
        }
    }

    let KernelFrame {
        doc_title,
        doc_terms,
        signature_out,
        ret,
    } = kernel_frame(block, symbols, form, " on triangles", rows, cols);
    // Only what the terms use: h (a sqrt) and K (a division) are skipped otherwise.
    let uses_h = block.terms.iter().any(|t| t.h_power != 0);
    let uses_k = alphas.iter().any(|a| *a != [0, 0]);
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
    let function = quote! {
        #[doc = #doc_title]
        #[doc = #doc_terms]
        #[inline]
        #[allow(unused_variables, unused_mut, clippy::all)]
        pub fn #name(x: &[f64; 6], p: &[f64; #np], d: &[&#runtime::DataFn; #nd]) -> #signature_out {
            let (j00, j01) = (x[2] - x[0], x[4] - x[0]);
            let (j10, j11) = (x[3] - x[1], x[5] - x[1]);
            let det = j00 * j11 - j01 * j10;
            // |det J| = 2·area; the reference triangle's weights sum to ½
            let area2 = det.abs();
            #k_code
            #h_code
            #(#t_lets)*
            #(#scalar_lets)*
            let mut k = [[0.0f64; #cols]; #rows];
            #(#loops)*
            #(#entries)*
            #ret
        }
    };
    BlockCode {
        function,
        quadrature_points,
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
}
