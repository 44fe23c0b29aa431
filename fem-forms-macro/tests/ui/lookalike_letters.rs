#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

// A Cyrillic `Т` for the parameter `T`, a Greek `ν` for the test function `v`: the
// hint says which letter is not what it looks like.
fem_forms_macro::model! {
    pub mod string on interval {
        unknowns: u: P1;
        tests: v;
        params: T;
        forms: "
            a(u;v) = ∫ Т u'v'
            b(u;ν) = ∫ u v
        ";
    }
}

fn main() {}
