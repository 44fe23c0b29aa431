//! Scene files of the one reader for the plate families: problems that could not be
//! posed without Rust before (a plate on another domain with each edge's support named),
//! checked against independent values.

use std::process::Command;

fn solve_json(args: &[&str]) -> serde_json::Value {
    let out = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("fem-forms-scene-families-{}", std::process::id()));
    let run = Command::new(env!("CARGO_BIN_EXE_fem-forms"))
        .arg("solve")
        .args(args)
        .arg("--json")
        .arg("--out")
        .arg(&out)
        .output()
        .expect("the binary runs");
    assert!(
        run.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&run.stderr)
    );
    serde_json::from_slice(&run.stdout).unwrap()
}

/// The strip clamped at one end and simply supported at the other bends like a propped
/// cantilever of length L = 2, `w(x) = q/(48 EI) (L³x − 3Lx³ + 2x⁴)`: its deflection at
/// mid-span, `q/(12 EI)`, lies between the cylindrical bending of a wide plate
/// (EI = D) and the beam of a narrow one with free edges (EI = D(1 − ν²)); t = 0.01 leaves
/// the Mindlin plate within 1e-3 of Kirchhoff's.
#[test]
fn a_plate_strip_with_mixed_supports_bends_like_a_propped_cantilever() {
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/scenes/plate_mixed_supports.toml"
    );
    let report = solve_json(&["--scene", file]);
    let w = report["centre_deflection"].as_f64().unwrap().abs();
    let (d, nu) = (1.0, 0.3);
    let wide = 1.0 / (12.0 * d);
    let narrow = 1.0 / (12.0 * d * (1.0 - nu * nu));
    assert!(wide < w && w < narrow, "{wide} < {w} < {narrow}");
    assert_eq!(report["supports"].as_array().unwrap().len(), 3);
}

/// The simply supported unit square Kirchhoff plate of a scene file on Argyris against
/// Navier's centre deflection 0.00406235 q/D (to 1e-6 at N = 8: Argyris is quintic).
#[test]
fn a_kirchhoff_scene_file_meets_navier() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("kirchhoff-file-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("ss.toml");
    std::fs::write(
        &path,
        "model = \"kirchhoff\"\npair = \"argyris-p0\"\n[mesh]\ngenerator = \"rectangle\"\nsize = 8\n[boundary]\nsimply_supported = \"all\"\n[parameters]\nD = 2.0\nnu = 0.3\n[data]\nf = \"1\"\npsi = \"-1\"\n",
    )
    .unwrap();
    let report = solve_json(&["--scene", path.to_str().unwrap()]);
    let w = report["centre_deflection"].as_f64().unwrap();
    let navier = 0.004_062_353_5 / 2.0;
    assert!((w / navier - 1.0).abs() < 1e-6, "{w} against {navier}");
    std::fs::remove_dir_all(&dir).unwrap();
}

fn run_file(dir: &std::path::Path, name: &str, text: &str) -> std::process::Output {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    Command::new(env!("CARGO_BIN_EXE_fem-forms"))
        .args(["solve", "--scene"])
        .arg(&path)
        .args(["--json", "--out"])
        .arg(dir)
        .output()
        .unwrap()
}

