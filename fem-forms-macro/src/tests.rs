//! End-to-end tests of the macro on `proc_macro2` input, and property tests of the
//! symbolic layer.

use super::*;
use quote::quote;

fn timoshenko(forms: &str) -> TokenStream {
    quote! {
        /// Timoshenko beam.
        pub mod timoshenko on interval {
            unknowns: θ: P2, w: P2, λ: P0 >= 0;
            tests: η, v, μ;
            params: t, α, s;
            data: f, ψ;
            forms: #forms;
        }
    }
}

const TIMOSHENKO: &str = "
    a(θ,w;η,v) = ∫θ'η' + t⁻²(w'−θ)(v'−η)
    b(η,v;μ)   = ∫ s v μ
    S(θ,λ;η,μ) = Σ_T h_T⁴ (θ''' − sλ, η''' − sμ)_T
    ℓ(η,v)     = ∫ f v
    B_h(θ,w,λ;η,v,μ) = a(θ,w;η,v) − b(η,v;λ) − b(θ,w;μ) − α S(θ,λ;η,μ)
";

fn rendered_errors(out: &TokenStream) -> Vec<String> {
    // compile_error!{ "…" } invocations, one per error
    let text = out.to_string();
    text.split("compile_error")
        .skip(1)
        .map(|s| s.to_string())
        .collect()
}

#[test]
fn the_users_model_expands_to_valid_rust() {
    let out = expand(timoshenko(TIMOSHENKO));
    let file: syn::File = syn::parse2(out.clone()).expect("generated code parses");
    let text = out.to_string();
    assert!(!text.contains("compile_error"), "{text}");
    assert_eq!(file.items.len(), 1);
    for kernel in [
        "fn matrix_η_θ",
        "fn matrix_v_w",
        "fn matrix_v_θ",
        "fn matrix_η_w",
        "fn matrix_μ_w",
        "fn matrix_μ_λ",
        "fn vector_v",
    ] {
        assert!(text.contains(kernel), "missing {kernel}");
    }
    // θ''' of P2 vanishes: S has only the (μ, λ) block, no (η, ·) or (·, θ) blocks.
    let s_module = text
        .split("pub mod S")
        .nth(1)
        .unwrap()
        .split("pub mod")
        .next()
        .unwrap();
    assert!(s_module.contains("fn matrix_μ_λ"));
    assert!(!s_module.contains("fn matrix_η_θ") && !s_module.contains("fn matrix_μ_θ"));
}

#[test]
fn unicode_and_ascii_spellings_give_the_same_blocks() {
    let ascii = "
        a(θ,w;η,v) = int θ'η' + t^-2 (w'-θ)*(v'-η)
        b(η,v;μ) = int s*v*μ
        S(θ,λ;η,μ) = sum_T h^4 (θ''' - s λ, η''' - s μ)_T
        ℓ(η,v) = int f v
        B_h(θ,w,λ;η,v,μ) = a(θ,w;η,v) - b(η,v;λ) - b(θ,w;μ) - α S(θ,λ;η,μ)
    ";
    let analyse_text = |text: &str| {
        let symbols = Symbols {
            fields: vec![
                Field {
                    name: "θ".into(),
                    test_name: "η".into(),
                    element: ElementKind::P2,
                    nonnegative: false,
                    component: None,
                },
                Field {
                    name: "w".into(),
                    test_name: "v".into(),
                    element: ElementKind::P2,
                    nonnegative: false,
                    component: None,
                },
                Field {
                    name: "λ".into(),
                    test_name: "μ".into(),
                    element: ElementKind::P0,
                    nonnegative: true,
                    component: None,
                },
            ],
            params: vec!["t".into(), "α".into(), "s".into()],
            data: vec![("f".into(), 2), ("ψ".into(), 2)],
            dimension: 1,
            ..Default::default()
        };
        let (tokens, e1) = lexer::tokenize(text);
        let (defs, e2) = parser::parse_forms(&tokens);
        let (forms, e3) = analysis::analyse(&symbols, &defs, text);
        assert!(e1.is_empty() && e2.is_empty() && e3.is_empty());
        forms.into_iter().map(|f| f.blocks).collect::<Vec<_>>()
    };
    assert_eq!(analyse_text(TIMOSHENKO), analyse_text(ascii));
}

#[test]
fn several_errors_are_reported_together_with_places() {
    let out = expand(timoshenko(
        "a(θ,w;η,v) = ∫ θ'η' + q(w'−θ)(v'−η)\n\
         b(η,v;μ) = ∫ s v μ μ\n\
         c(λ;η) = ∫ λ' η",
    ));
    let errors = rendered_errors(&out);
    assert_eq!(errors.len(), 3, "{out}");
    assert!(errors[0].contains("unknown symbol `q`") && errors[0].contains("line 1, column 23"));
    assert!(errors[1].contains("nonlinear term"));
    assert!(errors[2].contains("P0 field"));
}

#[test]
fn declaration_errors_point_at_tokens() {
    let out = expand(quote! {
        pub mod m on interval {
            unknowns: w: P7, λ: P0 >= 0;
            tests: v;
            forms: "a(w;v) = ∫ w'v'";
        }
    });
    let errors = rendered_errors(&out);
    assert_eq!(errors.len(), 2, "{out}");
    assert!(errors[0].contains("unknown element `P7`"));
    assert!(errors[1].contains("1 test functions for 2 unknowns"));
}

mod symbolic_properties {
    use super::*;
    use crate::symbolic::{evaluate, ArgFactor};
    use proptest::prelude::*;

    /// A random expression, to be written in one of the spellings and evaluated directly.
    #[derive(Clone, Debug)]
    enum Gen {
        Number(i32),
        Param(usize),
        H,
        Data,
        /// argument symbol (0 = u, 1 = v) with derivative order
        Arg(usize, u8),
        /// (a·u + b·v)' with integer coefficients
        DerivativeOfCombination(i32, i32, u8),
        Add(Box<Gen>, Box<Gen>),
        Sub(Box<Gen>, Box<Gen>),
        Mul(Box<Gen>, Box<Gen>),
        Neg(Box<Gen>),
        Pow(Box<Gen>, u8),
        ParamInversePower(usize, u8),
    }

    struct Values {
        params: [f64; 2],
        h: f64,
        f: f64,
        /// [symbol][derivative]
        args: [[f64; 3]; 2],
    }

    fn primes(n: u8, ascii: bool) -> String {
        if ascii {
            "'".repeat(n as usize)
        } else {
            ["", "′", "″", "‴"][n as usize].to_string()
        }
    }

    fn write(g: &Gen, ascii: bool) -> String {
        let params = ["t", "α"];
        let args = ["u", "v"];
        match g {
            Gen::Number(n) if *n < 0 => format!("({})", n),
            Gen::Number(n) => format!("{n}"),
            Gen::Param(i) => params[*i].to_string(),
            Gen::H => {
                if ascii {
                    "h".into()
                } else {
                    "h_T".into()
                }
            }
            Gen::Data => "f".into(),
            Gen::Arg(s, d) => format!("{}{}", args[*s], primes(*d, ascii)),
            Gen::DerivativeOfCombination(a, b, d) => {
                format!("({a} u + ({b}) v){}", primes(*d, ascii))
            }
            Gen::Add(a, b) => format!("({} + {})", write(a, ascii), write(b, ascii)),
            Gen::Sub(a, b) => {
                let minus = if ascii { "-" } else { "−" };
                format!("({} {minus} {})", write(a, ascii), write(b, ascii))
            }
            Gen::Mul(a, b) => {
                let times = if ascii { "*" } else { "·" };
                format!("{}{times}{}", write(a, ascii), write(b, ascii))
            }
            Gen::Neg(a) => format!("(-{})", write(a, ascii)),
            Gen::Pow(a, n) => {
                if ascii {
                    format!("({})^{n}", write(a, ascii))
                } else {
                    format!("({}){}", write(a, ascii), ["⁰", "¹", "²", "³"][*n as usize])
                }
            }
            Gen::ParamInversePower(i, n) => {
                if ascii {
                    format!("{}^(-{n})", params[*i])
                } else {
                    format!("{}⁻{}", params[*i], ["⁰", "¹", "²", "³"][*n as usize])
                }
            }
        }
    }

    fn value(g: &Gen, v: &Values) -> f64 {
        match g {
            Gen::Number(n) => *n as f64,
            Gen::Param(i) => v.params[*i],
            Gen::H => v.h,
            Gen::Data => v.f,
            Gen::Arg(s, d) => v.args[*s][*d as usize],
            Gen::DerivativeOfCombination(a, b, d) => {
                *a as f64 * v.args[0][*d as usize] + *b as f64 * v.args[1][*d as usize]
            }
            Gen::Add(a, b) => value(a, v) + value(b, v),
            Gen::Sub(a, b) => value(a, v) - value(b, v),
            Gen::Mul(a, b) => value(a, v) * value(b, v),
            Gen::Neg(a) => -value(a, v),
            Gen::Pow(a, n) => value(a, v).powi(*n as i32),
            Gen::ParamInversePower(i, n) => v.params[*i].powi(-(*n as i32)),
        }
    }

