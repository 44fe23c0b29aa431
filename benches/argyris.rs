//! Kirchhoff plate speed on the Argyris element (issue 13, "Speed"; docs/mathematics.md
//! §9), every ratio measured in this one run:
//! 1. assembly of the Argyris bending stiffness `a(w;v) = ∫ D[(1−ν) ∇∇w:∇∇v + ν Δw Δv]`
//!    (`kirchhoff_argyris`, 21 × 21 local entries) in elements per second, the generated
//!    kernel through the generic assembler against a hand-written loop: a degree-6
//!    quadrature (exact for the products of the quintics' cubic Hessians) of the reference
//!    basis Hessians tabulated once, mapped by the affine Jacobian, then `K = M K̂ Mᵀ` with
//!    `cell_transformation`, added into the same CSC values at precomputed positions;
//!    both results are compared entry by entry. The flop count of one generated element
//!    is printed beside it (how it was counted: see [`GENERATED_FLOPS`]); the generated
//!    kernel uses the symmetry of the block and the compact `M` (docs/mathematics.md §9);
//! 2. the complete obstacle solve of the scene kirchhoff-obstacle (clamped, q = 20 up
//!    against the flat obstacle w ≤ 0.002, Argyris–P0, α = ½/C_I), nested from N = 7 to
//!    N = 112 (≈ 113k DOFs) as the CLI does, against one sparse Cholesky analysis +
//!    factorization + solve of the final mesh's primal matrix `A`: once through the CLI's
//!    library entry, the one solve of the registry (`fem_forms::models::families::solve`,
//!    with its report), once through
//!    the same calls reproduced here, which expose the factorization count and `A`.
//!
//! `cargo bench --bench argyris` (add `-- --quick` for small meshes).
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

use fem_forms::element::triangle::cell_transformation;
use fem_forms::lcp::cholesky::Cholesky;
use fem_forms::models::kirchhoff::{kirchhoff_argyris, kirchhoff_argyris_p0};
use fem_forms::obstacle::triangle::{prolong_primal_on_triangles, TriangleObstacleSolution};
use fem_forms::obstacle::{solve_nested, Discretization, ObstacleOptions};
use fem_forms::reference::triangle::TriangleRule;
use fem_forms::{
    Coefficients, Constraints, DataFn, Diagonal, DirichletPart, ElementKind, MatrixAssembler,
    Model, PlateSupport, SparseMatrix, SystemDofs, TriangleMesh,
};
use std::hint::black_box;
use std::time::Instant;

type A = kirchhoff_argyris::Model;
type P0 = kirchhoff_argyris_p0::Model;

const D: f64 = 1.0;
const NU: f64 = 0.3;
/// The obstacle side of kirchhoff-obstacle: above, `s = −1`.
const S: f64 = -1.0;
const Q: f64 = 20.0;
/// Local DOFs of Argyris: per vertex `w, w_x, w_y, w_xx, w_xy, w_yy`, then three edge
/// normal derivatives.
const LOCAL: usize = 21;

/// Flops of one generated `kirchhoff_argyris::a::matrix_v_w` (additions, multiplications,
/// divisions and square roots; sign changes and comparisons not counted), counted in its
/// source as dumped by `FEM_FORMS_DUMP_DIR` and in the runtime epilogue it calls:
/// - the prologue: Jacobian, its inverse, the 9 products `T_αβ` of the Hessian map and
///   the 6 geometric scalars `s0..s5` of the symmetric block (the 9 reference pairs
///   with `(β, γ)` and `(γ, β)` merged): 126 multiplications + 36 additions + 1 division
///   (a script counting `*`, `+`, `-`, `/` outside indices);
/// - `K̂` on and above the diagonal: 231 entries of `Σ s_p T_p[i][j]` over the 6 merged
///   tables, 6 multiplications + 5 additions each (the lower triangle is copied);
/// - the compact transformation (`CompactTransformation::new`): 7 for `J` and `det J`,
///   per edge 20 for its length, tangent, `α` and `β` and 44 for the 12 coefficients of
///   its vertices' Hermite data, 15 for the Hessian block, 1 for the degeneracy test;
/// - `M K̂`: per vertex and column 45 (value 4, gradient 2 × 7, Hessian 3 × 9), 21
///   columns, plus the 63 multiplications of the edge rows; `M (M K̂)ᵀ` on and above the
///   diagonal: the same from the vertex's first column on (21 + 15 + 9 columns), plus 9.
const GENERATED_FLOPS: usize = (126 + 36 + 1)
    + 231 * 11
    + (7 + 3 * (20 + 44) + 15 + 1)
    + (45 * 21 * 3 + 63)
    + (45 * (21 + 15 + 9) + 9);

