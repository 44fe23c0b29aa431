//! The Reissner–Mindlin plate scenes (docs/mathematics.md §6), as data: the domain, the
//! support, the material, the load, the obstacle, the default thickness and mesh, and
//! the reference the scene is checked against.
//!
//! A scene says what is posed, not how it is discretized: the domain (a square or a
//! disk), the support on its whole boundary, a uniform load along w (w positive up, so
//! q > 0 pushes the plate up) with the list of loads its studies run, and an obstacle
//! (none, or flat above or below at a height). The plate family
//! (`crate::families::plate`) turns each into a scene of the one pipeline.

/// How the plate is held on its boundary.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlateSupport {
    /// `θ = 0`, `w = 0` on the whole boundary (model `mindlin_stenberg`).
    Clamped,
    /// `w = 0` on the whole boundary, θ free: the "soft" simple support (model
    /// `mindlin_simply_supported`).
    SimplySupported,
}

impl PlateSupport {
    /// The support's name as reports print it.
    pub fn name(self) -> &'static str {
        match self {
            PlateSupport::Clamped => "clamped",
            PlateSupport::SimplySupported => "simply-supported",
        }
    }
}

/// The plate's mid-surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PlateDomain {
    /// The square `(0, a)²` of side `a` (an N×N×2 mesh of it).
    Square {
        /// Side a.
        side: f64,
    },
    /// The disk of radius R centred at the origin (a ring mesh with N rings).
    Disk {
        /// Radius R.
        radius: f64,
    },
}

impl PlateDomain {
    /// The centre of the domain (the point whose deflection the reports print).
    pub fn centre(self) -> [f64; 2] {
        match self {
            PlateDomain::Square { side } => [0.5 * side, 0.5 * side],
            PlateDomain::Disk { .. } => [0.0, 0.0],
        }
    }

    /// The length `L` the Kirchhoff deflections scale with (`w ~ q L⁴/D`): the side of
    /// the square, the radius of the disk.
    pub fn length(self) -> f64 {
        match self {
            PlateDomain::Square { side } => side,
            PlateDomain::Disk { radius } => radius,
        }
    }

    /// The domain's diameter (the side of a square is compared with t as its size).
    pub fn size(self) -> f64 {
        match self {
            PlateDomain::Square { side } => side,
            PlateDomain::Disk { radius } => 2.0 * radius,
        }
    }

    /// Words for reports: `unit square`, `disk of radius 1`.
    pub fn describe(self) -> String {
        match self {
            PlateDomain::Square { side: 1.0 } => "unit square".into(),
            PlateDomain::Square { side } => format!("square of side {side}"),
            PlateDomain::Disk { radius } => format!("disk of radius {radius}"),
        }
    }
}

/// The rigid obstacle of a plate scene, `s·w ≥ s·ψ` with a flat ψ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PlateObstacle {
    /// No obstacle (the solve puts one out of reach, so λ ≡ 0).
    None,
    /// A flat obstacle above the plate: `w ≤ height` (s = −1).
    FlatAbove {
        /// Its height ψ.
        height: f64,
    },
    /// A flat obstacle below the plate: `w ≥ height` (s = +1).
    FlatBelow {
        /// Its height ψ.
        height: f64,
    },
}

impl PlateObstacle {
    /// `(s, ψ)` of a flat obstacle; `None` for no obstacle.
    pub fn side_and_height(self) -> Option<(f64, f64)> {
        match self {
            PlateObstacle::None => None,
            PlateObstacle::FlatAbove { height } => Some((-1.0, height)),
            PlateObstacle::FlatBelow { height } => Some((1.0, height)),
        }
    }

    /// Words for reports: `none`, `flat above, w ≤ 0.05`.
    pub fn describe(self) -> String {
        match self {
            PlateObstacle::None => "none".into(),
            PlateObstacle::FlatAbove { height } => format!("flat above, w ≤ {height}"),
            PlateObstacle::FlatBelow { height } => format!("flat below, w ≥ {height}"),
        }
    }
}

/// The Kirchhoff centre deflection of the clamped square in units of `q a⁴/D`
/// (Timoshenko & Woinowsky-Krieger, table 35).
pub const CLAMPED_SQUARE_CENTRE: f64 = 0.00126532;

/// The Kirchhoff (Navier) centre deflection of the simply supported square in units of
/// `q a⁴/D` (Timoshenko & Woinowsky-Krieger, table 8).
pub const SIMPLY_SUPPORTED_SQUARE_CENTRE: f64 = 0.00406235;

