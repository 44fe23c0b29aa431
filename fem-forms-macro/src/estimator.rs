//! The `estimator:` text: a residual a-posteriori estimator declared next to the forms.
//!
//! ```text
//! estimator: "
//!     η_T² = h_T² ‖f + Δu + λ‖²
//!     η_E² = h_E ‖[[∇u·n]]‖²
//! ";
//! ```
//!
//! `η_T²` is the squared indicator of a cell T, a sum of weighted squared L² norms over
//! T of residuals; `η_E²` that of an interior edge E, a sum of weighted squared L² norms
//! over E of jumps `[[X]] = X⁺ − X⁻` across it (`n` the unit normal of E, pointing out
//! of the cell on the `+` side; the square does not depend on the choice). A residual is
//! an expression of the form language that is linear in the unknowns (written by their
//! names: the estimator is a function of the discrete solution) plus data; it may call
//! the named expressions of the forms text (`Cε(θ)`). A weight is a scalar of
//! parameters and the element size (`h_T` on cells, `h_E` on edges). On edges, `n` is
//! the unit normal and `τ = (−n_y, n_x)` the unit tangent (`τ·∇X` the tangential
//! derivative, as in the Kirchhoff shear `V_n = Q·n + ∂_s M_ns`).
//!
//! `η_Γ²`, for a boundary part `Γ` of the model's `facets:` (`η_Γ_C²`, ASCII
//! `eta_Gamma_C^2` for a part declared `Gamma_C`), is the squared indicator of each edge
//! of that part: weighted squared norms over the edge of residuals of the boundary
//! condition, traced from the one cell next to it (`n` its outward normal), with data
//! (`h_E ‖σ(u)·n + q n‖²` on a loaded part, `h_E ‖σ(u)·n + λ (n_c_x, n_c_y)‖²` on a
//! contact part).
//!
//! Every mistake is a compile error at the place in the estimator text.

use crate::analysis::{expand_estimator_expression, Form, Symbols};
use crate::diagnostic::{Diagnostic, Loc};
use crate::lexer::{Tok, Token};
use crate::symbolic::Expansion;
use std::collections::HashSet;

/// Where a term of the estimator is integrated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Region {
    /// Over each cell: `h_T^p ‖R‖²_T`.
    Cell,
    /// Over each interior edge, of a jump: `h_E^p ‖[[X]]‖²_E`.
    Edge,
    /// Over each edge of the boundary part with this index in the model's `facets:`, of
    /// a residual traced from the edge's cell: `h_E^p ‖R‖²_E`.
    Boundary(usize),
    /// Over each boundary edge outside the boundary parts where the test coordinate
    /// `Estimator::natural[k]` is free (a natural boundary condition: that flux vanishes
    /// there): an interior edge term's flux traced from the edge's cell, `h_E^p ‖F‖²_E`.
    Natural(usize),
}

impl Region {
    /// Whether the terms are integrated over edges (interior or boundary): `n`, `τ`
    /// and `h_E` exist there.
    pub fn on_edges(self) -> bool {
        self != Region::Cell
    }
}

/// One weighted squared norm of the estimator.
#[derive(Clone, Debug)]
pub struct IndicatorTerm {
    /// Cells or interior edges.
    pub region: Region,
    /// The weight: a sum of scalar monomials (parameters, `h`, divisors).
    pub weight: Expansion,
    /// The residual (a cell's) or the quantity whose jump is taken (an edge's): each
    /// monomial holds at most one unknown's derivative, the others are data terms.
    pub residual: Expansion,
    /// The term as written, for the docs.
    pub source: String,
    /// Where the term starts in the estimator text, for errors.
    pub loc: Loc,
    /// On an interior edge: the average `{X} = ½(X⁺ + X⁻)` of the two sides instead of
    /// the jump `[[X]] = X⁺ − X⁻`.
    pub average: bool,
    /// On a cell, `‖X‖²[degree=N]`: the Gauss rule exact for degree N integrates the
    /// norm (a reduced-integration form's quantity), instead of the rule exact for `X²`.
    pub quadrature_degree: Option<usize>,
}

/// An analysed estimator.
#[derive(Clone, Debug, Default)]
pub struct Estimator {
    /// Its terms, cells' and edges'.
    pub terms: Vec<IndicatorTerm>,
    /// The test coordinates `(field, j)` (the coefficient of `v` for `j = 0`, of `∂_n v`
    /// for `j = 1`) whose flux an interior edge term is, in the order of the
    /// [`Region::Natural`] terms: where such a coordinate is free on the boundary its
    /// flux vanishes, and the term applies one-sided ([`crate::derived::natural_terms`]).
    pub natural: Vec<(usize, u8)>,
}

