//! The forms text → a syntax tree of form definitions.
//!
//! ```text
//! definition := NAME '(' args [';' args] ')' '=' sum      a form
//!             | NAME '(' args ')' ':=' sum                 an expression of its arguments
//! sum        := term (('+' | '−') term)*
//! term       := ('+' | '−')* product
//! product    := factor (('·' | '*' | '/' | ':')? factor)*    juxtaposition multiplies
//! factor     := operator factor | primary (prime | superscript | '^' exponent)*
//! operator   := '∇' | 'Δ' | '∂_x' | '∂_y' | 'ε' | 'div' | 'tr'
//! primary    := number | name | form '(' args ')' | '(' sum ')' | '[' sum ']'
//!             | '(' sum ',' sum ')_T' | '∫' ['[' 'degree' '=' integer ']'] sum | 'Σ_T' sum
//!             | '∫_' PART ['[' 'degree' '=' integer ']'] sum 'ds'
//! ```
//! `∫_Γ_C … ds` (ASCII `int_Γ_C … ds`) integrates over the edges of the boundary part
//! `Γ_C` declared under `facets:`; `ds` closes its integrand.
//! The operators bind tighter than products and looser than primes and powers: each
//! applies to the factor right of it, so `tr ε(θ) I` is `tr(ε(θ))·I` and `div θ div η`
//! a product of two divergences; `div div (D[(1−ν)ε(θ) + ν tr ε(θ) I])` needs its
//! parentheses (or `D div div […]`, D being constant).
//! An integral's integrand extends to the right over the whole sum, up to a `+`/`−` that
//! starts a new integral or form call (`∫ A + ∫[degree=1] B`, `a(…) − α S(…)`).
//! A definition starts at the beginning of a line with `NAME(args) =`; anything else
//! continues the previous line, so long forms may wrap.

use crate::diagnostic::{Diagnostic, Loc};
use crate::lexer::{ExponentFault, Tok, Token};
use std::collections::HashSet;

/// A name with its place.
#[derive(Clone, Debug, PartialEq)]
pub struct Name {
    /// The name as written.
    pub text: String,
    /// Where it is written.
    pub loc: Loc,
}

/// Highest polynomial degree of a quadrature option `∫[degree=N]` or of a data
/// function (`data: f: N`): the Gauss rules behind them stay small and accurate.
pub const MAX_DEGREE: usize = 40;

/// Integral or sum over elements (the same thing for element-wise integrands; only the
/// L² products `(X, Y)_T` differ in where they may appear).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IntegralKind {
    /// `∫ …`
    Integral,
    /// `Σ_T …`
    SumOverElements,
}

/// An expression node.
#[derive(Clone, Debug, PartialEq)]
pub enum ExprKind {
    /// A literal number.
    Number(f64),
    /// A name: parameter, data, argument, `h`, or juxtaposed names (`sλ`).
    Symbol(String),
    /// `−x`
    Neg(Box<Expr>),
    /// `x + y`
    Add(Box<Expr>, Box<Expr>),
    /// `x − y`
    Sub(Box<Expr>, Box<Expr>),
    /// `x · y`
    Mul(Box<Expr>, Box<Expr>),
    /// `x / y`
    Div(Box<Expr>, Box<Expr>),
    /// `x^n`
    Pow(Box<Expr>, i32),
    /// `x'`, `x''`, …
    Derivative(Box<Expr>, u8),
    /// `∇x`
    Gradient(Box<Expr>),
    /// `Δx`
    Laplacian(Box<Expr>),
    /// `∂_x x` (axis 0) or `∂_y x` (axis 1)
    Partial(Box<Expr>, u8),
    /// `ε(x)`, the symmetric gradient
    SymmetricGradient(Box<Expr>),
    /// `div x`
    Divergence(Box<Expr>),
    /// `tr x`
    Trace(Box<Expr>),
    /// `x : y`, the double contraction
    Contract(Box<Expr>, Box<Expr>),
    /// `(x, y)_T`
    InnerProduct(Box<Expr>, Box<Expr>),
    /// `(x, y)`: the vector of two scalars (in 2D).
    Vector(Box<Expr>, Box<Expr>),
    /// `∫ body`, `Σ_T body` or `∫_Γ body ds`
    Integral {
        /// Which notation.
        kind: IntegralKind,
        /// `∫_Γ … ds`: the boundary part integrated over (`None`: the cells).
        facet: Option<Name>,
        /// Explicit quadrature degree (`∫[degree=1]`).
        degree: Option<usize>,
        /// The integrand.
        body: Box<Expr>,
    },
    /// `b(η,v;λ)`: a previously defined form applied to arguments.
    Call {
        /// Form name.
        name: String,
        /// Argument groups (one for linear forms, two for bilinear ones).
        groups: Vec<Vec<Name>>,
    },
}

/// An expression with its place.
#[derive(Clone, Debug, PartialEq)]
pub struct Expr {
    /// The node.
    pub kind: ExprKind,
    /// Where it is written.
    pub loc: Loc,
}

impl Expr {
    fn new(kind: ExprKind, loc: Loc) -> Self {
        Self { kind, loc }
    }
}

/// `name(groups) = body`, or `name(args) := body`
#[derive(Clone, Debug, PartialEq)]
pub struct Definition {
    /// `:=`: a named expression of its arguments (`Cε(θ) := D[(1−ν)ε(θ) + ν tr ε(θ) I]`),
    /// substituted where it is called, of any shape; not a form.
    pub expression: bool,
    /// The form's name.
    pub name: Name,
    /// Its argument groups: `[trial…]; [test…]` for bilinear forms, `[test…]` for linear ones.
    pub groups: Vec<Vec<Name>>,
    /// The right-hand side.
    pub body: Expr,
    /// First and last line of the definition in the forms text.
    pub lines: (usize, usize),
}

