//! Multipliers on a boundary part: the discretization of a model whose multiplier lives
//! on the edges of one of its boundary parts (`facets:`), as Signorini contact's does on
//! `Γ_C` (docs/contact.md). It yields the same [`Discretization`] as a multiplier on the
//! cells, so the same solvers, nested iteration, checks and reports serve both.
//!
//! The model declares its multiplier as a P0 field (`λ: P0 >= 0`) and integrates it
//! only in boundary integrals `∫_Γ_C … ds`; here it gets one DOF per edge of the part (the
//! edge's P0 function), not one per cell. Declared P1 (`λ: P1 >= 0`) it is continuous
//! and piecewise linear on the part: one DOF per vertex of its edges
//! ([`BoundaryMultiplierDofs::vertices`]); its `C` block is lumped (see
//! [`discretize`]). From `B_h` and `L_h` (cell and facet blocks),
//!
//! ```text
//! A = (v, u) blocks,  B = −(μ, u) blocks,  C = −(μ, λ) blocks,  F = ℓ part,  G = −(μ part of L_h)
//! ```
//!
//! the LCP `A U − Bᵀ Λ = F, 0 ≤ Λ ⊥ B U + C Λ − G ≥ 0` of [`crate::lcp`] (semismooth
//! Newton needs `C > 0`, i.e. α > 0; the plain method `α = 0` goes to the QP).

use crate::assembly::boundary::{Constraints, DirichletPart};
use crate::assembly::change_of_basis::ChangeOfBasis;
use crate::assembly::dof_map::SystemDofs;
use crate::assembly::{assemble_vector, MatrixAssembler};
use crate::error::{Error, Result};
use crate::lcp::{ConstraintRows, Lcp};
use crate::mesh::TriangleMesh;
use crate::model::{Coefficients, FacetBlockInfo, IntoFieldIndex, IntoPartIndex, Model};
use crate::obstacle::{multiplier_field, system_forms, Discretization, Multipliers};
use crate::SparseMatrix;
use faer::sparse::{SparseColMat, Triplet};
use fem_reference::ElementKind;

/// One edge of the multiplier's boundary part: where its DOF lives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactEdge {
    /// Global edge number in the mesh.
    pub edge: usize,
    /// The cell next to it.
    pub cell: usize,
    /// Its local number in that cell (joining local vertices `local`, `local + 1`).
    pub local: usize,
    /// Its end points.
    pub ends: [[f64; 2]; 2],
}

impl ContactEdge {
    /// The edge's length `|E|` (= `h_E`).
    pub fn length(&self) -> f64 {
        let [a, b] = self.ends;
        (b[0] - a[0]).hypot(b[1] - a[1])
    }

    /// The edge's midpoint.
    pub fn midpoint(&self) -> [f64; 2] {
        let [a, b] = self.ends;
        [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]
    }

    /// The outward unit normal (the edge's cell is counter-clockwise).
    pub fn outward_normal(&self) -> [f64; 2] {
        let [a, b] = self.ends;
        let (tx, ty) = (b[0] - a[0], b[1] - a[1]);
        let l = tx.hypot(ty);
        [ty / l, -tx / l]
    }
}

/// The multiplier's space on the boundary part.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BoundaryMultiplier {
    /// Piecewise constant: one DOF per edge of the part.
    P0,
    /// Continuous piecewise linear on the part: one DOF per vertex of its edges.
    P1,
}

/// The DOFs of a multiplier on a boundary part: for P0 constraint `k` is the multiplier
/// of `edges[k]`; for P1 it is the nodal value at vertex `vertices[k]`.
#[derive(Clone, Debug, PartialEq)]
pub struct BoundaryMultiplierDofs {
    /// The boundary part (index in `M::FACET_PARTS`) the multiplier lives on.
    pub part: usize,
    /// The edges of the part (in constraint order for P0).
    pub edges: Vec<ContactEdge>,
    /// The multiplier's space.
    pub space: BoundaryMultiplier,
    /// P1: the mesh vertices of the part's edges, ascending by vertex number; constraint
    /// `k` is the multiplier's value at `vertices[k]`. Empty for P0.
    pub vertices: Vec<usize>,
    /// Per edge (same order as `edges`), the constraints of its two ends `ends[0]`,
    /// `ends[1]` (P1), or `[k, k]` for the edge's own constraint (P0): `λ_h` on edge `e`
    /// is `(1−s) Λ[edge_dofs[e][0]] + s Λ[edge_dofs[e][1]]`, s ∈ [0, 1].
    pub edge_dofs: Vec<[usize; 2]>,
}

impl BoundaryMultiplierDofs {
    /// The number of multiplier DOFs (constraints).
    pub fn count(&self) -> usize {
        match self.space {
            BoundaryMultiplier::P0 => self.edges.len(),
            BoundaryMultiplier::P1 => self.vertices.len(),
        }
    }

