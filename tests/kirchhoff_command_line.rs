//! The Kirchhoff scenes from the command line: `kirchhoff-square` against the plate
//! series (Navier's for the simple support, summed here), `kirchhoff-obstacle`'s JSON
//! fields and what they must satisfy whatever the discretization, and bad input refused
//! with a message naming it, never a panic.

mod common;

use common::number;

fn fem_forms(args: &[&str]) -> std::process::Output {
    common::fem_forms(args, "kirchhoff-cli")
}

fn solve_json(scene: &str, args: &[&str]) -> serde_json::Value {
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

/// Navier's series for the centre deflection of the simply supported unit square under a
/// unit load with D = 1: `16/π⁶ Σ_{m,n odd} (−1)^{(m+n)/2−1} / (mn(m²+n²)²)`; its terms
/// fall like `1/m⁵`, so 400 odd terms each way leave less than 1e-13.
fn navier_centre_deflection() -> f64 {
    let mut sum = 0.0;
    for m in (1..800).step_by(2) {
        for n in (1..800).step_by(2) {
            let sign = if ((m + n) / 2 - 1) % 2 == 0 {
                1.0
            } else {
                -1.0
            };
            let (m, n) = (m as f64, n as f64);
            sum += sign / (m * n * (m * m + n * n).powi(2));
        }
    }
    16.0 / std::f64::consts::PI.powi(6) * sum
}

/// The clamped square at the default mesh (N = 16) reproduces `0.00126532 q a⁴/D` to its
/// six digits (within half a unit of the last), for q = 1 and q = 3 (linear in q); the
/// simply supported one Navier's series to 1e-7.
#[test]
fn kirchhoff_square_matches_the_series() {
    let series = navier_centre_deflection();
    assert!((series - 0.00406235).abs() < 5e-9, "series {series}");
    for q in [1.0, 3.0] {
        let load = q.to_string();
        let json = solve_json("kirchhoff-square", &["--load", &load]);
        let w = number(&json, "centre_deflection");
        assert!(
            (w - 0.00126532 * q).abs() <= 0.5e-8 * q,
            "clamped q = {q}: {w}"
        );
        assert_eq!(number(&json, "total_contact_force"), 0.0);
        assert_eq!(number(&json, "contact_area"), 0.0);
        let json = solve_json(
            "kirchhoff-square",
            &["--load", &load, "--support", "simply-supported"],
        );
        let w = number(&json, "centre_deflection");
        assert!(
            ((w - series * q) / (series * q)).abs() < 1e-7,
            "simply supported q = {q}: {w} vs {}",
            series * q
        );
        assert!(number(&json, "complementarity_residual") < 1e-10);
    }
}

/// kirchhoff-obstacle at q = 5 and 20, flat and curved: the JSON has every field of the
/// issue; the plate stays under the obstacle at the centre and, for the flat one,
/// everywhere (to 1 % of the gap: the constraint holds cell by cell on the mean), the contact force is positive and below the load (the
/// supports carry the rest), the contact area lies inside the square, the interior
/// energy lies between the unobstructed plate's and 0 (the obstacle raises the minimum;
/// the plate at rest, w = 0, is admissible with J = 0).
#[test]
fn kirchhoff_obstacle_reports_what_the_issue_asks() {
    for (q, obstacle) in [(5.0, "flat"), (20.0, "curved"), (20.0, "flat")] {
        let load = format!("{q}");
        let json = solve_json(
            "kirchhoff-obstacle",
            &["--load", &load, "--obstacle", obstacle, "--mesh-size", "16"],
        );
        for field in [
            "energy",
            "max_deflection",
            "total_contact_force",
            "contact_area",
            "dofs",
            "iterations",
            "levels",
            "seconds",
            "complementarity_residual",
        ] {
            assert!(
                json.get(field).is_some_and(|v| !v.is_null()),
                "{field} missing"
            );
        }
        let what = format!("q = {q} {obstacle}");
        // ψ(centre) = 0.002 for both; the flat obstacle bounds w everywhere
        assert!(number(&json, "centre_deflection") <= 0.002 * 1.01, "{what}");
        if obstacle == "flat" {
            assert!(number(&json, "max_deflection") <= 0.002 * 1.01, "{what}");
        }
        let force = number(&json, "total_contact_force");
        assert!(force > 0.0 && force < q, "{what}: ∫λ_h = {force}");
        let area = number(&json, "contact_area");
        assert!(area > 0.0 && area < 1.0, "{what}: area {area}");
        let energy = number(&json, "energy");
        // the clamped plate without an obstacle: J = −½ ∫ f w = −½ q² ∫ w₁ < 0, and
        // ∫ w₁ < w₁(centre) = 0.00126532 bounds it from below
        assert!(
            energy < 0.0 && energy > -0.5 * q * q * 0.00126532,
            "{what}: J_h = {energy}"
        );
        assert!(number(&json, "complementarity_residual") < 1e-10, "{what}");
        let levels = json["levels"].as_array().unwrap();
        assert_eq!(levels.len(), 3, "{what}: N = 4, 8, 16");
    }
}

#[test]
fn bad_kirchhoff_input_is_refused_by_name() {
    let cases: [(&[&str], &str); 12] = [
        (
            &["solve", "kirchhoff-obstacle", "--load", "1e100"],
            "lost to rounding",
        ),
        (
            &["solve", "kirchhoff-obstacle", "--alpha", "1"],
            "stability range",
        ),
        (
            &["solve", "kirchhoff-obstacle", "--no-obstacle"],
            "--no-obstacle",
        ),
        (
            &["solve", "kirchhoff-obstacle", "--linear-solver", "bogus"],
            "--linear-solver",
        ),
        (
            &["solve", "kirchhoff-square", "--support", "glued"],
            "glued",
        ),
        (
            &["solve", "kirchhoff-obstacle", "--obstacle", "round"],
            "round",
        ),
        (&["solve", "kirchhoff-obstacle", "--pair", "p2-p0"], "p2-p0"),
        (
            &["solve", "kirchhoff-obstacle", "--mesh-size", "0"],
            "--mesh-size 0 is out of range",
        ),
        (&["solve", "kirchhoff-obstacle", "--alpha", "-1"], "α"),
        // inside the stability range but near the plain method: the failure names α
        (
            &["solve", "kirchhoff-obstacle", "--alpha", "1e-12"],
            "or a larger α",
        ),
        // a thickness poses the Reissner–Mindlin plate the Kirchhoff one stands for
        (
            &["solve", "kirchhoff-obstacle", "--thickness", "0"],
            "thickness t = 0 must be positive",
        ),
        (
            &["solve", "membrane-flat", "--support", "clamped"],
            "--support",
        ),
    ];
    for (args, named) in cases {
        let run = fem_forms(args);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(
            stderr.starts_with("error:") && stderr.contains(named),
            "{args:?}: {stderr}"
        );
    }
}

/// Below the refusal (1e-3), a rounding of w_h through the contact rows above 1e-8 is
/// a warning, as for beams and membranes: a tester's q = 5e16 was silent, and q = 1e17
/// refused.
#[test]
fn rounding_below_the_refusal_is_a_warning() {
    let warned = |json: &serde_json::Value| {
        json["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .any(|w| w.as_str().unwrap().contains("may be off by"))
    };
    let heavy = solve_json("kirchhoff-obstacle", &["--load", "5e16"]);
    assert!(warned(&heavy), "{heavy}");
    let plain = solve_json("kirchhoff-obstacle", &[]);
    assert!(!warned(&plain), "{plain}");
}

/// A mesh whose supports fix every DOF to 0 is refused, not solved to u ≡ 0 (the
/// trapezoid of five cells has no interior vertex: under membrane-flat's u = 0 its P1
/// membrane has nothing left to solve); a mesh with few free unknowns is solved with a
/// warning (the clamped Argyris square on one cell per corner keeps one, Morley's simply
/// supported one, 294 % off at the centre, five); and the mesh limit is each pair's own
/// memory estimate: Morley passes N = 200, beyond the Argyris limit of the shared
/// machine, and matches Navier's value there (Morley converges as h², 1.2e-4 off at N = 200), while Argyris with the obstacle at N = 256
/// is refused with the memory it would need.
#[test]
fn meshes_without_free_unknowns_are_refused_and_each_pair_has_its_own_limit() {
    let trapezoid = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/trapezoid_parametric.msh"
    );
    let run = fem_forms(&[
        "solve",
        "membrane-flat",
        "--msh",
        trapezoid,
        "--pair",
        "p1-p0",
    ]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        !run.status.success() && stderr.contains("fix every DOF"),
        "{stderr}"
    );
    for (scene, args) in [
        ("kirchhoff-obstacle", &["--mesh-size", "1"][..]),
        (
            "kirchhoff-square",
            &[
                "--mesh-size",
                "1",
                "--pair",
                "morley-p0",
                "--support",
                "simply-supported",
            ][..],
        ),
    ] {
        let coarse = solve_json(scene, args);
        assert!(
            coarse["warnings"]
                .to_string()
                .contains("free primal unknowns"),
            "{coarse}"
        );
    }
    let fine = solve_json(
        "kirchhoff-square",
        &[
            "--mesh-size",
            "200",
            "--pair",
            "morley-p0",
            "--support",
            "simply-supported",
        ],
    );
    let w = number(&fine, "centre_deflection");
    assert!(
        (w / navier_centre_deflection() - 1.0).abs() < 2e-4,
        "Morley N = 200: {w}"
    );
    let run = fem_forms(&["solve", "kirchhoff-obstacle", "--mesh-size", "256"]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        !run.status.success() && stderr.contains("--mesh-size 256 with argyris-p0 needs about"),
        "{stderr}"
    );
}

/// `study kirchhoff-square convergence` through the one study implementation, on the
/// scene's two variants (clamped, simply supported): J_h converges at rates above 5 for
/// Argyris from successive differences (no reference needed), near 1.5–2 for Morley,
/// and the error of the centre deflection against the series falls for both; the simply
/// supported Argyris deflection at N = 32 meets Navier's series (summed here) to 1e-8.
#[test]
fn the_square_convergence_study_shows_each_elements_rate() {
    let run = fem_forms(&["study", "kirchhoff-square", "convergence"]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let out = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("fem-forms-kirchhoff-cli-{}", std::process::id()));
    for support in ["clamped", "simply-supported"] {
        let file = out.join(format!("kirchhoff-square-{support}-convergence.csv"));
        let csv = std::fs::read_to_string(file).unwrap();
        // pair, size, h, cells, dofs, five errors, energy, ∫λ, contact, reference error, …
        let rows: Vec<Vec<&str>> = csv
            .lines()
            .skip(1)
            .map(|l| l.split(',').collect())
            .collect();
        for (pair, low, high) in [("argyris-p0", 5.0, 7.5), ("morley-p0", 1.4, 2.2)] {
            let column = |k: usize| -> Vec<f64> {
                rows.iter()
                    .filter(|r| r[0] == pair)
                    .map(|r| r[k].parse().unwrap())
                    .collect()
            };
            let j = column(10);
            assert_eq!(j.len(), 3, "{support} {pair}: {csv}");
            let rate = ((j[1] - j[0]) / (j[2] - j[1])).abs().log2();
            assert!(rate > low && rate < high, "{support} {pair}: rate {rate}");
            let errors = column(13);
            assert!(
                errors.windows(2).all(|e| e[1] < e[0]),
                "{support} {pair}: {errors:?}"
            );
        }
    }
    let report = solve_json(
        "kirchhoff-square",
        &["--support", "simply-supported", "--mesh-size", "32"],
    );
    let w = report["centre_deflection"].as_f64().unwrap();
    let navier = navier_centre_deflection();
    assert!((w / navier - 1.0).abs() < 1e-8, "{w} against {navier}");
}

/// A study variant runs on its own (`study kirchhoff-square-clamped convergence`
/// writes that variant's files and not the other's), `list` names the variants, and a
/// misspelt variant is an unknown scene.
#[test]
fn a_study_variant_runs_on_its_own() {
    let run = common::fem_forms(
        &["study", "kirchhoff-square-clamped", "convergence"],
        "kirchhoff-variant",
    );
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let out = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!(
        "fem-forms-kirchhoff-variant-{}",
        std::process::id()
    ));
    assert!(out
        .join("kirchhoff-square-clamped-convergence.csv")
        .exists());
    assert!(!out
        .join("kirchhoff-square-simply-supported-convergence.csv")
        .exists());
    let list = fem_forms(&["list"]);
    let text = String::from_utf8_lossy(&list.stdout);
    assert!(
        text.contains("studied as its variants clamped, simply-supported"),
        "{text}"
    );
    let run = fem_forms(&["study", "kirchhoff-square-clampd", "convergence"]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        !run.status.success() && stderr.contains("`kirchhoff-square-clampd` is not a scene"),
        "{stderr}"
    );
    std::fs::remove_dir_all(&out).unwrap();
}

