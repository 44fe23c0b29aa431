//! The one scene-file reader: a TOML file of any family read into a [`crate::scene::Scene`].
//!
//! Expressions use `+ − * / ^`, parentheses, numbers (`2.5`, `1e-3`), `PI`, `E`, and the
//! functions `sqrt`, `exp`, `ln`, `sin`, `cos`, `tan`, `abs`, `min`, `max`, … of the
//! `exmex` crate's `FloatOpsFactory`, in the variables `x` and `y`. A unary minus before
//! a power must be bracketed (`-(x^2)` or `0-x^2`): `exmex` reads `-x^2` as `(−x)²`, so
//! it is refused rather than read against the mathematics; so is a chained power
//! `a^b^c`, which it reads as `(a^b)^c`.

use crate::data::Data;
use exmex::prelude::*;
use fem_runtime::{Error, Result};
use std::path::Path;

/// The variables an expression may use, in the order of the point's coordinates.
const VARIABLES: [&str; 2] = ["x", "y"];

/// Parses `text` (the field `field` of `file`) into a function of the point: checks
/// that it uses no variable but `x` and `y`.
///
/// # Errors
/// [`Error::Input`] naming the file, the field and the expression: a syntax error, a
/// variable other than x, y, and the spellings `exmex` reads against the mathematics
/// (`-x^2`, `a^b^c`).
pub fn expression(text: &str, field: &str, file: &Path) -> Result<Data> {
    let parsed = parse_checked(text, field, file)?;
    Ok(function_of_point(parsed))
}

pub(crate) fn parse_checked(text: &str, field: &str, file: &Path) -> Result<FlatEx<f64>> {
    // TOML's multi-line strings let long expressions span lines; exmex wants one line
    let one_line = text.split_whitespace().collect::<Vec<_>>().join(" ");
    let one_line = normalize(&one_line).map_err(|why| {
        Error::Input(format!(
            "{}: field `{field}`: the expression `{text}`: {why}",
            file.display()
        ))
    })?;
    let parsed = exmex::parse::<f64>(&one_line).map_err(|e| {
        Error::Input(format!(
            "{}: field `{field}`: cannot parse the expression `{text}`: {e}",
            file.display()
        ))
    })?;
    if let Some(unknown) = parsed
        .var_names()
        .iter()
        .find(|v| !VARIABLES.contains(&v.as_str()))
    {
        return Err(Error::Input(format!(
            "{}: field `{field}`: unknown variable `{unknown}` in `{text}` (expressions are functions of x and y)",
            file.display()
        )));
    }
    Ok(parsed)
}

/// What `exmex` reads differently from the mathematics, made right or refused before it
/// parses: numbers in scientific notation (`1e-3`, which `exmex` cannot parse) become
/// their decimal expansion, exactly the same `f64`; a unary minus whose operand is
/// raised to a power (`-x^2`, which `exmex` reads as `(−x)²` where mathematics means
/// `−(x²)`) is refused with the two unambiguous spellings.
fn normalize(text: &str) -> std::result::Result<String, String> {
    let chars: Vec<char> = text.chars().collect();
    let is_name = |c: char| c.is_ascii_alphanumeric() || c == '_';
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        let starts_number = (c.is_ascii_digit() || c == '.')
            && (i == 0 || !(is_name(chars[i - 1]) || chars[i - 1] == '.'));
        if starts_number {
            let start = i;
            while i < chars.len() && (chars[i].is_ascii_digit() || chars[i] == '.') {
                i += 1;
            }
            // an exponent: e or E, an optional sign, at least one digit
            let mut j = i;
            if j < chars.len() && (chars[j] == 'e' || chars[j] == 'E') {
                j += 1;
                if j < chars.len() && (chars[j] == '+' || chars[j] == '-') {
                    j += 1;
                }
                let digits = j;
                while j < chars.len() && chars[j].is_ascii_digit() {
                    j += 1;
                }
                let followed_by_name = j < chars.len() && is_name(chars[j]);
                if j > digits && !followed_by_name {
                    let literal: String = chars[start..j].iter().collect();
                    let value: f64 = literal
                        .parse()
                        .map_err(|_| format!("`{literal}` is not a number"))?;
                    if !value.is_finite() {
                        return Err(format!("the number `{literal}` is not finite"));
                    }
                    // Display never uses an exponent and round-trips the value exactly
                    out.push_str(&format!("({value})"));
                    i = j;
                    continue;
                }
            }
            out.extend(&chars[start..i]);
            continue;
        }
        if c == '-' {
            let previous = chars[..i].iter().rev().find(|c| !c.is_whitespace());
            let unary = previous.is_none_or(|p| "(,+-*/^".contains(*p));
            if unary {
                let end = operand_end(&chars, i + 1);
                let next = chars[end..].iter().find(|c| !c.is_whitespace());
                if end > i + 1 && next == Some(&'^') {
                    let operand: String = chars[i + 1..end].iter().collect::<String>();
                    let operand = operand.trim();
                    return Err(format!(
                        "`-{operand}^…` is ambiguous here: the expression language reads it as (−{operand})^…, not −({operand}^…); write `-({operand}^…)` or `0-{operand}^…` for the negative power, or `(-{operand})^…` for the power of the negative"
                    ));
                }
            }
        }
        if c == '^' {
            // the exponent's own operand, after an optional sign
            let mut k = i + 1;
            while k < chars.len() && chars[k].is_whitespace() {
                k += 1;
            }
            if matches!(chars.get(k), Some('+' | '-')) {
                k += 1;
            }
            let end = operand_end(&chars, k);
            let next = chars[end..].iter().find(|c| !c.is_whitespace());
            if end > k && next == Some(&'^') {
                let exponent: String = chars[k..end].iter().collect();
                let exponent = exponent.trim();
                return Err(format!(
                    "`…^{exponent}^…` is ambiguous here: the expression language reads a chained power from the left, (a^{exponent})^c, where mathematics means a^({exponent}^c); write the brackets you mean"
                ));
            }
        }
        out.push(c);
        i += 1;
    }
    Ok(out)
}

