//! Obstacle problems of a model: the stabilized saddle-point system `B_h`, `L_h` is
//! assembled, boundary DOFs are eliminated, and the system is split into the LCP blocks
//! `A_α, B_α, C_α, F_α, G_α` of docs/mathematics.md §1 (the KKT matrix is
//! `[[A_α, −B_αᵀ], [−B_α, −C_α]]`, its right-hand side `[F_α; −G_α]`).

pub mod boundary_multiplier;
pub mod hierarchy;
pub mod nodal;
pub mod triangle;

use crate::assembly::boundary::{Constraints, Reduction, Side};
use crate::assembly::change_of_basis::{congruence, BlockRotation, ChangeOfBasis};
use crate::assembly::dof_map::DofNumbering;
use crate::assembly::dof_map::SystemDofs;
use crate::assembly::kernel::{self, Position};
use crate::assembly::{assemble_vector, block_plans, for_each_entry, BlockPlan};
use crate::element::interval::PhysicalBasis;
use crate::element::mapping::Affine;
use crate::error::{Error, Result};
use crate::lcp::external::Purpose;
use crate::lcp::{
    primal_dual_active_set, quadratic_program, recover_multiplier, semismooth_newton,
    semismooth_newton_prepared, semismooth_newton_with, ConstraintRows, CouplingBlocks, Lcp,
    LcpSolution, NewtonOptions, NewtonStep, NewtonWorkspace,
};
use crate::mesh::{IntervalMesh, Mesh};
use crate::model::{Coefficients, FormId, IntoFormIndex, Model};
use crate::multigrid::MultigridOptions;
use crate::norms::FieldView;
use crate::SparseMatrix;
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use fem_reference::{DofLocation, ElementKind};
use hierarchy::{LinearSolver, MultigridSteps};
use std::sync::{Arc, OnceLock};
use std::time::Instant;

/// Which algorithm solves the LCP.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VariationalSolver {
    /// Semismooth Newton / primal–dual active set on Φ, globalized by a line search.
    SemismoothNewton,
    /// clarabel's interior-point method on the equivalent QP.
    Clarabel,
    /// A solver outside this crate ([`crate::lcp::external`]: PETSc over MPI), given each
    /// level's LCP and nested iteration's start.
    External(crate::lcp::external::External),
}

impl VariationalSolver {
    /// Whether levels nest: each solved from the coarser level's prolonged solution (the
    /// QP solver takes the finest level alone).
    pub fn nests(self) -> bool {
        !matches!(self, Self::Clarabel)
    }

    /// Its name in reports: `pdas`, `clarabel`, or the external solver's.
    pub fn name(self) -> &'static str {
        match self {
            Self::SemismoothNewton => "pdas",
            Self::Clarabel => "clarabel",
            Self::External(e) => e.0.name(),
        }
    }

    /// Runs `work` with this solver's solves, where it is an external one, marked as
    /// serving `purpose` ([`ExternalSolver::set_purpose`]), and marks them
    /// [`Purpose::Answer`] again after it.
    ///
    /// [`ExternalSolver::set_purpose`]: crate::lcp::external::ExternalSolver::set_purpose
    pub fn during<T>(self, purpose: Purpose, work: impl FnOnce() -> T) -> T {
        let Self::External(external) = self else {
            return work();
        };
        external.0.set_purpose(purpose);
        let result = work();
        external.0.set_purpose(Purpose::Answer);
        result
    }

    /// The external solver's solves recorded so far (0 for the others):
    /// [`ExternalSolver::recorded`].
    ///
    /// [`ExternalSolver::recorded`]: crate::lcp::external::ExternalSolver::recorded
    pub fn recorded(self) -> usize {
        match self {
            Self::External(external) => external.0.recorded(),
            _ => 0,
        }
    }

    /// Marks the external solver's recorded solves `records` as serving `purpose`
    /// ([`ExternalSolver::relabel`]); nothing for the others.
    ///
    /// [`ExternalSolver::relabel`]: crate::lcp::external::ExternalSolver::relabel
    pub fn relabel(self, records: std::ops::Range<usize>, purpose: Purpose) {
        if let Self::External(external) = self {
            external.0.relabel(records, purpose);
        }
    }
}

#[derive(Clone, Copy, Debug)]
pub(crate) enum Role {
    Primal(usize),
    Multiplier(usize),
}

/// The discrete obstacle problem of a model on one mesh.
pub struct Discretization<G = IntervalMesh> {
    /// The mesh.
    pub mesh: G,
    /// DOFs of all fields of the model.
    pub dofs: SystemDofs,
    /// Elimination of the boundary DOFs, in the primed numbering of `basis`.
    pub reduction: Reduction,
    /// The rotation of the Argyris vertex DOFs that turns plate supports on edges not
    /// along x or y into fixed DOFs ([`Constraints::change_of_basis`]; the identity
    /// otherwise). The LCP is in the primed DOFs; full coefficient vectors
    /// ([`Discretization::full`], the solution's values) are Cartesian.
    pub basis: ChangeOfBasis,
    /// The LCP blocks.
    pub lcp: Lcp,
    /// The model field that holds the multiplier.
    pub multiplier_field: usize,
    /// Where the multiplier's DOFs live: on the cells (then they are DOFs of `dofs`) or
    /// on the edges of a boundary part.
    pub multipliers: Multipliers,
    pub(crate) roles: Vec<Role>,
    pub(crate) primal_reduced: Vec<usize>,
    pub(crate) multiplier_reduced: Vec<usize>,
    /// The cells whose element contributions the LCP holds: `None`, every cell; `Some`,
    /// this process's part of a partition of them ([`Discretization::with_constraints_on`],
    /// [`Lcp::share`] set by the caller that partitioned).
    pub cells: Option<Vec<usize>>,
}

/// Where a discretization's multiplier lives.
#[derive(Clone, Debug, PartialEq)]
pub enum Multipliers {
    /// On the cells: the multiplier field's DOF map (P0, P1disc), part of
    /// [`Discretization::dofs`].
    Cells,
    /// On the edges of a boundary part ([`boundary_multiplier`]): not in
    /// [`Discretization::dofs`], which holds the primal fields only.
    Boundary(boundary_multiplier::BoundaryMultiplierDofs),
    /// The nodal method's contact forces, one per free node (`B = I`, `C = 0`): the
    /// model has no multiplier field ([`crate::problem::nodal`]).
    Nodal,
}

/// The multiplier field of a model: the one declared `>= 0`.
pub fn multiplier_field<M: Model>() -> Result<usize> {
    let fields: Vec<usize> = (0..M::FIELDS.len())
        .filter(|&f| M::FIELDS[f].nonnegative)
        .collect();
    match fields.as_slice() {
        [f] => Ok(*f),
        _ => Err(Error::Input(format!(
            "model `{}` must declare exactly one multiplier `λ: P0 >= 0`, it declares {}",
            M::NAME,
            fields.len()
        ))),
    }
}

impl Discretization<IntervalMesh> {
    /// Assembles `bilinear` and `linear` (normally `B_h`, `L_h`) of `M` on `mesh`, with the
    /// fields in `clamped` clamped at both ends and the model's `boundary: u = g`
    /// conditions imposed at both ends (`u = g(x)` at the end points `x`; where a field
    /// with slope DOFs (Hermite) is both, `g` gives its value and the clamp its zero
    /// slope).
    ///
    /// # Errors
    /// Unknown field names, a field without slope DOFs both clamped and given by
    /// `boundary:`, boundary data that is not finite at an end (the message names the
    /// data and the point), and those of [`Discretization::with_constraints`].
    pub fn new<M: Model>(
        mesh: &IntervalMesh,
        coefficients: &Coefficients,
        clamped: &[&str],
        bilinear: impl IntoFormIndex<M>,
        linear: impl IntoFormIndex<M>,
    ) -> Result<Self> {
        let dofs = SystemDofs::all::<M>(mesh)?;
        let mut constraints = Constraints::new();
        for field in clamped {
            for side in [Side::Left, Side::Right] {
                constraints.clamp::<M>(mesh, &dofs, field, side)?;
            }
        }
        let ends = [
            (Side::Left, mesh.vertices()[0]),
            (Side::Right, *mesh.vertices().last().unwrap()),
        ];
        for &(field, data) in M::DIRICHLET {
            // a clamp of a field without slope DOFs is its value 0 alone, which `u = g`
            // would replace without a word (a clamped `u` ended at g = 0.05)
            let name = M::FIELDS[field].name;
            if clamped.contains(&name) && M::FIELDS[field].element.dofs_per_vertex() == 1 {
                return Err(Error::Input(format!(
                    "field `{name}` of `{}` is clamped (`{name}` = 0 at both ends) and its `boundary:` gives `{name} = {}`: two values for the same DOFs; drop it from the clamped fields or from `boundary:`",
                    M::NAME,
                    M::DATA[data]
                )));
            }
            let g = coefficients.data.get(data).ok_or_else(|| {
                Error::Input(format!(
                    "boundary data `{}` of model `{}` is not given",
                    M::DATA[data],
                    M::NAME
                ))
            })?;
            for (side, x) in ends {
                let value = g(&[x]);
                if !value.is_finite() {
                    return Err(Error::Input(format!(
                        "boundary data `{}` of `{}` is {value} at x = {x}",
                        M::DATA[data],
                        M::FIELDS[field].name
                    )));
                }
                constraints.dirichlet::<M>(mesh, &dofs, M::FIELDS[field].name, side, value)?;
            }
        }
        Self::with_constraints::<M>(mesh, coefficients, dofs, &constraints, bilinear, linear)
    }
}

impl<G: DofNumbering + Clone> Discretization<G> {
    /// Assembles `bilinear` and `linear` of `M` on `mesh` with the DOFs `dofs`, eliminates
    /// the fixed DOFs of `constraints` and splits the system into the LCP blocks. The forms
    /// are named by handle (`M::SYSTEM`, `model::forms::B_h`) or by name (`"B_h"`).
    ///
    /// Only `constraints` are imposed: the model's `boundary:` conditions are the caller's
    /// to include ([`Discretization::new`] does on intervals,
    /// [`triangle::dirichlet_constraints_on`] on triangles).
    pub fn with_constraints<M: Model>(
        mesh: &G,
        coefficients: &Coefficients,
        dofs: SystemDofs,
        constraints: &Constraints,
        bilinear: impl IntoFormIndex<M>,
        linear: impl IntoFormIndex<M>,
    ) -> Result<Self> {
        Self::with_constraints_on::<M>(
            mesh,
            None,
            coefficients,
            dofs,
            constraints,
            bilinear,
            linear,
        )
    }

