//! The stabilization policy: the element constant `C_I` of a model's stabilization term
//! against its bilinear form, computed from the model's own kernels, and the choice of α
//! from it.
//!
//! The stabilized methods (docs/mathematics.md §1) replace `a(u, v) − b(v, λ) − b(u, μ)` by
//! `B_h = a − b − bᵀ − α S_h`. Their stability rests on the inverse inequality
//! `S_T(v, v) ≤ C_I a_T(v, v)` for the primal part of `S_h` (μ = 0) on every cell T:
//! for the membrane `S_T(v, v) = h_T² ‖Δv‖²_T` and `a_T(v, v) = ‖∇v‖²_T`, and the method
//! is stable for `0 < α < 1/C_I` (Barbosa–Hughes; the proof in docs/mathematics.md). `C_I` depends
//! on the element and the cell's shape, not its size: 48 on the equilateral triangle,
//! 96 on the right isosceles one and 240 on the 120° isosceles one for P2, 0 for P1
//! (Δ vanishes on each cell), as for the beam pairs whose `θ'''` or `w''''` vanishes.

use crate::mesh::Mesh;
use crate::model::{FormId, IntoFormIndex, StabilizationRole};
use crate::{DataFn, Error, Model, Result};
use nalgebra::{DMatrix, SymmetricEigen};

/// How α is chosen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Alpha {
    /// This value.
    Fixed(f64),
    /// `fraction / C_I` with `C_I` the largest element constant of the mesh: inside the
    /// stability range `0 < α < 1/C_I` for `0 < fraction < 1`. Where `C_I = 0` every
    /// α > 0 is stable and the caller's fallback is used.
    FromInverseConstant(f64),
}

impl Default for Alpha {
    /// `½ / C_I`: the middle of the stability range.
    fn default() -> Self {
        Alpha::FromInverseConstant(0.5)
    }
}

impl Alpha {
    /// The value of α for a mesh whose largest element constant is `c_i`, with
    /// `when_zero` where `c_i = 0` and α is derived from it.
    ///
    /// # Errors
    /// A fixed α or a fraction that is negative or not finite, a fraction of 0
    /// (the plain method is `Alpha::Fixed(0.0)`), or a non-finite `c_i`.
    pub fn value(self, c_i: f64, when_zero: f64) -> Result<f64> {
        if !(c_i >= 0.0 && c_i.is_finite()) {
            return Err(Error::Input(format!(
                "the element constant C_I = {c_i} must be finite and ≥ 0"
            )));
        }
        let alpha = match self {
            Alpha::Fixed(a) => a,
            Alpha::FromInverseConstant(fraction) => {
                if !(fraction > 0.0 && fraction.is_finite()) {
                    return Err(Error::Input(format!(
                        "α = fraction/C_I needs a finite fraction > 0, got {fraction}"
                    )));
                }
                if c_i > 0.0 {
                    fraction / c_i
                } else {
                    when_zero
                }
            }
        };
        if !(alpha >= 0.0 && alpha.is_finite()) {
            return Err(Error::Input(format!(
                "α = {alpha} must be finite and ≥ 0 (0 is the plain mixed method)"
            )));
        }
        Ok(alpha)
    }
}

/// The primal-field (non-multiplier) part of the element matrix of `form` on one cell:
/// the sum of its blocks between primal fields, on the primal fields' local DOFs in field
/// order. `None` when the form has no such block.
fn primal_matrix<M: Model>(
    f: usize,
    vertices: &[f64],
    params: &[f64],
) -> Result<Option<DMatrix<f64>>> {
    let primal: Vec<usize> = (0..M::FIELDS.len())
        .filter(|&k| !M::FIELDS[k].nonnegative)
        .collect();
    let counts: Vec<usize> = M::FIELDS
        .iter()
        .map(|field| field.element.local_dof_count(M::CELL))
        .collect();
    let mut offsets = vec![0; M::FIELDS.len()];
    let mut n = 0;
    for &k in &primal {
        offsets[k] = n;
        n += counts[k];
    }
    // the data do not enter the bilinear forms' primal blocks of these models; zero data
    // keep the kernels callable
    let zero = |_: &[f64]| 0.0;
    let data: Vec<&DataFn> = vec![&zero; M::DATA.len()];
    let mut matrix = DMatrix::zeros(n, n);
    let mut any = false;
    for (b, block) in M::FORMS[f].blocks.iter().enumerate() {
        let Some(trial) = block.trial_field else {
            continue;
        };
        let test = block.test_field;
        if M::FIELDS[test].nonnegative || M::FIELDS[trial].nonnegative {
            continue;
        }
        let (rows, cols) = (counts[test], counts[trial]);
        let mut out = vec![0.0; rows * cols];
        M::element_matrix(f, b, vertices, params, &data, &mut out);
        for i in 0..rows {
            for j in 0..cols {
                matrix[(offsets[test] + i, offsets[trial] + j)] += out[i * cols + j];
            }
        }
        any = true;
    }
    Ok(any.then_some(matrix))
}

