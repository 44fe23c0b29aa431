//! A plate's stress resultants along its boundary (`--edge-resultants`,
//! `fem_forms::models::families::edge_resultants`), against independent references:
//! Timoshenko and Woinowsky-Krieger's table for the simply supported square (Kirchhoff),
//! Kirchhoff's effective shear as the limit of the Reissner–Mindlin edge shear force
//! once the boundary layer is resolved (Arnold–Falk), and equilibrium (the reaction
//! balances the load and the contact force). And the model choice: a scene that asks for
//! them keeps the Reissner–Mindlin plate where its energy alone would take Kirchhoff.

use fem_forms::adaptivity::AdaptiveOptions;
use fem_forms::models::report::{Outcome, Settings};
use fem_forms::models::scene::{Adjustment, Scene, Support};
use fem_forms::models::{choice, families};

/// Timoshenko and Woinowsky-Krieger, Theory of Plates and Shells, Table 8 (simply
/// supported rectangle under uniform load q, b/a = 1, ν = 0.3): the largest effective
/// shear `V = 0.420 q a` (at the middle of an edge) and the corner force
/// `R = 2 M_xy = 0.065 q a²`, three digits.
const TABLE_V: f64 = 0.420;
const TABLE_R: f64 = 0.065;

/// The corner force `R = 2 M_xy(0, 0) = 2(1−ν) D w_xy(0, 0)` of Navier's series for the
/// simply supported unit square (q = 1, ν = 0.3):
/// `w_xy(0, 0) = 16/(π⁴ D) Σ_{m,n odd} 1/(m² + n²)²`, summed to m, n < 4000 (the tail
/// is below 1e-7).
fn navier_corner_force() -> f64 {
    let mut sum = 0.0;
    for m in (1..4000).step_by(2) {
        for n in (1..4000).step_by(2) {
            let s = (m * m + n * n) as f64;
            sum += 1.0 / (s * s);
        }
    }
    2.0 * 0.7 * 16.0 / std::f64::consts::PI.powi(4) * sum
}

fn scene(name: &str) -> Scene {
    families::scene(name).unwrap_or_else(|| panic!("scene {name}"))
}

fn asking(mut scene: Scene) -> Scene {
    scene.edge_resultants = true;
    scene
}

fn resultants(outcome: &Outcome) -> &serde_json::Value {
    outcome
        .report
        .quantity("edge_resultants")
        .expect("edge_resultants in the report")
}

fn number(v: &serde_json::Value, key: &str) -> f64 {
    v[key].as_f64().unwrap_or_else(|| panic!("{key} in {v}"))
}

/// The column `key` of the edge resultants' `profile` (one value per boundary edge).
fn profile_column(v: &serde_json::Value, key: &str) -> Vec<f64> {
    v["profile"][key]
        .as_array()
        .unwrap_or_else(|| panic!("profile.{key}"))
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect()
}

/// The shear force of the profile at the midpoint sample nearest `(x, y)`.
fn shear_near(v: &serde_json::Value, [x, y]: [f64; 2]) -> f64 {
    let column = |k| profile_column(v, k);
    let (xs, ys, q) = (column("x"), column("y"), column("shear_force"));
    let k = (0..xs.len())
        .min_by(|&a, &b| {
            let d = |i: usize| (xs[i] - x).hypot(ys[i] - y);
            d(a).total_cmp(&d(b))
        })
        .unwrap();
    q[k]
}

/// The Mindlin plate on the soft simply supported unit square, q = 1, no obstacle, at
/// thickness t.
fn soft_square(t: f64) -> Scene {
    let mut scene = scene("mindlin-square-ss");
    scene.set_parameter("t", t);
    scene
}

/// The Kirchhoff plate on the simply supported unit square (q = 1, ν = 0.3), asked for its
/// edge resultants.
fn simply_supported_kirchhoff_square() -> Scene {
    let mut square = asking(scene("kirchhoff-square"));
    families::family("kirchhoff")
        .unwrap()
        .adjust(
            &mut square,
            &Adjustment::Support(Support::SimplySupported { hard: false }),
        )
        .unwrap();
    square
}

#[test]
fn the_kirchhoff_edge_resultants_are_the_tables() {
    let square = simply_supported_kirchhoff_square();
    let settings = Settings {
        mesh_size: Some(32),
        ..Settings::default()
    };
    let outcome = families::solve(&square, &settings).unwrap();
    let r = resultants(&outcome);
    let (v, twist, total) = (
        number(r, "shear_force_max"),
        number(r, "twisting_moment_max"),
        number(r, "shear_force_integral"),
    );
    let corner = navier_corner_force();
    println!("V_max {v:.5}, max |M_ns| {twist:.5}, ∫ V_n ds {total:.5}, Navier's R {corner:.6}");
    assert!((corner - TABLE_R).abs() < 5e-4);
    assert!((v - TABLE_V).abs() < 1e-3, "V {v}");
    assert!(
        (2.0 * twist - corner).abs() < 1e-3,
        "2 M_ns {}",
        2.0 * twist
    );
    // equilibrium: the edges' reaction and the four corner forces carry the load q a²
    assert!(
        (-total - (1.0 + 4.0 * corner)).abs() < 2e-3,
        "∫ V_n ds {total}"
    );
    // the soft edges' M_nn vanishes (the natural condition), to the discretization
    assert!(number(r, "bending_moment_max") < 1e-3 * TABLE_V);
}

