//! The same LCP as a convex quadratic program, solved by clarabel's interior-point
//! method: an independent path that shares nothing with Newton but the blocks, and the
//! solver of the plain mixed method (`C = 0`).

use super::*;

/// The LCP as a convex QP solved by clarabel (an interior-point method independent of
/// the Newton path): `min ½UᵀAU − FᵀU + ½ΛᵀCΛ` over `BU + CΛ ≥ G`. Its KKT conditions
/// are the LCP with `Λ` the constraint's multiplier (for `C` positive definite also
/// `Λ = C⁻¹CΛ`, the primal Λ); with `C = 0` it is the plain mixed method
/// `min ½UᵀAU − FᵀU` over `BU ≥ G`. Unlike a formulation with `C⁻¹`, nothing here grows
/// like `h⁻⁵`.
pub fn quadratic_program(lcp: &Lcp) -> Result<LcpSolution> {
    let clock = Instant::now();
    lcp.check_shapes()?;
    check_c(lcp)?;
    let qp = ScaledQp::of(lcp);
    let (u, lambda, status, iterations) = qp.solve(lcp)?;
    let mut kkt_residual = lcp.kkt_residual(&u, &lambda);
    if qp.with_lambda {
        // Check the result, not the solver's word (see `Lcp::newton_correction`).
        let correction = lcp.newton_correction(&u)?;
        if correction > 1e-6 {
            return Err(Error::NotConverged {
                solver: "clarabel",
                detail: format!(
                    "it reported {status:?}, but a Newton step from its point changes U by {correction:.1e} (relative): the QP is too ill-conditioned for the interior-point method in double precision at this size"
                ),
            });
        }
        kkt_residual = kkt_residual.max(correction);
    }
    let solution = LcpSolution {
        u,
        lambda,
        iterations,
        kkt_residual,
        seconds: clock.elapsed().as_secs_f64(),
        factorizations: iterations,
        low_rank_updates: 0,
        multiplier_noise: 0.0,
        iterative_steps: 0,
        krylov_iterations: 0,
    };
    if qp.with_lambda {
        return Ok(solution);
    }
    // The plain method (C = 0): polish, as OSQP does. The interior point leaves every
    // Λ_k a little positive and every constraint a little slack, at its tolerance (a
    // Hertz P1–P0 run came back "Solved" with a complementarity of 3e-3 measured
    // componentwise). Saddle-point solves on the active set it identifies, corrected as
    // the primal–dual active-set method does (drop Λ_k < 0, add R_k < 0), give the
    // solution to the rounding of those solves; kept only if its KKT residual is smaller.
    Ok(polish(lcp, solution, clock))
}

/// Refuses a `C` that is not positive semidefinite: a negative or NaN diagonal, a
/// coupled block that is not positive definite.
///
/// # Errors
/// [`Error::Input`] naming the fault.
fn check_c(lcp: &Lcp) -> Result<()> {
    if lcp.c.iter().any(|&c| c.is_nan() || c < 0.0) {
        return Err(Error::Input("C must be non-negative".into()));
    }
    let mut dense = [0.0; BLOCK_ENTRIES];
    for block in lcp.blocks().filter(|b| b.size > 1) {
        let s = block.size;
        block.dense(&lcp.c, &mut dense[..s * s]);
        if !small_cholesky(&mut dense, s) {
            return Err(Error::Input(format!(
                "C must be positive semidefinite, and its coupled block of constraints {} to {} is not positive definite",
                block.start,
                block.start + s - 1
            )));
        }
    }
    Ok(())
}

/// The LCP as clarabel's QP `min ½xᵀPx + qᵀx` over `A_c x + s = b`, `s ≥ 0`, scaled:
/// `U = D y` with the Jacobi scaling `D = diag(A)^{-1/2}` (thin beams have diag(A)
/// spread over many decades, t⁻²h⁻¹ against h, which stalls the interior-point method
/// unscaled), each constraint row by `r_k` to unit size, and the data by `1/σ`.
struct ScaledQp {
    p: clarabel::algebra::CscMatrix<f64>,
    q: Vec<f64>,
    a_c: clarabel::algebra::CscMatrix<f64>,
    b: Vec<f64>,
    /// `D`.
    scale: Vec<f64>,
    /// `r_k`.
    row_scale: Vec<f64>,
    /// σ.
    data_scale: f64,
    /// Whether `x` holds Λ beside `y` (`C ≠ 0`).
    with_lambda: bool,
}