/// The model's stabilization role ([`Model::STABILIZATION`]).
///
/// # Errors
/// [`Error::Input`] for a model that declares none.
pub fn role<M: Model>() -> Result<StabilizationRole> {
    M::STABILIZATION.ok_or_else(|| {
        Error::Input(format!(
            "model `{}` declares no stabilization (`stabilization: α S against a;`), so no C_I or α can be derived for it",
            M::NAME
        ))
    })
}

/// `C_I(T) = max S_T(v, v) / a_T(v, v)` over the primal functions v of one cell (μ = 0),
/// for the model's stabilization `S` against the form `a` it declares
/// ([`Model::STABILIZATION`]), with the model's parameters `params` in declaration
/// order (e.g. the beam's t and s). `vertices` are the cell's coordinates as the kernels
/// take them (`x₀ x₁` on intervals, `x₀ y₀ x₁ y₁ x₂ y₂` on triangles). 0 when `S` has no
/// primal block.
///
/// The maximum is taken on the complement of the kernel of `a_T` (constants for the
/// membrane, rigid motions for beams), found from the eigenvalues of `a_T`.
///
/// # Errors
/// A model without a stabilization role; `S_T` not vanishing on the kernel of `a_T`
/// (then no `C_I` exists: the stabilization is not bounded by `a`).
pub fn element_inverse_constant<M: Model>(vertices: &[f64], params: &[f64]) -> Result<f64> {
    let role = role::<M>()?;
    element_inverse_constant_between::<M>(vertices, params, role.form, role.against)
}

/// [`element_inverse_constant`] of the bilinear forms `stabilization` and `bilinear`
/// (indices in `FORMS`) in place of the model's declared ones.
///
/// # Errors
/// As [`element_inverse_constant`].
pub fn element_inverse_constant_between<M: Model>(
    vertices: &[f64],
    params: &[f64],
    stabilization: usize,
    bilinear: usize,
) -> Result<f64> {
    let (Some(s), Some(a)) = (
        primal_matrix::<M>(stabilization, vertices, params)?,
        primal_matrix::<M>(bilinear, vertices, params)?,
    ) else {
        return Ok(0.0);
    };
    let symmetric = |m: DMatrix<f64>| (&m + m.transpose()) * 0.5;
    let (s, a) = (symmetric(s), symmetric(a));
    // C_I is a generalized eigenvalue of (S_T, a_T), unchanged by a congruence with a
    // diagonal D. Scaled to a unit diagonal, a_T of elements with derivative DOFs
    // (Argyris: values, h-scaled gradients, h²-scaled Hessians) no longer spreads its
    // eigenvalues over powers of h, so that the kernel cut below separates the kernel of
    // a_T from small cells' genuine small eigenvalues (at h = 1/32 it did not).
    let scale: Vec<f64> = (0..a.nrows())
        .map(|i| {
            let d = a[(i, i)];
            if d > 0.0 && d.is_finite() {
                1.0 / d.sqrt()
            } else {
                1.0
            }
        })
        .collect();
    let congruent = |m: &DMatrix<f64>| {
        DMatrix::from_fn(m.nrows(), m.ncols(), |i, j| scale[i] * m[(i, j)] * scale[j])
    };
    let (s, a) = (congruent(&s), congruent(&a));
    let eigen = SymmetricEigen::new(a);
    let largest = eigen.eigenvalues.iter().cloned().fold(0.0, f64::max);
    if !(largest > 0.0 && largest.is_finite()) {
        return Err(Error::Input(format!(
            "the element matrix of `{bilinear}` of {} is not positive semidefinite with a positive part on this cell",
            M::NAME
        )));
    }
    let s_scale = s.norm().max(f64::MIN_POSITIVE);
    let tolerance = 1e-10 * largest;
    let mut range = Vec::new();
    for (k, &value) in eigen.eigenvalues.iter().enumerate() {
        let v = eigen.eigenvectors.column(k);
        if value > tolerance {
            range.push(v / value.sqrt());
        } else {
            // a kernel function of a: S must vanish on it, or no C_I bounds S by a
            let sv = (&s * v).norm();
            if sv > 1e-8 * s_scale {
                return Err(Error::Input(format!(
                    "`{}` of {} does not vanish on the kernel of `{}` (a function with a_T(v, v) = 0 has S_T(v, v) ≠ 0): no inverse constant bounds it",
                    M::FORMS[stabilization].name,
                    M::NAME,
                    M::FORMS[bilinear].name
                )));
            }
        }
    }
    if range.is_empty() {
        return Ok(0.0);
    }
    let z = DMatrix::from_columns(&range);
    let reduced = symmetric(z.transpose() * &s * &z);
    Ok(SymmetricEigen::new(reduced)
        .eigenvalues
        .iter()
        .cloned()
        .fold(0.0, f64::max))
}

