//! Solving a scene: one path for every family and pair. A [`Scene`] is bound to the
//! model of the chosen pair (its parameters and data by the model's declared names,
//! its supports by the fields' roles), meshed for the asked size, solved through the
//! runtime's one pipeline ([`fem_runtime::problem::Problem`]) and reported once
//! ([`Report`]); a family adds its own quantities through [`Quantities`].

use crate::data::Data;
use crate::family::Pair;
use crate::geometry::{Fields, Geometry};
pub use crate::report::{Outcome, Phases, Profile, Report, Schur, Settings, MAX_REFINEMENT_STEPS};
use crate::scene::{ExactSolution, Part, Posed, Scene, Support};
use fem_runtime::adaptivity::{AdaptiveOptions, BoundaryLayer};
use fem_runtime::lcp::NewtonOptions;
use fem_runtime::obstacle::{FirstStart, NearNullSpace, ObstacleOptions};
use fem_runtime::problem::memory::check_memory;
use fem_runtime::problem::{
    self, Condition, Exact, GradientFn, HessianFn, MemoryModel, Problem, SolveOptions, Solved,
};
use fem_runtime::stabilization::Alpha;
use fem_runtime::{
    CurvedTriangleMesh, DataFn, DataId, DirichletPart, Error, FieldId, Model, ParamId, Result,
    TriangleMesh,
};
use std::collections::BTreeMap;
use std::time::Instant;

/// What a family adds to the one solve: its own quantities, and where it must, its own
/// settings of the solve. Every method has a default, so a family with nothing of its
/// own implements nothing.
pub trait Quantities<G: Geometry>: 'static {
    /// The coarsest N of nested iteration.
    const COARSEST: usize = 4;

    /// What a scene's accuracy is compared with: a quantity the family reports (its key
    /// and its words for messages); `None`: the L² error of the constrained field.
    const ACCURACY_MEASURE: Option<(&'static str, &'static str)> = None;

    /// Whether the family's solves nest by default (each level started from the
    /// coarser one's solution).
    const NESTED: bool = true;

    /// Whether the rounding experiment runs by default.
    const ROUNDING_EXPERIMENT: bool = false;

    /// The complementarity solver's options.
    fn obstacle_options(settings: &Settings) -> ObstacleOptions {
        let defaults = ObstacleOptions::default();
        ObstacleOptions {
            solver: settings.solver,
            linear_solver: settings.linear_solver,
            newton: NewtonOptions {
                refinement_steps: settings
                    .refinement
                    .unwrap_or(defaults.newton.refinement_steps),
                ..defaults.newton
            },
            ..defaults
        }
    }

    /// The memory a solve of model `M` needs on `scene`'s domain at size `n`.
    fn memory<M: Model>(pair: &Pair, scene: &Scene, n: usize) -> MemoryModel {
        let _ = (scene, n);
        pair.memory.unwrap_or_else(MemoryModel::of_model::<M>)
    }

    /// Checks what the model cannot: the ranges of the family's parameters.
    ///
    /// # Errors
    /// A parameter out of its range, with the reason.
    fn check(scene: &Scene, posed: &Posed) -> Result<()> {
        let _ = (scene, posed);
        Ok(())
    }

    /// Checks what the model cannot on the finest mesh, before any solve: the data
    /// against the boundary parts (a contact load on the contact boundary).
    ///
    /// # Errors
    /// The first offending place, named.
    fn check_on_mesh(scene: &Scene, posed: &Posed, mesh: &G) -> Result<()> {
        let _ = (scene, posed, mesh);
        Ok(())
    }

    /// The start of the coarsest level, where the family has one (a body pressed onto
    /// its foundation); `None`: from zero.
    fn start(scene: &Scene, posed: &Posed) -> Option<Box<FirstStart<'static, G>>> {
        let _ = (scene, posed);
        None
    }

    /// The near null space of the family's operator without supports, for an external
    /// solver's algebraic multigrid (an elastic body's rigid motions); `None`: the
    /// solver's default (the constants).
    fn near_null_space() -> Option<Box<NearNullSpace<'static, G>>> {
        None
    }

    /// A boundary layer an adaptive solve of `scene` on `mesh` must resolve besides its
    /// tolerance (a quantity the scene asks for along the boundary varies across it);
    /// `None` by default.
    fn boundary_layer(scene: &Scene, posed: &Posed, mesh: &G) -> Option<BoundaryLayer> {
        let _ = (scene, posed, mesh);
        None
    }

    /// Adds the family's quantities and warnings to `report`.
    ///
    /// # Errors
    /// A quantity that cannot be evaluated.
    fn add<M: Model>(solved: &Run<'_, M, G>, report: &mut Report) -> Result<()> {
        let _ = (solved, report);
        Ok(())
    }

    /// The multiplier along its boundary part, where the family charts it.
    fn profile<M: Model>(run: &Run<'_, M, G>, report: &Report) -> Option<Profile> {
        let _ = (run, report);
        None
    }

    /// A solver's failure, explained where the family knows a likely cause (`alpha`:
    /// the α asked for, `cells`: of the finest mesh).
    fn explain(
        error: Error,
        pair: &Pair,
        posed: &Posed,
        alpha: Option<f64>,
        cells: usize,
    ) -> Error {
        let _ = (pair, posed, alpha, cells);
        error
    }
}

