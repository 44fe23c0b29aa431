//! `fem-forms report`: every study of every family, run now, on one self-contained web
//! page (`DIR/index.html`: charts inline as SVG, no network, opens from disk).
//!
//! The page is built from the registry and the one implementation of each study
//! ([`crate::registry_studies::run_hosted`]): for each family, the studies its scenes
//! host ([`crate::models::scene::Scene::studies`]), so a new family's studies appear on
//! it without code here; the accuracy of each scene against its reference, from the
//! solve's own report ([`comparisons`]); and the machine, the date, the commit and the
//! time each study took. Each study writes its charts, their data (`.chart.csv`) and its
//! CSV into `DIR/studies/<scene>-<study>/`, and what it printed into `log.txt` there.

use crate::models::families;
use crate::models::membrane_scenes::PETSC_EX9_ERRORS;
use crate::models::report::{Report, Settings};
use crate::models::scene::Scene;
use crate::plot::escape;
use crate::studies::Study;
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What `fem-forms report` is asked.
#[derive(Clone, Debug)]
pub struct Options {
    /// The studies' larger meshes (`--full`).
    pub full: bool,
    /// The directory the page and its files go to.
    pub out: PathBuf,
    /// Only the studies of these scenes (empty: every scene that hosts one); the
    /// accuracy tables then cover these scenes' families only.
    pub scenes: Vec<String>,
    /// PETSc's SNES tutorial ex9, built, to run beside the nodal method on the radial
    /// membrane (`None`: its published errors only).
    pub petsc_ex9: Option<PathBuf>,
}

/// One study of one scene.
#[derive(Clone)]
pub struct Job {
    /// The scene.
    pub scene: Scene,
    /// The study's name (a [`Study`] or the λ-scatter).
    pub kind: &'static str,
}

impl Job {
    /// The directory of its files, relative to the page: `studies/<scene>-<study>`.
    pub fn dir(&self) -> String {
        format!("studies/{}-{}", self.scene.name, self.kind)
    }
}

/// Every study each scene hosts, by family in the registry's order, of `only` (every
/// scene hosting a study where empty).
pub fn jobs(only: &[String]) -> Vec<Job> {
    let scenes = families::scenes();
    let mut jobs = Vec::new();
    for family in families::families() {
        for scene in scenes.iter().filter(|s| s.family == family.name()) {
            if !only.is_empty() && !only.iter().any(|n| *n == *scene.name) {
                continue;
            }
            for &kind in &scene.studies {
                jobs.push(Job {
                    scene: scene.clone(),
                    kind,
                });
            }
        }
    }
    jobs
}

/// What one study left on disk.
struct Done {
    job: Job,
    seconds: f64,
    /// What it printed.
    log: String,
    /// Its charts, relative to the page.
    charts: Vec<String>,
    /// Its CSV tables (not the charts' data), relative to the page.
    tables: Vec<String>,
    error: Option<String>,
}

/// A computed quantity beside its reference.
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    /// The scene.
    pub scene: String,
    /// The pair and mesh solved (`p2-p0, N = 16`).
    pub solved: String,
    /// What is compared.
    pub quantity: String,
    /// The computed value.
    pub computed: f64,
    /// The reference value (`None` for an error norm, whose reference is 0).
    pub reference: Option<f64>,
    /// Where the reference comes from.
    pub source: String,
}

impl Comparison {
    /// `|computed − reference| / |reference|` (`None` without a non-zero reference).
    pub fn relative(&self) -> Option<f64> {
        self.reference
            .filter(|r| *r != 0.0)
            .map(|r| (self.computed - r).abs() / r.abs())
    }
}

const EXACT: &str = "the scene's exact solution (docs/mathematics.md)";

