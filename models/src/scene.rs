//! One scene description for every family: what is posed (the domain, the model's
//! parameters and data by their declared names, the supports by boundary part, the
//! obstacle's side, the load, the exact solution or reference where one is known, the
//! accuracy asked) and what the registry adds (the pairs that discretize it, the studies
//! it hosts). Built-in scenes and scene files ([`crate::scene_file`]) yield the same
//! [`Scene`]; [`crate::run`] solves any of them with any pair of its family.
//!
//! Parameters and data are named as the model declares them (`t`, `D`, `ν`, `μ_L`; `f`,
//! `ψ`, `g`): a scene is bound to the model of the chosen pair in one place,
//! [`crate::run`], which refuses a name the model does not declare.

use crate::data::Data;
use fem_runtime::problem::ObstacleSide;
use fem_runtime::Diagonal;
use std::any::Any;
use std::borrow::Cow;
use std::fmt;
use std::path::PathBuf;
use std::sync::Arc;

/// A name of a parameter or data function: static for built-in scenes, owned for files.
pub type Name = Cow<'static, str>;

/// The domain a scene is posed on, and what `--mesh-size N` means on it.
#[derive(Clone)]
pub enum Domain {
    /// The interval `(start, end)` with N uniform elements.
    Interval {
        /// Left end (boundary part `left`).
        start: f64,
        /// Right end (boundary part `right`).
        end: f64,
    },
    /// The rectangle `[x0, x1] × [y0, y1]` with `N·cells[0] × N·cells[1]` squares split
    /// into two triangles each; boundary parts `bottom`, `right`, `top`, `left`.
    Rectangle {
        /// `[x0, x1]`.
        x: [f64; 2],
        /// `[y0, y1]`.
        y: [f64; 2],
        /// Squares per N along x and y (`[1, 1]`: the N×N×2 mesh).
        cells: [usize; 2],
        /// How each square is split.
        diagonal: Diagonal,
    },
    /// `(−1, 1)² ∖ [0, 1] × [−1, 0]` on the `N × N` grid of its bounding square (N
    /// even); boundary parts `outer` and `reentrant`.
    LShape,
    /// The disk with N rings of triangles; boundary part `circle`.
    Disk {
        /// Centre.
        centre: [f64; 2],
        /// Radius.
        radius: f64,
        /// Whether the boundary cells are curved onto the circle (isoparametric P2
        /// geometry) rather than left as the inscribed polygon.
        curved: bool,
    },
    /// A Gmsh MSH 4.1 mesh; N counts its uniform refinements. Boundary parts are its
    /// physical curve groups.
    Gmsh(PathBuf),
    /// A mesh given whole (a scene file's rectangle of the squares it names); N counts
    /// its uniform refinements, as for a Gmsh file.
    Refined {
        /// The coarsest mesh.
        mesh: Arc<fem_runtime::TriangleMesh>,
        /// Words for reports.
        description: Cow<'static, str>,
    },
    /// A mesh made by a family's own generator (the contact bodies' graded meshes).
    Generated(Generator),
}

/// A family's mesh generator: `build(N, q)` is the mesh for `--mesh-size N` at the load
/// magnitude q (a mesh graded to a contact zone whose width grows with the load).
#[derive(Clone)]
pub struct Generator {
    /// Words for reports.
    pub description: Cow<'static, str>,
    /// What N counts, for messages ("cells per contact half-width b/h").
    pub size_meaning: &'static str,
    /// The largest N it takes: beyond it the mesh alone (built before the memory
    /// estimate can see its cells) would take minutes.
    pub max_size: usize,
    /// The mesh for N.
    pub build: Arc<
        dyn Fn(usize, Option<f64>) -> fem_runtime::Result<fem_runtime::TriangleMesh> + Send + Sync,
    >,
}

impl fmt::Debug for Domain {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.describe())
    }
}

