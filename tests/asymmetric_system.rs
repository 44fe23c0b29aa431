//! A system form `B_h` whose couplings differ in sign: a tester's `− b(v;λ) + b(u;μ)`
//! compiled and solved to a string 0.93 through its obstacle with a KKT residual of
//! 1e-16, since the solver reads B from the multiplier rows alone. It is refused, naming
//! the blocks; the same model with matching signs solves.

#![allow(confusable_idents, mixed_script_confusables, uncommon_codepoints)]

use fem_runtime::obstacle::{solve_obstacle, ObstacleOptions};
use fem_runtime::{Coefficients, IntervalMesh};

macro_rules! string_model {
    ($name:ident, $system:literal) => {
        fem_runtime::model! {
            /// A string over an obstacle, u ∈ P1, λ ∈ P0.
            pub mod $name on interval {
                unknowns: u: P1, λ: P0 >= 0;
                tests: v, μ;
                params: α, s;
                data: f, ψ;
                forms: $system;
            }
        }
    };
}

string_model!(
    symmetric,
    "
    a(u;v)     = ∫ u'v'
    b(v;μ)     = ∫ s v μ
    S(u,λ;v,μ) = Σ_T h_T² (u'' + sλ, v'' + sμ)_T
    ℓ(v)       = ∫ f v
    ℓ_S(v,μ)   = Σ_T h_T² (f, v'' + sμ)_T
    g(μ)       = ∫ s ψ μ
    B_h(u,λ;v,μ) = a(u;v) − b(v;λ) − b(u;μ) − α S(u,λ;v,μ)
    L_h(v,μ)     = ℓ(v) − g(μ) − α ℓ_S(v,μ)
    "
);

string_model!(
    flipped,
    "
    a(u;v)     = ∫ u'v'
    b(v;μ)     = ∫ s v μ
    S(u,λ;v,μ) = Σ_T h_T² (u'' + sλ, v'' + sμ)_T
    ℓ(v)       = ∫ f v
    ℓ_S(v,μ)   = Σ_T h_T² (f, v'' + sμ)_T
    g(μ)       = ∫ s ψ μ
    B_h(u,λ;v,μ) = a(u;v) − b(v;λ) + b(u;μ) − α S(u,λ;v,μ)
    L_h(v,μ)     = ℓ(v) − g(μ) − α ℓ_S(v,μ)
    "
);

string_model!(
    added_stabilization,
    "
    a(u;v)     = ∫ u'v'
    b(v;μ)     = ∫ s v μ
    S(u,λ;v,μ) = Σ_T h_T² (u'' + sλ, v'' + sμ)_T
    ℓ(v)       = ∫ f v
    ℓ_S(v,μ)   = Σ_T h_T² (f, v'' + sμ)_T
    g(μ)       = ∫ s ψ μ
    B_h(u,λ;v,μ) = a(u;v) − b(v;λ) − b(u;μ) + α S(u,λ;v,μ)
    L_h(v,μ)     = ℓ(v) − g(μ) + α ℓ_S(v,μ)
    "
);

/// The stabilization added instead of subtracted makes `C = −αS` negative: a tester was
/// told "α ≤ 0 gives the plain mixed method" with α = 0.04. The error now says which
/// sign the system form needs.
#[test]
fn a_stabilization_of_the_wrong_sign_is_named() {
    let mesh = IntervalMesh::uniform(-1.0, 1.0, 32).unwrap();
    let load = |_: &[f64]| -4.0;
    let obstacle = |_: &[f64]| -0.1;
    let data: [(&str, &fem_runtime::DataFn); 2] = [("f", &load), ("ψ", &obstacle)];
    let c =
        Coefficients::new::<added_stabilization::Model>(&[("α", 0.04), ("s", 1.0)], &data).unwrap();
    let Err(e) =
        solve_obstacle::<added_stabilization::Model>(&mesh, &c, &["u"], ObstacleOptions::default())
    else {
        panic!("B_h = … + α S was solved");
    };
    let e = e.to_string();
    assert!(
        e.contains("must be positive") && e.contains("subtracts the stabilization"),
        "{e}"
    );
}

string_model!(
    mixed_rules,
    "
    a(u;v)     = ∫ u'v'
    S(u,λ;v,μ) = Σ_T h_T² (u'' + sλ, v'' + sμ)_T
    ℓ(v)       = ∫ f v
    ℓ_S(v,μ)   = Σ_T h_T² (f, v'' + sμ)_T
    g(μ)       = ∫ s ψ μ
    B_h(u,λ;v,μ) = a(u;v) − ∫[degree=1] s v λ − ∫ s u μ − α S(u,λ;v,μ)
    L_h(v,μ)     = ℓ(v) − g(μ) − α ℓ_S(v,μ)
    "
);

/// The re-test of the symmetry check: equal couplings written with different rules
/// (`∫[degree=1]` beside the exact one, both exact for P1·P0) were refused when the
/// check compared symbols; it compares the element matrices now, and this model solves
/// to the same string as the plain one.
#[test]
fn equal_couplings_written_differently_are_symmetric() {
    let mesh = IntervalMesh::uniform(-1.0, 1.0, 32).unwrap();
    let load = |_: &[f64]| -4.0;
    let obstacle = |_: &[f64]| -0.1;
    let params = [("α", 0.1), ("s", 1.0)];
    let data: [(&str, &fem_runtime::DataFn); 2] = [("f", &load), ("ψ", &obstacle)];
    let c = Coefficients::new::<mixed_rules::Model>(&params, &data).unwrap();
    let mixed = solve_obstacle::<mixed_rules::Model>(&mesh, &c, &["u"], ObstacleOptions::default())
        .unwrap();
    let c = Coefficients::new::<symmetric::Model>(&params, &data).unwrap();
    let plain =
        solve_obstacle::<symmetric::Model>(&mesh, &c, &["u"], ObstacleOptions::default()).unwrap();
    assert!((mixed.total_contact_force() - plain.total_contact_force()).abs() < 1e-12);
}

#[test]
fn a_system_form_with_couplings_of_different_signs_is_refused() {
    let mesh = IntervalMesh::uniform(-1.0, 1.0, 32).unwrap();
    let load = |_: &[f64]| -4.0;
    let obstacle = |_: &[f64]| -0.1;
    let params = [("α", 0.1), ("s", 1.0)];
    let data: [(&str, &fem_runtime::DataFn); 2] = [("f", &load), ("ψ", &obstacle)];
    let c = Coefficients::new::<symmetric::Model>(&params, &data).unwrap();
    let solution =
        solve_obstacle::<symmetric::Model>(&mesh, &c, &["u"], ObstacleOptions::default()).unwrap();
    // the string lies on the obstacle in the middle, crossing it by the O(h²) the
    // cell-wise constraint allows
    let u = solution.view(0);
    let lowest = (0..=64)
        .map(|i| u.at(-1.0 + i as f64 / 32.0, 0).unwrap())
        .fold(f64::INFINITY, f64::min);
    assert!((lowest + 0.1).abs() < 1e-2, "{lowest}");
    let c = Coefficients::new::<flipped::Model>(&params, &data).unwrap();
    let Err(e) = solve_obstacle::<flipped::Model>(&mesh, &c, &["u"], ObstacleOptions::default())
    else {
        panic!("the asymmetric B_h was solved");
    };
    let e = e.to_string();
    assert!(
        e.contains("`B_h` of model `flipped` is not symmetric") && e.contains("`λ`"),
        "{e}"
    );
}
