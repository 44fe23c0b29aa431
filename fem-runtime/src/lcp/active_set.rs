//! The primal–dual active set method with one global constant: the classical
//! algorithm, kept for comparison (it can cycle where `A` is not an M-matrix).

use super::*;

/// The primal–dual active set method on the saddle-point system, for when eliminating
/// Λ would lose it to cancellation ([`Lcp::elimination_noise`]): Λ is an unknown of each
/// linear solve, computed from the equilibrium. The step in U is the Newton step on Φ for
/// the current active set, globalized by the same Armijo search; after a full step the
/// next active set is `{Λ_k > 0}` on the active constraints and `{R_k < 0}` on the others.
pub fn primal_dual_active_set(
    lcp: &Lcp,
    start: Option<&[f64]>,
    options: NewtonOptions,
) -> Result<LcpSolution> {
    let clock = Instant::now();
    lcp.check_shapes()?;
    lcp.require_positive_c("the saddle-point active-set method")?;
    let (n, m) = (lcp.n(), lcp.m());
    let mut u = lcp.start_vector(start)?;
    let saddle = SaddlePoint::new(lcp);
    let lu = crate::lcp::cholesky::LuSolver::analyse(&saddle.symbolic)?;
    let mut active = lcp.eliminate(&lcp.b_times(&u)).1;
    let mut lambda: Vec<f64> = vec![0.0; m];
    let mut two_ago: Option<Vec<bool>> = None;
    for iteration in 1..=options.max_iterations {
        let k_matrix = saddle.matrix(lcp, &active);
        let factor = lu.factor(&k_matrix)?;
        let mut rhs = lcp.f.clone();
        rhs.extend((0..m).map(|k| if active[k] { -lcp.g[k] } else { 0.0 }));
        let x = factor.solve_refined(&k_matrix, &rhs, options.refinement_steps)?;
        let (u_new, lambda_new) = x.split_at(n);
        let d: Vec<f64> = u_new.iter().zip(&u).map(|(a, b)| a - b).collect();
        // Armijo on Φ along d (d is the Newton step of Φ for this active set).
        let au = multiply(&lcp.a, &u);
        let bu = lcp.b_times(&u);
        let btl = lcp.bt_times(&lcp.eliminated_multiplier(&bu));
        let slope: f64 = (0..n).map(|i| (au[i] - lcp.f[i] - btl[i]) * d[i]).sum();
        let step = lcp.armijo(&u, &au, &bu, &d, slope).unwrap_or(0.0);
        // On very fine meshes the cells at the free boundary have gaps below the rounding
        // of G − BU and flip without moving U beyond the solve's own accuracy.
        let small_step = max_norm(&d) <= 1e-10 * max_norm(u_new);
        if step == 1.0 {
            u = u_new.to_vec();
            lambda = lambda_new
                .iter()
                .zip(&active)
                .map(|(&l, &a)| if a { l } else { 0.0 })
                .collect();
            // R = BU + CΛ − G with Λ = 0 off the active set (for P0: R_k = B_kU − G_k there)
            let bu = lcp.b_times(&u);
            let c_lambda = lcp.c_times(&lambda);
            let next: Vec<bool> = (0..m)
                .map(|k| {
                    if active[k] {
                        lambda[k] > 0.0
                    } else {
                        bu[k] + c_lambda[k] - lcp.g[k] < 0.0
                    }
                })
                .collect();
            // Converged: the active set reproduces itself (U, Λ solve its equations), or
            // only constraints whose gap is at rounding level keep flipping.
            // A period-2 cycle of cells at the free boundary whose λ and gap are both at
            // rounding level is the same fixed point seen twice.
            let cycling = two_ago.as_ref() == Some(&next);
            // Λ comes from the equilibrium here, so the KKT residual certifies the point
            // whatever the active set still does.
            let certified = lcp
                .kkt_residual(&u, &lambda.iter().map(|l| l.max(0.0)).collect::<Vec<_>>())
                <= options.tolerance;
            if next == active || small_step || cycling || certified {
                let positive: Vec<f64> = lambda.iter().map(|l| l.max(0.0)).collect();
                let residual = lcp.kkt_residual(&u, &positive);
                if residual <= options.tolerance || ((small_step || cycling) && residual <= 1e-8) {
                    return Ok(LcpSolution {
                        u,
                        lambda: positive,
                        iterations: iteration,
                        kkt_residual: residual,
                        seconds: clock.elapsed().as_secs_f64(),
                        factorizations: iteration,
                        low_rank_updates: 0,
                        multiplier_noise: 0.0,
                        iterative_steps: 0,
                        krylov_iterations: 0,
                    });
                }
            }
            two_ago = Some(std::mem::replace(&mut active, next));
        } else {
            u = u.iter().zip(&d).map(|(u, d)| u + step * d).collect();
            active = lcp.eliminate(&lcp.b_times(&u)).1;
        }
    }
    Err(Error::NotConverged {
        solver: "primal–dual active set",
        detail: format!(
            "{} iterations without a settled active set (KKT residual {:e})",
            options.max_iterations,
            lcp.kkt_residual(&u, &lambda.iter().map(|l| l.max(0.0)).collect::<Vec<_>>())
        ),
    })
}
