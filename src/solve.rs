//! `fem-forms solve`: a scene (built-in or from a file) with the command line's options,
//! through the registry's one path ([`fem_forms::models::choice::solve`]), printed as a
//! summary or as JSON, with its chart or ParaView file where asked.

use crate::backend::{Backend, BackendOptions};
use crate::{SolveOptions, SolverName};
use fem_forms::adaptivity::{AdaptiveLevel, AdaptiveOptions, Marking};
use fem_forms::models::families;
use fem_forms::models::family::Opt;
use fem_forms::models::geometry::Fields;
use fem_forms::models::report::{Outcome, Profile, Progress, Report, Settings};
use fem_forms::models::scene::Adjustment;
use fem_forms::models::scene::{Scene, Support};
use fem_forms::obstacle::hierarchy::LinearSolver;
use fem_forms::obstacle::VariationalSolver;
use fem_forms::plot;
use std::path::{Path, PathBuf};

impl SolveOptions {
    /// The given options (flag spellings).
    pub fn given_options(&self) -> Vec<Opt> {
        let flags = [
            (self.elements.is_some(), Opt::Elements),
            (self.mesh_size.is_some(), Opt::MeshSize),
            (self.vtk, Opt::Vtk),
            (self.msh.is_some(), Opt::Msh),
            (self.load.is_some(), Opt::Load),
            (self.thickness.is_some(), Opt::Thickness),
            (self.alpha.is_some(), Opt::Alpha),
            (self.pair.is_some(), Opt::Pair),
            (self.solver.is_some(), Opt::Solver),
            (self.cold, Opt::Cold),
            (self.linear_solver.is_some(), Opt::LinearSolver),
            (self.refinement.is_some(), Opt::Refinement),
            (self.plot, Opt::Plot),
            (self.support.is_some(), Opt::Support),
            (self.obstacle.is_some(), Opt::Obstacle),
            (self.no_obstacle, Opt::NoObstacle),
            (self.tol.is_some(), Opt::Tol),
            (self.marking.is_some(), Opt::Marking),
            (self.theta.is_some(), Opt::Theta),
            (self.edge_resultants, Opt::EdgeResultants),
        ];
        flags
            .into_iter()
            .filter(|(given, _)| *given)
            .map(|(_, o)| o)
            .collect()
    }

    /// The backend's options (`--backend`, `--petsc-options`, `--petsc-formulation`).
    pub fn backend_options(&self) -> BackendOptions {
        BackendOptions {
            backend: self.backend.clone(),
            petsc_options: self.petsc_options.clone(),
            petsc_formulation: self.petsc_formulation.clone(),
        }
    }

    /// An error naming the first given option of `not_applicable`, with `why`.
    fn refuse_options(&self, not_applicable: &[Opt], why: &str) -> Result<(), String> {
        match self
            .given_options()
            .into_iter()
            .find(|o| not_applicable.contains(o))
        {
            Some(option) => Err(format!("{} does not apply: {why}", option.flag())),
            None => Ok(()),
        }
    }
}

/// The options of its family that a scene has no use for, each with the reason.
fn unused(scene: &Scene, options: &[Opt]) -> Vec<(Opt, String)> {
    let name = &scene.name;
    options
        .iter()
        .filter_map(|&o| {
            let why = match o {
                Opt::Load if scene.load.is_none() => {
                    format!("the load of `{name}` is fixed (not a scaled field)")
                }
                Opt::Thickness
                    if scene.parameter("t").is_none()
                        && !families::family(scene.family)
                            .is_some_and(|f| f.richer_parameters().contains(&"t")) =>
                {
                    format!("`{name}` has no thickness t")
                }
                Opt::NoObstacle if !scene.obstacle => format!("`{name}` has no obstacle"),
                Opt::Alpha | Opt::Cold if !scene.obstacle => format!(
                    "`{name}` is solved without an obstacle (one linear solve); α and the nested start concern contact"
                ),
                _ => return None,
            };
            Some((o, why))
        })
        .collect()
}