    /// [`Discretization::with_constraints`] with the element contributions of the cells
    /// `cells` of `mesh` alone (`None`: every cell): one MPI rank's share of a partition
    /// of the cells. The unknowns are the whole problem's (the DOFs, supports and
    /// multipliers of `mesh`), and every block of the LCP (`A`, `B`, `C`, `F`, `G`) is
    /// the sum of those cells' contributions, so the LCPs of a partition sum to the whole
    /// one. Each constraint of a multiplier on cells (P0, P1disc) lives on one cell: its
    /// rows of `B`, `C` and `G` are complete on the part holding that cell and zero on
    /// the others.
    ///
    /// # Errors
    /// Those of [`Discretization::with_constraints`]; a cell number beyond the mesh's.
    pub fn with_constraints_on<M: Model>(
        mesh: &G,
        cells: Option<&[usize]>,
        coefficients: &Coefficients,
        dofs: SystemDofs,
        constraints: &Constraints,
        bilinear: impl IntoFormIndex<M>,
        linear: impl IntoFormIndex<M>,
    ) -> Result<Self> {
        check_cells(cells, mesh.cell_count())?;
        let part = crate::mesh::CellSubset::new(mesh, cells);
        let multiplier = multiplier_field::<M>()?;
        let form = M::form(bilinear)?;
        let bilinear = M::FORMS[form].name;
        crate::model::require_symmetric::<M, G>(form, mesh, coefficients)?;
        let mut plans = block_plans::<M>(form, &dofs, true)?;
        let reduction = constraints.reduction(dofs.dof_count())?;
        let basis = constraints.change_of_basis(dofs.dof_count())?;
        let multiplier_range = dofs.range(multiplier).unwrap();
        let (roles, primal_reduced, multiplier_reduced) = roles_of(&reduction, &multiplier_range);
        let (n, m) = (primal_reduced.len(), multiplier_reduced.len());
        // Each full DOF's place in the LCP.
        let mut target: Vec<Target> = (0..dofs.dof_count())
            .map(|d| Target::Fixed(reduction.fixed_value(d)))
            .collect();
        for (&d, role) in reduction.free().iter().zip(&roles) {
            target[d] = match *role {
                Role::Primal(p) => Target::Primal(p),
                Role::Multiplier(k) => Target::Multiplier(k),
            };
        }
        let (rotated, extra_values) = rotated_groups(&basis, &mut target, n)?;
        let n_ext = n + extra_values.len();
        // The LCP takes B from the multiplier rows of B_h alone (B_h is symmetric): the
        // blocks of primal rows and multiplier columns would be computed, given scatter
        // positions and discarded, 3 of the 16 entries of a P1–P0 cell. They are needed
        // only where a multiplier DOF is fixed (its column moves to the right side).
        if !multiplier_range
            .clone()
            .any(|d| matches!(target[d], Target::Fixed(_)))
        {
            plans.retain(|p| !(p.trial_field == multiplier && p.test_field != multiplier));
        }
        let split = SplitPattern::new(&part, &dofs, &plans, &target, n_ext, m)?;
        // Written, not calloc'ed: the scatter's `+=` reads a calloc'ed page first, which
        // maps the shared zero page, and its write then faults again and flushes the
        // other core's TLB (measured at 2M P1–P0 cells: 4 % of the process's samples in
        // that copy-on-write fault, on the thread that bounds the finest level's setup).
        let mut values = Vec::new();
        values.resize(split.value_count, 0.0);
        let stride: usize = plans.iter().map(|p| p.rows * p.cols).sum();
        crate::assembly::add_form_matrices::<M, _>(
            form,
            &plans,
            &part,
            coefficients,
            &split.positions,
            &mut crate::kernel::Accumulator::new(&mut values),
        )?;
        if let Some(bad) = values.iter().position(|v| !v.is_finite()) {
            let entry = split
                .positions
                .iter()
                .position(|&p| p as usize == bad)
                .unwrap_or(0);
            return Err(Error::NonFinite {
                what: "matrix",
                cell: part.cell_number(entry / stride.max(1)),
            });
        }
        // L_h, less the columns of the fixed DOFs
        let mut rhs = assemble_vector::<M>(linear, &part, &dofs, coefficients)?;
        for (&(row, fixed), &v) in split.fixed_terms.iter().zip(&values[split.fixed_start..]) {
            rhs[row] -= v * fixed;
        }
        basis.to_primed(&mut rhs);
        let (a_len, b_len) = (split.a_rows.len(), split.b_columns.len());
        let (b_rows, multiplier_shift) = constraint_rows(
            &split,
            &values[a_len..a_len + b_len],
            &rotated,
            &extra_values,
            [n, m],
        )?;
        let (c, c_blocks) = multiplier_block(&split, &values[a_len + b_len..], m)
            .map_err(|e| {
                Error::Input(format!(
                    "the multiplier block of `{bilinear}`: {e}; this LCP form needs multipliers coupled only within a cell (P0, P1disc)"
                ))
            })?;
        // A's values lead the array: kept in place (a realloc that shrinks does not copy)
        // rather than copied out, 56 MB at 2M P1–P0 cells
        values.truncate(a_len);
        values.shrink_to_fit();
        let a: SparseMatrix = SparseColMat::new(
            SymbolicSparseColMat::new_checked(n_ext, n_ext, split.a_ptr, None, split.a_rows),
            values,
        );
        let free = reduction.free();
        let mut f: Vec<f64> = primal_reduced.iter().map(|&r| rhs[free[r]]).collect();
        let g = multiplier_reduced
            .iter()
            .zip(&multiplier_shift)
            .map(|(&r, shift)| shift - rhs[free[r]])
            .collect();
        let a = if rotated.is_empty() {
            a
        } else {
            // the extra unknowns' right sides, for `Reduction::rhs` to size the vector
            let mut extra = Constraints::new();
            for (j, &v) in extra_values.iter().enumerate() {
                extra.fix_dof(n + j, v)?;
            }
            let elimination = extra.reduction(n_ext)?;
            let a = congruence(&a, &rotated)?;
            f.resize(n_ext, 0.0);
            f = elimination.rhs(&a, &f);
            elimination.matrix(&a)
        };
        Ok(Self {
            mesh: mesh.clone(),
            dofs,
            reduction,
            lcp: Lcp {
                a,
                b_rows,
                c,
                c_blocks,
                f,
                g,
                share: None,
                near_null_space: Vec::new(),
            },
            multiplier_field: multiplier,
            multipliers: Multipliers::Cells,
            basis,
            roles,
            primal_reduced,
            multiplier_reduced,
            cells: cells.map(<[usize]>::to_vec),
        })
    }
}

/// Refuses cell numbers beyond a mesh of `count` cells (a part of a partition that
/// does not belong to the mesh).
pub(crate) fn check_cells(cells: Option<&[usize]>, count: usize) -> Result<()> {
    match cells.and_then(|cells| cells.iter().find(|&&c| c >= count)) {
        Some(c) => Err(Error::Input(format!(
            "cell {c} of a part is beyond the mesh's {count} cells"
        ))),
        None => Ok(()),
    }
}

/// This process's share of evaluating a solution cell by cell (the error norms, the
/// a-posteriori estimate): where the LCP was assembled in parts by several processes
/// that each hold the whole solution ([`Discretization::cells`], [`Lcp::share`]), each
/// evaluates its own cells and the sums add up over the processes, instead of every
/// process evaluating every cell. Every process calls the reductions in the same order
/// (they are collective); on one process they return their argument.
#[derive(Clone, Copy, Debug)]
pub struct Evaluation<'a> {
    cells: crate::mesh::Cells<'a>,
    count: usize,
    share: Option<&'a crate::lcp::Share>,
}

impl<'a> Evaluation<'a> {
    /// Every cell of a mesh of `count` cells, on one process.
    pub fn whole(count: usize) -> Self {
        Self {
            cells: crate::mesh::Cells::All(count),
            count,
            share: None,
        }
    }

    /// The cells this process evaluates.
    pub fn cells(self) -> crate::mesh::Cells<'a> {
        self.cells
    }

    /// Per cell of the whole mesh, whether this process evaluates it (`None`: every cell,
    /// on one process): what decides which process counts a facet between two cells.
    pub fn owned(self) -> Option<Vec<bool>> {
        let crate::mesh::Cells::Part(cells) = self.cells else {
            return None;
        };
        let mut owned = vec![false; self.count];
        for &c in cells {
            owned[c] = true;
        }
        Some(owned)
    }

    /// `values` summed entry by entry over the processes.
    pub fn sum<const N: usize>(self, mut values: [f64; N]) -> [f64; N] {
        self.sum_each(&mut values);
        values
    }

    /// `values` summed entry by entry over the processes, in place (every process with
    /// the same length).
    pub fn sum_each(self, values: &mut [f64]) {
        if let Some(share) = self.share {
            share.sum(values);
        }
    }

    /// `result` where it and every other process's succeeded; this process's error, or
    /// an error saying another process failed, where one did: every process then leaves
    /// the evaluation together, so none waits in a reduction for one that returned.
    ///
    /// # Errors
    /// As said.
    pub fn agree<T>(self, result: Result<T>) -> Result<T> {
        let Some(share) = self.share else {
            return result;
        };
        let failed = share.max(if result.is_err() { 1.0 } else { 0.0 });
        match result {
            Ok(_) if failed > 0.0 => Err(Error::Input(
                "the evaluation of the solution failed on another MPI process (its own error is printed there)"
                    .into(),
            )),
            other => other,
        }
    }
}

impl<G: Mesh> Discretization<G> {
    /// This process's share of evaluating the solution cell by cell: its own cells where
    /// the LCP is held in parts, every cell otherwise.
    pub fn evaluation(&self) -> Evaluation<'_> {
        match (&self.cells, &self.lcp.share) {
            (Some(cells), Some(share)) => Evaluation {
                cells: crate::mesh::Cells::Part(cells),
                count: self.mesh.cell_count(),
                share: Some(share),
            },
            _ => Evaluation::whole(self.mesh.cell_count()),
        }
    }
}

/// The role of each free DOF of `reduction` (a multiplier where it lies in
/// `multiplier_range`), and the reduced indices of the primal and the multiplier
/// unknowns in order.
fn roles_of(
    reduction: &Reduction,
    multiplier_range: &std::ops::Range<usize>,
) -> (Vec<Role>, Vec<usize>, Vec<usize>) {
    let mut roles = Vec::with_capacity(reduction.free().len());
    let (mut primal_reduced, mut multiplier_reduced) = (Vec::new(), Vec::new());
    for (r, &d) in reduction.free().iter().enumerate() {
        if multiplier_range.contains(&d) {
            roles.push(Role::Multiplier(multiplier_reduced.len()));
            multiplier_reduced.push(r);
        } else {
            roles.push(Role::Primal(primal_reduced.len()));
            primal_reduced.push(r);
        }
    }
    (roles, primal_reduced, multiplier_reduced)
}

/// A rotated group of DOFs (an oblique roller) as LCP indices with its rotation `T`.
type RotatedGroup = (
    crate::assembly::change_of_basis::DofGroup,
    [[f64; crate::assembly::change_of_basis::MAX_GROUP];
        crate::assembly::change_of_basis::MAX_GROUP],
);