    /// `∫_part μ_k ds` for each multiplier basis function `μ_k` (a length): the edge's
    /// length for P0, half the lengths of the (one or two) edges at the vertex for P1.
    /// `Σ_k Λ_k w_k` is the total `∫ λ_h ds`.
    pub fn integrals(&self) -> Vec<f64> {
        let mut w = vec![0.0; self.count()];
        for (e, dofs) in self.edges.iter().zip(&self.edge_dofs) {
            let l = e.length();
            w[dofs[0]] += 0.5 * l;
            w[dofs[1]] += 0.5 * l;
        }
        w
    }
}

/// The boundary edges of `mesh` with one of `markers`, with their cell and local number.
pub fn part_edges(mesh: &TriangleMesh, markers: &[u32]) -> Vec<ContactEdge> {
    let vertices = mesh.vertices();
    mesh.boundary_edges()
        .iter()
        .filter(|(_, m)| markers.contains(m))
        .map(|&(e, _)| {
            let (cell, _) = mesh.edge_cells(e);
            let local = mesh
                .local_edge(cell, e)
                .expect("an edge is an edge of its cell");
            let c = mesh.cell(cell);
            ContactEdge {
                edge: e,
                cell,
                local,
                ends: [vertices[c[local]], vertices[c[(local + 1) % 3]]],
            }
        })
        .collect()
}

