//! Euler–Bernoulli beam over a rigid obstacle (docs/mathematics.md §4): deflection w in C¹
//! Hermite cubics, contact multiplier λ ∈ P0, obstacle side s = ±1.
//!
//! `w'''' ≡ 0` for cubics, so `S_h = Σ h⁴ s²(λ, μ)`; α ≤ 1e-2 keeps the obstacle shift
//! `α h⁴ |f|` negligible.
//!
//! The estimator (`../shared/MODELS.md` §8): the cell residual of the contact equation
//! and, at interior nodes, the jumps of the shear force `w'''` and the moment `w''`
//! (h the mean length of the two neighbouring cells).

fem_runtime::model! {
    /// Euler–Bernoulli beam obstacle problem, w ∈ Hermite cubics, λ ∈ P0.
    pub mod bernoulli on interval {
        unknowns: w: Hermite, λ: P0 >= 0;
        tests: v, μ;
        params: α, s;
        data: f, ψ;
        forms: "
            a(w;v)     = ∫ w''v''
            b(v;μ)     = ∫ s v μ
            S(w,λ;v,μ) = Σ_T h_T⁴ (w'''' − sλ, v'''' − sμ)_T
            ℓ(v)       = ∫ f v
            ℓ_S(v,μ)   = Σ_T h_T⁴ (f, v'''' − sμ)_T
            g(μ)       = ∫ s ψ μ
            B_h(w,λ;v,μ) = a(w;v) − b(v;λ) − b(w;μ) − α S(w,λ;v,μ)
            L_h(v,μ)     = ℓ(v) − g(μ) − α ℓ_S(v,μ)
        ";
        system:        B_h, L_h;
        energy:        a, ℓ;
        stabilization: α S against a;
        side:          s;
        obstacle:      w >= ψ;
        estimator:     "
            η_T² = h_T⁴/81 ‖f + sλ − w''''‖²
            η_E² = h_E³/27 ‖[[w''']]‖² + h_E/3 ‖[[w'']]‖²
        ";
    }
}
