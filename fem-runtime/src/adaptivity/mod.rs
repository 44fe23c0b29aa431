//! A-posteriori estimation and adaptive refinement (`docs/adaptivity.md`).
//!
//! A model declares its residual estimator in its model file (`estimator:`); the macro
//! generates the cell and edge indicator kernels. This module sums them over a mesh
//! ([`triangle_estimate`]), adds the contact terms every obstacle problem has (the
//! violation `s(ψ − u_h)_+` in the energy norm and the complementarity defect
//! `(Σ_T (λ_h, s(u_h − ψ))_T)_+^{1/2}`, `../shared/MODELS.md` §8), marks cells
//! ([`Marking`]) and drives the adaptive loop of [`crate::problem::Problem::solve_adaptive`].

mod boundary;
mod interval;
pub mod marking;

pub use interval::interval_estimate;

pub use marking::Marking;

use crate::element::triangle::{TriangleBasis, TriangleField};
use crate::mesh::{Cells, CurvedTriangleMesh, TriangleMesh};
use crate::model::{DataFn, Model};
use crate::obstacle::{Multipliers, ObstacleSolution};
use crate::{Error, Result};
use fem_reference::triangle::TriangleRule;
use fem_reference::ElementKind;

/// One level of an adaptive solve, as the report lists it.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct AdaptiveLevel {
    /// Cells of the level's mesh.
    pub cells: usize,
    /// Unknowns solved for (primal and multiplier, fixed DOFs eliminated).
    pub dofs: usize,
    /// `(η² + S²)^{1/2}`.
    pub estimate: f64,
    /// `S`.
    pub estimate_contact: f64,
    /// `‖u_h‖_a`.
    pub energy_norm: f64,
    /// The error in the estimator's norm, where an exact solution is known.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error_energy: Option<f64>,
    /// Wall time of the level's solve and estimate, in seconds.
    pub seconds: f64,
}

/// How [`crate::problem::Problem::solve_adaptive`] refines.
#[derive(Clone, Debug)]
pub struct AdaptiveOptions {
    /// Stop when `(η² + S²)^{1/2} ≤ tolerance · ‖u_h‖_a`.
    pub tolerance: f64,
    /// How cells are marked.
    pub marking: Marking,
    /// Refuse to solve a level with more unknowns than this (the loop then fails with
    /// how far it got).
    pub max_dofs: usize,
    /// A boundary layer the mesh must resolve whatever the estimate says: the loop also
    /// refines the cells on its boundary edges until they are no longer than its width,
    /// and stops only when both the tolerance is met and the layer is resolved.
    pub boundary_layer: Option<BoundaryLayer>,
}

impl Default for AdaptiveOptions {
    fn default() -> Self {
        Self {
            tolerance: 1e-2,
            marking: Marking::default(),
            max_dofs: 2_000_000,
            boundary_layer: None,
        }
    }
}

/// A boundary layer to resolve: a quantity asked for on the boundary (a Reissner–Mindlin
/// plate's twisting moment and shear force along an edge where its rotations are free)
/// varies across a strip of width `width` along the boundary edges of `markers`, which
/// an energy estimate, its share of the energy being small, does not refine for.
#[derive(Clone, Debug, PartialEq)]
pub struct BoundaryLayer {
    /// The layer's width (length units of the mesh): the longest boundary edge allowed
    /// on its part of the boundary (a Reissner–Mindlin plate's `t/√(12κ)`).
    pub width: f64,
    /// The boundary markers of the edges it lies along.
    pub markers: Vec<u32>,
}

/// A discrete solution's a-posteriori estimate.
#[derive(Clone, Debug, Default)]
pub struct Estimate {
    /// Per cell, what marking ranks: its `η_T²`, half of `η_E²` of each of its interior
    /// edges, and its share of `S²` (its violation and complementarity defect).
    pub indicators: Vec<f64>,
    /// `η = (Σ_T η_T² + Σ_E η_E²)^{1/2}`: the residual part.
    pub residual: f64,
    /// `S = (‖I_h s(ψ − u_h)_+‖_a² + (Σ_T (λ_h, s(u_h − ψ))_T)_+)^{1/2}`: the contact
    /// part (`I_h` the nodal interpolant into the constrained field's space; for
    /// Argyris and Morley, without nodes, `Σ_T h_T^{−2m} ‖s(ψ − u_h)_+‖²_T` with `m`
    /// the energy's derivative order replaces the first term).
    pub contact: f64,
    /// `‖u_h‖_a = a(u_h, u_h)^{1/2}` with the model's energy form over every primal
    /// field: what a relative tolerance is relative to.
    pub energy_norm: f64,
}

