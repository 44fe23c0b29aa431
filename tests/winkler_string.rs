//! The example `winkler_string` against the closed-form contact solution of
//! docs/mathematics.md ("A string on a Winkler foundation"): contact half-width, ∫λ, u at
//! points and the energy, converging as the mesh is refined.

#![allow(
    confusable_idents,
    mixed_script_confusables,
    uncommon_codepoints,
    dead_code
)]

#[path = "../examples/winkler_string/model.rs"]
mod model;

use model::StringOnFoundation as Problem;

/// The closed-form solution on `(−L, L)`: with `m = √(k/T)`,
/// `cosh(m(L − c)) = q/(q − kd)`, `u = −d` and `λ = q − kd` on `[−c, c]`,
/// `u = −q/k + (q/k − d) cosh(m(|x| − c))` outside.
struct Exact {
    p: Problem,
    m: f64,
    c: f64,
}

impl Exact {
    fn new(p: Problem) -> Self {
        let m = (p.stiffness / p.tension).sqrt();
        let ratio = p.load / (p.load - p.stiffness * p.depth);
        let c = p.half_length - ratio.acosh() / m;
        assert!(c > 0.0, "the data must give contact");
        Exact { p, m, c }
    }
    fn u(&self, x: f64) -> f64 {
        let (q, k, d) = (self.p.load, self.p.stiffness, self.p.depth);
        if x.abs() <= self.c {
            -d
        } else {
            -q / k + (q / k - d) * (self.m * (x.abs() - self.c)).cosh()
        }
    }
    fn du(&self, x: f64) -> f64 {
        let (q, k, d) = (self.p.load, self.p.stiffness, self.p.depth);
        if x.abs() <= self.c {
            0.0
        } else {
            x.signum() * (q / k - d) * self.m * (self.m * (x.abs() - self.c)).sinh()
        }
    }
    fn force(&self) -> f64 {
        2.0 * self.c * (self.p.load - self.p.stiffness * self.p.depth)
    }
    /// `∫ ½T u'² + ½k u² − f u` with `f = −q`, by composite 5-point Gauss–Legendre on
    /// pieces that split at ±c (the integrand is smooth on each).
    fn energy(&self) -> f64 {
        let (t, k, q) = (self.p.tension, self.p.stiffness, self.p.load);
        let nodes = [
            (0.0, 128.0 / 225.0),
            (-0.538_469_310_105_683, 0.478_628_670_499_366_5),
            (0.538_469_310_105_683, 0.478_628_670_499_366_5),
            (-0.906_179_845_938_664, 0.236_926_885_056_189_1),
            (0.906_179_845_938_664, 0.236_926_885_056_189_1),
        ];
        let l = self.p.half_length;
        let mut total = 0.0;
        for (a, b) in [(-l, -self.c), (-self.c, self.c), (self.c, l)] {
            let pieces = 200;
            let h = (b - a) / pieces as f64;
            for i in 0..pieces {
                let mid = a + (i as f64 + 0.5) * h;
                for &(s, w) in &nodes {
                    let x = mid + 0.5 * h * s;
                    let (u, du) = (self.u(x), self.du(x));
                    total += 0.5 * h * w * (0.5 * t * du * du + 0.5 * k * u * u + q * u);
                }
            }
        }
        total
    }
}

fn problem() -> Problem {
    Problem {
        half_length: 1.0,
        tension: 1.0,
        stiffness: 1.0,
        load: 4.0,
        depth: 0.5,
    }
}

#[test]
fn the_exact_solution_solves_the_problem() {
    // A check of the formulas themselves: the ODE outside, the C¹ matching at c, u(L) = 0,
    // u ≥ −d and λ ≥ 0.
    let e = Exact::new(problem());
    let (t, k, q, d) = (1.0, 1.0, 4.0, 0.5);
    assert!((e.u(1.0)).abs() < 1e-14);
    assert!((e.u(e.c + 1e-12) + d).abs() < 1e-10 && e.du(e.c + 1e-12).abs() < 1e-10);
    for x in [0.5, 0.7, 0.9] {
        let h = 1e-4;
        let second = (e.u(x + h) - 2.0 * e.u(x) + e.u(x - h)) / (h * h);
        assert!((t * second - k * e.u(x) - q).abs() < 1e-6, "ODE at {x}");
        assert!(e.u(x) >= -d);
    }
    assert!(q - k * d > 0.0);
    // c = 1 − arccosh(8/7) = 0.47158…
    assert!((e.c - 0.4715_8).abs() < 1e-4, "{}", e.c);
}

