//! The membrane scenes: element pairs, the stabilization parameter from the computed
//! inverse-inequality constant `C_I`, the solve with its report (the CLI's `--json`),
//! errors against the exact radial solution, and VTK output.

use crate::models::data::Data;
use crate::models::membrane::{membrane_p1, membrane_p1_p0, membrane_p2_p0, membrane_p2_p1disc};
use crate::models::membrane_scenes::{
    DirichletParts, Domain, Exact, ExactMembrane, MembraneScene, MAX_LOAD,
};
use fem_runtime::assembly::{assemble_vector, MatrixAssembler};
use fem_runtime::element::triangle::{TriangleBasis, TriangleField};
use fem_runtime::lcp::cholesky::multiply;
use fem_runtime::lcp::LcpSolution;
use fem_runtime::multigrid::{
    parents_by_location, prolongation, reduced_prolongation, NestedLevel,
};
use fem_runtime::obstacle::hierarchy::LinearSolver;
use fem_runtime::obstacle::nodal::{nodal_active_set_level, NODAL_AUTO_MULTIGRID_UNKNOWNS};
use fem_runtime::obstacle::triangle::{
    dirichlet_constraints_on, solve_obstacle_on_part, TriangleObstacleSolution,
};
use fem_runtime::obstacle::{alongside, ObstacleOptions, VariationalSolver};
use fem_runtime::stabilization::{self, Alpha};
use fem_runtime::{
    Coefficients, Constraints, Diagonal, DirichletPart, DofMap, Error, Model, PointLocator,
    Reduction, Result, SparseMatrix, SystemDofs, TriangleMesh,
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

/// A pair as data: its name, the degree of u, its measured memory, and for a stabilized
/// pair the entry points of its model (instantiated for the model's type). Adding a pair
/// is one row here and its variant of [`MembranePair`].
struct PairRow {
    pair: MembranePair,
    name: &'static str,
    degree: usize,
    /// Measured peak bytes per triangle of the finest mesh (see [`check_memory`]).
    bytes_per_triangle: f64,
    /// `None` for the nodal method (no multiplier space, no stabilization).
    stabilized: Option<Stabilized>,
}

/// A stabilized solve: (request, posed, meshes, α, C_I) → report and fields.
type StabilizedRun = fn(
    &MembraneRequest,
    &Posed,
    &[TriangleMesh],
    f64,
    f64,
) -> Result<(MembraneReport, MembraneFields)>;

/// The entry points of a stabilized pair's model.
struct Stabilized {
    inverse_constant: fn(&TriangleMesh) -> Result<f64>,
    element_inverse_constant: fn(&[f64; 6]) -> Result<f64>,
    /// `run_stabilized` of the model: (request, posed, meshes, α, C_I) → report, fields.
    run: StabilizedRun,
}

impl Stabilized {
    const fn of<M: Model>() -> Self {
        Self {
            inverse_constant: inverse_constant::<M>,
            element_inverse_constant: element_inverse_constant::<M>,
            run: run_stabilized::<M>,
        }
    }
}

/// Every pair, in the order of [`MembranePair::ALL`].
const PAIRS: [PairRow; 4] = [
    PairRow {
        pair: MembranePair::P1P0,
        name: "p1-p0",
        degree: 1,
        bytes_per_triangle: 1.6e3,
        stabilized: Some(Stabilized::of::<membrane_p1_p0::Model>()),
    },
    PairRow {
        pair: MembranePair::P2P0,
        name: "p2-p0",
        degree: 2,
        bytes_per_triangle: 6.0e3,
        stabilized: Some(Stabilized::of::<membrane_p2_p0::Model>()),
    },
    PairRow {
        pair: MembranePair::P2P1Disc,
        name: "p2-p1d",
        degree: 2,
        bytes_per_triangle: 7.0e3,
        stabilized: Some(Stabilized::of::<membrane_p2_p1disc::Model>()),
    },
    PairRow {
        pair: MembranePair::P1Nodal,
        name: "p1-nodal",
        degree: 1,
        bytes_per_triangle: 0.6e3,
        stabilized: None,
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

/// α for pairs whose `C_I` is 0 (P1: Δ vanishes on each triangle): the stabilization is
/// then `α Σ h²(λ, μ)`, stable for every α > 0 and limited by accuracy only (see the α study).
pub const ALPHA_WHEN_CI_VANISHES: f64 = 0.1;

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
    /// `max ψ − min ψ` over the same points (not in the JSON): what
    /// `max_penetration` is compared with for its warning.
    #[serde(skip)]
    pub obstacle_range: f64,
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
    let c_i = match &request.pair.row().stabilized {
        Some(model) => (model.inverse_constant)(mesh)?,
        None => 0.0,
    };
    let policy = request.alpha.map_or(Alpha::default(), Alpha::Fixed);
    Ok((policy.value(c_i, ALPHA_WHEN_CI_VANISHES)?, c_i))
}

/// Checks the scene's data on the mesh: finite values, obstacle not above the boundary
/// data where u = g is imposed (`part`).
fn validate(
    data: &SceneData,
    mesh: &TriangleMesh,
    part: &DirichletPart,
    scene: &str,
) -> Result<()> {
    let on_part = part.vertices(mesh);
    // g is used on the Dirichlet part only: a tester's g = ln(x + 1) held on the right
    // side was refused for its value on the free left side
    for (name, key, f, only_on_part) in [
        ("load f", "data.f", &data.load, false),
        ("obstacle ψ", "data.psi", &data.obstacle, false),
        ("boundary data g", "data.g", &data.boundary, true),
    ] {
        let mut largest = 0.0f64;
        for (i, x) in mesh.vertices().iter().enumerate() {
            if only_on_part && !on_part[i] {
                continue;
            }
            let v = f.at(x);
            if !v.is_finite() {
                return Err(Error::Input(format!(
                    "scene `{scene}`: field `{key}`: the {name} is {v} at ({}, {})",
                    x[0], x[1]
                )));
            }
            // as for --load: beyond it the norms that certify the solve may overflow
            if v.abs() > MAX_LOAD {
                return Err(Error::Input(format!(
                    "scene `{scene}`: field `{key}`: the {name} is {v:e} at ({}, {}), beyond ±{MAX_LOAD:e}: norms in the solve would overflow double precision",
                    x[0], x[1]
                )));
            }
            largest = largest.max(v.abs());
        }
        if largest > 0.0 && largest < crate::MIN_DATA_SIZE {
            return Err(Error::Input(format!(
                "scene `{scene}`: field `{key}`: the {name} is at most {largest:e} in size, below {:e}: the solve multiplies it by powers of h and would underflow; rescale the units",
                crate::MIN_DATA_SIZE
            )));
        }
    }
    for v in (0..mesh.vertex_count()).filter(|&v| on_part[v]) {
        let x = mesh.vertices()[v];
        let (psi, g) = (data.obstacle.at(&x), data.boundary.at(&x));
        if psi > g + 1e-12 * (1.0 + g.abs()) {
            return Err(Error::Input(format!(
                "infeasible: the obstacle lies above the boundary data at ({}, {}): ψ = {psi} > g = {g}, so no u with u = g there and u ≥ ψ exists",
                x[0], x[1]
            )));
        }
    }
    Ok(())
}

/// An error for an exact solution no obstacle problem can have on `mesh`: a multiplier
/// below 0 at a vertex, or a contact area beyond the domain's (a tester's `[exact]
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
    validate(&posed.data, mesh, &posed.part, &scene.name)?;
    if let Some(exact) = &posed.exact {
        validate_exact(exact, mesh, &scene.name)?;
    }
    let quality = mesh.quality();
    quality.check(mesh)?;
    let (alpha, c_i) = alpha_of(request, mesh).map_err(|e| match e {
        // C_I's eigenproblem fails only when a cell's stiffness is numerically singular
        Error::LinearSolve(m) => Error::Input(format!(
            "cannot compute the stabilization's C_I on this mesh ({m}): its worst triangle, {}, is too thin; remesh with better-shaped triangles",
            worst_cell(mesh, quality.min_angle_cell)
        )),
        other => other,
    })?;
    check_stabilization_above_rounding(request, mesh, &quality, c_i)?;
    let checks_seconds = clock.elapsed().as_secs_f64() - meshes_seconds;
    let (mut report, fields) = match &request.pair.row().stabilized {
        Some(model) => (model.run)(request, &posed, &meshes, alpha, c_i)
            .map_err(|e| small_alpha_hint(e, request.alpha)),
        None => run_nodal(request, &posed, meshes),
    }?;
    let run_seconds = clock.elapsed().as_secs_f64() - meshes_seconds - checks_seconds;
    let finest = &fields.mesh;
    // α = ½/C_I only where C_I > 0 and no α was given
    let alpha_from_inverse_constant = c_i > 0.0 && request.alpha.is_none();
    report
        .warnings
        .extend(quality.warnings(finest, alpha_from_inverse_constant));
    if let DirichletParts::Named(names) = &scene.dirichlet {
        report.warnings.extend(crate::interior_curve_warnings(
            "boundary.dirichlet",
            finest,
            names,
        ));
    }
    let (penetration_scale, penetration_rounding) =
        penetration_scales(&report, &fields, posed.data.load.as_data_fn());
    if let Some(warning) = penetration_warning(
        report.max_penetration,
        penetration_scale,
        penetration_rounding,
        request.pair == MembranePair::P1Nodal,
    ) {
        report.warnings.push(warning);
        // refining or the nodal method is the advice for the default α; a large α of the
        // user's is the likelier cause (p1-p0 at α = 1e10: ∫λ_h 1e-7 of the exact 4.27)
        let default = Alpha::default().value(c_i, ALPHA_WHEN_CI_VANISHES).ok();
        if let (Some(given), Some(default), Some(_)) =
            (request.alpha, default, &request.pair.row().stabilized)
        {
            if given > LARGE_ALPHA_FACTOR * default {
                report.warnings.push(format!(
                    "--alpha {given:e} is {:.0e} times the default {default:.3e}: the stabilized constraint lets u_h cross ψ by about α h² λ_h, so lower --alpha before refining",
                    given / default
                ));
            }
        }
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
    let not_a_number = |e: Option<f64>| e.is_some_and(|e| !e.is_finite());
    if not_a_number(report.error_l2)
        || not_a_number(report.error_h1)
        || not_a_number(report.error_multiplier)
    {
        // JSON prints them as null: say why
        report.warnings.push(
            "an error against the exact solution is not a number: the exact u, its gradient or λ is not finite at some quadrature point (check the scene's [exact] expressions)".into(),
        );
    }
    if report.max_penetration.is_nan() {
        // JSON has no NaN: the field prints as null, so the reason must be said here
        report.warnings.push(
            "max_penetration is not a number: the obstacle ψ or u_h is not finite at some point the penetration check samples (the vertices, quadrature points and, on meshes of few cells, a lattice on each cell)".into(),
        );
    }
    report.mesh_quality = MeshQualityReport {
        min_angle_deg: quality.min_angle_deg,
        max_angle_deg: quality.max_angle_deg,
        max_aspect_ratio: quality.max_aspect_ratio,
        worst_inverse_constant: c_i,
        forced_alpha: (c_i > 0.0).then(|| 0.5 / c_i),
    };
    report.phases = PhaseSeconds {
        meshes: meshes_seconds,
        checks: checks_seconds,
        solve: report.seconds,
        evaluation: (run_seconds - report.seconds).max(0.0),
    };
    Ok((report, fields))
}

/// `α·C_I(equilateral)` below which [`check_stabilization_above_rounding`] refuses: about
/// 450 rounding units. λ_h's rounding noise grows like `ε / (α·C_I)` (a needle mesh
/// measured 2e-4 at 4e-12 and 2 at 4e-16), so below this it reaches the percent level.
const SMALLEST_RELATIVE_STABILIZATION: f64 = 1e-13;

/// Refuses a default α = ½/C_I so small, because of the mesh's worst cell, that the
/// stabilization of a well-shaped (equilateral) cell, `α·C_I(equilateral)` relative to
/// its stiffness, is below [`SMALLEST_RELATIVE_STABILIZATION`]: the method would run
/// unstabilized without saying so and λ_h be drowned in rounding. An α given by the
/// user is held to the same bound (with `α` itself as the relative size for P1, whose
/// `C_I` is 0): a tester's `--alpha 1e-16` failed in Newton's Cholesky with a message
/// that did not name α. `--alpha 0`, the plain method, passes.
fn check_stabilization_above_rounding(
    request: &MembraneRequest,
    mesh: &TriangleMesh,
    quality: &fem_runtime::mesh::triangle::MeshQuality,
    c_i: f64,
) -> Result<()> {
    let Some(model) = &request.pair.row().stabilized else {
        return Ok(());
    };
    let equilateral = [0.0, 0.0, 1.0, 0.0, 0.5, 0.75f64.sqrt()];
    let regular = (model.element_inverse_constant)(&equilateral)?;
    if let Some(alpha) = request.alpha {
        // P1's S_h is α h² (λ, μ) (its C_I is 0): relative to the stiffness it is α itself
        let per_alpha = if regular > 0.0 { regular } else { 1.0 };
        let relative = alpha * per_alpha;
        if alpha == 0.0 || relative >= SMALLEST_RELATIVE_STABILIZATION {
            return Ok(());
        }
        return Err(Error::Input(format!(
            "--alpha {alpha:e} makes the stabilization of a well-shaped triangle {relative:.1e} of its stiffness, below {SMALLEST_RELATIVE_STABILIZATION:.0e}: {} would run practically unstabilized, with λ_h lost in rounding (its Newton Hessian is then not positive definite in floating point); give --alpha 0 for the plain method, or at least {:.2e}",
            request.pair.name(),
            // rounded up: the printed value itself passes
            1.01 * SMALLEST_RELATIVE_STABILIZATION / per_alpha
        )));
    }
    if c_i <= 0.0 {
        return Ok(());
    }
    let relative = 0.5 / c_i * regular;
    if relative >= SMALLEST_RELATIVE_STABILIZATION {
        return Ok(());
    }
    Err(Error::Input(format!(
        "the mesh's worst triangle, {}, has C_I = {c_i:.3e}, which forces α = ½/C_I = {:.3e}: the stabilization of a well-shaped triangle is then {relative:.1e} of its stiffness, below {SMALLEST_RELATIVE_STABILIZATION:.0e}, so {} would run practically unstabilized with λ_h lost in rounding; remesh with better-shaped triangles (or give --alpha explicitly)",
        worst_cell(mesh, quality.min_angle_cell),
        0.5 / c_i,
        request.pair.name()
    )))
}

/// An `--alpha` this many times the default is named when u_h crosses ψ.
const LARGE_ALPHA_FACTOR: f64 = 10.0;

/// Below this an `--alpha` given by the user is named in a solver's failure.
const SMALL_ALPHA: f64 = 1e-6;

/// `error` with the user's `alpha` named as the likely cause, when it is positive and
/// below [`SMALL_ALPHA`] and the solvers failed: the eliminated multipliers are
/// `(G − BU)/(α h² |T|)`, whose rounding grows like `1/(α h²)`, so a small α that works on
/// a coarse mesh fails on a fine one (p1-p0 at α = 1e-13: N = 16 solves, N = 128 does
/// not), and Newton's failure alone does not say why.
fn small_alpha_hint(error: Error, alpha: Option<f64>) -> Error {
    let Some(alpha) = alpha.filter(|&a| a > 0.0 && a < SMALL_ALPHA) else {
        return error;
    };
    with_solver_hint(
        error,
        format!(
            "--alpha {alpha:e} is small: with so little stabilization the multipliers, eliminated as (G − BU)/(α h² |T|), drown in rounding on fine meshes; give --alpha 0 for the plain method, or a larger α"
        ),
    )
}

/// A solver failure (`NotConverged`, `LinearSolve`) with `hint` appended to its detail;
/// other errors unchanged.
pub(crate) fn with_solver_hint(error: Error, hint: String) -> Error {
    match error {
        Error::NotConverged { solver, detail } => Error::NotConverged {
            solver,
            detail: format!("{detail}; {hint}"),
        },
        Error::LinearSolve(detail) => Error::LinearSolve(format!("{detail}; {hint}")),
        other => other,
    }
}

/// "cell 3 with corners (…), (…), (…) and angles …°, …°, …°", for messages.
fn worst_cell(mesh: &TriangleMesh, c: usize) -> String {
    let angles: Vec<String> = mesh
        .cell_angles(c)
        .iter()
        .map(|a| match a.to_degrees() {
            d if d >= 0.01 => format!("{d:.4}°"),
            d => format!("{d:.3e}°"),
        })
        .collect();
    let corners: Vec<String> = mesh
        .cell(c)
        .iter()
        .map(|&v| format!("({}, {})", mesh.vertices()[v][0], mesh.vertices()[v][1]))
        .collect();
    format!(
        "cell {c} with corners {} and angles {}",
        corners.join(", "),
        angles.join(", ")
    )
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
        // not `at`: the field may not be written at all (a tester's file had no
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

/// The most memory a solve may plan to use, on any machine.
pub const MEMORY_LIMIT_BYTES: f64 = 16.0 * (1u64 << 30) as f64;

/// The share of the memory available now (`MemAvailable` of `/proc/meminfo`) a solve
/// may plan to use: the estimates are within about 20 % of the measured peaks.
pub const AVAILABLE_MEMORY_SHARE: f64 = 0.8;

/// The most memory a solve may plan to use here: [`MEMORY_LIMIT_BYTES`], or
/// [`AVAILABLE_MEMORY_SHARE`] of the memory available if that is less: the kernel's
/// `MemAvailable` (`/proc/meminfo`, in KiB) and a container's limit (cgroup v2
/// `memory.max`, v1 `memory.limit_in_bytes`), which `/proc/meminfo` does not show. A
/// tester's 28 GB run on a 23 GB machine passed a fixed 16 GiB check with an estimate of
/// half its need and was killed by the kernel. What cannot be read does not lower it.
pub fn memory_limit_bytes() -> f64 {
    MEMORY_LIMIT_BYTES
        .min(available_memory_bytes().map_or(f64::INFINITY, |b| AVAILABLE_MEMORY_SHARE * b))
}

/// The memory available to this process, as [`memory_limit_bytes`] reads it, in bytes;
/// `None` where none of its sources can be read.
fn available_memory_bytes() -> Option<f64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|text| {
            text.lines()
                .find_map(|line| line.strip_prefix("MemAvailable:"))
                .and_then(|rest| rest.trim().strip_suffix("kB"))
                .and_then(|kb| kb.trim().parse::<f64>().ok())
                .map(|kb| kb * 1024.0)
        });
    // "max" (no limit) does not parse, nor does a missing file
    let cgroup = [
        "/sys/fs/cgroup/memory.max",
        "/sys/fs/cgroup/memory/memory.limit_in_bytes",
    ]
    .iter()
    .find_map(|path| {
        std::fs::read_to_string(path)
            .ok()
            .and_then(|text| text.trim().parse::<f64>().ok())
    });
    match (meminfo, cgroup) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

/// "the 12.3 GB this solver allows itself here (80 % of the memory available now)" or,
/// where the fixed limit is the lower one, "… (its fixed limit)", for messages.
pub(crate) fn memory_limit_text(limit: f64) -> String {
    let why = if limit < MEMORY_LIMIT_BYTES {
        format!(
            "{:.0} % of the memory available now",
            100.0 * AVAILABLE_MEMORY_SHARE
        )
    } else {
        "its fixed limit".to_string()
    };
    format!(
        "the {:.1} GB this solver allows itself here ({why})",
        limit / 1e9
    )
}

/// "needs about 23.5 GB of memory, more than the 17.2 GB this solver allows itself here
/// (…)" when an estimated peak of `bytes` exceeds [`memory_limit_bytes`], for the
/// refusals of every family (each names its own input before it); `None` when it fits.
pub(crate) fn beyond_memory(bytes: f64) -> Option<String> {
    let limit = memory_limit_bytes();
    (bytes > limit).then(|| {
        format!(
            "needs about {:.1} GB of memory, more than {}",
            bytes / 1e9,
            memory_limit_text(limit)
        )
    })
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

/// The degree of the rule for the error norms of a solve whose u field has degree `k`
/// (`‖u − u_h‖_{L²}`, `|u − u_h|_{H¹}` and the multiplier's error): `2k + 4`. Where u is
/// smooth, `2k + 2` integrates the leading term of the squared error exactly, but the
/// kink of u at the free boundary lies inside cells. A tester's reference (8–24²
/// sub-triangles per cell, membrane-radial) measured:
/// - with `2k + 2`, errors off by up to 9e-4 relative in L² at N = 16, and the P0
///   multiplier's by 2 % at N = 32–64;
/// - P2's H¹ error at N = 32 moved by 2 %;
/// - with `2k + 4`, P1 errors within 1e-5 (L²) and 2.4e-4 (H¹) of the reference.
///
/// So the extra 0.15 s at 2M cells is kept.
pub fn error_rule_degree(k: usize) -> usize {
    2 * k + 4
}

/// `(u, ∇u)` of an exact solution, as the error norms take it.
fn exact_values(exact: &ExactMembrane) -> impl Fn([f64; 2]) -> (f64, [f64; 2]) + '_ {
    move |x| (exact.u.at(&x), exact.gradient.at(&x))
}

/// `[max, mean]` of `|u_h − u|` at the vertices of a Lagrange field (its first DOF at a
/// vertex is the value there); `None` without an exact solution.
fn vertex_errors(u: &TriangleField, exact: Option<&ExactMembrane>) -> [Option<f64>; 2] {
    let Some(exact) = exact else {
        return [None, None];
    };
    let (mut max, mut sum) = (0.0f64, 0.0);
    for (v, x) in u.mesh.vertices().iter().enumerate() {
        let e = (u.coefficients[u.map.vertex_dofs(v).start] - exact.u.at(x)).abs();
        max = max.max(e);
        sum += e;
    }
    [Some(max), Some(sum / u.mesh.vertex_count() as f64)]
}

fn run_stabilized<M: Model>(
    request: &MembraneRequest,
    posed: &Posed,
    meshes: &[TriangleMesh],
    alpha: f64,
    c_i: f64,
) -> Result<(MembraneReport, MembraneFields)> {
    let scene = &request.scene;
    let mut warnings = Vec::new();
    let solver = if alpha == 0.0 && request.solver == VariationalSolver::SemismoothNewton {
        warnings.push("α = 0 (the plain mixed method): C = 0 leaves nothing to eliminate Λ with, so the QP solver (clarabel) is used".to_string());
        VariationalSolver::Clarabel
    } else {
        request.solver
    };
    if c_i > 0.0 && alpha * c_i >= 1.0 {
        warnings.push(format!(
            "α·C_I = {:.2} ≥ 1: outside the stability range 0 < α < 1/C_I = {:.3e}; expect a degraded or unstable solution",
            alpha * c_i,
            1.0 / c_i
        ));
    }
    let coefficients = scene_coefficients::<M>(&posed.data, alpha)?;
    let options = ObstacleOptions {
        linear_solver: request.linear_solver,
        ..membrane_options(solver)
    };
    let meshes = if solver == VariationalSolver::Clarabel {
        &meshes[meshes.len() - 1..]
    } else {
        meshes
    };
    let solution = solve_obstacle_on_part::<M>(meshes, &coefficients, &posed.part, options).map_err(
        |e| {
            if c_i > 0.0 && alpha * c_i >= 1.0 {
                Error::Input(format!(
                    "α·C_I = {:.2} is outside the stability range 0 < α < 1/C_I = {:.3e}, where A_α = a − αS is indefinite, and the solve failed: {e}",
                    alpha * c_i,
                    1.0 / c_i
                ))
            } else {
                e
            }
        },
    )?;
    if request.linear_solver == LinearSolver::Multigrid && solution.iterative_steps == 0 {
        warnings.push(multigrid_unused(
            solver,
            "a cold start, a single level or N below 8",
        ));
    }
    let u_field = M::field("u")?;
    let d = &solution.discretization;
    let (primal_count, multiplier_count) = (d.lcp.n(), d.lcp.m());
    if alpha == 0.0 && multiplier_count > primal_count {
        warnings.push(format!(
            "α = 0: the plain pair has {multiplier_count} multipliers for {primal_count} primal unknowns, so Bᵀ has a kernel of dimension at least {} (no discrete inf-sup condition, docs/mathematics.md §1): u_h is unique, but where that kernel meets the contact set λ_h is not, and the λ_h, ∫λ_h and contact set reported are one of many; α > 0 (the default) gives the unique stabilized λ_h",
            multiplier_count - primal_count
        ));
    }
    let u = solution.view(u_field);
    let lambda = solution.view(d.multiplier_field);
    // each error with a rule of its own field's degree: λ's P0 at the u field's degree 6
    // took a quarter of the report's time at 2M cells
    let degree = error_rule_degree(M::FIELDS[u_field].element.degree());
    let (error_l2, error_h1, error_multiplier) = match &posed.exact {
        Some(exact) => {
            let (l2, h1) = u.errors(&exact_values(exact), degree);
            let multiplier = exact.multiplier.as_ref().map(|multiplier| {
                lambda.weighted_error(&|x: [f64; 2]| multiplier.at(&x), 1, degree)
            });
            (Some(l2), Some(h1), multiplier)
        }
        None => (None, None, None),
    };
    let [error_vertex_max, error_vertex_mean] = vertex_errors(&u, posed.exact.as_ref());
    let max_open_contact_gap = fem_runtime::obstacle::triangle::max_open_contact_gap(
        &u,
        &lambda,
        posed.data.obstacle.as_data_fn(),
        1.0,
    );
    if let Some(w) = open_gap_warning(
        max_open_contact_gap,
        &u,
        posed.data.obstacle.as_data_fn(),
        posed.data.load.as_data_fn(),
        alpha,
    ) {
        warnings.push(w);
    }
    if solution.multiplier_noise > 1e-6 {
        warnings.push(format!(
            "λ_h may carry rounding noise of up to {:.0e} relative",
            solution.multiplier_noise
        ));
    }
    let primal_rounding = primal_rounding(&solution, u_field, posed.data.obstacle.as_data_fn());
    if primal_rounding > MAX_PRIMAL_ROUNDING {
        return Err(Error::Input(format!(
            "the load dwarfs the obstacle: in contact the constraint rows subtract terms of the load's size, and their rounding moves u by {primal_rounding:.0e} of its own size; the answer would be rounding (its KKT residual cannot show it)"
        )));
    }
    if primal_rounding > 1e-8 {
        warnings.push(format!(
            "u may be off by {primal_rounding:.0e} of its size through the rounding of the contact rows (the load dwarfs the obstacle)"
        ));
    }
    // once for the area and the fields' contact indicator
    let contact = solution.contact_shares();
    let contact_area = contact
        .iter()
        .enumerate()
        .map(|(c, share)| share * d.mesh.area(c))
        .sum();
    let penetration = fem_runtime::obstacle::triangle::penetration(
        &u,
        posed.data.obstacle.as_data_fn(),
        2 * M::FIELDS[u_field].element.degree(),
    );
    let report = MembraneReport {
        scene: scene.name.to_string(),
        pair: request.pair.name().into(),
        solver: solver_name(solver).into(),
        linear_solver: solution.linear_solver_name(),
        krylov_iterations: solution.krylov_iterations,
        factorizations: solution.factorizations,
        domain: posed.domain.clone(),
        dirichlet_parts: scene.dirichlet.names(),
        load: posed.load,
        mesh_size: request.mesh_size,
        triangles: d.mesh.cell_count(),
        dofs: d.lcp.n() + d.lcp.m(),
        iterations: solution.iterations,
        levels: solution.levels.iter().map(|&(c, i)| [c, i]).collect(),
        seconds: solution.seconds,
        alpha,
        inverse_constant: c_i,
        error_l2,
        error_h1,
        error_vertex_max,
        error_vertex_mean,
        error_multiplier,
        total_contact_force: solution.total_contact_force(),
        exact_contact_force: posed.exact.as_ref().and_then(|e| e.total_contact_force),
        contact_area,
        exact_contact_area: posed.exact.as_ref().and_then(|e| e.contact_area),
        complementarity_residual: solution.kkt_residual,
        multiplier_noise: solution.multiplier_noise,
        primal_rounding,
        max_penetration: penetration.depth,
        obstacle_range: penetration.obstacle_range(),
        max_open_contact_gap,
        accuracy: None,
        warnings,
        mesh_quality: MeshQualityReport::default(),
        phases: PhaseSeconds::default(),
    };
    let fields = stabilized_fields(solution, u_field, &posed.data, contact);
    Ok((report, fields))
}

/// The warning of a `--linear-solver multigrid` request that no finest Newton step used
/// (`no_level`: when the family's nested solve has no coarser level).
pub(crate) fn multigrid_unused(solver: VariationalSolver, no_level: &str) -> String {
    if solver == VariationalSolver::SemismoothNewton {
        format!("--linear-solver multigrid: no Newton step of the finest level was solved by multigrid (it needs a coarser nested level: {no_level} have none; or CG did not converge), so they were factored")
    } else {
        "--linear-solver multigrid: the QP solver (clarabel) has no Newton steps; it factors its own systems".to_string()
    }
}

fn solver_name(solver: VariationalSolver) -> &'static str {
    match solver {
        VariationalSolver::SemismoothNewton => "pdas",
        VariationalSolver::Clarabel => "clarabel",
    }
}

/// The fields of a stabilized solve; `contact` is its
/// [`contact_shares`](fem_runtime::obstacle::ObstacleSolution::contact_shares).
fn stabilized_fields(
    solution: TriangleObstacleSolution,
    u_field: usize,
    data: &SceneData,
    contact: Vec<f64>,
) -> MembraneFields {
    let d = &solution.discretization;
    let lambda = solution.view(d.multiplier_field).centroid_values();
    let u_dofs = d.dofs.map(u_field).unwrap().clone();
    let u_coefficients = solution.field(u_field).to_vec();
    // the mesh moves into the fields (its tables are shared, so a clone would do too)
    let mesh = solution.discretization.mesh;
    MembraneFields::new(mesh, data, u_dofs, u_coefficients, lambda, contact)
}

/// From this many triangles on, the nodal method builds its finest level on the second
/// core while the coarser levels solve (below it a thread's start costs more than it
/// saves).
const PIPELINED_CELLS: usize = 32_768;

/// One level of the nodal method before its solve: DOFs, elimination of the boundary
/// DOFs, stiffness `a`, load `f` and obstacle `ψ` on the free nodes, and the
/// prolongations from the next coarser level (all DOFs; free DOFs) if there is one.
struct NodalLevel {
    /// The level's DOF count; its DOF map is not kept (48 MB at 2M cells, rebuilt for
    /// the finest level after the solve).
    dof_count: usize,
    reduction: Reduction,
    a: SparseMatrix,
    f: Vec<f64>,
    psi: Vec<f64>,
    prolongations: Option<(SparseMatrix, SparseMatrix)>,
}

/// The nodal method's nested iteration so far: (DOFs, iterations) per level, the
/// prolongations of the free DOFs finest first, the last level's full coefficients and
/// its elimination, solution and order.
#[derive(Default)]
struct NodalState {
    levels: Vec<[usize; 2]>,
    prolongations: Vec<SparseMatrix>,
    values: Option<Vec<f64>>,
    finest: Option<(Reduction, LcpSolution, usize)>,
}

/// The classical method: P1 with `u_i ≥ ψ(x_i)` at the free nodes.
fn run_nodal(
    request: &MembraneRequest,
    posed: &Posed,
    mut meshes: Vec<TriangleMesh>,
) -> Result<(MembraneReport, MembraneFields)> {
    type M = membrane_p1::Model;
    let clock = Instant::now();
    let scene = &request.scene;
    let data = &posed.data;
    let coefficients = Coefficients::new::<M>(
        &[],
        &[
            ("f", data.load.as_data_fn()),
            ("g", data.boundary.as_data_fn()),
        ],
    )?;
    // Everything a level needs before its solve; the finest level's is built on the
    // second core while the coarser levels solve (`alongside`).
    let setup = |i: usize| -> Result<NodalLevel> {
        let mesh = &meshes[i];
        let free_dofs = |mesh: &TriangleMesh| -> Result<(SystemDofs, Reduction, Constraints)> {
            let dofs = SystemDofs::all::<M>(mesh)?;
            let constraints =
                dirichlet_constraints_on::<M>(mesh, &dofs, &coefficients, &posed.part)?;
            let reduction = constraints.reduction(dofs.dof_count())?;
            Ok((dofs, reduction, constraints))
        };
        let (dofs, reduction, _) = free_dofs(mesh)?;
        // the pattern moves into `k` and `k`'s arrays into `a` (no copies: issue 15,
        // peak memory)
        let k =
            MatrixAssembler::new::<M>("a", mesh, &dofs)?.into_matrix::<M>(mesh, &coefficients)?;
        let l = assemble_vector::<M>("ℓ", mesh, &dofs, &coefficients)?;
        let f = reduction.rhs(&k, &l);
        drop(l);
        let a = reduction.into_matrix(k);
        let nodes = dofs.map(0).unwrap().nodes(mesh);
        let psi: Vec<f64> = reduction
            .free()
            .iter()
            .map(|&d| data.obstacle.at(&nodes[d]))
            .collect();
        let prolongations = match i.checked_sub(1).map(|c| &meshes[c]) {
            Some(coarse) => {
                let (coarse_dofs, coarse_reduction, _) = free_dofs(coarse)?;
                let parents = parents_by_location(coarse, mesh)?;
                let level = |mesh, dofs, reduction| NestedLevel {
                    mesh,
                    dofs,
                    reduction,
                };
                let all = prolongation(
                    &level(coarse, &coarse_dofs, None),
                    &level(mesh, &dofs, None),
                    &parents,
                )?;
                let free = reduced_prolongation(&all, &coarse_reduction, &reduction)?;
                Some((all, free))
            }
            None => None,
        };
        Ok(NodalLevel {
            dof_count: dofs.dof_count(),
            reduction,
            a,
            f,
            psi,
            prolongations,
        })
    };
    let mut state = NodalState::default();
    // the meshes are drained before the finest level's step: count them now
    let level_count = meshes.len();
    let step = |state: &mut NodalState, level: NodalLevel| -> Result<()> {
        let NodalLevel {
            dof_count,
            reduction,
            a,
            f,
            psi,
            prolongations,
        } = level;
        // the coarser level's results go before this level's solve allocates (issue 15:
        // peak memory); only its values are needed, for the start
        state.finest = None;
        // the coarse solution interpolated at the fine nodes, boundary values included
        let start = match (prolongations, state.values.take()) {
            (Some((all, free)), Some(values)) => {
                let fine = multiply(&all, &values);
                state.prolongations.insert(0, free);
                Some(
                    reduction
                        .free()
                        .iter()
                        .map(|&d| fine[d])
                        .collect::<Vec<f64>>(),
                )
            }
            _ => None,
        };
        let multigrid = match request.linear_solver {
            LinearSolver::Direct => false,
            LinearSolver::Multigrid => !state.prolongations.is_empty(),
            LinearSolver::Auto => {
                a.nrows() >= NODAL_AUTO_MULTIGRID_UNKNOWNS && state.prolongations.len() >= 2
            }
        };
        let hierarchy: &[SparseMatrix] = if multigrid { &state.prolongations } else { &[] };
        let last = state.levels.len() + 1 == level_count;
        let solution =
            nodal_active_set_level(&a, &f, &psi, start.as_deref(), 500, hierarchy, last)?;
        state.levels.push([dof_count, solution.iterations]);
        state.values = Some(reduction.expand(&solution.u));
        state.finest = Some((reduction, solution, a.nrows()));
        Ok(())
    };
    let count = meshes.len();
    let cell_counts: Vec<usize> = meshes.iter().map(TriangleMesh::cell_count).collect();
    if count >= 3 && meshes[count - 1].cell_count() >= PIPELINED_CELLS {
        let mut finest = None;
        alongside(
            || finest = Some(setup(count - 1)),
            || -> Result<()> {
                for i in 0..count - 1 {
                    step(&mut state, setup(i)?)?;
                }
                Ok(())
            },
        )?;
        // every level is set up: the coarser meshes (a third of the meshes' memory) are
        // not needed for the finest solve nor after it
        meshes.drain(..count - 1);
        step(&mut state, finest.expect("the worker has run")?)?;
    } else {
        for i in 0..count {
            step(&mut state, setup(i)?)?;
        }
    }
    let mut levels = state.levels;
    for (level, cells) in levels.iter_mut().zip(cell_counts) {
        level[0] = cells;
    }
    let mesh = meshes.last().expect("at least one mesh");
    let values = state.values.expect("at least one mesh");
    let (reduction, solution, n) = state.finest.expect("at least one mesh");
    let (krylov_iterations, factorizations) = (solution.krylov_iterations, solution.factorizations);
    let seconds = clock.elapsed().as_secs_f64();
    // the same numbering as the solve's (a function of the mesh alone)
    let dofs = SystemDofs::all::<M>(mesh)?;
    let map = dofs.map(0).unwrap();
    let u = TriangleField {
        mesh,
        map,
        coefficients: &values,
    };
    let (error_l2, error_h1) = match &posed.exact {
        Some(exact) => {
            let (l2, h1) = u.errors(
                &exact_values(exact),
                error_rule_degree(u.map.element().degree()),
            );
            (Some(l2), Some(h1))
        }
        None => (None, None),
    };
    let [error_vertex_max, error_vertex_mean] = vertex_errors(&u, posed.exact.as_ref());
    // nodal forces: active where λ_i > 0 or the node lies on ψ (boundary nodes too)
    let mut vertex_force = vec![0.0; mesh.vertex_count()];
    let scale = solution.lambda.iter().cloned().fold(0.0, f64::max);
    for (k, &dof) in reduction.free().iter().enumerate() {
        vertex_force[dof] = solution.lambda[k];
    }
    let mut free = vec![false; mesh.vertex_count()];
    for &dof in reduction.free() {
        free[dof] = true;
    }
    let on_obstacle = |v: usize| {
        let gap = values[v] - data.obstacle.at(&mesh.vertices()[v]);
        gap.abs() <= 1e-10 * (1.0 + values[v].abs())
    };
    let interior_active: Vec<bool> = (0..mesh.vertex_count())
        .map(|v| free[v] && (vertex_force[v] > 1e-8 * scale.max(1e-300) || on_obstacle(v)))
        .collect();
    // A boundary vertex where g = ψ lies on the obstacle whether or not the membrane
    // touches it: it counts as contact only next to contact, found in two steps (next to
    // interior contact, then next to those, which reaches a corner cell whose three
    // vertices are all on the boundary).
    let spread = |active: &[bool]| -> Vec<bool> {
        let mut next = active.to_vec();
        for c in 0..mesh.cell_count() {
            let cell = mesh.cell(c);
            if cell.iter().any(|&v| active[v]) {
                for v in cell {
                    next[v] |= !free[v] && on_obstacle(v);
                }
            }
        }
        next
    };
    let vertex_active = spread(&spread(&interior_active));
    let mut vertex_area = vec![0.0; mesh.vertex_count()];
    for c in 0..mesh.cell_count() {
        for v in mesh.cell(c) {
            vertex_area[v] += mesh.area(c) / 3.0;
        }
    }
    let contact: Vec<f64> = (0..mesh.cell_count())
        .map(|c| mesh.cell(c).iter().filter(|&&v| vertex_active[v]).count() as f64 / 3.0)
        .collect();
    let contact_area = contact
        .iter()
        .enumerate()
        .map(|(c, s)| s * mesh.area(c))
        .sum();
    let lambda = (0..mesh.cell_count())
        .map(|c| {
            mesh.cell(c)
                .iter()
                .map(|&v| vertex_force[v] / vertex_area[v])
                .sum::<f64>()
                / 3.0
        })
        .collect();
    let penetration =
        fem_runtime::obstacle::triangle::penetration(&u, posed.data.obstacle.as_data_fn(), 2);
    let mut report = MembraneReport {
        scene: scene.name.to_string(),
        pair: request.pair.name().into(),
        solver: "nodal active set".into(),
        // every free node in contact (or the start already the solution): no system
        linear_solver: if krylov_iterations > 0 {
            "multigrid"
        } else if factorizations > 0 {
            "direct"
        } else {
            "none"
        },
        krylov_iterations,
        factorizations,
        domain: posed.domain.clone(),
        dirichlet_parts: scene.dirichlet.names(),
        load: posed.load,
        mesh_size: request.mesh_size,
        triangles: mesh.cell_count(),
        dofs: n,
        iterations: solution.iterations,
        levels,
        seconds,
        alpha: 0.0,
        inverse_constant: 0.0,
        error_l2,
        error_h1,
        error_vertex_max,
        error_vertex_mean,
        error_multiplier: None,
        // a fold from +0: Rust's float `sum` of no terms is −0, which JSON and the
        // table printed for a mesh with no free node
        total_contact_force: solution.lambda.iter().fold(0.0, |s, l| s + l),
        exact_contact_force: posed.exact.as_ref().and_then(|e| e.total_contact_force),
        contact_area,
        exact_contact_area: posed.exact.as_ref().and_then(|e| e.contact_area),
        complementarity_residual: solution.kkt_residual,
        multiplier_noise: 0.0,
        primal_rounding: 0.0,
        max_penetration: penetration.depth,
        obstacle_range: penetration.obstacle_range(),
        // the nodal constraint holds exactly at the nodes: a pushing node touches ψ
        max_open_contact_gap: 0.0,
        accuracy: None,
        warnings: if (0..mesh.vertex_count()).any(|v| !free[v] && vertex_active[v]) {
            vec![
                "∫λ_h of the nodal method sums the forces at the free nodes: contact reaches the boundary where u = g = ψ, whose nodes carry a share of order h it leaves out (for example membrane-flat at N = 16 and q = 1: 14.06 of the exact 16); a stabilized pair or a finer mesh gives it".into(),
            ]
        } else {
            Vec::new()
        },
        mesh_quality: MeshQualityReport::default(),
        phases: PhaseSeconds::default(),
    };
    // with no factorization either, no step had a system to solve (every free node in
    // contact, or the start already the solution): nothing to warn about
    if request.linear_solver == LinearSolver::Multigrid
        && krylov_iterations == 0
        && factorizations > 0
    {
        report.warnings.push(
            "--linear-solver multigrid: no active-set step of the finest level was solved by multigrid (it needs a coarser nested level: a cold start, a single level or N below 8 have none; or CG did not converge), so they were factored".into(),
        );
    }
    let map = map.clone();
    // the finest mesh moves into the fields (its tables are shared, so a clone would do too)
    let mesh = meshes.pop().expect("at least one mesh");
    let fields = MembraneFields::new(mesh, data, map, values, lambda, contact);
    Ok((report, fields))
}

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

/// Largest rounding of u through the contact rows, relative to its size, accepted in a
/// result ([`MembraneReport::primal_rounding`]).
const MAX_PRIMAL_ROUNDING: f64 = 1e-3;

/// [`fem_runtime::obstacle::ObstacleSolution::primal_rounding`] relative to the size of
/// the answer ([`answer_level`]).
fn primal_rounding(
    solution: &TriangleObstacleSolution,
    u_field: usize,
    obstacle: &fem_runtime::DataFn,
) -> f64 {
    let mesh = &solution.discretization.mesh;
    let largest = |values: &mut dyn Iterator<Item = f64>| {
        values
            .filter(|v| v.is_finite())
            .fold(0.0, |m: f64, v| m.max(v.abs()))
    };
    let u_size = largest(&mut solution.field(u_field).iter().copied());
    let psi_size = largest(&mut mesh.vertices().iter().map(|p| obstacle(p)));
    let level = answer_level(u_size, psi_size, bounding_diameter(mesh));
    if level > 0.0 {
        solution.primal_rounding() / level
    } else {
        0.0
    }
}

/// The size an error in u_h is judged against: the largest `|u_h|` and `|ψ|` (both
/// scale with the data, so that scaling f, ψ and g together, which scales the exact
/// solution, leaves every judgement the same), or, where ψ is exactly 0 (a membrane
/// pressed flat onto ψ = 0 has u ≡ 0, and any rounding would be infinitely large
/// against it), the larger of `|u_h|` and 1e-6 of the mesh's diameter `d` (a
/// deflection is a length: one a millionth of the domain is the least that is judged).
///
/// The floor applied everywhere broke the scaling: a tester's membrane-lshape with ψ, f
/// and g scaled by 1e-20 was judged against it, and its u_h, 25 times ψ's range below ψ,
/// passed without a word while the same problem at scale 1 (q = 1e20) was refused. And
/// `|f| d²` in its place where ψ ≡ 0 (the re-test) hid membrane-flat at q = 1e20, whose
/// u_h is 46 against the exact 0.
fn answer_level(u_size: f64, psi_size: f64, diameter: f64) -> f64 {
    if psi_size > 0.0 {
        u_size.max(psi_size)
    } else {
        u_size.max(1e-6 * diameter)
    }
}

/// The rounding of the values of u_h and ψ that penetration and open-gap judgements
/// compare: [`OPEN_GAP_ROUNDING`] ε times the largest `|u_h|` and `|ψ|` (ψ = 10¹² +
/// 10⁻³x dipped one ulp of 10¹², "9.4 %" of its range), plus 10 ε `|f| d²`, the
/// rounding of a solve under the load `f` over the diameter `d` (membrane-flat's u = ψ
/// = 0 showed gaps of 5e-17 under f = −3). With 1e3 ε on the load term too, the
/// threshold at q = 1e12 on membrane-lshape was 1.8, and hid a penetration of 53 %.
fn value_rounding(u_size: f64, psi_size: f64, load_size: f64, diameter: f64) -> f64 {
    OPEN_GAP_ROUNDING * f64::EPSILON * u_size.max(psi_size)
        + 10.0 * f64::EPSILON * load_size * diameter * diameter
}

/// Largest open gap under a pushing λ_h, relative to the size of u_h and ψ (the largest
/// `|u_h|`, `|ψ|` at the vertices), that passes without a warning.
pub const OPEN_GAP_WARNING: f64 = 1e-2;

/// Gaps and crossings below this multiple of the machine epsilon times the largest
/// `|u_h|` and `|ψ|` are rounding ([`value_rounding`]).
const OPEN_GAP_ROUNDING: f64 = 1e3;

/// A warning when λ_h pushes on cells that stay clear of ψ by more than
/// [`OPEN_GAP_WARNING`] of the solution's size (docs/mathematics.md §1: the stabilized
/// constraint `u_h − ψ = α h² (…)` on the contact cells lets `α h²` open a gap), and by
/// more than rounding ([`OPEN_GAP_ROUNDING`]).
fn open_gap_warning(
    gap: f64,
    u: &TriangleField,
    obstacle: &fem_runtime::DataFn,
    load: &fem_runtime::DataFn,
    alpha: f64,
) -> Option<String> {
    let vertices = u.mesh.vertices();
    let (u_size, psi_size, largest_load) =
        vertices
            .iter()
            .zip(0..)
            .fold((0.0f64, 0.0f64, 0.0f64), |(s, p, l), (x, v)| {
                let value = u.coefficients[u.map.vertex_dofs(v).start];
                (
                    s.max(value.abs()),
                    p.max(obstacle(x).abs()),
                    l.max(load(x).abs()),
                )
            });
    let size = u_size.max(psi_size);
    let rounding = value_rounding(u_size, psi_size, largest_load, bounding_diameter(u.mesh));
    (gap > OPEN_GAP_WARNING * size && gap > rounding).then(|| {
        format!(
            "λ_h pushes on cells where u_h stays up to {gap:.2e} clear of ψ ({:.1} % of the solution's size {size:.2e}): the stabilized constraint u_h − ψ = α h²(…) on contact cells lets α h² (α = {alpha:e}) open that gap, so this contact set is not real; refine the mesh or lower α",
            100.0 * gap / size
        )
    })
}

/// The diagonal of `mesh`'s bounding box (its vertices' coordinates' extents).
pub(crate) fn bounding_diameter(mesh: &TriangleMesh) -> f64 {
    let extent = |k: usize| {
        let (lo, hi) = mesh
            .vertices()
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                (lo.min(x[k]), hi.max(x[k]))
            });
        hi - lo
    };
    extent(0).hypot(extent(1))
}

