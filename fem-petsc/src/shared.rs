//! An LCP assembled in parts, each rank its own cells of a partitioned level
//! ([`fem_runtime::lcp::Share`]): the whole `A U − Bᵀ Λ = F, 0 ≤ Λ ⊥ B U + C Λ − G ≥ 0`
//! is the sum of the ranks' LCPs and exists only inside PETSc.
//!
//! Every block goes into PETSc with `ADD_VALUES`, entries of rows other ranks own
//! included (they travel at assembly), into matrices preallocated by PETSc's
//! `MATPREALLOCATOR` from the same entries. An unknown belongs to the lowest rank whose
//! cells touch it, and PETSc's rows are numbered rank by rank, so a rank's rows are
//! those of its own cells except on the partition's interfaces. A constraint of a
//! multiplier on cells (or P0 on an edge) lives on one cell: its rows of `B`, `C`, `G`
//! are complete on the rank of that cell, which evaluates it alone (the eliminated
//! formulation's `(G − BU)₊,k / C_k` needs no communication beyond the entries of `U`
//! its row reads). A continuous P1 multiplier's constraint on a vertex where two ranks'
//! edges meet is held in part by both: the eliminated formulation gathers its parts to
//! the lower rank once ([`Rows`]); the mixed one adds them inside PETSc.

use crate::{
    minimize, solve_affine, Converged, Defaults, Error, Ghosts, Matrix, Petsc, Result, Vector,
    VectorView,
};
use fem_runtime::lcp::Lcp;

/// The answer of a shared LCP's solve, on every rank.
pub(crate) struct Shared {
    /// `U`, whole.
    pub u: Vec<f64>,
    /// `Λ`, whole.
    pub lambda: Vec<f64>,
    /// SNES's report.
    pub converged: Converged,
    /// `‖A‖∞` of the assembled `A`.
    pub a_norm: f64,
    /// PETSc's rows this rank owns.
    pub rows_here: usize,
}

/// PETSc's index of each unknown of a shared LCP, and this rank's rows.
struct Numbering {
    /// PETSc's row of each primal unknown.
    u: Vec<usize>,
    /// PETSc's row of each constraint's multiplier (mixed formulation; empty otherwise).
    lambda: Vec<usize>,
    /// This rank's first row and row count.
    first: usize,
    local: usize,
    /// The primal unknowns and the constraints this rank owns, in its row order.
    own_u: Vec<usize>,
    own_lambda: Vec<usize>,
}

/// The constraints whose rows this rank holds (a nonzero entry of `B`, `C` or `G`).
fn held(lcp: &Lcp) -> Vec<bool> {
    let mut held: Vec<bool> = (0..lcp.m())
        .map(|k| !lcp.b_rows[k].is_empty() || lcp.c[k] != 0.0 || lcp.g[k] != 0.0)
        .collect();
    for (first, size) in lcp.c_blocks.groups() {
        for h in &mut held[first..first + size] {
            *h = true;
        }
    }
    held
}

impl Numbering {
    /// Owners by the lowest rank touching each unknown (its column of this rank's `A`,
    /// its rows of `B`; for the multipliers, `with_multipliers`, their rows), numbered
    /// rank by rank: a rank's `U` rows, then its `Λ` rows.
    fn new(petsc: &Petsc, lcp: &Lcp, held: &[bool], with_multipliers: bool) -> Self {
        let (n, m) = (lcp.n(), if with_multipliers { lcp.m() } else { 0 });
        let (rank, size) = (petsc.rank(), petsc.size());
        let mut owner = vec![size as u64; n + m];
        let ptr = lcp.a.symbolic().col_ptr();
        for j in 0..n {
            if ptr[j + 1] > ptr[j] {
                owner[j] = rank as u64;
            }
        }
        for (k, row) in lcp.b_rows.iter().enumerate() {
            for &(j, _) in row {
                owner[j] = rank as u64;
            }
            if with_multipliers && held[k] {
                owner[n + k] = rank as u64;
            }
        }
        petsc.min_all(&mut owner);
        // an unknown no rank touches (none in a conforming assembly) goes to rank 0
        let owner: Vec<usize> = owner.iter().map(|&r| (r as usize) % size).collect();
        let mut counts = vec![0usize; size + 1];
        for &r in &owner {
            counts[r + 1] += 1;
        }
        for r in 0..size {
            counts[r + 1] += counts[r];
        }
        let mut next = counts.clone();
        let (mut u, mut lambda) = (vec![0; n], vec![0; m]);
        let (mut own_u, mut own_lambda) = (Vec::new(), Vec::new());
        // U before Λ within each rank: the unknowns in index order, U first
        for (i, &r) in owner.iter().enumerate() {
            let row = next[r];
            next[r] += 1;
            if i < n {
                u[i] = row;
                if r == rank {
                    own_u.push(i);
                }
            } else {
                lambda[i - n] = row;
                if r == rank {
                    own_lambda.push(i - n);
                }
            }
        }
        Self {
            u,
            lambda,
            first: counts[rank],
            local: counts[rank + 1] - counts[rank],
            own_u,
            own_lambda,
        }
    }