/// A finished solve, as a family's [`Quantities::add`] reads it.
pub struct Run<'r, M: Model, G: Geometry> {
    /// The scene solved.
    pub scene: &'r Scene,
    /// The values it was solved at.
    pub posed: &'r Posed,
    /// The request.
    pub settings: &'r Settings,
    /// The pair.
    pub pair: &'r Pair,
    /// The runtime's solution and report.
    pub solved: &'r Solved<M, G>,
    /// The obstacle as solved.
    pub psi: &'r DataFn,
    /// The solution's fields, sampled for output.
    pub fields: &'r Fields,
}

impl<M: Model, G: Geometry> Run<'_, M, G> {
    /// The constrained field (the model's `obstacle:` role; the first field otherwise).
    pub fn constrained_field(&self) -> usize {
        M::constrained_field()
    }

    /// The value of the constrained field at `x`, where `x` lies in the mesh.
    pub fn value_at(&self, x: &[f64]) -> Option<f64> {
        G::value_at(&self.solved.solution, self.constrained_field(), x)
    }
}

/// [`run`] on straight triangles, or on curved ones where the scene's disk is curved.
///
/// # Errors
/// Those of [`run`].
pub fn run_on_triangles<M, Q>(pair: &Pair, scene: &Scene, settings: &Settings) -> Result<Outcome>
where
    M: Model,
    Q: Quantities<TriangleMesh> + Quantities<CurvedTriangleMesh>,
{
    match scene.domain {
        crate::scene::Domain::Disk { curved: true, .. } => {
            run::<M, CurvedTriangleMesh, Q>(pair, scene, settings)
        }
        _ => run::<M, TriangleMesh, Q>(pair, scene, settings),
    }
}

