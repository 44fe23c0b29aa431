//! Hertz line contact (plane strain): the reference of the `hertz` scene of Signorini
//! contact (docs/contact.md; K. L. Johnson, *Contact Mechanics*, 1985, §4.2 and §5.2).
//!
//! A cylinder of radius `R` (per unit length), Young's modulus `E` and Poisson ratio
//! `ν`, pressed by the resultant `P` (force per unit length) onto a rigid plane, touches
//! it on `|x| ≤ b` with the elliptic pressure
//!
//! ```text
//! E* = E/(1 − ν²),   b = √(4PR/(πE*)),   p_max = 2P/(πb),   p(x) = p_max √(1 − x²/b²).
//! ```
//!
//! The P0 multiplier of a contact discretization is compared with `p` by its relative
//! L² error and against the best the P0 space can do: the L² projection of `p` onto the
//! same intervals. The square-root edge at `x = ±b` caps both at O(h) (docs/contact.md).
//! A continuous P1 multiplier is compared the same way against the best continuous P1
//! fit (the L² projection onto the piecewise linears on the same nodes).
//! All integrals here are exact (closed forms of `∫p`, `∫xp` and `∫p²`), so the reference
//! adds no quadrature error of its own (no Gauss rule meets the square-root edge at ±b).

/// Hertz line contact, the name the contact family uses.
pub type Hertz = HertzLineContact;

/// Hertz line contact of a cylinder on a rigid plane, plane strain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HertzLineContact {
    /// Cylinder radius R (length).
    pub radius: f64,
    /// Young's modulus E (force / length²).
    pub young: f64,
    /// Poisson ratio ν, in (−1, ½).
    pub poisson: f64,
    /// Resultant P pressing the cylinder down (force per unit length of cylinder).
    pub load: f64,
}

impl HertzLineContact {
    /// The plane-strain modulus `E* = E/(1 − ν²)` (rigid foundation).
    pub fn plane_strain_modulus(&self) -> f64 {
        self.young / (1.0 - self.poisson * self.poisson)
    }

    /// The contact half-width `b = √(4PR/(πE*))`.
    pub fn half_width(&self) -> f64 {
        (4.0 * self.load * self.radius / (std::f64::consts::PI * self.plane_strain_modulus()))
            .sqrt()
    }

    /// The peak pressure `p_max = 2P/(πb)`, at `x = 0`.
    pub fn max_pressure(&self) -> f64 {
        2.0 * self.load / (std::f64::consts::PI * self.half_width())
    }

    /// The contact pressure `p(x) = p_max √(1 − x²/b²)` for `|x| < b`, 0 outside.
    pub fn pressure(&self, x: f64) -> f64 {
        let s = x / self.half_width();
        if s.abs() >= 1.0 {
            0.0
        } else {
            self.max_pressure() * (1.0 - s * s).sqrt()
        }
    }

    /// `∫_{x0}^{x1} p(x) dx`, exact: `p_max [ (x/2)√(1 − x²/b²) + (b/2) asin(x/b) ]`
    /// between the limits clamped to `[−b, b]`.
    pub fn pressure_integral(&self, x0: f64, x1: f64) -> f64 {
        let b = self.half_width();
        let primitive = |x: f64| {
            let s = (x / b).clamp(-1.0, 1.0);
            0.5 * b * (s * (1.0 - s * s).sqrt() + s.asin())
        };
        self.max_pressure() * (primitive(x1) - primitive(x0))
    }

    /// `∫_{x0}^{x1} p(x)² dx`, exact: `p_max² (x − x³/(3b²))` between the limits
    /// clamped to `[−b, b]`.
    pub fn pressure_squared_integral(&self, x0: f64, x1: f64) -> f64 {
        let b = self.half_width();
        let primitive = |x: f64| {
            let x = x.clamp(-b, b);
            x - x * x * x / (3.0 * b * b)
        };
        self.max_pressure().powi(2) * (primitive(x1) - primitive(x0))
    }

    /// `∫_{x0}^{x1} x p(x) dx`, exact: `−p_max (b²/3) (1 − x²/b²)^{3/2}` between the
    /// limits clamped to `[−b, b]` (the first moment, for piecewise-linear pressures).
    pub fn pressure_moment_integral(&self, x0: f64, x1: f64) -> f64 {
        let b = self.half_width();
        let primitive = |x: f64| {
            let s = (x / b).clamp(-1.0, 1.0);
            -(b * b / 3.0) * (1.0 - s * s).powf(1.5)
        };
        self.max_pressure() * (primitive(x1) - primitive(x0))
    }

