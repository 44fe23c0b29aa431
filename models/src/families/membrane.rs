//! Membranes on triangle meshes (structured or Gmsh): `u = g` on chosen boundary parts,
//! `∂u/∂n = 0` on the rest, the obstacle `u ≥ ψ` (docs/mathematics.md §2). Three
//! stabilized pairs and the nodal method (`p1-nodal`, no multiplier space). The family
//! has no quantity of its own: the report is the runtime's.

use crate::family::{Family, Opt, Pair, PairSolve};
use crate::membrane_scenes::{self, DirichletParts, MembraneScene};
use crate::run::{run, Quantities, Settings};
use crate::scene::{Domain, Exact, ExactSolution, Load, Part, Posed, Scene, Support};
use crate::{membrane_p1, membrane_p1_p0, membrane_p2_p0, membrane_p2_p1disc};
use fem_runtime::lcp::NewtonOptions;
use fem_runtime::obstacle::ObstacleOptions;
use fem_runtime::problem::{MemoryModel, ALPHA_WHEN_CI_VANISHES};
use fem_runtime::stabilization::Alpha;
use fem_runtime::TriangleMesh;
use std::sync::Arc;

/// The membrane family.
pub struct Membranes;

/// The registry's membrane family.
pub static MEMBRANES: Membranes = Membranes;

/// Gauss–Seidel sweeps that replace the first Newton factorization on each nested level
/// (see [`NewtonOptions::smoothing_sweeps`]).
pub const SMOOTHING_SWEEPS: usize = 8;

/// A pair with its measured peak memory per triangle (membrane-radial, 2026-12-01: p1-p0
/// 1.2 kB at 2.1M and 1.3 kB at 8.4M triangles, p1-nodal 0.4 kB, p2-p0 4.3 kB at 131k
/// and 4.7 kB at 524k, p2-p1disc 5.6 kB, growing with the factor's fill; the figures
/// leave room for that growth).
const fn pair(
    name: &'static str,
    note: &'static str,
    bytes_per_triangle: f64,
    nodal: bool,
    solve: PairSolve,
) -> Pair {
    Pair {
        name,
        note,
        alpha: Alpha::FromInverseConstant(0.5),
        alpha_when_zero: ALPHA_WHEN_CI_VANISHES,
        memory: Some(MemoryModel::per_cell(bytes_per_triangle)),
        nodal,
        parameters: &[],
        solve,
    }
}

static PAIRS: [Pair; 4] = [
    pair(
        "p2-p0",
        "u ∈ P2, λ ∈ P0, stabilized",
        6.0e3,
        false,
        run::<membrane_p2_p0::Model, TriangleMesh, Membranes>,
    ),
    pair(
        "p1-p0",
        "u ∈ P1, λ ∈ P0, stabilized",
        1.6e3,
        false,
        run::<membrane_p1_p0::Model, TriangleMesh, Membranes>,
    ),
    pair(
        "p2-p1d",
        "u ∈ P2, λ ∈ P1 discontinuous, stabilized",
        7.0e3,
        false,
        run::<membrane_p2_p1disc::Model, TriangleMesh, Membranes>,
    ),
    pair(
        "p1-nodal",
        "u ∈ P1 with the nodal constraints u_i ≥ ψ(x_i), no multiplier space",
        0.6e3,
        true,
        run::<membrane_p1::Model, TriangleMesh, Membranes>,
    ),
];

/// The scene of a membrane description of [`crate::membrane_scenes`].
pub fn membrane_scene(old: &MembraneScene) -> Scene {
    let domain = match &old.domain {
        membrane_scenes::Domain::Square(a) => Domain::Rectangle {
            x: [-a, *a],
            y: [-a, *a],
            cells: [1, 1],
            diagonal: fem_runtime::Diagonal::Right,
        },
        membrane_scenes::Domain::LShape => Domain::LShape,
        membrane_scenes::Domain::File(path) => Domain::Gmsh(path.clone()),
    };
    let mesh_size = if domain.is_file() { 0 } else { 64 };
    let mut scene = Scene::new(
        old.name.clone(),
        old.description.clone(),
        "membrane",
        domain,
        mesh_size,
    )
    .with_data("f", old.load.clone())
    .with_data("ψ", old.obstacle.clone())
    .with_data("g", old.boundary.clone());
    let part = match &old.dirichlet {
        DirichletParts::All => Part::All,
        DirichletParts::Named(names) => Part::Named(names.clone()),
    };
    scene.supports.push(crate::scene::PartSupport {
        part,
        support: Support::Data,
        key: Some("boundary.dirichlet".into()),
    });
    scene.load = old.load_scale.map(|q| Load {
        default: q,
        scales: vec!["f".into()],
        symbol: "q",
        sign: crate::scene::LoadSign::Any,
    });
    let convert = |e: crate::membrane_scenes::ExactMembrane| ExactSolution {
        value: Some(e.u),
        gradient: Some(e.gradient),
        multiplier: e.multiplier,
        total_contact_force: e.total_contact_force,
        contact_area: e.contact_area,
        ..ExactSolution::default()
    };
    scene.exact = match &old.exact {
        membrane_scenes::Exact::Unknown => Exact::Unknown,
        membrane_scenes::Exact::AtDefaultLoad(e) => match old.load_scale {
            Some(_) => Exact::AtDefaultLoad(convert(e.clone())),
            // a fixed load: the exact solution holds whatever is asked
            None => {
                let e = convert(e.clone());
                Exact::Of(Arc::new(move |_: &Posed| Some(e.clone())))
            }
        },
        membrane_scenes::Exact::OfLoad(f) => {
            let f = *f;
            let q0 = old.load_scale.unwrap_or(1.0);
            Exact::Of(Arc::new(move |posed: &Posed| {
                // a load that presses onto the obstacle; a negative q lifts the membrane
                // off and the formula no longer holds
                let q = posed.load.unwrap_or(q0);
                (q >= 0.0).then(|| convert(f(q)))
            }))
        }
    };
    scene.pairs = PAIRS.iter().map(|p| p.name).collect();
    scene
}

