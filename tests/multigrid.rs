//! Geometric multigrid on the Newton Hessian of real membrane obstacle problems
//! (issue 15): the stabilized P1–P0 and P2–P0 pairs on the radial scene, solved by
//! nested iteration to convergence on meshes of N × N × 2 triangles; at the converged
//! active set the Hessian `H = A + Σ_{k active} c_k⁻¹ b_k b_kᵀ` (Φ's, docs/mathematics.md
//! §5, for a diagonal `C`) is solved by CG with one V-cycle per iteration on the nested
//! hierarchy down to N = 4. The iteration counts must stay bounded as N grows, and the
//! solution must be Cholesky's.
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

#[path = "common/membranes.rs"]
mod membranes;

use faer::sparse::{SparseColMat, Triplet};
use fem_forms::lcp::cholesky::{multiply, solve_spd};
use fem_forms::lcp::Lcp;
use fem_forms::lcp::NewtonStep;
use fem_forms::models::membrane::{membrane_p1_p0, membrane_p2_p0};
use fem_forms::models::membrane_scenes::membrane_scene;
use fem_forms::multigrid::{
    parents_by_location, prolongation, Multigrid, MultigridOptions, NestedLevel,
};
use fem_forms::obstacle::hierarchy::{LinearSolver, MultigridSteps, MULTIGRID_ROUNDING_FLOOR};
use fem_forms::obstacle::triangle::{discretize_on_triangles, solve_obstacle_on_triangles};
use fem_forms::obstacle::{Discretization, ObstacleOptions, VariationalSolver};
use fem_forms::{Constraints, Model, Reduction, SparseMatrix, SystemDofs, TriangleMesh};
use membranes::{options, SceneData};

/// Newton's Hessian of Φ at `u` for an LCP with a diagonal `C`: `A` plus `b_k b_kᵀ / c_k`
/// for each constraint whose eliminated multiplier is positive (`(G − BU)_k > 0`).
/// Returns the matrix and the number of active constraints.
fn newton_hessian(lcp: &Lcp, u: &[f64]) -> (SparseMatrix, usize) {
    assert!(lcp.c_blocks.is_empty(), "a diagonal C");
    let lambda = lcp.eliminated_multiplier(&lcp.b_times(u));
    let a = &lcp.a;
    let (col_ptr, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    let mut triplets: Vec<Triplet<usize, usize, f64>> = (0..a.ncols())
        .flat_map(|j| (col_ptr[j]..col_ptr[j + 1]).map(move |k| Triplet::new(rows[k], j, vals[k])))
        .collect();
    let mut active = 0;
    for (k, row) in lcp.b_rows.iter().enumerate() {
        if lambda[k] > 0.0 {
            active += 1;
            let w = 1.0 / lcp.c[k];
            for &(i, vi) in row {
                for &(j, vj) in row {
                    triplets.push(Triplet::new(i, j, w * vi * vj));
                }
            }
        }
    }
    let h = SparseColMat::try_new_from_triplets(a.nrows(), a.ncols(), &triplets).unwrap();
    (h, active)
}

/// The primal field `u` alone, with the DOFs the discretization fixes: its reduced
/// numbering is the LCP's primal numbering (`u` is the first field, so its full DOFs
/// are the same in both systems, and the primal unknowns are the free ones in order).
fn primal_level<M: Model>(d: &Discretization<TriangleMesh>) -> (SystemDofs, Reduction) {
    let dofs = SystemDofs::named::<M>(&d.mesh, &["u"]).unwrap();
    let u = d.dofs.range(M::field("u").unwrap()).unwrap();
    assert_eq!(u.start, 0);
    let mut constraints = Constraints::new();
    for dof in u.filter(|&dof| d.reduction.free_index(dof).is_none()) {
        constraints.fix_dof(dof, 0.0).unwrap();
    }
    let reduction = constraints.reduction(dofs.dof_count()).unwrap();
    assert_eq!(reduction.free().len(), d.lcp.n());
    (dofs, reduction)
}

/// Uniform in (0, 1) from a 64-bit LCG (Knuth's MMIX constants).
fn random(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*state >> 11) as f64 / (1u64 << 53) as f64
}

