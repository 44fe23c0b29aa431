//! Reissner–Mindlin plates (docs/mathematics.md §6) on triangles, straight or curved
//! (the disk's boundary cells follow the circle): the locking-free Stenberg pair and the
//! plain displacement method that locks. The family's own quantities: the centre
//! deflection against the Kirchhoff limit (or the closed form where there is one), the
//! deflection's integral, the contact radius and λ_h over the contact interior, and the
//! warnings of locking and of the soft simple support's boundary layer.

use crate::families::edge_resultants::{self, MindlinParameters};
use crate::family::{Family, Opt, Pair, PairSolve};
use crate::geometry::{halving_sizes, Fields, Geometry};
use crate::mindlin::{mindlin_plain_p1, mindlin_stenberg};
use crate::plate_scenes::{self, PlateDomain, PlateReference, PlateSupport};
use crate::run::{run_on_triangles, Quantities, Report, Run};
use crate::scene::{Domain, Load, Part, Posed, Scene, Support};
use fem_runtime::adaptivity::BoundaryLayer;
use fem_runtime::mesh::triangle::PointLocator;
use fem_runtime::problem::{MemoryModel, ObstacleSide};
use fem_runtime::stabilization::Alpha;
use fem_runtime::{Error, Model, Result, TriangleMesh};

/// The Mindlin plate family.
pub struct Plates;

/// The registry's plate family.
pub static PLATES: Plates = Plates;

/// The Stenberg parameter β of the shear weight `6κ(1−ν)D/(t² + β h_T²)` (§6: β ≤ 0.01
/// brings back coarse-mesh locking, β ≥ 0.3 loses accuracy).
pub const STENBERG_BETA: f64 = 0.1;

/// The default stabilization parameter α (§6: α = 1 is 5–10× less accurate, α ≤ 0.01
/// breaks the solver on fine meshes).
pub const PLATE_ALPHA: f64 = 0.1;

/// The thinnest plate a solve accepts: below it the Mindlin plate is Kirchhoff's to t²
/// (rounding), and the plain pair's shear weight `6κ(1−ν)D/t²` overflows.
pub const MIN_THICKNESS: f64 = 1e-8;

/// The peak memory of a Mindlin solve per triangle, `a + b·log₂(triangles)` (the direct
/// factor's fill grows like `T log T`). Measured peaks of `p1-p2-p0` (2026-12-01; the
/// plain pair needs less): square 289 MB at N = 128, 1.23 GB at 256, 5.45 GB at 512.
pub const STRAIGHT_MEMORY: MemoryModel = MemoryModel {
    per_cell: 2.8e3,
    per_cell_log: 0.4e3,
    floor: 0.0,
};

/// [`STRAIGHT_MEMORY`] on curved cells (the disk: 378 MB at 64 rings, 1.79 GB at 128,
/// 8.8 GB at 256), floored at the 15 kB a triangle measured on its smallest meshes.
pub const CURVED_MEMORY: MemoryModel = MemoryModel {
    per_cell: -16.7e3,
    per_cell_log: 2.1e3,
    floor: 15e3,
};

const fn pair(
    name: &'static str,
    note: &'static str,
    parameters: &'static [(&'static str, f64)],
    solve: PairSolve,
) -> Pair {
    Pair {
        name,
        note,
        alpha: Alpha::Fixed(PLATE_ALPHA),
        alpha_when_zero: PLATE_ALPHA,
        memory: Some(STRAIGHT_MEMORY),
        nodal: false,
        parameters,
        solve,
    }
}

static PAIRS: [Pair; 2] = [
    pair(
        "p1-p2-p0",
        "θ ∈ [P1]², w ∈ P2, λ ∈ P0, Stenberg shear weight: locking-free",
        &[("β", STENBERG_BETA)],
        run_on_triangles::<mindlin_stenberg::Model, Plates>,
    ),
    pair(
        "p1-p1-p0-plain",
        "θ ∈ [P1]², w ∈ P1, λ ∈ P0, physical shear weight: locks as t → 0",
        &[],
        run_on_triangles::<mindlin_plain_p1::Model, Plates>,
    ),
];

