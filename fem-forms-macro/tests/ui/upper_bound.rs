#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

// Only `>= 0` multipliers exist: the message says how an upper bound is written.
fem_forms_macro::model! {
    pub mod membrane on triangle {
        unknowns: u: P1, λ: P0 <= 0;
        tests: v, μ;
        forms: "a(u;v) = ∫ ∇u·∇v";
    }
}

fn main() {}
