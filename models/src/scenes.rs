//! The beam scenes: data (a name, a beam model, an obstacle, a load, a thickness), not
//! code paths. docs/mathematics.md §3–§4.
//!
//! All beams are clamped at both ends of (0, 1). `s = +1` is an obstacle below
//! (`w ≥ ψ`), `s = −1` one above (`w ≤ ψ`); the load is `f = load_sign · q`.

/// The beam theory of a scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Beam {
    /// Timoshenko (rotation θ and deflection w, thickness t).
    Timoshenko,
    /// Euler–Bernoulli (deflection w).
    EulerBernoulli,
}

/// An obstacle profile ψ(x).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Obstacle {
    /// `a x² + b x + c`
    Parabola {
        /// x² coefficient
        a: f64,
        /// x coefficient
        b: f64,
        /// constant
        c: f64,
    },
    /// `ψ = c`
    Constant(f64),
}

impl Obstacle {
    /// ψ(x).
    pub fn at(&self, x: f64) -> f64 {
        match *self {
            Obstacle::Parabola { a, b, c } => a * x * x + b * x + c,
            Obstacle::Constant(c) => c,
        }
    }
}

/// A scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scene {
    /// Its name on the command line.
    pub name: &'static str,
    /// One line of description.
    pub description: &'static str,
    /// The beam theory.
    pub beam: Beam,
    /// The obstacle.
    pub obstacle: Obstacle,
    /// `+1`: obstacle below (`w ≥ ψ`); `−1`: above (`w ≤ ψ`).
    pub side: f64,
    /// The load is `f = load_sign · q`.
    pub load_sign: f64,
    /// Thickness (Timoshenko).
    pub thickness: f64,
    /// The load magnitude q a solve poses unless asked otherwise.
    pub load: f64,
}

const CASE_A: Obstacle = Obstacle::Parabola {
    a: -0.4,
    b: 0.4,
    c: -0.15,
};
const CASE_B: Obstacle = Obstacle::Constant(0.05);

/// Every scene.
pub const SCENES: [Scene; 8] = [
    Scene {
        name: "timoshenko-a",
        description: "Timoshenko beam pressed down onto ψ = −0.4x²+0.4x−0.15 (w ≥ ψ, f = −q)",
        beam: Beam::Timoshenko,
        obstacle: CASE_A,
        side: 1.0,
        load_sign: -1.0,
        thickness: 1e-3,
        load: 1.0,
    },
    Scene {
        name: "timoshenko-b",
        description: "Timoshenko beam pushed up against ψ = 0.05 (w ≤ ψ, f = +q)",
        beam: Beam::Timoshenko,
        obstacle: CASE_B,
        side: -1.0,
        load_sign: 1.0,
        thickness: 1e-3,
        load: 1.0,
    },
    Scene {
        name: "bernoulli-a",
        description: "Euler–Bernoulli beam pressed down onto ψ = −0.4x²+0.4x−0.15 (w ≥ ψ, f = −q)",
        beam: Beam::EulerBernoulli,
        obstacle: CASE_A,
        side: 1.0,
        load_sign: -1.0,
        thickness: 0.0,
        load: 1.0,
    },
    Scene {
        name: "bernoulli-b",
        description: "Euler–Bernoulli beam pushed up against ψ = 0.05 (w ≤ ψ, f = +q)",
        beam: Beam::EulerBernoulli,
        obstacle: CASE_B,
        side: -1.0,
        load_sign: 1.0,
        thickness: 0.0,
        load: 1.0,
    },
    Scene {
        name: "bernoulli-flat",
        description: "Euler–Bernoulli beam pressed down onto a flat ψ = −0.05 (exact solution; contact interval for q > 57.6)",
        beam: Beam::EulerBernoulli,
        obstacle: Obstacle::Constant(-0.05),
        side: 1.0,
        load_sign: -1.0,
        thickness: 0.0,
        load: 1.0,
    },
    Scene {
        name: "timoshenko-t1e-1",
        description: "thick Timoshenko beam (t = 0.1) pressed down by q = 40 onto ψ = −0.4x²+0.4x−0.15: the shear matters at every tolerance",
        beam: Beam::Timoshenko,
        obstacle: CASE_A,
        side: 1.0,
        load_sign: -1.0,
        thickness: 1e-1,
        load: 40.0,
    },
    Scene {
        name: "timoshenko-t1e-2",
        description: "Timoshenko beam (t = 0.01) pressed down by q = 40 onto ψ = −0.4x²+0.4x−0.15: Euler–Bernoulli only at loose tolerances",
        beam: Beam::Timoshenko,
        obstacle: CASE_A,
        side: 1.0,
        load_sign: -1.0,
        thickness: 1e-2,
        load: 40.0,
    },
    Scene {
        name: "timoshenko-t1e-3",
        description: "thin Timoshenko beam (t = 0.001) pressed down by q = 40 onto ψ = −0.4x²+0.4x−0.15: Euler–Bernoulli is adequate to about 2 %",
        beam: Beam::Timoshenko,
        obstacle: CASE_A,
        side: 1.0,
        load_sign: -1.0,
        thickness: 1e-3,
        load: 40.0,
    },
];

