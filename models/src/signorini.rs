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
//! on the edge); it lives on the edges of `Γ_C` only: the runtime gives it one DOF per
//! contact edge. Declared P1 (the `_p1` models) it is continuous on `Γ_C`, one DOF per
//! vertex of its edges ([`fem_runtime::obstacle::boundary_multiplier::discretize`]).
//!
//! The models are solved, checked and reported by the contact family
//! ([`crate::families::contact`]) through the one solve of every family.

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
                constraint:    b, G;
                unit:          n_c;
                estimator: "
                    η_T²   = h_T²/(2μ_L) ‖div σ(u)‖²
                    η_E²   = h_E/(2μ_L) ‖[[σ(u)·n]]‖²
                    η_Γ_C² = h_E/(2μ_L) ‖σ(u)·n + λ (n_c_x, n_c_y)‖²
                    η_Γ_N² = h_E/(2μ_L) ‖σ(u)·n + q n‖²
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
/// vertex of the edges of Γ_C), chosen by the model's multiplier element.
pub use fem_runtime::obstacle::boundary_multiplier::BoundaryMultiplier as Multiplier;

use fem_runtime::{Error, Result};

/// Plane strain (`ε_zz = 0`, a long body) or plane stress (`σ_zz = 0`, a thin plate).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Plane {
    /// `λ_L = Eν/((1+ν)(1−2ν))`.
    Strain,
    /// `λ_L = Eν/(1−ν²)` (the plane-stress reduction `2λμ/(λ+2μ)` of the 3D value).
    Stress,
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
