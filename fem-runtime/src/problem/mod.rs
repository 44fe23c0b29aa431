//! One obstacle problem, one solve, one report, for any model the macro accepts.
//!
//! A [`Problem`] holds the model (its type), the meshes of its nested levels, the
//! parameters and data by typed handle, the supports by boundary part and field, the
//! markers of the model's boundary parts (where a boundary multiplier lives), the
//! obstacle side and the α policy. [`Problem::solve`] derives C_I and α from the
//! model's declared stabilization, fills α and the side, checks what can be checked
//! before any work (memory, data, feasibility, the stabilization's size against
//! rounding), solves the levels by nested iteration and returns the solution with one
//! [`Report`]: the fields every model has and the guards every solve needs (penetration
//! and open gap, rounding through the contact rows, multiplier noise, the KKT
//! certificate, the rounding experiment, warnings).
//!
//! ```
//! use fem_runtime::problem::{Condition, ObstacleSide, Problem, SolveOptions};
//! use fem_runtime::{DirichletPart, IntervalMesh};
//! fem_runtime::model! {
//!     /// A string over an obstacle, P1–P0.
//!     pub mod string on interval {
//!         unknowns: u: P1, λ: P0 >= 0;
//!         tests: v, μ;
//!         params: α;
//!         data: f, ψ;
//!         forms: "
//!             a(u;v)       = ∫ u'v'
//!             S(u,λ;v,μ)   = Σ_T h_T² (−u'' − λ, −v'' − μ)_T
//!             ℓ(v)         = ∫ f v
//!             ℓ_S(v,μ)     = Σ_T h_T² (f, −v'' − μ)_T
//!             B_h(u,λ;v,μ) = a(u;v) − ∫ v λ − ∫ u μ − α S(u,λ;v,μ)
//!             L_h(v,μ)     = ℓ(v) − ∫ ψ μ − α ℓ_S(v,μ)
//!         ";
//!         system: B_h, L_h;
//!         energy: a, ℓ;
//!         stabilization: α S against a;
//!         obstacle: u >= ψ;
//!     }
//! }
//! // pressed onto ψ = 0 everywhere: u = 0, λ = 1
//! let (load, obstacle) = (|_: &[f64]| -1.0, |_: &[f64]| 0.0);
//! let mesh = IntervalMesh::uniform(0.0, 1.0, 16).unwrap();
//! let solved = Problem::<string::Model, _>::new(vec![mesh])
//!     .data(string::data::f, &load)
//!     .data(string::data::ψ, &obstacle)
//!     .support(DirichletPart::All, string::fields::u, Condition::Zero)
//!     .side(ObstacleSide::Below)
//!     .solve()
//!     .unwrap();
//! assert!((solved.report.total_contact_force - 1.0).abs() < 1e-10);
//! ```

pub mod domain;
pub mod memory;
pub mod nodal;
pub mod report;

pub use domain::{error_rule_degree, Domain, Errors, Penetration};
pub use memory::MemoryModel;
pub use report::{MeshQualityReport, Report};

use crate::assembly::boundary::{Constraints, DirichletPart};
use crate::error::{Error, Result};
use crate::lcp::external::{External, Purpose};
use crate::lcp::Lcp;
use crate::mesh::Mesh;
use crate::model::{
    Coefficients, DataFn, IntoDataIndex, IntoFieldIndex, IntoParamIndex, IntoPartIndex, Model,
};
use crate::obstacle::{
    multiplier_field, solve_nested_from, Discretization, FirstStart, LevelStart, NearNullSpace,
    ObstacleOptions, ObstacleSolution, VariationalSolver,
};
use crate::stabilization::Alpha;
use report::{
    answer_level, load_rounding, value_rounding, MAX_MULTIPLIER_NOISE, MAX_PRIMAL_ROUNDING,
    MAX_ROUNDING, MULTIPLIER_NOISE_WARNING, OPEN_GAP_WARNING, PENETRATION_WARNING,
    PRIMAL_ROUNDING_WARNING, ROUNDING_WARNING,
};
use std::marker::PhantomData;
use std::time::Instant;

/// What a support holds on its boundary part.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Condition {
    /// The model's boundary data: `field = g` for its `boundary: field = g` (for a plate
    /// field, Argyris or Morley, the simple support with g = 0).
    Data,
    /// `field = 0` and what that implies along the part (for a plate field the simple
    /// support: value and tangential derivatives).
    Zero,
    /// `field = 0` and its normal derivative too where the element has one: clamped
    /// (Hermite ends, Argyris and Morley edges); `Zero` for Lagrange fields.
    Clamped,
    /// The tangential component of the vector field whose x component is `field` (its
    /// y component the field of the same name ending in `_y`): `θ·t = 0`, the hard
    /// simple support's condition on the rotations.
    Tangential,
    /// The component of the vector field whose x component is `field` along the unit
    /// vector `n`: `u·n = 0`, a roller.
    Along([f64; 2]),
}

/// A support: `condition` on `field` along `part` of the boundary (intervals: marker 1
/// is the left end, 2 the right one).
#[derive(Clone, Debug, PartialEq)]
pub struct Support {
    /// Where it holds.
    pub part: DirichletPart,
    /// The field (index in `M::FIELDS`).
    pub field: usize,
    /// What it holds.
    pub condition: Condition,
}

/// Which side of the structure the obstacle is on: `s·w ≥ s·ψ` with `s = +1` below,
/// `s = −1` above (docs/mathematics.md §1).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ObstacleSide {
    /// `w ≥ ψ`.
    #[default]
    Below,
    /// `w ≤ ψ`.
    Above,
}

impl ObstacleSide {
    /// `s`: +1 below, −1 above.
    pub fn sign(self) -> f64 {
        match self {
            ObstacleSide::Below => 1.0,
            ObstacleSide::Above => -1.0,
        }
    }
}

/// A gradient of the point: `[∂_x, ∂_y]` (on intervals `[u', 0]`).
pub type GradientFn = dyn Fn(&[f64]) -> [f64; 2] + Sync;

/// A Hessian of the point: `[[∂_xx, ∂_xy], [∂_yx, ∂_yy]]` (on intervals
/// `[[u'', 0], [0, 0]]`).
pub type HessianFn = dyn Fn(&[f64]) -> [[f64; 2]; 2] + Sync;

/// An exact solution to measure errors against: the constrained field's values (the
/// model's `obstacle:` role), its gradient, Hessian and the multiplier, where known.
#[derive(Clone, Copy)]
pub struct Exact<'a> {
    /// `u(x)`.
    pub value: &'a DataFn,
    /// `∇u(x)`.
    pub gradient: Option<&'a GradientFn>,
    /// `∇²u(x)`, for the broken H² seminorm of the error (plates, beams).
    pub hessian: Option<&'a HessianFn>,
    /// `λ(x)`.
    pub multiplier: Option<&'a DataFn>,
}

/// How [`Problem::solve`] solves.
#[derive(Clone, Copy, Debug)]
pub struct SolveOptions {
    /// The complementarity solver and its options.
    pub obstacle: ObstacleOptions,
    /// Nested iteration over every mesh given (`false`: the finest alone, from the
    /// problem's start or from zero). The QP solver always takes the finest alone.
    pub nested: bool,
    /// Run the rounding experiment ([`Report::rounding`]): two more solves on the mesh
    /// scaled in its last bits.
    pub rounding_experiment: bool,
}

impl Default for SolveOptions {
    fn default() -> Self {
        Self {
            obstacle: ObstacleOptions::default(),
            nested: true,
            rounding_experiment: false,
        }
    }
}

/// A solved problem: the discrete solution and its report.
pub struct Solved<M, G> {
    /// The solution on the finest mesh.
    pub solution: ObstacleSolution<G>,
    /// What the solve reports.
    pub report: Report,
    /// Every parameter's value as solved with (α and s filled in), in declaration order.
    pub params: Vec<f64>,
    /// Where a level of [`Problem::solve_refining`] failed from the previous level's
    /// solution and was solved again from the problem's start: that failure.
    pub fell_back: Option<String>,
    /// The a-posteriori estimate, for a model that declares an estimator.
    pub estimate: Option<crate::adaptivity::Estimate>,
    model: PhantomData<M>,
}

impl<M: Model, G> Solved<M, G> {
    /// The coefficients of a field (by handle or name).
    ///
    /// # Errors
    /// A field the model does not have.
    pub fn field(&self, field: impl IntoFieldIndex<M>) -> Result<&[f64]> {
        Ok(self.solution.field(M::field(field)?))
    }

    /// The finest mesh.
    pub fn mesh(&self) -> &G {
        &self.solution.discretization.mesh
    }
}

/// An obstacle problem of model `M` on meshes of kind `G` (see the module's docs).
pub struct Problem<'a, M: Model, G: Domain> {
    meshes: Vec<G>,
    params: Vec<Option<f64>>,
    data: Vec<Option<&'a DataFn>>,
    supports: Vec<Support>,
    parts: Vec<Option<Vec<u32>>>,
    side: ObstacleSide,
    alpha: Alpha,
    alpha_when_zero: f64,
    options: SolveOptions,
    start: Option<&'a FirstStart<'a, G>>,
    near_null_space: Option<&'a NearNullSpace<'a, G>>,
    exact: Option<Exact<'a>>,
    nodal: Option<&'a DataFn>,
    unconstrained: bool,
    memory: MemoryModel,
    size: Option<String>,
    invalid: Option<Error>,
    model: PhantomData<M>,
}

/// α where `C_I = 0` and nothing else is said: the stabilization is then `α Σ h^p (λ,
/// μ)`, stable for every α > 0 and limited by accuracy only (membranes and plates: 0.1).
pub const ALPHA_WHEN_CI_VANISHES: f64 = 0.1;

/// Below this share of the answer's size the ranges of ψ and u_h count as flat, and a
/// crossing of ψ is judged against the size instead.
const FLAT_SHARE: f64 = 1e-3;

/// The largest ratio of the estimate to `‖u_h‖_a` an adaptive solve goes on from: an
/// estimate a million times the solution's norm means the norm is rounding (a solution
/// held at zero), not a coarse mesh.
const VANISHING_SOLUTION: f64 = 1e6;

/// `α` times the stabilization's constant on a regular cell below which the
/// stabilization is lost in rounding: λ_h's rounding noise grows like `ε / (α C_I)` (a
/// needle mesh measured 2e-4 at 4e-12 and 2 at 4e-16).
pub const SMALLEST_RELATIVE_STABILIZATION: f64 = 1e-13;

/// `α·max C_I,E` below which a multiplier on a boundary part is refused: semismooth
/// Newton stalls there (contact on Hertz: 200 iterations at 3e-9, still failing up to
/// 3e-4), and the pressure oscillates like the plain method's; α = 0 is the plain method.
pub const MIN_BOUNDARY_ALPHA_TIMES_C_I: f64 = 1e-3;

impl<'a, M: Model, G: Domain> Problem<'a, M, G> {
    /// A problem on `meshes`, the levels of nested iteration coarsest first (the last is
    /// solved): no data, no support, the obstacle below, `α = ½/C_I` (or
    /// [`ALPHA_WHEN_CI_VANISHES`] where C_I = 0), nested semismooth Newton.
    pub fn new(meshes: Vec<G>) -> Self {
        Self {
            meshes,
            params: vec![None; M::PARAMS.len()],
            data: vec![None; M::DATA.len()],
            supports: Vec::new(),
            parts: vec![None; M::FACET_PARTS.len()],
            side: ObstacleSide::Below,
            alpha: Alpha::default(),
            alpha_when_zero: ALPHA_WHEN_CI_VANISHES,
            options: SolveOptions::default(),
            start: None,
            near_null_space: None,
            exact: None,
            nodal: None,
            unconstrained: false,
            memory: MemoryModel::of_model::<M>(),
            size: None,
            invalid: None,
            model: PhantomData,
        }
    }

    /// Keeps the first invalid input, which [`Problem::solve`] reports.
    fn refuse(mut self, error: Error) -> Self {
        self.invalid.get_or_insert(error);
        self
    }

