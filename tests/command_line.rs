//! The command line as a user runs it: the membrane `solve --json` fields the issue
//! asks for, the VTK file, the studies' output files, and errors that exit non-zero
//! with a message instead of a panic.

use std::path::PathBuf;
use std::process::Command;

fn fem_forms(args: &[&str], out: &PathBuf) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_fem-forms"))
        .args(args)
        .arg("--out")
        .arg(out)
        .output()
        .expect("the binary runs")
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("fem-forms-cli-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn membrane_json_has_every_field_and_agrees_with_the_exact_solution() {
    let out = scratch("json");
    let clock = std::time::Instant::now();
    let run = fem_forms(
        &[
            "solve",
            "membrane-radial",
            "--pair",
            "p2-p0",
            "--mesh-size",
            "16",
            "--json",
            "--vtk",
        ],
        &out,
    );
    let elapsed = clock.elapsed().as_secs_f64();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
    for field in [
        "dofs",
        "iterations",
        "seconds",
        "error_l2",
        "error_h1",
        "total_contact_force",
        "contact_area",
        "alpha",
        "complementarity_residual",
    ] {
        assert!(
            json.get(field).is_some_and(|v| !v.is_null()),
            "{field} missing"
        );
    }
    let force = json["total_contact_force"].as_f64().unwrap();
    let exact = json["exact_contact_force"].as_f64().unwrap();
    assert!(
        (force - exact).abs() < 0.01 * exact,
        "∫λ_h = {force}, 2πA = {exact}"
    );
    assert!(json["complementarity_residual"].as_f64().unwrap() < 1e-10);
    assert!((json["alpha"].as_f64().unwrap() - 0.5 / 96.0).abs() < 1e-12);
    // the phases: non-negative, the solve's is `seconds`, together within the process
    let phases = &json["phases"];
    let phase = |name: &str| phases[name].as_f64().unwrap_or_else(|| panic!("{name}"));
    for name in ["meshes", "checks", "solve", "evaluation"] {
        assert!(phase(name) >= 0.0, "{name}");
    }
    assert_eq!(phase("solve"), json["seconds"].as_f64().unwrap());
    let total: f64 = ["meshes", "checks", "solve", "evaluation"]
        .iter()
        .map(|n| phase(n))
        .sum();
    assert!(total <= elapsed, "{total} s of phases in {elapsed} s");
    assert!(out.join("membrane-radial-p2-p0-16.vtu").exists());
    std::fs::remove_dir_all(&out).unwrap();
}

/// A load that bends u more sharply than the mesh resolves makes u_h cross ψ visibly:
/// said in the warnings (at the default load the crossing is 6e-4 of ψ's range and no
/// warning is given).
#[test]
fn a_visible_penetration_is_a_warning() {
    let out = scratch("penetration");
    for (load, warned) in [("12", false), ("1e4", true)] {
        let run = fem_forms(
            &[
                "solve",
                "membrane-lshape",
                "--load",
                load,
                "--mesh-size",
                "32",
                "--json",
            ],
            &out,
        );
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let json: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
        let warnings = json["warnings"].as_array().unwrap();
        let says = warnings
            .iter()
            .any(|w| w.as_str().unwrap().contains("dips below ψ"));
        assert_eq!(says, warned, "q = {load}: {warnings:?}");
    }
    std::fs::remove_dir_all(&out).unwrap();
}

