#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

fem_forms_macro::model! {
    pub mod string on interval {
        unknowns: u: P1, λ: P0 >= 0;
        tests: v, μ;
        params: alpha;
        data: f, ψ;
        forms: "
            a(u;v)     = ∫ u'v'
            S(u,λ;v,μ) = Σ_T h_T² (λ, μ)_T
        ";
        stabilization: alpa S against a;
    }
}

fn main() {}
