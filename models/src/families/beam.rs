//! Beams on (0, 1), clamped at both ends: Timoshenko (θ, w, thickness t) and
//! Euler–Bernoulli (w), pressed onto an obstacle below or above (docs/mathematics.md
//! §3–§4). The family's own quantities: the largest deflection, the contact intervals,
//! the thin Timoshenko beam's conditioning, and the locking of the fully integrated P1
//! pair.

use crate::data::Data;
use crate::family::{Family, Opt, Pair};
use crate::run::{run, Quantities, Report, Run};
use crate::scene::{Domain, Exact, ExactSolution, Load, Part, Posed, Scene, Support};
use crate::scenes::{exact_solution, Beam, SCENES};
use crate::{bernoulli, timoshenko_p1_full, timoshenko_p1_reduced, timoshenko_p2};
use fem_runtime::problem::{MemoryModel, ObstacleSide};
use fem_runtime::stabilization::Alpha;
use fem_runtime::{Error, IntervalMesh, Model, Result};
use std::sync::Arc;

/// The beam family.
pub struct Beams;

/// The registry's beam family.
pub static BEAMS: Beams = Beams;

/// Peak memory of a beam solve per element (Timoshenko P2–P2–P0, the largest; nested
/// levels, the LCP, the rounding experiment's repeats and the sampled profiles): 5.2–5.5
/// kB measured from 262144 to 4M elements.
pub const BYTES_PER_ELEMENT: f64 = 5.5e3;

/// The thinnest Timoshenko beam solved: below it the shear penalty `t⁻²` leaves too few
/// digits for the bending energy (on timoshenko-a the L² error against the exact
/// solution grows from 2e-8 at t = 1e-3 to 2e-6 at t = 1e-6, and Newton fails at 1e-7).
pub const MIN_THICKNESS: f64 = 1e-6;

const fn pair(
    name: &'static str,
    note: &'static str,
    alpha: f64,
    solve: crate::family::PairSolve,
) -> Pair {
    Pair {
        name,
        note,
        alpha: Alpha::FromInverseConstant(0.5),
        // C_I = 0 for every beam pair (θ''' and w'''' vanish on each element), so
        // every α > 0 is stable: α ≈ 1 for Timoshenko, ≤ 1e-2 for Euler–Bernoulli so
        // that the obstacle shift α h⁴|f| stays negligible (docs/mathematics.md)
        alpha_when_zero: alpha,
        memory: Some(MemoryModel::per_cell(BYTES_PER_ELEMENT)),
        nodal: false,
        parameters: &[],
        solve,
    }
}

static PAIRS: [Pair; 4] = [
    pair(
        "p2-p2-p0",
        "Timoshenko θ, w ∈ P2, λ ∈ P0",
        1.0,
        run::<timoshenko_p2::Model, IntervalMesh, Beams>,
    ),
    pair(
        "p1-p1-p0-reduced",
        "Timoshenko θ, w ∈ P1, one-point shear integration, λ ∈ P0",
        1.0,
        run::<timoshenko_p1_reduced::Model, IntervalMesh, Beams>,
    ),
    pair(
        "p1-p1-p0-full",
        "Timoshenko θ, w ∈ P1, exact shear integration (locks as t → 0), λ ∈ P0",
        1.0,
        run::<timoshenko_p1_full::Model, IntervalMesh, Beams>,
    ),
    pair(
        "hermite-p0",
        "Euler–Bernoulli w ∈ Hermite cubics, λ ∈ P0",
        1e-2,
        run::<bernoulli::Model, IntervalMesh, Beams>,
    ),
];

/// The load q of the beams' studies: it presses every scene onto its obstacle.
pub const STUDY_LOAD: f64 = 100.0;

/// The multiplier of a beam on a flat obstacle with a contact interval: there
/// `w'''' = 0`, so `λ = q` inside it (the point forces at its ends left out); `None` for
/// other obstacles, whose λ the closed forms do not give.
fn flat_obstacle_multiplier(
    scene: &crate::scenes::Scene,
    q: f64,
    contact_set: &[[f64; 2]],
) -> Option<Data> {
    let flat = matches!(scene.obstacle, crate::scenes::Obstacle::Constant(_));
    let &[[a, b]] = contact_set else {
        return None;
    };
    (flat && a < b).then(|| Data::shared(move |x| if (a..=b).contains(&x[0]) { q } else { 0.0 }))
}