/// Largest `max_penetration`, relative to the larger of ψ's range over the points
/// sampled and u_h's range over the vertices, that passes without a warning.
const PENETRATION_WARNING: f64 = 1e-2;

/// What `max_penetration` is compared with ([`penetration_warning`]), from the solved
/// fields: `scale`, the larger of ψ's range over the penetration's samples and u_h's
/// range over the vertices (a flat ψ under a bent membrane still has a size to compare
/// with: a tester's ψ = 0 under g = 1 dipped 0.62 without a word), and `rounding`, the
/// rounding of the values compared ([`value_rounding`]).
fn penetration_scales(
    report: &MembraneReport,
    fields: &MembraneFields,
    load: &fem_runtime::DataFn,
) -> (f64, f64) {
    let extremes = |values: &[f64]| {
        values
            .iter()
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            })
    };
    let (u_lo, u_hi) = extremes(&fields.u);
    let (psi_lo, psi_hi) = extremes(&fields.psi);
    let largest_load = fields
        .mesh
        .vertices()
        .iter()
        .map(|x| load(x).abs())
        .filter(|f| f.is_finite())
        .fold(0.0f64, f64::max);
    let size = |lo: f64, hi: f64| {
        [lo, hi]
            .iter()
            .filter(|v| v.is_finite())
            .fold(0.0f64, |m, v| m.max(v.abs()))
    };
    let u_range = if u_hi >= u_lo { u_hi - u_lo } else { 0.0 };
    (
        report.obstacle_range.max(u_range),
        value_rounding(
            size(u_lo, u_hi),
            size(psi_lo, psi_hi),
            largest_load,
            bounding_diameter(&fields.mesh),
        ),
    )
}

