//! Tests of shapes in the forms text: vector fields lowered to their components, the
//! tensor operators checked against the same forms written component by component,
//! shape errors, and division by positive sums of parameters and `h`.

use super::*;
use crate::symbolic::{ArgFactor, Expansion};
use quote::quote;

/// A plate-like model: rotations θ ∈ [P1]², deflection w ∈ P2, multiplier λ ∈ P0.
fn plate(forms: &str) -> TokenStream {
    quote! {
        /// Plate.
        pub mod plate on triangle {
            unknowns: θ: [P1]^2, w: P2, λ: P0 >= 0;
            tests: η, v, μ;
            params: D, ν, κ, t > 0, β > 0, α, s;
            data: f;
            forms: #forms;
        }
    }
}

fn plate_symbols() -> Symbols {
    let declaration: Declaration = syn::parse2(plate("a(θ;η) = ∫ θ·η")).unwrap();
    assert!(declaration.check().is_empty());
    symbols(&declaration)
}

fn rendered_errors(out: &TokenStream) -> Vec<String> {
    out.to_string()
        .split("compile_error")
        .skip(1)
        .map(str::to_string)
        .collect()
}

/// The value of an expansion with fixed pseudo-random values for every argument
/// derivative (a different number per symbol and multi-index) and for the parameters.
fn value(e: &Expansion) -> f64 {
    let arg = |a: ArgFactor| {
        let k = a.symbol * 31 + a.derivative[0] as usize * 7 + a.derivative[1] as usize * 3 + 1;
        ((k as f64) * 0.618_033_988_749_895).fract() - 0.37
    };
    let params = [1.3, 0.3, 5.0 / 6.0, 0.1, 0.1, 0.25, -1.0];
    symbolic::evaluate(e, &|i| params[i], 0.3, &|_| 1.7, &arg)
}

fn expanded(text: &str) -> Expansion {
    analysis::expand_expression(&plate_symbols(), text).unwrap_or_else(|e| panic!("{text}: {e:?}"))
}

/// Both texts have the same value at arbitrary argument values.
fn same_value(a: &str, b: &str) {
    let (vx, vy) = (value(&expanded(a)), value(&expanded(b)));
    assert!(
        (vx - vy).abs() <= 1e-13 * vx.abs().max(1.0),
        "{a} = {vx}, {b} = {vy}"
    );
}

/// Both texts expand to the same polynomial in the argument derivatives (compared as
/// values at arbitrary argument values, and as numbers of terms after merging).
fn same(a: &str, b: &str) {
    let (x, y) = (expanded(a), expanded(b));
    let (vx, vy) = (value(&x), value(&y));
    assert!(
        (vx - vy).abs() <= 1e-13 * vx.abs().max(1.0),
        "{a} = {vx}, {b} = {vy}"
    );
    let difference = symbolic::add(x, symbolic::neg(y));
    assert!(
        difference.iter().all(|t| t.coefficient.abs() < 1e-14),
        "{a} − {b} leaves {difference:?}"
    );
}

#[test]
fn a_vector_field_is_lowered_to_its_components() {
    let s = plate_symbols();
    let names: Vec<(&str, &str)> = s
        .fields
        .iter()
        .map(|f| (f.name.as_str(), f.test_name.as_str()))
        .collect();
    assert_eq!(
        names,
        [("θ_x", "η_x"), ("θ_y", "η_y"), ("w", "v"), ("λ", "μ")]
    );
    assert_eq!(s.fields[1].component, Some((0, 1)));
    assert_eq!(s.vectors[0].first_field, 0);
    assert_eq!(s.positive, [3, 4]);
}

