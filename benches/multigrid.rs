//! Multigrid-preconditioned CG against sparse Cholesky on the Newton Hessian of the
//! radial membrane at its converged active set (issue 15), every ratio measured in this
//! one run, on one thread (faer's sequential mode, as the CLI runs).
//!
//! For each pair and mesh N × N × 2: Cholesky's symbolic analysis (done once per pattern
//! in Newton), its numeric factorization + solve (each Newton step), the multigrid setup
//! (prolongations, Galerkin operators, coarsest factorization; once per Newton step,
//! since the Hessian changes) and PCG to a relative residual of 1e-6 and of 1e-10 with
//! the V(1,1) and W(1,1) cycles. Medians of rounds.
//!
//! Then the 2-thread speed-up of the parallel kernels (assembly of the stiffness, the
//! multigrid products and the multicolour symmetric Gauss–Seidel sweep), each timed in a
//! 1-thread and a 2-thread rayon pool in this run, at 524k triangles P1 and 131k P2.
//!
//! `cargo bench --bench multigrid` (add `-- --quick` for smaller meshes, `-- --parallel`
//! for the parallel kernels only).
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

#[path = "../tests/common/membranes.rs"]
mod membranes;

use fem_forms::lcp::cholesky::Cholesky;
use fem_forms::models::membrane::{membrane_p1, membrane_p1_p0, membrane_p2_p0};
use fem_forms::models::membrane_scenes::membrane_scene;
use fem_forms::multigrid::{
    parents_by_location, prolongation, Multigrid, MultigridOptions, NestedLevel,
};
use fem_forms::obstacle::triangle::{discretize_on_triangles, solve_obstacle_on_triangles};
use fem_forms::obstacle::{Discretization, VariationalSolver};
use fem_forms::{
    assemble_vector, Coefficients, Constraints, Diagonal, MatrixAssembler, Model, Reduction,
    SparseMatrix, SystemDofs, TriangleMesh,
};
use std::hint::black_box;
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Seconds of `f`, median of `rounds`, and its last result.
fn timed<T>(rounds: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..rounds {
        let clock = Instant::now();
        last = Some(black_box(f()));
        times.push(clock.elapsed().as_secs_f64());
    }
    (median(times), last.unwrap())
}

/// The primal field with the DOFs the discretization fixes (as tests/multigrid.rs).
fn primal_level<M: Model>(d: &Discretization<TriangleMesh>) -> (SystemDofs, Reduction) {
    let dofs = SystemDofs::named::<M>(&d.mesh, &["u"]).unwrap();
    let u = d.dofs.range(M::field("u").unwrap()).unwrap();
    let mut constraints = Constraints::new();
    for dof in u.filter(|&dof| d.reduction.free_index(dof).is_none()) {
        constraints.fix_dof(dof, 0.0).unwrap();
    }
    let reduction = constraints.reduction(dofs.dof_count()).unwrap();
    assert_eq!(reduction.free().len(), d.lcp.n());
    (dofs, reduction)
}

