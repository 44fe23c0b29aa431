//! The fem-forms command line: solve the beam and membrane scenes, print tables, write charts.
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

use clap::{Parser, Subcommand, ValueEnum};
use fem_forms::models::families;
use fem_forms::models::report::{Report, Settings};
use fem_forms::models::scene::Scene;
use fem_forms::plot;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

mod backend;
mod solve;

#[derive(Parser)]
#[command(
    name = "fem-forms",
    version,
    about = "Stabilized finite elements for obstacle and contact problems of beams, membranes, plates and elastic bodies: solve scenes, print tables, write charts",
    long_about = "Without a command: solves the beam scenes at q = 1 (no contact) and q = 100 (contact), the membrane scenes, then every plate, Kirchhoff, contact and Winkler scene at its defaults, prints tables, writes plots of w, θ, λ and ψ, the contact pressures against Hertz's, .vtu files of the membranes and the study charts to out/."
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// Directory for charts and CSV files.
    #[arg(long, global = true, default_value = "out")]
    out: PathBuf,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum SolverName {
    /// Semismooth Newton / primal–dual active set (nested iteration).
    Pdas,
    /// clarabel's interior-point method on the equivalent QP.
    Clarabel,
}

#[derive(Subcommand)]
enum Command {
    /// List the scenes (with their family, pairs and studies) and the element pairs.
    List,
    /// Solve one scene: a built-in one by name, or a scene file (`--scene my.toml`).
    /// Options that do not apply to the scene's family are refused.
    Solve {
        /// Scene name (see `list`).
        #[arg(required_unless_present = "scene_file", conflicts_with = "scene_file")]
        name: Option<String>,
        /// A scene file (TOML: model, pair, mesh, boundary, parameters, data as
        /// expressions in x, y; see examples/ and the README). Options given on the
        /// command line override the file's.
        #[arg(long = "scene", value_name = "FILE")]
        scene_file: Option<PathBuf>,
        // boxed: the options are most of the enum's size (clippy::large_enum_variant)
        #[command(flatten)]
        options: Box<SolveOptions>,
    },
    /// Run a study and write its chart and CSV (out/<scene>-<study>.svg, .csv; the
    /// lambda-scatter study also out/<scene>-lambda-layer.*): `study <scene> [study]`
    /// runs one study the scene hosts (all of them when left out; see `list`);
    /// `study <study>` runs it on every scene that hosts it (convergence, locking,
    /// stability, alpha, work-precision, iterations, lambda-scatter).
    Study {
        /// A scene name, or a study.
        study: String,
        /// The study, after a scene name.
        kind: Option<String>,
        /// Larger meshes (longer).
        #[arg(long)]
        full: bool,
    },
    /// Run every study of every family and write one self-contained web page,
    /// <out>/index.html (charts inline, opens from disk; their data and the studies'
    /// tables under <out>/studies/), with each scene's accuracy against its reference
    /// and the machine, date, commit and time of each study. A progress bar shows the
    /// studies as they run; the quick settings take a few minutes on 2 cores.
    Report {
        /// The studies' larger meshes (much longer).
        #[arg(long)]
        full: bool,
        /// Only these scenes' studies (and their families' accuracy tables).
        #[arg(long = "scene", value_name = "SCENE")]
        scenes: Vec<String>,
        /// PETSc's SNES tutorial ex9, built (default: $FEM_FORMS_PETSC_EX9): run on the
        /// radial membrane's grids beside the nodal method, errors and solve times.
        #[arg(long, value_name = "PATH")]
        petsc_ex9: Option<PathBuf>,
    },
}

