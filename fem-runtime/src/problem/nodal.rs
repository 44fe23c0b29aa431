//! The classical nodal-constraint method as a [`super::Problem`]'s constraint: a model
//! without multiplier (P1 on triangles), `U_i ≥ ψ(x_i)` at its free nodes, solved by
//! nested primal–dual active sets ([`crate::obstacle::nodal`]), the finest level built
//! on the second core while the coarser ones solve. Its multipliers are the nodal
//! contact forces.

use super::{Domain, Support};
use crate::assembly::dof_map::{DofNumbering, SystemDofs};
use crate::assembly::{assemble_vector, MatrixAssembler};
use crate::error::{Error, Result};
use crate::lcp::cholesky::multiply;
use crate::lcp::external::{CellGraph, External};
use crate::lcp::LcpSolution;
use crate::mesh::TriangleMesh;
use crate::model::{Coefficients, DataFn, FormId, Model};
use crate::multigrid::{parents_by_location, prolongation, reduced_prolongation, NestedLevel};
use crate::obstacle::hierarchy::LinearSolver;
use crate::obstacle::nodal::{
    force_density_at_vertices, nodal_active_set_level, nodal_lcp, nodal_lcp_on,
    NODAL_AUTO_MULTIGRID_UNKNOWNS,
};
use crate::obstacle::{
    alongside, Discretization, Multipliers, ObstacleOptions, ObstacleSolution, VariationalSolver,
};
use crate::{Reduction, SparseMatrix};
use std::time::Instant;

/// From this many triangles on, the finest level is built on the second core while the
/// coarser levels solve (below it a thread's start costs more than it saves).
const PIPELINED_CELLS: usize = 32_768;

/// One level before its solve: DOFs, elimination of the boundary DOFs, stiffness `a`,
/// load `f` and obstacle `ψ` on the free nodes, and the prolongations from the next
/// coarser level (all DOFs; free DOFs) if there is one. Of a level assembled in parts,
/// `a` and `f` are this process's cells' and `part` says which.
struct NodalLevel {
    dofs: SystemDofs,
    reduction: Reduction,
    a: SparseMatrix,
    f: Vec<f64>,
    psi: Vec<f64>,
    prolongations: Option<(SparseMatrix, SparseMatrix)>,
    part: Option<Part>,
}

/// This process's share of a level assembled in parts: its cells, the constraints it
/// owns ([`owned_unknowns`]), and the solver whose processes hold the other parts.
struct Part {
    cells: Vec<usize>,
    owned: Vec<bool>,
    solver: External,
}

impl Part {
    /// The level's LCP as this process holds it ([`nodal_lcp_on`], [`Lcp::share`]).
    ///
    /// [`Lcp::share`]: crate::lcp::Lcp::share
    fn lcp(part: Option<&Part>, a: &SparseMatrix, f: &[f64], psi: &[f64]) -> crate::lcp::Lcp {
        let mut lcp = nodal_lcp_on(a, f, psi, part.map(|p| p.owned.as_slice()));
        lcp.share = part.map(|p| crate::lcp::Share::new(p.solver));
        lcp
    }
}

/// The nested iteration so far: (cells, iterations) per level, the prolongations of the
/// free DOFs finest first, the last level's full coefficients and that level.
#[derive(Default)]
struct NodalState {
    levels: Vec<(usize, usize)>,
    prolongations: Vec<SparseMatrix>,
    values: Option<Vec<f64>>,
    finest: Option<(NodalLevelSolved, LcpSolution)>,
}

/// A solved level's system, kept for the finest one's discretization.
struct NodalLevelSolved {
    dofs: SystemDofs,
    reduction: Reduction,
    a: SparseMatrix,
    f: Vec<f64>,
    psi: Vec<f64>,
    part: Option<Part>,
}