fn run<M: Model>(name: &str, alpha: f64, sizes: &[usize], rounds: usize) {
    let scene = membrane_scene("membrane-radial").unwrap();
    let data = membranes::SceneData::new(&scene);
    let coefficients = data.coefficients::<M>(alpha);
    let solve_options = membranes::options(VariationalSolver::SemismoothNewton);
    println!("{name}, α = {alpha:.4e}: seconds (median of {rounds})");
    println!(
        "| N | unknowns | Cholesky analysis | factor + solve | MG setup | MG update (all active) | V 1e-6 (its) | V 1e-10 (its) | W 1e-6 (its) | W 1e-10 (its) | setup + W 1e-6 / factor + solve |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    for &size in sizes {
        let mut meshes = Vec::new();
        let mut n = 4;
        while n <= size {
            meshes.push(membranes::mesh(&scene, n));
            n *= 2;
        }
        let solution =
            solve_obstacle_on_triangles::<M>(&meshes, &coefficients, solve_options).unwrap();
        let d = &solution.discretization;
        let (h, _) = d
            .lcp
            .newton_hessian(&d.primal_part(&solution.values))
            .unwrap();
        let mut state = 7u64;
        let b: Vec<f64> = (0..h.nrows())
            .map(|_| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            })
            .collect();
        let pattern = h.symbolic().to_owned().unwrap();
        let (analysis, cholesky) = timed(rounds, || Cholesky::analyse(&pattern).unwrap());
        let (direct, _) = timed(rounds, || cholesky.factor(&h).unwrap().solve(&b).unwrap());
        // the hierarchy's meshes and primal DOFs do not change between Newton steps:
        // built once, outside the timing
        let discretizations: Vec<_> = meshes
            .iter()
            .map(|mesh| discretize_on_triangles::<M>(mesh, &coefficients, "B_h", "L_h").unwrap())
            .collect();
        let primal: Vec<_> = discretizations.iter().map(primal_level::<M>).collect();
        let parents: Vec<Vec<usize>> = (1..meshes.len())
            .map(|l| parents_by_location(&meshes[l - 1], &meshes[l]).unwrap())
            .collect();
        let prolongations: Vec<SparseMatrix> = (1..meshes.len())
            .rev()
            .map(|l| {
                let level = |k: usize| NestedLevel {
                    mesh: &meshes[k],
                    dofs: &primal[k].0,
                    reduction: Some(&primal[k].1),
                };
                prolongation(&level(l - 1), &level(l), &parents[l - 1]).unwrap()
            })
            .collect();
        let build = |coarse_corrections| {
            Multigrid::new(
                h.clone(),
                prolongations.clone(),
                MultigridOptions {
                    sweeps: 1,
                    coarse_corrections,
                },
            )
            .unwrap()
        };
        let (setup, v) = timed(rounds, || build(1));
        let w = build(2);
        // what a Newton step pays instead of the setup: the coarse operators updated by
        // the terms of the flipped constraints (here all active ones, from the hierarchy
        // of A: an upper bound) and the fine level and coarsest factor renewed
        let lcp = &d.lcp;
        let u = d.primal_part(&solution.values);
        let active: Vec<bool> = lcp
            .eliminated_multiplier(&lcp.b_times(&u))
            .iter()
            .map(|&l| l > 0.0)
            .collect();
        let none = vec![false; active.len()];
        let mut base = Multigrid::new(
            lcp.a.clone(),
            prolongations.clone(),
            MultigridOptions::default(),
        )
        .unwrap();
        let (update, _) = timed(rounds, || {
            lcp.hessian_change_blocks(&none, &active, |rows, change| {
                base.add_coarse_term(rows, change)
            })
            .unwrap();
            base.reset_fine(&h).unwrap();
        });
        let mut cells = Vec::new();
        for mg in [&v, &w] {
            for tolerance in [1e-6, 1e-10] {
                let (seconds, pcg) = timed(rounds, || mg.pcg(&b, tolerance, 200).unwrap());
                cells.push((seconds, pcg.iterations));
            }
        }
        let cell = |(s, i): (f64, usize)| format!("{s:.3} ({i})");
        println!(
            "| {size} | {} | {analysis:.3} | {direct:.3} | {setup:.3} | {update:.3} | {} | {} | {} | {} | {:.2} |",
            h.nrows(),
            cell(cells[0]),
            cell(cells[1]),
            cell(cells[2]),
            cell(cells[3]),
            (setup + cells[2].0) / direct
        );
    }
}

/// Seconds per call of `f` (median of 5 rounds of `calls` calls) in a pool of `threads`.
fn pool_timed(threads: usize, calls: usize, mut f: impl FnMut() + Send) -> f64 {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        f(); // warm: first touch of the output pages
        let times: Vec<f64> = (0..5)
            .map(|_| {
                let clock = Instant::now();
                for _ in 0..calls {
                    f();
                }
                clock.elapsed().as_secs_f64() / calls as f64
            })
            .collect();
        median(times)
    })
}

fn zero(_: &[f64]) -> f64 {
    0.0
}

/// One table row: 1-thread and 2-thread times (ms) and their ratio.
fn speedup_row(what: &str, calls: usize, mut f: impl FnMut() + Send) {
    let one = pool_timed(1, calls, &mut f);
    let two = pool_timed(2, calls, &mut f);
    println!(
        "| {what} | {:.2} | {:.2} | {:.2} |",
        one * 1e3,
        two * 1e3,
        one / two
    );
}

