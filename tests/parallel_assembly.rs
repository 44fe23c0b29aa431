//! Parallel global assembly (issue 15): the matrix assembled on 2 and 3 rayon threads
//! (cells coloured in chunks, `assembly::CellColouring`) equals the one-thread assembly
//! (the plain serial cell loop) to 1e-13 relative in every entry, for the P1 stiffness
//! (the generated one-block loop), P2 (idem, 36 entries per cell), the P2–P0 membrane
//! system `B_h` (four blocks: the cell-major loop) and the clamped Mindlin plate `B_h`
//! (many blocks); and the same for their load vectors (`assemble_vector`). A dropped, doubled or racing chunk changes whole entries by O(1)
//! relative, far above the rounding of a reordered sum.
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

use fem_forms::models::membrane::{membrane_p1, membrane_p2_p0};
use fem_forms::models::mindlin::mindlin_clamped;
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
/// relative to the largest entry.
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
    let p1 = Coefficients::new::<P1>(&[], &[("f", &load), ("g", &boundary)]).unwrap();
    type P2 = membrane_p2_p0::Model;
    let p2 = Coefficients::new::<P2>(
        &[("α", 0.3)],
        &[("f", &load), ("ψ", &obstacle), ("g", &boundary)],
    )
    .unwrap();
    for mesh in meshes() {
        assert!(mesh.cell_count() >= 4096);
        let d1 = parallel_difference::<P1>("a", &mesh, &p1);
        assert!(d1 <= 1e-13, "P1 stiffness: {d1:e}");
        let d2 = parallel_difference::<P2>("B_h", &mesh, &p2);
        assert!(d2 <= 1e-13, "P2–P0 B_h: {d2:e}");
        let v1 = parallel_vector_difference::<P1>("ℓ", &mesh, &p1);
        assert!(v1 <= 1e-13, "P1 ℓ: {v1:e}");
        let v2 = parallel_vector_difference::<P2>("L_h", &mesh, &p2);
        assert!(v2 <= 1e-13, "P2–P0 L_h: {v2:e}");
    }
}

#[test]
fn parallel_mindlin_system_equals_the_serial_assembly() {
    type M = mindlin_clamped::Model;
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
    assert!(d <= 1e-13, "Mindlin B_h: {d:e}");
    let v = parallel_vector_difference::<M>("L_h", &mesh, &c);
    assert!(v <= 1e-13, "Mindlin L_h: {v:e}");
}
