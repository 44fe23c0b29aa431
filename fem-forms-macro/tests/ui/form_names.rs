#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

// Each form becomes a Rust module and a handle: names that cannot be one are refused
// at the name, not with errors in generated code.
fem_forms_macro::model! {
    pub mod beam on interval {
        unknowns: w: P2;
        tests: v;
        forms: "
            a₁(w;v) = ∫ w'v'
            fn(w;v) = ∫ w v
            Model(w;v) = ∫ w v
            data(w;v) = ∫ w v
        ";
    }
}

fn main() {}
