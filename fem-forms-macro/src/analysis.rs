//! From the syntax tree to the kernel IR: names are resolved, each definition is
//! expanded into monomials (calls of earlier forms are substituted), the arity of every
//! term is checked, terms that vanish for the chosen elements are dropped, and the rest
//! is grouped into (test field, trial field) blocks.
//!
//! Expressions evaluate to scalars, vectors or matrices whose entries are scalar
//! expansions (a vector field `θ` is the vector of its component fields `θ_x`, `θ_y`);
//! every operator checks the shapes it gets, so `∇w − w` or `ε(w)` of a scalar is an
//! error at the expression, and an integrand must come out a scalar.

use crate::diagnostic::{closest, lookalike, Diagnostic, Loc};
use crate::parser::{Definition, Expr, ExprKind, IntegralKind, Name, MAX_DEGREE};
use crate::symbolic::{self, ArgFactor, DerivativeError, Divisor, Expansion, Monomial};
use fem_reference::ElementKind;

/// Highest derivative order of the language.
pub const MAX_DERIVATIVE: u8 = 4;

/// A field of the model: an unknown with its test function.
#[derive(Clone, Debug, PartialEq)]
pub struct Field {
    /// Name of the unknown (trial function).
    pub name: String,
    /// Name of the paired test function.
    pub test_name: String,
    /// Its element.
    pub element: ElementKind,
    /// Whether it is a multiplier constrained `≥ 0`.
    pub nonnegative: bool,
    /// `Some((vector, axis))` when the field is component `axis` of vector field
    /// `Symbols::vectors[vector]`.
    pub component: Option<(usize, usize)>,
}

/// A vector field, lowered to consecutive scalar fields of its components.
#[derive(Clone, Debug, PartialEq)]
pub struct Vector {
    /// Name of the unknown (`θ`).
    pub name: String,
    /// Name of the test function (`η`).
    pub test_name: String,
    /// Index in `Symbols::fields` of its first component.
    pub first_field: usize,
    /// Number of components (the cell's dimension).
    pub components: usize,
}

/// The names a model declares.
#[derive(Clone, Debug, Default)]
pub struct Symbols {
    /// Scalar fields in declaration order (a vector field gives one per component).
    pub fields: Vec<Field>,
    /// The vector fields.
    pub vectors: Vec<Vector>,
    /// Parameter names.
    pub params: Vec<String>,
    /// Indices of the parameters declared `> 0` (checked by the runtime).
    pub positive: Vec<usize>,
    /// Data names with the polynomial degree assumed for quadrature.
    pub data: Vec<(String, usize)>,
    /// Spatial dimension of the cell (1 for intervals, 2 for triangles).
    pub dimension: usize,
    /// Boundary parts declared under `facets:`, integrated over by `∫_Γ … ds`.
    pub facets: Vec<String>,
}

impl Symbols {
    /// Function symbol `k` is unknown `k` for `k < F`, test `k − F` otherwise.
    pub fn function_name(&self, symbol: usize) -> &str {
        let f = self.fields.len();
        if symbol < f {
            &self.fields[symbol].name
        } else {
            &self.fields[symbol - f].test_name
        }
    }

    /// The field a function symbol belongs to.
    pub fn field_of(&self, symbol: usize) -> usize {
        symbol % self.fields.len().max(1)
    }

    fn function_symbol(&self, name: &str) -> Option<usize> {
        let f = self.fields.len();
        self.fields.iter().position(|x| x.name == name).or_else(|| {
            self.fields
                .iter()
                .position(|x| x.test_name == name)
                .map(|k| k + f)
        })
    }

    /// The function symbols a name stands for: one for a scalar field or a component,
    /// the components for a vector field.
    fn function_symbols(&self, name: &str) -> Option<Vec<usize>> {
        if let Some(s) = self.function_symbol(name) {
            return Some(vec![s]);
        }
        let f = self.fields.len();
        self.vectors.iter().find_map(|v| {
            let offset = if v.name == name {
                0
            } else if v.test_name == name {
                f
            } else {
                return None;
            };
            Some(
                (v.first_field..v.first_field + v.components)
                    .map(|k| k + offset)
                    .collect(),
            )
        })
    }

    /// The name of an argument given by its symbols: a vector's name for its
    /// components, the function's name otherwise.
    fn argument_name(&self, symbols: &[usize]) -> &str {
        match symbols {
            [first, _, ..] => {
                let test = *first >= self.fields.len();
                match self.fields[self.field_of(*first)].component {
                    Some((v, _)) if test => &self.vectors[v].test_name,
                    Some((v, _)) => &self.vectors[v].name,
                    None => self.function_name(*first),
                }
            }
            [s] => self.function_name(*s),
            [] => "",
        }
    }

    /// The unknown's and the test function's names of the field (or vector) of an argument.
    fn field_names(&self, symbols: &[usize]) -> (&str, &str) {
        let f = self.fields.len();
        match symbols {
            [first, _, ..] => (
                self.argument_name(&[first % f.max(1), first % f.max(1) + 1]),
                self.argument_name(&[first % f.max(1) + f, first % f.max(1) + f + 1]),
            ),
            [s] => {
                let field = &self.fields[self.field_of(*s)];
                (&field.name, &field.test_name)
            }
            [] => ("", ""),
        }
    }

    fn all_names(&self) -> Vec<&str> {
        let mut v: Vec<&str> = Vec::new();
        for vector in &self.vectors {
            v.push(&vector.name);
            v.push(&vector.test_name);
        }
        for f in &self.fields {
            v.push(&f.name);
            v.push(&f.test_name);
        }
        v.extend(self.params.iter().map(String::as_str));
        v.extend(self.data.iter().map(|d| d.0.as_str()));
        v.extend(["h", "h_T"]);
        v
    }
}

/// One term of a block: `coefficient · params · h^k · data · D^test φ_i · D^trial φ_j`.
#[derive(Clone, Debug, PartialEq)]
pub struct Term {
    /// The numeric coefficient.
    pub coefficient: f64,
    /// `(parameter index, exponent)`.
    pub params: Vec<(usize, i32)>,
    /// Power of the element size.
    pub h_power: i32,
    /// Positive sums the term is divided by, with their exponents.
    pub divisors: Vec<(Divisor, i32)>,
    /// Data factors (indices).
    pub data: Vec<usize>,
    /// Derivative multi-index on the test function.
    pub test_derivative: [u8; 2],
    /// Derivative multi-index on the trial function (bilinear forms only).
    pub trial_derivative: Option<[u8; 2]>,
    /// Explicit quadrature degree.
    pub quadrature_degree: Option<usize>,
    /// Powers of the outward normal's components `n_x`, `n_y` (facet terms only).
    pub normal: [u8; 2],
}

/// The nonzero part of a form for one (test field, trial field) pair.
#[derive(Clone, Debug, PartialEq)]
pub struct Block {
    /// Field of the test function: the rows.
    pub test_field: usize,
    /// Field of the trial function: the columns (`None` for linear forms).
    pub trial_field: Option<usize>,
    /// Its terms.
    pub terms: Vec<Term>,
}

/// An analysed form.
#[derive(Clone, Debug)]
pub struct Form {
    /// Its name.
    pub name: String,
    /// The definition as written (for docs).
    pub source: String,
    /// Argument groups as function symbols (a vector argument gives its components).
    pub groups: Vec<Vec<usize>>,
    /// Argument groups as written: per argument, its function symbols.
    pub arguments: Vec<Vec<Vec<usize>>>,
    /// The expansion with the form's own symbols (for substitution into later forms).
    pub terms: Expansion,
    /// Terms dropped because they vanish for the chosen elements.
    pub dropped: usize,
    /// Nonzero blocks of the cell integrals.
    pub blocks: Vec<Block>,
    /// Nonzero blocks of the boundary integrals `∫_Γ … ds`: `(facet part, block)`,
    /// sorted by part, then by block.
    pub facet_blocks: Vec<(usize, Block)>,
    /// For a named expression `Cε(θ) := …`: its value in its own symbols (it has no
    /// terms or blocks and generates no code).
    pub value: Option<Value>,
}

impl Form {
    /// 1 for linear forms, 2 for bilinear ones.
    pub fn arity(&self) -> usize {
        self.groups.len()
    }
}

