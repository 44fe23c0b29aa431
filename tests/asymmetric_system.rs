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
    ℓ_S(v,μ)   = Σ_T h_T² (−f, v'' + sμ)_T
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
    ℓ_S(v,μ)   = Σ_T h_T² (−f, v'' + sμ)_T
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
    ℓ_S(v,μ)   = Σ_T h_T² (−f, v'' + sμ)_T
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
    ℓ_S(v,μ)   = Σ_T h_T² (−f, v'' + sμ)_T
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

/// Signorini's forms with the contact couplings (boundary integrals over Γ_C) of
/// different signs: the cell blocks are symmetric, so only the facet blocks show it.
/// (The flipped model's stabilization follows its flipped coupling, `λ − σ_n(u)`, so
/// that it passes the macro's check of the boundary equation and reaches the runtime's
/// symmetry check.)
macro_rules! contact_model {
    ($name:ident, $system:literal) => {
        fem_runtime::model! {
            /// An elastic body on a rigid foundation, u ∈ `[P1]²`, λ ∈ P0 on Γ_C.
            pub mod $name on triangle {
                unknowns: u: [P1]^2, λ: P0 >= 0;
                tests: v, μ;
                params: μ_L > 0, λ_L, α, n_c_x, n_c_y;
                data: q: 2, g: 1;
                facets: Γ_C, Γ_N;
                forms: $system;
                unit: n_c;
            }
        }
    };
}

contact_model!(
    contact_symmetric,
    "
    σ(u)         := 2μ_L ε(u) + λ_L tr ε(u) I
    σ_n(u)       := (σ(u)·n)·n_c
    a(u;v)       = ∫ σ(u):ε(v)
    b(v;μ)       = −∫_Γ_C μ v·n_c ds
    S(u,λ;v,μ)   = ∫_Γ_C h_E (λ + σ_n(u))(μ + σ_n(v)) ds
    ℓ(v)         = −∫_Γ_N q v·n ds
    G(μ)         = −∫_Γ_C g μ ds
    B_h(u,λ;v,μ) = a(u;v) − b(v;λ) − b(u;μ) − α S(u,λ;v,μ)
    L_h(v,μ)     = ℓ(v) − G(μ)
    "
);

contact_model!(
    contact_flipped,
    "
    σ(u)         := 2μ_L ε(u) + λ_L tr ε(u) I
    σ_n(u)       := (σ(u)·n)·n_c
    a(u;v)       = ∫ σ(u):ε(v)
    b(v;μ)       = −∫_Γ_C μ v·n_c ds
    S(u,λ;v,μ)   = ∫_Γ_C h_E (λ − σ_n(u))(μ + σ_n(v)) ds
    ℓ(v)         = −∫_Γ_N q v·n ds
    G(μ)         = −∫_Γ_C g μ ds
    B_h(u,λ;v,μ) = a(u;v) + b(v;λ) − b(u;μ) − α S(u,λ;v,μ)
    L_h(v,μ)     = ℓ(v) − G(μ)
    "
);

/// The symmetry check reaches the boundary integrals: the contact form with couplings
/// of different signs is refused naming the part, the one with equal signs discretizes.
#[test]
fn a_contact_form_with_couplings_of_different_signs_is_refused() {
    use fem_runtime::mesh::triangle::Diagonal;
    use fem_runtime::obstacle::boundary_multiplier::discretize_on_parts;
    use fem_runtime::TriangleMesh;
    let mesh = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 4, 4, Diagonal::Alternating).unwrap();
    let pressure = |_: &[f64]| 1.0;
    let gap = |_: &[f64]| 0.0;
    let params = [
        ("μ_L", 1.0),
        ("λ_L", 1.0),
        ("α", 0.01),
        ("n_c_x", 0.0),
        ("n_c_y", -1.0),
    ];
    let data: [(&str, &fem_runtime::DataFn); 2] = [("q", &pressure), ("g", &gap)];
    let parts: [(&str, &[u32]); 2] = [("Γ_C", &[1]), ("Γ_N", &[3])];
    let c = Coefficients::new::<contact_symmetric::Model>(&params, &data).unwrap();
    discretize_on_parts::<contact_symmetric::Model, _, &str>(&mesh, &c, &parts, &[]).unwrap();
    let c = Coefficients::new::<contact_flipped::Model>(&params, &data).unwrap();
    let Err(e) = discretize_on_parts::<contact_flipped::Model, _, &str>(&mesh, &c, &parts, &[])
    else {
        panic!("the asymmetric contact B_h was discretized");
    };
    let e = e.to_string();
    assert!(
        e.contains("`B_h` of model `contact_flipped` is not symmetric")
            && e.contains("boundary integral over `Γ_C`"),
        "{e}"
    );
}