/// What a file may get wrong is refused or named: a beam file solves (its size is its
/// elements), a family on the other dimension's mesh is refused, two supports on one part
/// are refused, a non-positive declared parameter is refused before anything is computed
/// from it, a left-out obstacle is named, a given gradient wrong only near an edge is
/// caught, and a flat obstacle's crossing is judged against the answer's size.
#[test]
fn scene_file_mistakes_are_refused_or_named() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("scene-file-mistakes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let stderr = |o: &std::process::Output| String::from_utf8_lossy(&o.stderr).to_string();
    let beam = "model = \"beam\"\n[mesh]\ngenerator = \"interval\"\nsize = 8\n[boundary]\nclamped = \"all\"\n[parameters]\nthickness = 0.1\n[data]\nf = \"-1\"\npsi = \"-0.05\"\n";
    let o = run_file(&dir, "beam.toml", beam);
    assert!(o.status.success(), "{}", stderr(&o));
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(json["cells"], 8);
    let o = run_file(
        &dir,
        "beam2d.toml",
        &beam.replace("\"interval\"", "\"rectangle\""),
    );
    assert!(
        !o.status.success() && stderr(&o).contains("posed on an interval"),
        "{}",
        stderr(&o)
    );
    let plate = "model = \"winkler\"\n[mesh]\ngenerator = \"rectangle\"\nsize = 4\n[boundary]\nclamped = \"left\"\nfree = \"left\"\n[parameters]\nD = 1.0\nnu = 0.3\nfoundation_modulus = 100.0\n[data]\nf = \"-1\"\npsi = \"-1\"\n";
    let o = run_file(&dir, "overlap.toml", plate);
    assert!(
        !o.status.success() && stderr(&o).contains("give each part one support"),
        "{}",
        stderr(&o)
    );
    let single = plate.replace("free = \"left\"\n", "");
    let o = run_file(
        &dir,
        "negative.toml",
        &single.replace("D = 1.0", "D = -1.0"),
    );
    assert!(
        !o.status.success() && stderr(&o).contains("`D` = -1 must be positive"),
        "{}",
        stderr(&o)
    );
    // the obstacle side is the scene's, not a parameter: named, not sent to the API
    let o = run_file(
        &dir,
        "side.toml",
        &single.replace("nu = 0.3", "nu = 0.3\ns = -1.0"),
    );
    assert!(
        !o.status.success()
            && stderr(&o).contains("parameters.s")
            && stderr(&o).contains("obstacle_side")
            && !stderr(&o).contains("Problem::side"),
        "{}",
        stderr(&o)
    );
    // an obstacle above (`w ≤ ψ`): pushed up into it, touching; a misspelt side named
    let above = format!(
        "obstacle_side = \"above\"\n{}",
        single
            .replace("f = \"-1\"", "f = \"1\"")
            .replace("psi = \"-1\"", "psi = \"0.001\"")
    );
    let o = run_file(&dir, "above.toml", &above);
    assert!(o.status.success(), "{}", stderr(&o));
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(
        json["total_contact_force"].as_f64().unwrap() > 0.0,
        "{json}"
    );
    let o = run_file(
        &dir,
        "sideways.toml",
        &above.replace("\"above\"", "\"sideways\""),
    );
    assert!(
        !o.status.success() && stderr(&o).contains("field `obstacle_side`"),
        "{}",
        stderr(&o)
    );
    let o = run_file(&dir, "nopsi.toml", &single.replace("psi = \"-1\"\n", ""));
    assert!(o.status.success(), "{}", stderr(&o));
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(
        json["warnings"]
            .to_string()
            .contains("gives no obstacle `ψ`"),
        "{json}"
    );
    // wrong only for y < 0.1: the lattice samples that strip
    let membrane = "model = \"membrane\"\n[mesh]\ngenerator = \"rectangle\"\nx = [10.0, 11.0]\ny = [0.0, 1.0]\nsize = 8\n[data]\nf = \"0\"\npsi = \"-1\"\ng = \"abs(x-10.5)\"\n[exact]\nu = \"abs(x-10.5)\"\ngradient = [\"(x-10.5)/abs(x-10.5)*(1+100*max(0.1-y,0))\", \"0\"]\n";
    let o = run_file(&dir, "strip.toml", membrane);
    assert!(
        !o.status.success() && stderr(&o).contains("exact.gradient"),
        "{}",
        stderr(&o)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A manufactured Kirchhoff plate from a scene file with its exact Hessian: the simply
/// supported unit square under `f = 4π⁴ D sin(πx) sin(πy)` bends as `w = sin(πx) sin(πy)`
/// (`Δ²w = 4π⁴ w`, and `w = w_nn = 0` on the edges), far from its obstacle. The broken
/// H² error the report computes from `[exact] hessian` falls at Argyris's O(h⁴) and
/// Morley's O(h).
#[test]
fn an_exact_hessian_gives_the_h2_error_at_each_elements_rate() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("kirchhoff-hessian-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("manufactured.toml");
    std::fs::write(
        &path,
        r#"model = "kirchhoff"
[mesh]
generator = "rectangle"
[boundary]
simply_supported = "all"
[parameters]
D = 1.0
nu = 0.3
[data]
f = "4*PI^4*sin(PI*x)*sin(PI*y)"
psi = "-10"
[exact]
w = "sin(PI*x)*sin(PI*y)"
hessian = [["-(PI^2)*sin(PI*x)*sin(PI*y)", "PI^2*cos(PI*x)*cos(PI*y)"],
           ["PI^2*cos(PI*x)*cos(PI*y)", "-(PI^2)*sin(PI*x)*sin(PI*y)"]]
"#,
    )
    .unwrap();
    let path = path.to_str().unwrap();
    for (pair, low, high) in [("argyris-p0", 3.6, 4.6), ("morley-p0", 0.8, 1.2)] {
        let errors: Vec<f64> = ["4", "8", "16"]
            .iter()
            .map(|n| {
                let r = solve_json(&["--scene", path, "--pair", pair, "--mesh-size", n]);
                r["error_h2"].as_f64().unwrap()
            })
            .collect();
        for w in errors.windows(2) {
            let rate = (w[0] / w[1]).log2();
            assert!(rate > low && rate < high, "{pair}: H² errors {errors:?}");
        }
    }
}

/// Two spellings of one parameter or datum (a family's alias and the model's name), a
/// Hessian that is not 2 × 2 and derivatives without the exact value are refused by
/// their key: one of each pair used to win unseen, and a gradient without `u` gave
/// errors of NaN.
#[test]
fn ambiguous_and_incomplete_keys_are_refused() {
    let base = "model = \"membrane\"\n[mesh]\ngenerator = \"square\"\nsize = 4\n[data]\nf = \"0\"\npsi = \"-1\"\n";
    let path = std::path::Path::new("scene.toml");
    for (text, field, words) in [
        (
            format!("{base}\"ψ\" = \"-10\"\n"),
            "data.ψ",
            "both name the model's `ψ`",
        ),
        (
            format!("{base}[exact]\ngradient = [\"0\", \"0\"]\n"),
            "exact.gradient",
            "need its value",
        ),
        (
            format!(
                "{base}[exact]\nu = \"0\"\nhessian = [[\"0\", \"0\", \"1\"], [\"0\", \"0\"]]\n"
            ),
            "hessian",
            "two rows of two expressions",
        ),
        (
            format!("{base}[parameters]\nalpha = 0.1\n\"α\" = 0.2\n"),
            "parameters",
            "give it once",
        ),
    ] {
        let message = fem_forms::models::scene_file::parse(&text, path)
            .unwrap_err()
            .to_string();
        assert!(
            message.contains(field) && message.contains(words),
            "{field}: {message}"
        );
    }
}

/// `[mesh]` keys of another generator (or of a generator with a Gmsh file) are refused
/// by their key, not ignored: a square's `cells`, a disk's `x`, a file's `cells`.
#[test]
fn mesh_keys_of_another_generator_are_refused() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scene.toml");
    for (mesh, field) in [
        ("generator = \"square\"\ncells = [2, 2]", "mesh.cells"),
        ("generator = \"disk\"\nx = [0.0, 1.0]", "mesh.x"),
        (
            "generator = \"l-shape\"\ncentre = [0.0, 0.0]",
            "mesh.centre",
        ),
        ("generator = \"rectangle\"\nradius = 2.0", "mesh.radius"),
        ("file = \"square_named.msh\"\ncells = [2, 2]", "mesh.cells"),
    ] {
        let text =
            format!("model = \"membrane\"\n[mesh]\n{mesh}\n[data]\nf = \"0\"\npsi = \"-1\"\n");
        let message = fem_forms::models::scene_file::parse(&text, &path)
            .unwrap_err()
            .to_string();
        assert!(
            message.contains(&format!("`{field}`")) && message.contains("does not apply"),
            "{mesh}: {message}"
        );
    }
}
