//! The membrane scenes: element pairs, the stabilization parameter from the computed
//! inverse-inequality constant `C_I`, the solve with its report (the CLI's `--json`),
//! errors against the exact radial solution, and VTK output.

use crate::models::data::Data;
use crate::models::membrane::{membrane_p1, membrane_p1_p0, membrane_p2_p0, membrane_p2_p1disc};
use crate::models::membrane_scenes::{DirichletParts, Domain, Exact, ExactMembrane, MembraneScene};
use fem_runtime::element::triangle::{TriangleBasis, TriangleField};
use fem_runtime::obstacle::hierarchy::LinearSolver;
use fem_runtime::obstacle::{ObstacleOptions, VariationalSolver};
pub use fem_runtime::problem::ALPHA_WHEN_CI_VANISHES;
use fem_runtime::problem::{self, MemoryModel, Problem, SolveOptions};
use fem_runtime::stabilization::{self, Alpha};
use fem_runtime::{
    Coefficients, DataFn, Diagonal, DirichletPart, DofMap, Error, Model, PointLocator, Result,
    TriangleMesh,
};
use serde::Serialize;
use std::time::Instant;

/// The discretizations of the membrane.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MembranePair {
    /// u ∈ P1, λ ∈ P0, stabilized.
    P1P0,
    /// u ∈ P2, λ ∈ P0, stabilized.
    P2P0,
    /// u ∈ P2, λ ∈ P1 discontinuous, stabilized.
    P2P1Disc,
    /// u ∈ P1 with the nodal constraints `u_i ≥ ψ(x_i)` (no multiplier space).
    P1Nodal,
}

/// A pair as data: its name, the degree of u, its measured memory, and its model's
/// solve (instantiated for the model's type). Adding a pair is one row here and its
/// variant of [`MembranePair`].
struct PairRow {
    pair: MembranePair,
    name: &'static str,
    degree: usize,
    /// Measured peak bytes per triangle of the finest mesh (see [`check_memory`]).
    bytes_per_triangle: f64,
    /// The model's solve: (request, posed, meshes) → report and fields.
    run: Run,
    /// `max_T C_I` of the model's stabilization on a mesh (0 for the nodal method).
    inverse_constant: fn(&TriangleMesh) -> Result<f64>,
}

/// A pair's solve: (request, posed, meshes) → report and fields.
type Run =
    fn(&MembraneRequest, &Posed, Vec<TriangleMesh>) -> Result<(MembraneReport, MembraneFields)>;

/// Every pair, in the order of [`MembranePair::ALL`].
const PAIRS: [PairRow; 4] = [
    PairRow {
        pair: MembranePair::P1P0,
        name: "p1-p0",
        degree: 1,
        bytes_per_triangle: 1.6e3,
        run: run::<membrane_p1_p0::Model>,
        inverse_constant: inverse_constant::<membrane_p1_p0::Model>,
    },
    PairRow {
        pair: MembranePair::P2P0,
        name: "p2-p0",
        degree: 2,
        bytes_per_triangle: 6.0e3,
        run: run::<membrane_p2_p0::Model>,
        inverse_constant: inverse_constant::<membrane_p2_p0::Model>,
    },
    PairRow {
        pair: MembranePair::P2P1Disc,
        name: "p2-p1d",
        degree: 2,
        bytes_per_triangle: 7.0e3,
        run: run::<membrane_p2_p1disc::Model>,
        inverse_constant: inverse_constant::<membrane_p2_p1disc::Model>,
    },
    PairRow {
        pair: MembranePair::P1Nodal,
        name: "p1-nodal",
        degree: 1,
        bytes_per_triangle: 0.6e3,
        run: run::<membrane_p1::Model>,
        inverse_constant: |_| Ok(0.0),
    },
];

impl MembranePair {
    /// Every pair.
    pub const ALL: [MembranePair; 4] = [
        MembranePair::P1P0,
        MembranePair::P2P0,
        MembranePair::P2P1Disc,
        MembranePair::P1Nodal,
    ];

    fn row(self) -> &'static PairRow {
        let row = &PAIRS[self as usize];
        debug_assert_eq!(row.pair, self);
        row
    }

    /// The name on the command line.
    pub fn name(self) -> &'static str {
        self.row().name
    }

    /// The pair called `name` (`p2-p1disc` is also read as `p2-p1d`).
    ///
    /// # Errors
    /// [`Error::Input`] naming the pairs for any other name.
    pub fn parse(name: &str) -> Result<Self> {
        // the docs and the Kirchhoff family (`argyris-p1disc`) spell the multiplier
        // space in full: that spelling names the same pair
        let name = if name == "p2-p1disc" { "p2-p1d" } else { name };
        PAIRS
            .iter()
            .find(|p| p.name == name)
            .map(|p| p.pair)
            .ok_or_else(|| {
                Error::Input(format!(
                    "unknown membrane pair `{name}`; the pairs are {}",
                    PAIRS.map(|p| p.name).join(", ")
                ))
            })
    }

    /// Polynomial degree of u.
    pub fn degree(self) -> usize {
        self.row().degree
    }
}

