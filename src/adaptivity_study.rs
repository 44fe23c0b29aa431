//! The adaptivity study of any scene whose model declares an estimator: uniform
//! refinement and the adaptive loop side by side, in the estimator's own norm.
//!
//! Uniform: the scene's mesh ladder ([`crate::studies::Plan`]). Adaptive: from the
//! ladder's coarsest mesh to half the relative estimate the finest uniform mesh reached,
//! so the two curves cover the same range. Charts (`out/<scene>-adaptivity*.svg`, with
//! the numbers in `.csv`): error and estimate against unknowns with the rate each run
//! attains drawn as a triangle; the efficiency index `η/‖e‖` against unknowns; the error
//! (or the estimate, without an exact solution) against wall time; the final adaptive mesh
//! with the contact set.

use crate::plot::{self, Axes, Series};
use crate::studies::{io, output, write_csv_named, Row, Run, Study, StudyScene};
use fem_runtime::adaptivity::AdaptiveLevel;
use fem_runtime::Result;
use std::path::Path;

/// The least-squares slope of `ln y` against `ln x` over the second half of `points`
/// (positive values only): the rate a run settles to, `NaN` with fewer than two points.
pub fn settled_rate(points: &[(f64, f64)]) -> f64 {
    let usable: Vec<(f64, f64)> = points
        .iter()
        .filter(|p| p.0 > 0.0 && p.1 > 0.0)
        .map(|p| (p.0.ln(), p.1.ln()))
        .collect();
    let half = &usable[usable.len() / 2..];
    if half.len() < 2 {
        return f64::NAN;
    }
    let n = half.len() as f64;
    let (mx, my) = half
        .iter()
        .fold((0.0, 0.0), |(a, b), p| (a + p.0 / n, b + p.1 / n));
    let (sxy, sxx) = half.iter().fold((0.0, 0.0), |(a, b), p| {
        (a + (p.0 - mx) * (p.1 - my), b + (p.0 - mx) * (p.0 - mx))
    });
    if sxx > 0.0 {
        sxy / sxx
    } else {
        f64::NAN
    }
}

/// A rate triangle under the last point of `points` on log–log axes: its slope is
/// `rate`, its base spans a third of the decade range of x, labelled with the rate.
fn rate_triangle(label: &str, points: &[(f64, f64)], rate: f64) -> Option<Series> {
    let &(x1, y1) = points.iter().rev().find(|p| p.0 > 0.0 && p.1 > 0.0)?;
    let &(x0, _) = points.iter().find(|p| p.0 > 0.0 && p.1 > 0.0)?;
    if !rate.is_finite() || x1 <= x0 {
        return None;
    }
    let xa = x1 / (x1 / x0).powf(1.0 / 3.0);
    let ya = 0.5 * y1 * (xa / x1).powf(rate);
    let yb = 0.5 * y1;
    Some(Series::line(
        format!("{label}: slope {rate:.2}"),
        vec![(xa, ya), (x1, yb), (xa, yb), (xa, ya)],
    ))
}

/// The error of a row in the estimator's norm (`error_energy`), where known.
fn error(r: &Row) -> Option<f64> {
    r.error_energy
}

