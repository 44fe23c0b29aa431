#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

fem_forms_macro::model! {
    pub mod beam on interval {
        unknowns: θ: P2, w: P2, λ: P0 >= 0;
        tests: η, v, μ;
        params: t, s;
        data: f;
        forms: "
            a(θ,w;η,v) = ∫ θ'η' + t⁻²(w'−θ)(v'−η
            b(η,v;μ) = ∫ s v μ μ
            ℓ(η,v) = ∫ fv + q v
            S(θ,λ;η,μ) = Σ_T h⁴ (θ''' − sλ) (η''' − sμ)
        ";
    }
}

fn main() {}