/// The end of the operand that starts at `from` (after spaces): a number, a name with an
/// optional call `f(…)`, or a bracketed group; `from` itself where there is none.
fn operand_end(chars: &[char], from: usize) -> usize {
    let mut i = from;
    while i < chars.len() && chars[i].is_whitespace() {
        i += 1;
    }
    let group = |mut i: usize| {
        // i at '(': to just past its matching ')'
        let mut depth = 0usize;
        while i < chars.len() {
            match chars[i] {
                '(' => depth += 1,
                ')' => {
                    depth -= 1;
                    if depth == 0 {
                        return i + 1;
                    }
                }
                _ => {}
            }
            i += 1;
        }
        i
    };
    match chars.get(i) {
        Some(c) if c.is_ascii_digit() || *c == '.' => {
            while i < chars.len() && (chars[i].is_ascii_digit() || chars[i] == '.') {
                i += 1;
            }
            // and its exponent, if any
            if matches!(chars.get(i), Some('e' | 'E')) {
                let mut j = i + 1;
                if matches!(chars.get(j), Some('+' | '-')) {
                    j += 1;
                }
                let digits = j;
                while j < chars.len() && chars[j].is_ascii_digit() {
                    j += 1;
                }
                if j > digits {
                    i = j;
                }
            }
            i
        }
        Some(c) if c.is_ascii_alphabetic() || *c == '_' => {
            while i < chars.len() && (chars[i].is_ascii_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
            let mut j = i;
            while j < chars.len() && chars[j].is_whitespace() {
                j += 1;
            }
            if chars.get(j) == Some(&'(') {
                group(j)
            } else {
                i
            }
        }
        Some('(') => group(i),
        // a braced variable `{x}` (a `-{x}^2` passed the guard as a plain minus)
        Some('{') => chars[i..]
            .iter()
            .position(|&c| c == '}')
            .map_or(chars.len(), |k| i + k + 1),
        _ => from,
    }
}

/// The expression as a function of `[x, y]`: its variables (alphabetical in `exmex`)
/// mapped to coordinates once, here. An evaluation error (none is known for the float
/// operators) gives NaN, which the solver's data checks refuse.
fn function_of_point(parsed: FlatEx<f64>) -> Data {
    let coordinates: Vec<usize> = parsed
        .var_names()
        .iter()
        .map(|v| VARIABLES.iter().position(|c| c == v).expect("checked"))
        .collect();
    Data::shared(move |x: &[f64]| {
        let mut values = [0.0; 2];
        for (k, &c) in coordinates.iter().enumerate() {
            values[k] = x.get(c).copied().unwrap_or(0.0);
        }
        parsed
            .eval(&values[..coordinates.len()])
            .unwrap_or(f64::NAN)
    })
}

/// `∂/∂x` and `∂/∂y` of an expression (0 for a variable it does not use), each
/// derived once, symbolically, by `exmex`.
///
/// # Errors
/// As [`expression`]; an expression longer than 1000 characters, and one `exmex`
/// cannot differentiate.
pub fn gradient(text: &str, field: &str, file: &Path) -> Result<Data<[f64; 2]>> {
    // exmex differentiates by recursion over the expression tree, and its simplification
    // can take long on long expressions: bound the text, and give the work a large stack
    if text.len() > MAX_DIFFERENTIATED_LENGTH {
        return Err(Error::Input(format!(
            "{}: field `{field}`: the expression has {} characters; an exact solution to differentiate may have at most {MAX_DIFFERENTIATED_LENGTH}",
            file.display(),
            text.len()
        )));
    }
    std::thread::scope(|scope| {
        std::thread::Builder::new()
            .stack_size(256 << 20)
            .spawn_scoped(scope, || gradient_on_this_thread(text, field, file))
            .map_err(|e| {
                Error::Input(format!(
                    "cannot start the differentiation of `{field}`: {e}"
                ))
            })?
            .join()
            .unwrap_or_else(|_| {
                Err(Error::Input(format!(
                    "{}: field `{field}`: differentiating `{text}` failed",
                    file.display()
                )))
            })
    })
}

/// Longest `exact.u` text that is differentiated symbolically.
const MAX_DIFFERENTIATED_LENGTH: usize = 1000;

fn gradient_on_this_thread(text: &str, field: &str, file: &Path) -> Result<Data<[f64; 2]>> {
    let parsed = parse_checked(text, field, file)?;
    let mut parts: Vec<Option<Data>> = Vec::new();
    for variable in VARIABLES {
        match parsed.var_names().iter().position(|v| v == variable) {
            Some(k) => {
                let derivative = parsed.clone().partial(k).map_err(|e| {
                    Error::Input(format!(
                        "{}: field `{field}`: cannot differentiate `{text}` by {variable}: {e}",
                        file.display()
                    ))
                })?;
                parts.push(Some(function_of_point(derivative)));
            }
            None => parts.push(None),
        }
    }
    Ok(Data::shared(move |x: &[f64]| {
        let mut out = [0.0; 2];
        for (k, part) in parts.iter().enumerate() {
            if let Some(d) = part {
                out[k] = d.at(x);
            }
        }
        out
    }))
}

/// The name of a scene file's scene, which becomes part of output file names
/// (`out/<name>-<pair>-<N>.vtu`): the file's `name` as given, or else its file name's
/// stem with every character other than letters, digits, `-`, `_` and `.` turned into
/// `-` (`my gap.toml` → `my-gap`), `default` if nothing is left.
///
/// # Errors
/// The reason, for a given `name` that is empty, starts with `.` or `-` (a leading `-`
/// would read as an option to a shell command given the output file) or has other
/// characters.
pub fn scene_name(
    name: Option<&str>,
    path: &Path,
    default: &str,
) -> std::result::Result<String, String> {
    let plain = |c: char| c.is_alphanumeric() || c == '-' || c == '_' || c == '.';
    let Some(name) = name else {
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy())
            .unwrap_or_default();
        let cleaned: String = stem
            .chars()
            .map(|c| if plain(c) { c } else { '-' })
            .collect();
        let cleaned = cleaned.trim_start_matches(['.', '-']);
        return Ok(if cleaned.is_empty() {
            default.to_string()
        } else {
            cleaned.to_string()
        });
    };
    if name.is_empty() || name.starts_with(['.', '-']) || !name.chars().all(plain) {
        return Err(format!(
            "`{name}` cannot name output files: use letters, digits, `-`, `_` and `.` (not first, nor `-`)"
        ));
    }
    Ok(name.to_string())
}

// ---------------------------------------------------------------------------------------
// The scene of any registry family
// ---------------------------------------------------------------------------------------

use crate::family::{finite, Family, FieldError, FileKeys};
use crate::report::Settings;
use crate::scene::{Domain, Exact, ExactSolution, Load, Part, PartSupport, Scene, Support};
use fem_runtime::problem::MIN_DATA_SIZE;
use fem_runtime::TriangleMesh;
use serde::Deserialize;
use std::path::PathBuf;

/// A scene file as written; the family's own keys go under `[parameters]` and `[data]`
/// by the model's declared names or the family's aliases.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct FileToml {
    name: Option<String>,
    description: Option<String>,
    model: String,
    pair: Option<String>,
    /// The L² error of the constrained field the scene asks for (needs `[exact]`).
    accuracy: Option<f64>,
    /// Solve adaptively to this tolerance relative to the solution's energy norm.
    tol: Option<f64>,
    /// Plates: report the moments and shear force along the boundary (and resolve the
    /// Reissner–Mindlin boundary layer under `tol`).
    edge_resultants: Option<bool>,
    /// Which side of the structure the obstacle is on: "below" (the default) or "above".
    obstacle_side: Option<String>,
    mesh: MeshToml,
    /// The family's material (contact's E, ν), read by the family.
    material: Option<toml::Table>,
    #[serde(default)]
    boundary: BoundaryToml,
    #[serde(default)]
    parameters: toml::Table,
    #[serde(default)]
    data: toml::Table,
    exact: Option<ExactToml>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct MeshToml {
    generator: Option<String>,
    half_width: Option<f64>,
    #[serde(default, deserialize_with = "two")]
    x: Option<[f64; 2]>,
    #[serde(default, deserialize_with = "two")]
    y: Option<[f64; 2]>,
    #[serde(default, deserialize_with = "two")]
    cells: Option<[usize; 2]>,
    start: Option<f64>,
    end: Option<f64>,
    centre: Option<[f64; 2]>,
    radius: Option<f64>,
    curved: Option<bool>,
    size: Option<usize>,
    file: Option<PathBuf>,
    refinements: Option<usize>,
}

