//! A Kirchhoff plate on a Winkler foundation (docs/mathematics.md, ../MODELS.md §10): the
//! foundation's modulus k adds `k w v` to the bending form, so `𝒜w = DΔ²w + k w` and the
//! contact equation's residual is `DΔ²w + k w − sλ − f`, which the stabilization
//! penalizes on each cell. Argyris (C¹) deflection, P0 multiplier. Its estimator is the
//! Kirchhoff plate's (docs/adaptivity.md) with the foundation's `k w` in the cell
//! residual; the macro checks both against the strong form it derives from `a`.

fem_runtime::model! {
    /// Kirchhoff plate on a Winkler foundation with an obstacle, Argyris–P0, stabilized.
    pub mod winkler_argyris_p0 on triangle {
        unknowns: w: Argyris, λ: P0 >= 0;
        tests: v, μ;
        params: D > 0, ν, k, α, s;
        data: f, ψ, g;
        boundary: w = g;
        forms: "
            K(w)         := −∇∇w
            M(w)         := D[(1−ν)K(w) + ν tr K(w) I]
            a(w;v)       = ∫ M(w):K(v) + k w v
            b(v;μ)       = ∫ s v μ
            S(w,λ;v,μ)   = Σ_T h_T⁴ (D Δ²w + k w − sλ, D Δ²v + k v − sμ)_T
            ℓ(v)         = ∫ f v
            ℓ_S(v,μ)     = Σ_T h_T⁴ (f, D Δ²v + k v − sμ)_T
            G(μ)         = ∫ s ψ μ
            B_h(w,λ;v,μ) = a(w;v) − b(v;λ) − b(w;μ) − α S(w,λ;v,μ)
            L_h(v,μ)     = ℓ(v) − G(μ) − α ℓ_S(v,μ)
        ";
        system:        B_h, L_h;
        energy:        a, ℓ;
        stabilization: α S against a;
        side:          s;
        obstacle:      w >= ψ;
        estimator: "
            η_T² = h_T⁴/(625 D) ‖f − D Δ²w − k w + sλ‖²
            η_E² = h_E³/(125 D) ‖[[(div M(w))·n + τ·∇((M(w)·n)·τ)]]‖² + h_E/(5 D) ‖[[(M(w)·n)·n]]‖²
        ";
    }
}
