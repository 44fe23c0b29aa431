//! What a contact scene poses beyond its parameters and data: the material, the
//! foundation's direction and the built-in body, and the model's names of its parts.

use crate::contact_scenes::ContactBody;
use crate::hertz::Hertz;
use crate::signorini::{lame, Plane};
use fem_runtime::{DataFn, Result};

/// The contact boundary's name in the model's `facets:`.
pub const CONTACT_PART: &str = "Γ_C";
/// The loaded boundary's name in the model's `facets:`.
pub const LOAD_PART: &str = "Γ_N";

/// What a contact scene poses beyond its parameters and data: the material as its user
/// gives it, the foundation's direction, and the built-in body where the scene is one
/// (its reference: Hertz's pressure, the patch test's).
#[derive(Clone, Copy, Debug)]
pub struct ContactFacts {
    /// Young's modulus E (force per area).
    pub young: f64,
    /// Poisson's ratio ν.
    pub poisson: f64,
    /// Plane strain or plane stress.
    pub plane: Plane,
    /// The contact direction `n_c` (unit): the foundation's normal pointing away from
    /// the body.
    pub direction: [f64; 2],
    /// The middle of the contact zone along the contact plane (a symmetry line), for the
    /// half-width; `None`: the middle of the pressed edges.
    pub centre: Option<f64>,
    /// The built-in body, where the scene is one.
    pub body: Option<ContactBody>,
}

impl ContactFacts {
    /// The Hertz reference at load `load`, for the bodies that have one.
    pub fn hertz(&self, load: f64) -> Option<Hertz> {
        let radius = match self.body? {
            ContactBody::Cylinder { radius } | ContactBody::GapBlock { radius, .. } => radius,
            ContactBody::Block { .. } => return None,
        };
        Some(Hertz {
            radius,
            young: self.young,
            poisson: self.poisson,
            load,
        })
    }

    /// The share of the body solved: a half (a symmetry line) counts twice.
    pub(super) fn whole(&self) -> f64 {
        match self.body {
            Some(ContactBody::Cylinder { .. } | ContactBody::GapBlock { .. }) => 2.0,
            _ => 1.0,
        }
    }
}

/// The scene's parameters of the material and the direction: the Lamé parameters of E
/// and ν, and `n_c`.
///
/// # Errors
/// E, ν out of range ([`lame`]).
pub fn material_parameters(facts: &ContactFacts) -> Result<Vec<(&'static str, f64)>> {
    let (mu, lambda) = lame(facts.young, facts.poisson, facts.plane)?;
    Ok(vec![
        ("μ_L", mu),
        ("λ_L", lambda),
        ("n_c_x", facts.direction[0]),
        ("n_c_y", facts.direction[1]),
    ])
}

/// The unit tangent of the contact plane whose normal is `direction` (unit): `n_c`
/// turned by a quarter, oriented so that its first non-zero component is positive, so
/// that the coordinate `t·x` along the plane is x for `n_c = (0, ±1)` and y for
/// `n_c = (±1, 0)`. The contact half-width and `contact_centre` are measured in it.
pub fn contact_tangent(direction: [f64; 2]) -> [f64; 2] {
    let t = [-direction[1], direction[0]];
    if t[0] > 0.0 || (t[0] == 0.0 && t[1] > 0.0) {
        t
    } else {
        [-t[0], -t[1]]
    }
}

/// What the quantities of a contact solve are measured with: the boundary parts by
/// their markers, the pressure as solved, and the middle of the contact zone.
#[derive(Clone, Copy)]
pub struct ContactData<'a> {
    /// The potential contact boundary Γ_C.
    pub contact: &'a [u32],
    /// The loaded boundary Γ_N.
    pub load: &'a [u32],
    /// The pressure q on Γ_N (force per length, positive pressing in), a function of x.
    pub pressure: &'a DataFn,
    /// The middle of the contact zone, for the half-width (a symmetry line), as a
    /// coordinate along the contact plane ([`contact_tangent`]: x under a horizontal
    /// plane, y beside a vertical one); `None`: the middle of the pressed edges.
    pub centre: Option<f64>,
}
