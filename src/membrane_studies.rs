//! The membrane studies behind `fem-forms study membrane-radial convergence|stability|alpha`:
//! errors and observed rates against the exact radial solution for every pair, the
//! discrete inf-sup constants of the plain and the stabilized pairs with the multiplier
//! profiles that show the oscillation, and the error against α with `1/C_I` marked.
//! Each returns its rows (the tests run small versions), prints a table, and writes
//! `out/membrane-radial-<study>.svg` and `.csv`.

use crate::membranes::{self, alpha_of, scene_mesh, MembranePair, MembraneReport, MembraneRequest};
use crate::models::membrane::{membrane_p1_p0, membrane_p2_p0};
use crate::models::membrane_scenes::{membrane_scene, MembraneScene};
use crate::plot::{self, Axes, Series};
use crate::studies::{io, rates, write_csv};
use fem_runtime::lcp::cholesky::Cholesky;
use fem_runtime::obstacle::triangle::discretize_on_triangles;
use fem_runtime::obstacle::Discretization;
use fem_runtime::{Diagonal, Error, Model, Result, TriangleMesh};
use nalgebra::{DMatrix, SymmetricEigen};
use std::path::Path;

/// The membrane studies.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum MembraneStudy {
    /// Errors against the exact solution and observed rates, every pair.
    Convergence,
    /// Discrete inf-sup constants, plain against stabilized, and multiplier profiles.
    Stability,
    /// Error against α on one mesh, with 1/C_I marked.
    Alpha,
}

impl MembraneStudy {
    /// Every membrane study.
    pub const ALL: [MembraneStudy; 3] = [
        MembraneStudy::Convergence,
        MembraneStudy::Stability,
        MembraneStudy::Alpha,
    ];

    fn name(self) -> &'static str {
        match self {
            MembraneStudy::Convergence => "convergence",
            MembraneStudy::Stability => "stability",
            MembraneStudy::Alpha => "alpha",
        }
    }
}

fn radial() -> MembraneScene {
    membrane_scene("membrane-radial").expect("the scene exists")
}

/// Solves the radial scene with `pair` on N×N×2.
pub fn radial_report(pair: MembranePair, n: usize, alpha: Option<f64>) -> Result<MembraneReport> {
    let mut request = MembraneRequest::new(radial());
    request.pair = pair;
    request.mesh_size = n;
    request.alpha = alpha;
    Ok(membranes::solve(&request)?.0)
}

/// The mesh sizes N of the convergence study for a pair: six meshes, up to
/// 512×512×2 = 524,288 triangles for the P1 pairs and 128×128×2 for P2; `full` adds
/// one finer mesh (2M triangles for P1).
pub fn convergence_sizes(pair: MembranePair, full: bool) -> Vec<usize> {
    let top = match (pair.degree(), full) {
        (1, false) => 512,
        (1, true) => 1024,
        (_, false) => 128,
        (_, true) => 256,
    };
    let mut sizes = vec![top];
    while sizes.len() < 6 + usize::from(full) {
        sizes.insert(0, sizes[0] / 2);
    }
    sizes
}

/// Runs the convergence study for `pairs` on their sizes.
pub fn convergence(pairs: &[MembranePair], full: bool) -> Result<Vec<MembraneReport>> {
    let mut rows = Vec::new();
    for &pair in pairs {
        for n in convergence_sizes(pair, full) {
            rows.push(radial_report(pair, n, None)?);
        }
    }
    Ok(rows)
}

fn pair_rows<'a>(rows: &'a [MembraneReport], pair: &str) -> Vec<&'a MembraneReport> {
    rows.iter().filter(|r| r.pair == pair).collect()
}

