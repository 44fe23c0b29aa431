#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

// `boundary: w = g` interpolates g at the DOFs: wrong for Argyris and Morley, whose DOFs
// include derivatives, so it is refused at the field's name.
fem_forms_macro::model! {
    pub mod plate on triangle {
        unknowns: w: Argyris;
        tests: v;
        data: g;
        boundary: w = g;
        forms: "
            a(w;v) = ∫ ∇∇w:∇∇v
        ";
    }
}

fn main() {}
