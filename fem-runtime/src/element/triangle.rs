//! Finite element functions on triangle meshes: values and gradients on cells and at
//! points, integrals, and errors against exact functions.

use crate::assembly::dof_map::DofMap;
use crate::element::mapping::Affine;
use crate::mesh::triangle::{PointLocator, TriangleMesh};
use crate::mesh::{CellIter, Cells};
use fem_reference::triangle::{Polynomial2, TriangleRule};

/// A field given by its coefficients on a DOF map of a triangle mesh.
pub struct TriangleField<'a> {
    /// The mesh.
    pub mesh: &'a TriangleMesh,
    /// The field's DOFs.
    pub map: &'a DofMap,
    /// Its coefficients (indexed by the map's DOFs).
    pub coefficients: &'a [f64],
}

/// The affine map of a triangle (see [`crate::element::mapping`]).
pub type AffineMap = Affine<2>;

/// The per-cell DOF transformation `M` of `element` on the triangle with coordinates
/// `x = [x₀, y₀, x₁, y₁, x₂, y₂]` and global vertex numbers `global`
/// (`docs/elements.md` §3): `Ok(None)` for an element that needs none (Lagrange).
///
/// # Errors
/// The reference crate's `TransformationError` (degenerate cell, non-finite coordinate,
/// repeated global vertex number).
pub fn cell_transformation(
    element: fem_reference::ElementKind,
    x: &[f64; 6],
    global: &[usize; 3],
) -> Result<
    Option<fem_reference::dense::Matrix>,
    fem_reference::dof_transformation::TransformationError,
> {
    let vertices = [[x[0], x[1]], [x[2], x[3]], [x[4], x[5]]];
    element.triangle_transformation(vertices, *global)
}

/// The epilogue of a generated kernel with a transformed element: `k ← M_test k M_trialᵀ`
/// (`K = M K̂ Mᵀ`; for a load vector, `trial = None` and `k` has one column: `F = M F̂`),
/// where `k` holds the entries of the pulled-back reference basis `ψ = φ̂ ∘ F⁻¹`.
///
/// `M` is applied in its compact form ([`CompactTransformation`]: only its non-zeros,
/// row operations over whole rows of `k`); the other side as the same left product on
/// the transpose. Agrees with [`transform_element_matrix_dense`] to rounding (tested). A
/// cell for which `M` does not exist (degenerate, or a repeated global vertex number)
/// gets NaN entries: kernels cannot return errors, and meshes refuse such cells when
/// built, so this only marks a caller's misuse visibly instead of giving plausible
/// numbers.
pub fn transform_element_matrix<const R: usize, const C: usize>(
    test: fem_reference::ElementKind,
    trial: Option<fem_reference::ElementKind>,
    x: &[f64; 6],
    global: &[usize; 3],
    k: &mut [[f64; C]; R],
) {
    let compact = |e: fem_reference::ElementKind, dofs: usize| {
        if !e.needs_transformation() {
            Some(None)
        } else {
            CompactTransformation::new(e, x, global)
                .filter(|b| b.dofs() == dofs)
                .map(Some)
        }
    };
    let known = |e: fem_reference::ElementKind| {
        !e.needs_transformation() || CompactTransformation::knows(e)
    };
    if !known(test) || !trial.is_none_or(known) {
        return transform_element_matrix_dense(test, trial, x, global, k);
    }
    let Some(test_b) = compact(test, R) else {
        return poison(k);
    };
    let trial_b = match trial {
        None => None,
        Some(e) => match compact(e, C) {
            Some(b) => b,
            None => return poison(k),
        },
    };
    if let Some(b) = &test_b {
        b.apply_left(k, false);
    }
    if let Some(b) = &trial_b {
        // k M_trialᵀ = (M_trial kᵀ)ᵀ
        let mut t = [[0.0; R]; C];
        for (i, row) in k.iter().enumerate() {
            for (j, &v) in row.iter().enumerate() {
                t[j][i] = v;
            }
        }
        b.apply_left(&mut t, false);
        for (i, row) in k.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = t[j][i];
            }
        }
    }
}

/// [`transform_element_matrix`] for a block of one field against itself whose reference
/// matrix `k = K̂` is symmetric (the code generator decides this from the form's terms):
/// `K = M K̂ Mᵀ = M (M K̂)ᵀ`, so the second product is the same left product on the
/// transpose, computed only on and above the diagonal and mirrored. NaN entries for a
/// cell without `M`, as there; a `k` that is not symmetric gives a wrong result (it is
/// not checked: the kernel's terms are).
pub fn transform_symmetric_element_matrix<const N: usize>(
    element: fem_reference::ElementKind,
    x: &[f64; 6],
    global: &[usize; 3],
    k: &mut [[f64; N]; N],
) {
    if !element.needs_transformation() {
        return;
    }
    if !CompactTransformation::knows(element) {
        return transform_element_matrix_dense(element, Some(element), x, global, k);
    }
    let Some(b) = CompactTransformation::new(element, x, global).filter(|b| b.dofs() == N) else {
        return poison(k);
    };
    b.apply_left(k, false);
    transpose(k);
    b.apply_left(k, true);
    mirror_upper(k);
}

/// `k ← kᵀ` in place.
fn transpose<const N: usize>(k: &mut [[f64; N]; N]) {
    for i in 1..N {
        let (upper, lower) = k.split_at_mut(i);
        for (j, row) in upper.iter_mut().enumerate() {
            std::mem::swap(&mut row[i], &mut lower[0][j]);
        }
    }
}

/// The entries below the diagonal from those above it.
fn mirror_upper<const N: usize>(k: &mut [[f64; N]; N]) {
    for i in 1..N {
        let (upper, lower) = k.split_at_mut(i);
        for (target, row) in lower[0].iter_mut().zip(upper.iter()) {
            *target = row[i];
        }
    }
}

fn poison<const R: usize, const C: usize>(k: &mut [[f64; C]; R]) {
    k.iter_mut().flatten().for_each(|v| *v = f64::NAN);
}

