//! The Kirchhoff plate scenes (docs/mathematics.md §9, issue 13): the unit square on an
//! N×N×2 mesh, clamped or simply supported by DOF kind (`Constraints::support_plate`),
//! under a uniform load q, with or without an obstacle above it (`w ≤ ψ`, `s = −1`),
//! solved by nested semismooth Newton (or clarabel); the report of `solve --json`, the
//! convergence study and the study of the multiplier's scatter in the contact interior.

use crate::models::kirchhoff::{
    kirchhoff_argyris_p0, kirchhoff_argyris_p1disc, kirchhoff_morley_p0,
};
use crate::models::kirchhoff_scenes::{
    KirchhoffObstacle, KirchhoffScene, KirchhoffSupport, CURVED_OBSTACLE, FLAT_OBSTACLE,
};
use fem_runtime::element::triangle::{TriangleBasis, TriangleField};
use fem_runtime::obstacle::triangle::TriangleObstacleSolution;
use fem_runtime::obstacle::{ObstacleOptions, VariationalSolver};
use fem_runtime::problem::{Condition, MemoryModel, ObstacleSide, Problem, SolveOptions};
use fem_runtime::stabilization::{inverse_constant, Alpha};
use fem_runtime::{Diagonal, DirichletPart, Error, Model, PointLocator, Result, TriangleMesh};
use serde::Serialize;
use std::path::Path;

/// The obstacle side: every Kirchhoff scene's obstacle is above the plate (`w ≤ ψ`).
const SIDE: f64 = -1.0;
/// The largest N of the N×N×2 mesh a Kirchhoff solve accepts (Argyris: about 9 N² DOFs).
/// Below it the memory is checked too ([`estimated_memory_bytes`]). Measured on
/// kirchhoff-obstacle (2026-12-01): N = 104 takes 0.6 GB; from N = 112 on, where `C = αh⁴`
/// falls below the rounding of `G − BU` and λ_h is recovered from an LU factorization of
/// the saddle-point system, 5.0 GB at 112 and 6.5 GB (18 s) at 128; N = 256 passed
/// 7.8 GB before it finished.
pub const MAX_KIRCHHOFF_MESH_SIZE: usize = 160;

/// The estimated peak memory of a Kirchhoff solve on the N×N×2 mesh, in bytes, from the
/// measurements of [`MAX_KIRCHHOFF_MESH_SIZE`]: without recovery of the multiplier
/// 0.93 GB at N = 128 (kirchhoff-square) scaled by `N^2.3` (the factor's fill; 0.6 GB at
/// 104 with the obstacle); with it, 6.5 GB at 128 scaled by `N²` (5.0 GB at 112). The
/// recovery is assumed for a scene with an obstacle from N = 112 on, where the default α
/// needs it; a much smaller `--alpha` can need it on coarser meshes.
pub fn estimated_memory_bytes(mesh_size: usize, obstacle: bool) -> f64 {
    let n = mesh_size as f64 / 128.0;
    if obstacle && mesh_size >= 112 {
        6.5e9 * n * n
    } else {
        0.93e9 * n.powf(2.3)
    }
}
/// The contact interior of the λ-scatter measure: contact cells whose centroid is at
/// least this far from every cell outside the contact set (a fifth of the contact
/// radius, about 0.25, at q = 20 on the flat obstacle), and two vertex rings in.
pub const INTERIOR_MARGIN: f64 = 0.05;
/// The largest |q| a Kirchhoff solve accepts.
pub const MAX_LOAD: f64 = 1e100;
/// The coarsest mesh of the nested iteration (N×N×2 with N ≥ this).
pub const NESTED_FROM: usize = 4;
/// The default α of the Argyris pairs as a fraction of `1/C_I` (docs/mathematics.md §1:
/// stable for `0 < α < 1/C_I`; ½ is the middle of the range).
pub const ALPHA_FRACTION: f64 = 0.5;
/// The default α of Morley–P0, where `C_I = 0` (every α > 0 is stable): the term adds
/// `α h⁴ |T|` to the multiplier's diagonal and shifts the obstacle by `α h⁴ f` where
/// λ = 0: at q = 20, 0.04 % of the gap 0.002 at N = 32 and 10 % at N = 8 (α = 1 shifted
/// it by 4 % at N = 32 and grew the contact area from 0.25 to 0.31); below 1e-4 Newton
/// needs more iterations on the coarse levels (40 at N = 4 for α = 1e-12).
pub const MORLEY_ALPHA: f64 = 0.01;

/// The discretizations of the Kirchhoff plate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum KirchhoffPair {
    /// w ∈ Argyris (P5, C¹), λ ∈ P0.
    ArgyrisP0,
    /// w ∈ Argyris, λ ∈ P1 discontinuous.
    ArgyrisP1disc,
    /// w ∈ Morley (P2, non-conforming), λ ∈ P0.
    MorleyP0,
}

impl KirchhoffPair {
    /// How the report reads λ_h in the contact interior: [`DEFAULT_RECOVERY`] (the patch
    /// average) for the Argyris pairs; the raw λ_h for Morley, whose patch average a
    /// measured worse than the raw value (max relative error 1.16 against 0.44 at
    /// N = 32, q = 20): its scatter is not the Argyris line-force tail.
    pub fn recovery(self) -> MultiplierRecovery {
        match self {
            KirchhoffPair::MorleyP0 => MultiplierRecovery::Raw,
            _ => DEFAULT_RECOVERY,
        }
    }
}

impl KirchhoffPair {
    /// Every pair, the default first.
    pub const ALL: [KirchhoffPair; 3] = [
        KirchhoffPair::ArgyrisP0,
        KirchhoffPair::ArgyrisP1disc,
        KirchhoffPair::MorleyP0,
    ];

    /// The pair's name (`--pair`).
    pub fn name(self) -> &'static str {
        match self {
            KirchhoffPair::ArgyrisP0 => "argyris-p0",
            KirchhoffPair::ArgyrisP1disc => "argyris-p1disc",
            KirchhoffPair::MorleyP0 => "morley-p0",
        }
    }

    /// The pair called `name`.
    ///
    /// # Errors
    /// [`Error::Input`] naming the Kirchhoff pairs when there is none of that name.
    pub fn parse(name: &str) -> Result<Self> {
        Self::ALL
            .into_iter()
            .find(|p| p.name() == name)
            .ok_or_else(|| {
                Error::Input(format!(
                    "unknown Kirchhoff pair `{name}`; the Kirchhoff pairs are {}",
                    Self::ALL.map(Self::name).join(", ")
                ))
            })
    }
}

/// The support called `name` (`clamped`, `simply-supported`).
///
/// # Errors
/// [`Error::Input`] naming the supports when there is none of that name.
pub fn parse_support(name: &str) -> Result<KirchhoffSupport> {
    KirchhoffSupport::ALL
        .into_iter()
        .find(|s| s.name() == name)
        .ok_or_else(|| {
            Error::Input(format!(
                "unknown support `{name}`; the supports are clamped, simply-supported"
            ))
        })
}

