//! The plate scenes through the library: input that no command-line option reaches (a
//! scene's material, its obstacle) is refused with a message naming it, and nested
//! iteration on the disk keeps Newton's iterations flat in h while a cold start grows.

use fem_forms::models::plate_scenes::{
    PlateObstacle, PlateScene, MINDLIN_DISK, MINDLIN_SQUARE, MINDLIN_SQUARE_SS,
};
use fem_forms::plates::{iteration_levels, level_sizes, solve, PlateRequest};

fn refused(scene: PlateScene, message: &str) {
    match solve(&PlateRequest::new(scene)) {
        Ok(report) => panic!("{} solved: {report:?}", scene.name),
        Err(e) => assert!(e.to_string().contains(message), "{e}"),
    }
}

#[test]
fn bad_scene_data_is_refused_with_a_message() {
    for nu in [0.5, -1.0, 0.7, f64::NAN] {
        refused(
            PlateScene {
                poisson_ratio: nu,
                ..MINDLIN_DISK
            },
            &format!("Poisson's ratio ν = {nu} must lie in (−1, ½)"),
        );
    }
    // an obstacle above the plate but below its clamped edge w = 0: s(g − ψ) < 0 there
    refused(
        PlateScene {
            obstacle: PlateObstacle::FlatAbove { height: -0.01 },
            ..MINDLIN_DISK
        },
        "the obstacle (flat above, w ≤ -0.01) contradicts the clamped boundary",
    );
    refused(
        PlateScene {
            obstacle: PlateObstacle::FlatBelow { height: 0.02 },
            ..MINDLIN_SQUARE_SS
        },
        "the obstacle (flat below, w ≥ 0.02) contradicts the simply-supported boundary",
    );
    for height in [f64::NAN, f64::INFINITY, -1e200] {
        refused(
            PlateScene {
                obstacle: PlateObstacle::FlatAbove { height },
                ..MINDLIN_DISK
            },
            &format!("obstacle height ψ = {height} must be finite"),
        );
    }
    refused(
        PlateScene {
            bending_stiffness: 0.0,
            ..MINDLIN_SQUARE
        },
        "bending stiffness D = 0",
    );
    // an obstacle at the edge's own height is admissible: the plate is pressed flat
    // against it, w ≡ 0 and λ = q everywhere
    let flat = solve(&PlateRequest {
        mesh_size: 8,
        ..PlateRequest::new(PlateScene {
            obstacle: PlateObstacle::FlatAbove { height: 0.0 },
            ..MINDLIN_DISK
        })
    })
    .unwrap();
    assert!(flat.max_deflection < 1e-10, "{flat:?}");
    let area = flat.contact_area;
    assert!(
        (flat.total_contact_force - 20.0 * area).abs() < 1e-8 * 20.0 * area,
        "{flat:?}"
    );
}

/// Nested iteration on the disk (rings 4, 8, 16, 32, 64 at q = 50): at most 5 Newton
/// steps on every level, and on the finest fewer than a cold start there.
#[test]
fn nested_iterations_stay_flat_on_the_disk() {
    assert_eq!(level_sizes(64, true), [4, 8, 16, 32, 64]);
    assert_eq!(level_sizes(24, true), [6, 12, 24]);
    assert_eq!(level_sizes(64, false), [64]);
    let levels = iteration_levels(MINDLIN_DISK, 50.0, 64, 64).unwrap();
    assert_eq!(levels.len(), 5);
    for l in &levels {
        eprintln!("{l:?}");
        assert!(l.nested <= 5, "{levels:?}");
    }
    let finest = levels.last().unwrap();
    assert!(finest.cold.unwrap() > finest.nested, "{levels:?}");
}

/// The plain pair chosen by hand locks as its cells grow against the thickness (a
/// tester's mindlin-disk at N = 32: ∫λ_h 6.5 against 18.7, without a word): warned from
/// h = t/10, and not on finer cells, where it agrees with the Stenberg pair.
#[test]
fn the_locking_plate_pair_is_warned_about_where_it_locks() {
    use fem_forms::plates::PlatePair;
    let request = |n: usize| PlateRequest {
        pair: PlatePair::P1P1P0Plain,
        thickness: 0.2,
        mesh_size: n,
        ..PlateRequest::new(MINDLIN_SQUARE)
    };
    let coarse = solve(&request(4)).unwrap();
    assert!(
        coarse.warnings.iter().any(|w| w.contains("locks")),
        "{:?}",
        coarse.warnings
    );
    // the re-test: at h ≈ t the deflection was 12–15 % low without a word; the
    // warning starts at h = t/10, and below it the pair agrees with the Stenberg one
    let middle = solve(&request(16)).unwrap();
    assert!(middle.warnings.iter().any(|w| w.contains("locks")));
    let fine = solve(&request(80)).unwrap();
    assert!(
        !fine.warnings.iter().any(|w| w.contains("locks")),
        "{:?}",
        fine.warnings
    );
    let stenberg = solve(&PlateRequest {
        pair: PlatePair::P1P2P0,
        ..request(80)
    })
    .unwrap();
    let off = fine.centre_deflection / stenberg.centre_deflection - 1.0;
    assert!(off.abs() < 1e-2, "{off}");
}
