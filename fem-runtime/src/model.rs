//! What a generated model tells the runtime: its fields, parameters, data and forms,
//! and the dispatch to its element kernels.
//!
//! Forms, fields, parameters and data are named either by string (as a scene file
//! names them; a wrong name is a run-time [`Error::UnknownName`]) or by the typed
//! handles the model's module exports (`membrane_p2_p0::forms::B_h`,
//! `membrane_p2_p0::params::α`, …; a wrong name is a compile error, and a handle of
//! one model does not type-check as one of another). The functions that take a name
//! accept both through [`IntoFormIndex`], [`IntoFieldIndex`], [`IntoParamIndex`] and
//! [`IntoDataIndex`].
//!
//! ```
//! use fem_runtime::{Coefficients, Model};
//! fem_runtime::model! {
//!     pub mod string on interval {
//!         unknowns: u: P1;
//!         tests: v;
//!         params: k;
//!         data: f;
//!         forms: "
//!             a(u;v) = ∫ u'v' + k u v
//!             l(v)   = ∫ f v
//!         ";
//!     }
//! }
//! use string::{data, forms, params, Model as M};
//! assert_eq!(M::form(forms::l).unwrap(), M::form("l").unwrap());
//! let one = |_: &[f64]| 1.0;
//! let c = Coefficients::from_ids(&[(params::k, 2.0)], &[(data::f, &one)]).unwrap();
//! assert_eq!(c.params, [2.0]);
//! ```
//!
//! A misspelled handle does not compile:
//! ```compile_fail
//! fem_runtime::model! {
//!     pub mod string on interval { unknowns: u: P1; tests: v; forms: "a(u;v) = ∫ u'v'"; }
//! }
//! use fem_runtime::Model;
//! let _ = string::Model::form(string::forms::b);
//! ```
//! nor does a handle of another model:
//! ```compile_fail
//! fem_runtime::model! {
//!     pub mod one on interval { unknowns: u: P1; tests: v; forms: "a(u;v) = ∫ u'v'"; }
//! }
//! fem_runtime::model! {
//!     pub mod two on interval { unknowns: u: P1; tests: v; forms: "a(u;v) = ∫ u v"; }
//! }
//! use fem_runtime::Model;
//! let _ = two::Model::form(one::forms::a);
//! ```

use crate::error::{Error, Result};
use fem_reference::{CellKind, ElementKind};
use std::fmt;
use std::marker::PhantomData;

/// A data function of the physical point `x` (a slice of length the cell's dimension).
pub type DataFn = dyn Fn(&[f64]) -> f64 + Sync;

/// A field: an unknown with its test function and element.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FieldInfo {
    /// Name of the unknown.
    pub name: &'static str,
    /// Name of its test function.
    pub test_name: &'static str,
    /// Its element.
    pub element: ElementKind,
    /// Whether it is a multiplier constrained to be non-negative.
    pub nonnegative: bool,
}

/// One nonzero block of a form.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BlockInfo {
    /// Field of the test function (rows).
    pub test_field: usize,
    /// Field of the trial function (columns); `None` for linear forms.
    pub trial_field: Option<usize>,
    /// Gauss points of its run-time quadrature loops (0: integrated exactly at compile time).
    pub quadrature_points: usize,
    /// Its terms, readable.
    pub terms: &'static str,
}

/// One nonzero block of a boundary integral `∫_Γ … ds` (a model's `facets:`): its
/// kernel integrates over one edge of a cell ([`Model::facet_matrix`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FacetBlockInfo {
    /// Index of the form in `FORMS`.
    pub form: usize,
    /// Index of the boundary part in `FACET_PARTS`.
    pub part: usize,
    /// Field of the test function (rows).
    pub test_field: usize,
    /// Field of the trial function (columns); `None` for linear forms.
    pub trial_field: Option<usize>,
}

/// A form of a model.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FormInfo {
    /// Its name as written.
    pub name: &'static str,
    /// Its definition as written.
    pub source: &'static str,
    /// 1 for linear forms, 2 for bilinear ones.
    pub arity: usize,
    /// Terms dropped because they vanish for the chosen elements.
    pub dropped_terms: usize,
    /// Nonzero blocks.
    pub blocks: &'static [BlockInfo],
}

/// The stabilization's role in a model ([`Model::STABILIZATION`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StabilizationRole {
    /// Index in `PARAMS` of α (`None` for `stabilization: S against a`, a model that
    /// leaves α to its forms).
    pub alpha: Option<usize>,
    /// Index in `FORMS` of the stabilization form `S`.
    pub form: usize,
    /// Index in `FORMS` of the bilinear form `a` that `C_I` measures `S` against.
    pub against: usize,
}

