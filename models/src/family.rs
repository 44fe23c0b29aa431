//! The registry: every model family, its element pairs, the options it accepts and its
//! built-in scenes. A family is data plus its model files: a [`Family`] value, one
//! [`Pair`] per model, and where it has any, its own quantities ([`crate::run::Quantities`]).
//! The command line's `list`, `solve` and `study` go through [`families`] alone.

use crate::report::{Outcome, Settings};
use crate::scene::{Adjustment, LoadSign, Scene, Support};
use fem_runtime::problem::MemoryModel;
use fem_runtime::stabilization::Alpha;
use fem_runtime::Error;

type Result<T, E = Error> = std::result::Result<T, E>;

/// An option of `solve` a family may accept. Each family lists those that mean something
/// for it; any other given option is an error naming it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Opt {
    /// `--elements N` (the beams' size).
    Elements,
    /// `--mesh-size N`.
    MeshSize,
    /// `--msh FILE`: the scene on a Gmsh mesh.
    Msh,
    /// `--vtk`: a `.vtu` of the fields.
    Vtk,
    /// `--load q`.
    Load,
    /// `--thickness t`.
    Thickness,
    /// `--alpha α`.
    Alpha,
    /// `--pair NAME`.
    Pair,
    /// `--solver pdas|clarabel`.
    Solver,
    /// `--cold`.
    Cold,
    /// `--linear-solver auto|direct|multigrid`.
    LinearSolver,
    /// `--refinement k`.
    Refinement,
    /// `--support NAME`.
    Support,
    /// `--obstacle NAME`.
    Obstacle,
    /// `--no-obstacle`.
    NoObstacle,
    /// `--plot`.
    Plot,
    /// `--tol T`: solve adaptively to a relative tolerance.
    Tol,
    /// `--marking dorfler|max`.
    Marking,
    /// `--theta θ`: the marking parameter.
    Theta,
    /// `--edge-resultants`: a plate's moments and shear force along its boundary.
    EdgeResultants,
}

impl Opt {
    /// Every option.
    pub const ALL: [Opt; 20] = [
        Opt::Elements,
        Opt::MeshSize,
        Opt::Msh,
        Opt::Vtk,
        Opt::Load,
        Opt::Thickness,
        Opt::Alpha,
        Opt::Pair,
        Opt::Solver,
        Opt::Cold,
        Opt::LinearSolver,
        Opt::Refinement,
        Opt::Support,
        Opt::Obstacle,
        Opt::NoObstacle,
        Opt::Plot,
        Opt::Tol,
        Opt::Marking,
        Opt::Theta,
        Opt::EdgeResultants,
    ];

    /// Its spelling on the command line.
    pub fn flag(self) -> &'static str {
        match self {
            Opt::Elements => "--elements",
            Opt::MeshSize => "--mesh-size",
            Opt::Msh => "--msh",
            Opt::Vtk => "--vtk",
            Opt::Load => "--load",
            Opt::Thickness => "--thickness",
            Opt::Alpha => "--alpha",
            Opt::Pair => "--pair",
            Opt::Solver => "--solver",
            Opt::Cold => "--cold",
            Opt::LinearSolver => "--linear-solver",
            Opt::Refinement => "--refinement",
            Opt::Support => "--support",
            Opt::Obstacle => "--obstacle",
            Opt::NoObstacle => "--no-obstacle",
            Opt::Plot => "--plot",
            Opt::Tol => "--tol",
            Opt::Marking => "--marking",
            Opt::Theta => "--theta",
            Opt::EdgeResultants => "--edge-resultants",
        }
    }
}

/// A pair's solve: [`crate::run::run`] for its model, mesh kind and family.
pub type PairSolve = fn(&Pair, &Scene, &Settings) -> Result<Outcome>;

/// One element pair of a family: a model file's model and how it is solved.
pub struct Pair {
    /// Its name on the command line (`p2-p0`).
    pub name: &'static str,
    /// One line for `list`.
    pub note: &'static str,
    /// The α rule where `--alpha` is not given.
    pub alpha: Alpha,
    /// α where the rule's `C_I` vanishes.
    pub alpha_when_zero: f64,
    /// The memory a solve needs (`None`: [`MemoryModel::of_model`]).
    pub memory: Option<MemoryModel>,
    /// The nodal method: the constraint at the nodes, no multiplier space to stabilize
    /// (`--alpha` and `--solver` do not apply).
    pub nodal: bool,
    /// Parameters of the discretization, not of the scene (the Stenberg weight's β), by
    /// the model's names; a scene's value of the same name wins.
    pub parameters: &'static [(&'static str, f64)],
    /// The solve.
    pub solve: PairSolve,
}

