//! The estimate on interval meshes (beams): cells and interior nodes.

use super::{ContactTerms, Estimate};
use crate::element::interval::PhysicalBasis;
use crate::mesh::IntervalMesh;
use crate::model::{DataFn, Model};
use crate::norms::FieldView;
use crate::obstacle::ObstacleSolution;
use crate::{Error, Result};
use fem_reference::QuadratureRule;

/// The local coefficients of `view` on cell `c` in the reference basis: the DOFs with
/// each derivative DOF times `h^k` (Hermite slopes times the cell's length), what the
/// generated interval kernels take.
fn reference_coefficients(view: &FieldView, c: usize) -> Vec<f64> {
    let h = view.mesh.h(c);
    let element = view.map.element();
    view.local(c)
        .iter()
        .enumerate()
        .map(|(i, &u)| u * h.powi(element.dof_scaling_power(i)))
        .collect()
}

/// The estimate of `solution` on an interval mesh with the model's `estimator:` kernels
/// (cells, and interior nodes as the "edges") and the contact terms; as
/// [`super::triangle_estimate`] on triangles. An interior node's `η_E²` is shared
/// half-and-half by its two cells for marking.
///
/// The violation part of `S` is `Σ_T h_T^{−2m} ‖s(ψ − u_h)_+‖²_T` (`m` the energy's
/// derivative order of the constrained field, [`super::energy_order`]) for every element: the inverse-inequality scaling
/// of the L² norm to the energy norm, which needs no nodal interpolant of the positive part
/// (Hermite cubics have none).
///
/// # Errors
/// A model without an estimator or an energy form, and indicators that are not finite
/// (the message names the cell).
pub fn interval_estimate<M: Model>(
    solution: &ObstacleSolution<IntervalMesh>,
    params: &[f64],
    data: &[&DataFn],
    side: Option<f64>,
) -> Result<Estimate> {
    super::require_estimator::<M>()?;
    let mesh = &solution.discretization.mesh;
    let views: Vec<FieldView> = (0..M::FIELDS.len()).map(|f| solution.view(f)).collect();
    let local = |c: usize| -> Vec<Vec<f64>> {
        views.iter().map(|v| reference_coefficients(v, c)).collect()
    };
    let cells = mesh.cell_count();
    let mut indicators = vec![0.0; cells];
    let mut sum = 0.0;
    let mut previous = local(0);
    for c in 0..cells {
        let here = if c == 0 { previous.clone() } else { local(c) };
        let slices: Vec<&[f64]> = here.iter().map(Vec::as_slice).collect();
        let x = mesh.cell(c);
        let eta2 = M::cell_indicator(&x, &slices, params, data)?;
        indicators[c] += eta2;
        sum += eta2;
        if c > 0 {
            // the node between cells c − 1 (its right end) and c (its left end)
            let left: Vec<&[f64]> = previous.iter().map(Vec::as_slice).collect();
            let eta2 =
                M::edge_indicator(&mesh.cell(c - 1), 1, &left, &x, 0, &slices, params, data)?;
            indicators[c - 1] += 0.5 * eta2;
            indicators[c] += 0.5 * eta2;
            sum += eta2;
        }
        previous = here;
    }
    sum += natural_ends::<M>(solution, &local, params, data, &mut indicators)?;
    if let Some(c) = indicators.iter().position(|e| !e.is_finite()) {
        let [a, b] = mesh.cell(c);
        return Err(Error::Input(format!(
            "the indicator of cell {c} ([{a}, {b}]) is {}: the solution or the data are not finite there",
            indicators[c]
        )));
    }
    let field = M::constrained_field();
    let multiplier = solution.discretization.multiplier_field;
    let energy = energy_product::<M>(&views, multiplier, params, data)?;
    let contact = match (M::OBSTACLE, side) {
        (Some([_, psi]), Some(side)) => {
            let multiplier = &views[solution.discretization.multiplier_field];
            contact_terms::<M>(&views[field], multiplier, data[psi], side)
        }
        _ => ContactTerms::default(),
    };
    Ok(Estimate::of(
        indicators,
        sum,
        contact,
        energy.max(0.0).sqrt(),
    ))
}