/// The comparisons a solve's report holds: every quantity it reports beside a
/// reference value (a plate's centre deflection and the series', Hertz's half-width and
/// peak pressure, `∫λ_h` and the contact area against the exact solution's) and the
/// errors against an exact solution.
pub fn comparisons(report: &Report) -> Vec<Comparison> {
    let source = report
        .quantities
        .get("reference_source")
        .and_then(|v| v.as_str())
        .unwrap_or("the family's reference")
        .to_string();
    let solved = format!("{}, N = {}", report.pair, report.mesh_size);
    let row = |quantity: &str, computed: f64, reference: Option<f64>, source: &str| Comparison {
        scene: report.scene.clone(),
        solved: solved.clone(),
        quantity: quantity.into(),
        computed,
        reference,
        source: source.into(),
    };
    let mut rows = Vec::new();
    let pairs = [
        (
            "centre deflection",
            "centre_deflection",
            "reference_centre_deflection",
        ),
        (
            "contact half-width",
            "contact_half_width",
            "exact_half_width",
        ),
        (
            "peak pressure",
            "max_contact_pressure",
            "exact_max_pressure",
        ),
    ];
    for (quantity, key, reference) in pairs {
        if let (Some(c), Some(r)) = (report.number(key), report.number(reference)) {
            rows.push(row(quantity, c, Some(r), &source));
        }
    }
    if let Some(exact) = report.exact_contact_force {
        let computed = report
            .number("total_contact_force")
            .unwrap_or(report.solve.total_contact_force);
        rows.push(row("contact force ∫λ_h", computed, Some(exact), EXACT));
    }
    if let (Some(area), Some(exact)) = (report.solve.contact_area, report.exact_contact_area) {
        rows.push(row("contact area", area, Some(exact), EXACT));
    }
    if let Some(e) = report.solve.error_l2 {
        rows.push(row("L² error of the constrained field", e, None, EXACT));
    }
    if let Some(e) = report.solve.error_h1 {
        rows.push(row("H¹ error of the constrained field", e, None, EXACT));
    }
    if let Some(e) = report.number("patch_pressure_error") {
        rows.push(row(
            "largest relative error of λ_h against λ = q",
            e,
            None,
            EXACT,
        ));
    }
    if let Some(e) = report.number("pressure_l2_error") {
        rows.push(row("relative L² error of the pressure", e, None, &source));
    }
    rows
}

/// The radial membrane (`scene`) by the nodal method on the N×N mesh: the grid of ex9.
fn nodal_radial(scene: &Scene, n: usize) -> Result<Report, String> {
    let settings = Settings {
        pair: Some("p1-nodal".into()),
        mesh_size: Some(n),
        ..Settings::default()
    };
    families::solve(scene, &settings)
        .map(|outcome| outcome.report)
        .map_err(|e| format!("membrane-radial p1-nodal N = {n}: {e}"))
}

/// The radial membrane's nodal method against PETSc's ex9 on the same grids
/// ([`PETSC_EX9_ERRORS`]): both errors on each grid.
fn petsc_ex9() -> Result<Vec<Comparison>, String> {
    let scene = families::scene("membrane-radial").ok_or("the registry has no membrane-radial")?;
    let mut rows = Vec::new();
    for (n, mean, max) in PETSC_EX9_ERRORS {
        let report = nodal_radial(&scene, n)?;
        let source = format!(
            "PETSc 3.18 SNES tutorial ex9 (Bueler, p4pdes), {}² grid, as printed",
            n + 1
        );
        for (quantity, computed, reference) in [
            (
                "mean |u − u_h| at the vertices",
                report.solve.error_vertex_mean,
                mean,
            ),
            (
                "max |u − u_h| at the vertices",
                report.solve.error_vertex_max,
                max,
            ),
        ] {
            rows.push(Comparison {
                scene: "membrane-radial".into(),
                solved: format!("p1-nodal, N = {n}"),
                quantity: quantity.into(),
                computed: computed.unwrap_or(f64::NAN),
                reference: Some(reference),
                source: source.clone(),
            });
        }
    }
    Ok(rows)
}

/// The grids PETSc's ex9 is run on beside the nodal method: N + 1 points a side, from
/// grid sequencing `-snes_grid_sequence K` on its 5×5 start (N = 2^(K+2)).
const EX9_SIZES: [usize; 5] = [16, 32, 64, 128, 256];

/// One solve of ex9: the grid's N, the errors it printed (mean, max at the grid's
/// points) and its `SNESSolve` time from `-log_view` (every level of the sequence).
#[derive(Clone, Debug, PartialEq)]
pub struct Ex9Run {
    /// N of the (N + 1)² grid.
    pub size: usize,
    /// `av |u-uexact|`.
    pub mean: f64,
    /// `|u-uexact|_inf`.
    pub max: f64,
    /// Seconds in SNESSolve.
    pub seconds: f64,
}