/// Solves the nodal method of `M` (one P1 field, no multiplier) on the nested
/// `meshes` with the fixed DOFs of `supports` and the obstacle `obstacle`.
///
/// # Errors
/// A model that is not one P1 field without multiplier, a model without an energy
/// (`energy: a, ℓ`), the supports' and the assembly's errors, the solver's failure.
pub fn solve<M: Model>(
    meshes: &[TriangleMesh],
    coefficients: &Coefficients,
    supports: &[Support],
    obstacle: &DataFn,
    options: ObstacleOptions,
) -> Result<ObstacleSolution<TriangleMesh>> {
    let clock = Instant::now();
    let energy = nodal_energy::<M>()?;
    // Where an external solver runs on several processes, each assembles its own cells
    // of every level but the coarsest, whose null-space check reads the whole matrix
    // (partitioned here, on the thread that set the solver up).
    let mut parts = Vec::with_capacity(meshes.len());
    for (i, mesh) in meshes.iter().enumerate() {
        parts.push(match options.solver {
            VariationalSolver::External(e) if i > 0 => {
                e.0.partition(&CellGraph::of(mesh))?.map(|cells| (cells, e))
            }
            _ => None,
        });
    }
    let problem = NodalProblem {
        meshes,
        coefficients,
        supports,
        obstacle,
        energy,
        parts,
    };
    let setup = |i: usize| problem.level::<M>(i);
    let step = |state: &mut NodalState, level: NodalLevel, cells: usize| {
        state.step(level, cells, options, meshes.len())
    };
    let mut state = NodalState::default();
    let count = meshes.len();
    if count >= 3 && meshes[count - 1].cell_count() >= PIPELINED_CELLS {
        let mut finest = None;
        alongside(
            || finest = Some(setup(count - 1)),
            || -> Result<()> {
                for (i, mesh) in meshes[..count - 1].iter().enumerate() {
                    step(&mut state, setup(i)?, mesh.cell_count())?;
                }
                Ok(())
            },
        )?;
        let finest = finest.expect("the worker has run")?;
        step(&mut state, finest, meshes[count - 1].cell_count())?;
    } else {
        for (i, mesh) in meshes.iter().enumerate() {
            step(&mut state, setup(i)?, mesh.cell_count())?;
        }
    }
    let values = state.values.expect("at least one mesh");
    let (level, solution) = state.finest.expect("at least one mesh");
    let mut values = values;
    values.extend_from_slice(&solution.lambda);
    let n = level.reduction.free().len();
    let discretization = Discretization {
        mesh: meshes[count - 1].clone(),
        dofs: level.dofs,
        reduction: level.reduction,
        basis: Default::default(),
        lcp: Part::lcp(level.part.as_ref(), &level.a, &level.f, &level.psi),
        multiplier_field: M::FIELDS.len(),
        multipliers: Multipliers::Nodal,
        roles: Vec::new(),
        primal_reduced: (0..n).collect(),
        multiplier_reduced: Vec::new(),
        cells: level.part.map(|p| p.cells),
    };
    // the nodal method's multipliers are the nodal forces: no elimination to be noisy
    Ok(ObstacleSolution::of(
        &LcpSolution {
            multiplier_noise: 0.0,
            ..solution
        },
        discretization,
        values,
        state.levels,
        clock.elapsed().as_secs_f64(),
    ))
}

/// The energy forms `[a, ℓ]` of `M`, a model the nodal method takes: a primal P1 field
/// first, then at most a P1 multiplier, the density of the nodal forces that the
/// estimator reads (the solve assembles the first field's energy alone).
///
/// # Errors
/// A model of other fields, or that declares no energy.
fn nodal_energy<M: Model>() -> Result<[usize; 2]> {
    let p1 = |f: &crate::model::FieldInfo| f.element == crate::ElementKind::P1;
    let takes = match M::FIELDS {
        [u] => p1(u) && !u.nonnegative,
        [u, lambda] => p1(u) && !u.nonnegative && p1(lambda) && lambda.nonnegative,
        _ => false,
    };
    if !takes {
        return Err(Error::Input(format!(
            "the nodal method takes a model of one P1 field, with at most a P1 multiplier (the density of its nodal forces); `{}` has {}",
            M::NAME,
            M::FIELDS
                .iter()
                .map(|f| format!("{} ({})", f.name, f.element.name()))
                .collect::<Vec<_>>()
                .join(", ")
        )));
    }
    M::ENERGY.ok_or_else(|| {
        Error::Input(format!(
            "the nodal method assembles the energy of `{}`, which declares none (`energy: a, ℓ;`)",
            M::NAME
        ))
    })
}

/// The DOFs the nodal method solves for on `mesh`: its first field's (a multiplier field
/// is its forces' density, which the estimator reads and no form of the solve holds).
///
/// # Errors
/// Those of [`SystemDofs::new`].
pub fn primal_dofs<M: Model>(mesh: &impl DofNumbering) -> Result<SystemDofs> {
    SystemDofs::new::<M>(mesh, &[0])
}

/// What the levels of a nodal solve are built from.
struct NodalProblem<'a> {
    meshes: &'a [TriangleMesh],
    coefficients: &'a Coefficients<'a>,
    supports: &'a [Support],
    obstacle: &'a DataFn,
    /// The forms `[a, ℓ]`.
    energy: [usize; 2],
    /// This process's cells of each level and the solver that partitioned them, where
    /// the level is assembled in parts.
    parts: Vec<Option<(Vec<usize>, External)>>,
}

