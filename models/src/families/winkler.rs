//! Kirchhoff plates on a Winkler foundation: the family a user adds with one model file
//! ([`crate::winkler`]) and this registry entry. Its one quantity of its own is the
//! integral of the deflection, which the foundation's reaction `k ∫w` needs.

use crate::family::{Family, Opt, Pair};
use crate::geometry::Geometry;
use crate::report::Report;
use crate::run::{run, Quantities, Run};
use crate::scene::{Domain, Load, Part, Scene, Support};
use crate::winkler::winkler_argyris_p0;
use fem_runtime::problem::ALPHA_WHEN_CI_VANISHES;
use fem_runtime::stabilization::Alpha;
use fem_runtime::{Model, Result, TriangleMesh};

/// The Winkler plate family.
pub struct Winkler;

/// The registry's Winkler plate family.
pub static WINKLER: Winkler = Winkler;

static PAIRS: [Pair; 1] = [Pair {
    name: "argyris-p0",
    note: "w ∈ Argyris (C¹ quintic), λ ∈ P0, stabilized",
    alpha: Alpha::FromInverseConstant(0.5),
    alpha_when_zero: ALPHA_WHEN_CI_VANISHES,
    memory: None,
    nodal: false,
    parameters: &[],
    solve: run::<winkler_argyris_p0::Model, TriangleMesh, Winkler>,
}];

impl Family for Winkler {
    fn name(&self) -> &'static str {
        "winkler"
    }

    fn description(&self) -> &'static str {
        "Kirchhoff plates on a Winkler foundation (modulus k) over an obstacle"
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
            Opt::Support,
            Opt::NoObstacle,
            Opt::Solver,
            Opt::Cold,
            Opt::Tol,
            Opt::Marking,
            Opt::Theta,
        ]
    }

    /// The simply supported unit square (D = 1, ν = 0.3, k = 100) under a uniform load,
    /// over a flat obstacle that a strong load reaches.
    fn scenes(&self) -> Vec<Scene> {
        let scene = Scene::new(
            "winkler-square",
            "simply supported unit square on a Winkler foundation (D = 1, ν = 0.3, k = 100), uniform load q downwards onto the plane ψ = −0.002",
            "winkler",
            Domain::square(0.0, 1.0),
            16,
        )
        .with_parameter("D", 1.0)
        .with_parameter("ν", 0.3)
        .with_parameter("k", 100.0)
        .with_data("f", crate::data::Data::shared(|_| -1.0))
        .with_data("ψ", crate::data::Data::shared(|_| -0.002))
        .with_support(Part::All, Support::SimplySupported { hard: false });
        vec![Scene {
            // the kinds that need no exact solution, through the one study implementation
            studies: vec![
                "alpha",
                "iterations",
                "stability",
                "work-precision",
                "adaptivity",
            ],
            load: Some(Load {
                default: 1.0,
                scales: vec!["f".into()],
                symbol: "q",
                sign: crate::scene::LoadSign::Any,
            }),
            ..scene
        }]
    }

    fn aliases(&self) -> &'static [(&'static str, &'static str)] {
        &[
            ("bending_stiffness", "D"),
            ("nu", "ν"),
            ("foundation_modulus", "k"),
            ("psi", "ψ"),
            ("obstacle", "ψ"),
        ]
    }
}

impl Quantities<TriangleMesh> for Winkler {
    fn check(_: &Scene, posed: &crate::scene::Posed) -> Result<()> {
        if let Some(nu) = posed.parameter("ν").filter(|nu| !(*nu > -1.0 && *nu < 0.5)) {
            return Err(fem_runtime::Error::Input(format!(
                "Poisson's ratio ν = {nu} must lie in (−1, ½)"
            )));
        }
        if let Some(k) = posed.parameter("k").filter(|k| *k < 0.0) {
            return Err(fem_runtime::Error::Input(format!(
                "the foundation modulus k = {k} must be ≥ 0 (a foundation pushes back)"
            )));
        }
        Ok(())
    }

    fn add<M: Model>(run: &Run<'_, M, TriangleMesh>, report: &mut Report) -> Result<()> {
        let integral = TriangleMesh::integral(&run.solved.solution, run.constrained_field());
        report.set("deflection_integral", integral);
        Ok(())
    }
}