/// The scene called `name`.
pub fn scene(name: &str) -> Option<Scene> {
    SCENES.iter().copied().find(|s| s.name == name)
}

/// An exact solution: deflection (and rotation) with derivatives, contact set and force.
pub struct ExactSolution {
    /// `w^{(k)}(x)` for k = 0, 1, 2.
    pub w: Box<dyn Fn(f64, usize) -> f64 + Send + Sync>,
    /// `θ^{(k)}(x)` (Timoshenko) for k = 0, 1.
    pub theta: Option<Box<dyn Fn(f64, usize) -> f64 + Send + Sync>>,
    /// Contact intervals (a point contact as `[x, x]`).
    pub contact_set: Vec<[f64; 2]>,
    /// `∫ λ` (point forces included).
    pub total_contact_force: f64,
}

/// The clamped beam under the uniform load `f` without obstacle: Euler–Bernoulli
/// `w = f x²(1−x)²/24`; Timoshenko adds `f t² x(1−x)/2` and `θ = f x(2x−1)(x−1)/12`.
fn free(beam: Beam, f: f64, t: f64) -> ExactSolution {
    let shear = if beam == Beam::Timoshenko { t * t } else { 0.0 };
    let w = move |x: f64, k: usize| -> f64 {
        let bending = match k {
            0 => x * x * (1.0 - x).powi(2) / 24.0,
            1 => (2.0 * x - 6.0 * x * x + 4.0 * x.powi(3)) / 24.0,
            _ => (2.0 - 12.0 * x + 12.0 * x * x) / 24.0,
        };
        let shearing = match k {
            0 => x * (1.0 - x) / 2.0,
            1 => (1.0 - 2.0 * x) / 2.0,
            _ => -1.0,
        };
        f * (bending + shear * shearing)
    };
    let theta = move |x: f64, k: usize| -> f64 {
        match k {
            0 => f * (2.0 * x.powi(3) - 3.0 * x * x + x) / 12.0,
            _ => f * (6.0 * x * x - 6.0 * x + 1.0) / 12.0,
        }
    };
    ExactSolution {
        w: Box::new(w),
        theta: (beam == Beam::Timoshenko)
            .then(|| Box::new(theta) as Box<dyn Fn(f64, usize) -> f64 + Send + Sync>),
        contact_set: Vec::new(),
        total_contact_force: 0.0,
    }
}

/// The exact solution of `scene` at load `q` and thickness `t`, where one is known: when
/// the free beam does not touch the obstacle, and for `bernoulli-flat` and its mirror
/// image `bernoulli-b` always.
pub fn exact_solution(scene: &Scene, q: f64, t: f64) -> Option<ExactSolution> {
    let f = scene.load_sign * q;
    let free_solution = free(scene.beam, f, t);
    let touches = (0..=1000).any(|i| {
        let x = i as f64 / 1000.0;
        scene.side * ((free_solution.w)(x, 0) - scene.obstacle.at(x)) < 0.0
    });
    if !touches {
        return Some(free_solution);
    }
    match (scene.beam, scene.obstacle, scene.side, scene.load_sign) {
        (Beam::EulerBernoulli, Obstacle::Constant(psi), s, sign)
            if s == 1.0 && sign == -1.0 && psi < 0.0 =>
        {
            Some(flat_obstacle(q, -psi))
        }
        // the mirror image (w ↦ −w): pushed up by +q against w ≤ d, as bernoulli-b; its
        // solution is bernoulli-flat's mirrored, and so is its exact solution
        (Beam::EulerBernoulli, Obstacle::Constant(psi), s, sign)
            if s == -1.0 && sign == 1.0 && psi > 0.0 =>
        {
            let below = flat_obstacle(q, psi);
            let w = below.w;
            Some(ExactSolution {
                w: Box::new(move |x, k| -w(x, k)),
                ..below
            })
        }
        _ => None,
    }
}