/// The obstacle called `name`: `none`, `flat` (`w ≤ 0.002`) or `curved`
/// (`w ≤ 0.002 + 0.01 r²`).
///
/// # Errors
/// [`Error::Input`] naming the obstacles when there is none of that name.
pub fn parse_obstacle(name: &str) -> Result<KirchhoffObstacle> {
    match name {
        "none" => Ok(KirchhoffObstacle::None),
        "flat" => Ok(FLAT_OBSTACLE),
        "curved" => Ok(CURVED_OBSTACLE),
        _ => Err(Error::Input(format!(
            "unknown obstacle `{name}`; the obstacles are none, flat (w ≤ 0.002), curved (w ≤ 0.002 + 0.01 r²)"
        ))),
    }
}

/// How the multiplier is reported in the contact interior.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum MultiplierRecovery {
    /// λ_h as computed.
    Raw,
    /// The patch average: each vertex gets the area-weighted mean of λ_h over the cells
    /// around it, each cell the mean of its three vertex values (a continuous P1 field,
    /// the local L² projection of λ_h onto the patch's constants).
    PatchAverage,
    /// The patch average applied twice (the cell values of the first pass averaged
    /// again): a support of about two vertex rings.
    TwicePatchAverage,
}

/// One Kirchhoff solve: the scene and what the command line may change.
#[derive(Clone, Copy, Debug)]
pub struct KirchhoffRequest {
    /// The scene.
    pub scene: KirchhoffScene,
    /// The pair.
    pub pair: KirchhoffPair,
    /// The support on the whole boundary.
    pub support: KirchhoffSupport,
    /// The obstacle above the plate.
    pub obstacle: KirchhoffObstacle,
    /// N of the N×N×2 mesh, 1 ≤ N ≤ [`MAX_KIRCHHOFF_MESH_SIZE`].
    pub mesh_size: usize,
    /// Uniform load q (along +w, towards the obstacle for q > 0).
    pub load: f64,
    /// α; `None`: [`ALPHA_FRACTION`]`/C_I` for Argyris, [`MORLEY_ALPHA`] for Morley.
    pub alpha: Option<f64>,
    /// The LCP solver.
    pub solver: VariationalSolver,
    /// Nested iteration from N = [`NESTED_FROM`] (semismooth Newton only).
    pub nested: bool,
}

impl KirchhoffRequest {
    /// The scene's defaults with the default pair (Argyris–P0) and solver.
    pub fn new(scene: KirchhoffScene) -> Self {
        Self {
            scene,
            pair: KirchhoffPair::ArgyrisP0,
            support: scene.support,
            obstacle: scene.obstacle,
            mesh_size: scene.mesh_size,
            load: scene.load,
            alpha: None,
            solver: VariationalSolver::SemismoothNewton,
            nested: true,
        }
    }

    /// Checks the request.
    ///
    /// # Errors
    /// [`Error::Input`] naming the value at fault: a mesh size of 0 or above
    /// [`MAX_KIRCHHOFF_MESH_SIZE`], a load that is not finite or above [`MAX_LOAD`] in
    /// size, α ≤ 0 or not finite, D ≤ 0
    /// or ν outside (−1, ½), an obstacle whose gap or curvature is not finite or whose gap
    /// is not positive (the clamped plate starts at w = 0 below it).
    pub fn validate(&self) -> Result<()> {
        let bad = |what: String| Err(Error::Input(what));
        let s = &self.scene;
        if self.mesh_size == 0 || self.mesh_size > MAX_KIRCHHOFF_MESH_SIZE {
            return bad(format!(
                "mesh size N = {} must lie in 1..={MAX_KIRCHHOFF_MESH_SIZE} (N = 128 already takes about 6.5 GB; beyond {MAX_KIRCHHOFF_MESH_SIZE} the Argyris factorizations outgrow the memory of a shared machine)",
                self.mesh_size
            ));
        }
        // beyond 1e100 the far obstacle of a scene without one (100 |q|/D) and the
        // energy (q² a⁴/D) leave the range of f64
        if !(self.load.is_finite() && self.load.abs() <= MAX_LOAD) {
            return bad(format!(
                "load q = {:e} must be finite and at most {MAX_LOAD:e} in size",
                self.load
            ));
        }
        if let Some(alpha) = self.alpha {
            if !(alpha.is_finite() && alpha > 0.0) {
                return bad(format!(
                    "α = {alpha} must be positive and finite (α = 0 leaves the multiplier undetermined where there is no contact)"
                ));
            }
        }
        if !(s.bending_stiffness.is_finite() && s.bending_stiffness > 0.0) {
            return bad(format!(
                "bending stiffness D = {} must be positive and finite",
                s.bending_stiffness
            ));
        }
        if !(s.poisson_ratio > -1.0 && s.poisson_ratio < 0.5) {
            return bad(format!(
                "Poisson's ratio ν = {} must lie in (−1, ½)",
                s.poisson_ratio
            ));
        }
        let (gap, curvature) = match self.obstacle {
            KirchhoffObstacle::None => (1.0, 0.0),
            KirchhoffObstacle::Flat { gap } => (gap, 0.0),
            KirchhoffObstacle::Curved { gap, curvature } => (gap, curvature),
        };
        if !(gap.is_finite() && gap > 0.0 && curvature.is_finite()) {
            return bad(format!(
                "obstacle {}: gap {gap} must be positive and finite (the supported plate is at w = 0 under it), curvature {curvature} finite",
                self.obstacle.name()
            ));
        }
        Ok(())
    }

    /// α for this request: the given one, or the pair's default with the mesh's largest
    /// element constant `C_I` (returned beside it).
    ///
    /// `C_I` depends on the cells' shapes, not their size, and every N×N×2 right-diagonal
    /// mesh has the same two shapes: it is computed on N = 1, two cells instead of 2N².
    fn alpha_on<M: Model>(&self) -> Result<(f64, f64)> {
        let s = &self.scene;
        let params = [s.bending_stiffness, s.poisson_ratio, 1.0, SIDE];
        let shapes = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 1, 1, Diagonal::Right)?;
        let c_i = inverse_constant::<M, _>(&shapes, &params)?;
        let alpha = match (self.alpha, c_i > 0.0) {
            (Some(alpha), _) => alpha,
            (None, true) => ALPHA_FRACTION / c_i,
            (None, false) => MORLEY_ALPHA,
        };
        Ok((alpha, c_i))
    }
}

/// Statistics of the multiplier over the contact interior (see [`interior_cells`]),
/// against its exact value there.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct InteriorMultiplier {
    /// How λ is read.
    pub recovery: MultiplierRecovery,
    /// Number of interior cells.
    pub cells: usize,
    /// The exact λ there: `q` (`λ = s(DΔ²ψ − f)` with `Δ²ψ = 0`, `s = −1`, `f = q`).
    pub exact: f64,
    /// Smallest value (P1disc: over the cells' vertex values).
    pub min: f64,
    /// Largest value.
    pub max: f64,
    /// Mean value.
    pub mean: f64,
    /// `max |λ − exact| / exact`.
    pub max_relative_error: f64,
}