    /// `∫_{x0}^{x1} (p − l)² dx` for the linear `l` with `l(x0) = v0`, `l(x1) = v1`,
    /// exact (x0 < x1).
    fn linear_error_squared(&self, x0: f64, x1: f64, v0: f64, v1: f64) -> f64 {
        let h = x1 - x0;
        let (i0, i1) = (
            self.pressure_integral(x0, x1),
            self.pressure_moment_integral(x0, x1),
        );
        // l = (v0 (x1 − x) + v1 (x − x0)) / h
        let pl = (v0 * (x1 * i0 - i1) + v1 * (i1 - x0 * i0)) / h;
        let ll = h * (v0 * v0 + v0 * v1 + v1 * v1) / 3.0;
        self.pressure_squared_integral(x0, x1) - 2.0 * pl + ll
    }

    /// The relative L² error `‖p − p_h‖ / ‖p‖` of a piecewise-linear pressure:
    /// `intervals[i] = [x0, x1]` (x0 < x1, not overlapping) carries the linear function
    /// with end values `values[i] = [p_h(x0), p_h(x1)]`. Both norms are over the union of
    /// the intervals (a symmetric half of the contact, as on the quarter disc, gives the
    /// relative error of the whole). Exact integrals. Pairs interval and values by
    /// position; 0/0 (no pressure on the intervals) gives NaN.
    pub fn relative_l2_error_p1(&self, intervals: &[[f64; 2]], values: &[[f64; 2]]) -> f64 {
        let (mut error2, mut norm2) = (0.0, 0.0);
        for (&[x0, x1], &[v0, v1]) in intervals.iter().zip(values) {
            error2 += self.linear_error_squared(x0, x1, v0, v1);
            norm2 += self.pressure_squared_integral(x0, x1);
        }
        (error2.max(0.0) / norm2).sqrt()
    }

    /// The best continuous P1 fit on the nodes `x_0 < x_1 < … < x_n`: the L² projection
    /// of `p` onto the continuous piecewise linears on `[x_0, x_n]` (the tridiagonal mass
    /// system, solved exactly by elimination), its nodal values. Empty for fewer than 2
    /// nodes.
    pub fn best_p1_fit(&self, nodes: &[f64]) -> Vec<f64> {
        let n = nodes.len();
        if n < 2 {
            return Vec::new();
        }
        // M c = r, M_kk = (h_left + h_right)/3, M_k,k±1 = h/6, r_k = ∫ p φ_k
        let (mut diag, mut off, mut rhs) = (vec![0.0; n], vec![0.0; n - 1], vec![0.0; n]);
        for k in 0..n - 1 {
            let (x0, x1) = (nodes[k], nodes[k + 1]);
            let h = x1 - x0;
            let (i0, i1) = (
                self.pressure_integral(x0, x1),
                self.pressure_moment_integral(x0, x1),
            );
            diag[k] += h / 3.0;
            diag[k + 1] += h / 3.0;
            off[k] = h / 6.0;
            rhs[k] += (x1 * i0 - i1) / h;
            rhs[k + 1] += (i1 - x0 * i0) / h;
        }
        // Thomas algorithm: M is SPD and diagonally dominant
        for k in 1..n {
            let factor = off[k - 1] / diag[k - 1];
            diag[k] -= factor * off[k - 1];
            rhs[k] -= factor * rhs[k - 1];
        }
        let mut c = vec![0.0; n];
        c[n - 1] = rhs[n - 1] / diag[n - 1];
        for k in (0..n - 1).rev() {
            c[k] = (rhs[k] - off[k] * c[k + 1]) / diag[k];
        }
        c
    }

    /// The relative L² error of [`HertzLineContact::best_p1_fit`] on `nodes` (norms over
    /// `[x_0, x_n]`): the floor for any continuous P1 multiplier on them.
    pub fn best_p1_relative_l2_error(&self, nodes: &[f64]) -> f64 {
        let c = self.best_p1_fit(nodes);
        let intervals: Vec<[f64; 2]> = nodes.windows(2).map(|w| [w[0], w[1]]).collect();
        let values: Vec<[f64; 2]> = c.windows(2).map(|w| [w[0], w[1]]).collect();
        self.relative_l2_error_p1(&intervals, &values)
    }

