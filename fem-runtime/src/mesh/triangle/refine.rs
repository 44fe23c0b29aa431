//! Conforming newest-vertex bisection of marked cells (with the closure it needs) and
//! uniform refinement, with the parent of every new cell for prolongation.

use super::*;

impl TriangleMesh {
    /// Conforming newest-vertex bisection of the marked cells and the closure it needs.
    ///
    /// Returns the new mesh and, for each new cell, its parent cell in `self`. Indices may
    /// repeat; an out-of-range index is an error. Each cell is bisected at most twice in
    /// depth (into two, three or four children); boundary markers pass to edge halves and
    /// the named groups are kept, so every boundary part stays the same part. New vertices
    /// on the edges of a marker with a boundary curve
    /// ([`TriangleMesh::with_boundary_curve`]) are moved onto the curve.
    ///
    /// # Errors
    /// A cell index out of range; a move onto a curve that turns a cell inside out.
    pub fn refine(&self, marked: &[usize]) -> Result<(TriangleMesh, Vec<usize>)> {
        let mut edge_marked = vec![false; self.edges.len()];
        let mut queue = Vec::new();
        for &c in marked {
            if c >= self.cells.len() {
                return Err(mesh_error(format!(
                    "cannot refine cell {c}: the mesh has {} cells",
                    self.cells.len()
                )));
            }
            let r = self.cell_edges(c)[1];
            if !edge_marked[r] {
                edge_marked[r] = true;
                queue.push(r);
            }
        }
        // Closure: a cell with any edge to split must first split its refinement edge.
        // This terminates for any labelling (each edge is marked at most once).
        while let Some(e) = queue.pop() {
            let (c0, c1) = self.edge_cells(e);
            for c in std::iter::once(c0).chain(c1) {
                let r = self.cell_edges(c)[1];
                if !edge_marked[r] {
                    edge_marked[r] = true;
                    queue.push(r);
                }
            }
        }
        let old_vertices = self.vertices.len();
        let (mut fine, parents) = self.bisect(&edge_marked)?;
        if !self.curves.is_empty() {
            let curves = self.curves.clone();
            fine.snap_new_boundary_vertices(old_vertices, &|marker, p| {
                curves
                    .iter()
                    .find(|(m, _)| *m == marker)
                    .map_or(p, |(_, curve)| curve.project(p))
            })?;
        }
        Ok((fine, parents))
    }

    /// Splits every cell into four by two levels of bisection: cell count ×4, `h` halves
    /// on meshes whose cells' longest edges are their refinement edges.
    pub fn refine_uniformly(&self) -> TriangleMesh {
        self.bisect(&vec![true; self.edges.len()])
            .expect("bisecting every edge of a valid mesh gives a valid mesh")
            .0
    }

    /// Bisects the marked edges; every cell with a marked edge has its refinement edge marked.
    pub(super) fn bisect(&self, edge_marked: &[bool]) -> Result<(TriangleMesh, Vec<usize>)> {
        let mut vertices: Vec<[f64; 2]> = self.vertices.to_vec();
        let mut midpoint = vec![NONE; self.edges.len()];
        for e in (0..self.edges.len()).filter(|&e| edge_marked[e]) {
            let [a, b] = self.edges[e];
            let (p, q) = (self.vertices[a], self.vertices[b]);
            midpoint[e] = vertices.len();
            vertices.push([0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])]);
        }
        let mut cells =
            Vec::with_capacity(self.cells.len() + 3 * (vertices.len() - self.vertices.len()));
        let mut parents = Vec::with_capacity(cells.capacity());
        for (c, &[v0, v1, v2]) in self.cells.iter().enumerate() {
            let [e0, e1, e2] = self.cell_edges(c);
            let m = midpoint[e1];
            if m == NONE {
                cells.push([v0, v1, v2]);
                parents.push(c);
                continue;
            }
            // children [m, v0, v1] and [m, v2, v0]: the new vertex first, so each child's
            // refinement edge is one of the parent's other edges
            match midpoint[e0] {
                NONE => cells.push([m, v0, v1]),
                p => cells.extend([[p, m, v0], [p, v1, m]]),
            }
            match midpoint[e2] {
                NONE => cells.push([m, v2, v0]),
                p => cells.extend([[p, m, v2], [p, v0, m]]),
            }
            parents.resize(cells.len(), c);
        }
        let mut markers = Vec::new();
        for &(e, marker) in &self.boundary_edges {
            if marker == 0 {
                continue;
            }
            let [a, b] = self.edges[e];
            match midpoint[e] {
                NONE => markers.push((a, b, marker)),
                m => markers.extend([(a, m, marker), (m, b, marker)]),
            }
        }
        let mut mesh = Self::from_oriented(vertices, cells)?;
        mesh.apply_markers(&markers)?;
        mesh.set_named_groups(self.groups.clone());
        mesh.curves = self.curves.clone();
        Ok((mesh, parents))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Marked refinement of a quarter disc whose arc is declared a circle puts every new
    /// arc vertex on the circle (and leaves the straight parts straight); without the
    /// declaration the midpoints stay on the chords, inside the circle.
    #[test]
    fn refinement_moves_new_arc_vertices_onto_the_circle() {
        let radius = 2.0;
        let centre = [0.0, radius];
        let plain = TriangleMesh::quarter_disk(radius, 3).unwrap();
        let curved = plain
            .clone()
            .with_boundary_curve(1, BoundaryCurve::Circle { centre, radius });
        let distance = |p: [f64; 2]| (p[0] - centre[0]).hypot(p[1] - centre[1]);
        let arc_vertices = |m: &TriangleMesh| -> Vec<[f64; 2]> {
            m.boundary_edges()
                .iter()
                .filter(|&&(_, marker)| marker == 1)
                .flat_map(|&(e, _)| m.edges()[e].map(|v| m.vertices()[v]))
                .collect()
        };
        let mut mesh = curved;
        let mut chords = plain;
        for _ in 0..3 {
            let marked: Vec<usize> = (0..mesh.cell_count()).step_by(2).collect();
            mesh = mesh.refine(&marked).unwrap().0;
            chords = chords.refine(&marked).unwrap().0;
        }
        assert_eq!(
            mesh.boundary_curves().len(),
            1,
            "refinement keeps the curve"
        );
        for p in arc_vertices(&mesh) {
            assert!((distance(p) - radius).abs() < 1e-12, "{p:?} off the circle");
        }
        assert!(arc_vertices(&chords)
            .iter()
            .any(|&p| distance(p) < radius - 1e-3));
        for &(e, marker) in mesh.boundary_edges() {
            let [a, b] = mesh.edges()[e].map(|v| mesh.vertices()[v]);
            match marker {
                2 => assert!((a[1] - radius).abs() < 1e-12 && (b[1] - radius).abs() < 1e-12),
                3 => assert!(a[0].abs() < 1e-12 && b[0].abs() < 1e-12),
                _ => {}
            }
        }
    }
}
