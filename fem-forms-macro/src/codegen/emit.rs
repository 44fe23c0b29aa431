//! The cell-independent half of a block kernel: literals and coefficients as code, the
//! kernel's frame, the quadrature loops of data terms and the final entries. A backend
//! ([`CellBackend`]) supplies the geometry, the rules, the basis tables and the
//! constant-coefficient part.
//!
//! Every block kernel has the same shape:
//! ```text
//! pub fn matrix_v_u(x: &[f64; N], p: &[f64; NP], d: &[&DataFn; ND]) -> [[f64; C]; R] {
//!     <geometry>                      // backend: h, J, det J, K = J⁻¹ …
//!     <scalars of the exact part>     // backend: hoisted run-time coefficients
//!     let mut k = [[0.0; C]; R];
//!     { <one quadrature loop per (data set, rule)> }
//!     k[i][j] = k[i][j] + Σ scalar · literal;   // per non-zero entry
//!     k
//! }
//! ```

use super::backend::{CellBackend, Rule};
use crate::analysis::{Block, Symbols, Term};
use crate::symbolic::Divisor;
use fem_reference::ElementKind;
use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote};

/// A float literal (with a leading minus for negative values).
pub fn float(v: f64) -> TokenStream {
    assert!(
        v.is_finite(),
        "non-finite constant {v} in a generated kernel"
    );
    let lit = Literal::f64_suffixed(v.abs());
    if v.is_sign_negative() && v != 0.0 {
        quote!(-#lit)
    } else {
        quote!(#lit)
    }
}

/// `a * b * …` of non-empty `factors`, left to right.
pub fn product(factors: impl IntoIterator<Item = TokenStream>) -> TokenStream {
    let mut it = factors.into_iter();
    let first = it.next().expect("a product of at least one factor");
    it.fold(first, |acc, f| quote!(#acc * #f))
}

/// `base^e` as straight-line code (`None` for `e = 0`).
pub fn power(base: TokenStream, e: i32) -> Option<TokenStream> {
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

/// The coefficient `κ · Π pᵢ^eᵢ · h^k · Π Dₘ^-eₘ` of a term as code.
pub fn coefficient(
    coefficient: f64,
    params: &[(usize, i32)],
    h_power: i32,
    divisors: &[(Divisor, i32)],
) -> TokenStream {
    let mut factors = Vec::new();
    for &(i, e) in params {
        factors.extend(power(quote!(p[#i]), e));
    }
    factors.extend(power(quote!(h), h_power));
    for (d, e) in divisors {
        let terms = d
            .terms
            .iter()
            .map(|t| coefficient_without_divisors(t.coefficient, &t.params, t.h_power));
        factors.extend(power(quote!((#(#terms)+*)), -e));
    }
    if coefficient != 1.0 || factors.is_empty() {
        factors.insert(0, float(coefficient));
    }
    product(factors)
}

fn coefficient_without_divisors(c: f64, params: &[(usize, i32)], h_power: i32) -> TokenStream {
    coefficient(c, params, h_power, &[])
}

/// A divisor, readable: `(t^2 + β·h^2)`.
fn describe_divisor(d: &Divisor, symbols: &Symbols) -> String {
    let terms: Vec<String> = d
        .terms
        .iter()
        .map(|t| {
            let mut parts = Vec::new();
            if t.coefficient != 1.0 || (t.params.is_empty() && t.h_power == 0) {
                parts.push(format!("{}", t.coefficient));
            }
            for &(i, e) in &t.params {
                parts.push(if e == 1 {
                    symbols.params[i].clone()
                } else {
                    format!("{}^{e}", symbols.params[i])
                });
            }
            if t.h_power != 0 {
                parts.push(format!("h^{}", t.h_power));
            }
            parts.join("·")
        })
        .collect();
    format!("({})", terms.join(" + "))
}

/// A readable term: `2·t^-2·h^4·(t^2 + β·h^2)^-1·f·w'·v`.
pub fn describe_term(term: &Term, block: &Block, symbols: &Symbols) -> String {
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
    for (d, e) in &term.divisors {
        parts.push(format!("{}^{}", describe_divisor(d, symbols), -e));
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

/// All terms of a block, readable, joined by ` + `.
pub fn describe_block(block: &Block, symbols: &Symbols) -> String {
    block
        .terms
        .iter()
        .map(|t| describe_term(t, block, symbols))
        .collect::<Vec<_>>()
        .join(" + ")
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
pub struct BlockCode {
    /// The kernel function.
    pub function: TokenStream,
    /// Points of its quadrature loops (0: integrated exactly at compile time).
    pub quadrature_points: usize,
}

/// The element kernel of one block on the backend's cell.
pub fn block_kernel(
    backend: &dyn CellBackend,
    block: &Block,
    symbols: &Symbols,
    runtime: &TokenStream,
    form: &str,
) -> BlockCode {
    let (exact_terms, data_terms): (Vec<&Term>, Vec<&Term>) =
        block.terms.iter().partition(|t| t.data.is_empty());
    let exact = backend.exact_part(block, symbols, &exact_terms);
    let (loops, loop_points) = data_loops(backend, block, symbols, &data_terms);
    let symmetric = backend.symmetric_entries() && is_symmetric(block);
    let entries = entries(
        backend,
        block,
        symbols,
        &exact.tables,
        !loops.is_empty(),
        symmetric,
    );
    let (rows, cols) = shape(backend, block, symbols);
    let name = block_ident(block, symbols);
    let doc_title = doc_title(block, symbols, form, backend.doc_suffix());
    let doc_terms = format!(" Terms: {}.", describe_block(block, symbols));
    let (signature_out, ret) = if block.trial_field.is_some() {
        (quote!([[f64; #cols]; #rows]), quote!(k))
    } else {
        let items = (0..rows).map(|i| quote!(k[#i][0]));
        (quote!([f64; #rows]), quote!([#(#items),*]))
    };
    let coordinates = Literal::usize_unsuffixed(backend.coordinates());
    let np = symbols.params.len();
    let nd = symbols.data.len();
    let geometry = backend.geometry(block);
    let lets = &exact.lets;
    let function = if is_transformed(block, symbols) {
        // The entries above are those of the pulled-back reference basis; the epilogue
        // maps them to the physical basis with the cell's transformation, which needs
        // the global vertex numbers `g` for the edge orientation (docs/elements.md §3).
        let element = |e: ElementKind| {
            let variant = Ident::new(&format!("{e:?}"), proc_macro2::Span::call_site());
            quote!(#runtime::ElementKind::#variant)
        };
        let test = element(symbols.fields[block.test_field].element);
        let trial = match block.trial_field {
            Some(f) => {
                let e = element(symbols.fields[f].element);
                quote!(::core::option::Option::Some(#e))
            }
            None => quote!(::core::option::Option::None),
        };
        let doc_transformed = " Takes the cell's global vertex numbers `g` besides its coordinates: the entries are those of the physical basis, `M K̂ Mᵀ` (`M F̂`), with `M` the element's DOF transformation (`docs/elements.md`).";
        // A symmetric block (one field against itself) needs only one `M` and half of
        // the second product.
        let epilogue = if symmetric {
            quote!(#runtime::element::triangle::transform_symmetric_element_matrix(#test, x, g, &mut k);)
        } else {
            quote!(#runtime::element::triangle::transform_element_matrix(#test, #trial, x, g, &mut k);)
        };
        quote! {
            #[doc = #doc_title]
            #[doc = #doc_terms]
            #[doc = #doc_transformed]
            #[inline]
            #[allow(unused_variables, unused_mut, clippy::all)]
            pub fn #name(x: &[f64; #coordinates], g: &[usize; 3], p: &[f64; #np], d: &[&#runtime::DataFn; #nd]) -> #signature_out {
                #geometry
                #(#lets)*
                let mut k = [[0.0f64; #cols]; #rows];
                #(#loops)*
                #(#entries)*
                #epilogue
                #ret
            }
        }
    } else {
        quote! {
            #[doc = #doc_title]
            #[doc = #doc_terms]
            #[inline]
            #[allow(unused_variables, unused_mut, clippy::all)]
            pub fn #name(x: &[f64; #coordinates], p: &[f64; #np], d: &[&#runtime::DataFn; #nd]) -> #signature_out {
                #geometry
                #(#lets)*
                let mut k = [[0.0f64; #cols]; #rows];
                #(#loops)*
                #(#entries)*
                #ret
            }
        }
    };
    BlockCode {
        function,
        quadrature_points: exact.quadrature_points.max(loop_points),
    }
}

/// Whether a block's test or trial field has an element that needs the per-cell DOF
/// transformation (Argyris, Morley): its kernel then takes the global vertex numbers.
pub fn is_transformed(block: &Block, symbols: &Symbols) -> bool {
    std::iter::once(block.test_field)
        .chain(block.trial_field)
        .any(|f| symbols.fields[f].element.needs_transformation())
}

/// Whether a block is symmetric, decided on its terms: one field against itself, and
/// the terms (those with equal factors summed) a set that swapping the test and the
/// trial derivative maps onto itself with equal coefficients, parameters, powers of `h`,
/// divisors, data and rules. Then `a(φᵢ, φⱼ) = a(φⱼ, φᵢ)` for every pair of basis
/// functions (up to rounding), whatever the element.
pub fn is_symmetric(block: &Block) -> bool {
    if block.trial_field != Some(block.test_field) {
        return false;
    }
    let factors = |t: &Term| Term {
        coefficient: 0.0,
        ..t.clone()
    };
    let mut merged: Vec<Term> = Vec::new();
    for t in &block.terms {
        match merged.iter_mut().find(|m| factors(m) == factors(t)) {
            Some(m) => m.coefficient += t.coefficient,
            None => merged.push(t.clone()),
        }
    }
    merged.iter().all(|t| {
        let Some(trial) = t.trial_derivative else {
            return false;
        };
        let swapped = Term {
            test_derivative: trial,
            trial_derivative: Some(t.test_derivative),
            ..t.clone()
        };
        t.coefficient == 0.0 || merged.contains(&swapped)
    })
}

/// (rows, columns) of a block's element matrix (columns 1 for a vector).
fn shape(backend: &dyn CellBackend, block: &Block, symbols: &Symbols) -> (usize, usize) {
    let rows = backend.dof_count(symbols.fields[block.test_field].element);
    let cols = block
        .trial_field
        .map_or(1, |f| backend.dof_count(symbols.fields[f].element));
    (rows, cols)
}

/// First doc line of a kernel; `cell` is added after the form (e.g. " on triangles").
fn doc_title(block: &Block, symbols: &Symbols, form: &str, cell: &str) -> String {
    let test_element = symbols.fields[block.test_field].element;
    let test = &symbols.fields[block.test_field].test_name;
    match block.trial_field {
        Some(f) => format!(
            " Block ({test}, {}) of `{form}`{cell}: rows {test} ({}), columns {} ({}).",
            symbols.fields[f].name,
            test_element.name(),
            symbols.fields[f].name,
            symbols.fields[f].element.name()
        ),
        None => format!(" Block {test} of `{form}`{cell} ({}).", test_element.name()),
    }
}

/// Quadrature loops for the data terms of a block, one per (data set, rule), with the
/// largest number of points used.
fn data_loops(
    backend: &dyn CellBackend,
    block: &Block,
    symbols: &Symbols,
    terms: &[&Term],
) -> (Vec<TokenStream>, usize) {
    let mut groups: Vec<(&[usize], Rule, Vec<&Term>)> = Vec::new();
    for &term in terms {
        let rule = backend.rule(backend.term_degree(term, block, symbols));
        match groups
            .iter_mut()
            .find(|(d, r, _)| *d == term.data.as_slice() && *r == rule)
        {
            Some(g) => g.2.push(term),
            None => groups.push((&term.data, rule, vec![term])),
        }
    }
    let points = groups.iter().map(|(_, r, _)| r.len()).max().unwrap_or(0);
    let loops = groups
        .iter()
        .map(|(data, rule, terms)| quadrature_loop(backend, block, symbols, data, rule, terms))
        .collect();
    (loops, points)
}

/// One loop over the points of `rule`: the data product `Π d(xq)` evaluated once per
/// point, then each term's contribution `w·c · D^β φᵢ · D^γ ψⱼ` added to `k`, with the
/// basis values read from compile-time tables.
fn quadrature_loop(
    backend: &dyn CellBackend,
    block: &Block,
    symbols: &Symbols,
    data: &[usize],
    rule: &Rule,
    terms: &[&Term],
) -> TokenStream {
    let nq = rule.len();
    let (rows, cols) = shape(backend, block, symbols);
    let test_element = symbols.fields[block.test_field].element;
    let trial_element = block.trial_field.map(|f| symbols.fields[f].element);
    let mut tables: Vec<TokenStream> = Vec::new();
    let mut made: Vec<(ElementKind, [u8; 2])> = Vec::new();
    let mut table = |element: ElementKind, derivative: [u8; 2]| -> Ident {
        let ident = backend.table_ident(element, derivative);
        if !made.contains(&(element, derivative)) {
            made.push((element, derivative));
            let n = backend.dof_count(element);
            let rows_code = backend
                .tabulate(element, derivative, rule)
                .into_iter()
                .map(|row| {
                    let values = row.into_iter().map(float);
                    quote!([#(#values),*])
                });
            tables.push(quote! {
                const #ident: [[f64; #n]; #nq] = [#(#rows_code),*];
            });
        }
        ident
    };
    let mut body = Vec::new();
    for term in terms {
        let c = backend.data_term_coefficient(term);
        let test = backend.basis_value(test_element, term.test_derivative, quote!(i), &mut table);
        let accumulate = match (trial_element, term.trial_derivative) {
            (Some(e), Some(dv)) => {
                let trial = backend.basis_value(e, dv, quote!(j), &mut table);
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
    let argument = backend.data_argument();
    let data_product = product(data.iter().map(|&i| quote!(d[#i](#argument))));
    let points = backend.points_const(rule);
    let weights = rule.weights.iter().map(|&v| float(v));
    let point = backend.physical_point();
    let weight_factor = backend.weight_factor().map(|f| quote!(* #f));
    quote! {
        {
            #points
            const W: [f64; #nq] = [#(#weights),*];
            #(#tables)*
            for q in 0..#nq {
                #point
                let w = W[q] #weight_factor * #data_product;
                #(#body)*
            }
        }
    }
}

/// The non-negligible `name · literal` products of entry `(i, j)` of reference tables
/// (relative to each table's largest entry, so rounding residue is not emitted).
fn literal_products(tables: &[(Ident, Vec<Vec<f64>>)], i: usize, j: usize) -> Vec<TokenStream> {
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

/// Above this many `scalar · literal` products, the entries are computed by a loop over
/// literal tables (`table_entries`) instead of one statement per entry: the
/// straight-line code of the Argyris stiffness (3845 products) is larger than the
/// instruction cache and was most of the kernel's time (docs/mathematics.md §9).
const TABLE_LOOP_PRODUCTS: usize = 1024;

/// Assignments of the entries: `(k[i][j] + Σ scalar · literal) · h^{sᵢ + sⱼ}`, skipping
/// entries that stay as the loops left them. For a `symmetric` block (see
/// [`is_symmetric`]; its tables are symmetric) only the entries on and above the
/// diagonal are computed, then mirrored.
fn entries(
    backend: &dyn CellBackend,
    block: &Block,
    symbols: &Symbols,
    tables: &[(Ident, Vec<Vec<f64>>)],
    has_data: bool,
    symmetric: bool,
) -> Vec<TokenStream> {
    let (rows, cols) = shape(backend, block, symbols);
    let test_element = symbols.fields[block.test_field].element;
    let trial_element = block.trial_field.map(|f| symbols.fields[f].element);
    let scaling = |i: usize, j: usize| {
        backend.dof_scaling(test_element, i)
            + trial_element.map_or(0, |e| backend.dof_scaling(e, j))
    };
    let first_column = |i: usize| if symmetric { i } else { 0 };
    let products: usize = (0..rows)
        .flat_map(|i| (first_column(i)..cols).map(move |j| (i, j)))
        .map(|(i, j)| literal_products(tables, i, j).len())
        .sum();
    let unscaled = (0..rows).all(|i| (0..cols).all(|j| scaling(i, j) == 0));
    let mirror = symmetric.then(|| {
        quote! {
            for i in 1..#rows {
                for j in 0..i {
                    k[i][j] = k[j][i];
                }
            }
        }
    });
    if products > TABLE_LOOP_PRODUCTS && unscaled {
        let mut entries = vec![table_entries(tables, rows, cols, has_data, symmetric)];
        entries.extend(mirror);
        return entries;
    }
    let mut entries = Vec::new();
    for i in 0..rows {
        for j in first_column(i)..cols {
            let sum = literal_products(tables, i, j);
            let scale = power(quote!(h), scaling(i, j));
            let value = match (has_data, sum.is_empty(), &scale) {
                (false, true, _) | (true, true, None) => continue,
                (true, true, Some(_)) => quote!(k[#i][#j]),
                (false, false, _) => quote!(#(#sum)+*),
                (true, false, _) => quote!(k[#i][#j] + #(#sum)+*),
            };
            let value = match scale {
                Some(s) => quote!((#value) * #s),
                None => value,
            };
            entries.push(quote!(k[#i][#j] = #value;));
        }
    }
    entries.extend(mirror);
    entries
}

/// The entries as a loop over the literal tables, each stored as one constant array
/// (negligible literals as zeros, as `literal_products` skips them): per row, a loop
/// over its columns adding `Σ scalar · table[i][j]`, which the compiler vectorizes.
/// A `symmetric` block stores and computes only the entries with `j ≥ i`, row after
/// row (the caller mirrors them).
fn table_entries(
    tables: &[(Ident, Vec<Vec<f64>>)],
    rows: usize,
    cols: usize,
    has_data: bool,
    symmetric: bool,
) -> TokenStream {
    let first_column = |i: usize| if symmetric { i } else { 0 };
    let stored: usize = (0..rows).map(|i| cols - first_column(i)).sum();
    let count = tables.len();
    let packed = tables.iter().map(|(_, table)| {
        let scale = table.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        let values = (0..rows).flat_map(|i| {
            table[i][first_column(i)..]
                .iter()
                .map(move |&r| float(if r.abs() > 1e-14 * scale { r } else { 0.0 }))
        });
        quote!([#(#values),*])
    });
    let names: Vec<Ident> = (0..count).map(|n| format_ident!("t{}", n)).collect();
    let slices = names
        .iter()
        .enumerate()
        .map(|(n, t)| quote!(let #t = &TABLES[#n][o..o + n];));
    let terms = tables
        .iter()
        .zip(&names)
        .map(|((s, _), t)| quote!(#s * #t[j]));
    let start = if has_data {
        quote!(row[j] + )
    } else {
        quote!()
    };
    let first = if symmetric { quote!(i) } else { quote!(0) };
    quote! {
        {
            const TABLES: [[f64; #stored]; #count] = [#(#packed),*];
            let mut o = 0usize;
            for i in 0..#rows {
                let row = &mut k[i][#first..];
                let n = row.len();
                #(#slices)*
                for j in 0..n {
                    row[j] = #start #(#terms)+*;
                }
                o += n;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn term(coefficient: f64, test: [u8; 2], trial: [u8; 2]) -> Term {
        Term {
            coefficient,
            params: vec![],
            h_power: 0,
            divisors: vec![],
            data: vec![],
            test_derivative: test,
            trial_derivative: Some(trial),
            quadrature_degree: None,
            normal: [0, 0],
        }
    }

    fn block(terms: Vec<Term>) -> Block {
        Block {
            test_field: 0,
            trial_field: Some(0),
            terms,
        }
    }

    const X: [u8; 2] = [1, 0];
    const Y: [u8; 2] = [0, 1];
    const VALUE: [u8; 2] = [0, 0];

    #[test]
    fn symmetry_is_decided_on_the_terms() {
        // ∫ ∇w·∇v, and ∫ ∂x w ∂y v + ∂y w ∂x v: symmetric
        assert!(is_symmetric(&block(vec![term(1.0, X, X), term(1.0, Y, Y)])));
        assert!(is_symmetric(&block(vec![term(2.0, X, Y), term(2.0, Y, X)])));
        // ∫ ∂x w v (trial ∂x, test value) and ∫ ∂x w ∂y v alone: not symmetric
        assert!(!is_symmetric(&block(vec![term(1.0, VALUE, X)])));
        assert!(!is_symmetric(&block(vec![term(1.0, Y, X)])));
        // the swapped term with another coefficient, parameter or datum: not symmetric
        assert!(!is_symmetric(&block(vec![
            term(2.0, X, Y),
            term(1.0, Y, X)
        ])));
        let mut with_param = term(1.0, Y, X);
        with_param.params = vec![(0, 1)];
        assert!(!is_symmetric(&block(vec![term(1.0, X, Y), with_param])));
        let mut with_data = term(1.0, Y, X);
        with_data.data = vec![0];
        assert!(!is_symmetric(&block(vec![term(1.0, X, Y), with_data])));
        // equal factors are summed first: 1 + 1 against 2 is symmetric
        assert!(is_symmetric(&block(vec![
            term(1.0, X, Y),
            term(1.0, X, Y),
            term(2.0, Y, X)
        ])));
        // a symmetric part does not hide a non-symmetric one
        assert!(!is_symmetric(&block(vec![
            term(1.0, X, X),
            term(1.0, VALUE, X)
        ])));
        // blocks of two fields and linear forms are never symmetric
        let mut two_fields = block(vec![term(1.0, X, X)]);
        two_fields.trial_field = Some(1);
        assert!(!is_symmetric(&two_fields));
        let mut linear = block(vec![term(1.0, X, X)]);
        linear.trial_field = None;
        linear.terms[0].trial_derivative = None;
        assert!(!is_symmetric(&linear));
    }
}
