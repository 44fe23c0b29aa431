//! What a contact problem must satisfy before it is solved, and the start that checks
//! it: the load presses the body onto its foundation, the supports hold the motions
//! contact cannot (the translation along the foundation, a rotation that tips the body),
//! and no pressure acts on the contact boundary itself.

use super::facts::ContactData;
use fem_runtime::obstacle::{Discretization, LevelStart};
use fem_runtime::{Error, Result, TriangleMesh};

/// The start of a contact solve's first level: the body pressed into the foundation
/// (every constraint active) beyond the gaps, by the size of the elastic displacement.
/// The problem is refused where the supports leave the translation along the
/// foundation free; the level is [`LevelStart::TooCoarse`] where its load does not hold
/// the body on ([`load_holds`]) or its constraints cannot balance the load on the free
/// rigid motions ([`constraints_balance`]): a finer level may, and on the finest the
/// reason is the solve's error.
pub(super) fn pressed_start(
    d: &Discretization<TriangleMesh>,
    direction: [f64; 2],
) -> Result<LevelStart> {
    let motions = free_motions(d, direction)?;
    if let Some(reason) =
        load_holds(d, &motions, direction).or_else(|| constraints_balance(d, direction, &motions))
    {
        return Ok(LevelStart::TooCoarse(reason));
    }
    let b = d.boundary().expect("a boundary multiplier");
    let lcp = &d.lcp;
    // -g_k / ∫μ_k ds: the gap at constraint k (∫μ_k ds is |E| for P0)
    let depth = lcp
        .whole(lcp.g.clone())
        .iter()
        .zip(b.integrals())
        .fold(0.0f64, |m, (g, w)| m.max(-g / w));
    // beyond the gaps by the size of the elastic displacement (‖F‖∞/‖A‖∞, both in the
    // units of E): a fixed 1e-3 h was 1e22 times it at E = 1e25, and its multipliers
    // C⁻¹(G − BU) left Newton a Hessian that was not positive definite; of a shared
    // LCP, ‖A‖∞ is the largest of the parts' (a scale, within the few parts sharing a
    // row of the whole)
    let a_norm = lcp.largest(
        (0..lcp.n())
            .map(|j| lcp.a.val_of_col(j).iter().map(|v| v.abs()).sum::<f64>())
            .fold(0.0f64, f64::max),
    );
    let f_norm = norm(&lcp.whole(lcp.f.clone()));
    let elastic = f_norm / a_norm.max(f64::MIN_POSITIVE);
    let scale = 2.0 * depth + elastic.min(1e-3 * d.mesh.max_h());
    Ok(LevelStart::At(
        motions.translation.iter().map(|t| scale * t).collect(),
    ))
}

/// An error when the pressure q is not zero on an edge of both Γ_C and Γ_N. There
/// `σ(u)n = −q n − λ n_c`, so the residual the stabilization penalizes,
/// `λ + σ_n(u) = −q n·n_c`, is not zero at the exact solution: the method would not be
/// consistent (a uniform block, loaded on its top and on its contact side,
/// gave pressures off by 8 % instead of the exact patch value). q is sampled at 17
/// evenly spaced points of each shared edge (3 missed a bump between them), and counts
/// as zero below 1e-12 of its largest value on Γ_N (`cos(πy/2)` is 6e-17 at y = 1).
///
/// # Errors
/// [`Error::Input`] naming the first shared edge where q ≠ 0 and the value there.
pub(super) fn refuse_pressure_on_contact(mesh: &TriangleMesh, input: &ContactData) -> Result<()> {
    let v = mesh.vertices();
    let edge_points = |e: usize| {
        let [a, b] = mesh.edges()[e];
        let (p, q) = (v[a], v[b]);
        (0..=SAMPLES).map(move |k| {
            let t = k as f64 / SAMPLES as f64;
            [p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]
        })
    };
    // zero to the rounding of the pressure's size on Γ_N: cos(πy/2) on y = 1 is 6e-17
    let largest = mesh
        .boundary_edges()
        .iter()
        .filter(|(_, m)| input.load.contains(m))
        .flat_map(|&(e, _)| edge_points(e))
        .map(|x| (input.pressure)(&x).abs())
        .filter(|q| q.is_finite())
        .fold(0.0f64, f64::max);
    for &(e, marker) in mesh.boundary_edges() {
        if !(input.contact.contains(&marker) && input.load.contains(&marker)) {
            continue;
        }
        let [a, b] = mesh.edges()[e];
        let (p, q) = (v[a], v[b]);
        for x in edge_points(e) {
            let pressure = (input.pressure)(&x);
            if pressure.is_nan() || pressure.abs() > 1e-12 * largest {
                return Err(Error::Input(format!(
                    "the edge from ({}, {}) to ({}, {}) is both on the contact boundary Γ_C and on the loaded boundary Γ_N, and the pressure there is {pressure:e} at ({}, {}): the stabilization assumes no load on Γ_C (its residual λ + σ_n(u) would be −q n·n_c at the exact solution, and the pressures wrong); take the edge out of one of the two parts, or make the pressure vanish on it",
                    p[0], p[1], q[0], q[1], x[0], x[1]
                )));
            }
        }
    }
    Ok(())
}

