//! Solving a beam scene with a chosen element pair and solver, and what a solve reports.

use crate::models::membrane_scenes::MAX_LOAD;
use crate::models::scenes::{exact_solution, Beam, Scene};
use crate::models::{bernoulli, timoshenko_p1_full, timoshenko_p1_reduced, timoshenko_p2};
use fem_runtime::lcp::NewtonOptions;
use fem_runtime::obstacle::hierarchy::LinearSolver;
use fem_runtime::obstacle::{system_forms, Discretization, ObstacleOptions, VariationalSolver};
use fem_runtime::problem::{Condition, Exact, MemoryModel, ObstacleSide, Problem, SolveOptions};
use fem_runtime::stabilization::Alpha;
use fem_runtime::{Coefficients, DataFn, DirichletPart, Error, IntervalMesh, Model, Result};
use serde::Serialize;

/// The element pairs a beam scene can be solved with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pair {
    /// Timoshenko θ, w ∈ P2, λ ∈ P0 (default for Timoshenko).
    TimoshenkoP2,
    /// Timoshenko θ, w ∈ P1 with one-point shear integration, λ ∈ P0.
    TimoshenkoP1Reduced,
    /// Timoshenko θ, w ∈ P1 with exact shear integration (locks as t → 0).
    TimoshenkoP1Full,
    /// Euler–Bernoulli w ∈ Hermite cubics, λ ∈ P0.
    BernoulliHermite,
}

/// A pair as data: its name, the beam theory it discretizes, its default α and the
/// entry points of its model (the solver and the discretization, instantiated for the
/// model's type). Adding a pair is one row here and its variant of [`Pair`].
struct PairRow {
    pair: Pair,
    name: &'static str,
    beam: Beam,
    /// docs/mathematics.md: α ≈ 1 for Timoshenko, ≤ 1e-2 for Euler–Bernoulli so that the
    /// obstacle shift α h⁴|f| stays negligible.
    default_alpha: f64,
    run: fn(&Request, Pair) -> Result<(Report, Profiles)>,
    discretize: fn(&Request, Pair) -> Result<Discretization>,
}

/// Every pair, in the order of [`Pair::ALL`]; the first of each beam theory is its default.
const PAIRS: [PairRow; 4] = [
    PairRow {
        pair: Pair::TimoshenkoP2,
        name: "p2-p2-p0",
        beam: Beam::Timoshenko,
        default_alpha: 1.0,
        run: run::<timoshenko_p2::Model>,
        discretize: discretize_with::<timoshenko_p2::Model>,
    },
    PairRow {
        pair: Pair::TimoshenkoP1Reduced,
        name: "p1-p1-p0-reduced",
        beam: Beam::Timoshenko,
        default_alpha: 1.0,
        run: run::<timoshenko_p1_reduced::Model>,
        discretize: discretize_with::<timoshenko_p1_reduced::Model>,
    },
    PairRow {
        pair: Pair::TimoshenkoP1Full,
        name: "p1-p1-p0-full",
        beam: Beam::Timoshenko,
        default_alpha: 1.0,
        run: run::<timoshenko_p1_full::Model>,
        discretize: discretize_with::<timoshenko_p1_full::Model>,
    },
    PairRow {
        pair: Pair::BernoulliHermite,
        name: "hermite-p0",
        beam: Beam::EulerBernoulli,
        default_alpha: 1e-2,
        run: run::<bernoulli::Model>,
        discretize: discretize_with::<bernoulli::Model>,
    },
];

impl Pair {
    /// Every pair.
    pub const ALL: [Pair; 4] = [
        Pair::TimoshenkoP2,
        Pair::TimoshenkoP1Reduced,
        Pair::TimoshenkoP1Full,
        Pair::BernoulliHermite,
    ];