/// [`discretize`] with the model's boundary parts given by markers, by handle or name
/// (`(model::facets::Γ_C, &[1])`; every part of the model once), and the fields of
/// `fixed` held at 0 on the boundary edges of their markers
/// (`(model::fields::u_x, &[4])`).
///
/// # Errors
/// A part or field the model does not have, a part of the model without markers, and
/// those of [`discretize`].
pub fn discretize_on_parts<M, P, F>(
    mesh: &TriangleMesh,
    coefficients: &Coefficients,
    parts: &[(P, &[u32])],
    fixed: &[(F, &[u32])],
) -> Result<Discretization<TriangleMesh>>
where
    M: Model,
    P: IntoPartIndex<M> + Copy,
    F: IntoFieldIndex<M> + Copy,
{
    let mut markers: Vec<Option<Vec<u32>>> = vec![None; M::FACET_PARTS.len()];
    for &(part, on) in parts {
        markers[M::facet_part(part)?] = Some(on.to_vec());
    }
    let markers = markers
        .into_iter()
        .enumerate()
        .map(|(k, m)| {
            m.ok_or_else(|| {
                Error::Input(format!(
                    "the boundary part `{}` of `{}` is not given markers",
                    M::FACET_PARTS[k],
                    M::NAME
                ))
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let dofs = primal_dofs::<M>(mesh)?;
    let mut constraints = Constraints::new();
    for &(field, on) in fixed {
        let field = M::field(field)?;
        let (Some(map), Some(offset)) = (dofs.map(field), dofs.offset(field)) else {
            return Err(Error::Input(format!(
                "field `{}` is not a primal field of `{}`",
                M::FIELDS[field].name,
                M::NAME
            )));
        };
        for d in DirichletPart::Markers(on.to_vec()).dofs(map, mesh) {
            constraints.fix_dof(offset + d, 0.0)?;
        }
    }
    discretize::<M>(mesh, coefficients, &markers, dofs, &constraints)
}

/// Which of the model's boundary parts its multiplier lives on: the one part of the
/// boundary integrals of `B_h` in which the multiplier appears; `None` when it appears in
/// none (a multiplier on the cells).
///
/// # Errors
/// [`Error::Input`] for a multiplier in the boundary integrals of several parts.
pub fn multiplier_part<M: Model>() -> Result<Option<usize>> {
    // the nodal method's model has neither: no multiplier to place
    let (Some([bilinear, _]), Some(multiplier)) =
        (M::SYSTEM, M::FIELDS.iter().position(|f| f.nonnegative))
    else {
        return Ok(None);
    };
    let mut parts: Vec<usize> = M::FACET_BLOCKS
        .iter()
        .filter(|b| {
            b.form == bilinear && (b.test_field == multiplier || b.trial_field == Some(multiplier))
        })
        .map(|b| b.part)
        .collect();
    parts.sort_unstable();
    parts.dedup();
    match parts.as_slice() {
        [] => Ok(None),
        [p] => Ok(Some(*p)),
        _ => Err(Error::Input(format!(
            "the multiplier `{}` of `{}` appears in boundary integrals over several parts; it must live on one",
            M::FIELDS[multiplier].name,
            M::NAME
        ))),
    }
}

/// The DOFs of a model whose multiplier lives on a boundary part: its primal fields
/// (the multiplier's DOFs are the part's, [`BoundaryMultiplierDofs`]).
///
/// # Errors
/// Those of [`SystemDofs::new`] and [`multiplier_field`].
pub fn primal_dofs<M: Model>(mesh: &TriangleMesh) -> Result<SystemDofs> {
    let multiplier = multiplier_field::<M>()?;
    let primal: Vec<usize> = (0..M::FIELDS.len()).filter(|&f| f != multiplier).collect();
    SystemDofs::new::<M>(mesh, &primal)
}

/// The space of `M`'s boundary multiplier `multiplier`.
///
/// # Errors
/// [`Error::Input`] for an element other than P0 and P1.
fn multiplier_space<M: Model>(multiplier: usize) -> Result<BoundaryMultiplier> {
    match M::FIELDS[multiplier].element {
        ElementKind::P0 => Ok(BoundaryMultiplier::P0),
        ElementKind::P1 => Ok(BoundaryMultiplier::P1),
        other => Err(Error::Input(format!(
            "the boundary multiplier `{}` of `{}` must be P0 (one value per edge) or P1 (one per vertex of its part), not {}",
            M::FIELDS[multiplier].name,
            M::NAME,
            other.name()
        ))),
    }
}

/// The multiplier's DOFs on the edges of its part `part`, whose boundary markers are
/// `markers`.
///
/// # Errors
/// [`Error::Input`] for a multiplier that is neither P0 nor P1, and for a part that holds
/// no boundary edge of `mesh`.
pub fn multiplier_dofs_on<M: Model>(
    mesh: &TriangleMesh,
    part: usize,
    markers: &[u32],
) -> Result<BoundaryMultiplierDofs> {
    let space = multiplier_space::<M>(multiplier_field::<M>()?)?;
    let edges = part_edges(mesh, markers);
    if edges.is_empty() {
        return Err(Error::Input(format!(
            "the boundary part `{}` (markers {markers:?}) holds no boundary edge of the mesh: it is not on the boundary",
            M::FACET_PARTS[part]
        )));
    }
    let (vertices, edge_dofs) = multiplier_dofs(mesh, &edges, space);
    Ok(BoundaryMultiplierDofs {
        part,
        edges,
        space,
        vertices,
        edge_dofs,
    })
}

/// Assembles `B_h`, `L_h` of `M` (cell and facet blocks) on `mesh` with the multiplier
/// on the edges of its boundary part, and eliminates the fixed DOFs of `constraints`
/// (on `dofs`, the model's primal fields: [`primal_dofs`]).
///
/// `parts` gives the boundary markers of each of the model's `FACET_PARTS`, in their
/// order (e.g. from [`TriangleMesh::boundary_part_markers`]).
///
/// A P1 multiplier's facet kernels see its three local DOFs on the cell; on the edge only
/// the two end vertices' functions are nonzero, so the third vertex's rows and columns
/// must vanish (checked: an error otherwise, e.g. a derivative of λ in a boundary
/// integral). Its `(μ, λ)` block, `C = α Σ_E h_E (μ_l, μ_k)_E`, couples neighbouring
/// vertices along the whole part: a chain, not the small blocks of consecutive
/// constraints [`crate::lcp::CouplingBlocks`] holds (at most
/// [`crate::lcp::MAX_BLOCK`]), so it is lumped by rows: `C_kk = Σ_l C_kl`. That is exact
/// on constant pressures (the patch test keeps `λ_h = q`), keeps `C` diagonal and
/// positive for the semismooth Newton solver, and leaves `B`, `A` and `G` consistent.
///
/// # Errors
/// [`Error::Input`] when the model has no system, no single multiplier, a multiplier that
/// is neither P0 nor P1 or that appears in no boundary integral or on two parts, a P1
/// multiplier whose facet terms reach the vertex off the edge; `parts` not one list of
/// markers per part of the model, or a part that holds no boundary edge of the mesh;
/// the errors of the kernels ([`Error::NonFinite`] for a
/// non-finite entry).
pub fn discretize<M: Model>(
    mesh: &TriangleMesh,
    coefficients: &Coefficients,
    parts: &[Vec<u32>],
    dofs: SystemDofs,
    constraints: &Constraints,
) -> Result<Discretization<TriangleMesh>> {
    discretize_on::<M>(mesh, None, coefficients, parts, dofs, constraints)
}

/// [`discretize`] with the contributions of the cells `cells` alone (`None`: every
/// cell), the facet terms of a boundary edge with its cell's: one MPI rank's share of a
/// partition of the cells, whose LCPs sum to the whole one (as
/// [`Discretization::with_constraints_on`]). A P0 multiplier's constraint lives on one
/// edge, so its rows of `B`, `C` and `G` are complete on the part holding the edge's
/// cell; a P1 multiplier's are split between the parts of its two edges.
///
/// # Errors
/// Those of [`discretize`]; a cell number beyond the mesh's.
pub fn discretize_on<M: Model>(
    mesh: &TriangleMesh,
    cells: Option<&[usize]>,
    coefficients: &Coefficients,
    parts: &[Vec<u32>],
    dofs: SystemDofs,
    constraints: &Constraints,
) -> Result<Discretization<TriangleMesh>> {
    crate::obstacle::check_cells(cells, mesh.cell_count())?;
    let part = crate::mesh::CellSubset::new(mesh, cells);
    let owned: Option<Vec<bool>> = cells.map(|cells| {
        let mut owned = vec![false; mesh.cell_count()];
        for &c in cells {
            owned[c] = true;
        }
        owned
    });
    let (bilinear_id, linear_id) = system_forms::<M>()?;
    let (bilinear, linear) = (M::form(bilinear_id)?, M::form(linear_id)?);
    crate::model::require_symmetric::<M, TriangleMesh>(bilinear, mesh, coefficients)?;
    let multiplier = multiplier_field::<M>()?;
    let (multiplier_part, edges_of_part) =
        checked_parts::<M>(mesh, coefficients, parts, [bilinear, linear], multiplier)?;
    let boundary = multiplier_dofs_on::<M>(mesh, multiplier_part, &parts[multiplier_part])?;
    let n_full = dofs.dof_count();
    // A: the cell part, then the facet blocks
    let cell_part =
        MatrixAssembler::new::<M>(bilinear_id, &part, &dofs)?.assemble::<M>(&part, coefficients)?;
    let (ptr, rows, vals) = (
        cell_part.symbolic().col_ptr(),
        cell_part.symbolic().row_idx(),
        cell_part.val(),
    );
    let mut system = FullSystem {
        triplets: (0..n_full)
            .flat_map(|j| (ptr[j]..ptr[j + 1]).map(move |k| Triplet::new(rows[k], j, vals[k])))
            .collect(),
        b: vec![Vec::new(); boundary.count()],
        c: vec![0.0; boundary.count()],
        f: assemble_vector::<M>(linear_id, &part, &dofs, coefficients)?,
        g: vec![0.0; boundary.count()],
    };
    let facets = Facets {
        mesh,
        coefficients,
        dofs: &dofs,
        multiplier,
        space: boundary.space,
        edge_dofs: &boundary.edge_dofs,
    };
    for (index, block) in M::FACET_BLOCKS.iter().enumerate() {
        for (k, edge) in edges_of_part[block.part].iter().enumerate() {
            if owned.as_ref().is_some_and(|owned| !owned[edge.cell]) {
                continue;
            }
            if block.form == bilinear {
                facets.add_matrix::<M>(index, block, k, edge, &mut system)?;
            } else if block.form == linear {
                facets.add_vector::<M>(index, block, k, edge, &mut system)?;
            }
        }
    }
    let (basis, reduction, lcp) = system.reduced(n_full, constraints)?;
    let n = reduction.free().len();
    Ok(Discretization {
        mesh: mesh.clone(),
        dofs,
        reduction,
        basis,
        lcp,
        multiplier_field: multiplier,
        multipliers: Multipliers::Boundary(boundary),
        roles: Vec::new(),
        primal_reduced: (0..n).collect(),
        multiplier_reduced: Vec::new(),
        cells: cells.map(<[usize]>::to_vec),
    })
}

/// The part the multiplier of `M` lives on and the edges of each of the model's
/// boundary parts, after the checks of [`discretize`]: one list of markers per part,
/// each on the boundary, the bilinear form symmetric on every part's facets, and a P1
/// multiplier in no boundary integral of another part.
///
/// # Errors
/// Those checks', named.
fn checked_parts<M: Model>(
    mesh: &TriangleMesh,
    coefficients: &Coefficients,
    parts: &[Vec<u32>],
    [bilinear, linear]: [usize; 2],
    multiplier: usize,
) -> Result<(usize, Vec<Vec<ContactEdge>>)> {
    let Some(multiplier_part) = multiplier_part::<M>()? else {
        return Err(Error::Input(format!(
            "the multiplier `{}` of `{}` appears in no boundary integral of `{}`: it has no boundary part to live on",
            M::FIELDS[multiplier].name,
            M::NAME,
            M::FORMS[bilinear].name
        )));
    };
    if parts.len() != M::FACET_PARTS.len() {
        return Err(Error::Input(format!(
            "model `{}` integrates over the boundary parts {}: give markers for each ({} given)",
            M::NAME,
            M::FACET_PARTS.join(", "),
            parts.len()
        )));
    }
    let mut edges_of_part = Vec::with_capacity(M::FACET_PARTS.len());
    for (part, (name, markers)) in M::FACET_PARTS.iter().zip(parts).enumerate() {
        let edges = part_edges(mesh, markers);
        if edges.is_empty() {
            return Err(Error::Input(format!(
                "the boundary part `{name}` (markers {markers:?}) holds no boundary edge of the mesh: it is not on the boundary"
            )));
        }
        let places: Vec<(usize, usize)> = edges.iter().map(|e| (e.cell, e.local)).collect();
        crate::model::require_symmetric_facets::<M>(bilinear, part, mesh, coefficients, &places)?;
        edges_of_part.push(edges);
    }
    let space = multiplier_space::<M>(multiplier)?;
    if space == BoundaryMultiplier::P1 {
        if let Some(b) = M::FACET_BLOCKS.iter().find(|b| {
            (b.form == bilinear || b.form == linear)
                && b.part != multiplier_part
                && (b.test_field == multiplier || b.trial_field == Some(multiplier))
        }) {
            return Err(Error::Input(format!(
                "the P1 multiplier `{}` of `{}` appears in a boundary integral of `{}` over `{}`, not its part `{}`",
                M::FIELDS[multiplier].name,
                M::NAME,
                M::FORMS[b.form].name,
                M::FACET_PARTS[b.part],
                M::FACET_PARTS[multiplier_part]
            )));
        }
    }
    Ok((multiplier_part, edges_of_part))
}

/// `B_h`, `L_h` on the full DOFs before the supports act: `A` as triplets, the rows of
/// `B`, the diagonal of `C`, `F` and `G`.
struct FullSystem {
    triplets: Vec<Triplet<usize, usize, f64>>,
    b: Vec<Vec<(usize, f64)>>,
    c: Vec<f64>,
    f: Vec<f64>,
    g: Vec<f64>,
}

impl FullSystem {
    /// The LCP on the free DOFs of `constraints` (`n_full` DOFs), with the change of
    /// basis of its rotated groups and the reduction.
    ///
    /// # Errors
    /// An assembly, change of basis or reduction that fails.
    fn reduced(
        self,
        n_full: usize,
        constraints: &Constraints,
    ) -> Result<(ChangeOfBasis, crate::assembly::boundary::Reduction, Lcp)> {
        let FullSystem {
            triplets,
            b,
            c,
            mut f,
            mut g,
        } = self;
        let a_full: SparseMatrix =
            SparseColMat::try_new_from_triplets(n_full, n_full, &triplets)
                .map_err(|e| Error::Input(format!("assembling the system: {e:?}")))?;
        // supports on combinations of DOFs (a roller along an oblique direction) rotate
        // their groups: A' = Rᵀ A R, F' = Rᵀ F, each row of B to B R; the reduction is in
        // the primed numbering
        let basis = constraints.change_of_basis(n_full)?;
        let a_full = if basis.is_identity() {
            a_full
        } else {
            basis.transform_matrix(&a_full)?
        };
        basis.to_primed(&mut f);
        let reduction = constraints.reduction(n_full)?;
        let a = reduction.matrix(&a_full);
        let f = reduction.rhs(&a_full, &f);
        // B U_full = B U_free + B U_fixed: the fixed columns move to G
        let b_rows: Vec<Vec<(usize, f64)>> = b
            .into_iter()
            .map(|row| rotate_row(&basis, row))
            .zip(&mut g)
            .map(|(row, g)| {
                let mut out: Vec<(usize, f64)> = Vec::with_capacity(row.len());
                for (col, v) in row {
                    match reduction.free_index(col) {
                        Some(j) => match out.iter_mut().find(|(c, _)| *c == j) {
                            Some(e) => e.1 += v,
                            None => out.push((j, v)),
                        },
                        None => *g -= v * reduction.fixed_value(col),
                    }
                }
                out.sort_by_key(|e| e.0);
                out
            })
            .collect();
        let lcp = Lcp::new(a, ConstraintRows::from(b_rows), c, f, g);
        Ok((basis, reduction, lcp))
    }
}

/// What the facet blocks of [`discretize`] are added with: the mesh, coefficients and
/// DOFs, the multiplier field, its space and its constraints per edge.
struct Facets<'a> {
    mesh: &'a TriangleMesh,
    coefficients: &'a Coefficients<'a>,
    dofs: &'a SystemDofs,
    multiplier: usize,
    space: BoundaryMultiplier,
    edge_dofs: &'a [[usize; 2]],
}

impl Facets<'_> {
    /// The global rows of a primal field's local DOFs on `cell`.
    fn place(&self, field: usize, cell: usize) -> Vec<usize> {
        let (map, offset) = (
            self.dofs.map(field).expect("a primal field"),
            self.dofs.offset(field).expect("a primal field"),
        );
        map.cell_dofs(cell).iter().map(|d| d + offset).collect()
    }

    /// Adds facet block `index` (`block`, of the bilinear form) on the `k`-th edge of its
    /// part to `system`: to A, to the rows of B (`−b`: B_h holds `−b(v, λ)`), or to C
    /// (`−α S`); a P1 multiplier's rows are its edge's two end vertices, its C lumped by
    /// rows (the chain of the part does not fit [`crate::lcp::CouplingBlocks`]).
    ///
    /// # Errors
    /// A kernel's, a non-finite entry, a P1 term off the edge.
    fn add_matrix<M: Model>(
        &self,
        index: usize,
        block: &FacetBlockInfo,
        k: usize,
        edge: &ContactEdge,
        system: &mut FullSystem,
    ) -> Result<()> {
        let Some(trial) = block.trial_field else {
            return Ok(());
        };
        let multiplier = self.multiplier;
        let rows = M::FIELDS[block.test_field].element.local_dof_count(M::CELL);
        let cols = M::FIELDS[trial].element.local_dof_count(M::CELL);
        let mut local = vec![0.0; rows * cols];
        let x = self.mesh.cell_coordinates(edge.cell);
        let (params, data) = (&self.coefficients.params, &self.coefficients.data);
        M::facet_matrix(index, &x, edge.local, params, data, &mut local)?;
        if local.iter().any(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                what: "facet matrix",
                cell: edge.cell,
            });
        }
        let (test_is_multiplier, trial_is_multiplier) =
            (block.test_field == multiplier, trial == multiplier);
        // the multiplier's constraints among the rows: the edge's own (P0), or its two
        // end vertices' (P1), whose local rows are `on_edge`
        let (on_edge, constraints): (Vec<usize>, Vec<usize>) = if self.space
            == BoundaryMultiplier::P1
            && (test_is_multiplier || trial_is_multiplier)
        {
            let (on_edge, off) = edge_vertices(edge.local);
            check_off_edge::<M>(
                &local,
                cols,
                &|i, j| (test_is_multiplier && i == off) || (trial_is_multiplier && j == off),
                multiplier,
                edge,
            )?;
            (on_edge.to_vec(), self.edge_dofs[k].to_vec())
        } else {
            (vec![0], vec![k])
        };
        match (test_is_multiplier, trial_is_multiplier) {
            (true, true) => {
                for (&i, &constraint) in on_edge.iter().zip(&constraints) {
                    let row: f64 = on_edge.iter().map(|&j| local[i * cols + j]).sum();
                    system.c[constraint] -= row;
                }
            }
            (true, false) => {
                let columns = self.place(trial, edge.cell);
                for (&i, &constraint) in on_edge.iter().zip(&constraints) {
                    for (j, &col) in columns.iter().enumerate() {
                        let v = local[i * cols + j];
                        if v != 0.0 {
                            system.b[constraint].push((col, -v));
                        }
                    }
                }
            }
            // the (v, λ) block is the transpose of (μ, v): B_h is symmetric
            (false, true) => {}
            (false, false) => {
                let r = self.place(block.test_field, edge.cell);
                let s = self.place(trial, edge.cell);
                for (i, &row) in r.iter().enumerate() {
                    for (j, &col) in s.iter().enumerate() {
                        system
                            .triplets
                            .push(Triplet::new(row, col, local[i * cols + j]));
                    }
                }
            }
        }
        Ok(())
    }

    /// Adds facet block `index` (`block`, of the linear form) on the `k`-th edge of its
    /// part to `system`: to F, or to G (`−ℓ_S`) on the multiplier's constraints.
    ///
    /// # Errors
    /// A kernel's, a non-finite entry, a P1 term off the edge.
    fn add_vector<M: Model>(
        &self,
        index: usize,
        block: &FacetBlockInfo,
        k: usize,
        edge: &ContactEdge,
        system: &mut FullSystem,
    ) -> Result<()> {
        let rows = M::FIELDS[block.test_field].element.local_dof_count(M::CELL);
        let mut local = vec![0.0; rows];
        let x = self.mesh.cell_coordinates(edge.cell);
        let (params, data) = (&self.coefficients.params, &self.coefficients.data);
        M::facet_vector(index, &x, edge.local, params, data, &mut local)?;
        if local.iter().any(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                what: "facet vector",
                cell: edge.cell,
            });
        }
        let test_is_multiplier = block.test_field == self.multiplier;
        if test_is_multiplier && self.space == BoundaryMultiplier::P1 {
            let (on_edge, off) = edge_vertices(edge.local);
            check_off_edge::<M>(&local, 1, &|i, _| i == off, self.multiplier, edge)?;
            for (a, &i) in on_edge.iter().enumerate() {
                system.g[self.edge_dofs[k][a]] -= local[i];
            }
        } else if test_is_multiplier {
            system.g[k] -= local[0];
        } else {
            let r = self.place(block.test_field, edge.cell);
            for (i, &row) in r.iter().enumerate() {
                system.f[row] += local[i];
            }
        }
        Ok(())
    }
}

