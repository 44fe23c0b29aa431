//! Kernels on curved (six-node, isoparametric) triangles, next to the affine ones of
//! `triangle.rs` (docs/mathematics.md §8).
//!
//! A curved cell is the image of the reference triangle under the quadratic map
//! `x(ξ) = Σₙ xₙ Nₙ(ξ)` of its six nodes (vertices 0, 1, 2, then the nodes of the edges
//! 0–1, 1–2, 2–0: the P2 Lagrange basis in its local order). `J(ξ)` varies over the cell,
//! so no term has a constant coefficient and there is no tensor representation: every
//! term of a block is integrated by a quadrature loop that, per point, builds `J(ξ_q)`
//! from compile-time tables of `∇̂Nₙ(ξ_q)`, takes `|det J|`, `K = J⁻¹` and the
//! physical derivatives of the reference basis (compile-time tables of `∂̂^β φ̂ᵢ(ξ_q)`),
//! and evaluates data at the mapped point `x(ξ_q)`. No allocation.
//!
//! Choices, stated here and in docs/forms.md:
//! - `h_T` is the diameter of the cell's three vertices (as on the affine cell: the
//!   curved edge changes the diameter by O(h²) relative, which a weight `h^k` does not
//!   need).
//! - Quadrature: a term's rule is exact for its affine degree (basis degrees lowered by
//!   the derivative orders, data with their declared degree) plus the data degrees once
//!   more (`f(x(ξ))` of a polynomial `f` of degree `k` has degree `2k` in ξ) plus
//!   [`EXTRA_DEGREE`] = 2 for the map. A term without derivatives then is exact
//!   (`det J` has degree 2); with derivatives the integrand is rational (`K = adj J /
//!   det J`) and no rule is exact: +2 makes the error of the rule O(h^{p+3}) relative
//!   on a cell curved by O(h²), below the isoparametric discretization error. An
//!   explicit `∫[degree=N]` keeps its rule (the user chose it, e.g. reduced
//!   integration).
//! - Second derivatives are exact: `∂²φ = Kᵀ (∂̂²φ̂ − Σ_r (∂_r φ) ∂̂²x_r) K`, where the
//!   Hessians `∂̂²x_r` of the quadratic map are constant over the cell. Terms the
//!   analysis dropped because the reference second derivatives vanish (P1 rotations:
//!   `div div Cε(θ_h)`) stay dropped — on a curved cell `div div Cε(θ_h)` is O(h) small
//!   but not zero; docs/mathematics.md §8 states it. Derivatives of order ≥ 3 and
//!   elements with a per-cell DOF transformation (Argyris, Morley) get no curved kernel:
//!   the dispatch returns an error naming the form and block.

use super::backend::CellBackend;
use super::emit::{block_ident, coefficient, float, is_transformed, product};
use super::triangle::{
    derivatives, k_polynomial_code, rule_for_degree, t_code, t_ident, transform, Triangle,
};
use crate::analysis::{Block, Symbols, Term};
use fem_reference::ElementKind;
use proc_macro2::{Ident, TokenStream};
use quote::{format_ident, quote};

/// Quadrature degree added for the curved map (see the module docs).
pub const EXTRA_DEGREE: usize = 2;

/// Degree of the rule of `term` on a curved cell (module docs).
fn curved_degree(term: &Term, block: &Block, symbols: &Symbols) -> usize {
    if let Some(d) = term.quadrature_degree {
        return d;
    }
    let data: usize = term.data.iter().map(|&i| symbols.data[i].1).sum();
    Triangle.term_degree(term, block, symbols) + data + EXTRA_DEGREE
}

/// Total derivative order of a multi-index.
fn order(alpha: [u8; 2]) -> u8 {
    alpha[0] + alpha[1]
}

/// The largest derivative order of a block's terms.
fn block_order(block: &Block) -> u8 {
    block
        .terms
        .iter()
        .flat_map(|t| [Some(t.test_derivative), t.trial_derivative])
        .flatten()
        .map(order)
        .max()
        .unwrap_or(0)
}

/// The name of a block's curved kernel: `matrix_v_u_curved`.
pub fn curved_ident(block: &Block, symbols: &Symbols) -> Ident {
    format_ident!("{}_curved", block_ident(block, symbols))
}

/// Why a block gets no curved kernel, if it gets none.
pub fn refusal(block: &Block, symbols: &Symbols) -> Option<String> {
    if is_transformed(block, symbols) {
        return Some(
            "its element needs a per-cell DOF transformation (Argyris, Morley), which is defined on affine cells only".to_string(),
        );
    }
    let k = block_order(block);
    (k > 2)
        .then(|| format!("it takes derivatives of order {k}; curved cells support orders up to 2"))
}