/// Solves `scene` with model `M` (the pair `pair`) on meshes of kind `G`, the family's
/// quantities from `Q`.
///
/// # Errors
/// Invalid settings, a parameter, data function or boundary part the model or mesh does
/// not have, the memory estimate beyond what the machine allows, and the runtime's
/// refusals and failures.
pub fn run<M: Model, G: Geometry, Q: Quantities<G>>(
    pair: &Pair,
    scene: &Scene,
    settings: &Settings,
) -> Result<Outcome> {
    let clock = Instant::now();
    let posed = pose_checked::<G, Q>(scene, settings)?;
    let Levels {
        meshes,
        domain,
        n,
        memory,
        size_text,
        nested,
    } = levels::<M, G, Q>(pair, scene, settings, &posed)?;
    let finest = meshes.last().expect("at least one level").clone();
    let meshes_seconds = clock.elapsed().as_secs_f64();

    let bound = bind::<M>(scene, pair, &posed)?;
    let supports = supports::<M, G>(scene, &finest)?;
    let exact = scene.exact_at(&posed);
    // the runtime measures errors of the constrained field (and of a cell multiplier
    // beside it): without the field's value there is nothing for it to measure (a
    // multiplier on facets, contact's pressure on Γ_C, is measured by its family)
    let exact_fns = exact
        .as_ref()
        .filter(|e| e.value.is_some())
        .map(ExactFns::new);
    if let Some(e) = &exact {
        validate_exact(e, &finest, scene)?;
    }
    Q::check_on_mesh(scene, &posed, &finest)?;
    let start = Q::start(scene, &posed);
    let psi_index = M::OBSTACLE.map(|[_, d]| d);
    let psi: &DataFn = psi_index
        .and_then(|d| bound.data.iter().find(|(k, _)| *k == d))
        .map_or(&zero, |(_, f)| &**f);
    let checks_seconds = clock.elapsed().as_secs_f64() - meshes_seconds;

    let alpha = settings.alpha.map_or(pair.alpha, Alpha::Fixed);
    let mut problem = Problem::<M, G>::new(meshes)
        .side(scene.side)
        .alpha(alpha, pair.alpha_when_zero)
        .options(SolveOptions {
            obstacle: Q::obstacle_options(settings),
            nested,
            rounding_experiment: settings
                .rounding_experiment
                .unwrap_or(Q::ROUNDING_EXPERIMENT),
        })
        .memory(memory, size_text.clone());
    problem = posed_on(problem, &bound, &supports, scene, &finest)?;
    if let Some(start) = &start {
        problem = problem.start(&**start);
    }
    let near_null_space = Q::near_null_space();
    if let Some(space) = &near_null_space {
        problem = problem.near_null_space(&**space);
    }
    if let Some(fns) = &exact_fns {
        problem = problem.exact(fns.exact());
    }
    let cells = finest.cell_count();
    let adaptive = settings.adaptive.clone().or_else(|| {
        scene.tolerance.map(|tolerance| AdaptiveOptions {
            tolerance,
            ..AdaptiveOptions::default()
        })
    });
    let adaptive = adaptive.map(|mut options| {
        if options.boundary_layer.is_none() {
            options.boundary_layer = Q::boundary_layer(scene, &posed, &finest);
        }
        options
    });
    let solved = match adaptive {
        Some(options) => problem.solve_adaptive(options, |level| {
            if let Some(progress) = &settings.progress {
                (progress.0)(level);
            }
        }),
        None => problem.solve(),
    }
    .map_err(|e| {
        Q::explain(
            scene_field_of(e, scene),
            pair,
            &posed,
            settings.alpha,
            cells,
        )
    })?;
    let solve_seconds = clock.elapsed().as_secs_f64() - meshes_seconds - checks_seconds;

    let mut report = report_of(scene, pair, &domain, n, &posed, exact.as_ref(), &solved);
    report.solve.warnings.extend(supports.warnings);
    warn_defaulted::<M>(scene, &bound, &mut report);
    let mut fields = G::fields::<M>(&solved.solution, psi);
    if let (Some(estimate), Fields::Triangles { cell, .. }) = (&solved.estimate, &mut fields) {
        cell.push(("indicator", estimate.indicators.clone()));
    }
    let run = Run {
        scene,
        posed: &posed,
        settings,
        pair,
        solved: &solved,
        psi,
        fields: &fields,
    };
    Q::add(&run, &mut report)?;
    common_warnings(scene, &posed, Q::ACCURACY_MEASURE, &mut report);
    let profile = Q::profile(&run, &report);
    report.phases = phases(
        [meshes_seconds, checks_seconds, solve_seconds],
        report.solve.seconds,
        clock.elapsed().as_secs_f64(),
    );
    let schur = match (settings.schur, M::SYSTEM.is_some()) {
        (true, true) => Some(schur_of(&solved, report.solve.alpha)?),
        _ => None,
    };
    let solution = settings.keep_solution.then(|| crate::report::KeptSolution {
        fields: M::FIELDS.iter().map(|f| f.name).collect(),
        solution: std::sync::Arc::new(solved.solution),
    });
    Ok(Outcome {
        report,
        fields,
        profile,
        schur,
        solution,
    })
}