/// A sparse row `b` of B as `b R` in the primed DOFs of `basis`: at each rotated group
/// `b'_g = T b_g` (the same map as a load vector's, [`ChangeOfBasis::to_primed`]).
fn rotate_row(basis: &ChangeOfBasis, row: Vec<(usize, f64)>) -> Vec<(usize, f64)> {
    if basis.is_identity() {
        return row;
    }
    let mut out = row;
    for block in basis.blocks() {
        let group = block.group.as_slice();
        let values: Vec<f64> = group
            .iter()
            .map(|d| out.iter().filter(|(c, _)| c == d).map(|(_, v)| v).sum())
            .collect();
        if values.iter().all(|&v| v == 0.0) {
            continue;
        }
        out.retain(|(c, _)| !group.contains(c));
        for (k, &d) in group.iter().enumerate() {
            let v: f64 = (0..group.len()).map(|j| block.t[k][j] * values[j]).sum();
            if v != 0.0 {
                out.push((d, v));
            }
        }
    }
    out
}

/// The multiplier's DOF map on the part's edges: for P1 the vertices of the edges
/// (ascending) and each edge's two constraints; for P0 no vertices and `[k, k]`.
fn multiplier_dofs(
    mesh: &TriangleMesh,
    edges: &[ContactEdge],
    space: BoundaryMultiplier,
) -> (Vec<usize>, Vec<[usize; 2]>) {
    match space {
        BoundaryMultiplier::P0 => (Vec::new(), (0..edges.len()).map(|k| [k, k]).collect()),
        BoundaryMultiplier::P1 => {
            let ends = |e: &ContactEdge| {
                let c = mesh.cell(e.cell);
                [c[e.local], c[(e.local + 1) % 3]]
            };
            let mut vertices: Vec<usize> = edges.iter().flat_map(ends).collect();
            vertices.sort_unstable();
            vertices.dedup();
            let index = |v: usize| vertices.binary_search(&v).expect("a vertex of an edge");
            let edge_dofs = edges
                .iter()
                .map(|e| {
                    let [a, b] = ends(e);
                    [index(a), index(b)]
                })
                .collect();
            (vertices, edge_dofs)
        }
    }
}

