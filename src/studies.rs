//! The studies behind the charts: convergence against the exact flat-obstacle solution,
//! locking as t → 0, stability of plain vs stabilized pairs, the α range, work against
//! precision, and iteration counts. Each returns its rows (the tests run small
//! versions), prints a table, and writes `out/<study>.svg` and `out/<study>.csv`.

use crate::beams::{self, Pair, Profiles, Report, Request};
use crate::models::scenes::{exact_solution, scene, Scene};
use crate::plot::{self, Axes, Series};
use fem_runtime::obstacle::VariationalSolver;
use fem_runtime::{Error, Result};
use std::io::Write;
use std::path::Path;

/// The studies.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Study {
    /// Errors against the exact flat-obstacle solution and observed rates.
    Convergence,
    /// Timoshenko → Euler–Bernoulli as t → 0; the locking P1–P1 method beside.
    Locking,
    /// Plain (α = 0) against stabilized pairs: conditioning and multiplier profiles.
    Stability,
    /// Error and contact set against α.
    Alpha,
    /// Error against time for every solver.
    WorkPrecision,
    /// Newton iterations with nested iteration and from a cold start.
    Iterations,
}

impl Study {
    /// The studies of the default job.
    pub const DEFAULT: [Study; 6] = [
        Study::Convergence,
        Study::Locking,
        Study::Stability,
        Study::Alpha,
        Study::WorkPrecision,
        Study::Iterations,
    ];

    fn name(self) -> &'static str {
        match self {
            Study::Convergence => "convergence",
            Study::Locking => "locking",
            Study::Stability => "stability",
            Study::Alpha => "alpha",
            Study::WorkPrecision => "work-precision",
            Study::Iterations => "iterations",
        }
    }
}

fn flat() -> Scene {
    scene("bernoulli-flat").expect("the scene exists")
}

fn request(scene: Scene, elements: usize, load: f64) -> Request {
    let mut r = Request::new(scene);
    r.elements = elements;
    r.load = load;
    r
}

/// Observed rates `log2(e_k / e_{k+1})` of errors on meshes halved each time.
pub fn rates(errors: &[f64]) -> Vec<f64> {
    errors.windows(2).map(|e| (e[0] / e[1]).log2()).collect()
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
            let cells: Vec<String> = row.iter().map(|v| format!("{v:e}")).collect();
            writeln!(file, "{}", cells.join(","))?;
        }
    }
    std::fs::rename(tmp, path)
}

pub(crate) fn io(e: std::io::Error) -> Error {
    Error::Input(format!("writing output: {e}"))
}

/// One mesh of the convergence study.
#[derive(Clone, Debug)]
pub struct ConvergenceRow {
    /// Elements.
    pub elements: usize,
    /// `‖w − w_h‖_L2`.
    pub error_l2: f64,
    /// `‖(w − w_h)'‖_L2`.
    pub error_h1: f64,
    /// `|∫λ_h − ∫λ|` (point forces included in ∫λ).
    pub force_error: f64,
    /// Distance of the computed contact edge from the exact one.
    pub edge_error: f64,
    /// Solve time.
    pub seconds: f64,
}

/// `bernoulli-flat` at q = 100 (contact interval) on uniform meshes.
pub fn convergence(meshes: &[usize]) -> Result<Vec<ConvergenceRow>> {
    let q = 100.0;
    let exact = exact_solution(&flat(), q, 0.0).expect("bernoulli-flat has an exact solution");
    meshes
        .iter()
        .map(|&n| {
            let (r, _) = beams::solve(&request(flat(), n, q))?;
            let edge = r.contact_set.first().map_or(f64::NAN, |c| c[0]);
            Ok(ConvergenceRow {
                elements: n,
                error_l2: r.error_l2.unwrap_or(f64::NAN),
                error_h1: r.error_h1.unwrap_or(f64::NAN),
                force_error: (r.total_contact_force - exact.total_contact_force).abs(),
                edge_error: (edge - exact.contact_set[0][0]).abs(),
                seconds: r.seconds,
            })
        })
        .collect()
}

