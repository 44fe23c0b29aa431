//! The adaptive loop to a tolerance against the uniform refinement that reaches the same
//! true error, every number measured in this one run: for each scene with an exact
//! solution, the adaptive run to `T` (its final unknowns, wall time, true error in the
//! estimator's norm), then uniform meshes doubled until their true error is at most the
//! adaptive one; the uniform unknowns and time at equal error are interpolated log–log
//! between the last two uniform meshes (doubling overshoots the error by up to the
//! rate's factor), and the ratios uniform / adaptive are of those.
//!
//! `cargo bench --bench adaptivity` (add `-- --quick` for looser tolerances).

use fem_forms::adaptivity::AdaptiveOptions;
use fem_forms::models::families;
use fem_forms::models::report::{Outcome, Settings};
use std::time::Instant;

/// One case: scene, pair, load (`None`: the scene's), coarsest mesh size, tolerance
/// (full and quick), largest uniform size tried.
struct Case {
    scene: &'static str,
    pair: &'static str,
    load: Option<f64>,
    start: usize,
    tolerance: [f64; 2],
    largest: usize,
}

const CASES: [Case; 3] = [
    Case {
        scene: "membrane-radial",
        pair: "p1-p0",
        load: None,
        start: 4,
        tolerance: [0.05, 0.1],
        largest: 1024,
    },
    Case {
        scene: "membrane-radial",
        pair: "p2-p0",
        load: None,
        start: 4,
        tolerance: [5e-3, 2e-2],
        largest: 512,
    },
    Case {
        scene: "bernoulli-flat",
        pair: "hermite-p0",
        load: Some(100.0),
        start: 4,
        tolerance: [1e-4, 1e-3],
        largest: 1 << 15,
    },
];

fn solve(case: &Case, size: usize, tolerance: Option<f64>) -> (f64, Outcome) {
    let scene = families::scene(case.scene).expect("a registry scene");
    let settings = Settings {
        pair: Some(case.pair.into()),
        load: case.load,
        mesh_size: Some(size),
        adaptive: tolerance.map(|tolerance| AdaptiveOptions {
            tolerance,
            ..AdaptiveOptions::default()
        }),
        ..Settings::default()
    };
    let clock = Instant::now();
    let outcome = families::solve(&scene, &settings)
        .unwrap_or_else(|e| panic!("{} {} at {size}: {e}", case.scene, case.pair));
    (clock.elapsed().as_secs_f64(), outcome)
}

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    println!("adaptive to T against the uniform mesh that reaches the same true error (one run, wall times)");
    println!("| scene | pair | T | adaptive: levels, N, s, error | uniform reaching it: size, N, s, error | uniform at equal error: N, s | N ratio | time ratio |");
    println!("|---|---|---|---|---|---|---|---|");
    for case in &CASES {
        let tolerance = case.tolerance[usize::from(quick)];
        let (adaptive_seconds, adaptive) = solve(case, case.start, Some(tolerance));
        let report = &adaptive.report.solve;
        let Some(target) = report.error_energy else {
            println!(
                "| {} | {} | {tolerance:e} | no exact error | | | |",
                case.scene, case.pair
            );
            continue;
        };
        // (dofs, seconds, error) of each uniform mesh until one reaches the target
        let mut uniform: Vec<(f64, f64, f64)> = Vec::new();
        let mut size = case.start;
        loop {
            let (seconds, outcome) = solve(case, size, None);
            let error = outcome.report.solve.error_energy.unwrap_or(f64::INFINITY);
            uniform.push((outcome.report.solve.dofs as f64, seconds, error));
            if error <= target || 2 * size > case.largest {
                break;
            }
            size *= 2;
        }
        let &(dofs, seconds, error) = uniform.last().expect("one uniform solve");
        let (n_equal, t_equal) = match uniform.len() {
            k if k >= 2 && error <= target => {
                // log–log interpolation to the target error
                let (n0, t0, e0) = uniform[k - 2];
                let s = (target / e0).ln() / (error / e0).ln();
                (n0 * (dofs / n0).powf(s), t0 * (seconds / t0).powf(s))
            }
            _ => (dofs, seconds),
        };
        let reached = if error <= target {
            ""
        } else {
            " (not reached)"
        };
        println!(
            "| {} | {} | {tolerance:e} | {}, {}, {:.3}, {:.3e} | {size}, {dofs}, {seconds:.3}, {error:.3e}{reached} | {n_equal:.0}, {t_equal:.3} | {:.1} | {:.1} |",
            case.scene,
            case.pair,
            report.adaptive_levels.len(),
            report.dofs,
            adaptive_seconds,
            target,
            n_equal / report.dofs as f64,
            t_equal / adaptive_seconds,
        );
    }
}
