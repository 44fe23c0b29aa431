//! Generated facet kernels (`∫_Γ … ds`, docs/forms.md) of the Signorini models against
//! kernels written by hand, for u ∈ [P1]² and u ∈ [P2]², on every local edge of random
//! triangles (both orientations): the coupling `b(v;μ) = −∫_Γ_C μ v·n_c ds`, the
//! stabilization `S = ∫_Γ_C h_E (λ + σ_n(u))(μ + σ_n(v)) ds` with `σ_n(u) = n_c·σ(u)n`, the
//! facet part of `B_h`, the
//! load `ℓ(v) = −∫_Γ_N q v·n ds` and `G(μ) = −∫_Γ_C g μ ds`.
//!
//! The hand-coded side uses barycentric formulas for the bases, `σ(φ e_a)` written out
//! entry by entry, the normal from the edge's direction and the cell's centroid, and an
//! independent 4-point Gauss–Legendre rule on the edge.
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]
#![allow(clippy::needless_range_loop)]

use fem_forms::models::signorini::{signorini_p1, signorini_p2};
use fem_forms::Coefficients;

const MU: f64 = 3.7;
const LAMBDA: f64 = 5.3;
const ALPHA: f64 = 0.21;
const Q: f64 = 1.7;
/// The contact direction, a unit vector not along any edge's normal.
const NC: [f64; 2] = [0.6, -0.8];

fn pressure(_x: &[f64]) -> f64 {
    Q
}

fn gap(x: &[f64]) -> f64 {
    0.3 + x[0] - 2.0 * x[1]
}

/// 4-point Gauss–Legendre on [0, 1].
fn gauss4() -> [(f64, f64); 4] {
    let (a, b) = (0.339_981_043_584_856_3, 0.861_136_311_594_052_6);
    let (wa, wb) = (0.652_145_154_862_546_1, 0.347_854_845_137_453_9);
    [(-b, wb), (-a, wa), (a, wa), (b, wb)].map(|(x, w)| (0.5 * (1.0 + x), 0.5 * w))
}

