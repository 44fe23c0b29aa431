//! Signorini contact (docs/contact.md): a linear elastic body on a rigid foundation,
//! frictionless, the contact pressure a multiplier on the edges of the contact boundary
//! Γ_C (the model's `facets:`), stabilized. Pairs P1 or P2 displacements with a P0 or a
//! continuous P1 multiplier on Γ_C. The family's own quantities are the equilibrium of
//! the contact force with the load, the contact half-width and peak pressure, and
//! against Hertz's pressure where the scene has it, the relative L² error, the best
//! fit's and the checkerboard measure.

mod checks;
mod facts;
mod file;
mod quantities;

use crate::contact_scenes::{
    gap_block_mesh, hertz_mesh, ContactBody, ContactScene, CONTACT_SCENES,
};
use crate::data::Data;
use crate::family::{Family, FieldError, FileKeys, Opt, Pair};
use crate::hertz::Hertz;
use crate::report::{Profile, Report};
use crate::run::{run, Quantities, Run};
use crate::scene::{Domain, Generator, Load, LoadSign, Part, PartSupport, Posed, Scene, Support};
pub use crate::signorini::{lame, Plane};
use crate::signorini::{signorini_p1, signorini_p1_p1, signorini_p2, signorini_p2_p1, Multiplier};
use checks::{pressed_start, refuse_pressure_on_contact, rigid_motions};
use facts::ContactData;
pub use facts::{contact_tangent, material_parameters, ContactFacts, CONTACT_PART, LOAD_PART};
use fem_runtime::obstacle::{Discretization, FirstStart, LevelStart, NearNullSpace};
use fem_runtime::problem::ALPHA_WHEN_CI_VANISHES;
use fem_runtime::stabilization::Alpha;
use fem_runtime::{DirichletPart, Error, Model, TriangleMesh};
use file::DataScales;
use quantities::{
    checkerboard, checkerboard_against, compare_gap_block, compare_with_hertz, p1_corners,
    solution_of, SignoriniSolution,
};

type Result<T, E = Error> = std::result::Result<T, E>;
use std::sync::Arc;

/// The contact family.
pub struct Contact;

/// The registry's contact family.
pub static CONTACT: Contact = Contact;

/// The family's error measure ([`Family::error_measure`]): the pressure's relative L²
/// error on Γ_C, against Hertz's or a scene file's exact pressure.
pub const PRESSURE_ERROR: (&str, &str) = ("pressure_l2_error", "pressure's relative L² error");

/// The contact half-widths `b/R` the Hertz scenes accept (`--load`): Hertz's theory
/// wants b ≪ R (at b/R = 0.34 the peak was 2 % low, at 3.4 the error 91 %), and below
/// about 1e-7 the gap `x²/2R` is lost against the rounding of coordinates of size R.
pub const HERTZ_HALF_WIDTH_RANGE: (f64, f64) = (1e-6, 0.1);

/// The largest b/h of the graded meshes (b/h = 512 has 0.4M cells on the quarter disc).
pub const MAX_GRADED_SIZE: usize = 512;

/// The ratio `λ_L/μ_L` (`2ν/(1−2ν)` in plane strain) beyond which a P1 displacement
/// locks volumetrically: on the gap block at 32×32 cells with E* fixed, P1–P0's pressure
/// error was 1.12× P2–P0's at ν = 0.45 (ratio 9), 1.15× at 0.47, 1.23× at 0.48 (24),
/// 1.6× at 0.49 (49), 2.6× at 0.495 and 7× at 0.4999, while P2 stayed near 0.18.
pub const LOCKING_RATIO: f64 = 20.0;

/// The warning for a P1 displacement (`pair` `p1-…`) of a nearly incompressible body
/// (`λ_L/μ_L` beyond [`LOCKING_RATIO`]): it locks, the pressure oscillates and grows;
/// the cure is a P2 displacement.
pub fn volumetric_locking(pair: &str, mu: f64, lambda: f64) -> Option<String> {
    let ratio = lambda / mu;
    (pair.starts_with("p1") && ratio > LOCKING_RATIO).then(|| {
        format!(
            "λ_L/μ_L = {ratio:.3e} (ν near ½ in plane strain): a P1 displacement locks volumetrically, and its pressure errs by several times the best fit's; take a P2 displacement (--pair p2-p0)"
        )
    })
}