/// The registry's Euler–Bernoulli scene with the obstacle, side and load of the
/// Timoshenko `scene` (its limit t → 0), with the study load of `scene`.
fn bernoulli_limit(scene: &Scene) -> Option<Scene> {
    let thick = scene
        .reference::<crate::scenes::Scene>()
        .filter(|s| s.beam == Beam::Timoshenko)?;
    let limit = SCENES.iter().find(|s| {
        s.beam == Beam::EulerBernoulli
            && s.obstacle == thick.obstacle
            && s.side == thick.side
            && s.load_sign == thick.load_sign
    })?;
    Some(beam_scene(limit))
}

/// The studies each built-in beam scene hosts.
fn studies(name: &str) -> Vec<&'static str> {
    match name {
        "bernoulli-flat" => vec![
            "convergence",
            "stability",
            "alpha",
            "work-precision",
            "iterations",
            "adaptivity",
        ],
        "timoshenko-a" => vec!["locking", "stability", "iterations"],
        // the model choice's chart: Euler–Bernoulli adequate at loose tolerances only
        "timoshenko-t1e-2" => vec!["work-precision"],
        _ => Vec::new(),
    }
}

/// The scene of one of the beam data sets of [`crate::scenes`].
pub fn beam_scene(old: &crate::scenes::Scene) -> Scene {
    let old = *old;
    let obstacle = old.obstacle;
    let sign = old.load_sign;
    let mut scene = Scene::new(
        old.name,
        old.description,
        "beam",
        Domain::UNIT_INTERVAL,
        256,
    )
    .with_data("f", Data::shared(move |_| sign))
    .with_data("ψ", Data::shared(move |x| obstacle.at(x[0])))
    .with_support(Part::All, Support::Clamped);
    scene.load = Some(Load {
        default: old.load,
        scales: vec!["f".into()],
        symbol: "q",
        sign: crate::scene::LoadSign::NonNegative,
    });
    scene.side = if old.side > 0.0 {
        ObstacleSide::Below
    } else {
        ObstacleSide::Above
    };
    scene.pairs = match old.beam {
        Beam::Timoshenko => {
            scene.set_parameter("t", old.thickness);
            vec!["p2-p2-p0", "p1-p1-p0-reduced", "p1-p1-p0-full"]
        }
        Beam::EulerBernoulli => vec!["hermite-p0"],
    };
    scene.exact = Exact::Of(Arc::new(move |posed: &Posed| {
        let q = posed.load.unwrap_or(1.0);
        let t = posed.parameter("t").unwrap_or(0.0);
        let e = Arc::new(exact_solution(&old, q, t)?);
        let (value, slope, curvature) = (Arc::clone(&e), Arc::clone(&e), Arc::clone(&e));
        Some(ExactSolution {
            value: Some(Data::shared(move |x| (value.w)(x[0], 0))),
            gradient: Some(Data::shared(move |x| [(slope.w)(x[0], 1), 0.0])),
            // w'' (the energy norm ‖w''‖ of Euler–Bernoulli, and its estimator's); a
            // Timoshenko beam's energy norm is not w's H² seminorm
            hessian: (old.beam == Beam::EulerBernoulli)
                .then(|| Data::shared(move |x| [[(curvature.w)(x[0], 2), 0.0], [0.0, 0.0]])),
            multiplier: flat_obstacle_multiplier(&old, q, &e.contact_set),
            contact_area: Some(e.contact_set.iter().map(|c| c[1] - c[0]).sum()),
            contact_set: Some(e.contact_set.clone()),
            total_contact_force: Some(e.total_contact_force),
            ..ExactSolution::default()
        })
    }));
    scene.studies = studies(old.name);
    // at the default q = 1 no beam touches its obstacle
    scene.study_load = (old.load == 1.0).then_some(STUDY_LOAD);
    scene.reference = Some(Arc::new(old));
    scene.in_default_job = true;
    scene
}

