//! Parallel global assembly (issue 15): the matrix assembled on 1, 2 and 3 rayon threads
//! (cells coloured in chunks, `assembly::CellColouring`, the colours in the same order on
//! any thread count) is the same to the last bit, for the P1 stiffness (the generated
//! one-block loop), P2 (idem, 36 entries per cell), the P2–P0 membrane system `B_h`
//! (four blocks: the cell-major loop) and the clamped Mindlin plate `B_h` (many blocks);
//! and the same for their load vectors (`assemble_vector`). Before, one thread took the
//! plain cell loop and results differed in the last bits between thread counts. That
//! the colouring keeps every cell once is checked by an identity of the P1 stiffness:
//! `XᵀAX = |Ω|` for `X` the vertices' x coordinates (`∫|∇x|² = |Ω|`), which a dropped
//! or doubled chunk changes by its area.
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

use fem_forms::models::membrane::{membrane_p1, membrane_p2_p0};
use fem_forms::models::mindlin::mindlin_stenberg;
use fem_forms::{
    assemble_vector, Coefficients, Diagonal, MatrixAssembler, Model, SystemDofs, TriangleMesh,
};

fn load(x: &[f64]) -> f64 {
    1.0 + x[0] - 2.0 * x[1] * x[1]
}

fn obstacle(x: &[f64]) -> f64 {
    0.3 - x[0] * x[1] + 0.5 * x[0] * x[0]
}

fn boundary(x: &[f64]) -> f64 {
    0.7 * x[0] + x[1] * x[1]
}

/// `form` of `M` assembled on a pool of `threads` threads.
fn assembled<M: Model>(
    form: &str,
    mesh: &TriangleMesh,
    coefficients: &Coefficients,
    threads: usize,
) -> Vec<f64> {
    let dofs = SystemDofs::all::<M>(mesh).unwrap();
    let assembler = MatrixAssembler::new::<M>(form, mesh, &dofs).unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let mut values = Vec::new();
    pool.install(|| assembler.assemble_values::<M>(mesh, coefficients, &mut values))
        .unwrap();
    values
}

/// Linear form `form` of `M` assembled on a pool of `threads` threads.
fn assembled_vector<M: Model>(
    form: &str,
    mesh: &TriangleMesh,
    coefficients: &Coefficients,
    threads: usize,
) -> Vec<f64> {
    let dofs = SystemDofs::all::<M>(mesh).unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| assemble_vector::<M>(form, mesh, &dofs, coefficients))
        .unwrap()
}

/// The same as [`parallel_difference`] for the vector of a linear form.
fn parallel_vector_difference<M: Model>(form: &str, mesh: &TriangleMesh, c: &Coefficients) -> f64 {
    let serial = assembled_vector::<M>(form, mesh, c, 1);
    let scale = serial.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(scale > 0.0);
    [2, 3]
        .into_iter()
        .map(|threads| {
            let parallel = assembled_vector::<M>(form, mesh, c, threads);
            serial
                .iter()
                .zip(&parallel)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
                / scale
        })
        .fold(0.0, f64::max)
}

/// Largest entry difference between the 1-thread and the 2- and 3-thread assemblies,
/// relative to the largest entry (0: the same to the last bit).
fn parallel_difference<M: Model>(form: &str, mesh: &TriangleMesh, c: &Coefficients) -> f64 {
    let serial = assembled::<M>(form, mesh, c, 1);
    let scale = serial.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(scale > 0.0);
    [2, 3]
        .into_iter()
        .map(|threads| {
            let parallel = assembled::<M>(form, mesh, c, threads);
            assert_eq!(parallel.len(), serial.len());
            serial
                .iter()
                .zip(&parallel)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
                / scale
        })
        .fold(0.0, f64::max)
}

