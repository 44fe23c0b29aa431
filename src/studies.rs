//! The studies behind the charts, each kind implemented once and run on any scene whose
//! family implements [`StudyScene`]: convergence (against the exact solution, or by the
//! changes between successive meshes where there is none), stability of
//! the plain against the stabilized pairs (the family's measure of the multiplier
//! problem, and multiplier profiles), the α sweep, work against precision, and Newton
//! iterations with nested iteration and from a cold start. `locking` (t → 0) is
//! [`crate::locking`], once for every family with a thickness.
//!
//! A study of scene `s` prints a table and writes `out/<s>-<study>.svg` and `.csv`; the
//! functions behind each (the tests run small versions) return their rows.

use crate::plot::{self, Axes, Series};
use fem_runtime::obstacle::VariationalSolver;
use fem_runtime::{Error, Result};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The study kinds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Study {
    /// Errors against the exact solution (else the changes between successive meshes)
    /// and observed rates, every pair.
    Convergence,
    /// Timoshenko → Euler–Bernoulli as t → 0; the locking P1–P1 method beside.
    Locking,
    /// Plain (α = 0) against stabilized pairs: the family's stability measure of the
    /// multiplier problem, and multiplier profiles.
    Stability,
    /// Errors and contact against α on one mesh, with 1/C_I marked.
    Alpha,
    /// Error against time for every solver.
    WorkPrecision,
    /// Newton iterations with nested iteration and from a cold start.
    Iterations,
    /// Uniform refinement against the adaptive loop: error and estimate against
    /// unknowns, the efficiency index, error against time, the final mesh (the module
    /// `adaptivity_study`).
    Adaptivity,
}

impl Study {
    /// Every study kind.
    pub const ALL: [Study; 7] = [
        Study::Convergence,
        Study::Locking,
        Study::Stability,
        Study::Alpha,
        Study::WorkPrecision,
        Study::Iterations,
        Study::Adaptivity,
    ];

    /// Its name on the command line and in the registry.
    pub fn name(self) -> &'static str {
        match self {
            Study::Convergence => "convergence",
            Study::Locking => "locking",
            Study::Stability => "stability",
            Study::Alpha => "alpha",
            Study::WorkPrecision => "work-precision",
            Study::Iterations => "iterations",
            Study::Adaptivity => "adaptivity",
        }
    }

    /// What the study's charts check, and against what (the report page's words).
    pub fn checks(self) -> &'static str {
        match self {
            Study::Convergence => "Errors against the exact solution on uniformly refined meshes (where the scene has none, the change to the next mesh), for every pair, with the observed rate of each curve's finest segment in a triangle; the rates the theory predicts are in docs/mathematics.md.",
            Study::Locking => "The thick model's deflection (the beam's largest, the plate's at the centre) relative to its thin limit (Euler–Bernoulli, Kirchhoff) as the thickness t → 0, on several meshes, for the locking-free pairs and the plain pair that locks beside them: a locking-free pair's difference falls with t to its discretization error, a locking pair's grows towards 1 (its deflection towards zero).",
            Study::Stability => "The inf-sup constants γ₁ ≤ γ₂ of the multiplier's Schur complement B A⁻¹ Bᵀ + C in the stabilization's norm against h, for the plain (α = 0) and the stabilized pairs: a plain pair's γ₁ at rounding or falling with h is the instability the stabilization removes; below, λ_h along a line of the plain method (oscillating) against the stabilized one and the exact λ where known.",
            Study::Alpha => "Errors and the contact measure on one mesh against α, with α = 1/C_I (beyond which the stabilized matrix loses definiteness) and the automatic choice ½/C_I: the working range of α·C_I.",
            Study::WorkPrecision => "The model choice: every candidate (model, pair, uniform and adaptive meshes) as its error (the true error where a reference exists, else the estimate plus the modelling estimate) against wall time, with the choice made at three tolerances marked; where the scene has an exact solution, also the error against solve time of every solver (nested and cold semismooth Newton, PDAS, clarabel's QP).",
            Study::Iterations => "Newton iterations on each mesh with nested iteration (from the coarser mesh's solution) and from a cold start: with nesting the count stays flat as the mesh is refined.",
            Study::Adaptivity => "Uniform refinement against the adaptive loop (the model's estimator, Dörfler marking, newest-vertex bisection): error and estimate against unknowns, the efficiency index estimate/error (bounded above and below where the estimator is reliable and efficient), error against wall time, and the final mesh with the contact set.",
        }
    }

    /// The study called `name`.
    pub fn parse(name: &str) -> Option<Study> {
        Self::ALL.into_iter().find(|s| s.name() == name)
    }

    /// Whether its results depend on the load and the obstacle, so that it runs on each
    /// of a scene's study variants: not the stability study (the multiplier's Schur
    /// complement `B A⁻¹ Bᵀ + C` sees neither) nor locking (the thin limit of the same
    /// load).
    pub fn depends_on_data(self) -> bool {
        !matches!(self, Study::Stability | Study::Locking)
    }
}

/// One solve of a study.
#[derive(Clone, Copy, Debug)]
pub struct Run {
    /// Element pair (its command-line name).
    pub pair: &'static str,
    /// Mesh size: elements (beams) or N of the N×N×2 mesh (membranes).
    pub size: usize,
    /// α; `None`: the family's default; `Some(0.0)`: the plain mixed method.
    pub alpha: Option<f64>,
    /// LCP solver.
    pub solver: VariationalSolver,
    /// Nested iteration from coarser meshes (else a cold start on the final mesh).
    pub nested: bool,
}

impl Run {
    /// The default solve of `pair` at `size`: default α, nested semismooth Newton.
    pub fn new(pair: &'static str, size: usize) -> Self {
        Self {
            pair,
            size,
            alpha: None,
            solver: VariationalSolver::SemismoothNewton,
            nested: true,
        }
    }
}

/// What one solve of a study reports, whatever the family.
#[derive(Clone, Debug)]
pub struct Row {
    /// Element pair.
    pub pair: &'static str,
    /// Mesh size (elements, or N).
    pub size: usize,
    /// Largest cell diameter.
    pub h: f64,
    /// Smallest cell diameter (where a graded mesh refines: Hertz's contact zone).
    pub h_min: f64,
    /// Cells of the mesh (elements, or triangles).
    pub cells: usize,
    /// Unknowns after eliminating boundary DOFs (primal and multiplier).
    pub dofs: usize,
    /// α used.
    pub alpha: f64,
    /// `‖u − u_h‖_L2` where the exact solution is known.
    pub error_l2: Option<f64>,
    /// `|u − u_h|_H1` where the exact solution is known.
    pub error_h1: Option<f64>,
    /// An error of the multiplier where the family measures one (membranes:
    /// `(Σ_T h_T² ‖λ − λ_h‖²_T)^½`).
    pub error_multiplier: Option<f64>,
    /// The discrete energy `J_h`, where the model has one.
    pub energy: Option<f64>,
    /// The relative error of the family's reference quantity against the scene's
    /// reference value (a plate's centre deflection against the series), where it has one.
    pub reference_error: Option<f64>,
    /// `∫λ_h`.
    pub total_contact_force: f64,
    /// `|∫λ_h − ∫λ|` where the exact ∫λ is known.
    pub force_error: Option<f64>,
    /// The family's measure of the contact set ([`StudyScene::contact_names`]: beams the
    /// left edge of the contact set, membranes its area).
    pub contact: f64,
    /// Its distance from the exact one, where known.
    pub contact_error: Option<f64>,
    /// Newton iterations on the final mesh.
    pub iterations: usize,
    /// Solve time in seconds.
    pub seconds: f64,
    /// The a-posteriori estimate `(η² + S²)^{1/2}`, where the model declares an
    /// estimator.
    pub estimate: Option<f64>,
    /// The estimate relative to `‖u_h‖_a`.
    pub estimate_relative: Option<f64>,
    /// The error in the estimator's (energy) norm, where the exact solution is known.
    pub error_energy: Option<f64>,
    /// KKT residual.
    pub kkt_residual: f64,
    /// The solve's warnings.
    pub warnings: Vec<String>,
}

