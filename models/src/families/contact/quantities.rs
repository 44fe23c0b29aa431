//! The contact quantities of a solved problem: the pressure along Γ_C, the contact
//! force and the load it balances, the half-width and peak, and the comparisons with
//! an exact pressure (Hertz's, or a scene's): the relative L² error, the best fit's in
//! the multiplier's space and the checkerboard measure.

use super::checks::towards_foundation;
use super::facts::{contact_tangent, ContactData};
use crate::hertz::Hertz;
use crate::signorini::Multiplier;
use fem_runtime::obstacle::boundary_multiplier::ContactEdge;
use fem_runtime::problem::Solved;
use fem_runtime::{Model, TriangleMesh};

/// A solved Signorini problem.
#[derive(Clone, Debug)]
pub struct SignoriniSolution {
    /// The contact pressure λ_h per multiplier DOF (force per length): per contact edge
    /// (P0, in `contact_edges` order) or per vertex of Γ_C (P1, in the runtime's
    /// order of the vertices of Γ_C). Along Γ_C: [`SignoriniSolution::edge_pressures`].
    pub pressure: Vec<f64>,
    /// The edges of Γ_C.
    pub contact_edges: Vec<ContactEdge>,
    /// The multiplier's space.
    pub multiplier: Multiplier,
    /// Per contact edge, the indices into `pressure` of its ends `ends[0]`, `ends[1]`
    /// (P1) or `[k, k]` (P0).
    pub edge_dofs: Vec<[usize; 2]>,
    /// Force of the foundation on the body, `Σ_E ∫_E λ_h ds (−n_c)` (P0: `Σ_E λ_E |E|`).
    pub total_contact_force: [f64; 2],
    /// Resultant of the applied pressure, `∫_Γ_N q (−n) ds` (Gauss–Legendre, 4 points per edge).
    pub applied_load: [f64; 2],
    /// The load's resultant along the contact direction `n_c` as the discretization
    /// integrates it: `ℓ(t)` for the unit translation `t` along `n_c` (the model's
    /// quadrature of `q v·n` on Γ_N, exact for the degree of `q` the model declares). The
    /// contact force balances this one to rounding, whatever `q`; it differs from
    /// `applied_load · n_c` by the quadrature error of a pressure that varies faster.
    pub discretized_load: f64,
    /// Half the extent of the edges that carry pressure (above 1e-7 of the peak), holes between them
    /// included, along the contact plane (the coordinate of [`contact_tangent`]: x under
    /// a horizontal plane, y beside a vertical one); from `contact_centre` when given.
    pub contact_half_width: f64,
    /// The largest λ_E.
    pub max_contact_pressure: f64,
}

impl SignoriniSolution {
    /// λ_h at the two ends `ends[0]`, `ends[1]` of each contact edge (`contact_edges`
    /// order): equal for P0; λ_h is linear in between (P1) or constant (P0).
    pub fn edge_pressures(&self) -> Vec<[f64; 2]> {
        self.edge_dofs
            .iter()
            .map(|&[a, b]| [self.pressure[a], self.pressure[b]])
            .collect()
    }

    /// Where each pressure value lives and the value, `(point, λ_h)` in DOF order: the
    /// edge midpoints (P0) or the vertices (P1, where λ_h is linear in between).
    pub fn pressure_points(&self) -> Vec<([f64; 2], f64)> {
        match self.multiplier {
            Multiplier::P0 => self
                .contact_edges
                .iter()
                .zip(&self.pressure)
                .map(|(e, &p)| (e.midpoint(), p))
                .collect(),
            Multiplier::P1 => {
                let mut points = vec![([0.0; 2], 0.0); self.pressure.len()];
                for (e, dofs) in self.contact_edges.iter().zip(&self.edge_dofs) {
                    for (end, &k) in e.ends.iter().zip(dofs) {
                        points[k] = (*end, self.pressure[k]);
                    }
                }
                points
            }
        }
    }

    /// The pressure along Γ_C for a chart, `(x, λ_h)` sorted by x: the
    /// [`SignoriniSolution::pressure_points`].
    pub fn pressure_profile(&self) -> Vec<(f64, f64)> {
        let mut profile: Vec<(f64, f64)> = self
            .pressure_points()
            .into_iter()
            .map(|(x, p)| (x[0], p))
            .collect();
        profile.sort_by(|a, b| a.0.total_cmp(&b.0));
        profile
    }
}

