//! Indicator kernels of a declared estimator (`estimator.rs`) on affine triangles.
//!
//! `estimator::cell(x, c, p, d)` returns a cell's `η_T²`: each term's residual
//! `R = Σ c·D^α u + data` is evaluated at the points of a triangle rule exact for `R²`
//! (data counted with their declared degree) from compile-time tables of the reference
//! basis derivatives, `D^α` mapped to the cell by `K = J⁻¹` as in the form kernels, and
//! `weight · Σ_q w_q R(x_q)² |det J|` is summed. `estimator::edge(x, edge, c, y,
//! other, e, p, d)` returns an interior edge's `η_E²`: the edge is local edge `edge` of
//! the cell `x` (coefficients `c`, the `+` side, whose outward normal is `n`) and local
//! edge `other` of its neighbour `y` (coefficients `e`); the jump `X⁺ − X⁻` is
//! evaluated at Gauss–Legendre points of the edge, matched on the two sides whichever
//! way the neighbour runs along it. `h` is the cell's longest edge in `cell`; in `edge`
//! it is the edge's length in the weight and each side's longest edge inside the jump
//! (a Stenberg-weighted shear force on each side). Neither allocates.

use super::emit::{coefficient, float, power, product};
use super::triangle::{derivatives, k_polynomial_code, rule_for_degree, t_ident, transform};
use crate::analysis::Symbols;
use crate::estimator::{Estimator, IndicatorTerm, Region};
use crate::symbolic::{Expansion, Monomial};
use fem_reference::ElementKind;
use proc_macro2::{Ident, TokenStream};
use quote::{format_ident, quote};

/// The physical derivatives the residuals of `terms` take, without the identity.
fn alphas<'a>(terms: impl Iterator<Item = &'a IndicatorTerm>) -> Vec<[u8; 2]> {
    let mut alphas: Vec<[u8; 2]> = terms
        .flat_map(|t| {
            t.residual
                .iter()
                .flat_map(|m| m.args.iter().map(|a| a.derivative))
        })
        .filter(|a| *a != [0, 0])
        .collect();
    alphas.sort();
    alphas.dedup();
    alphas
}

