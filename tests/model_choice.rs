//! The choice of model, pair and mesh for a tolerance (`fem_forms::models::choice`):
//! the modelling estimate against the distance of the two models' fine solutions, and
//! the chosen solution's true error against a fine reference of the scene's own model,
//! both measured in the richer model's energy norm by quadrature on the union of the
//! two meshes (independent of the estimators the choice uses).

use fem_forms::adaptivity::AdaptiveOptions;
use fem_forms::models::report::{Outcome, Settings};
use fem_forms::models::scene::{Adjustment, Scene, Support};
use fem_forms::models::{choice, families};
use fem_forms::obstacle::ObstacleSolution;
use fem_forms::IntervalMesh;

/// A beam solution as a Timoshenko pair (θ, θ', γ) at x: an Euler–Bernoulli deflection
/// as θ = w′ with no shear; the one-point shear of the reduced P1 pair at its cell's
/// midpoint (the strain its energy holds).
fn timoshenko_jet(outcome: &Outcome, x: f64) -> [f64; 3] {
    let kept = outcome.solution.as_ref().expect("kept solution");
    let solution = kept
        .solution
        .downcast_ref::<ObstacleSolution<IntervalMesh>>()
        .expect("a beam solution");
    let field = |name: &str| kept.fields.iter().position(|f| *f == name).unwrap();
    let w = solution.view(field("w"));
    match kept.fields.iter().position(|f| *f == "θ") {
        None => [w.at(x, 1).unwrap(), w.at(x, 2).unwrap(), 0.0],
        Some(theta) => {
            let theta = solution.view(theta);
            let at = if outcome.report.pair == "p1-p1-p0-reduced" {
                let mesh = &solution.discretization.mesh;
                let [a, b] = mesh.cell(mesh.locate(x).unwrap());
                0.5 * (a + b)
            } else {
                x
            };
            [
                theta.at(x, 0).unwrap(),
                theta.at(x, 1).unwrap(),
                w.at(at, 1).unwrap() - theta.at(at, 0).unwrap(),
            ]
        }
    }
}

/// The cells' ends of a beam solution.
fn breakpoints(outcome: &Outcome) -> Vec<f64> {
    let kept = outcome.solution.as_ref().unwrap();
    let solution = kept
        .solution
        .downcast_ref::<ObstacleSolution<IntervalMesh>>()
        .unwrap();
    solution.discretization.mesh.vertices().to_vec()
}

/// `(‖u_a − u_b‖, ‖u_b‖)` in the Timoshenko energy norm `∫ θ′² + t⁻² ∫ γ²`, by a
/// 5-point Gauss rule on each interval of the union of the two meshes.
fn timoshenko_distance(a: &Outcome, b: &Outcome, t: f64) -> (f64, f64) {
    let mut points = breakpoints(a);
    points.extend(breakpoints(b));
    points.sort_by(f64::total_cmp);
    points.dedup_by(|x, y| (*x - *y).abs() < 1e-14);
    let rule = fem_forms::gauss_legendre(5);
    let (mut distance, mut norm) = (0.0, 0.0);
    for pair in points.windows(2) {
        let (x0, x1) = (pair[0], pair[1]);
        for (&xi, &weight) in rule.points.iter().zip(&rule.weights) {
            // inside the interval, away from the breakpoints where a jet jumps
            let x = x0 + (x1 - x0) * xi;
            let [_, da, ga] = timoshenko_jet(a, x);
            let [_, db, gb] = timoshenko_jet(b, x);
            let dx = weight * (x1 - x0);
            distance += dx * ((da - db).powi(2) + (ga - gb).powi(2) / (t * t));
            norm += dx * (db * db + gb * gb / (t * t));
        }
    }
    (distance.sqrt(), norm.sqrt())
}

fn scene(name: &str) -> Scene {
    families::scene(name).unwrap_or_else(|| panic!("scene {name}"))
}

fn settings(pair: Option<&str>, elements: Option<usize>, t: Option<f64>) -> Settings {
    Settings {
        pair: pair.map(str::to_string),
        mesh_size: elements,
        parameters: t.map(|t| vec![("t".into(), t)]).unwrap_or_default(),
        keep_solution: true,
        ..Settings::default()
    }
}

/// The fine Timoshenko P2 solution of `scene` at thickness t: the reference.
fn reference(scene: &Scene, t: f64, elements: usize) -> Outcome {
    families::solve(scene, &settings(Some("p2-p2-p0"), Some(elements), Some(t))).unwrap()
}

#[test]
fn the_euler_bernoulli_modelling_estimate_is_the_distance_of_the_two_beams() {
    let thick = scene("timoshenko-t1e-2");
    let family = families::family("beam").unwrap();
    for t in [1e-1, 1e-2, 1e-3, 1e-4] {
        let mut posed = thick.clone();
        posed.parameters = vec![("t".into(), t)];
        let thin = family.cheaper(&posed).unwrap();
        let bernoulli = families::solve(&thin, &settings(None, Some(1024), None)).unwrap();
        let estimate = bernoulli.report.number("modelling_estimate").unwrap();
        // λ concentrates in layers of width t at the contact's ends: an adaptive
        // reference resolves them, where t⁻²h⁻² rounding forbids uniform meshes fine
        // enough (docs/mathematics.md §3)
        let request = Settings {
            adaptive: Some(AdaptiveOptions {
                tolerance: 1e-3,
                ..AdaptiveOptions::default()
            }),
            ..settings(Some("p2-p2-p0"), None, Some(t))
        };
        let timoshenko = families::solve(&posed, &request).unwrap();
        let uncertainty = timoshenko.report.solve.estimate.unwrap();
        let (distance, norm) = timoshenko_distance(&bernoulli, &timoshenko, t);
        let ratio = estimate / distance;
        println!(
            "t = {t:e}: estimate {estimate:.4e}, distance {distance:.4e} ({:.3e} of ‖u‖), ratio {ratio:.4}, reference's estimate {uncertainty:.1e}",
            distance / norm
        );
        // reliable (the hypercircle bound) and asymptotically exact as t → 0, up to the
        // reference's own error
        assert!(
            estimate >= distance - uncertainty && estimate <= 1.15 * distance + uncertainty,
            "t = {t}: ratio {ratio}"
        );
        if (1e-3..=1e-2).contains(&t) {
            assert!((0.99..1.02).contains(&ratio), "t = {t}: ratio {ratio}");
        }
    }
}

#[test]
fn the_chosen_beam_is_within_the_tolerance_of_the_timoshenko_reference() {
    for (name, t) in [
        ("timoshenko-t1e-1", 1e-1),
        ("timoshenko-t1e-2", 1e-2),
        ("timoshenko-t1e-3", 1e-3),
    ] {
        let scene = scene(name);
        let reference = reference(&scene, t, 2048);
        for tolerance in [5e-2, 1e-2, 2e-3] {
            let request = Settings {
                adaptive: Some(AdaptiveOptions {
                    tolerance,
                    ..AdaptiveOptions::default()
                }),
                ..settings(None, None, None)
            };
            let chosen = choice::solve(&scene, &request).unwrap();
            let model = chosen.report.quantities["chosen_model"].as_str().unwrap();
            let (distance, norm) = timoshenko_distance(&chosen, &reference, t);
            println!(
                "{name}, T = {tolerance:e}: {model} {} with {} unknowns, true error {:.3e}",
                chosen.report.pair,
                chosen.report.solve.dofs,
                distance / norm
            );
            assert!(distance / norm <= tolerance, "{name}, T = {tolerance}");
            // the modelling error of Euler–Bernoulli is about 9.4 t of ‖u‖ here: adequate
            // (at most half of T) for the thin beam at the loosest tolerance alone
            let thin = t == 1e-3 && tolerance == 5e-2;
            assert_eq!(model == "Euler–Bernoulli", thin, "{name}, T = {tolerance}");
            let candidates = chosen.report.quantities["candidates"].as_array().unwrap();
            assert_eq!(candidates.len(), 4, "three Timoshenko pairs and Hermite");
            assert_eq!(candidates.iter().filter(|c| c["chosen"] == true).count(), 1);
        }
    }
}