#[derive(Deserialize, Debug, Default)]
#[serde(deny_unknown_fields)]
struct BoundaryToml {
    clamped: Option<toml::Value>,
    simply_supported: Option<toml::Value>,
    simply_supported_hard: Option<toml::Value>,
    free: Option<toml::Value>,
    dirichlet: Option<toml::Value>,
    /// `u_x = 0`: a roller along y.
    fixed_x: Option<toml::Value>,
    /// `u_y = 0`: a roller along x.
    fixed_y: Option<toml::Value>,
    /// The facet part Γ_C of a contact model ([`Family::facet_keys`]).
    contact: Option<toml::Value>,
    /// The loaded facet part Γ_N of a contact model.
    load: Option<toml::Value>,
    #[serde(default)]
    roller: Vec<RollerToml>,
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
struct RollerToml {
    part: toml::Value,
    #[serde(deserialize_with = "exactly_two")]
    normal: [f64; 2],
}

/// A Hessian written as exactly two rows of exactly two expressions.
fn hessian_rows<'de, D>(deserializer: D) -> std::result::Result<Option<[[String; 2]; 2]>, D::Error>
where
    D: serde::Deserializer<'de>,
{
    let rows = Vec::<Vec<String>>::deserialize(deserializer)?;
    let shape = || {
        serde::de::Error::custom(format!(
            "a Hessian is two rows of two expressions, [[\"u_xx\", \"u_xy\"], [\"u_yx\", \"u_yy\"]]; got {} row(s) of {:?} entries",
            rows.len(),
            rows.iter().map(Vec::len).collect::<Vec<_>>()
        ))
    };
    let pair = |row: &Vec<String>| <[String; 2]>::try_from(row.clone()).map_err(|_| shape());
    match rows.as_slice() {
        [a, b] => Ok(Some([pair(a)?, pair(b)?])),
        _ => Err(shape()),
    }
}

/// A required pair written as a TOML array of exactly two entries (see [`two`]).
fn exactly_two<'de, D, T>(deserializer: D) -> std::result::Result<[T; 2], D::Error>
where
    D: serde::Deserializer<'de>,
    T: Deserialize<'de>,
{
    two(deserializer).map(|pair| pair.expect("`two` gives a pair or an error"))
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct ExactToml {
    #[serde(alias = "u", alias = "w")]
    value: Option<String>,
    #[serde(default, deserialize_with = "two")]
    gradient: Option<[String; 2]>,
    #[serde(default, deserialize_with = "hessian_rows")]
    hessian: Option<[[String; 2]; 2]>,
    lambda: Option<String>,
    /// The contact pressure on Γ_C: the multiplier of a contact model.
    pressure: Option<String>,
    contact_force: Option<f64>,
    contact_area: Option<f64>,
}

/// A scene read from a file, with the solve settings it names (the command line's
/// options win).
#[derive(Clone, Debug)]
pub struct FileScene {
    /// The scene.
    pub scene: Scene,
    /// The pair the file names.
    pub pair: Option<String>,
    /// The α the file fixes (`parameters.alpha`).
    pub alpha: Option<f64>,
}

impl FileScene {
    /// The settings the file asks for: its pair and α, the rest the defaults.
    pub fn settings(&self) -> Settings {
        Settings {
            pair: self.pair.clone(),
            alpha: self.alpha,
            ..Settings::default()
        }
    }
}

/// The family a scene file names under `model`, read before the rest of the file.
pub fn family_of(text: &str) -> Option<String> {
    #[derive(Deserialize)]
    struct ModelOnly {
        model: Option<String>,
    }
    toml::from_str::<ModelOnly>(text).ok()?.model
}

/// The smallest `mesh.half_width` of a square: below it `α h⁴` of a fine mesh's cells
/// falls near the end of double precision's normal range (1e-40 failed with C_0 = −0).
const MIN_HALF_WIDTH: f64 = 1e-30;

/// The most uniform refinements of a Gmsh file (4⁸ times its triangles).
const MAX_REFINEMENTS: usize = 8;

/// Reads a scene file ([`parse`]).
///
/// # Errors
/// An unreadable file, and those of [`parse`].
pub fn read(path: &Path) -> Result<FileScene> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        Error::Input(format!(
            "cannot read the scene file {}: {e}",
            path.display()
        ))
    })?;
    parse(&text, path)
}

/// Parses a scene file of any registry family (docs/scene-files.md) whose relative paths
/// are relative to `path`.
///
/// # Errors
/// As [`read_scene`]; a `model` that is no family of the registry.
pub fn parse(text: &str, path: &Path) -> Result<FileScene> {
    let names: Vec<&str> = crate::families::families()
        .iter()
        .map(|f| f.name())
        .collect();
    let model = family_of(text);
    let family = model.as_deref().and_then(crate::families::family);
    match (model, family) {
        (Some(_), Some(family)) => read_scene(text, path, family),
        (Some(model), None) => Err(Error::Input(format!(
            "{}: field `model`: `{model}` is not a family scene files can pose; the families are {}",
            path.display(),
            names.join(", ")
        ))),
        // the TOML error (a syntax error, or `model` missing) names the place
        (None, _) => toml::from_str::<FileToml>(text)
            .map(|_| unreachable!("a file that deserializes has a model"))
            .map_err(|e| Error::Input(format!("scene file {}: {e}", path.display()))),
    }
}