/// For each finest size: (N, unknowns, active constraints, PCG iterations to 1e-10,
/// largest difference from the Cholesky solution relative to its largest entry).
fn newton_hessian_runs<M: Model>(
    sizes: &[usize],
    alpha: f64,
    options: MultigridOptions,
) -> Vec<(usize, usize, usize, usize, f64)> {
    let scene = membrane_scene("membrane-radial").unwrap();
    let data = SceneData::new(&scene);
    let coefficients = data.coefficients::<M>(alpha);
    let solve_options = membranes::options(VariationalSolver::SemismoothNewton);
    let finest = *sizes.last().unwrap();
    let mut meshes = Vec::new();
    let mut n = 4;
    while n <= finest {
        meshes.push(membranes::mesh(&scene, n));
        n *= 2;
    }
    let discretizations: Vec<_> = meshes
        .iter()
        .map(|mesh| discretize_on_triangles::<M>(mesh, &coefficients, "B_h", "L_h").unwrap())
        .collect();
    let primal: Vec<_> = discretizations.iter().map(primal_level::<M>).collect();
    // prolongations[l]: from level l to level l + 1 (coarse to fine order here)
    let prolongations: Vec<SparseMatrix> = (1..meshes.len())
        .map(|l| {
            let parents = parents_by_location(&meshes[l - 1], &meshes[l]).unwrap();
            let coarse = NestedLevel {
                mesh: &meshes[l - 1],
                dofs: &primal[l - 1].0,
                reduction: Some(&primal[l - 1].1),
            };
            let fine = NestedLevel {
                mesh: &meshes[l],
                dofs: &primal[l].0,
                reduction: Some(&primal[l].1),
            };
            prolongation(&coarse, &fine, &parents).unwrap()
        })
        .collect();
    let mut out = Vec::new();
    for &size in sizes {
        let level = meshes
            .iter()
            .position(|m| m.cell_count() == 2 * size * size)
            .unwrap();
        let solution =
            solve_obstacle_on_triangles::<M>(&meshes[..=level], &coefficients, solve_options)
                .unwrap();
        assert!(solution.kkt_residual <= 1e-10);
        let d = &solution.discretization;
        let u = d.primal_part(&solution.values);
        let (h, active) = newton_hessian(&d.lcp, &u);
        // the runtime's Hessian, built its own way, is this one
        let (runtime, runtime_active) = d.lcp.newton_hessian(&u).unwrap();
        assert_eq!(runtime_active, active);
        let x: Vec<f64> = (0..h.ncols())
            .map(|i| ((i * 7919) % 101) as f64 - 50.0)
            .collect();
        let (hx, rx) = (multiply(&h, &x), multiply(&runtime, &x));
        let scale = hx.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let difference = hx
            .iter()
            .zip(&rx)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(
            difference <= 1e-12 * scale,
            "H x differs by {difference:e} of {scale:e}"
        );
        assert!(active > 0, "the radial membrane touches its obstacle");
        let ps: Vec<SparseMatrix> = prolongations[..level].iter().rev().cloned().collect();
        let mg = Multigrid::new(h.clone(), ps, options).unwrap();
        let mut seed = 7u64;
        let b: Vec<f64> = (0..h.nrows()).map(|_| random(&mut seed) - 0.5).collect();
        let pcg = mg.pcg(&b, 1e-10, 100).unwrap();
        let direct = solve_spd(&h, &b).unwrap();
        let scale = direct.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let difference = pcg
            .x
            .iter()
            .zip(&direct)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
            / scale;
        let r: Vec<f64> = multiply(&h, &pcg.x)
            .iter()
            .zip(&b)
            .map(|(p, q)| p - q)
            .collect();
        let relative = r.iter().map(|v| v * v).sum::<f64>().sqrt()
            / b.iter().map(|v| v * v).sum::<f64>().sqrt();
        assert!(relative <= 2e-10, "N = {size}: true residual {relative:e}");
        out.push((size, h.nrows(), active, pcg.iterations, difference));
    }
    out
}

