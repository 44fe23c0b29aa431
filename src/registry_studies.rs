//! The studies of any registry scene ([`crate::models::families`]): one implementation of
//! [`StudyScene`] over the one solve, so that a family added as a model file and a
//! registry entry hosts every study kind without code of its own: convergence, α range,
//! work–precision, iterations, stability (the inf-sup constants of the multiplier's
//! Schur complement), locking where the family has a thickness ([`crate::locking`]).
//! The multiplier is charted along the family's own line where it has one (contact's
//! Γ_C), else along the cells met by the horizontal line through the mesh's centre.

use crate::models::families;
use crate::models::geometry::Fields;
use crate::models::report::{Outcome, Schur, Settings};
use crate::models::scene::{Domain, Exact, ExactSolution, Scene};
use crate::studies::{ExactMultiplier, Measure, Plan, Row, Run, StabilityRow, Study, StudyScene};
use fem_runtime::{Error, Result};
use std::path::Path;

/// A registry scene as the studies see it.
pub struct RegistryStudies {
    scene: Scene,
}

impl RegistryStudies {
    /// The studies of `scene`. A study chooses its own meshes, so the accuracy the
    /// scene asks for is not checked (it would warn on every coarse mesh).
    pub fn new(mut scene: Scene) -> Self {
        scene.accuracy = None;
        Self { scene }
    }

    /// The studies of the registry scene called `name`.
    ///
    /// # Errors
    /// A name the registry does not have.
    pub fn of(name: &str) -> Result<Self> {
        families::scene(name)
            .map(Self::new)
            .ok_or_else(|| Error::Input(format!("the registry has no scene `{name}`")))
    }

    fn outcome(&self, run: &Run) -> Result<Outcome> {
        let settings = Settings {
            pair: Some(run.pair.to_string()),
            load: self.scene.study_load,
            mesh_size: Some(run.size),
            alpha: run.alpha,
            solver: run.solver,
            nested: run.nested,
            ..Settings::default()
        };
        families::solve(&self.scene, &settings)
    }

    /// The default size and its halvings: `[N/4, N/2, N]` (quick) or up to `4N` (full),
    /// even on the L-shape, at least 1.
    fn ladder(&self, full: bool) -> Vec<usize> {
        let n = self.scene.mesh_size.max(4);
        let even = matches!(self.scene.domain, Domain::LShape);
        let mut sizes: Vec<usize> = [n / 4, n / 2, n]
            .into_iter()
            .chain(if full { vec![2 * n, 4 * n] } else { vec![] })
            .filter(|&k| k >= 1 && (!even || k % 2 == 0))
            .collect();
        sizes.dedup();
        sizes
    }

    /// The multiplier's Schur complement of `pair` at `size` with α (`None`: the pair's
    /// rule), and the α solved with.
    fn schur(&self, pair: &'static str, size: usize, alpha: Option<f64>) -> Result<(Schur, f64)> {
        let settings = Settings {
            pair: Some(pair.to_string()),
            mesh_size: Some(size),
            load: self.scene.study_load,
            alpha,
            schur: true,
            ..Settings::default()
        };
        let outcome = families::solve(&self.scene, &settings)?;
        let alpha = outcome.report.solve.alpha.unwrap_or(0.0);
        let schur = outcome
            .schur
            .ok_or_else(|| self.unsupported("multiplier space to measure"))?;
        Ok((schur, alpha))
    }

    /// The family's own error measure of the multiplier ([`crate::models::family::Family::error_measure`]).
    fn family_measure(&self) -> Option<(&'static str, &'static str)> {
        families::family(self.scene.family)?.error_measure()
    }

    /// The exact solution at the studies' load, where known.
    fn exact(&self) -> Option<ExactSolution> {
        let settings = Settings {
            load: self.scene.study_load,
            ..Settings::default()
        };
        let posed = crate::models::run::pose(&self.scene, &settings).ok()?;
        self.scene.exact_at(&posed)
    }

    fn unsupported(&self, what: &str) -> Error {
        Error::Input(format!(
            "scene `{}` (family {}) has no {what}: it is a family's own study",
            self.scene.name, self.scene.family
        ))
    }
}

