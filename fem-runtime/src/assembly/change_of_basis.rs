//! A change of basis of a few DOFs at a time, so that linear conditions on them become
//! fixed DOFs (docs/elements.md §6).
//!
//! A support may impose linear conditions on a group of DOFs that are not single DOFs:
//! the six Argyris vertex DOFs `U_v = (u, u_x, u_y, u_xx, u_xy, u_yy)` of a plate edge
//! that is not along x or y (`∂_t u = t·∇u`, `∂_tt u = tᵀHt`, …), or the two components
//! `(θ_x, θ_y)` of a vector field at a node of a slanted or curved edge (the hard simple
//! support `θ·t = 0`, a roller `u·n = 0`). The conditions of a group are orthonormalized
//! to `r` independent rows and completed by unit rows to an orthogonal `T` (k×k, k the
//! group's size); the new DOFs are `U'_g = T U_g` (so `U_g = Tᵀ U'_g`) and the first `r`
//! of them are fixed. Globally `R` is the identity but for the `Tᵀ` blocks of the
//! rotated groups, the system becomes `K' = Rᵀ K R`, `F' = Rᵀ F` (`Rᵀ = T` blockwise,
//! the same map as `U' = T U`), and the elimination of fixed DOFs works unchanged on the
//! primed DOFs. `T` orthogonal keeps `K'` as well conditioned as `K`, and since each
//! condition involves one derivative order only, `T` never mixes values, gradients and
//! Hessians (no mixing of units).

use crate::error::{Error, Result};
use crate::SparseMatrix;
use faer::sparse::{SparseColMat, SymbolicSparseColMat};

/// The number of Argyris DOFs at a vertex: `u, u_x, u_y, u_xx, u_xy, u_yy`.
pub const VERTEX_DOFS: usize = 6;

/// The most DOFs a group of conditions may take (an Argyris vertex's six).
pub const MAX_GROUP: usize = VERTEX_DOFS;

/// A condition whose residual after orthogonalization against the earlier ones is below
/// this (relative to its norm) depends on them: the same direction again (two collinear
/// edges meeting at a vertex), or edges meeting at less than ~1e-8 rad.
const DEPENDENT: f64 = 1e-8;

/// A group of global DOFs that conditions are stated on: `dofs[..len]`, distinct.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct DofGroup {
    /// The global DOFs (the first `len`).
    pub dofs: [usize; MAX_GROUP],
    /// How many.
    pub len: usize,
}

impl DofGroup {
    /// The group of `dofs` (1 to [`MAX_GROUP`] distinct DOFs).
    ///
    /// # Errors
    /// An empty group, one of more than [`MAX_GROUP`] DOFs, or a DOF twice.
    pub fn new(dofs: &[usize]) -> Result<Self> {
        if dofs.is_empty() || dofs.len() > MAX_GROUP {
            return Err(Error::Input(format!(
                "a group of conditioned DOFs has 1 to {MAX_GROUP} DOFs, not {}",
                dofs.len()
            )));
        }
        if dofs.iter().enumerate().any(|(i, d)| dofs[..i].contains(d)) {
            return Err(Error::Input(format!("DOFs {dofs:?} repeat one")));
        }
        let mut group = [0; MAX_GROUP];
        group[..dofs.len()].copy_from_slice(dofs);
        Ok(Self {
            dofs: group,
            len: dofs.len(),
        })
    }

    /// The six consecutive DOFs of an Argyris vertex from `start`.
    pub fn vertex(start: usize) -> Self {
        Self {
            dofs: std::array::from_fn(|k| start + k),
            len: VERTEX_DOFS,
        }
    }

    /// The DOFs.
    pub fn as_slice(&self) -> &[usize] {
        &self.dofs[..self.len]
    }

    /// Where DOF `d` is in the group.
    pub fn position(&self, d: usize) -> Option<usize> {
        self.as_slice().iter().position(|&x| x == d)
    }
}

/// One group of DOFs whose basis is rotated.
#[derive(Clone, Debug, PartialEq)]
pub struct RotatedBlock {
    /// The global DOFs: new DOF `k` takes the place of `group.dofs[k]`.
    pub group: DofGroup,
    /// Orthogonal on its leading `group.len × group.len` part: row `k` is new DOF `k` as
    /// a combination of the Cartesian ones, `U' = T U`, `U = Tᵀ U'`.
    pub t: [[f64; MAX_GROUP]; MAX_GROUP],
    /// The first `fixed` new DOFs are fixed (the conditions' span).
    pub fixed: usize,
    /// Their values (the rest 0).
    pub values: [f64; MAX_GROUP],
}