fn run_convergence(full: bool, out: &Path) -> Result<()> {
    let meshes: Vec<usize> = if full {
        (4..=14).map(|k| 1 << k).collect()
    } else {
        (4..=10).map(|k| 1 << k).collect()
    };
    let rows = convergence(&meshes)?;
    let r2 = rates(&rows.iter().map(|r| r.error_l2).collect::<Vec<_>>());
    let r1 = rates(&rows.iter().map(|r| r.error_h1).collect::<Vec<_>>());
    println!("convergence: bernoulli-flat, q = 100, Hermite–P0, α = 1e-2 (exact solution, contact interval)");
    println!(
        "{:>8} {:>12} {:>6} {:>12} {:>6} {:>12} {:>12}",
        "elements", "L2 error", "rate", "H1 error", "rate", "∫λ error", "edge error"
    );
    for (k, r) in rows.iter().enumerate() {
        let rate = |v: &[f64]| {
            if k == 0 {
                "-".to_string()
            } else {
                format!("{:.2}", v[k - 1])
            }
        };
        println!(
            "{:>8} {:>12.4e} {:>6} {:>12.4e} {:>6} {:>12.4e} {:>12.4e}",
            r.elements,
            r.error_l2,
            rate(&r2),
            r.error_h1,
            rate(&r1),
            r.force_error,
            r.edge_error
        );
    }
    let h = |r: &ConvergenceRow| 1.0 / r.elements as f64;
    plot::chart(
        &out.join("convergence.svg"),
        "bernoulli-flat q = 100: errors against h (Hermite–P0, stabilized)",
        Axes {
            x: "h",
            y: "error",
            log_x: true,
            log_y: true,
        },
        &[
            Series::marked(
                "‖w − w_h‖_L2",
                rows.iter().map(|r| (h(r), r.error_l2)).collect(),
            ),
            Series::marked(
                "‖(w − w_h)'‖_L2",
                rows.iter().map(|r| (h(r), r.error_h1)).collect(),
            ),
            Series::marked(
                "|∫λ_h − ∫λ|",
                rows.iter().map(|r| (h(r), r.force_error)).collect(),
            ),
        ],
    )
    .map_err(io)?;
    write_csv(
        &out.join("convergence.csv"),
        "elements,error_l2,error_h1,force_error,edge_error,seconds",
        &rows
            .iter()
            .map(|r| {
                vec![
                    r.elements as f64,
                    r.error_l2,
                    r.error_h1,
                    r.force_error,
                    r.edge_error,
                    r.seconds,
                ]
            })
            .collect::<Vec<_>>(),
    )
    .map_err(io)
}

/// One thickness of the locking study.
#[derive(Clone, Debug)]
pub struct LockingRow {
    /// Element pair.
    pub pair: Pair,
    /// Thickness.
    pub thickness: f64,
    /// Largest |w|.
    pub max_deflection: f64,
    /// `‖w_h − w_EB‖_L2` against the Euler–Bernoulli reference.
    pub difference_to_bernoulli: f64,
    /// Relative energy difference to the Euler–Bernoulli reference.
    pub energy_difference: f64,
}

/// Linear interpolation of sampled values at `x`.
fn sample(p: &Profiles, x: f64) -> f64 {
    let n = p.x.len() - 1;
    let i = ((x * n as f64).floor() as usize).min(n - 1);
    let t = x * n as f64 - i as f64;
    p.w[i] * (1.0 - t) + p.w[i + 1] * t
}

fn l2_difference(a: &Profiles, b: &Profiles) -> f64 {
    let n = 4000;
    let sum: f64 = (0..n)
        .map(|i| {
            let x = (i as f64 + 0.5) / n as f64;
            (sample(a, x) - sample(b, x)).powi(2)
        })
        .sum();
    (sum / n as f64).sqrt()
}

/// `timoshenko-a` at q = 100 on `elements` elements for each pair and thickness, against
/// `bernoulli-a` on a fine mesh.
pub fn locking(
    elements: usize,
    thicknesses: &[f64],
    pairs: &[Pair],
) -> Result<(Report, Vec<LockingRow>)> {
    let q = 100.0;
    let (reference, reference_profiles) =
        beams::solve(&request(scene("bernoulli-a").unwrap(), 4096, q))?;
    let mut rows = Vec::new();
    for &pair in pairs {
        for &t in thicknesses {
            let mut r = request(scene("timoshenko-a").unwrap(), elements, q);
            r.pair = Some(pair);
            r.thickness = Some(t);
            r.refinement_steps = if t < 1e-4 { 3 } else { 1 };
            let (report, profiles) = beams::solve(&r)?;
            rows.push(LockingRow {
                pair,
                thickness: t,
                max_deflection: report.max_deflection,
                difference_to_bernoulli: l2_difference(&profiles, &reference_profiles),
                energy_difference: ((report.energy - reference.energy) / reference.energy).abs(),
            });
        }
    }
    Ok((reference, rows))
}

