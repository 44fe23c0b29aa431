//! What a contact scene file poses beyond the reader's keys, and its checks on the mesh
//! (docs/scene-files.md, "Contact"): `[material]`, the contact direction and centre,
//! Γ_C facing the foundation edge by edge, one body, data finite on their parts, a
//! pressure that presses the body on, and data whose scales leave the displacement its
//! digits. Each error names the file's key.

use super::facts::contact_tangent;
use super::facts::{material_parameters, ContactFacts, CONTACT_PART, LOAD_PART};
use crate::data::Data;
use crate::family::{finite, FieldError, FileKeys};
use crate::scene::{Domain, Part, Scene, Support};
use crate::signorini::Plane;
use fem_runtime::{Error, TriangleMesh};
use std::sync::Arc;

/// The largest size of E, the pressure and the gap a contact scene may give (the
/// scenes' load bound): beyond it the stiffness, the KKT norms or the stabilization's
/// `½/C_I,E` leave the range of f64 (E = 1e-200 gave "α = inf").
pub const MAX_DATA: f64 = 1e100;

/// The largest rounding of the displacement through the gap, `ε |min g|` (the rigid
/// translation before contact, or the initial penetration), relative to the body's
/// elastic displacement `load · max|q| · L / E`, that a contact scene may ask for where
/// the translation along n_c is free: the translation carries the deformation's digits.
/// Measured on the 2 × 1 block (`q L/E` = 2.2e-3): a uniform gap of 1e10 (ε-ratio 1e-3)
/// gave a contact force 6.5 % off the load, 1e6 (1e-7) 6.9e-6 and 1e3 (1e-10) 6.5e-9,
/// about 60 times the ratio; below this bound the equilibrium stays within
/// the equilibrium warning's 1e-8.
pub const MAX_GAP_ROUNDING: f64 = 1e-10;

/// A pressure resultant below this fraction of `∫|q| ds` is the rounding of a zero one.
const RESULTANT_ROUNDING: f64 = 1e-12;

/// The Gauss–Legendre points of the integrals along edges here (exact to degree 7).
const GAUSS_POINTS: usize = 4;

/// The pieces of an edge on which [`resultant_and_magnitude`] integrates the pressure:
/// a scene file's mesh is refined up to 8 times before it is solved, and a pressure
/// that varies within its coarse edges (0.1 + cos(8πx) on one square refined 4 times,
/// resultant +0.1) came out pulling (−0.24) on one piece and the file was refused.
const RESULTANT_PIECES: usize = 16;

/// Reads `[material]` and the parameters `contact_direction` and `contact_centre` into
/// `scene`: the Lamé parameters, `n_c` and the [`ContactFacts`].
///
/// # Errors
/// The field at fault: a missing `[material]`, an unknown key in it, E ≤ 0 or outside
/// [1e-100, 1e100], ν outside (−1, ½), a plane other than strain or stress, a contact
/// direction that is not two finite numbers or is zero, a centre that is not finite.
pub fn read(keys: FileKeys<'_>, scene: &mut Scene) -> Result<(), FieldError> {
    let err = |f: &str, m: String| Err((f.to_string(), m));
    let (young, poisson, plane) = material_of(keys.material)?;
    let (direction, centre) = direction_of(&mut *keys.parameters)?;
    // the model's own parameters are derived from the material and the direction: set
    // by name they would bypass the checks above
    if let Some(key) = keys
        .parameters
        .keys()
        .find(|k| !["alpha", "α"].contains(&k.as_str()))
    {
        return err(
            &format!("parameters.{key}"),
            format!(
                "a contact file's [parameters] are contact_direction, contact_centre and alpha; the model's μ_L, λ_L and n_c follow from [material] (young, poisson, plane) and contact_direction, not `{key}`"
            ),
        );
    }
    let facts = ContactFacts {
        young,
        poisson,
        plane,
        direction,
        centre,
        body: None,
    };
    for (name, value) in
        material_parameters(&facts).map_err(|e| ("material".into(), e.to_string()))?
    {
        scene.set_parameter(name, value);
    }
    scene.reference = Some(Arc::new(facts));
    Ok(())
}

