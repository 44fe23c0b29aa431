//! Quadratic (isoparametric) geometry over a triangle mesh: one geometry node per edge,
//! at the edge's midpoint for straight edges and on the exact boundary for curved ones,
//! so that each cell is the six-node map of [`Isoparametric`] (docs/mathematics.md §8).
//!
//! A polygonal approximation of a curved domain errs by O(h²) in area (and in the
//! energy of a plate: 3e-4 relative to J on a disk, docs/mathematics.md §8); quadratic
//! geometry errs by O(h⁴).

use super::TriangleMesh;
use crate::element::isoparametric::Isoparametric;
use crate::error::{Error, Result};
use fem_reference::triangle::TriangleRule;

/// The geometry nodes of a mesh's edges (shape: one point per edge of the mesh, in the
/// order of [`TriangleMesh::edges`]).
#[derive(Clone, Debug, PartialEq)]
pub struct QuadraticGeometry {
    edge_nodes: Vec<[f64; 2]>,
}

impl QuadraticGeometry {
    /// Straight edges: every edge node at its edge's midpoint (the affine mesh itself).
    pub fn straight(mesh: &TriangleMesh) -> Self {
        let v = mesh.vertices();
        let edge_nodes = mesh
            .edges()
            .iter()
            .map(|&[a, b]| [(v[a][0] + v[b][0]) / 2.0, (v[a][1] + v[b][1]) / 2.0])
            .collect();
        Self { edge_nodes }
    }

    /// The geometry with the given edge nodes (shape: one point per edge of `mesh`, in the
    /// order of [`TriangleMesh::edges`]), e.g. from a second-order Gmsh mesh.
    ///
    /// # Errors
    /// [`Error::Mesh`] for a wrong number of nodes, a node that is not finite, or a cell
    /// whose map folds (as [`QuadraticGeometry::curved`]).
    pub fn from_edge_nodes(mesh: &TriangleMesh, edge_nodes: Vec<[f64; 2]>) -> Result<Self> {
        if edge_nodes.len() != mesh.edge_count() {
            return Err(Error::Mesh(format!(
                "{} edge nodes for a mesh of {} edges",
                edge_nodes.len(),
                mesh.edge_count()
            )));
        }
        if let Some(e) = edge_nodes
            .iter()
            .position(|p| !(p[0].is_finite() && p[1].is_finite()))
        {
            return Err(Error::Mesh(format!("the node of edge {e} is not finite")));
        }
        let geometry = Self { edge_nodes };
        geometry.check(mesh)?;
        Ok(geometry)
    }

    /// Curved boundary edges: the midpoint of every boundary edge whose marker is in
    /// `markers` (every boundary edge for `None`) moved onto the exact boundary by
    /// `projection` (a point near the boundary → the nearest point on it); all other
    /// edges straight. Only the boundary's own vertices need to lie on the curve.
    ///
    /// # Errors
    /// [`Error::Mesh`] naming the edge where the projection is not finite, or the cell
    /// whose map folds or inverts (`det J ≤ 0` at its vertices, edge nodes or the points
    /// of a degree-4 rule): a curved edge that bulges too far for its cell, to be cured by
    /// refining near the boundary.
    pub fn curved(
        mesh: &TriangleMesh,
        markers: Option<&[u32]>,
        projection: impl Fn([f64; 2]) -> [f64; 2],
    ) -> Result<Self> {
        let mut geometry = Self::straight(mesh);
        for &(edge, marker) in mesh.boundary_edges() {
            if markers.is_some_and(|m| !m.contains(&marker)) {
                continue;
            }
            let midpoint = geometry.edge_nodes[edge];
            let node = projection(midpoint);
            if !(node[0].is_finite() && node[1].is_finite()) {
                return Err(Error::Mesh(format!(
                    "the boundary projection of edge {edge}'s midpoint ({}, {}) is not finite",
                    midpoint[0], midpoint[1]
                )));
            }
            geometry.edge_nodes[edge] = node;
        }
        geometry.check(mesh)?;
        Ok(geometry)
    }

