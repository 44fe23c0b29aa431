#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

fem_forms_macro::model! {
    pub mod beam on interval {
        unknowns: w: Hermite;
        tests: v;
        params: s;
        data: f;
        forms: "
            a(w;v) = ∫ w''''' v
        ";
    }
}

fn main() {}
