//! Finite elements on the reference triangle declared as data: a polynomial space, a list
//! of DOF functionals, and the nodal (dual) basis computed from them.
//!
//! An element in Ciarlet's sense is a triple (cell, space `P`, functionals `ℓ_1…ℓ_n`).
//! Here the cell is the reference triangle `(0,0), (1,0), (0,1)`, the space is the full
//! `P_k` spanned by the monomials `p_j = x^a y^b` (`a + b ≤ k`, see [`monomials`]), and
//! the basis `φ_1…φ_n` is the one with `ℓ_i(φ_j) = δ_ij`. Writing `φ_j = Σ_m C_mj p_m`
//! and `V_im = ℓ_i(p_m)` (the generalized Vandermonde matrix), duality reads `V C = I`,
//! so `C = V⁻¹` ([`ElementDefinition::nodal_basis`]). Everything is plain owned data
//! computed deterministically, so the form compiler can call it at compile time.
//!
//! Local numbering: vertices 0, 1, 2 as above; edge `e` joins vertices `EDGES[e]`
//! (0–1, 1–2, 2–0), as in [`crate::triangle::lagrange_nodes`]. The formulas and their
//! sources are in `docs/elements.md`.

use std::fmt;

use crate::dense::{InverseError, Matrix};
use crate::triangle::Polynomial2;

/// The vertices of the reference triangle, in local order.
pub const REFERENCE_VERTICES: [[f64; 2]; 3] = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];

/// The local vertices of each edge of a triangle: edge `e` joins `EDGES[e][0]` and
/// `EDGES[e][1]`.
pub const EDGES: [[usize; 2]; 3] = [[0, 1], [1, 2], [2, 0]];

/// The mesh entity a DOF belongs to; it decides which cells share the DOF.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Entity {
    /// Local vertex `0..3`.
    Vertex(usize),
    /// Local edge `0..3` (see [`EDGES`]).
    Edge(usize),
    /// The cell itself (not shared).
    Interior,
}

/// A linear functional on polynomials of the reference triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Functional {
    /// The partial derivative `∂^(a+b) f / ∂x^a ∂y^b` at `point`, with `order = [a, b]`;
    /// `[0, 0]` is the point value.
    Partial {
        /// Where the derivative is taken.
        point: [f64; 2],
        /// `[a, b]`: the number of `x` and `y` derivatives.
        order: [u32; 2],
    },
    /// The directional derivative `∇f(point) · direction` (an edge normal derivative
    /// when `direction` is a unit normal of an edge through `point`).
    Directional {
        /// Where the derivative is taken.
        point: [f64; 2],
        /// The direction (not normalized here; unit vectors give true normal derivatives).
        direction: [f64; 2],
    },
}

impl Functional {
    /// The point value at `point`.
    pub fn value(point: [f64; 2]) -> Self {
        Functional::Partial {
            point,
            order: [0, 0],
        }
    }

    /// `ℓ(f)`, exactly (up to rounding) for a polynomial `f`.
    pub fn apply(&self, f: &Polynomial2) -> f64 {
        match *self {
            Functional::Partial {
                point,
                order: [a, b],
            } => f.derivative(a, b).eval(point),
            Functional::Directional { point, direction } => {
                direction[0] * f.derivative(1, 0).eval(point)
                    + direction[1] * f.derivative(0, 1).eval(point)
            }
        }
    }
}

/// One degree of freedom: what it measures, where it lives, and its name (`u`, `u_x`,
/// `u_xx`, `u_n`, … in the manner of scikit-fem), by which boundary conditions can pick
/// DOF kinds.
#[derive(Clone, Debug, PartialEq)]
pub struct Dof {
    /// The entity that owns the DOF.
    pub entity: Entity,
    /// The functional on the reference triangle.
    pub functional: Functional,
    /// The DOF's kind.
    pub name: &'static str,
}