/// What a plate scene's report compares with: the Kirchhoff limit of its centre
/// deflection, or the Mindlin closed form, and how it names its obstacle.
#[derive(Clone, Debug)]
pub struct PlateFacts {
    /// The reference of the centre deflection (`None`: none for the scene's supports).
    pub reference: Option<PlateReference>,
    /// The support `reference` is for, on every edge.
    pub support: Support,
    /// The obstacle in words (`flat above, w ≤ 0.05`).
    pub obstacle: String,
    /// The length `L` the Kirchhoff deflections scale with (`w ~ q L⁴/D`): the side of a
    /// square, the radius of a disk.
    pub length: f64,
}

/// The scene of a plate description of [`crate::plate_scenes`].
fn plate_scene(old: &plate_scenes::PlateScene) -> Scene {
    let domain = match old.domain {
        PlateDomain::Square { side } => Domain::square(0.0, side),
        PlateDomain::Disk { radius } => Domain::Disk {
            centre: [0.0, 0.0],
            radius,
            curved: true,
        },
    };
    let support = match old.support {
        PlateSupport::Clamped => Support::Clamped,
        PlateSupport::SimplySupported => Support::SimplySupported { hard: false },
    };
    let mut scene = Scene::new(old.name, old.description, "plate", domain, old.mesh_size)
        .with_parameter("D", old.bending_stiffness)
        .with_parameter("ν", old.poisson_ratio)
        .with_parameter("κ", old.shear_correction)
        .with_parameter("t", old.thickness)
        .with_data("f", crate::data::Data::shared(|_| 1.0))
        .with_support(Part::All, support);
    scene.load = Some(Load {
        default: old.load,
        scales: vec!["f".into()],
        symbol: "q",
        sign: crate::scene::LoadSign::Any,
    });
    match old.obstacle.side_and_height() {
        Some((side, height)) => {
            scene.side = if side > 0.0 {
                ObstacleSide::Below
            } else {
                ObstacleSide::Above
            };
            scene.set_data("ψ", crate::data::Data::shared(move |_| height));
        }
        None => scene.obstacle = false,
    }
    // the plain pair's model is clamped only where it locks: it is shown for comparison
    scene.pairs = match old.support {
        PlateSupport::Clamped => vec!["p1-p2-p0", "p1-p1-p0-plain"],
        PlateSupport::SimplySupported => vec!["p1-p2-p0"],
    };
    scene.studies = match old.name {
        "mindlin-square" => vec!["locking", "adaptivity"],
        "mindlin-disk" => vec!["convergence", "iterations"],
        // the model choice's chart: Kirchhoff against Reissner–Mindlin
        "mindlin-ss-t1e-2" => vec!["work-precision"],
        _ => Vec::new(),
    };
    // a scene that lists several loads is studied at each
    if old.loads.len() > 1 {
        scene.study_variants = old
            .loads
            .iter()
            .map(|&q| crate::scene::StudyVariant {
                label: format!("q{q}"),
                load: Some(q),
                adjustments: Vec::new(),
            })
            .collect();
    }
    scene.reference = Some(std::sync::Arc::new(PlateFacts {
        reference: Some(old.reference),
        support,
        obstacle: old.obstacle.describe(),
        length: old.domain.length(),
    }));
    scene
}

