//! Any level's LCP `A U − Bᵀ Λ = F, 0 ≤ Λ ⊥ B U + C Λ − G ≥ 0` solved by PETSc over MPI:
//! the [`fem_runtime::lcp::external::ExternalSolver`] that `fem-forms solve --backend
//! petsc` hands to the one pipeline (problem, nested levels, report, estimators, output
//! stay those of a native solve).
//!
//! Three formulations ([`Formulation`]):
//! - **primal** (the nodal method, `B = I`, `C = 0`), SNESVI (`vinewtonrsls` unless the
//!   options say otherwise): `F(U) = A U − F` with the bounds `U ≥ G = ψ` on the primal
//!   unknowns themselves;
//! - **eliminated** (the default where `C` is diagonal and positive: P0 multipliers on
//!   cells or boundary edges), a plain SNES without bounds: Λ eliminated constraint by
//!   constraint, `Λ = C⁻¹(G − B U)₊`, leaves the convex C¹ function
//!   `Φ(U) = ½ UᵀAU − FᵀU + ½ Σ_k (G − BU)²₊,k / C_k` (docs/mathematics.md §1), whose
//!   gradient `AU − F − BᵀC⁻¹(G − BU)₊` SNES zeroes with the generalized Hessian
//!   `A + Bᵀ D B` (`D = C⁻¹` on the active constraints, 0 elsewhere; SPD, so CG + GAMG
//!   apply) and its line search on Φ itself (`SNESSetObjective`). This avoids PETSc's
//!   reduced-space VI on a saddle point (Firedrake #2608, #4232), which on the beams
//!   runs out of iterations;
//! - **mixed** (any block-diagonal `C`: P1disc multipliers, or asked for), SNESVI: the
//!   mixed complementarity problem in `x = (U, Λ)`,
//!   `F(x) = [A U − Bᵀ Λ − F; B U + C Λ − G]`, `U` free and the bounds `Λ ≥ 0` on the
//!   multiplier unknowns only. Its Jacobian `[[A, −Bᵀ], [B, C]]` is not symmetric.
//!
//! The Newton systems are solved by MUMPS (LU, or Cholesky where they are SPD) unless
//! the options choose (`-ksp_type cg -pc_type gamg`).
//!
//! Two ways in. Where the pipeline partitions a level (a multiplier on the cells, on
//! triangles: [`PetscLcpSolver`] partitions the cells with PT-Scotch through
//! [`ExternalSolver::partition`]), each rank assembles its own cells and its LCP is one
//! part of the whole ([`Lcp::share`]): every block goes into PETSc with `ADD_VALUES`
//! (the `shared` module), and the whole LCP exists only inside PETSc. Elsewhere (a
//! multiplier on boundary edges, the beams, the nodal method) every rank receives the
//! whole LCP and inserts the rows it owns: contiguous blocks of `U` and of `Λ`, rank
//! `r`'s unknowns numbered `U` block then `Λ` block. Either way the answer comes back
//! whole to every rank and is checked there by the pipeline's KKT residual (reduced over
//! the ranks for a shared LCP, scaled by the assembled `‖A‖∞`).

use crate::{
    minimize, solve_affine, Converged, Defaults, Error, Ghosts, Matrix, Petsc, Result, Vector,
    VectorView,
};
use fem_runtime::lcp::external::{CellGraph, ExternalSolver, Purpose};
use fem_runtime::lcp::{recover_multiplier, ConstraintRows, Lcp, LcpSolution, NewtonOptions};
use std::sync::Mutex;
use std::time::Instant;

/// How an LCP is posed to PETSc (see the module's docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Formulation {
    /// SNESVI on the primal unknowns with the bounds `U ≥ ψ` (the nodal method).
    Primal,
    /// SNES on Φ(U), the multipliers eliminated (diagonal positive `C`).
    Eliminated,
    /// SNESVI on `(U, Λ)` with the bounds `Λ ≥ 0`.
    Mixed,
}

impl Formulation {
    /// `primal`, `eliminated`, `mixed`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Primal => "primal",
            Self::Eliminated => "eliminated",
            Self::Mixed => "mixed",
        }
    }

    /// The formulation called `name` (`eliminated` or `mixed`: the nodal method's is
    /// always primal).
    ///
    /// # Errors
    /// An unknown name (the message lists the known ones).
    pub fn parse(name: &str) -> std::result::Result<Self, String> {
        match name {
            "eliminated" => Ok(Self::Eliminated),
            "mixed" => Ok(Self::Mixed),
            _ => Err(format!(
                "unknown formulation `{name}`: `eliminated` (SNES on Φ(U), the default where C is diagonal) or `mixed` (SNESVI on (U, Λ)); the nodal method is always `primal`"
            )),
        }
    }
}

/// What one LCP solve by PETSc reported, for the command line's report.
#[derive(Clone, Debug, PartialEq)]
pub struct LevelRecord {
    /// The formulation.
    pub formulation: Formulation,
    /// Primal unknowns `n` and multipliers `m`.
    pub unknowns: [usize; 2],
    /// Where the LCP was assembled in parts (each rank its own cells, [`Lcp::share`]),
    /// PETSc's rows this rank owned; `None` where every rank held the whole LCP (a
    /// multiplier on boundary edges, the beams, the nodal method).
    pub rows_here: Option<usize>,
    /// SNES's reason and iteration counts.
    pub converged: Converged,
    /// Wall time of the solve on this rank, in seconds (assembly into PETSc included).
    pub seconds: f64,
    /// What the solve served (the answer, a probe of the model choice, the rounding
    /// experiment).
    pub purpose: Purpose,
}

/// PETSc as the pipeline's complementarity solver (see the module's docs). Made once per
/// process by the command line and leaked for the process's life
/// ([`fem_runtime::lcp::external::External`] holds a `'static` reference);
/// [`PetscLcpSolver::finalize`] ends PETSc and MPI before the process exits.
pub struct PetscLcpSolver {
    petsc: Mutex<Option<OnThread>>,
    preferred: Mutex<Option<Formulation>>,
    records: Mutex<Vec<LevelRecord>>,
    purpose: Mutex<Purpose>,
}

