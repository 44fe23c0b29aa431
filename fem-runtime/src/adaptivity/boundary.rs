//! The estimate on boundary parts: the indicators of the model's `η_Γ²` lines on the
//! edges of each part, and the contact terms of a multiplier that lives on a boundary
//! part (Signorini's `λ` on `Γ_C`), from the model's constraint forms `b` and `G`.

use super::{cell_coefficients, energy_form, TriangleCells};
use crate::element::triangle::{TriangleBasis, TriangleField};
use crate::model::{DataFn, Model};
use crate::obstacle::boundary_multiplier::{
    part_edges, BoundaryMultiplier, BoundaryMultiplierDofs,
};
use crate::obstacle::ObstacleSolution;
use crate::{Error, Result};

/// The multiplier's local coefficients on the cell of edge `k` of its part, as the
/// kernels see a P0 or P1 field: `[Λ_k]` for P0; for P1 the values at the edge's two
/// local vertices and 0 at the third, whose basis function vanishes on the edge.
fn multiplier_on_edge(boundary: &BoundaryMultiplierDofs, k: usize, values: &[f64]) -> Vec<f64> {
    let [a, b] = boundary.edge_dofs[k];
    match boundary.space {
        BoundaryMultiplier::P0 => vec![values[a]],
        BoundaryMultiplier::P1 => {
            let local = boundary.edges[k].local;
            let mut c = vec![0.0; 3];
            c[local] = values[a];
            c[(local + 1) % 3] = values[b];
            c
        }
    }
}

/// The local coefficients of every field on the cell of edge `k` of the multiplier's
/// part, the multiplier's traced from its part.
fn edge_coefficients<M: Model, G>(
    solution: &ObstacleSolution<G>,
    fields: &[Option<TriangleField>],
    boundary: &BoundaryMultiplierDofs,
    k: usize,
) -> Vec<Vec<f64>> {
    let d = &solution.discretization;
    let mut local = cell_coefficients::<M>(fields, boundary.edges[k].cell);
    local[d.multiplier_field] = multiplier_on_edge(boundary, k, solution.field(d.multiplier_field));
    local
}

/// Adds each boundary edge's `η_Γ²` to its cell's entry of `indicators` and returns
/// their sum: the model's boundary lines on the edges of each part (`parts[p]` the
/// markers of `FACET_PARTS[p]`), the multiplier of its part entering by its trace;
/// only the edges whose cells `owned` holds (all where `None`).
///
/// # Errors
/// `parts` not one list per part of the model, and the kernels' errors.
pub(super) fn boundary_indicators<M: Model, G: TriangleCells>(
    solution: &ObstacleSolution<G>,
    fields: &[Option<TriangleField>],
    params: &[f64],
    data: &[&DataFn],
    parts: &[Vec<u32>],
    owned: Option<&[bool]>,
    indicators: &mut [f64],
) -> Result<f64> {
    if parts.is_empty() && M::FACET_PARTS.is_empty() {
        return Ok(0.0);
    }
    if parts.len() != M::FACET_PARTS.len() {
        return Err(Error::Input(format!(
            "model `{}` has {} boundary parts ({}); the estimate was given markers for {}",
            M::NAME,
            M::FACET_PARTS.len(),
            M::FACET_PARTS.join(", "),
            parts.len()
        )));
    }
    let d = &solution.discretization;
    let mesh = d.mesh.straight();
    let mut sum = 0.0;
    for (p, markers) in parts.iter().enumerate() {
        let on_multiplier_part = d.boundary().filter(|b| b.part == p);
        let edges = match on_multiplier_part {
            Some(b) => b.edges.clone(),
            None => part_edges(mesh, markers),
        };
        for (k, e) in edges.iter().enumerate() {
            if !super::counts(owned, e.cell) {
                continue;
            }
            let local = match on_multiplier_part {
                Some(b) => edge_coefficients::<M, G>(solution, fields, b, k),
                None => cell_coefficients::<M>(fields, e.cell),
            };
            let slices: Vec<&[f64]> = local.iter().map(Vec::as_slice).collect();
            let eta2 = M::boundary_indicator(
                p,
                &mesh.cell_coordinates(e.cell),
                e.local,
                &slices,
                params,
                data,
            )?;
            indicators[e.cell] += eta2;
            sum += eta2;
        }
    }
    Ok(sum)
}

