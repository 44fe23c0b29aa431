//! Multigrid for the Newton steps of a nested solve (issue 15, `docs/multigrid.md` §4):
//! the meshes of the nested iteration are the multigrid hierarchy, the prolongation of
//! the LCP's primal unknowns from one level to the next is that of the finite element
//! fields restricted to the free primal DOFs, and each Newton step `H d = −∇Φ` is solved by
//! conjugate gradients preconditioned with a cycle on the Galerkin operators `PᵀHP`.

use super::Discretization;
use crate::element::interval::PhysicalBasis;
use crate::error::{Error, Result};
use crate::lcp::{Lcp, NewtonStep};
use crate::mesh::{IntervalMesh, TriangleMesh};
use crate::multigrid::{
    parents_by_location, prolongation, Multigrid, MultigridOptions, NestedLevel,
};
use crate::SparseMatrix;
use faer::sparse::{SparseColMat, Triplet};
use fem_reference::DofLocation;

/// The linear solver of the Newton steps of an obstacle solve.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LinearSolver {
    /// A sparse Cholesky factorization per step (or a low-rank update of the last one):
    /// about `O(N^1.5)` in 2D and `O(N)` on intervals, the faster one on small systems,
    /// and the only one for elements without a triangle prolongation (Hermite triangles,
    /// Argyris, Morley).
    Direct,
    /// Conjugate gradients preconditioned by a multigrid cycle on the nested meshes of
    /// the solve (`O(N)` per step). Levels without a coarser one, and steps whose CG does
    /// not reach [`MULTIGRID_TOLERANCE`] in [`MULTIGRID_MAX_ITERATIONS`], are factored.
    Multigrid,
    /// The faster one as measured: [`LinearSolver::Direct`] for the Newton steps of the
    /// eliminated LCP (the stabilized pairs) at every size, see [`LinearSolver::uses_multigrid`];
    /// the nodal method takes multigrid from `obstacle::nodal::NODAL_AUTO_MULTIGRID_UNKNOWNS`.
    Auto,
}

/// Relative residual `‖b − Hd‖₂/‖b‖₂` at which CG ends a Newton step. Newton's test
/// certifies the result by the KKT residual anyway; steps this accurate keep the
/// active-set iteration that of factored steps.
pub const MULTIGRID_TOLERANCE: f64 = 1e-10;

/// A Newton step's CG may stop once `‖b − Hd‖₂ ≤ MULTIGRID_ROUNDING_FLOOR · scale`
/// ([`NewtonStep::scale`], the size of the terms the gradient balances) even above
/// [`MULTIGRID_TOLERANCE`] relative to `‖b‖₂`: such a step is exact to the rounding of the
/// gradient. The nodal method polishes to the same `1e-14` of its right-hand side; at
/// 1e-10 its mean nodal error was 0.3 % off the factored solution's (`docs/multigrid.md`).
pub const MULTIGRID_ROUNDING_FLOOR: f64 = 1e-14;

/// The loosest relative tolerance the rounding floor may give a step (for gradients at
/// the rounding level itself, where Newton is about to stop anyway).
const MULTIGRID_LOOSEST_FLOOR: f64 = 1e-3;

/// Relative residual at which CG ends a Newton step while the active set still changes
/// ([`NewtonStep::settled`] false), for inexact Newton steps (Dembo, Eisenstat and
/// Steihaug 1982); Newton converges only after an exact step. Measured on membrane-radial
/// (`docs/multigrid.md`, "Multigrid in Newton"): from nested starts Newton needs 2–4
/// steps a level, and the last step before the active set settles is usually the last
/// one, so loose steps add a Newton iteration per level (1e-6: P1–P0 at 261k unknowns 4
/// iterations and 18 CG iterations against 3 and 16 exact) and save nothing: off (equal
/// to [`MULTIGRID_TOLERANCE`]) until a cheaper final test exists.
pub const MULTIGRID_INEXACT_TOLERANCE: f64 = MULTIGRID_TOLERANCE;

/// The inexact Newton steps of one solve: later steps are solved to
/// [`MULTIGRID_TOLERANCE`] whether or not the active set has settled. Inexact directions
/// can keep a few constraints flipping without end (measured: P1–P0 at 1M unknowns with
/// V-cycles and a tolerance of 1e-4, 40 Newton iterations without settling), exact ones
/// settle in finitely many steps.
pub const MULTIGRID_INEXACT_STEPS: usize = 3;

/// CG iterations after which a Newton step is given to the factorization instead.
pub const MULTIGRID_MAX_ITERATIONS: usize = 80;

impl LinearSolver {
    /// Every solver, by its name on the command line.
    pub const ALL: [LinearSolver; 3] = [
        LinearSolver::Auto,
        LinearSolver::Direct,
        LinearSolver::Multigrid,
    ];

