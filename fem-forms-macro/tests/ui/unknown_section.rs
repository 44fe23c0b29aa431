#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

fem_forms_macro::model! {
    pub mod beam on interval {
        unknowns: w: P2;
        test: v;
        forms: "a(w;v) = ∫ w'v'";
    }
}

fn main() {}
