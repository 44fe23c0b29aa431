#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

fem_forms_macro::model! {
    pub mod beam on interval {
        unknowns: w: P2;
        tests: v;
        params: s;
        data: f;
        forms: "
            a(w;v) = ∫ w'v' + s w v
            ℓ(v) = f v
        ";
    }
}

fn main() {}