fn run_convergence(full: bool, out: &Path) -> Result<()> {
    let pairs = available_pairs();
    let rows = convergence(&pairs, full)?;
    println!(
        "membrane-radial: errors against the exact solution (rates between successive meshes)"
    );
    println!(
        "{:<8} {:>5} {:>9} {:>9} {:>10} {:>6} {:>10} {:>6} {:>10} {:>6} {:>10} {:>9} {:>5} {:>8}",
        "pair",
        "N",
        "triangles",
        "dofs",
        "L2",
        "rate",
        "H1",
        "rate",
        "h·λ",
        "rate",
        "|∫λ−2πA|",
        "area err",
        "iter",
        "seconds"
    );
    let mut csv = Vec::new();
    let mut h1_series = Vec::new();
    let mut l2_series = Vec::new();
    let mut multiplier_series = Vec::new();
    let mut work_series = Vec::new();
    for pair in &pairs {
        let pr = pair_rows(&rows, pair.name());
        let l2: Vec<f64> = pr.iter().map(|r| r.error_l2.unwrap_or(f64::NAN)).collect();
        let h1: Vec<f64> = pr.iter().map(|r| r.error_h1.unwrap_or(f64::NAN)).collect();
        let lm: Vec<f64> = pr
            .iter()
            .map(|r| r.error_multiplier.unwrap_or(f64::NAN))
            .collect();
        let (rl2, rh1, rlm) = (rates(&l2), rates(&h1), rates(&lm));
        for (k, r) in pr.iter().enumerate() {
            let rate = |v: &[f64]| {
                k.checked_sub(1)
                    .map_or("".to_string(), |j| format!("{:.2}", v[j]))
            };
            let force = (r.total_contact_force - r.exact_contact_force.unwrap_or(f64::NAN)).abs();
            let area = (r.contact_area - r.exact_contact_area.unwrap_or(f64::NAN)).abs();
            println!(
                "{:<8} {:>5} {:>9} {:>9} {:>10.3e} {:>6} {:>10.3e} {:>6} {:>10.3e} {:>6} {:>10.3e} {:>9.2e} {:>5} {:>8.3}",
                r.pair,
                r.mesh_size,
                r.triangles,
                r.dofs,
                l2[k],
                rate(&rl2),
                h1[k],
                rate(&rh1),
                lm[k],
                rate(&rlm),
                force,
                area,
                r.iterations,
                r.seconds
            );
            let pair_index = pairs.iter().position(|p| p == pair).unwrap_or(0) as f64;
            csv.push(vec![
                pair_index,
                r.mesh_size as f64,
                4.0 * 2f64.sqrt() / r.mesh_size as f64,
                r.dofs as f64,
                l2[k],
                h1[k],
                lm[k],
                force,
                area,
                r.iterations as f64,
                r.seconds,
            ]);
        }
        let h = |r: &&MembraneReport| 4.0 * 2f64.sqrt() / r.mesh_size as f64;
        h1_series.push(Series::marked(
            format!("{} H¹", pair.name()),
            pr.iter().zip(&h1).map(|(r, &e)| (h(r), e)).collect(),
        ));
        l2_series.push(Series::marked(
            format!("{} L²", pair.name()),
            pr.iter().zip(&l2).map(|(r, &e)| (h(r), e)).collect(),
        ));
        work_series.push(Series::marked(
            format!("{} H¹ against seconds", pair.name()),
            pr.iter()
                .zip(&h1)
                .map(|(r, &e)| (r.seconds.max(1e-5), e))
                .collect(),
        ));
        if lm.iter().all(|e| e.is_finite()) {
            multiplier_series.push(Series::marked(
                format!("{} h-weighted λ", pair.name()),
                pr.iter().zip(&lm).map(|(r, &e)| (h(r), e)).collect(),
            ));
        }
    }
    let axes = |y| Axes {
        x: "h",
        y,
        log_x: true,
        log_y: true,
    };
    plot::stacked(
        &out.join("membrane-radial-convergence.svg"),
        &[
            (
                "membrane-radial: H¹ error of u".into(),
                axes("|u − u_h|_H1"),
                h1_series,
            ),
            (
                "membrane-radial: L² error of u".into(),
                axes("‖u − u_h‖_L2"),
                l2_series,
            ),
            (
                "membrane-radial: error of λ, (Σ h_T² ‖λ − λ_h‖²_T)^½".into(),
                axes("h-weighted error of λ"),
                multiplier_series,
            ),
            (
                "membrane-radial: work against precision (complete nested solve)".into(),
                Axes {
                    x: "seconds",
                    y: "|u − u_h|_H1",
                    log_x: true,
                    log_y: true,
                },
                work_series,
            ),
        ],
    )
    .map_err(io)?;
    write_csv(
        &out.join("membrane-radial-convergence.csv"),
        "pair_index,N,h,dofs,error_l2,error_h1,error_multiplier_h_weighted,error_total_force,error_contact_area,iterations,seconds",
        &csv,
    )
    .map_err(io)
}

