//! What a generated model tells the runtime: its fields, parameters, data and forms,
//! and the dispatch to its element kernels.

use crate::error::{Error, Result};
use fem_reference::{CellKind, ElementKind};

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
    /// into `values`, entry `(i, j)` of cell `c` at `positions[c·stride + offset + i·cols + j]`.
    #[allow(clippy::too_many_arguments)]
    fn add_element_matrices<G: crate::mesh::Mesh>(
        form: usize,
        block: usize,
        mesh: &G,
        params: &[f64],
        data: &[&DataFn],
        positions: &[usize],
        stride: usize,
        offset: usize,
        values: &mut [f64],
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

    /// Index of the form called `name`.
    fn form(name: &str) -> Result<usize> {
        Self::FORMS
            .iter()
            .position(|f| f.name == name)
            .ok_or_else(|| unknown::<Self>("form", name, Self::FORMS.iter().map(|f| f.name)))
    }

    /// Index of the field whose unknown (or test function) is called `name`.
    fn field(name: &str) -> Result<usize> {
        Self::FIELDS
            .iter()
            .position(|f| f.name == name || f.test_name == name)
            .ok_or_else(|| unknown::<Self>("field", name, Self::FIELDS.iter().map(|f| f.name)))
    }
}

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
    /// parameters must be finite.
    pub fn new<M: Model>(params: &[(&str, f64)], data: &[(&str, &'a DataFn)]) -> Result<Self> {
        let mut values = vec![None; M::PARAMS.len()];
        for &(name, v) in params {
            let i = M::PARAMS
                .iter()
                .position(|p| *p == name)
                .ok_or_else(|| unknown::<M>("parameter", name, M::PARAMS.iter().copied()))?;
            if !v.is_finite() {
                return Err(Error::Input(format!(
                    "parameter `{name}` = {v} is not finite"
                )));
            }
            if values[i].replace(v).is_some() {
                return Err(Error::Input(format!("parameter `{name}` given twice")));
            }
        }
        let mut functions: Vec<Option<&'a DataFn>> = vec![None; M::DATA.len()];
        for &(name, f) in data {
            let i = M::DATA
                .iter()
                .position(|p| *p == name)
                .ok_or_else(|| unknown::<M>("data function", name, M::DATA.iter().copied()))?;
            if functions[i].replace(f).is_some() {
                return Err(Error::Input(format!("data function `{name}` given twice")));
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
        Ok(Self {
            params: values.into_iter().map(Option::unwrap).collect(),
            data: functions.into_iter().map(Option::unwrap).collect(),
        })
    }
}
