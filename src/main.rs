//! The fem-forms command line: solve the beam and membrane scenes, print tables, write charts.
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

use clap::{Parser, Subcommand, ValueEnum};
use fem_forms::beams::{self, Pair, Report, Request};
use fem_forms::membrane_studies::{self, MembraneStudy};
use fem_forms::membranes::{self, MembranePair, MembraneReport, MembraneRequest};
use fem_forms::models::membrane_scenes::{membrane_scene, MEMBRANE_FLAT, MEMBRANE_SCENES};
use fem_forms::models::scenes::{scene, SCENES};
use fem_forms::obstacle::VariationalSolver;
use fem_forms::{plot, studies};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "fem-forms",
    version,
    about = "Stabilized finite elements for obstacle problems of beams and membranes: solve scenes, print tables, write charts",
    long_about = "Without a command: solves the beam scenes at q = 1 (no contact) and q = 100 (contact) and the membrane scenes, prints tables, writes plots of w, θ, λ and ψ, .vtu files of the membranes and the study charts to out/."
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// Directory for charts and CSV files.
    #[arg(long, global = true, default_value = "out")]
    out: PathBuf,
}

#[derive(Clone, Copy, ValueEnum)]
enum SolverName {
    /// Semismooth Newton / primal–dual active set (nested iteration).
    Pdas,
    /// clarabel's interior-point method on the equivalent QP.
    Clarabel,
}

