//! Generated triangle kernels of the membrane models against hand-coded element
//! matrices written with barycentric coordinates (an independent basis: `λᵢ(2λᵢ − 1)`,
//! `4λᵢλⱼ`, their gradients and Laplacians by hand) and an independent 6-point
//! Dunavant rule, on random triangles and parameters.
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

use fem_forms::model::FormId;
use fem_forms::models::{membrane_p1_p0, membrane_p2_p0, membrane_p2_p1disc};
use fem_forms::{DataFn, ElementKind, Model};
use proptest::prelude::*;

fn load(x: &[f64]) -> f64 {
    1.0 + x[0] - 2.0 * x[1] * x[1]
}

fn obstacle(x: &[f64]) -> f64 {
    x[0] * x[1] - 0.3 + 0.5 * x[0] * x[0]
}

fn boundary(_: &[f64]) -> f64 {
    0.0
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

/// A triangle with its barycentric gradients, area and diameter.
#[derive(Debug)]
struct Cell {
    x: [[f64; 2]; 3],
    grad: [[f64; 2]; 3],
    area: f64,
    h: f64,
}

impl Cell {
    fn new(x: [[f64; 2]; 3]) -> Self {
        let area = 0.5
            * ((x[1][0] - x[0][0]) * (x[2][1] - x[0][1])
                - (x[2][0] - x[0][0]) * (x[1][1] - x[0][1]));
        let grad = std::array::from_fn(|i| {
            let (j, k) = ((i + 1) % 3, (i + 2) % 3);
            [
                (x[j][1] - x[k][1]) / (2.0 * area),
                (x[k][0] - x[j][0]) / (2.0 * area),
            ]
        });
        let edge = |i: usize, j: usize| (x[i][0] - x[j][0]).hypot(x[i][1] - x[j][1]);
        let h = edge(0, 1).max(edge(1, 2)).max(edge(2, 0));
        Self { x, grad, area, h }
    }

    fn point(&self, b: [f64; 3]) -> [f64; 2] {
        let mut p = [0.0; 2];
        for (bi, xi) in b.iter().zip(&self.x) {
            p[0] += bi * xi[0];
            p[1] += bi * xi[1];
        }
        p
    }
}

fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// Value, gradient and Laplacian of local basis function `i` at barycentric point `b`.
fn basis(element: ElementKind, cell: &Cell, i: usize, b: [f64; 3]) -> (f64, [f64; 2], f64) {
    let g = &cell.grad;
    let edges = [(0, 1), (1, 2), (2, 0)];
    match element {
        ElementKind::P0 => (1.0, [0.0; 2], 0.0),
        ElementKind::P1 | ElementKind::P1Disc => (b[i], g[i], 0.0),
        ElementKind::P2 if i < 3 => (
            b[i] * (2.0 * b[i] - 1.0),
            [(4.0 * b[i] - 1.0) * g[i][0], (4.0 * b[i] - 1.0) * g[i][1]],
            4.0 * dot(g[i], g[i]),
        ),
        ElementKind::P2 => {
            let (j, k) = edges[i - 3];
            (
                4.0 * b[j] * b[k],
                [
                    4.0 * (b[k] * g[j][0] + b[j] * g[k][0]),
                    4.0 * (b[k] * g[j][1] + b[j] * g[k][1]),
                ],
                8.0 * dot(g[j], g[k]),
            )
        }
        other => panic!("no hand-coded {other:?}"),
    }
}

fn count(element: ElementKind) -> usize {
    match element {
        ElementKind::P0 => 1,
        ElementKind::P1 | ElementKind::P1Disc => 3,
        _ => 6,
    }
}

/// The blocks of `B_h` (test field, trial field) and `L_h` (test field) by hand.
fn hand_b_h(u: ElementKind, l: ElementKind, cell: &Cell, alpha: f64) -> [Vec<Vec<f64>>; 4] {
    let h2 = cell.h * cell.h;
    let integrate = |f: &dyn Fn([f64; 3]) -> f64| -> f64 {
        dunavant4().iter().map(|&(b, w)| w * f(b)).sum::<f64>() * cell.area
    };
    let block =
        |rows: ElementKind, cols: ElementKind, k: &dyn Fn(usize, usize, [f64; 3]) -> f64| {
            (0..count(rows))
                .map(|i| {
                    (0..count(cols))
                        .map(|j| integrate(&|b| k(i, j, b)))
                        .collect()
                })
                .collect::<Vec<Vec<f64>>>()
        };
    let uu = block(u, u, &|i, j, b| {
        let (_, gi, li) = basis(u, cell, i, b);
        let (_, gj, lj) = basis(u, cell, j, b);
        dot(gi, gj) - alpha * h2 * li * lj
    });
    // rows v, columns λ: −(λ, v) − αh²(λ, Δv)
    let ul = block(u, l, &|i, j, b| {
        let (vi, _, li) = basis(u, cell, i, b);
        let (mj, _, _) = basis(l, cell, j, b);
        -mj * vi - alpha * h2 * mj * li
    });
    let lu = block(l, u, &|i, j, b| {
        let (mi, _, _) = basis(l, cell, i, b);
        let (vj, _, lj) = basis(u, cell, j, b);
        -vj * mi - alpha * h2 * lj * mi
    });
    let ll = block(l, l, &|i, j, b| {
        let (mi, _, _) = basis(l, cell, i, b);
        let (mj, _, _) = basis(l, cell, j, b);
        -alpha * h2 * mi * mj
    });
    [uu, ul, lu, ll]
}

fn hand_l_h(u: ElementKind, l: ElementKind, cell: &Cell, alpha: f64) -> [Vec<f64>; 2] {
    let h2 = cell.h * cell.h;
    let integrate = |f: &dyn Fn([f64; 3]) -> f64| -> f64 {
        dunavant4().iter().map(|&(b, w)| w * f(b)).sum::<f64>() * cell.area
    };
    let v = (0..count(u))
        .map(|i| {
            integrate(&|b| {
                let (vi, _, li) = basis(u, cell, i, b);
                let f = load(&cell.point(b));
                f * vi + alpha * h2 * f * li
            })
        })
        .collect();
    let mu = (0..count(l))
        .map(|i| {
            integrate(&|b| {
                let (mi, _, _) = basis(l, cell, i, b);
                let x = cell.point(b);
                -obstacle(&x) * mi + alpha * h2 * load(&x) * mi
            })
        })
        .collect();
    [v, mu]
}

/// The model's `B_h` and `L_h`, by typed handle.
type Forms<M> = (FormId<M>, FormId<M>);

fn generated<M: Model>(
    cell: &Cell,
    alpha: f64,
    (bilinear, linear): Forms<M>,
) -> ([Vec<Vec<f64>>; 4], [Vec<f64>; 2]) {
    let x: Vec<f64> = cell.x.iter().flatten().copied().collect();
    let data: [&DataFn; 3] = [&load, &obstacle, &boundary];
    let params = [alpha];
    let form = M::form(bilinear).unwrap();
    let n = |f: usize| M::FIELDS[f].element.local_dof_count(M::CELL);
    let pairs = [(0, 0), (0, 1), (1, 0), (1, 1)];
    let blocks = pairs.map(|(test, trial)| {
        let (rows, cols) = (n(test), n(trial));
        let mut flat = vec![0.0; rows * cols];
        if let Some(b) = M::FORMS[form]
            .blocks
            .iter()
            .position(|b| b.test_field == test && b.trial_field == Some(trial))
        {
            M::element_matrix(form, b, &x, &params, &data, &mut flat);
        }
        flat.chunks(cols).map(<[f64]>::to_vec).collect::<Vec<_>>()
    });
    let form = M::form(linear).unwrap();
    let vectors = [0, 1].map(|test| {
        let mut out = vec![0.0; n(test)];
        if let Some(b) = M::FORMS[form]
            .blocks
            .iter()
            .position(|b| b.test_field == test)
        {
            M::element_vector(form, b, &x, &params, &data, &mut out);
        }
        out
    });
    (blocks, vectors)
}

fn largest_difference(a: &[Vec<f64>], b: &[Vec<f64>]) -> f64 {
    let scale = b.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    let diff = a
        .iter()
        .flatten()
        .zip(b.iter().flatten())
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    diff / scale.max(1e-300)
}

fn check<M: Model>(cell: &Cell, alpha: f64, forms: Forms<M>) {
    let u = M::FIELDS[0].element;
    let l = M::FIELDS[1].element;
    let (blocks, vectors) = generated(cell, alpha, forms);
    let hand = hand_b_h(u, l, cell, alpha);
    for (k, (g, h)) in blocks.iter().zip(&hand).enumerate() {
        let d = largest_difference(g, h);
        assert!(
            d < 1e-11,
            "{} block {k}: relative difference {d:e}",
            M::NAME
        );
    }
    let hand = hand_l_h(u, l, cell, alpha);
    for (k, (g, h)) in vectors.iter().zip(&hand).enumerate() {
        let d = largest_difference(std::slice::from_ref(g), std::slice::from_ref(h));
        assert!(
            d < 1e-11,
            "{} vector {k}: relative difference {d:e}",
            M::NAME
        );
    }
}

fn triangle() -> impl Strategy<Value = Cell> {
    (
        -3.0..3.0f64,
        -3.0..3.0f64,
        0.05..2.0f64,
        0.0..std::f64::consts::TAU,
        0.2..1.0f64,
        0.3..2.8f64,
    )
        .prop_map(|(x0, y0, size, turn, ratio, angle)| {
            let (c, s) = (turn.cos(), turn.sin());
            let a = [x0, y0];
            let b = [x0 + size * c, y0 + size * s];
            let r = size * ratio;
            let d = [
                x0 + r * (c * angle.cos() - s * angle.sin()),
                y0 + r * (s * angle.cos() + c * angle.sin()),
            ];
            Cell::new([a, b, d])
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn membrane_kernels_match_the_hand_coded_ones(cell in triangle(), alpha in 0.0..2.0f64) {
        check(&cell, alpha, (membrane_p1_p0::forms::B_h, membrane_p1_p0::forms::L_h));
        check(&cell, alpha, (membrane_p2_p0::forms::B_h, membrane_p2_p0::forms::L_h));
        check(&cell, alpha, (membrane_p2_p1disc::forms::B_h, membrane_p2_p1disc::forms::L_h));
    }
}

/// The check catches a wrong sign: flipping α in the hand-coded S must be seen.
#[test]
fn a_sign_error_is_caught() {
    let cell = Cell::new([[0.1, 0.2], [1.3, 0.1], [0.4, 0.9]]);
    let (blocks, _) = generated(
        &cell,
        0.7,
        (membrane_p2_p0::forms::B_h, membrane_p2_p0::forms::L_h),
    );
    let wrong = hand_b_h(ElementKind::P2, ElementKind::P0, &cell, -0.7);
    assert!(largest_difference(&blocks[0], &wrong[0]) > 1e-3);
}

/// The typed handles name the same indices as the strings a scene file uses, and the
/// two ways of giving coefficients agree.
#[test]
fn handles_and_names_agree() {
    use fem_forms::model::{DataId, FormId};
    use fem_forms::Coefficients;
    use membrane_p2_p0::{data, fields, forms, params};
    type M = membrane_p2_p0::Model;
    for (name, id) in [
        ("a", forms::a),
        ("ℓ_S", forms::ℓ_S),
        ("B_h", forms::B_h),
        ("L_h", forms::L_h),
    ] {
        assert_eq!(M::form(id).unwrap(), M::form(name).unwrap(), "{name}");
        assert_eq!(M::FORMS[id.index()].name, name);
    }
    assert_eq!(M::field(fields::u).unwrap(), 0);
    assert_eq!(M::field(fields::v).unwrap(), M::field("u").unwrap());
    assert_eq!(M::field(fields::μ).unwrap(), M::field("λ").unwrap());
    assert_eq!(M::param(params::α).unwrap(), M::param("α").unwrap());
    assert_eq!(M::data_function(data::g).unwrap(), 2);
    // a hand-made handle out of range is an error, not a panic
    assert!(M::form(FormId::<M>::new(99)).is_err());
    assert!(M::data_function(DataId::<M>::new(3)).is_err());
    assert!(M::form("B").is_err());

    let by_id = Coefficients::from_ids(
        &[(params::α, 0.25)],
        &[(data::g, &boundary), (data::f, &load), (data::ψ, &obstacle)],
    )
    .unwrap();
    let by_name = Coefficients::new::<M>(
        &[("α", 0.25)],
        &[("f", &load), ("ψ", &obstacle), ("g", &boundary)],
    )
    .unwrap();
    assert_eq!(by_id.params, by_name.params);
    let x = [0.3, -0.7];
    for (a, b) in by_id.data.iter().zip(&by_name.data) {
        assert_eq!(a(&x), b(&x));
    }
    // checks still apply: a handle given twice, a missing one, a non-finite value
    assert!(Coefficients::from_ids(&[(params::α, 0.25), (params::α, 0.5)], &[]).is_err());
    assert!(Coefficients::from_ids(&[(params::α, 0.25)], &[(data::f, &load)]).is_err());
    assert!(Coefficients::from_ids::<M>(&[(params::α, f64::NAN)], &[]).is_err());
}

/// `η_T² = h_T² ‖f + Δu + λ‖²_T` by hand, for the local coefficients `u` and `lambda`.
fn hand_cell_indicator(
    ue: ElementKind,
    le: ElementKind,
    cell: &Cell,
    u: &[f64],
    lambda: &[f64],
) -> f64 {
    let residual = |b: [f64; 3]| {
        let laplacian: f64 = (0..count(ue)).map(|i| u[i] * basis(ue, cell, i, b).2).sum();
        let multiplier: f64 = (0..count(le))
            .map(|i| lambda[i] * basis(le, cell, i, b).0)
            .sum();
        load(&cell.point(b)) + laplacian + multiplier
    };
    let integral: f64 = dunavant4()
        .iter()
        .map(|&(b, w)| w * residual(b).powi(2))
        .sum();
    cell.h * cell.h * integral * cell.area
}

/// The barycentric coordinates in `cell` of the point `p`.
fn barycentric(cell: &Cell, p: [f64; 2]) -> [f64; 3] {
    let d = [p[0] - cell.x[0][0], p[1] - cell.x[0][1]];
    let (b1, b2) = (dot(cell.grad[1], d), dot(cell.grad[2], d));
    [1.0 - b1 - b2, b1, b2]
}

/// `η_E² = h_E ‖[[∇u·n]]‖²_E` by hand on the edge `p`–`q` shared by `plus` and
/// `minus`, `n` the outward normal of `plus`, by 3-point Gauss–Legendre.
#[allow(clippy::too_many_arguments)]
fn hand_edge_indicator(
    ue: ElementKind,
    plus: &Cell,
    u: &[f64],
    minus: &Cell,
    w: &[f64],
    p: [f64; 2],
    q: [f64; 2],
) -> f64 {
    let len = (q[0] - p[0]).hypot(q[1] - p[1]);
    let mut n = [(q[1] - p[1]) / len, -(q[0] - p[0]) / len];
    // outward of `plus`: away from its third vertex
    let centre = plus.point([1.0 / 3.0; 3]);
    if dot(n, [centre[0] - p[0], centre[1] - p[1]]) > 0.0 {
        n = [-n[0], -n[1]];
    }
    let gradient = |cell: &Cell, c: &[f64], x: [f64; 2]| {
        let b = barycentric(cell, x);
        (0..count(ue)).fold([0.0; 2], |g, i| {
            let gi = basis(ue, cell, i, b).1;
            [g[0] + c[i] * gi[0], g[1] + c[i] * gi[1]]
        })
    };
    let s = 0.6f64.sqrt();
    let rule = [
        (0.5 * (1.0 - s), 5.0 / 18.0),
        (0.5, 8.0 / 18.0),
        (0.5 * (1.0 + s), 5.0 / 18.0),
    ];
    let integral: f64 = rule
        .iter()
        .map(|&(t, weight)| {
            let x = [p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])];
            let (a, b) = (gradient(plus, u, x), gradient(minus, w, x));
            weight * dot([a[0] - b[0], a[1] - b[1]], n).powi(2)
        })
        .sum();
    len * integral * len
}

fn flat(cell: &Cell) -> Vec<f64> {
    cell.x.iter().flatten().copied().collect()
}

/// The generated indicators of `M` against the hand-coded ones, on `cell` and its
/// neighbour across local edge 0 (the neighbour's vertices rotated by `turn`, so the
/// shared edge is any of its local edges).
fn check_indicators<M: Model>(cell: &Cell, apex: [f64; 2], turn: usize, coefficients: &[f64]) {
    let ue = M::FIELDS[0].element;
    let le = M::FIELDS[1].element;
    let (nu, nl) = (count(ue), count(le));
    let take = |k: usize, n: usize| -> Vec<f64> {
        (0..n)
            .map(|i| coefficients[(k + i) % coefficients.len()])
            .collect()
    };
    let (u, lambda) = (take(0, nu), take(nu, nl));
    let data: [&DataFn; 3] = [&load, &obstacle, &boundary];
    let alpha = [0.3];
    let generated = M::cell_indicator(&flat(cell), &[&u, &lambda], &alpha, &data).unwrap();
    let hand = hand_cell_indicator(ue, le, cell, &u, &lambda);
    assert!(
        (generated - hand).abs() <= 1e-10 * hand.max(1e-300),
        "{}: η_T² {generated:e} against {hand:e} by hand",
        M::NAME
    );
    // the neighbour across edge 0 (x0 → x1): counter-clockwise [x1, x0, apex], rotated
    let vertices = [cell.x[1], cell.x[0], apex];
    let rotated: [[f64; 2]; 3] = std::array::from_fn(|i| vertices[(i + turn) % 3]);
    let neighbour = Cell::new(rotated);
    let other_edge = (3 - turn) % 3;
    let (w, mu) = (take(3, nu), take(7, nl));
    let generated = M::edge_indicator(
        &flat(cell),
        0,
        &[&u, &lambda],
        &flat(&neighbour),
        other_edge,
        &[&w, &mu],
        &alpha,
        &data,
    )
    .unwrap();
    let hand = hand_edge_indicator(ue, cell, &u, &neighbour, &w, cell.x[0], cell.x[1]);
    assert!(
        (generated - hand).abs() <= 1e-10 * hand.max(1e-300),
        "{}: η_E² {generated:e} against {hand:e} by hand",
        M::NAME
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(100))]

    #[test]
    fn membrane_indicators_match_the_hand_coded_ones(
        cell in triangle(),
        height in 0.2..2.0f64,
        along in -0.5..1.5f64,
        turn in 0..3usize,
        coefficients in proptest::collection::vec(-2.0..2.0f64, 11),
    ) {
        // the apex on the other side of edge 0 from the cell's third vertex
        let [p, q, r] = cell.x;
        let (tx, ty) = (q[0] - p[0], q[1] - p[1]);
        let side = if (r[0] - p[0]) * -ty + (r[1] - p[1]) * tx > 0.0 { -1.0 } else { 1.0 };
        let apex = [p[0] + along * tx - side * height * ty, p[1] + along * ty + side * height * tx];
        check_indicators::<membrane_p1_p0::Model>(&cell, apex, turn, &coefficients);
        check_indicators::<membrane_p2_p0::Model>(&cell, apex, turn, &coefficients);
        check_indicators::<membrane_p2_p1disc::Model>(&cell, apex, turn, &coefficients);
    }
}