    /// Sets a parameter (by handle, or by name for readers of scene files). The roles α
    /// and s are the solve's to set ([`Problem::alpha`], [`Problem::side`]).
    pub fn param(mut self, param: impl IntoParamIndex<M>, value: f64) -> Self {
        match M::param(param) {
            Ok(p) if M::STABILIZATION.and_then(|s| s.alpha) == Some(p) => {
                let name = M::PARAMS[p];
                self.refuse(Error::Input(format!(
                    "`{name}` is the stabilization parameter of `{}`: give it through the α policy (Problem::alpha), not as a value",
                    M::NAME
                )))
            }
            Ok(p) if M::SIDE == Some(p) => {
                let name = M::PARAMS[p];
                self.refuse(Error::Input(format!(
                    "`{name}` is the obstacle side of `{}`: give it through Problem::side",
                    M::NAME
                )))
            }
            Ok(p) => {
                self.params[p] = Some(value);
                self
            }
            Err(e) => self.refuse(e),
        }
    }

    /// Sets a data function (by handle, or by name).
    pub fn data(mut self, data: impl IntoDataIndex<M>, function: &'a DataFn) -> Self {
        match M::data_function(data) {
            Ok(d) => {
                self.data[d] = Some(function);
                self
            }
            Err(e) => self.refuse(e),
        }
    }

    /// Holds `field` on `part` of the boundary with `condition`.
    pub fn support(
        mut self,
        part: DirichletPart,
        field: impl IntoFieldIndex<M>,
        condition: Condition,
    ) -> Self {
        match M::field(field) {
            Ok(field) => {
                self.supports.push(Support {
                    part,
                    field,
                    condition,
                });
                self
            }
            Err(e) => self.refuse(e),
        }
    }

    /// The model's boundary data (`boundary:`) on every field that has them, on `part`.
    pub fn boundary_data(mut self, part: DirichletPart) -> Self {
        for &(field, _) in M::DIRICHLET {
            self.supports.push(Support {
                part: part.clone(),
                field,
                condition: Condition::Data,
            });
        }
        self
    }

    /// The boundary markers of one of the model's boundary parts (`facets:`).
    pub fn part(mut self, part: impl IntoPartIndex<M>, markers: Vec<u32>) -> Self {
        match M::facet_part(part) {
            Ok(p) => {
                self.parts[p] = Some(markers);
                self
            }
            Err(e) => self.refuse(e),
        }
    }

    /// The obstacle's side (needs the model's `side:` role for `Above`).
    pub fn side(mut self, side: ObstacleSide) -> Self {
        self.side = side;
        if side == ObstacleSide::Above && M::SIDE.is_none() {
            // a model without the side parameter would solve the obstacle below
            return self.refuse(Error::Input(format!(
                "model `{}` has no obstacle side parameter (`side:`): its obstacle cannot be posed above",
                M::NAME
            )));
        }
        self
    }

    /// The α policy, and the α where `C_I = 0`.
    pub fn alpha(mut self, alpha: Alpha, when_inverse_constant_vanishes: f64) -> Self {
        self.alpha = alpha;
        self.alpha_when_zero = when_inverse_constant_vanishes;
        self
    }

    /// How to solve.
    pub fn options(mut self, options: SolveOptions) -> Self {
        self.options = options;
        self
    }

    /// The start of the coarsest level (it may also refuse the problem); it reads a
    /// level's LCP as [`FirstStart`] says, the level possibly one process's part.
    pub fn start(mut self, start: &'a FirstStart<'a, G>) -> Self {
        self.start = Some(start);
        self
    }

    /// The near null space of the levels' `A` without supports (an elastic body's rigid
    /// motions), handed to an external solver with each level's LCP
    /// ([`crate::lcp::Lcp::near_null_space`]) for its algebraic multigrid; the native
    /// solvers do not read it.
    pub fn near_null_space(mut self, space: &'a NearNullSpace<'a, G>) -> Self {
        self.near_null_space = Some(space);
        self
    }

    /// The nodal method's constraint `u_i ≥ ψ(x_i)` at the free nodes, for a model of
    /// one P1 field without multiplier ([`nodal`]).
    pub fn nodal(mut self, obstacle: &'a DataFn) -> Self {
        self.nodal = Some(obstacle);
        self
    }

    /// The problem without its constraint (no obstacle): the multiplier is 0 and the
    /// primal block of `B_h` is solved alone, `A U = F`, on the finest mesh: the obstacle
    /// problem whose constraint is nowhere active, one linear solve. The report has no
    /// penetration, open gap or contact set, and no rounding experiment.
    pub fn unconstrained(mut self) -> Self {
        self.unconstrained = true;
        self
    }

    /// The exact solution, for the report's errors.
    pub fn exact(mut self, exact: Exact<'a>) -> Self {
        self.exact = Some(exact);
        self
    }

    /// The memory model of the solve and what sets its size, for the refusal's message
    /// (e.g. `--mesh-size 512 with p2-p0`).
    pub fn memory(mut self, memory: MemoryModel, size: impl Into<String>) -> Self {
        self.memory = memory;
        self.size = Some(size.into());
        self
    }

    /// The meshes of the levels, coarsest first.
    pub fn meshes(&self) -> &[G] {
        &self.meshes
    }

    /// The parameter values with α and s filled in.
    fn param_values(&self, alpha: f64) -> Result<Vec<f64>> {
        let mut values = Vec::with_capacity(M::PARAMS.len());
        let mut missing = Vec::new();
        for (p, value) in self.params.iter().enumerate() {
            let role = if M::STABILIZATION.and_then(|s| s.alpha) == Some(p) {
                Some(alpha)
            } else if M::SIDE == Some(p) {
                Some(self.side.sign())
            } else {
                None
            };
            match role.or(*value) {
                // checked before anything is computed from it (C_I of a negative D)
                Some(v) if v <= 0.0 && M::POSITIVE_PARAMS.contains(&p) => {
                    return Err(Error::Input(format!(
                        "parameter `{}` = {v} must be positive (model `{}` declares `{} > 0`)",
                        M::PARAMS[p],
                        M::NAME,
                        M::PARAMS[p]
                    )))
                }
                Some(v) => values.push(v),
                None => {
                    missing.push(M::PARAMS[p]);
                    values.push(f64::NAN);
                }
            }
        }
        if !missing.is_empty() {
            return Err(Error::Input(format!(
                "model `{}` needs values for {}",
                M::NAME,
                missing.join(", ")
            )));
        }
        if self.side == ObstacleSide::Above && M::SIDE.is_none() {
            return Err(Error::Input(format!(
                "model `{}` has no obstacle side (`side: s`): its obstacle is below",
                M::NAME
            )));
        }
        Ok(values)
    }

