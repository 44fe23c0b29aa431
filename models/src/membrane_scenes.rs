//! The membrane scenes (docs/mathematics.md §2): domain, load, obstacle and boundary data, and the
//! exact solution where one is known.

use crate::data::Data;
use std::borrow::Cow;
use std::path::PathBuf;

/// The domain of a membrane scene.
#[derive(Clone, Debug, PartialEq)]
pub enum Domain {
    /// The square `(−a, a)²` (structured N×N×2 meshes).
    Square(f64),
    /// `(−1, 1)² ∖ [0, 1] × [−1, 0]` (structured meshes).
    LShape,
    /// A Gmsh MSH 4.1 file; `--mesh-size` counts its uniform refinements.
    File(PathBuf),
}

impl Domain {
    /// A short description for reports: `(−2,2)²`, `L-shape`, or the file's path.
    pub fn describe(&self) -> String {
        match self {
            Domain::Square(a) => format!("square (−{a},{a})²"),
            Domain::LShape => "L-shape (−1,1)² ∖ [0,1]×[−1,0]".into(),
            Domain::File(path) => format!("Gmsh file {}", path.display()),
        }
    }
}

/// Where a membrane scene holds `u = g`; on the rest of the boundary the condition is
/// the natural one, `∂u/∂n = 0` (the membrane's weak form `∫ ∇u·∇v` has no boundary
/// term, and its stabilization works cell by cell, so nothing else changes).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum DirichletParts {
    /// The whole boundary.
    #[default]
    All,
    /// The boundary parts of these names: Gmsh physical names of curve groups, or the
    /// names the generators give their sides (the square: `bottom`, `right`, `top`,
    /// `left`; the L-shape: `outer`, `reentrant`).
    Named(Vec<String>),
}

impl DirichletParts {
    /// The part as reports name it: `["all"]` or the names.
    pub fn names(&self) -> Vec<String> {
        match self {
            DirichletParts::All => vec!["all".into()],
            DirichletParts::Named(names) => names.clone(),
        }
    }
}

/// A membrane scene's exact solution.
#[derive(Clone, Debug)]
pub struct ExactMembrane {
    /// `u(x)`.
    pub u: Data,
    /// `∇u(x)`.
    pub gradient: Data<[f64; 2]>,
    /// `λ(x)`, where known.
    pub multiplier: Option<Data>,
    /// `∫ λ` over the scene's own domain, where known.
    pub total_contact_force: Option<f64>,
    /// The area of the contact set in the scene's own domain, where known.
    pub contact_area: Option<f64>,
}

/// Where a scene's exact solution is known.
#[derive(Clone, Debug)]
pub enum Exact {
    /// No exact solution.
    Unknown,
    /// Known at the scene's own load (the default `--load`) only.
    AtDefaultLoad(ExactMembrane),
    /// Known for every load magnitude q ≥ 0 (a load that presses onto the obstacle; a
    /// negative q lifts the membrane off and the formula no longer holds).
    OfLoad(fn(f64) -> ExactMembrane),
}

/// The exact solution of the radial problem.
pub const RADIAL_EXACT: ExactMembrane = ExactMembrane {
    u: Data::Fn(radial_u),
    gradient: Data::Fn(radial_gradient),
    multiplier: Some(Data::Fn(radial_multiplier)),
    total_contact_force: Some(2.0 * std::f64::consts::PI * RADIAL_A),
    contact_area: Some(std::f64::consts::PI * RADIAL_R * RADIAL_R),
};

/// A membrane scene.
///
/// The load is `f = q · load(x)` where the scene's load is a scaled field
/// (`load_scale = Some(q₀)`, q₀ the default of `--load`); a scene whose f is fixed
/// (`load_scale = None`, e.g. the radial problem whose exact solution needs f = 0) takes
/// no `--load`.
#[derive(Clone, Debug)]
pub struct MembraneScene {
    /// Its name on the command line.
    pub name: Cow<'static, str>,
    /// One line of description.
    pub description: Cow<'static, str>,
    /// The domain.
    pub domain: Domain,
    /// The load field: the shape `f̂` scaled by q (or f itself where `load_scale` is None).
    pub load: Data,
    /// The default load magnitude q₀ where the load is a scaled field.
    pub load_scale: Option<f64>,
    /// The obstacle `ψ(x)` (from below: `u ≥ ψ`).
    pub obstacle: Data,
    /// The boundary data `g(x)` (u = g on the Dirichlet part).
    pub boundary: Data,
    /// Where u = g holds (the rest of the boundary: ∂u/∂n = 0).
    pub dirichlet: DirichletParts,
    /// The accuracy the scene asks for: the L² error of u (estimated where no exact
    /// solution is known).
    pub target_l2: f64,
    /// The exact solution, where one is known.
    pub exact: Exact,
}

