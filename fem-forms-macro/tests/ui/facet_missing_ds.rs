#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

fem_forms_macro::model! {
    pub mod contact on triangle {
        unknowns: u: [P1]^2, λ: P0 >= 0;
        tests: v, μ;
        params: α;
        data: g;
        facets: Γ_C;
        forms: "
            b(v;μ) = ∫_Γ_C μ v·n
        ";
    }
}

fn main() {}
