//! Solves with a low-rank modification `H = H₀ + U S Uᵀ` of a Cholesky-factored SPD
//! matrix `H₀` by the Sherman–Morrison–Woodbury formula
//! `H⁻¹ = H₀⁻¹ − H₀⁻¹ U (I + S W)⁻¹ S Uᵀ H₀⁻¹`, `W = Uᵀ H₀⁻¹ U`.
//!
//! Semismooth Newton on an obstacle problem changes its Hessian between iterations only
//! in the cells whose contact state flips: `U` holds their rows of `B` (three entries
//! each for P1), `S` the change of `C⁻¹` on them. With `P H₀ Pᵀ = L Lᵀ`,
//! `W = ZᵀZ` for `Z = L⁻¹ P U`, and a column of `Z` is nonzero only on the elimination-tree
//! path from its entries to the root, which is all its forward solve visits (Gilbert–
//! Peierls). A few dozen flipped cells then cost a fraction of a new factorization.

use crate::error::{Error, Result};
use crate::lcp::cholesky::CholeskyFactor;
use crate::lcp::factor_tree::FactorTree;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::matmul::matmul;
use faer::linalg::triangular_solve::solve_lower_triangular_in_place;
use faer::sparse::linalg::cholesky::supernodal::SupernodalLltRef;
use faer::sparse::linalg::cholesky::SymbolicCholeskyRaw;
use faer::sparse::linalg::triangular_solve::solve_lower_triangular_in_place as sparse_lower_solve;
use faer::sparse::linalg::triangular_solve::solve_lower_triangular_transpose_in_place;
use faer::sparse::SparseColMatRef;
use faer::{Accum, Conj, MatMut, MatRef, Par};
use nalgebra::{DMatrix, DVector};

/// `Z = L⁻¹ P U` for sparse columns `U`: nonzero only on the nodes of the columns'
/// elimination-tree paths, stored per node of their union as a dense `width × q` block
/// for the `q` columns whose path passes through it.
struct PathMatrix {
    /// Union of the paths, in increasing order (children before parents).
    nodes: Vec<usize>,
    /// The columns at `nodes[i]`: `columns[column_ptr[i]..column_ptr[i + 1]]`, increasing.
    column_ptr: Vec<usize>,
    columns: Vec<usize>,
    /// `nodes[i]`'s block, column-major, starts at `values[value_ptr[i]]`.
    value_ptr: Vec<usize>,
    values: Vec<f64>,
}

impl PathMatrix {
    fn block(&self, i: usize) -> (&[usize], &[f64]) {
        (
            &self.columns[self.column_ptr[i]..self.column_ptr[i + 1]],
            &self.values[self.value_ptr[i]..self.value_ptr[i + 1]],
        )
    }
}

impl CholeskyFactor {
    fn tree(&self) -> &FactorTree {
        self.structure
            .tree
            .as_ref()
            .expect("callers check that the factor has a tree")
    }

    /// `P v` (`(P v)_i = v_{fwd(i)}`), the ordering of `L`.
    fn permute(&self, v: &[f64]) -> Vec<f64> {
        match self.structure.symbolic.perm() {
            Some(perm) => perm.arrays().0.iter().map(|&i| v[i]).collect(),
            None => v.to_vec(),
        }
    }

    /// `Pᵀ v`.
    fn unpermute(&self, v: &[f64]) -> Vec<f64> {
        match self.structure.symbolic.perm() {
            Some(perm) => perm.arrays().1.iter().map(|&i| v[i]).collect(),
            None => v.to_vec(),
        }
    }