/// The equilibrium residual beyond which a report warns: Newton meets it to about
/// 1e-13, the polished interior point (α = 0) to about 1e-12.
pub const EQUILIBRIUM_WARNING: f64 = 1e-8;

/// The relative difference between the load as discretized and as integrated by 4-point
/// Gauss beyond which a report warns: a pressure the model's quadrature does not
/// integrate (a kink inside an edge: 7e-2 on the 2 × 1 block with q = max(0, x − 1.9)).
/// A smooth pressure differs by far less (1e-7 for 1 + 0.1 sin x at h = 0.25), below the
/// discretization error of λ_h.
pub const QUADRATURE_WARNING: f64 = 1e-6;

const fn pair(name: &'static str, note: &'static str, solve: crate::family::PairSolve) -> Pair {
    Pair {
        name,
        note,
        alpha: Alpha::FromInverseConstant(0.5),
        alpha_when_zero: ALPHA_WHEN_CI_VANISHES,
        memory: None,
        nodal: false,
        parameters: &[],
        solve,
    }
}

static PAIRS: [Pair; 4] = [
    pair(
        "p1-p0",
        "u ∈ [P1]², λ ∈ P0 on the edges of Γ_C, stabilized",
        run::<signorini_p1::Model, TriangleMesh, Contact>,
    ),
    pair(
        "p2-p0",
        "u ∈ [P2]², λ ∈ P0 on the edges of Γ_C, stabilized",
        run::<signorini_p2::Model, TriangleMesh, Contact>,
    ),
    pair(
        "p1-p1",
        "u ∈ [P1]², λ continuous P1 on Γ_C, stabilized",
        run::<signorini_p1_p1::Model, TriangleMesh, Contact>,
    ),
    pair(
        "p2-p1",
        "u ∈ [P2]², λ continuous P1 on Γ_C, stabilized",
        run::<signorini_p2_p1::Model, TriangleMesh, Contact>,
    ),
];

/// The registry's scene of a built-in contact body (a changed copy of one of
/// [`CONTACT_SCENES`] gives that body's scene: a larger block, another material).
pub fn contact_scene(old: &ContactScene) -> Scene {
    let facts = ContactFacts {
        young: old.young,
        poisson: old.poisson,
        plane: old.plane,
        direction: [0.0, -1.0],
        centre: match old.body {
            ContactBody::Block { .. } => None,
            _ => Some(0.0),
        },
        body: Some(old.body),
    };
    let Layout {
        domain,
        contact,
        loaded,
        axis,
        pressure,
        gap,
        symbol,
    } = layout(old, facts);
    let mut scene = Scene::new(old.name, old.description, "contact", domain, old.mesh_size);
    for (name, value) in material_parameters(&facts).expect("valid built-in material") {
        scene.set_parameter(name, value);
    }
    scene.set_data("g", gap);
    scene.set_data("q", Data::shared(move |_| pressure));
    scene.load = Some(Load {
        default: old.load,
        scales: vec!["q".into()],
        symbol,
        sign: crate::scene::LoadSign::Positive,
    });
    scene.facets = vec![
        (CONTACT_PART.into(), Part::named(contact)),
        (LOAD_PART.into(), Part::named(loaded)),
    ];
    scene.supports.push(PartSupport {
        part: Part::named(axis),
        support: Support::Roller { normal: [1.0, 0.0] },
        key: None,
    });
    scene.accuracy = old.accuracy();
    scene.pairs = match old.body {
        ContactBody::GapBlock { .. } => vec!["p1-p0", "p2-p0"],
        _ => PAIRS.iter().map(|p| p.name).collect(),
    };
    scene.studies = match old.body {
        ContactBody::Cylinder { .. } => {
            vec!["convergence", "alpha", "work-precision", "adaptivity"]
        }
        _ => Vec::new(),
    };
    scene.in_default_job = true;
    scene.reference = Some(Arc::new(facts));
    scene
}

