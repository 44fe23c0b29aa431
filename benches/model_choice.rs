//! The choice of model, pair and mesh against the scene's fixed default, every number
//! measured in this one run: for one scene of each family, the time `choice::solve` takes
//! to reach the tolerance T (its probes included), and the time the scene's default
//! pair on its own model takes on uniform meshes, doubled until its error is at most
//! the chosen solution's. The error: the true relative error in the energy norm where
//! the scene has an exact solution and no cheaper model, else the relative estimate plus
//! the modelling estimate (a bound on the error, and estimators of different models are
//! calibrated differently: see docs/model-choice.md).
//!
//! `cargo bench --bench model_choice` (add `-- --quick` for the loosest tolerances).

use fem_forms::adaptivity::AdaptiveOptions;
use fem_forms::models::report::{Outcome, Settings};
use fem_forms::models::{choice, families};
use std::time::Instant;

/// One case: scene, tolerance (full and quick), coarsest and largest uniform size.
struct Case {
    scene: &'static str,
    tolerance: [f64; 2],
    start: usize,
    largest: usize,
}

const CASES: [Case; 8] = [
    Case {
        scene: "timoshenko-t1e-3",
        tolerance: [5e-2, 5e-2],
        start: 16,
        largest: 1 << 14,
    },
    Case {
        scene: "timoshenko-t1e-3",
        tolerance: [3e-3, 1e-2],
        start: 16,
        largest: 1 << 14,
    },
    Case {
        scene: "timoshenko-t1e-1",
        tolerance: [3e-3, 1e-2],
        start: 16,
        largest: 1 << 14,
    },
    Case {
        scene: "membrane-radial",
        tolerance: [1e-2, 3e-2],
        start: 4,
        largest: 512,
    },
    Case {
        scene: "kirchhoff-obstacle",
        tolerance: [1e-2, 3e-2],
        start: 4,
        largest: 128,
    },
    Case {
        scene: "hertz",
        tolerance: [3e-2, 5e-2],
        start: 1,
        largest: 64,
    },
    Case {
        scene: "winkler-square",
        tolerance: [1e-2, 3e-2],
        start: 4,
        largest: 128,
    },
    Case {
        scene: "mindlin-ss-t1e-3",
        tolerance: [0.1, 0.1],
        start: 4,
        largest: 128,
    },
];

/// The error of a solve as the module docs define it.
fn error(outcome: &Outcome, true_error: bool) -> Option<f64> {
    if true_error {
        return outcome.report.solve.error_energy_relative;
    }
    choice::error_bound(&outcome.report)
}

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    println!(
        "{:<20} {:>7} {:<36} {:>9} {:>10} {:>9} | {:<18} {:>9} {:>10} {:>9} {:>8}",
        "scene",
        "T",
        "chosen",
        "unknowns",
        "error",
        "seconds",
        "default (uniform)",
        "unknowns",
        "error",
        "seconds",
        "ratio"
    );
    for case in &CASES {
        let tolerance = case.tolerance[usize::from(quick)];
        let scene = families::scene(case.scene).expect("a registry scene");
        let has_cheaper = families::family(scene.family)
            .and_then(|f| f.cheaper(&scene))
            .is_some();
        let request = Settings {
            adaptive: Some(AdaptiveOptions {
                tolerance,
                ..AdaptiveOptions::default()
            }),
            ..Settings::default()
        };
        let clock = Instant::now();
        let chosen = match choice::solve(&scene, &request) {
            Ok(outcome) => outcome,
            Err(e) => {
                println!(
                    "{:<20} {tolerance:>7.0e} the choice failed: {e}",
                    case.scene
                );
                continue;
            }
        };
        let chosen_seconds = clock.elapsed().as_secs_f64();
        let true_error = !has_cheaper && chosen.report.solve.error_energy_relative.is_some();
        let Some(target) = error(&chosen, true_error) else {
            println!("{:<20} the chosen solve reports no error", case.scene);
            continue;
        };
        let label = choice::chosen_words(&chosen.report);
        let default = families::pairs_of(&scene)[0].name;
        let mut n = case.start;
        let mut reached = None;
        while n <= case.largest {
            let settings = Settings {
                pair: Some(default.into()),
                mesh_size: Some(n),
                ..Settings::default()
            };
            let clock = Instant::now();
            let Ok(outcome) = families::solve(&scene, &settings) else {
                break;
            };
            let seconds = clock.elapsed().as_secs_f64();
            let e = error(&outcome, true_error).unwrap_or(f64::INFINITY);
            if e <= target {
                reached = Some((outcome.report.solve.dofs, e, seconds));
                break;
            }
            n *= 2;
        }
        let measure = if true_error { "" } else { " (bound)" };
        match reached {
            Some((dofs, e, seconds)) => println!(
                "{:<20} {tolerance:>7.0e} {label:<36} {:>9} {target:>10.3e} {chosen_seconds:>9.3} | {default:<18} {dofs:>9} {e:>10.3e} {seconds:>9.3} {:>8.2}{measure}",
                case.scene,
                chosen.report.solve.dofs,
                seconds / chosen_seconds
            ),
            None => println!(
                "{:<20} {tolerance:>7.0e} {label:<36} {:>9} {target:>10.3e} {chosen_seconds:>9.3} | {default:<18} not reached by N = {}{measure}",
                case.scene,
                chosen.report.solve.dofs,
                case.largest
            ),
        }
    }
}
