//! The beams as the studies see them ([`StudyScene`]): a scene at q = 100 (contact),
//! its pairs, the condition number of the LCP matrix as the stability measure, the
//! multiplier per cell, and the beams' own study, locking as t → 0.

use crate::beams::{self, Pair, Profiles, Report, Request};
use crate::models::scenes::{exact_solution, Beam, Scene, SCENES};
use crate::plot::{self, Axes, Series};
use crate::studies::{
    io, output, write_csv_named, ExactMultiplier, Measure, Plan, Row, Run, StabilityRow, Study,
    StudyScene,
};
use fem_runtime::obstacle::VariationalSolver;
use fem_runtime::{Error, Result};
use std::path::Path;

/// The load magnitude of every beam study: q = 100 presses each scene onto its obstacle.
pub const STUDY_LOAD: f64 = 100.0;

/// A beam scene in the studies, at q = [`STUDY_LOAD`].
#[derive(Clone, Copy, Debug)]
pub struct BeamStudies {
    /// The scene.
    pub scene: Scene,
}

impl BeamStudies {
    /// The studies of `scene`.
    pub fn new(scene: Scene) -> Self {
        Self { scene }
    }

    /// The request of a run: the plain method (α = 0) is solved as a QP by clarabel.
    pub fn request(&self, run: &Run) -> Result<Request> {
        let mut r = Request::new(self.scene);
        r.elements = run.size;
        r.load = STUDY_LOAD;
        r.pair = Some(Pair::parse(run.pair, self.scene.beam)?);
        r.solver = run.solver;
        r.nested_from = run.nested.then_some(16);
        r.alpha = run.alpha;
        if run.alpha == Some(0.0) {
            r.plain = true;
            r.solver = VariationalSolver::Clarabel;
        }
        Ok(r)
    }

    fn default_pair(&self) -> &'static str {
        Pair::default_for(self.scene.beam).name()
    }
}

fn row(report: &Report, pair: &'static str, scene: &Scene) -> Row {
    let exact = exact_solution(scene, report.load, report.thickness.unwrap_or(0.0));
    let edge = report.contact_set.first().map_or(f64::NAN, |c| c[0]);
    Row {
        pair,
        size: report.elements,
        h: 1.0 / report.elements as f64,
        cells: report.elements,
        dofs: report.dofs,
        alpha: report.alpha,
        error_l2: report.error_l2,
        error_h1: report.error_h1,
        error_multiplier: None,
        total_contact_force: report.total_contact_force,
        force_error: exact
            .as_ref()
            .map(|e| (report.total_contact_force - e.total_contact_force).abs()),
        contact: edge,
        contact_error: exact
            .as_ref()
            .and_then(|e| e.contact_set.first())
            .map(|c| (edge - c[0]).abs()),
        iterations: report.iterations,
        seconds: report.seconds,
        kkt_residual: report.complementarity_residual,
        warnings: report.warnings.clone(),
    }
}

fn ladder(from: u32, to: u32) -> Vec<usize> {
    (from..=to).map(|k| 1 << k).collect()
}

impl StudyScene for BeamStudies {
    fn name(&self) -> String {
        self.scene.name.into()
    }

    fn setting(&self) -> String {
        format!("{} q = {STUDY_LOAD}", self.scene.name)
    }