impl Family for Plates {
    fn name(&self) -> &'static str {
        "plate"
    }

    fn description(&self) -> &'static str {
        "Reissner–Mindlin plates on triangles (straight, or curved onto a disk's circle)"
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
            Opt::Cold,
            Opt::Support,
            Opt::NoObstacle,
            Opt::Tol,
            Opt::Marking,
            Opt::Theta,
            Opt::EdgeResultants,
        ]
    }

    fn scenes(&self) -> Vec<Scene> {
        plate_scenes::PLATE_SCENES.iter().map(plate_scene).collect()
    }

    /// The centre deflection against the Kirchhoff plate's (the limit t → 0).
    fn locking(&self) -> Option<crate::family::Locking> {
        Some(crate::family::Locking {
            quantity: "centre_deflection",
            limit: crate::family::Limit::Reported("kirchhoff_reference"),
            quantity_words: "w_h(centre)",
            limit_words: "Kirchhoff",
        })
    }

    fn model_words(&self, _: &Scene) -> &'static str {
        "Reissner–Mindlin"
    }

    /// The Kirchhoff plate of the same domain, supports, load and obstacle, on Argyris
    /// (whose ∇Δw gives the modelling estimate; Morley's vanishes on every cell).
    fn cheaper(&self, scene: &Scene) -> Option<Scene> {
        scene.parameter("t")?;
        // its `dirichlet` holds w and θ, the Kirchhoff one w alone: not the same plate
        if scene.has_model_boundary_data() {
            return None;
        }
        let pairs = vec!["argyris-p0", "argyris-p1disc"];
        let mut thin =
            scene.posed_for_cheaper("kirchhoff", "kirchhoff", pairs, |p| ["D", "ν"].contains(&p));
        // Argyris elements are straight: the disk becomes its inscribed polygon
        if let Domain::Disk { curved, .. } = &mut thin.domain {
            *curved = false;
        }
        thin.reference = None;
        thin.studies = Vec::new();
        thin.study_variants = Vec::new();
        Some(thin)
    }

    fn aliases(&self) -> &'static [(&'static str, &'static str)] {
        &[
            ("thickness", "t"),
            ("bending_stiffness", "D"),
            ("poisson_ratio", "ν"),
            ("nu", "ν"),
            ("shear_correction", "κ"),
            ("kappa", "κ"),
            ("load", "f"),
            ("obstacle", "ψ"),
            ("psi", "ψ"),
        ]
    }
}

/// The facts of a plate scene for its supports as posed: where a request changed them
/// (`--support`), the reference of the new support (the square's series, clamped or
/// simply supported), or none (a disk not clamped, mixed or free edges); `None`
/// without facts (a scene file: no closed form).
fn facts(scene: &Scene) -> Option<PlateFacts> {
    let mut facts = scene.reference::<PlateFacts>()?.clone();
    let first = scene.supports.first().map(|s| s.support);
    let uniform = first.filter(|&f| scene.supports.iter().all(|s| s.support == f));
    if uniform != Some(facts.support) {
        let square =
            matches!(scene.domain, Domain::Rectangle { x, y, .. } if x[1] - x[0] == y[1] - y[0]);
        let coefficient = match uniform {
            Some(Support::Clamped) => Some(plate_scenes::CLAMPED_SQUARE_CENTRE),
            // the Kirchhoff limit of both: w = 0 on the edge fixes ∂w/∂s
            Some(Support::SimplySupported { .. }) => {
                Some(plate_scenes::SIMPLY_SUPPORTED_SQUARE_CENTRE)
            }
            _ => None,
        };
        facts.reference = coefficient
            .filter(|_| square)
            .map(|coefficient| PlateReference::KirchhoffCentre { coefficient });
    }
    Some(facts)
}

/// The Kirchhoff centre deflection of `reference` for a plate of size `length` at load
/// `q`, bending stiffness `d`.
fn kirchhoff_deflection(reference: PlateReference, length: f64, q: f64, d: f64) -> f64 {
    let scale = q * length.powi(4) / d;
    match reference {
        PlateReference::KirchhoffCentre { coefficient } => coefficient * scale,
        PlateReference::ClampedDisk => scale / 64.0,
    }
}

/// The exact Mindlin centre deflection where it has a closed form (the clamped disk:
/// `q R⁴/(64D) + q R²/(4S)`, `S = 6κ(1−ν)D/t²`).
fn mindlin_deflection(
    reference: PlateReference,
    length: f64,
    q: f64,
    posed: &Posed,
) -> Option<f64> {
    let PlateReference::ClampedDisk = reference else {
        return None;
    };
    let (d, nu, kappa, t) = (
        posed.parameter("D")?,
        posed.parameter("ν")?,
        posed.parameter("κ")?,
        posed.parameter("t")?,
    );
    let shear = 6.0 * kappa * (1.0 - nu) * d / (t * t);
    Some(kirchhoff_deflection(reference, length, q, d) + q * length * length / (4.0 * shear))
}