/// How a built-in body is posed: its mesh, the names of its contact, loaded and held
/// parts, the pressure per unit load, the gap and the load's symbol.
struct Layout {
    domain: Domain,
    contact: &'static str,
    loaded: &'static str,
    axis: &'static str,
    pressure: f64,
    gap: Data,
    symbol: &'static str,
}

/// The [`Layout`] of a built-in contact body.
fn layout(old: &ContactScene, facts: ContactFacts) -> Layout {
    let default_load = old.load;
    let hertz_at = move |load: Option<f64>| facts.hertz(load.unwrap_or(default_load));
    let (domain, contact, loaded, axis, pressure, gap, symbol) = match old.body {
        ContactBody::Block { width, height } => (
            Domain::Rectangle {
                x: [0.0, width],
                y: [0.0, height],
                cells: [((width / height).round() as usize).max(1), 1],
                diagonal: fem_runtime::Diagonal::Right,
            },
            "bottom",
            "top",
            "left",
            1.0,
            Data::from(zero as fn(&[f64]) -> f64),
            "q",
        ),
        ContactBody::Cylinder { radius } => (
            Domain::Generated(Generator {
                description: format!("quarter disc of radius {radius} graded to the contact")
                    .into(),
                size_meaning: "cells per contact half-width b/h",
                max_size: MAX_GRADED_SIZE,
                build: Arc::new(move |n, load| {
                    let hertz = hertz_at(load).expect("a cylinder");
                    let h = hertz.half_width() / n as f64;
                    // uniform cells a little beyond b; the grading tightens with b/h
                    // (docs/contact.md §4)
                    let grading = (4.0 / n as f64).min(0.25);
                    hertz_mesh(radius, 1.25 * hertz.half_width(), h, grading)
                }),
            }),
            "arc",
            "top",
            "axis",
            // the half carries P/2 over its top of width R
            1.0 / (2.0 * radius),
            // the gap to the plane y = 0, measured vertically
            Data::shared(|x| x[1]),
            "P",
        ),
        ContactBody::GapBlock {
            half_width,
            height,
            radius,
            ..
        } => (
            Domain::Generated(Generator {
                description: format!(
                    "half block (0,{half_width})×(0,{height}) graded to the contact"
                )
                .into(),
                size_meaning: "cells per contact half-width b/h",
                max_size: MAX_GRADED_SIZE,
                build: Arc::new(move |n, load| {
                    let hertz = hertz_at(load).expect("a gap block");
                    let b = hertz.half_width();
                    let grading = (4.0 / n as f64).min(0.25);
                    gap_block_mesh(half_width, height, 1.25 * b, b / n as f64, grading)
                }),
            }),
            "bottom",
            "top",
            "left",
            1.0 / (2.0 * half_width),
            Data::shared(move |x| x[0] * x[0] / (2.0 * radius)),
            "P",
        ),
    };
    Layout {
        domain,
        contact,
        loaded,
        axis,
        pressure,
        gap,
        symbol,
    }
}

impl Family for Contact {
    fn name(&self) -> &'static str {
        "contact"
    }

    fn description(&self) -> &'static str {
        "Signorini contact of an elastic body on a rigid foundation, the pressure on Γ_C"
    }

    fn pairs(&self) -> &'static [Pair] {
        &PAIRS
    }

    fn options(&self) -> &'static [Opt] {
        &[
            Opt::MeshSize,
            Opt::Load,
            Opt::Alpha,
            Opt::Pair,
            Opt::Cold,
            Opt::Solver,
            Opt::Plot,
            Opt::Tol,
            Opt::Marking,
            Opt::Theta,
        ]
    }

    fn scenes(&self) -> Vec<Scene> {
        CONTACT_SCENES.iter().map(contact_scene).collect()
    }

    fn aliases(&self) -> &'static [(&'static str, &'static str)] {
        &[("pressure", "q"), ("gap", "g")]
    }

    fn facet_keys(&self) -> &'static [(&'static str, &'static str)] {
        &[("contact", CONTACT_PART), ("load", LOAD_PART)]
    }

    fn scaled_load(&self) -> (&'static str, LoadSign) {
        ("q", LoadSign::Positive)
    }

    fn accuracy_key(&self) -> &'static str {
        "pressure"
    }

    fn error_measure(&self) -> Option<(&'static str, &'static str)> {
        Some(PRESSURE_ERROR)
    }

    fn read_file(&self, keys: FileKeys<'_>, scene: &mut Scene) -> Result<(), FieldError> {
        file::read(keys, scene)
    }

    fn check_file(&self, scene: &Scene) -> Result<(), FieldError> {
        let facts = facts(scene).map_err(|e| ("material".to_string(), e.to_string()))?;
        file::check(scene, &facts)
    }
}

