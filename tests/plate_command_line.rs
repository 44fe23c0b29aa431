//! The plate scenes from the command line: `mindlin-square` (`solve --json` reports the
//! centre deflection against the Kirchhoff value as t → 0, and the plain pair locking),
//! `mindlin-square-ss` against Navier's value, `mindlin-disk` with contact (its report
//! checked by identities and exact values) and without its obstacle (against the closed
//! form), its studies; and bad input exits non-zero with a message naming it, never a
//! panic.

mod common;

use std::process::Command;

fn fem_forms(args: &[&str]) -> std::process::Output {
    common::fem_forms(args, "plate-cli")
}

fn solve_json(args: &[&str]) -> serde_json::Value {
    scene_json("mindlin-square", args)
}

fn scene_json(scene: &str, args: &[&str]) -> serde_json::Value {
    let mut all = vec!["solve", scene, "--json"];
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
    // the field name the Kirchhoff plates use for the reference of relative_error
    assert_eq!(
        json["reference_centre_deflection"].as_f64().unwrap(),
        0.00126532
    );
    let w = json["centre_deflection"].as_f64().unwrap();
    assert!(
        ((w - 0.00126532) / 0.00126532).abs() < 1e-2,
        "centre deflection {w}"
    );
    assert!(
        (json["relative_error"].as_f64().unwrap() - (w - 0.00126532) / 0.00126532).abs() < 1e-12
    );
    // N = 32, the unknowns left by the clamped boundary: θ 2·31², w 63², λ 2·32²
    assert_eq!(
        json["dofs"].as_u64().unwrap(),
        2 * 31 * 31 + 63 * 63 + 2 * 32 * 32
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
        (&["--mesh-size", "0"][..], "--mesh-size 0 is out of range"),
        (&["--alpha", "0.1"][..], "--alpha does not apply"),
        (&["--cold"][..], "--cold does not apply"),
        (&["--pair", "p2-p0"][..], "unknown pair `p2-p0`"),
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
    let out = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("fem-forms-plate-study-{}", std::process::id()));
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

/// The simply supported square tends to Navier's 0.00406235 q a⁴/D (Timoshenko &
/// Woinowsky-Krieger, table 8) as t → 0: at t = 1e-4 the error falls with h (measured
/// +6.7e-3, +4.3e-3, +2.4e-3 at N = 16, 32, 64: about O(h) with the soft support) and is
/// within 0.5 % at N = 64.
#[test]
fn the_simply_supported_square_tends_to_navier() {
    let errors: Vec<f64> = [16, 32, 64]
        .iter()
        .map(|n| {
            let json = scene_json(
                "mindlin-square-ss",
                &["--thickness", "1e-4", "--mesh-size", &n.to_string()],
            );
            assert_eq!(json["support"], "simply-supported");
            assert_eq!(json["kirchhoff_reference"].as_f64().unwrap(), 0.00406235);
            let w = json["centre_deflection"].as_f64().unwrap();
            (w - 0.00406235) / 0.00406235
        })
        .collect();
    assert!(
        errors[0].abs() > errors[1].abs() && errors[1].abs() > errors[2].abs(),
        "{errors:?}"
    );
    assert!(errors[2].abs() < 5e-3, "{errors:?}");
}

/// mindlin-disk at q = 20 on 32 rings: the obstacle holds the centre at w = 0.05 (the
/// unobstructed plate would rise to 0.3126), the multiplier in the contact interior is
/// q (there w is constant and θ = 0, so `div div Cε(θ) − sλ = f` gives λ = q), the
/// energy satisfies `J_h = −½ q∫w_h + ½ s ψ ∫λ_h` (equilibrium tested with u_h, s = −1,
/// ψ = 0.05), and nested iteration takes a few Newton steps on every level.
#[test]
fn mindlin_disk_reports_contact_that_satisfies_its_identities() {
    let json = scene_json("mindlin-disk", &["--mesh-size", "32"]);
    for field in [
        "energy",
        "max_deflection",
        "total_contact_force",
        "contact_area",
        "contact_radius",
        "lambda_interior_mean",
        "lambda_interior_spread",
        "dofs",
        "iterations",
        "levels",
        "seconds",
        "complementarity_residual",
    ] {
        assert!(
            json.get(field).is_some_and(|v| !v.is_null()),
            "{field} missing: {json}"
        );
    }
    let value = |f: &str| json[f].as_f64().unwrap();
    assert_eq!(json["obstacle"], "flat above, w ≤ 0.05");
    assert_eq!(value("load"), 20.0);
    assert!(json.get("relative_error").is_none());
    assert!((value("centre_deflection") - 0.05).abs() < 1e-4);
    assert!(value("max_deflection") < 0.0501);
    assert!(value("complementarity_residual") <= 1e-10);
    let (force, j) = (value("total_contact_force"), value("energy"));
    assert!(force > 0.0);
    // the cell-wise constraint adds `−α Σ_T h_T⁴ (λ_h − q) λ_h |T|` to ∫ s w_h λ_h, of
    // order α h⁴ q² r_c² ≈ 1e-4 here (measured 1.1e-4 relative); a wrong shear weight in
    // J_h or a wrong sign of λ_h is off by O(1)
    let identity = -0.5 * 20.0 * value("deflection_integral") - 0.5 * 0.05 * force;
    assert!(
        (j - identity).abs() <= 5e-4 * j.abs(),
        "J_h = {j}, −½q∫w − ½ψ∫λ = {identity}"
    );
    assert!((value("lambda_interior_mean") - 20.0).abs() < 0.2);
    // the contact set is close to a disk: its area and its radius along rays agree
    let (area, radius) = (value("contact_area"), value("contact_radius"));
    assert!(
        (radius - (area / std::f64::consts::PI).sqrt()).abs() < 0.05,
        "radius {radius}, area {area}"
    );
    // 32 rings, the unknowns left by the clamped circle (192 vertices, 192 edges): θ
    // (2 · inner vertices), w (inner vertices and edges) and λ (cells)
    let (vertices, cells) = (1 + 3 * 32 * 33, 6 * 32 * 32);
    let edges = vertices + cells - 1;
    let rim = 6 * 32;
    assert_eq!(
        json["dofs"].as_u64().unwrap() as usize,
        2 * (vertices - rim) + (vertices - rim) + (edges - rim) + cells
    );
    let levels = json["levels"].as_array().unwrap();
    assert_eq!(levels.len(), 4, "rings 4, 8, 16, 32");
    for level in levels {
        assert!(level[1].as_u64().unwrap() <= 6, "{levels:?}");
    }
}

/// `--cold` solves the same discrete problem from zero on the finest mesh alone: one
/// level, more Newton steps, the same J_h and ∫λ_h as the nested solve.
#[test]
fn a_cold_start_solves_the_same_disk_problem() {
    let nested = scene_json("mindlin-disk", &["--mesh-size", "16"]);
    let cold = scene_json("mindlin-disk", &["--mesh-size", "16", "--cold"]);
    assert_eq!(cold["levels"].as_array().unwrap().len(), 1);
    assert_eq!(nested["levels"].as_array().unwrap().len(), 3);
    assert!(cold["iterations"].as_u64() > nested["iterations"].as_u64());
    for field in ["energy", "total_contact_force", "contact_area"] {
        let (a, b) = (
            nested[field].as_f64().unwrap(),
            cold[field].as_f64().unwrap(),
        );
        assert!((a - b).abs() <= 1e-9 * a.abs(), "{field}: {a} and {b}");
    }
}

/// Without its obstacle the disk's centre deflection is the closed form
/// `q/64 + q t²/14` (t = 0.01, q = 20: 0.3126428571); the polygonal ring mesh's error
/// falls with h and is below 1e-3 on 32 rings.
#[test]
fn the_unobstructed_disk_meets_its_closed_form() {
    let errors: Vec<f64> = ["16", "32"]
        .iter()
        .map(|n| {
            let json = scene_json("mindlin-disk", &["--no-obstacle", "--mesh-size", n]);
            assert_eq!(json["obstacle"], "none");
            let reference = json["unobstructed_reference"].as_f64().unwrap();
            assert!((reference - 0.3126428571).abs() < 1e-10, "{reference}");
            assert_eq!(json["total_contact_force"].as_f64().unwrap(), 0.0);
            let w = json["centre_deflection"].as_f64().unwrap();
            assert!(
                (json["relative_error"].as_f64().unwrap() - (w - reference) / reference).abs()
                    < 1e-12
            );
            (w - reference) / reference
        })
        .collect();
    assert!(errors[1].abs() < errors[0].abs(), "{errors:?}");
    assert!(errors[1].abs() < 1e-3, "{errors:?}");
    // q = 10 still touches: the free plate would rise to 0.156 > 0.05
    let touching = scene_json("mindlin-disk", &["--load", "10", "--mesh-size", "16"]);
    assert!(touching["total_contact_force"].as_f64().unwrap() > 0.0);
}

#[test]
fn bad_disk_input_exits_with_a_message() {
    for (scene, args, message) in [
        ("mindlin-disk", &["--thickness", "0"][..], "thickness t = 0"),
        (
            "mindlin-disk",
            &["--thickness", "3"][..],
            "exceeds the plate's diameter 2",
        ),
        (
            "mindlin-disk",
            &["--load", "NaN"][..],
            "--load NaN must be finite",
        ),
        (
            "mindlin-disk",
            &["--load", "inf"][..],
            "--load inf must be finite",
        ),
        (
            "mindlin-disk",
            &["--load", "1e300"][..],
            "--load 1e300 is beyond",
        ),
        (
            "mindlin-disk",
            // 960k curved cells: refused by the memory estimate, before any mesh is built
            &["--mesh-size", "400"][..],
            "--mesh-size 400 with p1-p2-p0 needs about",
        ),
        (
            "mindlin-disk",
            &["--thickness", "1e-9"][..],
            "thickness t = 1e-9 is below 1e-8",
        ),
        (
            "mindlin-disk",
            &["--msh", "x.msh"][..],
            "--msh does not apply",
        ),
        (
            "mindlin-disk",
            &["--load", "1e20"][..],
            "w_h is lost to rounding",
        ),
        (
            "mindlin-disk",
            &["--alpha", "1e300"][..],
            "w_h is lost to rounding",
        ),
        ("mindlin-disk", &["--alpha", "-0.1"][..], "α = -0.1"),
        (
            "mindlin-disk",
            &["--no-obstacle", "--alpha", "0.1"][..],
            "--alpha does not apply",
        ),
        (
            "mindlin-square",
            &["--no-obstacle"][..],
            "`mindlin-square` has no obstacle",
        ),
        (
            "mindlin-square-ss",
            &["--pair", "p1-p1-p0-plain"][..],
            "pair `p1-p1-p0-plain` does not discretize scene `mindlin-square-ss`",
        ),
    ] {
        let mut all = vec!["solve", scene];
        all.extend_from_slice(args);
        let run = fem_forms(&all);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(!run.status.success(), "{all:?} succeeded");
        assert!(stderr.contains(message), "{all:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{all:?}: {stderr}");
    }
}

/// `study mindlin-disk` writes both charts and tables for each of its loads (its study
/// variants q = 10, 20, 50): nested iterations flat (at most 6 on every mesh), and the
/// Stenberg pair's J_h converging (its change to the next mesh shrinking).
#[test]
fn the_disk_studies_write_their_charts_and_tables() {
    let out = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("fem-forms-disk-study-{}", std::process::id()));
    let run = Command::new(env!("CARGO_BIN_EXE_fem-forms"))
        .args(["study", "mindlin-disk", "--out"])
        .arg(&out)
        .output()
        .expect("the binary runs");
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    // the cells of a CSV file, by row
    let rows = |file: &str| -> Vec<Vec<String>> {
        std::fs::read_to_string(out.join(file))
            .unwrap()
            .lines()
            .skip(1)
            .map(|l| l.split(',').map(str::to_string).collect())
            .collect()
    };
    let number = |cell: &str| -> f64 { cell.parse().unwrap() };
    for q in ["q10", "q20", "q50"] {
        for study in ["iterations", "convergence"] {
            let svg =
                std::fs::read_to_string(out.join(format!("mindlin-disk-{q}-{study}.svg"))).unwrap();
            assert!(svg.contains("<svg"));
        }
        let iterations = rows(&format!("mindlin-disk-{q}-iterations.csv"));
        assert_eq!(iterations.len(), 3, "rings 8, 16, 32");
        assert!(
            iterations.iter().all(|r| number(&r[1]) <= 6.0),
            "{q}: {iterations:?}"
        );
        // pair, size, h, cells, dofs, five errors, energy, …
        let j: Vec<f64> = rows(&format!("mindlin-disk-{q}-convergence.csv"))
            .iter()
            .filter(|r| r[0] == "p1-p2-p0")
            .map(|r| number(&r[10]))
            .collect();
        assert_eq!(j.len(), 3);
        assert!((j[2] - j[1]).abs() < (j[1] - j[0]).abs(), "{q}: {j:?}");
    }
    std::fs::remove_dir_all(&out).unwrap();
}

