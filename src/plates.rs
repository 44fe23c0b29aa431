//! The plate scenes (docs/mathematics.md §6): a Reissner–Mindlin plate on the N×N×2
//! mesh of its square, solved as an obstacle problem (the obstacle out of reach), with the
//! report of `solve --json`: the centre deflection against the Kirchhoff limit.

use crate::models::mindlin::{mindlin_clamped, mindlin_plain_p1};
use crate::models::plate_scenes::{PlateScene, PlateSupport};
use fem_runtime::element::triangle::TriangleBasis;
use fem_runtime::obstacle::triangle::{solve_obstacle_on_triangles, TriangleObstacleSolution};
use fem_runtime::obstacle::ObstacleOptions;
use fem_runtime::{Coefficients, Diagonal, Error, Model, PointLocator, Result, TriangleMesh};
use serde::Serialize;

/// The Stenberg parameter β of the shear weight `6κ(1−ν)D/(t² + β h_T²)` (§6: β ≤ 0.01
/// brings back coarse-mesh locking, β ≥ 0.3 loses accuracy).
pub const STENBERG_BETA: f64 = 0.1;
/// The default stabilization parameter α (§6: α = 1 is 5–10× less accurate, α ≤ 0.01
/// breaks the solver on fine meshes).
pub const PLATE_ALPHA: f64 = 0.1;
/// The largest N of the N×N×2 mesh a plate solve accepts (memory: about 2 GB at 1024).
pub const MAX_PLATE_MESH_SIZE: usize = 1024;

/// The discretizations of the plate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlatePair {
    /// θ ∈ [P1]², w ∈ P2, λ ∈ P0 with the Stenberg shear weight: locking-free.
    P1P2P0,
    /// θ ∈ [P1]², w ∈ P1, λ ∈ P0 with the physical shear weight: locks as t → 0.
    P1P1P0Plain,
}

impl PlatePair {
    /// Every pair, the default first.
    pub const ALL: [PlatePair; 2] = [PlatePair::P1P2P0, PlatePair::P1P1P0Plain];

    /// The pair's name (`--pair`).
    pub fn name(self) -> &'static str {
        match self {
            PlatePair::P1P2P0 => "p1-p2-p0",
            PlatePair::P1P1P0Plain => "p1-p1-p0-plain",
        }
    }

    /// The pair called `name`.
    ///
    /// # Errors
    /// [`Error::Input`] naming the plate pairs when there is none of that name.
    pub fn parse(name: &str) -> Result<Self> {
        Self::ALL
            .into_iter()
            .find(|p| p.name() == name)
            .ok_or_else(|| {
                Error::Input(format!(
                    "unknown plate pair `{name}`; the plate pairs are {}",
                    Self::ALL.map(Self::name).join(", ")
                ))
            })
    }
}

/// One plate solve: the scene and what the command line may change.
#[derive(Clone, Copy, Debug)]
pub struct PlateRequest {
    /// The scene.
    pub scene: PlateScene,
    /// The pair.
    pub pair: PlatePair,
    /// Thickness t > 0.
    pub thickness: f64,
    /// N of the N×N×2 mesh, 1 ≤ N ≤ [`MAX_PLATE_MESH_SIZE`].
    pub mesh_size: usize,
    /// Uniform load q.
    pub load: f64,
    /// Stabilization parameter α > 0.
    pub alpha: f64,
}

impl PlateRequest {
    /// The scene's defaults: the default pair, its thickness, mesh, load and α.
    pub fn new(scene: PlateScene) -> Self {
        Self {
            scene,
            pair: PlatePair::P1P2P0,
            thickness: scene.thickness,
            mesh_size: scene.mesh_size,
            load: scene.load,
            alpha: PLATE_ALPHA,
        }
    }

    /// Checks the request.
    ///
    /// # Errors
    /// [`Error::Input`] naming the value at fault: t ≤ 0 or t > 1 (the side), ν outside (−1, ½), a mesh size
    /// of 0 or above [`MAX_PLATE_MESH_SIZE`], α ≤ 0, a load or material value that is not
    /// finite (D and κ must be positive).
    pub fn validate(&self) -> Result<()> {
        let s = &self.scene;
        let bad = |what: String| Err(Error::Input(what));
        if !(self.thickness.is_finite() && self.thickness > 0.0) {
            return bad(format!(
                "thickness t = {} must be positive and finite",
                self.thickness
            ));
        }
        if self.thickness > 1.0 {
            return bad(format!(
                "thickness t = {} exceeds the plate's side 1: plate theory describes thin bodies (t well below the side); a thicker body is a problem of elasticity",
                self.thickness
            ));
        }
        if !(s.poisson_ratio > -1.0 && s.poisson_ratio < 0.5) {
            return bad(format!(
                "Poisson's ratio ν = {} must lie in (−1, ½)",
                s.poisson_ratio
            ));
        }
        if !(s.bending_stiffness.is_finite() && s.bending_stiffness > 0.0) {
            return bad(format!(
                "bending stiffness D = {} must be positive and finite",
                s.bending_stiffness
            ));
        }
        if !(s.shear_correction.is_finite() && s.shear_correction > 0.0) {
            return bad(format!(
                "shear correction κ = {} must be positive and finite",
                s.shear_correction
            ));
        }
        if !(s.side.is_finite() && s.side > 0.0) {
            return bad(format!("side a = {} must be positive and finite", s.side));
        }
        if !self.load.is_finite() {
            return bad(format!("load q = {} must be finite", self.load));
        }
        if self.mesh_size == 0 || self.mesh_size > MAX_PLATE_MESH_SIZE {
            return bad(format!(
                "mesh size N = {} must lie in 1..={MAX_PLATE_MESH_SIZE}",
                self.mesh_size
            ));
        }
        if !(self.alpha.is_finite() && self.alpha > 0.0) {
            return bad(format!(
                "α = {} must be positive and finite (α = 0 leaves the multiplier undetermined where there is no contact)",
                self.alpha
            ));
        }
        Ok(())
    }
}

