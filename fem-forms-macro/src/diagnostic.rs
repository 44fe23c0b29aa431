//! Compile errors with a place: either a Rust token of the model declaration, or a
//! line and column inside the `forms` string literal.
//!
//! A string literal's inner positions cannot be underlined on stable Rust
//! (`Literal::subspan` is nightly-only), so an error inside the forms text is reported
//! at the whole literal and carries the line, the column and a caret in its message.

use proc_macro2::{Span, TokenStream};
use quote::quote_spanned;

/// A position inside the forms text: 1-based line and column (in characters), and the
/// number of characters to underline.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Loc {
    /// 1-based line.
    pub line: usize,
    /// 1-based column, in characters.
    pub column: usize,
    /// Characters to underline (at least one is shown).
    pub len: usize,
}

impl Loc {
    /// The smallest location covering `self` and `other` when both are on one line.
    pub fn to(self, other: Loc) -> Loc {
        if self.line == other.line && other.column >= self.column {
            Loc {
                line: self.line,
                column: self.column,
                len: (other.column + other.len).saturating_sub(self.column),
            }
        } else {
            self
        }
    }
}

/// Where an error is.
#[derive(Clone, Debug)]
pub enum Place {
    /// A token of the Rust declaration.
    Token(Span),
    /// A place in the forms text.
    Text(Loc),
}

/// One compile error.
#[derive(Clone, Debug)]
pub struct Diagnostic {
    /// What is wrong.
    pub message: String,
    /// Where.
    pub place: Place,
    /// How to fix it, when there is something useful to say.
    pub help: Option<String>,
}

impl Diagnostic {
    /// An error at a place in the forms text.
    pub fn text(loc: Loc, message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
            place: Place::Text(loc),
            help: None,
        }
    }

    /// An error at a Rust token of the declaration.
    pub fn token(span: Span, message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
            place: Place::Token(span),
            help: None,
        }
    }

    /// Adds a hint on how to fix it.
    pub fn help(mut self, help: impl Into<String>) -> Self {
        self.help = Some(help.into());
        self
    }

    /// The full message: the error, then for text places the line with a caret, then the hint.
    #[cfg(test)]
    pub fn render(&self, forms_text: &str) -> String {
        self.render_in(forms_text, "forms")
    }

    /// [`Diagnostic::render`] of a place in the text named `text_name` (`estimator`).
    pub fn render_in(&self, forms_text: &str, text_name: &str) -> String {
        let mut out = self.message.clone();
        if let Place::Text(loc) = self.place {
            let line_text = forms_text
                .lines()
                .nth(loc.line.saturating_sub(1))
                .unwrap_or("");
            let gutter = format!("{}", loc.line).len();
            out.push_str(&format!(
                "\n{:gutter$}--> {text_name}, line {}, column {}\n{:gutter$} |\n{} | {}\n{:gutter$} | {}{}",
                "",
                loc.line,
                loc.column,
                "",
                loc.line,
                line_text,
                "",
                " ".repeat(loc.column.saturating_sub(1)),
                "^".repeat(loc.len.max(1)),
            ));
        }
        if let Some(help) = &self.help {
            out.push_str("\n= help: ");
            out.push_str(help);
        }
        out
    }

    /// `compile_error!` at the right span.
    pub fn to_compile_error(&self, forms_text: &str, forms_span: Span) -> TokenStream {
        self.to_compile_error_in(forms_text, forms_span, "forms")
    }

    /// [`Diagnostic::to_compile_error`] for a place in the text named `text_name`.
    pub fn to_compile_error_in(&self, text: &str, span: Span, text_name: &str) -> TokenStream {
        let span = match self.place {
            Place::Token(span) => span,
            Place::Text(_) => span,
        };
        let message = self.render_in(text, text_name);
        quote_spanned! {span=> ::core::compile_error!{ #message } }
    }
}

/// Levenshtein distance, for "did you mean" hints.
pub fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut previous = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let substitution = previous + usize::from(ca != cb);
            previous = row[j + 1];
            row[j + 1] = substitution.min(row[j] + 1).min(row[j + 1] + 1);
        }
    }
    row[b.len()]
}

/// The candidate closest to `name`, if it is close enough to be a likely typo.
///
/// No hint when several candidates are equally close: a guess would mislead.
pub fn closest<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let close: Vec<(usize, &str)> = candidates
        .into_iter()
        .map(|c| (edit_distance(name, c), c))
        .filter(|&(d, c)| d <= 2 && d < c.chars().count().max(name.chars().count()))
        .collect();
    let best = close.iter().map(|&(d, _)| d).min()?;
    let mut at_best = close.iter().filter(|&&(d, _)| d == best);
    let first = at_best.next()?;
    at_best.next().is_none().then_some(first.1)
}

