//! Every family through the one pipeline with PETSc as its complementarity solver
//! (`fem-forms solve SCENE --backend petsc`), under `mpirun -n N` (N = 1, 2, 3 in
//! `.ci/run`): on every rank count the answer must be the native solver's to the
//! solvers' tolerance — the energy, the total contact force ∫λ_h and the contact set's
//! measure, the error norms and the a-posteriori estimate (each rank evaluating its own
//! cells) — and certified by the same KKT residual. The scenes cover the membrane
//! (P1–P0, P2–P0, P2–P1disc whose `C` has 3 × 3 blocks, and the nodal method with its
//! bounds on the primal unknowns), the Timoshenko and Euler–Bernoulli beams, the
//! Reissner–Mindlin plate, the Kirchhoff plate (Argyris, Morley), the Winkler plate and
//! Signorini contact with its multiplier (P0 or continuous P1) on boundary edges. Each
//! rank assembles only its own cells (PT-Scotch's partition; of intervals for the beams)
//! and the whole LCP exists only in PETSc: the ranks' rows must add up to PETSc's (the
//! nodal method's too, each bound `U_k ≥ ψ_k` set by one rank).

use fem_models::families;
use fem_models::report::{Outcome, Settings};
use fem_petsc::lcp::{Formulation, PetscLcpSolver};
use fem_runtime::lcp::external::External;
use fem_runtime::lcp::external::ExternalSolver;
use fem_runtime::obstacle::VariationalSolver;

/// (scene, pair, mesh size, load)
const CASES: [(&str, &str, usize, Option<f64>); 19] = [
    ("membrane-radial", "p1-p0", 8, None),
    ("membrane-radial", "p2-p0", 4, None),
    ("membrane-radial", "p2-p1d", 4, None),
    ("membrane-radial", "p1-nodal", 8, None),
    ("membrane-lshape", "p1-p0", 8, None),
    // pressed flat onto ψ = 0: the nested start is the solution, its residual rounding
    ("membrane-flat", "p1-p0", 8, None),
    ("membrane-flat", "p2-p0", 8, None),
    ("timoshenko-t1e-2", "p2-p2-p0", 64, None),
    ("bernoulli-flat", "hermite-p0", 64, Some(100.0)),
    // no load, ψ < 0: U = 0 is the solution and the residual at the start exactly 0
    ("bernoulli-a", "hermite-p0", 16, Some(0.0)),
    ("mindlin-disk", "p1-p2-p0", 4, None),
    ("mindlin-ss-t1e-2", "p1-p2-p0", 8, None),
    ("kirchhoff-obstacle", "argyris-p0", 8, None),
    ("kirchhoff-obstacle", "morley-p0", 16, None),
    ("winkler-square", "argyris-p0", 8, None),
    ("signorini-patch", "p1-p0", 8, None),
    ("hertz", "p1-p0", 4, None),
    // a continuous P1 multiplier: a constraint on a vertex where two ranks' contact
    // edges meet is held by both
    ("hertz", "p1-p1", 4, None),
    ("signorini-patch", "p2-p1", 4, None),
];

fn solve(
    scene: &str,
    pair: &str,
    n: usize,
    load: Option<f64>,
    solver: VariationalSolver,
) -> Outcome {
    let scene = families::scene(scene).unwrap_or_else(|| panic!("scene {scene}"));
    let settings = Settings {
        pair: Some(pair.into()),
        mesh_size: Some(n),
        load,
        solver,
        ..Settings::default()
    };
    families::solve(&scene, &settings)
        .unwrap_or_else(|e| panic!("{} {pair} N = {n} by {solver:?}: {e}", scene.name))
}