/// `max_T C_I(T)` over the cells of `mesh` (see [`element_inverse_constant`]) for the
/// model's declared stabilization. Cells that are translates of one another at the same
/// size are computed once (the first 64 distinct shapes are remembered: structured
/// meshes have one or two).
///
/// # Errors
/// Those of [`element_inverse_constant`].
pub fn inverse_constant<M: Model, G: Mesh>(mesh: &G, params: &[f64]) -> Result<f64> {
    let role = role::<M>()?;
    inverse_constant_between::<M, G>(
        mesh,
        params,
        FormId::new(role.form),
        FormId::new(role.against),
    )
}

/// [`inverse_constant`] of two bilinear forms given by handle (`NAME::forms::S`) in
/// place of the model's declared ones.
///
/// # Errors
/// [`Error::Input`] for a form that is not bilinear; those of
/// [`element_inverse_constant`].
pub fn inverse_constant_between<M: Model, G: Mesh>(
    mesh: &G,
    params: &[f64],
    stabilization: impl IntoFormIndex<M>,
    bilinear: impl IntoFormIndex<M>,
) -> Result<f64> {
    let (s, a) = (M::form(stabilization)?, M::form(bilinear)?);
    for f in [s, a] {
        if M::FORMS[f].arity != 2 {
            return Err(Error::Input(format!(
                "C_I compares two bilinear forms; `{}` of model `{}` is linear",
                M::FORMS[f].name,
                M::NAME
            )));
        }
    }
    let width = match G::CELL {
        crate::CellKind::Interval => 2,
        crate::CellKind::Triangle => 6,
    };
    let mut x = vec![0.0; width];
    let dim = if width == 2 { 1 } else { 2 };
    // the vertices relative to the first, scaled to the cell's size: at most 4 numbers
    // (fixed arrays: two allocations per cell took 0.1 s at 2M cells)
    let mut seen: Vec<[i64; 4]> = Vec::new();
    let mut largest: f64 = 0.0;
    for c in 0..mesh.cell_count() {
        mesh.cell_coordinates_into(c, &mut x);
        let mut relative = [0.0f64; 4];
        for (k, v) in x[dim..].iter().enumerate() {
            relative[k] = v - x[k % dim];
        }
        let size = relative.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let key = relative.map(|v| (v / size.max(f64::MIN_POSITIVE) * 1e9).round() as i64);
        if seen.contains(&key) {
            continue;
        }
        if seen.len() < 64 {
            seen.push(key);
        }
        largest = largest.max(element_inverse_constant_between::<M>(&x, params, s, a)?);
    }
    Ok(largest)
}

/// The discrete inf-sup constants of a multiplier: the eigenvalues `γ₁ ≤ γ₂ ≤ …` of
/// `S x = γ D x`, `S` the Schur complement `B A⁻¹ Bᵀ + C` ([`crate::lcp::Lcp::schur_complement`])
/// and `D = diag(weights)` the mesh-dependent norm of the multipliers, the diagonal of the
/// model's stabilization `C/α` (for a P0 membrane multiplier `h_T² |T|`: the norm
/// `Σ_T h_T² ‖μ‖²_T` of Barbosa–Hughes; a boundary multiplier's `h_E |E|`). `√γ₁` is
/// the inf-sup constant of the pair; the stabilized method has `γ₁ ≥ α` where `C` is
/// diagonal (`C = αD`), whatever the pair.
///
/// # Errors
/// Weights that are not positive and finite, or of another length than `schur`.
pub fn inf_sup_spectrum(schur: &DMatrix<f64>, weights: &[f64]) -> Result<Vec<f64>> {
    let m = schur.nrows();
    if weights.len() != m || !weights.iter().all(|w| w.is_finite() && *w > 0.0) {
        return Err(Error::Input(format!(
            "the multipliers' norm needs {m} positive finite weights (the stabilization's diagonal over α), got {}",
            weights.len()
        )));
    }
    let scale: Vec<f64> = weights.iter().map(|w| 1.0 / w.sqrt()).collect();
    let weighted = DMatrix::from_fn(m, m, |k, l| schur[(k, l)] * scale[k] * scale[l]);
    let mut values: Vec<f64> = SymmetricEigen::new(weighted)
        .eigenvalues
        .iter()
        .copied()
        .collect();
    values.sort_by(f64::total_cmp);
    Ok(values)
}

#[cfg(test)]
mod tests {
    use super::*;