/// The vertices where a continuous P1 pressure passes a corner of Γ_C, and the angle the
/// boundary turns there (degrees, above [`CORNER_DEGREES`]): one value serves both
/// sides, so it cannot jump as a pressure at a corner may (a block pressed on its
/// bottom and free on its side had the peak 60 % high there, at every mesh size).
/// Empty for P0, whose values are per edge.
pub fn p1_corners(solution: &SignoriniSolution) -> Vec<([f64; 2], f64)> {
    if solution.multiplier != Multiplier::P1 {
        return Vec::new();
    }
    let mut tangents: Vec<Vec<[f64; 2]>> = vec![Vec::new(); solution.pressure.len()];
    let mut points = vec![[0.0; 2]; solution.pressure.len()];
    for (e, dofs) in solution.contact_edges.iter().zip(&solution.edge_dofs) {
        let [a, b] = e.ends;
        let l = e.length();
        let t = [(b[0] - a[0]) / l, (b[1] - a[1]) / l];
        for (end, &k) in e.ends.iter().zip(dofs) {
            tangents[k].push(t);
            points[k] = *end;
        }
    }
    tangents
        .iter()
        .zip(points)
        .filter_map(|(t, x)| {
            let [s, u] = t.as_slice() else {
                return None;
            };
            // the turn between the two edges, whichever way each runs
            let turn = (s[0] * u[1] - s[1] * u[0]).abs().asin().to_degrees();
            (turn > CORNER_DEGREES).then_some((x, turn))
        })
        .collect()
}

/// The turn of Γ_C at a vertex above which a continuous pressure is warned about.
pub const CORNER_DEGREES: f64 = 20.0;

/// The share of the peak pressure above which an edge counts as pressed, for the
/// half-width: far above the QP's residual pressures on open edges (1e-9), far below any
/// pressure that matters.
const CARRIES_PRESSURE: f64 = 1e-7;

/// The contact quantities of a solved problem (`direction` the unit `n_c`).
pub fn solution_of<M: Model>(
    input: &ContactData,
    direction: [f64; 2],
    solved: &Solved<M, TriangleMesh>,
) -> SignoriniSolution {
    let solution = &solved.solution;
    let problem = &solution.discretization;
    let mesh = &problem.mesh;
    let boundary = problem.boundary().expect("a boundary multiplier");
    let lcp = &problem.lcp;
    let pressure = solution.multiplier_values().to_vec();
    let mut force = [0.0; 2];
    // ∫_E λ_h ds = |E| (λ_a + λ_b)/2 on each edge (P1), λ_E |E| (P0)
    for (&p, w) in pressure.iter().zip(boundary.integrals()) {
        force[0] -= p * w * direction[0];
        force[1] -= p * w * direction[1];
    }
    let mut load = [0.0; 2];
    let gauss = fem_runtime::gauss_legendre(4);
    for &(e, marker) in mesh.boundary_edges() {
        if !input.load.contains(&marker) {
            continue;
        }
        let (cell, _) = mesh.edge_cells(e);
        let c = mesh.cell(cell);
        let local = mesh
            .cell_edges(cell)
            .iter()
            .position(|&x| x == e)
            .unwrap_or(0);
        let edge = ContactEdge {
            edge: e,
            cell,
            local,
            ends: [
                mesh.vertices()[c[local]],
                mesh.vertices()[c[(local + 1) % 3]],
            ],
        };
        let n = edge.outward_normal();
        let [a, b] = edge.ends;
        let q: f64 = gauss
            .points
            .iter()
            .zip(&gauss.weights)
            .map(|(&s, &w)| {
                w * (input.pressure)(&[a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])])
            })
            .sum::<f64>()
            * edge.length();
        load[0] -= q * n[0];
        load[1] -= q * n[1];
    }
    let largest = pressure.iter().fold(0.0f64, |m, &p| m.max(p));
    let along = contact_tangent(direction);
    let (mut x_min, mut x_max) = (f64::INFINITY, f64::NEG_INFINITY);
    for (e, &[a, b]) in boundary.edges.iter().zip(&boundary.edge_dofs) {
        // the edges that carry pressure (for P1: either end): clarabel's interior point
        // leaves λ ≈ 1e-10…1e-9 p_max on open edges, which counted at 1e-10 and widened
        // the zone by an edge against semismooth Newton's exact zeros
        if pressure[a].max(pressure[b]) > CARRIES_PRESSURE * largest {
            for end in e.ends {
                let s = along[0] * end[0] + along[1] * end[1];
                x_min = x_min.min(s);
                x_max = x_max.max(s);
            }
        }
    }
    let half_width = match (x_max >= x_min, input.centre) {
        (false, _) => 0.0,
        (true, None) => 0.5 * (x_max - x_min),
        (true, Some(c)) => (x_max - c).abs().max((x_min - c).abs()),
    };
    SignoriniSolution {
        pressure,
        contact_edges: boundary.edges.clone(),
        multiplier: boundary.space,
        edge_dofs: boundary.edge_dofs.clone(),
        total_contact_force: force,
        applied_load: load,
        discretized_load: lcp.whole(vec![towards_foundation(problem, direction)
            .iter()
            .zip(&lcp.f)
            .map(|(t, f)| t * f)
            .sum()])[0],
        contact_half_width: half_width,
        max_contact_pressure: largest,
    }
}

