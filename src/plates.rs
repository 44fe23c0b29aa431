//! The plate scenes (docs/mathematics.md §6): a Reissner–Mindlin plate on the mesh of its
//! domain (the N×N×2 mesh of a square, the N-ring mesh of a disk), held by its support,
//! under its load and against its obstacle, solved as an obstacle problem with nested
//! iteration; the report of `solve --json`; and the plate studies (locking as t → 0,
//! Newton iterations per level, convergence of J_h, ∫λ_h and the contact radius).
//!
//! A scene is data ([`PlateScene`]: domain, support, load, obstacle); the pairs are a
//! table ([`PlatePair`] with one row each naming the model of each support). Adding a
//! scene is one constant in `models/src/plate_scenes.rs`, a pair one row here.

use crate::models::mindlin::{mindlin_plain_p1, mindlin_simply_supported, mindlin_stenberg};
use crate::models::plate_scenes::{PlateDomain, PlateObstacle, PlateScene, PlateSupport};
use crate::studies::{io, output, write_csv, Study};
use fem_runtime::element::triangle::{TriangleBasis, TriangleField};
use fem_runtime::mesh::triangle::QuadraticGeometry;
use fem_runtime::mesh::CurvedTriangleMesh;
use fem_runtime::obstacle::ObstacleSolution;
use fem_runtime::problem::{Domain, MemoryModel, ObstacleSide, Problem, Report};
use fem_runtime::reference::triangle::TriangleRule;
use fem_runtime::stabilization::Alpha;
use fem_runtime::{
    Diagonal, DirichletPart, DofNumbering, Error, Model, PointLocator, Result, TriangleMesh,
};
use serde::Serialize;
use std::path::Path;

/// The Stenberg parameter β of the shear weight `6κ(1−ν)D/(t² + β h_T²)` (§6: β ≤ 0.01
/// brings back coarse-mesh locking, β ≥ 0.3 loses accuracy).
pub const STENBERG_BETA: f64 = 0.1;
/// The default stabilization parameter α (§6: α = 1 is 5–10× less accurate, α ≤ 0.01
/// breaks the solver on fine meshes).
pub const PLATE_ALPHA: f64 = 0.1;
/// The largest N of the N×N×2 mesh a plate solve accepts; below it the memory the solve
/// would need is checked too ([`estimated_memory_bytes`]: about 5.5 GB at 512, 24 GB at 1024).
pub const MAX_PLATE_MESH_SIZE: usize = 1024;
/// The most rings of a disk mesh a plate solve accepts (6N² triangles: 393k at 256,
/// measured 53 s and 8.8 GB on curved cells; 512 rings ran out of 24 GB).
pub const MAX_DISK_RINGS: usize = 256;
/// The largest |q| and |ψ| accepted: beyond it the norms that certify a solve (the KKT
/// residual's `‖A‖∞‖U‖∞`) may overflow double precision.
pub const MAX_PLATE_DATA: f64 = 1e100;
/// The thinnest plate a solve accepts.
pub const MIN_PLATE_THICKNESS: f64 = 1e-8;
/// The largest rounding of the primal unknowns through the contact rows, relative to
/// the larger of max|w_h|, |ψ| and 1e-6 of the domain's size, accepted in a result
/// (fem_runtime `Lcp::primal_rounding`; the membranes' bound).
pub const MAX_PRIMAL_ROUNDING: f64 = 1e-3;

/// Rounding of w_h through the contact rows, relative to its size, above which a plate
/// solve warns (as beams and membranes do from 1e-8).
pub const ROUNDING_WARNING: f64 = 1e-8;
/// The coarsest level of a nested solve: N/2^k ≥ this (N×N×2 squares, or rings).
pub const COARSEST_LEVEL: usize = 4;

/// The discretizations of the plate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlatePair {
    /// θ ∈ [P1]², w ∈ P2, λ ∈ P0 with the Stenberg shear weight: locking-free.
    P1P2P0,
    /// θ ∈ [P1]², w ∈ P1, λ ∈ P0 with the physical shear weight: locks as t → 0.
    P1P1P0Plain,
}

/// A plate solve instantiated for one model.
type PlateRun = fn(&PlateRequest) -> Result<PlateReport>;

/// A pair as data: its name and the model of each support (`None`: not available).
struct PairRow {
    pair: PlatePair,
    name: &'static str,
    clamped: Option<PlateRun>,
    simply_supported: Option<PlateRun>,
}

/// Every pair, in the order of [`PlatePair::ALL`].
const PAIRS: [PairRow; 2] = [
    PairRow {
        pair: PlatePair::P1P2P0,
        name: "p1-p2-p0",
        clamped: Some(solve_with::<mindlin_stenberg::Model>),
        simply_supported: Some(solve_with::<mindlin_simply_supported::Model>),
    },
    PairRow {
        pair: PlatePair::P1P1P0Plain,
        name: "p1-p1-p0-plain",
        clamped: Some(solve_with::<mindlin_plain_p1::Model>),
        simply_supported: None,
    },
];

impl PlatePair {
    /// Every pair, the default first.
    pub const ALL: [PlatePair; 2] = [PlatePair::P1P2P0, PlatePair::P1P1P0Plain];