/// `--tol` on the plate obstacle: from a 4×4×2 mesh the adaptive run stops with the
/// estimate below the tolerance, the contact found and the KKT conditions held on the
/// final mesh.
#[test]
fn tol_refines_the_plate_obstacle_adaptively() {
    for pair in ["argyris-p0", "morley-p0"] {
        let tol = if pair == "morley-p0" { "0.2" } else { "2e-3" };
        let report = solve_json(
            "kirchhoff-obstacle",
            &["--tol", tol, "--mesh-size", "4", "--pair", pair],
        );
        let levels = report["adaptive_levels"].as_array().unwrap();
        assert!(levels.len() >= 3, "{pair}: {levels:?}");
        let last = levels.last().unwrap();
        let (estimate, norm) = (
            last["estimate"].as_f64().unwrap(),
            last["energy_norm"].as_f64().unwrap(),
        );
        let tol: f64 = tol.parse().unwrap();
        assert!(estimate <= tol * norm, "{pair}: {last}");
        let estimates: Vec<f64> = levels
            .iter()
            .map(|l| l["estimate"].as_f64().unwrap())
            .collect();
        assert!(
            estimates.last().unwrap() < &(0.5 * estimates[0]),
            "{pair}: {estimates:?}"
        );
        assert!(number(&report, "contact_area") > 0.0, "{pair}: {report}");
        assert!(number(&report, "kkt_residual") < 1e-8, "{pair}: {report}");
    }
}
