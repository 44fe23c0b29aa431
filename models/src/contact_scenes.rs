//! The Signorini contact scenes (docs/contact.md), as data: the body, its material, the
//! load and the foundation, and the graded meshes of the bodies with a Hertz reference;
//! the contact family ([`crate::families::contact`]) poses and solves them.

use crate::hertz::Hertz;
use crate::signorini::Plane;
use fem_runtime::mesh::BoundaryCurve;
use fem_runtime::{Diagonal, Error, Result, TriangleMesh};

/// The elastic body and how it meets the rigid foundation `y = 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ContactBody {
    /// The block `(0, width) × (0, height)` on the foundation, a uniform pressure q on
    /// its top, a roller `u_x = 0` on its left side; no gap. The exact solution is the
    /// uniform stress `σ_yy = −q`: the contact pressure is q on every edge (the patch
    /// test, docs/contact.md).
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
    /// A block `(−w, w) × (0, height)` over the rigid plane `y = 0` with the non-flat
    /// initial gap `g(x) = x²/(2R)` (the parabola Hertz's theory puts in place of a
    /// cylinder of radius R), pressed by the resultant P as a uniform pressure
    /// `P/(2w)` on its top; solved on its symmetric half `x ≥ 0` (`u_x = 0` on the
    /// axis, the side `x = w` free). For `b ≪ w, height` the pressure is Hertz's with
    /// E* and R ([`ContactScene::hertz`]); the finite block's deviation from it was
    /// measured (docs/contact.md) to lie well below `accuracy`.
    GapBlock {
        /// Half the block's width w (length).
        half_width: f64,
        /// Height (length).
        height: f64,
        /// Curvature radius R of the gap `x²/(2R)` (length).
        radius: f64,
        /// The accuracy the scene states: the relative L² error of the contact
        /// pressure against Hertz's that its default mesh reaches (and an
        /// accuracy-driven solve would aim at).
        accuracy: f64,
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
            ContactBody::GapBlock { radius, .. } => Some(Hertz {
                radius,
                young: self.young,
                poisson: self.poisson,
                load,
            }),
            ContactBody::Block { .. } => None,
        }
    }

    /// The accuracy the scene states (relative L² error of the contact pressure
    /// against its reference), where it states one.
    pub fn accuracy(&self) -> Option<f64> {
        match self.body {
            ContactBody::GapBlock { accuracy, .. } => Some(accuracy),
            _ => None,
        }
    }
}

/// The patch test of docs/contact.md: λ_h = q exactly.
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

/// Hertz line contact with docs/contact.md's constants: R = 1, E = 1000, ν = 0.3, P = 1,
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

/// A block over a non-flat gap, solved to a stated accuracy: the block
/// `(−1, 1) × (0, 1)` (E = 1000, ν = 0.3, plane strain) over the gap `x²/2` (R = 1),
/// pressed by P = 1: Hertz's b = 0.0340389, p_max = 18.7027. Mesh size: b/h.
pub const SIGNORINI_GAP: ContactScene = ContactScene {
    name: "signorini-gap",
    description: "elastic block (−1,1)×(0,1) (E = 1000, ν = 0.3, plane strain) over the parabolic gap x²/2 on a rigid plane, pressed by P = 1; pressure against Hertz's to a stated 2 % (mesh size: b/h)",
    body: ContactBody::GapBlock {
        half_width: 1.0,
        height: 1.0,
        radius: 1.0,
        accuracy: 0.02,
    },
    young: 1000.0,
    poisson: 0.3,
    plane: Plane::Strain,
    load: 1.0,
    mesh_size: 64,
};

/// Every contact scene, in `list` order.
pub const CONTACT_SCENES: [ContactScene; 3] = [SIGNORINI_PATCH, HERTZ, SIGNORINI_GAP];

/// Boundary markers of [`gap_block_mesh`]: the bottom `y = 0` (the potential contact
/// boundary), as [`TriangleMesh::rectangle`]'s.
pub const GAP_BOTTOM: u32 = 1;
/// Boundary markers of [`gap_block_mesh`]: the free side `x = w`.
pub const GAP_SIDE: u32 = 2;
/// Boundary markers of [`gap_block_mesh`]: the loaded top `y = height`.
pub const GAP_TOP: u32 = 3;
/// Boundary markers of [`gap_block_mesh`]: the symmetry line `x = 0`.
pub const GAP_AXIS: u32 = 4;