/// E, ν and the plane of `[material]`, checked.
fn material_of(material: Option<&toml::Table>) -> Result<(f64, f64, Plane), FieldError> {
    let err = |f: &str, m: String| Err((f.to_string(), m));
    let Some(material) = material else {
        return err(
            "material",
            "a contact body needs its `[material]`: young = E, poisson = ν (plane = \"strain\" or \"stress\")".into(),
        );
    };
    if let Some(key) = material
        .keys()
        .find(|k| !["young", "poisson", "plane"].contains(&k.as_str()))
    {
        return err(
            &format!("material.{key}"),
            format!("unknown key `{key}`; the material is young, poisson, plane"),
        );
    }
    let young = number(material, "young", "material")?;
    let poisson = number(material, "poisson", "material")?;
    if young <= 0.0 {
        return err(
            "material.young",
            format!("Young's modulus E = {young} must be positive and finite"),
        );
    }
    if !(1.0 / MAX_DATA..=MAX_DATA).contains(&young) {
        return err(
            "material.young",
            format!(
                "Young's modulus E = {young:e} lies outside [{:e}, {MAX_DATA:e}]: the stiffness and the stabilization's ½/C_I,E would leave the range of double precision; rescale the units",
                1.0 / MAX_DATA
            ),
        );
    }
    if !(poisson > -1.0 && poisson < 0.5) {
        return err(
            "material.poisson",
            format!("Poisson's ratio ν = {poisson} must lie in (−1, ½)"),
        );
    }
    let plane = match material.get("plane").map(|v| v.as_str()) {
        None | Some(Some("strain")) => Plane::Strain,
        Some(Some("stress")) => Plane::Stress,
        Some(other) => {
            return err(
                "material.plane",
                format!(
                    "`{}`: write \"strain\" or \"stress\"",
                    other.unwrap_or("not a string")
                ),
            )
        }
    };
    Ok((young, poisson, plane))
}

/// The contact direction `n_c` (unit) and the centre of `[parameters]`, taken out of it.
fn direction_of(parameters: &mut toml::Table) -> Result<([f64; 2], Option<f64>), FieldError> {
    let err = |f: &str, m: String| Err((f.to_string(), m));
    let direction = match parameters.remove("contact_direction") {
        None => [0.0, -1.0],
        Some(v) => {
            let field = "parameters.contact_direction";
            let pair = v
                .as_array()
                .filter(|a| a.len() == 2)
                .and_then(|a| Some([finite(&a[0])?, finite(&a[1])?]));
            let Some([cx, cy]) = pair else {
                return err(field, format!("{v} is not two finite numbers [n_x, n_y]"));
            };
            let length = cx.hypot(cy);
            if !(length.is_finite() && length > 0.0) {
                return err(
                    field,
                    format!("({cx}, {cy}) must be a non-zero finite vector"),
                );
            }
            [cx / length, cy / length]
        }
    };
    let centre = match parameters.remove("contact_centre") {
        None => None,
        Some(v) => Some(finite(&v).ok_or_else(|| {
            (
                "parameters.contact_centre".to_string(),
                format!("{v} must be a finite number"),
            )
        })?),
    };
    Ok((direction, centre))
}

/// The required finite number `key` of `table`.
fn number(table: &toml::Table, key: &str, prefix: &str) -> Result<f64, FieldError> {
    let field = format!("{prefix}.{key}");
    match table.get(key) {
        None => Err((field, format!("missing: give `{key}`"))),
        Some(v) => finite(v).ok_or_else(|| (field, format!("{v} must be a finite number"))),
    }
}

/// The coarsest mesh of a scene file's domain, on which its checks run (a Gmsh file as
/// written, a rectangle before refinement).
fn coarsest_mesh(domain: &Domain) -> Result<TriangleMesh, FieldError> {
    use crate::geometry::Geometry;
    let mesh = match domain {
        Domain::Refined { mesh, .. } => Ok((**mesh).clone()),
        Domain::Gmsh(path) => fem_runtime::mesh::gmsh::read_msh(path)
            .map_err(|e| ("mesh.file".to_string(), e.to_string())),
        other => TriangleMesh::levels(other, 2, false, 1, None, &|_| Ok(()))
            .map(|mut levels| levels.pop().expect("one level"))
            .map_err(|e| ("mesh".to_string(), e.to_string())),
    }?;
    Ok(mesh)
}