/// Analyses every definition in order; a definition may call those above it.
pub fn analyse(
    symbols: &Symbols,
    definitions: &[Definition],
    forms_text: &str,
) -> (Vec<Form>, Vec<Diagnostic>) {
    let mut forms: Vec<Form> = Vec::new();
    // `tests:` out of order makes every form that uses a test function wrong, usually
    // with errors about the wrong field's element (`v` is P0); the pairing, read off
    // the signatures alone, is the one error worth reading, so it goes first and alone
    // (at the first form that shows it).
    let mut pairing = Context {
        symbols,
        forms: &forms,
        later_forms: &[],
        errors: Vec::new(),
        facet: None,
        in_expression: false,
    };
    for definition in definitions.iter().filter(|d| !d.expression) {
        let mut signature = Context {
            errors: Vec::new(),
            ..pairing
        };
        if let Some((_, arguments)) = signature.signature(&definition.name, &definition.groups) {
            // one cause: the first form that shows it is enough
            if pairing.check_pairing(definition, &arguments).is_none() {
                break;
            }
        }
    }
    let pairing = pairing.errors;
    if !pairing.is_empty() {
        return (forms, pairing);
    }
    let mut errors = Vec::new();
    let all_names: Vec<&str> = definitions.iter().map(|d| d.name.text.as_str()).collect();
    for (k, definition) in definitions.iter().enumerate() {
        if let Some(first) = definitions[..k]
            .iter()
            .find(|d| d.name.text == definition.name.text)
        {
            errors.push(
                Diagnostic::text(
                    definition.name.loc,
                    format!("form `{}` is defined twice", definition.name.text),
                )
                .help(format!(
                    "the first definition is on line {}",
                    first.name.loc.line
                )),
            );
            continue;
        }
        if let Some(error) = form_name_error(&definition.name) {
            errors.push(error);
            continue;
        }
        if symbols.all_names().contains(&definition.name.text.as_str()) {
            errors.push(Diagnostic::text(
                definition.name.loc,
                format!(
                    "form name `{}` is already the name of a field, parameter or data",
                    definition.name.text
                ),
            ));
            continue;
        }
        let mut context = Context {
            symbols,
            forms: &forms,
            later_forms: &all_names[k..],
            errors: Vec::new(),
            facet: None,
            in_expression: false,
        };
        let form = if definition.expression {
            context.expression(definition, forms_text)
        } else {
            context.definition(definition, forms_text)
        };
        let failed = !context.errors.is_empty();
        errors.append(&mut context.errors);
        match form {
            Some(form) if !failed => forms.push(form),
            // Keep a placeholder so later calls do not report "unknown form" again.
            _ => forms.push(Form {
                name: definition.name.text.clone(),
                source: String::new(),
                groups: Vec::new(),
                arguments: Vec::new(),
                terms: Vec::new(),
                dropped: 0,
                blocks: Vec::new(),
                facet_blocks: Vec::new(),
                value: None,
            }),
        }
    }
    (forms, errors)
}

/// Items of the generated module that a form's module must not shadow.
const GENERATED_ITEMS: [&str; 7] = [
    "Model", "PARAMS", "DATA", "forms", "fields", "params", "data",
];

/// Why a form name cannot name the form's generated module and handle, if it cannot.
fn form_name_error(name: &Name) -> Option<Diagnostic> {
    let text = name.text.as_str();
    if GENERATED_ITEMS.contains(&text) {
        return Some(
            Diagnostic::text(
                name.loc,
                format!("form name `{text}` clashes with the generated item `{text}`"),
            )
            .help(format!(
                "the generated module has {}: pick another name",
                GENERATED_ITEMS.map(|n| format!("`{n}`")).join(", ")
            )),
        );
    }
    if syn::parse_str::<syn::Ident>(text).is_ok() {
        return None;
    }
    let keyword = syn::parse_str::<syn::Ident>(&format!("{text}_")).is_ok()
        && text.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    let (message, help) = if keyword {
        (
            format!("form name `{text}` is a Rust keyword or reserved name"),
            "each form becomes a Rust module and a handle of that name: pick another name"
                .to_string(),
        )
    } else {
        let suggestion: String = text
            .chars()
            .map(|c| match c {
                '₀'..='₉' => char::from(b'0' + (c as u32 - '₀' as u32) as u8),
                '⁰' => '0',
                '¹' => '1',
                '²' => '2',
                '³' => '3',
                '⁴'..='⁹' => char::from(b'4' + (c as u32 - '⁴' as u32) as u8),
                c => c,
            })
            .collect();
        let hint = if suggestion != text && syn::parse_str::<syn::Ident>(&suggestion).is_ok() {
            format!(" (e.g. `{suggestion}`)")
        } else {
            String::new()
        };
        (
            format!("form name `{text}` is not a Rust identifier"),
            format!(
                "each form becomes a Rust module and a handle of that name: use letters, digits and `_`{hint}"
            ),
        )
    };
    Some(Diagnostic::text(name.loc, message).help(help))
}

/// Expands a lone integrand-level expression (used by the tests of the symbolic layer).
#[cfg(test)]
pub(crate) fn expand_expression(
    symbols: &Symbols,
    text: &str,
) -> Result<Expansion, Vec<Diagnostic>> {
    let (tokens, errors) = crate::lexer::tokenize(text);
    if !errors.is_empty() {
        return Err(errors);
    }
    let expr = crate::parser::parse_expression(&tokens).map_err(|e| vec![e])?;
    let mut context = Context {
        symbols,
        forms: &[],
        later_forms: &[],
        errors: Vec::new(),
        facet: None,
        in_expression: false,
    };
    context.expand(&expr, true).ok_or(context.errors)
}

/// Expands an estimator's expression (a norm's body or its weight) with the analysed
/// `forms` callable: on an edge (`edge`) the normal `n` and `h_E` are allowed.
/// The entries of an estimator's expression: one for a scalar, one per component of a
/// vector, one per entry of a matrix (a norm of a vector or matrix is the sum of its
/// entries' squared norms).
pub(crate) fn expand_estimator_expression(
    symbols: &Symbols,
    forms: &[Form],
    expr: &crate::parser::Expr,
    edge: bool,
) -> Result<Vec<Expansion>, Vec<Diagnostic>> {
    let mut context = Context {
        symbols,
        forms,
        later_forms: &[],
        errors: Vec::new(),
        facet: None,
        in_expression: edge,
    };
    match context.value(expr, true) {
        Some(x) if context.errors.is_empty() => Ok(x.entries()),
        _ => Err(context.errors),
    }
}

/// What an expression expands to: a scalar, a vector (one scalar per axis) or a matrix
/// (rows of scalars, `dimension × dimension`; `∇θ` has the components in its rows).
#[derive(Clone, Debug)]
pub enum Value {
    /// One scalar.
    Scalar(Expansion),
    /// Entries by axis.
    Vector(Vec<Expansion>),
    /// Rows of entries.
    Matrix(Vec<Vec<Expansion>>),
}

impl Value {
    fn map(self, f: impl Fn(Expansion) -> Expansion) -> Self {
        match self {
            Value::Scalar(x) => Value::Scalar(f(x)),
            Value::Vector(v) => Value::Vector(v.into_iter().map(f).collect()),
            Value::Matrix(m) => Value::Matrix(
                m.into_iter()
                    .map(|row| row.into_iter().map(&f).collect())
                    .collect(),
            ),
        }
    }

    /// Every entry through `f`, or `None` when `f` fails on one (all are tried, so
    /// that every error is reported).
    fn try_map(self, mut f: impl FnMut(Expansion) -> Option<Expansion>) -> Option<Self> {
        let mut ok = true;
        let mut g = |x: Expansion| {
            f(x).unwrap_or_else(|| {
                ok = false;
                Vec::new()
            })
        };
        let out = match self {
            Value::Scalar(x) => Value::Scalar(g(x)),
            Value::Vector(v) => Value::Vector(v.into_iter().map(&mut g).collect()),
            Value::Matrix(m) => Value::Matrix(
                m.into_iter()
                    .map(|row| row.into_iter().map(&mut g).collect())
                    .collect(),
            ),
        };
        ok.then_some(out)
    }

    /// `a scalar`, `a vector`, `a matrix`: for messages.
    fn shape(&self) -> &'static str {
        match self {
            Value::Scalar(_) => "a scalar",
            Value::Vector(_) => "a vector",
            Value::Matrix(_) => "a matrix",
        }
    }

    /// The entries in order (row-major for matrices).
    fn entries(self) -> Vec<Expansion> {
        match self {
            Value::Scalar(x) => vec![x],
            Value::Vector(v) => v,
            Value::Matrix(m) => m.into_iter().flatten().collect(),
        }
    }

    /// `x + y` entry by entry, `None` when the shapes differ.
    fn add(self, y: Value) -> Option<Value> {
        match (self, y) {
            (Value::Scalar(x), Value::Scalar(y)) => Some(Value::Scalar(symbolic::add(x, y))),
            (Value::Vector(x), Value::Vector(y)) => Some(Value::Vector(
                x.into_iter()
                    .zip(y)
                    .map(|(x, y)| symbolic::add(x, y))
                    .collect(),
            )),
            (Value::Matrix(x), Value::Matrix(y)) => Some(Value::Matrix(
                x.into_iter()
                    .zip(y)
                    .map(|(r, s)| {
                        r.into_iter()
                            .zip(s)
                            .map(|(a, b)| symbolic::add(a, b))
                            .collect()
                    })
                    .collect(),
            )),
            _ => None,
        }
    }
}

struct Context<'a> {
    symbols: &'a Symbols,
    forms: &'a [Form],
    later_forms: &'a [&'a str],
    errors: Vec<Diagnostic>,
    /// The boundary part of the integral being expanded (`∫_Γ … ds`).
    facet: Option<usize>,
    /// Expanding a named expression `X(u) := …`: `n` and `h_E` are allowed there and
    /// checked where the expression is used.
    in_expression: bool,
}