    fn generator() -> impl Strategy<Value = Gen> {
        let leaf = prop_oneof![
            (-3i32..=5).prop_map(Gen::Number),
            (0usize..2).prop_map(Gen::Param),
            Just(Gen::H),
            Just(Gen::Data),
            (0usize..2, 0u8..3).prop_map(|(s, d)| Gen::Arg(s, d)),
            (-3i32..4, -3i32..4, 1u8..3)
                .prop_map(|(a, b, d)| Gen::DerivativeOfCombination(a, b, d)),
            (0usize..2, 1u8..4).prop_map(|(i, n)| Gen::ParamInversePower(i, n)),
        ];
        leaf.prop_recursive(4, 24, 2, |inner| {
            prop_oneof![
                (inner.clone(), inner.clone())
                    .prop_map(|(a, b)| Gen::Add(Box::new(a), Box::new(b))),
                (inner.clone(), inner.clone())
                    .prop_map(|(a, b)| Gen::Sub(Box::new(a), Box::new(b))),
                (inner.clone(), inner.clone())
                    .prop_map(|(a, b)| Gen::Mul(Box::new(a), Box::new(b))),
                inner.clone().prop_map(|a| Gen::Neg(Box::new(a))),
                (inner, 0u8..4).prop_map(|(a, n)| Gen::Pow(Box::new(a), n)),
            ]
        })
    }

    fn symbols() -> Symbols {
        Symbols {
            fields: vec![Field {
                name: "u".into(),
                test_name: "v".into(),
                element: ElementKind::P3,
                nonnegative: false,
                component: None,
            }],
            params: vec!["t".into(), "α".into()],
            data: vec![("f".into(), 2)],
            dimension: 1,
            ..Default::default()
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(400))]

        /// Parsing, expanding into monomials and evaluating the monomials agrees with
        /// evaluating the expression directly, in both spellings.
        #[test]
        fn expansion_agrees_with_direct_evaluation(
            g in generator(),
            params in prop::array::uniform2(0.3f64..2.0),
            h in 0.1f64..2.0,
            f in -2.0f64..2.0,
            args in prop::array::uniform2(prop::array::uniform3(-2.0f64..2.0)),
            ascii in any::<bool>(),
        ) {
            let text = write(&g, ascii);
            let values = Values { params, h, f, args };
            let expansion = analysis::expand_expression(&symbols(), &text)
                .map_err(|e| TestCaseError::fail(format!("{text}: {e:?}")))?;
            let direct = value(&g, &values);
            // symbol 0 is u (the unknown), symbol 1 is v (its test function)
            let arg = |a: ArgFactor| values.args[a.symbol][a.derivative[0] as usize];
            let expanded = evaluate(&expansion, &|i| values.params[i], values.h, &|_| values.f, &arg);
            let scale: f64 = expansion
                .iter()
                .map(|m| m.evaluate(&|i| values.params[i], values.h, &|_| values.f, &arg).abs())
                .sum::<f64>()
                .max(direct.abs())
                .max(1.0);
            prop_assert!((expanded - direct).abs() <= 1e-10 * scale,
                "{text}: expanded {expanded} direct {direct}");
        }
    }
}

fn membrane(element: &str, forms: &str) -> TokenStream {
    let element = syn::Ident::new(element, proc_macro2::Span::call_site());
    quote! {
        /// Membrane.
        pub mod membrane on triangle {
            unknowns: u: #element, λ: P0 >= 0;
            tests: v, μ;
            params: α;
            data: f, ψ, g;
            boundary: u = g;
            forms: #forms;
        }
    }
}

const MEMBRANE: &str = "
    a(u;v)       = ∫ ∇u·∇v
    b(v;μ)       = ∫ v μ
    S(u,λ;v,μ)   = Σ_T h_T² (−Δu − λ, −Δv − μ)_T
    ℓ(v)         = ∫ f v
    B_h(u,λ;v,μ) = a(u;v) − b(v;λ) − b(u;μ) − α S(u,λ;v,μ)
";

#[test]
fn the_membrane_expands_to_valid_rust_on_triangles() {
    let out = expand(membrane("P2", MEMBRANE));
    let text = out.to_string();
    assert!(!text.contains("compile_error"), "{text}");
    let _: syn::File = syn::parse2(out).expect("generated code parses");
    assert!(text.contains("CellKind :: Triangle"));
    assert!(text.contains("DIRICHLET"));
    // P2: Δu is a non-zero constant, so S couples (v, u)
    let s_module = text.split("pub mod S").nth(1).unwrap();
    assert!(s_module
        .split("pub mod")
        .next()
        .unwrap()
        .contains("fn matrix_v_u"));
    // P1: Δ vanishes on each triangle and only the (μ, λ) block of S is left
    let out = expand(membrane("P1", MEMBRANE)).to_string();
    let s_module = out
        .split("pub mod S")
        .nth(1)
        .unwrap()
        .split("pub mod")
        .next()
        .unwrap();
    assert!(s_module.contains("fn matrix_μ_λ") && !s_module.contains("fn matrix_v_u"));
}

#[test]
fn vector_calculus_ascii_and_unicode_agree_and_expand_componentwise() {
    let ascii = "
        a(u;v)       = int grad u dot grad v
        b(v;μ)       = int v*μ
        S(u,λ;v,μ)   = sum_T h^2 (-lap u - λ, -lap v - μ)_T
        ℓ(v)         = int f v
        B_h(u,λ;v,μ) = a(u;v) - b(v;λ) - b(u;μ) - α S(u,λ;v,μ)
    ";
    let symbols = Symbols {
        fields: vec![
            Field {
                name: "u".into(),
                test_name: "v".into(),
                element: ElementKind::P2,
                nonnegative: false,
                component: None,
            },
            Field {
                name: "λ".into(),
                test_name: "μ".into(),
                element: ElementKind::P0,
                nonnegative: true,
                component: None,
            },
        ],
        params: vec!["α".into()],
        data: vec![("f".into(), 2)],
        dimension: 2,
        ..Default::default()
    };
    let blocks = |text: &str| {
        let (tokens, errors) = lexer::tokenize(text);
        assert!(errors.is_empty());
        let (definitions, errors) = parser::parse_forms(&tokens);
        assert!(errors.is_empty());
        let (forms, errors) = analysis::analyse(&symbols, &definitions, text);
        assert!(errors.is_empty(), "{errors:?}");
        forms.into_iter().map(|f| f.blocks).collect::<Vec<_>>()
    };
    assert_eq!(blocks(MEMBRANE), blocks(ascii));
    let symbols = Symbols {
        fields: vec![Field {
            name: "u".into(),
            test_name: "v".into(),
            element: ElementKind::P3,
            nonnegative: false,
            component: None,
        }],
        params: vec![],
        data: vec![],
        dimension: 2,
        ..Default::default()
    };
    let terms = analysis::expand_expression(&symbols, "∇u·∇v").unwrap();
    let mut multi: Vec<Vec<[u8; 2]>> = terms
        .iter()
        .map(|t| t.args.iter().map(|a| a.derivative).collect())
        .collect();
    multi.sort();
    assert_eq!(multi, vec![vec![[0, 1], [0, 1]], vec![[1, 0], [1, 0]]]);
    let lap = analysis::expand_expression(&symbols, "Δu").unwrap();
    let mut d: Vec<[u8; 2]> = lap.iter().map(|t| t.args[0].derivative).collect();
    d.sort();
    assert_eq!(d, vec![[0, 2], [2, 0]]);
}

#[test]
fn vector_errors_point_at_the_expression() {
    let cases = [
        ("a(u;v) = ∫ ∇u + v", "sum of a vector and a scalar"),
        ("a(u;v) = ∫ ∇u v", "a vector where a scalar is needed"),
        (
            "a(u;v) = ∫ u'v'",
            "a prime ′ is the derivative along an interval",
        ),
        ("a(u;v) = ∫ ∇(∇u)·v", "a matrix where a scalar is needed"),
        ("a(u;v) = ∫ ∇∇∇u : ∇∇v", "∇ of a matrix"),
        ("a(u;v) = ∫ ε(u) : ε(v)", "ε of a scalar"),
        ("a(u;v) = ∫ div u v", "div of a scalar"),
        ("a(u;v) = ∫ tr ∇u v", "tr of a vector"),
        ("a(u;v) = ∫ ∇∇u : ∇v", "`:` of a matrix and a vector"),
        ("a(u;v) = ∫ ∇∇u · ∇∇v", "product of two matrices"),
        ("a(u;v) = ∫ ∇u − u v", "difference of a vector and a scalar"),
    ];
    for (forms, message) in cases {
        let errors = rendered_errors(&expand(membrane("P2", forms)));
        assert!(
            errors.iter().any(|e| e.contains(message)),
            "{forms}: {errors:?}"
        );
    }
}

