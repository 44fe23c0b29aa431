//! Element matrices written by hand, independent of the form compiler and of
//! `fem-reference`: basis functions typed in from their formulas, a Gauss rule from
//! the tables, and the forms of docs/mathematics.md written as integrands. Shared by the kernel
//! tests and the kernel benchmark.
#![allow(dead_code, clippy::needless_range_loop)]

/// 5-point Gauss–Legendre on [−1, 1] (Abramowitz & Stegun 25.4.30), exact to degree 9.
pub const GAUSS5: [(f64, f64); 5] = [
    (-0.906_179_845_938_664, 0.236_926_885_056_189_1),
    (-0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (0.0, 0.568_888_888_888_888_9),
    (0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (0.906_179_845_938_664, 0.236_926_885_056_189_1),
];

/// The basis functions of the 1D elements, by formula: `(value, d/dξ, d²/dξ², d³/dξ³, d⁴/dξ⁴)`
/// of reference function `i` at `ξ ∈ [0, 1]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HandElement {
    /// constant 1
    P0,
    /// 1 − ξ, ξ
    P1,
    /// nodes 0, 1, ½
    P2,
    /// value, slope at 0; value, slope at 1
    Hermite,
}

impl HandElement {
    /// Number of local functions.
    pub fn n(self) -> usize {
        match self {
            HandElement::P0 => 1,
            HandElement::P1 => 2,
            HandElement::P2 => 3,
            HandElement::Hermite => 4,
        }
    }

    /// Reference derivatives 0..=4 of function `i` at ξ.
    pub fn reference(self, i: usize, x: f64) -> [f64; 5] {
        match (self, i) {
            (HandElement::P0, 0) => [1.0, 0.0, 0.0, 0.0, 0.0],
            (HandElement::P1, 0) => [1.0 - x, -1.0, 0.0, 0.0, 0.0],
            (HandElement::P1, 1) => [x, 1.0, 0.0, 0.0, 0.0],
            (HandElement::P2, 0) => [(1.0 - x) * (1.0 - 2.0 * x), 4.0 * x - 3.0, 4.0, 0.0, 0.0],
            (HandElement::P2, 1) => [x * (2.0 * x - 1.0), 4.0 * x - 1.0, 4.0, 0.0, 0.0],
            (HandElement::P2, 2) => [4.0 * x * (1.0 - x), 4.0 - 8.0 * x, -8.0, 0.0, 0.0],
            (HandElement::Hermite, 0) => [
                1.0 - 3.0 * x * x + 2.0 * x * x * x,
                -6.0 * x + 6.0 * x * x,
                -6.0 + 12.0 * x,
                12.0,
                0.0,
            ],
            (HandElement::Hermite, 1) => [
                x - 2.0 * x * x + x * x * x,
                1.0 - 4.0 * x + 3.0 * x * x,
                -4.0 + 6.0 * x,
                6.0,
                0.0,
            ],
            (HandElement::Hermite, 2) => [
                3.0 * x * x - 2.0 * x * x * x,
                6.0 * x - 6.0 * x * x,
                6.0 - 12.0 * x,
                -12.0,
                0.0,
            ],
            (HandElement::Hermite, 3) => [
                -x * x + x * x * x,
                -2.0 * x + 3.0 * x * x,
                -2.0 + 6.0 * x,
                6.0,
                0.0,
            ],
            _ => panic!("{self:?} has no function {i}"),
        }
    }

    /// Physical derivatives 0..=4 of function `i` on a cell of length `h` at ξ: a slope
    /// DOF's function is `h` times the reference one, and `d/dx = h⁻¹ d/dξ`.
    pub fn physical(self, i: usize, h: f64, x: f64) -> [f64; 5] {
        let r = self.reference(i, x);
        let scale = if self == HandElement::Hermite && i % 2 == 1 {
            h
        } else {
            1.0
        };
        std::array::from_fn(|k| r[k] * scale / h.powi(k as i32))
    }
}

/// Parameter and data values for one element.
#[derive(Clone, Copy, Debug)]
pub struct Setting {
    /// Left end.
    pub x0: f64,
    /// Length.
    pub h: f64,
    /// Thickness.
    pub t: f64,
    /// Stabilization parameter.
    pub alpha: f64,
    /// Obstacle side ±1.
    pub s: f64,
}

/// Load f(x) of the comparisons (degree 2, as the models declare).
pub fn load(x: f64) -> f64 {
    1.0 + 2.0 * x - 3.0 * x * x
}

/// Obstacle ψ(x) of the comparisons (degree 2).
pub fn obstacle(x: f64) -> f64 {
    0.3 - x + 0.5 * x * x
}

/// Values `[field][derivative]` of a trial or test function that is basis function `i`
/// of `field` (all other fields zero).
pub type FieldValues = [[f64; 5]; 3];

/// `∫_T integrand(U, V, x) dx` for every pair (test basis i of field g, trial basis j of
/// field f), with the 5-point rule (or the given rule for reduced integration).
pub fn element_matrix(
    elements: &[HandElement],
    test_field: usize,
    trial_field: usize,
    setting: Setting,
    rule: &[(f64, f64)],
    integrand: &dyn Fn(&FieldValues, &FieldValues, f64) -> f64,
) -> Vec<Vec<f64>> {
    let (eg, ef) = (elements[test_field], elements[trial_field]);
    let mut m = vec![vec![0.0; ef.n()]; eg.n()];
    for &(z, w) in rule {
        let xi = 0.5 * (1.0 + z);
        let x = setting.x0 + setting.h * xi;
        for i in 0..eg.n() {
            for j in 0..ef.n() {
                let mut v = [[0.0; 5]; 3];
                let mut u = [[0.0; 5]; 3];
                v[test_field] = eg.physical(i, setting.h, xi);
                u[trial_field] = ef.physical(j, setting.h, xi);
                m[i][j] += 0.5 * w * setting.h * integrand(&u, &v, x);
            }
        }
    }
    m
}

/// `∫_T integrand(V, x) dx` for every test basis function of `test_field`.
pub fn element_vector(
    elements: &[HandElement],
    test_field: usize,
    setting: Setting,
    integrand: &dyn Fn(&FieldValues, f64) -> f64,
) -> Vec<f64> {
    let e = elements[test_field];
    let mut out = vec![0.0; e.n()];
    for &(z, w) in &GAUSS5 {
        let xi = 0.5 * (1.0 + z);
        let x = setting.x0 + setting.h * xi;
        for (i, o) in out.iter_mut().enumerate() {
            let mut v = [[0.0; 5]; 3];
            v[test_field] = e.physical(i, setting.h, xi);
            *o += 0.5 * w * setting.h * integrand(&v, x);
        }
    }
    out
}

// Field indices of the Timoshenko models and of the Euler–Bernoulli model.
const THETA: usize = 0;
const W: usize = 1;
const LAMBDA: usize = 2;
const BW: usize = 0;
const BLAMBDA: usize = 1;

/// The Timoshenko forms of docs/mathematics.md §3 as integrands `(form, U, V, x, setting)`;
/// `shear_rule` is the rule of the shear term (GAUSS5, or the midpoint for reduced integration).
pub fn timoshenko_matrix(
    form: &str,
    elements: &[HandElement; 3],
    test_field: usize,
    trial_field: usize,
    st: Setting,
    shear_rule: &[(f64, f64)],
) -> Vec<Vec<f64>> {
    let (t2, s, h4) = (st.t.powi(-2), st.s, st.h.powi(4));
    let bending = |u: &FieldValues, v: &FieldValues, _x: f64| u[THETA][1] * v[THETA][1];
    let shear = |u: &FieldValues, v: &FieldValues, _x: f64| {
        t2 * (u[W][1] - u[THETA][0]) * (v[W][1] - v[THETA][0])
    };
    // b(v, μ) = ∫ s v μ, in both roles
    let b_vl = |u: &FieldValues, v: &FieldValues, _x: f64| s * v[W][0] * u[LAMBDA][0];
    let b_wm = |u: &FieldValues, v: &FieldValues, _x: f64| s * u[W][0] * v[LAMBDA][0];
    let stab = |u: &FieldValues, v: &FieldValues, _x: f64| {
        h4 * (u[THETA][3] - s * u[LAMBDA][0]) * (v[THETA][3] - s * v[LAMBDA][0])
    };
    let m = |f: &dyn Fn(&FieldValues, &FieldValues, f64) -> f64, rule: &[(f64, f64)]| {
        element_matrix(elements, test_field, trial_field, st, rule, f)
    };
    let add = |a: Vec<Vec<f64>>, b: Vec<Vec<f64>>, c: f64| -> Vec<Vec<f64>> {
        a.iter()
            .zip(&b)
            .map(|(ra, rb)| ra.iter().zip(rb).map(|(x, y)| x + c * y).collect())
            .collect()
    };
    match form {
        "a" => add(m(&bending, &GAUSS5), m(&shear, shear_rule), 1.0),
        "b" => m(&b_wm, &GAUSS5),
        "S" => m(&stab, &GAUSS5),
        "B_h" => {
            let a = add(m(&bending, &GAUSS5), m(&shear, shear_rule), 1.0);
            let b = add(m(&b_vl, &GAUSS5), m(&b_wm, &GAUSS5), 1.0);
            add(add(a, b, -1.0), m(&stab, &GAUSS5), -st.alpha)
        }
        _ => panic!("no Timoshenko form {form}"),
    }
}

/// The Timoshenko linear forms: ℓ, ℓ_S, g, L_h.
pub fn timoshenko_vector(
    form: &str,
    elements: &[HandElement; 3],
    test_field: usize,
    st: Setting,
) -> Vec<f64> {
    let (s, h4, alpha) = (st.s, st.h.powi(4), st.alpha);
    let l = |v: &FieldValues, x: f64| load(x) * v[W][0];
    let ls = |v: &FieldValues, x: f64| h4 * load(x) * (v[THETA][3] - s * v[LAMBDA][0]);
    let g = |v: &FieldValues, x: f64| s * obstacle(x) * v[LAMBDA][0];
    let lh = |v: &FieldValues, x: f64| l(v, x) - g(v, x) - alpha * ls(v, x);
    let f: &dyn Fn(&FieldValues, f64) -> f64 = match form {
        "ℓ" => &l,
        "ℓ_S" => &ls,
        "g" => &g,
        "L_h" => &lh,
        _ => panic!("no Timoshenko form {form}"),
    };
    element_vector(elements, test_field, st, f)
}

/// The Euler–Bernoulli forms of docs/mathematics.md §4.
pub fn bernoulli_matrix(
    form: &str,
    test_field: usize,
    trial_field: usize,
    st: Setting,
) -> Vec<Vec<f64>> {
    let elements = [HandElement::Hermite, HandElement::P0];
    let (s, h4) = (st.s, st.h.powi(4));
    let a = |u: &FieldValues, v: &FieldValues, _x: f64| u[BW][2] * v[BW][2];
    let b_vl = |u: &FieldValues, v: &FieldValues, _x: f64| s * v[BW][0] * u[BLAMBDA][0];
    let b_wm = |u: &FieldValues, v: &FieldValues, _x: f64| s * u[BW][0] * v[BLAMBDA][0];
    let stab = |u: &FieldValues, v: &FieldValues, _x: f64| {
        h4 * (u[BW][4] - s * u[BLAMBDA][0]) * (v[BW][4] - s * v[BLAMBDA][0])
    };
    let bh = |u: &FieldValues, v: &FieldValues, x: f64| {
        a(u, v, x) - b_vl(u, v, x) - b_wm(u, v, x) - st.alpha * stab(u, v, x)
    };
    let f: &dyn Fn(&FieldValues, &FieldValues, f64) -> f64 = match form {
        "a" => &a,
        "b" => &b_wm,
        "S" => &stab,
        "B_h" => &bh,
        _ => panic!("no Euler–Bernoulli form {form}"),
    };
    element_matrix(&elements, test_field, trial_field, st, &GAUSS5, f)
}

/// The Euler–Bernoulli linear forms: ℓ, ℓ_S, g, L_h.
pub fn bernoulli_vector(form: &str, test_field: usize, st: Setting) -> Vec<f64> {
    let elements = [HandElement::Hermite, HandElement::P0];
    let (s, h4, alpha) = (st.s, st.h.powi(4), st.alpha);
    let l = |v: &FieldValues, x: f64| load(x) * v[BW][0];
    let ls = |v: &FieldValues, x: f64| h4 * load(x) * (v[BW][4] - s * v[BLAMBDA][0]);
    let g = |v: &FieldValues, x: f64| s * obstacle(x) * v[BLAMBDA][0];
    let lh = |v: &FieldValues, x: f64| l(v, x) - g(v, x) - alpha * ls(v, x);
    let f: &dyn Fn(&FieldValues, f64) -> f64 = match form {
        "ℓ" => &l,
        "ℓ_S" => &ls,
        "g" => &g,
        "L_h" => &lh,
        _ => panic!("no Euler–Bernoulli form {form}"),
    };
    element_vector(&elements, test_field, st, f)
}

/// Closed-form Timoshenko P2 block (η, θ) of `a`: `K/h + t⁻² h M` (for the benchmark).
#[inline]
pub fn timoshenko_p2_a_eta_theta(x: &[f64; 2], t: f64) -> [[f64; 3]; 3] {
    let h = x[1] - x[0];
    let k = 1.0 / (3.0 * h);
    let m = h / (30.0 * t * t);
    [
        [7.0 * k + 4.0 * m, k - m, -8.0 * k + 2.0 * m],
        [k - m, 7.0 * k + 4.0 * m, -8.0 * k + 2.0 * m],
        [-8.0 * k + 2.0 * m, -8.0 * k + 2.0 * m, 16.0 * k + 16.0 * m],
    ]
}

/// Closed-form Timoshenko P2 block (η, w) of `a`: `−t⁻² ∫ w' η`.
#[inline]
pub fn timoshenko_p2_a_eta_w(t: f64) -> [[f64; 3]; 3] {
    let c = 1.0 / (t * t);
    [
        [0.5 * c, c / 6.0, -2.0 * c / 3.0],
        [-c / 6.0, -0.5 * c, 2.0 * c / 3.0],
        [2.0 * c / 3.0, -2.0 * c / 3.0, 0.0],
    ]
}

/// Closed-form Timoshenko P2 block (v, w) of `a`: `t⁻² K / h`.
#[inline]
pub fn timoshenko_p2_a_v_w(x: &[f64; 2], t: f64) -> [[f64; 3]; 3] {
    let k = 1.0 / (3.0 * (x[1] - x[0]) * t * t);
    [
        [7.0 * k, k, -8.0 * k],
        [k, 7.0 * k, -8.0 * k],
        [-8.0 * k, -8.0 * k, 16.0 * k],
    ]
}

/// Closed-form Hermite bending stiffness `∫ w''v''`.
#[inline]
pub fn bernoulli_a(x: &[f64; 2]) -> [[f64; 4]; 4] {
    let h = x[1] - x[0];
    let c = 1.0 / (h * h * h);
    let (a, b, d, e) = (12.0 * c, 6.0 * h * c, 4.0 * h * h * c, 2.0 * h * h * c);
    [[a, b, -a, b], [b, d, -b, e], [-a, -b, a, -b], [b, e, -b, d]]
}

/// Load vector `∫ f v` for P2 with a 3-point Gauss rule (exact for quadratic f).
#[inline]
pub fn p2_load(x: &[f64; 2], f: &dyn Fn(&[f64]) -> f64) -> [f64; 3] {
    const Z: [f64; 3] = [0.112_701_665_379_258_3, 0.5, 0.887_298_334_620_741_7];
    const W: [f64; 3] = [5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0];
    let h = x[1] - x[0];
    let mut out = [0.0; 3];
    for q in 0..3 {
        let xi = Z[q];
        let fq = W[q] * h * f(&[x[0] + h * xi]);
        out[0] += fq * (1.0 - xi) * (1.0 - 2.0 * xi);
        out[1] += fq * xi * (2.0 * xi - 1.0);
        out[2] += fq * 4.0 * xi * (1.0 - xi);
    }
    out
}