    /// The circle of `radius` about `centre` as the curved boundary (all boundary
    /// edges): for [`TriangleMesh::disk`] and Gmsh disks.
    ///
    /// # Errors
    /// As [`QuadraticGeometry::curved`], and for a radius that is not positive and finite.
    pub fn circle(mesh: &TriangleMesh, centre: [f64; 2], radius: f64) -> Result<Self> {
        if !(radius > 0.0 && radius.is_finite()) {
            return Err(Error::Mesh(format!(
                "circle radius {radius} must be positive and finite"
            )));
        }
        Self::curved(mesh, None, |p| {
            let (dx, dy) = (p[0] - centre[0], p[1] - centre[1]);
            let r = dx.hypot(dy);
            [centre[0] + radius * dx / r, centre[1] + radius * dy / r]
        })
    }

    /// The six-node map of cell `c` of `mesh` (the mesh this geometry was built for).
    pub fn cell_map(&self, mesh: &TriangleMesh, c: usize) -> Isoparametric {
        let v = mesh.vertices();
        let [a, b, d] = mesh.cell(c);
        let [e0, e1, e2] = mesh.cell_edges(c);
        Isoparametric::new([
            v[a],
            v[b],
            v[d],
            self.edge_nodes[e0],
            self.edge_nodes[e1],
            self.edge_nodes[e2],
        ])
    }

    /// `∫_Ω f` over the curved cells with a rule exact for polynomials of `degree` on the
    /// reference cell (the integrand `f(x(ξ)) |det J(ξ)|` is a polynomial of degree
    /// `2·deg f + 2` in ξ for polynomial `f`).
    pub fn integrate(
        &self,
        mesh: &TriangleMesh,
        f: impl Fn([f64; 2]) -> f64,
        degree: usize,
    ) -> f64 {
        let rule = TriangleRule::exact_for_degree(degree);
        (0..mesh.cell_count())
            .map(|c| {
                let map = self.cell_map(mesh, c);
                rule.points
                    .iter()
                    .zip(&rule.weights)
                    .map(|(&xi, &w)| w * f(map.point(xi)) * map.det(xi).abs())
                    .sum::<f64>()
            })
            .sum()
    }

    /// The area of the curved domain.
    pub fn area(&self, mesh: &TriangleMesh) -> f64 {
        self.integrate(mesh, |_| 1.0, 2)
    }

    /// An error naming the first cell whose map is not orientation-preserving at its
    /// nodes and at the points of a degree-4 rule.
    fn check(&self, mesh: &TriangleMesh) -> Result<()> {
        let rule = TriangleRule::exact_for_degree(4);
        let nodes = [
            [0.0, 0.0],
            [1.0, 0.0],
            [0.0, 1.0],
            [0.5, 0.0],
            [0.5, 0.5],
            [0.0, 0.5],
        ];
        for c in 0..mesh.cell_count() {
            let map = self.cell_map(mesh, c);
            if let Some(xi) = nodes
                .iter()
                .chain(&rule.points)
                .find(|&&xi| map.det(xi).is_nan() || map.det(xi) <= 0.0)
            {
                let x = map.point(*xi);
                return Err(Error::Mesh(format!(
                    "curved cell {c} folds: det J = {:.3e} at ({:.6}, {:.6}); its curved edge bulges too far for the cell (refine near the boundary)",
                    map.det(*xi),
                    x[0],
                    x[1]
                )));
            }
        }
        Ok(())
    }
}

/// A triangle mesh with quadratic geometry: what assembly takes for curved domains.
///
/// Implements [`crate::mesh::Mesh`] (and DOF numbering) like the [`TriangleMesh`] of its
/// vertices, so every assembly and solver path accepts it; cells whose three edge nodes
/// lie at their edge midpoints (to 1e-12 of the cell diameter) are affine and keep the
/// generated fast kernels, the others ([`CurvedTriangleMesh::is_curved`]) are assembled
/// with the curved kernels (`Model::element_matrix_curved`). Measures are those of the
/// curved cells; diameters (`h_T`) those of the three vertices.
#[derive(Clone, Debug, PartialEq)]
pub struct CurvedTriangleMesh {
    mesh: TriangleMesh,
    geometry: QuadraticGeometry,
    curved: Vec<bool>,
    curved_count: usize,
    measures: Vec<f64>,
}