/// An adaptive run of the adaptivity study (the module `adaptivity_study`): its levels
/// and the final level's fields.
pub struct AdaptiveRun {
    /// Every level, first to last.
    pub levels: Vec<fem_runtime::adaptivity::AdaptiveLevel>,
    /// The final mesh's fields (λ_h and the contact share per cell).
    pub fields: fem_models::geometry::Fields,
}

/// One mesh and pair of the stability study: the family's measure of the multiplier
/// problem for the plain (α = 0) and the stabilized method.
#[derive(Clone, Debug)]
pub struct StabilityRow {
    /// Element pair.
    pub pair: &'static str,
    /// Mesh size.
    pub size: usize,
    /// α of the stabilized method.
    pub alpha: f64,
    /// The measure of the plain method ([`Measure::labels`]).
    pub plain: Vec<f64>,
    /// The measure of the stabilized method.
    pub stabilized: Vec<f64>,
}

/// What a family measures in the stability study.
#[derive(Clone, Copy, Debug)]
pub struct Measure {
    /// The table's title.
    pub title: &'static str,
    /// The values of a [`StabilityRow`] side (`κ₂`, or `γ₁, γ₂`).
    pub labels: &'static [&'static str],
    /// The chart's y axis.
    pub axis: &'static str,
    /// The plotted value of a measured one.
    pub plotted: fn(f64) -> f64,
}

/// The stability study's one measure, for every family: the two smallest eigenvalues
/// γ₁ ≤ γ₂ of the multiplier's Schur complement `B A⁻¹ Bᵀ + C` in the norm of the
/// pair's own stabilization ([`fem_runtime::stabilization::inf_sup_spectrum`]; √γ₁ is
/// the inf-sup constant). A zero γ (a kernel) is drawn at 1e-16.
pub fn inf_sup_measure() -> Measure {
    Measure {
        title: "inf-sup constants of the multiplier, γ₁ ≤ γ₂ of B A⁻¹ Bᵀ + C in the stabilization's norm",
        labels: &["γ₁", "γ₂"],
        axis: "γ",
        plotted: |v| v.max(1e-16),
    }
}

/// The exact multiplier along the line of [`StudyScene::multiplier_profile`].
pub struct ExactMultiplier {
    /// The contact interval on that line.
    pub contact: [f64; 2],
    /// `λ(x)` on that line (point forces at contact edges left out).
    pub lambda: Box<dyn Fn(f64) -> f64>,
}

/// The meshes and settings of one study on one scene (quick, or `--full`).
#[derive(Clone, Debug)]
pub struct Plan {
    /// The pair (studies over every pair use [`StudyScene::pairs`]).
    pub pair: &'static str,
    /// The mesh sizes (one for the α sweep and the profiles).
    pub sizes: Vec<usize>,
    /// Largest size solved from a cold start as well (work–precision, iterations).
    pub cold_max: usize,
    /// The α values (α sweep), or the α of each multiplier profile (stability; `None`
    /// the default, 0 the plain method).
    pub alphas: Vec<Option<f64>>,
}

/// A scene family as the studies see it: how to solve one (pair, mesh, α) of a scene,
/// the family's stability measure and multiplier profile, its mesh ladders and pairs.
pub trait StudyScene {
    /// The scene's name (for titles and output files).
    fn name(&self) -> String;
    /// The problem solved, for titles (`bernoulli-flat q = 100`).
    fn setting(&self) -> String;
    /// What a mesh size counts (`elements`, `N`).
    fn size_name(&self) -> &'static str;
    /// The largest cell diameter of the mesh of `size`.
    fn h(&self, size: usize) -> f64;
    /// `[measure, error]` names of [`Row::contact`] and [`Row::contact_error`].
    fn contact_names(&self) -> [&'static str; 2];
    /// The pairs the convergence study compares.
    fn pairs(&self) -> Vec<&'static str>;
    /// The meshes and settings of a study. `pair` is the pair of a study over every pair
    /// (convergence) or of the stability ladder; a study of one pair (α sweep,
    /// work–precision, iterations) uses the plan's own.
    fn plan(&self, study: Study, pair: &'static str, full: bool) -> Plan;
    /// The pair, mesh and α values of the stability study's multiplier profiles.
    fn profiles(&self, full: bool) -> Plan;
    /// Solves one run.
    fn solve(&self, run: &Run) -> Result<Row>;
    /// `max_T C_I` of `pair` on the mesh of `size` (0 where Δ vanishes on the elements).
    fn inverse_constant(&self, pair: &'static str, size: usize) -> Result<f64>;
    /// The exact measure of the contact set, where known.
    fn exact_contact(&self) -> Option<f64>;
    /// The pairs of the stability study.
    fn stability_pairs(&self) -> Vec<&'static str>;
    /// What the stability study measures.
    fn measure(&self) -> Measure;
    /// The stability measure of `pair` on the mesh of `size`.
    fn stability(&self, pair: &'static str, size: usize) -> Result<StabilityRow>;
    /// `(x, λ_h)` of a run along a line through the contact set, sorted by x.
    fn multiplier_profile(&self, run: &Run) -> Result<Vec<(f64, f64)>>;
    /// The exact multiplier along that line, where known.
    fn exact_multiplier(&self) -> Option<ExactMultiplier>;
    /// The x range of the profile chart.
    fn profile_window(&self) -> [f64; 2];
    /// What [`Row::error_multiplier`] measures, for tables and charts.
    fn multiplier_error_name(&self) -> String {
        "h-weighted ‖λ − λ_h‖".into()
    }
    /// An adaptive solve of `pair` from the mesh of `size` to the relative tolerance
    /// `tolerance` (the adaptivity study).
    ///
    /// # Errors
    /// Scenes without adaptive solves (the default), and the solve's.
    fn adaptive(&self, pair: &'static str, size: usize, tolerance: f64) -> Result<AdaptiveRun> {
        let _ = (pair, size, tolerance);
        Err(Error::Input(format!(
            "scene `{}` has no adaptive solve",
            self.name()
        )))
    }
    /// The adaptivity study (scenes whose pair declares an estimator).
    fn adaptivity(&self, _full: bool, _out: &Path) -> Result<()> {
        Err(Error::Input(format!(
            "scene `{}` has no adaptivity study",
            self.name()
        )))
    }
    /// The locking study (Timoshenko beams only).
    fn locking(&self, _full: bool, _out: &Path) -> Result<()> {
        Err(Error::Input(format!(
            "scene `{}` has no locking study (t → 0 is a Timoshenko study)",
            self.name()
        )))
    }
}

/// Observed rates `log2(e_k / e_{k+1})` of errors on meshes halved each time; NaN
/// (printed `-`) where either error is 0 or not finite, which has no rate (a contact
/// area equal on two meshes printed `inf -inf`).
pub fn rates(errors: &[f64]) -> Vec<f64> {
    errors
        .windows(2)
        .map(|e| {
            if e[0] > 0.0 && e[1] > 0.0 && e[0].is_finite() && e[1].is_finite() {
                (e[0] / e[1]).log2()
            } else {
                f64::NAN
            }
        })
        .collect()
}

pub(crate) fn write_csv(path: &Path, header: &str, rows: &[Vec<f64>]) -> std::io::Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let tmp = path.with_extension("csv.partial");
    {
        let mut file = std::io::BufWriter::new(std::fs::File::create(&tmp)?);
        writeln!(file, "{header}")?;
        for row in rows {
            // counts (mesh sizes, cells, iterations) as integers, measurements in
            // scientific notation with every digit
            let cells: Vec<String> = row
                .iter()
                .map(|v| {
                    if v.fract() == 0.0 && v.abs() < 1e15 {
                        format!("{v:.0}")
                    } else {
                        format!("{v:e}")
                    }
                })
                .collect();
            writeln!(file, "{}", cells.join(","))?;
        }
    }
    // a CSV path that is a directory left the .partial file behind
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        std::io::Error::new(e.kind(), format!("{}: {e}", path.display()))
    })
}

/// [`write_csv`] with a first column `column` of names (a pair, a method): each row's
/// first value is the index of its name in `names` (an index out of range is written as
/// it is), `header` the other columns' names.
pub(crate) fn write_csv_named(
    path: &Path,
    column: &str,
    header: &str,
    names: &[&str],
    rows: &[Vec<f64>],
) -> std::io::Result<()> {
    write_csv(path, &format!("{column},{header}"), rows)?;
    // the numbers are written by `write_csv` alone; here the first cell of each line is
    // swapped for its pair's name
    let text = std::fs::read_to_string(path)?;
    let mut lines = text.lines();
    let mut named = String::with_capacity(text.len());
    if let Some(first) = lines.next() {
        named.push_str(first);
        named.push('\n');
    }
    for line in lines {
        let (index, rest) = line.split_once(',').unwrap_or((line, ""));
        let name = index
            .parse::<usize>()
            .ok()
            .and_then(|i| names.get(i))
            .copied()
            .unwrap_or(index);
        named.push_str(name);
        if !rest.is_empty() {
            named.push(',');
            named.push_str(rest);
        }
        named.push('\n');
    }
    std::fs::write(path, named)
}

pub(crate) fn io(e: std::io::Error) -> Error {
    Error::Input(format!("writing output: {e}"))
}

/// `out/<scene>-<study>.<extension>`.
pub(crate) fn output(out: &Path, scene: &str, study: Study, extension: &str) -> PathBuf {
    out.join(format!("{scene}-{}.{extension}", study.name()))
}

fn nan(v: Option<f64>) -> f64 {
    v.unwrap_or(f64::NAN)
}

/// A table cell: `-` where there is no value.
fn cell(v: f64, width: usize) -> String {
    if v.is_nan() {
        format!("{:>width$}", "-")
    } else {
        format!("{v:>width$.4e}")
    }
}

fn log_axes<'a>(x: &'a str, y: &'a str) -> Axes<'a> {
    Axes {
        x,
        y,
        log_x: true,
        log_y: true,
        rates: false,
    }
}

/// [`log_axes`] against the mesh size, with rate triangles.
fn rate_axes<'a>(x: &'a str, y: &'a str) -> Axes<'a> {
    Axes {
        rates: true,
        ..log_axes(x, y)
    }
}

/// The convergence study: `pair` on each mesh of `sizes`.
pub fn convergence(
    scene: &dyn StudyScene,
    pair: &'static str,
    sizes: &[usize],
) -> Result<Vec<Row>> {
    sizes
        .iter()
        .map(|&n| scene.solve(&Run::new(pair, n)))
        .collect()
}

/// The pairs of a scene that solve on its coarsest convergence mesh (the others are
/// left out of the convergence study).
pub fn available_pairs(scene: &dyn StudyScene) -> Vec<&'static str> {
    scene
        .pairs()
        .into_iter()
        .filter(|&p| {
            let coarsest = scene.plan(Study::Convergence, p, false).sizes[0];
            scene.solve(&Run::new(p, coarsest)).is_ok()
        })
        .collect()
}

