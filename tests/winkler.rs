//! The Kirchhoff plate on a Winkler foundation, the family added as a user would (one
//! model file, one registry entry, a scene file): against Navier's series without
//! contact, and in contact against equilibrium, `∫λ = k∫w − ∫f` for a free plate (the
//! foundation's reaction and the contact force carry the load). Scene files of the one
//! reader: given derivatives of an exact solution are checked.

mod common;

use common::number;
use std::process::Command;

fn fem_forms(args: &[&str]) -> std::process::Output {
    common::fem_forms(args, "winkler")
}

fn solve_json(args: &[&str]) -> serde_json::Value {
    let mut all = vec!["solve"];
    all.extend_from_slice(args);
    all.push("--json");
    let run = fem_forms(&all);
    assert!(
        run.status.success(),
        "{all:?}: {}",
        String::from_utf8_lossy(&run.stderr)
    );
    serde_json::from_slice(&run.stdout).unwrap()
}

/// `∫w` of Navier's series for the simply supported unit square on a Winkler foundation
/// under the uniform load q (../MODELS.md §10): each term `16q/(π² m n) sin(mπx) sin(nπy)
/// / (Dπ⁴(m² + n²)² + k)` integrates to `4/(π² m n)` times its amplitude.
fn navier_integral(q: f64, d: f64, k: f64) -> f64 {
    let pi = std::f64::consts::PI;
    let mut sum = 0.0;
    for m in (1..800).step_by(2) {
        for n in (1..800).step_by(2) {
            let (m, n) = (m as f64, n as f64);
            let amplitude =
                16.0 * q / (pi * pi * m * n) / (d * pi.powi(4) * (m * m + n * n).powi(2) + k);
            sum += amplitude * 4.0 / (pi * pi * m * n);
        }
    }
    sum
}

#[test]
fn without_contact_the_plate_follows_navier_s_series() {
    let report = solve_json(&["winkler-square", "--no-obstacle", "--mesh-size", "8"]);
    let integral = number(&report, "deflection_integral");
    let exact = navier_integral(-1.0, 1.0, 100.0);
    assert!(
        (integral / exact - 1.0).abs() < 1e-6,
        "{integral} against {exact}"
    );
    // the energy −½ℓ(w) = −½ ∫ f w with f = −1
    let energy = number(&report, "energy");
    assert!(
        (energy - 0.5 * exact).abs() < 1e-6 * exact.abs(),
        "{energy}"
    );
}

#[test]
fn in_contact_the_free_plate_is_in_equilibrium() {
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/winkler-free-plate.toml"
    );
    for n in ["8", "16"] {
        let report = solve_json(&["--scene", file, "--mesh-size", n]);
        let force = number(&report, "total_contact_force");
        let w = number(&report, "deflection_integral");
        // ∫f = −1 on the unit square, k = 100
        let balance = 100.0 * w + 1.0;
        assert!(force > 0.1, "the bump carries part of the load: {force}");
        assert!(
            (force - balance).abs() < 1e-6 * force,
            "N = {n}: ∫λ = {force}, k∫w − ∫f = {balance}"
        );
        assert!(number(&report, "complementarity_residual") < 1e-10);
    }
}

#[test]
fn a_scene_file_s_exact_derivatives_are_checked() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("winkler-files-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let write = |name: &str, exact: &str| {
        let path = dir.join(name);
        std::fs::write(
            &path,
            format!(
                "model = \"kirchhoff\"\npair = \"argyris-p0\"\n[mesh]\ngenerator = \"rectangle\"\nsize = 4\n[boundary]\nclamped = \"all\"\n[parameters]\nD = 1.0\nnu = 0.3\n[data]\nf = \"0\"\npsi = \"-1\"\n[exact]\n{exact}\n"
            ),
        )
        .unwrap();
        path
    };
    // a kink: exmex cannot differentiate max, so the file gives the gradient
    let good = write(
        "good.toml",
        "value = \"max(0, x - 0.5)^2\"\ngradient = [\"2*max(0, x - 0.5)\", \"0\"]",
    );
    let run = fem_forms(&["solve", "--scene", good.to_str().unwrap()]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let wrong = write("wrong.toml", "value = \"x^2\"\ngradient = [\"x\", \"0\"]");
    let run = fem_forms(&["solve", "--scene", wrong.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success(), "a wrong gradient was accepted");
    assert!(
        stderr.contains("exact.gradient") && stderr.contains("finite difference"),
        "{stderr}"
    );
    let hessian = write(
        "hessian.toml",
        "value = \"x^2*y\"\nhessian = [[\"2*y\", \"2*x\"], [\"2*x\", \"1\"]]",
    );
    let run = fem_forms(&["solve", "--scene", hessian.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        !run.status.success() && stderr.contains("exact.hessian[1]"),
        "{stderr}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The family hosts the study kinds that need only solves through the one study
/// implementation (`fem_forms::registry_studies`), with no study code of its own: the α
/// sweep shows the method consistent (∫λ_h the same to 1e-4 over the stable range
/// 0 < α·C_I < 1, the plain method α = 0 included), and the iterations study solves
/// every mesh nested and cold.
#[test]
fn the_family_hosts_the_generic_studies() {
    let out = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("winkler-studies-{}", std::process::id()));
    let run = Command::new(env!("CARGO_BIN_EXE_fem-forms"))
        .args(["study", "winkler-square", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let csv = std::fs::read_to_string(out.join("winkler-square-alpha.csv")).unwrap();
    let forces: Vec<(f64, f64)> = csv
        .lines()
        .skip(1)
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            (v[1], v[7])
        })
        .filter(|&(ac, _)| ac < 1.0)
        .collect();
    assert!(forces.len() > 10, "{csv}");
    let reference = forces[0].1;
    for (ac, force) in &forces {
        assert!(
            (force - reference).abs() < 1e-4 * reference,
            "α·C_I = {ac}: ∫λ_h = {force} against {reference}"
        );
    }
    let iterations = std::fs::read_to_string(out.join("winkler-square-iterations.csv")).unwrap();
    for line in iterations.lines().skip(1) {
        let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        assert!(v[1] >= 1.0 && v[2] >= 1.0, "{line}");
    }
    std::fs::remove_dir_all(&out).unwrap();
}

/// A flat obstacle under a flat answer has ranges of rounding size: a crossing of ψ is
/// judged against the answer's size, so one cell's real crossing reads as a share of the
/// deflection (not 1e16 % of a range of 1e-17).
#[test]
fn a_crossing_of_a_flat_obstacle_is_judged_against_the_answer_s_size() {
    let report = solve_json(&["winkler-square", "--mesh-size", "1"]);
    let warnings = report["warnings"].to_string();
    assert!(warnings.contains("w_h's sizes"), "{warnings}");
    let depth = number(&report, "max_penetration");
    assert!(depth > 1e-4 && depth < 2e-3, "{depth}");
}