/// Refuses a thickness `t` above the plate's size (the square's side, the disk's
/// diameter): plate theory, Kirchhoff's or Reissner–Mindlin's, describes thin bodies.
///
/// # Errors
/// [`Error::Input`] naming t and the size.
pub(crate) fn thin_enough(scene: &Scene, t: f64) -> Result<()> {
    if let Some(size) = scene.domain.size() {
        let name = match scene.domain {
            Domain::Disk { .. } => "diameter",
            _ => "side",
        };
        if t > size {
            return Err(Error::Input(format!(
                "thickness t = {} exceeds the plate's {name} {size}: plate theory describes thin bodies (t well below the {name}); a thicker body is a problem of elasticity",
                fem_runtime::problem::number(t)
            )));
        }
    }
    Ok(())
}

/// Rays of the contact radius.
const CONTACT_RAYS: usize = 360;

/// The mean over rays from `centre` of the radius at which each ray leaves the contact
/// cells (`contact[c]`): the outer radius of the contact set along rays (O(h); unlike
/// `√(area/π)` it does not count holes or the jagged edge twice); a set that misses
/// the centre's cells takes the radius of a disk of its `area`.
fn contact_radius(mesh: &TriangleMesh, contact: &[bool], centre: [f64; 2], area: f64) -> f64 {
    let locator = PointLocator::new(mesh);
    let reach = mesh
        .vertices()
        .iter()
        .map(|p| (p[0] - centre[0]).hypot(p[1] - centre[1]))
        .fold(0.0, f64::max);
    let step = mesh.max_h() / 8.0;
    let mut total = 0.0;
    for k in 0..CONTACT_RAYS {
        let angle = std::f64::consts::TAU * (k as f64 + 0.5) / CONTACT_RAYS as f64;
        let (cos, sin) = (angle.cos(), angle.sin());
        let mut hint = None;
        let mut r = 0.0;
        // the first point of the ray outside the contact cells (or the mesh)
        while r <= reach {
            let x = [centre[0] + r * cos, centre[1] + r * sin];
            match locator.locate_near(x, hint) {
                Some((c, _)) if contact[c] => hint = Some(c),
                _ => break,
            }
            r += step;
        }
        // the exit lies between the last point inside and this one
        total += if r == 0.0 { 0.0 } else { r - 0.5 * step };
    }
    let radius = total / CONTACT_RAYS as f64;
    if radius == 0.0 && area > 0.0 {
        (area / std::f64::consts::PI).sqrt()
    } else {
        radius
    }
}

/// `(mean, (max − min)/|mean|)` of λ_h over the contact interior, the contact cells
/// whose centroid lies within half the contact radius (the line force at the edge of
/// contact, a layer of width O(t), is smeared over several cells of λ_h); `None` where
/// the interior is not wider than that layer (three cells).
fn interior_multiplier(
    mesh: &TriangleMesh,
    contact: &[bool],
    lambda: &[f64],
    centre: [f64; 2],
    radius: f64,
) -> Option<(f64, f64)> {
    if 0.5 * radius < 3.0 * mesh.max_h() {
        return None;
    }
    let interior: Vec<f64> = (0..mesh.cell_count())
        .filter(|&c| contact[c])
        .filter(|&c| {
            let x = mesh.cell(c).map(|v| mesh.vertices()[v]);
            let centroid = [
                (x[0][0] + x[1][0] + x[2][0]) / 3.0,
                (x[0][1] + x[1][1] + x[2][1]) / 3.0,
            ];
            (centroid[0] - centre[0]).hypot(centroid[1] - centre[1]) <= 0.5 * radius
        })
        .map(|c| lambda[c])
        .collect();
    (!interior.is_empty()).then(|| {
        let mean = interior.iter().sum::<f64>() / interior.len() as f64;
        let max = interior.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        let min = interior.iter().cloned().fold(f64::INFINITY, f64::min);
        (mean, (max - min) / mean.abs())
    })
}