/// The phases of a solve from the wall time taken by the meshes, the checks and the
/// whole runtime solve (`[meshes, checks, solve]`), the runtime's own solve time
/// `runtime` and the `total`: what the runtime spent outside its solve (assembly of the
/// report) counts as evaluation, with the family's quantities and the fields.
fn phases([meshes, checks, solve]: [f64; 3], runtime: f64, total: f64) -> Phases {
    Phases {
        meshes,
        checks,
        solve: runtime,
        evaluation: (total - meshes - checks - solve).max(0.0) + (solve - runtime).max(0.0),
    }
}

/// The multiplier's Schur complement of the finest mesh, and the stabilization's
/// diagonal over α as the multipliers' norm where α > 0.
///
/// # Errors
/// [`fem_runtime::lcp::Lcp::schur_complement`]'s.
fn schur_of<M: Model, G: Geometry>(solved: &Solved<M, G>, alpha: Option<f64>) -> Result<Schur> {
    let lcp = &solved.solution.discretization.lcp;
    let norm = alpha
        .filter(|a| *a > 0.0)
        .map(|a| lcp.c.iter().map(|c| c / a).collect());
    Ok(Schur {
        matrix: lcp.schur_complement()?,
        norm,
    })
}

/// The meshes of a solve and what sets them: the levels (coarsest first), the domain as
/// solved (with the request's diagonal), N, the memory model and the words for its
/// refusal, and whether the solve nests.
struct Levels<G> {
    meshes: Vec<G>,
    domain: crate::scene::Domain,
    n: usize,
    memory: MemoryModel,
    size_text: String,
    nested: bool,
}

/// The [`Levels`] of `scene` as `settings` ask, the memory estimated before any mesh is
/// built.
///
/// # Errors
/// The memory estimate's refusal and the mesh generators'.
fn levels<M: Model, G: Geometry, Q: Quantities<G>>(
    pair: &Pair,
    scene: &Scene,
    settings: &Settings,
    posed: &Posed,
) -> Result<Levels<G>> {
    let n = settings.mesh_size.unwrap_or(scene.mesh_size);
    let memory = Q::memory::<M>(pair, scene, n);
    let size_text = size_text(scene, pair, n, settings.mesh_size.is_some());
    // without an obstacle the problem is one linear solve: nothing to nest for
    let nested = Q::NESTED && settings.nested && settings.solver.nests() && scene.obstacle;
    let mut domain = scene.domain.clone();
    if let (Some(diagonal), crate::scene::Domain::Rectangle { diagonal: d, .. }) =
        (settings.diagonal, &mut domain)
    {
        *d = diagonal;
    }
    let budget = |cells: f64| check_memory(memory.bytes(cells as usize), &size_text);
    let meshes = G::levels(&domain, n, nested, Q::COARSEST, posed.load, &budget)?;
    Ok(Levels {
        meshes,
        domain,
        n,
        memory,
        size_text,
        nested,
    })
}

/// The obstacle and the load are what a scene poses: left out (taken as 0), they are
/// named in the report.
fn warn_defaulted<M: Model>(scene: &Scene, bound: &Bound, report: &mut Report) {
    let psi_index = M::OBSTACLE.map(|[_, d]| d);
    for &d in &bound.defaulted {
        let obstacle = psi_index == Some(d) && scene.obstacle;
        if obstacle || M::DATA[d] == "f" {
            report.warn(format!(
                "scene `{}` gives no {} `{}`: it is taken as 0",
                scene.name,
                if obstacle { "obstacle" } else { "load" },
                M::DATA[d]
            ));
        }
    }
}

/// The values a request solves the scene at ([`pose`]), checked by the family
/// ([`Quantities::check`]: it names a parameter as its users know it) and for finite
/// parameters.
///
/// # Errors
/// Those of [`pose`] and the family's check; a parameter that is not finite.
fn pose_checked<G: Geometry, Q: Quantities<G>>(
    scene: &Scene,
    settings: &Settings,
) -> Result<Posed> {
    let posed = pose(scene, settings)?;
    Q::check(scene, &posed)?;
    for (name, value) in &posed.parameters {
        if !value.is_finite() {
            return Err(Error::Input(format!(
                "scene `{}`: parameter `{name}` = {value} is not finite",
                scene.name
            )));
        }
    }
    Ok(posed)
}

