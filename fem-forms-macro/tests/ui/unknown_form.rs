#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

// A call of a form that is not defined names it and lists the forms defined so far.
fem_forms_macro::model! {
    pub mod membrane on triangle {
        unknowns: u: P1;
        tests: v;
        forms: "
            a(u;v) = ∫ ∇u·∇v
            B(u;v) = aa(u;v)
        ";
    }
}

fn main() {}
