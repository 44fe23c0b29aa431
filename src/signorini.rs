//! The Signorini contact scenes (docs/contact.md, issue 14; docs/contact.md): an elastic
//! body on a rigid foundation, frictionless, the contact pressure a P0 multiplier on the
//! edges of the potential contact boundary, stabilized (`α = 1/(2 max_E C_I,E)` by
//! default). `signorini-patch` checks λ_h = q; `hertz` compares the pressure with
//! Hertz's (half-width, peak, relative L² error against the best P0 fit) and hosts
//! the `convergence` and `alpha` studies. The pairs `p1-p1`, `p2-p1` take a continuous
//! P1 multiplier on Γ_C instead (one pressure per vertex of its edges).

use crate::models::contact_scenes::{solve_gap_block, ContactBody, ContactScene};
use crate::models::signorini::{
    solve_hertz_with, solve_signorini_with, Displacement, Hertz, Multiplier, SignoriniInput,
};
use crate::plot::{self, Axes, Series};
use fem_runtime::{Diagonal, Error, Result, TriangleMesh};
use serde::Serialize;
use std::path::Path;

/// The largest `--mesh-size`: N of the block's N×N×2 mesh (2N×N on the scene's 2:1
/// block), `b/h` of Hertz's graded mesh.
pub const MAX_CONTACT_MESH_SIZE: usize = 512;

/// The contact half-widths `b/R` the curved scenes accept (`--load`): Hertz's theory
/// wants b ≪ R (at b/R = 0.34 the peak was 2 % low, at 3.4 the error 91 %), and below
/// about 1e-7 the gap `x²/2R` is lost against the rounding of coordinates of size R
/// (P = 1e-11 had 10× the best fit's error).
pub const HERTZ_HALF_WIDTH_RANGE: (f64, f64) = (1e-6, 0.1);

/// The largest `--mesh-size` of the P2 pairs (a p2-p0 at 512 ran out of 8 GB in
/// the assembly).
pub const MAX_P2_CONTACT_MESH_SIZE: usize = 256;

/// An element pair of the contact scenes: displacement, multiplier.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContactPair {
    /// `u ∈ [P1]²`, λ P0 on the edges of Γ_C.
    P1P0,
    /// `u ∈ [P2]²`, λ P0 on the edges of Γ_C.
    P2P0,
    /// `u ∈ [P1]²`, λ continuous P1 on Γ_C (one value per vertex of its edges).
    P1P1,
    /// `u ∈ [P2]²`, λ continuous P1 on Γ_C.
    P2P1,
}

impl ContactPair {
    /// The P0-multiplier pairs, which every contact scene takes, the default first.
    pub const ALL: [ContactPair; 2] = [ContactPair::P1P0, ContactPair::P2P0];

    /// Every pair (`--pair`): [`ContactPair::ALL`] and the continuous-P1-multiplier pairs
    /// of the block and the cylinder.
    pub const EVERY: [ContactPair; 4] = [
        ContactPair::P1P0,
        ContactPair::P2P0,
        ContactPair::P1P1,
        ContactPair::P2P1,
    ];

    /// The pair's name (`--pair`).
    pub fn name(self) -> &'static str {
        match self {
            ContactPair::P1P0 => "p1-p0",
            ContactPair::P2P0 => "p2-p0",
            ContactPair::P1P1 => "p1-p1",
            ContactPair::P2P1 => "p2-p1",
        }
    }

    /// The pair called `name`.
    ///
    /// # Errors
    /// [`Error::Input`] listing the pairs for another name.
    pub fn parse(name: &str) -> Result<Self> {
        Self::EVERY
            .into_iter()
            .find(|p| p.name() == name)
            .ok_or_else(|| {
                Error::Input(format!(
                    "unknown contact pair `{name}` (p1-p0, p2-p0, p1-p1, p2-p1)"
                ))
            })
    }

    /// The pair's displacement element.
    pub fn displacement(self) -> Displacement {
        match self {
            ContactPair::P1P0 | ContactPair::P1P1 => Displacement::P1,
            ContactPair::P2P0 | ContactPair::P2P1 => Displacement::P2,
        }
    }

    /// The pair's multiplier space on Γ_C.
    pub fn multiplier(self) -> Multiplier {
        match self {
            ContactPair::P1P0 | ContactPair::P2P0 => Multiplier::P0,
            ContactPair::P1P1 | ContactPair::P2P1 => Multiplier::P1,
        }
    }
}

