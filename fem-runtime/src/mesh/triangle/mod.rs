//! Triangle meshes of polygonal domains: generators, validation, conforming
//! newest-vertex bisection (`refine.rs`), point location (`locate.rs`) and quality
//! (`quality.rs`).
//!
//! Every cell is stored counter-clockwise with its refinement edge opposite local
//! vertex 0 (local edge 1, vertices 1–2). `new` chooses the longest edge as refinement
//! edge; bisection then keeps the newest vertex at local position 0, so descendants
//! fall into at most four similarity classes per initial cell.

mod curved;
mod graded;
mod locate;
mod parts;
mod quality;
mod refine;

pub use curved::{CurvedTriangleMesh, QuadraticGeometry};
pub use graded::distance_to_segment;
pub use locate::PointLocator;
pub use parts::NamedGroup;

pub use quality::{
    estimated_bytes, MeshQuality, REFUSE_MAX_ANGLE_DEG, WARN_MAX_ANGLE_DEG, WARN_MIN_ANGLE_DEG,
};

use crate::error::{Error, Result};
use std::sync::Arc;

/// Marks "no cell" / "no midpoint" in the index tables.
const NONE: usize = usize::MAX;

/// Marks "no cell" in the 32-bit edge table `edge_cells`.
const NO_CELL: u32 = u32::MAX;

/// The largest vertex coordinate a mesh accepts, in absolute value: the kernels form
/// powers of lengths up to the sixth (the plates' `α h⁴ |T|`), which overflow `f64`
/// (1.8e308) beyond about 1e51; a cell of 1e300 was once called degenerate with a
/// longest edge of `inf`. No physical mesh comes near it in any unit.
pub const MAX_COORDINATE: f64 = 1e50;

/// `value` as a 32-bit index of the mesh tables: below `u32::MAX`, which marks "none".
///
/// The edge tables store `u32` indices (half the memory of `usize`: at 2M cells the
/// nested meshes of a solve take about 0.1 kB less per unknown); a mesh whose counts do
/// not fit is refused with an [`Error::Mesh`] naming `what`.
fn index32(value: usize, what: &str) -> Result<u32> {
    u32::try_from(value)
        .ok()
        .filter(|&v| v != NO_CELL)
        .ok_or_else(|| {
            mesh_error(format!(
                "{what} is {value}: the mesh tables hold 32-bit indices, at most {}",
                NO_CELL - 1
            ))
        })
}

/// How [`TriangleMesh::rectangle`] splits each grid square into triangles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Diagonal {
    /// The diagonal from the lower-left to the upper-right corner (`/`).
    Right,
    /// The diagonal from the lower-right to the upper-left corner (`\`).
    Left,
    /// `Right` and `Left` alternating like a checkerboard, `Right` in the lower-left square.
    Alternating,
    /// Both diagonals: four triangles per square around a centre vertex.
    Crossed,
}

/// A conforming mesh of counter-clockwise triangles with its edges and boundary markers.
///
/// The vertex, cell and edge tables are shared (`Arc`): a clone, as every discretization
/// keeps one of its mesh, costs no copy (at 2M cells the tables are 170 MB, and their
/// copy was 0.1 s of page faults on the thread that bounds the finest level's setup).
/// The few methods that change a table copy it first if it is shared.
#[derive(Clone, Debug, PartialEq)]
pub struct TriangleMesh {
    vertices: Arc<Vec<[f64; 2]>>,
    cells: Arc<Vec<[usize; 3]>>,
    /// Each edge as `[a, b]` with `a < b`, sorted lexicographically.
    edges: Arc<Vec<[usize; 2]>>,
    /// The edges whose smaller vertex is `v` are `edges[edge_start[v]..edge_start[v + 1]]`,
    /// sorted by the larger vertex, so an edge is found by a binary search.
    /// (This and the next two tables hold `u32` indices, see [`index32`].)
    edge_start: Arc<Vec<u32>>,
    cell_edges: Arc<Vec<[u32; 3]>>,
    /// The one or two cells of each edge; `NO_CELL` in the second slot on the boundary.
    edge_cells: Arc<Vec<[u32; 2]>>,
    /// Sorted by edge.
    boundary_edges: Vec<(usize, u32)>,
    /// Named groups (boundary parts by marker), kept by refinement.
    groups: Vec<NamedGroup>,
    /// The curves the boundary edges of a marker approximate, kept by refinement: new
    /// vertices on those edges are moved onto the curve ([`TriangleMesh::refine`]).
    curves: Vec<(u32, BoundaryCurve)>,
}

/// A curve a part of the boundary approximates with straight edges: where refinement
/// splits such an edge, the new vertex is projected onto the curve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BoundaryCurve {
    /// The circle of this centre and radius.
    Circle {
        /// Its centre.
        centre: [f64; 2],
        /// Its radius (positive).
        radius: f64,
    },
}

impl BoundaryCurve {
    /// The point of the curve nearest `p` (the radial projection for a circle; `p` at
    /// the centre is returned as is).
    pub fn project(&self, p: [f64; 2]) -> [f64; 2] {
        match *self {
            BoundaryCurve::Circle { centre, radius } => {
                let (dx, dy) = (p[0] - centre[0], p[1] - centre[1]);
                let r = dx.hypot(dy);
                if r == 0.0 {
                    return p;
                }
                [centre[0] + radius * dx / r, centre[1] + radius * dy / r]
            }
        }
    }
}

impl TriangleMesh {
    /// The mesh with the boundary edges of `marker` declared to approximate `curve`:
    /// [`TriangleMesh::refine`] moves the vertices it adds on them onto the curve (a
    /// later declaration for the same marker replaces the earlier).
    pub fn with_boundary_curve(mut self, marker: u32, curve: BoundaryCurve) -> Self {
        self.curves.retain(|(m, _)| *m != marker);
        self.curves.push((marker, curve));
        self
    }

    /// The boundary curves by marker ([`TriangleMesh::with_boundary_curve`]).
    pub fn boundary_curves(&self) -> &[(u32, BoundaryCurve)] {
        &self.curves
    }
}

fn mesh_error(message: String) -> Error {
    Error::Mesh(message)
}

/// Twice the signed area of the triangle `p q r` (positive when counter-clockwise).
#[inline]
fn cross(p: [f64; 2], q: [f64; 2], r: [f64; 2]) -> f64 {
    (q[0] - p[0]) * (r[1] - p[1]) - (r[0] - p[0]) * (q[1] - p[1])
}

#[inline]
fn dist2(p: [f64; 2], q: [f64; 2]) -> f64 {
    let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
    dx * dx + dy * dy
}

/// `a + (b − a) i / n`, exactly `b` at `i = n` so that generated meshes close up.
fn lerp(a: f64, b: f64, i: usize, n: usize) -> f64 {
    if i == n {
        b
    } else {
        a + (b - a) * i as f64 / n as f64
    }
}

