//! Golden data guarding the one-pipeline refactor (issue 31): the JSON report of every
//! built-in scene (default options and a few others) and of every example scene file,
//! recorded by the code before the refactor (`tests/golden/*.json`, the commands in
//! `tests/golden/cases.txt`, one per line, in file order).
//!
//! These numbers were produced by the code they guard: they do not show that an answer
//! is right (the other tests compare with exact solutions and independent references),
//! only that moving the code changed no number. Every recorded number must still be
//! reported, under the same key or the one [`RENAMED`] gives, and agree to rounding;
//! wall times are not compared.

use serde_json::Value;
use std::path::Path;
use std::process::Command;

/// Keys renamed by the refactor: `(scenes, old path, new path)`, paths joined by `.`;
/// `scenes` are the first words of the cases it applies to (`*`: every case).
const RENAMED: &[(&[&str], &str, &str)] = &[
    // one report for every family: the finest mesh's cells, the KKT residual under its
    // name (the families called it complementarity_residual; the runtime's
    // complementarity_residual is its complementarity part), the rounding experiment's
    // result under one name
    (BEAMS, "elements", "cells"),
    (BEAMS, "complementarity_residual", "kkt_residual"),
    (MEMBRANES, "triangles", "cells"),
    (PLATES, "triangles", "cells"),
    (KIRCHHOFF, "complementarity_residual", "kkt_residual"),
    (PLATES, "complementarity_residual", "kkt_residual"),
    (MEMBRANES, "complementarity_residual", "kkt_residual"),
    (TIMOSHENKO, "thickness_rounding", "rounding"),
    (BERNOULLI, "length_rounding", "rounding"),
];

/// The beam scenes.
const BEAMS: &[&str] = &[
    "timoshenko-a",
    "timoshenko-b",
    "bernoulli-a",
    "bernoulli-b",
    "bernoulli-flat",
];
/// The membrane scenes and scene files.
const MEMBRANES: &[&str] = &[
    "membrane-radial",
    "membrane-lshape",
    "membrane-flat",
    "--scene",
];
/// The Mindlin plate scenes.
const PLATES: &[&str] = &["mindlin-square", "mindlin-square-ss", "mindlin-disk"];
/// The Kirchhoff plate scenes.
const KIRCHHOFF: &[&str] = &["kirchhoff-square", "kirchhoff-obstacle"];
const TIMOSHENKO: &[&str] = &["timoshenko-a", "timoshenko-b"];
const BERNOULLI: &[&str] = &["bernoulli-a", "bernoulli-b", "bernoulli-flat"];

