//! What a solve is asked ([`Settings`]) and what it returns ([`Outcome`]: the one
//! [`Report`] of every family and the fields for output).

use crate::geometry::Fields;
use crate::scene::Name;
use fem_runtime::adaptivity::{AdaptiveLevel, AdaptiveOptions};
use fem_runtime::obstacle::hierarchy::LinearSolver;
use fem_runtime::obstacle::VariationalSolver;
use fem_runtime::Diagonal;
use serde::Serialize;
use std::collections::BTreeMap;

/// What a request may change of a scene's solve (the command line's options).
#[derive(Clone, Debug)]
pub struct Settings {
    /// The pair by name (`None`: the scene's default).
    pub pair: Option<String>,
    /// N (`None`: the scene's).
    pub mesh_size: Option<usize>,
    /// The load magnitude q (`None`: the scene's; refused where its load is fixed).
    pub load: Option<f64>,
    /// α (`None`: the pair's rule).
    pub alpha: Option<f64>,
    /// Parameters replacing the scene's, by the model's names (`--thickness` sets `t`).
    pub parameters: Vec<(Name, f64)>,
    /// The complementarity solver.
    pub solver: VariationalSolver,
    /// The solver of the Newton steps.
    pub linear_solver: LinearSolver,
    /// Nested iteration over coarser meshes (`false`: a cold start on the finest).
    pub nested: bool,
    /// Rounds of iterative refinement per linear solve (`None`: the family's).
    pub refinement: Option<usize>,
    /// How the squares of a structured mesh are split (`None`: the scene's).
    pub diagonal: Option<Diagonal>,
    /// Run the rounding experiment (`None`: where the family does).
    pub rounding_experiment: Option<bool>,
    /// Also form the multiplier's Schur complement of the finest mesh
    /// ([`Outcome::schur`]; the stability study).
    pub schur: bool,
    /// Also keep the discrete solution ([`Outcome::solution`]).
    pub keep_solution: bool,
    /// Solve adaptively (`--tol`, or a scene file's `tol`): the loop's tolerance,
    /// marking and limit (`None`: on the scene's mesh, or the scene file's `tol`).
    pub adaptive: Option<AdaptiveOptions>,
    /// What an adaptive solve tells of each level as it is done (the command line's
    /// progress bar).
    pub progress: Option<Progress>,
}

/// A callback that sees each level of an adaptive solve.
#[derive(Clone)]
pub struct Progress(pub std::sync::Arc<dyn Fn(&AdaptiveLevel) + Send + Sync>);

impl std::fmt::Debug for Progress {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Progress(..)")
    }
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            pair: None,
            mesh_size: None,
            load: None,
            alpha: None,
            parameters: Vec::new(),
            solver: VariationalSolver::SemismoothNewton,
            linear_solver: LinearSolver::Auto,
            nested: true,
            refinement: None,
            diagonal: None,
            rounding_experiment: None,
            schur: false,
            keep_solution: false,
            adaptive: None,
            progress: None,
        }
    }
}

/// Most rounds of iterative refinement per linear solve accepted.
pub const MAX_REFINEMENT_STEPS: usize = 10;

/// Wall time of the parts of a solve, in seconds.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct Phases {
    /// Building the meshes.
    pub meshes: f64,
    /// Binding the scene to the model and checking it.
    pub checks: f64,
    /// The runtime's solve (assembly and every level).
    pub solve: f64,
    /// The family's quantities and the output fields.
    pub evaluation: f64,
}

/// What a solve reports (the CLI's `--json` object): what every solve has, from the
/// runtime's report, and the family's own quantities beside it; a family's quantity
/// replaces the runtime's of the same key (contact's `total_contact_force` of the whole
/// body where the runtime's is of the half solved), so that no key appears twice.
#[derive(Clone, Debug)]
pub struct Report {
    /// Scene name.
    pub scene: String,
    /// Family name.
    pub family: &'static str,
    /// Pair name.
    pub pair: &'static str,
    /// The domain solved on.
    pub domain: String,
    /// N as solved (the beams' elements; a file's refinements).
    pub mesh_size: usize,
    /// The load magnitude q (`null` where the scene's load is fixed).
    pub load: Option<f64>,
    /// Every parameter of the scene by the model's name, as solved.
    pub parameters: BTreeMap<String, f64>,
    /// Each support as `name on parts`.
    pub supports: Vec<String>,
    /// The runtime's report.
    pub solve: fem_runtime::problem::Report,
    /// `∫ λ` of the exact solution over the scene's own domain, where known.
    pub exact_contact_force: Option<f64>,
    /// The exact contact set's area over the scene's own domain, where known.
    pub exact_contact_area: Option<f64>,
    /// The L² error the scene asks for.
    pub accuracy: Option<f64>,
    /// Where the time went.
    pub phases: Phases,
    /// The family's own quantities (a plate's centre deflection, Hertz's half-width).
    pub quantities: BTreeMap<String, serde_json::Value>,
}