/// What to solve.
#[derive(Clone, Debug)]
pub struct MembraneRequest {
    /// The scene.
    pub scene: MembraneScene,
    /// The load magnitude q: f is q times the scene's load field (`None`: the scene's
    /// own q; an error for a scene whose load is fixed).
    pub load: Option<f64>,
    /// The pair.
    pub pair: MembranePair,
    /// N: an N×N×2 triangle mesh of the scene's square (the L-shape: N×N squares of
    /// (−1,1)², three quarters of them kept).
    pub mesh_size: usize,
    /// The stabilization parameter; `½/C_I` by default. 0 is the plain mixed method.
    pub alpha: Option<f64>,
    /// The LCP solver.
    pub solver: VariationalSolver,
    /// Nested iteration from coarser meshes (N/2, N/4, … ≥ 4).
    pub nested: bool,
    /// The solver of the Newton steps (multigrid needs the nested meshes).
    pub linear_solver: LinearSolver,
    /// Diagonal pattern of the structured mesh.
    pub diagonal: Diagonal,
    /// A Gmsh mesh to solve on instead of the scene's own domain, refined uniformly
    /// `mesh_size` times (each refinement a level of the nested iteration). The scene's
    /// exact constants (∫λ, contact area) are then not reported: they belong to its
    /// own domain.
    pub mesh_file: Option<std::path::PathBuf>,
    /// An L² error of u to check `error_l2` against (a scene file's `accuracy`): a
    /// warning when it is missed or cannot be measured.
    pub accuracy: Option<f64>,
}

impl MembraneRequest {
    /// The defaults: P2–P0, N = 64 (a Gmsh domain: no refinement), the scene's load,
    /// α = ½/C_I, nested semismooth Newton.
    pub fn new(scene: MembraneScene) -> Self {
        let mesh_size = if matches!(scene.domain, Domain::File(_)) {
            0
        } else {
            64
        };
        Self {
            scene,
            load: None,
            pair: MembranePair::P2P0,
            mesh_size,
            alpha: None,
            solver: VariationalSolver::SemismoothNewton,
            nested: true,
            linear_solver: LinearSolver::Auto,
            diagonal: Diagonal::Right,
            mesh_file: None,
            accuracy: None,
        }
    }
}

/// What a membrane solve reports (the CLI's `--json` object).
#[derive(Clone, Debug, Serialize)]
pub struct MembraneReport {
    /// Scene name.
    pub scene: String,
    /// Element pair.
    pub pair: String,
    /// LCP solver.
    pub solver: String,
    /// The solver of the Newton steps on the finest level: `direct` (Cholesky) or
    /// `multigrid` (CG with a W-cycle on the nested meshes) when it solved any step;
    /// `none` for the nodal method when no step had a system to solve (every free node
    /// in contact).
    pub linear_solver: &'static str,
    /// CG iterations over the finest level's multigrid-solved Newton steps.
    pub krylov_iterations: usize,
    /// Newton steps solved by a Cholesky factorization on the finest level (with
    /// multigrid: the steps CG did not finish, and the level's steps after them, plus a
    /// settled system whose polish CG did not finish; normally 0).
    pub factorizations: usize,
    /// The domain solved on: the scene's own, or the Gmsh file given with `--msh`.
    pub domain: String,
    /// Where u = g holds: `["all"]` (the whole boundary) or the names of the boundary
    /// parts; the rest of the boundary has `∂u/∂n = 0`.
    pub dirichlet_parts: Vec<String>,
    /// The load magnitude q (f = q times the scene's load field); `null` where the
    /// scene's load is fixed.
    pub load: Option<f64>,
    /// N of the N×N×2 mesh (with a Gmsh mesh: its uniform refinements).
    pub mesh_size: usize,
    /// Triangles.
    pub triangles: usize,
    /// Unknowns after eliminating boundary DOFs (primal and multiplier).
    pub dofs: usize,
    /// Solver iterations on the final mesh.
    pub iterations: usize,
    /// `[triangles, iterations]` of each nested-iteration level.
    pub levels: Vec<[usize; 2]>,
    /// Wall time of the solve (assembly and all levels).
    pub seconds: f64,
    /// The stabilization parameter used.
    pub alpha: f64,
    /// `max_T C_I` of the mesh (0 where Δ vanishes on the elements).
    pub inverse_constant: f64,
    /// `‖u − u_h‖_L2` where an exact solution exists, with the rule of
    /// [`error_rule_degree`] on each cell (as `error_h1`, `error_multiplier`). On a
    /// `--msh` mesh of another
    /// domain it is still computed from the exact field, which is the solution there
    /// when the boundary data g equals u_exact on that boundary (as in membrane-radial).
    pub error_l2: Option<f64>,
    /// `|u − u_h|_H1` where an exact solution exists (on other domains: as `error_l2`).
    pub error_h1: Option<f64>,
    /// `max_v |u_h(v) − u(v)|` over the mesh vertices, where an exact solution exists:
    /// the finite-difference measure (PETSc's ex9 prints it as `|u-uexact|_inf`; on the
    /// right-diagonal grid p1-nodal is ex9's 5-point scheme, so the two agree).
    pub error_vertex_max: Option<f64>,
    /// The mean of `|u_h(v) − u(v)|` over the mesh vertices (ex9's `av |u-uexact|`).
    pub error_vertex_mean: Option<f64>,
    /// `(Σ_T h_T² ‖λ − λ_h‖²_T)^{1/2}` where an exact solution exists (stabilized pairs).
    pub error_multiplier: Option<f64>,
    /// `∫ λ_h` (the nodal method: the sum of its nodal contact forces).
    pub total_contact_force: f64,
    /// The exact `∫ λ` where known for the domain solved (`null` on a `--msh` mesh:
    /// the scene's constant belongs to its own domain).
    pub exact_contact_force: Option<f64>,
    /// Area of the contact set (holes of zero λ_h with zero gap filled).
    pub contact_area: f64,
    /// The exact contact area where known for the domain solved (as
    /// `exact_contact_force`).
    pub exact_contact_area: Option<f64>,
    /// KKT residual (equilibrium backward error and complementarity).
    pub complementarity_residual: f64,
    /// Estimated relative rounding noise of λ_h.
    pub multiplier_noise: f64,
    /// How far u may be off through the rounding of the rows in contact, relative to the
    /// larger of `max|u_h|`, `max|ψ|` at the vertices and 1e-6 of the mesh's diameter
    /// (fem_runtime `Lcp::primal_rounding`); 0 for the nodal method.
    pub primal_rounding: f64,
    /// `max(ψ − u_h, 0)` over the vertices, the quadrature points and, on meshes of few
    /// cells, a lattice on each cell: the weak (cell-wise) constraint lets u_h dip below
    /// ψ by `O(h²)` ([`fem_runtime::obstacle::triangle::penetration`]).
    pub max_penetration: f64,
    /// The largest clearance `side·(u_h − ψ)` of a cell where λ_h pushes
    /// ([`fem_runtime::obstacle::triangle::max_open_contact_gap`]): 0 for a real contact
    /// set; a share of the structure's size where `α h^k` overwhelms the gap (a coarse
    /// mesh, or α too large) and λ_h pushes where nothing touches (then warned).
    pub max_open_contact_gap: f64,
    /// The L² error the scene file asks for (`accuracy`), `null` where none is stated.
    pub accuracy: Option<f64>,
    /// What the numbers cannot be trusted for.
    pub warnings: Vec<String>,
    /// Shape of the solved (finest) mesh's triangles.
    pub mesh_quality: MeshQualityReport,
    /// Wall time of each phase of [`solve`], so that the time outside the solve shows.
    pub phases: PhaseSeconds,
}