fn run_locking(full: bool, out: &Path) -> Result<()> {
    let thicknesses = [1e-1, 3e-2, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 1e-5];
    let pairs = [
        Pair::TimoshenkoP2,
        Pair::TimoshenkoP1Reduced,
        Pair::TimoshenkoP1Full,
    ];
    let (reference, rows) = locking(if full { 1024 } else { 256 }, &thicknesses, &pairs)?;
    println!(
        "\nlocking: timoshenko-a, q = 100, {} elements; Euler–Bernoulli reference (4096 Hermite elements): max |w| = {:.6e}",
        if full { 1024 } else { 256 },
        reference.max_deflection
    );
    println!(
        "{:<18} {:>8} {:>12} {:>14} {:>12}",
        "pair", "t", "max |w|", "‖w − w_EB‖", "ΔJ/J"
    );
    for r in &rows {
        println!(
            "{:<18} {:>8.0e} {:>12.6e} {:>14.4e} {:>12.3e}",
            r.pair.name(),
            r.thickness,
            r.max_deflection,
            r.difference_to_bernoulli,
            r.energy_difference
        );
    }
    let series = |f: &dyn Fn(&LockingRow) -> f64| -> Vec<Series> {
        pairs
            .iter()
            .map(|p| {
                Series::marked(
                    p.name(),
                    rows.iter()
                        .filter(|r| r.pair == *p)
                        .map(|r| (r.thickness, f(r)))
                        .collect(),
                )
            })
            .collect()
    };
    let mut deflection = series(&|r| r.max_deflection);
    deflection.push(Series::line(
        "Euler–Bernoulli",
        vec![
            (thicknesses[thicknesses.len() - 1], reference.max_deflection),
            (thicknesses[0], reference.max_deflection),
        ],
    ));
    plot::stacked(
        &out.join("locking.svg"),
        &[
            (
                "timoshenko-a q = 100: max |w| against t (locking collapses it)".into(),
                Axes {
                    x: "t",
                    y: "max |w|",
                    log_x: true,
                    log_y: true,
                },
                deflection,
            ),
            (
                "‖w_h(t) − w_EB‖_L2: converges to Euler–Bernoulli as t → 0".into(),
                Axes {
                    x: "t",
                    y: "difference",
                    log_x: true,
                    log_y: true,
                },
                series(&|r| r.difference_to_bernoulli),
            ),
        ],
    )
    .map_err(io)?;
    write_csv(
        &out.join("locking.csv"),
        "pair_index,thickness,max_deflection,difference_to_bernoulli,energy_difference",
        &rows
            .iter()
            .map(|r| {
                vec![
                    pairs.iter().position(|p| *p == r.pair).unwrap() as f64,
                    r.thickness,
                    r.max_deflection,
                    r.difference_to_bernoulli,
                    r.energy_difference,
                ]
            })
            .collect::<Vec<_>>(),
    )
    .map_err(io)
}

/// Condition number of the LCP matrix `M = B A⁻¹ Bᵀ + C` of a request: the matrix the
/// multiplier sees once U is eliminated. Its smallest eigenvalue is the discrete inf-sup
/// constant squared (in the Euclidean norm of the P0 coefficients); `C = αΣh⁴(λ, μ)`
/// lifts it for the stabilized method.
pub fn lcp_condition(request: &Request) -> Result<f64> {
    let (d, _) = beams::discretize(request)?;
    let lcp = &d.lcp;
    let (n, m) = (lcp.n(), lcp.m());
    let mut a = nalgebra::DMatrix::<f64>::zeros(n, n);
    let (col_ptr, rows, vals) = (
        lcp.a.symbolic().col_ptr(),
        lcp.a.symbolic().row_idx(),
        lcp.a.val(),
    );
    for j in 0..n {
        for idx in col_ptr[j]..col_ptr[j + 1] {
            a[(rows[idx], j)] = vals[idx];
        }
    }
    let mut bt = nalgebra::DMatrix::<f64>::zeros(n, m);
    for (k, row) in lcp.b_rows.iter().enumerate() {
        for &(j, v) in row {
            bt[(j, k)] = v;
        }
    }
    let cholesky = a
        .cholesky()
        .ok_or_else(|| Error::LinearSolve("A is not positive definite".into()))?;
    let a_inv_bt = cholesky.solve(&bt);
    let mut schur = bt.transpose() * a_inv_bt;
    for k in 0..m {
        schur[(k, k)] += lcp.c[k];
    }
    let eigenvalues = nalgebra::SymmetricEigen::new(schur).eigenvalues;
    let largest = eigenvalues.max();
    let smallest = eigenvalues.min();
    Ok(if smallest > 0.0 {
        largest / smallest
    } else {
        f64::INFINITY
    })
}