/// `XᵀAX` of the P1 stiffness assembled on `threads` threads, `X` the vertices' x
/// coordinates (P1's DOF v is vertex v): `∫|∇x|² = |Ω|`.
fn x_energy(mesh: &TriangleMesh, c: &Coefficients, threads: usize) -> f64 {
    type P1 = membrane_p1::Model;
    let dofs = SystemDofs::all::<P1>(mesh).unwrap();
    let assembler = MatrixAssembler::new::<P1>("a", mesh, &dofs).unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let a = pool.install(|| assembler.assemble::<P1>(mesh, c)).unwrap();
    let x: Vec<f64> = mesh.vertices().iter().map(|v| v[0]).collect();
    let (col_ptr, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    (0..a.ncols())
        .map(|j| {
            (col_ptr[j]..col_ptr[j + 1])
                .map(|k| x[rows[k]] * vals[k] * x[j])
                .sum::<f64>()
        })
        .sum()
}

/// Meshes above the parallel threshold (4096 cells), both diagonals, and one refined by
/// bisection (its cells are not numbered row by row).
fn meshes() -> Vec<TriangleMesh> {
    let mut refined =
        TriangleMesh::rectangle(-1.0, 1.0, -1.0, 1.0, 24, 24, Diagonal::Left).unwrap();
    for _ in 0..2 {
        refined = refined.refine_uniformly();
    }
    vec![
        TriangleMesh::rectangle(-1.0, 1.0, -1.0, 1.0, 64, 48, Diagonal::Right).unwrap(),
        TriangleMesh::rectangle(0.0, 2.0, 0.0, 1.0, 80, 40, Diagonal::Left).unwrap(),
        refined,
    ]
}

#[test]
fn parallel_p1_and_p2_stiffness_equal_the_serial_assembly() {
    type P1 = membrane_p1::Model;
    let p1 =
        Coefficients::new::<P1>(&[], &[("f", &load), ("ψ", &obstacle), ("g", &boundary)]).unwrap();
    type P2 = membrane_p2_p0::Model;
    let p2 = Coefficients::new::<P2>(
        &[("α", 0.3)],
        &[("f", &load), ("ψ", &obstacle), ("g", &boundary)],
    )
    .unwrap();
    for (mesh, area) in meshes().into_iter().zip([4.0, 2.0, 4.0]) {
        assert!(mesh.cell_count() >= 4096);
        for threads in [1, 2] {
            let energy = x_energy(&mesh, &p1, threads);
            assert!(
                (energy - area).abs() <= 1e-12 * area,
                "{threads} threads: XᵀAX = {energy}, |Ω| = {area}"
            );
        }
        let d1 = parallel_difference::<P1>("a", &mesh, &p1);
        assert_eq!(d1, 0.0, "P1 stiffness");
        let d2 = parallel_difference::<P2>("B_h", &mesh, &p2);
        assert_eq!(d2, 0.0, "P2–P0 B_h");
        let v1 = parallel_vector_difference::<P1>("ℓ", &mesh, &p1);
        assert_eq!(v1, 0.0, "P1 ℓ");
        let v2 = parallel_vector_difference::<P2>("L_h", &mesh, &p2);
        assert_eq!(v2, 0.0, "P2–P0 L_h");
    }
}

#[test]
fn parallel_mindlin_system_equals_the_serial_assembly() {
    type M = mindlin_stenberg::Model;
    let params = [
        ("D", 1.3),
        ("ν", 0.3),
        ("κ", 5.0 / 6.0),
        ("t", 0.05),
        ("β", 0.1),
        ("α", 0.1),
        ("s", -1.0),
    ];
    let c = Coefficients::new::<M>(&params, &[("f", &load), ("ψ", &obstacle), ("g", &boundary)])
        .unwrap();
    assert!(M::FORMS[M::form("B_h").unwrap()].blocks.len() >= 3);
    let mesh = TriangleMesh::rectangle(-1.0, 1.0, -1.0, 1.0, 48, 48, Diagonal::Right).unwrap();
    let d = parallel_difference::<M>("B_h", &mesh, &c);
    assert_eq!(d, 0.0, "Mindlin B_h");
    let v = parallel_vector_difference::<M>("L_h", &mesh, &c);
    assert_eq!(v, 0.0, "Mindlin L_h");
}