/// `text` with every decimal number in it rounded to ten significant digits: a refusal
/// quotes sums (a load's work on a rigid motion) whose last bits depend on the order the
/// ranks' parts are added in, which changes with the partition (PT-Scotch's, whose
/// random state moves on with every earlier partition in the process).
fn to_ten_digits(text: &str) -> String {
    let mut out = String::new();
    let mut rest = text;
    while let Some(start) = rest.find(|c: char| c.is_ascii_digit()) {
        out.push_str(&rest[..start]);
        let tail = &rest[start..];
        let end = tail
            .char_indices()
            .find(|&(i, c)| {
                !(c.is_ascii_digit()
                    || c == '.'
                    || c == 'e'
                    || ((c == '-' || c == '+') && tail[..i].ends_with('e')))
            })
            .map_or(tail.len(), |(i, _)| i);
        let token = tail[..end].trim_end_matches(['.', 'e']);
        match token.parse::<f64>() {
            Ok(x) if token.contains(['.', 'e']) => out.push_str(&format!("{x:.9e}")),
            _ => out.push_str(token),
        }
        rest = &tail[token.len()..];
    }
    out.push_str(rest);
    out
}

fn relative(a: f64, b: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs()).max(1e-300)
}

fn main() {
    let petsc: &'static PetscLcpSolver = Box::leak(Box::new(
        PetscLcpSolver::new("", None).expect("PETSc starts"),
    ));
    let (rank, size) = petsc.rank_and_size();
    let external = VariationalSolver::External(External(petsc));
    for (scene, pair, n, load) in CASES {
        let native = solve(scene, pair, n, load, VariationalSolver::SemismoothNewton).report;
        let before = petsc.records().len();
        let ours = solve(scene, pair, n, load, external).report;
        let (a, b) = (&native.solve, &ours.solve);
        assert_eq!(b.solver, "petsc", "{scene} {pair}");
        assert!(
            petsc.records().len() > before,
            "{scene} {pair}: PETSc solved nothing"
        );
        let case = format!("{scene} {pair} N = {n} on {size} ranks");
        match (a.energy, b.energy) {
            // an exact energy of 0 (membrane-flat) is rounding on both sides
            (Some(x), Some(y)) => assert!(
                relative(x, y) < 1e-9 || (x - y).abs() < 1e-12,
                "{case}: energy {x} and {y}"
            ),
            (x, y) => assert_eq!(x.is_some(), y.is_some(), "{case}: energy {x:?} and {y:?}"),
        }
        let (x, y) = (a.total_contact_force, b.total_contact_force);
        assert!(
            (x - y).abs() <= 1e-7 * x.abs().max(y.abs()).max(1e-12),
            "{case}: ∫λ {x} and {y}"
        );
        for (what, x, y) in [
            ("contact area", a.contact_area, b.contact_area),
            ("contact length", a.contact_length, b.contact_length),
        ] {
            assert_eq!(x, y, "{case}: {what}");
        }
        assert!(
            b.kkt_residual < 1e-8,
            "{case}: KKT residual {}",
            b.kkt_residual
        );
        // the error norms and the estimate, each rank evaluating its own cells and the
        // sums reduced: the native ones to the solvers' tolerance. Absolute floors for
        // answers that are rounding (membrane-flat's u_h = 0 pressed flat, where the
        // estimate's residual f + λ_h cancels to the solves' KKT tolerance, 1e-8 of the
        // scenes' O(1) loads, differently in each solver)
        for (what, x, y, floor) in [
            ("L² error", a.error_l2, b.error_l2, 1e-10),
            ("H¹ error", a.error_h1, b.error_h1, 1e-10),
            ("H² error", a.error_h2, b.error_h2, 1e-10),
            (
                "multiplier error",
                a.error_multiplier,
                b.error_multiplier,
                1e-10,
            ),
            ("estimate", a.estimate, b.estimate, 1e-7),
            (
                "estimate's contact part",
                a.estimate_contact,
                b.estimate_contact,
                1e-7,
            ),
            (
                "error in the energy norm",
                a.error_energy,
                b.error_energy,
                1e-10,
            ),
        ] {
            match (x, y) {
                (Some(x), Some(y)) => assert!(
                    relative(x, y) < 1e-6 || (x - y).abs() < floor,
                    "{case}: {what} {x} and {y}"
                ),
                _ => assert_eq!(x.is_some(), y.is_some(), "{case}: {what} {x:?} and {y:?}"),
            }
        }
        // each rank assembled its own cells of the finest level, and the ranks' rows are
        // PETSc's
        let record = petsc.records().last().cloned().expect("a record");
        let rows = record
            .rows_here
            .unwrap_or_else(|| panic!("{case}: assembled whole on every rank"));
        let mut total = [rows as f64];
        petsc.sum(&mut total);
        let [n, m] = record.unknowns;
        let expected = match record.formulation {
            Formulation::Mixed => n + m,
            _ => n,
        };
        assert_eq!(total[0] as usize, expected, "{case}: the ranks' rows");
        if rank == 0 {
            println!(
                "{case}: {} formulation, {} assembly, {} ({} SNES its), energy {:?} vs {:?}, ∫λ {y:.12e} vs {x:.12e}, KKT {:.1e}",
                record.formulation.name(),
                if record.rows_here.is_some() { "partitioned" } else { "whole" },
                record.converged.reason,
                record.converged.iterations,
                b.energy,
                a.energy,
                b.kkt_residual
            );
        }
    }
    // a level without free primal unknowns (N = 1: every vertex on the boundary): Λ
    // directly, no PETSc solve (its solvers fail on empty matrices), as natively
    let native = solve(
        "membrane-radial",
        "p1-p0",
        1,
        None,
        VariationalSolver::SemismoothNewton,
    );
    let ours = solve("membrane-radial", "p1-p0", 1, None, external);
    assert_eq!(
        (
            ours.report.solve.energy,
            ours.report.solve.total_contact_force
        ),
        (
            native.report.solve.energy,
            native.report.solve.total_contact_force
        ),
        "membrane-radial N = 1"
    );
    // both formulations where both apply: the mixed one on P0 multipliers; at N = 2 the
    // load on the one free vertex is rounding, so the start U = 0 meets SNESVI's
    // absolute tolerance (scaled by (F, G)) and must still take a Newton step
    petsc.set_formulation(Some(Formulation::Mixed));
    for (scene, pair, n) in [
        ("membrane-radial", "p1-p0", 8),
        ("membrane-radial", "p1-p0", 2),
        ("kirchhoff-obstacle", "morley-p0", 16),
    ] {
        let native = solve(scene, pair, n, None, VariationalSolver::SemismoothNewton).report;
        let ours = solve(scene, pair, n, None, external).report;
        let (x, y) = (
            native.solve.total_contact_force,
            ours.solve.total_contact_force,
        );
        assert!(
            (x - y).abs() <= 1e-7 * x.abs(),
            "{scene} {pair} mixed: ∫λ {x} and {y}"
        );
        let record = petsc.records().last().cloned().expect("a record");
        assert_eq!(record.formulation, Formulation::Mixed);
        if rank == 0 {
            println!(
                "{scene} {pair} N = {n} mixed: {} SNESVI its, ∫λ {y:.12e} vs {x:.12e}",
                record.converged.iterations
            );
        }
    }
    // the eliminated formulation where C has blocks: refused, named
    petsc.set_formulation(Some(Formulation::Eliminated));
    let scene = families::scene("membrane-radial").unwrap();
    let settings = Settings {
        pair: Some("p2-p1d".into()),
        mesh_size: Some(4),
        solver: external,
        ..Settings::default()
    };
    let refused = families::solve(&scene, &settings)
        .expect_err("refused")
        .to_string();
    assert!(refused.contains("diagonal positive C"), "{refused}");
    petsc.set_formulation(None);
    contact_checks_on_parts(external, size);
    a_beam_touching_in_two_places(external, size);
    adaptive_meshes_are_the_native_ones(external, size);
    petsc.finalize();
    if rank == 0 {
        println!("pipeline: {} cases equal on {size} ranks", CASES.len());
    }
}

