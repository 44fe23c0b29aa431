//! The model declaration around the forms text, written in Rust tokens:
//!
//! ```text
//! /// docs
//! pub mod NAME on interval {
//!     unknowns: θ: P2, w: P2, λ: P0 >= 0;   // `θ: [P1]^2`: a vector field (triangles)
//!     tests:    η, v, μ;
//!     params:   t, α, s;       // `β > 0` declares a positive parameter (checked at run time)
//!     data:     f, ψ;          // `f: 0` declares f constant for quadrature (default degree 2)
//!     boundary: w = g;         // optional: Dirichlet data, a declared data function
//!     facets:   Γ_C;           // optional (triangles): boundary parts for `∫_Γ_C … ds`
//!     forms:    "…";
//!     // the roles of forms and parameters in the obstacle problem (optional: where a
//!     // section is left out, the names below are taken where the model has them)
//!     system:        B_h, L_h;     // the stabilized system the solvers assemble
//!     energy:        a, ℓ;         // J(u) = ½ a(u,u) − ℓ(u)
//!     stabilization: α S against a; // α's parameter, S_h, and the form C_I bounds it by
//!     side:          s;            // the parameter holding the obstacle side s = ±1
//!     obstacle:      w >= ψ;       // the constrained field and the obstacle: s·w ≥ s·ψ
//!     constraint:    b, G;         // b(v,μ) = (μ, sBv), G(μ) = (μ, sψ)
//!     unit:          n_c;          // the parameters n_c_x, n_c_y form a unit vector
//!     estimator:     "…";          // optional: the residual estimator (η_T², η_E², η_Γ²),
//!                                  // or `derived` (from `a`, `ℓ`, `b`)
//! }
//! ```
//!
//! The cell is `interval` or `triangle`.

use crate::diagnostic::{closest, Diagnostic};
use crate::parser::MAX_DEGREE;
use fem_reference::reference_element::ALL_ELEMENTS;
use fem_reference::{CellKind, ElementKind};
use proc_macro2::{Span, TokenStream, TokenTree};
use syn::parse::{Parse, ParseStream};
use syn::{Attribute, Ident, Lit, LitInt, LitStr, Token, Visibility};

/// Reserved names: the element size, the keywords of the forms text and `I`.
pub const RESERVED: [&str; 19] = [
    "h", "h_T", "int", "sum_T", "Σ_T", "degree", "Model", "grad", "lap", "dot", "d_x", "d_y", "ε",
    "eps", "div", "tr", "I", "ds", "h_E",
];

/// Suffixes of the components of a vector field (`θ_x`, `θ_y`), by axis.
pub const COMPONENT_SUFFIXES: [&str; 2] = ["_x", "_y"];

/// An unknown field: `θ: P2`, `λ: P0 >= 0` or the vector field `θ: [P1]^2`.
#[derive(Clone, Debug)]
pub struct UnknownDecl {
    /// The unknown's name.
    pub name: Ident,
    /// Its element, when the name is one fem-forms knows.
    pub element: Option<ElementKind>,
    /// The element name as written.
    pub element_name: Ident,
    /// `>= 0`: the field is a multiplier constrained to be non-negative.
    pub nonnegative: bool,
    /// `Some((n, span of n))` for a vector field `[P1]^n`, `None` for a scalar one.
    pub vector: Option<(usize, Span)>,
}

impl UnknownDecl {
    /// Number of scalar components: 1, or `n` of `[P1]^n`.
    pub fn components(&self) -> usize {
        self.vector.map_or(1, |(n, _)| n)
    }
}

/// The names of the components of vector `name`: `θ_x`, `θ_y`.
pub fn component_names(name: &str, components: usize) -> Vec<String> {
    COMPONENT_SUFFIXES
        .iter()
        .take(components)
        .map(|s| format!("{name}{s}"))
        .collect()
}

/// A data function: `f` or `f: 0`.
#[derive(Clone, Debug)]
pub struct DataDecl {
    /// Its name.
    pub name: Ident,
    /// Polynomial degree assumed when choosing quadrature.
    pub degree: usize,
}

