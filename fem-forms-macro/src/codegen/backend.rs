//! What a cell kind implements to get element kernels: the interface between the
//! cell-independent driver and emitter and one backend per reference cell.
//!
//! A backend knows its cell's geometry (the affine map, `h`, the Jacobian), its
//! reference basis and quadrature rules, and how a derivative on the physical cell is
//! written in reference derivatives. Everything else — the kernel's frame, the grouping
//! of data terms into quadrature loops, the tables of basis values, the final entries —
//! is shared (`emit.rs`). A new cell kind (quadrilaterals, tetrahedra) is a new
//! implementation of [`CellBackend`]; a facet integral would be a second kernel kind
//! with its own geometry prelude and rules, reusing the same loop emitter.

use crate::analysis::{Block, Symbols, Term};
use fem_reference::ElementKind;
use proc_macro2::{Ident, TokenStream};

/// A quadrature rule on the reference cell: points (one coordinate per dimension) and
/// weights (summing to the reference cell's measure).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Rule {
    /// The points, each of length the cell's dimension.
    pub points: Vec<Vec<f64>>,
    /// The weights.
    pub weights: Vec<f64>,
}

impl Rule {
    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }
}

/// The constant-coefficient part of a block kernel, integrated at compile time: run-time
/// scalars (`let` statements) and, per scalar, its table of reference integrals.
/// Entry `(i, j)` gets `Σ scalar · table[i][j]` over the tables' non-negligible literals.
pub(crate) struct ExactPart {
    /// `let` statements computing the scalars (and what they need), in order.
    pub lets: Vec<TokenStream>,
    /// `(scalar, table[row][column])`.
    pub tables: Vec<(Ident, Vec<Vec<f64>>)>,
    /// Points of the rules used at compile time for an explicit `∫[degree=N]` (reported
    /// in `BlockInfo::quadrature_points`, 0 when every term was integrated exactly).
    pub quadrature_points: usize,
}

/// One reference cell kind's part of the code generator.
pub(crate) trait CellBackend {
    /// The `CellKind` variant of the runtime (`Interval`, `Triangle`).
    fn cell_variant(&self) -> &'static str;
    /// Number of vertex coordinates of a cell (the kernels' `x: &[f64; N]`).
    fn coordinates(&self) -> usize;
    /// What to say when a vertex slice has the wrong length.
    fn coordinates_message(&self) -> &'static str;
    /// Added to a kernel's doc title (e.g. `" on triangles"`).
    fn doc_suffix(&self) -> &'static str;
    /// Number of basis functions of `element` on this cell.
    fn dof_count(&self, element: ElementKind) -> usize;
    /// Power of `h` scaling basis function `index` of `element` (Hermite slope DOFs on
    /// intervals, see `ElementKind::dof_scaling_power`); 0 for nodal bases.
    fn dof_scaling(&self, element: ElementKind, index: usize) -> i32;
    /// Quadrature degree that integrates `term` exactly on an affine cell (data counted
    /// with their declared degree), or the explicit `∫[degree=N]`: a derivative of total
    /// order `k` lowers a basis function's degree by `k` on an affine cell.
    fn term_degree(&self, term: &Term, block: &Block, symbols: &Symbols) -> usize {
        if let Some(d) = term.quadrature_degree {
            return d;
        }
        let degree = |field: usize, derivative: [u8; 2]| {
            let order = derivative.iter().map(|&d| d as usize).sum::<usize>();
            symbols.fields[field].element.degree().saturating_sub(order)
        };
        let mut total = degree(block.test_field, term.test_derivative);
        if let (Some(f), Some(d)) = (block.trial_field, term.trial_derivative) {
            total += degree(f, d);
        }
        total + term.data.iter().map(|&i| symbols.data[i].1).sum::<usize>()
    }
    /// Whether the emitter may use the symmetry of a symmetric block ([`super::emit::is_symmetric`]):
    /// compute its entries on and above the diagonal only and mirror them, which needs
    /// the backend's constant-coefficient part to be symmetric whenever the block's terms
    /// are. Off by default.
    fn symmetric_entries(&self) -> bool {
        false
    }
    /// The rule used for `degree`.
    fn rule(&self, degree: usize) -> Rule;
    /// Statements computing the cell geometry the block's terms need (`h`, `J`,
    /// `det J`, …) from the vertex coordinates `x`.
    fn geometry(&self, block: &Block) -> TokenStream;
    /// The block's constant-coefficient terms (`terms` holds only those).
    fn exact_part(&self, block: &Block, symbols: &Symbols, terms: &[&Term]) -> ExactPart;
    /// `const XI: [...; N] = [...];` for the points of `rule`.
    fn points_const(&self, rule: &Rule) -> TokenStream;
    /// Statement `let xq = …;`: the physical point of reference point `XI[q]`.
    fn physical_point(&self) -> TokenStream;
    /// The argument passed to a data function at `xq` (a `&[f64]`).
    fn data_argument(&self) -> TokenStream;
    /// Factor of a quadrature weight from the cell map (`None` when folded elsewhere).
    fn weight_factor(&self) -> Option<TokenStream>;
    /// The coefficient of a data term at a quadrature point, as code (without data).
    fn data_term_coefficient(&self, term: &Term) -> TokenStream;
    /// Name of the table of `derivative`s of `element`'s basis at the loop's points.
    fn table_ident(&self, element: ElementKind, derivative: [u8; 2]) -> Ident;
    /// Values `[q][i]` of the reference `derivative` of basis function `i` at point `q`.
    fn tabulate(&self, element: ElementKind, derivative: [u8; 2], rule: &Rule) -> Vec<Vec<f64>>;
    /// The physical `derivative` of basis function `index` of `element` at point `q`,
    /// written with reference tables named through `table`.
    fn basis_value(
        &self,
        element: ElementKind,
        derivative: [u8; 2],
        index: TokenStream,
        table: &mut dyn FnMut(ElementKind, [u8; 2]) -> Ident,
    ) -> TokenStream;
}
