//! Compile-fail tests of the DSL: every mistake is a compile error that points at its
//! place and says how to fix it. The expected messages are the `.stderr` files.

#[test]
fn dsl_errors() {
    let t = trybuild::TestCases::new();
    t.compile_fail("tests/ui/*.rs");
}
