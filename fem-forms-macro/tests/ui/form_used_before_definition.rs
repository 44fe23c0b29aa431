#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

fem_forms_macro::model! {
    pub mod beam on interval {
        unknowns: w: P2, λ: P0 >= 0;
        tests: v, μ;
        params: s;
        data: f;
        forms: "
            B(w,λ;v,μ) = b(v;λ) − b(w;μ)
            b(v;μ) = ∫ s v μ
        ";
    }
}

fn main() {}