/// The transposed DOF transformation `B = Mᵀ` of an Argyris or Morley cell
/// (`fem_reference::dof_transformation`, `docs/elements.md` §3) by its non-zeros only:
/// per vertex the blocks of the value (1), the gradient (`Jᵀ`) and, for Argyris, the
/// Hessian (`Ĥ_ab = Σ J_ra J_sb H_rs`); per edge the coefficient `α` of its own normal
/// derivative and the coefficients of the Hermite data at its two vertices (the
/// tangential part `β ∂_t`).
///
/// The edge's global orientation only flips the sign of `α`: reversing an edge flips
/// its normal and tangent, hence `α` and `β`, and `β` enters the vertex coefficients only
/// multiplied by the tangent or by the sign of the end (from/to), which flip with it.
/// So the vertex coefficients are computed for the edge oriented from its lower to its
/// higher LOCAL vertex and `α` gets the sign of the global orientation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CompactTransformation {
    argyris: bool,
    /// `J` (`jacobian[row][col]`): the gradient block of vertex DOFs is `Jᵀ`.
    jacobian: [[f64; 2]; 2],
    /// `hessian[r][c]`: reference second derivative `r` (ξξ, ξη, ηη) from physical `c`
    /// (xx, xy, yy).
    hessian: [[f64; 3]; 3],
    /// Per edge: the signed coefficient of its own normal-derivative DOF.
    alpha: [f64; 3],
    /// Per edge and end (lower, higher local vertex): the coefficients of that vertex's
    /// value, gradient and Hessian DOFs (Morley: the value only, index 0).
    ends: [[[f64; 6]; 2]; 3],
}

/// Local vertices of edge `e`, lower first (`fem_reference::dual_basis::EDGES` sorted).
const SORTED_EDGES: [[usize; 2]; 3] = [[0, 1], [1, 2], [0, 2]];

/// Per local vertex: its two edges and its end (0: lower, 1: higher local vertex) in each.
const VERTEX_EDGES: [[(usize, usize); 2]; 3] =
    [[(0, 0), (2, 0)], [(0, 1), (1, 0)], [(1, 1), (2, 1)]];

impl CompactTransformation {
    /// Whether `element` has a compact form here (Argyris, Morley).
    pub fn knows(element: fem_reference::ElementKind) -> bool {
        matches!(
            element,
            fem_reference::ElementKind::Argyris | fem_reference::ElementKind::Morley
        )
    }

    /// `B = Mᵀ` of `element` on the triangle with coordinates
    /// `x = [x₀, y₀, x₁, y₁, x₂, y₂]` and global vertex numbers `global`; `None` for an
    /// element without a compact form, a non-finite or degenerate cell
    /// (`|det J| ≤ 1e-12 · (longest edge)²`, as [`cell_transformation`] refuses) or a
    /// repeated global vertex number.
    pub fn new(
        element: fem_reference::ElementKind,
        x: &[f64; 6],
        global: &[usize; 3],
    ) -> Option<Self> {
        if !Self::knows(element) {
            return None;
        }
        if global[0] == global[1] || global[1] == global[2] || global[0] == global[2] {
            return None;
        }
        let argyris = element == fem_reference::ElementKind::Argyris;
        let j = [[x[2] - x[0], x[4] - x[0]], [x[3] - x[1], x[5] - x[1]]];
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        // The reference normals of `fem_reference::dual_basis::reference_edge_normal`.
        let r = std::f64::consts::FRAC_1_SQRT_2;
        let reference_normals = [[0.0, -1.0], [r, r], [1.0, 0.0]];
        let mut longest = 0.0f64;
        let mut alpha = [0.0; 3];
        let mut ends = [[[0.0; 6]; 2]; 3];
        for (e, [p, q]) in SORTED_EDGES.into_iter().enumerate() {
            let d = [x[2 * q] - x[2 * p], x[2 * q + 1] - x[2 * p + 1]];
            let l2 = d[0] * d[0] + d[1] * d[1];
            longest = longest.max(l2);
            let l = l2.sqrt();
            let t = [d[0] / l, d[1] / l];
            let n = [t[1], -t[0]];
            let nh = reference_normals[e];
            let w = [
                j[0][0] * nh[0] + j[0][1] * nh[1],
                j[1][0] * nh[0] + j[1][1] * nh[1],
            ];
            let (a, beta) = (w[0] * n[0] + w[1] * n[1], w[0] * t[0] + w[1] * t[1]);
            alpha[e] = if global[p] < global[q] { a } else { -a };
            if argyris {
                // β ∂_t f(m) by the Hermite data of the quintic trace (as in
                // `argyris_transformation`): from-end sign −1, to-end +1.
                let tt = [t[0] * t[0], 2.0 * t[0] * t[1], t[1] * t[1]];
                for (end, sign) in [(0, -1.0), (1, 1.0)] {
                    let c = &mut ends[e][end];
                    c[0] = beta * sign * 15.0 / (8.0 * l);
                    c[1] = beta * (-7.0 / 16.0) * t[0];
                    c[2] = beta * (-7.0 / 16.0) * t[1];
                    for (k, &v) in tt.iter().enumerate() {
                        c[3 + k] = beta * sign * l / 32.0 * v;
                    }
                }
            } else {
                // the secant slope of the quadratic trace
                ends[e][0][0] = -beta / l;
                ends[e][1][0] = beta / l;
            }
        }
        if !det.is_finite() || det.abs() <= 1e-12 * longest || !longest.is_finite() {
            return None;
        }
        let mut hessian = [[0.0; 3]; 3];
        for (row, (a, b)) in [(0, 0), (0, 1), (1, 1)].into_iter().enumerate() {
            hessian[row] = [
                j[0][a] * j[0][b],
                j[0][a] * j[1][b] + j[1][a] * j[0][b],
                j[1][a] * j[1][b],
            ];
        }
        Some(Self {
            argyris,
            jacobian: j,
            hessian,
            alpha,
            ends,
        })
    }

    /// Number of local DOFs (21 Argyris, 6 Morley).
    pub fn dofs(&self) -> usize {
        if self.argyris {
            21
        } else {
            6
        }
    }

