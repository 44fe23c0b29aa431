//! The λ-scatter study (docs/mathematics.md §9) over the one solve
//! ([`crate::models::families::solve`]): the scatter of λ_h in the contact interior of a
//! Kirchhoff plate on a flat obstacle, where λ = q exactly, for several pairs, α and
//! recoveries of λ (raw, patch-averaged once or twice), and its layer next to the free
//! boundary. It reads the interior statistics the Kirchhoff family reports; the other
//! study kinds are the one implementation of [`crate::studies`].

use crate::models::families;
use crate::models::report::{Report, Settings};
use crate::models::scene::{Adjustment, Scene};
use crate::plot::{self, Axes, Series};
use fem_runtime::obstacle::VariationalSolver;
use fem_runtime::{Error, Result};
use std::path::Path;

/// The study's name on the command line and in a scene's list of studies.
pub const NAME: &str = "lambda-scatter";

/// What the study's charts check, and against what (the report page's words).
pub const CHECKS: &str = "The scatter of λ_h in the interior of the contact set of a Kirchhoff plate on a flat obstacle, where λ = q exactly: the spread of λ_h for each pair, α and recovery (raw, patch-averaged once or twice) against h, and its layer next to the free boundary.";

/// `scene` with `adjustment` applied by its family.
fn adjusted(scene: &Scene, adjustment: &Adjustment) -> Result<Scene> {
    let mut scene = scene.clone();
    families::family(scene.family)
        .ok_or_else(|| Error::Input(format!("scene `{}` has no family", scene.name)))?
        .adjust(&mut scene, adjustment)?;
    Ok(scene)
}

/// One solve of a study: `pair` at N = `size`, load `load`, α `alpha` (`None`: the
/// pair's rule).
fn solve(
    scene: &Scene,
    pair: &str,
    size: usize,
    load: Option<f64>,
    alpha: Option<f64>,
) -> Result<Report> {
    let settings = Settings {
        pair: Some(pair.into()),
        mesh_size: Some(size),
        load,
        alpha,
        solver: VariationalSolver::SemismoothNewton,
        ..Settings::default()
    };
    Ok(families::solve(scene, &settings)?.report)
}

fn write_text(path: &Path, text: &str) -> Result<()> {
    let write = || -> std::io::Result<()> {
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir)?;
        }
        std::fs::write(path, text)
    };
    write().map_err(|e| Error::Input(format!("cannot write {}: {e}", path.display())))
}

fn chart(path: &Path, title: &str, axes: Axes, series: &[Series]) -> Result<()> {
    plot::chart(path, title, axes, series)
        .map_err(|e| Error::Input(format!("cannot write {}: {e}", path.display())))?;
    println!("→ {}, .csv", path.display());
    Ok(())
}

/// One method of the λ-scatter study: a pair, α as a multiple of `1/C_I` (or fixed for
/// Morley, whose C_I vanishes), and the report's key of λ read the method's way.
#[derive(Clone, Copy, Debug)]
pub struct ScatterMethod {
    /// Label in the table, CSV and chart.
    pub label: &'static str,
    /// The pair.
    pub pair: &'static str,
    /// `α·C_I` for Argyris; α itself for Morley (`None`: the pair's rule).
    pub alpha: Option<f64>,
    /// The report's statistics of λ over the contact interior read this way: raw
    /// (`interior_multiplier_raw`), patch-averaged once or twice.
    pub key: &'static str,
}

const fn method(
    label: &'static str,
    pair: &'static str,
    alpha: Option<f64>,
    key: &'static str,
) -> ScatterMethod {
    ScatterMethod {
        label,
        pair,
        alpha,
        key,
    }
}

/// The report keys of the three readings of λ.
const RAW: &str = "interior_multiplier_raw";
const AVERAGED: &str = "interior_multiplier";
const TWICE: &str = "interior_multiplier_twice_averaged";

/// The methods of the λ-scatter study (docs/mathematics.md §9).
pub const SCATTER_METHODS: &[ScatterMethod] = &[
    method("argyris-p0 α=½/C_I", "argyris-p0", None, RAW),
    method("argyris-p0 α=0.9/C_I", "argyris-p0", Some(0.9), RAW),
    method("argyris-p0 α=0.1/C_I", "argyris-p0", Some(0.1), RAW),
    method("argyris-p1disc α=½/C_I", "argyris-p1disc", None, RAW),
    method("morley-p0 α=0.01", "morley-p0", None, RAW),
    method(
        "argyris-p0 α=½/C_I patch average",
        "argyris-p0",
        None,
        AVERAGED,
    ),
    method(
        "argyris-p0 α=½/C_I twice averaged",
        "argyris-p0",
        None,
        TWICE,
    ),
    method(
        "argyris-p1disc α=½/C_I twice averaged",
        "argyris-p1disc",
        None,
        TWICE,
    ),
];