    /// PETSc's rows of this rank.
    fn rows(&self) -> Vec<usize> {
        (self.first..self.first + self.local).collect()
    }
}

/// A matrix of the layout of `numbering` preallocated for `A` and the extra entries
/// `extra` declares (the Hessian's `BᵀDB`, the constraint rows), with this rank's part
/// of `A` added where `with_values` (not assembled yet), or zero and assembled.
fn matrix_of_a<'p>(
    petsc: &'p Petsc,
    lcp: &Lcp,
    numbering: &Numbering,
    with_values: bool,
    extra: impl Fn(&mut crate::Pattern) -> Result<()>,
) -> Result<Matrix<'p>> {
    let (ptr, rows, values) = (
        lcp.a.symbolic().col_ptr(),
        lcp.a.symbolic().row_idx(),
        lcp.a.val(),
    );
    let column_rows = |j: usize| -> Vec<usize> {
        rows[ptr[j]..ptr[j + 1]]
            .iter()
            .map(|&i| numbering.u[i])
            .collect()
    };
    let mut matrix = Matrix::with_pattern(petsc, numbering.local, |pattern| {
        for j in 0..lcp.n() {
            if ptr[j + 1] > ptr[j] {
                pattern.add(&column_rows(j), &[numbering.u[j]])?;
            }
        }
        extra(pattern)
    })?;
    if !with_values {
        return Ok(matrix);
    }
    for j in 0..lcp.n() {
        if ptr[j + 1] > ptr[j] {
            matrix.add(
                &column_rows(j),
                &[numbering.u[j]],
                &values[ptr[j]..ptr[j + 1]],
            )?;
        }
    }
    Ok(matrix)
}

/// This rank's part of `v` (by unknown) added into a vector of this rank's `local` rows
/// at PETSc's rows `index`.
fn vector_of<'p>(
    petsc: &'p Petsc,
    local: usize,
    v: &[f64],
    index: impl Fn(usize) -> usize,
) -> Result<Vector<'p>> {
    let mut out = Vector::new(petsc, local)?;
    let (indices, values): (Vec<usize>, Vec<f64>) = v
        .iter()
        .enumerate()
        .filter(|(_, &x)| x != 0.0)
        .map(|(i, &x)| (index(i), x))
        .unzip();
    out.set(&indices, &values, true)?;
    out.assemble()?;
    Ok(out)
}

/// The rows this rank holds ([`held`]), the numbering of the unknowns (of the
/// multipliers too, `with_multipliers`), and the whole `A` assembled in PETSc from every
/// rank's part, with its `‖A‖∞`.
fn assembled_a<'p>(
    petsc: &'p Petsc,
    lcp: &Lcp,
    with_multipliers: bool,
) -> Result<(Vec<bool>, Numbering, Matrix<'p>, f64)> {
    let holds = held(lcp);
    let numbering = Numbering::new(petsc, lcp, &holds, with_multipliers);
    let mut a = matrix_of_a(petsc, lcp, &numbering, true, |_| Ok(()))?;
    a.assemble()?;
    let a_norm = a.norm_infinity()?;
    Ok((holds, numbering, a, a_norm))
}