/// The change of basis of a system's DOFs: the identity but at the rotated groups
/// ([`RotatedBlock`]). Built by [`crate::Constraints::change_of_basis`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ChangeOfBasis {
    blocks: Vec<RotatedBlock>,
}

/// How the conditions of one group are imposed.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum GroupResolution {
    /// Every condition is a single DOF (`(place in the group, value)`): fixed as it is.
    Direct(Vec<(usize, f64)>),
    /// A rotation (`group` to be filled in).
    Rotated(Box<RotatedBlock>),
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Resolves the conditions `row · U_g = value` of one group of `len` DOFs (rows of
/// which the first `len` entries are used).
///
/// # Errors
/// [`Error::Input`] for a zero or non-finite row or value, and for conditions that
/// contradict each other (a dependent row whose value does not follow from the others':
/// inconsistent boundary data).
pub(crate) fn resolve_group(
    len: usize,
    conditions: &[([f64; MAX_GROUP], f64)],
) -> Result<GroupResolution> {
    for (row, value) in conditions {
        let row = &row[..len];
        if !row.iter().all(|x| x.is_finite()) || row.iter().all(|&x| x == 0.0) {
            return Err(Error::Input(format!(
                "condition {row:?} on a group of DOFs is zero or not finite"
            )));
        }
        if !value.is_finite() {
            return Err(Error::Input(format!(
                "value {value} of the condition {row:?} is not finite"
            )));
        }
    }
    // the fast path: conditions on single DOFs (edges along x or y) fix them as they are
    let single = |row: &[f64; MAX_GROUP]| {
        let mut nonzero = row[..len].iter().enumerate().filter(|(_, &x)| x != 0.0);
        match (nonzero.next(), nonzero.next()) {
            (Some((k, &x)), None) => Some((k, x)),
            _ => None,
        }
    };
    if conditions.iter().all(|(row, _)| single(row).is_some()) {
        let mut fixed: Vec<(usize, f64)> = Vec::new();
        for (row, value) in conditions {
            let (k, x) = single(row).expect("checked");
            let v = value / x;
            match fixed.iter().find(|(j, _)| *j == k) {
                Some(&(_, w)) => check_consistent(v, w, &row[..len])?,
                None => fixed.push((k, v)),
            }
        }
        return Ok(GroupResolution::Direct(fixed));
    }
    // modified Gram–Schmidt, twice, carrying the values along
    let mut rows: Vec<[f64; MAX_GROUP]> = Vec::new();
    let mut values: Vec<f64> = Vec::new();
    for (row, value) in conditions {
        let norm = dot(&row[..len], &row[..len]).sqrt();
        let mut v = row.map(|x| x / norm);
        let mut val = value / norm;
        for _ in 0..2 {
            for (b, bv) in rows.iter().zip(&values) {
                let c = dot(&v[..len], &b[..len]);
                for k in 0..len {
                    v[k] -= c * b[k];
                }
                val -= c * bv;
            }
        }
        let residual = dot(&v[..len], &v[..len]).sqrt();
        if residual > DEPENDENT {
            rows.push(v.map(|x| x / residual));
            values.push(val / residual);
        } else {
            // the value the earlier conditions give this one
            check_consistent(value / norm, value / norm - val, &row[..len])?;
        }
    }
    let fixed = rows.len();
    // completion by unit rows, the one farthest from the span first
    while rows.len() < len {
        let mut best = ([0.0; MAX_GROUP], 0.0);
        for k in 0..len {
            let mut v = [0.0; MAX_GROUP];
            v[k] = 1.0;
            for _ in 0..2 {
                for b in &rows {
                    let c = dot(&v[..len], &b[..len]);
                    for j in 0..len {
                        v[j] -= c * b[j];
                    }
                }
            }
            let residual = dot(&v[..len], &v[..len]).sqrt();
            if residual > best.1 {
                best = (v, residual);
            }
        }
        rows.push(best.0.map(|x| x / best.1));
    }
    let mut t = [[0.0; MAX_GROUP]; MAX_GROUP];
    t[..len].copy_from_slice(&rows);
    let mut fixed_values = [0.0; MAX_GROUP];
    fixed_values[..fixed].copy_from_slice(&values);
    Ok(GroupResolution::Rotated(Box::new(RotatedBlock {
        group: DofGroup {
            dofs: [0; MAX_GROUP],
            len,
        },
        t,
        fixed,
        values: fixed_values,
    })))
}

/// Two values asked of the same functional must agree (to rounding of the data).
fn check_consistent(asked: f64, implied: f64, row: &[f64]) -> Result<()> {
    if (asked - implied).abs() > 1e-8 * (1.0 + asked.abs().max(implied.abs())) {
        return Err(Error::Input(format!(
            "the boundary conditions at a node contradict each other: the functional {row:?} is asked to be {asked} where the other conditions there make it {implied}"
        )));
    }
    Ok(())
}

impl ChangeOfBasis {
    /// The change of basis with these rotated groups (disjoint).
    pub(crate) fn new(blocks: Vec<RotatedBlock>) -> Self {
        Self { blocks }
    }

    /// The rotated groups.
    pub fn blocks(&self) -> &[RotatedBlock] {
        &self.blocks
    }

    /// Whether no group is rotated (primed and Cartesian DOFs are the same).
    pub fn is_identity(&self) -> bool {
        self.blocks.is_empty()
    }

    /// Maps a full coefficient vector in the primed DOFs to the Cartesian ones,
    /// `U = R U'` (`U_g = Tᵀ U'_g` at each rotated group), in place.
    ///
    /// # Panics
    /// If `x` is shorter than a rotated group's DOFs (a vector of another system).
    pub fn to_cartesian(&self, x: &mut [f64]) {
        for b in &self.blocks {
            let g = b.group.as_slice();
            let u: Vec<f64> = g.iter().map(|&d| x[d]).collect();
            for (k, &d) in g.iter().enumerate() {
                x[d] = (0..g.len()).map(|j| b.t[j][k] * u[j]).sum();
            }
        }
    }

    /// Maps a full vector in the Cartesian DOFs to the primed ones, `U' = T U` at each
    /// rotated group, in place. The same map takes a load vector `F` to `F' = Rᵀ F`
    /// (`R = Tᵀ` blockwise).
    ///
    /// # Panics
    /// As [`ChangeOfBasis::to_cartesian`].
    pub fn to_primed(&self, x: &mut [f64]) {
        for b in &self.blocks {
            let g = b.group.as_slice();
            let u: Vec<f64> = g.iter().map(|&d| x[d]).collect();
            for (k, &d) in g.iter().enumerate() {
                x[d] = dot(&b.t[k][..g.len()], &u);
            }
        }
    }

    /// `K' = Rᵀ K R` of a square matrix `k` on the system's DOFs (full storage, both
    /// triangles), the same size.
    ///
    /// # Errors
    /// [`Error::Input`] if `k` is smaller than a rotated group's DOFs or not square.
    pub fn transform_matrix(&self, k: &SparseMatrix) -> Result<SparseMatrix> {
        let n = k.nrows();
        if k.ncols() != n
            || self
                .blocks
                .iter()
                .any(|b| b.group.as_slice().iter().any(|&d| d >= n))
        {
            return Err(Error::Input(format!(
                "a {}×{} matrix does not hold the rotated DOFs",
                k.nrows(),
                k.ncols()
            )));
        }
        let blocks: Vec<(DofGroup, [[f64; MAX_GROUP]; MAX_GROUP])> =
            self.blocks.iter().map(|b| (b.group, b.t)).collect();
        congruence(k, &blocks)
    }
}

/// A rotation `T` of some index sets: the identity but on the index sets of its blocks
/// (`(indices, t)`: `T[indices[i], indices[j]] = t[i][j]`, disjoint sets).
pub(crate) struct BlockRotation<'a> {
    blocks: &'a [(DofGroup, [[f64; MAX_GROUP]; MAX_GROUP])],
    /// each index's block and place in it (`MAX_GROUP * block + place`), or MAX
    place: Vec<usize>,
}

