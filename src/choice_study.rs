//! The work–precision chart of a scene's model choice (`study SCENE work-precision`):
//! every candidate the choice weighs ([`crate::models::choice`]: each model and pair),
//! on uniform meshes and adaptively, as a curve of its error against wall time, with
//! the choice made for a few tolerances marked on it, so that a reader sees whether the
//! choice sits on the lower-left front.
//!
//! The error: where the scene has an exact solution and no neighbour model, the true
//! error in the energy norm relative to `‖u_h‖_a`; otherwise the relative estimate plus,
//! for the thinner of two neighbours, its modelling estimate (a bound on its distance to the scene's
//! own model's solution, docs/model-choice.md). The time of a marked choice includes its
//! probes. `out/<scene>-work-precision-choice.svg`, the numbers in `.csv`.

use crate::models::choice;
use crate::models::families;
use crate::models::report::{Outcome, Progress, Settings};
use crate::models::scene::{Domain, Scene};
use crate::plot::{self, Axes, Series};
use crate::studies::{io, write_csv_named};
use fem_runtime::adaptivity::{AdaptiveLevel, AdaptiveOptions};
use fem_runtime::{Error, Result};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// One solve (or adaptive level) on a curve.
#[derive(Clone, Copy, Debug)]
pub struct Point {
    /// Wall time, in seconds (an adaptive level's: the levels up to it).
    pub seconds: f64,
    /// Unknowns.
    pub dofs: usize,
    /// The true relative error in the energy norm, where known.
    pub error: Option<f64>,
    /// The relative estimate plus the modelling estimate.
    pub bound: f64,
}

/// A candidate's curve.
#[derive(Clone, Debug)]
pub struct Curve {
    /// `Timoshenko p2-p2-p0 uniform`.
    pub label: String,
    /// Its points, coarsest first.
    pub points: Vec<Point>,
}

/// The choice made for one tolerance.
#[derive(Clone, Debug)]
pub struct Mark {
    /// The tolerance.
    pub tolerance: f64,
    /// `Euler–Bernoulli hermite-p0`.
    pub chosen: String,
    /// Its solve: probes and the adaptive solve.
    pub point: Point,
}

/// The study's result.
#[derive(Clone, Debug)]
pub struct WorkPrecision {
    /// Every candidate, uniform and adaptive.
    pub curves: Vec<Curve>,
    /// The choice at each tolerance.
    pub marks: Vec<Mark>,
    /// Whether every point has a true error (else the chart shows the bound).
    pub true_error: bool,
}

/// The tolerances marked: looser on triangles, whose estimators converge like `d^{-1/2}`.
fn tolerances(scene: &Scene, full: bool) -> Vec<f64> {
    let mut t = match scene.domain {
        Domain::Interval { .. } => vec![1e-1, 3e-2, 1e-2],
        _ => vec![2e-1, 1e-1, 5e-2],
    };
    if full {
        t.push(t[t.len() - 1] / 3.0);
    }
    t
}

/// The uniform sizes of each candidate's curve: from the choice's probe sizes on,
/// doubling (one refinement more each on a mesh file); fewer on triangles.
fn sizes(scene: &Scene, full: bool) -> Vec<usize> {
    let steps = match (&scene.domain, full) {
        (Domain::Interval { .. }, true) => 6,
        (Domain::Interval { .. }, false) => 4,
        (_, true) => 5,
        (_, false) => 3,
    };
    let [first, second] = choice::probe_sizes(scene, None);
    let refined = second == first + 1;
    (0..steps)
        .map(|k| if refined { first + k } else { first << k })
        .collect()
}

fn point(outcome: &Outcome, seconds: f64) -> Option<Point> {
    Some(Point {
        seconds,
        dofs: outcome.report.solve.dofs,
        error: outcome.report.solve.error_energy_relative,
        bound: choice::error_bound(&outcome.report)?,
    })
}