impl TriangleMesh {
    /// A validated mesh; `cells` are vertex triples that must be counter-clockwise.
    ///
    /// `boundary_markers` lists `(vertex a, vertex b, marker)` for boundary edges (in
    /// either vertex order); boundary edges not listed get marker 0. Each cell is rotated
    /// (keeping its orientation) so that its longest edge becomes the refinement edge,
    /// with ties broken by the edge's vertex indices so neighbours agree.
    pub fn new(
        vertices: Vec<[f64; 2]>,
        mut cells: Vec<[usize; 3]>,
        boundary_markers: &[(usize, usize, u32)],
    ) -> Result<Self> {
        if cells.is_empty() {
            return Err(mesh_error("a triangle mesh needs at least one cell".into()));
        }
        if let Some(i) = vertices
            .iter()
            .position(|v| !(v[0].is_finite() && v[1].is_finite()))
        {
            return Err(mesh_error(format!(
                "vertex {i} has non-finite coordinates ({}, {})",
                vertices[i][0], vertices[i][1]
            )));
        }
        // the powers of lengths the kernels form overflow for cells this large
        if let Some(i) = vertices
            .iter()
            .position(|v| v[0].abs() > MAX_COORDINATE || v[1].abs() > MAX_COORDINATE)
        {
            return Err(mesh_error(format!(
                "vertex {i} has coordinates ({:e}, {:e}) beyond ±{MAX_COORDINATE:e}, where the powers of lengths the kernels form overflow: rescale the mesh",
                vertices[i][0], vertices[i][1]
            )));
        }
        let nv = vertices.len();
        let mut used = vec![false; nv];
        for (c, cell) in cells.iter_mut().enumerate() {
            if let Some(&v) = cell.iter().find(|&&v| v >= nv) {
                return Err(mesh_error(format!(
                    "cell {c} {cell:?} names vertex {v}, but the mesh has only {nv} vertices"
                )));
            }
            let [a, b, d] = *cell;
            if a == b || b == d || d == a {
                let repeated = if a == b || a == d { a } else { b };
                return Err(mesh_error(format!(
                    "cell {c} {cell:?} repeats vertex {repeated}"
                )));
            }
            let p = [vertices[a], vertices[b], vertices[d]];
            let twice_area = cross(p[0], p[1], p[2]);
            // opposite[i] = squared length of the edge opposite local vertex i
            let opposite = [dist2(p[1], p[2]), dist2(p[2], p[0]), dist2(p[0], p[1])];
            let longest = opposite.iter().copied().fold(0.0, f64::max);
            if twice_area.abs() <= 2e-12 * longest {
                return Err(mesh_error(format!(
                    "cell {c} {cell:?} is degenerate: its area {:e} is at most 1e-12 × (longest edge {:e})²",
                    0.5 * twice_area.abs(),
                    longest.sqrt()
                )));
            }
            if twice_area < 0.0 {
                return Err(mesh_error(format!(
                    "cell {c} {cell:?} is inverted (clockwise, signed area {:e}); cells must be counter-clockwise",
                    0.5 * twice_area
                )));
            }
            // The refinement edge is the longest; the tie-break is a function of the edge
            // alone, so both cells of an edge rank it the same way.
            let key = |i: usize| {
                let (u, w) = (cell[(i + 1) % 3], cell[(i + 2) % 3]);
                (opposite[i], u.min(w), u.max(w))
            };
            let top = (0..3)
                .max_by(|&i, &j| {
                    let (ki, kj) = (key(i), key(j));
                    ki.0.total_cmp(&kj.0)
                        .then(ki.1.cmp(&kj.1))
                        .then(ki.2.cmp(&kj.2))
                })
                .unwrap_or(0);
            *cell = [cell[top], cell[(top + 1) % 3], cell[(top + 2) % 3]];
            for v in *cell {
                used[v] = true;
            }
        }
        if let Some(v) = used.iter().position(|&u| !u) {
            return Err(mesh_error(format!(
                "vertex {v} ({}, {}) belongs to no cell",
                vertices[v][0], vertices[v][1]
            )));
        }
        let mut mesh = Self::from_oriented(vertices, cells)?;
        mesh.apply_markers(boundary_markers)?;
        Ok(mesh)
    }

