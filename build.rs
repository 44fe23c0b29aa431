//! Records the commit this program is built from (`FEM_FORMS_COMMIT`), for the report
//! page's head: the checkout at build time, not wherever the program later runs.

use std::process::Command;

fn main() {
    let git = |args: &[&str]| {
        Command::new("git")
            .args(args)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
    };
    let commit = match git(&["rev-parse", "HEAD"]) {
        Some(hash) => {
            let dirty = git(&["status", "--porcelain", "--untracked-files=no"])
                .is_some_and(|s| !s.is_empty());
            if dirty {
                format!("{hash}, built with uncommitted changes")
            } else {
                hash
            }
        }
        None => "unknown (built outside a git checkout)".into(),
    };
    println!("cargo:rustc-env=FEM_FORMS_COMMIT={commit}");
    // a new commit, a staged change, or an edit to the sources builds it again
    if let Some(dir) = git(&["rev-parse", "--git-dir"]) {
        println!("cargo:rerun-if-changed={dir}/HEAD");
        println!("cargo:rerun-if-changed={dir}/index");
        if let Some(reference) = git(&["symbolic-ref", "-q", "HEAD"]) {
            println!("cargo:rerun-if-changed={dir}/{reference}");
        }
    }
    for sources in [
        "src",
        "models/src",
        "fem-runtime/src",
        "fem-forms-macro/src",
    ] {
        println!("cargo:rerun-if-changed={sources}");
    }
}
