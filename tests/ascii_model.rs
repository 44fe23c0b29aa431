//! A model written in ASCII only, used through the library as the crate docs say: its
//! load form `l` serves `energy` (a tester's all-ASCII model was told it "has no form
//! ℓ"), and its roles (system, energy, stabilization) are found by their conventional
//! names: `stabilization::inverse_constant` needs no form named at run time.

use fem_runtime::obstacle::{solve_obstacle, ObstacleOptions};
use fem_runtime::{stabilization, Coefficients, IntervalMesh};

fem_runtime::model! {
    /// A string over an obstacle, in ASCII.
    pub mod ascii_string on interval {
        unknowns: u: P1, lam: P0 >= 0;
        tests: v, mu;
        params: alpha, s;
        data: f, psi;
        forms: "
            a(u;v)         = int u'v'
            b(v;mu)        = int s v mu
            S(u,lam;v,mu)  = sum_T h_T^2 (u'' + s lam, v'' + s mu)_T
            l(v)           = int f v
            lS(v,mu)       = sum_T h_T^2 (-f, v'' + s mu)_T
            g(mu)          = int s psi mu
            B_h(u,lam;v,mu) = a(u;v) - b(v;lam) - b(u;mu) - alpha S(u,lam;v,mu)
            L_h(v,mu)       = l(v) - g(mu) - alpha lS(v,mu)
        ";
    }
}

#[test]
fn an_ascii_model_has_its_energy_and_its_inverse_constant_by_handle() {
    let mesh = IntervalMesh::uniform(-1.0, 1.0, 64).unwrap();
    // a load too small to reach the obstacle: the free string u = q(1 − x²)/2
    let q = 0.1;
    let load = move |_: &[f64]| -q;
    let obstacle = |_: &[f64]| -1.0;
    let data: [(&str, &fem_runtime::DataFn); 2] = [("f", &load), ("psi", &obstacle)];
    let c = Coefficients::new::<ascii_string::Model>(&[("alpha", 0.1), ("s", 1.0)], &data).unwrap();
    use fem_runtime::Model;
    let role = ascii_string::Model::STABILIZATION.unwrap();
    assert_eq!(
        (role.form, role.against, role.alpha),
        (
            ascii_string::Model::form(ascii_string::forms::S).unwrap(),
            ascii_string::Model::form(ascii_string::forms::a).unwrap(),
            Some(ascii_string::Model::param(ascii_string::params::alpha).unwrap())
        )
    );
    assert_eq!(
        ascii_string::Model::ENERGY,
        Some([
            ascii_string::Model::form(ascii_string::forms::a).unwrap(),
            ascii_string::Model::form(ascii_string::forms::l).unwrap()
        ])
    );
    let by_role =
        stabilization::inverse_constant::<ascii_string::Model, _>(&mesh, &c.params).unwrap();
    let by_handle = stabilization::inverse_constant_between::<ascii_string::Model, _>(
        &mesh,
        &c.params,
        ascii_string::forms::S,
        ascii_string::forms::a,
    )
    .unwrap();
    assert_eq!(by_role, by_handle);
    // a linear form has no C_I against anything (it returned 0 before)
    let e = stabilization::inverse_constant_between::<ascii_string::Model, _>(
        &mesh,
        &c.params,
        ascii_string::forms::S,
        ascii_string::forms::l,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("`l`") && e.contains("linear"), "{e}");
    let solution =
        solve_obstacle::<ascii_string::Model>(&mesh, &c, &["u"], ObstacleOptions::default())
            .unwrap();
    // ½a(u,u) − ℓ(u) of u = −q(1 − x²)/2 on (−1, 1): ½∫q²x² − ∫q²(1 − x²)/2 = −q²/3
    let energy = solution.energy::<ascii_string::Model>(&c).unwrap();
    // P1 energies converge like h² (h = 1/32 here)
    assert!((energy + q * q / 3.0).abs() < 1e-3 * q * q, "{energy}");
}

fem_runtime::model! {
    /// A string on a Winkler foundation, in ASCII: its stabilization has a primal part.
    pub mod ascii_winkler on interval {
        unknowns: u: P1, lam: P0 >= 0;
        tests: v, mu;
        params: alpha, s, k;
        data: f, psi;
        forms: "
            a(u;v)         = int u'v' + k u v
            b(v;mu)        = int s v mu
            S(u,lam;v,mu)  = sum_T h_T^2 (k u - s lam, k v - s mu)_T
            l(v)           = int f v
            lS(v,mu)       = sum_T h_T^2 (f, k v - s mu)_T
            g(mu)          = int s psi mu
            B_h(u,lam;v,mu) = a(u;v) - b(v;lam) - b(u;mu) - alpha S(u,lam;v,mu)
            L_h(v,mu)       = l(v) - g(mu) - alpha lS(v,mu)
        ";
    }
}

/// α far beyond 1/C_I makes `a − αS` indefinite: a tester's α·C_I = 1e6 was told only
/// "the matrix is not positive definite". The error names α·C_I and where C_I comes from.
#[test]
fn an_alpha_beyond_the_stability_range_is_named_when_newton_fails() {
    let mesh = IntervalMesh::uniform(-1.0, 1.0, 64).unwrap();
    let load = |_: &[f64]| -4.0;
    let obstacle = |_: &[f64]| -0.5;
    let data: [(&str, &fem_runtime::DataFn); 2] = [("f", &load), ("psi", &obstacle)];
    let params = [("alpha", 1e6), ("s", 1.0), ("k", 1.0)];
    let c = Coefficients::new::<ascii_winkler::Model>(&params, &data).unwrap();
    let c_i = stabilization::inverse_constant::<ascii_winkler::Model, _>(&mesh, &c.params).unwrap();
    assert!(1e6 * c_i > 100.0, "α·C_I = {}", 1e6 * c_i);
    let Err(e) =
        solve_obstacle::<ascii_winkler::Model>(&mesh, &c, &["u"], ObstacleOptions::default())
    else {
        panic!("α·C_I = {} was solved", 1e6 * c_i);
    };
    let e = e.to_string();
    assert!(
        e.contains("α·C_I ≥ 1") && e.contains("inverse_constant"),
        "{e}"
    );
}
