//! The complete Signorini contact solve (nested) against one factorization + solve of
//! the elasticity matrix of the same mesh (issue 14, "Speed").
//!
//! `cargo bench --bench signorini` prints, for Hertz (P1–P0, quarter disc, coarse mesh
//! `hertz_mesh` at b/h = 2 refined uniformly 3 and 4 times) and for the unit block over a
//! parabolic gap (7 × 7 squares refined 4 and 5 times): the unknowns of the finest
//! level, the time of the whole nested solve (every level's meshes, assembly, inverse
//! constants, prolongation, Newton and report), the time of one sparse Cholesky
//! (symbolic + numeric, `fem_runtime::lcp::cholesky` on faer, as the runtime factors) and
//! solve of the finest level's elasticity matrix `A`, their ratio, and the Newton
//! iterations per level; at the largest size also the cold single-mesh solve (every
//! constraint active at the start) on the finest mesh.
//!
//! Under pure contact `A` is singular (a translation along the contact direction), so
//! the factored `A` is the elasticity matrix with the contact part also held
//! (`u_y = 0` on Γ_C): the linear problem of the same mesh and size.
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

use fem_forms::lcp::cholesky::Cholesky;
use fem_forms::models::signorini::{
    hertz_input, hertz_mesh, hertz_snap, lame, signorini_p1, solve_signorini,
    solve_signorini_nested, straight_boundary, Displacement, Hertz, HertzData, Plane,
    SignoriniInput, Snap,
};
use fem_forms::obstacle::boundary_multiplier::discretize_on_parts;
use fem_forms::{Coefficients, Diagonal, TriangleMesh};
use std::time::Instant;

/// Seconds of one Cholesky (symbolic + numeric) and solve of the elasticity matrix on
/// `mesh` with `u_y = 0` also on Γ_C, and its order; the best of three.
fn linear_solve(mesh: &TriangleMesh, input: &SignoriniInput) -> (f64, usize) {
    type M = signorini_p1::Model;
    let (mu, lambda) = lame(input.young, input.poisson, input.plane).unwrap();
    let coefficients = Coefficients::new::<M>(
        &[
            ("μ_L", mu),
            ("λ_L", lambda),
            ("α", 0.0),
            ("n_c_x", input.contact_direction[0]),
            ("n_c_y", input.contact_direction[1]),
        ],
        &[("q", input.pressure), ("g", input.gap)],
    )
    .unwrap();
    let held: Vec<u32> = input.fixed_y.iter().chain(input.contact).copied().collect();
    let fixed = [
        (signorini_p1::fields::u_x, input.fixed_x),
        (signorini_p1::fields::u_y, &held[..]),
    ];
    let d = discretize_on_parts::<M, _, _>(
        mesh,
        &coefficients,
        &[
            (signorini_p1::facets::Γ_C, input.contact),
            (signorini_p1::facets::Γ_N, input.load),
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

fn run(
    name: &str,
    coarse: &TriangleMesh,
    refinements: &[usize],
    snap: Snap,
    input: &SignoriniInput,
) {
    println!("{name}");
    println!(
        "{:>9} {:>9} {:>13} {:>13} {:>7}  Newton iterations per level (coarse → fine)",
        "cells", "unknowns", "nested s", "factor+solve", "ratio"
    );
    for (k, &l) in refinements.iter().enumerate() {
        let nested = match solve_signorini_nested(coarse, l, snap, input) {
            Ok(n) => n,
            Err(e) => {
                println!("{l} refinements: failed: {e}");
                continue;
            }
        };
        let (linear, order) = linear_solve(&nested.mesh, input);
        let iterations: Vec<String> = nested
            .levels
            .iter()
            .map(|l| l.iterations.to_string())
            .collect();
        let fallbacks = nested
            .levels
            .iter()
            .filter(|l| {
                matches!(
                    l.start,
                    fem_forms::models::signorini::LevelStart::FellBack(_)
                )
            })
            .count();
        println!(
            "{:>9} {:>9} {:>13.3} {:>13.3} {:>7.1}  {}{}   (A of order {order}; finest level {:.3} s, its Newton {:.3} s)",
            nested.mesh.cell_count(),
            nested.solution.dofs,
            nested.seconds,
            linear,
            nested.seconds / linear,
            iterations.join(" "),
            if fallbacks > 0 {
                format!(" ({fallbacks} fell back to the pressed start)")
            } else {
                String::new()
            },
            nested.levels.last().unwrap().seconds,
            nested.levels.last().unwrap().newton_seconds,
        );
        if k + 1 == refinements.len() {
            let start = Instant::now();
            match solve_signorini(&nested.mesh, input) {
                Ok(cold) => {
                    let seconds = start.elapsed().as_secs_f64();
                    println!(
                        "    cold start on the finest mesh: {seconds:.3} s in all ({} iterations, Newton {:.3} s), ratio {:.1}",
                        cold.iterations,
                        cold.seconds,
                        seconds / linear
                    );
                }
                Err(e) => println!("    cold start on the finest mesh failed: {e}"),
            }
        }
    }
    println!();
}

fn pressure(_: &[f64]) -> f64 {
    2.5
}

fn parabolic_gap(x: &[f64]) -> f64 {
    0.02 * (x[0] - 0.5) * (x[0] - 0.5)
}

fn main() {
    fem_forms::allocator::keep_freed_memory();
    fem_forms::lcp::cholesky::factor_sequentially();
    let hertz = Hertz {
        radius: 1.0,
        young: 1000.0,
        poisson: 0.3,
        load: 1.0,
    };
    let data = HertzData::new(&hertz);
    let input = hertz_input(&hertz, Displacement::P1, None, &data);
    let b = hertz.half_width();
    let coarse = hertz_mesh(1.0, 1.25 * b, b / 2.0, 0.25).unwrap();
    let snap = hertz_snap(1.0);
    run(
        "hertz P1–P0, coarse b/h = 2, uniform refinements",
        &coarse,
        &[3, 4],
        &snap,
        &input,
    );
    let block = SignoriniInput {
        young: 1000.0,
        poisson: 0.3,
        plane: Plane::Strain,
        element: Displacement::P1,
        contact: &[1],
        load: &[3],
        pressure: &pressure,
        gap: &parabolic_gap,
        contact_direction: [0.0, -1.0],
        fixed_x: &[4],
        fixed_y: &[],
        rollers: &[],
        alpha: None,
        contact_centre: None,
    };
    let coarse = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 7, 7, Diagonal::Alternating).unwrap();
    run(
        "unit block over a parabolic gap 0.02 (x − ½)², q = 2.5, P1–P0",
        &coarse,
        &[4, 5],
        &straight_boundary,
        &block,
    );
}