/// The contact terms of a multiplier on a boundary part, from the model's constraint
/// `b(v, μ) = (μ, sBv)`, `G(μ) = (μ, sψ)` (`constraint:`): on each edge E of the part,
/// `r_i = b(u_h, μ_i) − G(μ_i) = (μ_i, s(Bu_h − ψ))_E` for the multiplier's local
/// functions; the complementarity defect `Σ_i λ_i r_i = (λ_h, s(Bu_h − ψ))_E`; and where
/// the edge's mean `Σ_i r_i` is negative (u_h crosses ψ on average), the violation as the
/// energy `a_T(v, v)` on the edge's cell of the lifting `v = (−Σ_i r_i) β/|β|²`, `β_j =
/// Σ_i b(φ_j, μ_i)` — the primal function along the constraint's direction whose mean
/// constraint on E equals the violation's (for P1 displacements, the violation at the
/// edge's two nodes along the contact direction). Neighbouring cells that share those
/// nodes carry the lifting too; counting the edge's cell alone changes the term by a
/// bounded factor. Per cell of the mesh, `(violation, defect)`, over the edges whose
/// cells `owned` holds (all where `None`).
///
/// # Errors
/// A model without `constraint:`, a constraint form that is not between the multiplier
/// and a primal field on the multiplier's part, and the kernels' errors.
pub(super) fn boundary_contact_terms<M: Model, G: TriangleCells>(
    solution: &ObstacleSolution<G>,
    fields: &[Option<TriangleField>],
    boundary: &BoundaryMultiplierDofs,
    params: &[f64],
    data: &[&DataFn],
    owned: Option<&[bool]>,
) -> Result<(Vec<f64>, Vec<f64>)> {
    let d = &solution.discretization;
    let mesh = d.mesh.straight();
    let [b, g] = M::CONSTRAINT.ok_or_else(|| {
        Error::Input(format!(
            "model `{}` declares no constraint (`constraint: b, G;`): the contact terms of a multiplier on a boundary part are measured with it",
            M::NAME
        ))
    })?;
    let on_part = |form: usize| {
        M::FACET_BLOCKS
            .iter()
            .enumerate()
            .filter(move |(_, x)| x.form == form && x.part == boundary.part)
    };
    let mut b_blocks = Vec::new();
    for (i, block) in on_part(b) {
        match block.trial_field {
            Some(f) if block.test_field == d.multiplier_field && f != d.multiplier_field => {
                b_blocks.push((i, f));
            }
            _ => {
                return Err(Error::Input(format!(
                    "the constraint form `{}` of model `{}` must pair the multiplier `{}` (test) with primal fields (trial) on `{}`",
                    M::FORMS[b].name,
                    M::NAME,
                    M::FIELDS[d.multiplier_field].name,
                    M::FACET_PARTS[boundary.part]
                )))
            }
        }
    }
    let g_blocks: Vec<usize> = on_part(g).map(|(i, _)| i).collect();
    let a = energy_form::<M>()?;
    let mut violation = vec![0.0; mesh.cell_count()];
    let mut defect = vec![0.0; mesh.cell_count()];
    for k in 0..boundary.edges.len() {
        let edge = boundary.edges[k];
        if !super::counts(owned, edge.cell) {
            continue;
        }
        let x = mesh.cell_coordinates(edge.cell);
        let local = edge_coefficients::<M, G>(solution, fields, boundary, k);
        let lambda = &local[d.multiplier_field];
        let mut r = vec![0.0; lambda.len()];
        // β per primal field, over its local DOFs
        let mut beta: Vec<Vec<f64>> = local.iter().map(|c| vec![0.0; c.len()]).collect();
        for &(block, f) in &b_blocks {
            let n = local[f].len();
            let mut out = vec![0.0; r.len() * n];
            M::facet_matrix(block, &x, edge.local, params, data, &mut out)?;
            for (i, ri) in r.iter_mut().enumerate() {
                for j in 0..n {
                    *ri += out[i * n + j] * local[f][j];
                    beta[f][j] += out[i * n + j];
                }
            }
        }
        for &block in &g_blocks {
            let mut out = vec![0.0; r.len()];
            M::facet_vector(block, &x, edge.local, params, data, &mut out)?;
            for (ri, gi) in r.iter_mut().zip(&out) {
                *ri -= gi;
            }
        }
        defect[edge.cell] += lambda.iter().zip(&r).map(|(l, r)| l * r).sum::<f64>();
        let mean: f64 = r.iter().sum();
        let norm2: f64 = beta.iter().flatten().map(|b| b * b).sum();
        if mean < 0.0 && norm2 > 0.0 {
            let t = -mean / norm2;
            let v: Vec<Vec<f64>> = beta
                .iter()
                .map(|b| b.iter().map(|b| t * b).collect())
                .collect();
            violation[edge.cell] += cell_energy::<M, G>(&d.mesh, edge.cell, a, &v, params, data)?;
        }
    }
    Ok((violation, defect))
}

/// `a_T(v, v)` on cell `c` of the local coefficients `v` (one vector per field; the
/// multiplier's and other zero vectors add nothing) with form `a`'s blocks.
///
/// # Errors
/// Those of the element matrices ([`TriangleCells::cell_matrix`]).
fn cell_energy<M: Model, G: TriangleCells>(
    mesh: &G,
    c: usize,
    a: usize,
    v: &[Vec<f64>],
    params: &[f64],
    data: &[&DataFn],
) -> Result<f64> {
    let mut energy = 0.0;
    for (index, block) in M::FORMS[a].blocks.iter().enumerate() {
        let (test, Some(trial)) = (block.test_field, block.trial_field) else {
            continue;
        };
        let (u, w) = (&v[test], &v[trial]);
        if u.iter().all(|&x| x == 0.0) || w.iter().all(|&x| x == 0.0) {
            continue;
        }
        let mut k = vec![0.0; u.len() * w.len()];
        mesh.cell_matrix::<M>(a, index, c, params, data, &mut k)?;
        for (i, ui) in u.iter().enumerate() {
            for (j, wj) in w.iter().enumerate() {
                energy += ui * k[i * w.len() + j] * wj;
            }
        }
    }
    Ok(energy)
}

