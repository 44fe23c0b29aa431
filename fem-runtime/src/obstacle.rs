//! Obstacle problems of a model: the stabilized saddle-point system `B_h`, `L_h` is
//! assembled, boundary DOFs are eliminated, and the system is split into the LCP blocks
//! `A_α, B_α, C_α, F_α, G_α` of MODELS.md §1 (the KKT matrix is
//! `[[A_α, −B_αᵀ], [−B_α, −C_α]]`, its right-hand side `[F_α; −G_α]`).

use crate::assembly::{assemble_vector, MatrixAssembler};
use crate::boundary::{Constraints, Reduction, Side};
use crate::complementarity::{
    primal_dual_active_set, quadratic_program, recover_multiplier, semismooth_newton,
    semismooth_newton_prepared, CouplingBlocks, Lcp, LcpSolution, NewtonOptions, NewtonWorkspace,
};
use crate::dof_map::SystemDofs;
use crate::element::PhysicalBasis;
use crate::error::{Error, Result};
use crate::mesh::{IntervalMesh, Mesh};
use crate::model::{Coefficients, Model};
use crate::norms::FieldView;
use crate::SparseMatrix;
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use fem_reference::DofLocation;
use std::time::Instant;

/// Which algorithm solves the LCP.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VariationalSolver {
    /// Semismooth Newton / primal–dual active set on Φ, globalized by a line search.
    SemismoothNewton,
    /// clarabel's interior-point method on the equivalent QP.
    Clarabel,
}

#[derive(Clone, Copy, Debug)]
enum Role {
    Primal(usize),
    Multiplier(usize),
}

/// The discrete obstacle problem of a model on one mesh.
pub struct Discretization<G = IntervalMesh> {
    /// The mesh.
    pub mesh: G,
    /// DOFs of all fields of the model.
    pub dofs: SystemDofs,
    /// Elimination of the boundary DOFs.
    pub reduction: Reduction,
    /// The LCP blocks.
    pub lcp: Lcp,
    /// The model field that holds the multiplier.
    pub multiplier_field: usize,
    roles: Vec<Role>,
    primal_reduced: Vec<usize>,
    multiplier_reduced: Vec<usize>,
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
    /// fields in `clamped` clamped at both ends.
    pub fn new<M: Model>(
        mesh: &IntervalMesh,
        coefficients: &Coefficients,
        clamped: &[&str],
        bilinear: &str,
        linear: &str,
    ) -> Result<Self> {
        let dofs = SystemDofs::all::<M>(mesh)?;
        let mut constraints = Constraints::new();
        for field in clamped {
            for side in [Side::Left, Side::Right] {
                constraints.clamp::<M>(mesh, &dofs, field, side)?;
            }
        }
        Self::with_constraints::<M>(mesh, coefficients, dofs, &constraints, bilinear, linear)
    }
}

impl<G: Mesh + Clone> Discretization<G> {
    /// Assembles `bilinear` and `linear` of `M` on `mesh` with the DOFs `dofs`, eliminates
    /// the fixed DOFs of `constraints` and splits the system into the LCP blocks.
    pub fn with_constraints<M: Model>(
        mesh: &G,
        coefficients: &Coefficients,
        dofs: SystemDofs,
        constraints: &Constraints,
        bilinear: &str,
        linear: &str,
    ) -> Result<Self> {
        let multiplier = multiplier_field::<M>()?;
        let k =
            MatrixAssembler::new::<M>(bilinear, mesh, &dofs)?.assemble::<M>(mesh, coefficients)?;
        let rhs = assemble_vector::<M>(linear, mesh, &dofs, coefficients)?;
        let reduction = constraints.reduction(dofs.dof_count())?;
        let rhs = reduction.rhs(&k, &rhs);
        let k = reduction.matrix(&k);
        let multiplier_range = dofs.range(multiplier).unwrap();
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
        let (n, m) = (primal_reduced.len(), multiplier_reduced.len());
        let mut b_rows = vec![Vec::new(); m];
        let mut c = vec![0.0; m];
        // off-diagonal entries of C: the multipliers of one cell (P1disc) are coupled
        let mut coupling = Vec::new();
        let mut a_ptr = vec![0usize];
        let (mut a_rows, mut a_vals) = (Vec::new(), Vec::new());
        let (col_ptr, rows, vals) = (k.symbolic().col_ptr(), k.symbolic().row_idx(), k.val());
        for (j, role_j) in roles.iter().enumerate() {
            for idx in col_ptr[j]..col_ptr[j + 1] {
                let (i, v) = (rows[idx], vals[idx]);
                match (roles[i], *role_j) {
                    (Role::Primal(p), Role::Primal(_)) => {
                        a_rows.push(p);
                        a_vals.push(v);
                    }
                    (Role::Multiplier(mk), Role::Primal(p)) => b_rows[mk].push((p, -v)),
                    (Role::Multiplier(mi), Role::Multiplier(mj)) => {
                        if mi == mj {
                            c[mi] = -v;
                        } else if v != 0.0 {
                            coupling.push((mi, mj, -v));
                        }
                    }
                    (Role::Primal(_), Role::Multiplier(_)) => {}
                }
            }
            if let Role::Primal(_) = role_j {
                a_ptr.push(a_rows.len());
            }
        }
        for row in &mut b_rows {
            row.retain(|&(_, v)| v != 0.0);
        }
        let c_blocks = CouplingBlocks::from_entries(m, &coupling).map_err(|e| {
            Error::Input(format!(
                "the multiplier block of `{bilinear}`: {e}; this LCP form needs multipliers coupled only within a cell (P0, P1disc)"
            ))
        })?;
        let a: SparseMatrix = SparseColMat::new(
            SymbolicSparseColMat::new_checked(n, n, a_ptr, None, a_rows),
            a_vals,
        );
        let f = primal_reduced.iter().map(|&r| rhs[r]).collect();
        let g = multiplier_reduced.iter().map(|&r| -rhs[r]).collect();
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
            },
            multiplier_field: multiplier,
            roles,
            primal_reduced,
            multiplier_reduced,
        })
    }
}