/// What a coarse or odd solve must not hide: a plate that crosses its obstacle is
/// reported (`max_penetration`) and warned about; a small contact set that misses the
/// centre's cells still has a radius, and its "interior" λ_h (the smeared line force
/// only) is not reported as λ.
#[test]
fn penetration_and_small_contact_sets_are_reported_honestly() {
    let run = fem_forms(&["solve", "mindlin-disk", "--mesh-size", "4", "--json"]);
    assert!(run.status.success());
    let json: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
    let penetration = json["max_penetration"].as_f64().unwrap();
    // the JSON's own max w_h above ψ = 0.05
    let above = json["max_deflection"].as_f64().unwrap() - 0.05;
    assert!(
        penetration > 1e-3 && (penetration - above).abs() < 1e-12,
        "{json}"
    );
    let warnings = json["warnings"].as_array().unwrap();
    assert!(
        warnings
            .iter()
            .any(|w| w.as_str().unwrap().contains("rises above ψ")),
        "{json}"
    );
    let small = scene_json("mindlin-disk", &["--mesh-size", "32", "--load", "7"]);
    let area = small["contact_area"].as_f64().unwrap();
    let radius = small["contact_radius"].as_f64().unwrap();
    assert!(area > 0.0 && radius > 0.0, "{small}");
    if let Some(mean) = small["lambda_interior_mean"].as_f64() {
        assert!((mean - 7.0).abs() < 0.5, "{small}");
    }
}

