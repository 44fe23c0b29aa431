//! Signorini contact with a continuous P1 multiplier on Γ_C (docs/contact.md): one DOF
//! per vertex of the contact edges. The LCP blocks against hand-coded values, Newton
//! against clarabel's QP on the same LCP and against the pipeline's solve, and the
//! command line's pairs. (The patch test of every pair is in `tests/signorini.rs`,
//! Hertz against the best continuous P1 fit in `tests/signorini_hertz.rs`.)
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

#[path = "common/contact.rs"]
mod contact;

use contact::Q;
use fem_forms::{Diagonal, TriangleMesh};

fn pressure(_x: &[f64]) -> f64 {
    Q
}

fn parabolic_gap(x: &[f64]) -> f64 {
    // the foundation curves away from the block's bottom: contact in the middle only
    0.02 * (x[0] - 0.5) * (x[0] - 0.5)
}

/// The LCP of P1–P1 on a uniform bottom (n edges of length 1/n, h_E = |E|) against the
/// blocks of docs/contact.md by hand: `C = α Σ_E h_E (μ_l, μ_k)_E` lumped by rows is
/// `α h²` at an interior vertex and `α h²/2` at the two ends; `B` applied to a unit
/// translation `t` along `n_c` is `−∫ μ_k ds` (σ_n(t) = 0); a constant gap g₀ gives
/// `G_k = −g₀ ∫ μ_k ds`. Then Newton against clarabel's QP on the same LCP with a
/// parabolic gap (only part of Γ_C touches), and the force against the load.
#[test]
fn the_lcp_blocks_by_hand_and_newton_against_the_qp() {
    use fem_forms::lcp::{quadratic_program, semismooth_newton, NewtonOptions};
    use fem_forms::models::families::contact::{lame, Plane};
    use fem_forms::models::signorini::signorini_p1_p1::{self, Model as M};
    use fem_forms::obstacle::boundary_multiplier::discretize_on_parts;
    use fem_forms::{Coefficients, DataFn, Model};
    let n = 8;
    let h = 1.0 / n as f64;
    let mesh = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, n, n, Diagonal::Alternating).unwrap();
    let (mu, lambda) = lame(1000.0, 0.3, Plane::Strain).unwrap();
    let alpha = 3e-4;
    let constant_gap = |_: &[f64]| 0.01;
    let problem = |alpha: f64, gap: &DataFn| {
        let coefficients = Coefficients::from_ids(
            &[
                (signorini_p1_p1::params::μ_L, mu),
                (signorini_p1_p1::params::λ_L, lambda),
                (signorini_p1_p1::params::α, alpha),
                (signorini_p1_p1::params::n_c_x, 0.0),
                (signorini_p1_p1::params::n_c_y, -1.0),
            ],
            &[
                (signorini_p1_p1::data::q, &pressure),
                (signorini_p1_p1::data::g, gap),
            ],
        )
        .unwrap();
        discretize_on_parts::<M, _, _>(
            &mesh,
            &coefficients,
            &[
                (signorini_p1_p1::facets::Γ_C, &[1]),
                (signorini_p1_p1::facets::Γ_N, &[3]),
            ],
            &[(signorini_p1_p1::fields::u_x, &[4])],
        )
        .unwrap()
    };
    let p = problem(alpha, &constant_gap);
    let b = p.boundary().expect("a multiplier on Γ_C");
    assert_eq!(p.lcp.m(), n + 1);
    assert!(p.lcp.c_blocks.is_empty(), "C is lumped: diagonal");
    // the vertices are those at y = 0, ascending; edge_dofs point at the edge's ends
    let vertices = mesh.vertices();
    for &v in &b.vertices {
        assert!(vertices[v][1].abs() < 1e-15);
    }
    for (e, dofs) in b.edges.iter().zip(&b.edge_dofs) {
        for (end, &k) in e.ends.iter().zip(dofs) {
            assert_eq!(vertices[b.vertices[k]], *end);
        }
    }
    let weights = b.integrals();
    for (k, &v) in b.vertices.iter().enumerate() {
        let at_end = vertices[v][0].abs() < 1e-12 || (vertices[v][0] - 1.0).abs() < 1e-12;
        let (c, w) = if at_end {
            (0.5 * alpha * h * h, 0.5 * h)
        } else {
            (alpha * h * h, h)
        };
        assert!(
            (p.lcp.c[k] - c).abs() <= 1e-14,
            "C_{k}: {} against {c}",
            p.lcp.c[k]
        );
        assert!((weights[k] - w).abs() <= 1e-15);
        assert!(
            (p.lcp.g[k] + 0.01 * w).abs() <= 1e-15,
            "G_{k}: {}",
            p.lcp.g[k]
        );
    }
    // a unit translation towards the foundation (u_y = −1 everywhere)
    let mut full = vec![0.0; p.dofs.dof_count()];
    let uy = M::field("u_y").unwrap();
    full[p.dofs.range(uy).unwrap()].fill(-1.0);
    let t: Vec<f64> = p.reduction.free().iter().map(|&d| full[d]).collect();
    for (k, b) in p.lcp.b_times(&t).iter().enumerate() {
        assert!(
            (b + weights[k]).abs() <= 1e-12,
            "(B t)_{k} = {b}, −∫μ_k = {}",
            -weights[k]
        );
    }

    // Newton against the QP on the LCP, with only part of Γ_C touching, at the α and
    // against the pressures of the pipeline's solve of the same block
    let file = contact::parse(&contact::block(&Q.to_string(), "0.02 * (x - 0.5)^2", ""));
    let s = contact::solve_file(&file, |s| {
        s.pair = Some("p1-p1".into());
        s.mesh_size = Some(n);
        s.diagonal = Some(Diagonal::Alternating);
    })
    .unwrap();
    let p = problem(s.report.solve.alpha.unwrap(), &parabolic_gap);
    let newton = semismooth_newton(
        &p.lcp,
        Some(&vec![-0.01; p.lcp.n()]),
        NewtonOptions::default(),
    )
    .unwrap();
    let qp = quadratic_program(&p.lcp).unwrap();
    let scale = qp.lambda.iter().fold(0.0f64, |m, &l| m.max(l));
    for (k, (a, b)) in newton.lambda.iter().zip(&qp.lambda).enumerate() {
        assert!(
            (a - b).abs() <= 1e-6 * scale,
            "vertex {k}: Newton {a}, QP {b}"
        );
    }
    // the boundary's vertices ascend along x, as the pipeline's pressure profile does
    let pipeline = s.pressures();
    assert_eq!(pipeline.len(), newton.lambda.len());
    for (k, (a, b)) in newton.lambda.iter().zip(&pipeline).enumerate() {
        assert!((a - b).abs() <= 1e-9 * scale, "vertex {k}: {a} against {b}");
    }
}

