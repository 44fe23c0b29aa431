//! Signorini contact (docs/mathematics.md §7, MODELS.md §7): a linear elastic body
//! (plane strain or plane stress: the Lamé parameters `μ_L`, `λ_L` are given) on a rigid
//! foundation, frictionless, with a multiplier λ ≥ 0 on the potential contact boundary
//! `Γ_C`, the contact pressure `λ = −σ_n(u)`.
//!
//! In the frame of §1: `s = −1`, `Bv = v·n`, `ψ = g` (the initial gap along n, the
//! contact direction taken as the body's outward normal), `b(v,μ) = −(μ, v·n)_{Γ_C}`, the
//! residual of the contact equation `λ + σ_n(u)` with `σ_n(v) = n·σ(v)n` traced from the
//! cell next to the edge, and no data term in the stabilization:
//! `S_h = Σ_{E⊂Γ_C} h_E (λ + σ_n(u), μ + σ_n(v))_E`, `B_h = a − b − bᵀ − α S_h`.
//! The load is a pressure `q` (force per length, positive pushing in) on the boundary
//! part `Γ_N`: `ℓ(v) = −(q, v·n)_{Γ_N}`.
//!
//! The multiplier is declared as a P0 field so that the facet kernels see its trace (1
//! on the edge); it lives on the edges of `Γ_C` only: the solver gives it one DOF per
//! contact edge (`fem_models::signorini` solver below).

/// One elasticity–contact model per displacement element: the forms are one text.
macro_rules! signorini_model {
    ($(#[$doc:meta])* $name:ident, $element:ident) => {
        fem_runtime::model! {
            $(#[$doc])*
            pub mod $name on triangle {
                unknowns: u: [$element]^2, λ: P0 >= 0;
                tests: v, μ;
                params: μ_L > 0, λ_L, α;
                data: q: 0, g: 1;
                facets: Γ_C, Γ_N;
                forms: "
                    σ(u)             := 2μ_L ε(u) + λ_L tr ε(u) I
                    σ_n(u)           := (σ(u)·n)·n
                    a(u;v)           = ∫ σ(u):ε(v)
                    b(v;μ)           = −∫_Γ_C μ v·n ds
                    S(u,λ;v,μ)       = ∫_Γ_C h_E (λ + σ_n(u))(μ + σ_n(v)) ds
                    ℓ(v)             = −∫_Γ_N q v·n ds
                    G(μ)             = −∫_Γ_C g μ ds
                    B_h(u,λ;v,μ)     = a(u;v) − b(v;λ) − b(u;μ) − α S(u,λ;v,μ)
                    L_h(v,μ)         = ℓ(v) − G(μ)
                ";
            }
        }
    };
}

signorini_model! {
    /// Signorini contact, u ∈ [P1]², λ ∈ P0 on the edges of Γ_C, stabilized (§7).
    signorini_p1, P1
}

signorini_model! {
    /// Signorini contact, u ∈ [P2]², λ ∈ P0 on the edges of Γ_C, stabilized (§7).
    signorini_p2, P2
}