impl<'a> BlockRotation<'a> {
    /// The rotation of `blocks` on indices `0..n` (every index of a block below `n`).
    pub(crate) fn new(blocks: &'a [(DofGroup, [[f64; MAX_GROUP]; MAX_GROUP])], n: usize) -> Self {
        let mut place = vec![usize::MAX; n];
        for (b, (indices, _)) in blocks.iter().enumerate() {
            for (j, &i) in indices.as_slice().iter().enumerate() {
                place[i] = MAX_GROUP * b + j;
            }
        }
        Self { blocks, place }
    }

    /// Row `i` of `T`, appended to `out` as `(index, value)`.
    pub(crate) fn row(&self, i: usize, out: &mut Vec<(usize, f64)>) {
        if self.place[i] == usize::MAX {
            out.push((i, 1.0));
        } else {
            let (indices, t) = &self.blocks[self.place[i] / MAX_GROUP];
            let m = self.place[i] % MAX_GROUP;
            for (j, &x) in t[m][..indices.len].iter().enumerate() {
                if x != 0.0 {
                    out.push((indices.dofs[j], x));
                }
            }
        }
    }

    /// Column `i` of `T` times `v`, appended to `out` as `(index, value)`: the entry
    /// `(i, v)` of a vector `x` becomes its share of `T x`.
    pub(crate) fn spread(&self, i: usize, v: f64, out: &mut Vec<(usize, f64)>) {
        if self.place[i] == usize::MAX {
            out.push((i, v));
        } else {
            let (indices, t) = &self.blocks[self.place[i] / MAX_GROUP];
            let j = self.place[i] % MAX_GROUP;
            for (row, &index) in t.iter().zip(indices.as_slice()) {
                if row[j] != 0.0 {
                    out.push((index, row[j] * v));
                }
            }
        }
    }
}