/// One contact solve: the scene and what the command line may change.
#[derive(Clone, Copy, Debug)]
pub struct ContactRequest {
    /// The scene.
    pub scene: ContactScene,
    /// The pair.
    pub pair: ContactPair,
    /// N of the block's mesh, or the cylinder's `b/h`.
    pub mesh_size: usize,
    /// The block's top pressure q, or the cylinder's resultant P.
    pub load: f64,
    /// α; `None`: `1/(2 max_E C_I,E)`; `Some(0)`: the plain mixed method (a QP).
    pub alpha: Option<f64>,
}

impl ContactRequest {
    /// The scene's defaults with P1–P0.
    pub fn new(scene: ContactScene) -> Self {
        Self {
            scene,
            pair: ContactPair::P1P0,
            mesh_size: scene.mesh_size,
            load: scene.load,
            alpha: None,
        }
    }

    /// Checks the request.
    ///
    /// # Errors
    /// [`Error::Input`] naming the value at fault: a mesh size outside
    /// `1..=`[`MAX_CONTACT_MESH_SIZE`], a load that is not positive and finite (a
    /// negative one pulls the body off the foundation, where nothing holds it).
    pub fn validate(&self) -> Result<()> {
        if self.mesh_size == 0 || self.mesh_size > MAX_CONTACT_MESH_SIZE {
            return Err(Error::Input(format!(
                "mesh size {} must lie in 1..={MAX_CONTACT_MESH_SIZE}",
                self.mesh_size
            )));
        }
        if self.pair.displacement() == Displacement::P2 && self.mesh_size > MAX_P2_CONTACT_MESH_SIZE
        {
            return Err(Error::Input(format!(
                "mesh size {} with the P2 pair `{}`: at most {MAX_P2_CONTACT_MESH_SIZE} (signorini-patch at 256 took 4.8 GB; 512 needs about four times that)",
                self.mesh_size,
                self.pair.name()
            )));
        }
        if self.load.is_nan() {
            return Err(Error::Input("--load NaN is not a number".into()));
        }
        if self.load <= 0.0 {
            return Err(Error::Input(format!(
                "--load {} must be positive: the body only rests on the foundation, a pull lifts it off and nothing holds it then",
                crate::number(self.load)
            )));
        }
        if !(self.load.is_finite() && self.load <= 1e100) {
            return Err(Error::Input(format!(
                "--load {} is too large to compute with (at most 1e100)",
                crate::number(self.load)
            )));
        }
        // Hertz's theory, the reference of the curved scenes, holds for b ≪ R; at
        // b/R ~ 1e-7 the gap x²/2R drowns in the rounding of coordinates of size R.
        if let Some(hertz) = self.scene.hertz(self.load) {
            let ratio = hertz.half_width() / hertz.radius;
            if !(HERTZ_HALF_WIDTH_RANGE.0..=HERTZ_HALF_WIDTH_RANGE.1).contains(&ratio) {
                let at = |r: f64| self.load * (r / ratio).powi(2);
                return Err(Error::Input(format!(
                    "--load {} gives a contact half-width b = {:.3e} R; `{}` compares with Hertz's theory, which needs b ≪ R, and the mesh resolves b only while the gap b²/2R is well above the rounding of R: loads from {} to {} keep {:e} ≤ b/R ≤ {}",
                    crate::number(self.load),
                    ratio,
                    self.scene.name,
                    format_args!("{:.3e}", at(HERTZ_HALF_WIDTH_RANGE.0)),
                    format_args!("{:.3e}", at(HERTZ_HALF_WIDTH_RANGE.1)),
                    HERTZ_HALF_WIDTH_RANGE.0,
                    HERTZ_HALF_WIDTH_RANGE.1
                )));
            }
        }
        Ok(())
    }
}