/// PETSc and the thread that initialized it, the only one that may call it: MPI is
/// initialized without thread support (`MPI_THREAD_SINGLE`).
struct OnThread {
    petsc: Petsc,
    thread: std::thread::ThreadId,
}

// SAFETY: PETSc is only reached through the mutex, and only from the thread that
// initialized it (checked at each call, a solve from another thread is refused), so the
// raw handles inside never cross threads.
unsafe impl Send for OnThread {}

impl PetscLcpSolver {
    /// Initializes MPI and PETSc with `options` (PETSc's command-line options as one
    /// string) on this thread, which alone may solve; `formulation` asks for
    /// [`Formulation::Eliminated`] or [`Formulation::Mixed`] where both apply (`None`:
    /// eliminated where `C` is diagonal and positive, mixed elsewhere).
    ///
    /// # Errors
    /// Those of [`Petsc::initialize`].
    pub fn new(options: &str, formulation: Option<Formulation>) -> Result<Self> {
        // ahead of the user's, which override it
        let petsc = Petsc::initialize(&format!("{MUMPS_WORKSPACE} {options}"))?;
        Ok(Self {
            preferred: Mutex::new(formulation),
            petsc: Mutex::new(Some(OnThread {
                petsc,
                thread: std::thread::current().id(),
            })),
            records: Mutex::new(Vec::new()),
            purpose: Mutex::new(Purpose::Answer),
        })
    }

    /// This process's rank and the number of ranks (`(0, 1)` once finalized).
    pub fn rank_and_size(&self) -> (usize, usize) {
        let guard = self.petsc.lock().unwrap_or_else(|e| e.into_inner());
        guard
            .as_ref()
            .map_or((0, 1), |p| (p.petsc.rank(), p.petsc.size()))
    }

    /// Asks for `formulation` in later solves (`None`: the default).
    pub fn set_formulation(&self, formulation: Option<Formulation>) {
        *self.preferred.lock().unwrap_or_else(|e| e.into_inner()) = formulation;
    }

    /// The solves so far, in order (nested iteration: coarsest level first).
    pub fn records(&self) -> Vec<LevelRecord> {
        self.records
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clone()
    }

    /// Ends PETSc, then MPI; later solves are refused.
    pub fn finalize(&self) {
        self.petsc.lock().unwrap_or_else(|e| e.into_inner()).take();
    }

    /// One PETSc solve of `lcp` from `start`, recorded: `(U, Λ)` whole, SNES's report
    /// and the formulation; `full_steps`: the eliminated formulation without its line
    /// search on Φ (unless the options set one). PETSc's lock is released on return (the KKT check that
    /// follows reduces over the ranks through [`ExternalSolver::sum`], which takes it).
    ///
    /// # Errors
    /// A formulation that does not apply, PETSc's errors, a SNES that did not converge.
    fn attempt(
        &self,
        lcp: &Lcp,
        start: Option<&[f64]>,
        full_steps: bool,
    ) -> fem_runtime::Result<(Vec<f64>, Vec<f64>, Converged, Formulation)> {
        let guard = self.petsc.lock().unwrap_or_else(|e| e.into_inner());
        let on = self.on_this_thread(&guard)?;
        let clock = Instant::now();
        let preferred = *self.preferred.lock().unwrap_or_else(|e| e.into_inner());
        let formulation = match &lcp.share {
            None => formulation_of(lcp, preferred),
            Some(_) => shared_formulation(&on.petsc, lcp, preferred),
        }
        .map_err(fem_runtime::Error::Input)?;
        let mut rows_here = None;
        let solved = match (&lcp.share, formulation) {
            (None, Formulation::Eliminated) => solve_eliminated(&on.petsc, lcp, start, full_steps),
            (None, _) => solve_vi(&on.petsc, lcp, start, formulation),
            (Some(share), _) => {
                solve_shared(&on.petsc, lcp, start, formulation, full_steps).map(|s| {
                    // the KKT residual scales by the assembled ‖A‖∞
                    share.set_a_norm(s.a_norm);
                    rows_here = Some(s.rows_here);
                    (s.u, s.lambda, s.converged)
                })
            }
        };
        drop(guard);
        let solver = match formulation {
            Formulation::Eliminated => "PETSc SNES on Φ(U)",
            _ => "PETSc SNESVI",
        };
        let (u, lambda, converged) = solved.map_err(|e| {
            if e.code == 0 {
                fem_runtime::Error::NotConverged {
                    solver,
                    detail: format!(
                        "{} ({})",
                        e.message.trim_start_matches("did not converge: "),
                        e.call
                    ),
                }
            } else {
                // a PETSc error (an option it refuses, a failed factorization), not a
                // Newton iteration that ran out
                fem_runtime::Error::Input(format!("PETSc: {e}"))
            }
        })?;
        self.records
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .push(LevelRecord {
                formulation,
                unknowns: [lcp.n(), lcp.m()],
                rows_here,
                converged: converged.clone(),
                seconds: clock.elapsed().as_secs_f64(),
                purpose: *self.purpose.lock().unwrap_or_else(|e| e.into_inner()),
            });
        Ok((u, lambda, converged, formulation))
    }

    /// PETSc, where it is still running and this is the thread that initialized MPI.
    ///
    /// # Errors
    /// PETSc finalized, or another thread.
    fn on_this_thread<'g>(&self, guard: &'g Option<OnThread>) -> fem_runtime::Result<&'g OnThread> {
        let on = guard.as_ref().ok_or_else(|| {
            fem_runtime::Error::Input("PETSc was finalized: no more solves".into())
        })?;
        if std::thread::current().id() != on.thread {
            return Err(fem_runtime::Error::Input(
                "PETSc is called from a thread other than the one that initialized MPI".into(),
            ));
        }
        Ok(on)
    }
}