/// The scene's own description; scenes of this family always carry one.
fn facts(scene: &Scene) -> Result<ContactFacts> {
    scene.reference::<ContactFacts>().copied().ok_or_else(|| {
        Error::Input(format!(
            "scene `{}` states no material (E, ν) and contact direction",
            scene.name
        ))
    })
}

/// The boundary markers of the scene's facet part `name` on `mesh`.
fn facet_markers(scene: &Scene, mesh: &TriangleMesh, name: &str) -> Result<Vec<u32>> {
    let part = scene
        .facets
        .iter()
        .find(|(n, _)| n == name)
        .map(|(_, p)| p.clone())
        .ok_or_else(|| {
            Error::Input(format!(
                "scene `{}` names no boundary part {name}",
                scene.name
            ))
        })?;
    Ok(match crate::geometry::Geometry::part(mesh, &part)? {
        DirichletPart::Markers(m) => m,
        DirichletPart::All => mesh.boundary_edges().iter().map(|&(_, m)| m).collect(),
    })
}

/// The markers held along x and along y by the scene's rollers (for the checks of the
/// rigid motions, which see the discretization, and of a support on Γ_C).
fn rollers(scene: &Scene) -> Vec<(&Part, [f64; 2])> {
    scene
        .supports
        .iter()
        .filter_map(|s| match s.support {
            Support::Roller { normal } => Some((&s.part, normal)),
            _ => None,
        })
        .collect()
}

impl Quantities<TriangleMesh> for Contact {
    const ACCURACY_MEASURE: Option<(&'static str, &'static str)> = Some(PRESSURE_ERROR);

    fn check(scene: &Scene, posed: &Posed) -> Result<()> {
        let facts = facts(scene)?;
        // its sign is checked with the load ([`crate::scene::LoadSign::Positive`])
        let load = posed.load.unwrap_or(1.0);
        if let Some(hertz) = facts.hertz(load) {
            let ratio = hertz.half_width() / hertz.radius;
            if !(HERTZ_HALF_WIDTH_RANGE.0..=HERTZ_HALF_WIDTH_RANGE.1).contains(&ratio) {
                let at = |r: f64| load * (r / ratio).powi(2);
                return Err(Error::Input(format!(
                    "--load {} gives a contact half-width b = {ratio:.3e} R; `{}` compares with Hertz's theory, which needs b ≪ R, and the mesh resolves b only while the gap b²/2R is well above the rounding of R: loads from {:.3e} to {:.3e} keep {:e} ≤ b/R ≤ {}",
                    fem_runtime::problem::number(load),
                    scene.name,
                    at(HERTZ_HALF_WIDTH_RANGE.0),
                    at(HERTZ_HALF_WIDTH_RANGE.1),
                    HERTZ_HALF_WIDTH_RANGE.0,
                    HERTZ_HALF_WIDTH_RANGE.1
                )));
            }
        }
        lame(facts.young, facts.poisson, facts.plane)?;
        // a roller across n_c on Γ_C itself fights the contact constraint for u·n_c
        let contact = scene.facets.iter().find(|(n, _)| n == CONTACT_PART);
        for (part, normal) in rollers(scene) {
            let across = normal[0] * facts.direction[0] + normal[1] * facts.direction[1];
            if contact.is_some_and(|(_, c)| c == part) && across.abs() > 1e-12 {
                return Err(Error::Input(format!(
                    "scene `{}`: the contact boundary ({}) also has a roller along ({}, {}), which has a component along the contact direction: the support and the contact constraint both fix u·n_c there; drop the support on the contact part",
                    scene.name,
                    part.names().join(", "),
                    normal[0],
                    normal[1]
                )));
            }
        }
        Ok(())
    }