impl Domain {
    /// The unit interval `(0, 1)`.
    pub const UNIT_INTERVAL: Domain = Domain::Interval {
        start: 0.0,
        end: 1.0,
    };

    /// The square `(x0, x0 + side)²` with the N×N×2 mesh.
    pub fn square(x0: f64, side: f64) -> Domain {
        Domain::Rectangle {
            x: [x0, x0 + side],
            y: [x0, x0 + side],
            cells: [1, 1],
            diagonal: Diagonal::Right,
        }
    }

    /// A short description for reports: `square (−2,2)²`, `L-shape …`, the file's path.
    pub fn describe(&self) -> String {
        match self {
            Domain::Interval { start, end } => {
                format!("interval ({}, {})", number(*start), number(*end))
            }
            Domain::Rectangle { x, y, .. } if x[0] == 0.0 && x == y && x[1] == 1.0 => {
                "unit square".into()
            }
            Domain::Rectangle { x, y, .. } if x == y && x[0] == -x[1] => {
                format!("square (−{a},{a})²", a = number(x[1]))
            }
            Domain::Rectangle { x, y, .. } if x == y => {
                format!("square ({},{})²", number(x[0]), number(x[1]))
            }
            Domain::Rectangle { x, y, .. } => format!(
                "rectangle ({},{})×({},{})",
                number(x[0]),
                number(x[1]),
                number(y[0]),
                number(y[1])
            ),
            Domain::LShape => "L-shape (−1,1)² ∖ [0,1]×[−1,0]".into(),
            Domain::Disk { radius, .. } => format!("disk of radius {}", number(*radius)),
            Domain::Gmsh(path) => format!("Gmsh file {}", path.display()),
            Domain::Refined { description, .. } => description.to_string(),
            Domain::Generated(g) => g.description.to_string(),
        }
    }

    /// A point the reports evaluate a deflection at: the centre of a rectangle or disk,
    /// the midpoint of an interval; `None` where a domain has no natural centre.
    pub fn centre(&self) -> Option<Vec<f64>> {
        match self {
            Domain::Interval { start, end } => Some(vec![0.5 * (start + end)]),
            Domain::Rectangle { x, y, .. } => Some(vec![0.5 * (x[0] + x[1]), 0.5 * (y[0] + y[1])]),
            Domain::Disk { centre, .. } => Some(centre.to_vec()),
            _ => None,
        }
    }

    /// The diameter of the domain where it is known before meshing (a rectangle's
    /// longer side, a disk's diameter, an interval's length).
    pub fn size(&self) -> Option<f64> {
        match self {
            Domain::Interval { start, end } => Some(end - start),
            Domain::Rectangle { x, y, .. } => Some((x[1] - x[0]).max(y[1] - y[0])),
            Domain::Disk { radius, .. } => Some(2.0 * radius),
            Domain::LShape => Some(2.0),
            _ => None,
        }
    }

    /// Whether the scene's own geometry is a file's (N then counts refinements).
    pub fn is_file(&self) -> bool {
        matches!(self, Domain::Gmsh(_) | Domain::Refined { .. })
    }
}

/// Shortest decimal text of `x` (the runtime's [`fem_runtime::problem::number`]).
fn number(x: f64) -> String {
    fem_runtime::problem::number(x)
}

/// A part of the boundary.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Part {
    /// The whole boundary.
    All,
    /// The boundary parts of these names (a generator's names, or Gmsh physical names).
    Named(Vec<String>),
}

impl Part {
    /// The part as reports name it: `["all"]` or the names.
    pub fn names(&self) -> Vec<String> {
        match self {
            Part::All => vec!["all".into()],
            Part::Named(names) => names.clone(),
        }
    }

    /// The part of one name.
    pub fn named(name: &str) -> Part {
        Part::Named(vec![name.to_string()])
    }
}