impl ScaledQp {
    fn of(lcp: &Lcp) -> Self {
        use clarabel::algebra::CscMatrix;
        let (n, m) = (lcp.n(), lcp.m());
        let with_lambda = lcp.c.iter().any(|&c| c > 0.0);
        let nx = if with_lambda { n + m } else { n };
        let scale = jacobi_scale(&lcp.a);
        let c_entries = c_by_rows(lcp);
        let row_scale: Vec<f64> = (0..m)
            .map(|k| {
                let largest = lcp.b_rows[k]
                    .iter()
                    .map(|&(j, v)| (v * scale[j]).abs())
                    .chain(c_entries[k].iter().map(|&(_, v)| v.abs()))
                    .fold(0.0, f64::max);
                if largest > 0.0 {
                    1.0 / largest
                } else {
                    1.0
                }
            })
            .collect();
        let p = objective_matrix(lcp, &scale, with_lambda.then_some(&c_entries[..]));
        let mut q: Vec<f64> = lcp.f.iter().zip(&scale).map(|(f, d)| -f * d).collect();
        q.resize(nx, 0.0);
        // −BU − CΛ + s = −G, s ≥ 0, row k scaled by r_k
        let (mut ti, mut tj, mut tv) = (Vec::new(), Vec::new(), Vec::new());
        for (k, row) in lcp.b_rows.iter().enumerate() {
            for &(j, v) in row {
                ti.push(k);
                tj.push(j);
                tv.push(-v * scale[j] * row_scale[k]);
            }
            if with_lambda {
                for &(l, v) in &c_entries[k] {
                    ti.push(k);
                    tj.push(n + l);
                    tv.push(-v * row_scale[k]);
                }
            }
        }
        let mut b: Vec<f64> = lcp.g.iter().zip(&row_scale).map(|(g, r)| -g * r).collect();
        // The LCP is linear in the data (F, G): scaled by 1/σ, its solution is (U, Λ)/σ.
        // Unit data keep clarabel's absolute tolerances meaningful (a load of 1e-12 was
        // "solved" to a wrong answer at the gap tolerance, one of 1e50 declared dual
        // infeasible).
        // Only for the plain method, which the polish completes: with C > 0 (clarabel
        // as the independent check of Newton) the unit data asked more of the interior
        // point than it reaches on the thin beams' systems (a Newton step from its point
        // then moved U by 3e-6).
        let data_scale = q.iter().chain(&b).fold(0.0f64, |m, v| m.max(v.abs()));
        let data_scale = if !with_lambda && data_scale > 0.0 && data_scale.is_finite() {
            data_scale
        } else {
            1.0
        };
        q.iter_mut()
            .chain(b.iter_mut())
            .for_each(|v| *v /= data_scale);
        Self {
            p,
            q,
            a_c: CscMatrix::new_from_triplets(m, nx, ti, tj, tv),
            b,
            scale,
            row_scale,
            data_scale,
            with_lambda,
        }
    }