    fn data_functions(&self) -> Result<Vec<&'a DataFn>> {
        let missing: Vec<&str> = (0..M::DATA.len())
            .filter(|&d| self.data[d].is_none())
            .map(|d| M::DATA[d])
            .collect();
        if !missing.is_empty() {
            return Err(Error::Input(format!(
                "model `{}` needs the data {}",
                M::NAME,
                missing.join(", ")
            )));
        }
        Ok(self.data.iter().map(|d| d.expect("checked")).collect())
    }

    fn part_markers(&self) -> Result<Vec<Vec<u32>>> {
        self.parts
            .iter()
            .enumerate()
            .map(|(p, markers)| {
                markers.clone().ok_or_else(|| {
                    Error::Input(format!(
                        "the boundary part `{}` of `{}` is not given markers",
                        M::FACET_PARTS[p],
                        M::NAME
                    ))
                })
            })
            .collect()
    }

    /// Solves the problem (see the module's docs).
    ///
    /// # Errors
    /// An invalid input given to the builder, a missing parameter, data function or part,
    /// an estimated memory beyond what the solver allows itself, data that are not finite
    /// or too large or small for double precision, an obstacle that contradicts a support,
    /// an α that the stabilization cannot use, the solvers' failures (with α·C_I named
    /// where it is the likely cause), and an answer lost to rounding (the rows in contact,
    /// the multiplier, the rounding experiment).
    pub fn solve(&self) -> Result<Solved<M, G>> {
        if let Some(e) = &self.invalid {
            return Err(e.clone());
        }
        if self.meshes.is_empty() {
            return Err(Error::Input("no mesh to solve on".into()));
        }
        if let Some(obstacle) = self.nodal {
            let finest = self.meshes.last().expect("checked");
            let memory_estimate = self.memory.bytes(finest.cell_count());
            memory::check_memory(memory_estimate, &self.size_text(finest))?;
            return self.solve_nodal(&self.meshes, obstacle, memory_estimate);
        }
        self.solve_on(&self.meshes, None)
    }

    /// Solves on the problem's meshes, then on each mesh `next` makes from the solution
    /// so far (the next level is a function of the current solution: uniform refinement,
    /// or a refinement marked by an estimate), until it returns `None`. Each new level
    /// starts from the previous level's solution interpolated at its DOFs; where Newton
    /// fails from there, from the problem's start ([`Problem::start`]) if it has one.
    /// The report's `levels` list every level solved.
    ///
    /// # Errors
    /// Those of [`Problem::solve`] on any level, and those of `next`.
    pub fn solve_refining(
        &self,
        mut next: impl FnMut(&Solved<M, G>) -> Result<Option<G>>,
    ) -> Result<Solved<M, G>> {
        let mut current = self.solve()?;
        while let Some(mesh) = next(&current)? {
            let previous = &current.solution;
            if let Some(obstacle) = self.nodal {
                current = self.refine_nodal(&current, mesh, obstacle)?;
                continue;
            }
            let solved = match self.solve_on(std::slice::from_ref(&mesh), Some(previous)) {
                Err(e @ (Error::NotConverged { .. } | Error::LinearSolve(_)))
                    if self.start.is_some() =>
                {
                    let mut again = self.solve_on(std::slice::from_ref(&mesh), None)?;
                    again.fell_back = Some(e.to_string());
                    again
                }
                other => other?,
            };
            let mut levels = current.report.levels.clone();
            levels.extend(solved.report.levels.iter().copied());
            current = solved;
            current.report.levels = levels;
        }
        Ok(current)
    }

    /// Solves adaptively to a tolerance: solve → estimate → mark → refine → solve again
    /// from the previous solution ([`Problem::solve_refining`]), from the problem's
    /// finest mesh, until the estimate `(η² + S²)^{1/2}` is at most
    /// `options.tolerance · ‖u_h‖_a` and the cells along `options.boundary_layer`, where
    /// one is given, are no longer than its width. `progress` sees every level as it is done. The
    /// report lists the levels (`adaptive_levels`) and carries the last level's estimate.
    ///
    /// # Errors
    /// A model without an estimator, a tolerance that is not positive and finite, the
    /// next level's unknowns beyond `options.max_dofs` or no cell left to mark (the
    /// message says how far the loop got), and the errors of [`Problem::solve`] and
    /// [`Domain::estimate`] (on a level after the first, as [`Error::Input`] that says
    /// which level failed and what the one before reached).
    pub fn solve_adaptive(
        &self,
        options: crate::adaptivity::AdaptiveOptions,
        mut progress: impl FnMut(&crate::adaptivity::AdaptiveLevel),
    ) -> Result<Solved<M, G>> {
        use crate::adaptivity::AdaptiveLevel;
        if !M::HAS_ESTIMATOR {
            return Err(Error::Input(format!(
                "model `{}` declares no estimator (`estimator:` in its model file): it cannot be solved to a tolerance",
                M::NAME
            )));
        }
        if !G::ESTIMATES {
            return Err(Error::Input(format!(
                "model `{}`: estimates and adaptive refinement are computed on intervals and affine triangle meshes, not on this mesh's curved cells",
                M::NAME
            )));
        }
        let tolerance = options.tolerance;
        if !(tolerance > 0.0 && tolerance.is_finite()) {
            return Err(Error::Input(format!(
                "the tolerance {tolerance} is not a positive number"
            )));
        }
        let mut levels: Vec<AdaptiveLevel> = Vec::new();
        let mut clock = Instant::now();
        let mut stopped = false;
        let solved = self.solve_refining(|current| {
            let estimate = current
                .estimate
                .as_ref()
                .expect("a model with an estimator reports one on a geometry that estimates");
            let level = AdaptiveLevel {
                cells: current.report.cells,
                dofs: current.report.dofs,
                estimate: estimate.total(),
                estimate_contact: estimate.contact,
                energy_norm: estimate.energy_norm,
                error_energy: current.report.error_energy,
                seconds: clock.elapsed().as_secs_f64(),
            };
            progress(&level);
            levels.push(level);
            let met = level.estimate <= tolerance * level.energy_norm;
            let layer_cells = match &options.boundary_layer {
                Some(layer) => current
                    .mesh()
                    .cells_coarser_than_layer(&layer.markers, layer.width)?,
                None => Vec::new(),
            };
            if met && layer_cells.is_empty() {
                return Ok(None);
            }
            stopped = true;
            let reached = |why: String| {
                let layer = match &options.boundary_layer {
                    Some(layer) if !layer_cells.is_empty() => format!(
                        "; {} cells along the boundary layer are still longer than its width {}",
                        layer_cells.len(),
                        number(layer.width)
                    ),
                    _ => String::new(),
                };
                Error::Input(format!(
                    "{why}: the estimate is {} of ‖u_h‖_a = {} after {} levels ({} cells, {} unknowns), {} the tolerance {}{layer}",
                    number(level.estimate / level.energy_norm),
                    number(level.energy_norm),
                    levels.len(),
                    level.cells,
                    level.dofs,
                    if met { "within" } else { "above" },
                    number(tolerance)
                ))
            };
            // a solution held at zero (by the constraint or the supports) has a norm of
            // rounding size, which no refinement makes the estimate small against; an
            // exact 0 is a mesh without free unknowns (a first mesh of one cell per
            // corner), which refinement gives some
            if !met
                && level.energy_norm > 0.0
                && level.estimate > VANISHING_SOLUTION * level.energy_norm
            {
                return Err(reached(format!(
                    "‖u_h‖_a is {} against an estimate of {}: the solution is zero up to rounding (the obstacle or the supports hold it there), so no refinement meets a tolerance relative to it",
                    number(level.energy_norm),
                    number(level.estimate)
                )));
            }
            let mut marked = if met {
                Vec::new()
            } else {
                options.marking.mark(&estimate.indicators)?
            };
            if marked.is_empty() && layer_cells.is_empty() {
                return Err(reached("no cell has a positive indicator to refine".into()));
            }
            // the layer's cells besides the estimate's: its share of the energy is too
            // small for Dörfler marking to reach its width
            marked.extend(&layer_cells);
            marked.sort_unstable();
            marked.dedup();
            // bisecting a marked cell twice at most, with the closure: about 2–3 new
            // unknowns per marked cell; the next level's size is estimated before it is made
            let predicted = level.dofs + 3 * marked.len() * (level.dofs / level.cells.max(1)).max(1);
            if predicted > options.max_dofs {
                return Err(reached(format!(
                    "the next level would have about {predicted} unknowns, beyond the adaptive loop's limit of {} (`AdaptiveOptions::max_dofs`; `--max-dofs` on the command line)",
                    options.max_dofs
                )));
            }
            clock = Instant::now();
            stopped = false;
            Ok(Some(current.mesh().refine_marked(&marked)?))
        });
        // A level's solve that fails (a refined mesh can take the stabilization below
        // the rounding of the gap) is reported with how far the loop got.
        let mut solved = solved.map_err(|e| match levels.last() {
            Some(last) if !stopped => Error::Input(format!(
                "level {} of the adaptive solve failed: {e}; level {} reached an estimate of {} of ‖u_h‖_a with {} cells and {} unknowns, above the tolerance {} (an adaptive mesh's smallest cells are far smaller than a uniform mesh's of as many unknowns: a looser tolerance stops before them, a finer first mesh grades them less)",
                levels.len() + 1,
                levels.len(),
                number(last.estimate / last.energy_norm),
                last.cells,
                last.dofs,
                number(tolerance)
            )),
            _ => e,
        })?;
        // every level's solve, estimate, marking and refinement is the adaptive solve's
        solved.report.seconds = levels.iter().map(|l| l.seconds).sum();
        solved.report.adaptive_levels = levels;
        Ok(solved)
    }

    /// The input that sets the size, for the memory refusal.
    fn size_text(&self, finest: &G) -> String {
        self.size
            .clone()
            .unwrap_or_else(|| format!("a mesh of {} cells", finest.cell_count()))
    }

    /// [`Problem::solve`] on `meshes` (nested levels, coarsest first): the coarsest one
    /// starts from `previous` interpolated at its DOFs where given, else from the
    /// problem's start.
    fn solve_on(
        &self,
        meshes: &[G],
        previous: Option<&ObstacleSolution<G>>,
    ) -> Result<Solved<M, G>> {
        if let Some(e) = &self.invalid {
            return Err(e.clone());
        }
        let finest = meshes
            .last()
            .ok_or_else(|| Error::Input("no mesh to solve on".into()))?;
        let memory_estimate = self.memory.bytes(finest.cell_count());
        memory::check_memory(memory_estimate, &self.size_text(finest))?;

        multiplier_field::<M>()?;
        let data = self.data_functions()?;
        let parts = self.part_markers()?;
        self.check_data(finest, &data)?;
        let mut warnings = Vec::new();
        let alpha_from_inverse_constant = matches!(self.alpha, Alpha::FromInverseConstant(_));
        // before C_I, whose eigenproblem a flat cell would make fail
        let shape = finest.shape(false)?;
        // C_I with α = 0: the stabilization form's primal blocks do not hold α
        let c_i = self.inverse_constant(finest, &self.param_values(0.0)?, &data, &parts)?;
        let alpha = self.alpha.value(c_i, self.alpha_when_zero)?;
        self.check_alpha(finest, alpha, c_i, &mut warnings)?;
        let params = self.param_values(alpha)?;
        let coefficients = Coefficients::of_values::<M>(&params, &data)?;
        // the finest level's constraints: the feasibility check, and the level's own
        let dofs = finest.system_dofs::<M>()?;
        let constraints = finest.constraints::<M>(&dofs, &coefficients, &self.supports)?;
        warnings.extend(constraints.warnings().iter().cloned());
        warnings.extend(free_unknowns::<M>(finest, &dofs, &constraints)?);
        if !self.unconstrained {
            self.check_feasible(finest, &dofs, &constraints, &data)?;
        }
        let mut options = self.options.obstacle;
        if alpha == 0.0 && options.solver == VariationalSolver::SemismoothNewton {
            warnings.push("α = 0 (the plain mixed method): C = 0 leaves nothing to eliminate Λ with, so the QP solver (clarabel) is used".into());
            options.solver = VariationalSolver::Clarabel;
        }
        let held = match previous {
            None => self.check_held(meshes, &coefficients, &parts)?,
            Some(_) => None,
        };
        // a body the obstacle alone holds starts pressed onto it on the checked level
        let pressed = |d: &Discretization<G>| -> Result<LevelStart> {
            Ok(match &held {
                Some(HeldByObstacle {
                    checked,
                    motions: basis,
                }) if d.mesh.cell_count() == checked.mesh.cell_count()
                    && basis.first().map(Vec::len) == Some(d.lcp.n()) =>
                {
                    crate::lcp::null_space::pressed_start(&d.lcp, basis)
                        .map_or(LevelStart::Zero, LevelStart::At)
                }
                _ => LevelStart::Zero,
            })
        };
        let setup = LevelSetup {
            coefficients: &coefficients,
            parts: &parts,
            options,
            pressed: held.is_some().then_some(&pressed as &FirstStart<'_, G>),
        };
        let nested = self.options.nested && options.solver.nests();
        let first = if nested { 0 } else { meshes.len() - 1 };
        let solution = if self.unconstrained {
            let d = finest.discretize::<M>(&coefficients, dofs, &constraints, &parts)?;
            unconstrained_solution(d).map_err(|e| alpha_hint(e, alpha, c_i))?
        } else {
            self.solve_levels(&meshes[first..], setup, Some((dofs, constraints)), previous)
                .map_err(|e| alpha_hint(e, alpha, c_i))?
        };
        if let Some(HeldByObstacle { checked, motions }) = &held {
            check_balanced::<M, G>(checked, motions, &solution)?;
        }
        let mut report = self.report(&solution, &coefficients, alpha, c_i, options)?;
        if self.unconstrained {
            report.solver = "linear";
            // α acts without contact only through the stabilization's primal part
            if c_i == 0.0 {
                report.alpha = None;
            }
            report.complementarity_residual = 0.0;
            // no constraint, no contact set
            report.contact_area = report.contact_area.map(|_| 0.0);
            report.contact_length = report.contact_length.map(|_| 0.0);
        }
        // where the user's α is far above the default, it is the likelier cause
        if let Some(default) = self.default_alpha(c_i) {
            if alpha > LARGE_ALPHA * default {
                report.warnings.push(format!(
                    "α = {alpha:e} is {} times the default {default:e}, more than {LARGE_ALPHA:e}: the stabilization's term moves the contact set and the answer with α (bernoulli-flat at q = 100 on 256 elements: L² error 1.9e-7 at the default, 4.1e-6 at 1e4 times it, 1.1e-4 at 1e6 times it)",
                    number(alpha / default)
                ));
            }
        }
        report.memory_estimate = memory_estimate;
        warnings.append(&mut report.warnings);
        report.warnings = warnings;
        if shape.is_some() {
            record_mesh_quality(finest, alpha_from_inverse_constant, c_i, &mut report)?;
        }
        if self.options.rounding_experiment && !self.unconstrained {
            self.judge_rounding(meshes, &solution, setup, &mut report)?;
        }
        let estimate = if M::HAS_ESTIMATOR && G::ESTIMATES {
            Some(self.record_estimate(&solution, &params, &data, &parts, &mut report)?)
        } else {
            None
        };
        Ok(Solved {
            solution,
            report,
            params,
            fell_back: None,
            estimate,
            model: PhantomData,
        })
    }

    /// The a-posteriori estimate of `solution`, recorded in `report` with the error in
    /// the estimator's norm and the efficiency index where the exact solution gives them.
    ///
    /// # Errors
    /// Those of [`Domain::estimate`].
    fn record_estimate(
        &self,
        solution: &ObstacleSolution<G>,
        params: &[f64],
        data: &[&DataFn],
        parts: &[Vec<u32>],
        report: &mut Report,
    ) -> Result<crate::adaptivity::Estimate> {
        let side = (!self.unconstrained).then(|| self.side.sign());
        let estimate = G::estimate::<M>(solution, params, data, side, parts)?;
        let total = estimate.total();
        let relative = |x: f64| (estimate.energy_norm > 0.0).then(|| x / estimate.energy_norm);
        report.estimate = Some(total);
        report.estimate_contact = Some(estimate.contact);
        report.estimate_relative = relative(total);
        // the seminorm |u − u_h|_m in the energy norm's units: times ‖u_h‖_a / |u_h|_m,
        // exact where the energy density is a constant times |D^m u|² (the membrane, the
        // beam; the plate's D), within the ν-dependent equivalence for the plate
        let seminorm = if M::ORDER >= 4 {
            report.error_h2
        } else {
            report.error_h1
        };
        let zero = |_: &[f64]| 0.0;
        let zero_gradient = |_: &[f64]| [0.0; 2];
        let zero_hessian = |_: &[f64]| [[0.0; 2]; 2];
        // only the seminorm used: the broken H² seminorm costs a Hessian per point
        let of_u_h = G::errors(
            solution,
            M::constrained_field(),
            &Exact {
                value: &zero,
                gradient: (M::ORDER < 4).then_some(&zero_gradient as &GradientFn),
                hessian: (M::ORDER >= 4).then_some(&zero_hessian as &HessianFn),
                multiplier: None,
            },
        );
        let u_h_seminorm = if M::ORDER >= 4 { of_u_h.h2 } else { of_u_h.h1 };
        let units = match u_h_seminorm {
            Some(n) if n > 0.0 && estimate.energy_norm > 0.0 => estimate.energy_norm / n,
            _ => 1.0,
        };
        report.error_energy = seminorm.map(|e| e * units);
        report.error_energy_relative = report.error_energy.and_then(relative);
        report.efficiency_index = report.error_energy.filter(|&e| e > 0.0).map(|e| total / e);
        Ok(estimate)
    }

    /// Runs the rounding experiment on the solved levels and records it in `report`:
    /// a warning where rounding limits the answer's digits.
    ///
    /// # Errors
    /// An answer that rounding moves by more than [`MAX_ROUNDING`] of its size, or that
    /// the moved mesh cannot be solved on.
    fn judge_rounding(
        &self,
        meshes: &[G],
        solution: &ObstacleSolution<G>,
        setup: LevelSetup<'_, '_, G>,
        report: &mut Report,
    ) -> Result<()> {
        let clock = Instant::now();
        let rounding = setup
            .options
            .solver
            .during(Purpose::RoundingExperiment, || {
                self.rounding_experiment(meshes, solution, setup)
            })
            .unwrap_or(f64::INFINITY);
        report.rounding_seconds = Some(clock.elapsed().as_secs_f64());
        report.rounding = Some(rounding);
        if rounding.is_nan() || rounding > MAX_ROUNDING {
            let moved = if rounding.is_finite() {
                format!("moves the answer by {rounding:.0e} of its size")
            } else {
                "makes the solve fail".to_string()
            };
            return Err(Error::Input(format!(
                "{} is rounding: moving the mesh in its last bits {moved}; the system's condition leaves no correct digit here; use fewer cells (elements)",
                answer_name::<M>()
            )));
        }
        if rounding > ROUNDING_WARNING {
            report.warnings.push(format!(
                "{} is rounding-limited to about {rounding:.0e} of its size (moving the mesh in its last bits moves it that much): fewer cells (elements) give more correct digits here",
                answer_name::<M>()
            ));
        }
        Ok(())
    }

    /// The nodal method's next level of [`Problem::solve_refining`]: solved on `mesh` by
    /// nested iteration from `current`'s mesh (the coarse level is solved again: the
    /// nodal active sets start from an interpolated solution, not a multiplier), the
    /// report's levels those of `current` and the new one.
    ///
    /// # Errors
    /// Those of [`Problem::solve_nodal`].
    fn refine_nodal(
        &self,
        current: &Solved<M, G>,
        mesh: G,
        obstacle: &'a DataFn,
    ) -> Result<Solved<M, G>> {
        let memory_estimate = self.memory.bytes(mesh.cell_count());
        memory::check_memory(memory_estimate, &self.size_text(&mesh))?;
        let meshes = [current.mesh().clone(), mesh];
        let mut solved = self.solve_nodal(&meshes, obstacle, memory_estimate)?;
        let mut levels = current.report.levels.clone();
        levels.extend(solved.report.levels.last().copied());
        solved.report.levels = levels;
        Ok(solved)
    }

    /// The nodal method on nested `meshes` (the last one alone unless the options ask
    /// for nested iteration): the model is one P1 field (and at most its nodal forces'
    /// density), the constraint `u_i ≥ ψ(x_i)` at the free nodes, its multipliers the
    /// nodal forces; with the estimate where the model declares an estimator.
    fn solve_nodal(
        &self,
        meshes: &[G],
        obstacle: &'a DataFn,
        memory_estimate: f64,
    ) -> Result<Solved<M, G>> {
        let finest = meshes.last().expect("checked");
        let data = self.data_functions()?;
        self.check_data(finest, &data)?;
        let shape = finest.shape(false)?;
        let params = self.param_values(0.0)?;
        let coefficients = Coefficients::of_values::<M>(&params, &data)?;
        let dofs = nodal::primal_dofs::<M>(finest)?;
        let constraints = finest.constraints::<M>(&dofs, &coefficients, &self.supports)?;
        check_feasible_at(
            finest,
            &dofs,
            &constraints,
            0,
            obstacle,
            1.0,
            M::FIELDS[0].name,
        )?;
        let options = self.options.obstacle;
        let meshes = if self.options.nested {
            meshes
        } else {
            &meshes[meshes.len() - 1..]
        };
        let solution =
            G::solve_nodal::<M>(meshes, &coefficients, &self.supports, obstacle, options)?;
        let d = &solution.discretization;
        let (u, lambda) = (
            d.primal_part(&solution.values),
            d.multiplier_part(&solution.values),
        );
        let (contact_area, boundary_contact) = G::nodal_contact(&solution, obstacle);
        let penetration = G::penetration(&solution, 0, obstacle, 1.0);
        let mut report = Report {
            model: M::NAME,
            cells: d.mesh.cell_count(),
            dofs: d.lcp.n(),
            multiplier_dofs: d.lcp.m(),
            alpha: None,
            inverse_constant: 0.0,
            solver: match options.solver {
                VariationalSolver::External(e) => e.0.name(),
                _ => "nodal active set",
            },
            // every free node in contact (or the start already the solution): no system
            linear_solver: if let VariationalSolver::External(e) = options.solver {
                e.0.name()
            } else if solution.krylov_iterations > 0 {
                "multigrid"
            } else if solution.factorizations > 0 {
                "direct"
            } else {
                "none"
            },
            iterations: solution.iterations,
            levels: solution.levels.iter().map(|&(c, i)| [c, i]).collect(),
            factorizations: solution.factorizations,
            krylov_iterations: solution.krylov_iterations,
            seconds: solution.seconds,
            memory_estimate,
            energy: match M::ENERGY {
                Some(_) => Some(solution.energy::<M>(&coefficients)?),
                None => None,
            },
            total_contact_force: G::total_contact_force(&solution),
            contact_area: Some(contact_area),
            // the nodal constraint holds exactly at the nodes: a pushing node touches ψ
            max_open_contact_gap: Some(0.0),
            max_penetration: Some(penetration.depth),
            kkt_residual: solution.kkt_residual,
            complementarity_residual: d.lcp.complementarity_residual(&u, &lambda),
            ..Report::default()
        };
        if boundary_contact {
            report.warnings.push("∫λ_h of the nodal method sums the forces at the free nodes: contact reaches the boundary where u = g = ψ, whose nodes carry a share of order h it leaves out (for example membrane-flat at N = 16 and q = 1: 14.06 of the exact 16); a stabilized pair or a finer mesh gives it".into());
        }
        if options.linear_solver == crate::obstacle::hierarchy::LinearSolver::Multigrid
            && solution.krylov_iterations == 0
            && solution.factorizations > 0
        {
            report.warnings.push("--linear-solver multigrid: no active-set step of the finest level was solved by multigrid (it needs a coarser nested level: a cold start, a single level or N below 8 have none; or CG did not converge), so they were factored".into());
        }
        let u_values = G::field_at_vertices(&solution, 0);
        let psi_values = d.mesh.at_vertices(obstacle);
        let size = |v: &[f64]| {
            v.iter()
                .filter(|x| x.is_finite())
                .fold(0.0f64, |m, x| m.max(x.abs()))
        };
        let (lo, hi) = u_values
            .iter()
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            });
        let range = penetration
            .obstacle_range
            .max(if hi >= lo { hi - lo } else { 0.0 });
        let rounding = value_rounding(size(&u_values), size(&psi_values))
            + load_rounding(
                largest_load::<M, G>(&d.mesh, &coefficients),
                d.mesh.extent(),
                M::ORDER,
            );
        let share = 100.0 * penetration.depth / range;
        if range > 0.0
            && penetration.depth > PENETRATION_WARNING * range
            && penetration.depth > rounding
        {
            report.warnings.push(format!(
                "u_h dips below ψ between the vertices by up to {:.2e}, {share:.1}% of the larger of ψ's and u_h's ranges ({range:.2e}): the nodal constraint holds at the vertices only, and this mesh does not resolve ψ's curvature (refine)",
                penetration.depth
            ));
        }
        if let Some(exact) = &self.exact {
            let errors = G::errors(&solution, 0, exact);
            report.error_l2 = errors.l2;
            report.error_h1 = errors.h1;
            report.error_h2 = errors.h2;
            report.error_vertex_max = errors.vertex_max;
            report.error_vertex_mean = errors.vertex_mean;
        }
        if let Some((quality, shape_warnings)) = shape {
            report.warnings.extend(shape_warnings);
            report.mesh_quality = Some(MeshQualityReport {
                min_angle_deg: quality.min_angle_deg,
                max_angle_deg: quality.max_angle_deg,
                max_aspect_ratio: quality.max_aspect_ratio,
                worst_inverse_constant: 0.0,
                forced_alpha: None,
            });
        }
        let estimate = if M::HAS_ESTIMATOR && G::ESTIMATES {
            let parts = self.part_markers()?;
            Some(self.record_estimate(&solution, &params, &data, &parts, &mut report)?)
        } else {
            None
        };
        Ok(Solved {
            solution,
            report,
            params,
            fell_back: None,
            estimate,
            model: PhantomData,
        })
    }

    /// Nested iteration over `meshes`; `finest` are the DOFs and constraints of the last
    /// mesh, when already built.
    fn solve_levels(
        &self,
        meshes: &[G],
        setup: LevelSetup<'_, '_, G>,
        finest: Option<(crate::SystemDofs, Constraints)>,
        previous: Option<&ObstacleSolution<G>>,
    ) -> Result<ObstacleSolution<G>> {
        let LevelSetup {
            coefficients,
            parts,
            options,
            pressed,
        } = setup;
        let supports = &self.supports;
        let near_null_space = self.near_null_space;
        let last = meshes.len() - 1;
        let mut finest = finest;
        // Where the external solver runs on several processes, each assembles its own
        // cells of each level (partitioned here, on the thread that set the solver up),
        // except a level the start pressed onto the obstacle reads whole.
        let partitioned = self.partitioned(options);
        let mut cells: Vec<Option<Vec<usize>>> = Vec::with_capacity(meshes.len());
        for (k, mesh) in meshes.iter().enumerate() {
            cells.push(match partitioned {
                Some(e) if !(k == 0 && pressed.is_some()) => {
                    e.0.partition(&crate::lcp::external::CellGraph::of(mesh))?
                }
                _ => None,
            });
        }
        let levels: Vec<_> = meshes
            .iter()
            .zip(cells)
            .enumerate()
            .map(|(k, (mesh, cells))| {
                let built = if k == last { finest.take() } else { None };
                move || -> Result<Discretization<G>> {
                    let (dofs, constraints) = match built {
                        Some(b) => b,
                        None => {
                            let dofs = mesh.system_dofs::<M>()?;
                            let constraints =
                                mesh.constraints::<M>(&dofs, coefficients, supports)?;
                            (dofs, constraints)
                        }
                    };
                    let mut d = mesh.discretize_on::<M>(
                        cells.as_deref(),
                        coefficients,
                        dofs,
                        &constraints,
                        parts,
                    )?;
                    if let (Some(e), Some(_)) = (partitioned, &cells) {
                        d.lcp.share = Some(crate::lcp::Share::new(e));
                    }
                    if let (VariationalSolver::External(_), Some(space)) =
                        (options.solver, near_null_space)
                    {
                        d.lcp.near_null_space = space(&d);
                    }
                    Ok(d)
                }
            })
            .collect();
        let prolongation = G::primal_prolongation();
        let from_previous = |d: &Discretization<G>| -> Result<LevelStart> {
            let p = previous.expect("used with a previous level");
            Ok(LevelStart::At(d.primal_part(&G::prolong::<M>(
                &p.discretization,
                &p.values,
                d,
            ))))
        };
        let start: Option<&FirstStart<'_, G>> = match previous {
            Some(_) => Some(&from_previous),
            None => self.start.or(pressed),
        };
        solve_nested_from(
            levels,
            |coarse, values, fine| G::prolong::<M>(coarse, values, fine),
            prolongation,
            start,
            options,
        )
    }

    /// The external solver that partitions the levels' assembly among its processes
    /// ([`ExternalSolver::partition`]), where the problem has a constraint to solve (a
    /// problem without one is solved natively): triangles and intervals alike, the
    /// multiplier on the cells or on a boundary part (contact, whose start reads the
    /// level through the parts' reductions, [`FirstStart`]).
    ///
    /// [`ExternalSolver::partition`]: crate::lcp::external::ExternalSolver::partition
    fn partitioned(&self, options: ObstacleOptions) -> Option<External> {
        let VariationalSolver::External(e) = options.solver else {
            return None;
        };
        (!self.unconstrained).then_some(e)
    }

    /// Refuses a problem whose supports leave the body a motion without energy that the
    /// obstacle and the load do not fix ([`crate::lcp::null_space::check_held`]), judged
    /// on the coarsest mesh: the null space of conforming nested spaces under the same
    /// supports is the same on every level (the rigid motions the supports leave), and
    /// there it costs one small factorization. An obstacle over the domain (a multiplier
    /// on cells) sees a motion through its sign on each cell on every level alike.
    ///
    /// A multiplier on a boundary part (contact) is not judged here: a coarse level's
    /// few contact edges can leave a rotation free that finer levels hold, so the
    /// compatibility condition depends on the level; the contact family judges it per
    /// level in its first start (`models::families::contact::checks`, levels too coarse
    /// skipped) against the rigid motions of the elastic body.
    ///
    /// Where the obstacle alone holds the body, the checked level and the null space's
    /// basis there ([`crate::lcp::null_space::Held::ByObstacle`]), for the
    /// start pressed onto the obstacle.
    ///
    /// # Errors
    /// Those of [`crate::lcp::null_space::check_held`], and of building the level.
    fn check_held(
        &self,
        meshes: &[G],
        coefficients: &Coefficients,
        parts: &[Vec<u32>],
    ) -> Result<Option<HeldByObstacle<G>>> {
        let boundary = crate::obstacle::boundary_multiplier::multiplier_part::<M>()?.is_some();
        if boundary && !self.unconstrained {
            return Ok(None);
        }
        let mesh = &meshes[0];
        let dofs = mesh.system_dofs::<M>()?;
        let constraints = mesh.constraints::<M>(&dofs, coefficients, &self.supports)?;
        let d = mesh.discretize::<M>(coefficients, dofs, &constraints, parts)?;
        let name = format!("a mesh of {} cells", mesh.cell_count());
        Ok(
            match crate::lcp::null_space::check_held(&d.lcp, !self.unconstrained, &name)? {
                crate::lcp::null_space::Held::ByObstacle(motions) => Some(HeldByObstacle {
                    checked: d,
                    motions,
                }),
                crate::lcp::null_space::Held::BySupports => None,
            },
        )
    }

    /// The α the default policy would give, where the problem's α is a value of the
    /// user's (`None` where the policy is the default one).
    fn default_alpha(&self, c_i: f64) -> Option<f64> {
        match self.alpha {
            Alpha::Fixed(_) => Alpha::default().value(c_i, self.alpha_when_zero).ok(),
            Alpha::FromInverseConstant(_) => None,
        }
        .filter(|&d| d > 0.0)
    }

    /// `max C_I` of the model's stabilization on `mesh`: per cell, or per edge of the
    /// boundary part its multiplier lives on; 0 for a model without a stabilization.
    fn inverse_constant(
        &self,
        mesh: &G,
        params: &[f64],
        data: &[&DataFn],
        parts: &[Vec<u32>],
    ) -> Result<f64> {
        if M::STABILIZATION.is_none() {
            return Ok(0.0);
        }
        let Some(part) = crate::obstacle::boundary_multiplier::multiplier_part::<M>()? else {
            return crate::stabilization::inverse_constant::<M, G>(mesh, params);
        };
        let coefficients = Coefficients::of_values::<M>(params, data)?;
        let constants = mesh.boundary_inverse_constants::<M>(&coefficients, part, &parts[part])?;
        Ok(constants.iter().fold(0.0f64, |m, &c| m.max(c)))
    }

    /// The stabilization's size against rounding and its stability range.
    fn check_alpha(
        &self,
        mesh: &G,
        alpha: f64,
        c_i: f64,
        warnings: &mut Vec<String>,
    ) -> Result<()> {
        if alpha == 0.0 {
            return Ok(());
        }
        let boundary = crate::obstacle::boundary_multiplier::multiplier_part::<M>()?.is_some();
        if boundary && c_i > 0.0 && alpha * c_i < MIN_BOUNDARY_ALPHA_TIMES_C_I {
            return Err(Error::Input(format!(
                "α = {alpha:e} gives α·max C_I,E = {:.1e}, below {MIN_BOUNDARY_ALPHA_TIMES_C_I:e}: the stabilization is too weak for semismooth Newton (it stalls or needs hundreds of iterations, and the pressure oscillates like the plain method's); use α = 0 (the plain method, solved as a QP) or α·max C_I,E from 0.1 to 1 (the automatic α is ½/max C_I,E = {:.3e})",
                alpha * c_i,
                0.5 / c_i
            )));
        }
        if !boundary {
            // against a well-shaped cell's constant, where there is one (P1's S_h is
            // α h² (λ, μ): relative to the stiffness it is α itself)
            let regular = regular_inverse_constant::<M>(&self.param_values(0.0)?)?;
            let relative = alpha * if regular > 0.0 { regular } else { 1.0 };
            if relative < SMALLEST_RELATIVE_STABILIZATION {
                let smallest = 1.01 * SMALLEST_RELATIVE_STABILIZATION
                    / if regular > 0.0 { regular } else { 1.0 };
                return Err(Error::Input(match self.alpha {
                    Alpha::Fixed(_) => format!(
                        "α = {alpha:e} makes the stabilization of a well-shaped cell {relative:.1e} of its stiffness, below {SMALLEST_RELATIVE_STABILIZATION:.0e}: the method would run practically unstabilized, with λ_h lost in rounding; give α = 0 for the plain method or at least {smallest:.2e} (rounded up: that value itself is accepted)"
                    ),
                    Alpha::FromInverseConstant(_) => format!(
                        "the mesh's worst triangle, {}, has C_I = {c_i:.3e}, which forces α = ½/C_I = {alpha:.3e}: the stabilization of a well-shaped cell is then {relative:.1e} of its stiffness, below {SMALLEST_RELATIVE_STABILIZATION:.0e}, so the method would run practically unstabilized with λ_h lost in rounding; remesh with better-shaped triangles (or give α explicitly)",
                        mesh.worst_cell().unwrap_or_else(|| "a cell".into())
                    ),
                }));
            }
        }
        if c_i > 0.0 && alpha * c_i >= 1.0 {
            warnings.push(format!(
                "α·C_I = {:.2} ≥ 1: outside the stability range 0 < α < 1/C_I = {:.3e}; expect a degraded or unstable solution",
                alpha * c_i,
                1.0 / c_i
            ));
        }
        Ok(())
    }

    /// Every data function finite and within double precision's useful range at the
    /// vertices of `mesh` (boundary data: on the vertices of its supports' parts only,
    /// the only place it is used).
    fn check_data(&self, mesh: &G, data: &[&DataFn]) -> Result<()> {
        let points = mesh.vertex_points();
        let at = |v: usize| {
            points[v]
                .iter()
                .map(|c| c.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        };
        for (d, f) in data.iter().enumerate() {
            let values = mesh.at_vertices(*f);
            let on_part = self.boundary_data_vertices(mesh, d);
            let mut largest = 0.0f64;
            for (v, &value) in values.iter().enumerate() {
                if on_part.as_ref().is_some_and(|on| !on[v]) {
                    continue;
                }
                if !value.is_finite() {
                    return Err(Error::Input(format!(
                        "data `{}` of `{}` is {value} at ({})",
                        M::DATA[d],
                        M::NAME,
                        at(v)
                    )));
                }
                if value.abs() > MAX_DATA {
                    return Err(Error::Input(format!(
                        "data `{}` of `{}` is {value:e} at ({}), beyond ±{MAX_DATA:e}: norms in the solve would overflow double precision",
                        M::DATA[d],
                        M::NAME,
                        at(v)
                    )));
                }
                largest = largest.max(value.abs());
            }
            if largest > 0.0 && largest < MIN_DATA_SIZE {
                return Err(Error::Input(format!(
                    "data `{}` of `{}` is at most {largest:e} in size, below {MIN_DATA_SIZE:e}: the solve multiplies it by powers of h and would underflow; rescale the units",
                    M::DATA[d],
                    M::NAME
                )));
            }
        }
        Ok(())
    }

    /// For boundary data `d` (of a `boundary:` condition with a `Data` support), which
    /// vertices lie on its supports' parts; `None` for data used everywhere.
    fn boundary_data_vertices(&self, mesh: &G, d: usize) -> Option<Vec<bool>> {
        let fields: Vec<usize> = M::DIRICHLET
            .iter()
            .filter(|&&(_, data)| data == d)
            .map(|&(f, _)| f)
            .collect();
        let used_elsewhere = M::OBSTACLE.is_some_and(|[_, obstacle]| obstacle == d);
        if fields.is_empty() || used_elsewhere {
            return None;
        }
        let parts: Vec<&DirichletPart> = self
            .supports
            .iter()
            .filter(|s| s.condition == Condition::Data && fields.contains(&s.field))
            .map(|s| &s.part)
            .collect();
        let mut on = vec![false; mesh.vertex_points().len()];
        for part in parts {
            for (o, p) in on.iter_mut().zip(mesh.vertices_on(part)) {
                *o |= p;
            }
        }
        Some(on)
    }

    /// An error where a support holds the constrained field on the wrong side of the
    /// obstacle: no admissible state exists.
    fn check_feasible(
        &self,
        mesh: &G,
        dofs: &crate::SystemDofs,
        constraints: &Constraints,
        data: &[&DataFn],
    ) -> Result<()> {
        let Some([field, obstacle]) = M::OBSTACLE else {
            return Ok(());
        };
        check_feasible_at(
            mesh,
            dofs,
            constraints,
            field,
            data[obstacle],
            self.side.sign(),
            M::FIELDS[field].name,
        )
    }

    /// The report of a solution: the solve's numbers, and the guards every family shares
    /// (multiplier noise, the plain pair's kernel, rounding of the primal answer, the
    /// crossing of the obstacle and open gaps, errors against an exact solution).
    ///
    /// # Errors
    /// A multiplier or a primal answer lost to rounding.
    fn report(
        &self,
        solution: &ObstacleSolution<G>,
        coefficients: &Coefficients,
        alpha: f64,
        c_i: f64,
        options: ObstacleOptions,
    ) -> Result<Report> {
        let d = &solution.discretization;
        let lcp: &Lcp = &d.lcp;
        let (u, lambda) = (
            d.primal_part(&solution.values),
            d.multiplier_part(&solution.values),
        );
        let energy = match M::ENERGY {
            Some(_) => Some(solution.energy::<M>(coefficients)?),
            None => None,
        };
        let on_triangles = G::CELL == crate::CellKind::Triangle;
        let measure = G::contact_measure(solution);
        let mut report = Report {
            model: M::NAME,
            cells: d.mesh.cell_count(),
            dofs: lcp.n() + lcp.m(),
            multiplier_dofs: lcp.m(),
            alpha: Some(alpha),
            inverse_constant: c_i,
            solver: options.solver.name(),
            linear_solver: match options.solver {
                // its options choose it; its records name it
                VariationalSolver::External(e) => e.0.name(),
                _ => solution.linear_solver_name(),
            },
            iterations: solution.iterations,
            levels: solution.levels.iter().map(|&(c, i)| [c, i]).collect(),
            factorizations: solution.factorizations,
            krylov_iterations: solution.krylov_iterations,
            seconds: solution.seconds,
            energy,
            total_contact_force: G::total_contact_force(solution),
            contact_area: (on_triangles && d.boundary().is_none()).then_some(measure),
            contact_length: (!on_triangles || d.boundary().is_some()).then_some(measure),
            kkt_residual: solution.kkt_residual,
            complementarity_residual: lcp.complementarity_residual(&u, &lambda),
            multiplier_noise: solution.multiplier_noise,
            ..Report::default()
        };
        let mut warnings = solver_warnings::<M, G>(solution, alpha, options)?;
        let sizes = AnswerSizes::of::<M, G>(solution, coefficients, &u);
        let primal_rounding = solution.primal_rounding();
        report.primal_rounding = if sizes.level > 0.0 {
            primal_rounding / sizes.level
        } else {
            0.0
        };
        self.judge_primal_rounding(report.primal_rounding, alpha, c_i, &mut warnings)?;
        // without a constraint there is nothing to cross
        if let (Some([field, obstacle]), false) = (M::OBSTACLE, self.unconstrained) {
            let crossing = Crossing {
                field,
                psi: coefficients.data[obstacle],
                sizes,
                // the rounding of the compared values: of their size, of the solve under
                // its load, and of the solve through the rows in contact
                rounding: value_rounding(sizes.u, sizes.psi)
                    + load_rounding(
                        largest_load::<M, G>(&d.mesh, coefficients),
                        d.mesh.extent(),
                        M::ORDER,
                    )
                    + primal_rounding,
            };
            self.judge_crossing(solution, &crossing, alpha, c_i, &mut report, &mut warnings);
        }
        if let (Some(exact), Some([field, _])) = (&self.exact, M::OBSTACLE) {
            record_errors(solution, field, exact, &mut report, &mut warnings);
        }
        report.warnings = warnings;
        Ok(report)
    }

    /// Refuses a primal answer that rounding of the contact rows moves by more than
    /// [`MAX_PRIMAL_ROUNDING`] of its size (`relative`), naming α where the user's is
    /// far above the default; warns beyond [`PRIMAL_ROUNDING_WARNING`].
    ///
    /// # Errors
    /// [`Error::Input`] for an answer lost to rounding.
    fn judge_primal_rounding(
        &self,
        relative: f64,
        alpha: f64,
        c_i: f64,
        warnings: &mut Vec<String>,
    ) -> Result<()> {
        if relative.is_nan() || relative > MAX_PRIMAL_ROUNDING {
            let large_alpha = self
                .default_alpha(c_i)
                .filter(|&default| alpha > LARGE_ALPHA * default);
            if let Some(default) = large_alpha {
                return Err(Error::Input(format!(
                    "{} is lost to rounding: the load with α = {alpha:e} ({} times the default {default:e}) makes the terms of the constraint rows so large that their rounding moves it by {relative:.0e} of its own size (its KKT residual cannot show it): lower α first, then the load",
                    answer_name::<M>(),
                    number(alpha / default),
                )));
            }
            return Err(Error::Input(format!(
                "{} is lost to rounding: the load dwarfs the obstacle: in contact the constraint rows subtract terms of the load's size, and their rounding moves {} by {relative:.0e} of its own size (its KKT residual cannot show it); use a smaller load (or α)",
                answer_name::<M>(),
                answer_name::<M>(),
            )));
        }
        if relative > PRIMAL_ROUNDING_WARNING {
            warnings.push(format!(
                "{} may be off by {relative:.0e} of its size through the rounding of the contact rows (the load dwarfs the obstacle)",
                answer_name::<M>(),
            ));
        }
        Ok(())
    }

    /// Records the constrained field's crossing of the obstacle and the largest open
    /// gap under a pushing multiplier, and warns where either is beyond rounding and
    /// its share of the answer (naming α where the user's is the likelier cause).
    fn judge_crossing(
        &self,
        solution: &ObstacleSolution<G>,
        crossing: &Crossing<'_>,
        alpha: f64,
        c_i: f64,
        report: &mut Report,
        warnings: &mut Vec<String>,
    ) {
        let d = &solution.discretization;
        let Crossing {
            field,
            psi,
            sizes,
            rounding,
        } = *crossing;
        let name = M::FIELDS[field].name;
        let side = self.side.sign();
        let penetration = G::penetration(solution, field, psi, side);
        let gap = if d.boundary().is_some() {
            0.0
        } else {
            G::open_gap(solution, field, psi, side)
        };
        report.max_penetration = Some(penetration.depth);
        report.max_open_contact_gap = Some(gap);
        let large_alpha = self
            .default_alpha(c_i)
            .filter(|&default| alpha > 10.0 * default);
        // a flat obstacle under a flat answer has ranges of rounding size: the depth is
        // judged against the answer's size there (a percentage of 1e-17 meant nothing)
        let size = sizes.u.max(sizes.psi);
        let ranges = penetration.obstacle_range.max(sizes.u_range);
        let (range, measure) = if ranges < FLAT_SHARE * size {
            (size, "the larger of ψ's and {name}_h's sizes")
        } else {
            (ranges, "the larger of ψ's and {name}_h's ranges")
        };
        let measure = measure.replace("{name}", name);
        if penetration.depth.is_nan() {
            warnings.push(format!(
                "max_penetration is not a number: the obstacle ψ or {name}_h is not finite at some point the penetration check samples"
            ));
        } else if range > 0.0
            && penetration.depth > PENETRATION_WARNING * range
            && penetration.depth > rounding
        {
            warnings.push(format!(
                "{name}_h {} ψ by up to {:.2e}, {:.1} % of {measure} ({range:.2e}): the constraint holds on each cell's mean, so a mesh that does not resolve the contact lets {name}_h pass ψ by O(h²) inside cells; refine the mesh (or lower the load)",
                if side > 0.0 { "dips below" } else { "rises above" },
                penetration.depth,
                100.0 * penetration.depth / range
            ));
            if let Some(default) = large_alpha {
                warnings.push(format!(
                    "α = {alpha:e} is {:.0e} times the default {default:.3e}: the stabilized constraint lets {name}_h cross ψ by about α h^p λ_h, so lower α before refining",
                    alpha / default
                ));
            }
        }
        let level = sizes.level;
        if gap > OPEN_GAP_WARNING * level && gap > rounding {
            let cure = if large_alpha.is_some() {
                "lower α"
            } else {
                "refine the mesh or lower α"
            };
            warnings.push(format!(
                "λ_h pushes on cells where {name}_h stays up to {gap:.2e} clear of ψ ({:.1} % of the answer's size max(|{name}_h|, |ψ|) = {level:.2e}): the stabilized constraint on contact cells lets α h^p(…) (α = {alpha:e}) open that gap, so this contact set is not real; {cure}",
                100.0 * gap / level
            ));
        }
    }

    /// The rounding experiment: the largest relative change of the constrained field
    /// (at the vertices, against the answer's size) and of `∫ λ_h` (against the larger
    /// of itself and the load's force scale) when the mesh is scaled by `1 + 2⁻⁴⁰` and
    /// `1 − 2⁻³⁹`. The exact solution moves by O(2⁻⁴⁰); every entry of the system moves
    /// in its last bits, so the rounding of the solve is drawn anew. Measured on the
    /// Euler–Bernoulli beam against its exact solution (1024 to 65536 elements), the
    /// change is within a factor 3 of the true error wherever rounding dominates it,
    /// while a first-order estimate from random perturbations of the entries came out
    /// 1000× too small and the norm-wise `ε κ(A)` 100× too large.
    fn rounding_experiment(
        &self,
        meshes: &[G],
        solution: &ObstacleSolution<G>,
        setup: LevelSetup<'_, '_, G>,
    ) -> Result<f64> {
        let options = setup.options;
        let d = &solution.discretization;
        let field = M::OBSTACLE.map_or(0, |[f, _]| f);
        let reference = G::field_at_vertices(solution, field);
        let force = G::total_contact_force(solution);
        let diameter = d.mesh.extent();
        let size = reference
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()))
            .max(1e-6 * diameter);
        let force_scale = force
            .abs()
            .max(d.lcp.multiplier_scale() * domain_measure(&d.mesh))
            .max(f64::MIN_POSITIVE);
        let mut largest = 0.0f64;
        for factor in [1.0 + 2f64.powi(-40), 1.0 - 2f64.powi(-39)] {
            let meshes = meshes
                .iter()
                .map(|m| m.scaled(factor))
                .collect::<Result<Vec<G>>>()?;
            let first = if self.options.nested && options.solver.nests() {
                0
            } else {
                meshes.len() - 1
            };
            let moved = self.solve_levels(&meshes[first..], setup, None, None)?;
            let values = G::field_at_vertices(&moved, field);
            let change = values
                .iter()
                .zip(&reference)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            let force_change = (G::total_contact_force(&moved) - force).abs();
            largest = largest.max((change / size).max(force_change / force_scale));
        }
        Ok(largest)
    }
}