/// The curves and marks of `scene` (its study load applied by the caller).
///
/// # Errors
/// A scene without a family or whose load the request refuses.
pub fn work_precision(scene: &Scene, full: bool) -> Result<WorkPrecision> {
    let base = Settings {
        load: scene.study_load,
        ..Settings::default()
    };
    let models = choice::models(scene, &base)?;
    let tolerances = tolerances(scene, full);
    let tightest = tolerances[tolerances.len() - 1];
    let mut curves = Vec::new();
    for (words, model_scene) in &models {
        for pair in families::pairs_of(model_scene) {
            let mut uniform = Vec::new();
            // the cheaper model's modelling estimate, from its finest uniform solve
            let mut modelling = 0.0;
            for n in sizes(scene, full) {
                let settings = Settings {
                    pair: Some(pair.name.into()),
                    mesh_size: Some(n),
                    ..base.clone()
                };
                let clock = Instant::now();
                match families::solve(model_scene, &settings) {
                    Ok(outcome) => {
                        if let Some(m) = outcome.report.number("modelling_estimate_relative") {
                            modelling = m;
                        }
                        uniform.extend(point(&outcome, clock.elapsed().as_secs_f64()));
                    }
                    Err(e) => {
                        println!("  {words} {} at N = {n}: {e}", pair.name);
                        break;
                    }
                }
            }
            let uniform_dofs = uniform.last().map_or(0, |p| p.dofs);
            curves.push(Curve {
                label: format!("{words} {} uniform", pair.name),
                points: uniform,
            });
            // the levels as they are solved: a run stopped by its limit is charted as far
            // as it went
            let levels = Arc::new(Mutex::new(Vec::<AdaptiveLevel>::new()));
            let seen = Arc::clone(&levels);
            let settings = Settings {
                pair: Some(pair.name.into()),
                mesh_size: Some(choice::probe_sizes(scene, None)[0]),
                adaptive: Some(AdaptiveOptions {
                    tolerance: tightest,
                    // a candidate far from the tolerance (a locking pair) is charted
                    // as far as its uniform curve goes, not chased to the loop's limit
                    max_dofs: uniform_dofs.saturating_mul(20).max(10_000),
                    ..AdaptiveOptions::default()
                }),
                progress: Some(Progress(Arc::new(move |level: &AdaptiveLevel| {
                    if let Ok(mut levels) = seen.lock() {
                        levels.push(*level);
                    }
                }))),
                ..base.clone()
            };
            if let Err(e) = families::solve(model_scene, &settings) {
                println!("  {words} {} adaptive: {e}", pair.name);
            }
            let mut elapsed = 0.0;
            let points = levels
                .lock()
                .map(|levels| levels.clone())
                .unwrap_or_default()
                .iter()
                .map(|level| {
                    elapsed += level.seconds;
                    Point {
                        seconds: elapsed,
                        dofs: level.dofs,
                        error: level.error_energy.map(|e| e / level.energy_norm),
                        bound: level.estimate / level.energy_norm + modelling,
                    }
                })
                .collect();
            curves.push(Curve {
                label: format!("{words} {} adaptive", pair.name),
                points,
            });
        }
    }
    let mut marks = Vec::new();
    for &tolerance in &tolerances {
        let settings = Settings {
            adaptive: Some(AdaptiveOptions {
                tolerance,
                ..AdaptiveOptions::default()
            }),
            ..base.clone()
        };
        let clock = Instant::now();
        match choice::solve(scene, &settings) {
            Ok(outcome) => {
                let seconds = clock.elapsed().as_secs_f64();
                let chosen = choice::chosen_words(&outcome.report);
                if let Some(point) = point(&outcome, seconds) {
                    marks.push(Mark {
                        tolerance,
                        chosen,
                        point,
                    });
                }
            }
            Err(e) => println!("  the choice at T = {tolerance:e}: {e}"),
        }
    }
    let true_error = models.len() == 1
        && curves
            .iter()
            .flat_map(|c| &c.points)
            .chain(marks.iter().map(|m| &m.point))
            .all(|p| p.error.is_some());
    Ok(WorkPrecision {
        curves,
        marks,
        true_error,
    })
}