impl CurvedTriangleMesh {
    /// The mesh `mesh` with the geometry `geometry` (built for it).
    ///
    /// # Errors
    /// [`Error::Mesh`] if the geometry has not one node per edge of `mesh`.
    pub fn new(mesh: TriangleMesh, geometry: QuadraticGeometry) -> Result<Self> {
        if geometry.edge_nodes.len() != mesh.edge_count() {
            return Err(Error::Mesh(format!(
                "a quadratic geometry of {} edge nodes for a mesh of {} edges",
                geometry.edge_nodes.len(),
                mesh.edge_count()
            )));
        }
        let v = mesh.vertices();
        let curved: Vec<bool> = (0..mesh.cell_count())
            .map(|c| {
                let tolerance = 1e-12 * mesh.cell_diameter(c);
                mesh.cell_edges(c).iter().any(|&e| {
                    let [a, b] = mesh.edges()[e];
                    let mid = [(v[a][0] + v[b][0]) / 2.0, (v[a][1] + v[b][1]) / 2.0];
                    let node = geometry.edge_nodes[e];
                    (node[0] - mid[0]).hypot(node[1] - mid[1]) > tolerance
                })
            })
            .collect();
        // The measure of a curved cell is ∫|det J|, a polynomial of degree 2 in ξ.
        let rule = TriangleRule::exact_for_degree(2);
        let measures = (0..mesh.cell_count())
            .map(|c| {
                if !curved[c] {
                    return mesh.area(c);
                }
                let map = geometry.cell_map(&mesh, c);
                rule.points
                    .iter()
                    .zip(&rule.weights)
                    .map(|(&xi, &w)| w * map.det(xi).abs())
                    .sum()
            })
            .collect();
        let curved_count = curved.iter().filter(|&&c| c).count();
        Ok(Self {
            mesh,
            geometry,
            curved,
            curved_count,
            measures,
        })
    }

    /// The mesh with every coordinate (vertices and edge nodes) multiplied by `factor`.
    ///
    /// # Errors
    /// [`Error::Mesh`] for a factor that is not positive and finite.
    pub fn scaled(&self, factor: f64) -> Result<Self> {
        let mesh = self.mesh.scaled(factor)?;
        let geometry = QuadraticGeometry {
            edge_nodes: self
                .geometry
                .edge_nodes
                .iter()
                .map(|x| [x[0] * factor, x[1] * factor])
                .collect(),
        };
        Self::new(mesh, geometry)
    }

    /// The disk of `radius` about `centre` with `rings` rings ([`TriangleMesh::disk`]) and
    /// its boundary edges curved onto the circle ([`QuadraticGeometry::circle`]).
    ///
    /// # Errors
    /// Those of [`TriangleMesh::disk`] and [`QuadraticGeometry::circle`].
    pub fn disk(centre: [f64; 2], radius: f64, rings: usize) -> Result<Self> {
        let mesh = TriangleMesh::disk(centre, radius, rings)?;
        let geometry = QuadraticGeometry::circle(&mesh, centre, radius)?;
        Self::new(mesh, geometry)
    }