/// A model compiled by `model!`.
pub trait Model: Copy + Default + Send + Sync + 'static {
    /// Module name of the model.
    const NAME: &'static str;
    /// Its doc comment.
    const DESCRIPTION: &'static str;
    /// Reference cell.
    const CELL: CellKind;
    /// Fields in declaration order.
    const FIELDS: &'static [FieldInfo];
    /// Parameter names in declaration order.
    const PARAMS: &'static [&'static str];
    /// Data function names in declaration order.
    const DATA: &'static [&'static str];
    /// Forms in definition order.
    const FORMS: &'static [FormInfo];
    /// Dirichlet conditions `(field, data function)` declared under `boundary:`.
    const DIRICHLET: &'static [(usize, usize)] = &[];
    /// The discrete obstacle system `[B_h, L_h]` as indices in `FORMS`: the forms the
    /// model declares under `system:`, or else the bilinear form named `B_h` and the
    /// linear form named `L_h` (docs/mathematics.md §1); `None` for a model without them.
    /// Found at compile time, so the solvers need no name at run time.
    const SYSTEM: Option<[usize; 2]> = system_forms(Self::FORMS);
    /// The energy `J(u) = ½ a(u,u) − ℓ(u)` as `[a, ℓ]` (indices in `FORMS`): the forms
    /// declared under `energy:`, or else `a` and `ℓ` (`l`, `ell`) where the model has
    /// them; `None` otherwise.
    const ENERGY: Option<[usize; 2]> = None;
    /// The constraint of the obstacle problem as `[b, G]` (indices in `FORMS`):
    /// `b(v, μ) = (μ, sBv)` and `G(μ) = (μ, sψ)`, so that `b(u_h, μ) − G(μ) =
    /// (μ, s(Bu_h − ψ))` is the constraint's residual against μ (`../shared/MODELS.md`
    /// §1). Declared under `constraint:`, or else the forms `b` and `G` where the model
    /// has them; `None` otherwise. The estimate of a multiplier on a boundary part takes
    /// its contact terms from it ([`crate::adaptivity`]).
    const CONSTRAINT: Option<[usize; 2]> = None;
    /// Whether the macro derived the strong form of the model from `a`, `ℓ` and `b` by
    /// integration by parts (constant coefficients in `a`) and checked the cell
    /// stabilization and the declared estimator against it (docs/adaptivity.md,
    /// "Derived from `a`"); `false` where it could not, and by default.
    const STRONG_FORM: bool = false;
    /// The stabilization: the parameter α of `B_h = … − α S`, the form `S` and the form
    /// `a` that bounds it, `S_T(v, v) ≤ C_I a_T(v, v)` on the primal functions of a cell
    /// ([`crate::stabilization`]); declared under `stabilization: α S against a`, or else
    /// taken from those names where the model has them; `None` otherwise.
    const STABILIZATION: Option<StabilizationRole> = None;
    /// Index in `PARAMS` of the obstacle side `s` (`s·Bv ≥ s·ψ`, +1 below, −1 above):
    /// declared under `side:`, or else the parameter named `s`; `None` for a model whose
    /// obstacle is always below.
    const SIDE: Option<usize> = None;
    /// `[field, data]`: the constrained field `w` and the obstacle `ψ` (indices in
    /// `FIELDS` and `DATA`) of `s·w ≥ s·ψ`, declared under `obstacle: w >= ψ`, or else a
    /// field `u` or `w` and data `ψ` (`psi`) of a model with a multiplier; `None` where
    /// the constraint is not of this form (Signorini's `u·n_c ≤ g` on a boundary part).
    /// The reports measure penetration and open gaps pointwise with it.
    const OBSTACLE: Option<[usize; 2]> = None;
    /// The order `p` of the operator of the contact equation: the power of h in the
    /// stabilization's terms (`Σ_T h_T^p (…)`: 2 for membranes, 4 for beams and plates),
    /// or else the total derivative order of the energy's bilinear form; 0 where
    /// neither is known. A load `f` bends the structure by about `f·L^p` over a length L.
    const ORDER: u8 = 0;
    /// The highest derivative of the constrained field ([`Model::OBSTACLE`]) in the
    /// energy form: the order `m` of the seminorm `|w|_m` its energy is equivalent to (1
    /// for a membrane and for Timoshenko's deflection, whose stabilization is of order 4,
    /// 2 for plates and Euler–Bernoulli); 0 where unknown.
    const CONSTRAINED_ORDER: u8 = 0;
    /// Indices in `PARAMS` of the parameters declared `> 0` (`params: β > 0`): the
    /// forms may divide by sums that are positive only for positive values of them, so
    /// [`Coefficients`] refuses other values.
    const POSITIVE_PARAMS: &'static [usize] = &[];
    /// Index pairs in `PARAMS` of the vectors of parameters declared unit vectors
    /// (`unit: n_c;` for `n_c_x`, `n_c_y`): the model's forms are consistent only for
    /// `|n_c| = 1` (Signorini's `σ_n(u) = n_c·σ(u)n`), so [`Coefficients`] refuses
    /// other lengths ([`UNIT_TOLERANCE`]).
    const UNIT_PARAMS: &'static [(usize, usize)] = &[];

    /// The constrained field: the `obstacle:` role's field ([`Model::OBSTACLE`]), else
    /// the first field (a model without a pointwise obstacle, e.g. Signorini's).
    fn constrained_field() -> usize {
        Self::OBSTACLE.map_or(0, |[field, _]| field)
    }

    /// Element matrix of `block` of bilinear `form`, row-major into `out`.
    fn element_matrix(
        form: usize,
        block: usize,
        vertices: &[f64],
        params: &[f64],
        data: &[&DataFn],
        out: &mut [f64],
    );

    /// Adds the element matrices of `block` of bilinear `form` over all cells of `mesh`
    /// into `values`, entry `(i, j)` of cell `c` at `positions[c·stride + offset + i·cols + j]`
    /// (through the accumulator: parallel assembly gives each thread its own over one
    /// array).
    #[allow(clippy::too_many_arguments)]
    fn add_element_matrices<G: crate::mesh::Mesh>(
        form: usize,
        block: usize,
        mesh: &G,
        params: &[f64],
        data: &[&DataFn],
        positions: &[crate::kernel::Position],
        stride: usize,
        offset: usize,
        values: &mut crate::kernel::Accumulator,
    );

    /// Element vector of `block` of linear `form` into `out`.
    fn element_vector(
        form: usize,
        block: usize,
        vertices: &[f64],
        params: &[f64],
        data: &[&DataFn],
        out: &mut [f64],
    );

    /// [`Model::element_matrix`] on a cell whose global vertex numbers are `global`.
    ///
    /// Elements that need a per-cell DOF transformation (Argyris, Morley) orient their
    /// edge DOFs by the global vertex numbers, so that neighbouring cells agree
    /// (`docs/elements.md` §3); `element_matrix` orients them by the local numbers, as on
    /// a cell numbered increasingly. The default ignores `global`: right for every
    /// other element, and what models without such elements keep.
    #[allow(clippy::too_many_arguments)]
    fn element_matrix_on_cell(
        form: usize,
        block: usize,
        vertices: &[f64],
        global: &[usize],
        params: &[f64],
        data: &[&DataFn],
        out: &mut [f64],
    ) {
        let _ = global;
        Self::element_matrix(form, block, vertices, params, data, out);
    }

    /// [`Model::element_vector`] on a cell whose global vertex numbers are `global` (see
    /// [`Model::element_matrix_on_cell`]).
    #[allow(clippy::too_many_arguments)]
    fn element_vector_on_cell(
        form: usize,
        block: usize,
        vertices: &[f64],
        global: &[usize],
        params: &[f64],
        data: &[&DataFn],
        out: &mut [f64],
    ) {
        let _ = global;
        Self::element_vector(form, block, vertices, params, data, out);
    }

    /// Element matrix of `block` of bilinear `form` on a curved (six-node, isoparametric)
    /// triangle, row-major into `out` (docs/mathematics.md §8).
    ///
    /// `nodes` holds the twelve coordinates `x₀ y₀ … x₅ y₅` of the six nodes in the order
    /// of [`crate::element::Isoparametric`] (vertices 0, 1, 2 counter-clockwise, then the
    /// nodes of the edges 0–1, 1–2, 2–0; Gmsh's order for its type-9 triangles). The
    /// Jacobian is evaluated per quadrature point; `h_T` is the diameter of the three
    /// vertices. With the edge nodes at the edge midpoints the result equals
    /// [`Model::element_matrix`] up to rounding.
    ///
    /// `model!` generates it for every triangle model. The default, which interval models
    /// keep (no mesh of curved intervals exists, so the runtime never calls it for them),
    /// is an error, never a panic.
    ///
    /// # Errors
    /// [`Error::Input`] for `nodes` not of length 12, for a block whose element needs a
    /// per-cell DOF transformation (Argyris, Morley: defined on affine cells only) or
    /// derivatives of order ≥ 3 (the message names the form and the block), for a
    /// block the form does not have, and from the default.
    fn element_matrix_curved(
        form: usize,
        block: usize,
        nodes: &[f64],
        params: &[f64],
        data: &[&DataFn],
        out: &mut [f64],
    ) -> Result<()> {
        let _ = (form, block, nodes, params, data, out);
        Err(Error::Input(format!(
            "model `{}` has no kernels on curved triangles (model! generates them for triangle models only)",
            Self::NAME
        )))
    }

    /// Element vector of `block` of linear `form` on a curved triangle into `out`: as
    /// [`Model::element_matrix_curved`].
    ///
    /// # Errors
    /// As [`Model::element_matrix_curved`].
    fn element_vector_curved(
        form: usize,
        block: usize,
        nodes: &[f64],
        params: &[f64],
        data: &[&DataFn],
        out: &mut [f64],
    ) -> Result<()> {
        let _ = (form, block, nodes, params, data, out);
        Err(Error::Input(format!(
            "model `{}` has no kernels on curved triangles (model! generates them for triangle models only)",
            Self::NAME
        )))
    }

    /// The boundary parts the model's forms integrate over (`facets:`), by name; the
    /// mesh says which edges a name holds. Empty by default (no boundary integrals).
    const FACET_PARTS: &'static [&'static str] = &[];

    /// The blocks of the boundary integrals of every form, in the order of
    /// [`Model::facet_matrix`] and [`Model::facet_vector`]'s `block`. Empty by default.
    const FACET_BLOCKS: &'static [FacetBlockInfo] = &[];

    /// Facet matrix of `FACET_BLOCKS[block]` (a bilinear form's) on local edge `edge`
    /// (joining local vertices `edge` and `(edge + 1) % 3`) of the affine triangle with
    /// vertex coordinates `vertices` (`[x0, y0, x1, y1, x2, y2]`), row-major into `out`
    /// (rows: the test field's local DOFs, columns: the trial field's).
    ///
    /// # Errors
    /// [`Error::Input`] for a block that is not a bilinear facet block, an edge above 2 or
    /// `vertices` not of length 6; the default (no facets) always.
    fn facet_matrix(
        block: usize,
        vertices: &[f64],
        edge: usize,
        params: &[f64],
        data: &[&DataFn],
        out: &mut [f64],
    ) -> Result<()> {
        let _ = (block, vertices, edge, params, data, out);
        Err(Error::Input(format!(
            "model `{}` has no boundary integrals (`facets:`)",
            Self::NAME
        )))
    }

    /// Facet vector of `FACET_BLOCKS[block]` (a linear form's): as
    /// [`Model::facet_matrix`].
    ///
    /// # Errors
    /// As [`Model::facet_matrix`].
    fn facet_vector(
        block: usize,
        vertices: &[f64],
        edge: usize,
        params: &[f64],
        data: &[&DataFn],
        out: &mut [f64],
    ) -> Result<()> {
        let _ = (block, vertices, edge, params, data, out);
        Err(Error::Input(format!(
            "model `{}` has no boundary integrals (`facets:`)",
            Self::NAME
        )))
    }

    /// Whether the model declares an estimator (`estimator:`): then
    /// [`Model::cell_indicator`] and [`Model::edge_indicator`] are its kernels.
    const HAS_ESTIMATOR: bool = false;

    /// The squared indicator `η_T²` of the model's `estimator:` on the affine triangle
    /// with vertex coordinates `vertices` (`[x0, y0, x1, y1, x2, y2]`; on intervals
    /// `[x0, x1]`, Hermite slopes times the cell's length), for the
    /// coefficients of the discrete solution on the cell, one slice per field, in the
    /// pulled-back reference basis ([`crate::element::triangle::TriangleField::reference_coefficients`]:
    /// the local DOFs for Lagrange elements, `Mᵀ U` for Argyris and Morley).
    ///
    /// # Errors
    /// [`Error::Input`] for slices of the wrong lengths, and always for a model without
    /// an estimator.
    fn cell_indicator(
        vertices: &[f64],
        coefficients: &[&[f64]],
        params: &[f64],
        data: &[&DataFn],
    ) -> Result<f64> {
        let _ = (vertices, coefficients, params, data);
        Err(Error::Input(format!(
            "model `{}` declares no estimator (`estimator:`)",
            Self::NAME
        )))
    }

    /// The squared indicator `η_E²` of the interior edge that is local edge `edge` of
    /// the triangle `vertices` (coefficients `coefficients`) and local edge `other_edge`
    /// of its neighbour `other_vertices` (`other_coefficients`); local edge `k` joins
    /// local vertices `k` and `(k + 1) % 3`. As [`Model::cell_indicator`].
    ///
    /// On intervals (`vertices = [x0, x1]`) the "edge" is an interior node: end `edge`
    /// (0 left, 1 right) of the cell and end `other_edge` of its neighbour.
    ///
    /// # Errors
    /// As [`Model::cell_indicator`], and for an edge above 2 (an end above 1).
    #[allow(clippy::too_many_arguments)]
    fn edge_indicator(
        vertices: &[f64],
        edge: usize,
        coefficients: &[&[f64]],
        other_vertices: &[f64],
        other_edge: usize,
        other_coefficients: &[&[f64]],
        params: &[f64],
        data: &[&DataFn],
    ) -> Result<f64> {
        let _ = (
            vertices,
            edge,
            coefficients,
            other_vertices,
            other_edge,
            other_coefficients,
            params,
            data,
        );
        Err(Error::Input(format!(
            "model `{}` declares no estimator (`estimator:`)",
            Self::NAME
        )))
    }

    /// The test coordinates `(field, j)` with a natural boundary term in the estimator
    /// (the coefficient of `v` for `j = 0`, of `∂_n v` for `j = 1`: the membrane's
    /// `∂_n u`, elasticity's `σ(u)n` by component, the plate's `V_n` and `M_nn`): where
    /// the coordinate is free on a boundary edge outside every boundary part its flux
    /// vanishes, and the interior edge term of that flux applies one-sided there, as
    /// [`Model::boundary_indicator`] of part `FACET_PARTS.len() + k`. Derived by the
    /// macro from the edge terms that are fluxes of `a` (empty without a strong form).
    /// On intervals the boundary is the mesh's two ends, `j = 1` the slope's flux (the
    /// beam's moment).
    const NATURAL_FLUXES: &'static [(usize, u8)] = &[];

    /// The squared indicator `η_Γ²` of the model's `estimator:` on the boundary edge that
    /// is local edge `edge` of the triangle `vertices`, an edge of the boundary part
    /// `part` (index in [`Model::FACET_PARTS`]), or for `part = FACET_PARTS.len() + k`
    /// the natural boundary term of `NATURAL_FLUXES[k]`; 0 for a part without boundary
    /// terms. On intervals `vertices` is the end cell `[x0, x1]`, `edge` its end (0 left,
    /// 1 right) and `part` the natural term `k`. As [`Model::cell_indicator`] (a
    /// multiplier on the part enters by its trace on the edge: for P0 one coefficient,
    /// for P1 the cell's three vertex values, the one off the edge unused).
    ///
    /// # Errors
    /// As [`Model::cell_indicator`], for an edge above 2 (an end above 1) and a part out
    /// of range; always for a model without an estimator.
    fn boundary_indicator(
        part: usize,
        vertices: &[f64],
        edge: usize,
        coefficients: &[&[f64]],
        params: &[f64],
        data: &[&DataFn],
    ) -> Result<f64> {
        let _ = (part, vertices, edge, coefficients, params, data);
        Err(Error::Input(format!(
            "model `{}` declares no estimator on boundary parts",
            Self::NAME
        )))
    }

    /// Index in `FACET_PARTS` of a boundary part the forms integrate over: its handle
    /// (`model::facets::Γ_C`) or its name (`"Γ_C"`).
    ///
    /// # Errors
    /// [`Error::UnknownName`] for a name the model does not declare under `facets:`.
    fn facet_part(part: impl IntoPartIndex<Self>) -> Result<usize> {
        part.part_index()
    }

    /// Index in `FORMS` of a form: its handle (`model::forms::B_h`) or its name (`"B_h"`).
    ///
    /// # Errors
    /// [`Error::UnknownName`] for a name the model does not define.
    fn form(form: impl IntoFormIndex<Self>) -> Result<usize> {
        form.form_index()
    }

    /// Index in `FIELDS` of a field: its handle (`model::fields::u`) or the name of its
    /// unknown or test function.
    ///
    /// # Errors
    /// [`Error::UnknownName`] for a name the model does not declare.
    fn field(field: impl IntoFieldIndex<Self>) -> Result<usize> {
        field.field_index()
    }

    /// Index in `PARAMS` of a parameter: its handle (`model::params::α`) or its name.
    ///
    /// # Errors
    /// [`Error::UnknownName`] for a name the model does not declare.
    fn param(param: impl IntoParamIndex<Self>) -> Result<usize> {
        param.param_index()
    }

    /// Index in `DATA` of a data function: its handle (`model::data::f`) or its name.
    ///
    /// # Errors
    /// [`Error::UnknownName`] for a name the model does not declare.
    fn data_function(data: impl IntoDataIndex<Self>) -> Result<usize> {
        data.data_index()
    }
}

