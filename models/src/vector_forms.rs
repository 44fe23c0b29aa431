//! A test model of the form language's shapes (docs/forms.md): the bending and
//! Stenberg-weighted shear forms of a Reissner–Mindlin-like plate (docs/mathematics.md
//! §6) with rotations θ ∈ [P1]², deflection w ∈ P2 and a multiplier λ ∈ P0. It checks
//! the vector forms against hand-coded kernels (`tests/vector_forms.rs`); it is not a
//! scene and not the plate model (no boundary conditions, no obstacle data).

fem_runtime::model! {
    /// Plate-like forms with vector rotations: `Cε = D[(1−ν)ε + ν tr ε I]`, the shear
    /// weight `6κ(1−ν)D/(t² + β h_T²)`, and `S_h`, which P1 rotations reduce to `Σ h⁴ s²(λ, μ)`.
    pub mod rotation_shear on triangle {
        unknowns: θ: [P1]^2, w: P2, λ: P0 >= 0;
        tests: η, v, μ;
        params: D, ν, κ, t > 0, β > 0, s;
        data: f;
        forms: "
            Cε(θ)        := D[(1−ν)ε(θ) + ν tr ε(θ) I]
            a_b(θ;η)     = ∫ Cε(θ):ε(η)
            a_s(θ,w;η,v) = ∫ 6κ(1−ν)D/(t² + β h_T²) (∇w − θ)·(∇v − η)
            S(θ,λ;η,μ)   = Σ_T h_T⁴ (div div Cε(θ) − sλ, div div Cε(η) − sμ)_T
            ℓ(η,v)       = ∫ f v + f div η
        ";
    }
}
