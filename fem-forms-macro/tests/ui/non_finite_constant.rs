#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

// A constant that overflows f64 is an error at the number, and so is a product of
// constants that overflows or underflows: never a kernel of infinities, a term that
// vanished without a word, or a panic. A small constant that cancels nothing stays.
fem_forms_macro::model! {
    pub mod beam on interval {
        unknowns: w: P2;
        tests: v;
        data: f;
        forms: "
            a(w;v) = ∫ 1e999 w'v'
            b(w;v) = ∫ 1e200·1e200 f w v
            c(w;v) = ∫ 1e-200·1e-200 f w v
            d(w;v) = ∫ 1e-301 w v
        ";
    }
}

fn main() {}