/// Issue 11, depth: a sum of thousands of terms expands in a loop, not by recursion.
#[test]
fn a_form_of_five_thousand_terms_compiles() {
    let terms = vec!["α u v"; 5000].join(" + ");
    let forms = format!("a(u;v) = ∫ {terms}");
    let out = expand(membrane("P1", &forms));
    assert!(
        rendered_errors(&out).is_empty(),
        "{:?}",
        rendered_errors(&out)
    );
    // the 5000 equal terms are one term with coefficient 5000
    assert!(out.to_string().contains("5000"));
}

#[test]
fn deep_nesting_is_a_located_error() {
    let nested = format!("{}u{}", "(".repeat(525), ")".repeat(525));
    let errors = rendered_errors(&expand(membrane("P1", &format!("a(u;v) = ∫ {nested} v"))));
    assert!(
        errors
            .iter()
            .any(|e| e.contains("nested more than 100 levels")),
        "{errors:?}"
    );
    let product = vec!["2"; 300].join(" ");
    let errors = rendered_errors(&expand(membrane(
        "P1",
        &format!("a(u;v) = ∫ {product} u v"),
    )));
    assert!(
        errors
            .iter()
            .any(|e| e.contains("nested more than 100 levels")),
        "{errors:?}"
    );
}

/// Exponents that would make the expansion overflow its integer powers or take
/// quadratic time are located errors, whatever the spelling; modest powers compile.
#[test]
fn huge_exponents_are_located_errors() {
    for forms in [
        "a(u;v) = ∫ f^999999 u v",
        "a(u;v) = ∫ f⁻²¹⁴⁷⁴⁸³⁶⁴⁸ u v",
        "a(u;v) = ∫ f²¹⁴⁷⁴⁸³⁶⁴⁷ u v",
        "a(u;v) = ∫ ((f^10)^10)^11 u v",
    ] {
        let errors = rendered_errors(&expand(membrane("P2", forms)));
        assert!(
            errors.iter().any(|e| e.contains("beyond the limit 1000")),
            "{forms}: {errors:?}"
        );
    }
    // the data degree limit bounds a product of data too (default degree 2: 21 factors
    // sum to 42)
    let product = vec!["f"; 21].join(" ");
    let errors = rendered_errors(&expand(membrane(
        "P2",
        &format!("a(u;v) = ∫ {product} u v"),
    )));
    assert!(
        errors
            .iter()
            .any(|e| e.contains("degrees summing to 42, above the limit 40")),
        "{errors:?}"
    );
    let out = expand(membrane("P2", "a(u;v) = ∫ ((f^3)^2) u v"));
    assert!(
        rendered_errors(&out).is_empty(),
        "{:?}",
        rendered_errors(&out)
    );
}

#[test]
fn overflowing_constants_are_located_errors() {
    for (forms, message) in [
        ("a(u;v) = ∫ 1e999 ∇u·∇v", "number `1e999` is too large"),
        (
            "a(u;v) = ∫ (1e999 − 1e999) u v",
            "number `1e999` is too large",
        ),
        ("a(u;v) = ∫ 1e200·1e200 f u v", "overflows (inf)"),
        // a tester's silently vanished terms: an underflow is an error too
        ("a(u;v) = ∫ 1e-200·1e-200 f u v", "underflows"),
        ("a(u;v) = ∫ (1e-5)^100 u v", "underflows"),
        (
            "a(u;v) = ∫ 1e-400 u v + u v",
            "number `1e-400` is too small",
        ),
    ] {
        let errors = rendered_errors(&expand(membrane("P2", forms)));
        assert!(
            errors
                .iter()
                .any(|e| e.contains(message) && e.contains("line 1")),
            "{forms}: {errors:?}"
        );
    }
}

/// The dump names the runtime by its crate name, so the file compiles on its own.
#[test]
fn the_dump_has_no_macro_only_paths() {
    // A real `$crate` is one identifier only the compiler can make: test the rewrite on
    // text, and that the dump of a model is a whole Rust file.
    assert_eq!(
        standalone("impl $crate::Model for Model"),
        "impl ::fem_runtime::Model for Model"
    );
    let code = expand(quote! {
        pub mod m on interval { unknowns: u: P1; tests: v; forms: "a(u;v) = ∫ u'v'"; }
    });
    let text = dump_text(&code);
    assert!(text.contains("::fem_runtime::Model for Model"), "{text}");
    syn::parse_file(&text).expect("the dump parses as a Rust file");
}

/// Issue 11: whatever the text, the macro answers with code or located errors, never
/// a panic.
mod no_panic {
    use super::*;
    use proptest::prelude::*;

    const PIECES: &[&str] = &[
        "u",
        "v",
        "λ",
        "μ",
        "f",
        "t",
        "h",
        "h_T",
        "w",
        "a",
        "b",
        "B",
        "ν",
        "Т",
        "∫",
        "int",
        "Σ_T",
        "sum_T",
        "(",
        ")",
        ",",
        ";",
        "+",
        "−",
        "-",
        "*",
        "·",
        "/",
        "'",
        "''''",
        "²",
        "⁻²",
        "⁵",
        "^",
        "^-2",
        "[degree=",
        "[degree=1]",
        "]",
        "=",
        "a(u;v)",
        "b(v;μ)",
        "(u;v)",
        "1e999",
        "1e200",
        "0",
        "2",
        "0.5",
        "∇",
        "Δ",
        "grad",
        "lap",
        "dot",
        "_T",
        "\n",
        " ",
        "a₁(u;v) =",
        "fn(u;v) =",
        "#",
        "{",
        "}",
        "!",
        "é",
        "\"",
        "θ",
        "η_y",
        "ε",
        "eps",
        "div",
        "tr",
        "I",
        ":",
        "∂_x",
        "d_y",
        "[",
        "]",
        "/(t² + h²)",
        "/(t − 1)",
        "(1e200 + t)",
        "a(θ;η) =",
    ];

    fn model(cell: &str, forms: &str) -> TokenStream {
        let cell = proc_macro2::Ident::new(cell, proc_macro2::Span::call_site());
        quote! {
            pub mod m on #cell {
                unknowns: u: P2, λ: P0 >= 0;
                tests: v, μ;
                params: t;
                data: f;
                forms: #forms;
            }
        }
    }

    /// The same with a vector field θ: [P1]^2 (an error on intervals, after which the
    /// analysis must still not panic).
    fn vector_model(cell: &str, forms: &str) -> TokenStream {
        let cell = proc_macro2::Ident::new(cell, proc_macro2::Span::call_site());
        quote! {
            pub mod m on #cell {
                unknowns: θ: [P1]^2, u: P2, λ: P0 >= 0;
                tests: η, v, μ;
                params: t > 0;
                data: f;
                forms: #forms;
            }
        }
    }

    /// Code that parses as Rust, or at least one `compile_error!` (with a place: every
    /// diagnostic of the forms text names a line).
    fn check(out: &TokenStream) -> Result<(), TestCaseError> {
        let errors = rendered_errors(out);
        if errors.is_empty() {
            prop_assert!(syn::parse2::<syn::File>(out.clone()).is_ok());
        }
        Ok(())
    }

    fn piece_text() -> impl Strategy<Value = String> {
        prop::collection::vec(prop::sample::select(PIECES), 0..40).prop_map(|v| v.concat())
    }

    /// Grammar-shaped integrands: sums of products of (derivatives of) arguments,
    /// numbers and symbols, with parentheses, powers and integrals.
    fn integrand() -> impl Strategy<Value = String> {
        let leaf = prop::sample::select(
            &[
                "u",
                "v",
                "u'",
                "v''",
                "∇u",
                "∇v",
                "Δu",
                "λ",
                "μ",
                "f",
                "t",
                "h",
                "2",
                "1e300",
                "0",
                "θ",
                "η",
                "ε(θ)",
                "ε(η)",
                "div η",
                "I",
                "∂_x θ",
                "∇θ",
                "θ_x",
                "(t² + h²)",
            ][..],
        )
        .prop_map(str::to_string);
        leaf.prop_recursive(4, 24, 3, |inner| {
            prop_oneof![
                (inner.clone(), inner.clone()).prop_map(|(a, b)| format!("{a} + {b}")),
                (inner.clone(), inner.clone()).prop_map(|(a, b)| format!("{a} − {b}")),
                (inner.clone(), inner.clone()).prop_map(|(a, b)| format!("{a}·{b}")),
                (inner.clone(), inner.clone()).prop_map(|(a, b)| format!("{a} / {b}")),
                (inner.clone(), inner.clone()).prop_map(|(a, b)| format!("{a} : {b}")),
                inner.clone().prop_map(|a| format!("div [{a}]")),
                inner.clone().prop_map(|a| format!("tr({a}) ε({a})")),
                inner.clone().prop_map(|a| format!("({a})")),
                inner.clone().prop_map(|a| format!("({a})²")),
                inner.clone().prop_map(|a| format!("∇({a})")),
                inner.clone().prop_map(|a| format!("({a})'")),
                (inner.clone(), inner).prop_map(|(a, b)| format!("({a}, {b})_T")),
            ]
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]

        #[test]
        fn random_token_texts(text in piece_text(), triangle in any::<bool>()) {
            let cell = if triangle { "triangle" } else { "interval" };
            check(&expand(model(cell, &text)))?;
            check(&expand(model(cell, &format!("a(u;v) = ∫ {text}"))))?;
            check(&expand(vector_model(cell, &format!("a(θ,u;η,v) = ∫ {text}"))))?;
        }

        #[test]
        fn random_grammar_shaped_forms(
            body in integrand(),
            degree in prop::option::of(0usize..45),
            triangle in any::<bool>(),
        ) {
            let cell = if triangle { "triangle" } else { "interval" };
            let option = degree.map(|d| format!("[degree={d}]")).unwrap_or_default();
            let forms = format!("a(u,λ;v,μ) = ∫{option} {body}\nℓ(v,μ) = Σ_T {body}\nB(u,λ;v,μ) = a(u,λ;v,μ) − 2 a(u,λ;v,μ)");
            check(&expand(model(cell, &forms)))?;
            let forms = format!("a(θ,u,λ;η,v,μ) = ∫{option} {body}\nB(θ,u,λ;η,v,μ) = a(θ,u,λ;η,v,μ) − a(η,v,μ;θ,u,λ)");
            check(&expand(vector_model(cell, &forms)))?;
        }
    }
}

