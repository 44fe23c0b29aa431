//! The runtime, the macro, the models and the command line are layered: no source file imports a module that imports it
//! back (directly or through others). A cycle makes the layers impossible to read or test
//! alone, so this test reads the `crate::…` paths of every file and looks for one.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Module path (`mesh::triangle`, `crate` for lib.rs) → file, for every `.rs` under `root`.
fn modules(root: &Path) -> BTreeMap<String, PathBuf> {
    let mut out = BTreeMap::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                let relative = path.strip_prefix(root).unwrap().with_extension("");
                let parts: Vec<String> = relative
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .filter(|c| c != "mod")
                    .collect();
                let name = match parts.join("::").as_str() {
                    "lib" | "main" => "crate".to_string(),
                    other => other.to_string(),
                };
                out.insert(name, path);
            }
        }
    }
    out
}

/// The longest module path of `known` that `path` (`a::b::Item`) starts with.
fn resolve<'a>(path: &str, known: &'a BTreeMap<String, PathBuf>) -> Option<&'a str> {
    let parts: Vec<&str> = path.split("::").collect();
    (1..=parts.len()).rev().find_map(|k| {
        known
            .get_key_value(&parts[..k].join("::"))
            .map(|(name, _)| name.as_str())
    })
}

/// The module paths a file names, outside comments and its test module, as absolute
/// paths: `crate::a::b`, `super::x` and `self::x` (relative to `module`), and `x::…` in
/// a `use` where `x` is a child module of `module` (how a parent names its children).
/// `use …::{a, b::c}` groups are expanded.
fn named_paths(source: &str, module: &str, known: &BTreeMap<String, PathBuf>) -> Vec<String> {
    let code: String = source
        .split("#[cfg(test)]\nmod tests")
        .next()
        .unwrap()
        .lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n");
    let parent = match module.rsplit_once("::") {
        Some((parent, _)) => parent.to_string(),
        None => "crate".to_string(),
    };
    let absolute = |path: &str| -> String {
        let within = |base: &str, rest: &str| match base {
            "crate" => rest.to_string(),
            _ if rest.is_empty() => base.to_string(),
            _ => format!("{base}::{rest}"),
        };
        if let Some(rest) = path.strip_prefix("crate::") {
            rest.to_string()
        } else if let Some(rest) = path.strip_prefix("super::") {
            within(&parent, rest)
        } else if let Some(rest) = path.strip_prefix("self::") {
            within(module, rest)
        } else {
            within(module, path)
        }
    };
    let mut out = Vec::new();
    let word_end = |s: &str| {
        s.find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
            .unwrap_or(s.len())
    };
    for prefix in ["crate::", "super::", "self::"] {
        let mut rest = code.as_str();
        while let Some(at) = rest.find(prefix) {
            let before = rest[..at].chars().last();
            rest = &rest[at + prefix.len()..];
            if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
                continue; // `super::` inside `crate::a::super`-like text, or a longer word
            }
            if let Some(group) = rest.strip_prefix('{') {
                let end = group.find('}').unwrap_or(group.len());
                out.extend(
                    group[..end]
                        .split(',')
                        .map(|p| absolute(&format!("{prefix}{}", p.trim()))),
                );
            } else {
                let end = word_end(rest);
                out.push(absolute(&format!(
                    "{prefix}{}",
                    rest[..end].trim_end_matches(':')
                )));
            }
        }
    }
    // `use child::…` in a parent module
    for line in code.lines() {
        let line = line.trim_start();
        let Some(path) = line
            .strip_prefix("use ")
            .or_else(|| line.strip_prefix("pub use "))
        else {
            continue;
        };
        let first = &path[..word_end(path)];
        let head = first.split("::").next().unwrap_or("");
        if known.contains_key(&absolute(head)) && !["crate", "super", "self"].contains(&head) {
            out.push(absolute(first.trim_end_matches(':')));
        }
    }
    out
}