/// The warning of the plain pair where it locks: its shear term `t⁻²(∇w − θ)` with
/// w ∈ P1 forces `∇w_h = θ_h` cell by cell as the cells grow against the thickness,
/// and w_h collapses (the locking study: the deflection falls like `(t/h)²`). `h` is
/// the largest cell diameter.
fn locking_warning(pair: &str, h: f64, thickness: f64) -> Option<String> {
    // from a tenth of t on: at h ≈ t the deflection is already 12–15 % low
    (pair == "p1-p1-p0-plain" && h > 0.1 * thickness).then(|| {
        format!(
            "p1-p1-p0-plain locks here: its cells (h = {h:.2e}) are not small against the plate's thickness (t = {}), and w_h is then stiffened by about (h/t)² = {:.0e}; it is the locking pair of the locking study, shown for comparison: use p1-p2-p0 (the Stenberg pair, locking-free)",
            fem_runtime::problem::number(thickness),
            (h / thickness).powi(2)
        )
    })
}

/// The warning of a nested solve whose coarsest level is still fine: the levels halve N
/// while it is even, so an N with few factors of 2 gets no coarse start (mindlin-disk at
/// N = 63: one level of 14 Newton iterations in 1.56 s, against 3 iterations and 0.62 s
/// at N = 64). `sizes` are the levels, coarsest first; `coarsest` the smallest N a level
/// may have.
pub fn cold_coarsest_warning(sizes: &[usize], coarsest: usize) -> Option<String> {
    let (first, last) = (sizes[0], sizes[sizes.len() - 1]);
    // the nearest multiple of 16 nests at least four levels deep
    let suggested = ((last + 8) / 16).max(1) * 16;
    (first >= 4 * coarsest).then(|| {
        let why = if sizes.len() == 1 {
            format!("N = {last} is odd, so it has no coarser nested level: Newton starts cold on it, and --cold changes nothing")
        } else {
            format!("N = {last} halves only down to N = {first}, where it turns odd: Newton starts cold on that level, and --cold changes little")
        };
        format!(
            "{why} (the nested levels halve N while it is even, down to {coarsest}); an N with more factors of 2, such as {suggested}, nests deeper and needs fewer iterations"
        )
    })
}

/// The edge resultants of a Reissner–Mindlin solve ([`edge_resultants::mindlin`]), with a
/// warning where its mesh does not resolve the boundary layer.
fn add_edge_resultants<M: Model, G: Geometry>(run: &Run<'_, M, G>, report: &mut Report) {
    let solution = &run.solved.solution;
    let field = |name: &str| M::FIELDS.iter().position(|f| f.name == name);
    let param = |name: &str| {
        M::PARAMS
            .iter()
            .position(|p| *p == name)
            .map(|k| run.solved.params[k])
    };
    let views = (|| {
        let mesh = run.solved.mesh().straight()?;
        let [tx, ty, w] = [field("θ_x")?, field("θ_y")?, field("w")?];
        Some((
            mesh,
            G::straight_view(solution, tx)?,
            G::straight_view(solution, ty)?,
            G::straight_view(solution, w)?,
        ))
    })();
    let parameters = (|| {
        Some(MindlinParameters {
            d: param("D")?,
            nu: param("ν")?,
            kappa: param("κ")?,
            t: param("t")?,
            beta: param("β").unwrap_or(0.0),
        })
    })();
    let (Some((mesh, tx, ty, w)), Some(p)) = (views, parameters) else {
        report.warn("the edge resultants are evaluated on straight triangles: this mesh's curved cells give none");
        return;
    };
    let layered = edge_resultants::rotations_free_markers(run.scene, mesh);
    let resultants = edge_resultants::mindlin([&tx, &ty], &w, p, &layered);
    if let (Some(false), Some(longest), Some(width)) = (
        resultants.layer_resolved,
        resultants.layer_longest_edge,
        resultants.layer_width,
    ) {
        report.warn(format!(
            "the edge resultants are not resolved: the boundary edges that leave the rotations free (soft simple supports, free edges) are up to {longest:.3e} long, the rotations' boundary layer {width:.3e} = t/√(12κ) wide, where the twisting moment falls to 0 and the shear force gains −∂M_ns/∂s; solve with --tol, which refines along those edges to the layer's width"
        ));
    }
    report.set("edge_resultants", resultants);
}

/// The centre deflection's relative difference from Kirchhoff that the soft simple
/// support's boundary layer adds, per unit of `t/L`: the layer of width O(t) where θ
/// turns to satisfy the free moment makes the difference O(t), not O(t²) (the unit
/// square: 4.3 % of its 5.6 % at t = 0.05, 1.5 % at t = 0.02).
pub const SOFT_SUPPORT_LAYER: f64 = 0.8;

