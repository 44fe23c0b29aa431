//! Kirchhoff plate bending (docs/mathematics.md §9) on the C¹
//! Argyris quintic and on the non-conforming Morley quadratic: the bending form
//! `a(w;v) = ∫ D[(1−ν) ∇∇w:∇∇v + ν Δw Δv]` (that is `∫ M(w):K(v)` with
//! `K(w) = −∇∇w`, `M(w) = D[(1−ν)K(w) + ν tr K(w) I]`) and the load `ℓ(v) = ∫ f v`.
//! The first two exist to test the elements' wiring (issue 13); `kirchhoff_argyris_p0`,
//! `kirchhoff_argyris_p1disc` and `kirchhoff_morley_p0` are the obstacle problem.

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
                energy: a, ℓ;
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

/// One Kirchhoff obstacle model per element pair: the forms are the same text
/// (docs/mathematics.md §9, frame §1): `DΔ²w − sλ = f`, λ ≥ 0, obstacle side `s = ±1`
/// (`s·w ≥ s·ψ`: +1 an obstacle below, −1 one above), stabilized by
/// `S_h = Σ_T h_T⁴ (DΔ²w − sλ, DΔ²v − sμ)_T` and `a(w;v) = ∫ M(w):K(v)` with `K(w) = −∇∇w`, as written in the model. `boundary: w = g` is
/// the simple support with `g = 0` (the runtime fixes the value and the derivatives it
/// implies along the edges, `DirichletPart::plate_dofs`); a clamped plate is held by
/// `Constraints::support_plate` levels instead (the same forms: a support only fixes
/// DOFs, so no clamped variant of the text is needed).
macro_rules! kirchhoff_obstacle_model {
    ($(#[$doc:meta])* $name:ident, w: $w:ident, λ: $lambda:ident, estimator: $estimator:literal) => {
        fem_runtime::model! {
            $(#[$doc])*
            pub mod $name on triangle {
                unknowns: w: $w, λ: $lambda >= 0;
                tests: v, μ;
                params: D > 0, ν, α, s;
                data: f, ψ, g;
                boundary: w = g;
                forms: "
                    K(w)         := −∇∇w
                    M(w)         := D[(1−ν)K(w) + ν tr K(w) I]
                    a(w;v)       = ∫ M(w):K(v)
                    b(v;μ)       = ∫ s v μ
                    S(w,λ;v,μ)   = Σ_T h_T⁴ (D Δ²w − sλ, D Δ²v − sμ)_T
                    ℓ(v)         = ∫ f v
                    ℓ_S(v,μ)     = Σ_T h_T⁴ (f, D Δ²v − sμ)_T
                    G(μ)         = ∫ s ψ μ
                    B_h(w,λ;v,μ) = a(w;v) − b(v;λ) − b(w;μ) − α S(w,λ;v,μ)
                    L_h(v,μ)     = ℓ(v) − G(μ) − α ℓ_S(v,μ)
                ";
                system:        B_h, L_h;
                energy:        a, ℓ;
                stabilization: α S against a;
                side:          s;
                obstacle:      w >= ψ;
                estimator:     $estimator;
            }
        }
    };
}

kirchhoff_obstacle_model! {
    /// Kirchhoff plate obstacle problem on Argyris–P0: deflection w ∈ Argyris, contact
    /// multiplier λ ∈ P0 (see `kirchhoff_obstacle_model!` for the forms); α: stable for
    /// `0 < α < 1/C_I` (C_I ≈ 1.9e5 on right isosceles cells, computed at run time).
    ///
    /// The estimator is the plate's residual one (cell residual, jumps of the Kirchhoff
    /// shear and of `M_nn`; docs/adaptivity.md) with the weights `h/p` (p = 5) of
    /// Melenk–Wohlmuth (2001) in place of `h`: with
    /// plain `h` the quintic's cell residual, dominated by `f − Π₁f`, overestimates the
    /// error about 200-fold on a smooth plate; with `h/p` the efficiency index is 8–18.
    /// Every term is divided by D so that η has the units of the energy norm
    /// `‖w‖_a = (D ∫ |∇²w|²)^{1/2}` (its residuals carry one D each).
    kirchhoff_argyris_p0, w: Argyris, λ: P0,
    estimator: "
        η_T² = h_T⁴/(625 D) ‖f − D Δ²w + sλ‖²
        η_E² = h_E³/(125 D) ‖[[(div M(w))·n + τ·∇((M(w)·n)·τ)]]‖² + h_E/(5 D) ‖[[(M(w)·n)·n]]‖²
    "
}

kirchhoff_obstacle_model! {
    /// Kirchhoff plate obstacle problem on Argyris–P1disc: w ∈ Argyris, λ piecewise linear
    /// and discontinuous (coefficient-wise λ ≥ 0 is λ ≥ 0 pointwise); α as for
    /// Argyris–P0 (the primal part of `S_h`, hence C_I, is the same).
    kirchhoff_argyris_p1disc, w: Argyris, λ: P1disc,
    estimator: "
        η_T² = h_T⁴/(625 D) ‖f − D Δ²w + sλ‖²
        η_E² = h_E³/(125 D) ‖[[(div M(w))·n + τ·∇((M(w)·n)·τ)]]‖² + h_E/(5 D) ‖[[(M(w)·n)·n]]‖²
    "
}

kirchhoff_obstacle_model! {
    /// Kirchhoff plate obstacle problem on Morley–P0 (non-conforming, 6 DOFs per cell):
    /// `Δ²w` vanishes on each cell for w ∈ P2, so `S_h = Σ_T h_T⁴ s² (λ, μ)_T` and
    /// `ℓ_S = −Σ_T h_T⁴ (f, sμ)_T`: C_I = 0, every α > 0 is stable and α is limited by
    /// accuracy (the obstacle shifts by about `α h⁴ |f − sλ|`, zero where the residual is).
    ///
    /// The estimator adds to the plate's residual one the jumps of the nonconformity
    /// (Beirão da Veiga–Niiranen–Stenberg 2007 take the tangential derivative's; with
    /// the normal derivative's too the efficiency index stays at 1.07–1.22 where the
    /// tangential jump alone let it drift below 1).
    kirchhoff_morley_p0, w: Morley, λ: P0,
    estimator: "
        η_T² = h_T⁴/D ‖f − D Δ²w + sλ‖²
        η_E² = h_E³/D ‖[[(div M(w))·n + τ·∇((M(w)·n)·τ)]]‖² + h_E/D ‖[[(M(w)·n)·n]]‖²
               + D h_E⁻¹ ‖[[τ·∇w]]‖² + D h_E⁻¹ ‖[[n·∇w]]‖²
    "
}