/// The parallel kernels' 2-thread speed-up on the stiffness `a` of field `u` of `M` on an
/// `n × n × 2` right-diagonal square, with the prolongation from `n/2`.
fn parallel_kernels<M: Model>(name: &str, n: usize, coefficients: &Coefficients) {
    use fem_forms::multigrid::sparse;
    let coarse_mesh =
        TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, n / 2, n / 2, Diagonal::Right).unwrap();
    let mesh = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, n, n, Diagonal::Right).unwrap();
    let dofs = SystemDofs::named::<M>(&mesh, &["u"]).unwrap();
    let coarse_dofs = SystemDofs::named::<M>(&coarse_mesh, &["u"]).unwrap();
    let assembler = MatrixAssembler::new::<M>("a", &mesh, &dofs).unwrap();
    let a = assembler.assemble::<M>(&mesh, coefficients).unwrap();
    let unknowns = a.nrows();
    println!(
        "\n{name}: {} triangles, {unknowns} unknowns, {} nonzeros; ms per call (median of 5 rounds)",
        mesh.cell_count(),
        a.val().len()
    );
    println!("| kernel | 1 thread | 2 threads | speed-up |");
    println!("|---|---|---|---|");
    let mut values = Vec::new();
    speedup_row("matrix assembly", 3, || {
        assembler
            .assemble_values::<M>(&mesh, coefficients, &mut values)
            .unwrap();
        black_box(&values);
    });
    speedup_row("vector assembly ℓ", 3, || {
        black_box(assemble_vector::<M>("ℓ", &mesh, &dofs, coefficients).unwrap());
    });
    let parents = parents_by_location(&coarse_mesh, &mesh).unwrap();
    let level = |mesh, dofs| NestedLevel {
        mesh,
        dofs,
        reduction: None,
    };
    let p = prolongation(
        &level(&coarse_mesh, &coarse_dofs),
        &level(&mesh, &dofs),
        &parents,
    )
    .unwrap();
    let pt = sparse::transpose_of(&p);
    let mut state = 7u64;
    let x: Vec<f64> = (0..unknowns)
        .map(|_| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        })
        .collect();
    let mut y = vec![0.0; unknowns];
    let mut coarse = vec![0.0; p.ncols()];
    speedup_row("y = A x (rows)", 20, || {
        sparse::multiply_symmetric_into(&a, &x, &mut y)
    });
    speedup_row("x += P e (rows of Pᵀ)", 20, || {
        sparse::prolong_add_transposed(&pt, &x[..p.ncols()], &mut y)
    });
    speedup_row("e = Pᵀ r", 20, || {
        sparse::restrict_parallel(&p, &x, &mut coarse)
    });
    let inverse: Vec<f64> = {
        let (ptr, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
        (0..unknowns)
            .map(|j| {
                let k = (ptr[j]..ptr[j + 1]).find(|&k| rows[k] == j).unwrap();
                1.0 / vals[k]
            })
            .collect()
    };
    let clock = Instant::now();
    let coloured = sparse::Smoother::coloured(&a);
    let colouring = clock.elapsed().as_secs_f64();
    let lexicographic = sparse::Smoother::lexicographic();
    let serial = pool_timed(1, 10, || {
        lexicographic.symmetric_sweep(&a, &inverse, &x, &mut y)
    });
    speedup_row(
        &format!("symmetric GS, {} colours", coloured.colour_count()),
        10,
        || coloured.symmetric_sweep(&a, &inverse, &x, &mut y),
    );
    let hybrid = sparse::Smoother::hybrid(unknowns, 8);
    speedup_row("symmetric GS, hybrid (8 blocks)", 10, || {
        hybrid.symmetric_sweep(&a, &inverse, &x, &mut y)
    });
    println!(
        "lexicographic symmetric GS (1 thread): {:.2} ms; multicolouring (once per pattern): {:.2} ms",
        serial * 1e3,
        colouring * 1e3
    );
}

fn parallel(quick: bool) {
    let (n1, n2) = if quick { (128, 64) } else { (512, 256) };
    type P1 = membrane_p1::Model;
    let c1 = Coefficients::from_ids::<P1>(
        &[],
        &[
            (membrane_p1::data::f, &zero),
            (membrane_p1::data::ψ, &zero),
            (membrane_p1::data::g, &zero),
        ],
    )
    .unwrap();
    parallel_kernels::<P1>("P1", n1, &c1);
    type P2 = membrane_p2_p0::Model;
    let c2 = Coefficients::from_ids::<P2>(
        &[(membrane_p2_p0::params::α, 0.0)],
        &[
            (membrane_p2_p0::data::f, &zero),
            (membrane_p2_p0::data::ψ, &zero),
            (membrane_p2_p0::data::g, &zero),
        ],
    )
    .unwrap();
    parallel_kernels::<P2>("P2", n2, &c2);
}

fn main() {
    fem_forms::lcp::cholesky::factor_sequentially();
    let quick = std::env::args().any(|a| a == "--quick");
    if std::env::args().any(|a| a == "--parallel") {
        parallel(quick);
        return;
    }
    let rounds = if quick { 1 } else { 3 };
    let (p1, p2): (&[usize], &[usize]) = if quick {
        (&[64, 128], &[32, 64])
    } else {
        (&[256, 512], &[128, 256])
    };
    run::<membrane_p1_p0::Model>("P1–P0", 0.1, p1, rounds);
    run::<membrane_p2_p0::Model>("P2–P0", 0.5 / 96.0, p2, rounds);
    parallel(quick);
}