/// Issue 11: on triangles `∫[degree=1]` is one-point (centroid) reduced integration,
/// as on intervals: the P1 mass matrix becomes `|T|/9` in every entry.
#[test]
fn degree_one_on_triangles_is_one_point() {
    let out = expand(membrane("P1", "a(u;v) = ∫[degree=1] u v")).to_string();
    assert!(rendered_errors(&out.parse().unwrap()).is_empty(), "{out}");
    assert!(out.contains("quadrature_points : 1usize"), "{out}");
    // R[i][j] = ½ · (⅓)² = 1/18 of 2|T| (= area2): |T|/9
    let literal = format!("{:?}", 1.0f64 / 18.0);
    assert!(out.contains(&format!("s0 * {literal}f64")), "{out}");
}

/// `∫_Γ … ds` and `int_Γ … ds` give the same facet blocks; the cell blocks stay apart,
/// and the normal's powers are kept per term.
#[test]
fn facet_integrals_ascii_and_unicode_agree() {
    let forms = |text: &str| {
        let declaration: Declaration = syn::parse2(quote! {
            pub mod contact on triangle {
                unknowns: u: [P1]^2, λ: P0 >= 0;
                tests: v, μ;
                params: α;
                data: g;
                facets: Γ_C;
                forms: #text;
            }
        })
        .unwrap();
        assert!(declaration.check().is_empty());
        let symbols = crate::symbols(&declaration);
        let (tokens, errors) = lexer::tokenize(text);
        assert!(errors.is_empty(), "{errors:?}");
        let (definitions, errors) = parser::parse_forms(&tokens);
        assert!(errors.is_empty(), "{errors:?}");
        let (forms, errors) = analysis::analyse(&symbols, &definitions, text);
        assert!(errors.is_empty(), "{errors:?}");
        forms
            .into_iter()
            .map(|f| (f.blocks, f.facet_blocks))
            .collect::<Vec<_>>()
    };
    let unicode = forms(
        "
        a(u;v) = ∫ ε(u):ε(v) + ∫_Γ_C h_E (u·n)(v·n) ds
        b(v;μ) = −∫_Γ_C μ v·n ds
    ",
    );
    let ascii = forms(
        "
        a(u;v) = int eps(u):eps(v) + int_Γ_C h_E (u dot n)(v dot n) ds
        b(v;μ) = -int_Γ_C μ v dot n ds
    ",
    );
    assert_eq!(unicode, ascii);
    let (cell, facet) = &unicode[0];
    assert_eq!(cell.len(), 4);
    assert_eq!(facet.len(), 4);
    // (v_x, u_x) on Γ_C: h n_x²
    let (part, block) = &facet[0];
    assert_eq!(*part, 0);
    assert_eq!(block.terms.len(), 1);
    assert_eq!(block.terms[0].normal, [2, 0]);
    assert_eq!(block.terms[0].h_power, 1);
    assert!(unicode[1].0.is_empty());
}

/// A model on intervals with the parameters E, t, α and the data f, for the runs of
/// juxtaposed names below.
fn run_model(forms: &str) -> TokenStream {
    quote! {
        /// Runs of names.
        pub mod runs on interval {
            unknowns: u: P2;
            tests: v;
            params: E, t, α;
            data: f;
            forms: #forms;
        }
    }
}

/// A tester's wrong kernels: a power or primes after a run of juxtaposed names applied
/// to the whole run, so `Et³` was `(Et)³` and `αh_T²` was `α²h²` without a word, and
/// `fv'` was refused as a derivative of data. They belong to the run's last name, as
/// mathematics reads them: the expansion equals the spaced spelling's, kernel for kernel.
#[test]
fn powers_and_primes_bind_to_the_last_name_of_a_run() {
    for (run, spaced) in [
        ("a(u;v) = ∫ Et³ u'v'", "a(u;v) = ∫ E t³ u'v'"),
        (
            "a(u;v) = Σ_T αh_T² (u, v)_T",
            "a(u;v) = Σ_T α h_T² (u, v)_T",
        ),
        ("a(u;v) = ∫ Et⁻² u'v'", "a(u;v) = ∫ E t⁻² u'v'"),
        ("ℓ(v) = ∫ fv'", "ℓ(v) = ∫ f v'"),
        ("a(u;v) = ∫ uv' + u'v", "a(u;v) = ∫ u v' + u'v"),
    ] {
        let joined = expand(run_model(run)).to_string();
        assert!(!joined.contains("compile_error"), "{run}: {joined}");
        let spaced_out = expand(run_model(spaced)).to_string();
        // the form's text is embedded in the output: compare all else
        assert_eq!(joined.replace(run, spaced), spaced_out, "{run}");
    }
    // and the whole run still multiplies where nothing follows it
    let product = expand(run_model("a(u;v) = ∫ Et u'v'")).to_string();
    let spaced = expand(run_model("a(u;v) = ∫ E t u'v'")).to_string();
    assert_eq!(product.replace("Et u'v'", "E t u'v'"), spaced);
}

/// A tester's macro panic: a named expression using a function that is not its argument
/// (`γ(θ) := ∇w − θ`, the Mindlin shear strain written with one argument) unwrapped a
/// missing substitution. It is an error at the function, naming the expression.
#[test]
fn a_named_expression_uses_only_its_arguments() {
    let out = expand(quote! {
        /// Shear strain.
        pub mod shear on triangle {
            unknowns: θ: [P1]^2, w: P2;
            tests: η, v;
            forms: "
                γ(θ) := ∇w − θ
                a(θ,w;η,v) = ∫ γ(θ)·γ(η)
            ";
        }
    });
    let errors = rendered_errors(&out).join("\n");
    assert!(
        errors.contains("is not an argument of `γ`") && errors.contains("w"),
        "{errors}"
    );
}

/// A tester's wrong measure: a form called inside an integral (`∫ g(μ)` with `g` a
/// boundary integral, `∫_Γ_C m(λ;μ) ds` with `m` a cell integral) compiled as the outer
/// integral's kind. It is the "integral inside an integral" that `∫ ∫` already is.
#[test]
fn a_form_called_inside_an_integral_is_refused() {
    for forms in [
        "g(μ) = ∫_Γ_C ψ μ ds\n G(μ) = ∫ g(μ)",
        "m(λ;μ) = ∫ λ μ\n M(λ;μ) = ∫_Γ_C m(λ;μ) ds",
    ] {
        let out = expand(quote! {
            /// Facets.
            pub mod facets on triangle {
                unknowns: u: P1, λ: P0 >= 0;
                tests: v, μ;
                data: ψ;
                facets: Γ_C;
                forms: #forms;
            }
        });
        let errors = rendered_errors(&out).join("\n");
        assert!(
            errors.contains("integral inside an integral"),
            "{forms}: {errors}"
        );
    }
}