impl Estimate {
    /// The estimate from the cells' residual indicators (`indicators`, summing to
    /// `residual2`), the contact terms and `‖u_h‖_a`: each cell's share of `S²` joins its
    /// indicator, so that marking refines where the contact terms are large too (a point
    /// contact's complementarity defect sits on the few cells around the point, where the
    /// residual indicators may be small).
    fn of(
        mut indicators: Vec<f64>,
        residual2: f64,
        contact: ContactTerms,
        energy_norm: f64,
    ) -> Self {
        for (i, c) in indicators.iter_mut().zip(&contact.cells) {
            *i += c;
        }
        Self {
            indicators,
            residual: residual2.max(0.0).sqrt(),
            contact: contact.total,
            energy_norm,
        }
    }

    /// `(η² + S²)^{1/2}`: the bound on the error (up to a constant) that the reliability
    /// of the estimator gives.
    pub fn total(&self) -> f64 {
        self.residual.hypot(self.contact)
    }
}

/// The triangle meshes the estimate runs on: affine triangles, and isoparametric ones
/// whose indicators are those of their straight cells (the generated indicator kernels
/// are affine; a curved cell's map differs from its straight one's by O(hκ), relative,
/// for a boundary of curvature κ) while the energy norm takes each cell's own element matrix.
pub trait TriangleCells: crate::mesh::Mesh {
    /// The mesh of the vertices with straight cells.
    fn straight(&self) -> &TriangleMesh;

    /// The element matrix of block `block` of form `form` on cell `c`, as the assembly
    /// computes it, row-major into `out`.
    ///
    /// # Errors
    /// Those of the curved kernels (an element without them).
    fn cell_matrix<M: Model>(
        &self,
        form: usize,
        block: usize,
        c: usize,
        params: &[f64],
        data: &[&DataFn],
        out: &mut [f64],
    ) -> Result<()>;
}

impl TriangleCells for TriangleMesh {
    fn straight(&self) -> &TriangleMesh {
        self
    }

    fn cell_matrix<M: Model>(
        &self,
        form: usize,
        block: usize,
        c: usize,
        params: &[f64],
        data: &[&DataFn],
        out: &mut [f64],
    ) -> Result<()> {
        M::element_matrix_on_cell(
            form,
            block,
            &self.cell_coordinates(c),
            &self.cell(c),
            params,
            data,
            out,
        );
        Ok(())
    }
}

impl TriangleCells for CurvedTriangleMesh {
    fn straight(&self) -> &TriangleMesh {
        self.mesh()
    }

    fn cell_matrix<M: Model>(
        &self,
        form: usize,
        block: usize,
        c: usize,
        params: &[f64],
        data: &[&DataFn],
        out: &mut [f64],
    ) -> Result<()> {
        if self.is_curved(c) {
            M::element_matrix_curved(form, block, &self.cell_nodes(c), params, data, out)
        } else {
            self.mesh()
                .cell_matrix::<M>(form, block, c, params, data, out)
        }
    }
}

/// The local coefficients of every field on cell `c` in the pulled-back reference basis
/// (the field's own for Lagrange elements); zeros for a multiplier on a boundary part
/// (`None`), which has no values on the cells.
fn cell_coefficients<M: Model>(fields: &[Option<TriangleField>], c: usize) -> Vec<Vec<f64>> {
    fields
        .iter()
        .zip(M::FIELDS)
        .map(|(f, info)| match f {
            Some(f) => f.reference_coefficients(c),
            None => vec![0.0; info.element.triangle_basis().len()],
        })
        .collect()
}

