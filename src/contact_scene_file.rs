//! Contact scene files: a Signorini problem (docs/contact.md) as data,
//! `fem-forms solve --scene my.toml` with `model = "contact"`.
//!
//! The membrane scene files' conventions hold ([`crate::models::scene_file`]): data are
//! expressions in `x` and `y` (parsed once by [`crate::models::scene_file::expression`]), boundary
//! parts are chosen by name (Gmsh physical names of curve groups, or the generator's
//! sides), and every error names the file and the key at fault. An example, the patch
//! test with a pressure given as an expression:
//!
//! ```toml
//! name = "block"
//! model = "contact"
//! pair = "p1-p0"                  # or p2-p0; p1-p0 by default
//!
//! [mesh]
//! generator = "rectangle"         # sides `bottom`, `right`, `top`, `left`
//! x = [0.0, 2.0]
//! y = [0.0, 1.0]
//! cells = [8, 4]                  # nx, ny (each square split by its diagonal)
//! # file = "block.msh"            # or a Gmsh MSH 4.1 file, relative to this file
//! # refinements = 1               # uniform refinements (both kinds; --mesh-size)
//!
//! [material]
//! young = 1000.0                  # E > 0
//! poisson = 0.3                   # ν in (−1, ½)
//! plane = "strain"                # or "stress"
//!
//! [boundary]                      # each a name or a list of names
//! contact = "bottom"              # Γ_C, the potential contact boundary
//! load = "top"                    # Γ_N, where the pressure acts
//! fixed_x = "left"                # u_x = 0 (optional)
//! # fixed_y = []                  # u_y = 0 (optional)
//! # [[boundary.roller]]           # u·normal = 0 on a part, any direction (optional)
//! # part = "left"
//! # normal = [0.866, 0.5]
//!
//! [parameters]
//! contact_direction = [0.0, -1.0] # n_c: the foundation's normal away from the body
//! # alpha = 1e-4                  # α; 1/(2 max C_I,E) by default; 0: the plain method
//! # contact_centre = 0.0          # a symmetry line's x (y beside a vertical plane): the
//!                                 # half-width is measured along the plane from it
//!
//! [data]
//! load = 1.0                      # a scale of the pressure (--load); 1 by default
//! pressure = "2.5"                # q(x, y) on Γ_N, force per length, pressing in
//! gap = "0"                       # g(x, y) on Γ_C along n_c, length
//!
//! [exact]                         # optional: the contact pressure where known
//! pressure = "2.5"                # λ(x, y) on Γ_C at the file's data.load (not compared
//!                                 # under another --load: contact is not linear in it)
//! # accuracy = 0.02               # (top level) the relative L² error it should reach
//! ```
//!
//! Refused, naming the key: an unknown model, pair (or a P1-multiplier one), generator or
//! key; `mesh.refinements` beyond 6 (and, when solved with the command line's
//! overrides, beyond the memory the solver allows itself: an estimate, before
//! refining); an `accuracy` without `[exact]`; a part name the
//! mesh does not have (`boundary.contact`, …, with the names it has); a part that holds
//! no boundary edge (an interior Gmsh curve: "not on the boundary"); `material.young`
//! ≤ 0 or outside [1e-100, 1e100]; `material.poisson` outside (−1, ½); a zero
//! `parameters.contact_direction`, or one that does not point away from the body on
//! Γ_C (the mean of the outward normal along it ≤ 0: the foundation would lie inside
//! the body); a `parameters.contact_centre` outside Γ_C's extent along the plane; a
//! negative `parameters.alpha`; an expression that
//! does not parse, uses a variable other than x, y, or does not evaluate to a finite
//! number within ±1e100 on its part (`data.gap` on Γ_C, `data.pressure` on Γ_N,
//! `exact.pressure` on Γ_C); a pressure scale times max|q| beyond 1e100; a pressure
//! whose resultant pulls the body off the foundation or is zero to within 1e-12 of
//! `∫|q| ds` (`data.pressure`: nothing then holds the body); a gap whose smallest value is so far beyond the elastic
//! displacement that rounding swamps it (`data.gap`, `MAX_GAP_ROUNDING`; checked again
//! under `--load`).

use crate::models::data::Data;
use crate::models::scene_file::expression;
use crate::models::signorini::{solve_signorini, Plane, SignoriniInput, SignoriniSolution};
use crate::signorini::{ContactPair, ContactReport, PressureProfile};
use fem_runtime::{Diagonal, Error, Result, TriangleMesh};
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// The largest number of uniform refinements of a contact scene file's mesh.
pub const MAX_REFINEMENTS: usize = 6;

/// Peak memory of a contact solve per triangle of its finest mesh, in bytes, with
/// some margin: measured on examples/contact-gap.toml (GNU time's maximum resident set,
/// 2026-12-01) 2.8 kB per triangle for p1-p0 at 131k and 524k triangles, 12.9 and
/// 16.3 kB for p2-p0.
fn bytes_per_triangle(pair: ContactPair) -> f64 {
    match pair.displacement() {
        crate::models::signorini::Displacement::P1 => 3.5e3,
        crate::models::signorini::Displacement::P2 => 20e3,
    }
}