/// `let t_αβ = …;` for every physical derivative used, named with `suffix` (one set per
/// side of an edge), from `K` named `k00 … k11` in scope.
fn t_lets(alphas: &[[u8; 2]], suffix: &str) -> Vec<TokenStream> {
    let mut lets = Vec::new();
    for &alpha in alphas {
        for (beta, poly) in transform(alpha) {
            let ident = format_ident!("{}{}", t_ident(alpha, beta), suffix);
            let value = k_polynomial_code(&poly);
            lets.push(quote!(let #ident: f64 = #value;));
        }
    }
    lets
}

/// The degree the Gauss rule of a cell term is exact for: its `[degree=N]`, else that
/// of the squared residual (exact).
pub(super) fn cell_rule_degree(term: &IndicatorTerm, symbols: &Symbols) -> usize {
    term.quadrature_degree
        .unwrap_or_else(|| 2 * residual_degree(&term.residual, symbols))
}

/// The polynomial degree of a residual on the cell (of the monomial of highest degree).
pub(super) fn residual_degree(residual: &Expansion, symbols: &Symbols) -> usize {
    residual
        .iter()
        .map(|m| {
            let field = m.args.first().map_or(0, |a| {
                let degree = symbols.fields[a.symbol].element.degree();
                degree.saturating_sub(a.order() as usize)
            });
            field + m.data.iter().map(|&d| symbols.data[d].1).sum::<usize>()
        })
        .max()
        .unwrap_or(0)
}

/// The coefficient of a monomial as code: numbers, parameters, `h`, divisors, normals.
pub(super) fn monomial_coefficient(m: &Monomial) -> TokenStream {
    let mut factors = vec![coefficient(
        m.coefficient,
        &m.params,
        m.h_power,
        &m.divisors,
    )];
    factors.extend(power(quote!(n_x), i32::from(m.normal[0])));
    factors.extend(power(quote!(n_y), i32::from(m.normal[1])));
    product(factors)
}

/// A term's weight as code (a sum of scalar monomials).
pub(super) fn weight_code(weight: &Expansion) -> TokenStream {
    let parts = weight.iter().map(monomial_coefficient);
    quote!((#(#parts)+*))
}

/// The values of a basis at a reference point.
type AtPoint<'a> = &'a dyn Fn([f64; 2]) -> Vec<f64>;

/// A table's rows as code, from the basis values at each of its points.
type Rows<'a> = &'a dyn Fn(AtPoint) -> TokenStream;

/// Compile-time tables of reference basis derivatives, made on demand.
struct Tables {
    items: Vec<TokenStream>,
    made: Vec<(ElementKind, [u8; 2], &'static str)>,
}

impl Tables {
    /// The table of `element`'s `beta` derivatives at `points` (one row per point, or
    /// per edge and point), named with `tag`.
    fn get(
        &mut self,
        element: ElementKind,
        beta: [u8; 2],
        tag: &'static str,
        rows: Rows,
        shape: &dyn Fn(usize) -> TokenStream,
    ) -> Ident {
        let ident = format_ident!(
            "PHI{}_{}_D{}{}",
            tag,
            element.name().to_uppercase(),
            beta[0],
            beta[1]
        );
        if !self.made.contains(&(element, beta, tag)) {
            self.made.push((element, beta, tag));
            let basis = derivatives(element, beta);
            let n = basis.len();
            let values = rows(&|x| basis.iter().map(|p| p.eval(x)).collect());
            let ty = shape(n);
            self.items.push(quote!(const #ident: #ty = #values;));
        }
        ident
    }
}

/// `Σ_i c[i] · D^α φ_i` at the current point: `lookup(table)` indexes a table at the
/// point, `suffix` names the side's `T_αβ`.
fn field_value(
    element: ElementKind,
    alpha: [u8; 2],
    coefficients: TokenStream,
    suffix: &str,
    table: &mut dyn FnMut(ElementKind, [u8; 2]) -> TokenStream,
) -> TokenStream {
    let n = element.triangle_basis().len();
    let parts: Vec<TokenStream> = transform(alpha)
        .into_iter()
        .map(|(beta, _)| {
            let t = table(element, beta);
            if alpha == [0, 0] {
                quote!(#t[i])
            } else {
                let factor = format_ident!("{}{}", t_ident(alpha, beta), suffix);
                quote!(#factor * #t[i])
            }
        })
        .collect();
    quote!({
        let c = #coefficients;
        let mut v = 0.0f64;
        for i in 0..#n {
            v += c[i] * (#(#parts)+*);
        }
        v
    })
}

/// The data product of a monomial at the point `xq`.
pub(super) fn data_product(m: &Monomial) -> Option<TokenStream> {
    (!m.data.is_empty()).then(|| product(m.data.iter().map(|&i| quote!(d[#i](&xq)))))
}

/// The loop of one cell term: `weight · Σ_q w_q R(x_q)² |det J|` added to `eta2`.
fn cell_term(term: &IndicatorTerm, symbols: &Symbols) -> TokenStream {
    let rule = rule_for_degree(cell_rule_degree(term, symbols));
    let nq = rule.points.len();
    let mut tables = Tables {
        items: Vec::new(),
        made: Vec::new(),
    };
    let points = rule.points.clone();
    let mut body = Vec::new();
    for m in &term.residual {
        let c = monomial_coefficient(m);
        let data = data_product(m);
        let value = match m.args.first() {
            Some(a) => {
                let element = symbols.fields[a.symbol].element;
                let field = a.symbol;
                let mut table = |e: ElementKind, beta: [u8; 2]| -> TokenStream {
                    let ident = tables.get(
                        e,
                        beta,
                        "",
                        &|f| {
                            let rows = points.iter().map(|&x| {
                                let v = f(x).into_iter().map(float);
                                quote!([#(#v),*])
                            });
                            quote!([#(#rows),*])
                        },
                        &|n| quote!([[f64; #n]; #nq]),
                    );
                    quote!(#ident[q])
                };
                Some(field_value(
                    element,
                    a.derivative,
                    quote!(c[#field]),
                    "",
                    &mut table,
                ))
            }
            None => None,
        };
        let factors = std::iter::once(c).chain(data).chain(value);
        let p = product(factors);
        body.push(quote!(r += #p;));
    }
    let weights = rule.weights.iter().map(|&w| float(w));
    let xi = rule.points.iter().map(|&[a, b]| {
        let (a, b) = (float(a), float(b));
        quote!([#a, #b])
    });
    let uses_data = term.residual.iter().any(|m| !m.data.is_empty());
    let point = uses_data.then(|| {
        quote! {
            let xq = [
                x[0] + j00 * XI[q][0] + j01 * XI[q][1],
                x[1] + j10 * XI[q][0] + j11 * XI[q][1],
            ];
        }
    });
    let weight = weight_code(&term.weight);
    let items = &tables.items;
    let doc = &term.source;
    quote! {
        {
            #[doc = #doc]
            const XI: [[f64; 2]; #nq] = [#(#xi),*];
            const W: [f64; #nq] = [#(#weights),*];
            #(#items)*
            let mut s = 0.0f64;
            for q in 0..#nq {
                #point
                let mut r = 0.0f64;
                #(#body)*
                s += W[q] * r * r;
            }
            eta2 += #weight * s * area2;
        }
    }
}

/// `r += …` of a term of data alone in an average (a jump refuses it): continuous, the
/// mean of the two sides' coefficients (which may hold each side's `h`, `h_p` and
/// `h_m` in scope) times its value at `xq`.
pub(super) fn averaged_data(m: &Monomial) -> TokenStream {
    let c = monomial_coefficient(m);
    let data = data_product(m);
    let mean = quote!((0.5 * ({ let h = h_p; #c } + { let h = h_m; #c })));
    let p = product(std::iter::once(mean).chain(data));
    quote!(r += #p;)
}

/// A table's rows on each local edge of the reference triangle: the basis values `f` at
/// the edge parameters `s_of(s)` for the rule's points `s` (one block of rows per edge).
fn edge_rows(points: &[f64], s_of: &dyn Fn(f64) -> f64, f: AtPoint) -> TokenStream {
    let edges = (0..3).map(|edge| {
        let rows = points.iter().map(|&s| {
            let v = f(super::facet::edge_point(edge, s_of(s)))
                .into_iter()
                .map(float);
            quote!([#(#v),*])
        });
        quote!([#(#rows),*])
    });
    quote!([#(#edges),*])
}

/// The loop of one edge term: `weight · Σ_q w_q [[X]](x_q)² |E|` added to `eta2`.
fn edge_term(term: &IndicatorTerm, symbols: &Symbols) -> TokenStream {
    let degree = 2 * residual_degree(&term.residual, symbols);
    let nq = fem_reference::quadrature::QuadratureRule::exact_for_degree(degree).len();
    let rule = fem_reference::quadrature::gauss_legendre(nq);
    let mut tables = Tables {
        items: Vec::new(),
        made: Vec::new(),
    };
    let per_edge = |s_of: &dyn Fn(f64) -> f64, f: AtPoint| edge_rows(&rule.points, s_of, f);
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
        let mut plus_table = |e: ElementKind, beta: [u8; 2]| -> TokenStream {
            let ident = tables.get(
                e,
                beta,
                "",
                &|f| per_edge(&|s| s, f),
                &|n| quote!([[[f64; #n]; #nq]; 3]),
            );
            quote!(#ident[edge][q])
        };
        let plus = field_value(
            element,
            a.derivative,
            quote!(c[#field]),
            "_p",
            &mut plus_table,
        );
        let mut minus_table = |e: ElementKind, beta: [u8; 2]| -> TokenStream {
            let along = tables.get(
                e,
                beta,
                "",
                &|f| per_edge(&|s| s, f),
                &|n| quote!([[[f64; #n]; #nq]; 3]),
            );
            let against = tables.get(
                e,
                beta,
                "_REVERSED",
                &|f| per_edge(&|s| 1.0 - s, f),
                &|n| quote!([[[f64; #n]; #nq]; 3]),
            );
            quote!((if reversed { #against[other][q] } else { #along[other][q] }))
        };
        let minus = field_value(
            element,
            a.derivative,
            quote!(e[#field]),
            "_m",
            &mut minus_table,
        );
        // inside a jump or an average `h` is each side's cell size
        let jump = if term.average {
            quote!((0.5 * ({ let h = h_p; #c } * #plus + { let h = h_m; #c } * #minus)))
        } else {
            quote!(({ let h = h_p; #c } * #plus - { let h = h_m; #c } * #minus))
        };
        let p = product(data.into_iter().chain(std::iter::once(jump)));
        body.push(quote!(r += #p;));
    }
    let weights = rule.weights.iter().map(|&w| float(w));
    let uses_data = term.residual.iter().any(|m| !m.data.is_empty());
    let point = uses_data.then(|| {
        let s = rule.points.iter().map(|&s| float(s));
        quote! {
            const S: [f64; #nq] = [#(#s),*];
            let xq = [
                x[2 * a] + S[q] * (x[2 * b] - x[2 * a]),
                x[2 * a + 1] + S[q] * (x[2 * b + 1] - x[2 * a + 1]),
            ];
        }
    });
    let weight = weight_code(&term.weight);
    let items = &tables.items;
    let doc = &term.source;
    quote! {
        {
            #[doc = #doc]
            const W: [f64; #nq] = [#(#weights),*];
            #(#items)*
            let mut s = 0.0f64;
            for q in 0..#nq {
                #point
                let mut r = 0.0f64;
                #(#body)*
                s += W[q] * r * r;
            }
            eta2 += #weight * s * len;
        }
    }
}

/// The loop of one boundary term: `weight · Σ_q w_q R(x_q)² |E|` added to `eta2`, `R`
/// traced from the edge's cell `x` (coefficients `c`) at Gauss–Legendre points of its
/// local edge `edge`, data evaluated at the physical points.
fn boundary_term(term: &IndicatorTerm, symbols: &Symbols) -> TokenStream {
    let degree = 2 * residual_degree(&term.residual, symbols);
    let nq = fem_reference::quadrature::QuadratureRule::exact_for_degree(degree).len();
    let rule = fem_reference::quadrature::gauss_legendre(nq);
    let mut tables = Tables {
        items: Vec::new(),
        made: Vec::new(),
    };
    let mut body = Vec::new();
    for m in &term.residual {
        // inside the norm `h` is the cell's size, in the weight the edge's length
        let c = monomial_coefficient(m);
        let c = quote!({ let h = h_c; #c });
        let data = data_product(m);
        let value = m.args.first().map(|a| {
            let element = symbols.fields[a.symbol].element;
            let field = a.symbol;
            let mut table = |e: ElementKind, beta: [u8; 2]| -> TokenStream {
                let ident = tables.get(
                    e,
                    beta,
                    "",
                    &|f| edge_rows(&rule.points, &|s| s, f),
                    &|n| quote!([[[f64; #n]; #nq]; 3]),
                );
                quote!(#ident[edge][q])
            };
            field_value(element, a.derivative, quote!(c[#field]), "", &mut table)
        });
        let p = product(std::iter::once(c).chain(data).chain(value));
        body.push(quote!(r += #p;));
    }
    let weights = rule.weights.iter().map(|&w| float(w));
    let s = rule.points.iter().map(|&s| float(s));
    let weight = weight_code(&term.weight);
    let items = &tables.items;
    let doc = &term.source;
    quote! {
        {
            #[doc = #doc]
            const W: [f64; #nq] = [#(#weights),*];
            const S: [f64; #nq] = [#(#s),*];
            #(#items)*
            let mut s = 0.0f64;
            for q in 0..#nq {
                let xq = [
                    x[2 * a] + S[q] * (x[2 * b] - x[2 * a]),
                    x[2 * a + 1] + S[q] * (x[2 * b + 1] - x[2 * a + 1]),
                ];
                let mut r = 0.0f64;
                #(#body)*
                s += W[q] * r * r;
            }
            eta2 += #weight * s * len;
        }
    }
}

/// `K = J⁻¹` of the triangle `#x` as `k00 … k11`, with `det`.
fn inverse_jacobian(x: &Ident) -> TokenStream {
    quote! {
        let (j00, j01) = (#x[2] - #x[0], #x[4] - #x[0]);
        let (j10, j11) = (#x[3] - #x[1], #x[5] - #x[1]);
        let det = j00 * j11 - j01 * j10;
        let inv = 1.0 / det;
        let (k00, k01, k10, k11) = (j11 * inv, -j01 * inv, -j10 * inv, j00 * inv);
    }
}

/// The module `estimator` of a model with an `estimator:` text: the kernels `cell` and
/// `edge`.
pub fn module(estimator: &Estimator, symbols: &Symbols, runtime: &TokenStream) -> TokenStream {
    let nf = symbols.fields.len();
    let np = symbols.params.len();
    let nd = symbols.data.len();
    let cell_terms: Vec<TokenStream> = estimator
        .terms(Region::Cell)
        .map(|t| cell_term(t, symbols))
        .collect();
    let edge_terms: Vec<TokenStream> = estimator
        .terms(Region::Edge)
        .map(|t| edge_term(t, symbols))
        .collect();
    let describe = |region: Region| {
        estimator
            .terms(region)
            .map(|t| format!("`{}`", t.source))
            .collect::<Vec<_>>()
            .join(" + ")
    };
    let parts: Vec<TokenStream> = symbols
        .facets
        .iter()
        .enumerate()
        .map(|(k, _)| {
            let terms = estimator
                .terms(Region::Boundary(k))
                .map(|t| boundary_term(t, symbols));
            quote!(#k => { #(#terms)* })
        })
        .chain((0..estimator.natural.len()).map(|k| {
            let index = symbols.facets.len() + k;
            let terms = estimator
                .terms(Region::Natural(k))
                .map(|t| boundary_term(t, symbols));
            quote!(#index => { #(#terms)* })
        }))
        .collect();
    let boundary_lets = t_lets(
        &alphas(
            estimator
                .terms
                .iter()
                .filter(|t| matches!(t.region, Region::Boundary(_) | Region::Natural(_))),
        ),
        "",
    );
    let boundary_doc = {
        let lines: Vec<String> = symbols
            .facets
            .iter()
            .enumerate()
            .map(|(k, name)| match describe(Region::Boundary(k)) {
                s if s.is_empty() => format!("`{name}` (part {k}): no term (0)"),
                s => format!("`{name}` (part {k}): {s}"),
            })
            .chain(estimator.natural.iter().enumerate().map(|(k, &(i, j))| {
                format!(
                    "the natural boundary of `{}`{} (part {}): {} one-sided",
                    symbols.fields[i].test_name,
                    if j == 0 { "" } else { "'s normal derivative" },
                    symbols.facets.len() + k,
                    describe(Region::Natural(k))
                )
            }))
            .collect();
        format!(
            " The squared indicator `η_Γ²` of the boundary edge that is local edge `edge` of the triangle `x` with coefficients `c`, on the boundary part `part` (its index under `facets:`); `n` is the outward normal, `h` the edge's length in the weight and the cell's size inside the norm. {}.",
            if lines.is_empty() { "The model declares no boundary part and has no natural boundary term (0)".to_string() } else { lines.join("; ") }
        )
    };
    let cell_lets = t_lets(&alphas(estimator.terms(Region::Cell)), "");
    let edge_alphas = alphas(estimator.terms(Region::Edge));
    let (plus_lets, minus_lets) = (t_lets(&edge_alphas, "_p"), t_lets(&edge_alphas, "_m"));
    let cell_doc = format!(
        " The squared indicator `η_T²` of the triangle `x` (`[x0, y0, x1, y1, x2, y2]`) for the coefficients `c`: one slice per field, the cell's coefficients in the pulled-back reference basis (the local DOFs for Lagrange elements, `Mᵀ U` for elements with a DOF transformation `M`): {}.",
        match describe(Region::Cell) {
            s if s.is_empty() => "no cell term (0)".to_string(),
            s => s,
        }
    );
    let edge_doc = format!(
        " The squared indicator `η_E²` of the interior edge that is local edge `edge` (joining local vertices `edge` and `(edge + 1) % 3`) of the triangle `x` with coefficients `c` and local edge `other` of its neighbour `y` with coefficients `e`; `n` is the outward normal of `x`, `h` the edge's length: {}.",
        match describe(Region::Edge) {
            s if s.is_empty() => "no edge term (0)".to_string(),
            s => s,
        }
    );
    let x = format_ident!("x");
    let y = format_ident!("y");
    let kx = inverse_jacobian(&x);
    let ky = inverse_jacobian(&y);
    quote! {
        /// The indicator kernels of the model's `estimator:` text.
        pub mod estimator {
            #[doc = #cell_doc]
            #[allow(unused_variables, unused_mut, unused_parens, clippy::all)]
            pub fn cell(x: &[f64; 6], c: &[&[f64]; #nf], p: &[f64; #np], d: &[&#runtime::DataFn; #nd]) -> f64 {
                #kx
                let area2 = det.abs();
                let h = {
                    let e0 = j00 * j00 + j10 * j10;
                    let e1 = j01 * j01 + j11 * j11;
                    let (dx, dy) = (x[4] - x[2], x[5] - x[3]);
                    e0.max(e1).max(dx * dx + dy * dy).sqrt()
                };
                #(#cell_lets)*
                let mut eta2 = 0.0f64;
                #(#cell_terms)*
                eta2
            }

            #[doc = #edge_doc]
            ///
            /// # Panics
            /// When `edge > 2` or `other > 2`.
            #[allow(unused_variables, unused_mut, unused_parens, clippy::all, clippy::too_many_arguments)]
            pub fn edge(
                x: &[f64; 6],
                edge: usize,
                c: &[&[f64]; #nf],
                y: &[f64; 6],
                other: usize,
                e: &[&[f64]; #nf],
                p: &[f64; #np],
                d: &[&#runtime::DataFn; #nd],
            ) -> f64 {
                assert!(edge < 3 && other < 3, "a triangle has local edges 0, 1 and 2");
                // each side's size, as the cell kernel's `h`: its longest edge
                let diameter = |z: &[f64; 6]| {
                    let e = |a: usize, b: usize| {
                        (z[2 * b] - z[2 * a]).powi(2) + (z[2 * b + 1] - z[2 * a + 1]).powi(2)
                    };
                    e(0, 1).max(e(1, 2)).max(e(2, 0)).sqrt()
                };
                let (h_p, h_m) = (diameter(x), diameter(y));
                let (a, b) = (edge, (edge + 1) % 3);
                let (tx, ty) = (x[2 * b] - x[2 * a], x[2 * b + 1] - x[2 * a + 1]);
                let len = (tx * tx + ty * ty).sqrt();
                // the neighbour runs along the edge from `a` (same direction) or from `b`
                let reversed = !(y[2 * other] == x[2 * a] && y[2 * other + 1] == x[2 * a + 1]);
                {
                    #kx
                    // The edge's right-hand normal points out of a counter-clockwise cell.
                    let side = if det > 0.0 { 1.0 } else { -1.0 };
                    let (n_x, n_y) = (side * ty / len, -side * tx / len);
                    let h = len;
                    #(#plus_lets)*
                    {
                        #ky
                        #(#minus_lets)*
                        let mut eta2 = 0.0f64;
                        #(#edge_terms)*
                        eta2
                    }
                }
            }

            #[doc = #boundary_doc]
            ///
            /// # Panics
            /// When `edge > 2`.
            #[allow(unused_variables, unused_mut, unused_parens, clippy::all)]
            pub fn boundary(
                part: usize,
                x: &[f64; 6],
                edge: usize,
                c: &[&[f64]; #nf],
                p: &[f64; #np],
                d: &[&#runtime::DataFn; #nd],
            ) -> f64 {
                assert!(edge < 3, "a triangle has local edges 0, 1 and 2");
                let h_c = {
                    let e = |a: usize, b: usize| {
                        (x[2 * b] - x[2 * a]).powi(2) + (x[2 * b + 1] - x[2 * a + 1]).powi(2)
                    };
                    e(0, 1).max(e(1, 2)).max(e(2, 0)).sqrt()
                };
                let (a, b) = (edge, (edge + 1) % 3);
                let (tx, ty) = (x[2 * b] - x[2 * a], x[2 * b + 1] - x[2 * a + 1]);
                let len = (tx * tx + ty * ty).sqrt();
                #kx
                let side = if det > 0.0 { 1.0 } else { -1.0 };
                let (n_x, n_y) = (side * ty / len, -side * tx / len);
                let h = len;
                #(#boundary_lets)*
                let mut eta2 = 0.0f64;
                match part {
                    #(#parts)*
                    _ => {}
                }
                eta2
            }
        }
    }
}

/// The estimator items of the `Model` impl: `HAS_ESTIMATOR` and the dispatch of
/// `cell_indicator` / `edge_indicator` to the kernels (empty without `estimator:`).
///
/// On intervals (`interval`) a cell has two vertex coordinates and its "edges" are its
/// ends 0 and 1; on triangles six coordinates and edges 0, 1 and 2.
pub fn model_items(
    symbols: &Symbols,
    estimator: &Estimator,
    runtime: &TokenStream,
    model_name: &str,
    interval: bool,
) -> TokenStream {
    let nf = symbols.fields.len();
    let np = symbols.params.len();
    let nd = symbols.data.len();
    let sizes: Vec<usize> = symbols
        .fields
        .iter()
        .map(|f| {
            if interval {
                f.element.basis().len()
            } else {
                f.element.triangle_basis().len()
            }
        })
        .collect();
    let (coordinates, last, cell) = if interval {
        (2usize, 1usize, "an interval")
    } else {
        (6, 2, "a triangle")
    };
    let message = format!("{model_name}: the indicator of {cell} takes {coordinates} vertex coordinates and, per field, its local coefficients ({sizes:?})");
    let sides = format!("{cell} has local edges (ends) 0 to {last}, not {{}} and {{}}");
    // one cell's vertices and coefficients checked into `x` and `c` (cell and boundary
    // indicators)
    let cell_inputs = quote! {
        const SIZES: [usize; #nf] = [#(#sizes),*];
        let (::core::result::Result::Ok(x), ::core::result::Result::Ok(c)) =
            (<&[f64; #coordinates]>::try_from(vertices), <&[&[f64]; #nf]>::try_from(coefficients))
        else {
            return ::core::result::Result::Err(#runtime::Error::Input(#message.into()));
        };
        if c.iter().zip(SIZES).any(|(c, n)| c.len() != n) {
            return ::core::result::Result::Err(#runtime::Error::Input(#message.into()));
        }
    };
    let parts = symbols.facets.len() + estimator.natural.len();
    let natural = estimator.natural.iter().map(|&(i, j)| quote!((#i, #j)));
    // on intervals the parts are the natural ends' terms alone
    let boundary = {
        let wrong_part = format!(
            "{model_name} has boundary parts and natural boundaries 0 to {}, not {{}}",
            parts.saturating_sub(1)
        );
        quote! {
            fn boundary_indicator(
                part: usize,
                vertices: &[f64],
                edge: usize,
                coefficients: &[&[f64]],
                params: &[f64],
                data: &[&#runtime::DataFn],
            ) -> #runtime::Result<f64> {
                #cell_inputs
                if edge > #last {
                    return ::core::result::Result::Err(#runtime::Error::Input(::std::format!(#sides, edge, edge)));
                }
                // a const, not a literal: `part >= 0` is no comparison for a model without parts
                const PARTS: usize = #parts;
                if part >= PARTS {
                    return ::core::result::Result::Err(#runtime::Error::Input(::std::format!(#wrong_part, part)));
                }
                let p: &[f64; #np] = params.try_into().expect("parameter count checked by the runtime");
                let d: &[&#runtime::DataFn; #nd] = data.try_into().expect("data count checked by the runtime");
                ::core::result::Result::Ok(estimator::boundary(part, x, edge, c, p, d))
            }
        }
    };
    quote! {
        const HAS_ESTIMATOR: bool = true;

        fn cell_indicator(
            vertices: &[f64],
            coefficients: &[&[f64]],
            params: &[f64],
            data: &[&#runtime::DataFn],
        ) -> #runtime::Result<f64> {
            #cell_inputs
            let p: &[f64; #np] = params.try_into().expect("parameter count checked by the runtime");
            let d: &[&#runtime::DataFn; #nd] = data.try_into().expect("data count checked by the runtime");
            ::core::result::Result::Ok(estimator::cell(x, c, p, d))
        }

        #[allow(clippy::too_many_arguments)]
        fn edge_indicator(
            vertices: &[f64],
            edge: usize,
            coefficients: &[&[f64]],
            other_vertices: &[f64],
            other_edge: usize,
            other_coefficients: &[&[f64]],
            params: &[f64],
            data: &[&#runtime::DataFn],
        ) -> #runtime::Result<f64> {
            const SIZES: [usize; #nf] = [#(#sizes),*];
            let (
                ::core::result::Result::Ok(x),
                ::core::result::Result::Ok(c),
                ::core::result::Result::Ok(y),
                ::core::result::Result::Ok(e),
            ) = (
                <&[f64; #coordinates]>::try_from(vertices),
                <&[&[f64]; #nf]>::try_from(coefficients),
                <&[f64; #coordinates]>::try_from(other_vertices),
                <&[&[f64]; #nf]>::try_from(other_coefficients),
            )
            else {
                return ::core::result::Result::Err(#runtime::Error::Input(#message.into()));
            };
            if c.iter().chain(e.iter()).zip(SIZES.iter().chain(SIZES.iter())).any(|(c, &n)| c.len() != n) {
                return ::core::result::Result::Err(#runtime::Error::Input(#message.into()));
            }
            if edge > #last || other_edge > #last {
                return ::core::result::Result::Err(#runtime::Error::Input(::std::format!(#sides, edge, other_edge)));
            }
            let p: &[f64; #np] = params.try_into().expect("parameter count checked by the runtime");
            let d: &[&#runtime::DataFn; #nd] = data.try_into().expect("data count checked by the runtime");
            ::core::result::Result::Ok(estimator::edge(x, edge, c, y, other_edge, e, p, d))
        }

        const NATURAL_FLUXES: &'static [(usize, u8)] = &[#(#natural),*];

        #boundary
    }
}
