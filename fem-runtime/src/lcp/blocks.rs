//! The small dense algebra of `C`'s blocks: iterating them, Cholesky and inverses of
//! blocks up to [`MAX_BLOCK`](super::MAX_BLOCK), and the elimination of one block's
//! multipliers, `Λ_b = argmin_{Λ≥0} ½ΛᵀC_bΛ − Λᵀr_b`, by enumerating the faces of the
//! orthant (docs/mathematics.md §5).

use super::*;

/// One diagonal block of `C`: constraints `start..start + size`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Block<'a> {
    pub(super) start: usize,
    pub(super) size: usize,
    /// The group's `size × size` entries (empty for size 1).
    pub(super) off: &'a [f64],
}

impl Block<'_> {
    pub(super) fn range(&self) -> Range<usize> {
        self.start..self.start + self.size
    }

    /// `C_{start+i, start+j}` with the diagonal `c`.
    pub(super) fn entry(&self, c: &[f64], i: usize, j: usize) -> f64 {
        if i == j {
            c.get(self.start + i).copied().unwrap_or(0.0)
        } else {
            self.off[i * self.size + j]
        }
    }

    /// The dense block, row-major, into `out` (`size²` entries).
    pub(super) fn dense(&self, c: &[f64], out: &mut [f64]) {
        for i in 0..self.size {
            for j in 0..self.size {
                out[i * self.size + j] = self.entry(c, i, j);
            }
        }
    }

    /// The dense block restricted to the constraints `face` (indices within the block).
    pub(super) fn face(&self, c: &[f64], face: &[usize], out: &mut [f64]) {
        let q = face.len();
        for (a, &i) in face.iter().enumerate() {
            for (b, &j) in face.iter().enumerate() {
                out[a * q + b] = self.entry(c, i, j);
            }
        }
    }
}

/// The blocks of `C` in order, groups of [`CouplingBlocks`] and singletons between them.
pub(super) struct Blocks<'a> {
    pub(super) m: usize,
    pub(super) coupling: &'a CouplingBlocks,
    pub(super) k: usize,
    pub(super) group: usize,
}

impl<'a> Iterator for Blocks<'a> {
    type Item = Block<'a>;

    fn next(&mut self) -> Option<Block<'a>> {
        if self.k >= self.m {
            return None;
        }
        let cb = self.coupling;
        if self.group < cb.starts.len() && cb.starts[self.group] == self.k {
            let (s, o) = (cb.sizes[self.group], cb.offsets[self.group]);
            self.group += 1;
            // a group past the last constraint (rejected by `Lcp::check_shapes`) is
            // skipped rather than read out of bounds
            if self.k + s <= self.m {
                let block = Block {
                    start: self.k,
                    size: s,
                    off: &cb.values[o..o + s * s],
                };
                self.k += s;
                return Some(block);
            }
        }
        let block = Block {
            start: self.k,
            size: 1,
            off: &[],
        };
        self.k += 1;
        Some(block)
    }
}

/// In-place Cholesky factorization `a = L Lᵀ` of an `n × n` row-major matrix (L in the
/// lower triangle); false when a pivot is not positive.
pub(super) fn small_cholesky(a: &mut [f64], n: usize) -> bool {
    for j in 0..n {
        let mut d = a[j * n + j];
        for k in 0..j {
            d -= a[j * n + k] * a[j * n + k];
        }
        if d.is_nan() || d <= 0.0 {
            return false;
        }
        let d = d.sqrt();
        a[j * n + j] = d;
        for i in j + 1..n {
            let mut s = a[i * n + j];
            for k in 0..j {
                s -= a[i * n + k] * a[j * n + k];
            }
            a[i * n + j] = s / d;
        }
    }
    true
}

/// Solves `L Lᵀ x = b` in place (`l` from [`small_cholesky`]).
pub(super) fn small_solve(l: &[f64], n: usize, x: &mut [f64]) {
    for i in 0..n {
        let mut s = x[i];
        for k in 0..i {
            s -= l[i * n + k] * x[k];
        }
        x[i] = s / l[i * n + i];
    }
    for i in (0..n).rev() {
        let mut s = x[i];
        for k in i + 1..n {
            s -= l[k * n + i] * x[k];
        }
        x[i] = s / l[i * n + i];
    }
}

