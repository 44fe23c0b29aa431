//! Errors of finite element functions against exact solutions, by quadrature.

use crate::assembly::dof_map::DofMap;
use crate::element::interval::PhysicalBasis;
use crate::element::mapping::Affine;
use crate::mesh::IntervalMesh;
use fem_reference::gauss_legendre;

/// A field's coefficients with its DOF map, evaluated cell by cell.
pub struct FieldView<'a> {
    /// The mesh.
    pub mesh: &'a IntervalMesh,
    /// The field's DOF map.
    pub map: &'a DofMap,
    /// The field's coefficients (in the map's numbering).
    pub coefficients: &'a [f64],
}

impl FieldView<'_> {
    /// Local coefficients of cell `c`.
    pub fn local(&self, c: usize) -> Vec<f64> {
        self.map
            .cell_dofs(c)
            .iter()
            .map(|&d| self.coefficients[d])
            .collect()
    }

    /// `d^k/dx^k` of the field at `x` (from the left cell at a vertex); `None` outside.
    pub fn at(&self, x: f64, derivative: usize) -> Option<f64> {
        let basis = PhysicalBasis::new(self.map.element(), derivative);
        self.at_with(&basis, x, derivative)
    }

    /// [`FieldView::at`] with a basis built once by the caller (for many points).
    pub fn at_with(&self, basis: &PhysicalBasis, x: f64, derivative: usize) -> Option<f64> {
        let c = self.mesh.locate(x)?;
        let cell = self.mesh.cell(c);
        let [xi] = Affine::interval(cell).reference_point([x]);
        let dofs = self.map.cell_dofs(c);
        Some(
            dofs.iter()
                .enumerate()
                .map(|(i, &d)| self.coefficients[d] * basis.value(i, derivative, cell, xi))
                .sum(),
        )
    }

    /// `(Σ_T ∫_T |dᵏ(u − u_h)|²)^{1/2}` with an `n`-point Gauss rule per cell.
    pub fn error(&self, derivative: usize, exact: &dyn Fn(f64) -> f64, points: usize) -> f64 {
        let rule = gauss_legendre(points);
        let basis = PhysicalBasis::new(self.map.element(), derivative);
        let mut sum = 0.0;
        for c in 0..self.mesh.cell_count() {
            let cell = self.mesh.cell(c);
            let map = Affine::interval(cell);
            let local = self.local(c);
            for (&xi, &w) in rule.points.iter().zip(&rule.weights) {
                let [x] = map.point([xi]);
                let e = exact(x) - basis.evaluate(&local, derivative, cell, xi);
                sum += w * map.det * e * e;
            }
        }
        sum.sqrt()
    }

    /// `∫ u_h` (e.g. the total contact force of a multiplier).
    pub fn integral(&self) -> f64 {
        let rule = gauss_legendre(3);
        let basis = PhysicalBasis::new(self.map.element(), 0);
        (0..self.mesh.cell_count())
            .map(|c| {
                let cell = self.mesh.cell(c);
                let local = self.local(c);
                rule.points
                    .iter()
                    .zip(&rule.weights)
                    .map(|(&xi, &w)| w * (cell[1] - cell[0]) * basis.evaluate(&local, 0, cell, xi))
                    .sum::<f64>()
            })
            .sum()
    }
}