    fn check_on_mesh(scene: &Scene, posed: &Posed, mesh: &TriangleMesh) -> Result<()> {
        let facts = facts(scene)?;
        let contact = facet_markers(scene, mesh, CONTACT_PART)?;
        let loaded = facet_markers(scene, mesh, LOAD_PART)?;
        let pressure = pressure_of(scene, posed);
        let input = input(&facts, &contact, &loaded, pressure.as_data_fn());
        refuse_pressure_on_contact(mesh, &input)?;
        let scales = DataScales::of(
            mesh,
            &contact,
            &loaded,
            &data_of(scene, "q"),
            &data_of(scene, "g"),
            facts.young,
            file::translation_held(scene, &facts),
        );
        let load = posed.load.unwrap_or(1.0);
        // the scene's own load passed these checks when it was read: here the load is
        // the command line's
        let given = if scene.load.as_ref().is_some_and(|l| l.default != load) {
            format!(" with --load {}", fem_runtime::problem::number(load))
        } else {
            String::new()
        };
        scales.check(load).map_err(|(key, m)| {
            Error::Input(format!("scene `{}`{given}: field `{key}`: {m}", scene.name))
        })
    }

    fn start(scene: &Scene, _: &Posed) -> Option<Box<FirstStart<'static, TriangleMesh>>> {
        let direction = facts(scene).ok()?.direction;
        let name = scene.name.to_string();
        Some(Box::new(move |d: &Discretization<TriangleMesh>| {
            // a load that does not hold the body on its foundation is the pressure's
            // fault: named by its key
            Ok(match pressed_start(d, direction)? {
                LevelStart::TooCoarse(m)
                    if m.contains("rigid motion is not prevented")
                        || m.contains("tips the body") =>
                {
                    LevelStart::TooCoarse(format!("scene `{name}`: field `data.pressure`: {m}"))
                }
                other => other,
            })
        }))
    }

    fn near_null_space() -> Option<Box<NearNullSpace<'static, TriangleMesh>>> {
        Some(Box::new(rigid_motions))
    }

    fn add<M: Model>(run: &Run<'_, M, TriangleMesh>, report: &mut Report) -> Result<()> {
        let facts = facts(run.scene)?;
        let mesh = &run.solved.solution.discretization.mesh;
        let contact = facet_markers(run.scene, mesh, CONTACT_PART)?;
        let loaded = facet_markers(run.scene, mesh, LOAD_PART)?;
        let pressure = pressure_of(run.scene, run.posed);
        let input = input(&facts, &contact, &loaded, pressure.as_data_fn());
        let solution = solution_of::<M>(&input, facts.direction, run.solved);
        // the pressure's size, which the equilibrium's rounding is relative to
        let magnitude = pressure_of(run.scene, run.posed);
        let magnitude = file::resultant_and_magnitude(mesh, &loaded, &magnitude).1;
        add_quantities(&facts, run, &solution, magnitude, report);
        if let Some((x, turn)) = p1_corners(&solution).first() {
            report.warn(format!(
                "boundary.contact: the continuous P1 pressure of `{}` passes a corner of Γ_C at ({}, {}), where the boundary turns by {turn:.0}°: one value serves both sides, and a pressure that jumps there (pressed on one side, free on the other) comes out wrong near it at every mesh size; use a P0 pair (p1-p0, p2-p0), whose values are per edge",
                run.pair.name,
                fem_runtime::problem::number(x[0]),
                fem_runtime::problem::number(x[1])
            ));
        }
        for (name, part) in &run.scene.facets {
            let key = if name == CONTACT_PART {
                "boundary.contact"
            } else {
                "boundary.load"
            };
            for w in crate::geometry::Geometry::interior_part_warnings(mesh, &part.names()) {
                report.warn(format!("{key}: {w}"));
            }
        }
        Ok(())
    }

    fn profile<M: Model>(run: &Run<'_, M, TriangleMesh>, report: &Report) -> Option<Profile> {
        let facts = facts(run.scene).ok()?;
        let Some(hertz) = facts.hertz(run.posed.load?) else {
            return exact_profile(run, &facts);
        };
        let b = hertz.half_width();
        let mut computed: Vec<(f64, f64, f64)> = pressure_steps(run);
        computed.retain(|e| e.0 <= 1.5 * b);
        let exact = (0..=300)
            .map(|i| {
                let x = 1.5 * b * i as f64 / 300.0;
                (x, hertz.pressure(x))
            })
            .collect();
        Some(Profile {
            title: format!(
                "{}: contact pressure, b/h = {}",
                run.scene.name, report.mesh_size
            ),
            x: "x",
            y: "pressure",
            computed: (format!("λ_h ({})", run.pair.name), computed),
            reference: Some(("Hertz p(x)".into(), exact)),
        })
    }
}

