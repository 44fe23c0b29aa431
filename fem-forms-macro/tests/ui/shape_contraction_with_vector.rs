#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

fem_forms_macro::model! {
    pub mod plate on triangle {
        unknowns: θ: [P1]^2, w: P2;
        tests: η, v;
        params: D, ν, t > 0, β > 0;
        forms: "
            a(θ;η) = ∫ D[(1−ν)ε(θ) + ν tr ε(θ) I] : η
        ";
    }
}

fn main() {}