#[test]
fn bad_input_exits_with_a_message() {
    let out = scratch("bad");
    for (args, message) in [
        (
            &["solve", "membrane-radial", "--pair", "p9-p9"][..],
            "unknown pair `p9-p9`",
        ),
        (
            &["solve", "membrane-radial", "--msh", "/nonexistent/mesh.msh"][..],
            "/nonexistent/mesh.msh",
        ),
        (
            &[
                "solve",
                "membrane-radial",
                "--alpha",
                "-1",
                "--mesh-size",
                "8",
            ][..],
            "α = -1",
        ),
        (&["study", "membrane-radial", "nonsense"][..], "nonsense"),
        // a value starting with a hyphen is --alpha's (clap took `-inf` for flags)
        (
            &["solve", "membrane-radial", "--alpha", "-inf"][..],
            "α = -inf",
        ),
        // about 24 GB: refused before any allocation (it used to abort in the factor)
        (
            &["solve", "mindlin-square", "--mesh-size", "1024"][..],
            "--mesh-size 1024 with p1-p2-p0 needs about",
        ),
        (
            &["solve", "bernoulli-flat", "--refinement", "1000000"][..],
            "--refinement 1000000 is out of range",
        ),
        (
            &["solve", "bernoulli-flat", "--load", "-5"][..],
            "must be finite and ≥ 0",
        ),
        (&["study", "no-such-study"][..], "unknown study"),
        (
            &["study", "convergence", "membrane-radial"][..],
            "did you mean `study membrane-radial convergence`?",
        ),
        (&["study", "timoshenko-b"][..], "the scenes that do are"),
        // a load that dwarfs the obstacle: certified to 1e-16, and still rounding
        (
            &[
                "solve",
                "membrane-lshape",
                "--load",
                "1e20",
                "--mesh-size",
                "8",
            ][..],
            "the load dwarfs the obstacle",
        ),
        (
            &["solve", "timoshenko-a", "--load", "1e25"][..],
            "dwarfs the obstacle",
        ),
        // a user's α far above the default, not the load, makes the rows' terms large
        (
            &[
                "solve",
                "bernoulli-flat",
                "--load",
                "100",
                "--alpha",
                "1e30",
            ][..],
            "with α = 1e30 (1e32 times the default",
        ),
        // memory estimated before: a tester's 4M Timoshenko elements took 21 GB
        (
            &["solve", "timoshenko-a", "--elements", "20000000"][..],
            "needs about 110.0 GB",
        ),
        // the Hermite stiffness's h⁻⁴ is named (it was α·C_I and a free rigid motion)
        (
            &[
                "solve",
                "bernoulli-flat",
                "--load",
                "1",
                "--elements",
                "100000",
            ][..],
            "conditions the system like h⁻⁴",
        ),
        // loads that underflow with powers of h (Newton stopped at a residual of 8e-3)
        (
            &["solve", "bernoulli-flat", "--load", "1e-315"][..],
            "(subnormal) is below 1e-200",
        ),
        (
            &["solve", "membrane-flat", "--load", "-1e-310"][..],
            "is below 1e-200",
        ),
        (
            &["solve", "timoshenko-a", "--load", "2.3e-308"][..],
            "is below 1e-200",
        ),
        (
            &["solve", "bernoulli-a", "--load", "1e200"][..],
            "would overflow",
        ),
        (
            &["solve", "timoshenko-b", "--thickness", "1e7"][..],
            "exceeds the beam's length",
        ),
        (
            &["solve", "mindlin-square", "--thickness", "2"][..],
            "exceeds the plate's side",
        ),
        (
            &["solve", "timoshenko-a", "--thickness", "1e-8"][..],
            "the Euler–Bernoulli model is the limit",
        ),
        // a negative exponent is a value, not an option (clap read it as a flag)
        (
            &["solve", "timoshenko-a", "--thickness", "-1e-3"][..],
            "must be positive and finite",
        ),
    ] {
        let run = fem_forms(args, &out);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(!run.status.success(), "{args:?} succeeded");
        assert!(stderr.contains(message), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
    // an --out that is a file is refused before any work
    let file = out.join("a-file");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(&file, "not a directory").unwrap();
    let run = fem_forms(&["study", "bernoulli-flat", "alpha"], &file);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success());
    assert!(
        stderr.contains("exists and is not a directory") && stderr.contains("a-file"),
        "{stderr}"
    );
    // an --out where no file can be written (here /proc) is refused before any work,
    // naming it (a tester's read-only --out failed after the whole study)
    let run = fem_forms(
        &["study", "bernoulli-flat", "alpha"],
        &PathBuf::from("/proc"),
    );
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        !run.status.success() && stderr.contains("--out /proc: cannot write files there"),
        "{stderr}"
    );
    std::fs::remove_dir_all(&out).unwrap();
}

#[test]
fn the_stability_study_writes_its_chart_and_table() {
    let out = scratch("study");
    let run = fem_forms(&["study", "membrane-radial", "stability"], &out);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let csv = std::fs::read_to_string(out.join("membrane-radial-stability.csv")).unwrap();
    // the pair by name, as the plates' and contact's CSVs have it (a tester found an
    // index column that nothing explained)
    assert!(csv.starts_with("pair,size,alpha"), "{csv}");
    assert!(csv.lines().count() > 6);
    let pairs: Vec<&str> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap())
        .collect();
    assert!(
        pairs.contains(&"p1-p0") && pairs.iter().all(|p| p.starts_with('p')),
        "{csv}"
    );
    let svg = std::fs::read_to_string(out.join("membrane-radial-stability.svg")).unwrap();
    assert!(svg.contains("<svg"));
    std::fs::remove_dir_all(&out).unwrap();
}