    /// The entry `M[i][l] = B[l][i]`, through [`apply_left`](Self::apply_left) on the
    /// unit vector `e_l` (for the tests against `cell_transformation`).
    #[cfg(test)]
    fn entry(&self, i: usize, l: usize) -> f64 {
        let mut e = [0.0; 21];
        e[l] = 1.0;
        let mut rows = [[0.0; 1]; 21];
        for (r, v) in rows.iter_mut().zip(e) {
            r[0] = v;
        }
        let n = self.dofs();
        self.apply_left(&mut rows[..n], false);
        rows[i][0]
    }

    /// `rows ← Bᵀ rows = M rows` in place, each row of `rows` a whole vector of the
    /// other index (`rows.len()` must be [`dofs`](Self::dofs), else nothing is done).
    /// With `upper`, the rows of vertex `v`'s DOFs are only computed from column `v`'s
    /// first DOF on and the edge rows from the first edge DOF on: enough for the upper
    /// triangle of a square result (used by [`transform_symmetric_element_matrix`]).
    pub fn apply_left<const C: usize>(&self, rows: &mut [[f64; C]], upper: bool) {
        let n = self.dofs();
        if rows.len() != n {
            return;
        }
        let per_vertex = if self.argyris { 6 } else { 1 };
        let (vertex_rows, edge_rows) = rows.split_at_mut(3 * per_vertex);
        for (v, block) in vertex_rows.chunks_exact_mut(per_vertex).enumerate() {
            let [(ea, sa), (eb, sb)] = VERTEX_EDGES[v];
            let (ra, rb) = (&edge_rows[ea], &edge_rows[eb]);
            let (wa, wb) = (&self.ends[ea][sa], &self.ends[eb][sb]);
            let lo = if upper { per_vertex * v } else { 0 };
            if self.argyris {
                let [[j00, j01], [j10, j11]] = self.jacobian;
                let h = &self.hessian;
                let [b0, b1, b2, b3, b4, b5] = block else {
                    unreachable!("Argyris vertex blocks have six rows")
                };
                for c in lo..C {
                    let (ya, yb) = (ra[c], rb[c]);
                    let (g0, g1) = (b1[c], b2[c]);
                    let (h0, h1, h2) = (b3[c], b4[c], b5[c]);
                    b0[c] += wa[0] * ya + wb[0] * yb;
                    b1[c] = j00 * g0 + j01 * g1 + wa[1] * ya + wb[1] * yb;
                    b2[c] = j10 * g0 + j11 * g1 + wa[2] * ya + wb[2] * yb;
                    b3[c] = h[0][0] * h0 + h[1][0] * h1 + h[2][0] * h2 + wa[3] * ya + wb[3] * yb;
                    b4[c] = h[0][1] * h0 + h[1][1] * h1 + h[2][1] * h2 + wa[4] * ya + wb[4] * yb;
                    b5[c] = h[0][2] * h0 + h[1][2] * h1 + h[2][2] * h2 + wa[5] * ya + wb[5] * yb;
                }
            } else {
                let b0 = &mut block[0];
                for c in lo..C {
                    b0[c] += wa[0] * ra[c] + wb[0] * rb[c];
                }
            }
        }
        let lo = if upper { 3 * per_vertex } else { 0 };
        for (row, &a) in edge_rows.iter_mut().zip(&self.alpha) {
            for v in &mut row[lo..] {
                *v *= a;
            }
        }
    }
}

/// The dense reference of [`transform_element_matrix`]: `k ← M_test k M_trialᵀ` with
/// `M` built by [`cell_transformation`] (a heap matrix), the products skipping its zeros.
/// Slower (it builds the 21 × 21 matrix and tests every entry), kept as the independent
/// check of the compact epilogue and as the fallback for an element that
/// [`CompactTransformation`] does not know.
///
/// `M` is sparse (Argyris: 81 non-zeros of 441). A cell
/// for which `M` does not exist (degenerate, or a repeated global vertex number) gets NaN
/// entries: kernels cannot return errors, and meshes refuse such cells when built, so
/// this only marks a caller's misuse visibly instead of giving plausible numbers.
pub fn transform_element_matrix_dense<const R: usize, const C: usize>(
    test: fem_reference::ElementKind,
    trial: Option<fem_reference::ElementKind>,
    x: &[f64; 6],
    global: &[usize; 3],
    k: &mut [[f64; C]; R],
) {
    let poisoned = |k: &mut [[f64; C]; R]| k.iter_mut().flatten().for_each(|v| *v = f64::NAN);
    let Ok(test_m) = cell_transformation(test, x, global) else {
        return poisoned(k);
    };
    // A block of one field with itself (the usual bilinear form) builds `M` once.
    let other_m = match trial {
        Some(e) if e != test => match cell_transformation(e, x, global) {
            Ok(m) => m,
            Err(_) => return poisoned(k),
        },
        _ => None,
    };
    let trial_m = match trial {
        None => None,
        Some(e) if e == test => test_m.as_ref(),
        Some(_) => other_m.as_ref(),
    };
    if let Some(m) = &test_m {
        let mut out = [[0.0; C]; R];
        for (i, row) in out.iter_mut().enumerate() {
            for (l, &mil) in m.row(i).iter().enumerate() {
                if mil != 0.0 {
                    for (o, &v) in row.iter_mut().zip(&k[l]) {
                        *o += mil * v;
                    }
                }
            }
        }
        *k = out;
    }
    if let Some(m) = trial_m {
        for row in k.iter_mut() {
            let mut out = [0.0; C];
            for (j, o) in out.iter_mut().enumerate() {
                *o = m
                    .row(j)
                    .iter()
                    .zip(row.iter())
                    .filter(|(&mjl, _)| mjl != 0.0)
                    .map(|(&mjl, &v)| mjl * v)
                    .sum();
            }
            *row = out;
        }
    }
}

/// The reference basis of an element with its first and second derivatives.
pub struct TriangleBasis {
    values: Vec<Polynomial2>,
    dx: Vec<Polynomial2>,
    dy: Vec<Polynomial2>,
    /// `∂²/∂ξ², ∂²/∂ξ∂η, ∂²/∂η²` of each basis function.
    second: [Vec<Polynomial2>; 3],
    /// `∂³/∂ξ³, ∂³/∂ξ²∂η, ∂³/∂ξ∂η², ∂³/∂η³` of each basis function.
    third: [Vec<Polynomial2>; 4],
}

