//! Generated kernels of a model with a vector field (`θ: [P1]^2`, docs/forms.md) against
//! element matrices written by hand, component by component, on random triangles: the
//! bending form `∫ Cε(θ):ε(η)`, the Stenberg-weighted shear form `∫ w_s (∇w − θ)·(∇v − η)`,
//! the stabilization that P1 rotations reduce to `Σ h⁴ s²(λ, μ)`, and a load with
//! `div η`. The hand-coded side uses barycentric formulas for the P1 and P2 bases, the
//! strain `ε(φ e_b)` written out entry by entry, and an independent 6-point Dunavant rule.
//! Also: rigid motions are the bending kernel's null space, `θ = ∇w` the shear's, and
//! the runtime refuses a non-positive value of a parameter declared `> 0`.
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]
// The hand-coded blocks are written with the indices of the formulas.
#![allow(clippy::needless_range_loop)]

use fem_forms::models::vector_forms::rotation_shear::{self, fields, forms, Model as M};
use fem_forms::{Coefficients, DataFn, Model};

/// The load: a polynomial of degree 2, as the model declares `f`.
fn load(x: &[f64]) -> f64 {
    1.0 + x[0] - 2.0 * x[1] * x[1]
}

/// Dunavant's degree-4 rule: barycentric points and weights summing to 1.
fn dunavant4() -> Vec<([f64; 3], f64)> {
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
struct Cell {
    x: [[f64; 2]; 3],
    grad: [[f64; 2]; 3],
    area: f64,
    h: f64,
}

impl Cell {
    fn new(x: [[f64; 2]; 3]) -> Self {
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

    fn point(&self, b: [f64; 3]) -> [f64; 2] {
        let mut p = [0.0; 2];
        for (bi, xi) in b.iter().zip(&self.x) {
            p[0] += bi * xi[0];
            p[1] += bi * xi[1];
        }
        p
    }

    fn integrate(&self, f: &dyn Fn([f64; 3]) -> f64) -> f64 {
        dunavant4().iter().map(|&(b, w)| w * f(b)).sum::<f64>() * self.area
    }

    /// Value and gradient of P2 basis function `i` (vertices, then edges 01, 12, 20).
    fn p2(&self, i: usize, b: [f64; 3]) -> (f64, [f64; 2]) {
        let g = &self.grad;
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

    /// The P2 nodes: vertices, then the midpoints of edges 01, 12, 20.
    fn p2_nodes(&self) -> [[f64; 2]; 6] {
        let m = |i: usize, j: usize| {
            [
                0.5 * (self.x[i][0] + self.x[j][0]),
                0.5 * (self.x[i][1] + self.x[j][1]),
            ]
        };
        [self.x[0], self.x[1], self.x[2], m(0, 1), m(1, 2), m(2, 0)]
    }
}

/// Parameters in the model's order: D, ν, κ, t, β, s.
#[derive(Clone, Copy, Debug)]
struct Params {
    d: f64,
    nu: f64,
    kappa: f64,
    t: f64,
    beta: f64,
    s: f64,
}

impl Params {
    fn values(self) -> Vec<f64> {
        let c = Coefficients::from_ids(
            &[
                (rotation_shear::params::D, self.d),
                (rotation_shear::params::ν, self.nu),
                (rotation_shear::params::κ, self.kappa),
                (rotation_shear::params::t, self.t),
                (rotation_shear::params::β, self.beta),
                (rotation_shear::params::s, self.s),
            ],
            &[(rotation_shear::data::f, &load)],
        )
        .expect("valid coefficients");
        c.params
    }

    fn shear_weight(self, h: f64) -> f64 {
        6.0 * self.kappa * (1.0 - self.nu) * self.d / (self.t * self.t + self.beta * h * h)
    }
}

type Matrix = Vec<Vec<f64>>;

fn zeros(rows: usize, cols: usize) -> Matrix {
    vec![vec![0.0; cols]; rows]
}

/// Local DOFs per field: θ_x, θ_y (P1), w (P2), λ (P0).
const DOFS: [usize; 4] = [3, 3, 6, 1];

/// `ε(φ e_b)` of a P1 function with gradient `g` along axis `b`: `½(δ_kb g_l + δ_lb g_k)`.
fn strain(g: [f64; 2], b: usize) -> [[f64; 2]; 2] {
    let delta = |k: usize| if k == b { 1.0 } else { 0.0 };
    std::array::from_fn(|k| std::array::from_fn(|l| 0.5 * (delta(k) * g[l] + delta(l) * g[k])))
}

/// The hand-coded blocks `[test field][trial field]` of a bilinear form (zero where the
/// form has none).
fn hand_matrix(form: &str, cell: &Cell, p: Params) -> [[Matrix; 4]; 4] {
    let mut k: [[Matrix; 4]; 4] =
        std::array::from_fn(|a| std::array::from_fn(|b| zeros(DOFS[a], DOFS[b])));
    let g = &cell.grad;
    match form {
        // D[(1−ν) ε(θ):ε(η) + ν div θ div η], constant on the cell
        "a_b" => {
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
                            k[a][b][i][j] = cell.area
                                * p.d
                                * ((1.0 - p.nu) * contraction + p.nu * g[i][a] * g[j][b]);
                        }
                    }
                }
            }
        }
        // w_s [∇w·∇v − θ·∇v − ∇w·η + θ·η]
        "a_s" => {
            let ws = p.shear_weight(cell.h);
            for i in 0..6 {
                for j in 0..6 {
                    k[2][2][i][j] = ws
                        * cell.integrate(&|b| {
                            let (gi, gj) = (cell.p2(i, b).1, cell.p2(j, b).1);
                            gi[0] * gj[0] + gi[1] * gj[1]
                        });
                }
            }
            for a in 0..2 {
                for i in 0..3 {
                    for j in 0..6 {
                        // rows v (P2), columns θ_a (P1): −∫ φ_i ∂_a ψ_j, transposed
                        let value = -ws * cell.integrate(&|b| b[i] * cell.p2(j, b).1[a]);
                        k[2][a][j][i] = value;
                        k[a][2][i][j] = value;
                    }
                    for j in 0..3 {
                        k[a][a][i][j] = ws * cell.integrate(&|b| b[i] * b[j]);
                    }
                }
            }
        }
        // h⁴ (sλ, sμ): the div div terms vanish for P1 rotations
        "S" => k[3][3][0][0] = cell.h.powi(4) * p.s * p.s * cell.area,
        other => panic!("no hand-coded form {other}"),
    }
    k
}

