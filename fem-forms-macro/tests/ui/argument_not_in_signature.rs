#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

fem_forms_macro::model! {
    pub mod beam on interval {
        unknowns: θ: P2, w: P2;
        tests: η, v;
        params: t;
        data: f;
        forms: "
            ℓ(v) = ∫ f η
        ";
    }
}

fn main() {}
