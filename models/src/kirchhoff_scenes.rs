//! The Kirchhoff plate scenes (docs/mathematics.md §9, issue 13), as data: the unit
//! square, its support, the material, the load, the obstacle (none, flat or curved, above
//! the plate) and the default mesh; the solver is the CLI's (`src/kirchhoff.rs`).

/// How the plate is held on its whole boundary.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum KirchhoffSupport {
    /// `w = 0` and `∂w/∂n = 0`.
    Clamped,
    /// `w = 0` (the bending moment `M_nn = 0` is the natural condition).
    SimplySupported,
}

impl KirchhoffSupport {
    /// Both supports, the clamped one first.
    pub const ALL: [KirchhoffSupport; 2] =
        [KirchhoffSupport::Clamped, KirchhoffSupport::SimplySupported];

    /// The support's name (`--support`).
    pub fn name(self) -> &'static str {
        match self {
            KirchhoffSupport::Clamped => "clamped",
            KirchhoffSupport::SimplySupported => "simply-supported",
        }
    }

    /// The unobstructed centre deflection of the square `(0, a)²` under the uniform load
    /// q, in units of `q a⁴/D` (Timoshenko and Woinowsky-Krieger, *Theory of Plates and
    /// Shells*, Tables 35 (ν = 0.3) and 8; the simply supported value is Navier's series,
    /// independent of ν).
    pub fn centre_coefficient(self) -> f64 {
        match self {
            KirchhoffSupport::Clamped => 0.00126532,
            KirchhoffSupport::SimplySupported => 0.00406235,
        }
    }
}

/// The obstacle above the plate (`w ≤ ψ`, obstacle side `s = −1`), r the distance from
/// the centre of the square.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum KirchhoffObstacle {
    /// None in reach: λ ≡ 0.
    None,
    /// `ψ = gap`.
    Flat {
        /// The gap at the centre.
        gap: f64,
    },
    /// `ψ = gap + curvature · r²` (Δ²ψ = 0, so λ = q in the interior of contact as for
    /// the flat one).
    Curved {
        /// The gap at the centre.
        gap: f64,
        /// The coefficient of r².
        curvature: f64,
    },
}

impl KirchhoffObstacle {
    /// The obstacle's name (`--obstacle`).
    pub fn name(self) -> &'static str {
        match self {
            KirchhoffObstacle::None => "none",
            KirchhoffObstacle::Flat { .. } => "flat",
            KirchhoffObstacle::Curved { .. } => "curved",
        }
    }

    /// `ψ` at the distance `r` from the centre; `None` for no obstacle.
    pub fn height(self, r: f64) -> Option<f64> {
        match self {
            KirchhoffObstacle::None => None,
            KirchhoffObstacle::Flat { gap } => Some(gap),
            KirchhoffObstacle::Curved { gap, curvature } => Some(gap + curvature * r * r),
        }
    }
}

/// The flat obstacle of issue 13: `w ≤ 0.002`.
pub const FLAT_OBSTACLE: KirchhoffObstacle = KirchhoffObstacle::Flat { gap: 0.002 };
/// The curved obstacle of issue 13: `w ≤ 0.002 + 0.01 r²`.
pub const CURVED_OBSTACLE: KirchhoffObstacle = KirchhoffObstacle::Curved {
    gap: 0.002,
    curvature: 0.01,
};

/// A Kirchhoff plate scene on the unit square under the uniform load q (along +w).
#[derive(Clone, Copy, Debug)]
pub struct KirchhoffScene {
    /// Name (`fem-forms solve <name>`).
    pub name: &'static str,
    /// One line of description.
    pub description: &'static str,
    /// Default support (`--support`).
    pub support: KirchhoffSupport,
    /// Bending stiffness D.
    pub bending_stiffness: f64,
    /// Poisson's ratio ν.
    pub poisson_ratio: f64,
    /// Default load q (`--load`).
    pub load: f64,
    /// Default obstacle (`--obstacle`).
    pub obstacle: KirchhoffObstacle,
    /// Default N of the N×N×2 mesh (`--mesh-size`).
    pub mesh_size: usize,
}

/// The clamped unit square without an obstacle: its centre deflection against
/// `0.00126532 q a⁴/D` (simply supported: `0.00406235`).
pub const KIRCHHOFF_SQUARE: KirchhoffScene = KirchhoffScene {
    name: "kirchhoff-square",
    description: "unit square Kirchhoff plate (clamped or simply supported), uniform load, no contact; centre deflection against the series",
    support: KirchhoffSupport::Clamped,
    bending_stiffness: 1.0,
    poisson_ratio: 0.3,
    load: 1.0,
    obstacle: KirchhoffObstacle::None,
    mesh_size: 16,
};

/// The clamped unit square pushed up by q = 5 (or 20) against the flat obstacle
/// `w ≤ 0.002` (or the curved `0.002 + 0.01 r²`).
pub const KIRCHHOFF_OBSTACLE: KirchhoffScene = KirchhoffScene {
    name: "kirchhoff-obstacle",
    description: "clamped unit square Kirchhoff plate pushed up by q = 5 against w ≤ 0.002 (--obstacle curved: 0.002 + 0.01 r²)",
    support: KirchhoffSupport::Clamped,
    bending_stiffness: 1.0,
    poisson_ratio: 0.3,
    load: 5.0,
    obstacle: FLAT_OBSTACLE,
    mesh_size: 32,
};

/// Every built-in Kirchhoff scene.
pub const KIRCHHOFF_SCENES: &[KirchhoffScene] = &[KIRCHHOFF_SQUARE, KIRCHHOFF_OBSTACLE];