    /// The relative L² error `‖p − p_h‖ / ‖p‖` over the union of the intervals of a
    /// piecewise-constant pressure: `intervals[i] = [x0, x1]` (x0 < x1, not
    /// overlapping) carries the value `values[i]`. `‖p‖` is over the whole contact
    /// zone `[−b, b]`, so a contact zone the intervals miss counts as error. Pairs
    /// interval and value by position (extra entries of the longer slice are ignored).
    pub fn relative_l2_error_p0(&self, intervals: &[[f64; 2]], values: &[f64]) -> f64 {
        let b = self.half_width();
        let total = self.pressure_squared_integral(-b, b);
        let mut covered = 0.0;
        let mut error2 = 0.0;
        for (&[x0, x1], &c) in intervals.iter().zip(values) {
            let p2 = self.pressure_squared_integral(x0, x1);
            covered += p2;
            // ∫(p − c)² = ∫p² − 2c∫p + c²(x1 − x0)
            error2 += p2 - 2.0 * c * self.pressure_integral(x0, x1) + c * c * (x1 - x0);
        }
        // contact pressure on no interval: all of it is error
        error2 += (total - covered).max(0.0);
        (error2.max(0.0) / total).sqrt()
    }

    /// The relative L² error of the best P0 fit on `intervals`: the L² projection of `p`
    /// (each interval's mean of `p`), the floor for any P0 multiplier on them.
    pub fn best_p0_relative_l2_error(&self, intervals: &[[f64; 2]]) -> f64 {
        let means: Vec<f64> = intervals
            .iter()
            .map(|&[x0, x1]| self.pressure_integral(x0, x1) / (x1 - x0))
            .collect();
        self.relative_l2_error_p0(intervals, &means)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// docs/contact.md's prototype: R = 1, E = 1000, ν = 0.3, P = 1.
    const PROTOTYPE: HertzLineContact = HertzLineContact {
        radius: 1.0,
        young: 1000.0,
        poisson: 0.3,
        load: 1.0,
    };

    #[test]
    fn the_prototype_constants_match_the_models_document() {
        assert!((PROTOTYPE.half_width() - 0.0340389).abs() < 5e-8);
        assert!((PROTOTYPE.max_pressure() - 18.7027).abs() < 5e-5);
    }

    #[test]
    fn the_pressure_integrates_to_the_load() {
        let b = PROTOTYPE.half_width();
        assert!((PROTOTYPE.pressure_integral(-2.0 * b, 2.0 * b) - 1.0).abs() < 1e-14);
        // against a midpoint sum of p and p², not the closed forms
        let n = 200_000;
        let (mut s1, mut s2) = (0.0, 0.0);
        for i in 0..n {
            let x = -b + (i as f64 + 0.5) * 2.0 * b / n as f64;
            let p = PROTOTYPE.pressure(x);
            s1 += p * 2.0 * b / n as f64;
            s2 += p * p * 2.0 * b / n as f64;
        }
        assert!((s1 - 1.0).abs() < 1e-6, "{s1}");
        let exact2 = PROTOTYPE.pressure_squared_integral(-b, b);
        assert!((s2 - exact2).abs() < 1e-9 * exact2, "{s2} {exact2}");
        assert!(
            (PROTOTYPE.pressure_integral(0.0, 0.3 * b) - {
                let m = 20_000;
                (0..m)
                    .map(|i| PROTOTYPE.pressure((i as f64 + 0.5) * 0.3 * b / m as f64))
                    .sum::<f64>()
                    * 0.3
                    * b
                    / m as f64
            })
            .abs()
                < 1e-9
        );
    }

    #[test]
    fn the_best_p0_fit_decays_like_h_and_matches_the_prototype() {
        let b = PROTOTYPE.half_width();
        let cells = |n: usize| -> Vec<[f64; 2]> {
            // uniform intervals covering [−1.5b, 1.5b]
            let h = 3.0 * b / n as f64;
            (0..n)
                .map(|i| [-1.5 * b + i as f64 * h, -1.5 * b + (i + 1) as f64 * h])
                .collect()
        };
        let errors: Vec<f64> = [24, 48, 96, 192]
            .iter()
            .map(|&n| PROTOTYPE.best_p0_relative_l2_error(&cells(n)))
            .collect();
        for w in errors.windows(2) {
            let rate = (w[0] / w[1]).log2();
            // O(h) up to the square-root edge's logarithm: 0.87, 0.89, 0.90
            assert!((0.85..1.1).contains(&rate), "{errors:?}");
        }
        // docs/contact.md: stabilized P1–P0 measured .066 at b/h = 8, "within 1.15× of the
        // best P0 fit": h = b/8 on [−1.5b, 1.5b] is 24 intervals
        assert!((0.066 / errors[0] - 1.14).abs() < 0.01, "{}", errors[0]);
        // the projection is the best P0 fit: perturbing a value increases the error
        let c = cells(48);
        let mut values: Vec<f64> = c
            .iter()
            .map(|&[x0, x1]| PROTOTYPE.pressure_integral(x0, x1) / (x1 - x0))
            .collect();
        let best = PROTOTYPE.relative_l2_error_p0(&c, &values);
        values[24] *= 1.01;
        assert!(PROTOTYPE.relative_l2_error_p0(&c, &values) > best);
        // no multiplier at all: the whole pressure is error
        assert!((PROTOTYPE.relative_l2_error_p0(&[], &[]) - 1.0).abs() < 1e-15);
    }

    /// Midpoint sums of `f` on `[x0, x1]` with `n` points (the reference of the tests).
    fn midpoint(f: impl Fn(f64) -> f64, x0: f64, x1: f64, n: usize) -> f64 {
        let h = (x1 - x0) / n as f64;
        (0..n).map(|i| f(x0 + (i as f64 + 0.5) * h)).sum::<f64>() * h
    }

    #[test]
    fn the_p1_integrals_match_midpoint_sums() {
        let b = PROTOTYPE.half_width();
        for &(x0, x1) in &[(-1.5 * b, 1.5 * b), (0.1 * b, 0.7 * b), (0.6 * b, 1.3 * b)] {
            let exact = PROTOTYPE.pressure_moment_integral(x0, x1);
            let sum = midpoint(|x| x * PROTOTYPE.pressure(x), x0, x1, 400_000);
            assert!((exact - sum).abs() < 1e-9, "{x0} {x1}: {exact} {sum}");
        }
        // a linear function straddling the edge at b
        let (x0, x1, v0, v1) = (0.8 * b, 1.2 * b, 9.0, -1.0);
        let l = |x: f64| v0 + (v1 - v0) * (x - x0) / (x1 - x0);
        let exact = PROTOTYPE.relative_l2_error_p1(&[[x0, x1]], &[[v0, v1]]);
        let e2 = midpoint(|x| (PROTOTYPE.pressure(x) - l(x)).powi(2), x0, x1, 400_000);
        let n2 = midpoint(|x| PROTOTYPE.pressure(x).powi(2), x0, x1, 400_000);
        assert!((exact - (e2 / n2).sqrt()).abs() < 1e-6 * exact, "{exact}");
    }

    #[test]
    fn the_best_p1_fit_is_the_projection_and_decays() {
        let b = PROTOTYPE.half_width();
        let nodes =
            |n: usize| -> Vec<f64> { (0..=n).map(|i| 1.5 * b * i as f64 / n as f64).collect() };
        // the projection: the residual p − Πp is orthogonal to every hat function
        let x = nodes(24);
        let c = PROTOTYPE.best_p1_fit(&x);
        for k in [0, 5, 15, 16, 24] {
            let hat = |t: f64| {
                let left = if k > 0 {
                    (t - x[k - 1]) / (x[k] - x[k - 1])
                } else {
                    -1.0
                };
                let right = if k < 24 {
                    (x[k + 1] - t) / (x[k + 1] - x[k])
                } else {
                    -1.0
                };
                left.max(right).clamp(0.0, 1.0)
            };
            let fit = |t: f64| {
                let i = x.partition_point(|&v| v <= t).clamp(1, 24) - 1;
                let s = (t - x[i]) / (x[i + 1] - x[i]);
                (1.0 - s) * c[i] + s * c[i + 1]
            };
            let r = midpoint(
                |t| (PROTOTYPE.pressure(t) - fit(t)) * hat(t),
                0.0,
                1.5 * b,
                480_000,
            );
            assert!(r.abs() < 1e-8, "node {k}: {r}");
        }
        // perturbing a value increases the error
        let best = PROTOTYPE.best_p1_relative_l2_error(&x);
        let mut values: Vec<[f64; 2]> = c.windows(2).map(|w| [w[0], w[1]]).collect();
        values[10][1] *= 1.01;
        values[11][0] *= 1.01;
        let intervals: Vec<[f64; 2]> = x.windows(2).map(|w| [w[0], w[1]]).collect();
        assert!(PROTOTYPE.relative_l2_error_p1(&intervals, &values) > best);
        // O(h) (rate 1.00: .0129, .0064, .0032, .0016) with a node at b (x_16 = b for
        // every n here; without, the error jumps with b's place in its cell)
        let errors: Vec<f64> = [24, 48, 96, 192]
            .iter()
            .map(|&n| PROTOTYPE.best_p1_relative_l2_error(&nodes(n)))
            .collect();
        for w in errors.windows(2) {
            let rate = (w[0] / w[1]).log2();
            assert!((0.95..1.05).contains(&rate), "{errors:?}");
        }
    }
}