/// Runs the study: prints the tables and writes the charts and CSV files.
///
/// # Errors
/// A failed uniform solve on the coarsest mesh, and failures to write the output (an
/// adaptive run that fails is printed and left out of the charts).
pub fn run(scene: &dyn StudyScene, full: bool, out: &Path) -> Result<()> {
    let name = scene.name();
    let plan = scene.plan(Study::Adaptivity, scene.pairs()[0], full);
    let pair = plan.pair;
    println!(
        "{}, {pair}: uniform refinement and the adaptive loop (Dörfler θ = 0.5)",
        scene.setting()
    );
    let mut uniform: Vec<Row> = Vec::new();
    for &n in &plan.sizes {
        match scene.solve(&Run::new(pair, n)) {
            Ok(row) => uniform.push(row),
            Err(e) if uniform.is_empty() => return Err(e),
            Err(e) => println!("uniform {n}: failed: {e}"),
        }
    }
    let finest = uniform.last().expect("at least the coarsest solve");
    let reached = finest.estimate_relative.unwrap_or(f64::NAN);
    let tolerance = 0.5 * reached;
    println!(
        "{:<9} {:>9} {:>9} {:>12} {:>12} {:>8} {:>9}",
        "run", "cells", "unknowns", "estimate", "error", "index", "seconds"
    );
    let show = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.4e}"));
    for r in &uniform {
        println!(
            "{:<9} {:>9} {:>9} {:>12} {:>12} {:>8} {:>9.3}",
            "uniform",
            r.cells,
            r.dofs,
            show(r.estimate),
            show(error(r)),
            r.estimate
                .zip(error(r))
                .map_or("-".into(), |(e, x)| format!("{:.2}", e / x)),
            r.seconds
        );
    }
    let adaptive = if tolerance.is_finite() && tolerance > 0.0 {
        scene
            .adaptive(pair, plan.sizes[0], tolerance)
            .map_err(|e| println!("adaptive run to {tolerance:.3e}: failed: {e}"))
            .ok()
    } else {
        println!("no estimate on the uniform meshes: no adaptive run");
        None
    };
    let mut elapsed = 0.0;
    let levels: Vec<(AdaptiveLevel, f64)> = adaptive
        .as_ref()
        .map(|a| {
            a.levels
                .iter()
                .map(|l| {
                    elapsed += l.seconds;
                    (*l, elapsed)
                })
                .collect()
        })
        .unwrap_or_default();
    for (l, _) in &levels {
        println!(
            "{:<9} {:>9} {:>9} {:>12} {:>12} {:>8} {:>9.3}",
            "adaptive",
            l.cells,
            l.dofs,
            show(Some(l.estimate)),
            show(l.error_energy),
            l.error_energy
                .map_or("-".into(), |x| format!("{:.2}", l.estimate / x)),
            l.seconds
        );
    }

    // error and estimate against unknowns, with the rates attained
    let u_estimate: Vec<(f64, f64)> = uniform
        .iter()
        .filter_map(|r| Some((r.dofs as f64, r.estimate?)))
        .collect();
    let u_error: Vec<(f64, f64)> = uniform
        .iter()
        .filter_map(|r| Some((r.dofs as f64, error(r)?)))
        .collect();
    let a_estimate: Vec<(f64, f64)> = levels
        .iter()
        .map(|(l, _)| (l.dofs as f64, l.estimate))
        .collect();
    let a_error: Vec<(f64, f64)> = levels
        .iter()
        .filter_map(|(l, _)| Some((l.dofs as f64, l.error_energy?)))
        .collect();
    // the rates of the error where known, else of the estimate
    let (u_rated, a_rated) = if a_error.is_empty() {
        (&u_estimate, &a_estimate)
    } else {
        (&u_error, &a_error)
    };
    let mut series = vec![
        Series::marked("uniform: estimate", u_estimate.clone()),
        Series::marked("adaptive: estimate", a_estimate.clone()),
    ];
    if !a_error.is_empty() || !u_error.is_empty() {
        series.push(Series::marked("uniform: error", u_error.clone()));
        series.push(Series::marked("adaptive: error", a_error.clone()));
    }
    let (u_rate, a_rate) = (settled_rate(u_rated), settled_rate(a_rated));
    series.extend(rate_triangle("uniform", u_rated, u_rate));
    series.extend(rate_triangle("adaptive", a_rated, a_rate));
    println!(
        "rates in unknowns N (of the {}): uniform N^{u_rate:.2}, adaptive N^{a_rate:.2}",
        if a_error.is_empty() {
            "estimate"
        } else {
            "error"
        }
    );
    plot::chart(
        &output(out, &name, Study::Adaptivity, "svg"),
        &format!(
            "{}, {pair}: error and estimate against unknowns",
            scene.setting()
        ),
        Axes {
            x: "unknowns N",
            y: "energy norm",
            log_x: true,
            log_y: true,
            rates: false,
        },
        &series,
    )
    .map_err(io)?;

    // the efficiency index
    let index = |points: &[(f64, f64)], errors: &[(f64, f64)]| -> Vec<(f64, f64)> {
        points
            .iter()
            .zip(errors)
            .filter(|(p, e)| p.0 == e.0 && e.1 > 0.0)
            .map(|(p, e)| (p.0, p.1 / e.1))
            .collect()
    };
    let u_index = index(
        &uniform
            .iter()
            .filter(|r| r.estimate.is_some() && error(r).is_some())
            .map(|r| (r.dofs as f64, r.estimate.unwrap_or(f64::NAN)))
            .collect::<Vec<_>>(),
        &u_error,
    );
    let a_index = index(
        &levels
            .iter()
            .filter(|(l, _)| l.error_energy.is_some())
            .map(|(l, _)| (l.dofs as f64, l.estimate))
            .collect::<Vec<_>>(),
        &a_error,
    );
    if !u_index.is_empty() || !a_index.is_empty() {
        plot::chart(
            &out.join(format!("{name}-adaptivity-efficiency.svg")),
            &format!("{}, {pair}: efficiency index η / ‖e‖", scene.setting()),
            Axes {
                x: "unknowns N",
                y: "η / ‖e‖",
                log_x: true,
                log_y: false,
                rates: false,
            },
            &[
                Series::marked("uniform", u_index),
                Series::marked("adaptive", a_index),
            ],
        )
        .map_err(io)?;
    }

    // against wall time: the adaptive run's cumulative time
    let measured = |r: &Row| error(r).or(r.estimate);
    let u_time: Vec<(f64, f64)> = uniform
        .iter()
        .filter_map(|r| Some((r.seconds, measured(r)?)))
        .collect();
    let a_time: Vec<(f64, f64)> = levels
        .iter()
        .map(|(l, t)| (*t, l.error_energy.unwrap_or(l.estimate)))
        .collect();
    plot::chart(
        &out.join(format!("{name}-adaptivity-time.svg")),
        &format!(
            "{}, {pair}: {} against wall time",
            scene.setting(),
            if a_error.is_empty() {
                "estimate"
            } else {
                "error"
            }
        ),
        Axes {
            x: "seconds (adaptive: cumulative)",
            y: "energy norm",
            log_x: true,
            log_y: true,
            rates: false,
        },
        &[
            Series::marked("uniform", u_time),
            Series::marked("adaptive", a_time),
        ],
    )
    .map_err(io)?;

    if let Some(run) = &adaptive {
        plot::mesh(
            &out.join(format!("{name}-adaptivity-mesh.svg")),
            &format!(
                "{}, {pair}: the final adaptive mesh ({} cells), contact set shaded",
                scene.setting(),
                run.levels.last().map_or(0, |l| l.cells)
            ),
            &run.fields,
        )
        .map_err(io)?;
    }

    let nan = |v: Option<f64>| v.unwrap_or(f64::NAN);
    let mut rows: Vec<Vec<f64>> = uniform
        .iter()
        .map(|r| {
            vec![
                0.0,
                r.cells as f64,
                r.dofs as f64,
                nan(r.estimate),
                nan(error(r)),
                r.seconds,
            ]
        })
        .collect();
    rows.extend(levels.iter().map(|(l, _)| {
        vec![
            1.0,
            l.cells as f64,
            l.dofs as f64,
            l.estimate,
            nan(l.error_energy),
            l.seconds,
        ]
    }));
    write_csv_named(
        &output(out, &name, Study::Adaptivity, "csv"),
        "run",
        "cells,dofs,estimate,error_energy,seconds",
        &["uniform", "adaptive"],
        &rows,
    )
    .map_err(io)
}

#[cfg(test)]
mod tests {
    use super::settled_rate;

    /// On `y = 3 x^{-1.5}` past a different start, the second half's slope is −1.5.
    #[test]
    fn the_settled_rate_is_the_slope_of_the_second_half() {
        let mut points: Vec<(f64, f64)> = vec![(1.0, 100.0), (2.0, 90.0)];
        points.extend((2..8).map(|k| {
            let x = 10f64.powi(k);
            (x, 3.0 * x.powf(-1.5))
        }));
        assert!((settled_rate(&points) + 1.5).abs() < 1e-12);
        assert!(settled_rate(&points[..2]).is_nan());
    }
}
