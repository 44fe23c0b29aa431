//! Scene files (`fem-forms solve --scene my.toml`): the examples that reproduce built-in
//! scenes give the built-in scenes' numbers, and the disk example, a problem no built-in
//! scene poses, is checked by identities and an independent solver.

use fem_forms::models::families;
use fem_forms::models::geometry::Fields;
use fem_forms::models::report::{Report, Settings};
use fem_forms::models::scene_file::{self, FileScene};
use fem_forms::obstacle::VariationalSolver;
use fem_forms::TriangleMesh;
use std::path::{Path, PathBuf};

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples")
        .join(name)
}

/// Solves a file's scene with its settings, changed by `change`.
fn solve_with(
    file: &FileScene,
    change: impl FnOnce(&mut Settings),
) -> fem_forms::Result<(Report, Fields)> {
    let mut settings = file.settings();
    change(&mut settings);
    families::solve(&file.scene, &settings).map(|o| (o.report, o.fields))
}

fn solve(file: &FileScene) -> fem_forms::Result<(Report, Fields)> {
    solve_with(file, |_| {})
}

/// The mesh and the vertex values of field `name` (`u`, `psi`) of a triangle solve.
fn vertex<'a>(fields: &'a Fields, name: &str) -> (&'a TriangleMesh, &'a [f64]) {
    let Fields::Triangles { mesh, vertex, .. } = fields else {
        panic!("a membrane is solved on triangles");
    };
    let values = vertex.iter().find(|(n, _)| *n == name).expect("the field");
    (mesh, &values.1)
}

/// The per-cell mean multiplier of a triangle solve.
fn lambda(fields: &Fields) -> &[f64] {
    let Fields::Triangles { cell, .. } = fields else {
        panic!("a membrane is solved on triangles");
    };
    &cell.iter().find(|(n, _)| *n == "lambda").expect("λ").1
}

fn area(mesh: &TriangleMesh) -> f64 {
    (0..mesh.cell_count()).map(|c| mesh.area(c)).sum()
}

fn dirichlet_parts(report: &Report) -> Vec<String> {
    serde_json::from_value(report.quantities["dirichlet_parts"].clone()).unwrap()
}

fn close(a: f64, b: f64, what: &str, scene: &str) {
    assert!(
        (a - b).abs() <= 1e-9 * (1.0 + a.abs().max(b.abs())),
        "{scene}: {what} {a} (file) vs {b} (built-in)"
    );
}

fn same_numbers(file: &Report, builtin: &Report) {
    let s = &builtin.scene;
    let (f, b) = (&file.solve, &builtin.solve);
    assert_eq!(f.cells, b.cells, "{s}");
    assert_eq!(f.dofs, b.dofs, "{s}");
    assert_eq!(f.iterations, b.iterations, "{s}");
    assert_eq!(f.levels, b.levels, "{s}");
    close(f.alpha.unwrap(), b.alpha.unwrap(), "α", s);
    close(f.total_contact_force, b.total_contact_force, "∫λ_h", s);
    close(
        f.contact_area.unwrap(),
        b.contact_area.unwrap(),
        "contact area",
        s,
    );
    assert!(f.complementarity_residual < 1e-8, "{s}: {file:?}");
    for (a, b, what) in [
        (f.error_l2, b.error_l2, "L² error"),
        (
            file.exact_contact_force,
            builtin.exact_contact_force,
            "exact ∫λ",
        ),
        (
            file.exact_contact_area,
            builtin.exact_contact_area,
            "exact area",
        ),
    ] {
        if let (Some(a), Some(b)) = (a, b) {
            close(a, b, what, s);
        }
    }
}

/// Each example named after a built-in scene reproduces it: same mesh, pair, α, load,
/// obstacle and boundary data give the same solve.
#[test]
fn examples_reproduce_the_builtin_scenes() {
    for name in ["membrane-flat", "membrane-lshape", "membrane-radial"] {
        let file = scene_file::read(&example(&format!("{name}.toml"))).unwrap();
        let (from_file, _) = solve(&file).unwrap();
        let scene = families::scene(name).expect("a built-in membrane scene");
        let mut settings = file.settings();
        settings.mesh_size = Some(file.scene.mesh_size);
        let builtin = families::solve(&scene, &settings).unwrap().report;
        same_numbers(&from_file, &builtin);
        if name == "membrane-flat" {
            // the file's exact constants are reported (they belong to its domain)
            assert_eq!(from_file.exact_contact_force, Some(48.0));
            assert!(from_file.solve.error_l2.unwrap() < 1e-8);
        }
    }
}

