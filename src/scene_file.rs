//! Scene files: a user's own problem as data, `fem-forms solve --scene my.toml`.
//!
//! A scene file names the model and element pair, the mesh (a built-in generator and its
//! size, or a Gmsh file whose path is relative to the scene file), the boundary parts,
//! the parameters and the data f, ψ, g as expressions in `x` and `y` (and, where known,
//! the exact solution). Each expression is parsed once (by the `exmex` crate) and then
//! evaluated at every point the solver asks for. An example, the sign test on
//! `(−2, 2)²`:
//!
//! ```toml
//! name = "flat"
//! model = "membrane"
//! pair = "p2-p0"                  # optional; p2-p0 by default
//!
//! [mesh]
//! generator = "square"            # "square" (half_width a: (−a, a)²) or "l-shape"
//! half_width = 2.0
//! size = 16                       # N of the N×N×2 mesh
//! # file = "disk.msh"             # or a Gmsh MSH 4.1 file, relative to this file,
//! # refinements = 1               # refined uniformly this many times
//!
//! [boundary]
//! dirichlet = "all"               # u = g on the whole boundary (the default), or
//! # dirichlet = ["left", "right"] # u = g on these boundary parts, ∂u/∂n = 0 elsewhere
//!
//! [parameters]
//! # alpha = 0.005                 # α; ½/C_I by default
//!
//! [data]
//! load = 3.0                      # q: f = q · (the expression f); optional, 1 by default
//! f = "-1"
//! psi = "0"
//! g = "0"
//!
//! [exact]                         # optional: the exact solution where known
//! u = "0"                         # its gradient is derived from the expression
//! lambda = "3"
//! contact_force = 48.0            # ∫λ and the contact area on this domain
//! contact_area = 16.0
//! ```
//!
//! Boundary parts are named by the mesh: a Gmsh file's physical names of curve groups
//! (`Physical Curve("outer") = {…};` in a `.geo` script), the square's sides `bottom`,
//! `right`, `top`, `left`, the L-shape's `outer` and `reentrant` (its two re-entrant
//! edges). A single name may be written without brackets. On the boundary outside the
//! named parts the condition is the natural one, `∂u/∂n = 0`. A name the mesh does not
//! have, a surface's name, a number (a physical tag: parts are chosen by name) and an
//! empty list (no part where u = g: the membrane would be determined only up to a
//! constant) are errors naming the field `boundary.dirichlet`.
//!
//! Expressions use `+ − * / ^`, parentheses, numbers (`2.5`, `1e-3`), `PI`, `E`, and the functions
//! `sqrt`, `exp`, `ln`, `sin`, `cos`, `tan`, `abs`, `min`, `max`, … of the `exmex`
//! crate's `FloatOpsFactory`. A syntax error or a variable other than `x`, `y` is an
//! error naming the file, the field and the expression. A unary minus before a power
//! must be bracketed (`-(x^2)` or `0-x^2`): `exmex` reads `-x^2` as `(−x)²`, so it is
//! refused rather than read against the mathematics; so is a chained power `a^b^c`,
//! which it reads as `(a^b)^c`.

use crate::membranes::MembranePair;
use crate::models::membrane_scenes::{DirichletParts, Domain, Exact, ExactMembrane, MembraneScene};
use crate::models::scene_file::{expression, gradient, scene_name};
use fem_runtime::{Error, Result, TriangleMesh};
use serde::Deserialize;
use std::borrow::Cow;
use std::path::{Path, PathBuf};

