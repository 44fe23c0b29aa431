use fem_forms::beams::{solve, Request};
use fem_forms::models::scenes::SCENES;
use fem_forms::obstacle::VariationalSolver;
fn main() {
    for scene in SCENES {
        for q in [1.0, 40.0, 100.0] {
            for solver in [
                VariationalSolver::SemismoothNewton,
                VariationalSolver::Clarabel,
            ] {
                let mut r = Request::new(scene);
                r.load = q;
                r.solver = solver;
                match solve(&r) {
                    Ok((rep, _)) => println!("{:15} q={:5} {:9} it={:3} lv={:?} J={:.10e} kkt={:.1e} contact={:?} F={:.5} err={:?} t={:.3}s",
                        rep.scene, q, rep.solver, rep.iterations, rep.levels, rep.energy, rep.complementarity_residual, rep.contact_set, rep.total_contact_force, rep.error_l2, rep.seconds),
                    Err(e) => println!("{:15} q={q} {solver:?}: ERROR {e}", scene.name),
                }
            }
        }
    }
}