/// The report of a Kirchhoff solve (`solve --json`).
#[derive(Clone, Debug, Serialize)]
pub struct KirchhoffReport {
    /// Scene name.
    pub scene: String,
    /// Pair name.
    pub pair: &'static str,
    /// Support name.
    pub support: &'static str,
    /// Obstacle name.
    pub obstacle: &'static str,
    /// N of the N×N×2 mesh.
    pub mesh_size: usize,
    /// Load q.
    pub load: f64,
    /// α.
    pub alpha: f64,
    /// The mesh's largest element constant `C_I` (0 for Morley).
    pub inverse_constant: f64,
    /// Solver (`pdas`: nested semismooth Newton; `clarabel`).
    pub solver: &'static str,
    /// `J_h = ½ a(w_h, w_h) − ℓ(w_h)` (the physical energy, not the stabilized one).
    pub energy: f64,
    /// w_h at the centre of the square.
    pub centre_deflection: f64,
    /// Without an obstacle: the series' centre deflection `c q a⁴/D` (clamped: the
    /// tabulated 0.00126532, six digits; simply supported: Navier's series summed).
    pub reference_centre_deflection: Option<f64>,
    /// Without an obstacle: `(w_h(centre) − reference)/reference`, 0 at q = 0 (both 0).
    pub relative_error: Option<f64>,
    /// `max |w_h|` over the vertices, edge midpoints and centroids of the cells.
    pub max_deflection: f64,
    /// `∫λ_h`.
    pub total_contact_force: f64,
    /// The area enclosed by the contact set's outer boundary (see [`contact_cells`]).
    pub contact_area: f64,
    /// The multiplier in the contact interior ([`interior_cells`]) against its exact
    /// value, read as the pair's recovery ([`KirchhoffPair::recovery`]: the patch average
    /// for Argyris, the cure of the scatter, docs/mathematics.md §9); with an obstacle and
    /// contact only.
    pub interior_multiplier: Option<InteriorMultiplier>,
    /// λ_h as computed there.
    pub interior_multiplier_raw: Option<InteriorMultiplier>,
    /// The twice applied patch average there.
    pub interior_multiplier_twice_averaged: Option<InteriorMultiplier>,
    /// The layer profile of λ_h next to the free boundary (not in the JSON).
    #[serde(skip)]
    pub multiplier_layer: Vec<LayerBand>,
    /// The runtime's estimate of the relative rounding noise of λ_h (0: none; λ_h
    /// from a linear solve): the scatter is not rounding where this is small.
    pub multiplier_noise: f64,
    /// KKT residual of the solution (computed from it, not the solver's word).
    pub complementarity_residual: f64,
    /// Number of unknowns (all fields, multiplier included, fixed DOFs too).
    pub dofs: usize,
    /// Iterations on the finest mesh.
    pub iterations: usize,
    /// `[triangles, iterations]` of each level of the nested iteration (as every family
    /// reports it).
    pub levels: Vec<[usize; 2]>,
    /// Wall time of the solve, assembly included.
    pub seconds: f64,
    /// The largest `w_h − ψ` at the cells' vertices, edge midpoints and centroids (0
    /// without an obstacle or where the plate stays below it).
    pub max_penetration: f64,
    /// The largest clearance `ψ − w_h` of a cell where λ_h pushes (0 for a real contact
    /// set; see `fem_runtime::obstacle::triangle::max_open_contact_gap`), warned above
    /// 1 % of the gap.
    pub max_open_contact_gap: f64,
    /// Warnings (e.g. a visible penetration of the obstacle).
    pub warnings: Vec<String>,
}

fn zero(_: &[f64]) -> f64 {
    0.0
}

/// Solves `request`.
///
/// # Errors
/// [`KirchhoffRequest::validate`]'s, and the solver's if it does not converge.
pub fn solve(request: &KirchhoffRequest) -> Result<KirchhoffReport> {
    request.validate()?;
    let bytes = estimated_memory_bytes(
        request.mesh_size,
        request.obstacle != KirchhoffObstacle::None,
    );
    if let Some(m) = crate::membranes::beyond_memory(bytes) {
        return Err(Error::Input(format!(
            "--mesh-size {} {m}; a smaller N does",
            request.mesh_size
        )));
    }
    match request.pair {
        KirchhoffPair::ArgyrisP0 => solve_with::<kirchhoff_argyris_p0::Model>(request),
        KirchhoffPair::ArgyrisP1disc => solve_with::<kirchhoff_argyris_p1disc::Model>(request),
        KirchhoffPair::MorleyP0 => solve_with::<kirchhoff_morley_p0::Model>(request),
    }
}

/// N of the N×N×2 mesh of `triangles` cells.
fn mesh_size_of(triangles: usize) -> usize {
    ((triangles / 2) as f64).sqrt().round() as usize
}

/// The N of the nested levels ending at `n`: `n/2^k ≥ NESTED_FROM`, …, `n/2`, `n`.
fn level_sizes(n: usize, nested: bool) -> Vec<usize> {
    let mut sizes = vec![n];
    while nested && sizes[0] % 2 == 0 && sizes[0] / 2 >= NESTED_FROM {
        sizes.insert(0, sizes[0] / 2);
    }
    sizes
}

fn solve_with<M: Model>(request: &KirchhoffRequest) -> Result<KirchhoffReport> {
    let s = &request.scene;
    let q = request.load;
    let obstacle = request.obstacle;
    // no obstacle: one far above every deflection the load can cause (the square's stay
    // under 0.005 |q| a⁴/D), so λ ≡ 0
    let far = 100.0 * (q.abs() / s.bending_stiffness).max(1.0);
    let psi = move |x: &[f64]| {
        let r = (x[0] - 0.5).hypot(x[1] - 0.5);
        obstacle.height(r).unwrap_or(far)
    };
    let load = move |_: &[f64]| q;
    let n = request.mesh_size;
    let newton = request.solver == VariationalSolver::SemismoothNewton;
    let sizes = level_sizes(n, request.nested && newton);
    let meshes = sizes
        .iter()
        .map(|&n| TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, n, n, Diagonal::Right))
        .collect::<Result<Vec<_>>>()?;
    let support = match request.support {
        KirchhoffSupport::Clamped => Condition::Clamped,
        KirchhoffSupport::SimplySupported => Condition::Zero,
    };
    let alpha = match request.alpha {
        Some(alpha) => Alpha::Fixed(alpha),
        None => Alpha::FromInverseConstant(ALPHA_FRACTION),
    };
    let solved = Problem::<M, TriangleMesh>::new(meshes)
        .param("D", s.bending_stiffness)
        .param("ν", s.poisson_ratio)
        .data("f", &load)
        .data("ψ", &psi)
        .data("g", &zero)
        .support(DirichletPart::All, "w", support)
        .side(ObstacleSide::Above)
        .alpha(alpha, MORLEY_ALPHA)
        .options(SolveOptions {
            obstacle: ObstacleOptions {
                solver: request.solver,
                ..ObstacleOptions::default()
            },
            nested: request.nested && newton,
            rounding_experiment: false,
        })
        .memory(
            MemoryModel::per_cell(
                estimated_memory_bytes(n, obstacle != KirchhoffObstacle::None)
                    / (2.0 * (n * n) as f64),
            ),
            format!("--mesh-size {n}"),
        )
        .solve()?;
    let runtime = &solved.report;
    let solution = &solved.solution;
    let w = M::field("w")?;
    let view = solution.view(w);
    let basis = TriangleBasis::new(view.map.element());
    let mut warnings = runtime.warnings.clone();
    if request.nested && newton && obstacle != KirchhoffObstacle::None {
        warnings.extend(crate::plates::cold_coarsest_warning(&sizes, NESTED_FROM));
    }
    let locator = PointLocator::new(view.mesh);
    let centre = view
        .at(&basis, &locator, [0.5, 0.5])
        .ok_or_else(|| Error::Input("the centre (0.5, 0.5) is outside the mesh".into()))?;
    let coefficient = match request.support {
        KirchhoffSupport::Clamped => request.support.centre_coefficient(),
        KirchhoffSupport::SimplySupported => navier_centre_coefficient(),
    };
    let reference =
        matches!(obstacle, KirchhoffObstacle::None).then(|| coefficient * q / s.bending_stiffness);
    let contact = contact_cells(solution);
    let interior = if matches!(obstacle, KirchhoffObstacle::None) || q <= 0.0 {
        Vec::new()
    } else {
        interior_cells(&solution.discretization.mesh, &contact)
    };
    let statistics = |recovery| interior_statistics(solution, &interior, recovery, q);
    let in_contact = !matches!(obstacle, KirchhoffObstacle::None);
    Ok(KirchhoffReport {
        scene: s.name.to_string(),
        pair: request.pair.name(),
        support: request.support.name(),
        obstacle: obstacle.name(),
        mesh_size: n,
        load: q,
        alpha: runtime.alpha.unwrap_or(0.0),
        inverse_constant: runtime.inverse_constant,
        solver: if newton { "pdas" } else { "clarabel" },
        energy: runtime.energy.unwrap_or(f64::NAN),
        centre_deflection: centre,
        reference_centre_deflection: reference,
        // q = 0: both deflections are 0 exactly, and so is the error, as the Mindlin
        // plates report it (a 0/0 left out would read as "not measured")
        relative_error: reference.and_then(|r| {
            if r != 0.0 {
                Some((centre - r) / r)
            } else {
                (centre == 0.0).then_some(0.0)
            }
        }),
        max_deflection: max_deflection(&view, &basis),
        total_contact_force: runtime.total_contact_force,
        contact_area: filled_area(&solution.discretization.mesh, &contact),
        interior_multiplier: statistics(request.pair.recovery()),
        interior_multiplier_raw: statistics(MultiplierRecovery::Raw),
        multiplier_layer: if interior.is_empty() {
            Vec::new()
        } else {
            layer_profile(solution, &contact, q)
        },
        interior_multiplier_twice_averaged: statistics(MultiplierRecovery::TwicePatchAverage),
        multiplier_noise: runtime.multiplier_noise,
        complementarity_residual: runtime.kkt_residual,
        dofs: solution.discretization.dofs.dof_count(),
        iterations: runtime.iterations,
        levels: runtime.levels.clone(),
        seconds: runtime.seconds,
        max_penetration: if in_contact {
            runtime.max_penetration.unwrap_or(0.0)
        } else {
            0.0
        },
        max_open_contact_gap: if in_contact {
            runtime.max_open_contact_gap.unwrap_or(0.0)
        } else {
            0.0
        },
        warnings,
    })
}

