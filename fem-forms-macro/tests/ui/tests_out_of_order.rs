#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

// `tests:` out of order: μ belongs to u and v to λ, so `a(u;v)` would be assembled into
// the multiplier's rows. The system form, over both fields, shows it.
fem_forms_macro::model! {
    pub mod string on interval {
        unknowns: u: P1, λ: P0 >= 0;
        tests: μ, v;
        params: α;
        data: f, ψ;
        forms: "
            a(u;v)       = ∫ u'v'
            b(v;μ)       = ∫ v μ
            B_h(u,λ;v,μ) = a(u;v) − b(v;λ) − b(u;μ) − α Σ_T h_T² (λ, μ)_T
            L_h(v,μ)     = ∫ f v − ∫ ψ μ
        ";
    }
}

fn main() {}