/// The hand-coded blocks of `ℓ(η,v) = ∫ f v + f div η`.
fn hand_vector(cell: &Cell) -> [Vec<f64>; 4] {
    let f_mean = cell.integrate(&|b| load(&cell.point(b)));
    let eta = |a: usize| (0..3).map(|i| cell.grad[i][a] * f_mean).collect();
    let v = (0..6)
        .map(|i| cell.integrate(&|b| load(&cell.point(b)) * cell.p2(i, b).0))
        .collect();
    [eta(0), eta(1), v, vec![0.0]]
}

fn vertices(cell: &Cell) -> Vec<f64> {
    cell.x.iter().flatten().copied().collect()
}

/// The generated blocks of a bilinear form, zero where it has none.
fn generated_matrix(form: &str, cell: &Cell, p: Params) -> [[Matrix; 4]; 4] {
    let f = M::form(form).unwrap();
    let data: [&DataFn; 1] = [&load];
    let params = p.values();
    std::array::from_fn(|a| {
        std::array::from_fn(|b| {
            let mut out = zeros(DOFS[a], DOFS[b]);
            if let Some(block) = M::FORMS[f]
                .blocks
                .iter()
                .position(|x| x.test_field == a && x.trial_field == Some(b))
            {
                let mut flat = vec![0.0; DOFS[a] * DOFS[b]];
                M::element_matrix(f, block, &vertices(cell), &params, &data, &mut flat);
                for (i, row) in out.iter_mut().enumerate() {
                    row.copy_from_slice(&flat[i * DOFS[b]..(i + 1) * DOFS[b]]);
                }
            }
            out
        })
    })
}

fn generated_vector(cell: &Cell, p: Params) -> [Vec<f64>; 4] {
    let f = M::form(forms::ℓ).unwrap();
    let data: [&DataFn; 1] = [&load];
    let params = p.values();
    std::array::from_fn(|a| {
        let mut out = vec![0.0; DOFS[a]];
        if let Some(block) = M::FORMS[f].blocks.iter().position(|x| x.test_field == a) {
            M::element_vector(f, block, &vertices(cell), &params, &data, &mut out);
        }
        out
    })
}