/// A finite element on the reference triangle: the space `P_degree` and its DOFs in
/// local order.
#[derive(Clone, Debug, PartialEq)]
pub struct ElementDefinition {
    /// The element's name (`Argyris`, `Morley`, `P2`, …).
    pub name: &'static str,
    /// `k` of the full polynomial space `P_k`.
    pub degree: usize,
    /// The DOFs, in local order.
    pub dofs: Vec<Dof>,
}

/// Why an element's nodal basis does not exist.
#[derive(Clone, Debug, PartialEq)]
pub enum DualBasisError {
    /// The number of functionals differs from `dim P_k = (k+1)(k+2)/2`.
    CountMismatch {
        /// The element.
        element: &'static str,
        /// Its number of DOFs.
        dofs: usize,
        /// The dimension of its space.
        dimension: usize,
    },
    /// The Vandermonde matrix is singular: some combination of the space vanishes under
    /// every functional (the functionals are not unisolvent).
    NotUnisolvent {
        /// The element.
        element: &'static str,
        /// What the elimination found.
        cause: InverseError,
    },
}

impl fmt::Display for DualBasisError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DualBasisError::CountMismatch {
                element,
                dofs,
                dimension,
            } => write!(
                f,
                "element {element}: {dofs} DOF functionals for a space of dimension {dimension}"
            ),
            DualBasisError::NotUnisolvent { element, cause } => write!(
                f,
                "element {element}: the DOF functionals are not unisolvent on its space ({cause})"
            ),
        }
    }
}

impl std::error::Error for DualBasisError {}

/// The exponents `(a, b)` of the monomials `x^a y^b` spanning `P_k`, by total degree and
/// then by increasing `b`: `1, x, y, x², xy, y², …`.
pub fn monomials(degree: usize) -> Vec<(u32, u32)> {
    (0..=degree as u32)
        .flat_map(|total| (0..=total).map(move |b| (total - b, b)))
        .collect()
}

/// The midpoint of local edge `e` of the reference triangle.
pub fn reference_edge_midpoint(e: usize) -> [f64; 2] {
    let [a, b] = EDGES[e].map(|v| REFERENCE_VERTICES[v]);
    [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]
}

/// The unit normal of the segment from `from` to `to`: the unit tangent
/// `t = (to − from)/|to − from|` turned clockwise, `n = (t_y, −t_x)`. A triangle edge
/// oriented from its lower to its higher (global) vertex number gets the same normal
/// from both of its cells. Returns `[NaN, NaN]` when the points coincide.
pub fn segment_normal(from: [f64; 2], to: [f64; 2]) -> [f64; 2] {
    let t = [to[0] - from[0], to[1] - from[1]];
    let length = t[0].hypot(t[1]);
    [t[1] / length, -t[0] / length]
}

/// The normal of reference edge `e` that its normal-derivative DOFs use: the edge
/// oriented from its lower to its higher local vertex number, normal by
/// [`segment_normal`]. Edges 0 and 1 get the outward normals `(0, −1)` and
/// `(1, 1)/√2`, edge 2 (oriented 0 → 2) the inward one `(1, 0)`. With this choice the
/// DOF transformation is the identity on the reference cell numbered increasingly.
pub fn reference_edge_normal(e: usize) -> [f64; 2] {
    let [a, b] = EDGES[e];
    let (low, high) = (a.min(b), a.max(b));
    segment_normal(REFERENCE_VERTICES[low], REFERENCE_VERTICES[high])
}

impl ElementDefinition {
    /// `dim P_k = (k+1)(k+2)/2`.
    pub fn space_dimension(&self) -> usize {
        (self.degree + 1) * (self.degree + 2) / 2
    }

    /// The generalized Vandermonde matrix `V_im = ℓ_i(p_m)` (DOFs by rows, the
    /// [`monomials`] of the space by columns).
    pub fn vandermonde(&self) -> Matrix {
        let monomials: Vec<Polynomial2> = monomials(self.degree)
            .into_iter()
            .map(|(a, b)| Polynomial2 {
                terms: vec![(a, b, 1.0)],
            })
            .collect();
        Matrix::from_fn(self.dofs.len(), monomials.len(), |i, m| {
            self.dofs[i].functional.apply(&monomials[m])
        })
    }

