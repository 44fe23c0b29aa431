//! The Signorini contact scenes (docs/contact.md, issue 14), as data: the body, its
//! material, the load and the foundation; the solver is the CLI's (`src/signorini.rs`)
//! over [`crate::signorini::solve_signorini`].

use crate::signorini::{
    solve_signorini, Displacement, Hertz, Plane, SignoriniInput, SignoriniSolution,
};
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
    /// E* and R ([`gap_block_reference`]); the finite block's deviation from it was
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

/// The reference of a [`ContactBody::GapBlock`] scene: Hertz line contact with the
/// scene's E, ν, R and the load P (`None` for the other bodies).
pub fn gap_block_reference(scene: &ContactScene, load: f64) -> Option<Hertz> {
    match scene.body {
        ContactBody::GapBlock { .. } => scene.hertz(load),
        _ => None,
    }
}

/// A gap-block computation against Hertz's pressure.
#[derive(Clone, Debug)]
pub struct GapBlockResult {
    /// The reference.
    pub hertz: Hertz,
    /// The cell size over the contact zone.
    pub contact_h: f64,
    /// The computed solution (on the half block).
    pub solution: SignoriniSolution,
    /// `‖λ_h − p‖ / ‖p‖` over the whole contact line (both halves, by symmetry), with
    /// the exact integrals of [`Hertz::relative_l2_error_p0`].
    pub pressure_l2_error: f64,
    /// The same error of the best P0 fit on the same edges: the floor of any P0
    /// multiplier.
    pub best_fit_l2_error: f64,
}

/// Solves a [`ContactBody::GapBlock`] scene at load P with cells of `b/b_over_h` over
/// `x ≤ 1.25 b` (b Hertz's half-width), grading 0.25, and compares the pressure with
/// Hertz's.
///
/// # Errors
/// [`Error::Input`] for another body or `b_over_h` not positive and finite; those of
/// [`gap_block_mesh`] and [`solve_signorini`].
pub fn solve_gap_block(
    scene: &ContactScene,
    load: f64,
    b_over_h: f64,
    element: Displacement,
    alpha: Option<f64>,
) -> Result<GapBlockResult> {
    let ContactBody::GapBlock {
        half_width,
        height,
        radius,
        ..
    } = scene.body
    else {
        return Err(Error::Input(format!(
            "`{}` is not a block over a gap",
            scene.name
        )));
    };
    if !(b_over_h.is_finite() && b_over_h > 0.0) {
        return Err(Error::Input(format!("b/h = {b_over_h} must be positive")));
    }
    if !(load.is_finite() && load > 0.0) {
        return Err(Error::Input(format!(
            "the load P = {load} must be positive and finite: a pull lifts the block off the foundation"
        )));
    }
    let hertz = Hertz {
        radius,
        young: scene.young,
        poisson: scene.poisson,
        load,
    };
    let b = hertz.half_width();
    let h = b / b_over_h;
    // the grading tightens with b/h as on Hertz's meshes (docs/contact.md §4): at a fixed
    // 0.25 P1 stalled at 4.75× the best fit by b/h = 512, its peak 0.29 % high
    let grading = (4.0 / b_over_h).min(0.25);
    let mesh = gap_block_mesh(half_width, height, 1.25 * b, h, grading)?;
    // the half block carries P/2 over its top of width w
    let q = load / (2.0 * half_width);
    let pressure = move |_: &[f64]| q;
    let gap = move |x: &[f64]| x[0] * x[0] / (2.0 * radius);
    let input = SignoriniInput {
        young: scene.young,
        poisson: scene.poisson,
        plane: scene.plane,
        element,
        contact: &[GAP_BOTTOM],
        load: &[GAP_TOP],
        pressure: &pressure,
        gap: &gap,
        contact_direction: [0.0, -1.0],
        fixed_x: &[GAP_AXIS],
        fixed_y: &[],
        rollers: &[],
        alpha,
        contact_centre: Some(0.0),
    };
    let solution = solve_signorini(&mesh, &input)?;
    let (pressure_l2_error, best_fit_l2_error) = compare_gap_block(&hertz, &solution);
    Ok(GapBlockResult {
        hertz,
        contact_h: h,
        pressure_l2_error,
        best_fit_l2_error,
        solution,
    })
}

/// The relative L² errors against Hertz's pressure of a solution on the half block
/// ([`gap_block_mesh`]) and of the best P0 fit on its edges, over the whole contact line
/// (each half edge and its mirror image), with the exact integrals of
/// [`Hertz::relative_l2_error_p0`].
pub fn compare_gap_block(hertz: &Hertz, solution: &SignoriniSolution) -> (f64, f64) {
    let mut intervals = Vec::with_capacity(2 * solution.contact_edges.len());
    let mut values = Vec::with_capacity(intervals.capacity());
    for (e, &p) in solution.contact_edges.iter().zip(&solution.pressure) {
        let (a, c) = (e.ends[0][0], e.ends[1][0]);
        let (x0, x1) = (a.min(c), a.max(c));
        intervals.push([x0, x1]);
        intervals.push([-x1, -x0]);
        values.extend([p, p]);
    }
    (
        hertz.relative_l2_error_p0(&intervals, &values),
        hertz.best_p0_relative_l2_error(&intervals),
    )
}
