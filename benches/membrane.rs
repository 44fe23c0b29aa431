//! Membrane speed, every ratio measured in this one run:
//! 1. global stiffness assembly of P1 and P2 on the same mesh (elements per second),
//!    against a hand-written loop that adds barycentric P1 element matrices into the
//!    same fixed CSC pattern;
//! 2. the complete stabilized VI solve (coarse meshes, nested iteration, assembly
//!    included) against one sparse Cholesky analysis + factorization + solve of the
//!    final mesh's matrix `A_α` (the strict baseline: a linear problem of the primal
//!    size, on one thread, faer's fastest here), with the finest level built on a second
//!    thread (the default) and all on one thread; and against one sparse LU
//!    factorization + solve of the saddle-point matrix `[[A_α, −B_αᵀ], [−B_α, −C_α]]`
//!    of the same discretization. Newton iterations per level (the first on each nested
//!    level is Gauss–Seidel sweeps), factorizations and low-rank (Woodbury) updated solves
//!    on the final mesh, from 2k to 524k triangles.
//!
//! `cargo bench --bench membrane` (add `-- --quick` for smaller meshes).
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

#[path = "../tests/common/membranes.rs"]
mod membranes;

use faer::sparse::Triplet;
use fem_forms::lcp::cholesky::{Cholesky, LuSolver};
use fem_forms::lcp::Lcp;
use fem_forms::models::membrane::{membrane_p1, membrane_p2_p0};
use fem_forms::models::membrane_scenes::{membrane_scene, MembraneScene};
use fem_forms::obstacle::triangle::{solve_obstacle_on_triangles, TriangleObstacleSolution};
use fem_forms::obstacle::{ObstacleOptions, VariationalSolver};
use fem_forms::SparseMatrix;
use fem_forms::{Coefficients, Diagonal, MatrixAssembler, Model, SystemDofs, TriangleMesh};
use std::hint::black_box;
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn zero(_: &[f64]) -> f64 {
    0.0
}

/// The hand-written baseline: P1 stiffness from barycentric gradients, added into the
/// values of a fixed pattern at precomputed positions.
fn hand_p1_assembly(mesh: &TriangleMesh, positions: &[u32], values: &mut [f64]) {
    values.fill(0.0);
    for c in 0..mesh.cell_count() {
        let x = mesh.cell_coordinates(c);
        let det = (x[2] - x[0]) * (x[5] - x[1]) - (x[4] - x[0]) * (x[3] - x[1]);
        let g = [
            [x[3] - x[5], x[4] - x[2]],
            [x[5] - x[1], x[0] - x[4]],
            [x[1] - x[3], x[2] - x[0]],
        ];
        let scale = 0.5 / det.abs();
        let p = &positions[9 * c..9 * c + 9];
        for i in 0..3 {
            for j in 0..3 {
                values[p[3 * i + j] as usize] += scale * (g[i][0] * g[j][0] + g[i][1] * g[j][1]);
            }
        }
    }
}

