//! Solving a beam scene with a chosen element pair and solver, and what a solve reports.

use crate::models::membrane_scenes::MAX_LOAD;
use crate::models::scenes::{exact_solution, Beam, Scene};
use crate::models::{bernoulli, timoshenko_p1_full, timoshenko_p1_reduced, timoshenko_p2};
use fem_runtime::lcp::NewtonOptions;
use fem_runtime::obstacle::hierarchy::LinearSolver;
use fem_runtime::obstacle::{
    solve_obstacle, system_forms, Discretization, ObstacleOptions, VariationalSolver,
};
use fem_runtime::stabilization;
use fem_runtime::{Coefficients, DataFn, Error, IntervalMesh, Model, Result};
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
    // (a tester's 4M run took the machine's memory); refused before, with the figure
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

/// The rounding experiment of a Timoshenko solve: the larger change of w_h (as
/// `solve_at(t')` measures it against the solution at `thickness`) when the thickness
/// moves by `2⁻⁴⁰` and `−2⁻³⁹` of itself. That changes the rounding of every entry of
/// the shear term `t⁻²(w′ − θ)` and, to first order, nothing else (`∂w/∂t ~ t` moves w
/// by ~1e-12 t² relative): the change is the rounding of the solve. Two moves, since
/// one can land on a rounding close to the first. Measured on timoshenko-a at q = 1
/// against its exact solution (t = 1e-2 … 1e-5, 256 … 16384 elements), the larger change
/// is within a factor 3 of the true error wherever rounding dominates it, while a
/// first-order estimate from random ±ε perturbations of the matrix entries came out
/// 1000× too small and the norm-wise `ε κ(A)` 100× too large.
///
/// # Errors
/// Those of `solve_at`.
fn thickness_rounding(solve_at: impl Fn(f64) -> Result<f64>, thickness: f64) -> Result<f64> {
    let up = solve_at(thickness * (1.0 + 2f64.powi(-40)))?;
    let down = solve_at(thickness * (1.0 - 2f64.powi(-39)))?;
    Ok(up.max(down))
}

/// The Euler–Bernoulli beam's rounding experiment: solves it on `[0, L]` for L = 1 moved
/// in its last bits both ways (`1 + 2⁻⁴⁰`, `1 − 2⁻³⁹`) and returns the larger change
/// `solve_on` reports. The exact solution moves by O(2⁻⁴⁰), far below what is reported;
/// every stiffness entry moves in its last bits, so the rounding of the solve, ~ε h⁻⁴ of
/// w, is drawn anew. Measured on bernoulli-a (relative error of max w_h against q/384
/// from the rounding alone): 1e-7 at 1024 elements, 8.5e-6 at 4096, 1.3e-3 at 16384,
/// 2–7 % at 65536 with a KKT residual of 8e-17 and no warning before this check.
fn length_rounding(solve_on: impl Fn(f64) -> Result<f64>) -> Result<f64> {
    let up = solve_on(1.0 + 2f64.powi(-40))?;
    let down = solve_on(1.0 - 2f64.powi(-39))?;
    Ok(up.max(down))
}

/// `ε t⁻² h⁻²` on `elements` elements of the unit beam: the relative size of the rounding
/// of the shear term against the bending term it leaves (near 1 no digit is left).
fn shear_conditioning(thickness: f64, elements: usize) -> f64 {
    f64::EPSILON * ((elements as f64) / thickness).powi(2)
}

/// [`Report::thickness_rounding`] above which a solve is refused: w_h has no correct
/// digit (a tester's timoshenko-a at t = 1e-5 on 4096 elements was 18 % off, with a KKT
/// residual of 5e-17 and no warning).
const MAX_THICKNESS_ROUNDING: f64 = 0.1;

/// [`Report::thickness_rounding`] above which a solve warns: w_h keeps fewer than four
/// digits.
const THICKNESS_ROUNDING_WARNING: f64 = 1e-4;

/// Largest estimated relative rounding noise of λ_h accepted in a result (with a warning
/// above 1e-6): beyond it λ_h has no correct digit. The estimate is a bound, loose by up
/// to 10× (timoshenko-a, q = 100, 32768 elements: 0.1 with ∫λ_h still right to 4 digits);
/// on bernoulli-flat at q = 100 it is 1.8 at 20000 elements, where ∫λ_h is off by 6×.
const MAX_MULTIPLIER_NOISE: f64 = 1.0;

