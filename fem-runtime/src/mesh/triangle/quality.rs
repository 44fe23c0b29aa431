//! Mesh quality and mesh faults: angles and aspect ratios with the thresholds at which a
//! solve is warned about or refused, coincident vertices and vertices lying on boundary
//! edges (a mesh without Gmsh `Coherence`), and the memory of refined meshes.

use super::*;

/// Shape measures of a triangle mesh, from [`TriangleMesh::quality`].
///
/// Angles are in degrees. The aspect ratio of a cell is `h_T / (2√3 r_T)`, its longest
/// edge over the diameter of its inscribed circle, scaled so that the equilateral
/// triangle has 1; it grows like `1 / sin θ` as the smallest angle `θ` closes and like
/// `1 / (π − θ)` as the largest opens.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshQuality {
    /// The smallest angle of any cell.
    pub min_angle_deg: f64,
    /// The cell with the smallest angle.
    pub min_angle_cell: usize,
    /// The largest angle of any cell.
    pub max_angle_deg: f64,
    /// The cell with the largest angle.
    pub max_angle_cell: usize,
    /// The largest aspect ratio of any cell (1 for an equilateral triangle).
    pub max_aspect_ratio: f64,
    /// The cell with the largest aspect ratio.
    pub max_aspect_ratio_cell: usize,
}

/// Largest angle (degrees) beyond which [`MeshQuality::warnings`] warns: the P1
/// interpolation error grows like `1 / sin θ_max` (the maximum-angle condition of
/// Babuška and Aziz, 1976), and Gmsh's 2D meshers rarely exceed 150°.
pub const WARN_MAX_ANGLE_DEG: f64 = 160.0;

/// Smallest angle (degrees) below which [`MeshQuality::warnings`] warns: inverse
/// estimates, and with them the stabilization's `C_I`, grow like `1 / sin θ_min`.
pub const WARN_MIN_ANGLE_DEG: f64 = 5.0;

/// Largest angle (degrees) beyond which [`MeshQuality::check`] refuses the mesh: the
/// gradient error of P1 interpolation on a cell grows like `1 / cos(θ_max / 2)`
/// (the maximum-angle condition: Babuška and Aziz 1976, Jamet 1976), so above 179° it
/// is amplified more than 110-fold and u_h, λ_h near the cell cannot be trusted. (On
/// the sliver test mesh with a 179.4° angle, refined 5 times, the nodal method's ∫λ_h
/// was 2.8 times P2–P0's; with 174°, 5 % above it, and P1–P0's 13 % below: degraded,
/// which [`WARN_MAX_ANGLE_DEG`] warns of, but not lost.)
pub const REFUSE_MAX_ANGLE_DEG: f64 = 179.0;

impl MeshQuality {
    /// No cell yet: every comparison of [`TriangleMesh::quality`]'s scan replaces it.
    const EMPTY: Self = Self {
        min_angle_deg: f64::INFINITY,
        min_angle_cell: 0,
        max_angle_deg: 0.0,
        max_angle_cell: 0,
        max_aspect_ratio: 0.0,
        max_aspect_ratio_cell: 0,
    };

    fn merge_min_angle(&mut self, angle: f64, c: usize) {
        if angle < self.min_angle_deg {
            (self.min_angle_deg, self.min_angle_cell) = (angle, c);
        }
    }

    fn merge_max_angle(&mut self, angle: f64, c: usize) {
        if angle > self.max_angle_deg {
            (self.max_angle_deg, self.max_angle_cell) = (angle, c);
        }
    }

    fn merge_ratio(&mut self, ratio: f64, c: usize) {
        if ratio > self.max_aspect_ratio {
            (self.max_aspect_ratio, self.max_aspect_ratio_cell) = (ratio, c);
        }
    }

