//! Signorini contact (docs/contact.md) posed as scene files and solved through the one
//! pipeline: the patch test (an elastic block on a rigid foundation under a uniform
//! pressure q: λ_h = q exactly on every contact edge or vertex, which catches the sign
//! inside `λ + σ_n`), for every pair, mesh diagonal and α up to `1/max C_I`; vertical
//! equilibrium (total contact force = load, an identity since a rigid translation lies
//! in V_h) and complementarity; the inverse constants computed from the kernels against
//! the P1 closed form; Newton against clarabel's QP on a partial contact; the runtime's
//! nested levels against one cold level; the errors on bad input.
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

#[path = "common/contact.rs"]
mod contact;

use contact::{block, parse, patch, solve_file, try_parse, Solved, Q};
use fem_forms::models::families::contact::{lame, Plane};
use fem_forms::obstacle::VariationalSolver;
use fem_forms::Diagonal;

/// The identities and the exact pressure of the patch test on the unit block: `dofs`
/// multiplier values, each q.
fn check_patch(s: &Solved, dofs: usize, what: &str) {
    let pressures = s.pressures();
    assert_eq!(pressures.len(), dofs, "{what}: {pressures:?}");
    for (k, &p) in pressures.iter().enumerate() {
        assert!(
            (p - Q).abs() <= 1e-9 * Q,
            "{what}: λ_h = {p} at multiplier DOF {k}, expected q = {Q}"
        );
    }
    // equilibrium: the foundation carries the load, q over the unit width
    let (force, load) = (
        s.quantity("total_contact_force"),
        s.quantity("applied_load"),
    );
    assert!(
        (force - Q).abs() <= 1e-10 * Q,
        "{what}: contact force {force}"
    );
    assert!((load - Q).abs() <= 1e-12 * Q, "{what}: load {load}");
    assert!(s.quantity("equilibrium_residual") <= 1e-10, "{what}");
    let solve = &s.report.solve;
    assert!(
        solve.complementarity_residual <= 1e-9,
        "{what}: {}",
        solve.complementarity_residual
    );
    assert!(solve.kkt_residual <= 1e-9, "{what}: {}", solve.kkt_residual);
    assert!(
        (s.quantity("contact_half_width") - 0.5).abs() <= 1e-12,
        "{what}"
    );
    assert!(
        (s.quantity("max_contact_pressure") - Q).abs() <= 1e-9 * Q,
        "{what}"
    );
}

/// The patch test on every pair and diagonal: P0 multipliers one per bottom edge, P1
/// multipliers one per bottom vertex.
#[test]
fn the_patch_test_gives_the_pressure_exactly_for_every_pair() {
    let file = parse(&patch());
    let diagonals = [
        Diagonal::Right,
        Diagonal::Left,
        Diagonal::Alternating,
        Diagonal::Crossed,
    ];
    for (pair, sizes, diagonals) in [
        ("p1-p0", &[2, 5][..], &diagonals[..]),
        (
            "p2-p0",
            &[3][..],
            &[Diagonal::Right, Diagonal::Alternating][..],
        ),
        (
            "p1-p1",
            &[2, 5][..],
            &[Diagonal::Right, Diagonal::Alternating][..],
        ),
        (
            "p2-p1",
            &[3][..],
            &[Diagonal::Right, Diagonal::Alternating][..],
        ),
    ] {
        for &n in sizes {
            for &diagonal in diagonals {
                let s = solve_file(&file, |s| {
                    s.pair = Some(pair.into());
                    s.mesh_size = Some(n);
                    s.diagonal = Some(diagonal);
                })
                .unwrap_or_else(|e| panic!("{pair} {diagonal:?} n = {n}: {e}"));
                let dofs = if pair.ends_with("p1") { n + 1 } else { n };
                check_patch(&s, dofs, &format!("{pair} {diagonal:?} n = {n}"));
            }
        }
    }
}

