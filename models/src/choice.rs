//! The cheapest adequate model, pair and mesh for a tolerance (`solve SCENE --tol T`
//! without `--pair`, or a scene file's `tol`): one mechanism for every family.
//!
//! The candidates are the scene's own model with each of its pairs and, where its family
//! declares them, the cheaper neighbour model ([`crate::family::Family::cheaper`]:
//! Euler–Bernoulli for a Timoshenko beam, Kirchhoff for a Reissner–Mindlin plate) and
//! the richer one ([`crate::family::Family::richer`]: Reissner–Mindlin for a Kirchhoff
//! plate given its thickness), each with its pairs. Each candidate is probed by two
//! uniform solves (N and 2N), which give its a-posteriori estimate, its rate in the
//! unknowns and its time per solve, and for the thinner model of a pair of neighbours
//! the modelling estimate its own solution implies (the shear energy an Euler–Bernoulli
//! or Kirchhoff solution leaves out, [`Report`]'s `modelling_estimate_relative`). The
//! thinner model is adequate where its modelling estimate is at most [`MODEL_SHARE`] of
//! T; it is then solved to `T − modelling`, so that the triangle inequality keeps the
//! total within T. Among the adequate candidates
//! the one with the least predicted time (predictions within a factor [`TIE`] count as
//! equal: then the fewest unknowns, then the listing order) is solved adaptively from
//! the probe's coarse mesh (where its finer probe already reaches its target, that probe
//! is the answer; where its adaptive solve fails, the next is tried); the report lists
//! every candidate with its estimates and its predicted cost, and the chosen one's
//! actual cost. Where none is adequate, the scene's own model with its default pair is
//! solved, as without a choice. A request's `--alpha` applies to the scene's own model's
//! pairs, not to a neighbour model's, whose stability ranges are their own.
//!
//! The prediction: with the relative estimates `e₀, e₁` at `d₀, d₁` unknowns, the rate
//! `r = ln(e₀/e₁) / ln(d₁/d₀)`, the unknowns `d* = d₁ (e₁/target)^{1/r}` and the time
//! `s₁ (d*/d₁)^{1.2}` times [`ADAPTIVE_OVERHEAD`]. Adaptive meshes converge at least at
//! the uniform rate, so the prediction errs on the side of more work alike for every
//! candidate.

use crate::families;
use crate::report::{Outcome, Report, Settings};
use crate::scene::{Domain, Exact, Posed, Scene};
use fem_runtime::adaptivity::AdaptiveOptions;
use fem_runtime::lcp::external::Purpose;
use fem_runtime::obstacle::VariationalSolver;
use fem_runtime::{Error, Result};
use serde::Serialize;
use std::sync::Arc;
use std::time::Instant;

/// The share of the tolerance that the modelling error of a cheaper model may take.
pub const MODEL_SHARE: f64 = 0.5;

/// The growth of a solve's time with its unknowns assumed by the prediction, `s ∝ d^1.2`:
/// above the exponents measured for the membrane's solves (0.99 and 1.06 from 10⁴ to
/// 4·10⁶ unknowns, docs/benchmarks.md), as a margin for the direct factorizations of
/// the plates, whose exponent is not measured.
pub const TIME_EXPONENT: f64 = 1.2;

/// An adaptive solve's time over its last level's. Dörfler marking at θ = ½ grows the
/// unknowns by about 1.3 a level (membrane-radial: 128 → 61640 cells in 20 levels; the
/// thin beam: 46 → 2425 unknowns in 19), so the levels sum to about 1/(1 − 1/1.3) ≈ 4
/// times the last.
pub const ADAPTIVE_OVERHEAD: f64 = 4.0;

/// Below this rate (estimate against unknowns) a candidate is taken not to converge
/// at the probe's meshes (a locking pair): it is not predicted to reach the target.
pub const MIN_RATE: f64 = 0.05;

/// One probe solve of a candidate.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ProbeLevel {
    /// The mesh size N.
    pub mesh_size: usize,
    /// Unknowns.
    pub dofs: usize,
    /// Wall time of the solve, in seconds.
    pub seconds: f64,
    /// The estimate relative to `‖u_h‖_a`.
    pub estimate_relative: f64,
}