/// The constraints this rank evaluates in the eliminated formulation, each with its
/// whole row. A constraint held by one rank keeps that rank's row; one split between
/// ranks (a P1 multiplier on a vertex where two parts' contact edges meet) is summed on
/// the lowest of its holders from every holder's part, gathered from all ranks: few,
/// the partition's interfaces on the multiplier's part.
struct Rows<'l> {
    lcp: &'l Lcp,
    /// The constraints, ascending.
    held: Vec<usize>,
    /// The split constraints among them, each with its whole row of `B` (columns
    /// ascending), `C`'s diagonal entry and `G`; the others' rows are `lcp`'s.
    merged: std::collections::BTreeMap<usize, WholeRow>,
}

/// A constraint's whole row of `B` (columns ascending), `C`'s diagonal entry and `G`.
type WholeRow = (Vec<(usize, f64)>, f64, f64);

impl<'l> Rows<'l> {
    /// This rank's constraints of `lcp`, `holds` the ones it has entries of ([`held`]).
    ///
    /// # Errors
    /// A block of coupled multipliers (`C`'s off-diagonal blocks) split between ranks:
    /// its inverse needs the whole block on one rank.
    fn new(petsc: &Petsc, lcp: &'l Lcp, holds: &[bool]) -> Result<Self> {
        let (rank, size, n) = (petsc.rank(), petsc.size(), lcp.n());
        let mut holder: Vec<u64> = holds
            .iter()
            .map(|&h| if h { rank } else { size } as u64)
            .collect();
        petsc.min_all(&mut holder);
        let mut count: Vec<f64> = holds.iter().map(|&h| f64::from(u8::from(h))).collect();
        petsc.sum_all(&mut count);
        let split = |k: usize| count[k] > 1.0;
        for (first, s) in lcp.c_blocks.groups() {
            if let Some(k) = (first..first + s).find(|&k| split(k)) {
                return Err(Error::refused(
                    "PetscLcpSolver::solve",
                    format!(
                        "constraint {k} of a coupled block of C is held by {} ranks: the block's inverse needs it whole on one",
                        count[k]
                    ),
                ));
            }
        }
        // this rank's parts of the split rows as triples (k, j, v): column j of B, or
        // j = n for C's diagonal and j = n + 1 for G (indices exact in f64 below 2⁵³)
        let mut mine: Vec<f64> = Vec::new();
        for k in (0..lcp.m()).filter(|&k| holds[k] && split(k)) {
            for &(j, v) in &lcp.b_rows[k] {
                mine.extend([k as f64, j as f64, v]);
            }
            mine.extend([k as f64, n as f64, lcp.c[k]]);
            mine.extend([k as f64, (n + 1) as f64, lcp.g[k]]);
        }
        let mut pieces: std::collections::BTreeMap<usize, Vec<(usize, f64)>> = Default::default();
        for t in petsc.gather_all(&mine).chunks_exact(3) {
            let k = t[0] as usize;
            if holder[k] as usize == rank {
                pieces.entry(k).or_default().push((t[1] as usize, t[2]));
            }
        }
        let mut merged = std::collections::BTreeMap::new();
        for (k, mut entries) in pieces {
            entries.sort_by_key(|&(j, _)| j);
            let (mut row, mut c, mut g) = (Vec::<(usize, f64)>::new(), 0.0, 0.0);
            for (j, v) in entries {
                match j {
                    j if j == n => c += v,
                    j if j == n + 1 => g += v,
                    j => match row.last_mut() {
                        Some((last, w)) if *last == j => *w += v,
                        _ => row.push((j, v)),
                    },
                }
            }
            merged.insert(k, (row, c, g));
        }
        let held = (0..lcp.m())
            .filter(|&k| {
                if split(k) {
                    merged.contains_key(&k)
                } else {
                    holds[k]
                }
            })
            .collect();
        Ok(Self { lcp, held, merged })
    }

    /// The number of constraints this rank evaluates.
    fn len(&self) -> usize {
        self.held.len()
    }

