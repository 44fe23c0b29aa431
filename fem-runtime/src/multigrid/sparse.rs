//! The few sparse kernels the cycle runs, all into preallocated vectors: products with
//! `A` and `P`, restriction `Pᵀ r` without forming `Pᵀ`, Gauss–Seidel sweeps, and the
//! Galerkin triple product `PᵀAP` formed once per hierarchy.

use crate::SparseMatrix;
use faer::sparse::{SparseColMat, SymbolicSparseColMat};

/// `y = A x` (column-oriented: exact for any `A`, symmetric or not).
pub(super) fn multiply_into(a: &SparseMatrix, x: &[f64], y: &mut [f64]) {
    let (col_ptr, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    y.fill(0.0);
    for (j, &xj) in x.iter().enumerate() {
        if xj != 0.0 {
            for k in col_ptr[j]..col_ptr[j + 1] {
                y[rows[k]] += vals[k] * xj;
            }
        }
    }
}

/// `y += P x`.
pub(super) fn prolong_add(p: &SparseMatrix, x: &[f64], y: &mut [f64]) {
    let (col_ptr, rows, vals) = (p.symbolic().col_ptr(), p.symbolic().row_idx(), p.val());
    for (j, &xj) in x.iter().enumerate() {
        for k in col_ptr[j]..col_ptr[j + 1] {
            y[rows[k]] += vals[k] * xj;
        }
    }
}

/// `y = Pᵀ r`: column `j` of `P` is row `j` of `Pᵀ`, so each entry is one gather.
pub(super) fn restrict(p: &SparseMatrix, r: &[f64], y: &mut [f64]) {
    let (col_ptr, rows, vals) = (p.symbolic().col_ptr(), p.symbolic().row_idx(), p.val());
    for (j, yj) in y.iter_mut().enumerate() {
        *yj = (col_ptr[j]..col_ptr[j + 1])
            .map(|k| vals[k] * r[rows[k]])
            .sum();
    }
}

/// The diagonal of `a`, `None` at a missing entry.
pub(super) fn diagonal(a: &SparseMatrix) -> Vec<Option<f64>> {
    let (col_ptr, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    (0..a.ncols())
        .map(|j| {
            rows[col_ptr[j]..col_ptr[j + 1]]
                .binary_search(&j)
                .ok()
                .map(|k| vals[col_ptr[j] + k])
        })
        .collect()
}

/// One Gauss–Seidel sweep on `A x = b` in place, forward or backward, for a symmetric
/// `A` stored with both triangles (column `j` read as row `j`); `inverse_diagonal` holds
/// `1 / A_jj`.
pub(super) fn gauss_seidel(
    a: &SparseMatrix,
    inverse_diagonal: &[f64],
    b: &[f64],
    x: &mut [f64],
    forward: bool,
) {
    let (col_ptr, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    let relax = |j: usize, x: &mut [f64]| {
        let mut sum = b[j];
        for k in col_ptr[j]..col_ptr[j + 1] {
            sum -= vals[k] * x[rows[k]];
        }
        // the sum above subtracted A_jj x_j too: add it back through the update
        x[j] += sum * inverse_diagonal[j];
    };
    if forward {
        (0..x.len()).for_each(|j| relax(j, x));
    } else {
        (0..x.len()).rev().for_each(|j| relax(j, x));
    }
}

/// `C = A B` (Gustavson's column-by-column product with a dense accumulator), rows of
/// each column sorted.
pub(super) fn product(a: &SparseMatrix, b: &SparseMatrix) -> SparseMatrix {
    let (a_ptr, a_rows, a_vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    let (b_ptr, b_rows, b_vals) = (b.symbolic().col_ptr(), b.symbolic().row_idx(), b.val());
    let m = a.nrows();
    let mut accumulator = vec![0.0; m];
    let mut seen = vec![usize::MAX; m];
    let mut col_ptr = Vec::with_capacity(b.ncols() + 1);
    let mut rows = Vec::new();
    let mut values = Vec::new();
    col_ptr.push(0);
    for j in 0..b.ncols() {
        let start = rows.len();
        for kb in b_ptr[j]..b_ptr[j + 1] {
            let (k, bkj) = (b_rows[kb], b_vals[kb]);
            for ka in a_ptr[k]..a_ptr[k + 1] {
                let i = a_rows[ka];
                if seen[i] != j {
                    seen[i] = j;
                    accumulator[i] = 0.0;
                    rows.push(i);
                }
                accumulator[i] += a_vals[ka] * bkj;
            }
        }
        rows[start..].sort_unstable();
        values.extend(rows[start..].iter().map(|&i| accumulator[i]));
        col_ptr.push(rows.len());
    }
    SparseColMat::new(
        SymbolicSparseColMat::new_checked(m, b.ncols(), col_ptr, None, rows),
        values,
    )
}

/// `Pᵀ`.
pub(super) fn transpose(p: &SparseMatrix) -> SparseMatrix {
    let (col_ptr, rows, vals) = (p.symbolic().col_ptr(), p.symbolic().row_idx(), p.val());
    let (m, n) = (p.nrows(), p.ncols());
    let mut count = vec![0usize; m + 1];
    for &i in rows {
        count[i + 1] += 1;
    }
    for i in 0..m {
        count[i + 1] += count[i];
    }
    let t_ptr = count.clone();
    let mut t_rows = vec![0; rows.len()];
    let mut t_vals = vec![0.0; rows.len()];
    // columns visited in order, so each row of the transpose comes out sorted
    for j in 0..n {
        for k in col_ptr[j]..col_ptr[j + 1] {
            let slot = &mut count[rows[k]];
            t_rows[*slot] = j;
            t_vals[*slot] = vals[k];
            *slot += 1;
        }
    }
    SparseColMat::new(
        SymbolicSparseColMat::new_checked(n, m, t_ptr, None, t_rows),
        t_vals,
    )
}

/// The Galerkin coarse operator `PᵀAP`, made exactly symmetric (the average with its
/// transpose removes the rounding asymmetry of the two products, which Gauss–Seidel
/// reading columns as rows would otherwise see).
pub(super) fn galerkin(a: &SparseMatrix, p: &SparseMatrix) -> SparseMatrix {
    let c = product(&transpose(p), &product(a, p));
    let t = transpose(&c);
    // same pattern: Pᵀ A P has a symmetric pattern when A does
    if t.symbolic().col_ptr() == c.symbolic().col_ptr()
        && t.symbolic().row_idx() == c.symbolic().row_idx()
    {
        let values: Vec<f64> = c
            .val()
            .iter()
            .zip(t.val())
            .map(|(x, y)| 0.5 * (x + y))
            .collect();
        let n = c.ncols();
        let symbolic = SymbolicSparseColMat::new_checked(
            n,
            n,
            c.symbolic().col_ptr().to_vec(),
            None,
            c.symbolic().row_idx().to_vec(),
        );
        SparseColMat::new(symbolic, values)
    } else {
        c
    }
}