/// The text of a definition, its lines joined.
fn source(d: &Definition, forms_text: &str) -> String {
    forms_text
        .lines()
        .skip(d.lines.0 - 1)
        .take(d.lines.1 + 1 - d.lines.0)
        .map(str::trim)
        .collect::<Vec<_>>()
        .join(" ")
}

/// Longest run of juxtaposed names (in bytes) that is split into declared names; a
/// longer one is an unknown symbol (a run of 30,000 letters overflowed the
/// stack of the split's search).
const MAX_RUN_BYTES: usize = 1024;

fn scalar(loc: Loc) -> Monomial {
    Monomial::constant(1.0, loc)
}

impl<'a> Context<'a> {
    /// A named expression `Cε(θ) := …`: its value, for substitution where it is called.
    fn expression(&mut self, d: &Definition, forms_text: &str) -> Option<Form> {
        let (groups, arguments) = self.signature(&d.name, &d.groups)?;
        // Its calls stand inside integrals (`h` is allowed); an integral in it is an error.
        self.in_expression = true;
        let value = self.value(&d.body, true);
        self.in_expression = false;
        let value = value?;
        // a function of its arguments only: where it is called they are substituted, and
        // a function not among them would have no image (a `γ(θ) := ∇w − θ`
        // panicked the macro)
        let allowed: Vec<usize> = groups.iter().flatten().copied().collect();
        let stray = value.clone().entries().into_iter().flatten().find_map(|t| {
            t.args
                .iter()
                .find(|a| !allowed.contains(&a.symbol))
                .map(|a| (a.symbol, t.origin))
        });
        if let Some((symbol, at)) = stray {
            let function = self.symbols.function_name(symbol).to_string();
            self.errors.push(
                Diagnostic::text(
                    at,
                    format!("`{function}` is not an argument of `{}`", d.name.text),
                )
                .help(format!(
                    "a named expression is a function of its arguments only: add `{function}` to them, e.g. `{}(…, {function}) := …`",
                    d.name.text
                )),
            );
            return None;
        }
        Some(Form {
            name: d.name.text.clone(),
            source: source(d, forms_text),
            groups,
            arguments,
            terms: Vec::new(),
            dropped: 0,
            blocks: Vec::new(),
            facet_blocks: Vec::new(),
            value: Some(value),
        })
    }

    fn definition(&mut self, d: &Definition, forms_text: &str) -> Option<Form> {
        let source = source(d, forms_text);
        let (groups, arguments) = self.signature(&d.name, &d.groups)?;
        let terms = self.expand(&d.body, false)?;
        let mut kept = Vec::new();
        let mut dropped = 0;
        let group_text = |g: usize| {
            arguments[g]
                .iter()
                .map(|a| self.symbols.argument_name(a).to_string())
                .collect::<Vec<_>>()
                .join(", ")
        };
        let signature = format!(
            "{}({})",
            d.name.text,
            (0..groups.len())
                .map(group_text)
                .collect::<Vec<_>>()
                .join("; ")
        );
        for t in terms {
            if !t.coefficient.is_finite() {
                self.errors.push(
                    Diagnostic::text(
                        t.origin,
                        // NaN marks an underflow (`symbolic::mul`), ±inf an overflow
                        if t.coefficient.is_nan() {
                            format!(
                                "the coefficient of this term of `{}` underflows: a product or power of its constants is below about 2.2e-308",
                                d.name.text
                            )
                        } else {
                            format!(
                                "the coefficient of this term of `{}` overflows ({})",
                                d.name.text, t.coefficient
                            )
                        },
                    )
                    .help("products, quotients and powers of the constants must stay within the normal range of f64, about 2.2e-308 to 1.8e308 in size"),
                );
                continue;
            }
            if t.normal != [0, 0] && t.facet.is_none() {
                self.errors.push(
                    Diagnostic::text(t.origin, format!("the normal `n` in a term of `{}` that is not a boundary integral", d.name.text))
                        .help("the outward normal n exists on the boundary only: use it inside `∫_Γ … ds`, Γ a part declared under `facets:`"),
                );
                continue;
            }
            if !t.integrated {
                self.errors.push(
                    Diagnostic::text(t.origin, format!("term of `{}` outside an integral", d.name.text))
                        .help("every term of a form stands under ∫ (or Σ_T), or is a call of another form"),
                );
                continue;
            }
            // The quadrature of a term is exact for the sum of its data degrees (plus the
            // basis functions'): the per-declaration limit must bound that sum too.
            let data_degree: usize = t.data.iter().map(|&i| self.symbols.data[i].1).sum();
            if data_degree > MAX_DEGREE {
                self.errors.push(
                    Diagnostic::text(
                        t.origin,
                        format!("the data of this term of `{}` have degrees summing to {data_degree}, above the limit {MAX_DEGREE}: its quadrature would need too many points", d.name.text),
                    )
                    .help("lower the declared data degrees (`data: f: 2`), or split the product of data"),
                );
                continue;
            }
            // Each argument must belong to the form; count per group.
            let mut counts = vec![0usize; groups.len()];
            let mut ok = true;
            for a in &t.args {
                match groups.iter().position(|g| g.contains(&a.symbol)) {
                    Some(g) => counts[g] += 1,
                    None => {
                        ok = false;
                        self.errors.push(
                            Diagnostic::text(
                                t.origin,
                                format!(
                                    "`{}` is not an argument of {signature}",
                                    self.symbols.function_name(a.symbol)
                                ),
                            )
                            .help("add it to the form's argument list, or use one of the listed arguments"),
                        );
                    }
                }
            }
            if !ok {
                continue;
            }
            let kind = if groups.len() == 2 {
                "bilinear"
            } else {
                "linear"
            };
            for (g, &count) in counts.iter().enumerate() {
                let which = match (groups.len(), g) {
                    (2, 0) => "first argument group (trial functions",
                    (2, _) => "second argument group (test functions",
                    _ => "arguments (test functions",
                };
                if count > 1 {
                    let product = t
                        .args
                        .iter()
                        .filter(|a| groups[g].contains(&a.symbol))
                        .map(|a| self.symbols.function_name(a.symbol))
                        .collect::<Vec<_>>()
                        .join("·");
                    self.errors.push(
                        Diagnostic::text(
                            t.origin,
                            format!(
                                "nonlinear term in the {kind} form `{}`: {product} is a product of {count} functions of its {which} {})",
                                d.name.text,
                                group_text(g)
                            ),
                        )
                        .help(format!("a {kind} form is linear in each argument group: every term has exactly one function from each group")),
                    );
                    ok = false;
                } else if count == 0 {
                    self.errors.push(
                        Diagnostic::text(
                            t.origin,
                            format!(
                                "term of the {kind} form `{}` contains no function of its {which} {})",
                                d.name.text,
                                group_text(g)
                            ),
                        )
                        .help(format!("a {kind} form is linear in each argument group: every term has exactly one function from each group")),
                    );
                    ok = false;
                }
            }
            if !ok {
                continue;
            }
            let mut vanishes = false;
            for a in &t.args {
                let field = &self.symbols.fields[self.symbols.field_of(a.symbol)];
                let name = self.symbols.function_name(a.symbol);
                if a.order() > MAX_DERIVATIVE {
                    ok = false;
                    self.errors.push(
                        Diagnostic::text(
                            t.origin,
                            format!("derivative of order {} of `{name}`: the DSL supports up to order {MAX_DERIVATIVE}", a.order()),
                        )
                        .help("write at most four primes (w''''), or ∇/Δ of order ≤ 4"),
                    );
                } else if a.order() as usize > field.element.max_derivative() {
                    ok = false;
                    self.errors.push(
                        Diagnostic::text(
                            t.origin,
                            format!(
                                "`{name}` is a {} field: derivative of order {} is more than the element supports (at most {})",
                                field.element.name(),
                                a.order(),
                                field.element.max_derivative()
                            ),
                        )
                        .help("P0 and P1disc are discontinuous multiplier spaces: drop the derivative, or choose a continuous element (P1, P2, P3, Hermite)"),
                    );
                } else if a.order() as usize > field.element.degree() {
                    vanishes = true;
                }
            }
            if !ok {
                continue;
            }
            if vanishes {
                dropped += 1;
            } else {
                kept.push(t);
            }
        }
        let (cell_terms, facet_terms): (Vec<Monomial>, Vec<Monomial>) =
            kept.iter().cloned().partition(|t| t.facet.is_none());
        let blocks = self.blocks(&groups, &cell_terms);
        let mut facet_blocks = Vec::new();
        for part in 0..self.symbols.facets.len() {
            let on_part: Vec<Monomial> = facet_terms
                .iter()
                .filter(|t| t.facet == Some(part))
                .cloned()
                .collect();
            facet_blocks.extend(
                self.blocks(&groups, &on_part)
                    .into_iter()
                    .map(|b| (part, b)),
            );
        }
        Some(Form {
            name: d.name.text.clone(),
            source,
            groups,
            arguments,
            terms: kept,
            dropped,
            blocks,
            facet_blocks,
            value: None,
        })
    }