/// `stabilization: α S against a;`: the parameter α of `B_h = … − α S`, the
/// stabilization form `S` and the form `a` that `C_I` measures it against.
#[derive(Clone, Debug)]
pub struct StabilizationDecl {
    /// The parameter α (absent in `stabilization: S against a`).
    pub alpha: Option<Ident>,
    /// The stabilization form.
    pub form: Ident,
    /// The form it is bounded by (`S_T(v, v) ≤ C_I a_T(v, v)`).
    pub against: Ident,
}

/// The roles the model declares for its forms and parameters (each `None` where its
/// section is left out).
#[derive(Clone, Debug, Default)]
pub struct RolesDecl {
    /// `system: B_h, L_h;`
    pub system: Option<(Ident, Ident)>,
    /// `energy: a, ℓ;`
    pub energy: Option<(Ident, Ident)>,
    /// `stabilization: α S against a;`
    pub stabilization: Option<StabilizationDecl>,
    /// `side: s;`
    pub side: Option<Ident>,
    /// `obstacle: w >= ψ;`: the constrained field and the obstacle's data function.
    pub obstacle: Option<(Ident, Ident)>,
    /// `constraint: b, G;`: the constraint's forms, `b(v, μ) = (μ, sBv)` and
    /// `G(μ) = (μ, sψ)`.
    pub constraint: Option<(Ident, Ident)>,
    /// `unit: n_c;`: vectors of parameters (`n_c_x`, `n_c_y`) that are unit vectors.
    pub unit: Vec<Ident>,
}

/// The `estimator:` section.
#[derive(Clone)]
pub enum EstimatorDecl {
    /// The lines `η_T² = …`, `η_E² = …`, `η_Γ² = …` as written.
    Text(LitStr),
    /// `derived`: the residual estimator of the strong form derived from `a`, `ℓ` and
    /// `b` ([`crate::derived::residual_estimator`]).
    Derived(Span),
}

/// Everything the macro input declares.
#[derive(Clone)]
pub struct Declaration {
    /// Path of the runtime crate that the generated code names (`$crate` of `fem_runtime::model!`).
    pub runtime: TokenStream,
    /// Doc comments and other outer attributes.
    pub attrs: Vec<Attribute>,
    /// Visibility of the generated module.
    pub vis: Visibility,
    /// Name of the generated module.
    pub name: Ident,
    /// The reference cell.
    pub cell: Option<CellKind>,
    /// The cell name as written.
    pub cell_name: Ident,
    /// Unknown fields.
    pub unknowns: Vec<UnknownDecl>,
    /// Test functions, paired with the unknowns in order.
    pub tests: Vec<Ident>,
    /// Runtime scalar parameters.
    pub params: Vec<Ident>,
    /// Indices in `params` of those declared `> 0`.
    pub positive: Vec<usize>,
    /// Data functions of x.
    pub data: Vec<DataDecl>,
    /// Dirichlet conditions `field = data` on the whole boundary.
    pub dirichlet: Vec<(Ident, Ident)>,
    /// Boundary parts named under `facets:` (integrated over by `∫_Γ … ds`).
    pub facets: Vec<Ident>,
    /// The forms text.
    pub forms: LitStr,
    /// The estimator (`estimator: "η_T² = …";` or `estimator: derived;`), if the model
    /// declares one.
    pub estimator: Option<EstimatorDecl>,
    /// The roles of forms and parameters.
    pub roles: RolesDecl,
    /// Span of the section list, for "missing section" errors.
    pub body_span: Span,
}

/// The sections a model may have.
const SECTIONS: [&str; 15] = [
    "unknowns",
    "tests",
    "params",
    "data",
    "boundary",
    "facets",
    "forms",
    "system",
    "energy",
    "stabilization",
    "side",
    "obstacle",
    "constraint",
    "unit",
    "estimator",
];

/// Two names separated by a comma (`B_h, L_h`); `example` for the error.
fn name_pair(input: ParseStream, example: &str) -> syn::Result<(Ident, Ident)> {
    let first: Ident = input.parse()?;
    input.parse::<Token![,]>().map_err(|e| {
        syn::Error::new(e.span(), format!("expected two names, as in `{example};`"))
    })?;
    let second: Ident = input.parse()?;
    Ok((first, second))
}

fn comma_list<T>(
    input: ParseStream,
    mut item: impl FnMut(ParseStream) -> syn::Result<T>,
) -> syn::Result<Vec<T>> {
    let mut out = Vec::new();
    loop {
        out.push(item(input)?);
        if input.peek(Token![,]) {
            input.parse::<Token![,]>()?;
            if input.peek(Token![;]) {
                break;
            }
        } else {
            break;
        }
    }
    Ok(out)
}

