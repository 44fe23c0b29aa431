//! The elimination tree of a sparse Cholesky factor `P H Pᵀ = L Lᵀ`, node by node
//! (supernodes, or the columns of a simplicial factor), with the flop counts of a
//! factorization, a solve, and each node's path to the root. The factor keeps it
//! ([`crate::lcp::cholesky`]); the low-rank update ([`crate::lcp::woodbury`]) walks it.

use faer::sparse::linalg::cholesky::{SymbolicCholesky, SymbolicCholeskyRaw};

/// The elimination tree of a Cholesky factor's nodes (supernodes, or the columns of a
/// simplicial factor) with the flop counts that price a low-rank update against a new
/// factorization.
pub(crate) struct FactorTree {
    /// Node `s` holds the permuted columns `start[s]..start[s + 1]`.
    pub(super) start: Vec<usize>,
    pub(super) node_of_column: Vec<usize>,
    /// The parent node (`usize::MAX` at a root); always after its children.
    pub(super) parent: Vec<usize>,
    /// Flops of a forward solve with one right-hand side along the path from node `s`
    /// to its root.
    pub(super) path_flops: Vec<f64>,
    /// Entries of `L⁻¹ e` on that path.
    pub(super) path_length: Vec<usize>,
    /// Flops of the numeric factorization.
    pub(super) factor_flops: f64,
    /// Flops of one solve (forward and backward) with a dense right-hand side.
    pub(super) solve_flops: f64,
}

/// One node of `L`: its column count, the rows below its diagonal block, and its values,
/// column-major, `(width + pattern.len()) × width`.
pub(super) struct Node<'a> {
    pub(super) width: usize,
    pub(super) pattern: &'a [usize],
    pub(super) block: &'a [f64],
}

impl FactorTree {
    /// The tree of `symbolic`; `None` if a simplicial factor does not store each column's
    /// diagonal first (the layout [`Node`] reads).
    pub(crate) fn new(symbolic: &SymbolicCholesky<usize>) -> Option<Self> {
        let n = symbolic.nrows();
        let count = node_count(symbolic);
        let mut start = Vec::with_capacity(count + 1);
        let mut node_of_column = vec![0; n];
        let mut parent = vec![usize::MAX; count];
        let mut node_flops = vec![0.0; count];
        let (mut factor_flops, mut solve_flops) = (0.0, 0.0);
        for (s, parent) in parent.iter_mut().enumerate() {
            let (first, width, pattern) = match symbolic.raw() {
                SymbolicCholeskyRaw::Supernodal(sn) => {
                    let (begin, end) = (sn.supernode_begin()[s], sn.supernode_end()[s]);
                    (begin, end - begin, sn.supernode(s).pattern())
                }
                SymbolicCholeskyRaw::Simplicial(sp) => {
                    let (ptr, rows) = (sp.col_ptr(), sp.row_idx());
                    if rows.get(ptr[s]) != Some(&s) {
                        return None;
                    }
                    (s, 1, &rows[ptr[s] + 1..ptr[s + 1]])
                }
            };
            start.push(first);
            node_of_column[first..first + width].fill(s);
            if let Some(&lowest) = pattern.iter().min() {
                *parent = lowest;
            }
            let (w, p) = (width as f64, pattern.len() as f64);
            node_flops[s] = w * w + 2.0 * w * p;
            factor_flops += w * w * w / 3.0 + w * w * p + w * p * p;
            solve_flops += 2.0 * node_flops[s];
        }
        start.push(n);
        // the parent was stored as a column: map it to its node
        for p in parent.iter_mut().filter(|p| **p != usize::MAX) {
            *p = node_of_column[*p];
        }
        let mut path_flops = node_flops;
        let mut path_length: Vec<usize> = (0..count).map(|s| start[s + 1] - start[s]).collect();
        for s in (0..count).rev() {
            if parent[s] != usize::MAX {
                debug_assert!(parent[s] > s);
                path_flops[s] += path_flops[parent[s]];
                path_length[s] += path_length[parent[s]];
            }
        }
        Some(Self {
            start,
            node_of_column,
            parent,
            path_flops,
            path_length,
            factor_flops,
            solve_flops,
        })
    }

    pub(super) fn node<'a>(
        &self,
        symbolic: &'a SymbolicCholesky<usize>,
        values: &'a [f64],
        s: usize,
    ) -> Node<'a> {
        let width = self.start[s + 1] - self.start[s];
        match symbolic.raw() {
            SymbolicCholeskyRaw::Supernodal(sn) => Node {
                width,
                pattern: sn.supernode(s).pattern(),
                block: &values[sn.col_ptr_for_val()[s]..sn.col_ptr_for_val()[s + 1]],
            },
            SymbolicCholeskyRaw::Simplicial(sp) => {
                let (ptr, rows) = (sp.col_ptr(), sp.row_idx());
                Node {
                    width,
                    pattern: &rows[ptr[s] + 1..ptr[s + 1]],
                    block: &values[ptr[s]..ptr[s + 1]],
                }
            }
        }
    }
}

fn node_count(symbolic: &SymbolicCholesky<usize>) -> usize {
    match symbolic.raw() {
        SymbolicCholeskyRaw::Supernodal(sn) => sn.n_supernodes(),
        SymbolicCholeskyRaw::Simplicial(sp) => sp.nrows(),
    }
}