#[test]
fn tensor_operators_agree_with_components() {
    same(
        "ε(θ):ε(η)",
        "∂_x θ_x ∂_x η_x + ∂_y θ_y ∂_y η_y + 2·0.5(∂_y θ_x + ∂_x θ_y)·0.5(∂_y η_x + ∂_x η_y)",
    );
    same("eps(θ):eps(η)", "ε(θ):ε(η)");
    same("tr ε(θ) I : ε(η)", "div θ div η");
    same(
        "tr(ε(θ)) tr(ε(η))",
        "(∂_x θ_x + ∂_y θ_y)(d_x η_x + d_y η_y)",
    );
    same(
        "D[(1−ν)ε(θ) + ν tr ε(θ) I] : ε(η)",
        "D((1−ν) ε(θ):ε(η) + ν div θ div η)",
    );
    same(
        "(∇w − θ)·(∇v − η)",
        "(∂_x w − θ_x)(∂_x v − η_x) + (∂_y w − θ_y)(∂_y v − η_y)",
    );
    same("∇θ : ∇η", "∇θ_x·∇η_x + ∇θ_y·∇η_y");
    same("I : ∇θ v", "div θ v");
    same(
        "(∇θ ∇w)·η",
        "(∂_x θ_x ∂_x w + ∂_y θ_x ∂_y w) η_x + (∂_x θ_y ∂_x w + ∂_y θ_y ∂_y w) η_y",
    );
    same(
        "(∇w ∇θ)·η",
        "(∂_x w ∂_x θ_x + ∂_y w ∂_x θ_y) η_x + (∂_x w ∂_y θ_x + ∂_y w ∂_y θ_y) η_y",
    );
    same("div ∇w v", "Δw v");
    same("div div ∇∇w v", "ΔΔw v");
    // The Kirchhoff bending integrand (models/src/kirchhoff.rs) in Hessian notation is the
    // one written with partial derivatives, and ∂_x ∂_x reads as a second derivative.
    same(
        "D[(1−ν) ∇∇w:∇∇v + ν Δw Δv]",
        "D(1−ν)(∂_x ∂_x w ∂_x ∂_x v + 2 ∂_x ∂_y w ∂_y ∂_x v + ∂_y ∂_y w ∂_y ∂_y v) \
         + Dν(∂_x ∂_x w + ∂_y ∂_y w)(∂_x ∂_x v + ∂_y ∂_y v)",
    );
    same("div(∇θ)·η", "Δθ_x η_x + Δθ_y η_y");
    same("∂_x θ · ∂_y η", "∂_x θ_x ∂_y η_x + ∂_x θ_y ∂_y η_y");
    same("tr I w v", "2 w v");
    same("s θ·η", "sθ·η");
}

#[test]
fn the_plate_operator_of_p1_rotations_vanishes() {
    // div div Cε(θ) holds second derivatives of P1 components only: the kernel drops it.
    let out = expand(plate(
        "S(θ,λ;η,μ) = Σ_T h_T⁴ (D div div [(1−ν)ε(θ) + ν tr ε(θ) I] − sλ, div div (D[(1−ν)ε(η) + ν tr ε(η) I]) − sμ)_T",
    ));
    assert!(rendered_errors(&out).is_empty(), "{out}");
    let text = out.to_string();
    assert!(text.contains("fn matrix_μ_λ"));
    assert!(!text.contains("fn matrix_η_x") && !text.contains("fn matrix_μ_θ"));
}

