//! Reference elements on the reference interval `[0, 1]`.
//!
//! An element is declarative data: its degree, its DOF layout (which DOFs sit on which
//! vertex and which are interior), and its basis as polynomials on the reference cell.
//! Local DOFs are ordered vertex 0, vertex 1, then interior, so that a DOF map can
//! share vertex DOFs between neighbouring cells.

use crate::polynomial::Polynomial;

/// The reference cell a model is posed on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CellKind {
    /// The interval `[0, 1]` (beams).
    Interval,
    /// The triangle with vertices `(0,0), (1,0), (0,1)` (membranes and plates).
    Triangle,
}

impl CellKind {
    /// Spatial dimension of the cell.
    pub fn dimension(self) -> usize {
        match self {
            CellKind::Interval => 1,
            CellKind::Triangle => 2,
        }
    }

    /// Number of vertices of the cell.
    pub fn vertex_count(self) -> usize {
        match self {
            CellKind::Interval => 2,
            CellKind::Triangle => 3,
        }
    }

    /// The cell's name as written in a model file.
    pub fn name(self) -> &'static str {
        match self {
            CellKind::Interval => "interval",
            CellKind::Triangle => "triangle",
        }
    }
}

/// Where a degree of freedom lives on the reference cell and what it measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DofLocation {
    /// The value (`derivative = 0`) or the first derivative (`derivative = 1`) at a vertex.
    Vertex {
        /// Local vertex number.
        vertex: usize,
        /// Order of the derivative this DOF measures.
        derivative: usize,
    },
    /// A DOF owned by the cell alone (not shared with neighbours).
    Interior,
}

/// The finite elements fem-forms knows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ElementKind {
    /// Piecewise constants, discontinuous (multipliers).
    P0,
    /// Continuous piecewise linear Lagrange.
    P1,
    /// Continuous piecewise quadratic Lagrange.
    P2,
    /// Continuous piecewise cubic Lagrange.
    P3,
    /// C¹ Hermite cubic on intervals: value and slope at both vertices.
    Hermite,
    /// Discontinuous piecewise linear Lagrange (multipliers): nodal values at the
    /// cell's vertices, owned by the cell.
    P1Disc,
    /// The C¹ Argyris quintic on triangles (`docs/elements.md`): at each vertex the
    /// value, the gradient and the Hessian `(u, u_x, u_y, u_xx, u_xy, u_yy)`, and the
    /// normal derivative at each edge midpoint (edges oriented by global vertex numbers).
    /// Not affine-equivalent: kernels apply the per-cell DOF transformation.
    Argyris,
    /// The non-conforming Morley quadratic on triangles: vertex values and the normal
    /// derivative at each edge midpoint. Not affine-equivalent, like Argyris.
    Morley,
}

/// Every element, in the order the DSL lists them in error messages.
pub const ALL_ELEMENTS: [ElementKind; 8] = [
    ElementKind::P0,
    ElementKind::P1,
    ElementKind::P2,
    ElementKind::P3,
    ElementKind::Hermite,
    ElementKind::P1Disc,
    ElementKind::Argyris,
    ElementKind::Morley,
];