/// The half block `(0, half_width) × (0, height)`, graded towards the contact zone, the
/// segment from the origin to `(zone, 0)`: cells of diameter at most `contact_h` over
/// it, growing like `grading · distance` away from it, at most `min(w, height)/4`.
/// Markers [`GAP_BOTTOM`], [`GAP_SIDE`], [`GAP_TOP`], [`GAP_AXIS`] (those of
/// [`TriangleMesh::rectangle`], whose names `bottom`, `right`, `top`, `left` it keeps).
///
/// A 4×4 rectangle refined by [`TriangleMesh::refine_to_size`] (newest-vertex bisection).
///
/// # Errors
/// [`Error::Input`] for sizes not positive and finite or `contact_h` above the block's
/// size; the mesh's errors (more than 20 million cells).
pub fn gap_block_mesh(
    half_width: f64,
    height: f64,
    zone: f64,
    contact_h: f64,
    grading: f64,
) -> Result<TriangleMesh> {
    let positive = |v: f64| v.is_finite() && v > 0.0;
    let largest = 0.25 * half_width.min(height);
    let zone_ok = zone.is_finite() && zone >= 0.0;
    let sizes_ok = positive(half_width) && positive(height) && positive(contact_h);
    if !(sizes_ok && positive(grading) && zone_ok) || contact_h > largest {
        return Err(Error::Input(format!(
            "the gap block's mesh needs positive sizes, zone ≥ 0 and contact_h ≤ min(w, height)/4, got w {half_width}, height {height}, zone {zone}, contact_h {contact_h}, grading {grading}"
        )));
    }
    let size = |p: [f64; 2]| {
        let d = (p[0] - zone).max(0.0).hypot(p[1]);
        contact_h.max(grading * d).min(largest)
    };
    Ok(
        TriangleMesh::rectangle(0.0, half_width, 0.0, height, 4, 4, Diagonal::Right)?
            .refine_to_size(size, |_, p| p, 20_000_000)?
            .0,
    )
}

/// Boundary markers of [`hertz_mesh`]: the arc (the potential contact boundary).
pub const HERTZ_ARC: u32 = 1;
/// Boundary markers of [`hertz_mesh`]: the flat top `y = radius` (the load).
pub const HERTZ_TOP: u32 = 2;
/// Boundary markers of [`hertz_mesh`]: the symmetry line `x = 0`.
pub const HERTZ_AXIS: u32 = 3;

/// The quarter `x ≥ 0, y ≤ radius` of the disc of radius `radius` centred at
/// `(0, radius)` (the right half of a half disc resting on the plane `y = 0` at the
/// origin), graded towards the contact zone, the segment from the origin to
/// `(zone, 0)`: cells of diameter at most `contact_h` along the arc above it, growing
/// like `grading · distance` from that part of the arc (at most `radius / 6`). Markers [`HERTZ_ARC`],
/// [`HERTZ_TOP`], [`HERTZ_AXIS`]; the arc's vertices lie on the circle.
///
/// `TriangleMesh::quarter_disk` refined by `TriangleMesh::refine_to_size` (newest-vertex
/// bisection, new arc vertices moved onto the circle).
///
/// # Errors
/// [`Error::Input`] for a radius, `contact_h` or `grading` not positive and finite, or
/// `contact_h > radius`; the mesh's errors.
pub fn hertz_mesh(radius: f64, zone: f64, contact_h: f64, grading: f64) -> Result<TriangleMesh> {
    let positive = |v: f64| v.is_finite() && v > 0.0;
    if !(positive(radius) && positive(contact_h) && positive(grading))
        || contact_h > radius
        || !(zone.is_finite() && zone >= 0.0)
    {
        return Err(Error::Input(format!(
            "the Hertz mesh needs 0 < contact_h ≤ radius, zone ≥ 0 and grading > 0, got radius {radius}, zone {zone}, contact_h {contact_h}, grading {grading}"
        )));
    }
    let largest = radius / 6.0;
    // The distance to the arc's part below x = zone (not to the flat segment under it:
    // the arc rises like x²/2R, which at b/h = 512 already exceeds h/grading at x = b and
    // left the edge of contact coarser than asked).
    let angle = (zone / radius).min(1.0).asin();
    let end = [radius * angle.sin(), radius - radius * angle.cos()];
    let size = |p: [f64; 2]| {
        let (dx, dy) = (p[0], p[1] - radius);
        let d = if dx.atan2(-dy) <= angle {
            (radius - dx.hypot(dy)).abs()
        } else {
            (p[0] - end[0]).hypot(p[1] - end[1])
        };
        contact_h.max(grading * d).min(largest)
    };
    let arc = BoundaryCurve::Circle {
        centre: [0.0, radius],
        radius,
    };
    let onto_circle = |marker: u32, p: [f64; 2]| {
        if marker == HERTZ_ARC {
            arc.project(p)
        } else {
            p
        }
    };
    // 4 rings: cells of R/4 to start, refined to the size field; adaptive refinement
    // keeps the arc's new vertices on the circle too
    Ok(TriangleMesh::quarter_disk(radius, 4)?
        .refine_to_size(size, onto_circle, 20_000_000)?
        .0
        .with_boundary_curve(HERTZ_ARC, arc))
}