/// `T K Tᵀ` for `T` the identity but on the index sets of `blocks` (`(indices, t)`:
/// `T[indices[i], indices[j]] = t[i][j]`, disjoint sets); `k` square, full storage.
/// Column by column with a dense accumulator: memory of the order of `k`'s, and a
/// column away from the rotated groups is copied (its rows there rotated).
pub(crate) fn congruence(
    k: &SparseMatrix,
    blocks: &[(DofGroup, [[f64; MAX_GROUP]; MAX_GROUP])],
) -> Result<SparseMatrix> {
    let n = k.nrows();
    let rotation = BlockRotation::new(blocks, n);
    let (col_ptr, rows, values) = (k.symbolic().col_ptr(), k.symbolic().row_idx(), k.val());
    let mut out_ptr = Vec::with_capacity(n + 1);
    let mut out_rows = Vec::with_capacity(values.len());
    let mut out_values = Vec::with_capacity(values.len());
    out_ptr.push(0);
    let mut work = vec![0.0; n];
    let mut seen = vec![false; n];
    let (mut touched, mut sources, mut spread) = (Vec::new(), Vec::new(), Vec::new());
    for column in 0..n {
        // column `column` of T K Tᵀ = Σ_j T[column][j] · T (column j of K)
        sources.clear();
        rotation.row(column, &mut sources);
        for &(j, weight) in &sources {
            for e in col_ptr[j]..col_ptr[j + 1] {
                spread.clear();
                rotation.spread(rows[e], weight * values[e], &mut spread);
                for &(r, v) in &spread {
                    if !seen[r] {
                        seen[r] = true;
                        touched.push(r);
                    }
                    work[r] += v;
                }
            }
        }
        touched.sort_unstable();
        for &r in &touched {
            out_rows.push(r);
            out_values.push(work[r]);
            work[r] = 0.0;
            seen[r] = false;
        }
        touched.clear();
        out_ptr.push(out_rows.len());
    }
    let pattern = SymbolicSparseColMat::new_checked(n, n, out_ptr, None, out_rows);
    Ok(SparseColMat::new(pattern, out_values))
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::Triplet;

    fn rotation(conditions: &[([f64; 6], f64)]) -> RotatedBlock {
        match resolve_group(6, conditions).unwrap() {
            GroupResolution::Rotated(r) => *r,
            other => panic!("not rotated: {other:?}"),
        }
    }

    /// Single-DOF conditions take the fast path; a repeated one collapses; a slanted
    /// condition gives an orthogonal T whose fixed rows span the conditions and
    /// satisfy their values.
    #[test]
    fn vertex_conditions_resolve() {
        let e = |k: usize, s: f64| {
            let mut r = [0.0; 6];
            r[k] = s;
            r
        };
        assert_eq!(
            resolve_group(6, &[(e(0, 1.0), 0.0), (e(1, -1.0), 2.0), (e(1, 1.0), -2.0)]).unwrap(),
            GroupResolution::Direct(vec![(0, 0.0), (1, -2.0)])
        );
        assert!(resolve_group(6, &[(e(1, 1.0), 1.0), (e(1, 1.0), 2.0)]).is_err());
        let (c, s) = (0.6f64, 0.8f64);
        let conditions = [
            (e(0, 1.0), 0.5),
            ([0.0, c, s, 0.0, 0.0, 0.0], 1.5),
            ([0.0, 0.0, 0.0, c * c, 2.0 * c * s, s * s], -0.25),
            ([0.0, -2.0 * c, -2.0 * s, 0.0, 0.0, 0.0], -3.0), // the same, scaled
        ];
        let r = rotation(&conditions);
        assert_eq!(r.fixed, 3);
        for i in 0..6 {
            for j in 0..6 {
                let expected = if i == j { 1.0 } else { 0.0 };
                assert!((dot(&r.t[i], &r.t[j]) - expected).abs() < 1e-14);
            }
        }
        // U = Tᵀ U' with the fixed values and any free ones satisfies every condition
        let mut primed = [0.0, 0.0, 0.0, 0.3, -1.2, 0.7];
        primed[..3].copy_from_slice(&r.values[..3]);
        let u: [f64; 6] = std::array::from_fn(|k| (0..6).map(|j| r.t[j][k] * primed[j]).sum());
        for (row, value) in &conditions {
            assert!((dot(row, &u) - value).abs() < 1e-14, "{row:?}");
        }
        // no mixing of derivative orders
        for row in &r.t {
            let orders = [&row[..1], &row[1..3], &row[3..]];
            let used = orders
                .iter()
                .filter(|o| o.iter().any(|x| x.abs() > 1e-15))
                .count();
            assert_eq!(used, 1, "{row:?}");
        }
        let contradiction = [
            ([0.0, c, s, 0.0, 0.0, 0.0], 1.0),
            ([0.0, -c, -s, 0.0, 0.0, 0.0], 1.0),
        ];
        assert!(resolve_group(6, &contradiction).is_err());
    }

    /// `transform_matrix` agrees with the dense `T K Tᵀ`, and the vector maps are
    /// inverse to each other.
    #[test]
    fn the_congruence_is_the_dense_product() {
        let (c, s) = (0.6f64, 0.8f64);
        let mut r = rotation(&[([0.0, c, s, 0.0, 0.0, 0.0], 0.0)]);
        r.group = DofGroup::vertex(2);
        let basis = ChangeOfBasis::new(vec![r.clone()]);
        let n = 9;
        let dense: Vec<Vec<f64>> = (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| {
                        if (i + 2 * j) % 3 == 0 {
                            1.0 + (i * j) as f64
                        } else {
                            0.0
                        }
                    })
                    .collect()
            })
            .collect();
        let triplets: Vec<Triplet<usize, usize, f64>> = (0..n)
            .flat_map(|i| (0..n).map(move |j| (i, j)))
            .filter(|&(i, j)| dense[i][j] != 0.0)
            .map(|(i, j)| Triplet::new(i, j, dense[i][j]))
            .collect();
        let k = SparseColMat::try_new_from_triplets(n, n, &triplets).unwrap();
        let primed = basis.transform_matrix(&k).unwrap();
        let mut t = vec![vec![0.0; n]; n];
        for (i, row) in t.iter_mut().enumerate() {
            row[i] = 1.0;
        }
        for i in 0..6 {
            for j in 0..6 {
                t[2 + i][2 + j] = r.t[i][j];
            }
        }
        for i in 0..n {
            for j in 0..n {
                let expected: f64 = (0..n)
                    .flat_map(|a| (0..n).map(move |b| (a, b)))
                    .map(|(a, b)| t[i][a] * dense[a][b] * t[j][b])
                    .sum();
                let got = primed.get(i, j).copied().unwrap_or(0.0);
                assert!(
                    (got - expected).abs() < 1e-12,
                    "({i}, {j}): {got} {expected}"
                );
            }
        }
        let x: Vec<f64> = (0..n).map(|i| (i as f64).sin()).collect();
        let mut y = x.clone();
        basis.to_primed(&mut y);
        basis.to_cartesian(&mut y);
        for (a, b) in x.iter().zip(&y) {
            assert!((a - b).abs() < 1e-15);
        }
    }
}
