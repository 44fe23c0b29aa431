//! Reissner–Mindlin plate over a rigid obstacle (docs/mathematics.md §6, frame §1):
//! rotations θ, deflection w, contact multiplier λ ≥ 0, thickness t, obstacle side
//! `s = ±1` (`s·w ≥ s·ψ`: +1 an obstacle below, −1 one above).
//!
//! The rotation equation gives `S(∇w − θ) = −div Cε(θ)`, so the contact equation is
//! `div div Cε(θ) − sλ = f`, free of t: that is what `S_h` stabilizes, with weight h⁴.
//! For P1 rotations `div div Cε(θ_h) ≡ 0` on each triangle, the macro drops those terms
//! and `S_h = Σ_T h_T⁴ s²(λ, μ)_T`, `ℓ_S = −Σ_T h_T⁴ (f, sμ)_T`: stable for every α > 0
//! (α = 0.1 measured best, §6).
//!
//! The locking-free pair is θ ∈ [P1]², w ∈ P2, λ ∈ P0 with the Stenberg shear weight
//! `6κ(1−ν)D/(t² + β h_T²)` (β = 0.1); the plain displacement method θ ∈ [P1]², w ∈ P1
//! with the physical weight `6κ(1−ν)D/t²` is kept to show locking. Units: D the bending
//! stiffness `E t³/(12(1−ν²))`, κ the shear correction (5/6), f the load per area along w.
//!
//! The boundary conditions are those of `boundary:`, imposed on the Dirichlet part
//! (`DirichletPart`; the whole boundary by default) with the data g (0 for a plate
//! fixed at height 0): clamped (`θ = g, w = g`) or simply supported (`w = g`, θ free,
//! the "soft" support). One model per condition, since a model's `boundary:` list is
//! fixed; the forms are one text.

/// One Stenberg-weighted Mindlin model per boundary condition: the forms are the same text.
macro_rules! mindlin_model {
    ($(#[$doc:meta])* $name:ident, boundary: $($field:ident = $data:ident),+) => {
        fem_runtime::model! {
            $(#[$doc])*
            pub mod $name on triangle {
                unknowns: θ: [P1]^2, w: P2, λ: P0 >= 0;
                tests: η, v, μ;
                params: D > 0, ν, κ > 0, t > 0, β > 0, α, s;
                data: f, ψ, g;
                boundary: $($field = $data),+;
                forms: "
                    Cε(θ)            := D[(1−ν)ε(θ) + ν tr ε(θ) I]
                    q(θ,w)           := 6κ(1−ν)D/(t² + β h_T²) (∇w − θ)
                    a(θ,w;η,v)       = ∫ Cε(θ):ε(η) + ∫ q(θ,w)·(∇v − η)
                    b(v;μ)           = ∫ s v μ
                    S(θ,λ;η,μ)       = Σ_T h_T⁴ (div div Cε(θ) − sλ, div div Cε(η) − sμ)_T
                    ℓ(v)             = ∫ f v
                    ℓ_S(η,μ)         = Σ_T h_T⁴ (f, div div Cε(η) − sμ)_T
                    G(μ)             = ∫ s ψ μ
                    B_h(θ,w,λ;η,v,μ) = a(θ,w;η,v) − b(v;λ) − b(w;μ) − α S(θ,λ;η,μ)
                    L_h(η,v,μ)       = ℓ(v) − G(μ) − α ℓ_S(η,μ)
                ";
                system:        B_h, L_h;
                energy:        a, ℓ;
                stabilization: α S against a;
                side:          s;
                obstacle:      w >= ψ;
                estimator:     "
                    η_T² = h_T²/D ‖div Cε(θ) + q(θ,w)‖² + h_T²(t² + h_T²)/D ‖div q(θ,w) + f + sλ‖²
                    η_E² = h_E/D ‖[[Cε(θ)·n]]‖² + h_E(t² + h_E²)/D ‖[[q(θ,w)·n]]‖²
                ";
            }
        }
    };
}

mindlin_model! {
    /// Reissner–Mindlin plate obstacle problem, θ ∈ [P1]², w ∈ P2, λ ∈ P0, Stenberg shear
    /// weight: locking-free. Its `boundary:` data hold every field (`θ = g`, `w = g`, the
    /// clamp); the registry imposes any support by the fields' roles instead.
    mindlin_stenberg, boundary: θ_x = g, θ_y = g, w = g
}

mindlin_model! {
    /// Simply supported ("soft") Reissner–Mindlin plate obstacle problem (`w = g` on the
    /// Dirichlet part, θ free), θ ∈ [P1]², w ∈ P2, λ ∈ P0, Stenberg shear weight.
    mindlin_simply_supported, boundary: w = g
}

fem_runtime::model! {
    /// Clamped Reissner–Mindlin plate, the plain displacement method θ ∈ [P1]², w ∈ P1
    /// with the physical shear weight `6κ(1−ν)D/t²` (λ ∈ P0, stabilized as the others):
    /// it locks as t → 0, kept to show it.
    pub mod mindlin_plain_p1 on triangle {
        unknowns: θ: [P1]^2, w: P1, λ: P0 >= 0;
        tests: η, v, μ;
        params: D > 0, ν, κ > 0, t > 0, α, s;
        data: f, ψ, g;
        boundary: θ_x = g, θ_y = g, w = g;
        forms: "
            Cε(θ)            := D[(1−ν)ε(θ) + ν tr ε(θ) I]
            q(θ,w)           := 6κ(1−ν)D t⁻² (∇w − θ)
            a(θ,w;η,v)       = ∫ Cε(θ):ε(η) + ∫ q(θ,w)·(∇v − η)
            b(v;μ)           = ∫ s v μ
            S(θ,λ;η,μ)       = Σ_T h_T⁴ (div div Cε(θ) − sλ, div div Cε(η) − sμ)_T
            ℓ(v)             = ∫ f v
            ℓ_S(η,μ)         = Σ_T h_T⁴ (f, div div Cε(η) − sμ)_T
            G(μ)             = ∫ s ψ μ
            B_h(θ,w,λ;η,v,μ) = a(θ,w;η,v) − b(v;λ) − b(w;μ) − α S(θ,λ;η,μ)
            L_h(η,v,μ)       = ℓ(v) − G(μ) − α ℓ_S(η,μ)
        ";
        system:        B_h, L_h;
        energy:        a, ℓ;
        stabilization: α S against a;
        side:          s;
        obstacle:      w >= ψ;
        // the Stenberg pairs' estimator with the physical shear: reliable, and it sees
        // the locking (its shear terms grow with the locked shear as t falls below h)
        estimator:     "
            η_T² = h_T²/D ‖div Cε(θ) + q(θ,w)‖² + h_T²(t² + h_T²)/D ‖div q(θ,w) + f + sλ‖²
            η_E² = h_E/D ‖[[Cε(θ)·n]]‖² + h_E(t² + h_E²)/D ‖[[q(θ,w)·n]]‖²
        ";
    }
}