    /// The `i`-th held constraint's row of `B`, `C`'s diagonal entry and `G`.
    fn row(&self, i: usize) -> (&[(usize, f64)], f64, f64) {
        let k = self.held[i];
        match self.merged.get(&k) {
            Some((row, c, g)) => (row, *c, *g),
            None => (&self.lcp.b_rows[k], self.lcp.c[k], self.lcp.g[k]),
        }
    }

    /// The held constraints' rows, in order ([`Rows::row`]).
    fn rows(&self) -> impl Iterator<Item = (&[(usize, f64)], f64, f64)> + '_ {
        (0..self.len()).map(|i| self.row(i))
    }

    /// The eliminated multipliers `(G − BU)₊,k / C_k` of the held constraints, `u(j)`
    /// the unknown of column `j` of `B`.
    fn multipliers(&self, u: impl Fn(usize) -> f64) -> Vec<f64> {
        self.rows()
            .map(|(row, c, g)| {
                let r = g - row.iter().map(|&(j, v)| v * u(j)).sum::<f64>();
                r.max(0.0) / c
            })
            .collect()
    }
}

/// `‖F‖₂ + ‖BᵀC⁻¹G₊‖₂` of the whole LCP, the sizes of the two terms of `∇Φ(0)`.
fn gradient_scale(petsc: &Petsc, lcp: &Lcp, rows: &Rows) -> f64 {
    let mut pressed = vec![0.0; lcp.n()];
    for (row, c, g) in rows.rows() {
        if c > 0.0 {
            let z = g.max(0.0) / c;
            for &(j, v) in row.iter() {
                pressed[j] += v * z;
            }
        }
    }
    let mut f = lcp.f.clone();
    petsc.sum_all(&mut pressed);
    petsc.sum_all(&mut f);
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    norm(&f) + norm(&pressed)
}

