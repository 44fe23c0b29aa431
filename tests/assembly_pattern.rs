//! The global assembly's sparsity pattern and scatter positions (`MatrixAssembler::new`,
//! built column by column from the cells around each DOF since issue 15) against a
//! dense assembly written here from the element matrices and the DOF maps alone: every
//! entry equal to rounding, and the pattern exactly the entries some cell couples (no
//! entry missing, none extra, rows sorted). One-block (the P1 stiffness) and many-block
//! systems of several fields with different elements (the P2–P0 and P2–P1disc membrane
//! `B_h`, the
//! clamped Mindlin plate `B_h`), on a structured and on an irregular, refined mesh.
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

use fem_forms::models::membrane::{membrane_p1, membrane_p2_p0, membrane_p2_p1disc};
use fem_forms::models::mindlin::mindlin_stenberg;
use fem_forms::{Coefficients, Diagonal, MatrixAssembler, Model, SystemDofs, TriangleMesh};

fn load(x: &[f64]) -> f64 {
    1.0 + x[0] - 2.0 * x[1] * x[1]
}

fn boundary(x: &[f64]) -> f64 {
    0.7 * x[0] + x[1] * x[1]
}

fn obstacle(x: &[f64]) -> f64 {
    0.3 - x[0] * x[1] + 0.5 * x[0] * x[0]
}

/// Form `form` of `M` assembled cell by cell into a dense matrix, and the set of
/// entries some cell couples.
fn dense<M: Model>(
    form: usize,
    mesh: &TriangleMesh,
    dofs: &SystemDofs,
    coefficients: &Coefficients,
) -> (Vec<Vec<f64>>, Vec<Vec<bool>>) {
    let n = dofs.dof_count();
    let mut matrix = vec![vec![0.0; n]; n];
    let mut coupled = vec![vec![false; n]; n];
    for c in 0..mesh.cell_count() {
        let vertices: Vec<f64> = mesh
            .cell(c)
            .iter()
            .flat_map(|&v| mesh.vertices()[v])
            .collect();
        for (block, info) in M::FORMS[form].blocks.iter().enumerate() {
            let trial = info.trial_field.unwrap_or(info.test_field);
            let (test_map, trial_map) =
                (dofs.map(info.test_field).unwrap(), dofs.map(trial).unwrap());
            let (rows, cols) = (test_map.cell_dofs(c), trial_map.cell_dofs(c));
            let mut out = vec![0.0; rows.len() * cols.len()];
            M::element_matrix(
                form,
                block,
                &vertices,
                &coefficients.params,
                &coefficients.data,
                &mut out,
            );
            for (a, &r) in rows.iter().enumerate() {
                for (b, &s) in cols.iter().enumerate() {
                    let (i, j) = (
                        r + dofs.offset(info.test_field).unwrap(),
                        s + dofs.offset(trial).unwrap(),
                    );
                    matrix[i][j] += out[a * cols.len() + b];
                    coupled[i][j] = true;
                }
            }
        }
    }
    (matrix, coupled)
}

fn check<M: Model>(form_name: &str, mesh: &TriangleMesh, coefficients: &Coefficients) {
    let dofs = SystemDofs::all::<M>(mesh).unwrap();
    let form = M::FORMS
        .iter()
        .position(|f| f.name == form_name)
        .expect("a form of the model");
    let assembled = MatrixAssembler::new::<M>(form_name, mesh, &dofs)
        .unwrap()
        .assemble::<M>(mesh, coefficients)
        .unwrap();
    let (expected, coupled) = dense::<M>(form, mesh, &dofs, coefficients);
    let n = dofs.dof_count();
    assert_eq!((assembled.nrows(), assembled.ncols()), (n, n));
    let scale = expected
        .iter()
        .flatten()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let (col_ptr, rows, values) = (
        assembled.symbolic().col_ptr(),
        assembled.symbolic().row_idx(),
        assembled.val(),
    );
    let mut stored = vec![vec![false; n]; n];
    for j in 0..n {
        let column = &rows[col_ptr[j]..col_ptr[j + 1]];
        assert!(
            column.windows(2).all(|w| w[0] < w[1]),
            "{} `{form_name}`: column {j} not strictly sorted: {column:?}",
            M::NAME
        );
        for (k, &i) in column.iter().enumerate() {
            stored[i][j] = true;
            let value = values[col_ptr[j] + k];
            assert!(
                (value - expected[i][j]).abs() <= 1e-13 * scale,
                "{} `{form_name}`: entry ({i}, {j}) is {value}, the cells give {}",
                M::NAME,
                expected[i][j]
            );
        }
    }
    for i in 0..n {
        for j in 0..n {
            assert_eq!(
                stored[i][j],
                coupled[i][j],
                "{} `{form_name}`: entry ({i}, {j}) stored {} but coupled by a cell {}",
                M::NAME,
                stored[i][j],
                coupled[i][j]
            );
        }
    }
}

fn meshes() -> Vec<TriangleMesh> {
    let structured = TriangleMesh::rectangle(0.0, 1.0, 0.0, 0.7, 5, 4, Diagonal::Right).unwrap();
    // an irregular mesh: crossed diagonals refined once, then a few cells bisected
    let crossed = TriangleMesh::rectangle(-1.0, 1.0, 0.0, 1.0, 3, 2, Diagonal::Left)
        .unwrap()
        .refine_uniformly();
    let marked: Vec<usize> = (0..crossed.cell_count()).step_by(5).collect();
    let (irregular, _) = crossed.refine(&marked).unwrap();
    vec![structured, irregular]
}

#[test]
fn pattern_and_positions_match_a_dense_assembly_from_element_matrices() {
    for mesh in meshes() {
        let membrane = Coefficients::new::<membrane_p1::Model>(
            &[],
            &[("f", &load), ("ψ", &obstacle), ("g", &boundary)],
        )
        .unwrap();
        check::<membrane_p1::Model>("a", &mesh, &membrane);
        let stabilized = Coefficients::new::<membrane_p2_p0::Model>(
            &[("α", 0.1)],
            &[("f", &load), ("ψ", &obstacle), ("g", &boundary)],
        )
        .unwrap();
        check::<membrane_p2_p0::Model>("B_h", &mesh, &stabilized);
        let p1disc = Coefficients::new::<membrane_p2_p1disc::Model>(
            &[("α", 0.1)],
            &[("f", &load), ("ψ", &obstacle), ("g", &boundary)],
        )
        .unwrap();
        check::<membrane_p2_p1disc::Model>("B_h", &mesh, &p1disc);
        let plate = Coefficients::new::<mindlin_stenberg::Model>(
            &[
                ("D", 1.3),
                ("ν", 0.3),
                ("κ", 5.0 / 6.0),
                ("t", 0.05),
                ("β", 0.1),
                ("α", 0.1),
                ("s", -1.0),
            ],
            &[("f", &load), ("ψ", &obstacle), ("g", &boundary)],
        )
        .unwrap();
        check::<mindlin_stenberg::Model>("B_h", &mesh, &plate);
    }
}