/// Largest load magnitude `|q|` a built-in scene accepts, for membranes and beams alike:
/// beyond it the norms that certify a solution (`‖A‖∞‖U‖∞` in the KKT residual) may
/// overflow. Loads below it that dwarf the obstacle are caught after the solve, by the
/// rounding of the contact rows (fem_runtime `Lcp::primal_rounding`).
pub const MAX_LOAD: f64 = 1e100;

impl MembraneScene {
    /// The load magnitude q of a request (`None`: the scene's own): an error naming
    /// `--load` when the scene's load is not a scaled field, or q is not finite.
    pub fn load_magnitude(&self, requested: Option<f64>) -> Result<Option<f64>, String> {
        match (self.load_scale, requested) {
            (_, Some(q)) if !q.is_finite() => Err(format!("--load {q} must be finite")),
            (_, Some(q)) if q.abs() > MAX_LOAD => Err(format!(
                "--load {q:e} is beyond ±{MAX_LOAD:e}: norms in the solve would overflow double precision"
            )),
            (None, Some(_)) => Err(format!(
                "--load does not apply to `{}`: its load f is fixed (not a scaled field)",
                self.name
            )),
            (Some(q0), q) => Ok(Some(q.unwrap_or(q0))),
            (None, None) => Ok(None),
        }
    }

    /// The exact solution at load magnitude `q` (`None` for a scene without scaled
    /// load), where known.
    pub fn exact_at(&self, q: Option<f64>) -> Option<ExactMembrane> {
        match &self.exact {
            Exact::Unknown => None,
            Exact::AtDefaultLoad(e) => (q == self.load_scale).then(|| e.clone()),
            Exact::OfLoad(f) => {
                let q = q.or(self.load_scale).unwrap_or(1.0);
                (q >= 0.0).then(|| f(q))
            }
        }
    }
}

/// An independent solver's errors on the radial problem: PETSc's SNES tutorial ex9
/// (Bueler's obstacle problem, p4pdes), PETSc 3.18, `ex9 -snes_type vinewtonrsls
/// -snes_grid_sequence K -pc_type mg` with K = 2, 3, 4, printed `av |u-uexact|` and
/// `|u-uexact|_inf` on the 17², 33² and 65² grids: (N, mean, max) for the N×N right-diagonal
/// mesh, whose nodal P1 method (`p1-nodal`) is ex9's 5-point scheme.
pub const PETSC_EX9_ERRORS: [(usize, f64, f64); 3] = [
    (16, 2.707e-3, 1.428e-2),
    (32, 8.182e-4, 5.747e-3),
    (64, 9.818e-5, 5.991e-4),
];

/// The free-boundary radius `r*` of the radial problem: `r*²(ln 2 − ln r*) = 1 − r*²`.
pub const RADIAL_R: f64 = 0.697965148223374;
/// `A = r*²/√(1 − r*²)`.
pub const RADIAL_A: f64 = 0.680259411891717;
/// `B = A ln 2`.
pub const RADIAL_B: f64 = 0.471519893402110;

fn radius(x: &[f64]) -> f64 {
    // not `hypot`: the error norms evaluate this at every quadrature point of every cell,
    // and glibc's hypot (careful about overflow that |x| ≤ 2 cannot reach) took a tenth
    // of a whole membrane-radial run at 524k triangles
    (x[0] * x[0] + x[1] * x[1]).sqrt()
}

/// The radial obstacle `ψ = √(1 − r²)` for `r ≤ 1`, `−1` outside.
pub fn radial_obstacle(x: &[f64]) -> f64 {
    let r = radius(x);
    if r <= 1.0 {
        (1.0 - r * r).sqrt()
    } else {
        -1.0
    }
}

/// The exact radial solution `u`: `ψ` for `r ≤ r*`, `−A ln r + B` outside.
pub fn radial_u(x: &[f64]) -> f64 {
    let r = radius(x);
    if r <= RADIAL_R {
        (1.0 - r * r).sqrt()
    } else {
        -RADIAL_A * r.ln() + RADIAL_B
    }
}

/// `∇u` of the exact radial solution.
pub fn radial_gradient(x: &[f64]) -> [f64; 2] {
    let r = radius(x);
    // dU/dr divided by r, so that ∇u = (dU/dr / r)·x
    let radial = if r <= RADIAL_R {
        -1.0 / (1.0 - r * r).sqrt()
    } else {
        -RADIAL_A / (r * r)
    };
    [radial * x[0], radial * x[1]]
}

/// The exact multiplier `λ = (2 − r²)/(1 − r²)^{3/2}` on `r < r*`, 0 outside.
pub fn radial_multiplier(x: &[f64]) -> f64 {
    let r = radius(x);
    if r < RADIAL_R {
        // t·√t, not `powf(1.5)`: the error norms call this at every quadrature point
        let t = 1.0 - r * r;
        (2.0 - r * r) / (t * t.sqrt())
    } else {
        0.0
    }
}

fn zero(_: &[f64]) -> f64 {
    0.0
}

fn zero_gradient(_: &[f64]) -> [f64; 2] {
    [0.0, 0.0]
}

fn minus_one(_: &[f64]) -> f64 {
    -1.0
}