    /// The name (`--linear-solver`).
    pub fn name(self) -> &'static str {
        match self {
            LinearSolver::Direct => "direct",
            LinearSolver::Multigrid => "multigrid",
            LinearSolver::Auto => "auto",
        }
    }

    /// The solver called `name`.
    ///
    /// # Errors
    /// [`Error::Input`] listing the names when there is none of that name.
    pub fn parse(name: &str) -> Result<Self> {
        Self::ALL
            .into_iter()
            .find(|s| s.name() == name)
            .ok_or_else(|| {
                Error::Input(format!(
                    "unknown linear solver `{name}`; the linear solvers are {}",
                    Self::ALL.map(Self::name).join(", ")
                ))
            })
    }

    /// Whether the Newton steps of an LCP with `coarser` levels below it are solved by
    /// multigrid: asked for and a coarser level exists.
    ///
    /// [`LinearSolver::Auto`] is direct: the direct path factors once per level and
    /// solves the later steps by low-rank updates of that factor, as cheap as a few
    /// W-cycles, and it was faster at every size measured (membrane-radial P1–P0,
    /// 2026-12-01, `seconds` direct / multigrid: 0.26 / 0.37 s at 65k primal unknowns,
    /// 0.92 / 1.41 at 261k, 4.7 / 6.9 at 1.05M, 29.8 / 42.3 at 4.2M; P2–P0 1.6–2× slower
    /// with multigrid before, docs/multigrid.md "Multigrid in Newton"). Multigrid takes
    /// 10–20 % less memory; `--linear-solver multigrid` asks for it.
    pub fn uses_multigrid(self, coarser: usize) -> bool {
        self == LinearSolver::Multigrid && coarser > 0
    }
}

/// The prolongation of the LCP's primal unknowns from `coarse` to `fine` (two
/// discretizations of one model on nested triangle meshes): the fields' interpolation
/// ([`prolongation`]) on the free DOFs, restricted to the primal ones. A `fine.lcp.n() ×
/// coarse.lcp.n()` matrix.
///
/// # Errors
/// Meshes that are not nested (a fine cell outside every coarse one), elements without a
/// prolongation (Hermite, Argyris, Morley), other fields on the two levels.
pub fn primal_prolongation(
    coarse: &Discretization<TriangleMesh>,
    fine: &Discretization<TriangleMesh>,
) -> Result<SparseMatrix> {
    if let Some(field) = fine.dofs.fields().iter().find(|&&f| {
        f != fine.multiplier_field
            && fine
                .dofs
                .map(f)
                .is_some_and(|m| m.element().needs_transformation())
    }) {
        return Err(Error::Input(format!(
            "no multigrid prolongation for field {field}: its element has a per-cell DOF transformation"
        )));
    }
    let parents = parents_by_location(&coarse.mesh, &fine.mesh)?;
    let full = prolongation(&level(coarse), &level(fine), &parents)?;
    // reduced (free) DOF → primal unknown, on each level
    let primal_index = |d: &Discretization<TriangleMesh>| {
        let mut index = vec![usize::MAX; d.reduction.free().len()];
        for (p, &r) in d.primal_reduced.iter().enumerate() {
            index[r] = p;
        }
        index
    };
    let (rows, columns) = (primal_index(fine), primal_index(coarse));
    let (col_ptr, row_idx, values) = (
        full.symbolic().col_ptr(),
        full.symbolic().row_idx(),
        full.val(),
    );
    let mut triplets = Vec::with_capacity(values.len());
    for j in 0..full.ncols() {
        let column = columns[j];
        if column == usize::MAX {
            continue;
        }
        for k in col_ptr[j]..col_ptr[j + 1] {
            let row = rows[row_idx[k]];
            if row != usize::MAX {
                triplets.push(Triplet::new(row, column, values[k]));
            }
        }
    }
    SparseColMat::try_new_from_triplets(fine.lcp.n(), coarse.lcp.n(), &triplets)
        .map_err(|e| Error::Input(format!("primal prolongation: {e:?}")))
}