/// The options of `solve`. Each applies to one family (or one kind of scene) only; the
/// others are `None`/`false` unless given, and a given one that does not apply is an
/// error naming it.
#[derive(clap::Args, Debug, Default)]
struct SolveOptions {
    /// Elements of the uniform mesh (beams; default 256).
    #[arg(long, allow_negative_numbers = true)]
    elements: Option<usize>,
    /// N: an N×N×2 triangle mesh of the scene's square (membranes; the L-shape keeps
    /// three quarters of it). (default 64; with --msh: 0 refinements) Plates: N of the
    /// square's N×N×2 mesh or the disk's rings (default 32; kirchhoff-square 16).
    /// Contact: N of signorini-patch's 2N×N×2 block mesh (default 8); b/h, cells per
    /// contact half-width, of hertz's and signorini-gap's graded meshes (default 16, 64);
    /// with a scene file, uniform refinements of its mesh.
    #[arg(long, allow_negative_numbers = true)]
    mesh_size: Option<usize>,
    /// Also write u, λ, ψ and the contact set as a .vtu for ParaView (membranes).
    #[arg(long)]
    vtk: bool,
    /// Solve on this Gmsh mesh (MSH 4.1) instead of the structured one; with it,
    /// --mesh-size is the number of uniform refinements (membranes).
    #[arg(long)]
    msh: Option<PathBuf>,
    /// Load magnitude q: the load is q times the scene's load field (beams: f = ∓q, q = 1
    /// no contact, 40 and 100 contact; membrane-flat: f = −q, default 3;
    /// membrane-lshape: f = −q, default 12). Refused where the load is fixed
    /// (membrane-radial: f = 0). Contact: the pressure q on signorini-patch's top
    /// (default 1), the resultant P per unit length of hertz and signorini-gap (default
    /// 1), the scale of a contact scene file's pressure.
    #[arg(long, allow_hyphen_values = true, value_parser = parse_load)]
    load: Option<f64>,
    /// The plate's bending and twisting moments and shear force along its boundary
    /// (plates: the report's `edge_resultants`). Under --tol a Reissner–Mindlin mesh is
    /// refined along its free and soft simply supported edges until it resolves the
    /// rotations' boundary layer (width t/√(12κ)), and the Kirchhoff plate is weighed by
    /// its error in these resultants too, not by its energy alone.
    #[arg(long)]
    edge_resultants: bool,
    /// Thickness t (Timoshenko beams and the Reissner–Mindlin plates; on a Kirchhoff
    /// scene, that of the Reissner–Mindlin plate it stands for: its modelling estimate,
    /// and that plate weighed by --tol or solved by --pair p1-p2-p0).
    #[arg(long, allow_hyphen_values = true)]
    thickness: Option<f64>,
    /// Stabilization parameter α (negative values are refused with a reason; not for
    /// p1-nodal, which has no multiplier). 0: the plain mixed method, solved as a QP by
    /// clarabel. Each family's default is its rule ½/C_I (contact: ½/max C_I,E); values
    /// well beyond 1/C_I make the stabilized matrix indefinite: an error names α·C_I.
    #[arg(long, allow_hyphen_values = true, value_parser = parse_alpha)]
    alpha: Option<f64>,
    /// Element pair (beams: p2-p2-p0, p1-p1-p0-reduced, p1-p1-p0-full, hermite-p0;
    /// membranes: p1-p0, p2-p0, p2-p1d, p1-nodal; plates and contact: see `list`).
    #[arg(long)]
    pair: Option<String>,
    /// LCP solver (default pdas; not for p1-nodal).
    #[arg(long, value_enum)]
    solver: Option<SolverName>,
    /// Start Newton from zero on the final mesh instead of nested iteration.
    #[arg(long)]
    cold: bool,
    /// Solver of the Newton steps: auto (default: the faster as measured, multigrid on the
    /// nested meshes for p1-nodal's active-set steps, direct Cholesky with low-rank
    /// updates for the stabilized pairs and beams), direct, or multigrid (membranes and
    /// beams; multigrid takes 10–20 % less memory on the stabilized pairs; on beams the
    /// banded Cholesky is O(N) already, and multigrid is there for studies).
    #[arg(long, value_name = "auto|direct|multigrid")]
    linear_solver: Option<String>,
    /// Rounds of iterative refinement per linear solve (beams; default 1; t ≤ 1e-5
    /// wants 2 or 3).
    #[arg(long)]
    refinement: Option<usize>,
    /// Plate support (plate scenes): clamped, simply-supported (soft: w = 0),
    /// simply-supported-hard (and the rotations' tangential part), free, dirichlet.
    #[arg(long)]
    support: Option<String>,
    /// Obstacle above the plate (Kirchhoff scenes): none, flat (w ≤ 0.002) or curved
    /// (w ≤ 0.002 + 0.01 r²).
    #[arg(long)]
    obstacle: Option<String>,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    json: bool,
    /// Solve the plate without its obstacle (plates with one: mindlin-disk); the report
    /// then compares the centre deflection with the closed form where there is one.
    #[arg(long)]
    no_obstacle: bool,
    /// Also write the plot of w, θ, λ, ψ (beams), or of the contact pressure against
    /// Hertz's (hertz, signorini-gap).
    #[arg(long)]
    plot: bool,
    /// Solve adaptively until the a-posteriori estimate (η² + S²)^{1/2} is at most T
    /// times the energy norm ‖u_h‖_a of the solution: solve, estimate, mark, refine
    /// (newest-vertex bisection, new vertices on a curved boundary moved onto it;
    /// bisection on beams), solve again from the previous solution (every family, on
    /// the pairs whose model declares an estimator; the first level is --mesh-size,
    /// else the probes' coarse mesh: 16 elements, 8 of a square's N). Without --pair, T also chooses the
    /// model and pair: every pair of the scene and its family's cheaper model
    /// (Euler–Bernoulli for Timoshenko, Kirchhoff for Reissner–Mindlin) are probed, and
    /// the one predicted fastest within T is solved (docs/model-choice.md).
    #[arg(long, value_name = "T", allow_hyphen_values = true)]
    tol: Option<f64>,
    /// Marking of the adaptive loop: dorfler (default: the fewest cells holding θ of
    /// η²) or max (every cell with η_T ≥ θ max η).
    #[arg(long, value_name = "dorfler|max")]
    marking: Option<String>,
    /// The marking parameter θ in (0, 1] (default 0.5).
    #[arg(long, allow_hyphen_values = true)]
    theta: Option<f64>,
    /// The adaptive loop's limit on a level's unknowns (default 2000000): the loop stops
    /// before a larger level with an error saying how far it got. Memory is about 2 KB
    /// per unknown (a Reissner–Mindlin plate at t = 1e-4 with its edge layer resolved:
    /// 2.3 million unknowns, 4.6 GB, 55 s). With --tol; the model choice predicts against it.
    #[arg(long, value_name = "N")]
    max_dofs: Option<usize>,
    /// Who solves the complementarity problems: native (default) or petsc (PETSc's SNES
    /// and SNESVI over MPI, in a binary built with `--features petsc`; run it as
    /// `mpirun -n N fem-forms solve SCENE --backend petsc`; docs/petsc.md).
    #[arg(long, value_name = "native|petsc")]
    backend: Option<String>,
    /// PETSc's options, as one string (`"-snes_monitor -ksp_type cg -pc_type gamg"`).
    #[arg(long, value_name = "OPTIONS", allow_hyphen_values = true)]
    petsc_options: Option<String>,
    /// How PETSc is given a stabilized pair's problem: eliminated (default where the
    /// multipliers are P0: SNES on Φ(U)) or mixed (SNESVI on (U, Λ), bounds on Λ).
    #[arg(long, value_name = "eliminated|mixed")]
    petsc_formulation: Option<String>,
}