/// Adds the natural boundary terms ([`Model::NATURAL_FLUXES`]) to each boundary edge's
/// cell entry of `indicators` and returns their sum: on every boundary edge outside the
/// boundary parts (`parts`, which have their own lines), the flux of each test
/// coordinate that is free on the edge, one-sided. A coordinate is free where the
/// discrete test functions' edge means do not all vanish (`j = 0`: of their trace;
/// `j = 1`: of their normal derivative), found with one admissible test function of
/// random free DOFs ([`super::admissible_probe`], [`free_on_edge`]): exact for any element and
/// any support, a clamp, a roller along x or y, a simple support of a plate. Only the
/// edges whose cells `owned` holds (all where `None`).
///
/// # Errors
/// The kernels' errors.
pub(super) fn natural_indicators<M: Model, G: TriangleCells>(
    solution: &ObstacleSolution<G>,
    fields: &[Option<TriangleField>],
    params: &[f64],
    data: &[&DataFn],
    parts: &[Vec<u32>],
    owned: Option<&[bool]>,
    indicators: &mut [f64],
) -> Result<f64> {
    if M::NATURAL_FLUXES.is_empty() {
        return Ok(0.0);
    }
    let d = &solution.discretization;
    let mesh = d.mesh.straight();
    let on_parts: std::collections::HashSet<usize> = parts
        .iter()
        .flat_map(|markers| part_edges(mesh, markers))
        .map(|e| e.edge)
        .collect();
    let probe = super::admissible_probe(solution);
    let mut sum = 0.0;
    for &(e, _) in mesh.boundary_edges() {
        if on_parts.contains(&e) {
            continue;
        }
        let (cell, _) = mesh.edge_cells(e);
        if !super::counts(owned, cell) {
            continue;
        }
        let local = mesh
            .local_edge(cell, e)
            .expect("an edge is an edge of its cell");
        let coefficients = cell_coefficients::<M>(fields, cell);
        let slices: Vec<&[f64]> = coefficients.iter().map(Vec::as_slice).collect();
        for (k, &(field, j)) in M::NATURAL_FLUXES.iter().enumerate() {
            let Some((map, range)) = d.dofs.map(field).zip(d.dofs.range(field)) else {
                continue;
            };
            let test = TriangleField {
                mesh,
                map,
                coefficients: &probe[range],
            };
            if !free_on_edge(&test, cell, local, j) {
                continue;
            }
            let eta2 = M::boundary_indicator(
                M::FACET_PARTS.len() + k,
                &mesh.cell_coordinates(cell),
                local,
                &slices,
                params,
                data,
            )?;
            indicators[cell] += eta2;
            sum += eta2;
        }
    }
    Ok(sum)
}

/// Whether the test function `test` has a trace (`j = 0`) or normal derivative
/// (`j = 1`) of nonzero mean on local edge `edge` of cell `c` (3-point Gauss, exact for
/// Argyris's quintic trace), against the size of its coefficients on the cell (a fixed
/// DOF's rotation leaves rounding). The mean, not the values: a nonconforming element
/// holds only moments (Morley's clamp fixes the mean normal derivative of an edge, whose
/// quadratic test functions still tilt it along the edge); for a random conforming test
/// function a nonzero trace has a zero mean with probability 0.
fn free_on_edge(test: &TriangleField, c: usize, edge: usize, j: u8) -> bool {
    let element = test.map.element();
    let basis = TriangleBasis::new(element);
    let corners = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
    let (a, b) = (corners[edge], corners[(edge + 1) % 3]);
    let mesh = test.mesh;
    let size: f64 = test
        .map
        .cell_dofs(c)
        .iter()
        .map(|&dof| test.coefficients[dof].abs())
        .sum();
    let x = mesh.cell(c).map(|v| mesh.vertices()[v]);
    let (p, q) = (x[edge], x[(edge + 1) % 3]);
    let length = (q[0] - p[0]).hypot(q[1] - p[1]);
    let normal = [(q[1] - p[1]) / length, (p[0] - q[0]) / length];
    let map = crate::element::triangle::AffineMap::of(mesh, c);
    let g = 0.15f64.sqrt();
    let rule = [
        (0.5 - g, 5.0 / 18.0),
        (0.5, 8.0 / 18.0),
        (0.5 + g, 5.0 / 18.0),
    ];
    let mean: f64 = rule
        .iter()
        .map(|&(s, w)| {
            let xi = [a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])];
            let value = if j == 0 {
                test.value(&basis, c, xi)
            } else {
                let g = test.gradient(&basis, &map, c, xi);
                g[0] * normal[0] + g[1] * normal[1]
            };
            w * value
        })
        .sum();
    let scale = if j == 0 { size } else { size / length };
    mean.abs() > 1e-9 * scale
}