fn run_convergence(scene: &dyn StudyScene, full: bool, out: &Path) -> Result<()> {
    let name = scene.name();
    let pairs = available_pairs(scene);
    let solved = pairs
        .iter()
        .map(|&pair| {
            convergence(
                scene,
                pair,
                &scene.plan(Study::Convergence, pair, full).sizes,
            )
        })
        .collect::<Result<Vec<Vec<Row>>>>()?;
    let exact = solved
        .iter()
        .flatten()
        .any(|r| r.error_l2.is_some() || r.error_h1.is_some() || r.error_multiplier.is_some());
    let [contact, contact_error] = scene.contact_names();
    if exact {
        println!(
            "{}: errors against the exact solution (rates between successive meshes)",
            scene.setting()
        );
        print_convergence_header(scene.size_name(), contact_error);
    } else {
        println!(
            "{}: no exact solution field; J_h, ∫λ_h and the {contact} with their changes Δ from the mesh before (rates: log2 of the ratio of successive |Δ|), and the relative error of the family's reference quantity where it has one",
            scene.setting()
        );
        print_changes_header(scene.size_name(), contact);
    }
    let mut csv = Vec::new();
    let mut panels = ConvergencePanels::default();
    for (index, (&pair, rows)) in pairs.iter().zip(&solved).enumerate() {
        let column = |f: fn(&Row) -> Option<f64>| rows.iter().map(|r| nan(f(r))).collect();
        let l2: Vec<f64> = column(|r| r.error_l2);
        let h1: Vec<f64> = column(|r| r.error_h1);
        let lm: Vec<f64> = column(|r| r.error_multiplier);
        let force: Vec<f64> = column(|r| r.force_error);
        let reference: Vec<f64> = column(|r| r.reference_error);
        let changes = Changes::of(rows);
        for (k, r) in rows.iter().enumerate() {
            if exact {
                let (rl2, rh1, rlm) = (rates(&l2), rates(&h1), rates(&lm));
                print_convergence_row(r, k, [&l2, &h1, &lm, &force], [&rl2, &rh1, &rlm]);
            } else {
                print_changes_row(r, k, &changes, reference[k]);
            }
            // the solve's own warnings under its row: rates of −6.8 at
            // 16384 Hermite elements with no note, where the single solve warned
            for warning in &r.warnings {
                println!("    warning ({} {}): {warning}", r.pair, r.size);
            }
            let [energy, total, measure] = changes.values.each_ref().map(|v| v[k]);
            csv.push(vec![
                index as f64,
                r.size as f64,
                r.h,
                r.cells as f64,
                r.dofs as f64,
                l2[k],
                h1[k],
                lm[k],
                force[k],
                nan(r.contact_error),
                energy,
                total,
                measure,
                reference[k],
                r.iterations as f64,
                r.seconds,
            ]);
        }
        panels.add(pair, rows, [&l2, &h1, &lm, &force, &reference], &changes);
    }
    let multiplier = scene.multiplier_error_name();
    let panels = panels.finish(&scene.setting(), (contact, &multiplier), exact);
    plot::stacked(&output(out, &name, Study::Convergence, "svg"), &panels).map_err(io)?;
    write_csv_named(
        &output(out, &name, Study::Convergence, "csv"),
        "pair",
        "size,h,cells,dofs,error_l2,error_h1,error_multiplier,force_error,contact_error,energy,total_contact_force,contact,reference_error,iterations,seconds",
        &pairs,
        &csv,
    )
    .map_err(io)
}

/// The quantities the convergence study follows where there is no exact solution
/// (`J_h`, `∫λ_h` and the family's contact measure) on meshes halved each time: their
/// values, the changes `d_k = Q_{k+1} − Q_k` between successive meshes, and the observed
/// rates `log2(|d_k| / |d_{k+1}|)` (for `Q_h = Q + C hᵖ`, `d_k ∝ h_kᵖ` and the rate is
/// p). Shapes: `values[q]` has one entry per row, `changes[q]` one fewer, `rates[q]` two
/// fewer.
#[derive(Clone, Debug, Default)]
pub struct Changes {
    /// `[J_h, ∫λ_h, contact]` per row.
    pub values: [Vec<f64>; 3],
    /// Their changes to the next mesh.
    pub changes: [Vec<f64>; 3],
    /// The observed rates of the changes.
    pub rates: [Vec<f64>; 3],
}