/// A tester's stack overflows in rustc: a sum of 60,000 terms and `Δ^999999 u`. Both are
/// errors at the place now, and the limits are where the messages say.
#[test]
fn huge_sums_and_operator_powers_are_errors() {
    let long = vec!["u v"; crate::parser::MAX_TERMS + 1].join(" + ");
    let out = expand(run_model(&format!("a(u;v) = ∫ {long}")));
    let errors = rendered_errors(&out).join("\n");
    assert!(
        errors.contains("a sum of more than 10000 terms"),
        "{}",
        &errors[..errors.len().min(400)]
    );
    let at_limit = vec!["u v"; crate::parser::MAX_TERMS].join(" + ");
    let out = expand(run_model(&format!("a(u;v) = ∫ {at_limit}")));
    assert!(!out.to_string().contains("compile_error"));
    for (power, order) in [("Δ^999999", "1999998"), ("Δ^9", "18")] {
        let out = expand(membrane("P2", &format!("a(u;v) = ∫ {power} u v")));
        let errors = rendered_errors(&out).join("\n");
        assert!(
            errors.contains(&format!("order {order}")),
            "{power}: {errors}"
        );
    }
    let out = expand(membrane("P2", "a(u;v) = ∫ Δ^8 u v"));
    assert!(!rendered_errors(&out)
        .iter()
        .any(|e| e.contains("raised to")));
}

/// A tester's unusable names: a parameter `int_k` (the forms read `int_` as the ASCII
/// boundary integral) and a vector field `d` (its components `d_x`, `d_y` are ∂_x, ∂_y)
/// were accepted and then failed with messages about something else. Both are refused
/// at the declaration; `ϵ` for the operator ε gets the lookalike hint.
#[test]
fn names_the_forms_cannot_use_are_refused_where_declared() {
    let out = expand(quote! {
        /// Names.
        pub mod names on triangle {
            unknowns: d: [P1]^2;
            tests: e;
            params: int_k;
            forms: "a(d;e) = ∫ d·e";
        }
    });
    let errors = rendered_errors(&out).join("\n");
    assert!(errors.contains("starts with `int_`"), "{errors}");
    assert!(errors.contains("reserved component `d_x`"), "{errors}");
    let out = expand(quote! {
        /// Lookalike.
        pub mod lookalike on triangle {
            unknowns: θ: [P1]^2;
            tests: η;
            forms: "a(θ;η) = ∫ ϵ(θ):ε(η)";
        }
    });
    let errors = rendered_errors(&out).join("\n");
    assert!(errors.contains("looks like `ε`"), "{errors}");
}

/// A tester's misleading messages: `∂_xu ∂_xv` (no space) is ∂_x u ∂_x v, as `Δu` is Δ u;
/// a form that calls itself is told so, not that it is "used before its definition".
#[test]
fn partials_without_spaces_and_self_calls() {
    let joined = expand(membrane("P2", "a(u;v) = ∫ ∂_xu ∂_xv")).to_string();
    let spaced = expand(membrane("P2", "a(u;v) = ∫ ∂_x u ∂_x v")).to_string();
    assert!(!joined.contains("compile_error"), "{joined}");
    assert_eq!(joined.replace("∂_xu ∂_xv", "∂_x u ∂_x v"), spaced);
    let errors = rendered_errors(&expand(membrane("P2", "a(u;v) = ∫ u v + a(u;v)"))).join("\n");
    assert!(errors.contains("form `a` calls itself"), "{errors}");
}

/// The re-test of the run rule: brackets keep a run together (`(Et)³` is `(E·t)³`, and
/// `(uv)'` is still the derivative of a product, an error), primes on a parameter keep
/// the old reading (`uE'` is `(uE)'`, not a silent 0), and a long run with a power no
/// longer overflows the stack.
#[test]
fn brackets_keep_a_run_together() {
    let bracketed = expand(run_model("a(u;v) = ∫ (Et)³ u v")).to_string();
    let spelled = expand(run_model("a(u;v) = ∫ E³t³ u v")).to_string();
    assert!(!bracketed.contains("compile_error"), "{bracketed}");
    assert_eq!(bracketed.replace("(Et)³", "E³t³"), spelled);
    let errors = rendered_errors(&expand(run_model("a(u;v) = ∫ (uv)'"))).join("\n");
    assert!(errors.contains("derivative of a product"), "{errors}");
    let joined = expand(run_model("a(u;v) = ∫ uE' v")).to_string();
    let old = expand(run_model("a(u;v) = ∫ E u' v")).to_string();
    assert_eq!(joined.replace("uE' v", "E u' v"), old);
    let long = format!("a(u;v) = ∫ {}t² u v", "E".repeat(1000));
    assert!(!expand(run_model(&long))
        .to_string()
        .contains("compile_error"));
}

/// The model-language testers' leftovers: `∂_xy` is one error at the operator (it had
/// cascaded into "unknown symbol `_xy`"), ASCII `d_xu` is told to add a space, a run of
/// 300 primes is order 300 (a `u8` had saturated at 255), and an exponent too large for
/// an integer is called too large, not "malformed".
#[test]
fn derivative_and_exponent_spellings_get_one_precise_error() {
    for (forms, message, help) in [
        (
            "a(u;v) = ∫ ∂_xy u v",
            "`∂_xy` is ambiguous",
            "write ∂_x ∂_y",
        ),
        ("a(u;v) = ∫ ∂_yyu v", "`∂_yy` is ambiguous", "write ∂_y²"),
        // the re-test: a longer run and a capital were still cascades
        (
            "a(u;v) = ∫ ∂_xyz u v",
            "`∂_xyz` is ambiguous",
            "write ∂_x ∂_y",
        ),
        (
            "a(u;v) = ∫ ∂_X u v",
            "`∂_X` is not a partial derivative",
            "write ∂_x or ∂_y",
        ),
        (
            "a(u;v) = ∫ d_xu d_x v",
            "unknown symbol `d_xu`",
            "write `d_x u` with a space",
        ),
        ("a(u;v) = ∫ d_xy u v", "unknown symbol `d_xy`", "d_x d_y"),
    ] {
        let errors = rendered_errors(&expand(membrane("P2", forms)));
        assert_eq!(errors.len(), 1, "{forms}: {errors:?}");
        assert!(
            errors[0].contains(message) && errors[0].contains(help),
            "{forms}: {errors:?}"
        );
    }
    let primes = "'".repeat(300);
    for (forms, message) in [
        (format!("a(u;v) = ∫ u{primes} v"), "derivative of order 300"),
        (
            "a(u;v) = ∫ t⁹⁹⁹⁹⁹⁹⁹⁹⁹⁹⁹ u v".into(),
            "exponent `⁹⁹⁹⁹⁹⁹⁹⁹⁹⁹⁹` is beyond the limit 1000",
        ),
        (
            "a(u;v) = ∫ t^99999999 u v".into(),
            "exponent 99999999 is beyond the limit 1000",
        ),
        (
            "a(u;v) = ∫ t^2.5 u v".into(),
            "exponent 2.5 is not an integer",
        ),
        ("a(u;v) = ∫ t⁻⁻² u v".into(), "malformed exponent `⁻⁻²`"),
        // the re-test: the sign was dropped from the message
        (
            "a(u;v) = ∫ t^-2147483648 u v".into(),
            "exponent -2147483648 is beyond",
        ),
    ] {
        let errors = rendered_errors(&expand(run_model(&forms)));
        assert_eq!(errors.len(), 1, "{forms}: {errors:?}");
        assert!(errors[0].contains(message), "{forms}: {errors:?}");
    }
}

/// A tester's `∫_Ω T ∇u·∇v` (the domain's integral as many write it) was read as a
/// boundary integral over a part `Ω` and cascaded into "form `a` is used before its
/// definition"; it is the cell integral now, in both spellings. On an interval a
/// boundary integral no longer sends the user to `facets:`, which intervals refuse.
#[test]
fn the_integral_over_omega_is_the_cell_integral() {
    let plain = expand(membrane("P2", "a(u;v) = ∫ ∇u·∇v"))
        .to_string()
        .replace("a(u;v) = ∫ ∇u·∇v", "SOURCE");
    for spelling in ["a(u;v) = ∫_Ω ∇u·∇v", "a(u;v) = int_Omega grad u dot grad v"] {
        let text = expand(membrane("P2", spelling)).to_string();
        assert!(!text.contains("compile_error"), "{spelling}");
        // the same code but for the source text it quotes
        assert!(text.replace(spelling, "SOURCE") == plain, "{spelling}");
    }
    let errors = rendered_errors(&expand(timoshenko("a(θ,w;η,v) = ∫θ'η' + ∫_Γ w v ds"))).join("\n");
    assert!(
        errors.contains("available on triangles only") && !errors.contains("facets:"),
        "{errors}"
    );
}