#[test]
fn a_vector_model_expands_to_valid_rust_with_component_blocks_and_handles() {
    let forms = "
        a(θ;η)        = ∫ D[(1−ν)ε(θ) + ν tr ε(θ) I] : ε(η)
        a_s(θ,w;η,v)  = ∫ 6κ(1−ν)D/(t² + β h_T²) (∇w − θ)·(∇v − η)
        b(v;μ)        = ∫ s v μ
        ℓ(v)          = ∫ f v
        B(θ,w,λ;η,v,μ) = a(θ;η) + a_s(θ,w;η,v) − b(v;λ) − b(w;μ)
    ";
    let out = expand(plate(forms));
    assert!(rendered_errors(&out).is_empty(), "{out}");
    let file: syn::File = syn::parse2(out.clone()).expect("generated code parses");
    let text = prettyplease::unparse(&file);
    for kernel in [
        "fn matrix_η_x_θ_x",
        "fn matrix_η_x_θ_y",
        "fn matrix_η_y_θ_x",
        "fn matrix_η_y_θ_y",
        "fn matrix_v_w",
        "fn matrix_v_θ_x",
        "fn matrix_η_y_w",
    ] {
        assert!(text.contains(kernel), "{kernel} missing");
    }
    // a(θ;η) has no (w, …) block: zero blocks are not generated
    let a_module = text.split("pub mod a {").nth(1).unwrap();
    let a_module = a_module.split("pub mod a_s").next().unwrap();
    assert!(!a_module.contains("matrix_v_"));
    assert!(text.contains("name: \"θ_x\""));
    assert!(text.contains("test_name: \"η_y\""));
    let handle = text.split("pub const θ: [").nth(1).expect("a handle of θ");
    assert!(handle.contains("FieldId::new(0usize)") && handle.contains("FieldId::new(1usize)"));
    assert!(text.contains("const POSITIVE_PARAMS: &'static [usize] = &[3usize, 4usize];"));
    // the Stenberg weight divides by t² + β h²
    assert!(text.contains("(t^2 + β·h^2)^-1"), "{text}");
}

#[test]
fn forms_called_with_vector_arguments_substitute_components() {
    let forms = "
        m(θ;η) = ∫ θ·η
        B(θ,w;η,v) = m(θ;η) + m(η;θ)
        C(θ;η) = m(w;η)
    ";
    let errors = rendered_errors(&expand(plate(forms)));
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert!(
        errors[0].contains("argument `w` of `m` must be a function of the field `θ` (`θ` or `η`)"),
        "{errors:?}"
    );
}

#[test]
fn shape_errors_point_at_the_expression() {
    let cases = [
        (
            "a(θ,w;η,v) = ∫ (∇w − w)·(∇v − η)",
            "difference of a vector and a scalar",
            16,
        ),
        ("a(w;v) = ∫ ε(w):ε(v)", "ε of a scalar", 12),
        ("a(θ;η) = ∫ ε(θ):η", "`:` of a matrix and a vector", 12),
        ("a(w;v) = ∫ div w v", "div of a scalar", 12),
        ("a(θ;η) = ∫ tr θ η_x", "tr of a vector", 12),
        ("a(θ;η) = ∫ ε(θ)", "a matrix where a scalar is needed", 12),
        ("a(θ;η) = ∫ θ + η", "a vector where a scalar is needed", 12),
        ("a(θ;η) = ∫ ∇θ ∇η", "product of two matrices", 12),
        (
            "a(θ;η) = Σ_T (ε(θ), η)_T",
            "L² product of a matrix and a vector",
            14,
        ),
    ];
    for (forms, message, column) in cases {
        let errors = rendered_errors(&expand(plate(forms)));
        assert!(
            errors
                .iter()
                .any(|e| e.contains(message) && e.contains(&format!("column {column}"))),
            "{forms}: {errors:?}"
        );
    }
}

