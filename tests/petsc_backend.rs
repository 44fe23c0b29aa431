//! `fem-forms solve SCENE --backend petsc` under `mpirun -n 2`, in a binary built with
//! the `petsc` feature (`cargo test --release --features petsc --test petsc_backend`,
//! which `.ci/run` runs): the report equals the native solve's to the solvers'
//! tolerance (energy, ∫λ_h, contact area), carries PETSc's reasons and iteration counts,
//! and a SNES that stops without converging is an error naming its reason, not an answer.
#![cfg(feature = "petsc")]

use std::process::{Command, Output};

fn fem_forms(ranks: Option<usize>, args: &[&str]) -> Output {
    let binary = env!("CARGO_BIN_EXE_fem-forms");
    let mut command = match ranks {
        Some(n) => {
            let mut c = Command::new("mpirun");
            c.args([
                "--allow-run-as-root",
                "--oversubscribe",
                "-n",
                &n.to_string(),
                binary,
            ]);
            c.env("OMPI_ALLOW_RUN_AS_ROOT", "1")
                .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1");
            c
        }
        None => Command::new(binary),
    };
    command
        .args(args)
        .output()
        .expect("fem-forms (and mpirun) run")
}

fn json(output: &Output) -> serde_json::Value {
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    serde_json::from_slice(&output.stdout).expect("one JSON report, from rank 0 alone")
}

#[test]
fn the_report_of_two_ranks_equals_the_native_one() {
    for (scene, pair, n) in [
        ("membrane-radial", "p2-p0", "16"),
        ("membrane-radial", "p1-nodal", "16"),
        ("kirchhoff-obstacle", "morley-p0", "16"),
        ("hertz", "p1-p0", "4"),
    ] {
        let args = ["solve", scene, "--pair", pair, "--mesh-size", n, "--json"];
        let native = json(&fem_forms(None, &args));
        let mut distributed = args.to_vec();
        distributed.extend(["--backend", "petsc"]);
        let ours = json(&fem_forms(Some(2), &distributed));
        assert_eq!(ours["solver"], "petsc", "{scene} {pair}");
        let number = |r: &serde_json::Value, key: &str| r[key].as_f64();
        for key in [
            "energy",
            "total_contact_force",
            "contact_area",
            "contact_length",
        ] {
            match (number(&native, key), number(&ours, key)) {
                (Some(a), Some(b)) => assert!(
                    (a - b).abs() <= 1e-8 * a.abs().max(1e-12),
                    "{scene} {pair}: {key} {a} native, {b} by PETSc"
                ),
                (a, b) => assert_eq!(a.is_some(), b.is_some(), "{scene} {pair}: {key}"),
            }
        }
        let petsc = &ours["petsc"];
        assert_eq!(petsc["ranks"], 2);
        let levels = petsc["levels"].as_array().expect("levels");
        assert_eq!(
            levels.len(),
            ours["levels"].as_array().map_or(0, Vec::len),
            "{scene} {pair}: one PETSc solve per nested level"
        );
        for level in levels {
            let reason = level["converged_reason"].as_str().unwrap_or("");
            assert!(reason.starts_with("CONVERGED_"), "{scene} {pair}: {reason}");
            assert_eq!(level["purpose"], "answer", "{scene} {pair}");
            // the default: MUMPS's Cholesky or LU, whatever the report's native names
            let linear = level["linear_solver"].as_str().unwrap_or("");
            assert!(linear.ends_with("(mumps)"), "{scene} {pair}: {linear}");
        }
        assert_eq!(ours["linear_solver"], "petsc", "{scene} {pair}");
        let formulation = levels[0]["formulation"].as_str().unwrap_or("");
        let expected = if pair == "p1-nodal" {
            "primal"
        } else {
            "eliminated"
        };
        assert_eq!(formulation, expected, "{scene} {pair}");
        // each rank assembled its own cells of the finest level, contact's and the
        // nodal method's too
        let assembly = levels.last().map(|l| l["assembly"].clone());
        assert_eq!(assembly, Some("partitioned".into()), "{scene} {pair}");
    }
}

