//! The Reissner–Mindlin plate scenes (docs/mathematics.md §6), as data: the domain, the
//! support, the material and load, the default thickness and mesh, and the Kirchhoff
//! reference the scene is checked against as t → 0.

/// How the plate is held on its boundary.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlateSupport {
    /// `θ = 0`, `w = 0` on the whole boundary (model `mindlin_clamped`).
    Clamped,
}

impl PlateSupport {
    /// The support's name as reports print it.
    pub fn name(self) -> &'static str {
        match self {
            PlateSupport::Clamped => "clamped",
        }
    }
}

/// A plate scene on the square `(0, a)²` under the uniform load `q` (along w, per area)
/// with no obstacle in reach (ψ far below the plate, so λ ≡ 0).
#[derive(Clone, Copy, Debug)]
pub struct PlateScene {
    /// Name (`fem-forms solve <name>`).
    pub name: &'static str,
    /// One line of description.
    pub description: &'static str,
    /// The support on the whole boundary.
    pub support: PlateSupport,
    /// Side a of the square.
    pub side: f64,
    /// Bending stiffness D = E t³/(12(1−ν²)).
    pub bending_stiffness: f64,
    /// Poisson's ratio ν, in (−1, ½).
    pub poisson_ratio: f64,
    /// Shear correction factor κ.
    pub shear_correction: f64,
    /// Uniform load q.
    pub load: f64,
    /// Default thickness t (`--thickness`).
    pub thickness: f64,
    /// Default N of the N×N×2 mesh (`--mesh-size`).
    pub mesh_size: usize,
    /// The Kirchhoff centre deflection in units of `q a⁴/D`, the limit as t → 0.
    pub kirchhoff_coefficient: f64,
}

impl PlateScene {
    /// The Kirchhoff centre deflection `coefficient · q a⁴/D`.
    pub fn kirchhoff_deflection(&self) -> f64 {
        self.kirchhoff_coefficient * self.load * self.side.powi(4) / self.bending_stiffness
    }
}

/// The clamped unit square (issue 12): D = 1, ν = 0.3, κ = 5/6, q = 1; its centre
/// deflection tends to the Kirchhoff value 0.00126532 q a⁴/D (Timoshenko &
/// Woinowsky-Krieger, table 35) as t → 0.
pub const MINDLIN_SQUARE: PlateScene = PlateScene {
    name: "mindlin-square",
    description:
        "clamped unit square Reissner–Mindlin plate, uniform load, no contact; → Kirchhoff as t → 0",
    support: PlateSupport::Clamped,
    side: 1.0,
    bending_stiffness: 1.0,
    poisson_ratio: 0.3,
    shear_correction: 5.0 / 6.0,
    load: 1.0,
    thickness: 1e-3,
    mesh_size: 32,
    kirchhoff_coefficient: 0.00126532,
};

/// Every built-in plate scene.
pub const PLATE_SCENES: &[PlateScene] = &[MINDLIN_SQUARE];
