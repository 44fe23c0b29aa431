//! A contact body held by a roller along an oblique direction: the patch test turned by
//! an angle θ. The block (0,2)×(0,1) turned by θ rests with its bottom on a foundation
//! whose normal is the turned (0, −1), a roller holds its left side along the turned x
//! axis, and a uniform pressure q acts on its top: the exact stress is `σ = −q n⊗n` in
//! the turned frame, so the contact pressure is q on every edge, whatever θ.

use fem_forms::models::contact_scenes::ContactBody;
use fem_forms::models::families::contact::Plane;
use fem_forms::models::families::contact::{material_parameters, ContactFacts};
use fem_forms::models::families::{self};
use fem_forms::models::report::Settings;
use fem_forms::models::scene::{Domain, Generator, Load, Part, PartSupport, Scene, Support};
use fem_forms::{Diagonal, TriangleMesh};
use std::sync::Arc;

/// The block's N×N×2 (2N×N on its 2:1 shape) mesh turned by `theta` about the origin,
/// its sides named as the rectangle's.
fn turned_block(n: usize, theta: f64) -> fem_forms::Result<TriangleMesh> {
    let block = TriangleMesh::rectangle(0.0, 2.0, 0.0, 1.0, 2 * n, n, Diagonal::Right)?;
    let (s, c) = theta.sin_cos();
    let vertices = block
        .vertices()
        .iter()
        .map(|x| [c * x[0] - s * x[1], s * x[0] + c * x[1]])
        .collect();
    let markers: Vec<(usize, usize, u32)> = block
        .boundary_edges()
        .iter()
        .map(|&(e, m)| {
            let [a, b] = block.edges()[e];
            (a, b, m)
        })
        .collect();
    TriangleMesh::new(vertices, block.cells().to_vec(), &markers)?.with_boundary_names(&[
        ("bottom", &[1]),
        ("right", &[2]),
        ("top", &[3]),
        ("left", &[4]),
    ])
}

fn turned_patch(theta: f64) -> Scene {
    let (s, c) = theta.sin_cos();
    let facts = ContactFacts {
        young: 1000.0,
        poisson: 0.3,
        plane: Plane::Strain,
        direction: [s, -c],
        centre: None,
        body: Some(ContactBody::Block {
            width: 2.0,
            height: 1.0,
        }),
    };
    let domain = Domain::Generated(Generator {
        description: format!("the block (0,2)×(0,1) turned by {theta}").into(),
        size_meaning: "N of the block's 2N×N×2 mesh",
        max_size: 64,
        build: Arc::new(move |n, _| turned_block(n, theta)),
    });
    let mut scene = Scene::new("turned-patch", "turned patch test", "contact", domain, 4);
    for (name, value) in material_parameters(&facts).unwrap() {
        scene.set_parameter(name, value);
    }
    scene.set_data("q", fem_forms::models::data::Data::shared(|_| 1.0));
    scene.set_data("g", fem_forms::models::data::Data::shared(|_| 0.0));
    scene.load = Some(Load {
        default: 1.0,
        scales: vec!["q".into()],
        symbol: "q",
        sign: fem_forms::models::scene::LoadSign::Positive,
    });
    scene.facets = vec![
        ("Γ_C".into(), Part::named("bottom")),
        ("Γ_N".into(), Part::named("top")),
    ];
    scene.supports.push(PartSupport {
        part: Part::named("left"),
        support: Support::Roller { normal: [c, s] },
        key: None,
    });
    scene.reference = Some(Arc::new(facts));
    scene
}

#[test]
fn the_turned_patch_test_gives_the_pressure_exactly() {
    for theta in [0.0, 0.3, -std::f64::consts::FRAC_PI_6, 1.2] {
        for pair in ["p1-p0", "p2-p0", "p1-p1"] {
            let settings = Settings {
                pair: Some(pair.into()),
                ..Settings::default()
            };
            let outcome = families::solve(&turned_patch(theta), &settings)
                .unwrap_or_else(|e| panic!("θ = {theta}, {pair}: {e}"));
            let r = &outcome.report;
            let error = r.number("patch_pressure_error").unwrap();
            assert!(error < 1e-9, "θ = {theta}, {pair}: max |λ − q|/q = {error}");
            let force = r.number("total_contact_force").unwrap();
            assert!(
                (force - 2.0).abs() < 1e-9,
                "θ = {theta}, {pair}: ∫λ = {force}"
            );
            assert!(r.solve.complementarity_residual < 1e-10, "{r:?}");
        }
    }
}

/// The roller must hold the sliding: one along the foundation's normal leaves the body
/// free to slide along the foundation, and the solve says so.
#[test]
fn a_roller_that_leaves_the_sliding_free_is_refused() {
    let theta: f64 = 0.4;
    let mut scene = turned_patch(theta);
    let (s, c) = theta.sin_cos();
    scene.supports[0].support = Support::Roller { normal: [-s, c] };
    let e = families::solve(&scene, &Settings::default())
        .expect_err("a free sliding was solved")
        .to_string();
    assert!(
        e.contains("no support fixes the body along the foundation"),
        "{e}"
    );
}