/// The pairs the stabilized LCP solver handles today.
pub fn available_pairs() -> Vec<MembranePair> {
    MembranePair::ALL
        .into_iter()
        .filter(|&p| radial_report(p, 4, None).is_ok())
        .collect()
}

/// Discrete inf-sup constants of the multiplier: `γ_k = λ_k(M_h⁻¹ (B A⁻¹ Bᵀ + C))` in the
/// h-weighted norm `‖μ‖²_h = Σ_T h_T² ‖μ‖²_T`, the smallest two (√ of them are the
/// inf-sup constants; the stabilized method has γ ≥ α by construction).
pub fn inf_sup<M: Model>(mesh: &TriangleMesh, alpha: f64) -> Result<[f64; 2]> {
    let data = membranes::SceneData::new(&radial(), None);
    let coefficients = membranes::scene_coefficients::<M>(&data, alpha)?;
    let d: Discretization<TriangleMesh> =
        discretize_on_triangles::<M>(mesh, &coefficients, "B_h", "L_h")?;
    let lcp = &d.lcp;
    let (n, m) = (lcp.n(), lcp.m());
    if m > 4000 {
        return Err(Error::Input(format!(
            "the inf-sup eigenproblem is dense: {m} multipliers is too many"
        )));
    }
    let pattern = lcp
        .a
        .symbolic()
        .to_owned()
        .map_err(|e| Error::LinearSolve(format!("{e:?}")))?;
    let factor = Cholesky::analyse(&pattern)?.factor(&lcp.a)?;
    // columns of A⁻¹Bᵀ, then S = B A⁻¹ Bᵀ + C
    let mut x = DMatrix::<f64>::zeros(n, m);
    for k in 0..m {
        let mut column = vec![0.0; n];
        for &(j, v) in &lcp.b_rows[k] {
            column[j] = v;
        }
        let solved = factor.solve(&column)?;
        x.column_mut(k).copy_from_slice(&solved);
    }
    let mut s = DMatrix::<f64>::zeros(m, m);
    for k in 0..m {
        for l in 0..m {
            s[(k, l)] = lcp.b_rows[k].iter().map(|&(j, v)| v * x[(j, l)]).sum();
        }
        s[(k, k)] += lcp.c[k];
    }
    let weight: Vec<f64> = d
        .multiplier_dofs()
        .iter()
        .map(|&cell| {
            let h = d.mesh.cell_diameter(cell);
            (h * h * d.mesh.area(cell)).sqrt()
        })
        .collect();
    for k in 0..m {
        for l in 0..m {
            s[(k, l)] /= weight[k] * weight[l];
        }
    }
    let s = (&s + s.transpose()) * 0.5;
    let mut values: Vec<f64> = SymmetricEigen::new(s).eigenvalues.iter().cloned().collect();
    values.sort_by(f64::total_cmp);
    Ok([values[0], values.get(1).copied().unwrap_or(f64::NAN)])
}

/// One mesh of the stability study.
#[derive(Clone, Debug)]
pub struct StabilityRow {
    /// Pair name.
    pub pair: &'static str,
    /// N.
    pub n: usize,
    /// α of the stabilized method.
    pub alpha: f64,
    /// Smallest two γ of the plain pair (α = 0).
    pub plain: [f64; 2],
    /// Smallest two γ of the stabilized pair.
    pub stabilized: [f64; 2],
}