/// The flat scene's exact solution at load q: u = 0, λ = q on all of (−2,2)².
fn flat_exact(q: f64) -> ExactMembrane {
    ExactMembrane {
        u: Data::Fn(zero),
        gradient: Data::Fn(zero_gradient),
        multiplier: Some(Data::shared(move |_| q)),
        total_contact_force: Some(16.0 * q),
        contact_area: Some(16.0),
    }
}

/// The sign test of docs/mathematics.md §1 as a scene: ψ = 0, g = 0 and f = −q (q = 3 by default)
/// pressing everywhere onto the obstacle, so u = 0, λ = q, ∫λ = 16q and the contact is
/// the whole (−2,2)². Not among the default scenes: it checks signs, not accuracy.
pub const MEMBRANE_FLAT: MembraneScene = MembraneScene {
    name: Cow::Borrowed("membrane-flat"),
    description: Cow::Borrowed(
        "membrane on (−2,2)² pressed flat onto ψ = 0 by f = −q, q = 3 (exact: u = 0, λ = q)",
    ),
    domain: Domain::Square(2.0),
    load: Data::Fn(minus_one),
    load_scale: Some(3.0),
    obstacle: Data::Fn(zero),
    boundary: Data::Fn(zero),
    dirichlet: DirichletParts::All,
    target_l2: 1e-3,
    exact: Exact::OfLoad(flat_exact),
};

/// A tilted, off-centre paraboloid below the L-shaped membrane: not symmetric about
/// any axis of the domain.
fn lshape_obstacle(x: &[f64]) -> f64 {
    -0.05 - 0.6 * ((x[0] + 0.35).powi(2) + 0.5 * (x[1] - 0.4).powi(2)) + 0.1 * x[0]
}

/// Every membrane scene.
pub const MEMBRANE_SCENES: [MembraneScene; 2] = [
    MembraneScene {
        name: Cow::Borrowed("membrane-radial"),
        description: Cow::Borrowed("membrane on (−2,2)² over the hemisphere ψ = √(1−r²), f = 0, exact solution (docs/mathematics.md §2)"),
        domain: Domain::Square(2.0),
        load: Data::Fn(zero),
        load_scale: None,
        obstacle: Data::Fn(radial_obstacle),
        boundary: Data::Fn(radial_u),
        dirichlet: DirichletParts::All,
        target_l2: 1e-3,
        exact: Exact::AtDefaultLoad(RADIAL_EXACT),
    },
    MembraneScene {
        name: Cow::Borrowed("membrane-lshape"),
        description: Cow::Borrowed("L-shaped membrane, u = 0 on ∂Ω, f = −q, q = 12, pressed onto a tilted off-centre paraboloid"),
        domain: Domain::LShape,
        load: Data::Fn(minus_one),
        load_scale: Some(12.0),
        obstacle: Data::Fn(lshape_obstacle),
        boundary: Data::Fn(zero),
        dirichlet: DirichletParts::All,
        target_l2: 1e-3,
        exact: Exact::Unknown,
    },
];

/// The membrane scene called `name` (the default ones and `membrane-flat`).
pub fn membrane_scene(name: &str) -> Option<MembraneScene> {
    MEMBRANE_SCENES
        .iter()
        .chain([&MEMBRANE_FLAT])
        .find(|s| s.name == name)
        .cloned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_radial_constants_solve_their_equations() {
        let r: f64 = RADIAL_R;
        assert!((r * r * (2f64.ln() - r.ln()) - (1.0 - r * r)).abs() < 1e-14);
        assert!((RADIAL_A - r * r / (1.0 - r * r).sqrt()).abs() < 1e-14);
        assert!((RADIAL_B - RADIAL_A * 2f64.ln()).abs() < 1e-14);
        // u and ∂u/∂r are continuous at r*, and u ≥ ψ everywhere
        let inside = [r - 1e-9, 0.0];
        let outside = [r + 1e-9, 0.0];
        assert!((radial_u(&inside) - radial_u(&outside)).abs() < 1e-8);
        assert!((radial_gradient(&inside)[0] - radial_gradient(&outside)[0]).abs() < 1e-6);
        for i in 0..400 {
            let x = [-2.0 + 4.0 * i as f64 / 399.0, 0.3];
            assert!(radial_u(&x) >= radial_obstacle(&x) - 1e-15);
        }
    }

    #[test]
    fn obstacles_lie_below_the_boundary_data() {
        for scene in MEMBRANE_SCENES {
            for i in 0..=100 {
                let t = -1.0 + 2.0 * i as f64 / 100.0;
                let a = match scene.domain {
                    Domain::Square(a) => a,
                    Domain::LShape => 1.0,
                    Domain::File(_) => unreachable!("the built-in scenes are structured"),
                };
                for x in [[a * t, -a], [a * t, a], [-a, a * t], [a, a * t]] {
                    assert!(
                        scene.obstacle.at(&x) < scene.boundary.at(&x),
                        "{}",
                        scene.name
                    );
                }
            }
        }
    }
}