    fn row(self) -> &'static PairRow {
        let row = &PAIRS[self as usize];
        debug_assert_eq!(row.pair, self);
        row
    }

    /// Its name on the command line.
    pub fn name(self) -> &'static str {
        self.row().name
    }

    /// The beam theory it discretizes.
    pub fn beam(self) -> Beam {
        self.row().beam
    }

    /// The default pair of a beam theory: its first pair.
    pub fn default_for(beam: Beam) -> Pair {
        PAIRS
            .iter()
            .find(|row| row.beam == beam)
            .map(|row| row.pair)
            .expect("every beam theory has a pair")
    }

    /// The pair called `name`, which must discretize `beam`.
    pub fn parse(name: &str, beam: Beam) -> Result<Pair> {
        let pairs: Vec<&str> = PAIRS
            .iter()
            .filter(|p| p.beam == beam)
            .map(|p| p.name)
            .collect();
        match PAIRS.iter().find(|p| p.name == name) {
            Some(p) if p.beam == beam => Ok(p.pair),
            Some(_) => Err(Error::Input(format!(
                "pair `{name}` is for the other beam theory; this scene takes {}",
                pairs.join(", ")
            ))),
            None => Err(Error::Input(format!(
                "unknown pair `{name}`; this scene takes {}",
                pairs.join(", ")
            ))),
        }
    }

    /// The default stabilization parameter (docs/mathematics.md: α ≈ 1 for Timoshenko, ≤ 1e-2 for
    /// Euler–Bernoulli so that the obstacle shift α h⁴|f| stays negligible).
    pub fn default_alpha(self) -> f64 {
        self.row().default_alpha
    }
}

/// What to solve.
#[derive(Clone, Copy, Debug)]
pub struct Request {
    /// The scene.
    pub scene: Scene,
    /// Number of elements of the uniform mesh on (0, 1).
    pub elements: usize,
    /// Load magnitude q.
    pub load: f64,
    /// Thickness (Timoshenko); the scene's by default.
    pub thickness: Option<f64>,
    /// Stabilization parameter; the pair's default otherwise.
    pub alpha: Option<f64>,
    /// Element pair; the beam's default otherwise.
    pub pair: Option<Pair>,
    /// LCP solver.
    pub solver: VariationalSolver,
    /// Nested iteration from meshes of at least this many cells (Newton only).
    pub nested_from: Option<usize>,
    /// Iterative refinement rounds per linear solve.
    pub refinement_steps: usize,
    /// Solver of the Newton steps: `Auto` and `Direct` factor (banded Cholesky, `O(N)` on
    /// an interval, with low-rank updates); `Multigrid` solves the steps of the levels
    /// above the coarsest by CG with a W-cycle on the nested uniform meshes
    /// (`fem_runtime::obstacle::hierarchy::interval_primal_prolongation`, Hermite slopes
    /// included), for studying multigrid on fourth-order and locking-prone systems.
    pub linear_solver: LinearSolver,
    /// Allow α = 0: the plain (unstabilized) mixed method, for the stability studies;
    /// only the QP solver handles it.
    pub plain: bool,
}

impl Request {
    /// The defaults for a scene: 256 elements, q = 1, nested Newton.
    pub fn new(scene: Scene) -> Self {
        Self {
            scene,
            elements: 256,
            load: 1.0,
            thickness: None,
            alpha: None,
            pair: None,
            solver: VariationalSolver::SemismoothNewton,
            nested_from: Some(16),
            refinement_steps: 1,
            linear_solver: LinearSolver::Auto,
            plain: false,
        }
    }
}