/// Checks a contact scene read from a file on its coarsest mesh (see the module).
///
/// # Errors
/// The field at fault and why.
pub fn check(scene: &Scene, facts: &ContactFacts) -> Result<(), FieldError> {
    let mesh = coarsest_mesh(&scene.domain)?;
    one_body(&mesh).map_err(|m| ("mesh".to_string(), m))?;
    let markers = |name: &str, key: &str| -> Result<Vec<u32>, FieldError> {
        let part = scene
            .facets
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, p)| p)
            .ok_or_else(|| ("boundary".to_string(), format!("no `{key}` part")))?;
        markers_on_boundary(&mesh, part).map_err(|m| (key.to_string(), m))
    };
    let contact = markers(CONTACT_PART, "boundary.contact")?;
    let loaded = markers(LOAD_PART, "boundary.load")?;
    let n = facts.direction;
    for support in &scene.supports {
        let key = support.key.as_deref().unwrap_or("boundary").to_string();
        let held = markers_on_boundary(&mesh, &support.part).map_err(|m| (key.clone(), m))?;
        let on_contact = held.iter().any(|m| contact.contains(m));
        match support.support {
            Support::Data => {
                return Err((
                    key,
                    "a contact body has no prescribed displacement data: hold its parts with fixed_x, fixed_y, [[boundary.roller]] or clamped".into(),
                ))
            }
            Support::Clamped if on_contact => {
                return Err((
                    key,
                    "it clamps a part of `boundary.contact` too: the support and the contact constraint would both fix u·n_c there; drop the support on the contact part".into(),
                ))
            }
            Support::SimplySupported { .. } | Support::Free => {
                return Err((
                    key,
                    "a contact body's supports are fixed_x, fixed_y, [[boundary.roller]] and clamped (simply supported and free edges are a plate's)".into(),
                ))
            }
            _ => {}
        }
        if let Support::Roller { normal } = support.support {
            let along = normal[0] * n[0] + normal[1] * n[1];
            if along.abs() > 1e-12 && on_contact {
                return Err((
                    key,
                    format!(
                        "it holds u·({:.3}, {:.3}) on a part of `boundary.contact` too, which has a component along the contact direction ({:.3}, {:.3}): the support and the contact constraint would both fix u·n_c there; drop the support on the contact part",
                        normal[0], normal[1], n[0], n[1]
                    ),
                ));
            }
        }
    }
    let edges = oriented_edges(&mesh, &contact);
    faces_the_foundation(&edges, n)?;
    if let Some(c) = facts.centre {
        centre_on_contact(&edges, n, c).map_err(|m| ("parameters.contact_centre".into(), m))?;
    }
    let data = |name: &str| scene.data_fn(name).cloned();
    let gap = data("g").ok_or_else(|| {
        (
            "data.gap".to_string(),
            "missing: give the gap g(x, y) to the foundation along n_c (\"0\": touching)".into(),
        )
    })?;
    let pressure = data("q").ok_or_else(|| {
        (
            "data.pressure".to_string(),
            "missing: give the pressure q(x, y) on `boundary.load`, pressing in".into(),
        )
    })?;
    let gap_range = finite_on(&mesh, &contact, &gap).map_err(|m| ("data.gap".into(), m))?;
    let pressure_range =
        finite_on(&mesh, &loaded, &pressure).map_err(|m| ("data.pressure".into(), m))?;
    presses(&mesh, &loaded, &pressure, n).map_err(|m| ("data.pressure".into(), m))?;
    if let Some(exact) = scene.exact_at(&crate::scene::Posed {
        load: scene.load.as_ref().map(|l| l.default),
        parameters: Vec::new(),
    }) {
        if exact.value.is_some() || exact.gradient.is_some() || exact.hessian.is_some() {
            return Err((
                "exact.u".into(),
                "a contact file's exact solution is its pressure, `[exact] pressure`: the displacement is not compared".into(),
            ));
        }
        if let Some(p) = &exact.multiplier {
            finite_on(&mesh, &contact, p).map_err(|m| ("exact.pressure".into(), m))?;
        }
    }
    let scales = DataScales {
        pressure: pressure_range[0].abs().max(pressure_range[1].abs()),
        smallest_gap: gap_range[0],
        diameter: fem_runtime::problem::domain::bounding_diameter(&mesh),
        young: facts.young,
        translation_held: translation_held(scene, facts),
    };
    let load = scene.load.as_ref().map_or(1.0, |l| l.default);
    scales.check(load).map_err(|(key, m)| (key.to_string(), m))
}