/// The fields of a solution on a triangle mesh (`None` for a multiplier on a boundary
/// part). The nodal method's multiplier field is `density`, its nodal forces' density
/// ([`crate::obstacle::nodal::force_density_at_vertices`]) on the primal field's P1 DOFs.
///
/// # Errors
/// The nodal method's solution of a model without a P1 multiplier field (its forces have
/// no field for the kernels to read), and a field without DOFs on the cells.
fn fields<'a, M: Model, G: TriangleCells>(
    solution: &'a ObstacleSolution<G>,
    density: Option<&'a [f64]>,
) -> Result<Vec<Option<TriangleField<'a>>>> {
    let d = &solution.discretization;
    let multiplier = multiplier_index::<M, G>(solution);
    if matches!(d.multipliers, Multipliers::Nodal) {
        let (Some(map), Some(density), true) =
            (d.dofs.map(0), density, multiplier < M::FIELDS.len())
        else {
            return Err(Error::Input(format!(
                "model `{}`: the nodal method's estimate needs a P1 multiplier field in the model (the density of its nodal forces)",
                M::NAME
            )));
        };
        let field = |coefficients| {
            Some(TriangleField {
                mesh: d.mesh.straight(),
                map,
                coefficients,
            })
        };
        return Ok(vec![field(solution.field(0)), field(density)]);
    }
    (0..M::FIELDS.len())
        .map(|f| {
            if f == d.multiplier_field && d.boundary().is_some() {
                return Ok(None);
            }
            let map = d.dofs.map(f).ok_or_else(|| {
                Error::Input(format!(
                    "model `{}`: field `{}` has no DOFs on the cells",
                    M::NAME,
                    M::FIELDS[f].name
                ))
            })?;
            Ok(Some(TriangleField {
                mesh: d.mesh.straight(),
                map,
                coefficients: solution.field(f),
            }))
        })
        .collect()
}

/// The estimate of `solution` with the model's `estimator:` kernels and the contact
/// terms, for parameters `params` and data `data` as solved with; `side` is the
/// obstacle's sign `s` (1: `u ≥ ψ`), `None` for a problem solved without its constraint
/// (no contact terms); `parts` the boundary markers of each of the model's
/// `FACET_PARTS` (empty for a model without boundary parts), whose edges take the
/// estimator's boundary terms (`η_Γ_C²`).
///
/// # Errors
/// A model without an estimator or an energy form, a multiplier on a boundary part of a
/// model without a constraint (`constraint: b, G;`), `parts` not one list per part,
/// and indicators that are not finite (the message names the cell).
pub fn triangle_estimate<M: Model, G: TriangleCells>(
    solution: &ObstacleSolution<G>,
    params: &[f64],
    data: &[&DataFn],
    side: Option<f64>,
    parts: &[Vec<u32>],
) -> Result<Estimate> {
    require_estimator::<M>()?;
    let d = &solution.discretization;
    let density = matches!(d.multipliers, Multipliers::Nodal).then(|| {
        crate::obstacle::nodal::force_density_at_vertices(
            d.mesh.straight(),
            d.reduction.free(),
            solution.multiplier_values(),
        )
    });
    let fields = fields::<M, G>(solution, density.as_deref())?;
    // each process its own cells and their facets (an interior edge counted by the
    // process of its first cell), the per-cell terms then added up over the processes
    let evaluation = d.evaluation();
    let owned = evaluation.owned();
    let on = Own {
        cells: evaluation.cells(),
        owned: owned.as_deref(),
    };
    let mut local = evaluation.agree(local_estimate::<M, G>(
        solution, &fields, params, data, side, parts, on,
    ))?;
    for terms in [
        &mut local.indicators,
        &mut local.violation,
        &mut local.defect,
    ] {
        evaluation.sum_each(terms);
    }
    let [residual2, energy] = evaluation.sum([local.residual2, local.energy]);
    let indicators = local.indicators;
    if let Some(c) = indicators.iter().position(|e| !e.is_finite()) {
        return Err(Error::Input(format!(
            "the indicator of cell {c} is {}: the solution or the data are not finite there",
            indicators[c]
        )));
    }
    Ok(Estimate::of(
        indicators,
        residual2,
        ContactTerms::of(&local.violation, &local.defect),
        energy.max(0.0).sqrt(),
    ))
}

/// The cells one process evaluates ([`crate::obstacle::Evaluation`]): the list, and per
/// cell of the mesh whether it is one (`None`: every cell).
#[derive(Clone, Copy)]
struct Own<'a> {
    cells: Cells<'a>,
    owned: Option<&'a [bool]>,
}