impl std::fmt::Debug for Pair {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Pair").field("name", &self.name).finish()
    }
}

/// An error of a scene file: the field at fault (`material.young`) and the message.
pub type FieldError = (String, String);

/// A finite number of a scene file's field (a float or an integer), `-0` read as 0.
pub fn finite(value: &toml::Value) -> Option<f64> {
    value
        .as_float()
        .or_else(|| value.as_integer().map(|i| i as f64))
        .filter(|v| v.is_finite())
        .map(|v| v + 0.0)
}

/// What the locking study compares (see [`Family::locking`]): the report's quantity
/// `quantity` against its value in the limit t → 0.
#[derive(Clone, Copy, Debug)]
pub struct Locking {
    /// The report's key of the quantity (`centre_deflection`).
    pub quantity: &'static str,
    /// The quantity in words, for charts (`w_h(centre)`).
    pub quantity_words: &'static str,
    /// Where its limit t → 0 comes from.
    pub limit: Limit,
    /// The limit model's name (`Kirchhoff`).
    pub limit_words: &'static str,
}

/// The value of a [`Locking`] quantity in the limit t → 0.
#[derive(Clone, Copy, Debug)]
pub enum Limit {
    /// A closed form each solve reports under this key (`kirchhoff_reference`).
    Reported(&'static str),
    /// The same quantity of another scene, the thin model's (the Euler–Bernoulli beam with
    /// a Timoshenko scene's obstacle and load), solved once on a mesh sixteen times finer
    /// than the study's finest; `None` where the scene has no such limit scene.
    Scene(fn(&Scene) -> Option<Scene>),
}

/// The keys of a scene file a family reads itself: its `[material]`, and the
/// `[parameters]` that are not the model's (a contact direction), taken before the
/// reader maps the rest onto the model's names.
pub struct FileKeys<'a> {
    /// `[material]`, where the file has one.
    pub material: Option<&'a toml::Table>,
    /// `[parameters]`: the family removes the keys it reads.
    pub parameters: &'a mut toml::Table,
}

/// A model family: its pairs, options and scenes.
pub trait Family: Sync {
    /// Its name (`beam`, `membrane`, `plate`).
    fn name(&self) -> &'static str;

    /// One line for `list`.
    fn description(&self) -> &'static str;

    /// Its pairs; each scene takes those it names (all where it names none).
    fn pairs(&self) -> &'static [Pair];

    /// The options of `solve` that mean something for it.
    fn options(&self) -> &'static [Opt];

    /// Its built-in scenes.
    fn scenes(&self) -> Vec<Scene>;