/// An α above this multiple of the default is warned about: the error grows with α
/// (bernoulli-flat, q = 100, 256 elements: 1.9e-7 at the default 1e-2, 2.3e-5 at 1e3,
/// 1.1e-4 at 1e4), and the contact set widens without an open gap to show it.
pub const LARGE_ALPHA: f64 = 1e3;

/// Fewer free primal unknowns than this on the finest mesh earn a warning: the answer is
/// then a coarse-mesh approximation, off by O(1) in what it reports (Morley's simply
/// supported square on one cell per corner: +294 % at the centre).
pub const FEW_UNKNOWNS: usize = 16;

/// Refuses a mesh on which the supports fix every primal DOF to 0 (the answer would be
/// 0 whatever the load: the Kirchhoff square of one cell per corner), and warns where
/// fewer than [`FEW_UNKNOWNS`] are free (with none free and nonzero boundary data, u_h
/// is the data's interpolant).
fn free_unknowns<M: Model>(
    mesh: &impl Mesh,
    dofs: &crate::SystemDofs,
    constraints: &Constraints,
) -> Result<Option<String>> {
    let reduction = constraints.reduction(dofs.dof_count())?;
    let multiplier = multiplier_field::<M>()?;
    let multipliers = dofs.range(multiplier).unwrap_or(0..0);
    let free = reduction
        .free()
        .iter()
        .filter(|d| !multipliers.contains(d))
        .count();
    let homogeneous = (0..dofs.dof_count())
        .filter(|d| !multipliers.contains(d) && reduction.free_index(*d).is_none())
        .all(|d| reduction.fixed_value(d) == 0.0);
    if free == 0 && homogeneous {
        return Err(Error::Input(format!(
            "the supports fix every DOF of the primal fields on this mesh of {} cells: the solution would be 0 whatever the load; refine the mesh",
            mesh.cell_count()
        )));
    }
    Ok((free < FEW_UNKNOWNS).then(|| {
        format!(
            "the mesh of {} cells leaves {free} free primal unknowns: the answer is a coarse-mesh approximation, possibly off by O(1) in every quantity reported; refine the mesh",
            mesh.cell_count()
        )
    }))
}