/// `problem` with the scene as bound to the model: its parameters and data, the
/// supports as conditions, the boundary data's parts, the facet parts on `finest`, and
/// the unconstrained problem where the scene has no obstacle.
///
/// # Errors
/// A facet part the mesh does not have.
fn posed_on<'a, M: Model, G: Geometry>(
    mut problem: Problem<'a, M, G>,
    bound: &'a Bound,
    supports: &Supports,
    scene: &Scene,
    finest: &G,
) -> Result<Problem<'a, M, G>> {
    for &(p, value) in &bound.params {
        problem = problem.param(ParamId::<M>::new(p), value);
    }
    let psi_index = M::OBSTACLE.map(|[_, d]| d);
    let nodal = M::SYSTEM.is_none();
    for (d, f) in &bound.data {
        // the nodal method takes its obstacle at the nodes
        if nodal && Some(*d) == psi_index {
            problem = problem.nodal(&**f);
        }
        problem = problem.data(DataId::<M>::new(*d), &**f);
    }
    for (part, field, condition) in &supports.conditions {
        problem = problem.support(part.clone(), FieldId::<M>::new(*field), *condition);
    }
    for part in &supports.data {
        problem = problem.boundary_data(part.clone());
    }
    for (name, part) in &scene.facets {
        let markers = match finest.part(part)? {
            DirichletPart::Markers(m) => m,
            DirichletPart::All => Vec::new(),
        };
        problem = problem.part(&**name, markers);
    }
    if !scene.obstacle {
        problem = problem.unconstrained();
    }
    Ok(problem)
}

/// The report of a solved scene before the family's quantities: what was posed, the
/// runtime's report and the exact integrals where known.
fn report_of<M: Model, G: Geometry>(
    scene: &Scene,
    pair: &Pair,
    domain: &crate::scene::Domain,
    n: usize,
    posed: &Posed,
    exact: Option<&ExactSolution>,
    solved: &Solved<M, G>,
) -> Report {
    Report {
        scene: scene.name.to_string(),
        family: scene.family,
        pair: pair.name,
        domain: domain.describe(),
        mesh_size: n,
        load: posed.load,
        parameters: posed
            .parameters
            .iter()
            .map(|(k, v)| (k.to_string(), *v))
            .collect(),
        supports: scene
            .supports
            .iter()
            .map(|s| format!("{} on {}", s.support.name(), s.part.names().join(", ")))
            .collect(),
        solve: solved.report.clone(),
        exact_contact_force: exact.and_then(|e| e.total_contact_force),
        exact_contact_area: exact.and_then(|e| e.contact_area),
        accuracy: scene.accuracy,
        phases: Phases::default(),
        quantities: BTreeMap::new(),
    }
}

fn zero(_: &[f64]) -> f64 {
    0.0
}

/// The values a request solves the scene at: its load and every parameter (the scene's,
/// replaced by the request's).
///
/// # Errors
/// A load the scene refuses (see [`Scene::load_magnitude`]), a refinement count out of
/// range, and a parameter that is not finite.
pub fn pose(scene: &Scene, settings: &Settings) -> Result<Posed> {
    let load = scene.load_magnitude(settings.load).map_err(Error::Input)?;
    if let Some(r) = settings.refinement {
        if r > MAX_REFINEMENT_STEPS {
            return Err(Error::Input(format!(
                "--refinement {r} is out of range (0 to {MAX_REFINEMENT_STEPS}): each round is one more solve, and 2 or 3 already reach rounding"
            )));
        }
    }
    let mut parameters = scene.parameters.clone();
    for (name, value) in &settings.parameters {
        match parameters.iter_mut().find(|(n, _)| n == name) {
            Some(entry) => entry.1 = *value,
            None => parameters.push((name.clone(), *value)),
        }
    }
    Ok(Posed { load, parameters })
}