/// The disk example: a membrane on a Gmsh disk over an off-centre paraboloid with a
/// load given as an expression. Certified by the KKT residual, feasible at the vertices
/// up to the weak constraint's O(h²), λ_h ≥ 0 with a contact set strictly inside the
/// disk, the same ∫λ_h from the interior-point solver, and close to P2–P0's.
#[test]
fn the_disk_example_solves_and_satisfies_its_identities() {
    let file = scene_file::read(&example("disk-off-centre.toml")).unwrap();
    let (report, fields) = solve(&file).unwrap();
    let r = &report.solve;
    assert!(r.complementarity_residual < 1e-8, "{report:?}");
    let (mesh, u) = vertex(&fields, "u");
    let (_, psi) = vertex(&fields, "psi");
    let area = area(mesh);
    assert!((area - std::f64::consts::PI).abs() < 0.05, "|Ω_h| = {area}");
    let contact = r.contact_area.unwrap();
    assert!(contact > 0.0 && contact < 0.9 * area, "{report:?}");
    assert!(r.total_contact_force > 0.0);
    assert!(lambda(&fields).iter().all(|&l| l >= -1e-9));
    let h = mesh.max_h();
    for (u, psi) in u.iter().zip(psi) {
        assert!(u - psi >= -h * h, "u = {u} below ψ = {psi}");
    }
    // the load pushes the membrane onto the bump: the contact force is below the total
    // load −∫f = 8·|Ω_h| (∫xy vanishes on the disk), part of it carried by the rim
    assert!(r.total_contact_force < 8.0 * area);
    let (independent, _) = solve_with(&file, |s| s.solver = VariationalSolver::Clarabel).unwrap();
    assert!(
        (independent.solve.total_contact_force - r.total_contact_force).abs()
            < 1e-5 * r.total_contact_force,
        "Newton ∫λ_h = {}, clarabel {}",
        r.total_contact_force,
        independent.solve.total_contact_force
    );
    // another discretization (u ∈ P2) of the same problem agrees to its accuracy
    let (quadratic, _) = solve_with(&file, |s| s.pair = Some("p2-p0".into())).unwrap();
    let q = &quadratic.solve;
    assert!(q.complementarity_residual < 1e-8);
    assert!(
        (q.total_contact_force - r.total_contact_force).abs() < 3e-3 * r.total_contact_force,
        "P1–P0 ∫λ_h = {}, P2–P0 {}",
        r.total_contact_force,
        q.total_contact_force
    );
}

/// Where the load balance is exact: the disk pressed flat onto ψ = 0 = g by a constant
/// load f = −q gives u = 0, λ = q, so ∫λ_h = q·|Ω_h| (the mesh's own area).
#[test]
fn the_disk_pressed_flat_balances_its_load() {
    let text = std::fs::read_to_string(example("disk-off-centre.toml"))
        .unwrap()
        .replace("f = \"-(1 + x*y)\"", "f = \"-1\"")
        .replace(
            "psi = \"0.2 - 1.5*((x - 0.3)^2 + (y + 0.2)^2)\"",
            "psi = \"0\"",
        );
    let file = scene_file::parse(&text, &example("disk-flat.toml")).unwrap();
    for pair in ["p1-p0", "p1-nodal"] {
        let (report, fields) = solve_with(&file, |s| s.pair = Some(pair.into())).unwrap();
        let (mesh, u) = vertex(&fields, "u");
        let area = area(mesh);
        if pair == "p1-p0" {
            let force = report.solve.total_contact_force;
            assert!(
                (force - 8.0 * area).abs() < 1e-7 * 8.0 * area,
                "∫λ_h = {force} vs q|Ω_h| = {}",
                8.0 * area
            );
        }
        assert!(u.iter().all(|u| u.abs() < 1e-8));
    }
}