/// Numbers and messages the refactor changed on purpose: `(command, key, why)`. The new
/// value is checked by the tests of the concept named; for `warnings`, the count stays.
/// `PENETRATION`: every family's crossing of the obstacle is the runtime's one check,
/// which samples each cell's vertices, edge midpoints, centroid, quadrature points and,
/// on coarse meshes, a lattice (the families sampled fewer points: the plates w's nodes,
/// Kirchhoff vertices, midpoints and centroids, the membranes vertices and quadrature
/// points), so it finds crossings a little deeper (tests/vi_robustness.rs,
/// tests/plate_command_line.rs check it against known crossings).
///
/// `ACCURACY`: built-in membrane scenes state the accuracy they ask for (the one the
/// cheapest-pair choice aims at), and the report checks it as it did for scene files:
/// a solve that misses it, or cannot measure it, says so (tests/membrane.rs).
///
/// `DOFS`: the plates counted every DOF; every report counts the unknowns left after the
/// supports' DOFs are eliminated (primal and multiplier).
///
/// `UNCONSTRAINED`: a scene without obstacle is the unconstrained problem (λ = 0, the
/// primal block alone), which has no crossing of an obstacle and no open gap to report
/// (null, not 0); its numbers are those of the far obstacle the plates used before. It
/// is one linear solve on the finest mesh (`solver: linear`, one level), not nested
/// Newton, so its numbers agree to rounding of the solve (the Kirchhoff square's centre
/// deflection to 5e-13 of itself, which its relative error of 8e-7 shows in its 7th
/// digit), and α, where the stabilization has no primal part (Morley), is null.
///
/// `QUADRATURE`: a scene file's pressure errors against its exact pressure integrate on
/// 8 pieces of each edge: one 8-point rule on the edge across Hertz's square-root edge
/// at b left the errors about 1 % low (0.0494 against 0.0498).
///
/// `NESTED`: a contact scene file refined from a coarser mesh is solved by nested
/// iteration, each level from the one before (the levels whose constraints cannot
/// balance the load left out): Newton takes 2 iterations on the finest level instead of
/// 12 from the pressed start; the answer agrees to rounding
/// (tests/contact_scene_files.rs compares nested and one-level solves).
const CHANGED: &[(&str, &str, &str)] = &[
    ("--scene examples/contact-gap.toml", "iterations", "NESTED"),
    (
        "--scene examples/contact-gap.toml",
        "pressure_l2_error",
        "QUADRATURE",
    ),
    (
        "--scene examples/contact-gap.toml",
        "best_p0_l2_error",
        "QUADRATURE",
    ),
    (
        "--scene examples/contact-gap.toml",
        "best_fit_l2_error",
        "QUADRATURE",
    ),
    (
        "signorini-gap --mesh-size 16",
        "warnings",
        "the accuracy a scene asks for is checked once, by the pipeline, against the measure its family names (the pressure's L² error for contact)",
    ),
    ("kirchhoff-square", "dofs", "DOFS"),
    ("kirchhoff-square", "levels", "UNCONSTRAINED"),
    ("kirchhoff-square", "solver", "UNCONSTRAINED"),
    ("kirchhoff-square", "relative_error", "UNCONSTRAINED"),
    ("kirchhoff-square", "max_penetration", "UNCONSTRAINED"),
    ("kirchhoff-square", "max_open_contact_gap", "UNCONSTRAINED"),
    (
        "kirchhoff-square --support simply-supported --pair morley-p0 --mesh-size 32",
        "dofs",
        "DOFS",
    ),
    (
        "kirchhoff-square --support simply-supported --pair morley-p0 --mesh-size 32",
        "levels",
        "UNCONSTRAINED",
    ),
    (
        "kirchhoff-square --support simply-supported --pair morley-p0 --mesh-size 32",
        "solver",
        "UNCONSTRAINED",
    ),
    (
        "kirchhoff-square --support simply-supported --pair morley-p0 --mesh-size 32",
        "alpha",
        "UNCONSTRAINED",
    ),
    (
        "kirchhoff-square --support simply-supported --pair morley-p0 --mesh-size 32",
        "max_penetration",
        "UNCONSTRAINED",
    ),
    (
        "kirchhoff-square --support simply-supported --pair morley-p0 --mesh-size 32",
        "max_open_contact_gap",
        "UNCONSTRAINED",
    ),
    ("kirchhoff-obstacle --mesh-size 8", "dofs", "DOFS"),
    (
        "kirchhoff-obstacle --pair argyris-p1disc --mesh-size 8 --obstacle curved",
        "dofs",
        "DOFS",
    ),
    ("kirchhoff-obstacle --pair morley-p0 --mesh-size 16", "dofs", "DOFS"),
    ("mindlin-square", "dofs", "DOFS"),
    ("mindlin-square", "max_penetration", "UNCONSTRAINED"),
    ("mindlin-square", "max_open_contact_gap", "UNCONSTRAINED"),
    (
        "mindlin-square --thickness 0.01 --pair p1-p1-p0-plain --mesh-size 16",
        "dofs",
        "DOFS",
    ),
    (
        "mindlin-square --thickness 0.01 --pair p1-p1-p0-plain --mesh-size 16",
        "max_penetration",
        "UNCONSTRAINED",
    ),
    (
        "mindlin-square --thickness 0.01 --pair p1-p1-p0-plain --mesh-size 16",
        "max_open_contact_gap",
        "UNCONSTRAINED",
    ),
    ("mindlin-square-ss --thickness 0.05", "dofs", "DOFS"),
    ("mindlin-square-ss --thickness 0.05", "max_penetration", "UNCONSTRAINED"),
    (
        "mindlin-square-ss --thickness 0.05",
        "max_open_contact_gap",
        "UNCONSTRAINED",
    ),
    (
        "mindlin-square-ss --thickness 0.05",
        "warnings",
        "the soft simple support's O(t) boundary layer is named, with the hard support as its cure (tests/plate_supports.rs)",
    ),
    ("mindlin-disk --mesh-size 8", "dofs", "DOFS"),
    ("mindlin-disk --no-obstacle --mesh-size 8", "dofs", "DOFS"),
    (
        "mindlin-disk --no-obstacle --mesh-size 8",
        "max_penetration",
        "UNCONSTRAINED",
    ),
    (
        "mindlin-disk --no-obstacle --mesh-size 8",
        "max_open_contact_gap",
        "UNCONSTRAINED",
    ),
    (
        "membrane-radial --pair p1-p0 --mesh-size 32",
        "warnings+",
        "ACCURACY",
    ),
    (
        "membrane-radial --pair p2-p1d --mesh-size 16",
        "warnings+",
        "ACCURACY",
    ),
    (
        "membrane-radial --pair p1-nodal --mesh-size 32",
        "warnings+",
        "ACCURACY",
    ),
    (
        "membrane-radial --pair p1-nodal --mesh-size 32",
        "alpha",
        "α is null where there is no multiplier to stabilize (the nodal method), not 0",
    ),
    ("membrane-radial --mesh-size 16 --alpha 0", "warnings+", "ACCURACY"),
    ("membrane-lshape --mesh-size 32", "warnings+", "ACCURACY"),
    (
        "membrane-radial --pair p1-p0 --mesh-size 32",
        "max_penetration",
        "PENETRATION",
    ),
    (
        "membrane-radial --pair p1-nodal --mesh-size 32",
        "max_penetration",
        "PENETRATION",
    ),
    (
        "--scene examples/disk-off-centre.toml",
        "max_penetration",
        "PENETRATION",
    ),
    ("kirchhoff-obstacle --mesh-size 8", "max_penetration", "PENETRATION"),
    (
        "kirchhoff-obstacle --pair argyris-p1disc --mesh-size 8 --obstacle curved",
        "max_penetration",
        "PENETRATION",
    ),
    (
        "kirchhoff-obstacle --pair morley-p0 --mesh-size 16",
        "max_penetration",
        "PENETRATION",
    ),
    (
        "kirchhoff-obstacle --pair morley-p0 --mesh-size 16",
        "warnings",
        "the penetration warning is the runtime's",
    ),
    (
        "mindlin-disk --mesh-size 8",
        "max_penetration",
        "the runtime's one penetration check samples each cell's vertices, quadrature points and, on coarse meshes, a lattice (the plates sampled w's nodes only): 1.50e-3 instead of 1.47e-3 (tests/plate_scenes.rs)",
    ),
    (
        "mindlin-disk --mesh-size 8",
        "warnings",
        "the penetration warning is the runtime's, judged against ψ's and w_h's ranges",
    ),
];