#[test]
fn a_pair_given_fixes_the_model_and_the_pair() {
    let scene = scene("timoshenko-t1e-3");
    let request = Settings {
        adaptive: Some(AdaptiveOptions {
            tolerance: 5e-2,
            ..AdaptiveOptions::default()
        }),
        ..settings(Some("p2-p2-p0"), None, None)
    };
    let outcome = choice::solve(&scene, &request).unwrap();
    assert_eq!(outcome.report.pair, "p2-p2-p0");
    assert!(!outcome.report.quantities.contains_key("chosen_model"));
}

#[test]
fn a_pair_of_the_cheaper_model_solves_that_model() {
    // Euler–Bernoulli's pair on a Timoshenko scene, Kirchhoff's on a Reissner–Mindlin one:
    // the cheaper model is solved, said so, with its modelling estimate, and its answer is
    // that of the cheaper model's scene solved directly
    for (name, pair, size) in [
        ("timoshenko-t1e-3", "hermite-p0", 64),
        ("mindlin-ss-t1e-3", "argyris-p0", 8),
    ] {
        let rich = scene(name);
        let outcome = choice::solve(&rich, &settings(Some(pair), Some(size), None))
            .unwrap_or_else(|e| panic!("{name} with {pair}: {e}"));
        assert_eq!(outcome.report.pair, pair);
        assert!(
            outcome.report.quantities.contains_key("chosen_model"),
            "{name}"
        );
        let modelling = outcome.report.number("modelling_estimate_relative");
        assert!(modelling.is_some_and(|m| m > 0.0), "{name}: {modelling:?}");
        let family = families::family(rich.family).unwrap();
        let thin = family.cheaper(&rich).unwrap();
        let direct = families::solve(&thin, &settings(Some(pair), Some(size), None)).unwrap();
        let (a, b) = (outcome.report.solve.energy, direct.report.solve.energy);
        assert_eq!(a, b, "{name}: the cheaper model's own solve");
        assert!(choice::neighbour_pair(&rich, "no-such-pair").is_none());
    }
    // the scene's own pair is not the cheaper model's
    assert!(choice::neighbour_pair(&scene("timoshenko-t1e-3"), "p2-p2-p0").is_none());
}

#[test]
fn a_tolerance_without_a_choice_starts_from_the_probes_coarse_mesh() {
    // bernoulli-flat has one model and one pair: a tolerance refines adaptively, from the
    // probes' 16 elements rather than the scene's 256 (a loose T wants fewer)
    let flat = scene("bernoulli-flat");
    assert!(!choice::has_choice(&flat));
    let request = Settings {
        load: Some(100.0),
        adaptive: Some(AdaptiveOptions {
            tolerance: 5e-2,
            ..AdaptiveOptions::default()
        }),
        ..Settings::default()
    };
    let outcome = choice::solve(&flat, &request).unwrap();
    let levels = &outcome.report.solve.adaptive_levels;
    assert_eq!(
        levels.first().map(|l| l.cells),
        Some(choice::probe_sizes(&flat, None)[0])
    );
    let last = levels.last().unwrap();
    assert!(last.estimate <= 5e-2 * last.energy_norm, "{last:?}");
    assert!(last.cells < flat.mesh_size, "{} cells", last.cells);
}

/// The Kirchhoff plate of a Reissner–Mindlin scene at thickness t (its cheaper model).
fn kirchhoff_of(name: &str, t: f64, adjust: Option<Adjustment>) -> Scene {
    let plates = families::family("plate").unwrap();
    let mut posed = scene(name);
    if let Some(adjustment) = adjust {
        plates.adjust(&mut posed, &adjustment).unwrap();
    }
    for (n, v) in &mut posed.parameters {
        if &**n == "t" {
            *v = t;
        }
    }
    plates.cheaper(&posed).unwrap()
}

#[test]
fn the_soft_simple_supports_layer_keeps_a_thin_plate_from_kirchhoff() {
    let mut layers = Vec::new();
    for t in [1e-1, 1e-2, 1e-3, 1e-4] {
        let soft = kirchhoff_of("mindlin-ss-t1e-2", t, None);
        let outcome =
            families::solve(&soft, &settings(Some("argyris-p0"), Some(16), None)).unwrap();
        let shear = outcome.report.number("modelling_estimate_shear").unwrap();
        let layer = outcome.report.number("modelling_estimate_layer").unwrap();
        println!("t = {t:e}: shear {shear:.4e}, layer {layer:.4e}");
        // the layer's energy is of order t, the shear's t²: the layer dominates thin plates
        assert!(layer > shear, "t = {t}");
        layers.push(layer);
    }
    for pair in layers.windows(2) {
        let ratio = pair[0] / pair[1];
        assert!((ratio / 10f64.sqrt() - 1.0).abs() < 1e-9, "ratio {ratio}");
    }
    // at t = 0.001 and T = 5 %: Kirchhoff is adequate clamped (its modelling error is
    // the shear's, ~1e-3 of ‖u‖) and not on the soft support (the layer's, ~3 %)
    let request = Settings {
        adaptive: Some(AdaptiveOptions {
            tolerance: 5e-2,
            ..AdaptiveOptions::default()
        }),
        ..Settings::default()
    };
    let plates = families::family("plate").unwrap();
    for (support, kirchhoff_adequate) in [
        (Support::Clamped, true),
        (Support::SimplySupported { hard: false }, false),
    ] {
        let mut scene = scene("mindlin-ss-t1e-3");
        plates
            .adjust(&mut scene, &Adjustment::Support(support))
            .unwrap();
        let candidates = choice::candidates(&scene, &request, 5e-2).unwrap();
        for c in candidates.iter().filter(|c| c.model == "Kirchhoff") {
            println!(
                "{support:?}: {} {:.3e} {}",
                c.pair, c.modelling_estimate, c.note
            );
            assert_eq!(
                c.modelling_estimate <= 0.5 * 5e-2,
                kirchhoff_adequate,
                "{support:?}"
            );
        }
    }
}

#[test]
fn the_work_precision_chart_has_every_candidate_and_the_choice_within_t() {
    let scene = scene("timoshenko-t1e-3");
    let study = fem_forms::choice_study::work_precision(&scene, false).unwrap();
    for pair in [
        "p2-p2-p0",
        "p1-p1-p0-reduced",
        "p1-p1-p0-full",
        "hermite-p0",
    ] {
        assert!(
            study
                .curves
                .iter()
                .any(|c| c.label.ends_with(&format!("{pair} uniform")) && c.points.len() == 4),
            "{pair}"
        );
    }
    assert!(
        !study.true_error,
        "a scene with a cheaper model charts the bound"
    );
    assert_eq!(study.marks.len(), 3);
    for mark in &study.marks {
        assert!(mark.point.bound <= mark.tolerance, "{mark:?}");
    }
    assert!(study.marks[0].chosen.starts_with("Euler–Bernoulli"));
    // the chart and its numbers: one row per point and per choice
    let out = std::env::temp_dir().join(format!("model-choice-{}", std::process::id()));
    fem_forms::choice_study::run(&scene, false, &out).unwrap();
    let csv =
        std::fs::read_to_string(fem_forms::choice_study::output(&out, &scene.name, "csv")).unwrap();
    let svg =
        std::fs::read_to_string(fem_forms::choice_study::output(&out, &scene.name, "svg")).unwrap();
    let _ = std::fs::remove_dir_all(&out);
    let points: usize = study.curves.iter().map(|c| c.points.len()).sum();
    // a second run's adaptive levels are the same meshes: the row count is fixed
    assert_eq!(csv.lines().count(), 1 + points + study.marks.len());
    assert!(svg.contains("choice at T = 1e-1: Euler–Bernoulli hermite-p0"));
}