    /// `x ← L⁻¹ x` (`transpose`: `x ← L⁻ᵀ x`), in the ordering of `L`.
    fn triangular_solve(&self, x: &mut [f64], transpose: bool) {
        let n = x.len();
        let rhs = MatMut::from_column_major_slice_mut(x, n, 1);
        match self.structure.symbolic.raw() {
            SymbolicCholeskyRaw::Supernodal(sn) => {
                let factor = SupernodalLltRef::new(sn, &self.values);
                let mut scratch = MemBuffer::new(sn.solve_in_place_scratch::<f64>(1, Par::Seq));
                let stack = MemStack::new(&mut scratch);
                if transpose {
                    factor.l_transpose_solve_with_conj(Conj::No, rhs, Par::Seq, stack);
                } else {
                    factor.l_solve_with_conj(Conj::No, rhs, Par::Seq, stack);
                }
            }
            SymbolicCholeskyRaw::Simplicial(sp) => {
                let l = SparseColMatRef::new(sp.factor(), &self.values);
                if transpose {
                    solve_lower_triangular_transpose_in_place(l, Conj::No, rhs, Par::Seq);
                } else {
                    sparse_lower_solve(l, Conj::No, rhs, Par::Seq);
                }
            }
        }
    }

    /// `Z = L⁻¹ P U` for the columns of `term`, visiting only their paths to the root;
    /// the top of the tree, shared by every path, is solved for all columns at once.
    fn path_matrix(&self, term: &LowRankTerm) -> PathMatrix {
        let tree = self.tree();
        let symbolic = &self.structure.symbolic;
        let inverse = symbolic.perm().map(|p| p.arrays().1);
        let row = |i: usize| inverse.map_or(i, |inv| inv[i]);
        let k = term.rank();
        // (node, column) for every node on every column's path
        let mut visits = Vec::new();
        let mut last_visitor = vec![usize::MAX; tree.parent.len()];
        for j in 0..k {
            for &(i, _) in term.column(j) {
                let mut s = tree.node_of_column[row(i)];
                while s != usize::MAX && last_visitor[s] != j {
                    last_visitor[s] = j;
                    visits.push((s, j));
                    s = tree.parent[s];
                }
            }
        }
        visits.sort_unstable();
        let mut index_of_node = last_visitor;
        index_of_node.fill(usize::MAX);
        let (mut nodes, mut column_ptr, mut columns, mut value_ptr) = (
            Vec::new(),
            vec![0],
            Vec::with_capacity(visits.len()),
            vec![0],
        );
        for (v, &(s, j)) in visits.iter().enumerate() {
            columns.push(j);
            if v + 1 == visits.len() || visits[v + 1].0 != s {
                index_of_node[s] = nodes.len();
                nodes.push(s);
                column_ptr.push(columns.len());
                let q = column_ptr[nodes.len()] - column_ptr[nodes.len() - 1];
                value_ptr
                    .push(value_ptr[nodes.len() - 1] + q * (tree.start[s + 1] - tree.start[s]));
            }
        }
        let mut values = vec![0.0; *value_ptr.last().expect("value_ptr starts with 0")];
        // the position of column j among node i's columns
        let position = |columns: &[usize], i: usize, j: usize| {
            let at = &columns[column_ptr[i]..column_ptr[i + 1]];
            at.binary_search(&j)
                .expect("a column visits every node of its path")
        };
        if matches!(symbolic.raw(), SymbolicCholeskyRaw::Simplicial(_)) {
            // Nodes of one column each: the dense kernels would cost more in calls than
            // in flops, so each column is solved alone along its path.
            let mut x = vec![0.0; symbolic.nrows()];
            let mut path = Vec::new();
            let mut on_path = vec![false; tree.parent.len()];
            for j in 0..k {
                path.clear();
                for &(i, v) in term.column(j) {
                    let p = row(i);
                    x[p] += v;
                    let mut s = tree.node_of_column[p];
                    while s != usize::MAX && !on_path[s] {
                        on_path[s] = true;
                        path.push(s);
                        s = tree.parent[s];
                    }
                }
                path.sort_unstable();
                for &s in &path {
                    on_path[s] = false;
                    let node = tree.node(symbolic, &self.values, s);
                    let xs = x[s] / node.block[0];
                    x[s] = 0.0;
                    let b = index_of_node[s];
                    values[value_ptr[b] + position(&columns, b, j)] = xs;
                    if xs != 0.0 {
                        for (&r, l) in node.pattern.iter().zip(&node.block[1..]) {
                            x[r] -= l * xs;
                        }
                    }
                }
            }
        } else {
            self.solve_on_supernodes(
                &nodes,
                &column_ptr,
                &columns,
                &value_ptr,
                &index_of_node,
                term,
                &mut values,
            );
        }
        PathMatrix {
            nodes,
            column_ptr,
            columns,
            value_ptr,
            values,
        }
    }

