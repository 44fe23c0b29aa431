//! Semismooth Newton on the eliminated function Φ (docs/mathematics.md §5): the
//! Hessian's pattern and symbolic factorization computed once, an Armijo line search on
//! Φ so it cannot cycle, Gauss–Seidel first steps on prolonged starts, and low-rank
//! (Woodbury) updates of the last factor when few cells flipped.

use super::*;

impl Lcp {
    /// Newton's Hessian of Φ at `u` (length `n`) and the number of active constraints:
    /// `A + Bᵀ H B` with `H` the inverse of `C` on each block's active face
    /// (docs/mathematics.md §5; `A + Σ_{k active} b_k b_kᵀ / c_k` for a diagonal `C`),
    /// the `n × n` matrix each Newton step solves, e.g. for a multigrid preconditioner.
    ///
    /// # Errors
    /// [`Error::Input`] for shapes that do not fit or a `u` of another length.
    pub fn newton_hessian(&self, u: &[f64]) -> Result<(SparseMatrix, usize)> {
        self.check_shapes()?;
        if u.len() != self.n() {
            return Err(Error::Input(format!(
                "U has {} entries for an LCP of {} primal unknowns",
                u.len(),
                self.n()
            )));
        }
        let (_, active) = self.eliminate(&self.b_times(u));
        let count = active.iter().filter(|&&a| a).count();
        Ok((Hessian::new(self)?.matrix(self, &active), count))
    }

    /// `‖d‖∞ / ‖U‖∞` for the Newton step `d = −H⁻¹∇Φ(U)` at `U`: a forward-error
    /// certificate. The backward error alone cannot certify `U` when `A` is as badly
    /// conditioned as a thin beam's (κ ~ 1e13: a backward error of 1e-11 allows an O(1)
    /// error), and the eliminated Λ loses digits to cancellation when `C ~ αh⁵`; the
    /// step is damped by the `BᵀHB` part of the Hessian and has neither problem. Needs
    /// `C` positive definite.
    pub fn newton_correction(&self, u: &[f64]) -> Result<f64> {
        self.check_shapes()?;
        self.require_positive_c("the Newton correction")?;
        if u.len() != self.n() {
            return Err(Error::Input(format!(
                "U has {} entries, the problem {}",
                u.len(),
                self.n()
            )));
        }
        let hessian = Hessian::new(self)?;
        let bu = self.b_times(u);
        let (lambda, active) = self.eliminate(&bu);
        let au = multiply(&self.a, u);
        let btl = self.bt_times(&lambda);
        let minus_gradient: Vec<f64> = (0..self.n()).map(|i| self.f[i] + btl[i] - au[i]).collect();
        let h = hessian.matrix(self, &active);
        let d = Cholesky::analyse(&hessian.symbolic)?
            .factor(&h)?
            .solve_refined(&h, &minus_gradient, 2)?;
        let norm = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        // Relative to the size U has or should have: U ≡ 0 is a legitimate solution
        // (a membrane pressed flat onto ψ = 0), where ‖U‖ alone would make any rounding
        // of the step look like an O(1) correction.
        let corrected: Vec<f64> = u.iter().zip(&d).map(|(u, d)| u + d).collect();
        let scale = norm(u)
            .max(norm(&corrected))
            .max(norm(&self.f) / row_sum_norm(&self.a).max(f64::MIN_POSITIVE));
        Ok(norm(&d) / scale.max(f64::MIN_POSITIVE))
    }
}

/// Options of the semismooth Newton method.
#[derive(Clone, Copy, Debug)]
pub struct NewtonOptions {
    /// Iteration limit (an error beyond it).
    pub max_iterations: usize,
    /// Rounds of iterative refinement of each linear solve (thin structures need 1–2).
    pub refinement_steps: usize,
    /// KKT residual accepted at convergence.
    pub tolerance: f64,
    /// From a given start (nested iteration): sweeps of symmetric Gauss–Seidel on the
    /// first Newton system instead of its factorization (0: factor every step).
    ///
    /// A start prolonged from a coarser mesh is off mostly near the free boundary, by
    /// mesh-size detail that a few sweeps resolve; the first exact step would spend a
    /// whole factorization on it. Measured on the membrane at 524k triangles: 8 sweeps
    /// (0.04 s) lead to the same contact set as the exact step (0.23 s), and Newton ends
    /// after 2 factorizations instead of 3. The direction is a descent direction of Φ
    /// (the sweeps apply an SPD approximate inverse), so the line search and the
    /// convergence test stay as they are; convergence is only declared after exact steps.
    pub smoothing_sweeps: usize,
    /// Solve a step through a low-rank update of the last factorization
    /// ([`crate::lcp::woodbury`]) when few constraints changed their face since it and that
    /// is estimated cheaper than factoring anew; the step is checked by its residual and
    /// factored anew if that is not at rounding level.
    ///
    /// On the membrane at 524k triangles the last exact step flips ~60 cells: the update
    /// costs 0.05 s against 0.23 s for a factorization and its solve.
    pub low_rank_updates: bool,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        Self {
            max_iterations: 200,
            refinement_steps: 1,
            tolerance: 1e-10,
            smoothing_sweeps: 0,
            low_rank_updates: true,
        }
    }
}

/// A sparsity pattern built from the pattern of `A` in the leading block plus extra
/// entries, with the lookup of each entry's position in the value array.
pub(super) struct Pattern {
    pub(super) ptr: Vec<usize>,
    pub(super) idx: Vec<usize>,
}

impl Pattern {
    /// `A`'s pattern in a `size × size` matrix, then `extra(&mut columns)` adds entries.
    pub(super) fn new(
        a: &SparseMatrix,
        size: usize,
        extra: impl FnOnce(&mut [Vec<usize>]),
    ) -> Self {
        let (col_ptr, rows) = (a.symbolic().col_ptr(), a.symbolic().row_idx());
        let mut columns: Vec<Vec<usize>> = vec![Vec::new(); size];
        for (j, column) in columns.iter_mut().enumerate().take(a.ncols()) {
            column.extend_from_slice(&rows[col_ptr[j]..col_ptr[j + 1]]);
        }
        extra(&mut columns);
        let mut ptr = vec![0usize; size + 1];
        let mut idx = Vec::new();
        for (j, column) in columns.iter_mut().enumerate() {
            column.sort_unstable();
            column.dedup();
            idx.extend_from_slice(column);
            ptr[j + 1] = idx.len();
        }
        Self { ptr, idx }
    }