/// A body the obstacle alone holds: the level its null space was found on, and a
/// basis of it (vectors of that level's free unknowns).
struct HeldByObstacle<G> {
    checked: Discretization<G>,
    motions: Vec<Vec<f64>>,
}

/// Refuses an answer that does not balance the load on the motions the obstacle alone
/// holds (`basis`, on the level `checked`), prolonged to the answer's level
/// ([`crate::lcp::null_space::unbalanced_work`] above [`MAX_UNBALANCED_WORK`]).
///
/// # Errors
/// [`Error::Input`] saying that the contact that holds the body was lost.
fn check_balanced<M: Model, G: Domain>(
    checked: &Discretization<G>,
    basis: &[Vec<f64>],
    solution: &ObstacleSolution<G>,
) -> Result<()> {
    let fine = &solution.discretization;
    let expand = |u: Vec<f64>| checked.full_of_primal(u);
    // the motion alone: the fixed values (a support's data) subtracted
    let offset = expand(vec![0.0; checked.lcp.n()]);
    let motions: Vec<Vec<f64>> = basis
        .iter()
        .map(|r| {
            let full: Vec<f64> = expand(r.clone())
                .iter()
                .zip(&offset)
                .map(|(a, b)| a - b)
                .collect();
            fine.primal_part(&G::prolong::<M>(checked, &full, fine))
        })
        .collect();
    let lambda = fine.multiplier_part(&solution.values);
    let unbalanced = crate::lcp::null_space::unbalanced_work(&fine.lcp, &lambda, &motions);
    if unbalanced > MAX_UNBALANCED_WORK {
        return Err(Error::Input(format!(
            "the answer does not balance the load on a motion that only the obstacle holds (its work is unbalanced by {unbalanced:.1e} of its size): the solve lost the contact that holds the body, and its answer is the rounding of a singular system; support the body, or make its data less extreme in scale"
        )));
    }
    Ok(())
}