    fn size_name(&self) -> &'static str {
        "elements"
    }

    fn h(&self, size: usize) -> f64 {
        1.0 / size as f64
    }

    fn contact_names(&self) -> [&'static str; 2] {
        ["contact start", "edge error"]
    }

    fn pairs(&self) -> Vec<&'static str> {
        let default = Pair::default_for(self.scene.beam);
        std::iter::once(default)
            .chain(
                Pair::ALL
                    .into_iter()
                    .filter(|p| p.beam() == self.scene.beam && *p != default),
            )
            .map(Pair::name)
            .collect()
    }

    fn plan(&self, study: Study, pair: &'static str, full: bool) -> Plan {
        let (sizes, cold_max, alphas) = match study {
            Study::Convergence => (ladder(4, if full { 14 } else { 10 }), 0, vec![]),
            Study::Stability => {
                let mut sizes = vec![8, 16, 32, 64, 128];
                if full {
                    sizes.push(256);
                }
                (sizes, 0, vec![])
            }
            Study::Alpha => (
                vec![if full { 1024 } else { 128 }],
                0,
                (-8..=8).map(|k| Some(10f64.powi(k))).collect(),
            ),
            Study::WorkPrecision => (
                ladder(5, if full { 15 } else { 12 }),
                if full { 8192 } else { 2048 },
                vec![],
            ),
            Study::Iterations => (
                ladder(5, if full { 17 } else { 15 }),
                if full { 8192 } else { 2048 },
                vec![],
            ),
            Study::Locking => (vec![if full { 1024 } else { 256 }], 0, vec![]),
        };
        Plan {
            pair,
            sizes,
            cold_max,
            alphas,
        }
    }

    fn profiles(&self, full: bool) -> Plan {
        Plan {
            pair: self.default_pair(),
            sizes: vec![if full { 1024 } else { 256 }],
            cold_max: 0,
            alphas: vec![Some(0.0), Some(1e-2), Some(1.0)],
        }
    }

    fn solve(&self, run: &Run) -> Result<Row> {
        let (report, _) = beams::solve(&self.request(run)?)?;
        Ok(row(&report, run.pair, &self.scene))
    }

    fn inverse_constant(&self, pair: &'static str, size: usize) -> Result<f64> {
        // C_I = 0 for every beam pair: θ''' and w'''' vanish on each element
        let (report, _) = beams::solve(&self.request(&Run::new(pair, size))?)?;
        Ok(report.inverse_constant)
    }

    fn exact_contact(&self) -> Option<f64> {
        exact_solution(&self.scene, STUDY_LOAD, self.scene.thickness)
            .and_then(|e| e.contact_set.first().map(|c| c[0]))
    }

    fn stability_pairs(&self) -> Vec<&'static str> {
        vec![self.default_pair()]
    }

    fn measure(&self) -> Measure {
        crate::studies::inf_sup_measure()
    }

    /// The one measure of every family, on the registry's scene of this name.
    fn stability(&self, pair: &'static str, size: usize) -> Result<StabilityRow> {
        crate::registry_studies::RegistryStudies::of(self.scene.name)?.stability(pair, size)
    }

    /// `(x, λ_h)` at the cell midpoints.
    fn multiplier_profile(&self, run: &Run) -> Result<Vec<(f64, f64)>> {
        let (_, p) = beams::solve(&self.request(run)?)?;
        Ok(p.cell_x.into_iter().zip(p.lambda).collect())
    }

    /// Where the exact solution has a contact interval on a flat obstacle
    /// (`bernoulli-flat`): there `w'''' = 0`, so `λ = q` inside (the point forces at its
    /// edges are left out).
    fn exact_multiplier(&self) -> Option<ExactMultiplier> {
        let e = exact_solution(&self.scene, STUDY_LOAD, self.scene.thickness)?;
        let contact = *e.contact_set.first()?;
        (contact[0] < contact[1]).then(|| ExactMultiplier {
            contact,
            lambda: Box::new(move |x| {
                if (contact[0]..=contact[1]).contains(&x) {
                    STUDY_LOAD
                } else {
                    0.0
                }
            }),
        })
    }

    fn profile_window(&self) -> [f64; 2] {
        match self.exact_multiplier() {
            Some(e) => [e.contact[0] - 0.03, e.contact[1] + 0.03],
            None => [0.0, 1.0],
        }
    }

    fn locking(&self, full: bool, out: &Path) -> Result<()> {
        run_locking(&self.scene, full, out)
    }
}

/// One thickness of the locking study.
#[derive(Clone, Debug)]
pub struct LockingRow {
    /// Element pair.
    pub pair: Pair,
    /// Thickness.
    pub thickness: f64,
    /// Largest |w|.
    pub max_deflection: f64,
    /// `‖w_h − w_EB‖_L2` against the Euler–Bernoulli reference.
    pub difference_to_bernoulli: f64,
    /// Relative energy difference to the Euler–Bernoulli reference.
    pub energy_difference: f64,
}

/// Linear interpolation of sampled values at `x`.
fn sample(p: &Profiles, x: f64) -> f64 {
    let n = p.x.len() - 1;
    let i = ((x * n as f64).floor() as usize).min(n - 1);
    let t = x * n as f64 - i as f64;
    p.w[i] * (1.0 - t) + p.w[i + 1] * t
}

fn l2_difference(a: &Profiles, b: &Profiles) -> f64 {
    let n = 4000;
    let sum: f64 = (0..n)
        .map(|i| {
            let x = (i as f64 + 0.5) / n as f64;
            (sample(a, x) - sample(b, x)).powi(2)
        })
        .sum();
    (sum / n as f64).sqrt()
}

/// The Euler–Bernoulli scene with the obstacle, side and load of a Timoshenko scene: its
/// limit as t → 0.
pub fn bernoulli_limit(scene: &Scene) -> Result<Scene> {
    SCENES
        .into_iter()
        .find(|s| {
            s.beam == Beam::EulerBernoulli
                && s.obstacle == scene.obstacle
                && s.side == scene.side
                && s.load_sign == scene.load_sign
        })
        .filter(|_| scene.beam == Beam::Timoshenko)
        .ok_or_else(|| {
            Error::Input(format!(
                "scene `{}` has no locking study: it needs a Timoshenko scene whose Euler–Bernoulli limit is a scene",
                scene.name
            ))
        })
}