    /// `A`'s own pattern (`size ≥` A's order; the extra columns are empty).
    pub(super) fn of(a: &SparseMatrix, size: usize) -> Self {
        let (col_ptr, rows) = (a.symbolic().col_ptr(), a.symbolic().row_idx());
        let mut ptr = col_ptr.to_vec();
        ptr.resize(size + 1, rows.len());
        Self {
            ptr,
            idx: rows.to_vec(),
        }
    }

    /// Position of entry `(i, j)`, if it is in the pattern.
    pub(super) fn find(&self, i: usize, j: usize) -> Option<usize> {
        self.idx[self.ptr[j]..self.ptr[j + 1]]
            .binary_search(&i)
            .ok()
            .map(|k| self.ptr[j] + k)
    }

    /// Position of entry `(i, j)` (it must be in the pattern).
    pub(super) fn position(&self, i: usize, j: usize) -> usize {
        let column = &self.idx[self.ptr[j]..self.ptr[j + 1]];
        self.ptr[j]
            + column
                .binary_search(&i)
                .expect("the entry is in the pattern")
    }

    /// Positions of `A`'s entries, in `A`'s storage order.
    pub(super) fn positions_of(&self, a: &SparseMatrix) -> Vec<usize> {
        let (col_ptr, rows) = (a.symbolic().col_ptr(), a.symbolic().row_idx());
        (0..a.ncols())
            .flat_map(|j| {
                rows[col_ptr[j]..col_ptr[j + 1]]
                    .iter()
                    .map(move |&i| (i, j))
            })
            .map(|(i, j)| self.position(i, j))
            .collect()
    }

    pub(super) fn symbolic(self) -> SymbolicSparseColMat<usize> {
        let size = self.ptr.len() - 1;
        SymbolicSparseColMat::new_checked(size, size, self.ptr, None, self.idx)
    }
}

/// A value array for `pattern` holding `A`'s entries at `positions` and zeros elsewhere.
pub(super) fn values_of_a(
    pattern: &SymbolicSparseColMat<usize>,
    positions: &[usize],
    a: &SparseMatrix,
) -> Vec<f64> {
    let mut values = vec![0.0; pattern.row_idx().len()];
    for (&p, &v) in positions.iter().zip(a.val()) {
        values[p] += v;
    }
    values
}

/// The Hessian `A + Bᵀ H B` of Φ, `H = blockdiag(P_I C_II⁻¹ P_Iᵀ)` on each block's face
/// I, with a fixed pattern: the union over all faces, i.e. the rows of a whole block
/// coupled.
pub(super) struct Hessian {
    pub(super) symbolic: SymbolicSparseColMat<usize>,
    /// Where `A`'s entries go (`None`: `A`'s own pattern is the Hessian's).
    pub(super) a_positions: Option<Vec<usize>>,
    /// For each entry of `B` (in [`ConstraintRows::entries`] order), the index of its
    /// column in its block's column set J.
    pub(super) entry_local: Vec<u32>,
    /// Block `b`'s column count `|J|` is `widths[b]`; the value positions of its `J × J`
    /// (i-major) are `positions[position_ptr[b]..position_ptr[b + 1]]`.
    ///
    /// These three hold 32-bit indices ([`Hessian::new`] refuses a Hessian of more
    /// entries): at 2M P1–P0 cells, 9 positions and 3 local indices per cell were 190 MB
    /// as `usize`, built on the thread that bounds the finest level's setup.
    pub(super) widths: Vec<u32>,
    pub(super) position_ptr: Vec<usize>,
    pub(super) positions: Vec<u32>,
}

impl Hessian {
    /// # Errors
    /// [`Error::Input`] for a Hessian of more than `u32::MAX` entries.
    pub(super) fn new(lcp: &Lcp) -> Result<Self> {
        // Each block's column set J, flat (a block of size 1 is one row of B).
        let mut column_ptr = Vec::with_capacity(lcp.m() + 1);
        column_ptr.push(0);
        let mut columns: Vec<usize> = Vec::with_capacity(lcp.b_rows.entries().len());
        for block in lcp.blocks() {
            let from = columns.len();
            for k in block.range() {
                columns.extend(lcp.b_rows[k].iter().map(|&(j, _)| j));
            }
            let set = &mut columns[from..];
            set.sort_unstable();
            let mut kept = 0;
            for i in 0..set.len() {
                if i == 0 || set[i] != set[kept - 1] {
                    set[kept] = set[i];
                    kept += 1;
                }
            }
            columns.truncate(from + kept);
            column_ptr.push(columns.len());
        }
        let block_count = column_ptr.len() - 1;
        let block_columns = |b: usize| &columns[column_ptr[b]..column_ptr[b + 1]];
        let positions_in = |pattern: &Pattern| -> Option<(Vec<usize>, Vec<u32>)> {
            let mut ptr = Vec::with_capacity(block_count + 1);
            ptr.push(0);
            // sized ahead: growing it by doubling cost half of this loop at 524k cells
            let total = (0..block_count)
                .map(|b| block_columns(b).len().pow(2))
                .sum();
            let mut positions = Vec::with_capacity(total);
            for b in 0..block_count {
                let set = block_columns(b);
                for &i in set {
                    for &j in set {
                        // in range: `fits` below checked the pattern's size
                        positions.push(pattern.find(i, j)? as u32);
                    }
                }
                ptr.push(positions.len());
            }
            Some((ptr, positions))
        };
        // Finite element couplings usually lie inside A's pattern already (a cell's B
        // row touches the cell's own DOFs): then A's pattern is the Hessian's, and the
        // union, the costliest part of the setup, is skipped.
        let fits = |pattern: &Pattern| {
            if pattern.idx.len() > u32::MAX as usize {
                return Err(Error::Input(format!(
                    "the Newton Hessian has {} entries, beyond the 32-bit positions of its assembly ({})",
                    pattern.idx.len(),
                    u32::MAX
                )));
            }
            Ok(())
        };
        let own = Pattern::of(&lcp.a, lcp.n());
        fits(&own)?;
        let (pattern, a_positions, (position_ptr, positions)) = match positions_in(&own) {
            Some(found) => (own, None, found),
            None => {
                let pattern = Pattern::new(&lcp.a, lcp.n(), |pattern_columns| {
                    for b in 0..block_count {
                        let set = block_columns(b);
                        for &i in set {
                            for &j in set {
                                pattern_columns[j].push(i);
                            }
                        }
                    }
                });
                fits(&pattern)?;
                let found = positions_in(&pattern).expect("the union holds every block");
                let a_positions = pattern.positions_of(&lcp.a);
                (pattern, Some(a_positions), found)
            }
        };
        let mut entry_local = Vec::with_capacity(lcp.b_rows.entries().len());
        for (b, block) in lcp.blocks().enumerate() {
            let set = block_columns(b);
            for k in block.range() {
                // below `u32::MAX`: a block's columns are entries of the Hessian's pattern
                entry_local.extend(lcp.b_rows[k].iter().map(|&(j, _)| {
                    set.binary_search(&j)
                        .expect("the block's columns hold its rows' columns")
                        as u32
                }));
            }
        }
        // each at most `|J|` ≤ the Hessian's entry count, checked above
        let widths = (0..block_count)
            .map(|b| (column_ptr[b + 1] - column_ptr[b]) as u32)
            .collect();
        Ok(Self {
            symbolic: pattern.symbolic(),
            a_positions,
            entry_local,
            widths,
            position_ptr,
            positions,
        })
    }