impl<G: Geometry> Quantities<G> for Plates {
    fn memory<M: Model>(pair: &Pair, scene: &Scene, _: usize) -> MemoryModel {
        match scene.domain {
            Domain::Disk { curved: true, .. } => CURVED_MEMORY,
            _ => pair.memory.unwrap_or_else(MemoryModel::of_model::<M>),
        }
    }

    fn check(scene: &Scene, posed: &Posed) -> Result<()> {
        let bad = |what: String| Err(Error::Input(what));
        if let Some(t) = posed.parameter("t") {
            if !(t.is_finite() && t > 0.0) {
                return bad(format!(
                    "thickness t = {} must be positive and finite",
                    fem_runtime::problem::number(t)
                ));
            }
            if t < MIN_THICKNESS {
                return bad(format!(
                    "thickness t = {t:e} is below {MIN_THICKNESS:e}: the Mindlin plate is then Kirchhoff's to t² (rounding), and the plain pair's shear weight 6κ(1−ν)D/t² overflows; use t ≥ {MIN_THICKNESS:e}"
                ));
            }
            thin_enough(scene, t)?;
        }
        if let Some(nu) = posed.parameter("ν") {
            if !(nu > -1.0 && nu < 0.5) {
                return bad(format!("Poisson's ratio ν = {nu} must lie in (−1, ½)"));
            }
        }
        Ok(())
    }

    fn boundary_layer(scene: &Scene, posed: &Posed, mesh: &G) -> Option<BoundaryLayer> {
        let t = posed.parameter("t")?;
        let kappa = posed.parameter("κ").unwrap_or(5.0 / 6.0);
        edge_resultants::boundary_layer(scene, mesh.straight()?, t, kappa)
    }

    fn add<M: Model>(run: &Run<'_, M, G>, report: &mut Report) -> Result<()> {
        let posed = run.posed;
        let q = posed.load.unwrap_or(0.0);
        let t = posed.parameter("t").unwrap_or(f64::NAN);
        let solution = &run.solved.solution;
        let w = run.constrained_field();
        report.set("thickness", t);
        if run.scene.edge_resultants {
            add_edge_resultants(run, report);
        }
        report.set(
            "support",
            run.scene
                .supports
                .iter()
                .map(|s| s.support.name())
                .collect::<Vec<_>>()
                .join(", "),
        );
        let facts = facts(run.scene);
        let in_contact = run.scene.obstacle;
        report.set(
            "obstacle",
            match (in_contact, &facts) {
                (false, _) => "none".to_string(),
                (true, Some(f)) => f.obstacle.clone(),
                (true, None) => "ψ".to_string(),
            },
        );
        let max_deflection = solution.field(w).iter().fold(0.0f64, |m, v| m.max(v.abs()));
        report.set("max_deflection", max_deflection);
        report.set("deflection_integral", G::integral(solution, w));
        let Fields::Triangles { mesh, cell, .. } = run.fields else {
            return Ok(());
        };
        let centre = run.scene.domain.centre().map(|c| [c[0], c[1]]);
        if let Some(centre) = centre {
            let deflection = run.value_at(&centre).ok_or_else(|| {
                Error::Input(format!(
                    "the centre ({}, {}) is outside the mesh",
                    centre[0], centre[1]
                ))
            })?;
            report.set("centre_deflection", deflection);
            let reference = facts.as_ref().and_then(|f| Some((f.reference?, f.length)));
            if let (Some((reference, length)), Some(d)) = (reference, posed.parameter("D")) {
                let kirchhoff = kirchhoff_deflection(reference, length, q, d);
                report.set("kirchhoff_reference", kirchhoff);
                if !in_contact {
                    let closed = mindlin_deflection(reference, length, q, posed);
                    let reference = closed.unwrap_or(kirchhoff);
                    report.set("unobstructed_reference", closed);
                    report.set("reference_centre_deflection", reference);
                    report.set(
                        "reference_source",
                        if closed.is_some() {
                            "the clamped disk's Reissner–Mindlin closed form q R⁴/(64D) + q R²/(4S)"
                        } else {
                            "the Kirchhoff plate's series (Timoshenko and Woinowsky-Krieger), the limit t → 0"
                        },
                    );
                    // q = 0: both deflections are 0 exactly, and so is the error
                    let relative = if reference == 0.0 && deflection == 0.0 {
                        0.0
                    } else {
                        (deflection - reference) / reference
                    };
                    report.set("relative_error", relative);
                    model_difference_warnings(run, closed.is_none(), t, report);
                }
            }
        }
        if in_contact {
            let contact: Vec<bool> = cell_values(cell, "contact")
                .iter()
                .map(|&share| share > 0.0)
                .collect();
            let lambda = cell_values(cell, "lambda");
            let area = report.solve.contact_area.unwrap_or(0.0);
            if let Some(centre) = centre {
                let radius = contact_radius(mesh, &contact, centre, area);
                report.set("contact_radius", radius);
                if let Some((mean, spread)) =
                    interior_multiplier(mesh, &contact, &lambda, centre, radius)
                {
                    report.set("lambda_interior_mean", mean);
                    report.set("lambda_interior_spread", spread);
                }
            }
            let alpha = report.solve.alpha.unwrap_or(PLATE_ALPHA);
            if alpha > 1.0 {
                report.warn(format!(
                    "α = {alpha} is above 1: the stabilization's term α h⁴ s²(λ, μ) then moves the constraint visibly (docs/mathematics.md §6: α = 1 is already 5–10× less accurate than the default {PLATE_ALPHA})"
                ));
            }
            let n = run.settings.mesh_size.unwrap_or(run.scene.mesh_size);
            let newton = run.settings.solver.nests();
            if run.settings.nested && newton {
                let sizes = halving_sizes(n, true, <Self as Quantities<G>>::COARSEST, false);
                if let Some(w) = cold_coarsest_warning(&sizes, <Self as Quantities<G>>::COARSEST) {
                    report.warn(w);
                }
            }
        }
        if let Some(w) = locking_warning(run.pair.name, mesh.max_h(), t) {
            report.warn(w);
        }
        Ok(())
    }
}