/// Whether cell `c` is one of the cells `owned` marks (every cell where `None`).
fn counts(owned: Option<&[bool]>, c: usize) -> bool {
    owned.is_none_or(|owned| owned[c])
}

/// One process's share of an estimate: per cell of the whole mesh its residual
/// indicator (with half of each interior edge's), violation and complementarity defect
/// (both empty without contact terms), and the sums of the residual terms and of
/// `a(u_h, u_h)` over its cells.
struct LocalEstimate {
    indicators: Vec<f64>,
    residual2: f64,
    violation: Vec<f64>,
    defect: Vec<f64>,
    energy: f64,
}

/// [`LocalEstimate`] over the cells `on`.
fn local_estimate<M: Model, G: TriangleCells>(
    solution: &ObstacleSolution<G>,
    fields: &[Option<TriangleField>],
    params: &[f64],
    data: &[&DataFn],
    side: Option<f64>,
    parts: &[Vec<u32>],
    on: Own<'_>,
) -> Result<LocalEstimate> {
    let mesh = solution.discretization.mesh.straight();
    let mut indicators = vec![0.0; mesh.cell_count()];
    let mut sum = 0.0;
    for c in on.cells.iter() {
        let local = cell_coefficients::<M>(fields, c);
        let slices: Vec<&[f64]> = local.iter().map(Vec::as_slice).collect();
        let eta2 = M::cell_indicator(&mesh.cell_coordinates(c), &slices, params, data)?;
        indicators[c] += eta2;
        sum += eta2;
    }
    for (e, _) in mesh.edges().iter().enumerate() {
        let (c0, Some(c1)) = mesh.edge_cells(e) else {
            continue;
        };
        if !counts(on.owned, c0) {
            continue;
        }
        let local_edge = |c: usize| {
            mesh.local_edge(c, e)
                .expect("an edge is an edge of its cells")
        };
        let (a, b) = (
            cell_coefficients::<M>(fields, c0),
            cell_coefficients::<M>(fields, c1),
        );
        let a: Vec<&[f64]> = a.iter().map(Vec::as_slice).collect();
        let b: Vec<&[f64]> = b.iter().map(Vec::as_slice).collect();
        let eta2 = M::edge_indicator(
            &mesh.cell_coordinates(c0),
            local_edge(c0),
            &a,
            &mesh.cell_coordinates(c1),
            local_edge(c1),
            &b,
            params,
            data,
        )?;
        indicators[c0] += 0.5 * eta2;
        indicators[c1] += 0.5 * eta2;
        sum += eta2;
    }
    sum += boundary::boundary_indicators::<M, G>(
        solution,
        fields,
        params,
        data,
        parts,
        on.owned,
        &mut indicators,
    )?;
    sum += boundary::natural_indicators::<M, G>(
        solution,
        fields,
        params,
        data,
        parts,
        on.owned,
        &mut indicators,
    )?;
    let (violation, defect, energy) =
        contact_terms::<M, G>(solution, fields, params, data, side, on)?;
    Ok(LocalEstimate {
        indicators,
        residual2: sum,
        violation,
        defect,
        energy,
    })
}

/// An error for a model without an `estimator:` section.
pub(crate) fn require_estimator<M: Model>() -> Result<()> {
    if M::HAS_ESTIMATOR {
        Ok(())
    } else {
        Err(Error::Input(format!(
            "model `{}` declares no estimator (`estimator:` in its model file)",
            M::NAME
        )))
    }
}

/// The index of the model's energy form (`energy: a, ℓ;`).
///
/// # Errors
/// A model without an energy form: the energy norm needs it.
pub(crate) fn energy_form<M: Model>() -> Result<usize> {
    M::ENERGY.map(|[a, _]| a).ok_or_else(|| {
        Error::Input(format!(
            "model `{}` declares no energy form (`energy: a, ℓ;`): the energy norm needs it",
            M::NAME
        ))
    })
}