/// A block (0,2)×(0,1) of the contact family as a scene file, `boundary` its lines of
/// `[boundary]`, `pressure` the load's expression.
fn block(cells: [usize; 2], boundary: &str, pressure: &str) -> String {
    format!(
        r#"
    model = "contact"
    [mesh]
    generator = "rectangle"
    x = [0.0, 2.0]
    y = [0.0, 1.0]
    cells = [{}, {}]
    [material]
    young = 1000.0
    poisson = 0.3
    [boundary]
    {boundary}
    [data]
    pressure = "{pressure}"
    gap = "0"
"#,
        cells[0], cells[1]
    )
}

/// The contact family's checks of each level (the free rigid motions through `A`, the
/// load's work on them through `F`, the constraints' reach through `B`) read a level
/// each rank holds a part of through the ranks' reductions: the same answer, or the
/// same refusal word for word (its numbers to ten digits), as natively. Cases: a tilted
/// foundation under a roller (a free oblique translation, held by the contact; with
/// q = (x/2)⁵ the body tips), a
/// held translation with a one-sided tipping condition (held, and turned away), and a
/// coarse level whose one contact edge cannot hold the rotation (skipped for a finer).
fn contact_checks_on_parts(external: VariationalSolver, size: usize) {
    let tilted = |power: u32| {
        block(
            [2, 1],
            "contact = \"bottom\"\n    load = \"top\"\n    fixed_x = \"top\"\n    [parameters]\n    contact_direction = [0.28734788556634544, -0.9578262852211514]",
            &format!("(x/2)^{power}"),
        )
        .replace("cells = [2, 1]", "cells = [2, 1]\n    refinements = 3")
    };
    let one_sided = |load: &str, pressure: &str| {
        block(
            [8, 4],
            &format!("contact = \"bottom\"\n    load = {load}\n    fixed_y = \"left\"\n    fixed_x = \"top\""),
            pressure,
        )
    };
    let cases = [
        (tilted(2), "p1-p0", None),
        (tilted(2), "p1-p1", None),
        (tilted(5), "p1-p0", Some("tips the body")),
        (one_sided("[\"top\", \"right\"]", "10 - 9*y"), "p2-p1", None),
        (
            one_sided("[\"left\", \"top\"]", "0.01 + 10*(1 - y)^8"),
            "p1-p0",
            Some("turns the body away"),
        ),
    ];
    let path = std::path::Path::new("scene.toml");
    for (text, pair, refused) in &cases {
        let file = fem_models::scene_file::parse(text, path).expect("a scene file");
        let mut settings = file.settings();
        settings.pair = Some((*pair).into());
        let native = families::solve(&file.scene, &settings).map(|o| o.report);
        settings.solver = external;
        let ours = families::solve(&file.scene, &settings).map(|o| o.report);
        let case = format!("contact scene file, {pair}, on {size} ranks");
        match (native, ours) {
            (Ok(a), Ok(b)) => {
                assert!(refused.is_none(), "{case}: solved");
                let (x, y) = (a.solve.total_contact_force, b.solve.total_contact_force);
                assert!(
                    (x - y).abs() <= 1e-7 * x.abs().max(y.abs()),
                    "{case}: ∫λ {x} and {y}"
                );
                assert!(b.solve.kkt_residual < 1e-8, "{case}");
                assert_eq!(b.solve.solver, "petsc", "{case}");
            }
            (Err(a), Err(b)) => {
                assert!(
                    refused.is_some_and(|words| a.to_string().contains(words)),
                    "{case}: {a}"
                );
                assert_eq!(
                    to_ten_digits(&a.to_string()),
                    to_ten_digits(&b.to_string()),
                    "{case}"
                );
            }
            (a, b) => panic!(
                "{case}: natively {:?}, by PETSc {:?}",
                a.map(|r| r.solve.total_contact_force),
                b.map(|r| r.solve.total_contact_force)
            ),
        }
    }
    // a unit square free to rotate, pressed by q = x⁸ (its resultant meets the bottom at
    // x = 9/10): nested iteration begins on the first level whose P0 constraints reach
    // it, 128 cells, the coarser ones judged too coarse on every rank alike
    let square = block(
        [1, 1],
        "contact = \"bottom\"\n    load = \"top\"\n    fixed_x = \"top\"",
        "x^8",
    )
    .replace("x = [0.0, 2.0]", "x = [0.0, 1.0]")
    .replace("cells = [1, 1]", "cells = [1, 1]\n    refinements = 4");
    let file = fem_models::scene_file::parse(&square, path).expect("a scene file");
    let mut settings = file.settings();
    settings.pair = Some("p1-p0".into());
    settings.solver = external;
    let report = families::solve(&file.scene, &settings)
        .unwrap_or_else(|e| panic!("the square on {size} ranks: {e}"))
        .report;
    assert_eq!(report.solve.levels[0][0], 128, "the square on {size} ranks");
}