impl ExternalSolver for PetscLcpSolver {
    fn name(&self) -> &'static str {
        "petsc"
    }

    fn set_purpose(&self, purpose: Purpose) {
        *self.purpose.lock().unwrap_or_else(|e| e.into_inner()) = purpose;
    }

    fn recorded(&self) -> usize {
        self.records.lock().unwrap_or_else(|e| e.into_inner()).len()
    }

    /// Every rank assembles its own cells: PT-Scotch's partition of `graph` (on one
    /// rank, all of them), unless the nodal method or a whole LCP is asked for.
    fn partition(&self, graph: &CellGraph) -> fem_runtime::Result<Option<Vec<usize>>> {
        let guard = self.petsc.lock().unwrap_or_else(|e| e.into_inner());
        let on = self.on_this_thread(&guard)?;
        let ranks = crate::partition::partition(&on.petsc, graph)
            .map_err(|e| fem_runtime::Error::Input(format!("PETSc's partitioner: {e}")))?;
        let rank = on.petsc.rank();
        Ok(Some(
            (0..ranks.len()).filter(|&c| ranks[c] == rank).collect(),
        ))
    }

    /// `MPI_Allreduce`; called on another thread than MPI's (never, in the pipeline) or
    /// after [`PetscLcpSolver::finalize`], it makes every value NaN: a measure of the
    /// whole that is not one fails its check instead of passing silently.
    fn sum(&self, values: &mut [f64]) {
        let guard = self.petsc.lock().unwrap_or_else(|e| e.into_inner());
        match self.on_this_thread(&guard) {
            Ok(on) => on.petsc.sum_all(values),
            Err(_) => values.fill(f64::NAN),
        }
    }

    /// `MPI_Allreduce` (NaN where [`ExternalSolver::sum`] would be).
    fn max(&self, value: f64) -> f64 {
        let guard = self.petsc.lock().unwrap_or_else(|e| e.into_inner());
        match self.on_this_thread(&guard) {
            Ok(on) => on.petsc.max(value),
            Err(_) => f64::NAN,
        }
    }

    fn relabel(&self, records: std::ops::Range<usize>, purpose: Purpose) {
        let mut all = self.records.lock().unwrap_or_else(|e| e.into_inner());
        let end = records.end.min(all.len());
        for record in &mut all[records.start.min(end)..end] {
            record.purpose = purpose;
        }
    }

    fn solve(&self, lcp: &Lcp, start: Option<&[f64]>) -> fem_runtime::Result<LcpSolution> {
        let clock = Instant::now();
        if lcp.n() == 0 {
            return without_primal_unknowns(lcp);
        }
        let (mut u, mut lambda, mut converged, formulation) = self.attempt(lcp, start, false)?;
        let solver = match formulation {
            Formulation::Eliminated => "PETSc SNES on Φ(U)",
            _ => "PETSc SNESVI",
        };
        let mut kkt_residual = lcp.kkt_residual(&u, &lambda);
        let certified = |r: f64| !r.is_nan() && r <= MAX_KKT_RESIDUAL;
        let relative_stop = matches!(
            converged.reason.as_str(),
            "CONVERGED_SNORM_RELATIVE" | "CONVERGED_FNORM_RELATIVE"
        );
        if !certified(kkt_residual) && relative_stop {
            // Two relative stops short of the KKT tolerance, each resumed once from the
            // answer. The step test (a step below 10⁻⁸ of U): the line search on Φ
            // cannot see a decrease below Φ's rounding, and near the solution it cut the
            // steps until that test stopped the eliminated membrane at 1M unknowns with
            // CG + GAMG, in some runs (the order in which the ranks' contributions add
            // up varies), at a KKT residual of 1.8·10⁻⁸: resumed with full Newton steps,
            // which converge locally (a smaller step tolerance instead failed the
            // beams' line search at rounding). The residual test (10⁻¹⁰ of ∇Φ at the
            // start): a contact start pressed beyond the gaps has a gradient so large
            // that 10⁻¹⁰ of it left Hertz at 428k unknowns at a KKT residual of 4·10⁻⁷;
            // resumed, the test is relative to the answer's gradient.
            let full_steps = converged.reason == "CONVERGED_SNORM_RELATIVE";
            let first = converged.iterations;
            (u, lambda, converged, _) = self.attempt(lcp, Some(&u), full_steps)?;
            converged.iterations += first;
            kkt_residual = lcp.kkt_residual(&u, &lambda);
        }
        let seconds = clock.elapsed().as_secs_f64();
        if !certified(kkt_residual) {
            // PETSc's word is not the answer's certificate: options that stop it early
            // (`-snes_type ksponly`, `-snes_rtol 0.5`) report convergence on a point far
            // from the solution
            return Err(fem_runtime::Error::NotConverged {
                solver,
                detail: format!(
                    "PETSc reported {} after {} iterations, but the KKT residual of its answer is {kkt_residual:.1e} (at most {MAX_KKT_RESIDUAL:.0e} is a solution): not an answer; check --petsc-options",
                    converged.reason, converged.iterations
                ),
            });
        }
        let noise = match formulation {
            Formulation::Eliminated => lcp.elimination_noise(&lambda),
            _ => 0.0,
        };
        let solution = LcpSolution {
            kkt_residual,
            u,
            lambda,
            iterations: converged.iterations,
            seconds,
            factorizations: 0,
            low_rank_updates: 0,
            multiplier_noise: noise,
            iterative_steps: 0,
            krylov_iterations: converged.linear_iterations,
        };
        if noise > MAX_ELIMINATION_NOISE && lcp.share.is_some() {
            return Err(fem_runtime::Error::NotConverged {
                solver,
                detail: format!(
                    "the eliminated Λ is rounding noise ({noise:.0e} relative: C = αh^p lies below the rounding of G − BU), and its recovery by a saddle-point solve needs the whole LCP, which a partitioned assembly does not hold: ask for `--petsc-formulation mixed`, or a larger α"
                ),
            });
        }
        // as the native solver does: where the eliminated Λ loses digits to cancellation
        // (C = αh^p below the rounding of G − BU), Λ from one saddle-point solve on the
        // converged active set
        if noise > MAX_ELIMINATION_NOISE {
            return recover_multiplier(lcp, solution, NewtonOptions::default().refinement_steps);
        }
        Ok(solution)
    }
}