#[derive(Subcommand)]
enum Command {
    /// List the scenes and the element pairs.
    List,
    /// Solve one scene.
    Solve {
        /// Scene name (see `list`).
        scene: String,
        /// Elements of the uniform mesh (beams).
        #[arg(long, default_value_t = 256)]
        elements: usize,
        /// N: an N×N×2 triangle mesh of the scene's square (membranes; the L-shape keeps
        /// three quarters of it).
        /// (default 64; with --msh: 0 refinements)
        #[arg(long)]
        mesh_size: Option<usize>,
        /// Also write u, λ, ψ and the contact set as a .vtu for ParaView (membranes).
        #[arg(long)]
        vtk: bool,
        /// Solve on this Gmsh mesh (MSH 4.1) instead of the structured one; with it,
        /// --mesh-size is the number of uniform refinements (membranes).
        #[arg(long)]
        msh: Option<PathBuf>,
        /// Load magnitude q (1: no contact; 40 and 100: contact).
        #[arg(long, default_value_t = 1.0)]
        load: f64,
        /// Beam thickness t (Timoshenko scenes).
        #[arg(long)]
        thickness: Option<f64>,
        /// Stabilization parameter α (negative values are refused with a reason).
        #[arg(long, allow_negative_numbers = true)]
        alpha: Option<f64>,
        /// Element pair (beams: p2-p2-p0, p1-p1-p0-reduced, p1-p1-p0-full, hermite-p0;
        /// membranes: p1-p0, p2-p0, p2-p1d, p1-nodal).
        #[arg(long)]
        pair: Option<String>,
        /// LCP solver.
        #[arg(long, value_enum, default_value = "pdas")]
        solver: SolverName,
        /// Start Newton from zero on the final mesh instead of nested iteration.
        #[arg(long)]
        cold: bool,
        /// Rounds of iterative refinement per linear solve (t ≤ 1e-5 wants 2 or 3).
        #[arg(long, default_value_t = 1)]
        refinement: usize,
        /// Print one JSON object instead of a table.
        #[arg(long)]
        json: bool,
        /// Also write the plot of w, θ, λ, ψ.
        #[arg(long)]
        plot: bool,
    },
    /// Run a study and write its chart and CSV: a beam study (convergence, locking,
    /// stability, alpha, work-precision, iterations), or `membrane-radial` followed by
    /// convergence, stability or alpha (all three when left out).
    Study {
        /// Which study, or the membrane scene `membrane-radial`.
        study: String,
        /// The membrane study.
        #[arg(value_enum)]
        kind: Option<MembraneStudy>,
        /// Larger meshes (longer).
        #[arg(long)]
        full: bool,
    },
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

fn table_row(r: &Report) {
    for w in &r.warnings {
        eprintln!("warning ({} q = {}): {w}", r.scene, r.load);
    }
    println!(
        "{:<15} {:>5} {:>7} {:>6} {:>6} {:>5} {:>8.4} {:>14.8e} {:<24} {:>9.1e} {:>10}",
        r.scene,
        r.load,
        r.thickness.map_or("-".into(), |t| format!("{t:.0e}")),
        r.elements,
        r.dofs,
        r.iterations,
        r.seconds,
        r.energy,
        fmt_contact(&r.contact_set),
        r.complementarity_residual,
        r.error_l2.map_or("-".into(), |e| format!("{e:.2e}")),
    );
}

fn membrane_header() {
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

fn membrane_row(r: &MembraneReport) {
    for w in &r.warnings {
        eprintln!("warning ({} {}): {w}", r.scene, r.pair);
    }
    let opt = |e: Option<f64>| e.map_or("-".into(), |e| format!("{e:.3e}"));
    println!(
        "{:<16} {:<8} {:>5} {:>8} {:>8} {:>5} {:>8.3} {:>9.2e} {:>10} {:>10} {:>10.5} {:>9.5} {:>8.1e} {:>9.3}",
        r.scene,
        r.pair,
        r.mesh_size,
        r.triangles,
        r.dofs,
        r.iterations,
        r.seconds,
        r.alpha,
        opt(r.error_l2),
        opt(r.error_h1),
        r.total_contact_force,
        r.contact_area,
        r.complementarity_residual,
        r.inverse_constant
    );
}

fn default_job(out: &Path) -> Result<(), String> {
    println!("fem-forms: default beam scenes (clamped on (0,1), 256 elements, nested semismooth Newton)\n");
    table_header();
    for s in SCENES {
        for q in [1.0, 100.0] {
            let mut request = Request::new(s);
            request.load = q;
            let (report, profiles) =
                beams::solve(&request).map_err(|e| format!("{}: {e}", s.name))?;
            table_row(&report);
            let path = out.join(format!("{}-q{q}.svg", s.name));
            plot::profiles(&path, &format!("{} q = {q}", s.name), &profiles)
                .map_err(|e| format!("{}: {e}", path.display()))?;
        }
    }
    println!(
        "\nplots of w, θ, λ, ψ: {}/<scene>-q<q>.svg\n",
        out.display()
    );
    for study in studies::Study::DEFAULT {
        studies::run(study, false, out).map_err(|e| format!("study {study:?}: {e}"))?;
    }
    membrane_job(out)
}

/// The membrane part of the default job: every pair on the radial scene, each scene at
/// the cheapest pair and mesh that reach its asked accuracy, VTK files, the studies.
fn membrane_job(out: &Path) -> Result<(), String> {
    println!("\nfem-forms: membrane scenes (N×N×2 triangles, nested semismooth Newton)\n");
    membrane_header();
    let radial = membrane_scene("membrane-radial").expect("the scene exists");
    for pair in MembranePair::ALL {
        let mut request = MembraneRequest::new(radial);
        request.pair = pair;
        match membranes::solve(&request) {
            Ok((report, _)) => membrane_row(&report),
            Err(e) => println!("{:<16} {:<8} not solved: {e}", radial.name, pair.name()),
        }
    }
    std::fs::create_dir_all(out).map_err(|e| e.to_string())?;
    for scene in MEMBRANE_SCENES {
        let (rungs, cheapest) = membranes::cheapest_for_accuracy(&scene, &MembranePair::ALL)
            .map_err(|e| format!("{}: {e}", scene.name))?;
        println!(
            "\n{}: the coarsest mesh of each pair with estimated ‖u − u_h‖_L2 ≤ {:.0e} (Richardson estimate against N×2{})",
            scene.name,
            scene.target_l2,
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
                    ""
                } else {
                    "  (not reached by N = 512)"
                },
                if Some(k) == cheapest {
                    "  ← cheapest"
                } else {
                    ""
                }
            );
        }
        if let Some(k) = cheapest {
            let mut request = MembraneRequest::new(scene);
            request.pair = MembranePair::parse(&rungs[k].pair).map_err(|e| e.to_string())?;
            request.mesh_size = rungs[k].mesh_size;
            let (_, fields) = membranes::solve(&request).map_err(|e| e.to_string())?;
            let path = out.join(format!("{}.vtu", scene.name));
            membranes::write_vtk(&path, &fields).map_err(|e| e.to_string())?;
            println!(
                "  → {} (u, ψ, λ_h, contact set for ParaView)",
                path.display()
            );
        }
    }
    println!();
    for study in MembraneStudy::ALL {
        membrane_studies::run(study, false, out)
            .map_err(|e| format!("membrane study {study:?}: {e}"))?;
    }
    Ok(())
}