    /// The numeric part of [`CholeskyFactor::path_matrix`] on a supernodal factor: each
    /// node's block for all its columns at once (dense triangular solve and product).
    #[allow(clippy::too_many_arguments)]
    fn solve_on_supernodes(
        &self,
        nodes: &[usize],
        column_ptr: &[usize],
        columns: &[usize],
        value_ptr: &[usize],
        index_of_node: &[usize],
        term: &LowRankTerm,
        values: &mut [f64],
    ) {
        let tree = self.tree();
        let symbolic = &self.structure.symbolic;
        let inverse = symbolic.perm().map(|p| p.arrays().1);
        let row = |i: usize| inverse.map_or(i, |inv| inv[i]);
        let position = |i: usize, j: usize| {
            let at = &columns[column_ptr[i]..column_ptr[i + 1]];
            at.binary_search(&j)
                .expect("a column visits every node of its path")
        };
        for j in 0..term.rank() {
            for &(i, v) in term.column(j) {
                let p = row(i);
                let s = tree.node_of_column[p];
                let b = index_of_node[s];
                let width = tree.start[s + 1] - tree.start[s];
                values[value_ptr[b] + position(b, j) * width + p - tree.start[s]] += v;
            }
        }
        let mut below = Vec::new();
        let mut map = Vec::new();
        for (b, &s) in nodes.iter().enumerate() {
            let node = tree.node(symbolic, &self.values, s);
            let (w, p) = (node.width, node.pattern.len());
            let at = &columns[column_ptr[b]..column_ptr[b + 1]];
            let q = at.len();
            let (done, rest) = values.split_at_mut(value_ptr[b + 1]);
            let x = MatMut::from_column_major_slice_mut(&mut done[value_ptr[b]..], w, q);
            let l = MatRef::from_column_major_slice(node.block, w + p, w);
            let (top, bottom) = l.split_at_row(w);
            solve_lower_triangular_in_place(top, x, Par::Seq);
            if p == 0 {
                continue;
            }
            let x = MatRef::from_column_major_slice(&done[value_ptr[b]..], w, q);
            below.clear();
            below.resize(p * q, 0.0);
            matmul(
                MatMut::from_column_major_slice_mut(&mut below, p, q),
                Accum::Replace,
                bottom,
                x,
                1.0,
                Par::Seq,
            );
            // subtract into the ancestors' blocks; the pattern is sorted, so its rows come
            // node by node
            let mut t = 0;
            while t < p {
                let parent = tree.node_of_column[node.pattern[t]];
                let a = index_of_node[parent];
                let parent_width = tree.start[parent + 1] - tree.start[parent];
                map.clear();
                map.extend(at.iter().map(|&j| position(a, j)));
                let offset = value_ptr[a] - value_ptr[b + 1];
                while t < p && node.pattern[t] < tree.start[parent + 1] {
                    let r = node.pattern[t] - tree.start[parent];
                    for (c, &m) in map.iter().enumerate() {
                        rest[offset + m * parent_width + r] -= below[c * p + t];
                    }
                    t += 1;
                }
            }
        }
    }
}

/// The modification `U S Uᵀ`: sparse columns of `U` grouped in blocks, each with its
/// dense symmetric `S` block (`S` block diagonal).
#[derive(Clone, Debug, Default)]
pub struct LowRankTerm {
    column_ptr: Vec<usize>,
    entries: Vec<(usize, f64)>,
    /// `(first column, size)` of each block.
    blocks: Vec<(usize, usize)>,
    /// Each block's `S`, row-major, concatenated.
    s: Vec<f64>,
}

impl LowRankTerm {
    /// An empty term (`U S Uᵀ = 0`).
    pub fn new() -> Self {
        Self {
            column_ptr: vec![0],
            ..Self::default()
        }
    }

