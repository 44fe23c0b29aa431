//! What the membrane tests share: a membrane data set's solve through the one pipeline,
//! and the pieces of its discrete problem (meshes, coefficients, solver options) for the
//! tests that reach below the solve (the nested and multigrid solvers, the inf-sup
//! reference).
#![allow(dead_code)]

use fem_forms::models::data::Data;
use fem_forms::models::families::{self, membrane::membrane_scene, membrane::SMOOTHING_SWEEPS};
use fem_forms::models::geometry::Fields;
use fem_forms::models::membrane_scenes::{self, Domain, MembraneScene};
use fem_forms::models::report::{Outcome, Settings};
use fem_forms::obstacle::{ObstacleOptions, VariationalSolver};
use fem_forms::{Coefficients, Diagonal, Model, Result, TriangleMesh};

/// The built-in membrane data set `name`.
pub fn scene(name: &str) -> MembraneScene {
    membrane_scenes::membrane_scene(name).expect("a membrane scene")
}

/// The settings of a solve with `pair` at N = `n`.
pub fn settings(pair: &str, n: usize) -> Settings {
    Settings {
        pair: Some(pair.into()),
        mesh_size: Some(n),
        ..Settings::default()
    }
}

/// `scene` solved with `settings` through the one pipeline.
pub fn solve(scene: &MembraneScene, settings: &Settings) -> Result<Outcome> {
    families::solve(&membrane_scene(scene), settings)
}

/// The vertex values of the constrained field u_h.
pub fn u(outcome: &Outcome) -> &[f64] {
    field(outcome, "u")
}

/// The cell values of the multiplier λ_h (at the centroids).
pub fn lambda(outcome: &Outcome) -> &[f64] {
    field(outcome, "lambda")
}

fn field<'a>(outcome: &'a Outcome, name: &str) -> &'a [f64] {
    let Fields::Triangles { vertex, cell, .. } = &outcome.fields else {
        panic!("a membrane solve")
    };
    vertex
        .iter()
        .chain(cell)
        .find(|(n, _)| *n == name)
        .map(|(_, v)| v.as_slice())
        .unwrap_or_else(|| panic!("no field {name}"))
}

/// The structured N×N×2 mesh of a built-in data set (the L-shape's of N/2 per quadrant).
pub fn mesh(scene: &MembraneScene, n: usize) -> TriangleMesh {
    match &scene.domain {
        &Domain::Square(a) => TriangleMesh::rectangle(-a, a, -a, a, n, n, Diagonal::Right),
        Domain::LShape => TriangleMesh::l_shape(n / 2),
        Domain::File(path) => panic!("{} has no structured mesh", path.display()),
    }
    .unwrap()
}

/// The load f (the scene's load field at its own q), the obstacle ψ and the boundary
/// data g of a data set.
pub struct SceneData {
    /// f: the scene's load field times its load scale.
    pub load: Data,
    /// ψ.
    pub obstacle: Data,
    /// g, the Dirichlet data.
    pub boundary: Data,
}

impl SceneData {
    /// The data of `scene` at its own load.
    pub fn new(scene: &MembraneScene) -> Self {
        let load = match scene.load_scale {
            Some(q) => {
                let shape = scene.load.clone();
                Data::shared(move |x| q * shape.at(x))
            }
            None => scene.load.clone(),
        };
        Self {
            load,
            obstacle: scene.obstacle.clone(),
            boundary: scene.boundary.clone(),
        }
    }

    /// The coefficients of a membrane model: α, and the data f, ψ, g.
    pub fn coefficients<M: Model>(&self, alpha: f64) -> Coefficients<'_> {
        Coefficients::new::<M>(
            &[("α", alpha)],
            &[
                ("f", self.load.as_data_fn()),
                ("ψ", self.obstacle.as_data_fn()),
                ("g", self.boundary.as_data_fn()),
            ],
        )
        .unwrap()
    }
}

/// The membrane family's solver options: no iterative refinement of the Newton
/// directions, Gauss–Seidel sweeps for the first direction of a nested level.
pub fn options(solver: VariationalSolver) -> ObstacleOptions {
    let defaults = ObstacleOptions::default();
    ObstacleOptions {
        solver,
        newton: fem_forms::lcp::NewtonOptions {
            refinement_steps: 0,
            smoothing_sweeps: SMOOTHING_SWEEPS,
            ..defaults.newton
        },
        ..defaults
    }
}

/// The family's α on `mesh` for model `M`: ½/C_I (the runtime's fallback where C_I = 0).
pub fn alpha<M: Model>(mesh: &TriangleMesh) -> f64 {
    let c_i = fem_forms::stabilization::inverse_constant::<M, _>(mesh, &vec![0.0; M::PARAMS.len()])
        .unwrap();
    if c_i > 0.0 {
        0.5 / c_i
    } else {
        fem_forms::problem::ALPHA_WHEN_CI_VANISHES
    }
}
