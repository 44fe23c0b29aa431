//! Kirchhoff plates (docs/mathematics.md §9) on the C¹ Argyris quintic and the
//! non-conforming Morley quadratic, with or without an obstacle. The family's own
//! quantities: the centre deflection against the series, the largest deflection, the
//! contact area with its holes filled, and λ_h over the contact interior read raw and
//! patch-averaged (the cure of the Argyris multiplier's scatter).

use crate::data::Data;
use crate::families::edge_resultants;
use crate::family::{Family, Opt, Pair, PairSolve};
use crate::geometry::{halving_sizes, Fields};
use crate::kirchhoff::{kirchhoff_argyris_p0, kirchhoff_argyris_p1disc, kirchhoff_morley_p0};
use crate::run::{run, Quantities, Report, Run};
use crate::scene::{Adjustment, Domain, Load, Part, Posed, Scene, StudyVariant, Support};
use fem_runtime::element::triangle::{AffineMap, TriangleBasis, TriangleField};
use fem_runtime::problem::{MemoryModel, ObstacleSide};
use fem_runtime::stabilization::Alpha;
use fem_runtime::{Error, Model, Result, TriangleMesh};
use serde::Serialize;
use std::sync::Arc;

/// The Kirchhoff plate family.
pub struct KirchhoffPlates;

/// The registry's Kirchhoff family.
pub static KIRCHHOFF: KirchhoffPlates = KirchhoffPlates;

/// The default α of the Argyris pairs as a fraction of `1/C_I` (docs/mathematics.md §1:
/// stable for `0 < α < 1/C_I`; ½ is the middle of the range).
pub const ALPHA_FRACTION: f64 = 0.5;

/// The default α of Morley–P0, where `C_I = 0` (every α > 0 is stable): the term adds
/// `α h⁴ |T|` to the multiplier's diagonal and shifts the obstacle by `α h⁴ f` where
/// λ = 0: at q = 20, 0.04 % of the gap 0.002 at N = 32 and 10 % at N = 8 (α = 1 shifted
/// it by 4 % at N = 32 and grew the contact area from 0.25 to 0.31); below 1e-4 Newton
/// needs more iterations on the coarse levels (40 at N = 4 for α = 1e-12).
pub const MORLEY_ALPHA: f64 = 0.01;

/// The contact interior of the λ-scatter measure: contact cells whose centroid is at
/// least this far from every cell outside the contact set (a fifth of the contact
/// radius, about 0.25, at q = 20 on the flat obstacle), and two vertex rings in.
pub const INTERIOR_MARGIN: f64 = 0.05;

const fn pair(name: &'static str, note: &'static str, solve: PairSolve) -> Pair {
    Pair {
        name,
        note,
        alpha: Alpha::FromInverseConstant(ALPHA_FRACTION),
        alpha_when_zero: MORLEY_ALPHA,
        // the pair's own model: `KirchhoffPlates::memory`
        memory: None,
        nodal: false,
        parameters: &[],
        solve,
    }
}

static PAIRS: [Pair; 3] = [
    pair(
        "argyris-p0",
        "w ∈ Argyris (P5, C¹), λ ∈ P0; α = ½/C_I",
        run::<kirchhoff_argyris_p0::Model, TriangleMesh, KirchhoffPlates>,
    ),
    pair(
        "argyris-p1disc",
        "w ∈ Argyris, λ ∈ P1 discontinuous; α = ½/C_I",
        run::<kirchhoff_argyris_p1disc::Model, TriangleMesh, KirchhoffPlates>,
    ),
    pair(
        "morley-p0",
        "w ∈ Morley (P2, non-conforming), λ ∈ P0; C_I = 0, α = 0.01",
        run::<kirchhoff_morley_p0::Model, TriangleMesh, KirchhoffPlates>,
    ),
];

/// A named obstacle of the Kirchhoff scenes, above the plate (`w ≤ ψ`), `r` the distance
/// from the centre of the square: `ψ = gap + curvature · r²` (`Δ²ψ = 0`, so λ = q in
/// the interior of contact).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NamedObstacle {
    /// `flat` or `curved`.
    pub name: &'static str,
    /// The gap at the centre.
    pub gap: f64,
    /// The coefficient of r².
    pub curvature: f64,
}

/// The obstacles `--obstacle` names.
pub const OBSTACLES: [NamedObstacle; 2] = [
    NamedObstacle {
        name: "flat",
        gap: 0.002,
        curvature: 0.0,
    },
    NamedObstacle {
        name: "curved",
        gap: 0.002,
        curvature: 0.01,
    },
];

/// What a Kirchhoff scene's report compares with, and how it names its obstacle.
#[derive(Clone, Debug)]
pub struct KirchhoffFacts {
    /// The obstacle's name (`none`, `flat`, `curved`).
    pub obstacle: &'static str,
}

/// Puts `obstacle` (or none) above the plate of `scene`.
fn place(scene: &mut Scene, obstacle: Option<NamedObstacle>) {
    match obstacle {
        Some(o) => {
            let (gap, curvature) = (o.gap, o.curvature);
            scene.set_data(
                "ψ",
                Data::shared(move |x| {
                    let r2 = (x[0] - 0.5).powi(2) + (x[1] - 0.5).powi(2);
                    gap + curvature * r2
                }),
            );
            scene.obstacle = true;
        }
        None => scene.obstacle = false,
    }
    scene.reference = Some(Arc::new(KirchhoffFacts {
        obstacle: obstacle.map_or("none", |o| o.name),
    }));
}