/// The runtime's path: `@crate PATH;` before the model (the runtime's own tests), else
/// `::fem_runtime`.
fn runtime_path(input: ParseStream) -> syn::Result<TokenStream> {
    if !input.peek(Token![@]) {
        return Ok(quote::quote!(::fem_runtime));
    }
    input.parse::<Token![@]>()?;
    input.parse::<Token![crate]>()?;
    let mut path = TokenStream::new();
    while !input.peek(Token![;]) {
        path.extend([input.parse::<TokenTree>()?]);
    }
    input.parse::<Token![;]>()?;
    Ok(path)
}

/// One entry of `unknowns:`: `θ: P2`, `u: [P1]^2`, `λ: P0 >= 0`.
fn unknown(s: ParseStream) -> syn::Result<UnknownDecl> {
    let name: Ident = s.parse()?;
    s.parse::<Token![:]>()?;
    let (element_name, vector) = if s.peek(syn::token::Bracket) {
        let inner;
        let brackets = syn::bracketed!(inner in s);
        let element_name: Ident = inner.parse()?;
        if !inner.is_empty() {
            return Err(inner.error(format!(
                "a vector field is declared `{name}: [{element_name}]^2`"
            )));
        }
        if !s.peek(Token![^]) {
            return Err(syn::Error::new(
                brackets.span.join(),
                format!("a vector field is declared `{name}: [{element_name}]^2` (the number of components after `^`)"),
            ));
        }
        s.parse::<Token![^]>()?;
        let n: LitInt = s.parse()?;
        (element_name, Some((n.base10_parse::<usize>()?, n.span())))
    } else {
        (s.parse()?, None)
    };
    if !s.peek(Token![>=]) && (s.peek(Token![<]) || s.peek(Token![>])) {
        let op: TokenTree = s.parse()?;
        return Err(syn::Error::new(
            op.span(),
            format!(
                "only `>= 0` is supported: `{name}: {element_name} >= 0` declares a multiplier {name} ≥ 0. \
                 An upper bound u ≤ ψ is the obstacle seen from the other side: keep `>= 0` and flip the \
                 constraint's sign with a parameter `s = −1` in the forms (as the beams' `b(η,v;μ) = ∫ s v μ`)"
            ),
        ));
    }
    let nonnegative = if s.peek(Token![>=]) {
        s.parse::<Token![>=]>()?;
        let zero: LitInt = s.parse()?;
        if zero.base10_parse::<u64>()? != 0 {
            return Err(syn::Error::new(
                zero.span(),
                "only `>= 0` constraints are supported (multipliers λ ≥ 0)",
            ));
        }
        true
    } else {
        false
    };
    Ok(UnknownDecl {
        element: ElementKind::from_name(&element_name.to_string()),
        name,
        element_name,
        nonnegative,
        vector,
    })
}

/// One entry of `params:`: `t`, or `t > 0` (declared positive).
fn param(s: ParseStream) -> syn::Result<(Ident, bool)> {
    let name: Ident = s.parse()?;
    let positive = if s.peek(Token![>]) && !s.peek(Token![>=]) {
        s.parse::<Token![>]>()?;
        let zero: Lit = s.parse()?;
        let is_zero = match &zero {
            Lit::Int(i) => i.base10_parse::<u64>().is_ok_and(|v| v == 0),
            Lit::Float(f) => f.base10_parse::<f64>().is_ok_and(|v| v == 0.0),
            _ => false,
        };
        if !is_zero {
            return Err(syn::Error::new(
                zero.span(),
                format!("a parameter is declared positive with `{name} > 0`; other bounds are not supported"),
            ));
        }
        true
    } else if s.peek(Token![>=]) || s.peek(Token![<]) || s.peek(Token![<=]) {
        let op: TokenTree = s.parse()?;
        return Err(syn::Error::new(
            op.span(),
            format!("a parameter is declared positive with `{name} > 0`; other bounds are not supported"),
        ));
    } else {
        false
    };
    Ok((name, positive))
}