/// Prints the runs and checks them: at most `most` iterations, the last two levels
/// differing by at most `growth`, and every solution Cholesky's to 1e-9.
fn check(name: &str, runs: &[(usize, usize, usize, usize, f64)], most: usize, growth: usize) {
    eprintln!("{name}: (N, unknowns, active, PCG iterations, difference from Cholesky)");
    for run in runs {
        eprintln!("  {run:?}");
    }
    for &(size, _, _, iterations, difference) in runs {
        assert!(
            iterations <= most,
            "{name} N = {size}: {iterations} iterations"
        );
        assert!(
            difference <= 1e-9,
            "{name} N = {size}: {difference:e} from Cholesky"
        );
    }
    let last = runs[runs.len() - 1].3;
    let before = runs[runs.len() - 2].3;
    assert!(
        last <= before + growth,
        "{name}: iterations grow {before} → {last}"
    );
}

fn v(sweeps: usize) -> MultigridOptions {
    MultigridOptions {
        sweeps,
        coarse_corrections: 1,
    }
}

fn w(sweeps: usize) -> MultigridOptions {
    MultigridOptions {
        sweeps,
        coarse_corrections: 2,
    }
}

/// P1–P0 at the CLI's α = 0.1, N = 16 to 256 (65k unknowns), 4 to 7 levels. Measured:
/// V(1,1) 8, 9, 10, 11, 12 — bounded by the test's 15 but creeping up by one a level;
/// W(1,1) flat.
#[test]
fn multigrid_cg_on_the_p1_p0_newton_hessian_is_bounded_in_h() {
    type M = membrane_p1_p0::Model;
    let sizes = [16, 32, 64, 128, 256];
    check(
        "P1–P0 α = 0.1, V(1,1)",
        &newton_hessian_runs::<M>(&sizes, 0.1, v(1)),
        15,
        2,
    );
    check(
        "P1–P0 α = 0.1, W(1,1)",
        &newton_hessian_runs::<M>(&sizes, 0.1, w(1)),
        10,
        0,
    );
}

/// P2–P0 at the CLI's α = ½/C_I (C_I = 96 on right triangles), N = 8 to 128 (65k
/// unknowns). The V-cycle's count grows with the levels (measured V(1,1): 9, 10, 12, 14,
/// 17): the active cells' term `b_k b_kᵀ / (α h²|T|)` is a reaction term of size 1/α
/// against the stiffness that switches on across the contact boundary, which linear
/// interpolation misrepresents there. The W-cycle does not grow: W(2,2) 7, 7, 7, 8, 8,
/// and at α = 0.1/96 12, 14, 14, 14, 14.
#[test]
fn multigrid_cg_on_the_p2_p0_newton_hessian_is_bounded_in_h() {
    type M = membrane_p2_p0::Model;
    let sizes = [8, 16, 32, 64, 128];
    check(
        "P2–P0 α = 0.5/96, W(2,2)",
        &newton_hessian_runs::<M>(&sizes, 0.5 / 96.0, w(2)),
        10,
        1,
    );
    check(
        "P2–P0 α = 0.1/96, W(2,2)",
        &newton_hessian_runs::<M>(&sizes, 0.1 / 96.0, w(2)),
        15,
        1,
    );
    let runs = newton_hessian_runs::<M>(&sizes, 0.5 / 96.0, v(1));
    check("P2–P0 α = 0.5/96, V(1,1)", &runs, 20, 4);
}