/// The multiplier profile of a scene at q = 100 with stabilization `alpha` (`None`: the
/// plain mixed method, α = 0, solved as a QP).
pub fn multiplier_profile(
    scene_name: &str,
    elements: usize,
    alpha: Option<f64>,
) -> Result<Profiles> {
    let s = scene(scene_name).ok_or_else(|| Error::Input(format!("no scene {scene_name}")))?;
    let mut r = request(s, elements, 100.0);
    match alpha {
        Some(a) => r.alpha = Some(a),
        None => {
            r.alpha = Some(0.0);
            r.plain = true;
            r.solver = VariationalSolver::Clarabel;
        }
    }
    Ok(beams::solve(&r)?.1)
}

/// Largest `|λ_h − q|` over the middle half of the contact interval of `bernoulli-flat`
/// (where the exact λ is q = 100): the oscillation the stabilization damps.
pub fn interior_oscillation(p: &Profiles, contact: [f64; 2]) -> f64 {
    let (a, b) = (contact[0], contact[1]);
    let (lo, hi) = (a + 0.25 * (b - a), b - 0.25 * (b - a));
    p.cell_x
        .iter()
        .zip(&p.lambda)
        .filter(|(x, _)| **x >= lo && **x <= hi)
        .map(|(_, l)| (l - 100.0).abs())
        .fold(0.0, f64::max)
}

fn run_stability(full: bool, out: &Path) -> Result<()> {
    let meshes: Vec<usize> = if full {
        vec![8, 16, 32, 64, 128, 256]
    } else {
        vec![8, 16, 32, 64, 128]
    };
    println!("\nstability: condition number of the LCP matrix B A⁻¹ Bᵀ + C at q = 100");
    println!(
        "{:<15} {:>8} {:>14} {:>14}",
        "scene", "elements", "plain α = 0", "stabilized"
    );
    let mut charts = Vec::new();
    let mut csv = Vec::new();
    for (k, name) in ["bernoulli-a", "timoshenko-a"].iter().enumerate() {
        let mut plain_series = Vec::new();
        let mut stabilized_series = Vec::new();
        for &n in &meshes {
            let mut r = request(scene(name).unwrap(), n, 100.0);
            let stabilized = lcp_condition(&r)?;
            r.alpha = Some(0.0);
            r.plain = true;
            r.solver = VariationalSolver::Clarabel;
            let plain = lcp_condition(&r)?;
            println!("{name:<15} {n:>8} {plain:>14.4e} {stabilized:>14.4e}");
            plain_series.push((1.0 / n as f64, plain));
            stabilized_series.push((1.0 / n as f64, stabilized));
            csv.push(vec![k as f64, n as f64, plain, stabilized]);
        }
        charts.push((
            format!("{name}: condition number of the LCP matrix B A⁻¹ Bᵀ + C against h"),
            Axes {
                x: "h",
                y: "κ₂",
                log_x: true,
                log_y: true,
            },
            vec![
                Series::marked("plain (α = 0)", plain_series),
                Series::marked("stabilized", stabilized_series),
            ],
        ));
    }
    let elements = if full { 1024 } else { 256 };
    let exact = exact_solution(&flat(), 100.0, 0.0).unwrap();
    let variants: [(&str, Option<f64>); 3] = [
        ("plain (α = 0)", None),
        ("stabilized α = 1e-2", Some(1e-2)),
        ("stabilized α = 1", Some(1.0)),
    ];
    println!("\nbernoulli-flat q = 100, {elements} elements: multiplier λ_h (exact: q = 100 inside, point forces at the edges)");
    println!(
        "{:<22} {:>16} {:>22}",
        "method", "holes (λ_h = 0)", "max |λ_h − 100| inside"
    );
    let mut series = Vec::new();
    for (label, alpha) in variants {
        let p = multiplier_profile("bernoulli-flat", elements, alpha)?;
        println!(
            "{label:<22} {:>16} {:>22.4e}",
            zero_holes(&p.lambda),
            interior_oscillation(&p, exact.contact_set[0])
        );
        let half = 0.5 / p.lambda.len() as f64;
        series.push(Series::line(
            label,
            p.cell_x
                .iter()
                .zip(&p.lambda)
                .filter(|(x, _)| (**x - 0.5).abs() < 0.5 - exact.contact_set[0][0] + 0.03)
                .flat_map(|(&x, &l)| [(x - half, l), (x + half, l)])
                .collect(),
        ));
    }
    charts.push((
        format!("bernoulli-flat q = 100, {elements} elements: λ_h near the contact set (exact 100 inside)"),
        Axes { x: "x", y: "λ_h", ..Axes::default() },
        series,
    ));
    plot::stacked(&out.join("stability.svg"), &charts).map_err(io)?;
    write_csv(
        &out.join("stability.csv"),
        "scene_index,elements,condition_plain,condition_stabilized",
        &csv,
    )
    .map_err(io)
}

