//! Signorini contact (docs/contact.md): a linear elastic body
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
//! contact edge (`fem_models::signorini` solver below). Declared P1 (the `_p1` models)
//! it is continuous on `Γ_C`, one DOF per vertex of its edges
//! ([`fem_runtime::obstacle::boundary_multiplier::discretize`]).

/// One elasticity–contact model per displacement and multiplier element: the forms are
/// one text.
macro_rules! signorini_model {
    ($(#[$doc:meta])* $name:ident, $element:ident) => {
        signorini_model! { $(#[$doc])* $name, $element, P0 }
    };
    ($(#[$doc:meta])* $name:ident, $element:ident, $multiplier:ident) => {
        fem_runtime::model! {
            $(#[$doc])*
            pub mod $name on triangle {
                unknowns: u: [$element]^2, λ: $multiplier >= 0;
                tests: v, μ;
                params: μ_L > 0, λ_L, α, n_c_x, n_c_y;
                data: q: 2, g: 1;
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
                system:        B_h, L_h;
                energy:        a, ℓ;
                stabilization: α S against a;
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

signorini_model! {
    /// Signorini contact, u ∈ `[P1]²`, λ continuous P1 on Γ_C (one DOF per vertex of its
    /// edges), stabilized (§7).
    signorini_p1_p1, P1, P1
}

signorini_model! {
    /// Signorini contact, u ∈ `[P2]²`, λ continuous P1 on Γ_C (one DOF per vertex of its
    /// edges), stabilized (§7).
    signorini_p2_p1, P2, P1
}

/// The multiplier's space on Γ_C: P0 (one pressure per edge) or continuous P1 (one per
/// vertex of the edges of Γ_C), chosen with [`solve_signorini_with`].
pub use fem_runtime::obstacle::boundary_multiplier::BoundaryMultiplier as Multiplier;
use fem_runtime::obstacle::boundary_multiplier::ContactEdge;

use fem_runtime::obstacle::Discretization;
use fem_runtime::problem::{Condition, Domain, Problem, Solved as ProblemSolved};
use fem_runtime::stabilization::Alpha;
use fem_runtime::{DataFn, DirichletPart, Error, Model, Result, TriangleMesh};

/// The contact problem of `input` for model `M` on `meshes` (nested levels, coarsest
/// first), with the start that holds its rigid motions: the body pressed into the
/// foundation beyond the gaps (checked first: the load must press it on, and supports
/// must hold what the contact cannot).
fn contact_problem<'a, M: Model>(
    meshes: Vec<TriangleMesh>,
    input: &'a SignoriniInput<'a>,
    setup: &'a Setup<'a>,
    start: &'a fem_runtime::obstacle::FirstStart<'a, TriangleMesh>,
) -> Problem<'a, M, TriangleMesh> {
    let mut problem = Problem::<M, TriangleMesh>::new(meshes)
        .param("μ_L", setup.lame[0])
        .param("λ_L", setup.lame[1])
        .param("n_c_x", setup.direction[0])
        .param("n_c_y", setup.direction[1])
        .data("q", input.pressure)
        .data("g", input.gap)
        .part("Γ_C", input.contact.to_vec())
        .part("Γ_N", input.load.to_vec())
        .alpha(
            input.alpha.map_or(Alpha::default(), Alpha::Fixed),
            fem_runtime::problem::ALPHA_WHEN_CI_VANISHES,
        )
        .start(start);
    for (field, markers) in [("u_x", input.fixed_x), ("u_y", input.fixed_y)] {
        if !markers.is_empty() {
            problem = problem.support(
                DirichletPart::Markers(markers.to_vec()),
                field,
                Condition::Zero,
            );
        }
    }
    for (markers, n) in input.rollers {
        problem = problem.support(
            DirichletPart::Markers(markers.clone()),
            "u_x",
            Condition::Along(*n),
        );
    }
    problem
}

/// The start of a contact solve's first level: the body pressed into the foundation
/// (every constraint active) beyond the gaps, by the size of the elastic displacement;
/// the problem is refused first where the load does not press the body on or the
/// supports leave a motion free that contact cannot hold ([`rigid_motions_held`]).
pub(crate) fn pressed_start(
    d: &Discretization<TriangleMesh>,
    direction: [f64; 2],
) -> Result<Option<Vec<f64>>> {
    let translation = rigid_motions_held(d, direction)?;
    let b = d.boundary().expect("a boundary multiplier");
    // -g_k / ∫μ_k ds: the gap at constraint k (∫μ_k ds is |E| for P0)
    let depth = d
        .lcp
        .g
        .iter()
        .zip(b.integrals())
        .fold(0.0f64, |m, (g, w)| m.max(-g / w));
    // beyond the gaps by the size of the elastic displacement (‖F‖∞/‖A‖∞, both in the
    // units of E): a fixed 1e-3 h was 1e22 times it at E = 1e25, and its multipliers
    // C⁻¹(G − BU) left Newton a Hessian that was not positive definite
    let lcp = &d.lcp;
    let a_norm = (0..lcp.n())
        .map(|j| lcp.a.val_of_col(j).iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0f64, f64::max);
    let f_norm = lcp.f.iter().fold(0.0f64, |m, f| m.max(f.abs()));
    let elastic = f_norm / a_norm.max(f64::MIN_POSITIVE);
    let scale = 2.0 * depth + elastic.min(1e-3 * d.mesh.max_h());
    Ok(Some(translation.iter().map(|t| scale * t).collect()))
}

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
    /// Rollers along any direction: on the edges of the markers, `u·n = 0` for the unit
    /// `n` (a support on a face that is neither along x nor along y).
    pub rollers: &'a [(Vec<u32>, [f64; 2])],
    /// The stabilization parameter; `None`: `α = 1/(2 max_E C_I,E)` (docs/contact.md);
    /// `Some(0.0)`: the plain mixed method, solved as a QP.
    pub alpha: Option<f64>,
    /// The middle of the contact zone, for the half-width (a symmetry line), as a
    /// coordinate along the contact plane ([`contact_tangent`]: x under a horizontal
    /// plane, y beside a vertical one); `None`: the middle of the pressed edges.
    pub contact_centre: Option<f64>,
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
    /// The contact pressure λ_h per multiplier DOF (force per length): per contact edge
    /// (P0, in `contact_edges` order) or per vertex of Γ_C (P1, in `contact_vertices`
    /// order). Along Γ_C: [`SignoriniSolution::edge_pressures`].
    pub pressure: Vec<f64>,
    /// The edges of Γ_C.
    pub contact_edges: Vec<ContactEdge>,
    /// The multiplier's space.
    pub multiplier: Multiplier,
    /// P1: the mesh vertices of Γ_C (ascending), where `pressure` lives. Empty for P0.
    pub contact_vertices: Vec<usize>,
    /// Per contact edge, the indices into `pressure` of its ends `ends[0]`, `ends[1]`
    /// (P1) or `[k, k]` (P0).
    pub edge_dofs: Vec<[usize; 2]>,
    /// Force of the foundation on the body, `Σ_E ∫_E λ_h ds (−n_c)` (P0: `Σ_E λ_E |E|`).
    pub total_contact_force: [f64; 2],
    /// Resultant of the applied pressure, `∫_Γ_N q (−n) ds` (Gauss–Legendre, 4 points per edge).
    pub applied_load: [f64; 2],
    /// The load's resultant along the contact direction `n_c` as the discretization
    /// integrates it: `ℓ(t)` for the unit translation `t` along `n_c` (the model's
    /// quadrature of `q v·n` on Γ_N, exact for the degree of `q` the model declares). The
    /// contact force balances this one to rounding, whatever `q`; it differs from
    /// `applied_load · n_c` by the quadrature error of a pressure that varies faster.
    pub discretized_load: f64,
    /// Half the extent of the edges that carry pressure (λ_E > 0), holes between them
    /// included, along the contact plane (the coordinate of [`contact_tangent`]: x under
    /// a horizontal plane, y beside a vertical one); from `contact_centre` when given.
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

impl SignoriniSolution {
    /// λ_h at the two ends `ends[0]`, `ends[1]` of each contact edge (`contact_edges`
    /// order): equal for P0; λ_h is linear in between (P1) or constant (P0).
    pub fn edge_pressures(&self) -> Vec<[f64; 2]> {
        self.edge_dofs
            .iter()
            .map(|&[a, b]| [self.pressure[a], self.pressure[b]])
            .collect()
    }

    /// λ_h at `ends[0] + s (ends[1] − ends[0])` of contact edge `edge`, s ∈ [0, 1]
    /// (clamped); `None` for an edge index out of range.
    pub fn pressure_at(&self, edge: usize, s: f64) -> Option<f64> {
        let [a, b] = *self.edge_dofs.get(edge)?;
        let s = s.clamp(0.0, 1.0);
        Some((1.0 - s) * self.pressure[a] + s * self.pressure[b])
    }

    /// The pressure along Γ_C for a chart, `(x, λ_h)` sorted by x: the edge midpoints
    /// (P0) or the vertices (P1, where λ_h is linear in between).
    pub fn pressure_profile(&self) -> Vec<(f64, f64)> {
        let mut profile: Vec<(f64, f64)> = match self.multiplier {
            Multiplier::P0 => self
                .contact_edges
                .iter()
                .zip(&self.pressure)
                .map(|(e, &p)| (e.midpoint()[0], p))
                .collect(),
            Multiplier::P1 => {
                let mut points = vec![(0.0, 0.0); self.pressure.len()];
                for (e, dofs) in self.contact_edges.iter().zip(&self.edge_dofs) {
                    for (end, &k) in e.ends.iter().zip(dofs) {
                        points[k] = (end[0], self.pressure[k]);
                    }
                }
                points
            }
        };
        profile.sort_by(|a, b| a.0.total_cmp(&b.0));
        profile
    }
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

/// Solves a Signorini problem (docs/contact.md) with the stabilized P1–P0 or P2–P0
/// method: the multiplier is one pressure per edge of Γ_C.
///
/// # Errors
/// [`Error::Input`] for E ≤ 0, ν outside (−1, ½), α negative or not finite, a part that
/// holds no boundary edge, a load that does not press the body onto Γ_C (the rigid
/// translation towards the foundation is then not prevented), a pressure on edges of
/// Γ_C ([`refuse_pressure_on_contact`]); the solver's errors.
pub fn solve_signorini(mesh: &TriangleMesh, input: &SignoriniInput) -> Result<SignoriniSolution> {
    solve_signorini_with(mesh, input, Multiplier::P0)
}

/// [`solve_signorini`] with the multiplier's space chosen: P0 (the same) or continuous
/// P1 on Γ_C ([`signorini_p1_p1`], [`signorini_p2_p1`]; its `C` block lumped, see
/// `fem_runtime::obstacle::boundary_multiplier::discretize`).
///
/// # Errors
/// Those of [`solve_signorini`].
pub fn solve_signorini_with(
    mesh: &TriangleMesh,
    input: &SignoriniInput,
    multiplier: Multiplier,
) -> Result<SignoriniSolution> {
    refuse_pressure_on_contact(mesh, input)?;
    match (input.element, multiplier) {
        (Displacement::P1, Multiplier::P0) => solve::<signorini_p1::Model>(mesh, input),
        (Displacement::P2, Multiplier::P0) => solve::<signorini_p2::Model>(mesh, input),
        (Displacement::P1, Multiplier::P1) => solve::<signorini_p1_p1::Model>(mesh, input),
        (Displacement::P2, Multiplier::P1) => solve::<signorini_p2_p1::Model>(mesh, input),
    }
}

/// An error when the pressure q is not zero on an edge of both Γ_C and Γ_N. There
/// `σ(u)n = −q n − λ n_c`, so the residual the stabilization penalizes,
/// `λ + σ_n(u) = −q n·n_c`, is not zero at the exact solution: the method would not be
/// consistent (a uniform block, loaded on its top and on its contact side,
/// gave pressures off by 8 % instead of the exact patch value). q is sampled at 17
/// evenly spaced points of each shared edge (3 missed a bump between them), and counts
/// as zero below 1e-12 of its largest value on Γ_N (`cos(πy/2)` is 6e-17 at y = 1).
///
/// # Errors
/// [`Error::Input`] naming the first shared edge where q ≠ 0 and the value there.
pub fn refuse_pressure_on_contact(mesh: &TriangleMesh, input: &SignoriniInput) -> Result<()> {
    let v = mesh.vertices();
    let edge_points = |e: usize| {
        let [a, b] = mesh.edges()[e];
        let (p, q) = (v[a], v[b]);
        (0..=SAMPLES).map(move |k| {
            let t = k as f64 / SAMPLES as f64;
            [p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]
        })
    };
    // zero to the rounding of the pressure's size on Γ_N: cos(πy/2) on y = 1 is 6e-17
    let largest = mesh
        .boundary_edges()
        .iter()
        .filter(|(_, m)| input.load.contains(m))
        .flat_map(|&(e, _)| edge_points(e))
        .map(|x| (input.pressure)(&x).abs())
        .filter(|q| q.is_finite())
        .fold(0.0f64, f64::max);
    for &(e, marker) in mesh.boundary_edges() {
        if !(input.contact.contains(&marker) && input.load.contains(&marker)) {
            continue;
        }
        let [a, b] = mesh.edges()[e];
        let (p, q) = (v[a], v[b]);
        for x in edge_points(e) {
            let pressure = (input.pressure)(&x);
            if pressure.is_nan() || pressure.abs() > 1e-12 * largest {
                return Err(Error::Input(format!(
                    "the edge from ({}, {}) to ({}, {}) is both on the contact boundary Γ_C and on the loaded boundary Γ_N, and the pressure there is {pressure:e} at ({}, {}): the stabilization assumes no load on Γ_C (its residual λ + σ_n(u) would be −q n·n_c at the exact solution, and the pressures wrong); take the edge out of one of the two parts, or make the pressure vanish on it",
                    p[0], p[1], q[0], q[1], x[0], x[1]
                )));
            }
        }
    }
    Ok(())
}

/// Intervals per edge at which [`refuse_pressure_on_contact`] samples the pressure.
const SAMPLES: usize = 16;

/// What every Signorini solve derives from its input: the Lamé parameters and the unit
/// contact direction.
struct Setup<'a> {
    lame: [f64; 2],
    direction: [f64; 2],
    input: std::marker::PhantomData<&'a ()>,
}

impl Setup<'_> {
    /// # Errors
    /// [`Error::Input`] for E, ν out of range ([`lame`]), a zero contact direction, a
    /// negative α, and a support along the contact direction on Γ_C itself.
    fn new(input: &SignoriniInput) -> Result<Self> {
        if let Some(a) = input.alpha {
            if !(a.is_finite() && a >= 0.0) {
                return Err(Error::Input(format!(
                    "the stabilization parameter α = {a} must be ≥ 0"
                )));
            }
        }
        let (mu, lambda) = lame(input.young, input.poisson, input.plane)?;
        let [cx, cy] = input.contact_direction;
        let length = cx.hypot(cy);
        if !(length.is_finite() && length > 0.0) {
            return Err(Error::Input(format!(
                "the contact direction ({cx}, {cy}) must be a non-zero finite vector"
            )));
        }
        let direction = [cx / length, cy / length];
        // a support along n_c on Γ_C itself fights the contact constraint for u·n_c (a
        // fixed_y on the contact side gave a force of 0.001 for a load of 5)
        for (axis, fixed, name) in [(0, input.fixed_x, "x"), (1, input.fixed_y, "y")] {
            if direction[axis] != 0.0 && fixed.iter().any(|m| input.contact.contains(m)) {
                return Err(Error::Input(format!(
                    "the contact boundary (markers {:?}) also has u_{name} = 0 (markers {fixed:?}), a component of the contact direction ({:.3}, {:.3}): the support and the contact constraint both fix u·n_c there; drop the support on the contact part",
                    input.contact, direction[0], direction[1]
                )));
            }
        }
        for (markers, n) in input.rollers {
            let along = n[0] * direction[0] + n[1] * direction[1];
            if along.abs() > 1e-12 && markers.iter().any(|m| input.contact.contains(m)) {
                return Err(Error::Input(format!(
                    "the contact boundary (markers {:?}) also has a roller along ({:.3}, {:.3}), which has a component along the contact direction ({:.3}, {:.3}): the support and the contact constraint both fix u·n_c there; drop the support on the contact part",
                    input.contact, n[0], n[1], direction[0], direction[1]
                )));
            }
        }
        Ok(Self {
            lame: [mu, lambda],
            direction,
            input: std::marker::PhantomData,
        })
    }
}

fn solve<M: Model>(mesh: &TriangleMesh, input: &SignoriniInput) -> Result<SignoriniSolution> {
    let setup = Setup::new(input)?;
    let direction = setup.direction;
    let start = move |d: &Discretization<TriangleMesh>| pressed_start(d, direction);
    let solved = contact_problem::<M>(vec![mesh.clone()], input, &setup, &start).solve()?;
    report::<M>(input, direction, &solved)
}

/// Checks that the load holds the body on the foundation, and returns the free-DOF
/// vector of the unit translation towards it.
///
/// Frictionless contact resists only along `n_c`: the load must press the body on
/// (positive work on the translation towards the foundation), and a support must fix
/// the translation along the tangent (else `A` vanishes on it: singular, and a load
/// with a tangential part has no equilibrium at all — a block pushed sideways
/// "solved" with a 1 % equilibrium error).
///
/// # Errors
/// [`Error::Input`] naming the unbalanced component.
fn rigid_motions_held(problem: &Discretization<TriangleMesh>, n: [f64; 2]) -> Result<Vec<f64>> {
    let mesh = &problem.mesh;
    let f = &problem.lcp.f;
    let dot = |x: &[f64], y: &[f64]| x.iter().zip(y).map(|(a, b)| a * b).sum::<f64>();
    let translation = towards_foundation(problem, n);
    let work = dot(&translation, f);
    let norm = |x: &[f64]| x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let scale = norm(problem.lcp.a.val()).max(f64::MIN_POSITIVE);
    let product = |x: &[f64]| fem_runtime::lcp::cholesky::multiply(&problem.lcp.a, x);
    // supports along n_c hold the body whatever the load: only a free translation
    // needs the load to press it on
    let translation_free =
        norm(&translation) > 0.0 && norm(&product(&translation)) <= 1e-10 * scale;
    if translation_free && (work.is_nan() || work <= 0.0) {
        return Err(Error::Input(format!(
            "the load does not press the body onto the contact boundary (its work on a translation towards the foundation is {work:e} ≤ 0, with q at the quadrature points of the edges of Γ_N: a pressure confined within an edge can fall between them; refine the mesh): the rigid motion is not prevented"
        )));
    }
    let tangent = towards_foundation(problem, [-n[1], n[0]]);
    let free = norm(&product(&tangent)) <= 1e-10 * scale;
    let sliding = dot(&tangent, f);
    if free && norm(&tangent) > 0.0 {
        let load = if sliding.abs() > 1e-10 * work.abs() {
            format!(" and the load pushes it that way (work {sliding:e} against {work:e} towards the foundation)")
        } else {
            String::new()
        };
        return Err(Error::Input(format!(
            "no support fixes the body along the foundation, the direction ({:.3}, {:.3}){load}: frictionless contact leaves that translation free and the system singular; fix that displacement component on a symmetry line or a roller",
            -n[1], n[0]
        )));
    }
    rotation_held(mesh, problem, n, [&translation, &tangent], translation_free)?;
    Ok(translation)
}

/// Refuses a body that tips: when the supports leave a rotation free (a rigid motion
/// `Z = R + aT + bS` with `A Z = 0`: `R` the rotation about the origin, `T` and `S` the
/// translations along and across `n_c`), only the contact can hold it. With
/// `s(x) = Z(x)·n_c` the motion of point `x` towards the foundation, the load must do
/// negative work on every free rigid motion that opens every contact (Fichera's
/// condition), over the vertices of Γ_C:
/// - `T` free too: the motions `Z − s_max T` and `s_min T − Z` span those, so
///   `s_min W < f·Z < s_max W` with `W = f·T > 0`: the resultant meets Γ_C;
/// - `T` held by supports: only `βZ`, which opens every contact for `β ≥ 0` if
///   `s ≤ 0` on Γ_C (then `f·Z < 0` is needed), for `β ≤ 0` if `s ≥ 0` (`f·Z > 0`),
///   for every β if `s ≡ 0` (`f·Z = 0`), and for none if `s` changes sign.
///
/// Otherwise there is no equilibrium and Newton's answer misses the load (a
/// block against a wall "solved" with the contact force 39 % off the load).
fn rotation_held(
    mesh: &TriangleMesh,
    problem: &Discretization<TriangleMesh>,
    n: [f64; 2],
    [translation, tangent]: [&[f64]; 2],
    translation_free: bool,
) -> Result<()> {
    let fields = problem.dofs.fields();
    let mut full = vec![0.0; problem.dofs.dof_count()];
    for (axis, &field) in fields.iter().take(2).enumerate() {
        let (Some(range), Some(map)) = (problem.dofs.range(field), problem.dofs.map(field)) else {
            continue;
        };
        // (−y, x): the rotation about the origin
        for (d, x) in range.zip(map.nodes(mesh)) {
            full[d] = if axis == 0 { -x[1] } else { x[0] };
        }
    }
    // in the primed DOFs of the supports' rotated groups (oblique rollers)
    problem.basis.to_primed(&mut full);
    let rotation: Vec<f64> = problem.reduction.free().iter().map(|&d| full[d]).collect();
    let a = &problem.lcp.a;
    let multiply = |x: &[f64]| fem_runtime::lcp::cholesky::multiply(a, x);
    let dot = |x: &[f64], y: &[f64]| x.iter().zip(y).map(|(a, b)| a * b).sum::<f64>();
    let norm = |x: &[f64]| x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let (at, as_, ar) = (
        multiply(translation),
        multiply(tangent),
        multiply(&rotation),
    );
    // the combination of the translations closest to making R free (least squares)
    let (tt, ts, ss) = (dot(&at, &at), dot(&at, &as_), dot(&as_, &as_));
    let (tr, sr) = (dot(&at, &ar), dot(&as_, &ar));
    let det = tt * ss - ts * ts;
    let [a_t, b_s] = if det > 1e-12 * tt * ss && det > 0.0 {
        [(-tr * ss + sr * ts) / det, (-sr * tt + tr * ts) / det]
    } else if ss > 0.0 {
        [0.0, -sr / ss]
    } else {
        [0.0, 0.0]
    };
    let motion: Vec<f64> = (0..rotation.len())
        .map(|i| rotation[i] + a_t * translation[i] + b_s * tangent[i])
        .collect();
    let residual: Vec<f64> = (0..rotation.len())
        .map(|i| ar[i] + a_t * at[i] + b_s * as_[i])
        .collect();
    let scale = norm(a.val()).max(f64::MIN_POSITIVE) * norm(&motion);
    if norm(&motion) == 0.0 || norm(&residual) > 1e-10 * scale {
        return Ok(());
    }
    // s(x) = Z(x)·n = (−y, x)·n + a_t (S is normal to n)
    let s_of = |x: [f64; 2]| -x[1] * n[0] + x[0] * n[1] + a_t;
    let (s_min, s_max) = problem
        .boundary()
        .expect("a boundary multiplier")
        .edges
        .iter()
        .flat_map(|e| e.ends)
        .map(s_of)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), s| {
            (lo.min(s), hi.max(s))
        });
    let f = &problem.lcp.f;
    let moment = dot(&motion, f);
    let work = dot(translation, f);
    // rounding of the sums: a load doing (almost) no work on a motion is not refused
    let terms: f64 = motion.iter().zip(f).map(|(z, f)| (z * f).abs()).sum();
    let slack = 1e-9 * terms;
    // s at rounding level of the coordinates counts as 0
    let size = s_min.abs().max(s_max.abs()).max(f64::MIN_POSITIVE);
    let (below, above) = (s_min < -1e-12 * size, s_max > 1e-12 * size);
    let tips = match (translation_free, below, above) {
        (true, _, _) => {
            let slack = 1e-9 * work.abs() * (s_max - s_min).abs().max(1.0) + slack;
            moment < s_min * work - slack || moment > s_max * work + slack
        }
        // s ≤ 0 on Γ_C: βZ opens every contact for β ≥ 0
        (false, true, false) => moment > slack,
        // s ≥ 0: for β ≤ 0
        (false, false, true) => moment < -slack,
        // s ≡ 0: the contact cannot hold Z at all
        (false, false, false) => moment.abs() > slack,
        // s changes sign: no βZ opens every contact
        (false, true, true) => false,
    };
    if tips && !translation_free {
        return Err(Error::Input(format!(
            "the load tips the body: the supports leave a rotation free, which only the contact can hold, and the load turns the body away from the contact boundary (its work on that rotation, {moment:e}, opens every contact): there is no equilibrium; fix the rotation with a support (a displacement component on a second, non-parallel part) or move the load"
        )));
    }
    if tips {
        // where the resultant's line meets Γ_C, as a share of its extent from one end
        let place = if s_max > s_min {
            format!(
                " (its line meets Γ_C at {:.2} of its extent, outside 0…1)",
                (moment / work - s_min) / (s_max - s_min)
            )
        } else {
            String::new()
        };
        return Err(Error::Input(format!(
            "the load tips the body: the supports leave a rotation free, which only the contact can hold, but the load's resultant passes outside the contact boundary{place}: there is no equilibrium; fix the rotation with a support (a displacement component on a second, non-parallel part) or move the load"
        )));
    }
    Ok(())
}

/// The free-DOF vector of a unit translation along the contact direction: towards the
/// foundation.
fn towards_foundation(problem: &Discretization<TriangleMesh>, n: [f64; 2]) -> Vec<f64> {
    let fields = problem.dofs.fields();
    let mut full = vec![0.0; problem.dofs.dof_count()];
    for (axis, &field) in fields.iter().take(2).enumerate() {
        if let Some(range) = problem.dofs.range(field) {
            full[range].fill(n[axis]);
        }
    }
    // in the primed DOFs of the supports' rotated groups (oblique rollers)
    problem.basis.to_primed(&mut full);
    problem.reduction.free().iter().map(|&d| full[d]).collect()
}

/// The contact quantities of a solved problem (`direction` the unit `n_c`).
///
/// # Errors
/// The boundary inverse constants' errors.
pub(crate) fn report<M: Model>(
    input: &SignoriniInput,
    direction: [f64; 2],
    solved: &ProblemSolved<M, TriangleMesh>,
) -> Result<SignoriniSolution> {
    let solution = &solved.solution;
    let problem = &solution.discretization;
    let mesh = &problem.mesh;
    let boundary = problem.boundary().expect("a boundary multiplier");
    let lcp = &problem.lcp;
    let pressure = solution.multiplier_values().to_vec();
    let mut force = [0.0; 2];
    // ∫_E λ_h ds = |E| (λ_a + λ_b)/2 on each edge (P1), λ_E |E| (P0)
    for (&p, w) in pressure.iter().zip(boundary.integrals()) {
        force[0] -= p * w * direction[0];
        force[1] -= p * w * direction[1];
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
        let n = edge.outward_normal();
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
    let along = contact_tangent(direction);
    let (mut x_min, mut x_max) = (f64::INFINITY, f64::NEG_INFINITY);
    for (e, &[a, b]) in boundary.edges.iter().zip(&boundary.edge_dofs) {
        // the edges where λ_h is not identically 0 (for P1: either end positive)
        if pressure[a].max(pressure[b]) > 1e-10 * largest {
            for end in e.ends {
                let s = along[0] * end[0] + along[1] * end[1];
                x_min = x_min.min(s);
                x_max = x_max.max(s);
            }
        }
    }
    let half_width = match (x_max >= x_min, input.contact_centre) {
        (false, _) => 0.0,
        (true, None) => 0.5 * (x_max - x_min),
        (true, Some(c)) => (x_max - c).abs().max((x_min - c).abs()),
    };
    let alpha = solved.report.alpha.unwrap_or(0.0);
    let coefficients =
        fem_runtime::Coefficients::of_values::<M>(&solved.params, &[input.pressure, input.gap])?;
    let constants =
        mesh.boundary_inverse_constants::<M>(&coefficients, boundary.part, input.contact)?;
    Ok(SignoriniSolution {
        alpha,
        inverse_constants: constants,
        displacement: solution.values[..problem.dofs.dof_count()].to_vec(),
        pressure,
        contact_edges: boundary.edges.clone(),
        multiplier: boundary.space,
        contact_vertices: boundary.vertices.clone(),
        edge_dofs: boundary.edge_dofs.clone(),
        total_contact_force: force,
        applied_load: load,
        discretized_load: towards_foundation(problem, direction)
            .iter()
            .zip(&lcp.f)
            .map(|(t, f)| t * f)
            .sum(),
        contact_half_width: half_width,
        max_contact_pressure: largest,
        complementarity_residual: solved.report.complementarity_residual,
        kkt_residual: solution.kkt_residual,
        dofs: lcp.n() + lcp.m(),
        iterations: solution.iterations,
        seconds: solution.solve_seconds,
    })
}

/// The Hertz comparison of a continuous P1 pressure: exact integrals over the edges'
/// x-intervals (the contact edges of the quarter disc are ordered along x).
fn hertz_p1(hertz: Hertz, h: f64, solution: SignoriniSolution) -> HertzResult {
    let (intervals, values): (Vec<[f64; 2]>, Vec<[f64; 2]>) = solution
        .contact_edges
        .iter()
        .zip(solution.edge_pressures())
        .map(|(e, [p0, p1])| {
            let (x0, x1) = (e.ends[0][0], e.ends[1][0]);
            if x0 <= x1 {
                ([x0, x1], [p0, p1])
            } else {
                ([x1, x0], [p1, p0])
            }
        })
        .unzip();
    let nodes: Vec<f64> = solution.pressure_profile().iter().map(|p| p.0).collect();
    let oscillation = checkerboard(&solution, &hertz);
    HertzResult {
        hertz,
        contact_h: h,
        oscillation,
        pressure_l2_error: hertz.relative_l2_error_p1(&intervals, &values),
        best_fit_l2_error: hertz.best_p1_relative_l2_error(&nodes),
        solution,
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

/// Hertz line contact in plane strain (docs/contact.md): the reference, with its exact
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
    /// `‖λ_h − p‖ / ‖p‖` on Γ_C (P0: 16-point Gauss–Legendre per edge; P1: exact
    /// integrals over the edges' x-intervals,
    /// [`crate::hertz::HertzLineContact::relative_l2_error_p1`]).
    pub pressure_l2_error: f64,
    /// `‖Πp − p‖ / ‖p‖`: the error of the best fit in the multiplier's space on the same
    /// edges (P0: the edge means; P1: the continuous L² projection on the vertices' x,
    /// [`crate::hertz::HertzLineContact::best_p1_fit`]).
    pub best_fit_l2_error: f64,
    /// The checkerboard measure: `max |λ_{k−1} − 2λ_k + λ_{k+1}| / p_max` over
    /// consecutive multiplier DOFs (edges for P0, vertices for P1, ordered by x) inside
    /// `x < 0.8 b`, where p is smooth
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
    solve_hertz_with(hertz, b_over_h, element, Multiplier::P0, alpha)
}

/// [`solve_hertz`] with the multiplier's space chosen (P0 or continuous P1 on Γ_C).
///
/// # Errors
/// Those of [`solve_hertz`].
pub fn solve_hertz_with(
    hertz: Hertz,
    b_over_h: f64,
    element: Displacement,
    multiplier: Multiplier,
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
    solve_hertz_on_with(hertz, &mesh, h, element, multiplier, alpha)
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
    solve_hertz_on_with(hertz, mesh, contact_h, element, Multiplier::P0, alpha)
}

/// [`solve_hertz_on`] with the multiplier's space chosen (P0 or continuous P1 on Γ_C).
///
/// # Errors
/// Those of [`solve_signorini`].
pub fn solve_hertz_on_with(
    hertz: Hertz,
    mesh: &TriangleMesh,
    contact_h: f64,
    element: Displacement,
    multiplier: Multiplier,
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
        rollers: &[],
        alpha,
        contact_centre: Some(0.0),
    };
    let solution = solve_signorini_with(mesh, &input, multiplier)?;
    Ok(compare_with_hertz(hertz, h, solution))
}

/// The checkerboard measure of a pressure against Hertz's (see
/// [`HertzResult::oscillation`]): `max |λ_{k−1} − 2λ_k + λ_{k+1}| / p_max` over
/// consecutive multiplier DOFs along x ([`SignoriniSolution::pressure_profile`]: edge
/// midpoints for P0, vertices for P1) inside `x < 0.8 b`; 0 where fewer than three lie
/// there.
pub fn checkerboard(solution: &SignoriniSolution, hertz: &Hertz) -> f64 {
    let inside = 0.8 * hertz.half_width();
    solution
        .pressure_profile()
        .windows(3)
        .filter(|w| w[2].0 < inside)
        .map(|w| (w[0].1 - 2.0 * w[1].1 + w[2].1).abs())
        .fold(0.0f64, f64::max)
        / hertz.max_pressure()
}

/// The share of the exact peak pressure above which [`checkerboard_against`] measures:
/// Hertz's pressure is above 0.6 p_max exactly inside 0.8 b, where [`checkerboard`]
/// measures.
pub const SMOOTH_PRESSURE_SHARE: f64 = 0.6;

/// The checkerboard measure of a P0 pressure against any exact pressure `exact`:
/// `max |λ_{k−1} − 2λ_k + λ_{k+1}| / max p` (p sampled at the edges' ends and
/// midpoints) over consecutive contact edges, ordered along
/// the contact plane (`direction` its normal `n_c`), whose midpoints all lie where
/// `p ≥ 0.6 max p` (inside the contact zone, away from its square-root edges); for
/// Hertz's pressure the same as [`checkerboard`]. `None` where fewer than three edges
/// lie there, or the exact pressure vanishes on Γ_C.
pub fn checkerboard_against(
    solution: &SignoriniSolution,
    direction: [f64; 2],
    exact: &dyn Fn(&[f64]) -> f64,
) -> Option<f64> {
    let along = contact_tangent(direction);
    let mut profile: Vec<(f64, f64, f64)> = solution
        .contact_edges
        .iter()
        .zip(&solution.pressure)
        .map(|(e, &p)| {
            let m = e.midpoint();
            (along[0] * m[0] + along[1] * m[1], p, exact(&m))
        })
        .collect();
    profile.sort_by(|a, b| a.0.total_cmp(&b.0));
    let peak = solution
        .contact_edges
        .iter()
        .flat_map(|e| [e.ends[0], e.midpoint(), e.ends[1]])
        .map(|x| exact(&x))
        .fold(0.0f64, f64::max);
    if !(peak > 0.0 && peak.is_finite()) {
        return None;
    }
    let smooth = SMOOTH_PRESSURE_SHARE * peak;
    let windows: Vec<f64> = profile
        .windows(3)
        .filter(|w| w.iter().all(|p| p.2 >= smooth))
        .map(|w| (w[0].1 - 2.0 * w[1].1 + w[2].1).abs())
        .collect();
    (!windows.is_empty()).then(|| windows.iter().fold(0.0f64, |m, &d| m.max(d)) / peak)
}

/// The comparison of a solution on [`hertz_mesh`] with Hertz's pressure: the relative
/// L² error, the best fit's in the multiplier's space and the checkerboard measure
/// (see [`HertzResult`]; P0: 16-point Gauss–Legendre per edge, P1: exact integrals).
pub fn compare_with_hertz(hertz: Hertz, h: f64, solution: SignoriniSolution) -> HertzResult {
    if solution.multiplier == Multiplier::P1 {
        return hertz_p1(hertz, h, solution);
    }
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
    let oscillation = checkerboard(&solution, &hertz);
    HertzResult {
        hertz,
        contact_h: h,
        oscillation,
        solution,
        pressure_l2_error: (error / norm).sqrt(),
        best_fit_l2_error: (best / norm).sqrt(),
    }
}

// ---------------------------------------------------------------------------------------
// Nested iteration and the accuracy-driven stop (issue 14, "Speed"; docs/contact.md §7).
// ---------------------------------------------------------------------------------------

use std::collections::HashMap;
use std::time::Instant;

/// The projection of a new boundary vertex onto the curve its boundary part
/// approximates, `snap(marker, x)` (as [`TriangleMesh::refine_to_size`] takes it); the
/// identity for polygonal bodies.
pub type Snap<'a> = &'a (dyn Fn(u32, [f64; 2]) -> [f64; 2] + Sync);

/// The identity [`Snap`]: every boundary part is straight.
pub fn straight_boundary(_marker: u32, x: [f64; 2]) -> [f64; 2] {
    x
}

/// The projection onto the arc of [`hertz_mesh`] (marker [`HERTZ_ARC`], the circle of
/// radius `radius` centred at `(0, radius)`), the identity on the other parts.
pub fn hertz_snap(radius: f64) -> impl Fn(u32, [f64; 2]) -> [f64; 2] + Sync {
    move |marker, p| {
        if marker != HERTZ_ARC {
            return p;
        }
        let (dx, dy) = (p[0], p[1] - radius);
        let r = dx.hypot(dy);
        [radius * dx / r, radius + radius * dy / r]
    }
}

/// How Newton was started on one level of a nested solve.
#[derive(Clone, Debug, PartialEq)]
pub enum LevelStart {
    /// Pressed into the foundation, every constraint active (the coarsest level, and
    /// [`solve_signorini`]'s start).
    Pressed,
    /// The previous level's displacement prolongated (nodal interpolation on the nested
    /// meshes). The multiplier needs no start: semismooth Newton eliminates it from the
    /// displacement.
    Prolongated,
    /// Newton failed from the prolongated start (the message) and the level was solved
    /// again from the pressed start.
    FellBack(String),
}

/// One level of a nested Signorini solve.
#[derive(Clone, Debug)]
pub struct NestedLevelReport {
    /// Cells of the level's mesh.
    pub cells: usize,
    /// Unknowns of the level's LCP (free displacement DOFs + contact edges).
    pub dofs: usize,
    /// Edges of Γ_C.
    pub contact_edges: usize,
    /// The start of Newton.
    pub start: LevelStart,
    /// Newton iterations of the solve that succeeded.
    pub iterations: usize,
    /// Wall time of that Newton solve, seconds.
    pub newton_seconds: f64,
    /// Wall time of the whole level (assembly of the LCP, the inverse constants,
    /// the prolongation, Newton and the report), seconds.
    pub seconds: f64,
    /// `‖λ_{l−1} − λ_l‖ / ‖λ_l‖` in `L²(Γ_C)` on this level's edges, the previous level's
    /// pressure taken on each edge from the coarse edge it was split from; `None` on the
    /// coarsest level.
    pub pressure_change: Option<f64>,
    /// The estimate of this level's relative `L²(Γ_C)` pressure error: the larger of
    /// this level's and the previous level's `pressure_change`, over `2^r − 1` with `r`
    /// = [`PRESSURE_RATE`] (docs/contact.md §7); `None` on the two coarsest levels.
    pub estimated_error: Option<f64>,
}

/// A nested Signorini solve: the finest level's solution and every level's report.
#[derive(Clone, Debug)]
pub struct NestedSignoriniSolution {
    /// The finest mesh.
    pub mesh: TriangleMesh,
    /// The solution on it.
    pub solution: SignoriniSolution,
    /// The levels, coarsest first.
    pub levels: Vec<NestedLevelReport>,
    /// Wall time of the whole nested solve (meshes, assembly, solves), seconds.
    pub seconds: f64,
}

/// The convergence rate `r` in `h` assumed by the error estimate of
/// [`solve_signorini_to_accuracy`]: the multiplier is P0 and the pressure has a
/// square-root edge at the end of the contact zone, which caps the `L²(Γ_C)` rate at
/// O(h) (issue 14; docs/contact.md §7 for the estimate).
pub const PRESSURE_RATE: f64 = 1.0;

/// Limits of [`solve_signorini_to_accuracy`].
#[derive(Clone, Copy, Debug)]
pub struct AccuracyLimits {
    /// The most uniform refinements of the coarse mesh.
    pub max_refinements: usize,
    /// The most LCP unknowns of a level: a level that would exceed it (estimated as 4×
    /// the previous one's) is not built.
    pub max_dofs: usize,
}

impl Default for AccuracyLimits {
    fn default() -> Self {
        Self {
            max_refinements: 8,
            max_dofs: 2_000_000,
        }
    }
}

/// Solves a Signorini problem on `coarse` and on `refinements` uniform refinements of
/// it ([`TriangleMesh::refine_uniformly_onto`], new boundary vertices moved by `snap`),
/// starting Newton on each level from the previous level's displacement prolongated
/// (`fem_runtime::multigrid::prolongation`); the coarsest level starts pressed into the
/// foundation as [`solve_signorini`] does. A level whose prolongated start fails is
/// solved again from the pressed start ([`LevelStart::FellBack`]).
///
/// With `input.alpha = None` every level computes its `C_I,E` and keeps the previous
/// level's α while `α max_E C_I,E` stays in `[0.45, 0.5]` (otherwise it takes its own
/// automatic `1/(2 max C_I,E)`): the finest level's α (reported in the solution) may
/// then differ by a fraction of a percent from what [`solve_signorini`] would pick on
/// the finest mesh alone; given `Some(α)` gives the same discrete problem.
///
/// # Errors
/// Those of [`solve_signorini`] on any level, with the level named; the mesh's when
/// snapping turns a cell inside out.
pub fn solve_signorini_nested(
    coarse: &TriangleMesh,
    refinements: usize,
    snap: Snap,
    input: &SignoriniInput,
) -> Result<NestedSignoriniSolution> {
    nested(coarse, snap, input, |_, level| Ok(level < refinements))
}

/// Solves a Signorini problem on `coarse` and its uniform refinements (as
/// [`solve_signorini_nested`]) until the estimated relative `L²(Γ_C)` error of the
/// pressure is at most `tolerance`.
///
/// The estimate on level `l ≥ 2` is `max(δ_l, δ_{l−1}) / (2^r − 1)` with
/// `δ_l = ‖λ_{l−1} − λ_l‖ / ‖λ_l‖` and `r` = [`PRESSURE_RATE`] (Richardson: if
/// `‖λ − λ_h‖ ≈ C h^r`, then `‖λ − λ_{h/2}‖ ≈ ‖λ_h − λ_{h/2}‖ / (2^r − 1)`). Before the
/// asymptotic range the differences are irregular (on Hertz, one of them was 3.0× below
/// the true error of its level), hence the larger of the last two; docs/contact.md §7
/// has the measurements. At least two refinements are made.
///
/// # Errors
/// [`Error::Input`] for a tolerance not in (0, 1), and, naming the tolerance and the
/// last estimate, when `limits` stop the refinement before the estimate reaches it;
/// those of [`solve_signorini_nested`].
pub fn solve_signorini_to_accuracy(
    coarse: &TriangleMesh,
    snap: Snap,
    input: &SignoriniInput,
    tolerance: f64,
    limits: AccuracyLimits,
) -> Result<NestedSignoriniSolution> {
    if !(tolerance > 0.0 && tolerance < 1.0) {
        return Err(Error::Input(format!(
            "the pressure tolerance {tolerance} must lie in (0, 1) (a relative L² error)"
        )));
    }
    let reached = |levels: &[NestedLevelReport]| {
        levels
            .last()
            .and_then(|l| l.estimated_error)
            .is_some_and(|e| e <= tolerance)
    };
    let mut limit_hit = None;
    let solved = nested(coarse, snap, input, |levels, refinements| {
        if reached(levels) {
            return Ok(false);
        }
        let dofs = levels.last().map_or(0, |l| l.dofs);
        if refinements >= limits.max_refinements || 4 * dofs > limits.max_dofs {
            limit_hit = Some(format!(
                "{refinements} refinements (at most {}) and {dofs} unknowns (the next level would have about {}, at most {} allowed)",
                limits.max_refinements,
                4 * dofs,
                limits.max_dofs
            ));
            return Ok(false);
        }
        Ok(true)
    })?;
    if reached(&solved.levels) {
        return Ok(solved);
    }
    let estimate = solved
        .levels
        .last()
        .and_then(|l| l.estimated_error)
        .map_or("none (it needs two refinements)".to_string(), |e| {
            format!("{e:.3e}")
        });
    Err(Error::Input(format!(
        "the pressure tolerance {tolerance:e} (relative L² error on Γ_C) was not reached: stopped after {}; the last estimate is {estimate}",
        limit_hit.unwrap_or_else(|| "the last level".into())
    )))
}

/// The nested loop: solves the coarse level, then refines while `more(levels so far,
/// refinements so far)` says so.
fn nested(
    coarse: &TriangleMesh,
    snap: Snap,
    input: &SignoriniInput,
    mut more: impl FnMut(&[NestedLevelReport], usize) -> Result<bool>,
) -> Result<NestedSignoriniSolution> {
    match input.element {
        Displacement::P1 => nested_with::<signorini_p1::Model>(coarse, snap, input, &mut more),
        Displacement::P2 => nested_with::<signorini_p2::Model>(coarse, snap, input, &mut more),
    }
}

/// The runtime's solve that builds its levels as it goes ([`Problem::solve_refining`]):
/// each next level the uniform refinement of the last, made while `more` says so.
fn nested_with<M: Model>(
    coarse: &TriangleMesh,
    snap: Snap,
    input: &SignoriniInput,
    more: &mut dyn FnMut(&[NestedLevelReport], usize) -> Result<bool>,
) -> Result<NestedSignoriniSolution> {
    let clock = Instant::now();
    if let Some(a) = input.alpha {
        if !(a.is_finite() && a > 0.0) {
            return Err(Error::Input(format!(
                "the nested solve uses semismooth Newton: the stabilization parameter α = {a} must be > 0 (or automatic)"
            )));
        }
    }
    refuse_pressure_on_contact(coarse, input)?;
    let setup = Setup::new(input)?;
    let direction = setup.direction;
    let start = move |d: &Discretization<TriangleMesh>| pressed_start(d, direction);
    let problem = contact_problem::<M>(vec![coarse.clone()], input, &setup, &start);
    let mut levels: Vec<NestedLevelReport> = Vec::new();
    let mut previous: Option<(SignoriniSolution, Vec<usize>)> = None;
    let mut level_clock = Instant::now();
    let mut last = None;
    let solved = problem
        .solve_refining(|solved| {
            let solution = report::<M>(input, direction, solved)?;
            let start = match (&solved.fell_back, levels.is_empty()) {
                (_, true) => LevelStart::Pressed,
                (Some(e), false) => LevelStart::FellBack(e.clone()),
                (None, false) => LevelStart::Prolongated,
            };
            let mut level = NestedLevelReport {
                cells: solved.mesh().cell_count(),
                dofs: solution.dofs,
                contact_edges: solution.contact_edges.len(),
                start,
                iterations: solution.iterations,
                newton_seconds: solution.seconds,
                seconds: level_clock.elapsed().as_secs_f64(),
                pressure_change: None,
                estimated_error: None,
            };
            if let Some((coarse, parents)) = &previous {
                let change = pressure_change(coarse, &solution, parents);
                level.pressure_change = Some(change);
                // two differences: one alone can be small by a coincidence (docs/contact.md §7)
                level.estimated_error = levels
                    .last()
                    .and_then(|l| l.pressure_change)
                    .map(|before| change.max(before) / (2f64.powf(PRESSURE_RATE) - 1.0));
            }
            levels.push(level);
            if !more(&levels, levels.len() - 1)? {
                last = Some(solution);
                return Ok(None);
            }
            let (fine, parents) = solved.mesh().refine_uniformly_onto(snap)?;
            refuse_pressure_on_contact(&fine, input)?;
            previous = Some((solution, parents));
            level_clock = Instant::now();
            Ok(Some(fine))
        })
        .map_err(|e| match e {
            Error::Input(m) => Error::Input(format!("nested level {}: {m}", levels.len())),
            other => other,
        })?;
    Ok(NestedSignoriniSolution {
        mesh: solved.mesh().clone(),
        solution: last.expect("the last level was reported"),
        levels,
        seconds: clock.elapsed().as_secs_f64(),
    })
}

/// `‖λ_c − λ_f‖ / ‖λ_f‖` in `L²(Γ_C)` over the fine contact edges, `λ_c` taken on each
/// fine edge from the coarse contact edge of its parent cell nearest to it.
fn pressure_change(coarse: &SignoriniSolution, fine: &SignoriniSolution, parents: &[usize]) -> f64 {
    let coarse_edges = &coarse.contact_edges;
    let mut by_cell: HashMap<usize, Vec<usize>> = HashMap::new();
    for (k, e) in coarse_edges.iter().enumerate() {
        by_cell.entry(e.cell).or_default().push(k);
    }
    let distance = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    let (mut difference, mut norm) = (0.0, 0.0);
    for (e, &lambda) in fine.contact_edges.iter().zip(&fine.pressure) {
        let m = e.midpoint();
        let nearest = |candidates: &mut dyn Iterator<Item = usize>| {
            candidates.min_by(|&a, &b| {
                distance(coarse_edges[a].midpoint(), m)
                    .total_cmp(&distance(coarse_edges[b].midpoint(), m))
            })
        };
        // a fine edge on the boundary lies in a parent's boundary edge of the same part
        let k = by_cell
            .get(&parents[e.cell])
            .and_then(|ks| nearest(&mut ks.iter().copied()))
            .or_else(|| nearest(&mut (0..coarse_edges.len())));
        let previous = k.map_or(0.0, |k| coarse.pressure[k]);
        difference += e.length() * (previous - lambda) * (previous - lambda);
        norm += e.length() * lambda * lambda;
    }
    if norm > 0.0 {
        (difference / norm).sqrt()
    } else {
        difference.sqrt()
    }
}

/// `‖λ_h − p‖ / ‖p‖` on Γ_C of a solution on a quarter disc of [`hertz_mesh`]'s markers
/// against Hertz's pressure `p` (16-point Gauss–Legendre per edge), as
/// [`HertzResult::pressure_l2_error`].
pub fn hertz_pressure_error(hertz: &Hertz, solution: &SignoriniSolution) -> f64 {
    let gauss = fem_runtime::gauss_legendre(16);
    let (mut error, mut norm) = (0.0, 0.0);
    for (e, &lambda) in solution.contact_edges.iter().zip(&solution.pressure) {
        let [a, b] = e.ends;
        for (&s, &w) in gauss.points.iter().zip(&gauss.weights) {
            let p = hertz.pressure(a[0] + s * (b[0] - a[0]));
            error += w * e.length() * (lambda - p) * (lambda - p);
            norm += w * e.length() * p * p;
        }
    }
    (error / norm).sqrt()
}

/// The Hertz problem of [`solve_hertz_on`] as a [`SignoriniInput`] (its data live in
/// `data`: `(q, …)`), for the nested solves.
pub fn hertz_input<'a>(
    hertz: &Hertz,
    element: Displacement,
    alpha: Option<f64>,
    data: &'a HertzData,
) -> SignoriniInput<'a> {
    SignoriniInput {
        young: hertz.young,
        poisson: hertz.poisson,
        plane: Plane::Strain,
        element,
        contact: &[HERTZ_ARC],
        load: &[HERTZ_TOP],
        pressure: &*data.pressure,
        gap: &*data.gap,
        contact_direction: [0.0, -1.0],
        fixed_x: &[HERTZ_AXIS],
        fixed_y: &[],
        rollers: &[],
        alpha,
        contact_centre: Some(0.0),
    }
}

/// The data functions of the Hertz problem: the uniform pressure `P/(2R)` on the top,
/// the vertical gap `y` to the plane.
pub struct HertzData {
    /// `q(x) = P/(2R)`.
    pub pressure: Box<DataFn>,
    /// `g(x) = y`.
    pub gap: Box<DataFn>,
}

impl HertzData {
    /// The data of `hertz`.
    pub fn new(hertz: &Hertz) -> Self {
        let q = hertz.load / (2.0 * hertz.radius);
        Self {
            pressure: Box::new(move |_: &[f64]| q),
            gap: Box::new(|x: &[f64]| x[1]),
        }
    }
}
