//! Tokens of the forms text: the math notation with its Unicode and ASCII spellings.
//!
//! | meaning            | Unicode            | ASCII            |
//! |--------------------|--------------------|------------------|
//! | integral           | `∫`, `∫_Ω`         | `int`, `int_Omega` |
//! | boundary integral  | `∫_Γ … ds`         | `int_Γ … ds`     |
//! | sum over elements  | `Σ_T`, `∑_T`       | `sum_T`          |
//! | derivative         | `′ ″ ‴ ⁗`, `'`     | `'`, `''`, …     |
//! | power              | `⁻² ³ ⁴`           | `^-2`, `^(-2)`   |
//! | minus              | `−` (U+2212), `–`  | `-`              |
//! | product            | `·`, `⋅`, `×`, juxtaposition | `*`, `dot` |
//! | gradient           | `∇`                | `grad`           |
//! | Laplacian          | `Δ`                | `lap`            |
//! | partial derivative | `∂_x`, `∂_y`       | `d_x`, `d_y`     |
//! | symmetric gradient | `ε`                | `eps`            |
//! | divergence         | `div`              | `div`            |
//! | trace              | `tr`               | `tr`             |
//! | double contraction | `:`                | `:`              |
//! | grouping           | `( … )`, `[ … ]`   | the same         |
//!
//! A product of two vectors (`∇u·∇v`, `grad u dot grad v`) is their dot product; `A:B`
//! contracts two matrices. `I` (the identity matrix) is a name, resolved by the analysis.

use crate::diagnostic::{Diagnostic, Loc};

/// A token kind.
#[derive(Clone, Debug, PartialEq)]
pub enum Tok {
    /// A name: a letter or `_`, then letters, digits, `_`.
    Ident(String),
    /// A decimal number.
    Number(f64),
    /// `∫` or `int`.
    Integral,
    /// `Σ_T`, `∑_T` or `sum_T`.
    SumT,
    /// `∫_Γ` or `int_Γ`: an integral over the boundary part named `Γ` (the name as written).
    FacetIntegral(String),
    /// `ds`: closes a boundary integral `∫_Γ … ds`.
    Ds,
    /// A run of primes: the derivative order (counted in full, so that 300 primes are
    /// reported as order 300).
    Prime(u32),
    /// A run of superscript characters, e.g. `⁻²`, with its value, or why it has none.
    Superscript(Result<i32, ExponentFault>, String),
    /// `^`
    Caret,
    /// `+`
    Plus,
    /// `-`, `−`, `–`
    Minus,
    /// `*`, `·`, `⋅`, `×`, `dot`
    Star,
    /// `∇` or `grad`
    Grad,
    /// `Δ` or `lap`
    Laplacian,
    /// `∂_x` (axis 0) or `∂_y` (axis 1); ASCII `d_x`, `d_y`
    Partial(u8),
    /// `ε` or `eps`: the symmetric gradient
    SymGrad,
    /// `div`
    Divergence,
    /// `tr`
    Trace,
    /// `:` the double contraction of two matrices
    Colon,
    /// `/`
    Slash,
    /// `(`
    LParen,
    /// `)`
    RParen,
    /// `[`
    LBracket,
    /// `]`
    RBracket,
    /// `{`
    LBrace,
    /// `}`
    RBrace,
    /// `,`
    Comma,
    /// `;`
    Semicolon,
    /// `=`
    Equals,
    /// `_T` right after `)`: closes an L² product `(X, Y)_T`.
    SubscriptT,
    /// `‖` (or `||`): a norm's bar, in the `estimator:` text (`h_T² ‖f + Δu + λ‖²`).
    Norm,
    /// End of a line (definitions start at the beginning of a line).
    Newline,
}

/// Why a run of superscripts is no exponent.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ExponentFault {
    /// Not an integer: `⁻⁻²`, `⁺⁻`.
    Malformed,
    /// An integer beyond `i32`: `⁹⁹⁹⁹⁹⁹⁹⁹⁹⁹⁹`.
    TooLarge,
}

impl ExponentFault {
    /// The value of the ASCII spelling `ascii` of a superscript run (`-2` for `⁻²`).
    fn parse(ascii: &str) -> Result<i32, ExponentFault> {
        let digits = ascii.strip_prefix(['+', '-']).unwrap_or(ascii);
        if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
            return Err(ExponentFault::Malformed);
        }
        ascii
            .trim_start_matches('+')
            .parse::<i32>()
            .map_err(|_| ExponentFault::TooLarge)
    }
}