/// An LCP without primal unknowns (a mesh whose every vertex is held: membrane-radial
/// at N = 1): `Λ = C⁻¹ G₊` for a diagonal positive `C`, without PETSc, whose solvers
/// fail on empty matrices (`DIVERGED_LINEAR_SOLVE`).
///
/// # Errors
/// A `C` that is not diagonal and positive.
fn without_primal_unknowns(lcp: &Lcp) -> fem_runtime::Result<LcpSolution> {
    let coupled = lcp.largest(f64::from(u8::from(!lcp.c_blocks.is_empty()))) > 0.0;
    let (c, g) = (lcp.whole(lcp.c.clone()), lcp.whole(lcp.g.clone()));
    if coupled || c.iter().any(|&c| c <= 0.0) {
        return Err(fem_runtime::Error::Input(
            "the level has no free primal unknown and its C is not diagonal and positive: solve it natively (or refine the mesh)".into(),
        ));
    }
    let lambda: Vec<f64> = g.iter().zip(&c).map(|(g, c)| g.max(0.0) / c).collect();
    Ok(LcpSolution {
        kkt_residual: lcp.kkt_residual(&[], &lambda),
        u: Vec::new(),
        lambda,
        iterations: 0,
        seconds: 0.0,
        factorizations: 0,
        low_rank_updates: 0,
        multiplier_noise: 0.0,
        iterative_steps: 0,
        krylov_iterations: 0,
    })
}

/// MUMPS's workspace relaxation, `ICNTL(14)` (percent beyond its analysis's estimate),
/// unless the options set it: at PETSc's default of 20 the adaptive membrane's Hessians
/// on three ranks failed their factorization now and then with `INFOG(1) = −9` (the
/// workspace short by a few thousand entries, 9900 of a 41k-unknown level; the
/// partition, and so the shortfall, varies from run to run), even factored as
/// `LLᵀ` without pivoting ([`crate::Matrix::set_spd`]).
const MUMPS_WORKSPACE: &str = "-mat_mumps_icntl_14 50";

/// SNES's relative tolerance on the residual norm: from a nested start the last Newton
/// step lands on rounding, which on fine levels sits near 10⁻¹² of the start's residual
/// (the nodal membrane at 261k unknowns stalled at 1.4·10⁻¹² under a 10⁻¹² tolerance);
/// the pipeline's KKT residual certifies the answer whatever the tolerance.
const RELATIVE_TOLERANCE: f64 = 1e-10;

/// The largest KKT residual ([`Lcp::kkt_residual`], relative) of an answer PETSc's
/// solve may return: its converged solves certify to 10⁻¹⁵–10⁻¹⁰; beyond this the
/// options stopped it early.
const MAX_KKT_RESIDUAL: f64 = 1e-8;

/// SNES's absolute tolerance relative to the residual at zero: a start that is already
/// the solution (membrane-flat, pressed onto ψ = 0 everywhere, from its nested start)
/// has a residual at rounding, 10⁻¹⁴ of that scale, from which no relative decrease
/// exists and the line search on Φ failed (DIVERGED_LINE_SEARCH).
const ABSOLUTE_TOLERANCE: f64 = 1e-12;

/// The Euclidean norm.
fn norm2<'a>(values: impl IntoIterator<Item = &'a f64>) -> f64 {
    values.into_iter().map(|v| v * v).sum::<f64>().sqrt()
}

/// `‖F‖ + ‖BᵀC⁻¹G₊‖`, the sizes of the two terms of `∇Φ(0)`: not `‖∇Φ(0)‖`, which
/// vanishes where `U = 0` is the solution (membrane-flat).
fn gradient_scale(lcp: &Lcp) -> f64 {
    let mut pressed = vec![0.0; lcp.n()];
    for ((row, g), c) in lcp.b_rows.iter().zip(&lcp.g).zip(&lcp.c) {
        let z = g.max(0.0) / c;
        for &(j, v) in row {
            pressed[j] += v * z;
        }
    }
    norm2(&lcp.f) + norm2(&pressed)
}

/// The relative rounding noise of an eliminated Λ above which it is recovered by a
/// saddle-point solve (the native solver's threshold).
const MAX_ELIMINATION_NOISE: f64 = 1e-6;

/// The formulation of `lcp`: primal for the nodal method, else `preferred`, else
/// eliminated where `C` is diagonal and positive and mixed elsewhere.
///
/// # Errors
/// The eliminated formulation asked for where `C` is not diagonal and positive.
fn formulation_of(
    lcp: &Lcp,
    preferred: Option<Formulation>,
) -> std::result::Result<Formulation, String> {
    if is_nodal(lcp) {
        return Ok(Formulation::Primal);
    }
    choose(lcp.c_blocks.is_empty(), &lcp.c, preferred)
}

/// [`formulation_of`] for an LCP held in parts by the ranks ([`Lcp::share`]): judged on
/// the whole `C`, summed over them; primal for the nodal method's parts
/// ([`crate::shared::is_nodal`]).
fn shared_formulation(
    petsc: &Petsc,
    lcp: &Lcp,
    preferred: Option<Formulation>,
) -> std::result::Result<Formulation, String> {
    if crate::shared::is_nodal(petsc, lcp) {
        return Ok(Formulation::Primal);
    }
    let mut c = lcp.c.clone();
    petsc.sum_all(&mut c);
    let coupled = petsc.max(f64::from(u8::from(!lcp.c_blocks.is_empty()))) > 0.0;
    choose(!coupled, &c, preferred)
}

