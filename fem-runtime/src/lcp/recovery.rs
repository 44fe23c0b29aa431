//! The multiplier on fine meshes: how many digits the eliminated Λ loses to
//! cancellation when `C ~ αh^p` is tiny, and its recovery from one saddle-point solve on
//! the converged active set (docs/mathematics.md §5).

use super::*;

impl Lcp {
    /// How many digits the eliminated multiplier `lambda` loses to cancellation: the
    /// rounding `ε‖G_b‖∞‖C_b⁻¹‖∞` of `Λ_b = C_b⁻¹(G − BU)_b` (`ε|G_k| / C_k` for P0)
    /// at its worst block among those where `lambda` is nonzero, relative to the
    /// multiplier's natural size under the load `Λ* = ‖F‖∞/‖Bᵀ‖∞`
    /// ([`Lcp::multiplier_scale`]), or to `‖lambda‖∞` where `F = 0` (contact driven by
    /// the obstacle or the boundary data alone). Near 1 the eliminated Λ is rounding
    /// noise: on fine meshes `C = αh⁵` falls below the rounding of `G − BU ≈ CΛ`.
    ///
    /// The load's scale comes first because `‖lambda‖∞` can be far larger than the
    /// multiplier's typical value (P0 multipliers resolve the point forces at a beam's
    /// contact edge as ~force/h): relative to it the noise in `∫λ` would be understated.
    ///
    /// 0 when `lambda ≡ 0`: the elimination clips every inactive constraint's Λ to an
    /// exact 0, so there is nothing to be noisy (before, the estimate divided by the load
    /// scale alone and reported ~1e302 at zero load).
    pub fn elimination_noise(&self, lambda: &[f64]) -> f64 {
        let largest = lambda.iter().fold(0.0f64, |m, l| m.max(l.abs()));
        if largest == 0.0 || !largest.is_finite() {
            return if largest == 0.0 { 0.0 } else { f64::INFINITY };
        }
        let load_scale = self.multiplier_scale();
        let scale = if load_scale > 0.0 {
            load_scale
        } else {
            largest
        };
        let carries = |range: std::ops::Range<usize>| {
            lambda
                .get(range)
                .is_some_and(|l| l.iter().any(|&l| l != 0.0))
        };
        let mut dense = [0.0; BLOCK_ENTRIES];
        let mut inverse = [0.0; BLOCK_ENTRIES];
        let noise = self
            .blocks()
            .filter_map(|block| {
                if !carries(block.range()) {
                    return None;
                }
                let k = block.start;
                if block.size == 1 {
                    return (self.c[k] > 0.0)
                        .then(|| f64::EPSILON * self.g[k].abs() / (self.c[k] * scale));
                }
                let s = block.size;
                block.dense(&self.c, &mut dense[..s * s]);
                if !small_inverse(&dense, s, &mut inverse) {
                    return None;
                }
                let inverse_norm = (0..s)
                    .map(|i| (0..s).map(|j| inverse[i * s + j].abs()).sum::<f64>())
                    .fold(0.0, f64::max);
                let g = self.g[block.range()]
                    .iter()
                    .fold(0.0f64, |m, g| m.max(g.abs()));
                Some(f64::EPSILON * g * inverse_norm / scale)
            })
            .fold(0.0, f64::max);
        // each constraint is complete on one part of a shared LCP (empty elsewhere)
        self.largest(noise)
    }

    /// An estimate of the 1-norm condition number `κ₁(A) = ‖A‖₁‖A⁻¹‖₁` of the primal
    /// matrix, `‖A⁻¹‖₁` by Hager's estimator (Higham, *Accuracy and Stability of
    /// Numerical Algorithms*, 2nd ed., §15.3: at most ten solves with one Cholesky
    /// factorization; a lower bound, usually within a factor 3).
    ///
    /// # Errors
    /// Those of the factorization (`A` not positive definite).
    pub fn primal_condition_estimate(&self) -> Result<f64> {
        let n = self.n();
        if n == 0 {
            return Ok(1.0);
        }
        let pattern = self
            .a
            .symbolic()
            .to_owned()
            .map_err(|e| Error::LinearSolve(format!("the pattern of A: {e:?}")))?;
        let factor = Cholesky::analyse(&pattern)?.factor_cholesky(&self.a)?;
        let mut x = vec![1.0 / n as f64; n];
        let mut estimate = 0.0;
        for _ in 0..5 {
            let y = factor.solve(&x)?;
            estimate = y.iter().map(|v| v.abs()).sum::<f64>();
            let sign: Vec<f64> = y
                .iter()
                .map(|&v| if v >= 0.0 { 1.0 } else { -1.0 })
                .collect();
            // A is symmetric: A⁻ᵀ = A⁻¹
            let z = factor.solve(&sign)?;
            let (j, largest) = z.iter().enumerate().fold((0, 0.0f64), |(j, m), (i, v)| {
                if v.abs() > m {
                    (i, v.abs())
                } else {
                    (j, m)
                }
            });
            let zx: f64 = z.iter().zip(&x).map(|(z, x)| z * x).sum();
            if largest <= zx {
                break;
            }
            x = vec![0.0; n];
            x[j] = 1.0;
        }
        Ok(row_sum_norm(&self.a) * estimate)
    }