/// The settings of a solve from the command line's options.
fn settings(options: &SolveOptions) -> Result<Settings, String> {
    let linear_solver = options
        .linear_solver
        .as_deref()
        .map_or(Ok(LinearSolver::Auto), LinearSolver::parse)
        .map_err(|e| format!("--linear-solver: {e}"))?;
    let mut parameters = Vec::new();
    if let Some(t) = options.thickness {
        parameters.push(("t".into(), t));
    }
    Ok(Settings {
        adaptive: adaptive_options(options)?,
        pair: options.pair.clone(),
        mesh_size: options.elements.or(options.mesh_size),
        load: options.load,
        alpha: options.alpha,
        parameters,
        solver: match options.solver.unwrap_or(SolverName::Pdas) {
            SolverName::Pdas => VariationalSolver::SemismoothNewton,
            SolverName::Clarabel => VariationalSolver::Clarabel,
        },
        linear_solver,
        nested: !options.cold,
        refinement: options.refinement,
        ..Settings::default()
    })
}

/// The adaptive loop's options from `--tol`, `--marking` and `--theta`.
fn adaptive_options(options: &SolveOptions) -> Result<Option<AdaptiveOptions>, String> {
    let theta = options.theta.unwrap_or(0.5);
    if !(theta > 0.0 && theta <= 1.0) {
        return Err(format!(
            "--theta {theta}: the marking parameter θ must lie in (0, 1]"
        ));
    }
    let marking = match options.marking.as_deref() {
        None | Some("dorfler") => Marking::Dorfler(theta),
        Some("max") => Marking::Maximum(theta),
        Some(other) => {
            return Err(format!(
                "--marking {other}: the markings are dorfler (Dörfler's bulk criterion) and max (every cell with η_T ≥ θ max η)"
            ))
        }
    };
    let Some(tolerance) = options.tol else {
        if options.marking.is_some() || options.theta.is_some() || options.max_dofs.is_some() {
            return Err("--marking, --theta and --max-dofs set the adaptive loop: give --tol T to solve adaptively".into());
        }
        return Ok(None);
    };
    if !(tolerance > 0.0 && tolerance < 1.0) {
        return Err(format!(
            "--tol {tolerance}: the tolerance is a relative error of the solution's energy norm, in (0, 1) (e.g. 1e-2)"
        ));
    }
    let max_dofs = match options.max_dofs {
        Some(0) => {
            return Err("--max-dofs 0: the limit on a level's unknowns must be positive".into())
        }
        Some(n) => n,
        None => AdaptiveOptions::default().max_dofs,
    };
    Ok(Some(AdaptiveOptions {
        tolerance,
        marking,
        max_dofs,
        ..AdaptiveOptions::default()
    }))
}