/// A small deterministic generator (xorshift), so that failures reproduce.
struct Random(u64);

impl Random {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }

    /// A triangle of either orientation, not degenerate (area ≥ 1e-2 of its h²).
    fn cell(&mut self) -> Cell {
        loop {
            let x = std::array::from_fn(|_| [self.range(-1.0, 2.0), self.range(-1.0, 2.0)]);
            let cell = Cell::new(x);
            if cell.area > 1e-2 * cell.h * cell.h {
                return cell;
            }
        }
    }

    fn params(&mut self) -> Params {
        Params {
            d: self.range(0.5, 2.0),
            nu: self.range(-0.5, 0.45),
            kappa: 5.0 / 6.0,
            t: 10f64.powf(self.range(-3.0, 0.0)),
            beta: self.range(0.05, 0.3),
            s: if self.next() < 0.5 { -1.0 } else { 1.0 },
        }
    }
}

fn max_abs(m: &Matrix) -> f64 {
    m.iter().flatten().fold(0.0, |a, v| a.max(v.abs()))
}

#[test]
fn the_model_lowers_θ_to_two_scalar_fields() {
    let names: Vec<(&str, &str)> = M::FIELDS.iter().map(|f| (f.name, f.test_name)).collect();
    assert_eq!(
        names,
        [("θ_x", "η_x"), ("θ_y", "η_y"), ("w", "v"), ("λ", "μ")]
    );
    assert_eq!(fields::θ, [fields::θ_x, fields::θ_y]);
    assert_eq!(fields::η, fields::θ);
    assert_eq!(M::field(fields::θ[1]).unwrap(), 1);
    assert_eq!(M::field("η_y").unwrap(), 1);
    // S keeps only the multiplier block: the div div terms of P1 rotations vanish
    let s = &M::FORMS[M::form(forms::S).unwrap()];
    assert_eq!(s.blocks.len(), 1);
    assert_eq!(
        (s.blocks[0].test_field, s.blocks[0].trial_field),
        (3, Some(3))
    );
    assert!(s.dropped_terms > 0);
    // a_b has exactly the four rotation blocks
    let a_b = &M::FORMS[M::form(forms::a_b).unwrap()];
    let pairs: Vec<(usize, Option<usize>)> = a_b
        .blocks
        .iter()
        .map(|b| (b.test_field, b.trial_field))
        .collect();
    assert_eq!(
        pairs,
        [(0, Some(0)), (0, Some(1)), (1, Some(0)), (1, Some(1))]
    );
}

#[test]
fn generated_kernels_match_hand_coded_ones_on_random_triangles() {
    let mut random = Random(0x9e37_79b9_7f4a_7c15);
    for _ in 0..300 {
        let cell = random.cell();
        let p = random.params();
        for form in ["a_b", "a_s", "S"] {
            let (hand, generated) = (
                hand_matrix(form, &cell, p),
                generated_matrix(form, &cell, p),
            );
            let scale = hand.iter().flatten().map(max_abs).fold(0.0, f64::max);
            assert!(scale > 0.0);
            for a in 0..4 {
                for b in 0..4 {
                    for i in 0..DOFS[a] {
                        for j in 0..DOFS[b] {
                            let (x, y) = (generated[a][b][i][j], hand[a][b][i][j]);
                            assert!(
                                (x - y).abs() <= 1e-12 * scale,
                                "{form} block ({a}, {b}) entry ({i}, {j}): generated {x}, by hand {y}, {p:?}, {:?}",
                                cell.x
                            );
                        }
                    }
                }
            }
        }
        let (hand, generated) = (hand_vector(&cell), generated_vector(&cell, p));
        let scale = hand.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        for a in 0..4 {
            for i in 0..DOFS[a] {
                assert!(
                    (generated[a][i] - hand[a][i]).abs() <= 1e-12 * scale,
                    "ℓ block {a} entry {i}: generated {}, by hand {}",
                    generated[a][i],
                    hand[a][i]
                );
            }
        }
    }
}

/// The 6×6 bending matrix on (θ_x, θ_y) from the generated blocks.
fn bending(cell: &Cell, p: Params) -> [[f64; 6]; 6] {
    let k = generated_matrix("a_b", cell, p);
    std::array::from_fn(|r| std::array::from_fn(|c| k[r / 3][c / 3][r % 3][c % 3]))
}