/// The formulation for a `C` with diagonal `c` (and blocks unless `diagonal_only`):
/// `preferred` where it applies, else eliminated where `C` is diagonal and positive and
/// mixed elsewhere.
///
/// # Errors
/// The eliminated formulation asked for where `C` is not diagonal and positive; the
/// plain mixed method (`C = 0`) without `mixed` asked for.
fn choose(
    diagonal_only: bool,
    c: &[f64],
    preferred: Option<Formulation>,
) -> std::result::Result<Formulation, String> {
    let diagonal = diagonal_only && c.iter().all(|&c| c > 0.0);
    let plain = diagonal_only && c.iter().all(|&c| c == 0.0);
    if plain && preferred.is_none() {
        // measured: the membrane, the Euler–Bernoulli beam and Hertz at α = 0 all ran
        // out of SNESVI iterations; a refusal that says so beats 50 wasted iterations
        return Err("the plain mixed method (α = 0: C = 0) has no multiplier to eliminate, and PETSc's reduced-space VI on its saddle point does not converge here (DIVERGED_MAX_IT on the membrane, the beam and Hertz); solve it natively (clarabel), or ask for `--petsc-formulation mixed` to try".into());
    }
    match preferred {
        Some(Formulation::Eliminated) if !diagonal => Err(
            "the eliminated formulation needs a diagonal positive C (P0 multipliers, α > 0); this LCP has coupled multipliers or C = 0: use `mixed`".into(),
        ),
        Some(f @ (Formulation::Eliminated | Formulation::Mixed)) => Ok(f),
        _ if diagonal => Ok(Formulation::Eliminated),
        _ => Ok(Formulation::Mixed),
    }
}

/// Whether `lcp` is the nodal method's: `B = I` (one unit entry per row, on the
/// diagonal) and `C = 0`.
fn is_nodal(lcp: &Lcp) -> bool {
    nodal_shape(lcp, false)
}

/// The nodal method's shape: as many constraints as unknowns, `C = 0` without blocks,
/// row `k` of `B` the unit entry `e_k` (or empty, `part`: one rank's part, which holds
/// some of the rows).
pub(crate) fn nodal_shape(lcp: &Lcp, part: bool) -> bool {
    lcp.m() == lcp.n()
        && lcp.c.iter().all(|&c| c == 0.0)
        && lcp.c_blocks.is_empty()
        && lcp
            .b_rows
            .iter()
            .enumerate()
            .all(|(k, row)| (part && row.is_empty()) || row == [(k, 1.0)])
}

/// The first index of each of `size` contiguous blocks of `0..count`, and `count`.
fn blocks(count: usize, size: usize) -> Vec<usize> {
    (0..=size).map(|r| count * r / size).collect()
}

/// Where each unknown of `(U, Λ)` lives in PETSc's numbering: rank `r` owns its block of
/// `U` then its block of `Λ`.
struct Layout {
    u_blocks: Vec<usize>,
    l_blocks: Vec<usize>,
    rank: usize,
}

impl Layout {
    fn new(n: usize, m: usize, rank: usize, size: usize) -> Self {
        Self {
            u_blocks: blocks(n, size),
            l_blocks: blocks(m, size),
            rank,
        }
    }

    /// The first PETSc row of rank `r`.
    fn offset(&self, r: usize) -> usize {
        self.u_blocks[r] + self.l_blocks[r]
    }

    /// The rank whose block of `blocks` holds `i`.
    fn owner(blocks: &[usize], i: usize) -> usize {
        blocks.partition_point(|&b| b <= i) - 1
    }

    fn u(&self, i: usize) -> usize {
        let r = Self::owner(&self.u_blocks, i);
        self.offset(r) + i - self.u_blocks[r]
    }

    fn lambda(&self, k: usize) -> usize {
        let r = Self::owner(&self.l_blocks, k);
        self.offset(r) + (self.u_blocks[r + 1] - self.u_blocks[r]) + k - self.l_blocks[r]
    }

    fn local_u(&self) -> std::ops::Range<usize> {
        self.u_blocks[self.rank]..self.u_blocks[self.rank + 1]
    }

    fn local_lambda(&self) -> std::ops::Range<usize> {
        self.l_blocks[self.rank]..self.l_blocks[self.rank + 1]
    }

    fn first_row(&self) -> usize {
        self.offset(self.rank)
    }

    fn local_len(&self) -> usize {
        self.local_u().len() + self.local_lambda().len()
    }

    /// Whether PETSc row `row` is this rank's.
    fn is_local(&self, row: usize) -> bool {
        (self.first_row()..self.first_row() + self.local_len()).contains(&row)
    }
}

/// This rank's rows of a square matrix, as `(row, column, value)` in PETSc's numbering,
/// added to a matrix preallocated for exactly them.
fn matrix_of<'p>(
    petsc: &'p Petsc,
    layout: &Layout,
    entries: &[(usize, usize, f64)],
) -> Result<Matrix<'p>> {
    let first = layout.first_row();
    let (mut diagonal, mut off) = (vec![0; layout.local_len()], vec![0; layout.local_len()]);
    let mut sorted: Vec<(usize, usize)> = entries.iter().map(|&(i, j, _)| (i, j)).collect();
    sorted.sort_unstable();
    sorted.dedup();
    for (i, j) in sorted {
        if layout.is_local(j) {
            diagonal[i - first] += 1;
        } else {
            off[i - first] += 1;
        }
    }
    let mut matrix = Matrix::new(petsc, &diagonal, &off)?;
    for &(i, j, v) in entries {
        matrix.add(&[i], &[j], &[v])?;
    }
    matrix.assemble()?;
    Ok(matrix)
}