impl<G> Discretization<G> {
    /// For each constraint of the LCP, the DOF (numbered within the multiplier field) of
    /// its multiplier.
    pub fn multiplier_dofs(&self) -> Vec<usize> {
        let offset = self.dofs.offset(self.multiplier_field).unwrap_or(0);
        self.multiplier_reduced
            .iter()
            .map(|&r| self.reduction.free()[r] - offset)
            .collect()
    }

    /// The full coefficient vector (all fields, boundary values included) of an LCP solution.
    pub fn full(&self, solution: &LcpSolution) -> Vec<f64> {
        let mut reduced = vec![0.0; self.roles.len()];
        for (p, &r) in self.primal_reduced.iter().enumerate() {
            reduced[r] = solution.u[p];
        }
        for (k, &r) in self.multiplier_reduced.iter().enumerate() {
            reduced[r] = solution.lambda[k];
        }
        self.reduction.expand(&reduced)
    }

    /// The primal unknowns of a full coefficient vector (a start for Newton).
    pub fn primal_part(&self, full: &[f64]) -> Vec<f64> {
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
        let nodes = element.lagrange_nodes();
        for c in 0..fine_mesh.cell_count() {
            let cell = fine_mesh.cell(c);
            let mut interior = 0;
            for (i, location) in element.dofs().iter().enumerate() {
                let (x, derivative) = match *location {
                    DofLocation::Vertex { vertex, derivative } => (cell[vertex], derivative),
                    DofLocation::Interior => {
                        let xi = nodes.map_or(0.5, |n| n[2 * element.dofs_per_vertex() + interior]);
                        interior += 1;
                        (cell[0] + (cell[1] - cell[0]) * xi, 0)
                    }
                };
                // P0: its single "interior" node is the midpoint
                let x = if element.dofs_per_vertex() == 0 {
                    0.5 * (cell[0] + cell[1])
                } else {
                    x
                };
                fine[offset + map_f.cell_dofs(c)[i]] =
                    view.at_with(&basis, x, derivative).unwrap_or(0.0);
            }
        }
    }
    fine
}

/// A solved obstacle problem.
pub struct ObstacleSolution<G = IntervalMesh> {
    /// The discrete problem on the finest mesh.
    pub discretization: Discretization<G>,
    /// Coefficients of all fields (multiplier included).
    pub values: Vec<f64>,
    /// Iterations on the finest mesh.
    pub iterations: usize,
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
}

impl Default for ObstacleOptions {
    fn default() -> Self {
        Self {
            solver: VariationalSolver::SemismoothNewton,
            nested_from: Some(16),
            newton: NewtonOptions::default(),
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
            let newton = match workspace {
                Some(w) => semismooth_newton_prepared(lcp, w, start, newton),
                None => semismooth_newton(lcp, start, newton),
            };
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
            if lcp.elimination_noise() > 1e-6 {
                recover_multiplier(lcp, solution, options.newton.refinement_steps)
            } else {
                Ok(solution)
            }
        }
        VariationalSolver::Clarabel => quadratic_program(lcp),
    }
}