/// No load on a plate without an obstacle: w = 0 exactly, the free plate's report with an
/// error of 0 (it was NaN, which switched the line to the contact report's "contact
/// radius NaN").
#[test]
fn an_unloaded_plate_reports_a_zero_error() {
    let json = solve_json(&["--load", "0"]);
    assert_eq!(json["centre_deflection"].as_f64(), Some(0.0));
    assert_eq!(json["relative_error"].as_f64(), Some(0.0));
    let run = fem_forms(&["solve", "mindlin-square", "--load", "0"]);
    let text = String::from_utf8_lossy(&run.stdout);
    assert!(run.status.success());
    // against Kirchhoff's value the text says the models' difference is in it (a
    // tester took 13.6 % at t = 0.1 for a discretization error)
    assert!(
        text.contains("relative_error 0") && !text.contains("NaN"),
        "{text}"
    );
}

/// α = 10 on a 4×4 disk mesh lets α h⁴ q open the stabilized constraint: λ_h pushes on
/// cells where w_h stays clear of ψ = 0.05 by most of it, and the report says so with
/// the gap it measured and the size it compares with. The default α on a finer mesh
/// gives no such warning.
#[test]
fn a_plate_whose_contact_set_is_not_real_is_warned_about() {
    let json = scene_json("mindlin-disk", &["--alpha", "10", "--mesh-size", "4"]);
    let gap = json["max_open_contact_gap"].as_f64().unwrap();
    // ψ = 0.05 is the plate's size here; the gap must be a visible share of it and
    // cannot exceed the obstacle's height above the clamped rim
    assert!(gap > 0.01 * 0.05 && gap <= 0.05, "{json}");
    let warnings = json["warnings"].to_string();
    assert!(
        warnings.contains(&format!("{gap:.2e}")) && warnings.contains("max(|w_h|, |ψ|) = 5.00e-2"),
        "{warnings}"
    );
    let json = scene_json("mindlin-disk", &["--mesh-size", "16"]);
    assert!(
        !json["warnings"]
            .to_string()
            .contains("clear of the obstacle"),
        "{json}"
    );
}

