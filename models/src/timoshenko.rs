//! Timoshenko beam over a rigid obstacle (docs/mathematics.md §3): rotation θ, deflection w,
//! contact multiplier λ ≥ 0, thickness t, obstacle side s = ±1.
//!
//! The contact equation `θ''' − sλ = f` is free of t, so it is what `S_h` stabilizes,
//! with weight h⁴; for θ in P1 or P2, `θ''' ≡ 0` and `S_h = Σ h⁴ s²(λ, μ)`.

fem_runtime::model! {
    /// Timoshenko beam obstacle problem, θ, w ∈ P2, λ ∈ P0 (stable for every α > 0, locking-free).
    pub mod timoshenko_p2 on interval {
        unknowns: θ: P2, w: P2, λ: P0 >= 0;
        tests: η, v, μ;
        params: t, α, s;
        data: f, ψ;
        forms: "
            a(θ,w;η,v) = ∫ θ'η' + t⁻²(w'−θ)(v'−η)
            b(η,v;μ)   = ∫ s v μ
            S(θ,λ;η,μ) = Σ_T h_T⁴ (θ''' − sλ, η''' − sμ)_T
            ℓ(η,v)     = ∫ f v
            ℓ_S(η,μ)   = Σ_T h_T⁴ (f, η''' − sμ)_T
            g(μ)       = ∫ s ψ μ
            B_h(θ,w,λ;η,v,μ) = a(θ,w;η,v) − b(η,v;λ) − b(θ,w;μ) − α S(θ,λ;η,μ)
            L_h(η,v,μ)       = ℓ(η,v) − g(μ) − α ℓ_S(η,μ)
        ";
        system:        B_h, L_h;
        energy:        a, ℓ;
        stabilization: α S against a;
        side:          s;
        obstacle:      w >= ψ;
        estimator:     "
            η_T² = h_T² ‖θ'' + t⁻²(w' − θ)‖² + h_T²(t² + h_T²) ‖t⁻²(w'' − θ') + f + sλ‖²
            η_E² = h_E ‖[[θ']]‖² + h_E(t² + h_E²) ‖[[t⁻²(w' − θ)]]‖²
        ";
    }
}

fem_runtime::model! {
    /// Timoshenko beam obstacle problem, θ, w ∈ P1 with one-point (reduced) shear integration, λ ∈ P0.
    pub mod timoshenko_p1_reduced on interval {
        unknowns: θ: P1, w: P1, λ: P0 >= 0;
        tests: η, v, μ;
        params: t, α, s;
        data: f, ψ;
        forms: "
            a(θ,w;η,v) = ∫ θ'η' + ∫[degree=1] t⁻²(w'−θ)(v'−η)
            b(η,v;μ)   = ∫ s v μ
            S(θ,λ;η,μ) = Σ_T h_T⁴ (θ''' − sλ, η''' − sμ)_T
            ℓ(η,v)     = ∫ f v
            ℓ_S(η,μ)   = Σ_T h_T⁴ (f, η''' − sμ)_T
            g(μ)       = ∫ s ψ μ
            B_h(θ,w,λ;η,v,μ) = a(θ,w;η,v) − b(η,v;λ) − b(θ,w;μ) − α S(θ,λ;η,μ)
            L_h(η,v,μ)       = ℓ(η,v) − g(μ) − α ℓ_S(η,μ)
        ";
        system:        B_h, L_h;
        energy:        a, ℓ;
        stabilization: α S against a;
        side:          s;
        obstacle:      w >= ψ;
        // The shear force is the cell constant γ_h = t⁻²(w' − θ) at the midpoint (as
        // `∫[degree=1]` sees it), so `[degree=1]`; its derivative vanishes in the cell.
        // The node jumps of θ' and γ_h are left out: the method's own equations give
        // [[γ_h]] = ∫(f + sλ)φ_i and [[θ']] = −∫γ_hφ_i at a node, which the cell terms bound.
        estimator:     "
            η_T² = h_T² ‖θ'' + t⁻²(w' − θ)‖²[degree=1] + h_T²(t² + h_T²) ‖f + sλ‖²
        ";
    }
}

fem_runtime::model! {
    /// Timoshenko beam, θ, w ∈ P1 with full (exact) shear integration: the standard
    /// displacement method that locks as t → 0, kept to show it.
    pub mod timoshenko_p1_full on interval {
        unknowns: θ: P1, w: P1, λ: P0 >= 0;
        tests: η, v, μ;
        params: t, α, s;
        data: f, ψ;
        forms: "
            a(θ,w;η,v) = int θ'η' + t^-2 (w' - θ)(v' - η)
            b(η,v;μ)   = int s v μ
            S(θ,λ;η,μ) = sum_T h_T^4 (θ''' - s λ, η''' - s μ)_T
            ℓ(η,v)     = int f v
            ℓ_S(η,μ)   = sum_T h_T^4 (f, η''' - s μ)_T
            g(μ)       = int s ψ μ
            B_h(θ,w,λ;η,v,μ) = a(θ,w;η,v) - b(η,v;λ) - b(θ,w;μ) - α S(θ,λ;η,μ)
            L_h(η,v,μ)       = ℓ(η,v) - g(μ) - α ℓ_S(η,μ)
        ";
        system:        B_h, L_h;
        energy:        a, ℓ;
        stabilization: α S against a;
        side:          s;
        obstacle:      w >= ψ;
        // the P2 pair's estimator: exact integration has the same strong form
        estimator:     "
            eta_T^2 = h_T^2 ||θ'' + t^-2 (w' - θ)||^2 + h_T^2 (t^2 + h_T^2) ||t^-2 (w'' - θ') + f + s λ||^2
            eta_E^2 = h_E ||[[θ']]||^2 + h_E (t^2 + h_E^2) ||[[t^-2 (w' - θ)]]||^2
        ";
    }
}
