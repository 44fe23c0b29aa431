//! Kirchhoff plate bending (docs/mathematics.md §9) on the C¹
//! Argyris quintic and on the non-conforming Morley quadratic: the bending form
//! `a(w;v) = ∫ D[(1−ν) ∇∇w:∇∇v + ν Δw Δv]` (that is `∫ M(w):K(v)` with
//! `K(w) = −∇∇w`, `M(w) = D[(1−ν)K(w) + ν tr K(w) I]`) and the load `ℓ(v) = ∫ f v`.
//! The first two exist to test the elements' wiring (issue 13); `kirchhoff_argyris_p0` is
//! the obstacle problem.

/// One plate model per element: the forms are the same text.
macro_rules! kirchhoff_model {
    ($(#[$doc:meta])* $name:ident, w: $w:ident) => {
        fem_runtime::model! {
            $(#[$doc])*
            pub mod $name on triangle {
                unknowns: w: $w;
                tests: v;
                params: D, ν;
                data: f: 0;
                forms: "
                    a(w;v) = ∫ D[(1−ν) ∇∇w:∇∇v + ν Δw Δv]
                    ℓ(v)   = ∫ f v
                ";
            }
        }
    };
}

kirchhoff_model! {
    /// Kirchhoff plate bending on the Argyris element (P5, C¹, 21 DOFs per cell).
    kirchhoff_argyris, w: Argyris
}

kirchhoff_model! {
    /// Kirchhoff plate bending on the Morley element (P2, non-conforming, 6 DOFs per cell).
    kirchhoff_morley, w: Morley
}

fem_runtime::model! {
    /// Kirchhoff plate obstacle problem on Argyris–P0 (docs/mathematics.md §9, frame §1): deflection
    /// w ∈ Argyris, contact multiplier λ ∈ P0, λ ≥ 0, obstacle side `s = ±1`
    /// (`s·w ≥ s·ψ`: +1 an obstacle below, −1 one above), `DΔ²w − sλ = f`, stabilized by
    /// `S_h = Σ_T h_T⁴ (DΔ²w − sλ, DΔ²v − sμ)_T` (`Δ²` written `ΔΔ`). `boundary: w = g`
    /// is the simple support with `g = 0` (the runtime fixes the value and the derivatives
    /// it implies along the edges, `DirichletPart::plate_dofs`); α: stable for
    /// `0 < α < 1/C_I`.
    pub mod kirchhoff_argyris_p0 on triangle {
        unknowns: w: Argyris, λ: P0 >= 0;
        tests: v, μ;
        params: D > 0, ν, α, s;
        data: f, ψ, g;
        boundary: w = g;
        forms: "
            a(w;v)       = ∫ D[(1−ν) ∇∇w:∇∇v + ν Δw Δv]
            b(v;μ)       = ∫ s v μ
            S(w,λ;v,μ)   = Σ_T h_T⁴ (D ΔΔw − sλ, D ΔΔv − sμ)_T
            ℓ(v)         = ∫ f v
            ℓ_S(v,μ)     = Σ_T h_T⁴ (f, D ΔΔv − sμ)_T
            G(μ)         = ∫ s ψ μ
            B_h(w,λ;v,μ) = a(w;v) − b(v;λ) − b(w;μ) − α S(w,λ;v,μ)
            L_h(v,μ)     = ℓ(v) − G(μ) − α ℓ_S(v,μ)
        ";
    }
}