impl TriangleBasis {
    /// The basis of `element` on the reference triangle.
    pub fn new(element: fem_reference::ElementKind) -> Self {
        let values = element.triangle_basis();
        let dx = values.iter().map(|p| p.derivative(1, 0)).collect();
        let dy = values.iter().map(|p| p.derivative(0, 1)).collect();
        let second = [(2, 0), (1, 1), (0, 2)]
            .map(|(i, j)| values.iter().map(|p| p.derivative(i, j)).collect());
        let third = [(3, 0), (2, 1), (1, 2), (0, 3)]
            .map(|(i, j)| values.iter().map(|p| p.derivative(i, j)).collect());
        Self {
            values,
            dx,
            dy,
            second,
            third,
        }
    }
}

/// The reference basis and its gradient at the points of a rule, evaluated once: the
/// error norms visit every cell at the same reference points, and evaluating the
/// polynomials there anew was most of their cost.
pub(crate) struct Tabulation {
    /// Per point: the basis values, then the ξ- and η-derivatives, `3 × count` numbers.
    rows: Vec<Vec<f64>>,
    count: usize,
}

impl Tabulation {
    pub(crate) fn new(basis: &TriangleBasis, points: &[[f64; 2]]) -> Self {
        let count = basis.values.len();
        let rows = points
            .iter()
            .map(|&xi| {
                let eval = |ps: &[Polynomial2]| ps.iter().map(|p| p.eval(xi)).collect::<Vec<_>>();
                [eval(&basis.values), eval(&basis.dx), eval(&basis.dy)].concat()
            })
            .collect();
        Self { rows, count }
    }

    /// The value at point `q` of the function with reference coefficients `u`.
    pub(crate) fn value(&self, q: usize, u: &[f64]) -> f64 {
        self.rows[q][..self.count]
            .iter()
            .zip(u)
            .map(|(p, u)| p * u)
            .sum()
    }

    /// The value and reference gradient at point `q` of the function with reference
    /// coefficients `u`.
    fn evaluate(&self, q: usize, u: &[f64]) -> (f64, [f64; 2]) {
        let row = &self.rows[q];
        let n = self.count;
        let (mut value, mut gx, mut gy) = (0.0, 0.0, 0.0);
        for (i, &ui) in u.iter().enumerate().take(n) {
            value += ui * row[i];
            gx += ui * row[n + i];
            gy += ui * row[2 * n + i];
        }
        (value, [gx, gy])
    }
}