fn kirchhoff_scene(
    name: &'static str,
    description: &'static str,
    load: f64,
    obstacle: Option<NamedObstacle>,
    mesh_size: usize,
) -> Scene {
    let mut scene = Scene::new(
        name,
        description,
        "kirchhoff",
        Domain::square(0.0, 1.0),
        mesh_size,
    )
    .with_parameter("D", 1.0)
    .with_parameter("ν", 0.3)
    .with_data("f", Data::shared(|_| 1.0))
    .with_support(Part::All, Support::Clamped);
    scene.load = Some(Load {
        default: load,
        scales: vec!["f".into()],
        symbol: "q",
        sign: crate::scene::LoadSign::Any,
    });
    scene.side = ObstacleSide::Above;
    place(&mut scene, obstacle);
    scene.studies = match obstacle {
        Some(_) => vec!["convergence", "lambda-scatter", "stability", "adaptivity"],
        None => vec!["convergence", "work-precision"],
    };
    scene.study_variants = match obstacle {
        // two loads, flat and curved: contact sets of different shapes and sizes
        Some(_) => [5.0, 20.0]
            .into_iter()
            .flat_map(|q| {
                ["flat", "curved"].map(|o| StudyVariant {
                    label: format!("q{q}-{o}"),
                    load: Some(q),
                    adjustments: vec![Adjustment::Obstacle(o.into())],
                })
            })
            .collect(),
        // both supports against their series
        None => [
            ("clamped", Support::Clamped),
            ("simply-supported", Support::SimplySupported { hard: false }),
        ]
        .into_iter()
        .map(|(label, support)| StudyVariant {
            label: label.into(),
            load: None,
            adjustments: vec![Adjustment::Support(support)],
        })
        .collect(),
    };
    scene
}

impl Family for KirchhoffPlates {
    fn name(&self) -> &'static str {
        "kirchhoff"
    }

    fn description(&self) -> &'static str {
        "Kirchhoff plates (Argyris, Morley) on triangles, with or without an obstacle"
    }

    fn pairs(&self) -> &'static [Pair] {
        &PAIRS
    }

    fn options(&self) -> &'static [Opt] {
        &[
            Opt::MeshSize,
            Opt::Load,
            Opt::Thickness,
            Opt::Alpha,
            Opt::Pair,
            Opt::Solver,
            Opt::Cold,
            Opt::Support,
            Opt::Obstacle,
            Opt::Tol,
            Opt::Marking,
            Opt::Theta,
            Opt::EdgeResultants,
        ]
    }

    fn scenes(&self) -> Vec<Scene> {
        vec![
            kirchhoff_scene(
                "kirchhoff-square",
                "unit square Kirchhoff plate (clamped or simply supported), uniform load, no contact; centre deflection against the series",
                1.0,
                None,
                16,
            ),
            kirchhoff_scene(
                "kirchhoff-obstacle",
                "clamped unit square Kirchhoff plate pushed up by q = 5 against w ≤ 0.002 (--obstacle curved: 0.002 + 0.01 r²)",
                5.0,
                Some(OBSTACLES[0]),
                32,
            ),
        ]
    }

    fn model_words(&self, _: &Scene) -> &'static str {
        "Kirchhoff"
    }

    fn aliases(&self) -> &'static [(&'static str, &'static str)] {
        &[
            ("bending_stiffness", "D"),
            ("poisson_ratio", "ν"),
            ("nu", "ν"),
            ("load", "f"),
            ("obstacle", "ψ"),
            ("psi", "ψ"),
            ("thickness", "t"),
            ("shear_correction", "κ"),
            ("kappa", "κ"),
        ]
    }

    /// A Kirchhoff plate given its thickness is the thin limit of a Reissner–Mindlin
    /// plate: `t` (and `κ`, 5/6 where not given) say how far it is from it.
    fn richer_parameters(&self) -> &'static [&'static str] {
        &["t", "κ"]
    }

    /// The Reissner–Mindlin plate of the same domain, supports, load and obstacle, with
    /// the scene's `D`, `ν` and its stated thickness (a simple support is the soft one,
    /// `w = 0` alone, whose boundary layer the modelling estimate counts; write
    /// `simply-supported-hard` for the other), on the locking-free pair (the plain pair
    /// locks as t → 0). `None` where the scene states no thickness.
    fn richer(&self, scene: &Scene) -> Option<Scene> {
        let t = scene.richer_parameter("t")?;
        // the models' own boundary data are not the same support
        if scene.has_model_boundary_data() {
            return None;
        }
        let kappa = scene.richer_parameter("κ").unwrap_or(5.0 / 6.0);
        let mut thick = scene.clone();
        thick.name = format!("{}-mindlin", scene.name).into();
        thick.family = "plate";
        thick.richer = None;
        thick.set_parameter("κ", kappa);
        thick.set_parameter("t", t);
        thick.pairs = vec!["p1-p2-p0"];
        // the Kirchhoff closed forms are not the thicker plate's
        thick.exact = crate::scene::Exact::Unknown;
        thick.reference = None;
        thick.studies = Vec::new();
        thick.study_variants = Vec::new();
        Some(thick)
    }

    /// `--obstacle none|flat|curved` places the named obstacle; supports as every family.
    fn adjust(&self, scene: &mut Scene, adjustment: &Adjustment) -> Result<()> {
        match adjustment {
            Adjustment::Obstacle(name) => {
                let obstacle = match name.as_str() {
                    "none" => None,
                    other => Some(
                        OBSTACLES
                            .iter()
                            .copied()
                            .find(|o| o.name == other)
                            .ok_or_else(|| {
                                Error::Input(format!(
                                    "unknown obstacle `{other}`; the obstacles are none, flat (w ≤ 0.002), curved (w ≤ 0.002 + 0.01 r²)"
                                ))
                            })?,
                    ),
                };
                place(scene, obstacle);
                Ok(())
            }
            Adjustment::Support(support) => {
                for s in &mut scene.supports {
                    s.support = *support;
                }
                Ok(())
            }
            Adjustment::NoObstacle => {
                place(scene, None);
                Ok(())
            }
        }
    }
}