/// The inf-sup study on N×N×2 meshes for P1–P0 and P2–P0.
pub fn stability(sizes: &[usize]) -> Result<Vec<StabilityRow>> {
    let mut rows = Vec::new();
    for &n in sizes {
        let mesh = TriangleMesh::rectangle(-2.0, 2.0, -2.0, 2.0, n, n, Diagonal::Right)?;
        for pair in [MembranePair::P1P0, MembranePair::P2P0] {
            let mut request = MembraneRequest::new(radial());
            request.pair = pair;
            let (alpha, _) = alpha_of(&request, &mesh)?;
            let (plain, stabilized) = match pair {
                MembranePair::P1P0 => (
                    inf_sup::<membrane_p1_p0::Model>(&mesh, 0.0)?,
                    inf_sup::<membrane_p1_p0::Model>(&mesh, alpha)?,
                ),
                _ => (
                    inf_sup::<membrane_p2_p0::Model>(&mesh, 0.0)?,
                    inf_sup::<membrane_p2_p0::Model>(&mesh, alpha)?,
                ),
            };
            rows.push(StabilityRow {
                pair: pair.name(),
                n,
                alpha,
                plain,
                stabilized,
            });
        }
    }
    Ok(rows)
}

/// `(x, λ_h)` at the centroids of the cells in the band `0 < y < 4/N` (the row of
/// cells just above the x axis) of a solve.
pub fn multiplier_profile(
    pair: MembranePair,
    n: usize,
    alpha: Option<f64>,
) -> Result<Vec<(f64, f64)>> {
    let mut request = MembraneRequest::new(radial());
    request.pair = pair;
    request.mesh_size = n;
    request.alpha = alpha;
    let (_, fields) = membranes::solve(&request)?;
    let band = 4.0 / n as f64;
    let mut points: Vec<(f64, f64)> = (0..fields.mesh.cell_count())
        .filter_map(|c| {
            let x = fields.mesh.cell_coordinates(c);
            let (cx, cy) = ((x[0] + x[2] + x[4]) / 3.0, (x[1] + x[3] + x[5]) / 3.0);
            (cy > 0.0 && cy < band).then_some((cx, fields.lambda[c]))
        })
        .collect();
    points.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(points)
}

/// Total variation of a profile's values (an oscillation measure).
pub fn total_variation(profile: &[(f64, f64)]) -> f64 {
    profile.windows(2).map(|w| (w[1].1 - w[0].1).abs()).sum()
}