/// The adaptivity study: uniform and adaptive rows in one CSV and four charts; the
/// adaptive run reaches a smaller true error than the finest uniform mesh with fewer
/// unknowns (bernoulli-flat: the contact ends; membrane-radial: the free boundary).
#[test]
fn the_adaptivity_study_shows_adaptive_beating_uniform() {
    let out = scratch("adaptivity-study");
    for scene in ["bernoulli-flat", "membrane-radial"] {
        let run = fem_forms(&["study", scene, "adaptivity"], &out);
        assert!(
            run.status.success(),
            "{scene}: {}",
            String::from_utf8_lossy(&run.stderr)
        );
        let csv = std::fs::read_to_string(out.join(format!("{scene}-adaptivity.csv"))).unwrap();
        assert!(
            csv.starts_with("run,cells,dofs,estimate,error_energy,seconds"),
            "{csv}"
        );
        let last = |name: &str| -> Vec<f64> {
            let line = csv
                .lines()
                .rfind(|l| l.starts_with(&format!("{name},")))
                .unwrap_or_else(|| panic!("{scene}: no {name} row in {csv}"));
            line.split(',')
                .skip(1)
                .map(|v| v.parse().unwrap())
                .collect()
        };
        let (uniform, adaptive) = (last("uniform"), last("adaptive"));
        // [cells, dofs, estimate, error, seconds]
        assert!(
            adaptive[3] < uniform[3] && adaptive[1] < uniform[1],
            "{scene}: adaptive {adaptive:?} against uniform {uniform:?}"
        );
        for chart in ["", "-efficiency", "-time", "-mesh"] {
            let svg = std::fs::read_to_string(out.join(format!("{scene}-adaptivity{chart}.svg")))
                .unwrap_or_else(|e| panic!("{scene}{chart}: {e}"));
            assert!(svg.contains("<svg"));
        }
    }
    std::fs::remove_dir_all(&out).unwrap();
}