    /// The coefficients `C = V⁻¹`: column `j` holds the monomial coefficients of `φ_j`.
    ///
    /// # Errors
    /// [`DualBasisError`] when the functionals do not match the space in number or are
    /// not unisolvent on it.
    pub fn basis_coefficients(&self) -> Result<Matrix, DualBasisError> {
        let dimension = self.space_dimension();
        if self.dofs.len() != dimension {
            return Err(DualBasisError::CountMismatch {
                element: self.name,
                dofs: self.dofs.len(),
                dimension,
            });
        }
        self.vandermonde()
            .inverse()
            .map_err(|cause| DualBasisError::NotUnisolvent {
                element: self.name,
                cause,
            })
    }

    /// The nodal basis `φ_j` (`ℓ_i(φ_j) = δ_ij`) in local DOF order, as polynomials in
    /// the reference coordinates (coefficients that are exactly zero are left out).
    ///
    /// # Errors
    /// As [`ElementDefinition::basis_coefficients`].
    pub fn nodal_basis(&self) -> Result<Vec<Polynomial2>, DualBasisError> {
        let c = self.basis_coefficients()?;
        let monomials = monomials(self.degree);
        Ok((0..c.cols())
            .map(|j| Polynomial2 {
                terms: monomials
                    .iter()
                    .enumerate()
                    .map(|(m, &(a, b))| (a, b, c[(m, j)]))
                    .filter(|t| t.2 != 0.0)
                    .collect(),
            })
            .collect())
    }

    /// Lagrange `P_k` (`k = 1…`) declared through point values at the nodes of
    /// [`crate::triangle::lagrange_nodes`], with vertex, edge and interior owners.
    pub fn lagrange(degree: usize) -> Self {
        let k = degree.max(1);
        let dofs = crate::triangle::lagrange_nodes(k)
            .into_iter()
            .enumerate()
            .map(|(n, point)| {
                let entity = if n < 3 {
                    Entity::Vertex(n)
                } else if n < 3 + 3 * (k - 1) {
                    Entity::Edge((n - 3) / (k - 1))
                } else {
                    Entity::Interior
                };
                Dof {
                    entity,
                    functional: Functional::value(point),
                    name: "u",
                }
            })
            .collect();
        Self {
            name: "Lagrange",
            degree: k,
            dofs,
        }
    }

    /// The Argyris element (P5, 21 DOFs; C¹ after the DOF transformation of
    /// [`crate::dof_transformation::argyris_transformation`]). Local order: for each
    /// vertex `v = 0, 1, 2` the six DOFs `u, u_x, u_y, u_xx, u_xy, u_yy` at `v`
    /// (local index `6v + k`), then for each edge `e` the normal derivative `u_n` at its
    /// midpoint along [`reference_edge_normal`] (local index `18 + e`).
    pub fn argyris() -> Self {
        const ORDERS: [([u32; 2], &str); 6] = [
            ([0, 0], "u"),
            ([1, 0], "u_x"),
            ([0, 1], "u_y"),
            ([2, 0], "u_xx"),
            ([1, 1], "u_xy"),
            ([0, 2], "u_yy"),
        ];
        let mut dofs: Vec<Dof> = (0..3)
            .flat_map(|v| {
                ORDERS.iter().map(move |&(order, name)| Dof {
                    entity: Entity::Vertex(v),
                    functional: Functional::Partial {
                        point: REFERENCE_VERTICES[v],
                        order,
                    },
                    name,
                })
            })
            .collect();
        dofs.extend(normal_derivative_dofs());
        Self {
            name: "Argyris",
            degree: 5,
            dofs,
        }
    }

