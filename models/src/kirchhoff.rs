//! Kirchhoff plate bending (docs/mathematics.md and ../shared/MODELS.md §5) on the C¹
//! Argyris quintic and on the non-conforming Morley quadratic: the bending form
//! `a(w;v) = ∫ D[(1−ν) ∇∇w:∇∇v + ν Δw Δv]` (that is `∫ M(w):K(v)` with
//! `K(w) = −∇∇w`, `M(w) = D[(1−ν)K(w) + ν tr K(w) I]`) and the load `ℓ(v) = ∫ f v`.
//! No obstacle yet: these models exist to test the elements' wiring (issue 13).

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