fn load(_: &[f64]) -> f64 {
    1.0
}

fn zero(_: &[f64]) -> f64 {
    0.0
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn square(n: usize) -> TriangleMesh {
    TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, n, n, Diagonal::Right).unwrap()
}

/// The reference Argyris basis Hessians `(∂ξξ, ∂ξη, ∂ηη)` at the points of a degree-6
/// rule, tabulated once, and the rule's weights (summing to ½).
struct Tabulation {
    hessians: Vec<[[f64; 3]; LOCAL]>,
    weights: Vec<f64>,
}

impl Tabulation {
    fn new() -> Self {
        let basis = ElementKind::Argyris.triangle_basis();
        assert_eq!(basis.len(), LOCAL, "the Argyris basis has 21 functions");
        let second: Vec<[_; 3]> = basis
            .iter()
            .map(|p| [p.derivative(2, 0), p.derivative(1, 1), p.derivative(0, 2)])
            .collect();
        let rule = TriangleRule::exact_for_degree(6);
        let hessians = rule
            .points
            .iter()
            .map(|&xi| std::array::from_fn(|i| std::array::from_fn(|a| second[i][a].eval(xi))))
            .collect();
        Self {
            hessians,
            weights: rule.weights,
        }
    }
}

/// The hand-written element stiffness on the cell with vertex coordinates `x` and global
/// vertex numbers `global`: with `K = J⁻¹`, the physical Hessian of the pulled-back
/// reference function is `Kᵀ Ĥ K`; the integrand `D[(1−ν) H:H' + ν tr H tr H']` is
/// `hᵀ E h'` with `h = (H_xx, H_xy, H_yy)` and `E = D[[1, 0, ν], [0, 2(1−ν), 0], [ν, 0, 1]]`;
/// `K̂` (symmetric: the upper triangle computed, mirrored) is then mapped by the cell's
/// DOF transformation, `M K̂ Mᵀ`, skipping the zeros of `M`.
fn hand_element(t: &Tabulation, x: &[f64; 6], global: &[usize; 3]) -> [[f64; LOCAL]; LOCAL] {
    let (j00, j01, j10, j11) = (x[2] - x[0], x[4] - x[0], x[3] - x[1], x[5] - x[1]);
    let det = j00 * j11 - j01 * j10;
    let (k00, k01, k10, k11) = (j11 / det, -j01 / det, -j10 / det, j00 / det);
    let mut k = [[0.0; LOCAL]; LOCAL];
    for (hat, &w) in t.hessians.iter().zip(&t.weights) {
        let scale = w * det.abs();
        let mut h = [[0.0; 3]; LOCAL];
        let mut e = [[0.0; 3]; LOCAL];
        for i in 0..LOCAL {
            let [a, b, c] = hat[i];
            // (Kᵀ Ĥ K)_pq = Σ K_rp Ĥ_rs K_sq, Ĥ = [[a, b], [b, c]]
            let xx = k00 * k00 * a + 2.0 * k00 * k10 * b + k10 * k10 * c;
            let xy = k00 * k01 * a + (k00 * k11 + k10 * k01) * b + k10 * k11 * c;
            let yy = k01 * k01 * a + 2.0 * k01 * k11 * b + k11 * k11 * c;
            h[i] = [xx, xy, yy];
            e[i] = [
                scale * D * (xx + NU * yy),
                scale * D * 2.0 * (1.0 - NU) * xy,
                scale * D * (yy + NU * xx),
            ];
        }
        for i in 0..LOCAL {
            for j in i..LOCAL {
                k[i][j] += e[i][0] * h[j][0] + e[i][1] * h[j][1] + e[i][2] * h[j][2];
            }
        }
    }
    // the lower triangle from the upper: row i, columns j < i, from rows j < i
    for i in 1..LOCAL {
        let (upper, lower) = k.split_at_mut(i);
        for (target, row) in lower[0].iter_mut().zip(upper.iter()) {
            *target = row[i];
        }
    }
    let m = cell_transformation(ElementKind::Argyris, x, global)
        .unwrap()
        .expect("Argyris has a DOF transformation");
    let nonzeros: Vec<Vec<(usize, f64)>> = (0..LOCAL)
        .map(|i| {
            m.row(i)
                .iter()
                .enumerate()
                .filter(|(_, &v)| v != 0.0)
                .map(|(l, &v)| (l, v))
                .collect()
        })
        .collect();
    let mut mk = [[0.0; LOCAL]; LOCAL];
    for (row, nz) in mk.iter_mut().zip(&nonzeros) {
        for &(l, v) in nz {
            for (o, &kl) in row.iter_mut().zip(&k[l]) {
                *o += v * kl;
            }
        }
    }
    let mut out = [[0.0; LOCAL]; LOCAL];
    for (o, r) in out.iter_mut().zip(&mk) {
        for (oj, nz) in o.iter_mut().zip(&nonzeros) {
            *oj = nz.iter().map(|&(l, v)| v * r[l]).sum();
        }
    }
    out
}