fn assembly(n: usize, rounds: usize) {
    let mesh = TriangleMesh::rectangle(-2.0, 2.0, -2.0, 2.0, n, n, Diagonal::Right).unwrap();
    let cells = mesh.cell_count();
    println!("assembly of the stiffness ∫∇u·∇v on {n}×{n}×2 = {cells} triangles (median of {rounds} rounds)");
    // P1: generated, through the generic assembler
    type P1 = membrane_p1::Model;
    let coefficients = Coefficients::from_ids::<P1>(
        &[],
        &[
            (membrane_p1::data::f, &zero),
            (membrane_p1::data::ψ, &zero),
            (membrane_p1::data::g, &zero),
        ],
    )
    .unwrap();
    let dofs = SystemDofs::named::<P1>(&mesh, &["u"]).unwrap();
    let clock = Instant::now();
    let assembler = MatrixAssembler::new::<P1>("a", &mesh, &dofs).unwrap();
    let pattern_seconds = clock.elapsed().as_secs_f64();
    let mut values = Vec::new();
    // hand-written: positions of every local entry in the same pattern (not timed)
    let map = dofs.map(0).unwrap();
    let (col_ptr, row_idx) = (
        assembler.symbolic().col_ptr().to_vec(),
        assembler.symbolic().row_idx().to_vec(),
    );
    let mut positions = Vec::with_capacity(9 * cells);
    for c in 0..cells {
        let d = map.cell_dofs(c);
        for &r in d {
            for &col in d {
                let column = &row_idx[col_ptr[col]..col_ptr[col + 1]];
                positions.push((col_ptr[col] + column.binary_search(&r).unwrap()) as u32);
            }
        }
    }
    let mut hand_values = vec![0.0; assembler.nonzero_count()];
    let (mut generated, mut hand) = (Vec::new(), Vec::new());
    for round in 0..rounds {
        let mut time_generated = || {
            let t = Instant::now();
            assembler
                .assemble_values::<P1>(&mesh, &coefficients, &mut values)
                .unwrap();
            black_box(&values);
            t.elapsed().as_secs_f64()
        };
        let mut time_hand = || {
            let t = Instant::now();
            hand_p1_assembly(&mesh, &positions, &mut hand_values);
            black_box(&hand_values);
            t.elapsed().as_secs_f64()
        };
        if round % 2 == 0 {
            generated.push(time_generated());
            hand.push(time_hand());
        } else {
            hand.push(time_hand());
            generated.push(time_generated());
        }
    }
    let difference = values
        .iter()
        .zip(&hand_values)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(
        difference < 1e-10,
        "generated and hand-written P1 assembly differ by {difference}"
    );
    let (g, h) = (median(generated), median(hand));
    println!(
        "  P1 generated   {:>7.1} M triangles/s  ({:.3} s; pattern built once in {:.3} s)",
        cells as f64 / g / 1e6,
        g,
        pattern_seconds
    );
    println!(
        "  P1 hand-written {:>6.1} M triangles/s  ({:.3} s)   generated/hand time ratio {:.2}",
        cells as f64 / h / 1e6,
        h,
        g / h
    );
    // P2: the u block of the P2–P0 membrane's `a`
    type P2 = membrane_p2_p0::Model;
    let coefficients = Coefficients::from_ids(
        &[(membrane_p2_p0::params::α, 0.0)],
        &[
            (membrane_p2_p0::data::f, &zero),
            (membrane_p2_p0::data::ψ, &zero),
            (membrane_p2_p0::data::g, &zero),
        ],
    )
    .unwrap();
    let dofs = SystemDofs::named::<P2>(&mesh, &["u"]).unwrap();
    let assembler = MatrixAssembler::new::<P2>("a", &mesh, &dofs).unwrap();
    let times: Vec<f64> = (0..rounds)
        .map(|_| {
            let t = Instant::now();
            assembler
                .assemble_values::<P2>(&mesh, &coefficients, &mut values)
                .unwrap();
            black_box(&values);
            t.elapsed().as_secs_f64()
        })
        .collect();
    let p2 = median(times);
    println!(
        "  P2 generated   {:>7.1} M triangles/s  ({:.3} s, 36 entries per triangle)",
        cells as f64 / p2 / 1e6,
        p2
    );
}

/// One complete stabilized VI solve of the radial scene on the `n × n × 2` mesh: the
/// coarse meshes, every level's assembly and solve (nested from N = 4), as the CLI runs
/// it. Returns the solution and its wall time.
fn vi_solve_once<M: Model>(
    scene: &MembraneScene,
    coefficients: &Coefficients,
    mesh: &TriangleMesh,
    n: usize,
    pipelined: bool,
) -> (TriangleObstacleSolution, f64) {
    let clock = Instant::now();
    let mut sizes = vec![n];
    while sizes[0] / 2 >= 4 && sizes[0] % 2 == 0 {
        sizes.insert(0, sizes[0] / 2);
    }
    // the final mesh is the input, as the matrix is the baseline's; the coarse ones are
    // the solver's own
    let mut meshes: Vec<TriangleMesh> = sizes[..sizes.len() - 1]
        .iter()
        .map(|&k| membranes::mesh(scene, k))
        .collect();
    meshes.push(mesh.clone());
    let options = ObstacleOptions {
        pipelined,
        ..membranes::options(VariationalSolver::SemismoothNewton)
    };
    let solution = solve_obstacle_on_triangles::<M>(&meshes, coefficients, options).unwrap();
    (solution, clock.elapsed().as_secs_f64())
}

/// One Cholesky analysis + factorization + solve of `a`, timed.
fn cholesky_once(a: &SparseMatrix) -> f64 {
    let clock = Instant::now();
    let pattern = a.symbolic().to_owned().unwrap();
    let factor = Cholesky::analyse(&pattern).unwrap().factor(a).unwrap();
    black_box(factor.solve(&vec![1.0; a.nrows()]).unwrap());
    clock.elapsed().as_secs_f64()
}

