//! The stability study's one measure of every family (the discrete inf-sup constants of
//! the multiplier in the stabilization's norm, formed from the one solve's LCP:
//! `fem_runtime::stabilization::inf_sup_spectrum`) against the membranes' own
//! implementation, which assembles the system itself and weights by `h_T² |T|` from the
//! mesh: the two agree on the radial membrane, and the identities of the method hold
//! (the stabilized γ₁ ≥ α; the plain P1–P0 pair has a kernel).

use fem_forms::membrane_studies::MembraneStudies;
use fem_forms::models::families;
use fem_forms::models::membrane_scenes::membrane_scene;
use fem_forms::registry_studies::RegistryStudies;
use fem_forms::studies::StudyScene;

#[test]
fn the_one_inf_sup_measure_agrees_with_the_membranes_own() {
    let one = RegistryStudies::new(families::scene("membrane-radial").unwrap());
    let own = MembraneStudies::new(membrane_scene("membrane-radial").unwrap());
    for pair in ["p1-p0", "p2-p0"] {
        for n in [4, 8] {
            let a = one.stability(pair, n).unwrap();
            let b = own.stability(pair, n).unwrap();
            assert!((a.alpha - b.alpha).abs() <= 1e-12 * b.alpha, "{pair} {n}");
            for (x, y) in a.stabilized.iter().zip(&b.stabilized) {
                assert!((x - y).abs() <= 1e-9 * y.abs(), "{pair} {n}: {a:?} {b:?}");
            }
            // the plain method's: P1–P0 has more multipliers than the primal space holds
            // (a kernel, zero to rounding in both), P2–P0's smallest two agree
            if pair == "p1-p0" {
                assert!(
                    a.plain.iter().chain(&b.plain).all(|g| g.abs() < 1e-12),
                    "{a:?} {b:?}"
                );
            } else {
                for (x, y) in a.plain.iter().zip(&b.plain) {
                    assert!((x - y).abs() <= 1e-9 * y.abs(), "{pair} {n}: {a:?} {b:?}");
                }
            }
            // C = αD: the stabilized γ₁ is at least α, whatever the pair
            assert!(a.stabilized[0] >= a.alpha * (1.0 - 1e-12), "{a:?}");
        }
    }
}

/// A family with no study code of its own hosts the stability study through the one
/// implementation: the Winkler plate's Argyris–P0 pair is stable without stabilization
/// (γ₁ bounded away from 0 as h falls), and the stabilization only lifts it.
#[test]
fn the_winkler_plate_hosts_the_stability_study() {
    let one = RegistryStudies::new(families::scene("winkler-square").unwrap());
    let rows: Vec<_> = [4, 8]
        .iter()
        .map(|&n| one.stability("argyris-p0", n).unwrap())
        .collect();
    for r in &rows {
        assert!(r.plain[0] > 1e-6 && r.stabilized[0] >= r.plain[0], "{r:?}");
    }
    assert!(rows[1].plain[0] > 0.5 * rows[0].plain[0], "{rows:?}");
}