/// Import edges between the files of a crate (a file's own ancestors excluded: a child
/// naming its parent module is the ordinary way down a tree).
fn edges(root: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let known = modules(root);
    known
        .iter()
        .map(|(name, file)| {
            let source = std::fs::read_to_string(file).unwrap();
            let targets = named_paths(&source, name, &known)
                .iter()
                .filter_map(|p| resolve(p, &known))
                .filter(|t| *t != name && !name.starts_with(&format!("{t}::")) && *t != "crate")
                .map(str::to_string)
                .collect();
            (name.clone(), targets)
        })
        .collect()
}

/// One cycle through `start`, if any (depth-first search).
fn cycle_through(graph: &BTreeMap<String, BTreeSet<String>>, start: &str) -> Option<Vec<String>> {
    let mut stack = vec![(start.to_string(), vec![start.to_string()])];
    let mut seen = BTreeSet::new();
    while let Some((node, path)) = stack.pop() {
        for next in graph.get(&node).into_iter().flatten() {
            if next == start {
                let mut cycle = path.clone();
                cycle.push(start.to_string());
                return Some(cycle);
            }
            if seen.insert(next.clone()) {
                let mut longer = path.clone();
                longer.push(next.clone());
                stack.push((next.clone(), longer));
            }
        }
    }
    None
}

fn assert_acyclic(crate_dir: &str) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(crate_dir)
        .join("src");
    let crate_dir = if crate_dir.is_empty() {
        "the command line"
    } else {
        crate_dir
    };
    let graph = edges(&root);
    assert!(graph.len() > 3, "read no modules under {}", root.display());
    let cycles: Vec<String> = graph
        .keys()
        .filter_map(|m| cycle_through(&graph, m))
        .map(|c| c.join(" → "))
        .collect();
    assert!(
        cycles.is_empty(),
        "import cycles in {crate_dir}:\n{}",
        cycles.join("\n")
    );
}

#[test]
fn the_runtime_has_no_import_cycle() {
    assert_acyclic("fem-runtime");
}

#[test]
fn the_form_compiler_has_no_import_cycle() {
    assert_acyclic("fem-forms-macro");
}

#[test]
fn the_models_have_no_import_cycle() {
    assert_acyclic("models");
}

#[test]
fn the_command_line_has_no_import_cycle() {
    assert_acyclic("");
}

#[test]
fn a_cycle_is_found() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("fem-forms-cycle-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("a")).unwrap();
    std::fs::write(dir.join("lib.rs"), "pub mod a;\npub mod b;\n").unwrap();
    std::fs::write(
        dir.join("a/mod.rs"),
        "use crate::b::Thing;\npub mod inner;\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("a/inner.rs"),
        "use crate::a::X; // a parent, not a cycle\n",
    )
    .unwrap();
    std::fs::write(dir.join("b.rs"), "use crate::{error::E, a::Z};\n").unwrap();
    std::fs::create_dir_all(dir.join("c")).unwrap();
    std::fs::write(dir.join("c/mod.rs"), "mod x;\nmod y;\nuse x::Thing;\n").unwrap();
    std::fs::write(dir.join("c/x.rs"), "use super::*;\nuse super::y::Other;\n").unwrap();
    std::fs::write(
        dir.join("c/y.rs"),
        "fn f() { self::g(); }\n#[cfg(test)]\nmod tests { use super::super::x; }\n",
    )
    .unwrap();
    let graph = edges(&dir);
    assert!(cycle_through(&graph, "b").is_some(), "{graph:?}");
    assert!(cycle_through(&graph, "a::inner").is_none(), "{graph:?}");
    assert!(
        graph["c"].contains("c::x") && graph["c::x"].contains("c::y"),
        "{graph:?}"
    );
    assert!(cycle_through(&graph, "c::x").is_none(), "{graph:?}");
    // a sibling naming the other back through `super::` closes a cycle
    std::fs::write(dir.join("c/y.rs"), "use super::x::Thing;\n").unwrap();
    let graph = edges(&dir);
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(cycle_through(&graph, "c::x").is_some(), "{graph:?}");
}