/// `tests:` out of order with a vector field (the plate's `tests: v, η, μ` for
/// `unknowns: θ, w, λ`): the first signature over the same fields on both sides shows
/// it (`a(θ,w;η,v)`), and it is the only error
/// (the forms' own errors about the wrong field's element would mislead). Written in
/// the declared order, the same forms compile.
#[test]
fn tests_out_of_order_are_one_error_at_the_signature() {
    let model = |tests: proc_macro2::TokenStream| {
        expand(quote! {
            /// Plate.
            pub mod plate on triangle {
                unknowns: θ: [P1]^2, w: P2, λ: P0 >= 0;
                tests: #tests;
                params: α;
                data: f, ψ;
                forms: "
                    a(θ,w;η,v)       = ∫ ∇θ:∇η + (∇w − θ)·(∇v − η)
                    B_h(θ,w,λ;η,v,μ) = a(θ,w;η,v) − ∫ v λ − ∫ w μ − α ∫ λ μ
                    L_h(η,v,μ)       = ∫ f v − ∫ ψ μ
                ";
            }
        })
    };
    let errors = rendered_errors(&model(quote! { v, η, μ }));
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert!(
        errors[0].contains("`a` pairs the unknown `θ` with the test function `η`")
            && errors[0].contains("pair `θ` with `v`"),
        "{errors:?}"
    );
    assert!(rendered_errors(&model(quote! { η, v, μ })).is_empty());
}

/// Names written together with two readings (`params: s, t, st`: `stu` is `st·u` or
/// `s·t·u`) are an error naming both; one reading (`sλ`) multiplies as before.
#[test]
fn juxtaposed_names_with_two_readings_are_refused() {
    let out = expand(quote! {
        /// Ambiguous.
        pub mod ambiguous on interval {
            unknowns: u: P1;
            tests: v;
            params: s, t, st;
            forms: "a(u;v) = ∫ stu v";
        }
    });
    let errors = rendered_errors(&out).join("\n");
    assert!(
        errors.contains("`stu` can be read as `st·u` or as `s·t·u`"),
        "{errors}"
    );
    let out = expand(quote! {
        /// Plain.
        pub mod plain on interval {
            unknowns: u: P1;
            tests: v;
            params: s, t;
            forms: "a(u;v) = ∫ stu v";
        }
    });
    assert!(rendered_errors(&out).is_empty());
}

/// A prime on a parameter alone is 0: with `params: k, ku` the re-tester's `∫ ku'v'`
/// (meant k·u'v') compiled to a form without a kernel. It is an error with the reading
/// the user likely meant.
#[test]
fn a_prime_on_a_parameter_is_refused() {
    let out = expand(quote! {
        /// Primed parameter.
        pub mod primed on interval {
            unknowns: u: P1;
            tests: v;
            params: k, ku;
            forms: "a(u;v) = ∫ ku'v'";
        }
    });
    let errors = rendered_errors(&out).join("\n");
    assert!(
        errors.contains("`ku` is a parameter: its derivative is 0") && errors.contains("`k u'`"),
        "{errors}"
    );
}

fn membrane_with_estimator(estimator: &str) -> TokenStream {
    quote! {
        /// Membrane.
        pub mod membrane on triangle {
            unknowns: u: P2, λ: P0 >= 0;
            tests: v, μ;
            params: α;
            data: f, ψ, g;
            boundary: u = g;
            forms: #MEMBRANE;
            estimator: #estimator;
        }
    }
}

#[test]
fn an_estimator_expands_to_kernels() {
    for text in [
        "η_T² = h_T² ‖f + Δu + λ‖²\n η_E² = h_E ‖[[∇u·n]]‖²",
        // a vector's norm (its components'), and each side's h_T inside a jump
        "η_T² = h_T² ‖f + Δu + λ‖² + ‖∇u‖²\n η_E² = h_E ‖[[h_T ∇u·n]]‖² + ‖[[∇u]]‖²",
        "eta_T^2 = h_T^2 ||f + lap u + λ||^2\n eta_E^2 = h_E ||[[grad u dot n]]||^2",
    ] {
        let out = expand(membrane_with_estimator(text));
        let text = out.to_string();
        assert!(!text.contains("compile_error"), "{text}");
        let _: syn::File = syn::parse2(out).expect("generated code parses");
        assert!(text.contains("pub mod estimator"));
        assert!(text.contains("HAS_ESTIMATOR"));
    }
}

#[test]
fn estimator_errors_point_at_the_place() {
    let cases = [
        ("η_T² = h_T² ‖f + Δu + λ‖", "must be squared"),
        ("η_T² = h_T² ‖f + Δv + λ‖²", "test function `v`"),
        ("η_T² = h_T² ‖f + uλ‖²", "linear in the unknowns"),
        ("η_E² = h_E ‖∇u·n‖²", "jump"),
        ("η_E² = h_E ‖[[f + ∇u·n]]‖²", "data alone in a jump"),
        ("η_T² = h_T² ‖∇u·n‖²", "normal"),
        ("η_T² = u ‖f + Δu‖²", "weight"),
        ("η_T² = h_T² ‖f‖²", "does not depend on the solution"),
        ("η_E² = h_T ‖[[∇u·n]]‖²", "`h_T`"),
        ("η_E² = h_E ‖[[h_E ∇u·n]]‖²", "`h_E` inside a jump"),
        ("η_T² = ∇u ‖f + Δu + λ‖²", "weight of a norm is a vector"),
        ("η² = h_T² ‖f‖²", "expected `η_T² =`"),
        (
            "η_E² = h_E ‖[[∇u·n]]‖²[degree=1]",
            "quadrature option on an edge",
        ),
        (
            "η_T² = h_T² ‖f + Δu + λ‖²[degre=1]",
            "malformed quadrature option",
        ),
        (
            "η_T² = h_T² ‖f + Δu + λ‖²[degree=x]",
            "malformed quadrature option",
        ),
        ("", "declares no indicator"),
    ];
    for (text, expected) in cases {
        let out = expand(membrane_with_estimator(text));
        let errors = rendered_errors(&out);
        assert!(
            errors.iter().any(|e| e.contains(expected)),
            "{text}: expected an error with `{expected}`, got {errors:?}"
        );
    }
}

#[test]
fn an_estimator_on_an_interval_expands_to_cell_and_node_kernels() {
    let out = expand(quote! {
        /// Beam.
        pub mod beam on interval {
            unknowns: w: Hermite, λ: P0 >= 0;
            tests: v, μ;
            data: f;
            forms: "a(w;v) = ∫ w''v''";
            estimator: "
                η_T² = h_T⁴ ‖f + λ − w''''‖²
                η_E² = h_E³ ‖[[w''']]‖² + h_E ‖[[w'']]‖²
            ";
        }
    });
    let text = out.to_string();
    assert!(!text.contains("compile_error"), "{text}");
    let _: syn::File = syn::parse2(out).expect("generated code parses");
    assert!(text.contains("pub mod estimator") && text.contains("PHI_END_HERMITE_D3"));
}

#[test]
fn an_interval_estimator_refuses_the_normal_on_cells() {
    let out = expand(quote! {
        /// Beam.
        pub mod beam on interval {
            unknowns: w: Hermite, λ: P0 >= 0;
            tests: v, μ;
            data: f;
            forms: "a(w;v) = ∫ w''v''";
            estimator: "η_T² = h_T⁴ ‖n w''''‖²";
        }
    });
    let errors = rendered_errors(&out);
    assert!(errors.iter().any(|e| e.contains("`n`")), "{errors:?}");
}

fn loaded_membrane_with_estimator(estimator: &str) -> TokenStream {
    quote! {
        /// Membrane loaded on a boundary part.
        pub mod loaded on triangle {
            unknowns: u: P1;
            tests: v;
            data: q;
            facets: Γ_N;
            forms: "
                a(u;v) = ∫ ∇u·∇v
                ℓ(v)   = ∫_Γ_N q v ds
            ";
            estimator: #estimator;
        }
    }
}

#[test]
fn a_boundary_part_has_its_own_indicator() {
    for text in [
        "η_T² = h_T² ‖Δu‖²\n η_Γ_N² = h_E ‖∇u·n − q‖²",
        // a vector `(X, Y)` of scalars
        "η_Γ_N² = h_E ‖(∂_x u, ∂_y u)·n − q‖² + h_E ‖∇u + (q, 0)‖²",
    ] {
        let out = expand(loaded_membrane_with_estimator(text));
        let text = out.to_string();
        assert!(!text.contains("compile_error"), "{text}");
        let _: syn::File = syn::parse2(out).expect("generated code parses");
        assert!(text.contains("fn boundary_indicator"));
    }
}