/// Refuses `refinements` of a mesh of `cells` triangles that would need more memory
/// than [`crate::membranes::memory_limit_bytes`] with `pair` (each refinement
/// quadruples the triangles), before anything is refined.
fn check_memory(
    cells: usize,
    refinements: usize,
    pair: ContactPair,
) -> std::result::Result<(), String> {
    let bytes = fem_runtime::mesh::triangle::estimated_bytes(
        cells,
        refinements as u32,
        bytes_per_triangle(pair),
    );
    if let Some(m) = crate::membranes::beyond_memory(bytes) {
        return Err(format!(
            "{refinements} uniform refinements of the mesh's {cells} triangles make {:.0} triangles, which with {} {m}",
            cells as f64 * 4f64.powi(refinements as i32),
            pair.name(),
        ));
    }
    Ok(())
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct ContactToml {
    name: Option<String>,
    description: Option<String>,
    model: String,
    pair: Option<String>,
    mesh: MeshToml,
    material: MaterialToml,
    boundary: BoundaryToml,
    #[serde(default)]
    parameters: ParametersToml,
    data: DataToml,
    exact: Option<ExactToml>,
    accuracy: Option<f64>,
}

/// A pair written as a TOML array of exactly two entries: serde's arrays read the
/// first two of a longer one and drop the rest (`x = [0, 1, 2]` solved on (0, 1)).
fn two<'de, D, T>(deserializer: D) -> std::result::Result<Option<[T; 2]>, D::Error>
where
    D: serde::Deserializer<'de>,
    T: Deserialize<'de>,
{
    let entries = Vec::<T>::deserialize(deserializer)?;
    let count = entries.len();
    <[T; 2]>::try_from(entries).map(Some).map_err(|_| {
        serde::de::Error::custom(match count {
            1 => "an array of one entry where two are expected".to_string(),
            _ => format!("an array of {count} entries where two are expected"),
        })
    })
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct MeshToml {
    generator: Option<String>,
    #[serde(default, deserialize_with = "two")]
    x: Option<[f64; 2]>,
    #[serde(default, deserialize_with = "two")]
    y: Option<[f64; 2]>,
    #[serde(default, deserialize_with = "two")]
    cells: Option<[usize; 2]>,
    file: Option<PathBuf>,
    refinements: Option<usize>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct MaterialToml {
    young: f64,
    poisson: f64,
    plane: Option<String>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct BoundaryToml {
    contact: toml::Value,
    load: toml::Value,
    fixed_x: Option<toml::Value>,
    fixed_y: Option<toml::Value>,
    #[serde(default)]
    roller: Vec<RollerToml>,
}

/// `[[boundary.roller]]`: `u·normal = 0` on `part`.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct RollerToml {
    part: toml::Value,
    normal: [f64; 2],
}

#[derive(Deserialize, Debug, Default)]
#[serde(deny_unknown_fields)]
struct ParametersToml {
    #[serde(default, deserialize_with = "two")]
    contact_direction: Option<[f64; 2]>,
    alpha: Option<f64>,
    contact_centre: Option<f64>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct DataToml {
    load: Option<f64>,
    pressure: String,
    gap: String,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct ExactToml {
    pressure: String,
}

/// A contact problem read from a scene file: the mesh as read (before refinement), the
/// markers of its parts, the material and the data (see the module documentation).
#[derive(Clone, Debug)]
pub struct ContactSceneFile {
    /// The scene's name (names output files).
    pub name: String,
    /// One line of description.
    pub description: String,
    /// The pair (default p1-p0).
    pub pair: ContactPair,
    /// The mesh the file gives, before `refinements`.
    pub mesh: TriangleMesh,
    /// Uniform refinements of `mesh` (`mesh.refinements`, `--mesh-size`).
    pub refinements: usize,
    /// Young's modulus E.
    pub young: f64,
    /// Poisson's ratio ν.
    pub poisson: f64,
    /// Plane strain or stress.
    pub plane: Plane,
    /// Boundary markers of Γ_C.
    pub contact: Vec<u32>,
    /// Boundary markers of Γ_N.
    pub load_part: Vec<u32>,
    /// Boundary markers where `u_x = 0`.
    pub fixed_x: Vec<u32>,
    /// Boundary markers where `u_y = 0`.
    pub fixed_y: Vec<u32>,
    /// Rollers along any direction: markers and the unit direction held.
    pub rollers: Vec<(Vec<u32>, [f64; 2])>,
    /// The boundary part names as written, per key (for the report).
    pub part_names: Vec<(String, Vec<String>)>,
    /// The contact direction n_c (unit).
    pub contact_direction: [f64; 2],
    /// α where the file fixes it.
    pub alpha: Option<f64>,
    /// The x of the middle of the contact zone (a symmetry line), from which the
    /// half-width is measured; `None`: the middle of the pressed edges.
    pub contact_centre: Option<f64>,
    /// The pressure's scale (`data.load`, `--load`).
    pub load: f64,
    /// The pressure shape q(x, y) on Γ_N (multiplied by `load`).
    pub pressure: Data,
    /// The gap g(x, y) on Γ_C.
    pub gap: Data,
    /// The scales [`data_scales`] checks at every load: the largest |q| on Γ_N, the
    /// smallest g on Γ_C, the body's diameter, and whether supports hold the
    /// translation along n_c.
    scales: DataScales,
    /// The exact contact pressure at the file's own `load`, where known. Contact is not
    /// linear in the load (the contact set grows with it: Hertz's pressure goes like
    /// √P), so under another `--load` it is not the solution and is not compared.
    pub exact_pressure: Option<Data>,
    /// The accuracy the file asks of the pressure (relative L² error), where given.
    pub accuracy: Option<f64>,
}

/// Whether the TOML text names the contact model (`model = "contact"`): the CLI's
/// choice between this reader and [`crate::models::scene_file`]'s. Text that is not TOML is
/// left to the membrane reader, whose error names the line.
pub fn names_contact(text: &str) -> bool {
    text.parse::<toml::Table>()
        .ok()
        .and_then(|t| {
            t.get("model")
                .and_then(|m| m.as_str())
                .map(|m| m == "contact")
        })
        .unwrap_or(false)
}

/// Reads and checks a contact scene file (Gmsh meshes are read and their parts checked
/// here too).
///
/// # Errors
/// An unreadable file; those of [`parse`].
pub fn read(path: &Path) -> Result<ContactSceneFile> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        Error::Input(format!(
            "cannot read the scene file {}: {e}",
            path.display()
        ))
    })?;
    parse(&text, path)
}

/// Parses the text of a contact scene file; `path` names it in errors and anchors a
/// relative mesh path.
///
/// # Errors
/// [`Error::Input`] naming the file and the key, for everything the module
/// documentation lists; TOML errors with their line and column.
pub fn parse(text: &str, path: &Path) -> Result<ContactSceneFile> {
    let file: ContactToml = toml::from_str(text)
        .map_err(|e| Error::Input(format!("scene file {}: {e}", path.display())))?;
    let at = |key: &str, message: String| {
        Error::Input(format!("{}: key `{key}`: {message}", path.display()))
    };
    if file.model != "contact" {
        return Err(at(
            "model",
            format!("`{}`: this reader poses `contact` problems", file.model),
        ));
    }
    let pair = match &file.pair {
        Some(p) => pair_of_file(p).map_err(|m| at("pair", m))?,
        None => ContactPair::P1P0,
    };
    let mesh = mesh_of(&file.mesh, path, &at)?;
    one_body(&mesh).map_err(|m| at("mesh", m))?;
    let refinements = file.mesh.refinements.unwrap_or(0);
    if refinements > MAX_REFINEMENTS {
        return Err(at(
            "mesh.refinements",
            format!("{refinements} uniform refinements: at most {MAX_REFINEMENTS}"),
        ));
    }
    let m = &file.material;
    if !(m.young.is_finite() && m.young > 0.0) {
        return Err(at(
            "material.young",
            format!(
                "Young's modulus E = {} must be positive and finite",
                m.young
            ),
        ));
    }
    if !(1.0 / MAX_DATA..=MAX_DATA).contains(&m.young) {
        return Err(at(
            "material.young",
            format!(
                "Young's modulus E = {:e} lies outside [{:e}, {MAX_DATA:e}]: the stiffness and the stabilization's ½/C_I,E would leave the range of double precision; rescale the units",
                m.young,
                1.0 / MAX_DATA
            ),
        ));
    }
    if !(m.poisson > -1.0 && m.poisson < 0.5) {
        return Err(at(
            "material.poisson",
            format!("Poisson's ratio ν = {} must lie in (−1, ½)", m.poisson),
        ));
    }
    let plane = match m.plane.as_deref() {
        None | Some("strain") => Plane::Strain,
        Some("stress") => Plane::Stress,
        Some(other) => {
            return Err(at(
                "material.plane",
                format!("`{other}`: write \"strain\" or \"stress\""),
            ))
        }
    };
    let mut part_names = Vec::new();
    let mut part = |key: &str, value: Option<&toml::Value>, required: bool| {
        let names = names_of(value, required).map_err(|m| at(key, m))?;
        let markers = if names.is_empty() {
            Vec::new()
        } else {
            markers_on_boundary(&mesh, &names).map_err(|m| at(key, m))?
        };
        part_names.push((key.to_string(), names));
        Ok::<_, Error>(markers)
    };
    let b = &file.boundary;
    let contact = part("boundary.contact", Some(&b.contact), true)?;
    let load_part = part("boundary.load", Some(&b.load), true)?;
    let fixed_x = part("boundary.fixed_x", b.fixed_x.as_ref(), false)?;
    let fixed_y = part("boundary.fixed_y", b.fixed_y.as_ref(), false)?;
    let mut rollers = Vec::with_capacity(b.roller.len());
    for (k, r) in b.roller.iter().enumerate() {
        let key = format!("boundary.roller[{k}]");
        let markers = part(&key, Some(&r.part), true)?;
        let [nx, ny] = r.normal;
        let length = nx.hypot(ny);
        if !(length.is_finite() && length > 0.0) {
            return Err(at(
                &format!("{key}.normal"),
                format!("({nx}, {ny}) must be a non-zero finite vector"),
            ));
        }
        rollers.push((markers, [nx / length, ny / length]));
    }
    let [cx, cy] = file.parameters.contact_direction.unwrap_or([0.0, -1.0]);
    let length = cx.hypot(cy);
    if !(length.is_finite() && length > 0.0) {
        return Err(at(
            "parameters.contact_direction",
            format!("({cx}, {cy}) must be a non-zero finite vector"),
        ));
    }
    let contact_direction = [cx / length, cy / length];
    if let Some(a) = file.parameters.alpha {
        if !(a.is_finite() && a >= 0.0) {
            return Err(at(
                "parameters.alpha",
                format!("α = {} must be ≥ 0 (0: the plain method)", crate::number(a)),
            ));
        }
    }
    // Γ_C must face the foundation: the body's outward normal ν along n_c on the whole
    // (a contact on the top face with n_c = (0, −1), a foundation inside the
    // block, was solved and reported as valid)
    let edges = oriented_edges(&mesh, &contact);
    let (facing, total) = edges.iter().fold((0.0, 0.0), |(f, t), ends| {
        let l = self::length(ends);
        let nu = [ends[1][1] - ends[0][1], -(ends[1][0] - ends[0][0])];
        (
            f + nu[0] * contact_direction[0] + nu[1] * contact_direction[1],
            t + l,
        )
    });
    // and edge by edge: a face of Γ_C turned away from the foundation is inside the
    // body's shadow, and its constraint acts through the body (a trapezoid with
    // its top and bottom as Γ_C passed the mean and tripled the peak pressure)
    let cosine = |ends: &&[[f64; 2]; 2]| {
        let nu = [ends[1][1] - ends[0][1], -(ends[1][0] - ends[0][0])];
        (nu[0] * contact_direction[0] + nu[1] * contact_direction[1]) / self::length(ends)
    };
    let turned_away = edges.iter().find(|ends| cosine(ends) < -1e-6);
    // some edge faces the foundation: n_c is right for it, and the edges turned away are
    // at fault (top and bottom as Γ_C have mean ν·n_c = 0, and were told to
    // flip n_c, whichever way it pointed)
    let some_facing = edges.iter().any(|ends| cosine(&ends) > 1e-6);
    if let Some(ends) = turned_away.filter(|_| some_facing) {
        let middle = point(ends, 0.5);
        return Err(at(
            "boundary.contact",
            format!(
                "its edge at ({:.6}, {:.6}) faces away from the foundation (its outward normal points against the contact direction ({:.3}, {:.3})): a part of Γ_C turned away from the plane cannot touch it; name only the faces towards it",
                middle[0], middle[1], contact_direction[0], contact_direction[1]
            ),
        ));
    }
    if facing <= 1e-9 * total {
        return Err(at(
            "parameters.contact_direction",
            format!(
                "({:.3}, {:.3}) does not point away from the body on `boundary.contact`: its outward normal ν has mean ν·n_c = {:.3} there, so the foundation would lie inside the body; n_c is the foundation plane's normal away from the body{}",
                contact_direction[0],
                contact_direction[1],
                facing / total,
                if turned_away.is_some() {
                    format!(
                        ": here [{}, {}]",
                        -contact_direction[0] + 0.0,
                        -contact_direction[1] + 0.0
                    )
                } else {
                    " (e.g. [0.0, 1.0] for a contact part on the top)".to_string()
                }
            ),
        ));
    }
    if let Some(c) = file.parameters.contact_centre {
        if !c.is_finite() {
            return Err(at(
                "parameters.contact_centre",
                format!("{} must be finite", crate::number(c)),
            ));
        }
        // measured along the plane: the half-width is taken from c, which must lie
        // on Γ_C's extent (5.0 beside a 1-wide block reported a half-width 5)
        let along = crate::models::signorini::contact_tangent(contact_direction);
        let (lo, hi) = edges
            .iter()
            .flatten()
            .map(|p| along[0] * p[0] + along[1] * p[1])
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), s| {
                (lo.min(s), hi.max(s))
            });
        let slack = 1e-9 * (hi - lo).abs().max(lo.abs()).max(hi.abs());
        if !(c >= lo - slack && c <= hi + slack) {
            // under a horizontal or vertical plane the coordinate is x or y; under an
            // oblique one, the distance along the plane's tangent from the origin
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
            return Err(at(
                "parameters.contact_centre",
                format!(
                    "{c} lies outside `boundary.contact`, which spans {lo} to {hi} in {coordinate}: the half-width is measured from it"
                ),
            ));
        }
    }
    let load = file.data.load.unwrap_or(1.0);
    check_load(load).map_err(|m| at("data.load", m))?;
    let pressure = expression(&file.data.pressure, "data.pressure", path)?;
    let gap = expression(&file.data.gap, "data.gap", path)?;
    // the model refuses this too, but by its boundary markers: here by the key
    for (key, fixed, axis) in [
        ("boundary.fixed_x", &fixed_x, 0),
        ("boundary.fixed_y", &fixed_y, 1),
    ] {
        if contact_direction[axis] != 0.0 && fixed.iter().any(|m| contact.contains(m)) {
            return Err(at(
                key,
                format!(
                    "it fixes u_{} on a part of `boundary.contact` too, a component of the contact direction ({:.3}, {:.3}): the support and the contact constraint would both fix u·n_c there; drop the support on the contact part",
                    ["x", "y"][axis],
                    contact_direction[0],
                    contact_direction[1]
                ),
            ));
        }
    }
    let gap_range = finite_on(&mesh, &contact, &gap).map_err(|m| at("data.gap", m))?;
    let pressure_range =
        finite_on(&mesh, &load_part, &pressure).map_err(|m| at("data.pressure", m))?;
    presses(&mesh, &load_part, &pressure, contact_direction).map_err(|m| at("data.pressure", m))?;
    let scales = DataScales {
        pressure: pressure_range[0].abs().max(pressure_range[1].abs()),
        smallest_gap: gap_range[0],
        diameter: fem_runtime::problem::domain::bounding_diameter(&mesh),
        young: m.young,
        translation_held: (contact_direction[0] != 0.0 && !fixed_x.is_empty())
            || (contact_direction[1] != 0.0 && !fixed_y.is_empty())
            || rollers.iter().any(|(_, n)| {
                (n[0] * contact_direction[0] + n[1] * contact_direction[1]).abs() > 1e-12
            }),
    };
    data_scales(&scales, load).map_err(|(key, m)| at(key, m))?;
    let exact_pressure = file
        .exact
        .as_ref()
        .map(|e| expression(&e.pressure, "exact.pressure", path))
        .transpose()?;
    if let Some(exact) = &exact_pressure {
        finite_on(&mesh, &contact, exact).map_err(|m| at("exact.pressure", m))?;
    }
    if let Some(a) = file.accuracy {
        if !(a.is_finite() && a > 0.0) {
            return Err(at(
                "accuracy",
                format!("{} must be positive", crate::number(a)),
            ));
        }
        if exact_pressure.is_none() {
            return Err(at(
                "accuracy",
                "an accuracy needs an `[exact] pressure` to measure the error against".into(),
            ));
        }
    }
    let name = crate::models::scene_file::scene_name(file.name.as_deref(), path, "contact")
        .map_err(|m| at("name", m))?;
    Ok(ContactSceneFile {
        name,
        description: file
            .description
            .clone()
            .unwrap_or_else(|| format!("contact scene file {}", path.display())),
        pair,
        mesh,
        refinements,
        young: m.young,
        poisson: m.poisson,
        plane,
        contact,
        load_part,
        fixed_x,
        fixed_y,
        rollers,
        part_names,
        contact_direction,
        alpha: file.parameters.alpha,
        contact_centre: file.parameters.contact_centre,
        load,
        pressure,
        gap,
        scales,
        exact_pressure,
        accuracy: file.accuracy,
    })
}

