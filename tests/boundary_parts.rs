//! Boundary parts by name: u = g on the named parts, ∂u/∂n = 0 on the rest.
//!
//! The mixed problem on (−1, 1)²: u = 1 on the left and right sides (x = ±1),
//! ∂u/∂n = 0 on the top and bottom, f = −8, ψ = 0. Its solution depends on x alone: the
//! 1-D obstacle problem −u'' = −8, u ≥ 0, u(±1) = 1, whose solution (derived by hand)
//! is u = 4 (|x| − ½)₊²: on ½ < |x| < 1, u'' = 8 with u = u' = 0 at |x| = ½ (contact
//! ends smoothly) and u(±1) = 4·¼ = 1. On the contact strip |x| < ½, λ = −Δu − f = 8,
//! so ∫λ = 8 · (1 × 2) = 16 and the contact area is 2. Imposing g = 1 on the whole
//! boundary instead gives another solution (u = 1 ≠ 4 (|x| − ½)₊² on top and bottom),
//! so a wrong Dirichlet part cannot pass.

#![allow(confusable_idents, mixed_script_confusables, uncommon_codepoints)]

use fem_forms::mesh::gmsh::read_msh;
use fem_forms::models::data::Data;
use fem_forms::models::families;
use fem_forms::models::report::Report;
use fem_forms::models::scene::{Exact, ExactSolution};
use fem_forms::models::scene_file::{self, FileScene};
use std::path::{Path, PathBuf};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn strip_u(x: &[f64]) -> f64 {
    4.0 * (x[0].abs() - 0.5).max(0.0).powi(2)
}

fn strip_gradient(x: &[f64]) -> [f64; 2] {
    [8.0 * (x[0].abs() - 0.5).max(0.0) * x[0].signum(), 0.0]
}

fn strip_multiplier(x: &[f64]) -> f64 {
    if x[0].abs() < 0.5 {
        8.0
    } else {
        0.0
    }
}

/// The scene file of the strip problem with `mesh` (a `[mesh]` body) and `dirichlet`.
fn strip_scene(mesh: &str, dirichlet: &str) -> String {
    format!(
        r#"
        name = "strip"
        model = "membrane"
        [mesh]
        {mesh}
        [boundary]
        dirichlet = {dirichlet}
        [data]
        load = 8.0
        f = "-1"
        psi = "0"
        g = "1"
        "#
    )
}

const GMSH: &str = "file = \"square_named.msh\"";

/// The scene file parsed as if it lay in tests/data, with the exact solution attached.
fn parse(text: &str) -> fem_forms::Result<FileScene> {
    let mut file = scene_file::parse(text, &data("strip.toml"))?;
    file.scene.exact = Exact::AtDefaultLoad(ExactSolution {
        value: Some(Data::Fn(strip_u)),
        gradient: Some(Data::Fn(strip_gradient)),
        multiplier: Some(Data::Fn(strip_multiplier)),
        total_contact_force: Some(16.0),
        contact_area: Some(2.0),
        ..ExactSolution::default()
    });
    Ok(file)
}

/// The membrane pairs.
const PAIRS: [&str; 4] = ["p2-p0", "p1-p0", "p2-p1d", "p1-nodal"];

fn try_solve(file: &FileScene, pair: Option<&str>, mesh_size: usize) -> fem_forms::Result<Report> {
    let mut settings = file.settings();
    settings.pair = pair.map(str::to_string);
    settings.mesh_size = Some(mesh_size);
    families::solve(&file.scene, &settings).map(|o| o.report)
}

fn solve(file: &FileScene, pair: &str, mesh_size: usize) -> Report {
    try_solve(file, Some(pair), mesh_size).unwrap_or_else(|e| panic!("{pair} at {mesh_size}: {e}"))
}

fn dirichlet_parts(report: &Report) -> Vec<String> {
    serde_json::from_value(report.quantities["dirichlet_parts"].clone()).unwrap()
}