/// One entry of `data:`: `f`, or `f: 4` (its polynomial degree for quadrature).
fn data_function(s: ParseStream) -> syn::Result<DataDecl> {
    let name: Ident = s.parse()?;
    let degree = if s.peek(Token![:]) {
        s.parse::<Token![:]>()?;
        let literal = s.parse::<LitInt>()?;
        let degree = literal.base10_parse::<usize>()?;
        if degree > MAX_DEGREE {
            return Err(syn::Error::new(
                literal.span(),
                format!("data degree {degree} is above the limit {MAX_DEGREE}: the quadrature of its terms would need too many points"),
            ));
        }
        degree
    } else {
        2
    };
    Ok(DataDecl { name, degree })
}

/// The `stabilization:` role: `α S against a` or `S against a`.
fn stabilization(content: ParseStream) -> syn::Result<StabilizationDecl> {
    let first: Ident = content.parse()?;
    let second: Ident = content.parse().map_err(|e| {
        syn::Error::new(e.span(), "expected `stabilization: α S against a;` (the parameter, the stabilization form, `against` and the form it is bounded by)")
    })?;
    let (alpha, form) = if second == "against" {
        (None, first)
    } else {
        let word: Ident = content.parse()?;
        if word != "against" {
            return Err(syn::Error::new(
                word.span(),
                format!("expected `against`, as in `stabilization: {first} {second} against a;`"),
            ));
        }
        (Some(first), second)
    };
    let against: Ident = content.parse()?;
    Ok(StabilizationDecl {
        alpha,
        form,
        against,
    })
}

/// The `obstacle:` role: `w >= ψ`.
fn obstacle(content: ParseStream) -> syn::Result<(Ident, Ident)> {
    let field: Ident = content.parse()?;
    content.parse::<Token![>=]>().map_err(|e| {
        syn::Error::new(e.span(), format!("expected `obstacle: {field} >= ψ;` (the constrained field, `>=`, the obstacle's data function; `side:` turns it into s·{field} ≥ s·ψ)"))
    })?;
    let data: Ident = content.parse()?;
    Ok((field, data))
}

impl Parse for Declaration {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        let runtime = runtime_path(input)?;
        let attrs = input.call(Attribute::parse_outer)?;
        let vis: Visibility = input.parse()?;
        input.parse::<Token![mod]>().map_err(|e| {
            syn::Error::new(
                e.span(),
                "expected `mod NAME on CELL { … }`, e.g. `pub mod timoshenko on interval { … }`",
            )
        })?;
        let name: Ident = input.parse()?;
        let on: Ident = input.parse()?;
        if on != "on" {
            return Err(syn::Error::new(
                on.span(),
                "expected `on`, as in `mod timoshenko on interval { … }`",
            ));
        }
        let cell_name: Ident = input.parse()?;
        let cell = match cell_name.to_string().as_str() {
            "interval" => Some(CellKind::Interval),
            "triangle" => Some(CellKind::Triangle),
            _ => None,
        };
        let content;
        let brace = syn::braced!(content in input);
        let mut declaration = Declaration {
            runtime,
            attrs,
            vis,
            name,
            cell,
            cell_name,
            unknowns: Vec::new(),
            tests: Vec::new(),
            params: Vec::new(),
            positive: Vec::new(),
            data: Vec::new(),
            dirichlet: Vec::new(),
            facets: Vec::new(),
            forms: LitStr::new("", brace.span.join()),
            estimator: None,
            roles: RolesDecl::default(),
            body_span: brace.span.join(),
        };
        let mut seen: Vec<Ident> = Vec::new();
        let mut have_forms = false;
        while !content.is_empty() {
            let key: Ident = content.parse()?;
            if let Some(previous) = seen.iter().find(|k| **k == key) {
                let mut e = syn::Error::new(key.span(), format!("section `{key}` is given twice"));
                e.combine(syn::Error::new(previous.span(), "first given here"));
                return Err(e);
            }
            content.parse::<Token![:]>()?;
            match key.to_string().as_str() {
                "unknowns" => declaration.unknowns = comma_list(&content, unknown)?,
                "tests" => declaration.tests = comma_list(&content, |s| s.parse())?,
                "params" => {
                    let params = comma_list(&content, param)?;
                    declaration.positive = (0..params.len()).filter(|&i| params[i].1).collect();
                    declaration.params = params.into_iter().map(|(n, _)| n).collect();
                }
                "data" => declaration.data = comma_list(&content, data_function)?,
                "boundary" => {
                    declaration.dirichlet = comma_list(&content, |s| {
                        let field: Ident = s.parse()?;
                        s.parse::<Token![=]>()?;
                        let data: Ident = s.parse()?;
                        Ok((field, data))
                    })?
                }
                "facets" => declaration.facets = comma_list(&content, |s| s.parse())?,
                "estimator" => {
                    declaration.estimator = Some(if content.peek(LitStr) {
                        EstimatorDecl::Text(content.parse()?)
                    } else {
                        let word: Ident = content.parse()?;
                        if word != "derived" {
                            return Err(syn::Error::new(
                                word.span(),
                                "expected the estimator's text `\"η_T² = …\"` or `derived`",
                            ));
                        }
                        EstimatorDecl::Derived(word.span())
                    })
                }
                "forms" => {
                    declaration.forms = content.parse()?;
                    have_forms = true;
                }
                "system" => {
                    declaration.roles.system = Some(name_pair(&content, "system: B_h, L_h")?)
                }
                "energy" => declaration.roles.energy = Some(name_pair(&content, "energy: a, ℓ")?),
                "constraint" => {
                    declaration.roles.constraint = Some(name_pair(&content, "constraint: b, G")?)
                }
                "stabilization" => declaration.roles.stabilization = Some(stabilization(&content)?),
                "side" => declaration.roles.side = Some(content.parse()?),
                "unit" => declaration.roles.unit = comma_list(&content, |s| s.parse())?,
                "obstacle" => declaration.roles.obstacle = Some(obstacle(&content)?),
                other => {
                    let sections = SECTIONS;
                    let hint = closest(other, sections)
                        .map(|s| format!("; did you mean `{s}`?"))
                        .unwrap_or_default();
                    return Err(syn::Error::new(
                        key.span(),
                        format!(
                            "unknown section `{other}`: expected one of {}{hint}",
                            SECTIONS.join(", ")
                        ),
                    ));
                }
            }
            seen.push(key);
            content.parse::<Token![;]>()?;
        }
        for required in ["unknowns", "tests", "forms"] {
            if !seen.iter().any(|k| k == required) {
                return Err(syn::Error::new(
                    declaration.body_span,
                    format!("the model declares no `{required}:` section"),
                ));
            }
        }
        debug_assert!(have_forms);
        Ok(declaration)
    }
}

