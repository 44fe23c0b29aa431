//! Small dense matrices: enough linear algebra to invert the generalized Vandermonde
//! matrix of an element (at most a few dozen rows) and to hold its per-cell DOF
//! transformation, with no dependencies so that the form compiler can use it at
//! compile time.

use std::fmt;
use std::ops::{Index, IndexMut};

/// A dense `rows × cols` matrix of `f64`, stored row by row.
#[derive(Clone, Debug, PartialEq)]
pub struct Matrix {
    rows: usize,
    cols: usize,
    data: Vec<f64>,
}

/// Why [`Matrix::inverse`] has no answer.
#[derive(Clone, Debug, PartialEq)]
pub enum InverseError {
    /// The matrix is not square.
    NotSquare {
        /// Number of rows.
        rows: usize,
        /// Number of columns.
        cols: usize,
    },
    /// An entry is NaN or infinite.
    NonFinite {
        /// Its row.
        row: usize,
        /// Its column.
        col: usize,
    },
    /// Gauss–Jordan elimination met a pivot that is zero to rounding: the matrix is
    /// singular (for a Vandermonde matrix: the functionals are not unisolvent).
    Singular {
        /// The column (0-based) in which no usable pivot was left.
        column: usize,
        /// The largest remaining candidate pivot, in absolute value.
        pivot: f64,
    },
}

impl fmt::Display for InverseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            InverseError::NotSquare { rows, cols } => {
                write!(f, "a {rows} × {cols} matrix is not square, so it has no inverse")
            }
            InverseError::NonFinite { row, col } => {
                write!(f, "the matrix entry ({row}, {col}) is not finite")
            }
            InverseError::Singular { column, pivot } => write!(
                f,
                "the matrix is singular: no pivot left in column {column} (largest candidate {pivot:e})"
            ),
        }
    }
}

impl std::error::Error for InverseError {}

impl Matrix {
    /// The `rows × cols` zero matrix.
    pub fn zeros(rows: usize, cols: usize) -> Self {
        Self {
            rows,
            cols,
            data: vec![0.0; rows * cols],
        }
    }

    /// The `n × n` identity.
    pub fn identity(n: usize) -> Self {
        let mut m = Self::zeros(n, n);
        for i in 0..n {
            m[(i, i)] = 1.0;
        }
        m
    }

    /// The matrix whose entry `(i, j)` is `entry(i, j)`.
    pub fn from_fn(rows: usize, cols: usize, entry: impl Fn(usize, usize) -> f64) -> Self {
        let mut m = Self::zeros(rows, cols);
        for i in 0..rows {
            for j in 0..cols {
                m[(i, j)] = entry(i, j);
            }
        }
        m
    }

    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Number of columns.
    pub fn cols(&self) -> usize {
        self.cols
    }

    /// Row `i` as a slice.
    pub fn row(&self, i: usize) -> &[f64] {
        &self.data[i * self.cols..(i + 1) * self.cols]
    }

    /// The entries row by row.
    pub fn as_slice(&self) -> &[f64] {
        &self.data
    }

    /// The transpose.
    pub fn transpose(&self) -> Self {
        Self::from_fn(self.cols, self.rows, |i, j| self[(j, i)])
    }

    /// The product `self · other`, or `None` when the inner dimensions differ.
    pub fn checked_mul(&self, other: &Matrix) -> Option<Matrix> {
        if self.cols != other.rows {
            return None;
        }
        let mut out = Matrix::zeros(self.rows, other.cols);
        for i in 0..self.rows {
            for k in 0..self.cols {
                let a = self[(i, k)];
                if a == 0.0 {
                    continue;
                }
                for j in 0..other.cols {
                    out[(i, j)] += a * other[(k, j)];
                }
            }
        }
        Some(out)
    }

    /// The largest entry in absolute value (0 for an empty matrix).
    pub fn max_abs(&self) -> f64 {
        self.data.iter().fold(0.0, |m, &x| m.max(x.abs()))
    }