    /// The Morley element (P2, 6 DOFs, non-conforming for fourth-order problems). Local
    /// order: the values `u` at vertices 0, 1, 2, then for each edge `e` the normal
    /// derivative `u_n` at its midpoint along [`reference_edge_normal`] (index `3 + e`).
    pub fn morley() -> Self {
        let mut dofs: Vec<Dof> = (0..3)
            .map(|v| Dof {
                entity: Entity::Vertex(v),
                functional: Functional::value(REFERENCE_VERTICES[v]),
                name: "u",
            })
            .collect();
        dofs.extend(normal_derivative_dofs());
        Self {
            name: "Morley",
            degree: 2,
            dofs,
        }
    }
}

fn normal_derivative_dofs() -> impl Iterator<Item = Dof> {
    (0..3).map(|e| Dof {
        entity: Entity::Edge(e),
        functional: Functional::Directional {
            point: reference_edge_midpoint(e),
            direction: reference_edge_normal(e),
        },
        name: "u_n",
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn assert_dual(element: &ElementDefinition, tolerance: f64) -> Vec<Polynomial2> {
        let basis = element.nodal_basis().unwrap();
        assert_eq!(basis.len(), element.dofs.len());
        for (i, dof) in element.dofs.iter().enumerate() {
            for (j, phi) in basis.iter().enumerate() {
                let expected = f64::from(u8::from(i == j));
                let got = dof.functional.apply(phi);
                assert!(
                    (got - expected).abs() < tolerance,
                    "{}: ℓ_{i}(φ_{j}) = {got}",
                    element.name
                );
            }
        }
        basis
    }

    /// `Σ_i ℓ_i(p) φ_i = p` for every monomial `p` of the space, checked at points
    /// spread over the triangle: the basis spans the whole space.
    fn assert_reproduces_space(element: &ElementDefinition, basis: &[Polynomial2]) {
        let points = [
            [0.1, 0.2],
            [0.7, 0.05],
            [0.3, 0.6],
            [0.45, 0.45],
            [0.0, 0.9],
        ];
        for (a, b) in monomials(element.degree) {
            let p = Polynomial2 {
                terms: vec![(a, b, 1.0)],
            };
            for x in points {
                let interpolant: f64 = element
                    .dofs
                    .iter()
                    .zip(basis)
                    .map(|(dof, phi)| dof.functional.apply(&p) * phi.eval(x))
                    .sum();
                assert!(
                    (interpolant - p.eval(x)).abs() < 1e-11,
                    "{}: x^{a} y^{b} at {x:?}",
                    element.name
                );
            }
        }
    }

    #[test]
    fn argyris_basis_is_dual_and_spans_p5() {
        let argyris = ElementDefinition::argyris();
        assert_eq!(argyris.dofs.len(), 21);
        let basis = assert_dual(&argyris, 1e-12);
        assert_reproduces_space(&argyris, &basis);
        for phi in &basis {
            assert!(phi.terms.iter().all(|&(a, b, _)| a + b <= 5));
        }
    }

    #[test]
    fn morley_basis_is_dual_and_spans_p2() {
        let morley = ElementDefinition::morley();
        let basis = assert_dual(&morley, 1e-13);
        assert_reproduces_space(&morley, &basis);
    }

    /// Closed forms derived by hand (docs/elements.md): the edge functions are
    /// `y² − y`, `(x+y)(x+y−1)/√2`, `x − x²`, the vertex-0 function `1 − x − y + 2xy`.
    #[test]
    fn morley_basis_matches_its_closed_form() {
        let basis = ElementDefinition::morley().nodal_basis().unwrap();
        type Exact = fn([f64; 2]) -> f64;
        let exact: [(usize, Exact); 4] = [
            (0, |[x, y]| 1.0 - x - y + 2.0 * x * y),
            (3, |[_, y]| y * y - y),
            (4, |[x, y]| {
                (x + y) * (x + y - 1.0) * std::f64::consts::FRAC_1_SQRT_2
            }),
            (5, |[x, _]| x - x * x),
        ];
        for (i, f) in exact {
            for p in [[0.1, 0.2], [0.7, 0.05], [0.3, 0.6], [0.9, 0.1]] {
                assert!((basis[i].eval(p) - f(p)).abs() < 1e-14, "φ_{i} at {p:?}");
            }
        }
    }

    /// Hand-derived Argyris functions: the edge-0 normal-derivative function is the
    /// bubble `−16 λ0² λ1² λ2` (it vanishes to second order at every vertex, its normal
    /// derivative vanishes on edges 1 and 2 through the squared factors, and on edge 0
    /// `∂_n = −∂_y` of it is `16 λ0² λ1² = 1` at the midpoint); the three value functions
    /// sum to 1 (interpolating 1), and interpolating `x` (value `x_v`, `u_x = 1` at each
    /// vertex, `u_n = n_x`: 0, 1/√2, 1 on edges 0, 1, 2) gives back `x`.
    #[test]
    fn argyris_basis_matches_hand_derived_functions() {
        let basis = ElementDefinition::argyris().nodal_basis().unwrap();
        for p in [[0.1, 0.2], [0.7, 0.05], [0.3, 0.6], [0.2, 0.2]] {
            let [x, y] = p;
            let l0 = 1.0 - x - y;
            let bubble = -16.0 * l0 * l0 * x * x * y;
            assert!((basis[18].eval(p) - bubble).abs() < 1e-12);
            let values: f64 = (0..3).map(|v| basis[6 * v].eval(p)).sum();
            assert!((values - 1.0).abs() < 1e-12);
            let xs: f64 = (0..3)
                .map(|v| REFERENCE_VERTICES[v][0] * basis[6 * v].eval(p) + basis[6 * v + 1].eval(p))
                .sum::<f64>()
                + std::f64::consts::FRAC_1_SQRT_2 * basis[19].eval(p)
                + basis[20].eval(p);
            assert!((xs - x).abs() < 1e-12);
        }
    }

    /// The generic construction reproduces the independently written Lagrange bases.
    #[test]
    fn lagrange_as_data_matches_the_triangle_module() {
        for k in 1..=3 {
            let generic = ElementDefinition::lagrange(k).nodal_basis().unwrap();
            let direct = crate::triangle::lagrange_basis(k);
            for (g, d) in generic.iter().zip(&direct) {
                for p in [[0.1, 0.2], [0.5, 0.3], [0.05, 0.9]] {
                    assert!((g.eval(p) - d.eval(p)).abs() < 1e-12);
                }
            }
        }
    }

    #[test]
    fn malformed_definitions_are_errors() {
        let mut short = ElementDefinition::morley();
        short.dofs.pop();
        assert!(matches!(
            short.nodal_basis(),
            Err(DualBasisError::CountMismatch {
                dofs: 5,
                dimension: 6,
                ..
            })
        ));
        // the tangential derivative of a quadratic at an edge midpoint is the secant
        // slope of its vertex values, so tangential DOFs add nothing to the vertex values
        let mut tangential = ElementDefinition::morley();
        for (e, dof) in tangential.dofs.iter_mut().skip(3).enumerate() {
            let [a, b] = EDGES[e].map(|v| REFERENCE_VERTICES[v]);
            dof.functional = Functional::Directional {
                point: reference_edge_midpoint(e),
                direction: [b[0] - a[0], b[1] - a[1]],
            };
        }
        let error = tangential.nodal_basis().unwrap_err();
        assert!(matches!(error, DualBasisError::NotUnisolvent { .. }));
        assert!(error.to_string().contains("Morley"));
    }

    #[test]
    fn reference_normals() {
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let expected = [[0.0, -1.0], [s, s], [1.0, 0.0]];
        for (e, n) in expected.iter().enumerate() {
            let got = reference_edge_normal(e);
            assert!((got[0] - n[0]).abs() < 1e-15 && (got[1] - n[1]).abs() < 1e-15);
        }
    }
}