/// `fem-forms ARGS --out DIR` run in a directory of its own (removed after).
fn fem_forms(args: &[&str], tag: &str) -> std::process::Output {
    let out = std::env::temp_dir().join(format!("model-choice-{tag}-{}", std::process::id()));
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_fem-forms"))
        .args(args)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let _ = std::fs::remove_dir_all(&out);
    output
}

/// The report of `fem-forms ARGS --json`.
fn json_of(args: &[&str]) -> serde_json::Value {
    let output = fem_forms(args, "cli");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    serde_json::from_slice(&output.stdout).unwrap()
}

#[test]
fn the_command_line_and_a_scene_file_tolerance_choose() {
    let report = json_of(&["solve", "timoshenko-t1e-3", "--tol", "5e-2", "--json"]);
    assert_eq!(report["chosen_model"], "Euler–Bernoulli");
    assert_eq!(report["chosen_pair"], "hermite-p0");
    assert_eq!(report["pair"], "hermite-p0");
    assert_eq!(report["scene"], "timoshenko-t1e-3");
    let candidates = report["candidates"].as_array().unwrap();
    assert_eq!(candidates.len(), 4);
    for c in candidates {
        for key in [
            "model",
            "pair",
            "probe",
            "modelling_estimate",
            "discretization_target",
            "predicted_seconds",
            "adequate",
            "chosen",
            "note",
        ] {
            assert!(c.get(key).is_some(), "{key} in {c}");
        }
    }
    let chosen = candidates.iter().find(|c| c["chosen"] == true).unwrap();
    assert!(chosen["actual_seconds"].as_f64().unwrap() > 0.0);
    // `--pair` fixes the pair: no choice
    let fixed = json_of(&[
        "solve",
        "timoshenko-t1e-3",
        "--tol",
        "5e-2",
        "--pair",
        "p2-p2-p0",
        "--json",
    ]);
    assert!(fixed.get("chosen_model").is_none());
    assert_eq!(fixed["pair"], "p2-p2-p0");

    // a scene file's `tol` without `pair`: the membrane's pairs are weighed
    let example = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/membrane-lshape.toml"
    ))
    .unwrap()
    .replace("model = \"membrane\"", "model = \"membrane\"\ntol = 0.05");
    let file = std::env::temp_dir().join(format!("lshape-tol-{}.toml", std::process::id()));
    std::fs::write(&file, example).unwrap();
    let report = json_of(&["solve", "--scene", file.to_str().unwrap(), "--json"]);
    let _ = std::fs::remove_file(&file);
    assert_eq!(report["chosen_model"], "membrane");
    assert!(report["candidates"].as_array().unwrap().len() >= 3);
    let target = report["candidates"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["chosen"] == true)
        .unwrap()["discretization_target"]
        .as_f64()
        .unwrap();
    // solved adaptively, or on the probe's finer mesh where that already reaches it
    assert!(report["estimate_relative"].as_f64().unwrap() <= target);
}

/// The longest edge of a triangle given as `[x₀, y₀, x₁, y₁, x₂, y₂]`: the `h_T` of the
/// Stenberg weight.
fn longest_edge(x: &[f64]) -> f64 {
    (0..3)
        .map(|k| {
            let (a, b) = (k, (k + 1) % 3);
            (x[2 * a] - x[2 * b]).hypot(x[2 * a + 1] - x[2 * b + 1])
        })
        .fold(0.0, f64::max)
}

/// `∫ |Q_h|² / S` of a Reissner–Mindlin solution: its discrete shear force
/// `Q_h = S_T (∇w_h − θ_h)` with the Stenberg weight `S_T = 6κ(1−ν)D/(t² + β h_T²)`
/// (h_T the longest edge), against the physical shear stiffness `S = 6κ(1−ν)D/t²`: the
/// Mindlin solution's own shear energy, the leading-order distance to the Kirchhoff
/// solution where no boundary layer forms.
fn mindlin_shear_energy(outcome: &Outcome, [d, nu, kappa, t, beta]: [f64; 5]) -> f64 {
    use fem_forms::element::triangle::{AffineMap, TriangleBasis};
    use fem_forms::TriangleMesh;
    let kept = outcome.solution.as_ref().unwrap();
    let solution = kept
        .solution
        .downcast_ref::<ObstacleSolution<TriangleMesh>>()
        .unwrap();
    let field = |name: &str| {
        let k = kept
            .fields
            .iter()
            .position(|f| *f == name)
            .unwrap_or_else(|| panic!("{name} in {:?}", kept.fields));
        solution.view(k)
    };
    let (theta_x, theta_y, w) = (field("θ_x"), field("θ_y"), field("w"));
    let (bx, by, bw) = (
        TriangleBasis::new(theta_x.map.element()),
        TriangleBasis::new(theta_y.map.element()),
        TriangleBasis::new(w.map.element()),
    );
    let mesh = w.mesh;
    let rule = fem_forms::reference::triangle::TriangleRule::exact_for_degree(4);
    let physical = 6.0 * kappa * (1.0 - nu) * d / (t * t);
    let mut energy = 0.0;
    for c in 0..mesh.cell_count() {
        let map = AffineMap::of(mesh, c);
        let x = mesh.cell_coordinates(c);
        let h = longest_edge(&x);
        let stenberg = 6.0 * kappa * (1.0 - nu) * d / (t * t + beta * h * h);
        for (&xi, &weight) in rule.points.iter().zip(&rule.weights) {
            let g = w.gradient(&bw, &map, c, xi);
            let gamma = [
                g[0] - theta_x.value(&bx, c, xi),
                g[1] - theta_y.value(&by, c, xi),
            ];
            let q2 = stenberg * stenberg * (gamma[0] * gamma[0] + gamma[1] * gamma[1]);
            energy += weight * map.det * q2 / physical;
        }
    }
    energy.sqrt()
}

#[test]
fn the_kirchhoff_shear_estimate_is_the_mindlin_solutions_shear_energy() {
    let plates = families::family("plate").unwrap();
    let (d, nu, kappa, beta) = (1.0, 0.3, 5.0 / 6.0, 0.1);
    for t in [1e-1, 1e-2, 1e-3, 1e-4] {
        // clamped: the rotations are held, no boundary layer
        let mut posed = scene("mindlin-square");
        for (n, v) in &mut posed.parameters {
            if &**n == "t" {
                *v = t;
            }
        }
        let mindlin = families::solve(&posed, &settings(Some("p1-p2-p0"), Some(64), None)).unwrap();
        let thin = plates.cheaper(&posed).unwrap();
        let kirchhoff =
            families::solve(&thin, &settings(Some("argyris-p0"), Some(32), None)).unwrap();
        let estimate = kirchhoff.report.number("modelling_estimate_shear").unwrap();
        let layer = kirchhoff.report.number("modelling_estimate_layer").unwrap();
        let shear = mindlin_shear_energy(&mindlin, [d, nu, kappa, t, beta]);
        println!(
            "t = {t:e}: estimate {estimate:.4e}, Mindlin's shear energy {shear:.4e}, ratio {:.4}",
            estimate / shear
        );
        assert_eq!(layer, 0.0);
        // the Stenberg shear force of a mesh with h ≫ t differs from Kirchhoff's by 8 %
        // in L² at t ≤ 1e-3, on 64×64 as on 32×32 (likely the shear force's layer of
        // width t at the clamped edges, which such meshes do not resolve), against
        // 0.6 % at t = 1e-2
        let within = if t >= 1e-2 { 0.05 } else { 0.1 };
        assert!((estimate / shear - 1.0).abs() < within, "t = {t}");
    }
}