/// Solves `lcp` by SNESVI in the `primal` or `mixed` formulation (see the module's
/// docs): `(U, Λ)` on every rank and SNES's report.
fn solve_vi(
    petsc: &Petsc,
    lcp: &Lcp,
    start: Option<&[f64]>,
    formulation: Formulation,
) -> Result<(Vec<f64>, Vec<f64>, Converged)> {
    check_start(lcp, start)?;
    let nodal = formulation == Formulation::Primal;
    let (n, m) = (lcp.n(), if nodal { 0 } else { lcp.m() });
    let layout = Layout::new(n, m, petsc.rank(), petsc.size());
    let mut entries = Vec::new();
    // A is symmetric and stored whole: column i is row i
    let (col_ptr, row_idx, values) = (
        lcp.a.symbolic().col_ptr(),
        lcp.a.symbolic().row_idx(),
        lcp.a.val(),
    );
    for i in layout.local_u() {
        for p in col_ptr[i]..col_ptr[i + 1] {
            entries.push((layout.u(i), layout.u(row_idx[p]), values[p]));
        }
    }
    if !nodal {
        let mine = layout.local_lambda();
        let u_mine = layout.local_u();
        for (k, row) in lcp.b_rows.iter().enumerate() {
            for &(j, v) in row {
                if mine.contains(&k) {
                    entries.push((layout.lambda(k), layout.u(j), v));
                }
                if u_mine.contains(&j) {
                    entries.push((layout.u(j), layout.lambda(k), -v));
                }
            }
        }
        for k in mine.clone() {
            entries.push((layout.lambda(k), layout.lambda(k), lcp.c[k]));
        }
        for (first, s, block) in lcp.c_blocks.blocks() {
            for a in 0..s {
                if !mine.contains(&(first + a)) {
                    continue;
                }
                for b in (0..s).filter(|&b| b != a) {
                    let v = block[a * s + b];
                    if v != 0.0 {
                        entries.push((layout.lambda(first + a), layout.lambda(first + b), v));
                    }
                }
            }
        }
    }
    let jacobian = matrix_of(petsc, &layout, &entries)?;
    drop(entries);
    let rows: Vec<usize> = (layout.first_row()..layout.first_row() + layout.local_len()).collect();
    let (u_mine, l_mine) = (layout.local_u(), layout.local_lambda());
    let of_mine = |u: &dyn Fn(usize) -> f64, l: &dyn Fn(usize) -> f64| -> Vec<f64> {
        u_mine.clone().map(u).chain(l_mine.clone().map(l)).collect()
    };
    let mut right = Vector::new(petsc, layout.local_len())?;
    right.set(&rows, &of_mine(&|i| lcp.f[i], &|k| lcp.g[k]), false)?;
    let infinity = crate::sys::FEM_PETSC_INFINITY;
    let (floor, ceiling) = if nodal {
        (of_mine(&|i| lcp.g[i], &|_| 0.0), vec![infinity; rows.len()])
    } else {
        (
            of_mine(&|_| -infinity, &|_| 0.0),
            vec![infinity; rows.len()],
        )
    };
    let mut x = Vector::new(petsc, layout.local_len())?;
    let begin = |i: usize| start.map_or(0.0, |s| s[i]);
    x.set(&rows, &of_mine(&begin, &|_| 0.0), false)?;
    let mut lower = Vector::new(petsc, layout.local_len())?;
    let mut upper = Vector::new(petsc, layout.local_len())?;
    lower.set(&rows, &floor, false)?;
    upper.set(&rows, &ceiling, false)?;
    for v in [&mut right, &mut x, &mut lower, &mut upper] {
        v.assemble()?;
    }
    // direct solves unless the user chose (`-ksp_type cg -pc_type gamg`): the reduced
    // Newton systems change with the active set, and GAMG under vinewtonrsls fails in
    // PETSc 3.18; the mixed Jacobian is indefinite and not symmetric (LU), the primal one
    // SPD (Cholesky). Full steps: on the mixed system the backtracking search on ‖F‖
    // stalls (DIVERGED_LINE_SEARCH on the P2–P1disc membrane at N = 4) where full
    // semismooth steps converge in 3–6.
    let defaults = Defaults {
        ksp_type: Some(c"preonly"),
        pc_type: Some(if nodal { c"cholesky" } else { c"lu" }),
        factor_package: Some(c"mumps"),
        line_search: Some(c"basic"),
        rtol: Some(RELATIVE_TOLERANCE),
        // the residual at x = 0 is −(F, G): its size sets the rounding floor
        atol: Some(ABSOLUTE_TOLERANCE * norm2(lcp.f.iter().chain(&lcp.g))),
        // a problem with (F, G) = 0 has its solution at the start: no step to force
        force_iteration: !nodal && norm2(lcp.f.iter().chain(&lcp.g)) > 0.0,
    };
    let converged = solve_affine(&defaults, &jacobian, &right, Some((&lower, &upper)), &mut x)?;
    let whole = x.gather()?;
    let mut u = vec![0.0; n];
    let mut lambda = vec![0.0; m];
    for i in 0..n {
        u[i] = whole[layout.u(i)];
    }
    for (k, l) in lambda.iter_mut().enumerate() {
        *l = whole[layout.lambda(k)];
    }
    if nodal {
        // the nodal forces: A U − F, the contact force at each node (≥ 0 up to the
        // solver's tolerance where U = ψ, 0 elsewhere)
        let au = fem_runtime::lcp::cholesky::multiply(&lcp.a, &u);
        lambda = au
            .iter()
            .zip(&lcp.f)
            .map(|(a, f)| (a - f).max(0.0))
            .collect();
    }
    Ok((u, lambda, converged))
}

