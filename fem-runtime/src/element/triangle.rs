//! Finite element functions on triangle meshes: values and gradients on cells and at
//! points, integrals, and errors against exact functions.

use crate::assembly::dof_map::DofMap;
use crate::element::mapping::Affine;
use crate::mesh::triangle::{PointLocator, TriangleMesh};
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
/// `M` is sparse (Argyris: 81 non-zeros of 441), so the products skip its zeros. A cell
/// for which `M` does not exist (degenerate, or a repeated global vertex number) gets NaN
/// entries: kernels cannot return errors, and meshes refuse such cells when built, so
/// this only marks a caller's misuse visibly instead of giving plausible numbers.
pub fn transform_element_matrix<const R: usize, const C: usize>(
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
}

impl TriangleBasis {
    /// The basis of `element` on the reference triangle.
    pub fn new(element: fem_reference::ElementKind) -> Self {
        let values = element.triangle_basis();
        let dx = values.iter().map(|p| p.derivative(1, 0)).collect();
        let dy = values.iter().map(|p| p.derivative(0, 1)).collect();
        let second = [(2, 0), (1, 1), (0, 2)]
            .map(|(i, j)| values.iter().map(|p| p.derivative(i, j)).collect());
        Self {
            values,
            dx,
            dy,
            second,
        }
    }
}

/// The reference basis and its gradient at the points of a rule, evaluated once: the
/// error norms visit every cell at the same reference points, and evaluating the
/// polynomials there anew was most of their cost.
struct Tabulation {
    /// Per point: the basis values, then the ξ- and η-derivatives, `3 × count` numbers.
    rows: Vec<Vec<f64>>,
    count: usize,
}

impl Tabulation {
    fn new(basis: &TriangleBasis, points: &[[f64; 2]]) -> Self {
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
    pub fn errors(&self, exact: &dyn Fn([f64; 2]) -> (f64, [f64; 2]), degree: usize) -> (f64, f64) {
        let basis = TriangleBasis::new(self.map.element());
        let rule = TriangleRule::exact_for_degree(degree);
        let table = Tabulation::new(&basis, &rule.points);
        let (mut l2, mut h1) = (0.0, 0.0);
        let mut local = Vec::new();
        for c in 0..self.mesh.cell_count() {
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
        (l2.sqrt(), h1.sqrt())
    }

    /// `(Σ_T h_T^{2·power} ‖λ − λ_h‖²_T)^{1/2}` against `exact(x)`; `power = 0` is the L² norm.
    pub fn weighted_error(
        &self,
        exact: &dyn Fn([f64; 2]) -> f64,
        power: i32,
        degree: usize,
    ) -> f64 {
        let basis = TriangleBasis::new(self.map.element());
        let rule = TriangleRule::exact_for_degree(degree);
        let table = Tabulation::new(&basis, &rule.points);
        let mut sum = 0.0;
        let mut local = Vec::new();
        for c in 0..self.mesh.cell_count() {
            let map = AffineMap::of(self.mesh, c);
            let weight = self.mesh.cell_diameter(c).powi(2 * power);
            self.local_coefficients(c, &mut local);
            let mut cell = 0.0;
            for (q, (&xi, &w)) in rule.points.iter().zip(&rule.weights).enumerate() {
                let e = exact(map.point(xi)) - table.evaluate(q, &local).0;
                cell += w * map.det * e * e;
            }
            sum += weight * cell;
        }
        sum.sqrt()
    }

    /// The coefficients of cell `c` in the pulled-back reference basis into `out`
    /// ([`TriangleField::reference_coefficients`] without its allocation on the Lagrange
    /// path).
    fn local_coefficients(&self, c: usize, out: &mut Vec<f64>) {
        out.clear();
        match self.transformed(c) {
            Some(u) => out.extend(u),
            None => out.extend(self.map.cell_dofs(c).iter().map(|&d| self.coefficients[d])),
        }
    }

    /// The value at every mesh vertex (the mean over the cells around it for
    /// discontinuous fields).
    pub fn vertex_values(&self) -> Vec<f64> {
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
        let basis = TriangleBasis::new(self.map.element());
        (0..self.mesh.cell_count())
            .map(|c| self.value(&basis, c, [1.0 / 3.0, 1.0 / 3.0]))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fem_reference::ElementKind;

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
}