impl TriangleField<'_> {
    /// The coefficients of cell `c` in the pulled-back reference basis `ψ_j = φ̂_j ∘ F⁻¹`,
    /// in local order: the field's own local coefficients `U` for Lagrange elements, and
    /// `Mᵀ U` for elements with a DOF transformation `M` (Argyris, Morley), since
    /// `Σ_i U_i φ_i = Σ_j (Mᵀ U)_j ψ_j` (`docs/elements.md` §3). NaN where `M` does not
    /// exist (a degenerate cell, which a validated mesh does not have).
    pub fn reference_coefficients(&self, c: usize) -> Vec<f64> {
        let local: Vec<f64> = self
            .map
            .cell_dofs(c)
            .iter()
            .map(|&d| self.coefficients[d])
            .collect();
        match cell_transformation(
            self.map.element(),
            &self.mesh.cell_coordinates(c),
            &self.mesh.cell(c),
        ) {
            Ok(None) => local,
            Ok(Some(m)) => (0..local.len())
                .map(|j| (0..local.len()).map(|i| m[(i, j)] * local[i]).sum())
                .collect(),
            Err(_) => vec![f64::NAN; local.len()],
        }
    }

    /// The reference coefficients of cell `c` when the element needs a transformation;
    /// `None` on the Lagrange fast path, which reads the coefficients in place.
    fn transformed(&self, c: usize) -> Option<Vec<f64>> {
        self.map
            .element()
            .needs_transformation()
            .then(|| self.reference_coefficients(c))
    }

    /// Value at reference point `ξ` of cell `c`.
    pub fn value(&self, basis: &TriangleBasis, c: usize, xi: [f64; 2]) -> f64 {
        if let Some(u) = self.transformed(c) {
            return u
                .iter()
                .zip(&basis.values)
                .map(|(u, p)| u * p.eval(xi))
                .sum();
        }
        self.map
            .cell_dofs(c)
            .iter()
            .zip(&basis.values)
            .map(|(&d, p)| self.coefficients[d] * p.eval(xi))
            .sum()
    }

    /// Gradient at reference point `ξ` of cell `c`.
    pub fn gradient(
        &self,
        basis: &TriangleBasis,
        map: &AffineMap,
        c: usize,
        xi: [f64; 2],
    ) -> [f64; 2] {
        let mut g = [0.0; 2];
        if let Some(u) = self.transformed(c) {
            for ((u, px), py) in u.iter().zip(&basis.dx).zip(&basis.dy) {
                g[0] += u * px.eval(xi);
                g[1] += u * py.eval(xi);
            }
            return map.gradient(g);
        }
        for ((&d, px), py) in self.map.cell_dofs(c).iter().zip(&basis.dx).zip(&basis.dy) {
            g[0] += self.coefficients[d] * px.eval(xi);
            g[1] += self.coefficients[d] * py.eval(xi);
        }
        map.gradient(g)
    }

    /// Hessian (physical second derivatives) at reference point `ξ` of cell `c`.
    pub fn hessian(
        &self,
        basis: &TriangleBasis,
        map: &AffineMap,
        c: usize,
        xi: [f64; 2],
    ) -> [[f64; 2]; 2] {
        let mut h = [0.0; 3];
        let local = self.transformed(c).unwrap_or_else(|| {
            let dofs = self.map.cell_dofs(c);
            dofs.iter().map(|&d| self.coefficients[d]).collect()
        });
        for (i, u) in local.iter().enumerate() {
            for (k, derivative) in basis.second.iter().enumerate() {
                h[k] += u * derivative[i].eval(xi);
            }
        }
        map.hessian([[h[0], h[1]], [h[1], h[2]]])
    }

    /// The physical third derivatives `D³u_h[i][j][k]` at reference point `ξ` of cell
    /// `c` (zero for elements of degree below 3): a Kirchhoff plate's shear force is
    /// `Q = −D ∇(Δw)`, `(∇Δw)_i = Σ_j D³w[i][j][j]`.
    pub fn third_derivatives(
        &self,
        basis: &TriangleBasis,
        map: &AffineMap,
        c: usize,
        xi: [f64; 2],
    ) -> [[[f64; 2]; 2]; 2] {
        let local = self.transformed(c).unwrap_or_else(|| {
            let dofs = self.map.cell_dofs(c);
            dofs.iter().map(|&d| self.coefficients[d]).collect()
        });
        // ∂ξξξ, ∂ξξη, ∂ξηη, ∂ηηη of the reference function
        let mut t = [0.0; 4];
        for (i, u) in local.iter().enumerate() {
            for (k, derivative) in basis.third.iter().enumerate() {
                t[k] += u * derivative[i].eval(xi);
            }
        }
        let reference = |a: usize, b: usize, d: usize| t[a + b + d];
        // each index mapped to physical coordinates in turn: ∂/∂x = Kᵀ ∂/∂ξ
        let mut out = [[[0.0; 2]; 2]; 2];
        let once: [[[f64; 2]; 2]; 2] = std::array::from_fn(|a| {
            std::array::from_fn(|b| map.gradient([reference(a, b, 0), reference(a, b, 1)]))
        });
        let mut twice = [[[0.0; 2]; 2]; 2];
        for a in 0..2 {
            for k in 0..2 {
                let g = map.gradient([once[a][0][k], once[a][1][k]]);
                for j in 0..2 {
                    twice[a][j][k] = g[j];
                }
            }
        }
        for j in 0..2 {
            for k in 0..2 {
                let g = map.gradient([twice[0][j][k], twice[1][j][k]]);
                for i in 0..2 {
                    out[i][j][k] = g[i];
                }
            }
        }
        out
    }

    /// Value at a physical point, `None` outside the mesh.
    pub fn at(&self, basis: &TriangleBasis, locator: &PointLocator, x: [f64; 2]) -> Option<f64> {
        let (c, b) = locator.locate(x)?;
        Some(self.value(basis, c, [b[1], b[2]]))
    }

    /// `∫ u_h`.
    pub fn integral(&self) -> f64 {
        let basis = TriangleBasis::new(self.map.element());
        let rule = TriangleRule::exact_for_degree(self.map.element().degree());
        (0..self.mesh.cell_count())
            .map(|c| {
                let det = AffineMap::of(self.mesh, c).det;
                rule.integrate(|xi| self.value(&basis, c, xi)) * det
            })
            .sum()
    }

    /// `‖u − u_h‖_{L²}` and `|u − u_h|_{H¹}` against `exact(x) = (u, ∇u)`, with a rule of
    /// degree `degree` on each cell.
    pub fn errors(
        &self,
        exact: &(dyn Fn([f64; 2]) -> (f64, [f64; 2]) + Sync),
        degree: usize,
    ) -> (f64, f64) {
        let (l2, h1) = self.squared_errors(self.all_cells(), exact, degree);
        (l2.sqrt(), h1.sqrt())
    }

    /// Every cell of the field's mesh.
    fn all_cells(&self) -> Cells<'static> {
        Cells::All(self.mesh.cell_count())
    }

    /// `(‖u − u_h‖²_{L²}, |u − u_h|²_{H¹})` of [`TriangleField::errors`] over `cells`
    /// only: one process's share of the squares, which the processes add up.
    pub fn squared_errors(
        &self,
        cells: Cells<'_>,
        exact: &(dyn Fn([f64; 2]) -> (f64, [f64; 2]) + Sync),
        degree: usize,
    ) -> (f64, f64) {
        let basis = TriangleBasis::new(self.map.element());
        let rule = TriangleRule::exact_for_degree(degree);
        let table = Tabulation::new(&basis, &rule.points);
        let squares = over_cell_chunks(cells, |cells| {
            let (mut l2, mut h1) = (0.0, 0.0);
            let mut local = Vec::new();
            for c in cells {
                let map = AffineMap::of(self.mesh, c);
                self.local_coefficients(c, &mut local);
                for (q, (&xi, &w)) in rule.points.iter().zip(&rule.weights).enumerate() {
                    let (u, g) = exact(map.point(xi));
                    let (value, gradient) = table.evaluate(q, &local);
                    let e = u - value;
                    let gh = map.gradient(gradient);
                    l2 += w * map.det * e * e;
                    h1 += w * map.det * ((g[0] - gh[0]).powi(2) + (g[1] - gh[1]).powi(2));
                }
            }
            (l2, h1)
        });
        squares
            .into_iter()
            .fold((0.0, 0.0), |(a, b), (x, y)| (a + x, b + y))
    }

    /// The broken H² seminorm `(Σ_T ∫_T |∇²u − ∇²u_h|²)^{1/2}` (Frobenius norm of the
    /// Hessians) against `exact(x) = ∇²u(x)`, with a rule of degree `degree` on each cell.
    pub fn hessian_error(
        &self,
        exact: &(dyn Fn([f64; 2]) -> [[f64; 2]; 2] + Sync),
        degree: usize,
    ) -> f64 {
        self.squared_hessian_error(self.all_cells(), exact, degree)
            .sqrt()
    }

    /// The square of [`TriangleField::hessian_error`] over `cells` only.
    pub fn squared_hessian_error(
        &self,
        cells: Cells<'_>,
        exact: &(dyn Fn([f64; 2]) -> [[f64; 2]; 2] + Sync),
        degree: usize,
    ) -> f64 {
        let basis = TriangleBasis::new(self.map.element());
        let rule = TriangleRule::exact_for_degree(degree);
        let sums = over_cell_chunks(cells, |cells| {
            let mut sum = 0.0;
            for c in cells {
                let map = AffineMap::of(self.mesh, c);
                for (&xi, &w) in rule.points.iter().zip(&rule.weights) {
                    let h = exact(map.point(xi));
                    let hh = self.hessian(&basis, &map, c, xi);
                    let e: f64 = (0..2)
                        .flat_map(|i| (0..2).map(move |j| (i, j)))
                        .map(|(i, j)| (h[i][j] - hh[i][j]).powi(2))
                        .sum();
                    sum += w * map.det * e;
                }
            }
            sum
        });
        sums.into_iter().sum()
    }

    /// `(Σ_T h_T^{2·power} ‖λ − λ_h‖²_T)^{1/2}` against `exact(x)`; `power = 0` is the L² norm.
    pub fn weighted_error(
        &self,
        exact: &(dyn Fn([f64; 2]) -> f64 + Sync),
        power: i32,
        degree: usize,
    ) -> f64 {
        self.squared_weighted_error(self.all_cells(), exact, power, degree)
            .sqrt()
    }

    /// The square of [`TriangleField::weighted_error`] over `cells` only.
    pub fn squared_weighted_error(
        &self,
        cells: Cells<'_>,
        exact: &(dyn Fn([f64; 2]) -> f64 + Sync),
        power: i32,
        degree: usize,
    ) -> f64 {
        let basis = TriangleBasis::new(self.map.element());
        let rule = TriangleRule::exact_for_degree(degree);
        let table = Tabulation::new(&basis, &rule.points);
        let sums = over_cell_chunks(cells, |cells| {
            let mut sum = 0.0;
            let mut local = Vec::new();
            for c in cells {
                let map = AffineMap::of(self.mesh, c);
                let weight = self.mesh.cell_diameter(c).powi(2 * power);
                self.local_coefficients(c, &mut local);
                let mut cell = 0.0;
                for (q, (&xi, &w)) in rule.points.iter().zip(&rule.weights).enumerate() {
                    let e = exact(map.point(xi)) - table.value(q, &local);
                    cell += w * map.det * e * e;
                }
                sum += weight * cell;
            }
            sum
        });
        sums.into_iter().sum()
    }

    /// The coefficients of cell `c` in the pulled-back reference basis into `out`
    /// ([`TriangleField::reference_coefficients`] without its allocation on the Lagrange
    /// path).
    pub(crate) fn local_coefficients(&self, c: usize, out: &mut Vec<f64>) {
        out.clear();
        match self.transformed(c) {
            Some(u) => out.extend(u),
            None => out.extend(self.map.cell_dofs(c).iter().map(|&d| self.coefficients[d])),
        }
    }

    /// The value at every mesh vertex (the mean over the cells around it for
    /// discontinuous fields).
    pub fn vertex_values(&self) -> Vec<f64> {
        if matches!(
            self.map.element(),
            fem_reference::ElementKind::P1
                | fem_reference::ElementKind::P2
                | fem_reference::ElementKind::P3
        ) {
            // a continuous Lagrange field's vertex DOF is its value there: the evaluation
            // on every cell (six polynomials per corner) took 0.15 s at 2M cells
            return (0..self.mesh.vertex_count())
                .map(|v| self.coefficients[self.map.vertex_dofs(v).start])
                .collect();
        }
        let basis = TriangleBasis::new(self.map.element());
        let mut sum = vec![0.0; self.mesh.vertex_count()];
        let mut count = vec![0usize; self.mesh.vertex_count()];
        let corners = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
        for c in 0..self.mesh.cell_count() {
            for (&v, &xi) in self.mesh.cell(c).iter().zip(&corners) {
                sum[v] += self.value(&basis, c, xi);
                count[v] += 1;
            }
        }
        sum.iter()
            .zip(&count)
            .map(|(s, &n)| s / n.max(1) as f64)
            .collect()
    }

    /// The value at every cell's centroid (its mean for P0 and P1 fields).
    pub fn centroid_values(&self) -> Vec<f64> {
        if self.map.element() == fem_reference::ElementKind::P0 {
            // the cell's one coefficient, without evaluating its basis
            return (0..self.mesh.cell_count())
                .map(|c| self.coefficients[self.map.cell_dofs(c)[0]])
                .collect();
        }
        let basis = TriangleBasis::new(self.map.element());
        (0..self.mesh.cell_count())
            .map(|c| self.value(&basis, c, [1.0 / 3.0, 1.0 / 3.0]))
            .collect()
    }
}