    /// The names a scene file may use for the model's parameters and data, beside the
    /// model's own (`thickness` for `t`): `(alias, model name)`.
    fn aliases(&self) -> &'static [(&'static str, &'static str)] {
        &[]
    }

    /// The dimension of its domains: 1 (beams on intervals) or 2 (triangle meshes).
    fn dimension(&self) -> usize {
        2
    }

    /// The support a scene file without `[boundary]` keys has on its whole boundary,
    /// with the key its errors name (the membrane's `u = g`); `None`: free.
    fn default_support(&self) -> Option<(Support, &'static str)> {
        None
    }

    /// The `[boundary]` keys of a scene file that name the model's facet parts (the
    /// `facets:` of its model file), as `(key, facet name)`: contact's `contact = …` for
    /// Γ_C. Each is required when the family has any.
    fn facet_keys(&self) -> &'static [(&'static str, &'static str)] {
        &[]
    }

    /// The data the load magnitude scales (`data.load`, `--load`), by the model's name,
    /// and the signs it may take.
    fn scaled_load(&self) -> (&'static str, LoadSign) {
        ("f", LoadSign::Any)
    }

    /// The family's own error measure of the multiplier, where it has one, as the
    /// report's key and words (contact's relative L² error of the pressure): what a
    /// scene's `accuracy` asks of, and what the studies chart as the multiplier's error.
    fn error_measure(&self) -> Option<(&'static str, &'static str)> {
        None
    }

    /// Other spellings of its pairs' names, as `(alias, name)` (the membrane's
    /// `p2-p1disc` for `p2-p1d`).
    fn pair_aliases(&self) -> &'static [(&'static str, &'static str)] {
        &[]
    }

    /// The family's measure of locking, where it has a thickness `t` whose limit t → 0 is
    /// a thinner model: the report's key of a quantity and of its value in that limit
    /// (the Reissner–Mindlin plate's centre deflection against Kirchhoff's), what the
    /// locking study compares as t falls.
    fn locking(&self) -> Option<Locking> {
        None
    }

    /// The model a scene of the family poses, in words (`Timoshenko`, `Kirchhoff`): what
    /// a report's `chosen_model` names.
    fn model_words(&self, scene: &Scene) -> &'static str {
        let _ = scene;
        self.name()
    }

    /// The cheaper neighbour of `scene`'s model, where the family declares one: the
    /// same scene posed for the thinner model (Euler–Bernoulli for a Timoshenko beam,
    /// Kirchhoff for a Reissner–Mindlin plate), possibly of another family, its
    /// [`Scene::richer`] set to `scene`'s parameters so that its solve reports the
    /// modelling estimate (`modelling_estimate`). [`crate::choice`] weighs it against
    /// `scene` for a tolerance.
    fn cheaper(&self, scene: &Scene) -> Option<Scene> {
        let _ = scene;
        None
    }

    /// The richer neighbour of `scene`'s model, where the family declares one and the
    /// scene states what it needs ([`Family::richer_parameters`]): the same scene posed
    /// for the thicker model (Reissner–Mindlin for a Kirchhoff plate given a thickness),
    /// possibly of another family. `scene`'s own solves then report their modelling
    /// estimate against it, and [`crate::choice`] weighs the two for a tolerance.
    fn richer(&self, scene: &Scene) -> Option<Scene> {
        let _ = scene;
        None
    }

    /// The richer model's parameters that a scene of this family may state beside its
    /// own model's (the Kirchhoff plate's thickness `t` and shear correction `κ`): they
    /// pose no term of its model; kept in [`Scene::richer`], they give the modelling
    /// estimate and pose [`Family::richer`].
    fn richer_parameters(&self) -> &'static [&'static str] {
        &[]
    }

    /// The `[exact]` key of the quantity a scene file's `accuracy` is measured on (`u`;
    /// contact's `pressure`).
    fn accuracy_key(&self) -> &'static str {
        "u"
    }

    /// Reads the scene file's keys of the family's own ([`FileKeys`]) into `scene`. By
    /// default there are none: a `[material]` is refused.
    ///
    /// # Errors
    /// The field at fault and why.
    fn read_file(&self, keys: FileKeys<'_>, scene: &mut Scene) -> Result<(), FieldError> {
        let _ = scene;
        match keys.material {
            Some(_) => Err((
                "material".into(),
                format!(
                    "the {} family takes no [material]: its parameters go under [parameters] by the model's names",
                    self.name()
                ),
            )),
            None => Ok(()),
        }
    }

    /// Checks a scene read from a file as a whole, where the family knows more than the
    /// reader (contact: its parts on the mesh, the data on them, the load's direction).
    ///
    /// # Errors
    /// The field at fault and why.
    fn check_file(&self, scene: &Scene) -> Result<(), FieldError> {
        let _ = scene;
        Ok(())
    }

    /// Applies `adjustment` to `scene`: by default a support replaces every support of
    /// the scene and `--no-obstacle` removes the obstacle; other obstacles are the
    /// family's to name.
    ///
    /// # Errors
    /// An adjustment the family does not take, with the reason.
    fn adjust(&self, scene: &mut Scene, adjustment: &Adjustment) -> Result<()> {
        match adjustment {
            Adjustment::Support(support) => {
                for s in &mut scene.supports {
                    s.support = *support;
                }
                Ok(())
            }
            Adjustment::NoObstacle => {
                scene.obstacle = false;
                Ok(())
            }
            Adjustment::Obstacle(name) => Err(Error::Input(format!(
                "--obstacle {name} does not apply: the {} family names no obstacles",
                self.name()
            ))),
        }
    }
}