/// The report of a plate solve (`solve --json`).
#[derive(Clone, Debug, Serialize)]
pub struct PlateReport {
    /// Scene name.
    pub scene: String,
    /// Pair name.
    pub pair: &'static str,
    /// Support (`clamped`).
    pub support: &'static str,
    /// Thickness t.
    pub thickness: f64,
    /// N of the N×N×2 mesh.
    pub mesh_size: usize,
    /// Load q.
    pub load: f64,
    /// α.
    pub alpha: f64,
    /// w_h at the centre of the square.
    pub centre_deflection: f64,
    /// The Kirchhoff centre deflection (the limit as t → 0).
    pub kirchhoff_reference: f64,
    /// `(w_h(centre) − w_K)/w_K`: discretization error plus the O(t²) Mindlin–Kirchhoff
    /// difference (about 20 t² for the clamped square).
    pub relative_error: f64,
    /// `J_h = ½UᵀA_hU − FᵀU` with the Stenberg (or, for the plain pair, physical) weight.
    pub energy: f64,
    /// The largest |w_h| over the DOF values of w.
    pub max_deflection: f64,
    /// `∫λ_h` (0: the obstacle is out of reach).
    pub total_contact_force: f64,
    /// KKT residual of the solution.
    pub complementarity_residual: f64,
    /// Number of unknowns (all fields, multiplier included).
    pub dofs: usize,
    /// Newton iterations.
    pub iterations: usize,
    /// Wall time of the solve, assembly included.
    pub seconds: f64,
}

fn zero(_: &[f64]) -> f64 {
    0.0
}

/// Solves `request`.
///
/// # Errors
/// [`PlateRequest::validate`]'s, and the solver's if it does not converge.
pub fn solve(request: &PlateRequest) -> Result<PlateReport> {
    request.validate()?;
    match (request.scene.support, request.pair) {
        (PlateSupport::Clamped, PlatePair::P1P2P0) => solve_with::<mindlin_clamped::Model>(request),
        (PlateSupport::Clamped, PlatePair::P1P1P0Plain) => {
            solve_with::<mindlin_plain_p1::Model>(request)
        }
    }
}

fn solve_with<M: Model>(request: &PlateRequest) -> Result<PlateReport> {
    let s = &request.scene;
    let q = request.load;
    // an obstacle below every deflection the load can cause (the clamped and the simply
    // supported square stay under 0.005 q a⁴/D; the shear adds O(t²) to it), so λ ≡ 0
    let depth = -100.0
        * (q.abs() * s.side.powi(4) / s.bending_stiffness).max(1.0)
        * (1.0 + request.thickness.powi(2));
    let load = move |_: &[f64]| q;
    let obstacle = move |_: &[f64]| depth;
    let mut params = vec![
        ("D", s.bending_stiffness),
        ("ν", s.poisson_ratio),
        ("κ", s.shear_correction),
        ("t", request.thickness),
        ("α", request.alpha),
        ("s", 1.0),
    ];
    if M::param("β").is_ok() {
        params.push(("β", STENBERG_BETA));
    }
    let coefficients =
        Coefficients::new::<M>(&params, &[("f", &load), ("ψ", &obstacle), ("g", &zero)])?;
    let n = request.mesh_size;
    let mesh = TriangleMesh::rectangle(0.0, s.side, 0.0, s.side, n, n, Diagonal::Right)?;
    let solution =
        solve_obstacle_on_triangles::<M>(&[mesh], &coefficients, ObstacleOptions::default())?;
    let w = M::field("w")?;
    let centre = value_at(&solution, w, [0.5 * s.side, 0.5 * s.side])?;
    let reference = s.kirchhoff_deflection();
    let energy = solution.energy::<M>(&coefficients)?;
    Ok(PlateReport {
        scene: s.name.to_string(),
        pair: request.pair.name(),
        support: s.support.name(),
        thickness: request.thickness,
        mesh_size: n,
        load: q,
        alpha: request.alpha,
        centre_deflection: centre,
        kirchhoff_reference: reference,
        relative_error: (centre - reference) / reference,
        energy,
        max_deflection: solution.field(w).iter().fold(0.0, |m, v| m.max(v.abs())),
        total_contact_force: solution.total_contact_force(),
        complementarity_residual: solution.kkt_residual,
        dofs: solution.discretization.dofs.dof_count(),
        iterations: solution.iterations,
        seconds: solution.seconds,
    })
}