/// The load scale's range (as the built-in scenes'): positive, finite, at most 1e100.
fn check_load(load: f64) -> std::result::Result<(), String> {
    if !load.is_finite() {
        Err(format!(
            "the pressure's scale {load} must be a finite number"
        ))
    } else if load <= 0.0 {
        Err(format!(
            "the pressure's scale {load:e} must be positive; turn the pressure's direction in `data.pressure`"
        ))
    } else if load > MAX_DATA {
        Err(format!(
            "the pressure's scale {load:e} is beyond {MAX_DATA:e}: the solve's norms would overflow; rescale the units"
        ))
    } else if load < crate::MIN_DATA_SIZE {
        Err(format!(
            "the pressure's scale {load:e} is below {:e}: the solve multiplies it by powers of h and would underflow; rescale the units",
            crate::MIN_DATA_SIZE
        ))
    } else {
        Ok(())
    }
}

/// The mesh of `[mesh]`.
/// An error when the mesh falls into separate pieces: a contact scene poses one body
/// on the foundation, whose rigid motions the supports, the contact and the load's
/// direction are checked to hold; a second piece escapes those checks (a
/// floating second block ended in "the matrix is not positive definite").
fn one_body(mesh: &TriangleMesh) -> std::result::Result<(), String> {
    let (piece, count) = mesh.cell_pieces();
    if count < 2 {
        return Ok(());
    }
    let sizes = (0..count)
        .map(|p| piece.iter().filter(|&&q| q == p).count().to_string())
        .collect::<Vec<_>>();
    Err(format!(
        "the mesh falls into {count} pieces joined by no edge (of {} cells; pieces that share only a vertex are a hinge, which holds nothing): a contact scene file poses one elastic body on a rigid foundation; mesh one connected body (in Gmsh, a coherent geometry), or pose each body in its own scene",
        sizes.join(", ")
    ))
}

