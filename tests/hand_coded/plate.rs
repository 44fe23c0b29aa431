//! Element matrices of the Reissner–Mindlin plate (docs/mathematics.md §6) written by
//! hand on one triangle, independent of the form compiler: barycentric formulas for the
//! P1 and P2 bases, the strain `ε(φ e_b)` entry by entry, and Dunavant's degree-4 rule
//! (exact for every integrand here when the data are quadratic).
#![allow(dead_code, clippy::needless_range_loop)]

/// Dunavant's degree-4 rule: barycentric points and weights summing to 1.
pub fn dunavant4() -> Vec<([f64; 3], f64)> {
    let (a, wa) = (0.445948490915965, 0.223381589678011);
    let (b, wb) = (0.091576213509771, 0.109951743655322);
    let mut rule = Vec::new();
    for (p, w) in [(a, wa), (b, wb)] {
        let q = 1.0 - 2.0 * p;
        for point in [[p, p, q], [p, q, p], [q, p, p]] {
            rule.push((point, w));
        }
    }
    rule
}

/// A triangle: vertices, barycentric gradients, area (positive) and diameter.
pub struct Cell {
    pub x: [[f64; 2]; 3],
    pub grad: [[f64; 2]; 3],
    pub area: f64,
    pub h: f64,
}

impl Cell {
    pub fn new(x: [[f64; 2]; 3]) -> Self {
        let signed = 0.5
            * ((x[1][0] - x[0][0]) * (x[2][1] - x[0][1])
                - (x[2][0] - x[0][0]) * (x[1][1] - x[0][1]));
        let grad = std::array::from_fn(|i| {
            let (j, k) = ((i + 1) % 3, (i + 2) % 3);
            [
                (x[j][1] - x[k][1]) / (2.0 * signed),
                (x[k][0] - x[j][0]) / (2.0 * signed),
            ]
        });
        let edge = |i: usize, j: usize| (x[i][0] - x[j][0]).hypot(x[i][1] - x[j][1]);
        let h = edge(0, 1).max(edge(1, 2)).max(edge(2, 0));
        Self {
            x,
            grad,
            area: signed.abs(),
            h,
        }
    }

    pub fn point(&self, b: [f64; 3]) -> [f64; 2] {
        let mut p = [0.0; 2];
        for (bi, xi) in b.iter().zip(&self.x) {
            p[0] += bi * xi[0];
            p[1] += bi * xi[1];
        }
        p
    }

    pub fn integrate(&self, f: &dyn Fn([f64; 3]) -> f64) -> f64 {
        dunavant4().iter().map(|&(b, w)| w * f(b)).sum::<f64>() * self.area
    }

    /// Value and gradient of basis function `i` of the scalar element of degree
    /// `degree` (1: the vertices; 2: the vertices, then the edges 01, 12, 20).
    pub fn basis(&self, degree: usize, i: usize, b: [f64; 3]) -> (f64, [f64; 2]) {
        let g = &self.grad;
        if degree == 1 {
            return (b[i], g[i]);
        }
        if i < 3 {
            let s = 4.0 * b[i] - 1.0;
            (b[i] * (2.0 * b[i] - 1.0), [s * g[i][0], s * g[i][1]])
        } else {
            let (j, k) = [(0, 1), (1, 2), (2, 0)][i - 3];
            (
                4.0 * b[j] * b[k],
                [
                    4.0 * (b[k] * g[j][0] + b[j] * g[k][0]),
                    4.0 * (b[k] * g[j][1] + b[j] * g[k][1]),
                ],
            )
        }
    }
}

/// `ε(φ e_b)` of a P1 function with gradient `g` along axis `b`: `½(δ_kb g_l + δ_lb g_k)`.
pub fn strain(g: [f64; 2], b: usize) -> [[f64; 2]; 2] {
    let delta = |k: usize| if k == b { 1.0 } else { 0.0 };
    std::array::from_fn(|k| std::array::from_fn(|l| 0.5 * (delta(k) * g[l] + delta(l) * g[k])))
}

/// Plate parameters; `shear` is the shear weight of the cell (Stenberg or physical).
#[derive(Clone, Copy, Debug)]
pub struct PlateParams {
    pub d: f64,
    pub nu: f64,
    pub alpha: f64,
    pub s: f64,
}

