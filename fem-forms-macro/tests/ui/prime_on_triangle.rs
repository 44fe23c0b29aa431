#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

fem_forms_macro::model! {
    pub mod membrane on triangle {
        unknowns: u: P1;
        tests: v;
        forms: "a(u;v) = int u'v'";
    }
}

fn main() {}
