//! The locking study, once for every family with a thickness (docs/mathematics.md §3,
//! §6): a scene solved for each of its pairs on a few meshes and thicknesses t → 0, the
//! family's quantity against its value in the thin limit ([`Locking`]: the Timoshenko
//! beam's largest deflection against Euler–Bernoulli's, the Reissner–Mindlin plate's
//! centre deflection against Kirchhoff's). A locking-free pair keeps the relative
//! difference at the discretization error as t falls; a locking one falls towards −1.

use crate::models::families;
use crate::models::family::{Limit, Locking};
use crate::models::report::Settings;
use crate::models::scene::{Name, Scene};
use crate::plot::{self, Axes, Series};
use crate::studies::{io, output, Study};
use fem_runtime::{Error, Result};
use std::path::Path;

/// The thicknesses of the locking study as the command line runs it.
pub const THICKNESSES: [f64; 7] = [1e-1, 3e-2, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4];

/// One solve of the locking study.
#[derive(Clone, Debug)]
pub struct LockingRow {
    /// The pair.
    pub pair: &'static str,
    /// The mesh size (N, or elements).
    pub mesh_size: usize,
    /// The thickness t.
    pub thickness: f64,
    /// The family's quantity ([`Locking::quantity`]) of the solve.
    pub quantity: f64,
    /// Its value in the limit t → 0 ([`Locking::limit`]).
    pub limit: f64,
    /// `quantity / limit − 1`.
    pub relative_error: f64,
}

/// The family's measure of locking for `scene`.
///
/// # Errors
/// [`Error::Input`] for a family without a thickness whose limit is a thinner model.
pub fn measure_of(scene: &Scene) -> Result<Locking> {
    families::family(scene.family)
        .and_then(|f| f.locking())
        .ok_or_else(|| {
            Error::Input(format!(
                "scene `{}` (family {}) has no locking study: its family has no thickness whose limit t → 0 is a thinner model",
                scene.name, scene.family
            ))
        })
}

/// The locking study on `scene` at its study load: every pair of the scene on every
/// size of `mesh_sizes` and t of `thicknesses`. With `csv`, also writes
/// `pair,mesh_size,thickness,<quantity>,relative_error` to that file.
///
/// # Errors
/// [`measure_of`]'s, the solves', a solve without the family's limit value, and
/// [`Error::Input`] when the file cannot be written.
pub fn locking_study(
    scene: &Scene,
    mesh_sizes: &[usize],
    thicknesses: &[f64],
    csv: Option<&Path>,
) -> Result<Vec<LockingRow>> {
    let measure = measure_of(scene)?;
    let finest = mesh_sizes.iter().copied().max().unwrap_or(1);
    // NaN where each solve reports its own limit
    let solved_limit = match measure.limit {
        Limit::Reported(_) => f64::NAN,
        Limit::Scene(limit_of) => {
            let limit = limit_of(scene).ok_or_else(|| {
                Error::Input(format!(
                    "scene `{}` has no {} scene to compare with",
                    scene.name, measure.limit_words
                ))
            })?;
            let settings = Settings {
                mesh_size: Some(16 * finest),
                load: scene.study_load,
                ..Settings::default()
            };
            let report = families::solve(&limit, &settings)?.report;
            number(&report, &limit, "", measure.quantity)?
        }
    };
    let mut rows = Vec::new();
    for pair in families::pairs_of(scene) {
        for &n in mesh_sizes {
            for &t in thicknesses {
                let settings = Settings {
                    pair: Some(pair.name.to_string()),
                    mesh_size: Some(n),
                    load: scene.study_load,
                    parameters: vec![(Name::from("t"), t)],
                    ..Settings::default()
                };
                let report = families::solve(scene, &settings)?.report;
                let at = format!(" with {} at t = {t:e}", pair.name);
                let quantity = number(&report, scene, &at, measure.quantity)?;
                let limit = match measure.limit {
                    Limit::Reported(key) => number(&report, scene, &at, key)?,
                    Limit::Scene(_) => solved_limit,
                };
                rows.push(LockingRow {
                    pair: pair.name,
                    mesh_size: n,
                    thickness: t,
                    quantity,
                    limit,
                    relative_error: quantity / limit - 1.0,
                });
            }
        }
    }
    if let Some(path) = csv {
        write_rows(path, measure.quantity, &rows)?;
    }
    Ok(rows)
}