/// Options are checked against the scene's family: one that does not apply is an error
/// naming it, not silently ignored.
#[test]
fn options_that_do_not_apply_are_refused_by_name() {
    let out = scratch("options");
    for (args, option) in [
        (
            &["solve", "membrane-flat", "--thickness", "0.01"][..],
            "--thickness",
        ),
        (
            &["solve", "membrane-flat", "--elements", "64"][..],
            "--elements",
        ),
        (
            &["solve", "membrane-lshape", "--refinement", "2"][..],
            "--refinement",
        ),
        (&["solve", "membrane-lshape", "--plot"][..], "--plot"),
        (&["solve", "bernoulli-a", "--msh", "x.msh"][..], "--msh"),
        (
            &["solve", "bernoulli-a", "--mesh-size", "8"][..],
            "--mesh-size",
        ),
        (&["solve", "timoshenko-a", "--vtk"][..], "--vtk"),
        (
            &["solve", "bernoulli-a", "--thickness", "0.01"][..],
            "--thickness",
        ),
        (&["solve", "membrane-radial", "--load", "2"][..], "--load"),
        (
            &["solve", "bernoulli-a", "--linear-solver", "banded"][..],
            "--linear-solver",
        ),
        (
            &["solve", "membrane-flat", "--linear-solver", "gmres"][..],
            "--linear-solver",
        ),
        (
            &[
                "solve",
                "membrane-flat",
                "--pair",
                "p1-nodal",
                "--alpha",
                "0.1",
            ][..],
            "--alpha",
        ),
    ] {
        let run = fem_forms(args, &out);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(!run.status.success(), "{args:?} succeeded");
        assert!(stderr.contains(option), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
    std::fs::remove_dir_all(&out).unwrap();
}

fn json_of(args: &[&str], out: &PathBuf) -> serde_json::Value {
    let run = fem_forms(args, out);
    assert!(
        run.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&run.stderr)
    );
    serde_json::from_slice(&run.stdout).unwrap()
}

/// `--load q` scales the membrane's load field: membrane-flat is f = −q, so u = 0,
/// λ = q and ∫λ = 16q on (−2,2)² (48 at the scene's own q = 3).
#[test]
fn load_scales_the_membrane_load() {
    let out = scratch("load");
    for (q, args) in [
        (
            3.0,
            &["solve", "membrane-flat", "--mesh-size", "8", "--json"][..],
        ),
        (
            1.0,
            &[
                "solve",
                "membrane-flat",
                "--mesh-size",
                "8",
                "--json",
                "--load",
                "1",
            ][..],
        ),
        (
            5.0,
            &[
                "solve",
                "membrane-flat",
                "--mesh-size",
                "8",
                "--json",
                "--load",
                "5",
            ][..],
        ),
    ] {
        let json = json_of(args, &out);
        let force = json["total_contact_force"].as_f64().unwrap();
        assert!(
            (force - 16.0 * q).abs() < 1e-7 * 16.0 * q,
            "q = {q}: ∫λ_h = {force}"
        );
        assert_eq!(json["load"].as_f64(), Some(q));
        assert_eq!(json["exact_contact_force"].as_f64(), Some(16.0 * q));
    }
    std::fs::remove_dir_all(&out).unwrap();
}

/// On a Gmsh mesh of another domain the scene's own constants (∫λ, contact area of
/// (−2,2)²) are not reported as exact; the errors against the exact field stay (g is
/// u_exact there, so it is the solution on the disk too).
#[test]
fn json_is_honest_about_the_domain() {
    let out = scratch("domain");
    let disk = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/disk_r1_order1.msh");
    let json = json_of(
        &[
            "solve",
            "membrane-radial",
            "--msh",
            disk,
            "--pair",
            "p1-p0",
            "--json",
        ],
        &out,
    );
    assert!(json["exact_contact_force"].is_null(), "{json}");
    assert!(json["exact_contact_area"].is_null(), "{json}");
    assert!(json["domain"]
        .as_str()
        .unwrap()
        .contains("disk_r1_order1.msh"));
    // the contact disk r* = 0.698 lies inside the unit disk: the error is small
    assert!(json["error_l2"].as_f64().unwrap() < 0.05, "{json}");
    let own = json_of(
        &["solve", "membrane-radial", "--mesh-size", "8", "--json"],
        &out,
    );
    assert!(own["exact_contact_force"].as_f64().is_some());
    std::fs::remove_dir_all(&out).unwrap();
}

/// A scene file's mesh size belongs to its own mesh: with `--msh` replacing that mesh,
/// the file is solved on the given mesh unrefined (it was read as 16 refinements), and
/// a negative `--load` reaches the scene's own check instead of clap's "unexpected
/// argument". membrane-flat pressed the other way has no exact solution to claim.
#[test]
fn scene_files_with_msh_and_negative_loads() {
    let out = scratch("scene-msh");
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/membrane-flat.toml");
    let halves = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/halves_coherent.msh"
    );
    let json = json_of(
        &["solve", "--scene", scene, "--msh", halves, "--json"],
        &out,
    );
    let file_only = json_of(
        &["solve", "membrane-radial", "--msh", halves, "--json"],
        &out,
    );
    assert_eq!(json["triangles"], file_only["triangles"], "{json}");
    let lifted = json_of(
        &[
            "solve",
            "membrane-flat",
            "--load",
            "-5",
            "--mesh-size",
            "8",
            "--json",
        ],
        &out,
    );
    assert!(lifted["exact_contact_force"].is_null(), "{lifted}");
    assert!(lifted["error_l2"].is_null(), "{lifted}");
    assert_eq!(
        lifted["total_contact_force"].as_f64(),
        Some(0.0),
        "{lifted}"
    );
    assert_eq!(lifted["contact_area"].as_f64(), Some(0.0), "{lifted}");
    // the nodal method's boundary vertices sit on ψ = g = 0 whether or not the membrane
    // touches: lifted off, no contact; pressed flat, all of (−2,2)²
    for (load, area) in [("-5", 0.0), ("3", 16.0)] {
        let nodal = json_of(
            &[
                "solve",
                "membrane-flat",
                "--pair",
                "p1-nodal",
                "--load",
                load,
                "--mesh-size",
                "8",
                "--json",
            ],
            &out,
        );
        let measured = nodal["contact_area"].as_f64().unwrap();
        assert!((measured - area).abs() < 1e-9, "--load {load}: {nodal}");
    }
}