/// Reads what ex9 printed with `-snes_converged_reason -log_view`: its error line and
/// the SNESSolve event's time. A diverged solve is an error naming its reason (ex9
/// itself exits 0 on DIVERGED_MAX_IT).
///
/// # Errors
/// A divergence, or output without the error line or the SNESSolve event.
pub fn parse_ex9(size: usize, output: &str) -> Result<Ex9Run, String> {
    if let Some(line) = output.lines().find(|l| l.contains("DIVERGED")) {
        return Err(format!("ex9 on the {}² grid: {}", size + 1, line.trim()));
    }
    let number_after = |line: &str, key: &str| -> Option<f64> {
        let rest = &line[line.find(key)? + key.len()..];
        let rest = rest.trim_start().strip_prefix('=')?.trim_start();
        rest.split([',', ' ']).next()?.parse().ok()
    };
    let errors = output
        .lines()
        .find(|l| l.starts_with("errors on"))
        .ok_or_else(|| format!("ex9 on the {}² grid printed no `errors on` line", size + 1))?;
    let (mean, max) = number_after(errors, "av |u-uexact|")
        .zip(number_after(errors, "|u-uexact|_inf"))
        .ok_or_else(|| format!("ex9's error line is not as expected: {errors}"))?;
    let seconds = output
        .lines()
        .find(|l| l.starts_with("SNESSolve "))
        .and_then(|l| l.split_whitespace().nth(3)?.parse().ok())
        .ok_or_else(|| {
            format!(
                "ex9 on the {}² grid printed no SNESSolve time (-log_view)",
                size + 1
            )
        })?;
    Ok(Ex9Run {
        size,
        mean,
        max,
        seconds,
    })
}

/// Runs ex9 (`vinewtonrsls`, grid sequencing, PCMG: the run whose printed errors
/// [`PETSC_EX9_ERRORS`] records) on the grid of N.
fn run_ex9(ex9: &Path, size: usize) -> Result<Ex9Run, String> {
    let sequence = size.trailing_zeros().saturating_sub(2);
    let output = std::process::Command::new(ex9)
        .args([
            "-snes_type",
            "vinewtonrsls",
            "-snes_grid_sequence",
            &sequence.to_string(),
            "-pc_type",
            "mg",
            "-snes_converged_reason",
            "-log_view",
        ])
        // Open MPI's singleton refuses root without these
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .output()
        .map_err(|e| format!("{}: {e}", ex9.display()))?;
    let text = String::from_utf8_lossy(&output.stdout);
    if !output.status.success() {
        return Err(format!(
            "{} exited with {}: {}",
            ex9.display(),
            output.status,
            String::from_utf8_lossy(&output.stderr).trim()
        ));
    }
    parse_ex9(size, &text)
}