/// The complete VI solve against one Cholesky of the final `A_α`, all measured in this
/// run after one untimed warm-up solve (the allocator then holds the memory, for the
/// solve as for the baseline), medians of `rounds` interleaved repetitions.
fn vi_solve<M: Model>(pair: &str, sizes: &[usize], rounds: usize, with_lu: bool) {
    let scene = membrane_scene("membrane-radial").unwrap();
    println!(
        "\n{} on membrane-radial: complete VI solve (nested from N = 4, assembly included) vs one Cholesky (analysis + factorization + solve) of the final A_α; medians of {rounds}",
        pair
    );
    println!(
        "{:>5} {:>9} {:>9} {:>16} {:>8} {:>10} {:>11} {:>6} {:>11} {:>6} {:>9} {:>6}",
        "N",
        "triangles",
        "dofs",
        "iterations/level",
        "fact/upd",
        "Cholesky s",
        "VI s (2 thr)",
        "ratio",
        "VI s (1 thr)",
        "ratio",
        "KKT LU s",
        "ratio"
    );
    for &n in sizes {
        let mesh = membranes::mesh(&scene, n);
        let data = membranes::SceneData::new(&scene);
        let coefficients = data.coefficients::<M>(membranes::alpha::<M>(&mesh));
        let (warm, _) = vi_solve_once::<M>(&scene, &coefficients, &mesh, n, true);
        let a = warm.discretization.lcp.a.clone();
        let (mut linear, mut pipelined, mut sequential) = (Vec::new(), Vec::new(), Vec::new());
        for _ in 0..rounds {
            linear.push(cholesky_once(&a));
            pipelined.push(vi_solve_once::<M>(&scene, &coefficients, &mesh, n, true).1);
            sequential.push(vi_solve_once::<M>(&scene, &coefficients, &mesh, n, false).1);
        }
        let (linear, pipelined, sequential) =
            (median(linear), median(pipelined), median(sequential));
        // the saddle-point matrix of the same discretization, factored by sparse LU
        let saddle = with_lu.then(|| {
            let k = kkt_matrix(&warm.discretization.lcp);
            let t = Instant::now();
            let pattern = k.symbolic().to_owned().unwrap();
            let factor = LuSolver::analyse(&pattern).unwrap().factor(&k).unwrap();
            black_box(factor.solve(&vec![1.0; k.nrows()]).unwrap());
            t.elapsed().as_secs_f64()
        });
        let lcp = &warm.discretization.lcp;
        let levels = warm
            .levels
            .iter()
            .map(|(_, i)| i.to_string())
            .collect::<Vec<_>>()
            .join(",");
        let (lu, lu_ratio) = saddle.map_or(("-".to_string(), "-".to_string()), |s| {
            (format!("{s:.3}"), format!("{:.2}", pipelined / s))
        });
        println!(
            "{:>5} {:>9} {:>9} {:>16} {:>8} {:>10.3} {:>11.3} {:>6.2} {:>11.3} {:>6.2} {:>9} {:>6}",
            n,
            2 * n * n,
            lcp.n() + lcp.m(),
            levels,
            format!("{}/{}", warm.factorizations, warm.low_rank_updates),
            linear,
            pipelined,
            pipelined / linear,
            sequential,
            sequential / linear,
            lu,
            lu_ratio
        );
    }
}

/// The KKT matrix `[[A, −Bᵀ], [−B, −C]]` of an LCP with a diagonal C.
fn kkt_matrix(lcp: &Lcp) -> SparseMatrix {
    let n = lcp.n();
    let mut triplets = Vec::new();
    let a = &lcp.a;
    let (col_ptr, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    for j in 0..n {
        for k in col_ptr[j]..col_ptr[j + 1] {
            triplets.push(Triplet::new(rows[k], j, vals[k]));
        }
    }
    for (k, row) in lcp.b_rows.iter().enumerate() {
        for &(j, v) in row {
            triplets.push(Triplet::new(n + k, j, -v));
            triplets.push(Triplet::new(j, n + k, -v));
        }
        triplets.push(Triplet::new(n + k, n + k, -lcp.c[k]));
    }
    let size = n + lcp.m();
    SparseMatrix::try_new_from_triplets(size, size, &triplets).unwrap()
}

fn main() {
    fem_forms::lcp::cholesky::factor_sequentially();
    fem_forms::allocator::keep_freed_memory();
    let quick = std::env::args().any(|a| a == "--quick");
    let (assembly_n, p1_sizes, p2_sizes): (usize, Vec<usize>, Vec<usize>) = if quick {
        (128, vec![32, 64, 128], vec![32, 64])
    } else {
        (512, vec![32, 64, 128, 256, 512], vec![32, 64, 128, 256])
    };
    assembly(assembly_n, if quick { 3 } else { 9 });
    let rounds = if quick { 3 } else { 5 };
    vi_solve::<fem_forms::models::membrane::membrane_p1_p0::Model>(
        "p1-p0", &p1_sizes, rounds, !quick,
    );
    vi_solve::<membrane_p2_p0::Model>("p2-p0", &p2_sizes, rounds, !quick);
}