#[test]
fn the_resolved_mindlin_layer_gives_kirchhoffs_effective_shear_in_equilibrium() {
    let plate = asking(soft_square(1e-2));
    let uniform = families::solve(
        &plate,
        &Settings {
            mesh_size: Some(32),
            ..Settings::default()
        },
    )
    .unwrap();
    let adaptive = families::solve(
        &plate,
        &Settings {
            adaptive: Some(AdaptiveOptions {
                tolerance: 0.1,
                ..AdaptiveOptions::default()
            }),
            ..Settings::default()
        },
    )
    .unwrap();
    let (coarse, fine) = (resultants(&uniform), resultants(&adaptive));
    let width = number(fine, "layer_width");
    assert!((width - 1e-2 / 10f64.sqrt()).abs() < 1e-15);
    assert_eq!(coarse["layer_resolved"], false);
    assert!(uniform
        .report
        .solve
        .warnings
        .iter()
        .any(|w| w.contains("edge resultants are not resolved")));
    assert_eq!(fine["layer_resolved"], true);
    assert!(number(fine, "layer_longest_edge") <= width);
    let middle = [0.5, 0.0];
    let (v_coarse, v_fine) = (shear_near(coarse, middle), shear_near(fine, middle));
    println!(
        "edge middle: Q·n {v_coarse:.4} on 32×32, {v_fine:.4} resolved ({} cells); ∫ Q·n ds {:.5}",
        adaptive.report.solve.cells,
        number(fine, "shear_force_integral")
    );
    // Arnold–Falk: across the layer the Mindlin shear force gains −∂_s M_ns, so on the
    // edge it is Kirchhoff's effective shear V (outward: −V), not Kirchhoff's Q = 0.338
    assert!((-v_fine - TABLE_V).abs() < 0.01 * TABLE_V, "{v_fine}");
    assert!((-v_coarse - TABLE_V).abs() > 0.05 * TABLE_V, "{v_coarse}");
    // equilibrium: ∫_∂Ω Q·n ds = −∫ f, with no corner forces (the layer carries them)
    let total = number(fine, "shear_force_integral");
    assert!((total + 1.0).abs() < 2e-3, "{total}");
    // the layer turns the twisting moment towards its free value 0 on the edge
    assert!(number(fine, "twisting_moment_max") < 0.5 * TABLE_R / 2.0);
}

#[test]
fn a_scene_asking_for_edge_resultants_keeps_the_mindlin_plate_and_resolves_its_layer() {
    let request = Settings {
        adaptive: Some(AdaptiveOptions {
            tolerance: 0.1,
            ..AdaptiveOptions::default()
        }),
        ..Settings::default()
    };
    // t = 1e-3: the layer's share of the energy is 3 %, so the energy alone takes Kirchhoff
    let plain = choice::solve(&scene("mindlin-ss-t1e-3"), &request).unwrap();
    assert_eq!(
        plain.report.quantity("chosen_model").unwrap(),
        "Kirchhoff",
        "{:?}",
        plain.report.quantity("candidates")
    );
    let asked = choice::solve(&asking(scene("mindlin-ss-t1e-3")), &request).unwrap();
    assert_eq!(
        asked.report.quantity("chosen_model").unwrap(),
        "Reissner–Mindlin"
    );
    let candidates = asked
        .report
        .quantity("candidates")
        .unwrap()
        .as_array()
        .unwrap();
    for c in candidates.iter().filter(|c| c["model"] == "Kirchhoff") {
        assert_eq!(c["adequate"], false);
        assert!(
            c["note"].as_str().unwrap().contains("edge resultants"),
            "{c}"
        );
        assert!(c["modelling_estimate"].as_f64().unwrap() > 0.9);
    }
    let r = resultants(&asked);
    assert_eq!(r["layer_resolved"], true);
    // equilibrium with the obstacle above (s = −1): ∫ Q·n ds = −∫ f + ∫ λ
    let total = number(r, "shear_force_integral");
    let contact = asked.report.solve.total_contact_force;
    let load = 20.0;
    println!("∫ Q·n ds {total:.5}, ∫ λ {contact:.5}");
    assert!(
        (total - (contact - load)).abs() < 2e-3 * load,
        "{total} {contact}"
    );
}

