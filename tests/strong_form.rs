//! The strong form every shipped model's forms give by integration by parts
//! (`fem-forms-macro/src/derived.rs`, docs/adaptivity.md "Derived from `a`"): the macro
//! derives it and checks the model's cell stabilization and declared estimator against
//! it at compile time, so that these models compiling is the check passing. Here: the
//! derivation ran for each of them (a model where it could not would compile
//! unchecked). The refusals of wrong models are the macro's tests
//! (`fem-forms-macro/src/tests.rs`, `derived`).
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

use fem_forms::models::{
    bernoulli, kirchhoff, membrane, mindlin, signorini, timoshenko_p2, winkler,
};
use fem_forms::Model;

#[test]
fn every_shipped_model_with_an_estimator_or_a_cell_stabilization_is_checked() {
    let checked = [
        (
            "membrane P1–P0",
            membrane::membrane_p1_p0::Model::STRONG_FORM,
        ),
        (
            "membrane P2–P0",
            membrane::membrane_p2_p0::Model::STRONG_FORM,
        ),
        (
            "membrane P2–P1disc",
            membrane::membrane_p2_p1disc::Model::STRONG_FORM,
        ),
        (
            "Kirchhoff Argyris–P0",
            kirchhoff::kirchhoff_argyris_p0::Model::STRONG_FORM,
        ),
        (
            "Kirchhoff Argyris–P1disc",
            kirchhoff::kirchhoff_argyris_p1disc::Model::STRONG_FORM,
        ),
        (
            "Kirchhoff Morley–P0",
            kirchhoff::kirchhoff_morley_p0::Model::STRONG_FORM,
        ),
        (
            "Reissner–Mindlin Stenberg",
            mindlin::mindlin_stenberg::Model::STRONG_FORM,
        ),
        (
            "Reissner–Mindlin simply supported",
            mindlin::mindlin_simply_supported::Model::STRONG_FORM,
        ),
        (
            "Reissner–Mindlin plain P1",
            mindlin::mindlin_plain_p1::Model::STRONG_FORM,
        ),
        ("Timoshenko P2", timoshenko_p2::Model::STRONG_FORM),
        ("Euler–Bernoulli", bernoulli::Model::STRONG_FORM),
        (
            "Signorini P1–P0",
            signorini::signorini_p1::Model::STRONG_FORM,
        ),
        (
            "Signorini P2–P1",
            signorini::signorini_p2_p1::Model::STRONG_FORM,
        ),
        (
            "Winkler plate",
            winkler::winkler_argyris_p0::Model::STRONG_FORM,
        ),
    ];
    let unchecked: Vec<&str> = checked
        .iter()
        .filter(|(_, strong)| !strong)
        .map(|(name, _)| *name)
        .collect();
    assert!(unchecked.is_empty(), "not derived: {unchecked:?}");
}

fem_forms::model! {
    /// The shipped P2–P0 membrane with its estimator derived from `a`, `ℓ` and `b`
    /// instead of written.
    pub mod membrane_derived on triangle {
        unknowns: u: P2, λ: P0 >= 0;
        tests: v, μ;
        params: α;
        data: f, ψ, g;
        boundary: u = g;
        forms: "
            a(u;v)       = ∫ ∇u·∇v
            b(v;μ)       = ∫ v μ
            S(u,λ;v,μ)   = Σ_T h_T² (−Δu − λ, −Δv − μ)_T
            ℓ(v)         = ∫ f v
            ℓ_S(v,μ)     = Σ_T h_T² (f, −Δv − μ)_T
            G(μ)         = ∫ ψ μ
            B_h(u,λ;v,μ) = a(u;v) − b(v;λ) − b(u;μ) − α S(u,λ;v,μ)
            L_h(v,μ)     = ℓ(v) − G(μ) − α ℓ_S(v,μ)
        ";
        system:        B_h, L_h;
        energy:        a, ℓ;
        stabilization: α S against a;
        obstacle:      u >= ψ;
        estimator:     derived;
    }
}