/// The centre deflection of the simply supported unit square under a unit load with
/// D = 1 from Navier's double sine series (Timoshenko and Woinowsky-Krieger §30):
/// `16/π⁶ Σ_{m,n odd} (−1)^{(m+n)/2−1} / (mn(m²+n²)²)` = 0.0040623527; 200 odd terms
/// each way leave an error below 1e-12 (the terms fall like `1/m⁵`).
pub fn navier_centre_coefficient() -> f64 {
    let mut sum = 0.0;
    for m in (1..400usize).step_by(2) {
        for n in (1..400usize).step_by(2) {
            let sign = if ((m + n) / 2 - 1) % 2 == 0 {
                1.0
            } else {
                -1.0
            };
            let (m, n) = (m as f64, n as f64);
            sum += sign / (m * n * (m * m + n * n).powi(2));
        }
    }
    16.0 / std::f64::consts::PI.powi(6) * sum
}

/// `max |w_h|` over each cell's vertices, edge midpoints and centroid.
fn max_deflection(view: &TriangleField, basis: &TriangleBasis) -> f64 {
    const POINTS: [[f64; 2]; 7] = [
        [0.0, 0.0],
        [1.0, 0.0],
        [0.0, 1.0],
        [0.5, 0.0],
        [0.5, 0.5],
        [0.0, 0.5],
        [1.0 / 3.0, 1.0 / 3.0],
    ];
    let mut largest = 0.0f64;
    for c in 0..view.mesh.cell_count() {
        for xi in POINTS {
            largest = largest.max(view.value(basis, c, xi).abs());
        }
    }
    largest
}

/// The contact cells: a cell is in contact when one of its multiplier constraints is
/// active (λ above 1e-8 of the multiplier scale) or touching (its residual negligible),
/// `fem_runtime::obstacle::triangle::contact_indicator`.
pub fn contact_cells(solution: &TriangleObstacleSolution) -> Vec<bool> {
    solution
        .contact_shares()
        .into_iter()
        .map(|share| share > 0.0)
        .collect()
}

/// The area enclosed by the outer boundary of the cells in `contact`: the contact cells
/// and every other cell that cannot be reached from a boundary cell through non-contact
/// cells across edges (a hole of zero λ_h inside the contact set counts as contact, as
/// docs/mathematics.md §9 asks). Cells touched only partly count fully, so the area
/// carries an O(h) error at the free boundary.
pub fn filled_area(mesh: &TriangleMesh, contact: &[bool]) -> f64 {
    let cells = mesh.cell_count();
    let mut outside = vec![false; cells];
    let mut stack = Vec::new();
    for &(e, _) in mesh.boundary_edges() {
        let (c, _) = mesh.edge_cells(e);
        if !contact[c] && !outside[c] {
            outside[c] = true;
            stack.push(c);
        }
    }
    while let Some(c) = stack.pop() {
        for e in mesh.cell_edges(c) {
            let (a, b) = mesh.edge_cells(e);
            for n in std::iter::once(a).chain(b) {
                if !contact[n] && !outside[n] {
                    outside[n] = true;
                    stack.push(n);
                }
            }
        }
    }
    // from +0: an empty f64 sum is −0
    (0..cells)
        .filter(|&c| !outside[c])
        .fold(0.0, |sum, c| sum + mesh.area(c))
}

/// The contact interior: contact cells whose three vertices are in contact (every cell
/// around them is a contact cell), and the same once more, so that every interior cell
/// is two vertex rings away from the free boundary (where λ carries a line force), and
/// whose centroid is at least [`INTERIOR_MARGIN`] from the centroid of every cell
/// outside the contact set.
pub fn interior_cells(mesh: &TriangleMesh, contact: &[bool]) -> Vec<usize> {
    let distance = frontier_distances(mesh, contact);
    let erode = |inside: &[bool]| -> Vec<bool> {
        let mut vertex = vec![true; mesh.vertex_count()];
        for (c, &on) in inside.iter().enumerate() {
            if !on {
                for v in mesh.cell(c) {
                    vertex[v] = false;
                }
            }
        }
        (0..mesh.cell_count())
            .map(|c| inside[c] && mesh.cell(c).iter().all(|&v| vertex[v]))
            .collect()
    };
    let once = erode(contact);
    let twice = erode(&once);
    (0..mesh.cell_count())
        .filter(|&c| twice[c] && distance[c] >= INTERIOR_MARGIN)
        .collect()
}