    fn blocks(&self, groups: &[Vec<usize>], terms: &[Monomial]) -> Vec<Block> {
        let mut blocks: Vec<Block> = Vec::new();
        for t in terms {
            let find = |g: usize| {
                *t.args
                    .iter()
                    .find(|a| groups[g].contains(&a.symbol))
                    .unwrap()
            };
            let test = find(groups.len() - 1);
            let trial = (groups.len() == 2).then(|| find(0));
            let test_field = self.symbols.field_of(test.symbol);
            let trial_field = trial.map(|a| self.symbols.field_of(a.symbol));
            let term = Term {
                coefficient: t.coefficient,
                params: t.params.clone(),
                h_power: t.h_power,
                divisors: t.divisors.clone(),
                data: t.data.clone(),
                test_derivative: test.derivative,
                trial_derivative: trial.map(|a| a.derivative),
                quadrature_degree: t.quadrature_degree,
                normal: t.normal,
            };
            match blocks
                .iter_mut()
                .find(|b| b.test_field == test_field && b.trial_field == trial_field)
            {
                Some(b) => b.terms.push(term),
                None => blocks.push(Block {
                    test_field,
                    trial_field,
                    terms: vec![term],
                }),
            }
        }
        blocks.sort_by_key(|b| (b.test_field, b.trial_field));
        blocks
    }

    /// A bilinear form over the same fields on both sides (`B_h(u,λ;v,μ)`) pairs its
    /// i-th unknown with its i-th test function; the declarations pair each unknown with
    /// the test function at its place in `tests:`. When the two disagree, `tests:` is
    /// most likely out of order (a `tests: μ, v` assembled `a(u;v)` into the
    /// multiplier's rows, refused only at run time as "not positive definite"), and the
    /// form is refused here. Forms over different fields (`b(v;μ)`) pair nothing.
    fn check_pairing(&mut self, d: &Definition, arguments: &[Vec<Vec<usize>>]) -> Option<()> {
        let [trials, tests] = arguments else {
            return Some(());
        };
        let f = self.symbols.fields.len();
        let field = |a: &Vec<usize>| self.symbols.field_of(a[0]);
        if trials.len() < 2
            || trials.len() != tests.len()
            || trials.iter().any(|a| a[0] >= f)
            || tests.iter().any(|a| a[0] < f)
        {
            return Some(());
        }
        let sorted = |group: &[Vec<usize>]| {
            let mut fields: Vec<usize> = group.iter().map(field).collect();
            fields.sort_unstable();
            fields
        };
        if sorted(trials) != sorted(tests) {
            return Some(());
        }
        let Some(i) = (0..trials.len()).find(|&i| field(&trials[i]) != field(&tests[i])) else {
            return Some(());
        };
        let (unknown, declared) = self.symbols.field_names(&trials[i]);
        let written = self.symbols.argument_name(&tests[i]);
        let order: Vec<&str> = trials
            .iter()
            .map(|a| self.symbols.field_names(a).1)
            .collect();
        self.errors.push(
            Diagnostic::text(
                d.groups[1][i].loc,
                format!(
                    "`{}` pairs the unknown `{unknown}` with the test function `{written}`, but the declarations pair `{unknown}` with `{declared}`",
                    d.name.text
                ),
            )
            .help(format!(
                "`tests:` lists the test functions in the order of `unknowns:`, the i-th test function belonging to the i-th unknown; if that order is right, write the test arguments in the order of the unknowns: `; {}`",
                order.join(", ")
            )),
        );
        None
    }

    /// The argument groups of a definition: flat symbols and, per argument, its symbols.
    #[allow(clippy::type_complexity)]
    fn signature(
        &mut self,
        name: &Name,
        groups: &[Vec<Name>],
    ) -> Option<(Vec<Vec<usize>>, Vec<Vec<Vec<usize>>>)> {
        let mut flat = Vec::new();
        let mut arguments = Vec::new();
        let mut ok = true;
        let mut seen: Vec<usize> = Vec::new();
        if groups.iter().all(|g| g.is_empty()) {
            self.errors.push(
                Diagnostic::text(name.loc, format!("form `{}` has no arguments", name.text))
                    .help("a bilinear form is written `a(trial args; test args)`, a linear one `ℓ(test args)`"),
            );
            return None;
        }
        for g in groups {
            let mut group = Vec::new();
            let mut args = Vec::new();
            for n in g {
                match self.symbols.function_symbols(&n.text) {
                    Some(s) if s.iter().any(|x| seen.contains(x)) => {
                        ok = false;
                        self.errors.push(Diagnostic::text(
                            n.loc,
                            format!(
                                "`{}` appears twice among the arguments of `{}`",
                                n.text, name.text
                            ),
                        ));
                    }
                    Some(s) => {
                        seen.extend(&s);
                        group.extend(&s);
                        args.push(s);
                    }
                    None => {
                        ok = false;
                        self.errors.push(self.not_a_function(n, &name.text));
                    }
                }
            }
            flat.push(group);
            arguments.push(args);
        }
        ok.then_some((flat, arguments))
    }

    fn not_a_function(&self, n: &Name, form: &str) -> Diagnostic {
        let candidates: Vec<&str> = self
            .symbols
            .vectors
            .iter()
            .flat_map(|v| [v.name.as_str(), v.test_name.as_str()])
            .chain(
                self.symbols
                    .fields
                    .iter()
                    .flat_map(|f| [f.name.as_str(), f.test_name.as_str()]),
            )
            .collect();
        let hint = lookalike(&n.text, candidates.iter().copied())
            .map(|h| format!(" {h}."))
            .or_else(|| {
                closest(&n.text, candidates.iter().copied())
                    .map(|c| format!(" Did you mean `{c}`?"))
            })
            .unwrap_or_default();
        Diagnostic::text(
            n.loc,
            format!(
                "`{}` in the arguments of `{form}` is not a declared unknown or test function",
                n.text
            ),
        )
        .help(format!(
            "the model declares the functions {}.{hint}",
            candidates.join(", ")
        ))
    }

    fn fail(&mut self, d: Diagnostic) -> Option<Expansion> {
        self.errors.push(d);
        None
    }

    /// Resolves a name: a declared symbol, `h`, `I`, or declared symbols written
    /// together (`sλ`).
    fn symbol(&mut self, name: &str, loc: Loc, inside_integral: bool) -> Option<Value> {
        if let Some(e) = self.single_symbol(name, loc, inside_integral) {
            return e;
        }
        if let Some(parts) = self.split(name) {
            if let Some(other) = self.other_split(name, &parts) {
                return self.fail_value(
                    Diagnostic::text(
                        loc,
                        format!(
                            "`{name}` can be read as `{}` or as `{}`",
                            parts.join("·"),
                            other.join("·")
                        ),
                    )
                    .help("write the product with spaces or `·` between its factors"),
                );
            }
            let mut product = Value::Scalar(vec![scalar(loc)]);
            for part in parts {
                let factor = self.single_symbol(&part, loc, inside_integral)??;
                product = self.product(product, factor, loc)?;
            }
            return Some(product);
        }
        if self.later_forms.contains(&name) || self.forms.iter().any(|f| f.name == name) {
            return self.fail_value(
                Diagnostic::text(loc, format!("form `{name}` used without its arguments"))
                    .help(format!("call it with arguments, e.g. `{name}(u; v)`")),
            );
        }
        let names = self.symbols.all_names();
        // ε is an operator, not a declared name, but `ϵ(θ)` is the same typo
        let hint = ascii_partial_hint(name)
            .or_else(|| lookalike(name, names.iter().copied().chain(["ε"])))
            .map(|h| format!("{h}; "))
            .or_else(|| {
                closest(name, names.iter().copied()).map(|c| format!("did you mean `{c}`? "))
            })
            .unwrap_or_default();
        self.fail_value(
            Diagnostic::text(loc, format!("unknown symbol `{name}`")).help(format!(
                "{hint}declared names are {}; declare new parameters under `params:` and functions of x under `data:`",
                names.join(", ")
            )),
        )
    }