/// The Reissner–Mindlin energy norm of the difference of a Mindlin and a Kirchhoff
/// solution (on the Mindlin solution's mesh, the Kirchhoff one evaluated where it lies
/// on its own): the bending part `∫ C(ε(θ_h) − ∇∇w_K) : (ε(θ_h) − ∇∇w_K)`
/// and the shear part [`mindlin_shear_energy`] (the Kirchhoff shear strain is 0).
fn mindlin_kirchhoff_distance(mindlin: &Outcome, kirchhoff: &Outcome, parameters: [f64; 5]) -> f64 {
    use fem_forms::element::triangle::{AffineMap, TriangleBasis};
    use fem_forms::TriangleMesh;
    let [d, nu, ..] = parameters;
    fn solution_of(o: &Outcome) -> (Vec<&'static str>, &ObstacleSolution<TriangleMesh>) {
        let kept = o.solution.as_ref().unwrap();
        let s = kept
            .solution
            .downcast_ref::<ObstacleSolution<TriangleMesh>>()
            .unwrap();
        (kept.fields.clone(), s)
    }
    let (m_fields, m) = solution_of(mindlin);
    let (k_fields, k) = solution_of(kirchhoff);
    let at = |fields: &[&str], name: &str| fields.iter().position(|f| *f == name).unwrap();
    let (theta_x, theta_y) = (m.view(at(&m_fields, "θ_x")), m.view(at(&m_fields, "θ_y")));
    let w = k.view(at(&k_fields, "w"));
    let (bx, by, bw) = (
        TriangleBasis::new(theta_x.map.element()),
        TriangleBasis::new(theta_y.map.element()),
        TriangleBasis::new(w.map.element()),
    );
    // on other meshes (an adapted Mindlin mesh, a uniform Kirchhoff one) the Kirchhoff
    // Hessian at each quadrature point of the Mindlin mesh, from the cell that holds it
    let same = theta_x.mesh.vertices() == w.mesh.vertices();
    let locator = fem_forms::PointLocator::new(w.mesh);
    let mut hint = None;
    let mut hessian_at = |c: usize, xi: [f64; 2], map: &AffineMap| {
        if same {
            return w.hessian(&bw, map, c, xi);
        }
        let x = theta_x.mesh.cell_coordinates(c);
        let p = [
            x[0] + (x[2] - x[0]) * xi[0] + (x[4] - x[0]) * xi[1],
            x[1] + (x[3] - x[1]) * xi[0] + (x[5] - x[1]) * xi[1],
        ];
        let (cell, b) = locator.locate_or_nearest(p, hint).expect("a cell");
        hint = Some(cell);
        w.hessian(&bw, &AffineMap::of(w.mesh, cell), cell, [b[1], b[2]])
    };
    let rule = fem_forms::reference::triangle::TriangleRule::exact_for_degree(6);
    let mut bending = 0.0;
    for c in 0..theta_x.mesh.cell_count() {
        let map = AffineMap::of(theta_x.mesh, c);
        for (&xi, &weight) in rule.points.iter().zip(&rule.weights) {
            let gx = theta_x.gradient(&bx, &map, c, xi);
            let gy = theta_y.gradient(&by, &map, c, xi);
            let h = hessian_at(c, xi, &map);
            let shear = 0.5 * (gx[1] + gy[0]);
            let e = [
                [gx[0] - h[0][0], shear - h[0][1]],
                [shear - h[1][0], gy[1] - h[1][1]],
            ];
            let trace = e[0][0] + e[1][1];
            let contraction = e[0][0] * e[0][0] + 2.0 * e[0][1] * e[1][0] + e[1][1] * e[1][1];
            bending += weight * map.det * d * ((1.0 - nu) * contraction + nu * trace * trace);
        }
    }
    bending.hypot(mindlin_shear_energy(mindlin, parameters))
}

#[test]
fn the_kirchhoff_modelling_estimate_is_the_soft_supported_plates_distance() {
    let plates = families::family("plate").unwrap();
    let (d, nu, kappa, beta) = (1.0, 0.3, 5.0 / 6.0, 0.1);
    for (t, n) in [(1e-1, 64), (3e-2, 128)] {
        let mut posed = scene("mindlin-square-ss");
        for (name, v) in &mut posed.parameters {
            if &**name == "t" {
                *v = t;
            }
        }
        let mindlin = families::solve(&posed, &settings(Some("p1-p2-p0"), Some(n), None)).unwrap();
        let thin = plates.cheaper(&posed).unwrap();
        let kirchhoff =
            families::solve(&thin, &settings(Some("argyris-p0"), Some(n), None)).unwrap();
        let estimate = kirchhoff.report.number("modelling_estimate").unwrap();
        let layer = kirchhoff.report.number("modelling_estimate_layer").unwrap();
        let distance = mindlin_kirchhoff_distance(&mindlin, &kirchhoff, [d, nu, kappa, t, beta]);
        let shear = (estimate * estimate - layer * layer).sqrt();
        println!(
            "t = {t:e}, N = {n}: estimate {estimate:.4e} (layer {layer:.4e}), distance {distance:.4e}, ratio {:.4}",
            estimate / distance
        );
        // the shear alone misses the layer's energy (0.75 and 0.51 of the distance) ...
        assert!(shear < 0.8 * distance, "t = {t}");
        // ... which the layer term brings back, from above: 1.22 and 1.31 (at t = 3e-2
        // the layer, of width t/√10, is not resolved by h = 1/128, and the Mindlin
        // solution's distance falls short of the true one)
        assert!((1.0..1.4).contains(&(estimate / distance)), "t = {t}");
    }
}

/// The soft simply supported square at thickness `t`: the Kirchhoff plate's modelling
/// estimate over its distance to the Mindlin plate solved adaptively to `tolerance`
/// (refined along the edges to the layer's width t/√10 where `resolve_layer`, at most
/// `max_dofs` unknowns), with the Mindlin solve's unknowns.
fn layer_estimate_over_distance(
    t: f64,
    tolerance: f64,
    resolve_layer: bool,
    max_dofs: usize,
) -> (f64, usize) {
    // below t = 3e-2 a uniform mesh does not resolve the layer of width t/√10: the
    // Mindlin plate solved adaptively (the estimator refines along the edges), the
    // Kirchhoff plate on a uniform mesh (Argyris: 4e-4 of the norm at N = 16)
    let plates = families::family("plate").unwrap();
    let (d, nu, kappa, beta) = (1.0, 0.3, 5.0 / 6.0, 0.1);
    let mut posed = scene("mindlin-square-ss");
    for (name, v) in &mut posed.parameters {
        if &**name == "t" {
            *v = t;
        }
    }
    posed.edge_resultants = resolve_layer;
    let adaptive = Settings {
        adaptive: Some(AdaptiveOptions {
            tolerance,
            max_dofs,
            ..AdaptiveOptions::default()
        }),
        ..settings(Some("p1-p2-p0"), Some(8), None)
    };
    let mindlin = families::solve(&posed, &adaptive).unwrap();
    let thin = plates.cheaper(&posed).unwrap();
    let kirchhoff = families::solve(&thin, &settings(Some("argyris-p0"), Some(32), None)).unwrap();
    let estimate = kirchhoff.report.number("modelling_estimate").unwrap();
    let layer = kirchhoff.report.number("modelling_estimate_layer").unwrap();
    let distance = mindlin_kirchhoff_distance(&mindlin, &kirchhoff, [d, nu, kappa, t, beta]);
    println!(
        "t = {t:e}: Mindlin {} unknowns, estimate {estimate:.4e} (layer {layer:.4e}), distance {distance:.4e}, ratio {:.4}",
        mindlin.report.solve.dofs,
        estimate / distance
    );
    (estimate / distance, mindlin.report.solve.dofs)
}