fn run_stability(full: bool, out: &Path) -> Result<()> {
    let sizes: Vec<usize> = if full {
        vec![2, 4, 6, 8, 12, 16, 20, 24]
    } else {
        vec![2, 4, 6, 8, 12, 16]
    };
    let rows = stability(&sizes)?;
    println!("membrane-radial: smallest eigenvalues γ of M_h⁻¹(B A⁻¹ Bᵀ + C), h-weighted norm (inf-sup constant = √γ)");
    println!(
        "{:<6} {:>4} {:>9} {:>12} {:>12} {:>12} {:>12}",
        "pair", "N", "α", "plain γ₁", "plain γ₂", "stab. γ₁", "stab. γ₂"
    );
    let mut csv = Vec::new();
    let mut series = Vec::new();
    for pair in ["p1-p0", "p2-p0"] {
        let pr: Vec<&StabilityRow> = rows.iter().filter(|r| r.pair == pair).collect();
        for r in &pr {
            println!(
                "{:<6} {:>4} {:>9.2e} {:>12.3e} {:>12.3e} {:>12.3e} {:>12.3e}",
                r.pair, r.n, r.alpha, r.plain[0], r.plain[1], r.stabilized[0], r.stabilized[1]
            );
            csv.push(vec![
                f64::from(u8::from(pair == "p2-p0")),
                r.n as f64,
                r.alpha,
                r.plain[0],
                r.plain[1],
                r.stabilized[0],
                r.stabilized[1],
            ]);
        }
        let h = |r: &&StabilityRow| 4.0 * 2f64.sqrt() / r.n as f64;
        // √γ, with the numerically zero ones (a kernel) drawn at 1e-8
        let floor = |g: f64| g.max(1e-16).sqrt();
        series.push(Series::marked(
            format!("{pair} plain"),
            pr.iter().map(|r| (h(r), floor(r.plain[0]))).collect(),
        ));
        if pair == "p2-p0" {
            series.push(Series::marked(
                format!("{pair} plain, 2nd (past the checkerboard)"),
                pr.iter().map(|r| (h(r), floor(r.plain[1]))).collect(),
            ));
        }
        series.push(Series::marked(
            format!("{pair} stabilized"),
            pr.iter().map(|r| (h(r), floor(r.stabilized[0]))).collect(),
        ));
    }
    let n = if full { 64 } else { 32 };
    let plain = multiplier_profile(MembranePair::P2P0, n, Some(0.0))?;
    let stabilized = multiplier_profile(MembranePair::P2P0, n, None)?;
    let exact: Vec<(f64, f64)> = (0..=400)
        .map(|i| {
            let x = -1.0 + 2.0 * i as f64 / 400.0;
            (
                x,
                crate::models::membrane_scenes::radial_multiplier(&[x, 0.0]),
            )
        })
        .collect();
    println!(
        "λ_h along y ≈ 0 (N = {n}, P2–P0): total variation plain {:.3e}, stabilized {:.3e}, exact {:.3e}",
        total_variation(&plain),
        total_variation(&stabilized),
        total_variation(&exact)
    );
    let window = |p: Vec<(f64, f64)>| -> Vec<(f64, f64)> {
        p.into_iter().filter(|(x, _)| x.abs() <= 1.0).collect()
    };
    plot::stacked(
        &out.join("membrane-radial-stability.svg"),
        &[
            (
                "discrete inf-sup constant √γ₁ (h-weighted norm); plain pairs have a kernel".into(),
                Axes {
                    x: "h",
                    y: "√γ",
                    log_x: true,
                    log_y: true,
                },
                series,
            ),
            (
                format!("λ_h along y ≈ 0, P2–P0, N = {n}: plain (α = 0) oscillates, stabilized does not"),
                Axes {
                    x: "x",
                    y: "λ_h",
                    log_x: false,
                    log_y: false,
                },
                vec![
                    Series::marked("plain α = 0", window(plain)),
                    Series::marked("stabilized α = ½/C_I", window(stabilized)),
                    Series::line("exact λ", exact),
                ],
            ),
        ],
    )
    .map_err(io)?;
    write_csv(
        &out.join("membrane-radial-stability.csv"),
        "pair_is_p2,N,alpha,plain_gamma1,plain_gamma2,stabilized_gamma1,stabilized_gamma2",
        &csv,
    )
    .map_err(io)
}

/// One α of the α study: errors, or the failure.
#[derive(Clone, Debug)]
pub struct AlphaRow {
    /// α.
    pub alpha: f64,
    /// The report, or why the solve failed.
    pub result: std::result::Result<MembraneReport, String>,
}

/// P2–P0 on N×N×2 for every α in `alphas`; also returns `C_I`.
pub fn alpha_sweep(n: usize, alphas: &[f64]) -> Result<(Vec<AlphaRow>, f64)> {
    let mesh = scene_mesh(&radial(), n, Diagonal::Right)?;
    let c_i = membranes::inverse_constant::<membrane_p2_p0::Model>(&mesh)?;
    let rows = alphas
        .iter()
        .map(|&alpha| AlphaRow {
            alpha,
            result: radial_report(MembranePair::P2P0, n, Some(alpha)).map_err(|e| e.to_string()),
        })
        .collect();
    Ok((rows, c_i))
}

