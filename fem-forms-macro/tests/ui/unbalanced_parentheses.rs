#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

fem_forms_macro::model! {
    pub mod beam on interval {
        unknowns: θ: P2, w: P2;
        tests: η, v;
        params: t;
        data: f;
        forms: "
            a(θ,w;η,v) = ∫ θ'η' + t⁻²(w'−θ(v'−η)
        ";
    }
}

fn main() {}