/// The estimated peak memory of a Kirchhoff solve on the N×N×2 mesh, in bytes: without
/// recovery of the multiplier 0.93 GB at N = 128 (kirchhoff-square) scaled by `N^2.3`
/// (the factor's fill; 0.6 GB at 104 with the obstacle); with it, 6.5 GB at 128 scaled
/// by `N²` (5.0 GB at 112). The recovery (an LU of the saddle-point system, where
/// `C = αh⁴` falls below the rounding of `G − BU`) is assumed for a scene with an
/// obstacle from N = 112 on, where the default α needs it.
pub fn argyris_memory_bytes(mesh_size: usize, obstacle: bool) -> f64 {
    let n = mesh_size as f64 / 128.0;
    if obstacle && mesh_size >= 112 {
        6.5e9 * n * n
    } else {
        0.93e9 * n.powf(2.3)
    }
}

/// The unobstructed centre deflection of the simply supported unit square under a unit
/// load with D = 1 from Navier's double sine series (Timoshenko and Woinowsky-Krieger
/// §30): `16/π⁶ Σ_{m,n odd} (−1)^{(m+n)/2−1} / (mn(m²+n²)²)` = 0.0040623527; 200 odd
/// terms each way leave an error below 1e-12 (the terms fall like `1/m⁵`).
pub fn navier_centre_coefficient() -> f64 {
    let mut sum = 0.0;
    for m in (1..400usize).step_by(2) {
        for n in (1..400usize).step_by(2) {
            let sign = if ((m + n) / 2 - 1) % 2 == 0 {
                1.0
            } else {
                -1.0
            };
            let (m, n) = (m as f64, n as f64);
            sum += sign / (m * n * (m * m + n * n).powi(2));
        }
    }
    16.0 / std::f64::consts::PI.powi(6) * sum
}

/// The clamped unit square's centre deflection in units of `q a⁴/D` (Timoshenko and
/// Woinowsky-Krieger, *Theory of Plates and Shells*, Table 35, ν = 0.3; six digits).
pub const CLAMPED_CENTRE_COEFFICIENT: f64 = 0.00126532;

/// How λ is read in the contact interior.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum MultiplierRecovery {
    /// λ_h as computed.
    Raw,
    /// The patch average: each vertex gets the area-weighted mean of λ_h over the cells
    /// around it, each cell the mean of its three vertex values (a continuous P1 field,
    /// the local L² projection of λ_h onto the patch's constants).
    PatchAverage,
    /// The patch average applied twice: a support of about two vertex rings.
    TwicePatchAverage,
}

/// λ over the contact interior against its exact value there.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct InteriorMultiplier {
    /// How λ is read.
    pub recovery: MultiplierRecovery,
    /// Number of interior cells.
    pub cells: usize,
    /// The exact λ there: `q` (`λ = s(DΔ²ψ − f)` with `Δ²ψ = 0`, `s = −1`, `f = q`).
    pub exact: f64,
    /// Smallest value (P1disc: over the cells' vertex values).
    pub min: f64,
    /// Largest value.
    pub max: f64,
    /// Mean value.
    pub mean: f64,
    /// `max |λ − exact| / exact`.
    pub max_relative_error: f64,
}

impl Quantities<TriangleMesh> for KirchhoffPlates {
    /// Morley's own model; Argyris's measured one on the N×N×2 square (the recovery
    /// regime included), its fit `a + b log₂(cells)` elsewhere.
    fn memory<M: Model>(_: &Pair, scene: &Scene, n: usize) -> MemoryModel {
        let argyris = M::FIELDS.iter().any(|f| f.element.needs_transformation())
            && M::FIELDS
                .iter()
                .any(|f| f.element == fem_runtime::ElementKind::Argyris);
        if !argyris {
            return MemoryModel::of_model::<M>();
        }
        match scene.domain {
            Domain::Rectangle { cells, .. } if n > 0 => {
                let triangles = 2.0 * (n * n * cells[0] * cells[1]) as f64;
                MemoryModel::per_cell(argyris_memory_bytes(n, scene.obstacle) / triangles)
            }
            _ => MemoryModel {
                per_cell: -4.6e3,
                per_cell_log: 2.2e3,
                floor: 10e3,
            },
        }
    }