/// For each cell and local entry (row-major, `LOCAL²` per cell) its position in the
/// pattern of `assembler`.
fn positions(mesh: &TriangleMesh, dofs: &SystemDofs, assembler: &MatrixAssembler) -> Vec<u32> {
    let w = A::field("w").unwrap();
    let map = dofs.map(w).unwrap();
    let offset = dofs.offset(w).unwrap();
    let (col_ptr, row_idx) = (
        assembler.symbolic().col_ptr(),
        assembler.symbolic().row_idx(),
    );
    let mut out = Vec::with_capacity(LOCAL * LOCAL * mesh.cell_count());
    for c in 0..mesh.cell_count() {
        let global: Vec<usize> = map.cell_dofs(c).iter().map(|d| offset + d).collect();
        for &r in &global {
            for &col in &global {
                let column = &row_idx[col_ptr[col]..col_ptr[col + 1]];
                let k = column
                    .binary_search(&r)
                    .expect("every local pair is in the pattern");
                out.push((col_ptr[col] + k) as u32);
            }
        }
    }
    out
}

/// The hand-written assembly loop.
fn hand_assembly(t: &Tabulation, mesh: &TriangleMesh, positions: &[u32], values: &mut [f64]) {
    values.fill(0.0);
    for c in 0..mesh.cell_count() {
        let k = hand_element(t, &mesh.cell_coordinates(c), &mesh.cell(c));
        let p = &positions[LOCAL * LOCAL * c..LOCAL * LOCAL * (c + 1)];
        for (&at, &v) in p.iter().zip(k.iter().flatten()) {
            values[at as usize] += v;
        }
    }
}