/// The interior statistics of λ the report gives under `key`: `[cells, min, max, mean,
/// max relative error]` (NaN where there is no contact interior).
fn interior(report: &Report, key: &str) -> [f64; 5] {
    let stats = report.quantities.get(key);
    let field = |name: &str| {
        stats
            .and_then(|s| s.get(name))
            .and_then(serde_json::Value::as_f64)
            .unwrap_or(f64::NAN)
    };
    [
        field("cells"),
        field("min"),
        field("max"),
        field("mean"),
        field("max_relative_error"),
    ]
}

/// One row of the λ-scatter study.
#[derive(Clone, Debug)]
pub struct ScatterRow {
    /// The method.
    pub method: ScatterMethod,
    /// N.
    pub mesh_size: usize,
    /// The solve's report.
    pub report: Report,
}

impl ScatterRow {
    /// `[cells, min, max, mean, max relative error]` of λ over the contact interior, read
    /// the method's way.
    pub fn interior(&self) -> [f64; 5] {
        interior(&self.report, self.method.key)
    }
}

/// The λ-scatter study on `scene` at load `load` (flat obstacle): every method of
/// [`SCATTER_METHODS`] on every N of `meshes` (the pairs other than Argyris–P0 up to
/// N = 64: they take minutes beyond, and their trend is clear by then).
///
/// # Errors
/// The solves'.
pub fn scatter_study(scene: &Scene, load: f64, meshes: &[usize]) -> Result<Vec<ScatterRow>> {
    let scene = adjusted(scene, &Adjustment::Obstacle("flat".into()))?;
    let mut rows = Vec::new();
    for &method in SCATTER_METHODS {
        let largest = if method.pair == "argyris-p0" {
            usize::MAX
        } else {
            64
        };
        for &n in meshes.iter().filter(|&&n| n <= largest) {
            let alpha = match (method.alpha, method.pair) {
                (None, _) => None,
                (Some(a), "morley-p0") => Some(a),
                (Some(a), pair) => {
                    let c_i = solve(&scene, pair, n, Some(load), None)?
                        .solve
                        .inverse_constant;
                    Some(a / c_i)
                }
            };
            rows.push(ScatterRow {
                method,
                mesh_size: n,
                report: solve(&scene, method.pair, n, Some(load), alpha)?,
            });
        }
    }
    Ok(rows)
}

