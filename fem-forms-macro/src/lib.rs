#![cfg_attr(test, allow(mixed_script_confusables, confusable_idents))]
//! The fem-forms DSL: a model file's forms in math notation, compiled at `cargo build`
//! into plain Rust element kernels.
//!
//! Use it through `fem_forms::model!` (or `fem_runtime::model!`), which passes the
//! runtime's path to this macro. The pipeline is three pure stages, each unit-tested on
//! `proc_macro2` types: `parser` (text → syntax tree), `analysis` with the
//! `symbolic` IR (syntax tree → blocks of expanded monomials), `codegen` (blocks →
//! Rust: a driver, one backend per cell kind — intervals, affine triangles — and one
//! shared quadrature/data-loop emitter).
//!
//! # A model file
//!
//! ```text
//! fem_forms::model! {
//!     /// Timoshenko beam over a rigid obstacle (docs/mathematics.md §3), P2–P2–P0.
//!     pub mod timoshenko on interval {
//!         unknowns: θ: P2, w: P2, λ: P0 >= 0;
//!         tests: η, v, μ;
//!         params: t, α, s;
//!         data: f, ψ;
//!         forms: "
//!             a(θ,w;η,v) = ∫θ'η' + t⁻²(w'−θ)(v'−η)
//!             b(η,v;μ)   = ∫ s v μ
//!             S(θ,λ;η,μ) = Σ_T h_T⁴ (θ''' − sλ, η''' − sμ)_T
//!             ℓ(η,v)     = ∫ f v
//!             B_h(θ,w,λ;η,v,μ) = a(θ,w;η,v) − b(η,v;λ) − b(θ,w;μ) − α S(θ,λ;η,μ)
//!         ";
//!     }
//! }
//! ```
//!
//! ## Declarations (Rust tokens)
//! - `mod NAME on interval` or `on triangle`.
//! - `unknowns: NAME: ELEMENT, …` with elements `P0 P1 P2 P3 P1disc` (and `Hermite` on
//!   intervals, `Argyris` and `Morley` on triangles: their kernels take the cell's global
//!   vertex numbers too and apply the element's DOF transformation, docs/elements.md §5); `λ: P0 >= 0` (or `P1disc >= 0`) marks a multiplier constrained to be
//!   non-negative (`P1 >= 0` on a boundary part of `facets:`, or in a model without
//!   `system:`, where it is the nodal method's force density that only the estimator
//!   reads). `θ: [P1]^2` (on triangles) declares a vector field of two P1
//!   components (`[P1]²` cannot be written: `²` is not a Rust token); it is lowered to
//!   the scalar fields `θ_x` and `θ_y` (tests `η_x`, `η_y`), which is what the runtime
//!   sees, so its DOF map, assembly and kernels are those of scalar fields.
//! - `tests: …` one test function per unknown, in order: `η` goes with `θ`. A bilinear
//!   form over the same fields on both sides (`B_h(θ,w,λ;η,v,μ)`) must pair its
//!   arguments the same way (its i-th test function the i-th unknown's); otherwise
//!   `tests:` is likely out of order, and that is the one error reported.
//! - `params: …` runtime scalars (on triangles, two parameters `a_x`, `a_y` also
//!   make the constant vector `a`: with `n_c_x, n_c_y` declared, `n_c` in the forms is
//!   `(n_c_x, n_c_y)`; `d_x`, `d_y` are reserved, the ASCII ∂_x, ∂_y, so there is no
//!   vector `d`); `β > 0` declares one positive (the runtime's
//!   `Coefficients` refuses other values), which lets the forms divide by sums that are
//!   positive only then. `data: f, ψ: 0` functions of x (the number is the
//!   polynomial degree assumed for quadrature, default 2, at most 40; the degrees of
//!   the data in one term may sum to at most 40 too).
//! - `boundary: u = g` (optional) Dirichlet data: unknown `u` equals the data function
//!   `g` on the whole boundary (the runtime interpolates it at the boundary DOFs); a
//!   vector field is prescribed by component (`θ_x = g, θ_y = g`).
//! - `facets: Γ_C, Γ_N;` (optional, triangles) names boundary parts that the forms
//!   integrate over with `∫_Γ_C … ds`; the runtime says which edges a part holds (a
//!   Gmsh physical name or a generator's marker).
//! - `estimator: "…"` (optional) a residual a-posteriori estimator: lines
//!   `η_T² = h_T² ‖f + Δu + λ‖²` (a cell's squared indicator: weighted squared L² norms
//!   over the cell of residuals linear in the unknowns, plus data) and
//!   `η_E² = h_E ‖[[∇u·n]]‖²` (an interior edge's: of jumps `X⁺ − X⁻`, `n` the edge's
//!   unit normal; on intervals an interior node's jumps). It generates
//!   `NAME::estimator::cell` and `::edge` and the `Model` methods `cell_indicator` and
//!   `edge_indicator` (`estimator.rs`, `codegen/estimator.rs`, `codegen/estimator_interval.rs`).
//! - `forms: "…"` the forms text below. Greek names are fine; a crate using them may
//!   want `#![allow(mixed_script_confusables)]`.
//!
//! ## The forms text
//! One definition per line (a line that does not start with `name(…) =` continues the
//! previous one; `#` starts a comment):
//! - `a(θ,w;η,v) = …` a **bilinear** form: trial arguments, `;`, test arguments. Each term
//!   must hold exactly one function of each group; block (row, column) = (field of the test
//!   function, field of the trial function). `ℓ(η,v) = …` a **linear** form.
//! - `∫ integrand` (ASCII `int`) integrates over the domain, element by element; its
//!   integrand runs over the whole sum to its right, up to a `+`/`−` that starts another
//!   integral or form call. `∫[degree=N]` overrides the quadrature with the rule exact
//!   for degree N, `0 ≤ N ≤ 40` (`∫[degree=1]`: one-point reduced integration, the
//!   midpoint on intervals and the centroid on triangles).
//! - `∫_Γ integrand ds` (ASCII `int_Γ … ds`) integrates over the edges of the boundary
//!   part `Γ` declared under `facets:`, with the traces of the cell's functions (and
//!   their derivatives, from the cell next to the edge); `ds` closes the integrand.
//!   There, `n` is the outward unit normal (a vector: `v·n`, `(σ(u)·n)·n`) and `h_E`
//!   (or `h`) the edge's length; `n` anywhere else, `h_E` in a cell integral, `h_T` on
//!   an edge, or a missing `ds` are errors at the place. A named expression
//!   `σ_n(u) := (σ(u)·n)·n` may use `n` and `h_E`: they are checked where it is used.
//!   Facet terms give facet kernels: `S::on_Γ_C::matrix_v_x_u_x(x, edge, p, d)`
//!   integrates over local edge `edge` (joining local vertices `edge`, `edge + 1`) of
//!   the triangle `x` (`codegen/facet.rs`); they are not part of `Model::FORMS`' blocks,
//!   which hold the cell integrals only.
//! - `Σ_T w (X, Y)_T` (ASCII `sum_T`) is the sum over elements of weighted L² products.
//! - Derivatives on intervals: `w'`, `w''`, …, `w''''` (also `′ ″ ‴ ⁗`), of arguments
//!   or of linear combinations `(w'−θ)'`; taken element-wise. On triangles: `∇u`
//!   (`grad u`), a vector; `Δu` (`lap u`); sums and scalar multiples of vectors are
//!   vectors, and a product of two vectors (`∇u·∇v`, `grad u dot grad v`, or an L²
//!   product `(∇u, ∇v)_T`) is their dot product; an integrand must be a scalar. A derivative above the element's degree
//!   is zero and the term is dropped (`θ'''` of P2); P0 fields have no derivative.
//! - Shapes (docs/forms.md): expressions are scalars, vectors or matrices. A vector
//!   field `θ` is a vector, `θ_x`/`θ_y` its components; `∂_x`, `∂_y` (`d_x`, `d_y`) act
//!   entry by entry; `∇` of a vector is a matrix with the components in its rows;
//!   `ε(θ)` (`eps`) is ½(∇θ + ∇θᵀ); `div` of a vector is a scalar, of a matrix the
//!   vector of its rows' divergences; `tr` of a matrix; `I` the identity. A scalar
//!   scales anything; `u·v` of vectors is the dot product, `A:B` of matrices the double
//!   contraction, `A·v` the matrix–vector product; `[ … ]` groups like `( … )`. Every
//!   operator checks its shapes at compile time (`∇w − w`, `ε(w)` of a scalar, `A:v`,
//!   `div w` are errors at the expression), and an integrand must be a scalar.
//! - Products by juxtaposition, `·`, `⋅`, `×` or `*`; powers `t⁻²`, `h⁴` or `t^-2`,
//!   `h^4`, `t^(-2)`; minus `−` or `-`. `/` by a non-zero number, a parameter or a
//!   power of `h`, or by a sum of those that is positive for all allowed values:
//!   every term a positive number times even powers of parameters, parameters declared
//!   `> 0` and powers of `h`, and one term free of parameters only known to be ≥ 0.
//!   `6κ(1−ν)D/(t² + β h_T²)` with `β > 0` is such a quotient; `1/(t − β)` or
//!   `1/(ν + t)` with `ν` not declared positive are errors at the divisor.
//! - Names: declared symbols, `h` or `h_T` (element size); names written together that
//!   are declared symbols multiply (`sλ` = `s·λ`), and a power or primes after them
//!   belong to the last one, as in mathematics (`Et³` = `E·t³`, `αh_T²` = `α·h_T²`,
//!   `fv'` = `f·v'`); `(Et)³` needs its parentheses. A declared name is read as itself
//!   (with `params: s, t, st`, `st` is the parameter `st`); a run that splits into
//!   declared names in two ways (`stu`: `st·u` or `s·t·u`) is an error.
//! - `Cε(θ) := D[(1−ν)ε(θ) + ν tr ε(θ) I]` (with `:=`) names an expression of its
//!   arguments, of any shape, substituted where it is called (`∫ Cε(θ):ε(η)`,
//!   `div div Cε(η)`); it generates no code of its own.
//! - A form may call forms defined above it with other arguments:
//!   `B_h(…) = a(θ,w;η,v) − b(η,v;λ)` substitutes the arguments positionally (each must
//!   belong to the same field as the formal argument it replaces).
//!
//! ## What is generated
//! A module `NAME` with `Model` (implementing the runtime's `Model` trait), and per form
//! a module with one kernel per nonzero block: `a::matrix_η_θ(x, p, d) -> [[f64; 3]; 3]`
//! (rows η, columns θ) and `ℓ::vector_v(x, p, d) -> [f64; 3]`. Constant-coefficient
//! terms are integrated exactly at compile time; data terms use quadrature rules
//! exact for the term's degree (data counted with their declared degree):
//! Gauss–Legendre on intervals, collapsed Gauss rules on triangles.
//!
//! ### Typed handles
//! Beside the kernels, four modules of constants name everything the model declares,
//! so that Rust code refers to them by a checked name instead of a string:
//! - `NAME::forms::B_h: FormId<NAME::Model>`, one per form;
//! - `NAME::fields::θ`, `NAME::fields::η: FieldId<NAME::Model>`, one per unknown and
//!   one per test function (a test function names its unknown's field);
//! - `NAME::params::α: ParamId<NAME::Model>` and `NAME::data::f: DataId<NAME::Model>`.
//!
//! A misspelled handle is a compile error, and since each handle carries its model's
//! type, a handle of one model passed where another model is expected does not compile
//! either. The runtime's functions that take one form, field, parameter or data name
//! accept a handle or a string (scene files name things by string; lists of names, such
//! as `solve_obstacle`'s clamped fields, take strings): `Model::form(NAME::forms::B_h)`
//! and `Model::form("B_h")`
//! give the same index; `Coefficients::from_ids(&[(NAME::params::α, 0.1)], &[(NAME::data::f,
//! &f)])` is the handle form of `Coefficients::new::<NAME::Model>(&[("α", 0.1)], &[("f",
//! &f)])`. (The same design as serde's derives: the generated code exposes plain items
//! whose types carry the information, and the library's functions are generic over a
//! small trait — `IntoFormIndex`, `IntoFieldIndex`, `IntoParamIndex`, `IntoDataIndex`.)
//!
//! Because of this, a form's name must be a Rust identifier that is not a keyword and
//! not one of the generated items `Model`, `PARAMS`, `DATA`, `forms`, `fields`,
//! `params`, `data`; other names (`a₁`, `fn`, `Model`) are compile errors at the name.
//! Greek and other Unicode letters are fine (`ℓ_S`), subscript digits are not (write
//! `a1` or `a_1`).
//!
//! ### How the code generator is organised
//! `codegen/mod.rs` is the driver: it writes the module, the `Model` impl, the form
//! modules and the handles, and asks the backend of the model's cell for each block
//! kernel. A backend (`codegen/interval.rs`, `codegen/triangle.rs`) implements the
//! `CellBackend` trait of `codegen/backend.rs`: the cell's geometry (`h`, `J`, `K =
//! J⁻¹`), its reference basis and quadrature rules, how physical derivatives are written
//! in reference ones, and the compile-time integration of constant-coefficient terms.
//! `codegen/emit.rs` holds what all cells share: the kernel's frame, the one emitter of
//! quadrature loops over data terms (grouped per data set and rule, with compile-time
//! tables of basis values), and the final entries. A new cell kind is a new
//! `CellBackend`; facet integrals would add a kernel kind with its own geometry and
//! rules on top of the same loop emitter.
//!
//! To read the generated code, build with `FEM_FORMS_DUMP_DIR=some/dir`: each model is
//! written there, formatted, as `NAME.rs` (touch the model file first if it is already
//! built, so that the macro runs again).
//!
//! ## Errors
//! Every mistake is a compile error at the token, or for the forms text at the string
//! literal with the line, the column and a caret in the message, plus a hint; errors in
//! several definitions are reported together. No input makes the macro panic (a
//! property test feeds it random texts): in particular
//! - a number or a product of constants that overflows or underflows `f64` is an error
//!   at the term;
//! - expressions nest at most 100 levels (parentheses, signs, ∇/Δ, integrals, the
//!   factors of one product, powers and primes); a sum has at most 10,000 terms
//!   (split longer ones into forms), `Δ` and `∂` powers go up to 8;
//! - exponents may build powers up to 1000 in all (`f^999999`, `t⁻²¹⁴⁷⁴⁸³⁶⁴⁸` or
//!   `((f^10)^10)^11` are errors at the power: the expansion multiplies bases out and
//!   adds exponents in integers);
//! - a call of an undefined form names it and lists the forms defined above;
//! - a name that differs from a declared one only by lookalike letters (Cyrillic `Т`,
//!   Greek `ν` for `v`) gets a hint naming the letters and their scripts.
//!
//! The dump (`FEM_FORMS_DUMP_DIR`) names the runtime `::fem_runtime` instead of the
//! macro-only `$crate`, so the file compiles on its own in a crate depending on it.