/// The membrane's derived estimator (`h_T² ‖f + λ + Δu‖²`, `h_E ‖[[∇u·n]]‖²`) is the
/// declared one of the shipped model: on the radial membrane every cell's indicator
/// agrees to rounding.
#[test]
fn the_derived_membrane_estimator_is_the_declared_one() {
    use fem_forms::models::membrane_scenes::{radial_obstacle, radial_u};
    use fem_forms::problem::{Problem, Solved};
    use fem_forms::{DirichletPart, TriangleMesh};
    fn zero(_: &[f64]) -> f64 {
        0.0
    }
    fn solve<M: Model>() -> Solved<M, TriangleMesh> {
        let mesh = TriangleMesh::rectangle(-2.0, 2.0, -2.0, 2.0, 8, 8, fem_forms::Diagonal::Right)
            .unwrap();
        Problem::<M, TriangleMesh>::new(vec![mesh])
            .data("f", &zero)
            .data("ψ", &radial_obstacle)
            .data("g", &radial_u)
            .boundary_data(DirichletPart::All)
            .solve()
            .unwrap()
    }
    let derived = solve::<membrane_derived::Model>().estimate.unwrap();
    let declared = solve::<membrane::membrane_p2_p0::Model>().estimate.unwrap();
    assert!(derived.residual > 0.0);
    assert!((derived.residual - declared.residual).abs() <= 1e-12 * declared.residual);
    for (c, (a, b)) in derived
        .indicators
        .iter()
        .zip(&declared.indicators)
        .enumerate()
    {
        assert!(
            (a - b).abs() <= 1e-10 * b.abs().max(1e-14),
            "cell {c}: {a} against {b}"
        );
    }
}

/// The natural boundary terms each shipped model takes from its edge (node) terms
/// (`Model::NATURAL_FLUXES`, `(field, j)`: the flux of `v` for j = 0, of `∂_n v` for
/// j = 1): the membrane's `∂_n u`; the plate's `V_n` and `M_nn` (Morley's `[[∇w]]` is a
/// conformity jump, no flux, and its `V_n` vanishes); Reissner–Mindlin's `Cε(θ)n` by component and `q·n`;
/// elasticity's `σ(u)n` by component; the derived estimator's the declared one's.
#[test]
fn every_flux_of_an_edge_term_is_a_natural_boundary_term() {
    fn named<M: Model>() -> Vec<(&'static str, u8)> {
        M::NATURAL_FLUXES
            .iter()
            .map(|&(f, j)| (M::FIELDS[f].name, j))
            .collect()
    }
    let membrane = vec![("u", 0)];
    let plate = vec![("w", 0), ("w", 1)];
    assert_eq!(named::<membrane::membrane_p1_p0::Model>(), membrane);
    assert_eq!(named::<membrane::membrane_p1::Model>(), membrane);
    assert_eq!(named::<membrane_derived::Model>(), membrane);
    assert_eq!(named::<kirchhoff::kirchhoff_argyris_p0::Model>(), plate);
    // Morley's quadratics have V_n = D(∇Δw·n + ∂_s M_ns) ≡ 0 on each cell
    assert_eq!(
        named::<kirchhoff::kirchhoff_morley_p0::Model>(),
        vec![("w", 1)]
    );
    assert_eq!(named::<winkler::winkler_argyris_p0::Model>(), plate);
    assert_eq!(
        named::<mindlin::mindlin_stenberg::Model>(),
        vec![("θ_x", 0), ("θ_y", 0), ("w", 0)]
    );
    assert_eq!(
        named::<signorini::signorini_p1::Model>(),
        vec![("u_x", 0), ("u_y", 0)]
    );
    // on intervals the two ends: the beam's shear and moment, Timoshenko's θ' and shear
    assert_eq!(named::<bernoulli::Model>(), plate);
    assert_eq!(named::<timoshenko_p2::Model>(), vec![("θ", 0), ("w", 0)]);
    // the one-point shear pair has no strong form to match its terms with
    assert!(fem_forms::models::timoshenko_p1_reduced::Model::NATURAL_FLUXES.is_empty());
}

/// The energy order of each shipped model's constrained field (the `m` of `|w|_m` that
/// scales the violation term of the estimate): not the stabilization's order, which is 4
/// for Timoshenko's `θ''' − sλ` while its deflection's energy is `|w|₁`.
#[test]
fn the_constrained_fields_energy_orders() {
    assert_eq!(membrane::membrane_p1_p0::Model::CONSTRAINED_ORDER, 1);
    assert_eq!(membrane::membrane_p1::Model::CONSTRAINED_ORDER, 1);
    assert_eq!(bernoulli::Model::CONSTRAINED_ORDER, 2);
    assert_eq!(timoshenko_p2::Model::CONSTRAINED_ORDER, 1);
    assert_eq!(timoshenko_p2::Model::ORDER, 4);
    assert_eq!(
        fem_forms::models::timoshenko_p1_reduced::Model::CONSTRAINED_ORDER,
        1
    );
    assert_eq!(kirchhoff::kirchhoff_argyris_p0::Model::CONSTRAINED_ORDER, 2);
    assert_eq!(kirchhoff::kirchhoff_morley_p0::Model::CONSTRAINED_ORDER, 2);
    assert_eq!(mindlin::mindlin_stenberg::Model::CONSTRAINED_ORDER, 1);
    assert_eq!(winkler::winkler_argyris_p0::Model::CONSTRAINED_ORDER, 2);
}