impl Changes {
    /// The names of the quantities, in order.
    pub const NAMES: [&'static str; 3] = ["J_h", "∫λ_h", "contact"];

    /// The changes of `rows` (one pair on meshes halved each time).
    pub fn of(rows: &[Row]) -> Self {
        let values = [
            rows.iter().map(|r| nan(r.energy)).collect::<Vec<_>>(),
            rows.iter().map(|r| r.total_contact_force).collect(),
            rows.iter().map(|r| r.contact).collect(),
        ];
        let changes = values
            .each_ref()
            .map(|v| v.windows(2).map(|w| w[1] - w[0]).collect::<Vec<_>>());
        let rates = changes
            .each_ref()
            .map(|d| rates(&d.iter().map(|d| d.abs()).collect::<Vec<_>>()));
        Self {
            values,
            changes,
            rates,
        }
    }
}

/// The header of the table of changes (`size`: the scene's word for its mesh size,
/// `contact`: its contact measure).
fn print_changes_header(size: &str, contact: &str) {
    println!(
        "{:<15} {:>8} {:>9} {:>9} {:>16} {:>10} {:>5} {:>14} {:>10} {:>5} {:>12} {:>10} {:>5} {:>11} {:>5} {:>8}",
        "pair", size, "cells", "dofs", "J_h", "ΔJ_h", "rate", "∫λ_h", "Δ∫λ_h", "rate", contact, "Δ", "rate", "ref. error", "iter", "seconds"
    );
}

/// Row `k` of the table of changes, with the relative error of the family's reference
/// quantity `reference` (NaN where there is none).
fn print_changes_row(r: &Row, k: usize, changes: &Changes, reference: f64) {
    let entry = |v: &[f64], shift: usize| {
        k.checked_sub(shift)
            .and_then(|k| v.get(k).copied())
            .unwrap_or(f64::NAN)
    };
    let [j, force, contact] = changes.values.each_ref().map(|v| v[k]);
    let [dj, dforce, dcontact] = changes.changes.each_ref().map(|d| entry(d, 1));
    let [rj, rforce, rcontact] = changes.rates.each_ref().map(|d| entry(d, 2));
    println!(
        "{}",
        crate::dash_nan(format!(
            "{:<15} {:>8} {:>9} {:>9} {j:>16.9e} {dj:>10.2e} {rj:>5.2} {force:>14.7e} {dforce:>10.2e} {rforce:>5.2} {contact:>12.6} {dcontact:>10.2e} {rcontact:>5.2} {reference:>11.2e} {:>5} {:>8.3}",
            r.pair, r.size, r.cells, r.dofs, r.iterations, r.seconds
        ))
    );
}

/// The series of the convergence chart, pair by pair.
#[derive(Default)]
struct ConvergencePanels {
    l2: Vec<Series>,
    h1: Vec<Series>,
    multiplier: Vec<Series>,
    force: Vec<Series>,
    reference: Vec<Series>,
    changes: Vec<Series>,
    work: Vec<Series>,
    /// What each work curve measures (the H¹ error, the reference's, or |ΔJ_h|).
    precision: Vec<&'static str>,
}

impl ConvergencePanels {
    /// The series of `pair`'s `rows` with their errors `[L², H¹, λ, ∫λ, reference]` and
    /// changes; a measure no row has is left out.
    fn add(&mut self, pair: &str, rows: &[Row], errors: [&[f64]; 5], changes: &Changes) {
        let [l2, h1, lm, force, reference] = errors;
        // a graded mesh keeps its largest cell (Hertz's far field) as it refines: its
        // curves are drawn against the smallest cell, which the refinement halves
        let graded = rows.len() > 1 && rows.iter().all(|r| (r.h - rows[0].h).abs() <= 1e-12 * r.h);
        let h_of = |r: &Row| if graded { r.h_min } else { r.h };
        let against_h = |v: &[f64]| -> Vec<(f64, f64)> {
            rows.iter().zip(v).map(|(r, &e)| (h_of(r), e)).collect()
        };
        let graded_words = if graded {
            " (against the smallest cell: graded mesh)"
        } else {
            ""
        };
        let any = |v: &[f64]| v.iter().any(|e| e.is_finite());
        for (target, values, label) in [
            (&mut self.l2, l2, "L²"),
            (&mut self.h1, h1, "H¹"),
            (&mut self.multiplier, lm, "λ"),
            (&mut self.force, force, "∫λ"),
            (&mut self.reference, reference, "reference"),
        ] {
            if any(values) {
                target.push(Series::marked(
                    format!("{pair} {label}{graded_words}"),
                    against_h(values),
                ));
            }
        }
        for (name, d) in Changes::NAMES.iter().zip(&changes.changes) {
            // the change to the next mesh, plotted at the coarser one's h; a log axis
            // has no 0 (a contact measure equal on two meshes)
            let points: Vec<(f64, f64)> = rows
                .iter()
                .zip(d)
                .map(|(r, d)| (h_of(r), d.abs()))
                .filter(|(_, d)| d.is_finite() && *d > 0.0)
                .collect();
            if !points.is_empty() {
                self.changes
                    .push(Series::marked(format!("{pair} |Δ {name}|"), points));
            }
        }
        // precision: the H¹ error where known, else the reference's, else |ΔJ_h|
        let (precision, measure): (Vec<f64>, &'static str) = if any(h1) {
            (h1.to_vec(), "|u − u_h|_H1")
        } else if any(reference) {
            (reference.to_vec(), "|relative error of the reference|")
        } else {
            (
                changes.changes[0].iter().map(|d| d.abs()).collect(),
                "|ΔJ_h| to the next mesh",
            )
        };
        self.precision.push(measure);
        self.work.push(Series::marked(
            format!("{pair} against seconds ({measure})"),
            rows.iter()
                .zip(&precision)
                .map(|(r, &e)| (r.seconds.max(1e-5), e))
                .collect(),
        ));
    }

    /// The panels of the chart (`setting` for titles, `contact` the contact measure's
    /// name, `exact` whether errors against an exact solution were measured).
    fn finish(
        self,
        setting: &str,
        (contact, multiplier): (&str, &str),
        exact: bool,
    ) -> Vec<(String, Axes<'static>, Vec<Series>)> {
        let mut panels = Vec::new();
        let mut panel = |title: String, axes: Axes<'static>, series: Vec<Series>| {
            if !series.is_empty() {
                panels.push((title, axes, series));
            }
        };
        panel(
            format!("{setting}: L² error of u"),
            rate_axes("h", "‖u − u_h‖_L2"),
            self.l2,
        );
        panel(
            format!("{setting}: H¹ error of u"),
            rate_axes("h", "|u − u_h|_H1"),
            self.h1,
        );
        panel(
            format!("{setting}: error of λ, {multiplier}"),
            rate_axes("h", "error of λ"),
            self.multiplier,
        );
        panel(
            format!("{setting}: error of the total contact force"),
            rate_axes("h", "|∫λ_h − ∫λ|"),
            self.force,
        );
        panel(
            format!("{setting}: relative error of the reference quantity"),
            rate_axes("h", "|relative error|"),
            self.reference,
        );
        if !exact {
            panel(
                format!("{setting}: change of J_h, ∫λ_h and the {contact} to the next mesh"),
                rate_axes("h", "|change to the next mesh|"),
                self.changes,
            );
        }
        // the curves' own measure where they share one, else each names its own
        let precision = match self.precision.first() {
            Some(first) if self.precision.iter().all(|p| p == first) => *first,
            _ => "each curve's measure (in its legend)",
        };
        panel(
            format!("{setting}: work against precision (complete nested solve)"),
            log_axes("seconds", precision),
            self.work,
        );
        panels
    }
}

/// The header of the convergence table (`size`: the scene's word for its mesh size,
/// `contact_error`: its contact quantity's column).
fn print_convergence_header(size: &str, contact_error: &str) {
    println!(
        "{:<10} {:>8} {:>9} {:>9} {:>11} {:>6} {:>11} {:>6} {:>11} {:>6} {:>11} {:>11} {:>5} {:>8}",
        "pair",
        size,
        "cells",
        "dofs",
        "L2",
        "rate",
        "H1",
        "rate",
        "λ error",
        "rate",
        "|∫λ_h − ∫λ|",
        contact_error,
        "iter",
        "seconds"
    );
}