    /// `Some(result)` when `name` is one declared symbol (or `I`).
    fn single_symbol(
        &mut self,
        name: &str,
        loc: Loc,
        inside_integral: bool,
    ) -> Option<Option<Value>> {
        let mut m = scalar(loc);
        if name == "h_T" && self.facet.is_some() {
            return Some(
                self.fail_value(
                    Diagnostic::text(loc, "`h_T` in a boundary integral").help(
                        "on an edge E the size is `h_E` (its length; `h` means the same there)",
                    ),
                ),
            );
        }
        if name == "h_E" && !self.in_expression && self.facet.is_none() {
            return Some(self.fail_value(
                Diagnostic::text(loc, "`h_E` is the length of an edge: it has a meaning only inside a boundary integral `∫_Γ … ds`")
                    .help("in a cell integral the element size is `h_T` (or `h`)"),
            ));
        }
        if name == "h" || name == "h_T" || name == "h_E" {
            if !inside_integral {
                return Some(
                    self.fail_value(
                        Diagnostic::text(
                            loc,
                            "`h` is the size of an element: it has a meaning only inside ∫ or Σ_T",
                        )
                        .help("move the factor into the integrand"),
                    ),
                );
            }
            m.h_power = 1;
        } else if name == "I" {
            let n = self.symbols.dimension;
            let identity = (0..n)
                .map(|i| {
                    (0..n)
                        .map(|j| {
                            if i == j {
                                vec![scalar(loc)]
                            } else {
                                Vec::new()
                            }
                        })
                        .collect()
                })
                .collect();
            return Some(Some(Value::Matrix(identity)));
        } else if let Some(s) = self.symbols.function_symbols(name) {
            let component = |s: usize| {
                let mut m = scalar(loc);
                m.args = vec![ArgFactor {
                    symbol: s,
                    derivative: [0, 0],
                }];
                vec![m]
            };
            return Some(Some(match s.as_slice() {
                [s] => Value::Scalar(component(*s)),
                _ => Value::Vector(s.into_iter().map(component).collect()),
            }));
        } else if let Some(i) = self.symbols.params.iter().position(|p| p == name) {
            m.params = vec![(i, 1)];
        } else if let Some(i) = self.symbols.data.iter().position(|d| d.0 == name) {
            m.data = vec![i];
        } else if name == "n" && self.symbols.dimension == 2 {
            // The outward normal: a vector, constant on each (straight) edge.
            if self.facet.is_none() && !self.in_expression {
                return Some(self.fail_value(
                    Diagnostic::text(loc, "the outward normal `n` exists only on the boundary")
                        .help("use `n` inside a boundary integral `∫_Γ … ds`, Γ a part declared under `facets:`"),
                ));
            }
            let component = |axis: usize| {
                let mut m = scalar(loc);
                m.normal[axis] = 1;
                vec![m]
            };
            return Some(Some(Value::Vector(vec![component(0), component(1)])));
        } else if (name == "τ" || name == "tau") && self.symbols.dimension == 2 {
            // The unit tangent τ = (−n_y, n_x): n turned a quarter counter-clockwise.
            if self.facet.is_none() && !self.in_expression {
                return Some(self.fail_value(
                    Diagnostic::text(loc, "the unit tangent `τ` exists only on edges").help(
                        "use `τ` inside a boundary integral `∫_Γ … ds` or an estimator's edge term",
                    ),
                ));
            }
            let component = |axis: usize, sign: f64| {
                let mut m = scalar(loc);
                m.coefficient = sign;
                m.normal[axis] = 1;
                vec![m]
            };
            return Some(Some(Value::Vector(vec![
                component(1, -1.0),
                component(0, 1.0),
            ])));
        } else if let Some(components) = self.vector_parameter(name) {
            // `n_c` of the parameters `n_c_x`, `n_c_y`: a constant vector.
            let component = |i: usize| {
                let mut m = scalar(loc);
                m.params = vec![(i, 1)];
                vec![m]
            };
            return Some(Some(Value::Vector(
                components.into_iter().map(component).collect(),
            )));
        } else {
            return None;
        }
        Some(Some(Value::Scalar(vec![m])))
    }

    /// The parameters `name_x`, `name_y` (on triangles), when both are declared: the
    /// components of the constant vector `name` (a given direction such as `n_c`).
    fn vector_parameter(&self, name: &str) -> Option<Vec<usize>> {
        if self.symbols.dimension != 2 {
            return None;
        }
        crate::declaration::COMPONENT_SUFFIXES
            .iter()
            .map(|suffix| {
                let component = format!("{name}{suffix}");
                self.symbols.params.iter().position(|p| *p == component)
            })
            .collect()
    }

    /// `Et³`, `αh_T²`, `fv'`: a power or primes after a run of juxtaposed names belong to
    /// its last name, as mathematics reads them (`E·t³`, `f·v'`); applied to the whole
    /// run they gave `(Et)³` without a word (a `Et³` kernel was 4× too large).
    /// The run rewritten as the product of its names with `apply` on the last, or `None`
    /// when `a` is not such a run.
    fn last_of_run(
        &self,
        a: &Expr,
        derivative: bool,
        apply: impl FnOnce(Box<Expr>) -> ExprKind,
    ) -> Option<Expr> {
        let ExprKind::Symbol(name) = &a.kind else {
            return None;
        };
        if self.symbols.all_names().contains(&name.as_str()) {
            return None;
        }
        let parts = self.split(name)?;
        let last = parts.last()?.clone();
        if derivative {
            // primes on a parameter are 0: `uE'` keeps its old reading (uE)' = E u',
            // rather than vanishing without a word; only functions and data take them
            let differentiable = self.symbols.function_symbols(&last).is_some()
                || self.symbols.data.iter().any(|(d, _)| *d == last);
            if !differentiable {
                return None;
            }
        }
        let loc = a.loc;
        let symbol = |text: String| {
            Box::new(Expr {
                kind: ExprKind::Symbol(text),
                loc,
            })
        };
        // the run before its last name stays one symbol (split again the same way, as
        // the split is the first in a fixed order): a product as deep as the run
        // overflowed the stack for a run of 1000 names
        let prefix = name[..name.len() - last.len()].to_string();
        Some(Expr {
            kind: ExprKind::Mul(
                symbol(prefix),
                Box::new(Expr {
                    kind: apply(symbol(last)),
                    loc,
                }),
            ),
            loc,
        })
    }

    /// Splits `sλ` into declared names (longest first), if it can be done.
    fn split(&self, name: &str) -> Option<Vec<String>> {
        self.reading(name, true, &[])
            .filter(|parts| parts.len() > 1)
    }

    /// A second way to split `name` into declared names, other than `first`: with
    /// `params: s, t, st`, `stu` is `st·u` or `s·t·u`, and taking the longest names first
    /// chose one without a word (a kernel was 33.3 instead of 2).
    fn other_split(&self, name: &str, first: &[String]) -> Option<Vec<String>> {
        // shortest first: a reading that differs from the longest-first one, if any
        self.reading(name, false, first)
    }

    /// A split of `name` into declared names other than `avoid` (none: any), trying the
    /// longest or the shortest names first.
    fn reading(&self, name: &str, longest_first: bool, avoid: &[String]) -> Option<Vec<String>> {
        // the search recurses once per name of the run: bounded, as the nesting is
        if name.len() > MAX_RUN_BYTES {
            return None;
        }
        let mut names = self.symbols.all_names();
        names.retain(|n| !n.is_empty());
        if longest_first {
            names.sort_by_key(|n| std::cmp::Reverse(n.len()));
        } else {
            names.sort_by_key(|n| n.len());
        }
        // `dead[i]`: the rest from byte i has no split. Remembered, so that the search
        // is linear in the run (it was exponential: 29 a's against the names
        // a, aa, aaa took 12 s to say "unknown symbol").
        fn go(
            name: &str,
            at: usize,
            names: &[&str],
            dead: &mut [bool],
            out: &mut Vec<String>,
            avoid: &[String],
        ) -> bool {
            if at == name.len() {
                return avoid.is_empty() || out.as_slice() != avoid;
            }
            if dead[at] {
                return false;
            }
            for c in names.iter().filter(|n| name[at..].starts_with(**n)) {
                out.push(c.to_string());
                if go(name, at + c.len(), names, dead, out, avoid) {
                    return true;
                }
                out.pop();
            }
            // while `out` is a prefix of `avoid` the rest may still be completed
            // differently later: only a rest that no reading finishes is dead
            if avoid.is_empty() || out.as_slice() != &avoid[..out.len().min(avoid.len())] {
                dead[at] = true;
            }
            false
        }
        let mut dead = vec![false; name.len() + 1];
        let mut out = Vec::new();
        go(name, 0, &names, &mut dead, &mut out, avoid).then_some(out)
    }

    /// Expands a scalar expression; a vector or matrix here is an error.
    fn expand(&mut self, e: &Expr, inside_integral: bool) -> Option<Expansion> {
        match self.value(e, inside_integral)? {
            Value::Scalar(x) => Some(x),
            Value::Vector(_) => self.fail(
                Diagnostic::text(e.loc, "a vector where a scalar is needed")
                    .help("take a dot product of two vectors (∇u·∇v, grad u dot grad v), or use Δ (lap) for the divergence of a gradient"),
            ),
            Value::Matrix(_) => self.fail(
                Diagnostic::text(e.loc, "a matrix where a scalar is needed")
                    .help("contract two matrices with `:` (ε(θ):ε(η)), or take the trace `tr`"),
            ),
        }
    }

    fn fail_value(&mut self, d: Diagnostic) -> Option<Value> {
        self.errors.push(d);
        None
    }