#[test]
fn edge_resultants_are_a_plates_and_need_third_derivatives_from_kirchhoff() {
    // a membrane's scene file refuses the key, naming it
    let dir = std::env::temp_dir().join("fem-forms-edge-resultants");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("membrane.toml");
    let flat = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/membrane-flat.toml"),
    )
    .unwrap();
    std::fs::write(
        &file,
        flat.replace("pair = ", "edge_resultants = true\npair = "),
    )
    .unwrap();
    let error = fem_forms::models::scene_file::read(&file)
        .unwrap_err()
        .to_string();
    assert!(error.contains("edge_resultants"), "{error}");
    // Morley's ∇Δw vanishes: no resultants, said so
    let outcome = families::solve(
        &asking(scene("kirchhoff-square")),
        &Settings {
            pair: Some("morley-p0".into()),
            mesh_size: Some(8),
            ..Settings::default()
        },
    )
    .unwrap();
    assert!(outcome.report.quantity("edge_resultants").is_none());
    assert!(outcome
        .report
        .solve
        .warnings
        .iter()
        .any(|w| w.contains("gives no edge resultants")));
}

/// The Kirchhoff plate on the simply supported square, asked for its edge resultants,
/// solved adaptively to `tolerance` from N = 4 (a mesh whose edges are stored in either
/// order along the boundary).
fn adaptive_kirchhoff_square(tolerance: f64, pair: Option<&str>) -> Outcome {
    let square = simply_supported_kirchhoff_square();
    let settings = Settings {
        pair: pair.map(str::to_string),
        mesh_size: Some(4),
        adaptive: Some(AdaptiveOptions {
            tolerance,
            ..AdaptiveOptions::default()
        }),
        ..Settings::default()
    };
    if pair.is_some() {
        families::solve(&square, &settings).unwrap()
    } else {
        choice::solve(&square, &settings).unwrap()
    }
}

#[test]
fn the_twisting_moment_is_odd_about_each_edges_middle_on_an_adaptive_mesh() {
    // Navier's M_xy is odd about x = ½ on the edge y = 0 (and so on round the square);
    // M_ns = n·M·τ with τ the outward normal turned counter-clockwise keeps that sign
    // pattern whatever order the refined mesh stores an edge's vertices in
    let outcome = adaptive_kirchhoff_square(1e-4, Some("argyris-p0"));
    let column = |k| profile_column(resultants(&outcome), k);
    let (xs, ys, m_ns) = (column("x"), column("y"), column("m_ns"));
    // the sign of M_ns against that of ½ − s, s the counter-clockwise coordinate along
    // the edge from its first corner: one sign for every sample
    let mut signs = Vec::new();
    for k in 0..xs.len() {
        let (x, y) = (xs[k], ys[k]);
        let along = if y.abs() < 1e-12 {
            x
        } else if (x - 1.0).abs() < 1e-12 {
            y
        } else if (y - 1.0).abs() < 1e-12 {
            1.0 - x
        } else {
            1.0 - y
        };
        if (along - 0.5).abs() > 0.05 {
            signs.push((m_ns[k].signum() * (0.5 - along).signum(), x, y, m_ns[k]));
        }
    }
    assert!(signs.len() > 40, "{} samples", signs.len());
    for &(sign, x, y, m) in &signs {
        assert_eq!(sign, signs[0].0, "M_ns {m} at ({x}, {y})");
    }
}

#[test]
fn a_tolerance_with_edge_resultants_does_not_take_morley() {
    // Morley gives no resultants: asked for them, the choice takes Argyris even where
    // Morley is faster and accurate enough
    let outcome = adaptive_kirchhoff_square(0.3, None);
    assert!(outcome.report.quantity("edge_resultants").is_some());
    assert_ne!(outcome.report.pair, "morley-p0");
}

#[test]
fn supports_that_overlap_combine_for_the_layer_as_in_the_solve() {
    // `free` on an edge that a clamped support also names adds no condition: the plate
    // is clamped all round, so no edge leaves the rotations free and there is no layer
    let mut plate = asking(scene("mindlin-square"));
    let clamped_free_right = |scene: &mut Scene| {
        scene.supports = vec![
            fem_forms::models::scene::PartSupport {
                part: fem_forms::models::scene::Part::All,
                support: Support::Clamped,
                key: None,
            },
            fem_forms::models::scene::PartSupport {
                part: fem_forms::models::scene::Part::Named(vec!["right".into()]),
                support: Support::Free,
                key: None,
            },
        ];
    };
    clamped_free_right(&mut plate);
    let settings = Settings {
        mesh_size: Some(8),
        ..Settings::default()
    };
    let outcome = families::solve(&plate, &settings).unwrap();
    let r = resultants(&outcome);
    assert!(r["layer_resolved"].is_null(), "{}", r["layer_resolved"]);
    assert_eq!(number(r, "twisting_moment_max"), 0.0);
    let clamped = families::solve(&asking(scene("mindlin-square")), &settings).unwrap();
    assert_eq!(
        outcome.report.solve.energy, clamped.report.solve.energy,
        "the free line changes the solve"
    );
}