/// Row `k` of the convergence table: the errors `[L², H¹, λ, ∫λ]` of every row of its
/// pair and the rates of the first three between successive rows.
fn print_convergence_row(r: &Row, k: usize, errors: [&[f64]; 4], rates: [&[f64]; 3]) {
    let [l2, h1, lm, force] = errors;
    let rate = |errors: &[f64], rates: &[f64]| match k.checked_sub(1) {
        Some(j) if !errors[k].is_nan() => format!("{:.2}", rates[j]),
        _ => "-".to_string(),
    };
    println!(
        "{:<10} {:>8} {:>9} {:>9} {} {:>6} {} {:>6} {} {:>6} {} {} {:>5} {:>8.3}",
        r.pair,
        r.size,
        r.cells,
        r.dofs,
        cell(l2[k], 11),
        rate(l2, rates[0]),
        cell(h1[k], 11),
        rate(h1, rates[1]),
        cell(lm[k], 11),
        rate(lm, rates[2]),
        cell(force[k], 11),
        cell(nan(r.contact_error), 11),
        r.iterations,
        r.seconds
    );
}

/// The stability measure of `pair` on each mesh of `sizes`.
pub fn stability(
    scene: &dyn StudyScene,
    pair: &'static str,
    sizes: &[usize],
) -> Result<Vec<StabilityRow>> {
    sizes.iter().map(|&n| scene.stability(pair, n)).collect()
}

/// The multiplier profile ([`StudyScene::multiplier_profile`]) of `pair` on the mesh of
/// `size` with `alpha` (`None`: the default; `Some(0.0)`: the plain method).
pub fn multiplier_profile(
    scene: &dyn StudyScene,
    pair: &'static str,
    size: usize,
    alpha: Option<f64>,
) -> Result<Vec<(f64, f64)>> {
    scene.multiplier_profile(&Run {
        alpha,
        ..Run::new(pair, size)
    })
}

/// Cells with λ = 0 between the first and the last cell with λ > 0 ("holes") of a
/// profile.
pub fn zero_holes(profile: &[(f64, f64)]) -> usize {
    let largest = profile.iter().map(|p| p.1).fold(0.0, f64::max);
    let on: Vec<bool> = profile.iter().map(|&(_, l)| l > 1e-8 * largest).collect();
    match (on.iter().position(|&b| b), on.iter().rposition(|&b| b)) {
        (Some(first), Some(last)) => on[first..=last].iter().filter(|&&b| !b).count(),
        _ => 0,
    }
}

/// Total variation of a profile's values (an oscillation measure).
pub fn total_variation(profile: &[(f64, f64)]) -> f64 {
    profile.windows(2).map(|w| (w[1].1 - w[0].1).abs()).sum()
}

/// Largest `|λ_h − λ|` over the middle half of the exact contact interval: the
/// oscillation the stabilization damps.
pub fn interior_oscillation(profile: &[(f64, f64)], exact: &ExactMultiplier) -> f64 {
    let [a, b] = exact.contact;
    let (lo, hi) = (a + 0.25 * (b - a), b - 0.25 * (b - a));
    profile
        .iter()
        .filter(|(x, _)| *x >= lo && *x <= hi)
        .map(|&(x, l)| (l - (exact.lambda)(x)).abs())
        .fold(0.0, f64::max)
}

fn variant_label(alpha: Option<f64>) -> String {
    match alpha {
        Some(0.0) => "plain (α = 0)".into(),
        Some(a) if a >= 0.1 => format!("stabilized α = {a}"),
        Some(a) => format!("stabilized α = {a:.0e}"),
        None => "stabilized, default α".into(),
    }
}

fn run_stability(scene: &dyn StudyScene, full: bool, out: &Path) -> Result<()> {
    let name = scene.name();
    let measure = scene.measure();
    println!("{}: {}", scene.setting(), measure.title);
    let mut header = format!("{:<16} {:>8} {:>9}", "pair", scene.size_name(), "α");
    for side in ["plain", "stab."] {
        for label in measure.labels {
            header += &format!(" {:>14}", format!("{side} {label}"));
        }
    }
    println!("{header}");
    let mut csv = Vec::new();
    let mut series = Vec::new();
    for (index, &pair) in scene.stability_pairs().iter().enumerate() {
        let rows = stability(scene, pair, &scene.plan(Study::Stability, pair, full).sizes)?;
        for r in &rows {
            let mut line = format!("{:<16} {:>8} {:>9.2e}", r.pair, r.size, r.alpha);
            for v in r.plain.iter().chain(&r.stabilized) {
                line += &format!(" {v:>14.4e}");
            }
            println!("{line}");
            let mut values = vec![index as f64, r.size as f64, r.alpha];
            values.extend(r.plain.iter().chain(&r.stabilized));
            csv.push(values);
        }
        let h = |r: &StabilityRow| scene.h(r.size);
        for (k, label) in measure.labels.iter().enumerate() {
            series.push(Series::marked(
                format!("{pair} plain {label}"),
                rows.iter()
                    .map(|r| (h(r), (measure.plotted)(r.plain[k])))
                    .collect(),
            ));
        }
        series.push(Series::marked(
            format!("{pair} stabilized {}", measure.labels[0]),
            rows.iter()
                .map(|r| (h(r), (measure.plotted)(r.stabilized[0])))
                .collect(),
        ));
    }
    let profile = scene.profiles(full);
    let (pair, n) = (profile.pair, profile.sizes[0]);
    let mut panels = vec![(
        format!("{name}: {}", measure.title),
        log_axes("h", measure.axis),
        series,
    )];
    // a family without a chart of its multiplier along a line has the measure alone
    if multiplier_profile(scene, pair, n, None).is_ok() {
        panels.push(stability_profiles(scene, &profile)?);
    }
    plot::stacked(&output(out, &name, Study::Stability, "svg"), &panels).map_err(io)?;
    let mut header = "size,alpha".to_string();
    for side in ["plain", "stabilized"] {
        for k in 1..=measure.labels.len() {
            header += &format!(",{side}_{k}");
        }
    }
    write_csv_named(
        &output(out, &name, Study::Stability, "csv"),
        "pair",
        &header,
        &scene.stability_pairs(),
        &csv,
    )
    .map_err(io)
}

/// The stability study's profiles: λ_h along the family's line for each α of the plan
/// (the plain method and the stabilized one), with the holes, total variation and
/// oscillation against the exact λ printed, as a chart panel.
fn stability_profiles(
    scene: &dyn StudyScene,
    profile: &Plan,
) -> Result<(String, Axes<'static>, Vec<Series>)> {
    let name = scene.name();
    let (pair, n) = (profile.pair, profile.sizes[0]);
    let exact = scene.exact_multiplier();
    println!(
        "\n{}, {pair}, {} = {n}: multiplier λ_h along a line through the contact set",
        scene.setting(),
        scene.size_name()
    );
    println!(
        "{:<24} {:>16} {:>16} {:>22}",
        "method", "holes (λ_h = 0)", "total variation", "max |λ_h − λ| inside"
    );
    let [lo, hi] = scene.profile_window();
    let window = |p: &[(f64, f64)]| -> Vec<(f64, f64)> {
        p.iter()
            .copied()
            .filter(|(x, _)| (lo..=hi).contains(x))
            .collect()
    };
    let mut profiles = Vec::new();
    for &alpha in &profile.alphas {
        let p = multiplier_profile(scene, pair, n, alpha)?;
        let label = variant_label(alpha);
        println!(
            "{label:<24} {:>16} {:>16.4e} {:>22}",
            zero_holes(&p),
            total_variation(&window(&p)),
            exact.as_ref().map_or("-".into(), |e| format!(
                "{:.4e}",
                interior_oscillation(&p, e)
            ))
        );
        profiles.push(Series::marked(label, window(&p)));
    }
    if let Some(e) = &exact {
        let samples: Vec<(f64, f64)> = (0..=400)
            .map(|i| {
                let x = lo + (hi - lo) * i as f64 / 400.0;
                (x, (e.lambda)(x))
            })
            .collect();
        println!(
            "{:<24} {:>16} {:>16.4e}",
            "exact",
            "",
            total_variation(&samples)
        );
        profiles.push(Series::line("exact λ", samples));
    }
    Ok((
        format!(
            "{name}, {pair}, {} = {n}: λ_h of the plain (α = 0) and the stabilized method",
            scene.size_name()
        ),
        Axes {
            x: "x",
            y: "λ_h",
            ..Axes::default()
        },
        profiles,
    ))
}