/// The inverse of an SPD `n × n` row-major matrix into `out`; false if it is not SPD.
pub(super) fn small_inverse(a: &[f64], n: usize, out: &mut [f64]) -> bool {
    let mut l = [0.0; BLOCK_ENTRIES];
    l[..n * n].copy_from_slice(&a[..n * n]);
    if !small_cholesky(&mut l, n) {
        return false;
    }
    let mut x = [0.0; MAX_BLOCK];
    for j in 0..n {
        x[..n].fill(0.0);
        x[j] = 1.0;
        small_solve(&l, n, &mut x[..n]);
        for i in 0..n {
            out[i * n + j] = x[i];
        }
    }
    true
}

/// On the face `mask` of the orthant (the components in `mask` free, the others zero):
/// `x` with `C_II x_I = r_I`, and how far it is from the minimizer's KKT conditions
/// (`x_I ≥ 0` and `(Cx − r)_j ≥ 0` off I) in units of r; `None` if `C_II` is singular.
pub(super) fn face_point(
    c: &[f64],
    s: usize,
    r: &[f64],
    mask: usize,
    x: &mut [f64],
) -> Option<f64> {
    let mut face = [0usize; MAX_BLOCK];
    let q = (0..s).filter(|i| mask >> i & 1 == 1).fold(0, |q, i| {
        face[q] = i;
        q + 1
    });
    let mut l = [0.0; BLOCK_ENTRIES];
    for a in 0..q {
        for b in 0..q {
            l[a * q + b] = c[face[a] * s + face[b]];
        }
    }
    let mut y = [0.0; MAX_BLOCK];
    for a in 0..q {
        y[a] = r[face[a]];
    }
    if q > 0 {
        if !small_cholesky(&mut l, q) {
            return None;
        }
        small_solve(&l, q, &mut y[..q]);
    }
    x[..s].fill(0.0);
    let mut violation = 0.0f64;
    for a in 0..q {
        x[face[a]] = y[a];
        violation = violation.max(-y[a] * c[face[a] * s + face[a]]);
    }
    for j in (0..s).filter(|j| mask >> j & 1 == 0) {
        let dual: f64 = (0..q).map(|a| c[j * s + face[a]] * y[a]).sum::<f64>() - r[j];
        violation = violation.max(-dual);
    }
    Some(violation)
}

/// `Λ = argmin_{Λ≥0} ½ΛᵀCΛ − Λᵀr` for one SPD block `c` (`s × s`, row-major) and the
/// face it lies on (`active`: the components solved for). The faces are tried from the
/// smallest: on face I, `C_II Λ_I = r_I`, and the minimizer is the face point with
/// `Λ_I ≥ 0` and `(CΛ − r)_j ≥ 0` off I (the KKT conditions, which single out the unique
/// minimizer of a strictly convex QP). Rounding can leave no face exactly feasible at a
/// kink: then the least violating one, clipped to `Λ ≥ 0`.
pub(super) fn block_minimizer(
    c: &[f64],
    s: usize,
    r: &[f64],
    lambda: &mut [f64],
    active: &mut [bool],
) {
    let mut x = [0.0; MAX_BLOCK];
    let mut best = (f64::INFINITY, 0usize);
    'search: for count in 0..=s {
        for mask in (0..1usize << s).filter(|m| m.count_ones() as usize == count) {
            if let Some(violation) = face_point(c, s, r, mask, &mut x) {
                if violation <= 0.0 {
                    best = (violation, mask);
                    break 'search;
                }
                if violation < best.0 {
                    best = (violation, mask);
                }
            }
        }
    }
    if face_point(c, s, r, best.1, &mut x).is_none() {
        x[..s].fill(0.0);
    }
    for i in 0..s {
        lambda[i] = x[i].max(0.0);
        active[i] = best.1 >> i & 1 == 1;
    }
}