/// [`primal_prolongation`] on intervals: each fine DOF functional (value or slope at a
/// point, [`super::dof_functionals`]) applied to the basis functions of the coarse cell
/// containing its point. Exact on nested meshes, where every coarse function is a fine
/// one (cubic Hermite: the slopes at a new midpoint are those of the coarse cubic, not an
/// average); on meshes that are not nested it is the interpolation, still a valid
/// prolongation for the cycle. A `fine.lcp.n() × coarse.lcp.n()` matrix.
///
/// # Errors
/// Discretizations in rotated DOFs ([`Discretization::basis`] not the identity), a field
/// missing or with another element on one level, a fine DOF point outside the coarse
/// mesh.
pub fn interval_primal_prolongation(
    coarse: &Discretization<IntervalMesh>,
    fine: &Discretization<IntervalMesh>,
) -> Result<SparseMatrix> {
    if !coarse.basis.is_identity() || !fine.basis.is_identity() {
        return Err(Error::Input(
            "no multigrid prolongation in rotated DOFs".into(),
        ));
    }
    let (rows, columns) = (primal_of_dof(fine), primal_of_dof(coarse));
    let mut triplets = Vec::new();
    for &field in fine.dofs.fields() {
        if field == fine.multiplier_field {
            continue;
        }
        let (Some(map_c), Some(map_f)) = (coarse.dofs.map(field), fine.dofs.map(field)) else {
            return Err(Error::Input(format!(
                "no multigrid prolongation: field {field} is missing on the coarser level"
            )));
        };
        let element = map_f.element();
        if map_c.element() != element {
            return Err(Error::Input(format!(
                "no multigrid prolongation: field {field} has another element on the coarser level"
            )));
        }
        let highest = element
            .dofs()
            .iter()
            .map(|location| match *location {
                DofLocation::Vertex { derivative, .. } => derivative,
                DofLocation::Interior => 0,
            })
            .max()
            .unwrap_or(0);
        if element.dofs_per_vertex() == 0 && element.dofs().len() > 1 {
            return Err(Error::Input(format!(
                "no multigrid prolongation for field {field}: its discontinuous element has no point-value DOFs"
            )));
        }
        let basis = PhysicalBasis::new(element, highest);
        let (offset_c, offset_f) = (
            coarse.dofs.offset(field).unwrap_or(0),
            fine.dofs.offset(field).unwrap_or(0),
        );
        // a vertex DOF belongs to two cells: its row is written once
        let mut written = vec![false; map_f.dof_count()];
        let (mut functionals, mut weights) = (Vec::new(), Vec::new());
        for c in 0..fine.mesh.cell_count() {
            super::dof_functionals(element, fine.mesh.cell(c), &mut functionals);
            for (&d, &(x, derivative)) in map_f.cell_dofs(c).iter().zip(&functionals) {
                let row = rows[offset_f + d];
                if std::mem::replace(&mut written[d], true) || row == usize::MAX {
                    continue;
                }
                let parent = coarse.mesh.locate(x).ok_or_else(|| {
                    Error::Input(format!(
                        "no multigrid prolongation: the fine DOF point {x} is outside the coarser mesh"
                    ))
                })?;
                let cell = coarse.mesh.cell(parent);
                // At a coarse vertex ξ must be exactly 0 or 1: at 1 − ε the slope rows
                // would pick up couplings of relative size ε/h. Division is exact where
                // the coordinates coincide (the map's (1/h)(x − x₀) is not); the snap
                // covers meshes whose coordinates round differently.
                let xi = match (x - cell[0]) / (cell[1] - cell[0]) {
                    xi if xi.abs() <= SNAP => 0.0,
                    xi if (1.0 - xi).abs() <= SNAP => 1.0,
                    xi => xi,
                };
                weights.clear();
                weights.extend(
                    (0..map_c.cell_dofs(parent).len())
                        .map(|j| basis.value(j, derivative, cell, xi)),
                );
                let largest = weights.iter().fold(0.0f64, |m, w| m.max(w.abs()));
                for (&dc, &weight) in map_c.cell_dofs(parent).iter().zip(&weights) {
                    let column = columns[offset_c + dc];
                    if column != usize::MAX && weight.abs() > DROP * largest {
                        triplets.push(Triplet::new(row, column, weight));
                    }
                }
            }
        }
    }
    SparseColMat::try_new_from_triplets(fine.lcp.n(), coarse.lcp.n(), &triplets)
        .map_err(|e| Error::Input(format!("primal prolongation: {e:?}")))
}

/// Weights of [`interval_primal_prolongation`] below this fraction of the largest of
/// their row are the rounding of an exact 0. The weights of one row differ by powers of
/// the cell length (a slope row holds `3/(2h)` and `1/4`), so the threshold is relative.
const DROP: f64 = 1e-13;

/// Reference coordinates this close to 0 or 1 are a coarse vertex ([`interval_primal_prolongation`]).
const SNAP: f64 = 1e-10;

/// The primal unknown of every DOF of `d` (`usize::MAX` for multipliers and fixed DOFs).
fn primal_of_dof<G>(d: &Discretization<G>) -> Vec<usize> {
    let mut index = vec![usize::MAX; d.dofs.dof_count()];
    for (p, &r) in d.primal_reduced.iter().enumerate() {
        index[d.reduction.free()[r]] = p;
    }
    index
}

fn level(d: &Discretization<TriangleMesh>) -> NestedLevel<'_> {
    NestedLevel {
        mesh: &d.mesh,
        dofs: &d.dofs,
        reduction: Some(&d.reduction),
    }
}