/// What a contact solve reports (`--json`).
#[derive(Clone, Debug, Serialize)]
pub struct ContactReport {
    /// Scene name.
    pub scene: String,
    /// Pair name.
    pub pair: &'static str,
    /// N (block) or b/h (cylinder).
    pub mesh_size: usize,
    /// q (block) or P (cylinder).
    pub load: f64,
    /// The stabilization parameter used.
    pub alpha: f64,
    /// `max_E C_I,E` over the contact edges, from the model's kernels.
    pub inverse_constant: f64,
    /// Unknowns of the LCP (free displacements and contact pressures).
    pub dofs: usize,
    /// Edges of Γ_C (one pressure each for P0).
    pub contact_edges: usize,
    /// Pressure unknowns: one per edge of Γ_C (P0) or per vertex of its edges (P1).
    pub multiplier_dofs: usize,
    /// Solver iterations (semismooth Newton; the QP's for α = 0).
    pub iterations: usize,
    /// Wall time of the solve, seconds.
    pub seconds: f64,
    /// The vertical force of the foundation on the body (the whole cylinder: twice the
    /// symmetric half's), force per unit length.
    pub total_contact_force: f64,
    /// The applied vertical load, likewise (the pressure integrated by 4-point
    /// Gauss–Legendre per edge).
    pub applied_load: f64,
    /// The applied load as the discretization integrates it (the model's quadrature of
    /// the pressure, `models::signorini::SignoriniSolution::discretized_load`): what the
    /// contact force balances. It differs from `applied_load` only for a pressure that
    /// varies within an edge faster than that quadrature resolves. NaN (null in JSON)
    /// for a scene file whose supports hold the body along n_c.
    pub discretized_load: f64,
    /// `|total_contact_force − discretized_load| / discretized_load` (a scene file's: over
    /// the larger of that and `∫|q| ds`, so that a pressure whose resultant is a small
    /// share of its size is not judged by the rounding of the rest): 0 to solver
    /// precision (a rigid translation lies in V_h, so equilibrium is exact); NaN (null in
    /// JSON) for a scene file whose supports act along n_c and carry part of the load.
    pub equilibrium_residual: f64,
    /// Half the extent along x of the edges carrying pressure (their far ends; the
    /// cylinder from its axis, `models::signorini::SignoriniSolution`).
    pub contact_half_width: f64,
    /// The largest contact pressure λ_E.
    pub max_contact_pressure: f64,
    /// Hertz's half-width b (cylinder).
    pub exact_half_width: Option<f64>,
    /// Hertz's peak pressure p_max (cylinder).
    pub exact_max_pressure: Option<f64>,
    /// `‖p − λ_h‖ / ‖p‖` on Γ_C against Hertz's pressure (cylinder).
    pub pressure_l2_error: Option<f64>,
    /// The same error of the best P0 fit on the same edges (the L² projection of p):
    /// the floor of any P0 multiplier (P0 pairs).
    pub best_p0_l2_error: Option<f64>,
    /// The same error of the best fit in the pair's multiplier space (cylinder): the best
    /// P0 fit, or for P1 pairs the L² projection onto the continuous piecewise linears on
    /// the vertices of Γ_C.
    pub best_fit_l2_error: Option<f64>,
    /// The checkerboard measure `max |λ_{k−1} − 2λ_k + λ_{k+1}| / p_max` inside
    /// `x < 0.8 b` (cylinder; `models::signorini::HertzResult::oscillation`); `None`
    /// where fewer than three pressures lie there.
    pub oscillation: Option<f64>,
    /// `max_k |λ_k − q| / q` over the pressure unknowns (the block: 0 exactly for a
    /// correct method).
    pub patch_pressure_error: Option<f64>,
    /// The complementarity part of the KKT residual (relative).
    pub complementarity_residual: f64,
    /// The solver's KKT residual.
    pub kkt_residual: f64,
    /// The accuracy the scene states for `pressure_l2_error` (`signorini-gap`), where
    /// it states one.
    pub accuracy: Option<f64>,
    /// Warnings ([`warnings`]): equilibrium missed beyond solver precision, the stated
    /// accuracy not reached, the plain method's solver.
    pub warnings: Vec<String>,
}

