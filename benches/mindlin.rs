//! Reissner–Mindlin plate speed (`mindlin_stenberg`: θ ∈ [P1]², w ∈ P2, λ ∈ P0,
//! docs/mathematics.md §9), every ratio measured in this one run:
//! 1. assembly of the whole system matrix `B_h` (13 × 13 local entries, the θ–λ blocks
//!    structurally zero) in triangles per second, generated kernels through the generic
//!    assembler against a hand-written loop (closed-form element matrix, the edge-midpoint
//!    rule exact for its quadratic integrands, added into the same CSC pattern at
//!    precomputed positions); both results are compared entry by entry;
//! 2. the complete stabilized VI solve of a clamped square plate pressed by an upward
//!    load q = 1000 against a flat obstacle above (w ≤ 0.05, t = 1e-3; the contact set
//!    a rounded square of about half the plate), nested from N = 8, assembly included,
//!    against one sparse Cholesky analysis + factorization + solve of the final mesh's
//!    primal matrix `A` (the linear problem of the same size), up to 131k triangles;
//!    "final LCP s" is the semismooth Newton solve on the final mesh alone (the rest of
//!    the VI time is the coarse levels and the assembly of every level); the "swept"
//!    columns start each nested level with Gauss–Seidel sweeps as the membrane does.
//!
//! `cargo bench --bench mindlin` (add `-- --quick` for small meshes).
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

use fem_forms::lcp::cholesky::Cholesky;
use fem_forms::mesh::triangle::QuadraticGeometry;
use fem_forms::models::mindlin::mindlin_stenberg;
use fem_forms::obstacle::triangle::{
    solve_obstacle_on_curved_triangles, solve_obstacle_on_triangles, CurvedObstacleSolution,
    TriangleObstacleSolution,
};
use fem_forms::obstacle::ObstacleOptions;
use fem_forms::{
    Coefficients, DataFn, Diagonal, MatrixAssembler, Model, SparseMatrix, SystemDofs, TriangleMesh,
};
use std::hint::black_box;
use std::time::Instant;

type M = mindlin_stenberg::Model;

const D: f64 = 1.0;
const NU: f64 = 0.3;
const KAPPA: f64 = 5.0 / 6.0;
const T: f64 = 1e-3;
const BETA: f64 = 0.1;
const ALPHA: f64 = 0.1;
/// The obstacle lies above: `s = −1`.
const S: f64 = -1.0;
const Q: f64 = 1000.0;

fn upward_load(_: &[f64]) -> f64 {
    Q
}

fn flat_obstacle(_: &[f64]) -> f64 {
    0.05
}

fn zero(_: &[f64]) -> f64 {
    0.0
}

fn coefficients() -> Coefficients<'static> {
    let params = [
        ("D", D),
        ("ν", NU),
        ("κ", KAPPA),
        ("t", T),
        ("β", BETA),
        ("α", ALPHA),
        ("s", S),
    ];
    let data: [(&str, &DataFn); 3] = [("f", &upward_load), ("ψ", &flat_obstacle), ("g", &zero)];
    Coefficients::new::<M>(&params, &data).unwrap()
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn square(n: usize) -> TriangleMesh {
    TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, n, n, Diagonal::Right).unwrap()
}

/// Local DOFs of the system on one cell: θ_x 0–2, θ_y 3–5 (P1 at the vertices), w 6–11
/// (P2: vertices, then the edges 01, 12, 20), λ 12 (P0).
const LOCAL: usize = 13;