/// PETSc's ex9 beside the nodal method on the radial membrane, both run now on the same
/// grids: the mean error at the grid points against solve time, as a chart and a table
/// (`studies/membrane-radial-petsc-ex9/`). Returns the page's HTML.
fn ex9_beside(ex9: &Path, out: &Path) -> Result<String, String> {
    let scene = families::scene("membrane-radial").ok_or("the registry has no membrane-radial")?;
    let dir = out.join("studies/membrane-radial-petsc-ex9");
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let mut ours = Vec::new();
    let mut theirs = Vec::new();
    let mut table = String::from("<table class=\"ex9\"><tr><th>grid</th><th>p1-nodal mean error</th><th>ex9 mean error</th><th>p1-nodal max error</th><th>ex9 max error</th><th>p1-nodal seconds</th><th>ex9 seconds (SNESSolve)</th></tr>\n");
    let mut csv =
        String::from("n,nodal_mean,ex9_mean,nodal_max,ex9_max,nodal_seconds,ex9_seconds\n");
    for size in EX9_SIZES {
        let report = nodal_radial(&scene, size)?;
        let (mean, max) = (
            report.solve.error_vertex_mean.unwrap_or(f64::NAN),
            report.solve.error_vertex_max.unwrap_or(f64::NAN),
        );
        let run = run_ex9(ex9, size)?;
        ours.push((report.solve.seconds, mean));
        theirs.push((run.seconds, run.mean));
        let _ = writeln!(
            table,
            "<tr><td>{0}²</td><td class=\"n\">{1:.3e}</td><td class=\"n\">{2:.3e}</td><td class=\"n\">{3:.3e}</td><td class=\"n\">{4:.3e}</td><td class=\"n\">{5:.4}</td><td class=\"n\">{6:.4}</td></tr>",
            size + 1,
            mean,
            run.mean,
            max,
            run.max,
            report.solve.seconds,
            run.seconds
        );
        let _ = writeln!(
            csv,
            "{size},{mean:e},{:e},{max:e},{:e},{:e},{:e}",
            run.mean, run.max, report.solve.seconds, run.seconds
        );
    }
    table.push_str("</table>\n");
    let chart = dir.join("membrane-radial-petsc-ex9.svg");
    crate::plot::chart(
        &chart,
        "membrane-radial: the nodal method and PETSc's ex9 on the same grids",
        crate::plot::Axes {
            x: "solve time (s)",
            y: "mean |u − u_h| at the grid points",
            log_x: true,
            log_y: true,
            rates: false,
        },
        &[
            crate::plot::Series::marked("p1-nodal (fem-forms, nested semismooth Newton)", ours),
            crate::plot::Series::marked("PETSc ex9 (vinewtonrsls, grid sequencing, PCMG)", theirs),
        ],
    )
    .map_err(|e| format!("{}: {e}", chart.display()))?;
    let table_path = dir.join("membrane-radial-petsc-ex9.csv");
    std::fs::write(&table_path, csv).map_err(|e| format!("{}: {e}", table_path.display()))?;
    let svg = inline_chart(
        out,
        "studies/membrane-radial-petsc-ex9/membrane-radial-petsc-ex9.svg",
    )?;
    Ok(format!(
        "<h3 id=\"membrane-radial-petsc-ex9\">membrane-radial: PETSc's ex9 beside the nodal method</h3>\n<p class=\"checks\">An independent solver run now: PETSc's SNES tutorial ex9 ({}), the same 5-point discrete problem as the p1-nodal pair on the right-diagonal mesh, so the errors must agree to the digits printed; the times are fem-forms' whole nested solve against ex9's SNESSolve over every level of its grid sequence.</p>\n{table}<figure id=\"chart-ex9\" data-csv=\"studies/membrane-radial-petsc-ex9/membrane-radial-petsc-ex9.chart.csv\">\n{svg}\n<figcaption>studies/membrane-radial-petsc-ex9/membrane-radial-petsc-ex9.svg · table: <a href=\"studies/membrane-radial-petsc-ex9/membrane-radial-petsc-ex9.csv\">membrane-radial-petsc-ex9.csv</a></figcaption>\n</figure>\n",
        escape(&ex9.display().to_string())
    ))
}

/// The stdout of this process sent to a file while a study runs: the studies print their
/// tables, which the page keeps (and which would tear the progress bar).
struct StdoutTo {
    saved: libc::c_int,
}

impl StdoutTo {
    fn file(path: &Path) -> std::io::Result<Self> {
        use std::os::fd::AsRawFd;
        let file = std::fs::File::create(path)?;
        std::io::stdout().flush()?;
        // SAFETY: dup and dup2 on this process's own descriptors; `saved` is restored
        // and closed on drop
        let saved = unsafe { libc::dup(1) };
        if saved < 0 || unsafe { libc::dup2(file.as_raw_fd(), 1) } < 0 {
            return Err(std::io::Error::last_os_error());
        }
        Ok(Self { saved })
    }
}

impl Drop for StdoutTo {
    fn drop(&mut self) {
        let _ = std::io::stdout().flush();
        // SAFETY: restores the descriptor saved in `file`
        unsafe {
            libc::dup2(self.saved, 1);
            libc::close(self.saved);
        }
    }
}

/// Runs one study into its directory.
fn run_job(job: &Job, full: bool, out: &Path) -> Done {
    let dir = out.join(job.dir());
    let _ = std::fs::remove_dir_all(&dir);
    let mut done = Done {
        job: job.clone(),
        seconds: 0.0,
        log: String::new(),
        charts: Vec::new(),
        tables: Vec::new(),
        error: None,
    };
    if let Err(e) = std::fs::create_dir_all(&dir) {
        done.error = Some(format!("{}: {e}", dir.display()));
        return done;
    }
    let log = dir.join("log.txt");
    let start = Instant::now();
    let result = match StdoutTo::file(&log) {
        Ok(_redirect) => {
            crate::registry_studies::run_hosted(job.scene.clone(), Some(job.kind), full, &dir)
        }
        Err(e) => Err(format!("{}: {e}", log.display())),
    };
    done.seconds = start.elapsed().as_secs_f64();
    done.log = std::fs::read_to_string(&log).unwrap_or_default();
    done.error = result.err();
    let mut files: Vec<String> = std::fs::read_dir(&dir)
        .map(|entries| {
            entries
                .flatten()
                .filter_map(|e| e.file_name().into_string().ok())
                .collect()
        })
        .unwrap_or_default();
    files.sort();
    for name in files {
        let relative = format!("{}/{name}", job.dir());
        if name.ends_with(".svg") {
            done.charts.push(relative);
        } else if name.ends_with(".csv") && !name.ends_with(".chart.csv") {
            done.tables.push(relative);
        }
    }
    done
}