/// membrane-radial solved by nested Newton on N = 4, 8, 16, 32, and the prolongations of
/// its primal unknowns between those levels, fine to coarse (as `Multigrid` and the
/// Newton step solver take them).
fn solved_on_hierarchy<M: Model>(
    alpha: f64,
) -> (
    fem_forms::obstacle::triangle::TriangleObstacleSolution,
    Vec<SparseMatrix>,
) {
    let scene = membrane_scene("membrane-radial").unwrap();
    let data = SceneData::new(&scene);
    let coefficients = data.coefficients::<M>(alpha);
    let meshes: Vec<TriangleMesh> = [4, 8, 16, 32]
        .iter()
        .map(|&n| membranes::mesh(&scene, n))
        .collect();
    let discretizations: Vec<_> = meshes
        .iter()
        .map(|mesh| discretize_on_triangles::<M>(mesh, &coefficients, "B_h", "L_h").unwrap())
        .collect();
    let primal: Vec<_> = discretizations.iter().map(primal_level::<M>).collect();
    let prolongations = (1..meshes.len())
        .rev()
        .map(|l| {
            let parents = parents_by_location(&meshes[l - 1], &meshes[l]).unwrap();
            let level = |k: usize| NestedLevel {
                mesh: &meshes[k],
                dofs: &primal[k].0,
                reduction: Some(&primal[k].1),
            };
            prolongation(&level(l - 1), &level(l), &parents).unwrap()
        })
        .collect();
    let options = options(VariationalSolver::SemismoothNewton);
    let solution = solve_obstacle_on_triangles::<M>(&meshes, &coefficients, options).unwrap();
    (solution, prolongations)
}

/// The coarse operators of a multigrid hierarchy updated across Newton steps (the terms
/// of the constraints whose active state flipped, `Lcp::hessian_change_blocks` into
/// `Multigrid::add_coarse_term`) equal the Galerkin products `PᵀHP` recomputed from this
/// test's own Hessian, to 1e-12 of the largest entry, on every level, after each of
/// several active-set changes of the real P1–P0 and P2–P0 LCPs (N = 32, hierarchy down
/// to N = 4): the active sets of `t·U*` for a few `t`, `U*` the converged solution.
#[test]
fn updated_galerkin_operators_of_the_newton_hessian_are_the_recomputed_ones() {
    fn run<M: Model>(alpha: f64) {
        let (solution, prolongations) = solved_on_hierarchy::<M>(alpha);
        let d = &solution.discretization;
        let lcp = &d.lcp;
        let u_star = d.primal_part(&solution.values);
        let active_of = |u: &[f64]| -> Vec<bool> {
            let lambda = lcp.eliminated_multiplier(&lcp.b_times(u));
            lambda.iter().map(|&l| l > 0.0).collect()
        };
        let scaled = |t: f64| -> Vec<f64> { u_star.iter().map(|v| t * v).collect() };
        let (h, _) = newton_hessian(lcp, &scaled(0.5));
        let mut previous = active_of(&scaled(0.5));
        let mut mg = Multigrid::new(h, prolongations.clone(), w(1)).unwrap();
        for t in [0.9, 1.0, 0.7, 1.1] {
            let u = scaled(t);
            let active = active_of(&u);
            let flipped = previous.iter().zip(&active).filter(|(a, b)| a != b).count();
            assert!(flipped > 0, "t = {t}: no constraint flipped");
            lcp.hessian_change_blocks(&previous, &active, |rows, change| {
                mg.add_coarse_term(rows, change)
            })
            .unwrap();
            let (h, count) = newton_hessian(lcp, &u);
            assert_eq!(count, active.iter().filter(|&&a| a).count());
            mg.reset_fine(&h).unwrap();
            let fresh = Multigrid::new(h, prolongations.clone(), w(1)).unwrap();
            for l in 0..fresh.level_count() {
                let (updated, expected) = (mg.operator(l).unwrap(), fresh.operator(l).unwrap());
                assert_eq!(updated.symbolic().col_ptr(), expected.symbolic().col_ptr());
                assert_eq!(updated.symbolic().row_idx(), expected.symbolic().row_idx());
                let scale = expected.val().iter().fold(0.0f64, |m, v| m.max(v.abs()));
                let worst = updated
                    .val()
                    .iter()
                    .zip(expected.val())
                    .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
                assert!(
                    worst <= 1e-12 * scale,
                    "{} t = {t} ({flipped} flipped) level {l}: off by {worst:e} of {scale:e}",
                    M::NAME
                );
            }
            previous = active;
        }
    }
    run::<membrane_p1_p0::Model>(0.1);
    run::<membrane_p2_p0::Model>(0.5 / 96.0);
}