/// The values of the cell field `name` of a triangle solution's fields.
fn cell_values(cell: &[(&'static str, Vec<f64>)], name: &str) -> Vec<f64> {
    cell.iter()
        .find(|(n, _)| *n == name)
        .map(|(_, v)| v.clone())
        .unwrap_or_default()
}

/// Where the centre deflection is compared with Kirchhoff's (no closed form for the
/// Mindlin plate), what the difference holds beside the discretization's error: the
/// O(t²) difference of the models, and with a soft simple support the O(t) boundary
/// layer, with the hard support as its cure.
fn model_difference_warnings<M: Model, G: Geometry>(
    run: &Run<'_, M, G>,
    against_kirchhoff: bool,
    t: f64,
    report: &mut Report,
) {
    if !against_kirchhoff {
        return;
    }
    let size = run.scene.domain.size().unwrap_or(1.0);
    let soft = run
        .scene
        .supports
        .iter()
        .any(|s| s.support == Support::SimplySupported { hard: false });
    let layer = SOFT_SUPPORT_LAYER * t / size;
    if soft && layer > 1e-3 {
        report.warn(format!(
            "relative_error compares w_h(centre) with the Kirchhoff plate, the limit t → 0, and the soft simple support (w = 0, θ free) leaves a boundary layer of width O(t) in the Mindlin plate: at t = {} it makes the difference O(t), about {:.1} % here, beyond the O(t²) difference of the models; the hard simple support (--support simply-supported-hard: w = 0 and θ·t = 0) has no such layer",
            fem_runtime::problem::number(t),
            100.0 * layer
        ));
    } else if t > 0.02 * size {
        report.warn(format!(
            "relative_error compares w_h(centre) with the Kirchhoff plate, the limit t → 0: at t = {} ({:.1} % of the plate's size {size}) it is mostly the O(t²) difference between the Mindlin and Kirchhoff models, not the discretization's error",
            fem_runtime::problem::number(t),
            100.0 * t / size
        ));
    }
}