    fn shape_mismatch(&mut self, loc: Loc, what: &str, x: &Value, y: &Value) -> Option<Value> {
        self.fail_value(
            Diagnostic::text(loc, format!("{what} of {} and {}", x.shape(), y.shape()))
                .help("both sides must have the same shape: scalars, vectors (∇w − θ) or matrices (ε(θ) + ε(η)); a product of two vectors is their dot product"),
        )
    }

    /// Expands a sum `t₀ ± t₁ ± … ± tₙ`. The parser builds it as a left-leaning tree as
    /// deep as it has terms, so it is walked down its left spine in a loop, not by
    /// recursion: a form of thousands of terms must not overflow the stack.
    fn sum_value(&mut self, e: &Expr, inside_integral: bool) -> Option<Value> {
        let mut spine: Vec<(&Expr, bool, Loc)> = Vec::new();
        let mut left = e;
        while let ExprKind::Add(a, b) | ExprKind::Sub(a, b) = &left.kind {
            spine.push((b, matches!(left.kind, ExprKind::Sub(..)), left.loc));
            left = a;
        }
        let mut sum = self.value(left, inside_integral);
        for (right, subtract, loc) in spine.into_iter().rev() {
            // Expand every term, also after an error, so that all errors are reported.
            let y = self.value(right, inside_integral);
            sum = match (sum, y) {
                (Some(x), Some(y)) => {
                    let y = if subtract { y.map(symbolic::neg) } else { y };
                    let what = if subtract { "difference" } else { "sum" };
                    match x.clone().add(y.clone()) {
                        Some(v) => Some(v),
                        None => self.shape_mismatch(loc, what, &x, &y),
                    }
                }
                _ => None,
            };
        }
        sum
    }

    /// `x·y`: a scalar scales anything, two vectors give their dot product, a matrix
    /// times a vector is the matrix–vector product (`v·A` is `Aᵀv`); two matrices are
    /// contracted with `:`, not multiplied.
    fn product(&mut self, x: Value, y: Value, loc: Loc) -> Option<Value> {
        match (x, y) {
            (Value::Scalar(x), Value::Scalar(y)) => {
                self.scalar_product(&x, &y, loc).map(Value::Scalar)
            }
            (Value::Scalar(s), v) | (v, Value::Scalar(s)) => {
                v.try_map(|c| self.scalar_product(&s, &c, loc))
            }
            (Value::Vector(x), Value::Vector(y)) => {
                self.dot(x.iter().zip(&y), loc).map(Value::Scalar)
            }
            (Value::Matrix(a), Value::Vector(v)) => {
                let mut out = Vec::new();
                for row in &a {
                    out.push(self.dot(row.iter().zip(&v), loc)?);
                }
                Some(Value::Vector(out))
            }
            (Value::Vector(v), Value::Matrix(a)) => {
                let mut out = Vec::new();
                for j in 0..v.len() {
                    let column: Vec<&Expansion> = a.iter().map(|row| &row[j]).collect();
                    out.push(self.dot(v.iter().zip(column), loc)?);
                }
                Some(Value::Vector(out))
            }
            (Value::Matrix(_), Value::Matrix(_)) => self.fail_value(
                Diagnostic::text(loc, "product of two matrices")
                    .help("write `A:B` for the double contraction Σᵢⱼ AᵢⱼBᵢⱼ (ε(θ):ε(η))"),
            ),
        }
    }

