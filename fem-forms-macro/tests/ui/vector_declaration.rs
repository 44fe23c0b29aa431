#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

fem_forms_macro::model! {
    pub mod plate on triangle {
        unknowns: θ: [P1]^3, w: P2, λ: [P0]^2 >= 0;
        tests: η, v, μ;
        params: θ_x;
        forms: "a(w;v) = ∫ ∇w·∇v";
    }
}

fn main() {}