/// Errors of a sequence of meshes whose sizes h fall by the factors `h_ratios`: L² and
/// H¹ fall at least at the rates `l2_rate`, `h1_rate` from one to the next, and the
/// finest solve is certified and reports its Dirichlet parts.
fn check_convergence(reports: &[Report], h_ratios: &[f64], l2_rate: f64, h1_rate: f64) {
    for (w, &h_ratio) in reports.windows(2).zip(h_ratios) {
        let (coarse, fine) = (&w[0].solve, &w[1].solve);
        let l2 = coarse.error_l2.unwrap() / fine.error_l2.unwrap();
        let h1 = coarse.error_h1.unwrap() / fine.error_h1.unwrap();
        assert!(
            l2 >= h_ratio.powf(l2_rate) && h1 >= h_ratio.powf(h1_rate),
            "{} at {} → {}: L² ratio {l2}, H¹ ratio {h1} ({:?} → {:?})",
            w[1].pair,
            coarse.cells,
            fine.cells,
            coarse.error_l2,
            fine.error_l2
        );
    }
    let report = reports.last().unwrap();
    let finest = &report.solve;
    assert!(finest.complementarity_residual < 1e-8, "{finest:?}");
    assert_eq!(dirichlet_parts(report), ["left", "right"]);
    assert!(finest.error_l2.unwrap() < 1e-2, "{finest:?}");
    // ∫λ_h → 16 and the contact area → 2 (the strip |x| < ½)
    assert!(
        (finest.total_contact_force - 16.0).abs() < 0.05 * 16.0,
        "{}: ∫λ_h = {}",
        report.pair,
        finest.total_contact_force
    );
    let area = finest.contact_area.unwrap();
    assert!(
        (area - 2.0).abs() < 0.25,
        "{}: contact area {area}",
        report.pair
    );
}

/// The P1 rates are 2 (L²) and 1 (H¹); P2 is limited by u ∈ H^{5/2−ε} (u'' jumps at
/// |x| = ½, inside cells) to about 2.5 and 1.5, reached only on fine meshes (H¹ on the
/// Gmsh square's levels: 0.85–1.0, then 1.5). The bounds leave room for that range.
fn rates(pair: &str) -> (f64, f64) {
    if pair.starts_with("p1") {
        (1.7, 0.8)
    } else {
        (2.0, 0.8)
    }
}

