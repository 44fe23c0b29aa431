//! A string on a Winkler foundation over an obstacle (docs/mathematics.md, "A string on
//! a Winkler foundation"): tension `T`, foundation stiffness `k`, load `f`, obstacle
//! `u ≥ ψ` (side `s = 1`), `−T u'' + k u − sλ = f`, `λ ≥ 0`, `s(u − ψ) ≥ 0`,
//! `λ s(u − ψ) = 0`.
//!
//! Deflection `u ∈ P1`, multiplier `λ ∈ P0`. `u'' ≡ 0` on each P1 cell, so the residual
//! in `S_h` is `k u − sλ`; its primal part `h² k² ‖v‖²` is bounded by `h² k a_T(v, v)`,
//! so `C_I ≤ h² k` and any `0 < α < 1/C_I` is stable.

use fem_runtime::obstacle::{solve_obstacle, ObstacleOptions, ObstacleSolution};
use fem_runtime::{stabilization, Coefficients, IntervalMesh, Result};

fem_runtime::model! {
    /// String on a Winkler foundation, u ∈ P1, λ ∈ P0.
    pub mod winkler_string on interval {
        unknowns: u: P1, λ: P0 >= 0;
        tests: v, μ;
        params: α, s, T, k;
        data: f, ψ;
        forms: "
            a(u;v)     = ∫ T u'v' + k u v
            b(v;μ)     = ∫ s v μ
            S(u,λ;v,μ) = Σ_T h_T² (−T u'' + k u − sλ, −T v'' + k v − sμ)_T
            ℓ(v)       = ∫ f v
            ℓ_S(v,μ)   = Σ_T h_T² (f, −T v'' + k v − sμ)_T
            g(μ)       = ∫ s ψ μ
            B_h(u,λ;v,μ) = a(u;v) − b(v;λ) − b(u;μ) − α S(u,λ;v,μ)
            L_h(v,μ)     = ℓ(v) − g(μ) − α ℓ_S(v,μ)
        ";
    }
}

/// A solved [`Problem`].
pub struct Solved {
    /// The discrete solution (`u` is field 0, `λ` field 1).
    pub solution: ObstacleSolution,
    /// `½ a(u_h, u_h) − ℓ(u_h)`.
    pub energy: f64,
    /// The element constant `C_I` of `S` against `a` on the mesh.
    pub inverse_constant: f64,
}

/// A string of length `2L` on `(−L, L)`, clamped `u(±L) = 0`, under the uniform load
/// `−q`, over the flat obstacle `u ≥ −d`.
#[derive(Clone, Copy, Debug)]
pub struct Problem {
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
    /// Stabilization parameter α.
    pub alpha: f64,
}

impl Problem {
    /// Solves the stabilized VI on a uniform mesh of `cells` cells by nested semismooth
    /// Newton.
    ///
    /// # Errors
    /// A mesh that cannot be built, `α C_I ≥ 1` (unstable), or a solver failure.
    pub fn solve(&self, cells: usize) -> Result<Solved> {
        let mesh = IntervalMesh::uniform(-self.half_length, self.half_length, cells)?;
        let (q, d) = (self.load, self.depth);
        let load = move |_: &[f64]| -q;
        let obstacle = move |_: &[f64]| -d;
        let params = [
            ("α", self.alpha),
            ("s", 1.0),
            ("T", self.tension),
            ("k", self.stiffness),
        ];
        let coefficients =
            Coefficients::new::<winkler_string::Model>(&params, &[("f", &load), ("ψ", &obstacle)])?;
        let c_i = stabilization::inverse_constant::<winkler_string::Model, _>(
            &mesh,
            &coefficients.params,
        )?;
        if self.alpha * c_i >= 1.0 {
            return Err(fem_runtime::Error::Input(format!(
                "α = {} is outside the stability range 0 < α < 1/C_I = {}",
                self.alpha,
                1.0 / c_i
            )));
        }
        let solution = solve_obstacle::<winkler_string::Model>(
            &mesh,
            &coefficients,
            &["u"],
            ObstacleOptions::default(),
        )?;
        let energy = solution.energy::<winkler_string::Model>(&coefficients)?;
        Ok(Solved {
            solution,
            energy,
            inverse_constant: c_i,
        })
    }
}