    /// Appends a block: `columns` of `U` (sparse, `(row, value)`) with their `S` block
    /// (`q × q` row-major, `q` the number of columns).
    ///
    /// # Errors
    /// [`Error::Input`] (and the term unchanged) when `s` does not have `q²` entries.
    pub fn push_block<'a>(
        &mut self,
        columns: impl IntoIterator<Item = &'a [(usize, f64)]>,
        s: &[f64],
    ) -> Result<()> {
        if self.column_ptr.is_empty() {
            self.column_ptr.push(0);
        }
        let (first, entries) = (self.rank(), self.entries.len());
        for column in columns {
            self.entries.extend_from_slice(column);
            self.column_ptr.push(self.entries.len());
        }
        let q = self.rank() - first;
        if s.len() != q * q {
            self.entries.truncate(entries);
            self.column_ptr.truncate(first + 1);
            return Err(Error::Input(format!(
                "a block of {q} columns of U needs {} entries of S, not {}",
                q * q,
                s.len()
            )));
        }
        self.blocks.push((first, q));
        self.s.extend_from_slice(s);
        Ok(())
    }

    /// An error unless every row of `U` is below `n`, the order of the matrix modified.
    fn check_rows(&self, n: usize) -> Result<()> {
        match self.entries.iter().find(|&&(i, _)| i >= n) {
            Some(&(i, _)) => Err(Error::Input(format!(
                "the low-rank term has an entry in row {i} of a matrix of order {n}"
            ))),
            None => Ok(()),
        }
    }

    /// The number of columns of `U`.
    pub fn rank(&self) -> usize {
        self.column_ptr.len().saturating_sub(1)
    }

    fn column(&self, j: usize) -> &[(usize, f64)] {
        &self.entries[self.column_ptr[j]..self.column_ptr[j + 1]]
    }

    /// `U S Uᵀ x` (`x` of the matrix's order).
    ///
    /// # Errors
    /// [`Error::Input`] when `U` has a row beyond `x`.
    pub fn apply(&self, x: &[f64]) -> Result<Vec<f64>> {
        self.check_rows(x.len())?;
        let t: Vec<f64> = (0..self.rank())
            .map(|j| self.column(j).iter().map(|&(i, v)| v * x[i]).sum())
            .collect();
        let st = self.s_times(&t);
        let mut y = vec![0.0; x.len()];
        for (j, c) in st.iter().enumerate() {
            for &(i, v) in self.column(j) {
                y[i] += v * c;
            }
        }
        Ok(y)
    }

    /// `y = S x` (block diagonal).
    fn s_times(&self, x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; x.len()];
        let mut offset = 0;
        for &(first, q) in &self.blocks {
            let s = &self.s[offset..offset + q * q];
            for i in 0..q {
                y[first + i] = (0..q).map(|l| s[i * q + l] * x[first + l]).sum();
            }
            offset += q * q;
        }
        y
    }
}

/// `(H₀ + U S Uᵀ)⁻¹` applied through the Cholesky factor of `H₀`: one solve with `H₀`
/// and one with the `k × k` capacitance matrix `I + S W` per application.
pub struct WoodburySolver<'f> {
    factor: &'f CholeskyFactor,
    term: LowRankTerm,
    z: PathMatrix,
    /// The LU factors of `I + S W`; `None` for a term of rank 0 (nothing to correct:
    /// nalgebra's LU of a `0 × 0` matrix cannot solve).
    capacitance: Option<nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>>,
}

impl<'f> WoodburySolver<'f> {
    /// Estimated flops of `applications` solves through the update, relative to a new
    /// factorization followed by as many solves; `None` when the factor's layout is not
    /// supported, the term has a row beyond the factor's order, or its rank exceeds that
    /// order (then factor anew: the update cannot be cheaper).
    pub fn relative_cost(
        factor: &CholeskyFactor,
        term: &LowRankTerm,
        applications: usize,
    ) -> Option<f64> {
        let (structure, tree) = (&*factor.structure, factor.structure.tree.as_ref()?);
        let n = structure.symbolic.nrows();
        if term.rank() > n || term.check_rows(n).is_err() {
            return None;
        }
        let inverse = structure.symbolic.perm().map(|p| p.arrays().1);
        let k = term.rank();
        let (mut paths, mut length) = (0.0, 0.0);
        for j in 0..k {
            // the column's entries share their path but for its lowest nodes: price the
            // longest
            let node = term
                .column(j)
                .iter()
                .map(|&(i, _)| tree.node_of_column[inverse.map_or(i, |inv| inv[i])])
                .max_by(|&a, &b| tree.path_flops[a].total_cmp(&tree.path_flops[b]));
            if let Some(s) = node {
                paths += tree.path_flops[s];
                length += tree.path_length[s] as f64;
            }
        }
        let k = k as f64;
        let dots = 0.5 * k * length;
        let capacitance = k * k * k / 3.0;
        let applications = applications as f64;
        let update = paths + dots + capacitance + applications * tree.solve_flops;
        let refactor = tree.factor_flops + applications * tree.solve_flops;
        Some(update / refactor)
    }