    /// Warnings for angles beyond [`WARN_MAX_ANGLE_DEG`] or below [`WARN_MIN_ANGLE_DEG`],
    /// naming the cell of `mesh` (the mesh `self` was computed on) by its corners; empty
    /// for a shape-regular mesh. A small angle is warned about for what it does: where
    /// the stabilization parameter comes from the mesh's inverse constant
    /// (`alpha_from_inverse_constant`: `α = ½/C_I`, which one thin cell makes small
    /// everywhere), that; otherwise stiffness entries of the size of its cotangent, so
    /// that the linear systems lose digits (small angles alone do not degrade P1
    /// interpolation; the maximum-angle condition does).
    pub fn warnings(&self, mesh: &TriangleMesh, alpha_from_inverse_constant: bool) -> Vec<String> {
        let mut out = Vec::new();
        if self.max_angle_deg > WARN_MAX_ANGLE_DEG {
            out.push(format!(
                "{} has an angle of {:.5}° (above {WARN_MAX_ANGLE_DEG}°): near-flat triangles degrade the accuracy of u_h and λ_h around them; remesh",
                describe_cell(mesh, self.max_angle_cell),
                self.max_angle_deg
            ));
        }
        if self.min_angle_deg < WARN_MIN_ANGLE_DEG {
            let consequence = if alpha_from_inverse_constant {
                "its inverse constant C_I is large, which makes the stabilization α = ½/C_I small on the whole mesh"
            } else {
                "its stiffness entries grow like the cotangent of that angle, so the linear systems lose digits"
            };
            out.push(format!(
                "{} has an angle of {:.5}° (below {WARN_MIN_ANGLE_DEG}°): {consequence}; remesh",
                describe_cell(mesh, self.min_angle_cell),
                self.min_angle_deg
            ));
        }
        out
    }

    /// Refuses a mesh with an angle above [`REFUSE_MAX_ANGLE_DEG`], naming the cell of
    /// `mesh` (the mesh `self` was computed on), its corners and its angles.
    ///
    /// # Errors
    /// [`Error::Mesh`] with that description and how to fix the mesh.
    pub fn check(&self, mesh: &TriangleMesh) -> Result<()> {
        if self.max_angle_deg <= REFUSE_MAX_ANGLE_DEG {
            return Ok(());
        }
        let c = self.max_angle_cell;
        let angles = mesh
            .cell_angles(c)
            .map(|a| format!("{:.5}°", a.to_degrees()));
        let amplification = 1.0 / (0.5 * self.max_angle_deg.to_radians()).cos();
        Err(mesh_error(format!(
            "{} is nearly flat, with angles {}: its largest angle is above {REFUSE_MAX_ANGLE_DEG}°, which amplifies the interpolation error of u_h there {amplification:.1e}-fold, so the solution cannot be trusted; remesh so that no vertex lies (almost) on the segment between two others",
            describe_cell(mesh, c),
            angles.join(", ")
        )))
    }
}

/// "cell 7 (corners (0, 0), (1, 0), (0, 1))".
pub(super) fn describe_cell(mesh: &TriangleMesh, c: usize) -> String {
    let corners: Vec<String> = mesh
        .cell(c)
        .iter()
        .map(|&v| format!("({}, {})", mesh.vertices[v][0], mesh.vertices[v][1]))
        .collect();
    format!("cell {c} (corners {})", corners.join(", "))
}

/// Bytes an obstacle solve on a mesh of `cells` triangles refined uniformly
/// `refinements` times plans to use, at `bytes_per_cell` on the finest mesh (each
/// refinement multiplies the cells by 4); `f64` so that no count overflows.
///
/// The per-cell figure is the caller's (it depends on the elements); nested levels are
/// within it, since the coarser levels together have a third of the finest's cells.
pub fn estimated_bytes(cells: usize, refinements: u32, bytes_per_cell: f64) -> f64 {
    cells as f64 * 4f64.powi(refinements as i32) * bytes_per_cell
}

impl TriangleMesh {
    /// The three angles of cell `c` in radians, at its local vertices 0, 1, 2.
    ///
    /// Computed as `atan2(|cross|, dot)` of the two edges at each vertex, which stays
    /// accurate for angles near 0 and near π (where `acos` of the cosine loses digits).
    pub fn cell_angles(&self, c: usize) -> [f64; 3] {
        let [a, b, d] = self.cells[c];
        let p = [self.vertices[a], self.vertices[b], self.vertices[d]];
        [0, 1, 2].map(|i| {
            let (o, u, w) = (p[i], p[(i + 1) % 3], p[(i + 2) % 3]);
            let (e, f) = ([u[0] - o[0], u[1] - o[1]], [w[0] - o[0], w[1] - o[1]]);
            (e[0] * f[1] - e[1] * f[0])
                .abs()
                .atan2(e[0] * f[0] + e[1] * f[1])
        })
    }

    /// The aspect ratio `h_T / (2√3 r_T)` of cell `c` (1 for the equilateral triangle),
    /// with `r_T = 2|T| / perimeter` the inradius.
    pub fn cell_aspect_ratio(&self, c: usize) -> f64 {
        let [a, b, d] = self.cells[c];
        let p = [self.vertices[a], self.vertices[b], self.vertices[d]];
        let sides = [dist2(p[1], p[2]), dist2(p[2], p[0]), dist2(p[0], p[1])].map(f64::sqrt);
        let h = sides.iter().copied().fold(0.0, f64::max);
        let perimeter: f64 = sides.iter().sum();
        let inradius = self.area(c).abs() * 2.0 / perimeter;
        h / (2.0 * 3f64.sqrt() * inradius)
    }