/// The hand-written element matrix of `B_h = a − b(v;λ) − b(w;μ) − α S` on the cell with
/// vertex coordinates `x` (as `TriangleMesh::cell_coordinates`): the bending part
/// `∫ D[(1−ν)ε(θ):ε(η) + ν div θ div η]` is constant on the cell; the shear part with
/// the Stenberg weight `6κ(1−ν)D/(t² + βh²)`, and `∫ s v μ`, have integrands of degree
/// ≤ 2, which the three edge midpoints with weights |T|/3 integrate exactly.
fn hand_element(x: &[f64; 6]) -> [[f64; LOCAL]; LOCAL] {
    let p = [[x[0], x[1]], [x[2], x[3]], [x[4], x[5]]];
    let det = (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]);
    let area = 0.5 * det.abs();
    // barycentric gradients
    let g: [[f64; 2]; 3] = std::array::from_fn(|i| {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        [(p[j][1] - p[k][1]) / det, (p[k][0] - p[j][0]) / det]
    });
    let edge = |i: usize, j: usize| (p[i][0] - p[j][0]).hypot(p[i][1] - p[j][1]);
    let h = edge(0, 1).max(edge(1, 2)).max(edge(2, 0));
    let shear = 6.0 * KAPPA * (1.0 - NU) * D / (T * T + BETA * h * h);
    let mut k = [[0.0; LOCAL]; LOCAL];
    // bending: ε(φ_i e_a):ε(φ_j e_b) = ½(δ_ab g_i·g_j + g_i[b] g_j[a])
    for a in 0..2 {
        for b in 0..2 {
            for i in 0..3 {
                for j in 0..3 {
                    let dot = if a == b {
                        g[i][0] * g[j][0] + g[i][1] * g[j][1]
                    } else {
                        0.0
                    };
                    k[3 * a + i][3 * b + j] = area
                        * D
                        * (0.5 * (1.0 - NU) * (dot + g[i][b] * g[j][a]) + NU * g[i][a] * g[j][b]);
                }
            }
        }
    }
    let weight = area / 3.0;
    for point in [[0.5, 0.5, 0.0], [0.0, 0.5, 0.5], [0.5, 0.0, 0.5]] {
        let l: [f64; 3] = point;
        // P2: values and gradients of the vertex and edge functions at the point
        let mut value = [0.0; 6];
        let mut grad = [[0.0; 2]; 6];
        for i in 0..3 {
            value[i] = l[i] * (2.0 * l[i] - 1.0);
            let s = 4.0 * l[i] - 1.0;
            grad[i] = [s * g[i][0], s * g[i][1]];
            let (a, b) = (i, (i + 1) % 3);
            value[3 + i] = 4.0 * l[a] * l[b];
            grad[3 + i] = [
                4.0 * (l[b] * g[a][0] + l[a] * g[b][0]),
                4.0 * (l[b] * g[a][1] + l[a] * g[b][1]),
            ];
        }
        let ws = weight * shear;
        for i in 0..6 {
            for j in 0..6 {
                k[6 + i][6 + j] += ws * (grad[i][0] * grad[j][0] + grad[i][1] * grad[j][1]);
            }
            // −b(v;λ), −b(w;μ)
            k[6 + i][12] -= weight * S * value[i];
            k[12][6 + i] -= weight * S * value[i];
        }
        for a in 0..2 {
            for i in 0..3 {
                for j in 0..3 {
                    k[3 * a + i][3 * a + j] += ws * l[i] * l[j];
                }
                for j in 0..6 {
                    let v = -ws * l[i] * grad[j][a];
                    k[3 * a + i][6 + j] += v;
                    k[6 + j][3 * a + i] += v;
                }
            }
        }
    }
    k[12][12] = -ALPHA * h.powi(4) * S * S * area;
    k
}

/// For each cell and local entry (row-major, `LOCAL²` per cell) its position in the
/// pattern of `assembler` (32-bit, as the generated assembly's), `u32::MAX` for the
/// structurally zero θ–λ entries.
fn positions(mesh: &TriangleMesh, dofs: &SystemDofs, assembler: &MatrixAssembler) -> Vec<u32> {
    let fields = ["θ_x", "θ_y", "w", "λ"].map(|f| M::field(f).unwrap());
    let (col_ptr, row_idx) = (
        assembler.symbolic().col_ptr(),
        assembler.symbolic().row_idx(),
    );
    let mut out = Vec::with_capacity(LOCAL * LOCAL * mesh.cell_count());
    let mut global = Vec::with_capacity(LOCAL);
    for c in 0..mesh.cell_count() {
        global.clear();
        for &f in &fields {
            let offset = dofs.offset(f).unwrap();
            global.extend(dofs.map(f).unwrap().cell_dofs(c).iter().map(|d| offset + d));
        }
        for &r in &global {
            for &col in &global {
                let column = &row_idx[col_ptr[col]..col_ptr[col + 1]];
                out.push(
                    column
                        .binary_search(&r)
                        .map_or(u32::MAX, |k| (col_ptr[col] + k) as u32),
                );
            }
        }
    }
    out
}

