//! What the command-line tests share: the binary run with an output directory of its
//! own, and a number of its JSON report.

// each test crate uses what it needs of these
#![allow(dead_code)]

use std::process::{Command, Output};

/// `fem-forms ARGS --out <tmp>/fem-forms-<tag>-<pid>`.
pub fn fem_forms(args: &[&str], tag: &str) -> Output {
    let out = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("fem-forms-{tag}-{}", std::process::id()));
    Command::new(env!("CARGO_BIN_EXE_fem-forms"))
        .args(args)
        .arg("--out")
        .arg(&out)
        .output()
        .expect("the binary runs")
}

/// The JSON printed by `fem-forms ARGS` (which must succeed).
pub fn json_of(args: &[&str], tag: &str) -> serde_json::Value {
    let run = fem_forms(args, tag);
    assert!(
        run.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&run.stderr)
    );
    serde_json::from_slice(&run.stdout).unwrap()
}

/// The number under `field` of a JSON report.
///
/// # Panics
/// Where the report has no number there.
pub fn number(json: &serde_json::Value, field: &str) -> f64 {
    json[field]
        .as_f64()
        .unwrap_or_else(|| panic!("{field} missing in {json}"))
}