impl Declaration {
    /// Meaning-level checks of the declaration: elements, cells, pairing of tests, names.
    pub fn check(&self) -> Vec<Diagnostic> {
        let mut errors = Vec::new();
        let cell = self.checked_cell(&mut errors);
        self.check_unknowns(cell, &mut errors);
        self.check_tests(&mut errors);
        self.check_dirichlet(&mut errors);
        self.check_facets(cell, &mut errors);
        self.check_names(&mut errors);
        errors
    }

    /// The cell, or an error at its name.
    fn checked_cell(&self, errors: &mut Vec<Diagnostic>) -> Option<CellKind> {
        match self.cell {
            Some(c) => Some(c),
            None => {
                errors.push(
                    Diagnostic::token(
                        self.cell_name.span(),
                        format!("unknown cell `{}`", self.cell_name),
                    )
                    .help("expected `interval` or `triangle`"),
                );
                None
            }
        }
    }

    /// Each unknown's element: known, available on `cell`, a vector field of the cell's
    /// dimension, a multiplier `>= 0` discontinuous (or P1 on a boundary part).
    fn check_unknowns(&self, cell: Option<CellKind>, errors: &mut Vec<Diagnostic>) {
        for u in &self.unknowns {
            match u.element {
                None => {
                    let names = ALL_ELEMENTS.map(|e| e.name());
                    let hint = closest(&u.element_name.to_string(), names)
                        .map(|s| format!(" Did you mean `{s}`?"))
                        .unwrap_or_default();
                    errors.push(
                        Diagnostic::token(
                            u.element_name.span(),
                            format!("unknown element `{}` for `{}`", u.element_name, u.name),
                        )
                        .help(format!("expected one of {}.{hint}", names.join(", "))),
                    );
                }
                Some(e) => {
                    if let Some((n, span)) = u.vector {
                        if u.nonnegative {
                            errors.push(Diagnostic::token(
                                span,
                                format!("`{}` is a vector field: a multiplier `>= 0` must be a scalar field", u.name),
                            ));
                        }
                        if cell == Some(CellKind::Interval) || n != 2 {
                            errors.push(
                                Diagnostic::token(
                                    span,
                                    format!(
                                        "`{}: [{}]^{n}`: a vector field has as many components as the cell's dimension",
                                        u.name,
                                        e.name()
                                    ),
                                )
                                .help("vector fields are declared on triangles as `[P1]^2`; on intervals every field is a scalar"),
                            );
                        }
                    }
                    if let Some(c) = cell {
                        if !e.supports(c) {
                            errors.push(Diagnostic::token(
                                u.element_name.span(),
                                format!(
                                    "element {} is not available on {} cells",
                                    e.name(),
                                    c.name()
                                ),
                            ));
                        } else if c == CellKind::Triangle {
                            // Argyris and Morley invert their Vandermonde matrix here, at
                            // compile time: a failure is an error at the element's name.
                            if let Err(error) = e.try_triangle_basis() {
                                errors.push(Diagnostic::token(
                                    u.element_name.span(),
                                    format!("element {}: {error}", e.name()),
                                ));
                            }
                        }
                    }
                }
            }
        }
    }

