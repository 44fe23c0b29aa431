//! The Signorini contact scenes (MODELS.md §7, issue 14), as data: the body, its
//! material, the load and the foundation; the solver is the CLI's (`src/signorini.rs`)
//! over [`crate::signorini::solve_signorini`].

use crate::signorini::{Hertz, Plane};

/// The elastic body and how it meets the rigid foundation `y = 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ContactBody {
    /// The block `(0, width) × (0, height)` on the foundation, a uniform pressure q on
    /// its top, a roller `u_x = 0` on its left side; no gap. The exact solution is the
    /// uniform stress `σ_yy = −q`: the contact pressure is q on every edge (the patch
    /// test, MODELS.md §7).
    Block {
        /// Width (length).
        width: f64,
        /// Height (length).
        height: f64,
    },
    /// Hertz line contact: the cylinder of radius R pressed by the resultant P (per
    /// unit length) onto the plane, solved on its symmetric half `x ≥ 0` (a quarter
    /// disc, `u_x = 0` on the axis), the resultant applied as a uniform pressure
    /// `P / (2R)` on its flat top; initial gap along the body's normal.
    Cylinder {
        /// Radius R (length).
        radius: f64,
    },
}

/// A contact scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactScene {
    /// Name (`fem-forms solve <name>`).
    pub name: &'static str,
    /// One line for `list`.
    pub description: &'static str,
    /// The body.
    pub body: ContactBody,
    /// Young's modulus E (force / length²).
    pub young: f64,
    /// Poisson's ratio ν.
    pub poisson: f64,
    /// Plane strain or plane stress.
    pub plane: Plane,
    /// The load: the top pressure q of a block (force / length), the resultant P of
    /// a cylinder (force per unit length of cylinder).
    pub load: f64,
    /// Default `--mesh-size`: N of the block's N×N×2 mesh; the cylinder's `b/h`, cells
    /// per contact half-width.
    pub mesh_size: usize,
}

impl ContactScene {
    /// The Hertz reference of a cylinder scene at load `load` (`None` for a block).
    pub fn hertz(&self, load: f64) -> Option<Hertz> {
        match self.body {
            ContactBody::Cylinder { radius } => Some(Hertz {
                radius,
                young: self.young,
                poisson: self.poisson,
                load,
            }),
            ContactBody::Block { .. } => None,
        }
    }
}

/// The patch test of MODELS.md §7: λ_h = q exactly.
pub const SIGNORINI_PATCH: ContactScene = ContactScene {
    name: "signorini-patch",
    description: "elastic block (0,2)×(0,1) on a rigid foundation under a uniform pressure q on its top (exact: λ = q on every contact edge)",
    body: ContactBody::Block {
        width: 2.0,
        height: 1.0,
    },
    young: 1000.0,
    poisson: 0.3,
    plane: Plane::Strain,
    load: 1.0,
    mesh_size: 8,
};

/// Hertz line contact with MODELS.md §7's constants: R = 1, E = 1000, ν = 0.3, P = 1,
/// plane strain (b = 0.0340389, p_max = 18.7027).
pub const HERTZ: ContactScene = ContactScene {
    name: "hertz",
    description: "cylinder R = 1 (E = 1000, ν = 0.3, plane strain) pressed by P = 1 onto a rigid plane; pressure against Hertz's (mesh size: b/h)",
    body: ContactBody::Cylinder { radius: 1.0 },
    young: 1000.0,
    poisson: 0.3,
    plane: Plane::Strain,
    load: 1.0,
    mesh_size: 16,
};

/// Every contact scene, in `list` order.
pub const CONTACT_SCENES: [ContactScene; 2] = [SIGNORINI_PATCH, HERTZ];
