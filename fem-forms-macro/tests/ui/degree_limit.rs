#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

// A quadrature degree above the limit says what the limit is.
fem_forms_macro::model! {
    pub mod beam on interval {
        unknowns: w: P2;
        tests: v;
        forms: "a(w;v) = ∫[degree=41] w v";
    }
}

fn main() {}
