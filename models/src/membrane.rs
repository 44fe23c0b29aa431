//! Membrane over a rigid obstacle (docs/mathematics.md §2): deflection u, contact multiplier
//! λ ≥ 0, `u ≥ ψ`, `u = g` on ∂Ω, `−Δu − λ = f`.
//!
//! `S_h = Σ_T h² (−Δu − λ, −Δv − μ)_T`: for P1 the Laplacian vanishes on each triangle
//! and the term is `α Σ h² (λ, μ)_T`; for P2 it is stable for `0 < α < 1/C_I`, with `C_I`
//! the inverse-inequality constant of the element (computed at run time). The three
//! stabilized models differ only in their elements, so one text serves them all.

/// One membrane obstacle model per element pair: the forms are the same text.
macro_rules! membrane_model {
    ($(#[$doc:meta])* $name:ident, u: $u:ident, λ: $lambda:ident) => {
        fem_runtime::model! {
            $(#[$doc])*
            pub mod $name on triangle {
                unknowns: u: $u, λ: $lambda >= 0;
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
                estimator: "
                    η_T² = h_T² ‖f + Δu + λ‖²
                    η_E² = h_E ‖[[∇u·n]]‖²
                ";
            }
        }
    };
}

membrane_model! {
    /// Membrane obstacle problem, u ∈ P1, λ ∈ P0 (stabilized; the plain pair, α = 0, is singular).
    membrane_p1_p0, u: P1, λ: P0
}

membrane_model! {
    /// Membrane obstacle problem, u ∈ P2, λ ∈ P0 (stabilized; the plain pair has a checkerboard mode).
    membrane_p2_p0, u: P2, λ: P0
}

membrane_model! {
    /// Membrane obstacle problem, u ∈ P2, λ ∈ P1 discontinuous (stabilized).
    membrane_p2_p1disc, u: P2, λ: P1disc
}

fem_runtime::model! {
    /// The membrane of the classical nodal-constraint method, u ∈ P1: the stiffness and
    /// load it assembles (`energy: a, ℓ`; the obstacle enters at the nodes, `u_i ≥ ψ(x_i)`,
    /// not in a form), and λ ∈ P1, the density of its nodal contact forces `r_i`,
    /// `λ_h = Σ_i r_i/∫φ_i φ_i` (Braess, Numer. Math. 101, 2005), which only the estimator
    /// reads. `b` and `G` with the vertex rule are the nodal constraint itself:
    /// `Σ_i μ_i ∫φ_i (u_i − ψ_i) ≥ 0` for every `μ ≥ 0` is `u_i ≥ ψ_i`.
    pub mod membrane_p1 on triangle {
        unknowns: u: P1, λ: P1 >= 0;
        tests: v, μ;
        data: f, ψ, g;
        boundary: u = g;
        forms: "
            a(u;v) = ∫ ∇u·∇v
            ℓ(v)   = ∫ f v
            b(v;μ) = ∫ v μ
            G(μ)   = ∫ ψ μ
        ";
        energy: a, ℓ;
        constraint: b, G;
        obstacle: u >= ψ;
        estimator: "
            η_T² = h_T² ‖f + Δu + λ‖²
            η_E² = h_E ‖[[∇u·n]]‖²
        ";
    }
}