/// Wall time in seconds of the phases of a membrane solve (the `phases` object of the
/// `--json` report); their sum is the solve's share of the process, the rest being
/// start-up and output.
#[derive(Clone, Debug, Default, Serialize)]
pub struct PhaseSeconds {
    /// Building the meshes of every level (generation, or reading and refining a file).
    pub meshes: f64,
    /// Checks of the data and the finest mesh: validation, shape, the inverse constant
    /// `C_I` that fixes α, the Dirichlet part.
    pub checks: f64,
    /// Assembly and the solve of all levels (the report's `seconds`).
    pub solve: f64,
    /// What follows the solve: errors against the exact solution, penetration and gap
    /// checks, the contact set and the fields for output.
    pub evaluation: f64,
}

/// The shape of a mesh's triangles and what it forces on the stabilization (the
/// `mesh_quality` object of the `--json` report).
#[derive(Clone, Debug, Default, Serialize)]
pub struct MeshQualityReport {
    /// Smallest angle of any triangle, in degrees.
    pub min_angle_deg: f64,
    /// Largest angle of any triangle, in degrees.
    pub max_angle_deg: f64,
    /// Largest `h_T / (2√3 r_T)` (1 for the equilateral triangle; see
    /// [`fem_runtime::mesh::triangle::MeshQuality`]).
    pub max_aspect_ratio: f64,
    /// `max_T C_I(T)` of the pair's elements (0 where Δ vanishes on them: P1).
    pub worst_inverse_constant: f64,
    /// The α = ½/C_I that constant forces (`None` where C_I = 0).
    pub forced_alpha: Option<f64>,
}

/// The solved fields, for VTK and charts.
pub struct MembraneFields {
    /// The mesh.
    pub mesh: TriangleMesh,
    /// u at the vertices.
    pub u: Vec<f64>,
    /// ψ at the vertices.
    pub psi: Vec<f64>,
    /// λ_h at the cell centroids (nodal method: the nodal force over the vertex's area
    /// share, averaged to the cells).
    pub lambda: Vec<f64>,
    /// 1 on contact cells, 0 elsewhere.
    pub contact: Vec<f64>,
    /// The DOFs of u.
    pub u_dofs: DofMap,
    /// The coefficients of u on `u_dofs`.
    pub u_coefficients: Vec<f64>,
}

impl MembraneFields {
    /// The fields of a solve: u from its DOFs and coefficients, ψ from the scene.
    fn new(
        mesh: TriangleMesh,
        data: &SceneData,
        u_dofs: DofMap,
        u_coefficients: Vec<f64>,
        lambda: Vec<f64>,
        contact: Vec<f64>,
    ) -> Self {
        use rayon::prelude::*;
        let psi = mesh
            .vertices()
            .par_iter()
            .map(|x| data.obstacle.at(x))
            .collect();
        let u = TriangleField {
            mesh: &mesh,
            map: &u_dofs,
            coefficients: &u_coefficients,
        }
        .vertex_values();
        Self {
            mesh,
            u,
            psi,
            lambda,
            contact,
            u_dofs,
            u_coefficients,
        }
    }

    /// u_h as a finite element function.
    pub fn u_field(&self) -> TriangleField<'_> {
        TriangleField {
            mesh: &self.mesh,
            map: &self.u_dofs,
            coefficients: &self.u_coefficients,
        }
    }
}

/// The `--mesh-size` values of the built-in membrane domains.
pub const MESH_SIZES: std::ops::RangeInclusive<usize> = 2..=4096;

/// The structured mesh of a scene with parameter N.
pub fn scene_mesh(scene: &MembraneScene, n: usize, diagonal: Diagonal) -> Result<TriangleMesh> {
    if !MESH_SIZES.contains(&n) {
        return Err(Error::Input(format!(
            "--mesh-size {n} is out of range ({} to {})",
            MESH_SIZES.start(),
            MESH_SIZES.end()
        )));
    }
    match &scene.domain {
        &Domain::Square(a) => TriangleMesh::rectangle(-a, a, -a, a, n, n, diagonal),
        Domain::LShape => {
            if n % 2 != 0 {
                return Err(Error::Input(format!(
                    "the L-shape needs an even --mesh-size, got {n}"
                )));
            }
            TriangleMesh::l_shape(n / 2)
        }
        Domain::File(path) => Err(Error::Input(format!(
            "scene `{}` is posed on the Gmsh mesh {}: it has no structured mesh",
            scene.name,
            path.display()
        ))),
    }
}