/// The indices of the bilinear form `B_h` and the linear form `L_h` in `forms`
/// ([`Model::SYSTEM`]).
///
/// ```
/// use fem_runtime::Model;
/// fem_runtime::model! {
///     pub mod string on interval {
///         unknowns: u: P1, λ: P0 >= 0;
///         tests: v, μ;
///         forms: "
///             L_h(v, μ) = ∫ v
///             B_h(u,λ;v,μ) = ∫ u'v' − λ v − u μ
///             a(u;v) = ∫ u'v'
///         ";
///     }
/// }
/// assert_eq!(string::Model::SYSTEM, Some([1, 0]));
/// fem_runtime::model! {
///     pub mod plain on interval { unknowns: u: P1; tests: v; forms: "B_h(v) = ∫ v"; }
/// }
/// // a linear form named B_h is not the system's bilinear form
/// assert_eq!(plain::Model::SYSTEM, None);
/// ```
pub const fn system_forms(forms: &[FormInfo]) -> Option<[usize; 2]> {
    const fn same(a: &str, b: &str) -> bool {
        let (a, b) = (a.as_bytes(), b.as_bytes());
        if a.len() != b.len() {
            return false;
        }
        let mut i = 0;
        while i < a.len() {
            if a[i] != b[i] {
                return false;
            }
            i += 1;
        }
        true
    }
    let (mut bilinear, mut linear) = (None, None);
    let mut i = 0;
    while i < forms.len() {
        if forms[i].arity == 2 && same(forms[i].name, "B_h") {
            bilinear = Some(i);
        }
        if forms[i].arity == 1 && same(forms[i].name, "L_h") {
            linear = Some(i);
        }
        i += 1;
    }
    match (bilinear, linear) {
        (Some(b), Some(l)) => Some([b, l]),
        _ => None,
    }
}