    /// The solver for `H₀ + U S Uᵀ` with `H₀ = L Lᵀ` in `factor`. A term of rank 0
    /// solves with `H₀` alone.
    ///
    /// # Errors
    /// [`Error::Input`] when `U` has a row beyond the factor's order `n`;
    /// [`Error::LinearSolve`] when the capacitance matrix is singular (the modified
    /// matrix is, or nearly), the rank exceeds `n` (factor the modified matrix instead)
    /// or the factor's layout is not supported.
    pub fn new(factor: &'f CholeskyFactor, term: LowRankTerm) -> Result<Self> {
        let Some(tree) = factor.structure.tree.as_ref() else {
            return Err(Error::LinearSolve(
                "the factor's layout does not support low-rank updates".into(),
            ));
        };
        let n = factor.structure.symbolic.nrows();
        term.check_rows(n)?;
        let k = term.rank();
        if k > n {
            return Err(Error::LinearSolve(format!(
                "a low-rank update of rank {k} to a matrix of order {n}: factor it anew"
            )));
        }
        let z = factor.path_matrix(&term);
        if k == 0 {
            return Ok(Self {
                factor,
                term,
                z,
                capacitance: None,
            });
        }
        let mut w = DMatrix::<f64>::zeros(k, k);
        let mut gram = Vec::new();
        for (i, &s) in z.nodes.iter().enumerate() {
            let width = tree.start[s + 1] - tree.start[s];
            let (at, block) = z.block(i);
            let q = at.len();
            if width == 1 {
                // a simplicial node: the dense product would cost more in its call
                for (a, &ja) in at.iter().enumerate() {
                    for (b, &jb) in at.iter().enumerate() {
                        w[(ja, jb)] += block[a] * block[b];
                    }
                }
                continue;
            }
            let x = MatRef::from_column_major_slice(block, width, q);
            gram.clear();
            gram.resize(q * q, 0.0);
            matmul(
                MatMut::from_column_major_slice_mut(&mut gram, q, q),
                Accum::Replace,
                x.transpose(),
                x,
                1.0,
                Par::Seq,
            );
            for (a, &ja) in at.iter().enumerate() {
                for (b, &jb) in at.iter().enumerate() {
                    w[(ja, jb)] += gram[b * q + a];
                }
            }
        }
        // I + S W, S block diagonal
        let mut capacitance = DMatrix::identity(k, k);
        let mut offset = 0;
        for &(first, q) in &term.blocks {
            let s = &term.s[offset..offset + q * q];
            for i in 0..q {
                for j in 0..k {
                    capacitance[(first + i, j)] += (0..q)
                        .map(|l| s[i * q + l] * w[(first + l, j)])
                        .sum::<f64>();
                }
            }
            offset += q * q;
        }
        let capacitance = capacitance.lu();
        if !capacitance.is_invertible() {
            return Err(Error::LinearSolve(
                "the low-rank update leaves a singular matrix".into(),
            ));
        }
        Ok(Self {
            factor,
            term,
            z,
            capacitance: Some(capacitance),
        })
    }

