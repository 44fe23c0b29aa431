//! The complete Signorini contact solve through the one pipeline against one
//! factorization + solve of the elasticity matrix of the same mesh.
//!
//! `cargo bench --bench signorini` prints, for the unit block over a parabolic gap (a
//! scene file: 7 × 7 squares refined 3, 4 and 5 times) and for Hertz (the built-in
//! scene's graded meshes, b/h = 32, 64, 128), each solved on one level as the contact
//! family does (docs/contact.md §7): the cells and unknowns, the wall time of the whole
//! solve (meshes, assembly, inverse constants, Newton, the report), the time of one sparse Cholesky (symbolic + numeric,
//! `fem_runtime::lcp::cholesky` on faer, as the runtime factors) and solve of the
//! finest level's elasticity matrix `A`, their ratio, and the Newton iterations per
//! level.
//!
//! Under pure contact `A` is singular (a translation along the contact direction), so
//! the factored `A` is the elasticity matrix with the contact part also held
//! (`u_y = 0` on Γ_C): the linear problem of the same mesh and size.
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

use fem_forms::lcp::cholesky::Cholesky;
use fem_forms::models::contact_scenes::{hertz_mesh, HERTZ_ARC, HERTZ_AXIS, HERTZ_TOP};
use fem_forms::models::families::{self, contact::lame, contact::Plane};
use fem_forms::models::hertz::Hertz;
use fem_forms::models::report::Settings;
use fem_forms::models::scene_file;
use fem_forms::models::signorini::signorini_p1;
use fem_forms::obstacle::boundary_multiplier::discretize_on_parts;
use fem_forms::{Coefficients, DataFn, Diagonal, TriangleMesh};
use std::time::Instant;

/// A contact problem's boundary parts by marker: contact, load, `u_x = 0`.
struct Parts<'a> {
    contact: &'a [u32],
    load: &'a [u32],
    fixed_x: &'a [u32],
}

/// Seconds of one Cholesky (symbolic + numeric) and solve of the elasticity matrix
/// (E = 1000, ν = 0.3, plane strain) on `mesh` with `u_y = 0` also on Γ_C, and its
/// order; the best of three.
fn linear_solve(
    mesh: &TriangleMesh,
    parts: &Parts,
    pressure: &DataFn,
    gap: &DataFn,
) -> (f64, usize) {
    type M = signorini_p1::Model;
    let (mu, lambda) = lame(1000.0, 0.3, Plane::Strain).unwrap();
    let coefficients = Coefficients::from_ids(
        &[
            (signorini_p1::params::μ_L, mu),
            (signorini_p1::params::λ_L, lambda),
            (signorini_p1::params::α, 0.0),
            (signorini_p1::params::n_c_x, 0.0),
            (signorini_p1::params::n_c_y, -1.0),
        ],
        &[
            (signorini_p1::data::q, pressure),
            (signorini_p1::data::g, gap),
        ],
    )
    .unwrap();
    let fixed = [
        (signorini_p1::fields::u_x, parts.fixed_x),
        (signorini_p1::fields::u_y, parts.contact),
    ];
    let d = discretize_on_parts::<M, _, _>(
        mesh,
        &coefficients,
        &[
            (signorini_p1::facets::Γ_C, parts.contact),
            (signorini_p1::facets::Γ_N, parts.load),
        ],
        &fixed,
    )
    .unwrap();
    let mut best = f64::INFINITY;
    for _ in 0..3 {
        let start = Instant::now();
        let pattern = d.lcp.a.symbolic().to_owned().unwrap();
        let factor = Cholesky::analyse(&pattern)
            .unwrap()
            .factor(&d.lcp.a)
            .unwrap();
        let x = factor.solve(&d.lcp.f).unwrap();
        best = best.min(start.elapsed().as_secs_f64());
        std::hint::black_box(x);
    }
    (best, d.lcp.n())
}

/// One row: the solve of `scene` with `settings`, against `linear` (seconds, order).
fn row(scene: &fem_forms::models::scene::Scene, settings: &Settings, linear: (f64, usize)) {
    let clock = Instant::now();
    match families::solve(scene, settings) {
        Ok(outcome) => {
            let seconds = clock.elapsed().as_secs_f64();
            let solve = &outcome.report.solve;
            let iterations: Vec<String> = solve.levels.iter().map(|l| l[1].to_string()).collect();
            println!(
                "{:>9} {:>9} {:>9.3} {:>13.3} {:>7.1}  {}   (A of order {})",
                solve.cells,
                solve.dofs,
                seconds,
                linear.0,
                seconds / linear.0,
                iterations.join(" "),
                linear.1
            );
        }
        Err(e) => println!("failed: {e}"),
    }
}

fn header(name: &str) {
    println!("{name}");
    println!(
        "{:>9} {:>9} {:>9} {:>13} {:>7}  Newton iterations per level (coarse → fine)",
        "cells", "unknowns", "solve s", "factor+solve", "ratio"
    );
}

fn pressure(_: &[f64]) -> f64 {
    2.5
}

fn parabolic_gap(x: &[f64]) -> f64 {
    0.02 * (x[0] - 0.5) * (x[0] - 0.5)
}

const BLOCK: &str = r#"
model = "contact"
[mesh]
generator = "rectangle"
x = [0.0, 1.0]
y = [0.0, 1.0]
cells = [7, 7]
[material]
young = 1000.0
poisson = 0.3
[boundary]
contact = "bottom"
load = "top"
fixed_x = "left"
[data]
pressure = "2.5"
gap = "0.02 * (x - 0.5)^2"
"#;

fn main() {
    fem_forms::allocator::keep_freed_memory();
    fem_forms::lcp::cholesky::factor_sequentially();

    let file = scene_file::parse(BLOCK, std::path::Path::new("block.toml")).unwrap();
    let block = Parts {
        contact: &[1],
        load: &[3],
        fixed_x: &[4],
    };
    header("unit block over a parabolic gap 0.02 (x − ½)², q = 2.5, p1-p0, 7 × 7 squares refined");
    for refinements in [3, 4, 5] {
        let mut mesh = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 7, 7, Diagonal::Right).unwrap();
        for _ in 0..refinements {
            mesh = mesh.refine_uniformly();
        }
        let linear = linear_solve(&mesh, &block, &pressure, &parabolic_gap);
        let mut settings = file.settings();
        settings.mesh_size = Some(refinements);
        row(&file.scene, &settings, linear);
    }
    println!();

    let hertz = Hertz {
        radius: 1.0,
        young: 1000.0,
        poisson: 0.3,
        load: 1.0,
    };
    let scene = families::scene("hertz").unwrap();
    let q = hertz.load / (2.0 * hertz.radius);
    let top = move |_: &[f64]| q;
    let gap = |x: &[f64]| x[1];
    let parts = Parts {
        contact: &[HERTZ_ARC],
        load: &[HERTZ_TOP],
        fixed_x: &[HERTZ_AXIS],
    };
    header("hertz p1-p0, graded quarter disc (one level)");
    for b_over_h in [32usize, 64, 128] {
        // the scene's generator: uniform cells a little beyond b, grading tightening with b/h
        let b = hertz.half_width();
        let grading = (4.0 / b_over_h as f64).min(0.25);
        let mesh = hertz_mesh(1.0, 1.25 * b, b / b_over_h as f64, grading).unwrap();
        let linear = linear_solve(&mesh, &parts, &top, &gap);
        let settings = Settings {
            mesh_size: Some(b_over_h),
            ..Settings::default()
        };
        row(&scene, &settings, linear);
    }
}