/// Whether a support holds the translation along `n_c` (the gap is then no rigid
/// translation, and the contact force need not balance the load alone).
pub fn translation_held(scene: &Scene, facts: &ContactFacts) -> bool {
    let n = facts.direction;
    scene.supports.iter().any(|s| match s.support {
        Support::Roller { normal } => (normal[0] * n[0] + normal[1] * n[1]).abs() > 1e-12,
        Support::Clamped => true,
        _ => false,
    })
}

/// Γ_C must face the foundation: the body's outward normal ν along n_c, on the whole and
/// edge by edge.
fn faces_the_foundation(edges: &[[[f64; 2]; 2]], n: [f64; 2]) -> Result<(), FieldError> {
    let normal_along = |ends: &[[f64; 2]; 2]| {
        let nu = [ends[1][1] - ends[0][1], -(ends[1][0] - ends[0][0])];
        nu[0] * n[0] + nu[1] * n[1]
    };
    let (facing, total) = edges.iter().fold((0.0, 0.0), |(f, t), ends| {
        (f + normal_along(ends), t + length(ends))
    });
    // a face of Γ_C turned away from the foundation is inside the body's shadow, and its
    // constraint acts through the body (a trapezoid with its top and bottom as Γ_C
    // passed the mean and tripled the peak pressure)
    let cosine = |ends: &[[f64; 2]; 2]| normal_along(ends) / length(ends);
    let turned_away = edges.iter().find(|ends| cosine(ends) < -1e-6);
    // where some edge faces the foundation, n_c is right for it and the edges turned
    // away are at fault (top and bottom as Γ_C have mean ν·n_c = 0)
    let some_facing = edges.iter().any(|ends| cosine(ends) > 1e-6);
    if let Some(ends) = turned_away.filter(|_| some_facing) {
        let middle = point(ends, 0.5);
        return Err((
            "boundary.contact".into(),
            format!(
                "its edge at ({:.6}, {:.6}) faces away from the foundation (its outward normal points against the contact direction ({:.3}, {:.3})): a part of Γ_C turned away from the plane cannot touch it; name only the faces towards it",
                middle[0], middle[1], n[0], n[1]
            ),
        ));
    }
    if facing <= 1e-9 * total {
        return Err((
            "parameters.contact_direction".into(),
            format!(
                "({:.3}, {:.3}) does not point away from the body on `boundary.contact`: its outward normal ν has mean ν·n_c = {:.3} there, so the foundation would lie inside the body; n_c is the foundation plane's normal away from the body{}",
                n[0],
                n[1],
                facing / total,
                if turned_away.is_some() {
                    format!(": here [{}, {}]", -n[0] + 0.0, -n[1] + 0.0)
                } else {
                    " (e.g. [0.0, 1.0] for a contact part on the top)".to_string()
                }
            ),
        ));
    }
    Ok(())
}

/// The centre the half-width is measured from lies on Γ_C's extent along the plane.
fn centre_on_contact(edges: &[[[f64; 2]; 2]], n: [f64; 2], c: f64) -> Result<(), String> {
    let along = contact_tangent(n);
    let (lo, hi) = edges
        .iter()
        .flatten()
        .map(|p| along[0] * p[0] + along[1] * p[1])
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), s| {
            (lo.min(s), hi.max(s))
        });
    let slack = 1e-9 * (hi - lo).abs().max(lo.abs()).max(hi.abs());
    if c >= lo - slack && c <= hi + slack {
        return Ok(());
    }
    // under a horizontal or vertical plane the coordinate is x or y; under an oblique
    // one, the distance along the plane's tangent from the origin
    let coordinate = if along[1] == 0.0 {
        "x".to_string()
    } else if along[0] == 0.0 {
        "y".to_string()
    } else {
        format!(
            "the coordinate along the plane, {:.4}·x + {:.4}·y",
            along[0], along[1]
        )
    };
    Err(format!(
        "{c} lies outside `boundary.contact`, which spans {lo} to {hi} in {coordinate}: the half-width is measured from it"
    ))
}