/// `--linear-solver multigrid` solves the finest level's Newton steps by CG (no
/// factorization) and gives the direct solver's answer; the default (auto) keeps
/// Cholesky on a system this small.
#[test]
fn the_linear_solver_is_chosen_and_reported() {
    let out = scratch("linear-solver");
    let args = [
        "solve",
        "membrane-radial",
        "--pair",
        "p1-p0",
        "--mesh-size",
        "32",
        "--json",
    ];
    let auto = json_of(&args, &out);
    assert_eq!(auto["linear_solver"], "direct");
    assert!(auto["factorizations"].as_u64().unwrap() > 0);
    let multigrid = json_of(
        &[&args[..], &["--linear-solver", "multigrid"]].concat(),
        &out,
    );
    assert_eq!(multigrid["linear_solver"], "multigrid");
    assert_eq!(multigrid["factorizations"], 0);
    assert!(multigrid["krylov_iterations"].as_u64().unwrap() > 0);
    let (a, b) = (
        auto["error_l2"].as_f64().unwrap(),
        multigrid["error_l2"].as_f64().unwrap(),
    );
    assert!((a - b).abs() <= 1e-9 * a, "{a} against {b}");
    // beams too: the Hermite prolongation on the nested interval meshes
    let beam = ["solve", "bernoulli-flat", "--load", "100", "--json"];
    let direct = json_of(&beam, &out);
    assert_eq!(direct["linear_solver"], "direct");
    let multigrid = json_of(
        &[&beam[..], &["--linear-solver", "multigrid"]].concat(),
        &out,
    );
    assert_eq!(multigrid["linear_solver"], "multigrid");
    assert!(multigrid["krylov_iterations"].as_u64().unwrap() > 0);
    // the error (2e-7) is far below w (5e-2): the two solves agree to CG's 1e-10 of w
    let (a, b) = (
        direct["error_l2"].as_f64().unwrap(),
        multigrid["error_l2"].as_f64().unwrap(),
    );
    let w = direct["max_deflection"].as_f64().unwrap();
    assert!((a - b).abs() <= 1e-10 * w, "{a} against {b}");
    // a cold start has no coarser level: said, not silently factored
    let cold = json_of(
        &[&beam[..], &["--linear-solver", "multigrid", "--cold"]].concat(),
        &out,
    );
    assert_eq!(cold["linear_solver"], "direct");
    assert!(
        cold["warnings"]
            .to_string()
            .contains("--linear-solver multigrid"),
        "{cold}"
    );
    std::fs::remove_dir_all(&out).unwrap();
}

/// `--alpha -0` is the plain method (α = 0), reported as 0 and not as a negative zero;
/// a plain pair with more multipliers than primal unknowns says that λ_h is not unique.
#[test]
fn a_negative_zero_alpha_is_the_plain_method_whose_multiplier_may_not_be_unique() {
    let out = scratch("negative-zero-alpha");
    let json = json_of(
        &[
            "solve",
            "membrane-flat",
            "--pair",
            "p1-p0",
            "--mesh-size",
            "4",
            "--alpha=-0",
            "--json",
        ],
        &out,
    );
    let alpha = json["alpha"].as_f64().unwrap();
    assert!(alpha == 0.0 && alpha.is_sign_positive(), "α = {alpha}");
    // the plain P1–P0 pair has 32 multipliers for 9 free vertices: λ_h is one of many
    // (∫λ_h came out 45.4 against the exact 48, without a word), u_h = 0 is unique
    let warnings = json["warnings"].to_string();
    assert!(
        warnings.contains("32 multipliers for 9 primal unknowns")
            && warnings.contains("at least 23"),
        "{warnings}"
    );
    assert!(json["error_l2"].as_f64().unwrap() < 1e-12);
    // P2–P0 has fewer multipliers than primal unknowns: no such warning
    let json = json_of(
        &[
            "solve",
            "membrane-flat",
            "--pair",
            "p2-p0",
            "--mesh-size",
            "4",
            "--alpha",
            "0",
            "--json",
        ],
        &out,
    );
    assert!(!json["warnings"].to_string().contains("kernel"));
    assert!((json["total_contact_force"].as_f64().unwrap() - 48.0).abs() < 1e-8);
}

