#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

// The data degree has the same limit as `∫[degree=N]`.
fem_forms_macro::model! {
    pub mod beam on interval {
        unknowns: w: P2;
        tests: v;
        data: f: 1000;
        forms: "ℓ(v) = ∫ f v";
    }
}

fn main() {}