#[test]
fn declarations_of_vector_fields_are_checked() {
    let model = |unknowns: TokenStream, cell: &str| {
        let cell = syn::Ident::new(cell, proc_macro2::Span::call_site());
        quote! {
            pub mod m on #cell {
                unknowns: #unknowns;
                tests: η, v;
                params: θ_x;
                forms: "a(w;v) = ∫ w v";
            }
        }
    };
    let errors = rendered_errors(&expand(model(quote!(θ: [P1]^2, w: P1), "triangle")));
    assert!(
        errors
            .iter()
            .any(|e| e
                .contains("`θ_x` is both a declared name and a component of the vector field `θ`")),
        "{errors:?}"
    );
    let errors = rendered_errors(&expand(model(quote!(θ: [P1]^3, w: P1), "triangle")));
    assert!(
        errors
            .iter()
            .any(|e| e.contains("as many components as the cell")),
        "{errors:?}"
    );
    let errors = rendered_errors(&expand(model(quote!(θ: [P1]^2, w: P1), "interval")));
    assert!(
        errors
            .iter()
            .any(|e| e.contains("as many components as the cell")),
        "{errors:?}"
    );
    let errors = rendered_errors(&expand(model(quote!(θ: [P0]^2 >= 0, w: P1), "triangle")));
    assert!(
        errors.iter().any(|e| e.contains("must be a scalar field")),
        "{errors:?}"
    );
    let errors = rendered_errors(&expand(model(quote!(θ: [P1] 2, w: P1), "triangle")));
    assert!(errors.iter().any(|e| e.contains("[P1]^2")), "{errors:?}");
    let boundary = quote! {
        pub mod m on triangle {
            unknowns: θ: [P1]^2;
            tests: η;
            data: g;
            boundary: θ_x = g, θ = g;
            forms: "a(θ;η) = ∫ ε(θ):ε(η)";
        }
    };
    let errors = rendered_errors(&expand(boundary));
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert!(errors[0].contains("`θ` is a vector field: prescribe its components"));
    assert!(errors[0].contains("`θ_x = g`, `θ_y = g`"));
}

#[test]
fn division_by_positive_sums() {
    // 6κ(1−ν)D/(t² + β h²) at D = 1.3, ν = 0.3, κ = 5/6, t = 0.1, β = 0.1, h = 0.3
    let weight = 6.0 * (5.0 / 6.0) * 0.7 * 1.3 / (0.01 + 0.1 * 0.09);
    for text in [
        "6κ(1−ν)D/(t² + β h_T²) θ·η",
        "6κ(1−ν)D (t² + β h_T²)⁻¹ θ·η",
        "6κ(1−ν)D (t^2 + β h^2)^-1 θ·η",
    ] {
        let with = value(&expanded(text));
        let without = value(&expanded("θ·η"));
        assert!(
            (with - weight * without).abs() < 1e-12 * with.abs(),
            "{text}: {with} vs {}",
            weight * without
        );
    }
    // a divisor times its sum is not simplified, but has the same value
    same_value("θ·η / (t² + β h²) (t² + β h²)", "θ·η");
    // (…)² is multiplied out before the division: another divisor, the same value
    same_value("θ·η / (β h² + t²)²", "θ·η / (t² + β h²) / (t² + h² β)");
    same("θ·η (β h² + t²)⁻²", "θ·η / (t² + β h²) / (t² + h² β)");
    // h > 0 always, even powers are ≥ 0, declared parameters are > 0
    for ok in ["1/(1 + ν²)", "1/(h + κ²)", "1/(t + β)", "1/(t² + 2 ν² h)"] {
        expanded(&format!("{ok} θ·η"));
    }
    let refused = [
        ("1/(t − β)", "a term has the coefficient -1"),
        ("1/(ν + t)", "`ν` is not declared positive"),
        ("1/(ν² + κ²)", "every term vanishes"),
        ("1/(t − t)", "it is zero"),
        ("1/(t + w)", "holds functions, data or integrals"),
        ("(t + ν)⁻¹", "`ν` is not declared positive"),
        ("1/(1e200·1e200 + t)", "overflows"),
    ];
    for (divisor, message) in refused {
        let text = format!("a(θ;η) = ∫ {divisor} θ·η");
        let errors = rendered_errors(&expand(plate(&text)));
        assert!(
            errors.iter().any(|e| e.contains(message)),
            "{text}: {errors:?}"
        );
    }
}