/// A function that is a quadratic on the whole plane has no jumps, and its cell residual
/// is that of its Laplacian: the indicators see the solution, not its numbering.
#[test]
fn a_global_quadratic_has_no_jump() {
    type M = membrane_p2_p0::Model;
    let quadratic = |x: [f64; 2]| {
        0.3 + x[0] - 2.0 * x[1] + 0.7 * x[0] * x[0] - 0.4 * x[0] * x[1] + 1.1 * x[1] * x[1]
    };
    // P2 nodes: vertices, then the midpoints of the edges 0–1, 1–2, 2–0
    let nodes = |c: &Cell| -> Vec<f64> {
        let mid =
            |i: usize, j: usize| [(c.x[i][0] + c.x[j][0]) / 2.0, (c.x[i][1] + c.x[j][1]) / 2.0];
        [c.x[0], c.x[1], c.x[2], mid(0, 1), mid(1, 2), mid(2, 0)]
            .map(quadratic)
            .to_vec()
    };
    let plus = Cell::new([[0.1, 0.2], [1.3, 0.1], [0.4, 0.9]]);
    let minus = Cell::new([[1.3, 0.1], [0.1, 0.2], [0.8, -0.7]]);
    let data: [&DataFn; 3] = [&load, &obstacle, &boundary];
    let jump = M::edge_indicator(
        &flat(&plus),
        0,
        &[&nodes(&plus), &[0.0]],
        &flat(&minus),
        0,
        &[&nodes(&minus), &[0.0]],
        &[0.3],
        &data,
    )
    .unwrap();
    assert!(jump < 1e-26, "η_E² = {jump:e}");
    // Δ = 2·0.7 + 2·1.1 = 3.6; with λ = −3.6 the residual is f alone
    let cell = M::cell_indicator(&flat(&plus), &[&nodes(&plus), &[-3.6]], &[0.3], &data).unwrap();
    let load_only: f64 = dunavant4()
        .iter()
        .map(|&(b, w)| w * load(&plus.point(b)).powi(2))
        .sum::<f64>()
        * plus.area
        * plus.h
        * plus.h;
    assert!(
        (cell - load_only).abs() < 1e-12 * load_only,
        "{cell:e} against {load_only:e}"
    );
}