    /// The Hessian on the faces `active` (per constraint, from [`Lcp::eliminate`]).
    pub(super) fn matrix(&self, lcp: &Lcp, active: &[bool]) -> SparseMatrix {
        let mut values = match &self.a_positions {
            None => lcp.a.val().to_vec(),
            Some(positions) => values_of_a(&self.symbolic, positions, &lcp.a),
        };
        let offsets = lcp.b_rows.offsets();
        let entries = lcp.b_rows.entries();
        let mut inverse = [0.0; BLOCK_ENTRIES];
        let mut face = [0usize; MAX_BLOCK];
        let diagonal = lcp.c_blocks.is_empty();
        for (b, block) in lcp.blocks().enumerate() {
            if diagonal && !active[b] {
                // the common case, decided without the face machinery
                continue;
            }
            let q = lcp.face_inverse(&block, active, &mut face, &mut inverse);
            if q == 0 {
                continue;
            }
            let width = self.widths[b] as usize;
            let positions = &self.positions[self.position_ptr[b]..self.position_ptr[b + 1]];
            for a in 0..q {
                let k = block.start + face[a];
                for c in 0..q {
                    let l = block.start + face[c];
                    let w = inverse[a * q + c];
                    let (row_k, row_l) = (offsets[k]..offsets[k + 1], offsets[l]..offsets[l + 1]);
                    let local_l = &self.entry_local[row_l.clone()];
                    for (&(_, vk), &ik) in
                        entries[row_k.clone()].iter().zip(&self.entry_local[row_k])
                    {
                        for (&(_, vl), &il) in entries[row_l.clone()].iter().zip(local_l) {
                            values[positions[ik as usize * width + il as usize] as usize] +=
                                w * vk * vl;
                        }
                    }
                }
            }
        }
        SparseColMat::new(self.symbolic.clone(), values)
    }
}

impl Lcp {
    /// The active face `I` of `block` under `active` (per constraint) into `face` (indices
    /// within the block) and `C_II⁻¹` into `inverse` (`q × q` row-major); returns `q`,
    /// 0 when the face is empty or `C_II` is not SPD (the solvers reject such a `C`
    /// before they get here).
    pub(super) fn face_inverse(
        &self,
        block: &Block,
        active: &[bool],
        face: &mut [usize; MAX_BLOCK],
        inverse: &mut [f64; BLOCK_ENTRIES],
    ) -> usize {
        let q = block.range().filter(|&k| active[k]).fold(0, |q, k| {
            face[q] = k - block.start;
            q + 1
        });
        if q == 0 {
            return 0;
        }
        if block.size == 1 {
            inverse[0] = 1.0 / self.c[block.start];
            return 1;
        }
        let mut dense = [0.0; BLOCK_ENTRIES];
        block.face(&self.c, &face[..q], &mut dense[..q * q]);
        if small_inverse(&dense, q, inverse) {
            q
        } else {
            0
        }
    }

    /// `H(active) − H(previous)` of the Newton Hessian as `U S Uᵀ`: for each block whose
    /// face changed, its rows of `B` and the change of `P_I C_II⁻¹ P_Iᵀ`.
    pub(super) fn hessian_change(&self, previous: &[bool], active: &[bool]) -> Result<LowRankTerm> {
        let mut term = LowRankTerm::new();
        let mut face = [0usize; MAX_BLOCK];
        let mut inverse = [0.0; BLOCK_ENTRIES];
        for block in self.blocks() {
            let range = block.range();
            if previous[range.clone()] == active[range.clone()] {
                continue;
            }
            let s = block.size;
            let mut change = [0.0; BLOCK_ENTRIES];
            for (sign, flags) in [(1.0, active), (-1.0, previous)] {
                let q = self.face_inverse(&block, flags, &mut face, &mut inverse);
                for a in 0..q {
                    for c in 0..q {
                        change[face[a] * s + face[c]] += sign * inverse[a * q + c];
                    }
                }
            }
            term.push_block(range.map(|k| &self.b_rows[k]), &change[..s * s])?;
        }
        Ok(term)
    }