/// A candidate of the choice: a model and one of its pairs.
#[derive(Clone, Debug, Serialize)]
pub struct Candidate {
    /// The model in words (`Timoshenko`).
    pub model: &'static str,
    /// Its family.
    pub family: &'static str,
    /// The pair.
    pub pair: &'static str,
    /// Its probe solves (coarse, fine).
    pub probe: Vec<ProbeLevel>,
    /// The estimate's rate in the unknowns, `e ∝ d^{−rate}`, between the probes.
    pub rate: Option<f64>,
    /// The modelling estimate relative to `‖u_h‖_a` (0 for the scene's own model).
    pub modelling_estimate: f64,
    /// The discretization tolerance it must reach: `T − modelling`.
    pub discretization_target: f64,
    /// Predicted unknowns of the adaptive solve to that target.
    pub predicted_dofs: Option<f64>,
    /// Predicted wall time of that solve, in seconds.
    pub predicted_seconds: Option<f64>,
    /// The actual wall time, for the one solved.
    pub actual_seconds: Option<f64>,
    /// The actual unknowns of its final mesh, for the one solved.
    pub actual_dofs: Option<usize>,
    /// Whether its model is adequate (modelling estimate within the share of T) and its
    /// target predicted to be reached.
    pub adequate: bool,
    /// Whether it was taken.
    pub chosen: bool,
    /// Why it is or is not adequate.
    pub note: String,
}

/// Solves `scene` as `settings` ask: asked for a tolerance (`settings.adaptive`, or the
/// scene's `tol`) without a pair, with the cheapest adequate candidate where the scene has
/// more than one ([`choose`]); a pair of the scene's neighbour model (`--pair hermite-p0`
/// on a Timoshenko scene) with that model ([`solve_neighbour`]);
/// otherwise with [`families::solve`], a tolerance's adaptive loop starting from the
/// probes' coarse mesh where no mesh size is given (a loose tolerance wants no more than
/// it).
///
/// # Errors
/// Those of [`choose`] and [`families::solve`].
pub fn solve(scene: &Scene, settings: &Settings) -> Result<Outcome> {
    if let Some((scene, settings)) = families::richer_parameters_moved(scene, settings) {
        return solve(&scene, &settings);
    }
    let tolerance = settings
        .adaptive
        .as_ref()
        .map(|a| a.tolerance)
        .or(scene.tolerance);
    if let Some(pair) = settings.pair.as_deref() {
        if let Some(outcome) = solve_neighbour(scene, settings, pair)? {
            return Ok(outcome);
        }
    } else if let Some(tolerance) = tolerance.filter(|_| has_choice(scene)) {
        return choose(scene, settings, tolerance);
    }
    let mut outcome = if tolerance.is_some() && settings.mesh_size.is_none() {
        let coarse = Settings {
            mesh_size: Some(probe_sizes(scene, None)[0]),
            ..settings.clone()
        };
        families::solve(scene, &coarse)?
    } else {
        families::solve(scene, settings)?
    };
    if let Some(tolerance) = tolerance {
        warn_beyond(&mut outcome.report, tolerance);
    }
    Ok(outcome)
}

/// Warns where a solve to `tolerance` carries a modelling estimate (a thinner model's,
/// its pair fixed) that puts its error bound above the tolerance, which bounds the
/// discretization error alone.
fn warn_beyond(report: &mut Report, tolerance: f64) {
    let Some(modelling) = report.number("modelling_estimate_relative") else {
        return;
    };
    if let Some(bound) = error_bound(report).filter(|&b| b > tolerance) {
        report.warn(format!(
            "the error bound {bound:.2e} (estimate plus modelling estimate {modelling:.2e}) is above the tolerance {}: with the pair fixed the tolerance bounds the discretization error alone, and the model's own distance to the richer one is {modelling:.2e}; without --pair the choice weighs the richer model",
            fem_runtime::problem::number(tolerance)
        ));
    }
}

/// Solves `scene`'s neighbour model with `pair` where `pair` is one of that model's and
/// not of the scene's own: the report says so (`chosen_model`, `chosen_pair`), and a
/// cheaper model's carries its modelling estimate. The request's α applies: it names
/// the pair. `None` where `pair` is the scene's own or no neighbour takes it (the
/// caller's solve then names the pairs it takes).
///
/// # Errors
/// Those of [`models`] and of the solve.
fn solve_neighbour(scene: &Scene, settings: &Settings, pair: &str) -> Result<Option<Outcome>> {
    if neighbour_pair(scene, pair).is_none() {
        return Ok(None);
    }
    let models = models(scene, settings)?;
    let Some((words, thin)) = models
        .iter()
        .skip(1)
        .find(|(_, thin)| families::pairs_of(thin).iter().any(|p| p.name == pair))
    else {
        return Ok(None);
    };
    let mut thin = thin.clone();
    thin.tolerance = scene.tolerance;
    let request = Settings {
        pair: Some(pair.to_string()),
        ..candidate_settings(settings, &thin, true)
    };
    let mut outcome = if request.adaptive.is_some() || thin.tolerance.is_some() {
        solve(&thin, &request)?
    } else {
        families::solve(&thin, &request)?
    };
    outcome.report.set("chosen_model", *words);
    outcome.report.set("chosen_pair", pair);
    Ok(Some(outcome))
}