/// What a solve reports (the CLI's `--json` object).
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    /// Scene name.
    pub scene: String,
    /// Element pair.
    pub pair: String,
    /// LCP solver.
    pub solver: String,
    /// Load q.
    pub load: f64,
    /// Thickness (Timoshenko), `null` for Euler–Bernoulli.
    pub thickness: Option<f64>,
    /// Stabilization parameter.
    pub alpha: f64,
    /// `max_T C_I(T)` of the pair's `S_h` against `a` on the mesh
    /// ([`fem_runtime::stabilization`]): 0 for every beam pair (θ''' and w'''' vanish on
    /// each element), so every α > 0 is stable.
    pub inverse_constant: f64,
    /// Elements.
    pub elements: usize,
    /// Unknowns after eliminating boundary DOFs (primal and multiplier).
    pub dofs: usize,
    /// Solver iterations on the final mesh.
    pub iterations: usize,
    /// What solved the finest level's Newton steps: `direct` or `multigrid`.
    pub linear_solver: &'static str,
    /// CG iterations of the finest level's multigrid steps (0 on the direct path).
    pub krylov_iterations: usize,
    /// Cholesky factorizations on the finest level (its steps that multigrid did not
    /// solve start from one; the others are low-rank updates of it).
    pub factorizations: usize,
    /// `[elements, iterations]` of each nested-iteration level.
    pub levels: Vec<[usize; 2]>,
    /// Wall time of the whole solve (assembly, all levels, post-processing excluded).
    pub seconds: f64,
    /// Wall time of the rounding experiment's two repeated solves
    /// ([`Report::thickness_rounding`], [`Report::length_rounding`]), not in `seconds`.
    pub rounding_seconds: f64,
    /// `½a(u,u) − ℓ(u)` of the discrete solution.
    pub energy: f64,
    /// Largest |w|.
    pub max_deflection: f64,
    /// Largest crossing of the obstacle, `max s(ψ − w)₊` at four points per cell (`s = +1`
    /// for an obstacle below): the weak cell-wise constraint allows it inside cells.
    pub max_penetration: f64,
    /// The largest clearance `s(w_h − ψ)` of a cell where λ_h pushes (its smallest over
    /// five points of the cell): 0 for a real contact set; a share of the beam's size
    /// where α (or one long element) lets λ_h push where nothing touches (then warned).
    pub max_open_contact_gap: f64,
    /// Contact intervals `[start, end]`, a point contact as `[x, x]`.
    pub contact_set: Vec<[f64; 2]>,
    /// `∫ λ_h`.
    pub total_contact_force: f64,
    /// KKT residual (equilibrium backward error and complementarity).
    pub complementarity_residual: f64,
    /// `‖w − w_h‖_L2` where an exact solution exists.
    pub error_l2: Option<f64>,
    /// `‖(w − w_h)'‖_L2` where an exact solution exists.
    pub error_h1: Option<f64>,
    /// Estimated relative rounding noise of the multiplier values λ_h (see `warnings`).
    pub multiplier_noise: f64,
    /// How far w may be off through the rounding of the rows in contact, relative to the
    /// larger of `max|w_h|`, `max|ψ|` and 1e-6 of the length (fem_runtime
    /// `Lcp::primal_rounding`).
    pub primal_rounding: f64,
    /// Timoshenko: how far w_h moves when t is changed in its last bits, relative to
    /// `max|w_h|` ([`thickness_rounding`]): an estimate of the part of w_h that is
    /// rounding. `None` for Euler–Bernoulli.
    pub thickness_rounding: Option<f64>,
    /// Euler–Bernoulli: how far w_h and ∫λ_h move when the beam's length is changed in
    /// its last bits (the same experiment with h for t, [`length_rounding`]), relative to
    /// `max|w_h|` and to the load: an estimate of the part that is rounding, from the
    /// stiffness's condition ~h⁻⁴. `None` for Timoshenko.
    pub length_rounding: Option<f64>,
    /// What the numbers cannot be trusted for.
    pub warnings: Vec<String>,
}

/// Sampled fields for plots.
#[derive(Clone, Debug, Default)]
pub struct Profiles {
    /// Sample points.
    pub x: Vec<f64>,
    /// Deflection.
    pub w: Vec<f64>,
    /// Rotation (Timoshenko).
    pub theta: Option<Vec<f64>>,
    /// Obstacle.
    pub psi: Vec<f64>,
    /// Cell midpoints.
    pub cell_x: Vec<f64>,
    /// Multiplier per cell.
    pub lambda: Vec<f64>,
}

/// Solves a request.
pub fn solve(request: &Request) -> Result<(Report, Profiles)> {
    let pair = request
        .pair
        .unwrap_or(Pair::default_for(request.scene.beam));
    if pair.beam() != request.scene.beam {
        return Err(Error::Input(format!(
            "pair `{}` does not discretize scene `{}`",
            pair.name(),
            request.scene.name
        )));
    }
    (pair.row().run)(request, pair)
}