    /// `(H₀ + U S Uᵀ)⁻¹ b = Pᵀ L⁻ᵀ (y − Z (I + S W)⁻¹ S Zᵀ y)`, `y = L⁻¹ P b`: one
    /// solve with `H₀` and products with `Z` on its paths.
    ///
    /// # Errors
    /// [`Error::Input`] when `b` is not of the matrix's order; [`Error::LinearSolve`]
    /// when the result is not finite.
    pub fn solve(&self, b: &[f64]) -> Result<Vec<f64>> {
        let n = self.factor.structure.symbolic.nrows();
        if b.len() != n {
            return Err(Error::Input(format!(
                "a right-hand side of length {} for a matrix of order {n}",
                b.len()
            )));
        }
        let tree = self.factor.tree();
        let mut y = self.factor.permute(b);
        self.factor.triangular_solve(&mut y, false);
        let k = self.term.rank();
        let Some(capacitance) = &self.capacitance else {
            // rank 0: H = H₀
            self.factor.triangular_solve(&mut y, true);
            return finite(self.factor.unpermute(&y));
        };
        let mut t = vec![0.0; k];
        for (i, &s) in self.z.nodes.iter().enumerate() {
            let (at, block) = self.z.block(i);
            let ys = &y[tree.start[s]..tree.start[s + 1]];
            for (&j, column) in at.iter().zip(block.chunks_exact(ys.len())) {
                t[j] += column.iter().zip(ys).map(|(z, y)| z * y).sum::<f64>();
            }
        }
        let st = DVector::from_vec(self.term.s_times(&t));
        let c = capacitance.solve(&st).ok_or_else(|| {
            Error::LinearSolve("the low-rank update leaves a singular matrix".into())
        })?;
        for (i, &s) in self.z.nodes.iter().enumerate() {
            let (at, block) = self.z.block(i);
            let ys = &mut y[tree.start[s]..tree.start[s + 1]];
            for (&j, column) in at.iter().zip(block.chunks_exact(ys.len())) {
                for (y, z) in ys.iter_mut().zip(column) {
                    *y -= z * c[j];
                }
            }
        }
        self.factor.triangular_solve(&mut y, true);
        finite(self.factor.unpermute(&y))
    }
}