#[test]
fn the_layer_estimate_holds_for_thinner_soft_supported_plates() {
    for t in [1e-2, 3e-3, 1e-3] {
        // at t = 1e-3 the estimator alone leaves the layer (width 3.2e-4) under-resolved
        // at this tolerance; the edge resultants' request refines along it to its width
        let (ratio, _) = layer_estimate_over_distance(t, 1e-1, t < 2e-3, 2_000_000);
        // 1.37 at t = 1e-2 (the same to 0.2 % at T = 5e-2: the distance is converged),
        // 1.38 at 3e-3, and 1.38 at 1e-3 (434k unknowns, the layer resolved): an
        // estimate from above by a factor near √2 as t → 0
        assert!((1.0..1.5).contains(&ratio), "t = {t}");
    }
}

/// The same at t = 1e-4: the layer, of width 3.2e-5, resolved along the edges by 2.3
/// million unknowns (measured: 90 s and 3.5 GB, the longest test of the run; the ratio
/// 1.383, as at t = 1e-3).
#[test]
fn the_layer_estimate_holds_at_t_1e_4() {
    let (ratio, _) = layer_estimate_over_distance(1e-4, 1e-1, true, 4_000_000);
    assert!((1.0..1.5).contains(&ratio), "ratio {ratio}");
}

/// Asked for T, the choice's solve with a tolerance `tolerance` and no pair.
fn chosen(scene: &Scene, tolerance: f64, adjust: Option<Adjustment>) -> Outcome {
    let mut scene = scene.clone();
    if let Some(adjustment) = adjust {
        families::family(scene.family)
            .unwrap()
            .adjust(&mut scene, &adjustment)
            .unwrap();
    }
    let request = Settings {
        adaptive: Some(AdaptiveOptions {
            tolerance,
            ..AdaptiveOptions::default()
        }),
        ..Settings::default()
    };
    choice::solve(&scene, &request).unwrap()
}

#[test]
fn the_chosen_membrane_is_within_the_tolerance_of_the_exact_solution() {
    let radial = scene("membrane-radial");
    for tolerance in [5e-2, 1e-2] {
        let outcome = chosen(&radial, tolerance, None);
        let error = outcome.report.solve.error_energy_relative.unwrap();
        println!(
            "T = {tolerance:e}: {} with {} unknowns, true error {error:.3e}",
            outcome.report.pair, outcome.report.solve.dofs
        );
        assert!(error <= tolerance, "T = {tolerance}: {error}");
        let candidates = outcome.report.quantities["candidates"].as_array().unwrap();
        assert_eq!(candidates.len(), families::pairs_of(&radial).len());
    }
}

#[test]
fn the_chosen_kirchhoff_plate_is_within_the_tolerance_of_navier() {
    // the simply supported unit square under q = 1 (D = 1): Navier's series gives
    // ∫w = Σ_{m,n odd} 64 q / (π⁸ D m² n² (m² + n²)²), the energy J = −½ q ∫w and
    // ‖u‖_a² = q ∫w; for a conforming (Argyris) solution without contact
    // ‖u − u_h‖_a² = 2 (J_h − J), the energy identity of Galerkin's method
    let pi8 = std::f64::consts::PI.powi(8);
    let mut integral = 0.0;
    for m in (1..4000).step_by(2) {
        for n in (1..4000).step_by(2) {
            let (m, n) = (m as f64, n as f64);
            integral += 64.0 / (pi8 * m * m * n * n * (m * m + n * n).powi(2));
        }
    }
    let exact_energy = -0.5 * integral;
    let square = scene("kirchhoff-square");
    for tolerance in [1e-2, 1e-3] {
        let outcome = chosen(
            &square,
            tolerance,
            Some(Adjustment::Support(Support::SimplySupported {
                hard: false,
            })),
        );
        let pair = outcome.report.pair;
        assert!(
            pair.starts_with("argyris"),
            "{pair}: the identity needs a conforming pair"
        );
        let energy = outcome.report.solve.energy.unwrap();
        let error = (2.0 * (energy - exact_energy)).max(0.0).sqrt() / integral.sqrt();
        println!(
            "T = {tolerance:e}: {pair} with {} unknowns, true error {error:.3e}",
            outcome.report.solve.dofs
        );
        assert!(error <= tolerance, "T = {tolerance}: {error}");
    }
}

#[test]
fn the_chosen_winkler_plate_is_within_the_tolerance_of_navier() {
    // winkler-square without its obstacle: the simply supported unit square (D = 1) on a
    // foundation k = 100 under q = 1; Navier's series with the foundation,
    // w = Σ a_mn sin mπx sin nπy, a_mn = 16 q / (π² m n (D π⁴ (m² + n²)² + k)), gives
    // ∫w = Σ_{m,n odd} 64 q / (π⁴ m² n² (D π⁴ (m² + n²)² + k)) and ‖u‖_a² = q ∫w; the
    // energy identity of the conforming Argyris solve, ‖u − u_h‖_a² = 2 (J_h − J)
    let (pi, k) = (std::f64::consts::PI, 100.0);
    let mut integral = 0.0;
    for m in (1..4000).step_by(2) {
        for n in (1..4000).step_by(2) {
            let (m, n) = (m as f64, n as f64);
            integral +=
                64.0 / (pi.powi(4) * m * m * n * n * (pi.powi(4) * (m * m + n * n).powi(2) + k));
        }
    }
    let exact_energy = -0.5 * integral;
    for tolerance in [1e-2, 1e-3] {
        let outcome = chosen(
            &scene("winkler-square"),
            tolerance,
            Some(Adjustment::NoObstacle),
        );
        let energy = outcome.report.solve.energy.unwrap();
        let error = (2.0 * (energy - exact_energy)).max(0.0).sqrt() / integral.sqrt();
        println!(
            "T = {tolerance:e}: {} with {} unknowns, true error {error:.3e}",
            outcome.report.pair, outcome.report.solve.dofs
        );
        assert!(error <= tolerance, "T = {tolerance}: {error}");
        // the identity holds: a solve's energy is above the exact one
        assert!(energy >= exact_energy - 1e-15);
    }
}

#[test]
fn the_chosen_contact_pressure_is_the_patch_tests() {
    // signorini-patch: the block under a uniform pressure q is compressed uniformly, and
    // the exact contact pressure is q on every contact edge
    let outcome = chosen(&scene("signorini-patch"), 5e-2, None);
    let error = outcome.report.number("patch_pressure_error").unwrap();
    println!("{}: pressure error {error:.3e}", outcome.report.pair);
    assert!(error <= 5e-2 * 1.0, "{error}");
    assert!((outcome.report.solve.total_contact_force - 2.0).abs() < 1e-9);
}