/// Adds the natural boundary terms ([`Model::NATURAL_FLUXES`]) at the mesh's two ends
/// to their cells' entries of `indicators` and returns their sum: the flux of each test
/// coordinate that is free at the end (`j = 0` the value, `j = 1` the slope; a free or
/// simply supported beam's shear and moment), found with one admissible test function
/// of random free DOFs ([`super::admissible_probe`]). `local` gives a cell's reference
/// coefficients.
///
/// # Errors
/// The kernels' errors.
fn natural_ends<M: Model>(
    solution: &ObstacleSolution<IntervalMesh>,
    local: &dyn Fn(usize) -> Vec<Vec<f64>>,
    params: &[f64],
    data: &[&DataFn],
    indicators: &mut [f64],
) -> Result<f64> {
    if M::NATURAL_FLUXES.is_empty() {
        return Ok(0.0);
    }
    let d = &solution.discretization;
    let mesh = &d.mesh;
    let probe = super::admissible_probe(solution);
    let last = mesh.cell_count() - 1;
    let mut sum = 0.0;
    for (cell, end) in [(0, 0), (last, 1)] {
        let x = mesh.cell(cell);
        let coefficients = local(cell);
        let slices: Vec<&[f64]> = coefficients.iter().map(Vec::as_slice).collect();
        for (k, &(field, j)) in M::NATURAL_FLUXES.iter().enumerate() {
            let Some((map, range)) = d.dofs.map(field).zip(d.dofs.range(field)) else {
                continue;
            };
            let test = FieldView {
                mesh,
                map,
                coefficients: &probe[range],
            };
            let size: f64 = test.local(cell).iter().map(|v| v.abs()).sum();
            let scale = size / mesh.h(cell).powi(i32::from(j));
            let value = test.at(x[end], usize::from(j)).unwrap_or(0.0);
            if value.abs() <= 1e-9 * scale {
                continue;
            }
            let eta2 = M::boundary_indicator(k, &x, end, &slices, params, data)?;
            indicators[cell] += eta2;
            sum += eta2;
        }
    }
    Ok(sum)
}

/// `a(u_h, u_h)` with the model's energy form over every primal field (every block
/// between two fields other than the multiplier: a Timoshenko beam's bending and shear
/// together), summed from the element matrices.
///
/// # Errors
/// A model without an energy form.
fn energy_product<M: Model>(
    views: &[FieldView],
    multiplier: usize,
    params: &[f64],
    data: &[&DataFn],
) -> Result<f64> {
    let a = super::energy_form::<M>()?;
    let mut total = 0.0;
    let mut k = Vec::new();
    for (b, block) in M::FORMS[a].blocks.iter().enumerate() {
        let (test, Some(trial)) = (block.test_field, block.trial_field) else {
            continue;
        };
        if test == multiplier || trial == multiplier {
            continue;
        }
        let (u, v) = (&views[test], &views[trial]);
        let (nu, nv) = (u.map.local_count(), v.map.local_count());
        k.resize(nu * nv, 0.0);
        for c in 0..u.mesh.cell_count() {
            let (lu, lv) = (u.local(c), v.local(c));
            M::element_matrix(a, b, &u.mesh.cell(c), params, data, &mut k);
            for i in 0..nu {
                for j in 0..nv {
                    total += lu[i] * k[i * nv + j] * lv[j];
                }
            }
        }
    }
    Ok(total)
}

/// `S = (Σ_T h_T^{−2m} ‖s(ψ − u_h)_+‖²_T + (Σ_T (λ_h, s(u_h − ψ))_T)_+)^{1/2}`.
fn contact_terms<M: Model>(
    u: &FieldView,
    lambda: &FieldView,
    psi: &DataFn,
    side: f64,
) -> ContactTerms {
    let m = super::energy_order::<M>();
    let element = u.map.element();
    let rule = QuadratureRule::exact_for_degree(2 * element.degree() + 2);
    let (u_basis, l_basis) = (
        PhysicalBasis::new(element, 0),
        PhysicalBasis::new(lambda.map.element(), 0),
    );
    let cells = u.mesh.cell_count();
    let (mut violation, mut defect) = (vec![0.0; cells], vec![0.0; cells]);
    for c in 0..cells {
        let cell = u.mesh.cell(c);
        let h = cell[1] - cell[0];
        let (local, multiplier) = (u.local(c), lambda.local(c));
        let mut cell_violation = 0.0;
        for (&xi, &w) in rule.points.iter().zip(&rule.weights) {
            let x = cell[0] + h * xi;
            let gap = side * (u_basis.evaluate(&local, 0, cell, xi) - psi(&[x]));
            cell_violation += w * h * gap.min(0.0).powi(2);
            defect[c] += w * h * l_basis.evaluate(&multiplier, 0, cell, xi) * gap;
        }
        violation[c] = cell_violation * h.powi(-2 * m);
    }
    ContactTerms::of(&violation, &defect)
}