/// The relative unbalanced work above which an answer is refused. Measured: the free
/// bodies of the tests balance to 1e-9; a plate held on one edge whose scale is
/// extreme (half-width 1e-3, or D = 1e9) to 7e-6 and 3e-5, from rounding; an answer
/// that lost its contact (w ≈ 0, no reaction) is off by 0.99.
const MAX_UNBALANCED_WORK: f64 = 1e-3;

/// What every level of one solve shares: the coefficients, the boundary parts'
/// markers, the solver's options, and the start of a body the obstacle alone holds
/// (`None` where the supports hold it).
struct LevelSetup<'s, 'f, G> {
    coefficients: &'s Coefficients<'f>,
    parts: &'s [Vec<u32>],
    options: ObstacleOptions,
    pressed: Option<&'s FirstStart<'f, G>>,
}

// by hand: a derive would ask `G: Copy`
impl<G> Clone for LevelSetup<'_, '_, G> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<G> Copy for LevelSetup<'_, '_, G> {}

/// The solution of `d` with every constraint inactive: `Λ = 0` and `A U = F` by sparse
/// Cholesky (`A`, the primal block of `B_h`, is SPD for `α < 1/C_I`); its residual is
/// the equilibrium backward error `‖AU − F‖∞ / (‖A‖∞‖U‖∞ + ‖F‖∞)`.
fn unconstrained_solution<G: crate::DofNumbering>(
    d: Discretization<G>,
) -> Result<ObstacleSolution<G>> {
    let clock = Instant::now();
    let lcp = &d.lcp;
    let u = crate::lcp::cholesky::solve_spd(&lcp.a, &lcp.f)?;
    let au = crate::lcp::cholesky::multiply(&lcp.a, &u);
    let inf = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let a_norm = (0..lcp.n())
        .map(|j| lcp.a.val_of_col(j).iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0f64, f64::max);
    let difference: Vec<f64> = au.iter().zip(&lcp.f).map(|(a, f)| a - f).collect();
    let scale = a_norm * inf(&u) + inf(&lcp.f);
    let residual = if scale > 0.0 {
        inf(&difference) / scale
    } else {
        0.0
    };
    let seconds = clock.elapsed().as_secs_f64();
    let solution = crate::lcp::LcpSolution {
        u,
        lambda: vec![0.0; lcp.m()],
        iterations: 1,
        kkt_residual: residual,
        seconds,
        factorizations: 1,
        low_rank_updates: 0,
        multiplier_noise: 0.0,
        iterative_steps: 0,
        krylov_iterations: 0,
    };
    let values = d.full(&solution);
    let cells = d.mesh.cell_count();
    Ok(ObstacleSolution::of(
        &solution,
        d,
        values,
        vec![(cells, 1)],
        seconds,
    ))
}