/// `x`, or an error when it is not finite (a numerically singular matrix).
fn finite(x: Vec<f64>) -> Result<Vec<f64>> {
    if x.iter().all(|v| v.is_finite()) {
        Ok(x)
    } else {
        Err(Error::LinearSolve(
            "the solution is not finite: the matrix is numerically singular".into(),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lcp::cholesky::{multiply, Cholesky};
    use crate::SparseMatrix;
    use faer::sparse::Triplet;

    struct Random(u64);

    impl Random {
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }

        fn index(&mut self, n: usize) -> usize {
            ((self.next() * n as f64) as usize).min(n - 1)
        }
    }

    /// The 5-point Laplacian on an `nx × ny` grid plus `shift` on the diagonal, both
    /// triangles stored, as triplets.
    fn grid_laplacian(nx: usize, ny: usize, shift: f64) -> Vec<Triplet<usize, usize, f64>> {
        let id = |i: usize, j: usize| i + nx * j;
        let mut t = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                t.push(Triplet::new(id(i, j), id(i, j), 4.0 + shift));
                if i + 1 < nx {
                    t.push(Triplet::new(id(i, j), id(i + 1, j), -1.0));
                    t.push(Triplet::new(id(i + 1, j), id(i, j), -1.0));
                }
                if j + 1 < ny {
                    t.push(Triplet::new(id(i, j), id(i, j + 1), -1.0));
                    t.push(Triplet::new(id(i, j + 1), id(i, j), -1.0));
                }
            }
        }
        t
    }

    /// Adds `U S Uᵀ` of one block to the triplets.
    fn add_block(
        triplets: &mut Vec<Triplet<usize, usize, f64>>,
        columns: &[Vec<(usize, f64)>],
        s: &[f64],
        sign: f64,
    ) {
        let q = columns.len();
        for a in 0..q {
            for b in 0..q {
                for &(i, u) in &columns[a] {
                    for &(j, v) in &columns[b] {
                        triplets.push(Triplet::new(i, j, sign * u * s[a * q + b] * v));
                    }
                }
            }
        }
    }

    fn matrix(n: usize, triplets: &[Triplet<usize, usize, f64>]) -> SparseMatrix {
        SparseMatrix::try_new_from_triplets(n, n, triplets).unwrap()
    }

    /// Sparse columns of `U` and their `S` block.
    type TermBlock = (Vec<Vec<(usize, f64)>>, Vec<f64>);

    /// Random blocks of 1–3 sparse columns (three entries each, as a P1 cell's row of
    /// B) with SPD `S` blocks.
    fn random_blocks(random: &mut Random, n: usize, count: usize) -> Vec<TermBlock> {
        (0..count)
            .map(|_| {
                let q = 1 + random.index(3);
                let columns: Vec<Vec<(usize, f64)>> = (0..q)
                    .map(|_| {
                        let first = random.index(n - 2);
                        (first..first + 3)
                            .map(|i| (i, 0.2 + random.next()))
                            .collect()
                    })
                    .collect();
                // S = G Gᵀ + I/2, scaled over decades as 1/C is
                let g: Vec<f64> = (0..q * q).map(|_| random.next() - 0.5).collect();
                let scale = 10f64.powf(4.0 * random.next() - 1.0);
                let mut s = vec![0.0; q * q];
                for a in 0..q {
                    for b in 0..q {
                        let gg: f64 = (0..q).map(|c| g[a * q + c] * g[b * q + c]).sum();
                        s[a * q + b] = scale * (gg + if a == b { 0.5 } else { 0.0 });
                    }
                }
                (columns, s)
            })
            .collect()
    }

    /// The updated solve equals a fresh factorization of the modified matrix, for added
    /// terms (`S > 0`) and removed ones (`S < 0` taking back what `H₀` holds), on a
    /// supernodal (2D grid) and a simplicial (1D chain) factor.
    #[test]
    fn woodbury_solves_equal_a_fresh_factorization() {
        let mut kinds = Vec::new();
        for (nx, ny, seed, supernodal) in [
            (60, 60, 1, true),
            (60, 60, 4, false),
            (400, 1, 2, false),
            (25, 30, 3, true),
        ] {
            let n = nx * ny;
            let mut random = Random(seed);
            let base = grid_laplacian(nx, ny, 0.01);
            let removed = random_blocks(&mut random, n, 6);
            let added = random_blocks(&mut random, n, 20);
            // H₀ holds the blocks that the modification removes
            let mut h0 = base.clone();
            for (columns, s) in &removed {
                add_block(&mut h0, columns, s, 1.0);
            }
            let h0 = matrix(n, &h0);
            let mut h = base;
            let mut term = LowRankTerm::new();
            for (columns, s) in &added {
                add_block(&mut h, columns, s, 1.0);
                term.push_block(columns.iter().map(|c| c.as_slice()), s)
                    .unwrap();
            }
            for (columns, s) in &removed {
                let minus: Vec<f64> = s.iter().map(|v| -v).collect();
                term.push_block(columns.iter().map(|c| c.as_slice()), &minus)
                    .unwrap();
            }
            let h = matrix(n, &h);
            let pattern = h0.symbolic().to_owned().unwrap();
            let analysis = if supernodal {
                Cholesky::analyse_supernodal(&pattern)
            } else {
                Cholesky::analyse(&pattern)
            };
            let factor = analysis.unwrap().factor_cholesky(&h0).unwrap();
            kinds.push(matches!(
                factor.structure.symbolic.raw(),
                SymbolicCholeskyRaw::Supernodal(_)
            ));
            let cost = WoodburySolver::relative_cost(&factor, &term, 1).unwrap();
            assert!(cost.is_finite() && cost > 0.0);
            let solver = WoodburySolver::new(&factor, term).unwrap();
            let b: Vec<f64> = (0..n).map(|_| random.next() - 0.5).collect();
            let x = solver.solve(&b).unwrap();
            let exact = crate::lcp::cholesky::solve_spd(&h, &b).unwrap();
            let scale = exact.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let error = x
                .iter()
                .zip(&exact)
                .fold(0.0f64, |m, (x, e)| m.max((x - e).abs()));
            assert!(
                error <= 1e-9 * scale,
                "{nx}×{ny}: error {error:e} of {scale:e}"
            );
            // and the residual of the modified system, independently of the reference
            let hx = multiply(&h, &x);
            let residual = hx
                .iter()
                .zip(&b)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            assert!(residual <= 1e-9, "{nx}×{ny}: residual {residual:e}");
        }
        assert!(
            kinds.contains(&true) && kinds.contains(&false),
            "both layouts are covered: {kinds:?}"
        );
    }

    /// A term of rank 0 (the Newton step whose contact set did not change since the last
    /// factorization) solves with `H₀` alone; it panicked in the `0 × 0` capacitance
    /// solve. Terms that do not fit the factor are errors, not panics.
    #[test]
    fn empty_and_misfit_terms_are_solved_or_refused() {
        for supernodal in [false, true] {
            let (nx, ny) = (12, 9);
            let n = nx * ny;
            let h0 = matrix(n, &grid_laplacian(nx, ny, 0.1));
            let pattern = h0.symbolic().to_owned().unwrap();
            let analysis = if supernodal {
                Cholesky::analyse_supernodal(&pattern)
            } else {
                Cholesky::analyse(&pattern)
            };
            let factor = analysis.unwrap().factor_cholesky(&h0).unwrap();
            let b: Vec<f64> = (0..n).map(|i| (i % 7) as f64 - 3.0).collect();
            let empty = LowRankTerm::new();
            assert!(WoodburySolver::relative_cost(&factor, &empty, 1).unwrap() < 1.0);
            let x = WoodburySolver::new(&factor, empty)
                .unwrap()
                .solve(&b)
                .unwrap();
            let residual = multiply(&h0, &x)
                .iter()
                .zip(&b)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            assert!(residual <= 1e-12, "rank 0: residual {residual:e}");
            // the default term (no column pointer yet) is empty too
            assert!(WoodburySolver::new(&factor, LowRankTerm::default())
                .unwrap()
                .solve(&b)
                .is_ok());
            // a right-hand side of another order
            let solver = WoodburySolver::new(&factor, LowRankTerm::new()).unwrap();
            assert!(solver.solve(&b[1..]).is_err());
            assert!(factor.solve(&b[1..]).is_err());
            // a row beyond the matrix
            let mut outside = LowRankTerm::new();
            outside.push_block([&[(n, 1.0)][..]], &[1.0]).unwrap();
            assert!(WoodburySolver::relative_cost(&factor, &outside, 1).is_none());
            assert!(WoodburySolver::new(&factor, outside).is_err());
            // more columns than the order: factor anew instead
            let mut wide = LowRankTerm::new();
            let column = [(0usize, 1.0)];
            let columns = vec![&column[..]; n + 1];
            let mut s = vec![0.0; (n + 1) * (n + 1)];
            s[0] = 1.0;
            wide.push_block(columns, &s).unwrap();
            assert!(WoodburySolver::relative_cost(&factor, &wide, 1).is_none());
            assert!(WoodburySolver::new(&factor, wide).is_err());
            // an S block of the wrong size leaves the term as it was
            let mut term = LowRankTerm::new();
            assert!(term.push_block([&column[..], &column[..]], &[1.0]).is_err());
            assert_eq!(term.rank(), 0);
            // a matrix of another order for the analysis
            assert!(Cholesky::analyse(&pattern)
                .unwrap()
                .factor_cholesky(&matrix(4, &grid_laplacian(2, 2, 0.0)))
                .is_err());
        }
    }

    /// An update that makes the matrix singular is refused, not solved into garbage.
    #[test]
    fn a_singular_update_is_refused() {
        let n = 50;
        let h0 = matrix(n, &grid_laplacian(n, 1, 0.0));
        let pattern = h0.symbolic().to_owned().unwrap();
        let factor = Cholesky::analyse(&pattern)
            .unwrap()
            .factor_cholesky(&h0)
            .unwrap();
        // H = H₀ − e₀e₀ᵀ / (H₀⁻¹)₀₀ is singular: H H₀⁻¹e₀ = e₀ − e₀ = 0
        let e0 = crate::lcp::cholesky::solve_spd(&h0, &{
            let mut e = vec![0.0; n];
            e[0] = 1.0;
            e
        })
        .unwrap();
        let mut term = LowRankTerm::new();
        term.push_block([&[(0usize, 1.0)][..]], &[-1.0 / e0[0]])
            .unwrap();
        assert!(WoodburySolver::new(&factor, term).is_err());
    }
}