impl Estimator {
    /// The terms over `region`.
    pub fn terms(&self, region: Region) -> impl Iterator<Item = &IndicatorTerm> {
        self.terms.iter().filter(move |t| t.region == region)
    }
}

/// The place of a token run, for errors (at least one character).
fn span(tokens: &[Token]) -> Loc {
    match (tokens.first(), tokens.last()) {
        (Some(a), Some(b)) if a.loc.line == b.loc.line => Loc {
            len: (b.loc.column + b.loc.len)
                .saturating_sub(a.loc.column)
                .max(1),
            ..a.loc
        },
        (Some(a), _) => a.loc,
        _ => Loc {
            line: 1,
            column: 1,
            len: 1,
        },
    }
}

/// The region a line's head names: `η_T²`, `η_E²` or `η_Γ²` for a boundary part `Γ`
/// of `facets` (ASCII `eta_T^2`), with the number of tokens it takes.
fn head(tokens: &[Token], facets: &[String]) -> Option<(Region, usize)> {
    let Tok::Ident(name) = &tokens.first()?.tok else {
        return None;
    };
    let rest = name
        .strip_prefix("η_")
        .or_else(|| name.strip_prefix("eta_"))?;
    let region = match rest {
        "T" => Region::Cell,
        "E" => Region::Edge,
        part => Region::Boundary(facets.iter().position(|f| f == part)?),
    };
    let squared = match (&tokens.get(1)?.tok, tokens.get(2).map(|t| &t.tok)) {
        (Tok::Superscript(Ok(2), _), _) => 2,
        (Tok::Caret, Some(Tok::Number(n))) if *n == 2.0 => 3,
        _ => return None,
    };
    (tokens.get(squared)?.tok == Tok::Equals).then_some((region, squared + 1))
}

/// Parses and analyses the estimator text's tokens against the model's symbols and its
/// analysed forms (whose named expressions the norms may call).
pub fn analyse(
    tokens: &[Token],
    text: &str,
    symbols: &Symbols,
    forms: &[Form],
) -> (Estimator, Vec<Diagnostic>) {
    let mut errors = Vec::new();
    let mut estimator = Estimator::default();
    let lines: Vec<&[Token]> = tokens
        .split(|t| t.tok == Tok::Newline)
        .filter(|l| !l.is_empty())
        .collect();
    if lines.is_empty() {
        errors.push(
            Diagnostic::text(span(&[]), "the estimator text declares no indicator").help(
                "write `η_T² = h_T² ‖f + Δu + λ‖²` and `η_E² = h_E ‖[[∇u·n]]‖²`, one per line",
            ),
        );
    }
    let names: HashSet<String> = forms.iter().map(|f| f.name.clone()).collect();
    let ordered: Vec<String> = forms.iter().map(|f| f.name.clone()).collect();
    let context = Analysis {
        symbols,
        forms,
        names: &names,
        ordered: &ordered,
        text,
    };
    // a line that does not start with a head continues the one above
    let mut definitions: Vec<(Region, Vec<Token>)> = Vec::new();
    for line in lines {
        match (head(line, &symbols.facets), definitions.last_mut()) {
            (Some((region, skip)), _) => definitions.push((region, line[skip..].to_vec())),
            (None, Some((_, body))) => body.extend_from_slice(line),
            (None, None) => errors.push(
                Diagnostic::text(line[0].loc, "expected `η_T² =`, `η_E² =` or `η_Γ² =` of a boundary part")
                    .help(format!("each line of the estimator is a cell's squared indicator `η_T² = …`, an interior edge's `η_E² = …` or the edges' of a boundary part declared under `facets:` ({}) (a line that starts otherwise continues the one above)", if symbols.facets.is_empty() { "this model declares none".to_string() } else { symbols.facets.iter().map(|f| format!("`η_{f}² = …`")).collect::<Vec<_>>().join(", ") })),
            ),
        }
    }
    for (region, body) in &definitions {
        let region = *region;
        for term in split_terms(body) {
            match context.term(region, term) {
                Ok(t) => estimator.terms.extend(t),
                Err(mut e) => errors.append(&mut e),
            }
        }
    }
    (estimator, errors)
}