/// What sets the size, for the memory refusal's message: the option where the request
/// gives it, else the scene's own (a scene file's key).
fn size_text(scene: &Scene, pair: &Pair, n: usize, given: bool) -> String {
    use crate::scene::Domain;
    let refined = match &scene.domain {
        Domain::Gmsh(path) => Some(path.display().to_string()),
        Domain::Refined { description, .. } => Some(format!("the {description}")),
        _ => None,
    };
    let option = match (&scene.domain, given) {
        (Domain::Interval { .. }, true) => format!("--elements {n}"),
        (Domain::Interval { .. }, false) => format!("the scene's {n} elements"),
        (_, true) => format!("--mesh-size {n}"),
        (_, false) if refined.is_some() => format!("the scene's mesh.refinements = {n}"),
        (_, false) => format!("the scene's mesh size {n}"),
    };
    match refined {
        Some(mesh) => format!(
            "{option} ({n} uniform refinements of {mesh}, 4^{n} times its triangles) with {}",
            pair.name
        ),
        None => format!("{option} with {}", pair.name),
    }
}

/// A scene bound to model `M`: parameter and data indices with their values.
struct Bound {
    params: Vec<(usize, f64)>,
    data: Vec<(usize, Box<DataFn>)>,
    /// The model's data the scene leaves out (taken as 0).
    defaulted: Vec<usize>,
}

/// Binds the scene's parameters and data to model `M` by name; the data `--load` scales
/// are multiplied by q. The one place a scene's names meet the model's.
fn bind<M: Model>(scene: &Scene, pair: &Pair, posed: &Posed) -> Result<Bound> {
    let unknown = |kind: &str, name: &str, names: Vec<&str>| {
        Error::Input(format!(
            "scene `{}`: {kind} `{name}` is not one of model `{}`'s ({})",
            scene.name,
            M::NAME,
            names.join(", ")
        ))
    };
    let mut params = Vec::new();
    for (name, value) in &posed.parameters {
        let p = M::PARAMS
            .iter()
            .position(|p| *p == &**name)
            .ok_or_else(|| {
                // and those of the richer model the scene may state (a Kirchhoff plate's t)
                let richer = crate::families::family(scene.family)
                    .map_or(&[][..], |f| f.richer_parameters());
                unknown("parameter", name, [M::PARAMS, richer].concat())
            })?;
        params.push((p, *value));
    }
    for &(name, value) in pair.parameters {
        let p = M::PARAMS
            .iter()
            .position(|p| *p == name)
            .ok_or_else(|| unknown("parameter", name, M::PARAMS.to_vec()))?;
        if !params.iter().any(|(k, _)| *k == p) {
            params.push((p, value));
        }
    }
    let mut data: Vec<(usize, Box<DataFn>)> = Vec::new();
    for (name, f) in &scene.data {
        let d = M::DATA
            .iter()
            .position(|d| *d == &**name)
            .ok_or_else(|| unknown("data function", name, M::DATA.to_vec()))?;
        let scaled = scene
            .load
            .as_ref()
            .is_some_and(|l| l.scales.iter().any(|s| s == name));
        let f = f.clone();
        let function: Box<DataFn> = match (scaled, posed.load) {
            (true, Some(q)) => Box::new(move |x: &[f64]| q * f.at(x)),
            _ => Box::new(move |x: &[f64]| f.at(x)),
        };
        data.push((d, function));
    }
    // a model's data the scene leaves out is 0 (a boundary value g on a clamped plate)
    let mut defaulted = Vec::new();
    for d in 0..M::DATA.len() {
        if !data.iter().any(|(k, _)| *k == d) {
            data.push((d, Box::new(zero)));
            defaulted.push(d);
        }
    }
    Ok(Bound {
        params,
        data,
        defaulted,
    })
}

/// The runtime's supports of a scene on one mesh.
struct Supports {
    conditions: Vec<(DirichletPart, usize, Condition)>,
    data: Vec<DirichletPart>,
    warnings: Vec<String>,
}