    /// An error unless every block of `C` is positive definite (Φ and the elimination of
    /// Λ need it).
    pub(super) fn require_positive_c(&self, method: &str) -> Result<()> {
        let mut dense = [0.0; BLOCK_ENTRIES];
        for block in self.blocks() {
            let k = block.start;
            if block.size == 1 {
                if self.c[k].is_nan() || self.c[k] <= 0.0 {
                    return Err(Error::Input(format!(
                        "{method} needs C > 0 (it uses Φ and Λ = C⁻¹(G − BU)₊); C_{k} = {}: {}",
                        self.c[k],
                        c_fault(self.c[k])
                    )));
                }
                continue;
            }
            let s = block.size;
            block.dense(&self.c, &mut dense[..s * s]);
            if !small_cholesky(&mut dense, s) {
                return Err(Error::Input(format!(
                    "{method} needs C positive definite (it uses Φ and the eliminated Λ); its block of constraints {k} to {} is not: {}",
                    k + s - 1,
                    // the block's diagonal says which sign it has
                    c_fault((0..s).map(|i| block.entry(&self.c, i, i)).fold(f64::INFINITY, f64::min))
                )));
            }
        }
        Ok(())
    }

    /// The start vector, or zero.
    pub(super) fn start_vector(&self, start: Option<&[f64]>) -> Result<Vec<f64>> {
        match start {
            Some(s) if s.len() == self.n() => Ok(s.to_vec()),
            Some(s) => Err(Error::Input(format!(
                "start vector has {} entries, the problem {}",
                s.len(),
                self.n()
            ))),
            None => Ok(vec![0.0; self.n()]),
        }
    }

    /// The eliminated multiplier from `bu = BU`: per block of `C`,
    /// `Λ_b = argmin_{Λ≥0} ½ΛᵀC_bΛ − Λᵀ(G − BU)_b` (for a block of size 1,
    /// `Λ_k = (G − BU)₊,k / C_k`). Needs `C` positive definite.
    pub fn eliminated_multiplier(&self, bu: &[f64]) -> Vec<f64> {
        self.eliminate(bu).0
    }

    /// The eliminated multiplier and, per constraint, whether it is on its block's
    /// active face (the constraints Newton's Hessian includes).
    pub(super) fn eliminate(&self, bu: &[f64]) -> (Vec<f64>, Vec<bool>) {
        let m = self.m();
        let mut lambda = vec![0.0; m];
        let mut active = vec![false; m];
        if self.c_blocks.is_empty() {
            // diagonal C: the size-1 formulas in one pass, as [`Lcp::penalty`]
            for (k, (lambda, active)) in lambda.iter_mut().zip(&mut active).enumerate() {
                (*lambda, *active) = single_multiplier(self.g[k] - bu[k], self.c[k]);
            }
            return (lambda, active);
        }
        let mut dense = [0.0; BLOCK_ENTRIES];
        let mut r = [0.0; MAX_BLOCK];
        for block in self.blocks() {
            let range = block.range();
            self.block_multiplier(
                &block,
                bu,
                &mut dense,
                &mut r,
                &mut lambda[range.clone()],
                &mut active[range],
            );
        }
        (lambda, active)
    }

    /// One block's eliminated multiplier from `bu = BU`: fills `dense` with `C_b`
    /// (`s × s`), `r` with `(G − BU)_b`, and `lambda`, `active` with `Λ_b` and its
    /// active face.
    pub(super) fn block_multiplier(
        &self,
        block: &Block,
        bu: &[f64],
        dense: &mut [f64],
        r: &mut [f64],
        lambda: &mut [f64],
        active: &mut [bool],
    ) {
        let (k, s) = (block.start, block.size);
        for (i, r) in r[..s].iter_mut().enumerate() {
            *r = self.g[k + i] - bu[k + i];
        }
        if s == 1 {
            dense[0] = self.c[k];
            (lambda[0], active[0]) = single_multiplier(r[0], self.c[k]);
            return;
        }
        block.dense(&self.c, &mut dense[..s * s]);
        block_minimizer(
            &dense[..s * s],
            s,
            &r[..s],
            &mut lambda[..s],
            &mut active[..s],
        );
    }

    /// The merit function `Φ(U) = ½UᵀAU − FᵀU + Σ_b max_{Λ≥0}(Λᵀr_b − ½ΛᵀC_bΛ)`,
    /// `r = G − BU` (for P0: `½Σ_k (G − BU)²₊,k / C_k`), from `au = AU`, `bu = BU`.
    pub fn merit(&self, u: &[f64], au: &[f64], bu: &[f64]) -> f64 {
        let quadratic: f64 = u
            .iter()
            .zip(au)
            .zip(&self.f)
            .map(|((u, au), f)| 0.5 * u * au - f * u)
            .sum();
        quadratic + self.penalty(bu)
    }

    /// The constraint part of [`Lcp::merit`] from `bu = BU`.
    pub(super) fn penalty(&self, bu: &[f64]) -> f64 {
        if self.c_blocks.is_empty() {
            // diagonal C: the closed form in one vectorizable pass; the general per-block
            // code cost 10 ms per pass at 524k cells, and the line search evaluates this
            // for every trial
            return self
                .g
                .iter()
                .zip(bu)
                .zip(&self.c)
                .map(|((g, bu), c)| single_penalty(g - bu, *c))
                .sum();
        }
        let mut dense = [0.0; BLOCK_ENTRIES];
        let mut r = [0.0; MAX_BLOCK];
        let mut lambda = [0.0; MAX_BLOCK];
        let mut active = [false; MAX_BLOCK];
        self.blocks()
            .map(|block| {
                let k = block.start;
                if block.size == 1 {
                    // the closed form, cheaper than the general one in the line search
                    return single_penalty(self.g[k] - bu[k], self.c[k]);
                }
                let s = block.size;
                self.block_multiplier(&block, bu, &mut dense, &mut r, &mut lambda, &mut active);
                (0..s)
                    .map(|i| {
                        let c_lambda: f64 = (0..s).map(|j| dense[i * s + j] * lambda[j]).sum();
                        lambda[i] * (r[i] - 0.5 * c_lambda)
                    })
                    .sum::<f64>()
            })
            .sum()
    }