/// `C_I(T) = max h_T² ‖Δv‖²_T / ‖∇v‖²_T` over the element's functions, from the model's
/// own kernels (the forms `S` and `a`, by
/// [`fem_runtime::stabilization::element_inverse_constant`]). 0 when Δ vanishes on the
/// element.
pub fn element_inverse_constant<M: Model>(x: &[f64; 6]) -> Result<f64> {
    stabilization::element_inverse_constant::<M>(x, &vec![0.0; M::PARAMS.len()])
}

/// The memory every family's solve may plan to use, and its refusal text (the
/// runtime's, [`fem_runtime::problem::memory`]).
pub use fem_runtime::problem::memory::{beyond_memory, memory_limit_bytes, MEMORY_LIMIT_BYTES};

/// Largest open gap under a pushing λ_h, relative to the answer's size, that passes
/// without a warning (the runtime's).
pub use fem_runtime::problem::report::OPEN_GAP_WARNING;

/// `max_T C_I(T)` over a mesh (shapes repeated by translation are computed once).
pub fn inverse_constant<M: Model>(mesh: &TriangleMesh) -> Result<f64> {
    stabilization::inverse_constant::<M, _>(mesh, &vec![0.0; M::PARAMS.len()])
}

/// The data a solve uses: the load f (the scene's load field times q), the obstacle ψ
/// and the boundary data g.
#[derive(Clone, Debug)]
pub struct SceneData {
    /// The load f.
    pub load: Data,
    /// The obstacle ψ.
    pub obstacle: Data,
    /// The boundary data g.
    pub boundary: Data,
}

impl SceneData {
    /// The data of `scene` at load magnitude `q` (`None`: the scene's own q). Where the
    /// scene's load is fixed (`load_scale` is `None`) f is its load field and q is not
    /// used ([`MembraneScene::load_magnitude`] refuses one).
    pub fn new(scene: &MembraneScene, q: Option<f64>) -> Self {
        let load = match q.or(scene.load_scale) {
            Some(q) if scene.load_scale.is_some() => {
                let shape = scene.load.clone();
                Data::shared(move |x| q * shape.at(x))
            }
            _ => scene.load.clone(),
        };
        Self {
            load,
            obstacle: scene.obstacle.clone(),
            boundary: scene.boundary.clone(),
        }
    }
}

/// The parameters and data of a stabilized membrane model: α, and the load f, obstacle
/// ψ and boundary data g.
pub fn scene_coefficients<M: Model>(data: &SceneData, alpha: f64) -> Result<Coefficients<'_>> {
    Coefficients::new::<M>(
        &[("α", alpha)],
        &[
            ("f", data.load.as_data_fn()),
            ("ψ", data.obstacle.as_data_fn()),
            ("g", data.boundary.as_data_fn()),
        ],
    )
}

/// Gauss–Seidel sweeps that replace the first Newton factorization on each nested level
/// (see [`fem_runtime::lcp::NewtonOptions::smoothing_sweeps`]).
pub const MEMBRANE_SMOOTHING_SWEEPS: usize = 8;

/// The LCP options of the membrane solves: no iterative refinement of the Newton
/// directions (the membrane's condition ~h⁻² leaves them accurate, and the KKT
/// residual is checked at the end anyway), saving two triangular solves per iteration,
/// and [`MEMBRANE_SMOOTHING_SWEEPS`] sweeps for the first direction of a nested level.
pub fn membrane_options(solver: VariationalSolver) -> ObstacleOptions {
    let defaults = ObstacleOptions::default();
    ObstacleOptions {
        solver,
        newton: fem_runtime::lcp::NewtonOptions {
            refinement_steps: 0,
            smoothing_sweeps: MEMBRANE_SMOOTHING_SWEEPS,
            ..defaults.newton
        },
        ..defaults
    }
}

/// The α a request uses and the mesh's `C_I`.
pub fn alpha_of(request: &MembraneRequest, mesh: &TriangleMesh) -> Result<(f64, f64)> {
    let c_i = (request.pair.row().inverse_constant)(mesh)?;
    let policy = request.alpha.map_or(Alpha::default(), Alpha::Fixed);
    Ok((policy.value(c_i, ALPHA_WHEN_CI_VANISHES)?, c_i))
}

/// An error for an exact solution no obstacle problem can have on `mesh`: a multiplier
/// below 0 at a vertex, or a contact area beyond the domain's (a `[exact]
/// lambda = "-2"` and `contact_area = 100` on a domain of area 4 were accepted and
/// compared with).
fn validate_exact(exact: &ExactMembrane, mesh: &TriangleMesh, scene: &str) -> Result<()> {
    if let Some(lambda) = &exact.multiplier {
        let values: Vec<f64> = mesh.vertices().iter().map(|x| lambda.at(x)).collect();
        // not-a-number values are left to the report, which says the error cannot be
        // measured
        let largest = values
            .iter()
            .filter(|v| v.is_finite())
            .fold(0.0f64, |m, v| m.max(v.abs()));
        if let Some((x, v)) = mesh
            .vertices()
            .iter()
            .zip(&values)
            .find(|(_, &v)| v < -1e-12 * largest)
        {
            return Err(Error::Input(format!(
                "scene `{scene}`: field `exact.lambda`: λ = {} at ({}, {}); the multiplier of u ≥ ψ is a pressure, ≥ 0",
                crate::number(*v),
                x[0],
                x[1]
            )));
        }
    }
    if let Some(area) = exact.contact_area {
        let domain: f64 = (0..mesh.cell_count()).map(|c| mesh.area(c)).sum();
        if area > domain * (1.0 + 1e-9) {
            return Err(Error::Input(format!(
                "scene `{scene}`: field `exact.contact_area`: {} exceeds the domain's area {domain}",
                crate::number(area)
            )));
        }
    }
    Ok(())
}