#[test]
fn named_expressions_read_as_in_the_mathematics() {
    // Cε(θ) := D[(1−ν)ε(θ) + ν tr ε(θ) I], called with a trial and a test function
    let named = "
        Cε(θ)      := D[(1−ν)ε(θ) + ν tr ε(θ) I]
        a(θ;η)     = ∫ Cε(θ):ε(η)
        b(θ;η)     = ∫ D[(1−ν)ε(θ) + ν tr ε(θ) I] : ε(η)
        S(θ,λ;η,μ) = Σ_T h_T⁴ (div div Cε(θ) − sλ, div div Cε(η) − sμ)_T
        ℓ(η)       = ∫ f tr Cε(η)
    ";
    let out = expand(plate(named));
    assert!(rendered_errors(&out).is_empty(), "{out}");
    let file: syn::File = syn::parse2(out).expect("generated code parses");
    let text = prettyplease::unparse(&file);
    // no module or handle for the expression; a and b give the same kernels
    assert!(!text.contains("pub mod Cε") && !text.contains("const Cε"));
    let module = |name: &str| {
        let body = text.split(&format!("pub mod {name} {{")).nth(1).unwrap();
        body.split("pub mod ").next().unwrap().to_string()
    };
    let strip = |m: String| {
        m.replace("`a`", "")
            .replace("`b`", "")
            .replace("INDEX: usize = 1", "INDEX: usize = 0")
    };
    let (a, b) = (module("a"), module("b"));
    let kernels = |m: &str| {
        m.split("pub fn")
            .skip(1)
            .map(|k| k.split("\n        }\n").next().unwrap().to_string())
            .collect::<Vec<_>>()
    };
    assert_eq!(kernels(&strip(a)), kernels(&strip(b)));
    let s = module("S");
    assert!(s.contains("fn matrix_μ_λ") && !s.contains("fn matrix_η"));
    // an expression of two arguments: the shear strain γ(θ,w) = ∇w − θ
    let shear = "
        γ(θ,w)       := ∇w − θ
        a(θ,w;η,v)   = ∫ t⁻² γ(θ,w)·γ(η,v)
        b(θ,w;η,v)   = ∫ t⁻² (∇w − θ)·(∇v − η)
    ";
    let text = prettyplease::unparse(&syn::parse2(expand(plate(shear))).unwrap());
    let (a, b) = (
        text.split("pub mod a {").nth(1).unwrap(),
        text.split("pub mod b {").nth(1).unwrap(),
    );
    let a = kernels(&strip(a.split("pub mod b").next().unwrap().to_string()));
    // θ_x, θ_y, w against each other but (η_x, θ_y) and (η_y, θ_x): zero, dropped;
    // each kernel twice, affine and curved (`_curved`)
    assert_eq!(a.len(), 14);
    assert_eq!(a, kernels(&strip(b.to_string())));
    // errors: a wrong field, a shape, an integral inside
    for (forms, message) in [
        (
            "Cε(θ) := ε(θ)\na(w;v) = ∫ Cε(w):ε(v)",
            "must be a function of the field `θ`",
        ),
        (
            "Cε(θ) := ε(θ)\na(θ;η) = ∫ Cε(θ)·ε(η)",
            "product of two matrices",
        ),
        (
            "Cε(θ) := ∫ ε(θ)\na(θ;η) = ∫ Cε(θ):ε(η)",
            "integral inside an integral",
        ),
    ] {
        let errors = rendered_errors(&expand(plate(forms)));
        assert!(
            errors.iter().any(|e| e.contains(message)),
            "{forms}: {errors:?}"
        );
    }
}