mod analysis;
mod codegen;
mod declaration;
mod derived;
mod diagnostic;
mod estimator;
mod lexer;
mod parser;
mod roles;
mod symbolic;

use analysis::{Field, Symbols, Vector};
use declaration::Declaration;
use fem_reference::ElementKind;
use proc_macro2::TokenStream;

/// Compiles a model declaration into element kernels (see the crate docs).
#[proc_macro]
pub fn model(input: proc_macro::TokenStream) -> proc_macro::TokenStream {
    expand(input.into()).into()
}

/// The macro on `proc_macro2` types: declaration → analysis → code, or compile errors.
fn expand(input: TokenStream) -> TokenStream {
    let declaration = match syn::parse2::<Declaration>(input) {
        Ok(d) => d,
        Err(e) => return e.to_compile_error(),
    };
    let mut errors = declaration.check();
    let symbols = symbols(&declaration);
    let text = declaration.forms.value();
    let (tokens, lex_errors) = lexer::tokenize(&text);
    let (definitions, parse_errors) = parser::parse_forms(&tokens);
    let (forms, analysis_errors) = analysis::analyse(&symbols, &definitions, &text);
    errors.extend(lex_errors);
    errors.extend(parse_errors);
    errors.extend(analysis_errors);
    if !errors.is_empty() {
        let span = declaration.forms.span();
        return errors
            .iter()
            .map(|e| e.to_compile_error(&text, span))
            .collect();
    }
    // Named expressions (`Cε(θ) := …`) were substituted where called: no code of their own.
    let all_forms = forms.clone();
    let forms: Vec<_> = forms.into_iter().filter(|f| f.value.is_none()).collect();
    let (roles, role_errors) = roles::resolve(&declaration, &symbols, &forms);
    if !role_errors.is_empty() {
        let span = declaration.forms.span();
        return role_errors
            .iter()
            .map(|e| e.to_compile_error(&text, span))
            .collect();
    }
    let derived = derived::derive(&symbols, &forms, &roles);
    let roles = roles::Roles {
        strong_form: derived.is_some(),
        ..roles
    };
    if let Some(derived) = &derived {
        let mut errors = derived::check_stabilization(&symbols, &forms, &roles, derived);
        errors.extend(derived::check_facet_stabilization(
            &symbols, &forms, &roles, derived,
        ));
        if !errors.is_empty() {
            let span = declaration.forms.span();
            return errors
                .iter()
                .map(|e| e.to_compile_error(&text, span))
                .collect();
        }
    }
    let estimator = match &declaration.estimator {
        None => None,
        Some(declaration::EstimatorDecl::Derived(span)) => match &derived {
            Some(derived) if derived.boundary_terms => {
                return syn::Error::new(
                    *span,
                    "the estimator cannot be derived: the forms integrate over boundary parts (a load, a Robin term or a multiplier on `facets:`), whose boundary residuals a derived estimator does not have; write it as `estimator: \"η_T² = …  η_Γ² = …\";`",
                )
                .to_compile_error()
            }
            Some(derived) => Some(derived::residual_estimator(
                &symbols,
                &forms,
                &roles,
                derived,
                diagnostic::Loc {
                    line: 1,
                    column: 1,
                    len: 1,
                },
            )),
            None => {
                return syn::Error::new(
                    *span,
                    "the estimator cannot be derived: it needs `energy: a, ℓ;` with constant coefficients in `a` on the cells, no derivative of data in `ℓ`, and `constraint: b, G;` for a model with a multiplier; write it as `estimator: \"η_T² = …\";`",
                )
                .to_compile_error()
            }
        },
        Some(declaration::EstimatorDecl::Text(literal)) => {
            let text = literal.value();
            let (tokens, mut errors) = lexer::tokenize(&text);
            let (estimator, more) = estimator::analyse(&tokens, &text, &symbols, &all_forms);
            errors.extend(more);
            if let (true, Some(derived)) = (errors.is_empty(), &derived) {
                errors.extend(derived::check_estimator(&symbols, &roles, derived, &estimator));
            }
            if !errors.is_empty() {
                let span = literal.span();
                return errors
                    .iter()
                    .map(|e| e.to_compile_error_in(&text, span, "estimator"))
                    .collect();
            }
            Some(estimator)
        }
    };
    let estimator = estimator.map(|mut estimator| {
        if let Some(derived) = &derived {
            derived::natural_terms(&symbols, &roles, derived, &mut estimator);
        }
        estimator
    });
    let code = codegen::generate(&declaration, &symbols, &forms, &roles, estimator.as_ref());
    if let Ok(dir) = std::env::var("FEM_FORMS_DUMP_DIR") {
        dump(&dir, &declaration.name.to_string(), &code);
    }
    code
}

