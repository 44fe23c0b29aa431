#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

fem_forms_macro::model! {
    pub mod membrane on triangle {
        unknowns: u: P2, λ: P0 >= 0;
        tests: v, μ;
        params: α;
        data: f, ψ, g;
        boundary: u = g;
        forms: "
            a(u;v) = ∫ ∇u·∇v
            S(u;v) = Σ_T h² (∇u + u, Δv)_T
        ";
    }
}

fn main() {}
