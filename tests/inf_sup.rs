//! The stability study's one measure of every family (the discrete inf-sup constants of
//! the multiplier in the stabilization's norm, formed from the one solve's LCP:
//! `fem_runtime::stabilization::inf_sup_spectrum`) against a hand-coded version for the
//! membrane that assembles the system itself and weights by `h_T² |T|` from the mesh:
//! the two agree on the radial membrane, and the identities of the method hold (the
//! stabilized γ₁ ≥ α; the plain P1–P0 pair has a kernel).

#[path = "common/membranes.rs"]
mod membranes;

use fem_forms::lcp::cholesky::Cholesky;
use fem_forms::models::families;
use fem_forms::models::membrane::{membrane_p1_p0, membrane_p2_p0};
use fem_forms::models::membrane_scenes::{membrane_scene, MembraneScene};
use fem_forms::obstacle::system_forms;
use fem_forms::obstacle::triangle::discretize_on_part;
use fem_forms::obstacle::Discretization;
use fem_forms::registry_studies::RegistryStudies;
use fem_forms::studies::StudyScene;
use fem_forms::{DirichletPart, Error, Model, Result, TriangleMesh};
use nalgebra::{DMatrix, SymmetricEigen};

/// Hand-coded, independent of the one measure: discrete inf-sup constants of the
/// multiplier assembled here from the membrane's data and weighted by the mesh, `γ_k = λ_k(M_h⁻¹ (B A⁻¹ Bᵀ + C))` in the
/// h-weighted norm `‖μ‖²_h = Σ_T h_T² ‖μ‖²_T`, the smallest two (√ of them are the
/// inf-sup constants; the stabilized method has γ ≥ α by construction).
fn inf_sup<M: Model>(scene: &MembraneScene, mesh: &TriangleMesh, alpha: f64) -> Result<[f64; 2]> {
    let data = membranes::SceneData::new(scene);
    let coefficients = data.coefficients::<M>(alpha);
    // u = g on the whole boundary (the radial scene's)
    let part = DirichletPart::All;
    let (bilinear, linear) = system_forms::<M>()?;
    let d: Discretization<TriangleMesh> =
        discretize_on_part::<M>(mesh, &coefficients, &part, bilinear, linear)?;
    let lcp = &d.lcp;
    let (n, m) = (lcp.n(), lcp.m());
    if m > 4000 {
        return Err(Error::Input(format!(
            "the inf-sup eigenproblem is dense: {m} multipliers is too many"
        )));
    }
    let pattern = lcp
        .a
        .symbolic()
        .to_owned()
        .map_err(|e| Error::LinearSolve(format!("{e:?}")))?;
    let factor = Cholesky::analyse(&pattern)?.factor(&lcp.a)?;
    // columns of A⁻¹Bᵀ, then S = B A⁻¹ Bᵀ + C
    let mut x = DMatrix::<f64>::zeros(n, m);
    for k in 0..m {
        let mut column = vec![0.0; n];
        for &(j, v) in &lcp.b_rows[k] {
            column[j] = v;
        }
        let solved = factor.solve(&column)?;
        x.column_mut(k).copy_from_slice(&solved);
    }
    let mut s = DMatrix::<f64>::zeros(m, m);
    for k in 0..m {
        for l in 0..m {
            s[(k, l)] = lcp.b_rows[k].iter().map(|&(j, v)| v * x[(j, l)]).sum();
        }
        s[(k, k)] += lcp.c[k];
    }
    let weight: Vec<f64> = d
        .multiplier_dofs()
        .iter()
        .map(|&cell| {
            let h = d.mesh.cell_diameter(cell);
            (h * h * d.mesh.area(cell)).sqrt()
        })
        .collect();
    for k in 0..m {
        for l in 0..m {
            s[(k, l)] /= weight[k] * weight[l];
        }
    }
    let s = (&s + s.transpose()) * 0.5;
    let mut values: Vec<f64> = SymmetricEigen::new(s).eigenvalues.iter().cloned().collect();
    values.sort_by(f64::total_cmp);
    Ok([values[0], values.get(1).copied().unwrap_or(f64::NAN)])
}

#[test]
fn the_one_inf_sup_measure_agrees_with_a_hand_coded_one() {
    let one = RegistryStudies::new(families::scene("membrane-radial").unwrap());
    let scene = membrane_scene("membrane-radial").unwrap();
    for pair in ["p1-p0", "p2-p0"] {
        for n in [4, 8] {
            let a = one.stability(pair, n).unwrap();
            let mesh = membranes::mesh(&scene, n);
            let (alpha, plain, stabilized) = match pair {
                "p1-p0" => {
                    let alpha = membranes::alpha::<membrane_p1_p0::Model>(&mesh);
                    (
                        alpha,
                        inf_sup::<membrane_p1_p0::Model>(&scene, &mesh, 0.0).unwrap(),
                        inf_sup::<membrane_p1_p0::Model>(&scene, &mesh, alpha).unwrap(),
                    )
                }
                _ => {
                    let alpha = membranes::alpha::<membrane_p2_p0::Model>(&mesh);
                    (
                        alpha,
                        inf_sup::<membrane_p2_p0::Model>(&scene, &mesh, 0.0).unwrap(),
                        inf_sup::<membrane_p2_p0::Model>(&scene, &mesh, alpha).unwrap(),
                    )
                }
            };
            assert!((a.alpha - alpha).abs() <= 1e-12 * alpha, "{pair} {n}");
            for (x, y) in a.stabilized.iter().zip(&stabilized) {
                assert!(
                    (x - y).abs() <= 1e-9 * y.abs(),
                    "{pair} {n}: {a:?} {stabilized:?}"
                );
            }
            // the plain method's: P1–P0 has more multipliers than the primal space holds
            // (a kernel, zero to rounding in both), P2–P0's smallest two agree
            if pair == "p1-p0" {
                assert!(
                    a.plain.iter().chain(&plain).all(|g| g.abs() < 1e-12),
                    "{a:?} {plain:?}"
                );
            } else {
                for (x, y) in a.plain.iter().zip(&plain) {
                    assert!(
                        (x - y).abs() <= 1e-9 * y.abs(),
                        "{pair} {n}: {a:?} {plain:?}"
                    );
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