/// A token with its place.
#[derive(Clone, Debug, PartialEq)]
pub struct Token {
    /// What it is.
    pub tok: Tok,
    /// Where it is.
    pub loc: Loc,
}

fn superscript_value(c: char) -> Option<char> {
    Some(match c {
        '⁰' => '0',
        '¹' => '1',
        '²' => '2',
        '³' => '3',
        '⁴' => '4',
        '⁵' => '5',
        '⁶' => '6',
        '⁷' => '7',
        '⁸' => '8',
        '⁹' => '9',
        '⁻' => '-',
        '⁺' => '+',
        _ => return None,
    })
}

fn prime_count(c: char) -> Option<u8> {
    match c {
        '\'' | '′' => Some(1),
        '″' => Some(2),
        '‴' => Some(3),
        '⁗' => Some(4),
        _ => None,
    }
}

fn is_ident_start(c: char) -> bool {
    (c.is_alphabetic() || c == '_') && superscript_value(c).is_none() && c != 'Δ'
}

fn is_ident_continue(c: char) -> bool {
    (c.is_alphanumeric() || c == '_') && superscript_value(c).is_none() && c != 'Δ'
}

/// Splits the forms text into tokens; unknown characters become errors (lexing goes on).
pub fn tokenize(text: &str) -> (Vec<Token>, Vec<Diagnostic>) {
    let chars: Vec<char> = text.chars().collect();
    let mut tokens = Vec::new();
    let mut errors = Vec::new();
    let (mut i, mut line, mut column) = (0usize, 1usize, 1usize);
    while i < chars.len() {
        let c = chars[i];
        let start = Loc {
            line,
            column,
            len: 1,
        };
        let push = |tok: Tok, len: usize, tokens: &mut Vec<Token>| {
            tokens.push(Token {
                tok,
                loc: Loc { len, ..start },
            });
        };
        if c == '\n' {
            push(Tok::Newline, 1, &mut tokens);
            i += 1;
            line += 1;
            column = 1;
            continue;
        }
        if c.is_whitespace() {
            i += 1;
            column += 1;
            continue;
        }
        if c == '#' {
            while i < chars.len() && chars[i] != '\n' {
                i += 1;
                column += 1;
            }
            continue;
        }
        let mut j = i + 1;
        if let Some(n) = prime_count(c) {
            let mut order = n as usize;
            while j < chars.len() {
                match prime_count(chars[j]) {
                    Some(m) => order += m as usize,
                    None => break,
                }
                j += 1;
            }
            push(
                Tok::Prime(u32::try_from(order).unwrap_or(u32::MAX)),
                j - i,
                &mut tokens,
            );
        } else if superscript_value(c).is_some() {
            while j < chars.len() && superscript_value(chars[j]).is_some() {
                j += 1;
            }
            let raw: String = chars[i..j].iter().collect();
            let ascii: String = raw.chars().filter_map(superscript_value).collect();
            let value = ExponentFault::parse(&ascii);
            push(Tok::Superscript(value, raw), j - i, &mut tokens);
        } else if c.is_ascii_digit()
            || (c == '.' && chars.get(i + 1).is_some_and(|d| d.is_ascii_digit()))
        {
            let (end, number) = number(&chars, i, start);
            j = end;
            match number {
                Ok(v) => push(Tok::Number(v), j - i, &mut tokens),
                Err(e) => errors.push(e),
            }
        } else if c == '_'
            && chars.get(i + 1) == Some(&'T')
            && !chars.get(i + 2).is_some_and(|&d| is_ident_continue(d))
            && matches!(
                tokens.last(),
                Some(Token {
                    tok: Tok::RParen,
                    ..
                })
            )
        {
            j = i + 2;
            push(Tok::SubscriptT, 2, &mut tokens);
        } else if is_ident_start(c) {
            while j < chars.len() && is_ident_continue(chars[j]) {
                j += 1;
            }
            let name: String = chars[i..j].iter().collect();
            push(word(name), j - i, &mut tokens);
        } else if let Some((end, error, tok)) = misread_partial(&chars, i, start) {
            j = end;
            errors.push(error);
            push(tok, j - i, &mut tokens);
        } else {
            let (end, tok) = symbol(&chars, i);
            j = end;
            match tok {
                Some(tok) => push(tok, j - i, &mut tokens),
                None => errors.push(
                    Diagnostic::text(start, format!("unexpected character `{c}` (U+{:04X})", c as u32))
                        .help(if c == '∂' {
                            "a partial derivative is written ∂_x or ∂_y (ASCII d_x, d_y)"
                        } else {
                            "the forms use ∫ (or int), Σ_T (or sum_T), + − · : /, primes ' for derivatives (1D), ∇ Δ ∂_x ∂_y ε div tr (grad, lap, d_x, d_y, eps) on triangles, ⁻² or ^-2 for powers, and (X, Y)_T for L² products"
                        }),
                ),
            }
        }
        column += j - i;
        i = j;
    }
    (tokens, errors)
}