/// Solves the shared `lcp` by SNES on Φ(U), the multipliers eliminated (see the crate's
/// `lcp` module): `A` and `F` added into PETSc from every rank's cells, the constraints
/// evaluated on the ranks that hold them ([`Rows`]), the Hessian `A + BᵀDB` preallocated
/// for every constraint. Returns the whole `(U, Λ)` on every rank, SNES's report and `‖A‖∞` ([`Shared`]).
pub(crate) fn solve_eliminated(
    petsc: &Petsc,
    lcp: &Lcp,
    start: Option<&[f64]>,
    defaults: Defaults,
) -> Result<Shared> {
    let (holds, numbering, a, a_norm) = assembled_a(petsc, lcp, false)?;
    let rows = Rows::new(petsc, lcp, &holds)?;
    let columns_of =
        |i: usize| -> Vec<usize> { rows.row(i).0.iter().map(|&(j, _)| numbering.u[j]).collect() };
    let hessian_matrix = matrix_of_a(petsc, lcp, &numbering, false, |pattern| {
        for i in 0..rows.len() {
            let columns = columns_of(i);
            pattern.add(&columns, &columns)?;
        }
        Ok(())
    })?;
    let mut hessian_matrix = hessian_matrix;
    // by PETSc's row; a vector of another length than U's is left as it is, for
    // `set_near_null_space` to refuse on every rank
    let by_row: Vec<Vec<f64>> = lcp
        .near_null_space
        .iter()
        .map(|v| {
            if v.len() != lcp.n() {
                return v.clone();
            }
            let mut row = vec![0.0; v.len()];
            for (j, &x) in v.iter().enumerate() {
                row[numbering.u[j]] = x;
            }
            row
        })
        .collect();
    hessian_matrix.set_near_null_space(petsc, &numbering.rows(), &by_row)?;
    let f = vector_of(petsc, numbering.local, &lcp.f, |i| numbering.u[i])?;
    let mut x = Vector::new(petsc, numbering.local)?;
    let begin: Vec<f64> = numbering
        .own_u
        .iter()
        .map(|&i| start.map_or(0.0, |s| s[i]))
        .collect();
    x.set(&numbering.rows(), &begin, false)?;
    x.assemble()?;
    // the entries of U the held rows read, and the rows in their local indices (row i's
    // entries at `local[starts[i]..starts[i + 1]]`)
    let mut needed: Vec<usize> = (0..rows.len()).flat_map(columns_of).collect();
    needed.sort_unstable();
    needed.dedup();
    let mut starts = Vec::with_capacity(rows.len() + 1);
    starts.push(0);
    let mut local: Vec<(usize, f64)> = Vec::new();
    for (row, _, _) in rows.rows() {
        local.extend(row.iter().map(|&(j, v)| {
            let at = needed
                .binary_search(&numbering.u[j])
                .expect("every column read is needed");
            (at, v)
        }));
        starts.push(local.len());
    }
    let ghosts = std::cell::RefCell::new(Ghosts::new(petsc, &x, &needed)?);
    let mut work = Vector::new(petsc, numbering.local)?;
    work.assemble()?;
    let work = std::cell::RefCell::new(work);
    let defaults = Defaults {
        atol: defaults
            .atol
            .map(|relative| relative * gradient_scale(petsc, lcp, &rows)),
        ..defaults
    };
    // the eliminated multipliers of the held constraints from the needed entries of U
    let multipliers = |u: &[f64]| -> Vec<f64> {
        starts
            .windows(2)
            .zip(rows.rows())
            .map(|(at, (_, c, g))| {
                let row = &local[at[0]..at[1]];
                let r = g - row.iter().map(|&(j, v)| v * u[j]).sum::<f64>();
                r.max(0.0) / c
            })
            .collect()
    };
    let (a, f) = (&a, &f);
    let objective = |x: &VectorView| -> Result<f64> {
        let work = work.borrow_mut();
        let mut ax = VectorView::of(&work);
        a.multiply(x, &mut ax)?;
        let quadratic = 0.5 * x.dot(&ax)? - x.dot(&VectorView::of(f))?;
        let z = multipliers(&ghosts.borrow_mut().read(x)?);
        let share: f64 = rows
            .rows()
            .zip(&z)
            .map(|((_, c, _), z)| 0.5 * z * z * c)
            .sum();
        Ok(quadratic + petsc.sum(share))
    };
    let gradient = |x: &VectorView, out: &mut VectorView| -> Result<()> {
        a.multiply(x, out)?;
        out.axpy(-1.0, &VectorView::of(f))?;
        let z = multipliers(&ghosts.borrow_mut().read(x)?);
        let (mut indices, mut values) = (Vec::new(), Vec::new());
        for (&zk, (row, _, _)) in z.iter().zip(rows.rows()) {
            if zk != 0.0 {
                for &(j, v) in row.iter() {
                    indices.push(numbering.u[j]);
                    values.push(-v * zk);
                }
            }
        }
        out.add(&indices, &values)?;
        out.assemble()
    };
    let hessian = |x: &VectorView, matrix: &mut Matrix| -> Result<()> {
        let z = multipliers(&ghosts.borrow_mut().read(x)?);
        matrix.zero_entries()?;
        matrix.add_scaled(1.0, a)?;
        let mut block = Vec::new();
        for (i, &zk) in z.iter().enumerate() {
            // active where (G − BU)_k > 0, i.e. where the eliminated Λ_k is
            if zk > 0.0 {
                let (row, c, _) = rows.row(i);
                let columns = columns_of(i);
                block.clear();
                for &(_, v) in row.iter() {
                    block.extend(row.iter().map(|&(_, w)| v * w / c));
                }
                matrix.add(&columns, &columns, &block)?;
            }
        }
        matrix.assemble()
    };
    let converged = minimize(
        &defaults,
        Box::new(objective),
        Box::new(gradient),
        Box::new(hessian),
        hessian_matrix,
        &mut x,
    )?;
    let whole = x.gather()?;
    let u: Vec<f64> = (0..lcp.n()).map(|j| whole[numbering.u[j]]).collect();
    let mut lambda = vec![0.0; lcp.m()];
    for (&k, z) in rows.held.iter().zip(rows.multipliers(|j| u[j])) {
        lambda[k] = z;
    }
    petsc.sum_all(&mut lambda);
    Ok(Shared {
        u,
        lambda,
        converged,
        a_norm,
        rows_here: numbering.local,
    })
}