/// For each contact cell, the distance from its centroid to the nearest centroid of a
/// cell outside the contact set (∞ when there is none); 0 for the cells outside.
pub fn frontier_distances(mesh: &TriangleMesh, contact: &[bool]) -> Vec<f64> {
    let centroid = |c: usize| {
        let x = mesh.cell_coordinates(c);
        [(x[0] + x[2] + x[4]) / 3.0, (x[1] + x[3] + x[5]) / 3.0]
    };
    // only the cells outside contact next to it can be nearest
    let frontier: Vec<[f64; 2]> = (0..mesh.cell_count())
        .filter(|&c| {
            !contact[c]
                && mesh.cell_edges(c).iter().any(|&e| {
                    let (a, b) = mesh.edge_cells(e);
                    contact[a] || b.is_some_and(|b| contact[b])
                })
        })
        .map(centroid)
        .collect();
    (0..mesh.cell_count())
        .map(|c| {
            if !contact[c] {
                return 0.0;
            }
            let x = centroid(c);
            frontier
                .iter()
                .map(|y| (x[0] - y[0]).hypot(x[1] - y[1]))
                .fold(f64::INFINITY, f64::min)
        })
        .collect()
}

/// One band of the multiplier's layer next to the free boundary: the contact cells whose
/// distance to the nearest cell outside contact ([`frontier_distances`]) lies in
/// `[k h, (k+1) h)`, h the cell diameter.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct LayerBand {
    /// k.
    pub distance_in_cells: usize,
    /// Cells in the band.
    pub cells: usize,
    /// `max |λ_h − q| / q` over them (cell means).
    pub max_relative_error: f64,
    /// The same for the patch average.
    pub patch_average_max_relative_error: f64,
}

/// The layer profile of λ_h next to the free boundary, bands k = 0, 1, … (see [`LayerBand`]).
fn layer_profile(solution: &TriangleObstacleSolution, contact: &[bool], q: f64) -> Vec<LayerBand> {
    let mesh = &solution.discretization.mesh;
    let distance = frontier_distances(mesh, contact);
    let h = mesh.max_h();
    let raw = cell_means(solution);
    let averaged = averaged_cells(mesh, &raw, 1);
    let mut bands: Vec<LayerBand> = Vec::new();
    for c in (0..mesh.cell_count()).filter(|&c| contact[c] && distance[c].is_finite()) {
        let k = (distance[c] / h).floor() as usize;
        while bands.len() <= k {
            bands.push(LayerBand {
                distance_in_cells: bands.len(),
                cells: 0,
                max_relative_error: 0.0,
                patch_average_max_relative_error: 0.0,
            });
        }
        let band = &mut bands[k];
        band.cells += 1;
        band.max_relative_error = band.max_relative_error.max((raw[c] - q).abs() / q);
        band.patch_average_max_relative_error = band
            .patch_average_max_relative_error
            .max((averaged[c] - q).abs() / q);
    }
    bands
}

/// The cell values `values` patch-averaged `passes` times ([`MultiplierRecovery::PatchAverage`]).
fn averaged_cells(mesh: &TriangleMesh, values: &[f64], passes: usize) -> Vec<f64> {
    let mut cells = values.to_vec();
    for _ in 0..passes {
        let at_vertices = patch_average(mesh, &cells);
        cells = (0..mesh.cell_count())
            .map(|c| mesh.cell(c).iter().map(|&v| at_vertices[v]).sum::<f64>() / 3.0)
            .collect();
    }
    cells
}

/// The multiplier's cell means (P0: its values; P1disc: the mean of the three).
fn cell_means(solution: &TriangleObstacleSolution) -> Vec<f64> {
    let d = &solution.discretization;
    let map = d.dofs.map(d.multiplier_field).unwrap();
    let lambda = solution.field(d.multiplier_field);
    (0..d.mesh.cell_count())
        .map(|c| {
            let dofs = map.cell_dofs(c);
            dofs.iter().map(|&k| lambda[k]).sum::<f64>() / dofs.len() as f64
        })
        .collect()
}

/// The patch average of the cell values `means` at every vertex
/// ([`MultiplierRecovery::PatchAverage`]).
fn patch_average(mesh: &TriangleMesh, means: &[f64]) -> Vec<f64> {
    let (mut sum, mut weight) = (
        vec![0.0; mesh.vertex_count()],
        vec![0.0; mesh.vertex_count()],
    );
    for (c, &m) in means.iter().enumerate() {
        let area = mesh.area(c);
        for v in mesh.cell(c) {
            sum[v] += area * m;
            weight[v] += area;
        }
    }
    sum.iter().zip(&weight).map(|(s, w)| s / w).collect()
}

/// λ over `interior` read as `recovery`, against the exact `q`; `None` for no cells.
fn interior_statistics(
    solution: &TriangleObstacleSolution,
    interior: &[usize],
    recovery: MultiplierRecovery,
    q: f64,
) -> Option<InteriorMultiplier> {
    if interior.is_empty() {
        return None;
    }
    let d = &solution.discretization;
    let values: Vec<f64> = match recovery {
        MultiplierRecovery::Raw => {
            let map = d.dofs.map(d.multiplier_field).unwrap();
            let lambda = solution.field(d.multiplier_field);
            interior
                .iter()
                .flat_map(|&c| map.cell_dofs(c).iter().map(|&k| lambda[k]))
                .collect()
        }
        MultiplierRecovery::PatchAverage | MultiplierRecovery::TwicePatchAverage => {
            let passes = if recovery == MultiplierRecovery::PatchAverage {
                1
            } else {
                2
            };
            let cells = averaged_cells(&d.mesh, &cell_means(solution), passes);
            interior.iter().map(|&c| cells[c]).collect()
        }
    };
    let min = values.iter().cloned().fold(f64::INFINITY, f64::min);
    let max = values.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    Some(InteriorMultiplier {
        recovery,
        cells: interior.len(),
        exact: q,
        min,
        max,
        mean: values.iter().sum::<f64>() / values.len() as f64,
        max_relative_error: (max - q).abs().max((min - q).abs()) / q,
    })
}

/// How the reported interior multiplier is read by default: the patch average, which
/// takes out most of λ_h's oscillating layer next to the free boundary (the λ-scatter
/// study, docs/mathematics.md §9).
pub const DEFAULT_RECOVERY: MultiplierRecovery = MultiplierRecovery::PatchAverage;