#[test]
fn rigid_motions_are_the_null_space_of_the_bending_kernel() {
    let mut random = Random(0x2545_f491_4f6c_dd1d);
    for _ in 0..100 {
        let cell = random.cell();
        let p = random.params();
        let k = bending(&cell, p);
        let norm = k.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        let apply = |theta: &dyn Fn([f64; 2]) -> [f64; 2]| -> [f64; 6] {
            let nodal: [f64; 6] = std::array::from_fn(|r| theta(cell.x[r % 3])[r / 3]);
            std::array::from_fn(|r| (0..6).map(|c| k[r][c] * nodal[c]).sum())
        };
        // θ = (a − c y, b + c x): ε(θ) = 0
        let (a, b, c) = (
            random.range(-1.0, 1.0),
            random.range(-1.0, 1.0),
            random.range(-1.0, 1.0),
        );
        let rigid = apply(&|x| [a - c * x[1], b + c * x[0]]);
        assert!(
            rigid.iter().all(|v| v.abs() <= 1e-12 * norm),
            "K·rigid = {rigid:?} (|K| = {norm})"
        );
        // θ = (x, 0): ε = e₁e₁ᵀ, tr ε = 1, so θᵀKθ = D·area·((1−ν)·1 + ν·1) = D·area
        let nodal: [f64; 6] = std::array::from_fn(|r| if r < 3 { cell.x[r][0] } else { 0.0 });
        let stretch = apply(&|x| [x[0], 0.0]);
        let energy: f64 = nodal.iter().zip(&stretch).map(|(u, v)| u * v).sum();
        assert!(
            (energy - p.d * cell.area).abs() <= 1e-12 * p.d * cell.area,
            "θᵀKθ = {energy}, D·area = {}",
            p.d * cell.area
        );
    }
}

#[test]
fn rotations_equal_to_the_gradient_are_the_null_space_of_the_shear_kernel() {
    let mut random = Random(0x1234_5678_9abc_def1);
    for _ in 0..100 {
        let cell = random.cell();
        let p = random.params();
        let k = generated_matrix("a_s", &cell, p);
        // w = c₁x² + c₂y + c₃ (in P2) and θ = ∇w = (2c₁x, c₂) (in P1)
        let c: [f64; 3] = std::array::from_fn(|_| random.range(-1.0, 1.0));
        let w: Vec<f64> = cell
            .p2_nodes()
            .iter()
            .map(|x| c[0] * x[0] * x[0] + c[1] * x[1] + c[2])
            .collect();
        let theta = [
            cell.x
                .iter()
                .map(|x| 2.0 * c[0] * x[0])
                .collect::<Vec<f64>>(),
            vec![c[1]; 3],
        ];
        let u = [theta[0].clone(), theta[1].clone(), w, vec![0.0]];
        let scale = k.iter().flatten().map(max_abs).fold(0.0, f64::max);
        for a in 0..3 {
            for i in 0..DOFS[a] {
                let r: f64 = (0..3)
                    .map(|b| (0..DOFS[b]).map(|j| k[a][b][i][j] * u[b][j]).sum::<f64>())
                    .sum();
                assert!(r.abs() <= 1e-11 * scale, "row {a}/{i}: {r} (|K| = {scale})");
            }
        }
    }
}

#[test]
fn a_parameter_declared_positive_is_refused_at_zero_or_below() {
    let values = |beta: f64| {
        Coefficients::new::<M>(
            &[
                ("D", 1.0),
                ("ν", 0.3),
                ("κ", 5.0 / 6.0),
                ("t", 0.01),
                ("β", beta),
                ("s", 1.0),
            ],
            &[("f", &load)],
        )
    };
    assert!(values(0.1).is_ok());
    for beta in [0.0, -0.1] {
        let message = values(beta).err().expect("refused").to_string();
        assert!(
            message.contains("`β`") && message.contains("must be positive"),
            "{message}"
        );
    }
    // ν is not declared positive: a negative Poisson ratio is a value like any other
    assert!(Coefficients::new::<M>(
        &[
            ("D", 1.0),
            ("ν", -0.3),
            ("κ", 5.0 / 6.0),
            ("t", 0.01),
            ("β", 0.1),
            ("s", 1.0)
        ],
        &[("f", &load)],
    )
    .is_ok());
}