    /// Armijo backtracking on Φ from `u` along `d` (`slope = ∇Φ·d`); Φ is re-evaluated from
    /// the products `AU, Ad, BU, Bd`, so each trial is cheap. The accepted step, if any.
    pub(super) fn armijo(
        &self,
        u: &[f64],
        au: &[f64],
        bu: &[f64],
        d: &[f64],
        slope: f64,
    ) -> Option<f64> {
        let ad = multiply(&self.a, d);
        let bd = self.b_times(d);
        let phi0 = self.merit(u, au, bu);
        let mut step = 1.0;
        for _ in 0..60 {
            let ut: Vec<f64> = u.iter().zip(d).map(|(u, d)| u + step * d).collect();
            let aut: Vec<f64> = au.iter().zip(&ad).map(|(a, b)| a + step * b).collect();
            let but: Vec<f64> = bu.iter().zip(&bd).map(|(a, b)| a + step * b).collect();
            // the last term forgives rounding in Φ itself
            if self.merit(&ut, &aut, &but)
                <= phi0 + 1e-4 * step * slope.min(0.0) + 1e-14 * phi0.abs()
            {
                return Some(step);
            }
            step *= 0.5;
        }
        None
    }
}

/// A constraint alone in its block of `C` (`c > 0`) with `r = G − BU`: its eliminated
/// multiplier `r₊ / c` and whether it is active.
#[inline]
pub(super) fn single_multiplier(r: f64, c: f64) -> (f64, bool) {
    (r.max(0.0) / c, r > 0.0)
}

/// Its share of the merit: `max_{λ≥0} (λr − ½cλ²) = ½ r₊² / c`.
#[inline]
pub(super) fn single_penalty(r: f64, c: f64) -> f64 {
    let r = r.max(0.0);
    0.5 * r * r / c
}

pub(super) fn max_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// What semismooth Newton needs before its first iteration and that depends only on the
/// LCP's sparsity: the Hessian's pattern and its symbolic Cholesky factorization (the
/// ordering). Built apart from the iteration so that it can be prepared on another
/// thread while a coarser level is solved (see [`crate::obstacle::solve_nested`]); the
/// symbolic factorization may even be left to finish there while Newton's first,
/// smoothed step, which needs only the pattern, runs.
pub struct NewtonWorkspace {
    hessian: Hessian,
    /// Filled by [`NewtonWorkspace::analyse`], from whichever thread asks first (the
    /// others wait for it). The error is kept as text: [`Error`] is not `Clone`.
    cholesky: OnceLock<std::result::Result<Cholesky, String>>,
    /// `(n, m)` of the LCP it was built for.
    shape: (usize, usize),
}

impl NewtonWorkspace {
    /// The Hessian pattern and symbolic factorization of `lcp`.
    pub fn new(lcp: &Lcp) -> Result<Self> {
        let workspace = Self::pattern_of(lcp)?;
        workspace.analyse()?;
        Ok(workspace)
    }

    /// The Hessian pattern of `lcp` only; the symbolic factorization follows from
    /// [`NewtonWorkspace::analyse`], called ahead (on another thread) or by Newton
    /// itself when it first factors.
    pub fn pattern_of(lcp: &Lcp) -> Result<Self> {
        lcp.check_shapes()?;
        Ok(Self {
            hessian: Hessian::new(lcp)?,
            cholesky: OnceLock::new(),
            shape: (lcp.n(), lcp.m()),
        })
    }

    /// The symbolic Cholesky factorization of the Hessian pattern, computed on the first
    /// call; a call while another thread computes it waits for that one.
    pub fn analyse(&self) -> Result<&Cholesky> {
        self.cholesky
            .get_or_init(|| {
                Cholesky::analyse(&self.hessian.symbolic).map_err(|e| match e {
                    Error::LinearSolve(message) => message,
                    other => other.to_string(),
                })
            })
            .as_ref()
            .map_err(|e| Error::LinearSolve(e.clone()))
    }
}

/// Semismooth Newton (primal–dual active set) on Φ with an Armijo line search, from
/// `start` (e.g. the prolonged solution of a coarser mesh) or from zero.
pub fn semismooth_newton(
    lcp: &Lcp,
    start: Option<&[f64]>,
    options: NewtonOptions,
) -> Result<LcpSolution> {
    lcp.check_shapes()?;
    lcp.require_positive_c("semismooth Newton")?;
    // the symbolic factorization follows when Newton first factors
    semismooth_newton_prepared(lcp, &NewtonWorkspace::pattern_of(lcp)?, start, options)
}

/// [`semismooth_newton`] with the pattern work done ahead in `workspace` (built by
/// [`NewtonWorkspace::new`] for this `lcp`).
pub fn semismooth_newton_prepared(
    lcp: &Lcp,
    workspace: &NewtonWorkspace,
    start: Option<&[f64]>,
    options: NewtonOptions,
) -> Result<LcpSolution> {
    let clock = Instant::now();
    lcp.check_shapes()?;
    lcp.require_positive_c("semismooth Newton")?;
    if workspace.shape != (lcp.n(), lcp.m()) {
        return Err(Error::Input(format!(
            "the Newton workspace was built for an LCP with {:?} (primal, constraint) unknowns, this one has {:?}",
            workspace.shape,
            (lcp.n(), lcp.m())
        )));
    }
    newton_iteration(lcp, workspace, None, start, options, clock)
}

/// One Newton system `H d = b` handed to a [`StepSolver`].
#[derive(Clone, Copy, Debug)]
pub struct NewtonStep<'a> {
    /// The Hessian `H` (the pattern is the same at every step of one solve).
    pub hessian: &'a SparseMatrix,
    /// `b = −∇Φ`.
    pub rhs: &'a [f64],
    /// The active constraints `H` includes (per constraint, as [`Lcp::hessian_change_blocks`]
    /// takes them), so that a solver can update what it built for an earlier step.
    pub active: &'a [bool],
    /// Whether the active set is that of the previous full step: Newton is then in its
    /// final phase, where a step solved loosely costs iterations. Before that a
    /// moderately inexact step can do (`docs/multigrid.md` measures how inexact);
    /// Newton's KKT test certifies the result either way.
    pub settled: bool,
    /// The size of the terms the gradient balances, `max(‖AU‖₂, ‖F‖₂, ‖BᵀΛ‖₂)`: the
    /// gradient itself is computed to about `1e-16` of it, so a step's residual far
    /// below that is rounding (an iterative solver may stop at a small multiple of it).
    pub scale: f64,
}