#[test]
fn mixed_problem_on_a_gmsh_file_with_physical_names_converges_to_the_exact_solution() {
    let file = parse(&strip_scene(GMSH, r#"["left", "right"]"#)).unwrap();
    for pair in PAIRS {
        let reports: Vec<Report> = (1..=3).map(|r| solve(&file, pair, r)).collect();
        let (l2, h1) = rates(pair);
        check_convergence(&reports, &[2.0, 2.0], l2, h1);
    }
}

#[test]
fn mixed_problem_on_the_generator_square_converges_to_the_exact_solution() {
    let mesh = "generator = \"square\"\nhalf_width = 1.0\nsize = 8";
    let file = parse(&strip_scene(mesh, r#"["left", "right"]"#)).unwrap();
    // odd N: the free boundary x = ±½ never lies on grid lines (it would for N = 4k,
    // where P2 is exact: u is piecewise quadratic in x)
    for pair in PAIRS {
        let reports: Vec<Report> = [7, 15, 31].map(|n| solve(&file, pair, n)).to_vec();
        let (l2, h1) = rates(pair);
        check_convergence(&reports, &[15.0 / 7.0, 31.0 / 15.0], l2, h1);
    }
}

/// The same data with u = g on the whole boundary: the Dirichlet part matters (an
/// error of order 1 against the mixed problem's solution), so the tests above can fail.
#[test]
fn the_whole_boundary_gives_another_solution() {
    for (mesh, size) in [
        (GMSH, 2),
        ("generator = \"square\"\nhalf_width = 1.0\nsize = 8", 16),
    ] {
        let file = parse(&strip_scene(mesh, "\"all\"")).unwrap();
        for pair in ["p1-p0", "p2-p0", "p1-nodal"] {
            let report = solve(&file, pair, size);
            assert_eq!(dirichlet_parts(&report), ["all"]);
            assert!(report.solve.error_l2.unwrap() > 0.1, "{report:?}");
        }
    }
}

/// `sides` holds the same curves as `left` and `right` (each of those curves is in
/// two physical groups): it is the same problem, solved the same way.
#[test]
fn a_group_of_curves_in_two_groups_is_the_same_part() {
    let named = parse(&strip_scene(GMSH, r#"["right", "left"]"#)).unwrap();
    let sides = parse(&strip_scene(GMSH, "\"sides\"")).unwrap();
    for pair in ["p2-p1d", "p1-nodal"] {
        let (a, b) = (solve(&named, pair, 1), solve(&sides, pair, 1));
        assert_eq!(
            (a.solve.dofs, a.solve.iterations),
            (b.solve.dofs, b.solve.iterations)
        );
        assert_eq!(a.solve.error_l2, b.solve.error_l2);
        assert_eq!(dirichlet_parts(&b), ["sides"]);
    }
}

#[test]
fn the_file_names_its_parts_and_refinement_keeps_them() {
    let mesh = read_msh(&data("square_named.msh")).unwrap();
    assert_eq!(
        mesh.boundary_part_names(),
        ["left", "right", "walls", "sides"]
    );
    let fine = mesh.refine_uniformly().refine_uniformly();
    for m in [&mesh, &fine] {
        let edges_on = |name: &str| {
            let markers = m.boundary_part_markers(&[name]).unwrap();
            m.boundary_edges()
                .iter()
                .filter(|e| markers.contains(&e.1))
                .map(|&(e, _)| m.edges()[e])
                .collect::<Vec<_>>()
        };
        for (name, x) in [("left", -1.0), ("right", 1.0)] {
            let edges = edges_on(name);
            assert!(!edges.is_empty());
            assert!(edges.iter().flatten().all(|&v| m.vertices()[v][0] == x));
        }
        let walls = edges_on("walls");
        assert!(walls
            .iter()
            .flatten()
            .all(|&v| m.vertices()[v][1].abs() == 1.0));
        assert_eq!(
            walls.len() + edges_on("sides").len(),
            m.boundary_edges().len()
        );
    }
}

/// The binary file of the same mesh (MSH 4.1, `$PhysicalNames` as text in it) reads to
/// the same mesh, names and markers included.
#[test]
fn the_binary_file_names_the_same_parts() {
    let ascii = read_msh(&data("square_named.msh")).unwrap();
    let binary = read_msh(&data("square_named_binary.msh")).unwrap();
    assert_eq!(binary, ascii);
    assert_eq!(binary.boundary_part_markers(&["sides"]).unwrap(), [11, 12]);
}

/// A named curve group with no boundary edge (here: no curve at all) is no Dirichlet
/// part: u = g would hold nowhere, so the solve is refused, not run pure Neumann.
#[test]
fn a_part_without_boundary_edges_is_refused() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("fem-forms-slit-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let text = std::fs::read_to_string(data("square_named.msh")).unwrap();
    let with_slit = text.replace("$PhysicalNames\n6\n", "$PhysicalNames\n7\n1 15 \"slit\"\n");
    assert_ne!(with_slit, text);
    std::fs::write(dir.join("square_named.msh"), with_slit).unwrap();
    // alone, or listed beside a real part (where it would be reported and do nothing)
    for dirichlet in ["\"slit\"", "[\"slit\", \"left\"]"] {
        let mut file =
            scene_file::parse(&strip_scene(GMSH, dirichlet), &dir.join("strip.toml")).unwrap();
        file.scene.exact = Exact::Unknown;
        let e = match try_solve(&file, None, 0) {
            Ok(_) => panic!("{dirichlet}: solved with a part that holds no boundary edge"),
            Err(e) => e.to_string(),
        };
        assert!(
            e.contains("boundary.dirichlet")
                && e.contains("`slit`")
                && e.contains("no boundary edge"),
            "{dirichlet}: {e}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Bad boundary parts are errors naming `boundary.dirichlet`, never a solve.
#[test]
fn bad_boundary_parts_are_refused_with_clear_messages() {
    let refused = |dirichlet: &str| -> String {
        let file = match parse(&strip_scene(GMSH, dirichlet)) {
            Ok(file) => file,
            Err(e) => return e.to_string(),
        };
        match try_solve(&file, None, 0) {
            Ok(_) => panic!("{dirichlet} was solved"),
            Err(e) => e.to_string(),
        }
    };
    for (dirichlet, words) in [
        // a name the mesh does not have: the names it has
        (
            r#"["left", "outer"]"#,
            &[
                "`outer`",
                "`left`",
                "`right`",
                "`walls`",
                "`sides`",
                "square_named.msh",
            ][..],
        ),
        // a surface
        (r#""membrane""#, &["`membrane`", "surface"]),
        // a physical tag instead of its name, as a number or as text
        ("[11]", &["11 is a number", "by name"]),
        (
            r#"["11"]"#,
            &["`11`", "by name", "marker 11 belong to `left`"],
        ),
        // no part where u = g: pure Neumann
        ("[]", &["empty list", "constant"]),
    ] {
        let e = refused(dirichlet);
        assert!(
            e.contains("boundary.dirichlet")
                && words.iter().all(|w| e.contains(w))
                && e.matches("invalid input").count() <= 1,
            "{dirichlet}: {e}"
        );
    }
}

fem_forms::model! {
    /// A string over an obstacle held at u = γ at its ends, u ∈ P1, λ ∈ P0.
    pub mod held_string on interval {
        unknowns: u: P1, λ: P0 >= 0;
        tests: v, μ;
        params: α;
        data: f, ψ, γ;
        boundary: u = γ;
        forms: "
            a(u;v)       = ∫ u'v'
            b(v;μ)       = ∫ v μ
            B_h(u,λ;v,μ) = a(u;v) − b(v;λ) − b(u;μ) − α Σ_T h_T² (λ, μ)_T
            L_h(v,μ)     = ∫ f v − ∫ ψ μ
        ";
    }
}

/// A field without slope DOFs both clamped and given by `boundary:` has two values at
/// its ends: a tester's clamped string ended at γ = 0.05 without a word. Refused; the
/// `boundary:` alone holds the string at γ.
#[test]
fn a_clamp_and_a_boundary_value_of_one_field_are_refused() {
    use fem_forms::obstacle::{solve_obstacle, ObstacleOptions};
    use fem_forms::{Coefficients, IntervalMesh};
    let mesh = IntervalMesh::uniform(-1.0, 1.0, 16).unwrap();
    let (load, obstacle, held) = (|_: &[f64]| -4.0, |_: &[f64]| -10.0, |_: &[f64]| 0.05);
    let data: [(&str, &fem_forms::DataFn); 3] = [("f", &load), ("ψ", &obstacle), ("γ", &held)];
    let c = Coefficients::new::<held_string::Model>(&[("α", 0.1)], &data).unwrap();
    let Err(e) =
        solve_obstacle::<held_string::Model>(&mesh, &c, &["u"], ObstacleOptions::default())
    else {
        panic!("the clamp and u = γ were both imposed")
    };
    assert!(
        e.to_string().contains("two values for the same DOFs"),
        "{e}"
    );
    let s =
        solve_obstacle::<held_string::Model>(&mesh, &c, &[], ObstacleOptions::default()).unwrap();
    let u = s.view(0);
    for x in [-1.0, 1.0] {
        assert!((u.at(x, 0).unwrap() - 0.05).abs() < 1e-12);
    }
}
