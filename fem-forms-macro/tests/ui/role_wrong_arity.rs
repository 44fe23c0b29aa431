#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

fem_forms_macro::model! {
    pub mod string on interval {
        unknowns: u: P1, λ: P0 >= 0;
        tests: v, μ;
        data: f, ψ;
        forms: "
            B_h(u,λ;v,μ) = ∫ u'v' − λ v − u μ
            L_h(v,μ)     = ∫ f v − ψ μ
        ";
        system: L_h, B_h;
    }
}

fn main() {}