/// The discrete problem of a request (for studies of its matrices), and its pair.
pub fn discretize(request: &Request) -> Result<(Discretization, Pair)> {
    let pair = request
        .pair
        .unwrap_or(Pair::default_for(request.scene.beam));
    Ok(((pair.row().discretize)(request, pair)?, pair))
}

fn discretize_with<M: Model>(request: &Request, pair: Pair) -> Result<Discretization> {
    let setup = Setup::new(request, pair)?;
    let coefficients = setup.coefficients::<M>()?;
    let mesh = IntervalMesh::uniform(0.0, 1.0, request.elements)?;
    let (bilinear, linear) = system_forms::<M>()?;
    Discretization::new::<M>(&mesh, &coefficients, setup.clamped, bilinear, linear)
}

/// Parameters and data of a request, validated.
struct Setup {
    alpha: f64,
    thickness: f64,
    side: f64,
    timoshenko: bool,
    clamped: &'static [&'static str],
    load: Box<DataFn>,
    obstacle: Box<DataFn>,
}

impl Setup {
    fn new(request: &Request, pair: Pair) -> Result<Self> {
        let scene = request.scene;
        let alpha = request.alpha.unwrap_or(pair.default_alpha());
        let thickness = request.thickness.unwrap_or(scene.thickness);
        validate(request, alpha, thickness)?;
        let load = scene.load_sign * request.load;
        let obstacle = scene.obstacle;
        Ok(Self {
            alpha,
            thickness,
            side: scene.side,
            timoshenko: scene.beam == Beam::Timoshenko,
            clamped: match scene.beam {
                Beam::Timoshenko => &["θ", "w"],
                Beam::EulerBernoulli => &["w"],
            },
            load: Box::new(move |_: &[f64]| load),
            obstacle: Box::new(move |x: &[f64]| obstacle.at(x[0])),
        })
    }

    fn coefficients<M: Model>(&self) -> Result<Coefficients<'_>> {
        self.coefficients_at::<M>(self.thickness)
    }

    /// The coefficients with the thickness `thickness` in place of the scene's (the
    /// rounding experiment, [`thickness_rounding`]).
    fn coefficients_at<M: Model>(&self, thickness: f64) -> Result<Coefficients<'_>> {
        let mut params: Vec<(&str, f64)> = vec![("α", self.alpha), ("s", self.side)];
        if self.timoshenko {
            params.push(("t", thickness));
        }
        Coefficients::new::<M>(&params, &[("f", &*self.load), ("ψ", &*self.obstacle)])
    }
}

/// Peak memory of a beam solve per element (Timoshenko P2–P2–P0, the largest; nested
/// levels, the LCP, the rounding experiment's repeats and the sampled profiles): 5.2–5.5
/// kB measured from 262144 to 4M elements.
pub const BYTES_PER_ELEMENT: f64 = 5.5e3;

/// The thinnest Timoshenko beam solved: below it the shear penalty `t⁻²` leaves too few
/// digits for the bending energy (measured on timoshenko-a: the L² error against the exact
/// solution grows from 2e-8 at t = 1e-3 to 2e-6 at t = 1e-6, and Newton fails at 1e-7).
const MIN_THICKNESS: f64 = 1e-6;