    /// The edge tables of counter-clockwise cells whose local order is kept as given.
    ///
    /// Edges are bucketed by their smaller vertex (a counting sort), so the build is
    /// linear in the mesh size apart from sorting the few edges at each vertex; the
    /// buckets are counted before the tables are allocated, which are then exactly as
    /// long as the edges (no spare capacity kept alive with the mesh).
    ///
    /// # Errors
    /// [`Error::Mesh`] for invalid edges (see `check_edge_group`) and for a mesh beyond
    /// the 32-bit indices of the edge tables.
    fn from_oriented(vertices: Vec<[f64; 2]>, cells: Vec<[usize; 3]>) -> Result<Self> {
        let nv = vertices.len();
        let nc = cells.len();
        // every vertex, edge and half-edge index below is at most one of these
        index32(nv, "the vertex count")?;
        index32(3 * nc, "three times the cell count (the half-edges)")?;
        let mut start = vec![0usize; nv + 1];
        for cell in &cells {
            for k in 0..3 {
                start[cell[k].min(cell[(k + 1) % 3]) + 1] += 1;
            }
        }
        for v in 0..nv {
            start[v + 1] += start[v];
        }
        // (larger vertex, 3·cell + local edge) per half-edge, grouped by smaller vertex;
        // both fit in u32 (checked above), which halves this transient table
        let mut slots = vec![(0u32, 0u32); 3 * nc];
        let mut fill = start.clone();
        for (c, cell) in cells.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (cell[k], cell[(k + 1) % 3]);
                let lo = a.min(b);
                slots[fill[lo]] = (a.max(b) as u32, (3 * c + k) as u32);
                fill[lo] += 1;
            }
        }
        drop(fill);
        let mut edge_count = 0;
        for lo in 0..nv {
            let bucket = &mut slots[start[lo]..start[lo + 1]];
            bucket.sort_unstable();
            edge_count += bucket.len() - bucket.windows(2).filter(|w| w[0].0 == w[1].0).count();
        }
        let mut edges = Vec::with_capacity(edge_count);
        let mut edge_start = vec![0u32; nv + 1];
        let mut edge_cells = Vec::with_capacity(edge_count);
        let mut cell_edges = vec![[NO_CELL; 3]; nc];
        let mut boundary_edges = Vec::new();
        for lo in 0..nv {
            edge_start[lo] = edges.len() as u32;
            let bucket = &slots[start[lo]..start[lo + 1]];
            let mut i = 0;
            while i < bucket.len() {
                let hi = bucket[i].0;
                let mut j = i + 1;
                while j < bucket.len() && bucket[j].0 == hi {
                    j += 1;
                }
                let group = &bucket[i..j];
                Self::check_edge_group(&cells, lo, hi as usize, group)?;
                let e = edges.len();
                edges.push([lo, hi as usize]);
                for &(_, s) in group {
                    cell_edges[s as usize / 3][s as usize % 3] = e as u32;
                }
                if group.len() == 1 {
                    edge_cells.push([group[0].1 / 3, NO_CELL]);
                    boundary_edges.push((e, 0));
                } else {
                    edge_cells.push([group[0].1 / 3, group[1].1 / 3]);
                }
                i = j;
            }
        }
        edge_start[nv] = edges.len() as u32;
        Ok(Self {
            vertices: Arc::new(vertices),
            cells: Arc::new(cells),
            edges: Arc::new(edges),
            edge_start: Arc::new(edge_start),
            cell_edges: Arc::new(cell_edges),
            edge_cells: Arc::new(edge_cells),
            boundary_edges,
            groups: Vec::new(),
            curves: Vec::new(),
        })
    }

    /// Rejects an edge `(lo, hi)` whose cells are duplicates, overlap, or number more than
    /// two; `group` holds `(hi, 3·cell + local edge)` for each cell of the edge.
    fn check_edge_group(
        cells: &[[usize; 3]],
        lo: usize,
        hi: usize,
        group: &[(u32, u32)],
    ) -> Result<()> {
        if group.len() == 1 {
            return Ok(());
        }
        // read in place: a vector per interior edge cost 3M allocations at 2M cells
        let owner = |i: usize| (group[i].1 as usize / 3, group[i].1 as usize % 3);
        let owners = || (0..group.len()).map(owner);
        // Two counter-clockwise cells on the same side of an edge run it in the same
        // direction; with the same third vertex they are the same triangle.
        let third = |(c, k): (usize, usize)| cells[c][(k + 2) % 3];
        let start = |(c, k): (usize, usize)| cells[c][k];
        for (i, x) in owners().enumerate() {
            for y in owners().skip(i + 1) {
                if third(x) == third(y) {
                    let mut set = cells[x.0];
                    set.sort_unstable();
                    return Err(mesh_error(format!(
                        "cell {} and cell {} are duplicates: both have the vertices {set:?}",
                        x.0, y.0
                    )));
                }
            }
        }
        if group.len() > 2 {
            let names: Vec<String> = owners().map(|(c, _)| format!("cell {c}")).collect();
            return Err(mesh_error(format!(
                "the edge between vertex {lo} and vertex {hi} is shared by {} cells ({}); an edge may belong to at most two cells",
                group.len(),
                names.join(", ")
            )));
        }
        if group.len() == 2 && start(owner(0)) == start(owner(1)) {
            return Err(mesh_error(format!(
                "cell {} and cell {} overlap: both lie on the same side of their common edge between vertex {lo} and vertex {hi}",
                owner(0).0,
                owner(1).0
            )));
        }
        Ok(())
    }

    /// Sets the markers of the listed boundary edges; the rest keep theirs.
    pub(crate) fn apply_markers(&mut self, markers: &[(usize, usize, u32)]) -> Result<()> {
        let mut set = vec![false; self.boundary_edges.len()];
        for &(a, b, marker) in markers {
            let e = self.find_edge(a, b).ok_or_else(|| {
                mesh_error(format!(
                    "boundary marker ({a}, {b}, {marker}): vertex {a} and vertex {b} are not joined by an edge of the mesh"
                ))
            })?;
            if let (c0, Some(c1)) = self.edge_cells(e) {
                return Err(mesh_error(format!(
                    "boundary marker ({a}, {b}, {marker}) names an interior edge (shared by cell {c0} and cell {c1}), not a boundary edge"
                )));
            }
            let Ok(slot) = self.boundary_edges.binary_search_by_key(&e, |&(e, _)| e) else {
                return Err(mesh_error(format!(
                    "boundary marker ({a}, {b}, {marker}): edge {e} is missing from the boundary table"
                )));
            };
            if set[slot] && self.boundary_edges[slot].1 != marker {
                return Err(mesh_error(format!(
                    "boundary edge between vertex {a} and vertex {b} is given two markers, {} and {marker}",
                    self.boundary_edges[slot].1
                )));
            }
            set[slot] = true;
            self.boundary_edges[slot].1 = marker;
        }
        Ok(())
    }

    /// The global edge joining vertices `a` and `b`, if there is one.
    pub(crate) fn find_edge(&self, a: usize, b: usize) -> Option<usize> {
        let (lo, hi) = (a.min(b), a.max(b));
        if hi >= self.vertices.len() {
            return None;
        }
        let range = self.edge_start[lo] as usize..self.edge_start[lo + 1] as usize;
        self.edges[range.clone()]
            .binary_search_by_key(&hi, |e| e[1])
            .ok()
            .map(|i| range.start + i)
    }

    /// `nx × ny` squares on `[x0, x1] × [y0, y1]`, each split as `diagonal` says.
    ///
    /// Boundary markers: 1 bottom (`y = y0`), 2 right, 3 top, 4 left; the boundary
    /// parts (see [`TriangleMesh::boundary_part_markers`]) are named `bottom`,
    /// `right`, `top` and `left`.
    pub fn rectangle(
        x0: f64,
        x1: f64,
        y0: f64,
        y1: f64,
        nx: usize,
        ny: usize,
        diagonal: Diagonal,
    ) -> Result<Self> {
        if !(x0.is_finite() && x1.is_finite() && y0.is_finite() && y1.is_finite())
            || x0 >= x1
            || y0 >= y1
        {
            return Err(mesh_error(format!(
                "rectangle [{x0}, {x1}] × [{y0}, {y1}] needs finite bounds with x0 < x1 and y0 < y1"
            )));
        }
        if nx == 0 || ny == 0 {
            return Err(mesh_error(format!(
                "rectangle needs at least one square in each direction, got {nx} × {ny}"
            )));
        }
        let id = |i: usize, j: usize| j * (nx + 1) + i;
        let mut vertices = Vec::with_capacity((nx + 1) * (ny + 1));
        for j in 0..=ny {
            let y = lerp(y0, y1, j, ny);
            for i in 0..=nx {
                vertices.push([lerp(x0, x1, i, nx), y]);
            }
        }
        let per_square = if diagonal == Diagonal::Crossed { 4 } else { 2 };
        let mut cells = Vec::with_capacity(per_square * nx * ny);
        for j in 0..ny {
            for i in 0..nx {
                let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                let right = match diagonal {
                    Diagonal::Right => true,
                    Diagonal::Left => false,
                    Diagonal::Alternating => (i + j) % 2 == 0,
                    Diagonal::Crossed => {
                        let e = vertices.len();
                        let (xa, ya) = (vertices[a][0], vertices[a][1]);
                        let (xc, yc) = (vertices[c][0], vertices[c][1]);
                        vertices.push([0.5 * (xa + xc), 0.5 * (ya + yc)]);
                        cells.extend([[a, b, e], [b, c, e], [c, d, e], [d, a, e]]);
                        continue;
                    }
                };
                if right {
                    cells.extend([[a, b, c], [a, c, d]]);
                } else {
                    cells.extend([[a, b, d], [b, c, d]]);
                }
            }
        }
        let mut markers = Vec::with_capacity(2 * (nx + ny));
        for i in 0..nx {
            markers.push((id(i, 0), id(i + 1, 0), 1));
            markers.push((id(i, ny), id(i + 1, ny), 3));
        }
        for j in 0..ny {
            markers.push((id(nx, j), id(nx, j + 1), 2));
            markers.push((id(0, j), id(0, j + 1), 4));
        }
        Self::new(vertices, cells, &markers)?.with_boundary_names(&[
            ("bottom", &[1]),
            ("right", &[2]),
            ("top", &[3]),
            ("left", &[4]),
        ])
    }

    /// A disk: a centre vertex and `rings` rings, ring `k` with `6k` vertices at radius
    /// `k/rings · radius`; neighbouring rings are zipped by angle. Boundary marker 1,
    /// the boundary part named `circle`.
    pub fn disk(centre: [f64; 2], radius: f64, rings: usize) -> Result<Self> {
        if !(centre[0].is_finite() && centre[1].is_finite()) {
            return Err(mesh_error(format!(
                "disk centre ({}, {}) is not finite",
                centre[0], centre[1]
            )));
        }
        if !(radius > 0.0 && radius.is_finite()) {
            return Err(mesh_error(format!(
                "disk radius {radius} must be positive and finite"
            )));
        }
        if rings == 0 {
            return Err(mesh_error("a disk needs at least one ring".into()));
        }
        // ring k ≥ 1 starts at 1 + 6(1 + … + (k − 1)) = 1 + 3k(k − 1)
        let ring_start = |k: usize| if k == 0 { 0 } else { 1 + 3 * k * (k - 1) };
        let mut vertices = Vec::with_capacity(ring_start(rings + 1));
        vertices.push(centre);
        for k in 1..=rings {
            let r = lerp(0.0, radius, k, rings);
            let n = 6 * k;
            for i in 0..n {
                let t = std::f64::consts::TAU * i as f64 / n as f64;
                vertices.push([centre[0] + r * t.cos(), centre[1] + r * t.sin()]);
            }
        }
        let mut cells = Vec::with_capacity(6 * rings * rings);
        for q in 0..6 {
            cells.push([0, 1 + q, 1 + (q + 1) % 6]);
        }
        for k in 2..=rings {
            let (n_in, n_out) = (6 * (k - 1), 6 * k);
            let (s_in, s_out) = (ring_start(k - 1), ring_start(k));
            let inner = |p: usize| s_in + p % n_in;
            let outer = |q: usize| s_out + q % n_out;
            let (mut p, mut q) = (0, 0);
            while p < n_in || q < n_out {
                // advance on the ring whose next vertex comes first by angle
                let step_outer = p == n_in || (q < n_out && (q + 1) * n_in <= (p + 1) * n_out);
                if step_outer {
                    cells.push([inner(p), outer(q), outer(q + 1)]);
                    q += 1;
                } else {
                    cells.push([inner(p), outer(q), inner(p + 1)]);
                    p += 1;
                }
            }
        }
        let (s, n) = (ring_start(rings), 6 * rings);
        let markers: Vec<_> = (0..n).map(|i| (s + i, s + (i + 1) % n, 1)).collect();
        Self::new(vertices, cells, &markers)?.with_boundary_names(&[("circle", &[1])])
    }

    /// The L-shaped domain `(−1, 1)² \ [0, 1] × [−1, 0]`: the `2n × 2n` grid of squares of
    /// side `1/n` on `(−1, 1)²` with `Right` diagonals, less the lower-right quadrant.
    ///
    /// Marker 2 on the re-entrant edges (`{0} × [−1, 0]` and `[0, 1] × {0}`), 1 elsewhere;
    /// the boundary parts are named `reentrant` (marker 2) and `outer` (marker 1).
    pub fn l_shape(n: usize) -> Result<Self> {
        if n == 0 {
            return Err(mesh_error(
                "an L-shape needs at least one square per unit length".into(),
            ));
        }
        let m = 2 * n;
        let removed_square = |i: usize, j: usize| i >= n && j < n;
        let mut id = vec![NONE; (m + 1) * (m + 1)];
        let mut vertices = Vec::new();
        for j in 0..=m {
            for i in 0..=m {
                if !(i > n && j < n) {
                    id[j * (m + 1) + i] = vertices.len();
                    vertices.push([lerp(-1.0, 1.0, i, m), lerp(-1.0, 1.0, j, m)]);
                }
            }
        }
        let at = |i: usize, j: usize| id[j * (m + 1) + i];
        let mut cells = Vec::with_capacity(6 * n * n);
        for j in 0..m {
            for i in 0..m {
                if !removed_square(i, j) {
                    let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                    cells.extend([[a, b, c], [a, c, d]]);
                }
            }
        }
        let mut markers = Vec::with_capacity(8 * n);
        for i in 0..n {
            markers.push((at(i, 0), at(i + 1, 0), 1)); // bottom of the left half
            markers.push((at(n, i), at(n, i + 1), 2)); // re-entrant x = 0
            markers.push((at(n + i, n), at(n + i + 1, n), 2)); // re-entrant y = 0
            markers.push((at(m, n + i), at(m, n + i + 1), 1)); // right of the upper half
        }
        for k in 0..m {
            markers.push((at(0, k), at(0, k + 1), 1)); // left
            markers.push((at(k, m), at(k + 1, m), 1)); // top
        }
        Self::new(vertices, cells, &markers)?
            .with_boundary_names(&[("outer", &[1]), ("reentrant", &[2])])
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.vertices.len()
    }

    /// The mesh with every coordinate multiplied by `factor` (the same cells, edges and
    /// boundary parts): the rounding experiment solves on it ([`crate::problem`]).
    ///
    /// # Errors
    /// [`Error::Mesh`] for a factor that is not positive and finite.
    pub fn scaled(&self, factor: f64) -> Result<Self> {
        if !(factor > 0.0 && factor.is_finite()) {
            return Err(mesh_error(format!(
                "a mesh is scaled by a positive finite factor, not {factor}"
            )));
        }
        let mut scaled = self.clone();
        scaled.vertices = Arc::new(
            self.vertices
                .iter()
                .map(|x| [x[0] * factor, x[1] * factor])
                .collect(),
        );
        Ok(scaled)
    }

    /// Number of cells.
    pub fn cell_count(&self) -> usize {
        self.cells.len()
    }

    /// Number of edges.
    pub fn edge_count(&self) -> usize {
        self.edges.len()
    }

    /// The vertex coordinates.
    pub fn vertices(&self) -> &[[f64; 2]] {
        &self.vertices
    }

    /// The cells' vertex triples, counter-clockwise, refinement edge opposite local vertex 0.
    pub fn cells(&self) -> &[[usize; 3]] {
        &self.cells
    }

    /// The vertices of cell `c`.
    #[inline]
    pub fn cell(&self, c: usize) -> [usize; 3] {
        self.cells[c]
    }

    /// The coordinates `x0, y0, x1, y1, x2, y2` of cell `c`, as the element kernels take them.
    #[inline]
    pub fn cell_coordinates(&self, c: usize) -> [f64; 6] {
        let [a, b, d] = self.cells[c];
        let (p, q, r) = (self.vertices[a], self.vertices[b], self.vertices[d]);
        [p[0], p[1], q[0], q[1], r[0], r[1]]
    }

    /// The length of the longest edge of cell `c`.
    pub fn cell_diameter(&self, c: usize) -> f64 {
        let [a, b, d] = self.cells[c];
        let (p, q, r) = (self.vertices[a], self.vertices[b], self.vertices[d]);
        dist2(p, q).max(dist2(q, r)).max(dist2(r, p)).sqrt()
    }

    /// The area of cell `c`.
    pub fn area(&self, c: usize) -> f64 {
        let [a, b, d] = self.cells[c];
        0.5 * cross(self.vertices[a], self.vertices[b], self.vertices[d])
    }

    /// The largest cell diameter.
    pub fn max_h(&self) -> f64 {
        (0..self.cells.len())
            .map(|c| self.cell_diameter(c))
            .fold(0.0, f64::max)
    }

    /// The smallest cell diameter.
    pub fn min_h(&self) -> f64 {
        (0..self.cells.len())
            .map(|c| self.cell_diameter(c))
            .fold(f64::INFINITY, f64::min)
    }

    /// The global edges, each stored as `[a, b]` with `a < b`.
    pub fn edges(&self) -> &[[usize; 2]] {
        &self.edges
    }

    /// The global edges of cell `c`: local edge `k` joins local vertices `k` and `(k + 1) % 3`.
    #[inline]
    pub fn cell_edges(&self, c: usize) -> [usize; 3] {
        self.cell_edges[c].map(|e| e as usize)
    }

    /// The local index of edge `e` in cell `c` (local edge `k` joins local vertices `k`
    /// and `(k + 1) % 3`), `None` where `e` is not an edge of `c`.
    #[inline]
    pub fn local_edge(&self, c: usize, e: usize) -> Option<usize> {
        self.cell_edges(c).iter().position(|&x| x == e)
    }

    /// The cells of edge `e`: one, or two for an interior edge.
    pub fn edge_cells(&self, e: usize) -> (usize, Option<usize>) {
        let [c0, c1] = self.edge_cells[e];
        (c0 as usize, (c1 != NO_CELL).then_some(c1 as usize))
    }

    /// `(global edge, marker)` for every edge with exactly one cell, sorted by edge.
    pub fn boundary_edges(&self) -> &[(usize, u32)] {
        &self.boundary_edges
    }

    /// The vertices on boundary edges, sorted and unique.
    pub fn boundary_vertices(&self) -> Vec<usize> {
        let flags = self.is_boundary_vertex();
        (0..flags.len()).filter(|&v| flags[v]).collect()
    }

    /// For each vertex, whether it lies on a boundary edge.
    pub fn is_boundary_vertex(&self) -> Vec<bool> {
        let mut flags = vec![false; self.vertices.len()];
        for &(e, _) in &self.boundary_edges {
            let [a, b] = self.edges[e];
            flags[a] = true;
            flags[b] = true;
        }
        flags
    }

    /// The connected pieces of the mesh: for each cell the index of its piece, pieces
    /// numbered in the order of their first cell, and the number of pieces. Cells are
    /// connected through shared edges: two pieces that touch at one vertex are two
    /// pieces, since a point holds nothing in H¹ (a square hinged at a corner
    /// to a clamped one sagged like log h as the mesh was refined).
    pub fn cell_pieces(&self) -> (Vec<usize>, usize) {
        let mut parent: Vec<usize> = (0..self.cells.len()).collect();
        fn root(parent: &mut [usize], mut c: usize) -> usize {
            while parent[c] != c {
                parent[c] = parent[parent[c]];
                c = parent[c];
            }
            c
        }
        for e in 0..self.edges.len() {
            if let (a, Some(b)) = self.edge_cells(e) {
                let (a, b) = (root(&mut parent, a), root(&mut parent, b));
                if a != b {
                    parent[a.max(b)] = a.min(b);
                }
            }
        }
        let mut index = vec![usize::MAX; self.cells.len()];
        let mut count = 0;
        let piece = (0..self.cells.len())
            .map(|c| {
                let r = root(&mut parent, c);
                if index[r] == usize::MAX {
                    index[r] = count;
                    count += 1;
                }
                index[r]
            })
            .collect();
        (piece, count)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pieces_are_joined_through_shared_edges_only() {
        // two unit squares side by side, apart, then touching at one corner
        let square = |x: f64| vec![[x, 0.0], [x + 1.0, 0.0], [x + 1.0, 1.0], [x, 1.0]];
        let cells = |o: usize| [[o, o + 1, o + 2], [o, o + 2, o + 3]];
        let mut vertices = square(0.0);
        vertices.extend(square(2.0));
        let apart: Vec<[usize; 3]> = cells(0).into_iter().chain(cells(4)).collect();
        let mesh = TriangleMesh::new(vertices, apart, &[]).unwrap();
        assert_eq!(mesh.cell_pieces(), (vec![0, 0, 1, 1], 2));
        // the second square hinged at the first's corner (1, 1): still two pieces
        let hinged = vec![
            [0.0, 0.0],
            [1.0, 0.0],
            [1.0, 1.0],
            [0.0, 1.0],
            [2.0, 1.0],
            [2.0, 2.0],
            [1.0, 2.0],
        ];
        let cells = vec![[0, 1, 2], [0, 2, 3], [2, 4, 5], [2, 5, 6]];
        let mesh = TriangleMesh::new(hinged, cells, &[]).unwrap();
        assert_eq!(mesh.cell_pieces(), (vec![0, 0, 1, 1], 2));
        // one square: one piece
        let mesh = TriangleMesh::new(square(0.0), cells_of_square(), &[]).unwrap();
        assert_eq!(mesh.cell_pieces().1, 1);
    }

    fn cells_of_square() -> Vec<[usize; 3]> {
        vec![[0, 1, 2], [0, 2, 3]]
    }

    /// A small deterministic generator (xorshift64*), so the tests need no dependencies.
    struct Rng(u64);

    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
        }
        fn uniform(&mut self) -> f64 {
            (self.next() >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    fn total_area(m: &TriangleMesh) -> f64 {
        (0..m.cell_count()).map(|c| m.area(c)).sum()
    }

    /// V − E + F for the mesh (1 for a simply connected domain).
    fn euler(m: &TriangleMesh) -> i64 {
        m.vertex_count() as i64 - m.edge_count() as i64 + m.cell_count() as i64
    }

    fn angles(m: &TriangleMesh, c: usize) -> [f64; 3] {
        let [a, b, d] = m.cell(c);
        let p = [m.vertices()[a], m.vertices()[b], m.vertices()[d]];
        [0, 1, 2].map(|k| {
            let (o, u, w) = (p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
            let (ux, uy, wx, wy) = (u[0] - o[0], u[1] - o[1], w[0] - o[0], w[1] - o[1]);
            (ux * wy - uy * wx).atan2(ux * wx + uy * wy)
        })
    }

    fn min_angle(m: &TriangleMesh) -> f64 {
        (0..m.cell_count())
            .flat_map(|c| angles(m, c))
            .fold(f64::INFINITY, f64::min)
    }

    fn boundary_length(m: &TriangleMesh, marker: Option<u32>) -> f64 {
        m.boundary_edges()
            .iter()
            .filter(|&&(_, mk)| marker.is_none_or(|x| x == mk))
            .map(|&(e, _)| {
                let [a, b] = m.edges()[e];
                dist2(m.vertices()[a], m.vertices()[b]).sqrt()
            })
            .sum()
    }

    /// Checks, independently of the edge tables, that no vertex lies inside another
    /// cell's edge (a hanging node), that all cells are counter-clockwise, and that the
    /// stored tables agree with the cells.
    fn assert_conforming(m: &TriangleMesh) {
        for c in 0..m.cell_count() {
            assert!(m.area(c) > 0.0, "cell {c} is not counter-clockwise");
            let cell = m.cell(c);
            for (k, &e) in m.cell_edges(c).iter().enumerate() {
                let (a, b) = (cell[k], cell[(k + 1) % 3]);
                assert_eq!(
                    m.edges()[e],
                    [a.min(b), a.max(b)],
                    "cell {c} local edge {k}"
                );
            }
        }
        let mut count = vec![0; m.edge_count()];
        for c in 0..m.cell_count() {
            for e in m.cell_edges(c) {
                count[e] += 1;
            }
        }
        assert!(count.iter().all(|&n| n == 1 || n == 2));
        let boundary: Vec<usize> = (0..count.len()).filter(|&e| count[e] == 1).collect();
        let listed: Vec<usize> = m.boundary_edges().iter().map(|&(e, _)| e).collect();
        assert_eq!(boundary, listed);
        if m.vertex_count() * m.edge_count() <= 20_000_000 {
            for (e, &[a, b]) in m.edges().iter().enumerate() {
                let (p, q) = (m.vertices()[a], m.vertices()[b]);
                let len2 = dist2(p, q);
                for (v, &x) in m.vertices().iter().enumerate() {
                    if v == a || v == b {
                        continue;
                    }
                    let t = ((x[0] - p[0]) * (q[0] - p[0]) + (x[1] - p[1]) * (q[1] - p[1])) / len2;
                    let off = cross(p, q, x).abs() / len2.sqrt();
                    assert!(
                        !(t > 1e-9 && t < 1.0 - 1e-9 && off < 1e-9 * len2.sqrt()),
                        "vertex {v} hangs on edge {e} ({a}, {b})"
                    );
                }
            }
        }
    }

    #[test]
    fn rectangle_counts_areas_and_markers() {
        for diagonal in [
            Diagonal::Right,
            Diagonal::Left,
            Diagonal::Alternating,
            Diagonal::Crossed,
        ] {
            let (nx, ny) = (5, 3);
            let m = TriangleMesh::rectangle(-1.0, 2.0, 0.5, 1.5, nx, ny, diagonal).unwrap();
            let per = if diagonal == Diagonal::Crossed { 4 } else { 2 };
            assert_eq!(m.cell_count(), per * nx * ny, "{diagonal:?}");
            let extra = if diagonal == Diagonal::Crossed {
                nx * ny
            } else {
                0
            };
            assert_eq!(m.vertex_count(), (nx + 1) * (ny + 1) + extra);
            assert!((total_area(&m) - 3.0).abs() < 1e-13, "{diagonal:?}");
            assert!((0..m.cell_count()).all(|c| m.area(c) > 0.0));
            assert_eq!(euler(&m), 1, "{diagonal:?}");
            assert_eq!(m.boundary_edges().len(), 2 * (nx + ny));
            assert_conforming(&m);
            for &(e, marker) in m.boundary_edges() {
                let [a, b] = m.edges()[e];
                let (p, q) = (m.vertices()[a], m.vertices()[b]);
                let expected = if p[1] == 0.5 && q[1] == 0.5 {
                    1
                } else if p[0] == 2.0 && q[0] == 2.0 {
                    2
                } else if p[1] == 1.5 && q[1] == 1.5 {
                    3
                } else if p[0] == -1.0 && q[0] == -1.0 {
                    4
                } else {
                    panic!("edge {e} is not on the rectangle's boundary")
                };
                assert_eq!(marker, expected, "edge {e} of {diagonal:?}");
            }
            for (marker, length) in [(1, 3.0), (2, 1.0), (3, 3.0), (4, 1.0)] {
                assert!((boundary_length(&m, Some(marker)) - length).abs() < 1e-13);
            }
            assert_eq!(m.boundary_vertices().len(), 2 * (nx + ny));
        }
        assert!(TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 0, 2, Diagonal::Right).is_err());
        assert!(TriangleMesh::rectangle(1.0, 0.0, 0.0, 1.0, 2, 2, Diagonal::Right).is_err());
        assert!(TriangleMesh::rectangle(0.0, f64::NAN, 0.0, 1.0, 2, 2, Diagonal::Right).is_err());
    }

    #[test]
    fn rectangle_diagonal_directions() {
        // slope sign of the diagonal edges (edges neither horizontal nor vertical)
        let slopes = |m: &TriangleMesh| -> Vec<([f64; 2], f64)> {
            m.edges()
                .iter()
                .filter_map(|&[a, b]| {
                    let (p, q) = (m.vertices()[a], m.vertices()[b]);
                    let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
                    (dx != 0.0 && dy != 0.0)
                        .then(|| ([0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])], dy / dx))
                })
                .collect()
        };
        let (nx, ny) = (4, 3);
        let right = TriangleMesh::rectangle(0.0, 4.0, 0.0, 3.0, nx, ny, Diagonal::Right).unwrap();
        let s = slopes(&right);
        assert_eq!(s.len(), nx * ny);
        assert!(s.iter().all(|&(_, k)| (k - 1.0).abs() < 1e-14));
        let left = TriangleMesh::rectangle(0.0, 4.0, 0.0, 3.0, nx, ny, Diagonal::Left).unwrap();
        let s = slopes(&left);
        assert_eq!(s.len(), nx * ny);
        assert!(s.iter().all(|&(_, k)| (k + 1.0).abs() < 1e-14));
        let alt =
            TriangleMesh::rectangle(0.0, 4.0, 0.0, 3.0, nx, ny, Diagonal::Alternating).unwrap();
        let s = slopes(&alt);
        assert_eq!(s.len(), nx * ny);
        for (mid, k) in s {
            // square (i, j) holds the diagonal through its centre
            let (i, j) = (mid[0].floor() as usize, mid[1].floor() as usize);
            let expected = if (i + j) % 2 == 0 { 1.0 } else { -1.0 };
            assert!((k - expected).abs() < 1e-14, "square ({i}, {j})");
        }
        let crossed =
            TriangleMesh::rectangle(0.0, 4.0, 0.0, 3.0, nx, ny, Diagonal::Crossed).unwrap();
        let s = slopes(&crossed);
        assert_eq!(s.len(), 4 * nx * ny);
        assert_eq!(s.iter().filter(|&&(_, k)| k > 0.0).count(), 2 * nx * ny);
    }

    #[test]
    fn refinement_edge_is_the_longest() {
        let m = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 3, 3, Diagonal::Crossed).unwrap();
        for c in 0..m.cell_count() {
            let [a, b, d] = m.cell(c);
            let v = m.vertices();
            let refinement = dist2(v[b], v[d]);
            assert!(refinement >= dist2(v[a], v[b]) && refinement >= dist2(v[d], v[a]));
        }
    }

    #[test]
    fn disk_area_euler_and_markers() {
        let mut previous_error = f64::INFINITY;
        for rings in [1, 2, 4, 8, 16] {
            let r = 2.0;
            let m = TriangleMesh::disk([1.0, -1.0], r, rings).unwrap();
            let n = 6 * rings;
            assert_eq!(m.vertex_count(), 1 + 3 * rings * (rings + 1));
            assert_eq!(m.cell_count(), 6 * rings * rings);
            // the mesh is the inscribed regular n-gon
            let polygon = 0.5 * n as f64 * r * r * (std::f64::consts::TAU / n as f64).sin();
            let area = total_area(&m);
            assert!((area - polygon).abs() < 1e-12 * polygon, "{rings} rings");
            let error = std::f64::consts::PI * r * r - area;
            assert!(error > 0.0 && error < previous_error);
            previous_error = error;
            assert_eq!(euler(&m), 1);
            assert_eq!(m.boundary_edges().len(), n);
            assert!(m.boundary_edges().iter().all(|&(_, mk)| mk == 1));
            for v in m.boundary_vertices() {
                let p = m.vertices()[v];
                assert!(((p[0] - 1.0).hypot(p[1] + 1.0) - r).abs() < 1e-13);
            }
            assert_conforming(&m);
            // shape-regular: the smallest angle does not shrink as the rings grow
            assert!(min_angle(&m) > 25f64.to_radians(), "{rings} rings");
        }
        assert!(TriangleMesh::disk([0.0, 0.0], 0.0, 3).is_err());
        assert!(TriangleMesh::disk([0.0, 0.0], 1.0, 0).is_err());
    }

    #[test]
    fn l_shape_area_euler_and_markers() {
        for n in [1, 2, 5] {
            let m = TriangleMesh::l_shape(n).unwrap();
            assert_eq!(m.cell_count(), 6 * n * n);
            assert_eq!(m.vertex_count(), 3 * n * n + 4 * n + 1);
            assert!((total_area(&m) - 3.0).abs() < 1e-13);
            assert_eq!(euler(&m), 1);
            assert_eq!(m.boundary_edges().len(), 8 * n);
            assert!((boundary_length(&m, Some(2)) - 2.0).abs() < 1e-13);
            assert!((boundary_length(&m, Some(1)) - 6.0).abs() < 1e-13);
            for &(e, marker) in m.boundary_edges() {
                let [a, b] = m.edges()[e];
                let (p, q) = (m.vertices()[a], m.vertices()[b]);
                let reentrant = (p[0] == 0.0 && q[0] == 0.0 && p[1] <= 0.0 && q[1] <= 0.0)
                    || (p[1] == 0.0 && q[1] == 0.0 && p[0] >= 0.0 && q[0] >= 0.0);
                assert_eq!(marker, if reentrant { 2 } else { 1 }, "edge {e}");
            }
            // no vertex in the removed quadrant's interior
            assert!(m.vertices().iter().all(|p| !(p[0] > 0.0 && p[1] < 0.0)));
            assert_conforming(&m);
        }
        assert!(TriangleMesh::l_shape(0).is_err());
    }

    fn message(result: Result<TriangleMesh>) -> String {
        match result {
            Ok(_) => panic!("the mesh was accepted"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn coordinates_whose_squares_overflow_are_refused_by_vertex() {
        let square = |s: f64| vec![[0.0, 0.0], [s, 0.0], [s, s], [0.0, s]];
        let cells = vec![[0, 1, 2], [0, 2, 3]];
        let e = message(TriangleMesh::new(square(1e300), cells.clone(), &[]));
        assert!(e.contains("vertex 1") && e.contains("rescale"), "{e}");
        assert!(TriangleMesh::new(square(1e40), cells, &[]).is_ok());
    }

    fn square() -> Vec<[f64; 2]> {
        vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
    }

    #[test]
    fn validation_names_the_element() {
        let ok = TriangleMesh::new(square(), vec![[0, 1, 2], [0, 2, 3]], &[(0, 1, 7)]).unwrap();
        assert_eq!(ok.cell_count(), 2);

        let e = message(TriangleMesh::new(square(), vec![], &[]));
        assert!(e.contains("at least one cell"), "{e}");

        let mut v = square();
        v[2] = [f64::NAN, 1.0];
        let e = message(TriangleMesh::new(v, vec![[0, 1, 2], [0, 2, 3]], &[]));
        assert!(e.contains("vertex 2") && e.contains("non-finite"), "{e}");

        let e = message(TriangleMesh::new(square(), vec![[0, 1, 2], [0, 2, 4]], &[]));
        assert!(e.contains("cell 1") && e.contains("vertex 4"), "{e}");

        let e = message(TriangleMesh::new(square(), vec![[0, 1, 2], [0, 3, 3]], &[]));
        assert!(
            e.contains("cell 1") && e.contains("repeats vertex 3"),
            "{e}"
        );

        let mut v = square();
        v.push([0.5, 0.5]);
        let e = message(TriangleMesh::new(
            v.clone(),
            vec![[0, 1, 2], [0, 2, 3], [0, 4, 2]],
            &[],
        ));
        assert!(e.contains("cell 2") && e.contains("degenerate"), "{e}");

        let e = message(TriangleMesh::new(square(), vec![[0, 1, 2], [0, 3, 2]], &[]));
        assert!(e.contains("cell 1") && e.contains("inverted"), "{e}");

        let e = message(TriangleMesh::new(
            square(),
            vec![[0, 1, 2], [0, 2, 3], [2, 3, 0]],
            &[],
        ));
        assert!(
            e.contains("cell 1") && e.contains("cell 2") && e.contains("duplicates"),
            "{e}"
        );

        // a third cell on the diagonal 0–2 (it overlaps cell 0, but the count is reported)
        let v3 = vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [2.0, 0.5]];
        let e = message(TriangleMesh::new(
            v3,
            vec![[0, 1, 2], [0, 2, 3], [0, 4, 2]],
            &[],
        ));
        assert!(
            e.contains("vertex 0 and vertex 2")
                && e.contains("3 cells")
                && e.contains("cell 0")
                && e.contains("cell 1")
                && e.contains("cell 2"),
            "{e}"
        );

        let e = message(TriangleMesh::new(
            vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.5, 2.0]],
            vec![[0, 1, 2], [0, 1, 3]],
            &[],
        ));
        assert!(
            e.contains("cell 0") && e.contains("cell 1") && e.contains("overlap"),
            "{e}"
        );

        let mut v = square();
        v.push([5.0, 5.0]);
        let e = message(TriangleMesh::new(v, vec![[0, 1, 2], [0, 2, 3]], &[]));
        assert!(e.contains("vertex 4") && e.contains("no cell"), "{e}");

        let e = message(TriangleMesh::new(
            square(),
            vec![[0, 1, 2], [0, 2, 3]],
            &[(0, 2, 1)],
        ));
        assert!(e.contains("(0, 2, 1)") && e.contains("interior"), "{e}");
        let e = message(TriangleMesh::new(
            square(),
            vec![[0, 1, 2], [0, 2, 3]],
            &[(1, 3, 1)],
        ));
        assert!(e.contains("(1, 3, 1)") && e.contains("not joined"), "{e}");
        let e = message(TriangleMesh::new(
            square(),
            vec![[0, 1, 2], [0, 2, 3]],
            &[(0, 1, 1), (1, 0, 2)],
        ));
        assert!(e.contains("two markers"), "{e}");
    }

    #[test]
    fn new_keeps_markers_and_orientation() {
        let m = TriangleMesh::new(
            square(),
            vec![[1, 2, 0], [2, 3, 0]],
            &[(1, 0, 5), (2, 3, 6)],
        )
        .unwrap();
        let marker = |a: usize, b: usize| {
            let e = m.find_edge(a, b).unwrap();
            m.boundary_edges().iter().find(|&&(x, _)| x == e).unwrap().1
        };
        assert_eq!(marker(0, 1), 5);
        assert_eq!(marker(3, 2), 6);
        assert_eq!(marker(1, 2), 0);
        assert_eq!(m.boundary_edges().len(), 4);
        assert_eq!(m.boundary_vertices(), vec![0, 1, 2, 3]);
        // the diagonal 0–2 is each cell's refinement edge
        for c in 0..2 {
            let [_, b, d] = m.cell(c);
            assert_eq!([b.min(d), b.max(d)], [0, 2]);
        }
        let (c0, c1) = m.edge_cells(m.find_edge(0, 2).unwrap());
        assert_eq!((c0, c1), (0, Some(1)));
    }

    /// Conformity, area, parents and markers of `fine = coarse.refine(..)`.
    fn assert_refinement(coarse: &TriangleMesh, fine: &TriangleMesh, parents: &[usize]) {
        assert_conforming(fine);
        assert_eq!(euler(fine), euler(coarse));
        assert!((total_area(fine) - total_area(coarse)).abs() < 1e-12 * total_area(coarse));
        assert_eq!(parents.len(), fine.cell_count());
        let mut child_area = vec![0.0; coarse.cell_count()];
        for (c, &p) in parents.iter().enumerate() {
            child_area[p] += fine.area(c);
            // the child's centroid lies in its parent
            let x = fine.cell_coordinates(c);
            let g = [(x[0] + x[2] + x[4]) / 3.0, (x[1] + x[3] + x[5]) / 3.0];
            let [a, b, d] = coarse.cell(p);
            let v = coarse.vertices();
            assert!(
                cross(v[a], v[b], g) > 0.0
                    && cross(v[b], v[d], g) > 0.0
                    && cross(v[d], v[a], g) > 0.0
            );
        }
        for (p, &area) in child_area.iter().enumerate() {
            assert!(
                (area - coarse.area(p)).abs() < 1e-12 * coarse.area(p),
                "parent {p}"
            );
        }
        // boundary edges only split: same length per marker, at least as many edges
        assert!(fine.boundary_edges().len() >= coarse.boundary_edges().len());
        for marker in 0..5 {
            let (l0, l1) = (
                boundary_length(coarse, Some(marker)),
                boundary_length(fine, Some(marker)),
            );
            assert!((l0 - l1).abs() < 1e-12 * (1.0 + l0), "marker {marker}");
        }
    }

    #[test]
    fn refining_one_cell_is_conforming() {
        let m = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 4, 4, Diagonal::Right).unwrap();
        let (fine, parents) = m.refine(&[5]).unwrap();
        assert_refinement(&m, &fine, &parents);
        assert!(fine.cell_count() > m.cell_count());
        assert_eq!(parents.iter().filter(|&&p| p == 5).count(), 2);
        // refining again at the same place forces closure across neighbours
        let children: Vec<usize> = (0..fine.cell_count())
            .filter(|&c| parents[c] == 5)
            .collect();
        let (finer, parents2) = fine.refine(&children).unwrap();
        assert_refinement(&fine, &finer, &parents2);
        let (again, parents3) = finer.refine(&[0, 0, 3]).unwrap();
        assert_refinement(&finer, &again, &parents3);
        assert!(m.refine(&[32]).unwrap_err().to_string().contains("cell 32"));
        let (same, identity) = m.refine(&[]).unwrap();
        assert_eq!(same.cells(), m.cells());
        assert_eq!(identity, (0..m.cell_count()).collect::<Vec<_>>());
    }

    #[test]
    fn random_refinement_stays_conforming_and_shape_regular() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let starts = [
            TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 3, 3, Diagonal::Right).unwrap(),
            TriangleMesh::rectangle(0.0, 2.0, 0.0, 1.0, 3, 2, Diagonal::Crossed).unwrap(),
            TriangleMesh::disk([0.0, 0.0], 1.0, 3).unwrap(),
            TriangleMesh::l_shape(2).unwrap(),
        ];
        for (s, start) in starts.iter().enumerate() {
            let initial = min_angle(start);
            let mut m = start.clone();
            for round in 0..10 {
                let marked: Vec<usize> = (0..m.cell_count())
                    .filter(|_| rng.uniform() < 0.1)
                    .collect();
                let (fine, parents) = m.refine(&marked).unwrap();
                assert_refinement(&m, &fine, &parents);
                for &c in &marked {
                    assert!(
                        parents.iter().filter(|&&p| p == c).count() >= 2,
                        "mesh {s} round {round}"
                    );
                }
                m = fine;
            }
            assert!(m.cell_count() > 2 * start.cell_count());
            assert!(min_angle(&m) >= 0.5 * initial - 1e-12, "mesh {s}");
            if s == 0 {
                // bisecting right isosceles triangles at the hypotenuse keeps them so
                for c in 0..m.cell_count() {
                    let mut a = angles(&m, c);
                    a.sort_by(f64::total_cmp);
                    let quarter = std::f64::consts::FRAC_PI_4;
                    assert!((a[0] - quarter).abs() < 1e-9 && (a[2] - 2.0 * quarter).abs() < 1e-9);
                }
            }
        }
    }

    #[test]
    fn uniform_refinement_quadruples_and_halves() {
        let m = TriangleMesh::rectangle(0.0, 1.0, 0.0, 2.0, 3, 5, Diagonal::Right).unwrap();
        let fine = m.refine_uniformly();
        assert_eq!(fine.cell_count(), 4 * m.cell_count());
        assert!((fine.max_h() - 0.5 * m.max_h()).abs() < 1e-14);
        assert!((fine.min_h() - 0.5 * m.min_h()).abs() < 1e-14);
        assert_eq!(fine.vertex_count(), m.vertex_count() + m.edge_count());
        let all: Vec<usize> = (0..m.cell_count()).collect();
        let (_, parents) = m.refine(&all).unwrap();
        assert_refinement(&m, &fine, &{
            // refine_uniformly keeps the parent order of bisect: four children per cell
            let p: Vec<usize> = (0..m.cell_count()).flat_map(|c| [c; 4]).collect();
            p
        });
        assert_eq!(parents.len(), 2 * m.cell_count());
        let finer = fine.refine_uniformly();
        assert!((finer.max_h() - 0.25 * m.max_h()).abs() < 1e-14);
        for marker in 1..=4 {
            assert!(
                (boundary_length(&finer, Some(marker)) - boundary_length(&m, Some(marker))).abs()
                    < 1e-13
            );
        }
        let d = TriangleMesh::disk([0.0, 0.0], 1.0, 4).unwrap();
        let fd = d.refine_uniformly();
        assert_refinement(
            &d,
            &fd,
            &(0..d.cell_count()).flat_map(|c| [c; 4]).collect::<Vec<_>>(),
        );
    }

    #[test]
    fn locator_finds_points_and_rejects_outside() {
        let mut rng = Rng(12345);
        let meshes = [
            TriangleMesh::rectangle(-1.0, 3.0, 0.0, 1.0, 20, 7, Diagonal::Alternating).unwrap(),
            TriangleMesh::l_shape(4).unwrap(),
            TriangleMesh::disk([0.5, 0.5], 2.0, 6).unwrap(),
        ];
        // refined locally, so cells of very different sizes share buckets
        let graded = {
            let mut m = meshes[1].clone();
            for _ in 0..8 {
                let near: Vec<usize> = (0..m.cell_count())
                    .filter(|&c| {
                        let x = m.cell_coordinates(c);
                        x[0].abs() + x[1].abs() < 0.3
                    })
                    .collect();
                m = m.refine(&near).unwrap().0;
            }
            m
        };
        for (k, m) in meshes.iter().chain([&graded]).enumerate() {
            let locator = PointLocator::new(m);
            for _ in 0..2000 {
                // a random point of a random cell, so it is inside the domain
                let c = (rng.next() % m.cell_count() as u64) as usize;
                let (mut s, mut t) = (rng.uniform(), rng.uniform());
                if s + t > 1.0 {
                    (s, t) = (1.0 - s, 1.0 - t);
                }
                let x = m.cell_coordinates(c);
                let p = [
                    x[0] + s * (x[2] - x[0]) + t * (x[4] - x[0]),
                    x[1] + s * (x[3] - x[1]) + t * (x[5] - x[1]),
                ];
                // with no hint, a hint at the right cell, at a random one, or out of range
                let hint = match rng.next() % 4 {
                    0 => None,
                    1 => Some(c),
                    2 => Some((rng.next() % m.cell_count() as u64) as usize),
                    _ => Some(m.cell_count() + 3),
                };
                let (found, lambda) = locator
                    .locate_near(p, hint)
                    .expect("a point inside the mesh");
                let y = m.cell_coordinates(found);
                let q = [
                    lambda[0] * y[0] + lambda[1] * y[2] + lambda[2] * y[4],
                    lambda[0] * y[1] + lambda[1] * y[3] + lambda[2] * y[5],
                ];
                assert!(dist2(p, q).sqrt() < 1e-12, "mesh {k}");
                assert!(lambda.iter().all(|&l| l >= -1e-12));
                assert!((lambda.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            }
            for v in 0..m.vertex_count() {
                assert!(
                    locator.locate(m.vertices()[v]).is_some(),
                    "mesh {k} vertex {v}"
                );
            }
        }
        let locator = PointLocator::new(&meshes[1]);
        for p in [
            [0.5, -0.5],
            [0.01, -0.01],
            [1.5, 0.0],
            [-1.0 - 1e-6, 0.0],
            [f64::NAN, 0.0],
        ] {
            assert!(locator.locate(p).is_none(), "{p:?}");
        }
        assert!(locator.locate([0.0, -1.0]).is_some());
        let disk = PointLocator::new(&meshes[2]);
        // just outside the inscribed polygon's edge midpoint at angle 0 + half a step
        let r = 2.0 * (std::f64::consts::PI / 36.0).cos();
        let a = std::f64::consts::PI / 36.0;
        assert!(disk
            .locate([0.5 + 1.0001 * r * a.cos(), 0.5 + 1.0001 * r * a.sin()])
            .is_none());
        assert!(disk
            .locate([0.5 + 0.9999 * r * a.cos(), 0.5 + 0.9999 * r * a.sin()])
            .is_some());
    }

    /// Outside the mesh, `locate_or_nearest` finds a cell at the least distance (checked
    /// against every cell) and coordinates that reproduce the point; inside, it agrees
    /// with `locate`.
    #[test]
    fn nearest_cell_is_the_closest_of_all() {
        let disk = TriangleMesh::disk([0.5, 0.5], 2.0, 4).unwrap();
        let locator = PointLocator::new(&disk);
        let mut rng = Rng(7);
        for _ in 0..300 {
            let angle = rng.uniform() * std::f64::consts::TAU;
            let radius = 2.0 * (0.5 + rng.uniform());
            let p = [0.5 + radius * angle.cos(), 0.5 + radius * angle.sin()];
            let (c, lambda) = locator.locate_or_nearest(p, None).unwrap();
            let brute = (0..disk.cell_count())
                .map(|k| locator.distance(k, p))
                .fold(f64::INFINITY, f64::min);
            assert!((locator.distance(c, p) - brute).abs() <= 1e-12, "{p:?}");
            let y = disk.cell_coordinates(c);
            let q = [
                lambda[0] * y[0] + lambda[1] * y[2] + lambda[2] * y[4],
                lambda[0] * y[1] + lambda[1] * y[3] + lambda[2] * y[5],
            ];
            assert!(dist2(p, q).sqrt() < 1e-12, "{p:?}");
            if let Some((inside, _)) = locator.locate(p) {
                assert!(locator.contains(inside, p) && locator.contains(c, p));
            }
        }
        assert!(locator.locate_or_nearest([f64::NAN, 0.0], None).is_none());
    }

    /// The 32-bit index tables: the largest index kept is `u32::MAX − 1` (`u32::MAX`
    /// marks "no cell"); beyond it the mesh is refused by name, not truncated.
    #[test]
    fn index32_refuses_counts_beyond_u32() {
        let largest = u32::MAX as usize - 1;
        assert_eq!(index32(0, "x").unwrap(), 0);
        assert_eq!(index32(largest, "x").unwrap(), u32::MAX - 1);
        for too_large in [largest + 1, 1 << 40, usize::MAX] {
            let Err(Error::Mesh(message)) = index32(too_large, "the vertex count") else {
                panic!("{too_large} accepted as a 32-bit index");
            };
            assert!(
                message.contains("the vertex count") && message.contains(&too_large.to_string()),
                "{message}"
            );
        }
    }

    /// The edge tables stay consistent with `u32` storage across refinements, and the
    /// counts follow Euler's formula (independent of the tables' construction).
    #[test]
    fn edge_tables_of_refined_meshes_follow_euler() {
        let mut m = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 3, 2, Diagonal::Left).unwrap();
        for _ in 0..3 {
            m = m.refine_uniformly();
            assert_conforming(&m);
            assert_eq!(euler(&m), 1);
            // every cell has three edges; an interior edge is counted by two cells
            let boundary: usize = m.boundary_edges().len();
            assert_eq!(3 * m.cell_count(), 2 * m.edge_count() - boundary);
            for e in 0..m.edge_count() {
                let [a, b] = m.edges()[e];
                assert_eq!(m.find_edge(b, a), Some(e));
                let (c0, c1) = m.edge_cells(e);
                assert!(m.cell_edges(c0).contains(&e));
                assert_eq!(
                    c1.is_none(),
                    m.boundary_edges()
                        .binary_search_by_key(&e, |&(e, _)| e)
                        .is_ok()
                );
            }
        }
    }

    /// Timing of the spec's large case; run with
    /// `cargo test --release -p fem-runtime --lib -- --ignored large_rectangle --nocapture`.
    #[test]
    #[ignore]
    fn large_rectangle_timing() {
        let t = std::time::Instant::now();
        let m = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 1000, 1000, Diagonal::Right).unwrap();
        let build = t.elapsed();
        let t = std::time::Instant::now();
        let fine = m.refine_uniformly();
        let refine = t.elapsed();
        let t = std::time::Instant::now();
        let locator = PointLocator::new(&fine);
        let locate = t.elapsed();
        assert!(locator.locate([0.3, 0.7]).is_some());
        eprintln!(
            "rectangle 1000×1000 ({} cells): build {build:?}; refine_uniformly ({} cells) {refine:?}; locator {locate:?}",
            m.cell_count(),
            fine.cell_count()
        );
    }
}