/// A solver of the Newton systems `H d = b` other than the factorization (e.g. multigrid
/// preconditioned CG, [`crate::obstacle`]): `Some((d, exact))` when it solved the system,
/// `exact` when to the accuracy of a factored step, otherwise a descent direction solved
/// loosely (see [`NewtonStep::settled`]); `None` to have the step factored instead. Newton
/// declares convergence only after an exact step, so that an inexact one never decides
/// the answer. The solver may keep state from step to step (a multigrid hierarchy
/// updated by the flipped constraints).
pub type StepSolver<'a> = &'a mut dyn FnMut(NewtonStep<'_>) -> Option<(Vec<f64>, bool)>;

impl Lcp {
    /// The change `H(active) − H(previous)` of Newton's Hessian, block by block: for each
    /// block of constraints whose active face differs, `visit(rows, change)` with its rows
    /// of `B` (sparse, `(column, value)`) and the `s × s` change (row-major, `s` the block
    /// size, symmetric) of `P_I C_II⁻¹ P_Iᵀ`, so that the change is `Σ Bᵦᵀ change Bᵦ`
    /// over the visited blocks (docs/mathematics.md §5). With `previous` all false it is
    /// the whole active part `Bᵀ H_I B` of the Hessian.
    ///
    /// # Errors
    /// [`Error::Input`] when `previous` or `active` is not of length `m`; `visit`'s error,
    /// which ends the visit.
    pub fn hessian_change_blocks(
        &self,
        previous: &[bool],
        active: &[bool],
        mut visit: impl FnMut(&[&[(usize, f64)]], &[f64]) -> Result<()>,
    ) -> Result<()> {
        if previous.len() != self.m() || active.len() != self.m() {
            return Err(Error::Input(format!(
                "active sets of {} and {} constraints for an LCP of {}",
                previous.len(),
                active.len(),
                self.m()
            )));
        }
        let mut face = [0usize; MAX_BLOCK];
        let mut inverse = [0.0; BLOCK_ENTRIES];
        let mut rows: [&[(usize, f64)]; MAX_BLOCK] = [&[]; MAX_BLOCK];
        for block in self.blocks() {
            let range = block.range();
            if previous[range.clone()] == active[range.clone()] {
                continue;
            }
            let s = block.size;
            let mut change = [0.0; BLOCK_ENTRIES];
            for (sign, flags) in [(1.0, active), (-1.0, previous)] {
                let q = self.face_inverse(&block, flags, &mut face, &mut inverse);
                for a in 0..q {
                    for c in 0..q {
                        change[face[a] * s + face[c]] += sign * inverse[a * q + c];
                    }
                }
            }
            for (row, k) in rows.iter_mut().zip(range) {
                *row = &self.b_rows[k];
            }
            visit(&rows[..s], &change[..s * s])?;
        }
        Ok(())
    }
}

/// [`semismooth_newton_prepared`] with the exact steps solved by `step` (each step it
/// declines is factored as usual and counted in [`LcpSolution::factorizations`]).
/// Newton's convergence test is unchanged: the KKT residual certifies the result.
///
/// # Errors
/// Those of [`semismooth_newton_prepared`].
pub fn semismooth_newton_with(
    lcp: &Lcp,
    workspace: &NewtonWorkspace,
    step: StepSolver,
    start: Option<&[f64]>,
    options: NewtonOptions,
) -> Result<LcpSolution> {
    let clock = Instant::now();
    lcp.check_shapes()?;
    lcp.require_positive_c("semismooth Newton")?;
    if workspace.shape != (lcp.n(), lcp.m()) {
        return Err(Error::Input(format!(
            "the Newton workspace was built for an LCP with {:?} (primal, constraint) unknowns, this one has {:?}",
            workspace.shape,
            (lcp.n(), lcp.m())
        )));
    }
    newton_iteration(lcp, workspace, Some(step), start, options, clock)
}

pub(super) fn newton_iteration(
    lcp: &Lcp,
    workspace: &NewtonWorkspace,
    mut step_solver: Option<StepSolver>,
    start: Option<&[f64]>,
    options: NewtonOptions,
    clock: Instant,
) -> Result<LcpSolution> {
    let n = lcp.n();
    let mut u = lcp.start_vector(start)?;
    let hessian = &workspace.hessian;
    let mut solves = StepCounts::default();
    let done =
        |u: Vec<f64>, lambda: Vec<f64>, iterations: usize, residual: f64, solves: StepCounts| {
            let multiplier_noise = lcp.elimination_noise(&lambda);
            LcpSolution {
                u,
                lambda,
                iterations,
                kkt_residual: residual,
                seconds: clock.elapsed().as_secs_f64(),
                factorizations: solves.factorizations,
                low_rank_updates: solves.low_rank_updates,
                multiplier_noise,
                iterative_steps: solves.iterative_steps,
                krylov_iterations: 0,
            }
        };
    let mut smooth_first = start.is_some() && options.smoothing_sweeps > 0;
    let mut last_exact = true;
    let mut previous_active: Option<Vec<bool>> = None;
    // the last factored Hessian and its faces, for low-rank updates
    let mut factored: Option<(CholeskyFactor, Vec<bool>)> = None;
    let mut seen_faces = std::collections::HashSet::new();
    // the iterate after a full exact step with the smallest KKT residual
    let mut best: Option<(Vec<f64>, Vec<f64>, f64)> = None;
    let scales = lcp.kkt_scales();
    for iteration in 1..=options.max_iterations {
        let au = multiply(&lcp.a, &u);
        let bu = lcp.b_times(&u);
        let (lambda, active) = lcp.eliminate(&bu);
        let btl = lcp.bt_times(&lambda);
        let residual_here = || lcp.kkt_residual_from(&u, &lambda, &au, &btl, &scales);
        // Converged: the active faces did not change over a full exact step, so u is the
        // exact minimizer of the quadratic that Φ is on these faces.
        if last_exact && previous_active.as_ref() == Some(&active) {
            let residual = residual_here();
            if residual <= options.tolerance {
                return Ok(done(u, lambda, iteration - 1, residual, solves));
            }
        }
        // Cycling: after full exact steps the faces come back to a set seen before. On
        // ill-conditioned systems (Hermite beams at 20000 elements, κ ~ h⁻⁴) constraints
        // whose λ and gap are both at rounding level flip forever while U stays put; the
        // KKT residual then certifies the point, and iterating on only ends in the
        // iteration limit with a point as good as this one.
        //
        // The best iterate serves only a run that reaches the iteration limit without
        // settling: it is tracked over the second half of the iterations. Tracking it
        // from the start cost a KKT residual and two vector copies per iteration (0.04 s
        // at 1M unknowns) in every run, where nested starts settle in 2–5 iterations.
        if previous_active.is_some() {
            let cycling = !seen_faces.insert(faces_fingerprint(&active));
            let tracked = iteration > options.max_iterations / 2;
            if (cycling && last_exact) || tracked {
                let residual = residual_here();
                if cycling && last_exact && residual <= options.tolerance {
                    return Ok(done(u, lambda, iteration - 1, residual, solves));
                }
                if tracked && best.as_ref().is_none_or(|b| residual < b.2) {
                    best = Some((u.clone(), lambda.clone(), residual));
                }
            }
        }
        let gradient: Vec<f64> = (0..n).map(|i| au[i] - lcp.f[i] - btl[i]).collect();
        let h = hessian.matrix(lcp, &active);
        let minus_gradient: Vec<f64> = gradient.iter().map(|g| -g).collect();
        let smoothed = if std::mem::take(&mut smooth_first) {
            symmetric_gauss_seidel(&h, &minus_gradient, options.smoothing_sweeps)
        } else {
            None
        };
        let full = smoothed.is_none();
        let (solved, solved_exact) = match (&smoothed, step_solver.as_mut()) {
            (None, Some(solve)) => match solve(NewtonStep {
                hessian: &h,
                rhs: &minus_gradient,
                active: &active,
                settled: previous_active.as_ref() == Some(&active),
                scale: [au.as_slice(), &lcp.f, &btl]
                    .into_iter()
                    .map(norm2)
                    .fold(0.0, f64::max),
            }) {
                Some((d, exact)) => (Some(d), exact),
                None => (None, true),
            },
            _ => (None, true),
        };
        let exact = full && solved_exact;
        solves.iterative_steps += usize::from(solved.is_some());
        let d = match smoothed.or(solved) {
            Some(d) => d,
            None => {
                let direct = DirectStep {
                    lcp,
                    workspace,
                    hessian: &h,
                    active: &active,
                    rhs: &minus_gradient,
                    options,
                };
                direct.solve(&mut factored, &mut solves)?
            }
        };
        let slope: f64 = gradient.iter().zip(&d).map(|(g, d)| g * d).sum();
        let Some(step) = lcp.armijo(&u, &au, &bu, &d, slope) else {
            // No decrease along a Newton direction: at the minimizer up to rounding.
            let residual = residual_here();
            if residual <= options.tolerance.max(1e-8) {
                return Ok(done(u, lambda, iteration, residual, solves));
            }
            return Err(Error::NotConverged {
                solver: "semismooth Newton",
                detail: format!(
                    "line search failed at iteration {iteration} with KKT residual {residual:e}"
                ),
            });
        };
        for (u, d) in u.iter_mut().zip(&d) {
            *u += step * d;
        }
        // A full step of rounding size: constraints whose gap CΛ is below the rounding
        // of G − BU (α h⁴ λ ≪ ε|ψ| on fine meshes) may flip forever without moving U.
        if exact && step == 1.0 && max_norm(&d) <= 1e-13 * max_norm(&u) {
            let lambda = lcp.eliminated_multiplier(&lcp.b_times(&u));
            let residual = lcp.kkt_residual(&u, &lambda);
            if residual <= options.tolerance {
                return Ok(done(u, lambda, iteration, residual, solves));
            }
        }
        // an inexact full step still tells whether the active set has settled
        previous_active = (full && step == 1.0).then_some(active);
        last_exact = exact;
    }
    // The active set never settled (constraints with λ and gap at rounding level flip
    // without end), but an iterate the KKT residual certifies is a solution all the same.
    if let Some((u, lambda, residual)) = best.filter(|b| b.2 <= options.tolerance) {
        return Ok(done(u, lambda, options.max_iterations, residual, solves));
    }
    let lambda = lcp.eliminated_multiplier(&lcp.b_times(&u));
    Err(Error::NotConverged {
        solver: "semismooth Newton",
        detail: format!(
            "{} iterations without a settled active set (KKT residual {:e})",
            options.max_iterations,
            lcp.kkt_residual(&u, &lambda)
        ),
    })
}

/// How the steps of a Newton solve were solved: factorizations of the Hessian, low-rank
/// updates of a factored one, and steps the caller's [`StepSolver`] solved.
#[derive(Clone, Copy, Debug, Default)]
struct StepCounts {
    factorizations: usize,
    low_rank_updates: usize,
    iterative_steps: usize,
}

/// A Newton step solved directly: `hessian d = rhs` on the faces `active`.
struct DirectStep<'a> {
    lcp: &'a Lcp,
    workspace: &'a NewtonWorkspace,
    hessian: &'a SparseMatrix,
    active: &'a [bool],
    rhs: &'a [f64],
    options: NewtonOptions,
}