/// The number at `chars[i..]` (digits, a point, an exponent `1e-3`, `2.5E+4`): the end
/// of its text and its value, or an error at `start` for a number that over- or
/// underflows a 64-bit float or does not parse.
fn number(chars: &[char], i: usize, start: Loc) -> (usize, Result<f64, Diagnostic>) {
    let mut j = i + 1;
    while j < chars.len() && (chars[j].is_ascii_digit() || chars[j] == '.') {
        j += 1;
    }
    // exponent part: 1e-3, 2.5E+4
    if j < chars.len() && (chars[j] == 'e' || chars[j] == 'E') {
        let mut k = j + 1;
        if k < chars.len() && (chars[k] == '-' || chars[k] == '+') {
            k += 1;
        }
        if k < chars.len() && chars[k].is_ascii_digit() {
            while k < chars.len() && chars[k].is_ascii_digit() {
                k += 1;
            }
            j = k;
        }
    }
    let raw: String = chars[i..j].iter().collect();
    let at = Loc {
        len: j - i,
        ..start
    };
    // a literal with a non-zero digit that reads as 0 or a subnormal underflowed
    // (a `1e-400` vanished from its form without a word)
    let nonzero = raw
        .chars()
        .take_while(|c| !matches!(c, 'e' | 'E'))
        .any(|c| c.is_ascii_digit() && c != '0');
    let value = match raw.parse::<f64>() {
        Ok(v) if nonzero && (v == 0.0 || v.is_subnormal()) => Err(Diagnostic::text(
            at,
            format!("number `{raw}` is too small: it underflows a 64-bit float"),
        )
        .help("non-zero constants must be at least about 2.2e-308 in size; rescale the units")),
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(Diagnostic::text(
            at,
            format!("number `{raw}` is too large: it overflows a 64-bit float"),
        )
        .help("constants must be finite, below about 1.8e308")),
        Err(_) => Err(Diagnostic::text(at, format!("malformed number `{raw}`"))
            .help("write numbers like 2, 0.5 or 1e-3")),
    };
    (j, value)
}

/// The token of a word: a keyword's (`int`, `grad`, `d_x`, `eps`, …, `int_Γ` a boundary
/// integral), else a name.
fn word(name: String) -> Tok {
    match name.as_str() {
        "int" => Tok::Integral,
        "ds" => Tok::Ds,
        // the domain's integral as many write it (a `∫_Ω T ∇u·∇v` was
        // read as a boundary integral and cascaded)
        "int_Omega" | "int_Ω" => Tok::Integral,
        _ if name.len() > 4 && name.starts_with("int_") => {
            Tok::FacetIntegral(name["int_".len()..].to_string())
        }
        "Σ_T" | "sum_T" => Tok::SumT,
        "grad" => Tok::Grad,
        "lap" => Tok::Laplacian,
        "dot" => Tok::Star,
        "d_x" => Tok::Partial(0),
        "d_y" => Tok::Partial(1),
        "ε" | "eps" => Tok::SymGrad,
        "div" => Tok::Divergence,
        "tr" => Tok::Trace,
        _ => Tok::Ident(name),
    }
}