/// Clamped Euler–Bernoulli beam, load `−q`, flat obstacle `w ≥ −d`, in contact.
///
/// Point contact at ½ (`384 d < q ≤ 1152 d`): the free deflection plus a central point
/// force `P = q/2 − 192 d` (the clamped beam's central deflection under P is P/192).
/// Contact interval `[a, 1−a]` (`q > 1152 d`): on `(0, a)`, `w'''' = −q` with
/// `w(0) = w'(0) = 0`, and the matching conditions `w(a) = −d, w'(a) = 0, w''(a) = 0`
/// give `w = −q x⁴/24 + q a x³/9 − q a² x²/12` and `q a⁴/72 = d`; λ is `q` on the
/// interval plus point forces `q a/3` at its ends (the jumps of w''').
fn flat_obstacle(q: f64, d: f64) -> ExactSolution {
    if q <= 1152.0 * d {
        let p = q / 2.0 - 192.0 * d;
        // clamped–clamped deflection under a unit central point force, on x ≤ ½
        let g = |x: f64, k: usize| -> f64 {
            match k {
                0 => x * x * (3.0 - 4.0 * x) / 48.0,
                1 => x * (1.0 - 2.0 * x) / 8.0,
                _ => (1.0 - 4.0 * x) / 8.0,
            }
        };
        let free_w = free(Beam::EulerBernoulli, -q, 0.0).w;
        let w = move |x: f64, k: usize| -> f64 {
            let point = if x <= 0.5 {
                g(x, k)
            } else {
                // mirror: g(1 − x), odd derivatives change sign
                g(1.0 - x, k) * if k % 2 == 1 { -1.0 } else { 1.0 }
            };
            free_w(x, k) + p * point
        };
        return ExactSolution {
            w: Box::new(w),
            theta: None,
            contact_set: vec![[0.5, 0.5]],
            total_contact_force: p,
        };
    }
    let a = (72.0 * d / q).powf(0.25);
    let left = move |x: f64, k: usize| -> f64 {
        match k {
            0 => -q * x.powi(4) / 24.0 + q * a * x.powi(3) / 9.0 - q * a * a * x * x / 12.0,
            1 => -q * x.powi(3) / 6.0 + q * a * x * x / 3.0 - q * a * a * x / 6.0,
            _ => -q * x * x / 2.0 + 2.0 * q * a * x / 3.0 - q * a * a / 6.0,
        }
    };
    let w = move |x: f64, k: usize| -> f64 {
        if x <= a {
            left(x, k)
        } else if x >= 1.0 - a {
            left(1.0 - x, k) * if k % 2 == 1 { -1.0 } else { 1.0 }
        } else if k == 0 {
            -d
        } else {
            0.0
        }
    };
    ExactSolution {
        w: Box::new(w),
        theta: None,
        contact_set: vec![[a, 1.0 - a]],
        total_contact_force: q * (1.0 - 2.0 * a) + 2.0 * q * a / 3.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The flat-obstacle solution is continuous with two continuous derivatives at the
    /// free boundary, stays above the obstacle, and balances the load.
    #[test]
    fn flat_obstacle_solution_is_consistent() {
        for q in [100.0, 40.0] {
            let e = flat_obstacle(q, 0.05);
            let a = e.contact_set[0][0];
            for k in 0..3 {
                let (l, r) = ((e.w)(a - 1e-9, k), (e.w)(a + 1e-9, k));
                assert!(
                    (l - r).abs() < 1e-6,
                    "q = {q}, w^({k}) jumps at {a}: {l} vs {r}"
                );
            }
            for i in 0..=100 {
                assert!((e.w)(i as f64 / 100.0, 0) >= -0.05 - 1e-15);
            }
            // vertical equilibrium: load q = contact force + clamp reactions 2·(−w'''(0))
            let h = 1e-4;
            let w3 = ((e.w)(2.0 * h, 2) - (e.w)(h, 2)) / h; // w''' near 0 (w'' is smooth there)
            let reactions = 2.0 * w3;
            assert!(
                (q - e.total_contact_force - reactions).abs() < 1e-2 * q,
                "q = {q}: force {} + reactions {reactions}",
                e.total_contact_force
            );
        }
    }

    #[test]
    fn free_solutions_solve_the_equations() {
        // w'''' = f for Euler–Bernoulli: check the fourth difference of w.
        let e = free(Beam::EulerBernoulli, 3.0, 0.0);
        let h = 1e-2;
        let x = 0.3;
        let d4 = ((e.w)(x + 2.0 * h, 0) - 4.0 * (e.w)(x + h, 0) + 6.0 * (e.w)(x, 0)
            - 4.0 * (e.w)(x - h, 0)
            + (e.w)(x - 2.0 * h, 0))
            / h.powi(4);
        assert!((d4 - 3.0).abs() < 1e-6, "{d4}");
    }
}
