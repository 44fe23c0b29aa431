//! Per-cell DOF transformations for elements that are not affine-equivalent (Argyris,
//! Morley): the matrix `M` with
//!
//! ```text
//!     φ_i = Σ_j M_ij (φ̂_j ∘ F⁻¹)
//! ```
//!
//! where `F(x̂) = v0 + J x̂` maps the reference triangle onto the physical one
//! (`J = [v1 − v0 | v2 − v0]`), `φ̂_j` is the reference nodal basis of
//! [`crate::dual_basis`], and `φ_i` is the basis dual to the PHYSICAL DOFs listed with
//! each function below. An element kernel computed with the pulled-back reference basis,
//! `K̂_jl = a(φ̂_j ∘ F⁻¹, φ̂_l ∘ F⁻¹)`, becomes the kernel of the physical basis as
//! `K = M K̂ Mᵀ`.
//!
//! How it is obtained (Kirby 2018, "A general approach to transforming finite elements",
//! SMAI J. Comp. Math. 4; for Argyris also Domínguez & Sayas 2008): for `f` in the
//! element's space, the reference DOFs of the pull-back `f ∘ F` are linear combinations
//! of the physical DOFs of `f`, `ℓ̂(f ∘ F) = B ℓ(f)`, exactly (chain rule, plus one
//! identity along each edge). Since `f ∘ F = Σ_j ℓ̂_j(f ∘ F) φ̂_j`, taking `f = φ_k` gives
//! `φ_k ∘ F = Σ_j B_jk φ̂_j`, i.e. `M = Bᵀ`. Details in `docs/elements.md`.
//!
//! Edges are oriented from their lower to their higher GLOBAL vertex number and the
//! physical normal-derivative DOF uses the normal of [`segment_normal`] for that
//! orientation, so the two cells sharing an edge measure the same derivative.

use std::fmt;

use crate::dense::Matrix;
use crate::dual_basis::{reference_edge_normal, segment_normal, EDGES};

/// Why a cell's transformation cannot be formed.
#[derive(Clone, Debug, PartialEq)]
pub enum TransformationError {
    /// A vertex coordinate is NaN or infinite.
    NonFiniteVertex {
        /// Local vertex number.
        vertex: usize,
    },
    /// The triangle has (almost) no area, `|det J| ≤ 1e-12 · (longest edge)²`, or its
    /// coordinates are so large that `det J` overflows.
    Degenerate {
        /// `det J = 2 × signed area`.
        determinant: f64,
    },
    /// Two local vertices carry the same global number (edge orientation undefined).
    RepeatedGlobalVertex {
        /// The repeated global number.
        number: usize,
    },
}

impl fmt::Display for TransformationError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TransformationError::NonFiniteVertex { vertex } => {
                write!(f, "triangle vertex {vertex} has a non-finite coordinate")
            }
            TransformationError::Degenerate { determinant } => write!(
                f,
                "degenerate triangle: det J = {determinant:e} is zero relative to its edge lengths or not finite"
            ),
            TransformationError::RepeatedGlobalVertex { number } => write!(
                f,
                "global vertex number {number} appears twice in one triangle"
            ),
        }
    }
}

impl std::error::Error for TransformationError {}

/// The affine map of a physical triangle and the orientation of its edges.
#[derive(Clone, Debug, PartialEq)]
pub struct CellGeometry {
    /// `J = [v1 − v0 | v2 − v0]`, as `jacobian[row][col]`.
    pub jacobian: [[f64; 2]; 2],
    /// For each local edge `e` (see [`EDGES`]): the local vertices `[from, to]` ordered
    /// by increasing global number.
    pub oriented_edges: [[usize; 2]; 3],
    /// For each local edge: the unit tangent from `from` to `to`.
    pub tangents: [[f64; 2]; 3],
    /// For each local edge: the unit normal of the oriented edge ([`segment_normal`]).
    pub normals: [[f64; 2]; 3],
    /// For each local edge: its length.
    pub lengths: [f64; 3],
}