#[test]
fn the_example_converges_to_the_closed_form_contact_solution() {
    let exact = Exact::new(problem());
    let mut previous: Option<[f64; 4]> = None;
    for cells in [32, 64, 128, 256] {
        let h = 2.0 / cells as f64;
        let solved = problem().solve(cells).unwrap();
        let s = &solved.solution;
        // C_I ≤ h²k (the module docs of the model): a P1 cell attains it
        let c_i = solved.report.inverse_constant;
        assert!(c_i <= h * h * (1.0 + 1e-9), "C_I");
        assert_eq!(solved.report.alpha, Some(0.1));
        // the contact cells: all those well inside [−c, c], none well outside
        let cells_in_contact = s.contact_cells();
        for cell in 0..cells {
            let mid = -1.0 + (cell as f64 + 0.5) * h;
            if mid.abs() < exact.c - h {
                assert!(cells_in_contact.contains(&cell), "cell {cell} of {cells}");
            } else if mid.abs() > exact.c + h {
                assert!(!cells_in_contact.contains(&cell), "cell {cell} of {cells}");
            }
        }
        let set = s.contact_set();
        assert_eq!(
            set.len(),
            1,
            "{cells} cells: one contact interval, got {set:?}"
        );
        let [left, right] = set[0];
        let width_error = ((right - left) / 2.0 - exact.c)
            .abs()
            .max((left + right).abs());
        // P0 λ resolves the free boundary to within a cell.
        assert!(
            width_error <= h,
            "{cells} cells: contact set {set:?}, c = {}",
            exact.c
        );
        let force_error = (s.total_contact_force() - exact.force()).abs();
        let u = s.view(0);
        let u_error = [0.0, 0.3, 0.5, 0.75, 0.9, -0.6]
            .iter()
            .map(|&x| (u.at(x, 0).unwrap() - exact.u(x)).abs())
            .fold(0.0, f64::max);
        let energy_error = (solved.report.energy.unwrap() - exact.energy()).abs();
        assert!(force_error < 2.0 * h, "{cells}: ∫λ error {force_error}");
        assert!(u_error < h * h, "{cells}: u error {u_error}");
        assert!(energy_error < h * h, "{cells}: energy error {energy_error}");
        let errors = [width_error, force_error, u_error, energy_error];
        if let Some(before) = previous {
            // the errors fall with h (the contact width by at most one cell at a time)
            assert!(
                force_error < 0.75 * before[1] || force_error < 1e-3 * h,
                "∫λ"
            );
            assert!(u_error < 0.75 * before[2] || u_error < 1e-10, "u");
            assert!(
                energy_error < 0.75 * before[3] || energy_error < 1e-10,
                "energy"
            );
        }
        previous = Some(errors);
        eprintln!("{cells} cells: {errors:?}");
    }
}

/// The example's estimator is derived from its forms (`estimator: derived`): over an
/// adaptive run from 8 cells its efficiency index against the closed-form solution stays
/// in a band (energy norm `(T‖e'‖² + k‖e‖²)^{1/2}`, here with T = k = 1 measured by the
/// H¹ seminorm in the energy norm's units), and the error falls like N^{-1}, the P1
/// rate, through the kinks at ±c.
#[test]
fn the_derived_estimator_is_efficient_over_an_adaptive_run() {
    let (for_value, for_gradient) = (Exact::new(problem()), Exact::new(problem()));
    let value = move |x: &[f64]| for_value.u(x[0]);
    let gradient = move |x: &[f64]| [for_gradient.du(x[0]), 0.0];
    let solved = problem()
        .solve_adaptive(
            8,
            2e-3,
            Some(fem_runtime::problem::Exact {
                value: &value,
                gradient: Some(&gradient),
                hessian: None,
                multiplier: None,
            }),
        )
        .unwrap();
    let levels = &solved.report.adaptive_levels;
    assert!(levels.len() >= 4, "{} levels", levels.len());
    let indices: Vec<f64> = levels
        .iter()
        .map(|l| l.estimate / l.error_energy.unwrap())
        .collect();
    let (low, high) = indices
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &x| (a.min(x), b.max(x)));
    // measured: 3.8 to 4.3 over 26 levels, 15 to 6359 unknowns
    assert!(
        low > 1.0 && high / low < 2.0,
        "efficiency indices {indices:?}"
    );
    let (first, last) = (levels[0], levels[levels.len() - 1]);
    let rate = -(last.error_energy.unwrap() / first.error_energy.unwrap()).ln()
        / (last.dofs as f64 / first.dofs as f64).ln();
    assert!(rate > 0.8, "error ~ N^-{rate:.2}");
}