/// The run's facts for the page's head: machine, date, commit.
fn run_facts() -> Vec<(&'static str, String)> {
    let read = |path: &str| std::fs::read_to_string(path).unwrap_or_default();
    let cpuinfo = read("/proc/cpuinfo");
    let cpu = cpuinfo
        .lines()
        .find(|l| l.starts_with("model name"))
        .and_then(|l| l.split_once(':'))
        .map_or("unknown".into(), |(_, v)| v.trim().to_string());
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    let memory = read("/proc/meminfo")
        .lines()
        .find(|l| l.starts_with("MemTotal"))
        .and_then(|l| {
            l.split_whitespace()
                .nth(1)
                .and_then(|k| k.parse::<f64>().ok())
        })
        .map_or("unknown".into(), |kb| {
            format!("{:.1} GiB", kb / 1024.0 / 1024.0)
        });
    let host = read("/etc/hostname").trim().to_string();
    // recorded at build time (build.rs): the checkout this program was built from
    let commit = env!("FEM_FORMS_COMMIT").to_string();
    vec![
        ("date", utc_now()),
        ("commit", commit),
        ("machine", format!("{host}: {cpu}, {cores} cores, {memory}")),
        (
            "program",
            format!(
                "fem-forms {} ({} build)",
                env!("CARGO_PKG_VERSION"),
                if cfg!(debug_assertions) {
                    "debug"
                } else {
                    "release"
                }
            ),
        ),
    ]
}

/// The time now as `2026-12-04 15:30:00 UTC` (the civil date from the days since the
/// epoch: H. Hinnant's algorithm).
fn utc_now() -> String {
    let seconds = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs()) as i64;
    let (days, rest) = (seconds.div_euclid(86400), seconds.rem_euclid(86400));
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02} {:02}:{:02}:{:02} UTC",
        rest / 3600,
        rest % 3600 / 60,
        rest % 60
    )
}

/// A number for a table: four significant digits.
fn figure(v: f64) -> String {
    if v.is_nan() {
        "–".into()
    } else if v == 0.0 {
        "0".into()
    } else if (1e-3..1e5).contains(&v.abs()) {
        let decimals = (3 - v.abs().log10().floor() as i32).max(0) as usize;
        format!("{v:.decimals$}")
    } else {
        format!("{v:.3e}")
    }
}

/// What the study `kind` checks, for the page.
fn checks(kind: &str) -> &'static str {
    match Study::parse(kind) {
        Some(study) => study.checks(),
        None if kind == crate::lambda_scatter::NAME => crate::lambda_scatter::CHECKS,
        None => "",
    }
}

