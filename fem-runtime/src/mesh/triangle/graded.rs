//! Meshes graded by a mesh-size function, and the half disc of Hertz line contact.
//!
//! [`TriangleMesh::refine_to_size`] bisects (newest-vertex bisection with closure) every
//! cell larger than a prescribed size `s(x)` until none is, the way a background size
//! field drives a mesh generator; vertices created on curved parts of the boundary are
//! moved onto the curve by a caller's projection, so the polygon converges to the
//! curve instead of staying the coarse mesh's. [`TriangleMesh::half_disk`] is the
//! cylinder of the Hertz problem (docs/contact.md; docs/contact.md): refining it towards
//! the contact zone gives the graded meshes a contact solve needs (`b/h` ≥ 64 at the
//! contact zone with a few ten thousand cells instead of millions).

use super::*;

/// The distance from `p` to the segment `a b`: the building block of size fields
/// graded towards a part of the boundary ([`TriangleMesh::refine_to_size`]).
pub fn distance_to_segment(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1]];
    let length2 = d[0] * d[0] + d[1] * d[1];
    let s = if length2 > 0.0 {
        (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / length2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    dist2(p, [a[0] + s * d[0], a[1] + s * d[1]]).sqrt()
}

/// The half (`quarter = false`: angles π…2π) or the right quarter (3π/2…2π) of the
/// disc of radius `radius` centred at `(0, radius)`, `rings` rings zipped by angle.
fn lower_sector(radius: f64, rings: usize, quarter: bool) -> Result<TriangleMesh> {
    if !(radius > 0.0 && radius.is_finite()) {
        return Err(mesh_error(format!(
            "half-disc radius {radius} must be positive and finite"
        )));
    }
    if rings == 0 {
        return Err(mesh_error("a half disc needs at least one ring".into()));
    }
    let segments = |k: usize| if quarter { (3 * k).div_ceil(2) } else { 3 * k };
    let (start, span) = if quarter {
        (1.5 * std::f64::consts::PI, 0.5 * std::f64::consts::PI)
    } else {
        (std::f64::consts::PI, std::f64::consts::PI)
    };
    let mut ring_start = vec![0, 1];
    for k in 1..=rings {
        ring_start.push(ring_start[k] + segments(k) + 1);
    }
    let vertex = |k: usize, i: usize| if k == 0 { 0 } else { ring_start[k] + i };
    let mut vertices = vec![[0.0, radius]];
    for k in 1..=rings {
        let r = lerp(0.0, radius, k, rings);
        let n = segments(k);
        for i in 0..=n {
            // the straight sides exactly on their lines
            let point = if i == n {
                [r, radius]
            } else if i == 0 && !quarter {
                [-r, radius]
            } else if i == 0 {
                [0.0, radius - r]
            } else {
                let t = start + span * i as f64 / n as f64;
                [r * t.cos(), radius + r * t.sin()]
            };
            vertices.push(point);
        }
    }
    let mut cells = Vec::new();
    for i in 0..segments(1) {
        cells.push([0, vertex(1, i), vertex(1, i + 1)]);
    }
    for k in 2..=rings {
        let (n_in, n_out) = (segments(k - 1), segments(k));
        let (mut p, mut q) = (0, 0);
        while p < n_in || q < n_out {
            let step_outer = p == n_in || (q < n_out && (q + 1) * n_in <= (p + 1) * n_out);
            if step_outer {
                cells.push([vertex(k - 1, p), vertex(k, q), vertex(k, q + 1)]);
                q += 1;
            } else {
                cells.push([vertex(k - 1, p), vertex(k, q), vertex(k - 1, p + 1)]);
                p += 1;
            }
        }
    }
    let start_marker = if quarter { 3 } else { 2 };
    let mut markers: Vec<(usize, usize, u32)> = (0..segments(rings))
        .map(|i| (vertex(rings, i), vertex(rings, i + 1), 1))
        .collect();
    for k in 1..=rings {
        let last_in = if k == 1 { 0 } else { segments(k - 1) };
        markers.push((vertex(k - 1, 0), vertex(k, 0), start_marker));
        markers.push((vertex(k - 1, last_in), vertex(k, segments(k)), 2));
    }
    let mesh = TriangleMesh::new(vertices, cells, &markers)?;
    if quarter {
        mesh.with_boundary_names(&[("arc", &[1]), ("top", &[2]), ("axis", &[3])])
    } else {
        mesh.with_boundary_names(&[("arc", &[1]), ("top", &[2])])
    }
}

impl TriangleMesh {
    /// The lower half of the disc of radius `radius` centred at `(0, radius)`: the
    /// cylinder of Hertz line contact resting on the plane `y = 0` at the origin.
    ///
    /// A centre vertex `(0, radius)` and `rings` half rings, ring `k` with `3k + 1`
    /// vertices at radius `k/rings · radius`, angles from π to 2π; neighbouring rings are
    /// zipped by angle. Boundary parts: `arc` (marker 1, the curved boundary, where
    /// contact can happen) and `top` (marker 2, the flat side `y = radius`, where the
    /// load is applied).
    ///
    /// # Errors
    /// [`Error::Mesh`] for a radius that is not positive and finite, or `rings = 0`.
    pub fn half_disk(radius: f64, rings: usize) -> Result<Self> {
        lower_sector(radius, rings, false)
    }

    /// The lower right quarter `x ≥ 0` of [`TriangleMesh::half_disk`]: the symmetric
    /// half of the Hertz cylinder, whose rigid motions the symmetry line removes
    /// (`u_x = 0` on it). Ring `k` has `⌈3k/2⌉` segments from angle 3π/2 to 2π.
    /// Boundary parts: `arc` (marker 1), `top` (marker 2, `y = radius`) and `axis`
    /// (marker 3, the symmetry line `x = 0`).
    ///
    /// # Errors
    /// As [`TriangleMesh::half_disk`].
    pub fn quarter_disk(radius: f64, rings: usize) -> Result<Self> {
        lower_sector(radius, rings, true)
    }

    /// Refines by newest-vertex bisection until every cell's diameter is at most the
    /// smallest value of the size function `size(x)` at its vertices and centroid, and
    /// moves each vertex created on a boundary edge to `snap(marker, x)` (its projection
    /// onto the curve that part of the boundary approximates; return `x` for straight
    /// parts).
    ///
    /// `size` is in the mesh's length unit and must be positive where evaluated;
    /// `max_cells` bounds the result, so that a size field asking for too fine a mesh is
    /// refused instead of exhausting memory.
    /// Returns the refined mesh (boundary parts and names kept) and, per refinement
    /// round, the parent of every cell of the next mesh (for prolongation).
    ///
    /// # Errors
    /// [`Error::Mesh`] where `size` is not positive and finite at a point it is asked
    /// at, where the mesh would exceed `max_cells` cells, or where moving a
    /// boundary vertex onto its curve would turn a cell inside out (the curve is then
    /// too curved for the cells next to it: start from a finer mesh).
    pub fn refine_to_size(
        &self,
        size: impl Fn([f64; 2]) -> f64,
        snap: impl Fn(u32, [f64; 2]) -> [f64; 2],
        max_cells: usize,
    ) -> Result<(TriangleMesh, Vec<Vec<usize>>)> {
        let mut mesh = self.clone();
        let mut parents_per_round = Vec::new();
        loop {
            let mut marked = Vec::new();
            for c in 0..mesh.cells.len() {
                let x = mesh.cell_coordinates(c);
                let points = [
                    [x[0], x[1]],
                    [x[2], x[3]],
                    [x[4], x[5]],
                    [(x[0] + x[2] + x[4]) / 3.0, (x[1] + x[3] + x[5]) / 3.0],
                ];
                let mut s = f64::INFINITY;
                for p in points {
                    let value = size(p);
                    if !(value > 0.0 && value.is_finite()) {
                        return Err(mesh_error(format!(
                            "the mesh size function is {value} at ({}, {}): it must be positive and finite",
                            p[0], p[1]
                        )));
                    }
                    s = s.min(value);
                }
                if mesh.cell_diameter(c) > s {
                    marked.push(c);
                }
            }
            if marked.is_empty() {
                return Ok((mesh, parents_per_round));
            }
            // Closure at most quadruples the marked cells' count and touches as many
            // neighbours; refuse before allocating what cannot be wanted.
            if mesh.cells.len() + 3 * marked.len() > max_cells {
                return Err(mesh_error(format!(
                    "the mesh size function asks for more than {max_cells} cells (at {} cells, {} more to split): give a larger minimum size",
                    mesh.cells.len(),
                    marked.len()
                )));
            }
            let old_vertices = mesh.vertices.len();
            let (mut next, parents) = mesh.refine(&marked)?;
            next.snap_new_boundary_vertices(old_vertices, &snap)?;
            parents_per_round.push(parents);
            mesh = next;
        }
    }

    /// [`TriangleMesh::refine_uniformly`] with each new boundary vertex moved to
    /// `snap(marker, x)` as in [`TriangleMesh::refine_to_size`], and the parent of every
    /// cell of the result (the coarse cell it was split from, for prolongation: the
    /// parents are those of the split, exact even where snapping moved a vertex off the
    /// coarse cell).
    ///
    /// # Errors
    /// [`Error::Mesh`] where the projection is not finite or would turn a cell inside out.
    pub fn refine_uniformly_onto(
        &self,
        snap: impl Fn(u32, [f64; 2]) -> [f64; 2],
    ) -> Result<(TriangleMesh, Vec<usize>)> {
        let old_vertices = self.vertices.len();
        let (mut fine, parents) = self.bisect(&vec![true; self.edges.len()])?;
        fine.snap_new_boundary_vertices(old_vertices, &snap)?;
        Ok((fine, parents))
    }

    /// Moves the boundary vertices numbered from `first_new` to `snap(marker, x)`,
    /// checking that no cell turns inside out.
    pub(super) fn snap_new_boundary_vertices(
        &mut self,
        first_new: usize,
        snap: &impl Fn(u32, [f64; 2]) -> [f64; 2],
    ) -> Result<()> {
        let mut moved = false;
        for &(e, marker) in &self.boundary_edges {
            for v in self.edges[e] {
                if v >= first_new {
                    let p = snap(marker, self.vertices[v]);
                    if !(p[0].is_finite() && p[1].is_finite()) {
                        return Err(mesh_error(format!(
                            "the boundary projection of ({}, {}) (marker {marker}) is not finite",
                            self.vertices[v][0], self.vertices[v][1]
                        )));
                    }
                    moved |= p != self.vertices[v];
                    std::sync::Arc::make_mut(&mut self.vertices)[v] = p;
                }
            }
        }
        if moved {
            for (c, &[a, b, d]) in self.cells.iter().enumerate() {
                let (p, q, r) = (self.vertices[a], self.vertices[b], self.vertices[d]);
                let longest = dist2(p, q).max(dist2(q, r)).max(dist2(r, p));
                if cross(p, q, r) <= 2e-12 * longest {
                    return Err(mesh_error(format!(
                        "moving new boundary vertices onto the curve turns cell {c} inside out: the curve is too curved for the cells next to it; start from a finer mesh"
                    )));
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn onto_circle(centre: [f64; 2], radius: f64) -> impl Fn(u32, [f64; 2]) -> [f64; 2] {
        move |marker, p| {
            if marker != 1 {
                return p;
            }
            let (dx, dy) = (p[0] - centre[0], p[1] - centre[1]);
            let r = (dx * dx + dy * dy).sqrt();
            [centre[0] + radius * dx / r, centre[1] + radius * dy / r]
        }
    }

    #[test]
    fn uniform_refinement_onto_the_arc_keeps_the_split_parents() {
        let coarse = TriangleMesh::quarter_disk(1.0, 3).unwrap();
        let (fine, parents) = coarse
            .refine_uniformly_onto(onto_circle([0.0, 1.0], 1.0))
            .unwrap();
        let plain = coarse.refine_uniformly();
        assert_eq!(fine.cell_count(), 4 * coarse.cell_count());
        assert_eq!(fine.cells(), plain.cells());
        // the split's parents are those the unsnapped (exactly nested) mesh locates
        assert_eq!(
            parents,
            crate::multigrid::parents_by_location(&coarse, &plain).unwrap()
        );
        for (v, (p, q)) in fine.vertices().iter().zip(plain.vertices()).enumerate() {
            let on_arc = fine
                .boundary_edges()
                .iter()
                .any(|&(e, m)| m == 1 && fine.edges()[e].contains(&v));
            if on_arc {
                assert!((p[0].hypot(p[1] - 1.0) - 1.0).abs() <= 1e-15, "{p:?}");
            } else {
                assert_eq!(p, q, "vertex {v} moved off the arc");
            }
        }
    }

    #[test]
    fn the_half_disk_has_half_the_area_and_its_two_named_sides() {
        for rings in [1, 2, 5, 16] {
            let m = TriangleMesh::half_disk(2.0, rings).unwrap();
            let area: f64 = (0..m.cell_count()).map(|c| m.area(c)).sum();
            // the polygon inscribed in the half circle with 3·rings segments
            let n = 3 * rings;
            let polygon = 0.5 * n as f64 * 4.0 * (std::f64::consts::PI / n as f64).sin();
            assert!((area - polygon).abs() < 1e-12 * polygon, "{rings}: {area}");
            assert_eq!(m.boundary_part_names(), ["arc", "top"]);
            let arc = m.boundary_edges().iter().filter(|e| e.1 == 1).count();
            let top = m.boundary_edges().iter().filter(|e| e.1 == 2).count();
            assert_eq!((arc, top), (n, 2 * rings));
            for &(e, marker) in m.boundary_edges() {
                for v in m.edges()[e] {
                    let [x, y] = m.vertices()[v];
                    match marker {
                        1 => assert!((x.hypot(y - 2.0) - 2.0).abs() < 1e-14),
                        _ => assert_eq!(y, 2.0),
                    }
                }
            }
        }
        assert!(TriangleMesh::half_disk(0.0, 4).is_err());
        assert!(TriangleMesh::half_disk(1.0, 0).is_err());
    }

    #[test]
    fn the_quarter_disk_is_half_the_half_disk_with_its_axis() {
        for rings in [1, 2, 3, 8] {
            let m = TriangleMesh::quarter_disk(1.0, rings).unwrap();
            let area: f64 = (0..m.cell_count()).map(|c| m.area(c)).sum();
            let n = (3 * rings).div_ceil(2);
            let polygon = 0.5 * n as f64 * (std::f64::consts::FRAC_PI_2 / n as f64).sin();
            assert!((area - polygon).abs() < 1e-12, "{rings}: {area} {polygon}");
            assert_eq!(m.boundary_part_names(), ["arc", "top", "axis"]);
            for &(e, marker) in m.boundary_edges() {
                for v in m.edges()[e] {
                    let [x, y] = m.vertices()[v];
                    match marker {
                        1 => assert!((x.hypot(y - 1.0) - 1.0).abs() < 1e-14),
                        2 => assert_eq!(y, 1.0),
                        _ => assert_eq!(x, 0.0),
                    }
                }
            }
            assert!(m.boundary_edges().iter().all(|e| e.1 != 0));
        }
    }

    #[test]
    fn graded_refinement_meets_the_size_field_and_keeps_the_arc_on_the_circle() {
        let radius = 1.0;
        let coarse = TriangleMesh::half_disk(radius, 4).unwrap();
        let (h_min, grading, zone): (f64, f64, f64) = (2e-3, 0.3, 0.05);
        // uniform h_min on the zone |x| ≤ zone of the line y = 0, growing away from it
        let size = |p: [f64; 2]| {
            let d = distance_to_segment(p, [-zone, 0.0], [zone, 0.0]);
            h_min.max(grading * d)
        };
        let (fine, rounds) = coarse
            .refine_to_size(size, onto_circle([0.0, radius], radius), 1_000_000)
            .unwrap();
        assert!(!rounds.is_empty());
        // bisection keeps the shapes of the coarse cells' descendants
        let (q0, q) = (coarse.quality(), fine.quality());
        assert!(q.min_angle_deg > 0.5 * q0.min_angle_deg, "{q:?}");
        for c in 0..fine.cell_count() {
            let x = fine.cell_coordinates(c);
            let s = [0, 2, 4]
                .iter()
                .map(|&i| size([x[i], x[i + 1]]))
                .fold(f64::INFINITY, f64::min);
            assert!(fine.cell_diameter(c) <= s, "cell {c}");
        }
        // the contact zone is resolved: its boundary edges are at most h_min long
        let mut zone_edges = 0;
        for &(e, marker) in fine.boundary_edges() {
            let [a, b] = fine.edges()[e];
            let (p, q) = (fine.vertices()[a], fine.vertices()[b]);
            if marker == 1 {
                for v in [p, q] {
                    assert!((v[0].hypot(v[1] - radius) - radius).abs() < 1e-13);
                }
                if p[0].abs() <= zone && q[0].abs() <= zone {
                    zone_edges += 1;
                    assert!(dist2(p, q).sqrt() <= h_min * (1.0 + 1e-12));
                }
            }
        }
        assert!(
            zone_edges as f64 >= 2.0 * zone / h_min * 0.9,
            "{zone_edges}"
        );
        // graded, not uniform: far fewer cells than h_min everywhere would take
        let uniform = std::f64::consts::PI / 2.0 / (h_min * h_min / 2.0);
        assert!(
            (fine.cell_count() as f64) < uniform / 100.0,
            "{}",
            fine.cell_count()
        );
        // every round's parents index the previous mesh
        let mut count = coarse.cell_count();
        for parents in &rounds {
            assert!(parents.iter().all(|&p| p < count));
            count = parents.len();
        }
        assert_eq!(count, fine.cell_count());
    }

    #[test]
    fn bad_size_functions_are_refused() {
        let m = TriangleMesh::half_disk(1.0, 2).unwrap();
        let keep = |_: u32, p: [f64; 2]| p;
        let e = m
            .refine_to_size(|_| 0.0, keep, 1000)
            .unwrap_err()
            .to_string();
        assert!(e.contains("mesh size function is 0"), "{e}");
        let e = m
            .refine_to_size(|_| f64::NAN, keep, 1000)
            .unwrap_err()
            .to_string();
        assert!(e.contains("NaN"), "{e}");
        let e = m
            .refine_to_size(|_| 1e-9, keep, 1000)
            .unwrap_err()
            .to_string();
        assert!(e.contains("more than"), "{e}");
        let e = m
            .refine_to_size(|_| 0.3, |_, p| [p[0], p[1] + 10.0], 1000)
            .unwrap_err()
            .to_string();
        assert!(e.contains("inside out"), "{e}");
    }
}