/// A warning when u_h dips below ψ by more than [`PENETRATION_WARNING`] of `range` and
/// by more than `rounding` ([`penetration_scales`]): the weak cell-wise constraint lets
/// u_h cross ψ by O(h²|∇²(u − ψ)|), and a load that bends u sharply at the free boundary
/// (membrane-lshape at q = 1e4: 0.38 on N = 64, falling to 0.034 on N = 256) makes that
/// visible on the mesh.
fn penetration_warning(penetration: f64, range: f64, rounding: f64, nodal: bool) -> Option<String> {
    let share = 100.0 * penetration / range;
    (range > 0.0 && penetration > PENETRATION_WARNING * range && penetration > rounding).then(|| {
        if nodal {
            format!(
                "u_h dips below ψ between the vertices by up to {penetration:.2e}, {share:.1}% of the larger of ψ's and u_h's ranges ({range:.2e}): the nodal constraint holds at the vertices only, and this mesh does not resolve ψ's curvature (refine)"
            )
        } else {
            format!(
                "u_h dips below ψ by up to {penetration:.2e}, {share:.1}% of the larger of ψ's and u_h's ranges ({range:.2e}): the cell-wise constraint does not resolve the free boundary at this mesh size (refine, or use p1-nodal, which keeps u_h ≥ ψ at the vertices)"
            )
        }
    })
}