fn table_header() {
    println!(
        "{:<15} {:>5} {:>7} {:>6} {:>6} {:>5} {:>8} {:>14} {:<24} {:>9} {:>10}",
        "scene",
        "q",
        "t",
        "elems",
        "dofs",
        "iter",
        "seconds",
        "energy",
        "contact set",
        "kkt res",
        "L2 error"
    );
}

fn fmt_contact(set: &[[f64; 2]]) -> String {
    if set.is_empty() {
        return "none".into();
    }
    set.iter()
        .map(|[a, b]| {
            if a == b {
                format!("point {a:.4}")
            } else {
                format!("[{a:.4}, {b:.4}]")
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

fn table_row(r: &fem_forms::models::run::Report) {
    let load = r.load.unwrap_or(1.0);
    for w in &r.solve.warnings {
        eprintln!("warning ({} q = {}): {w}", r.scene, fem_forms::number(load));
    }
    let contact_set: Vec<[f64; 2]> = r
        .quantities
        .get("contact_set")
        .and_then(|v| serde_json::from_value(v.clone()).ok())
        .unwrap_or_default();
    println!(
        "{:<15} {:>5} {:>7} {:>6} {:>6} {:>5} {:>8.4} {:>14.8e} {:<24} {:>9.1e} {:>10}",
        r.scene,
        fem_forms::number(load),
        // in full where it fits the column, else to three digits
        r.parameters.get("t").map_or("-".into(), |&t| {
            let full = fem_forms::number(t);
            if full.chars().count() <= 7 {
                full
            } else {
                format!("{t:.2e}")
            }
        }),
        r.solve.cells,
        r.solve.dofs,
        r.solve.iterations,
        r.solve.seconds,
        r.solve.energy.unwrap_or(f64::NAN),
        fmt_contact(&contact_set),
        r.solve.kkt_residual,
        r.solve.error_l2.map_or("-".into(), |e| format!("{e:.2e}")),
    );
}

fn pair_header() {
    println!(
        "{:<16} {:<8} {:>5} {:>8} {:>8} {:>5} {:>8} {:>9} {:>10} {:>10} {:>10} {:>9} {:>8} {:>9}",
        "scene",
        "pair",
        "N",
        "triangles",
        "dofs",
        "iter",
        "seconds",
        "alpha",
        "L2 error",
        "H1 error",
        "∫λ_h",
        "area",
        "kkt res",
        "C_I"
    );
}

fn pair_row(r: &Report) {
    let s = &r.solve;
    for w in &s.warnings {
        eprintln!("warning ({} {}): {w}", r.scene, r.pair);
    }
    let opt = |e: Option<f64>| e.map_or("-".into(), |e| format!("{e:.3e}"));
    println!(
        "{:<16} {:<8} {:>5} {:>8} {:>8} {:>5} {:>8.3} {:>9} {:>10} {:>10} {:>10.5} {:>9.5} {:>8.1e} {:>9.3}",
        r.scene,
        r.pair,
        r.mesh_size,
        s.cells,
        s.dofs,
        s.iterations,
        s.seconds,
        s.alpha.map_or("-".into(), |a| format!("{a:.2e}")),
        opt(s.error_l2),
        opt(s.error_h1),
        s.total_contact_force,
        s.contact_area.unwrap_or(f64::NAN),
        s.kkt_residual,
        s.inverse_constant
    );
}

fn default_job(out: &Path) -> Result<(), String> {
    println!("fem-forms: default beam scenes (clamped on (0,1), 256 elements, nested semismooth Newton)\n");
    table_header();
    let in_job = |family: &str| -> Vec<Scene> {
        families::scenes()
            .into_iter()
            .filter(|s| s.family == family && s.in_default_job)
            .collect()
    };
    let beams = in_job("beam");
    for scene in &beams {
        for q in [1.0, 100.0] {
            let settings = Settings {
                load: Some(q),
                ..Default::default()
            };
            let outcome =
                families::solve(scene, &settings).map_err(|e| format!("{}: {e}", scene.name))?;
            table_row(&outcome.report);
            let path = out.join(format!("{}-q{q}.svg", scene.name));
            plot::profiles(&path, &format!("{} q = {q}", scene.name), &outcome.fields)
                .map_err(|e| format!("{}: {e}", path.display()))?;
        }
    }
    println!(
        "\nplots of w, θ, λ, ψ: {}/<scene>-q<q>.svg\n",
        out.display()
    );
    hosted_studies(&beams, out)?;
    let membranes = in_job("membrane");
    membrane_job(&membranes, out)?;
    hosted_studies(&membranes, out)?;
    registry_job(&["plate", "kirchhoff", "contact", "winkler"], out)
}

/// The default job's families solved at their defaults through the registry: the
/// plates, contact and the Winkler plate, a summary each and the family's chart where it
/// has one (out/hertz-pressure.svg, out/signorini-gap-pressure.svg).
fn registry_job(names: &[&str], out: &Path) -> Result<(), String> {
    for family in names {
        println!("\nfem-forms: {family} scenes at their defaults\n");
        for scene in families::scenes().iter().filter(|s| s.family == *family) {
            let outcome = families::solve(scene, &Default::default())
                .map_err(|e| format!("{}: {e}", scene.name))?;
            println!("{}", solve::summary(&outcome.report));
            for warning in &outcome.report.solve.warnings {
                println!("  warning: {warning}");
            }
            if let Some(profile) = &outcome.profile {
                let path = solve::profile_chart(&scene.name, profile, out)?;
                println!("→ {}", path.display());
            }
        }
    }
    Ok(())
}

/// Every study each of `scenes` hosts, quick versions.
fn hosted_studies(scenes: &[Scene], out: &Path) -> Result<(), String> {
    for scene in scenes.iter().filter(|s| !s.studies.is_empty()) {
        fem_forms::registry_studies::run_hosted(scene.clone(), None, false, out)?;
    }
    Ok(())
}

/// `solve --scene FILE`: the file's scene with its pair, α and mesh size where the
/// command line gives none.
fn solve_file(
    file: fem_forms::models::scene_file::FileScene,
    path: &Path,
    mut options: SolveOptions,
    out: &Path,
) -> Result<(), String> {
    if options.pair.is_none() {
        options.pair = file.pair.clone();
    }
    // the file's size belongs to its own mesh: with --msh replacing it, --mesh-size
    // (refinements of that file) defaults to 0 as for built-in scenes
    let interval = matches!(
        file.scene.domain,
        fem_forms::models::scene::Domain::Interval { .. }
    );
    match &options.msh {
        // a beam's size is its number of elements (`--elements`)
        None if interval => {
            options.elements.get_or_insert(file.scene.mesh_size);
        }
        // a mesh size left out is the file's (the memory refusal then names its key)
        None => {}
        // said, so that the file's size is not dropped unseen
        Some(msh) if options.mesh_size.is_none() => eprintln!(
            "warning: --msh {} replaces the mesh of {}, and with it the file's mesh size or refinements ({}); --mesh-size gives the refinements of the --msh mesh (0 here)",
            msh.display(),
            path.display(),
            file.scene.mesh_size
        ),
        Some(_) => {}
    }
    if options.alpha.is_none() {
        if let Some(alpha) = file.alpha {
            // the file's α, not an --alpha, where the pair has none to take
            let pair = fem_forms::models::families::pair_of(&file.scene, options.pair.as_deref())
                .map_err(|e| e.to_string())?;
            if pair.nodal {
                return Err(format!(
                    "{}: key `parameters.alpha` does not apply to the pair {}: it has no multiplier to stabilize; drop the key or choose a stabilized pair",
                    path.display(),
                    pair.name
                ));
            }
            options.alpha = Some(alpha);
        }
    }
    solve::solve_scene(file.scene, &options, out)
}

/// The membrane part of the default job: every pair on the radial scene, for each scene
/// the coarsest mesh of each pair that reaches its asked accuracy and the cheapest of
/// them ([`fem_forms::accuracy`]), and the cheapest solve as a .vtu.
fn membrane_job(scenes: &[Scene], out: &Path) -> Result<(), String> {
    println!("\nfem-forms: membrane scenes (N×N×2 triangles, nested semismooth Newton)\n");
    pair_header();
    let radial = scenes
        .iter()
        .find(|s| s.name == "membrane-radial")
        .ok_or("the registry has no membrane-radial")?;
    for pair in families::pairs_of(radial) {
        let settings = Settings {
            pair: Some(pair.name.into()),
            ..Settings::default()
        };
        match families::solve(radial, &settings) {
            Ok(outcome) => pair_row(&outcome.report),
            Err(e) => println!("{:<16} {:<8} not solved: {e}", radial.name, pair.name),
        }
    }
    std::fs::create_dir_all(out).map_err(|e| e.to_string())?;
    for scene in scenes.iter().filter(|s| s.accuracy.is_some()) {
        accuracy_table(scene, out)?;
    }
    println!();
    Ok(())
}

/// The accuracy table of one scene ([`fem_forms::accuracy::cheapest_for_accuracy`]) and
/// the .vtu of its cheapest solve.
fn accuracy_table(scene: &Scene, out: &Path) -> Result<(), String> {
    let (rungs, cheapest) = fem_forms::accuracy::cheapest_for_accuracy(scene)
        .map_err(|e| format!("{}: {e}", scene.name))?;
    println!(
        "\n{}: the coarsest mesh of each pair with estimated ‖u − u_h‖_L2 ≤ {:.0e} (Richardson estimate against N×2{})",
        scene.name,
        scene.accuracy.unwrap_or(f64::NAN),
        if rungs.iter().any(|r| r.exact_l2.is_some()) { "; exact error beside" } else { "" }
    );
    for (k, r) in rungs.iter().enumerate() {
        if let Some(e) = &r.failure {
            println!("  {:<9} not solved: {e}", r.pair);
            continue;
        }
        println!(
            "  {:<9} N = {:>3} {:>8} dofs {:>8.3} s  estimated {:.2e}{}{}{}",
            r.pair,
            r.mesh_size,
            r.dofs,
            r.seconds,
            r.estimated_l2,
            r.exact_l2
                .map_or(String::new(), |e| format!(", exact {e:.2e}")),
            if r.reached {
                String::new()
            } else {
                format!("  (not reached by N = {})", fem_forms::accuracy::FINEST)
            },
            if Some(k) == cheapest {
                "  ← cheapest"
            } else {
                ""
            }
        );
    }
    if let Some(k) = cheapest {
        let settings = Settings {
            pair: Some(rungs[k].pair.into()),
            mesh_size: Some(rungs[k].mesh_size),
            ..Settings::default()
        };
        let outcome = families::solve(scene, &settings).map_err(|e| e.to_string())?;
        let path = out.join(format!("{}.vtu", scene.name));
        outcome.fields.write_vtu(&path).map_err(|e| e.to_string())?;
        println!(
            "  → {} (u, ψ, λ_h, contact set for ParaView)",
            path.display()
        );
    }
    Ok(())
}

fn list() {
    println!("scenes (family, pairs with the default first, studies):");
    for scene in families::scenes() {
        let load = scene.load.as_ref().map_or("fixed load".to_string(), |l| {
            format!(
                "--load {} = {} by default",
                l.symbol,
                fem_forms::number(l.default)
            )
        });
        let pairs: Vec<&str> = families::pairs_of(&scene).iter().map(|p| p.name).collect();
        println!("  {:<18} {}", scene.name, scene.description);
        println!(
            "  {:<18} {} scene; pairs {}; {load}{}",
            "",
            scene.family,
            pairs.join(", "),
            if scene.studies.is_empty() {
                String::new()
            } else {
                format!("; studies {}", scene.studies.join(", "))
            }
        );
        if !scene.study_variants.is_empty() {
            let labels: Vec<&str> = scene
                .study_variants
                .iter()
                .map(|v| v.label.as_str())
                .collect();
            println!(
                "  {:<18} studied as its variants {} (`study {}-{} …` runs one)",
                "",
                labels.join(", "),
                scene.name,
                labels[0]
            );
        }
    }
    for family in families::families() {
        let options: Vec<&str> = family.options().iter().map(|o| o.flag()).collect();
        println!(
            "{} ({}); options {}:",
            family.name(),
            family.description(),
            options.join(", ")
        );
        for p in family.pairs() {
            println!("  {:<18} {} (α: {})", p.name, p.note, alpha_rule(p));
        }
    }
}

/// A pair's α rule in words.
fn alpha_rule(pair: &fem_forms::models::family::Pair) -> String {
    use fem_forms::stabilization::Alpha;
    if pair.nodal {
        return "none: no multiplier space".into();
    }
    match pair.alpha {
        Alpha::Fixed(a) => fem_forms::number(a),
        Alpha::FromInverseConstant(c) => format!(
            "{}/C_I, or {} where C_I = 0",
            fem_forms::number(c),
            fem_forms::number(pair.alpha_when_zero)
        ),
    }
}

/// Every study kind some scene hosts, sorted.
fn hosted_kinds() -> Vec<&'static str> {
    let mut kinds: Vec<&str> = families::scenes()
        .iter()
        .flat_map(|s| s.studies.clone())
        .collect();
    kinds.sort_unstable();
    kinds.dedup();
    kinds
}

/// `study <scene> [kind]` through the registry, or `study <kind>` on every scene that
/// hosts it.
fn study(name: &str, kind: Option<&str>, full: bool, out: &Path) -> Result<(), String> {
    if let Some(scene) = families::scene(name) {
        return fem_forms::registry_studies::run_hosted(scene, kind, full, out);
    }
    // a study variant of a scene (`mindlin-disk-q20`)
    let variant = families::scenes()
        .iter()
        .filter(|s| !s.study_variants.is_empty() && name.starts_with(&*s.name))
        .filter_map(|s| families::study_variants(s).ok())
        .flatten()
        .find(|v| v.name == name);
    if let Some(scene) = variant {
        return fem_forms::registry_studies::run_hosted(scene, kind, full, out);
    }
    let scene_names = || -> String {
        let names: Vec<String> = families::scenes()
            .iter()
            .map(|s| s.name.to_string())
            .collect();
        names.join(", ")
    };
    if let Some(kind) = kind {
        let swapped = if families::scene(kind).is_some() && hosted_kinds().contains(&name) {
            format!(" (did you mean `study {kind} {name}`?)")
        } else {
            String::new()
        };
        return Err(format!(
            "`{name}` is not a scene, so `{kind}` cannot be its study{swapped}; the scenes are {}",
            scene_names()
        ));
    }
    let hosts: Vec<Scene> = families::scenes()
        .into_iter()
        .filter(|s| s.studies.contains(&name))
        .collect();
    if hosts.is_empty() {
        return Err(format!(
            "unknown study or scene `{name}`; the studies are {}, and `study <scene> <study>` runs a study a scene hosts (see `list`)",
            hosted_kinds().join(", ")
        ));
    }
    for scene in hosts {
        fem_forms::registry_studies::run_hosted(scene, Some(name), full, out)?;
    }
    Ok(())
}

fn run(cli: Cli) -> Result<(), String> {
    if let Some((_, size)) = backend::launcher_ranks().filter(|&(_, size)| size > 1) {
        let distributed = matches!(
            &cli.command,
            Some(Command::Solve { options, .. }) if options.backend.as_deref() == Some("petsc")
        );
        if !distributed {
            return Err(format!(
                "started as {size} processes (mpirun): only `solve … --backend petsc` runs distributed; any other command would run {size} times over"
            ));
        }
    }
    let out = cli.out.clone();
    let created = !out.exists();
    let result = run_in(cli);
    // a command refused before it wrote anything leaves no empty --out behind
    if result.is_err() && created {
        let _ = std::fs::remove_dir(&out);
    }
    result
}

/// [`run`] once `--out` may be created.
fn run_in(cli: Cli) -> Result<(), String> {
    // checked before any solve: a study found its --out unusable only after running
    if cli.out.exists() && !cli.out.is_dir() {
        return Err(format!(
            "--out {}: exists and is not a directory",
            cli.out.display()
        ));
    }
    std::fs::create_dir_all(&cli.out).map_err(|e| {
        format!(
            "--out {}: cannot create the directory: {e}",
            cli.out.display()
        )
    })?;
    // and writable: a read-only --out failed after a whole study, naming no file
    let probe = cli
        .out
        .join(format!(".fem-forms-write-check-{}", std::process::id()));
    std::fs::write(&probe, b"")
        .map_err(|e| format!("--out {}: cannot write files there: {e}", cli.out.display()))?;
    let _ = std::fs::remove_file(&probe);
    match cli.command {
        None => default_job(&cli.out),
        Some(Command::Report {
            full,
            scenes,
            petsc_ex9,
        }) => {
            let petsc_ex9 =
                petsc_ex9.or_else(|| std::env::var_os("FEM_FORMS_PETSC_EX9").map(PathBuf::from));
            if let Some(ex9) = &petsc_ex9 {
                if !ex9.is_file() {
                    return Err(format!(
                        "--petsc-ex9 {}: no such file (build PETSc's src/snes/tutorials/ex9.c, e.g. `mpicc ex9.c $(pkg-config --cflags --libs PETSc) -lm -o ex9`)",
                        ex9.display()
                    ));
                }
            }
            for name in &scenes {
                let scene = families::scene(name).ok_or_else(|| {
                    // `mindlin-disk-q10` names a study variant: the report runs them all
                    match families::scenes().into_iter().find(|s| {
                        !s.study_variants.is_empty() && name.starts_with(&format!("{}-", s.name))
                    }) {
                        Some(parent) => format!(
                            "--scene {name}: a study variant of `{0}`, whose every variant the report runs: --scene {0}",
                            parent.name
                        ),
                        None => format!("--scene {name}: no such scene (see `list`)"),
                    }
                })?;
                if scene.studies.is_empty() {
                    return Err(format!(
                        "--scene {name}: hosts no study (see `list` for the scenes that do)"
                    ));
                }
            }
            let options = fem_forms::report_page::Options {
                full,
                out: cli.out.clone(),
                scenes,
                petsc_ex9,
            };
            let page = fem_forms::report_page::write(&options)?;
            println!("→ {}", page.display());
            Ok(())
        }
        Some(Command::List) => {
            list();
            Ok(())
        }
        Some(Command::Solve {
            name,
            scene_file,
            options,
        }) => match (name, scene_file) {
            (_, Some(path)) => {
                let file = fem_forms::models::scene_file::read(&path).map_err(|e| e.to_string())?;
                solve_file(file, &path, *options, &cli.out)
            }
            (Some(name), None) => {
                let scene = fem_forms::models::families::scene(&name).ok_or_else(|| {
                    let names: Vec<String> = fem_forms::models::families::scenes()
                        .iter()
                        .map(|s| s.name.to_string())
                        .collect();
                    format!(
                        "unknown scene `{name}`; the scenes are {}",
                        names.join(", ")
                    )
                })?;
                solve::solve_scene(scene, &options, &cli.out)
            }
            (None, None) => Err("give a scene name or --scene FILE".into()),
        },
        Some(Command::Study {
            study: name,
            kind,
            full,
        }) => study(&name, kind.as_deref(), full, &cli.out),
    }
}

/// `--alpha`: a number, with `-0` read as 0 (the plain method), so that reports do not
/// echo a negative zero.
fn parse_alpha(text: &str) -> Result<f64, String> {
    text.trim()
        .parse::<f64>()
        .map(|alpha| alpha + 0.0)
        .map_err(|e| format!("`{text}` is not a number: {e}"))
}

/// `--load`: a number, refused when subnormal (non-zero below 2.2e-308, the smallest
/// normal double). Its products with the forms' coefficients lose their digits:
/// 1e-315 made Newton stop at a KKT residual of 8e-3 on a problem whose answer
/// is the load times a fixed field.
fn parse_load(text: &str) -> Result<f64, String> {
    let q = text
        .trim()
        .parse::<f64>()
        .map_err(|e| format!("`{text}` is not a number: {e}"))?;
    if q != 0.0 && q.abs() < fem_forms::MIN_DATA_SIZE {
        let subnormal = if q.abs() < f64::MIN_POSITIVE {
            " (subnormal)"
        } else {
            ""
        };
        return Err(format!(
            "{q:e}{subnormal} is below {:e} in size: the solve multiplies it by powers of h and would underflow; give 0 or rescale the units",
            fem_forms::MIN_DATA_SIZE
        ));
    }
    Ok(q)
}

fn main() -> ExitCode {
    // a reader that stops early (`fem-forms solve … | head -1`) ends the process as it
    // ends any Unix filter, instead of `println!` panicking on the closed pipe (Rust
    // ignores SIGPIPE by default)
    // SAFETY: at the start of main, before any thread exists; SIG_DFL is a valid handler
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    fem_forms::lcp::cholesky::factor_sequentially();
    // before any thread allocates
    fem_forms::allocator::keep_freed_memory();
    fem_forms::allocator::small_pages();
    // under mpirun every rank runs this; rank 0 alone speaks, from the first message on
    // (an argument refused by clap, too)
    if backend::launcher_ranks().is_some_and(|(rank, _)| rank != 0) {
        backend::silence_output();
    }
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