/// The patch holds for every α up to `1/max C_I` (the exact solution satisfies the
/// stabilized equations: consistency), and for the plain method (α = 0, by the QP).
/// (At `α max C_I = 1.5` this mesh's Newton Hessian `A_α + B_αᵀC_α⁻¹B_α` is not positive
/// definite and semismooth Newton refuses it: an error, not a wrong answer.)
#[test]
fn the_patch_test_holds_for_every_alpha() {
    let file = parse(&patch());
    for pair in ["p1-p0", "p1-p1"] {
        let at = |alpha: Option<f64>| {
            solve_file(&file, |s| {
                s.pair = Some(pair.into());
                s.mesh_size = Some(4);
                s.diagonal = Some(Diagonal::Alternating);
                s.alpha = alpha;
            })
        };
        let auto = at(None).unwrap();
        let max_ci = auto.report.solve.inverse_constant;
        assert!(max_ci > 0.0);
        let dofs = if pair == "p1-p1" { 5 } else { 4 };
        for factor in [0.1, 0.5, 1.0] {
            let s = at(Some(factor / max_ci))
                .unwrap_or_else(|e| panic!("{pair} α C_I = {factor}: {e}"));
            check_patch(&s, dofs, &format!("{pair} α C_I = {factor}"));
        }
        let plain = at(Some(0.0)).unwrap();
        assert_eq!(plain.report.solve.solver, "clarabel", "{pair}");
        for p in plain.pressures() {
            assert!((p - Q).abs() <= 1e-6 * Q, "{pair} plain: λ_h = {p}");
        }
    }
}

/// `C_I,E` from the kernels' generalized eigenvalue problem against the P1 closed form
/// `h_E |E| (λ_L + 2μ)/|T_E|` on a mesh of unequal cells, and the pipeline's
/// α = 1/(2 max C_I,E) against it on the block, in plane strain and plane stress.
#[test]
fn inverse_constants_match_the_p1_closed_form() {
    use fem_forms::models::signorini::signorini_p1::{self, Model as M};
    use fem_forms::problem::Domain;
    use fem_forms::{Coefficients, TriangleMesh};
    for (plane, name) in [(Plane::Strain, "strain"), (Plane::Stress, "stress")] {
        let (mu, lambda) = lame(1000.0, 0.3, plane).unwrap();
        let mesh = TriangleMesh::rectangle(0.0, 2.0, 0.0, 1.0, 5, 3, Diagonal::Alternating)
            .unwrap()
            .refine(&[0, 3])
            .unwrap()
            .0;
        let zero = |_: &[f64]| 0.0;
        let coefficients = Coefficients::from_ids(
            &[
                (signorini_p1::params::μ_L, mu),
                (signorini_p1::params::λ_L, lambda),
                (signorini_p1::params::α, 0.0),
                (signorini_p1::params::n_c_x, 0.0),
                (signorini_p1::params::n_c_y, -1.0),
            ],
            &[
                (signorini_p1::data::q, &zero),
                (signorini_p1::data::g, &zero),
            ],
        )
        .unwrap();
        let part = signorini_p1::facets::Γ_C.index();
        let constants = mesh
            .boundary_inverse_constants::<M>(&coefficients, part, &[1])
            .unwrap();
        let bottom: Vec<usize> = mesh
            .boundary_edges()
            .iter()
            .filter(|(_, m)| *m == 1)
            .map(|&(e, _)| e)
            .collect();
        assert_eq!(constants.len(), bottom.len());
        for (&e, &c) in bottom.iter().zip(&constants) {
            let [a, b] = mesh.edges()[e];
            let (p, q) = (mesh.vertices()[a], mesh.vertices()[b]);
            let l = (p[0] - q[0]).hypot(p[1] - q[1]);
            let (cell, _) = mesh.edge_cells(e);
            let closed = l * l * (lambda + 2.0 * mu) / mesh.area(cell);
            assert!(
                (c - closed).abs() <= 1e-9 * closed,
                "{name}: C_I = {c}, closed form {closed}"
            );
        }
        // on the n × n block every bottom cell is a right triangle of legs 1/n: C_I,E
        // = 2(λ_L + 2μ) on each, whatever n
        let text = patch().replace(
            "poisson = 0.3",
            &format!("poisson = 0.3\n    plane = \"{name}\""),
        );
        let s = solve_file(&parse(&text), |s| s.mesh_size = Some(3)).unwrap();
        let expected = 0.5 / (2.0 * (lambda + 2.0 * mu));
        let alpha = s.report.solve.alpha.unwrap();
        assert!(
            (alpha - expected).abs() <= 1e-9 * expected,
            "{name}: α = {alpha}, closed form {expected}"
        );
    }
}