/// Intervals per edge at which [`refuse_pressure_on_contact`] samples the pressure.
const SAMPLES: usize = 16;

/// The rigid motions of a level's discretization that its supports leave free
/// (`A Z = 0`), as free-DOF vectors.
struct FreeMotions {
    /// The unit translation towards the foundation `T`.
    translation: Vec<f64>,
    /// Whether `A T = 0`: no support holds the body along `n_c`.
    translation_free: bool,
    /// A free rotation, where the supports leave one.
    rotation: Option<FreeRotation>,
}

/// The rigid motions the supports of `problem` leave free; frictionless contact resists
/// only along `n_c`, so a support must fix the translation along the tangent (else `A`
/// vanishes on it: singular, and a load with a tangential part has no equilibrium at
/// all — a block pushed sideways "solved" with a 1 % equilibrium error).
///
/// # Errors
/// [`Error::Input`] where the translation along the foundation is free.
fn free_motions(problem: &Discretization<TriangleMesh>, n: [f64; 2]) -> Result<FreeMotions> {
    let f = &problem.lcp.whole(problem.lcp.f.clone());
    let translation = towards_foundation(problem, n);
    let scale = scale_of_a(problem);
    let product = |x: &[f64]| a_times(problem, x);
    let translation_free =
        norm(&translation) > 0.0 && norm(&product(&translation)) <= 1e-10 * scale;
    let tangent = towards_foundation(problem, [-n[1], n[0]]);
    let free = norm(&product(&tangent)) <= 1e-10 * scale;
    if free && norm(&tangent) > 0.0 {
        let work = dot(&translation, f);
        let sliding = dot(&tangent, f);
        let load = if sliding.abs() > 1e-10 * work.abs() {
            format!(" and the load pushes it that way (work {sliding:e} against {work:e} towards the foundation)")
        } else {
            String::new()
        };
        return Err(Error::Input(format!(
            "no support fixes the body along the foundation, the direction ({:.3}, {:.3}){load}: frictionless contact leaves that translation free and the system singular; fix that displacement component on a symmetry line or a roller",
            -n[1], n[0]
        )));
    }
    let rotation = free_rotation(&problem.mesh, problem, [&translation, &tangent]);
    // a roller across a contact direction along neither axis (a tilted foundation)
    // leaves a translation free that is neither along n_c nor along the tangent, and
    // only the contact holds it: its analysis is that of the translation along n_c,
    // scaled to move Γ_C by 1 along n_c (judged by the translation along n_c alone, a
    // body that tipped was solved with its force 7.7 % off and an energy of 5e5)
    let oblique = (!translation_free)
        .then(|| oblique_translation(problem, n))
        .flatten();
    Ok(match oblique {
        Some(translation) => FreeMotions {
            translation,
            translation_free: true,
            rotation,
        },
        None => FreeMotions {
            translation,
            translation_free,
            rotation,
        },
    })
}