/// How a structure is held on a part of its boundary. The conditions are stated on the
/// model's fields by their roles (docs/mathematics.md §1): the constrained field is the
/// one of the model's `obstacle:` role (the deflection of a beam or plate), the others
/// are its rotations or the displacement of an elastic body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Support {
    /// Every primal field 0, and its normal derivative where the element has one
    /// (Hermite ends, Argyris and Morley edges).
    Clamped,
    /// The simple support. `hard`: the deflection 0 and the rotations' tangential
    /// component too (`w = 0`, `θ·t = 0`); soft: the deflection alone (`w = 0`, θ free),
    /// which leaves a boundary layer in a Mindlin plate. On a Kirchhoff plate the two
    /// are the same (`w = 0` along the edge fixes `∂w/∂t`).
    SimplySupported {
        /// Whether the rotations' tangential component is held too.
        hard: bool,
    },
    /// Nothing held (the natural condition).
    Free,
    /// The model's boundary data: `u = g` (its `boundary:` declaration).
    Data,
    /// A roller: the displacement's component along `normal` (a unit vector) is 0, the
    /// body slides freely across it.
    Roller {
        /// The held direction.
        normal: [f64; 2],
    },
}

impl Support {
    /// The support's name in scene files and reports.
    pub fn name(self) -> String {
        match self {
            Support::Clamped => "clamped".into(),
            Support::SimplySupported { hard: true } => "simply-supported-hard".into(),
            Support::SimplySupported { hard: false } => "simply-supported".into(),
            Support::Free => "free".into(),
            Support::Data => "dirichlet".into(),
            Support::Roller { normal } => {
                format!(
                    "roller along ({}, {})",
                    number(normal[0]),
                    number(normal[1])
                )
            }
        }
    }

    /// The support called `name` (`clamped`, `simply-supported` (soft),
    /// `simply-supported-hard`, `simply-supported-soft`, `free`, `dirichlet`); rollers
    /// take a direction and are read by the scene-file reader.
    pub fn parse(name: &str) -> Option<Support> {
        Some(match name {
            "clamped" => Support::Clamped,
            "simply-supported" | "simply-supported-soft" => {
                Support::SimplySupported { hard: false }
            }
            "simply-supported-hard" => Support::SimplySupported { hard: true },
            "free" => Support::Free,
            "dirichlet" => Support::Data,
            _ => return None,
        })
    }

    /// The names [`Support::parse`] takes.
    pub const NAMES: &'static [&'static str] = &[
        "clamped",
        "simply-supported",
        "simply-supported-hard",
        "free",
        "dirichlet",
    ];
}

/// A support on a part of the boundary.
#[derive(Clone, Debug, PartialEq)]
pub struct PartSupport {
    /// Where.
    pub part: Part,
    /// What.
    pub support: Support,
    /// The scene file's key it was read from (`boundary.dirichlet`), which errors name.
    pub key: Option<Name>,
}

/// The load magnitude `q` of `--load`: the named data are `q` times the scene's fields.
#[derive(Clone, Debug, PartialEq)]
pub struct Load {
    /// The scene's own q.
    pub default: f64,
    /// The data scaled by q (the load `f`, a contact pressure `q`).
    pub scales: Vec<Name>,
    /// What q is called in `list` (`q`, or `P` for a resultant).
    pub symbol: &'static str,
    /// The values q may take.
    pub sign: LoadSign,
}

/// The values a scene's load magnitude q may take.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LoadSign {
    /// Any (the data's sign is the scene's; −q pushes the other way).
    Any,
    /// q ≥ 0: the scene fixes the load's direction.
    NonNegative,
    /// q > 0: a body that only rests on its foundation needs a load to hold it there.
    Positive,
}

/// Largest load magnitude `|q|` a scene accepts: beyond it the norms that certify a
/// solution (`‖A‖∞‖U‖∞` in the KKT residual) may overflow.
pub const MAX_LOAD: f64 = 1e100;

