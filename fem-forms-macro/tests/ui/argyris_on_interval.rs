#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

// Argyris and Morley are triangle elements: on an interval they are errors at the name.
fem_forms_macro::model! {
    pub mod plate on interval {
        unknowns: w: Argyris, u: Morley;
        tests: v, z;
        forms: "
            a(w;v) = ∫ w''v''
            b(u;z) = ∫ u''z''
        ";
    }
}

fn main() {}