impl ElementKind {
    /// The element's name as written in a model file.
    pub fn name(self) -> &'static str {
        match self {
            ElementKind::P0 => "P0",
            ElementKind::P1 => "P1",
            ElementKind::P2 => "P2",
            ElementKind::P3 => "P3",
            ElementKind::Hermite => "Hermite",
            ElementKind::P1Disc => "P1disc",
            ElementKind::Argyris => "Argyris",
            ElementKind::Morley => "Morley",
        }
    }

    /// Parses an element name (`P0`…`P3`, `Hermite`, `H3`, `P1disc`, `Argyris`, `Morley`).
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "P0" => Some(ElementKind::P0),
            "P1" => Some(ElementKind::P1),
            "P2" => Some(ElementKind::P2),
            "P3" => Some(ElementKind::P3),
            "Hermite" | "H3" => Some(ElementKind::Hermite),
            "P1disc" | "P1d" | "DG1" => Some(ElementKind::P1Disc),
            "Argyris" => Some(ElementKind::Argyris),
            "Morley" => Some(ElementKind::Morley),
            _ => None,
        }
    }

    /// Whether the element exists on the given cell (Hermite only on intervals, Argyris
    /// and Morley only on triangles).
    pub fn supports(self, cell: CellKind) -> bool {
        match self {
            ElementKind::Hermite => cell == CellKind::Interval,
            ElementKind::Argyris | ElementKind::Morley => cell == CellKind::Triangle,
            _ => true,
        }
    }

    /// Whether the reference basis pulled back to a cell is not yet the physical nodal
    /// basis, so that kernels need the per-cell DOF transformation `M`
    /// ([`crate::argyris_transformation`], [`crate::morley_transformation`]) and the
    /// cell's global vertex numbers. False for Lagrange and Hermite (their identity or
    /// diagonal fast path).
    pub fn needs_transformation(self) -> bool {
        matches!(self, ElementKind::Argyris | ElementKind::Morley)
    }

    /// The per-cell transformation `M` (`φ = M (φ̂ ∘ F⁻¹)`, `docs/elements.md` §3) of an
    /// element that [`needs_transformation`](Self::needs_transformation); `Ok(None)` for
    /// the others.
    ///
    /// # Errors
    /// [`crate::dof_transformation::TransformationError`] for a degenerate cell, a
    /// non-finite coordinate or a repeated global vertex number.
    pub fn triangle_transformation(
        self,
        vertices: [[f64; 2]; 3],
        global: [usize; 3],
    ) -> Result<Option<crate::dense::Matrix>, crate::dof_transformation::TransformationError> {
        match self {
            ElementKind::Argyris => crate::argyris_transformation(vertices, global).map(Some),
            ElementKind::Morley => crate::morley_transformation(vertices, global).map(Some),
            _ => Ok(None),
        }
    }

    /// Number of local DOFs on `cell`.
    pub fn local_dof_count(self, cell: CellKind) -> usize {
        match cell {
            CellKind::Interval => self.dof_count(),
            CellKind::Triangle => {
                let [v, e, i] = self.triangle_layout();
                3 * v + 3 * e + i
            }
        }
    }

    /// DOFs per vertex, per edge and in the interior of a triangle. Local order on the
    /// triangle: vertices, then edges 0–1, 1–2, 2–0 (nodes from the edge's first
    /// vertex), then interior, as in [`crate::triangle::lagrange_nodes`].
    pub fn triangle_layout(self) -> [usize; 3] {
        match self {
            ElementKind::P0 => [0, 0, 1],
            ElementKind::P1 => [1, 0, 0],
            ElementKind::P2 => [1, 1, 0],
            ElementKind::P3 => [1, 2, 1],
            ElementKind::P1Disc => [0, 0, 3],
            ElementKind::Argyris => [6, 1, 0],
            ElementKind::Morley => [1, 1, 0],
            // Not available on triangles (see `supports`).
            ElementKind::Hermite => [0, 0, 0],
        }
    }

    /// The reference basis on the triangle, in local DOF order (empty where unsupported,
    /// or if [`try_triangle_basis`](Self::try_triangle_basis) fails).
    pub fn triangle_basis(self) -> Vec<crate::triangle::Polynomial2> {
        self.try_triangle_basis().unwrap_or_default()
    }

    /// The reference basis on the triangle, in local DOF order: Lagrange bases in closed
    /// form, Argyris and Morley by inverting the Vandermonde matrix of their DOF
    /// functionals ([`crate::ElementDefinition::nodal_basis`]); empty where unsupported.
    ///
    /// # Errors
    /// The [`crate::dual_basis::DualBasisError`] of a definition whose functionals are
    /// not unisolvent (does not happen for the elements declared here; the tests check).
    pub fn try_triangle_basis(
        self,
    ) -> Result<Vec<crate::triangle::Polynomial2>, crate::dual_basis::DualBasisError> {
        Ok(match self {
            ElementKind::Hermite => Vec::new(),
            ElementKind::P1Disc => crate::triangle::lagrange_basis(1),
            ElementKind::Argyris => crate::ElementDefinition::argyris().nodal_basis()?,
            ElementKind::Morley => crate::ElementDefinition::morley().nodal_basis()?,
            _ => crate::triangle::lagrange_basis(self.degree()),
        })
    }

    /// Polynomial degree of the basis.
    pub fn degree(self) -> usize {
        match self {
            ElementKind::P0 => 0,
            ElementKind::P1 | ElementKind::P1Disc => 1,
            ElementKind::P2 | ElementKind::Morley => 2,
            ElementKind::P3 | ElementKind::Hermite => 3,
            ElementKind::Argyris => 5,
        }
    }

    /// Highest derivative order the DSL may apply to a field of this element.
    ///
    /// Derivatives are taken element by element (broken); a piecewise constant field is
    /// discontinuous, and its derivative is not a function, so P0 admits none.
    pub fn max_derivative(self) -> usize {
        match self {
            ElementKind::P0 | ElementKind::P1Disc => 0,
            _ => 4,
        }
    }

    /// Whether neighbouring cells share the vertex DOFs (and edge DOFs on triangles).
    pub fn is_continuous(self) -> bool {
        !matches!(self, ElementKind::P0 | ElementKind::P1Disc)
    }

    /// The DOF layout, in local order.
    pub fn dofs(self) -> &'static [DofLocation] {
        use DofLocation::*;
        const V0: DofLocation = Vertex {
            vertex: 0,
            derivative: 0,
        };
        const V1: DofLocation = Vertex {
            vertex: 1,
            derivative: 0,
        };
        match self {
            ElementKind::P0 => &[Interior],
            ElementKind::P1 => &[V0, V1],
            ElementKind::P1Disc => &[Interior, Interior],
            ElementKind::P2 => &[V0, V1, Interior],
            ElementKind::P3 => &[V0, V1, Interior, Interior],
            // Triangles only: no layout on the interval (see `supports`).
            ElementKind::Argyris | ElementKind::Morley => &[],
            ElementKind::Hermite => &[
                V0,
                Vertex {
                    vertex: 0,
                    derivative: 1,
                },
                V1,
                Vertex {
                    vertex: 1,
                    derivative: 1,
                },
            ],
        }
    }

    /// Number of local DOFs.
    pub fn dof_count(self) -> usize {
        self.dofs().len()
    }

    /// Number of DOFs at each vertex (shared between neighbours for continuous elements).
    pub fn dofs_per_vertex(self) -> usize {
        if !self.is_continuous() {
            return 0;
        }
        self.dofs()
            .iter()
            .filter(|d| matches!(d, DofLocation::Vertex { vertex: 0, .. }))
            .count()
    }

    /// Number of interior DOFs of a cell.
    pub fn interior_dof_count(self) -> usize {
        self.dofs()
            .iter()
            .filter(|d| matches!(d, DofLocation::Interior))
            .count()
    }

    /// Nodes of the Lagrange elements on `[0, 1]`, in local DOF order.
    pub fn lagrange_nodes(self) -> Option<&'static [f64]> {
        match self {
            ElementKind::P0 => Some(&[0.5]),
            ElementKind::P1 | ElementKind::P1Disc => Some(&[0.0, 1.0]),
            ElementKind::P2 => Some(&[0.0, 1.0, 0.5]),
            ElementKind::P3 => Some(&[0.0, 1.0, 1.0 / 3.0, 2.0 / 3.0]),
            ElementKind::Hermite | ElementKind::Argyris | ElementKind::Morley => None,
        }
    }

    /// The reference basis as polynomials on `[0, 1]`, in local DOF order (empty for the
    /// triangle-only Argyris and Morley).
    pub fn basis(self) -> Vec<Polynomial> {
        if !self.supports(CellKind::Interval) {
            return Vec::new();
        }
        match self.lagrange_nodes() {
            Some(nodes) if nodes.len() == 1 => vec![Polynomial::constant(1.0)],
            Some(nodes) => (0..nodes.len())
                .map(|i| {
                    let others: Vec<f64> = (0..nodes.len())
                        .filter(|&j| j != i)
                        .map(|j| nodes[j])
                        .collect();
                    let denominator: f64 = others.iter().map(|&xj| nodes[i] - xj).product();
                    Polynomial::from_roots(&others, 1.0 / denominator)
                })
                .collect(),
            None => vec![
                Polynomial::new(vec![1.0, 0.0, -3.0, 2.0]),
                Polynomial::new(vec![0.0, 1.0, -2.0, 1.0]),
                Polynomial::new(vec![0.0, 0.0, 3.0, -2.0]),
                Polynomial::new(vec![0.0, 0.0, -1.0, 1.0]),
            ],
        }
    }

    /// Power of the cell length `h` that maps reference DOF `i` to its physical DOF.
    ///
    /// A Hermite slope DOF measures `dφ/dx = h⁻¹ dφ/dξ`, so its physical basis function is
    /// `h` times the reference one; every other DOF maps with power 0.
    pub fn dof_scaling_power(self, i: usize) -> i32 {
        match self.dofs()[i] {
            DofLocation::Vertex { derivative, .. } => derivative as i32,
            DofLocation::Interior => 0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The defining property of every basis: DOF functional j applied to basis i is δ_ij.
    #[test]
    fn basis_is_dual_to_the_dofs() {
        for element in ALL_ELEMENTS {
            let basis = element.basis();
            assert_eq!(basis.len(), element.dof_count());
            let mut interior_nodes = element
                .lagrange_nodes()
                .map(|n| n.to_vec())
                .unwrap_or_default()
                .into_iter();
            type Functional = Box<dyn Fn(&Polynomial) -> f64>;
            let functionals: Vec<Functional> = element
                .dofs()
                .iter()
                .map(|d| -> Functional {
                    match *d {
                        DofLocation::Vertex { vertex, derivative } => {
                            let _ = interior_nodes.next();
                            Box::new(move |p: &Polynomial| {
                                p.derivative(derivative).eval(vertex as f64)
                            })
                        }
                        DofLocation::Interior => {
                            let x = interior_nodes.next().unwrap();
                            Box::new(move |p: &Polynomial| p.eval(x))
                        }
                    }
                })
                .collect();
            for (i, phi) in basis.iter().enumerate() {
                for (j, functional) in functionals.iter().enumerate() {
                    let expected = if i == j { 1.0 } else { 0.0 };
                    assert!(
                        (functional(phi) - expected).abs() < 1e-13,
                        "{element:?}: dof {j} of basis {i}"
                    );
                }
            }
        }
    }

    #[test]
    fn degrees_and_layouts() {
        for element in ALL_ELEMENTS {
            for phi in element.basis() {
                assert!(phi.derivative(element.degree() + 1).is_zero());
            }
            let per_vertex = element.dofs_per_vertex();
            assert_eq!(
                2 * per_vertex + element.interior_dof_count(),
                element.dof_count()
            );
            assert_eq!(ElementKind::from_name(element.name()), Some(element));
        }
        // Partition of unity for the Lagrange elements.
        for element in [ElementKind::P1, ElementKind::P2, ElementKind::P3] {
            let sum: f64 = element.basis().iter().map(|p| p.eval(0.3141)).sum();
            assert!((sum - 1.0).abs() < 1e-14);
        }
    }

    /// On the triangle every supported basis is dual to its nodes in layout order, has
    /// the element's degree and sums to one.
    #[test]
    fn triangle_bases_match_their_layouts() {
        for element in ALL_ELEMENTS {
            if !element.supports(CellKind::Triangle) {
                assert!(element.triangle_basis().is_empty());
                continue;
            }
            if element.needs_transformation() {
                // Not nodal at points: checked against its functionals below.
                continue;
            }
            let basis = element.triangle_basis();
            assert_eq!(basis.len(), element.local_dof_count(CellKind::Triangle));
            let nodes = crate::triangle::lagrange_nodes(element.degree());
            for (i, phi) in basis.iter().enumerate() {
                for (j, &node) in nodes.iter().enumerate() {
                    let expected = f64::from(u8::from(i == j));
                    assert!(
                        (phi.eval(node) - expected).abs() < 1e-12,
                        "{element:?} {i} {j}"
                    );
                }
                let top = element.degree() as u32;
                assert!(phi.terms.iter().all(|&(a, b, _)| a + b <= top));
            }
            let sum: f64 = basis.iter().map(|p| p.eval([0.21, 0.37])).sum();
            assert!((sum - 1.0).abs() < 1e-13);
        }
    }

    /// Argyris and Morley: the basis is dual to the functionals of their definitions, the
    /// layout counts the DOFs each vertex and edge owns in that local order, and they
    /// exist on triangles only.
    #[test]
    fn transformed_elements_match_their_definitions() {
        use crate::dual_basis::Entity;
        for (element, definition) in [
            (ElementKind::Argyris, crate::ElementDefinition::argyris()),
            (ElementKind::Morley, crate::ElementDefinition::morley()),
        ] {
            assert!(element.needs_transformation());
            assert!(element.supports(CellKind::Triangle));
            assert!(!element.supports(CellKind::Interval));
            assert!(element.basis().is_empty());
            assert_eq!(ElementKind::from_name(element.name()), Some(element));
            let basis = element.try_triangle_basis().unwrap();
            assert_eq!(basis.len(), element.local_dof_count(CellKind::Triangle));
            assert_eq!(basis.len(), definition.dofs.len());
            for (i, dof) in definition.dofs.iter().enumerate() {
                for (j, phi) in basis.iter().enumerate() {
                    let expected = f64::from(u8::from(i == j));
                    let value = dof.functional.apply(phi);
                    assert!((value - expected).abs() < 1e-10, "{element:?} {i} {j}");
                }
            }
            // Local order: the vertex DOFs vertex by vertex, then the edge DOFs edge by edge.
            let [v, e, interior] = element.triangle_layout();
            assert_eq!(interior, 0);
            for (i, dof) in definition.dofs.iter().enumerate() {
                let expected = if i < 3 * v {
                    Entity::Vertex(i / v)
                } else {
                    Entity::Edge((i - 3 * v) / e)
                };
                assert_eq!(dof.entity, expected, "{element:?} dof {i}");
            }
            let top = element.degree() as u32;
            assert!(basis
                .iter()
                .all(|p| p.terms.iter().all(|&(a, b, _)| a + b <= top)));
        }
        for element in ALL_ELEMENTS {
            assert_eq!(
                element.needs_transformation(),
                matches!(element, ElementKind::Argyris | ElementKind::Morley)
            );
            let cell = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
            let m = element.triangle_transformation(cell, [0, 1, 2]).unwrap();
            assert_eq!(m.is_some(), element.needs_transformation());
        }
    }
}