/// An exact solution of a scene: the constrained field (the model's `obstacle:` role),
/// its derivatives and the multiplier where known, and the integrals the reports compare.
#[derive(Clone, Debug, Default)]
pub struct ExactSolution {
    /// `u(x)`.
    pub value: Option<Data>,
    /// `∇u(x)` (`[u', 0]` on intervals).
    pub gradient: Option<Data<[f64; 2]>>,
    /// The Hessian `∇²u(x)`, for plates (`[[u'', 0], [0, 0]]` on intervals).
    pub hessian: Option<Data<[[f64; 2]; 2]>>,
    /// `λ(x)`.
    pub multiplier: Option<Data>,
    /// The scene file's key of `multiplier` where it is not `exact.lambda` (contact's
    /// `exact.pressure`), for messages.
    pub multiplier_key: Option<&'static str>,
    /// `∫ λ` over the scene's own domain.
    pub total_contact_force: Option<f64>,
    /// The measure of the contact set over the scene's own domain: its area on
    /// triangles, its length on an interval.
    pub contact_area: Option<f64>,
    /// The contact intervals of a beam (a point contact as `[x, x]`).
    pub contact_set: Option<Vec<[f64; 2]>>,
}

/// The values a scene is solved at, which an exact solution may depend on.
#[derive(Clone, Debug, Default)]
pub struct Posed {
    /// The load magnitude (`None` where the scene's load is fixed).
    pub load: Option<f64>,
    /// Every parameter of the scene by name, as solved.
    pub parameters: Vec<(Name, f64)>,
}

impl Posed {
    /// The value of parameter `name`, if the scene sets it.
    pub fn parameter(&self, name: &str) -> Option<f64> {
        self.parameters
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| *v)
    }
}

/// An exact solution as a function of the values solved at.
pub type ExactOf = Arc<dyn Fn(&Posed) -> Option<ExactSolution> + Send + Sync>;

/// Where a scene's exact solution is known.
#[derive(Clone, Default)]
pub enum Exact {
    /// Nowhere.
    #[default]
    Unknown,
    /// At the scene's own load only (a scene file's `[exact]`: the contact set is not
    /// linear in the load).
    AtDefaultLoad(ExactSolution),
    /// For every load and parameter it is defined at (`None` elsewhere).
    Of(ExactOf),
}

impl fmt::Debug for Exact {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Exact::Unknown => f.write_str("Unknown"),
            Exact::AtDefaultLoad(e) => f.debug_tuple("AtDefaultLoad").field(e).finish(),
            Exact::Of(_) => f.write_str("Of(..)"),
        }
    }
}

/// A family's own description of a scene, beyond what every scene has: the body and
/// reference of a contact scene, a plate's closed-form deflection. The family that made
/// the scene reads it back by its type ([`Scene::reference`]).
pub type Reference = Arc<dyn Any + Send + Sync>;