/// The rotated groups of `basis` in LCP indices, and the values of their fixed DOFs. A
/// rotated group is assembled in its Cartesian DOFs, all of them primal unknowns (its
/// fixed primed DOFs as extra unknowns `n..`, which `target` then names), then rotated
/// (`T A Tᵀ`, `B Tᵀ`, `T F`) and its fixed primed DOFs eliminated.
///
/// # Errors
/// A multiplier DOF in a rotated group: supports are for the primal fields.
fn rotated_groups(
    basis: &ChangeOfBasis,
    target: &mut [Target],
    n: usize,
) -> Result<(Vec<RotatedGroup>, Vec<f64>)> {
    let mut extra_values = Vec::new();
    let mut rotated = Vec::with_capacity(basis.blocks().len());
    for block in basis.blocks() {
        let mut indices = block.group;
        for (k, index) in indices.dofs[..indices.len].iter_mut().enumerate() {
            let d = block.group.dofs[k];
            *index = match target[d] {
                Target::Primal(p) => p,
                Target::Fixed(v) => {
                    target[d] = Target::Primal(n + extra_values.len());
                    extra_values.push(v);
                    n + extra_values.len() - 1
                }
                Target::Multiplier(_) => {
                    return Err(Error::Input(format!(
                        "DOF {d} of the multiplier has a condition combining DOFs: supports are for the primal fields"
                    )))
                }
            };
        }
        rotated.push((indices, block.t));
    }
    Ok((rotated, extra_values))
}

/// B = −(the multiplier rows of B_h), without its zeros (`values`: the assembled
/// entries of `split`'s B pattern); rotated, `B_h Tᵀ` less the columns of the fixed
/// primed DOFs `n..` (values `extra_values`), which move to the multiplier rows' right
/// side: the `m` rows and that shift of each.
///
/// # Errors
/// Rows that do not make [`ConstraintRows`].
fn constraint_rows(
    split: &SplitPattern,
    values: &[f64],
    rotated: &[RotatedGroup],
    extra_values: &[f64],
    [n, m]: [usize; 2],
) -> Result<(ConstraintRows, Vec<f64>)> {
    let rotation = BlockRotation::new(rotated, n + extra_values.len());
    let mut b_ptr = Vec::with_capacity(m + 1);
    let mut b_entries = Vec::with_capacity(values.len());
    let mut multiplier_shift = vec![0.0; m];
    let mut row = Vec::new();
    b_ptr.push(0);
    for (k, shift) in multiplier_shift.iter_mut().enumerate() {
        row.clear();
        let entries = split.b_ptr[k]..split.b_ptr[k + 1];
        for (&v, &column) in values[entries.clone()]
            .iter()
            .zip(&split.b_columns[entries])
        {
            if v != 0.0 {
                rotation.spread(column, v, &mut row);
            }
        }
        if !rotated.is_empty() {
            row.sort_unstable_by_key(|&(q, _)| q);
            let mut merged: Vec<(usize, f64)> = Vec::with_capacity(row.len());
            for &(q, v) in &row {
                match merged.last_mut() {
                    Some(last) if last.0 == q => last.1 += v,
                    _ => merged.push((q, v)),
                }
            }
            row.clear();
            for (q, v) in merged {
                if q >= n {
                    *shift += v * extra_values[q - n];
                } else if v != 0.0 {
                    row.push((q, v));
                }
            }
        }
        b_entries.extend(row.iter().map(|&(q, v)| (q, -v)));
        b_ptr.push(b_entries.len());
    }
    Ok((
        ConstraintRows::from_flat(b_ptr, b_entries)?,
        multiplier_shift,
    ))
}

/// C = −(the multiplier block of B_h) from `values` (the assembled entries of `split`'s
/// C pattern: the `m` diagonal entries, then the couplings within a cell, P1disc).
///
/// # Errors
/// Couplings that do not make [`CouplingBlocks`] (the message, for the caller to name
/// the form).
fn multiplier_block(
    split: &SplitPattern,
    values: &[f64],
    m: usize,
) -> std::result::Result<(Vec<f64>, CouplingBlocks), String> {
    let c: Vec<f64> = values[..m].iter().map(|v| -v).collect();
    let coupling: Vec<(usize, usize, f64)> = split
        .coupling
        .iter()
        .zip(&values[m..])
        .filter(|(_, &v)| v != 0.0)
        .map(|(&(k, l), &v)| (k, l, -v))
        .collect();
    let blocks = CouplingBlocks::from_entries(m, &coupling).map_err(|e| e.to_string())?;
    Ok((c, blocks))
}

/// Where a DOF of the full system goes in the LCP.
#[derive(Clone, Copy, Debug)]
enum Target {
    Primal(usize),
    Multiplier(usize),
    /// A fixed DOF with its value.
    Fixed(f64),
}

/// The patterns of the LCP blocks of a bilinear form, built straight from the element
/// DOFs (no pattern of the whole saddle-point system, no copies of it: at 524k
/// triangles those cost more than the assembly itself), and the position of every
/// element-matrix entry in one value array laid out as
/// `[A (CSC) | B (rows) | diag C | off-diagonal C entries | fixed-column entries | discard]`.
struct SplitPattern {
    a_ptr: Vec<usize>,
    a_rows: Vec<usize>,
    b_ptr: Vec<usize>,
    b_columns: Vec<usize>,
    /// `(k, l)` of each off-diagonal `C` slot.
    coupling: Vec<(usize, usize)>,
    /// Where the fixed-column slots start, and `(full row, fixed value)` of each.
    fixed_start: usize,
    fixed_terms: Vec<(usize, f64)>,
    value_count: usize,
    positions: Vec<Position>,
}

impl SplitPattern {
    fn new<G: Mesh>(
        mesh: &G,
        dofs: &SystemDofs,
        plans: &[BlockPlan],
        target: &[Target],
        n: usize,
        m: usize,
    ) -> Result<Self> {
        // Bucket A's rows by column and B's columns by row (counting sort); each entry
        // remembers its bucket slot, and the slot learns its place in the pattern when the
        // buckets are sorted and deduplicated (no search per entry).
        let mut a_count = vec![0usize; n + 1];
        let mut b_count = vec![0usize; m + 1];
        let mut entries = 0;
        for_each_entry(mesh, dofs, plans, |r, c| {
            entries += 1;
            match (target[r], target[c]) {
                (Target::Primal(_), Target::Primal(q)) => a_count[q + 1] += 1,
                (Target::Multiplier(k), Target::Primal(_)) => b_count[k + 1] += 1,
                _ => {}
            }
        });
        for j in 0..n {
            a_count[j + 1] += a_count[j];
        }
        for k in 0..m {
            b_count[k + 1] += b_count[k];
        }
        // an entry's provisional place, one `Position`: A's bucket slots, then B's, then
        // the diagonal of C, then the per-occurrence slots (at most one per entry);
        // `DISCARDED` is discarded. Buckets and places are 32-bit: at 2M cells they are
        // 56M indices, and memory first touched costs time (docs/multigrid.md).
        const DISCARDED: Position = Position::MAX;
        let a_slots = a_count[n];
        let b_slots = b_count[m];
        let occurrence_base = a_slots + b_slots + m;
        // every provisional place (A's and B's slots and the per-occurrence ones, at most
        // one per entry, then C's diagonal) and every bucket entry (an index below n)
        // stays below this, and so below `DISCARDED`
        kernel::position(entries + m + n)?;
        let mut a_bucket: Vec<Position> = vec![0; a_slots];
        let mut b_bucket: Vec<Position> = vec![0; b_slots];
        let (mut a_fill, mut b_fill) = (a_count.clone(), b_count.clone());
        // off-diagonal C and fixed-column entries get one slot per occurrence (summed
        // later); everything else of B_h (the rows of fixed DOFs, the Bᵀ block) is
        // discarded into the last slot
        let mut coupling = Vec::new();
        let mut fixed_terms = Vec::new();
        let mut slots = Vec::new();
        // sized ahead: one per entry, millions of them
        let mut positions = Vec::with_capacity(entries);
        for_each_entry(mesh, dofs, plans, |r, c| {
            let at = match (target[r], target[c]) {
                (Target::Primal(p), Target::Primal(q)) => {
                    let slot = a_fill[q];
                    a_bucket[slot] = p as Position;
                    a_fill[q] += 1;
                    slot
                }
                (Target::Multiplier(k), Target::Primal(q)) => {
                    let slot = b_fill[k];
                    b_bucket[slot] = q as Position;
                    b_fill[k] += 1;
                    a_slots + slot
                }
                (Target::Multiplier(k), Target::Multiplier(l)) if k == l => a_slots + b_slots + k,
                (Target::Multiplier(k), Target::Multiplier(l)) => {
                    coupling.push((k, l));
                    slots.push(Slot::Coupling);
                    occurrence_base + slots.len() - 1
                }
                (Target::Primal(_) | Target::Multiplier(_), Target::Fixed(v)) if v != 0.0 => {
                    fixed_terms.push((r, v));
                    slots.push(Slot::Fixed);
                    occurrence_base + slots.len() - 1
                }
                _ => DISCARDED as usize,
            };
            // checked above: every provisional place fits
            positions.push(at as Position);
        });
        drop((a_fill, b_fill));
        // sorts each bucket, keeps its distinct indices and turns every slot of the
        // bucket into the position of its index in the pattern
        let compress = |count: &[usize], bucket: &mut [Position]| {
            let mut ptr = Vec::with_capacity(count.len());
            ptr.push(0);
            let mut idx = Vec::with_capacity(bucket.len());
            let mut group: Vec<(Position, usize)> = Vec::new();
            for j in 0..count.len() - 1 {
                group.clear();
                group.extend((count[j]..count[j + 1]).map(|slot| (bucket[slot], slot)));
                group.sort_unstable();
                let mut last = None;
                for &(i, slot) in &group {
                    if last != Some(i) {
                        idx.push(i as usize);
                        last = Some(i);
                    }
                    bucket[slot] = (idx.len() - 1) as Position;
                }
                ptr.push(idx.len());
            }
            (ptr, idx)
        };
        let (a_ptr, a_rows) = compress(&a_count, &mut a_bucket);
        let (b_ptr, b_columns) = compress(&b_count, &mut b_bucket);
        let b_start = a_rows.len();
        let c_start = b_start + b_columns.len();
        let coupling_start = c_start + m;
        // Give the per-occurrence slots their places: coupling ones first, then fixed.
        let fixed_start = coupling_start + coupling.len();
        let discard = fixed_start + fixed_terms.len();
        let mut place = Vec::with_capacity(slots.len());
        let (mut next_coupling, mut next_fixed) = (coupling_start, fixed_start);
        for slot in &slots {
            match slot {
                Slot::Coupling => {
                    place.push(next_coupling);
                    next_coupling += 1;
                }
                Slot::Fixed => {
                    place.push(next_fixed);
                    next_fixed += 1;
                }
            }
        }
        // the final places are below the provisional ones' bound: the pattern has at
        // most one entry per bucket slot
        for at in &mut positions {
            let provisional = *at as usize;
            let final_place = if provisional < a_slots {
                a_bucket[provisional] as usize
            } else if provisional < a_slots + b_slots {
                b_start + b_bucket[provisional - a_slots] as usize
            } else if provisional < occurrence_base {
                c_start + (provisional - a_slots - b_slots)
            } else if *at != DISCARDED {
                place[provisional - occurrence_base]
            } else {
                discard
            };
            *at = final_place as Position;
        }
        Ok(Self {
            a_ptr,
            a_rows,
            b_ptr,
            b_columns,
            coupling,
            fixed_start,
            fixed_terms,
            value_count: discard + 1,
            positions,
        })
    }
}

