//! Signorini contact (docs/mathematics.md §7, MODELS.md §7): a linear elastic body
//! (plane strain or plane stress: the Lamé parameters `μ_L`, `λ_L` are given) on a rigid
//! foundation, frictionless, with a multiplier λ ≥ 0 on the potential contact boundary
//! `Γ_C`, the contact pressure `λ = −σ_n(u)`.
//!
//! In the frame of §1: `s = −1`, `Bv = v·n_c`, `ψ = g` (the initial gap along the
//! contact direction `n_c = (n_c_x, n_c_y)`, a unit vector: the rigid plane's normal
//! pointing away from the body, or n itself), `b(v,μ) = −(μ, v·n_c)_{Γ_C}`, the
//! residual of the contact equation `λ + σ_n(u)` with `σ_n(v) = n_c·σ(v)n` traced from
//! the cell next to the edge (n the outward normal), and no data term in the
//! stabilization:
//! `S_h = Σ_{E⊂Γ_C} h_E (λ + σ_n(u), μ + σ_n(v))_E`, `B_h = a − b − bᵀ − α S_h`.
//! The load is a pressure `q` (force per length, positive pushing in) on the boundary
//! part `Γ_N`: `ℓ(v) = −(q, v·n)_{Γ_N}`.
//!
//! The multiplier is declared as a P0 field so that the facet kernels see its trace (1
//! on the edge); it lives on the edges of `Γ_C` only: the solver gives it one DOF per
//! contact edge (`fem_models::signorini` solver below).

/// One elasticity–contact model per displacement element: the forms are one text.
macro_rules! signorini_model {
    ($(#[$doc:meta])* $name:ident, $element:ident) => {
        fem_runtime::model! {
            $(#[$doc])*
            pub mod $name on triangle {
                unknowns: u: [$element]^2, λ: P0 >= 0;
                tests: v, μ;
                params: μ_L > 0, λ_L, α, n_c_x, n_c_y;
                data: q: 0, g: 1;
                facets: Γ_C, Γ_N;
                forms: "
                    σ(u)             := 2μ_L ε(u) + λ_L tr ε(u) I
                    σ_n(u)           := (σ(u)·n)·n_c
                    a(u;v)           = ∫ σ(u):ε(v)
                    b(v;μ)           = −∫_Γ_C μ v·n_c ds
                    S(u,λ;v,μ)       = ∫_Γ_C h_E (λ + σ_n(u))(μ + σ_n(v)) ds
                    ℓ(v)             = −∫_Γ_N q v·n ds
                    G(μ)             = −∫_Γ_C g μ ds
                    B_h(u,λ;v,μ)     = a(u;v) − b(v;λ) − b(u;μ) − α S(u,λ;v,μ)
                    L_h(v,μ)         = ℓ(v) − G(μ)
                ";
            }
        }
    };
}

signorini_model! {
    /// Signorini contact, u ∈ `[P1]²`, λ ∈ P0 on the edges of Γ_C, stabilized (§7).
    signorini_p1, P1
}

signorini_model! {
    /// Signorini contact, u ∈ `[P2]²`, λ ∈ P0 on the edges of Γ_C, stabilized (§7).
    signorini_p2, P2
}

use fem_runtime::contact::{
    discretize_boundary_multiplier, inverse_constants, BoundaryMultiplierProblem, ContactEdge,
};
use fem_runtime::lcp::{quadratic_program, semismooth_newton, LcpSolution, NewtonOptions};
use fem_runtime::{Coefficients, DataFn, Error, Model, Result, TriangleMesh};

/// Plane strain (`ε_zz = 0`, a long body) or plane stress (`σ_zz = 0`, a thin plate).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Plane {
    /// `λ_L = Eν/((1+ν)(1−2ν))`.
    Strain,
    /// `λ_L = Eν/(1−ν²)` (the plane-stress reduction `2λμ/(λ+2μ)` of the 3D value).
    Stress,
}

/// The displacement element.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Displacement {
    /// u ∈ `[P1]²` ([`signorini_p1`]).
    P1,
    /// u ∈ `[P2]²` ([`signorini_p2`]).
    P2,
}