/// The meshes of a nested solve: N/2^k ≥ 4, …, N (just N without nesting).
fn level_sizes(n: usize, nested: bool, even: bool) -> Vec<usize> {
    let mut sizes = vec![n];
    while nested && sizes[0] % 2 == 0 && sizes[0] / 2 >= 4 && (!even || (sizes[0] / 2) % 2 == 0) {
        sizes.insert(0, sizes[0] / 2);
    }
    sizes
}

/// Solves a membrane request.
pub fn solve(request: &MembraneRequest) -> Result<(MembraneReport, MembraneFields)> {
    let scene = &request.scene;
    let load = scene.load_magnitude(request.load).map_err(Error::Input)?;
    check_memory(request)?;
    let clock = Instant::now();
    let (meshes, domain, own_domain) = match (&request.mesh_file, &scene.domain) {
        (Some(path), _) => (
            file_levels(path, request.mesh_size, request.nested, request.pair)?,
            format!("Gmsh file {}", path.display()),
            false,
        ),
        (None, Domain::File(path)) => (
            file_levels(path, request.mesh_size, request.nested, request.pair)?,
            scene.domain.describe(),
            true,
        ),
        (None, domain) => {
            let even = *domain == Domain::LShape;
            // the coarser levels on the second core while the finest builds (a third
            // of its cells in all)
            use rayon::prelude::*;
            let meshes = level_sizes(request.mesh_size, request.nested, even)
                .into_par_iter()
                .map(|n| scene_mesh(scene, n, request.diagonal))
                .collect::<Result<Vec<_>>>()?;
            (meshes, domain.describe(), true)
        }
    };
    let mut exact = scene.exact_at(load);
    // a scene file's [exact] holds at its own load only: say so rather than drop it
    let exact_dropped = matches!(scene.exact, Exact::AtDefaultLoad(_)) && exact.is_none();
    if !own_domain {
        // ∫λ and the contact area belong to the scene's domain; the exact field stays
        // (the solution wherever g = u_exact on the boundary solved)
        if let Some(e) = &mut exact {
            e.total_contact_force = None;
            e.contact_area = None;
        }
    }
    let meshes_seconds = clock.elapsed().as_secs_f64();
    let part = dirichlet_part(scene, meshes.last().expect("at least one level"), &domain)?;
    let posed = Posed {
        data: SceneData::new(scene, load),
        load,
        exact,
        domain,
        part,
    };
    let mesh = meshes.last().expect("at least one level");
    if let Some(exact) = &posed.exact {
        validate_exact(exact, mesh, &scene.name)?;
    }
    let checks_seconds = clock.elapsed().as_secs_f64() - meshes_seconds;
    let (mut report, fields) = (request.pair.row().run)(request, &posed, meshes)
        .map_err(|e| scene_field_of(e, &scene.name))?;
    let run_seconds = clock.elapsed().as_secs_f64() - meshes_seconds - checks_seconds;
    let finest = &fields.mesh;
    if let DirichletParts::Named(names) = &scene.dirichlet {
        report.warnings.extend(crate::interior_curve_warnings(
            "boundary.dirichlet",
            finest,
            names,
        ));
    }
    if exact_dropped {
        report.warnings.push(format!(
            "the scene's exact solution holds at its own load q = {}; under --load {} it is not compared (the contact set is not linear in the load)",
            scene.load_scale.map_or("?".into(), crate::number),
            load.map_or("?".into(), crate::number)
        ));
    }
    if let Some(accuracy) = request.accuracy {
        report.accuracy = Some(accuracy);
        match report.error_l2 {
            Some(e) if e > accuracy => report.warnings.push(format!(
                "the L² error {e:.3e} exceeds the accuracy the scene asks for, {accuracy:e}: refine (--mesh-size) or take a pair of higher order"
            )),
            Some(_) => {}
            None => report.warnings.push(format!(
                "the accuracy {accuracy:e} the scene asks for is not checked: there is no exact solution to measure the error against here"
            )),
        }
    }
    report.phases = PhaseSeconds {
        meshes: meshes_seconds,
        checks: checks_seconds,
        solve: report.seconds,
        evaluation: (run_seconds - report.seconds).max(0.0),
    };
    Ok((report, fields))
}

