#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

fem_forms_macro::model! {
    pub mod beam on interval {
        unknowns: w: P2;
        tests: v;
        params: t;
        data: f;
        facets: Γ_C;
        forms: "
            ℓ(v) = ∫ f v
        ";
    }
}

fn main() {}