/// The hand-written assembly loop.
fn hand_assembly(mesh: &TriangleMesh, positions: &[u32], values: &mut [f64]) {
    values.fill(0.0);
    for c in 0..mesh.cell_count() {
        let k = hand_element(&mesh.cell_coordinates(c));
        let p = &positions[LOCAL * LOCAL * c..LOCAL * LOCAL * (c + 1)];
        for (i, row) in k.iter().enumerate() {
            for (j, &v) in row.iter().enumerate() {
                let at = p[LOCAL * i + j];
                if at != u32::MAX {
                    values[at as usize] += v;
                }
            }
        }
    }
}

fn assembly(n: usize, rounds: usize) {
    let mesh = square(n);
    let cells = mesh.cell_count();
    let c = coefficients();
    let dofs = SystemDofs::all::<M>(&mesh).unwrap();
    let clock = Instant::now();
    let assembler = MatrixAssembler::new::<M>("B_h", &mesh, &dofs).unwrap();
    let pattern_seconds = clock.elapsed().as_secs_f64();
    println!(
        "assembly of the Mindlin B_h on {n}×{n}×2 = {cells} triangles, {} DOFs, {} stored entries (median of {rounds} interleaved rounds)",
        dofs.dof_count(),
        assembler.nonzero_count()
    );
    let positions = positions(&mesh, &dofs, &assembler);
    let mut values = Vec::new();
    let mut hand_values = vec![0.0; assembler.nonzero_count()];
    let (mut generated, mut hand) = (Vec::new(), Vec::new());
    for round in 0..rounds {
        let mut time_generated = || {
            let t = Instant::now();
            assembler
                .assemble_values::<M>(&mesh, &c, &mut values)
                .unwrap();
            black_box(&values);
            t.elapsed().as_secs_f64()
        };
        let mut time_hand = || {
            let t = Instant::now();
            hand_assembly(&mesh, &positions, &mut hand_values);
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
    let scale = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let difference = values
        .iter()
        .zip(&hand_values)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(
        difference <= 1e-12 * scale,
        "generated and hand-written Mindlin assembly differ by {difference} (largest entry {scale})"
    );
    let (g, h) = (median(generated), median(hand));
    println!(
        "  generated    {:>6.2} M triangles/s  ({:.3} s; pattern built once in {:.3} s)",
        cells as f64 / g / 1e6,
        g,
        pattern_seconds
    );
    println!(
        "  hand-written {:>6.2} M triangles/s  ({:.3} s)   generated/hand time ratio {:.2}   (largest difference {:.1e} of the largest entry)",
        cells as f64 / h / 1e6,
        h,
        g / h,
        difference / scale
    );
}

/// The element kernels alone, without the scatter: per triangle, every block of the
/// generated `B_h` through `Model::element_matrix` against the one hand-written element
/// matrix (both summed so that they are kept). Separates the kernels' arithmetic from
/// the assembler's memory traffic (it adds each block in its own pass over the mesh).
fn kernels_only(n: usize, rounds: usize) {
    let mesh = square(n);
    let c = coefficients();
    let form = M::form("B_h").unwrap();
    let blocks = M::FORMS[form].blocks;
    let fields = M::FIELDS;
    let size = |f: usize| {
        fields[f]
            .element
            .local_dof_count(fem_forms::CellKind::Triangle)
    };
    let mut buffer = vec![0.0; LOCAL * LOCAL];
    let (mut generated, mut hand) = (Vec::new(), Vec::new());
    for _ in 0..rounds {
        let t = Instant::now();
        let mut sum = 0.0;
        for cell in 0..mesh.cell_count() {
            let x = mesh.cell_coordinates(cell);
            for (b, block) in blocks.iter().enumerate() {
                let entries = size(block.test_field) * size(block.trial_field.unwrap());
                M::element_matrix(
                    form,
                    b,
                    black_box(&x),
                    &c.params,
                    &c.data,
                    &mut buffer[..entries],
                );
                sum += buffer[0] + buffer[entries - 1];
            }
        }
        black_box(sum);
        generated.push(t.elapsed().as_secs_f64());
        let t = Instant::now();
        let mut sum = 0.0;
        for cell in 0..mesh.cell_count() {
            let k = hand_element(black_box(&mesh.cell_coordinates(cell)));
            sum += k[0][0] + k[LOCAL - 1][LOCAL - 1];
        }
        black_box(sum);
        hand.push(t.elapsed().as_secs_f64());
    }
    let per = |v: Vec<f64>| median(v) / mesh.cell_count() as f64 * 1e9;
    let (g, h) = (per(generated), per(hand));
    println!(
        "  kernels alone ({} blocks): generated {g:.1} ns/triangle, hand-written {h:.1} ns/triangle, ratio {:.2}",
        blocks.len(),
        g / h
    );
}

/// The scatter alone (adding 1 at every position, no kernel): one pass over the
/// triangles adding all 157 entries of each, against one pass per nonzero block (12, in
/// the local ranges θ_x 0–2, θ_y 3–5, w 6–11, λ 12) as the generic assembler does.
fn scatter_only(n: usize, rounds: usize) {
    let mesh = square(n);
    let dofs = SystemDofs::all::<M>(&mesh).unwrap();
    let assembler = MatrixAssembler::new::<M>("B_h", &mesh, &dofs).unwrap();
    let positions = positions(&mesh, &dofs, &assembler);
    let mut values = vec![0.0; assembler.nonzero_count()];
    let ranges = [0..3, 3..6, 6..12, 12..13];
    let blocks: Vec<(usize, usize)> = (0..4)
        .flat_map(|a| (0..4).map(move |b| (a, b)))
        .filter(|&(a, b)| !((a < 2 && b == 3) || (a == 3 && b < 2)))
        .collect();
    let (mut once, mut per_block) = (Vec::new(), Vec::new());
    for _ in 0..rounds {
        values.fill(0.0);
        let t = Instant::now();
        for at in positions.chunks_exact(LOCAL * LOCAL) {
            for &p in at {
                if p != u32::MAX {
                    values[p as usize] += 1.0;
                }
            }
        }
        black_box(&values);
        once.push(t.elapsed().as_secs_f64());
        values.fill(0.0);
        let t = Instant::now();
        for &(a, b) in &blocks {
            for at in positions.chunks_exact(LOCAL * LOCAL) {
                for i in ranges[a].clone() {
                    for j in ranges[b].clone() {
                        values[at[LOCAL * i + j] as usize] += 1.0;
                    }
                }
            }
        }
        black_box(&values);
        per_block.push(t.elapsed().as_secs_f64());
    }
    let per = |v: Vec<f64>| median(v) / mesh.cell_count() as f64 * 1e9;
    let (o, b) = (per(once), per(per_block));
    println!(
        "  scatter alone: one pass {o:.1} ns/triangle, {} block passes {b:.1} ns/triangle",
        blocks.len()
    );
}

/// One complete VI solve nested from N = 8 to `n`, meshes generated inside the timing
/// except the final one (the baseline's matrix is built on it too).
fn vi_solve_once(
    c: &Coefficients,
    mesh: &TriangleMesh,
    n: usize,
    options: ObstacleOptions,
) -> (TriangleObstacleSolution, f64) {
    let clock = Instant::now();
    let mut meshes: Vec<TriangleMesh> = std::iter::successors(Some(8), |&m| Some(2 * m))
        .take_while(|&m| m < n)
        .map(square)
        .collect();
    meshes.push(mesh.clone());
    let solution = solve_obstacle_on_triangles::<M>(&meshes, c, options).unwrap();
    (solution, clock.elapsed().as_secs_f64())
}

/// The default options with the membrane's start on nested levels: 8 symmetric
/// Gauss–Seidel sweeps on the first Newton system instead of its factorization
/// (`NewtonOptions::smoothing_sweeps`), the "swept" columns.
fn with_sweeps() -> ObstacleOptions {
    let defaults = ObstacleOptions::default();
    ObstacleOptions {
        newton: fem_forms::lcp::NewtonOptions {
            smoothing_sweeps: 8,
            ..defaults.newton
        },
        ..defaults
    }
}

/// Newton iterations per level, comma-separated.
fn levels_of(solution: &TriangleObstacleSolution) -> String {
    solution
        .levels
        .iter()
        .map(|(_, i)| i.to_string())
        .collect::<Vec<_>>()
        .join(",")
}

/// One Cholesky analysis + factorization + solve of `a`, timed.
fn cholesky_once(a: &SparseMatrix) -> f64 {
    let clock = Instant::now();
    let pattern = a.symbolic().to_owned().unwrap();
    let factor = Cholesky::analyse(&pattern).unwrap().factor(a).unwrap();
    black_box(factor.solve(&vec![1.0; a.nrows()]).unwrap());
    clock.elapsed().as_secs_f64()
}

fn vi_solve(sizes: &[usize], rounds: usize) {
    let c = coefficients();
    println!(
        "\nclamped square, q = {Q} up against w ≤ 0.05, t = {T}: complete VI solve (nested from N = 8, assembly included) vs one Cholesky (analysis + factorization + solve) of the final primal A; medians of {rounds}"
    );
    println!(
        "{:>5} {:>9} {:>9} {:>9} {:>16} {:>8} {:>10} {:>8} {:>6} {:>11} {:>9} {:>10} {:>16} {:>11} {:>6}",
        "N",
        "triangles",
        "primal",
        "λ",
        "iterations/level",
        "fact/upd",
        "Cholesky s",
        "VI s",
        "ratio",
        "final LCP s",
        "∫λ_h",
        "KKT",
        "swept it./level",
        "swept VI s",
        "ratio"
    );
    for &n in sizes {
        let mesh = square(n);
        let (warm, _) = vi_solve_once(&c, &mesh, n, ObstacleOptions::default());
        let a = warm.discretization.lcp.a.clone();
        let (mut linear, mut vi, mut last, mut swept) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut swept_levels = String::new();
        for _ in 0..rounds {
            linear.push(cholesky_once(&a));
            let (solution, seconds) = vi_solve_once(&c, &mesh, n, ObstacleOptions::default());
            vi.push(seconds);
            last.push(solution.solve_seconds);
            let (solution, seconds) = vi_solve_once(&c, &mesh, n, with_sweeps());
            swept.push(seconds);
            swept_levels = levels_of(&solution);
        }
        let (linear, vi, last, swept) = (median(linear), median(vi), median(last), median(swept));
        let lcp = &warm.discretization.lcp;
        let levels = levels_of(&warm);
        println!(
            "{:>5} {:>9} {:>9} {:>9} {:>16} {:>8} {:>10.3} {:>8.3} {:>6.2} {:>11.3} {:>9.3} {:>10.1e} {:>16} {:>11.3} {:>6.2}",
            n,
            2 * n * n,
            lcp.n(),
            lcp.m(),
            levels,
            format!("{}/{}", warm.factorizations, warm.low_rank_updates),
            linear,
            vi,
            vi / linear,
            last,
            warm.total_contact_force(),
            warm.kkt_residual,
            swept_levels,
            swept,
            swept / linear
        );
    }
}

fn disk_load(_: &[f64]) -> f64 {
    20.0
}

/// The scene mindlin-disk: the clamped unit disk, t = 0.01, q = 20 up against w ≤ 0.05.
fn disk_coefficients() -> Coefficients<'static> {
    let params = [
        ("D", D),
        ("ν", NU),
        ("κ", KAPPA),
        ("t", 0.01),
        ("β", BETA),
        ("α", ALPHA),
        ("s", S),
    ];
    let data: [(&str, &DataFn); 3] = [("f", &disk_load), ("ψ", &flat_obstacle), ("g", &zero)];
    Coefficients::new::<M>(&params, &data).unwrap()
}

/// One complete VI solve of the disk on curved cells, nested from `rings` halved while
/// even and at least 8; meshes and their geometries built inside the timing.
fn disk_solve_once(c: &Coefficients, rings: usize) -> (CurvedObstacleSolution, f64) {
    let clock = Instant::now();
    let mut sizes = vec![rings];
    while sizes[0] % 2 == 0 && sizes[0] / 2 >= 8 {
        sizes.insert(0, sizes[0] / 2);
    }
    let meshes: Vec<TriangleMesh> = sizes
        .iter()
        .map(|&r| TriangleMesh::disk([0.0, 0.0], 1.0, r).unwrap())
        .collect();
    let geometries: Vec<QuadraticGeometry> = meshes
        .iter()
        .map(|m| QuadraticGeometry::circle(m, [0.0, 0.0], 1.0).unwrap())
        .collect();
    let solution = solve_obstacle_on_curved_triangles::<M>(
        &meshes,
        &geometries,
        c,
        ObstacleOptions::default(),
    )
    .unwrap();
    (solution, clock.elapsed().as_secs_f64())
}

/// The issue's own plate scene (mindlin-disk) against one Cholesky of its final matrix.
fn disk_vi_solve(rings: &[usize], rounds: usize) {
    let c = disk_coefficients();
    println!(
        "
mindlin-disk (curved cells), q = 20 up against w ≤ 0.05, t = 0.01: complete VI solve (nested, meshes and assembly included) vs one Cholesky (analysis + factorization + solve) of the final primal A; medians of {rounds}"
    );
    println!(
        "{:>6} {:>9} {:>9} {:>9} {:>16} {:>8} {:>10} {:>8} {:>6} {:>9}",
        "rings",
        "triangles",
        "primal",
        "λ",
        "iterations/level",
        "fact/upd",
        "Cholesky s",
        "VI s",
        "ratio",
        "∫λ_h"
    );
    for &n in rings {
        let (warm, _) = disk_solve_once(&c, n);
        let a = warm.discretization.lcp.a.clone();
        let (mut linear, mut vi) = (Vec::new(), Vec::new());
        for _ in 0..rounds {
            linear.push(cholesky_once(&a));
            vi.push(disk_solve_once(&c, n).1);
        }
        let (linear, vi) = (median(linear), median(vi));
        let lcp = &warm.discretization.lcp;
        let levels = warm
            .levels
            .iter()
            .map(|(_, i)| i.to_string())
            .collect::<Vec<_>>()
            .join(",");
        println!(
            "{:>6} {:>9} {:>9} {:>9} {:>16} {:>8} {:>10.3} {:>8.3} {:>6.2} {:>9.4}",
            n,
            6 * n * n,
            lcp.n(),
            lcp.m(),
            levels,
            format!("{}/{}", warm.factorizations, warm.low_rank_updates),
            linear,
            vi,
            vi / linear,
            warm.total_contact_force(),
        );
    }
}

fn main() {
    fem_forms::lcp::cholesky::factor_sequentially();
    fem_forms::allocator::keep_freed_memory();
    let quick = std::env::args().any(|a| a == "--quick");
    let (assembly_n, sizes) = if quick {
        (64, vec![16, 32])
    } else {
        (256, vec![32, 64, 128, 256])
    };
    assembly(assembly_n, if quick { 3 } else { 9 });
    kernels_only(assembly_n, if quick { 3 } else { 9 });
    scatter_only(assembly_n, if quick { 3 } else { 9 });
    vi_solve(&sizes, if quick { 1 } else { 3 });
    let rings: &[usize] = if quick { &[16, 32] } else { &[32, 64, 144] };
    disk_vi_solve(rings, if quick { 1 } else { 3 });
}