/// A progress bar on standard error for the levels of an adaptive solve (hidden where
/// standard error is not a terminal).
fn adaptive_progress() -> (Progress, indicatif::ProgressBar) {
    let bar = indicatif::ProgressBar::new_spinner();
    bar.set_style(
        indicatif::ProgressStyle::with_template("{spinner} {elapsed_precise} {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_spinner()),
    );
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    let shown = bar.clone();
    let level = std::sync::atomic::AtomicUsize::new(0);
    let progress = Progress(std::sync::Arc::new(move |l: &AdaptiveLevel| {
        let k = level.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
        shown.set_message(format!(
            "level {k}: {} cells, {} unknowns, estimate {:.3e} ({:.2e} of ‖u_h‖_a), {:.2} s",
            l.cells,
            l.dofs,
            l.estimate,
            l.estimate / l.energy_norm,
            l.seconds
        ));
    }));
    (progress, bar)
}

/// Solves `scene` as `options` ask and prints the result.
pub fn solve_scene(mut scene: Scene, options: &SolveOptions, out: &Path) -> Result<(), String> {
    let family = families::family(scene.family)
        .ok_or_else(|| format!("scene `{}` names no known family", scene.name))?;
    let unused = unused(&scene, family.options());
    let list: Vec<&str> = family
        .options()
        .iter()
        .filter(|o| !unused.iter().any(|(u, _)| u == *o))
        .map(|o| o.flag())
        .chain(["--json"])
        .collect();
    let foreign: Vec<Opt> = Opt::ALL
        .into_iter()
        .filter(|o| !family.options().contains(o))
        .collect();
    options.refuse_options(
        &foreign,
        &format!(
            "`{}` is a {} scene on the {} ({})",
            scene.name,
            family.name(),
            scene.domain.describe(),
            list.join(", ")
        ),
    )?;
    for (option, why) in unused {
        options.refuse_options(&[option], &why)?;
    }
    // a Kirchhoff plate's thickness poses its richer neighbour, whose pairs it then takes
    if let Some(t) = options.thickness {
        if family.richer_parameters().contains(&"t") {
            scene.set_richer_parameter("t", t);
        }
    }
    // a pair of a neighbour model of the scene solves that model (choice::solve), which
    // takes its own family's options
    let pair = match families::pair_of(&scene, options.pair.as_deref()) {
        Ok(pair) => pair,
        Err(e) => {
            let name = options.pair.as_deref().unwrap_or_default();
            let neighbour = fem_forms::models::choice::neighbour_of(&scene, name)
                .ok_or_else(|| e.to_string())?;
            if let Some(other) = families::family(neighbour.family) {
                let foreign: Vec<Opt> = Opt::ALL
                    .into_iter()
                    // the scene's own family applies these before posing the neighbour
                    .filter(|o| {
                        !other.options().contains(o)
                            && ![Opt::Thickness, Opt::Obstacle, Opt::Support].contains(o)
                    })
                    .collect();
                options.refuse_options(
                    &foreign,
                    &format!(
                        "pair {name} solves the {} model ({} family)",
                        other.model_words(&neighbour),
                        other.name()
                    ),
                )?;
            }
            fem_forms::models::choice::neighbour_pair(&scene, name).ok_or_else(|| e.to_string())?
        }
    };
    if pair.nodal {
        options.refuse_options(
            &[Opt::Alpha, Opt::Solver],
            &format!(
                "{} has no multiplier to stabilize and solves its nodal constraints by its own active-set method",
                pair.name
            ),
        )?;
    }
    if options.cold && options.solver == Some(SolverName::Clarabel) {
        // every family hands clarabel the finest level alone: there is no nested start
        // to turn off, and an accepted flag that changes nothing misleads
        return Err(
            "--cold does not apply with --solver clarabel: the QP solver solves the finest mesh alone, with no nested start to turn off".into(),
        );
    }
    if options.alpha == Some(0.0) {
        options.refuse_options(
            &[Opt::Cold],
            "α = 0 (the plain mixed method) is solved by clarabel on the finest mesh alone, with no nested start to turn off",
        )?;
        if options.solver == Some(SolverName::Pdas) {
            return Err("--solver pdas does not apply with α = 0: the plain mixed method has C = 0, which leaves semismooth Newton nothing to eliminate the multiplier with; it is solved by clarabel".into());
        }
    }
    if options.edge_resultants {
        scene.edge_resultants = true;
    }
    if let Some(name) = &options.support {
        let support = Support::parse(name).ok_or_else(|| {
            format!(
                "--support {name}: unknown support; the supports are {}",
                Support::NAMES.join(", ")
            )
        })?;
        family
            .adjust(&mut scene, &Adjustment::Support(support))
            .map_err(|e| e.to_string())?;
    }
    if let Some(name) = &options.obstacle {
        family
            .adjust(&mut scene, &Adjustment::Obstacle(name.clone()))
            .map_err(|e| e.to_string())?;
    }
    if options.no_obstacle {
        family
            .adjust(&mut scene, &Adjustment::NoObstacle)
            .map_err(|e| e.to_string())?;
        options.refuse_options(
            &[Opt::Alpha, Opt::Cold],
            &format!(
                "`{}` is solved without an obstacle (one linear solve); α and the nested start concern contact",
                scene.name
            ),
        )?;
    }
    let mut settings = settings(options)?;
    let backend_options = options.backend_options();
    let backend = if backend_options.wants_petsc()? {
        if options.solver == Some(SolverName::Clarabel) {
            return Err("--solver clarabel does not apply with --backend petsc: PETSc solves the complementarity problems".into());
        }
        options.refuse_options(
            &[Opt::LinearSolver, Opt::Solver, Opt::Refinement],
            "with --backend petsc, PETSc solves the complementarity problems and its options choose the method and the linear solver (--petsc-options \"-ksp_type cg -pc_type gamg\")",
        )?;
        let backend = Backend::start(&backend_options)?;
        settings.solver = backend.solver();
        Some(backend)
    } else {
        None
    };
    if let Some(path) = &options.msh {
        scene = scene.on_mesh_file(path.clone());
        settings.mesh_size = Some(options.mesh_size.unwrap_or(0));
    }
    let adaptive = settings.adaptive.is_some() || scene.tolerance.is_some();
    let bar = adaptive.then(|| {
        let (progress, bar) = adaptive_progress();
        settings.progress = Some(progress);
        bar
    });
    let outcome = fem_forms::models::choice::solve(&scene, &settings);
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    let mut outcome = outcome.map_err(|e| format!("{}: {e}", scene.name))?;
    if let Some(backend) = &backend {
        if !backend.is_root() {
            return Ok(());
        }
        backend.describe(&mut outcome.report, &backend_options);
    }
    print(&outcome.report, options.json)?;
    write_outputs(&scene, &outcome, options, out)
}

/// The report as JSON, or as a summary with its warnings on stderr.
fn print(report: &Report, json: bool) -> Result<(), String> {
    if json {
        println!(
            "{}",
            serde_json::to_string_pretty(report).map_err(|e| e.to_string())?
        );
        return Ok(());
    }
    println!("{}", summary(report));
    // on stderr: a summary piped to a file stays a summary
    for warning in &report.solve.warnings {
        eprintln!("warning: {warning}");
    }
    Ok(())
}

/// A few lines of what a solve found: the discretization, the solver's work, the answer's
/// integrals and certificate, the error where an exact solution is known, and the
/// family's own quantities.
pub fn summary(r: &Report) -> String {
    let number = fem_forms::number;
    let s = &r.solve;
    let mut lines = vec![format!(
        "{} ({}, {}): {} on the {}, N = {}, {} cells, {} unknowns",
        r.scene, r.family, r.pair, s.model, r.domain, r.mesh_size, s.cells, s.dofs
    )];
    let mut posed: Vec<String> = r
        .parameters
        .iter()
        .map(|(k, v)| format!("{k} = {}", number(*v)))
        .collect();
    if let Some(q) = r.load {
        posed.insert(0, format!("load = {}", number(q)));
    }
    if let Some(alpha) = s.alpha {
        posed.push(format!("α = {}", number(alpha)));
    }
    if !r.supports.is_empty() {
        posed.push(r.supports.join("; "));
    }
    lines.push(format!("  posed: {}", posed.join(", ")));
    lines.push(format!(
        "  solved: {} ({} linear steps), {} iterations on the finest level, {:.3} s",
        s.solver, s.linear_solver, s.iterations, s.seconds
    ));
    let mut answer = Vec::new();
    if let Some(e) = s.energy {
        answer.push(format!("energy {e:.10e}"));
    }
    answer.push(format!("∫λ_h {:.8e}", s.total_contact_force));
    if let Some(a) = s.contact_area {
        answer.push(format!("contact area {a:.6}"));
    }
    if let Some(l) = s.contact_length {
        answer.push(format!("contact length {l:.6}"));
    }
    answer.push(format!("KKT residual {:.1e}", s.kkt_residual));
    lines.push(format!("  answer: {}", answer.join(", ")));
    let errors: Vec<String> = [
        ("L²", s.error_l2),
        ("H¹", s.error_h1),
        ("H²", s.error_h2),
        ("λ", s.error_multiplier),
        ("vertex max", s.error_vertex_max),
    ]
    .iter()
    .filter_map(|(name, e)| e.map(|e| format!("{name} {e:.3e}")))
    .collect();
    if !errors.is_empty() {
        lines.push(format!(
            "  error against the exact solution: {}",
            errors.join(", ")
        ));
    }
    if let Some(estimate) = s.estimate {
        // relative to a norm of 0 (an unloaded plate) there is no ratio to show
        let relative = s
            .estimate_relative
            .map_or(String::new(), |r| format!(" ({r:.2e} of ‖u_h‖_a)"));
        let mut line = format!(
            "  estimate: (η² + S²)^½ = {estimate:.3e}{relative}, contact part S {:.3e}",
            s.estimate_contact.unwrap_or(0.0)
        );
        if let Some(index) = s.efficiency_index {
            line.push_str(&format!(", efficiency index {index:.2}"));
        }
        lines.push(line);
    }
    if let (Some(first), Some(last)) = (s.adaptive_levels.first(), s.adaptive_levels.last()) {
        lines.push(format!(
            "  adaptive: {} levels, {} → {} cells, estimate {:.3e} → {:.3e}",
            s.adaptive_levels.len(),
            first.cells,
            last.cells,
            first.estimate,
            last.estimate
        ));
    }
    lines.extend(choice_lines(r));
    lines.extend(edge_resultant_lines(r));
    let quantities: Vec<String> = r
        .quantities
        .iter()
        .filter(|(k, v)| {
            !v.is_null() && !CHOICE_KEYS.contains(&k.as_str()) && k.as_str() != "edge_resultants"
        })
        .map(|(k, v)| match v.as_f64() {
            Some(x) if !v.is_u64() && !v.is_i64() => format!("{k} {x:.8e}"),
            _ => format!("{k} {v}"),
        })
        .collect();
    if !quantities.is_empty() {
        lines.push(format!("  {}", quantities.join(", ")));
    }
    lines.join("\n")
}

/// The summary of a plate's edge resultants (`edge_resultants`; its profile along the
/// boundary is in the JSON report alone).
fn edge_resultant_lines(r: &Report) -> Vec<String> {
    let Some(e) = r.quantities.get("edge_resultants") else {
        return Vec::new();
    };
    let number = |key: &str| {
        e.get(key)
            .and_then(serde_json::Value::as_f64)
            .map_or("–".to_string(), |x| format!("{x:.4e}"))
    };
    let mut lines = vec![
        format!(
            "  edge resultants: max |M_nn| {}, max |M_ns| on free and soft edges {}, max |shear force| {}, ∫ shear force ds {}",
            number("bending_moment_max"),
            number("twisting_moment_max"),
            number("shear_force_max"),
            number("shear_force_integral")
        ),
        format!(
            "    shear force: {} (the profile along the boundary: --json)",
            e.get("shear_force_kind").and_then(|v| v.as_str()).unwrap_or("")
        ),
    ];
    if e.get("layer_width").is_some_and(|v| !v.is_null()) {
        let resolved = match e.get("layer_resolved").and_then(serde_json::Value::as_bool) {
            Some(true) => "resolved",
            Some(false) => "not resolved",
            // the Mindlin plate with every edge clamped or hard simply supported
            None if e
                .get("shear_force_kind")
                .and_then(serde_json::Value::as_str)
                .is_some_and(|k| k.starts_with("Q·n")) =>
            {
                "none (no edge leaves the rotations free)"
            }
            None => "not modelled (Kirchhoff)",
        };
        let longest = if e.get("layer_resolved").is_some_and(|v| !v.is_null()) {
            format!(
                ", the longest edge along it {}",
                number("layer_longest_edge")
            )
        } else {
            String::new()
        };
        lines.push(format!(
            "    boundary layer t/√(12κ) = {}: {resolved}{longest}",
            number("layer_width")
        ));
    }
    lines
}

/// The report keys of the model choice ([`fem_forms::models::choice`]): summarized by
/// [`choice_lines`], not listed among the family's quantities.
const CHOICE_KEYS: [&str; 6] = [
    "chosen_model",
    "chosen_pair",
    "tolerance",
    "modelling_estimate_relative",
    "candidates",
    "choice_seconds",
];

/// What the choice of model and pair weighed and took, a line per candidate.
fn choice_lines(r: &Report) -> Vec<String> {
    let (Some(model), Some(candidates)) = (
        r.quantities.get("chosen_model").and_then(|v| v.as_str()),
        r.quantities.get("candidates").and_then(|v| v.as_array()),
    ) else {
        return Vec::new();
    };
    let number = |key: &str| r.number(key).unwrap_or(f64::NAN);
    let mut lines = vec![format!(
        "  chosen for T = {}: {model} {} (modelling estimate {:.2e} of ‖u_h‖_a), after {:.3} s of probes:",
        fem_forms::number(number("tolerance")),
        r.pair,
        number("modelling_estimate_relative"),
        number("choice_seconds"),
    )];
    for c in candidates {
        let text = |key: &str| c[key].as_str().unwrap_or("?").to_string();
        let value = |key: &str| c[key].as_f64();
        let predicted =
            value("predicted_seconds").map_or("—".to_string(), |s| format!("{s:.3} s predicted"));
        let actual = value("actual_seconds").map_or(String::new(), |s| format!(", {s:.3} s taken"));
        let modelling = match value("modelling_estimate") {
            Some(m) if m > 0.0 => format!("modelling {m:.1e}"),
            // the thicker model of the two, or a scene without a neighbour
            Some(_) => "modelling 0".to_string(),
            None => "no modelling estimate".to_string(),
        };
        lines.push(format!(
            "    {} {:<16} {:<18} {modelling}, {predicted}{actual}: {}",
            if c["chosen"] == true { "→" } else { " " },
            text("model"),
            text("pair"),
            text("note"),
        ));
    }
    lines
}

/// Writes `out/<scene>-pressure.svg`: the multiplier along its boundary part against its
/// reference ([`Profile`]).
///
/// # Errors
/// The output directory or chart cannot be written.
pub fn profile_chart(scene: &str, profile: &Profile, out: &Path) -> Result<PathBuf, String> {
    let path = out.join(format!("{scene}-pressure.svg"));
    std::fs::create_dir_all(out).map_err(|e| e.to_string())?;
    let mut series = Vec::new();
    if let Some((label, curve)) = &profile.reference {
        series.push(plot::Series::line(label.clone(), curve.clone()));
    }
    let steps = profile
        .computed
        .1
        .iter()
        .flat_map(|&(x0, x1, p)| [(x0, p), (x1, p)])
        .collect();
    series.push(plot::Series::line(profile.computed.0.clone(), steps));
    let axes = plot::Axes {
        x: profile.x,
        y: profile.y,
        ..plot::Axes::default()
    };
    plot::chart(&path, &profile.title, axes, &series).map_err(|e| e.to_string())?;
    Ok(path)
}

/// The chart (`--plot`) and the ParaView file (`--vtk`) of a solve.
fn write_outputs(
    scene: &Scene,
    outcome: &Outcome,
    options: &SolveOptions,
    out: &Path,
) -> Result<(), String> {
    if let (true, Some(profile)) = (options.plot, &outcome.profile) {
        let path = profile_chart(&scene.name, profile, out)?;
        eprintln!("→ {}", path.display());
    } else if options.plot {
        let Fields::Interval { .. } = &outcome.fields else {
            return Err(format!(
                "--plot does not apply: `{}` has no profile chart",
                scene.name
            ));
        };
        let load = outcome.report.load.unwrap_or(1.0);
        let path = out.join(format!("{}-q{load}.svg", scene.name));
        plot::profiles(
            &path,
            &format!("{} q = {load}", scene.name),
            &outcome.fields,
        )
        .map_err(|e| e.to_string())?;
        eprintln!("→ {}", path.display());
    }
    if options.vtk {
        let Fields::Triangles { .. } = &outcome.fields else {
            return Err(format!(
                "--vtk does not apply: `{}` is not solved on triangles",
                scene.name
            ));
        };
        // an adaptive run's mesh is not the uniform mesh of its starting size: the file
        // says how many cells it has instead
        let size = if outcome.report.solve.adaptive_levels.is_empty() {
            outcome.report.mesh_size.to_string()
        } else {
            format!("adaptive-{}-cells", outcome.report.solve.cells)
        };
        let path = out.join(format!("{}-{}-{size}.vtu", scene.name, outcome.report.pair));
        std::fs::create_dir_all(out).map_err(|e| e.to_string())?;
        outcome.fields.write_vtu(&path).map_err(|e| e.to_string())?;
        eprintln!("→ {}", path.display());
    }
    Ok(())
}
