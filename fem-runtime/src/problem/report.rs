//! What every solve reports, whatever the model: the discretization, the solver's work,
//! the answer's integrals, its certificate and the guards that say what it cannot be
//! trusted for. A family adds its own quantities beside these (the application's
//! report flattens both into one JSON object).

use serde::Serialize;

/// The report of one solve ([`super::Problem::solve`]).
#[derive(Clone, Debug, Default, Serialize)]
pub struct Report {
    /// The model solved (its module name).
    pub model: &'static str,
    /// Cells of the finest mesh.
    pub cells: usize,
    /// Unknowns after eliminating the fixed DOFs: primal and multiplier.
    pub dofs: usize,
    /// Multiplier unknowns (constraints).
    pub multiplier_dofs: usize,
    /// The stabilization parameter used; `null` for the nodal method (no multiplier).
    pub alpha: Option<f64>,
    /// `max C_I` of the stabilization on the finest mesh (per cell, or per edge of a
    /// boundary part): `S_T(v, v) ≤ C_I a_T(v, v)`; 0 where S has no primal part.
    pub inverse_constant: f64,
    /// The complementarity solver: `pdas` (semismooth Newton), `clarabel` (QP) or
    /// `nodal active set`.
    pub solver: &'static str,
    /// What solved the finest level's Newton steps: `direct` or `multigrid` (`none`
    /// where no step had a system to solve).
    pub linear_solver: &'static str,
    /// Iterations on the finest mesh.
    pub iterations: usize,
    /// `[cells, iterations]` of each level of the nested iteration, coarsest first.
    pub levels: Vec<[usize; 2]>,
    /// Numeric factorizations on the finest level.
    pub factorizations: usize,
    /// CG iterations of the finest level's multigrid-solved steps.
    pub krylov_iterations: usize,
    /// Wall time of the solve: assembly and every level (of an adaptive solve: every
    /// level's solve, estimate, marking and refinement).
    pub seconds: f64,
    /// The memory the solve was estimated to need before any work, in bytes.
    pub memory_estimate: f64,
    /// `½ a(u_h, u_h) − ℓ(u_h)` with the model's energy forms; `null` for a model that
    /// declares none.
    pub energy: Option<f64>,
    /// `∫ λ_h`: the total contact force (on a boundary part, along the contact direction).
    pub total_contact_force: f64,
    /// The contact set's area (multipliers on triangles): cells with an active or
    /// touching constraint, so that holes of zero λ_h on the obstacle count.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact_area: Option<f64>,
    /// The contact set's length (multipliers on intervals and on boundary parts).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact_length: Option<f64>,
    /// The deepest crossing `s(ψ − u_h)` of the obstacle at the sample points (the
    /// cell-wise constraint allows it inside cells); `null` without a pointwise obstacle.
    pub max_penetration: Option<f64>,
    /// The largest clearance `s(u_h − ψ)` of a cell where λ_h pushes: 0 for a real
    /// contact set.
    pub max_open_contact_gap: Option<f64>,
    /// `‖u − u_h‖_L²` of the constrained field against the exact solution, where known.
    pub error_l2: Option<f64>,
    /// `|u − u_h|_H¹`, where the exact gradient is known.
    pub error_h1: Option<f64>,
    /// The broken H² seminorm `(Σ_T |u − u_h|²_{H²(T)})^{1/2}`, where the exact Hessian
    /// is known (a scene file's `[exact] hessian`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error_h2: Option<f64>,
    /// `(Σ_T h_T² ‖λ − λ_h‖²_T)^{1/2}`, where the exact multiplier is known.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error_multiplier: Option<f64>,
    /// `max |u_h(v) − u(v)|` over the vertices (the finite-difference measure).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error_vertex_max: Option<f64>,
    /// The mean of `|u_h(v) − u(v)|` over the vertices.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error_vertex_mean: Option<f64>,
    /// The a-posteriori estimate `(η² + S²)^{1/2}` of the model's `estimator:` with the
    /// contact terms ([`crate::adaptivity::Estimate::total`]); absent for a model that
    /// declares no estimator.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub estimate: Option<f64>,
    /// The contact part `S` of the estimate (violation and complementarity defect).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub estimate_contact: Option<f64>,
    /// The estimate relative to `‖u_h‖_a`, the energy norm of the constrained field:
    /// what `--tol` bounds.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub estimate_relative: Option<f64>,
    /// The error in the estimator's norm, where an exact solution gives it: `|u − u_h|_H¹`
    /// for second-order models, the broken H² seminorm for fourth-order ones, in the
    /// units of the energy norm (times `‖u_h‖_a / |u_h|`: exact where the energy density
    /// is a constant times the seminorm's, as the plate's D; within the ν-dependent
    /// norm equivalence for the plate).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error_energy: Option<f64>,
    /// `error_energy / ‖u_h‖_a`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error_energy_relative: Option<f64>,
    /// `estimate / error_energy`: bounded above and below over a refinement when the
    /// estimator is reliable and efficient.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub efficiency_index: Option<f64>,
    /// The levels of an adaptive solve (`Problem::solve_adaptive`), first to last.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub adaptive_levels: Vec<crate::adaptivity::AdaptiveLevel>,
    /// The KKT residual of the result, computed from it (equilibrium backward error and
    /// complementarity), not the solver's word.
    pub kkt_residual: f64,
    /// The complementarity part of it: `max_k |min(λ_k/λ*, r_k)|`.
    pub complementarity_residual: f64,
    /// Estimated relative rounding noise of λ_h (0: none).
    pub multiplier_noise: f64,
    /// How far u_h may be off through the rounding of the rows in contact, relative to
    /// the size of the answer (the larger of `max|u_h|` and `max|ψ|`).
    pub primal_rounding: f64,
    /// The rounding experiment, where it ran: how far u_h (relative to its size) and
    /// `∫λ_h` move when the mesh is scaled in its last bits: the part of the answer
    /// that is rounding.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rounding: Option<f64>,
    /// Wall time of the rounding experiment's two extra solves.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rounding_seconds: Option<f64>,
    /// The shape of the finest mesh's triangles (triangle meshes).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mesh_quality: Option<MeshQualityReport>,
    /// What the numbers cannot be trusted for.
    pub warnings: Vec<String>,
}