/// Declares a typed handle, its conversion trait and the trait's impls for names
/// (`&str`, `&String`, …) and for the handle.
macro_rules! handle {
    (
        $(#[$doc:meta])*
        $handle:ident, $trait:ident, $method:ident, $kind:literal,
        |$name:ident| $find:expr, $names:expr, $count:expr
    ) => {
        $(#[$doc])*
        ///
        /// Generated by `model!` as a constant of the model's module; `M` is the model's
        /// `Model` type, so a handle of one model cannot be used with another.
        pub struct $handle<M> {
            index: usize,
            model: PhantomData<fn() -> M>,
        }

        impl<M> $handle<M> {
            /// The handle of entry `index` (in declaration order). Used by the generated
            /// code; an index out of range is refused where the handle is used.
            #[doc(hidden)]
            pub const fn new(index: usize) -> Self {
                Self {
                    index,
                    model: PhantomData,
                }
            }

            /// The index it stands for, in declaration order.
            pub const fn index(self) -> usize {
                self.index
            }
        }

        // Written out: derives would require `M: Clone` etc., which model types need not be.
        impl<M> Clone for $handle<M> {
            fn clone(&self) -> Self {
                *self
            }
        }

        impl<M> Copy for $handle<M> {}

        impl<M> PartialEq for $handle<M> {
            fn eq(&self, other: &Self) -> bool {
                self.index == other.index
            }
        }

        impl<M> Eq for $handle<M> {}

        impl<M> fmt::Debug for $handle<M> {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                write!(f, "{}({})", stringify!($handle), self.index)
            }
        }

        #[doc = concat!("A ", $kind, " of model `M`: its typed handle or its name.")]
        pub trait $trait<M: Model> {
            /// Its index in declaration order.
            ///
            /// # Errors
            /// [`Error::UnknownName`] for a name (or a hand-made handle) the model does
            /// not have.
            fn $method(self) -> Result<usize>;
        }

        impl<M: Model> $trait<M> for $handle<M> {
            fn $method(self) -> Result<usize> {
                if self.index < $count {
                    Ok(self.index)
                } else {
                    Err(unknown::<M>(
                        $kind,
                        &format!("#{}", self.index),
                        $names,
                    ))
                }
            }
        }

        impl<M: Model, S: AsRef<str> + ?Sized> $trait<M> for &S {
            fn $method(self) -> Result<usize> {
                let $name = self.as_ref();
                $find.ok_or_else(|| unknown::<M>($kind, $name, $names))
            }
        }
    };
}

handle!(
    /// Typed handle of a form of model `M`, e.g. `membrane_p2_p0::forms::B_h`.
    FormId, IntoFormIndex, form_index, "form",
    |name| M::FORMS.iter().position(|f| f.name == name),
    M::FORMS.iter().map(|f| f.name),
    M::FORMS.len()
);

handle!(
    /// Typed handle of a field of model `M`, by its unknown or its test function, e.g.
    /// `membrane_p2_p0::fields::u` (the same field as `fields::v`).
    FieldId, IntoFieldIndex, field_index, "field",
    |name| M::FIELDS
        .iter()
        .position(|f| f.name == name || f.test_name == name),
    M::FIELDS.iter().map(|f| f.name),
    M::FIELDS.len()
);

handle!(
    /// Typed handle of a parameter of model `M`, e.g. `membrane_p2_p0::params::α`.
    ParamId, IntoParamIndex, param_index, "parameter",
    |name| M::PARAMS.iter().position(|p| *p == name),
    M::PARAMS.iter().copied(),
    M::PARAMS.len()
);

handle!(
    /// Typed handle of a data function of model `M`, e.g. `membrane_p2_p0::data::f`.
    DataId, IntoDataIndex, data_index, "data function",
    |name| M::DATA.iter().position(|p| *p == name),
    M::DATA.iter().copied(),
    M::DATA.len()
);

handle!(
    /// Typed handle of a boundary part of model `M` (declared under `facets:`), e.g.
    /// `signorini_p1::facets::Γ_C`.
    PartId, IntoPartIndex, part_index, "boundary part",
    |name| M::FACET_PARTS.iter().position(|p| *p == name),
    M::FACET_PARTS.iter().copied(),
    M::FACET_PARTS.len()
);

fn unknown<M: Model>(
    kind: &'static str,
    name: &str,
    available: impl Iterator<Item = &'static str>,
) -> Error {
    Error::UnknownName {
        model: M::NAME,
        kind,
        name: name.to_string(),
        available: available.collect::<Vec<_>>().join(", "),
    }
}

/// Parameter values and data functions for one model, checked against its declaration.
pub struct Coefficients<'a> {
    /// Parameter values in declaration order.
    pub params: Vec<f64>,
    /// Data functions in declaration order.
    pub data: Vec<&'a DataFn>,
}