/// One α of the α sweep: the solve's row, or why it failed.
#[derive(Clone, Debug)]
pub struct AlphaRow {
    /// α.
    pub alpha: f64,
    /// The row, or the failure (a result of the study: where the method breaks down).
    pub result: std::result::Result<Row, String>,
}

/// `pair` on the mesh of `size` for every α in `alphas`; also returns the mesh's `C_I`.
pub fn alpha_sweep(
    scene: &dyn StudyScene,
    pair: &'static str,
    size: usize,
    alphas: &[f64],
) -> Result<(Vec<AlphaRow>, f64)> {
    let c_i = scene.inverse_constant(pair, size)?;
    let rows = alphas
        .iter()
        .map(|&alpha| AlphaRow {
            alpha,
            result: scene
                .solve(&Run {
                    alpha: Some(alpha),
                    ..Run::new(pair, size)
                })
                .map_err(|e| e.to_string()),
        })
        .collect();
    Ok((rows, c_i))
}

fn run_alpha(scene: &dyn StudyScene, full: bool, out: &Path) -> Result<()> {
    let name = scene.name();
    let plan = scene.plan(Study::Alpha, scene.pairs()[0], full);
    let (pair, n) = (plan.pair, plan.sizes[0]);
    let alphas: Vec<f64> = plan.alphas.iter().map(|a| a.unwrap_or(0.0)).collect();
    let (rows, c_i) = alpha_sweep(scene, pair, n, &alphas)?;
    let [contact, _] = scene.contact_names();
    println!(
        "{}, {pair}, {} = {n}: errors against α ({})",
        scene.setting(),
        scene.size_name(),
        if c_i > 0.0 {
            format!(
                "C_I = {c_i:.1}, 1/C_I = {:.3e}, default ½/C_I = {:.3e}",
                1.0 / c_i,
                0.5 / c_i
            )
        } else {
            "C_I = 0: every α > 0 is stable, a small one is accurate".into()
        }
    );
    println!(
        "{:>10} {:>7} {:>11} {:>11} {:>11} {:>11} {:>14} {:>10}  note",
        "α", "α·C_I", "L2", "H1", "λ error", "|∫λ_h − ∫λ|", contact, "∫λ_h"
    );
    let mut csv = Vec::new();
    let mut errors = [Vec::new(), Vec::new(), Vec::new(), Vec::new()];
    let mut contacts = Vec::new();
    for row in &rows {
        match &row.result {
            Ok(r) => {
                let values = [r.error_l2, r.error_h1, r.error_multiplier, r.force_error].map(nan);
                let note = r.warnings.join("; ");
                println!(
                    "{:>10.3e} {:>7.3} {} {} {} {} {:>14.6} {:>10.4}  {}{}",
                    row.alpha,
                    row.alpha * c_i,
                    cell(values[0], 11),
                    cell(values[1], 11),
                    cell(values[2], 11),
                    cell(values[3], 11),
                    r.contact,
                    r.total_contact_force,
                    note.chars().take(90).collect::<String>(),
                    if note.chars().count() > 90 { "…" } else { "" }
                );
                let mut line = vec![row.alpha, row.alpha * c_i];
                line.extend(values);
                line.extend([r.contact, r.total_contact_force, 1.0]);
                csv.push(line);
                if row.alpha > 0.0 {
                    for (series, v) in errors.iter_mut().zip(values) {
                        if v.is_finite() {
                            series.push((row.alpha, v));
                        }
                    }
                    contacts.push((row.alpha, r.contact));
                }
            }
            Err(e) => {
                println!(
                    "{:>10.3e} {:>7.3} {:>11} {:>11} {:>11} {:>11} {:>14} {:>10}  failed: {}",
                    row.alpha,
                    row.alpha * c_i,
                    "-",
                    "-",
                    "-",
                    "-",
                    "-",
                    "-",
                    e.chars().take(90).collect::<String>()
                );
                let mut line = vec![row.alpha, row.alpha * c_i];
                line.extend([f64::NAN; 6]);
                line.push(0.0);
                csv.push(line);
            }
        }
    }
    alpha_chart(
        scene,
        (pair, n),
        &rows,
        c_i,
        (&alphas, &errors, contacts),
        out,
    )?;
    alpha_profiles(scene, (pair, n), &rows, c_i, out)?;
    write_csv(
        &output(out, &name, Study::Alpha, "csv"),
        "alpha,alpha_times_CI,error_l2,error_h1,error_multiplier,force_error,contact,total_contact_force,solved",
        &csv,
    )
    .map_err(io)
}

/// Points of a chart's curve.
type Points = Vec<(f64, f64)>;

/// The α study's chart, `<scene>-alpha.svg`: the errors against α with 1/C_I and the
/// default ½/C_I marked and the failed α drawn at the top, and the contact measure
/// against α beside the exact one.
fn alpha_chart(
    scene: &dyn StudyScene,
    (pair, n): (&'static str, usize),
    rows: &[AlphaRow],
    c_i: f64,
    (alphas, errors, contacts): (&[f64], &[Points; 4], Points),
    out: &Path,
) -> Result<()> {
    let name = scene.name();
    let [contact, _] = scene.contact_names();
    let exact_contact = scene.exact_contact();
    if let Some(c) = exact_contact {
        println!("exact {contact} {c:.6}");
    }
    let finite = errors.iter().flatten().map(|p| p.1);
    let (low, high) = finite.fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)));
    // no error measured (no exact solution): the markers span a unit decade, not the
    // sentinels f64::MAX and f64::MIN (a log axis over them never finished its ticks)
    let measured = low <= high;
    let (low, high) = if measured { (low, high) } else { (0.1, 1.0) };
    let marker = |a: f64| vec![(a, low.max(1e-12)), (a, high)];
    let multiplier_error = scene.multiplier_error_name();
    let labels = [
        "‖u − u_h‖_L2",
        "|u − u_h|_H1",
        multiplier_error.as_str(),
        "|∫λ_h − ∫λ|",
    ];
    let mut series: Vec<Series> = labels
        .iter()
        .zip(errors.iter().cloned())
        .filter(|(_, points)| !points.is_empty())
        .map(|(label, points)| Series::marked(*label, points))
        .collect();
    if c_i > 0.0 {
        series.push(Series::line(
            format!("1/C_I = {:.2e}", 1.0 / c_i),
            marker(1.0 / c_i),
        ));
        series.push(Series::line(
            format!("default ½/C_I = {:.2e}", 0.5 / c_i),
            marker(0.5 / c_i),
        ));
    }
    let failed: Vec<(f64, f64)> = rows
        .iter()
        .filter(|r| r.result.is_err() && r.alpha > 0.0)
        .map(|r| (r.alpha, high))
        .collect();
    if !failed.is_empty() {
        series.push(Series::points(
            "failed: no solution (drawn at the top)",
            failed,
        ));
    }
    let (first, last) = (
        alphas
            .iter()
            .copied()
            .filter(|a| *a > 0.0)
            .fold(f64::MAX, f64::min),
        alphas.iter().copied().fold(0.0, f64::max),
    );
    let mut contact_series = vec![Series::marked("computed", contacts.clone())];
    if let Some(c) = exact_contact {
        contact_series.push(Series::line("exact", vec![(first, c), (last, c)]));
    }
    let mut panels = Vec::new();
    if measured {
        panels.push((
            format!(
                "{}, {pair}, {} = {n}: errors against α{}",
                scene.setting(),
                scene.size_name(),
                if c_i > 0.0 {
                    " (breaks down at α ≥ 1/C_I)"
                } else {
                    " (1/C_I = ∞)"
                }
            ),
            log_axes("α", "error"),
            series,
        ));
    } else {
        // no error to chart (no exact solution): 1/C_I and ½/C_I on the contact panel
        println!("no exact solution: the chart shows the {contact} against α only");
        let (lo, hi) = contacts
            .iter()
            .map(|p| p.1)
            .filter(|v| v.is_finite())
            .fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)));
        if c_i > 0.0 && lo <= hi {
            // a measure constant in α still gets markers of a visible length
            let pad = if hi > lo {
                0.0
            } else {
                0.05 * hi.abs().max(1e-300)
            };
            for (label, a) in [("1/C_I", 1.0 / c_i), ("default ½/C_I", 0.5 / c_i)] {
                contact_series.push(Series::line(
                    format!("{label} = {a:.2e}"),
                    vec![(a, lo - pad), (a, hi + pad)],
                ));
            }
        }
    }
    panels.push((
        format!(
            "{}, {pair}, {} = {n}: {contact} against α (an overlarge α shifts the contact set)",
            scene.setting(),
            scene.size_name()
        ),
        Axes {
            x: "α",
            y: contact,
            log_x: true,
            log_y: false,
            rates: false,
        },
        contact_series,
    ));
    plot::stacked(&output(out, &name, Study::Alpha, "svg"), &panels).map_err(io)?;
    Ok(())
}