/// Solves an LCP held in parts by the ranks ([`Lcp::share`], each rank's own cells) in
/// `formulation` (the eliminated one without its line search where `full_steps`):
/// `(U, Λ)` whole on every rank, SNES's report, `‖A‖∞` of the assembled `A` and this
/// rank's rows (see the `shared` module).
fn solve_shared(
    petsc: &Petsc,
    lcp: &Lcp,
    start: Option<&[f64]>,
    formulation: Formulation,
    full_steps: bool,
) -> Result<crate::shared::Shared> {
    check_start(lcp, start)?;
    // MUMPS's factorization (Cholesky of the SPD Hessians, LU of the mixed Jacobian),
    // the tolerances of the whole LCP's solves; full steps but where the eliminated
    // formulation's line search on Φ applies
    let direct = |pc: &'static std::ffi::CStr, line_search| Defaults {
        ksp_type: Some(c"preonly"),
        pc_type: Some(pc),
        factor_package: Some(c"mumps"),
        line_search,
        rtol: Some(RELATIVE_TOLERANCE),
        atol: Some(ABSOLUTE_TOLERANCE),
        force_iteration: false,
    };
    let basic = Some(c"basic");
    match formulation {
        Formulation::Eliminated => crate::shared::solve_eliminated(
            petsc,
            lcp,
            start,
            direct(c"cholesky", if full_steps { basic } else { None }),
        ),
        Formulation::Mixed => crate::shared::solve_mixed(
            petsc,
            lcp,
            start,
            Defaults {
                force_iteration: true,
                ..direct(c"lu", basic)
            },
        ),
        Formulation::Primal => {
            crate::shared::solve_primal(petsc, lcp, start, direct(c"cholesky", basic))
        }
    }
}

/// Refuses an LCP of inconsistent shapes and a start of the wrong length.
fn check_start(lcp: &Lcp, start: Option<&[f64]>) -> Result<()> {
    lcp.check_shapes()
        .map_err(|e| Error::refused("PetscLcpSolver::solve", e.to_string()))?;
    match start {
        Some(s) if s.len() != lcp.n() => Err(Error::refused(
            "PetscLcpSolver::solve",
            format!("a start of {} unknowns for {}", s.len(), lcp.n()),
        )),
        _ => Ok(()),
    }
}

/// `(G − B U)₊,k / C_k` for every constraint: the eliminated multipliers.
fn eliminated_multipliers(lcp: &Lcp, u: &[f64]) -> Vec<f64> {
    lcp.b_rows
        .iter()
        .zip(lcp.g.iter().zip(&lcp.c))
        .map(|(row, (g, c))| {
            let r = g - row.iter().map(|&(j, v)| v * u[j]).sum::<f64>();
            r.max(0.0) / c
        })
        .collect()
}

/// What one rank of the eliminated formulation reads and writes: its block of `U`, the
/// entries of `U` its rows couple to (its own and its ghosts, `needed`, ascending), and
/// the constraints that touch its rows or that it owns (a constraint belongs to the rank
/// of its first column), with `B`'s entries in local columns.
struct EliminatedRows {
    needed: Vec<usize>,
    /// Per own row, its `A` entries as (local column, value).
    a_rows: ConstraintRows,
    /// Per own row, the constraints touching it as (index into `constraints`, `B` entry).
    touching: ConstraintRows,
    /// The constraints this rank evaluates (their `k`).
    constraints: Vec<usize>,
    /// Their entries of `B`, in local columns.
    constraint_rows: ConstraintRows,
    /// Those of `constraints` this rank owns (each counted once in Φ).
    owned: Vec<usize>,
}

impl EliminatedRows {
    fn new(
        lcp: &Lcp,
        mine: std::ops::Range<usize>,
        owner_of: impl Fn(usize) -> usize,
        rank: usize,
    ) -> Self {
        let (col_ptr, row_idx, values) = (
            lcp.a.symbolic().col_ptr(),
            lcp.a.symbolic().row_idx(),
            lcp.a.val(),
        );
        let mut relevant: Vec<usize> = Vec::new();
        let mut owned_k: Vec<usize> = Vec::new();
        for (k, row) in lcp.b_rows.iter().enumerate() {
            let owner = row.first().map_or(0, |&(j, _)| owner_of(j));
            let touches = row.iter().any(|&(j, _)| mine.contains(&j));
            if touches || owner == rank {
                relevant.push(k);
            }
            if owner == rank {
                owned_k.push(k);
            }
        }
        let mut needed: Vec<usize> = mine.clone().collect();
        for i in mine.clone() {
            needed.extend(&row_idx[col_ptr[i]..col_ptr[i + 1]]);
        }
        for &k in &relevant {
            needed.extend(lcp.b_rows[k].iter().map(|&(j, _)| j));
        }
        needed.sort_unstable();
        needed.dedup();
        let local = |j: usize| {
            needed
                .binary_search(&j)
                .expect("every column read is needed")
        };
        let mut offsets = vec![0];
        let mut entries = Vec::new();
        for i in mine.clone() {
            entries.extend((col_ptr[i]..col_ptr[i + 1]).map(|p| (local(row_idx[p]), values[p])));
            offsets.push(entries.len());
        }
        let a_rows = ConstraintRows::from_flat(offsets, entries).expect("offsets ascend");
        let mut touching = vec![Vec::new(); mine.len()];
        let (mut offsets, mut entries) = (vec![0], Vec::new());
        for (r, &k) in relevant.iter().enumerate() {
            for &(j, v) in &lcp.b_rows[k] {
                if mine.contains(&j) {
                    touching[j - mine.start].push((r, v));
                }
                entries.push((local(j), v));
            }
            offsets.push(entries.len());
        }
        let constraint_rows = ConstraintRows::from_flat(offsets, entries).expect("offsets ascend");
        let touching = ConstraintRows::from(touching);
        let owned = owned_k
            .iter()
            .map(|k| {
                relevant
                    .binary_search(k)
                    .expect("owned constraints are evaluated")
            })
            .collect();
        Self {
            needed,
            a_rows,
            touching,
            constraints: relevant,
            constraint_rows,
            owned,
        }
    }

    /// The eliminated multipliers `(G − BU)₊,k / C_k` of the evaluated constraints, from
    /// the needed entries `u` of `U`.
    fn multipliers(&self, lcp: &Lcp, u: &[f64]) -> Vec<f64> {
        self.constraints
            .iter()
            .zip(self.constraint_rows.iter())
            .map(|(&k, row)| {
                let r = lcp.g[k] - row.iter().map(|&(j, v)| v * u[j]).sum::<f64>();
                r.max(0.0) / lcp.c[k]
            })
            .collect()
    }