impl CellGeometry {
    /// The geometry of the triangle with vertex coordinates `vertices` (local order)
    /// and global vertex numbers `global`.
    ///
    /// # Errors
    /// [`TransformationError`] for a non-finite coordinate, a degenerate triangle or a
    /// repeated global number.
    pub fn new(vertices: [[f64; 2]; 3], global: [usize; 3]) -> Result<Self, TransformationError> {
        if let Some(vertex) = vertices
            .iter()
            .position(|v| !(v[0].is_finite() && v[1].is_finite()))
        {
            return Err(TransformationError::NonFiniteVertex { vertex });
        }
        for [a, b] in EDGES {
            if global[a] == global[b] {
                return Err(TransformationError::RepeatedGlobalVertex { number: global[a] });
            }
        }
        let [v0, v1, v2] = vertices;
        let jacobian = [
            [v1[0] - v0[0], v2[0] - v0[0]],
            [v1[1] - v0[1], v2[1] - v0[1]],
        ];
        let determinant = jacobian[0][0] * jacobian[1][1] - jacobian[0][1] * jacobian[1][0];
        let mut lengths = [0.0; 3];
        let mut tangents = [[0.0; 2]; 3];
        let mut normals = [[0.0; 2]; 3];
        let mut oriented_edges = [[0; 2]; 3];
        for (e, [a, b]) in EDGES.into_iter().enumerate() {
            let (from, to) = if global[a] < global[b] {
                (a, b)
            } else {
                (b, a)
            };
            let d = [
                vertices[to][0] - vertices[from][0],
                vertices[to][1] - vertices[from][1],
            ];
            lengths[e] = d[0].hypot(d[1]);
            tangents[e] = [d[0] / lengths[e], d[1] / lengths[e]];
            normals[e] = segment_normal(vertices[from], vertices[to]);
            oriented_edges[e] = [from, to];
        }
        let longest = lengths.iter().fold(0.0_f64, |m, &l| m.max(l));
        if !determinant.is_finite() || determinant.abs() <= 1e-12 * longest * longest {
            return Err(TransformationError::Degenerate { determinant });
        }
        Ok(Self {
            jacobian,
            oriented_edges,
            tangents,
            normals,
            lengths,
        })
    }

    /// `(α, β)` with `J n̂_e = α n_e + β t_e`: the pushed-forward reference normal of
    /// edge `e` split into the physical normal and tangent.
    fn split_reference_normal(&self, e: usize) -> (f64, f64) {
        let n_hat = reference_edge_normal(e);
        let j = &self.jacobian;
        let w = [
            j[0][0] * n_hat[0] + j[0][1] * n_hat[1],
            j[1][0] * n_hat[0] + j[1][1] * n_hat[1],
        ];
        let (n, t) = (self.normals[e], self.tangents[e]);
        (w[0] * n[0] + w[1] * n[1], w[0] * t[0] + w[1] * t[1])
    }
}

/// The Argyris transformation `M` (21 × 21, `φ = M (φ̂ ∘ F⁻¹)`).
///
/// Physical DOFs, in the local order of [`crate::dual_basis::ElementDefinition::argyris`]:
/// at each vertex `v` the value, `∂x`, `∂y`, `∂xx`, `∂xy`, `∂yy` in physical Cartesian
/// coordinates (index `6v + k`); on each local edge `e` the derivative along the unit
/// normal `n_e` of the edge oriented from its lower to its higher global vertex number
/// ([`segment_normal`]) at the edge's midpoint (index `18 + e`).
///
/// Rows of `B = Mᵀ` (reference DOF ← physical DOFs): vertex values are copied;
/// `∇̂ = Jᵀ ∇`; `∇̂∇̂ = Jᵀ (∇∇) J`; on edge `e`, `∂_n̂ = α ∂_n + β ∂_t` with
/// `J n̂_e = α n_e + β t_e`, and the tangential derivative at the midpoint of an edge of
/// length `L` from `A` to `B` is, exactly for quintics along the edge,
/// `∂_t f(m) = 15/(8L) (f(B) − f(A)) − 7/16 (∂_t f(A) + ∂_t f(B)) + L/32 (∂_tt f(B) − ∂_tt f(A))`.
///
/// # Errors
/// [`TransformationError`] as in [`CellGeometry::new`].
pub fn argyris_transformation(
    vertices: [[f64; 2]; 3],
    global: [usize; 3],
) -> Result<Matrix, TransformationError> {
    let geometry = CellGeometry::new(vertices, global)?;
    let j = geometry.jacobian;
    let mut b = Matrix::zeros(21, 21);
    for v in 0..3 {
        let o = 6 * v;
        b[(o, o)] = 1.0;
        for a in 0..2 {
            for c in 0..2 {
                b[(o + 1 + a, o + 1 + c)] = j[c][a];
            }
        }
        // Ĥ_ab = J_0a J_0b H_xx + (J_0a J_1b + J_1a J_0b) H_xy + J_1a J_1b H_yy
        for (r, (a, bb)) in [(0, 0), (0, 1), (1, 1)].into_iter().enumerate() {
            b[(o + 3 + r, o + 3)] = j[0][a] * j[0][bb];
            b[(o + 3 + r, o + 4)] = j[0][a] * j[1][bb] + j[1][a] * j[0][bb];
            b[(o + 3 + r, o + 5)] = j[1][a] * j[1][bb];
        }
    }
    for e in 0..3 {
        let row = 18 + e;
        let (alpha, beta) = geometry.split_reference_normal(e);
        b[(row, row)] = alpha;
        let [from, to] = geometry.oriented_edges[e];
        let t = geometry.tangents[e];
        let l = geometry.lengths[e];
        // β ∂_t f(m) through the Hermite data of the quintic trace at the edge's ends
        for (vertex, sign) in [(from, -1.0), (to, 1.0)] {
            let o = 6 * vertex;
            b[(row, o)] += beta * sign * 15.0 / (8.0 * l);
            b[(row, o + 1)] += beta * (-7.0 / 16.0) * t[0];
            b[(row, o + 2)] += beta * (-7.0 / 16.0) * t[1];
            let tt = [t[0] * t[0], 2.0 * t[0] * t[1], t[1] * t[1]];
            for (k, &w) in tt.iter().enumerate() {
                b[(row, o + 3 + k)] += beta * sign * l / 32.0 * w;
            }
        }
    }
    Ok(b.transpose())
}