/// A clamped beam pressed onto an obstacle with two bumps, `ψ = −0.005 −
/// 4000((x − 0.45)(x − 0.55))²`: it touches near each and not between, and the contact
/// set keeps the two apart only where the constraints of the cells between are judged
/// open, each on the rank that holds it, the verdicts reduced over the ranks. On 3 ranks
/// the cells between lie on one rank alone: checked to fail there when the other ranks
/// judge the constraints they do not hold.
fn a_beam_touching_in_two_places(external: VariationalSolver, size: usize) {
    let text = r#"
    model = "beam"
    pair = "p2-p2-p0"
    [mesh]
    generator = "interval"
    start = 0.0
    end = 1.0
    size = 64
    [boundary]
    clamped = "all"
    [parameters]
    thickness = 1e-2
    [data]
    f = "-10"
    psi = "-0.005 - 4000*((x-0.45)*(x-0.55))^2"
"#;
    let file = fem_models::scene_file::parse(text, std::path::Path::new("beam.toml"))
        .expect("a scene file");
    let mut settings = file.settings();
    let native = families::solve(&file.scene, &settings).expect("solved natively");
    settings.solver = external;
    let ours = families::solve(&file.scene, &settings).expect("solved by PETSc");
    let set = |o: &fem_models::report::Outcome| o.report.quantity("contact_set").cloned();
    let runs = set(&native)
        .and_then(|s| s.as_array().map(Vec::len))
        .unwrap_or(0);
    assert_eq!(runs, 2, "two contacts natively: {:?}", set(&native));
    assert_eq!(
        set(&ours),
        set(&native),
        "the beam's contact set on {size} ranks"
    );
    assert_eq!(ours.report.solve.solver, "petsc");
}