/// The scene's supports as conditions on model `M`'s fields, by their roles (see
/// [`Support`]).
fn supports<M: Model, G: Geometry>(scene: &Scene, mesh: &G) -> Result<Supports> {
    let mut out = Supports {
        conditions: Vec::new(),
        data: Vec::new(),
        warnings: Vec::new(),
    };
    let multiplier = (0..M::FIELDS.len()).find(|&f| M::FIELDS[f].nonnegative);
    let primal: Vec<usize> = (0..M::FIELDS.len())
        .filter(|&f| Some(f) != multiplier)
        .collect();
    let at = |message: String, support: &crate::scene::PartSupport| {
        Error::Input(match &support.key {
            Some(key) => format!("scene `{}`: field `{key}`: {message}", scene.name),
            None => format!(
                "scene `{}`: support on {}: {message}",
                scene.name,
                support.part.names().join(", ")
            ),
        })
    };
    // `all` is the keyword for the whole boundary: a mesh with a part of that name would
    // make `all` and `["all"]` mean different sets under one printed name
    if !scene.supports.is_empty() && mesh.part_markers(&["all"]).is_ok() {
        return Err(Error::Input(format!(
            "scene `{}`: the mesh ({}) has a boundary part named `all`, which is the keyword for the whole boundary (and its default where a scene names no part): rename the Gmsh physical group (e.g. Physical Curve(\"outer\")) so that the choice is unambiguous",
            scene.name,
            scene.domain.describe()
        )));
    }
    for s in &scene.supports {
        let part = mesh.part(&s.part).map_err(|e| match e {
            Error::Input(m) => at(format!("{m}, on the {}", scene.domain.describe()), s),
            other => other,
        })?;
        if let Part::Named(names) = &s.part {
            let warnings = mesh.interior_part_warnings(names).into_iter();
            out.warnings.extend(warnings.map(|w| match &s.key {
                Some(key) => format!("field `{key}`: {w}"),
                None => w,
            }));
        }
        match s.support {
            Support::Free => {}
            Support::Data => out.data.push(part),
            Support::Clamped => {
                for &f in &primal {
                    out.conditions.push((part.clone(), f, Condition::Clamped));
                }
            }
            Support::SimplySupported { hard } => {
                let [w, _] = M::OBSTACLE.ok_or_else(|| {
                    at(
                        format!(
                            "a simple support holds the constrained field, and model `{}` declares none (its `obstacle:` role)",
                            M::NAME
                        ),
                        s,
                    )
                })?;
                out.conditions.push((part.clone(), w, Condition::Zero));
                if hard {
                    for [x, _] in vector_fields::<M>(&primal) {
                        out.conditions
                            .push((part.clone(), x, Condition::Tangential));
                    }
                }
            }
            Support::Roller { normal } => {
                let vectors = vector_fields::<M>(&primal);
                let [[x, y]] = vectors.as_slice() else {
                    return Err(at(
                        format!(
                            "a roller holds a displacement, and model `{}` has {} vector fields",
                            M::NAME,
                            vectors.len()
                        ),
                        s,
                    ));
                };
                let length = normal[0].hypot(normal[1]);
                if !(length.is_finite() && length > 0.0) {
                    return Err(at(
                        format!("the roller's direction {normal:?} is not a direction"),
                        s,
                    ));
                }
                let n = [normal[0] / length, normal[1] / length];
                let condition = if n[1] == 0.0 {
                    (*x, Condition::Zero)
                } else if n[0] == 0.0 {
                    (*y, Condition::Zero)
                } else {
                    (*x, Condition::Along(n))
                };
                out.conditions.push((part, condition.0, condition.1));
            }
        }
    }
    Ok(out)
}

/// The vector fields among `primal`: pairs of component fields `stem_x`, `stem_y`.
fn vector_fields<M: Model>(primal: &[usize]) -> Vec<[usize; 2]> {
    primal
        .iter()
        .filter_map(|&f| {
            let stem = M::FIELDS[f].name.strip_suffix("_x")?;
            let y = primal
                .iter()
                .copied()
                .find(|&g| M::FIELDS[g].name.strip_suffix("_y") == Some(stem))?;
            Some([f, y])
        })
        .collect()
}

/// The exact solution's functions in the runtime's types.
struct ExactFns {
    value: Option<Data>,
    gradient: Option<Data<[f64; 2]>>,
    hessian: Option<Data<[[f64; 2]; 2]>>,
    multiplier: Option<Data>,
}

impl ExactFns {
    fn new(e: &ExactSolution) -> Self {
        Self {
            value: e.value.clone(),
            gradient: e.gradient.clone(),
            hessian: e.hessian.clone(),
            multiplier: e.multiplier.clone(),
        }
    }