/// The hard simply supported unit square under q = 1 (D = 1, ν = 0.3, κ = 5/6) as a
/// Reissner–Mindlin plate, exactly: for a polygonal plate with hard simple supports the
/// Mindlin solution is the Kirchhoff one shifted by the Marcus moment,
/// `w_M = w_K + ℳ_K / S`, `θ_M = ∇w_K`, with `ℳ_K = −D Δw_K` and the shear stiffness
/// `S = 6κ(1−ν)D/t²` (Wang, Reddy and Lee, *Shear Deformable Beams and Plates*, 2000,
/// §5.3), and `w_K` is Navier's series `Σ a_mn sin mπx sin nπy`,
/// `a_mn = 16 q / (π⁶ D m n (m² + n²)²)`, m and n odd. Returns the relative error
/// `‖u_M − u_h‖_a / ‖u_M‖_a` of a chosen solution in the Mindlin energy norm
/// `∫ Cε(θ):ε(θ) + |Q|²/S` with the shear force `Q` (the discrete one `S_T (∇w_h − θ_h)`
/// with the Stenberg weight `S_T = 6κ(1−ν)D/(t² + β h_T²)`, β = 0.1: it, not the strain,
/// approximates `Q = S γ`; a Kirchhoff solution taken as `θ_h = ∇w_h`, `Q_h = 0`), and
/// its centre deflection.
fn lee_reddy_relative_error(outcome: &Outcome, t: f64) -> (f64, f64) {
    use fem_forms::element::triangle::{AffineMap, TriangleBasis};
    use fem_forms::TriangleMesh;
    use std::f64::consts::PI;
    let (d, nu, kappa) = (1.0, 0.3, 5.0 / 6.0);
    let stiffness = 6.0 * kappa * (1.0 - nu) * d / (t * t);
    // the norm from the load: ‖u‖² = ∫ q w_M = ∫ w_K + ∫ ℳ_K / S (series to m, n < 4000)
    let (mut deflection, mut moment) = (0.0, 0.0);
    for m in (1..4000).step_by(2) {
        for n in (1..4000).step_by(2) {
            let (m, n) = (m as f64, n as f64);
            let s = m * m + n * n;
            deflection += 64.0 / (PI.powi(8) * d * m * m * n * n * s * s);
            moment += 64.0 / (PI.powi(6) * m * m * n * n * s);
        }
    }
    let norm2 = deflection + moment / stiffness;
    // the fields at a point: ε(θ) = ∇∇w_K and the shear strain γ = ∇ℳ_K / S, from the
    // series to m, n ≤ 63 (its truncation ~1e-4 of ε, far below the tolerances tested)
    let orders: Vec<f64> = (1..64).step_by(2).map(f64::from).collect();
    let exact = |p: [f64; 2]| {
        let (sx, cx): (Vec<f64>, Vec<f64>) =
            orders.iter().map(|m| (m * PI * p[0]).sin_cos()).unzip();
        let (sy, cy): (Vec<f64>, Vec<f64>) =
            orders.iter().map(|n| (n * PI * p[1]).sin_cos()).unzip();
        let (mut eps, mut gamma) = ([0.0; 3], [0.0; 2]);
        for (i, m) in orders.iter().enumerate() {
            for (j, n) in orders.iter().enumerate() {
                let s = m * m + n * n;
                let a = 16.0 / (PI.powi(6) * d * m * n * s * s);
                let (ss, cs, sc, cc) = (sx[i] * sy[j], cx[i] * sy[j], sx[i] * cy[j], cx[i] * cy[j]);
                eps[0] -= a * m * m * PI * PI * ss;
                eps[1] -= a * n * n * PI * PI * ss;
                eps[2] += a * m * n * PI * PI * cc;
                let marcus = a * d * PI * PI * s / stiffness;
                gamma[0] += marcus * m * PI * cs;
                gamma[1] += marcus * n * PI * sc;
            }
        }
        (eps, gamma)
    };
    let kept = outcome.solution.as_ref().expect("the solution kept");
    let solution = kept
        .solution
        .downcast_ref::<ObstacleSolution<TriangleMesh>>()
        .unwrap();
    let at = |name: &str| kept.fields.iter().position(|f| *f == name);
    let w = solution.view(at("w").expect("a plate's deflection"));
    let rotations = at("θ_x").map(|x| (solution.view(x), solution.view(at("θ_y").unwrap())));
    let bw = TriangleBasis::new(w.map.element());
    let bases = rotations.as_ref().map(|(x, y)| {
        (
            TriangleBasis::new(x.map.element()),
            TriangleBasis::new(y.map.element()),
        )
    });
    let mesh = w.mesh;
    let rule = fem_forms::reference::triangle::TriangleRule::exact_for_degree(6);
    let mut error2 = 0.0;
    let mut centre = f64::NAN;
    for c in 0..mesh.cell_count() {
        let map = AffineMap::of(mesh, c);
        let x = mesh.cell_coordinates(c);
        let h = longest_edge(&x);
        // the discrete shear strain as the strain of its shear force: S_T γ_h / S
        let share = t * t / (t * t + 0.1 * h * h);
        for (&xi, &weight) in rule.points.iter().zip(&rule.weights) {
            let p = [
                x[0] + (x[2] - x[0]) * xi[0] + (x[4] - x[0]) * xi[1],
                x[1] + (x[3] - x[1]) * xi[0] + (x[5] - x[1]) * xi[1],
            ];
            let (eps, gamma) = exact(p);
            let g = w.gradient(&bw, &map, c, xi);
            let (eps_h, gamma_h) = match (&rotations, &bases) {
                (Some((tx, ty)), Some((bx, by))) => {
                    let th = [tx.value(bx, c, xi), ty.value(by, c, xi)];
                    let (gx, gy) = (tx.gradient(bx, &map, c, xi), ty.gradient(by, &map, c, xi));
                    (
                        [gx[0], gy[1], 0.5 * (gx[1] + gy[0])],
                        [share * (g[0] - th[0]), share * (g[1] - th[1])],
                    )
                }
                // Kirchhoff: θ_h = ∇w_h, no shear strain
                _ => {
                    let h = w.hessian(&bw, &map, c, xi);
                    ([h[0][0], h[1][1], h[0][1]], [0.0, 0.0])
                }
            };
            let e = [eps[0] - eps_h[0], eps[1] - eps_h[1], eps[2] - eps_h[2]];
            let trace = e[0] + e[1];
            let bending = d
                * ((1.0 - nu) * (e[0] * e[0] + 2.0 * e[2] * e[2] + e[1] * e[1])
                    + nu * trace * trace);
            let (sx, sy) = (gamma[0] - gamma_h[0], gamma[1] - gamma_h[1]);
            error2 += weight * map.det * (bending + stiffness * (sx * sx + sy * sy));
        }
        if centre.is_nan() {
            let inside = (0..3).all(|k| {
                let (a, b) = (k, (k + 1) % 3);
                let cross = (x[2 * b] - x[2 * a]) * (0.5 - x[2 * a + 1])
                    - (x[2 * b + 1] - x[2 * a + 1]) * (0.5 - x[2 * a]);
                cross >= -1e-12
            });
            if inside {
                // the barycentric coordinates of the centre in this cell
                let det = (x[2] - x[0]) * (x[5] - x[1]) - (x[4] - x[0]) * (x[3] - x[1]);
                let xi0 = ((0.5 - x[0]) * (x[5] - x[1]) - (x[4] - x[0]) * (0.5 - x[1])) / det;
                let xi1 = ((x[2] - x[0]) * (0.5 - x[1]) - (0.5 - x[0]) * (x[3] - x[1])) / det;
                centre = w.value(&bw, c, [xi0, xi1]);
            }
        }
    }
    ((error2 / norm2).sqrt(), centre)
}

#[test]
fn the_chosen_mindlin_plate_is_within_the_tolerance_of_the_exact_solution() {
    // hard supports: no boundary layer, so the exact solution is Lee–Reddy's; at
    // t = 1e-1 the shear matters, at t = 1e-3 Kirchhoff is within a small share of T.
    // (Measured: at t = 1e-1 the Mindlin solve reaches 8.1e-3 for T = 5e-2 with 170k
    // unknowns, and 3.3e-3 for T = 2e-2 with 990k: its estimator is pessimistic by about
    // 6, docs/model-choice.md; the second case takes a minute and is left out here.)
    let hard = Adjustment::Support(Support::SimplySupported { hard: true });
    for (t, tolerance) in [(1e-1, 5e-2), (1e-3, 5e-2), (1e-3, 2e-2)] {
        let mut square = scene("mindlin-square-ss");
        families::family(square.family)
            .unwrap()
            .adjust(&mut square, &hard)
            .unwrap();
        let request = Settings {
            adaptive: Some(AdaptiveOptions {
                tolerance,
                ..AdaptiveOptions::default()
            }),
            keep_solution: true,
            ..settings(None, None, Some(t))
        };
        let outcome = choice::solve(&square, &request).unwrap();
        let (error, centre) = lee_reddy_relative_error(&outcome, t);
        println!(
            "t = {t:e}, T = {tolerance:e}: {} with {} unknowns, true error {error:.3e}, w(½,½) = {centre:.6e}",
            choice::chosen_words(&outcome.report),
            outcome.report.solve.dofs
        );
        // the load pushes w up (the exact centre deflection is 0.00406 + shear)
        assert!(centre > 0.004, "t = {t}: w(½,½) = {centre}");
        assert!(
            error <= tolerance,
            "t = {t}, T = {tolerance}: true error {error}"
        );
    }
}