/// Reads a scene file of `family` (docs/scene-files.md): the mesh, the supports per
/// boundary part, the parameters and data by the model's names or the family's aliases,
/// the exact solution with its derivatives given or derived.
///
/// # Errors
/// [`Error::Input`] naming the file and the field: TOML errors, unknown keys, a mesh
/// given both ways or neither or out of range, boundary parts that are not names or not
/// the generator's, a load that is not finite or would underflow, expressions that do
/// not parse, an exact gradient or Hessian that the finite differences of the value
/// (or gradient) contradict, exact integrals that are negative, an accuracy without an
/// exact solution.
pub fn read_scene(text: &str, path: &Path, family: &dyn Family) -> Result<FileScene> {
    let at = |(field, message): FieldError| {
        Error::Input(format!("{}: field `{field}`: {message}", path.display()))
    };
    let file: FileToml = toml::from_str(text)
        .map_err(|e| Error::Input(format!("scene file {}: {e}", path.display())))?;
    if file.model != family.name() {
        return Err(at((
            "model".into(),
            format!("`{}` is read as the family `{}`", file.model, family.name()),
        )));
    }
    let name =
        scene_name(file.name.as_deref(), path, "scene").map_err(|m| at(("name".into(), m)))?;
    let (domain, mesh_size) = domain_of(&file.mesh, path).map_err(at)?;
    check_dimension(&domain, family).map_err(at)?;
    let description = file
        .description
        .clone()
        .unwrap_or_else(|| format!("scene file {}", path.display()));
    let mut scene = Scene::new(name, description, family.name(), domain, mesh_size);
    let alpha = read_parameters(&file, family, &mut scene).map_err(at)?;
    let model_name = |key: &str| model_name(family, key);
    let load = read_data(&mut scene, &file.data, &model_name, path)?;
    scale_load(&mut scene, family, load).map_err(at)?;
    scene.supports = supports(&file.boundary, family).map_err(at)?;
    scene.facets = facets(&file.boundary, family).map_err(at)?;
    check_parts(&scene).map_err(at)?;
    if let Some(e) = &file.exact {
        // the contact set is not linear in the load: the file's exact solution holds at
        // its own load
        scene.exact = Exact::AtDefaultLoad(exact_of(e, &scene.domain, path)?);
    }
    scene.accuracy = accuracy_of(&file, family).map_err(at)?;
    if let Some(side) = &file.obstacle_side {
        scene.side = match side.as_str() {
            "below" => fem_runtime::problem::ObstacleSide::Below,
            "above" => fem_runtime::problem::ObstacleSide::Above,
            other => {
                return Err(at((
                    "obstacle_side".into(),
                    format!(
                        "`{other}` is no side: \"below\" (w ≥ ψ, the default) or \"above\" (w ≤ ψ)"
                    ),
                )))
            }
        };
    }
    if let Some(tol) = file.tol {
        if !(tol > 0.0 && tol < 1.0) {
            return Err(at((
                "tol".into(),
                format!("{tol} is not a tolerance: a relative error of the solution's energy norm lies in (0, 1), e.g. 1e-2"),
            )));
        }
        if !family.options().contains(&crate::family::Opt::Tol) {
            return Err(at((
                "tol".into(),
                format!(
                    "the {} family has no a-posteriori estimator yet: solve it on the file's mesh without `tol`",
                    family.name()
                ),
            )));
        }
        scene.tolerance = Some(tol);
    }
    if file.edge_resultants == Some(true) {
        if !family
            .options()
            .contains(&crate::family::Opt::EdgeResultants)
        {
            return Err(at((
                "edge_resultants".into(),
                format!(
                    "the {} family has no edge resultants: they are a plate's moments and shear force along its boundary (families plate and kirchhoff)",
                    family.name()
                ),
            )));
        }
        scene.edge_resultants = true;
    }
    if let Some(pair) = &file.pair {
        // a neighbour model's pair (a Kirchhoff file's thickness takes p1-p2-p0) solves
        // that model; one that a thickness given on the command line would pose is
        // checked by the solve
        if let Err(e) = crate::families::pair_of(&scene, Some(pair)) {
            if crate::choice::neighbour_pair(&scene, pair).is_none()
                && crate::families::richer_pair_given(&scene, family, pair).is_none()
            {
                return Err(at(("pair".into(), e.to_string())));
            }
        }
    }
    family.check_file(&scene).map_err(at)?;
    Ok(FileScene {
        scene,
        pair: file.pair,
        alpha,
    })
}

/// The model's name of a scene file's key: the family's alias, or the key itself.
fn model_name(family: &dyn Family, key: &str) -> String {
    family
        .aliases()
        .iter()
        .find(|(alias, _)| *alias == key)
        .map_or(key.to_string(), |(_, name)| name.to_string())
}

/// The domain is of the family's dimension: an interval for beams, triangles otherwise.
fn check_dimension(domain: &Domain, family: &dyn Family) -> std::result::Result<(), FieldError> {
    let interval = matches!(domain, Domain::Interval { .. });
    if interval == (family.dimension() == 1) {
        return Ok(());
    }
    Err((
        "mesh".into(),
        if interval {
            format!(
                "the {} family is posed on triangle meshes (a 2D generator or a Gmsh file), not on an interval",
                family.name()
            )
        } else {
            format!(
                "the {} family is posed on an interval: generator = \"interval\" with start, end and size",
                family.name()
            )
        },
    ))
}

/// `[material]` and the family's own parameters ([`Family::read_file`]), then every other
/// `[parameters]` key by the model's name; returns `parameters.alpha`.
fn read_parameters(
    file: &FileToml,
    family: &dyn Family,
    scene: &mut Scene,
) -> std::result::Result<Option<f64>, FieldError> {
    let mut parameters = file.parameters.clone();
    family.read_file(
        FileKeys {
            material: file.material.as_ref(),
            parameters: &mut parameters,
        },
        scene,
    )?;
    let mut alpha = None;
    for (key, value) in &parameters {
        let field = format!("parameters.{key}");
        let Some(v) = finite(value) else {
            return Err((field, format!("{value} is not a finite number")));
        };
        if key == "alpha" || key == "α" {
            if v < 0.0 {
                return Err((
                    field,
                    format!(
                        "α = {} must be ≥ 0 (0: the plain method)",
                        fem_runtime::problem::number(v)
                    ),
                ));
            }
            if alpha.is_some() {
                return Err((field, "`alpha` and `α` both name α: give it once".into()));
            }
            alpha = Some(v);
        } else if key == "s" {
            // the models' obstacle side: the solve sets it from the scene's side
            return Err((
                field,
                "`s` is the obstacle's side (+1 below the structure, −1 above), not a parameter: write `obstacle_side = \"above\"` (or \"below\", the default) at the top of the file".into(),
            ));
        } else {
            let name = model_name(family, key);
            if let Some(other) = parameters
                .keys()
                .take_while(|k| *k != key)
                .find(|k| model_name(family, k) == name)
            {
                return Err((
                    field,
                    format!("`{key}` and `{other}` both name the model's `{name}`: give it once"),
                ));
            }
            if family.richer_parameters().contains(&name.as_str()) {
                scene.set_richer_parameter(name, v);
            } else {
                scene.set_parameter(name, v);
            }
        }
    }
    Ok(alpha)
}

/// The load magnitude `data.load` scales the family's scaled data by
/// ([`Family::scaled_load`]), checked for its sign and range as a `--load` is.
fn scale_load(
    scene: &mut Scene,
    family: &dyn Family,
    load: Option<f64>,
) -> std::result::Result<(), FieldError> {
    let (scaled, sign) = family.scaled_load();
    let scaled = model_name(family, scaled);
    if scene.data_fn(&scaled).is_none() {
        // the family's word for it (contact's `pressure`), else the model's
        let key = family
            .aliases()
            .iter()
            .find(|(_, name)| *name == scaled)
            .map_or_else(
                || crate::scene::data_key(&scaled),
                |(alias, _)| alias.to_string(),
            );
        return match load {
            Some(_) => Err((
                "data.load".into(),
                format!("scales the load `data.{key}`, which the file does not give"),
            )),
            None => Ok(()),
        };
    }
    scene.load = Some(Load {
        default: load.unwrap_or(1.0),
        scales: vec![scaled.into()],
        symbol: "q",
        sign,
    });
    scene
        .load_magnitude(load)
        .map(|_| ())
        .map_err(|m| ("data.load".into(), m.replace("--load", "the load")))
}

/// The file's `accuracy`, which needs the exact quantity it is measured on
/// ([`Family::accuracy_key`]).
fn accuracy_of(
    file: &FileToml,
    family: &dyn Family,
) -> std::result::Result<Option<f64>, FieldError> {
    let Some(a) = file.accuracy else {
        return Ok(None);
    };
    let key = family.accuracy_key();
    let given = file.exact.as_ref().is_some_and(|e| match key {
        "pressure" => e.pressure.is_some() || e.lambda.is_some(),
        _ => e.value.is_some(),
    });
    if !given {
        return Err((
            "accuracy".into(),
            format!("an accuracy needs an `[exact] {key}` to measure the error against"),
        ));
    }
    if !(a.is_finite() && a > 0.0) {
        return Err((
            "accuracy".into(),
            format!("{a} must be positive and finite"),
        ));
    }
    Ok(Some(a))
}