/// Solves the obstacle problem `B_h`, `L_h` of `M` on `mesh`.
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
    let mut sizes = vec![mesh.cell_count()];
    if let (Some(min), true, VariationalSolver::SemismoothNewton) =
        (options.nested_from, uniform, options.solver)
    {
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
                Discretization::new::<M>(&level_mesh, coefficients, clamped, "B_h", "L_h")
            }
        })
        .collect();
    solve_nested(
        levels,
        |coarse, values, fine| {
            prolong::<M>(&coarse.mesh, &coarse.dofs, values, &fine.mesh, &fine.dofs)
        },
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
/// part of the last level follows the coarse solves.
pub fn solve_nested<G, B>(
    levels: Vec<B>,
    prolong: impl Fn(&Discretization<G>, &[f64], &Discretization<G>) -> Vec<f64>,
    options: ObstacleOptions,
) -> Result<ObstacleSolution<G>>
where
    G: Mesh + Send,
    B: FnOnce() -> Result<Discretization<G>> + Send,
{
    let clock = Instant::now();
    let mut levels = levels;
    let finest = levels
        .pop()
        .ok_or_else(|| Error::Input("no mesh to solve on".into()))?;
    let newton = options.solver == VariationalSolver::SemismoothNewton;
    let prepare = move || -> Result<(Discretization<G>, Option<NewtonWorkspace>)> {
        let d = finest()?;
        // Newton's own checks (positive C) come with the solve, where their error is
        // reported; a workspace that cannot be built is simply not used.
        let workspace = if newton {
            NewtonWorkspace::new(&d.lcp).ok()
        } else {
            None
        };
        Ok((d, workspace))
    };
    let (coarse, finest) = if levels.is_empty() {
        (Ok(None), prepare())
    } else {
        std::thread::scope(|scope| {
            let finest = scope.spawn(prepare);
            let coarse = solve_levels(levels, &prolong, options);
            let finest = finest
                .join()
                .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
            (coarse, finest)
        })
    };
    let (coarse, mut counts) = match coarse? {
        Some((d, values, counts)) => (Some((d, values)), counts),
        None => (None, Vec::new()),
    };
    let (discretization, workspace) = finest?;
    let start = coarse.as_ref().map(|(coarse, values)| {
        discretization.primal_part(&prolong(coarse, values, &discretization))
    });
    drop(coarse);
    let solution = solve_lcp_prepared(
        &discretization.lcp,
        workspace.as_ref(),
        start.as_deref(),
        options,
    )?;
    counts.push((discretization.mesh.cell_count(), solution.iterations));
    let values = discretization.full(&solution);
    Ok(ObstacleSolution {
        iterations: solution.iterations,
        kkt_residual: solution.kkt_residual,
        solve_seconds: solution.seconds,
        multiplier_noise: solution.multiplier_noise,
        discretization,
        values,
        levels: counts,
        seconds: clock.elapsed().as_secs_f64(),
    })
}

/// A level's discretization, its solution's full coefficients, and the (cells, iterations)
/// of every level so far.
type SolvedLevel<G> = (Discretization<G>, Vec<f64>, Vec<(usize, usize)>);

/// Builds and solves `levels` in turn, each from the prolonged solution of the one
/// before; the last one solved, or `None` for no levels.
fn solve_levels<G: Mesh, B: FnOnce() -> Result<Discretization<G>>>(
    levels: Vec<B>,
    prolong: &impl Fn(&Discretization<G>, &[f64], &Discretization<G>) -> Vec<f64>,
    options: ObstacleOptions,
) -> Result<Option<SolvedLevel<G>>> {
    let mut last: Option<SolvedLevel<G>> = None;
    for build in levels {
        let d = build()?;
        let start = last
            .as_ref()
            .map(|(coarse, values, _)| d.primal_part(&prolong(coarse, values, &d)));
        let solution = solve_lcp(&d.lcp, start.as_deref(), options)?;
        let mut counts = last.map(|(_, _, counts)| counts).unwrap_or_default();
        counts.push((d.mesh.cell_count(), solution.iterations));
        let values = d.full(&solution);
        last = Some((d, values, counts));
    }
    Ok(last)
}

impl<G> ObstacleSolution<G> {
    /// The coefficients of model field `field`.
    pub fn field(&self, field: usize) -> &[f64] {
        &self.values[self.discretization.dofs.range(field).unwrap()]
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
        let lcp = &self.discretization.lcp;
        let u = self.discretization.primal_part(&self.values);
        let c_lambda = lcp.c_times(lambda);
        let touching = |k: usize| {
            let row = &lcp.b_rows[k];
            let bu: f64 = row.iter().map(|&(j, v)| v * u[j]).sum();
            let terms: f64 =
                row.iter().map(|&(j, v)| (v * u[j]).abs()).sum::<f64>() + lcp.g[k].abs();
            (bu + c_lambda[k] - lcp.g[k]).abs() <= 1e-6 * terms
        };
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