#[test]
fn boundary_indicator_errors_point_at_the_place() {
    let cases = [
        ("η_Γ_D² = h_E ‖∇u·n − q‖²", "`η_Γ_N² = …`"),
        (
            "η_Γ_N² = h_T ‖∇u·n − q‖²",
            "`h_T` in the weight of a boundary part's line",
        ),
        (
            "η_Γ_N² = h_E ‖h_E ∇u·n − q‖²",
            "`h_E` inside the norm of a boundary part's line",
        ),
        ("η_Γ_N² = h_E ‖(∇u, q)‖²", "a vector `(X, Y)` of a vector"),
        ("η_Γ_N² = h_E ‖q‖²", "does not depend on the solution"),
    ];
    for (text, expected) in cases {
        let out = expand(loaded_membrane_with_estimator(text));
        let errors = rendered_errors(&out);
        assert!(
            errors.iter().any(|e| e.contains(expected)),
            "{text}: expected an error with `{expected}`, got {errors:?}"
        );
    }
}

#[test]
fn a_vector_on_an_interval_is_refused() {
    let out = expand(quote! {
        /// Beam.
        pub mod beam on interval {
            unknowns: w: P1;
            tests: v;
            forms: "a(w;v) = ∫ (w', w')·(v', v')";
        }
    });
    let errors = rendered_errors(&out);
    assert!(
        errors
            .iter()
            .any(|e| e.contains("a vector `(X, Y)` on an interval")),
        "{errors:?}"
    );
}

/// The stabilized membrane as shipped (`models/src/membrane.rs`), with `S` and `L_h`
/// replaceable.
fn stabilized_membrane(s: &str, l_h: &str, estimator: &str) -> TokenStream {
    let forms = format!(
        "
        a(u;v)       = ∫ ∇u·∇v
        b(v;μ)       = ∫ v μ
        S(u,λ;v,μ)   = {s}
        ℓ(v)         = ∫ f v
        ℓ_S(v,μ)     = Σ_T h_T² (f, −Δv − μ)_T
        G(μ)         = ∫ ψ μ
        B_h(u,λ;v,μ) = a(u;v) − b(v;λ) − b(u;μ) − α S(u,λ;v,μ)
        L_h(v,μ)     = {l_h}
    "
    );
    quote! {
        /// Membrane.
        pub mod membrane on triangle {
            unknowns: u: P2, λ: P0 >= 0;
            tests: v, μ;
            params: α;
            data: f, ψ, g;
            boundary: u = g;
            forms: #forms;
            estimator: #estimator;
        }
    }
}

const CONSISTENT_S: &str = "Σ_T h_T² (−Δu − λ, −Δv − μ)_T";
const CONSISTENT_L: &str = "ℓ(v) − G(μ) − α ℓ_S(v,μ)";
const DECLARED: &str = "η_T² = h_T² ‖f + Δu + λ‖²\n η_E² = h_E ‖[[∇u·n]]‖²";

#[test]
fn a_consistent_membrane_is_derived_and_passes() {
    let out = expand(stabilized_membrane(CONSISTENT_S, CONSISTENT_L, DECLARED));
    let text = out.to_string();
    assert!(!text.contains("compile_error"), "{text}");
    assert!(text.contains("const STRONG_FORM : bool = true"), "{text}");
}

#[test]
fn an_inconsistent_stabilization_is_a_compile_error() {
    for (s, l_h, why) in [
        (
            "Σ_T h_T² (−Δu + λ, −Δv − μ)_T",
            CONSISTENT_L,
            "the sign of λ",
        ),
        (CONSISTENT_S, "ℓ(v) − G(μ)", "ℓ_S missing"),
        (CONSISTENT_S, "ℓ(v) − G(μ) + α ℓ_S(v,μ)", "the sign of ℓ_S"),
        (
            "Σ_T h_T² (−2Δu − λ, −Δv − μ)_T",
            CONSISTENT_L,
            "another operator",
        ),
    ] {
        let out = expand(stabilized_membrane(s, l_h, DECLARED));
        let errors = rendered_errors(&out);
        assert!(
            errors
                .iter()
                .any(|e| e.contains("does not stabilize the residual of the equation of `v`")),
            "{why}: {errors:?}"
        );
    }
}

#[test]
fn an_estimator_that_is_not_the_models_residual_is_a_compile_error() {
    for (text, expected) in [
        (
            "η_T² = h_T² ‖f − Δu + λ‖²",
            "not a multiple of the residual",
        ),
        (
            "η_T² = h_T² ‖f + Δu − λ‖²",
            "not a multiple of the residual",
        ),
        ("η_E² = h_E ‖[[∇u·τ]]‖²", "not a multiple of a flux"),
    ] {
        let out = expand(stabilized_membrane(CONSISTENT_S, CONSISTENT_L, text));
        let errors = rendered_errors(&out);
        assert!(
            errors.iter().any(|e| e.contains(expected)),
            "{text}: expected `{expected}`, got {errors:?}"
        );
    }
}