/// `[data]`: each expression set on `scene` by the model's name (`model_name` of its
/// key); returns `data.load`, the scale of the load.
///
/// # Errors
/// A load that is not finite or would underflow, a value that is not an expression, and
/// an expression that does not parse.
fn read_data(
    scene: &mut Scene,
    data: &toml::Table,
    model_name: &dyn Fn(&str) -> String,
    path: &Path,
) -> Result<Option<f64>> {
    let at = |field: &str, message: String| {
        Error::Input(format!("{}: field `{field}`: {message}", path.display()))
    };
    let mut load = None;
    for (key, value) in data {
        let field = format!("data.{key}");
        if key == "load" {
            let q = finite(value)
                .ok_or_else(|| at(&field, format!("{value} is not a finite number")))?;
            if q != 0.0 && q.abs() < MIN_DATA_SIZE {
                return Err(at(
                    &field,
                    format!("{q:e} is below {MIN_DATA_SIZE:e} in size: the solve multiplies it by powers of h and would underflow; give 0 or rescale the units"),
                ));
            }
            load = Some(q);
            continue;
        }
        let text = match value {
            toml::Value::String(s) => s.clone(),
            toml::Value::Float(v) => v.to_string(),
            toml::Value::Integer(v) => v.to_string(),
            other => return Err(at(&field, format!("{other} is not an expression"))),
        };
        let name = model_name(key);
        if let Some(other) = data
            .keys()
            .take_while(|k| *k != key)
            .find(|k| *k != "load" && model_name(k) == name)
        {
            return Err(at(
                &field,
                format!("`{key}` and `{other}` both name the model's `{name}`: give it once"),
            ));
        }
        scene.set_data(name.clone(), expression(&text, &field, path)?);
        scene.file_keys.push((name.into(), key.clone()));
    }
    Ok(load)
}

/// The domain and `N` of `[mesh]`; errors as `(field, message)`.
fn domain_of(
    mesh: &MeshToml,
    path: &Path,
) -> std::result::Result<(Domain, usize), (String, String)> {
    let err = |f: &str, m: String| Err((f.to_string(), m));
    match (&mesh.generator, &mesh.file) {
        (Some(_), Some(_)) => err("mesh", "give either `generator` or `file`, not both".into()),
        (None, None) => err(
            "mesh",
            "give a `generator` (interval, rectangle, square, l-shape, disk) or a Gmsh `file`"
                .into(),
        ),
        (None, Some(msh)) => {
            if mesh.size.is_some() || mesh.half_width.is_some() {
                return err(
                    "mesh",
                    "a Gmsh `file` takes `refinements`, not `size` or `half_width`".into(),
                );
            }
            foreign_keys("file", mesh)?;
            let refinements = mesh.refinements.unwrap_or(0);
            if refinements > MAX_REFINEMENTS {
                return err(
                    "mesh.refinements",
                    format!("{refinements} uniform refinements (4^{refinements} times the triangles): at most {MAX_REFINEMENTS}"),
                );
            }
            let base = path.parent().unwrap_or(Path::new("."));
            Ok((Domain::Gmsh(base.join(msh)), refinements))
        }
        (Some(generator), None) => {
            // a rectangle of the squares the file counts is refined like a file's mesh
            if generator == "rectangle" && mesh.cells.is_some() && mesh.size.is_none() {
                return refined_rectangle(mesh);
            }
            if mesh.refinements.is_some() {
                return err(
                    "mesh.refinements",
                    "applies to a Gmsh `file` or a rectangle of given `cells` (without `size`); a generator takes `size`".into(),
                );
            }
            let interval = generator == "interval";
            let size = mesh.size.unwrap_or(if interval { 256 } else { 64 });
            let range = if interval { 1..=1 << 20 } else { 2..=4096 };
            if !range.contains(&size) {
                return err(
                    "mesh.size",
                    format!(
                        "{size} is out of range ({} to {})",
                        range.start(),
                        range.end()
                    ),
                );
            }
            Ok((generated(generator, mesh, size)?, size))
        }
    }
}

/// The domain of a `[mesh]` generator at size `size` (checked by the caller); errors as
/// `(field, message)`.
fn generated(
    generator: &str,
    mesh: &MeshToml,
    size: usize,
) -> std::result::Result<Domain, (String, String)> {
    let err = |f: &str, m: String| Err((f.to_string(), m));
    foreign_keys(generator, mesh)?;
    let no_half_width = |what: &str| match mesh.half_width {
        Some(_) => Err((
            "mesh.half_width".to_string(),
            format!("{what}; it takes no half_width"),
        )),
        None => Ok(()),
    };
    let domain = match generator {
        "interval" => {
            no_half_width("the interval is (start, end)")?;
            Domain::Interval {
                start: mesh.start.unwrap_or(0.0),
                end: mesh.end.unwrap_or(1.0),
            }
        }
        "square" => {
            if mesh.x.is_some() || mesh.y.is_some() {
                return err(
                    "mesh.x",
                    "a square is (−a, a)² with a = half_width; `rectangle` takes x and y".into(),
                );
            }
            let a = mesh.half_width.unwrap_or(1.0);
            let largest = fem_runtime::mesh::triangle::MAX_COORDINATE;
            if !(MIN_HALF_WIDTH..=largest).contains(&a) {
                return err(
                    "mesh.half_width",
                    format!("{} must be within {MIN_HALF_WIDTH:e} to {largest:e}: below, the stabilization's α h⁴ underflows; rescale the units", fem_runtime::problem::number(a)),
                );
            }
            Domain::square(-a, 2.0 * a)
        }
        "rectangle" => {
            no_half_width("a rectangle is x × y")?;
            let [x, y] = rectangle_sides(mesh)?;
            Domain::Rectangle {
                x,
                y,
                cells: rectangle_cells(mesh)?,
                diagonal: fem_runtime::Diagonal::Right,
            }
        }
        "l-shape" => {
            no_half_width("the L-shape is (−1,1)² ∖ [0,1]×[−1,0]")?;
            if size % 2 != 0 {
                return err(
                    "mesh.size",
                    format!("the L-shape needs an even size, got {size}"),
                );
            }
            Domain::LShape
        }
        "disk" => {
            no_half_width("a disk has a radius")?;
            Domain::Disk {
                centre: mesh.centre.unwrap_or([0.0, 0.0]),
                radius: mesh.radius.unwrap_or(1.0),
                curved: mesh.curved.unwrap_or(false),
            }
        }
        other => {
            return err(
                "mesh.generator",
                format!("unknown generator `{other}`; the generators are interval, rectangle, square, l-shape, disk"),
            )
        }
    };
    Ok(domain)
}