/// Largest rounding of w through the contact rows, relative to its size, accepted in a
/// result ([`Report::primal_rounding`]).
const MAX_PRIMAL_ROUNDING: f64 = 1e-3;

/// Most rounds of iterative refinement per linear solve that `--refinement` accepts.
pub const MAX_REFINEMENT_STEPS: usize = 10;

fn run<M: Model>(request: &Request, pair: Pair) -> Result<(Report, Profiles)> {
    let scene = request.scene;
    let setup = Setup::new(request, pair)?;
    let (alpha, thickness, q) = (setup.alpha, setup.thickness, request.load);
    let coefficients = setup.coefficients::<M>()?;
    let clamped = setup.clamped;
    let mesh = IntervalMesh::uniform(0.0, 1.0, request.elements)?;
    let inverse_constant = stabilization::inverse_constant::<M, _>(&mesh, &coefficients.params)?;
    let options = ObstacleOptions {
        solver: request.solver,
        nested_from: request.nested_from,
        newton: NewtonOptions {
            refinement_steps: request.refinement_steps,
            ..NewtonOptions::default()
        },
        linear_solver: request.linear_solver,
        ..ObstacleOptions::default()
    };
    let solution = solve_obstacle::<M>(&mesh, &coefficients, clamped, options).map_err(|e| {
        match e {
            // the stiffness's h⁻⁴ first: a tester's bernoulli-flat without contact at 100000
            // elements was told of α·C_I and a free rigid motion (C_I = 0 for Hermite)
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
                if setup.timoshenko && shear_conditioning(thickness, request.elements) > 1e-3 =>
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
    })?;
    if solution.multiplier_noise > MAX_MULTIPLIER_NOISE {
        return Err(Error::Input(format!(
            "at {} elements λ_h is rounding noise (estimated {:.0e} relative; ∫λ_h would be off by as much, and w follows it): the multiplier's stabilization C = αh⁵ lies below the rounding of the gap G − BU; use fewer elements or a larger α",
            request.elements, solution.multiplier_noise
        )));
    }
    let w_field = M::field("w")?;
    let energy = solution.energy::<M>(&coefficients)?;
    let w = solution.view(w_field);
    let exact = exact_solution(&scene, q, thickness);
    let (error_l2, error_h1) = match &exact {
        Some(e) => (
            Some(w.error(0, &|x| (e.w)(x, 0), 6)),
            Some(w.error(1, &|x| (e.w)(x, 1), 6)),
        ),
        None => (None, None),
    };
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
    // the weak (cell-wise) constraint lets w cross ψ inside cells: s(ψ − w)₊ at 4 points per cell
    let max_penetration = (0..=4 * request.elements)
        .map(|i| {
            let x = i as f64 / (4 * request.elements) as f64;
            let gap = scene.side * (w.at(x, 0).unwrap_or(f64::NAN) - scene.obstacle.at(x));
            (-gap).max(0.0)
        })
        .fold(0.0, f64::max);
    let theta = M::field("θ").ok().map(|f| {
        let view = solution.view(f);
        x.iter()
            .map(|&x| view.at(x, 0).unwrap_or(f64::NAN))
            .collect()
    });
    let psi_size = x
        .iter()
        .map(|&x| scene.obstacle.at(x).abs())
        .fold(0.0, f64::max);
    // 1e-6 of the beam's length: so that a beam at rest on ψ = 0 is judged against something
    let primal_rounding = solution.primal_rounding() / max_deflection.max(psi_size).max(1e-6);
    if primal_rounding > MAX_PRIMAL_ROUNDING {
        // the rows' large terms are the load's, or αC Λ's when the user's α is far above
        // the default (a tester's α = 1e30 at q = 100 was told the load was at fault)
        if alpha > LARGE_ALPHA * pair.default_alpha() {
            return Err(Error::Input(format!(
                "the load q = {q:e} with α = {alpha:e} ({} times the pair's default {:e}) makes the terms of the constraint rows so large that their rounding moves w by {primal_rounding:.0e} of its own size; the answer would be rounding (its KKT residual cannot show it): lower --alpha first, then the load",
                crate::number(alpha / pair.default_alpha()),
                pair.default_alpha()
            )));
        }
        return Err(Error::Input(format!(
            "the load q = {q:e} dwarfs the obstacle: in contact the constraint rows subtract terms of the load's size, and their rounding moves w by {primal_rounding:.0e} of its own size; the answer would be rounding (its KKT residual cannot show it)"
        )));
    }
    let size = max_deflection.max(psi_size).max(1e-6);
    let rounding_clock = std::time::Instant::now();
    let thickness_rounding = if setup.timoshenko {
        let moved = thickness_rounding(
            |t| {
                let coefficients = setup.coefficients_at::<M>(t)?;
                let other = solve_obstacle::<M>(&mesh, &coefficients, clamped, options)?;
                let view = other.view(w_field);
                Ok((0..=4 * request.elements)
                    .map(|i| {
                        let x = i as f64 / (4 * request.elements) as f64;
                        (view.at(x, 0).unwrap_or(f64::NAN) - w.at(x, 0).unwrap_or(f64::NAN)).abs()
                    })
                    .fold(0.0, f64::max))
            },
            thickness,
        )
        // a perturbed solve that fails has no digit to lose either
        .unwrap_or(f64::INFINITY);
        // relative to w_h itself: ψ can be far larger than a stiff beam's deflection
        Some(if moved == 0.0 {
            0.0
        } else {
            moved / max_deflection
        })
    } else {
        None
    };
    let length_rounding = if setup.timoshenko {
        None
    } else {
        let force = solution.total_contact_force();
        let moved = length_rounding(|length| {
            let mesh = IntervalMesh::uniform(0.0, length, request.elements)?;
            let other = solve_obstacle::<M>(&mesh, &coefficients, clamped, options)?;
            let view = other.view(w_field);
            let w_moved = (0..=4 * request.elements)
                .map(|i| {
                    let x = i as f64 / (4 * request.elements) as f64;
                    (view.at(x * length, 0).unwrap_or(f64::NAN) - w.at(x, 0).unwrap_or(f64::NAN))
                        .abs()
                })
                .fold(0.0, f64::max);
            // ∫λ_h against the load it carries (a tester's ∫λ_h was 6× the exact at
            // 65536 elements, with a multiplier-noise estimate of 2e-2)
            let force_moved = (other.total_contact_force() - force).abs();
            let load = q.abs().max(f64::MIN_POSITIVE);
            // against 1e-6 of the length at least: a beam pressed flat onto ψ = 0 has
            // w ≡ 0, and its 1e-17 of noise would be judged against itself
            Ok((w_moved / max_deflection.max(1e-6)).max(force_moved / load))
        })
        .unwrap_or(f64::INFINITY);
        Some(moved)
    };
    let rounding_seconds = rounding_clock.elapsed().as_secs_f64();
    if let Some(r) = length_rounding.filter(|&r| r > MAX_THICKNESS_ROUNDING || r.is_nan()) {
        let moved = if r.is_finite() {
            format!("moves w_h or ∫λ_h by {r:.0e} of their size")
        } else {
            "makes the solve fail".to_string()
        };
        return Err(Error::Input(format!(
            "on {} elements w_h is rounding: moving the beam's length in its last bits {moved}; the bending stiffness conditions the system like h⁻⁴, which leaves no digit here; use fewer elements (Hermite cubics reach 1e-12 at 256)",
            request.elements
        )));
    }
    if let Some(r) = thickness_rounding.filter(|&r| r > MAX_THICKNESS_ROUNDING || r.is_nan()) {
        let moved = if r.is_finite() {
            format!("moves w_h by {r:.0e} of its size")
        } else {
            "makes the solve fail".to_string()
        };
        return Err(Error::Input(format!(
            "at t = {} on {} elements w_h is rounding: moving t in its last bits {moved}; the shear term t⁻²(w′ − θ) conditions the system like t⁻²h⁻², which leaves the bending part no digit; use fewer elements, a larger t, or the Euler–Bernoulli limit (bernoulli-a, bernoulli-b)",
            crate::number(thickness),
            request.elements
        )));
    }
    let mut warnings = Vec::new();
    let h = 1.0 / request.elements as f64;
    // from a tenth of t on: at h = t the error is already 8 % (the re-test)
    if pair == Pair::TimoshenkoP1Full && (h / thickness).powi(2) / 12.0 > 1e-3 {
        // the locking study's collapsing pair: a tester's t = 1e-5 got max|w| 2e-7
        // against the true 2.6e-3, without a word
        warnings.push(format!(
            "p1-p1-p0-full locks here: its elements (h = {}) are not short against the beam's thickness (t = {}), and its fully integrated shear term t⁻²(w′ − θ) then stiffens w_h by about (h/t)²/12 = {:.0e}; it is the locking pair of the locking study, shown for comparison: use p2-p2-p0 or p1-p1-p0-reduced",
            crate::number(h),
            crate::number(thickness),
            (h / thickness).powi(2) / 12.0
        ));
    }
    if let Some(r) = length_rounding.filter(|&r| r > THICKNESS_ROUNDING_WARNING) {
        warnings.push(format!(
            "w_h is rounding-limited to about {r:.0e} of its size on {} elements (moving the beam's length in its last bits moves w_h or ∫λ_h that much; the bending stiffness conditions the system like h⁻⁴): fewer elements give more correct digits here (Hermite cubics reach 1e-12 at 256)",
            request.elements
        ));
    }
    if let Some(r) = thickness_rounding.filter(|&r| r > THICKNESS_ROUNDING_WARNING) {
        warnings.push(format!(
            "w_h is rounding-limited to about {r:.0e} of its size at t = {} on {} elements (moving t in its last bits moves w_h that much; the shear term t⁻²(w′ − θ) conditions the system like t⁻²h⁻²): fewer elements give more correct digits here, or use the Euler–Bernoulli limit",
            crate::number(thickness),
            request.elements
        ));
    }
    if request.linear_solver == LinearSolver::Multigrid && solution.iterative_steps == 0 {
        warnings.push(crate::membranes::multigrid_unused(
            request.solver,
            "a cold start, and an element count that is odd or below twice the coarsest level's (16 by default)",
        ));
    }
    // as for membranes: relative to ψ's size (its range, or |ψ| for a flat one)
    let psi_values: Vec<f64> = x.iter().map(|&x| scene.obstacle.at(x)).collect();
    let psi_range = psi_values.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
        - psi_values.iter().cloned().fold(f64::INFINITY, f64::min);
    let psi_scale = if psi_range > 0.0 { psi_range } else { psi_size };
    if psi_scale > 0.0 && max_penetration > 1e-2 * psi_scale {
        warnings.push(format!(
            "w_h crosses ψ by up to {max_penetration:.2e}, {:.1}% of ψ's size: the cell-wise constraint does not resolve the contact at this mesh size and load (refine, or lower the load)",
            100.0 * max_penetration / psi_scale
        ));
    }
    // as for membranes and plates: λ_h pushing on cells that stay clear of ψ is a
    // contact set made by α h^k (bernoulli-flat at α = 1e10: w_h 5.6e-5, 0.05 below ψ,
    // and all of [0, 1] "in contact"; timoshenko-a on one element)
    let max_open_contact_gap = open_contact_gap(&mesh, solution.multiplier(), |x| {
        scene.side * (w.at(x, 0).unwrap_or(f64::NAN) - scene.obstacle.at(x))
    });
    if max_open_contact_gap > crate::membranes::OPEN_GAP_WARNING * size
        && max_open_contact_gap > solution.primal_rounding()
    {
        let large = alpha > 10.0 * pair.default_alpha();
        warnings.push(format!(
            "λ_h pushes on cells where w_h stays up to {max_open_contact_gap:.2e} clear of ψ ({:.1} % of the beam's size max(|w_h|, |ψ|) = {size:.2e}): the stabilized constraint on contact cells lets α h^k (…) open that gap (α = {alpha:e}{}), so this contact set is not real; {}",
            100.0 * max_open_contact_gap / size,
            if large { format!(", {} times the pair's default", crate::number(alpha / pair.default_alpha())) } else { String::new() },
            if large { "lower --alpha" } else { "use more elements or a smaller α" }
        ));
    }
    if alpha > LARGE_ALPHA * pair.default_alpha() {
        warnings.push(format!(
            "α = {alpha:e} is {} times the pair's default {:e}, more than {LARGE_ALPHA:e}: the stabilization's term moves the contact set and w_h with α (bernoulli-flat at q = 100 on 256 elements: L² error 1.9e-7 at the default, 4.1e-6 at α = 100, 1.1e-4 at α = 1e4)",
            crate::number(alpha / pair.default_alpha()),
            pair.default_alpha()
        ));
    }
    if solution.multiplier_noise > 1e-6 {
        warnings.push(format!(
            "λ_h may carry rounding noise of up to {:.0e} relative: C = αh⁵ approaches the rounding of G − BU at this mesh size, and the saddle-point recovery of λ is no guarantee at this conditioning; w is affected too once the noise passes ~1e-3 (a larger α or a coarser mesh avoids it)",
            solution.multiplier_noise
        ));
    }
    if primal_rounding > 1e-8 {
        warnings.push(format!(
            "w may be off by {primal_rounding:.0e} of its size through the rounding of the contact rows (the load dwarfs the obstacle)"
        ));
    }
    let d = &solution.discretization;
    let report = Report {
        scene: scene.name.to_string(),
        pair: pair.name().to_string(),
        solver: match request.solver {
            VariationalSolver::SemismoothNewton => "pdas".into(),
            VariationalSolver::Clarabel => "clarabel".into(),
        },
        load: q,
        thickness: (scene.beam == Beam::Timoshenko).then_some(thickness),
        alpha,
        inverse_constant,
        elements: request.elements,
        dofs: d.lcp.n() + d.lcp.m(),
        iterations: solution.iterations,
        linear_solver: solution.linear_solver_name(),
        krylov_iterations: solution.krylov_iterations,
        factorizations: solution.factorizations,
        levels: solution.levels.iter().map(|&(c, i)| [c, i]).collect(),
        seconds: solution.seconds,
        rounding_seconds,
        energy,
        max_deflection,
        max_penetration,
        max_open_contact_gap,
        contact_set: solution.contact_set(),
        total_contact_force: solution.total_contact_force(),
        complementarity_residual: solution.kkt_residual,
        error_l2,
        error_h1,
        multiplier_noise: solution.multiplier_noise,
        primal_rounding,
        thickness_rounding,
        length_rounding,
        warnings,
    };
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

/// An α above this multiple of the pair's default is warned about: the error grows with
/// α (bernoulli-flat, q = 100, 256 elements: 1.9e-7 at the default 1e-2, 2.3e-5 at
/// 1e3, 1.1e-4 at 1e4), and the contact set widens without an open gap to show it.
const LARGE_ALPHA: f64 = 1e3;

/// The largest open gap under a pushing multiplier on an interval mesh: over the cells
/// whose P0 multiplier `lambda` pushes (above 1e-6 of its largest), the smallest
/// `clearance(x)` at the cell's ends, quarter points and midpoint; the largest of these,
/// 0 where every such cell touches ψ (or none pushes, or `lambda` is not one value per
/// cell). NaN clearances are skipped: the penetration check reports those.
fn open_contact_gap(mesh: &IntervalMesh, lambda: &[f64], clearance: impl Fn(f64) -> f64) -> f64 {
    if lambda.len() != mesh.cell_count() {
        return 0.0;
    }
    let largest = lambda.iter().fold(0.0f64, |m, l| m.max(*l));
    if largest <= 0.0 {
        return 0.0;
    }
    (0..mesh.cell_count())
        .filter(|&c| lambda[c] > 1e-6 * largest)
        .map(|c| {
            let [a, b] = mesh.cell(c);
            (0..=4)
                .map(|i| clearance(a + (b - a) * i as f64 / 4.0))
                .filter(|g| !g.is_nan())
                .fold(f64::INFINITY, f64::min)
        })
        .filter(|g| g.is_finite())
        .fold(0.0, f64::max)
}