/// A scene: what is posed, and how the registry offers it.
#[derive(Clone)]
pub struct Scene {
    /// Its name on the command line.
    pub name: Name,
    /// One line of description.
    pub description: Name,
    /// The family (its registry name).
    pub family: &'static str,
    /// The domain.
    pub domain: Domain,
    /// The default `--mesh-size` N (the beams' `--elements`).
    pub mesh_size: usize,
    /// The model's parameters by their declared names (α and the side `s` are set by
    /// the solve).
    pub parameters: Vec<(Name, f64)>,
    /// The model's data functions by their declared names.
    pub data: Vec<(Name, Data)>,
    /// The load magnitude `--load` scales, where the load is a scaled field.
    pub load: Option<Load>,
    /// Which side of the structure the obstacle is on.
    pub side: ObstacleSide,
    /// Whether the obstacle `ψ` is in place (`false`: the unconstrained problem
    /// `a(u, v) = ℓ(v)`, `--no-obstacle`).
    pub obstacle: bool,
    /// The supports, by boundary part. Where parts overlap the conditions combine: an
    /// edge holds every condition of every support naming it (`free` adds none).
    pub supports: Vec<PartSupport>,
    /// The boundary parts of the model's `facets:` declaration (a contact boundary Γ_C
    /// where the multiplier lives, a loaded part Γ_N), by the model's names.
    pub facets: Vec<(Name, Part)>,
    /// The exact solution, where known.
    pub exact: Exact,
    /// The L² error of the constrained field the scene asks for.
    pub accuracy: Option<f64>,
    /// Solve adaptively to this tolerance, relative to `‖u_h‖_a` (a scene file's `tol`;
    /// `--tol` wins).
    pub tolerance: Option<f64>,
    /// The pairs that discretize it, the default first (empty: every pair of the family).
    pub pairs: Vec<&'static str>,
    /// The studies it hosts.
    pub studies: Vec<&'static str>,
    /// The load q its studies pose where it is not [`Load::default`] (the beams are
    /// solved at q = 1, where they do not touch their obstacles, and studied at q = 100).
    pub study_load: Option<f64>,
    /// The variants its studies run ([`StudyVariant`]); empty: the scene itself.
    pub study_variants: Vec<StudyVariant>,
    /// Whether the default job (`fem-forms` without a command) solves it.
    pub in_default_job: bool,
    /// The family's own description (see [`Reference`]).
    pub reference: Option<Reference>,
    /// The keys a scene file gave its data under, by the model's name (`q` was
    /// `pressure`): errors about a datum name the user's key.
    pub file_keys: Vec<(Name, String)>,
    /// Where the scene is the cheaper neighbour of a richer model's scene
    /// ([`crate::family::Family::cheaper`]), or states a richer model's parameters
    /// ([`crate::family::Family::richer_parameters`]: a Kirchhoff plate's thickness):
    /// that model's parameters (its thickness `t`), from which the solve estimates the
    /// modelling error.
    pub richer: Option<Vec<(Name, f64)>>,
    /// Whether the scene asks for a plate's stress resultants along its boundary
    /// ([`crate::families::edge_resultants`]): the report then gives them, the
    /// Reissner–Mindlin mesh of a tolerance resolves the boundary layer, and the model
    /// choice weighs the Kirchhoff plate's error in them.
    pub edge_resultants: bool,
}

impl fmt::Debug for Scene {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Scene")
            .field("name", &self.name)
            .field("family", &self.family)
            .field("domain", &self.domain)
            .field("parameters", &self.parameters)
            .field("supports", &self.supports)
            .finish_non_exhaustive()
    }
}

/// A change `--support`, `--obstacle` or `--no-obstacle` asks of a scene.
#[derive(Clone, Debug, PartialEq)]
pub enum Adjustment {
    /// Every support of the scene replaced by this one.
    Support(Support),
    /// The obstacle replaced by one the family names.
    Obstacle(String),
    /// No obstacle: the unconstrained problem.
    NoObstacle,
}

/// A variant of a scene that its studies run beside it (or instead: a scene with
/// variants is studied as its variants), e.g. each load of a plate's list, or both
/// supports of a square: applied by [`crate::families::study_variants`].
#[derive(Clone, Debug, PartialEq)]
pub struct StudyVariant {
    /// Its label, appended to the scene's name in titles and file names (`q20`).
    pub label: String,
    /// The load q, where the variant sets one (else the scene's study load).
    pub load: Option<f64>,
    /// The changes the scene's family makes ([`crate::family::Family::adjust`]).
    pub adjustments: Vec<Adjustment>,
}

impl Scene {
    /// A scene of `family` on `domain` with nothing else posed: no parameter, no data,
    /// no support, the obstacle below, no exact solution.
    pub fn new(
        name: impl Into<Name>,
        description: impl Into<Name>,
        family: &'static str,
        domain: Domain,
        mesh_size: usize,
    ) -> Self {
        Self {
            name: name.into(),
            description: description.into(),
            family,
            domain,
            mesh_size,
            parameters: Vec::new(),
            data: Vec::new(),
            load: None,
            side: ObstacleSide::Below,
            obstacle: true,
            supports: Vec::new(),
            facets: Vec::new(),
            exact: Exact::Unknown,
            accuracy: None,
            tolerance: None,
            pairs: Vec::new(),
            studies: Vec::new(),
            study_load: None,
            study_variants: Vec::new(),
            in_default_job: false,
            reference: None,
            file_keys: Vec::new(),
            richer: None,
            edge_resultants: false,
        }
    }