/// Solves the shared `lcp` by SNESVI in the mixed formulation `(U, Λ)` with `Λ ≥ 0`:
/// the Jacobian `[[A, −Bᵀ], [B, C]]` and the right side `(F, G)` added into PETSc from
/// every rank's cells. Returns the whole `(U, Λ)` on every rank, SNES's report and
/// `‖A‖∞` ([`Shared`]).
pub(crate) fn solve_mixed(
    petsc: &Petsc,
    lcp: &Lcp,
    start: Option<&[f64]>,
    defaults: Defaults,
) -> Result<Shared> {
    let (holds, numbering, a, a_norm) = assembled_a(petsc, lcp, true)?;
    drop(a);
    // the constraint rows: (λ_k, u_j) = B_kj and (u_j, λ_k) = −B_kj, C's diagonal and
    // blocks, each entry from the one rank that holds the constraint
    let mut entries: Vec<(usize, usize, f64)> = Vec::new();
    for (k, row) in lcp.b_rows.iter().enumerate() {
        let l = numbering.lambda[k];
        for &(j, v) in row {
            entries.push((l, numbering.u[j], v));
            entries.push((numbering.u[j], l, -v));
        }
        if holds[k] {
            entries.push((l, l, lcp.c[k]));
        }
    }
    for (first, s, block) in lcp.c_blocks.blocks() {
        for i in 0..s {
            for j in (0..s).filter(|&j| j != i) {
                let v = block[i * s + j];
                if v != 0.0 {
                    entries.push((numbering.lambda[first + i], numbering.lambda[first + j], v));
                }
            }
        }
    }
    let mut jacobian = matrix_of_a(petsc, lcp, &numbering, true, |pattern| {
        for &(i, j, _) in &entries {
            pattern.add(&[i], &[j])?;
        }
        Ok(())
    })?;
    for &(i, j, v) in &entries {
        jacobian.add(&[i], &[j], &[v])?;
    }
    drop(entries);
    jacobian.assemble()?;
    let (n, m) = (lcp.n(), lcp.m());
    let mut right = Vector::new(petsc, numbering.local)?;
    for (v, index) in [
        (&lcp.f, &numbering.u as &[usize]),
        (&lcp.g, &numbering.lambda),
    ] {
        let (indices, values): (Vec<usize>, Vec<f64>) = v
            .iter()
            .enumerate()
            .filter(|(_, &x)| x != 0.0)
            .map(|(i, &x)| (index[i], x))
            .unzip();
        right.set(&indices, &values, true)?;
    }
    right.assemble()?;
    let rows = numbering.rows();
    let infinity = crate::sys::FEM_PETSC_INFINITY;
    let own = |u: &dyn Fn(usize) -> f64, l: &dyn Fn(usize) -> f64| -> Vec<f64> {
        numbering
            .own_u
            .iter()
            .map(|&i| u(i))
            .chain(numbering.own_lambda.iter().map(|&k| l(k)))
            .collect()
    };
    let mut x = Vector::new(petsc, numbering.local)?;
    x.set(
        &rows,
        &own(&|i| start.map_or(0.0, |s| s[i]), &|_| 0.0),
        false,
    )?;
    let mut lower = Vector::new(petsc, numbering.local)?;
    lower.set(&rows, &own(&|_| -infinity, &|_| 0.0), false)?;
    let mut upper = Vector::new(petsc, numbering.local)?;
    upper.set(&rows, &vec![infinity; rows.len()], false)?;
    for v in [&mut x, &mut lower, &mut upper] {
        v.assemble()?;
    }
    let mut sizes: Vec<f64> = lcp.f.iter().chain(&lcp.g).copied().collect();
    petsc.sum_all(&mut sizes);
    let scale = sizes.iter().map(|x| x * x).sum::<f64>().sqrt();
    let defaults = Defaults {
        atol: defaults.atol.map(|relative| relative * scale),
        // a problem with (F, G) = 0 has its solution at the start: no step to force
        force_iteration: defaults.force_iteration && scale > 0.0,
        ..defaults
    };
    let converged = solve_affine(&defaults, &jacobian, &right, Some((&lower, &upper)), &mut x)?;
    let whole = x.gather()?;
    let u = (0..n).map(|j| whole[numbering.u[j]]).collect();
    let lambda = (0..m).map(|k| whole[numbering.lambda[k]]).collect();
    Ok(Shared {
        u,
        lambda,
        converged,
        a_norm,
        rows_here: numbering.local,
    })
}