/// What a scene's centre deflection is checked against.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PlateReference {
    /// The Kirchhoff centre deflection `coefficient · q L⁴/D` (the limit as t → 0); the
    /// Mindlin solution has no closed form.
    KirchhoffCentre {
        /// The coefficient in units of `q L⁴/D`.
        coefficient: f64,
    },
    /// The clamped disk: Kirchhoff `q R⁴/(64D)`, and the exact Mindlin centre deflection
    /// `q R⁴/(64D) + q R²/(4 S)` with `S = 6κ(1−ν)D/t²` (t = 0.01, q = 20, R = D = 1,
    /// κ = 5/6, ν = 0.3: 0.3126428571). Why: equilibrium gives the shear force
    /// `S(w' − θ) = −q r/2` and the moments give the same θ as Kirchhoff's clamped disk,
    /// so `w − w_K = q (R² − r²)/(4S)`.
    ClampedDisk,
}

/// A plate scene: a Reissner–Mindlin plate on `domain`, held by `support` on its whole
/// boundary, under the uniform load `q` (along w, per area) and in contact with
/// `obstacle`.
#[derive(Clone, Copy, Debug)]
pub struct PlateScene {
    /// Name (`fem-forms solve <name>`).
    pub name: &'static str,
    /// One line of description.
    pub description: &'static str,
    /// The mid-surface.
    pub domain: PlateDomain,
    /// The support on the whole boundary.
    pub support: PlateSupport,
    /// Bending stiffness D = E t³/(12(1−ν²)).
    pub bending_stiffness: f64,
    /// Poisson's ratio ν, in (−1, ½).
    pub poisson_ratio: f64,
    /// Shear correction factor κ.
    pub shear_correction: f64,
    /// Default uniform load q (`--load`).
    pub load: f64,
    /// The loads the scene's studies run (the default among them).
    pub loads: &'static [f64],
    /// The obstacle.
    pub obstacle: PlateObstacle,
    /// Default thickness t (`--thickness`).
    pub thickness: f64,
    /// Default mesh size (`--mesh-size`): N of the square's N×N×2 mesh, or the disk's
    /// number of rings.
    pub mesh_size: usize,
    /// The reference of the centre deflection.
    pub reference: PlateReference,
}

impl PlateScene {
    /// The Kirchhoff centre deflection at load `q` (the limit as t → 0 without contact).
    pub fn kirchhoff_deflection_at(&self, q: f64) -> f64 {
        let scale = q * self.domain.length().powi(4) / self.bending_stiffness;
        match self.reference {
            PlateReference::KirchhoffCentre { coefficient } => coefficient * scale,
            PlateReference::ClampedDisk => scale / 64.0,
        }
    }

    /// The Kirchhoff centre deflection at the scene's load.
    pub fn kirchhoff_deflection(&self) -> f64 {
        self.kirchhoff_deflection_at(self.load)
    }

    /// The exact Mindlin centre deflection at load `q` and thickness `t` without
    /// contact, where it is known in closed form (the clamped disk).
    pub fn mindlin_deflection_at(&self, q: f64, t: f64) -> Option<f64> {
        match self.reference {
            PlateReference::KirchhoffCentre { .. } => None,
            PlateReference::ClampedDisk => {
                let shear = 6.0
                    * self.shear_correction
                    * (1.0 - self.poisson_ratio)
                    * self.bending_stiffness
                    / (t * t);
                let r = self.domain.length();
                Some(self.kirchhoff_deflection_at(q) + q * r * r / (4.0 * shear))
            }
        }
    }
}

/// The clamped unit square (issue 12): D = 1, ν = 0.3, κ = 5/6, q = 1; its centre
/// deflection tends to the Kirchhoff value 0.00126532 q a⁴/D (Timoshenko &
/// Woinowsky-Krieger, table 35) as t → 0.
pub const MINDLIN_SQUARE: PlateScene = PlateScene {
    name: "mindlin-square",
    description:
        "clamped unit square Reissner–Mindlin plate, uniform load, no contact; → Kirchhoff as t → 0",
    domain: PlateDomain::Square { side: 1.0 },
    support: PlateSupport::Clamped,
    bending_stiffness: 1.0,
    poisson_ratio: 0.3,
    shear_correction: 5.0 / 6.0,
    load: 1.0,
    loads: &[1.0],
    obstacle: PlateObstacle::None,
    thickness: 1e-3,
    mesh_size: 32,
    reference: PlateReference::KirchhoffCentre {
        coefficient: CLAMPED_SQUARE_CENTRE,
    },
};