#[test]
fn the_levels_say_what_each_solve_served_and_its_linear_solver() {
    // the beam runs the rounding experiment: two more nested solves on moved meshes (a
    // Krylov tolerance at rounding: at CG's default 1e-5 the inexact Newton step's line
    // search on Φ fails near rounding, an error docs/petsc.md lists)
    let report = json(&fem_forms(
        Some(2),
        &[
            "solve",
            "bernoulli-flat",
            "--backend",
            "petsc",
            "--petsc-options",
            "-ksp_type cg -pc_type jacobi -ksp_rtol 1e-12",
            "--json",
        ],
    ));
    let levels = report["petsc"]["levels"].as_array().expect("levels");
    let nested = report["levels"].as_array().map_or(0, Vec::len);
    let count = |purpose: &str| levels.iter().filter(|l| l["purpose"] == purpose).count();
    assert_eq!(count("answer"), nested, "{levels:?}");
    assert_eq!(count("rounding experiment"), 2 * nested, "{levels:?}");
    assert!(
        levels.iter().all(|l| l["linear_solver"] == "cg + jacobi"),
        "{levels:?}"
    );
    // the model choice's probes
    let chosen = json(&fem_forms(
        Some(2),
        &[
            "solve",
            "timoshenko-t1e-3",
            "--backend",
            "petsc",
            "--tol",
            "5e-2",
            "--json",
        ],
    ));
    let levels = chosen["petsc"]["levels"].as_array().expect("levels");
    assert!(levels.iter().any(|l| l["purpose"] == "probe"), "{levels:?}");
    // Euler–Bernoulli's finer probe already reaches T and is the answer: its solves are
    // relabelled (they were all "probe")
    let taken = chosen["candidates"]
        .as_array()
        .expect("candidates")
        .iter()
        .find(|c| c["chosen"] == true)
        .expect("a chosen candidate");
    assert_eq!(
        taken["note"], "the probe's finer mesh already reaches the target",
        "{taken}"
    );
    let answers = count_of(levels, "answer");
    assert!(answers >= 1, "{levels:?}");
    assert_eq!(
        levels.last().map(|l| l["purpose"].clone()),
        Some("answer".into()),
        "{levels:?}"
    );
}

fn count_of(levels: &[serde_json::Value], purpose: &str) -> usize {
    levels.iter().filter(|l| l["purpose"] == purpose).count()
}

#[test]
fn a_snes_that_stops_short_is_an_error_naming_its_reason() {
    let output = fem_forms(
        Some(2),
        &[
            "solve",
            "membrane-radial",
            "--mesh-size",
            "16",
            "--cold",
            "--backend",
            "petsc",
            "--petsc-options",
            "-snes_max_it 1",
        ],
    );
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("DIVERGED_MAX_IT"), "{stderr}");
    assert!(output.stdout.is_empty(), "no answer printed");
}

#[test]
fn an_answer_petsc_calls_converged_is_checked_by_its_kkt_residual() {
    // `ksponly` takes one Newton step and reports CONVERGED_ITS: far from the solution
    let output = fem_forms(
        Some(2),
        &[
            "solve",
            "kirchhoff-obstacle",
            "--mesh-size",
            "8",
            "--backend",
            "petsc",
            "--petsc-options",
            "-snes_type ksponly",
        ],
    );
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("KKT residual"), "{stderr}");
    assert_eq!(
        stderr.matches("error:").count(),
        1,
        "one rank speaks: {stderr}"
    );
    assert!(output.stdout.is_empty(), "no answer printed");
}

#[test]
fn mpirun_without_the_backend_is_refused_once() {
    let output = fem_forms(Some(2), &["solve", "membrane-radial", "--mesh-size", "8"]);
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("only `solve … --backend petsc` runs distributed"),
        "{stderr}"
    );
    assert_eq!(stderr.matches("error:").count(), 1, "{stderr}");
}

#[test]
fn options_that_do_not_apply_are_refused() {
    for (args, words) in [
        (
            vec!["--backend", "petsc", "--petsc-formulation", "bogus"],
            "unknown formulation",
        ),
        (
            vec!["--backend", "petsc", "--solver", "clarabel"],
            "clarabel",
        ),
        (
            vec!["--backend", "petsc", "--linear-solver", "direct"],
            "its options choose",
        ),
        (
            vec!["--backend", "petsc", "--solver", "pdas"],
            "its options choose",
        ),
        (vec!["--backend", "cuda"], "unknown backend"),
    ] {
        let mut all = vec!["solve", "membrane-radial", "--mesh-size", "8"];
        all.extend(args);
        let output = fem_forms(None, &all);
        assert!(!output.status.success(), "{all:?}");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(stderr.contains(words), "{all:?}: {stderr}");
    }
}