/// Refuses the `[mesh]` keys another generator takes (a square's `cells`, a disk's `x`):
/// left unread, they would be ignored without a word.
fn foreign_keys(generator: &str, mesh: &MeshToml) -> std::result::Result<(), (String, String)> {
    let given = [
        ("half_width", mesh.half_width.is_some()),
        ("x", mesh.x.is_some()),
        ("y", mesh.y.is_some()),
        ("cells", mesh.cells.is_some()),
        ("start", mesh.start.is_some()),
        ("end", mesh.end.is_some()),
        ("centre", mesh.centre.is_some()),
        ("radius", mesh.radius.is_some()),
        ("curved", mesh.curved.is_some()),
    ];
    let takes: &[&str] = match generator {
        "interval" => &["start", "end"],
        "square" => &["half_width"],
        "rectangle" => &["x", "y", "cells"],
        "l-shape" => &[],
        "disk" => &["centre", "radius", "curved"],
        "file" => &[],
        // an unknown generator is named by its own error
        _ => return Ok(()),
    };
    // a half_width off the square, and a square's x, have their own messages that say
    // which generator to take
    let said = |key: &str| key == "half_width" || (key == "x" && generator == "square");
    match given
        .iter()
        .find(|(key, set)| *set && !takes.contains(key) && !said(key))
    {
        Some((key, _)) => Err((
            format!("mesh.{key}"),
            if generator == "file" {
                "does not apply to a Gmsh `file`, which takes refinements".to_string()
            } else {
                format!(
                    "does not apply to the generator `{generator}`, which takes {}size",
                    takes.iter().map(|k| format!("{k}, ")).collect::<String>()
                )
            },
        )),
        None => Ok(()),
    }
}

/// The sides `[x, y]` of a `[mesh]` rectangle, checked; errors as `(field, message)`.
fn rectangle_sides(mesh: &MeshToml) -> std::result::Result<[[f64; 2]; 2], (String, String)> {
    let x = mesh.x.unwrap_or([0.0, 1.0]);
    let y = mesh.y.unwrap_or(x);
    let largest = fem_runtime::mesh::triangle::MAX_COORDINATE;
    for (field, s) in [("mesh.x", x), ("mesh.y", y)] {
        if !(s[0] < s[1] && s.iter().all(|c| c.is_finite() && c.abs() <= largest)) {
            return Err((
                field.into(),
                format!(
                    "[{}, {}] must be finite and increasing, within ±{largest:e}",
                    s[0], s[1]
                ),
            ));
        }
    }
    Ok([x, y])
}

/// The most squares of a rectangle's `cells` (before `size` or `refinements`).
const MAX_RECTANGLE_SQUARES: usize = 1 << 20;

/// The squares `[nx, ny]` of a `[mesh]` rectangle (`[1, 1]` by default), checked.
fn rectangle_cells(mesh: &MeshToml) -> std::result::Result<[usize; 2], (String, String)> {
    let [nx, ny] = mesh.cells.unwrap_or([1, 1]);
    if !(1..=4096).contains(&nx) || !(1..=4096).contains(&ny) || nx * ny > MAX_RECTANGLE_SQUARES {
        return Err((
            "mesh.cells".into(),
            format!("[{nx}, {ny}]: each from 1 to 4096, at most 2^20 squares"),
        ));
    }
    Ok([nx, ny])
}

/// A rectangle of the squares `cells` names and its `refinements` (N counts them, as for
/// a Gmsh file); errors as `(field, message)`.
fn refined_rectangle(mesh: &MeshToml) -> std::result::Result<(Domain, usize), (String, String)> {
    if mesh.half_width.is_some() {
        return Err((
            "mesh.half_width".into(),
            "a rectangle is x × y; it takes no half_width".into(),
        ));
    }
    let [x, y] = rectangle_sides(mesh)?;
    let [nx, ny] = rectangle_cells(mesh)?;
    let refinements = mesh.refinements.unwrap_or(0);
    if refinements > MAX_REFINEMENTS {
        return Err((
            "mesh.refinements".into(),
            format!("{refinements} uniform refinements (4^{refinements} times the triangles): at most {MAX_REFINEMENTS}"),
        ));
    }
    let coarsest =
        TriangleMesh::rectangle(x[0], x[1], y[0], y[1], nx, ny, fem_runtime::Diagonal::Right)
            .map_err(|e| ("mesh".to_string(), e.to_string()))?;
    let description = format!(
        "rectangle ({},{})×({},{}) of {nx}×{ny} squares",
        fem_runtime::problem::number(x[0]),
        fem_runtime::problem::number(x[1]),
        fem_runtime::problem::number(y[0]),
        fem_runtime::problem::number(y[1])
    );
    Ok((
        Domain::Refined {
            mesh: std::sync::Arc::new(coarsest),
            description: description.into(),
        },
        refinements,
    ))
}

/// The generator's name in the scene file.
fn generator_name(domain: &Domain) -> &'static str {
    match domain {
        Domain::Interval { .. } => "interval",
        Domain::Rectangle { x, y, .. } if x[0] == -x[1] && x == y => "square",
        Domain::Rectangle { .. } => "rectangle",
        Domain::LShape => "l-shape",
        Domain::Disk { .. } => "disk",
        Domain::Refined { .. } => "rectangle",
        Domain::Gmsh(_) | Domain::Generated(_) => "file",
    }
}

/// The parts a `[boundary]` key names: `"all"`, a name or a list of names (repeats
/// dropped). The error is the message for the field.
fn part_of(key: &str, value: &toml::Value) -> std::result::Result<Part, String> {
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
        Value::String(s) if s == "all" => Ok(Part::All),
        Value::Array(list) if list.is_empty() && key == "dirichlet" => Err(
            "an empty list: u = g would hold nowhere, and with ∂u/∂n = 0 on the whole boundary the membrane is determined only up to a constant where contact does not hold it; name at least one boundary part (or \"all\")".into(),
        ),
        Value::Array(list) if list.is_empty() => {
            Err("an empty list names no part; leave the key out instead".into())
        }
        Value::Array(list) => {
            let mut names: Vec<String> = Vec::with_capacity(list.len());
            for v in list {
                let n = name(v)?;
                if !names.contains(&n) {
                    names.push(n);
                }
            }
            Ok(Part::Named(names))
        }
        v => Ok(Part::Named(vec![name(v)?])),
    }
}