/// The free translation `d/(d·n_c)` of `problem` where its supports leave exactly one
/// translation `d` free and `d` is neither along `n_c` nor across it: the smallest
/// eigenvector of the Gram matrix of `A e_x`, `A e_y`, where `A d` vanishes to rounding.
fn oblique_translation(problem: &Discretization<TriangleMesh>, n: [f64; 2]) -> Option<Vec<f64>> {
    let scale = scale_of_a(problem);
    let product = |x: &[f64]| a_times(problem, x);
    let (x, y) = (
        towards_foundation(problem, [1.0, 0.0]),
        towards_foundation(problem, [0.0, 1.0]),
    );
    let (ax, ay) = (product(&x), product(&y));
    let (a, b, c) = (dot(&ax, &ax), dot(&ax, &ay), dot(&ay, &ay));
    // the smaller eigenvalue of [[a, b], [b, c]] and its eigenvector
    let smallest = 0.5 * (a + c) - (0.25 * (a - c) * (a - c) + b * b).sqrt();
    let d = if (smallest - a).abs() >= (smallest - c).abs() {
        [b, smallest - a]
    } else {
        [smallest - c, b]
    };
    let length = d[0].hypot(d[1]);
    if length.is_nan() || length <= 0.0 {
        return None;
    }
    let d = [d[0] / length, d[1] / length];
    let along = d[0] * n[0] + d[1] * n[1];
    let motion: Vec<f64> = x.iter().zip(&y).map(|(x, y)| d[0] * x + d[1] * y).collect();
    let free = norm(&motion) > 0.0 && norm(&product(&motion)) <= 1e-10 * scale;
    (free && along.abs() > 1e-12).then(|| motion.iter().map(|m| m / along).collect())
}

/// Why the load of `problem` does not hold the body on its foundation, if it does not:
/// supports along `n_c` hold the body whatever the load, but a free translation needs
/// the load to press it on (positive work on the translation towards the foundation),
/// and a free rotation needs the load to turn it onto the contact ([`tipping`]).
fn load_holds(
    problem: &Discretization<TriangleMesh>,
    motions: &FreeMotions,
    n: [f64; 2],
) -> Option<String> {
    let work = problem
        .lcp
        .whole(vec![dot(&motions.translation, &problem.lcp.f)])[0];
    if motions.translation_free && (work.is_nan() || work <= 0.0) {
        return Some(format!(
            "the load does not press the body onto the contact boundary (its work on a translation towards the foundation is {work:e} ≤ 0, with q at the quadrature points of the edges of Γ_N: a pressure confined within an edge can fall between them; refine the mesh): the rigid motion is not prevented"
        ));
    }
    tipping(problem, n, motions.rotation.as_ref()?, motions)
}

/// Why the load tips the body, if it does: when the supports leave a rotation free (a
/// rigid motion `Z = R + aT + bS` with `A Z = 0`: `R` the rotation about the origin,
/// `T` and `S` the translations along and across `n_c`), only the contact can hold it.
/// With `s(x) = Z(x)·n_c` the motion of point `x` towards the foundation, the load must
/// do negative work on every free rigid motion that opens every contact (Fichera's
/// condition), over the vertices of Γ_C:
/// - `T` free too: the motions `Z − s_max T` and `s_min T − Z` span those, so
///   `s_min W < f·Z < s_max W` with `W = f·T > 0`: the resultant meets Γ_C;
/// - `T` held by supports: only `βZ`, which opens every contact for `β ≥ 0` if
///   `s ≤ 0` on Γ_C (then `f·Z < 0` is needed), for `β ≤ 0` if `s ≥ 0` (`f·Z > 0`),
///   for every β if `s ≡ 0` (`f·Z = 0`), and for none if `s` changes sign.
///
/// Otherwise there is no equilibrium and Newton's answer misses the load (a
/// block against a wall "solved" with the contact force 39 % off the load).
fn tipping(
    problem: &Discretization<TriangleMesh>,
    n: [f64; 2],
    rotation: &FreeRotation,
    motions: &FreeMotions,
) -> Option<String> {
    let [s_min, s_max] = vertex_range(problem, n, rotation);
    let load = moments(problem, rotation, motions);
    if !load.tips(motions.translation_free, [s_min, s_max]) {
        return None;
    }
    if !motions.translation_free {
        return Some(format!(
            "the load tips the body: the supports leave a rotation free, which only the contact can hold, and the load turns the body away from the contact boundary (its work on that rotation, {:e}, opens every contact): there is no equilibrium; fix the rotation with a support (a displacement component on a second, non-parallel part) or move the load",
            load.moment
        ));
    }
    let across = Across::new(n, rotation.along);
    let [a, b] = across.span([s_min, s_max]);
    let place = format!(
        " (its line {} = {:.3} misses Γ_C, which spans {a:.3} ≤ {} ≤ {b:.3})",
        across.name,
        across.at(load.resultant()),
        across.name
    );
    Some(format!(
        "the load tips the body: the supports leave a rotation free, which only the contact can hold, but the load's resultant passes outside the contact boundary{place}: there is no equilibrium; fix the rotation with a support (a displacement component on a second, non-parallel part) or move the load"
    ))
}