/// Nested semismooth Newton on membrane-radial with the Newton steps solved by
/// `linear_solver`, meshes N = 4, 8, …, `finest`.
fn nested_solve<M: Model>(
    finest: usize,
    alpha: f64,
    linear_solver: LinearSolver,
) -> fem_forms::obstacle::triangle::TriangleObstacleSolution {
    let scene = membrane_scene("membrane-radial").unwrap();
    let data = SceneData::new(&scene);
    let coefficients = data.coefficients::<M>(alpha);
    let options = ObstacleOptions {
        linear_solver,
        ..options(VariationalSolver::SemismoothNewton)
    };
    let mut meshes = Vec::new();
    let mut n = 4;
    while n <= finest {
        meshes.push(membranes::mesh(&scene, n));
        n *= 2;
    }
    solve_obstacle_on_triangles::<M>(&meshes, &coefficients, options).unwrap()
}

/// Newton with multigrid steps (issue 15) against Newton with Cholesky steps, for P1–P0
/// and P2–P0 from N = 16 to 64: the same VI solution (both KKT-certified, the values equal
/// to 1e-9 of their size), every step of the finest level solved by CG (no
/// factorization), and the CG iterations per Newton step bounded as h halves.
#[test]
fn newton_with_multigrid_steps_is_newton_with_cholesky_steps() {
    fn compare<M: Model>(name: &str, alpha: f64) {
        let mut per_step = Vec::new();
        for finest in [16, 32, 64] {
            let direct = nested_solve::<M>(finest, alpha, LinearSolver::Direct);
            let multigrid = nested_solve::<M>(finest, alpha, LinearSolver::Multigrid);
            assert!(direct.kkt_residual <= 1e-10 && multigrid.kkt_residual <= 1e-10);
            assert_eq!(direct.iterative_steps, 0, "{name} N = {finest}: direct");
            assert!(direct.factorizations > 0);
            assert_eq!(
                multigrid.factorizations, 0,
                "{name} N = {finest}: a multigrid step fell back to Cholesky"
            );
            assert!(multigrid.iterative_steps > 0);
            let scale = direct.values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let difference = direct
                .values
                .iter()
                .zip(&multigrid.values)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            assert!(
                difference <= 1e-9 * scale,
                "{name} N = {finest}: the solutions differ by {difference:e} of {scale:e}"
            );
            per_step.push(multigrid.krylov_iterations as f64 / multigrid.iterative_steps as f64);
        }
        eprintln!("{name}: CG iterations per Newton step at N = 16, 32, 64: {per_step:?}");
        assert!(per_step.iter().all(|&k| k <= 14.0), "{name}: {per_step:?}");
        assert!(
            per_step[2] <= per_step[1] + 1.5,
            "{name}: CG iterations per step grow with 1/h: {per_step:?}"
        );
    }
    compare::<membrane_p1_p0::Model>("P1–P0", 0.1);
    compare::<membrane_p2_p0::Model>("P2–P0", 0.5 / 96.0);
}