    fn row(self) -> &'static PairRow {
        let row = &PAIRS[self as usize];
        debug_assert_eq!(row.pair, self);
        row
    }

    /// The pair's name (`--pair`).
    pub fn name(self) -> &'static str {
        self.row().name
    }

    /// Whether the pair has a model for `support`.
    pub fn supports(self, support: PlateSupport) -> bool {
        self.run(support).is_some()
    }

    fn run(self, support: PlateSupport) -> Option<PlateRun> {
        match support {
            PlateSupport::Clamped => self.row().clamped,
            PlateSupport::SimplySupported => self.row().simply_supported,
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
    /// The mesh size: N of the square's N×N×2 mesh, 1 ≤ N ≤ [`MAX_PLATE_MESH_SIZE`], or
    /// the disk's rings, 1 ≤ N ≤ [`MAX_DISK_RINGS`].
    pub mesh_size: usize,
    /// Uniform load q (along w, per area; w is positive up).
    pub load: f64,
    /// Stabilization parameter α > 0.
    pub alpha: f64,
    /// Whether the scene's obstacle is in place (`false`: `--no-obstacle`, the
    /// unobstructed plate, checked against its closed form where there is one).
    pub obstacle: bool,
    /// Nested iteration over the meshes N/2^k ≥ [`COARSEST_LEVEL`], …, N (`false`: a
    /// cold start on mesh N).
    pub nested: bool,
}

impl PlateRequest {
    /// The scene's defaults: the default pair, its thickness, mesh, load and α, its
    /// obstacle in place; nested iteration where the scene has an obstacle (without
    /// contact the problem is linear and one Newton step solves it from any start).
    pub fn new(scene: PlateScene) -> Self {
        Self {
            scene,
            pair: PlatePair::P1P2P0,
            thickness: scene.thickness,
            mesh_size: scene.mesh_size,
            load: scene.load,
            alpha: PLATE_ALPHA,
            obstacle: true,
            nested: scene.obstacle != PlateObstacle::None,
        }
    }

    /// The obstacle solved against: the scene's, or none with `obstacle` off.
    pub fn obstacle(&self) -> PlateObstacle {
        if self.obstacle {
            self.scene.obstacle
        } else {
            PlateObstacle::None
        }
    }

    /// Checks the request.
    ///
    /// # Errors
    /// [`Error::Input`] naming the value at fault: t ≤ 0 or t above the domain's size
    /// (the side of a square, the diameter of a disk), ν outside (−1, ½), a mesh size of
    /// 0 or above [`MAX_PLATE_MESH_SIZE`] ([`MAX_DISK_RINGS`]), α ≤ 0, a load or obstacle
    /// height that is not finite or beyond ±[`MAX_PLATE_DATA`], a material or domain
    /// value that is not positive and finite, a pair without a model for the support,
    /// and an obstacle that contradicts the support (`s(g − ψ) < 0` on the boundary,
    /// where w = g = 0).
    pub fn validate(&self) -> Result<()> {
        let s = &self.scene;
        let bad = |what: String| Err(Error::Input(what));
        if !(self.thickness.is_finite() && self.thickness > 0.0) {
            return bad(format!(
                "thickness t = {} must be positive and finite",
                crate::number(self.thickness)
            ));
        }
        if self.thickness < MIN_PLATE_THICKNESS {
            return bad(format!(
                "thickness t = {:e} is below {MIN_PLATE_THICKNESS:e}: the Mindlin plate is then Kirchhoff's to t² (rounding), and the plain pair's shear weight 6κ(1−ν)D/t² overflows; use t ≥ {MIN_PLATE_THICKNESS:e}",
                self.thickness
            ));
        }
        let (size, size_name) = match s.domain {
            PlateDomain::Square { side } => (side, "side"),
            PlateDomain::Disk { radius } => (2.0 * radius, "diameter"),
        };
        if !(size.is_finite() && size > 0.0) {
            return bad(format!(
                "the plate's {size_name} {size} must be positive and finite"
            ));
        }
        if self.thickness > size {
            return bad(format!(
                "thickness t = {} exceeds the plate's {size_name} {size}: plate theory describes thin bodies (t well below the {size_name}); a thicker body is a problem of elasticity",
                crate::number(self.thickness)
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
        if !self.load.is_finite() {
            return bad(format!("load q = {} must be finite", self.load));
        }
        if self.load.abs() > MAX_PLATE_DATA {
            return bad(format!(
                "load q = {:e} is beyond ±{MAX_PLATE_DATA:e}: norms in the solve would overflow double precision",
                self.load
            ));
        }
        let largest = match s.domain {
            PlateDomain::Square { .. } => MAX_PLATE_MESH_SIZE,
            PlateDomain::Disk { .. } => MAX_DISK_RINGS,
        };
        if self.mesh_size == 0 || self.mesh_size > largest {
            return bad(format!(
                "mesh size N = {} must lie in 1..={largest}",
                self.mesh_size
            ));
        }
        if !(self.alpha.is_finite() && self.alpha > 0.0) {
            return bad(format!(
                "α = {} must be positive and finite (α = 0 leaves the multiplier undetermined where there is no contact)",
                self.alpha
            ));
        }
        if !self.pair.supports(s.support) {
            return bad(format!(
                "pair {} has no {} model; the pairs for it are {}",
                self.pair.name(),
                s.support.name(),
                PlatePair::ALL
                    .into_iter()
                    .filter(|p| p.supports(s.support))
                    .map(PlatePair::name)
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
        if let Some((side, height)) = self.obstacle().side_and_height() {
            if !height.is_finite() || height.abs() > MAX_PLATE_DATA {
                return bad(format!(
                    "obstacle height ψ = {height} must be finite and within ±{MAX_PLATE_DATA:e}"
                ));
            }
            // the support fixes w = g = 0 on the whole boundary, where w must also obey
            // s·w ≥ s·ψ: no admissible deflection exists if s(g − ψ) < 0 there
            if side * (0.0 - height) < 0.0 {
                return bad(format!(
                    "the obstacle ({}) contradicts the {} boundary, where w = 0: s(g − ψ) = {} < 0 on the whole boundary, so no admissible deflection exists",
                    self.obstacle().describe(),
                    s.support.name(),
                    side * (0.0 - height)
                ));
            }
        }
        Ok(())
    }
}

/// The report of a plate solve (`solve --json`). Fields marked optional are left out of
/// the JSON where they do not apply.
#[derive(Clone, Debug, Serialize)]
pub struct PlateReport {
    /// Scene name.
    pub scene: String,
    /// Pair name.
    pub pair: &'static str,
    /// Support (`clamped`, `simply-supported`).
    pub support: &'static str,
    /// The domain (`unit square`, `disk of radius 1`).
    pub domain: String,
    /// The obstacle solved against (`none`, `flat above, w ≤ 0.05`).
    pub obstacle: String,
    /// Thickness t.
    pub thickness: f64,
    /// N of the N×N×2 mesh, or the disk's rings.
    pub mesh_size: usize,
    /// Triangles of the (finest) mesh.
    pub triangles: usize,
    /// Load q.
    pub load: f64,
    /// α of the stabilization; `null` without an obstacle, where there is no multiplier
    /// for it to act on.
    pub alpha: Option<f64>,
    /// w_h at the centre of the domain.
    pub centre_deflection: f64,
    /// The Kirchhoff centre deflection without contact (the limit as t → 0).
    pub kirchhoff_reference: f64,
    /// The exact Mindlin centre deflection without contact where it has a closed form
    /// (the clamped disk: `q R⁴/(64D) + q R²/(4S)`); only without an obstacle.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unobstructed_reference: Option<f64>,
    /// Without an obstacle: the centre deflection `relative_error` is measured against
    /// (`unobstructed_reference` where there is one, else `kirchhoff_reference`); the
    /// field of the same name in the Kirchhoff plates' report.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reference_centre_deflection: Option<f64>,
    /// `(w_h(centre) − w_ref)/w_ref` without an obstacle, against
    /// `unobstructed_reference` where there is one, else against `kirchhoff_reference`
    /// (then it includes the O(t²) Mindlin–Kirchhoff difference, about 20 t² for the
    /// clamped square). NaN (left out of the JSON) with an obstacle in place.
    #[serde(skip_serializing_if = "is_nan")]
    pub relative_error: f64,
    /// `J_h = ½UᵀA_hU − FᵀU` with the Stenberg (or, for the plain pair, physical) weight.
    pub energy: f64,
    /// The largest |w_h| over the DOF values of w.
    pub max_deflection: f64,
    /// `∫w_h`, the volume swept by the plate: with J_h and ∫λ_h it checks the energy,
    /// since testing the equilibrium with u_h gives `J_h = −½ q∫w_h + ½ ∫ s w_h λ_h`,
    /// and `∫ s w_h λ_h = s ψ ∫λ_h` for a flat obstacle up to the O(α h⁴) stabilization.
    pub deflection_integral: f64,
    /// `∫λ_h` (0: the obstacle is out of reach).
    pub total_contact_force: f64,
    /// Area of the contact set: the cells whose multiplier is active or whose constraint
    /// holds with equality (holes of zero λ_h filled).
    pub contact_area: f64,
    /// With an obstacle: the mean, over 360 rays from the centre, of the radius at which
    /// the ray leaves the contact cells of `contact_area` (the outer radius of the active
    /// cells along rays; O(h), unlike `√(area/π)` it does not count holes or the jagged
    /// edge twice). 0 without contact.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact_radius: Option<f64>,
    /// With contact: the mean of λ_h over the contact interior (the contact cells whose
    /// centroid lies within `contact_radius / 2`: the line force at the edge of contact,
    /// a layer of width O(t) in the plate, is smeared over several cells of λ_h; on the
    /// disk at q = 20 λ_h departs from q by 1e-3 at 0.45 r_c on 32 rings, at 0.6 r_c on
    /// 64). A flat
    /// obstacle there holds w constant and θ = 0, so the contact equation
    /// `div div Cε(θ) − sλ = f` gives λ = −s q exactly (q for the disk pushed up).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lambda_interior_mean: Option<f64>,
    /// `(max − min)/|mean|` of λ_h over that contact interior: its smoothness.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lambda_interior_spread: Option<f64>,
    /// KKT residual of the solution.
    pub complementarity_residual: f64,
    /// Number of unknowns (all fields, multiplier included).
    pub dofs: usize,
    /// Newton iterations on the finest mesh.
    pub iterations: usize,
    /// `[triangles, iterations]` of each level of the nested iteration.
    pub levels: Vec<[usize; 2]>,
    /// Wall time of the solve, assembly included.
    pub seconds: f64,
    /// The largest penetration `s(ψ − w_h)` at the nodes of w_h (0 without an obstacle or
    /// where the plate stays on its side).
    pub max_penetration: f64,
    /// The largest clearance of a cell where λ_h pushes (0 for a real contact set; see
    /// `fem_runtime::obstacle::triangle::max_open_contact_gap`), warned above 1 % of
    /// the obstacle's height.
    pub max_open_contact_gap: f64,
    /// Warnings (a visible penetration of the obstacle).
    pub warnings: Vec<String>,
}

fn is_nan(v: &f64) -> bool {
    v.is_nan()
}

fn zero(_: &[f64]) -> f64 {
    0.0
}

/// Solves `request`.
///
/// # Errors
/// [`PlateRequest::validate`]'s, the solver's if it does not converge, and
/// [`Error::Input`] when the load (or α) dwarfs the obstacle so that w_h is rounding (its
/// rounding through the contact rows above [`MAX_PRIMAL_ROUNDING`]).
pub fn solve(request: &PlateRequest) -> Result<PlateReport> {
    request.validate()?;
    check_memory(request)?;
    let run = request
        .pair
        .run(request.scene.support)
        .ok_or_else(|| Error::Input("no model for this support".into()))?;
    run(request)
}

/// The peak memory of a Mindlin solve, in bytes per triangle, `a + b·log₂(triangles)`
/// (the direct factor's fill grows like `T log T`), for the square (N×N×2, affine cells)
/// and the disk (6N² cells, curved at the boundary). Measured peaks of `p1-p2-p0`
/// (2026-12-01; the plain pair needs less): square 289 MB at N = 128, 1.23 GB at 256,
/// 5.45 GB at 512; disk 378 MB at 64 rings, 1.79 GB at 128, 8.8 GB at 256.
/// The disk's fit is floored at the 15 kB a triangle measured on its smallest meshes.
const PLATE_BYTES_PER_TRIANGLE: [(f64, f64, f64); 2] =
    [(2.8e3, 0.4e3, 0.0), (-16.7e3, 2.1e3, 15e3)];

/// The estimated peak memory of `request`'s solve, in bytes ([`PLATE_BYTES_PER_TRIANGLE`]).
pub fn estimated_memory_bytes(request: &PlateRequest) -> f64 {
    let n = request.mesh_size as f64;
    let (triangles, (a, b, floor)) = match request.scene.domain {
        PlateDomain::Square { .. } => (2.0 * n * n, PLATE_BYTES_PER_TRIANGLE[0]),
        PlateDomain::Disk { .. } => (6.0 * n * n, PLATE_BYTES_PER_TRIANGLE[1]),
    };
    triangles * (a + b * triangles.max(1.0).log2()).max(floor)
}

/// Refuses a mesh size whose estimated peak memory exceeds what the solver allows itself
/// ([`crate::membranes::memory_limit_bytes`]), before any allocation: the factor's
/// allocation failing later aborts the process (`mindlin-square --mesh-size 1024` needs
/// about 24 GB).
fn check_memory(request: &PlateRequest) -> Result<()> {
    match crate::membranes::beyond_memory(estimated_memory_bytes(request)) {
        Some(m) => Err(Error::Input(format!(
            "--mesh-size {} {m}; a smaller N does (the memory grows about 4× per doubling)",
            request.mesh_size
        ))),
        None => Ok(()),
    }
}

/// The mesh of `domain` with size `n`: the N×N×2 mesh of the square (diagonals to the
/// right), the ring mesh of the disk ([`TriangleMesh::disk`]: its boundary vertices lie
/// on the circle; the solve curves its boundary edges with `QuadraticGeometry::circle`).
///
/// # Errors
/// The mesh generator's, for a size of 0 or a domain that is not finite.
pub fn plate_mesh(domain: PlateDomain, n: usize) -> Result<TriangleMesh> {
    match domain {
        PlateDomain::Square { side } => {
            TriangleMesh::rectangle(0.0, side, 0.0, side, n, n, Diagonal::Right)
        }
        PlateDomain::Disk { radius } => TriangleMesh::disk(domain.centre(), radius, n),
    }
}

/// The mesh sizes of a solve: N/2^k ≥ [`COARSEST_LEVEL`], …, N with nesting (halving
/// while even), just N without.
pub fn level_sizes(n: usize, nested: bool) -> Vec<usize> {
    let mut sizes = vec![n];
    while nested && sizes[0] % 2 == 0 && sizes[0] / 2 >= COARSEST_LEVEL {
        sizes.insert(0, sizes[0] / 2);
    }
    sizes
}

/// What the report reads from a solution on straight (affine) or curved cells: the
/// straight mesh (point location, cell lists), field views (evaluated in reference
/// coordinates, exact on either kind of cell), and the integrals over the cells' own
/// measures.
trait PlateCells {
    /// The mesh of straight cells (the curved one's vertices and cells).
    fn straight(&self) -> &TriangleMesh;
    /// The view of a field.
    fn field_view(&self, field: usize) -> TriangleField<'_>;
    /// The contact area over the cells.
    fn area_in_contact(&self) -> f64;
    /// `∫ u_h` of `field` over the cells.
    fn integral(&self, field: usize) -> f64;
}

impl PlateCells for ObstacleSolution<TriangleMesh> {
    fn straight(&self) -> &TriangleMesh {
        &self.discretization.mesh
    }
    fn field_view(&self, field: usize) -> TriangleField<'_> {
        self.view(field)
    }
    fn area_in_contact(&self) -> f64 {
        self.contact_area()
    }
    fn integral(&self, field: usize) -> f64 {
        self.view(field).integral()
    }
}

impl PlateCells for ObstacleSolution<CurvedTriangleMesh> {
    fn straight(&self) -> &TriangleMesh {
        self.discretization.mesh.mesh()
    }
    fn field_view(&self, field: usize) -> TriangleField<'_> {
        self.view(field)
    }
    fn area_in_contact(&self) -> f64 {
        self.contact_area()
    }
    /// The isoparametric field is its reference polynomial on each cell, so the integral
    /// is `Σ_T ∫_T̂ u(ξ) |det J(ξ)| dξ`, with a rule two degrees above the field's for the
    /// map's Jacobian (a polynomial of degree 2 on quadratic cells).
    fn integral(&self, field: usize) -> f64 {
        let view = self.view(field);
        let basis = TriangleBasis::new(view.map.element());
        let rule = TriangleRule::exact_for_degree(view.map.element().degree() + 2);
        let mesh = &self.discretization.mesh;
        (0..mesh.mesh().cell_count())
            .map(|c| {
                let map = mesh.cell_map(c);
                rule.integrate(|xi| view.value(&basis, c, xi) * map.det(xi).abs())
            })
            .sum()
    }
}

/// Solves the plate on its meshes, coarsest first (each level started from the one
/// before), through the runtime's one pipeline: on straight cells for the square, on
/// isoparametric (quadratic-geometry) cells for the disk, whose boundary edges follow the
/// circle (`QuadraticGeometry::circle`; docs/mathematics.md §8: the polygon adds ~3e-4
/// relative to J).
fn solve_with<M: Model>(request: &PlateRequest) -> Result<PlateReport> {
    let s = &request.scene;
    // without an obstacle the plate is one linear solve: the nested start serves contact
    // (mindlin-disk --no-obstacle solved five levels of one iteration each)
    let nested = request.nested && request.obstacle() != PlateObstacle::None;
    let sizes = level_sizes(request.mesh_size, nested);
    let coarse_start = nested
        .then(|| cold_coarsest_warning(&sizes, COARSEST_LEVEL))
        .flatten();
    let meshes = sizes
        .into_iter()
        .map(|n| plate_mesh(s.domain, n))
        .collect::<Result<Vec<_>>>()?;
    let h = meshes.last().map_or(0.0, |m| m.max_h());
    let mut report = match s.domain {
        PlateDomain::Square { .. } => solve_on::<M, _>(request, meshes),
        PlateDomain::Disk { radius } => {
            let curved = meshes
                .into_iter()
                .map(|mesh| {
                    let geometry = QuadraticGeometry::circle(&mesh, s.domain.centre(), radius)?;
                    CurvedTriangleMesh::new(mesh, geometry)
                })
                .collect::<Result<Vec<_>>>()?;
            solve_on::<M, _>(request, curved)
        }
    }?;
    report.warnings.extend(coarse_start);
    report
        .warnings
        .extend(locking_warning(request.pair, h, request.thickness));
    Ok(report)
}

/// The plate's problem on `meshes` and its report.
fn solve_on<M: Model, G>(request: &PlateRequest, meshes: Vec<G>) -> Result<PlateReport>
where
    G: Domain,
    ObstacleSolution<G>: PlateCells,
{
    let (params, side, height) = plate_parameters::<M>(request);
    let q = request.load;
    let load = move |_: &[f64]| q;
    let obstacle = move |_: &[f64]| height;
    let mut problem = Problem::<M, G>::new(meshes)
        .data("f", &load)
        .data("ψ", &obstacle)
        .data("g", &zero)
        .boundary_data(DirichletPart::All)
        .side(side)
        .alpha(Alpha::Fixed(request.alpha), PLATE_ALPHA)
        .memory(
            MemoryModel::per_cell(estimated_memory_bytes(request) / triangles_of(request)),
            format!("--mesh-size {}", request.mesh_size),
        );
    for (name, value) in params {
        problem = problem.param(name, value);
    }
    let solved = problem.solve()?;
    report::<M, G>(request, &solved.solution, &solved.report)
}

/// The triangles of the finest mesh of `request` (the square's 2N², the disk's 6N²).
fn triangles_of(request: &PlateRequest) -> f64 {
    let n = request.mesh_size as f64;
    match request.scene.domain {
        PlateDomain::Square { .. } => 2.0 * n * n,
        PlateDomain::Disk { .. } => 6.0 * n * n,
    }
}

/// The warning of the plain pair where it locks: its shear term `t⁻²(∇w − θ)` with
/// w ∈ P1 forces `∇w_h = θ_h` cell by cell as the cells grow against the thickness,
/// and w_h collapses (the locking study: the deflection falls like `(t/h)²`;
/// a mindlin-disk at N = 32 got ∫λ_h = 6.5 against 18.7, without a word).
/// `h` is the largest cell diameter.
fn locking_warning(pair: PlatePair, h: f64, thickness: f64) -> Option<String> {
    // from a tenth of t on: at h ≈ t the deflection is already 12–15 % low (the re-test)
    (pair == PlatePair::P1P1P0Plain && h > 0.1 * thickness).then(|| {
        format!(
            "p1-p1-p0-plain locks here: its cells (h = {h:.2e}) are not small against the plate's thickness (t = {}), and w_h is then stiffened by about (h/t)² = {:.0e}; it is the locking pair of the locking study, shown for comparison: use p1-p2-p0 (the Stenberg pair, locking-free)",
            crate::number(thickness),
            (h / thickness).powi(2)
        )
    })
}

/// The warning of a nested solve whose coarsest level is still fine: the levels halve N
/// while it is even, so an N with few factors of 2 gets no coarse start (a
/// mindlin-disk at N = 63: one level of 14 Newton iterations in 1.56 s, against 3
/// iterations and 0.62 s at N = 64; `--cold` then changed nothing, unsaid). `sizes` are
/// the levels, coarsest first; `coarsest` the smallest N a level may have.
pub(crate) fn cold_coarsest_warning(sizes: &[usize], coarsest: usize) -> Option<String> {
    let (first, last) = (sizes[0], sizes[sizes.len() - 1]);
    // the nearest multiple of 16 nests at least four levels deep
    let suggested = ((last + 8) / 16).max(1) * 16;
    (first >= 4 * coarsest).then(|| {
        let why = if sizes.len() == 1 {
            format!("N = {last} is odd, so it has no coarser nested level: Newton starts cold on it, and --cold changes nothing")
        } else {
            format!("N = {last} halves only down to N = {first}, where it turns odd: Newton starts cold on that level, and --cold changes little")
        };
        format!(
            "{why} (the nested levels halve N while it is even, down to {coarsest}); an N with more factors of 2, such as {suggested}, nests deeper and needs fewer iterations"
        )
    })
}

/// The parameters of `request` for model `M` (all but α and s, which the solve sets),
/// the obstacle's side and its height (far below the plate when the scene has none).
fn plate_parameters<M: Model>(
    request: &PlateRequest,
) -> (Vec<(&'static str, f64)>, ObstacleSide, f64) {
    let s = &request.scene;
    let q = request.load;
    let length = s.domain.length();
    let (side, height) = request.obstacle().side_and_height().unwrap_or_else(|| {
        // an obstacle below every deflection the load can cause (the clamped and the
        // simply supported square stay under 0.005 q a⁴/D, the disk under q R⁴/(64D);
        // the shear adds O(t²) to it), so λ ≡ 0
        let depth = -100.0
            * (q.abs() * length.powi(4) / s.bending_stiffness).max(1.0)
            * (1.0 + (request.thickness / length).powi(2));
        (1.0, depth)
    });
    let mut params = vec![
        ("D", s.bending_stiffness),
        ("ν", s.poisson_ratio),
        ("κ", s.shear_correction),
        ("t", request.thickness),
    ];
    if M::param("β").is_ok() {
        params.push(("β", STENBERG_BETA));
    }
    let side = if side > 0.0 {
        ObstacleSide::Below
    } else {
        ObstacleSide::Above
    };
    (params, side, height)
}

/// The report of a solved plate: the runtime's report and the plate's own quantities.
fn report<M: Model, G: DofNumbering>(
    request: &PlateRequest,
    solution: &ObstacleSolution<G>,
    runtime: &Report,
) -> Result<PlateReport>
where
    ObstacleSolution<G>: PlateCells,
{
    let s = &request.scene;
    let q = request.load;
    let w = M::field("w")?;
    let max_deflection = solution.field(w).iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut warnings = runtime.warnings.clone();
    if request.alpha > 1.0 {
        warnings.push(format!(
            "α = {} is above 1: the stabilization's term α h⁴ s²(λ, μ) then moves the constraint visibly (docs/mathematics.md §6: α = 1 is already 5–10× less accurate than the default {PLATE_ALPHA})",
            request.alpha
        ));
    }
    let centre = value_at(solution, w, s.domain.centre())?;
    let kirchhoff = s.kirchhoff_deflection_at(q);
    let in_contact = request.obstacle() != PlateObstacle::None;
    let unobstructed = if in_contact {
        None
    } else {
        s.mindlin_deflection_at(q, request.thickness)
    };
    // without a closed form for the thick plate, relative_error is against Kirchhoff's
    // t → 0 limit: a thick plate's difference is the models', not the discretization's
    let plate_size = s.domain.size();
    if !in_contact && unobstructed.is_none() && request.thickness > 0.02 * plate_size {
        warnings.push(format!(
            "relative_error compares w_h(centre) with the Kirchhoff plate, the limit t → 0: at t = {} ({:.1} % of the plate's size {plate_size}) it is mostly the O(t²) difference between the Mindlin and Kirchhoff models, not the discretization's error",
            crate::number(request.thickness),
            100.0 * request.thickness / plate_size
        ));
    }
    let contact = ContactGeometry::of(solution, s.domain.centre());
    let mesh = solution.straight();
    Ok(PlateReport {
        scene: s.name.to_string(),
        pair: request.pair.name(),
        support: s.support.name(),
        domain: s.domain.describe(),
        obstacle: request.obstacle().describe(),
        thickness: request.thickness,
        mesh_size: request.mesh_size,
        triangles: mesh.cell_count(),
        load: q,
        alpha: (request.obstacle() != PlateObstacle::None).then_some(request.alpha),
        centre_deflection: centre,
        kirchhoff_reference: kirchhoff,
        unobstructed_reference: unobstructed,
        reference_centre_deflection: (!in_contact).then(|| unobstructed.unwrap_or(kirchhoff)),
        relative_error: if in_contact {
            f64::NAN
        } else {
            let reference = unobstructed.unwrap_or(kirchhoff);
            // q = 0: both deflections are 0 exactly, and so is the error
            if reference == 0.0 && centre == 0.0 {
                0.0
            } else {
                (centre - reference) / reference
            }
        },
        energy: runtime.energy.unwrap_or(f64::NAN),
        max_deflection,
        deflection_integral: solution.integral(w),
        total_contact_force: runtime.total_contact_force,
        contact_area: contact.area,
        contact_radius: in_contact.then_some(contact.radius),
        lambda_interior_mean: contact.interior.map(|(mean, _)| mean),
        lambda_interior_spread: contact.interior.map(|(_, spread)| spread),
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
        max_open_contact_gap: runtime.max_open_contact_gap.unwrap_or(0.0),
        warnings,
    })
}

/// Rays of [`PlateReport::contact_radius`].
const CONTACT_RAYS: usize = 360;

/// The contact set of a solution seen from a centre: its area, its radius along rays,
/// and λ_h over its interior.
struct ContactGeometry {
    area: f64,
    radius: f64,
    /// `(mean, (max − min)/|mean|)` of λ_h over the contact interior, if it has cells.
    interior: Option<(f64, f64)>,
}

impl ContactGeometry {
    fn of<G>(solution: &ObstacleSolution<G>, centre: [f64; 2]) -> Self
    where
        ObstacleSolution<G>: PlateCells,
    {
        let d = &solution.discretization;
        let mesh = solution.straight();
        let contact: Vec<bool> = solution
            .contact_shares()
            .into_iter()
            .map(|share| share > 0.0)
            .collect();
        let locator = PointLocator::new(mesh);
        let h = mesh.max_h();
        let reach = mesh
            .vertices()
            .iter()
            .map(|p| (p[0] - centre[0]).hypot(p[1] - centre[1]))
            .fold(0.0, f64::max);
        let step = h / 8.0;
        let mut total = 0.0;
        for k in 0..CONTACT_RAYS {
            let angle = std::f64::consts::TAU * (k as f64 + 0.5) / CONTACT_RAYS as f64;
            let (cos, sin) = (angle.cos(), angle.sin());
            let mut hint = None;
            let mut r = 0.0;
            // the first point of the ray outside the contact cells (or the mesh)
            while r <= reach {
                let x = [centre[0] + r * cos, centre[1] + r * sin];
                match locator.locate_near(x, hint) {
                    Some((c, _)) if contact[c] => hint = Some(c),
                    _ => break,
                }
                r += step;
            }
            // the exit lies between the last point inside and this one
            total += if r == 0.0 { 0.0 } else { r - 0.5 * step };
        }
        let area = solution.area_in_contact();
        // a contact set that misses the centre's cells (a small one, found only in part)
        // has no ray length: the radius of a disk of its area instead
        let mut radius = total / CONTACT_RAYS as f64;
        if radius == 0.0 && area > 0.0 {
            radius = (area / std::f64::consts::PI).sqrt();
        }
        // the interior must be wider than the layer of the smeared line force at the
        // edge of contact (a few cells), or its mean is that force's, not λ's
        let wide_enough = 0.5 * radius >= 3.0 * h;
        let lambda_cells = solution.field_view(d.multiplier_field).centroid_values();
        let interior: Vec<f64> = (0..mesh.cell_count())
            .filter(|&c| wide_enough && contact[c])
            .filter(|&c| {
                let x = mesh.cell(c).map(|v| mesh.vertices()[v]);
                let centroid = [
                    (x[0][0] + x[1][0] + x[2][0]) / 3.0,
                    (x[0][1] + x[1][1] + x[2][1]) / 3.0,
                ];
                (centroid[0] - centre[0]).hypot(centroid[1] - centre[1]) <= 0.5 * radius
            })
            .map(|c| lambda_cells[c])
            .collect();
        let interior = (!interior.is_empty()).then(|| {
            let mean = interior.iter().sum::<f64>() / interior.len() as f64;
            let max = interior.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
            let min = interior.iter().cloned().fold(f64::INFINITY, f64::min);
            (mean, (max - min) / mean.abs())
        });
        Self {
            area,
            radius,
            interior,
        }
    }
}

/// The value of `field` of `solution` at the point `x` of its mesh.
fn value_at(solution: &impl PlateCells, field: usize, x: [f64; 2]) -> Result<f64> {
    let view = solution.field_view(field);
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
    for pair in PlatePair::ALL
        .into_iter()
        .filter(|p| p.supports(scene.support))
    {
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
    for pair in PlatePair::ALL
        .into_iter()
        .filter(|p| p.supports(scene.support))
    {
        for &n in meshes {
            let points: Vec<(f64, f64)> = reports
                .iter()
                .filter(|r| r.pair == pair.name() && r.mesh_size == n)
                .filter(|r| r.relative_error.is_finite())
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

/// The plate studies a scene may host: `locking` ([`locking_run`]), `iterations`
/// ([`iterations_run`]) and `convergence` ([`convergence_run`]). Each writes
/// `out/<scene>-<study>.svg` and `.csv`.
///
/// # Errors
/// [`Error::Input`] for another study kind, and the study's own.
pub fn run_study(scene: PlateScene, study: Study, full: bool, out: &Path) -> Result<()> {
    match study {
        Study::Locking => locking_run(scene, full, out),
        Study::Iterations => iterations_run(scene, full, out),
        Study::Convergence => convergence_run(scene, full, out),
        other => Err(Error::Input(format!(
            "plate scene `{}` hosts no study `{}`; the plate studies are locking, iterations and convergence",
            scene.name,
            other.name()
        ))),
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
    /// the study's cold limit or where the cold start failed (a result of the study).
    pub cold: Option<usize>,
}

/// The iterations study of `scene` at load `q`: one nested solve on the meshes
/// [`level_sizes`]`(finest)`, its iterations per level, and beside each level a cold
/// start on that level's mesh (up to size `cold_max`).
///
/// # Errors
/// [`solve`]'s for the nested solve.
pub fn iteration_levels(
    scene: PlateScene,
    q: f64,
    finest: usize,
    cold_max: usize,
) -> Result<Vec<IterationLevel>> {
    let nested = solve(&PlateRequest {
        load: q,
        mesh_size: finest,
        nested: true,
        ..PlateRequest::new(scene)
    })?;
    let sizes = level_sizes(finest, true);
    Ok(sizes
        .iter()
        .zip(&nested.levels)
        .map(|(&n, &[triangles, iterations])| IterationLevel {
            load: q,
            mesh_size: n,
            triangles,
            nested: iterations,
            cold: (n <= cold_max)
                .then(|| {
                    solve(&PlateRequest {
                        load: q,
                        mesh_size: n,
                        nested: false,
                        ..PlateRequest::new(scene)
                    })
                    .ok()
                    .map(|r| r.iterations)
                })
                .flatten(),
        })
        .collect())
}

/// The iterations study as the CLI runs it (`study mindlin-disk iterations`): for every
/// load of the scene, [`iteration_levels`] up to N = 32 (128 with `full`), a table, the
/// CSV `load,mesh_size,triangles,nested,cold` and the chart of iterations against N,
/// nested and cold per load: nested iteration stays flat in h, a cold start grows.
///
/// # Errors
/// [`iteration_levels`]'s, and [`Error::Input`] when the output cannot be written.
pub fn iterations_run(scene: PlateScene, full: bool, out: &Path) -> Result<()> {
    let finest = if full { 128 } else { 32 };
    println!(
        "\niterations: {}, semismooth Newton iterations per level of a nested solve, a cold start on the same mesh beside ('-': failed)",
        scene.name
    );
    println!(
        "{:>8} {:>6} {:>10} {:>7} {:>6}",
        "q", "N", "triangles", "nested", "cold"
    );
    let mut rows = Vec::new();
    for &q in scene.loads {
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
    for &q in scene.loads {
        let of = |pick: &dyn Fn(&IterationLevel) -> Option<usize>| -> Vec<(f64, f64)> {
            rows.iter()
                .filter(|r| r.load == q)
                .filter_map(|r| pick(r).map(|c| (r.mesh_size as f64, c.max(1) as f64)))
                .collect()
        };
        series.push(crate::plot::Series::marked(
            format!("nested, q = {q}"),
            of(&|r| Some(r.nested)),
        ));
        series.push(crate::plot::Series::marked(
            format!("cold start, q = {q}"),
            of(&|r| r.cold),
        ));
    }
    let svg = output(out, scene.name, Study::Iterations, "svg");
    crate::plot::chart(
        &svg,
        &format!("{}: Newton iterations per mesh", scene.name),
        crate::plot::Axes {
            x: size_name(scene.domain),
            y: "iterations",
            log_x: true,
            log_y: true,
        },
        &series,
    )
    .map_err(|e| Error::Input(format!("cannot write {}: {e}", svg.display())))?;
    write_csv(
        &output(out, scene.name, Study::Iterations, "csv"),
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

/// What a mesh size counts on `domain`, for axes.
fn size_name(domain: PlateDomain) -> &'static str {
    match domain {
        PlateDomain::Square { .. } => "N (N×N×2 mesh)",
        PlateDomain::Disk { .. } => "rings",
    }
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
    pub report: PlateReport,
}

/// The quantities the convergence study follows, by name: `J_h`, `∫λ_h`, the contact
/// radius.
pub const CONVERGENCE_QUANTITIES: [&str; 3] = ["J_h", "∫λ_h", "contact radius"];

impl ConvergenceRow {
    /// `[J_h, ∫λ_h, contact radius]` (the radius 0 without an obstacle).
    pub fn quantities(&self) -> [f64; 3] {
        [
            self.report.energy,
            self.report.total_contact_force,
            self.report.contact_radius.unwrap_or(0.0),
        ]
    }
}

/// The convergence study of `scene` at load `q`: [`solve`] on each mesh size (nested),
/// one row each. No exact solution is known with contact; [`differences`] gives the
/// changes between meshes and their observed rates.
///
/// # Errors
/// [`solve`]'s.
pub fn convergence_study(
    scene: PlateScene,
    q: f64,
    sizes: &[usize],
) -> Result<Vec<ConvergenceRow>> {
    sizes
        .iter()
        .map(|&n| {
            let report = solve(&PlateRequest {
                load: q,
                mesh_size: n,
                ..PlateRequest::new(scene)
            })?;
            Ok(ConvergenceRow {
                load: q,
                mesh_size: n,
                h: plate_mesh(scene.domain, n)?.max_h(),
                report,
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
/// load of the scene, [`convergence_study`] on N = 8, 16, 32 (up to 128 with `full`);
/// a table of J_h, ∫λ_h and the contact radius with the differences between meshes and
/// their observed rates, the CSV
/// `load,mesh_size,h,dofs,energy,total_contact_force,contact_radius,contact_area,lambda_interior_spread,iterations,seconds`
/// and the chart of |differences| against h (one line per quantity and load).
///
/// # Errors
/// [`convergence_study`]'s, and [`Error::Input`] when the output cannot be written.
pub fn convergence_run(scene: PlateScene, full: bool, out: &Path) -> Result<()> {
    let sizes: &[usize] = if full {
        &[8, 16, 32, 64, 128]
    } else {
        &[8, 16, 32]
    };
    println!(
        "\nconvergence: {} ({}, {}, t = {}), J_h, ∫λ_h and contact radius against h; Δ: change from the mesh before, rate: log2 of the ratio of consecutive Δ",
        scene.name,
        scene.domain.describe(),
        scene.obstacle.describe(),
        scene.thickness
    );
    let mut csv = Vec::new();
    let mut series = Vec::new();
    for &q in scene.loads {
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
            println!("{}", crate::dash_nan(format!(
                "{:>5} {:>8.4} {:>8} {:>16.9e} {:>10.2e} {:>5.2} {:>14.7e} {:>10.2e} {:>5.2} {:>12.6} {:>10.2e} {:>5.2} {:>10.2e} {:>5}",
                r.mesh_size,
                r.h,
                r.report.dofs,
                j,
                entry(&d[0], k, 1),
                entry(&rates[0], k, 2),
                force,
                entry(&d[1], k, 1),
                entry(&rates[1], k, 2),
                radius,
                entry(&d[2], k, 1),
                entry(&rates[2], k, 2),
                r.report.lambda_interior_spread.unwrap_or(f64::NAN),
                r.report.iterations
            )));
            csv.push(vec![
                q,
                r.mesh_size as f64,
                r.h,
                r.report.dofs as f64,
                j,
                force,
                radius,
                r.report.contact_area,
                r.report.lambda_interior_spread.unwrap_or(f64::NAN),
                r.report.iterations as f64,
                r.report.seconds,
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
            series.push(crate::plot::Series::marked(
                format!("|Δ {name}|, q = {q}"),
                points,
            ));
        }
    }
    let svg = output(out, scene.name, Study::Convergence, "svg");
    crate::plot::chart(
        &svg,
        &format!(
            "{}: change of J_h, ∫λ_h and the contact radius to the next mesh",
            scene.name
        ),
        crate::plot::Axes {
            x: "h (largest cell diameter)",
            y: "|change to the next mesh|",
            log_x: true,
            log_y: true,
        },
        &series,
    )
    .map_err(|e| Error::Input(format!("cannot write {}: {e}", svg.display())))?;
    write_csv(
        &output(out, scene.name, Study::Convergence, "csv"),
        "load,mesh_size,h,dofs,energy,total_contact_force,contact_radius,contact_area,lambda_interior_spread,iterations,seconds",
        &csv,
    )
    .map_err(io)?;
    println!("→ {}, .csv", svg.display());
    Ok(())
}