/// The studies each built-in membrane scene hosts: work–precision needs the exact error,
/// iterations need no exact solution.
fn studies(name: &str) -> Vec<&'static str> {
    match name {
        "membrane-radial" => vec![
            "convergence",
            "stability",
            "alpha",
            "work-precision",
            "iterations",
            "adaptivity",
        ],
        "membrane-lshape" => vec!["iterations", "adaptivity"],
        _ => Vec::new(),
    }
}

impl Family for Membranes {
    fn default_support(&self) -> Option<(Support, &'static str)> {
        Some((Support::Data, "boundary.dirichlet"))
    }

    fn name(&self) -> &'static str {
        "membrane"
    }

    fn description(&self) -> &'static str {
        "membranes on triangle meshes (structured or Gmsh), u = g on chosen boundary parts"
    }

    fn pairs(&self) -> &'static [Pair] {
        &PAIRS
    }

    fn options(&self) -> &'static [Opt] {
        &[
            Opt::MeshSize,
            Opt::Msh,
            Opt::Vtk,
            Opt::Load,
            Opt::Alpha,
            Opt::Pair,
            Opt::Solver,
            Opt::Cold,
            Opt::LinearSolver,
            Opt::Tol,
            Opt::Marking,
            Opt::Theta,
        ]
    }

    fn scenes(&self) -> Vec<Scene> {
        let mut scenes: Vec<Scene> = membrane_scenes::MEMBRANE_SCENES
            .iter()
            .map(|s| {
                let mut scene = membrane_scene(s);
                scene.accuracy = Some(s.target_l2);
                scene.studies = studies(&s.name);
                scene.in_default_job = true;
                scene
            })
            .collect();
        let mut flat = membrane_scene(&membrane_scenes::MEMBRANE_FLAT);
        flat.accuracy = Some(membrane_scenes::MEMBRANE_FLAT.target_l2);
        scenes.push(flat);
        scenes
    }

    fn pair_aliases(&self) -> &'static [(&'static str, &'static str)] {
        &[("p2-p1disc", "p2-p1d")]
    }

    fn aliases(&self) -> &'static [(&'static str, &'static str)] {
        &[
            ("load", "f"),
            ("obstacle", "ψ"),
            ("psi", "ψ"),
            ("boundary", "g"),
        ]
    }
}

impl Quantities<TriangleMesh> for Membranes {
    /// No iterative refinement of the Newton directions (the membrane's condition ~h⁻²
    /// leaves them accurate, and the KKT residual is checked at the end anyway), saving
    /// two triangular solves per iteration, and [`SMOOTHING_SWEEPS`] sweeps for the first
    /// direction of a nested level.
    fn obstacle_options(settings: &Settings) -> ObstacleOptions {
        let defaults = ObstacleOptions::default();
        ObstacleOptions {
            solver: settings.solver,
            linear_solver: settings.linear_solver,
            newton: NewtonOptions {
                refinement_steps: settings.refinement.unwrap_or(0),
                smoothing_sweeps: SMOOTHING_SWEEPS,
                ..defaults.newton
            },
            ..defaults
        }
    }

    fn add<M: fem_runtime::Model>(
        run: &crate::run::Run<'_, M, TriangleMesh>,
        report: &mut crate::run::Report,
    ) -> fem_runtime::Result<()> {
        let parts: Vec<String> = run
            .scene
            .supports
            .iter()
            .filter(|s| s.support == Support::Data)
            .flat_map(|s| s.part.names())
            .collect();
        report.set("dirichlet_parts", parts);
        Ok(())
    }
}
