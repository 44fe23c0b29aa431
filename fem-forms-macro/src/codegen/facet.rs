//! Facet kernels: the blocks of boundary integrals `∫_Γ … ds` on affine triangles.
//!
//! A facet kernel integrates over one edge of a cell, with the traces of the cell's
//! basis functions: `pub fn matrix_μ_u_x(x: &[f64; 6], edge: usize, p, d)`, `edge` the
//! local edge `k` joining local vertices `k` and `(k + 1) % 3` (the runtime's
//! `TriangleMesh::cell_edges` convention). Everything is integrated by Gauss–Legendre
//! quadrature on the edge, exact for the term's polynomial degree (data counted with
//! their declared degree): the points and the reference values and derivatives of the
//! basis are compile-time tables, one slice per local edge, so the kernel does not
//! allocate. On the edge, `h` (`h_E`) is the edge's length `|E|`, `n = (n_x, n_y)` the
//! cell's outward unit normal, constant on a straight edge; physical derivatives are
//! reference ones through `K = J⁻¹` exactly as in the cell kernels (`triangle.rs`).

use super::backend::CellBackend;
use super::emit::{coefficient, describe_term, float, power, product};
use super::triangle::{derivatives, k_polynomial_code, t_code, t_ident, transform, Triangle};
use crate::analysis::{Block, Symbols, Term};
use fem_reference::quadrature::QuadratureRule;
use fem_reference::ElementKind;
use proc_macro2::{Ident, TokenStream};
use quote::{format_ident, quote};

/// The reference triangle's vertices; local edge `k` runs from vertex `k` to `k + 1`.
const VERTICES: [[f64; 2]; 3] = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];

/// The point at parameter `s ∈ [0, 1]` of local edge `edge` of the reference triangle.
pub(crate) fn edge_point(edge: usize, s: f64) -> [f64; 2] {
    let (a, b) = (VERTICES[edge], VERTICES[(edge + 1) % 3]);
    [a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])]
}

/// Name of a facet part's kernel module: `on_Γ_C`.
pub fn part_ident(part: &str) -> Ident {
    format_ident!("on_{}", part)
}

/// Degree of a term on the edge (the polynomial degree of its integrand along it).
fn term_degree(term: &Term, block: &Block, symbols: &Symbols) -> usize {
    Triangle.term_degree(term, block, symbols)
}

/// Readable term with its normal factors: `… · n_x · n_y^2`.
fn describe(term: &Term, block: &Block, symbols: &Symbols) -> String {
    let mut s = describe_term(term, block, symbols);
    for (axis, &e) in term.normal.iter().enumerate() {
        let name = ["n_x", "n_y"][axis];
        match e {
            0 => {}
            1 => s.push_str(&format!("·{name}")),
            e => s.push_str(&format!("·{name}^{e}")),
        }
    }
    s
}

/// The physical multi-indices the block's terms use, sorted.
fn alphas(block: &Block) -> Vec<[u8; 2]> {
    let mut alphas: Vec<[u8; 2]> = block
        .terms
        .iter()
        .flat_map(|t| [Some(t.test_derivative), t.trial_derivative])
        .flatten()
        .collect();
    alphas.sort();
    alphas.dedup();
    alphas
}