/// A pair's solve through the runtime's one pipeline: the stabilized pairs with their
/// model's multiplier, `p1-nodal` (a model without one) with the nodal constraint.
fn run<M: Model>(
    request: &MembraneRequest,
    posed: &Posed,
    meshes: Vec<TriangleMesh>,
) -> Result<(MembraneReport, MembraneFields)> {
    let scene = &request.scene;
    let data = &posed.data;
    let nodal = request.pair == MembranePair::P1Nodal;
    let (load, obstacle, boundary) = (
        data.load.clone(),
        data.obstacle.clone(),
        data.boundary.clone(),
    );
    let f = move |x: &[f64]| load.at(x);
    let psi = move |x: &[f64]| obstacle.at(x);
    let g = move |x: &[f64]| boundary.at(x);
    let exact = posed.exact.clone();
    let (u, gradient, multiplier) = match &exact {
        Some(e) => (
            Some(e.u.clone()),
            Some(e.gradient.clone()),
            e.multiplier.clone(),
        ),
        None => (None, None, None),
    };
    let exact_u = move |x: &[f64]| u.as_ref().map_or(f64::NAN, |u| u.at(x));
    let exact_gradient = move |x: &[f64]| gradient.as_ref().map_or([f64::NAN; 2], |g| g.at(x));
    let has_multiplier = multiplier.is_some();
    let exact_multiplier = move |x: &[f64]| multiplier.as_ref().map_or(f64::NAN, |m| m.at(x));
    let mesh_size = request.mesh_size;
    let pair = request.pair;
    let mut problem = Problem::<M, TriangleMesh>::new(meshes)
        .data("f", &f)
        .data("g", &g)
        .boundary_data(posed.part.clone())
        .alpha(
            request.alpha.map_or(Alpha::default(), Alpha::Fixed),
            ALPHA_WHEN_CI_VANISHES,
        )
        .options(SolveOptions {
            obstacle: ObstacleOptions {
                linear_solver: request.linear_solver,
                ..membrane_options(request.solver)
            },
            nested: request.nested,
            rounding_experiment: false,
        })
        .memory(
            MemoryModel::per_cell(pair.row().bytes_per_triangle),
            format!("--mesh-size {mesh_size} with {}", pair.name()),
        );
    problem = problem.data("ψ", &psi);
    if nodal {
        problem = problem.nodal(&psi);
    }
    if exact.is_some() {
        problem = problem.exact(problem::Exact {
            value: &exact_u,
            gradient: Some(&exact_gradient),
            hessian: None,
            multiplier: has_multiplier.then_some(&exact_multiplier as &DataFn),
        });
    }
    let solved = problem.solve()?;
    let r = solved.report;
    let solution = solved.solution;
    let d = &solution.discretization;
    let u_field = 0;
    let (lambda, contact) = if nodal {
        let (shares, _) = fem_runtime::problem::nodal::contact_shares(&solution, &psi);
        (
            fem_runtime::problem::nodal::force_density(&solution),
            shares,
        )
    } else {
        (
            solution.view(d.multiplier_field).centroid_values(),
            solution.contact_shares(),
        )
    };
    let report = MembraneReport {
        scene: scene.name.to_string(),
        pair: pair.name().into(),
        solver: r.solver.into(),
        linear_solver: r.linear_solver,
        krylov_iterations: r.krylov_iterations,
        factorizations: r.factorizations,
        domain: posed.domain.clone(),
        dirichlet_parts: scene.dirichlet.names(),
        load: posed.load,
        mesh_size,
        triangles: r.cells,
        dofs: r.dofs,
        iterations: r.iterations,
        levels: r.levels.clone(),
        seconds: r.seconds,
        alpha: r.alpha.unwrap_or(0.0),
        inverse_constant: r.inverse_constant,
        error_l2: r.error_l2,
        error_h1: r.error_h1,
        error_vertex_max: r.error_vertex_max,
        error_vertex_mean: r.error_vertex_mean,
        error_multiplier: r.error_multiplier,
        total_contact_force: r.total_contact_force,
        exact_contact_force: posed.exact.as_ref().and_then(|e| e.total_contact_force),
        contact_area: r.contact_area.unwrap_or(0.0),
        exact_contact_area: posed.exact.as_ref().and_then(|e| e.contact_area),
        complementarity_residual: r.kkt_residual,
        multiplier_noise: r.multiplier_noise,
        primal_rounding: r.primal_rounding,
        max_penetration: r.max_penetration.unwrap_or(0.0),
        max_open_contact_gap: r.max_open_contact_gap.unwrap_or(0.0),
        accuracy: None,
        warnings: r.warnings,
        mesh_quality: r
            .mesh_quality
            .map(|q| MeshQualityReport {
                min_angle_deg: q.min_angle_deg,
                max_angle_deg: q.max_angle_deg,
                max_aspect_ratio: q.max_aspect_ratio,
                worst_inverse_constant: q.worst_inverse_constant,
                forced_alpha: q.forced_alpha,
            })
            .unwrap_or_default(),
        phases: PhaseSeconds::default(),
    };
    let u_dofs = d.dofs.map(u_field).expect("the u field").clone();
    let u_coefficients = solution.field(u_field).to_vec();
    let mesh = solution.discretization.mesh;
    let fields = MembraneFields::new(mesh, data, u_dofs, u_coefficients, lambda, contact);
    Ok((report, fields))
}

/// A runtime error about a data function, with the scene and the scene file's field
/// named: "data `ψ` of `membrane_p2_p0` is inf at (1, 0)" becomes "scene `radial`:
/// field `data.psi`: data `ψ` …".
fn scene_field_of(error: Error, scene: &str) -> Error {
    let Error::Input(message) = error else {
        return error;
    };
    let key = [("f", "f"), ("ψ", "psi"), ("g", "g")]
        .iter()
        .find(|(name, _)| message.starts_with(&format!("data `{name}` of ")))
        .map(|(_, key)| *key);
    match key {
        Some(key) => Error::Input(format!("scene `{scene}`: field `data.{key}`: {message}")),
        None => Error::Input(message),
    }
}

/// What a request poses on the mesh solved: the data at its load, the exact solution
/// that holds there, the domain's description, where u = g holds.
struct Posed {
    data: SceneData,
    load: Option<f64>,
    exact: Option<ExactMembrane>,
    domain: String,
    part: DirichletPart,
}