fn mesh_of(
    mesh: &MeshToml,
    path: &Path,
    at: &dyn Fn(&str, String) -> Error,
) -> Result<TriangleMesh> {
    match (&mesh.generator, &mesh.file) {
        (Some(_), Some(_)) => Err(at(
            "mesh",
            "give either `generator` or `file`, not both".into(),
        )),
        (None, None) => Err(at(
            "mesh",
            "give a `generator` (rectangle) or a Gmsh `file`".into(),
        )),
        (None, Some(msh)) => {
            if mesh.x.is_some() || mesh.y.is_some() || mesh.cells.is_some() {
                return Err(at(
                    "mesh",
                    "a Gmsh `file` takes `refinements`, not `x`, `y` or `cells`".into(),
                ));
            }
            let full = path.parent().unwrap_or(Path::new(".")).join(msh);
            fem_runtime::mesh::gmsh::read_msh(&full).map_err(|e| at("mesh.file", e.to_string()))
        }
        (Some(generator), None) => {
            if generator != "rectangle" {
                return Err(at(
                    "mesh.generator",
                    format!(
                        "unknown generator `{generator}`; contact scene files have `rectangle`"
                    ),
                ));
            }
            let [x0, x1] = mesh.x.unwrap_or([0.0, 1.0]);
            let [y0, y1] = mesh.y.unwrap_or([0.0, 1.0]);
            for (key, [a, b]) in [("mesh.x", [x0, x1]), ("mesh.y", [y0, y1])] {
                if !(a.is_finite() && b.is_finite() && a < b && (b - a) <= 1e100) {
                    return Err(at(key, format!("[{a}, {b}] must be finite and increasing")));
                }
            }
            let [nx, ny] = mesh.cells.unwrap_or([8, 8]);
            if !(1..=4096).contains(&nx) || !(1..=4096).contains(&ny) || nx * ny > 1 << 20 {
                return Err(at(
                    "mesh.cells",
                    format!("[{nx}, {ny}]: each from 1 to 4096, at most 2^20 squares"),
                ));
            }
            TriangleMesh::rectangle(x0, x1, y0, y1, nx, ny, Diagonal::Right)
                .map_err(|e| at("mesh", e.to_string()))
        }
    }
}