/// Cells per chunk of [`over_cell_chunks`]: large enough that a chunk's work outweighs
/// rayon's scheduling, small enough to balance two threads on 100k-cell meshes.
const CELL_CHUNK: usize = 4096;

/// `work` on consecutive runs of [`CELL_CHUNK`] of `cells`, on rayon's threads, and the
/// results in the order of the runs: a sum over them in that order is the same on any
/// number of threads.
pub fn over_cell_chunks<T: Send>(
    cells: Cells<'_>,
    work: impl Fn(CellIter<'_>) -> T + Sync,
) -> Vec<T> {
    use rayon::prelude::*;
    let count = cells.len();
    (0..count.div_ceil(CELL_CHUNK))
        .into_par_iter()
        .map(|k| work(cells.slice(k * CELL_CHUNK..((k + 1) * CELL_CHUNK).min(count))))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use fem_reference::ElementKind;

    /// xorshift64*: reproducible pseudo-random numbers in `[-1, 1)`.
    struct Random(u64);

    impl Random {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            let bits = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11;
            2.0 * (bits as f64 / (1u64 << 53) as f64) - 1.0
        }

        /// Vertex coordinates of a non-degenerate triangle of size about `scale`, in
        /// either orientation.
        fn triangle(&mut self, scale: f64) -> [f64; 6] {
            loop {
                let x: [f64; 6] = std::array::from_fn(|_| scale * self.next());
                let det = (x[2] - x[0]) * (x[5] - x[1]) - (x[4] - x[0]) * (x[3] - x[1]);
                if det.abs() > 0.3 * scale * scale {
                    return x;
                }
            }
        }

        fn matrix<const R: usize, const C: usize>(&mut self) -> [[f64; C]; R] {
            std::array::from_fn(|_| std::array::from_fn(|_| self.next()))
        }
    }

    /// Global numberings giving every edge orientation pattern.
    const NUMBERINGS: [[usize; 3]; 6] = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [20, 3, 11],
    ];

    fn assert_close<const R: usize, const C: usize>(
        got: &[[f64; C]; R],
        want: &[[f64; C]; R],
        what: &str,
    ) {
        let scale = want.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        for (i, (g, w)) in got.iter().zip(want).enumerate() {
            for (j, (g, w)) in g.iter().zip(w).enumerate() {
                assert!(
                    (g - w).abs() <= 1e-13 * scale,
                    "{what}: entry ({i}, {j}) {g} vs {w} (scale {scale})"
                );
            }
        }
    }

    /// The compact `M` is the matrix of `cell_transformation`, entry by entry, for every
    /// edge orientation.
    #[test]
    fn compact_transformation_is_the_reference_matrix() {
        let mut random = Random(99);
        for element in [ElementKind::Argyris, ElementKind::Morley] {
            for (n, global) in NUMBERINGS.iter().enumerate() {
                let x = random.triangle([1.0, 0.01, 30.0][n % 3]);
                let m = cell_transformation(element, &x, global).unwrap().unwrap();
                let b = CompactTransformation::new(element, &x, global).unwrap();
                let size = b.dofs();
                assert_eq!(size, m.row(0).len());
                let scale = (0..size)
                    .flat_map(|i| m.row(i).to_vec())
                    .fold(0.0f64, |a, v| a.max(v.abs()));
                for i in 0..size {
                    for l in 0..size {
                        let (got, want) = (b.entry(i, l), m[(i, l)]);
                        assert!(
                            (got - want).abs() <= 1e-14 * scale,
                            "{element:?} {global:?}: M[{i}][{l}] = {got}, reference {want}"
                        );
                    }
                }
            }
        }
    }

    /// The compact epilogue agrees with the dense reference on random reference matrices:
    /// both sides transformed, one side (a mixed block with P0 or P1disc, a load vector),
    /// and the symmetric variant on a symmetric `K̂`.
    #[test]
    fn compact_epilogue_agrees_with_the_dense_reference() {
        let mut random = Random(5);
        let (a, m) = (ElementKind::Argyris, ElementKind::Morley);
        for (n, global) in NUMBERINGS.iter().enumerate() {
            let x = random.triangle([1.0, 0.05, 7.0][n % 3]);
            {
                let k0: [[f64; 21]; 21] = random.matrix();
                let (mut got, mut want) = (k0, k0);
                transform_element_matrix(a, Some(a), &x, global, &mut got);
                transform_element_matrix_dense(a, Some(a), &x, global, &mut want);
                assert_close(&got, &want, "Argyris × Argyris");
                let symmetric: [[f64; 21]; 21] =
                    std::array::from_fn(|i| std::array::from_fn(|j| k0[i.min(j)][i.max(j)]));
                let (mut got, mut want) = (symmetric, symmetric);
                transform_symmetric_element_matrix(a, &x, global, &mut got);
                transform_element_matrix_dense(a, Some(a), &x, global, &mut want);
                assert_close(&got, &want, "symmetric Argyris");
            }
            let k0: [[f64; 6]; 6] = random.matrix();
            let (mut got, mut want) = (k0, k0);
            transform_element_matrix(m, Some(m), &x, global, &mut got);
            transform_element_matrix_dense(m, Some(m), &x, global, &mut want);
            assert_close(&got, &want, "Morley × Morley");
            let symmetric: [[f64; 6]; 6] =
                std::array::from_fn(|i| std::array::from_fn(|j| k0[i.min(j)][i.max(j)]));
            let (mut got, mut want) = (symmetric, symmetric);
            transform_symmetric_element_matrix(m, &x, global, &mut got);
            transform_element_matrix_dense(m, Some(m), &x, global, &mut want);
            assert_close(&got, &want, "symmetric Morley");
            let k0: [[f64; 3]; 21] = random.matrix();
            let (mut got, mut want) = (k0, k0);
            transform_element_matrix(a, Some(ElementKind::P1Disc), &x, global, &mut got);
            transform_element_matrix_dense(a, Some(ElementKind::P1Disc), &x, global, &mut want);
            assert_close(&got, &want, "Argyris × P1disc");
            let k0: [[f64; 21]; 1] = random.matrix();
            let (mut got, mut want) = (k0, k0);
            transform_element_matrix(ElementKind::P0, Some(a), &x, global, &mut got);
            transform_element_matrix_dense(ElementKind::P0, Some(a), &x, global, &mut want);
            assert_close(&got, &want, "P0 × Argyris");
            let k0: [[f64; 1]; 6] = random.matrix();
            let (mut got, mut want) = (k0, k0);
            transform_element_matrix(m, None, &x, global, &mut got);
            transform_element_matrix_dense(m, None, &x, global, &mut want);
            assert_close(&got, &want, "Morley load vector");
            let k0: [[f64; 6]; 21] = random.matrix();
            let (mut got, mut want) = (k0, k0);
            transform_element_matrix(a, Some(m), &x, global, &mut got);
            transform_element_matrix_dense(a, Some(m), &x, global, &mut want);
            assert_close(&got, &want, "Argyris × Morley");
        }
    }

    /// Cells without `M` get NaN from both epilogues, and a Lagrange block is untouched.
    #[test]
    fn cells_without_a_transformation_are_poisoned() {
        let flat = [0.0, 0.0, 1.0, 1.0, 2.0, 2.0];
        let good = [0.0, 0.0, 1.0, 0.0, 0.0, 1.0];
        let a = ElementKind::Argyris;
        let mut k = [[1.0; 21]; 21];
        transform_symmetric_element_matrix(a, &flat, &[0, 1, 2], &mut k);
        assert!(k.iter().flatten().all(|v| v.is_nan()));
        let mut k = [[1.0; 21]; 21];
        transform_element_matrix(a, Some(a), &good, &[4, 1, 4], &mut k);
        assert!(k.iter().flatten().all(|v| v.is_nan()));
        let mut k = [[1.0; 6]; 6];
        let nan = [0.0, 0.0, f64::NAN, 0.0, 0.0, 1.0];
        transform_element_matrix(ElementKind::Morley, None, &nan, &[0, 1, 2], &mut k);
        assert!(k.iter().flatten().all(|v| v.is_nan()));
        let mut k = [[1.0; 3]; 3];
        transform_element_matrix(
            ElementKind::P1,
            Some(ElementKind::P1),
            &flat,
            &[0, 1, 2],
            &mut k,
        );
        assert_eq!(k, [[1.0; 3]; 3]);
    }

    /// A P2 field interpolating `u = x² + 3xy − y²` is `u` itself: its gradient and
    /// Hessian at any point of any cell of a curved-boundary (disk) mesh are exact.
    #[test]
    fn p2_field_reproduces_derivatives_of_a_quadratic() {
        let mesh = TriangleMesh::disk([0.3, -0.1], 1.5, 3).unwrap();
        let map = DofMap::on_triangles(&mesh, ElementKind::P2);
        let coefficients: Vec<f64> = map
            .nodes(&mesh)
            .iter()
            .map(|&[x, y]| x * x + 3.0 * x * y - y * y)
            .collect();
        let field = TriangleField {
            mesh: &mesh,
            map: &map,
            coefficients: &coefficients,
        };
        let basis = TriangleBasis::new(ElementKind::P2);
        for c in 0..mesh.cell_count() {
            let affine = AffineMap::of(&mesh, c);
            let xi = [0.21, 0.37];
            let [x, y] = affine.point(xi);
            let g = field.gradient(&basis, &affine, c, xi);
            let h = field.hessian(&basis, &affine, c, xi);
            assert!((g[0] - (2.0 * x + 3.0 * y)).abs() < 1e-11, "{g:?}");
            assert!((g[1] - (3.0 * x - 2.0 * y)).abs() < 1e-11, "{g:?}");
            let exact = [[2.0, 3.0], [3.0, -2.0]];
            for r in 0..2 {
                for s in 0..2 {
                    assert!((h[r][s] - exact[r][s]).abs() < 1e-9, "cell {c}: {h:?}");
                }
            }
        }
    }

    /// A P3 field interpolating `u = x³ + 2x²y − xy² + 3y³` has its third derivatives at
    /// any point of any cell of a disk mesh: the map of each index to physical
    /// coordinates.
    #[test]
    fn p3_field_reproduces_third_derivatives_of_a_cubic() {
        let mesh = TriangleMesh::disk([0.3, -0.1], 1.5, 3).unwrap();
        let map = DofMap::on_triangles(&mesh, ElementKind::P3);
        let coefficients: Vec<f64> = map
            .nodes(&mesh)
            .iter()
            .map(|&[x, y]| x * x * x + 2.0 * x * x * y - x * y * y + 3.0 * y * y * y)
            .collect();
        let field = TriangleField {
            mesh: &mesh,
            map: &map,
            coefficients: &coefficients,
        };
        let basis = TriangleBasis::new(ElementKind::P3);
        // u_xxx = 6, u_xxy = 4, u_xyy = −2, u_yyy = 18
        let exact = [[[6.0, 4.0], [4.0, -2.0]], [[4.0, -2.0], [-2.0, 18.0]]];
        for c in 0..mesh.cell_count() {
            let affine = AffineMap::of(&mesh, c);
            let d3 = field.third_derivatives(&basis, &affine, c, [0.21, 0.37]);
            for i in 0..2 {
                for j in 0..2 {
                    for k in 0..2 {
                        let e = (d3[i][j][k] - exact[i][j][k]).abs();
                        assert!(e < 1e-7, "cell {c}: {d3:?}");
                    }
                }
            }
        }
    }

    /// The Lagrange fast path of `vertex_values` (the vertex DOF) gives the value that
    /// evaluating the field at each cell's corners gives, for random coefficients on a
    /// disk mesh, P1 to P3.
    #[test]
    fn lagrange_vertex_values_are_the_corner_values() {
        let mesh = TriangleMesh::disk([0.3, -0.1], 1.5, 3).unwrap();
        let mut random = Random(0x9e37_79b9_7f4a_7c15);
        for element in [ElementKind::P1, ElementKind::P2, ElementKind::P3] {
            let map = DofMap::on_triangles(&mesh, element);
            let coefficients: Vec<f64> = (0..map.dof_count()).map(|_| random.next()).collect();
            let field = TriangleField {
                mesh: &mesh,
                map: &map,
                coefficients: &coefficients,
            };
            let values = field.vertex_values();
            let basis = TriangleBasis::new(element);
            let corners = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
            for c in 0..mesh.cell_count() {
                for (&v, &xi) in mesh.cell(c).iter().zip(&corners) {
                    let corner = field.value(&basis, c, xi);
                    assert!(
                        (values[v] - corner).abs() < 1e-13,
                        "{element:?}, vertex {v}: {} against {corner}",
                        values[v]
                    );
                }
            }
        }
    }

    /// The P0 fast path of `centroid_values` (the cell's coefficient) gives the value at
    /// the centroid.
    #[test]
    fn p0_centroid_values_are_the_cell_values() {
        let mesh = TriangleMesh::disk([0.3, -0.1], 1.5, 3).unwrap();
        let map = DofMap::on_triangles(&mesh, ElementKind::P0);
        let mut random = Random(0x2545_f491_4f6c_dd1d);
        let coefficients: Vec<f64> = (0..map.dof_count()).map(|_| random.next()).collect();
        let field = TriangleField {
            mesh: &mesh,
            map: &map,
            coefficients: &coefficients,
        };
        let basis = TriangleBasis::new(ElementKind::P0);
        for (c, value) in field.centroid_values().into_iter().enumerate() {
            assert_eq!(
                value,
                field.value(&basis, c, [1.0 / 3.0, 1.0 / 3.0]),
                "cell {c}"
            );
        }
    }
}