/// The shape of a mesh's triangles and what it forces on the stabilization.
#[derive(Clone, Debug, Default, Serialize)]
pub struct MeshQualityReport {
    /// Smallest angle of any triangle, in degrees.
    pub min_angle_deg: f64,
    /// Largest angle of any triangle, in degrees.
    pub max_angle_deg: f64,
    /// Largest `h_T / (2√3 r_T)` (1 for the equilateral triangle).
    pub max_aspect_ratio: f64,
    /// `max_T C_I(T)` of the model's stabilization on the mesh.
    pub worst_inverse_constant: f64,
    /// The α = ½/C_I that constant forces (`None` where C_I = 0).
    pub forced_alpha: Option<f64>,
}

/// Largest rounding of u_h through the contact rows, relative to its size, accepted in
/// a result ([`Report::primal_rounding`]); above 1e-8 it is warned about.
pub const MAX_PRIMAL_ROUNDING: f64 = 1e-3;

/// [`Report::primal_rounding`] above which a warning says how far it reaches.
pub const PRIMAL_ROUNDING_WARNING: f64 = 1e-8;

/// Largest estimated relative rounding noise of λ_h accepted in a result: beyond it λ_h
/// has no correct digit (the estimate is a bound, loose by up to 10×: timoshenko-a at
/// q = 100 on 32768 elements showed 0.1 with ∫λ_h still right to 4 digits, and
/// bernoulli-flat at q = 100 1.8 at 20000 elements, where ∫λ_h was off by 6×).
pub const MAX_MULTIPLIER_NOISE: f64 = 1.0;

/// [`Report::multiplier_noise`] above which it is warned about.
pub const MULTIPLIER_NOISE_WARNING: f64 = 1e-6;

/// [`Report::rounding`] above which a solve is refused: u_h has no correct digit (a
/// thin Timoshenko beam on 4096 elements was 18 % off with a KKT residual of 5e-17).
pub const MAX_ROUNDING: f64 = 0.1;

/// [`Report::rounding`] above which a solve warns: u_h keeps fewer than four digits.
pub const ROUNDING_WARNING: f64 = 1e-4;

/// Largest open gap under a pushing λ_h, relative to the size of the answer, that
/// passes without a warning.
pub const OPEN_GAP_WARNING: f64 = 1e-2;

/// Largest penetration, relative to the larger of ψ's and u_h's ranges, that passes
/// without a warning.
pub const PENETRATION_WARNING: f64 = 1e-2;

/// Gaps and crossings below this multiple of the machine epsilon times the largest
/// `|u_h|` and `|ψ|` are rounding ([`value_rounding`]).
pub const VALUE_ROUNDING: f64 = 1e3;

/// The size an error in u_h is judged against: the largest `|u_h|` and `|ψ|` (both
/// scale with the data, so that scaling f, ψ and g together leaves every judgement the
/// same), or, where ψ is exactly 0 (a structure pressed flat onto ψ = 0 has u ≡ 0, and
/// any rounding would be infinitely large against it), the larger of `|u_h|` and 1e-6
/// of the mesh's diameter (a deflection is a length: a millionth of the domain is the
/// least that is judged).
pub fn answer_level(u_size: f64, psi_size: f64, diameter: f64) -> f64 {
    if psi_size > 0.0 {
        u_size.max(psi_size)
    } else {
        u_size.max(1e-6 * diameter)
    }
}

/// The rounding of the values of u_h and ψ that penetration and open-gap judgements
/// compare: [`VALUE_ROUNDING`] ε times the largest `|u_h|` and `|ψ|` (ψ = 10¹² + 10⁻³x
/// dipped one ulp of 10¹², "9.4 %" of its range). The solve's own rounding through the
/// rows in contact is added to it where it is judged ([`Report::primal_rounding`]).
pub fn value_rounding(u_size: f64, psi_size: f64) -> f64 {
    VALUE_ROUNDING * f64::EPSILON * u_size.max(psi_size)
}

/// The rounding of a solve under the load `f` (its largest `|f|`) over a domain of
/// extent `d`, for an operator of order `p` ([`crate::Model::ORDER`]): 10 ε times
/// `|f| d^p / 384`, a deflection below what the load causes without obstacle (a clamped
/// beam of length d deflects by `|f| d⁴/384`, a membrane by about `|f| d²/8`). Where the
/// structure is pressed flat onto the obstacle (u_h = ψ = 0), this is what its values
/// are known to: a membrane under f = −3 showed crossings of 5e-17 there.
pub fn load_rounding(load_size: f64, extent: f64, order: u8) -> f64 {
    if order == 0 {
        return 0.0;
    }
    10.0 * f64::EPSILON * load_size * extent.powi(order as i32) / 384.0
}