/// A slot of one occurrence of an entry.
enum Slot {
    Coupling,
    Fixed,
}

impl<G> Discretization<G> {
    /// The multiplier's DOFs on a boundary part; `None` for a multiplier on the cells.
    pub fn boundary(&self) -> Option<&boundary_multiplier::BoundaryMultiplierDofs> {
        match &self.multipliers {
            Multipliers::Boundary(b) => Some(b),
            Multipliers::Cells | Multipliers::Nodal => None,
        }
    }

    /// For each constraint of the LCP, the DOF (numbered within the multiplier field) of
    /// its multiplier; on a boundary part, the constraint's own index.
    pub fn multiplier_dofs(&self) -> Vec<usize> {
        match &self.multipliers {
            Multipliers::Boundary(b) => return (0..b.count()).collect(),
            Multipliers::Nodal => return (0..self.lcp.m()).collect(),
            Multipliers::Cells => {}
        }
        let offset = self.dofs.offset(self.multiplier_field).unwrap_or(0);
        self.multiplier_reduced
            .iter()
            .map(|&r| self.reduction.free()[r] - offset)
            .collect()
    }

    /// [`Discretization::full`] of the primal unknowns `u` with every multiplier 0.
    pub fn full_of_primal(&self, u: Vec<f64>) -> Vec<f64> {
        self.full(&LcpSolution {
            u,
            lambda: vec![0.0; self.lcp.m()],
            iterations: 0,
            kkt_residual: 0.0,
            seconds: 0.0,
            factorizations: 0,
            low_rank_updates: 0,
            multiplier_noise: 0.0,
            iterative_steps: 0,
            krylov_iterations: 0,
        })
    }

    /// The full coefficient vector (all fields, boundary values included, Cartesian
    /// DOFs: mapped back from the primed ones of [`Discretization::basis`]) of an LCP
    /// solution: the DOFs of `dofs`, followed on a boundary part by the multiplier's.
    pub fn full(&self, solution: &LcpSolution) -> Vec<f64> {
        if !matches!(self.multipliers, Multipliers::Cells) {
            let mut full = self.reduction.expand(&solution.u);
            full.extend_from_slice(&solution.lambda);
            return full;
        }
        let mut reduced = vec![0.0; self.roles.len()];
        for (p, &r) in self.primal_reduced.iter().enumerate() {
            reduced[r] = solution.u[p];
        }
        for (k, &r) in self.multiplier_reduced.iter().enumerate() {
            reduced[r] = solution.lambda[k];
        }
        let mut full = self.reduction.expand(&reduced);
        self.basis.to_cartesian(&mut full);
        full
    }

    /// The multipliers of a full coefficient vector, in the order of the LCP's constraints.
    pub fn multiplier_part(&self, full: &[f64]) -> Vec<f64> {
        if !matches!(self.multipliers, Multipliers::Cells) {
            return full[self.dofs.dof_count()..].to_vec();
        }
        self.multiplier_reduced
            .iter()
            .map(|&r| full[self.reduction.free()[r]])
            .collect()
    }

    /// The coefficients of the multiplier in a full coefficient vector, numbered as its
    /// field's DOFs (on a boundary part: its constraints).
    pub fn multiplier_coefficients<'v>(&self, full: &'v [f64]) -> &'v [f64] {
        match &self.multipliers {
            Multipliers::Boundary(_) | Multipliers::Nodal => &full[self.dofs.dof_count()..],
            Multipliers::Cells => &full[self.dofs.range(self.multiplier_field).unwrap()],
        }
    }

    /// The primal unknowns of a full coefficient vector (Cartesian DOFs, as
    /// [`Discretization::full`] gives; a start for Newton): in the primed DOFs of
    /// [`Discretization::basis`], which the LCP is in.
    pub fn primal_part(&self, full: &[f64]) -> Vec<f64> {
        let primed;
        let full = if self.basis.is_identity() {
            full
        } else {
            primed = {
                let mut x = full.to_vec();
                self.basis.to_primed(&mut x);
                x
            };
            &primed
        };
        self.primal_reduced
            .iter()
            .map(|&r| full[self.reduction.free()[r]])
            .collect()
    }
}

/// Interpolates the fields of `coarse` (a coefficient vector on `coarse_dofs`) at the DOFs
/// of a finer mesh: values and slopes at vertices, Lagrange nodes, P0 cell midpoints.
pub fn prolong<M: Model>(
    coarse_mesh: &IntervalMesh,
    coarse_dofs: &SystemDofs,
    coarse: &[f64],
    fine_mesh: &IntervalMesh,
    fine_dofs: &SystemDofs,
) -> Vec<f64> {
    let mut fine = vec![0.0; fine_dofs.dof_count()];
    for &field in fine_dofs.fields() {
        let (Some(map_c), Some(map_f)) = (coarse_dofs.map(field), fine_dofs.map(field)) else {
            continue;
        };
        let range = coarse_dofs.range(field).unwrap();
        let view = FieldView {
            mesh: coarse_mesh,
            map: map_c,
            coefficients: &coarse[range],
        };
        let element = map_f.element();
        let basis = PhysicalBasis::new(element, 1);
        let offset = fine_dofs.offset(field).unwrap();
        let mut functionals = Vec::new();
        for c in 0..fine_mesh.cell_count() {
            dof_functionals(element, fine_mesh.cell(c), &mut functionals);
            for (i, &(x, derivative)) in functionals.iter().enumerate() {
                fine[offset + map_f.cell_dofs(c)[i]] =
                    view.at_with(&basis, x, derivative).unwrap_or(0.0);
            }
        }
    }
    fine
}

/// The DOF functionals of `element` on the interval `cell`, in the element's local
/// order, into `out`: `(x, k)` for `ℓ_i(v) = v⁽ᵏ⁾(x)`, the values and slopes at the
/// vertices (Hermite) and the Lagrange nodes. An element without vertex DOFs (P0, and
/// P1disc, whose DOFs are not point values here) gets the midpoint for each DOF: exact for
/// P0, a piecewise-constant approximation otherwise.
pub(crate) fn dof_functionals(element: ElementKind, cell: [f64; 2], out: &mut Vec<(f64, usize)>) {
    let map = Affine::interval(cell);
    let nodes = element.lagrange_nodes();
    let mut interior = 0;
    out.clear();
    out.extend(element.dofs().iter().map(|location| match *location {
        DofLocation::Vertex { vertex, derivative } => (cell[vertex], derivative),
        DofLocation::Interior if element.dofs_per_vertex() == 0 => (map.point([0.5])[0], 0),
        DofLocation::Interior => {
            let xi = nodes.map_or(0.5, |n| n[2 * element.dofs_per_vertex() + interior]);
            interior += 1;
            (map.point([xi])[0], 0)
        }
    }));
}

/// The forms `B_h`, `L_h` of `M` that the obstacle solvers assemble ([`Model::SYSTEM`]).
///
/// # Errors
/// [`Error::Input`] for a model without a bilinear form `B_h` and a linear form `L_h`.
pub fn system_forms<M: Model>() -> Result<(FormId<M>, FormId<M>)> {
    let [bilinear, linear] = M::SYSTEM.ok_or_else(|| {
        Error::Input(format!(
            "model `{}` has no bilinear form `B_h` and linear form `L_h`, the system the obstacle solvers assemble",
            M::NAME
        ))
    })?;
    Ok((FormId::new(bilinear), FormId::new(linear)))
}

/// A solved obstacle problem.
pub struct ObstacleSolution<G = IntervalMesh> {
    /// The discrete problem on the finest mesh.
    pub discretization: Discretization<G>,
    /// Coefficients of all fields (multiplier included).
    pub values: Vec<f64>,
    /// Iterations on the finest mesh.
    pub iterations: usize,
    /// Numeric factorizations on the finest mesh.
    pub factorizations: usize,
    /// Newton steps on the finest mesh solved through a low-rank update of the last
    /// factorization instead of a new one.
    pub low_rank_updates: usize,
    /// `(cells, iterations)` of every level of the nested iteration.
    pub levels: Vec<(usize, usize)>,
    /// KKT residual of the result.
    pub kkt_residual: f64,
    /// Wall time of the whole solve (assembly included).
    pub seconds: f64,
    /// Wall time of the LCP solve on the finest mesh alone.
    pub solve_seconds: f64,
    /// Estimated relative rounding noise of the multiplier values (0: none).
    pub multiplier_noise: f64,
    /// Newton steps of the finest level solved by multigrid-preconditioned CG
    /// ([`ObstacleOptions::linear_solver`]).
    pub iterative_steps: usize,
    /// CG iterations over those steps.
    pub krylov_iterations: usize,
}

impl<G> ObstacleSolution<G> {
    /// What solved the finest level's Newton steps, as the reports name it: `multigrid`
    /// when any step was solved by CG with a multigrid cycle (`iterative_steps > 0`; the
    /// count of factorizations tells whether others were factored), else `direct`.
    pub fn linear_solver_name(&self) -> &'static str {
        if self.iterative_steps > 0 {
            "multigrid"
        } else {
            "direct"
        }
    }

    /// The contact set per cell: the share of the cell's multiplier DOFs in contact,
    /// active (λ above 1e-8 of the multiplier scale) or touching (constraint residual
    /// negligible; [`triangle::contact_indicator`]), so holes of zero λ_h where u_h lies
    /// on ψ are filled. One number in `[0, 1]` per cell; the multiplier's DOFs must be
    /// owned by the cells (P0, P1disc: cell `c` owns DOFs `c·k..(c+1)·k`), as those of
    /// the LCP models are.
    pub fn contact_shares(&self) -> Vec<f64> {
        let d = &self.discretization;
        let active = triangle::contact_indicator(
            &d.lcp,
            &d.primal_part(&self.values),
            &d.multiplier_part(&self.values),
        );
        let map = d.dofs.map(d.multiplier_field).unwrap();
        let per_cell = map.local_count();
        let mut share = vec![0.0; map.dof_count() / per_cell.max(1)];
        for (k, &dof) in d.multiplier_dofs().iter().enumerate() {
            if active[k] {
                share[dof / per_cell] += 1.0 / per_cell as f64;
            }
        }
        share
    }

    /// How far the primal coefficients may be off through the rounding of the rows in
    /// contact ([`Lcp::primal_rounding`]), in the units of the primal field: compare it
    /// with the size of u, ψ or g. Far below them unless the load dwarfs the obstacle.
    pub fn primal_rounding(&self) -> f64 {
        let d = &self.discretization;
        d.lcp.primal_rounding(
            &d.primal_part(&self.values),
            &d.multiplier_part(&self.values),
        )
    }
}