/// The equilibrium residual beyond which a report warns: Newton meets it to about
/// 1e-13, the polished interior point (α = 0) to about 1e-12.
pub const EQUILIBRIUM_WARNING: f64 = 1e-8;

/// The relative difference between the load as discretized and as integrated by 4-point
/// Gauss beyond which a report warns: a pressure the model's quadrature does not
/// integrate (a kink inside an edge: 7e-2 on the 2 × 1 block with q = max(0, x − 1.9)).
/// A smooth pressure differs by far less (1e-7 for 1 + 0.1 sin x at h = 0.25), below the
/// discretization error of λ_h, and is not worth a word.
pub const QUADRATURE_WARNING: f64 = 1e-6;

/// The warnings of a contact report: what its own checks say about it.
pub fn warnings(r: &ContactReport) -> Vec<String> {
    let mut out = Vec::new();
    // NaN: not measured (supports carry load along n_c)
    if r.equilibrium_residual > EQUILIBRIUM_WARNING {
        out.push(format!(
            "the contact force misses the load as discretized by {:.1e} (relative; a rigid translation lies in V_h, so it should be rounding): the solve did not reach solver precision, or the data's scales (a gap far beyond the elastic displacement) leave the displacement too few digits",
            r.equilibrium_residual
        ));
    }
    // NaN (supports hold n_c): the load is not all the contact force's to balance
    let quadrature = (r.discretized_load - r.applied_load).abs() / r.applied_load.abs();
    if quadrature > QUADRATURE_WARNING {
        out.push(format!(
            "the model integrates the pressure on Γ_N with a rule exact for pressures up to quadratic along an edge: this pressure's resultant comes out {:.6e} against {:.6e} by 4-point Gauss per edge ({quadrature:.1e} relative), and the contact force balances the former; refine the mesh for a pressure that varies within an edge",
            r.discretized_load, r.applied_load
        ));
    }
    if let (Some(accuracy), Some(error)) = (r.accuracy, r.pressure_l2_error) {
        if error > accuracy {
            out.push(format!(
                "the pressure's relative L² error {error:.3e} exceeds the accuracy the scene states, {accuracy}: refine (--mesh-size)"
            ));
        }
    }
    if r.alpha == 0.0 {
        out.push(
            "α = 0: the plain mixed method, solved by clarabel's interior point and polished on its active set (unstable pairs oscillate)".into(),
        );
    }
    out
}

/// The contact pressure along x (scene files: along the contact plane, the coordinate of
/// `contact_tangent`), sorted by x0: per edge `(x0, x1, λ_E)` (P0 pairs), or
/// per vertex of Γ_C `(x, x, λ_k)` (P1 pairs: λ_h is linear between consecutive
/// entries, and the chart joins them so).
pub type PressureProfile = Vec<(f64, f64, f64)>;

