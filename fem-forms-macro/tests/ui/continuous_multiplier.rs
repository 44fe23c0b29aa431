#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

// A continuous multiplier that the system solves for is refused (the same field on a
// model without `system:`, the nodal method's force density, compiles: membrane_p1).
fem_forms_macro::model! {
    pub mod string on interval {
        unknowns: u: P1, λ: P1 >= 0;
        tests: v, μ;
        data: f, ψ;
        forms: "
            a(u;v)       = ∫ u'v'
            b(v;μ)       = ∫ v μ
            B_h(u,λ;v,μ) = a(u;v) − b(v;λ) − b(u;μ)
            L_h(v,μ)     = ∫ f v − ∫ ψ μ
        ";
    }
}

fn main() {}