fn zero(_: &[f64]) -> f64 {
    0.0
}

/// The scene's data function `name` (0 where it sets none).
fn data_of(scene: &Scene, name: &str) -> Data {
    scene
        .data_fn(name)
        .cloned()
        .unwrap_or_else(|| Data::from(zero as fn(&[f64]) -> f64))
}

/// The pressure as solved: the scene's `q` times the load magnitude.
fn pressure_of(scene: &Scene, posed: &Posed) -> Data {
    let q = data_of(scene, "q");
    let scale = posed.load.unwrap_or(1.0);
    Data::shared(move |x| scale * q.at(x))
}

/// What the checks and quantities of a contact solve measure with.
fn input<'a>(
    facts: &ContactFacts,
    contact: &'a [u32],
    loaded: &'a [u32],
    pressure: &'a fem_runtime::DataFn,
) -> ContactData<'a> {
    ContactData {
        contact,
        load: loaded,
        pressure,
        centre: facts.centre,
    }
}

/// The chart of the pressure along Γ_C, against a scene's exact pressure (a scene
/// file's `[exact] pressure`) where it has one at the load solved.
fn exact_profile<M: Model>(
    run: &Run<'_, M, TriangleMesh>,
    facts: &ContactFacts,
) -> Option<Profile> {
    let boundary = run.solved.solution.discretization.boundary()?;
    let along = contact_tangent(facts.direction);
    let reference = run
        .scene
        .exact_at(run.posed)
        .and_then(|e| e.multiplier)
        .map(|exact| {
            let mut samples: Vec<(f64, f64)> = boundary
                .edges
                .iter()
                .flat_map(|e| {
                    (0..=8).map(|i| {
                        let x = file::point(&e.ends, i as f64 / 8.0);
                        (along[0] * x[0] + along[1] * x[1], exact.at(&x))
                    })
                })
                .collect();
            samples.sort_by(|a, b| a.0.total_cmp(&b.0));
            ("exact pressure".to_string(), samples)
        })
        .or_else(|| {
            // the patch test's exact pressure is the load q on every edge
            let Some(ContactBody::Block { .. }) = facts.body else {
                return None;
            };
            let q = run.posed.load?;
            let ends = boundary.edges.iter().flat_map(|e| e.ends);
            let (lo, hi) = ends
                .map(|x| along[0] * x[0] + along[1] * x[1])
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), s| {
                    (lo.min(s), hi.max(s))
                });
            Some(("exact pressure q".to_string(), vec![(lo, q), (hi, q)]))
        });
    Some(Profile {
        title: format!("{}: contact pressure", run.scene.name),
        x: "coordinate along the contact plane",
        y: "pressure",
        computed: (format!("λ_h ({})", run.pair.name), pressure_steps(run)),
        reference,
    })
}

/// The pressure along Γ_C as steps `(s0, s1, λ)` sorted by s0, s the coordinate along
/// the contact plane ([`contact_tangent`]: x under a horizontal one; see [`Profile`]).
fn pressure_steps<M: Model>(run: &Run<'_, M, TriangleMesh>) -> Vec<(f64, f64, f64)> {
    let solution = &run.solved.solution;
    let Some(boundary) = solution.discretization.boundary() else {
        return Vec::new();
    };
    let along = facts(run.scene).map_or([1.0, 0.0], |f| contact_tangent(f.direction));
    let coordinate = |x: [f64; 2]| along[0] * x[0] + along[1] * x[1];
    let pressure = solution.multiplier_values();
    let mut steps: Vec<(f64, f64, f64)> = match boundary.space {
        Multiplier::P0 => boundary
            .edges
            .iter()
            .zip(pressure)
            .map(|(e, &p)| {
                let (a, b) = (coordinate(e.ends[0]), coordinate(e.ends[1]));
                (a.min(b), a.max(b), p)
            })
            .collect(),
        Multiplier::P1 => {
            let mut points = vec![(0.0, 0.0, 0.0); pressure.len()];
            for (e, dofs) in boundary.edges.iter().zip(&boundary.edge_dofs) {
                for (end, &k) in e.ends.iter().zip(dofs) {
                    let s = coordinate(*end);
                    points[k] = (s, s, pressure[k]);
                }
            }
            points
        }
    };
    steps.sort_by(|a, b| a.0.total_cmp(&b.0));
    steps
}

