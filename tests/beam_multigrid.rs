//! Multigrid on the nested interval meshes of the beam obstacle problems (issue 15:
//! "prolongation from the refinement … P1/P2 Lagrange and Hermite"): the prolongation
//! of the primal unknowns reproduces every coarse function on the finer mesh (values and
//! slopes, checked pointwise through an independent evaluation), and Newton with
//! multigrid steps reaches the direct path's KKT-certified solution with CG iteration
//! counts bounded as h → 0 on the Hermite beam.

#[path = "common/beams.rs"]
mod beams;

use fem_forms::element::interval::PhysicalBasis;
use fem_forms::models::report::Settings;
use fem_forms::norms::FieldView;
use fem_forms::obstacle::hierarchy::{interval_primal_prolongation, LinearSolver};
use fem_forms::obstacle::Discretization;

/// The problem of `name` with `pair` on `elements` elements at q = 1 (α = 1).
fn discretize(name: &str, pair: &str, elements: usize) -> Discretization {
    beams::discretize(name, pair, elements, 1.0, 1.0).unwrap()
}

/// Value and slope of every primal field of `values` at `x`, on `d`'s mesh.
fn evaluate(d: &Discretization, values: &[f64], x: f64) -> Vec<f64> {
    let mut out = Vec::new();
    for &field in d.dofs.fields() {
        if field == d.multiplier_field {
            continue;
        }
        let map = d.dofs.map(field).unwrap();
        let view = FieldView {
            mesh: &d.mesh,
            map,
            coefficients: &values[d.dofs.range(field).unwrap()],
        };
        let basis = PhysicalBasis::new(map.element(), 1);
        for derivative in 0..2 {
            out.push(view.at_with(&basis, x, derivative).unwrap());
        }
    }
    out
}

#[test]
fn the_prolongation_reproduces_every_coarse_function_with_its_slope() {
    for (name, pair) in [
        ("bernoulli-a", "hermite-p0"),
        ("timoshenko-a", "p2-p2-p0"),
        ("timoshenko-a", "p1-p1-p0-reduced"),
    ] {
        let (coarse, fine) = (discretize(name, pair, 8), discretize(name, pair, 16));
        let p = interval_primal_prolongation(&coarse, &fine).unwrap();
        assert_eq!((p.nrows(), p.ncols()), (fine.lcp.n(), coarse.lcp.n()));
        let dense = p.to_dense();
        for j in 0..coarse.lcp.n() {
            let mut unit = vec![0.0; coarse.lcp.n()];
            unit[j] = 1.0;
            let coarse_values = coarse.full_of_primal(unit);
            let fine_values =
                fine.full_of_primal((0..fine.lcp.n()).map(|i| dense[(i, j)]).collect());
            // points inside cells of both meshes (slopes of P1/P2 jump at vertices)
            for k in 0..64 {
                let x = (k as f64 + 0.37) / 64.0;
                let (a, b) = (
                    evaluate(&coarse, &coarse_values, x),
                    evaluate(&fine, &fine_values, x),
                );
                for (a, b) in a.iter().zip(&b) {
                    assert!(
                        (a - b).abs() <= 1e-10 * (1.0 + a.abs()),
                        "{name} {pair}: coarse function {j} at x = {x}: {a} on the coarse mesh, {b} prolonged"
                    );
                }
            }
        }
    }
}

#[test]
fn newton_with_multigrid_steps_reaches_the_direct_solution_on_beams() {
    // (scene, pair, load): a contact interval on each
    let cases = [
        ("bernoulli-flat", "hermite-p0", 100.0),
        ("bernoulli-a", "hermite-p0", 40.0),
        ("timoshenko-a", "p1-p1-p0-reduced", 40.0),
        ("timoshenko-b", "p2-p2-p0", 100.0),
    ];
    for (name, pair, load) in cases {
        let mut iterations_per_step = Vec::new();
        for elements in [128, 512] {
            let with = |linear_solver| Settings {
                pair: Some(pair.into()),
                linear_solver,
                ..beams::settings(elements, load)
            };
            let direct = beams::solve(name, &with(LinearSolver::Direct))
                .unwrap()
                .report;
            let multigrid = beams::solve(name, &with(LinearSolver::Multigrid))
                .unwrap()
                .report;
            let (d, m) = (&direct.solve, &multigrid.solve);
            assert_eq!(d.linear_solver, "direct");
            assert_eq!(m.linear_solver, "multigrid", "{name} at {elements}");
            assert!(d.factorizations > 0, "{name}: the direct path factors");
            assert!(m.complementarity_residual <= 1e-10, "{name}: {m:?}");
            let (em, ed) = (m.energy.unwrap(), d.energy.unwrap());
            assert!(
                (em - ed).abs() <= 1e-9 * ed.abs(),
                "{name} at {elements}: energy {em} with multigrid, {ed} direct"
            );
            let (cm, cd) = (beams::contact_set(&multigrid), beams::contact_set(&direct));
            assert_eq!(cm.len(), cd.len(), "{name}");
            for (a, b) in cm.iter().zip(&cd) {
                assert!((a[0] - b[0]).abs() <= 1e-9 && (a[1] - b[1]).abs() <= 1e-9);
            }
            iterations_per_step.push(m.krylov_iterations as f64 / m.iterations.max(1) as f64);
        }
        if pair == "hermite-p0" {
            // fourth order, κ ~ h⁻⁴: still no growth of the CG iterations per Newton step
            assert!(
                iterations_per_step[1] <= 1.5 * iterations_per_step[0] + 2.0,
                "{name}: CG iterations per Newton step {iterations_per_step:?} at 128 and 512 elements"
            );
        }
    }
}

/// On a large nested Hermite mesh every fine DOF at a coarse vertex is that vertex's
/// coarse DOF (one entry, 1), and every new one couples to the four DOFs of its parent
/// cell at most: no rounding couples a row to a farther coarse DOF.
#[test]
fn the_hermite_prolongation_of_a_large_mesh_has_the_nested_pattern() {
    let coarse = discretize("bernoulli-a", "hermite-p0", 3000);
    let fine = discretize("bernoulli-a", "hermite-p0", 6000);
    let p = interval_primal_prolongation(&coarse, &fine).unwrap();
    let pt = p.to_row_major().unwrap();
    let (row_ptr, columns, values) = (pt.symbolic().row_ptr(), pt.symbolic().col_idx(), pt.val());
    let (mut identity_rows, mut new_rows) = (0, 0);
    for i in 0..p.nrows() {
        let entries = row_ptr[i]..row_ptr[i + 1];
        assert!(entries.len() <= 4, "row {i}: {} entries", entries.len());
        // 1 up to the rounding of a slope's scaling h·(1/h)
        if entries.len() == 1 && (values[entries.start] - 1.0).abs() <= 1e-12 {
            identity_rows += 1;
        } else {
            new_rows += 1;
            // the parent's DOFs: two vertices, value and slope each, within 4 columns
            let cols = &columns[entries];
            assert!(
                cols.iter().max().unwrap() - cols.iter().min().unwrap() <= 3,
                "row {i}: {cols:?}"
            );
        }
    }
    // the interior coarse vertices (2 DOFs each, 2999 of them) and the 3000 midpoints
    assert_eq!(identity_rows, 2 * 2999, "{identity_rows} identity rows");
    assert_eq!(new_rows, 2 * 3000);
}