/// The local vertices of a cell's edge `local`: its two ends (the P1 multiplier's
/// nonzero local DOFs there), in the order of [`ContactEdge::ends`], and the one off it.
fn edge_vertices(local: usize) -> ([usize; 2], usize) {
    ([local, (local + 1) % 3], (local + 2) % 3)
}

/// A P1 multiplier's function at the vertex off the edge vanishes on the edge, so the
/// facet kernel's entries `(i, j)` selected by `off` (`cols` columns per row) must be
/// zero up to rounding; a nonzero one means a facet term that is not the trace of λ
/// (a derivative), which a DOF map on Γ_C's vertices cannot represent.
fn check_off_edge<M: Model>(
    local: &[f64],
    cols: usize,
    off: &dyn Fn(usize, usize) -> bool,
    multiplier: usize,
    edge: &ContactEdge,
) -> Result<()> {
    let scale = local.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for (index, v) in local.iter().enumerate() {
        let (i, j) = (index / cols, index % cols);
        if off(i, j) && v.abs() > 1e-12 * scale {
            return Err(Error::Input(format!(
                "the P1 multiplier `{}` of `{}` has a nonzero facet entry {v:e} at the vertex off contact edge {} (cell {}): only its trace on the edge may enter the boundary integrals",
                M::FIELDS[multiplier].name,
                M::NAME,
                edge.edge,
                edge.cell
            )));
        }
    }
    Ok(())
}