fn run(cli: Cli) -> Result<(), String> {
    match cli.command {
        None => default_job(&cli.out),
        Some(Command::List) => {
            println!("scenes:");
            for s in SCENES {
                println!("  {:<15} {}", s.name, s.description);
            }
            println!("pairs:");
            for p in Pair::ALL {
                println!(
                    "  {:<17} {:?} (default α = {})",
                    p.name(),
                    p.beam(),
                    p.default_alpha()
                );
            }
            println!("membrane scenes (--mesh-size N, or --msh FILE):");
            for s in MEMBRANE_SCENES.iter().chain([&MEMBRANE_FLAT]) {
                println!("  {:<17} {}", s.name, s.description);
            }
            println!(
                "membrane pairs (default p2-p0; α = ½/C_I, or {} where C_I = 0):",
                membranes::ALPHA_WHEN_CI_VANISHES
            );
            for p in MembranePair::ALL {
                println!("  {}", p.name());
            }
            Ok(())
        }
        Some(Command::Solve {
            scene: name,
            mesh_size,
            alpha,
            pair,
            solver,
            cold,
            json,
            vtk,
            msh,
            ..
        }) if membrane_scene(&name).is_some() => {
            let scene = membrane_scene(&name).expect("checked");
            let mut request = MembraneRequest::new(scene);
            request.mesh_size = mesh_size.unwrap_or(if msh.is_some() { 0 } else { 64 });
            request.mesh_file = msh;
            request.alpha = alpha;
            if let Some(p) = pair {
                request.pair = MembranePair::parse(&p).map_err(|e| e.to_string())?;
            }
            request.solver = match solver {
                SolverName::Pdas => VariationalSolver::SemismoothNewton,
                SolverName::Clarabel => VariationalSolver::Clarabel,
            };
            request.nested = !cold;
            let (report, fields) = membranes::solve(&request).map_err(|e| e.to_string())?;
            if json {
                println!(
                    "{}",
                    serde_json::to_string_pretty(&report).map_err(|e| e.to_string())?
                );
            } else {
                membrane_header();
                membrane_row(&report);
            }
            if vtk {
                let path = cli.out.join(format!(
                    "{}-{}-{}.vtu",
                    scene.name, report.pair, request.mesh_size
                ));
                std::fs::create_dir_all(&cli.out).map_err(|e| e.to_string())?;
                membranes::write_vtk(&path, &fields).map_err(|e| e.to_string())?;
                eprintln!("→ {}", path.display());
            }
            Ok(())
        }
        Some(Command::Solve {
            scene: name,
            elements,
            load,
            thickness,
            alpha,
            pair,
            solver,
            cold,
            refinement,
            json,
            plot: write_plot,
            ..
        }) => {
            let s = scene(&name).ok_or_else(|| {
                format!(
                    "unknown scene `{name}`; the scenes are {}",
                    SCENES
                        .iter()
                        .map(|s| s.name)
                        .chain(MEMBRANE_SCENES.iter().map(|s| s.name))
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            })?;
            let pair = pair
                .map(|p| Pair::parse(&p, s.beam))
                .transpose()
                .map_err(|e| e.to_string())?;
            let request = Request {
                scene: s,
                elements,
                load,
                thickness,
                alpha,
                pair,
                solver: match solver {
                    SolverName::Pdas => VariationalSolver::SemismoothNewton,
                    SolverName::Clarabel => VariationalSolver::Clarabel,
                },
                nested_from: (!cold).then_some(16),
                refinement_steps: refinement,
                plain: false,
            };
            let (report, profiles) = beams::solve(&request).map_err(|e| e.to_string())?;
            if json {
                println!(
                    "{}",
                    serde_json::to_string_pretty(&report).map_err(|e| e.to_string())?
                );
            } else {
                table_header();
                table_row(&report);
            }
            if write_plot {
                let path = cli.out.join(format!("{}-q{load}.svg", s.name));
                plot::profiles(&path, &format!("{} q = {load}", s.name), &profiles)
                    .map_err(|e| e.to_string())?;
            }
            Ok(())
        }
        Some(Command::Study { study, kind, full }) => {
            if study == "membrane-radial" {
                let kinds = kind.map_or(MembraneStudy::ALL.to_vec(), |k| vec![k]);
                for k in kinds {
                    membrane_studies::run(k, full, &cli.out).map_err(|e| e.to_string())?;
                }
                return Ok(());
            }
            if kind.is_some() {
                return Err(format!(
                    "`{study}` takes no second argument (only membrane-radial does)"
                ));
            }
            let beam_study = <studies::Study as ValueEnum>::from_str(&study, true).map_err(|_| {
                format!(
                    "unknown study `{study}`; the studies are {} and membrane-radial convergence|stability|alpha",
                    studies::Study::DEFAULT
                        .iter()
                        .filter_map(|s| s.to_possible_value().map(|v| v.get_name().to_string()))
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            })?;
            studies::run(beam_study, full, &cli.out).map_err(|e| e.to_string())
        }
    }
}

// The solvers allocate and drop large vectors at every level and iteration; glibc
// returns each to the kernel and pays page faults for the next. mimalloc keeps them:
// the membrane VI solve at 524k triangles takes 2.1–2.3 s instead of 3.0 s.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() -> ExitCode {
    fem_forms::lcp::cholesky::factor_sequentially();
    fem_forms::allocator::retain_freed_memory();
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