/// Parses every definition of the forms text, collecting errors across definitions.
pub fn parse_forms(tokens: &[Token]) -> (Vec<Definition>, Vec<Diagnostic>) {
    let mut errors = Vec::new();
    let starts: Vec<usize> = (0..tokens.len())
        .filter(|&i| {
            (i == 0 || tokens[i - 1].tok == Tok::Newline) && header_end(tokens, i).is_some()
        })
        .collect();
    let first = starts.first().copied().unwrap_or(tokens.len());
    if let Some(stray) = tokens[..first].iter().find(|t| t.tok != Tok::Newline) {
        errors.push(
            Diagnostic::text(stray.loc, "expected a form definition")
                .help("each definition starts a line with `name(trial args; test args) =`, e.g. `a(u;v) = ∫ u'v'`"),
        );
    }
    let form_names: HashSet<String> = starts
        .iter()
        .filter_map(|&i| match &tokens[i].tok {
            Tok::Ident(name) => Some(name.clone()),
            _ => None,
        })
        .collect();
    let names_in_order: Vec<String> = starts
        .iter()
        .filter_map(|&i| match &tokens[i].tok {
            Tok::Ident(name) => Some(name.clone()),
            _ => None,
        })
        .collect();
    let mut definitions = Vec::new();
    for (k, &start) in starts.iter().enumerate() {
        let end = starts.get(k + 1).copied().unwrap_or(tokens.len());
        let slice: Vec<Token> = tokens[start..end]
            .iter()
            .filter(|t| t.tok != Tok::Newline)
            .cloned()
            .collect();
        let last_line = slice.last().map_or(tokens[start].loc.line, |t| t.loc.line);
        let mut parser = Parser {
            tokens: &slice,
            pos: 0,
            form_names: &form_names,
            earlier_forms: &names_in_order[..k.min(names_in_order.len())],
            nesting: 0,
        };
        match parser.definition() {
            Ok(mut d) => {
                d.lines = (tokens[start].loc.line, last_line);
                definitions.push(d);
            }
            Err(e) => errors.push(e),
        }
    }
    if starts.is_empty() && errors.is_empty() {
        errors.push(
            Diagnostic::text(
                Loc {
                    line: 1,
                    column: 1,
                    len: 1,
                },
                "the forms text defines no form",
            )
            .help("write definitions like `a(u;v) = ∫ u'v'` and `ℓ(v) = ∫ f v`, one per line"),
        );
    }
    (definitions, errors)
}

/// Parses a lone expression (used by the tests of the symbolic layer).
#[cfg(test)]
pub(crate) fn parse_expression(tokens: &[Token]) -> Result<Expr> {
    parse_expression_calling(tokens, &HashSet::new(), &[])
}

/// Parses a lone expression that may call the forms and named expressions `forms`
/// (the estimator's norms, which may use `Cε(θ)` of the forms text).
pub(crate) fn parse_expression_calling(
    tokens: &[Token],
    form_names: &HashSet<String>,
    forms: &[String],
) -> Result<Expr> {
    let mut parser = Parser {
        tokens,
        pos: 0,
        form_names,
        earlier_forms: forms,
        nesting: 0,
    };
    let e = parser.sum(false)?;
    match parser.peek() {
        None => Ok(e),
        Some(_) => Err(parser.unexpected("the end of the expression")),
    }
}

/// If a definition header `NAME ( … ) =` (or `:=`) starts at `i`, the index of its `=`.
fn header_end(tokens: &[Token], i: usize) -> Option<usize> {
    matches!(tokens.get(i)?.tok, Tok::Ident(_)).then_some(())?;
    (tokens.get(i + 1)?.tok == Tok::LParen).then_some(())?;
    let mut j = i + 2;
    while let Some(t) = tokens.get(j) {
        match t.tok {
            Tok::Ident(_) | Tok::Comma | Tok::Semicolon => j += 1,
            Tok::RParen => {
                return match tokens.get(j + 1)?.tok {
                    Tok::Equals => Some(j + 1),
                    Tok::Colon => (tokens.get(j + 2)?.tok == Tok::Equals).then_some(j + 2),
                    _ => None,
                };
            }
            _ => return None,
        }
    }
    None
}

/// `(e)` or `[e]` at `loc` (a bracketed run of names followed by a power or primes is
/// kept together by `factor`, see [`kept_together`]).
fn grouped(e: Expr, loc: Loc) -> Expr {
    Expr::new(e.kind, loc)
}

/// `1·e` at `e`'s place, for a bracketed run of names followed by a power or primes:
/// they take the whole run (`(Et)³` is `(E·t)³`), where after a bare run they take its
/// last name (`Et³` is `E·t³`, see the analysis). The brackets were once dropped,
/// `(Et)³` computed as `E·t³`.
fn kept_together(e: Expr) -> Expr {
    let loc = e.loc;
    Expr::new(
        ExprKind::Mul(Box::new(Expr::new(ExprKind::Number(1.0), loc)), Box::new(e)),
        loc,
    )
}

/// Deepest nesting of parentheses, integrals, signs and ∇/Δ: the parser and the
/// expansion recurse on it, and a deeper text must be an error, not a stack overflow.
pub const MAX_NESTING: usize = 100;

/// Most terms of one sum: the syntax tree of a sum is a left spine as long as the sum,
/// and the compiler's own passes over the macro's output (and the tree's drop) recurse
/// on it. 20,000 terms compiled; 60,000 overflowed rustc's stack.
pub const MAX_TERMS: usize = 10_000;

/// Highest power of `Δ` or `∂` (`Δ³ w` is of order 6): beyond any element's degree (the
/// quintic Argyris) every such derivative vanishes, and a `Δ^999999` built a
/// million nested nodes that overflowed the stack.
pub const MAX_OPERATOR_POWER: i32 = 8;

/// Where `body` is nested deeper than [`MAX_NESTING`], counting every node except the
/// left spine of a sum (expanded in a loop), if it is. Walks with an explicit stack.
fn too_deep(body: &Expr) -> Option<Loc> {
    let mut stack = vec![(body, 0usize)];
    while let Some((e, depth)) = stack.pop() {
        if depth > MAX_NESTING {
            return Some(e.loc);
        }
        match &e.kind {
            ExprKind::Number(_) | ExprKind::Symbol(_) | ExprKind::Call { .. } => {}
            ExprKind::Add(a, b) | ExprKind::Sub(a, b) => {
                stack.push((a, depth));
                stack.push((b, depth + 1));
            }
            ExprKind::Mul(a, b)
            | ExprKind::Div(a, b)
            | ExprKind::Contract(a, b)
            | ExprKind::InnerProduct(a, b)
            | ExprKind::Vector(a, b) => {
                stack.push((a, depth + 1));
                stack.push((b, depth + 1));
            }
            ExprKind::Neg(a)
            | ExprKind::Pow(a, _)
            | ExprKind::Derivative(a, _)
            | ExprKind::Gradient(a)
            | ExprKind::Laplacian(a)
            | ExprKind::Partial(a, _)
            | ExprKind::SymmetricGradient(a)
            | ExprKind::Divergence(a)
            | ExprKind::Trace(a)
            | ExprKind::Integral { body: a, .. } => stack.push((a, depth + 1)),
        }
    }
    None
}