/// Quantities that are themselves rounding measurements (residuals, noise estimates):
/// compared by order of magnitude, since a change of summation order moves them.
const ROUNDING: &[&str] = &[
    "complementarity_residual",
    "patch_pressure_error",
    "kkt_residual",
    "multiplier_noise",
    "primal_rounding",
    "thickness_rounding",
    "length_rounding",
    "equilibrium_residual",
];

fn is_time(key: &str) -> bool {
    key.contains("seconds") || key.starts_with("phases")
}

fn lookup<'a>(root: &'a Value, path: &str) -> Option<&'a Value> {
    path.split('.').try_fold(root, |v, k| v.get(k))
}

/// The leaves of `value` (arrays count as leaves) with their paths.
fn leaves<'a>(value: &'a Value, path: String, out: &mut Vec<(String, &'a Value)>) {
    match value {
        Value::Object(map) => {
            for (k, v) in map {
                let p = if path.is_empty() {
                    k.clone()
                } else {
                    format!("{path}.{k}")
                };
                leaves(v, p, out);
            }
        }
        _ => out.push((path, value)),
    }
}

/// Whether `new` reports `old` to rounding; `leaf` is the key's last part.
fn agree(old: &Value, new: &Value, leaf: &str) -> bool {
    match (old, new) {
        (Value::Array(a), Value::Array(b)) => {
            a.len() == b.len() && a.iter().zip(b).all(|(x, y)| agree(x, y, leaf))
        }
        (Value::Number(a), Value::Number(b)) => {
            let (x, y) = (a.as_f64().unwrap(), b.as_f64().unwrap());
            if ROUNDING.contains(&leaf) {
                (x - y).abs() <= 1e-12
                    || (x.abs().max(1e-300) / y.abs().max(1e-300)).log10().abs() <= 2.0
            } else if a.is_u64() && b.is_u64() {
                x == y
            } else {
                (x - y).abs() <= 1e-8 * x.abs().max(y.abs()) + 1e-14
            }
        }
        _ => old == new,
    }
}