/// The terms of a line's right-hand side: split at the `+` signs outside norms and
/// brackets.
fn split_terms(tokens: &[Token]) -> Vec<&[Token]> {
    let mut terms = Vec::new();
    let (mut depth, mut inside_norm, mut start) = (0i32, false, 0);
    for (i, t) in tokens.iter().enumerate() {
        match t.tok {
            Tok::LParen | Tok::LBracket | Tok::LBrace => depth += 1,
            Tok::RParen | Tok::RBracket | Tok::RBrace => depth -= 1,
            Tok::Norm => inside_norm = !inside_norm,
            Tok::Plus if depth == 0 && !inside_norm && i > start => {
                terms.push(&tokens[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    terms.push(&tokens[start..]);
    terms
}

struct Analysis<'a> {
    symbols: &'a Symbols,
    forms: &'a [Form],
    names: &'a HashSet<String>,
    ordered: &'a [String],
    text: &'a str,
}

impl Analysis<'_> {
    /// One term `weight ‖body‖²` over `region`: one indicator term per entry of the
    /// body (a vector's components, a matrix's entries).
    fn term(
        &self,
        region: Region,
        tokens: &[Token],
    ) -> Result<Vec<IndicatorTerm>, Vec<Diagnostic>> {
        let example = match region {
            Region::Cell => "h_T² ‖f + Δu + λ‖²",
            Region::Edge => "h_E ‖[[∇u·n]]‖²",
            Region::Boundary(_) | Region::Natural(_) => "h_E ‖σ(u)·n + q n‖²",
        };
        if matches!(region, Region::Boundary(_)) && self.symbols.dimension != 2 {
            return Err(vec![Diagnostic::text(
                span(tokens),
                "a boundary part's indicator on an interval",
            )
            .help("boundary parts are edges of triangles; on an interval the indicators are `η_T²` and the interior nodes' `η_E²`")]);
        }
        let bars: Vec<usize> = (0..tokens.len())
            .filter(|&i| tokens[i].tok == Tok::Norm)
            .collect();
        let squared = |i: usize| match (tokens.get(i).map(|t| &t.tok), tokens.get(i + 1)) {
            (Some(Tok::Superscript(Ok(2), _)), _) => Some(i + 1),
            (Some(Tok::Caret), Some(t)) if t.tok == Tok::Number(2.0) => Some(i + 2),
            _ => None,
        };
        let [open, close] = bars[..] else {
            return Err(vec![Diagnostic::text(
                span(tokens),
                "a term of an estimator is a weight times one squared norm",
            )
            .help(format!("write it as `{example}`"))]);
        };
        let quadrature_degree = match squared(close + 1) {
            Some(end) if end == tokens.len() => None,
            Some(end) if tokens[end].tok == Tok::LBracket => {
                if region != Region::Cell {
                    return Err(vec![Diagnostic::text(
                        span(&tokens[end..]),
                        "a quadrature option on an edge's norm",
                    )
                    .help("`[degree=N]` integrates a cell's norm as a reduced-integration form does; an edge's norm is integrated exactly (a point value on an interval)")]);
                }
                Some(quadrature_option(&tokens[end..], example)?)
            }
            _ => {
                return Err(vec![Diagnostic::text(
                    tokens[close].loc,
                    "the norm must be squared, and end the term",
                )
                .help(format!("indicators are sums of squares: write `{example}`"))])
            }
        };
        let weight_tokens = &tokens[..open];
        let body = &tokens[open + 1..close];
        let average = region == Region::Edge && average_inside(body).is_some();
        let body = match region {
            Region::Edge => match average_inside(body) {
                Some(inside) => inside,
                None => jump_inside(body, example)?,
            },
            Region::Cell | Region::Boundary(_) | Region::Natural(_) => body,
        };
        if body.is_empty() {
            return Err(vec![Diagnostic::text(tokens[open].loc, "an empty norm")
                .help(format!("write `{example}`"))]);
        }
        let edge = region.on_edges();
        let weight = if weight_tokens.is_empty() {
            vec![crate::symbolic::Monomial::constant(1.0, tokens[open].loc)]
        } else {
            match &self.expand(weight_tokens, edge)?[..] {
                [weight] => weight.clone(),
                _ => {
                    return Err(vec![Diagnostic::text(
                        span(weight_tokens),
                        "the weight of a norm is a vector or a matrix",
                    )
                    .help(
                        "a weight is a scalar of parameters and the element size (`h_T²`, `α h_E`)",
                    )])
                }
            }
        };
        if let Some(m) = weight.iter().find(|m| !m.is_scalar() || m.normal != [0, 0]) {
            return Err(vec![Diagnostic::text(
                m.origin,
                "the weight of a norm holds an unknown, data or the normal",
            )
            .help("a weight is a scalar of parameters and the element size (`h_T²`, `α h_E`); move the rest into the norm")]);
        }
        let mut entries = self.expand(body, edge)?;
        // a vector's vanishing component is no term; a norm of zero is an error below
        entries.retain(|e| !e.is_empty());
        if entries.is_empty() {
            entries.push(Expansion::new());
        }
        for residual in &entries {
            self.check_residual(region, residual, body, average)?;
        }
        check_sizes(region, weight_tokens, body)?;
        let first = tokens[0].loc;
        let last = tokens[tokens.len() - 1].loc;
        let source = source_text(self.text, first, last);
        Ok(entries
            .into_iter()
            .map(|residual| IndicatorTerm {
                region,
                weight: weight.clone(),
                residual,
                source: source.clone(),
                loc: span(tokens),
                average,
                quadrature_degree,
            })
            .collect())
    }

    fn expand(&self, tokens: &[Token], edge: bool) -> Result<Vec<Expansion>, Vec<Diagnostic>> {
        let expr = crate::parser::parse_expression_calling(tokens, self.names, self.ordered)
            .map_err(|e| vec![e])?;
        expand_estimator_expression(self.symbols, self.forms, &expr, edge)
    }

    /// A residual is linear in the unknowns (by their names) and, in a jump, holds no
    /// data alone.
    fn check_residual(
        &self,
        region: Region,
        residual: &Expansion,
        body: &[Token],
        average: bool,
    ) -> Result<(), Vec<Diagnostic>> {
        let fields = self.symbols.fields.len();
        for m in residual {
            if m.args.len() > 1 {
                return Err(vec![Diagnostic::text(
                    m.origin,
                    "a residual in an estimator is linear in the unknowns",
                )
                .help("an indicator is the norm of a residual `𝒜u − sλ − f`: a product of two unknowns has no place in it")]);
            }
            if let Some(a) = m.args.first() {
                if a.symbol >= fields {
                    return Err(vec![Diagnostic::text(
                        m.origin,
                        format!(
                            "test function `{}` in an estimator",
                            self.symbols.function_name(a.symbol)
                        ),
                    )
                    .help(format!(
                        "an estimator is a function of the discrete solution: write the unknown `{}`",
                        self.symbols.fields[self.symbols.field_of(a.symbol)].name
                    ))]);
                }
            } else if region == Region::Edge && !average {
                return Err(vec![Diagnostic::text(
                    m.origin,
                    if m.data.is_empty() {
                        "a term without an unknown in a jump: a constant jumps by zero"
                    } else {
                        "data alone in a jump: continuous data jump by zero"
                    },
                )
                .help(
                    "a jump `[[X]]` is taken of the unknowns' traces; leave the term out",
                )]);
            }
            if region == Region::Cell && m.normal != [0, 0] {
                return Err(vec![Diagnostic::text(
                    span(body),
                    "the normal `n` in a cell's residual",
                )
                .help(
                    "`n` exists on edges: use it in `η_E²` or a boundary part's `η_Γ²`",
                )]);
            }
        }
        if residual.iter().all(|m| m.args.is_empty()) {
            return Err(vec![Diagnostic::text(
                span(body),
                "this norm does not depend on the solution",
            )
            .help(
                "an indicator measures a residual of the discrete solution: name an unknown in it",
            )]);
        }
        Ok(())
    }
}

/// The quadrature option `[degree=N]` after a cell's squared norm, as in the forms'
/// `∫[degree=N]`: the norm is integrated by the Gauss rule exact for degree N, so that an
/// indicator sees the reduced-integration quantity its form does (one point, `degree=1`:
/// the shear strain `t⁻²(w' − θ)` of `∫[degree=1]` at the cell's midpoint).
fn quadrature_option(tokens: &[Token], example: &str) -> Result<usize, Vec<Diagnostic>> {
    let bad = || {
        vec![Diagnostic::text(span(tokens), "malformed quadrature option of a norm")
            .help(format!("write `{example}[degree=N]` to integrate the squared norm by the Gauss rule exact for degree N (`[degree=1]`: one point, as `∫[degree=1]` in a form)"))]
    };
    match tokens {
        [open, key, equals, number, close]
            if open.tok == Tok::LBracket
                && key.tok == Tok::Ident("degree".into())
                && equals.tok == Tok::Equals
                && close.tok == Tok::RBracket =>
        {
            match number.tok {
                Tok::Number(v)
                    if v.fract() == 0.0 && v >= 0.0 && v <= crate::parser::MAX_DEGREE as f64 =>
                {
                    Ok(v as usize)
                }
                _ => Err(bad()),
            }
        }
        _ => Err(bad()),
    }
}

/// `{X}` → `X` (the average of the two sides), where the whole body is one brace group.
fn average_inside(body: &[Token]) -> Option<&[Token]> {
    let n = body.len();
    if n < 3 || body[0].tok != Tok::LBrace || body[n - 1].tok != Tok::RBrace {
        return None;
    }
    // the opening brace must close at the end, not before (`{a} + {b}` is no average)
    let mut depth = 0i32;
    for (i, t) in body.iter().enumerate() {
        match t.tok {
            Tok::LBrace => depth += 1,
            Tok::RBrace => {
                depth -= 1;
                if depth == 0 && i + 1 < n {
                    return None;
                }
            }
            _ => {}
        }
    }
    Some(&body[1..n - 1])
}

/// `[[X]]` → `X`, or the error that says how to write a jump.
fn jump_inside<'t>(body: &'t [Token], example: &str) -> Result<&'t [Token], Vec<Diagnostic>> {
    let n = body.len();
    let jump = n >= 5
        && body[0].tok == Tok::LBracket
        && body[1].tok == Tok::LBracket
        && body[n - 2].tok == Tok::RBracket
        && body[n - 1].tok == Tok::RBracket;
    if jump {
        Ok(&body[2..n - 2])
    } else {
        Err(vec![Diagnostic::text(
            span(body),
            "an edge's norm is that of a jump `[[X]]`",
        )
        .help(format!(
            "write `{example}`, or the average `{{X}}` of the two sides"
        ))])
    }
}

/// `h_E` on a cell, `h_T` in an edge's weight and `h_E` inside a jump are errors at the
/// name: inside a jump `h_T` (or `h`) is the size of the cell on each side (a Stenberg
/// weight `(t² + βh_T²)⁻¹` in a shear force), outside it the edge's length `h_E`.
fn check_sizes(region: Region, weight: &[Token], body: &[Token]) -> Result<(), Vec<Diagnostic>> {
    let find = |tokens: &[Token], name: &str| {
        tokens
            .iter()
            .find(|t| t.tok == Tok::Ident(name.into()))
            .map(|t| t.loc)
    };
    let wrong = match region {
        Region::Cell => find(weight, "h_E")
            .or_else(|| find(body, "h_E"))
            .map(|at| (at, "`h_E` in an `η_T²` line", "the size there is `h_T`")),
        Region::Boundary(_) | Region::Natural(_) => find(weight, "h_T")
            .map(|at| {
                (
                    at,
                    "`h_T` in the weight of a boundary part's line",
                    "the size there is the edge's `h_E`; inside the norm `h_T` is the size of the edge's cell",
                )
            })
            .or_else(|| {
                find(body, "h_E").map(|at| {
                    (
                        at,
                        "`h_E` inside the norm of a boundary part's line",
                        "inside the norm the size is the edge's cell's `h_T`; the edge's `h_E` goes in the weight",
                    )
                })
            }),
        Region::Edge => find(weight, "h_T")
            .map(|at| {
                (
                    at,
                    "`h_T` in the weight of an `η_E²` line",
                    "the size there is `h_E`; inside a jump `h_T` is each side's cell size",
                )
            })
            .or_else(|| {
                find(body, "h_E").map(|at| {
                    (
                        at,
                        "`h_E` inside a jump",
                        "inside `[[…]]` the size is each side's `h_T`; the edge's `h_E` goes in the weight",
                    )
                })
            }),
    };
    match wrong {
        Some((at, message, help)) => Err(vec![Diagnostic::text(at, message).help(help)]),
        None => Ok(()),
    }
}

/// The text between two places of the estimator text (on one line or several).
fn source_text(text: &str, first: Loc, last: Loc) -> String {
    let lines: Vec<&str> = text.lines().collect();
    let take = |line: usize, from: usize, to: Option<usize>| -> String {
        let chars: Vec<char> = lines
            .get(line - 1)
            .map_or(Vec::new(), |l| l.chars().collect());
        let end = to.unwrap_or(chars.len()).min(chars.len());
        chars[(from - 1).min(end)..end].iter().collect()
    };
    if first.line == last.line {
        take(first.line, first.column, Some(last.column - 1 + last.len))
    } else {
        let mut s = take(first.line, first.column, None);
        for line in first.line + 1..last.line {
            s.push(' ');
            s.push_str(take(line, 1, None).trim());
        }
        s.push(' ');
        s.push_str(take(last.line, 1, Some(last.column - 1 + last.len)).trim());
        s
    }
    .trim()
    .to_string()
}