    crate::model! {
        /// The P2 membrane's stabilization against its stiffness (as in fem-models).
        pub mod membrane_p2 on triangle {
            unknowns: u: P2, λ: P0 >= 0;
            tests: v, μ;
            data: f;
            forms: "
                a(u;v)       = ∫ ∇u·∇v
                b(v;μ)       = ∫ v μ
                S(u,λ;v,μ)   = Σ_T h_T² (−Δu − λ, −Δv − μ)_T
                L(v)         = ∫ f v
            ";
        }
    }

    crate::model! {
        /// The same on P1, where Δ vanishes on each cell.
        pub mod membrane_p1 on triangle {
            unknowns: u: P1, λ: P0 >= 0;
            tests: v, μ;
            data: f;
            forms: "
                a(u;v)       = ∫ ∇u·∇v
                b(v;μ)       = ∫ v μ
                S(u,λ;v,μ)   = Σ_T h_T² (−Δu − λ, −Δv − μ)_T
                L(v)         = ∫ f v
            ";
        }
    }

    crate::model! {
        /// On intervals: `h² (u'', v'')` against `(u', v')` for P2.
        pub mod interval_p2 on interval {
            unknowns: u: P2, λ: P0 >= 0;
            tests: v, μ;
            data: f;
            forms: "
                a(u;v)       = ∫ u'v'
                b(v;μ)       = ∫ v μ
                S(u,λ;v,μ)   = Σ_T h_T² (u'' − λ, v'' − μ)_T
                L(v)         = ∫ f v
            ";
        }
    }

    /// The closed forms of docs/mathematics.md §1 for P2 triangles, scale and translation
    /// invariance, and 0 for P1.
    #[test]
    fn triangle_constants_match_their_closed_forms() {
        let s3 = 3f64.sqrt();
        let cases = [
            ([0.0, 0.0, 1.0, 0.0, 0.5, 0.5 * s3], 48.0),
            ([0.0, 0.0, 1.0, 0.0, 0.0, 1.0], 96.0),
            ([0.0, 0.0, s3, 0.0, 0.5 * s3, 0.5], 240.0),
        ];
        for (x, expected) in cases {
            let c = element_inverse_constant::<membrane_p2::Model>(&x, &[]).unwrap();
            assert!((c - expected).abs() < 1e-8 * expected, "{c} vs {expected}");
            let moved = x.map(|v| 3.7 * v + 1.0);
            let d = element_inverse_constant::<membrane_p2::Model>(&moved, &[]).unwrap();
            assert!((c - d).abs() < 1e-8 * c, "{c} vs {d}");
            let p1 = element_inverse_constant::<membrane_p1::Model>(&x, &[]).unwrap();
            assert_eq!(p1, 0.0);
        }
    }

    /// P2 on an interval of length h: the bubble `x(x − h)` maximizes `h²‖u''‖²/‖u'‖²`
    /// (`u''` is constant, so only the bubble's share counts): `h²·4h / (h³/3) = 12`.
    #[test]
    fn interval_constant_matches_its_closed_form() {
        for x in [[0.0, 1.0], [2.0, 2.25]] {
            let c = element_inverse_constant::<interval_p2::Model>(&x, &[]).unwrap();
            assert!((c - 12.0).abs() < 1e-9, "{c}");
        }
        let mesh = crate::IntervalMesh::uniform(0.0, 1.0, 7).unwrap();
        let c = inverse_constant::<interval_p2::Model, _>(&mesh, &[]).unwrap();
        assert!((c - 12.0).abs() < 1e-9, "{c}");
    }

    /// The mesh maximum: a structured right-diagonal mesh has only right isosceles cells.
    #[test]
    fn mesh_constant_is_the_largest_cell_constant() {
        let mesh =
            crate::TriangleMesh::rectangle(-1.0, 1.0, -1.0, 1.0, 4, 4, crate::Diagonal::Right)
                .unwrap();
        let c = inverse_constant::<membrane_p2::Model, _>(&mesh, &[]).unwrap();
        assert!((c - 96.0).abs() < 1e-8 * 96.0, "{c}");
    }

    #[test]
    fn alpha_policy() {
        assert_eq!(Alpha::default().value(96.0, 0.1).unwrap(), 0.5 / 96.0);
        assert_eq!(Alpha::default().value(0.0, 0.1).unwrap(), 0.1);
        assert_eq!(Alpha::Fixed(0.25).value(96.0, 0.1).unwrap(), 0.25);
        assert_eq!(Alpha::Fixed(0.0).value(96.0, 0.1).unwrap(), 0.0);
        assert!(Alpha::Fixed(-1.0).value(96.0, 0.1).is_err());
        assert!(Alpha::Fixed(f64::NAN).value(96.0, 0.1).is_err());
        assert!(Alpha::FromInverseConstant(0.0).value(96.0, 0.1).is_err());
        assert!(Alpha::default().value(f64::INFINITY, 0.1).is_err());
    }
}