/// A scene file as written (see the module documentation for the fields).
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct SceneToml {
    name: Option<String>,
    description: Option<String>,
    model: String,
    pair: Option<String>,
    mesh: MeshToml,
    #[serde(default)]
    boundary: BoundaryToml,
    #[serde(default)]
    parameters: ParametersToml,
    data: DataToml,
    exact: Option<ExactToml>,
    /// The asked accuracy (L² error of u; needs `[exact]`).
    accuracy: Option<f64>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct MeshToml {
    generator: Option<String>,
    half_width: Option<f64>,
    size: Option<usize>,
    file: Option<PathBuf>,
    refinements: Option<usize>,
}

#[derive(Deserialize, Debug, Default)]
#[serde(deny_unknown_fields)]
struct BoundaryToml {
    dirichlet: Option<toml::Value>,
}

#[derive(Deserialize, Debug, Default)]
#[serde(deny_unknown_fields)]
struct ParametersToml {
    alpha: Option<f64>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct DataToml {
    load: Option<f64>,
    f: String,
    psi: String,
    g: String,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct ExactToml {
    u: String,
    lambda: Option<String>,
    contact_force: Option<f64>,
    contact_area: Option<f64>,
}

/// A scene read from a file, with the solve settings it asks for (the command line's
/// options override them).
#[derive(Clone, Debug)]
pub struct SceneFile {
    /// The scene (family: membrane).
    pub scene: MembraneScene,
    /// The pair it names (default p2-p0).
    pub pair: MembranePair,
    /// N of the structured mesh, or the refinements of the Gmsh file.
    pub mesh_size: usize,
    /// α where the file fixes it.
    pub alpha: Option<f64>,
    /// The L² error of u the file asks for (`accuracy`), where it states one: the solve
    /// compares `error_l2` with it and warns when it is missed.
    pub accuracy: Option<f64>,
}

/// The smallest `mesh.half_width` of a square: a tester's problem solved at 1e-39 and
/// failed at 1e-40, where `α h⁴` of the cells of a fine mesh (h ~ 1e-43) falls to
/// 1e-172 and below, near the end of double precision's normal range.
const MIN_HALF_WIDTH: f64 = 1e-30;

/// The `boundary.dirichlet` field: absent or `"all"`: the whole boundary; a name or a
/// list of names: those boundary parts. The error is the message for the field.
fn dirichlet_parts(value: Option<&toml::Value>) -> std::result::Result<DirichletParts, String> {
    use toml::Value;
    let by_name = "boundary parts are chosen by name (Gmsh physical names of curve groups, or a generator's side names), not by number; a Gmsh group without a name cannot be chosen: name it (Physical Curve(\"outer\") = {…};)";
    let name = |v: &Value| {
        match v {
        Value::String(s) if s.trim().is_empty() => Err("an empty name".to_string()),
        Value::String(s) => Ok(s.clone()),
        Value::Integer(i) => Err(format!("{i} is a number: {by_name}")),
        other => Err(format!(
            "{other} is not a name: write \"all\", a name, or a list of names such as [\"left\", \"right\"]"
        )),
    }
    };
    match value {
        None => Ok(DirichletParts::All),
        Some(Value::String(s)) if s == "all" => Ok(DirichletParts::All),
        Some(Value::Array(list)) if list.is_empty() => Err(
            "an empty list: u = g would hold nowhere, and with ∂u/∂n = 0 on the whole boundary the membrane is determined only up to a constant where contact does not hold it; name at least one boundary part (or \"all\")".into(),
        ),
        Some(Value::Array(list)) => {
            let mut names = Vec::with_capacity(list.len());
            for v in list {
                let n = name(v)?;
                if !names.contains(&n) {
                    names.push(n);
                }
            }
            Ok(DirichletParts::Named(names))
        }
        Some(v) => Ok(DirichletParts::Named(vec![name(v)?])),
    }
}

/// The generator's name in the scene file.
fn mesh_generator_name(domain: &Domain) -> &'static str {
    match domain {
        Domain::Square(_) => "square",
        Domain::LShape => "l-shape",
        Domain::File(_) => "file",
    }
}

/// Reads and checks a scene file.
///
/// # Errors
/// An unreadable file, TOML errors (with their line and column), unknown fields, a
/// model other than `membrane`, an unknown pair or mesh generator, a mesh given both
/// ways or neither, boundary parts that are not names (numbers, an empty list) or not
/// the generator's, and expressions that do not parse or use variables other than x,
/// y. The names of a Gmsh file's parts are checked when it is read, by
/// [`crate::membranes::solve`].
pub fn read(path: &Path) -> Result<SceneFile> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        Error::Input(format!(
            "cannot read the scene file {}: {e}",
            path.display()
        ))
    })?;
    parse(&text, path)
}