    /// Solves it by clarabel: `(U, Λ)` unscaled, the status and the iterations.
    ///
    /// # Errors
    /// Settings or a problem clarabel rejects, infeasible constraints, and any status
    /// short of (almost) solved.
    fn solve(
        &self,
        lcp: &Lcp,
    ) -> Result<(Vec<f64>, Vec<f64>, clarabel::solver::SolverStatus, usize)> {
        use clarabel::solver::{DefaultSolver, IPSolver, NonnegativeConeT, SolverStatus};
        let (n, m) = (lcp.n(), lcp.m());
        let cones = [NonnegativeConeT(m)];
        let mut solver =
            DefaultSolver::new(&self.p, &self.q, &self.a_c, &self.b, &cones, settings()?)
                .map_err(|e| Error::Input(format!("clarabel rejected the problem: {e:?}")))?;
        solver.solve();
        let status = solver.solution.status;
        if !matches!(status, SolverStatus::Solved | SolverStatus::AlmostSolved) {
            let infeasible = matches!(
                status,
                SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible
            );
            return Err(if infeasible {
                Error::Input("the constraints are infeasible (clarabel found a certificate)".into())
            } else {
                Error::NotConverged {
                    solver: "clarabel",
                    detail: format!(
                        "status {status:?} after {} iterations",
                        solver.solution.iterations
                    ),
                }
            });
        }
        let u: Vec<f64> = solver.solution.x[..n]
            .iter()
            .zip(&self.scale)
            .map(|(y, d)| y * d * self.data_scale)
            .collect();
        // the multiplier of the scaled row k is Λ_k / r_k
        let lambda: Vec<f64> = solver.solution.z[..m]
            .iter()
            .zip(&self.row_scale)
            .map(|(z, r)| (z * r * self.data_scale).max(0.0))
            .collect();
        Ok((u, lambda, status, solver.solution.iterations as usize))
    }
}

/// clarabel's settings for these QPs.
///
/// # Errors
/// Settings clarabel refuses.
fn settings() -> Result<clarabel::solver::DefaultSettings<f64>> {
    clarabel::solver::DefaultSettingsBuilder::default()
        .verbose(false)
        .max_iter(400)
        // Relative to the unit data. On some plain-method problems the method stalls
        // short of these and reports AlmostSolved at its reduced accuracy; the polish
        // recovers those.
        .tol_gap_abs(1e-13)
        .tol_gap_rel(1e-13)
        .tol_feas(1e-13)
        .tol_ktratio(1e-10)
        // The default static regularization (1e-8) perturbs systems whose smallest
        // relative eigenvalue is ~h⁴ (bending) far more than that.
        .static_regularization_constant(1e-15)
        .static_regularization_proportional(f64::EPSILON * f64::EPSILON)
        .iterative_refinement_reltol(1e-15)
        .iterative_refinement_abstol(1e-15)
        .iterative_refinement_max_iter(40)
        .build()
        .map_err(|e| Error::Input(format!("clarabel settings: {e:?}")))
}