/// The plate's stabilization measures `div div Cε(θ) − sλ`, the contact equation's
/// residual after the rotation equation's `q = −div Cε(θ)`: consistent up to the
/// derivative of another equation; the beam's `θ''' − sλ` likewise. Changing the sign
/// of the third derivative is caught.
#[test]
fn a_stabilization_consistent_up_to_another_equation_passes() {
    // `S` takes every field, so that a residual of the rotation equation can be written
    let beam = |s: &str| {
        let forms = format!(
            "
            a(θ,w;η,v) = ∫ θ'η' + t⁻²(w'−θ)(v'−η)
            b(η,v;μ)   = ∫ s v μ
            S(θ,w,λ;η,v,μ) = {s}
            ℓ(η,v)     = ∫ f v
            ℓ_S(η,μ)   = Σ_T h_T⁴ (f, η''' − sμ)_T
            g(μ)       = ∫ s ψ μ
            B_h(θ,w,λ;η,v,μ) = a(θ,w;η,v) − b(η,v;λ) − b(θ,w;μ) − α S(θ,w,λ;η,v,μ)
            L_h(η,v,μ)       = ℓ(η,v) − g(μ) − α ℓ_S(η,μ)
        "
        );
        quote! {
            /// Timoshenko beam.
            pub mod beam on interval {
                unknowns: θ: P3, w: P3, λ: P0 >= 0;
                tests: η, v, μ;
                params: t > 0, α, s;
                data: f, ψ;
                forms: #forms;
            }
        }
    };
    let out = expand(beam("Σ_T h_T⁴ (θ''' − sλ, η''' − sμ)_T"));
    let text = out.to_string();
    assert!(!text.contains("compile_error"), "{text}");
    assert!(text.contains("const STRONG_FORM : bool = true"));
    // a sign changed, and a residual of the rotation equation alone (its derivative
    // `θ''' + t⁻²(w'' − θ')`, which no contact term enters: the contact equation's
    // residual must take part)
    for wrong in [
        "Σ_T h_T⁴ (−θ''' − sλ, η''' − sμ)_T",
        "Σ_T h_T⁴ (θ''' + t⁻²(w'' − θ'), η''' − sμ)_T",
    ] {
        let errors = rendered_errors(&expand(beam(wrong)));
        assert!(
            errors
                .iter()
                .any(|e| e.contains("does not stabilize the residual of the equation of `v`")),
            "{wrong}: {errors:?}"
        );
    }
}

/// The plate's fluxes: the Kirchhoff shear `V_n = (div M)·n + ∂_s M_ns` and `M_nn` are
/// what integration by parts of `a = ∫ M(w):K(v)` gives on an edge; the shear without
/// its tangential part, `(div M)·n`, is not.
#[test]
fn the_kirchhoff_shear_is_the_plates_flux() {
    let plate = |estimator: &str| {
        quote! {
            /// Plate.
            pub mod plate on triangle {
                unknowns: w: Argyris, λ: P0 >= 0;
                tests: v, μ;
                params: D > 0, ν, α, s;
                data: f, ψ, g;
                boundary: w = g;
                forms: "
                    K(w)         := −∇∇w
                    M(w)         := D[(1−ν)K(w) + ν tr K(w) I]
                    a(w;v)       = ∫ M(w):K(v)
                    b(v;μ)       = ∫ s v μ
                    S(w,λ;v,μ)   = Σ_T h_T⁴ (D Δ²w − sλ, D Δ²v − sμ)_T
                    ℓ(v)         = ∫ f v
                    ℓ_S(v,μ)     = Σ_T h_T⁴ (f, D Δ²v − sμ)_T
                    G(μ)         = ∫ s ψ μ
                    B_h(w,λ;v,μ) = a(w;v) − b(v;λ) − b(w;μ) − α S(w,λ;v,μ)
                    L_h(v,μ)     = ℓ(v) − G(μ) − α ℓ_S(v,μ)
                ";
                estimator: #estimator;
            }
        }
    };
    let shipped = "η_T² = h_T⁴/D ‖f − D Δ²w + sλ‖²\n η_E² = h_E³/D ‖[[(div M(w))·n + τ·∇((M(w)·n)·τ)]]‖² + h_E/D ‖[[(M(w)·n)·n]]‖²";
    let out = expand(plate(shipped));
    let text = out.to_string();
    assert!(!text.contains("compile_error"), "{text}");
    let out = expand(plate("η_E² = h_E³/D ‖[[(div M(w))·n]]‖²"));
    let errors = rendered_errors(&out);
    assert!(
        errors
            .iter()
            .any(|e| e.contains("not a multiple of a flux")),
        "{errors:?}"
    );
}

#[test]
fn a_derived_estimator_expands_on_intervals() {
    let beam = quote! {
        /// Beam.
        pub mod beam on interval {
            unknowns: w: Hermite, λ: P0 >= 0;
            tests: v, μ;
            params: s;
            data: f, ψ;
            forms: "
                a(w;v) = ∫ w''v''
                b(v;μ) = ∫ s v μ
                ℓ(v)   = ∫ f v
                G(μ)   = ∫ s ψ μ
            ";
            estimator: derived;
        }
    };
    let out = expand(beam);
    let text = out.to_string();
    assert!(!text.contains("compile_error"), "{text}");
    let _: syn::File = syn::parse2(out).expect("generated code parses");
    // the cell residual and the two node fluxes, w''' and w''
    assert!(text.contains("PHI_END_HERMITE_D3") && text.contains("PHI_END_HERMITE_D2"));
}

#[test]
fn an_estimator_that_cannot_be_derived_says_why() {
    let out = expand(quote! {
        /// Membrane with a variable coefficient.
        pub mod variable on triangle {
            unknowns: u: P1;
            tests: v;
            data: k, f;
            forms: "
                a(u;v) = ∫ k ∇u·∇v
                ℓ(v)   = ∫ f v
            ";
            estimator: derived;
        }
    });
    let errors = rendered_errors(&out);
    assert!(
        errors.iter().any(|e| e.contains("cannot be derived")),
        "{errors:?}"
    );
    let out = expand(quote! {
        /// A misspelt estimator.
        pub mod misspelt on triangle {
            unknowns: u: P1;
            tests: v;
            data: f;
            forms: "a(u;v) = ∫ ∇u·∇v";
            estimator: derive;
        }
    });
    let errors = rendered_errors(&out);
    assert!(
        errors.iter().any(|e| e.contains("or `derived`")),
        "{errors:?}"
    );
}

/// The primal rows are checked too: a plate whose `ℓ_S` keeps `(f, −sμ)` but drops
/// `(f, DΔ²v)` is consistent in the multiplier's row and not in `v`'s.
#[test]
fn a_stabilization_missing_part_of_its_load_is_refused() {
    let out = expand(quote! {
        /// Plate.
        pub mod plate on triangle {
            unknowns: w: Argyris, λ: P0 >= 0;
            tests: v, μ;
            params: D > 0, ν, α, s;
            data: f, ψ, g;
            boundary: w = g;
            forms: "
                K(w)         := −∇∇w
                M(w)         := D[(1−ν)K(w) + ν tr K(w) I]
                a(w;v)       = ∫ M(w):K(v)
                b(v;μ)       = ∫ s v μ
                S(w,λ;v,μ)   = Σ_T h_T⁴ (D Δ²w − sλ, D Δ²v − sμ)_T
                ℓ(v)         = ∫ f v
                ℓ_S(v,μ)     = Σ_T h_T⁴ (f, −sμ)_T
                G(μ)         = ∫ s ψ μ
                B_h(w,λ;v,μ) = a(w;v) − b(v;λ) − b(w;μ) − α S(w,λ;v,μ)
                L_h(v,μ)     = ℓ(v) − G(μ) − α ℓ_S(v,μ)
            ";
        }
    });
    let errors = rendered_errors(&out);
    assert!(
        errors.iter().any(|e| e.contains("the row of `v`")),
        "{errors:?}"
    );
}

/// A derived estimator keeps the jumps of a field whose cell residual vanishes (P1
/// elasticity: `div σ(u) = 0` on each cell), and is refused for forms with boundary
/// integrals, whose boundary residuals it would miss.
#[test]
fn a_derived_estimator_keeps_jumps_and_refuses_boundary_loads() {
    let body = |facets: bool| {
        let load = if facets {
            "ℓ(v) = ∫_Γ_N q v·n ds"
        } else {
            "ℓ(v) = ∫ (0, q)·v"
        };
        let forms = format!(
            "
            σ(u)   := 2μ_L ε(u) + λ_L tr ε(u) I
            a(u;v) = ∫ σ(u):ε(v)
            {load}
        "
        );
        quote! {
            /// Elasticity.
            pub mod body on triangle {
                unknowns: u: [P1]^2;
                tests: v;
                params: μ_L > 0, λ_L;
                data: q;
                facets: Γ_N;
                forms: #forms;
                estimator: derived;
            }
        }
    };
    let out = expand(body(false));
    let text = out.to_string();
    assert!(!text.contains("compile_error"), "{text}");
    assert!(text.contains("F_v_x") && text.contains("F_v_y"), "{text}");
    let errors = rendered_errors(&expand(body(true)));
    assert!(
        errors
            .iter()
            .any(|e| e.contains("integrate over boundary parts")),
        "{errors:?}"
    );
}

/// Signorini's model as shipped (`models/src/signorini.rs`), with `S` and the `unit:`
/// section replaceable.
fn signorini(s: &str, unit: TokenStream) -> TokenStream {
    let forms = format!(
        "
        σ(u)         := 2μ_L ε(u) + λ_L tr ε(u) I
        σ_n(u)       := (σ(u)·n)·n_c
        a(u;v)       = ∫ σ(u):ε(v)
        b(v;μ)       = −∫_Γ_C μ v·n_c ds
        S(u,λ;v,μ)   = {s}
        ℓ(v)         = −∫_Γ_N q v·n ds
        G(μ)         = −∫_Γ_C g μ ds
        B_h(u,λ;v,μ) = a(u;v) − b(v;λ) − b(u;μ) − α S(u,λ;v,μ)
        L_h(v,μ)     = ℓ(v) − G(μ)
    "
    );
    quote! {
        /// Signorini.
        pub mod signorini on triangle {
            unknowns: u: [P1]^2, λ: P0 >= 0;
            tests: v, μ;
            params: μ_L > 0, λ_L, α, n_c_x, n_c_y;
            data: q: 2, g: 1;
            facets: Γ_C, Γ_N;
            forms: #forms;
            #unit
        }
    }
}

/// The facet stabilization is checked against the boundary equation `a`, `b` and `ℓ`
/// give on `Γ_C`: Signorini's passes with its direction declared a unit vector; a wrong
/// sign, another operator, or the direction not declared `unit:` (then `λ + σ_n(u)` is
/// not the normal part of `σ(u)n + λ n_c`) is a compile error at the term.
#[test]
fn a_facet_stabilization_is_checked_against_the_boundary_equation() {
    const CONSISTENT: &str = "∫_Γ_C h_E (λ + σ_n(u))(μ + σ_n(v)) ds";
    let unit = quote!(unit: n_c;);
    let out = expand(signorini(CONSISTENT, unit.clone()));
    let text = out.to_string();
    assert!(!text.contains("compile_error"), "{text}");
    assert!(text.contains("UNIT_PARAMS"), "{text}");
    for (s, unit, why) in [
        (
            "∫_Γ_C h_E (λ − σ_n(u))(μ − σ_n(v)) ds",
            unit.clone(),
            "the sign of σ_n",
        ),
        (
            "∫_Γ_C h_E (λ + 2σ_n(u))(μ + 2σ_n(v)) ds",
            unit.clone(),
            "another operator",
        ),
        (CONSISTENT, quote!(), "the direction not a unit vector"),
    ] {
        let errors = rendered_errors(&expand(signorini(s, unit)));
        assert!(
            errors
                .iter()
                .any(|e| e.contains("does not stabilize the boundary equation")),
            "{why}: {errors:?}"
        );
    }
    let errors = rendered_errors(&expand(signorini(CONSISTENT, quote!(unit: m;))));
    assert!(
        errors.iter().any(|e| e.contains("`m_x` and `m_y`")),
        "{errors:?}"
    );
}
