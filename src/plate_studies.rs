//! The Reissner–Mindlin plate's own studies (docs/mathematics.md §6) over the one solve
//! ([`crate::models::families::solve`]): Newton's iterations per level of a nested solve
//! against cold starts, and convergence without an exact solution (the changes of J_h,
//! ∫λ_h and the contact radius between meshes). Locking is the one study of
//! [`crate::locking`].

use crate::models::families;
use crate::models::geometry::{halving_sizes, Fields};
use crate::models::report::{Report, Settings};
use crate::models::scene::{Domain, Name, Scene};
use crate::plot::{self, Axes, Series};
use crate::studies::{io, output, write_csv, Study};
use fem_runtime::Result;
use std::path::Path;

/// The coarsest level of a nested plate solve (the family's: N halves while it is even
/// and at least this).
const COARSEST_LEVEL: usize = 4;

/// Runs the plate study `kind` on `scene` (`iterations`, `convergence`);
/// `None` where `scene` is not a plate scene or `kind` is a generic study kind (the one
/// implementation runs it).
///
/// # Errors
/// The study's errors.
pub fn run(scene: &Scene, kind: &str, full: bool, out: &Path) -> Option<Result<()>> {
    if scene.family != "plate" {
        return None;
    }
    match kind {
        "iterations" => Some(iterations_run(scene, full, out)),
        "convergence" => Some(convergence_run(scene, full, out)),
        _ => None,
    }
}

/// One solve of a study: `pair` (`None`: the scene's default) at N = `size`, the load
/// `load`, the thickness `thickness` where given, nested or from a cold start.
fn solve(
    scene: &Scene,
    pair: Option<&str>,
    size: usize,
    load: Option<f64>,
    thickness: Option<f64>,
    nested: bool,
) -> Result<Report> {
    let parameters: Vec<(Name, f64)> = thickness.map(|t| ("t".into(), t)).into_iter().collect();
    let settings = Settings {
        pair: pair.map(str::to_string),
        mesh_size: Some(size),
        load,
        parameters,
        nested,
        ..Settings::default()
    };
    Ok(families::solve(scene, &settings)?.report)
}

/// A family quantity of `report` (NaN where absent).
fn quantity(report: &Report, key: &str) -> f64 {
    report.number(key).unwrap_or(f64::NAN)
}

/// The loads a plate scene's studies run (the default alone where it lists none).
fn loads(scene: &Scene) -> Vec<f64> {
    let listed = scene
        .reference::<crate::models::families::plate::PlateFacts>()
        .map(|f| f.loads.to_vec())
        .unwrap_or_default();
    if listed.is_empty() {
        scene.load.as_ref().map(|l| l.default).into_iter().collect()
    } else {
        listed
    }
}

/// What a mesh size counts on the scene's domain, for axes.
fn size_name(scene: &Scene) -> &'static str {
    match scene.domain {
        Domain::Disk { .. } => "rings",
        _ => "N (N×N×2 mesh)",
    }
}

/// One level of the iterations study: the Newton iterations on a mesh, within a nested
/// solve and from a cold start.
#[derive(Clone, Debug, PartialEq)]
pub struct IterationLevel {
    /// The load q.
    pub load: f64,
    /// The level's mesh size (N, or rings).
    pub mesh_size: usize,
    /// Its triangles.
    pub triangles: usize,
    /// Newton iterations on this level within the nested solve of the finest size
    /// (started from the level before; the coarsest from zero).
    pub nested: usize,
    /// Newton iterations of a cold start (from zero) on this level's mesh; `None` above
    /// `cold_max` or where the cold start failed (a result of the study).
    pub cold: Option<usize>,
}

/// The iterations study of `scene` at load `q`: one nested solve on the halvings of
/// `finest`, its iterations per level, and beside each level a cold start on that
/// level's mesh (up to size `cold_max`).
///
/// # Errors
/// The nested solve's.
pub fn iteration_levels(
    scene: &Scene,
    q: f64,
    finest: usize,
    cold_max: usize,
) -> Result<Vec<IterationLevel>> {
    let nested = solve(scene, None, finest, Some(q), None, true)?;
    let sizes = halving_sizes(finest, true, COARSEST_LEVEL, false);
    Ok(sizes
        .iter()
        .zip(&nested.solve.levels)
        .map(|(&n, &[triangles, iterations])| IterationLevel {
            load: q,
            mesh_size: n,
            triangles,
            nested: iterations,
            cold: (n <= cold_max)
                .then(|| {
                    solve(scene, None, n, Some(q), None, false)
                        .ok()
                        .map(|r| r.solve.iterations)
                })
                .flatten(),
        })
        .collect())
}