/// A Signorini problem on a triangle mesh: the body, its supports, the load and the
/// foundation. Boundary parts are given by the mesh's boundary markers.
#[derive(Clone, Copy)]
pub struct SignoriniInput<'a> {
    /// Young's modulus E > 0 (force per area).
    pub young: f64,
    /// Poisson's ratio ν ∈ (−1, ½).
    pub poisson: f64,
    /// Plane strain or plane stress.
    pub plane: Plane,
    /// The displacement element.
    pub element: Displacement,
    /// Potential contact boundary Γ_C.
    pub contact: &'a [u32],
    /// The loaded boundary Γ_N.
    pub load: &'a [u32],
    /// The pressure q on Γ_N (force per length, positive pressing in), a function of x.
    pub pressure: &'a DataFn,
    /// The initial gap g along `contact_direction` on Γ_C (length), a function of x.
    pub gap: &'a DataFn,
    /// The contact direction `n_c`: the foundation's normal pointing away from the body
    /// (`[0, −1]` for a foundation below); normalized here.
    pub contact_direction: [f64; 2],
    /// Edges where `u_x = 0` (a symmetry line or a roller).
    pub fixed_x: &'a [u32],
    /// Edges where `u_y = 0`.
    pub fixed_y: &'a [u32],
    /// The stabilization parameter; `None`: `α = 1/(2 max_E C_I,E)` (MODELS.md §7);
    /// `Some(0.0)`: the plain mixed method, solved as a QP.
    pub alpha: Option<f64>,
    /// The x of the middle of the contact zone, for the half-width (a symmetry line);
    /// `None`: the middle of the pressed edges.
    pub contact_centre: Option<f64>,
}

/// A solved Signorini problem.
#[derive(Clone, Debug)]
pub struct SignoriniSolution {
    /// The stabilization parameter used.
    pub alpha: f64,
    /// `C_I,E` per contact edge (computed from the kernels), in `contact_edges` order.
    pub inverse_constants: Vec<f64>,
    /// The displacement: the full primal DOF vector, the `u_x` DOFs then the `u_y` ones
    /// (each numbered by the element's DOF map on the mesh).
    pub displacement: Vec<f64>,
    /// The contact pressure λ_h per contact edge (force per length, P0).
    pub pressure: Vec<f64>,
    /// The edges of Γ_C.
    pub contact_edges: Vec<ContactEdge>,
    /// Force of the foundation on the body, `Σ_E λ_E |E| (−n_c)`.
    pub total_contact_force: [f64; 2],
    /// Resultant of the applied pressure, `∫_Γ_N q (−n) ds` (Gauss–Legendre, 4 points per edge).
    pub applied_load: [f64; 2],
    /// Half the extent along x of the edges that carry pressure (λ_E > 0), holes
    /// between them included (from `contact_centre` when given).
    pub contact_half_width: f64,
    /// The largest λ_E.
    pub max_contact_pressure: f64,
    /// `max_E |min(λ_E/λ*, r_E)|` with `r_E` the constraint residual relative to its
    /// terms and `λ*` the pressure scale: the complementarity part of the KKT residual
    /// ([`fem_runtime::lcp::Lcp::complementarity_residual`]).
    pub complementarity_residual: f64,
    /// The solver's KKT residual ([`fem_runtime::lcp::Lcp::kkt_residual`]).
    pub kkt_residual: f64,
    /// Unknowns of the LCP (free displacement DOFs + multipliers).
    pub dofs: usize,
    /// Solver iterations.
    pub iterations: usize,
    /// Wall time of the LCP solve, seconds.
    pub seconds: f64,
}

/// The Lamé parameters `(μ_L, λ_L)` of E, ν.
///
/// # Errors
/// [`Error::Input`] for E ≤ 0 or not finite, ν outside (−1, ½).
pub fn lame(young: f64, poisson: f64, plane: Plane) -> Result<(f64, f64)> {
    if !(young.is_finite() && young > 0.0) {
        return Err(Error::Input(format!(
            "Young's modulus E = {young} must be positive"
        )));
    }
    if !(poisson > -1.0 && poisson < 0.5) {
        return Err(Error::Input(format!(
            "Poisson's ratio ν = {poisson} must lie in (−1, ½)"
        )));
    }
    let mu = young / (2.0 * (1.0 + poisson));
    let lambda = match plane {
        Plane::Strain => young * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson)),
        Plane::Stress => young * poisson / (1.0 - poisson * poisson),
    };
    Ok((mu, lambda))
}