/// The α study's second chart, `<scene>-alpha-profiles.svg`, where the family draws
/// the multiplier along a line: λ_h of the plain method, of the default α and of the
/// largest α of the sweep that solved, beside the exact λ where known (oscillation
/// without stabilization, a shifted contact set with too much). Nothing where the
/// family has no profile.
fn alpha_profiles(
    scene: &dyn StudyScene,
    (pair, n): (&'static str, usize),
    rows: &[AlphaRow],
    c_i: f64,
    out: &Path,
) -> Result<()> {
    let Ok(default) = multiplier_profile(scene, pair, n, None) else {
        return Ok(());
    };
    let mut series = vec![Series::marked("default α", default)];
    if let Ok(plain) = multiplier_profile(scene, pair, n, Some(0.0)) {
        series.push(Series::marked("plain, α = 0", plain));
    }
    let largest = rows
        .iter()
        .filter(|r| r.result.is_ok() && r.alpha > 0.0)
        .map(|r| r.alpha)
        .fold(0.0, f64::max);
    if largest > 0.0 {
        if let Ok(p) = multiplier_profile(scene, pair, n, Some(largest)) {
            let label = if c_i > 0.0 {
                format!("largest that solved, α·C_I = {:.3}", largest * c_i)
            } else {
                format!("largest that solved, α = {largest:.3e}")
            };
            series.push(Series::marked(label, p));
        }
    }
    let xs = series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.0))
        .fold((f64::MAX, f64::MIN), |(a, b), x| (a.min(x), b.max(x)));
    if let (Some(e), true) = (scene.exact_multiplier(), xs.0 < xs.1) {
        let samples = (0..=400)
            .map(|i| {
                let x = xs.0 + (xs.1 - xs.0) * i as f64 / 400.0;
                (x, (e.lambda)(x))
            })
            .collect();
        series.push(Series::line("exact λ", samples));
    }
    let name = scene.name();
    let path = out.join(format!("{name}-alpha-profiles.svg"));
    plot::chart(
        &path,
        &format!(
            "{name}, {pair}, {} = {n}: λ_h for α = 0, the default and the largest",
            scene.size_name()
        ),
        Axes {
            x: "x",
            y: "λ_h",
            ..Axes::default()
        },
        &series,
    )
    .map_err(io)?;
    println!("→ {}", path.display());
    Ok(())
}

/// The solvers of the work–precision study: name, solver, nested iteration.
pub const METHODS: [(&str, VariationalSolver, bool); 3] = [
    ("pdas nested", VariationalSolver::SemismoothNewton, true),
    ("pdas cold", VariationalSolver::SemismoothNewton, false),
    ("clarabel", VariationalSolver::Clarabel, false),
];

/// One solve of the work–precision study.
#[derive(Clone, Debug)]
pub struct WorkRow {
    /// Index into [`METHODS`].
    pub method: usize,
    /// Mesh size.
    pub size: usize,
    /// The row, or why the solve failed.
    pub result: std::result::Result<Row, String>,
}

/// `pair` with each of [`METHODS`] on each mesh (cold starts up to `cold_max`).
pub fn work_precision(
    scene: &dyn StudyScene,
    pair: &'static str,
    sizes: &[usize],
    cold_max: usize,
) -> Vec<WorkRow> {
    let mut rows = Vec::new();
    for &n in sizes {
        for (method, &(_, solver, nested)) in METHODS.iter().enumerate() {
            if !nested && solver == VariationalSolver::SemismoothNewton && n > cold_max {
                continue;
            }
            let run = Run {
                solver,
                nested,
                ..Run::new(pair, n)
            };
            rows.push(WorkRow {
                method,
                size: n,
                result: scene.solve(&run).map_err(|e| e.to_string()),
            });
        }
    }
    rows
}

fn run_work_precision(scene: &dyn StudyScene, full: bool, out: &Path) -> Result<()> {
    let name = scene.name();
    let plan = scene.plan(Study::WorkPrecision, scene.pairs()[0], full);
    let rows = work_precision(scene, plan.pair, &plan.sizes, plan.cold_max);
    let measured = rows.iter().any(|w| {
        w.result
            .as_ref()
            .is_ok_and(|r| nan(r.error_l2).is_finite() || nan(r.error_h1).is_finite())
    });
    if !measured {
        // without an exact solution at this load there is no error to chart
        println!(
            "{}: no exact solution at this load, so no error against solve time (the model choice's chart measures by the estimate)",
            scene.setting()
        );
        return Ok(());
    }
    println!(
        "{}, {}: error against solve time",
        scene.setting(),
        plan.pair
    );
    println!(
        "{:<12} {:>8} {:>10} {:>12} {:>12} {:>6}",
        "method",
        scene.size_name(),
        "seconds",
        "L2 error",
        "H1 error",
        "iter"
    );
    let mut csv = Vec::new();
    for w in &rows {
        let method = METHODS[w.method].0;
        match &w.result {
            Ok(r) => {
                println!(
                    "{:<12} {:>8} {:>10.4} {:>12.4e} {:>12.4e} {:>6}",
                    method,
                    w.size,
                    r.seconds,
                    nan(r.error_l2),
                    nan(r.error_h1),
                    r.iterations
                );
                csv.push(vec![
                    w.method as f64,
                    w.size as f64,
                    r.seconds,
                    nan(r.error_l2),
                    nan(r.error_h1),
                    r.iterations as f64,
                ]);
            }
            Err(e) => {
                println!("{method:<12} {:>8}  failed: {e}", w.size);
                csv.push(vec![
                    w.method as f64,
                    w.size as f64,
                    f64::NAN,
                    f64::NAN,
                    f64::NAN,
                    0.0,
                ]);
            }
        }
    }
    let series: Vec<Series> = METHODS
        .iter()
        .enumerate()
        .map(|(m, (method, _, _))| {
            Series::marked(
                *method,
                rows.iter()
                    .filter(|w| w.method == m)
                    .filter_map(|w| w.result.as_ref().ok())
                    .map(|r| (r.seconds, nan(r.error_l2)))
                    .collect(),
            )
        })
        .collect();
    plot::chart(
        &output(out, &name, Study::WorkPrecision, "svg"),
        &format!(
            "{}, {}: L2 error against solve time",
            scene.setting(),
            plan.pair
        ),
        log_axes("seconds", "‖u − u_h‖_L2"),
        &series,
    )
    .map_err(io)?;
    write_csv_named(
        &output(out, &name, Study::WorkPrecision, "csv"),
        "method",
        "size,seconds,error_l2,error_h1,iterations",
        &METHODS.map(|(method, _, _)| method),
        &csv,
    )
    .map_err(io)
}