/// The supports of `[boundary]`, in the order clamped, simply supported (soft, hard),
/// free, dirichlet, rollers; where parts overlap the conditions combine (`free` adds
/// none, so `clamped = "all"` with `free = "right"` is clamped). Without any, the
/// family's default ([`Family::default_support`]) on the whole boundary.
fn supports(
    b: &BoundaryToml,
    family: &dyn Family,
) -> std::result::Result<Vec<PartSupport>, (String, String)> {
    let mut out = Vec::new();
    for (key, value, support) in [
        ("clamped", &b.clamped, Support::Clamped),
        (
            "simply_supported",
            &b.simply_supported,
            Support::SimplySupported { hard: false },
        ),
        (
            "simply_supported_hard",
            &b.simply_supported_hard,
            Support::SimplySupported { hard: true },
        ),
        ("free", &b.free, Support::Free),
        ("dirichlet", &b.dirichlet, Support::Data),
    ] {
        if let Some(v) = value {
            let field = format!("boundary.{key}");
            let part = part_of(key, v).map_err(|m| (field.clone(), m))?;
            out.push(PartSupport {
                part,
                support,
                key: Some(field.into()),
            });
        }
    }
    // u_x = 0 holds the displacement along (1, 0): a roller of that normal
    for (key, value, normal) in [
        ("fixed_x", &b.fixed_x, [1.0, 0.0]),
        ("fixed_y", &b.fixed_y, [0.0, 1.0]),
    ] {
        if let Some(v) = value {
            let field = format!("boundary.{key}");
            let part = part_of(key, v).map_err(|m| (field.clone(), m))?;
            out.push(PartSupport {
                part,
                support: Support::Roller { normal },
                key: Some(field.into()),
            });
        }
    }
    for (k, r) in b.roller.iter().enumerate() {
        let field = format!("boundary.roller[{k}]");
        let part = part_of("roller", &r.part).map_err(|m| (field.clone(), m))?;
        let [nx, ny] = r.normal;
        let length = nx.hypot(ny);
        if !(length.is_finite() && length > 0.0) {
            return Err((
                format!("{field}.normal"),
                format!("({nx}, {ny}) must be a non-zero finite vector"),
            ));
        }
        out.push(PartSupport {
            part,
            support: Support::Roller {
                normal: [nx / length, ny / length],
            },
            key: Some(field.into()),
        });
    }
    // two supports on the same named part: which one holds there would be the order of
    // the keys, which the file does not show
    for (k, a) in out.iter().enumerate() {
        for b in &out[..k] {
            if let (Part::Named(x), Part::Named(y)) = (&a.part, &b.part) {
                if let Some(name) = x.iter().find(|n| y.contains(n)) {
                    return Err((
                        a.key.as_deref().unwrap_or("boundary").to_string(),
                        format!(
                            "the part `{name}` also has `{}`: give each part one support",
                            b.key.as_deref().unwrap_or("another support")
                        ),
                    ));
                }
            }
        }
    }
    if out.is_empty() {
        if let Some((support, key)) = family.default_support() {
            out.push(PartSupport {
                part: Part::All,
                support,
                key: Some(key.into()),
            });
        }
    }
    Ok(out)
}

/// The model's facet parts of `[boundary]` ([`Family::facet_keys`]): each the family
/// has is required, and a family without facet parts takes none.
fn facets(
    b: &BoundaryToml,
    family: &dyn Family,
) -> std::result::Result<Vec<(crate::scene::Name, Part)>, (String, String)> {
    let keys = family.facet_keys();
    let mut out = Vec::new();
    for (key, value) in [("contact", &b.contact), ("load", &b.load)] {
        let field = format!("boundary.{key}");
        match (keys.iter().find(|(k, _)| *k == key), value) {
            (Some((_, facet)), Some(v)) => {
                let part = match v {
                    toml::Value::Array(list) if list.is_empty() => {
                        return Err((field, "name at least one boundary part".into()))
                    }
                    v => part_of(key, v).map_err(|m| (field.clone(), m))?,
                };
                out.push(((*facet).into(), part));
            }
            (Some(_), None) => {
                return Err((
                    "boundary".into(),
                    format!("the {} family needs `{key}` = the boundary part(s) of its {}", family.name(), if key == "contact" { "contact boundary Γ_C" } else { "loaded boundary Γ_N" }),
                ))
            }
            (None, Some(_)) => {
                return Err((
                    field,
                    format!(
                        "the {} family has no {key} boundary (contact bodies do): its supports are clamped, simply_supported, simply_supported_hard, free, dirichlet and rollers",
                        family.name()
                    ),
                ))
            }
            (None, None) => {}
        }
    }
    Ok(out)
}

/// The named parts of every support, checked against a coarse mesh of the generator
/// (a Gmsh file's names are checked when it is read).
fn check_parts(scene: &Scene) -> std::result::Result<(), (String, String)> {
    let sample = match &scene.domain {
        Domain::Rectangle { x, y, .. } => {
            TriangleMesh::rectangle(x[0], x[1], y[0], y[1], 2, 2, fem_runtime::Diagonal::Right).ok()
        }
        Domain::LShape => TriangleMesh::l_shape(2).ok(),
        _ => None,
    };
    let Some(mesh) = sample else {
        return Ok(());
    };
    for s in &scene.supports {
        let Part::Named(names) = &s.part else {
            continue;
        };
        if let Err(Error::Input(message)) = mesh.boundary_part_markers(names) {
            let keyword = if names.iter().any(|n| n == "all") {
                "; \"all\" (the whole boundary) is a keyword on its own, `dirichlet = \"all\"`, not a name in a list"
            } else {
                ""
            };
            let field = s.key.as_deref().unwrap_or("boundary").to_string();
            return Err((
                field,
                format!(
                    "{message} (generator `{}`){keyword}",
                    generator_name(&scene.domain)
                ),
            ));
        }
    }
    Ok(())
}

/// Points inside the domain's bounding box at which given derivatives are checked
/// (irrational shares: unlikely to sit on a kink of `max` or `abs`; a strip along an
/// edge is sampled too).
fn check_points(domain: &Domain) -> Vec<[f64; 2]> {
    let (x, y) = match domain {
        Domain::Interval { start, end } => ([*start, *end], [0.0, 0.0]),
        Domain::Rectangle { x, y, .. } => (*x, *y),
        Domain::Refined { mesh, .. } => {
            let box_of = |k: usize| {
                mesh.vertices()
                    .iter()
                    .fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], v| {
                        [lo.min(v[k]), hi.max(v[k])]
                    })
            };
            (box_of(0), box_of(1))
        }
        Domain::Disk { centre, radius, .. } => {
            let r = radius / std::f64::consts::SQRT_2;
            (
                [centre[0] - r, centre[0] + r],
                [centre[1] - r, centre[1] + r],
            )
        }
        _ => ([-1.0, 1.0], [-1.0, 1.0]),
    };
    // a 7 × 7 lattice of shares with irrational offsets, near every edge too
    let shares = [0.0123, 0.1617, 0.3172, 0.4714, 0.6180, 0.7861, 0.9641];
    shares
        .iter()
        .flat_map(|&s| {
            shares
                .iter()
                .map(move |&t| [x[0] + s * (x[1] - x[0]), y[0] + t * (y[1] - y[0])])
        })
        .collect()
}

/// Checks `derivative` (the given `∂f/∂x_k` as `derivative(x, k)`) against the central
/// differences of `f` at `points`.
fn check_derivative(
    f: &dyn Fn(&[f64]) -> f64,
    derivative: &dyn Fn(&[f64], usize) -> f64,
    points: &[[f64; 2]],
    dimension: usize,
) -> std::result::Result<(), String> {
    for p in points {
        for k in 0..dimension {
            let step = 1e-5 * (1.0 + p[k].abs());
            let (mut a, mut b) = (*p, *p);
            a[k] += step;
            b[k] -= step;
            let difference = (f(&a) - f(&b)) / (2.0 * step);
            let given = derivative(p, k);
            let scale = 1.0 + difference.abs().max(given.abs());
            let agrees = (given - difference).abs() <= 1e-4 * scale;
            // NaN (a derivative undefined where the function is) fails too
            if !agrees {
                return Err(format!(
                    "at ({}, {}) its component {} is {given:e}, the finite difference of the function {difference:e}",
                    p[0],
                    p[1],
                    k + 1
                ));
            }
        }
    }
    Ok(())
}