/// A third tester's plate findings: an odd N (no coarser nested level) started Newton
/// cold without a word, and `--cold` then changed nothing; without an obstacle the plate
/// was solved on every nested level although the refusal of `--alpha` called it one
/// linear solve, and its JSON reported an α; kirchhoff-square at q = 0 had a null
/// relative error where the Mindlin plates report 0; the refusal on mindlin-square listed
/// options it refuses.
#[test]
fn plates_say_when_nesting_is_lost_and_solve_unobstructed_once() {
    let odd = scene_json("mindlin-disk", &["--mesh-size", "33"]);
    assert!(odd["warnings"].to_string().contains("is odd"), "{odd}");
    assert_eq!(odd["levels"].as_array().unwrap().len(), 1, "{odd}");
    let even = scene_json("mindlin-disk", &["--mesh-size", "32"]);
    assert!(!even["warnings"].to_string().contains("nested"), "{even}");
    let free = scene_json("mindlin-disk", &["--no-obstacle", "--mesh-size", "16"]);
    assert_eq!(free["levels"].as_array().unwrap().len(), 1, "{free}");
    assert!(free["alpha"].is_null(), "{free}");
    assert!(!even["alpha"].is_null(), "{even}");
    let unloaded = scene_json("kirchhoff-square", &["--load", "0"]);
    assert_eq!(unloaded["relative_error"].as_f64(), Some(0.0), "{unloaded}");
    let run = fem_forms(&["solve", "mindlin-square", "--plot"]);
    let errors = String::from_utf8_lossy(&run.stderr);
    assert!(
        errors.contains("--plot does not apply") && !errors.contains("--alpha"),
        "{errors}"
    );
}