/// The fields of a [`Report`] before the family's quantities, as they serialize.
#[derive(Serialize)]
struct Common<'a> {
    scene: &'a str,
    family: &'static str,
    pair: &'static str,
    domain: &'a str,
    mesh_size: usize,
    load: Option<f64>,
    parameters: &'a BTreeMap<String, f64>,
    supports: &'a [String],
    #[serde(flatten)]
    solve: &'a fem_runtime::problem::Report,
    exact_contact_force: Option<f64>,
    exact_contact_area: Option<f64>,
    accuracy: Option<f64>,
    phases: &'a Phases,
}

impl Serialize for Report {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::{Error, SerializeMap};
        let common = serde_json::to_value(Common {
            scene: &self.scene,
            family: self.family,
            pair: self.pair,
            domain: &self.domain,
            mesh_size: self.mesh_size,
            load: self.load,
            parameters: &self.parameters,
            supports: &self.supports,
            solve: &self.solve,
            exact_contact_force: self.exact_contact_force,
            exact_contact_area: self.exact_contact_area,
            accuracy: self.accuracy,
            phases: &self.phases,
        })
        .map_err(S::Error::custom)?;
        let serde_json::Value::Object(common) = common else {
            return Err(S::Error::custom("a report serializes to an object"));
        };
        let mut map = serializer.serialize_map(None)?;
        for (key, value) in &common {
            match self.quantities.get(key) {
                Some(own) => map.serialize_entry(key, own)?,
                None => map.serialize_entry(key, value)?,
            }
        }
        for (key, value) in &self.quantities {
            if !common.contains_key(key) {
                map.serialize_entry(key, value)?;
            }
        }
        map.end()
    }
}

impl Report {
    /// Sets the family quantity `key`.
    pub fn set(&mut self, key: &str, value: impl Serialize) {
        let value = serde_json::to_value(value).unwrap_or(serde_json::Value::Null);
        self.quantities.insert(key.to_string(), value);
    }

    /// A family quantity as a number (`None` where absent or not a number).
    pub fn number(&self, key: &str) -> Option<f64> {
        self.quantities.get(key).and_then(serde_json::Value::as_f64)
    }

    /// A family quantity as it was set (`None` where absent).
    pub fn quantity(&self, key: &str) -> Option<&serde_json::Value> {
        self.quantities.get(key)
    }

    /// Whether the solve's mesh leaves a boundary layer the scene asks about unresolved
    /// (`edge_resultants.layer_resolved` false).
    pub fn layer_unresolved(&self) -> bool {
        self.quantity("edge_resultants")
            .and_then(|r| r.get("layer_resolved"))
            .and_then(serde_json::Value::as_bool)
            == Some(false)
    }

    /// Adds a warning.
    pub fn warn(&mut self, warning: impl Into<String>) {
        self.solve.warnings.push(warning.into());
    }
}

/// A solved scene: its report and its fields for output.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The report.
    pub report: Report,
    /// The fields, sampled for charts and ParaView.
    pub fields: Fields,
    /// The multiplier along the boundary part it lives on, where the family charts it
    /// (`--plot`).
    pub profile: Option<Profile>,
    /// The multiplier's Schur complement on the finest mesh, where the settings ask for
    /// it ([`Settings::schur`]) and the pair has a multiplier space.
    pub schur: Option<Schur>,
    /// The discrete solution, where the settings ask for it
    /// ([`Settings::keep_solution`]).
    pub solution: Option<KeptSolution>,
}

/// The discrete solution of a solve, kept for comparisons across models and pairs (the
/// distance of a chosen cheaper model's solution to a reference of the scene's own).
#[derive(Clone)]
pub struct KeptSolution {
    /// The model's fields by name, in its order.
    pub fields: Vec<&'static str>,
    /// The runtime's `ObstacleSolution` of the mesh kind solved on
    /// (`ObstacleSolution<IntervalMesh>` for beams, `<TriangleMesh>` or
    /// `<CurvedTriangleMesh>` on triangles): downcast it.
    pub solution: std::sync::Arc<dyn std::any::Any + Send + Sync>,
}

impl std::fmt::Debug for KeptSolution {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("KeptSolution")
            .field("fields", &self.fields)
            .finish_non_exhaustive()
    }
}

/// The multiplier problem of a solve's finest mesh once the primal unknowns are
/// eliminated: what the stability (inf-sup) study measures.
#[derive(Clone, Debug)]
pub struct Schur {
    /// `S = B A⁻¹ Bᵀ + C` (m × m).
    pub matrix: nalgebra::DMatrix<f64>,
    /// The diagonal of the stabilization `C/α`, the multipliers' mesh-dependent norm
    /// (`None` for the plain method, α = 0, which has none).
    pub norm: Option<Vec<f64>>,
}

/// A multiplier along a boundary part (the contact pressure along Γ_C), against its
/// reference where one is known.
#[derive(Clone, Debug)]
pub struct Profile {
    /// The chart's title.
    pub title: String,
    /// The abscissa's name (`x`).
    pub x: &'static str,
    /// The ordinate's name (`pressure`).
    pub y: &'static str,
    /// The computed multiplier's label and values as steps `(x0, x1, λ)`: one per edge
    /// (x0 < x1, piecewise constant) or per vertex (x0 = x1, linear in between).
    pub computed: (String, Vec<(f64, f64, f64)>),
    /// The reference's label and curve `(x, λ)`.
    pub reference: Option<(String, Vec<(f64, f64)>)>,
}