/// What of `old` `new` lost or changed, one line each, but for the keys `changed`
/// allows (a changed `warnings` keeps its count; `warnings+` keeps every recorded warning
/// and may add others); `scene` is the case's first word.
fn differences(old: &Value, new: &Value, changed: &[&str], scene: &str) -> Vec<String> {
    let mut recorded = Vec::new();
    leaves(old, String::new(), &mut recorded);
    let mut faults = Vec::new();
    for (path, value) in recorded {
        if is_time(&path) || (changed.contains(&path.as_str()) && path != "warnings") {
            continue;
        }
        if path == "warnings" && changed.contains(&"warnings+") {
            let now = new["warnings"].as_array().cloned().unwrap_or_default();
            for w in value.as_array().into_iter().flatten() {
                if !now.contains(w) {
                    faults.push(format!("warnings: lost {w}"));
                }
            }
            continue;
        }
        let target = RENAMED
            .iter()
            .find(|(scenes, from, _)| {
                *from == path && (scenes.contains(&"*") || scenes.contains(&scene))
            })
            .map_or(path.as_str(), |(_, _, to)| to);
        let leaf = path.rsplit('.').next().unwrap_or(&path);
        let value = &match (path.as_str(), value) {
            ("warnings", Value::Array(a)) if changed.contains(&"warnings") => Value::from(a.len()),
            _ => value.clone(),
        };
        let count;
        let now = match (path.as_str(), lookup(new, target)) {
            ("warnings", Some(Value::Array(a))) if changed.contains(&"warnings") => {
                count = Value::from(a.len());
                Some(&count)
            }
            (_, found) => found,
        };
        match now {
            // a recorded null is no number: the key may go (the other beam theory's
            // rounding experiment, which the report now gives under one name) or gain a
            // value (the accuracy built-in scenes now state)
            _ if value.is_null() => {}
            None => faults.push(format!("{path}: missing (was {value})")),
            Some(now) if !agree(value, now, leaf) => {
                faults.push(format!("{path}: {now}, was {value}"))
            }
            Some(_) => {}
        }
    }
    faults
}

#[test]
fn every_recorded_report_keeps_its_numbers() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = root.join("tests/golden");
    let cases = std::fs::read_to_string(dir.join("cases.txt")).unwrap();
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    files.sort();
    let lines: Vec<&str> = cases.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(files.len(), lines.len(), "one golden file per case");
    let mut failures = Vec::new();
    for (line, file) in lines.iter().zip(&files) {
        let output = Command::new(env!("CARGO_BIN_EXE_fem-forms"))
            .current_dir(root)
            .arg("solve")
            .args(line.split_whitespace())
            .arg("--json")
            .output()
            .unwrap();
        if !output.status.success() {
            failures.push(format!(
                "`solve {line}` failed: {}",
                String::from_utf8_lossy(&output.stderr)
            ));
            continue;
        }
        let new: Value = serde_json::from_slice(&output.stdout)
            .unwrap_or_else(|e| panic!("`solve {line} --json`: {e}"));
        let old: Value = serde_json::from_str(&std::fs::read_to_string(file).unwrap()).unwrap();
        let changed: Vec<&str> = CHANGED
            .iter()
            .filter(|(case, _, _)| case == line)
            .map(|(_, key, _)| *key)
            .collect();
        let scene = line.split_whitespace().next().unwrap_or_default();
        let faults = differences(&old, &new, &changed, scene);
        if !faults.is_empty() {
            failures.push(format!("`solve {line}`:\n    {}", faults.join("\n    ")));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The comparison sees a changed number, a lost key and a renamed one.
#[test]
fn the_comparison_can_fail() {
    let old: Value =
        serde_json::json!({"energy": 1.0, "levels": [[8, 2]], "seconds": 1.0, "a": {"b": 3.0}});
    let same: Value = serde_json::json!({"energy": 1.0 + 1e-12, "levels": [[8, 2]], "seconds": 9.0, "a": {"b": 3.0}});
    assert!(differences(&old, &same, &[], "x").is_empty());
    let changed: Value = serde_json::json!({"energy": 1.001, "levels": [[8, 3]], "a": {}});
    assert_eq!(differences(&old, &changed, &[], "x").len(), 3);
    assert_eq!(differences(&old, &changed, &["energy"], "x").len(), 2);
}