    /// How far `u` may be off through the rounding of the contact rows, in the units of
    /// U: on a constraint in contact, `B_k U = G_k − (CΛ)_k` is known only to
    /// `ε(Σ_j|B_kj U_j| + Σ_l|C_kl Λ_l| + |G_k|)`, which moves U along the row by that
    /// over `Σ_j |B_kj|`; the largest such value over the constraints with `Λ_k > 0`.
    ///
    /// The stabilized rows subtract terms of the size of the load (`αh^k f`) to leave the
    /// obstacle's own part: where the load dwarfs the obstacle the answer is rounding,
    /// while the KKT residual, relative to those same large terms, stays at 1e-16. The
    /// caller compares the value with the size of U, ψ or the boundary data.
    ///
    /// # Panics
    /// If `u.len() != n` or `lambda.len() != m`.
    pub fn primal_rounding(&self, u: &[f64], lambda: &[f64]) -> f64 {
        assert!(u.len() == self.n() && lambda.len() == self.m());
        let c_terms = self.c_times_abs(lambda);
        let rounding = self
            .b_rows
            .iter()
            .enumerate()
            .filter(|&(k, _)| lambda[k] > 0.0)
            .map(|(k, row)| {
                let b_norm: f64 = row.iter().map(|&(_, v)| v.abs()).sum();
                let terms: f64 = row.iter().map(|&(j, v)| (v * u[j]).abs()).sum::<f64>()
                    + c_terms[k]
                    + self.g[k].abs();
                if b_norm > 0.0 {
                    f64::EPSILON * terms / b_norm
                } else {
                    0.0
                }
            })
            .fold(0.0, f64::max);
        // each constraint is complete on one part of a shared LCP (empty elsewhere)
        self.largest(rounding)
    }
}

/// The saddle-point system `[[A, −B̃ᵀ], [−B̃, D]]` of the primal–dual active set method with
/// a fixed pattern: active rows carry `B_k` and, within their block of `C`, `D_kl = −C_kl`
/// between active constraints; inactive rows `Λ_k = 0` (`B̃_k = 0`, `D_kk = −1` scaled,
/// no coupling), so one symbolic LU serves every iteration.
pub(super) struct SaddlePoint {
    pub(super) symbolic: SymbolicSparseColMat<usize>,
    pub(super) a_positions: Vec<usize>,
    /// For row k of B: positions of (n+k, j) and (j, n+k) per entry.
    pub(super) b_positions: Vec<Vec<(usize, usize)>>,
    /// For each block of C: the positions of (n+k, n+l), k and l in the block (k-major).
    pub(super) block_positions: Vec<Vec<usize>>,
}

impl SaddlePoint {
    pub(super) fn new(lcp: &Lcp) -> Self {
        let (n, m) = (lcp.n(), lcp.m());
        let pattern = Pattern::new(&lcp.a, n + m, |columns| {
            for (k, row) in lcp.b_rows.iter().enumerate() {
                for &(j, _) in row {
                    columns[j].push(n + k);
                    columns[n + k].push(j);
                }
            }
            for block in lcp.blocks() {
                for k in block.range() {
                    for l in block.range() {
                        columns[n + l].push(n + k);
                    }
                }
            }
        });
        let a_positions = pattern.positions_of(&lcp.a);
        let b_positions = lcp
            .b_rows
            .iter()
            .enumerate()
            .map(|(k, row)| {
                row.iter()
                    .map(|&(j, _)| (pattern.position(n + k, j), pattern.position(j, n + k)))
                    .collect()
            })
            .collect();
        let block_positions = lcp
            .blocks()
            .map(|block| {
                block
                    .range()
                    .flat_map(|k| block.range().map(move |l| (k, l)))
                    .map(|(k, l)| pattern.position(n + k, n + l))
                    .collect()
            })
            .collect();
        Self {
            symbolic: pattern.symbolic(),
            a_positions,
            b_positions,
            block_positions,
        }
    }

