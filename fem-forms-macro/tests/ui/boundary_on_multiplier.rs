#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

fem_forms_macro::model! {
    pub mod membrane on triangle {
        unknowns: u: P1, λ: P0 >= 0;
        tests: v, μ;
        data: g;
        boundary: λ = g, u = h0;
        forms: "a(u;v) = ∫ ∇u·∇v";
    }
}

fn main() {}