/// A pressure against Hertz's: its errors and its checkerboard measure.
#[derive(Clone, Copy, Debug)]
pub struct HertzErrors {
    /// `‖λ_h − p‖ / ‖p‖` on Γ_C (P0: 16-point Gauss–Legendre per edge; P1: exact
    /// integrals over the edges' x-intervals,
    /// [`crate::hertz::HertzLineContact::relative_l2_error_p1`]).
    pub pressure_l2_error: f64,
    /// `‖Πp − p‖ / ‖p‖`: the error of the best fit in the multiplier's space on the same
    /// edges (P0: the edge means; P1: the continuous L² projection on the vertices' x,
    /// [`crate::hertz::HertzLineContact::best_p1_fit`]).
    pub best_fit_l2_error: f64,
    /// The checkerboard measure: `max |λ_{k−1} − 2λ_k + λ_{k+1}| / p_max` over
    /// consecutive multiplier DOFs (edges for P0, vertices for P1, ordered by x) inside
    /// `x < 0.8 b`, where p is smooth
    /// (its own second difference there is at most `4.7 (h/b)² p_max`: 0.018 at b/h = 16).
    pub oscillation: f64,
}

/// The Hertz comparison of a continuous P1 pressure: exact integrals over the edges'
/// x-intervals (the contact edges of the quarter disc are ordered along x).
fn hertz_p1(hertz: Hertz, solution: &SignoriniSolution) -> HertzErrors {
    let (intervals, values): (Vec<[f64; 2]>, Vec<[f64; 2]>) = solution
        .contact_edges
        .iter()
        .zip(solution.edge_pressures())
        .map(|(e, [p0, p1])| {
            let (x0, x1) = (e.ends[0][0], e.ends[1][0]);
            if x0 <= x1 {
                ([x0, x1], [p0, p1])
            } else {
                ([x1, x0], [p1, p0])
            }
        })
        .unzip();
    let nodes: Vec<f64> = solution.pressure_profile().iter().map(|p| p.0).collect();
    HertzErrors {
        oscillation: checkerboard(solution, &hertz),
        pressure_l2_error: hertz.relative_l2_error_p1(&intervals, &values),
        best_fit_l2_error: hertz.best_p1_relative_l2_error(&nodes),
    }
}

/// The checkerboard measure of a pressure against Hertz's (see
/// [`HertzErrors::oscillation`]): `max |λ_{k−1} − 2λ_k + λ_{k+1}| / p_max` over
/// consecutive multiplier DOFs along x ([`SignoriniSolution::pressure_profile`]: edge
/// midpoints for P0, vertices for P1) inside `x < 0.8 b`; 0 where fewer than three lie
/// there.
pub fn checkerboard(solution: &SignoriniSolution, hertz: &Hertz) -> f64 {
    let inside = 0.8 * hertz.half_width();
    solution
        .pressure_profile()
        .windows(3)
        .filter(|w| w[2].0 < inside)
        .map(|w| (w[0].1 - 2.0 * w[1].1 + w[2].1).abs())
        .fold(0.0f64, f64::max)
        / hertz.max_pressure()
}

/// The share of the exact peak pressure above which [`checkerboard_against`] measures:
/// Hertz's pressure is above 0.6 p_max exactly inside 0.8 b, where [`checkerboard`]
/// measures.
pub const SMOOTH_PRESSURE_SHARE: f64 = 0.6;