fn assembly(n: usize, rounds: usize) {
    let mesh = square(n);
    let cells = mesh.cell_count();
    let f: &DataFn = &load;
    let c = Coefficients::new::<A>(&[("D", D), ("ν", NU)], &[("f", f)]).unwrap();
    let dofs = SystemDofs::all::<A>(&mesh).unwrap();
    let clock = Instant::now();
    let assembler = MatrixAssembler::new::<A>("a", &mesh, &dofs).unwrap();
    let pattern_seconds = clock.elapsed().as_secs_f64();
    println!(
        "assembly of the Argyris bending stiffness on {n}×{n}×2 = {cells} triangles, {} DOFs, {} stored entries (median of {rounds} interleaved rounds, one core)",
        dofs.dof_count(),
        assembler.nonzero_count()
    );
    let tabulation = Tabulation::new();
    let positions = positions(&mesh, &dofs, &assembler);
    let mut values = Vec::new();
    let mut hand_values = vec![0.0; assembler.nonzero_count()];
    let (mut generated, mut hand) = (Vec::new(), Vec::new());
    for round in 0..rounds {
        let mut time_generated = || {
            let t = Instant::now();
            assembler
                .assemble_values::<A>(&mesh, &c, &mut values)
                .unwrap();
            black_box(&values);
            t.elapsed().as_secs_f64()
        };
        let mut time_hand = || {
            let t = Instant::now();
            hand_assembly(&tabulation, &mesh, &positions, &mut hand_values);
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
        difference <= 1e-10 * scale,
        "generated and hand-written Argyris assembly differ by {difference} (largest entry {scale})"
    );
    let (g, h) = (median(generated), median(hand));
    let rate = cells as f64 / g;
    println!(
        "  generated    {:>6.3} M elements/s  ({:.3} s; pattern built once in {:.3} s); {GENERATED_FLOPS} flops per element (see GENERATED_FLOPS) = {:.2} GFlop/s",
        rate / 1e6,
        g,
        pattern_seconds,
        rate * GENERATED_FLOPS as f64 / 1e9
    );
    println!(
        "  hand-written {:>6.3} M elements/s  ({:.3} s)   generated/hand time ratio {:.2}   (largest difference {:.1e} of the largest entry)",
        cells as f64 / h / 1e6,
        h,
        g / h,
        difference / scale
    );
    println!(
        "  issue 13 target ≥ 0.5 M elements/s on one core: {}",
        if rate >= 0.5e6 { "met" } else { "NOT met" }
    );
}

/// The element kernels alone, without the scatter, in ns per element: the generated
/// `matrix_v_w`, the hand-written element, and `cell_transformation` alone (the dense
/// `M` that the hand-written element builds once per cell; the generated one builds the
/// compact `M` of `fem_runtime::element::triangle::CompactTransformation`); each result
/// summed so that it is kept.
fn kernels_only(n: usize, rounds: usize) {
    let mesh = square(n);
    let tabulation = Tabulation::new();
    let f: &DataFn = &load;
    let (mut generated, mut hand, mut transformation) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..rounds {
        let t = Instant::now();
        let mut sum = 0.0;
        for c in 0..mesh.cell_count() {
            let k = kirchhoff_argyris::a::matrix_v_w(
                black_box(&mesh.cell_coordinates(c)),
                &mesh.cell(c),
                &[D, NU],
                &[f],
            );
            sum += k[0][0] + k[LOCAL - 1][LOCAL - 1];
        }
        black_box(sum);
        generated.push(t.elapsed().as_secs_f64());
        let t = Instant::now();
        let mut sum = 0.0;
        for c in 0..mesh.cell_count() {
            let k = hand_element(
                &tabulation,
                black_box(&mesh.cell_coordinates(c)),
                &mesh.cell(c),
            );
            sum += k[0][0] + k[LOCAL - 1][LOCAL - 1];
        }
        black_box(sum);
        hand.push(t.elapsed().as_secs_f64());
        let t = Instant::now();
        let mut sum = 0.0;
        for c in 0..mesh.cell_count() {
            let m = cell_transformation(
                ElementKind::Argyris,
                black_box(&mesh.cell_coordinates(c)),
                &mesh.cell(c),
            )
            .unwrap()
            .expect("Argyris has a DOF transformation");
            sum += m.row(0)[0];
        }
        black_box(sum);
        transformation.push(t.elapsed().as_secs_f64());
    }
    let per = |v: Vec<f64>| median(v) / mesh.cell_count() as f64 * 1e9;
    let (g, h, m) = (per(generated), per(hand), per(transformation));
    println!(
        "  kernels alone: generated {g:.0} ns/element, hand-written {h:.0} ns/element, ratio {:.2}; cell_transformation alone (in the hand-written one) {m:.0} ns",
        g / h
    );
}

/// kirchhoff-obstacle at q = 20 (flat obstacle, clamped, Argyris–P0) on N×N×2, through
/// the one solve: its report.
fn solve(n: usize) -> fem_forms::models::report::Report {
    use fem_forms::models::families;
    let scene = families::scene("kirchhoff-obstacle").expect("the built-in scene");
    let settings = fem_forms::models::report::Settings {
        pair: Some("argyris-p0".into()),
        mesh_size: Some(n),
        load: Some(Q),
        ..Default::default()
    };
    families::solve(&scene, &settings).unwrap().report
}

/// The calls of the one solve for Argyris–P0 reproduced (levels N/2^k
/// down to an odd N or N/2 < 4, clamped by `Constraints::support_plate`), timed with the
/// meshes built inside.
fn reproduced_once(n: usize, alpha: f64) -> (TriangleObstacleSolution, f64) {
    let clock = Instant::now();
    let psi = |_: &[f64]| 0.002;
    let f = |_: &[f64]| Q;
    let c = Coefficients::new::<P0>(
        &[("D", D), ("ν", NU), ("α", alpha), ("s", S)],
        &[("f", &f), ("ψ", &psi), ("g", &zero)],
    )
    .unwrap();
    let mut sizes = vec![n];
    while sizes[0] % 2 == 0 && sizes[0] / 2 >= 4 {
        sizes.insert(0, sizes[0] / 2);
    }
    let meshes: Vec<TriangleMesh> = sizes.iter().map(|&m| square(m)).collect();
    let c = &c;
    let levels: Vec<_> = meshes
        .iter()
        .map(|mesh| {
            move || {
                let dofs = SystemDofs::all::<P0>(mesh)?;
                let mut constraints = Constraints::new();
                constraints.support_plate::<P0>(
                    mesh,
                    &dofs,
                    "w",
                    &DirichletPart::All,
                    PlateSupport::Clamped,
                )?;
                Discretization::with_constraints::<P0>(mesh, c, dofs, &constraints, "B_h", "L_h")
            }
        })
        .collect();
    let solution = solve_nested(
        levels,
        prolong_primal_on_triangles,
        ObstacleOptions::default(),
    )
    .unwrap();
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

fn obstacle_solve(n: usize, rounds: usize) {
    println!(
        "\nkirchhoff-obstacle (clamped, q = {Q} up against w ≤ 0.002, Argyris–P0, α = ½/C_I) on {n}×{n}×2: complete nested VI solve (meshes and assembly included) vs one Cholesky (analysis + factorization + solve) of the final primal A; medians of {rounds}"
    );
    // warm-up, and α and the level iterations from the CLI's entry
    let report = solve(n).solve;
    let alpha = report.alpha.expect("α of a stabilized pair");
    let (warm, _) = reproduced_once(n, alpha);
    let a = warm.discretization.lcp.a.clone();
    let (mut library, mut reproduced, mut linear) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..rounds {
        linear.push(cholesky_once(&a));
        let clock = Instant::now();
        black_box(solve(n));
        library.push(clock.elapsed().as_secs_f64());
        reproduced.push(reproduced_once(n, alpha).1);
    }
    let (library, reproduced, linear) = (median(library), median(reproduced), median(linear));
    let levels = report
        .levels
        .iter()
        .map(|[triangles, iterations]| {
            format!("{}:{iterations}", ((triangles / 2) as f64).sqrt().round())
        })
        .collect::<Vec<_>>()
        .join(", ");
    let lcp = &warm.discretization.lcp;
    println!(
        "  {} DOFs (primal {}, λ {}), α = {:.3e}, iterations per level (N:it) {levels}, factorizations/low-rank updates {}/{}, KKT residual {:.1e}, ∫λ_h {:.4} (report: {:.4})",
        report.dofs,
        lcp.n(),
        lcp.m(),
        alpha,
        warm.factorizations,
        warm.low_rank_updates,
        warm.kkt_residual,
        warm.total_contact_force(),
        report.total_contact_force
    );
    println!("  one Cholesky of A          {linear:>8.3} s");
    println!(
        "  VI solve, reproduced calls {reproduced:>8.3} s   ratio {:.2}   (final-level LCP alone {:.3} s)",
        reproduced / linear,
        warm.solve_seconds
    );
    println!(
        "  VI solve, the one solve   {library:>8.3} s   ratio {:.2}   (post-processing of the report included)",
        library / linear
    );
}

fn main() {
    fem_forms::lcp::cholesky::factor_sequentially();
    fem_forms::allocator::keep_freed_memory();
    let quick = std::env::args().any(|a| a == "--quick");
    let (assembly_n, solve_n) = if quick { (32, 28) } else { (256, 112) };
    assembly(assembly_n, if quick { 3 } else { 9 });
    kernels_only(assembly_n, 3);
    obstacle_solve(solve_n, if quick { 1 } else { 3 });
}