/// Options of [`solve_obstacle`].
#[derive(Clone, Copy, Debug)]
pub struct ObstacleOptions {
    /// The algorithm.
    pub solver: VariationalSolver,
    /// Nested iteration from meshes of at least this many cells (uniform meshes only;
    /// `None`: a cold start on the final mesh).
    pub nested_from: Option<usize>,
    /// Newton options.
    pub newton: NewtonOptions,
    /// Build the finest level on a second thread while the coarser ones are solved
    /// (see [`solve_nested`]); `false` does everything on the calling thread.
    pub pipelined: bool,
    /// The solver of the Newton steps: direct, or multigrid on the nested meshes where
    /// the solve has them ([`hierarchy`]).
    pub linear_solver: LinearSolver,
    /// The cycle of the multigrid steps (W(1,1): on the Newton Hessians of the membrane
    /// its CG iterations stay flat across the contact boundary, `docs/multigrid.md`).
    pub multigrid: MultigridOptions,
}

impl Default for ObstacleOptions {
    fn default() -> Self {
        Self {
            solver: VariationalSolver::SemismoothNewton,
            nested_from: Some(16),
            newton: NewtonOptions::default(),
            pipelined: true,
            linear_solver: LinearSolver::Auto,
            multigrid: MultigridOptions {
                sweeps: 1,
                coarse_corrections: 2,
            },
        }
    }
}

/// Solves one LCP with the algorithm of `options`, from `start` (primal unknowns) if given.
pub fn solve_lcp(
    lcp: &Lcp,
    start: Option<&[f64]>,
    options: ObstacleOptions,
) -> Result<LcpSolution> {
    solve_lcp_prepared(lcp, None, start, options)
}

/// [`solve_lcp`] with semismooth Newton's pattern work (Hessian pattern, symbolic
/// Cholesky) done ahead in `workspace`, if given (other solvers ignore it).
pub fn solve_lcp_prepared(
    lcp: &Lcp,
    workspace: Option<&NewtonWorkspace>,
    start: Option<&[f64]>,
    options: ObstacleOptions,
) -> Result<LcpSolution> {
    solve_lcp_on_hierarchy(lcp, workspace, &[], start, options)
}

/// [`solve_lcp_prepared`] with the prolongations of the primal unknowns from the coarser
/// levels of a nested solve, fine to coarse (`prolongations[0]` maps the next coarser
/// level's to `lcp`'s), for the multigrid steps of [`ObstacleOptions::linear_solver`].
pub fn solve_lcp_on_hierarchy(
    lcp: &Lcp,
    workspace: Option<&NewtonWorkspace>,
    prolongations: &[SparseMatrix],
    start: Option<&[f64]>,
    options: ObstacleOptions,
) -> Result<LcpSolution> {
    if lcp.share.is_some() && !matches!(options.solver, VariationalSolver::External(_)) {
        return Err(Error::Input(format!(
            "this LCP is one process's part of a partitioned assembly: only the solver that partitioned it solves it, not {}",
            options.solver.name()
        )));
    }
    let multigrid = prolongations.first().is_some_and(|p| p.nrows() == lcp.n())
        && options.linear_solver.uses_multigrid(prolongations.len());
    match options.solver {
        // Newton with Λ eliminated (SPD Hessian, one symbolic Cholesky); if it fails,
        // the active-set method on the saddle-point system. Where the eliminated Λ
        // loses digits to cancellation (C = αh⁵ on fine meshes), Λ is recovered from
        // one saddle-point solve on the converged active set.
        VariationalSolver::SemismoothNewton => {
            // From a nested start Newton needs a handful of iterations where it works
            // at all: fail over to the saddle-point method early.
            let newton = NewtonOptions {
                max_iterations: if start.is_some() {
                    options.newton.max_iterations.min(40)
                } else {
                    options.newton.max_iterations
                },
                ..options.newton
            };
            let mut steps = MultigridSteps::new(lcp, prolongations, options.multigrid);
            let mut step = |s: NewtonStep<'_>| steps.solve(s);
            let newton = match (workspace, multigrid) {
                (Some(w), true) => semismooth_newton_with(lcp, w, &mut step, start, newton),
                (None, true) => NewtonWorkspace::pattern_of(lcp)
                    .and_then(|w| semismooth_newton_with(lcp, &w, &mut step, start, newton)),
                (Some(w), false) => semismooth_newton_prepared(lcp, w, start, newton),
                (None, false) => semismooth_newton(lcp, start, newton),
            };
            let krylov_iterations = steps.krylov_iterations;
            let newton = newton.map(|mut s| {
                s.krylov_iterations = krylov_iterations;
                s
            });
            let solution = match newton {
                Ok(s) => s,
                // the fallback factors an LU per iteration: give it fewer
                Err(newton) => primal_dual_active_set(
                    lcp,
                    start,
                    NewtonOptions {
                        max_iterations: options.newton.max_iterations.min(50),
                        ..options.newton
                    },
                )
                .map_err(|pdas| Error::NotConverged {
                    solver: "semismooth Newton and the saddle-point active-set method",
                    detail: format!("{newton}; {pdas}"),
                })?,
            };
            if lcp.elimination_noise(&solution.lambda) > 1e-6 {
                // The recovery factors the saddle-point system by LU, whose fill under
                // partial pivoting can be ten times the Newton factor's (the Argyris
                // plate at N = 112: 4.5 GB against 0.5 GB). Where faer reports that it
                // ran out of memory, the solution stands with its eliminated Λ and the
                // noise estimate that says how far to trust it; any other failure is
                // reported as before.
                match recover_multiplier(lcp, solution.clone(), options.newton.refinement_steps) {
                    Err(Error::LinearSolve(m)) if m.contains("out of memory") => Ok(solution),
                    recovered => recovered,
                }
            } else {
                Ok(solution)
            }
        }
        VariationalSolver::Clarabel => quadratic_program(lcp),
        VariationalSolver::External(external) => external.0.solve(lcp, start),
    }
}

/// Solves the obstacle problem `B_h`, `L_h` of `M` on `mesh`.
///
/// With `options.linear_solver` [`LinearSolver::Multigrid`] the Newton steps of every
/// level above the coarsest of the nested iteration are solved by CG with a multigrid
/// cycle on the nested uniform meshes ([`hierarchy::interval_primal_prolongation`]:
/// Lagrange nodes and Hermite slopes); `Auto` factors (banded, `O(N)` on an interval).
pub fn solve_obstacle<M: Model>(
    mesh: &IntervalMesh,
    coefficients: &Coefficients,
    clamped: &[&str],
    options: ObstacleOptions,
) -> Result<ObstacleSolution> {
    // Nested iteration over uniform meshes: N/2^k, …, N/2, N.
    let uniform = IntervalMesh::uniform(
        mesh.vertices()[0],
        *mesh.vertices().last().unwrap(),
        mesh.cell_count(),
    )
    .map(|u| {
        u.vertices()
            .iter()
            .zip(mesh.vertices())
            .all(|(a, b)| (a - b).abs() <= 1e-12 * (1.0 + a.abs()))
    })
    .unwrap_or(false);
    let (bilinear, linear) = system_forms::<M>()?;
    let mut sizes = vec![mesh.cell_count()];
    if let (Some(min), true, true) = (options.nested_from, uniform, options.solver.nests()) {
        while sizes[0] % 2 == 0 && sizes[0] / 2 >= min.max(1) {
            sizes.insert(0, sizes[0] / 2);
        }
    }
    let (a, b) = (mesh.vertices()[0], *mesh.vertices().last().unwrap());
    let last = sizes.len() - 1;
    let levels = sizes
        .into_iter()
        .enumerate()
        .map(|(level, cells)| {
            move || {
                let level_mesh = if level == last {
                    mesh.clone()
                } else {
                    IntervalMesh::uniform(a, b, cells)?
                };
                Discretization::new::<M>(&level_mesh, coefficients, clamped, bilinear, linear)
            }
        })
        .collect();
    solve_nested_on_hierarchy(
        levels,
        |coarse, values, fine| {
            prolong::<M>(&coarse.mesh, &coarse.dofs, values, &fine.mesh, &fine.dofs)
        },
        Some(&hierarchy::interval_primal_prolongation),
        options,
    )
}

/// Solves the LCP of each level in turn, each started from the solution of the level
/// before, carried over by `prolong` (nested iteration); returns the last level's.
///
/// `levels` build the discretizations, coarsest first. The last level, the most costly
/// to build (assembly, and for Newton the Hessian pattern and its symbolic Cholesky
/// factorization), does not depend on the coarser solutions: it is built on a second
/// thread while the coarser levels are solved, so that on two cores only the numeric
/// part of the last level follows the coarse solves; its symbolic factorization may
/// still run there during Newton's first, smoothed step, which needs only the pattern.
pub fn solve_nested<G, B>(
    levels: Vec<B>,
    prolong: impl Fn(&Discretization<G>, &[f64], &Discretization<G>) -> Vec<f64>,
    options: ObstacleOptions,
) -> Result<ObstacleSolution<G>>
where
    G: DofNumbering + Send + Sync,
    B: FnOnce() -> Result<Discretization<G>> + Send,
{
    solve_nested_on_hierarchy(levels, prolong, None, options)
}

/// The prolongation of the LCP's primal unknowns from a coarser level to the next finer
/// one ([`hierarchy::primal_prolongation`] on triangles), for multigrid Newton steps.
pub type PrimalProlongation<G> =
    dyn Fn(&Discretization<G>, &Discretization<G>) -> Result<SparseMatrix> + Sync;

/// [`solve_nested`] whose levels also form the multigrid hierarchy of the Newton steps
/// ([`ObstacleOptions::linear_solver`]): `primal_prolongation` maps each level's primal
/// unknowns to the next finer level's. Where it fails (elements without a prolongation)
/// the levels above are solved directly. With a `primal_prolongation` (multigrid asked
/// for) the second thread builds the finest Hessian's pattern but not its symbolic
/// factorization, which Newton then computes only if a step is factored.
pub fn solve_nested_on_hierarchy<G, B>(
    levels: Vec<B>,
    prolong: impl Fn(&Discretization<G>, &[f64], &Discretization<G>) -> Vec<f64>,
    primal_prolongation: Option<&PrimalProlongation<G>>,
    options: ObstacleOptions,
) -> Result<ObstacleSolution<G>>
where
    G: DofNumbering + Send + Sync,
    B: FnOnce() -> Result<Discretization<G>> + Send,
{
    solve_nested_from(levels, prolong, primal_prolongation, None, options)
}

/// The first start of a nested solve: its judgement of a level ([`LevelStart`]), where
/// Newton starts on the first level solved (and again where a prolonged start fails);
/// an error refuses the problem (e.g. a body whose rigid motion nothing holds).
///
/// The level may be one process's part of a partitioned assembly ([`Lcp::share`]): a
/// start reads the whole LCP through the parts' reductions ([`Lcp::whole`],
/// [`Lcp::largest`]), called on every process alike.
///
/// [`Lcp::share`]: crate::lcp::Lcp::share
/// [`Lcp::whole`]: crate::lcp::Lcp::whole
/// [`Lcp::largest`]: crate::lcp::Lcp::largest
pub type FirstStart<'a, G> = dyn Fn(&Discretization<G>) -> Result<LevelStart> + Sync + 'a;

