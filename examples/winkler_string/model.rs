//! A string on a Winkler foundation over an obstacle (docs/mathematics.md, "A string on
//! a Winkler foundation"): tension `T`, foundation stiffness `k`, load `f`, obstacle
//! `u ≥ ψ`, `−T u'' + k u − λ = f`, `λ ≥ 0`, `u ≥ ψ`, `λ (u − ψ) = 0`.
//!
//! Deflection `u ∈ P1`, multiplier `λ ∈ P0`. `u'' ≡ 0` on each P1 cell, so the residual
//! in `S_h` is `k u − sλ`; its primal part `h² k² ‖v‖²` is bounded by `h² k a_T(v, v)`,
//! so `C_I ≤ h² k` (the runtime computes it from the declared roles and checks α
//! against it). Its rule `α = ½/C_I` would grow like `1/h²` here and make `α S_h` of
//! order one, so the string takes a fixed α = 0.1, well inside `0 < α < 1/C_I`.
//!
//! Its estimator is not written but derived from the forms (`estimator: derived`,
//! docs/adaptivity.md): `h_T² ‖f + sλ + T u'' − k u‖²` on the cells and `h_E [[T u']]²` at
//! the interior nodes, so the string can be solved to a tolerance
//! ([`StringOnFoundation::solve_adaptive`]).

use fem_runtime::adaptivity::AdaptiveOptions;
use fem_runtime::problem::{Condition, Exact, Problem, Solved, ALPHA_WHEN_CI_VANISHES};
use fem_runtime::stabilization::Alpha;
use fem_runtime::{DirichletPart, IntervalMesh, Result};

fem_runtime::model! {
    /// String on a Winkler foundation, u ∈ P1, λ ∈ P0.
    pub mod winkler_string on interval {
        unknowns: u: P1, λ: P0 >= 0;
        tests: v, μ;
        params: α, s, T > 0, k;
        data: f, ψ;
        forms: "
            a(u;v)     = ∫ T u'v' + k u v
            b(v;μ)     = ∫ s v μ
            S(u,λ;v,μ) = Σ_T h_T² (−T u'' + k u − sλ, −T v'' + k v − sμ)_T
            ℓ(v)       = ∫ f v
            ℓ_S(v,μ)   = Σ_T h_T² (f, −T v'' + k v − sμ)_T
            G(μ)       = ∫ s ψ μ
            B_h(u,λ;v,μ) = a(u;v) − b(v;λ) − b(u;μ) − α S(u,λ;v,μ)
            L_h(v,μ)     = ℓ(v) − G(μ) − α ℓ_S(v,μ)
        ";
        system:        B_h, L_h;
        energy:        a, ℓ;
        stabilization: α S against a;
        side:          s;
        obstacle:      u >= ψ;
        estimator:     derived;
    }
}

use winkler_string::{data, fields, params, Model};

/// A string of length `2L` on `(−L, L)`, clamped `u(±L) = 0`, under the uniform load
/// `−q`, over the flat obstacle `u ≥ −d`.
#[derive(Clone, Copy, Debug)]
pub struct StringOnFoundation {
    /// Half-length `L`.
    pub half_length: f64,
    /// Tension `T > 0`.
    pub tension: f64,
    /// Foundation stiffness `k > 0`.
    pub stiffness: f64,
    /// Load magnitude `q` (the load is `f = −q`).
    pub load: f64,
    /// Obstacle depth `d > 0` (the obstacle is `ψ = −d`).
    pub depth: f64,
}

impl StringOnFoundation {
    /// Solves the stabilized VI on a uniform mesh of `cells` cells (α = 0.1).
    ///
    /// # Errors
    /// A mesh that cannot be built, and the solve's errors.
    pub fn solve(&self, cells: usize) -> Result<Solved<Model, IntervalMesh>> {
        self.solve_with(cells, None, None)
    }

    /// Solves adaptively from a uniform mesh of `cells` cells until the derived
    /// estimate is below `tolerance` times the energy norm (bisection of the cells
    /// Dörfler marks), reporting the true error of every level against `exact` where
    /// given.
    ///
    /// # Errors
    /// As [`StringOnFoundation::solve`], and the adaptive loop's (the unknowns' limit).
    pub fn solve_adaptive(
        &self,
        cells: usize,
        tolerance: f64,
        exact: Option<Exact>,
    ) -> Result<Solved<Model, IntervalMesh>> {
        self.solve_with(cells, Some(tolerance), exact)
    }

    fn solve_with(
        &self,
        cells: usize,
        tolerance: Option<f64>,
        exact: Option<Exact>,
    ) -> Result<Solved<Model, IntervalMesh>> {
        let mesh = IntervalMesh::uniform(-self.half_length, self.half_length, cells)?;
        let (q, d) = (self.load, self.depth);
        let load = move |_: &[f64]| -q;
        let obstacle = move |_: &[f64]| -d;
        let mut problem = Problem::<Model, IntervalMesh>::new(vec![mesh])
            .param(params::T, self.tension)
            .param(params::k, self.stiffness)
            .alpha(Alpha::Fixed(0.1), ALPHA_WHEN_CI_VANISHES)
            .data(data::f, &load)
            .data(data::ψ, &obstacle)
            .support(DirichletPart::All, fields::u, Condition::Zero);
        if let Some(exact) = exact {
            problem = problem.exact(exact);
        }
        match tolerance {
            None => problem.solve(),
            Some(tolerance) => problem.solve_adaptive(
                AdaptiveOptions {
                    tolerance,
                    ..AdaptiveOptions::default()
                },
                |_| {},
            ),
        }
    }
}