/// A part's names: one name or a list of names; `required`: at least one.
fn names_of(
    value: Option<&toml::Value>,
    required: bool,
) -> std::result::Result<Vec<String>, String> {
    use toml::Value;
    let name = |v: &Value| {
        match v {
        Value::String(s) if s.trim().is_empty() => Err("an empty name".to_string()),
        Value::String(s) => Ok(s.clone()),
        Value::Integer(i) => Err(format!(
            "{i} is a number: boundary parts are chosen by name (Gmsh physical names of curve groups, or the generator's sides)"
        )),
        other => Err(format!(
            "{other} is not a name: write a name or a list of names such as [\"bottom\"]"
        )),
    }
    };
    let mut names = Vec::new();
    match value {
        None => {}
        Some(Value::Array(list)) => {
            for v in list {
                let n = name(v)?;
                if !names.contains(&n) {
                    names.push(n);
                }
            }
        }
        Some(v) => names.push(name(v)?),
    }
    if required && names.is_empty() {
        return Err("name at least one boundary part".into());
    }
    Ok(names)
}

/// The markers of the parts `names`, each of which must hold a boundary edge.
fn markers_on_boundary(
    mesh: &TriangleMesh,
    names: &[String],
) -> std::result::Result<Vec<u32>, String> {
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
                "the part `{name}` is not on the boundary: no boundary edge of the mesh belongs to it (a curve inside the body cannot touch the foundation or carry a pressure)"
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
fn oriented_edges(mesh: &TriangleMesh, markers: &[u32]) -> Vec<[[f64; 2]; 2]> {
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

/// The Gauss–Legendre points of the integrals here (exact to degree 7).
const GAUSS_POINTS: usize = 4;

fn point(ends: &[[f64; 2]; 2], s: f64) -> [f64; 2] {
    let [a, b] = ends;
    [a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])]
}