/// Solves a Signorini problem (MODELS.md §7) with the stabilized P1–P0 or P2–P0
/// method: the multiplier is one pressure per edge of Γ_C.
///
/// # Errors
/// [`Error::Input`] for E ≤ 0, ν outside (−1, ½), α negative or not finite, a part that
/// holds no boundary edge, a load that does not press the body onto Γ_C (the rigid
/// translation towards the foundation is then not prevented); the solver's errors.
pub fn solve_signorini(mesh: &TriangleMesh, input: &SignoriniInput) -> Result<SignoriniSolution> {
    match input.element {
        Displacement::P1 => solve::<signorini_p1::Model>(mesh, input),
        Displacement::P2 => solve::<signorini_p2::Model>(mesh, input),
    }
}

fn solve<M: Model>(mesh: &TriangleMesh, input: &SignoriniInput) -> Result<SignoriniSolution> {
    let (mu, lambda) = lame(input.young, input.poisson, input.plane)?;
    if let Some(a) = input.alpha {
        if !(a.is_finite() && a >= 0.0) {
            return Err(Error::Input(format!(
                "the stabilization parameter α = {a} must be ≥ 0"
            )));
        }
    }
    let [cx, cy] = input.contact_direction;
    let length = cx.hypot(cy);
    if !(length.is_finite() && length > 0.0) {
        return Err(Error::Input(format!(
            "the contact direction ({cx}, {cy}) must be a non-zero finite vector"
        )));
    }
    let direction = [cx / length, cy / length];
    let (ux, uy) = (M::field("u_x")?, M::field("u_y")?);
    let parts: [(&str, &[u32]); 2] = [("Γ_C", input.contact), ("Γ_N", input.load)];
    let fixed: [(usize, &[u32]); 2] = [(ux, input.fixed_x), (uy, input.fixed_y)];
    let coefficients = |alpha: f64| {
        Coefficients::new::<M>(
            &[
                ("μ_L", mu),
                ("λ_L", lambda),
                ("α", alpha),
                ("n_c_x", direction[0]),
                ("n_c_y", direction[1]),
            ],
            &[("q", input.pressure), ("g", input.gap)],
        )
    };
    let problem = discretize_boundary_multiplier::<M>(mesh, &coefficients(0.0)?, &parts, &fixed)?;
    let constants = inverse_constants::<M>(mesh, &problem, &coefficients(0.0)?, "a", "S")?;
    let alpha = match input.alpha {
        Some(a) => a,
        None => {
            let max = constants.iter().fold(0.0f64, |m, &c| m.max(c));
            0.5 / max
        }
    };
    let problem = if alpha == 0.0 {
        problem
    } else {
        discretize_boundary_multiplier::<M>(mesh, &coefficients(alpha)?, &parts, &fixed)?
    };
    let translation = towards_foundation(&problem, direction);
    let work: f64 = translation
        .iter()
        .zip(&problem.lcp.f)
        .map(|(t, f)| t * f)
        .sum();
    if work.is_nan() || work <= 0.0 {
        return Err(Error::Input(format!(
            "the load does not press the body onto the contact boundary (its work on a translation towards the foundation is {work:e} ≤ 0): the rigid motion is not prevented"
        )));
    }
    let solution = if alpha > 0.0 {
        // Start pressed into the foundation (every constraint active), beyond the gaps.
        let depth = problem
            .lcp
            .g
            .iter()
            .zip(&problem.contact_edges)
            .fold(0.0f64, |m, (g, e)| m.max(-g / e.length()));
        let scale = 2.0 * depth + 1e-3 * mesh.max_h();
        let start: Vec<f64> = translation.iter().map(|t| scale * t).collect();
        semismooth_newton(&problem.lcp, Some(&start), NewtonOptions::default())?
    } else {
        quadratic_program(&problem.lcp)?
    };
    Ok(report(
        mesh, input, direction, &problem, solution, alpha, constants,
    ))
}

/// The free-DOF vector of a unit translation along the contact direction: towards the
/// foundation.
fn towards_foundation(problem: &BoundaryMultiplierProblem, n: [f64; 2]) -> Vec<f64> {
    let fields = problem.dofs.fields();
    let mut full = vec![0.0; problem.dofs.dof_count()];
    for (axis, &field) in fields.iter().take(2).enumerate() {
        if let Some(range) = problem.dofs.range(field) {
            full[range].fill(n[axis]);
        }
    }
    problem.reduction.free().iter().map(|&d| full[d]).collect()
}

/// The outward unit normal of a boundary edge (its cell is counter-clockwise).
fn outward_normal(e: &ContactEdge) -> [f64; 2] {
    let [a, b] = e.ends;
    let (tx, ty) = (b[0] - a[0], b[1] - a[1]);
    let l = tx.hypot(ty);
    [ty / l, -tx / l]
}