/// The pair called `name` of `scene`'s neighbour models, where it is not one of the
/// scene's own (`hermite-p0` for a Timoshenko scene, `argyris-p0` for a Reissner–Mindlin
/// one, `p1-p2-p0` for a Kirchhoff one given its thickness): a request for it solves
/// that model.
pub fn neighbour_pair(scene: &Scene, name: &str) -> Option<&'static crate::family::Pair> {
    let neighbour = neighbour_of(scene, name)?;
    families::pairs_of(&neighbour)
        .into_iter()
        .find(|p| p.name == name)
}

/// The neighbour model's scene whose pair `name` is, where it is not one of `scene`'s
/// own ([`neighbour_pair`]): its family says which options it takes.
pub fn neighbour_of(scene: &Scene, name: &str) -> Option<Scene> {
    let family = families::family(scene.family)?;
    let own = families::pairs_of(scene).iter().any(|p| p.name == name)
        || family
            .pair_aliases()
            .iter()
            .any(|(alias, _)| *alias == name);
    if own {
        return None;
    }
    [family.cheaper(scene), family.richer(scene)]
        .into_iter()
        .flatten()
        .find(|neighbour| families::pairs_of(neighbour).iter().any(|p| p.name == name))
}

/// The error bound of a solve relative to `‖u_h‖_a`: its relative estimate plus, for a
/// cheaper model's solve, its modelling estimate; `None` without an estimate.
pub fn error_bound(report: &Report) -> Option<f64> {
    let modelling = report.number("modelling_estimate_relative").unwrap_or(0.0);
    Some(report.solve.estimate_relative? + modelling)
}

/// What a chosen solve took: `Euler–Bernoulli hermite-p0` (the family's name for the
/// model of a report without a choice: a scene with one candidate).
pub fn chosen_words(report: &Report) -> String {
    let model = report
        .quantities
        .get("chosen_model")
        .and_then(|v| v.as_str())
        .unwrap_or(report.family);
    format!("{model} {}", report.pair)
}

impl Candidate {
    /// A candidate not judged yet: no estimate, target, rate or prediction (NaN, `None`),
    /// not adequate, not chosen.
    fn new(model: &'static str, scene: &Scene, pair: &'static str, probe: Vec<ProbeLevel>) -> Self {
        Self {
            model,
            family: scene.family,
            pair,
            probe,
            rate: None,
            modelling_estimate: f64::NAN,
            discretization_target: f64::NAN,
            predicted_dofs: None,
            predicted_seconds: None,
            actual_seconds: None,
            actual_dofs: None,
            adequate: false,
            chosen: false,
            note: String::new(),
        }
    }
}

/// Whether a tolerance chooses among several candidates for `scene`: its family
/// declares a neighbour model for it, or the scene takes more than one pair.
pub fn has_choice(scene: &Scene) -> bool {
    let Some(family) = families::family(scene.family) else {
        return false;
    };
    families::pairs_of(scene).len() > 1
        || family.cheaper(scene).is_some()
        || family.richer(scene).is_some()
}

/// The two mesh sizes the probes solve on: N and 2N on generated meshes (16, 32
/// elements of a beam; 8×8 and 16×16 squares), 0 and 1 refinements of a mesh file;
/// `given` (the request's size) replaces the coarser.
pub fn probe_sizes(scene: &Scene, given: Option<usize>) -> [usize; 2] {
    match (&scene.domain, given) {
        (Domain::Gmsh(_) | Domain::Refined { .. }, n) => {
            let n = n.unwrap_or(0);
            [n, n + 1]
        }
        (_, Some(n)) => [n.max(1), 2 * n.max(1)],
        (Domain::Interval { .. }, None) => [16, 32],
        (_, None) => [8, 16],
    }
}