fn run_alpha(full: bool, out: &Path) -> Result<()> {
    let n = if full { 64 } else { 32 };
    let alphas: Vec<f64> = (0..=24)
        .map(|k| 10f64.powf(-6.0 + 0.2 * k as f64))
        .chain([0.0])
        .collect();
    let (rows, c_i) = alpha_sweep(n, &alphas)?;
    println!(
        "membrane-radial, P2–P0, N = {n}: error against α (C_I = {c_i:.1}, 1/C_I = {:.3e}, default ½/C_I = {:.3e})",
        1.0 / c_i,
        0.5 / c_i
    );
    println!(
        "{:>10} {:>7} {:>10} {:>10} {:>10} {:>10}  note",
        "α", "α·C_I", "L2", "H1", "h·λ", "|∫λ−2πA|"
    );
    let mut csv = Vec::new();
    let mut series = [Vec::new(), Vec::new(), Vec::new()];
    for row in &rows {
        match &row.result {
            Ok(r) => {
                let force = (r.total_contact_force - r.exact_contact_force.unwrap_or(0.0)).abs();
                let (l2, h1, lm) = (
                    r.error_l2.unwrap_or(f64::NAN),
                    r.error_h1.unwrap_or(f64::NAN),
                    r.error_multiplier.unwrap_or(f64::NAN),
                );
                println!(
                    "{:>10.3e} {:>7.3} {:>10.3e} {:>10.3e} {:>10.3e} {:>10.3e}  {}",
                    row.alpha,
                    row.alpha * c_i,
                    l2,
                    h1,
                    lm,
                    force,
                    r.warnings.join("; ")
                );
                csv.push(vec![row.alpha, row.alpha * c_i, l2, h1, lm, force, 1.0]);
                if row.alpha > 0.0 {
                    series[0].push((row.alpha, h1));
                    series[1].push((row.alpha, lm));
                    series[2].push((row.alpha, force));
                }
            }
            Err(e) => {
                println!(
                    "{:>10.3e} {:>7.3} {:>10} {:>10} {:>10} {:>10}  failed: {}",
                    row.alpha,
                    row.alpha * c_i,
                    "-",
                    "-",
                    "-",
                    "-",
                    e.chars().take(90).collect::<String>()
                );
                csv.push(vec![
                    row.alpha,
                    row.alpha * c_i,
                    f64::NAN,
                    f64::NAN,
                    f64::NAN,
                    f64::NAN,
                    0.0,
                ]);
            }
        }
    }
    let all = series
        .iter()
        .flatten()
        .map(|p| p.1)
        .filter(|v| v.is_finite());
    let (low, high) = all.fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)));
    let marker = |a: f64| vec![(a, low.max(1e-12)), (a, high)];
    let failed: Vec<(f64, f64)> = rows
        .iter()
        .filter(|r| r.result.is_err() && r.alpha > 0.0)
        .map(|r| (r.alpha, high))
        .collect();
    plot::chart(
        &out.join("membrane-radial-alpha.svg"),
        &format!("membrane-radial, P2–P0, N = {n}: errors against α (breaks down at α ≥ 1/C_I)"),
        Axes {
            x: "α",
            y: "error",
            log_x: true,
            log_y: true,
        },
        &[
            Series::marked("|u − u_h|_H1", series[0].clone()),
            Series::marked("h-weighted ‖λ − λ_h‖", series[1].clone()),
            Series::marked("|∫λ_h − 2πA|", series[2].clone()),
            Series::line(format!("1/C_I = {:.2e}", 1.0 / c_i), marker(1.0 / c_i)),
            Series::line(
                format!("default ½/C_I = {:.2e}", 0.5 / c_i),
                marker(0.5 / c_i),
            ),
            Series::marked("failed: A_α indefinite (drawn at the top)", failed),
        ],
    )
    .map_err(io)?;
    write_csv(
        &out.join("membrane-radial-alpha.csv"),
        "alpha,alpha_times_CI,error_l2,error_h1,error_multiplier_h_weighted,error_total_force,solved",
        &csv,
    )
    .map_err(io)
}

/// Runs a membrane study on `membrane-radial`, prints its table, writes its chart and CSV.
pub fn run(study: MembraneStudy, full: bool, out: &Path) -> Result<()> {
    match study {
        MembraneStudy::Convergence => run_convergence(full, out),
        MembraneStudy::Stability => run_stability(full, out),
        MembraneStudy::Alpha => run_alpha(full, out),
    }?;
    println!(
        "→ {}/membrane-radial-{}.svg, .csv",
        out.display(),
        study.name()
    );
    Ok(())
}