    /// The inverse by Gauss–Jordan elimination with partial (row) pivoting.
    ///
    /// # Errors
    /// [`InverseError`] when the matrix is not square, contains a non-finite entry,
    /// or a pivot falls to `n·ε·max|a_ij|` or below (singular to rounding).
    pub fn inverse(&self) -> Result<Matrix, InverseError> {
        let n = self.rows;
        if self.cols != n {
            return Err(InverseError::NotSquare {
                rows: self.rows,
                cols: self.cols,
            });
        }
        if let Some(k) = self.data.iter().position(|x| !x.is_finite()) {
            return Err(InverseError::NonFinite {
                row: k / n,
                col: k % n,
            });
        }
        let tolerance = n as f64 * f64::EPSILON * self.max_abs();
        let mut a = self.clone();
        let mut inverse = Matrix::identity(n);
        for col in 0..n {
            let (pivot_row, pivot) = (col..n)
                .map(|r| (r, a[(r, col)]))
                .max_by(|x, y| x.1.abs().total_cmp(&y.1.abs()))
                .unwrap_or((col, 0.0));
            if pivot.abs() <= tolerance {
                return Err(InverseError::Singular {
                    column: col,
                    pivot: pivot.abs(),
                });
            }
            a.swap_rows(col, pivot_row);
            inverse.swap_rows(col, pivot_row);
            for c in 0..n {
                a[(col, c)] /= pivot;
                inverse[(col, c)] /= pivot;
            }
            for r in 0..n {
                let factor = a[(r, col)];
                if r == col || factor == 0.0 {
                    continue;
                }
                for c in 0..n {
                    a[(r, c)] -= factor * a[(col, c)];
                    inverse[(r, c)] -= factor * inverse[(col, c)];
                }
            }
        }
        Ok(inverse)
    }

    fn swap_rows(&mut self, i: usize, j: usize) {
        if i != j {
            for c in 0..self.cols {
                self.data.swap(i * self.cols + c, j * self.cols + c);
            }
        }
    }
}

impl Index<(usize, usize)> for Matrix {
    type Output = f64;

    /// Entry `(i, j)`; panics when out of range, like slice indexing.
    fn index(&self, (i, j): (usize, usize)) -> &f64 {
        assert!(
            i < self.rows && j < self.cols,
            "index ({i}, {j}) out of range"
        );
        &self.data[i * self.cols + j]
    }
}

impl IndexMut<(usize, usize)> for Matrix {
    fn index_mut(&mut self, (i, j): (usize, usize)) -> &mut f64 {
        assert!(
            i < self.rows && j < self.cols,
            "index ({i}, {j}) out of range"
        );
        &mut self.data[i * self.cols + j]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_of_a_hand_computed_matrix() {
        // [[2, 1], [7, 4]]⁻¹ = [[4, −1], [−7, 2]] (determinant 1); the zero-free first
        // column forces a row swap.
        let a = Matrix::from_fn(2, 2, |i, j| [[2.0, 1.0], [7.0, 4.0]][i][j]);
        let inv = a.inverse().unwrap();
        let expected = [[4.0, -1.0], [-7.0, 2.0]];
        for i in 0..2 {
            for j in 0..2 {
                assert!((inv[(i, j)] - expected[i][j]).abs() < 1e-14);
            }
        }
    }

    #[test]
    fn inverse_needs_pivoting_and_multiplies_back_to_the_identity() {
        // a zero on the diagonal: elimination without row exchanges would divide by zero
        let a = Matrix::from_fn(4, 4, |i, j| {
            if i == j {
                0.0
            } else {
                1.0 / (1.0 + i as f64 + 2.0 * j as f64)
            }
        });
        let product = a.checked_mul(&a.inverse().unwrap()).unwrap();
        for i in 0..4 {
            for j in 0..4 {
                let expected = f64::from(u8::from(i == j));
                assert!((product[(i, j)] - expected).abs() < 1e-13);
            }
        }
    }

    #[test]
    fn singular_and_malformed_matrices_are_errors() {
        let rank_one = Matrix::from_fn(3, 3, |i, j| (i + 1) as f64 * (j + 1) as f64);
        assert!(matches!(
            rank_one.inverse(),
            Err(InverseError::Singular { column: 1, .. })
        ));
        assert_eq!(
            Matrix::zeros(2, 3).inverse(),
            Err(InverseError::NotSquare { rows: 2, cols: 3 })
        );
        let mut nan = Matrix::identity(2);
        nan[(1, 0)] = f64::NAN;
        assert_eq!(
            nan.inverse(),
            Err(InverseError::NonFinite { row: 1, col: 0 })
        );
        assert!(nan.inverse().unwrap_err().to_string().contains("(1, 0)"));
        assert!(Matrix::zeros(2, 3)
            .checked_mul(&Matrix::zeros(2, 3))
            .is_none());
    }
}