/// A tester's two-triangle square (no interior vertex, so u_h is the boundary data
/// ≈ −0.24): under the radial ψ = √(1 − r²) the membrane lies 1.24 below ψ at the
/// centre, between the vertices and the quadrature points, where ψ = −1. It was
/// reported as `max_penetration` 0 (P1) or 0.95 without a warning (ψ's range was taken
/// at the vertices only, where ψ is flat). Now the few cells are sampled on a lattice,
/// ψ's range over the same points, and every pair warns.
#[test]
fn a_mesh_of_few_cells_does_not_hide_a_penetration() {
    let out = scratch("two-triangles");
    let mesh = out.join("two_triangles.msh");
    std::fs::write(
        &mesh,
        "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 1 0\n1 -1 -1 0 1 1 0 0 0\n$EndEntities\n\
         $Nodes\n1 4 1 4\n2 1 0 4\n1\n2\n3\n4\n-2 -2 0\n2 -2 0\n2 2 0\n-2 2 0\n$EndNodes\n\
         $Elements\n1 2 1 2\n2 1 2 2\n1 1 2 3\n2 1 3 4\n$EndElements\n",
    )
    .unwrap();
    for pair in ["p1-p0", "p1-nodal", "p2-p0"] {
        let json = json_of(
            &[
                "solve",
                "membrane-radial",
                "--msh",
                mesh.to_str().unwrap(),
                "--pair",
                pair,
                "--json",
            ],
            &out,
        );
        // u_h(0) is the mean of the diagonal's ends, the exact u there: ψ(0) = 1 lies
        // 1 − u(2, 2) above it (P2: u_h is the boundary data's quadratic, a little higher)
        let depth = json["max_penetration"].as_f64().unwrap();
        assert!(depth > 0.95 && depth < 1.3, "{pair}: {json}");
        assert!(
            json["warnings"].to_string().contains("dips below ψ"),
            "{pair}: {json}"
        );
    }
    std::fs::remove_dir_all(&out).unwrap();
}

/// A tester's beams with a contact set that α made, with no warning: bernoulli-flat at
/// α = 1e10 put all of [0, 1] in contact with w_h 0.05 clear of ψ, and timoshenko-a on
/// one element (q = 1, no contact) pushed with ∫λ_h = 0.92 where w_h is 1e-8. The gap
/// under the pushing cells is now reported and warned about, as for membranes and
/// plates; an α far above the pair's default is warned about even without a gap. The
/// default runs have neither warning.
#[test]
fn beams_warn_about_a_contact_set_that_alpha_made() {
    let out = scratch("beam-gap");
    let clear = |args: &[&str]| {
        let mut all = vec!["solve"];
        all.extend_from_slice(args);
        all.push("--json");
        let json = json_of(&all, &out);
        let gap = json["max_open_contact_gap"].as_f64().unwrap();
        (gap, json["warnings"].to_string(), json)
    };
    // bernoulli-flat's ψ is 0.05 away from the rest position and w_h stays near rest
    let (gap, warnings, json) = clear(&["bernoulli-flat", "--load", "100", "--alpha", "1e10"]);
    let max_w = json["max_deflection"].as_f64().unwrap();
    assert!(gap > 0.05 - 2.0 * max_w && gap <= 0.05, "{json}");
    assert!(
        warnings.contains("clear of ψ") && warnings.contains("lower α"),
        "{warnings}"
    );
    let (gap, warnings, json) = clear(&["timoshenko-a", "--elements", "1"]);
    assert!(gap > 0.04, "{json}");
    assert!(warnings.contains("clear of ψ"), "{warnings}");
    let (_, warnings, _) = clear(&["bernoulli-flat", "--load", "100", "--alpha", "1e4"]);
    assert!(warnings.contains("times the default"), "{warnings}");
    for scene in [
        &["bernoulli-flat", "--load", "100"][..],
        &["timoshenko-a", "--load", "100"],
    ] {
        let (gap, warnings, json) = clear(scene);
        assert!(gap < 1e-10, "{json}");
        assert_eq!(warnings, "[]", "{scene:?}");
    }
    std::fs::remove_dir_all(&out).unwrap();
}