/// Solves `request`.
///
/// # Errors
/// [`Error::Input`] for an invalid request or scene (E ≤ 0, ν outside (−1, ½), α < 0);
/// the mesh generator's and the solver's errors.
pub fn solve(request: &ContactRequest) -> Result<(ContactReport, PressureProfile)> {
    request.validate()?;
    let s = &request.scene;
    let q = request.load;
    let n = request.mesh_size;
    let element = request.pair.displacement();
    let multiplier = request.pair.multiplier();
    let (solution, hertz, errors) = match s.body {
        ContactBody::Block { width, height } => {
            let nx = ((width / height).round() as usize).max(1) * n;
            let mesh = TriangleMesh::rectangle(0.0, width, 0.0, height, nx, n, Diagonal::Right)?;
            let pressure = move |_: &[f64]| q;
            let no_gap = |_: &[f64]| 0.0;
            // contact at the bottom (marker 1), the load on the top (3), a roller on
            // the left side (4) against the rigid translation along x
            let input = SignoriniInput {
                young: s.young,
                poisson: s.poisson,
                plane: s.plane,
                element,
                contact: &[1],
                load: &[3],
                pressure: &pressure,
                gap: &no_gap,
                contact_direction: [0.0, -1.0],
                fixed_x: &[4],
                fixed_y: &[],
                rollers: &[],
                alpha: request.alpha,
                contact_centre: None,
            };
            (solve_signorini_with(&mesh, &input, multiplier)?, None, None)
        }
        ContactBody::Cylinder { radius } => {
            let hertz = Hertz {
                radius,
                young: s.young,
                poisson: s.poisson,
                load: q,
            };
            let r = solve_hertz_with(hertz, n as f64, element, multiplier, request.alpha)?;
            (
                r.solution,
                Some(hertz),
                Some([r.pressure_l2_error, r.best_fit_l2_error, r.oscillation]),
            )
        }
        ContactBody::GapBlock { .. } => {
            if multiplier != Multiplier::P0 {
                return Err(Error::Input(format!(
                    "pair `{}`: the scene `{}` takes the P0-multiplier pairs p1-p0, p2-p0",
                    request.pair.name(),
                    s.name
                )));
            }
            let r = solve_gap_block(s, q, n as f64, element, request.alpha)?;
            let oscillation = crate::models::signorini::checkerboard(&r.solution, &r.hertz);
            (
                r.solution,
                Some(r.hertz),
                Some([r.pressure_l2_error, r.best_fit_l2_error, oscillation]),
            )
        }
    };
    // the cylinder is solved on its symmetric half
    let factor = if hertz.is_some() { 2.0 } else { 1.0 };
    let largest = solution.max_contact_pressure;
    let mut profile: PressureProfile = match multiplier {
        Multiplier::P0 => solution
            .contact_edges
            .iter()
            .zip(&solution.pressure)
            .map(|(e, &p)| {
                let (a, b) = (e.ends[0][0], e.ends[1][0]);
                (a.min(b), a.max(b), p)
            })
            .collect(),
        Multiplier::P1 => solution
            .pressure_profile()
            .into_iter()
            .map(|(x, p)| (x, x, p))
            .collect(),
    };
    profile.sort_by(|a, b| a.0.total_cmp(&b.0));
    let total = factor * solution.total_contact_force[1];
    let applied = -factor * solution.applied_load[1];
    let discretized = factor * solution.discretized_load;
    let report = ContactReport {
        scene: s.name.to_string(),
        pair: request.pair.name(),
        mesh_size: n,
        load: q,
        alpha: solution.alpha,
        inverse_constant: solution
            .inverse_constants
            .iter()
            .fold(0.0f64, |m, &c| m.max(c)),
        dofs: solution.dofs,
        contact_edges: solution.contact_edges.len(),
        multiplier_dofs: solution.pressure.len(),
        iterations: solution.iterations,
        seconds: solution.seconds,
        total_contact_force: total,
        applied_load: applied,
        discretized_load: discretized,
        equilibrium_residual: (total - discretized).abs() / discretized.abs(),
        contact_half_width: solution.contact_half_width,
        max_contact_pressure: largest,
        exact_half_width: hertz.map(|h| h.half_width()),
        exact_max_pressure: hertz.map(|h| h.max_pressure()),
        pressure_l2_error: errors.map(|e| e[0]),
        best_p0_l2_error: errors
            .filter(|_| multiplier == Multiplier::P0)
            .map(|e| e[1]),
        best_fit_l2_error: errors.map(|e| e[1]),
        // a second difference needs three pressures inside 0.8 b (b/h = 1, 2 have
        // fewer: nothing measured, not 0)
        oscillation: errors.map(|e| e[2]).filter(|_| {
            hertz.is_some_and(|h| {
                profile
                    .iter()
                    .filter(|p| p.1.abs() < 0.8 * h.half_width())
                    .count()
                    >= 3
            })
        }),
        patch_pressure_error: hertz.is_none().then(|| {
            solution
                .pressure
                .iter()
                .fold(0.0f64, |m, &p| m.max((p - q).abs() / q))
        }),
        complementarity_residual: solution.complementarity_residual,
        kkt_residual: solution.kkt_residual,
        accuracy: s.accuracy(),
        warnings: Vec::new(),
    };
    let report = ContactReport {
        warnings: warnings(&report),
        ..report
    };
    Ok((report, profile))
}