/// The piecewise linear interpolant of `samples` (sorted by x) at `x`; 0 outside.
fn interpolate(samples: &[(f64, f64)], x: f64) -> f64 {
    samples
        .windows(2)
        .find(|w| w[0].0 <= x && x <= w[1].0)
        .map_or(0.0, |w| {
            let width = w[1].0 - w[0].0;
            if width > 0.0 {
                w[0].1 + (x - w[0].0) / width * (w[1].1 - w[0].1)
            } else {
                w[0].1
            }
        })
}

/// λ as a function of the abscissa along a chart's line.
type Curve = Box<dyn Fn(f64) -> f64>;

/// The smallest and largest abscissa of `points`, where they differ.
fn extent(points: &[(f64, f64)]) -> Option<(f64, f64)> {
    let (lo, hi) = points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.0), hi.max(p.0))
        });
    (lo < hi).then_some((lo, hi))
}

/// The multiplier of a solve along a line, as `(x, λ_h)` sorted by x, and the line's
/// ordinate: on an interval λ_h at the cell midpoints (y = 0); on triangles λ_h at the
/// centroids of the cells met by the horizontal line through the centre of the mesh's
/// bounding box, or touching it from above (on a structured mesh, the row of cells just
/// above it).
pub fn line_profile(fields: &Fields) -> (Vec<(f64, f64)>, f64) {
    match fields {
        Fields::Interval { cell_x, lambda, .. } => (
            cell_x.iter().copied().zip(lambda.iter().copied()).collect(),
            0.0,
        ),
        Fields::Triangles { mesh, cell, .. } => {
            let (lo, hi) = mesh
                .vertices()
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                    (lo.min(v[1]), hi.max(v[1]))
                });
            let y = 0.5 * (lo + hi);
            let tolerance = 1e-12 * (hi - lo);
            let lambda = cell.iter().find(|c| c.0 == "lambda").map(|c| &c.1);
            let mut points: Vec<(f64, f64)> = (0..mesh.cell_count())
                .filter_map(|c| {
                    let x = mesh.cell_coordinates(c);
                    let centroid = [(x[0] + x[2] + x[4]) / 3.0, (x[1] + x[3] + x[5]) / 3.0];
                    let lowest = x[1].min(x[3]).min(x[5]);
                    let met = centroid[1] > y && lowest <= y + tolerance;
                    met.then(|| (centroid[0], lambda.map_or(f64::NAN, |l| l[c])))
                })
                .collect();
            points.sort_by(|a, b| a.0.total_cmp(&b.0));
            (points, y)
        }
    }
}

/// The largest cell diameter of a solve's mesh.
fn largest_h(fields: &Fields) -> f64 {
    match fields {
        // the cells' lengths (x holds the plot's samples, several to a cell)
        Fields::Interval { x, cell_x, .. } => crate::plot::cell_lengths(x, cell_x)
            .into_iter()
            .fold(0.0f64, f64::max),
        Fields::Triangles { mesh, .. } => mesh.max_h(),
    }
}

/// The smallest cell diameter of a solve's mesh.
fn smallest_h(fields: &Fields) -> f64 {
    match fields {
        Fields::Interval { x, cell_x, .. } => crate::plot::cell_lengths(x, cell_x)
            .into_iter()
            .fold(f64::INFINITY, f64::min),
        Fields::Triangles { mesh, .. } => mesh.min_h(),
    }
}

impl StudyScene for RegistryStudies {
    fn name(&self) -> String {
        self.scene.name.to_string()
    }

    fn setting(&self) -> String {
        match &self.scene.load {
            Some(l) => format!(
                "{} {} = {}",
                self.scene.name,
                l.symbol,
                fem_runtime::problem::number(self.scene.study_load.unwrap_or(l.default))
            ),
            None => self.scene.name.to_string(),
        }
    }