/// The command line's `p1-p1`, `p2-p1` pairs: the patch block (2 wide, 2N × N cells:
/// 2N + 1 pressure unknowns) gives λ_h = q, the foundation carries 2q; Hertz reports
/// the best P1 fit and no best P0 fit; `--plot` writes the chart.
#[test]
fn the_command_line_pairs() {
    use std::process::Command;
    let out = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("fem-forms-p1m-{}", std::process::id()));
    let run = |args: &[&str]| {
        let run = Command::new(env!("CARGO_BIN_EXE_fem-forms"))
            .args(args)
            .arg("--out")
            .arg(&out)
            .output()
            .expect("the binary runs");
        assert!(
            run.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&run.stderr)
        );
        run.stdout
    };
    let number = |json: &serde_json::Value, field: &str| {
        json[field]
            .as_f64()
            .unwrap_or_else(|| panic!("{field} missing in {json}"))
    };
    for pair in ["p1-p1", "p2-p1"] {
        let args = [
            "solve",
            "signorini-patch",
            "--json",
            "--pair",
            pair,
            "--load",
            "3",
            "--mesh-size",
            "4",
        ];
        let json: serde_json::Value = serde_json::from_slice(&run(&args)).unwrap();
        assert_eq!(json["pair"], pair);
        assert_eq!(number(&json, "multiplier_dofs"), 9.0, "{json}");
        assert_eq!(number(&json, "contact_edges"), 8.0, "{json}");
        assert!(number(&json, "patch_pressure_error") <= 1e-9, "{json}");
        assert!(
            (number(&json, "total_contact_force") - 6.0).abs() <= 1e-9 * 6.0,
            "{json}"
        );
        assert!(number(&json, "equilibrium_residual") <= 1e-10, "{json}");
    }
    let args = [
        "solve",
        "hertz",
        "--json",
        "--pair",
        "p1-p1",
        "--mesh-size",
        "16",
    ];
    let json: serde_json::Value = serde_json::from_slice(&run(&args)).unwrap();
    assert!(json["best_p0_l2_error"].is_null(), "{json}");
    let ratio = number(&json, "pressure_l2_error") / number(&json, "best_fit_l2_error");
    assert!((1.0..2.0).contains(&ratio), "{json}");
    assert!(number(&json, "equilibrium_residual") <= 1e-10, "{json}");
    run(&[
        "solve",
        "hertz",
        "--plot",
        "--pair",
        "p2-p1",
        "--mesh-size",
        "8",
    ]);
    let chart = std::fs::read_to_string(out.join("hertz-pressure.svg")).unwrap();
    assert!(chart.contains("λ_h (p2-p1)"), "the chart names the pair");
    let _ = std::fs::remove_dir_all(&out);
}