/// Why the constraints of `problem` cannot balance the load on its free rigid motions,
/// if they cannot: [`tipping`]'s condition with the constraints in place of Γ_C's
/// vertices. With `A Z = 0`, `A U − BᵀΛ = F` gives `Σ_k Λ_k ζ_k = f·Z` for `Λ ≥ 0`,
/// `ζ_k = −(BZ)_k = ∫ μ_k s ds`, and `Σ_k Λ_k w_k = W` with `w_k = −(BT)_k = ∫ μ_k ds`:
/// the load's resultant must meet Γ_C between the constraints' weighted means
/// `r_k = ζ_k / w_k` of `s`, which lie inside Γ_C's extent. A coarse level can miss it
/// where a finer one holds it: one P0 edge under a body free to rotate holds no moment
/// at all (its Newton answer was a huge rotation, and the next level started from it
/// ended 55 % off the load).
fn constraints_balance(
    problem: &Discretization<TriangleMesh>,
    n: [f64; 2],
    motions: &FreeMotions,
) -> Option<String> {
    let rotation = motions.rotation.as_ref()?;
    let lcp = &problem.lcp;
    let w: Vec<f64> = lcp
        .whole(lcp.b_times(&motions.translation))
        .iter()
        .map(|b| -b)
        .collect();
    let zeta: Vec<f64> = lcp
        .whole(lcp.b_times(&rotation.motion))
        .iter()
        .map(|b| -b)
        .collect();
    // a constraint whose DOFs supports hold along n_c weighs nothing; only its sign of
    // ζ counts then (the translation is held, and the range's signs are what matter)
    let means = w
        .iter()
        .zip(&zeta)
        .map(|(&w, &z)| if w > 0.0 { z / w } else { z });
    let (r_min, r_max) = means.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), r| {
        (lo.min(r), hi.max(r))
    });
    let load = moments(problem, rotation, motions);
    if !load.tips(motions.translation_free, [r_min, r_max]) {
        return None;
    }
    let reach = if motions.translation_free {
        let across = Across::new(n, rotation.along);
        let [a, b] = across.span([r_min, r_max]);
        format!(
            ": they act on {a:.3} ≤ {name} ≤ {b:.3}, and the load's resultant, as this mesh integrates the load, on {name} = {:.3}",
            across.at(load.resultant()),
            name = across.name
        )
    } else {
        String::new()
    };
    Some(format!(
        "the contact constraints of this mesh ({}) cannot hold the rotation the supports leave free{reach}; refine the mesh",
        lcp.m()
    ))
}

/// A value of `s = Z·n_c` as the coordinate across `n_c` of the line along `n_c` where
/// the rotation moves points by `s` (`s = t·x + a` with `t = (n_y, −n_x)`): `x` or `y`
/// for a contact direction along an axis, else the coordinate along `t`.
struct Across {
    name: String,
    sign: f64,
    along: f64,
}

impl Across {
    fn new(n: [f64; 2], along: f64) -> Self {
        let t = [n[1], -n[0]];
        let (name, sign) = if t[1].abs() < 1e-12 {
            ("x".to_string(), t[0].signum())
        } else if t[0].abs() < 1e-12 {
            ("y".to_string(), t[1].signum())
        } else {
            // oriented with a positive x component, the way a reader sets up an axis
            let sign = t[0].signum();
            (format!("({:.3}, {:.3})·x", sign * t[0], sign * t[1]), sign)
        };
        Self { name, sign, along }
    }

    fn at(&self, s: f64) -> f64 {
        self.sign * (s - self.along)
    }

    /// The coordinates of a range of `s`, in increasing order.
    fn span(&self, [lo, hi]: [f64; 2]) -> [f64; 2] {
        let (a, b) = (self.at(lo), self.at(hi));
        [a.min(b), a.max(b)]
    }
}