/// The facet kernel of one block of form `form` on boundary part `part`.
pub fn facet_kernel(
    block: &Block,
    symbols: &Symbols,
    runtime: &TokenStream,
    form: &str,
    part: &str,
) -> TokenStream {
    let test_element = symbols.fields[block.test_field].element;
    let trial_element = block.trial_field.map(|f| symbols.fields[f].element);
    let rows = test_element.triangle_basis().len();
    let cols = trial_element.map_or(1, |e| e.triangle_basis().len());
    let np = symbols.params.len();
    let nd = symbols.data.len();
    let name = super::emit::block_ident(block, symbols);

    // T_αβ for every physical derivative used.
    let mut lets = Vec::new();
    for alpha in alphas(block).into_iter().filter(|a| *a != [0, 0]) {
        for (beta, poly) in transform(alpha) {
            let ident = t_ident(alpha, beta);
            let value = k_polynomial_code(&poly);
            lets.push(quote!(let #ident: f64 = #value;));
        }
    }

    // One quadrature loop per (data set, number of points).
    let groups = quadrature_groups(block, symbols);
    let shape = KernelShape {
        test: test_element,
        trial: trial_element,
        rows,
        cols,
    };
    let loops: Vec<TokenStream> = groups
        .iter()
        .map(|(data, nq, terms)| quadrature_loop(&shape, data, *nq, terms))
        .collect();

    let (doc_title, doc_terms) = kernel_docs(block, symbols, form, part);
    let (signature_out, ret) = if block.trial_field.is_some() {
        (quote!([[f64; #cols]; #rows]), quote!(k))
    } else {
        let items = (0..rows).map(|i| quote!(k[#i][0]));
        (quote!([f64; #rows]), quote!([#(#items),*]))
    };
    quote! {
        #[doc = #doc_title]
        #[doc = #doc_terms]
        ///
        /// # Panics
        /// When `edge > 2` (a triangle has three local edges).
        #[inline]
        #[allow(unused_variables, unused_mut, clippy::all)]
        pub fn #name(x: &[f64; 6], edge: usize, p: &[f64; #np], d: &[&#runtime::DataFn; #nd]) -> #signature_out {
            assert!(edge < 3, "a triangle has local edges 0, 1 and 2");
            let (j00, j01) = (x[2] - x[0], x[4] - x[0]);
            let (j10, j11) = (x[3] - x[1], x[5] - x[1]);
            let det = j00 * j11 - j01 * j10;
            let inv = 1.0 / det;
            let (k00, k01, k10, k11) = (j11 * inv, -j01 * inv, -j10 * inv, j00 * inv);
            let (a, b) = (edge, (edge + 1) % 3);
            let (tx, ty) = (x[2 * b] - x[2 * a], x[2 * b + 1] - x[2 * a + 1]);
            let len = (tx * tx + ty * ty).sqrt();
            // The edge's right-hand normal points out of a counter-clockwise cell.
            let side = if det > 0.0 { 1.0 } else { -1.0 };
            let (n_x, n_y) = (side * ty / len, -side * tx / len);
            let h = len;
            #(#lets)*
            let mut k = [[0.0f64; #cols]; #rows];
            #(#loops)*
            #ret
        }
    }
}

/// The terms of `block` grouped by the quadrature loop that integrates them: one per
/// (data functions, number of Gauss points exact for the term's degree).
fn quadrature_groups<'a>(
    block: &'a Block,
    symbols: &Symbols,
) -> Vec<(&'a [usize], usize, Vec<&'a Term>)> {
    let mut groups: Vec<(&[usize], usize, Vec<&Term>)> = Vec::new();
    for term in &block.terms {
        let points = QuadratureRule::exact_for_degree(term_degree(term, block, symbols)).len();
        match groups
            .iter_mut()
            .find(|(d, n, _)| *d == term.data.as_slice() && *n == points)
        {
            Some(g) => g.2.push(term),
            None => groups.push((&term.data, points, vec![term])),
        }
    }
    groups
}

/// The elements and local sizes of a facet kernel: the test field's (rows), the trial
/// field's where the block has one (columns, else 1).
struct KernelShape {
    test: ElementKind,
    trial: Option<ElementKind>,
    rows: usize,
    cols: usize,
}

/// One quadrature loop of a facet kernel: `terms` (on `data`) integrated by `nq`-point
/// Gauss–Legendre on the edge, with the compile-time tables of the basis derivatives
/// they use at the points of each of the three local edges.
fn quadrature_loop(shape: &KernelShape, data: &[usize], nq: usize, terms: &[&Term]) -> TokenStream {
    let KernelShape {
        test: test_element,
        trial: trial_element,
        rows,
        cols,
    } = *shape;
    let rule = fem_reference::quadrature::gauss_legendre(nq);
    let mut tables: Vec<TokenStream> = Vec::new();
    let mut made: Vec<(ElementKind, [u8; 2])> = Vec::new();
    let mut table = |element: ElementKind, beta: [u8; 2]| -> Ident {
        let ident = format_ident!(
            "PHI_{}_D{}{}",
            element.name().to_uppercase(),
            beta[0],
            beta[1]
        );
        if !made.contains(&(element, beta)) {
            made.push((element, beta));
            let basis = derivatives(element, beta);
            let n = basis.len();
            let per_edge = (0..3).map(|edge| {
                let per_point = rule.points.iter().map(|&s| {
                    let x = edge_point(edge, s);
                    let values = basis.iter().map(|p| float(p.eval(x)));
                    quote!([#(#values),*])
                });
                quote!([#(#per_point),*])
            });
            tables.push(quote! {
                const #ident: [[[f64; #n]; #nq]; 3] = [#(#per_edge),*];
            });
        }
        ident
    };
    // Σ_β T_αβ TABLE_β[edge][q][index]
    let mut value = |element: ElementKind, alpha: [u8; 2], index: TokenStream| {
        let parts: Vec<TokenStream> = transform(alpha)
            .into_iter()
            .map(|(beta, _)| {
                let t = table(element, beta);
                match t_code(alpha, beta) {
                    Some(c) => quote!(#c * #t[edge][q][#index]),
                    None => quote!(#t[edge][q][#index]),
                }
            })
            .collect();
        quote!((#(#parts)+*))
    };
    let body: Vec<TokenStream> = terms
        .iter()
        .map(|term| {
            let mut factors = vec![coefficient(
                term.coefficient,
                &term.params,
                term.h_power,
                &term.divisors,
            )];
            factors.extend(power(quote!(n_x), i32::from(term.normal[0])));
            factors.extend(power(quote!(n_y), i32::from(term.normal[1])));
            let c = product(factors);
            let test = value(test_element, term.test_derivative, quote!(i));
            let accumulate = match (trial_element, term.trial_derivative) {
                (Some(e), Some(dv)) => {
                    let trial = value(e, dv, quote!(j));
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
            quote! {
                let g = w * (#c);
                #accumulate
            }
        })
        .collect();
    let points = (0..3).map(|edge| {
        let per_point = rule.points.iter().map(|&s| {
            let [a, b] = edge_point(edge, s).map(float);
            quote!([#a, #b])
        });
        quote!([#(#per_point),*])
    });
    let weights = rule.weights.iter().map(|&v| float(v));
    let data_product = product(
        std::iter::once(quote!(W[q] * len)).chain(data.iter().map(|&i| quote!(d[#i](&xq)))),
    );
    let point = (!data.is_empty()).then(|| {
        quote! {
            let xq = [
                x[0] + j00 * XI[edge][q][0] + j01 * XI[edge][q][1],
                x[1] + j10 * XI[edge][q][0] + j11 * XI[edge][q][1],
            ];
        }
    });
    quote! {
        {
            const XI: [[[f64; 2]; #nq]; 3] = [#(#points),*];
            const W: [f64; #nq] = [#(#weights),*];
            #(#tables)*
            for q in 0..#nq {
                #point
                let w = #data_product;
                #(#body)*
            }
        }
    }
}

/// The doc comment of a facet kernel: its title and its terms.
fn kernel_docs(block: &Block, symbols: &Symbols, form: &str, part: &str) -> (String, String) {
    let test_element = symbols.fields[block.test_field].element;
    let test = &symbols.fields[block.test_field].test_name;
    let doc_title = match block.trial_field {
    Some(f) => format!(
        " Block ({test}, {}) of `{form}` on the edges of the boundary part `{part}`: rows {test} ({}), columns {} ({}).",
        symbols.fields[f].name,
        test_element.name(),
        symbols.fields[f].name,
        symbols.fields[f].element.name()
    ),
    None => format!(
        " Block {test} of `{form}` on the edges of the boundary part `{part}` ({}).",
        test_element.name()
    ),
};
    let doc_terms = format!(
    " Terms: {}, integrated over local edge `edge` (joining local vertices `edge` and `(edge + 1) % 3`, `edge < 3`) of the triangle `x`, counter-clockwise or not; `h` is the edge's length and `n` the outward unit normal.",
    block
        .terms
        .iter()
        .map(|t| describe(t, block, symbols))
        .collect::<Vec<_>>()
        .join(" + ")
);
    (doc_title, doc_terms)
}

/// The facet items of the `Model` impl: `FACET_PARTS`, `FACET_BLOCKS` and the dispatch
/// of `facet_matrix` / `facet_vector` to the kernels (empty without `facets:`, so that
/// the other models' code stays as it was).
pub fn model_items(
    symbols: &Symbols,
    forms: &[crate::analysis::Form],
    runtime: &TokenStream,
    model_name: &str,
) -> TokenStream {
    if symbols.facets.is_empty() {
        return TokenStream::new();
    }
    let parts = &symbols.facets;
    let mut infos = Vec::new();
    let (mut matrix, mut vector) = (Vec::new(), Vec::new());
    let mut index = 0usize;
    for (form_index, form) in forms.iter().enumerate() {
        let form_ident = Ident::new(&form.name, proc_macro2::Span::call_site());
        // the order of the kernels' modules: by part, then by block
        for (part, part_name) in parts.iter().enumerate() {
            for (_, block) in form.facet_blocks.iter().filter(|(p, _)| *p == part) {
                let test = block.test_field;
                let trial = match block.trial_field {
                    Some(f) => quote!(::core::option::Option::Some(#f)),
                    None => quote!(::core::option::Option::None),
                };
                infos.push(quote! {
                    #runtime::FacetBlockInfo { form: #form_index, part: #part, test_field: #test, trial_field: #trial }
                });
                let module = part_ident(part_name);
                let name = super::emit::block_ident(block, symbols);
                let arm = if block.trial_field.is_some() {
                    quote!(#index => #runtime::kernel::store_matrix(&#form_ident::#module::#name(x, edge, p, d), out),)
                } else {
                    quote!(#index => #runtime::kernel::store_vector(&#form_ident::#module::#name(x, edge, p, d), out),)
                };
                if block.trial_field.is_some() {
                    matrix.push(arm);
                } else {
                    vector.push(arm);
                }
                index += 1;
            }
        }
    }
    let np = symbols.params.len();
    let nd = symbols.data.len();
    let body = |arms: &[TokenStream], what: &str| {
        let message = format!("{model_name}: facet block {{}} is not a {what} facet block");
        quote! {
            let x: &[f64; 6] = match vertices.try_into() {
                ::core::result::Result::Ok(x) => x,
                ::core::result::Result::Err(_) => {
                    return ::core::result::Result::Err(#runtime::Error::Input(::std::format!("a triangle has six vertex coordinates, not {}", vertices.len())));
                }
            };
            if edge > 2 {
                return ::core::result::Result::Err(#runtime::Error::Input(::std::format!("a triangle has local edges 0, 1 and 2, not {}", edge)));
            }
            let p: &[f64; #np] = params.try_into().expect("parameter count checked by the runtime");
            let d: &[&#runtime::DataFn; #nd] = data.try_into().expect("data count checked by the runtime");
            match block {
                #(#arms)*
                _ => return ::core::result::Result::Err(#runtime::Error::Input(::std::format!(#message, block))),
            }
            ::core::result::Result::Ok(())
        }
    };
    let matrix_body = body(&matrix, "bilinear");
    let vector_body = body(&vector, "linear");
    quote! {
        const FACET_PARTS: &'static [&'static str] = &[#(#parts),*];
        const FACET_BLOCKS: &'static [#runtime::FacetBlockInfo] = &[#(#infos),*];

        #[allow(unreachable_code)]
        fn facet_matrix(
            block: usize,
            vertices: &[f64],
            edge: usize,
            params: &[f64],
            data: &[&#runtime::DataFn],
            out: &mut [f64],
        ) -> #runtime::Result<()> {
            #matrix_body
        }

        #[allow(unreachable_code)]
        fn facet_vector(
            block: usize,
            vertices: &[f64],
            edge: usize,
            params: &[f64],
            data: &[&#runtime::DataFn],
            out: &mut [f64],
        ) -> #runtime::Result<()> {
            #vector_body
        }
    }
}