fn report(
    mesh: &TriangleMesh,
    input: &SignoriniInput,
    direction: [f64; 2],
    problem: &BoundaryMultiplierProblem,
    solution: LcpSolution,
    alpha: f64,
    constants: Vec<f64>,
) -> SignoriniSolution {
    let lcp = &problem.lcp;
    let pressure = solution.lambda.clone();
    let mut force = [0.0; 2];
    for (e, &p) in problem.contact_edges.iter().zip(&pressure) {
        force[0] -= p * e.length() * direction[0];
        force[1] -= p * e.length() * direction[1];
    }
    let mut load = [0.0; 2];
    let gauss = fem_runtime::gauss_legendre(4);
    for &(e, marker) in mesh.boundary_edges() {
        if !input.load.contains(&marker) {
            continue;
        }
        let (cell, _) = mesh.edge_cells(e);
        let c = mesh.cell(cell);
        let local = mesh
            .cell_edges(cell)
            .iter()
            .position(|&x| x == e)
            .unwrap_or(0);
        let edge = ContactEdge {
            edge: e,
            cell,
            local,
            ends: [
                mesh.vertices()[c[local]],
                mesh.vertices()[c[(local + 1) % 3]],
            ],
        };
        let n = outward_normal(&edge);
        let [a, b] = edge.ends;
        let q: f64 = gauss
            .points
            .iter()
            .zip(&gauss.weights)
            .map(|(&s, &w)| {
                w * (input.pressure)(&[a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])])
            })
            .sum::<f64>()
            * edge.length();
        load[0] -= q * n[0];
        load[1] -= q * n[1];
    }
    let largest = pressure.iter().fold(0.0f64, |m, &p| m.max(p));
    let (mut x_min, mut x_max) = (f64::INFINITY, f64::NEG_INFINITY);
    for (e, &p) in problem.contact_edges.iter().zip(&pressure) {
        if p > 1e-10 * largest {
            for end in e.ends {
                x_min = x_min.min(end[0]);
                x_max = x_max.max(end[0]);
            }
        }
    }
    let half_width = match (x_max >= x_min, input.contact_centre) {
        (false, _) => 0.0,
        (true, None) => 0.5 * (x_max - x_min),
        (true, Some(c)) => (x_max - c).abs().max((x_min - c).abs()),
    };
    let complementarity = lcp.complementarity_residual(&solution.u, &pressure);
    SignoriniSolution {
        alpha,
        inverse_constants: constants,
        displacement: problem.reduction.expand(&solution.u),
        pressure,
        contact_edges: problem.contact_edges.clone(),
        total_contact_force: force,
        applied_load: load,
        contact_half_width: half_width,
        max_contact_pressure: largest,
        complementarity_residual: complementarity,
        kkt_residual: solution.kkt_residual,
        dofs: lcp.n() + lcp.m(),
        iterations: solution.iterations,
        seconds: solution.seconds,
    }
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
    let onto_circle = |marker: u32, p: [f64; 2]| {
        if marker != HERTZ_ARC {
            return p;
        }
        let (dx, dy) = (p[0], p[1] - radius);
        let r = dx.hypot(dy);
        [radius * dx / r, radius + radius * dy / r]
    };
    // 4 rings: cells of R/4 to start, refined to the size field
    Ok(TriangleMesh::quarter_disk(radius, 4)?
        .refine_to_size(size, onto_circle, 20_000_000)?
        .0)
}

/// Hertz line contact in plane strain (MODELS.md §7): the reference, with its exact
/// integrals, is [`crate::hertz::HertzLineContact`].
pub use crate::hertz::HertzLineContact as Hertz;

/// A Hertz computation against the formulas.
#[derive(Clone, Debug)]
pub struct HertzResult {
    /// The reference.
    pub hertz: Hertz,
    /// The cell size at the contact point.
    pub contact_h: f64,
    /// The computed solution (on the quarter disc).
    pub solution: SignoriniSolution,
    /// `‖λ_h − p‖ / ‖p‖` on Γ_C (16-point Gauss–Legendre per edge).
    pub pressure_l2_error: f64,
    /// `‖Π₀p − p‖ / ‖p‖`: the error of the best P0 fit on the same edges.
    pub best_fit_l2_error: f64,
    /// The checkerboard measure: `max |λ_{k−1} − 2λ_k + λ_{k+1}| / p_max` over
    /// consecutive contact edges (ordered by x) inside `x < 0.8 b`, where p is smooth
    /// (its own second difference there is at most `4.7 (h/b)² p_max`: 0.018 at b/h = 16).
    pub oscillation: f64,
}