/// The sizes an answer's checks are judged against: the largest |u_h| and |ψ| at the
/// vertices, the range of u_h there, and the answer's level
/// ([`report::answer_level`]).
#[derive(Clone, Copy, Debug)]
struct AnswerSizes {
    u: f64,
    psi: f64,
    u_range: f64,
    level: f64,
}

impl AnswerSizes {
    /// The sizes of `solution` (`u` its primal unknowns, the size of a model without an
    /// obstacle).
    fn of<M: Model, G: Domain>(
        solution: &ObstacleSolution<G>,
        coefficients: &Coefficients,
        u: &[f64],
    ) -> Self {
        let d = &solution.discretization;
        let size_of = |values: &[f64]| {
            values
                .iter()
                .filter(|v| v.is_finite())
                .fold(0.0f64, |m, v| m.max(v.abs()))
        };
        let (u_size, psi_size, u_range) = match M::OBSTACLE {
            Some([field, obstacle]) => {
                let u_values = G::field_at_vertices(solution, field);
                let psi = d.mesh.at_vertices(coefficients.data[obstacle]);
                let (lo, hi) = u_values
                    .iter()
                    .filter(|v| v.is_finite())
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                        (lo.min(v), hi.max(v))
                    });
                (
                    size_of(&u_values),
                    size_of(&psi),
                    if hi >= lo { hi - lo } else { 0.0 },
                )
            }
            None => (size_of(u), 0.0, 0.0),
        };
        Self {
            u: u_size,
            psi: psi_size,
            u_range,
            level: answer_level(u_size, psi_size, d.mesh.extent()),
        }
    }
}

/// What the check of the obstacle's crossing compares: the constrained field, ψ, the
/// answer's sizes and the rounding of the compared values.
struct Crossing<'a> {
    field: usize,
    psi: &'a DataFn,
    sizes: AnswerSizes,
    rounding: f64,
}

/// The warnings of how the solve went (a multiplier near rounding noise, the plain
/// pair's kernel, multigrid asked for but not used).
///
/// # Errors
/// [`Error::Input`] for a multiplier that is rounding noise.
fn solver_warnings<M: Model, G>(
    solution: &ObstacleSolution<G>,
    alpha: f64,
    options: ObstacleOptions,
) -> Result<Vec<String>> {
    let lcp = &solution.discretization.lcp;
    let mut warnings = Vec::new();
    if solution.multiplier_noise > MAX_MULTIPLIER_NOISE {
        return Err(Error::Input(format!(
            "λ_h is rounding noise (estimated {:.0e} relative; ∫λ_h would be off by as much, and {} follows it): the multiplier's stabilization C = α h^p lies below the rounding of the gap G − BU; use fewer cells (elements) or a larger α",
            solution.multiplier_noise,
            answer_name::<M>()
        )));
    }
    if solution.multiplier_noise > MULTIPLIER_NOISE_WARNING {
        warnings.push(format!(
            "λ_h may carry rounding noise of up to {:.0e} relative: C = α h^p approaches the rounding of G − BU at this mesh size, and its recovery is no guarantee at this conditioning (a larger α or a coarser mesh avoids it)",
            solution.multiplier_noise
        ));
    }
    if alpha == 0.0 && lcp.m() > lcp.n() {
        warnings.push(format!(
            "α = 0: the plain pair has {} multipliers for {} primal unknowns, so Bᵀ has a kernel of dimension at least {} (no discrete inf-sup condition, docs/mathematics.md §1): u_h is unique, but where that kernel meets the contact set λ_h is not, and the λ_h, ∫λ_h and contact set reported are one of many; α > 0 (the default) gives the unique stabilized λ_h",
            lcp.m(),
            lcp.n(),
            lcp.m() - lcp.n()
        ));
    }
    if options.linear_solver == crate::obstacle::hierarchy::LinearSolver::Multigrid
        && solution.iterative_steps == 0
    {
        warnings.push(match options.solver {
            VariationalSolver::SemismoothNewton => "--linear-solver multigrid: no Newton step of the finest level was solved by multigrid (it needs a coarser nested level and elements with a prolongation; or CG did not converge), so they were factored".to_string(),
            VariationalSolver::Clarabel => "--linear-solver multigrid: the QP solver (clarabel) has no Newton steps; it factors its own systems".to_string(),
            VariationalSolver::External(e) => format!("--linear-solver multigrid: the {} solver chooses its own linear solver (its options say which)", e.0.name()),
        });
    }
    Ok(warnings)
}

/// Records the errors of `solution`'s `field` against `exact`, with a warning where one
/// is not a number.
fn record_errors<G: Domain>(
    solution: &ObstacleSolution<G>,
    field: usize,
    exact: &Exact<'_>,
    report: &mut Report,
    warnings: &mut Vec<String>,
) {
    let errors = G::errors(solution, field, exact);
    report.error_l2 = errors.l2;
    report.error_h1 = errors.h1;
    report.error_h2 = errors.h2;
    report.error_multiplier = errors.multiplier;
    report.error_vertex_max = errors.vertex_max;
    report.error_vertex_mean = errors.vertex_mean;
    let not_a_number = |e: Option<f64>| e.is_some_and(|e| !e.is_finite());
    if not_a_number(errors.l2) || not_a_number(errors.h1) || not_a_number(errors.multiplier) {
        warnings.push("an error against the exact solution is not a number: the exact u, its gradient or λ is not finite at some quadrature point".into());
    }
}

/// A user's number as a message prints it: as written for magnitudes in [10⁻³, 10⁶)
/// and zero, in scientific notation otherwise (`1e-300` is not three hundred digits).
pub fn number(x: f64) -> String {
    if x == 0.0 || (1e-3..1e6).contains(&x.abs()) {
        x.to_string()
    } else {
        format!("{x:e}")
    }
}

/// Largest size of a data function a solve accepts: beyond it the norms that certify a
/// solution (`‖A‖∞‖U‖∞` in the KKT residual) may overflow.
pub const MAX_DATA: f64 = 1e100;

/// The smallest size a non-zero data function may have: the solves multiply it by
/// `h⁴`, `αh^k` and rounding-sized weights, which underflow below it.
pub const MIN_DATA_SIZE: f64 = 1e-200;

/// C_I of the model's stabilization on a regular cell (the unit interval, the
/// equilateral triangle of side 1).
fn regular_inverse_constant<M: Model>(params: &[f64]) -> Result<f64> {
    let cell: &[f64] = match M::CELL {
        crate::CellKind::Interval => &[0.0, 1.0],
        crate::CellKind::Triangle => &[0.0, 0.0, 1.0, 0.0, 0.5, 0.866_025_403_784_438_6],
    };
    if M::STABILIZATION.is_none() {
        return Ok(0.0);
    }
    crate::stabilization::element_inverse_constant::<M>(cell, params)
}

/// The largest `|f|` at the vertices over the model's data other than the obstacle and
/// the boundary data: the size of its loads.
fn largest_load<M: Model, G: Domain>(mesh: &G, coefficients: &Coefficients) -> f64 {
    let obstacle = M::OBSTACLE.map(|[_, d]| d);
    (0..M::DATA.len())
        .filter(|&d| Some(d) != obstacle && !M::DIRICHLET.iter().any(|&(_, g)| g == d))
        .flat_map(|d| mesh.at_vertices(coefficients.data[d]))
        .filter(|v| v.is_finite())
        .fold(0.0f64, |m, v| m.max(v.abs()))
}

/// What the reports call the answer: the constrained field with `_h` (`w_h`), or "the
/// answer" for a model without a pointwise obstacle.
fn answer_name<M: Model>() -> String {
    match M::OBSTACLE {
        Some([field, _]) => format!("{}_h", M::FIELDS[field].name),
        None => "the answer".to_string(),
    }
}

/// The total measure of a mesh (its cells' lengths or areas).
fn domain_measure<G: Mesh>(mesh: &G) -> f64 {
    (0..mesh.cell_count()).map(|c| mesh.measure(c)).sum()
}

/// An error where a support holds `field` (named `name`) on the wrong side of the
/// obstacle `psi` at a vertex: no admissible state exists.
fn check_feasible_at<G: Domain>(
    mesh: &G,
    dofs: &crate::SystemDofs,
    constraints: &Constraints,
    field: usize,
    psi: &DataFn,
    side: f64,
    name: &str,
) -> Result<()> {
    let (Some(map), Some(offset)) = (dofs.map(field), dofs.offset(field)) else {
        return Ok(());
    };
    let mut fixed: std::collections::HashMap<usize, f64> =
        constraints.fixed().iter().copied().collect();
    // a condition on one DOF of a group fixes it too (an Argyris vertex's `u = 0` among
    // the rows of a simple support)
    for (group, row, value) in constraints.combinations() {
        let g = group.as_slice();
        let mut nonzero = (0..g.len()).filter(|&k| row[k] != 0.0);
        if let (Some(k), None) = (nonzero.next(), nonzero.next()) {
            fixed.entry(g[k]).or_insert(value / row[k]);
        }
    }
    for (v, x) in mesh.vertex_points().iter().enumerate() {
        let Some(&value) = fixed.get(&(offset + map.vertex_dofs(v).start)) else {
            continue;
        };
        let obstacle = psi(x);
        if side * (value - obstacle) < -1e-12 * (1.0 + value.abs().max(obstacle.abs())) {
            let at = x
                .iter()
                .map(|c| c.to_string())
                .collect::<Vec<_>>()
                .join(", ");
            return Err(Error::Input(format!(
                "infeasible: a support holds `{name}` = {value} at ({at}), but the obstacle requires {name} {} ψ = {obstacle} there, so no admissible {name} exists",
                if side > 0.0 { "≥" } else { "≤" }
            )));
        }
    }
    Ok(())
}