/// The range `[s_min, s_max]` of `s = Z·n_c` over the vertices of Γ_C.
fn vertex_range(
    problem: &Discretization<TriangleMesh>,
    n: [f64; 2],
    rotation: &FreeRotation,
) -> [f64; 2] {
    // s(x) = Z(x)·n = (−y, x)·n + a_t (S is normal to n)
    let s_of = |x: [f64; 2]| -x[1] * n[0] + x[0] * n[1] + rotation.along;
    let (lo, hi) = problem
        .boundary()
        .expect("a boundary multiplier")
        .edges
        .iter()
        .flat_map(|e| e.ends)
        .map(s_of)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), s| {
            (lo.min(s), hi.max(s))
        });
    [lo, hi]
}

/// The load's work on a free rotation and on the translation towards the foundation,
/// and the rounding of the first.
struct Moments {
    moment: f64,
    work: f64,
    slack: f64,
}

impl Moments {
    /// Whether this load tips the body, `[s_min, s_max]` the range of `s = Z·n_c` that
    /// holds it ([`tips`]).
    fn tips(&self, translation_free: bool, range: [f64; 2]) -> bool {
        tips(translation_free, range, self.moment, self.work, self.slack)
    }

    /// The `s` where the load's resultant meets the contact plane: `f·Z / f·T`.
    fn resultant(&self) -> f64 {
        self.moment / self.work
    }
}

fn moments(
    problem: &Discretization<TriangleMesh>,
    rotation: &FreeRotation,
    motions: &FreeMotions,
) -> Moments {
    let f = &problem.lcp.whole(problem.lcp.f.clone());
    let motion = &rotation.motion;
    // rounding of the sums: a load doing (almost) no work on a motion is not refused
    let terms: f64 = motion.iter().zip(f).map(|(z, f)| (z * f).abs()).sum();
    Moments {
        moment: dot(motion, f),
        work: dot(&motions.translation, f),
        slack: 1e-9 * terms,
    }
}

/// A rigid motion `Z = R + aT + bS` the supports leave free (`A Z = 0`), as free DOFs,
/// and `a`, its part along the contact direction.
struct FreeRotation {
    motion: Vec<f64>,
    along: f64,
}

/// The rotation about the origin `R` plus the combination of the translations `T`
/// (along `n_c`) and `S` (across) closest to making it free (least squares), where that
/// leaves `A Z = 0` to rounding; `None` where the supports hold every rotation.
fn free_rotation(
    mesh: &TriangleMesh,
    problem: &Discretization<TriangleMesh>,
    [translation, tangent]: [&[f64]; 2],
) -> Option<FreeRotation> {
    let rotation = rotation_about(mesh, problem, [0.0, 0.0]);
    let multiply = |x: &[f64]| a_times(problem, x);
    let (at, as_, ar) = (
        multiply(translation),
        multiply(tangent),
        multiply(&rotation),
    );
    let (tt, ts, ss) = (dot(&at, &at), dot(&at, &as_), dot(&as_, &as_));
    let (tr, sr) = (dot(&at, &ar), dot(&as_, &ar));
    let det = tt * ss - ts * ts;
    let [a_t, b_s] = if det > 1e-12 * tt * ss && det > 0.0 {
        [(-tr * ss + sr * ts) / det, (-sr * tt + tr * ts) / det]
    } else if ss > 0.0 {
        [0.0, -sr / ss]
    } else {
        [0.0, 0.0]
    };
    let motion: Vec<f64> = (0..rotation.len())
        .map(|i| rotation[i] + a_t * translation[i] + b_s * tangent[i])
        .collect();
    let residual: Vec<f64> = (0..rotation.len())
        .map(|i| ar[i] + a_t * at[i] + b_s * as_[i])
        .collect();
    let scale = scale_of_a(problem) * norm(&motion);
    (norm(&motion) > 0.0 && norm(&residual) <= 1e-10 * scale)
        .then_some(FreeRotation { motion, along: a_t })
}

/// Fichera's condition on a free rotation `Z` (see [`tipping`]): whether the load,
/// doing `moment` on `Z` and `work` on the translation towards the foundation, tips the
/// body, `[s_min, s_max]` the range of `s = Z·n_c` over Γ_C's vertices, `slack` the
/// rounding of the sums.
fn tips(
    translation_free: bool,
    [s_min, s_max]: [f64; 2],
    moment: f64,
    work: f64,
    slack: f64,
) -> bool {
    // s at rounding level of the coordinates counts as 0
    let size = s_min.abs().max(s_max.abs()).max(f64::MIN_POSITIVE);
    let (below, above) = (s_min < -1e-12 * size, s_max > 1e-12 * size);
    match (translation_free, below, above) {
        (true, _, _) => {
            let slack = 1e-9 * work.abs() * (s_max - s_min).abs().max(1.0) + slack;
            moment < s_min * work - slack || moment > s_max * work + slack
        }
        // s ≤ 0 on Γ_C: βZ opens every contact for β ≥ 0
        (false, true, false) => moment > slack,
        // s ≥ 0: for β ≤ 0
        (false, false, true) => moment < -slack,
        // s ≡ 0: the contact cannot hold Z at all
        (false, false, false) => moment.abs() > slack,
        // s changes sign: no βZ opens every contact
        (false, true, true) => false,
    }
}