/// A triangle with the barycentric gradients of its vertices.
struct Cell {
    x: [[f64; 2]; 3],
    grad: [[f64; 2]; 3],
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
        Self { x, grad }
    }

    fn flat(&self) -> [f64; 6] {
        [
            self.x[0][0],
            self.x[0][1],
            self.x[1][0],
            self.x[1][1],
            self.x[2][0],
            self.x[2][1],
        ]
    }

    /// Value and gradient of scalar basis function `i` of degree `p` (P2: vertices,
    /// then the midpoints of edges 01, 12, 20) at barycentric point `b`.
    fn basis(&self, p: usize, i: usize, b: [f64; 3]) -> (f64, [f64; 2]) {
        let g = &self.grad;
        if p == 1 {
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

    /// Length and outward unit normal of local edge `e` (vertices `e`, `e + 1`): the
    /// normal is the one pointing away from the opposite vertex.
    fn edge(&self, e: usize) -> (f64, [f64; 2]) {
        let (a, b, c) = (self.x[e], self.x[(e + 1) % 3], self.x[(e + 2) % 3]);
        let t = [b[0] - a[0], b[1] - a[1]];
        let len = t[0].hypot(t[1]);
        let mut n = [t[1] / len, -t[0] / len];
        if (c[0] - a[0]) * n[0] + (c[1] - a[1]) * n[1] > 0.0 {
            n = [-n[0], -n[1]];
        }
        (len, n)
    }

    /// `Σ_q w_q f(b_q, x_q) |E|` over local edge `e`.
    fn integrate_edge(&self, e: usize, f: &dyn Fn([f64; 3], [f64; 2]) -> f64) -> f64 {
        let (len, _) = self.edge(e);
        gauss4()
            .iter()
            .map(|&(s, w)| {
                let mut b = [0.0; 3];
                b[e] = 1.0 - s;
                b[(e + 1) % 3] = s;
                let x = [
                    b[0] * self.x[0][0] + b[1] * self.x[1][0] + b[2] * self.x[2][0],
                    b[0] * self.x[0][1] + b[1] * self.x[1][1] + b[2] * self.x[2][1],
                ];
                w * f(b, x)
            })
            .sum::<f64>()
            * len
    }

    /// `n_c·σ(φ_i e_a)n` with `σ = 2μ ε + λ tr ε I`.
    fn sigma_n(&self, p: usize, i: usize, a: usize, b: [f64; 3], n: [f64; 2]) -> f64 {
        let g = self.basis(p, i, b).1;
        // ε(φ e_a)_kl = ½(δ_ka g_l + δ_la g_k), tr ε = g_a
        let mut s = 0.0;
        for k in 0..2 {
            for l in 0..2 {
                let dk = f64::from(u8::from(k == a));
                let dl = f64::from(u8::from(l == a));
                let eps = 0.5 * (dk * g[l] + dl * g[k]);
                let id = f64::from(u8::from(k == l));
                s += NC[k] * (2.0 * MU * eps + LAMBDA * g[a] * id) * n[l];
            }
        }
        s
    }
}

/// The hand-coded facet blocks on edge `e` of element degree `p`:
/// (b: [a][j], S_uu: [a][b][i][j], S_uλ: [a][i], S_λλ, ℓ: [a][i], G).
struct Hand {
    b: Vec<Vec<f64>>,
    s_uu: Vec<Vec<Vec<Vec<f64>>>>,
    s_ul: Vec<Vec<f64>>,
    s_ll: f64,
    l: Vec<Vec<f64>>,
    g: f64,
}

fn hand(cell: &Cell, p: usize, e: usize) -> Hand {
    let nb = if p == 1 { 3 } else { 6 };
    let (len, n) = cell.edge(e);
    let h = len;
    let b = (0..2)
        .map(|a| {
            (0..nb)
                .map(|j| -cell.integrate_edge(e, &|bc, _| cell.basis(p, j, bc).0 * NC[a]))
                .collect()
        })
        .collect();
    let s_uu = (0..2)
        .map(|a| {
            (0..2)
                .map(|c| {
                    (0..nb)
                        .map(|i| {
                            (0..nb)
                                .map(|j| {
                                    cell.integrate_edge(e, &|bc, _| {
                                        h * cell.sigma_n(p, i, a, bc, n)
                                            * cell.sigma_n(p, j, c, bc, n)
                                    })
                                })
                                .collect()
                        })
                        .collect()
                })
                .collect()
        })
        .collect();
    let s_ul = (0..2)
        .map(|a| {
            (0..nb)
                .map(|i| cell.integrate_edge(e, &|bc, _| h * cell.sigma_n(p, i, a, bc, n)))
                .collect()
        })
        .collect();
    let s_ll = cell.integrate_edge(e, &|_, _| h);
    let l = (0..2)
        .map(|a| {
            (0..nb)
                .map(|i| -cell.integrate_edge(e, &|bc, _| Q * cell.basis(p, i, bc).0 * n[a]))
                .collect()
        })
        .collect();
    let g = -cell.integrate_edge(e, &|_, x| gap(&x));
    Hand {
        b,
        s_uu,
        s_ul,
        s_ll,
        l,
        g,
    }
}

/// Random triangles (a fixed xorshift sequence), of both orientations.
fn cells() -> Vec<Cell> {
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut uniform = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut out = Vec::new();
    while out.len() < 12 {
        let x: [[f64; 2]; 3] =
            std::array::from_fn(|_| [4.0 * uniform() - 2.0, 3.0 * uniform() - 1.0]);
        let signed =
            (x[1][0] - x[0][0]) * (x[2][1] - x[0][1]) - (x[2][0] - x[0][0]) * (x[1][1] - x[0][1]);
        if signed.abs() > 0.1 {
            out.push(Cell::new(x));
        }
    }
    out
}

fn close(a: f64, b: f64, what: &str) {
    assert!(
        (a - b).abs() <= 1e-12 * (1.0 + b.abs()),
        "{what}: generated {a}, hand-coded {b}"
    );
}

/// Checks the kernels of one model (through a macro: the two models are distinct types).
macro_rules! check_model {
    ($model:ident, $p:expr) => {{
        use $model::{b as coupling, data, params, ℓ, B_h, G, S};
        let coefficients = Coefficients::from_ids(
            &[
                (params::μ_L, MU),
                (params::λ_L, LAMBDA),
                (params::α, ALPHA),
                (params::n_c_x, NC[0]),
                (params::n_c_y, NC[1]),
            ],
            &[(data::q, &pressure), (data::g, &gap)],
        )
        .expect("valid coefficients");
        let prm: [f64; 5] = coefficients.params.clone().try_into().unwrap();
        let dat: [&fem_forms::DataFn; 2] = [&pressure, &gap];
        let nb = if $p == 1 { 3 } else { 6 };
        for (c, cell) in cells().iter().enumerate() {
            let x = cell.flat();
            for e in 0..3 {
                let hc = hand(cell, $p, e);
                let at = |what: &str| format!("{what}, cell {c}, edge {e}");
                // b(v;μ): rows μ, columns u_a
                let b = [
                    coupling::on_Γ_C::matrix_μ_u_x(&x, e, &prm, &dat),
                    coupling::on_Γ_C::matrix_μ_u_y(&x, e, &prm, &dat),
                ];
                let s_uu = [
                    [
                        S::on_Γ_C::matrix_v_x_u_x(&x, e, &prm, &dat),
                        S::on_Γ_C::matrix_v_x_u_y(&x, e, &prm, &dat),
                    ],
                    [
                        S::on_Γ_C::matrix_v_y_u_x(&x, e, &prm, &dat),
                        S::on_Γ_C::matrix_v_y_u_y(&x, e, &prm, &dat),
                    ],
                ];
                let s_vl = [
                    S::on_Γ_C::matrix_v_x_λ(&x, e, &prm, &dat),
                    S::on_Γ_C::matrix_v_y_λ(&x, e, &prm, &dat),
                ];
                let s_mu = [
                    S::on_Γ_C::matrix_μ_u_x(&x, e, &prm, &dat),
                    S::on_Γ_C::matrix_μ_u_y(&x, e, &prm, &dat),
                ];
                let s_ll = S::on_Γ_C::matrix_μ_λ(&x, e, &prm, &dat);
                close(s_ll[0][0], hc.s_ll, &at("S (μ, λ)"));
                let bh_ll = B_h::on_Γ_C::matrix_μ_λ(&x, e, &prm, &dat);
                close(bh_ll[0][0], -ALPHA * hc.s_ll, &at("B_h (μ, λ)"));
                let bh_uu = [
                    [
                        B_h::on_Γ_C::matrix_v_x_u_x(&x, e, &prm, &dat),
                        B_h::on_Γ_C::matrix_v_x_u_y(&x, e, &prm, &dat),
                    ],
                    [
                        B_h::on_Γ_C::matrix_v_y_u_x(&x, e, &prm, &dat),
                        B_h::on_Γ_C::matrix_v_y_u_y(&x, e, &prm, &dat),
                    ],
                ];
                let bh_vl = [
                    B_h::on_Γ_C::matrix_v_x_λ(&x, e, &prm, &dat),
                    B_h::on_Γ_C::matrix_v_y_λ(&x, e, &prm, &dat),
                ];
                let bh_mu = [
                    B_h::on_Γ_C::matrix_μ_u_x(&x, e, &prm, &dat),
                    B_h::on_Γ_C::matrix_μ_u_y(&x, e, &prm, &dat),
                ];
                let l = [
                    ℓ::on_Γ_N::vector_v_x(&x, e, &prm, &dat),
                    ℓ::on_Γ_N::vector_v_y(&x, e, &prm, &dat),
                ];
                close(G::on_Γ_C::vector_μ(&x, e, &prm, &dat)[0], hc.g, &at("G"));
                for a in 0..2 {
                    for i in 0..nb {
                        close(b[a][0][i], hc.b[a][i], &at("b"));
                        close(s_vl[a][i][0], hc.s_ul[a][i], &at("S (v, λ)"));
                        close(s_mu[a][0][i], hc.s_ul[a][i], &at("S (μ, u)"));
                        // −b(v;λ) − α S and −b(u;μ) − α S
                        close(
                            bh_vl[a][i][0],
                            -hc.b[a][i] - ALPHA * hc.s_ul[a][i],
                            &at("B_h (v, λ)"),
                        );
                        close(
                            bh_mu[a][0][i],
                            -hc.b[a][i] - ALPHA * hc.s_ul[a][i],
                            &at("B_h (μ, u)"),
                        );
                        close(l[a][i], hc.l[a][i], &at("ℓ"));
                        for c2 in 0..2 {
                            for j in 0..nb {
                                close(s_uu[a][c2][i][j], hc.s_uu[a][c2][i][j], &at("S (v, u)"));
                                close(
                                    bh_uu[a][c2][i][j],
                                    -ALPHA * hc.s_uu[a][c2][i][j],
                                    &at("B_h (v, u) on Γ_C"),
                                );
                            }
                        }
                    }
                }
            }
        }
    }};
}

#[test]
fn p1_facet_kernels_match_hand_coded_ones() {
    check_model!(signorini_p1, 1);
}

#[test]
fn p2_facet_kernels_match_hand_coded_ones() {
    check_model!(signorini_p2, 2);
}

/// The trace of a P1 field on an edge does not see the opposite vertex: the kernels of
/// `b` vanish in the column of the vertex off the edge, and the two others share
/// |E|·n_c,a (here n_c = (0, −1)).
#[test]
fn coupling_sees_only_the_edge() {
    let cell = Cell::new([[0.0, 0.0], [2.0, 0.0], [0.5, 1.5]]);
    let x = cell.flat();
    let prm = [MU, LAMBDA, ALPHA, 0.0, -1.0];
    let dat: [&fem_forms::DataFn; 2] = [&pressure, &gap];
    // edge 0 is the bottom [0,0]–[2,0]: n = (0, −1), |E| = 2
    let k = signorini_p1::b::on_Γ_C::matrix_μ_u_y(&x, 0, &prm, &dat);
    assert_eq!(k[0][2], 0.0);
    close(k[0][0], 1.0, "b, first vertex");
    close(k[0][1], 1.0, "b, second vertex");
}