    fn check(scene: &Scene, posed: &Posed) -> Result<()> {
        if let Some(nu) = posed.parameter("ν") {
            if !(nu > -1.0 && nu < 0.5) {
                return Err(Error::Input(format!(
                    "Poisson's ratio ν = {nu} must lie in (−1, ½)"
                )));
            }
        }
        if scene.richer_parameter("t").is_some() && scene.has_model_boundary_data() {
            return Err(Error::Input(
                "a thickness poses the Reissner–Mindlin plate this Kirchhoff plate stands for, but a `dirichlet` support (the model's own w = g) names no support of that plate (its `dirichlet` holds the rotations too): name the supports (clamped, simply-supported, simply-supported-hard, free)".into(),
            ));
        }
        if scene.richer_parameter("κ").is_some() && scene.richer_parameter("t").is_none() {
            return Err(Error::Input(
                "the shear correction κ is given without a thickness t: κ belongs to the Reissner–Mindlin plate of that thickness that the Kirchhoff plate stands for; give the thickness too".into(),
            ));
        }
        for (name, words) in [("t", "thickness"), ("κ", "shear correction")] {
            if let Some(v) = scene.richer_parameter(name) {
                if !(v.is_finite() && v > 0.0) {
                    return Err(Error::Input(format!(
                        "{words} {name} = {} must be positive and finite",
                        fem_runtime::problem::number(v)
                    )));
                }
            }
        }
        if let Some(t) = scene.richer_parameter("t") {
            super::plate::thin_enough(scene, t)?;
        }
        Ok(())
    }

    fn add<M: Model>(run: &Run<'_, M, TriangleMesh>, report: &mut Report) -> Result<()> {
        let solution = &run.solved.solution;
        let q = run.posed.load.unwrap_or(0.0);
        let facts = run.scene.reference::<KirchhoffFacts>();
        report.set(
            "support",
            run.scene
                .supports
                .iter()
                .map(|s| s.support.name())
                .collect::<Vec<_>>()
                .join(", "),
        );
        report.set(
            "obstacle",
            match (run.scene.obstacle, facts) {
                (false, _) => "none",
                (true, Some(f)) => f.obstacle,
                (true, None) => "ψ",
            },
        );
        if let Some(t) = run.scene.richer_parameter("t") {
            // the Reissner–Mindlin plate it stands for
            report.set("thickness", t);
            report.set(
                "shear_correction",
                run.scene.richer_parameter("κ").unwrap_or(5.0 / 6.0),
            );
            if matches!(run.scene.domain, Domain::Disk { .. }) {
                report.warn("on a disk the Argyris plate is its inscribed polygon, whose corners make ∇Δw singular: the modelling estimate grows with refinement (clamped, t = 0.01: 5.4 %, 8.0 %, 11.5 % at N = 4, 8, 16) and bounds nothing here");
            }
            if modelling_estimate(run).is_none() {
                report.warn(format!(
                    "the thickness t = {} is not used: {} gives no modelling estimate (its ∇Δw vanishes on every cell), so how far this Kirchhoff plate is from the Reissner–Mindlin one is not known; argyris-p0 gives it",
                    fem_runtime::problem::number(t),
                    run.pair.name
                ));
            }
        }
        if run.scene.richer.is_some() {
            if let Some([interior, layer]) = modelling_estimate(run) {
                let estimate = interior.hypot(layer);
                report.set("modelling_estimate", estimate);
                report.set("modelling_estimate_shear", interior);
                report.set("modelling_estimate_layer", layer);
                if let Some(norm) = run.solved.estimate.as_ref().map(|e| e.energy_norm) {
                    report.set("modelling_estimate_relative", estimate / norm);
                }
            }
        }
        let w = run.constrained_field();
        let view = solution.view(w);
        if run.scene.edge_resultants {
            add_edge_resultants(run, &view, report);
        }
        let basis = TriangleBasis::new(view.map.element());
        report.set("max_deflection", max_deflection(&view, &basis));
        if let Some(centre) = run.scene.domain.centre() {
            let deflection = run.value_at(&centre).ok_or_else(|| {
                Error::Input(format!(
                    "the centre ({}, {}) is outside the mesh",
                    centre[0], centre[1]
                ))
            })?;
            report.set("centre_deflection", deflection);
            if !run.scene.obstacle {
                if let Some((reference, source)) = series_reference(run.scene, run.posed) {
                    report.set("reference_centre_deflection", reference);
                    report.set("reference_source", source);
                    // q = 0: both deflections are 0 exactly, and so is the error
                    let relative = if reference != 0.0 {
                        Some((deflection - reference) / reference)
                    } else {
                        (deflection == 0.0).then_some(0.0)
                    };
                    report.set("relative_error", relative);
                }
            }
        }
        let Fields::Triangles { mesh, cell, .. } = run.fields else {
            return Ok(());
        };
        if run.scene.obstacle {
            let contact: Vec<bool> = cell
                .iter()
                .find(|(n, _)| *n == "contact")
                .map(|(_, v)| v.iter().map(|&s| s > 0.0).collect())
                .unwrap_or_default();
            report.solve.contact_area = Some(filled_area(mesh, &contact));
            // λ = q in the contact interior holds for the built-in scenes' uniform load
            // and obstacles with Δ²ψ = 0 (their facts); a scene file's f and ψ make λ
            // another function, against which q would report a false error
            let interior = if q > 0.0 && facts.is_some() {
                interior_cells(mesh, &contact)
            } else {
                Vec::new()
            };
            let morley = run.pair.name.starts_with("morley");
            // Morley's patch average measured worse than its raw λ_h (max relative
            // error 1.16 against 0.44 at N = 32, q = 20): its scatter is not the Argyris
            // line-force tail
            let recovery = if morley {
                MultiplierRecovery::Raw
            } else {
                MultiplierRecovery::PatchAverage
            };
            let statistics = |r| interior_statistics(solution, &interior, r, q);
            report.set("interior_multiplier", statistics(recovery));
            report.set(
                "interior_multiplier_raw",
                statistics(MultiplierRecovery::Raw),
            );
            report.set(
                "interior_multiplier_twice_averaged",
                statistics(MultiplierRecovery::TwicePatchAverage),
            );
            if q > 0.0 && facts.is_some() {
                report.set("multiplier_layer", layer_profile(solution, &contact, q));
            }
            let n = run.settings.mesh_size.unwrap_or(run.scene.mesh_size);
            let newton = run.settings.solver.nests();
            if run.settings.nested && newton {
                let sizes = halving_sizes(n, true, Self::COARSEST, false);
                if let Some(w) = super::plate::cold_coarsest_warning(&sizes, Self::COARSEST) {
                    report.warn(w);
                }
            }
        }
        Ok(())
    }
}