/// Cells with λ = 0 between the first and the last cell with λ > 0 ("holes").
pub fn zero_holes(lambda: &[f64]) -> usize {
    let largest = lambda.iter().cloned().fold(0.0, f64::max);
    let on: Vec<bool> = lambda.iter().map(|&l| l > 1e-8 * largest).collect();
    match (on.iter().position(|&b| b), on.iter().rposition(|&b| b)) {
        (Some(first), Some(last)) => on[first..=last].iter().filter(|&&b| !b).count(),
        _ => 0,
    }
}

/// One α of the α sweep.
#[derive(Clone, Debug)]
pub struct AlphaRow {
    /// α.
    pub alpha: f64,
    /// `‖w − w_h‖_L2`.
    pub error_l2: f64,
    /// Left edge of the computed contact set.
    pub contact_start: f64,
    /// `∫λ_h`.
    pub total_contact_force: f64,
}

/// `bernoulli-flat` at q = 100 for each α.
pub fn alpha_sweep(elements: usize, alphas: &[f64]) -> Result<Vec<AlphaRow>> {
    alphas
        .iter()
        .map(|&alpha| {
            let mut r = request(flat(), elements, 100.0);
            r.alpha = Some(alpha);
            let (report, _) = beams::solve(&r)?;
            Ok(AlphaRow {
                alpha,
                error_l2: report.error_l2.unwrap_or(f64::NAN),
                contact_start: report.contact_set.first().map_or(f64::NAN, |c| c[0]),
                total_contact_force: report.total_contact_force,
            })
        })
        .collect()
}

fn run_alpha(full: bool, out: &Path) -> Result<()> {
    let elements = if full { 1024 } else { 128 };
    let alphas: Vec<f64> = (-8..=8).map(|k| 10f64.powi(k)).collect();
    let rows = alpha_sweep(elements, &alphas)?;
    let exact = exact_solution(&flat(), 100.0, 0.0).unwrap();
    println!(
        "\nα sweep: bernoulli-flat q = 100, {elements} elements (C_I = 0 for Hermite–P0: every α > 0 is stable; α ≤ 1e-2 is accurate)"
    );
    println!(
        "{:>8} {:>12} {:>14} {:>10}",
        "α", "L2 error", "contact start", "∫λ_h"
    );
    for r in &rows {
        println!(
            "{:>8.0e} {:>12.4e} {:>14.6} {:>10.4}",
            r.alpha, r.error_l2, r.contact_start, r.total_contact_force
        );
    }
    println!(
        "exact contact start {:.6}, ∫λ = {:.4}",
        exact.contact_set[0][0], exact.total_contact_force
    );
    plot::stacked(
        &out.join("alpha.svg"),
        &[
            (
                format!("bernoulli-flat q = 100, {elements} elements: L2 error against α (1/C_I = ∞ for Hermite–P0)"),
                Axes { x: "α", y: "‖w − w_h‖_L2", log_x: true, log_y: true },
                vec![Series::marked("stabilized Hermite–P0", rows.iter().map(|r| (r.alpha, r.error_l2)).collect())],
            ),
            (
                "contact start against α: a too large α shifts the contact set".into(),
                Axes { x: "α", y: "contact start", log_x: true, log_y: false },
                vec![
                    Series::marked("computed", rows.iter().map(|r| (r.alpha, r.contact_start)).collect()),
                    Series::line(
                        "exact",
                        vec![(alphas[0], exact.contact_set[0][0]), (alphas[alphas.len() - 1], exact.contact_set[0][0])],
                    ),
                ],
            ),
        ],
    )
    .map_err(io)?;
    write_csv(
        &out.join("alpha.csv"),
        "alpha,error_l2,contact_start,total_contact_force",
        &rows
            .iter()
            .map(|r| vec![r.alpha, r.error_l2, r.contact_start, r.total_contact_force])
            .collect::<Vec<_>>(),
    )
    .map_err(io)
}