/// Largest total power a form may build from exponents (`h_T⁴`, `t⁻²`, `(…)²`): the
/// symbolic expansion multiplies a base `n` times and adds exponents in `i32`, so
/// `t^999999` would take quadratic time and nested powers would overflow.
pub const MAX_TOTAL_POWER: f64 = 1000.0;

/// The error for a run of superscripts `raw` at `loc` that has no value.
fn bad_superscript(fault: ExponentFault, raw: &str, loc: Loc) -> Diagnostic {
    match fault {
        ExponentFault::TooLarge => Diagnostic::text(
            loc,
            format!("exponent `{raw}` is beyond the limit {MAX_TOTAL_POWER}"),
        )
        .help("a form is a polynomial of low degree in its fields and data: write the power you mean (h_T⁴, t⁻²)"),
        ExponentFault::Malformed => Diagnostic::text(loc, format!("malformed exponent `{raw}`"))
            .help("write an integer exponent such as ² or ⁻² (ASCII: ^2, ^-2)"),
    }
}

/// Where the exponents of `body` can multiply to more than [`MAX_TOTAL_POWER`], with the
/// bound reached there. A product adds its factors' bounds, a power multiplies its
/// base's bound by `|n|`, a sum takes the larger. Recursion is safe: it runs after
/// [`too_deep`] has bounded the depth.
fn power_too_large(body: &Expr) -> Option<(Loc, f64)> {
    fn bound(e: &Expr, worst: &mut Option<(Loc, f64)>) -> f64 {
        let b = match &e.kind {
            ExprKind::Number(_) | ExprKind::Symbol(_) | ExprKind::Call { .. } => 1.0,
            ExprKind::Add(a, b) | ExprKind::Sub(a, b) => bound(a, worst).max(bound(b, worst)),
            ExprKind::Mul(a, b)
            | ExprKind::Div(a, b)
            | ExprKind::Contract(a, b)
            | ExprKind::InnerProduct(a, b) => bound(a, worst) + bound(b, worst),
            ExprKind::Vector(a, b) => bound(a, worst).max(bound(b, worst)),
            ExprKind::Neg(a)
            | ExprKind::Derivative(a, _)
            | ExprKind::Gradient(a)
            | ExprKind::Laplacian(a)
            | ExprKind::Partial(a, _)
            | ExprKind::SymmetricGradient(a)
            | ExprKind::Divergence(a)
            | ExprKind::Trace(a)
            | ExprKind::Integral { body: a, .. } => bound(a, worst),
            ExprKind::Pow(a, n) => bound(a, worst) * f64::from(*n).abs().max(1.0),
        };
        if b > MAX_TOTAL_POWER && worst.is_none() {
            *worst = Some((e.loc, b));
        }
        b
    }
    let mut worst = None;
    bound(body, &mut worst);
    worst
}

struct Parser<'a> {
    tokens: &'a [Token],
    pos: usize,
    form_names: &'a HashSet<String>,
    /// Names of the definitions above this one, for "unknown form" messages.
    earlier_forms: &'a [String],
    /// Current nesting depth (see [`MAX_NESTING`]).
    nesting: usize,
}

type Result<T> = std::result::Result<T, Diagnostic>;

fn describe(tok: &Tok) -> String {
    match tok {
        Tok::Ident(s) => format!("`{s}`"),
        Tok::Number(v) => format!("the number {v}"),
        Tok::Integral => "`∫`".into(),
        Tok::SumT => "`Σ_T`".into(),
        Tok::FacetIntegral(part) => format!("`∫_{part}`"),
        Tok::Ds => "`ds`".into(),
        Tok::Prime(n) => format!("a derivative mark ({n} prime(s))"),
        Tok::Superscript(_, raw) => format!("the exponent `{raw}`"),
        Tok::Caret => "`^`".into(),
        Tok::Plus => "`+`".into(),
        Tok::Minus => "`−`".into(),
        Tok::Star => "`·`".into(),
        Tok::Grad => "`∇`".into(),
        Tok::Laplacian => "`Δ`".into(),
        Tok::Partial(0) => "`∂_x`".into(),
        Tok::Partial(_) => "`∂_y`".into(),
        Tok::SymGrad => "`ε`".into(),
        Tok::Divergence => "`div`".into(),
        Tok::Trace => "`tr`".into(),
        Tok::Colon => "`:`".into(),
        Tok::Slash => "`/`".into(),
        Tok::LParen => "`(`".into(),
        Tok::RParen => "`)`".into(),
        Tok::LBracket => "`[`".into(),
        Tok::RBracket => "`]`".into(),
        Tok::LBrace => "`{`".into(),
        Tok::RBrace => "`}`".into(),
        Tok::Comma => "`,`".into(),
        Tok::Semicolon => "`;`".into(),
        Tok::Equals => "`=`".into(),
        Tok::SubscriptT => "`_T`".into(),
        Tok::Norm => "`‖`".into(),
        Tok::Newline => "the end of the line".into(),
    }
}