/// A partial derivative written as the forms do not read it, at `chars[i..]`: `∂_xy`
/// (ambiguous: a mixed derivative to some readers) or `∂_X`, `∂_t` (not a coordinate).
/// The end of its text, one error for the whole operator, and a partial to put in its
/// place so that the parse goes on without a cascade about a symbol `_xy`.
fn misread_partial(chars: &[char], i: usize, start: Loc) -> Option<(usize, Diagnostic, Tok)> {
    if chars.get(i) != Some(&'∂') || chars.get(i + 1) != Some(&'_') {
        return None;
    }
    let written = |j: usize| -> String { chars[i..j].iter().collect() };
    if matches!(chars.get(i + 2), Some('x' | 'y')) && matches!(chars.get(i + 3), Some('x' | 'y')) {
        let mut j = i + 4;
        while matches!(chars.get(j), Some('x' | 'y' | 'z')) {
            j += 1;
        }
        let (a, b) = (chars[i + 2], chars[i + 3]);
        let help = if a == b {
            format!("write ∂_{a}² for the second derivative (ASCII d_{a}^2)")
        } else {
            format!("write ∂_{a} ∂_{b} for the mixed derivative (ASCII d_{a} d_{b})")
        };
        let error = Diagnostic::text(
            Loc { len: j - i, ..start },
            format!(
                "`{}` is ambiguous: a mixed derivative to some readers, ∂_{a} of a name `{b}…` to others",
                written(j)
            ),
        )
        .help(help);
        return Some((j, error, Tok::Partial(u8::from(a == 'y'))));
    }
    if chars.get(i + 2).is_some_and(|&d| is_ident_start(d))
        && !matches!(chars.get(i + 2), Some('x' | 'y'))
    {
        let mut j = i + 2;
        while j < chars.len() && is_ident_continue(chars[j]) {
            j += 1;
        }
        let error = Diagnostic::text(
            Loc {
                len: j - i,
                ..start
            },
            format!(
                "`{}` is not a partial derivative of the forms: the coordinates are x and y",
                written(j)
            ),
        )
        .help("write ∂_x or ∂_y (ASCII d_x, d_y), then the field: ∂_x u");
        return Some((j, error, Tok::Partial(0)));
    }
    None
}