/// Parses the text of a scene file; `path` names it in errors and anchors its relative
/// mesh path.
///
/// # Errors
/// As [`read`].
pub fn parse(text: &str, path: &Path) -> Result<SceneFile> {
    let at = |field: &str, message: String| {
        Error::Input(format!("{}: field `{field}`: {message}", path.display()))
    };
    let unknown_model = |model: &str| {
        at(
            "model",
            format!(
                "`{model}` is not a model scene files can pose; they support `membrane` and `contact` (beams, Kirchhoff and Mindlin plates: the built-in scenes, see `fem-forms list`)"
            ),
        )
    };
    // The model first: a misspelt one must be named as such, not reported as the
    // membrane format's complaint about the other model's keys.
    #[derive(Deserialize)]
    struct ModelOnly {
        model: Option<String>,
    }
    if let Ok(ModelOnly { model: Some(model) }) = toml::from_str::<ModelOnly>(text) {
        if model != "membrane" {
            return Err(unknown_model(&model));
        }
    }
    let file: SceneToml = toml::from_str(text)
        .map_err(|e| Error::Input(format!("scene file {}: {e}", path.display())))?;
    if file.model != "membrane" {
        return Err(unknown_model(&file.model));
    }
    let pair = match &file.pair {
        Some(p) => MembranePair::parse(p).map_err(|e| at("pair", e.to_string()))?,
        None => MembranePair::P2P0,
    };
    let mesh = &file.mesh;
    let (domain, mesh_size) = match (&mesh.generator, &mesh.file) {
        (Some(_), Some(_)) => {
            return Err(at(
                "mesh",
                "give either `generator` or `file`, not both".into(),
            ))
        }
        (None, None) => {
            return Err(at(
                "mesh",
                "give a `generator` (square, l-shape) or a Gmsh `file`".into(),
            ))
        }
        (None, Some(msh)) => {
            if mesh.size.is_some() || mesh.half_width.is_some() {
                return Err(at(
                    "mesh",
                    "a Gmsh `file` takes `refinements`, not `size` or `half_width`".into(),
                ));
            }
            let base = path.parent().unwrap_or(Path::new("."));
            let refinements = mesh.refinements.unwrap_or(0);
            // the solver's own limit, named here by the file's field
            if refinements > 8 {
                return Err(at(
                    "mesh.refinements",
                    format!("{refinements} uniform refinements (4^{refinements} times the triangles): at most 8"),
                ));
            }
            (Domain::File(base.join(msh)), refinements)
        }
        (Some(generator), None) => {
            if mesh.refinements.is_some() {
                return Err(at(
                    "mesh.refinements",
                    "applies to a Gmsh `file`; a generator takes `size`".into(),
                ));
            }
            let size = mesh.size.unwrap_or(64);
            // the structured meshes' range, named here by the file's field
            if !(2..=4096).contains(&size) {
                return Err(at(
                    "mesh.size",
                    format!("{size} is out of range (2 to 4096)"),
                ));
            }
            match generator.as_str() {
                "square" => {
                    let a = mesh.half_width.unwrap_or(1.0);
                    // below this the stabilization's αh⁴ of the finest cells underflows
                    // (a tester's half_width 1e-40 to 1e-100 failed with "C_0 = -0");
                    // above, the mesh's coordinate bound (the kernels' powers of lengths
                    // overflow)
                    let largest = fem_runtime::mesh::triangle::MAX_COORDINATE;
                    if !(MIN_HALF_WIDTH..=largest).contains(&a) {
                        return Err(at(
                            "mesh.half_width",
                            format!("{} must be within {MIN_HALF_WIDTH:e} to {largest:e}: below, the stabilization's α h⁴ underflows; rescale the units", crate::number(a)),
                        ));
                    }
                    (Domain::Square(a), size)
                }
                "l-shape" => {
                    if size % 2 != 0 {
                        return Err(at(
                            "mesh.size",
                            format!("the L-shape needs an even size, got {size}"),
                        ));
                    }
                    if mesh.half_width.is_some() {
                        return Err(at(
                            "mesh.half_width",
                            "the L-shape is (−1,1)² ∖ [0,1]×[−1,0]; it takes no half_width".into(),
                        ));
                    }
                    (Domain::LShape, size)
                }
                other => {
                    return Err(at(
                        "mesh.generator",
                        format!("unknown generator `{other}`; the generators are square, l-shape"),
                    ))
                }
            }
        }
    };
    let dirichlet = dirichlet_parts(file.boundary.dirichlet.as_ref())
        .map_err(|m| at("boundary.dirichlet", m))?;
    if let DirichletParts::Named(names) = &dirichlet {
        // a generator's names are known now: check them before any solve
        let sample = match &domain {
            Domain::Square(a) => Some(TriangleMesh::rectangle(
                -a,
                *a,
                -a,
                *a,
                2,
                2,
                fem_runtime::Diagonal::Right,
            )?),
            Domain::LShape => Some(TriangleMesh::l_shape(1)?),
            Domain::File(_) => None,
        };
        if let Some(mesh) = sample {
            mesh.boundary_part_markers(names).map_err(|e| match e {
                Error::Input(message) => {
                    let keyword = if names.iter().any(|n| n == "all") {
                        "; \"all\" (the whole boundary) is a keyword on its own, `dirichlet = \"all\"`, not a name in a list"
                    } else {
                        ""
                    };
                    at(
                        "boundary.dirichlet",
                        format!(
                            "{message} (generator `{}`){keyword}",
                            mesh_generator_name(&domain)
                        ),
                    )
                }
                other => other,
            })?;
        }
    }
    let data = &file.data;
    if let Some(q) = data.load {
        if !q.is_finite() {
            return Err(at(
                "data.load",
                format!("{} must be finite", crate::number(q)),
            ));
        }
        if q != 0.0 && q.abs() < crate::MIN_DATA_SIZE {
            return Err(at(
                "data.load",
                format!(
                    "{q:e} is below {:e} in size: the solve multiplies it by powers of h and would underflow; give 0 or rescale the units",
                    crate::MIN_DATA_SIZE
                ),
            ));
        }
    }
    if let Some(e) = &file.exact {
        for (key, value) in [
            ("exact.contact_force", e.contact_force),
            ("exact.contact_area", e.contact_area),
        ] {
            if let Some(v) = value {
                // −0.0 passes (it is ≥ 0) and is read as 0, not echoed as −0
                if !(v.is_finite() && v >= 0.0) {
                    return Err(at(
                        key,
                        format!("{} must be a finite number ≥ 0 (∫λ and the contact area cannot be negative)", crate::number(v)),
                    ));
                }
            }
        }
    }
    if file.accuracy.is_some() && file.exact.is_none() {
        return Err(at(
            "accuracy",
            "an accuracy needs an `[exact] u` to measure the L² error against".into(),
        ));
    }
    let exact = match &file.exact {
        None => Exact::Unknown,
        Some(e) => Exact::AtDefaultLoad(ExactMembrane {
            u: expression(&e.u, "exact.u", path)?,
            gradient: gradient(&e.u, "exact.u", path)?,
            multiplier: e
                .lambda
                .as_deref()
                .map(|l| expression(l, "exact.lambda", path))
                .transpose()?,
            total_contact_force: e.contact_force.map(|v| v + 0.0),
            contact_area: e.contact_area.map(|v| v + 0.0),
        }),
    };
    let target_l2 = file.accuracy.unwrap_or(1e-3);
    if !(target_l2 > 0.0 && target_l2.is_finite()) {
        return Err(at(
            "accuracy",
            format!("{target_l2} must be positive and finite"),
        ));
    }
    let name = scene_name(file.name.as_deref(), path, "scene").map_err(|m| at("name", m))?;
    let scene = MembraneScene {
        name: Cow::Owned(name),
        description: Cow::Owned(
            file.description
                .clone()
                .unwrap_or_else(|| format!("scene file {}", path.display())),
        ),
        domain,
        load: expression(&data.f, "data.f", path)?,
        load_scale: Some(data.load.unwrap_or(1.0)),
        obstacle: expression(&data.psi, "data.psi", path)?,
        boundary: expression(&data.g, "data.g", path)?,
        dirichlet,
        target_l2,
        exact,
    };
    Ok(SceneFile {
        scene,
        pair,
        mesh_size,
        alpha: file.parameters.alpha,
        accuracy: file.accuracy,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn here() -> &'static Path {
        Path::new("test.toml")
    }

    #[test]
    fn expressions_evaluate_at_points_and_differentiate() {
        let f = expression("x^2 + 3*y - sqrt(4)", "data.f", here()).unwrap();
        assert_eq!(f.at(&[2.0, 1.0]), 4.0 + 3.0 - 2.0);
        // only y: the variable order must still follow the coordinates
        let g = expression("2*y", "data.g", here()).unwrap();
        assert_eq!(g.at(&[5.0, 1.5]), 3.0);
        let grad = gradient("x^2*y + y", "exact.u", here()).unwrap();
        let [dx, dy] = grad.at(&[3.0, 2.0]);
        assert!((dx - 12.0).abs() < 1e-12 && (dy - 10.0).abs() < 1e-12);
        let grad = gradient("x^3", "exact.u", here()).unwrap();
        assert_eq!(grad.at(&[2.0, 7.0]), [12.0, 0.0]);
        // a long sum overflowed the main thread's stack in exmex's differentiation
        let long = format!("x{}", "+x*y".repeat(150));
        let grad = gradient(&long, "exact.u", here()).unwrap();
        let [dx, dy] = grad.at(&[2.0, 3.0]);
        assert!(
            (dx - 451.0).abs() < 1e-9 && (dy - 300.0).abs() < 1e-9,
            "{dx} {dy}"
        );
        let too_long = format!("x{}", "+x*y".repeat(300));
        let message = gradient(&too_long, "exact.u", here())
            .unwrap_err()
            .to_string();
        assert!(
            message.contains("exact.u") && message.contains("at most 1000"),
            "{message}"
        );
    }

    #[test]
    fn bad_expressions_name_the_field_and_the_place() {
        let e = expression("x + * 2", "data.f", here())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("test.toml") && e.contains("data.f") && e.contains("x + * 2"),
            "{e}"
        );
        let e = expression("x + z", "data.psi", here())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("data.psi") && e.contains("unknown variable `z`"),
            "{e}"
        );
    }

    const FLAT: &str = r#"
        model = "membrane"
        [mesh]
        generator = "square"
        half_width = 2.0
        size = 8
        [data]
        load = 3.0
        f = "-1"
        psi = "0"
        g = "0"
    "#;

    #[test]
    fn a_scene_file_is_read_and_checked() {
        let s = parse(FLAT, here()).unwrap();
        assert_eq!(s.scene.domain, Domain::Square(2.0));
        assert_eq!(s.mesh_size, 8);
        assert_eq!(s.scene.load_scale, Some(3.0));
        assert_eq!(s.scene.load.at(&[0.3, 0.1]), -1.0);
        for (broken, field) in [
            (FLAT.replace("\"membrane\"", "\"plate\""), "model"),
            (FLAT.replace("\"square\"", "\"circle\""), "mesh.generator"),
            (FLAT.replace("psi = \"0\"", "psi = \"0 +\""), "data.psi"),
            (FLAT.replace("g = \"0\"", "g = \"r\""), "data.g"),
            (
                FLAT.replace("[data]", "[boundary]\ndirichlet = \"outer\"\n[data]"),
                "boundary.dirichlet",
            ),
            (
                FLAT.replace("[data]", "[boundary]\ndirichlet = []\n[data]"),
                "boundary.dirichlet",
            ),
            (
                FLAT.replace("[data]", "[boundary]\ndirichlet = [4]\n[data]"),
                "boundary.dirichlet",
            ),
            (format!("name = \"../escape/x\"\n{FLAT}"), "name"),
            (FLAT.replace("size = 8", "size = 0"), "mesh.size"),
            (format!("name = \"\"\n{FLAT}"), "name"),
        ] {
            let e = parse(&broken, here()).unwrap_err().to_string();
            assert!(e.contains(field), "{field}: {e}");
        }
        let with =
            |d: &str| FLAT.replace("[data]", &format!("[boundary]\ndirichlet = {d}\n[data]"));
        for (d, expected) in [
            ("\"all\"", DirichletParts::All),
            ("\"left\"", DirichletParts::Named(vec!["left".into()])),
            (
                "[\"right\", \"left\", \"right\"]",
                DirichletParts::Named(vec!["right".into(), "left".into()]),
            ),
        ] {
            assert_eq!(
                parse(&with(d), here()).unwrap().scene.dirichlet,
                expected,
                "{d}"
            );
        }
        for (d, words) in [
            (
                "\"outer\"",
                &["`outer`", "`left`", "generator `square`"][..],
            ),
            ("[]", &["empty list", "constant"]),
            ("[4]", &["4 is a number", "by name"]),
            ("[\"left\", 2.5]", &["2.5 is not a name"]),
            ("\" \"", &["empty name"]),
        ] {
            let e = parse(&with(d), here()).unwrap_err().to_string();
            assert!(
                e.contains("boundary.dirichlet") && words.iter().all(|w| e.contains(w)),
                "{d}: {e}"
            );
        }
        let e = parse(&FLAT.replace("size = 8", "size = 8\nsizes = 3"), here())
            .unwrap_err()
            .to_string();
        assert!(e.contains("sizes"), "{e}");
    }
}
