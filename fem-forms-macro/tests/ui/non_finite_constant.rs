#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

// A constant that overflows f64 is an error at the number, and so is a product of
// constants that overflows: never a kernel of infinities or a panic.
fem_forms_macro::model! {
    pub mod beam on interval {
        unknowns: w: P2;
        tests: v;
        data: f;
        forms: "
            a(w;v) = ∫ 1e999 w'v'
            b(w;v) = ∫ 1e200·1e200 f w v
        ";
    }
}

fn main() {}