impl NodalProblem<'_> {
    /// The DOFs of `mesh` and the elimination of its supported ones.
    fn free_dofs<M: Model>(&self, mesh: &TriangleMesh) -> Result<(SystemDofs, Reduction)> {
        let dofs = primal_dofs::<M>(mesh)?;
        let constraints = mesh.constraints::<M>(&dofs, self.coefficients, self.supports)?;
        let reduction = constraints.reduction(dofs.dof_count())?;
        Ok((dofs, reduction))
    }

    /// Level `i` before its solve, with the prolongations from level `i − 1`.
    fn level<M: Model>(&self, i: usize) -> Result<NodalLevel> {
        let mesh = &self.meshes[i];
        let [stiffness, load] = self.energy;
        let (dofs, reduction) = self.free_dofs::<M>(mesh)?;
        let cells = self.parts[i].as_ref().map(|(cells, _)| cells.as_slice());
        crate::obstacle::check_cells(cells, mesh.cell_count())?;
        let on = crate::mesh::CellSubset::new(mesh, cells);
        // the pattern moves into `k` and `k`'s arrays into `a` (no copies: peak memory)
        let k = MatrixAssembler::new::<M>(FormId::new(stiffness), &on, &dofs)?
            .into_matrix::<M>(&on, self.coefficients)?;
        let l = assemble_vector::<M>(FormId::new(load), &on, &dofs, self.coefficients)?;
        let f = reduction.rhs(&k, &l);
        drop(l);
        let a = reduction.into_matrix(k);
        let nodes = dofs.map(0).expect("one field").nodes(mesh);
        let psi: Vec<f64> = reduction
            .free()
            .iter()
            .map(|&d| (self.obstacle)(&nodes[d]))
            .collect();
        let prolongations = match i.checked_sub(1).map(|c| &self.meshes[c]) {
            Some(coarse) => {
                let (coarse_dofs, coarse_reduction) = self.free_dofs::<M>(coarse)?;
                let parents = parents_by_location(coarse, mesh)?;
                let level = |mesh, dofs, reduction| NestedLevel {
                    mesh,
                    dofs,
                    reduction,
                };
                let all = prolongation(
                    &level(coarse, &coarse_dofs, None),
                    &level(mesh, &dofs, None),
                    &parents,
                )?;
                let free = reduced_prolongation(&all, &coarse_reduction, &reduction)?;
                Some((all, free))
            }
            None => None,
        };
        let part = self.parts[i].as_ref().map(|(cells, solver)| Part {
            owned: owned_unknowns(mesh, &dofs, &reduction, cells),
            cells: cells.clone(),
            solver: *solver,
        });
        Ok(NodalLevel {
            dofs,
            reduction,
            a,
            f,
            psi,
            prolongations,
            part,
        })
    }
}

impl NodalState {
    /// Solves `level` (of `cells` triangles, one of `level_count`) from the last solved
    /// level's solution interpolated at its nodes, by multigrid steps where
    /// `options.linear_solver` asks for them and there are coarser levels; by the
    /// external solver of `options.solver` where it names one.
    ///
    /// # Errors
    /// The active-set method's.
    fn step(
        &mut self,
        level: NodalLevel,
        cells: usize,
        options: ObstacleOptions,
        level_count: usize,
    ) -> Result<()> {
        let NodalLevel {
            dofs,
            reduction,
            a,
            f,
            psi,
            prolongations,
            part,
        } = level;
        // the coarser level's system goes before this level's solve allocates
        self.finest = None;
        // the coarse solution interpolated at the fine nodes, boundary values included
        let start = match (prolongations, self.values.take()) {
            (Some((all, free)), Some(values)) => {
                let fine = multiply(&all, &values);
                self.prolongations.insert(0, free);
                Some(
                    reduction
                        .free()
                        .iter()
                        .map(|&d| fine[d])
                        .collect::<Vec<f64>>(),
                )
            }
            _ => None,
        };
        let multigrid = match options.linear_solver {
            LinearSolver::Direct => false,
            LinearSolver::Multigrid => !self.prolongations.is_empty(),
            LinearSolver::Auto => {
                a.nrows() >= NODAL_AUTO_MULTIGRID_UNKNOWNS && self.prolongations.len() >= 2
            }
        };
        let hierarchy: &[SparseMatrix] = if multigrid { &self.prolongations } else { &[] };
        if self.levels.is_empty() {
            // the coarsest level judges whether the problem is held (docs/mathematics.md §5)
            crate::lcp::null_space::check_held(
                &nodal_lcp(&a, &f, &psi),
                true,
                &format!("a mesh of {cells} cells"),
            )?;
        }
        let last = self.levels.len() + 1 == level_count;
        let solution = match options.solver {
            VariationalSolver::External(external) => external
                .0
                .solve(&Part::lcp(part.as_ref(), &a, &f, &psi), start.as_deref())?,
            _ => nodal_active_set_level(&a, &f, &psi, start.as_deref(), 500, hierarchy, last)?,
        };
        self.levels.push((cells, solution.iterations));
        self.values = Some(reduction.expand(&solution.u));
        self.finest = Some((
            NodalLevelSolved {
                dofs,
                reduction,
                a,
                f,
                psi,
                part,
            },
            solution,
        ));
        Ok(())
    }
}