/// The checkerboard measure of a pressure against any exact pressure `exact`:
/// `max |λ_{k−1} − 2λ_k + λ_{k+1}| / max p` (p sampled at the edges' ends and
/// midpoints) over consecutive multiplier DOFs ([`SignoriniSolution::pressure_points`]:
/// edges for P0, vertices for P1), ordered along the contact plane (`direction` its
/// normal `n_c`), whose points all lie where `p ≥ 0.6 max p` (inside the contact zone,
/// away from its square-root edges); for Hertz's pressure the same as
/// [`checkerboard`]. `None` where fewer than three DOFs lie there, or the exact
/// pressure vanishes on Γ_C.
pub fn checkerboard_against(
    solution: &SignoriniSolution,
    direction: [f64; 2],
    exact: &dyn Fn(&[f64]) -> f64,
) -> Option<f64> {
    let along = contact_tangent(direction);
    let mut profile: Vec<(f64, f64, f64)> = solution
        .pressure_points()
        .into_iter()
        .map(|(x, p)| (along[0] * x[0] + along[1] * x[1], p, exact(&x)))
        .collect();
    profile.sort_by(|a, b| a.0.total_cmp(&b.0));
    let peak = solution
        .contact_edges
        .iter()
        .flat_map(|e| [e.ends[0], e.midpoint(), e.ends[1]])
        .map(|x| exact(&x))
        .fold(0.0f64, f64::max);
    if !(peak > 0.0 && peak.is_finite()) {
        return None;
    }
    let smooth = SMOOTH_PRESSURE_SHARE * peak;
    let windows: Vec<f64> = profile
        .windows(3)
        .filter(|w| w.iter().all(|p| p.2 >= smooth))
        .map(|w| (w[0].1 - 2.0 * w[1].1 + w[2].1).abs())
        .collect();
    (!windows.is_empty()).then(|| windows.iter().fold(0.0f64, |m, &d| m.max(d)) / peak)
}

/// The comparison of a solution on [`crate::contact_scenes::hertz_mesh`] with Hertz's pressure: the relative
/// L² error, the best fit's in the multiplier's space and the checkerboard measure
/// (see [`HertzErrors`]; P0: 16-point Gauss–Legendre per edge, P1: exact integrals).
pub fn compare_with_hertz(hertz: Hertz, solution: &SignoriniSolution) -> HertzErrors {
    if solution.multiplier == Multiplier::P1 {
        return hertz_p1(hertz, solution);
    }
    let gauss = fem_runtime::gauss_legendre(16);
    let (mut error, mut best, mut norm) = (0.0, 0.0, 0.0);
    for (e, &lambda) in solution.contact_edges.iter().zip(&solution.pressure) {
        let [a, b] = e.ends;
        let l = e.length();
        let at = |s: f64| hertz.pressure(a[0] + s * (b[0] - a[0]));
        let mean: f64 = gauss
            .points
            .iter()
            .zip(&gauss.weights)
            .map(|(&s, &w)| w * at(s))
            .sum();
        for (&s, &w) in gauss.points.iter().zip(&gauss.weights) {
            let p = at(s);
            error += w * l * (lambda - p) * (lambda - p);
            best += w * l * (mean - p) * (mean - p);
            norm += w * l * p * p;
        }
    }
    HertzErrors {
        oscillation: checkerboard(solution, &hertz),
        pressure_l2_error: (error / norm).sqrt(),
        best_fit_l2_error: (best / norm).sqrt(),
    }
}