    fn size_name(&self) -> &'static str {
        match self.scene.domain {
            Domain::Interval { .. } => "elements",
            _ => "N",
        }
    }

    fn h(&self, size: usize) -> f64 {
        self.scene
            .domain
            .size()
            .map_or(f64::NAN, |d| d / size as f64)
    }

    fn contact_names(&self) -> [&'static str; 2] {
        // a multiplier on a boundary part, or on an interval, touches along a length
        let interval = matches!(self.scene.domain, Domain::Interval { .. });
        if self.scene.facets.is_empty() && !interval {
            ["contact area", "|area error|"]
        } else {
            ["contact length", "|length error|"]
        }
    }

    fn pairs(&self) -> Vec<&'static str> {
        families::pairs_of(&self.scene)
            .iter()
            .map(|p| p.name)
            .collect()
    }

    fn plan(&self, study: Study, pair: &'static str, full: bool) -> Plan {
        let default = self.pairs()[0];
        let n = self.scene.mesh_size.max(1);
        match study {
            Study::Alpha => {
                // α·C_I from 1e-3 to 2.5 where C_I is known, else α itself; and 0
                let c_i = self.inverse_constant(default, n).unwrap_or(0.0);
                let scale = if c_i > 0.0 { 1.0 / c_i } else { 1.0 };
                Plan {
                    pair: default,
                    sizes: vec![n],
                    cold_max: 0,
                    alphas: (0..=17)
                        .map(|k| Some(scale * 10f64.powf(-3.0 + 0.2 * k as f64)))
                        .chain([Some(0.0)])
                        .collect(),
                }
            }
            // the inf-sup eigenproblem is dense in the multipliers: small meshes
            Study::Stability => {
                let sizes: &[usize] = match (&self.scene.domain, full) {
                    (Domain::Interval { .. }, false) => &[16, 32, 64],
                    (Domain::Interval { .. }, true) => &[16, 32, 64, 128, 256],
                    (_, false) => &[4, 8, 16],
                    (_, true) => &[4, 8, 16, 24, 32],
                };
                Plan {
                    pair,
                    sizes: sizes.to_vec(),
                    cold_max: 0,
                    alphas: vec![],
                }
            }
            Study::WorkPrecision | Study::Iterations => Plan {
                pair: default,
                sizes: self.ladder(full),
                cold_max: usize::MAX,
                alphas: vec![],
            },
            _ => Plan {
                pair,
                sizes: self.ladder(full),
                cold_max: 0,
                alphas: vec![],
            },
        }
    }

    /// The default pair at the scene's size, plain (α = 0) and stabilized.
    fn profiles(&self, _full: bool) -> Plan {
        Plan {
            pair: self.pairs()[0],
            sizes: vec![self.scene.mesh_size],
            cold_max: 0,
            alphas: vec![Some(0.0), None],
        }
    }

    fn solve(&self, run: &Run) -> Result<Row> {
        let outcome = self.outcome(run)?;
        let r = &outcome.report;
        let s = &r.solve;
        let contact = s.contact_area.or(s.contact_length).unwrap_or(f64::NAN);
        Ok(Row {
            pair: run.pair,
            size: run.size,
            h: largest_h(&outcome.fields),
            h_min: smallest_h(&outcome.fields),
            cells: s.cells,
            dofs: s.dofs,
            alpha: s.alpha.unwrap_or(0.0),
            error_l2: s.error_l2,
            error_h1: s.error_h1,
            // the family's own measure of the multiplier where the runtime has none
            // (contact's pressure error against Hertz's)
            error_multiplier: s.error_multiplier.or_else(|| {
                self.family_measure()
                    .and_then(|(key, _)| outcome.report.number(key))
            }),
            energy: s.energy,
            // a plate's centre deflection against the series, where the family has one
            reference_error: r.number("relative_error").map(f64::abs),
            total_contact_force: s.total_contact_force,
            force_error: r
                .exact_contact_force
                .map(|e| (s.total_contact_force - e).abs()),
            contact,
            contact_error: r.exact_contact_area.map(|e| (contact - e).abs()),
            iterations: s.iterations,
            seconds: s.seconds,
            estimate: s.estimate,
            estimate_relative: s.estimate_relative,
            error_energy: s.error_energy,
            kkt_residual: s.kkt_residual,
            warnings: s.warnings.clone(),
        })
    }

    fn inverse_constant(&self, pair: &'static str, size: usize) -> Result<f64> {
        Ok(self
            .outcome(&Run::new(pair, size))?
            .report
            .solve
            .inverse_constant)
    }

    fn exact_contact(&self) -> Option<f64> {
        self.exact()?.contact_area
    }

    /// Every pair with a multiplier space (the nodal method has none to measure).
    fn stability_pairs(&self) -> Vec<&'static str> {
        families::pairs_of(&self.scene)
            .iter()
            .filter(|p| !p.nodal)
            .map(|p| p.name)
            .collect()
    }

    fn measure(&self) -> Measure {
        crate::studies::inf_sup_measure()
    }

    /// The two smallest eigenvalues of the multiplier's Schur complement in the norm of
    /// the pair's stabilization (its diagonal over α, from the stabilized solve), for the
    /// plain method (α = 0) and the stabilized one (the default α): one implementation
    /// for every family ([`fem_runtime::stabilization::inf_sup_spectrum`]).
    fn stability(&self, pair: &'static str, size: usize) -> Result<StabilityRow> {
        let (stabilized, alpha) = self.schur(pair, size, None)?;
        let norm = stabilized.norm.clone().ok_or_else(|| {
            Error::Input(format!(
                "pair {pair} of `{}` has no stabilization whose norm the inf-sup constants are measured in",
                self.scene.name
            ))
        })?;
        let (plain, _) = self.schur(pair, size, Some(0.0))?;
        let two = |schur: &Schur| -> Result<Vec<f64>> {
            let values = fem_runtime::stabilization::inf_sup_spectrum(&schur.matrix, &norm)?;
            Ok(values
                .into_iter()
                .chain([f64::NAN, f64::NAN])
                .take(2)
                .collect())
        };
        Ok(StabilityRow {
            pair,
            size,
            alpha,
            plain: two(&plain)?,
            stabilized: two(&stabilized)?,
        })
    }

    /// The family's chart of the multiplier along its boundary part
    /// ([`crate::models::report::Profile`]), each P0 step at its middle; else
    /// [`line_profile`] of the solve.
    fn multiplier_profile(&self, run: &Run) -> Result<Vec<(f64, f64)>> {
        let outcome = self.outcome(run)?;
        Ok(match outcome.profile {
            Some(profile) => profile
                .computed
                .1
                .iter()
                .map(|&(x0, x1, lambda)| (0.5 * (x0 + x1), lambda))
                .collect(),
            None => line_profile(&outcome.fields).0,
        })
    }

    /// The reference curve of the family's chart at the default solve, interpolated;
    /// else the exact multiplier along the line of [`line_profile`].
    fn exact_multiplier(&self) -> Option<ExactMultiplier> {
        let run = Run::new(self.pairs()[0], self.scene.mesh_size);
        let outcome = self.outcome(&run).ok()?;
        let (samples, lambda): (Vec<(f64, f64)>, Curve) = match outcome.profile {
            Some(profile) => {
                let (_, samples) = profile.reference?;
                let curve = samples.clone();
                (samples, Box::new(move |x| interpolate(&curve, x)))
            }
            None => {
                let multiplier = self.exact()?.multiplier?;
                let (points, y) = line_profile(&outcome.fields);
                let (lo, hi) = extent(&points)?;
                let samples = (0..=4000)
                    .map(|i| {
                        let x = lo + (hi - lo) * i as f64 / 4000.0;
                        (x, multiplier.at(&[x, y]))
                    })
                    .collect();
                (samples, Box::new(move |x| multiplier.at(&[x, y])))
            }
        };
        let touching: Vec<f64> = samples.iter().filter(|p| p.1 > 0.0).map(|p| p.0).collect();
        let (lo, hi) = extent(&touching.iter().map(|&x| (x, 0.0)).collect::<Vec<_>>())?;
        Some(ExactMultiplier {
            contact: [lo, hi],
            lambda,
        })
    }

    fn multiplier_error_name(&self) -> String {
        self.family_measure()
            .map_or("h-weighted ‖λ − λ_h‖".into(), |(_, words)| {
                words.into()
            })
    }

    /// The one adaptive loop ([`fem_runtime::problem::Problem::solve_adaptive`]) through
    /// the scene's solve, at the studies' load.
    fn adaptive(
        &self,
        pair: &'static str,
        size: usize,
        tolerance: f64,
    ) -> Result<crate::studies::AdaptiveRun> {
        let settings = Settings {
            pair: Some(pair.to_string()),
            load: self.scene.study_load,
            mesh_size: Some(size),
            adaptive: Some(fem_runtime::adaptivity::AdaptiveOptions {
                tolerance,
                ..Default::default()
            }),
            ..Settings::default()
        };
        let outcome = families::solve(&self.scene, &settings)?;
        Ok(crate::studies::AdaptiveRun {
            levels: outcome.report.solve.adaptive_levels,
            fields: outcome.fields,
        })
    }

    /// The one adaptivity study ([`crate::adaptivity_study`]).
    fn adaptivity(&self, full: bool, out: &std::path::Path) -> Result<()> {
        crate::adaptivity_study::run(self, full, out)
    }

    /// The one locking study ([`crate::locking`]).
    fn locking(&self, full: bool, out: &std::path::Path) -> Result<()> {
        crate::locking::run(&self.scene, full, out)
    }

    /// The exact contact interval widened by a quarter of its width on each side where
    /// it is known, else the extent of the chart at the default solve.
    fn profile_window(&self) -> [f64; 2] {
        if let Some(exact) = self.exact_multiplier() {
            let [a, b] = exact.contact;
            let margin = 0.25 * (b - a).max(0.0);
            return [a - margin, b + margin];
        }
        let run = Run::new(self.pairs()[0], self.scene.mesh_size);
        let points = self.multiplier_profile(&run).unwrap_or_default();
        extent(&points).map_or([0.0, 1.0], |(lo, hi)| [lo, hi])
    }
}