/// An error when the mesh falls into separate pieces: a contact scene poses one body on
/// the foundation, whose rigid motions the supports, the contact and the load's
/// direction are checked to hold; a second piece escapes those checks (a floating
/// second block ended in "the matrix is not positive definite").
fn one_body(mesh: &TriangleMesh) -> Result<(), String> {
    let (piece, count) = mesh.cell_pieces();
    if count < 2 {
        return Ok(());
    }
    let sizes = (0..count)
        .map(|p| piece.iter().filter(|&&q| q == p).count().to_string())
        .collect::<Vec<_>>();
    Err(format!(
        "the mesh falls into {count} pieces joined by no edge (of {} cells; pieces that share only a vertex are a hinge, which holds nothing): a contact scene poses one elastic body on a rigid foundation; mesh one connected body (in Gmsh, a coherent geometry), or pose each body in its own scene",
        sizes.join(", ")
    ))
}

/// The markers of `part`, each of whose names must hold a boundary edge.
fn markers_on_boundary(mesh: &TriangleMesh, part: &Part) -> Result<Vec<u32>, String> {
    let names = match part {
        Part::All => return Ok(mesh.boundary_edges().iter().map(|&(_, m)| m).collect()),
        Part::Named(names) => names,
    };
    let mut all = Vec::new();
    for name in names {
        let markers = mesh
            .boundary_part_markers(std::slice::from_ref(name))
            .map_err(|e| match e {
                Error::Input(m) => m,
                other => other.to_string(),
            })?;
        if mesh.boundary_edges_with_markers(&markers) == 0 {
            return Err(format!(
                "the part `{name}` is not on the boundary: no boundary edge of the mesh belongs to it (a curve inside the body cannot touch the foundation, carry a pressure or a support)"
            ));
        }
        all.extend(markers);
    }
    all.sort_unstable();
    all.dedup();
    Ok(all)
}

/// The boundary edges carrying one of `markers`: their ends, ordered so the body lies to
/// the left (the outward normal is `(t_y, −t_x)/|t|`).
pub fn oriented_edges(mesh: &TriangleMesh, markers: &[u32]) -> Vec<[[f64; 2]; 2]> {
    let v = mesh.vertices();
    mesh.boundary_edges()
        .iter()
        .filter(|(_, m)| markers.contains(m))
        .map(|&(e, _)| {
            let [a, b] = mesh.edges()[e];
            let (cell, _) = mesh.edge_cells(e);
            let c = mesh.cell(cell);
            let third = c.iter().copied().find(|&k| k != a && k != b).unwrap_or(a);
            let (pa, pb, pc) = (v[a], v[b], v[third]);
            // the third vertex to the left of a → b: counter-clockwise
            let cross = (pb[0] - pa[0]) * (pc[1] - pa[1]) - (pb[1] - pa[1]) * (pc[0] - pa[0]);
            if cross > 0.0 {
                [pa, pb]
            } else {
                [pb, pa]
            }
        })
        .collect()
}

/// The point at share `s` of the edge `ends`.
pub fn point(ends: &[[f64; 2]; 2], s: f64) -> [f64; 2] {
    let [a, b] = ends;
    [a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])]
}

fn length(ends: &[[f64; 2]; 2]) -> f64 {
    (ends[1][0] - ends[0][0]).hypot(ends[1][1] - ends[0][1])
}