/// Checks what a model cannot check: obstacle data, feasibility at the clamped ends,
/// the ranges of q, t, α.
fn validate(request: &Request, alpha: f64, thickness: f64) -> Result<()> {
    let scene = &request.scene;
    // measured peaks: 1.36 GB at 262144 Timoshenko elements, 5.5 GB at 1M, 21.3 GB at 4M
    // (a 4M run took the machine's memory); refused before, with the figure
    let bytes = BYTES_PER_ELEMENT * request.elements as f64;
    let limit = crate::membranes::memory_limit_bytes();
    if bytes > limit {
        return Err(Error::Input(format!(
            "--elements {} needs about {:.1} GB of memory ({BYTES_PER_ELEMENT:.0} bytes per element, measured), more than the {:.1} GB this solver allows itself here; use fewer elements (Hermite and P2 beams reach 1e-12 and 1e-8 of w on a few thousand)",
            request.elements,
            bytes / 1e9,
            limit / 1e9
        )));
    }
    if request.elements == 0 || request.elements > 50_000_000 {
        return Err(Error::Input(format!(
            "--elements {} is out of range (1 to 50,000,000)",
            request.elements
        )));
    }
    if request.refinement_steps > MAX_REFINEMENT_STEPS {
        return Err(Error::Input(format!(
            "--refinement {} is out of range (0 to {MAX_REFINEMENT_STEPS}): each round is one more solve, and 2 or 3 already reach rounding for t ≤ 1e-5",
            request.refinement_steps
        )));
    }
    if !request.load.is_finite() || request.load < 0.0 {
        return Err(Error::Input(format!(
            "load q = {} must be finite and ≥ 0 (the scene fixes its direction)",
            request.load
        )));
    }
    if request.load > MAX_LOAD {
        return Err(Error::Input(format!(
            "load q = {:e} is beyond {MAX_LOAD:e}: norms in the solve would overflow double precision",
            request.load
        )));
    }
    if scene.beam == Beam::Timoshenko && !(thickness > 0.0 && thickness.is_finite()) {
        return Err(Error::Input(format!(
            "thickness t = {} must be positive and finite",
            crate::number(thickness)
        )));
    }
    if scene.beam == Beam::Timoshenko && thickness > 1.0 {
        return Err(Error::Input(format!(
            "thickness t = {thickness:e} exceeds the beam's length 1: beam theory describes slender bodies (t well below the length; t = 1e7 made the stiffness numerically singular); a thicker body is a problem of elasticity"
        )));
    }
    if scene.beam == Beam::Timoshenko && thickness < MIN_THICKNESS {
        return Err(Error::Input(format!(
            "thickness t = {thickness:e} is below {MIN_THICKNESS:e} (the beam has length 1): the shear term t⁻²(w′−θ) then swamps the bending term in double precision and the discrete system is numerically singular (at t = 1e-6 rounding already dominates the discretization error); the Euler–Bernoulli model is the limit t → 0 (the scenes bernoulli-a and bernoulli-b)"
        )));
    }
    if request.plain {
        if alpha != 0.0 || request.solver != VariationalSolver::Clarabel {
            return Err(Error::Input(
                "the plain mixed method is α = 0, solved by the QP solver (--solver clarabel)"
                    .into(),
            ));
        }
    } else if !(alpha > 0.0 && alpha.is_finite()) {
        return Err(Error::Input(format!(
            "α = {alpha}: the stabilized method needs 0 < α < 1/C_I; for the beam pairs C_I = 0 (the stabilized residual θ''' or w'''' vanishes on each element), so every finite α > 0 is stable, and α ≈ 1 (Timoshenko) or ≤ 1e-2 (Euler–Bernoulli) is accurate"
        )));
    }
    for i in 0..=64 {
        let x = i as f64 / 64.0;
        if !scene.obstacle.at(x).is_finite() {
            return Err(Error::Input(format!(
                "the obstacle ψ({x}) = {} is not finite",
                scene.obstacle.at(x)
            )));
        }
    }
    for x in [0.0, 1.0] {
        let psi = scene.obstacle.at(x);
        if scene.side * (0.0 - psi) < 0.0 {
            return Err(Error::Input(format!(
                "infeasible: the beam is clamped at x = {x} (w = 0) but the obstacle requires w {} ψ({x}) = {psi}",
                if scene.side > 0.0 { "≥" } else { "≤" }
            )));
        }
    }
    Ok(())
}

/// `ε t⁻² h⁻²` on `elements` elements of the unit beam: the relative size of the rounding
/// of the shear term against the bending term it leaves (near 1 no digit is left).
fn shear_conditioning(thickness: f64, elements: usize) -> f64 {
    f64::EPSILON * ((elements as f64) / thickness).powi(2)
}

/// Most rounds of iterative refinement per linear solve that `--refinement` accepts.
pub const MAX_REFINEMENT_STEPS: usize = 10;