/// `diag(A)^{-1/2}` (1 where a diagonal entry is not positive).
fn jacobi_scale(a: &SparseMatrix) -> Vec<f64> {
    let (col_ptr, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    let mut scale = vec![1.0; a.ncols()];
    for (j, s) in scale.iter_mut().enumerate() {
        for k in col_ptr[j]..col_ptr[j + 1] {
            if rows[k] == j && vals[k] > 0.0 {
                *s = 1.0 / vals[k].sqrt();
            }
        }
    }
    scale
}

/// The entries of C by row: `(l, C_kl)` within each block, `l` ascending, the diagonal
/// always.
fn c_by_rows(lcp: &Lcp) -> Vec<Vec<(usize, f64)>> {
    let mut rows_of_c = vec![Vec::new(); lcp.m()];
    for block in lcp.blocks() {
        for (i, k) in block.range().enumerate() {
            for (j, l) in block.range().enumerate() {
                let v = block.entry(&lcp.c, i, j);
                if v != 0.0 || k == l {
                    rows_of_c[k].push((l, v));
                }
            }
        }
    }
    rows_of_c
}

/// The upper triangle of `blockdiag(DAD, C)` (`C` by rows where the QP holds Λ).
fn objective_matrix(
    lcp: &Lcp,
    scale: &[f64],
    c_entries: Option<&[Vec<(usize, f64)>]>,
) -> clarabel::algebra::CscMatrix<f64> {
    let (n, m) = (lcp.n(), lcp.m());
    let (col_ptr, rows, vals) = (
        lcp.a.symbolic().col_ptr(),
        lcp.a.symbolic().row_idx(),
        lcp.a.val(),
    );
    let mut p_ptr = vec![0usize];
    let mut p_rows = Vec::new();
    let mut p_vals = Vec::new();
    for j in 0..n {
        for k in col_ptr[j]..col_ptr[j + 1] {
            if rows[k] <= j {
                p_rows.push(rows[k]);
                p_vals.push(scale[rows[k]] * vals[k] * scale[j]);
            }
        }
        p_ptr.push(p_rows.len());
    }
    let nx = if c_entries.is_some() { n + m } else { n };
    // column l of C: its rows k ≤ l (C is symmetric), ascending
    for (l, entries) in c_entries.into_iter().flatten().enumerate() {
        for &(k, v) in entries.iter().filter(|&&(k, _)| k <= l) {
            p_rows.push(n + k);
            p_vals.push(v);
        }
        p_ptr.push(p_rows.len());
    }
    clarabel::algebra::CscMatrix::new(nx, nx, p_ptr, p_rows, p_vals)
}

/// The active-set polish of an interior-point solution of the plain method (`C = 0`):
/// at most [`POLISH_STEPS`] saddle-point solves.
fn polish(lcp: &Lcp, solution: LcpSolution, clock: Instant) -> LcpSolution {
    let (n, m) = (lcp.n(), lcp.m());
    let a_norm = row_sum_norm(&lcp.a);
    let bu = lcp.b_times(&solution.u);
    let lambda_scale = solution
        .lambda
        .iter()
        .fold(lcp.multiplier_scale(), |s, &l| s.max(l))
        .max(f64::MIN_POSITIVE);
    let u_star = lcp.f.iter().fold(0.0f64, |s, f| s.max(f.abs())) / a_norm.max(f64::MIN_POSITIVE);
    // active where the multiplier outweighs the relative slack
    let mut active: Vec<bool> = (0..m)
        .map(|k| {
            let terms: f64 = lcp.b_rows[k]
                .iter()
                .map(|&(j, v)| (v * solution.u[j]).abs() + v.abs() * u_star)
                .sum::<f64>()
                + lcp.g[k].abs();
            let slack = (bu[k] - lcp.g[k]) / terms.max(f64::MIN_POSITIVE);
            solution.lambda[k] / lambda_scale >= slack
        })
        .collect();
    let saddle = super::recovery::SaddlePoint::new(lcp);
    let Ok(lu) = super::cholesky::LuSolver::analyse(&saddle.symbolic) else {
        return solution;
    };
    for _ in 0..POLISH_STEPS {
        let matrix = saddle.matrix(lcp, &active);
        let Ok(factor) = lu.factor(&matrix) else {
            return solution;
        };
        let mut rhs = lcp.f.clone();
        rhs.extend((0..m).map(|k| if active[k] { -lcp.g[k] } else { 0.0 }));
        let Ok(x) = factor.solve_refined(&matrix, &rhs, 2) else {
            return solution;
        };
        let (u, multipliers) = x.split_at(n);
        let bu = lcp.b_times(u);
        let next: Vec<bool> = (0..m)
            .map(|k| {
                if active[k] {
                    multipliers[k] >= 0.0
                } else {
                    bu[k] - lcp.g[k] < 0.0
                }
            })
            .collect();
        if next == active {
            let lambda: Vec<f64> = multipliers
                .iter()
                .zip(&active)
                .map(|(&l, &a)| if a { l.max(0.0) } else { 0.0 })
                .collect();
            let residual = lcp.kkt_residual(u, &lambda);
            if residual < solution.kkt_residual {
                return LcpSolution {
                    u: u.to_vec(),
                    lambda,
                    kkt_residual: residual,
                    seconds: clock.elapsed().as_secs_f64(),
                    factorizations: solution.factorizations + 1,
                    ..solution
                };
            }
            return solution;
        }
        active = next;
    }
    solution
}

/// Saddle-point solves of the active-set polish; the interior point's active set is
/// right but for a few constraints at the free boundary.
const POLISH_STEPS: usize = 8;