/// Which free unknowns' constraints `U_k ≥ ψ_k` this process owns, `cells` its cells of
/// `mesh`: a node belongs to the part of the lowest-numbered cell that has it, so each
/// constraint is owned by exactly one part of a partition, decided by each process
/// from the whole mesh without communication.
fn owned_unknowns(
    mesh: &TriangleMesh,
    dofs: &SystemDofs,
    reduction: &Reduction,
    cells: &[usize],
) -> Vec<bool> {
    let (map, offset) = (
        dofs.map(0).expect("one field"),
        dofs.offset(0).expect("one field"),
    );
    let mut first = vec![usize::MAX; dofs.dof_count()];
    for c in 0..mesh.cell_count() {
        for &d in map.cell_dofs(c) {
            let d = offset + d;
            if first[d] == usize::MAX {
                first[d] = c;
            }
        }
    }
    let mut mine = vec![false; mesh.cell_count()];
    for &c in cells {
        mine[c] = true;
    }
    reduction
        .free()
        .iter()
        .map(|&d| first[d] != usize::MAX && mine[first[d]])
        .collect()
}

/// The nodal method's contact set, per cell: the share of its vertices in contact. A
/// free vertex touches where its force is positive or it lies on ψ; a boundary vertex
/// where g = ψ lies on the obstacle whether or not the membrane touches it, so it counts
/// only next to contact, found in two steps (next to interior contact, then next to
/// those, which reaches a corner cell whose three vertices are all on the boundary).
/// Also whether such a boundary vertex is in contact (its force is not in ∫λ_h).
pub fn contact_shares(
    solution: &ObstacleSolution<TriangleMesh>,
    obstacle: &DataFn,
) -> (Vec<f64>, bool) {
    let d = &solution.discretization;
    let mesh = &d.mesh;
    let values = &solution.values[..d.dofs.dof_count()];
    let lambda = solution.multiplier_values();
    let scale = lambda.iter().cloned().fold(0.0, f64::max);
    let mut vertex_force = vec![0.0; mesh.vertex_count()];
    let mut free = vec![false; mesh.vertex_count()];
    for (k, &dof) in d.reduction.free().iter().enumerate() {
        vertex_force[dof] = lambda[k];
        free[dof] = true;
    }
    let on_obstacle = |v: usize| {
        let gap = values[v] - obstacle(&mesh.vertices()[v]);
        gap.abs() <= 1e-10 * (1.0 + values[v].abs())
    };
    let interior: Vec<bool> = (0..mesh.vertex_count())
        .map(|v| free[v] && (vertex_force[v] > 1e-8 * scale.max(1e-300) || on_obstacle(v)))
        .collect();
    let spread = |active: &[bool]| -> Vec<bool> {
        let mut next = active.to_vec();
        for c in 0..mesh.cell_count() {
            let cell = mesh.cell(c);
            if cell.iter().any(|&v| active[v]) {
                for v in cell {
                    next[v] |= !free[v] && on_obstacle(v);
                }
            }
        }
        next
    };
    let active = spread(&spread(&interior));
    let shares = (0..mesh.cell_count())
        .map(|c| mesh.cell(c).iter().filter(|&&v| active[v]).count() as f64 / 3.0)
        .collect();
    let boundary_contact = (0..mesh.vertex_count()).any(|v| !free[v] && active[v]);
    (shares, boundary_contact)
}

/// The nodal forces as a density per cell: the vertices' densities
/// ([`crate::obstacle::nodal::force_density_at_vertices`]) averaged over the cell's
/// vertices.
pub fn force_density(solution: &ObstacleSolution<TriangleMesh>) -> Vec<f64> {
    let d = &solution.discretization;
    let mesh = &d.mesh;
    let density = force_density_at_vertices(mesh, d.reduction.free(), solution.multiplier_values());
    (0..mesh.cell_count())
        .map(|c| mesh.cell(c).iter().map(|&v| density[v]).sum::<f64>() / 3.0)
        .collect()
}