/// The λ-scatter study as the CLI runs it (`study kirchhoff-obstacle lambda-scatter`):
/// [`scatter_study`] at q = 20 on N = 16, 32, 64 (and 128 with `full`), a table, the CSV
/// and the chart of the interior band `[min, max]/q` against N, one pair of lines per
/// method; and the layer of λ_h next to the free boundary (Argyris–P0 at the C_I rule).
///
/// # Errors
/// [`scatter_study`]'s, and [`Error::Input`] when a file cannot be written.
pub fn scatter_run(scene: &Scene, full: bool, out: &Path) -> Result<()> {
    let meshes: &[usize] = if full {
        &[16, 32, 64, 128]
    } else {
        &[16, 32, 64]
    };
    let load = 20.0;
    let rows = scatter_study(scene, load, meshes)?;
    println!(
        "\nλ-scatter: {} q = {load}, flat obstacle; λ_h over the contact interior (exact {load})",
        scene.name
    );
    println!(
        "{:<38} {:>4} {:>10} {:>6} {:>10} {:>10} {:>10} {:>10} {:>11}",
        "method", "N", "α", "cells", "min", "max", "mean", "max|err|/q", "∫λ_h"
    );
    let mut csv = String::from(
        "method,mesh_size,alpha,cells,min,max,mean,max_relative_error,total_contact_force,energy\n",
    );
    for r in &rows {
        let [cells, min, max, mean, error] = r.interior();
        let s = &r.report.solve;
        let alpha = s.alpha.unwrap_or(f64::NAN);
        println!(
            "{}",
            crate::dash_nan(format!(
                "{:<38} {:>4} {alpha:>10.3e} {:>6} {min:>10.4} {max:>10.4} {mean:>10.4} {error:>10.2e} {:>11.6}",
                r.method.label,
                r.mesh_size,
                if cells.is_nan() { 0.0 } else { cells },
                s.total_contact_force
            ))
        );
        csv += &format!(
            "{},{},{alpha:e},{},{min:e},{max:e},{mean:e},{error:e},{:e},{:e}\n",
            r.method.label,
            r.mesh_size,
            if cells.is_nan() { 0.0 } else { cells },
            s.total_contact_force,
            s.energy.unwrap_or(f64::NAN)
        );
    }
    write_text(
        &out.join(format!("{}-lambda-scatter.csv", scene.name)),
        &csv,
    )?;
    let mut series = Vec::new();
    for method in SCATTER_METHODS {
        let mine: Vec<&ScatterRow> = rows
            .iter()
            .filter(|r| r.method.label == method.label)
            .collect();
        let band = |k: usize| -> Vec<(f64, f64)> {
            mine.iter()
                .map(|r| (r.mesh_size as f64, r.interior()[k] / load))
                .filter(|p| p.1.is_finite())
                .collect()
        };
        series.push(Series::marked(format!("{} max", method.label), band(2)));
        series.push(Series::marked(format!("{} min", method.label), band(1)));
    }
    layer_run(scene, &rows, load, out)?;
    chart(
        &out.join(format!("{}-lambda-scatter.svg", scene.name)),
        &format!(
            "{}: λ_h / q over the contact interior (min and max), q = {load}",
            scene.name
        ),
        Axes {
            x: "N (N×N×2 mesh)",
            y: "λ_h / q",
            log_x: true,
            log_y: false,
            rates: false,
        },
        &series,
    )
}

/// The layer of λ_h next to the free boundary of the first method's solves: the
/// report's `multiplier_layer` per N, a table, CSV and chart.
fn layer_run(scene: &Scene, rows: &[ScatterRow], load: f64, out: &Path) -> Result<()> {
    use crate::models::families::kirchhoff::LayerBand;
    let first = SCATTER_METHODS[0].label;
    let mut layer_series = Vec::new();
    let mut layer_csv = String::from(
        "mesh_size,distance_in_cells,cells,max_relative_error,patch_average_max_relative_error\n",
    );
    println!("\nλ_h next to the free boundary ({first}): max |λ − q|/q per band of one cell diameter, raw / patch average");
    for r in rows.iter().filter(|r| r.method.label == first) {
        let layer: Vec<LayerBand> = r
            .report
            .quantities
            .get("multiplier_layer")
            .and_then(|v| serde_json::from_value(v.clone()).ok())
            .unwrap_or_default();
        let bands: Vec<String> = layer
            .iter()
            .map(|b| {
                format!(
                    "{:.0e}/{:.0e}",
                    b.max_relative_error, b.patch_average_max_relative_error
                )
            })
            .collect();
        println!("  N = {:>3}: {}", r.mesh_size, bands.join(" "));
        for b in &layer {
            layer_csv += &format!(
                "{},{},{},{:e},{:e}\n",
                r.mesh_size,
                b.distance_in_cells,
                b.cells,
                b.max_relative_error,
                b.patch_average_max_relative_error
            );
        }
        let at = |f: fn(&LayerBand) -> f64| -> Vec<(f64, f64)> {
            layer
                .iter()
                .filter(|b| b.cells > 0)
                .map(|b| (b.distance_in_cells as f64, f(b).max(1e-8)))
                .collect()
        };
        layer_series.push(Series::marked(
            format!("raw N = {}", r.mesh_size),
            at(|b| b.max_relative_error),
        ));
        layer_series.push(Series::line(
            format!("patch average N = {}", r.mesh_size),
            at(|b| b.patch_average_max_relative_error),
        ));
    }
    write_text(
        &out.join(format!("{}-lambda-layer.csv", scene.name)),
        &layer_csv,
    )?;
    chart(
        &out.join(format!("{}-lambda-layer.svg", scene.name)),
        &format!(
            "{}: max |λ_h − q|/q against the distance from the free boundary, q = {load}",
            scene.name
        ),
        Axes {
            x: "distance from the free boundary / cell diameter",
            y: "max |λ_h − q| / q",
            log_x: false,
            log_y: true,
            rates: false,
        },
        &layer_series,
    )
}