/// The number `key` of a report of `scene` (solved `at`).
fn number(
    report: &crate::models::report::Report,
    scene: &Scene,
    at: &str,
    key: &str,
) -> Result<f64> {
    report.number(key).ok_or_else(|| {
        Error::Input(format!(
            "the solve of `{}`{at} reports no `{key}`",
            scene.name
        ))
    })
}

fn write_rows(path: &Path, quantity: &str, rows: &[LockingRow]) -> Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(io)?;
    }
    let mut text = format!("pair,mesh_size,thickness,{quantity},relative_error\n");
    for r in rows {
        text += &format!(
            "{},{},{:e},{:e},{:e}\n",
            r.pair, r.mesh_size, r.thickness, r.quantity, r.relative_error
        );
    }
    std::fs::write(path, text).map_err(io)
}

/// The mesh sizes of the study: the scene's size and its two halvings, and twice it with
/// `full` (the plates' N = 8, 16, 32; the beams' 64, 128, 256 elements).
pub fn mesh_sizes(scene: &Scene, full: bool) -> Vec<usize> {
    let n = scene.mesh_size.max(4);
    let mut sizes = vec![n / 4, n / 2, n];
    if full {
        sizes.push(2 * n);
    }
    sizes
}

/// The locking study as the CLI runs it (`study mindlin-square locking`): [`mesh_sizes`],
/// t of [`THICKNESSES`], a table, `out/<scene>-locking.csv` and the chart of the
/// relative difference against t, one line per (pair, size).
///
/// # Errors
/// [`locking_study`]'s, and [`Error::Input`] when the chart cannot be written.
pub fn run(scene: &Scene, full: bool, out: &Path) -> Result<()> {
    let measure = measure_of(scene)?;
    let sizes = mesh_sizes(scene, full);
    let csv = output(out, &scene.name, Study::Locking, "csv");
    let rows = locking_study(scene, &sizes, &THICKNESSES, Some(&csv))?;
    println!(
        "\nlocking: {}, {} against the {} value {:.6e}",
        scene.name,
        measure.quantity_words,
        measure.limit_words,
        rows.first().map_or(f64::NAN, |r| r.limit)
    );
    println!(
        "{:<18} {:>5} {:>8} {:>14} {:>12}",
        "pair", "size", "t", measure.quantity_words, "rel. error"
    );
    for r in &rows {
        println!(
            "{:<18} {:>5} {:>8.0e} {:>14.6e} {:>12.3e}",
            r.pair, r.mesh_size, r.thickness, r.quantity, r.relative_error
        );
    }
    let mut series = Vec::new();
    for pair in families::pairs_of(scene) {
        for &n in &sizes {
            let points: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| r.pair == pair.name && r.mesh_size == n)
                .filter(|r| r.relative_error.is_finite())
                .map(|r| (r.thickness, r.relative_error.abs().max(1e-12)))
                .collect();
            series.push(Series::marked(format!("{} at {n}", pair.name), points));
        }
    }
    let svg = output(out, &scene.name, Study::Locking, "svg");
    let y = format!("|{} / {} − 1|", measure.quantity_words, measure.limit_words);
    plot::chart(
        &svg,
        &format!(
            "{}: {} against the {} limit as t → 0",
            scene.name, measure.quantity_words, measure.limit_words
        ),
        Axes {
            x: "t",
            y: &y,
            log_x: true,
            log_y: true,
            rates: false,
        },
        &series,
    )
    .map_err(io)
}