impl Family for Beams {
    fn dimension(&self) -> usize {
        1
    }

    fn name(&self) -> &'static str {
        "beam"
    }

    fn description(&self) -> &'static str {
        "beams on (0, 1), clamped at both ends (Timoshenko or Euler–Bernoulli)"
    }

    fn pairs(&self) -> &'static [Pair] {
        &PAIRS
    }

    fn options(&self) -> &'static [Opt] {
        &[
            Opt::Elements,
            Opt::Load,
            Opt::Thickness,
            Opt::Alpha,
            Opt::Pair,
            Opt::Solver,
            Opt::Cold,
            Opt::LinearSolver,
            Opt::Refinement,
            Opt::Plot,
            Opt::Tol,
            Opt::Marking,
            Opt::Theta,
        ]
    }

    fn scenes(&self) -> Vec<Scene> {
        SCENES.iter().map(beam_scene).collect()
    }

    /// The largest deflection against the Euler–Bernoulli beam's (the limit t → 0), solved on
    /// Hermite cubics.
    fn locking(&self) -> Option<crate::family::Locking> {
        Some(crate::family::Locking {
            quantity: "max_deflection",
            limit: crate::family::Limit::Scene(bernoulli_limit),
            quantity_words: "max |w_h|",
            limit_words: "Euler–Bernoulli",
        })
    }

    fn model_words(&self, scene: &Scene) -> &'static str {
        if scene.parameter("t").is_some() {
            "Timoshenko"
        } else {
            "Euler–Bernoulli"
        }
    }

    /// A Timoshenko scene's Euler–Bernoulli beam: the same obstacle, load and supports
    /// on Hermite cubics, without the thickness.
    fn cheaper(&self, scene: &Scene) -> Option<Scene> {
        scene.parameter("t")?;
        Some(scene.posed_for_cheaper("euler-bernoulli", "beam", vec!["hermite-p0"], |p| p != "t"))
    }

    fn aliases(&self) -> &'static [(&'static str, &'static str)] {
        &[
            ("thickness", "t"),
            ("load", "f"),
            ("obstacle", "ψ"),
            ("psi", "ψ"),
        ]
    }
}

/// The modelling error of an Euler–Bernoulli deflection `w` as a Timoshenko beam of
/// thickness `t`, and `‖w''‖`: the shear force `Q = −w'''` that w implies is in
/// equilibrium with the load and carries the shear compliance `t²` of the Timoshenko
/// beam, so by the hypercircle (Prager–Synge) identity the Timoshenko energy norm of the
/// difference of the two models' solutions is at most `t ‖w'''‖`, and equal to it to
/// leading order in t: the shear energy the thinner model leaves out
/// (`../shared/MODELS.md` §9).
fn shear_implied(w: &fem_runtime::norms::FieldView<'_>, t: f64) -> (f64, f64) {
    // ‖dᵏ w‖ as the error against 0; Gauss with 3 points is exact for the cubics' w''²
    let zero = |_: f64| 0.0;
    (t * w.error(3, &zero, 3), w.error(2, &zero, 3))
}

/// `ε t⁻² h⁻²` on `elements` elements of the unit beam: the relative size of the rounding
/// of the shear term against the bending term it leaves (near 1 no digit is left).
fn shear_conditioning(thickness: f64, elements: usize) -> f64 {
    f64::EPSILON * ((elements as f64) / thickness).powi(2)
}

impl Quantities<IntervalMesh> for Beams {
    const COARSEST: usize = 16;
    const ROUNDING_EXPERIMENT: bool = true;

