//! The membrane scenes (docs/mathematics.md §2): domain, load, obstacle and boundary data, and the
//! exact solution where one is known.

/// The domain of a membrane scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Domain {
    /// The square `(−a, a)²`.
    Square(f64),
    /// `(−1, 1)² ∖ [0, 1] × [−1, 0]`.
    LShape,
}

/// A membrane scene's exact solution.
#[derive(Clone, Copy, Debug)]
pub struct ExactMembrane {
    /// `u(x)`.
    pub u: fn(&[f64]) -> f64,
    /// `∇u(x)`.
    pub gradient: fn(&[f64]) -> [f64; 2],
    /// `λ(x)`.
    pub multiplier: fn(&[f64]) -> f64,
    /// `∫ λ`.
    pub total_contact_force: f64,
    /// The area of the contact set.
    pub contact_area: f64,
}

/// The exact solution of the radial problem.
pub const RADIAL_EXACT: ExactMembrane = ExactMembrane {
    u: radial_u,
    gradient: radial_gradient,
    multiplier: radial_multiplier,
    total_contact_force: 2.0 * std::f64::consts::PI * RADIAL_A,
    contact_area: std::f64::consts::PI * RADIAL_R * RADIAL_R,
};

/// A membrane scene.
#[derive(Clone, Copy, Debug)]
pub struct MembraneScene {
    /// Its name on the command line.
    pub name: &'static str,
    /// One line of description.
    pub description: &'static str,
    /// The domain.
    pub domain: Domain,
    /// The load `f(x)`.
    pub load: fn(&[f64]) -> f64,
    /// The obstacle `ψ(x)` (from below: `u ≥ ψ`).
    pub obstacle: fn(&[f64]) -> f64,
    /// The boundary data `g(x)`.
    pub boundary: fn(&[f64]) -> f64,
    /// The accuracy the scene asks for: the L² error of u (estimated where no exact
    /// solution is known).
    pub target_l2: f64,
    /// The exact solution, where one is known.
    pub exact: Option<ExactMembrane>,
}

/// The free-boundary radius `r*` of the radial problem: `r*²(ln 2 − ln r*) = 1 − r*²`.
pub const RADIAL_R: f64 = 0.697965148223374;
/// `A = r*²/√(1 − r*²)`.
pub const RADIAL_A: f64 = 0.680259411891717;
/// `B = A ln 2`.
pub const RADIAL_B: f64 = 0.471519893402110;

fn radius(x: &[f64]) -> f64 {
    x[0].hypot(x[1])
}

/// The radial obstacle `ψ = √(1 − r²)` for `r ≤ 1`, `−1` outside.
pub fn radial_obstacle(x: &[f64]) -> f64 {
    let r = radius(x);
    if r <= 1.0 {
        (1.0 - r * r).sqrt()
    } else {
        -1.0
    }
}

/// The exact radial solution `u`: `ψ` for `r ≤ r*`, `−A ln r + B` outside.
pub fn radial_u(x: &[f64]) -> f64 {
    let r = radius(x);
    if r <= RADIAL_R {
        (1.0 - r * r).sqrt()
    } else {
        -RADIAL_A * r.ln() + RADIAL_B
    }
}

/// `∇u` of the exact radial solution.
pub fn radial_gradient(x: &[f64]) -> [f64; 2] {
    let r = radius(x);
    // dU/dr divided by r, so that ∇u = (dU/dr / r)·x
    let radial = if r <= RADIAL_R {
        -1.0 / (1.0 - r * r).sqrt()
    } else {
        -RADIAL_A / (r * r)
    };
    [radial * x[0], radial * x[1]]
}

/// The exact multiplier `λ = (2 − r²)/(1 − r²)^{3/2}` on `r < r*`, 0 outside.
pub fn radial_multiplier(x: &[f64]) -> f64 {
    let r = radius(x);
    if r < RADIAL_R {
        (2.0 - r * r) / (1.0 - r * r).powf(1.5)
    } else {
        0.0
    }
}

fn zero(_: &[f64]) -> f64 {
    0.0
}

fn zero_gradient(_: &[f64]) -> [f64; 2] {
    [0.0, 0.0]
}

fn press_down(_: &[f64]) -> f64 {
    -3.0
}