/// `out/<scene>-work-precision-choice.<extension>`.
pub fn output(out: &Path, scene: &str, extension: &str) -> PathBuf {
    out.join(format!("{scene}-work-precision-choice.{extension}"))
}

/// Runs the study on `scene`, prints its table and writes the chart and CSV.
///
/// # Errors
/// Those of [`work_precision`]; the output cannot be written.
pub fn run(scene: &Scene, full: bool, out: &Path) -> Result<()> {
    let result = work_precision(scene, full)?;
    let measure = |p: &Point| {
        if result.true_error {
            p.error.unwrap_or(f64::NAN)
        } else {
            p.bound
        }
    };
    let words = if result.true_error {
        "‖u − u_h‖_a / ‖u_h‖_a"
    } else {
        "(η + modelling) / ‖u_h‖_a"
    };
    println!(
        "{}: every candidate's {words} against wall time",
        scene.name
    );
    println!(
        "{:<44} {:>10} {:>10} {:>12}",
        "candidate", "unknowns", "seconds", "error"
    );
    let mut rows = Vec::new();
    let mut names: Vec<String> = Vec::new();
    for (k, curve) in result.curves.iter().enumerate() {
        names.push(curve.label.clone());
        for p in &curve.points {
            println!(
                "{:<44} {:>10} {:>10.4} {:>12.4e}",
                curve.label,
                p.dofs,
                p.seconds,
                measure(p)
            );
            rows.push(vec![
                k as f64,
                p.seconds,
                p.dofs as f64,
                measure(p),
                f64::NAN,
            ]);
        }
    }
    for mark in &result.marks {
        let k = names.len();
        names.push(format!("choice: {}", mark.chosen));
        println!(
            "{:<44} {:>10} {:>10.4} {:>12.4e}  (T = {:e})",
            format!("choice: {}", mark.chosen),
            mark.point.dofs,
            mark.point.seconds,
            measure(&mark.point),
            mark.tolerance
        );
        rows.push(vec![
            k as f64,
            mark.point.seconds,
            mark.point.dofs as f64,
            measure(&mark.point),
            mark.tolerance,
        ]);
    }
    let drawn: Vec<&Curve> = result
        .curves
        .iter()
        .filter(|c| !c.points.is_empty())
        .collect();
    let mut series: Vec<Series> = drawn
        .iter()
        .map(|c| {
            Series::marked(
                &c.label,
                c.points.iter().map(|p| (p.seconds, measure(p))).collect(),
            )
        })
        .collect();
    for mark in &result.marks {
        // in the colour of the chosen candidate's adaptive curve, which it solved
        let like = drawn
            .iter()
            .position(|c| c.label == format!("{} adaptive", mark.chosen))
            .unwrap_or(0);
        series.push(Series::highlighted(
            format!("choice at T = {:e}: {}", mark.tolerance, mark.chosen),
            vec![(mark.point.seconds, measure(&mark.point))],
            like,
        ));
    }
    plot::chart(
        &output(out, &scene.name, "svg"),
        &format!("{}: candidates and the choice", scene.name),
        Axes {
            x: "wall time (s)",
            y: words,
            log_x: true,
            log_y: true,
            rates: false,
        },
        &series,
    )
    .map_err(io)?;
    let refs: Vec<&str> = names.iter().map(String::as_str).collect();
    write_csv_named(
        &output(out, &scene.name, "csv"),
        "candidate",
        "seconds,dofs,error,tolerance",
        &refs,
        &rows,
    )
    .map_err(io)?;
    if result.curves.is_empty() {
        return Err(Error::Input(format!(
            "scene `{}`: no candidate could be solved",
            scene.name
        )));
    }
    Ok(())
}