/// Solves `scene` to the relative tolerance `tolerance` with the cheapest adequate
/// candidate (module docs), and reports the choice in the outcome's report:
/// `chosen_model`, `chosen_pair`, `tolerance`, `candidates` (every [`Candidate`]) and
/// `choice_seconds` (the probes' time).
///
/// # Errors
/// A load or parameter the scene refuses. A candidate whose probe fails is listed with
/// its failure and not taken; where every probe fails, the first failure. Where the
/// chosen candidate's solve fails the next is tried; where every one tried fails,
/// [`Error::Input`] listing every candidate weighed with its failure or why it was not
/// adequate.
pub fn choose(scene: &Scene, settings: &Settings, tolerance: f64) -> Result<Outcome> {
    let clock = Instant::now();
    let Probed {
        mut candidates,
        scenes,
        mut finished,
        own,
        sizes,
        first_failure,
    } = probe_all(scene, settings, tolerance)?;
    // the request's α is the scene's own pairs': where it fails one of their probes
    // (outside its stability range), that is the answer, as it is without a tolerance,
    // not a reason to weigh the others without it
    if settings.alpha.is_some()
        && (0..candidates.len()).any(|k| own[k] && candidates[k].probe.is_empty())
    {
        if let Some(e) = first_failure {
            return Err(e);
        }
    }
    let mut order = ranking(&candidates);
    if order.is_empty() {
        // none predicted to reach the target: the scene's own model with its default
        // pair, whose adaptive loop then says how far it got (or that the solution
        // vanishes); where even its probe failed, that failure
        match (0..candidates.len()).find(|&k| own[k]) {
            Some(k) if !candidates[k].probe.is_empty() => order.push(k),
            _ => {
                return Err(first_failure.unwrap_or_else(|| {
                    Error::Input(format!(
                        "scene `{}` has no pair to solve it with",
                        scene.name
                    ))
                }))
            }
        }
    }
    let probe_seconds = clock.elapsed().as_secs_f64();

    // the best first; where its adaptive solve fails (a user's α out of range on graded
    // cells), the next, the failure noted on the candidate
    for best in order {
        let target = candidates[best]
            .discretization_target
            .max(f64::MIN_POSITIVE);
        let solve_clock = Instant::now();
        let solved = match finished[best].take() {
            Some(probe) => {
                settings.solver.relabel(probe.records, Purpose::Answer);
                Ok((probe.outcome, candidates[best].probe[1].seconds))
            }
            None => {
                let final_settings = Settings {
                    pair: Some(candidates[best].pair.to_string()),
                    mesh_size: Some(sizes[0]),
                    adaptive: Some(AdaptiveOptions {
                        // the scene's own model taken for want of an adequate one: its
                        // modelling estimate is still its share of T where it is below T
                        tolerance: if target > f64::MIN_POSITIVE {
                            target
                        } else {
                            tolerance
                        },
                        ..settings.adaptive.clone().unwrap_or_default()
                    }),
                    ..candidate_settings(settings, &scenes[best], own[best])
                };
                families::solve(&scenes[best], &final_settings)
                    .map(|outcome| (outcome, solve_clock.elapsed().as_secs_f64()))
            }
        };
        match solved {
            Ok((mut outcome, seconds)) => {
                let chosen = &mut candidates[best];
                chosen.chosen = true;
                chosen.actual_seconds = Some(seconds);
                chosen.actual_dofs = Some(outcome.report.solve.dofs);
                let dropped = dropped_options(settings, &scenes[best], own[best]);
                record(
                    &mut outcome.report,
                    scene,
                    &candidates,
                    best,
                    tolerance,
                    probe_seconds,
                    &dropped,
                );
                return Ok(outcome);
            }
            Err(e) => {
                candidates[best].note = format!("its adaptive solve failed: {e}");
            }
        }
    }
    // every candidate tried failed: each failure is in its candidate's line
    Err(Error::Input(format!(
        "scene `{}` to the tolerance {}: no candidate's solve succeeded; the candidates weighed:\n{}",
        scene.name,
        fem_runtime::problem::number(tolerance),
        candidate_lines(&candidates)
    )))
}