    /// Newest-vertex bisection of the marked cells (with the closure it needs, as
    /// [`TriangleMesh::refine`]) that keeps the quadratic geometry: a new vertex on a
    /// curved edge (on the boundary or inside, as a second-order Gmsh mesh may have) is
    /// that edge's node (the point `s = ½` of its quadratic), and the two halves carry
    /// the quadratic's points at `s = ¼` and `s = ¾` as their nodes, so the refined mesh
    /// has the same piecewise-quadratic curves. New edges across a cell are straight.
    /// Returns the mesh and each new cell's parent.
    ///
    /// # Errors
    /// Those of [`TriangleMesh::refine`], and a refined cell whose map folds.
    pub fn refine(&self, marked: &[usize]) -> Result<(Self, Vec<usize>)> {
        let coarse = &self.mesh;
        let old = coarse.vertices().len();
        let v = coarse.vertices();
        let nodes = &self.geometry.edge_nodes;
        let key = |p: [f64; 2]| (p[0].to_bits(), p[1].to_bits());
        // each curved edge by the chord midpoint a new vertex on it starts at (the same
        // arithmetic as the bisection's)
        let mut by_midpoint = std::collections::HashMap::new();
        for (e, &[a, b]) in coarse.edges().iter().enumerate() {
            let mid = [0.5 * (v[a][0] + v[b][0]), 0.5 * (v[a][1] + v[b][1])];
            if nodes[e] != mid {
                by_midpoint.insert(key(mid), e);
            }
        }
        let plain = TriangleMesh {
            curves: Vec::new(),
            ..coarse.clone()
        };
        let (mut fine, parents) = plain.refine(marked)?;
        // the new vertices on curved edges, moved onto their edge's node
        let mut split = std::collections::HashMap::new();
        for w in old..fine.vertices().len() {
            if let Some(&e) = by_midpoint.get(&key(fine.vertices()[w])) {
                split.insert(w, e);
                std::sync::Arc::make_mut(&mut fine.vertices)[w] = nodes[e];
            }
        }
        fine.curves = coarse.curves.clone();
        // the point at s of coarse edge e's quadratic, from its first vertex
        let quadratic = |e: usize, s: f64| {
            let [a, b] = coarse.edges()[e];
            let (pa, pb, m) = (v[a], v[b], nodes[e]);
            let (la, lm, lb) = (
                (1.0 - s) * (1.0 - 2.0 * s),
                4.0 * s * (1.0 - s),
                s * (2.0 * s - 1.0),
            );
            [
                la * pa[0] + lm * m[0] + lb * pb[0],
                la * pa[1] + lm * m[1] + lb * pb[1],
            ]
        };
        let mut edge_nodes = QuadraticGeometry::straight(&fine).edge_nodes;
        for (e, &[p, q]) in fine.edges().iter().enumerate() {
            edge_nodes[e] = match (split.get(&p), split.get(&q)) {
                // an edge of the coarse mesh, not split: its own node
                (None, None) if p < old && q < old => match coarse.find_edge(p, q) {
                    Some(c) => nodes[c],
                    None => edge_nodes[e],
                },
                // half of a split curved edge: a quarter point of its quadratic
                (Some(&c), None) | (None, Some(&c)) => {
                    let end = if split.contains_key(&p) { q } else { p };
                    let [first, last] = coarse.edges()[c];
                    if end == first {
                        quadratic(c, 0.25)
                    } else if end == last {
                        quadratic(c, 0.75)
                    } else {
                        edge_nodes[e]
                    }
                }
                _ => edge_nodes[e],
            };
        }
        let geometry = QuadraticGeometry::from_edge_nodes(&fine, edge_nodes)?;
        Ok((Self::new(fine, geometry)?, parents))
    }

    /// The mesh of the vertices (the cells as straight triangles).
    pub fn mesh(&self) -> &TriangleMesh {
        &self.mesh
    }

    /// The quadratic geometry.
    pub fn geometry(&self) -> &QuadraticGeometry {
        &self.geometry
    }

    /// Whether cell `c` is curved (an edge node off its edge's midpoint).
    pub fn is_curved(&self, c: usize) -> bool {
        self.curved[c]
    }

    /// Number of curved cells.
    pub fn curved_cell_count(&self) -> usize {
        self.curved_count
    }

    /// The six-node map of cell `c`.
    pub fn cell_map(&self, c: usize) -> Isoparametric {
        self.geometry.cell_map(&self.mesh, c)
    }

