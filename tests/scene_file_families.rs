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