/// The Morley transformation `M` (6 × 6, `φ = M (φ̂ ∘ F⁻¹)`).
///
/// Physical DOFs, in the local order of [`crate::dual_basis::ElementDefinition::morley`]:
/// the values at vertices 0, 1, 2, then on each local edge `e` the derivative along the
/// unit normal of the edge oriented from its lower to its higher global vertex number,
/// at its midpoint (index `3 + e`). Rows of `B = Mᵀ`: values are copied; on edge `e`,
/// `∂_n̂ = α ∂_n + β ∂_t` as for Argyris, with the tangential derivative of a quadratic
/// at the midpoint equal to the secant slope `(f(B) − f(A))/L`.
///
/// # Errors
/// [`TransformationError`] as in [`CellGeometry::new`].
pub fn morley_transformation(
    vertices: [[f64; 2]; 3],
    global: [usize; 3],
) -> Result<Matrix, TransformationError> {
    let geometry = CellGeometry::new(vertices, global)?;
    let mut b = Matrix::identity(6);
    for e in 0..3 {
        let row = 3 + e;
        let (alpha, beta) = geometry.split_reference_normal(e);
        b[(row, row)] = alpha;
        let [from, to] = geometry.oriented_edges[e];
        b[(row, from)] -= beta / geometry.lengths[e];
        b[(row, to)] += beta / geometry.lengths[e];
    }
    Ok(b.transpose())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dual_basis::{monomials, ElementDefinition};
    use crate::triangle::Polynomial2;

    /// xorshift64*: reproducible pseudo-random numbers without dependencies.
    struct Random(u64);

    impl Random {
        fn uniform(&mut self, low: f64, high: f64) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            let bits = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11;
            low + (high - low) * (bits as f64 / (1u64 << 53) as f64)
        }

        /// A triangle of diameter about `scale`, neither tiny-angled nor degenerate,
        /// in either orientation.
        fn triangle(&mut self, scale: f64) -> [[f64; 2]; 3] {
            loop {
                let v = [(); 3].map(|_| {
                    [
                        self.uniform(-2.0, 2.0) * scale,
                        self.uniform(-2.0, 2.0) * scale,
                    ]
                });
                let det = (v[1][0] - v[0][0]) * (v[2][1] - v[0][1])
                    - (v[2][0] - v[0][0]) * (v[1][1] - v[0][1]);
                if det.abs() > 0.5 * scale * scale {
                    return v;
                }
            }
        }
    }

    /// Value, gradient and Hessian `[f, fx, fy, fxx, fxy, fyy]` of the physical basis
    /// functions `φ_i = Σ_j M_ij φ̂_j ∘ F⁻¹` at a physical point, evaluated through the
    /// inverse map `x̂ = K (x − v0)`, `K = J⁻¹`: `∇ = Kᵀ ∇̂`, `∇∇ = Kᵀ ∇̂∇̂ K`.
    struct Physical {
        v0: [f64; 2],
        k: [[f64; 2]; 2],
        basis: Vec<Polynomial2>,
        m: Matrix,
    }

    impl Physical {
        fn new(element: &ElementDefinition, vertices: [[f64; 2]; 3], m: Matrix) -> Self {
            let [v0, v1, v2] = vertices;
            let (a, b, c, d) = (v1[0] - v0[0], v2[0] - v0[0], v1[1] - v0[1], v2[1] - v0[1]);
            let det = a * d - b * c;
            Self {
                v0,
                k: [[d / det, -b / det], [-c / det, a / det]],
                basis: element.nodal_basis().unwrap(),
                m,
            }
        }

        fn jets(&self, x: [f64; 2]) -> Vec<[f64; 6]> {
            let k = self.k;
            let d = [x[0] - self.v0[0], x[1] - self.v0[1]];
            let xh = [
                k[0][0] * d[0] + k[0][1] * d[1],
                k[1][0] * d[0] + k[1][1] * d[1],
            ];
            let reference: Vec<[f64; 6]> = self
                .basis
                .iter()
                .map(|p| {
                    let g = [p.derivative(1, 0).eval(xh), p.derivative(0, 1).eval(xh)];
                    let h = [
                        [p.derivative(2, 0).eval(xh), p.derivative(1, 1).eval(xh)],
                        [p.derivative(1, 1).eval(xh), p.derivative(0, 2).eval(xh)],
                    ];
                    let grad = [
                        k[0][0] * g[0] + k[1][0] * g[1],
                        k[0][1] * g[0] + k[1][1] * g[1],
                    ];
                    let hess = |r: usize, s: usize| -> f64 {
                        (0..2)
                            .flat_map(|a| (0..2).map(move |b| (a, b)))
                            .map(|(a, b)| k[a][r] * h[a][b] * k[b][s])
                            .sum()
                    };
                    [
                        p.eval(xh),
                        grad[0],
                        grad[1],
                        hess(0, 0),
                        hess(0, 1),
                        hess(1, 1),
                    ]
                })
                .collect();
            (0..self.m.rows())
                .map(|i| {
                    let mut out = [0.0; 6];
                    for (j, r) in reference.iter().enumerate() {
                        for (o, rv) in out.iter_mut().zip(r) {
                            *o += self.m[(i, j)] * rv;
                        }
                    }
                    out
                })
                .collect()
        }
    }

    /// The physical unit normal of local edge `e` for the global numbering, written
    /// independently of [`segment_normal`]: the tangent from the lower-numbered vertex
    /// rotated by −90° with a rotation matrix.
    fn physical_normal(vertices: [[f64; 2]; 3], global: [usize; 3], e: usize) -> [f64; 2] {
        let (a, b) = ([0, 1, 2][e], [1, 2, 0][e]);
        let (p, q) = if global[a] < global[b] {
            (vertices[a], vertices[b])
        } else {
            (vertices[b], vertices[a])
        };
        let t = [q[0] - p[0], q[1] - p[1]];
        let l = (t[0] * t[0] + t[1] * t[1]).sqrt();
        let rotation = [[0.0, 1.0], [-1.0, 0.0]];
        [
            (rotation[0][0] * t[0] + rotation[0][1] * t[1]) / l,
            (rotation[1][0] * t[0] + rotation[1][1] * t[1]) / l,
        ]
    }

    fn midpoint(vertices: [[f64; 2]; 3], e: usize) -> [f64; 2] {
        let (a, b) = (vertices[e], vertices[(e + 1) % 3]);
        [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]
    }

    /// The physical DOFs of a function given by its jet `[f, fx, fy, fxx, fxy, fyy]`
    /// at points.
    fn physical_dofs(
        element: &str,
        vertices: [[f64; 2]; 3],
        global: [usize; 3],
        jet: impl Fn([f64; 2]) -> [f64; 6],
    ) -> Vec<f64> {
        let per_vertex = if element == "Argyris" { 6 } else { 1 };
        let mut dofs: Vec<f64> = vertices
            .iter()
            .flat_map(|&v| jet(v)[..per_vertex].to_vec())
            .collect();
        for e in 0..3 {
            let n = physical_normal(vertices, global, e);
            let j = jet(midpoint(vertices, e));
            dofs.push(n[0] * j[1] + n[1] * j[2]);
        }
        dofs
    }

    type Transformation = fn([[f64; 2]; 3], [usize; 3]) -> Result<Matrix, TransformationError>;

    fn elements() -> [(ElementDefinition, Transformation); 2] {
        [
            (ElementDefinition::argyris(), argyris_transformation),
            (ElementDefinition::morley(), morley_transformation),
        ]
    }

    /// (a) `ℓ_i^phys(φ_j^phys) = δ_ij` on random triangles of several sizes, both
    /// orientations and random global numberings.
    #[test]
    fn physical_basis_is_dual_to_the_physical_dofs() {
        let mut random = Random(0x9e37_79b9_7f4a_7c15);
        for (element, transformation) in elements() {
            for trial in 0..40 {
                let scale = [1.0, 0.1, 0.01, 3.0][trial % 4];
                let vertices = random.triangle(scale);
                let global = [[3, 8, 5], [10, 2, 7], [1, 0, 2], [4, 6, 9], [20, 11, 3]][trial % 5];
                let m = transformation(vertices, global).unwrap();
                let physical = Physical::new(&element, vertices, m);
                let n = element.dofs.len();
                let order = |i: usize| -> i32 {
                    match element.dofs[i].name {
                        "u" => 0,
                        "u_x" | "u_y" | "u_n" => 1,
                        _ => 2,
                    }
                };
                for j in 0..n {
                    let dofs =
                        physical_dofs(element.name, vertices, global, |x| physical.jets(x)[j]);
                    for (i, &d) in dofs.iter().enumerate() {
                        let expected = f64::from(u8::from(i == j));
                        // φ_j is of size h^r_j and ℓ_i differentiates r_i times, so
                        // ℓ_i(φ_j) is naturally of size h^(r_j − r_i), and so is its
                        // rounding (amplified by cancellation when K ~ 1/h enters twice)
                        let size = scale.powi(order(j) - order(i)).max(1.0);
                        assert!(
                            (d - expected).abs() < 1e-10 * size,
                            "{} trial {trial}: ℓ_{i}(φ_{j}) = {d}",
                            element.name
                        );
                    }
                }
            }
        }
    }

    /// On the reference triangle numbered increasingly the transformation is the
    /// identity; a reversed numbering flips exactly the edge normals it reverses.
    #[test]
    fn reference_cell_transformations() {
        let reference = crate::dual_basis::REFERENCE_VERTICES;
        for (element, transformation) in elements() {
            let n = element.dofs.len();
            let m = transformation(reference, [0, 1, 2]).unwrap();
            for i in 0..n {
                for j in 0..n {
                    let expected = f64::from(u8::from(i == j));
                    assert!((m[(i, j)] - expected).abs() < 1e-15, "{}", element.name);
                }
            }
            // numbering 1, 0, 2 reverses edge 0 (0–1) only: its normal DOF flips sign
            let m = transformation(reference, [1, 0, 2]).unwrap();
            for (e, sign) in [-1.0, 1.0, 1.0].into_iter().enumerate() {
                let i = n - 3 + e;
                assert!((m[(i, i)] - sign).abs() < 1e-15, "{}", element.name);
            }
        }
    }

    fn random_polynomial(random: &mut Random, degree: usize) -> Polynomial2 {
        Polynomial2 {
            terms: monomials(degree)
                .into_iter()
                .map(|(a, b)| (a, b, random.uniform(-1.0, 1.0)))
                .collect(),
        }
    }

    fn jet_of(p: &Polynomial2) -> impl Fn([f64; 2]) -> [f64; 6] + '_ {
        move |x| {
            [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)]
                .map(|(a, b)| p.derivative(a, b).eval(x))
        }
    }

    /// (c) Interpolating a random polynomial of the element's degree with the physical
    /// DOFs and basis gives the polynomial back, with all its derivatives up to 2.
    #[test]
    fn interpolation_of_the_full_space_is_exact() {
        let mut random = Random(42);
        for (element, transformation) in elements() {
            for trial in 0..20 {
                let vertices = random.triangle([1.0, 0.2, 2.0][trial % 3]);
                let global = [[7, 3, 12], [0, 1, 2], [5, 9, 1]][trial % 3];
                let f = random_polynomial(&mut random, element.degree);
                let physical = Physical::new(
                    &element,
                    vertices,
                    transformation(vertices, global).unwrap(),
                );
                let dofs = physical_dofs(element.name, vertices, global, jet_of(&f));
                for _ in 0..5 {
                    let (s, t) = (random.uniform(0.0, 1.0), random.uniform(0.0, 1.0));
                    let (s, t) = if s + t > 1.0 {
                        (1.0 - s, 1.0 - t)
                    } else {
                        (s, t)
                    };
                    let x = [0, 1].map(|c| {
                        vertices[0][c]
                            + s * (vertices[1][c] - vertices[0][c])
                            + t * (vertices[2][c] - vertices[0][c])
                    });
                    let exact = jet_of(&f)(x);
                    let mut interpolant = [0.0; 6];
                    for (d, jet) in dofs.iter().zip(physical.jets(x)) {
                        for (o, v) in interpolant.iter_mut().zip(jet) {
                            *o += d * v;
                        }
                    }
                    for k in 0..6 {
                        assert!(
                            (interpolant[k] - exact[k]).abs() < 1e-9 * (1.0 + exact[k].abs()),
                            "{} trial {trial}: derivative {k}: {} vs {}",
                            element.name,
                            interpolant[k],
                            exact[k]
                        );
                    }
                }
            }
        }
    }

    /// Vertex coordinates and global vertex numbers of one cell.
    type Cell = ([[f64; 2]; 3], [usize; 3]);

    /// Two counterclockwise triangles `[p5, p2, p9]` and `[p9, p2, p7]` sharing the edge
    /// p2–p9: local edge 1 of the first and local edge 0 of the second, so the cells
    /// traverse it in opposite local directions. The shared vertices get the global
    /// numbers 2 and 9, or 9 and 2 when `swap`, the others 5 and 7.
    fn edge_pair(random: &mut Random, swap: bool) -> (Cell, Cell) {
        let p2 = [random.uniform(-1.0, 1.0), random.uniform(-1.0, 1.0)];
        let angle = random.uniform(0.0, std::f64::consts::TAU);
        let length = random.uniform(0.3, 1.5);
        let p9 = [p2[0] + length * angle.cos(), p2[1] + length * angle.sin()];
        let side = |random: &mut Random, sign: f64| {
            let (s, h) = (
                random.uniform(0.2, 0.8),
                sign * random.uniform(0.3, 1.0) * length,
            );
            [
                p2[0] + s * (p9[0] - p2[0]) - h * angle.sin(),
                p2[1] + s * (p9[1] - p2[1]) + h * angle.cos(),
            ]
        };
        let p5 = side(random, 1.0);
        let p7 = side(random, -1.0);
        let (g2, g9) = if swap { (9, 2) } else { (2, 9) };
        (([p5, p2, p9], [5, g2, g9]), ([p9, p2, p7], [g9, g2, 7]))
    }

    /// A global DOF: `Vertex(g, k)` is DOF `k` at global vertex `g`; `Edge(lo, hi)` the
    /// normal-derivative DOF of the edge between global vertices `lo < hi`.
    #[derive(Clone, Copy)]
    enum GlobalDof {
        Vertex(usize, usize),
        Edge(usize, usize),
    }

    /// The function with global DOF values `values`, evaluated on one cell;
    /// `orientation` are the global numbers handed to the transformation (normally
    /// `global` itself).
    fn cell_function(
        element: &ElementDefinition,
        transformation: Transformation,
        (vertices, global): Cell,
        orientation: [usize; 3],
        values: impl Fn(GlobalDof) -> f64,
    ) -> impl Fn([f64; 2]) -> [f64; 6] {
        let per_vertex = element.dofs.len() / 3 - 1;
        let mut local: Vec<f64> = global
            .iter()
            .flat_map(|&g| (0..per_vertex).map(move |k| (g, k)))
            .map(|(g, k)| values(GlobalDof::Vertex(g, k)))
            .collect();
        for [a, b] in EDGES {
            let (lo, hi) = (global[a].min(global[b]), global[a].max(global[b]));
            local.push(values(GlobalDof::Edge(lo, hi)));
        }
        let physical = Physical::new(
            element,
            vertices,
            transformation(vertices, orientation).unwrap(),
        );
        move |x| {
            let mut out = [0.0; 6];
            for (u, jet) in local.iter().zip(physical.jets(x)) {
                for (o, v) in out.iter_mut().zip(jet) {
                    *o += u * v;
                }
            }
            out
        }
    }

    /// Reproducible random values per global DOF.
    fn random_values(seed: u64) -> impl Fn(GlobalDof) -> f64 {
        move |dof| {
            let key = match dof {
                GlobalDof::Vertex(g, k) => 100 * g as u64 + k as u64 + 1,
                GlobalDof::Edge(lo, hi) => 100_000 + 1000 * lo as u64 + hi as u64,
            };
            Random(seed ^ key.wrapping_mul(0x9e37_79b9)).uniform(-1.0, 1.0)
        }
    }

    /// A global function from one random value per global DOF (six per vertex, one per
    /// edge), evaluated on one cell of the pair.
    fn global_function(
        element: &ElementDefinition,
        transformation: Transformation,
        vertices: [[f64; 2]; 3],
        global: [usize; 3],
        orientation: [usize; 3],
        seed: u64,
    ) -> impl Fn([f64; 2]) -> [f64; 6] {
        cell_function(
            element,
            transformation,
            (vertices, global),
            orientation,
            random_values(seed),
        )
    }

    /// (b) Argyris is C¹: value and gradient of a global function agree from both sides
    /// at points along a shared edge; ignoring the global orientation breaks it.
    #[test]
    fn argyris_global_functions_are_c1_across_a_shared_edge() {
        let mut random = Random(7);
        let argyris = ElementDefinition::argyris();
        for trial in 0..20 {
            let ((va, ga), (vb, gb)) = edge_pair(&mut random, trial % 2 == 1);
            let seed = 1000 + trial;
            let ua = global_function(&argyris, argyris_transformation, va, ga, ga, seed);
            let ub = global_function(&argyris, argyris_transformation, vb, gb, gb, seed);
            for s in [0.0, 0.13, 0.5, 0.77, 1.0] {
                let x = [0, 1].map(|c| va[1][c] + s * (va[2][c] - va[1][c]));
                let (ja, jb) = (ua(x), ub(x));
                for k in 0..3 {
                    assert!(
                        (ja[k] - jb[k]).abs() < 1e-10 * (1.0 + ja[k].abs()),
                        "trial {trial}, s = {s}, component {k}: {} vs {}",
                        ja[k],
                        jb[k]
                    );
                }
            }
            // the same DOF values, but the second cell orients the shared edge by a
            // numbering that reverses it: its normal DOF flips and the gradient jumps
            let reversed = gb.map(|g| if g == gb[0].min(gb[1]) { 20 } else { g });
            let wrong = global_function(&argyris, argyris_transformation, vb, gb, reversed, seed);
            let mid = [0, 1].map(|c| 0.5 * (va[1][c] + va[2][c]));
            let (good, bad) = (ua(mid), wrong(mid));
            assert!((good[1] - bad[1]).abs() + (good[2] - bad[2]).abs() > 1e-6);
        }
    }

    /// (b) Morley: the value is continuous at the shared vertices and the mean of the
    /// normal derivative over the shared edge agrees (the jet is evaluated from each
    /// side; the normal derivative of a P2 function is linear along an edge, so the
    /// two-point Gauss rule gives its mean exactly).
    #[test]
    fn morley_global_functions_match_at_vertices_and_in_normal_mean() {
        let mut random = Random(11);
        let morley = ElementDefinition::morley();
        let gauss = crate::quadrature::gauss_legendre(2);
        for trial in 0..20 {
            let ((va, ga), (vb, gb)) = edge_pair(&mut random, trial % 2 == 1);
            let seed = 77 + trial;
            let ua = global_function(&morley, morley_transformation, va, ga, ga, seed);
            let ub = global_function(&morley, morley_transformation, vb, gb, gb, seed);
            for x in [va[1], va[2]] {
                assert!((ua(x)[0] - ub(x)[0]).abs() < 1e-12);
            }
            let n = physical_normal(va, ga, 1);
            let mean = |u: &dyn Fn([f64; 2]) -> [f64; 6]| {
                gauss.integrate(|s| {
                    let x = [0, 1].map(|c| va[1][c] + s * (va[2][c] - va[1][c]));
                    let j = u(x);
                    n[0] * j[1] + n[1] * j[2]
                })
            };
            let (ma, mb) = (mean(&ua), mean(&ub));
            assert!((ma - mb).abs() < 1e-11, "trial {trial}: {ma} vs {mb}");
        }
    }

    /// A patch of 18 cells: a perturbed 4 × 4 grid of vertices, squares split along
    /// alternating diagonals, every other cell listed clockwise, vertices numbered by a
    /// scrambled permutation.
    fn patch(random: &mut Random) -> (Vec<[f64; 2]>, Vec<[usize; 3]>) {
        let coordinates: Vec<[f64; 2]> = (0..16)
            .map(|k| {
                let (i, j) = ((k % 4) as f64, (k / 4) as f64);
                [i + random.uniform(-0.2, 0.2), j + random.uniform(-0.2, 0.2)]
            })
            .collect();
        let number = |i: usize, j: usize| (7 * (4 * j + i) + 3) % 16;
        let mut cells = Vec::new();
        for j in 0..3 {
            for i in 0..3 {
                let [a, b, c, d] =
                    [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)].map(|(i, j)| number(i, j));
                let pair = if (i + j) % 2 == 0 {
                    [[a, b, c], [a, c, d]]
                } else {
                    [[a, b, d], [b, c, d]]
                };
                for (n, [x, y, z]) in pair.into_iter().enumerate() {
                    cells.push(if n == 1 { [x, z, y] } else { [x, y, z] });
                }
            }
        }
        // coordinates are indexed by global number
        let mut by_number = vec![[0.0; 2]; 16];
        for (k, &p) in coordinates.iter().enumerate() {
            by_number[(7 * k + 3) % 16] = p;
        }
        (by_number, cells)
    }

    /// The issue's patch test on a small mesh: a global P5 polynomial's DOFs reproduce
    /// it on every cell, and a global function of random DOFs is C¹ across every
    /// interior edge (values and gradients at three points per edge).
    #[test]
    fn argyris_patch_reproduces_p5_and_is_c1_across_every_interior_edge() {
        let mut random = Random(2024);
        let argyris = ElementDefinition::argyris();
        let (points, cells) = patch(&mut random);
        let cell = |c: usize| -> Cell { (cells[c].map(|g| points[g]), cells[c]) };
        let f = random_polynomial(&mut random, 5);
        let f_values = |dof: GlobalDof| match dof {
            GlobalDof::Vertex(g, k) => jet_of(&f)(points[g])[k],
            GlobalDof::Edge(lo, hi) => {
                let (p, q) = (points[lo], points[hi]);
                let t = [q[0] - p[0], q[1] - p[1]];
                let l = t[0].hypot(t[1]);
                let j = jet_of(&f)([0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])]);
                (t[1] * j[1] - t[0] * j[2]) / l
            }
        };
        let mut interior_edges = 0;
        for c in 0..cells.len() {
            let (vertices, global) = cell(c);
            let u = cell_function(&argyris, argyris_transformation, cell(c), global, f_values);
            let centroid = [0, 1].map(|k| vertices.iter().map(|v| v[k]).sum::<f64>() / 3.0);
            let (got, exact) = (u(centroid), jet_of(&f)(centroid));
            for k in 0..6 {
                assert!(
                    (got[k] - exact[k]).abs() < 1e-9 * (1.0 + exact[k].abs()),
                    "cell {c}, derivative {k}: {} vs {}",
                    got[k],
                    exact[k]
                );
            }
            for (d, other) in cells.iter().enumerate().skip(c + 1) {
                let shared: Vec<usize> = global
                    .iter()
                    .copied()
                    .filter(|g| other.contains(g))
                    .collect();
                if shared.len() != 2 {
                    continue;
                }
                interior_edges += 1;
                let ua = global_function(
                    &argyris,
                    argyris_transformation,
                    vertices,
                    global,
                    global,
                    5,
                );
                let ub = global_function(
                    &argyris,
                    argyris_transformation,
                    cell(d).0,
                    *other,
                    *other,
                    5,
                );
                let (p, q) = (points[shared[0]], points[shared[1]]);
                for s in [0.2, 0.5, 0.9] {
                    let x = [0, 1].map(|k| p[k] + s * (q[k] - p[k]));
                    let (ja, jb) = (ua(x), ub(x));
                    for k in 0..3 {
                        assert!(
                            (ja[k] - jb[k]).abs() < 1e-10 * (1.0 + ja[k].abs()),
                            "cells {c} and {d}, s = {s}, component {k}: {} vs {}",
                            ja[k],
                            jb[k]
                        );
                    }
                }
            }
        }
        // 3 × 3 squares: 12 inner grid edges and 9 diagonals
        assert_eq!(interior_edges, 21);
    }

    #[test]
    fn bad_cells_are_errors() {
        let good = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
        assert_eq!(
            argyris_transformation([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]], [0, 1, 2])
                .map(|_| ())
                .unwrap_err(),
            TransformationError::Degenerate { determinant: 0.0 }
        );
        assert!(matches!(
            morley_transformation(good, [4, 1, 4]),
            Err(TransformationError::RepeatedGlobalVertex { number: 4 })
        ));
        let mut nan = good;
        nan[2][1] = f64::NAN;
        let error = argyris_transformation(nan, [0, 1, 2]).unwrap_err();
        assert_eq!(error, TransformationError::NonFiniteVertex { vertex: 2 });
        assert!(error.to_string().contains("vertex 2"));
        assert!(matches!(
            argyris_transformation([[0.0, 0.0], [1e300, 0.0], [0.0, 1e300]], [0, 1, 2]),
            Err(TransformationError::Degenerate { .. })
        ));
        // a coincident pair of vertices is degenerate, not a division by zero
        assert!(matches!(
            morley_transformation([[0.0, 0.0], [0.0, 0.0], [0.0, 1.0]], [0, 1, 2]),
            Err(TransformationError::Degenerate { .. })
        ));
    }
}