/// The series' centre deflection of an unobstructed unit square, `c q a⁴/D` (clamped:
/// the tabulated coefficient; simply supported: Navier's series summed), with its
/// source; `None` for another domain or mixed supports.
fn series_reference(scene: &Scene, posed: &Posed) -> Option<(f64, &'static str)> {
    let Domain::Rectangle { x, y, .. } = scene.domain else {
        return None;
    };
    if x != [0.0, 1.0] || y != [0.0, 1.0] {
        return None;
    }
    let supports: Vec<Support> = scene.supports.iter().map(|s| s.support).collect();
    let (coefficient, source) = match supports.as_slice() {
        [Support::Clamped] => (
            CLAMPED_CENTRE_COEFFICIENT,
            "Timoshenko and Woinowsky-Krieger, Theory of Plates and Shells, Table 35 (ν = 0.3), six digits: a relative difference below 4e-6 is the table's rounding",
        ),
        [Support::SimplySupported { .. }] => (
            navier_centre_coefficient(),
            "Navier's double series, summed (Timoshenko and Woinowsky-Krieger §30)",
        ),
        _ => return None,
    };
    Some((coefficient * posed.load? / posed.parameter("D")?, source))
}

/// `max |w_h|` over each cell's vertices, edge midpoints and centroid.
fn max_deflection(
    view: &fem_runtime::element::triangle::TriangleField,
    basis: &TriangleBasis,
) -> f64 {
    const POINTS: [[f64; 2]; 7] = [
        [0.0, 0.0],
        [1.0, 0.0],
        [0.0, 1.0],
        [0.5, 0.0],
        [0.5, 0.5],
        [0.0, 0.5],
        [1.0 / 3.0, 1.0 / 3.0],
    ];
    let mut largest = 0.0f64;
    for c in 0..view.mesh.cell_count() {
        for xi in POINTS {
            largest = largest.max(view.value(basis, c, xi).abs());
        }
    }
    largest
}

/// The area enclosed by the outer boundary of the cells in `contact`: the contact cells
/// and every other cell that cannot be reached from a boundary cell through non-contact
/// cells across edges (a hole of zero λ_h inside the contact set counts as contact,
/// docs/mathematics.md §9). Cells touched only partly count fully, so the area carries
/// an O(h) error at the free boundary.
pub fn filled_area(mesh: &TriangleMesh, contact: &[bool]) -> f64 {
    let cells = mesh.cell_count();
    if contact.len() != cells {
        return 0.0;
    }
    let mut outside = vec![false; cells];
    let mut stack = Vec::new();
    for &(e, _) in mesh.boundary_edges() {
        let (c, _) = mesh.edge_cells(e);
        if !contact[c] && !outside[c] {
            outside[c] = true;
            stack.push(c);
        }
    }
    while let Some(c) = stack.pop() {
        for e in mesh.cell_edges(c) {
            let (a, b) = mesh.edge_cells(e);
            for n in std::iter::once(a).chain(b) {
                if !contact[n] && !outside[n] {
                    outside[n] = true;
                    stack.push(n);
                }
            }
        }
    }
    // from +0: an empty f64 sum is −0
    (0..cells)
        .filter(|&c| !outside[c])
        .fold(0.0, |sum, c| sum + mesh.area(c))
}

/// The contact interior: contact cells whose three vertices are in contact (every cell
/// around them is a contact cell), and the same once more, so that every interior cell
/// is two vertex rings away from the free boundary (where λ carries a line force), and
/// whose centroid is at least [`INTERIOR_MARGIN`] from the centroid of every cell
/// outside the contact set.
pub fn interior_cells(mesh: &TriangleMesh, contact: &[bool]) -> Vec<usize> {
    if contact.len() != mesh.cell_count() {
        return Vec::new();
    }
    let distance = frontier_distances(mesh, contact);
    let erode = |inside: &[bool]| -> Vec<bool> {
        let mut vertex = vec![true; mesh.vertex_count()];
        for (c, &on) in inside.iter().enumerate() {
            if !on {
                for v in mesh.cell(c) {
                    vertex[v] = false;
                }
            }
        }
        (0..mesh.cell_count())
            .map(|c| inside[c] && mesh.cell(c).iter().all(|&v| vertex[v]))
            .collect()
    };
    let once = erode(contact);
    let twice = erode(&once);
    (0..mesh.cell_count())
        .filter(|&c| twice[c] && distance[c] >= INTERIOR_MARGIN)
        .collect()
}