/// The simply supported ("soft": w = 0, θ free) unit square, otherwise as
/// [`MINDLIN_SQUARE`]; its centre deflection tends to the Kirchhoff (Navier) value
/// 0.00406235 q a⁴/D (Timoshenko & Woinowsky-Krieger, table 8) as t → 0.
pub const MINDLIN_SQUARE_SS: PlateScene = PlateScene {
    name: "mindlin-square-ss",
    description: "simply supported unit square Reissner–Mindlin plate, uniform load, no contact; → Navier's value as t → 0",
    support: PlateSupport::SimplySupported,
    reference: PlateReference::KirchhoffCentre {
        coefficient: SIMPLY_SUPPORTED_SQUARE_CENTRE,
    },
    ..MINDLIN_SQUARE
};

/// The clamped unit disk pushed up against a flat obstacle (issue 12): D = 1, ν = 0.3,
/// κ = 5/6, t = 0.01, q = 20 upward (studies: 10, 20, 50), `w ≤ 0.05`. Without the
/// obstacle its centre would rise to `q/64 + q t²/14` (0.3126 at q = 20), so every load
/// of the list touches.
pub const MINDLIN_DISK: PlateScene = PlateScene {
    name: "mindlin-disk",
    description: "clamped unit disk Reissner–Mindlin plate pushed up by q against a flat obstacle w ≤ 0.05 (t = 0.01)",
    domain: PlateDomain::Disk { radius: 1.0 },
    support: PlateSupport::Clamped,
    bending_stiffness: 1.0,
    poisson_ratio: 0.3,
    shear_correction: 5.0 / 6.0,
    load: 20.0,
    loads: &[10.0, 20.0, 50.0],
    obstacle: PlateObstacle::FlatAbove { height: 0.05 },
    thickness: 0.01,
    mesh_size: 32,
    reference: PlateReference::ClampedDisk,
};

/// A simply supported (soft: w = 0, rotations free) unit square pushed up by q = 20
/// against a flat obstacle w ≤ 0.05, at thickness t: the Mindlin rotations' boundary
/// layer at the soft support keeps the Kirchhoff model from being adequate on
/// thickness alone (the model-choice scenes).
const fn simply_supported_obstacle(
    name: &'static str,
    description: &'static str,
    thickness: f64,
) -> PlateScene {
    PlateScene {
        name,
        description,
        support: PlateSupport::SimplySupported,
        load: 20.0,
        loads: &[20.0],
        obstacle: PlateObstacle::FlatAbove { height: 0.05 },
        thickness,
        mesh_size: 16,
        reference: PlateReference::KirchhoffCentre {
            coefficient: SIMPLY_SUPPORTED_SQUARE_CENTRE,
        },
        ..MINDLIN_SQUARE
    }
}

/// The simply supported square against its obstacle at t = 0.1.
pub const MINDLIN_SS_T1E1: PlateScene = simply_supported_obstacle(
    "mindlin-ss-t1e-1",
    "simply supported unit square Reissner–Mindlin plate (t = 0.1) pushed up by q = 20 against w ≤ 0.05",
    1e-1,
);

/// The simply supported square against its obstacle at t = 0.01.
pub const MINDLIN_SS_T1E2: PlateScene = simply_supported_obstacle(
    "mindlin-ss-t1e-2",
    "simply supported unit square Reissner–Mindlin plate (t = 0.01) pushed up by q = 20 against w ≤ 0.05",
    1e-2,
);

/// The simply supported square against its obstacle at t = 0.001.
pub const MINDLIN_SS_T1E3: PlateScene = simply_supported_obstacle(
    "mindlin-ss-t1e-3",
    "simply supported unit square Reissner–Mindlin plate (t = 0.001) pushed up by q = 20 against w ≤ 0.05",
    1e-3,
);

/// Every built-in plate scene.
pub const PLATE_SCENES: &[PlateScene] = &[
    MINDLIN_SQUARE,
    MINDLIN_SQUARE_SS,
    MINDLIN_DISK,
    MINDLIN_SS_T1E1,
    MINDLIN_SS_T1E2,
    MINDLIN_SS_T1E3,
];