/// Adaptive solves end on the native meshes, level by level, on every rank count: the
/// marking ties cells whose indicators differ by the rounding of the solve (a symmetric
/// beam refined 57 cells natively and 58 and 60 through PETSc before), and every level
/// is assembled in parts.
fn adaptive_meshes_are_the_native_ones(external: VariationalSolver, size: usize) {
    for (scene, pair, load, n, tolerance) in [
        ("bernoulli-flat", "hermite-p0", Some(100.0), 16, 0.01),
        ("membrane-radial", "p1-p0", None, 4, 0.05),
        ("membrane-radial", "p1-nodal", None, 4, 0.05),
    ] {
        let scene = families::scene(scene).unwrap_or_else(|| panic!("scene {scene}"));
        let mut settings = Settings {
            pair: Some(pair.into()),
            load,
            mesh_size: Some(n),
            adaptive: Some(fem_runtime::adaptivity::AdaptiveOptions {
                tolerance,
                ..Default::default()
            }),
            ..Settings::default()
        };
        let levels = |settings: &Settings| -> Vec<usize> {
            families::solve(&scene, settings)
                .unwrap_or_else(|e| panic!("{} {pair} adaptive on {size} ranks: {e}", scene.name))
                .report
                .solve
                .adaptive_levels
                .iter()
                .map(|l| l.cells)
                .collect()
        };
        let native = levels(&settings);
        settings.solver = external;
        let ours = levels(&settings);
        assert!(
            native.len() > 2,
            "{} {pair}: adaptive levels {native:?}",
            scene.name
        );
        assert_eq!(
            ours, native,
            "{} {pair} adaptive meshes on {size} ranks",
            scene.name
        );
    }
}