/// A Timoshenko `scene` at q = 100 on `elements` elements for each pair and thickness,
/// against its Euler–Bernoulli limit ([`bernoulli_limit`]) on 4096 Hermite elements.
pub fn locking(
    scene: &Scene,
    elements: usize,
    thicknesses: &[f64],
    pairs: &[Pair],
) -> Result<(Report, Vec<LockingRow>)> {
    let mut reference_request = Request::new(bernoulli_limit(scene)?);
    reference_request.elements = 4096;
    reference_request.load = STUDY_LOAD;
    let (reference, reference_profiles) = beams::solve(&reference_request)?;
    let mut rows = Vec::new();
    for &pair in pairs {
        for &t in thicknesses {
            let mut r = Request::new(*scene);
            r.elements = elements;
            r.load = STUDY_LOAD;
            r.pair = Some(pair);
            r.thickness = Some(t);
            r.refinement_steps = if t < 1e-4 { 3 } else { 1 };
            let (report, profiles) = beams::solve(&r)?;
            rows.push(LockingRow {
                pair,
                thickness: t,
                max_deflection: report.max_deflection,
                difference_to_bernoulli: l2_difference(&profiles, &reference_profiles),
                energy_difference: ((report.energy - reference.energy) / reference.energy).abs(),
            });
        }
    }
    Ok((reference, rows))
}

fn run_locking(scene: &Scene, full: bool, out: &Path) -> Result<()> {
    let thicknesses = [1e-1, 3e-2, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 1e-5];
    let pairs = [
        Pair::TimoshenkoP2,
        Pair::TimoshenkoP1Reduced,
        Pair::TimoshenkoP1Full,
    ];
    let elements = BeamStudies::new(*scene)
        .plan(Study::Locking, "", full)
        .sizes[0];
    let (reference, rows) = locking(scene, elements, &thicknesses, &pairs)?;
    let name = scene.name;
    println!(
        "locking: {name}, q = {STUDY_LOAD}, {elements} elements; Euler–Bernoulli reference (4096 Hermite elements): max |w| = {:.6e}",
        reference.max_deflection
    );
    println!(
        "{:<18} {:>8} {:>12} {:>14} {:>12}",
        "pair", "t", "max |w|", "‖w − w_EB‖", "ΔJ/J"
    );
    for r in &rows {
        println!(
            "{:<18} {:>8.0e} {:>12.6e} {:>14.4e} {:>12.3e}",
            r.pair.name(),
            r.thickness,
            r.max_deflection,
            r.difference_to_bernoulli,
            r.energy_difference
        );
    }
    let series = |f: &dyn Fn(&LockingRow) -> f64| -> Vec<Series> {
        pairs
            .iter()
            .map(|p| {
                Series::marked(
                    p.name(),
                    rows.iter()
                        .filter(|r| r.pair == *p)
                        .map(|r| (r.thickness, f(r)))
                        .collect(),
                )
            })
            .collect()
    };
    let mut deflection = series(&|r| r.max_deflection);
    deflection.push(Series::line(
        "Euler–Bernoulli",
        vec![
            (thicknesses[thicknesses.len() - 1], reference.max_deflection),
            (thicknesses[0], reference.max_deflection),
        ],
    ));
    let log = |y| Axes {
        x: "t",
        y,
        log_x: true,
        log_y: true,
    };
    plot::stacked(
        &output(out, name, Study::Locking, "svg"),
        &[
            (
                format!("{name} q = {STUDY_LOAD}: max |w| against t (locking collapses it)"),
                log("max |w|"),
                deflection,
            ),
            (
                "‖w_h(t) − w_EB‖_L2: converges to Euler–Bernoulli as t → 0".into(),
                log("difference"),
                series(&|r| r.difference_to_bernoulli),
            ),
        ],
    )
    .map_err(io)?;
    write_csv_named(
        &output(out, name, Study::Locking, "csv"),
        "pair",
        "thickness,max_deflection,difference_to_bernoulli,energy_difference",
        &pairs.map(Pair::name),
        &rows
            .iter()
            .map(|r| {
                vec![
                    pairs.iter().position(|p| *p == r.pair).unwrap_or(0) as f64,
                    r.thickness,
                    r.max_deflection,
                    r.difference_to_bernoulli,
                    r.energy_difference,
                ]
            })
            .collect::<Vec<_>>(),
    )
    .map_err(io)
}