    /// Sets parameter `name` (replacing an earlier value).
    pub fn with_parameter(mut self, name: impl Into<Name>, value: f64) -> Self {
        self.set_parameter(name, value);
        self
    }

    /// Sets parameter `name` (replacing an earlier value).
    pub fn set_parameter(&mut self, name: impl Into<Name>, value: f64) {
        let name = name.into();
        match self.parameters.iter_mut().find(|(n, _)| *n == name) {
            Some(entry) => entry.1 = value,
            None => self.parameters.push((name, value)),
        }
    }

    /// Sets the richer model's parameter `name` ([`Scene::richer`], replacing an
    /// earlier value).
    pub fn set_richer_parameter(&mut self, name: impl Into<Name>, value: f64) {
        let name = name.into();
        let richer = self.richer.get_or_insert_with(Vec::new);
        match richer.iter_mut().find(|(n, _)| *n == name) {
            Some(entry) => entry.1 = value,
            None => richer.push((name, value)),
        }
    }

    /// Whether some part is held by the model's own boundary data (`dirichlet`: `w = g`
    /// for Kirchhoff, `w` and `θ` for Reissner–Mindlin), which names no support shared
    /// by two neighbour models.
    pub fn has_model_boundary_data(&self) -> bool {
        self.supports.iter().any(|s| s.support == Support::Data)
    }