    /// `Σ xᵢ yᵢ` over pairs of scalars.
    fn dot<'e>(
        &mut self,
        pairs: impl Iterator<Item = (&'e Expansion, &'e Expansion)>,
        loc: Loc,
    ) -> Option<Expansion> {
        let mut sum = Vec::new();
        for (a, b) in pairs {
            sum = symbolic::add(sum, self.scalar_product(a, b, loc)?);
        }
        Some(sum)
    }

    /// `∇x`: a scalar's gradient is a vector, a vector's a matrix with the components
    /// in its rows (`(∇θ)ᵢⱼ = ∂ⱼθᵢ`).
    fn gradient(&mut self, x: Value, loc: Loc) -> Option<Value> {
        let n = self.symbols.dimension;
        match x {
            Value::Scalar(x) => {
                let mut components = Vec::new();
                for axis in 0..n {
                    components.push(self.partial(&x, axis, 1, loc)?);
                }
                Some(Value::Vector(components))
            }
            Value::Vector(v) => {
                let mut rows = Vec::new();
                for c in &v {
                    let mut row = Vec::new();
                    for axis in 0..n {
                        row.push(self.partial(c, axis, 1, loc)?);
                    }
                    rows.push(row);
                }
                Some(Value::Matrix(rows))
            }
            Value::Matrix(_) => self.fail_value(
                Diagnostic::text(loc, "∇ of a matrix")
                    .help("∇ takes a scalar (giving a vector) or a vector (giving a matrix); for a matrix take `div` row by row"),
            ),
        }
    }

    /// Expands an expression to a scalar, a vector or a matrix.
    fn value(&mut self, e: &Expr, inside_integral: bool) -> Option<Value> {
        let loc = e.loc;
        match &e.kind {
            ExprKind::Symbol(name) => self.symbol(name, loc, inside_integral),
            ExprKind::Call { name, groups } => {
                let called = self.call(name, groups, loc)?;
                // a form is a sum of integrals: inside another integral it would be
                // integrated twice, or over another measure (a `∫ g(μ)` with
                // `g = ∫_Γ_C … ds` became a cell integral without a word)
                if inside_integral
                    && called
                        .clone()
                        .entries()
                        .iter()
                        .any(|e| e.iter().any(|t| t.integrated))
                {
                    return self.fail_value(
                        Diagnostic::text(loc, format!("integral inside an integral: the form `{name}` is a sum of integrals"))
                            .help(format!("call forms outside integrals (`∫ A + {name}(…)`); a quantity to integrate is a named expression `X(u) := …`")),
                    );
                }
                Some(called)
            }
            ExprKind::Neg(a) => Some(self.value(a, inside_integral)?.map(symbolic::neg)),
            ExprKind::Add(..) | ExprKind::Sub(..) => self.sum_value(e, inside_integral),
            ExprKind::Mul(a, b) => {
                let x = self.value(a, inside_integral);
                let y = self.value(b, inside_integral);
                self.product(x?, y?, loc)
            }
            ExprKind::Contract(a, b) => {
                let x = self.value(a, inside_integral);
                let y = self.value(b, inside_integral);
                match (x?, y?) {
                    (Value::Matrix(x), Value::Matrix(y)) => self
                        .dot(x.iter().flatten().zip(y.iter().flatten()), loc)
                        .map(Value::Scalar),
                    (x, y) => self.fail_value(
                        Diagnostic::text(loc, format!("`:` of {} and {}", x.shape(), y.shape()))
                            .help("`A:B` contracts two matrices (ε(θ):ε(η)); two vectors multiply with `·` (their dot product), and a scalar scales anything by juxtaposition or `·`"),
                    ),
                }
            }
            ExprKind::Div(a, b) => {
                let x = self.value(a, inside_integral);
                let y = self.expand(b, inside_integral);
                let (x, y) = (x?, y?);
                let inverse = self.inverse(&y, 1, loc, b.loc)?;
                x.try_map(|c| Some(symbolic::mul(&c, &inverse, loc)))
            }
            ExprKind::Gradient(a) => {
                let x = self.value(a, inside_integral)?;
                self.gradient(x, loc)
            }
            ExprKind::Laplacian(a) => {
                let x = self.value(a, inside_integral)?;
                x.try_map(|c| {
                    let mut sum = Vec::new();
                    for axis in 0..self.symbols.dimension {
                        sum = symbolic::add(sum, self.partial(&c, axis, 2, loc)?);
                    }
                    Some(sum)
                })
            }
            ExprKind::Partial(a, axis) => {
                let axis = *axis as usize;
                if axis >= self.symbols.dimension {
                    return self.fail_value(
                        Diagnostic::text(loc, "∂_y on an interval: the cell has one coordinate")
                            .help("on intervals write primes (w') or ∂_x"),
                    );
                }
                let x = self.value(a, inside_integral)?;
                x.try_map(|c| self.partial(&c, axis, 1, loc))
            }
            ExprKind::SymmetricGradient(a) => match self.value(a, inside_integral)? {
                v @ Value::Vector(_) => {
                    let Value::Matrix(g) = self.gradient(v, loc)? else {
                        return None;
                    };
                    let n = g.len();
                    let half = vec![Monomial::constant(0.5, loc)];
                    let rows = (0..n)
                        .map(|i| {
                            (0..n)
                                .map(|j| {
                                    let sum = symbolic::add(g[i][j].clone(), g[j][i].clone());
                                    symbolic::mul(&half, &sum, loc)
                                })
                                .collect()
                        })
                        .collect();
                    Some(Value::Matrix(rows))
                }
                x => self.fail_value(
                    Diagnostic::text(loc, format!("ε of {}", x.shape()))
                        .help("ε(θ) = ½(∇θ + ∇θᵀ) is the symmetric gradient of a vector field; the gradient of a scalar w is ∇w"),
                ),
            },
            ExprKind::Divergence(a) => match self.value(a, inside_integral)? {
                Value::Vector(v) => {
                    let mut sum = Vec::new();
                    for (axis, c) in v.iter().enumerate() {
                        sum = symbolic::add(sum, self.partial(c, axis, 1, loc)?);
                    }
                    Some(Value::Scalar(sum))
                }
                Value::Matrix(m) => {
                    let mut out = Vec::new();
                    for row in &m {
                        let mut sum = Vec::new();
                        for (axis, c) in row.iter().enumerate() {
                            sum = symbolic::add(sum, self.partial(c, axis, 1, loc)?);
                        }
                        out.push(sum);
                    }
                    Some(Value::Vector(out))
                }
                Value::Scalar(_) => self.fail_value(
                    Diagnostic::text(loc, "div of a scalar")
                        .help("div takes a vector (giving a scalar) or a matrix (row by row, giving a vector); a scalar w has the gradient ∇w and the Laplacian Δw = div ∇w"),
                ),
            },
            ExprKind::Trace(a) => match self.value(a, inside_integral)? {
                Value::Matrix(m) => {
                    let mut sum = Vec::new();
                    for (i, row) in m.into_iter().enumerate() {
                        sum = symbolic::add(sum, row.into_iter().nth(i).unwrap_or_default());
                    }
                    Some(Value::Scalar(sum))
                }
                x => self.fail_value(
                    Diagnostic::text(loc, format!("tr of {}", x.shape()))
                        .help("tr takes a matrix: tr ε(θ) = div θ, tr I = 2"),
                ),
            },
            ExprKind::InnerProduct(a, b) => {
                let x = self.value(a, inside_integral);
                let y = self.value(b, inside_integral);
                let (x, y) = (x?, y?);
                if std::mem::discriminant(&x) != std::mem::discriminant(&y) {
                    return self.shape_mismatch(loc, "L² product", &x, &y);
                }
                let mut p = Vec::new();
                for (a, b) in x.entries().iter().zip(&y.entries()) {
                    p = symbolic::add(p, symbolic::mul(a, b, loc));
                }
                for t in &mut p {
                    t.inner_products += 1;
                }
                Some(Value::Scalar(p))
            }
            ExprKind::Vector(a, b) => {
                let x = self.value(a, inside_integral);
                let y = self.value(b, inside_integral);
                let (x, y) = (x?, y?);
                if self.symbols.dimension != 2 {
                    return self.fail_value(
                        Diagnostic::text(loc, "a vector `(X, Y)` on an interval")
                            .help("vectors have two components, on triangles; on intervals every quantity is a scalar"),
                    );
                }
                match (x, y) {
                    (Value::Scalar(x), Value::Scalar(y)) => Some(Value::Vector(vec![x, y])),
                    (x, y) => {
                        let wrong = if matches!(x, Value::Scalar(_)) { &y } else { &x };
                        self.fail_value(
                            Diagnostic::text(loc, format!("a vector `(X, Y)` of {}", wrong.shape()))
                                .help("the components of a vector `(X, Y)` are scalars: `(n_c_x, n_c_y)`; an L² product over elements is written `(X, Y)_T`"),
                        )
                    }
                }
            }
            _ => self.scalar_value(e, inside_integral).map(Value::Scalar),
        }
    }

    /// `1/x^k` (`k > 0`) of a scalar: a non-zero number, parameter or power of `h`
    /// (any sign: the runtime checks what it must), or a sum of parameters and `h`
    /// that is positive for every allowed parameter value. `at` locates `x`.
    fn inverse(&mut self, x: &Expansion, k: i32, loc: Loc, at: Loc) -> Option<Expansion> {
        if let Some(inverse) = symbolic::pow(x, -k, loc) {
            return Some(inverse);
        }
        if x.iter().any(|t| !t.is_scalar()) {
            return self.fail(
                Diagnostic::text(at, "division by an expression that holds functions, data or integrals")
                    .help("forms are polynomial in the arguments and data; divide only by numbers, parameters, h and positive sums of those (t² + β h_T² with `params: β > 0`)"),
            );
        }
        match self.positive_sum(x) {
            Ok(()) => symbolic::divide_by_sum(x, k, loc).map(|m| vec![m]).or_else(|| {
                self.fail(Diagnostic::text(at, "division by a sum that holds a division by a sum")
                    .help("write the quotient over one common denominator"))
            }),
            Err(why) => self.fail(
                Diagnostic::text(at, format!("division by a sum that is not known to be positive: {why}"))
                    .help("a sum is a divisor when each term is ≥ 0 (a positive number times even powers, parameters declared `> 0` and h) and one term is > 0 (no parameter in it only known ≥ 0): declare parameters positive with `params: β > 0`"),
            ),
        }
    }

    /// Why the scalar sum `x` of parameters and `h` may vanish or be negative, if it may.
    fn positive_sum(&self, x: &Expansion) -> Result<(), String> {
        if x.is_empty() {
            return Err("it is zero".into());
        }
        let name = |i: usize| self.symbols.params[i].as_str();
        let mut strictly = false;
        for t in x {
            if !t.coefficient.is_finite() {
                return Err(format!(
                    "a term's coefficient overflows ({})",
                    t.coefficient
                ));
            }
            if t.coefficient <= 0.0 {
                return Err(format!("a term has the coefficient {}", t.coefficient));
            }
            if !t.divisors.is_empty() {
                continue; // refused by the caller with its own message
            }
            let mut positive = true;
            for &(i, e) in &t.params {
                if self.symbols.positive.contains(&i) {
                    continue;
                }
                if e % 2 != 0 {
                    return Err(format!(
                        "`{}` is not declared positive and appears to an odd power",
                        name(i)
                    ));
                }
                positive = false; // an even power is ≥ 0, and 0 when the parameter is
            }
            strictly |= positive;
        }
        if strictly {
            Ok(())
        } else {
            Err("every term vanishes when a parameter not declared positive is 0".into())
        }
    }

    /// `x·y` of two scalars, refusing integrals times functions.
    fn scalar_product(&mut self, x: &Expansion, y: &Expansion, loc: Loc) -> Option<Expansion> {
        let integrated = |v: &Expansion| v.iter().any(|t| t.integrated);
        let all_scalar = |v: &Expansion| v.iter().all(Monomial::is_scalar);
        if integrated(x) && integrated(y) {
            return self.fail(
                Diagnostic::text(loc, "product of two integrals")
                    .help("a form is a sum of integrals; multiply integrands inside one ∫"),
            );
        }
        if (integrated(x) && !all_scalar(y)) || (integrated(y) && !all_scalar(x)) {
            return self.fail(
                Diagnostic::text(loc, "an integral or form call multiplied by a function")
                    .help("outside ∫ only numbers and parameters may scale a term; move functions into the integrand"),
            );
        }
        Some(symbolic::mul(x, y, loc))
    }

    /// `∂^k/∂x_axis^k` of a scalar, with the DSL's errors.
    fn partial(&mut self, x: &Expansion, axis: usize, k: u8, loc: Loc) -> Option<Expansion> {
        if x.iter().any(|t| t.integrated) {
            return self.fail(Diagnostic::text(loc, "derivative of an integral"));
        }
        match symbolic::derivative(x, axis, k) {
            Ok(d) => Some(d),
            Err(DerivativeError::OfData(at)) => self.fail(
                Diagnostic::text(at.to(loc), "derivative of a term with data (or of data alone)")
                    .help("data functions are given by value only; differentiate the arguments, not the data"),
            ),
            Err(DerivativeError::OfProduct(at)) => self.fail(
                Diagnostic::text(at.to(loc), "derivative of a product of functions")
                    .help("expand it with the product rule by hand"),
            ),
        }
    }

    /// Expands the scalar-only constructs.
    fn scalar_value(&mut self, e: &Expr, inside_integral: bool) -> Option<Expansion> {
        let loc = e.loc;
        match &e.kind {
            ExprKind::Number(v) => Some(vec![Monomial::constant(*v, loc)]),
            ExprKind::Pow(a, n) => {
                if let Some(e) = self.last_of_run(a, false, |last| ExprKind::Pow(last, *n)) {
                    return self.expand(&e, inside_integral);
                }
                let x = self.expand(a, inside_integral)?;
                if x.iter().any(|t| t.integrated) {
                    return self.fail(Diagnostic::text(loc, "power of an integral"));
                }
                match symbolic::pow(&x, *n, loc) {
                    Some(p) => Some(p),
                    // a positive sum of parameters and h: (t² + β h²)⁻¹
                    None if x.len() > 1 && x.iter().all(Monomial::is_scalar) => {
                        self.inverse(&x, -*n, loc, a.loc)
                    }
                    None => self.fail(
                        Diagnostic::text(loc, format!("negative power {n} of an expression that is not a non-zero number, parameter or h"))
                            .help("only numbers, parameters and h may carry negative exponents (t⁻², h⁻¹)"),
                    ),
                }
            }
            ExprKind::Derivative(a, k) => {
                if self.symbols.dimension > 1 {
                    return self.fail(
                        Diagnostic::text(loc, "a prime ′ is the derivative along an interval")
                            .help("on triangles write ∇ (grad) for the gradient and Δ (lap) for the Laplacian"),
                    );
                }
                if let Some(e) = self.last_of_run(a, true, |last| ExprKind::Derivative(last, *k)) {
                    return self.expand(&e, inside_integral);
                }
                // a prime on a parameter alone is 0: with `params: k, ku` a
                // `∫ ku'v'` (meant k·u'v') was a form without a kernel, without a word
                if let ExprKind::Symbol(name) = &a.kind {
                    if self.symbols.params.iter().any(|p| p == name) {
                        let hint = self
                            .other_split(name, std::slice::from_ref(name))
                            .map(|parts| {
                                format!(
                                    "; if you meant `{}'`, write it with a space or `·`",
                                    parts.join(" ")
                                )
                            })
                            .unwrap_or_default();
                        return self.fail(
                            Diagnostic::text(
                                loc,
                                format!("`{name}` is a parameter: its derivative is 0"),
                            )
                            .help(format!("a prime applies to a field or data{hint}")),
                        );
                    }
                }
                let x = self.expand(a, inside_integral)?;
                self.partial(&x, 0, *k, loc)
            }
            ExprKind::Integral {
                kind,
                facet,
                degree,
                body,
            } => {
                if inside_integral {
                    return self.fail(
                        Diagnostic::text(loc, "integral inside an integral")
                            .help("a form is a sum of single integrals: `∫ A + ∫ B`"),
                    );
                }
                let part = match facet {
                    None => None,
                    Some(name) => match self.symbols.facets.iter().position(|f| *f == name.text) {
                        Some(k) if self.symbols.dimension == 2 => Some(k),
                        Some(_) => {
                            return self.fail(Diagnostic::text(
                                name.loc,
                                "boundary integrals `∫_Γ … ds` are available on triangles only",
                            ))
                        }
                        None if self.symbols.dimension == 1 => {
                            // `facets:` is refused on intervals: the help below would send
                            // the user there
                            return self.fail(
                                Diagnostic::text(
                                    name.loc,
                                    "boundary integrals `∫_Γ … ds` are available on triangles only",
                                )
                                .help("an interval's boundary is its two end points: a point term there is not a form the language writes; impose values with `boundary:`"),
                            );
                        }
                        None => {
                            let declared = &self.symbols.facets;
                            let hint = closest(&name.text, declared.iter().map(String::as_str))
                                .map(|c| format!("did you mean `{c}`? "))
                                .unwrap_or_default();
                            let list = if declared.is_empty() {
                                "the model declares none".to_string()
                            } else {
                                format!("declared parts: {}", declared.join(", "))
                            };
                            return self.fail(
                                Diagnostic::text(
                                    name.loc,
                                    format!(
                                        "unknown boundary part `{}` in `∫_{} … ds`",
                                        name.text, name.text
                                    ),
                                )
                                .help(format!("{hint}declare the part under `facets:` ({list})")),
                            );
                        }
                    },
                };
                self.facet = part;
                let x = self.expand(body, true);
                self.facet = None;
                let mut x = x?;
                for t in &mut x {
                    match (kind, t.inner_products) {
                        (IntegralKind::Integral, 0) | (IntegralKind::SumOverElements, 1) => {}
                        (IntegralKind::Integral, _) => {
                            return self.fail(
                                Diagnostic::text(
                                    t.origin,
                                    "an L² product (X, Y)_T is already an integral over T",
                                )
                                .help("write `∫ X·Y`, or `Σ_T (X, Y)_T`"),
                            )
                        }
                        (IntegralKind::SumOverElements, 0) => {
                            return self.fail(
                                Diagnostic::text(
                                    t.origin,
                                    "a term of Σ_T without an L² product (X, Y)_T",
                                )
                                .help("write every term of Σ_T as weight·(X, Y)_T, or use ∫"),
                            )
                        }
                        (IntegralKind::SumOverElements, _) => {
                            return self.fail(Diagnostic::text(
                                t.origin,
                                "a term of Σ_T with more than one L² product",
                            ))
                        }
                    }
                    t.integrated = true;
                    t.facet = part;
                    t.inner_products = 0;
                    t.quadrature_degree = *degree;
                }
                Some(x)
            }
            // the vector-capable constructs, handled by `value`
            _ => self.expand(e, inside_integral),
        }
    }

    /// A call of a form (a scalar) or of a named expression (any shape) with its
    /// arguments substituted positionally.
    fn call(&mut self, name: &str, groups: &[Vec<Name>], loc: Loc) -> Option<Value> {
        let (callee, mapping) = self.call_mapping(name, groups, loc)?;
        let substitute = |mut terms: Expansion| {
            for t in &mut terms {
                for a in &mut t.args {
                    a.symbol = mapping.iter().find(|(f, _)| *f == a.symbol).unwrap().1;
                }
                t.args.sort();
                t.origin = loc;
            }
            terms
        };
        Some(match &callee.value {
            Some(value) => value.clone().map(substitute),
            None => Value::Scalar(substitute(callee.terms.clone())),
        })
    }

    /// The form called and its formal → actual symbols, after the checks of a call.
    fn call_mapping(
        &mut self,
        name: &str,
        groups: &[Vec<Name>],
        loc: Loc,
    ) -> Option<(&'a Form, Vec<(usize, usize)>)> {
        let forms = self.forms;
        let Some(callee) = forms.iter().find(|f| f.name == name) else {
            // the first of the later forms is the one being defined
            if self.later_forms.first() == Some(&name) {
                return self.fail_mapping(
                    Diagnostic::text(loc, format!("form `{name}` calls itself"))
                        .help("a form is a finite sum of integrals and calls of forms defined above it; it cannot be recursive"),
                );
            }
            return self.fail_mapping(
                Diagnostic::text(loc, format!("form `{name}` is used before its definition"))
                    .help("define a form above the forms that call it"),
            );
        };
        if callee.groups.is_empty() {
            return None; // its own definition failed and was reported
        }
        let show = |g: &[Vec<usize>]| {
            g.iter()
                .map(|a| self.symbols.argument_name(a))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let callee_signature = format!(
            "{name}({})",
            callee
                .arguments
                .iter()
                .map(|g| show(g))
                .collect::<Vec<_>>()
                .join("; ")
        );
        if groups.len() != callee.arguments.len()
            || groups
                .iter()
                .zip(&callee.arguments)
                .any(|(a, b)| a.len() != b.len())
        {
            let counts = |v: Vec<usize>| {
                v.iter()
                    .map(|c| c.to_string())
                    .collect::<Vec<_>>()
                    .join(";")
            };
            return self.fail_mapping(
                Diagnostic::text(
                    loc,
                    format!(
                        "wrong number of arguments for `{name}`: it is defined as {callee_signature} ({} arguments), called with {}",
                        counts(callee.arguments.iter().map(Vec::len).collect()),
                        counts(groups.iter().map(Vec::len).collect()),
                    ),
                )
                .help("pass one function per argument, with `;` between the trial and the test group"),
            );
        }
        let mut mapping: Vec<(usize, usize)> = Vec::new();
        for (g, group) in groups.iter().enumerate() {
            for (k, n) in group.iter().enumerate() {
                let formal = &callee.arguments[g][k];
                let Some(actual) = self.symbols.function_symbols(&n.text) else {
                    let d = self.not_a_function(n, name);
                    return self.fail_mapping(d);
                };
                let same_field = actual.len() == formal.len()
                    && actual
                        .iter()
                        .zip(formal)
                        .all(|(&a, &f)| self.symbols.field_of(a) == self.symbols.field_of(f));
                if !same_field {
                    let (unknown, test) = self.symbols.field_names(formal);
                    return self.fail_mapping(
                        Diagnostic::text(
                            n.loc,
                            format!(
                                "argument `{}` of `{name}` must be a function of the field `{unknown}` (`{unknown}` or `{test}`), as in {callee_signature}",
                                n.text
                            ),
                        ),
                    );
                }
                mapping.extend(formal.iter().copied().zip(actual));
            }
        }
        Some((callee, mapping))
    }

    fn fail_mapping<T>(&mut self, d: Diagnostic) -> Option<T> {
        self.errors.push(d);
        None
    }
}

/// The hint for an unknown name that starts with the ASCII partial `d_x` or `d_y`:
/// `d_xu` is one identifier, unlike `∂_xu`, since ASCII names may hold `_`.
fn ascii_partial_hint(name: &str) -> Option<String> {
    let (op, rest) = ["d_x", "d_y"]
        .into_iter()
        .find_map(|op| name.strip_prefix(op).map(|rest| (op, rest)))?;
    if rest.is_empty() {
        return None;
    }
    Some(match rest.chars().next() {
        Some(c @ ('x' | 'y')) if rest.len() == 1 || op.ends_with(c) => {
            format!("`{name}` is one name; for a derivative write {op} d_{c} (or {op}^2 for a second derivative along one axis) with spaces")
        }
        _ => format!("`{name}` is one name; for the derivative write `{op} {rest}` with a space"),
    })
}