/// The family's quantities and warnings.
///
/// `magnitude` is `∫_Γ_N |q| ds` of the pressure solved, the size the equilibrium's
/// rounding is relative to (a resultant of 1e-9 ∫|q| leaves the contact force the
/// rounding of ∫|q|, which is no failure of the solve).
fn add_quantities<M: Model>(
    facts: &ContactFacts,
    run: &Run<'_, M, TriangleMesh>,
    solution: &SignoriniSolution,
    magnitude: f64,
    report: &mut Report,
) {
    report.set("young", facts.young);
    report.set("poisson", facts.poisson);
    report.set(
        "plane",
        match facts.plane {
            Plane::Strain => "strain",
            Plane::Stress => "stress",
        },
    );
    report.set("contact_edges", solution.contact_edges.len());
    report.set("contact_half_width", solution.contact_half_width);
    report.set("max_contact_pressure", solution.max_contact_pressure);
    add_equilibrium(facts, run, solution, magnitude, report);
    let (mu, lambda) = (run.posed.parameter("μ_L"), run.posed.parameter("λ_L"));
    if let Some(w) = mu
        .zip(lambda)
        .and_then(|(m, l)| volumetric_locking(run.pair.name, m, l))
    {
        report.warn(w);
    }
    let load = run.posed.load.unwrap_or(1.0);
    match (facts.body, facts.hertz(load)) {
        (Some(ContactBody::Block { .. }), _) => {
            let q = load;
            report.set(
                "patch_pressure_error",
                solution
                    .pressure
                    .iter()
                    .fold(0.0f64, |m, &p| m.max((p - q).abs() / q)),
            );
        }
        (Some(body), Some(hertz)) => add_hertz(body, hertz, run, solution, report),
        _ => add_exact_pressure(run, solution, report),
    }
}

/// The balance of the contact force with the load along `n_c` (the whole body's where
/// a symmetry line halves it), with its warnings: a residual beyond rounding, a load
/// the model's quadrature does not integrate, supports that carry part of the load.
fn add_equilibrium<M: Model>(
    facts: &ContactFacts,
    run: &Run<'_, M, TriangleMesh>,
    solution: &SignoriniSolution,
    magnitude: f64,
    report: &mut Report,
) {
    let factor = facts.whole();
    let n = facts.direction;
    let along = |v: [f64; 2]| -(v[0] * n[0] + v[1] * n[1]);
    let total = factor * along(solution.total_contact_force);
    // the load's resultant pushes the body towards the foundation, along n_c
    let applied = -factor * along(solution.applied_load);
    // supports along n_c carry part of the load, and the translation the load is
    // measured on has their DOFs fixed: no resultant to balance (NaN, null in JSON)
    let held = file::translation_held(run.scene, facts);
    let discretized = if held {
        f64::NAN
    } else {
        factor * solution.discretized_load
    };
    let equilibrium = (total - discretized).abs() / discretized.abs().max(factor * magnitude);
    report.set("total_contact_force", total);
    // a scene's exact force (a file's `[exact] contact_force`) is compared, not only shown
    if let Some(exact) = report.exact_contact_force.filter(|e| *e != 0.0) {
        report.set("contact_force_error", (total - exact).abs() / exact.abs());
    }
    report.set("applied_load", applied);
    report.set("discretized_load", discretized);
    report.set("equilibrium_residual", equilibrium);
    if equilibrium > EQUILIBRIUM_WARNING {
        report.warn(format!(
            "the contact force misses the load as discretized by {equilibrium:.1e} (relative; a rigid translation lies in V_h, so it should be rounding): the solve did not reach solver precision, or the data's scales (a gap far beyond the elastic displacement) leave the displacement too few digits"
        ));
    }
    if held {
        report.warn(
            "supports hold the body along the contact direction and carry part of the load: the contact force need not balance it, and no equilibrium is checked (discretized_load and equilibrium_residual are null)",
        );
    }
    let quadrature = (discretized - applied).abs() / applied.abs();
    if quadrature > QUADRATURE_WARNING {
        report.warn(format!(
            "the model integrates the pressure on Γ_N with a rule exact for pressures up to quadratic along an edge: this pressure's resultant comes out {discretized:.6e} against {applied:.6e} by 4-point Gauss per edge ({quadrature:.1e} relative), and the contact force balances the former; refine the mesh for a pressure that varies within an edge"
        ));
    }
}

