//! The plate scenes through the one solve: input that no command-line option reaches (a
//! scene's material, its obstacle) is refused with a message naming it, and nested
//! iteration on the disk keeps Newton's iterations flat in h while a cold start grows.

use fem_forms::models::data::Data;
use fem_forms::models::families;
use fem_forms::models::geometry::halving_sizes;
use fem_forms::models::report::{Report, Settings};
use fem_forms::models::scene::Scene;
use fem_forms::problem::ObstacleSide;
use fem_forms::registry_studies::RegistryStudies;
use fem_forms::studies;

fn scene(name: &str) -> Scene {
    families::scene(name).unwrap()
}

fn solve(scene: &Scene, settings: &Settings) -> fem_forms::Result<Report> {
    families::solve(scene, settings).map(|o| o.report)
}

fn refused(scene: &Scene, settings: &Settings, words: &[&str]) {
    match solve(scene, settings) {
        Ok(report) => panic!("{} solved: {report:?}", scene.name),
        Err(e) => {
            let message = e.to_string();
            assert!(words.iter().all(|w| message.contains(w)), "{message}");
        }
    }
}

/// A flat obstacle `ψ = height` on `side` of the plate of `name`.
fn with_obstacle(name: &str, side: ObstacleSide, height: f64) -> Scene {
    let mut s = scene(name);
    s.side = side;
    s.obstacle = true;
    s.set_data("ψ", Data::shared(move |_| height));
    s
}

#[test]
fn bad_scene_data_is_refused_with_a_message() {
    let disk = scene("mindlin-disk");
    for nu in [0.5, -1.0, 0.7, f64::NAN] {
        let settings = Settings {
            parameters: vec![("ν".into(), nu)],
            ..Settings::default()
        };
        refused(
            &disk,
            &settings,
            &[&format!("Poisson's ratio ν = {nu} must lie in (−1, ½)")],
        );
    }
    let small = Settings {
        mesh_size: Some(8),
        ..Settings::default()
    };
    // an obstacle above the plate but below its clamped edge w = 0: no admissible w
    refused(
        &with_obstacle("mindlin-disk", ObstacleSide::Above, -0.01),
        &small,
        &["infeasible", "ψ = -0.01"],
    );
    refused(
        &with_obstacle("mindlin-square-ss", ObstacleSide::Below, 0.02),
        &small,
        &["infeasible", "ψ = 0.02"],
    );
    for height in [f64::NAN, f64::INFINITY] {
        refused(
            &with_obstacle("mindlin-disk", ObstacleSide::Above, height),
            &small,
            &["ψ", &format!("{height}")],
        );
    }
    refused(
        &scene("mindlin-square"),
        &Settings {
            parameters: vec![("D".into(), 0.0)],
            ..Settings::default()
        },
        &["`D`", "0"],
    );
    // an obstacle at the edge's own height is admissible: the plate is pressed flat
    // against it, w ≡ 0 and λ = q everywhere
    let flat = solve(
        &with_obstacle("mindlin-disk", ObstacleSide::Above, 0.0),
        &small,
    )
    .unwrap();
    let max_w = flat.number("max_deflection").unwrap();
    assert!(max_w < 1e-10, "{flat:?}");
    let area = flat.solve.contact_area.unwrap();
    let q = flat.load.unwrap();
    assert!(
        (flat.solve.total_contact_force - q * area).abs() < 1e-8 * q * area,
        "{flat:?}"
    );
}