const STYLE: &str = "body{font-family:sans-serif;max-width:1100px;margin:0 auto;padding:0 16px;color:#111;line-height:1.45}
h1{font-size:1.7em}h2{border-bottom:2px solid #ccc;margin-top:2.2em}h3{margin-top:1.6em}
table{border-collapse:collapse;margin:0.6em 0;font-size:0.92em}th,td{border:1px solid #bbb;padding:3px 7px;text-align:left;vertical-align:top}
td.n{text-align:right;font-variant-numeric:tabular-nums}th{background:#f0f0f0}
figure{margin:1em 0}figure svg{max-width:100%;height:auto;border:1px solid #ddd}
figcaption{font-size:0.85em;color:#444}p.checks{background:#f6f8fa;padding:6px 10px;border-left:3px solid #3a7}
p.failed{background:#fdecea;padding:6px 10px;border-left:3px solid #c33}pre{font-size:0.8em;overflow-x:auto;background:#fafafa;padding:8px}
nav ul{columns:2}";

/// Checks, once the page is loaded, that every chart has a drawing (a bounding box of
/// positive size, at least one drawn element in each curve) and records the result on
/// the page for a headless browser's dump; a failure is a console error.
const RENDER_CHECK: &str = "<script>
window.addEventListener('load', function () {
  var charts = document.querySelectorAll('figure svg');
  var empty = [];
  charts.forEach(function (svg, k) {
    var box = svg.getBBox();
    var curves = svg.querySelectorAll('g.series');
    var blank = Array.prototype.filter.call(curves, function (g) {
      var b = g.getBBox();
      return g.querySelector('polyline').getAttribute('points').trim() !== '' && b.width === 0 && b.height === 0;
    });
    if (!(box.width > 0 && box.height > 0) || blank.length > 0) {
      empty.push(svg.closest('figure').id);
    }
  });
  var result = document.getElementById('render-check');
  result.setAttribute('data-charts', String(charts.length));
  result.setAttribute('data-empty', empty.join(' '));
  result.textContent = 'Rendered in this browser: ' + charts.length + ' charts, ' + empty.length + ' without a drawing.';
  if (empty.length > 0) { console.error('charts without a drawing: ' + empty.join(' ')); }
});
</script>";

/// The accuracy of every scene of `family` at its defaults (at its studies' load where
/// it has one), and the published
/// comparisons of the scenes that have one.
fn accuracy(family: &str) -> Accuracy {
    let mut accuracy = Accuracy::default();
    for scene in families::scenes().iter().filter(|s| s.family == family) {
        // each variant its studies pose (a plate's supports, its loads), at the load its
        // studies pose (the beams touch their obstacles at q = 100 only)
        let variants = match families::study_variants(scene) {
            Ok(variants) => variants,
            Err(e) => {
                accuracy.failures.push(format!("{}: {e}", scene.name));
                continue;
            }
        };
        for posed in variants {
            let settings = Settings {
                load: posed.study_load,
                ..Settings::default()
            };
            match families::solve(&posed, &settings) {
                Ok(outcome) => {
                    let rows = comparisons(&outcome.report);
                    if rows.is_empty() {
                        accuracy.without.push(posed.name.to_string());
                    }
                    accuracy.rows.extend(rows);
                }
                Err(e) => accuracy.failures.push(format!("{}: {e}", posed.name)),
            }
        }
        if *scene.name == *"membrane-radial" {
            match petsc_ex9() {
                Ok(more) => accuracy.rows.extend(more),
                Err(e) => accuracy.failures.push(e),
            }
        }
    }
    accuracy
}

/// The accuracy section of a family.
#[derive(Default)]
struct Accuracy {
    rows: Vec<Comparison>,
    /// Scenes (variants) whose report has no reference value.
    without: Vec<String>,
    /// Solves that failed, with their messages.
    failures: Vec<String>,
}

fn accuracy_table(html: &mut String, rows: &[Comparison]) {
    html.push_str("<table class=\"accuracy\"><tr><th>scene</th><th>solved</th><th>quantity</th><th>computed</th><th>reference</th><th>relative difference</th><th>source of the reference</th></tr>\n");
    for r in rows {
        let _ = writeln!(
            html,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td>{}</td></tr>",
            escape(&r.scene),
            escape(&r.solved),
            escape(&r.quantity),
            figure(r.computed),
            r.reference.map_or("0 (an error)".into(), figure),
            r.relative().map_or("–".into(), |d| if d == 0.0 {
                "0".into()
            } else {
                format!("{d:.2e}")
            }),
            escape(&r.source)
        );
    }
    html.push_str("</table>\n");
}

/// `Ok` where the error is that the file was not there.
trait NotFoundIsFine {
    fn filter_not_found(self) -> std::io::Result<()>;
}

impl NotFoundIsFine for std::io::Result<()> {
    fn filter_not_found(self) -> std::io::Result<()> {
        match self {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
            other => other,
        }
    }
}

/// A chart inline: the SVG file's text, which `write` checks is one `<svg>` element.
fn inline_chart(out: &Path, chart: &str) -> Result<String, String> {
    let text = std::fs::read_to_string(out.join(chart)).map_err(|e| format!("{chart}: {e}"))?;
    let start = text
        .find("<svg")
        .ok_or_else(|| format!("{chart}: not an SVG file"))?;
    Ok(text[start..].trim_end().to_string())
}

/// Runs every study and writes `options.out/index.html`; returns its path. A study or
/// solve that fails is shown on the page as failed (with its message), and the page is
/// still written; the error returned names the failures.
///
/// # Errors
/// The output directory or the page cannot be written; or studies failed (the page
/// is written, and the message lists them).
pub fn write(options: &Options) -> Result<PathBuf, String> {
    let start = Instant::now();
    let out = &options.out;
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    // a page of an earlier run would link this run's files (and its studies would stay
    // beside them): both go before anything runs, so an interrupted run leaves no page
    for old in [out.join("index.html"), out.join("studies")] {
        let removed = if old.is_dir() {
            std::fs::remove_dir_all(&old)
        } else {
            std::fs::remove_file(&old)
        };
        if let Err(e) = removed.filter_not_found() {
            return Err(format!("{}: {e}", old.display()));
        }
    }
    let jobs = jobs(&options.scenes);
    if jobs.is_empty() {
        return Err(format!(
            "no scene among {} hosts a study (see `fem-forms list`)",
            options.scenes.join(", ")
        ));
    }
    let family_names: Vec<&'static str> = families::families()
        .iter()
        .map(|f| f.name())
        .filter(|f| jobs.iter().any(|j| j.scene.family == *f))
        .collect();
    let bar = indicatif::ProgressBar::new((jobs.len() + family_names.len()) as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{elapsed_precise} [{bar:30}] {pos}/{len} {msg}")
            .map_err(|e| e.to_string())?
            .progress_chars("=> "),
    );
    // the clock moves during a long study too
    bar.enable_steady_tick(std::time::Duration::from_millis(500));
    // without a terminal the bar draws nothing: a line per study instead
    let lines = bar.is_hidden();
    let total = jobs.len();
    let mut done = Vec::with_capacity(jobs.len());
    for (k, job) in jobs.iter().enumerate() {
        bar.set_message(format!("study {} {}", job.scene.name, job.kind));
        if lines {
            eprintln!("[{}/{total}] study {} {}", k + 1, job.scene.name, job.kind);
        }
        let result = run_job(job, options.full, out);
        if let Some(e) = &result.error {
            bar.println(format!("failed: {e}"));
        }
        done.push(result);
        bar.inc(1);
    }
    let mut accuracies = Vec::new();
    for family in &family_names {
        bar.set_message(format!("accuracy of the {family} scenes"));
        if lines {
            eprintln!("accuracy of the {family} scenes");
        }
        accuracies.push(accuracy(family));
        bar.inc(1);
    }
    bar.finish_and_clear();

    let mut html = String::new();
    let _ = write!(
        html,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>fem-forms report</title>\n<style>{STYLE}</style>\n</head>\n<body>\n<h1>fem-forms: the studies of every family</h1>\n"
    );
    html.push_str("<p>Every number and chart on this page comes from the run that wrote it: each study below ran through the one solve, its charts are inline and their data is in the <code>.chart.csv</code> file beside each, and each scene's accuracy is its solve's own report against the reference named in the table. ");
    let _ = writeln!(
        html,
        "Settings: {} (<code>fem-forms report{}</code>).</p>",
        if options.full {
            "the larger meshes"
        } else {
            "quick"
        },
        if options.full { " --full" } else { "" }
    );
    html.push_str("<table class=\"facts\">\n");
    let total = start.elapsed().as_secs_f64();
    let mut facts = run_facts();
    facts.push(("total time", format!("{total:.1} s")));
    for (key, value) in facts {
        let _ = writeln!(html, "<tr><th>{key}</th><td>{}</td></tr>", escape(&value));
    }
    html.push_str("</table>\n<p id=\"render-check\" data-charts=\"\" data-empty=\"\">Not rendered by a browser with scripts.</p>\n<nav><h2>Families</h2><ul>\n");
    for family in &family_names {
        let description = families::family(family).map_or("", |f| f.description());
        let _ = writeln!(
            html,
            "<li><a href=\"#family-{family}\">{family}</a>: {}</li>",
            escape(description)
        );
    }
    html.push_str("</ul></nav>\n");
    let mut failed = Vec::new();
    let mut figure_id = 0;
    for (family, accuracy) in family_names.iter().zip(&accuracies) {
        let (rows, failures) = (&accuracy.rows, &accuracy.failures);
        let description = families::family(family).map_or("", |f| f.description());
        let _ = writeln!(
            html,
            "<section id=\"family-{family}\">\n<h2>{family}: {}</h2>",
            escape(description)
        );
        html.push_str("<h3>Accuracy against references</h3>\n<p class=\"checks\">Each scene of the family (each variant its studies pose) solved at its defaults and its studies' load: every quantity its report gives beside a reference, the relative difference, and where the reference comes from. Error norms have the reference 0.</p>\n");
        if !rows.is_empty() {
            accuracy_table(&mut html, rows);
        }
        if !accuracy.without.is_empty() {
            let _ = writeln!(
                html,
                "<p>No reference value at the load solved (no exact solution, series or closed form there): {}.</p>",
                escape(&accuracy.without.join(", "))
            );
        }
        for failure in failures {
            let _ = writeln!(
                html,
                "<p class=\"failed\">Not solved: {}</p>",
                escape(failure)
            );
            failed.push(failure.clone());
        }
        let radial = families::scenes()
            .iter()
            .any(|s| s.family == *family && *s.name == *"membrane-radial");
        match (&options.petsc_ex9, radial) {
            (Some(ex9), true) => match ex9_beside(ex9, out) {
                Ok(part) => html.push_str(&part),
                Err(e) => {
                    let _ = writeln!(html, "<p class=\"failed\">PETSc's ex9: {}</p>", escape(&e));
                    failed.push(e);
                }
            },
            (None, true) => html.push_str("<p>PETSc's ex9 was not run beside the nodal method (<code>--petsc-ex9 PATH</code>, or <code>FEM_FORMS_PETSC_EX9</code>, gives a built ex9); the errors it printed on the same grids are in the table above.</p>\n"),
            _ => {}
        }
        for d in done.iter().filter(|d| d.job.scene.family == *family) {
            let _ = writeln!(
                html,
                "<h3 id=\"{}-{}\">{}: {}</h3>\n<p class=\"checks\">{}</p>",
                d.job.scene.name,
                d.job.kind,
                escape(&d.job.scene.name),
                d.job.kind,
                escape(checks(d.job.kind))
            );
            let _ = writeln!(
                html,
                "<p>{} — took {:.2} s.</p>",
                escape(&d.job.scene.description),
                d.seconds
            );
            if let Some(e) = &d.error {
                let _ = writeln!(html, "<p class=\"failed\">Failed: {}</p>", escape(e));
                failed.push(e.clone());
            }
            for chart in &d.charts {
                figure_id += 1;
                let svg = match inline_chart(out, chart) {
                    Ok(svg) => svg,
                    Err(e) => {
                        failed.push(e.clone());
                        let _ = writeln!(html, "<p class=\"failed\">{}</p>", escape(&e));
                        continue;
                    }
                };
                let data = chart.replace(".svg", ".chart.csv");
                let points = std::fs::read_to_string(out.join(&data))
                    .map_or(usize::MAX, |text| text.lines().count().saturating_sub(1));
                if points == 0 {
                    let e = format!("{chart}: a chart without a single point");
                    let _ = writeln!(html, "<p class=\"failed\">{}</p>", escape(&e));
                    failed.push(e);
                    continue;
                }
                let data_attribute = if out.join(&data).exists() {
                    format!(" data-csv=\"{}\"", escape(&data))
                } else {
                    String::new()
                };
                let _ = writeln!(
                    html,
                    "<figure id=\"chart-{figure_id}\"{data_attribute}>\n{svg}\n<figcaption>{}{}</figcaption>\n</figure>",
                    escape(chart),
                    if data_attribute.is_empty() {
                        String::new()
                    } else {
                        format!(" · data: <a href=\"{0}\">{0}</a>", escape(&data))
                    }
                );
            }
            if !d.tables.is_empty() {
                let links: Vec<String> = d
                    .tables
                    .iter()
                    .map(|t| format!("<a href=\"{0}\">{0}</a>", escape(t)))
                    .collect();
                let _ = writeln!(html, "<p>Tables: {}</p>", links.join(", "));
            }
            if !d.log.trim().is_empty() {
                let _ = writeln!(
                    html,
                    "<details><summary>What the study printed</summary><pre>{}</pre></details>",
                    escape(d.log.trim_end())
                );
            }
        }
        html.push_str("</section>\n");
    }
    html.push_str(RENDER_CHECK);
    html.push_str("\n</body>\n</html>\n");
    let page = out.join("index.html");
    let partial = out.join("index.html.partial");
    std::fs::write(&partial, &html)
        .and_then(|()| std::fs::rename(&partial, &page))
        .map_err(|e| format!("{}: {e}", page.display()))?;
    if failed.is_empty() {
        Ok(page)
    } else {
        Err(format!(
            "{} written, but {} part(s) failed: {}",
            page.display(),
            failed.len(),
            failed.join("; ")
        ))
    }
}