impl DirectStep<'_> {
    /// The step, by a low-rank update of the last factored Hessian (`factored`, with
    /// its faces) where the options allow it and the faces changed little, else by a
    /// new factorization, which becomes `factored`; `counts` records which.
    ///
    /// # Errors
    /// A Hessian that is not positive definite, and a failed refinement.
    fn solve(
        &self,
        factored: &mut Option<(CholeskyFactor, Vec<bool>)>,
        counts: &mut StepCounts,
    ) -> Result<Vec<f64>> {
        let reusable = factored.as_ref().filter(|_| self.options.low_rank_updates);
        let updated = reusable.and_then(|(factor, factored_active)| {
            updated_solve(
                self.lcp,
                self.hessian,
                factor,
                factored_active,
                self.active,
                self.rhs,
                self.options,
            )
        });
        if let Some(d) = updated {
            counts.low_rank_updates += 1;
            return Ok(d);
        }
        counts.factorizations += 1;
        let factor = self
            .workspace
            .analyse()?
            .factor_cholesky(self.hessian)
            .map_err(hessian_not_positive)?;
        let d = refined(self.hessian, self.rhs, self.options.refinement_steps, |b| {
            factor.solve(b)
        })?;
        *factored = Some((factor, self.active.to_vec()));
        Ok(d)
    }
}