    /// The richer model's parameter `name` ([`Scene::richer`]), if the scene states it.
    pub fn richer_parameter(&self, name: &str) -> Option<f64> {
        self.richer
            .as_ref()?
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| *v)
    }

    /// Sets data function `name` (replacing an earlier one).
    pub fn with_data(mut self, name: impl Into<Name>, data: impl Into<Data>) -> Self {
        self.set_data(name, data.into());
        self
    }

    /// Sets data function `name` (replacing an earlier one).
    pub fn set_data(&mut self, name: impl Into<Name>, data: Data) {
        let name = name.into();
        match self.data.iter_mut().find(|(n, _)| *n == name) {
            Some(entry) => entry.1 = data,
            None => self.data.push((name, data)),
        }
    }

    /// Adds a support on `part`.
    pub fn with_support(mut self, part: Part, support: Support) -> Self {
        self.supports.push(PartSupport {
            part,
            support,
            key: None,
        });
        self
    }

    /// The value of parameter `name`, if the scene sets it.
    pub fn parameter(&self, name: &str) -> Option<f64> {
        self.parameters
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| *v)
    }

    /// The scene posed for a cheaper neighbour model ([`crate::family::Family::cheaper`]):
    /// named `<scene>-<model>`, of `family`, taking `pairs`, with the parameters `keep`
    /// accepts, and this scene's parameters as [`Scene::richer`] (from which its solve
    /// estimates the modelling error); the data, supports, load and obstacle as they are.
    pub fn posed_for_cheaper(
        &self,
        model: &str,
        family: &'static str,
        pairs: Vec<&'static str>,
        keep: impl Fn(&str) -> bool,
    ) -> Scene {
        let mut thin = self.clone();
        thin.name = format!("{}-{model}", self.name).into();
        thin.family = family;
        thin.richer = Some(self.parameters.clone());
        thin.parameters.retain(|(name, _)| keep(name));
        thin.pairs = pairs;
        thin
    }

    /// Data function `name`, if the scene sets it.
    pub fn data_fn(&self, name: &str) -> Option<&Data> {
        self.data.iter().find(|(n, _)| n == name).map(|(_, d)| d)
    }

    /// The family's own description, if it is of type `T`.
    pub fn reference<T: Any>(&self) -> Option<&T> {
        self.reference.as_ref().and_then(|r| r.downcast_ref::<T>())
    }

    /// The load magnitude of a request: `requested` or the scene's own.
    ///
    /// # Errors
    /// A message naming `--load` where the scene's load is fixed, and for a q that is not
    /// finite, beyond ±[`MAX_LOAD`], or negative where the scene fixes the direction.
    pub fn load_magnitude(&self, requested: Option<f64>) -> Result<Option<f64>, String> {
        match (&self.load, requested) {
            (_, Some(q)) if !q.is_finite() => Err(format!("--load {q} must be finite")),
            (_, Some(q)) if q.abs() > MAX_LOAD => Err(format!(
                "--load {q:e} is beyond ±{MAX_LOAD:e}: norms in the solve would overflow double precision"
            )),
            (None, Some(_)) => Err(format!(
                "--load does not apply to `{}`: its load is fixed (not a scaled field)",
                self.name
            )),
            (Some(load), Some(q)) if load.sign == LoadSign::NonNegative && q < 0.0 => {
                Err(format!(
                    "--load {} must be finite and ≥ 0: the scene `{}` fixes the load's direction",
                    number(q),
                    self.name
                ))
            }
            (Some(load), Some(q)) if load.sign == LoadSign::Positive && q <= 0.0 => Err(format!(
                "--load {} must be positive: the body of `{}` only rests on its foundation, a pull lifts it off and nothing holds it then",
                number(q),
                self.name
            )),
            (Some(load), q) => Ok(Some(q.unwrap_or(load.default))),
            (None, None) => Ok(None),
        }
    }

    /// The exact solution at `posed`, where known.
    pub fn exact_at(&self, posed: &Posed) -> Option<ExactSolution> {
        match &self.exact {
            Exact::Unknown => None,
            Exact::AtDefaultLoad(e) => {
                (posed.load == self.load.as_ref().map(|l| l.default)).then(|| e.clone())
            }
            Exact::Of(f) => f(posed),
        }
    }

    /// The scene on the Gmsh mesh `path` in place of its own domain. The exact solution's
    /// field stays (it is the solution wherever its boundary values are imposed); its
    /// integrals (the contact force and area) belong to the scene's own domain and go.
    pub fn on_mesh_file(mut self, path: PathBuf) -> Self {
        self.domain = Domain::Gmsh(path);
        let strip = |mut e: ExactSolution| {
            e.total_contact_force = None;
            e.contact_area = None;
            e.contact_set = None;
            e
        };
        self.exact = match std::mem::take(&mut self.exact) {
            Exact::Unknown => Exact::Unknown,
            Exact::AtDefaultLoad(e) => Exact::AtDefaultLoad(strip(e)),
            Exact::Of(f) => Exact::Of(Arc::new(move |posed: &Posed| f(posed).map(strip))),
        };
        self
    }

    /// Whether the scene's exact solution is dropped at `posed` because it holds at the
    /// scene's own load only.
    pub fn exact_dropped_at(&self, posed: &Posed) -> bool {
        matches!(self.exact, Exact::AtDefaultLoad(_)) && self.exact_at(posed).is_none()
    }
}

impl Scene {
    /// The key under `[data]` of the model's data function `name`: the one the scene's
    /// file gave it under, else its ASCII spelling ([`data_key`]).
    pub fn file_key(&self, name: &str) -> String {
        self.file_keys
            .iter()
            .find(|(n, _)| n == name)
            .map_or_else(|| data_key(name), |(_, key)| key.clone())
    }
}

/// The key under `[data]` of a scene file for the model's data function `name`: its
/// ASCII spelling (`ψ` is `psi`).
pub fn data_key(name: &str) -> String {
    match name {
        "ψ" => "psi".into(),
        "λ" => "lambda".into(),
        other => other.into(),
    }
}