/// The energy form of the model and its (`field`, `field`) block.
///
/// # Errors
/// A model without an energy form, or whose energy form has no such block.
fn energy_block<M: Model>(field: usize) -> Result<(usize, usize)> {
    let a = energy_form::<M>()?;
    let block = M::FORMS[a]
        .blocks
        .iter()
        .position(|b| b.test_field == field && b.trial_field == Some(field))
        .ok_or_else(|| {
            Error::Input(format!(
                "the energy form `{}` of model `{}` has no block of field `{}` against itself",
                M::FORMS[a].name,
                M::NAME,
                M::FIELDS[field].name
            ))
        })?;
    Ok((a, block))
}

/// `a(v, v)` of the coefficient vector `v` of `field` with the model's energy form,
/// summed cell by cell from its element matrices.
///
/// # Errors
/// A model without an energy form, or whose energy form has no (field, field) block.
pub fn energy_product<M: Model, G: TriangleCells>(
    mesh: &G,
    map: &crate::assembly::dof_map::DofMap,
    field: usize,
    v: &[f64],
    params: &[f64],
    data: &[&DataFn],
) -> Result<f64> {
    let cells = Cells::All(mesh.straight().cell_count());
    Ok(
        cell_energies::<M, G>(mesh, map, field, v, params, data, cells)?
            .iter()
            .sum(),
    )
}

/// Each cell's `v_Tᵀ K_T v_T` of [`energy_product`] (its share of `a(v, v)`), on the
/// cells `cells` (0 on the others).
///
/// # Errors
/// As [`energy_product`].
fn cell_energies<M: Model, G: TriangleCells>(
    mesh: &G,
    map: &crate::assembly::dof_map::DofMap,
    field: usize,
    v: &[f64],
    params: &[f64],
    data: &[&DataFn],
    cells: Cells<'_>,
) -> Result<Vec<f64>> {
    let (a, block) = energy_block::<M>(field)?;
    let mut energies = vec![0.0; mesh.straight().cell_count()];
    add_block_energies::<M, G>(
        mesh,
        [a, block],
        [(map, v), (map, v)],
        params,
        data,
        cells,
        &mut energies,
    )?;
    Ok(energies)
}

/// The contact part of the estimate: `S² = violation + (Σ_T defect_T)_+`, and each
/// cell's share of it (its violation and its defect's positive part), which marking
/// adds to the cell's indicator.
#[derive(Clone, Debug, Default)]
struct ContactTerms {
    /// `S`.
    total: f64,
    /// Per cell, its share of `S²`.
    cells: Vec<f64>,
}

impl ContactTerms {
    /// From each cell's violation and complementarity defect.
    fn of(violation: &[f64], defect: &[f64]) -> Self {
        let sum_violation: f64 = violation.iter().sum();
        let sum_defect: f64 = defect.iter().sum();
        Self {
            total: (sum_violation.max(0.0) + sum_defect.max(0.0)).sqrt(),
            cells: violation
                .iter()
                .zip(defect)
                .map(|(v, d)| v.max(0.0) + d.max(0.0))
                .collect(),
        }
    }
}

/// Adds to the entry of each cell of `cells` in `energies` its `u_Tᵀ K_T v_T` for block
/// `[form, block]` of the model's forms, `u` and `v` the (map, coefficients) of the
/// block's test and trial fields; cells where either vanishes are skipped.
///
/// # Errors
/// Those of the element matrices ([`TriangleCells::cell_matrix`]).
fn add_block_energies<M: Model, G: TriangleCells>(
    mesh: &G,
    [form, block]: [usize; 2],
    [(map_u, u), (map_v, v)]: [(&crate::assembly::dof_map::DofMap, &[f64]); 2],
    params: &[f64],
    data: &[&DataFn],
    cells: Cells<'_>,
    energies: &mut [f64],
) -> Result<()> {
    let (nu, nv) = (map_u.local_count(), map_v.local_count());
    let mut k = vec![0.0; nu * nv];
    for c in cells.iter() {
        let energy = &mut energies[c];
        let (du, dv) = (map_u.cell_dofs(c), map_v.cell_dofs(c));
        if du.iter().all(|&d| u[d] == 0.0) || dv.iter().all(|&d| v[d] == 0.0) {
            continue;
        }
        mesh.cell_matrix::<M>(form, block, c, params, data, &mut k)?;
        for (i, &di) in du.iter().enumerate() {
            for (j, &dj) in dv.iter().enumerate() {
                *energy += u[di] * k[i * nv + j] * v[dj];
            }
        }
    }
    Ok(())
}

