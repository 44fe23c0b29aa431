//! Indicator kernels of a declared estimator on intervals.
//!
//! `estimator::cell(x, c, p, d)` returns a cell's `η_T²`: each term's residual
//! `R = Σ c·u⁽ᵏ⁾ + data` is evaluated at the Gauss–Legendre points of a rule exact for
//! `R²` (data counted with their declared degree) from compile-time tables of the
//! reference basis derivatives, `u⁽ᵏ⁾ = h⁻ᵏ Σ_i c_i φ̂_i⁽ᵏ⁾(ξ)` (the coefficients in the
//! reference basis: Hermite slopes times `h`), and `weight · Σ_q w_q R(ξ_q)² h` is summed.
//! `estimator::edge(x, end, c, y, other, e, p, d)` returns the squared indicator of an
//! interior node: the node is end `end` (0: left, 1: right) of the cell `x` (the `+`
//! side, whose outward normal is `n = ±1`) and end `other` of its neighbour `y`; a
//! point's "norm" is the value of the jump `X⁺ − X⁻` there, and `h` the mean of the two
//! cells' lengths in the weight, each side's length inside the jump (`../shared/MODELS.md` §8, Euler–Bernoulli). Neither allocates.

use super::emit::{float, product};
use super::estimator::{
    averaged_data, cell_rule_degree, data_product, monomial_coefficient, weight_code,
};
use crate::analysis::Symbols;
use crate::estimator::{Estimator, IndicatorTerm, Region};
use fem_reference::ElementKind;
use proc_macro2::TokenStream;
use quote::{format_ident, quote};