    /// One test function per unknown.
    fn check_tests(&self, errors: &mut Vec<Diagnostic>) {
        if self.tests.len() != self.unknowns.len() {
            let span = self
                .tests
                .get(self.unknowns.len())
                .or(self.tests.last())
                .map_or(self.body_span, |t| t.span());
            errors.push(
                Diagnostic::token(
                    span,
                    format!(
                        "{} test functions for {} unknowns",
                        self.tests.len(),
                        self.unknowns.len()
                    ),
                )
                .help("list one test function per unknown, in the same order (`unknowns: θ: P2, w: P2; tests: η, v;`)"),
            );
        }
    }

    /// Boundary data `w = g`: `w` a continuous scalar unknown or a component, `g` data.
    fn check_dirichlet(&self, errors: &mut Vec<Diagnostic>) {
        for (field, data) in &self.dirichlet {
            // A component `θ_x` of a vector field is prescribed like a scalar field.
            let component_of = self.unknowns.iter().find(|u| {
                u.vector.is_some()
                    && component_names(&u.name.to_string(), u.components())
                        .contains(&field.to_string())
            });
            match self
                .unknowns
                .iter()
                .find(|u| u.name == *field)
                .or(component_of)
            {
                Some(u) if u.vector.is_some() && u.name == *field => errors.push(
                    Diagnostic::token(
                        field.span(),
                        format!("`{field}` is a vector field: prescribe its components"),
                    )
                    .help(format!(
                        "write one condition per component: {}",
                        component_names(&field.to_string(), u.components())
                            .iter()
                            .map(|c| format!("`{c} = {data}`"))
                            .collect::<Vec<_>>()
                            .join(", ")
                    )),
                ),
                None => errors.push(
                    Diagnostic::token(field.span(), format!("`{field}` is not an unknown")).help(
                        "boundary data `w = g` prescribes an unknown declared under `unknowns:`",
                    ),
                ),
                Some(u) if u.element.is_some_and(|e| !e.is_continuous()) => {
                    errors.push(Diagnostic::token(
                        field.span(),
                        format!(
                            "`{field}` is discontinuous: it has no boundary values to prescribe"
                        ),
                    ))
                }
                // Argyris, Morley: the runtime reads `w = g` as the simple support with
                // g = 0, fixing DOFs by kind (`DirichletPart::plate_dofs`), not by
                // interpolating g at points.
                Some(_) => {}
            }
            if !self.data.iter().any(|d| d.name == *data) {
                errors.push(
                    Diagnostic::token(
                        data.span(),
                        format!("`{data}` is not declared under `data:`"),
                    )
                    .help("boundary values are a data function of x: declare it under `data:`"),
                );
            }
        }
    }

