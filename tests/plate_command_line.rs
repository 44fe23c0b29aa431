//! The plate scene `mindlin-square` from the command line: `solve --json` reports the
//! centre deflection against the Kirchhoff value as t → 0 (and the plain pair locking),
//! and bad input exits non-zero with a message naming it, never a panic.

use std::process::Command;

fn fem_forms(args: &[&str]) -> std::process::Output {
    let out = std::env::temp_dir().join(format!("fem-forms-plate-cli-{}", std::process::id()));
    Command::new(env!("CARGO_BIN_EXE_fem-forms"))
        .args(args)
        .arg("--out")
        .arg(&out)
        .output()
        .expect("the binary runs")
}

fn solve_json(args: &[&str]) -> serde_json::Value {
    let mut all = vec!["solve", "mindlin-square", "--json"];
    all.extend_from_slice(args);
    let run = fem_forms(&all);
    assert!(
        run.status.success(),
        "{all:?}: {}",
        String::from_utf8_lossy(&run.stderr)
    );
    serde_json::from_slice(&run.stdout).unwrap()
}

#[test]
fn mindlin_square_json_tends_to_kirchhoff_and_the_plain_pair_locks() {
    let json = solve_json(&["--thickness", "1e-4", "--mesh-size", "32"]);
    for field in [
        "centre_deflection",
        "kirchhoff_reference",
        "relative_error",
        "energy",
        "max_deflection",
        "total_contact_force",
        "complementarity_residual",
        "dofs",
        "iterations",
        "seconds",
    ] {
        assert!(
            json.get(field).is_some_and(|v| !v.is_null()),
            "{field} missing"
        );
    }
    // Timoshenko & Woinowsky-Krieger, table 35: 0.00126532 q a⁴/D with q = a = D = 1
    assert_eq!(json["kirchhoff_reference"].as_f64().unwrap(), 0.00126532);
    let w = json["centre_deflection"].as_f64().unwrap();
    assert!(
        ((w - 0.00126532) / 0.00126532).abs() < 1e-2,
        "centre deflection {w}"
    );
    assert!(
        (json["relative_error"].as_f64().unwrap() - (w - 0.00126532) / 0.00126532).abs() < 1e-12
    );
    // N = 32: θ 2·33², w 65², λ 2·32²
    assert_eq!(
        json["dofs"].as_u64().unwrap(),
        2 * 33 * 33 + 65 * 65 + 2 * 32 * 32
    );
    assert_eq!(json["total_contact_force"].as_f64().unwrap(), 0.0);
    assert!(json["complementarity_residual"].as_f64().unwrap() <= 1e-10);
    // J_h = −½ ℓ(u_h) at the unconstrained minimum: negative
    assert!(json["energy"].as_f64().unwrap() < 0.0);
    let plain = solve_json(&[
        "--thickness",
        "1e-4",
        "--mesh-size",
        "16",
        "--pair",
        "p1-p1-p0-plain",
    ]);
    assert!(
        plain["relative_error"].as_f64().unwrap() < -0.8,
        "plain P1/P1 at t = 1e-4: {}",
        plain["relative_error"]
    );
}

#[test]
fn bad_plate_input_exits_with_a_message() {
    for (args, message) in [
        (&["--thickness", "0"][..], "thickness t = 0"),
        (&["--thickness=-1e-3"][..], "thickness t = -0.001"),
        (&["--thickness", "NaN"][..], "thickness t = NaN"),
        (&["--mesh-size", "0"][..], "mesh size N = 0"),
        (&["--alpha", "-0.1"][..], "α = -0.1"),
        (&["--pair", "p2-p0"][..], "unknown plate pair `p2-p0`"),
        (&["--vtk"][..], "--vtk does not apply"),
        (&["--elements", "8"][..], "--elements does not apply"),
    ] {
        let mut all = vec!["solve", "mindlin-square"];
        all.extend_from_slice(args);
        let run = fem_forms(&all);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(!run.status.success(), "{all:?} succeeded");
        assert!(stderr.contains(message), "{all:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{all:?}: {stderr}");
    }
    let run = fem_forms(&["study", "mindlin-square", "convergence"]);
    assert!(!run.status.success());
    assert!(String::from_utf8_lossy(&run.stderr).contains("hosts no study `convergence`"));
}

/// `study mindlin-square locking` writes the chart and its table: the Stenberg pair's
/// error at N = 32 stays within 1 % for every t ≤ 1e-2 (no locking), the plain pair's
/// deflection collapses (relative error below −0.99 at t = 1e-4).
#[test]
fn the_locking_study_writes_its_chart_and_table() {
    let out = std::env::temp_dir().join(format!("fem-forms-plate-study-{}", std::process::id()));
    let run = Command::new(env!("CARGO_BIN_EXE_fem-forms"))
        .args(["study", "mindlin-square", "locking", "--out"])
        .arg(&out)
        .output()
        .expect("the binary runs");
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let csv = std::fs::read_to_string(out.join("mindlin-square-locking.csv")).unwrap();
    let svg = std::fs::read_to_string(out.join("mindlin-square-locking.svg")).unwrap();
    assert!(svg.contains("<svg"));
    let rows: Vec<Vec<&str>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    let value = |r: &Vec<&str>, i: usize| r[i].parse::<f64>().unwrap();
    for r in &rows {
        let (n, t, error) = (value(r, 1), value(r, 2), value(r, 4));
        if r[0] == "p1-p2-p0" && n == 32.0 && t <= 1e-2 {
            assert!(error.abs() < 0.01, "{r:?}");
        }
        if r[0] != "p1-p2-p0" && t == 1e-4 {
            assert!(error < -0.99, "{r:?}");
        }
    }
    assert!(rows.iter().any(|r| r[0] != "p1-p2-p0"));
    std::fs::remove_dir_all(&out).unwrap();
}
