//! The manufactured clamped Kirchhoff plate on the unit square: `w = (x(1−x) y(1−y))²`
//! vanishes with its gradient on the boundary, so it is the clamped plate's deflection
//! under `f = DΔ²w` (with `D = 1.3`, a value that a dropped `D` would show).
#![allow(dead_code)]

/// The bending stiffness the load is made for.
pub const D: f64 = 1.3;

/// `X²` with `X = x(1−x)`, and its first four derivatives.
fn factor(x: f64) -> [f64; 5] {
    let (p, dp) = (x * (1.0 - x), 1.0 - 2.0 * x);
    [
        p * p,
        2.0 * p * dp,
        2.0 * dp * dp - 4.0 * p,
        -12.0 * dp,
        24.0,
    ]
}

/// The deflection `w`.
pub fn w(x: &[f64]) -> f64 {
    factor(x[0])[0] * factor(x[1])[0]
}

/// `∇w`.
pub fn gradient(x: &[f64]) -> [f64; 2] {
    let (a, b) = (factor(x[0]), factor(x[1]));
    [a[1] * b[0], a[0] * b[1]]
}

/// `∇²w` as a symmetric 2×2 matrix.
pub fn hessian(x: &[f64]) -> [[f64; 2]; 2] {
    let (a, b) = (factor(x[0]), factor(x[1]));
    let xy = a[1] * b[1];
    [[a[2] * b[0], xy], [xy, a[0] * b[2]]]
}

/// `f = DΔ²w = D(w_xxxx + 2 w_xxyy + w_yyyy)`.
pub fn load(x: &[f64]) -> f64 {
    let (a, b) = (factor(x[0]), factor(x[1]));
    D * (a[4] * b[0] + 2.0 * a[2] * b[2] + a[0] * b[4])
}