fn run<M: Model>(request: &Request, pair: Pair) -> Result<(Report, Profiles)> {
    let scene = request.scene;
    let setup = Setup::new(request, pair)?;
    let (alpha, thickness, q) = (setup.alpha, setup.thickness, request.load);
    let exact = exact_solution(&scene, q, thickness).map(std::sync::Arc::new);
    let (for_value, for_slope) = (exact.clone(), exact.clone());
    let exact_value = move |x: &[f64]| for_value.as_ref().map_or(f64::NAN, |e| (e.w)(x[0], 0));
    let exact_slope =
        move |x: &[f64]| [for_slope.as_ref().map_or(f64::NAN, |e| (e.w)(x[0], 1)), 0.0];
    // nested iteration over uniform meshes N/2^k ≥ 16 (Newton only)
    let mut sizes = vec![request.elements];
    if let (Some(min), VariationalSolver::SemismoothNewton) = (request.nested_from, request.solver)
    {
        while sizes[0] % 2 == 0 && sizes[0] / 2 >= min.max(1) {
            sizes.insert(0, sizes[0] / 2);
        }
    }
    let meshes = sizes
        .iter()
        .map(|&n| IntervalMesh::uniform(0.0, 1.0, n))
        .collect::<Result<Vec<_>>>()?;
    let options = SolveOptions {
        obstacle: ObstacleOptions {
            solver: request.solver,
            newton: NewtonOptions {
                refinement_steps: request.refinement_steps,
                ..NewtonOptions::default()
            },
            linear_solver: request.linear_solver,
            ..ObstacleOptions::default()
        },
        nested: request.nested_from.is_some(),
        rounding_experiment: true,
    };
    let side = if scene.side > 0.0 {
        ObstacleSide::Below
    } else {
        ObstacleSide::Above
    };
    let mut problem = Problem::<M, IntervalMesh>::new(meshes)
        .data("f", &*setup.load)
        .data("ψ", &*setup.obstacle)
        .side(side)
        .alpha(
            request.alpha.map_or(Alpha::default(), Alpha::Fixed),
            pair.default_alpha(),
        )
        .options(options)
        .memory(
            MemoryModel::per_cell(BYTES_PER_ELEMENT),
            format!("--elements {}", request.elements),
        );
    for field in setup.clamped {
        problem = problem.support(DirichletPart::All, *field, Condition::Clamped);
    }
    if setup.timoshenko {
        problem = problem.param("t", thickness);
    }
    if exact.is_some() {
        problem = problem.exact(Exact {
            value: &exact_value,
            gradient: Some(&exact_slope),
            hessian: None,
            multiplier: None,
        });
    }
    let solved = problem
        .solve()
        .map_err(|e| conditioning_hint(e, request, pair, thickness))?;
    let solution = &solved.solution;
    let runtime = &solved.report;
    let w = solution.view(M::field("w")?);
    let samples = 8 * request.elements.min(512) + 1;
    let x: Vec<f64> = (0..samples)
        .map(|i| i as f64 / (samples - 1) as f64)
        .collect();
    let w_values: Vec<f64> = x.iter().map(|&x| w.at(x, 0).unwrap_or(f64::NAN)).collect();
    let max_deflection = (0..=4 * request.elements)
        .map(|i| {
            w.at(i as f64 / (4 * request.elements) as f64, 0)
                .unwrap_or(0.0)
                .abs()
        })
        .fold(0.0, f64::max);
    let theta = M::field("θ").ok().map(|f| {
        let view = solution.view(f);
        x.iter()
            .map(|&x| view.at(x, 0).unwrap_or(f64::NAN))
            .collect()
    });
    let mut warnings = runtime.warnings.clone();
    let h = 1.0 / request.elements as f64;
    // from a tenth of t on: at h = t the error is already 8 %
    if pair == Pair::TimoshenkoP1Full && (h / thickness).powi(2) / 12.0 > 1e-3 {
        warnings.push(format!(
            "p1-p1-p0-full locks here: its elements (h = {}) are not short against the beam's thickness (t = {}), and its fully integrated shear term t⁻²(w′ − θ) then stiffens w_h by about (h/t)²/12 = {:.0e}; it is the locking pair of the locking study, shown for comparison: use p2-p2-p0 or p1-p1-p0-reduced",
            crate::number(h),
            crate::number(thickness),
            (h / thickness).powi(2) / 12.0
        ));
    }
    let d = &solution.discretization;
    let report = Report {
        scene: scene.name.to_string(),
        pair: pair.name().to_string(),
        solver: runtime.solver.into(),
        load: q,
        thickness: (scene.beam == Beam::Timoshenko).then_some(thickness),
        alpha,
        inverse_constant: runtime.inverse_constant,
        elements: request.elements,
        dofs: d.lcp.n() + d.lcp.m(),
        iterations: runtime.iterations,
        linear_solver: runtime.linear_solver,
        krylov_iterations: runtime.krylov_iterations,
        factorizations: runtime.factorizations,
        levels: runtime.levels.clone(),
        seconds: runtime.seconds,
        rounding_seconds: runtime.rounding_seconds.unwrap_or(0.0),
        energy: runtime.energy.unwrap_or(f64::NAN),
        max_deflection,
        max_penetration: runtime.max_penetration.unwrap_or(0.0),
        max_open_contact_gap: runtime.max_open_contact_gap.unwrap_or(0.0),
        contact_set: solution.contact_set(),
        total_contact_force: runtime.total_contact_force,
        complementarity_residual: runtime.kkt_residual,
        error_l2: runtime.error_l2,
        error_h1: runtime.error_h1,
        multiplier_noise: runtime.multiplier_noise,
        primal_rounding: runtime.primal_rounding,
        thickness_rounding: setup.timoshenko.then(|| runtime.rounding.unwrap_or(0.0)),
        length_rounding: (!setup.timoshenko).then(|| runtime.rounding.unwrap_or(0.0)),
        warnings,
    };
    let mesh = &d.mesh;
    let profiles = Profiles {
        psi: x.iter().map(|&x| scene.obstacle.at(x)).collect(),
        w: w_values,
        theta,
        cell_x: (0..mesh.cell_count())
            .map(|c| 0.5 * (mesh.cell(c)[0] + mesh.cell(c)[1]))
            .collect(),
        lambda: solution.multiplier().to_vec(),
        x,
    };
    Ok((report, profiles))
}