/// One line for a report (`solve` without `--json`).
pub fn summary(r: &ContactReport) -> String {
    let mut line = format!(
        "{} {} mesh size {}: α {:.3e}, {} dofs, {} contact edges, total contact force {:.9e} (load {:.9e}, {}), contact half-width {:.6e}, max pressure {:.6e}",
        r.scene,
        r.pair,
        r.mesh_size,
        r.alpha,
        r.dofs,
        r.contact_edges,
        r.total_contact_force,
        r.applied_load,
        // NaN where supports along the contact direction carry part of the load (JSON
        // null): "equilibrium residual NaN" reads as a failure
        if r.equilibrium_residual.is_nan() {
            "no equilibrium check: supports along the contact direction carry part of the load".to_string()
        } else {
            format!("equilibrium residual {:.1e}", r.equilibrium_residual)
        },
        r.contact_half_width,
        r.max_contact_pressure
    );
    if let (Some(b), Some(p), Some(e), Some(best)) = (
        r.exact_half_width,
        r.exact_max_pressure,
        r.pressure_l2_error,
        r.best_fit_l2_error,
    ) {
        let space = if r.best_p0_l2_error.is_some() {
            "P0"
        } else {
            "P1"
        };
        line += &format!(
            " (Hertz b {b:.6e}, p_max {p:.6e}); pressure L² error {e:.3e} (best {space} fit {best:.3e}, ratio {:.2})",
            e / best
        );
    }
    if let Some(e) = r.patch_pressure_error {
        line += &format!("; max |λ_h − q|/q {e:.1e}");
    }
    if let (Some(a), Some(e)) = (r.accuracy, r.pressure_l2_error) {
        line += &format!(
            "; stated accuracy {a:.1e}: {}",
            if e <= a { "reached" } else { "NOT reached" }
        );
    }
    line += &format!(
        ", {} iterations, complementarity {:.1e}, {:.3} s",
        r.iterations, r.complementarity_residual, r.seconds
    );
    for w in &r.warnings {
        line += &format!("\n  warning: {w}");
    }
    line
}

/// The pressure profile as a step curve for a chart (P1 pairs' vertex entries `x0 = x1`
/// give the piecewise-linear curve through the vertex values).
fn steps(profile: &PressureProfile) -> Vec<(f64, f64)> {
    profile
        .iter()
        .flat_map(|&(x0, x1, p)| [(x0, p), (x1, p)])
        .collect()
}

/// Writes `out/<scene>-pressure.svg`: λ_h against Hertz's p(x) over `0 ≤ x ≤ 1.5 b`.
///
/// # Errors
/// [`Error::Input`] for a scene without a Hertz reference; I/O errors.
pub fn pressure_chart(
    out: &Path,
    report: &ContactReport,
    curves: &[(String, &PressureProfile)],
    hertz: &Hertz,
) -> Result<std::path::PathBuf> {
    std::fs::create_dir_all(out).map_err(crate::studies::io)?;
    let b = hertz.half_width();
    let path = out.join(format!("{}-pressure.svg", report.scene));
    let exact: Vec<(f64, f64)> = (0..=300)
        .map(|i| {
            let x = 1.5 * b * i as f64 / 300.0;
            (x, hertz.pressure(x))
        })
        .collect();
    let mut series = vec![Series::line("Hertz p(x)", exact)];
    for (name, profile) in curves {
        let clipped: PressureProfile = profile.iter().copied().filter(|e| e.0 <= 1.5 * b).collect();
        series.push(Series::line(name.clone(), steps(&clipped)));
    }
    plot::chart(
        &path,
        &format!(
            "{}: contact pressure, b/h = {}",
            report.scene, report.mesh_size
        ),
        Axes {
            x: "x",
            y: "pressure",
            ..Axes::default()
        },
        &series,
    )
    .map_err(crate::studies::io)?;
    Ok(path)
}