/// The near null space of a level's `A` without its supports, as vectors of the
/// level's free primal unknowns ([`Lcp::near_null_space`]): an elastic body's rigid
/// motions. Called on each level (possibly one process's part: it reads the mesh, the
/// DOFs and the reduction, not the LCP's blocks) where an external solver solves.
///
/// [`Lcp::near_null_space`]: crate::lcp::Lcp::near_null_space
pub type NearNullSpace<'a, G> = dyn Fn(&Discretization<G>) -> Vec<Vec<f64>> + Sync + 'a;

/// How a level of a nested solve starts when no coarser solution is prolonged to it.
#[derive(Clone, Debug, PartialEq)]
pub enum LevelStart {
    /// From zero.
    Zero,
    /// From these primal unknowns (the free DOFs of the level's discretization).
    At(Vec<f64>),
    /// Not on this level: it has no solution (the reason), though a finer one may, e.g.
    /// a contact boundary whose few constraints cannot hold a rigid motion the supports
    /// leave free. Nested iteration leaves the level out; on the finest level the reason
    /// is the solve's error ([`Error::Input`]).
    TooCoarse(String),
}

impl LevelStart {
    /// The start vector, `None` for zero.
    ///
    /// # Errors
    /// [`Error::Input`] with the reason of a level [`LevelStart::TooCoarse`].
    pub fn vector(self) -> Result<Option<Vec<f64>>> {
        match self {
            Self::Zero => Ok(None),
            Self::At(x) => Ok(Some(x)),
            Self::TooCoarse(reason) => Err(Error::Input(reason)),
        }
    }
}

/// [`solve_nested_on_hierarchy`] whose coarsest level starts from `first_start`'s
/// vector (semismooth Newton from zero otherwise).
pub fn solve_nested_from<G, B>(
    levels: Vec<B>,
    prolong: impl Fn(&Discretization<G>, &[f64], &Discretization<G>) -> Vec<f64>,
    primal_prolongation: Option<&PrimalProlongation<G>>,
    first_start: Option<&FirstStart<'_, G>>,
    options: ObstacleOptions,
) -> Result<ObstacleSolution<G>>
where
    G: DofNumbering + Send + Sync,
    B: FnOnce() -> Result<Discretization<G>> + Send,
{
    let clock = Instant::now();
    // Only a multigrid step reads the prolongations: with `auto` choosing the direct
    // path they would be built on every level for nothing (0.3 s at 1M unknowns).
    let primal_prolongation = primal_prolongation.filter(|_| {
        options.solver == VariationalSolver::SemismoothNewton
            && options.linear_solver.uses_multigrid(1)
    });
    let mut levels = levels;
    let finest = levels
        .pop()
        .ok_or_else(|| Error::Input("no mesh to solve on".into()))?;
    let newton = options.solver == VariationalSolver::SemismoothNewton;
    // Newton's own checks (positive C) come with the solve, where their error is
    // reported; a workspace that cannot be built is simply not used.
    let pattern_of = move |d: &Discretization<G>| {
        if newton {
            NewtonWorkspace::pattern_of(&d.lcp).ok()
        } else {
            None
        }
    };
    let solve_finest = |coarse: Option<SolvedLevel<G>>,
                        d: &Discretization<G>,
                        workspace: Option<&NewtonWorkspace>| {
        // the finest level is judged too: one without an equilibrium is refused
        let first = first_start.map(|f| f(d)).transpose()?;
        let hierarchy = extend_hierarchy(coarse.as_ref(), d, primal_prolongation);
        let solution = solve_level(
            d,
            coarse.as_ref(),
            &prolong,
            workspace,
            &hierarchy,
            first,
            options,
        )?;
        let mut counts = coarse.map(|(_, _, counts, _)| counts).unwrap_or_default();
        counts.push((d.mesh.cell_count(), solution.iterations));
        Ok::<_, Error>((solution, counts))
    };
    let (discretization, (solution, counts)) = if levels.is_empty() || !options.pipelined {
        let coarse = solve_levels(levels, &prolong, primal_prolongation, first_start, options)?;
        let d = finest()?;
        let workspace = pattern_of(&d);
        let solved = solve_finest(coarse, &d, workspace.as_ref())?;
        (d, solved)
    } else {
        // The worker hands the discretization and the Hessian pattern over as soon as
        // they exist, then computes the symbolic factorization, which Newton's first,
        // smoothed step does not need: the start is prolonged and that step taken
        // meanwhile.
        let (sender, receiver) = std::sync::mpsc::channel();
        // Multigrid steps need no factorization of the finest Hessian (a step whose CG
        // fails analyses it then): AMD and the symbolic factorization would cost the
        // worker 0.6 s and 0.3 GB at 1M unknowns for nothing. (With multigrid asked for
        // on elements without a prolongation every step factors, and the analysis then
        // runs on this thread: that request is warned about as unused.)
        let factors = primal_prolongation.is_none();
        let worker = move || {
            let built = finest().map(|d| {
                let workspace = pattern_of(&d);
                Arc::new((d, workspace))
            });
            let shared = built.as_ref().ok().map(Arc::clone);
            let _ = sender.send(built);
            if let Some(workspace) = shared
                .as_ref()
                .and_then(|s| s.1.as_ref())
                .filter(|_| factors)
            {
                // an error here is Newton's to report when it factors
                let _ = workspace.analyse();
            }
        };
        let (solved, shared) = alongside(worker, || {
            let coarse = solve_levels(levels, &prolong, primal_prolongation, first_start, options);
            // the coarse levels' error first, as in the sequential order
            match (coarse, receiver.recv()) {
                (Err(e), _) | (Ok(_), Ok(Err(e))) => (Err(e), None),
                (Ok(coarse), Ok(Ok(shared))) => {
                    let solved = solve_finest(coarse, &shared.0, shared.1.as_ref());
                    (solved, Some(shared))
                }
                // the worker panicked: the panic resumes when it is joined
                (Ok(_), Err(_)) => (
                    Err(Error::Input("the finest level was not built".into())),
                    None,
                ),
            }
        });
        let solved = solved?;
        let shared = shared.expect("a solved finest level was built");
        // the worker has finished and dropped its handle
        let (d, _) = Arc::try_unwrap(shared)
            .map_err(|_| Error::Input("the finest discretization is still shared".into()))?;
        (d, solved)
    };
    let values = discretization.full(&solution);
    Ok(ObstacleSolution::of(
        &solution,
        discretization,
        values,
        counts,
        clock.elapsed().as_secs_f64(),
    ))
}

/// Runs `worker` on another thread while `main` runs on this one; returns `main`'s result
/// once both have finished (a panic of either resumes here).
///
/// The other thread is kept for the process (one, whatever the number of solves):
/// allocations made on a fresh thread are fresh memory for the allocator, which the
/// kernel faults in and zeroes page by page — at 524k triangles that cost more than the
/// finest level's assembly. Called from that thread itself (a level built by a nested
/// solve), a scoped thread runs `worker` instead, as when the kept one cannot start.
pub fn alongside<R>(worker: impl FnOnce() + Send, main: impl FnOnce() -> R) -> R {
    static KEPT: OnceLock<Option<rayon::ThreadPool>> = OnceLock::new();
    let kept = KEPT.get_or_init(|| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .thread_name(|_| "fem-forms finest level".into())
            .build()
            .ok()
    });
    match kept {
        Some(pool) if pool.current_thread_index().is_none() => pool.in_place_scope(|scope| {
            scope.spawn(move |_| worker());
            main()
        }),
        _ => std::thread::scope(|scope| {
            scope.spawn(worker);
            main()
        }),
    }
}

/// A level's discretization, its solution's full coefficients, the (cells, iterations)
/// of every level so far, and the prolongations of the primal unknowns down to the
/// coarsest level, fine to coarse (empty without a multigrid hierarchy).
type SolvedLevel<G> = (
    Discretization<G>,
    Vec<f64>,
    Vec<(usize, usize)>,
    Vec<SparseMatrix>,
);

/// The multigrid hierarchy of `fine`: the prolongation from `coarse`'s level followed by
/// `coarse`'s own hierarchy; empty without a coarse level or a `primal_prolongation`, or
/// where it fails (then the level is solved directly; so is every finer one, whose chain
/// would have to pass through it).
fn extend_hierarchy<G>(
    coarse: Option<&SolvedLevel<G>>,
    fine: &Discretization<G>,
    primal_prolongation: Option<&PrimalProlongation<G>>,
) -> Vec<SparseMatrix> {
    let (Some((c, _, counts, below)), Some(prolongation)) = (coarse, primal_prolongation) else {
        return Vec::new();
    };
    // a coarse level that is not the coarsest but has no hierarchy broke the chain
    if below.is_empty() && counts.len() > 1 {
        return Vec::new();
    }
    match prolongation(c, fine) {
        Ok(p) => std::iter::once(p).chain(below.iter().cloned()).collect(),
        Err(_) => Vec::new(),
    }
}

/// Solves level `d`: from `coarse`'s solution prolonged where there is a coarser level,
/// else from `first`, the first start's judgement of `d` (from zero without one). A
/// body that only contact holds is singular where no constraint is active, and a
/// prolonged start can open every contact the finer level has (a block whose one coarse
/// contact edge split in two): where Newton fails from the prolonged start, the level
/// is solved again from the first start, which holds such a body.
///
/// # Errors
/// [`Error::Input`] with the reason of a level `first` calls
/// [`LevelStart::TooCoarse`], and the solver's from the last start tried.
fn solve_level<G: Mesh>(
    d: &Discretization<G>,
    coarse: Option<&SolvedLevel<G>>,
    prolong: &impl Fn(&Discretization<G>, &[f64], &Discretization<G>) -> Vec<f64>,
    workspace: Option<&NewtonWorkspace>,
    hierarchy: &[SparseMatrix],
    first: Option<LevelStart>,
    options: ObstacleOptions,
) -> Result<LcpSolution> {
    let retry = first.is_some();
    let first = first.map(LevelStart::vector).transpose()?.flatten();
    let from_first =
        || solve_lcp_on_hierarchy(&d.lcp, workspace, hierarchy, first.as_deref(), options);
    let Some((c, values, _, _)) = coarse else {
        return from_first();
    };
    let start = d.primal_part(&prolong(c, values, d));
    match solve_lcp_on_hierarchy(&d.lcp, workspace, hierarchy, Some(&start), options) {
        Err(Error::NotConverged { .. } | Error::LinearSolve(_)) if retry => from_first(),
        other => other,
    }
}