/// Letters that look like a Latin letter: Cyrillic and Greek lookalikes, mapped to it.
const LOOKALIKES: &[(char, char)] = &[
    // the micro sign that keyboards type for μ, and the Greek variant letters
    ('µ', 'μ'),
    ('ϑ', 'θ'),
    ('ϵ', 'ε'),
    ('ϕ', 'φ'),
    ('ϰ', 'κ'),
    ('ϱ', 'ρ'),
    ('ϖ', 'π'),
    ('а', 'a'),
    ('е', 'e'),
    ('о', 'o'),
    ('р', 'p'),
    ('с', 'c'),
    ('у', 'y'),
    ('х', 'x'),
    ('і', 'i'),
    ('ј', 'j'),
    ('ѕ', 's'),
    ('ԁ', 'd'),
    ('ԛ', 'q'),
    ('ԝ', 'w'),
    ('А', 'A'),
    ('В', 'B'),
    ('Е', 'E'),
    ('К', 'K'),
    ('М', 'M'),
    ('Н', 'H'),
    ('О', 'O'),
    ('Р', 'P'),
    ('С', 'C'),
    ('Т', 'T'),
    ('Х', 'X'),
    ('У', 'Y'),
    ('І', 'I'),
    ('Ј', 'J'),
    ('Ѕ', 'S'),
    ('α', 'a'),
    ('ο', 'o'),
    ('ν', 'v'),
    ('ι', 'i'),
    ('κ', 'k'),
    ('ρ', 'p'),
    ('υ', 'u'),
    ('χ', 'x'),
    ('Α', 'A'),
    ('Β', 'B'),
    ('Ε', 'E'),
    ('Ζ', 'Z'),
    ('Η', 'H'),
    ('Ι', 'I'),
    ('Κ', 'K'),
    ('Μ', 'M'),
    ('Ν', 'N'),
    ('Ο', 'O'),
    ('Ρ', 'P'),
    ('Τ', 'T'),
    ('Υ', 'Y'),
    ('Χ', 'X'),
];

fn skeleton(c: char) -> char {
    LOOKALIKES
        .iter()
        .find(|(l, _)| *l == c)
        .map_or(c, |&(_, latin)| latin)
}

fn script(c: char) -> &'static str {
    match c as u32 {
        0x00B5 => "the micro sign",
        0x03D0..=0x03FF => "a Greek variant form",
        0x0370..=0x03CF => "Greek",
        0x0400..=0x052F => "Cyrillic",
        _ if c.is_ascii() => "Latin",
        _ => "another script",
    }
}

/// A hint when `name` differs from one candidate only by lookalike letters (Cyrillic
/// `Т` for Latin `T`, Greek `ν` for `v`): such a typo is invisible in the source.
pub fn lookalike<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<String> {
    let key: Vec<char> = name.chars().map(skeleton).collect();
    let candidate = candidates.into_iter().find(|c| {
        *c != name
            && c.chars().count() == key.len()
            && c.chars().map(skeleton).eq(key.iter().copied())
    })?;
    let differences: Vec<String> = name
        .chars()
        .zip(candidate.chars())
        .filter(|(a, b)| a != b)
        .map(|(a, b)| {
            format!(
                "`{a}` (U+{:04X}, {}) is not `{b}` (U+{:04X}, {})",
                a as u32,
                script(a),
                b as u32,
                script(b)
            )
        })
        .collect();
    Some(format!(
        "`{name}` looks like `{candidate}` but is not the same name: {}",
        differences.join(", ")
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn caret_under_the_place() {
        let text = "a(u;v) = ∫ u'v'\nb(u;v) = ∫ q u v";
        let d = Diagnostic::text(
            Loc {
                line: 2,
                column: 12,
                len: 1,
            },
            "unknown symbol `q`",
        )
        .help("declare it");
        let r = d.render(text);
        assert!(r.contains("line 2, column 12"), "{r}");
        assert!(r.contains("2 | b(u;v) = ∫ q u v"), "{r}");
        assert!(r.contains("  |            ^\n"), "{r}");
        assert!(r.ends_with("= help: declare it"));
    }

    #[test]
    fn typo_suggestions() {
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(closest("psi", ["ψ", "psy", "t"]), Some("psy"));
        assert_eq!(closest("x", ["t", "α"]), None);
        assert_eq!(closest("P7", ["P0", "P1", "P2"]), None);
    }

    #[test]
    fn lookalike_letters_are_named() {
        let hint = lookalike("Т", ["T", "v"]).unwrap();
        assert!(
            hint.contains("U+0422, Cyrillic") && hint.contains("U+0054, Latin"),
            "{hint}"
        );
        assert!(lookalike("ν", ["u", "v"]).unwrap().contains("Greek"));
        assert!(lookalike("wа", ["w", "wa"]).unwrap().contains("`wa`"));
        assert_eq!(lookalike("x", ["T", "v"]), None);
        // as people type them: the micro sign typed for μ, ϑ for θ
        assert!(lookalike("µ", ["u", "μ"])
            .unwrap()
            .contains("the micro sign"));
        assert!(lookalike("ϑ", ["θ"]).unwrap().contains("Greek variant"));
        assert_eq!(lookalike("v", ["v"]), None);
    }
}