/// The relative L² errors against Hertz's pressure of a solution on the half block
/// ([`crate::contact_scenes::gap_block_mesh`]) and of the best P0 fit on its edges, over the whole contact line
/// (each half edge and its mirror image), with the exact integrals of
/// [`Hertz::relative_l2_error_p0`].
pub fn compare_gap_block(hertz: &Hertz, solution: &SignoriniSolution) -> (f64, f64) {
    let mut intervals = Vec::with_capacity(2 * solution.contact_edges.len());
    let mut values = Vec::with_capacity(intervals.capacity());
    for (e, &p) in solution.contact_edges.iter().zip(&solution.pressure) {
        let (a, c) = (e.ends[0][0], e.ends[1][0]);
        let (x0, x1) = (a.min(c), a.max(c));
        intervals.push([x0, x1]);
        intervals.push([-x1, -x0]);
        values.extend([p, p]);
    }
    (
        hertz.relative_l2_error_p0(&intervals, &values),
        hertz.best_p0_relative_l2_error(&intervals),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A P0 pressure along `0 ≤ x ≤ 1.2 b` on edges of width `h`: Hertz's at the
    /// midpoints with a checkerboard of amplitude `noise` on top.
    fn checkered(hertz: &Hertz, h: f64, noise: f64) -> SignoriniSolution {
        let n = (1.2 * hertz.half_width() / h).ceil() as usize;
        let edges: Vec<ContactEdge> = (0..n)
            .map(|k| ContactEdge {
                edge: k,
                cell: k,
                local: 0,
                ends: [[k as f64 * h, 0.0], [(k + 1) as f64 * h, 0.0]],
            })
            .collect();
        let pressure = edges
            .iter()
            .enumerate()
            .map(|(k, e)| {
                let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
                (hertz.pressure(e.midpoint()[0]) + sign * noise).max(0.0)
            })
            .collect();
        SignoriniSolution {
            pressure,
            multiplier: Multiplier::P0,
            edge_dofs: (0..n).map(|k| [k, k]).collect(),
            contact_edges: edges,
            total_contact_force: [0.0; 2],
            applied_load: [0.0; 2],
            discretized_load: 0.0,
            contact_half_width: 0.0,
            max_contact_pressure: 0.0,
        }
    }

    /// The checkerboard measure against any exact pressure is Hertz's own measure when
    /// the exact pressure is Hertz's: the same windows (p ≥ 0.6 p_max exactly inside
    /// 0.8 b), normalized by the largest pressure sampled on Γ_C, p_max to O((h/b)²);
    /// a checkerboard of amplitude ε shows as 4ε/p_max, give or take the smooth
    /// pressure's own second difference.
    #[test]
    fn the_checkerboard_against_hertz_is_hertzs_own_measure() {
        let hertz = Hertz {
            radius: 1.0,
            young: 1000.0,
            poisson: 0.3,
            load: 1.0,
        };
        let h = hertz.half_width() / 16.0;
        // the smooth pressure's own second difference, at most 4.7 (h/b)² p_max
        let smooth = checkerboard(&checkered(&hertz, h, 0.0), &hertz);
        assert!(smooth > 0.0 && smooth <= 4.7 / 256.0, "{smooth}");
        for noise in [0.0, 0.05, 0.5] {
            let solution = checkered(&hertz, h, noise);
            let own = checkerboard(&solution, &hertz);
            let against =
                checkerboard_against(&solution, [0.0, -1.0], &|x: &[f64]| hertz.pressure(x[0]))
                    .unwrap();
            assert!(
                (own - against).abs() <= 1e-3 * own.max(1e-3),
                "ε = {noise}: {own} against {against}"
            );
            if noise > 0.0 {
                let expected = 4.0 * noise / hertz.max_pressure();
                assert!(
                    (own - expected).abs() <= smooth,
                    "ε = {noise}: {own}, expected {expected} within {smooth}"
                );
            }
        }
    }

    /// The best continuous P1 fit of a scene file's exact pressure (CG on the assembled
    /// mass matrix, composite Gauss quadrature) against Hertz's own (a tridiagonal
    /// elimination with exact integrals), on graded nodes across the square-root edge at
    /// b: to 1 %, the quadrature's error at that edge (to 1e-3 on nodes inside 0.9 b).
    #[test]
    fn the_best_p1_fit_matches_hertzs_closed_form() {
        let hertz = Hertz {
            radius: 1.0,
            young: 1000.0,
            poisson: 0.3,
            load: 1.0,
        };
        let b = hertz.half_width();
        let nodes: Vec<f64> = (0..=24)
            .map(|k| 1.5 * b * (k as f64 / 24.0).powf(1.3))
            .collect();
        let edges: Vec<([[f64; 2]; 2], [usize; 2])> = nodes
            .windows(2)
            .enumerate()
            .map(|(k, w)| ([[w[0], 0.0], [w[1], 0.0]], [k, k + 1]))
            .collect();
        let exact = crate::data::Data::shared(move |x| hertz.pressure(x[0]));
        let ours = super::super::file::best_p1_error(&edges, nodes.len(), &exact);
        let closed = hertz.best_p1_relative_l2_error(&nodes);
        assert!(
            (ours - closed).abs() <= 1e-2 * closed,
            "{ours} against {closed}"
        );
    }
}