fn length(ends: &[[f64; 2]; 2]) -> f64 {
    (ends[1][0] - ends[0][0]).hypot(ends[1][1] - ends[0][1])
}

/// `data` is finite at the ends and the Gauss points of every edge of the part.
fn finite_on(
    mesh: &TriangleMesh,
    markers: &[u32],
    data: &Data,
) -> std::result::Result<[f64; 2], String> {
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

/// The largest size of E, the pressure and the gap a contact scene file may give (the
/// built-in scenes' load bound): beyond it the stiffness, the KKT norms or the
/// stabilization's `½/C_I,E` leave the range of f64 (E = 1e-200 gave "α = inf").
const MAX_DATA: f64 = 1e100;

/// The largest rounding of the displacement through the gap, `ε |min g|` (the rigid
/// translation before contact, or the initial penetration), relative to the body's
/// elastic displacement `load · max|q| · L / E`, that a contact scene file may ask for
/// where the translation along n_c is free: the translation carries the deformation's
/// digits. Measured on the 2 × 1 block (`q L/E` = 2.2e-3): a uniform gap of 1e10
/// (ε-ratio 1e-3) gave a contact force 6.5 % off the load, 1e6 (1e-7) 6.9e-6 and 1e3
/// (1e-10) 6.5e-9, about 60 times the ratio; below this bound the equilibrium stays
/// within [`crate::signorini::EQUILIBRIUM_WARNING`].
const MAX_GAP_ROUNDING: f64 = 1e-10;

/// What [`data_scales`] needs of a file's data, found when it is read.
#[derive(Clone, Copy, Debug)]
struct DataScales {
    /// max |q| over the quadrature points of Γ_N (before the load scale).
    pressure: f64,
    /// min g over Γ_C.
    smallest_gap: f64,
    /// The mesh's bounding-box diagonal L.
    diameter: f64,
    /// E.
    young: f64,
    /// Supports fix the displacement along n_c (the gap is then no translation).
    translation_held: bool,
}

/// Checks the data's scales at the pressure scale `load` (the file's or `--load`): the
/// pressure `load · max|q|` at most [`MAX_DATA`], and a gap whose rounding does not
/// swamp the elastic displacement ([`MAX_GAP_ROUNDING`]). The error names its key.
fn data_scales(scales: &DataScales, load: f64) -> std::result::Result<(), (&'static str, String)> {
    let pressure = load * scales.pressure;
    // the smallest pressure the range of E allows (pressure = "1e-320" stopped
    // Newton at a KKT residual of 5e-3)
    if pressure > 0.0 && pressure < 1.0 / MAX_DATA {
        return Err((
            "data.pressure",
            format!(
                "the pressure reaches at most {pressure:e} (scale {load:e} times max|q| = {:e}), below {:e}: the solve would underflow; rescale the units",
                scales.pressure,
                1.0 / MAX_DATA
            ),
        ));
    }
    if pressure > MAX_DATA {
        return Err((
            "data.pressure",
            format!(
                "the pressure reaches {pressure:e} (scale {load:e} times max|q| = {:e}), beyond {MAX_DATA:e}: the solve's norms would overflow; rescale the units",
                scales.pressure
            ),
        ));
    }
    let elastic = pressure * scales.diameter / scales.young;
    let translation = scales.smallest_gap.abs();
    if !scales.translation_held && f64::EPSILON * translation > MAX_GAP_ROUNDING * elastic {
        return Err((
            "data.gap",
            format!(
                "the body moves by the gap's smallest value {:e} before it touches (or starts that far inside the foundation), {:.1e} times its elastic displacement (about load · max|q| L/E = {elastic:.2e}): the displacement then holds the deformation only in its last digits; measure the gap from a foundation placed closer (only its variation along Γ_C matters)",
                scales.smallest_gap,
                translation / elastic
            ),
        ));
    }
    Ok(())
}

/// The resultant `∫_Γ_N q (−n) ds` pushes along `n_c`, towards the foundation: else
/// nothing holds the body (the foundation only pushes).
fn presses(
    mesh: &TriangleMesh,
    markers: &[u32],
    pressure: &Data,
    direction: [f64; 2],
) -> std::result::Result<(), String> {
    let (force, magnitude) = resultant_and_magnitude(mesh, markers, pressure);
    let along = force[0] * direction[0] + force[1] * direction[1];
    // a resultant within the rounding of its own quadrature is zero, whichever its sign
    // (x − 0.5 on the top face came out +7e-18 and was accepted, sin(2πx)
    // −4e-17 and was refused)
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
/// rounding is relative to (Gauss–Legendre, exact for q of degree 7).
fn resultant_and_magnitude(
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
        let q: f64 = gauss
            .points
            .iter()
            .zip(&gauss.weights)
            .map(|(&s, &w)| w * pressure.at(&point(&ends, s)))
            .sum::<f64>()
            * l;
        magnitude += gauss
            .points
            .iter()
            .zip(&gauss.weights)
            .map(|(&s, &w)| w * pressure.at(&point(&ends, s)).abs())
            .sum::<f64>()
            * l;
        force[0] -= q * n[0];
        force[1] -= q * n[1];
    }
    (force, magnitude)
}

/// A pressure resultant below this fraction of `∫|q| ds` is the rounding of a zero one.
const RESULTANT_ROUNDING: f64 = 1e-12;

/// The pair called `name`, for a contact scene file: p1-p0 or p2-p0.
///
/// # Errors
/// A message listing those two for any other name (it once offered p1-p1 and
/// p2-p1 for a file, which the file then refused).
pub fn pair_of_file(name: &str) -> std::result::Result<ContactPair, String> {
    let pair = ContactPair::parse(name).map_err(|_| {
        format!("unknown contact pair `{name}`: contact scene files take p1-p0 and p2-p0")
    })?;
    if pair.multiplier() != crate::models::signorini::Multiplier::P0 {
        return Err(p0_pairs_only(pair));
    }
    Ok(pair)
}

/// Why `pair` (a P1-multiplier pair) cannot solve a contact scene file.
fn p0_pairs_only(pair: ContactPair) -> String {
    format!(
        "`{}` has a P1 multiplier; contact scene files take the P0-multiplier pairs p1-p0 and p2-p0 (their pressure errors are per edge; the P1-multiplier pairs solve the built-in contact scenes: `fem-forms list`)",
        pair.name()
    )
}

/// What the command line may change in a contact scene file.
#[derive(Clone, Debug, Default)]
pub struct Overrides {
    /// `--pair`.
    pub pair: Option<ContactPair>,
    /// `--mesh-size`: uniform refinements of the file's mesh.
    pub refinements: Option<usize>,
    /// `--load`: the pressure's scale.
    pub load: Option<f64>,
    /// `--alpha`.
    pub alpha: Option<f64>,
}

/// A solved contact scene file: the report, the pressure per edge, and the solution.
#[derive(Clone, Debug)]
pub struct ContactFileSolution {
    /// The `--json` report (the fields of the built-in scenes'; `pressure_l2_error` and
    /// `best_p0_l2_error` against `exact.pressure` where given; `mesh_size` is the
    /// number of refinements).
    pub report: ContactReport,
    /// `(x0, x1, λ_E)` per contact edge, sorted by x0.
    pub profile: PressureProfile,
    /// The solution on the refined mesh.
    pub solution: SignoriniSolution,
}

/// Solves a contact scene file with the command line's overrides.
///
/// # Errors
/// [`Error::Input`] naming the option for an out-of-range `--mesh-size`, `--load` or
/// `--alpha`, or the key `data.pressure` for a load that does not press the body onto
/// Γ_C; the solver's errors.
pub fn solve(file: &ContactSceneFile, overrides: &Overrides) -> Result<ContactFileSolution> {
    let pair = overrides.pair.unwrap_or(file.pair);
    if pair.multiplier() != crate::models::signorini::Multiplier::P0 {
        return Err(Error::Input(format!("--pair: {}", p0_pairs_only(pair))));
    }
    let refinements = overrides.refinements.unwrap_or(file.refinements);
    if refinements > MAX_REFINEMENTS {
        return Err(Error::Input(format!(
            "--mesh-size {refinements}: the refinements of a contact scene file's mesh are at most {MAX_REFINEMENTS}"
        )));
    }
    check_memory(file.mesh.cell_count(), refinements, pair).map_err(|m| {
        let what = match (overrides.refinements, overrides.pair) {
            (Some(r), _) => format!("--mesh-size {r}"),
            (None, Some(p)) => format!("--pair {}", p.name()),
            (None, None) => format!("{}: mesh.refinements", file.name),
        };
        Error::Input(format!("{what}: {m}"))
    })?;
    let load = overrides.load.unwrap_or(file.load);
    check_load(load).map_err(|m| Error::Input(format!("--load: {m}")))?;
    if overrides.load.is_some() {
        data_scales(&file.scales, load).map_err(|(key, m)| {
            Error::Input(format!("--load {load:e} with {}'s `{key}`: {m}", file.name))
        })?;
    }
    let alpha = overrides.alpha.or(file.alpha);
    let mut mesh = file.mesh.clone();
    for _ in 0..refinements {
        mesh = mesh.refine_uniformly();
    }
    // as for membranes: near-flat cells refused, thin ones named (a block with
    // 0.45° cells far from the contact set got α = ½/max C_I,E 1.5e-6 from them and a
    // pressure error 3.6× the best fit's, without a word)
    let quality = mesh.quality();
    quality
        .check(&mesh)
        .map_err(|e| Error::Input(format!("{}: key `mesh`: {e}", file.name)))?;
    let shape = file.pressure.clone();
    let pressure = move |x: &[f64]| load * shape.at(x);
    let input = SignoriniInput {
        young: file.young,
        poisson: file.poisson,
        plane: file.plane,
        element: pair.displacement(),
        contact: &file.contact,
        load: &file.load_part,
        pressure: &pressure,
        gap: file.gap.as_data_fn(),
        contact_direction: file.contact_direction,
        fixed_x: &file.fixed_x,
        fixed_y: &file.fixed_y,
        rollers: &file.rollers,
        alpha,
        contact_centre: file.contact_centre,
    };
    let solution = solve_signorini(&mesh, &input).map_err(|e| match e {
        Error::Input(m)
            if m.contains("rigid motion is not prevented") || m.contains("tips the body") =>
        {
            Error::Input(format!("{}: key `data.pressure`: {m}", file.name))
        }
        other => other,
    })?;
    let n = file.contact_direction;
    let total = -(solution.total_contact_force[0] * n[0] + solution.total_contact_force[1] * n[1]);
    let applied = solution.applied_load[0] * n[0] + solution.applied_load[1] * n[1];
    // supports along n_c carry part of the load, and the translation the load is
    // measured on has their DOFs fixed: not a resultant (NaN, null in JSON)
    let held = file.scales.translation_held;
    let discretized = if held {
        f64::NAN
    } else {
        solution.discretized_load
    };
    // along the contact plane: x under a horizontal one, y beside a vertical one
    let along = crate::models::signorini::contact_tangent(n);
    let coordinate = |x: [f64; 2]| along[0] * x[0] + along[1] * x[1];
    let mut profile: PressureProfile = solution
        .contact_edges
        .iter()
        .zip(&solution.pressure)
        .map(|(e, &p)| {
            let (a, b) = (coordinate(e.ends[0]), coordinate(e.ends[1]));
            (a.min(b), a.max(b), p)
        })
        .collect();
    profile.sort_by(|a, b| a.0.total_cmp(&b.0));
    // the exact pressure belongs to the file's own load only
    let own_load = (load - file.load).abs() <= 1e-12 * file.load;
    let errors = file
        .exact_pressure
        .as_ref()
        .filter(|_| own_load)
        .map(|exact| pressure_errors(&solution, exact));
    let report = ContactReport {
        scene: file.name.clone(),
        pair: pair.name(),
        mesh_size: refinements,
        load,
        alpha: solution.alpha,
        inverse_constant: solution
            .inverse_constants
            .iter()
            .fold(0.0f64, |m, &c| m.max(c)),
        dofs: solution.dofs,
        contact_edges: solution.contact_edges.len(),
        multiplier_dofs: solution.pressure.len(),
        iterations: solution.iterations,
        seconds: solution.seconds,
        total_contact_force: total,
        applied_load: applied,
        discretized_load: discretized,
        // supports acting along n_c carry part of the load: the contact force alone
        // then need not equal it (not measured: null)
        // relative to the pressure's size, ∫|q| ds, not to its resultant alone: a
        // resultant of 1e-9 ∫|q| leaves the contact force rounding of ∫|q|, which is
        // no failure of the solve (x − 0.5 + 1e-9 warned "1.8e-5")
        equilibrium_residual: if held {
            f64::NAN
        } else {
            let magnitude =
                load * resultant_and_magnitude(&mesh, &file.load_part, &file.pressure).1;
            (total - discretized).abs() / discretized.abs().max(magnitude)
        },
        contact_half_width: solution.contact_half_width,
        max_contact_pressure: solution.max_contact_pressure,
        exact_half_width: None,
        exact_max_pressure: None,
        pressure_l2_error: errors.map(|e| e[0]),
        best_p0_l2_error: errors.map(|e| e[1]),
        best_fit_l2_error: errors.map(|e| e[1]),
        oscillation: file
            .exact_pressure
            .as_ref()
            .filter(|_| own_load)
            .and_then(|exact| {
                crate::models::signorini::checkerboard_against(&solution, n, exact.as_data_fn())
            }),
        patch_pressure_error: None,
        complementarity_residual: solution.complementarity_residual,
        kkt_residual: solution.kkt_residual,
        accuracy: file.accuracy,
        warnings: Vec::new(),
    };
    let mut warnings = crate::signorini::warnings(&report);
    let (mu, lambda) = crate::models::signorini::lame(file.young, file.poisson, file.plane)?;
    warnings.extend(crate::models::families::contact::volumetric_locking(
        pair.name(),
        mu,
        lambda,
    ));
    warnings.extend(quality.warnings(&mesh, alpha.is_none()));
    for (key, names) in &file.part_names {
        warnings.extend(crate::interior_curve_warnings(key, &mesh, names));
    }
    if file.exact_pressure.is_some() && !own_load {
        warnings.push(format!(
            "exact.pressure is the pressure at the file's data.load = {}; at --load {load} it is not known (contact is not linear in the load: the contact set changes with it), so no pressure error is reported",
            file.load
        ));
    }
    let report = ContactReport { warnings, ..report };
    Ok(ContactFileSolution {
        report,
        profile,
        solution,
    })
}

/// `‖λ_h − p‖/‖p‖` on Γ_C and the same of p's best P0 fit (the edge means), p the exact
/// pressure (8-point Gauss–Legendre per edge); an exact pressure of zero norm gives the
/// absolute errors.
fn pressure_errors(solution: &SignoriniSolution, exact: &Data) -> [f64; 2] {
    let gauss = fem_runtime::gauss_legendre(8);
    let (mut error, mut best, mut norm) = (0.0, 0.0, 0.0);
    for (e, &lambda) in solution.contact_edges.iter().zip(&solution.pressure) {
        let ends = e.ends;
        let l = e.length();
        let values: Vec<f64> = gauss
            .points
            .iter()
            .map(|&s| exact.at(&point(&ends, s)))
            .collect();
        let mean: f64 = values.iter().zip(&gauss.weights).map(|(p, w)| w * p).sum();
        for (&p, &w) in values.iter().zip(&gauss.weights) {
            error += w * l * (lambda - p) * (lambda - p);
            best += w * l * (mean - p) * (mean - p);
            norm += w * l * p * p;
        }
    }
    let scale = if norm > 0.0 { norm } else { 1.0 };
    [(error / scale).sqrt(), (best / scale).sqrt()]
}