/// The range of `data` over the ends and the Gauss points of every edge of the part,
/// where it is finite and within ±[`MAX_DATA`] there.
fn finite_on(mesh: &TriangleMesh, markers: &[u32], data: &Data) -> Result<[f64; 2], String> {
    let gauss = fem_runtime::gauss_legendre(GAUSS_POINTS);
    let mut range = [f64::INFINITY, f64::NEG_INFINITY];
    for ends in oriented_edges(mesh, markers) {
        for s in [0.0, 1.0].iter().chain(&gauss.points) {
            let p = point(&ends, *s);
            let value = data.at(&p);
            if !value.is_finite() {
                return Err(format!(
                    "the expression is {value} at ({}, {}) on its boundary part: it must evaluate to a finite number there",
                    p[0], p[1]
                ));
            }
            if value.abs() > MAX_DATA {
                return Err(format!(
                    "the expression is {value:e} at ({}, {}) on its boundary part, beyond ±{MAX_DATA:e}: the solve's norms would overflow; rescale the units",
                    p[0], p[1]
                ));
            }
            range = [range[0].min(value), range[1].max(value)];
        }
    }
    Ok(range)
}

/// What [`DataScales::check`] needs of a scene's data.
#[derive(Clone, Copy, Debug)]
pub struct DataScales {
    /// max |q| over the quadrature points of Γ_N (before the load scale).
    pub pressure: f64,
    /// min g over Γ_C.
    pub smallest_gap: f64,
    /// The mesh's bounding-box diagonal L.
    pub diameter: f64,
    /// E.
    pub young: f64,
    /// Supports fix the displacement along n_c (the gap is then no translation).
    pub translation_held: bool,
}

impl DataScales {
    /// The scales of `pressure` on the edges `loaded` and `gap` on `contact` of `mesh`
    /// (non-finite values are left to the solve's own checks).
    pub fn of(
        mesh: &TriangleMesh,
        contact: &[u32],
        loaded: &[u32],
        pressure: &Data,
        gap: &Data,
        young: f64,
        translation_held: bool,
    ) -> Self {
        let range = |markers: &[u32], data: &Data| {
            finite_on(mesh, markers, data).unwrap_or([f64::NAN, f64::NAN])
        };
        let p = range(loaded, pressure);
        Self {
            pressure: p[0].abs().max(p[1].abs()),
            smallest_gap: range(contact, gap)[0],
            diameter: fem_runtime::problem::domain::bounding_diameter(mesh),
            young,
            translation_held,
        }
    }

    /// Checks the data's scales at the load magnitude `load`: the pressure
    /// `load · max|q|` within [1e-100, 1e100], and a gap whose rounding does not swamp
    /// the elastic displacement ([`MAX_GAP_ROUNDING`]). The error names its key.
    ///
    /// # Errors
    /// `(key, message)`.
    pub fn check(&self, load: f64) -> Result<(), (&'static str, String)> {
        let pressure = load * self.pressure;
        // the smallest pressure the range of E allows (pressure = "1e-320" stopped
        // Newton at a KKT residual of 5e-3)
        if pressure > 0.0 && pressure < 1.0 / MAX_DATA {
            return Err((
                "data.pressure",
                format!(
                    "the pressure reaches at most {pressure:e} (scale {load:e} times max|q| = {:e}), below {:e}: the solve would underflow; rescale the units",
                    self.pressure,
                    1.0 / MAX_DATA
                ),
            ));
        }
        if pressure > MAX_DATA {
            return Err((
                "data.pressure",
                format!(
                    "the pressure reaches {pressure:e} (scale {load:e} times max|q| = {:e}), beyond {MAX_DATA:e}: the solve's norms would overflow; rescale the units",
                    self.pressure
                ),
            ));
        }
        let elastic = pressure * self.diameter / self.young;
        let translation = self.smallest_gap.abs();
        if !self.translation_held && f64::EPSILON * translation > MAX_GAP_ROUNDING * elastic {
            return Err((
                "data.gap",
                format!(
                    "the body moves by the gap's smallest value {:e} before it touches (or starts that far inside the foundation), {:.1e} times its elastic displacement (about load · max|q| L/E = {elastic:.2e}): the displacement then holds the deformation only in its last digits; measure the gap from a foundation placed closer (only its variation along Γ_C matters)",
                    self.smallest_gap,
                    translation / elastic
                ),
            ));
        }
        Ok(())
    }
}