    fn exact(&self) -> Exact<'_> {
        Exact {
            value: self.value.as_ref().map_or(&nan, Data::as_data_fn),
            gradient: self.gradient.as_ref().map(|g| g.as_fn() as &GradientFn),
            hessian: self.hessian.as_ref().map(|h| h.as_fn() as &HessianFn),
            multiplier: self.multiplier.as_ref().map(Data::as_data_fn),
        }
    }
}

fn nan(_: &[f64]) -> f64 {
    f64::NAN
}

/// Refuses an exact solution no obstacle problem can have on `mesh`: a multiplier below
/// 0 at a vertex, or a contact area beyond the domain's.
fn validate_exact<G: Geometry>(exact: &ExactSolution, mesh: &G, scene: &Scene) -> Result<()> {
    if let Some(lambda) = &exact.multiplier {
        let points = mesh.vertex_points();
        let values: Vec<f64> = points.iter().map(|x| lambda.at(x)).collect();
        // not-a-number values are left to the report, which says the error cannot be
        // measured
        let largest = values
            .iter()
            .filter(|v| v.is_finite())
            .fold(0.0f64, |m, v| m.max(v.abs()));
        if let Some((x, v)) = points
            .iter()
            .zip(&values)
            .find(|(_, &v)| v < -1e-12 * largest)
        {
            let at: Vec<String> = x.iter().map(|c| c.to_string()).collect();
            return Err(Error::Input(format!(
                "scene `{}`: field `{}`: λ = {} at ({}); the multiplier of the constraint is a pressure, ≥ 0",
                scene.name,
                exact.multiplier_key.unwrap_or("exact.lambda"),
                problem::number(*v),
                at.join(", ")
            )));
        }
    }
    if let Some(area) = exact.contact_area {
        let domain = mesh.total_measure();
        if area > domain * (1.0 + 1e-9) {
            return Err(Error::Input(format!(
                "scene `{}`: field `exact.contact_area`: {} exceeds the domain's area {domain}",
                scene.name,
                problem::number(area)
            )));
        }
    }
    Ok(())
}

/// The warnings every scene may earn: an exact solution that does not hold at the load
/// asked, and an accuracy the solve does not reach or cannot check.
fn common_warnings(
    scene: &Scene,
    posed: &Posed,
    measure: Option<(&str, &str)>,
    report: &mut Report,
) {
    if scene.exact_dropped_at(posed) {
        let own = scene.load.as_ref().map(|l| l.default);
        report.warn(format!(
            "the scene's exact solution holds at its own load q = {}; under --load {} it is not compared (the contact set is not linear in the load)",
            own.map_or("?".into(), problem::number),
            posed.load.map_or("?".into(), problem::number)
        ));
    }
    if let Some(accuracy) = scene.accuracy {
        let (error, words) = match measure {
            Some((key, words)) => (report.number(key), words),
            None => (report.solve.error_l2, "L² error"),
        };
        match error {
            Some(e) if e > accuracy => report.warn(format!(
                "the {words} {e:.3e} exceeds the accuracy the scene asks for, {accuracy:e}: refine (--mesh-size) or take a pair of higher order"
            )),
            Some(_) => {}
            None => report.warn(format!(
                "the accuracy {accuracy:e} the scene asks for is not checked: there is no exact solution to measure the error against here"
            )),
        }
    }
}

/// A runtime error about a data function, with the scene named: "data `ψ` of
/// `membrane_p2_p0` is inf at (1, 0)" becomes "scene `radial`: field `data.psi`: data
/// `ψ` …" (the scene file's key of the function).
fn scene_field_of(error: Error, scene: &Scene) -> Error {
    let Error::Input(message) = error else {
        return error;
    };
    let key = scene
        .data
        .iter()
        .map(|(name, _)| name)
        .find(|name| message.starts_with(&format!("data `{name}` of ")))
        .map(|name| scene.file_key(name));
    match key {
        Some(key) => Error::Input(format!(
            "scene `{}`: field `data.{key}`: {message}",
            scene.name
        )),
        None => Error::Input(message),
    }
}