/// `(size, nested final-level iterations, cold-start iterations)`; `None` where not run
/// or failed (a failure is a result of the study: where the method breaks down).
pub type IterationRow = (usize, Option<usize>, Option<usize>);

/// Newton iterations of `pair` on each mesh, nested and (up to `cold_max`) cold.
pub fn iteration_counts(
    scene: &dyn StudyScene,
    pair: &'static str,
    sizes: &[usize],
    cold_max: usize,
) -> Vec<IterationRow> {
    sizes
        .iter()
        .map(|&n| {
            let iterations = |nested: bool| {
                scene
                    .solve(&Run {
                        nested,
                        ..Run::new(pair, n)
                    })
                    .ok()
                    .map(|r| r.iterations)
            };
            let nested = iterations(true);
            let cold = (n <= cold_max).then(|| iterations(false)).flatten();
            (n, nested, cold)
        })
        .collect()
}

fn run_iterations(scene: &dyn StudyScene, full: bool, out: &Path) -> Result<()> {
    let name = scene.name();
    let plan = scene.plan(Study::Iterations, scene.pairs()[0], full);
    println!(
        "{}, {}: semismooth Newton iterations on the final mesh, nested iteration (cold start beside; '-': failed or not run)",
        scene.setting(),
        plan.pair
    );
    println!(
        "{:<16} {:>8} {:>8} {:>6}",
        "scene",
        scene.size_name(),
        "nested",
        "cold"
    );
    let rows = iteration_counts(scene, plan.pair, &plan.sizes, plan.cold_max);
    let show = |v: Option<usize>| v.map_or("-".to_string(), |c| c.to_string());
    let count = |v: Option<usize>| v.map_or(f64::NAN, |c| c as f64);
    for &(n, nested, cold) in &rows {
        println!("{name:<16} {n:>8} {:>8} {:>6}", show(nested), show(cold));
    }
    let points = |pick: fn(&IterationRow) -> Option<usize>| -> Vec<(f64, f64)> {
        rows.iter()
            .filter_map(|r| pick(r).map(|c| (r.0 as f64, c.max(1) as f64)))
            .collect()
    };
    plot::chart(
        &output(out, &name, Study::Iterations, "svg"),
        &format!(
            "{}, {}: Newton iterations on the final mesh",
            scene.setting(),
            plan.pair
        ),
        log_axes(scene.size_name(), "iterations"),
        &[
            Series::marked("nested", points(|r| r.1)),
            Series::marked("cold start", points(|r| r.2)),
        ],
    )
    .map_err(io)?;
    write_csv(
        &output(out, &name, Study::Iterations, "csv"),
        "size,nested,cold",
        &rows
            .iter()
            .map(|&(n, nested, cold)| vec![n as f64, count(nested), count(cold)])
            .collect::<Vec<_>>(),
    )
    .map_err(io)
}

/// Runs `study` on `scene`, prints its table, writes `out/<scene>-<study>.svg` and `.csv`.
pub fn run(scene: &dyn StudyScene, study: Study, full: bool, out: &Path) -> Result<()> {
    match study {
        Study::Convergence => run_convergence(scene, full, out),
        Study::Locking => scene.locking(full, out),
        Study::Stability => run_stability(scene, full, out),
        Study::Alpha => run_alpha(scene, full, out),
        Study::WorkPrecision => run_work_precision(scene, full, out),
        Study::Iterations => run_iterations(scene, full, out),
        Study::Adaptivity => scene.adaptivity(full, out),
    }?;
    println!(
        "→ {}, .csv\n",
        output(out, &scene.name(), study, "svg").display()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    /// The changes between meshes and their rates: `Q_h = 1 + h²` on h = ¼, ⅛, 1/16
    /// changes by −3/64 and −3/256, a ratio of 4: rate 2.
    #[test]
    fn changes_between_meshes_give_the_rate_of_the_quantity() {
        let row = |h: f64| super::Row {
            pair: "p",
            size: 1,
            h,
            h_min: h,
            cells: 1,
            dofs: 1,
            alpha: 0.0,
            error_l2: None,
            error_h1: None,
            error_multiplier: None,
            energy: Some(1.0 + h * h),
            reference_error: None,
            total_contact_force: 2.0 - h * h * h,
            force_error: None,
            contact: 0.5,
            contact_error: None,
            iterations: 1,
            seconds: 0.0,
            estimate: None,
            estimate_relative: None,
            error_energy: None,
            kkt_residual: 0.0,
            warnings: Vec::new(),
        };
        let rows: Vec<_> = [0.25, 0.125, 0.0625].map(row).to_vec();
        let c = super::Changes::of(&rows);
        assert_eq!(c.changes[0], [-3.0 / 64.0, -3.0 / 256.0]);
        assert_eq!(c.rates[0], [2.0]);
        assert!((c.rates[1][0] - 3.0).abs() < 1e-12, "{:?}", c.rates);
        // an unchanged contact measure has no rate
        assert_eq!(c.changes[2], [0.0, 0.0]);
        assert!(c.rates[2][0].is_nan());
    }

    /// A zero or infinite error has no rate: NaN (printed `-`), not `inf` or `-inf` (
    /// contact area equal on two meshes); the others are log₂ of the ratio.
    #[test]
    fn rates_of_zero_differences_are_not_a_number() {
        let r = super::rates(&[4.0, 1.0, 0.0, 2.0, f64::INFINITY, 1.0]);
        assert_eq!(r[0], 2.0);
        assert!(
            r[1].is_nan() && r[2].is_nan() && r[3].is_nan() && r[4].is_nan(),
            "{r:?}"
        );
    }

    /// The name column of `write_csv_named`: indices become names, one out of range
    /// stays a number.
    #[test]
    fn named_csv_rows_start_with_their_names() {
        let path = std::env::temp_dir().join(format!("fem-forms-named-{}.csv", std::process::id()));
        let rows = vec![vec![1.0, 8.0], vec![0.0, 16.0], vec![5.0, 32.0]];
        super::write_csv_named(&path, "pair", "size", &["p1-p0", "p2-p0"], &rows).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(text, "pair,size\np2-p0,8\np1-p0,16\n5,32\n");
        std::fs::remove_file(&path).unwrap();
    }

    /// Counts come out as integers (`8e0` appeared for a mesh size), measurements
    /// with every digit, missing values as `NaN`, and each reads back exactly.
    #[test]
    fn csv_cells_are_integers_or_full_precision() {
        let path = std::env::temp_dir().join(format!("fem-forms-csv-{}.csv", std::process::id()));
        let row = vec![8.0, 1635.0, 0.1 + 0.2, 1e-300, f64::NAN, -3.0];
        super::write_csv(&path, "a,b,c,d,e,f", std::slice::from_ref(&row)).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let line = text.lines().nth(1).unwrap();
        assert!(line.starts_with("8,1635,"), "{line}");
        assert!(line.ends_with(",NaN,-3"), "{line}");
        for (cell, value) in line.split(',').zip(&row) {
            let back: f64 = cell.parse().unwrap();
            assert!(
                back == *value || (back.is_nan() && value.is_nan()),
                "{cell}"
            );
        }
        std::fs::remove_file(&path).unwrap();
    }
}