    /// The smallest and largest angles and the largest aspect ratio over the cells, with
    /// the cells where they occur (see [`MeshQuality`]).
    pub fn quality(&self) -> MeshQuality {
        // chunks on rayon's threads, merged in order with the serial scan's strict
        // comparisons, so the cells named are the first of their kind on any thread
        // count (0.08 s serially at 2M cells); not `element::triangle::over_cell_chunks`,
        // which would make the mesh module import the element module that imports it
        use rayon::prelude::*;
        const CHUNK: usize = 4096;
        let chunks: Vec<MeshQuality> = (0..self.cells.len().div_ceil(CHUNK))
            .into_par_iter()
            .map(|k| {
                let mut q = MeshQuality::EMPTY;
                for c in k * CHUNK..((k + 1) * CHUNK).min(self.cells.len()) {
                    for angle in self.cell_angles(c).map(f64::to_degrees) {
                        q.merge_min_angle(angle, c);
                        q.merge_max_angle(angle, c);
                    }
                    q.merge_ratio(self.cell_aspect_ratio(c), c);
                }
                q
            })
            .collect();
        let mut q = MeshQuality::EMPTY;
        for chunk in chunks {
            q.merge_min_angle(chunk.min_angle_deg, chunk.min_angle_cell);
            q.merge_max_angle(chunk.max_angle_deg, chunk.max_angle_cell);
            q.merge_ratio(chunk.max_aspect_ratio, chunk.max_aspect_ratio_cell);
        }
        q
    }

    /// The cells after `refinements` uniform refinements ([`Self::refine_uniformly`]
    /// multiplies them by 4), or `None` if the count overflows `usize`.
    pub fn uniformly_refined_cell_count(&self, refinements: u32) -> Option<usize> {
        4usize
            .checked_pow(refinements)
            .and_then(|f| f.checked_mul(self.cells.len()))
    }

    /// Pairs of distinct vertices closer than `1e-6 ×` the mesh's shortest edge, each
    /// pair `[a, b]` with `a < b`, sorted.
    ///
    /// Vertices joined by an edge are at least the shortest edge apart, so such a pair is
    /// never an edge: in a mesh read from a file it is a duplicated node, typically two
    /// surfaces meshed separately along their common curve, which leaves a slit of
    /// boundary edges inside the domain. Vertices are hashed on their coordinates rounded
    /// to the tolerance and each is compared with those of the neighbouring 3×3 buckets,
    /// so the search is linear in the vertex count.
    pub fn coincident_vertices(&self) -> Vec<[usize; 2]> {
        let shortest = self
            .edges
            .iter()
            .map(|&[a, b]| dist2(self.vertices[a], self.vertices[b]))
            .fold(f64::INFINITY, f64::min)
            .sqrt();
        let tolerance = 1e-6 * shortest;
        if !(tolerance > 0.0 && tolerance.is_finite()) {
            return Vec::new();
        }
        // float → int casts saturate, so huge coordinates only share buckets, never wrap
        let key = |p: [f64; 2]| {
            (
                (p[0] / tolerance).floor() as i64,
                (p[1] / tolerance).floor() as i64,
            )
        };
        let mut buckets: std::collections::HashMap<(i64, i64), Vec<usize>> =
            std::collections::HashMap::with_capacity(self.vertices.len());
        for (v, &p) in self.vertices.iter().enumerate() {
            buckets.entry(key(p)).or_default().push(v);
        }
        let mut pairs = Vec::new();
        for (a, &p) in self.vertices.iter().enumerate() {
            let (i, j) = key(p);
            for di in -1..=1i64 {
                for dj in -1..=1i64 {
                    let Some(bucket) = buckets.get(&(i.saturating_add(di), j.saturating_add(dj)))
                    else {
                        continue;
                    };
                    for &b in bucket {
                        if b > a && dist2(p, self.vertices[b]) <= tolerance * tolerance {
                            pairs.push([a, b]);
                        }
                    }
                }
            }
        }
        pairs.sort_unstable();
        pairs.dedup();
        pairs
    }
}