/// One line of text for a report (`solve` without `--json`); the command line prints the
/// warnings apart, on stderr.
pub fn summary(r: &KirchhoffReport) -> String {
    let mut line = format!(
        "{} {} {} obstacle {} q = {} N = {}: J_h {:.8e}, w(centre) {:.8e}",
        r.scene,
        r.pair,
        r.support,
        r.obstacle,
        crate::number(r.load),
        r.mesh_size,
        r.energy,
        r.centre_deflection
    );
    if let (Some(reference), Some(e)) = (r.reference_centre_deflection, r.relative_error) {
        line += &format!(" (reference {reference:.8e}, relative error {e:+.2e})");
    }
    line += &format!(
        ", max |w| {:.6e}, ∫λ_h {:.6e}, contact area {:.5}",
        r.max_deflection, r.total_contact_force, r.contact_area
    );
    if let Some(m) = &r.interior_multiplier {
        line += &format!(
            ", interior λ ({}) {:.4}…{:.4} (exact {})",
            match m.recovery {
                MultiplierRecovery::Raw => "raw",
                MultiplierRecovery::PatchAverage => "patch average",
                MultiplierRecovery::TwicePatchAverage => "patch average twice",
            },
            m.min,
            m.max,
            m.exact
        );
    }
    let levels: Vec<String> = r
        .levels
        .iter()
        .map(|[triangles, iterations]| format!("{}:{iterations}", mesh_size_of(*triangles)))
        .collect();
    line += &format!(
        "; α {:.3e}, {} dofs, iterations per level (N:it) {}, KKT residual {:.1e}, {:.3} s",
        r.alpha,
        r.dofs,
        levels.join(" "),
        r.complementarity_residual,
        r.seconds
    );
    line
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

fn chart(
    path: &Path,
    title: &str,
    axes: crate::plot::Axes,
    series: &[crate::plot::Series],
) -> Result<()> {
    crate::plot::chart(path, title, axes, series)
        .map_err(|e| Error::Input(format!("cannot write {}: {e}", path.display())))?;
    println!("→ {}, .csv", path.display());
    Ok(())
}

/// The convergence study of a Kirchhoff scene (`study <scene> convergence`).
///
/// Without an obstacle (kirchhoff-square): the centre deflection of both supports and
/// every pair on N = 4 … 32 (64 with `full`) against the series, with the observed rate
/// from successive differences `log2(|w_N − w_{N/2}| / |w_{2N} − w_N|)` (independent of
/// the 6-digit reference). With one (kirchhoff-obstacle): q = 5 and 20, flat and curved,
/// the scene's default pair, N = 8 … 64 (128 with `full`): J_h, ∫λ_h, contact area and
/// max w, their successive differences and rates. A table on stdout,
/// `out/<scene>-convergence.csv` and the chart `.svg` of the successive differences
/// against N.
///
/// # Errors
/// [`solve`]'s, and [`Error::Input`] when a file cannot be written.
pub fn convergence_run(scene: KirchhoffScene, full: bool, out: &Path) -> Result<()> {
    if matches!(scene.obstacle, KirchhoffObstacle::None) {
        square_convergence(scene, full, out)
    } else {
        obstacle_convergence(scene, full, out)
    }
}

fn square_convergence(scene: KirchhoffScene, full: bool, out: &Path) -> Result<()> {
    let meshes: &[usize] = if full {
        &[4, 8, 16, 32, 64]
    } else {
        &[4, 8, 16, 32]
    };
    let mut csv =
        String::from("support,pair,mesh_size,centre_deflection,relative_error,difference,rate\n");
    let mut series = Vec::new();
    println!(
        "\nconvergence: {}, centre deflection against the reference (simply supported: Navier's series; clamped: the tabulated 0.00126532, whose six digits floor the error near 7e-7)",
        scene.name
    );
    println!(
        "{:<17} {:<15} {:>4} {:>16} {:>11} {:>11} {:>6}",
        "support", "pair", "N", "w(centre)", "rel. error", "difference", "rate"
    );
    for support in KirchhoffSupport::ALL {
        for pair in [KirchhoffPair::ArgyrisP0, KirchhoffPair::MorleyP0] {
            let mut values = Vec::new();
            for &mesh_size in meshes {
                let r = solve(&KirchhoffRequest {
                    pair,
                    support,
                    mesh_size,
                    ..KirchhoffRequest::new(scene)
                })?;
                values.push((
                    mesh_size,
                    r.centre_deflection,
                    r.relative_error.unwrap_or(0.0),
                ));
            }
            let differences: Vec<f64> =
                values.windows(2).map(|w| (w[1].1 - w[0].1).abs()).collect();
            for (k, &(n, w, e)) in values.iter().enumerate() {
                let difference = k.checked_sub(1).map(|j| differences[j]);
                let rate = (k >= 2).then(|| (differences[k - 2] / differences[k - 1]).log2());
                let show =
                    |x: Option<f64>, p: usize| x.map_or("-".to_string(), |x| format!("{x:.p$e}"));
                println!(
                    "{:<17} {:<15} {:>4} {:>16.9e} {:>+11.2e} {:>11} {:>6}",
                    support.name(),
                    pair.name(),
                    n,
                    w,
                    e,
                    show(difference, 2),
                    rate.map_or("-".into(), |r| format!("{r:.2}"))
                );
                csv += &format!(
                    "{},{},{n},{w:e},{e:e},{},{}\n",
                    support.name(),
                    pair.name(),
                    difference.map_or(String::new(), |d| format!("{d:e}")),
                    rate.map_or(String::new(), |r| format!("{r}"))
                );
            }
            series.push(crate::plot::Series::marked(
                format!("{} {}", pair.name(), support.name()),
                values
                    .iter()
                    .map(|&(n, _, e)| (n as f64, e.abs().max(1e-12)))
                    .collect(),
            ));
        }
    }
    write_text(&out.join(format!("{}-convergence.csv", scene.name)), &csv)?;
    chart(
        &out.join(format!("{}-convergence.svg", scene.name)),
        &format!(
            "{}: |relative error| of the centre deflection against N",
            scene.name
        ),
        crate::plot::Axes {
            x: "N (N×N×2 mesh)",
            y: "|w_h(centre) / reference − 1|",
            log_x: true,
            log_y: true,
        },
        &series,
    )
}

fn obstacle_convergence(scene: KirchhoffScene, full: bool, out: &Path) -> Result<()> {
    let meshes: &[usize] = if full {
        &[8, 16, 32, 64, 128]
    } else {
        &[8, 16, 32, 64]
    };
    let names = ["J_h", "∫λ_h", "contact area", "max w"];
    let mut csv = String::from(
        "load,obstacle,mesh_size,energy,total_contact_force,contact_area,max_deflection,iterations,kkt_residual,seconds\n",
    );
    let mut series = Vec::new();
    println!(
        "\nconvergence: {} ({}), successive differences |Q_N − Q_N/2| and their rates",
        scene.name,
        KirchhoffPair::ArgyrisP0.name()
    );
    for load in [5.0, 20.0] {
        for obstacle in [FLAT_OBSTACLE, CURVED_OBSTACLE] {
            let mut reports = Vec::new();
            for &mesh_size in meshes {
                reports.push(solve(&KirchhoffRequest {
                    load,
                    obstacle,
                    mesh_size,
                    ..KirchhoffRequest::new(scene)
                })?);
            }
            println!("q = {load}, obstacle {}:", obstacle.name());
            println!(
                "{:>5} {:>15} {:>13} {:>10} {:>13} {:>12} {:>9} {:>8}",
                "N", "J_h", "∫λ_h", "area", "max w", "iterations", "KKT res", "seconds"
            );
            for r in &reports {
                let levels: Vec<String> = r.levels.iter().map(|l| l[1].to_string()).collect();
                println!(
                    "{:>5} {:>15.9e} {:>13.7e} {:>10.6} {:>13.7e} {:>12} {:>9.1e} {:>8.2}",
                    r.mesh_size,
                    r.energy,
                    r.total_contact_force,
                    r.contact_area,
                    r.max_deflection,
                    levels.join(","),
                    r.complementarity_residual,
                    r.seconds
                );
                csv += &format!(
                    "{load},{},{},{:e},{:e},{:e},{:e},{},{:e},{}\n",
                    obstacle.name(),
                    r.mesh_size,
                    r.energy,
                    r.total_contact_force,
                    r.contact_area,
                    r.max_deflection,
                    levels.join(" "),
                    r.complementarity_residual,
                    r.seconds
                );
            }
            let quantities: [Vec<f64>; 4] = [
                reports.iter().map(|r| r.energy).collect(),
                reports.iter().map(|r| r.total_contact_force).collect(),
                reports.iter().map(|r| r.contact_area).collect(),
                reports.iter().map(|r| r.max_deflection).collect(),
            ];
            for (name, values) in names.iter().zip(&quantities) {
                let differences: Vec<f64> =
                    values.windows(2).map(|w| (w[1] - w[0]).abs()).collect();
                let rates: Vec<String> = crate::studies::rates(&differences)
                    .iter()
                    .map(|r| {
                        if r.is_nan() {
                            "-".into()
                        } else {
                            format!("{r:.2}")
                        }
                    })
                    .collect();
                println!(
                    "  {name:<13} differences {} rates {}",
                    differences
                        .iter()
                        .map(|d| format!("{d:.2e}"))
                        .collect::<Vec<_>>()
                        .join(" "),
                    rates.join(" ")
                );
                series.push(crate::plot::Series::marked(
                    format!("{name} q = {load} {}", obstacle.name()),
                    meshes[1..]
                        .iter()
                        .zip(&differences)
                        // a log axis has no 0: a difference of 0 (a contact area equal on
                        // two meshes) is left out, not drawn at 1e-14
                        .map(|(&n, &d)| (n as f64, d / values.last().unwrap().abs()))
                        .filter(|&(_, d)| d > 0.0 && d.is_finite())
                        .collect(),
                ));
            }
        }
    }
    write_text(&out.join(format!("{}-convergence.csv", scene.name)), &csv)?;
    chart(
        &out.join(format!("{}-convergence.svg", scene.name)),
        &format!(
            "{}: relative successive differences |Q_N − Q_N/2| / |Q_finest|",
            scene.name
        ),
        crate::plot::Axes {
            x: "N (N×N×2 mesh)",
            y: "relative difference",
            log_x: true,
            log_y: true,
        },
        &series,
    )
}

/// One method of the λ-scatter study: a pair, α as a multiple of `1/C_I` (or fixed for
/// Morley), and how λ is read.
#[derive(Clone, Copy, Debug)]
pub struct ScatterMethod {
    /// Label in the table, CSV and chart.
    pub label: &'static str,
    /// The pair.
    pub pair: KirchhoffPair,
    /// `α·C_I` for Argyris; α itself for Morley (`None`: the pair's default).
    pub alpha: Option<f64>,
    /// How λ is read.
    pub recovery: MultiplierRecovery,
}

/// The methods of the λ-scatter study (docs/mathematics.md §9).
pub const SCATTER_METHODS: &[ScatterMethod] = &[
    ScatterMethod {
        label: "argyris-p0 α=½/C_I",
        pair: KirchhoffPair::ArgyrisP0,
        alpha: None,
        recovery: MultiplierRecovery::Raw,
    },
    ScatterMethod {
        label: "argyris-p0 α=0.9/C_I",
        pair: KirchhoffPair::ArgyrisP0,
        alpha: Some(0.9),
        recovery: MultiplierRecovery::Raw,
    },
    ScatterMethod {
        label: "argyris-p0 α=0.1/C_I",
        pair: KirchhoffPair::ArgyrisP0,
        alpha: Some(0.1),
        recovery: MultiplierRecovery::Raw,
    },
    ScatterMethod {
        label: "argyris-p1disc α=½/C_I",
        pair: KirchhoffPair::ArgyrisP1disc,
        alpha: None,
        recovery: MultiplierRecovery::Raw,
    },
    ScatterMethod {
        label: "morley-p0 α=0.01",
        pair: KirchhoffPair::MorleyP0,
        alpha: None,
        recovery: MultiplierRecovery::Raw,
    },
    ScatterMethod {
        label: "argyris-p0 α=½/C_I patch average",
        pair: KirchhoffPair::ArgyrisP0,
        alpha: None,
        recovery: MultiplierRecovery::PatchAverage,
    },
    ScatterMethod {
        label: "argyris-p0 α=½/C_I twice averaged",
        pair: KirchhoffPair::ArgyrisP0,
        alpha: None,
        recovery: MultiplierRecovery::TwicePatchAverage,
    },
    ScatterMethod {
        label: "argyris-p1disc α=½/C_I twice averaged",
        pair: KirchhoffPair::ArgyrisP1disc,
        alpha: None,
        recovery: MultiplierRecovery::TwicePatchAverage,
    },
];

/// One row of the λ-scatter study.
#[derive(Clone, Debug, Serialize)]
pub struct ScatterRow {
    /// The method's label.
    pub method: &'static str,
    /// N.
    pub mesh_size: usize,
    /// α used.
    pub alpha: f64,
    /// The interior multiplier as the method reads it.
    pub interior: Option<InteriorMultiplier>,
    /// The layer profile next to the free boundary.
    pub layer: Vec<LayerBand>,
    /// `∫λ_h`.
    pub total_contact_force: f64,
    /// J_h.
    pub energy: f64,
}

/// The λ-scatter study on `scene` at load `load` (flat obstacle): every method of
/// [`SCATTER_METHODS`] on every N of `meshes`.
///
/// # Errors
/// [`solve`]'s.
pub fn scatter_study(
    scene: KirchhoffScene,
    load: f64,
    meshes: &[usize],
) -> Result<Vec<ScatterRow>> {
    let mut rows = Vec::new();
    for method in SCATTER_METHODS {
        // the other pairs take minutes beyond N = 64 (Argyris–P1disc: 30 and more
        // Newton iterations a level); their trend is clear by then
        let largest = if method.pair == KirchhoffPair::ArgyrisP0 {
            usize::MAX
        } else {
            64
        };
        for &mesh_size in meshes.iter().filter(|&&n| n <= largest) {
            let mut request = KirchhoffRequest {
                pair: method.pair,
                mesh_size,
                load,
                obstacle: FLAT_OBSTACLE,
                ..KirchhoffRequest::new(scene)
            };
            if let Some(a) = method.alpha {
                request.alpha = Some(match method.pair {
                    KirchhoffPair::MorleyP0 => a,
                    _ => {
                        let c_i = match method.pair {
                            KirchhoffPair::ArgyrisP1disc => {
                                request.alpha_on::<kirchhoff_argyris_p1disc::Model>()?.1
                            }
                            _ => request.alpha_on::<kirchhoff_argyris_p0::Model>()?.1,
                        };
                        a / c_i
                    }
                });
            }
            let r = solve(&request)?;
            rows.push(ScatterRow {
                method: method.label,
                mesh_size,
                alpha: r.alpha,
                interior: match method.recovery {
                    MultiplierRecovery::Raw => r.interior_multiplier_raw,
                    MultiplierRecovery::PatchAverage => r.interior_multiplier,
                    MultiplierRecovery::TwicePatchAverage => r.interior_multiplier_twice_averaged,
                },
                total_contact_force: r.total_contact_force,
                energy: r.energy,
                layer: r.multiplier_layer,
            });
        }
    }
    Ok(rows)
}

/// The λ-scatter study as the CLI runs it (`study kirchhoff-obstacle lambda-scatter`):
/// [`scatter_study`] at q = 20 on N = 16, 32, 64 (and 128 with `full`), a table, the CSV
/// and the chart of the interior band `[min, max]/q` against N, one pair of lines per
/// method.
///
/// # Errors
/// [`scatter_study`]'s, and [`Error::Input`] when a file cannot be written.
pub fn scatter_run(scene: KirchhoffScene, full: bool, out: &Path) -> Result<()> {
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
        "{:<34} {:>4} {:>10} {:>6} {:>10} {:>10} {:>10} {:>10} {:>11}",
        "method", "N", "α", "cells", "min", "max", "mean", "max|err|/q", "∫λ_h"
    );
    let mut csv = String::from(
        "method,mesh_size,alpha,cells,min,max,mean,max_relative_error,total_contact_force,energy\n",
    );
    for r in &rows {
        let i = r.interior;
        let cell = |f: fn(&InteriorMultiplier) -> f64| i.as_ref().map_or(f64::NAN, f);
        println!(
            "{}",
            crate::dash_nan(format!(
                "{:<34} {:>4} {:>10.3e} {:>6} {:>10.4} {:>10.4} {:>10.4} {:>10.2e} {:>11.6}",
                r.method,
                r.mesh_size,
                r.alpha,
                i.map_or(0, |i| i.cells),
                cell(|i| i.min),
                cell(|i| i.max),
                cell(|i| i.mean),
                cell(|i| i.max_relative_error),
                r.total_contact_force
            ))
        );
        csv += &format!(
            "{},{},{:e},{},{:e},{:e},{:e},{:e},{:e},{:e}\n",
            r.method,
            r.mesh_size,
            r.alpha,
            i.map_or(0, |i| i.cells),
            cell(|i| i.min),
            cell(|i| i.max),
            cell(|i| i.mean),
            cell(|i| i.max_relative_error),
            r.total_contact_force,
            r.energy
        );
    }
    write_text(
        &out.join(format!("{}-lambda-scatter.csv", scene.name)),
        &csv,
    )?;
    let mut series = Vec::new();
    for method in SCATTER_METHODS {
        let mine: Vec<&ScatterRow> = rows.iter().filter(|r| r.method == method.label).collect();
        let band = |f: fn(&InteriorMultiplier) -> f64| -> Vec<(f64, f64)> {
            mine.iter()
                .filter_map(|r| {
                    r.interior
                        .as_ref()
                        .map(|i| (r.mesh_size as f64, f(i) / load))
                })
                .collect()
        };
        series.push(crate::plot::Series::marked(
            format!("{} max", method.label),
            band(|i| i.max),
        ));
        series.push(crate::plot::Series::marked(
            format!("{} min", method.label),
            band(|i| i.min),
        ));
    }
    // the layer next to the free boundary, Argyris–P0 at the C_I rule, per N
    let mut layer_series = Vec::new();
    let mut layer_csv = String::from(
        "mesh_size,distance_in_cells,cells,max_relative_error,patch_average_max_relative_error\n",
    );
    println!("\nλ_h next to the free boundary ({}): max |λ − q|/q per band of one cell diameter, raw / patch average", SCATTER_METHODS[0].label);
    for r in rows.iter().filter(|r| r.method == SCATTER_METHODS[0].label) {
        let bands: Vec<String> = r
            .layer
            .iter()
            .map(|b| {
                format!(
                    "{:.0e}/{:.0e}",
                    b.max_relative_error, b.patch_average_max_relative_error
                )
            })
            .collect();
        println!("  N = {:>3}: {}", r.mesh_size, bands.join(" "));
        for b in &r.layer {
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
            r.layer
                .iter()
                .filter(|b| b.cells > 0)
                .map(|b| (b.distance_in_cells as f64, f(b).max(1e-8)))
                .collect()
        };
        layer_series.push(crate::plot::Series::marked(
            format!("raw N = {}", r.mesh_size),
            at(|b| b.max_relative_error),
        ));
        layer_series.push(crate::plot::Series::line(
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
        crate::plot::Axes {
            x: "distance from the free boundary / cell diameter",
            y: "max |λ_h − q| / q",
            log_x: false,
            log_y: true,
        },
        &layer_series,
    )?;
    chart(
        &out.join(format!("{}-lambda-scatter.svg", scene.name)),
        &format!(
            "{}: λ_h / q over the contact interior (min and max), q = {load}",
            scene.name
        ),
        crate::plot::Axes {
            x: "N (N×N×2 mesh)",
            y: "λ_h / q",
            log_x: true,
            log_y: false,
        },
        &series,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ring of contact cells around a hole: the hole counts, the cells outside the
    /// ring do not; without contact the area is +0.
    #[test]
    fn the_contact_area_fills_holes_but_not_the_outside() {
        let mesh = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 5, 5, Diagonal::Right).unwrap();
        let centre = |c: usize| {
            let x = mesh.cell_coordinates(c);
            [(x[0] + x[2] + x[4]) / 3.0, (x[1] + x[3] + x[5]) / 3.0]
        };
        // the cells of the squares 1..4 × 1..4 (in units of 0.2) except the middle one
        let contact: Vec<bool> = (0..mesh.cell_count())
            .map(|c| {
                let [x, y] = centre(c).map(|v| (v * 5.0).floor() as i32);
                (1..4).contains(&x) && (1..4).contains(&y) && !(x == 2 && y == 2)
            })
            .collect();
        assert_eq!(contact.iter().filter(|&&c| c).count(), 16);
        let area = filled_area(&mesh, &contact);
        assert!((area - 9.0 * 0.04).abs() < 1e-12, "{area}");
        let none = filled_area(&mesh, &vec![false; mesh.cell_count()]);
        assert!(none == 0.0 && none.is_sign_positive());
    }

    /// The contact interior and its distances: on a contact disk, interior cells are at
    /// least the margin from the outside and two rings in; the layer bands count every
    /// contact cell once.
    #[test]
    fn interior_cells_keep_their_distance_from_the_free_boundary() {
        let mesh = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 32, 32, Diagonal::Right).unwrap();
        let centre = |c: usize| {
            let x = mesh.cell_coordinates(c);
            [(x[0] + x[2] + x[4]) / 3.0, (x[1] + x[3] + x[5]) / 3.0]
        };
        let contact: Vec<bool> = (0..mesh.cell_count())
            .map(|c| {
                let [x, y] = centre(c);
                (x - 0.5).hypot(y - 0.5) < 0.3
            })
            .collect();
        let distance = frontier_distances(&mesh, &contact);
        let interior = interior_cells(&mesh, &contact);
        assert!(!interior.is_empty());
        let h = mesh.max_h();
        let radius = |c: usize| (centre(c)[0] - 0.5).hypot(centre(c)[1] - 0.5);
        for &c in &interior {
            // the cells outside the disk next to it surround r = 0.3 within a diameter
            assert!(radius(c) < 0.3 - INTERIOR_MARGIN + h, "cell {c}");
            assert!(distance[c] >= INTERIOR_MARGIN);
        }
        // and every cell well inside is interior: two vertex rings lie within 4 h
        for c in (0..mesh.cell_count()).filter(|&c| radius(c) < 0.3 - INTERIOR_MARGIN - 4.0 * h) {
            assert!(interior.contains(&c), "cell {c} at r = {}", radius(c));
        }
        // a cell right at the edge of the disk is not interior
        let edge = (0..mesh.cell_count())
            .filter(|&c| contact[c])
            .max_by(|&a, &b| radius(a).total_cmp(&radius(b)))
            .unwrap();
        assert!(!interior.contains(&edge));
        assert!(distance[edge] < 2.0 * h);
    }
}
