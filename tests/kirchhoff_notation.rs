//! The Kirchhoff obstacle models are written as in the mathematics (docs/mathematics.md §9, issue
//! 13): `K(w) = −∇∇w`, `M(w) = D[(1−ν)K(w) + ν tr K(w) I]`, `a(w,v) = ∫ M(w):K(v)` and the
//! stabilization with `Δ²` (`models/src/kirchhoff.rs`). Against the same forms written
//! with `∇∇w:∇∇v`, `Δw Δv` and `ΔΔ` (the notation whose kernels tests/argyris.rs checks
//! against exact integrals): the element matrices agree on random triangles,
//! transformation included.
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

use fem_forms::models::kirchhoff::kirchhoff_argyris_p0;
use fem_forms::DataFn;

fem_forms::model! {
    /// Argyris–P0 Kirchhoff obstacle model in Hessian notation.
    pub mod kirchhoff_hessians on triangle {
        unknowns: w: Argyris, λ: P0 >= 0;
        tests: v, μ;
        params: D > 0, ν, α, s;
        data: f, ψ, g;
        forms: "
            a(w;v)       = ∫ D[(1−ν) ∇∇w:∇∇v + ν Δw Δv]
            S(w,λ;v,μ)   = Σ_T h_T⁴ (D ΔΔw − sλ, D ΔΔv − sμ)_T
            ℓ_S(v,μ)     = Σ_T h_T⁴ (f, D ΔΔv − sμ)_T
        ";
    }
}

fn load(_: &[f64]) -> f64 {
    1.7
}

/// Uniform in (0, 1) from a 64-bit LCG (Knuth's MMIX constants).
fn random(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*state >> 11) as f64 / (1u64 << 53) as f64
}

fn largest(k: &[[f64; 21]]) -> f64 {
    k.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()))
}

#[test]
fn moments_and_curvatures_give_the_kernels_of_the_hessian_notation() {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let f: &DataFn = &load;
    for case in 0..30 {
        let scale = [0.02, 1.0, 4.0][case % 3];
        let x: [f64; 6] = std::array::from_fn(|_| scale * (random(&mut state) - 0.5));
        let area = (x[2] - x[0]) * (x[5] - x[1]) - (x[4] - x[0]) * (x[3] - x[1]);
        if area.abs() < 1e-3 * scale * scale {
            continue;
        }
        let global = if case % 2 == 0 { [0, 1, 2] } else { [7, 3, 5] };
        let params = [
            0.5 + random(&mut state),
            0.45 * random(&mut state),
            1e-3,
            if case % 4 < 2 { 1.0 } else { -1.0 },
        ];
        let data = [f, f, f];
        let (ours, theirs) = (
            kirchhoff_hessians::a::matrix_v_w(&x, &global, &params, &data),
            kirchhoff_argyris_p0::a::matrix_v_w(&x, &global, &params, &data),
        );
        let tolerance = 1e-12 * largest(&theirs);
        for (a, b) in ours.iter().flatten().zip(theirs.iter().flatten()) {
            assert!((a - b).abs() <= tolerance, "case {case}: a {a} against {b}");
        }
        let (ours, theirs) = (
            kirchhoff_hessians::S::matrix_v_w(&x, &global, &params, &data),
            kirchhoff_argyris_p0::S::matrix_v_w(&x, &global, &params, &data),
        );
        let tolerance = 1e-12 * largest(&theirs);
        for (a, b) in ours.iter().flatten().zip(theirs.iter().flatten()) {
            assert!((a - b).abs() <= tolerance, "case {case}: S {a} against {b}");
        }
    }
}