/// For each contact cell, the distance from its centroid to the nearest centroid of a
/// cell outside the contact set (∞ when there is none); 0 for the cells outside.
pub fn frontier_distances(mesh: &TriangleMesh, contact: &[bool]) -> Vec<f64> {
    let centroid = |c: usize| {
        let x = mesh.cell_coordinates(c);
        [(x[0] + x[2] + x[4]) / 3.0, (x[1] + x[3] + x[5]) / 3.0]
    };
    // only the cells outside contact next to it can be nearest
    let frontier: Vec<[f64; 2]> = (0..mesh.cell_count())
        .filter(|&c| {
            !contact[c]
                && mesh.cell_edges(c).iter().any(|&e| {
                    let (a, b) = mesh.edge_cells(e);
                    contact[a] || b.is_some_and(|b| contact[b])
                })
        })
        .map(centroid)
        .collect();
    (0..mesh.cell_count())
        .map(|c| {
            if !contact[c] {
                return 0.0;
            }
            let x = centroid(c);
            frontier
                .iter()
                .map(|y| (x[0] - y[0]).hypot(x[1] - y[1]))
                .fold(f64::INFINITY, f64::min)
        })
        .collect()
}

/// The cell values `values` patch-averaged `passes` times
/// ([`MultiplierRecovery::PatchAverage`]).
pub fn averaged_cells(mesh: &TriangleMesh, values: &[f64], passes: usize) -> Vec<f64> {
    let mut cells = values.to_vec();
    for _ in 0..passes {
        let at_vertices = patch_average(mesh, &cells);
        cells = (0..mesh.cell_count())
            .map(|c| mesh.cell(c).iter().map(|&v| at_vertices[v]).sum::<f64>() / 3.0)
            .collect();
    }
    cells
}

/// One band of the multiplier's layer next to the free boundary: the contact cells whose
/// distance to the nearest cell outside contact ([`frontier_distances`]) lies in
/// `[k h, (k+1) h)`, h the largest cell diameter.
#[derive(Clone, Copy, Debug, serde::Serialize, serde::Deserialize)]
pub struct LayerBand {
    /// k.
    pub distance_in_cells: usize,
    /// Cells in the band.
    pub cells: usize,
    /// `max |λ_h − q| / q` over them (cell means).
    pub max_relative_error: f64,
    /// The same for the patch average.
    pub patch_average_max_relative_error: f64,
}

/// The layer profile of λ_h next to the free boundary, bands k = 0, 1, … (see
/// [`LayerBand`]), against the exact λ = q of the contact interior.
pub fn layer_profile(
    solution: &fem_runtime::obstacle::ObstacleSolution<TriangleMesh>,
    contact: &[bool],
    q: f64,
) -> Vec<LayerBand> {
    let mesh = &solution.discretization.mesh;
    let distance = frontier_distances(mesh, contact);
    let h = mesh.max_h();
    let raw = cell_means(solution);
    let averaged = averaged_cells(mesh, &raw, 1);
    let mut bands: Vec<LayerBand> = Vec::new();
    for c in (0..mesh.cell_count()).filter(|&c| contact[c] && distance[c].is_finite()) {
        let k = (distance[c] / h).floor() as usize;
        while bands.len() <= k {
            bands.push(LayerBand {
                distance_in_cells: bands.len(),
                cells: 0,
                max_relative_error: 0.0,
                patch_average_max_relative_error: 0.0,
            });
        }
        let band = &mut bands[k];
        band.cells += 1;
        band.max_relative_error = band.max_relative_error.max((raw[c] - q).abs() / q);
        band.patch_average_max_relative_error = band
            .patch_average_max_relative_error
            .max((averaged[c] - q).abs() / q);
    }
    bands
}

/// The multiplier's cell means (P0: its values; P1disc: the mean of the three).
pub fn cell_means(solution: &fem_runtime::obstacle::ObstacleSolution<TriangleMesh>) -> Vec<f64> {
    let d = &solution.discretization;
    let map = d.dofs.map(d.multiplier_field).expect("the multiplier");
    let lambda = solution.field(d.multiplier_field);
    (0..d.mesh.cell_count())
        .map(|c| {
            let dofs = map.cell_dofs(c);
            dofs.iter().map(|&k| lambda[k]).sum::<f64>() / dofs.len() as f64
        })
        .collect()
}

/// The patch average of the cell values `means` at every vertex
/// ([`MultiplierRecovery::PatchAverage`]).
fn patch_average(mesh: &TriangleMesh, means: &[f64]) -> Vec<f64> {
    let (mut sum, mut weight) = (
        vec![0.0; mesh.vertex_count()],
        vec![0.0; mesh.vertex_count()],
    );
    for (c, &m) in means.iter().enumerate() {
        let area = mesh.area(c);
        for v in mesh.cell(c) {
            sum[v] += area * m;
            weight[v] += area;
        }
    }
    sum.iter().zip(&weight).map(|(s, w)| s / w).collect()
}