/// The symbol at `chars[i..]` (an operator, a bracket, `∫_Γ`, `∂_x`, `∑_T`): the end of
/// its text and its token, `None` for a character the forms do not use.
fn symbol(chars: &[char], i: usize) -> (usize, Option<Tok>) {
    let c = chars[i];
    let mut j = i + 1;
    let tok = match c {
        // `∫_Γ_C`: the boundary part's name follows the underscore.
        '∫' if chars.get(i + 1) == Some(&'_')
            && chars.get(i + 2).is_some_and(|&d| is_ident_start(d)) =>
        {
            j = i + 2;
            while j < chars.len() && is_ident_continue(chars[j]) {
                j += 1;
            }
            let part: String = chars[i + 2..j].iter().collect();
            Some(if part == "Ω" {
                Tok::Integral
            } else {
                Tok::FacetIntegral(part)
            })
        }
        '∫' => Some(Tok::Integral),
        '∇' => Some(Tok::Grad),
        'Δ' => Some(Tok::Laplacian),
        // `∂_xu` is ∂_x u, as `Δu` is Δ u: no name starts with ∂ (a
        // `∂_xu ∂_xv` was told that a partial derivative is written ∂_x); `∂_xy`
        // stays an error, a mixed derivative to some readers
        '∂' if chars.get(i + 1) == Some(&'_')
            && matches!(chars.get(i + 2), Some('x' | 'y'))
            && !matches!(chars.get(i + 3), Some('x' | 'y')) =>
        {
            j = i + 3;
            Some(Tok::Partial(u8::from(chars[i + 2] == 'y')))
        }
        ':' => Some(Tok::Colon),
        '∑' if chars.get(i + 1) == Some(&'_') && chars.get(i + 2) == Some(&'T') => {
            j = i + 3;
            Some(Tok::SumT)
        }
        '^' => Some(Tok::Caret),
        '+' => Some(Tok::Plus),
        '-' | '−' | '–' => Some(Tok::Minus),
        '*' | '·' | '⋅' | '×' => Some(Tok::Star),
        '/' => Some(Tok::Slash),
        '(' => Some(Tok::LParen),
        ')' => Some(Tok::RParen),
        '[' => Some(Tok::LBracket),
        ']' => Some(Tok::RBracket),
        '{' => Some(Tok::LBrace),
        '}' => Some(Tok::RBrace),
        ',' => Some(Tok::Comma),
        ';' => Some(Tok::Semicolon),
        '=' => Some(Tok::Equals),
        '‖' => Some(Tok::Norm),
        '|' if chars.get(i + 1) == Some(&'|') => {
            j = i + 2;
            Some(Tok::Norm)
        }
        _ => None,
    };
    (j, tok)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kinds(text: &str) -> Vec<Tok> {
        let (tokens, errors) = tokenize(text);
        assert!(errors.is_empty(), "{errors:?}");
        tokens.into_iter().map(|t| t.tok).collect()
    }

    #[test]
    fn unicode_and_ascii_spellings_agree() {
        let unicode = kinds("a(θ,w;η,v) = ∫θ′η′ + t⁻²(w′−θ)(v'−η)");
        let ascii = kinds("a(θ,w;η,v) = int θ'η' + t^-2 (w'-θ)(v'-η)");
        let strip = |v: Vec<Tok>| -> Vec<Tok> {
            v.into_iter()
                .map(|t| match t {
                    Tok::Superscript(Ok(n), _) => Tok::Superscript(Ok(n), String::new()),
                    t => t,
                })
                .collect()
        };
        let unicode = strip(unicode);
        // The ASCII power is Caret, Minus, Number: compare everything else.
        assert_eq!(unicode[0], Tok::Ident("a".into()));
        assert!(unicode.contains(&Tok::Superscript(Ok(-2), String::new())));
        assert_eq!(
            unicode.iter().filter(|t| **t == Tok::Prime(1)).count(),
            ascii.iter().filter(|t| **t == Tok::Prime(1)).count()
        );
        assert_eq!(ascii[11], Tok::Integral);
    }

    #[test]
    fn vector_calculus_spellings_agree() {
        assert_eq!(kinds("∇u·∇v + Δw"), kinds("grad u dot grad v + lap w"));
        assert_eq!(kinds("Δw")[0], Tok::Laplacian);
        assert_eq!(kinds("∇")[0], Tok::Grad);
    }

    #[test]
    fn tensor_spellings_agree() {
        assert_eq!(
            kinds("∂_x θ_x + ∂_y w − ε(θ):ε(η) + div θ tr I"),
            kinds("d_x θ_x + d_y w - eps(θ):eps(η) + div θ tr I")
        );
        assert_eq!(kinds("∂_y")[0], Tok::Partial(1));
        // a name that merely starts like an operator stays a name
        assert_eq!(
            kinds("εr divs d_xx"),
            vec![
                Tok::Ident("εr".into()),
                Tok::Ident("divs".into()),
                Tok::Ident("d_xx".into())
            ]
        );
        let (tokens, errors) = tokenize("∂_xy w");
        assert_eq!(errors.len(), 1);
        assert!(errors[0].help.as_deref().unwrap_or("").contains("∂_x ∂_y"));
        assert_eq!(tokens[0].tok, Tok::Partial(0));
        let (_, errors) = tokenize("∂_z w");
        assert!(errors[0]
            .help
            .as_deref()
            .unwrap_or("")
            .contains("∂_x or ∂_y"));
    }

    #[test]
    fn primes_merge_into_an_order() {
        assert_eq!(
            kinds("w'''' θ‴ u″"),
            vec![
                Tok::Ident("w".into()),
                Tok::Prime(4),
                Tok::Ident("θ".into()),
                Tok::Prime(3),
                Tok::Ident("u".into()),
                Tok::Prime(2)
            ]
        );
    }

    #[test]
    fn places_are_lines_and_character_columns() {
        let (tokens, _) = tokenize("∫ a\n  θ⁴ 1e-3");
        let theta = tokens
            .iter()
            .find(|t| t.tok == Tok::Ident("θ".into()))
            .unwrap();
        assert_eq!((theta.loc.line, theta.loc.column), (2, 3));
        let number = tokens
            .iter()
            .find(|t| matches!(t.tok, Tok::Number(_)))
            .unwrap();
        assert_eq!(number.tok, Tok::Number(1e-3));
        assert_eq!((number.loc.column, number.loc.len), (6, 4));
    }

    #[test]
    fn subscript_t_and_sums() {
        assert_eq!(
            kinds("Σ_T (a, b)_T sum_T h_T"),
            vec![
                Tok::SumT,
                Tok::LParen,
                Tok::Ident("a".into()),
                Tok::Comma,
                Tok::Ident("b".into()),
                Tok::RParen,
                Tok::SubscriptT,
                Tok::SumT,
                Tok::Ident("h_T".into())
            ]
        );
    }

    #[test]
    fn bad_characters_are_reported_with_their_place() {
        let (_, errors) = tokenize("a(u;v) = ∫ u ≥ v");
        assert_eq!(errors.len(), 1);
        let crate::diagnostic::Place::Text(loc) = errors[0].place else {
            panic!()
        };
        assert_eq!(loc.column, 14);
        let (_, errors) = tokenize("t⁻");
        assert!(errors.is_empty()); // a malformed exponent is the parser's to report
    }
}