/// The multigrid step solver of one Newton solve (one level of a nested solve): the
/// hierarchy is built on the first step (Galerkin products of that step's `H`) and kept;
/// each later step adds to the coarse operators only the terms of the constraints whose
/// active state flipped ([`Lcp::hessian_change_blocks`], [`Multigrid::add_coarse_term`]),
/// copies `H` into the fine level and refactors the tiny coarsest one. A step is solved by
/// CG to [`MULTIGRID_INEXACT_TOLERANCE`] while the active set still changes (for at most
/// [`MULTIGRID_INEXACT_STEPS`] steps) and to [`MULTIGRID_TOLERANCE`] once it has settled,
/// or to [`MULTIGRID_ROUNDING_FLOOR`] of [`NewtonStep::scale`] when that is looser.
pub struct MultigridSteps<'a> {
    lcp: &'a Lcp,
    prolongations: &'a [SparseMatrix],
    options: MultigridOptions,
    /// The hierarchy and the active set its coarse operators include.
    hierarchy: Option<(Multigrid, Vec<bool>)>,
    /// CG iterations over the steps solved.
    pub krylov_iterations: usize,
    /// Hierarchies built from the Galerkin products (1 when every update succeeded).
    pub full_setups: usize,
    /// Steps asked for so far.
    steps: usize,
    /// A step failed (no hierarchy, or CG short of its tolerance): the later ones are
    /// left to the factorization at once. Retrying costs up to 80 CG iterations and a
    /// hierarchy per step where the smoother fails (cells of aspect ratio 80: the nodal
    /// method's same retries made a solve 10× slower than the direct one).
    gave_up: bool,
}

impl<'a> MultigridSteps<'a> {
    /// The step solver of `lcp`'s Newton solve on `prolongations` (fine to coarse, the
    /// first one's rows `lcp`'s primal unknowns).
    pub fn new(lcp: &'a Lcp, prolongations: &'a [SparseMatrix], options: MultigridOptions) -> Self {
        Self {
            lcp,
            prolongations,
            options,
            hierarchy: None,
            krylov_iterations: 0,
            full_setups: 0,
            steps: 0,
            gave_up: false,
        }
    }

    /// The Newton direction of `step` by CG preconditioned with the cycle of the options
    /// on the updated hierarchy, and whether it was solved to [`MULTIGRID_TOLERANCE`] or
    /// to the rounding floor (an exact step); `None` when the hierarchy cannot be built (a level whose
    /// operator is not SPD) or CG does not reach its tolerance in
    /// [`MULTIGRID_MAX_ITERATIONS`], so that Newton factors the step instead; after one
    /// such step always `None` (the level's later steps are factored).
    pub fn solve(&mut self, step: NewtonStep<'_>) -> Option<(Vec<f64>, bool)> {
        if self.gave_up {
            return None;
        }
        let solved = self.solve_by_multigrid(step);
        if solved.is_none() {
            self.gave_up = true;
            self.hierarchy = None;
        }
        solved
    }

    fn solve_by_multigrid(&mut self, step: NewtonStep<'_>) -> Option<(Vec<f64>, bool)> {
        let updated = self.hierarchy.take().and_then(|(mut mg, previous)| {
            let lcp = self.lcp;
            lcp.hessian_change_blocks(&previous, step.active, |rows, change| {
                mg.add_coarse_term(rows, change)
            })
            .and_then(|()| mg.reset_fine(step.hessian))
            .ok()
            .map(|()| mg)
        });
        let mg = match updated {
            Some(mg) => mg,
            None => {
                self.full_setups += 1;
                Multigrid::new(
                    step.hessian.clone(),
                    self.prolongations.to_vec(),
                    self.options,
                )
                .ok()?
            }
        };
        self.steps += 1;
        let relative = if step.settled || self.steps > MULTIGRID_INEXACT_STEPS {
            MULTIGRID_TOLERANCE
        } else {
            MULTIGRID_INEXACT_TOLERANCE
        };
        // Late steps correct a few flipped constraints: 1e-10 of their small gradient
        // would ask for a residual far below the rounding of the gradient itself.
        let norm_rhs = crate::lcp::norm2(step.rhs);
        let floor = MULTIGRID_ROUNDING_FLOOR * step.scale / norm_rhs;
        // a zero or non-finite gradient or scale gets no floor (CG then decides alone)
        let floor = if floor.is_finite() { floor } else { 0.0 };
        let tolerance = relative.max(floor.min(MULTIGRID_LOOSEST_FLOOR));
        let pcg = mg.pcg(step.rhs, tolerance, MULTIGRID_MAX_ITERATIONS);
        self.hierarchy = Some((mg, step.active.to_vec()));
        let pcg = pcg.ok()?;
        self.krylov_iterations += pcg.iterations;
        (pcg.relative_residual <= tolerance).then_some((pcg.x, relative <= MULTIGRID_TOLERANCE))
    }
}