/// Nested iteration on the disk (rings 4, 8, 16, 32, 64 at q = 50): at most 5 Newton
/// steps on every level, and on the finest fewer than a cold start there.
#[test]
fn nested_iterations_stay_flat_on_the_disk() {
    assert_eq!(halving_sizes(64, true, 4, false), [4, 8, 16, 32, 64]);
    assert_eq!(halving_sizes(24, true, 4, false), [6, 12, 24]);
    assert_eq!(halving_sizes(64, false, 4, false), [64]);
    let disk = scene("mindlin-disk");
    let at = |nested: bool| {
        let settings = Settings {
            mesh_size: Some(64),
            load: Some(50.0),
            nested,
            ..Settings::default()
        };
        solve(&disk, &settings).unwrap()
    };
    let nested = at(true);
    let levels = &nested.solve.levels;
    assert_eq!(levels.len(), 5, "{levels:?}");
    assert!(levels.iter().all(|l| l[1] <= 5), "{levels:?}");
    let cold = at(false);
    assert!(
        cold.solve.iterations > nested.solve.iterations,
        "{} cold against {levels:?}",
        cold.solve.iterations
    );
    // the iterations study runs the disk's loads as its variants: q = 50's is this solve
    let variants = families::study_variants(&disk).unwrap();
    let names: Vec<&str> = variants.iter().map(|s| &*s.name).collect();
    assert_eq!(
        names,
        ["mindlin-disk-q10", "mindlin-disk-q20", "mindlin-disk-q50"]
    );
    let q50 = RegistryStudies::new(variants[2].clone());
    let rows = studies::iteration_counts(&q50, "p1-p2-p0", &[64], 64);
    assert_eq!(
        rows,
        [(
            64,
            Some(nested.solve.iterations),
            Some(cold.solve.iterations)
        )]
    );
}

/// The convergence study of a scene without an exact solution follows the changes of
/// J_h, ∫λ_h and the contact measure between meshes, and a Kirchhoff square's variants
/// (both supports) their centre deflections against the two series (clamped: the
/// tabulated 0.00126532; simply supported: Navier's 0.00406235, Timoshenko &
/// Woinowsky-Krieger tables 35 and 8): Morley's errors fall as h² for both
/// (by about 3.6 per halving).
#[test]
fn the_convergence_study_runs_every_variant_against_its_reference() {
    let square = scene("kirchhoff-square");
    let variants = families::study_variants(&square).unwrap();
    assert_eq!(variants.len(), 2);
    let mut finest_energies = Vec::new();
    for variant in variants {
        let name = variant.name.to_string();
        let rows =
            studies::convergence(&RegistryStudies::new(variant), "morley-p0", &[4, 8, 16]).unwrap();
        let errors: Vec<f64> = rows.iter().map(|r| r.reference_error.unwrap()).collect();
        assert!(
            errors.windows(2).all(|w| w[1] < 0.35 * w[0]),
            "{name}: {errors:?}"
        );
        let changes = studies::Changes::of(&rows);
        let j: Vec<f64> = rows.iter().map(|r| r.energy.unwrap()).collect();
        assert_eq!(changes.changes[0], [j[1] - j[0], j[2] - j[1]], "{name}");
        finest_energies.push(j[2]);
    }
    // J = −½ ∫ f w: the simply supported square deflects several times as far (its
    // centre 3.2 times), so the variant's support was applied
    let ratio = finest_energies[1] / finest_energies[0];
    assert!(ratio > 2.5, "{finest_energies:?}");
}

/// The plain pair chosen by hand locks as its cells grow against the thickness (a
/// mindlin-disk at N = 32: ∫λ_h 6.5 against 18.7, without a word): warned from h = t/10,
/// and not on finer cells, where it agrees with the Stenberg pair.
#[test]
fn the_locking_plate_pair_is_warned_about_where_it_locks() {
    let square = scene("mindlin-square");
    let request = |pair: &str, n: usize| Settings {
        pair: Some(pair.into()),
        mesh_size: Some(n),
        parameters: vec![("t".into(), 0.2)],
        ..Settings::default()
    };
    let plain = |n: usize| solve(&square, &request("p1-p1-p0-plain", n)).unwrap();
    let locks = |r: &Report| r.solve.warnings.iter().any(|w| w.contains("locks"));
    let coarse = plain(4);
    assert!(locks(&coarse), "{:?}", coarse.solve.warnings);
    // at h ≈ t the deflection was 12–15 % low without a word; the warning starts at
    // h = t/10, and below it the pair agrees with the Stenberg one
    assert!(locks(&plain(16)));
    let fine = plain(80);
    assert!(!locks(&fine), "{:?}", fine.solve.warnings);
    let stenberg = solve(&square, &request("p1-p2-p0", 80)).unwrap();
    let w = |r: &Report| r.number("centre_deflection").unwrap();
    let off = w(&fine) / w(&stenberg) - 1.0;
    assert!(off.abs() < 1e-2, "{off}");
}