impl TriangleMesh {
    /// Boundary vertices that lie on a boundary edge they do not end, as
    /// `(vertex, edge)` pairs sorted by vertex: within `1e-6 ×` the shorter of the
    /// edge and the vertex's shortest boundary edge of the segment.
    ///
    /// On a valid mesh of a domain the boundary edges meet only at their ends, so such a
    /// vertex is the end of a slit inside the domain: two surfaces meshed separately
    /// along a common curve, with coincident nodes ([`Self::coincident_vertices`] finds
    /// those too) or with different nodes on each side (hanging vertices). Boundary
    /// edges are bucketed on a grid of the longest boundary edge's size, so the search
    /// is linear for boundaries of comparable edge lengths.
    pub fn vertices_on_boundary_edges(&self) -> Vec<(usize, usize)> {
        let segment = |e: usize| {
            let [a, b] = self.edges[e];
            (self.vertices[a], self.vertices[b])
        };
        let longest = self
            .boundary_edges
            .iter()
            .map(|&(e, _)| {
                let (p, q) = segment(e);
                dist2(p, q)
            })
            .fold(0.0, f64::max)
            .sqrt();
        if !(longest > 0.0 && longest.is_finite()) {
            return Vec::new();
        }
        let key = |x: f64| (x / longest).floor() as i64;
        let mut buckets: std::collections::HashMap<(i64, i64), Vec<usize>> =
            std::collections::HashMap::with_capacity(2 * self.boundary_edges.len());
        for &(e, _) in &self.boundary_edges {
            let (p, q) = segment(e);
            let slack = 1e-6 * dist2(p, q).sqrt();
            for i in key(p[0].min(q[0]) - slack)..=key(p[0].max(q[0]) + slack) {
                for j in key(p[1].min(q[1]) - slack)..=key(p[1].max(q[1]) + slack) {
                    buckets.entry((i, j)).or_default().push(e);
                }
            }
        }
        // each boundary vertex's shortest boundary edge, so that a vertex near a short
        // edge of its own is not taken for one on a longer edge nearby
        let mut local = vec![f64::INFINITY; self.vertices.len()];
        for &(e, _) in &self.boundary_edges {
            let (p, q) = segment(e);
            for v in self.edges[e] {
                local[v] = local[v].min(dist2(p, q));
            }
        }
        let mut found = Vec::new();
        for (v, &local2) in local.iter().enumerate() {
            if local2 == f64::INFINITY {
                continue;
            }
            let x = self.vertices[v];
            let Some(candidates) = buckets.get(&(key(x[0]), key(x[1]))) else {
                continue;
            };
            for &e in candidates {
                if self.edges[e].contains(&v) {
                    continue;
                }
                let (p, q) = segment(e);
                let d = [q[0] - p[0], q[1] - p[1]];
                let length2 = d[0] * d[0] + d[1] * d[1];
                let s = ((x[0] - p[0]) * d[0] + (x[1] - p[1]) * d[1]) / length2;
                let s = s.clamp(0.0, 1.0);
                let nearest = [p[0] + s * d[0], p[1] + s * d[1]];
                if dist2(x, nearest) <= 1e-12 * length2.min(local2) {
                    found.push((v, e));
                }
            }
        }
        found.sort_unstable();
        found.dedup();
        found
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::triangle::Diagonal;

    /// The scan `quality` replaced: one pass over the cells in order, strict comparisons.
    fn serial_quality(mesh: &TriangleMesh) -> MeshQuality {
        let mut q = MeshQuality::EMPTY;
        for c in 0..mesh.cell_count() {
            for angle in mesh.cell_angles(c).map(f64::to_degrees) {
                q.merge_min_angle(angle, c);
                q.merge_max_angle(angle, c);
            }
            q.merge_ratio(mesh.cell_aspect_ratio(c), c);
        }
        q
    }

    /// On meshes of several chunks, the chunked scan names the cells the serial scan
    /// names: with every angle tied (a uniform grid, the first cell of each kind) and with
    /// the extremes in a late chunk (one vertex moved).
    #[test]
    fn chunked_quality_names_the_serial_scans_cells() {
        let grid =
            TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 64, 64, Diagonal::Alternating).unwrap();
        assert!(grid.cell_count() >= 2 * 4096);
        assert_eq!(grid.quality(), serial_quality(&grid));
        let mut vertices = grid.vertices().to_vec();
        let cells: Vec<[usize; 3]> = (0..grid.cell_count()).map(|c| grid.cell(c)).collect();
        // an interior vertex in the upper half, moved by a third of a cell
        let v = 50 * 65 + 40;
        vertices[v][0] += 0.3 / 64.0;
        vertices[v][1] += 0.2 / 64.0;
        let moved = TriangleMesh::new(vertices, cells, &[]).unwrap();
        let q = moved.quality();
        assert_eq!(q, serial_quality(&moved));
        assert!(
            q.min_angle_cell > 4096 && moved.cell(q.min_angle_cell).contains(&v),
            "{q:?} {:?}",
            moved.cell(q.min_angle_cell)
        );
    }
}