/// The iterations study as the CLI runs it (`study mindlin-disk iterations`): for every
/// load of the scene, [`iteration_levels`] up to N = 32 (128 with `full`), a table, the
/// CSV `load,mesh_size,triangles,nested,cold` and the chart of iterations against N:
/// nested iteration stays flat in h, a cold start grows.
///
/// # Errors
/// [`iteration_levels`]'s, and [`Error::Input`] when the output cannot be written.
pub fn iterations_run(scene: &Scene, full: bool, out: &Path) -> Result<()> {
    let finest = if full { 128 } else { 32 };
    println!(
        "\niterations: {}, semismooth Newton iterations per level of a nested solve, a cold start on the same mesh beside ('-': failed)",
        scene.name
    );
    println!(
        "{:>8} {:>6} {:>10} {:>7} {:>6}",
        "q", "N", "triangles", "nested", "cold"
    );
    let loads = loads(scene);
    let mut rows = Vec::new();
    for &q in &loads {
        rows.extend(iteration_levels(scene, q, finest, finest)?);
    }
    let show = |v: Option<usize>| v.map_or("-".to_string(), |c| c.to_string());
    for r in &rows {
        println!(
            "{:>8} {:>6} {:>10} {:>7} {:>6}",
            r.load,
            r.mesh_size,
            r.triangles,
            r.nested,
            show(r.cold)
        );
    }
    let mut series = Vec::new();
    for &q in &loads {
        let of = |pick: &dyn Fn(&IterationLevel) -> Option<usize>| -> Vec<(f64, f64)> {
            rows.iter()
                .filter(|r| r.load == q)
                .filter_map(|r| pick(r).map(|c| (r.mesh_size as f64, c.max(1) as f64)))
                .collect()
        };
        series.push(Series::marked(
            format!("nested, q = {q}"),
            of(&|r| Some(r.nested)),
        ));
        series.push(Series::marked(
            format!("cold start, q = {q}"),
            of(&|r| r.cold),
        ));
    }
    let svg = output(out, &scene.name, Study::Iterations, "svg");
    plot::chart(
        &svg,
        &format!("{}: Newton iterations per mesh", scene.name),
        Axes {
            x: size_name(scene),
            y: "iterations",
            log_x: true,
            log_y: true,
        },
        &series,
    )
    .map_err(io)?;
    write_csv(
        &output(out, &scene.name, Study::Iterations, "csv"),
        "load,mesh_size,triangles,nested,cold",
        &rows
            .iter()
            .map(|r| {
                vec![
                    r.load,
                    r.mesh_size as f64,
                    r.triangles as f64,
                    r.nested as f64,
                    r.cold.map_or(f64::NAN, |c| c as f64),
                ]
            })
            .collect::<Vec<_>>(),
    )
    .map_err(io)?;
    println!("→ {}, .csv", svg.display());
    Ok(())
}

/// One mesh of the convergence study.
#[derive(Clone, Debug)]
pub struct ConvergenceRow {
    /// The load q.
    pub load: f64,
    /// The mesh size (N, or rings).
    pub mesh_size: usize,
    /// The largest cell diameter.
    pub h: f64,
    /// The report of the solve.
    pub report: Report,
}

/// The quantities the convergence study follows, by name: `J_h`, `∫λ_h`, the contact
/// radius.
pub const CONVERGENCE_QUANTITIES: [&str; 3] = ["J_h", "∫λ_h", "contact radius"];

impl ConvergenceRow {
    /// `[J_h, ∫λ_h, contact radius]` (the radius 0 without an obstacle).
    pub fn quantities(&self) -> [f64; 3] {
        let radius = self.report.number("contact_radius").unwrap_or(0.0);
        [
            self.report.solve.energy.unwrap_or(f64::NAN),
            self.report.solve.total_contact_force,
            radius,
        ]
    }
}

/// The convergence study of `scene` at load `q`: the nested solve on each mesh size, one
/// row each. No exact solution is known with contact; [`differences`] gives the changes
/// between meshes and their observed rates.
///
/// # Errors
/// The solves'.
pub fn convergence_study(scene: &Scene, q: f64, sizes: &[usize]) -> Result<Vec<ConvergenceRow>> {
    sizes
        .iter()
        .map(|&n| {
            let settings = Settings {
                mesh_size: Some(n),
                load: Some(q),
                ..Settings::default()
            };
            let outcome = families::solve(scene, &settings)?;
            let h = match &outcome.fields {
                Fields::Triangles { mesh, .. } => mesh.max_h(),
                Fields::Interval { .. } => f64::NAN,
            };
            Ok(ConvergenceRow {
                load: q,
                mesh_size: n,
                h,
                report: outcome.report,
            })
        })
        .collect()
}