/// `Σ_n x[2n + r] · TABLE[q][n]` for coordinate `r` of the map.
fn map_sum(table: &Ident, r: usize) -> TokenStream {
    let parts = (0..6).map(|n| {
        let i = 2 * n + r;
        quote!(x[#i] * #table[q][#n])
    });
    quote!((#(#parts)+*))
}

/// The constant reference Hessians of the map's coordinates, `mx_β`, `my_β` for
/// β ∈ {20, 11, 02}: `Σ_n x_n ∂̂^β N_n` (the shape functions are quadratic).
fn map_hessians() -> TokenStream {
    let mut lets = Vec::new();
    for beta in [[2u8, 0], [1, 1], [0, 2]] {
        let values: Vec<f64> = derivatives(ElementKind::P2, beta)
            .iter()
            .map(|p| p.eval([0.0, 0.0]))
            .collect();
        for (r, axis) in ["x", "y"].iter().enumerate() {
            let ident = format_ident!("m{}_{}{}", axis, beta[0], beta[1]);
            let parts = values
                .iter()
                .enumerate()
                .filter(|(_, v)| **v != 0.0)
                .map(|(n, &v)| {
                    let i = 2 * n + r;
                    let v = float(v);
                    quote!(#v * x[#i])
                });
            lets.push(quote!(let #ident: f64 = #(#parts)+*;));
        }
    }
    quote!(#(#lets)*)
}

/// The physical `alpha` derivative of basis function `index` of `element` at point `q`.
fn basis_value(
    element: ElementKind,
    alpha: [u8; 2],
    index: TokenStream,
    table: &mut dyn FnMut(ElementKind, [u8; 2]) -> Ident,
) -> TokenStream {
    if alpha == [0, 0] {
        let t = table(element, alpha);
        return quote!(#t[q][#index]);
    }
    let correction = (order(alpha) == 2).then(|| {
        // ∂̂²φ̂ − Σ_r (∂_r φ) ∂̂²x_r, with ∂_x = k00 ∂̂ξ + k10 ∂̂η, ∂_y = k01 ∂̂ξ + k11 ∂̂η
        let (d10, d01) = (table(element, [1, 0]), table(element, [0, 1]));
        quote! {
            let gx = k00 * #d10[q][#index] + k10 * #d01[q][#index];
            let gy = k01 * #d10[q][#index] + k11 * #d01[q][#index];
        }
    });
    let parts: Vec<TokenStream> = transform(alpha)
        .into_iter()
        .map(|(beta, _)| {
            let t = table(element, beta);
            let reference = if correction.is_some() {
                let (mx, my) = (
                    format_ident!("mx_{}{}", beta[0], beta[1]),
                    format_ident!("my_{}{}", beta[0], beta[1]),
                );
                quote!((#t[q][#index] - gx * #mx - gy * #my))
            } else {
                quote!(#t[q][#index])
            };
            match t_code(alpha, beta) {
                Some(t) => quote!(#t * #reference),
                None => reference,
            }
        })
        .collect();
    quote!({ #correction #(#parts)+* })
}

/// One loop over the points of the rule of `degree` for `terms` (which share `data`).
fn curved_loop(
    block: &Block,
    symbols: &Symbols,
    data: &[usize],
    degree: usize,
    terms: &[&Term],
    dofs: (usize, usize),
) -> TokenStream {
    let rule = rule_for_degree(degree);
    let nq = rule.points.len();
    let (rows, cols) = dofs;
    let test_element = symbols.fields[block.test_field].element;
    let trial_element = block.trial_field.map(|f| symbols.fields[f].element);
    let mut tables: Vec<TokenStream> = Vec::new();
    let mut made: Vec<(ElementKind, [u8; 2])> = Vec::new();
    let mut table = |element: ElementKind, derivative: [u8; 2]| -> Ident {
        let ident = format_ident!(
            "PHI_{}_D{}{}",
            element.name().to_uppercase(),
            derivative[0],
            derivative[1]
        );
        if !made.contains(&(element, derivative)) {
            made.push((element, derivative));
            let basis = derivatives(element, derivative);
            let n = basis.len();
            let rows_code = rule.points.iter().map(|&x| {
                let values = basis.iter().map(|p| float(p.eval(x)));
                quote!([#(#values),*])
            });
            tables.push(quote! {
                const #ident: [[f64; #n]; #nq] = [#(#rows_code),*];
            });
        }
        ident
    };
    // The map's shape functions are the P2 basis: their tables serve the geometry.
    let (n10, n01) = (
        table(ElementKind::P2, [1, 0]),
        table(ElementKind::P2, [0, 1]),
    );
    let (j00, j01, j10, j11) = (
        map_sum(&n10, 0),
        map_sum(&n01, 0),
        map_sum(&n10, 1),
        map_sum(&n01, 1),
    );
    let point = (!data.is_empty()).then(|| {
        let n00 = table(ElementKind::P2, [0, 0]);
        let (px, py) = (map_sum(&n00, 0), map_sum(&n00, 1));
        quote!(let xq = [#px, #py];)
    });
    let mut alphas: Vec<[u8; 2]> = Vec::new();
    for t in terms {
        for a in [Some(t.test_derivative), t.trial_derivative]
            .into_iter()
            .flatten()
        {
            if a != [0, 0] && !alphas.contains(&a) {
                alphas.push(a);
            }
        }
    }
    alphas.sort();
    let inverse = (!alphas.is_empty()).then(|| {
        quote! {
            let inv = 1.0 / det;
            let (k00, k01, k10, k11) = (j11 * inv, -j01 * inv, -j10 * inv, j00 * inv);
        }
    });
    let transforms = alphas.iter().flat_map(|&alpha| {
        transform(alpha).into_iter().map(move |(beta, poly)| {
            let ident = t_ident(alpha, beta);
            let value = k_polynomial_code(&poly);
            quote!(let #ident: f64 = #value;)
        })
    });
    let transforms: Vec<TokenStream> = transforms.collect();
    let mut body = Vec::new();
    for term in terms {
        let c = coefficient(term.coefficient, &term.params, term.h_power, &term.divisors);
        let test = basis_value(test_element, term.test_derivative, quote!(i), &mut table);
        let accumulate = match (trial_element, term.trial_derivative) {
            (Some(e), Some(dv)) => {
                let trial = basis_value(e, dv, quote!(j), &mut table);
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
    let data_product = (!data.is_empty()).then(|| {
        let factors = product(data.iter().map(|&i| quote!(d[#i](&xq))));
        quote!(* #factors)
    });
    let weights = rule.weights.iter().map(|&v| float(v));
    quote! {
        {
            const W: [f64; #nq] = [#(#weights),*];
            #(#tables)*
            for q in 0..#nq {
                let (j00, j01, j10, j11) = (#j00, #j01, #j10, #j11);
                let det = j00 * j11 - j01 * j10;
                let area2 = det.abs();
                #inverse
                #(#transforms)*
                #point
                let w = W[q] * area2 #data_product;
                #(#body)*
            }
        }
    }
}

/// The curved kernel of a block (call [`refusal`] first: this assumes there is none),
/// and the largest number of points of its loops.
pub fn curved_kernel(
    block: &Block,
    symbols: &Symbols,
    runtime: &TokenStream,
    form: &str,
) -> TokenStream {
    let mut groups: Vec<(&[usize], usize, Vec<&Term>)> = Vec::new();
    for term in &block.terms {
        let degree = curved_degree(term, block, symbols);
        match groups
            .iter_mut()
            .find(|(d, r, _)| *d == term.data.as_slice() && *r == degree)
        {
            Some(g) => g.2.push(term),
            None => groups.push((&term.data, degree, vec![term])),
        }
    }
    let rows = Triangle.dof_count(symbols.fields[block.test_field].element);
    let cols = block
        .trial_field
        .map_or(1, |f| Triangle.dof_count(symbols.fields[f].element));
    let loops: Vec<TokenStream> = groups
        .iter()
        .map(|(data, degree, terms)| {
            curved_loop(block, symbols, data, *degree, terms, (rows, cols))
        })
        .collect();
    let uses_h = block.terms.iter().any(|t| {
        t.h_power != 0
            || t.divisors
                .iter()
                .any(|(d, _)| d.terms.iter().any(|x| x.h_power != 0))
    });
    let h_code = uses_h.then(|| {
        quote! {
            let h = {
                let (ax, ay) = (x[2] - x[0], x[3] - x[1]);
                let (bx, by) = (x[4] - x[0], x[5] - x[1]);
                let (cx, cy) = (x[4] - x[2], x[5] - x[3]);
                (ax * ax + ay * ay).max(bx * bx + by * by).max(cx * cx + cy * cy).sqrt()
            };
        }
    });
    let hessians = (block_order(block) == 2).then(map_hessians);
    let name = curved_ident(block, symbols);
    let test = &symbols.fields[block.test_field].test_name;
    let doc = match block.trial_field {
        Some(f) => format!(
            " Block ({test}, {}) of `{form}` on a curved (six-node) triangle: `x` holds the six nodes (vertices, then the nodes of the edges 0–1, 1–2, 2–0), `J` per quadrature point (docs/mathematics.md §8).",
            symbols.fields[f].name
        ),
        None => format!(
            " Block {test} of `{form}` on a curved (six-node) triangle: `x` holds the six nodes (vertices, then the nodes of the edges 0–1, 1–2, 2–0), `J` per quadrature point (docs/mathematics.md §8)."
        ),
    };
    let np = symbols.params.len();
    let nd = symbols.data.len();
    let (signature_out, ret) = if block.trial_field.is_some() {
        (quote!([[f64; #cols]; #rows]), quote!(k))
    } else {
        let items = (0..rows).map(|i| quote!(k[#i][0]));
        (quote!([f64; #rows]), quote!([#(#items),*]))
    };
    quote! {
        #[doc = #doc]
        #[inline]
        #[allow(unused_variables, unused_mut, clippy::all)]
        pub fn #name(x: &[f64; 12], p: &[f64; #np], d: &[&#runtime::DataFn; #nd]) -> #signature_out {
            #h_code
            #hessians
            let mut k = [[0.0f64; #cols]; #rows];
            #(#loops)*
            #ret
        }
    }
}
