//! The radial membrane by the nodal method through the pipeline with PETSc (`mpirun -n
//! N`, N = 1, 2, 3 in `.ci/run`): each rank assembles its own cells of every level but
//! the coarsest (PT-Scotch's partition) with the generated P1 kernels, and SNESVI
//! (`vinewtonrsls`) solves with the bounds on the vertex values, each set by the rank
//! that owns it. The errors must be the native solver's (`fem-forms solve
//! membrane-radial --pair p1-nodal`) to the solver tolerance on every rank count, and so
//! reproduce the errors PETSc's ex9 printed on the same grids to every printed digit.

use fem_models::families;
use fem_models::membrane_scenes::PETSC_EX9_ERRORS;
use fem_models::report::Settings;
use fem_petsc::lcp::{Formulation, PetscLcpSolver};
use fem_runtime::lcp::external::{External, ExternalSolver};
use fem_runtime::obstacle::VariationalSolver;

fn main() {
    let petsc: &'static PetscLcpSolver = Box::leak(Box::new(
        PetscLcpSolver::new("", None).expect("PETSc starts"),
    ));
    let (rank, size) = petsc.rank_and_size();
    let scene = families::scene("membrane-radial").expect("the registry's radial membrane");
    for (n, mean, max) in PETSC_EX9_ERRORS {
        let solve = |solver| {
            let settings = Settings {
                pair: Some("p1-nodal".into()),
                mesh_size: Some(n),
                solver,
                ..Settings::default()
            };
            families::solve(&scene, &settings)
                .unwrap_or_else(|e| panic!("N = {n} on {size} ranks by {solver:?}: {e}"))
                .report
                .solve
        };
        let native = solve(VariationalSolver::SemismoothNewton);
        let ours = solve(VariationalSolver::External(External(petsc)));
        assert_eq!(ours.solver, "petsc", "N = {n}");
        let record = petsc.records().last().cloned().expect("a PETSc solve");
        assert_eq!(record.formulation, Formulation::Primal, "N = {n}");
        let rows = record
            .rows_here
            .expect("the finest level assembled in parts");
        let mut total = [rows as f64];
        petsc.sum(&mut total);
        assert_eq!(
            total[0] as usize, record.unknowns[0],
            "N = {n}: the ranks' rows"
        );
        let (ours_mean, ours_max) = (
            ours.error_vertex_mean.expect("the vertex errors"),
            ours.error_vertex_max.expect("the vertex errors"),
        );
        // ex9's digits
        assert_eq!(
            format!("{ours_mean:.3e} {ours_max:.3e}"),
            format!("{mean:.3e} {max:.3e}"),
            "N = {n} on {size} ranks against ex9"
        );
        // the native solver's answer
        let (native_mean, native_max) = (
            native.error_vertex_mean.expect("the vertex errors"),
            native.error_vertex_max.expect("the vertex errors"),
        );
        assert!(
            (ours_mean - native_mean).abs() <= 1e-9 * native_mean
                && (ours_max - native_max).abs() <= 1e-9 * native_max,
            "N = {n} on {size} ranks: mean {ours_mean:e}, max {ours_max:e} against the native {native_mean:e}, {native_max:e}"
        );
        if rank == 0 {
            println!(
                "{size} ranks, N = {n}: {rows} rows on rank 0 of {}; {} after {} iterations; mean error {ours_mean:.4e} (native {native_mean:.4e}), max {ours_max:.4e}",
                record.unknowns[0], record.converged.reason, record.converged.iterations
            );
        }
    }
    petsc.finalize();
}