/// `a(u_h, u_h)` with the model's energy form over every primal field (every block of
/// the form between two fields other than the multiplier): the plate's bending and shear
/// energy together, where a field alone (w's shear block) would be no norm of the plate.
/// Summed over the cells `cells`.
///
/// # Errors
/// A model without an energy form, or whose energy form has no block.
fn solution_energy<M: Model, G: TriangleCells>(
    mesh: &G,
    fields: &[Option<TriangleField>],
    multiplier: usize,
    params: &[f64],
    data: &[&DataFn],
    cells: Cells<'_>,
) -> Result<f64> {
    let a = energy_form::<M>()?;
    let mut energies = vec![0.0; mesh.straight().cell_count()];
    for (b, block) in M::FORMS[a].blocks.iter().enumerate() {
        let (test, Some(trial)) = (block.test_field, block.trial_field) else {
            continue;
        };
        if test == multiplier || trial == multiplier {
            continue;
        }
        let (Some(u), Some(v)) = (&fields[test], &fields[trial]) else {
            continue;
        };
        add_block_energies::<M, G>(
            mesh,
            [a, b],
            [(u.map, u.coefficients), (v.map, v.coefficients)],
            params,
            data,
            cells,
            &mut energies,
        )?;
    }
    Ok(energies.iter().sum())
}

/// The model's field that is the multiplier: the discretization's, or for the nodal
/// method (whose multipliers are its nodal forces, on no field) the model's nonnegative
/// field, their density; `M::FIELDS.len()` where there is none.
fn multiplier_index<M: Model, G>(solution: &ObstacleSolution<G>) -> usize {
    let d = &solution.discretization;
    match d.multipliers {
        Multipliers::Nodal => M::FIELDS
            .iter()
            .position(|f| f.nonnegative)
            .unwrap_or(M::FIELDS.len()),
        _ => d.multiplier_field,
    }
}

/// The contact terms of the estimate on the cells `on`, per cell of the mesh (0 on the
/// others): `(violation, defect)`, both empty without contact terms; and `a(u_h, u_h)`
/// summed over those cells.
fn contact_terms<M: Model, G: TriangleCells>(
    solution: &ObstacleSolution<G>,
    fields: &[Option<TriangleField>],
    params: &[f64],
    data: &[&DataFn],
    side: Option<f64>,
    on: Own<'_>,
) -> Result<(Vec<f64>, Vec<f64>, f64)> {
    let d = &solution.discretization;
    let cells = &d.mesh;
    let mesh = cells.straight();
    let multiplier = multiplier_index::<M, G>(solution);
    let energy = solution_energy::<M, G>(cells, fields, multiplier, params, data, on.cells)?;
    if let (Some(b), Some(_)) = (d.boundary(), side) {
        let (violation, defect) =
            boundary::boundary_contact_terms::<M, G>(solution, fields, b, params, data, on.owned)?;
        return Ok((violation, defect, energy));
    }
    let (Some([_, psi]), Some(side)) = (M::OBSTACLE, side) else {
        return Ok((Vec::new(), Vec::new(), energy));
    };
    let field = M::constrained_field();
    let (Some(u), Some(Some(lambda))) = (&fields[field], fields.get(multiplier)) else {
        return Err(Error::Input(format!(
            "model `{}`: the constrained field or the multiplier has no values on the cells",
            M::NAME
        )));
    };
    let psi = data[psi];
    let element = u.map.element();
    let violation = if matches!(element, ElementKind::P1 | ElementKind::P2 | ElementKind::P3) {
        // ‖I_h s(ψ − u_h)_+‖_a
        let violation: Vec<f64> = u
            .map
            .nodes(mesh)
            .iter()
            .zip(u.coefficients)
            .map(|(x, &value)| (side * (psi(x) - value)).max(0.0))
            .collect();
        cell_energies::<M, G>(cells, u.map, field, &violation, params, data, on.cells)?
    } else {
        weighted_violation::<M>(mesh, u, psi, side, on.cells)
    };
    // Σ_T (λ_h, s(u_h − ψ))_T
    let degree = u.map.element().degree() + lambda.map.element().degree() + 2;
    let rule = TriangleRule::exact_for_degree(degree);
    let (u_basis, l_basis) = (
        TriangleBasis::new(element),
        TriangleBasis::new(lambda.map.element()),
    );
    let mut defect = vec![0.0; mesh.cell_count()];
    for c in on.cells.iter() {
        let defect = &mut defect[c];
        let x = mesh.cell_coordinates(c);
        let area2 = ((x[2] - x[0]) * (x[5] - x[1]) - (x[4] - x[0]) * (x[3] - x[1])).abs();
        for (xi, w) in rule.points.iter().zip(&rule.weights) {
            let l = lambda.value(&l_basis, c, *xi);
            if l == 0.0 {
                continue;
            }
            let p = [
                x[0] + (x[2] - x[0]) * xi[0] + (x[4] - x[0]) * xi[1],
                x[1] + (x[3] - x[1]) * xi[0] + (x[5] - x[1]) * xi[1],
            ];
            *defect += w * area2 * l * side * (u.value(&u_basis, c, *xi) - psi(&p));
        }
    }
    Ok((violation, defect, energy))
}