/// The `alpha` study of a Hertz scene: α·max C_I from 0 (the plain method) to 2.5 at
/// one b/h, the pressure error and its oscillation (the second difference of
/// neighbouring edges' pressures relative to p_max, inside the contact zone), and the
/// chart of the plain, the automatic and a too-large α against Hertz.
///
/// # Errors
/// As [`solve`]; I/O errors.
pub fn alpha_study(scene: ContactScene, b_over_h: usize, out: &Path) -> Result<()> {
    let mut request = ContactRequest::new(scene);
    request.mesh_size = b_over_h;
    let (auto, auto_profile) = solve(&request)?;
    let hertz = scene
        .hertz(request.load)
        .ok_or_else(|| Error::Input(format!("`{}` has no Hertz reference", scene.name)))?;
    let c_i = auto.inverse_constant;
    println!(
        "\nalpha: {}, b/h = {b_over_h}, α·max C_I (automatic: 0.5), relative L² error of the pressure and its oscillation",
        scene.name
    );
    println!(
        "{:>8} {:>11} {:>10} {:>10} {:>11} {:>6}",
        "α·C_I", "α", "L² error", "best P0", "oscillation", "iter"
    );
    let mut csv = String::from("alpha_c_i,alpha,l2_error,best_p0,oscillation,iterations\n");
    let mut profiles = Vec::new();
    let (mut largest, mut worked) = (None, Vec::new());
    for fraction in [0.0, 0.01, 0.1, 0.25, 0.5, 1.0, 1.5, 1.9, 2.5] {
        request.alpha = Some(fraction / c_i);
        match solve(&request) {
            Ok((r, profile)) => {
                let oscillation = r.oscillation.unwrap_or(f64::NAN);
                let e = r.pressure_l2_error.unwrap_or(f64::NAN);
                let best = r.best_p0_l2_error.unwrap_or(f64::NAN);
                println!(
                    "{fraction:>8} {:>11.3e} {e:>10.3e} {best:>10.3e} {oscillation:>11.3e} {:>6}",
                    r.alpha, r.iterations
                );
                csv += &format!(
                    "{fraction},{:e},{e:e},{best:e},{oscillation:e},{}\n",
                    r.alpha, r.iterations
                );
                if fraction == 0.0 {
                    profiles.push((format!("plain, α·C_I = {fraction}"), profile));
                } else {
                    worked.push(fraction);
                    if fraction > 0.5 {
                        largest =
                            Some((format!("largest that solves, α·C_I = {fraction}"), profile));
                    }
                }
            }
            Err(e) => {
                println!("{fraction:>8} {:>11.3e} failed: {e}", fraction / c_i);
                csv += &format!("{fraction},{:e},,,,\n", fraction / c_i);
            }
        }
    }
    if let (Some(low), Some(high)) = (worked.first(), worked.last()) {
        println!(
            "solved for α·C_I from {low} to {high} of these; the automatic α·C_I = ½ stays a factor 2–4 below where A_α turns indefinite (docs/contact.md; 1.0–1.3 on the block patch, 1.5–1.9 here), at the price of some accuracy where a larger α is still stable"
        );
    }
    profiles.extend(largest);
    std::fs::create_dir_all(out).map_err(crate::studies::io)?;
    let csv_path = out.join(format!("{}-alpha.csv", scene.name));
    std::fs::write(&csv_path, csv).map_err(crate::studies::io)?;
    let mut curves: Vec<(String, &PressureProfile)> =
        vec![("automatic α·C_I = 0.5".to_string(), &auto_profile)];
    curves.extend(profiles.iter().map(|(n, p)| (n.clone(), p)));
    let path = pressure_chart(out, &auto, &curves, &hertz)?;
    let target = out.join(format!("{}-alpha.svg", scene.name));
    std::fs::rename(&path, &target).map_err(crate::studies::io)?;
    println!("→ {}, {}", target.display(), csv_path.display());
    Ok(())
}