/// A 64-bit fingerprint of a set of active faces, for detecting cycles of the active set
/// (a collision can only end a cycle early at a point the KKT residual certifies anyway).
fn faces_fingerprint(active: &[bool]) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut hasher = std::collections::hash_map::DefaultHasher::new();
    active.hash(&mut hasher);
    hasher.finish()
}

/// Largest relative cost ([`WoodburySolver::relative_cost`]) at which a Newton step is
/// solved through a low-rank update of the last factorization rather than a new one: the
/// factorization runs at dense-kernel speed, the update's path solves do not.
pub(super) const LOW_RANK_COST_LIMIT: f64 = 0.5;

/// Largest backward error `‖b − Hd‖∞ / (‖H‖∞‖d‖∞ + ‖b‖∞)` accepted from an updated
/// solve; beyond it the step is factored anew (a nearly singular capacitance matrix).
pub(super) const LOW_RANK_BACKWARD_ERROR: f64 = 1e-14;

/// The Newton direction `H d = b` for the faces `active` through a low-rank update of the
/// factor of the Hessian on `factored_active`, when that is cheaper than a new
/// factorization and accurate; `None` otherwise.
pub(super) fn updated_solve(
    lcp: &Lcp,
    h: &SparseMatrix,
    factor: &CholeskyFactor,
    factored_active: &[bool],
    active: &[bool],
    b: &[f64],
    options: NewtonOptions,
) -> Option<Vec<f64>> {
    let term = lcp.hessian_change(factored_active, active).ok()?;
    let cost = WoodburySolver::relative_cost(factor, &term, 1 + options.refinement_steps)?;
    if cost > LOW_RANK_COST_LIMIT {
        return None;
    }
    let solver = WoodburySolver::new(factor, term).ok()?;
    let d = refined(h, b, options.refinement_steps, |r| solver.solve(r)).ok()?;
    let residual = residual_compensated(h, &d, b);
    let backward =
        max_norm(&residual) / (row_sum_norm(h) * max_norm(&d) + max_norm(b)).max(f64::MIN_POSITIVE);
    (backward <= LOW_RANK_BACKWARD_ERROR).then_some(d)
}

/// A failed factorization of Newton's Hessian `A + BᵀC⁻¹B` (with `C > 0` checked before)
/// with its usual causes: α·C_I = 1e6 was told only "not positive definite".
fn hessian_not_positive(error: Error) -> Error {
    match error {
        Error::LinearSolve(m) => Error::LinearSolve(format!(
            "{m}: Newton's matrix A + BᵀC⁻¹B is not positive definite, so A = a − αS on the primal fields is not: α·C_I ≥ 1 makes it indefinite (stabilization::inverse_constant gives C_I; α = ½/C_I is the usual choice), as do a bilinear form `a` that is not positive (a wrong sign, a derivative the element does not carry) and, for thin structures, rounding; and where no constraint is active it is A alone, singular for a body that only contact holds (a rigid motion is free): start from an iterate in contact (as the contact family's pressed start does) or hold the body"
        )),
        other => other,
    }
}

/// Why a block of `C` whose smallest diagonal entry is `c` is not positive definite, for
/// the error of [`Lcp::require_positive_c`]. `C = αS` restricted to the multipliers, so a negative
/// entry with α > 0 is a sign in the forms (a `B_h = … + α S` was told that
/// "α ≤ 0 gives the plain mixed method" with α = 0.04), and a zero one is α = 0 or an
/// `αh^k` that underflows on tiny cells.
fn c_fault(c: f64) -> &'static str {
    if c < 0.0 {
        "C = αS on the multipliers must be positive: with α > 0 the system form subtracts the stabilization (B_h = a − b − b − α S, L_h = ℓ − g − α ℓ_S, S a sum of squares); with α < 0 use α > 0, or α = 0 for the plain mixed method (the QP solver)"
    } else if c == 0.0 {
        "α = 0 gives the plain mixed method, solve it with the QP solver; with α > 0 the stabilization αh^k underflowed (cells far below the unit length: rescale the problem)"
    } else if c.is_nan() {
        "C is not a number: the stabilization's data or parameters are not finite"
    } else {
        "its diagonal is positive but the block is not positive definite: the stabilization S must be a sum of squares on the multipliers, (R(u,λ), R(v,μ)) with the same residual R on both sides"
    }
}

#[cfg(test)]
mod c_fault_tests {
    /// Each sign of a block of C gets its own cause: a block with a positive diagonal
    /// that is not positive definite (a P1disc multiplier's S of the wrong shape) was told
    /// "α ≤ 0 gives the plain mixed method".
    #[test]
    fn each_kind_of_c_that_is_not_positive_gets_its_cause() {
        assert!(super::c_fault(-1.0).contains("subtracts the stabilization"));
        assert!(super::c_fault(0.0).contains("α = 0"));
        assert!(super::c_fault(f64::NAN).contains("not a number"));
        assert!(super::c_fault(1.0).contains("sum of squares"));
    }
}