/// λ over `interior` read as `recovery`, against the exact `q`; `None` for no cells.
pub fn interior_statistics(
    solution: &fem_runtime::obstacle::ObstacleSolution<TriangleMesh>,
    interior: &[usize],
    recovery: MultiplierRecovery,
    q: f64,
) -> Option<InteriorMultiplier> {
    if interior.is_empty() {
        return None;
    }
    let d = &solution.discretization;
    let values: Vec<f64> = match recovery {
        MultiplierRecovery::Raw => {
            let map = d.dofs.map(d.multiplier_field)?;
            let lambda = solution.field(d.multiplier_field);
            interior
                .iter()
                .flat_map(|&c| map.cell_dofs(c).iter().map(|&k| lambda[k]))
                .collect()
        }
        MultiplierRecovery::PatchAverage | MultiplierRecovery::TwicePatchAverage => {
            let passes = if recovery == MultiplierRecovery::PatchAverage {
                1
            } else {
                2
            };
            let cells = averaged_cells(&d.mesh, &cell_means(solution), passes);
            interior.iter().map(|&c| cells[c]).collect()
        }
    };
    let min = values.iter().cloned().fold(f64::INFINITY, f64::min);
    let max = values.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    Some(InteriorMultiplier {
        recovery,
        cells: interior.len(),
        exact: q,
        min,
        max,
        mean: values.iter().sum::<f64>() / values.len() as f64,
        max_relative_error: (max - q).abs().max((min - q).abs()) / q,
    })
}

/// The edge resultants of a Kirchhoff solve ([`edge_resultants::kirchhoff`]) and, where
/// the scene has a thickness, their modelling estimate `modelling_estimate_edge`
/// ([`edge_resultants::twisting_share`]); a warning for elements without third
/// derivatives.
fn add_edge_resultants<M: Model>(
    run: &Run<'_, M, TriangleMesh>,
    view: &TriangleField<'_>,
    report: &mut Report,
) {
    let own = |name: &str| {
        M::PARAMS
            .iter()
            .position(|p| *p == name)
            .map(|k| run.solved.params[k])
    };
    let (Some(d), Some(nu)) = (own("D"), own("ν")) else {
        return;
    };
    if view.map.element().degree() < 3 {
        report.warn(format!(
            "{} gives no edge resultants (its shear force −D∇Δw vanishes on every cell and its moments are constant per cell); argyris-p0 gives them",
            run.pair.name
        ));
        return;
    }
    let layered = edge_resultants::rotations_free_markers(run.scene, view.mesh);
    let layer = run.scene.richer_parameter("t").map(|t| {
        edge_resultants::layer_width(t, run.scene.richer_parameter("κ").unwrap_or(5.0 / 6.0))
    });
    let resultants = edge_resultants::kirchhoff(view, d, nu, &layered, layer);
    if run.scene.richer.is_some() {
        report.set(
            "modelling_estimate_edge",
            edge_resultants::twisting_share(&resultants, &layered),
        );
    }
    report.set("edge_resultants", resultants);
}

/// The modelling error of a Kirchhoff deflection as a Reissner–Mindlin plate whose
/// parameters `richer` holds (thickness `t`, shear correction `κ`), as
/// `[interior, layer]` in the energy norm.
///
/// - Interior: the shear force `Q = −D ∇(Δw)` that w implies is in equilibrium with the
///   load and carries the Mindlin shear compliance `t² / (6κ(1−ν)D)`; by the hypercircle
///   identity the shear energy the thinner model leaves out is
///   `t² D / (6κ(1−ν)) ‖∇Δw‖²` (`../shared/MODELS.md` §9).
/// - Layer: where the Mindlin rotations are free on the boundary (a soft simple support,
///   a free edge) the twisting moment `M_ns = −D(1−ν) n·∇∇w·τ` of the Kirchhoff solution
///   does not vanish as the Mindlin one must; the rotation's boundary layer of width
///   `δ = t/√(12κ)` (Arnold–Falk) that cancels it holds the energy
///   `2δ/(D(1−ν)) ∫ M_ns² ds` (the layer `φ(ρ) = A e^{−ρ/δ}` of
///   `D(1−ν)/2 φ″ = S φ` with `D(1−ν)/2 φ′(0) = M_ns`).
///
/// `None` for elements of degree below 3, whose `∇Δw` vanishes on every cell (Morley:
/// its shear lives in the jumps, which this estimate does not read).
fn modelling_estimate<M: Model>(run: &Run<'_, M, TriangleMesh>) -> Option<[f64; 2]> {
    let richer = run.scene.richer.as_ref()?;
    let get = |name: &str| richer.iter().find(|(n, _)| &**n == name).map(|(_, v)| *v);
    let t = get("t")?;
    let kappa = get("κ").unwrap_or(5.0 / 6.0);
    let own = |name: &str| {
        M::PARAMS
            .iter()
            .position(|p| *p == name)
            .map(|k| run.solved.params[k])
    };
    let (d, nu) = (own("D")?, own("ν")?);
    let solution = &run.solved.solution;
    let view = solution.view(run.constrained_field());
    if view.map.element().degree() < 3 {
        return None;
    }
    let mesh = view.mesh;
    let basis = TriangleBasis::new(view.map.element());
    let rule = fem_runtime::reference::triangle::TriangleRule::exact_for_degree(
        2 * (view.map.element().degree() - 3),
    );
    let mut shear = 0.0;
    for c in 0..mesh.cell_count() {
        let map = AffineMap::of(mesh, c);
        for (&xi, &weight) in rule.points.iter().zip(&rule.weights) {
            let third = view.third_derivatives(&basis, &map, c, xi);
            let grad_laplacian = [0, 1].map(|i| third[i][0][0] + third[i][1][1]);
            shear += weight * map.det * (grad_laplacian[0].powi(2) + grad_laplacian[1].powi(2));
        }
    }
    let interior = t * (d / (6.0 * kappa * (1.0 - nu))).sqrt() * shear.sqrt();

    let layered = edge_resultants::rotations_free_markers(run.scene, mesh);
    let line = fem_runtime::gauss_legendre(4);
    let mut twisting = 0.0;
    for &(e, marker) in mesh.boundary_edges() {
        if !layered.contains(&marker) {
            continue;
        }
        let (c, _) = mesh.edge_cells(e);
        let map = AffineMap::of(mesh, c);
        let [a, b] = mesh.edges()[e].map(|v| mesh.vertices()[v]);
        let length = (b[0] - a[0]).hypot(b[1] - a[1]);
        let tau = [(b[0] - a[0]) / length, (b[1] - a[1]) / length];
        let n = [tau[1], -tau[0]];
        for (&s, &weight) in line.points.iter().zip(&line.weights) {
            let x = [a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])];
            let h = view.hessian(&basis, &map, c, map.reference_point(x));
            let m = (0..2)
                .map(|i| (0..2).map(|j| n[i] * h[i][j] * tau[j]).sum::<f64>())
                .sum::<f64>();
            twisting += weight * length * m * m;
        }
    }
    let delta = edge_resultants::layer_width(t, kappa);
    let layer = (2.0 * delta * d * (1.0 - nu) * twisting).sqrt();
    Some([interior, layer])
}

