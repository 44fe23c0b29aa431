#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

fem_forms_macro::model! {
    pub mod beam on interval {
        unknowns: θ: P2, w: P2;
        tests: η;
        forms: "a(θ,w;η) = ∫ θ'η'";
    }
}

fn main() {}