/// The pressure against Hertz's on a built-in body that has it: the half-width, the
/// peak, the relative L² errors of λ_h and of the best fit, and the checkerboard measure.
fn add_hertz<M: Model>(
    body: ContactBody,
    hertz: Hertz,
    run: &Run<'_, M, TriangleMesh>,
    solution: &SignoriniSolution,
    report: &mut Report,
) {
    let (error, best, oscillation) = match body {
        ContactBody::GapBlock { .. } => {
            let (error, best) = compare_gap_block(&hertz, solution);
            (error, best, checkerboard(solution, &hertz))
        }
        _ => {
            let r = compare_with_hertz(hertz, solution);
            (r.pressure_l2_error, r.best_fit_l2_error, r.oscillation)
        }
    };
    report.set(
        "reference_source",
        "Hertz's line contact (K. L. Johnson, Contact Mechanics, 1985, §4.2)",
    );
    report.set("exact_half_width", hertz.half_width());
    report.set("exact_max_pressure", hertz.max_pressure());
    report.set("pressure_l2_error", error);
    report.set("best_fit_l2_error", best);
    if solution.multiplier == Multiplier::P0 {
        report.set("best_p0_l2_error", best);
    }
    // a second difference needs three pressures inside 0.8 b (b/h = 1, 2 have fewer:
    // nothing measured, not 0)
    let inside = pressure_steps(run)
        .iter()
        .filter(|p| p.1.abs() < 0.8 * hertz.half_width())
        .count();
    if inside >= 3 {
        report.set("oscillation", oscillation);
    }
}

/// The pressure's errors against a scene's exact pressure (a scene file's `[exact]
/// pressure`) at the load solved: the relative L² error, the best fit's in the
/// pressure's space (P0 or continuous P1) and the checkerboard measure.
fn add_exact_pressure<M: Model>(
    run: &Run<'_, M, TriangleMesh>,
    solution: &SignoriniSolution,
    report: &mut Report,
) {
    let Some(exact) = run.scene.exact_at(run.posed).and_then(|e| e.multiplier) else {
        return;
    };
    let edges: Vec<([[f64; 2]; 2], [f64; 2])> = solution
        .contact_edges
        .iter()
        .zip(solution.edge_pressures())
        .map(|(e, p)| (e.ends, p))
        .collect();
    let [error, best] = file::pressure_errors(&edges, &exact);
    report.set("pressure_l2_error", error);
    // the best fit in the pressure's own space: the edge means for P0, the L²
    // projection onto the continuous piecewise linears for P1
    match solution.multiplier {
        Multiplier::P0 => {
            report.set("best_p0_l2_error", best);
            report.set("best_fit_l2_error", best);
        }
        Multiplier::P1 => {
            let edges: Vec<([[f64; 2]; 2], [usize; 2])> = solution
                .contact_edges
                .iter()
                .zip(&solution.edge_dofs)
                .map(|(e, &dofs)| (e.ends, dofs))
                .collect();
            let best = file::best_p1_error(&edges, solution.pressure.len(), &exact);
            report.set("best_fit_l2_error", best);
        }
    }
    let direction = facts(run.scene).map_or([0.0, -1.0], |f| f.direction);
    if let Some(o) = checkerboard_against(solution, direction, exact.as_data_fn()) {
        report.set("oscillation", o);
    }
}
