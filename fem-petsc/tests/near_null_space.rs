//! The rigid motions as GAMG's near null space (`Lcp::near_null_space`,
//! `Matrix::set_near_null_space`): Hertz contact (P1–P0, b/h = 32) through the pipeline
//! with CG + GAMG on the eliminated Hessian, under `mpirun -n N` (N = 1, 2, 3 in
//! `.ci/run`). The answer must be the native one; and with the contact family's rigid
//! motions GAMG must need far fewer CG iterations than the same solve stripped of them
//! (GAMG's default near null space, the constants, does not hold an elastic body's
//! translations per component and its rotation). An iteration count in one run against
//! another, not a time.

use fem_models::families;
use fem_models::report::Settings;
use fem_petsc::lcp::PetscLcpSolver;
use fem_runtime::lcp::external::{CellGraph, External, ExternalSolver, Purpose};
use fem_runtime::lcp::{Lcp, LcpSolution};
use fem_runtime::obstacle::VariationalSolver;

/// PETSc's solver with the LCPs stripped of their near null space.
struct WithoutNearNullSpace(&'static PetscLcpSolver);

impl ExternalSolver for WithoutNearNullSpace {
    fn name(&self) -> &'static str {
        self.0.name()
    }

    fn solve(&self, lcp: &Lcp, start: Option<&[f64]>) -> fem_runtime::Result<LcpSolution> {
        let mut stripped = lcp.clone();
        stripped.near_null_space.clear();
        self.0.solve(&stripped, start)
    }

    fn set_purpose(&self, purpose: Purpose) {
        self.0.set_purpose(purpose);
    }

    fn partition(&self, graph: &CellGraph) -> fem_runtime::Result<Option<Vec<usize>>> {
        self.0.partition(graph)
    }

    fn sum(&self, values: &mut [f64]) {
        self.0.sum(values);
    }

    fn max(&self, value: f64) -> f64 {
        self.0.max(value)
    }
}

/// Solves Hertz at b/h = 32 by `solver`: the energy, ∫λ_h, and the CG iterations of
/// the finest level's solve with its Newton steps.
fn hertz(solver: VariationalSolver, records: Option<&PetscLcpSolver>) -> (f64, f64, [usize; 2]) {
    let scene = families::scene("hertz").expect("the hertz scene");
    let settings = Settings {
        pair: Some("p1-p0".into()),
        mesh_size: Some(32),
        solver,
        ..Settings::default()
    };
    let before = records.map_or(0, |r| r.records().len());
    let report = families::solve(&scene, &settings)
        .unwrap_or_else(|e| panic!("hertz by {solver:?}: {e}"))
        .report;
    let iterations = records.map_or([0, 0], |r| {
        let finest = r.records()[before..]
            .iter()
            .max_by_key(|record| record.unknowns[0])
            .cloned()
            .expect("PETSc solved a level");
        [
            finest.converged.linear_iterations,
            finest.converged.iterations,
        ]
    });
    (
        report.solve.energy.expect("an energy"),
        report.solve.total_contact_force,
        iterations,
    )
}

fn main() {
    let petsc: &'static PetscLcpSolver = Box::leak(Box::new(
        PetscLcpSolver::new("-ksp_type cg -pc_type gamg -ksp_rtol 1e-10", None)
            .expect("PETSc starts"),
    ));
    let (rank, size) = petsc.rank_and_size();
    let without: &'static WithoutNearNullSpace = Box::leak(Box::new(WithoutNearNullSpace(petsc)));
    let native = hertz(VariationalSolver::SemismoothNewton, None);
    let with = hertz(VariationalSolver::External(External(petsc)), Some(petsc));
    let stripped = hertz(VariationalSolver::External(External(without)), Some(petsc));
    for (what, (energy, force, _)) in [("with", with), ("without", stripped)] {
        assert!(
            (energy - native.0).abs() <= 1e-9 * native.0.abs()
                && (force - native.1).abs() <= 1e-9 * native.1.abs(),
            "{what} the rigid motions on {size} ranks: energy {energy} and ∫λ {force}, native {} and {}",
            native.0,
            native.1
        );
    }
    let ([cg_with, newton_with], [cg_without, newton_without]) = (with.2, stripped.2);
    if rank == 0 {
        eprintln!(
            "near null space on {size} ranks: {cg_with} CG iterations in {newton_with} Newton steps with the rigid motions, {cg_without} in {newton_without} without"
        );
    }
    assert!(
        2 * cg_with < cg_without,
        "on {size} ranks: {cg_with} CG iterations with the rigid motions, {cg_without} without"
    );
    petsc.finalize();
}