/// `A x` of the whole LCP of `problem`, also where this process holds one part of it
/// ([`fem_runtime::lcp::Lcp::share`]): the parts' products summed.
fn a_times(problem: &Discretization<TriangleMesh>, x: &[f64]) -> Vec<f64> {
    let lcp = &problem.lcp;
    lcp.whole(fem_runtime::lcp::cholesky::multiply(&lcp.a, x))
}

/// The largest absolute entry of `A`, the scale of its rounding (of a shared LCP the
/// largest of the parts', within the few parts that share an entry of the whole).
fn scale_of_a(problem: &Discretization<TriangleMesh>) -> f64 {
    let lcp = &problem.lcp;
    lcp.largest(norm(lcp.a.val())).max(f64::MIN_POSITIVE)
}

fn dot(x: &[f64], y: &[f64]) -> f64 {
    x.iter().zip(y).map(|(a, b)| a * b).sum()
}

/// The largest absolute entry.
fn norm(x: &[f64]) -> f64 {
    x.iter().fold(0.0f64, |m, v| m.max(v.abs()))
}

/// The free-DOF vector of the rotation about `center`, `(−(y − c_y), x − c_x)` at each
/// node.
fn rotation_about(
    mesh: &TriangleMesh,
    problem: &Discretization<TriangleMesh>,
    center: [f64; 2],
) -> Vec<f64> {
    let fields = problem.dofs.fields();
    let mut full = vec![0.0; problem.dofs.dof_count()];
    for (axis, &field) in fields.iter().take(2).enumerate() {
        let (Some(range), Some(map)) = (problem.dofs.range(field), problem.dofs.map(field)) else {
            continue;
        };
        for (d, x) in range.zip(map.nodes(mesh)) {
            full[d] = if axis == 0 {
                center[1] - x[1]
            } else {
                x[0] - center[0]
            };
        }
    }
    // in the primed DOFs of the supports' rotated groups (oblique rollers)
    problem.basis.to_primed(&mut full);
    problem.reduction.free().iter().map(|&d| full[d]).collect()
}

/// The rigid motions of the plane as free-DOF vectors — the translations along x and y
/// and the rotation about the vertices' centroid (about a far origin it would be nearly
/// a translation, and its part independent of them lost to rounding) —: the near null
/// space of elasticity without supports, which GAMG's coarse spaces must reproduce (with
/// the constants alone, its default, CG took 12896 iterations on Hertz at b/h = 128,
/// 1716 with these).
pub(super) fn rigid_motions(problem: &Discretization<TriangleMesh>) -> Vec<Vec<f64>> {
    let vertices = problem.mesh.vertices();
    let count = vertices.len().max(1) as f64;
    let center = vertices
        .iter()
        .fold([0.0, 0.0], |[x, y], v| [x + v[0] / count, y + v[1] / count]);
    vec![
        towards_foundation(problem, [1.0, 0.0]),
        towards_foundation(problem, [0.0, 1.0]),
        rotation_about(&problem.mesh, problem, center),
    ]
}

/// The free-DOF vector of a unit translation along the contact direction: towards the
/// foundation.
pub(super) fn towards_foundation(problem: &Discretization<TriangleMesh>, n: [f64; 2]) -> Vec<f64> {
    let fields = problem.dofs.fields();
    let mut full = vec![0.0; problem.dofs.dof_count()];
    for (axis, &field) in fields.iter().take(2).enumerate() {
        if let Some(range) = problem.dofs.range(field) {
            full[range].fill(n[axis]);
        }
    }
    // in the primed DOFs of the supports' rotated groups (oblique rollers)
    problem.basis.to_primed(&mut full);
    problem.reduction.free().iter().map(|&d| full[d]).collect()
}