fn three(_: &[f64]) -> f64 {
    3.0
}

/// The sign test of docs/mathematics.md §1 as a scene: ψ = 0, g = 0 and f = −3 pressing everywhere
/// onto the obstacle, so u = 0, λ = 3, ∫λ = 48 and the contact is the whole (−2,2)².
/// Not among the default scenes: it checks signs, not accuracy.
pub const MEMBRANE_FLAT: MembraneScene = MembraneScene {
    name: "membrane-flat",
    description: "membrane on (−2,2)² pressed flat onto ψ = 0 by f = −3 (exact: u = 0, λ = 3)",
    domain: Domain::Square(2.0),
    load: press_down,
    obstacle: zero,
    boundary: zero,
    target_l2: 1e-3,
    exact: Some(ExactMembrane {
        u: zero,
        gradient: zero_gradient,
        multiplier: three,
        total_contact_force: 48.0,
        contact_area: 16.0,
    }),
};

/// A tilted, off-centre paraboloid below the L-shaped membrane: not symmetric about
/// any axis of the domain.
fn lshape_obstacle(x: &[f64]) -> f64 {
    -0.05 - 0.6 * ((x[0] + 0.35).powi(2) + 0.5 * (x[1] - 0.4).powi(2)) + 0.1 * x[0]
}

fn lshape_load(_: &[f64]) -> f64 {
    -12.0
}

/// Every membrane scene.
pub const MEMBRANE_SCENES: [MembraneScene; 2] = [
    MembraneScene {
        name: "membrane-radial",
        description: "membrane on (−2,2)² over the hemisphere ψ = √(1−r²), f = 0, exact solution (docs/mathematics.md §2)",
        domain: Domain::Square(2.0),
        load: zero,
        obstacle: radial_obstacle,
        boundary: radial_u,
        target_l2: 1e-3,
        exact: Some(RADIAL_EXACT),
    },
    MembraneScene {
        name: "membrane-lshape",
        description: "L-shaped membrane, u = 0 on ∂Ω, f = −12, pressed onto a tilted off-centre paraboloid",
        domain: Domain::LShape,
        load: lshape_load,
        obstacle: lshape_obstacle,
        boundary: zero,
        target_l2: 1e-3,
        exact: None,
    },
];

/// The membrane scene called `name` (the default ones and `membrane-flat`).
pub fn membrane_scene(name: &str) -> Option<MembraneScene> {
    MEMBRANE_SCENES
        .iter()
        .chain([&MEMBRANE_FLAT])
        .copied()
        .find(|s| s.name == name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_radial_constants_solve_their_equations() {
        let r: f64 = RADIAL_R;
        assert!((r * r * (2f64.ln() - r.ln()) - (1.0 - r * r)).abs() < 1e-14);
        assert!((RADIAL_A - r * r / (1.0 - r * r).sqrt()).abs() < 1e-14);
        assert!((RADIAL_B - RADIAL_A * 2f64.ln()).abs() < 1e-14);
        // u and ∂u/∂r are continuous at r*, and u ≥ ψ everywhere
        let inside = [r - 1e-9, 0.0];
        let outside = [r + 1e-9, 0.0];
        assert!((radial_u(&inside) - radial_u(&outside)).abs() < 1e-8);
        assert!((radial_gradient(&inside)[0] - radial_gradient(&outside)[0]).abs() < 1e-6);
        for i in 0..400 {
            let x = [-2.0 + 4.0 * i as f64 / 399.0, 0.3];
            assert!(radial_u(&x) >= radial_obstacle(&x) - 1e-15);
        }
    }

    #[test]
    fn obstacles_lie_below_the_boundary_data() {
        for scene in MEMBRANE_SCENES {
            for i in 0..=100 {
                let t = -1.0 + 2.0 * i as f64 / 100.0;
                let a = match scene.domain {
                    Domain::Square(a) => a,
                    Domain::LShape => 1.0,
                };
                for x in [[a * t, -a], [a * t, a], [-a, a * t], [a, a * t]] {
                    assert!(
                        (scene.obstacle)(&x) < (scene.boundary)(&x),
                        "{}",
                        scene.name
                    );
                }
            }
        }
    }
}