/// A study of a registry scene through the one implementation over the one solve
/// ([`fem_forms::registry_studies`]), on each of its study variants where the study
/// depends on the data ([`Study::depends_on_data`]); the λ-scatter through its own
/// ([`crate::lambda_scatter`]).
pub fn run_hosted(
    scene: Scene,
    kind: Option<&str>,
    full: bool,
    out: &Path,
) -> std::result::Result<(), String> {
    let name = scene.name.to_string();
    let hosted = scene.studies.clone();
    let work_precision = Study::WorkPrecision.name();
    if kind == Some(work_precision) && !hosted.contains(&work_precision) {
        // every scene has the chart of its candidates and of the choice made for them
        return crate::choice_study::run(&scene, full, out)
            .map_err(|e| format!("study {name} {work_precision}: {e}"));
    }
    if hosted.is_empty() {
        let hosts: Vec<String> = families::scenes()
            .iter()
            .filter(|s| !s.studies.is_empty())
            .map(|s| s.name.to_string())
            .collect();
        return Err(format!(
            "scene `{name}` hosts no study; the scenes that do are {}",
            hosts.join(", ")
        ));
    }
    let kinds: Vec<&str> = match kind {
        Some(k) if hosted.contains(&k) => vec![k],
        Some(k) => {
            return Err(format!(
                "scene `{name}` hosts no study `{k}`; its studies are {}",
                hosted.join(", ")
            ))
        }
        None => hosted.clone(),
    };
    for k in kinds {
        let failed = |e: fem_runtime::Error| format!("study {name} {k}: {e}");
        if k == crate::lambda_scatter::NAME {
            crate::lambda_scatter::scatter_run(&scene, full, out).map_err(failed)?;
            continue;
        }
        let study = Study::parse(k).ok_or_else(|| format!("unknown study `{k}`"))?;
        let scenes = if study.depends_on_data() {
            families::study_variants(&scene).map_err(failed)?
        } else {
            vec![scene.clone()]
        };
        for posed in scenes {
            if study == Study::WorkPrecision {
                crate::choice_study::run(&posed, full, out).map_err(failed)?;
                // the solvers' error against time needs the exact solution
                if matches!(posed.exact, Exact::Unknown) {
                    continue;
                }
            }
            let studies = RegistryStudies::new(posed);
            crate::studies::run(&studies, study, full, out).map_err(failed)?;
        }
    }
    Ok(())
}