/// The same plate posed from either side: a Reissner–Mindlin scene's Kirchhoff
/// candidate and a Kirchhoff scene given the same thickness have the same modelling
/// estimate, and the Kirchhoff scene's Mindlin candidate the Mindlin scene's estimates
/// (one plate, one set of parameters and supports, whichever model the scene names).
#[test]
fn a_kirchhoff_scene_given_its_thickness_weighs_the_same_mindlin_plate() {
    let t = 1e-2;
    let soft = Adjustment::Support(Support::SimplySupported { hard: false });
    let mut kirchhoff = scene("kirchhoff-square");
    families::family("kirchhoff")
        .unwrap()
        .adjust(&mut kirchhoff, &soft)
        .unwrap();
    let mindlin = scene("mindlin-square-ss");
    let tolerance = 5e-2;
    let from_kirchhoff =
        choice::candidates(&kirchhoff, &settings(None, None, Some(t)), tolerance).unwrap();
    let from_mindlin =
        choice::candidates(&mindlin, &settings(None, None, Some(t)), tolerance).unwrap();
    let find = |candidates: &[choice::Candidate], pair: &str| {
        candidates
            .iter()
            .find(|c| c.pair == pair)
            .unwrap_or_else(|| panic!("no {pair} among {candidates:?}"))
            .clone()
    };
    for pair in ["argyris-p0", "p1-p2-p0"] {
        let (a, b) = (find(&from_kirchhoff, pair), find(&from_mindlin, pair));
        assert!(a.probe.len() == 2 && b.probe.len() == 2, "{a:?}\n{b:?}");
        println!(
            "{pair}: modelling {:.6e} / {:.6e}, estimate {:.6e} / {:.6e}",
            a.modelling_estimate,
            b.modelling_estimate,
            a.probe[1].estimate_relative,
            b.probe[1].estimate_relative
        );
        assert_eq!(a.model, b.model);
        assert!((a.modelling_estimate - b.modelling_estimate).abs() <= 1e-12);
        for (p, q) in a.probe.iter().zip(&b.probe) {
            assert_eq!(p.dofs, q.dofs);
            assert!(
                (p.estimate_relative - q.estimate_relative).abs() <= 1e-9 * q.estimate_relative
            );
        }
    }
    // the soft support's layer: the Kirchhoff plate is 10 % off at t = 1e-2, above
    // half of T
    let argyris = find(&from_kirchhoff, "argyris-p0");
    assert!(argyris.modelling_estimate > 0.5 * tolerance, "{argyris:?}");
    assert!(!argyris.adequate);
    // Morley gives no modelling estimate: not adequate, and it says why
    let morley = find(&from_kirchhoff, "morley-p0");
    assert!(
        !morley.adequate && morley.note.contains("no modelling estimate"),
        "{morley:?}"
    );
    // a Kirchhoff scene without a thickness has no richer neighbour to weigh
    let alone = choice::candidates(&kirchhoff, &settings(None, None, None), tolerance).unwrap();
    assert!(alone.iter().all(|c| c.model == "Kirchhoff"), "{alone:?}");
}

#[test]
fn the_chosen_plate_of_a_kirchhoff_scene_is_within_the_tolerance_of_the_mindlin_solution() {
    // the Kirchhoff square on hard simple supports given its thickness: the plate it
    // stands for is Lee–Reddy's; at t = 1e-1 the shear matters and the Reissner–Mindlin
    // plate is taken, at t = 1e-3 the Kirchhoff one
    let hard = Adjustment::Support(Support::SimplySupported { hard: true });
    for (t, tolerance, model) in [(1e-1, 5e-2, "Reissner–Mindlin"), (1e-3, 5e-2, "Kirchhoff")] {
        let mut square = scene("kirchhoff-square");
        families::family(square.family)
            .unwrap()
            .adjust(&mut square, &hard)
            .unwrap();
        let request = Settings {
            adaptive: Some(AdaptiveOptions {
                tolerance,
                ..AdaptiveOptions::default()
            }),
            ..settings(None, None, Some(t))
        };
        let outcome = choice::solve(&square, &request).unwrap();
        let (error, centre) = lee_reddy_relative_error(&outcome, t);
        println!(
            "t = {t:e}, T = {tolerance:e}: {} with {} unknowns, true error {error:.3e}, w(½,½) = {centre:.6e}",
            choice::chosen_words(&outcome.report),
            outcome.report.solve.dofs
        );
        assert_eq!(outcome.report.quantities["chosen_model"], model);
        assert!(centre > 0.004, "t = {t}: w(½,½) = {centre}");
        assert!(
            error <= tolerance,
            "t = {t}, T = {tolerance}: true error {error}"
        );
    }
    // `--thickness` reaches the Kirchhoff scene, and a Mindlin pair solves the richer
    // model
    let report = json_of(&[
        "solve",
        "kirchhoff-square",
        "--thickness",
        "0.1",
        "--pair",
        "p1-p2-p0",
        "--mesh-size",
        "8",
        "--json",
    ]);
    assert_eq!(report["chosen_model"], "Reissner–Mindlin");
    assert_eq!(report["thickness"], 0.1);
    // a scene file's `thickness` too: the soft supports' layer puts Kirchhoff 42 % off
    // at t = 0.1 (the shear alone 15 %), 3 % at t = 1e-3
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/kirchhoff-thick-plate.toml"
    );
    let thick = json_of(&["solve", "--scene", file, "--json"]);
    assert!(thick["modelling_estimate_relative"].as_f64().unwrap() > 0.3);
    assert!(thick["modelling_estimate_layer"].as_f64().unwrap() > 0.0);
    let thin = json_of(&[
        "solve",
        "--scene",
        file,
        "--thickness",
        "1e-3",
        "--tol",
        "0.1",
        "--json",
    ]);
    assert_eq!(thin["chosen_model"], "Kirchhoff");
    assert!(thin["modelling_estimate_relative"].as_f64().unwrap() < 0.05);
}

/// `fem-forms ARGS`'s failure message (standard error).
fn failure_of(args: &[&str]) -> String {
    let output = fem_forms(args, "fail");
    assert!(!output.status.success(), "{args:?} succeeded");
    String::from_utf8_lossy(&output.stderr).into_owned()
}