/// The value of `field` of `solution` at the point `x` of its mesh.
fn value_at(solution: &TriangleObstacleSolution, field: usize, x: [f64; 2]) -> Result<f64> {
    let view = solution.view(field);
    let basis = TriangleBasis::new(view.map.element());
    let locator = PointLocator::new(view.mesh);
    view.at(&basis, &locator, x).ok_or_else(|| {
        Error::Input(format!(
            "the point ({}, {}) is outside the mesh",
            x[0], x[1]
        ))
    })
}

/// The locking study of a plate scene: [`solve`] for every pair, mesh size in `mesh_sizes`
/// and thickness in `thicknesses` (the scene's load and α), one report per solve, pairs
/// outermost, then meshes, then thicknesses. The chart of it is the relative error of the
/// centre deflection against t, one line per (pair, mesh): flat for the Stenberg pair (the
/// error does not grow as t → 0), falling to −1 for the plain pair (locking).
///
/// With `csv`, also writes `pair,mesh_size,thickness,centre_deflection,relative_error`,
/// one line per report, to that file (its directory created).
///
/// # Errors
/// [`solve`]'s, and [`Error::Input`] when the file cannot be written.
pub fn locking_study(
    scene: PlateScene,
    mesh_sizes: &[usize],
    thicknesses: &[f64],
    csv: Option<&std::path::Path>,
) -> Result<Vec<PlateReport>> {
    let mut reports = Vec::new();
    for pair in PlatePair::ALL {
        for &mesh_size in mesh_sizes {
            for &thickness in thicknesses {
                reports.push(solve(&PlateRequest {
                    pair,
                    mesh_size,
                    thickness,
                    ..PlateRequest::new(scene)
                })?);
            }
        }
    }
    if let Some(path) = csv {
        let mut text = String::from("pair,mesh_size,thickness,centre_deflection,relative_error\n");
        for r in &reports {
            text += &format!(
                "{},{},{:e},{:e},{:e}\n",
                r.pair, r.mesh_size, r.thickness, r.centre_deflection, r.relative_error
            );
        }
        let write = || -> std::io::Result<()> {
            if let Some(dir) = path.parent() {
                std::fs::create_dir_all(dir)?;
            }
            std::fs::write(path, text)
        };
        write().map_err(|e| Error::Input(format!("cannot write {}: {e}", path.display())))?;
    }
    Ok(reports)
}

/// The locking study of `scene` as the CLI runs it (`study mindlin-square locking`):
/// [`locking_study`] on N = 8, 16, 32 (and 64 with `full`) and t = 1e-1 … 1e-4, a table
/// on stdout, `out/<scene>-locking.csv` and the chart `out/<scene>-locking.svg` of the
/// relative error of the centre deflection against t, one line per (pair, N): flat for
/// the Stenberg pair, rising to 1 (a deflection of 0) for the plain pair.
///
/// # Errors
/// [`locking_study`]'s, and [`Error::Input`] when the chart cannot be written.
pub fn locking_run(scene: PlateScene, full: bool, out: &std::path::Path) -> Result<()> {
    let meshes: &[usize] = if full { &[8, 16, 32, 64] } else { &[8, 16, 32] };
    let thicknesses = [1e-1, 3e-2, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4];
    let csv = out.join(format!("{}-locking.csv", scene.name));
    let reports = locking_study(scene, meshes, &thicknesses, Some(&csv))?;
    println!(
        "\nlocking: {}, centre deflection against the Kirchhoff value {:.6e}",
        scene.name, reports[0].kirchhoff_reference
    );
    println!(
        "{:<16} {:>4} {:>8} {:>14} {:>12}",
        "pair", "N", "t", "w(centre)", "rel. error"
    );
    for r in &reports {
        println!(
            "{:<16} {:>4} {:>8.0e} {:>14.6e} {:>12.3e}",
            r.pair, r.mesh_size, r.thickness, r.centre_deflection, r.relative_error
        );
    }
    let mut series = Vec::new();
    for pair in PlatePair::ALL {
        for &n in meshes {
            let points: Vec<(f64, f64)> = reports
                .iter()
                .filter(|r| r.pair == pair.name() && r.mesh_size == n)
                .map(|r| (r.thickness, r.relative_error.abs().max(1e-12)))
                .collect();
            series.push(crate::plot::Series::marked(
                format!("{} N = {n}", pair.name()),
                points,
            ));
        }
    }
    let svg = out.join(format!("{}-locking.svg", scene.name));
    crate::plot::chart(
        &svg,
        &format!(
            "{}: |relative error| of the centre deflection against t",
            scene.name
        ),
        crate::plot::Axes {
            x: "t",
            y: "|w_h(centre) / w_Kirchhoff − 1|",
            log_x: true,
            log_y: true,
        },
        &series,
    )
    .map_err(|e| Error::Input(format!("cannot write {}: {e}", svg.display())))?;
    println!("→ {}, .csv", svg.display());
    Ok(())
}