    /// `(AU)_i` for own row `i` (local), from the needed entries `u`.
    fn a_times(&self, i: usize, u: &[f64]) -> f64 {
        self.a_rows[i].iter().map(|&(j, v)| v * u[j]).sum()
    }

    /// The local index of own row `i` (global) among the needed entries.
    fn local_of_own(&self, i: usize) -> usize {
        self.needed.binary_search(&i).expect("own rows are needed")
    }
}

/// Solves `lcp` by SNES on Φ(U) (see the module's docs), with its line search on Φ
/// unless `full_steps`: `(U, Λ)` on every rank and SNES's report. Each rank owns a contiguous block of `U` and writes its rows of the
/// gradient and of the generalized Hessian, whose pattern (that of `A + BᵀB`) is
/// preallocated once; the callbacks read only the entries of `U` their rows couple to
/// (one `VecScatter` of the ghosts), and Φ is the sum of the ranks' shares (one
/// `MPI_Allreduce`). The whole `U` is gathered once, at the end, for the pipeline.
fn solve_eliminated(
    petsc: &Petsc,
    lcp: &Lcp,
    start: Option<&[f64]>,
    full_steps: bool,
) -> Result<(Vec<f64>, Vec<f64>, Converged)> {
    check_start(lcp, start)?;
    let n = lcp.n();
    let bounds = blocks(n, petsc.size());
    let rank = petsc.rank();
    let mine = bounds[rank]..bounds[rank + 1];
    let owner_of = |j: usize| Layout::owner(&bounds, j);
    let rows = EliminatedRows::new(lcp, mine.clone(), owner_of, rank);
    let (mut diagonal, mut off) = (
        Vec::with_capacity(mine.len()),
        Vec::with_capacity(mine.len()),
    );
    for i in 0..mine.len() {
        let mut columns: Vec<usize> = rows.a_rows[i].iter().map(|&(j, _)| j).collect();
        for &(r, _) in &rows.touching[i] {
            columns.extend(rows.constraint_rows[r].iter().map(|&(j, _)| j));
        }
        columns.sort_unstable();
        columns.dedup();
        let here = columns
            .iter()
            .filter(|&&j| mine.contains(&rows.needed[j]))
            .count();
        diagonal.push(here);
        off.push(columns.len() - here);
    }
    let mut matrix = Matrix::new(petsc, &diagonal, &off)?;
    let own: Vec<usize> = mine.clone().collect();
    // PETSc's rows are the unknowns here
    matrix.set_near_null_space(petsc, &own, &lcp.near_null_space)?;
    let mut x = Vector::new(petsc, mine.len())?;
    let begin: Vec<f64> = mine.clone().map(|i| start.map_or(0.0, |s| s[i])).collect();
    x.set(&own, &begin, false)?;
    x.assemble()?;
    let ghosts = std::cell::RefCell::new(Ghosts::new(petsc, &x, &rows.needed)?);
    // the Hessian is SPD: Cholesky unless the user chose (`-ksp_type cg -pc_type gamg`);
    // the line search backtracks on Φ (the objective), PETSc's default `bt`
    let defaults = Defaults {
        ksp_type: Some(c"preonly"),
        pc_type: Some(c"cholesky"),
        factor_package: Some(c"mumps"),
        line_search: full_steps.then_some(c"basic"),
        rtol: Some(RELATIVE_TOLERANCE),
        // the gradient at U = 0 is −F − BᵀC⁻¹G₊: its terms' sizes set the rounding floor
        atol: Some(ABSOLUTE_TOLERANCE * gradient_scale(lcp)),
        force_iteration: false,
    };
    let rows = &rows;
    let objective = |x: &VectorView| -> Result<f64> {
        let u = ghosts.borrow_mut().read(x)?;
        let mut share = 0.0;
        for (i, global) in mine.clone().enumerate() {
            let ui = u[rows.local_of_own(global)];
            share += 0.5 * ui * rows.a_times(i, &u) - lcp.f[global] * ui;
        }
        let z = rows.multipliers(lcp, &u);
        for &r in &rows.owned {
            share += 0.5 * z[r] * z[r] * lcp.c[rows.constraints[r]];
        }
        Ok(petsc.sum(share))
    };
    let gradient = |x: &VectorView, out: &mut VectorView| -> Result<()> {
        let u = ghosts.borrow_mut().read(x)?;
        let z = rows.multipliers(lcp, &u);
        let local: Vec<f64> = mine
            .clone()
            .enumerate()
            .map(|(i, global)| {
                let btz: f64 = rows.touching[i].iter().map(|&(r, v)| v * z[r]).sum();
                rows.a_times(i, &u) - lcp.f[global] - btz
            })
            .collect();
        out.write_local(&local)
    };
    let hessian = |x: &VectorView, matrix: &mut Matrix| -> Result<()> {
        let u = ghosts.borrow_mut().read(x)?;
        let z = rows.multipliers(lcp, &u);
        matrix.zero_entries()?;
        let (mut columns, mut entries) = (Vec::new(), Vec::new());
        for (i, global) in mine.clone().enumerate() {
            columns.clear();
            entries.clear();
            for &(j, v) in &rows.a_rows[i] {
                columns.push(rows.needed[j]);
                entries.push(v);
            }
            for &(r, v) in &rows.touching[i] {
                // active where (G − BU)_k > 0, i.e. where the eliminated Λ_k is
                if z[r] > 0.0 {
                    let scale = v / lcp.c[rows.constraints[r]];
                    for &(j, w) in &rows.constraint_rows[r] {
                        columns.push(rows.needed[j]);
                        entries.push(scale * w);
                    }
                }
            }
            // repeated columns add up (ADD_VALUES)
            matrix.add(&[global], &columns, &entries)?;
        }
        matrix.assemble()
    };
    let converged = minimize(
        &defaults,
        Box::new(objective),
        Box::new(gradient),
        Box::new(hessian),
        matrix,
        &mut x,
    )?;
    let u = x.gather()?;
    let lambda = eliminated_multipliers(lcp, &u);
    Ok((u, lambda, converged))
}