/// The candidates weighed, one line each (model, pair, estimates, prediction, and why it
/// was or was not taken), for an error that ends the choice.
fn candidate_lines(candidates: &[Candidate]) -> String {
    candidates
        .iter()
        .map(|c| {
            let predicted = match (c.predicted_dofs, c.predicted_seconds) {
                (Some(dofs), Some(seconds)) => {
                    format!("predicted {dofs:.1e} unknowns in {seconds:.2e} s")
                }
                _ => "no prediction".to_string(),
            };
            format!(
                "  {} {}: modelling estimate {:.2e}, {predicted}, {}: {}",
                c.model,
                c.pair,
                c.modelling_estimate,
                if c.adequate {
                    "adequate"
                } else {
                    "not adequate"
                },
                c.note
            )
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// Two predicted times within this factor are a tie: the probes' times of small solves
/// (milliseconds) vary by as much from run to run, and a choice that flips between runs
/// is no choice.
pub const TIE: f64 = 2.0;

/// The adequate candidates, best first: by predicted time, where two are within [`TIE`]
/// of each other by fewer predicted unknowns, then in the listing order (the scene's own
/// model first, each model's default pair first).
fn ranking(candidates: &[Candidate]) -> Vec<usize> {
    let mut adequate: Vec<usize> = (0..candidates.len())
        .filter(|&k| candidates[k].adequate)
        .collect();
    let cost = |k: usize| candidates[k].predicted_seconds.unwrap_or(f64::INFINITY);
    let dofs = |k: usize| candidates[k].predicted_dofs.unwrap_or(f64::INFINITY);
    let mut ranked = Vec::new();
    while !adequate.is_empty() {
        let fastest = adequate
            .iter()
            .map(|&k| cost(k))
            .fold(f64::INFINITY, f64::min);
        // among those tied with the fastest, the fewest unknowns, then the first listed
        let (position, _) = adequate
            .iter()
            .enumerate()
            .filter(|(_, &k)| cost(k) <= TIE * fastest)
            .min_by(|a, b| dofs(*a.1).total_cmp(&dofs(*b.1)).then(a.1.cmp(b.1)))
            .expect("the fastest is tied with itself");
        ranked.push(adequate.remove(position));
    }
    ranked
}

/// The settings of a candidate's solves: the request's, without its parameters (the
/// scenes are posed with them already: a cheaper model has not the richer one's `t`) and,
/// unless the candidate is of the scene's own model (`own`), without its α (a stability
/// range is a pair's own: a neighbour model's pairs take their own rule) and, where the
/// candidate's family takes no `--solver` (the Reissner–Mindlin plate), with the default
/// solver (an external one, PETSc, solves every candidate).
fn candidate_settings(settings: &Settings, scene: &Scene, own: bool) -> Settings {
    let solver = if takes_solver(settings, scene, own) {
        settings.solver
    } else {
        Settings::default().solver
    };
    Settings {
        parameters: Vec::new(),
        alpha: if own { settings.alpha } else { None },
        solver,
        ..settings.clone()
    }
}

/// Whether the request's solver applies to a candidate posed on `scene`.
fn takes_solver(settings: &Settings, scene: &Scene, own: bool) -> bool {
    own || matches!(settings.solver, VariationalSolver::External(_))
        || families::family(scene.family)
            .is_some_and(|f| f.options().contains(&crate::family::Opt::Solver))
}

/// The request's options that a candidate posed on `scene` does not take, in words
/// (`--alpha 1e-6`): the chosen solve's report says so.
fn dropped_options(settings: &Settings, scene: &Scene, own: bool) -> Vec<String> {
    let mut dropped = Vec::new();
    if let (Some(alpha), false) = (settings.alpha, own) {
        dropped.push(format!("--alpha {}", fem_runtime::problem::number(alpha)));
    }
    if settings.solver != Settings::default().solver && !takes_solver(settings, scene, own) {
        dropped.push(format!("--solver {}", settings.solver.name()));
    }
    dropped
}

/// The candidates of `scene` for `tolerance`, probed and judged, without the final
/// solve: what [`choose`] weighs (the model-choice tests read it).
///
/// # Errors
/// Those of [`choose`] before its solve.
pub fn candidates(scene: &Scene, settings: &Settings, tolerance: f64) -> Result<Vec<Candidate>> {
    Ok(probe_all(scene, settings, tolerance)?.candidates)
}

/// Every candidate probed: the candidates, the scene each is posed on, the probes'
/// mesh sizes and the first probe failure.
struct Probed {
    candidates: Vec<Candidate>,
    scenes: Vec<Scene>,
    /// Per candidate, its finer probe where that already reaches its target.
    finished: Vec<Option<Probe>>,
    /// Per candidate, whether it is of the scene's own model.
    own: Vec<bool>,
    sizes: [usize; 2],
    first_failure: Option<Error>,
}

/// The models a tolerance weighs for `scene` as `settings` pose it: `(model in words,
/// scene)`, the scene's own first, then its family's cheaper neighbour (with the
/// scene's exact solution, so that its errors are against what the scene poses) and
/// its richer one (without: the thinner model's closed forms are not the thicker
/// one's); each model's candidates are its scene's pairs ([`families::pairs_of`]).
///
/// # Errors
/// A scene without a family; a load or parameter the scene refuses.
pub fn models(scene: &Scene, settings: &Settings) -> Result<Vec<(&'static str, Scene)>> {
    let moved = families::richer_parameters_moved(scene, settings);
    let (scene, settings) = moved.as_ref().map_or((scene, settings), |(s, t)| (s, t));
    let family = families::family(scene.family)
        .ok_or_else(|| Error::Input(format!("scene `{}` has no family", scene.name)))?;
    let posed = crate::run::pose(scene, settings)?;
    // the scene as posed: a request's parameters (--thickness) are the model's values
    let mut rich = scene.clone();
    rich.parameters = posed.parameters.clone();
    rich.tolerance = None;
    let mut models = vec![(family.model_words(&rich), rich.clone())];
    if let Some(mut thin) = family.cheaper(&rich) {
        thin.tolerance = None;
        thin.exact = exact_of(&rich, &posed);
        let words = families::family(thin.family).map_or("", |f| f.model_words(&thin));
        models.push((words, thin));
    }
    if let Some(mut thick) = family.richer(&rich) {
        thick.tolerance = None;
        let words = families::family(thick.family).map_or("", |f| f.model_words(&thick));
        models.push((words, thick));
    }
    Ok(models)
}

fn probe_all(scene: &Scene, settings: &Settings, tolerance: f64) -> Result<Probed> {
    let models = models(scene, settings)?;
    let sizes = probe_sizes(scene, settings.mesh_size);
    let mut candidates = Vec::new();
    let mut scenes = Vec::new();
    let mut finished = Vec::new();
    let mut own = Vec::new();
    let mut first_failure = None;
    let limit = settings
        .adaptive
        .as_ref()
        .map_or(AdaptiveOptions::default().max_dofs, |a| a.max_dofs);
    for (k, (words, model_scene)) in models.iter().enumerate() {
        for pair in families::pairs_of(model_scene) {
            own.push(k == 0);
            match probe(model_scene, pair.name, settings, sizes, k == 0) {
                Ok((probe, modelling, finer)) => {
                    let mut candidate = judge(
                        words,
                        model_scene,
                        pair.name,
                        probe,
                        modelling,
                        tolerance,
                        limit,
                    );
                    let report = &finer.outcome.report;
                    if let Some(edge) = report.number("modelling_estimate_edge") {
                        if model_scene.edge_resultants && edge > MODEL_SHARE * tolerance {
                            candidate.note = format!(
                                "the scene asks for the edge resultants, and the twisting moment of this model on the edges that leave the Reissner–Mindlin rotations free (where the Reissner–Mindlin one vanishes) is {edge:.3e} of its edge moments, above {MODEL_SHARE} of the tolerance {}",
                                fem_runtime::problem::number(tolerance)
                            );
                        }
                    }
                    if model_scene.edge_resultants
                        && candidate.adequate
                        && report.quantity("edge_resultants").is_none()
                    {
                        candidate.adequate = false;
                        candidate.note = "the scene asks for the edge resultants, and this pair gives none (Morley's moments are constant on a cell and its shear force vanishes; a curved disk's edges are not sampled)".into();
                    }
                    // a probe that already reaches the target is the answer, if chosen,
                    // unless it leaves a boundary layer asked about unresolved
                    let reached = candidate.adequate
                        && candidate.probe[1].estimate_relative <= candidate.discretization_target
                        && !report.layer_unresolved();
                    finished.push(reached.then_some(finer));
                    candidates.push(candidate);
                }
                Err(e) => {
                    let mut failed = Candidate::new(words, model_scene, pair.name, Vec::new());
                    failed.note = format!("the probe failed: {e}");
                    candidates.push(failed);
                    first_failure.get_or_insert(e);
                    finished.push(None);
                }
            }
            scenes.push(model_scene.clone());
        }
    }
    Ok(Probed {
        candidates,
        scenes,
        finished,
        own,
        sizes,
        first_failure,
    })
}

/// The thick model's exact solution at its posed parameters, for the cheaper model's
/// scene: the cheaper solve's errors are then against what the scene poses.
fn exact_of(rich: &Scene, posed: &Posed) -> Exact {
    if matches!(rich.exact, Exact::Unknown) {
        return Exact::Unknown;
    }
    let rich = rich.clone();
    let parameters = posed.parameters.clone();
    Exact::Of(Arc::new(move |p: &Posed| {
        rich.exact_at(&Posed {
            load: p.load,
            parameters: parameters.clone(),
        })
    }))
}

/// The two probe solves of `pair` on `scene` (of the scene's `own` model or not), and
/// the modelling estimate of the finer one where the scene is the thinner of two
/// neighbours ([`Scene::richer`]).
fn probe(
    scene: &Scene,
    pair: &'static str,
    settings: &Settings,
    sizes: [usize; 2],
    own: bool,
) -> Result<(Vec<ProbeLevel>, f64, Probe)> {
    let mut levels = Vec::new();
    let mut modelling = 0.0;
    let mut finer = None;
    let mut records = 0..0;
    for n in sizes {
        let probe_settings = Settings {
            pair: Some(pair.to_string()),
            mesh_size: Some(n),
            adaptive: None,
            progress: None,
            // the probes weigh the candidates; the rounding experiment (a beam's solve
            // repeated on a moved mesh) is the final solve's to run
            rounding_experiment: Some(false),
            ..candidate_settings(settings, scene, own)
        };
        let clock = Instant::now();
        let first_record = settings.solver.recorded();
        let outcome = settings
            .solver
            .during(Purpose::Probe, || families::solve(scene, &probe_settings))?;
        let seconds = clock.elapsed().as_secs_f64();
        records = first_record..settings.solver.recorded();
        let s = &outcome.report.solve;
        let estimate_relative = s.estimate_relative.ok_or_else(|| {
            Error::Input(match s.estimate {
                None => format!(
                    "pair `{pair}` has no a-posteriori estimate (its model declares no estimator): a tolerance cannot be met with it; give --pair with a pair that has one"
                ),
                Some(_) => format!(
                    "pair `{pair}` solves to ‖u_h‖_a = 0 on the probe's mesh N = {n} ({} unknowns), so no error relative to it exists there: either the supports fix every unknown of so coarse a mesh (start from a finer one: --mesh-size) or the solution is 0 (no load and no obstacle above 0: there is nothing to estimate, solve without a tolerance)",
                    s.dofs
                ),
            })
        })?;
        if scene.richer.is_some() {
            // NaN where the pair gives none (Morley): [`judge`] says so
            modelling = outcome
                .report
                .number("modelling_estimate_relative")
                .unwrap_or(f64::NAN);
            if scene.edge_resultants {
                // the edge resultants asked for: the thinner model's error in them too
                modelling = match outcome.report.number("modelling_estimate_edge") {
                    Some(edge) => modelling.max(edge),
                    None => f64::NAN,
                };
            }
        }
        levels.push(ProbeLevel {
            mesh_size: n,
            dofs: s.dofs,
            seconds,
            estimate_relative,
        });
        finer = Some(outcome);
    }
    let finer = finer.ok_or_else(|| Error::Input("no probe size".into()))?;
    Ok((
        levels,
        modelling,
        Probe {
            outcome: finer,
            records,
        },
    ))
}

/// The finer probe's solve: its outcome, and the external solver's records of it
/// ([`VariationalSolver::recorded`]), relabelled as the answer where the choice takes it.
struct Probe {
    outcome: Outcome,
    records: std::ops::Range<usize>,
}

/// A probed candidate judged against the tolerance: its target, rate and predicted cost.
fn judge(
    model: &'static str,
    scene: &Scene,
    pair: &'static str,
    probe: Vec<ProbeLevel>,
    modelling: f64,
    tolerance: f64,
    max_dofs: usize,
) -> Candidate {
    // a cheaper model whose modelling error alone exceeds T has nothing left to reach
    let target = (tolerance - modelling).max(0.0);
    let mut candidate = Candidate {
        modelling_estimate: modelling,
        discretization_target: target,
        ..Candidate::new(model, scene, pair, probe)
    };
    if modelling.is_nan() {
        candidate.note = "its solution gives no modelling estimate (Morley's ∇Δw vanishes on every cell), so its distance to the richer model is unknown".into();
        return candidate;
    }
    if modelling > MODEL_SHARE * tolerance {
        candidate.note = format!(
            "the modelling estimate {modelling:.3e} exceeds {MODEL_SHARE} of the tolerance {} ({:.3e})",
            fem_runtime::problem::number(tolerance),
            MODEL_SHARE * tolerance
        );
        return candidate;
    }
    let [coarse, fine] = [candidate.probe[0], candidate.probe[1]];
    let rate = (coarse.estimate_relative / fine.estimate_relative).ln()
        / (fine.dofs as f64 / coarse.dofs as f64).ln();
    candidate.rate = rate.is_finite().then_some(rate);
    if fine.estimate_relative <= target {
        candidate.predicted_dofs = Some(fine.dofs as f64);
        candidate.predicted_seconds = Some(coarse.seconds + fine.seconds);
        candidate.adequate = true;
        candidate.note = "the probe's finer mesh already reaches the target".into();
        return candidate;
    }
    if rate.is_nan() || rate < MIN_RATE {
        candidate.note = format!(
            "its estimate does not fall between the probes (rate {rate:.2}): it does not converge at these meshes"
        );
        return candidate;
    }
    let dofs = fine.dofs as f64 * (fine.estimate_relative / target).powf(1.0 / rate);
    let limit = max_dofs as f64;
    candidate.predicted_dofs = Some(dofs);
    candidate.predicted_seconds =
        Some(fine.seconds * (dofs / fine.dofs as f64).powf(TIME_EXPONENT) * ADAPTIVE_OVERHEAD);
    candidate.adequate = dofs <= limit;
    candidate.note = if candidate.adequate {
        format!("predicted to reach {target:.2e} at rate {rate:.2}")
    } else {
        format!("predicted to need {dofs:.1e} unknowns, beyond the adaptive loop's {limit:.0e}")
    };
    candidate
}

/// The choice in the chosen solve's report; `dropped`: the request's options the chosen
/// candidate did not take ([`dropped_options`]).
fn record(
    report: &mut Report,
    scene: &Scene,
    candidates: &[Candidate],
    best: usize,
    tolerance: f64,
    probe_seconds: f64,
    dropped: &[String],
) {
    let chosen = &candidates[best];
    report.scene = scene.name.to_string();
    report.set("chosen_model", chosen.model);
    report.set("chosen_pair", chosen.pair);
    report.set("tolerance", tolerance);
    // the final solve's own where it has one: a fallback solved on another mesh than
    // the probe's
    if report.number("modelling_estimate_relative").is_none() {
        report.set("modelling_estimate_relative", chosen.modelling_estimate);
    }
    report.set("candidates", candidates);
    report.set("choice_seconds", probe_seconds);
    if !chosen.adequate {
        let bound = error_bound(report).map_or(String::new(), |b| {
            format!(
                "; its error bound (estimate plus modelling estimate) is {b:.2e}, {} the tolerance",
                if b <= tolerance { "within" } else { "above" }
            )
        });
        report.warn(format!(
            "no candidate was predicted to reach the tolerance {}: solved with {} ({}), the scene's own model{bound}",
            fem_runtime::problem::number(tolerance),
            chosen.pair,
            chosen.model
        ));
    }
    if !dropped.is_empty() {
        report.warn(format!(
            "{} {} to the scene's own model's pairs: {} ({}) was solved with its own (the report's alpha and solver)",
            dropped.join(" and "),
            if dropped.len() == 1 { "applies" } else { "apply" },
            chosen.pair,
            chosen.model
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn candidate(seconds: Option<f64>, dofs: f64, adequate: bool) -> Candidate {
        let scene = Scene::new("s", "", "beam", Domain::UNIT_INTERVAL, 4);
        Candidate {
            predicted_seconds: seconds,
            predicted_dofs: Some(dofs),
            adequate,
            ..Candidate::new("m", &scene, "p", Vec::new())
        }
    }

    /// Predictions within a factor 2 tie, and the fewer unknowns win the tie; an
    /// inadequate candidate is not ranked however fast.
    #[test]
    fn ties_in_time_go_to_the_fewer_unknowns_then_the_first_listed() {
        let candidates = [
            candidate(Some(1.0), 100.0, true),
            candidate(Some(1.5), 50.0, true),
            candidate(Some(10.0), 10.0, true),
            candidate(Some(0.1), 1.0, false),
            candidate(Some(1.2), 50.0, true),
        ];
        assert_eq!(ranking(&candidates), vec![1, 4, 0, 2]);
    }
}