/// Builds and solves `levels` in turn, each from the prolonged solution of the last one
/// solved; a level the first start calls [`LevelStart::TooCoarse`] is left out (nested
/// iteration begins on the first level it accepts, and the load's quadrature on a
/// coarse level can judge a level finer than an accepted one unbalanced). The last one
/// solved, or `None` for no levels.
fn solve_levels<G: Mesh, B: FnOnce() -> Result<Discretization<G>>>(
    levels: Vec<B>,
    prolong: &impl Fn(&Discretization<G>, &[f64], &Discretization<G>) -> Vec<f64>,
    primal_prolongation: Option<&PrimalProlongation<G>>,
    first_start: Option<&FirstStart<'_, G>>,
    options: ObstacleOptions,
) -> Result<Option<SolvedLevel<G>>> {
    let mut last: Option<SolvedLevel<G>> = None;
    for build in levels {
        let d = build()?;
        let first = first_start.map(|f| f(&d)).transpose()?;
        if let Some(LevelStart::TooCoarse(_)) = first {
            continue;
        }
        let hierarchy = extend_hierarchy(last.as_ref(), &d, primal_prolongation);
        let solution = solve_level(&d, last.as_ref(), prolong, None, &hierarchy, first, options)?;
        let mut counts = last.map(|(_, _, counts, _)| counts).unwrap_or_default();
        counts.push((d.mesh.cell_count(), solution.iterations));
        let values = d.full(&solution);
        last = Some((d, values, counts, hierarchy));
    }
    Ok(last)
}

impl<G> ObstacleSolution<G> {
    /// The solution of `discretization` that the LCP's `solution` gives: its full
    /// coefficients `values`, `(cells, iterations)` of each level solved and the whole
    /// solve's `seconds`, with the LCP solver's counts.
    pub(crate) fn of(
        solution: &LcpSolution,
        discretization: Discretization<G>,
        values: Vec<f64>,
        levels: Vec<(usize, usize)>,
        seconds: f64,
    ) -> Self {
        Self {
            iterations: solution.iterations,
            factorizations: solution.factorizations,
            low_rank_updates: solution.low_rank_updates,
            kkt_residual: solution.kkt_residual,
            solve_seconds: solution.seconds,
            multiplier_noise: solution.multiplier_noise,
            iterative_steps: solution.iterative_steps,
            krylov_iterations: solution.krylov_iterations,
            discretization,
            values,
            levels,
            seconds,
        }
    }

    /// The coefficients of model field `field`.
    ///
    /// # Panics
    /// When `field` is not a field of the solved model: take the index from
    /// `Model::field(name)`, which names the fields when it errs.
    pub fn field(&self, field: usize) -> &[f64] {
        let d = &self.discretization;
        if field == d.multiplier_field {
            return d.multiplier_coefficients(&self.values);
        }
        &self.values[d.dofs.range(field).unwrap()]
    }

    /// The multiplier's coefficients (by its DOFs on the cells, or by the constraints of
    /// a boundary part).
    pub fn multiplier_values(&self) -> &[f64] {
        self.field(self.discretization.multiplier_field)
    }

    /// The contact cells: indices of the cells on which some multiplier coefficient is
    /// positive, i.e. above 1e-8 of the larger of its maximum and the load's multiplier
    /// scale ‖F‖∞/‖Bᵀ‖∞ (so that solver noise is not contact), in increasing order.
    /// Works on any cell kind; cells touching the obstacle with `λ_h = 0` are not
    /// included (see [`ObstacleSolution::contact_set`] on intervals, which fills them).
    pub fn contact_cells(&self) -> Vec<usize> {
        let d = &self.discretization;
        let lambda = self.field(d.multiplier_field);
        let largest = lambda.iter().cloned().fold(0.0, f64::max);
        let scale = largest.max(d.lcp.multiplier_scale());
        if largest <= 1e-8 * scale {
            return Vec::new();
        }
        let map = d.dofs.map(d.multiplier_field).unwrap();
        let cells = map.dof_count() / map.local_count().max(1);
        let mut contact = Vec::new();
        for c in 0..cells {
            if map.cell_dofs(c).iter().any(|&k| lambda[k] > 1e-8 * scale) {
                contact.push(c);
            }
        }
        contact
    }
}

impl<G: DofNumbering> ObstacleSolution<G> {
    /// The energy `½ a(u,u) − ℓ(u)` of the primal fields `u` (all fields but the
    /// multiplier) of the solution, with the model's energy forms ([`Model::ENERGY`])
    /// and the parameters and data of `coefficients`; the boundary values of the
    /// solution are included as they are. For the exact solution of the obstacle
    /// problem it is the minimum of the energy over the admissible set.
    ///
    /// Computed in twice the working precision: `½uᵀAu` of a thin structure is a small
    /// difference of huge terms.
    ///
    /// # Errors
    /// If `M` declares no energy, or if `M` is not the model the solution was computed
    /// with (its fields do not fit the mesh).
    pub fn energy<M: Model>(&self, coefficients: &Coefficients) -> Result<f64> {
        let d = &self.discretization;
        let primal: Vec<usize> = (0..M::FIELDS.len())
            .filter(|&f| f != d.multiplier_field && !M::FIELDS[f].nonnegative)
            .collect();
        let dofs = SystemDofs::new::<M>(&d.mesh, &primal)?;
        let mut u = Vec::with_capacity(dofs.dof_count());
        for &f in &primal {
            let range = d.dofs.range(f).ok_or_else(|| {
                Error::Input(format!(
                    "the solution has no field {f} of model `{}`: solved with another model?",
                    M::NAME
                ))
            })?;
            u.extend_from_slice(&self.values[range]);
        }
        if u.len() != dofs.dof_count() {
            return Err(Error::Input(format!(
                "the solution's fields do not fit model `{}`: solved with another model?",
                M::NAME
            )));
        }
        let [a, load] = M::ENERGY.ok_or_else(|| {
            Error::Input(format!(
                "model `{}` declares no energy (`energy: a, ℓ;`)",
                M::NAME
            ))
        })?;
        // on a partitioned level, this process's cells, the energy summed over them all
        let cells = crate::mesh::CellSubset::new(&d.mesh, d.cells.as_deref());
        let a = crate::assembly::MatrixAssembler::new::<M>(FormId::new(a), &cells, &dofs)?
            .assemble::<M>(&cells, coefficients)?;
        let l = assemble_vector::<M>(FormId::new(load), &cells, &dofs, coefficients)?;
        let energy = 0.5 * crate::lcp::cholesky::quadratic_form(&a, &u, &u)
            - crate::lcp::cholesky::dot(&l, &u);
        Ok(match &d.lcp.share {
            Some(share) if d.cells.is_some() => {
                let mut total = [energy];
                share.sum(&mut total);
                total[0]
            }
            _ => energy,
        })
    }
}

