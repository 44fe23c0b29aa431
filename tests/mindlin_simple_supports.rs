//! The two simple supports of the Reissner–Mindlin square (`w = 0` soft, `w = 0` and
//! `θ·t = 0` hard), checked against independent values.
//!
//! The hard support has no boundary layer: its centre deflection is Kirchhoff's plus
//! the Marcus moment's share, `w_M = w_K + ℳ_K / S` with `ℳ_K = −D Δw_K` and the shear
//! stiffness `S = 6κ(1−ν)D/t²` (Wang, Reddy & Lee, *Shear deformable beams and plates*,
//! 2000: exact for simply supported polygonal plates), `ℳ_K` from Navier's series.
//! The soft support adds an O(t) boundary layer beyond that, and the report says so.

use serde_json::Value;

fn solve(args: &[&str]) -> Value {
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_fem-forms"))
        .args(["solve", "mindlin-square-ss", "--json"])
        .args(args)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&run.stderr)
    );
    serde_json::from_slice(&run.stdout).unwrap()
}

/// Navier's series for the simply supported unit square under q = D = 1 at its centre:
/// `(w_K, −Δw_K)`, 400 odd terms each way.
fn navier_centre() -> (f64, f64) {
    let pi = std::f64::consts::PI;
    let (mut w, mut laplacian) = (0.0, 0.0);
    for m in (1..800usize).step_by(2) {
        for n in (1..800usize).step_by(2) {
            let sign = if ((m + n) / 2 - 1) % 2 == 0 {
                1.0
            } else {
                -1.0
            };
            let (mf, nf) = (m as f64, n as f64);
            let s = mf * mf + nf * nf;
            let coefficient = 16.0 / (pi.powi(6) * mf * nf * s * s);
            w += sign * coefficient;
            laplacian += sign * coefficient * s * pi * pi;
        }
    }
    (w, laplacian)
}

#[test]
fn the_hard_support_follows_the_marcus_moment_and_the_soft_one_adds_a_layer() {
    let (w_k, marcus) = navier_centre();
    assert!((w_k - 0.00406235).abs() < 1e-8);
    // κ = 5/6, ν = 0.3, D = 1: S = 3.5/t²
    for t in [0.05, 0.02] {
        let t_text = t.to_string();
        let hard = solve(&[
            "--thickness",
            &t_text,
            "--support",
            "simply-supported-hard",
            "--mesh-size",
            "64",
        ]);
        let predicted = marcus * t * t / 3.5 / w_k;
        let measured = hard["relative_error"].as_f64().unwrap();
        // the discretization error at N = 64 is a few 1e-4 of the deflection
        assert!(
            (measured - predicted).abs() < 3e-4,
            "t = {t}: hard support {measured:.5} against Marcus {predicted:.5}"
        );
        assert!(!hard["warnings"].to_string().contains("boundary layer"));
        let soft = solve(&["--thickness", &t_text, "--mesh-size", "64"]);
        let layer = soft["relative_error"].as_f64().unwrap() - measured;
        // the layer is O(t): 0.6–1 t here, far above the models' O(t²)
        assert!(layer > 0.6 * t && layer < 1.0 * t, "t = {t}: layer {layer}");
        let warnings = soft["warnings"].to_string();
        assert!(
            warnings.contains("boundary layer") && warnings.contains("simply-supported-hard"),
            "{warnings}"
        );
    }
}