fem_runtime::model! {
    /// A string over an obstacle in a wind β (convection), u ∈ P1, λ ∈ P0.
    pub mod wind on interval {
        unknowns: u: P1, λ: P0 >= 0;
        tests: v, μ;
        params: α, s;
        data: f, ψ, β;
        forms: "
    a(u;v)     = ∫ u'v' + β u' v
    b(v;μ)     = ∫ s v μ
    S(u,λ;v,μ) = Σ_T h_T² (u'' + sλ, v'' + sμ)_T
    ℓ(v)       = ∫ f v
    ℓ_S(v,μ)   = Σ_T h_T² (−f, v'' + sμ)_T
    g(μ)       = ∫ s ψ μ
    B_h(u,λ;v,μ) = a(u;v) − b(v;λ) − b(u;μ) − α S(u,λ;v,μ)
    L_h(v,μ)     = ℓ(v) − g(μ) − α ℓ_S(v,μ)
    ";
    }
}

/// A tester's convection `β u'v` with a wind that vanishes on the left half, cell 0
/// included: the check compared cell 0 alone and the string was solved (KKT residual
/// 7e-17) as if the solver could take a non-symmetric A. Every cell is compared now,
/// and the refusal names one on the right; without wind the model solves. A wind that
/// is NaN on a cell is named as non-finite data, not as an asymmetry.
#[test]
fn an_asymmetry_away_from_the_first_cell_is_refused() {
    let mesh = IntervalMesh::uniform(-1.0, 1.0, 32).unwrap();
    let load = |_: &[f64]| -4.0;
    let obstacle = |_: &[f64]| -0.1;
    let params = [("α", 0.1), ("s", 1.0)];
    let half = |x: &[f64]| 20.0 * x[0].max(0.0);
    let calm = |_: &[f64]| 0.0;
    let nan = |x: &[f64]| (x[0] + 0.9).sqrt();
    let solve = |wind: &fem_runtime::DataFn| {
        let data: [(&str, &fem_runtime::DataFn); 3] = [("f", &load), ("ψ", &obstacle), ("β", wind)];
        let c = Coefficients::new::<wind::Model>(&params, &data).unwrap();
        solve_obstacle::<wind::Model>(&mesh, &c, &["u"], ObstacleOptions::default())
    };
    assert!(solve(&calm).is_ok());
    let Err(e) = solve(&half) else {
        panic!("the convection was solved")
    };
    let e = e.to_string();
    assert!(
        e.contains("not symmetric") && e.contains("on cell") && !e.contains("on cell 0 "),
        "{e}"
    );
    let Err(e) = solve(&nan) else {
        panic!("NaN data were solved")
    };
    assert!(
        matches!(e, fem_runtime::Error::NonFinite { cell: 0, .. }),
        "{e}"
    );
}

contact_model!(
    contact_true_normal,
    "
    σ(u)         := 2μ_L ε(u) + λ_L tr ε(u) I
    σ_n(u)       := (σ(u)·n)·n_c
    a(u;v)       = ∫ σ(u):ε(v)
    b(v;μ)       = −∫_Γ_C μ v·n_c ds
    bn(v;μ)      = −∫_Γ_C μ v·n ds
    S(u,λ;v,μ)   = ∫_Γ_C h_E (λ + σ_n(u))(μ + σ_n(v)) ds
    ℓ(v)         = −∫_Γ_N q v·n ds
    G(μ)         = −∫_Γ_C g μ ds
    B_h(u,λ;v,μ) = a(u;v) − b(v;λ) − bn(u;μ) − α S(u,λ;v,μ)
    L_h(v,μ)     = ℓ(v) − G(μ)
    "
);

/// Couplings written with the normal n on one side and n_c on the other are symmetric
/// on Γ_C, where n = n_c: a tester's model was refused because the facet blocks were
/// compared on the first edge of cell 0, an interior edge. They are compared on the
/// part's own edges now.
#[test]
fn facet_blocks_are_compared_on_their_own_edges() {
    use fem_runtime::mesh::triangle::Diagonal;
    use fem_runtime::obstacle::boundary_multiplier::discretize_on_parts;
    use fem_runtime::TriangleMesh;
    let mesh = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 4, 4, Diagonal::Alternating).unwrap();
    let pressure = |_: &[f64]| 1.0;
    let gap = |_: &[f64]| 0.0;
    let params = [
        ("μ_L", 1.0),
        ("λ_L", 1.0),
        ("α", 0.01),
        ("n_c_x", 0.0),
        ("n_c_y", -1.0),
    ];
    let data: [(&str, &fem_runtime::DataFn); 2] = [("q", &pressure), ("g", &gap)];
    let c = Coefficients::new::<contact_true_normal::Model>(&params, &data).unwrap();
    // the bottom (marker 1), where n = n_c = (0, −1)
    let parts: [(&str, &[u32]); 2] = [("Γ_C", &[1]), ("Γ_N", &[3])];
    discretize_on_parts::<contact_true_normal::Model, _, &str>(&mesh, &c, &parts, &[]).unwrap();
    // the right side (marker 2), where n = (1, 0) ≠ n_c: not symmetric there
    let parts: [(&str, &[u32]); 2] = [("Γ_C", &[2]), ("Γ_N", &[3])];
    let Err(e) = discretize_on_parts::<contact_true_normal::Model, _, &str>(&mesh, &c, &parts, &[])
    else {
        panic!("n ≠ n_c on Γ_C was accepted")
    };
    assert!(
        e.to_string().contains("boundary integral over `Γ_C`"),
        "{e}"
    );
}