/// The scene's Dirichlet part on `mesh` (the finest level; coarser levels have the same
/// markers and names): its boundary parts' markers.
///
/// # Errors
/// [`Error::Input`] naming the field `boundary.dirichlet` and the scene for a name the
/// mesh does not have (listing those it has), the name of a surface or of a number, and
/// for parts holding no boundary edge of the mesh (the natural condition on the whole
/// boundary leaves the membrane undetermined up to a constant: refused).
pub fn dirichlet_part(
    scene: &MembraneScene,
    mesh: &TriangleMesh,
    domain: &str,
) -> Result<DirichletPart> {
    let at = |message: String| {
        Error::Input(format!(
            "scene `{}`: field `boundary.dirichlet`: {message}",
            scene.name
        ))
    };
    // `"all"` is the keyword for the whole boundary: a mesh with a boundary part of that
    // name would make `"all"` and `["all"]` mean different sets under one printed name
    if mesh.boundary_part_names().contains(&"all") {
        // not `at`: the field may not be written at all (a file had no
        // `[boundary]`, and was told its `boundary.dirichlet` was at fault)
        return Err(Error::Input(format!(
            "scene `{}`: the mesh ({domain}) has a boundary part named `all`, which is the keyword of `boundary.dirichlet` (and its default) for the whole boundary: rename the Gmsh physical group (e.g. Physical Curve(\"outer\")) so that the choice is unambiguous",
            scene.name
        )));
    }
    let DirichletParts::Named(names) = &scene.dirichlet else {
        return Ok(DirichletPart::All);
    };
    if names.is_empty() {
        return Err(at(
            "no boundary part is chosen: with ∂u/∂n = 0 on the whole boundary the membrane is determined only up to a constant where contact does not hold it; choose at least one part".into(),
        ));
    }
    let markers = mesh.boundary_part_markers(names).map_err(|e| match e {
        Error::Input(message) => {
            // `["all"]`: the keyword is a plain string, not a name in a list
            let keyword = if names.iter().any(|n| n == "all") && message.contains("`all`") {
                "; \"all\" (the whole boundary) is a keyword on its own, `dirichlet = \"all\"`, not a name in a list"
            } else {
                ""
            };
            at(format!("{message} (domain: {domain}){keyword}"))
        }
        other => other,
    })?;
    // a part listed beside others must hold boundary edges of its own: an interior
    // curve or an empty group would otherwise be reported as a Dirichlet part and do
    // nothing
    if names.len() > 1 {
        for name in names {
            let own =
                DirichletPart::Markers(mesh.boundary_part_markers(&[name]).map_err(
                    |e| match e {
                        Error::Input(message) => at(format!("{message} (domain: {domain})")),
                        other => other,
                    },
                )?);
            if own.edge_count(mesh) == 0 {
                return Err(at(format!(
                    "the boundary part `{name}` holds no boundary edge of the mesh ({domain}): an interior curve or an empty group cannot carry u = g; remove it from the list"
                )));
            }
        }
    }
    let part = DirichletPart::Markers(markers);
    if part.edge_count(mesh) == 0 {
        return Err(at(format!(
            "the boundary parts {} hold no boundary edge of the mesh ({domain}): u = g would hold nowhere and ∂u/∂n = 0 on the whole boundary, which determines the membrane only up to a constant; refused",
            names.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", ")
        )));
    }
    Ok(part)
}

/// Refuses, before allocating, a structured mesh whose solve would need more than
/// [`memory_limit_bytes`]. Measured peaks per triangle (membrane-radial, 2026-12-01):
/// p1-p0 1.2 kB at 2.1M and 1.3 kB at 8.4M triangles, p1-nodal 0.4 kB at 2.1M and
/// 8.4M, p2-p0 4.3 kB at
/// 131k and 4.7 kB at 524k, p2-p1disc 5.6 kB at both, growing with the factor's fill
/// (`O(N log N)` in 2D); the table's figures leave room for that growth.
fn check_memory(request: &MembraneRequest) -> Result<()> {
    // a size out of range is refused as such by `scene_mesh` (4097 was refused for its
    // memory, which hid the range)
    if request.mesh_file.is_some()
        || matches!(request.scene.domain, Domain::File(_))
        || !MESH_SIZES.contains(&request.mesh_size)
    {
        return Ok(());
    }
    let per_triangle = request.pair.row().bytes_per_triangle;
    let n = request.mesh_size as f64;
    let bytes = 2.0 * n * n * per_triangle;
    if let Some(m) = beyond_memory(bytes) {
        return Err(Error::Input(format!(
            "--mesh-size {} with {} {m}",
            request.mesh_size,
            request.pair.name(),
        )));
    }
    Ok(())
}