impl<'a> Coefficients<'a> {
    /// Values by name; every declared parameter and data function must be given once,
    /// parameters must be finite, and positive where the model declares them `> 0`.
    /// Names come from the model's declaration (a scene file gives them as strings); in
    /// Rust, [`Coefficients::from_ids`] takes typed handles.
    ///
    /// # Errors
    /// An unknown name, a name given twice, a missing one, a non-finite value, or a
    /// value ≤ 0 of a parameter declared `> 0`.
    pub fn new<M: Model>(params: &[(&str, f64)], data: &[(&str, &'a DataFn)]) -> Result<Self> {
        let params = params
            .iter()
            .map(|&(name, v)| Ok((M::param(name)?, v)))
            .collect::<Result<Vec<_>>>()?;
        let data = data
            .iter()
            .map(|&(name, f)| Ok((M::data_function(name)?, f)))
            .collect::<Result<Vec<_>>>()?;
        Self::from_indices::<M>(&params, &data)
    }

    /// Values by typed handle, e.g. `Coefficients::from_ids(&[(m::params::α, 0.1)],
    /// &[(m::data::f, &f)])`: a misspelled name is a compile error and the model is
    /// inferred from the handles. Every declared parameter and data function must be
    /// given once, parameters must be finite, and positive where declared `> 0`.
    ///
    /// # Errors
    /// A handle given twice, a missing one, a non-finite value, or a value ≤ 0 of a
    /// parameter declared `> 0`.
    pub fn from_ids<M: Model>(
        params: &[(ParamId<M>, f64)],
        data: &[(DataId<M>, &'a DataFn)],
    ) -> Result<Self> {
        let params = params
            .iter()
            .map(|&(id, v)| Ok((M::param(id)?, v)))
            .collect::<Result<Vec<_>>>()?;
        let data = data
            .iter()
            .map(|&(id, f)| Ok((M::data_function(id)?, f)))
            .collect::<Result<Vec<_>>>()?;
        Self::from_indices::<M>(&params, &data)
    }

    /// Every parameter's value and every data function, in declaration order, checked as
    /// [`Coefficients::new`] checks them.
    ///
    /// # Errors
    /// Counts that do not match the model's, a non-finite value, or a value ≤ 0 of a
    /// parameter declared `> 0`.
    pub fn of_values<M: Model>(params: &[f64], data: &[&'a DataFn]) -> Result<Self> {
        if params.len() != M::PARAMS.len() || data.len() != M::DATA.len() {
            return Err(Error::Input(format!(
                "model `{}` has {} parameters and {} data functions, given {} and {}",
                M::NAME,
                M::PARAMS.len(),
                M::DATA.len(),
                params.len(),
                data.len()
            )));
        }
        let params: Vec<(usize, f64)> = params.iter().copied().enumerate().collect();
        let data: Vec<(usize, &'a DataFn)> = data.iter().copied().enumerate().collect();
        Self::from_indices::<M>(&params, &data)
    }

    /// The checks shared by [`Coefficients::new`] and [`Coefficients::from_ids`], on
    /// indices in declaration order.
    fn from_indices<M: Model>(
        params: &[(usize, f64)],
        data: &[(usize, &'a DataFn)],
    ) -> Result<Self> {
        let mut values = vec![None; M::PARAMS.len()];
        for &(i, v) in params {
            let name = M::PARAMS[i];
            if !v.is_finite() {
                return Err(Error::Input(format!(
                    "parameter `{name}` = {v} is not finite"
                )));
            }
            if v <= 0.0 && M::POSITIVE_PARAMS.contains(&i) {
                return Err(Error::Input(format!(
                    "parameter `{name}` = {v} must be positive (model `{}` declares `{name} > 0`)",
                    M::NAME
                )));
            }
            if values[i].replace(v).is_some() {
                return Err(Error::Input(format!("parameter `{name}` given twice")));
            }
        }
        let mut functions: Vec<Option<&'a DataFn>> = vec![None; M::DATA.len()];
        for &(i, f) in data {
            if functions[i].replace(f).is_some() {
                return Err(Error::Input(format!(
                    "data function `{}` given twice",
                    M::DATA[i]
                )));
            }
        }
        let missing: Vec<&str> = M::PARAMS
            .iter()
            .zip(&values)
            .filter(|(_, v)| v.is_none())
            .map(|(n, _)| *n)
            .chain(
                M::DATA
                    .iter()
                    .zip(&functions)
                    .filter(|(_, f)| f.is_none())
                    .map(|(n, _)| *n),
            )
            .collect();
        if !missing.is_empty() {
            return Err(Error::Input(format!(
                "model `{}` needs values for {}",
                M::NAME,
                missing.join(", ")
            )));
        }
        let params: Vec<f64> = values.into_iter().map(Option::unwrap).collect();
        for &(x, y) in M::UNIT_PARAMS {
            let length = params[x].hypot(params[y]);
            if (length - 1.0).abs() > UNIT_TOLERANCE {
                return Err(Error::Input(format!(
                    "parameters `{}` = {} and `{}` = {} must form a unit vector (model `{}` declares it `unit:`), their length is {length}: normalize them",
                    M::PARAMS[x],
                    params[x],
                    M::PARAMS[y],
                    params[y],
                    M::NAME
                )));
            }
        }
        Ok(Self {
            params,
            data: functions.into_iter().map(Option::unwrap).collect(),
        })
    }
}

/// How far from 1 the length of a vector of parameters declared `unit:` may be: a
/// direction normalized in double precision is within a few ulps; a hand-written
/// `(0.6, 0.8)` within rounding too.
pub const UNIT_TOLERANCE: f64 = 1e-9;

/// Cells whose blocks [`require_symmetric`] compares at most: every cell up to this
/// many, else every k-th cell. At about 0.1 µs per kernel call that is well under a
/// second on the largest meshes, against an assembly that visits every cell anyway.
pub const MAX_SYMMETRY_CELLS: usize = 1 << 18;

/// An error unless the cell blocks of bilinear form `form` are symmetric on `mesh`:
/// on each cell (every cell, or every k-th beyond [`MAX_SYMMETRY_CELLS`]) block
/// `(i, j)` the transpose of block `(j, i)`, to 1e-9 of their largest entry, with the
/// parameters and data of `coefficients`. The obstacle and contact solvers need their
/// system form `B_h` symmetric: they read `B` from its multiplier rows alone and factor
/// its primal block by Cholesky, so a `− b(v;λ) + b(u;μ)` was solved to a
/// string 0.93 through its obstacle with a KKT residual of 1e-16. Compared in numbers,
/// not symbols, so that equal terms written differently (`∫[degree=1]` beside an exact
/// rule, `1/(2 + 2t²)` beside `0.5/(1 + t²)`) pass; and on every cell, not the first
/// alone, since data can make a form symmetric on some cells only (a
/// convection `β u'v` with β = 0 on half the domain, including cell 0). Boundary
/// integrals are compared on their own edges by [`require_symmetric_facets`].
///
/// # Errors
/// [`Error::Input`] naming the cell and the fields of the first block that is not the
/// transpose of its mirror; [`Error::NonFinite`] for a cell whose blocks are not finite
/// (NaN or infinite data there).
pub fn require_symmetric<M: Model, G: crate::mesh::Mesh>(
    form: usize,
    mesh: &G,
    coefficients: &Coefficients,
) -> Result<()> {
    if mesh.cell_count() == 0 || M::FORMS[form].arity != 2 {
        return Ok(());
    }
    let width = match G::CELL {
        CellKind::Interval => 2,
        CellKind::Triangle => 6,
    };
    let mut x = vec![0.0; width];
    let counts: Vec<usize> = M::FIELDS
        .iter()
        .map(|field| field.element.local_dof_count(M::CELL))
        .collect();
    let mut blocks = Blocks::default();
    let mut out = Vec::new();
    let step = mesh.cell_count().div_ceil(MAX_SYMMETRY_CELLS);
    for cell in (0..mesh.cell_count()).step_by(step) {
        mesh.cell_coordinates_into(cell, &mut x);
        blocks.clear();
        for (b, block) in M::FORMS[form].blocks.iter().enumerate() {
            let Some(trial) = block.trial_field else {
                continue;
            };
            let test = block.test_field;
            out.clear();
            out.resize(counts[test] * counts[trial], 0.0);
            M::element_matrix(
                form,
                b,
                &x,
                &coefficients.params,
                &coefficients.data,
                &mut out,
            );
            blocks.add((test, trial), &out);
        }
        if !blocks.finite() {
            return Err(Error::NonFinite {
                what: "matrix",
                cell,
            });
        }
        blocks.require_transposes::<M>(form, &counts, &format!("on cell {cell}"))?;
    }
    Ok(())
}

/// [`require_symmetric`] for the boundary integrals of `form` over the boundary part
/// `part` (an index in `FACET_PARTS`), on its edges `edges` (`(cell, local edge)`): the
/// facet blocks are compared where they are integrated, since a form can be symmetric
/// on the part and not elsewhere (`v·n` beside `v·n_c`, equal where n = n_c).
///
/// # Errors
/// [`Error::Input`] naming the part, the edge's cell and the fields of the first block
/// that is not the transpose of its mirror; [`Error::NonFinite`] for non-finite blocks;
/// the facet kernels' errors.
pub fn require_symmetric_facets<M: Model>(
    form: usize,
    part: usize,
    mesh: &crate::mesh::TriangleMesh,
    coefficients: &Coefficients,
    edges: &[(usize, usize)],
) -> Result<()> {
    if M::FORMS[form].arity != 2 || M::CELL != CellKind::Triangle {
        return Ok(());
    }
    let counts: Vec<usize> = M::FIELDS
        .iter()
        .map(|field| field.element.local_dof_count(M::CELL))
        .collect();
    let mut x = vec![0.0; 6];
    let mut blocks = Blocks::default();
    let mut out = Vec::new();
    for &(cell, local) in edges {
        crate::mesh::Mesh::cell_coordinates_into(mesh, cell, &mut x);
        blocks.clear();
        for (b, block) in M::FACET_BLOCKS.iter().enumerate() {
            let Some(trial) = block.trial_field else {
                continue;
            };
            if block.form != form || block.part != part {
                continue;
            }
            let test = block.test_field;
            out.clear();
            out.resize(counts[test] * counts[trial], 0.0);
            M::facet_matrix(
                b,
                &x,
                local,
                &coefficients.params,
                &coefficients.data,
                &mut out,
            )?;
            blocks.add((test, trial), &out);
        }
        if !blocks.finite() {
            return Err(Error::NonFinite {
                what: "facet matrix",
                cell,
            });
        }
        blocks.require_transposes::<M>(
            form,
            &counts,
            &format!(
                "on the edge of cell {cell} in the boundary integral over `{}`",
                M::FACET_PARTS[part]
            ),
        )?;
    }
    Ok(())
}

/// The blocks of one form on one cell (or edge), summed by `(test field, trial field)`;
/// cleared and refilled cell by cell without allocating.
#[derive(Default)]
struct Blocks(Vec<((usize, usize), Vec<f64>, bool)>);

impl Blocks {
    /// Marks every block unused (its storage stays).
    fn clear(&mut self) {
        for (_, sum, used) in &mut self.0 {
            sum.iter_mut().for_each(|s| *s = 0.0);
            *used = false;
        }
    }

    fn add(&mut self, key: (usize, usize), out: &[f64]) {
        match self.0.iter_mut().find(|(k, _, _)| *k == key) {
            Some((_, sum, used)) => {
                sum.iter_mut().zip(out).for_each(|(s, o)| *s += o);
                *used = true;
            }
            None => self.0.push((key, out.to_vec(), true)),
        }
    }

    fn finite(&self) -> bool {
        self.0
            .iter()
            .all(|(_, sum, _)| sum.iter().all(|v| v.is_finite()))
    }

    /// `place` says where the blocks were computed (`on cell 7`).
    fn require_transposes<M: Model>(
        &self,
        form: usize,
        counts: &[usize],
        place: &str,
    ) -> Result<()> {
        let largest = |m: &[f64]| m.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        for ((test, trial), mine, used) in &self.0 {
            if !used {
                continue;
            }
            let (rows, cols) = (counts[*test], counts[*trial]);
            let zero = vec![0.0; rows * cols];
            let mirror = self
                .0
                .iter()
                .find(|(key, _, used)| *used && *key == (*trial, *test))
                .map_or(&zero, |(_, m, _)| m);
            let tolerance = 1e-9 * largest(mine).max(largest(mirror));
            let transposed = (0..rows).all(|i| {
                (0..cols).all(|j| (mine[i * cols + j] - mirror[j * rows + i]).abs() <= tolerance)
            });
            if !transposed {
                let (name, fields) = (M::FORMS[form].name, M::FIELDS);
                let which = if test == trial {
                    format!(
                        "its block of `{}` rows and `{}` columns is not symmetric",
                        fields[*test].test_name, fields[*trial].name
                    )
                } else {
                    format!(
                        "its block of `{}` rows and `{}` columns is not the transpose of the block of `{}` rows and `{}` columns",
                        fields[*test].test_name,
                        fields[*trial].name,
                        fields[*trial].test_name,
                        fields[*test].name,
                    )
                };
                return Err(Error::Input(format!(
                    "`{name}` of model `{}` is not symmetric: {place} {which}. The obstacle solvers read B from the multiplier rows alone and factor the primal block by Cholesky, so they would solve another problem; write `{name}` as a(u;v) − b(v;λ) − b(u;μ) − α S(u,λ;v,μ) with a and S symmetric",
                    M::NAME,
                )));
            }
        }
        Ok(())
    }
}