/// Whether the shared `lcp` is the nodal method's (`B = I`, `C = 0`, `U_k ≥ ψ_k`): every
/// rank's rows empty or `e_k`, `C` zero without blocks, and each constraint held by
/// exactly one rank (collective: every rank must call it).
pub(crate) fn is_nodal(petsc: &Petsc, lcp: &Lcp) -> bool {
    let here = crate::lcp::nodal_shape(lcp, true);
    // every rank must take part in the count below, whatever its rows
    let mut count: Vec<f64> = lcp
        .b_rows
        .iter()
        .map(|row| f64::from(u8::from(!row.is_empty())))
        .collect();
    let length = count.len() as f64;
    let same_length = petsc.max(length) == -petsc.max(-length);
    if petsc.max(f64::from(u8::from(!here))) > 0.0 || !same_length {
        return false;
    }
    petsc.sum_all(&mut count);
    count.iter().all(|&c| c == 1.0)
}

/// Solves the shared nodal LCP ([`is_nodal`]) by SNESVI with the bounds `U ≥ ψ` on the
/// primal unknowns: `A` and `F` added into PETSc from every rank's cells, each bound
/// set by the rank that owns its constraint. Returns the whole `U` and the nodal forces
/// `Λ = (AU − F)₊` on every rank, SNES's report and `‖A‖∞` ([`Shared`]).
pub(crate) fn solve_primal(
    petsc: &Petsc,
    lcp: &Lcp,
    start: Option<&[f64]>,
    defaults: Defaults,
) -> Result<Shared> {
    let (holds, numbering, a, a_norm) = assembled_a(petsc, lcp, false)?;
    let f = vector_of(petsc, numbering.local, &lcp.f, |i| numbering.u[i])?;
    let rows = numbering.rows();
    let infinity = crate::sys::FEM_PETSC_INFINITY;
    // ψ_k from the rank holding constraint k (B = I: it bounds unknown k)
    let (bounded, floor): (Vec<usize>, Vec<f64>) = (0..lcp.m())
        .filter(|&k| holds[k])
        .map(|k| (numbering.u[k], lcp.g[k]))
        .unzip();
    let mut lower = Vector::new(petsc, numbering.local)?;
    lower.set(&bounded, &floor, false)?;
    let mut upper = Vector::new(petsc, numbering.local)?;
    upper.set(&rows, &vec![infinity; rows.len()], false)?;
    let mut x = Vector::new(petsc, numbering.local)?;
    let begin: Vec<f64> = numbering
        .own_u
        .iter()
        .map(|&i| start.map_or(0.0, |s| s[i]))
        .collect();
    x.set(&rows, &begin, false)?;
    for v in [&mut x, &mut lower, &mut upper] {
        v.assemble()?;
    }
    // the residual at x = 0 is −F: its size sets the rounding floor
    let mut whole_f = lcp.f.clone();
    petsc.sum_all(&mut whole_f);
    let scale = whole_f.iter().map(|x| x * x).sum::<f64>().sqrt();
    let defaults = Defaults {
        atol: defaults.atol.map(|relative| relative * scale),
        ..defaults
    };
    let converged = solve_affine(&defaults, &a, &f, Some((&lower, &upper)), &mut x)?;
    // the nodal forces A U − F, ≥ 0 up to the solver's tolerance where U = ψ
    let mut residual = Vector::new(petsc, numbering.local)?;
    residual.assemble()?;
    {
        let mut r = VectorView::of(&residual);
        a.multiply(&VectorView::of(&x), &mut r)?;
        r.axpy(-1.0, &VectorView::of(&f))?;
    }
    let (whole, forces) = (x.gather()?, residual.gather()?);
    let u = (0..lcp.n()).map(|j| whole[numbering.u[j]]).collect();
    let lambda = (0..lcp.m())
        .map(|k| forces[numbering.u[k]].max(0.0))
        .collect();
    Ok(Shared {
        u,
        lambda,
        converged,
        a_norm,
        rows_here: numbering.local,
    })
}