/// For rows on meshes halved each time: per quantity of [`ConvergenceRow::quantities`],
/// the differences `d_k = Q_{k+1} − Q_k` between consecutive meshes and the observed
/// rates `log2(|d_k| / |d_{k+1}|)` (for `Q_h = Q + C hᵖ`, `d_k ∝ h_kᵖ` and the rate is p).
/// Shapes: `differences[q]` has `rows − 1` entries, `rates[q]` `rows − 2`.
pub fn differences(rows: &[ConvergenceRow]) -> ([Vec<f64>; 3], [Vec<f64>; 3]) {
    let d: [Vec<f64>; 3] = std::array::from_fn(|q| {
        rows.windows(2)
            .map(|w| w[1].quantities()[q] - w[0].quantities()[q])
            .collect()
    });
    let rates = std::array::from_fn(|q| {
        d[q].windows(2)
            .map(|w| (w[0].abs() / w[1].abs()).log2())
            .collect()
    });
    (d, rates)
}

/// The convergence study as the CLI runs it (`study mindlin-disk convergence`): for each
/// load of the scene, [`convergence_study`] on N = 8, 16, 32 (up to 128 with `full`); a
/// table of J_h, ∫λ_h and the contact radius with the differences between meshes and
/// their observed rates, the CSV
/// `load,mesh_size,h,dofs,energy,total_contact_force,contact_radius,contact_area,lambda_interior_spread,iterations,seconds`
/// and the chart of |differences| against h (one line per quantity and load).
///
/// # Errors
/// [`convergence_study`]'s, and [`Error::Input`] when the output cannot be written.
pub fn convergence_run(scene: &Scene, full: bool, out: &Path) -> Result<()> {
    let sizes: &[usize] = if full {
        &[8, 16, 32, 64, 128]
    } else {
        &[8, 16, 32]
    };
    println!(
        "\nconvergence: {} ({}, t = {}), J_h, ∫λ_h and contact radius against h; Δ: change from the mesh before, rate: log2 of the ratio of consecutive Δ",
        scene.name,
        scene.domain.describe(),
        scene
            .parameter("t")
            .map_or("?".into(), fem_runtime::problem::number)
    );
    let mut csv = Vec::new();
    let mut series = Vec::new();
    for q in loads(scene) {
        let rows = convergence_study(scene, q, sizes)?;
        let (d, rates) = differences(&rows);
        println!(
            "q = {q}\n{:>5} {:>8} {:>8} {:>16} {:>10} {:>5} {:>14} {:>10} {:>5} {:>12} {:>10} {:>5} {:>10} {:>5}",
            "N", "h", "dofs", "J_h", "ΔJ", "rate", "∫λ_h", "Δ∫λ", "rate", "radius", "Δradius", "rate", "λ spread", "iter"
        );
        let entry = |v: &[f64], k: usize, shift: usize| {
            k.checked_sub(shift)
                .and_then(|k| v.get(k).copied())
                .unwrap_or(f64::NAN)
        };
        for (k, r) in rows.iter().enumerate() {
            let [j, force, radius] = r.quantities();
            let s = &r.report.solve;
            let spread = quantity(&r.report, "lambda_interior_spread");
            println!("{}", crate::dash_nan(format!(
                "{:>5} {:>8.4} {:>8} {:>16.9e} {:>10.2e} {:>5.2} {:>14.7e} {:>10.2e} {:>5.2} {:>12.6} {:>10.2e} {:>5.2} {:>10.2e} {:>5}",
                r.mesh_size,
                r.h,
                s.dofs,
                j,
                entry(&d[0], k, 1),
                entry(&rates[0], k, 2),
                force,
                entry(&d[1], k, 1),
                entry(&rates[1], k, 2),
                radius,
                entry(&d[2], k, 1),
                entry(&rates[2], k, 2),
                spread,
                s.iterations
            )));
            csv.push(vec![
                q,
                r.mesh_size as f64,
                r.h,
                s.dofs as f64,
                j,
                force,
                radius,
                s.contact_area.unwrap_or(f64::NAN),
                spread,
                s.iterations as f64,
                s.seconds,
            ]);
        }
        for (name, d) in CONVERGENCE_QUANTITIES.iter().zip(&d) {
            // the change to the next mesh, plotted at the coarser one's h
            let points = rows
                .iter()
                .zip(d)
                .filter(|(_, d)| d.is_finite() && d.abs() > 0.0)
                .map(|(r, d)| (r.h, d.abs()))
                .collect();
            series.push(Series::marked(format!("|Δ {name}|, q = {q}"), points));
        }
    }
    let svg = output(out, &scene.name, Study::Convergence, "svg");
    plot::chart(
        &svg,
        &format!(
            "{}: change of J_h, ∫λ_h and the contact radius to the next mesh",
            scene.name
        ),
        Axes {
            x: "h (largest cell diameter)",
            y: "|change to the next mesh|",
            log_x: true,
            log_y: true,
        },
        &series,
    )
    .map_err(io)?;
    write_csv(
        &output(out, &scene.name, Study::Convergence, "csv"),
        "load,mesh_size,h,dofs,energy,total_contact_force,contact_radius,contact_area,lambda_interior_spread,iterations,seconds",
        &csv,
    )
    .map_err(io)?;
    println!("→ {}, .csv", svg.display());
    Ok(())
}