impl<'a> Parser<'a> {
    fn peek(&self) -> Option<&'a Token> {
        self.tokens.get(self.pos)
    }

    fn peek_tok(&self) -> Option<&'a Tok> {
        self.peek().map(|t| &t.tok)
    }

    fn bump(&mut self) -> Option<&'a Token> {
        let t = self.tokens.get(self.pos);
        self.pos += 1;
        t
    }

    /// Place of the current token, or just past the last one.
    fn here(&self) -> Loc {
        match self.peek() {
            Some(t) => t.loc,
            None => self.tokens.last().map_or(Loc::default(), |t| Loc {
                column: t.loc.column + t.loc.len,
                len: 1,
                ..t.loc
            }),
        }
    }

    fn previous_loc(&self) -> Loc {
        self.tokens[self.pos.saturating_sub(1).min(self.tokens.len() - 1)].loc
    }

    fn unexpected(&self, expected: &str) -> Diagnostic {
        match self.peek() {
            Some(t) => Diagnostic::text(
                t.loc,
                format!("expected {expected}, found {}", describe(&t.tok)),
            ),
            None => Diagnostic::text(
                self.here(),
                format!("expected {expected}, found the end of the definition"),
            ),
        }
    }

    fn expect(&mut self, tok: Tok, expected: &str) -> Result<&'a Token> {
        if self.peek_tok() == Some(&tok) {
            Ok(self.bump().unwrap())
        } else {
            Err(self.unexpected(expected))
        }
    }

    fn definition(&mut self) -> Result<Definition> {
        let name = self.name("a form name")?;
        self.expect(Tok::LParen, "`(`")?;
        let groups = self.argument_groups()?;
        let expression = self.peek_tok() == Some(&Tok::Colon);
        if expression {
            self.pos += 1;
            if groups.len() != 1 {
                return Err(Diagnostic::text(
                    name.loc,
                    format!(
                        "`{}(…) :=` names an expression of one argument list",
                        name.text
                    ),
                )
                .help(
                    "write `Cε(θ) := …` without `;`; forms of trial and test functions use `=`",
                ));
            }
        }
        self.expect(Tok::Equals, "`=`")?;
        if self.peek().is_none() {
            return Err(self.unexpected("the form's right-hand side"));
        }
        let body = self.sum(false)?;
        if let Some(t) = self.peek() {
            let d = match t.tok {
                Tok::RParen => Diagnostic::text(t.loc, "unmatched `)`")
                    .help("remove it, or add the `(` it was meant to close"),
                _ => self.unexpected("an operator (+, −, ·, /) or the end of the definition"),
            };
            return Err(d);
        }
        if let Some(loc) = too_deep(&body) {
            return Err(Diagnostic::text(
                loc,
                format!("expression nested more than {MAX_NESTING} levels deep (products, powers, derivatives and parentheses)"),
            )
            .help("split it: define a form for a part and call it"));
        }
        if let Some((loc, total)) = power_too_large(&body) {
            return Err(Diagnostic::text(
                loc,
                format!("exponents here build a power of up to {total:.3e}, beyond the limit {MAX_TOTAL_POWER}"),
            )
            .help("a form is a polynomial of low degree in its fields and data: write the power you mean (h_T⁴, t⁻²)"));
        }
        Ok(Definition {
            expression,
            name,
            groups,
            body,
            lines: (0, 0),
        })
    }

    fn name(&mut self, what: &str) -> Result<Name> {
        match self.peek() {
            Some(Token {
                tok: Tok::Ident(s),
                loc,
            }) => {
                self.pos += 1;
                Ok(Name {
                    text: s.clone(),
                    loc: *loc,
                })
            }
            _ => Err(self.unexpected(what)),
        }
    }

    /// `a, b; c)` after the opening parenthesis.
    fn argument_groups(&mut self) -> Result<Vec<Vec<Name>>> {
        let mut groups = vec![Vec::new()];
        loop {
            match self.peek_tok() {
                Some(Tok::RParen) => {
                    self.pos += 1;
                    return Ok(groups);
                }
                Some(Tok::Ident(_)) => {
                    let n = self.name("an argument name")?;
                    groups.last_mut().unwrap().push(n);
                    match self.peek_tok() {
                        Some(Tok::Comma) => self.pos += 1,
                        Some(Tok::Semicolon) => {
                            if groups.len() == 2 {
                                return Err(self.unexpected(
                                    "`,` or `)` (a form has at most two argument groups)",
                                ));
                            }
                            self.pos += 1;
                            groups.push(Vec::new());
                        }
                        Some(Tok::RParen) => {}
                        _ => return Err(self.unexpected("`,`, `;` or `)`")),
                    }
                }
                _ => return Err(self.unexpected("an argument name or `)`")),
            }
        }
    }

    /// Whether the term after a `+`/`−` at `start` is a new integral or form call.
    fn starts_form_term(&self, start: usize) -> bool {
        let mut depth = 0usize;
        let mut i = start;
        while matches!(
            self.tokens.get(i).map(|t| &t.tok),
            Some(Tok::Plus | Tok::Minus)
        ) {
            i += 1;
        }
        while let Some(t) = self.tokens.get(i) {
            match &t.tok {
                Tok::LParen | Tok::LBracket => depth += 1,
                Tok::RParen | Tok::RBracket => {
                    if depth == 0 {
                        return false;
                    }
                    depth -= 1;
                }
                Tok::Caret => {
                    // `t^-2`: the sign belongs to the exponent
                    if matches!(
                        self.tokens.get(i + 1).map(|t| &t.tok),
                        Some(Tok::Minus | Tok::Plus)
                    ) {
                        i += 1;
                    }
                }
                Tok::Plus | Tok::Minus | Tok::Comma if depth == 0 => return false,
                Tok::Integral | Tok::SumT | Tok::FacetIntegral(_) if depth == 0 => return true,
                Tok::Ident(name)
                    if depth == 0
                        && self.form_names.contains(name)
                        && self.tokens.get(i + 1).map(|t| &t.tok) == Some(&Tok::LParen) =>
                {
                    return true
                }
                _ => {}
            }
            i += 1;
        }
        false
    }

    /// Runs `inner` one nesting level deeper, or refuses beyond [`MAX_NESTING`].
    fn nested<T>(&mut self, loc: Loc, inner: impl FnOnce(&mut Self) -> Result<T>) -> Result<T> {
        if self.nesting >= MAX_NESTING {
            return Err(Diagnostic::text(
                loc,
                format!("expression nested more than {MAX_NESTING} levels deep"),
            )
            .help("split it: define a form for the inner part and call it"));
        }
        self.nesting += 1;
        let out = inner(self);
        self.nesting -= 1;
        out
    }

    /// A call `name(…;…)` of a form that the text does not define.
    fn unknown_form(&self, name: &str, loc: Loc) -> Diagnostic {
        let listed = if self.earlier_forms.is_empty() {
            "no form is defined above this one".to_string()
        } else {
            format!(
                "the forms defined so far are {}",
                self.earlier_forms
                    .iter()
                    .map(|n| format!("`{n}`"))
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        };
        let hint = crate::diagnostic::closest(name, self.earlier_forms.iter().map(String::as_str))
            .map(|n| format!("; did you mean `{n}`?"))
            .unwrap_or_default();
        Diagnostic::text(loc, format!("unknown form `{name}`")).help(format!("{listed}{hint}"))
    }

    /// Whether the parenthesis at `open` holds a `;` at its own level (an argument
    /// list of a bilinear form call, never an expression).
    fn parenthesis_has_semicolon(&self, open: usize) -> bool {
        let mut depth = 0usize;
        for t in &self.tokens[open..] {
            match t.tok {
                Tok::LParen => depth += 1,
                Tok::RParen => {
                    depth = depth.saturating_sub(1);
                    if depth == 0 {
                        return false;
                    }
                }
                Tok::Semicolon if depth == 1 => return true,
                _ => {}
            }
        }
        false
    }

    fn sum(&mut self, integrand: bool) -> Result<Expr> {
        let mut lhs = self.term()?;
        let mut terms = 1usize;
        while let Some(Tok::Plus | Tok::Minus) = self.peek_tok() {
            if integrand && self.starts_form_term(self.pos + 1) {
                break;
            }
            terms += 1;
            if terms > MAX_TERMS {
                return Err(Diagnostic::text(
                    self.peek().map_or(lhs.loc, |t| t.loc),
                    format!("a sum of more than {MAX_TERMS} terms"),
                )
                .help(
                    "split it into several forms and add their calls: `a(u;v) = a₁(u;v) + a₂(u;v)`",
                ));
            }
            let op = self.bump().unwrap().tok.clone();
            let rhs = self.term()?;
            let loc = lhs.loc.to(rhs.loc);
            lhs = Expr::new(
                if op == Tok::Plus {
                    ExprKind::Add(Box::new(lhs), Box::new(rhs))
                } else {
                    ExprKind::Sub(Box::new(lhs), Box::new(rhs))
                },
                loc,
            );
        }
        Ok(lhs)
    }

    fn term(&mut self) -> Result<Expr> {
        match self.peek_tok() {
            Some(Tok::Minus) => {
                let loc = self.bump().unwrap().loc;
                let inner = self.nested(loc, Self::term)?;
                let loc = loc.to(inner.loc);
                Ok(Expr::new(ExprKind::Neg(Box::new(inner)), loc))
            }
            Some(Tok::Plus) => {
                let loc = self.bump().unwrap().loc;
                self.nested(loc, Self::term)
            }
            _ => self.product(),
        }
    }

    fn starts_factor(tok: &Tok) -> bool {
        matches!(
            tok,
            Tok::Ident(_)
                | Tok::Number(_)
                | Tok::LParen
                | Tok::Integral
                | Tok::SumT
                | Tok::FacetIntegral(_)
                | Tok::LBracket
                | Tok::Grad
                | Tok::Laplacian
                | Tok::Partial(_)
                | Tok::SymGrad
                | Tok::Divergence
                | Tok::Trace
        )
    }

    fn product(&mut self) -> Result<Expr> {
        let mut lhs = self.factor()?;
        loop {
            let (op, explicit) = match self.peek_tok() {
                Some(Tok::Star) => (Tok::Star, true),
                Some(Tok::Slash) => (Tok::Slash, true),
                Some(Tok::Colon) => (Tok::Colon, true),
                Some(t) if Self::starts_factor(t) => (Tok::Star, false),
                _ => break,
            };
            if explicit {
                self.pos += 1;
            }
            let rhs = if explicit && self.peek_tok() == Some(&Tok::Minus) {
                let loc = self.bump().unwrap().loc;
                let f = self.factor()?;
                let loc = loc.to(f.loc);
                Expr::new(ExprKind::Neg(Box::new(f)), loc)
            } else {
                self.factor()?
            };
            let loc = lhs.loc.to(rhs.loc);
            lhs = Expr::new(
                match op {
                    Tok::Slash => ExprKind::Div(Box::new(lhs), Box::new(rhs)),
                    Tok::Colon => ExprKind::Contract(Box::new(lhs), Box::new(rhs)),
                    _ => ExprKind::Mul(Box::new(lhs), Box::new(rhs)),
                },
                loc,
            );
        }
        Ok(lhs)
    }

    fn factor(&mut self) -> Result<Expr> {
        // The operators bind tighter than products and looser than primes and powers:
        // ∇u·∇v, ε(θ):ε(η), div div A.
        if let Some(
            op @ (Tok::Grad
            | Tok::Laplacian
            | Tok::Partial(_)
            | Tok::SymGrad
            | Tok::Divergence
            | Tok::Trace),
        ) = self.peek_tok()
        {
            let op = op.clone();
            let loc = self.bump().unwrap().loc;
            let (power, loc) = self.operator_power(&op, loc)?;
            if !self.peek_tok().is_some_and(Self::starts_factor) {
                return Err(self.unexpected(&format!("a function after {}", describe(&op))));
            }
            let mut e = self.nested(loc, Self::factor)?;
            for _ in 0..power {
                let inner = Box::new(e);
                let l = loc.to(inner.loc);
                let kind = match op {
                    Tok::Laplacian => ExprKind::Laplacian(inner),
                    Tok::Partial(axis) => ExprKind::Partial(inner, axis),
                    Tok::SymGrad => ExprKind::SymmetricGradient(inner),
                    Tok::Divergence => ExprKind::Divergence(inner),
                    Tok::Trace => ExprKind::Trace(inner),
                    _ => ExprKind::Gradient(inner),
                };
                e = Expr::new(kind, l);
            }
            return Ok(e);
        }
        let mut e = self.primary()?;
        let bracketed =
            self.pos > 0 && matches!(self.tokens[self.pos - 1].tok, Tok::RParen | Tok::RBracket);
        if bracketed
            && matches!(e.kind, ExprKind::Symbol(_))
            && matches!(
                self.peek_tok(),
                Some(Tok::Prime(_) | Tok::Superscript(..) | Tok::Caret)
            )
        {
            e = kept_together(e);
        }
        loop {
            match self.peek() {
                Some(Token {
                    tok: Tok::Prime(n),
                    loc,
                }) => {
                    self.pos += 1;
                    let l = e.loc.to(*loc);
                    let Ok(order) = u8::try_from(*n) else {
                        return Err(Diagnostic::text(
                            l,
                            format!("derivative of order {n}: the DSL supports up to order 4"),
                        )
                        .help("write at most four primes (w''''), or ∇/Δ of order ≤ 4"));
                    };
                    e = Expr::new(ExprKind::Derivative(Box::new(e), order), l);
                }
                Some(Token {
                    tok: Tok::Superscript(value, raw),
                    loc,
                }) => {
                    self.pos += 1;
                    let n = match value {
                        Ok(n) => n,
                        Err(fault) => return Err(bad_superscript(*fault, raw, *loc)),
                    };
                    let l = e.loc.to(*loc);
                    e = Expr::new(ExprKind::Pow(Box::new(e), *n), l);
                }
                Some(Token {
                    tok: Tok::Caret,
                    loc,
                }) => {
                    self.pos += 1;
                    let (n, end) = self.ascii_exponent(*loc)?;
                    let l = e.loc.to(end);
                    e = Expr::new(ExprKind::Pow(Box::new(e), n), l);
                }
                _ => return Ok(e),
            }
        }
    }

    /// The power of an operator just read at `loc`: `Δ²` (the bilaplacian, ASCII
    /// `lap^2`) and `∂_x²` (ASCII `d_x^2`) apply it that many times; 1 without an
    /// exponent. Powers of the other operators are refused: `∇²` means the Laplacian to
    /// some readers and the Hessian to others, and `div²`, `ε²`, `tr²` nothing standard.
    /// Returns the power and the location of the operator with its exponent.
    fn operator_power(&mut self, op: &Tok, loc: Loc) -> Result<(u32, Loc)> {
        let (n, end) = match self.peek() {
            Some(Token {
                tok: Tok::Superscript(value, raw),
                loc: end,
            }) => {
                let (value, raw, end) = (*value, raw.clone(), *end);
                self.pos += 1;
                let n = match value {
                    Ok(n) => n,
                    Err(fault) => return Err(bad_superscript(fault, &raw, end)),
                };
                (n, end)
            }
            Some(Token {
                tok: Tok::Caret,
                loc: caret,
            }) => {
                let caret = *caret;
                self.pos += 1;
                self.ascii_exponent(caret)?
            }
            _ => return Ok((1, loc)),
        };
        let whole = loc.to(end);
        if !matches!(op, Tok::Laplacian | Tok::Partial(_)) {
            let help = match op {
                Tok::Grad => "write ∇∇ w for the Hessian or Δ w for the Laplacian",
                _ => "write the operator twice, e.g. div div A",
            };
            return Err(Diagnostic::text(
                whole,
                format!("{} cannot be raised to a power", describe(op)),
            )
            .help(help));
        }
        if n < 1 {
            return Err(Diagnostic::text(
                whole,
                format!(
                    "{} raised to {n}: only positive powers are derivatives",
                    describe(op)
                ),
            )
            .help("write a positive integer power: Δ² w, ∂_x² w"));
        }
        if n > MAX_OPERATOR_POWER {
            return Err(Diagnostic::text(
                whole,
                format!(
                    "{} raised to {n}: a derivative of order {} or more",
                    describe(op),
                    n.saturating_mul(if matches!(op, Tok::Laplacian) { 2 } else { 1 })
                ),
            )
            .help(format!("powers up to {MAX_OPERATOR_POWER} are derivatives some element can carry; the highest-degree element, Argyris, is quintic, and every derivative of order 6 or more of it is zero")));
        }
        Ok((n as u32, whole))
    }

    /// After `^`: `2`, `-2`, `(-2)`, `{-2}`.
    fn ascii_exponent(&mut self, caret: Loc) -> Result<(i32, Loc)> {
        let malformed = |loc: Loc| {
            Diagnostic::text(loc, "malformed exponent after `^`")
                .help("write an integer exponent: t^2, t^-2, t^(-2), or the superscripts t² t⁻²")
        };
        let close = match self.peek_tok() {
            Some(Tok::LParen) => Some(Tok::RParen),
            Some(Tok::LBrace) => Some(Tok::RBrace),
            _ => None,
        };
        if close.is_some() {
            self.pos += 1;
        }
        let mut sign = 1.0;
        match self.peek_tok() {
            Some(Tok::Minus) => {
                sign = -1.0;
                self.pos += 1;
            }
            Some(Tok::Plus) => self.pos += 1,
            _ => {}
        }
        let (value, mut end) = match self.peek() {
            Some(Token {
                tok: Tok::Number(v),
                loc,
            }) if v.fract() == 0.0 && v.abs() < 1e6 => (sign * v, *loc),
            Some(Token {
                tok: Tok::Number(v),
                loc,
            }) => {
                let (what, help) = if v.fract() == 0.0 {
                    (
                        format!("exponent {} is beyond the limit {MAX_TOTAL_POWER}", sign * v),
                        "a form is a polynomial of low degree in its fields and data: write the power you mean (h_T^4, t^-2)",
                    )
                } else {
                    (
                        format!("exponent {} is not an integer", sign * v),
                        "powers in forms are integers: t^2, t^-2; a fractional power of data belongs in the data's own expression",
                    )
                };
                return Err(Diagnostic::text(caret.to(*loc), what).help(help));
            }
            Some(t) => return Err(malformed(caret.to(t.loc))),
            None => return Err(malformed(caret)),
        };
        self.pos += 1;
        if let Some(close) = close {
            match self.peek() {
                Some(t) if t.tok == close => {
                    end = t.loc;
                    self.pos += 1;
                }
                _ => return Err(malformed(caret.to(end))),
            }
        }
        Ok((value as i32, end))
    }

    fn primary(&mut self) -> Result<Expr> {
        let Some(token) = self.peek() else {
            return Err(self.unexpected("an expression"));
        };
        let loc = token.loc;
        match &token.tok {
            Tok::Number(v) => {
                self.pos += 1;
                Ok(Expr::new(ExprKind::Number(*v), loc))
            }
            Tok::Ident(name) => {
                self.pos += 1;
                if self.form_names.contains(name) && self.peek_tok() == Some(&Tok::LParen) {
                    self.pos += 1;
                    let groups = self.argument_groups()?;
                    let l = loc.to(self.previous_loc());
                    return Ok(Expr::new(
                        ExprKind::Call {
                            name: name.clone(),
                            groups,
                        },
                        l,
                    ));
                }
                if self.peek_tok() == Some(&Tok::LParen) && self.parenthesis_has_semicolon(self.pos)
                {
                    return Err(self.unknown_form(name, loc));
                }
                Ok(Expr::new(ExprKind::Symbol(name.clone()), loc))
            }
            Tok::LParen => {
                self.pos += 1;
                let first = self.nested(loc, |p| p.sum(false))?;
                let second = if self.peek_tok() == Some(&Tok::Comma) {
                    self.pos += 1;
                    Some(self.nested(loc, |p| p.sum(false))?)
                } else {
                    None
                };
                match self.peek_tok() {
                    Some(Tok::RParen) => {}
                    None => {
                        return Err(Diagnostic::text(loc, "this `(` is never closed")
                            .help("add the matching `)`"))
                    }
                    Some(_) => {
                        return Err(self.unexpected("`)`").help(format!(
                            "the `(` at line {}, column {} is still open",
                            loc.line, loc.column
                        )))
                    }
                }
                let close = self.bump().unwrap().loc;
                let subscript = self.peek_tok() == Some(&Tok::SubscriptT);
                match (second, subscript) {
                    (Some(second), true) => {
                        let end = self.bump().unwrap().loc;
                        Ok(Expr::new(
                            ExprKind::InnerProduct(Box::new(first), Box::new(second)),
                            loc.to(end),
                        ))
                    }
                    (Some(second), false) => Ok(Expr::new(
                        ExprKind::Vector(Box::new(first), Box::new(second)),
                        loc.to(close),
                    )),
                    (None, true) => {
                        Err(Diagnostic::text(self.here(), "`(X)_T` needs two arguments")
                            .help("an L² product over an element is written `(X, Y)_T`"))
                    }
                    (None, false) => Ok(grouped(first, loc.to(close))),
                }
            }
            Tok::LBracket => {
                // `D[(1−ν)ε + ν tr ε I]`: brackets group like parentheses
                self.pos += 1;
                let inner = self.nested(loc, |p| p.sum(false))?;
                match self.peek_tok() {
                    Some(Tok::RBracket) => {}
                    None => {
                        return Err(Diagnostic::text(loc, "this `[` is never closed")
                            .help("add the matching `]`"))
                    }
                    Some(_) => {
                        return Err(self.unexpected("`]`").help(format!(
                            "the `[` at line {}, column {} is still open",
                            loc.line, loc.column
                        )))
                    }
                }
                let close = self.bump().unwrap().loc;
                Ok(grouped(inner, loc.to(close)))
            }
            Tok::Integral | Tok::SumT => {
                let kind = if token.tok == Tok::Integral {
                    IntegralKind::Integral
                } else {
                    IntegralKind::SumOverElements
                };
                self.pos += 1;
                let degree = if self.peek_tok() == Some(&Tok::LBracket) {
                    Some(self.quadrature_option()?)
                } else {
                    None
                };
                if self.peek().is_none() {
                    return Err(self.unexpected("an integrand"));
                }
                let body = self.nested(loc, |p| p.sum(true))?;
                if self.peek_tok() == Some(&Tok::Ds) {
                    return Err(Diagnostic::text(self.here(), "`ds` closes a boundary integral `∫_Γ … ds`")
                        .help("integrate over a boundary part declared under `facets:` with `∫_Γ … ds`, or drop `ds`: a cell integral `∫ …` needs none"));
                }
                let l = loc.to(body.loc);
                Ok(Expr::new(
                    ExprKind::Integral {
                        kind,
                        facet: None,
                        degree,
                        body: Box::new(body),
                    },
                    l,
                ))
            }
            Tok::FacetIntegral(part) => {
                let facet = Name {
                    text: part.clone(),
                    loc,
                };
                self.pos += 1;
                let degree = if self.peek_tok() == Some(&Tok::LBracket) {
                    Some(self.quadrature_option()?)
                } else {
                    None
                };
                if self.peek().is_none() || self.peek_tok() == Some(&Tok::Ds) {
                    return Err(self.unexpected("an integrand"));
                }
                let body = self.nested(loc, |p| p.sum(true))?;
                if self.peek_tok() != Some(&Tok::Ds) {
                    return Err(Diagnostic::text(
                        loc.to(body.loc),
                        format!("the boundary integral `∫_{part}` is not closed by `ds`"),
                    )
                    .help(format!("write `∫_{part} … ds`: `ds` ends the integrand")));
                }
                let close = self.bump().unwrap().loc;
                Ok(Expr::new(
                    ExprKind::Integral {
                        kind: IntegralKind::Integral,
                        facet: Some(facet),
                        degree,
                        body: Box::new(body),
                    },
                    loc.to(close),
                ))
            }
            Tok::Ds => Err(Diagnostic::text(loc, "`ds` without a boundary integral")
                .help("`ds` closes a boundary integral `∫_Γ … ds`")),
            Tok::RParen => Err(Diagnostic::text(loc, "unmatched `)`")
                .help("remove it, or add the `(` it was meant to close")),
            _ => Err(self.unexpected("an expression")),
        }
    }

    /// `[degree=N]` after `∫`.
    fn quadrature_option(&mut self) -> Result<usize> {
        let open = self.bump().unwrap().loc;
        let bad = |loc: Loc| {
            Diagnostic::text(loc, "malformed quadrature option")
                .help("write `∫[degree=N]` to integrate exactly polynomials of degree N (e.g. ∫[degree=1] for one-point reduced integration)")
        };
        match self.peek_tok() {
            Some(Tok::Ident(k)) if k == "degree" => self.pos += 1,
            _ => return Err(bad(self.here())),
        }
        if self.peek_tok() != Some(&Tok::Equals) {
            return Err(bad(self.here()));
        }
        self.pos += 1;
        let degree = match self.peek_tok() {
            Some(Tok::Number(v)) if v.fract() == 0.0 && *v >= 0.0 && *v <= MAX_DEGREE as f64 => {
                *v as usize
            }
            Some(Tok::Number(v)) if v.fract() == 0.0 && *v > MAX_DEGREE as f64 => {
                return Err(Diagnostic::text(
                    self.here(),
                    format!("quadrature degree {v} is above the limit {MAX_DEGREE}"),
                )
                .help(format!("write `∫[degree=N]` with N from 0 to {MAX_DEGREE}")))
            }
            _ => return Err(bad(self.here())),
        };
        self.pos += 1;
        if self.peek_tok() != Some(&Tok::RBracket) {
            return Err(bad(open.to(self.here())));
        }
        self.pos += 1;
        Ok(degree)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lexer::tokenize;

    fn parse(text: &str) -> (Vec<Definition>, Vec<Diagnostic>) {
        let (tokens, errors) = tokenize(text);
        assert!(errors.is_empty());
        parse_forms(&tokens)
    }

    fn sexpr(e: &Expr) -> String {
        use ExprKind::*;
        match &e.kind {
            Number(v) => format!("{v}"),
            Symbol(s) => s.clone(),
            Neg(a) => format!("(- {})", sexpr(a)),
            Add(a, b) => format!("(+ {} {})", sexpr(a), sexpr(b)),
            Sub(a, b) => format!("(- {} {})", sexpr(a), sexpr(b)),
            Mul(a, b) => format!("(* {} {})", sexpr(a), sexpr(b)),
            Div(a, b) => format!("(/ {} {})", sexpr(a), sexpr(b)),
            Pow(a, n) => format!("(^ {} {n})", sexpr(a)),
            Derivative(a, n) => format!("(d{n} {})", sexpr(a)),
            Gradient(a) => format!("(grad {})", sexpr(a)),
            Laplacian(a) => format!("(lap {})", sexpr(a)),
            Partial(a, axis) => format!("(d_{axis} {})", sexpr(a)),
            SymmetricGradient(a) => format!("(eps {})", sexpr(a)),
            Divergence(a) => format!("(div {})", sexpr(a)),
            Trace(a) => format!("(tr {})", sexpr(a)),
            Contract(a, b) => format!("(: {} {})", sexpr(a), sexpr(b)),
            InnerProduct(a, b) => format!("(ip {} {})", sexpr(a), sexpr(b)),
            Vector(a, b) => format!("(vec {} {})", sexpr(a), sexpr(b)),
            Integral { degree, body, .. } => format!("(int{degree:?} {})", sexpr(body)),
            Call { name, groups } => format!(
                "(call {name} {})",
                groups
                    .iter()
                    .map(|g| g
                        .iter()
                        .map(|n| n.text.clone())
                        .collect::<Vec<_>>()
                        .join(","))
                    .collect::<Vec<_>>()
                    .join(";")
            ),
        }
    }

    #[test]
    fn the_users_timoshenko_line() {
        let (defs, errors) = parse("a(θ,w;η,v) = ∫θ'η' + t⁻²(w'−θ)(v'−η)");
        assert!(errors.is_empty(), "{errors:?}");
        assert_eq!(defs[0].name.text, "a");
        assert_eq!(defs[0].groups.len(), 2);
        assert_eq!(
            sexpr(&defs[0].body),
            "(intNone (+ (* (d1 θ) (d1 η)) (* (* (^ t -2) (- (d1 w) θ)) (- (d1 v) η))))"
        );
        let (ascii, errors) = parse("a(θ,w;η,v) = int θ'η' + t^-2 (w'-θ)(v'-η)");
        assert!(errors.is_empty());
        assert_eq!(sexpr(&ascii[0].body), sexpr(&defs[0].body));
    }

    #[test]
    fn integrals_and_calls_split_at_new_form_terms() {
        let text = "a(u;v) = ∫ u'v' + ∫[degree=1] u v\n\
                    b(u;v) = ∫ u v\n\
                    B(u;v) = a(u;v) − 2 α b(u;v)\n\
                    S(u;v) = Σ_T h_T⁴ (u'' − 1, v'')_T";
        let (defs, errors) = parse(text);
        assert!(errors.is_empty(), "{errors:?}");
        assert_eq!(
            sexpr(&defs[0].body),
            "(+ (intNone (* (d1 u) (d1 v))) (intSome(1) (* u v)))"
        );
        assert_eq!(
            sexpr(&defs[2].body),
            "(- (call a u;v) (* (* 2 α) (call b u;v)))"
        );
        assert_eq!(
            sexpr(&defs[3].body),
            "(intNone (* (^ h_T 4) (ip (- (d2 u) 1) (d2 v))))"
        );
    }

    #[test]
    fn definitions_may_wrap_lines() {
        let (defs, errors) = parse("a(u;v) = ∫ u'v'\n    + u v\nℓ(v) = ∫ f v");
        assert!(errors.is_empty());
        assert_eq!(defs.len(), 2);
        assert_eq!(defs[0].lines, (1, 2));
        assert_eq!(
            sexpr(&defs[0].body),
            "(intNone (+ (* (d1 u) (d1 v)) (* u v)))"
        );
    }

    #[test]
    fn errors_in_several_definitions_are_all_reported() {
        let (_, errors) = parse("a(u;v) = ∫ (u v\nb(u;v) = ∫ u v)\nc(u;v) = ∫ t^ u v");
        assert_eq!(errors.len(), 3, "{errors:?}");
        assert!(errors[0].message.contains("never closed"));
        assert!(errors[1].message.contains("unmatched `)`"));
        assert!(errors[2].message.contains("malformed exponent"));
    }

    #[test]
    fn gradients_bind_tighter_than_products() {
        let (defs, errors) = parse("a(u;v) = ∫ ∇u·∇v + h²(Δu + f, Δv)_T");
        assert!(errors.is_empty(), "{errors:?}");
        assert_eq!(
            sexpr(&defs[0].body),
            "(intNone (+ (* (grad u) (grad v)) (* (^ h 2) (ip (+ (lap u) f) (lap v)))))"
        );
        let (_, errors) = parse("a(u;v) = ∫ ∇ + v");
        assert_eq!(errors.len(), 1);
    }

    #[test]
    fn tensor_operators_bind_like_gradients() {
        let (defs, errors) =
            parse("a(θ;η) = ∫ D[(1−ν)ε(θ) + ν tr ε(θ) I] : ε(η) + div div θ ∂_x η_y");
        assert!(errors.is_empty(), "{errors:?}");
        assert_eq!(
            sexpr(&defs[0].body),
            "(intNone (+ (: (* D (+ (* (- 1 ν) (eps θ)) (* (* ν (tr (eps θ))) I))) (eps η)) (* (div (div θ)) (d_0 η_y))))"
        );
        let (_, errors) = parse("a(u;v) = ∫ u [u v");
        assert!(errors[0].message.contains("never closed"), "{errors:?}");
        let (_, errors) = parse("a(u;v) = ∫ div + v");
        assert!(errors[0].message.contains("after `div`"), "{errors:?}");
    }

    #[test]
    fn named_expressions_use_colon_equals() {
        let (defs, errors) = parse("Cε(θ) := D[ε(θ)]\na(θ;η) = ∫ Cε(θ):ε(η)");
        assert!(errors.is_empty(), "{errors:?}");
        assert!(defs[0].expression && !defs[1].expression);
        assert_eq!(sexpr(&defs[1].body), "(intNone (: (call Cε θ) (eps η)))");
        let (_, errors) = parse("C(θ;η) := θ η");
        assert!(
            errors[0].message.contains("one argument list"),
            "{errors:?}"
        );
    }

    #[test]
    fn powers_and_signs() {
        let (defs, errors) = parse("a(u;v) = ∫ −2·t^(-2) h^{3} u/4 v + -u v");
        assert!(errors.is_empty(), "{errors:?}");
        assert_eq!(
            sexpr(&defs[0].body),
            "(intNone (+ (- (* (/ (* (* (* 2 (^ t -2)) (^ h 3)) u) 4) v)) (- (* u v))))"
        );
    }
}