    pub(super) fn matrix(&self, lcp: &Lcp, active: &[bool]) -> SparseMatrix {
        let mut values = values_of_a(&self.symbolic, &self.a_positions, &lcp.a);
        for (k, row) in lcp.b_rows.iter().enumerate() {
            if active[k] {
                for (&(_, v), &(p, q)) in row.iter().zip(&self.b_positions[k]) {
                    values[p] = -v;
                    values[q] = -v;
                }
            }
        }
        for (block, positions) in lcp.blocks().zip(&self.block_positions) {
            let s = block.size;
            for (i, k) in block.range().enumerate() {
                for (j, l) in block.range().enumerate() {
                    let p = positions[i * s + j];
                    if active[k] && active[l] {
                        values[p] = -block.entry(&lcp.c, i, j);
                    } else if k == l {
                        // Λ_k = 0, scaled like the row so that the matrix stays balanced
                        let scale = lcp.b_rows[k]
                            .iter()
                            .fold(0.0f64, |m, &(_, v)| m.max(v.abs()));
                        values[p] = -scale.max(lcp.c[k]).max(f64::MIN_POSITIVE);
                    }
                }
            }
        }
        SparseColMat::new(self.symbolic.clone(), values)
    }
}

/// Recovers `(U, Λ)` on the active set `{Λ_k > 0}` of a converged solution from one
/// saddle-point solve, in which Λ comes from the equilibrium instead of
/// `C⁻¹(G − BU)`: on fine meshes, where `C = αh⁵` is below the rounding of `G − BU`, this is the
/// difference between a multiplier and rounding noise. Keeps the solution it was given
/// when the recovered one does not satisfy the KKT conditions as well.
pub fn recover_multiplier(
    lcp: &Lcp,
    solution: LcpSolution,
    refinement_steps: usize,
) -> Result<LcpSolution> {
    let clock = Instant::now();
    lcp.check_shapes()?;
    let (n, m) = (lcp.n(), lcp.m());
    if solution.u.len() != n || solution.lambda.len() != m {
        return Err(Error::Input(format!(
            "a solution with {} primal values and {} multipliers for a problem with {n} and {m}",
            solution.u.len(),
            solution.lambda.len()
        )));
    }
    let active: Vec<bool> = solution.lambda.iter().map(|&l| l > 0.0).collect();
    let saddle = SaddlePoint::new(lcp);
    let k_matrix = saddle.matrix(lcp, &active);
    let factor = crate::lcp::cholesky::LuSolver::analyse(&saddle.symbolic)?.factor(&k_matrix)?;
    let mut rhs = lcp.f.clone();
    rhs.extend((0..m).map(|k| if active[k] { -lcp.g[k] } else { 0.0 }));
    let x = factor.solve_refined(&k_matrix, &rhs, refinement_steps)?;
    let u = x[..n].to_vec();
    let lambda: Vec<f64> = x[n..]
        .iter()
        .zip(&active)
        .map(|(&l, &a)| if a { l.max(0.0) } else { 0.0 })
        .collect();
    let residual = lcp.kkt_residual(&u, &lambda);
    // The eliminated Λ's noise is invisible to the (backward-error) residual, so the
    // recovered solution is taken whenever it satisfies the KKT conditions to 1e-8.
    if residual <= 1e-8 {
        // Λ now comes from the equilibrium `BᵀΛ = AU − F`, whose solve loses digits to
        // A's conditioning: bernoulli-flat at 3000–4000 Hermite elements had ∫λ_h off by
        // 2–6 % with an elimination estimate of 1e-3. The larger of the two is the
        // honest "up to".
        let conditioning = lcp
            .primal_condition_estimate()
            .map_or(0.0, |kappa| f64::EPSILON * kappa);
        let multiplier_noise = lcp.elimination_noise(&lambda).max(conditioning);
        Ok(LcpSolution {
            u,
            lambda,
            kkt_residual: residual,
            seconds: solution.seconds + clock.elapsed().as_secs_f64(),
            factorizations: solution.factorizations + 1,
            low_rank_updates: solution.low_rank_updates,
            // the recovery helps, but with κ this large it is no guarantee: keep the estimate
            multiplier_noise,
            ..solution
        })
    } else {
        Ok(solution)
    }
}