impl ObstacleSolution<IntervalMesh> {
    /// A view of model field `field` for evaluation and norms.
    pub fn view(&self, field: usize) -> FieldView<'_> {
        FieldView {
            mesh: &self.discretization.mesh,
            map: self.discretization.dofs.map(field).unwrap(),
            coefficients: self.field(field),
        }
    }

    /// The multiplier per cell (P0).
    pub fn multiplier(&self) -> &[f64] {
        self.field(self.discretization.multiplier_field)
    }

    /// `∫ λ_h`: the total contact force.
    pub fn total_contact_force(&self) -> f64 {
        self.view(self.discretization.multiplier_field).integral()
    }

    /// The contact set: runs of cells with `λ_h > 0` (above 1e-8 of the larger of its
    /// maximum and the load's multiplier scale, so solver noise is not contact), holes
    /// between runs filled when the beam touches there (zero gap), and a run at most two cells wide reported as a point
    /// contact at its λ-weighted centre.
    pub fn contact_set(&self) -> Vec<[f64; 2]> {
        let lambda = self.multiplier();
        let mesh = &self.discretization.mesh;
        let largest = lambda.iter().cloned().fold(0.0, f64::max);
        let scale = largest.max(self.discretization.lcp.multiplier_scale());
        if largest <= 1e-8 * scale {
            return Vec::new();
        }
        let active: Vec<bool> = lambda.iter().map(|&l| l > 1e-8 * scale).collect();
        // A cell touches when its constraint residual R_k is negligible against the
        // terms it is made of: holes of touching cells are filled, real gaps are not.
        // Of an LCP held in parts (`Lcp::share`) the residuals are sums over the parts,
        // and a constraint on cells lives on one part, where its terms are complete.
        let lcp = &self.discretization.lcp;
        let u = self.discretization.primal_part(&self.values);
        let c_lambda = lcp.c_times(lambda);
        let (residual, terms): (Vec<f64>, Vec<f64>) = (0..lcp.m())
            .map(|k| {
                let row = &lcp.b_rows[k];
                let bu: f64 = row.iter().map(|&(j, v)| v * u[j]).sum();
                let terms =
                    row.iter().map(|&(j, v)| (v * u[j]).abs()).sum::<f64>() + lcp.g[k].abs();
                (bu + c_lambda[k] - lcp.g[k], terms)
            })
            .unzip();
        let (residual, terms) = (lcp.whole(residual), lcp.whole(terms));
        let touching = |k: usize| residual[k].abs() <= 1e-6 * terms[k];
        let mut runs: Vec<(usize, usize)> = Vec::new();
        for (c, &on) in active.iter().enumerate() {
            if on {
                match runs.last_mut() {
                    Some((_, end)) if (*end + 1..c).all(touching) => *end = c,
                    _ => runs.push((c, c)),
                }
            }
        }
        runs.into_iter()
            .map(|(first, last)| {
                if last - first < 2 {
                    let (mut weight, mut moment) = (0.0, 0.0);
                    for (c, l) in lambda.iter().enumerate().take(last + 1).skip(first) {
                        let x = 0.5 * (mesh.cell(c)[0] + mesh.cell(c)[1]);
                        weight += l * mesh.h(c);
                        moment += l * mesh.h(c) * x;
                    }
                    let x = moment / weight;
                    [x, x]
                } else {
                    [mesh.cell(first)[0], mesh.cell(last)[1]]
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::triangle::solve_obstacle_on_triangles;
    use super::*;
    use crate::mesh::{Diagonal, TriangleMesh};

    crate::model! {
        /// A clamped string over an obstacle, P1 / P0 (for P1 `u'' = 0`, so `S_h` acts on λ).
        pub mod string_p1 on interval {
            unknowns: u: P1, λ: P0 >= 0;
            tests: v, μ;
            params: alpha;
            data: f, ψ;
            forms: "
                a(u;v)       = ∫ u'v'
                b(v;μ)       = ∫ v μ
                S(u,λ;v,μ)   = Σ_T h_T² (−u'' − λ, −v'' − μ)_T
                ℓ(v)         = ∫ f v
                ℓ_S(v,μ)     = Σ_T h_T² (f, −v'' − μ)_T
                G(μ)         = ∫ ψ μ
                B_h(u,λ;v,μ) = a(u;v) − b(v;λ) − b(u;μ) − alpha S(u,λ;v,μ)
                L_h(v,μ)     = ℓ(v) − G(μ) − alpha ℓ_S(v,μ)
            ";
        }
    }

    crate::model! {
        /// The P1 / P0 membrane with Dirichlet data `u = g`.
        pub mod membrane_p1 on triangle {
            unknowns: u: P1, λ: P0 >= 0;
            tests: v, μ;
            params: alpha;
            data: f, ψ, g;
            boundary: u = g;
            forms: "
                a(u;v)       = ∫ ∇u·∇v
                b(v;μ)       = ∫ v μ
                S(u,λ;v,μ)   = Σ_T h_T² (−Δu − λ, −Δv − μ)_T
                ℓ(v)         = ∫ f v
                ℓ_S(v,μ)     = Σ_T h_T² (f, −Δv − μ)_T
                G(μ)         = ∫ ψ μ
                B_h(u,λ;v,μ) = a(u;v) − b(v;λ) − b(u;μ) − alpha S(u,λ;v,μ)
                L_h(v,μ)     = ℓ(v) − G(μ) − alpha ℓ_S(v,μ)
            ";
        }
    }

    crate::model! {
        /// The string with Dirichlet data `u = g` at both ends.
        pub mod string_dirichlet on interval {
            unknowns: u: P1, λ: P0 >= 0;
            tests: v, μ;
            params: alpha;
            data: f, ψ, g;
            boundary: u = g;
            forms: "
                a(u;v)       = ∫ u'v'
                b(v;μ)       = ∫ v μ
                S(u,λ;v,μ)   = Σ_T h_T² (−u'' − λ, −v'' − μ)_T
                ℓ(v)         = ∫ f v
                ℓ_S(v,μ)     = Σ_T h_T² (f, −v'' − μ)_T
                G(μ)         = ∫ ψ μ
                B_h(u,λ;v,μ) = a(u;v) − b(v;λ) − b(u;μ) − alpha S(u,λ;v,μ)
                L_h(v,μ)     = ℓ(v) − G(μ) − alpha ℓ_S(v,μ)
            ";
        }
    }

    crate::model! {
        /// The string with its system under other names than `B_h`, `L_h`.
        pub mod string_renamed on interval {
            unknowns: u: P1, λ: P0 >= 0;
            tests: v, μ;
            data: f, ψ;
            forms: "
                K(u,λ;v,μ) = ∫ u'v' − λ v − u μ
                F(v,μ)     = ∫ f v − ψ μ
            ";
        }
    }

    /// The solvers find the system through `Model::SYSTEM`: a model without `B_h`, `L_h`
    /// is a clear error, and its forms still assemble by handle or name.
    #[test]
    fn the_system_is_found_at_compile_time_and_its_absence_is_named() {
        assert_eq!(
            string_p1::Model::SYSTEM,
            Some([
                string_p1::Model::form("B_h").unwrap(),
                string_p1::Model::form("L_h").unwrap()
            ])
        );
        assert_eq!(string_renamed::Model::SYSTEM, None);
        let (one, low) = (|_: &[f64]| 1.0, |_: &[f64]| -1.0);
        let c =
            Coefficients::new::<string_renamed::Model>(&[], &[("f", &one), ("ψ", &low)]).unwrap();
        let mesh = IntervalMesh::uniform(0.0, 1.0, 8).unwrap();
        let error = solve_obstacle::<string_renamed::Model>(&mesh, &c, &["u"], Default::default())
            .err()
            .unwrap()
            .to_string();
        assert!(error.contains("no bilinear form `B_h`"), "{error}");
        let d = Discretization::new::<string_renamed::Model>(
            &mesh,
            &c,
            &["u"],
            string_renamed::forms::K,
            string_renamed::forms::F,
        );
        assert!(d.is_ok());
    }

    /// `boundary: u = g` on an interval model (issue 11: it used to be ignored): with
    /// `f = 0` and `g = 1 + x` on (0, 1) the solution is `u = 1 + x`, energy ½, on every
    /// level of the nested iteration; a `g` that is infinite at an end is an error naming
    /// it.
    #[test]
    fn interval_boundary_data_is_imposed() {
        let (zero, obstacle) = (|_: &[f64]| 0.0, |_: &[f64]| -10.0);
        let g = |x: &[f64]| 1.0 + x[0];
        let c = Coefficients::new::<string_dirichlet::Model>(
            &[("alpha", 0.1)],
            &[("f", &zero), ("ψ", &obstacle), ("g", &g)],
        )
        .unwrap();
        let mesh = IntervalMesh::uniform(0.0, 1.0, 32).unwrap();
        let s =
            solve_obstacle::<string_dirichlet::Model>(&mesh, &c, &[], Default::default()).unwrap();
        let u = s.view(0);
        for x in [0.0, 0.25, 0.6, 1.0] {
            assert!((u.at(x, 0).unwrap() - (1.0 + x)).abs() < 1e-12, "u({x})");
        }
        let energy = s.energy::<string_dirichlet::Model>(&c).unwrap();
        assert!((energy - 0.5).abs() < 1e-12, "{energy}");
        let bad = |x: &[f64]| 1.0 / x[0];
        let c = Coefficients::new::<string_dirichlet::Model>(
            &[("alpha", 0.1)],
            &[("f", &zero), ("ψ", &obstacle), ("g", &bad)],
        )
        .unwrap();
        let error = solve_obstacle::<string_dirichlet::Model>(&mesh, &c, &[], Default::default())
            .err()
            .unwrap()
            .to_string();
        assert!(error.contains("`g` of `u` is inf at x = 0"), "{error}");
    }

    fn string(f: f64, psi: f64, cells: usize) -> (ObstacleSolution, f64) {
        let (load, obstacle) = (move |_: &[f64]| f, move |_: &[f64]| psi);
        let c = Coefficients::new::<string_p1::Model>(
            &[("alpha", 0.1)],
            &[("f", &load), ("ψ", &obstacle)],
        )
        .unwrap();
        let mesh = IntervalMesh::uniform(0.0, 1.0, cells).unwrap();
        let s = solve_obstacle::<string_p1::Model>(&mesh, &c, &["u"], Default::default()).unwrap();
        let energy = s.energy::<string_p1::Model>(&c).unwrap();
        (s, energy)
    }

    /// `−u'' = 1`, `u(0) = u(1) = 0` far above the obstacle: P1 is nodally exact in 1D
    /// (and `S_h` has no primal part), so `½a(u_h,u_h) − ℓ(u_h) = −½ℓ(u_h) = −½ ∫ I_h u`
    /// with `u = x(1−x)/2`: the trapezoid rule, `−(1 − h²)/24`. No contact.
    #[test]
    fn string_energy_without_contact_is_the_trapezoid_value() {
        for cells in [4, 10] {
            let h = 1.0 / cells as f64;
            let (s, energy) = string(1.0, -10.0, cells);
            let expected = -(1.0 - h * h) / 24.0;
            assert!((energy - expected).abs() < 1e-12, "{energy} vs {expected}");
            assert!(s.contact_cells().is_empty());
            assert!(s.total_contact_force().abs() < 1e-12);
        }
    }

    /// Pushed down (`f = −1`) onto `ψ = 0`: `u = 0`, `λ = 1` everywhere, so every cell is
    /// in contact, `∫λ = 1` and the energy is 0.
    #[test]
    fn string_pressed_flat_is_in_contact_everywhere() {
        let (s, energy) = string(-1.0, 0.0, 8);
        assert_eq!(s.contact_cells(), (0..8).collect::<Vec<_>>());
        assert!((s.total_contact_force() - 1.0).abs() < 1e-10);
        assert!(energy.abs() < 1e-12, "{energy}");
    }

    fn membrane(f: f64, psi: f64, g: fn(&[f64]) -> f64) -> (ObstacleSolution<TriangleMesh>, f64) {
        let (load, obstacle) = (move |_: &[f64]| f, move |_: &[f64]| psi);
        let c = Coefficients::new::<membrane_p1::Model>(
            &[("alpha", 0.1)],
            &[("f", &load), ("ψ", &obstacle), ("g", &g)],
        )
        .unwrap();
        let mesh = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 4, 4, Diagonal::Right).unwrap();
        let s = solve_obstacle_on_triangles::<membrane_p1::Model>(&[mesh], &c, Default::default())
            .unwrap();
        let energy = s.energy::<membrane_p1::Model>(&c).unwrap();
        (s, energy)
    }

    /// `u = x` on the boundary, `f = 0`, obstacle far below: `u_h = x` exactly, so the
    /// energy is `½ ∫ |∇x|² = ½` on the unit square, with the boundary values included.
    #[test]
    fn membrane_energy_of_a_linear_solution() {
        let (s, energy) = membrane(0.0, -10.0, |x| x[0]);
        assert!((energy - 0.5).abs() < 1e-12, "{energy}");
        assert!(s.contact_cells().is_empty());
    }

    /// u = g on the left and right sides only, `∂u/∂n = 0` on top and bottom: with
    /// g = x + 7x(1 − x) (= x on the sides, not on top and bottom), f = 0 and the
    /// obstacle far below, the solution is u = x, which P1 reproduces exactly, on every
    /// level of a nested solve (refinement keeps the sides' markers).
    #[test]
    fn membrane_with_natural_condition_on_top_and_bottom() {
        use crate::assembly::boundary::DirichletPart;
        use crate::obstacle::triangle::solve_obstacle_on_part;
        let (load, obstacle) = (|_: &[f64]| 0.0, |_: &[f64]| -10.0);
        let g = |x: &[f64]| x[0] + 7.0 * x[0] * (1.0 - x[0]);
        let c = Coefficients::new::<membrane_p1::Model>(
            &[("alpha", 0.1)],
            &[("f", &load), ("ψ", &obstacle), ("g", &g)],
        )
        .unwrap();
        let coarse = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 4, 4, Diagonal::Right).unwrap();
        let meshes = [coarse.clone(), coarse.refine_uniformly()];
        let sides =
            DirichletPart::Markers(coarse.boundary_part_markers(&["left", "right"]).unwrap());
        let s =
            solve_obstacle_on_part::<membrane_p1::Model>(&meshes, &c, &sides, Default::default())
                .unwrap();
        let u = s.field(0);
        for (v, x) in s.discretization.mesh.vertices().iter().enumerate() {
            assert!((u[v] - x[0]).abs() < 1e-12, "vertex {v} at {x:?}: {}", u[v]);
        }
        // on the whole boundary the same data give another solution
        let all =
            solve_obstacle_on_triangles::<membrane_p1::Model>(&meshes, &c, Default::default())
                .unwrap();
        assert!(all.field(0).iter().zip(u).any(|(a, b)| (a - b).abs() > 0.1));
        // no Dirichlet edge: refused, not solved
        let none = DirichletPart::Markers(vec![99]);
        let Err(e) =
            solve_obstacle_on_part::<membrane_p1::Model>(&meshes, &c, &none, Default::default())
        else {
            panic!("a problem without Dirichlet edge was solved");
        };
        let e = e.to_string();
        assert!(e.contains("not coercive") && e.contains("u = g"), "{e}");
    }

    /// Pushed down onto `ψ = 0 = g`: every cell is in contact, `∫λ = 1`, energy 0.
    #[test]
    fn membrane_pressed_flat_is_in_contact_everywhere() {
        let (s, energy) = membrane(-1.0, 0.0, |_| 0.0);
        assert_eq!(s.contact_cells(), (0..32).collect::<Vec<_>>());
        assert!((s.total_contact_force() - 1.0).abs() < 1e-10);
        assert!(energy.abs() < 1e-12, "{energy}");
    }
}