/// The square (it has no obstacle): its relative_error is against Kirchhoff's t → 0 limit:
/// a tester's t = 1 read +1672 % as the discretization's error. A thick plate says so;
/// a thin one (the default t) does not.
#[test]
fn a_thick_plates_error_against_kirchhoff_is_explained() {
    let warned = |json: &serde_json::Value| {
        json["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .any(|w| w.as_str().unwrap().contains("the limit t → 0"))
    };
    let thick = solve_json(&["--thickness", "0.5", "--mesh-size", "8"]);
    assert!(warned(&thick), "{thick}");
    let thin = solve_json(&["--mesh-size", "8"]);
    assert!(!warned(&thin), "{thin}");
}

/// A support changed on the command line changes the reference: the square's series of
/// the new support, and none where no closed form exists (a disk not clamped).
#[test]
fn the_reference_follows_the_support_asked_for() {
    let clamped = scene_json(
        "mindlin-square-ss",
        &["--support", "clamped", "--thickness", "1e-3"],
    );
    // q = D = a = 1: the clamped square's Kirchhoff coefficient itself
    assert_eq!(clamped["reference_centre_deflection"], 0.00126532);
    let relative = clamped["relative_error"].as_f64().unwrap();
    assert!(relative.abs() < 2e-2, "{relative}");
    let simple = scene_json(
        "mindlin-square",
        &["--support", "simply-supported-hard", "--thickness", "1e-3"],
    );
    assert_eq!(simple["reference_centre_deflection"], 0.00406235);
    let disk = scene_json(
        "mindlin-disk",
        &[
            "--support",
            "simply-supported",
            "--no-obstacle",
            "--mesh-size",
            "4",
        ],
    );
    assert!(disk.get("reference_centre_deflection").is_none(), "{disk}");
    assert!(disk.get("kirchhoff_reference").is_none(), "{disk}");
}