/// The resultant `∫_Γ_N q (−n) ds` pushes along `n_c`, towards the foundation: else
/// nothing holds the body (the foundation only pushes).
fn presses(
    mesh: &TriangleMesh,
    markers: &[u32],
    pressure: &Data,
    direction: [f64; 2],
) -> Result<(), String> {
    let (force, magnitude) = resultant_and_magnitude(mesh, markers, pressure);
    let along = force[0] * direction[0] + force[1] * direction[1];
    // a resultant within the rounding of its own quadrature is zero, whichever its sign
    // (x − 0.5 on the top face came out +7e-18, sin(2πx) −4e-17)
    if along.abs() <= RESULTANT_ROUNDING * magnitude {
        Err(format!(
            "the pressure's resultant along the contact direction is zero (to the rounding {along:.1e} of ∫|q| ds = {magnitude:.3e}): it does not push the body towards the foundation, and nothing else holds it then"
        ))
    } else if along > 0.0 {
        Ok(())
    } else {
        Err(format!(
            "the pressure's resultant ({:e}, {:e}) does not push the body towards the foundation (its component along the contact direction is {along:e} ≤ 0): it pulls the body off, and nothing holds it then (a pressure is positive pressing in)",
            force[0], force[1]
        ))
    }
}

/// The resultant `∫_part q (−n) ds` and `∫_part |q| ds`, the size the resultant's
/// rounding is relative to: Gauss–Legendre on [`RESULTANT_PIECES`] pieces of each edge,
/// exact for q of degree 7 on each piece.
pub fn resultant_and_magnitude(
    mesh: &TriangleMesh,
    markers: &[u32],
    pressure: &Data,
) -> ([f64; 2], f64) {
    let gauss = fem_runtime::gauss_legendre(GAUSS_POINTS);
    let mut force = [0.0; 2];
    let mut magnitude = 0.0;
    for ends in oriented_edges(mesh, markers) {
        let l = length(&ends);
        let n = [
            (ends[1][1] - ends[0][1]) / l,
            -(ends[1][0] - ends[0][0]) / l,
        ];
        let (mut q, mut size) = (0.0, 0.0);
        let piece = 1.0 / RESULTANT_PIECES as f64;
        for k in 0..RESULTANT_PIECES {
            for (&s, &w) in gauss.points.iter().zip(&gauss.weights) {
                let value = pressure.at(&point(&ends, (k as f64 + s) * piece));
                q += w * value * l * piece;
                size += w * value.abs() * l * piece;
            }
        }
        magnitude += size;
        force[0] -= q * n[0];
        force[1] -= q * n[1];
    }
    (force, magnitude)
}

/// The rule on an edge `[0, 1]` of the errors against an exact pressure: 8-point
/// Gauss–Legendre on each of 8 pieces. An exact contact pressure has square-root edges
/// (Hertz's at ±b), where one 8-point rule on the edge across it missed the best P1
/// fit's error by 12 %; the pieces bring that below 1 %.
fn along_edge() -> fem_runtime::QuadratureRule {
    const PIECES: usize = 8;
    let gauss = fem_runtime::gauss_legendre(8);
    let piece = 1.0 / PIECES as f64;
    let (mut points, mut weights) = (Vec::new(), Vec::new());
    for k in 0..PIECES {
        for (&s, &w) in gauss.points.iter().zip(&gauss.weights) {
            points.push((k as f64 + s) * piece);
            weights.push(w * piece);
        }
    }
    fem_runtime::QuadratureRule { points, weights }
}