/// The per-edge inverse-inequality constants `C_I,E` of the stabilization
/// (docs/contact.md): the smallest `C` with `h_E ‖σ_n(v)‖²_E ≤ C a_{T_E}(v, v)` for every `v` of the
/// primal space on the cell `T_E` next to edge `E`, computed from the model's own
/// kernels: the largest generalized eigenvalue of `S_E v = C K_T v` on the complement
/// of the kernel of `K_T` (the rigid motions, where `S_E` vanishes too).
///
/// The forms are the model's stabilization role ([`Model::STABILIZATION`]): the cell
/// form it is measured against (`a(u;v)`, its blocks give `K_T`) and the stabilization
/// form, whose facet blocks on the multiplier's part, restricted to the primal fields
/// `dofs`, give `S_E` (`S(u,λ;v,μ) = ∫_Γ_C h_E (λ + σ_n(u))(μ + σ_n(v)) ds`). One value
/// per edge of `boundary.edges`; `α = 1/(2 max_E C_I,E)` is the rule of §1.
///
/// # Errors
/// [`Error::Input`] for a model without a stabilization role; the kernels' errors;
/// [`Error::NonFinite`] when a local matrix is not finite.
pub fn inverse_constants<M: Model>(
    mesh: &TriangleMesh,
    boundary: &BoundaryMultiplierDofs,
    dofs: &SystemDofs,
    coefficients: &Coefficients,
) -> Result<Vec<f64>> {
    let role = crate::stabilization::role::<M>()?;
    let (energy, stabilization) = (role.against, role.form);
    // Local numbering: the primal fields' local DOFs one after the other.
    let fields = dofs.fields();
    let counts: Vec<usize> = fields
        .iter()
        .map(|&f| M::FIELDS[f].element.local_dof_count(M::CELL))
        .collect();
    let start: Vec<usize> = counts
        .iter()
        .scan(0, |s, &c| {
            let x = *s;
            *s += c;
            Some(x)
        })
        .collect();
    let size: usize = counts.iter().sum();
    let local_start = |field: usize| fields.iter().position(|&f| f == field).map(|k| start[k]);
    let (params, data) = (&coefficients.params, &coefficients.data);
    let largest = M::FIELDS
        .iter()
        .map(|f| f.element.local_dof_count(M::CELL))
        .max()
        .unwrap_or(0);
    let mut out = vec![0.0; largest * largest];
    let mut constants = Vec::with_capacity(boundary.edges.len());
    for edge in &boundary.edges {
        let x = mesh.cell_coordinates(edge.cell);
        let mut k = nalgebra::DMatrix::<f64>::zeros(size, size);
        let mut s = nalgebra::DMatrix::<f64>::zeros(size, size);
        for (b, block) in M::FORMS[energy].blocks.iter().enumerate() {
            let trial = block.trial_field.unwrap_or(block.test_field);
            let (Some(r0), Some(c0)) = (local_start(block.test_field), local_start(trial)) else {
                continue;
            };
            let rows = M::FIELDS[block.test_field].element.local_dof_count(M::CELL);
            let cols = M::FIELDS[trial].element.local_dof_count(M::CELL);
            M::element_matrix(energy, b, &x, params, data, &mut out[..rows * cols]);
            for i in 0..rows {
                for j in 0..cols {
                    k[(r0 + i, c0 + j)] += out[i * cols + j];
                }
            }
        }
        for (index, block) in M::FACET_BLOCKS.iter().enumerate() {
            if block.form != stabilization || block.part != boundary.part {
                continue;
            }
            let Some(trial) = block.trial_field else {
                continue;
            };
            let (Some(r0), Some(c0)) = (local_start(block.test_field), local_start(trial)) else {
                continue;
            };
            let rows = M::FIELDS[block.test_field].element.local_dof_count(M::CELL);
            let cols = M::FIELDS[trial].element.local_dof_count(M::CELL);
            M::facet_matrix(index, &x, edge.local, params, data, &mut out[..rows * cols])?;
            for i in 0..rows {
                for j in 0..cols {
                    s[(r0 + i, c0 + j)] += out[i * cols + j];
                }
            }
        }
        if k.iter().chain(s.iter()).any(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                what: "local matrix of the inverse constant",
                cell: edge.cell,
            });
        }
        let k = 0.5 * (&k + k.transpose());
        let s = 0.5 * (&s + s.transpose());
        let eigen = k.symmetric_eigen();
        let largest = eigen.eigenvalues.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let kept: Vec<usize> = (0..size)
            .filter(|&i| eigen.eigenvalues[i] > 1e-10 * largest)
            .collect();
        // Q_r Λ_r^{-1/2}: S restricted to the range of K, in its energy-orthonormal basis
        let mut basis = nalgebra::DMatrix::<f64>::zeros(size, kept.len());
        for (c, &i) in kept.iter().enumerate() {
            let scale = 1.0 / eigen.eigenvalues[i].sqrt();
            for r in 0..size {
                basis[(r, c)] = eigen.eigenvectors[(r, i)] * scale;
            }
        }
        let reduced = basis.transpose() * &s * &basis;
        let reduced = 0.5 * (&reduced + reduced.transpose());
        let value = reduced
            .symmetric_eigen()
            .eigenvalues
            .iter()
            .fold(0.0f64, |m, &v| m.max(v));
        constants.push(value);
    }
    Ok(constants)
}