    /// Boundary parts: on triangles, each declared once, and `n` (the outward normal)
    /// not hidden by a declared name.
    fn check_facets(&self, cell: Option<CellKind>, errors: &mut Vec<Diagnostic>) {
        if !self.facets.is_empty() && cell != Some(CellKind::Triangle) {
            errors.push(
                Diagnostic::token(
                    self.facets[0].span(),
                    "boundary parts (`facets:`) are supported on triangles only",
                )
                .help("declare the model `on triangle`, or drop the `facets:` section"),
            );
        }
        for (k, part) in self.facets.iter().enumerate() {
            if self.facets[..k].contains(part) {
                errors.push(Diagnostic::token(
                    part.span(),
                    format!("boundary part `{part}` is declared twice"),
                ));
            }
        }
        if !self.facets.is_empty() {
            // `n` is the outward normal in boundary integrals: no declared name may hide it.
            let declared = self
                .unknowns
                .iter()
                .map(|u| &u.name)
                .chain(&self.tests)
                .chain(&self.params)
                .chain(self.data.iter().map(|d| &d.name));
            for name in declared.filter(|n| *n == "n") {
                errors.push(
                    Diagnostic::token(
                        name.span(),
                        "`n` is the outward normal in a model with boundary parts",
                    )
                    .help("pick another name"),
                );
            }
        }
    }

    /// Every name means one thing: not reserved, not `int_…`, declared once, and not a
    /// component of a vector field.
    fn check_names(&self, errors: &mut Vec<Diagnostic>) {
        // Every name means one thing.
        // (name, where declared, the vector it is a component of)
        let mut names: Vec<(String, &Ident, Option<&Ident>)> = Vec::new();
        let components = |name: &Ident| -> usize {
            self.unknowns
                .iter()
                .position(|u| u.name == *name)
                .or_else(|| self.tests.iter().position(|t| t == name))
                .and_then(|k| self.unknowns.get(k))
                .map_or(1, UnknownDecl::components)
        };
        let all = self
            .unknowns
            .iter()
            .map(|u| &u.name)
            .chain(&self.tests)
            .chain(&self.params)
            .chain(self.data.iter().map(|d| &d.name));
        for name in all {
            let text = name.to_string();
            if RESERVED.contains(&text.as_str()) {
                errors.push(
                    Diagnostic::token(name.span(), format!("`{text}` is reserved"))
                        .help("`h`/`h_T` is the element size, `int`/`sum_T` are ∫ and Σ_T, `grad`/`lap`/`dot`/`d_x`/`d_y` are ∇, Δ, ·, ∂_x, ∂_y, `ε`/`eps`/`div`/`tr` the symmetric gradient, divergence and trace, `I` the identity, `ds` closes a boundary integral and `h_E` is an edge's length; pick another name"),
                );
                continue;
            }
            // `int_…` is the ASCII boundary integral `∫_…`: such a name could never be
            // used in the forms (a parameter `int_k`)
            if text.starts_with("int_") {
                errors.push(
                    Diagnostic::token(name.span(), format!("`{text}` starts with `int_`"))
                        .help("`int_Γ … ds` is the ASCII spelling of the boundary integral ∫_Γ: the forms text would read the name as one; pick another name"),
                );
                continue;
            }
            // The components of a vector field are names too (`θ_x`, `η_y`).
            let mut new = vec![(text.clone(), name, None)];
            let n = components(name);
            let reserved_component = (n > 1)
                .then(|| component_names(&text, n))
                .and_then(|c| c.into_iter().find(|c| RESERVED.contains(&c.as_str())));
            if let Some(component) = reserved_component {
                // `d` would have the components d_x, d_y: the ASCII ∂_x, ∂_y (a
                // vector field `d` had its components read as derivatives)
                errors.push(
                    Diagnostic::token(name.span(), format!("the vector field `{text}` would have the reserved component `{component}`"))
                        .help("`d_x` and `d_y` are ∂_x and ∂_y in ASCII: pick another name for the field"),
                );
                continue;
            }
            if n > 1 {
                new.extend(
                    component_names(&text, n)
                        .into_iter()
                        .map(|c| (c, name, Some(name))),
                );
            }
            for entry in new {
                if let Some(earlier) = names.iter().find(|e| e.0 == entry.0) {
                    errors.push(match (earlier.2, entry.2) {
                        (None, None) => Diagnostic::token(
                            name.span(),
                            format!("`{}` is declared twice", entry.0),
                        ),
                        (Some(v), _) | (None, Some(v)) => Diagnostic::token(
                            name.span(),
                            format!(
                                "`{}` is both a declared name and a component of the vector field `{v}`",
                                entry.0
                            ),
                        )
                        .help("the components of a vector field θ are named θ_x and θ_y: pick other names"),
                    });
                }
                names.push(entry);
            }
        }
    }
}