/// The `convergence` study of a Hertz scene: b/h = 8, 16, 32, 64 (`full`: to 128),
/// half-width, peak and the pressure's L² error against the best fit in the pair's
/// multiplier space (P0 or continuous P1), per pair.
///
/// # Errors
/// As [`solve`]; I/O errors.
pub fn convergence_study(scene: ContactScene, full: bool, out: &Path) -> Result<()> {
    let sizes: &[usize] = if full {
        &[8, 16, 32, 64, 128]
    } else {
        &[8, 16, 32, 64]
    };
    println!(
        "\nconvergence: {}, pressure against Hertz per b/h (relative errors)",
        scene.name
    );
    println!(
        "{:>6} {:>5} {:>8} {:>10} {:>10} {:>10} {:>10} {:>6} {:>8}",
        "pair", "b/h", "dofs", "b error", "p_max err", "L² error", "best fit", "iter", "seconds"
    );
    let mut csv = String::from(
        "pair,b_over_h,dofs,half_width_error,max_pressure_error,l2_error,best_fit,iterations,seconds\n",
    );
    let mut series = Vec::new();
    let (mut best_series, mut best_p1_series) = (Vec::new(), Vec::new());
    // the P1-multiplier pairs on the cylinder only (the gap block takes P0 pairs)
    let pairs: &[ContactPair] = if matches!(scene.body, ContactBody::Cylinder { .. }) {
        &ContactPair::EVERY
    } else {
        &ContactPair::ALL
    };
    for &pair in pairs {
        let mut points = Vec::new();
        for &n in sizes {
            let mut request = ContactRequest::new(scene);
            request.pair = pair;
            request.mesh_size = n;
            let (r, _) = solve(&request)?;
            let b = r.exact_half_width.unwrap_or(f64::NAN);
            let p = r.exact_max_pressure.unwrap_or(f64::NAN);
            let (eb, ep) = (
                (r.contact_half_width - b) / b,
                (r.max_contact_pressure - p) / p,
            );
            let e = r.pressure_l2_error.unwrap_or(f64::NAN);
            let best = r.best_fit_l2_error.unwrap_or(f64::NAN);
            println!(
                "{:>6} {n:>5} {:>8} {eb:>+10.2e} {ep:>+10.2e} {e:>10.3e} {best:>10.3e} {:>6} {:>8.3}",
                pair.name(),
                r.dofs,
                r.iterations,
                r.seconds
            );
            csv += &format!(
                "{},{n},{},{eb:e},{ep:e},{e:e},{best:e},{},{}\n",
                pair.name(),
                r.dofs,
                r.iterations,
                r.seconds
            );
            points.push((n as f64, e));
            if pair == ContactPair::P1P0 {
                best_series.push((n as f64, best));
            }
            if pair == ContactPair::P1P1 {
                best_p1_series.push((n as f64, best));
            }
        }
        series.push(Series::marked(format!("{} λ_h", pair.name()), points));
    }
    series.push(Series::marked("best P0 fit", best_series));
    series.push(Series::marked("best P1 fit", best_p1_series));
    std::fs::create_dir_all(out).map_err(crate::studies::io)?;
    let csv_path = out.join(format!("{}-convergence.csv", scene.name));
    std::fs::write(&csv_path, csv).map_err(crate::studies::io)?;
    let svg = out.join(format!("{}-convergence.svg", scene.name));
    plot::chart(
        &svg,
        &format!("{}: relative L² error of the contact pressure", scene.name),
        Axes {
            x: "b/h",
            y: "‖p − λ_h‖/‖p‖",
            log_x: true,
            log_y: true,
        },
        &series,
    )
    .map_err(crate::studies::io)?;
    println!("→ {}, .csv", svg.display());
    Ok(())
}
