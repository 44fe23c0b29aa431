//! What the beam tests share: a scene's solve through the one pipeline, with the
//! report's beam quantities, and the discrete obstacle problem built from its model file
//! through the runtime, for the tests that reach below the solve (the LCP solvers, the
//! multigrid prolongation).
#![allow(dead_code)]

use fem_forms::models::families;
use fem_forms::models::report::{Outcome, Report, Settings};
use fem_forms::models::scene::Name;
use fem_forms::models::scenes::{self, Beam};
use fem_forms::models::{bernoulli, timoshenko_p1_full, timoshenko_p1_reduced, timoshenko_p2};
use fem_forms::obstacle::{system_forms, Discretization};
use fem_forms::{Coefficients, DataFn, IntervalMesh, Model, Result};

/// The settings of a solve on `elements` elements at load `q`.
pub fn settings(elements: usize, q: f64) -> Settings {
    Settings {
        mesh_size: Some(elements),
        load: Some(q),
        ..Settings::default()
    }
}

/// The thickness `t` as a setting.
pub fn thickness(t: f64) -> Vec<(Name, f64)> {
    vec![(Name::from("t"), t)]
}

/// The registry's beam scene `name` solved with `settings`.
pub fn solve(name: &str, settings: &Settings) -> Result<Outcome> {
    families::solve(&families::scene(name).expect("a beam scene"), settings)
}

/// The largest |w_h| of a beam's report.
pub fn max_deflection(report: &Report) -> f64 {
    report.number("max_deflection").expect("a beam report")
}

/// The contact intervals of a beam's report (a point contact as `[x, x]`).
pub fn contact_set(report: &Report) -> Vec<[f64; 2]> {
    serde_json::from_value(report.quantities["contact_set"].clone()).expect("a beam report")
}

/// The multiplier per cell of a solve on an interval.
pub fn lambda(outcome: &Outcome) -> &[f64] {
    match &outcome.fields {
        fem_forms::models::geometry::Fields::Interval { lambda, .. } => lambda,
        _ => panic!("a beam solve"),
    }
}

/// The discrete obstacle problem of the beam scene `name` with `pair` on `elements`
/// uniform elements at load `q` and stabilization `alpha`, clamped at both ends.
pub fn discretize(
    name: &str,
    pair: &str,
    elements: usize,
    q: f64,
    alpha: f64,
) -> Result<Discretization> {
    discretize_scene(
        &scenes::scene(name).expect("a beam scene"),
        pair,
        elements,
        q,
        alpha,
    )
}

/// [`discretize`] of a beam data set (its thickness, obstacle and load direction).
pub fn discretize_scene(
    scene: &scenes::Scene,
    pair: &str,
    elements: usize,
    q: f64,
    alpha: f64,
) -> Result<Discretization> {
    match pair {
        "hermite-p0" => discretize_with::<bernoulli::Model>(scene, elements, q, alpha),
        "p2-p2-p0" => discretize_with::<timoshenko_p2::Model>(scene, elements, q, alpha),
        "p1-p1-p0-reduced" => {
            discretize_with::<timoshenko_p1_reduced::Model>(scene, elements, q, alpha)
        }
        "p1-p1-p0-full" => discretize_with::<timoshenko_p1_full::Model>(scene, elements, q, alpha),
        _ => panic!("no beam pair `{pair}`"),
    }
}

fn discretize_with<M: Model>(
    scene: &scenes::Scene,
    elements: usize,
    q: f64,
    alpha: f64,
) -> Result<Discretization> {
    let timoshenko = scene.beam == Beam::Timoshenko;
    let (load, obstacle) = (scene.load_sign * q, scene.obstacle);
    let f = move |_: &[f64]| load;
    let psi = move |x: &[f64]| obstacle.at(x[0]);
    let mut parameters = vec![("α", alpha), ("s", scene.side)];
    if timoshenko {
        parameters.push(("t", scene.thickness));
    }
    let coefficients =
        Coefficients::new::<M>(&parameters, &[("f", &f as &DataFn), ("ψ", &psi as &DataFn)])?;
    let mesh = IntervalMesh::uniform(0.0, 1.0, elements)?;
    let (bilinear, linear) = system_forms::<M>()?;
    let clamped: &[&str] = if timoshenko { &["θ", "w"] } else { &["w"] };
    Discretization::new::<M>(&mesh, &coefficients, clamped, bilinear, linear)
}