/// The names the declaration gives, with each vector field lowered to scalar fields
/// of its components (`θ: [P1]^2` → `θ_x`, `θ_y`, tests `η_x`, `η_y`): the runtime sees
/// only scalar fields, so its DOF map, assembly and kernels need no change.
fn symbols(declaration: &Declaration) -> Symbols {
    let mut fields = Vec::new();
    let mut vectors = Vec::new();
    let dimension = declaration.cell.map_or(1, |c| c.dimension());
    for (k, u) in declaration.unknowns.iter().enumerate() {
        let name = u.name.to_string();
        let test_name = declaration
            .tests
            .get(k)
            .map_or_else(|| format!("{name}_test"), |t| t.to_string());
        // An unknown element is reported by `check`; P1 lets the analysis go on.
        let element = u.element.unwrap_or(ElementKind::P1);
        if u.vector.is_none() {
            fields.push(Field {
                name,
                test_name,
                element,
                nonnegative: u.nonnegative,
                component: None,
            });
            continue;
        }
        // A wrong component count (or a vector on an interval) is reported by `check`;
        // the analysis goes on with one component per coordinate, so that every
        // vector and matrix it builds has the cell's dimension.
        let n = dimension;
        let trial = declaration::component_names(&name, n);
        let test = declaration::component_names(&test_name, n);
        for (axis, (name, test_name)) in trial.into_iter().zip(test).enumerate() {
            fields.push(Field {
                name,
                test_name,
                element,
                nonnegative: false,
                component: Some((vectors.len(), axis)),
            });
        }
        vectors.push(Vector {
            name,
            test_name,
            first_field: fields.len() - n,
            components: n,
        });
    }
    Symbols {
        fields,
        vectors,
        params: declaration.params.iter().map(|p| p.to_string()).collect(),
        positive: declaration.positive.clone(),
        data: declaration
            .data
            .iter()
            .map(|d| (d.name.to_string(), d.degree))
            .collect(),
        dimension,
        facets: declaration.facets.iter().map(|f| f.to_string()).collect(),
    }
}

/// The generated code as a file that compiles on its own: formatted, and with the
/// runtime named `::fem_runtime` where the macro was given `$crate` (a path only
/// meaningful inside a `macro_rules!` expansion).
fn dump_text(code: &TokenStream) -> String {
    let text = match syn::parse2::<syn::File>(code.clone()) {
        Ok(file) => prettyplease::unparse(&file),
        Err(_) => code.to_string(),
    };
    standalone(&text)
}

/// `$crate` (which `fem_runtime::model!` passes, and which only means something inside
/// a macro expansion) replaced by the runtime's crate name.
fn standalone(text: &str) -> String {
    text.replace("$crate", "::fem_runtime")
}

fn dump(dir: &str, name: &str, code: &TokenStream) {
    let text = dump_text(code);
    let path = std::path::Path::new(dir).join(format!("{name}.rs"));
    // Dumping is a debugging aid: failing to write must not fail the build.
    let _ = std::fs::create_dir_all(dir).and_then(|_| std::fs::write(path, text));
}

#[cfg(test)]
mod tests;

#[cfg(test)]
mod shape_tests;
