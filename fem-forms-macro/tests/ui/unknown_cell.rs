#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

fem_forms_macro::model! {
    pub mod plate on tetrahedron {
        unknowns: w: P2;
        tests: v;
        forms: "a(w;v) = ∫ w'v'";
    }
}

fn main() {}