/// The Hertz problem on [`hertz_mesh`]: the quarter disc with `u_x = 0` on the axis, the
/// resultant `P/2` as a uniform pressure `P/(2R)` on the top, the gap to the plane
/// `y = 0` measured vertically, the contact direction the plane's normal `(0, −1)`.
/// `b_over_h` sets the cell size at the contact point, `h = b / b_over_h`.
///
/// # Errors
/// Those of [`hertz_mesh`] and [`solve_signorini`]; [`Error::Input`] for `b_over_h` not
/// positive and finite.
pub fn solve_hertz(
    hertz: Hertz,
    b_over_h: f64,
    element: Displacement,
    alpha: Option<f64>,
) -> Result<HertzResult> {
    if !(b_over_h.is_finite() && b_over_h > 0.0) {
        return Err(Error::Input(format!("b/h = {b_over_h} must be positive")));
    }
    let h = hertz.half_width() / b_over_h;
    // Uniform cells a little beyond b: the square-root edge of the pressure lies at b.
    // The grading tightens with b/h: at a fixed 0.25 the P1 stresses carry an O(h/d)
    // relative error at every distance d, the compliance an error that refining the
    // contact zone does not reduce (the peak stayed 0.28 % high and the L² error 2–3×
    // the best fit's from b/h = 128 on; docs/contact.md §4).
    let grading = (4.0 / b_over_h).min(0.25);
    let mesh = hertz_mesh(hertz.radius, 1.25 * hertz.half_width(), h, grading)?;
    solve_hertz_on(hertz, &mesh, h, element, alpha)
}

/// [`solve_hertz`] on a given mesh of the quarter disc (markers as [`hertz_mesh`]'s),
/// `contact_h` its cell size at the contact (reported only).
///
/// # Errors
/// Those of [`solve_signorini`].
pub fn solve_hertz_on(
    hertz: Hertz,
    mesh: &TriangleMesh,
    contact_h: f64,
    element: Displacement,
    alpha: Option<f64>,
) -> Result<HertzResult> {
    let h = contact_h;
    let q = hertz.load / (2.0 * hertz.radius);
    let pressure = move |_: &[f64]| q;
    let gap = |x: &[f64]| x[1];
    let input = SignoriniInput {
        young: hertz.young,
        poisson: hertz.poisson,
        plane: Plane::Strain,
        element,
        contact: &[HERTZ_ARC],
        load: &[HERTZ_TOP],
        pressure: &pressure,
        gap: &gap,
        contact_direction: [0.0, -1.0],
        fixed_x: &[HERTZ_AXIS],
        fixed_y: &[],
        alpha,
        contact_centre: Some(0.0),
    };
    let solution = solve_signorini(mesh, &input)?;
    let gauss = fem_runtime::gauss_legendre(16);
    let (mut error, mut best, mut norm) = (0.0, 0.0, 0.0);
    for (e, &lambda) in solution.contact_edges.iter().zip(&solution.pressure) {
        let [a, b] = e.ends;
        let l = e.length();
        let at = |s: f64| hertz.pressure(a[0] + s * (b[0] - a[0]));
        let mean: f64 = gauss
            .points
            .iter()
            .zip(&gauss.weights)
            .map(|(&s, &w)| w * at(s))
            .sum();
        for (&s, &w) in gauss.points.iter().zip(&gauss.weights) {
            let p = at(s);
            error += w * l * (lambda - p) * (lambda - p);
            best += w * l * (mean - p) * (mean - p);
            norm += w * l * p * p;
        }
    }
    let mut profile: Vec<(f64, f64)> = solution
        .contact_edges
        .iter()
        .zip(&solution.pressure)
        .map(|(e, &p)| (e.midpoint()[0], p))
        .collect();
    profile.sort_by(|a, b| a.0.total_cmp(&b.0));
    let inside = 0.8 * hertz.half_width();
    let oscillation = profile
        .windows(3)
        .filter(|w| w[2].0 < inside)
        .map(|w| (w[0].1 - 2.0 * w[1].1 + w[2].1).abs())
        .fold(0.0f64, f64::max)
        / hertz.max_pressure();
    Ok(HertzResult {
        hertz,
        contact_h: h,
        oscillation,
        solution,
        pressure_l2_error: (error / norm).sqrt(),
        best_fit_l2_error: (best / norm).sqrt(),
    })
}