#[cfg(test)]
mod tests {
    use super::*;
    use fem_runtime::Diagonal;

    /// A ring of contact cells around a hole: the hole counts, the cells outside the
    /// ring do not; without contact the area is +0.
    #[test]
    fn the_contact_area_fills_holes_but_not_the_outside() {
        let mesh = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 5, 5, Diagonal::Right).unwrap();
        let centre = |c: usize| {
            let x = mesh.cell_coordinates(c);
            [(x[0] + x[2] + x[4]) / 3.0, (x[1] + x[3] + x[5]) / 3.0]
        };
        // the cells of the squares 1..4 × 1..4 (in units of 0.2) except the middle one
        let contact: Vec<bool> = (0..mesh.cell_count())
            .map(|c| {
                let [x, y] = centre(c).map(|v| (v * 5.0).floor() as i32);
                (1..4).contains(&x) && (1..4).contains(&y) && !(x == 2 && y == 2)
            })
            .collect();
        assert_eq!(contact.iter().filter(|&&c| c).count(), 16);
        let area = filled_area(&mesh, &contact);
        assert!((area - 9.0 * 0.04).abs() < 1e-12, "{area}");
        let none = filled_area(&mesh, &vec![false; mesh.cell_count()]);
        assert!(none == 0.0 && none.is_sign_positive());
    }

    /// The contact interior and its distances: on a contact disk, interior cells are at
    /// least the margin from the outside and two rings in; the layer bands count every
    /// contact cell once.
    #[test]
    fn interior_cells_keep_their_distance_from_the_free_boundary() {
        let mesh = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 32, 32, Diagonal::Right).unwrap();
        let centre = |c: usize| {
            let x = mesh.cell_coordinates(c);
            [(x[0] + x[2] + x[4]) / 3.0, (x[1] + x[3] + x[5]) / 3.0]
        };
        let contact: Vec<bool> = (0..mesh.cell_count())
            .map(|c| {
                let [x, y] = centre(c);
                (x - 0.5).hypot(y - 0.5) < 0.3
            })
            .collect();
        let distance = frontier_distances(&mesh, &contact);
        let interior = interior_cells(&mesh, &contact);
        assert!(!interior.is_empty());
        let h = mesh.max_h();
        let radius = |c: usize| (centre(c)[0] - 0.5).hypot(centre(c)[1] - 0.5);
        for &c in &interior {
            // the cells outside the disk next to it surround r = 0.3 within a diameter
            assert!(radius(c) < 0.3 - INTERIOR_MARGIN + h, "cell {c}");
            assert!(distance[c] >= INTERIOR_MARGIN);
        }
        // and every cell well inside is interior: two vertex rings lie within 4 h
        for c in (0..mesh.cell_count()).filter(|&c| radius(c) < 0.3 - INTERIOR_MARGIN - 4.0 * h) {
            assert!(interior.contains(&c), "cell {c} at r = {}", radius(c));
        }
        // a cell right at the edge of the disk is not interior
        let edge = (0..mesh.cell_count())
            .filter(|&c| contact[c])
            .max_by(|&a, &b| radius(a).total_cmp(&radius(b)))
            .unwrap();
        assert!(!interior.contains(&edge));
        assert!(distance[edge] < 2.0 * h);
    }
}
