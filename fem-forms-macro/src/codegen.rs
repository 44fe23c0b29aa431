//! Kernel IR → Rust element kernels.
//!
//! For each block, the terms are split in two:
//! - terms without data have coefficients constant on the element (parameters and powers
//!   of `h`), so their reference integrals `∫₀¹ φ̂ᵢ⁽ᵏ⁾ φ̂ⱼ⁽ˡ⁾` are computed here, at compile
//!   time, and emitted as literals; at run time an entry is a handful of multiply-adds
//!   with the hoisted coefficients `c = κ(params) · h^{1−k−l}`;
//! - terms with data get a quadrature loop over compile-time tables of basis values at
//!   the Gauss points, the data evaluated once per point.
//!
//! Hermite slope DOFs are scaled by `h` (see `ElementKind::dof_scaling_power`).

use crate::analysis::{Block, Form, Symbols, Term};
use crate::declaration::Declaration;
use fem_reference::{ElementKind, Polynomial, QuadratureRule};
use proc_macro2::{Ident, Span, TokenStream};
use quote::{format_ident, quote};

/// A float literal (with a leading minus for negative values).
pub fn float(v: f64) -> TokenStream {
    assert!(
        v.is_finite(),
        "non-finite constant {v} in a generated kernel"
    );
    let lit = proc_macro2::Literal::f64_suffixed(v.abs());
    if v.is_sign_negative() && v != 0.0 {
        quote!(-#lit)
    } else {
        quote!(#lit)
    }
}

/// Polynomial degree of `D^k φ` for the element, after differentiation.
fn factor_degree(element: ElementKind, derivative: u8) -> usize {
    element.degree().saturating_sub(derivative as usize)
}

/// Quadrature degree that integrates the term exactly on an affine cell (data counted
/// with their declared degree), or the explicit `∫[degree=N]`.
pub fn term_degree(term: &Term, block: &Block, symbols: &Symbols) -> usize {
    if let Some(d) = term.quadrature_degree {
        return d;
    }
    let element = |f: usize| symbols.fields[f].element;
    let mut degree = factor_degree(element(block.test_field), term.test_derivative[0]);
    if let (Some(f), Some(d)) = (block.trial_field, term.trial_derivative) {
        degree += factor_degree(element(f), d[0]);
    }
    degree + term.data.iter().map(|&i| symbols.data[i].1).sum::<usize>()
}

/// Values of `d^k φ̂ᵢ / dξ^k` at the points of `rule`: `[q][i]`.
fn table(element: ElementKind, derivative: u8, rule: &QuadratureRule) -> Vec<Vec<f64>> {
    let basis: Vec<Polynomial> = element
        .basis()
        .iter()
        .map(|p| p.derivative(derivative as usize))
        .collect();
    rule.points
        .iter()
        .map(|&xi| basis.iter().map(|p| p.eval(xi)).collect())
        .collect()
}

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

/// `base^e` as straight-line code.
fn power(base: TokenStream, e: i32) -> Option<TokenStream> {
    let positive = |n: i32| -> TokenStream {
        match n {
            1 => base.clone(),
            2 => quote!((#base * #base)),
            n => quote!(#base.powi(#n)),
        }
    };
    match e {
        0 => None,
        e if e > 0 => Some(positive(e)),
        e => {
            let p = positive(-e);
            Some(quote!((1.0 / #p)))
        }
    }
}

/// The coefficient `κ · Π pᵢ^eᵢ · h^k` of a term as code.
pub(crate) fn coefficient(coefficient: f64, params: &[(usize, i32)], h_power: i32) -> TokenStream {
    let mut factors = Vec::new();
    for &(i, e) in params {
        factors.extend(power(quote!(p[#i]), e));
    }
    factors.extend(power(quote!(h), h_power));
    if coefficient != 1.0 || factors.is_empty() {
        factors.insert(0, float(coefficient));
    }
    let mut it = factors.into_iter();
    let first = it.next().unwrap();
    it.fold(first, |acc, f| quote!(#acc * #f))
}

/// A readable term: `2·t^-2·h^4·f·w'·v`.
pub(crate) fn describe_term(term: &Term, block: &Block, symbols: &Symbols) -> String {
    let mut parts = Vec::new();
    if term.coefficient != 1.0 {
        parts.push(format!("{}", term.coefficient));
    }
    for &(i, e) in &term.params {
        parts.push(if e == 1 {
            symbols.params[i].clone()
        } else {
            format!("{}^{e}", symbols.params[i])
        });
    }
    if term.h_power != 0 {
        parts.push(format!("h^{}", term.h_power));
    }
    for &i in &term.data {
        parts.push(symbols.data[i].0.clone());
    }
    let derivative = |name: &str, d: [u8; 2]| -> String {
        if symbols.dimension == 1 {
            format!("{name}{}", "'".repeat(d[0] as usize))
        } else if d == [0, 0] {
            name.to_string()
        } else {
            format!(
                "∂{}{}{name}",
                "x".repeat(d[0] as usize),
                "y".repeat(d[1] as usize)
            )
        }
    };
    if let (Some(f), Some(d)) = (block.trial_field, term.trial_derivative) {
        parts.push(derivative(&symbols.fields[f].name, d));
    }
    parts.push(derivative(
        &symbols.fields[block.test_field].test_name,
        term.test_derivative,
    ));
    parts.join("·")
}

/// The non-negligible `name · literal` products of entry `(i, j)` of reference tables
/// (relative to each table's largest entry, so rounding residue is not emitted).
pub(crate) fn literal_products(
    tables: &[(Ident, &Vec<Vec<f64>>)],
    i: usize,
    j: usize,
) -> Vec<TokenStream> {
    tables
        .iter()
        .filter_map(|(name, table)| {
            let scale = table.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
            let r = table[i][j];
            (r.abs() > 1e-14 * scale).then(|| {
                let lit = float(r);
                quote!(#name * #lit)
            })
        })
        .collect()
}

/// What every block kernel shares around its body: its doc lines, return type and
/// return expression.
pub(crate) struct KernelFrame {
    /// First doc line.
    pub doc_title: String,
    /// Second doc line: the terms.
    pub doc_terms: String,
    /// The return type.
    pub signature_out: TokenStream,
    /// The return expression.
    pub ret: TokenStream,
}

/// The frame of a block kernel; `cell` is added to the doc title (e.g. " on triangles").
pub(crate) fn kernel_frame(
    block: &Block,
    symbols: &Symbols,
    form: &str,
    cell: &str,
    rows: usize,
    cols: usize,
) -> KernelFrame {
    let test_element = symbols.fields[block.test_field].element;
    let test = &symbols.fields[block.test_field].test_name;
    let terms: Vec<String> = block
        .terms
        .iter()
        .map(|t| describe_term(t, block, symbols))
        .collect();
    let doc_title = match block.trial_field {
        Some(f) => format!(
            " Block ({test}, {}) of `{form}`{cell}: rows {test} ({}), columns {} ({}).",
            symbols.fields[f].name,
            test_element.name(),
            symbols.fields[f].name,
            symbols.fields[f].element.name()
        ),
        None => format!(" Block {test} of `{form}`{cell} ({}).", test_element.name()),
    };
    let (signature_out, ret) = if block.trial_field.is_some() {
        (quote!([[f64; #cols]; #rows]), quote!(k))
    } else {
        let items = (0..rows).map(|i| quote!(k[#i][0]));
        (quote!([f64; #rows]), quote!([#(#items),*]))
    };
    KernelFrame {
        doc_title,
        doc_terms: format!(" Terms: {}.", terms.join(" + ")),
        signature_out,
        ret,
    }
}

/// Name of a block kernel: `matrix_η_θ` (rows, columns) or `vector_v`.
pub fn block_ident(block: &Block, symbols: &Symbols) -> Ident {
    let test = &symbols.fields[block.test_field].test_name;
    match block.trial_field {
        Some(f) => format_ident!("matrix_{}_{}", test, symbols.fields[f].name),
        None => format_ident!("vector_{}", test),
    }
}

/// One generated block kernel.
pub(crate) struct BlockCode {
    /// The kernel function.
    pub function: TokenStream,
    /// Points of its run-time quadrature loops.
    pub quadrature_points: usize,
}

fn block_kernel(block: &Block, symbols: &Symbols, runtime: &TokenStream, form: &str) -> BlockCode {
    if symbols.dimension == 2 {
        return crate::codegen_triangle::block_kernel(block, symbols, runtime, form);
    }
    let test_element = symbols.fields[block.test_field].element;
    let trial_element = block.trial_field.map(|f| symbols.fields[f].element);
    let rows = test_element.dof_count();
    let cols = trial_element.map_or(1, |e| e.dof_count());
    let np = symbols.params.len();
    let nd = symbols.data.len();
    let name = block_ident(block, symbols);
    let mut quadrature_points = 0;

    // Compile-time integrated part: group by the hoisted coefficient's monomial key.
    struct Group {
        params: Vec<(usize, i32)>,
        h_power: i32,
        reference: Vec<Vec<f64>>,
    }
    let mut groups: Vec<Group> = Vec::new();
    let mut data_terms: Vec<&Term> = Vec::new();
    for term in &block.terms {
        if !term.data.is_empty() {
            data_terms.push(term);
            continue;
        }
        let rule = QuadratureRule::exact_for_degree(term_degree(term, block, symbols));
        if term.quadrature_degree.is_some() {
            quadrature_points = quadrature_points.max(rule.len());
        }
        let test = table(test_element, term.test_derivative[0], &rule);
        let trial = match (trial_element, term.trial_derivative) {
            (Some(e), Some(d)) => table(e, d[0], &rule),
            _ => vec![vec![1.0]; rule.len()],
        };
        let h_power = term.h_power + 1
            - term.test_derivative[0] as i32
            - term.trial_derivative.map_or(0, |d| d[0]) as i32;
        let idx = match groups
            .iter()
            .position(|g| g.params == term.params && g.h_power == h_power)
        {
            Some(i) => i,
            None => {
                groups.push(Group {
                    params: term.params.clone(),
                    h_power,
                    reference: vec![vec![0.0; cols]; rows],
                });
                groups.len() - 1
            }
        };
        if term.quadrature_degree.is_some() {
            // An explicit rule (e.g. reduced integration) is the point: use it as given.
            for (q, w) in rule.weights.iter().enumerate() {
                for (row, test_value) in groups[idx].reference.iter_mut().zip(&test[q]) {
                    for (entry, trial_value) in row.iter_mut().zip(&trial[q]) {
                        *entry += term.coefficient * w * test_value * trial_value;
                    }
                }
            }
        } else {
            // Exact: integrate the polynomial products coefficient by coefficient.
            let test_basis = derivatives(test_element, term.test_derivative[0]);
            let trial_basis = match (trial_element, term.trial_derivative) {
                (Some(e), Some(d)) => derivatives(e, d[0]),
                _ => vec![Polynomial::constant(1.0)],
            };
            for (i, p) in test_basis.iter().enumerate() {
                for (j, q) in trial_basis.iter().enumerate() {
                    groups[idx].reference[i][j] += term.coefficient * integral_of_product(p, q);
                }
            }
        }
    }
    let coefficient_lets: Vec<TokenStream> = groups
        .iter()
        .enumerate()
        .map(|(g, group)| {
            let c = format_ident!("c{}", g);
            let value = coefficient(1.0, &group.params, group.h_power);
            quote!(let #c: f64 = #value;)
        })
        .collect();

    // Quadrature loops for data terms, one per (data set, rule).
    let mut loops = Vec::new();
    let mut data_groups: Vec<(Vec<usize>, usize, Vec<&Term>)> = Vec::new();
    for term in data_terms {
        let degree = term_degree(term, block, symbols);
        let points = QuadratureRule::exact_for_degree(degree).len();
        match data_groups
            .iter_mut()
            .find(|(d, n, _)| *d == term.data && *n == points)
        {
            Some(g) => g.2.push(term),
            None => data_groups.push((term.data.clone(), points, vec![term])),
        }
    }
    for (data, points, terms) in &data_groups {
        quadrature_points = quadrature_points.max(*points);
        let rule = fem_reference::gauss_legendre(*points);
        let xi = rule.points.iter().map(|&v| float(v));
        let weights = rule.weights.iter().map(|&v| float(v));
        let nq = *points;
        let mut body = Vec::new();
        let mut tables = Vec::new();
        let mut tables_made: Vec<(usize, ElementKind, u8)> = Vec::new();
        let mut table_ident =
            |element: ElementKind, derivative: u8, tables: &mut Vec<TokenStream>| {
                let ident = format_ident!("PHI_{}_D{}", element.name().to_uppercase(), derivative);
                if !tables_made.contains(&(nq, element, derivative)) {
                    tables_made.push((nq, element, derivative));
                    let t = table(element, derivative, &rule);
                    let n = element.dof_count();
                    let rows_code = t.iter().map(|row| {
                        let vals = row.iter().map(|&v| float(v));
                        quote!([#(#vals),*])
                    });
                    tables.push(quote! {
                        const #ident: [[f64; #n]; #nq] = [#(#rows_code),*];
                    });
                }
                ident
            };
        let data_product: TokenStream = {
            let mut it = data.iter().map(|&i| quote!(d[#i](&[xq])));
            let first = it.next().expect("a data group has data");
            it.fold(first, |acc, f| quote!(#acc * #f))
        };
        for term in terms {
            let h_power = term.h_power + 1
                - term.test_derivative[0] as i32
                - term.trial_derivative.map_or(0, |d| d[0]) as i32;
            let c = coefficient(term.coefficient, &term.params, h_power);
            let test = table_ident(test_element, term.test_derivative[0], &mut tables);
            let accumulate = match (trial_element, term.trial_derivative) {
                (Some(e), Some(dv)) => {
                    let trial = table_ident(e, dv[0], &mut tables);
                    quote! {
                        for i in 0..#rows {
                            for j in 0..#cols {
                                k[i][j] += g * #test[q][i] * #trial[q][j];
                            }
                        }
                    }
                }
                _ => quote! {
                    for i in 0..#rows {
                        k[i][0] += g * #test[q][i];
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
                const XI: [f64; #nq] = [#(#xi),*];
                const W: [f64; #nq] = [#(#weights),*];
                #(#tables)*
                for q in 0..#nq {
                    let xq = x[0] + h * XI[q];
                    let w = W[q] * #data_product;
                    #(#body)*
                }
            }
        });
    }

    // Entries: (data part + Σ c_g R_g[i][j]) · h^{sᵢ + sⱼ}.
    let has_data = !loops.is_empty();
    let tables: Vec<(Ident, &Vec<Vec<f64>>)> = groups
        .iter()
        .enumerate()
        .map(|(g, group)| (format_ident!("c{}", g), &group.reference))
        .collect();
    let mut entries = Vec::new();
    for i in 0..rows {
        for j in 0..cols {
            let sum = literal_products(&tables, i, j);
            let scaling = test_element.dof_scaling_power(i)
                + trial_element.map_or(0, |e| e.dof_scaling_power(j));
            let scale = power(quote!(h), scaling);
            let value = match (has_data, sum.is_empty()) {
                (false, true) => continue,
                (true, true) => quote!(k[#i][#j]),
                (false, false) => quote!(#(#sum)+*),
                (true, false) => quote!(k[#i][#j] + #(#sum)+*),
            };
            if has_data && scale.is_none() && sum.is_empty() {
                continue;
            }
            let value = match scale {
                Some(s) => quote!((#value) * #s),
                None => value,
            };
            entries.push(quote!(k[#i][#j] = #value;));
        }
    }

    let KernelFrame {
        doc_title,
        doc_terms,
        signature_out,
        ret,
    } = kernel_frame(block, symbols, form, "", rows, cols);
    let function = quote! {
        #[doc = #doc_title]
        #[doc = #doc_terms]
        #[inline]
        #[allow(unused_variables, unused_mut, clippy::all)]
        pub fn #name(x: &[f64; 2], p: &[f64; #np], d: &[&#runtime::DataFn; #nd]) -> #signature_out {
            let h = x[1] - x[0];
            #(#coefficient_lets)*
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

/// The whole generated module.
pub fn generate(declaration: &Declaration, symbols: &Symbols, forms: &[Form]) -> TokenStream {
    let runtime = &declaration.runtime;
    let module = &declaration.name;
    let vis = &declaration.vis;
    let attrs = &declaration.attrs;
    let model_name = module.to_string();
    let np = symbols.params.len();
    let nd = symbols.data.len();
    let (cell, coordinates, cell_text) = if symbols.dimension == 2 {
        (
            quote!(Triangle),
            6usize,
            "a triangle has six vertex coordinates",
        )
    } else {
        (
            quote!(Interval),
            2usize,
            "an interval has two vertex coordinates",
        )
    };
    let dirichlet = declaration.dirichlet.iter().map(|(field, data)| {
        let f = symbols
            .fields
            .iter()
            .position(|x| *field == x.name)
            .unwrap_or(0);
        let g = symbols.data.iter().position(|x| *data == x.0).unwrap_or(0);
        quote!((#f, #g))
    });

    let mut form_modules = Vec::new();
    let mut form_infos = Vec::new();
    let mut matrix_arms = Vec::new();
    let mut add_arms = Vec::new();
    let mut vector_arms = Vec::new();
    for (form_index, form) in forms.iter().enumerate() {
        let form_ident = Ident::new(&form.name, Span::call_site());
        let mut functions = Vec::new();
        let mut block_infos = Vec::new();
        for (block_index, block) in form.blocks.iter().enumerate() {
            let code = block_kernel(block, symbols, runtime, &form.name);
            functions.push(code.function);
            let name = block_ident(block, symbols);
            let test_field = block.test_field;
            let trial_field = match block.trial_field {
                Some(f) => quote!(::core::option::Option::Some(#f)),
                None => quote!(::core::option::Option::None),
            };
            let points = code.quadrature_points;
            let description = block
                .terms
                .iter()
                .map(|t| describe_term(t, block, symbols))
                .collect::<Vec<_>>()
                .join(" + ");
            block_infos.push(quote! {
                #runtime::BlockInfo {
                    test_field: #test_field,
                    trial_field: #trial_field,
                    quadrature_points: #points,
                    terms: #description,
                }
            });
            if block.trial_field.is_some() {
                add_arms.push(quote! {
                    (#form_index, #block_index) => #runtime::kernel::add_matrices(mesh, positions, stride, offset, values, |x| #form_ident::#name(x, p, d)),
                });
                matrix_arms.push(quote! {
                    (#form_index, #block_index) => #runtime::kernel::store_matrix(&#form_ident::#name(x, p, d), out),
                });
            } else {
                vector_arms.push(quote! {
                    (#form_index, #block_index) => #runtime::kernel::store_vector(&#form_ident::#name(x, p, d), out),
                });
            }
        }
        let source = &form.source;
        let arity = form.arity();
        let dropped = form.dropped;
        let doc = format!(" Kernels of `{}`.", form.source);
        let dropped_doc = format!(
            " {} term(s) vanish for the chosen elements and were dropped.",
            form.dropped
        );
        form_modules.push(quote! {
            #[doc = #doc]
            #[doc = #dropped_doc]
            pub mod #form_ident {
                use super::*;
                /// Index of this form in `Model::FORMS`.
                pub const INDEX: usize = #form_index;
                /// The definition as written in the model file.
                pub const SOURCE: &str = #source;
                #(#functions)*
            }
        });
        let name = &form.name;
        form_infos.push(quote! {
            #runtime::FormInfo {
                name: #name,
                source: #source,
                arity: #arity,
                dropped_terms: #dropped,
                blocks: &[#(#block_infos),*],
            }
        });
    }

    let field_infos = symbols.fields.iter().map(|f| {
        let (name, test, nonnegative) = (&f.name, &f.test_name, f.nonnegative);
        let element = Ident::new(&format!("{:?}", f.element), Span::call_site());
        quote! {
            #runtime::FieldInfo {
                name: #name,
                test_name: #test,
                element: #runtime::ElementKind::#element,
                nonnegative: #nonnegative,
            }
        }
    });
    let params = &symbols.params;
    let data = symbols.data.iter().map(|d| &d.0);
    let description: String = declaration
        .attrs
        .iter()
        .filter_map(|a| match &a.meta {
            syn::Meta::NameValue(nv) if nv.path.is_ident("doc") => match &nv.value {
                syn::Expr::Lit(syn::ExprLit {
                    lit: syn::Lit::Str(s),
                    ..
                }) => Some(s.value().trim().to_string()),
                _ => None,
            },
            _ => None,
        })
        .collect::<Vec<_>>()
        .join(" ");

    quote! {
        #(#attrs)*
        #[allow(non_snake_case, non_upper_case_globals, mixed_script_confusables, confusable_idents, uncommon_codepoints, clippy::all)]
        #vis mod #module {
            /// The model: its fields, parameters, data and forms, and the dispatch to its kernels.
            #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
            pub struct Model;

            /// Number of runtime parameters.
            pub const PARAMS: usize = #np;
            /// Number of data functions.
            pub const DATA: usize = #nd;

            #(#form_modules)*

            impl #runtime::Model for Model {
                const NAME: &'static str = #model_name;
                const DESCRIPTION: &'static str = #description;
                const CELL: #runtime::CellKind = #runtime::CellKind::#cell;
                const DIRICHLET: &'static [(usize, usize)] = &[#(#dirichlet),*];
                const FIELDS: &'static [#runtime::FieldInfo] = &[#(#field_infos),*];
                const PARAMS: &'static [&'static str] = &[#(#params),*];
                const DATA: &'static [&'static str] = &[#(#data),*];
                const FORMS: &'static [#runtime::FormInfo] = &[#(#form_infos),*];

                fn element_matrix(
                    form: usize,
                    block: usize,
                    vertices: &[f64],
                    params: &[f64],
                    data: &[&#runtime::DataFn],
                    out: &mut [f64],
                ) {
                    let x: &[f64; #coordinates] = vertices.try_into().expect(#cell_text);
                    let p: &[f64; #np] = params.try_into().expect("parameter count checked by the runtime");
                    let d: &[&#runtime::DataFn; #nd] = data.try_into().expect("data count checked by the runtime");
                    match (form, block) {
                        #(#matrix_arms)*
                        _ => panic!("{}: form {} has no bilinear block {}", #model_name, form, block),
                    }
                }

                fn add_element_matrices<G: #runtime::mesh::Mesh>(
                    form: usize,
                    block: usize,
                    mesh: &G,
                    params: &[f64],
                    data: &[&#runtime::DataFn],
                    positions: &[usize],
                    stride: usize,
                    offset: usize,
                    values: &mut [f64],
                ) {
                    let p: &[f64; #np] = params.try_into().expect("parameter count checked by the runtime");
                    let d: &[&#runtime::DataFn; #nd] = data.try_into().expect("data count checked by the runtime");
                    match (form, block) {
                        #(#add_arms)*
                        _ => panic!("{}: form {} has no bilinear block {}", #model_name, form, block),
                    }
                }

                fn element_vector(
                    form: usize,
                    block: usize,
                    vertices: &[f64],
                    params: &[f64],
                    data: &[&#runtime::DataFn],
                    out: &mut [f64],
                ) {
                    let x: &[f64; #coordinates] = vertices.try_into().expect(#cell_text);
                    let p: &[f64; #np] = params.try_into().expect("parameter count checked by the runtime");
                    let d: &[&#runtime::DataFn; #nd] = data.try_into().expect("data count checked by the runtime");
                    match (form, block) {
                        #(#vector_arms)*
                        _ => panic!("{}: form {} has no linear block {}", #model_name, form, block),
                    }
                }
            }
        }
    }
}
