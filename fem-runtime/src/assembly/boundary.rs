//! Boundary conditions as fixed DOFs, applied by eliminating them from the system.
//!
//! Elimination keeps a symmetric matrix symmetric (and SPD stays SPD), which the
//! Cholesky solve and the active-set solvers rely on.

use crate::assembly::dof_map::SystemDofs;
use crate::error::{Error, Result};
use crate::mesh::IntervalMesh;
use crate::model::Model;
use crate::SparseMatrix;
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use fem_reference::DofLocation;

/// An end of the interval.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// The left end.
    Left,
    /// The right end.
    Right,
}

/// Fixed DOFs with their values.
#[derive(Clone, Debug, Default)]
pub struct Constraints {
    fixed: Vec<(usize, f64)>,
}

impl Constraints {
    /// No constraint.
    pub fn new() -> Self {
        Self::default()
    }

    fn vertex(mesh: &IntervalMesh, side: Side) -> usize {
        match side {
            Side::Left => 0,
            Side::Right => mesh.vertex_count() - 1,
        }
    }

    /// Fixes the DOF of `field` at the `side` vertex that measures the derivative of
    /// order `derivative` (0: value, 1: slope, Hermite only).
    fn fix<M: Model>(
        &mut self,
        mesh: &IntervalMesh,
        dofs: &SystemDofs,
        field: &str,
        side: Side,
        derivative: usize,
        value: f64,
    ) -> Result<()> {
        let f = M::field(field)?;
        let map = dofs
            .map(f)
            .ok_or_else(|| Error::Input(format!("field `{field}` is not part of this system")))?;
        let element = map.element();
        let vertex_dofs = map.vertex_dofs(Self::vertex(mesh, side));
        let k = element
            .dofs()
            .iter()
            .filter(|d| matches!(d, DofLocation::Vertex { vertex: 0, .. }))
            .position(
                |d| matches!(d, DofLocation::Vertex { derivative: o, .. } if *o == derivative),
            )
            .ok_or_else(|| {
                Error::Input(format!(
                    "field `{field}` ({}) has no {} DOF at the boundary",
                    element.name(),
                    if derivative == 0 { "value" } else { "slope" }
                ))
            })?;
        if !value.is_finite() {
            return Err(Error::Input(format!(
                "boundary value {value} for `{field}` is not finite"
            )));
        }
        let dof = dofs.offset(f).unwrap() + vertex_dofs.start + k;
        self.fixed.retain(|&(d, _)| d != dof);
        self.fixed.push((dof, value));
        Ok(())
    }

    /// `field = value` at the `side` end.
    pub fn dirichlet<M: Model>(
        &mut self,
        mesh: &IntervalMesh,
        dofs: &SystemDofs,
        field: &str,
        side: Side,
        value: f64,
    ) -> Result<()> {
        self.fix::<M>(mesh, dofs, field, side, 0, value)
    }

    /// `field' = slope` at the `side` end (C¹ elements).
    pub fn slope<M: Model>(
        &mut self,
        mesh: &IntervalMesh,
        dofs: &SystemDofs,
        field: &str,
        side: Side,
        slope: f64,
    ) -> Result<()> {
        self.fix::<M>(mesh, dofs, field, side, 1, slope)
    }

    /// Clamps `field` at the `side` end: its value, and its slope when the element has a
    /// slope DOF, are zero.
    pub fn clamp<M: Model>(
        &mut self,
        mesh: &IntervalMesh,
        dofs: &SystemDofs,
        field: &str,
        side: Side,
    ) -> Result<()> {
        self.dirichlet::<M>(mesh, dofs, field, side, 0.0)?;
        let f = M::field(field)?;
        if M::FIELDS[f].element.dofs_per_vertex() > 1 {
            self.slope::<M>(mesh, dofs, field, side, 0.0)?;
        }
        Ok(())
    }

    /// Fixes global DOF `dof` to `value` (a later value for the same DOF wins).
    pub fn fix_dof(&mut self, dof: usize, value: f64) -> Result<()> {
        if !value.is_finite() {
            return Err(Error::Input(format!(
                "boundary value {value} at DOF {dof} is not finite"
            )));
        }
        self.fixed.push((dof, value));
        Ok(())
    }

    /// The fixed DOFs and their values.
    pub fn fixed(&self) -> &[(usize, f64)] {
        &self.fixed
    }

    /// The elimination for a system of `n` DOFs.
    pub fn reduction(&self, n: usize) -> Result<Reduction> {
        let mut value = vec![None; n];
        for &(d, v) in &self.fixed {
            *value
                .get_mut(d)
                .ok_or_else(|| Error::Input(format!("fixed DOF {d} outside a system of {n}")))? =
                Some(v);
        }
        let mut free_index = vec![usize::MAX; n];
        let mut free = Vec::new();
        for (d, v) in value.iter().enumerate() {
            if v.is_none() {
                free_index[d] = free.len();
                free.push(d);
            }
        }
        Ok(Reduction {
            value: value.into_iter().map(|v| v.unwrap_or(0.0)).collect(),
            free_index,
            free,
        })
    }
}

/// The map between a full system and its free DOFs.
#[derive(Clone, Debug)]
pub struct Reduction {
    value: Vec<f64>,
    free_index: Vec<usize>,
    free: Vec<usize>,
}

impl Reduction {
    /// Free DOFs (full numbering), increasing.
    pub fn free(&self) -> &[usize] {
        &self.free
    }

    /// The value of DOF `d` if it is fixed, 0 if it is free.
    pub fn fixed_value(&self, d: usize) -> f64 {
        self.value[d]
    }

    /// Index among the free DOFs of full DOF `d`, if it is free.
    pub fn free_index(&self, d: usize) -> Option<usize> {
        (self.free_index[d] != usize::MAX).then_some(self.free_index[d])
    }

    /// The free–free block of `a`.
    pub fn matrix(&self, a: &SparseMatrix) -> SparseMatrix {
        let n = self.free.len();
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::new();
        let mut values = Vec::new();
        col_ptr.push(0);
        let (col_ptrs, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
        for &j in &self.free {
            for k in col_ptrs[j]..col_ptrs[j + 1] {
                let fi = self.free_index[rows[k]];
                if fi != usize::MAX {
                    row_idx.push(fi);
                    values.push(vals[k]);
                }
            }
            col_ptr.push(row_idx.len());
        }
        SparseColMat::new(
            SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx),
            values,
        )
    }

    /// The free part of `b − A u_fixed`.
    pub fn rhs(&self, a: &SparseMatrix, b: &[f64]) -> Vec<f64> {
        let mut full = b.to_vec();
        let (col_ptrs, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
        for (j, &v) in self.value.iter().enumerate() {
            if v != 0.0 && self.free_index[j] == usize::MAX {
                for k in col_ptrs[j]..col_ptrs[j + 1] {
                    full[rows[k]] -= vals[k] * v;
                }
            }
        }
        self.free.iter().map(|&d| full[d]).collect()
    }

    /// The full vector from the free values (fixed DOFs get their values).
    pub fn expand(&self, free_values: &[f64]) -> Vec<f64> {
        let mut full = self.value.clone();
        for (k, &d) in self.free.iter().enumerate() {
            full[d] = free_values[k];
        }
        full
    }
}