/// A tester's small output faults: the plate line printed t = 0.0025 as "3e-3"; the
/// Kirchhoff warnings went to stdout while every other family writes them to stderr;
/// `--cold` with clarabel (which solves the finest mesh alone) was accepted and ignored.
#[test]
fn text_output_keeps_the_thickness_and_warnings_on_stderr() {
    let out = scratch("text-output");
    let run = fem_forms(&["solve", "mindlin-square", "--thickness", "0.0025"], &out);
    let text = String::from_utf8_lossy(&run.stdout);
    assert!(
        run.status.success() && text.contains("t = 0.0025"),
        "{text}"
    );
    let run = fem_forms(&["solve", "kirchhoff-obstacle", "--mesh-size", "2"], &out);
    let (text, errors) = (
        String::from_utf8_lossy(&run.stdout),
        String::from_utf8_lossy(&run.stderr),
    );
    assert!(run.status.success(), "{errors}");
    assert!(
        !text.contains("warning") && errors.contains("warning: "),
        "{text}\n{errors}"
    );
    let run = fem_forms(
        &["solve", "membrane-lshape", "--solver", "clarabel", "--cold"],
        &out,
    );
    let errors = String::from_utf8_lossy(&run.stderr);
    assert!(
        !run.status.success() && errors.contains("--cold does not apply"),
        "{errors}"
    );
    // α = 0 goes to clarabel too: --cold and an explicit --solver pdas cannot act
    for (extra, refused) in [
        (&["--cold"][..], "--cold does not apply"),
        (&["--solver", "pdas"], "--solver pdas does not apply"),
    ] {
        let args = [&["solve", "membrane-flat", "--alpha", "0"][..], extra].concat();
        let run = fem_forms(&args, &out);
        let errors = String::from_utf8_lossy(&run.stderr);
        assert!(
            !run.status.success() && errors.contains(refused),
            "{errors}"
        );
    }
    std::fs::remove_dir_all(&out).ok();
}

/// Extreme numbers a user gives are echoed as they were written, not as 300-digit
/// decimals (a tester's --thickness 1e300 and half_width 1e-200).
#[test]
fn refusals_echo_extreme_numbers_in_scientific_notation() {
    let out = scratch("extreme-numbers");
    for (args, number) in [
        (
            &["solve", "mindlin-square", "--thickness", "1e300"][..],
            "1e300",
        ),
        (
            &["solve", "timoshenko-a", "--thickness", "-1e300"][..],
            "-1e300",
        ),
    ] {
        let run = fem_forms(args, &out);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(!run.status.success());
        assert!(
            stderr.contains(&format!("t = {number}")) && !stderr.contains("00000000"),
            "{stderr}"
        );
    }
}

/// `--tol` solves adaptively: the JSON lists every level with its estimate, the last
/// one below the tolerance relative to ‖u_h‖_a, the estimate falls while the error does,
/// and the `.vtu` carries the indicators. A scene file's `tol` does the same.
#[test]
fn tol_solves_adaptively_and_reports_every_level() {
    let out = scratch("tol");
    let args = [
        "solve",
        "membrane-radial",
        "--mesh-size",
        "8",
        "--pair",
        "p1-p0",
        "--tol",
        "0.2",
        "--json",
        "--vtk",
    ];
    let report = json_of(&args, &out);
    let levels = report["adaptive_levels"].as_array().unwrap();
    assert!(levels.len() >= 3, "{levels:?}");
    let last = levels.last().unwrap();
    let (estimate, norm) = (
        last["estimate"].as_f64().unwrap(),
        last["energy_norm"].as_f64().unwrap(),
    );
    assert!(estimate <= 0.2 * norm, "{last}");
    assert_eq!(report["estimate"].as_f64(), Some(estimate));
    assert!(report["efficiency_index"].as_f64().unwrap() > 1.0);
    let errors: Vec<f64> = levels
        .iter()
        .map(|l| l["error_energy"].as_f64().unwrap())
        .collect();
    assert!(errors.last().unwrap() < &errors[0], "{errors:?}");
    // named after the final mesh's cells, not the starting size
    let cells = last["cells"].as_u64().unwrap();
    let name = format!("membrane-radial-p1-p0-adaptive-{cells}-cells.vtu");
    let vtu = std::fs::read_to_string(out.join(&name)).unwrap();
    assert!(vtu.contains("indicator"), "the .vtu has no indicator field");
    assert!(
        vtu.contains(&format!("NumberOfCells=\"{cells}\"")),
        "{name}"
    );

    // a scene file's `tol`: the radial example, from a coarse mesh
    let example = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/membrane-radial.toml"
    ))
    .unwrap()
    .replace("size = 32", "size = 8")
    .replace(
        "model = \"membrane\"",
        "model = \"membrane\"\npair = \"p1-p0\"\ntol = 0.3",
    );
    let file = out.join("radial-tol.toml");
    std::fs::write(&file, example).unwrap();
    let report = json_of(
        &["solve", "--scene", file.to_str().unwrap(), "--json"],
        &out,
    );
    let levels = report["adaptive_levels"].as_array().unwrap();
    assert!(levels.len() >= 2, "{report}");
    let last = levels.last().unwrap();
    assert!(last["estimate"].as_f64().unwrap() <= 0.3 * last["energy_norm"].as_f64().unwrap());
    let bad = out.join("radial-bad-tol.toml");
    std::fs::write(
        &bad,
        std::fs::read_to_string(&file)
            .unwrap()
            .replace("tol = 0.3", "tol = -2"),
    )
    .unwrap();
    let run = fem_forms(&["solve", "--scene", bad.to_str().unwrap()], &out);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success() && stderr.contains("tol"), "{stderr}");

    // a file's `tol` solves adaptively in every family: the Winkler plate's too
    let winkler = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/winkler-free-plate.toml"
    ))
    .unwrap()
    .replacen("\nname = ", "\ntol = 0.01\nname = ", 1);
    assert!(
        winkler.contains("tol = 0.01"),
        "the example has no `name` line"
    );
    let file = out.join("winkler-tol.toml");
    std::fs::write(&file, winkler).unwrap();
    let report = json_of(
        &["solve", "--scene", file.to_str().unwrap(), "--json"],
        &out,
    );
    let levels = report["adaptive_levels"]
        .as_array()
        .expect("adaptive levels");
    let last = levels.last().unwrap();
    assert!(
        levels.len() > 1
            && last["estimate"].as_f64().unwrap() <= 0.01 * last["energy_norm"].as_f64().unwrap(),
        "{levels:?}"
    );
}