/// The exact solution of `[exact]`, its gradient and Hessian given (and checked) or
/// derived symbolically.
fn exact_of(e: &ExactToml, domain: &Domain, path: &Path) -> Result<ExactSolution> {
    let at = |field: &str, message: String| {
        Error::Input(format!("{}: field `{field}`: {message}", path.display()))
    };
    for (key, value) in [
        ("exact.contact_force", e.contact_force),
        ("exact.contact_area", e.contact_area),
    ] {
        if let Some(v) = value {
            if !(v.is_finite() && v >= 0.0) {
                return Err(at(
                    key,
                    format!(
                        "{} must be a finite number ≥ 0 (∫λ and the contact area cannot be negative)",
                        fem_runtime::problem::number(v)
                    ),
                ));
            }
        }
    }
    let dimension = if matches!(domain, Domain::Interval { .. }) {
        1
    } else {
        2
    };
    let points = check_points(domain);
    let multiplier = match (&e.lambda, &e.pressure) {
        (Some(_), Some(_)) => {
            return Err(at(
                "exact.pressure",
                "the multiplier is given twice: `lambda` and `pressure` name the same λ".into(),
            ))
        }
        (Some(l), None) => Some(expression(l, "exact.lambda", path)?),
        (None, Some(p)) => Some(expression(p, "exact.pressure", path)?),
        (None, None) => None,
    };
    let mut out = ExactSolution {
        multiplier,
        multiplier_key: e.pressure.is_some().then_some("exact.pressure"),
        total_contact_force: e.contact_force.map(|v| v + 0.0),
        contact_area: e.contact_area.map(|v| v + 0.0),
        ..ExactSolution::default()
    };
    let Some(value) = &e.value else {
        if e.gradient.is_some() || e.hessian.is_some() {
            return Err(at(
                if e.gradient.is_some() {
                    "exact.gradient"
                } else {
                    "exact.hessian"
                },
                "derivatives of an exact solution need its value, `[exact] u`".into(),
            ));
        }
        return Ok(out);
    };
    let u = expression(value, "exact.u", path)?;
    let gradient = match &e.gradient {
        Some([gx, gy]) => {
            let (gx, gy) = (
                expression(gx, "exact.gradient[0]", path)?,
                expression(gy, "exact.gradient[1]", path)?,
            );
            let g = Data::shared(move |x: &[f64]| [gx.at(x), gy.at(x)]);
            check_derivative(&|x| u.at(x), &|x, k| g.at(x)[k], &points, dimension)
                .map_err(|m| at("exact.gradient", format!("does not match `exact.u`: {m}")))?;
            g
        }
        None => gradient(value, "exact.u", path).map_err(|e| match e {
            Error::Input(m) => Error::Input(format!(
                "{m}; give the derivatives as `gradient = [\"∂u/∂x\", \"∂u/∂y\"]`"
            )),
            other => other,
        })?,
    };
    if let Some(h) = &e.hessian {
        out.hessian = Some(hessian_of(h, &gradient, &points, dimension, path)?);
    }
    out.value = Some(u);
    out.gradient = Some(gradient);
    Ok(out)
}

/// The exact Hessian of `[exact] hessian`, each row checked against the finite
/// differences of the gradient at `points`.
///
/// # Errors
/// An expression that does not parse, a row the gradient's differences contradict.
fn hessian_of(
    h: &[[String; 2]; 2],
    gradient: &Data<[f64; 2]>,
    points: &[[f64; 2]],
    dimension: usize,
    path: &Path,
) -> Result<Data<[[f64; 2]; 2]>> {
    let mut rows = Vec::new();
    for (i, row) in h.iter().enumerate() {
        rows.push([
            expression(&row[0], &format!("exact.hessian[{i}][0]"), path)?,
            expression(&row[1], &format!("exact.hessian[{i}][1]"), path)?,
        ]);
    }
    let rows = std::sync::Arc::new(rows);
    for i in 0..dimension {
        let (g, r) = (gradient.clone(), rows.clone());
        check_derivative(
            &move |x| g.at(x)[i],
            &move |x, k| r[i][k].at(x),
            points,
            dimension,
        )
        .map_err(|m| {
            Error::Input(format!(
                "{}: field `exact.hessian[{i}]`: does not match the gradient: {m}",
                path.display()
            ))
        })?;
    }
    Ok(Data::shared(move |x: &[f64]| {
        [
            [rows[0][0].at(x), rows[0][1].at(x)],
            [rows[1][0].at(x), rows[1][1].at(x)],
        ]
    }))
}

#[cfg(test)]
mod normalize_tests {
    use super::*;

    fn value(text: &str, x: f64, y: f64) -> f64 {
        let parsed = parse_checked(text, "f", Path::new("t.toml")).unwrap();
        let names: Vec<String> = parsed.var_names().to_vec();
        let args: Vec<f64> = names.iter().map(|n| if n == "x" { x } else { y }).collect();
        parsed.eval(&args).unwrap()
    }

    /// Scientific notation gives the same f64 as Rust's parser, wherever it stands.
    #[test]
    fn scientific_notation_is_read_exactly() {
        for (text, expected) in [
            ("1e20", 1e20),
            ("-1e20", -1e20),
            ("2.5e-3", 2.5e-3),
            ("1E5 + 1", 1e5 + 1.0),
            ("x*1e-3", 2.0 * 1e-3),
            ("3e+2", 300.0),
            ("1e-300", 1e-300),
            ("exp(0) + 2", 3.0),
        ] {
            let v = value(text, 2.0, 0.0);
            assert_eq!(v, expected, "{text}");
        }
        assert!(normalize("1e999").unwrap_err().contains("not finite"));
    }

    /// `-x^2` would be read as `(−x)²`: refused with the spellings that say what is meant;
    /// the unambiguous forms keep their meaning.
    #[test]
    fn a_unary_minus_before_a_power_is_refused() {
        for text in [
            "-x^2",
            "exp(-x^2-y^2)",
            "-1^2",
            "2*-x^2",
            "-(x)^2",
            "-{x}^2",
            "2^-{x}^2",
            "-sin(x)^2",
            "- x ^ 2",
            "-1e2^2",
        ] {
            let error = normalize(text).unwrap_err();
            assert!(error.contains("ambiguous"), "{text}: {error}");
        }
        for (text, expected) in [
            ("0-x^2", -9.0),
            ("-(x^2)", -9.0),
            ("(-x)^2", 9.0),
            ("2^-x", 0.125),
            ("x-y^2", 3.0 - 4.0),
            ("-x", -3.0),
            ("exp(0-(x^2+y^2))", (-13.0f64).exp()),
        ] {
            assert_eq!(value(text, 3.0, 2.0), expected, "{text}");
        }
    }

    /// `a^b^c` would be read as `(a^b)^c` (2^3^2 = 64, where mathematics means 512):
    /// refused; bracketed chains keep their meaning.
    #[test]
    fn a_chained_power_is_refused() {
        for text in [
            "2^3^2",
            "x^y^2",
            "x ^ 2 ^ y",
            "x^-2^2",
            "x^(1)^2",
            "x^sin(y)^2",
        ] {
            let error = normalize(text).unwrap_err();
            assert!(error.contains("chained power"), "{text}: {error}");
        }
        for (text, expected) in [
            ("2^(3^2)", 512.0),
            ("(2^3)^2", 64.0),
            ("x^2*y^2", 36.0),
            ("x^2+y^2", 13.0),
            ("2^-x", 0.125),
        ] {
            assert_eq!(value(text, 3.0, 2.0), expected, "{text}");
        }
    }
}