/// One solve of the work–precision study.
#[derive(Clone, Debug)]
pub struct WorkRow {
    /// "pdas nested", "pdas cold", "clarabel".
    pub method: &'static str,
    /// Elements.
    pub elements: usize,
    /// Seconds.
    pub seconds: f64,
    /// `‖w − w_h‖_L2`.
    pub error_l2: f64,
    /// Iterations on the final mesh.
    pub iterations: usize,
    /// Why the solve failed, if it did.
    pub failure: Option<String>,
}

/// `bernoulli-flat` at q = 100 with each solver on each mesh (cold starts up to `cold_max`).
pub fn work_precision(meshes: &[usize], cold_max: usize) -> Result<Vec<WorkRow>> {
    let mut rows = Vec::new();
    for &n in meshes {
        let methods: [(&'static str, VariationalSolver, Option<usize>); 3] = [
            ("pdas nested", VariationalSolver::SemismoothNewton, Some(16)),
            ("pdas cold", VariationalSolver::SemismoothNewton, None),
            ("clarabel", VariationalSolver::Clarabel, None),
        ];
        for (method, solver, nested) in methods {
            if nested.is_none() && solver == VariationalSolver::SemismoothNewton && n > cold_max {
                continue;
            }
            let mut r = request(flat(), n, 100.0);
            r.solver = solver;
            r.nested_from = nested;
            // A failure is a result of the study (where a method breaks down), not an abort.
            match beams::solve(&r) {
                Ok((report, _)) => rows.push(WorkRow {
                    method,
                    elements: n,
                    seconds: report.seconds,
                    error_l2: report.error_l2.unwrap_or(f64::NAN),
                    iterations: report.iterations,
                    failure: None,
                }),
                Err(e) => rows.push(WorkRow {
                    method,
                    elements: n,
                    seconds: f64::NAN,
                    error_l2: f64::NAN,
                    iterations: 0,
                    failure: Some(e.to_string()),
                }),
            }
        }
    }
    Ok(rows)
}

fn run_work_precision(full: bool, out: &Path) -> Result<()> {
    let meshes: Vec<usize> = (5..=if full { 15 } else { 12 }).map(|k| 1 << k).collect();
    let rows = work_precision(&meshes, if full { 8192 } else { 2048 })?;
    println!("\nwork–precision: bernoulli-flat q = 100");
    println!(
        "{:<12} {:>8} {:>10} {:>12} {:>6}",
        "method", "elements", "seconds", "L2 error", "iter"
    );
    for r in &rows {
        match &r.failure {
            None => println!(
                "{:<12} {:>8} {:>10.4} {:>12.4e} {:>6}",
                r.method, r.elements, r.seconds, r.error_l2, r.iterations
            ),
            Some(e) => println!("{:<12} {:>8}  failed: {e}", r.method, r.elements),
        }
    }
    let series: Vec<Series> = ["pdas nested", "pdas cold", "clarabel"]
        .iter()
        .map(|m| {
            Series::marked(
                *m,
                rows.iter()
                    .filter(|r| r.method == *m)
                    .map(|r| (r.seconds, r.error_l2))
                    .collect(),
            )
        })
        .collect();
    plot::chart(
        &out.join("work-precision.svg"),
        "bernoulli-flat q = 100: L2 error against solve time",
        Axes {
            x: "seconds",
            y: "‖w − w_h‖_L2",
            log_x: true,
            log_y: true,
        },
        &series,
    )
    .map_err(io)?;
    write_csv(
        &out.join("work-precision.csv"),
        "method_index,elements,seconds,error_l2,iterations",
        &rows
            .iter()
            .map(|r| {
                let m = ["pdas nested", "pdas cold", "clarabel"]
                    .iter()
                    .position(|m| *m == r.method)
                    .unwrap();
                vec![
                    m as f64,
                    r.elements as f64,
                    r.seconds,
                    r.error_l2,
                    r.iterations as f64,
                ]
            })
            .collect::<Vec<_>>(),
    )
    .map_err(io)
}

/// Newton iterations of a scene at q = 100: `(elements, nested final-level iterations,
/// cold-start iterations where run)`.
/// `(elements, nested iterations, cold-start iterations)`; `None` where not run or failed.
pub type IterationRow = (usize, Option<usize>, Option<usize>);

/// A failed solve is recorded as `None`: the study shows where the method breaks down.
pub fn iteration_counts(
    scene_name: &str,
    meshes: &[usize],
    cold_max: usize,
) -> Result<Vec<IterationRow>> {
    let s = scene(scene_name).ok_or_else(|| Error::Input(format!("no scene {scene_name}")))?;
    Ok(meshes
        .iter()
        .map(|&n| {
            let nested = beams::solve(&request(s, n, 100.0))
                .ok()
                .map(|r| r.0.iterations);
            let cold = (n <= cold_max)
                .then(|| {
                    let mut r = request(s, n, 100.0);
                    r.nested_from = None;
                    beams::solve(&r).ok().map(|r| r.0.iterations)
                })
                .flatten();
            (n, nested, cold)
        })
        .collect())
}

fn run_iterations(full: bool, out: &Path) -> Result<()> {
    let meshes: Vec<usize> = (5..=if full { 17 } else { 15 }).map(|k| 1 << k).collect();
    let cold_max = if full { 8192 } else { 2048 };
    println!("\niterations: semismooth Newton at q = 100, nested iteration from 16 elements (cold start beside)");
    println!(
        "{:<15} {:>8} {:>8} {:>6}",
        "scene", "elements", "nested", "cold"
    );
    let mut charts = Vec::new();
    let mut csv = Vec::new();
    for (k, name) in ["bernoulli-flat", "timoshenko-a"].iter().enumerate() {
        let rows = iteration_counts(name, &meshes, cold_max)?;
        for &(n, nested, cold) in &rows {
            let show = |v: Option<usize>| v.map_or("-".to_string(), |c| c.to_string());
            println!("{name:<15} {n:>8} {:>8} {:>6}", show(nested), show(cold));
            csv.push(vec![
                k as f64,
                n as f64,
                nested.map_or(f64::NAN, |c| c as f64),
                cold.map_or(f64::NAN, |c| c as f64),
            ]);
        }
        println!("  ('-' in nested: the solve failed; Hermite bending matrices have κ ~ h⁻⁴, past 1/ε near 10⁴ elements)");
        charts.push((
            format!("{name} q = 100: Newton iterations on the final mesh"),
            Axes {
                x: "elements",
                y: "iterations",
                log_x: true,
                log_y: true,
            },
            vec![
                Series::marked(
                    "nested",
                    rows.iter()
                        .filter_map(|r| r.1.map(|c| (r.0 as f64, c.max(1) as f64)))
                        .collect(),
                ),
                Series::marked(
                    "cold start",
                    rows.iter()
                        .filter_map(|r| r.2.map(|c| (r.0 as f64, c.max(1) as f64)))
                        .collect(),
                ),
            ],
        ));
    }
    plot::stacked(&out.join("iterations.svg"), &charts).map_err(io)?;
    write_csv(
        &out.join("iterations.csv"),
        "scene_index,elements,nested,cold",
        &csv,
    )
    .map_err(io)
}

/// Runs a study, prints its table, writes its chart and CSV.
pub fn run(study: Study, full: bool, out: &Path) -> Result<()> {
    match study {
        Study::Convergence => run_convergence(full, out),
        Study::Locking => run_locking(full, out),
        Study::Stability => run_stability(full, out),
        Study::Alpha => run_alpha(full, out),
        Study::WorkPrecision => run_work_precision(full, out),
        Study::Iterations => run_iterations(full, out),
    }?;
    println!("→ {}/{}.svg, .csv", out.display(), study.name());
    Ok(())
}