#[test]
fn a_kirchhoff_plates_thickness_is_refused_or_warned_where_it_cannot_serve() {
    for (args, named) in [
        // nothing holds the plate: singular, whichever model
        (
            &["solve", "kirchhoff-square", "--support", "free"][..],
            "without energy",
        ),
        (
            &["solve", "mindlin-square-ss", "--support", "free"][..],
            "without energy",
        ),
        // the two models' own boundary data are not one support
        (
            &[
                "solve",
                "kirchhoff-square",
                "--support",
                "dirichlet",
                "--thickness",
                "0.01",
            ][..],
            "`dirichlet` support",
        ),
        (
            &["solve", "kirchhoff-square", "--thickness", "10"][..],
            "exceeds the plate's side",
        ),
        // a Mindlin pair needs the thickness, and takes the plate family's options
        (
            &["solve", "kirchhoff-square", "--pair", "p1-p2-p0"][..],
            "once given its `thickness`",
        ),
        (
            &[
                "solve",
                "kirchhoff-square",
                "--thickness",
                "0.1",
                "--pair",
                "p1-p2-p0",
                "--solver",
                "clarabel",
            ][..],
            "--solver does not apply",
        ),
    ] {
        let stderr = failure_of(args);
        assert!(stderr.contains(named), "{args:?}: {stderr}");
    }
    // the Mindlin plate posed with `dirichlet` has no Kirchhoff neighbour: one candidate
    let report = json_of(&[
        "solve",
        "mindlin-square-ss",
        "--support",
        "dirichlet",
        "--thickness",
        "0.01",
        "--tol",
        "0.2",
        "--json",
    ]);
    assert!(report.get("chosen_model").is_none(), "{report}");

    let warnings = |report: &serde_json::Value| report["warnings"].to_string();
    // Morley cannot use the thickness, and says so; the report names the thickness
    let morley = json_of(&[
        "solve",
        "kirchhoff-square",
        "--support",
        "simply-supported",
        "--thickness",
        "0.1",
        "--pair",
        "morley-p0",
        "--json",
    ]);
    assert!(warnings(&morley).contains("is not used"), "{morley}");
    assert_eq!(morley["thickness"], 0.1);
    // a fixed Kirchhoff pair meets T in its discretization only: the bound is warned
    let fixed = json_of(&[
        "solve",
        "kirchhoff-square",
        "--support",
        "simply-supported",
        "--thickness",
        "0.1",
        "--pair",
        "argyris-p0",
        "--tol",
        "0.05",
        "--json",
    ]);
    assert!(warnings(&fixed).contains("above the tolerance"), "{fixed}");
    // α is the scene's own model's: taken to the Mindlin plate, the report says so
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/kirchhoff-thick-plate.toml"
    );
    let chosen = json_of(&[
        "solve", "--scene", file, "--tol", "0.2", "--alpha", "1e-6", "--json",
    ]);
    assert_eq!(chosen["chosen_model"], "Reissner–Mindlin");
    assert!(
        warnings(&chosen).contains("--alpha 1e-6 applies"),
        "{chosen}"
    );
    // a scene file's Mindlin pair with its thickness
    let text = std::fs::read_to_string(file).unwrap().replace(
        "model = \"kirchhoff\"",
        "model = \"kirchhoff\"\npair = \"p1-p2-p0\"",
    );
    let path = std::env::temp_dir().join(format!("thick-pair-{}.toml", std::process::id()));
    std::fs::write(&path, text).unwrap();
    let paired = json_of(&["solve", "--scene", path.to_str().unwrap(), "--json"]);
    let _ = std::fs::remove_file(&path);
    assert_eq!(paired["chosen_model"], "Reissner–Mindlin");
    assert_eq!(paired["pair"], "p1-p2-p0");
}

#[test]
fn a_neighbour_takes_its_own_familys_options_and_the_scenes_own() {
    // the Reissner–Mindlin plate takes no --solver: chosen by a tolerance, it is solved
    // by its default and the report says so
    let chosen = json_of(&[
        "solve",
        "kirchhoff-obstacle",
        "--thickness",
        "0.3",
        "--tol",
        "0.5",
        "--solver",
        "clarabel",
        "--json",
    ]);
    assert_eq!(chosen["chosen_model"], "Reissner–Mindlin");
    assert_eq!(chosen["solver"], "pdas");
    assert!(
        chosen["warnings"]
            .to_string()
            .contains("--solver clarabel applies"),
        "{chosen}"
    );
    // an α outside the Kirchhoff pairs' range is refused, not a reason to take the
    // Reissner–Mindlin plate
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/kirchhoff-thick-plate.toml"
    );
    let refused = failure_of(&["solve", "--scene", file, "--tol", "0.05", "--alpha", "0.01"]);
    assert!(refused.contains("stability range"), "{refused}");
    // the scene's own family applies --obstacle before the neighbour is posed
    let bare = json_of(&[
        "solve",
        "--scene",
        file,
        "--obstacle",
        "none",
        "--pair",
        "p1-p2-p0",
        "--mesh-size",
        "8",
        "--json",
    ]);
    assert_eq!(bare["chosen_model"], "Reissner–Mindlin");
    assert_eq!(bare["obstacle"], "none");
    // a file's Mindlin pair posed by a thickness given on the command line
    let text = std::fs::read_to_string(file)
        .unwrap()
        .replace("thickness = 0.1\n", "")
        .replace(
            "model = \"kirchhoff\"",
            "model = \"kirchhoff\"\npair = \"p1-p2-p0\"",
        );
    let path = std::env::temp_dir().join(format!("thin-pair-{}.toml", std::process::id()));
    std::fs::write(&path, text).unwrap();
    let given = json_of(&[
        "solve",
        "--scene",
        path.to_str().unwrap(),
        "--thickness",
        "0.02",
        "--json",
    ]);
    let missing = failure_of(&["solve", "--scene", path.to_str().unwrap()]);
    let _ = std::fs::remove_file(&path);
    assert_eq!(given["chosen_model"], "Reissner–Mindlin");
    assert_eq!(given["thickness"], 0.02);
    assert!(missing.contains("once given its `thickness`"), "{missing}");
}

#[test]
fn the_requests_options_reach_each_model_as_it_takes_them() {
    // --thickness is the Timoshenko beam's: the Euler–Bernoulli candidate is posed
    // without it, not refused for it
    let report = json_of(&[
        "solve",
        "timoshenko-t1e-3",
        "--tol",
        "5e-2",
        "--thickness",
        "0.001",
        "--json",
    ]);
    assert_eq!(report["chosen_model"], "Euler–Bernoulli", "{report}");
    // --alpha is the Mindlin pair's: the Kirchhoff pairs keep their own rule
    let report = json_of(&[
        "solve",
        "mindlin-ss-t1e-3",
        "--tol",
        "0.1",
        "--alpha",
        "0.1",
        "--json",
    ]);
    assert_eq!(report["chosen_model"], "Kirchhoff", "{report}");
    // a tolerance is a relative error below 1
    assert!(failure_of(&["solve", "timoshenko-t1e-1", "--tol", "1e300"]).contains("in (0, 1)"));
    // where every probe fails, the failure says why, not that a tolerance is NaN
    let message = failure_of(&[
        "solve",
        "timoshenko-t1e-2",
        "--load",
        "1e30",
        "--tol",
        "0.05",
    ]);
    assert!(!message.contains("NaN"), "{message}");
    // a probe mesh whose supports fix every unknown has no relative error: say so
    let message = failure_of(&[
        "solve",
        "kirchhoff-obstacle",
        "--mesh-size",
        "1",
        "--tol",
        "0.1",
    ]);
    assert!(message.contains("start from a finer one"), "{message}");
    // nor has a solution that is 0
    let message = failure_of(&["solve", "kirchhoff-square", "--load", "0", "--tol", "0.1"]);
    assert!(message.contains("solve without a tolerance"), "{message}");
}

/// When every candidate's solve fails (here: a limit on the unknowns below what the
/// tolerance needs), the error lists every candidate weighed and why, not only the
/// first failure.
#[test]
fn a_choice_whose_every_solve_fails_lists_its_candidates() {
    let radial = scene("membrane-radial");
    let request = Settings {
        adaptive: Some(AdaptiveOptions {
            tolerance: 1e-3,
            max_dofs: 300,
            ..AdaptiveOptions::default()
        }),
        ..Settings::default()
    };
    let Err(e) = choice::solve(&radial, &request) else {
        panic!("solved within 300 unknowns");
    };
    let e = e.to_string();
    assert!(e.contains("no candidate's solve succeeded"), "{e}");
    for pair in families::pairs_of(&radial) {
        assert!(
            e.contains(&format!(" {}: ", pair.name)),
            "{}: {e}",
            pair.name
        );
    }
    assert!(e.contains("its adaptive solve failed"), "{e}");
}
