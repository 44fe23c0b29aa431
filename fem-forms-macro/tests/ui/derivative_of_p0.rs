#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

fem_forms_macro::model! {
    pub mod beam on interval {
        unknowns: w: P2, λ: P0 >= 0;
        tests: v, μ;
        params: s;
        data: f;
        forms: "
            c(λ;v) = ∫ λ' v'
        ";
    }
}

fn main() {}