/// A foundation that curves away from the block's bottom: contact in the middle only.
const PARABOLIC_GAP: &str = "0.02 * (x - 0.5)^2";

/// A non-flat initial gap: only part of Γ_C touches. Newton's answer against
/// clarabel's QP (an independent solver) through the same pipeline, the contact force
/// against the load, and a contact zone that is neither empty nor the whole bottom.
#[test]
fn a_partial_contact_newton_agrees_with_the_qp() {
    let file = parse(&block(&Q.to_string(), PARABOLIC_GAP, ""));
    for pair in ["p1-p0", "p1-p1"] {
        let at = |solver| {
            solve_file(&file, |s| {
                s.pair = Some(pair.into());
                s.mesh_size = Some(8);
                s.diagonal = Some(Diagonal::Alternating);
                s.solver = solver;
            })
            .unwrap()
        };
        let newton = at(VariationalSolver::SemismoothNewton);
        let qp = at(VariationalSolver::Clarabel);
        assert!(newton.quantity("equilibrium_residual") <= 1e-10, "{pair}");
        let pressures = newton.pressures();
        let touching = pressures.iter().filter(|&&p| p > 0.0).count();
        assert!(
            touching > 0 && touching < pressures.len(),
            "{pair}: {touching} of {}",
            pressures.len()
        );
        assert!(newton.quantity("contact_half_width") < 0.5, "{pair}");
        let scale = pressures.iter().fold(0.0f64, |m, &p| m.max(p));
        let others = qp.pressures();
        assert_eq!(pressures.len(), others.len());
        for (k, (a, b)) in pressures.iter().zip(&others).enumerate() {
            assert!(
                (a - b).abs() <= 1e-6 * scale,
                "{pair} DOF {k}: Newton {a}, QP {b}"
            );
        }
    }
}

/// The runtime's nested solve of a contact problem (the unit square refined from one
/// square, over a parabolic gap), each level from the one before, the coarsest pressed
/// into the foundation: its one coarse contact edge splits, and the prolonged start of
/// the next level opens both halves, leaving a body only contact holds singular
/// ("matrix is not positive definite" before). Such a level is solved again from the
/// pressed start, and the nested answer is the cold one on the finest mesh.
#[test]
fn a_nested_level_whose_prolonged_start_fails_starts_pressed() {
    use fem_forms::models::signorini::signorini_p1::{self, Model as M};
    use fem_forms::obstacle::{Discretization, LevelStart};
    use fem_forms::problem::{Condition, Problem, ALPHA_WHEN_CI_VANISHES};
    use fem_forms::stabilization::Alpha;
    use fem_forms::{DirichletPart, TriangleMesh};
    let (mu, lambda) = lame(1000.0, 0.3, Plane::Strain).unwrap();
    let pressure = |_: &[f64]| Q;
    let gap = |x: &[f64]| 0.02 * (x[0] - 0.5) * (x[0] - 0.5);
    // every constraint active: the body pushed beyond the largest gap, 0.005
    let pressed = |d: &Discretization<TriangleMesh>| -> fem_forms::Result<LevelStart> {
        let mut full = vec![0.0; d.dofs.dof_count()];
        full[d.dofs.range(signorini_p1::fields::u_y.index()).unwrap()].fill(-0.01);
        Ok(LevelStart::At(
            d.reduction.free().iter().map(|&k| full[k]).collect(),
        ))
    };
    let solve = |meshes: Vec<TriangleMesh>| {
        Problem::<M, TriangleMesh>::new(meshes)
            .param(signorini_p1::params::μ_L, mu)
            .param(signorini_p1::params::λ_L, lambda)
            .param(signorini_p1::params::n_c_x, 0.0)
            .param(signorini_p1::params::n_c_y, -1.0)
            .data(signorini_p1::data::q, &pressure)
            .data(signorini_p1::data::g, &gap)
            .part(signorini_p1::facets::Γ_C, vec![1])
            .part(signorini_p1::facets::Γ_N, vec![3])
            .support(
                DirichletPart::Markers(vec![4]),
                signorini_p1::fields::u_x,
                Condition::Zero,
            )
            .alpha(Alpha::default(), ALPHA_WHEN_CI_VANISHES)
            .start(&pressed)
            .solve()
            .unwrap_or_else(|e| panic!("{e}"))
    };
    let mut levels =
        vec![TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 1, 1, Diagonal::Right).unwrap()];
    for _ in 0..3 {
        let finer = levels.last().unwrap().refine_uniformly();
        levels.push(finer);
    }
    let finest = levels[3].clone();
    let nested = solve(levels);
    let cold = solve(vec![finest]);
    assert_eq!(nested.report.levels.len(), 4, "{:?}", nested.report.levels);
    let (a, b) = (
        nested.solution.multiplier_values(),
        cold.solution.multiplier_values(),
    );
    let scale = b.iter().fold(0.0f64, |m, &p| m.max(p));
    assert!(scale > 0.0);
    assert_eq!(a.len(), b.len());
    for (k, (x, y)) in a.iter().zip(b).enumerate() {
        assert!(
            (x - y).abs() <= 1e-8 * scale,
            "DOF {k}: nested {x}, cold {y}"
        );
    }
}