/// A solver's failure where the beam's conditioning is the likely cause: the Hermite
/// stiffness's `h⁻⁴` on many elements, or the shear term's `t⁻²h⁻²` of a thin
/// Timoshenko beam.
fn conditioning_hint(e: Error, request: &Request, pair: Pair, thickness: f64) -> Error {
    let alpha = request.alpha.unwrap_or(pair.default_alpha());
    match e {
        Error::NotConverged { .. } | Error::LinearSolve(_)
            if pair == Pair::BernoulliHermite && request.elements > 2000 =>
        {
            Error::Input(format!(
                "{e}; at {} Hermite elements the bending stiffness conditions the system like h⁻⁴ (N⁴ = {:.0e}), and where the beam is in contact the multiplier's stabilization C = αh⁵ = {:.0e} lies below the rounding of the gap G − BU: use fewer elements (the error against the exact solutions is smallest near 1000; Hermite cubics reach 1e-12 at 256), or for contact a larger α",
                request.elements,
                (request.elements as f64).powi(4),
                alpha * (1.0 / request.elements as f64).powi(5)
            ))
        }
        Error::NotConverged { .. } | Error::LinearSolve(_)
            if pair.beam() == Beam::Timoshenko
                && shear_conditioning(thickness, request.elements) > 1e-3 =>
        {
            Error::Input(format!(
                "{e}; at t = {} on {} elements the shear term t⁻²(w′ − θ) conditions the system like t⁻²h⁻², and its rounding ε t⁻²h⁻² ≈ {:.0e} is not small against the bending term the answer lives in: use fewer elements, a larger t, or the Euler–Bernoulli limit (bernoulli-a, bernoulli-b)",
                crate::number(thickness),
                request.elements,
                shear_conditioning(thickness, request.elements)
            ))
        }
        e => e,
    }
}