/// The adaptive options are refused where they cannot act, with the reason.
#[test]
fn adaptive_options_are_checked() {
    let out = scratch("tol-errors");
    for (args, expected) in [
        (
            vec!["solve", "membrane-radial", "--marking", "max"],
            "give --tol",
        ),
        (vec!["solve", "membrane-radial", "--tol", "-1"], "in (0, 1)"),
        (vec!["solve", "membrane-radial", "--tol", "2"], "in (0, 1)"),
        (
            vec![
                "solve",
                "membrane-radial",
                "--tol",
                "0.1",
                "--marking",
                "greedy",
            ],
            "dorfler",
        ),
        (
            vec!["solve", "membrane-radial", "--tol", "0.1", "--theta", "2"],
            "(0, 1]",
        ),
        (
            vec!["solve", "membrane-radial", "--max-dofs", "100"],
            "give --tol",
        ),
        (
            vec![
                "solve",
                "membrane-radial",
                "--tol",
                "0.1",
                "--max-dofs",
                "0",
            ],
            "must be positive",
        ),
        // the limit stops the loop before a larger level, saying how far it got
        (
            vec![
                "solve",
                "membrane-lshape",
                "--tol",
                "1e-3",
                "--mesh-size",
                "4",
                "--pair",
                "p1-p0",
                "--max-dofs",
                "400",
            ],
            "beyond the adaptive loop's limit of 400",
        ),
    ] {
        let run = fem_forms(&args, &out);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(!run.status.success(), "{args:?} succeeded");
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
}

/// `report`: a scene that is not there, or hosts no study, is refused by name before
/// any study runs; a scene's studies give a page with its charts.
#[test]
fn report_checks_its_scenes_and_writes_the_page() {
    let out = scratch("report");
    for (scene, words) in [
        ("no-such-scene", "--scene no-such-scene: no such scene"),
        ("membrane-flat", "--scene membrane-flat: hosts no study"),
        ("mindlin-disk-q10", "a study variant of `mindlin-disk`"),
    ] {
        let output = fem_forms(&["report", "--scene", scene], &out);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!output.status.success());
        assert!(stderr.contains(words), "{stderr}");
        assert!(!out.join("index.html").exists());
        // a refused command leaves no --out it created
        let fresh = out.join("not-yet");
        let refused = fem_forms(&["report", "--scene", scene], &fresh);
        assert!(!refused.status.success());
        assert!(!fresh.exists(), "{}", fresh.display());
    }
    let output = fem_forms(&["report", "--scene", "timoshenko-a"], &out);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let page = std::fs::read_to_string(out.join("index.html")).unwrap();
    for chart in [
        "studies/timoshenko-a-locking/timoshenko-a-locking.svg",
        "studies/timoshenko-a-stability/timoshenko-a-stability.svg",
        "studies/timoshenko-a-iterations/timoshenko-a-iterations.svg",
    ] {
        assert!(page.contains(chart), "{chart}");
        assert!(out.join(chart).exists(), "{chart}");
    }
    // the studies' printing went to their logs, not to the terminal
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert_eq!(
        stdout.trim(),
        format!("→ {}", out.join("index.html").display())
    );
}