    /// The twelve node coordinates `x₀ y₀ … x₅ y₅` of cell `c`, as the curved kernels
    /// take them.
    pub fn cell_nodes(&self, c: usize) -> [f64; 12] {
        let nodes = self.cell_map(c);
        let mut out = [0.0; 12];
        for (n, p) in nodes.nodes().iter().enumerate() {
            out[2 * n] = p[0];
            out[2 * n + 1] = p[1];
        }
        out
    }

    /// Area of the curved domain: the sum of the cell measures.
    pub fn total_area(&self) -> f64 {
        self.measures.iter().sum()
    }
}

impl crate::mesh::Mesh for CurvedTriangleMesh {
    const CELL: fem_reference::CellKind = fem_reference::CellKind::Triangle;
    fn cell_count(&self) -> usize {
        self.mesh.cell_count()
    }
    #[inline]
    fn cell_coordinates_into(&self, c: usize, out: &mut [f64]) {
        out[..6].copy_from_slice(&self.mesh.cell_coordinates(c));
    }
    #[inline]
    fn cell_vertex_numbers_into(&self, c: usize, out: &mut [usize]) -> bool {
        out[..3].copy_from_slice(&self.mesh.cell(c));
        true
    }
    fn diameter(&self, c: usize) -> f64 {
        self.mesh.cell_diameter(c)
    }
    fn measure(&self, c: usize) -> f64 {
        self.measures[c]
    }
    fn has_curved_cells(&self) -> bool {
        self.curved_count > 0
    }
    fn curved_cell_nodes_into(&self, c: usize, out: &mut [f64]) -> bool {
        if !self.curved[c] {
            return false;
        }
        out[..12].copy_from_slice(&self.cell_nodes(c));
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Diagonal;
    use std::f64::consts::PI;

    /// Marked refinement keeps the piecewise-quadratic boundary: the curved area is the
    /// same to rounding after three rounds (the area of a different curve would differ
    /// by O(h³)), the new boundary vertices lie within the quadratics' distance of the
    /// circle, and the result is a valid curved mesh (no folded cell).
    #[test]
    fn marked_refinement_keeps_the_quadratic_boundary() {
        let mut mesh = CurvedTriangleMesh::disk([0.0, 0.0], 1.0, 3).unwrap();
        let area = mesh.total_area();
        for round in 0..3 {
            // the cells with a vertex in the right half plane
            let marked: Vec<usize> = (0..mesh.mesh().cell_count())
                .filter(|&c| {
                    mesh.mesh()
                        .cell(c)
                        .iter()
                        .any(|&v| mesh.mesh().vertices()[v][0] > 0.3)
                })
                .collect();
            let (fine, parents) = mesh.refine(&marked).unwrap();
            assert_eq!(parents.len(), fine.mesh().cell_count());
            assert!(
                fine.mesh().cell_count() > mesh.mesh().cell_count(),
                "round {round}"
            );
            assert!(
                (fine.total_area() - area).abs() < 1e-13,
                "round {round}: {} against {area}",
                fine.total_area()
            );
            mesh = fine;
        }
        for &(e, _) in mesh.mesh().boundary_edges() {
            for v in mesh.mesh().edges()[e] {
                let p = mesh.mesh().vertices()[v];
                // the coarse quadratics' distance to the circle: O(h³), here below 1e-4
                assert!((p[0].hypot(p[1]) - 1.0).abs() < 1e-4, "{p:?}");
            }
        }
    }

    /// Fitted rate of errors on meshes whose h halves each time.
    fn rate(errors: &[f64]) -> f64 {
        let k = errors.len() - 1;
        (errors[k - 1] / errors[k]).log2()
    }

    /// The unit disk: its area and `∫ x²y² = π/24` converge at O(h²) on the polygonal
    /// mesh and at O(h⁴) with quadratic geometry (rings double, so h halves).
    #[test]
    fn the_disk_converges_at_the_isoparametric_rate() {
        let (mut straight_area, mut curved_area, mut curved_moment) = (vec![], vec![], vec![]);
        for rings in [4, 8, 16, 32] {
            let mesh = TriangleMesh::disk([0.0, 0.0], 1.0, rings).unwrap();
            let polygon = QuadraticGeometry::straight(&mesh);
            let curved = QuadraticGeometry::circle(&mesh, [0.0, 0.0], 1.0).unwrap();
            straight_area.push((polygon.area(&mesh) - PI).abs());
            curved_area.push((curved.area(&mesh) - PI).abs());
            let moment = curved.integrate(&mesh, |x| x[0] * x[0] * x[1] * x[1], 10);
            curved_moment.push((moment - PI / 24.0).abs());
        }
        let (s, a, m) = (
            rate(&straight_area),
            rate(&curved_area),
            rate(&curved_moment),
        );
        assert!(
            (s - 2.0).abs() < 0.1,
            "polygon: rate {s}, errors {straight_area:?}"
        );
        assert!(a > 3.8, "curved area: rate {a}, errors {curved_area:?}");
        assert!(m > 3.8, "curved ∫x²y²: rate {m}, errors {curved_moment:?}");
        assert!(curved_area[3] < 1e-6 && straight_area[3] > 1e-4);
    }

    /// Straight geometry integrates polynomials exactly on a polygon; an edge node pushed
    /// through its cell is refused naming the cell.
    #[test]
    fn straight_geometry_is_exact_and_a_folded_cell_is_refused() {
        let mesh = TriangleMesh::rectangle(0.0, 2.0, 0.0, 1.0, 4, 3, Diagonal::Right).unwrap();
        let straight = QuadraticGeometry::straight(&mesh);
        // ∫ x y over (0,2)×(0,1) = 2·½ = 1
        assert!((straight.integrate(&mesh, |x| x[0] * x[1], 4) - 1.0).abs() < 1e-13);
        assert!((straight.area(&mesh) - 2.0).abs() < 1e-13);
        let error = QuadraticGeometry::curved(&mesh, None, |p| [p[0], 3.0 - p[1]])
            .unwrap_err()
            .to_string();
        assert!(error.contains("folds"), "{error}");
        let error = QuadraticGeometry::curved(&mesh, None, |_| [f64::NAN, 0.0])
            .unwrap_err()
            .to_string();
        assert!(error.contains("not finite"), "{error}");
    }

    /// An interior curved edge (a second-order Gmsh mesh may curve them) is split at
    /// its node, not at its chord's midpoint, and its halves keep its quadratic: the two
    /// cells' areas, which the bulge moves from one to the other, are kept.
    #[test]
    fn refinement_keeps_an_interior_curved_edge() {
        let mesh = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 1, 1, Diagonal::Right).unwrap();
        let mut nodes = QuadraticGeometry::straight(&mesh).edge_nodes;
        let diagonal = (0..mesh.edge_count())
            .find(|&e| mesh.edge_cells(e).1.is_some())
            .unwrap();
        let mid = nodes[diagonal];
        nodes[diagonal] = [mid[0] + 0.05, mid[1] + 0.05];
        let geometry = QuadraticGeometry::from_edge_nodes(&mesh, nodes.clone()).unwrap();
        let curved = CurvedTriangleMesh::new(mesh.clone(), geometry).unwrap();
        let areas = |m: &CurvedTriangleMesh, parents: &[usize]| {
            let mut a = [0.0; 2];
            for (c, &p) in parents.iter().enumerate() {
                a[p] += m.measures[c];
            }
            a
        };
        let before = [curved.measures[0], curved.measures[1]];
        let (fine, parents) = curved.refine(&[0, 1]).unwrap();
        let after = areas(&fine, &parents);
        for k in 0..2 {
            assert!(
                (after[k] - before[k]).abs() < 1e-14,
                "{after:?} against {before:?}"
            );
        }
        assert!(fine.mesh().vertices().contains(&nodes[diagonal]));
    }
}
