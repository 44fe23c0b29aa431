//! The radial membrane by the nodal method, distributed (`mpirun -n N`, N = 1, 2, 3 in
//! `.ci/run`): the cells partitioned by PT-Scotch, each rank assembling its own with the
//! generated P1 kernels, SNESVI (`vinewtonrsls`) with the bounds on the vertex values.
//! The answer must be the native solver's (`fem-forms solve membrane-radial --pair
//! p1-nodal`) to the solver tolerance on every rank count, and so reproduce the errors
//! PETSc's ex9 printed on the same grids to every printed digit.

use fem_models::families;
use fem_models::membrane_p1::Model as NodalMembrane;
use fem_models::membrane_scenes::{radial_obstacle, radial_u, PETSC_EX9_ERRORS};
use fem_models::report::Settings;
use fem_models::scene::Domain;
use fem_petsc::nodal::solve_nodal;
use fem_petsc::Petsc;
use fem_runtime::model::DataFn;
use fem_runtime::TriangleMesh;

fn main() {
    let petsc = Petsc::initialize("-snes_rtol 1e-12 -snes_atol 1e-14 -ksp_rtol 1e-14")
        .expect("PETSc starts");
    let (rank, size) = (petsc.rank(), petsc.size());
    let scene = families::scene("membrane-radial").expect("the registry's radial membrane");
    let Domain::Rectangle {
        x,
        y,
        cells,
        diagonal,
    } = scene.domain
    else {
        panic!("the radial membrane is posed on a rectangle");
    };
    let zero = |_: &[f64]| 0.0;
    let psi = |p: &[f64]| radial_obstacle(p);
    let g = |p: &[f64]| radial_u(p);
    let data: [&DataFn; 3] = [&zero, &psi, &g];
    for (n, mean, max) in PETSC_EX9_ERRORS {
        let mesh =
            TriangleMesh::rectangle(x[0], x[1], y[0], y[1], n * cells[0], n * cells[1], diagonal)
                .unwrap();
        let solution = solve_nodal::<NodalMembrane>(
            &petsc,
            &mesh,
            &[],
            &data,
            &|p| radial_obstacle(&p),
            &|p| radial_u(&p),
        )
        .unwrap_or_else(|e| panic!("N = {n} on {size} ranks: {e}"));
        let errors: Vec<f64> = mesh
            .vertices()
            .iter()
            .zip(&solution.values)
            .map(|(p, u)| (u - radial_u(p)).abs())
            .collect();
        let ours_mean = errors.iter().sum::<f64>() / errors.len() as f64;
        let ours_max = errors.iter().fold(0.0, |a: f64, &b| a.max(b));
        // ex9's digits
        assert_eq!(
            format!("{ours_mean:.3e} {ours_max:.3e}"),
            format!("{mean:.3e} {max:.3e}"),
            "N = {n} on {size} ranks against ex9"
        );
        // the native solver's answer
        let settings = Settings {
            pair: Some("p1-nodal".into()),
            mesh_size: Some(n),
            ..Settings::default()
        };
        let native = families::solve(&scene, &settings).unwrap().report.solve;
        let (native_mean, native_max) = (
            native.error_vertex_mean.unwrap(),
            native.error_vertex_max.unwrap(),
        );
        assert!(
            (ours_mean - native_mean).abs() <= 1e-9 * native_mean
                && (ours_max - native_max).abs() <= 1e-9 * native_max,
            "N = {n} on {size} ranks: mean {ours_mean:e}, max {ours_max:e} against the native {native_mean:e}, {native_max:e}"
        );
        println!(
            "rank {rank}/{size}, N = {n}: {} cells, {} rows here; {} after {} iterations; mean error {ours_mean:.4e} (native {native_mean:.4e}), max {ours_max:.4e}",
            solution.cells_here,
            solution.rows_here,
            solution.converged.reason,
            solution.converged.iterations
        );
    }
}