/// A late Newton step corrects a few flipped constraints: its gradient is tiny next to
/// the terms it balances, and CG stops once the residual is at the rounding floor
/// `MULTIGRID_ROUNDING_FLOOR · scale` instead of 1e-10 of that gradient. Checked on the
/// P1–P0 Hessian at N = 32 with a right-hand side of 1e-9 of the scale: the residual
/// reached (recomputed here) is below the floor, the step counts as exact, it takes
/// fewer CG iterations than the same step without a scale, and the two directions agree
/// to the floor's accuracy.
#[test]
fn late_newton_steps_stop_at_the_rounding_floor() {
    let (solution, prolongations) = solved_on_hierarchy::<membrane_p1_p0::Model>(0.1);
    let lcp = &solution.discretization.lcp;
    let u = solution.discretization.primal_part(&solution.values);
    let (h, count) = newton_hessian(lcp, &u);
    let active: Vec<bool> = lcp
        .eliminated_multiplier(&lcp.b_times(&u))
        .iter()
        .map(|&l| l > 0.0)
        .collect();
    assert_eq!(active.iter().filter(|&&a| a).count(), count);
    let mut seed = 11u64;
    let raw: Vec<f64> = (0..h.nrows()).map(|_| random(&mut seed) - 0.5).collect();
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let (scale, size) = (1.0, 1e-9);
    let b: Vec<f64> = raw.iter().map(|v| v * size / norm(&raw)).collect();
    let step = |scale: f64| NewtonStep {
        hessian: &h,
        rhs: &b,
        active: &active,
        settled: true,
        scale,
    };
    let mut floored = MultigridSteps::new(lcp, &prolongations, w(1));
    let (d, exact) = floored.solve(step(scale)).expect("CG converges");
    let mut plain = MultigridSteps::new(lcp, &prolongations, w(1));
    let (reference, _) = plain.solve(step(0.0)).expect("CG converges");
    let residual: Vec<f64> = multiply(&h, &d)
        .iter()
        .zip(&b)
        .map(|(p, q)| q - p)
        .collect();
    let floor = MULTIGRID_ROUNDING_FLOOR * scale;
    assert!(
        norm(&residual) <= floor,
        "residual {:e} above the floor {floor:e}",
        norm(&residual)
    );
    assert!(exact, "a step at the rounding floor is exact");
    assert!(
        floored.krylov_iterations < plain.krylov_iterations,
        "{} CG iterations at the floor against {} to 1e-10 of the gradient",
        floored.krylov_iterations,
        plain.krylov_iterations
    );
    let difference: Vec<f64> = d.iter().zip(&reference).map(|(x, y)| x - y).collect();
    assert!(
        norm(&difference) <= 1e-3 * norm(&reference),
        "the directions differ by {:e} of {:e}",
        norm(&difference),
        norm(&reference)
    );
    // no floor without a gradient or a finite scale: the zero step, exact
    let zero = vec![0.0; h.nrows()];
    for scale in [1.0, 0.0, f64::INFINITY, f64::NAN] {
        let (d, exact) = MultigridSteps::new(lcp, &prolongations, w(1))
            .solve(NewtonStep {
                rhs: &zero,
                ..step(scale)
            })
            .expect("a zero right-hand side");
        assert!(exact && d.iter().all(|&x| x == 0.0), "scale {scale}");
    }
}

/// The automatic choice is Cholesky for the stabilized pairs (measured faster at every
/// size), and a hierarchy of one level (no coarser mesh) is solved directly even when
/// multigrid is asked for.
#[test]
fn small_systems_and_single_levels_are_solved_directly() {
    type M = membrane_p1_p0::Model;
    let auto = nested_solve::<M>(32, 0.1, LinearSolver::Auto);
    assert_eq!(auto.iterative_steps, 0);
    assert!(auto.factorizations > 0);
    let scene = membrane_scene("membrane-radial").unwrap();
    let data = SceneData::new(&scene);
    let coefficients = data.coefficients::<M>(0.1);
    let options = ObstacleOptions {
        linear_solver: LinearSolver::Multigrid,
        ..options(VariationalSolver::SemismoothNewton)
    };
    let mesh = membranes::mesh(&scene, 16);
    let single = solve_obstacle_on_triangles::<M>(&[mesh], &coefficients, options).unwrap();
    assert_eq!(single.iterative_steps, 0);
    assert!(single.kkt_residual <= 1e-10);
}

/// `--linear-solver` names: every solver parses back from its name, others are refused
/// with the list.
#[test]
fn linear_solver_names() {
    for s in LinearSolver::ALL {
        assert_eq!(LinearSolver::parse(s.name()).unwrap(), s);
    }
    let error = LinearSolver::parse("gmres").unwrap_err().to_string();
    assert!(error.contains("auto, direct, multigrid"), "{error}");
}