/// A scene file's errors name the file and the field.
#[test]
fn scene_file_errors_name_the_field() {
    let text = std::fs::read_to_string(example("membrane-flat.toml")).unwrap();
    let broken = text.replace("f = \"-1\"", "f = \"-1 + t\"");
    let e = scene_file::parse(&broken, Path::new("mine.toml"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("mine.toml") && e.contains("data.f") && e.contains("`t`"),
        "{e}"
    );
    for (from, to, field) in [
        ("half_width = 2.0", "half_width = 1e-200", "mesh.half_width"),
        // a tester's 1e-40 failed with "C_0 = -0": the stabilization underflows
        ("half_width = 2.0", "half_width = 1e-40", "mesh.half_width"),
        ("half_width = 2.0", "half_width = 1e200", "mesh.half_width"),
        // within the field's old bound but beyond the mesh's: refused by the mesh,
        // whose message named no field
        ("half_width = 2.0", "half_width = 1e60", "mesh.half_width"),
    ] {
        let e = scene_file::parse(&text.replace(from, to), Path::new("mine.toml"))
            .unwrap_err()
            .to_string();
        assert!(e.contains(field), "{to}: {e}");
    }
    let lshape = text
        .replace("generator = \"square\"", "generator = \"l-shape\"")
        .replace("half_width = 2.0\n", "")
        .replace("size = 16", "size = 7");
    let e = scene_file::parse(&lshape, Path::new("mine.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("mesh.size") && e.contains("even"), "{e}");
    let e = scene_file::read(Path::new("/nonexistent/scene.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("/nonexistent/scene.toml"), "{e}");
    // a misspelt model is named as such, also when the file has another model's keys
    let contact = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/contact-gap.toml"),
    )
    .unwrap();
    for misspelt in [
        text.replace("model = \"membrane\"", "model = \"membrain\""),
        contact.replace("model = \"contact\"", "model = \"contakt\""),
    ] {
        let e = scene_file::parse(&misspelt, Path::new("mine.toml"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("field `model`") && (e.contains("`membrain`") || e.contains("`contakt`")),
            "{e}"
        );
    }
}

/// Data the solver cannot take are refused before solving, naming the field: a load
/// whose values would overflow the solve's norms, and `-x^2` (read `(−x)²` by the
/// expression crate). Scientific notation reads as written: `-3e0` is membrane-flat's
/// own load, so ∫λ_h = 48 (16q, q = 3).
#[test]
fn scene_file_loads_are_read_as_meant_or_refused() {
    let text = std::fs::read_to_string(example("membrane-flat.toml")).unwrap();
    let without_exact = |t: String| t[..t.find("[exact]").unwrap()].to_string();
    let huge = without_exact(text.replace("f = \"-1\"", "f = \"0-10^300\""));
    let file = scene_file::parse(&huge, Path::new("huge.toml")).unwrap();
    let e = match solve(&file) {
        Ok(_) => panic!("a load of 3e300 was solved"),
        Err(e) => e.to_string(),
    };
    assert!(
        e.contains("field `data.f`") && e.contains("overflow"),
        "{e}"
    );
    let ambiguous = text.replace("f = \"-1\"", "f = \"-x^2\"");
    let e = scene_file::parse(&ambiguous, Path::new("minus.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("data.f") && e.contains("ambiguous"), "{e}");
    // an exact λ that is not finite: its error cannot be reported, and the report says so
    let broken_exact = text.replace("lambda = \"3\"", "lambda = \"sqrt(0-1)\"");
    let file = scene_file::parse(&broken_exact, Path::new("exact.toml")).unwrap();
    let (report, _) = solve(&file).unwrap();
    assert!(
        report
            .solve
            .warnings
            .iter()
            .any(|w| w.contains("not a number")),
        "{:?}",
        report.solve.warnings
    );
    let scientific = text.replace("f = \"-1\"", "f = \"-1e0\"");
    let file = scene_file::parse(&scientific, Path::new("e.toml")).unwrap();
    let (report, _) = solve(&file).unwrap();
    let force = report.solve.total_contact_force;
    assert!((force - 48.0).abs() < 1e-9, "{force}");
}

/// The strip example names its Dirichlet parts (Gmsh physical names): it solves the
/// mixed problem whose exact ∫λ = 16 and contact area 2 (tests/boundary_parts.rs), and
/// choosing the part `sides` (the same curves) gives the same numbers.
#[test]
fn the_strip_example_solves_with_named_boundary_parts() {
    let file = scene_file::read(&example("membrane-strip.toml")).unwrap();
    let (report, _) = solve(&file).unwrap();
    assert_eq!(dirichlet_parts(&report), ["left", "right"]);
    let r = &report.solve;
    assert!(r.complementarity_residual < 1e-8, "{report:?}");
    assert!((r.total_contact_force - 16.0).abs() < 0.01, "{report:?}");
    assert!((r.contact_area.unwrap() - 2.0).abs() < 0.1, "{report:?}");
    let text = std::fs::read_to_string(example("membrane-strip.toml")).unwrap();
    let sides = text.replace(r#"["left", "right"]"#, r#""sides""#);
    assert_ne!(sides, text);
    let file = scene_file::parse(&sides, &example("membrane-strip.toml")).unwrap();
    let (same, _) = solve(&file).unwrap();
    assert_eq!(dirichlet_parts(&same), ["sides"]);
    assert_eq!(same.solve.total_contact_force, r.total_contact_force);
    assert_eq!(same.solve.dofs, r.dofs);
}

/// A boundary part the Gmsh file does not name is refused by the command line with
/// the field, the name and the file's names, not a panic.
#[test]
fn an_unknown_boundary_part_is_refused_by_the_command_line() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("fem-forms-parts-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let text = std::fs::read_to_string(example("membrane-strip.toml")).unwrap();
    let scene = dir.join("strip.toml");
    std::fs::write(
        &scene,
        text.replace(r#"["left", "right"]"#, r#"["left", "rim"]"#)
            .replace(
                "square_named.msh",
                &example("square_named.msh").display().to_string(),
            ),
    )
    .unwrap();
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_fem-forms"))
        .args(["solve", "--scene"])
        .arg(&scene)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        !run.status.success() && !stderr.contains("panicked"),
        "{stderr}"
    );
    for word in ["boundary.dirichlet", "`rim`", "`walls`", "`sides`"] {
        assert!(stderr.contains(word), "{word}: {stderr}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `"all"` is the keyword for the whole boundary; a Gmsh file with a boundary group
/// named `all` (a tester's annulus: outer circle `all`, inner `hole`) made `"all"` and
/// `["all"]` choose different boundaries under one printed name. Both are refused with
/// a message that says how to fix the mesh.
#[test]
fn a_boundary_group_named_like_the_keyword_is_refused() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("fem-forms-all-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mesh = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/annulus_group_named_all.msh");
    // the last: no `[boundary]` at all, where the default "all" meets the group (a
    // tester was told the `boundary.dirichlet` they had not written was at fault)
    for choice in [r#""all""#, r#"["all"]"#, r#"["hole"]"#, ""] {
        let scene = dir.join("annulus.toml");
        let boundary = if choice.is_empty() {
            String::new()
        } else {
            format!("[boundary]\ndirichlet = {choice}\n")
        };
        std::fs::write(
            &scene,
            format!(
                "name = \"annulus\"\nmodel = \"membrane\"\npair = \"p1-p0\"\n[mesh]\nfile = {:?}\n{boundary}[data]\nf = \"-1\"\npsi = \"-1\"\ng = \"0\"\n",
                mesh.display().to_string()
            ),
        )
        .unwrap();
        let run = std::process::Command::new(env!("CARGO_BIN_EXE_fem-forms"))
            .args(["solve", "--scene"])
            .arg(&scene)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(!run.status.success(), "{choice}: solved");
        assert!(
            stderr.contains("boundary part named `all`")
                && stderr.contains("its default")
                && !stderr.contains("field `boundary.dirichlet`")
                && !stderr.contains("panicked"),
            "{choice}: {stderr}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A scene's name comes from its file's name when the file gives none, with characters
/// that cannot be in output file names turned into `-` (a file `flat one.toml` is
/// `flat-one`); a `name` written in the file is taken as written or refused.
#[test]
fn a_scene_without_a_name_is_named_after_its_file() {
    use fem_forms::models::scene_file::scene_name;
    for (path, expected) in [
        ("dir/flat one.toml", "flat-one"),
        ("-x y.toml", "x-y"),
        (".hidden.toml", "hidden"),
        ("é√.toml", "é-"),
        ("  .toml", "scene"),
    ] {
        assert_eq!(
            scene_name(None, Path::new(path), "scene").unwrap(),
            expected,
            "{path}"
        );
    }
    assert_eq!(
        scene_name(Some("a.b_c-1"), Path::new("x.toml"), "s").unwrap(),
        "a.b_c-1"
    );
    for bad in ["my gap", "-rf", ".x", "", "a/b"] {
        let e = scene_name(Some(bad), Path::new("x.toml"), "s").unwrap_err();
        assert!(e.contains("cannot name output files"), "{bad}: {e}");
    }
    let text = std::fs::read_to_string(example("membrane-flat.toml")).unwrap();
    let unnamed: String = text
        .lines()
        .filter(|l| !l.starts_with("name"))
        .map(|l| format!("{l}\n"))
        .collect();
    let file = scene_file::parse(&unnamed, Path::new("my scenes/flat one.toml")).unwrap();
    assert_eq!(file.scene.name, "flat-one");
}

/// A tester's silent scene-file inputs: `accuracy` was accepted and ignored, `[exact]`
/// constants could be NaN or negative, and another `--load` dropped the exact solution
/// without a word. Now: the accuracy needs `[exact]`, is reported and checked against
/// `error_l2` (a warning when missed); the constants are refused by key; another load
/// warns that the exact solution is not compared.
#[test]
fn a_scene_files_accuracy_and_exact_solution_are_checked_or_refused() {
    let text = std::fs::read_to_string(example("membrane-flat.toml")).unwrap();
    let mine = Path::new("mine.toml");
    let without_exact = text[..text.find("[exact]").unwrap()].to_string();
    let e = scene_file::parse(&format!("accuracy = 1e-3\n{without_exact}"), mine)
        .unwrap_err()
        .to_string();
    assert!(e.contains("`accuracy`") && e.contains("[exact] u"), "{e}");
    for (from, to, key) in [
        (
            "contact_area = 16.0",
            "contact_area = -1.0",
            "exact.contact_area",
        ),
        (
            "contact_force = 48.0",
            "contact_force = nan",
            "exact.contact_force",
        ),
    ] {
        assert!(text.contains(from), "the example changed: {from}");
        let e = scene_file::parse(&text.replace(from, to), mine)
            .unwrap_err()
            .to_string();
        assert!(e.contains(key) && e.contains("≥ 0"), "{to}: {e}");
    }
    // u = 0 exactly: P2 reaches it to rounding on membrane-flat, so an accuracy of 1e-6
    // is met and one of 1e-30 is not
    for (accuracy, missed) in [(1e-6, false), (1e-30, true)] {
        let file = scene_file::parse(&format!("accuracy = {accuracy:e}\n{text}"), mine).unwrap();
        assert_eq!(file.scene.accuracy, Some(accuracy));
        let (report, _) = solve_with(&file, |s| s.mesh_size = Some(8)).unwrap();
        let error = report.solve.error_l2.unwrap();
        assert_eq!(error > accuracy, missed, "{error}");
        assert_eq!(report.accuracy, Some(accuracy));
        assert_eq!(
            report
                .solve
                .warnings
                .iter()
                .any(|w| w.contains("exceeds the accuracy")),
            missed,
            "{:?}",
            report.solve.warnings
        );
    }
    let file = scene_file::parse(&text, mine).unwrap();
    let (report, _) = solve_with(&file, |s| {
        s.mesh_size = Some(8);
        s.load = Some(1.0);
    })
    .unwrap();
    assert!(report.solve.error_l2.is_none() && report.exact_contact_force.is_none());
    assert!(
        report
            .solve
            .warnings
            .iter()
            .any(|w| w.contains("not compared")),
        "{:?}",
        report.solve.warnings
    );
}

/// A second tester's: under a flat ψ = 0 a membrane held at g = 1 and pressed down by
/// f = −20 dipped 0.33 below ψ at N = 8 without a warning (ψ's range, 0, was all the
/// check compared with); it now compares with u_h's range too. And ψ = g = 10¹² + 10⁻³x
/// dipped one ulp of 10¹², which was "9.4 %" of ψ's range: below the rounding of the
/// values compared, it is no longer a warning.
#[test]
fn penetration_warnings_compare_with_the_solution_and_its_rounding() {
    let scene = |psi: &str, g: &str, load: f64, pair: &str| {
        format!(
            "model = \"membrane\"\npair = \"{pair}\"\n[mesh]\ngenerator = \"square\"\nhalf_width = 2.0\nsize = 8\n[data]\nload = {load:?}\nf = \"-1\"\npsi = \"{psi}\"\ng = \"{g}\"\n"
        )
    };
    let solve_text = |text: String| {
        let file = scene_file::parse(&text, Path::new("mine.toml")).unwrap();
        solve(&file).unwrap().0.solve
    };
    let report = solve_text(scene("0", "1", 20.0, "p2-p0"));
    assert!(report.max_penetration.unwrap() > 0.1, "{report:?}");
    assert!(
        report.warnings.iter().any(|w| w.contains("dips below ψ")),
        "{:?}",
        report.warnings
    );
    for pair in ["p1-nodal", "p2-p0"] {
        let report = solve_text(scene("1e12 + 1e-3*x", "1e12 + 1e-3*x", 3.0, pair));
        // one ulp of 1e12 is 1.2e-4: the depth is rounding
        assert!(report.max_penetration.unwrap_or(0.0) < 1e-3, "{report:?}");
        assert!(
            !report.warnings.iter().any(|w| w.contains("dips below ψ")),
            "{pair}: {:?}",
            report.warnings
        );
    }
}

/// A tester's mesh of two squares apart, the Dirichlet part on one of them: the other
/// piece had only the natural condition, and the solve "succeeded" with u ≈ 6e15 there
/// (KKT residual 2e-16, no warning). Every piece needs a Dirichlet part, as the whole
/// mesh does; with both rims Dirichlet the same mesh solves.
#[test]
fn a_mesh_piece_without_a_dirichlet_part_is_refused() {
    let mesh = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/two_squares_apart.msh");
    let text = |dirichlet: &str| {
        format!(
            "model = \"membrane\"\n[mesh]\nfile = \"{}\"\n[boundary]\ndirichlet = {dirichlet}\n[data]\nf = \"1\"\npsi = \"-100\"\ng = \"0\"\n",
            mesh.display()
        )
    };
    let file = scene_file::parse(&text("\"A\""), Path::new("mine.toml")).unwrap();
    let Err(e) = solve(&file) else {
        panic!("the unheld piece was solved");
    };
    let e = e.to_string();
    for word in [
        "2 pieces joined by no edge",
        "[0.5, 2] × [-1, 1]",
        "not coercive",
    ] {
        assert!(e.contains(word), "{word}: {e}");
    }
    // the re-test's hinge: a second square touching the held one at a corner sagged
    // like log h (a vertex holds nothing in H¹); it is a piece of its own
    let hinged = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/two_squares_hinged.msh");
    let hinge = format!(
        "model = \"membrane\"\npair = \"p1-p0\"\n[mesh]\nfile = \"{}\"\n[boundary]\ndirichlet = \"held\"\n[data]\nf = \"-1\"\npsi = \"-1000\"\ng = \"0\"\n",
        hinged.display()
    );
    let file = scene_file::parse(&hinge, Path::new("mine.toml")).unwrap();
    let Err(e) = solve(&file) else {
        panic!("the hinged piece was solved");
    };
    assert!(
        e.to_string().contains("a shared vertex holds nothing"),
        "{e}"
    );
    let file = scene_file::parse(&text("[\"A\", \"B\"]"), Path::new("mine.toml")).unwrap();
    let (report, _) = solve(&file).unwrap();
    // no contact: −Δu = 1 on each square, u = 0 on its rim, so 0 < u < 1/8 (the strip's)
    let force = report.solve.total_contact_force;
    assert!(force == 0.0, "{force}");
}

/// `--msh` replaces a scene file's mesh, and with it the file's refinements: a tester's
/// `refinements = 2` was dropped without a word (128 triangles instead of 2048). It is
/// said on stderr, and `--mesh-size` refines the `--msh` mesh.
#[test]
fn msh_over_a_scene_file_says_what_it_replaces() {
    let run = |extra: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_fem-forms"))
            .args(["solve", "--scene"])
            .arg(example("membrane-strip.toml"))
            .arg("--msh")
            .arg(example("square_named.msh"))
            .args(extra)
            .output()
            .unwrap()
    };
    let plain = run(&[]);
    let stderr = String::from_utf8_lossy(&plain.stderr);
    assert!(plain.status.success(), "{stderr}");
    assert!(
        stderr.contains("replaces the mesh of") && stderr.contains("(2)"),
        "{stderr}"
    );
    let refined = run(&["--mesh-size", "2"]);
    assert!(refined.status.success());
    assert!(!String::from_utf8_lossy(&refined.stderr).contains("replaces"));
}

/// A scene file's `parameters.alpha` with the pair p1-nodal was refused as "--alpha does
/// not apply", an option the tester had not given: the key is named now.
#[test]
fn a_file_alpha_for_the_nodal_pair_names_its_key() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("fem-forms-nodal-alpha-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("nodal.toml");
    std::fs::write(
        &scene,
        "model = \"membrane\"\npair = \"p1-nodal\"\n[mesh]\ngenerator = \"square\"\nsize = 8\n[parameters]\nalpha = 0.1\n[data]\nf = \"-1\"\npsi = \"-0.1\"\ng = \"0\"\n",
    )
    .unwrap();
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_fem-forms"))
        .args(["solve", "--scene"])
        .arg(&scene)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success());
    assert!(
        stderr.contains("parameters.alpha") && !stderr.contains("--alpha"),
        "{stderr}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// An exact solution no obstacle problem has: a negative multiplier, or a contact area
/// beyond the domain's (a tester's `lambda = "-2"` and `contact_area = 100` on a domain
/// of area 4 were accepted and compared with). The membrane pressed flat (u = 0, λ = 3)
/// with its true data solves.
#[test]
fn an_impossible_exact_solution_is_refused() {
    let text = |lambda: &str, area: f64| {
        format!(
            "model = \"membrane\"\n[mesh]\ngenerator = \"square\"\nhalf_width = 1.0\nsize = 8\n[data]\nf = \"-3\"\npsi = \"0\"\ng = \"0\"\n[exact]\nu = \"0\"\nlambda = \"{lambda}\"\ncontact_area = {area:?}\n"
        )
    };
    for (lambda, area, key) in [
        ("-2", 4.0, "exact.lambda"),
        ("3", 100.0, "exact.contact_area"),
    ] {
        let file = scene_file::parse(&text(lambda, area), Path::new("mine.toml")).unwrap();
        let Err(e) = solve(&file) else {
            panic!("{key}: accepted");
        };
        assert!(e.to_string().contains(key), "{e}");
    }
    let file = scene_file::parse(&text("3", 4.0), Path::new("mine.toml")).unwrap();
    assert!(solve(&file).is_ok());
}

/// The strip example's text with `[boundary]` and `[data]` lines replaced, its mesh
/// named by absolute path, parsed as a file in `dir`.
fn strip_with(dir: &Path, mesh: &Path, dirichlet: &str, g: &str, psi: &str) -> FileScene {
    let text = std::fs::read_to_string(example("membrane-strip.toml"))
        .unwrap()
        .replace(r#"["left", "right"]"#, dirichlet)
        .replace("g = \"1\"", &format!("g = \"{g}\""))
        .replace("psi = \"0\"", &format!("psi = \"{psi}\""))
        .replace("square_named.msh", &mesh.display().to_string());
    scene_file::parse(&text, &dir.join("strip.toml")).unwrap()
}

/// The boundary data g is used on the Dirichlet part only: a tester's g = ln(x + 1)
/// held on the right side was refused for its value −∞ on the free left side. Data that
/// are not finite where they are used are refused naming the scene's field.
#[test]
fn data_are_checked_where_they_are_used_and_named_by_field() {
    let dir = example("");
    let mesh = example("square_named.msh");
    let file = strip_with(&dir, &mesh, r#""right""#, "ln(x + 1) + 1", "0");
    let (report, _) = solve(&file).unwrap();
    assert_eq!(dirichlet_parts(&report), ["right"]);
    let file = strip_with(&dir, &mesh, r#""left""#, "ln(x + 1) + 1", "0");
    let e = refusal(&file);
    assert!(e.contains("field `data.g`") && e.contains("-inf"), "{e}");
    let file = strip_with(&dir, &mesh, r#""left""#, "1", "1/x - 10");
    let e = refusal(&file);
    assert!(e.contains("field `data.psi`") && e.contains("inf"), "{e}");
    // data too small to survive the powers of h (Newton stopped at a residual of 5e-3)
    let file = strip_with(&dir, &mesh, r#""left""#, "1e-320", "0");
    let e = refusal(&file);
    assert!(
        e.contains("field `data.g`") && e.contains("below 1e-200"),
        "{e}"
    );
}

/// `"all"` is a keyword on its own; inside a list it is a name the mesh lacks, and the
/// refusal says how to write the keyword.
#[test]
fn all_in_a_list_is_explained() {
    let dir = example("");
    let file = strip_with(&dir, &example("square_named.msh"), r#"["all"]"#, "1", "0");
    let e = refusal(&file);
    assert!(
        e.contains("boundary.dirichlet") && e.contains(r#"`dirichlet = "all"`"#),
        "{e}"
    );
    // and on a generated mesh, whose names are checked when the file is read
    let text = "model = \"membrane\"\n[mesh]\ngenerator = \"square\"\nsize = 8\n[boundary]\ndirichlet = [\"all\"]\n[data]\nf = \"-1\"\npsi = \"-1\"\ng = \"0\"\n";
    let Err(e) = scene_file::parse(text, Path::new("all.toml")) else {
        panic!("[\"all\"] was read")
    };
    let e = e.to_string();
    assert!(e.contains(r#"`dirichlet = "all"`"#), "{e}");
}

/// A Dirichlet group holding an embedded curve beside boundary curves: nothing is
/// imposed on the interior edges, and the solve says so.
#[test]
fn a_dirichlet_group_with_interior_edges_is_warned_about() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!(
        "fem-forms-interior-dirichlet-{}",
        std::process::id()
    ));
    std::fs::create_dir_all(&dir).unwrap();
    let mesh = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/contact_block.msh"),
    )
    .unwrap();
    // the midline y = ½ of the block joins the group `side`
    let wired = mesh.replace(
        "5 0.0 0.5 0 2.0 0.5 0 1 35 0",
        "5 0.0 0.5 0 2.0 0.5 0 2 32 35 0",
    );
    assert_ne!(wired, mesh);
    let path = dir.join("block.msh");
    std::fs::write(&path, wired).unwrap();
    let file = strip_with(&dir, &path, r#""side""#, "1", "0");
    let (report, _) = solve(&file).unwrap();
    assert!(
        report
            .solve
            .warnings
            .iter()
            .any(|w| w.contains("boundary.dirichlet")
                && w.contains("`side`")
                && w.contains("inside the domain")),
        "{:?}",
        report.solve.warnings
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

fn refusal(file: &FileScene) -> String {
    match solve(file) {
        Ok(_) => panic!("the scene was solved"),
        Err(e) => e.to_string(),
    }
}

/// membrane-lshape's obstacle as a scene file, with f = `load` and ψ scaled by `scale`.
fn lshape(load: &str, scale: &str) -> FileScene {
    let text = format!(
        "name = \"lsh\"\nmodel = \"membrane\"\npair = \"p2-p0\"\n[mesh]\ngenerator = \"l-shape\"\nsize = 32\n[data]\nf = \"{load}\"\npsi = \"{scale}*(-0.05 - 0.6*((x + 0.35)^2 + 0.5*(y - 0.4)^2) + 0.1*x)\"\ng = \"0\"\n"
    );
    scene_file::parse(&text, Path::new("lsh.toml")).unwrap()
}

/// Scaling f, ψ and g together scales the exact solution, so every judgement of the
/// answer must stay the same: a tester's ψ × 1e-20 under f = −1 (the refused q = 1e20
/// at scale 1e-20) passed without a word, its u_h 25 times ψ's range below ψ, because
/// the rounding was judged against a fixed floor of 1e-6 of the diameter. And the
/// penetration at q = 1e12 (53 %, a matter of the mesh) was hidden behind a rounding
/// level of |f| d² = 1.8.
#[test]
fn judgements_of_the_answer_do_not_depend_on_the_data_scale() {
    for (load, scale) in [("-1e20", "1"), ("-1", "1e-20")] {
        let e = refusal(&lshape(load, scale));
        assert!(
            e.contains("the load dwarfs the obstacle"),
            "{load} {scale}: {e}"
        );
    }
    let big = solve(&lshape("-1e16", "1")).unwrap().0.solve;
    let small = solve(&lshape("-1", "1e-16")).unwrap().0.solve;
    let ratio = big.primal_rounding / small.primal_rounding;
    assert!((0.5..2.0).contains(&ratio), "{big:?} {small:?}");
    assert!(big.primal_rounding > 1e-8, "{big:?}");
    assert_eq!(
        big.warnings.len(),
        small.warnings.len(),
        "{big:?} {small:?}"
    );
    let pressed = solve(&lshape("-1e12", "1")).unwrap().0.solve;
    assert!(
        pressed.max_penetration.unwrap() > 0.1
            && pressed.warnings.iter().any(|w| w.contains("dips below ψ")),
        "{pressed:?}"
    );
}

/// A plate simply supported on one straight edge only keeps a motion without energy
/// (`w = x`, which vanishes there): pushed up, away from its obstacle below, nothing
/// stops it and there is no solution (the solvers returned w ≈ 1e10 with exit 0);
/// pushed down, the obstacle holds it, and the solution balances the moment of the
/// load about the supported edge (the motion `w = x` is a test function without
/// energy: `∫ f x + ∫ λ x = 0`, exactly for P0 multipliers).
#[test]
fn a_plate_the_supports_leave_free_is_refused_unless_its_obstacle_holds_it() {
    let text = |load: &str| {
        format!(
            "model = \"kirchhoff\"\nobstacle_side = \"below\"\n[mesh]\ngenerator = \"rectangle\"\nx = [0.0, 1.0]\nsize = 8\n[boundary]\nsimply_supported = \"left\"\n[parameters]\nD = 1.0\nnu = 0.3\n[data]\nf = \"{load}\"\npsi = \"-0.01\"\n"
        )
    };
    let file = scene_file::parse(&text("1"), Path::new("hinged.toml")).unwrap();
    let Err(e) = solve(&file) else {
        panic!("a plate pulled off its obstacle was solved");
    };
    let e = e.to_string();
    for words in ["a motion of the body without energy", "no solution"] {
        assert!(e.contains(words), "{words}: {e}");
    }
    let file = scene_file::parse(&text("-1"), Path::new("hinged.toml")).unwrap();
    let (report, fields) = solve(&file).unwrap();
    assert!(report.solve.contact_area.unwrap() > 0.1);
    let Fields::Triangles { mesh, .. } = &fields else {
        panic!("a plate is solved on triangles");
    };
    let moment: f64 = (0..mesh.cell_count())
        .map(|c| {
            let x = mesh.cell_coordinates(c);
            lambda(&fields)[c] * mesh.area(c) * (x[0] + x[2] + x[4]) / 3.0
        })
        .sum();
    // ∫ f x = −1/2
    assert!((moment - 0.5).abs() < 1e-9, "∫ λ x = {moment}");
}

/// Free bodies that only their obstacle holds: a Reissner–Mindlin plate and a
/// Timoshenko beam pressed onto a paraboloid. A start at zero leaves every constraint
/// inactive and Newton's matrix singular (both failed with "A + BᵀC⁻¹B is not positive
/// definite … α·C_I ≥ 1"); they start pressed onto the obstacle. Their rigid motions
/// are test functions without energy, so the obstacle's reaction balances the load in
/// force and moment: `∫λ = −∫f`, `∫λ x = −∫f x`, `∫λ y = −∫f y`.
#[test]
fn free_bodies_only_the_obstacle_holds_are_solved_in_equilibrium() {
    let plate = "model = \"plate\"\nobstacle_side = \"below\"\n[mesh]\ngenerator = \"rectangle\"\nx = [0.0, 1.0]\nsize = 16\n[parameters]\nD = 1.0\nnu = 0.3\nthickness = 0.01\nshear_correction = 0.8333333333\n[data]\nf = \"-1\"\npsi = \"-0.3*((x-0.45)^2+(y-0.5)^2)\"\n";
    let file = scene_file::parse(plate, Path::new("free-plate.toml")).unwrap();
    let (report, fields) = solve(&file).unwrap();
    assert!((report.solve.total_contact_force - 1.0).abs() < 1e-9);
    let Fields::Triangles { mesh, .. } = &fields else {
        panic!("a plate is solved on triangles");
    };
    let moment = |axis: usize| -> f64 {
        (0..mesh.cell_count())
            .map(|c| {
                let x = mesh.cell_coordinates(c);
                lambda(&fields)[c] * mesh.area(c) * (x[axis] + x[axis + 2] + x[axis + 4]) / 3.0
            })
            .sum()
    };
    // ∫ f x = ∫ f y = −1/2 on the unit square
    for axis in [0, 1] {
        let m = moment(axis);
        assert!((m - 0.5).abs() < 1e-9, "axis {axis}: ∫ λ x = {m}");
    }
    let beam = "model = \"beam\"\npair = \"p2-p2-p0\"\n[mesh]\ngenerator = \"interval\"\nstart = 0.0\nend = 1.0\nsize = 64\n[parameters]\nthickness = 1e-3\n[data]\nload = 40.0\nf = \"-1\"\npsi = \"-0.4*x^2+0.4*x-0.15\"\n";
    let file = scene_file::parse(beam, Path::new("free-beam.toml")).unwrap();
    let (report, _) = solve(&file).unwrap();
    let force = report.solve.total_contact_force;
    // rounding: the thin beam's matrix has a condition near 1e7 (t = 1e-3)
    assert!((force - 40.0).abs() < 1e-8 * 40.0, "∫λ = {force}");
}

/// A free Kirchhoff plate pushed up against a flat obstacle above by a load with a
/// moment: where the load's resultant meets the plate it lies flat on the obstacle with
/// `λ = f` (balanced in force and moments), where it passes outside the plate there is
/// no equilibrium and the problem is refused; the interior multiplier is compared with
/// `q` only where the scene's load is uniform (a built-in scene), not with a file's `f`.
#[test]
fn a_free_plate_tipped_against_an_obstacle_above_is_balanced_or_refused() {
    let text = |f: &str| {
        format!("model = \"kirchhoff\"\nobstacle_side = \"above\"\n[mesh]\ngenerator = \"rectangle\"\nx = [0.0, 1.0]\nsize = 8\n[boundary]\nfree = \"all\"\n[parameters]\nD = 1.0\nnu = 0.3\n[data]\nload = 20.0\nf = \"{f}\"\npsi = \"0.05\"\n")
    };
    // resultant at x = 0.5 + 2/12: inside the plate
    let file = scene_file::parse(&text("1 + 2*(x-0.5)"), Path::new("tipped.toml")).unwrap();
    let (report, fields) = solve(&file).unwrap();
    assert!((report.solve.total_contact_force - 20.0).abs() < 1e-9);
    let Fields::Triangles { mesh, .. } = &fields else {
        panic!("a plate is solved on triangles");
    };
    let moment: f64 = (0..mesh.cell_count())
        .map(|c| {
            let x = mesh.cell_coordinates(c);
            lambda(&fields)[c] * mesh.area(c) * ((x[0] + x[2] + x[4]) / 3.0 - 0.5)
        })
        .sum();
    // ∫ 20 (1 + 2(x − ½)) (x − ½) = 40/12
    assert!(
        (moment - 40.0 / 12.0).abs() < 1e-8,
        "∫ λ (x − ½) = {moment}"
    );
    assert!(report.quantities["interior_multiplier"].is_null());
    // resultant at x = 0.5 + 10/12: outside
    let file = scene_file::parse(&text("1 + 10*(x-0.5)"), Path::new("tipped.toml")).unwrap();
    let Err(e) = solve(&file) else {
        panic!("a plate tipped off its obstacle was solved");
    };
    assert!(
        e.to_string().contains("moves away from the obstacle"),
        "{e}"
    );
}

/// A membrane free on its whole boundary keeps the constants: pulled off its obstacle
/// it has no solution (the nodal method returned an energy of −2.5e14 with exit 0),
/// pressed onto it it lies on the obstacle with `∫λ = −∫f`; every pair alike.
#[test]
fn a_free_membrane_is_refused_pulled_off_and_solved_pressed_on() {
    for pair in ["p1-p0", "p2-p0", "p1-nodal"] {
        let text = |load: &str| {
            format!("model = \"membrane\"\npair = \"{pair}\"\n[mesh]\ngenerator = \"rectangle\"\nx = [0.0, 1.0]\nsize = 8\n[boundary]\nfree = \"all\"\n[data]\nf = \"{load}\"\npsi = \"-0.1\"\ng = \"0\"\n")
        };
        let file = scene_file::parse(&text("1"), Path::new("free.toml")).unwrap();
        let Err(e) = solve(&file) else {
            panic!("{pair}: a membrane pulled off its obstacle was solved");
        };
        assert!(e.to_string().contains("no solution"), "{pair}: {e}");
        let file = scene_file::parse(&text("-1"), Path::new("free.toml")).unwrap();
        let (report, _) = solve(&file).unwrap();
        let force = report.solve.total_contact_force;
        assert!((force - 1.0).abs() < 1e-9, "{pair}: ∫λ = {force}");
    }
}

/// The plate held on one edge, at extreme scales. Half-width 1e4: the obstacle holds it
/// (the cone test once read the Argyris DOFs' mixed units as rounding and refused it);
/// its reaction balances the load. Half-width 1e-3 with D = 1e9: the solve loses the
/// contact that holds it and returned w ≈ 0 without a reaction, exit 0; the answer is
/// refused by its unbalanced moment.
#[test]
fn a_hinged_plate_at_extreme_scales_is_balanced_or_refused() {
    let text = |half_width: &str, d: &str| {
        format!(
            "model = \"kirchhoff\"\nobstacle_side = \"below\"\n[mesh]\ngenerator = \"square\"\nhalf_width = {half_width}\nsize = 8\n[boundary]\nsimply_supported = \"left\"\n[parameters]\nD = {d}\nnu = 0.3\n[data]\nf = \"-1\"\npsi = \"-0.01*{half_width}\"\n"
        )
    };
    let file = scene_file::parse(&text("1e4", "1"), Path::new("large.toml")).unwrap();
    let (report, _) = solve(&file).unwrap();
    assert!(report.solve.total_contact_force > 0.5 * 4e8);
    let file = scene_file::parse(&text("1e-3", "1e9"), Path::new("small.toml")).unwrap();
    let Err(e) = solve(&file) else {
        panic!("the unbalanced answer was returned");
    };
    assert!(e.to_string().contains("does not balance the load"), "{e}");
}