    fn check(scene: &Scene, posed: &Posed) -> Result<()> {
        let Some(t) = posed.parameter("t") else {
            return Ok(());
        };
        let length = scene.domain.size().unwrap_or(1.0);
        if !(t > 0.0 && t.is_finite()) {
            return Err(Error::Input(format!(
                "thickness t = {} must be positive and finite",
                fem_runtime::problem::number(t)
            )));
        }
        if t > length {
            return Err(Error::Input(format!(
                "thickness t = {t:e} exceeds the beam's length {length}: beam theory describes slender bodies (t well below the length; t = 1e7 made the stiffness numerically singular); a thicker body is a problem of elasticity"
            )));
        }
        if t < MIN_THICKNESS {
            return Err(Error::Input(format!(
                "thickness t = {t:e} is below {MIN_THICKNESS:e} (the beam has length 1): the shear term t⁻²(w′−θ) then swamps the bending term in double precision and the discrete system is numerically singular (at t = 1e-6 rounding already dominates the discretization error); the Euler–Bernoulli model is the limit t → 0 (the scenes bernoulli-a and bernoulli-b)"
            )));
        }
        Ok(())
    }

    fn add<M: Model>(run: &Run<'_, M, IntervalMesh>, report: &mut Report) -> Result<()> {
        let solution = &run.solved.solution;
        let cells = solution.discretization.mesh.cell_count();
        let w = solution.view(run.constrained_field());
        let max_deflection = (0..=4 * cells)
            .map(|i| w.at(i as f64 / (4 * cells) as f64, 0).unwrap_or(0.0).abs())
            .fold(0.0, f64::max);
        report.set("max_deflection", max_deflection);
        report.set("contact_set", solution.contact_set());
        let thickness = run.posed.parameter("t");
        report.set("thickness", thickness);
        if let Some(t) = run
            .scene
            .richer
            .as_ref()
            .and_then(|p| p.iter().find(|(name, _)| &**name == "t"))
            .map(|(_, t)| *t)
        {
            let (estimate, norm) = shear_implied(&w, t);
            report.set("modelling_estimate", estimate);
            report.set("modelling_estimate_relative", estimate / norm);
        }

        if let (Some(t), "p1-p1-p0-full") = (thickness, run.pair.name) {
            let h = 1.0 / cells as f64;
            // from a tenth of t on: at h = t the error is already 8 %
            let stiffening = (h / t).powi(2) / 12.0;
            if stiffening > 1e-3 {
                report.warn(format!(
                    "p1-p1-p0-full locks here: its elements (h = {}) are not short against the beam's thickness (t = {}), and its fully integrated shear term t⁻²(w′ − θ) then stiffens w_h by about (h/t)²/12 = {stiffening:.0e}; it is the locking pair of the locking study, shown for comparison: use p2-p2-p0 or p1-p1-p0-reduced",
                    fem_runtime::problem::number(h),
                    fem_runtime::problem::number(t),
                ));
            }
        }
        Ok(())
    }

    /// The Hermite stiffness's `h⁻⁴` on many elements, or the shear term's `t⁻²h⁻²` of
    /// a thin Timoshenko beam.
    fn explain(
        error: Error,
        pair: &Pair,
        posed: &Posed,
        alpha: Option<f64>,
        cells: usize,
    ) -> Error {
        let failed = matches!(error, Error::NotConverged { .. } | Error::LinearSolve(_));
        if !failed {
            return error;
        }
        match posed.parameter("t") {
            None if cells > 2000 => {
                let alpha = alpha.unwrap_or(pair.alpha_when_zero);
                Error::Input(format!(
                    "{error}; at {cells} Hermite elements the bending stiffness conditions the system like h⁻⁴ (N⁴ = {:.0e}), and where the beam is in contact the multiplier's stabilization C = αh⁵ = {:.0e} lies below the rounding of the gap G − BU: use fewer elements (the error against the exact solutions is smallest near 1000; Hermite cubics reach 1e-12 at 256), or for contact a larger α",
                    (cells as f64).powi(4),
                    alpha * (1.0 / cells as f64).powi(5)
                ))
            }
            Some(t) if shear_conditioning(t, cells) > 1e-3 => Error::Input(format!(
                "{error}; at t = {} on {cells} elements the shear term t⁻²(w′ − θ) conditions the system like t⁻²h⁻², and its rounding ε t⁻²h⁻² ≈ {:.0e} is not small against the bending term the answer lives in: use fewer elements, a larger t, or the Euler–Bernoulli limit (bernoulli-a, bernoulli-b)",
                fem_runtime::problem::number(t),
                shear_conditioning(t, cells)
            )),
            _ => error,
        }
    }
}