/// The mesh's quality in `report` with its warnings, `c_i` the worst inverse constant
/// and the α it forces where α follows from it (`alpha_from_inverse_constant`).
///
/// # Errors
/// Those of the mesh's shape measures.
fn record_mesh_quality<G: Domain>(
    finest: &G,
    alpha_from_inverse_constant: bool,
    c_i: f64,
    report: &mut Report,
) -> Result<()> {
    if let Some((quality, shape_warnings)) =
        finest.shape(alpha_from_inverse_constant && c_i > 0.0)?
    {
        report.warnings.extend(shape_warnings);
        report.mesh_quality = Some(MeshQualityReport {
            min_angle_deg: quality.min_angle_deg,
            max_angle_deg: quality.max_angle_deg,
            max_aspect_ratio: quality.max_aspect_ratio,
            worst_inverse_constant: c_i,
            forced_alpha: (c_i > 0.0).then(|| 0.5 / c_i),
        });
    }
    Ok(())
}

/// A solver's failure with α named where it is the likely cause: beyond the stability
/// range `A_α` is indefinite; a small α leaves the eliminated multipliers
/// `(G − BU)/(α h^p |T|)` to rounding on fine meshes.
fn alpha_hint(error: Error, alpha: f64, c_i: f64) -> Error {
    let hint = if c_i > 0.0 && alpha * c_i >= 1.0 {
        let product = alpha * c_i;
        // three digits: 1e300 written out is a line of digits
        let product = if product < 1e6 {
            format!("{product:.2}")
        } else {
            format!("{product:.2e}")
        };
        return Error::Input(format!(
            "α·C_I = {product} is outside the stability range 0 < α < 1/C_I = {:.3e}, where A_α = a − αS is indefinite, and the solve failed: {error}",
            1.0 / c_i
        ));
    } else if alpha > 0.0 && (alpha < 1e-6 || (c_i > 0.0 && alpha * c_i < 1e-4)) {
        format!(
            "α = {alpha:e} is small: with so little stabilization the multipliers, eliminated as (G − BU)/(α h^p |T|), drown in rounding on fine meshes; give α = 0 for the plain method, or a larger α"
        )
    } else {
        return error;
    };
    match error {
        Error::NotConverged { solver, detail } => Error::NotConverged {
            solver,
            detail: format!("{detail}; {hint}"),
        },
        Error::LinearSolve(detail) => Error::LinearSolve(format!("{detail}; {hint}")),
        other => other,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{Diagonal, IntervalMesh, TriangleMesh};
    use crate::obstacle::{solve_obstacle, triangle::solve_obstacle_on_triangles};

    crate::model! {
        /// A string over an obstacle on either side, P1–P0, with boundary data.
        pub mod string on interval {
            unknowns: u: P1, lam: P0 >= 0;
            tests: v, mu;
            params: alpha, s, k;
            data: f, psi, g;
            boundary: u = g;
            forms: "
                a(u;v)           = ∫ u'v' + k u v
                b(v;mu)          = ∫ s v mu
                S(u,lam;v,mu)    = Σ_T h_T² (−u'' + k u − s lam, −v'' + k v − s mu)_T
                l(v)             = ∫ f v
                lS(v,mu)         = Σ_T h_T² (f, −v'' + k v − s mu)_T
                G(mu)            = ∫ s psi mu
                B_h(u,lam;v,mu)  = a(u;v) − b(v;lam) − b(u;mu) − alpha S(u,lam;v,mu)
                L_h(v,mu)        = l(v) − G(mu) − alpha lS(v,mu)
            ";
            system: B_h, L_h;
            energy: a, l;
            stabilization: alpha S against a;
            side: s;
            obstacle: u >= psi;
        }
    }

    crate::model! {
        /// The P1–P0 membrane with boundary data.
        pub mod membrane on triangle {
            unknowns: u: P1, lam: P0 >= 0;
            tests: v, mu;
            params: alpha;
            data: f, psi, g;
            boundary: u = g;
            forms: "
                a(u;v)          = ∫ ∇u·∇v
                S(u,lam;v,mu)   = Σ_T h_T² (−Δu − lam, −Δv − mu)_T
                l(v)            = ∫ f v
                lS(v,mu)        = Σ_T h_T² (f, −Δv − mu)_T
                B_h(u,lam;v,mu) = a(u;v) − ∫ v lam − ∫ u mu − alpha S(u,lam;v,mu)
                L_h(v,mu)       = l(v) − ∫ psi mu − alpha lS(v,mu)
            ";
        }
    }

    fn string_meshes() -> Vec<IntervalMesh> {
        [16, 32, 64]
            .map(|n| IntervalMesh::uniform(0.0, 1.0, n).unwrap())
            .to_vec()
    }

    /// The one solve gives the same solution as the interval entry point it replaces,
    /// with α and s filled from the roles, and reports its integrals.
    #[test]
    fn the_interval_solve_agrees_with_solve_obstacle() {
        let (f, psi, zero) = (|_: &[f64]| -8.0, |_: &[f64]| -0.3, |_: &[f64]| 0.0);
        let solved = Problem::<string::Model, _>::new(string_meshes())
            .param(string::params::k, 1.0)
            .data(string::data::f, &f)
            .data(string::data::psi, &psi)
            .data(string::data::g, &zero)
            .boundary_data(DirichletPart::All)
            .alpha(Alpha::Fixed(0.1), 0.1)
            .solve()
            .unwrap();
        let c = Coefficients::new::<string::Model>(
            &[("alpha", 0.1), ("s", 1.0), ("k", 1.0)],
            &[("f", &f), ("psi", &psi), ("g", &zero)],
        )
        .unwrap();
        let mesh = string_meshes().pop().unwrap();
        let old =
            solve_obstacle::<string::Model>(&mesh, &c, &[], ObstacleOptions::default()).unwrap();
        for (a, b) in solved.solution.values.iter().zip(&old.values) {
            assert!((a - b).abs() <= 1e-12 * (1.0 + b.abs()), "{a} vs {b}");
        }
        let r = &solved.report;
        assert!((r.total_contact_force - old.total_contact_force()).abs() < 1e-12);
        assert!(r.total_contact_force > 0.0 && r.contact_length.unwrap() > 0.0);
        assert_eq!(r.levels.len(), 3);
        assert_eq!(solved.params, [0.1, 1.0, 1.0]);
        assert!(r.kkt_residual < 1e-10 && r.warnings.is_empty(), "{r:?}");
    }

    /// The obstacle above (`s = −1`): a string pushed up against ψ = 0.1 touches it, and
    /// the same problem mirrored (w ↦ −w) below gives the mirrored solution.
    #[test]
    fn the_side_turns_the_constraint() {
        fn up(_: &[f64]) -> f64 {
            8.0
        }
        fn down(_: &[f64]) -> f64 {
            -8.0
        }
        fn above(_: &[f64]) -> f64 {
            0.3
        }
        fn below(_: &[f64]) -> f64 {
            -0.3
        }
        let zero = |_: &[f64]| 0.0;
        let solve = |f: &'static DataFn, psi: &'static DataFn, side| {
            Problem::<string::Model, _>::new(string_meshes())
                .param(string::params::k, 0.0)
                .data(string::data::f, f)
                .data(string::data::psi, psi)
                .data(string::data::g, &zero)
                .boundary_data(DirichletPart::All)
                .side(side)
                .solve()
                .unwrap()
        };
        let a = solve(&up, &above, ObstacleSide::Above);
        let b = solve(&down, &below, ObstacleSide::Below);
        let (ua, ub) = (
            a.field(string::fields::u).unwrap(),
            b.field(string::fields::u).unwrap(),
        );
        for (x, y) in ua.iter().zip(ub) {
            assert!((x + y).abs() < 1e-12, "{x} vs {y}");
        }
        // the cell-wise constraint: at most the reported crossing, which is small
        let crossing = a.report.max_penetration.unwrap();
        assert!(crossing < 1e-2, "{crossing}");
        assert!(ua.iter().all(|&u| u <= 0.3 + crossing + 1e-12));
        assert!((a.report.total_contact_force - b.report.total_contact_force).abs() < 1e-12);
        assert_eq!(a.params[1], -1.0);
    }

    /// Pressed flat onto ψ = 0 = g: u = 0 and λ = 1 on every cell, the contact area the
    /// square's, the energy 0; the same as the triangle entry point.
    #[test]
    fn a_membrane_pressed_flat_touches_everywhere() {
        let (f, zero) = (|_: &[f64]| -1.0, |_: &[f64]| 0.0);
        let meshes = vec![
            TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 4, 4, Diagonal::Right).unwrap(),
            TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 8, 8, Diagonal::Right).unwrap(),
        ];
        let solved = Problem::<membrane::Model, _>::new(meshes.clone())
            .data(membrane::data::f, &f)
            .data(membrane::data::psi, &zero)
            .data(membrane::data::g, &zero)
            .boundary_data(DirichletPart::All)
            .solve()
            .unwrap();
        let r = &solved.report;
        assert!((r.total_contact_force - 1.0).abs() < 1e-10, "{r:?}");
        assert!((r.contact_area.unwrap() - 1.0).abs() < 1e-12);
        assert!(r.energy.unwrap().abs() < 1e-12);
        assert_eq!(r.alpha, Some(ALPHA_WHEN_CI_VANISHES));
        assert_eq!(r.inverse_constant, 0.0);
        assert!(r.mesh_quality.is_none() || r.warnings.is_empty());
        let c = Coefficients::new::<membrane::Model>(
            &[("alpha", ALPHA_WHEN_CI_VANISHES)],
            &[("f", &f), ("psi", &zero), ("g", &zero)],
        )
        .unwrap();
        let old =
            solve_obstacle_on_triangles::<membrane::Model>(&meshes, &c, ObstacleOptions::default())
                .unwrap();
        for (a, b) in solved.solution.values.iter().zip(&old.values) {
            assert!((a - b).abs() < 1e-12);
        }
    }

    /// What the solve refuses before any work, each naming its cause.
    #[test]
    fn refusals_name_their_cause() {
        let (f, psi, zero, bad) = (
            |_: &[f64]| -1.0,
            |_: &[f64]| 0.5,
            |_: &[f64]| 0.0,
            |x: &[f64]| 1.0 / x[0],
        );
        let base = || {
            Problem::<string::Model, _>::new(string_meshes())
                .param(string::params::k, 0.0)
                .data(string::data::f, &f)
                .data(string::data::g, &zero)
                .boundary_data(DirichletPart::All)
        };
        let error = |p: Problem<string::Model, IntervalMesh>| p.solve().err().unwrap().to_string();
        // the obstacle above the boundary data: nothing admissible
        let e = error(base().data(string::data::psi, &psi));
        assert!(e.contains("infeasible") && e.contains("ψ = 0.5"), "{e}");
        // a missing parameter, and the roles given as values
        let e = error(
            Problem::<string::Model, _>::new(string_meshes())
                .data(string::data::f, &f)
                .data(string::data::psi, &zero)
                .data(string::data::g, &zero),
        );
        assert!(e.contains("needs values for k"), "{e}");
        let e = error(base().data(string::data::psi, &zero).param("alpha", 0.3));
        assert!(e.contains("stabilization parameter"), "{e}");
        let e = error(base().data(string::data::psi, &zero).param("s", 1.0));
        assert!(e.contains("obstacle side"), "{e}");
        // data not finite where used
        let e = error(base().data(string::data::psi, &bad));
        assert!(e.contains("data `psi`") && e.contains("inf"), "{e}");
        // memory beyond what the machine allows
        let huge = MemoryModel::per_cell(1e20);
        let e = error(
            base()
                .data(string::data::psi, &zero)
                .memory(huge, "--elements 64"),
        );
        assert!(e.contains("--elements 64 needs about"), "{e}");
        // an unknown name from a reader
        let e = error(base().data(string::data::psi, &zero).param("kappa", 1.0));
        assert!(e.contains("no parameter `kappa`"), "{e}");
    }
}