/// The levels of a Gmsh mesh: the file's mesh and its `refinements` uniform
/// refinements (all of them for nested iteration, else the finest only). Refused before
/// refining if the solve would need more than [`memory_limit_bytes`].
fn file_levels(
    path: &std::path::Path,
    refinements: usize,
    nested: bool,
    pair: MembranePair,
) -> Result<Vec<TriangleMesh>> {
    if refinements > 8 {
        return Err(Error::Input(format!(
            "--mesh-size {refinements} on a Gmsh mesh (--msh, or a scene file's mesh.file) means {refinements} uniform refinements of the file's mesh (4^{refinements} times the triangles); at most 8"
        )));
    }
    let mesh = fem_runtime::mesh::gmsh::read_msh(path)?;
    // the file's own cells first, so a refusal names corners the user wrote
    mesh.quality().check(&mesh).map_err(|e| match e {
        Error::Mesh(m) => Error::Mesh(format!("{}: {m}", path.display())),
        other => other,
    })?;
    let bytes = fem_runtime::mesh::triangle::estimated_bytes(
        mesh.cell_count(),
        refinements as u32,
        pair.row().bytes_per_triangle,
    );
    if let Some(m) = beyond_memory(bytes) {
        return Err(Error::Input(format!(
            "--mesh-size {refinements} with --msh {} refines its {} triangles {refinements} times, to {:.3e} triangles; with {} that {m}: use fewer refinements",
            path.display(),
            mesh.cell_count(),
            mesh.cell_count() as f64 * 4f64.powi(refinements as i32),
            pair.name(),
        )));
    }
    let mut levels = vec![mesh];
    for _ in 0..refinements {
        let finer = levels.last().expect("a level").refine_uniformly();
        levels.push(finer);
    }
    if !nested {
        levels.drain(..levels.len() - 1);
    }
    Ok(levels)
}

/// The degree of the rule for the error norms (the runtime's).
pub use fem_runtime::problem::error_rule_degree;

/// Writes the solved fields as a `.vtu` for ParaView: u and ψ at the vertices, λ_h and
/// the contact set per cell.
pub fn write_vtk(path: &std::path::Path, fields: &MembraneFields) -> Result<()> {
    fem_runtime::io::vtk::write_vtu(
        path,
        &fields.mesh,
        &[("u", &fields.u), ("psi", &fields.psi)],
        &[("lambda", &fields.lambda), ("contact", &fields.contact)],
    )
}

/// Interpolates the P1/P2 field of one solve at the points of another (for reference
/// errors between meshes): `‖u_a − u_b‖_L2` on `a`'s mesh with a rule of degree `degree`.
pub fn difference_l2(a: &TriangleField, b: &TriangleField, degree: usize) -> f64 {
    use fem_runtime::element::triangle::AffineMap;
    let rule = fem_runtime::reference::triangle::TriangleRule::exact_for_degree(degree);
    let basis_a = TriangleBasis::new(a.map.element());
    let basis_b = TriangleBasis::new(b.map.element());
    let locator = PointLocator::new(b.mesh);
    let mut sum = 0.0;
    for c in 0..a.mesh.cell_count() {
        let map = AffineMap::of(a.mesh, c);
        for (&xi, &w) in rule.points.iter().zip(&rule.weights) {
            let x = map.point(xi);
            let vb = b.at(&basis_b, &locator, x).unwrap_or(0.0);
            let e = a.value(&basis_a, c, xi) - vb;
            sum += w * map.det * e * e;
        }
    }
    sum.sqrt()
}

/// One pair's way to a scene's asked accuracy.
#[derive(Clone, Debug, Serialize)]
pub struct AccuracyRung {
    /// The pair.
    pub pair: String,
    /// The first N whose estimated L² error of u is within the target (or the last tried).
    pub mesh_size: usize,
    /// Unknowns at that N.
    pub dofs: usize,
    /// Wall time of the solve at that N.
    pub seconds: f64,
    /// Richardson estimate `‖u_N − u_2N‖ / (1 − 2⁻²)` of `‖u − u_N‖_L2`.
    pub estimated_l2: f64,
    /// The true error where an exact solution is known.
    pub exact_l2: Option<f64>,
    /// Whether the target was reached (N ≤ 512).
    pub reached: bool,
    /// Why the pair could not be solved, if it could not.
    pub failure: Option<String>,
}

/// For every pair, the coarsest N = 8·2^k whose estimated L² error of u is within the
/// scene's `target_l2`; and the index of the cheapest (least solve time) that reaches it.
pub fn cheapest_for_accuracy(
    scene: &MembraneScene,
    pairs: &[MembranePair],
) -> Result<(Vec<AccuracyRung>, Option<usize>)> {
    let mut rungs = Vec::new();
    for &pair in pairs {
        match accuracy_rung(scene, pair) {
            Ok(rung) => rungs.push(rung),
            Err(e) => rungs.push(AccuracyRung {
                pair: pair.name().into(),
                mesh_size: 0,
                dofs: 0,
                seconds: f64::NAN,
                estimated_l2: f64::NAN,
                exact_l2: None,
                reached: false,
                failure: Some(e.to_string()),
            }),
        }
    }
    let cheapest = rungs
        .iter()
        .enumerate()
        .filter(|(_, r)| r.reached)
        .min_by(|a, b| a.1.seconds.total_cmp(&b.1.seconds))
        .map(|(k, _)| k);
    Ok((rungs, cheapest))
}

fn accuracy_rung(scene: &MembraneScene, pair: MembranePair) -> Result<AccuracyRung> {
    let mut request = MembraneRequest::new(scene.clone());
    request.pair = pair;
    request.mesh_size = 8;
    let mut coarse = solve(&request)?;
    loop {
        request.mesh_size *= 2;
        let fine = solve(&request)?;
        let difference = difference_l2(&coarse.1.u_field(), &fine.1.u_field(), 8);
        // ‖u − u_N‖ ≈ ‖u_N − u_2N‖ / (1 − 2^−p) with the L² rate p = 2
        let estimated_l2 = difference / 0.75;
        let reached = estimated_l2 <= scene.target_l2;
        if reached || request.mesh_size >= 512 {
            return Ok(AccuracyRung {
                pair: pair.name().into(),
                mesh_size: coarse.0.mesh_size,
                dofs: coarse.0.dofs,
                seconds: coarse.0.seconds,
                estimated_l2,
                exact_l2: coarse.0.error_l2,
                reached,
                failure: None,
            });
        }
        coarse = fine;
    }
}