/// Bad material, loads the contact cannot hold and a negative α are refused with a
/// message naming the fault, never a panic or an answer.
#[test]
fn bad_input_is_an_error_not_a_panic() {
    let message = |text: &str, alpha: Option<f64>| -> String {
        match try_parse(text) {
            Err(e) => e.to_string(),
            Ok(file) => solve_file(&file, |s| {
                s.mesh_size = Some(2);
                s.alpha = alpha;
            })
            .map(|s| format!("solved: {:?}", s.report.solve.warnings))
            .unwrap_or_else(|e| e.to_string()),
        }
    };
    let q = Q.to_string();
    let cases: Vec<(String, Option<f64>, &str)> = vec![
        (
            patch().replace("young = 1000.0", "young = 0.0"),
            None,
            "young",
        ),
        (
            patch().replace("poisson = 0.3", "poisson = 0.5"),
            None,
            "poisson",
        ),
        (block(&format!("-{q}"), "0", ""), None, "pulls the body off"),
        (patch(), Some(-1.0), "α"),
        // the top and the right side pressed, nothing holding the block along x: it
        // slides (frictionless contact cannot hold it)
        (
            block(
                &q,
                "0",
                "contact = \"bottom\"\n    load = [\"top\", \"right\"]",
            ),
            None,
            "pushes it that way",
        ),
        // balanced sideways (left and right pressed alike) the translation is free
        (
            block(
                &q,
                "0",
                "contact = \"bottom\"\n    load = [\"top\", \"right\", \"left\"]",
            ),
            None,
            "no support fixes",
        ),
        // a support along n_c on the contact part itself
        (
            patch().replace(
                "fixed_x = \"left\"",
                "fixed_x = \"left\"\n    fixed_y = \"bottom\"",
            ),
            None,
            "drop the support",
        ),
    ];
    for (text, alpha, expected) in cases {
        let m = message(&text, alpha);
        assert!(
            m.to_lowercase().contains(&expected.to_lowercase()),
            "expected `{expected}` in: {m}\n{text}"
        );
    }
}

/// The contact direction is declared a unit vector (`unit: n_c;`): the forms hold
/// `σ_n(u) = n_c·σ(u)n`, which is the normal stress only for `|n_c| = 1`, so other
/// lengths are refused, naming the parameters; a unit direction along no axis is taken.
#[test]
fn a_contact_direction_that_is_not_a_unit_vector_is_refused() {
    use fem_forms::models::signorini::signorini_p1;
    let zero = |_: &[f64]| 0.0;
    let coefficients = |n: [f64; 2]| {
        fem_forms::Coefficients::from_ids(
            &[
                (signorini_p1::params::μ_L, 1.0),
                (signorini_p1::params::λ_L, 1.0),
                (signorini_p1::params::α, 0.1),
                (signorini_p1::params::n_c_x, n[0]),
                (signorini_p1::params::n_c_y, n[1]),
            ],
            &[
                (signorini_p1::data::q, &zero),
                (signorini_p1::data::g, &zero),
            ],
        )
    };
    assert_eq!(
        <signorini_p1::Model as fem_forms::Model>::UNIT_PARAMS,
        &[(3, 4)]
    );
    let Err(e) = coefficients([0.0, -2.0]) else {
        panic!("a contact direction of length 2 was taken");
    };
    let message = e.to_string();
    assert!(
        message.contains("n_c_x") && message.contains("unit vector"),
        "{message}"
    );
    assert!(coefficients([0.6, -0.8]).is_ok());
}