/// `Σ_T h_T^{−2m} ‖s(ψ − u_h)_+‖²_T`, `m` the energy's derivative order ([`energy_order`]): the
/// violation for fields without Lagrange nodes (Argyris, Morley), where the nodal
/// interpolant of the positive part does not exist; the inverse inequality scales the
/// L² norm of a discrete function to its energy norm this way (with unit coefficient).
/// Per cell of `cells` (0 on the others).
fn weighted_violation<M: Model>(
    mesh: &TriangleMesh,
    u: &TriangleField,
    psi: &DataFn,
    side: f64,
    cells: Cells<'_>,
) -> Vec<f64> {
    let m = energy_order::<M>();
    let element = u.map.element();
    let rule = TriangleRule::exact_for_degree(2 * element.degree() + 2);
    let basis = TriangleBasis::new(element);
    let mut violation = vec![0.0; mesh.cell_count()];
    for c in cells.iter() {
        let total = &mut violation[c];
        let x = mesh.cell_coordinates(c);
        let area2 = ((x[2] - x[0]) * (x[5] - x[1]) - (x[4] - x[0]) * (x[3] - x[1])).abs();
        let mut cell = 0.0;
        for (xi, w) in rule.points.iter().zip(&rule.weights) {
            let p = [
                x[0] + (x[2] - x[0]) * xi[0] + (x[4] - x[0]) * xi[1],
                x[1] + (x[3] - x[1]) * xi[0] + (x[5] - x[1]) * xi[1],
            ];
            let v = (side * (psi(&p) - u.value(&basis, c, *xi))).max(0.0);
            cell += w * area2 * v * v;
        }
        *total = cell * mesh.cell_diameter(c).powi(-2 * m);
    }
    violation
}

/// A full coefficient vector of an admissible homogeneous test function: each free DOF
/// (in the primed numbering of the discretization's change of basis) a pseudo-random
/// number in [0.5, 1.5), each fixed one 0, mapped to the Cartesian DOFs. Its trace
/// vanishes exactly on the edges where the supports hold every test function at 0.
pub(crate) fn admissible_probe<G>(solution: &ObstacleSolution<G>) -> Vec<f64> {
    let d = &solution.discretization;
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut full = vec![0.0; d.dofs.dof_count()];
    for &dof in d.reduction.free() {
        if dof < full.len() {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            full[dof] = 0.5 + (state >> 11) as f64 / (1u64 << 53) as f64;
        }
    }
    d.basis.to_cartesian(&mut full);
    full
}

/// The order `m` of the energy seminorm `|w|_m` of the constrained field, by which the
/// violation `h^{−2m} ‖(ψ − w_h)_+‖²` is scaled to the energy's units:
/// [`Model::CONSTRAINED_ORDER`], else half the operator's order (at least 1). Not the
/// stabilization's order: Timoshenko's is 4 while its deflection's energy is `|w|_1`,
/// and an `h⁻⁴` weight would keep a P1 deflection's O(h²) dip between the nodes at a
/// constant share of the estimate under refinement.
pub(crate) fn energy_order<M: Model>() -> i32 {
    match M::CONSTRAINED_ORDER {
        0 => i32::from(M::ORDER / 2).max(1),
        m => i32::from(m),
    }
}