/// `‖Πp − p‖/‖p‖` on Γ_C for `Πp` the best continuous P1 fit of the exact pressure p:
/// its L² projection onto the piecewise linears on the vertices of Γ_C, given by
/// `edges` (the ends of each edge and the indices of their values among `vertices`).
/// The mass matrix, scaled by its diagonal, has a condition number bounded
/// independently of the edges' lengths (at most 3 in 1D), so Jacobi-preconditioned CG
/// solves it in a few dozen steps. The rule of [`along_edge`]; an exact pressure of
/// zero norm gives the absolute error.
pub fn best_p1_error(edges: &[([[f64; 2]; 2], [usize; 2])], vertices: usize, exact: &Data) -> f64 {
    let gauss = along_edge();
    let mut mass: Vec<Vec<(usize, f64)>> = vec![Vec::new(); vertices];
    let mut rhs = vec![0.0; vertices];
    let mut norm = 0.0;
    for (ends, [a, b]) in edges {
        let l = length(ends);
        for (i, j, m) in [(a, a, 2.0), (a, b, 1.0), (b, a, 1.0), (b, b, 2.0)] {
            mass[*i].push((*j, m * l / 6.0));
        }
        for (&t, &w) in gauss.points.iter().zip(&gauss.weights) {
            let p = exact.at(&point(ends, t));
            rhs[*a] += w * l * (1.0 - t) * p;
            rhs[*b] += w * l * t * p;
            norm += w * l * p * p;
        }
    }
    let fit = jacobi_cg(&mass, &rhs);
    let mut error = 0.0;
    for (ends, [a, b]) in edges {
        let l = length(ends);
        for (&t, &w) in gauss.points.iter().zip(&gauss.weights) {
            let d = (1.0 - t) * fit[*a] + t * fit[*b] - exact.at(&point(ends, t));
            error += w * l * d * d;
        }
    }
    let scale = if norm > 0.0 { norm } else { 1.0 };
    (error / scale).sqrt()
}

/// `M x = b` for the symmetric positive definite `M` given by rows of `(column, value)`
/// (repeated columns summed), by conjugate gradients preconditioned with the diagonal,
/// to 1e-14 of `‖b‖`.
fn jacobi_cg(rows: &[Vec<(usize, f64)>], b: &[f64]) -> Vec<f64> {
    let multiply = |x: &[f64]| -> Vec<f64> {
        rows.iter()
            .map(|row| row.iter().map(|&(j, m)| m * x[j]).sum())
            .collect()
    };
    let diagonal: Vec<f64> = rows
        .iter()
        .enumerate()
        .map(|(i, row)| row.iter().filter(|e| e.0 == i).map(|e| e.1).sum())
        .collect();
    let dot = |x: &[f64], y: &[f64]| x.iter().zip(y).map(|(a, b)| a * b).sum::<f64>();
    let mut x = vec![0.0; b.len()];
    let mut r = b.to_vec();
    let mut z: Vec<f64> = r.iter().zip(&diagonal).map(|(r, d)| r / d).collect();
    let mut p = z.clone();
    let mut rz = dot(&r, &z);
    let tolerance = 1e-14 * dot(b, b).sqrt();
    for _ in 0..10 * b.len().max(10) {
        if dot(&r, &r).sqrt() <= tolerance {
            break;
        }
        let q = multiply(&p);
        let step = rz / dot(&p, &q);
        for i in 0..x.len() {
            x[i] += step * p[i];
            r[i] -= step * q[i];
        }
        z = r.iter().zip(&diagonal).map(|(r, d)| r / d).collect();
        let next = dot(&r, &z);
        let beta = next / rz;
        rz = next;
        for i in 0..p.len() {
            p[i] = z[i] + beta * p[i];
        }
    }
    x
}

/// `‖λ_h − p‖/‖p‖` on Γ_C and the same of p's best P0 fit (the edge means), for a
/// pressure linear along each edge `ends`, `[λ_h(ends[0]), λ_h(ends[1])]` (equal for
/// P0), p the exact pressure (the rule of [`along_edge`]); an exact pressure of zero
/// norm gives the absolute errors.
pub fn pressure_errors(edges: &[([[f64; 2]; 2], [f64; 2])], exact: &Data) -> [f64; 2] {
    let gauss = along_edge();
    let (mut error, mut best, mut norm) = (0.0, 0.0, 0.0);
    for (ends, [start, end]) in edges {
        let l = length(ends);
        let values: Vec<f64> = gauss
            .points
            .iter()
            .map(|&s| exact.at(&point(ends, s)))
            .collect();
        let mean: f64 = values.iter().zip(&gauss.weights).map(|(p, w)| w * p).sum();
        for ((&p, &w), &s) in values.iter().zip(&gauss.weights).zip(&gauss.points) {
            let lambda = (1.0 - s) * start + s * end;
            error += w * l * (lambda - p) * (lambda - p);
            best += w * l * (mean - p) * (mean - p);
            norm += w * l * p * p;
        }
    }
    let scale = if norm > 0.0 { norm } else { 1.0 };
    [(error / scale).sqrt(), (best / scale).sqrt()]
}