#[test]
fn ascii_and_unicode_vector_models_give_the_same_blocks() {
    let blocks = |declaration: TokenStream| {
        let declaration: Declaration = syn::parse2(declaration).unwrap();
        assert!(declaration.check().is_empty());
        let symbols = symbols(&declaration);
        let text = declaration.forms.value();
        let (tokens, e1) = lexer::tokenize(&text);
        let (definitions, e2) = parser::parse_forms(&tokens);
        let (forms, e3) = analysis::analyse(&symbols, &definitions, &text);
        assert!(
            e1.is_empty() && e2.is_empty() && e3.is_empty(),
            "{e1:?} {e2:?} {e3:?}"
        );
        forms.into_iter().map(|f| f.blocks).collect::<Vec<_>>()
    };
    let unicode = blocks(quote! {
        pub mod m on triangle {
            unknowns: θ: [P1]^2, w: P2;
            tests: η, v;
            params: ν, t > 0, β > 0;
            forms: "
                Cε(θ)  := [(1−ν)ε(θ) + ν tr ε(θ) I]
                a(θ,w;η,v) = ∫ Cε(θ):ε(η) + ∂_x θ_x ∂_y η_y + (∇w − θ)·(∇v − η)/(t² + β h_T²)
            ";
        }
    });
    let ascii = blocks(quote! {
        pub mod m on triangle {
            unknowns: theta: [P1]^2, w: P2;
            tests: eta, v;
            params: nu, t > 0, beta > 0;
            forms: "
                C(theta) := ((1-nu)*eps(theta) + nu*tr(eps(theta))*I)
                a(theta,w;eta,v) = int C(theta):eps(eta) + d_x theta_x * d_y eta_y + (grad w - theta) dot (grad v - eta) / (t^2 + beta*h^2)
            ";
        }
    });
    assert_eq!(unicode, ascii);
    assert_eq!(unicode[1].len(), 9);
}

#[test]
fn powers_of_derivative_operators_read_as_repeated_operators() {
    same("Δ²w v", "ΔΔw v");
    same("lap^2 w v", "ΔΔw v");
    same("Δ³w v", "ΔΔΔw v");
    same("∂_x² w v", "∂_x ∂_x w v");
    same("d_y^2 w d_x^2 v", "∂_y ∂_y w ∂_x ∂_x v");
    same("Δ²w Δ²v", "div div ∇∇w ΔΔv");
    for (text, message) in [
        ("a(w;v) = ∫ ∇²w v", "cannot be raised to a power"),
        ("a(w;v) = ∫ div² ∇w v", "cannot be raised to a power"),
        ("a(w;v) = ∫ Δ⁻¹w v", "only positive powers"),
        ("a(w;v) = ∫ Δ^0 w v", "only positive powers"),
    ] {
        let errors = rendered_errors(&expand(plate(text)));
        assert!(
            errors.iter().any(|e| e.contains(message)),
            "{text}: {errors:?}"
        );
    }
}

#[test]
fn the_kirchhoff_moment_and_curvature_read_as_in_the_mathematics() {
    // docs/mathematics.md §9: K(w) = −∇∇w, M(w) = D[(1−ν)K(w) + ν tr K(w) I], a(w,v) = ∫ M(w):K(v)
    let forms = "
        K(w)   := −∇∇w
        M(w)   := D[(1−ν)K(w) + ν tr K(w) I]
        a(w;v) = ∫ M(w):K(v)
        b(w;v) = ∫ D[(1−ν) ∇∇w:∇∇v + ν Δw Δv]
        c(w;v) = Σ_T h_T⁴ (D Δ²w, D Δ²v)_T
        d(w;v) = Σ_T h_T⁴ (D ΔΔw, D ΔΔv)_T
    ";
    let out = expand(plate(forms));
    assert!(rendered_errors(&out).is_empty(), "{out}");
    // the same kernels up to the order of the terms: compared numerically in
    // tests/kirchhoff_notation.rs; here, the same blocks and the Δ² spelling's identity
    let text = prettyplease::unparse(&syn::parse2(out).unwrap());
    let module = |name: &str| {
        let body = text.split(&format!("pub mod {name} {{")).nth(1).unwrap();
        body.split("pub mod ").next().unwrap().to_string()
    };
    let kernels = |m: &str| {
        m.split("pub fn")
            .skip(1)
            .map(|k| k.split("\n        }\n").next().unwrap().to_string())
            .collect::<Vec<_>>()
    };
    let names = |m: &str| {
        kernels(m)
            .iter()
            .map(|k| k.split('(').next().unwrap().to_string())
            .collect::<Vec<_>>()
    };
    assert!(names(&module("a")).contains(&" matrix_v_w".to_string()));
    assert_eq!(names(&module("a")), names(&module("b")));
    assert_eq!(kernels(&module("c")), kernels(&module("d")));
}