pub type Matrix = Vec<Vec<f64>>;

pub fn zeros(rows: usize, cols: usize) -> Matrix {
    vec![vec![0.0; cols]; rows]
}

/// The blocks `[test field][trial field]` of
/// `B_h = a_b + a_s − b(v;λ) − b(w;μ) − α Σ h⁴ s²(λ, μ)` on `cell`, fields θ_x, θ_y
/// (P1), w (P1 or P2 by `w_degree`), λ (P0); `shear` the cell's shear weight.
pub fn system_matrix(cell: &Cell, p: PlateParams, shear: f64, w_degree: usize) -> [[Matrix; 4]; 4] {
    let nw = if w_degree == 1 { 3 } else { 6 };
    let dofs = [3, 3, nw, 1];
    let mut k: [[Matrix; 4]; 4] =
        std::array::from_fn(|a| std::array::from_fn(|b| zeros(dofs[a], dofs[b])));
    let g = &cell.grad;
    // bending D[(1−ν) ε(θ):ε(η) + ν div θ div η], constant on the cell
    for a in 0..2 {
        for b in 0..2 {
            for i in 0..3 {
                for j in 0..3 {
                    let (ei, ej) = (strain(g[i], a), strain(g[j], b));
                    let mut contraction = 0.0;
                    for r in 0..2 {
                        for c in 0..2 {
                            contraction += ei[r][c] * ej[r][c];
                        }
                    }
                    k[a][b][i][j] +=
                        cell.area * p.d * ((1.0 - p.nu) * contraction + p.nu * g[i][a] * g[j][b]);
                }
            }
        }
    }
    // shear w_s [∇w·∇v − θ·∇v − ∇w·η + θ·η]
    for i in 0..nw {
        for j in 0..nw {
            k[2][2][i][j] = shear
                * cell.integrate(&|b| {
                    let (gi, gj) = (cell.basis(w_degree, i, b).1, cell.basis(w_degree, j, b).1);
                    gi[0] * gj[0] + gi[1] * gj[1]
                });
        }
    }
    for a in 0..2 {
        for i in 0..3 {
            for j in 0..nw {
                let value = -shear * cell.integrate(&|b| b[i] * cell.basis(w_degree, j, b).1[a]);
                k[2][a][j][i] = value;
                k[a][2][i][j] = value;
            }
            for j in 0..3 {
                k[a][a][i][j] += shear * cell.integrate(&|b| b[i] * b[j]);
            }
        }
    }
    // −b(v;λ) and −b(w;μ): −s ∫ φ_i
    for i in 0..nw {
        let value = -p.s * cell.integrate(&|b| cell.basis(w_degree, i, b).0);
        k[2][3][i][0] = value;
        k[3][2][0][i] = value;
    }
    // −α h⁴ s² (λ, μ): the div div Cε terms vanish for P1 rotations
    k[3][3][0][0] = -p.alpha * cell.h.powi(4) * p.s * p.s * cell.area;
    k
}

/// The blocks of `L_h = ℓ(v) − G(μ) − α ℓ_S(η,μ)`: `∫ f v`, and for μ
/// `−s ∫ ψ + α s h⁴ ∫ f` (the η part of ℓ_S vanishes with `div div Cε(η) ≡ 0`).
pub fn system_vector(
    cell: &Cell,
    p: PlateParams,
    w_degree: usize,
    f: &dyn Fn([f64; 2]) -> f64,
    psi: &dyn Fn([f64; 2]) -> f64,
) -> [Vec<f64>; 4] {
    let nw = if w_degree == 1 { 3 } else { 6 };
    let v = (0..nw)
        .map(|i| cell.integrate(&|b| f(cell.point(b)) * cell.basis(w_degree, i, b).0))
        .collect();
    let f_int = cell.integrate(&|b| f(cell.point(b)));
    let psi_int = cell.integrate(&|b| psi(cell.point(b)));
    let mu = -p.s * psi_int + p.alpha * p.s * cell.h.powi(4) * f_int;
    [vec![0.0; 3], vec![0.0; 3], v, vec![mu]]
}