/// Compile-time tables of reference basis derivatives, made on demand.
#[derive(Default)]
struct Tables {
    items: Vec<TokenStream>,
    made: Vec<(ElementKind, u8, &'static str)>,
}

impl Tables {
    /// The table of `element`'s `k`-th derivatives at `points` (a row per point), named
    /// with `tag`.
    fn get(
        &mut self,
        element: ElementKind,
        k: u8,
        tag: &'static str,
        points: &[f64],
    ) -> TokenStream {
        let ident = format_ident!("PHI{}_{}_D{}", tag, element.name().to_uppercase(), k);
        if !self.made.contains(&(element, k, tag)) {
            self.made.push((element, k, tag));
            let basis: Vec<_> = element
                .basis()
                .iter()
                .map(|p| p.derivative(k as usize))
                .collect();
            let (n, nq) = (basis.len(), points.len());
            let rows = points.iter().map(|&x| {
                let v = basis.iter().map(|p| float(p.eval(x)));
                quote!([#(#v),*])
            });
            self.items
                .push(quote!(const #ident: [[f64; #n]; #nq] = [#(#rows),*];));
        }
        quote!(#ident)
    }
}

/// `h⁻ᵏ Σ_i c[i] φ̂_i⁽ᵏ⁾` at row `row` of `table`, with `hinv` the cell's `1/h`.
fn field_value(
    element: ElementKind,
    k: u8,
    coefficients: TokenStream,
    table: TokenStream,
    row: TokenStream,
    hinv: TokenStream,
) -> TokenStream {
    let n = element.basis().len();
    let scale = (0..k).map(|_| hinv.clone());
    quote!({
        let c = #coefficients;
        let mut v = 0.0f64;
        for i in 0..#n {
            v += c[i] * #table[#row][i];
        }
        v #(* #scale)*
    })
}

/// The loop of one cell term: `weight · Σ_q w_q R(ξ_q)² h` added to `eta2`.
fn cell_term(term: &IndicatorTerm, symbols: &Symbols) -> TokenStream {
    let rule = fem_reference::quadrature::QuadratureRule::exact_for_degree(cell_rule_degree(
        term, symbols,
    ));
    let nq = rule.len();
    let mut tables = Tables::default();
    let mut body = Vec::new();
    for m in &term.residual {
        let c = monomial_coefficient(m);
        let data = data_product(m);
        let value = m.args.first().map(|a| {
            let element = symbols.fields[a.symbol].element;
            let field = a.symbol;
            let k = a.derivative[0];
            let table = tables.get(element, k, "", &rule.points);
            field_value(
                element,
                k,
                quote!(c[#field]),
                table,
                quote!(q),
                quote!(hinv),
            )
        });
        let p = product(std::iter::once(c).chain(data).chain(value));
        body.push(quote!(r += #p;));
    }
    let weights = rule.weights.iter().map(|&w| float(w));
    let xi = rule.points.iter().map(|&x| float(x));
    let uses_data = term.residual.iter().any(|m| !m.data.is_empty());
    let point = uses_data.then(|| quote!(let xq = [x[0] + h * XI[q]];));
    let weight = weight_code(&term.weight);
    let items = &tables.items;
    let doc = &term.source;
    quote! {
        {
            #[doc = #doc]
            const XI: [f64; #nq] = [#(#xi),*];
            const W: [f64; #nq] = [#(#weights),*];
            #(#items)*
            let mut s = 0.0f64;
            for q in 0..#nq {
                #point
                let mut r = 0.0f64;
                #(#body)*
                s += W[q] * r * r;
            }
            eta2 += #weight * s * h;
        }
    }
}

/// One node term: `weight · [[X]]²` added to `eta2`.
fn node_term(term: &IndicatorTerm, symbols: &Symbols) -> TokenStream {
    let mut tables = Tables::default();
    let ends = [0.0, 1.0];
    let mut body = Vec::new();
    for m in &term.residual {
        let Some(a) = m.args.first() else {
            body.push(averaged_data(m));
            continue;
        };
        let c = monomial_coefficient(m);
        let data = data_product(m);
        let element = symbols.fields[a.symbol].element;
        let field = a.symbol;
        let k = a.derivative[0];
        let table = tables.get(element, k, "_END", &ends);
        let plus = field_value(
            element,
            k,
            quote!(c[#field]),
            table.clone(),
            quote!(end),
            quote!(hinv_p),
        );
        let minus = field_value(
            element,
            k,
            quote!(e[#field]),
            table,
            quote!(other),
            quote!(hinv_m),
        );
        // inside a jump or an average `h` is each side's length
        let jump = if term.average {
            quote!((0.5 * ({ let h = h_p; #c } * #plus + { let h = h_m; #c } * #minus)))
        } else {
            quote!(({ let h = h_p; #c } * #plus - { let h = h_m; #c } * #minus))
        };
        let p = product(data.into_iter().chain(std::iter::once(jump)));
        body.push(quote!(r += #p;));
    }
    squared(term, &tables, &body)
}

/// A point term's code: its tables, `r = Σ body`, and `weight · r²` added to `eta2`.
fn squared(term: &IndicatorTerm, tables: &Tables, body: &[TokenStream]) -> TokenStream {
    let weight = weight_code(&term.weight);
    let items = &tables.items;
    let doc = &term.source;
    quote! {
        {
            #[doc = #doc]
            #(#items)*
            let mut r = 0.0f64;
            #(#body)*
            eta2 += #weight * r * r;
        }
    }
}

/// One natural end term: `weight · X²` added to `eta2`, `X` the node term's quantity at
/// end `end` of the one cell `x` (`h` its length), where the boundary condition says
/// the flux vanishes.
fn end_term(term: &IndicatorTerm, symbols: &Symbols) -> TokenStream {
    let mut tables = Tables::default();
    let ends = [0.0, 1.0];
    let mut body = Vec::new();
    for m in &term.residual {
        let Some(a) = m.args.first() else { continue };
        let c = monomial_coefficient(m);
        let data = data_product(m);
        let element = symbols.fields[a.symbol].element;
        let field = a.symbol;
        let k = a.derivative[0];
        let table = tables.get(element, k, "_END", &ends);
        let value = field_value(
            element,
            k,
            quote!(c[#field]),
            table,
            quote!(end),
            quote!(hinv),
        );
        let p = product(std::iter::once(c).chain(data).chain(std::iter::once(value)));
        body.push(quote!(r += #p;));
    }
    squared(term, &tables, &body)
}

/// The module `estimator` of an interval model with an `estimator:` text: the kernels
/// `cell` and `edge` (an interior node).
pub fn module(estimator: &Estimator, symbols: &Symbols, runtime: &TokenStream) -> TokenStream {
    let nf = symbols.fields.len();
    let np = symbols.params.len();
    let nd = symbols.data.len();
    let cell_terms: Vec<TokenStream> = estimator
        .terms(Region::Cell)
        .map(|t| cell_term(t, symbols))
        .collect();
    let node_terms: Vec<TokenStream> = estimator
        .terms(Region::Edge)
        .map(|t| node_term(t, symbols))
        .collect();
    let natural: Vec<TokenStream> = (0..estimator.natural.len())
        .map(|k| {
            let terms = estimator
                .terms(Region::Natural(k))
                .map(|t| end_term(t, symbols));
            quote!(#k => { #(#terms)* })
        })
        .collect();
    let describe = |region: Region| match estimator
        .terms(region)
        .map(|t| format!("`{}`", t.source))
        .collect::<Vec<_>>()
        .join(" + ")
    {
        s if s.is_empty() => "no such term (0)".to_string(),
        s => s,
    };
    let cell_doc = format!(
        " The squared indicator `η_T²` of the interval `x` (`[x0, x1]`) for the coefficients `c`: one slice per field, the cell's coefficients in the reference basis (Hermite slopes times the cell's length): {}.",
        describe(Region::Cell)
    );
    let node_doc = format!(
        " The squared indicator of the interior node that is end `end` (0: left, 1: right) of the interval `x` with coefficients `c` and end `other` of its neighbour `y` with coefficients `e`: the jump `X⁺ − X⁻` of each term at the node squared, `n = ±1` the outward normal of `x` there, `h` the mean of the two cells' lengths: {}.",
        describe(Region::Edge)
    );
    let boundary_doc = format!(
        " The natural boundary term `k` at end `end` (0: left, 1: right) of the interval `x` (the mesh's first or last cell) with coefficients `c`: the node term of that flux with the one side, `n = ±1` the outward normal, `h` the cell's length: {}.",
        estimator
            .natural
            .iter()
            .enumerate()
            .map(|(k, &(i, j))| format!(
                "{k}: `{}`{}, {}",
                symbols.fields[i].test_name,
                if j == 0 { "" } else { "'" },
                describe(Region::Natural(k))
            ))
            .collect::<Vec<_>>()
            .join("; ")
    );
    quote! {
        /// The indicator kernels of the model's `estimator:` text.
        pub mod estimator {
            #[doc = #cell_doc]
            #[allow(unused_variables, unused_mut, unused_parens, clippy::all)]
            pub fn cell(x: &[f64; 2], c: &[&[f64]; #nf], p: &[f64; #np], d: &[&#runtime::DataFn; #nd]) -> f64 {
                let h = (x[1] - x[0]).abs();
                let hinv = 1.0 / (x[1] - x[0]);
                let mut eta2 = 0.0f64;
                #(#cell_terms)*
                eta2
            }

            #[doc = #node_doc]
            ///
            /// # Panics
            /// When `end > 1` or `other > 1`.
            #[allow(unused_variables, unused_mut, unused_parens, clippy::all, clippy::too_many_arguments)]
            pub fn edge(
                x: &[f64; 2],
                end: usize,
                c: &[&[f64]; #nf],
                y: &[f64; 2],
                other: usize,
                e: &[&[f64]; #nf],
                p: &[f64; #np],
                d: &[&#runtime::DataFn; #nd],
            ) -> f64 {
                assert!(end < 2 && other < 2, "an interval has ends 0 and 1");
                let (hinv_p, hinv_m) = (1.0 / (x[1] - x[0]), 1.0 / (y[1] - y[0]));
                let (h_p, h_m) = ((x[1] - x[0]).abs(), (y[1] - y[0]).abs());
                let h = 0.5 * (h_p + h_m);
                let (n_x, n_y) = (if end == 1 { 1.0f64 } else { -1.0f64 }, 0.0f64);
                let xq = [x[end]];
                let mut eta2 = 0.0f64;
                #(#node_terms)*
                eta2
            }

            #[doc = #boundary_doc]
            ///
            /// # Panics
            /// When `end > 1`.
            #[allow(unused_variables, unused_mut, unused_parens, clippy::all)]
            pub fn boundary(
                k: usize,
                x: &[f64; 2],
                end: usize,
                c: &[&[f64]; #nf],
                p: &[f64; #np],
                d: &[&#runtime::DataFn; #nd],
            ) -> f64 {
                assert!(end < 2, "an interval has ends 0 and 1");
                let hinv = 1.0 / (x[1] - x[0]);
                let h = (x[1] - x[0]).abs();
                let (n_x, n_y) = (if end == 1 { 1.0f64 } else { -1.0f64 }, 0.0f64);
                let xq = [x[end]];
                let mut eta2 = 0.0f64;
                match k {
                    #(#natural)*
                    _ => {}
                }
                eta2
            }
        }
    }
}
