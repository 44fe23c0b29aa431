//! Point location: the cell containing a point and its barycentric coordinates, through
//! a grid of buckets over the mesh's bounding box.

use super::*;

/// Finds the cell containing a point, through a grid of buckets over the mesh's bounding box.
#[derive(Clone, Debug)]
pub struct PointLocator<'a> {
    mesh: &'a TriangleMesh,
    origin: [f64; 2],
    /// Buckets per unit length in x and y.
    scale: [f64; 2],
    nx: usize,
    ny: usize,
    /// The cells whose (slightly widened) bounding boxes meet bucket `b` are
    /// `items[start[b]..start[b + 1]]`.
    start: Vec<usize>,
    items: Vec<usize>,
    /// Absolute distance by which a point may lie outside a cell and still be in it.
    slack: f64,
    upper: [f64; 2],
}

impl<'a> PointLocator<'a> {
    /// Buckets the cells of `mesh` (about one bucket per cell, linear time).
    pub fn new(mesh: &'a TriangleMesh) -> Self {
        let mut lower = [f64::INFINITY; 2];
        let mut upper = [f64::NEG_INFINITY; 2];
        for v in mesh.vertices.iter() {
            for d in 0..2 {
                lower[d] = lower[d].min(v[d]);
                upper[d] = upper[d].max(v[d]);
            }
        }
        let size = [upper[0] - lower[0], upper[1] - lower[1]];
        let magnitude = lower
            .iter()
            .chain(&upper)
            .map(|x| x.abs())
            .fold(size[0].max(size[1]), f64::max);
        let slack = 1e-12 * magnitude;
        // about one bucket per cell, square-ish buckets
        let n = mesh.cells.len().max(1) as f64;
        let aspect = size[0] / size[1];
        // capped so that a very elongated mesh does not get more buckets than cells
        let cap = 4 * mesh.cells.len() + 1;
        let nx = ((n * aspect).sqrt().ceil() as usize).clamp(1, cap);
        let ny = ((n / aspect).sqrt().ceil() as usize).clamp(1, cap / nx + 1);
        let scale = [nx as f64 / size[0], ny as f64 / size[1]];
        let mut locator = Self {
            mesh,
            origin: lower,
            scale,
            nx,
            ny,
            start: vec![0; nx * ny + 1],
            items: Vec::new(),
            slack,
            upper,
        };
        let ranges: Vec<[usize; 4]> = (0..mesh.cells.len())
            .map(|c| {
                let [a, b, d] = mesh.cells[c];
                let p = [mesh.vertices[a], mesh.vertices[b], mesh.vertices[d]];
                let lo = [0, 1].map(|k| p[0][k].min(p[1][k]).min(p[2][k]) - slack);
                let hi = [0, 1].map(|k| p[0][k].max(p[1][k]).max(p[2][k]) + slack);
                let (i0, j0) = locator.bucket(lo);
                let (i1, j1) = locator.bucket(hi);
                [i0, i1, j0, j1]
            })
            .collect();
        for &[i0, i1, j0, j1] in &ranges {
            for j in j0..=j1 {
                for i in i0..=i1 {
                    locator.start[j * nx + i + 1] += 1;
                }
            }
        }
        for b in 0..nx * ny {
            locator.start[b + 1] += locator.start[b];
        }
        let mut fill = locator.start.clone();
        locator.items = vec![0; locator.start[nx * ny]];
        for (c, &[i0, i1, j0, j1]) in ranges.iter().enumerate() {
            for j in j0..=j1 {
                for i in i0..=i1 {
                    let b = j * nx + i;
                    locator.items[fill[b]] = c;
                    fill[b] += 1;
                }
            }
        }
        locator
    }

    /// The bucket of a point, clamped to the grid.
    pub(super) fn bucket(&self, p: [f64; 2]) -> (usize, usize) {
        let i = ((p[0] - self.origin[0]) * self.scale[0]).floor();
        let j = ((p[1] - self.origin[1]) * self.scale[1]).floor();
        // `as usize` saturates negatives to 0
        ((i as usize).min(self.nx - 1), (j as usize).min(self.ny - 1))
    }

    /// [`PointLocator::locate`], trying cell `hint` first: points visited in mesh order
    /// (a finer mesh's nodes) mostly fall in the cell of the point before.
    pub fn locate_near(&self, p: [f64; 2], hint: Option<usize>) -> Option<(usize, [f64; 3])> {
        if let Some(c) = hint.filter(|&c| c < self.mesh.cells.len()) {
            let (v, w) = self.sub_areas(c, p);
            if w.iter().all(|&w| w >= 0.0) {
                let twice_area = cross(v[0], v[1], v[2]);
                return Some((c, w.map(|x| x / twice_area)));
            }
        }
        self.locate(p)
    }

    /// [`PointLocator::locate_near`], or else the cell nearest to `p` with `p`'s
    /// barycentric coordinates in it (some negative): the point at which a field on this
    /// mesh is continued by its nearest cell's polynomial, as a finer mesh's boundary
    /// nodes lying on a curve the coarse chords cut need. `None` only for a non-finite
    /// point or a mesh without cells.
    pub fn locate_or_nearest(&self, p: [f64; 2], hint: Option<usize>) -> Option<(usize, [f64; 3])> {
        if let Some(found) = self.locate_near(p, hint) {
            return Some(found);
        }
        let c = self.nearest(p)?;
        let (v, w) = self.sub_areas(c, p);
        let twice_area = cross(v[0], v[1], v[2]);
        Some((c, w.map(|x| x / twice_area)))
    }

    /// The cell at the least distance from `p`, searching rings of buckets outward from
    /// the bucket of `p` clamped to the grid. Clamping only brings a point closer to every
    /// point of the grid, so ring `r` lies at least `(r − 1)·w` from `p` (`w` the smaller
    /// bucket side) and the search stops once that passes the best distance found.
    fn nearest(&self, p: [f64; 2]) -> Option<usize> {
        if !(p[0].is_finite() && p[1].is_finite()) || self.mesh.cells.is_empty() {
            return None;
        }
        let (i0, j0) = self.bucket(p);
        let width = (1.0 / self.scale[0]).min(1.0 / self.scale[1]);
        let mut best: Option<(f64, usize)> = None;
        let rings = self.nx.max(self.ny);
        for r in 0..=rings {
            if let Some((d, _)) = best {
                if (r as f64 - 1.0) * width > d {
                    break;
                }
            }
            let (i_lo, i_hi) = (i0.saturating_sub(r), (i0 + r).min(self.nx - 1));
            let (j_lo, j_hi) = (j0.saturating_sub(r), (j0 + r).min(self.ny - 1));
            for j in j_lo..=j_hi {
                for i in i_lo..=i_hi {
                    // the ring only: buckets at Chebyshev distance exactly r
                    if i.abs_diff(i0).max(j.abs_diff(j0)) != r {
                        continue;
                    }
                    let b = j * self.nx + i;
                    for &c in &self.items[self.start[b]..self.start[b + 1]] {
                        let d = self.distance(c, p);
                        if best.is_none_or(|(e, _)| d < e) {
                            best = Some((d, c));
                        }
                    }
                }
            }
        }
        best.map(|(_, c)| c)
    }

    /// The distance from `p` to cell `c` (0 inside).
    pub(super) fn distance(&self, c: usize, p: [f64; 2]) -> f64 {
        let (v, w) = self.sub_areas(c, p);
        if w.iter().all(|&w| w >= 0.0) {
            return 0.0;
        }
        (0..3)
            .map(|k| segment_distance(p, v[k], v[(k + 1) % 3]))
            .fold(f64::INFINITY, f64::min)
    }

    /// Whether `p` lies in cell `c` (on its boundary included), by the signs of the
    /// sub-triangle areas: the test [`PointLocator::locate_near`] makes of its hint.
    #[inline]
    pub fn contains(&self, c: usize, p: [f64; 2]) -> bool {
        c < self.mesh.cells.len() && self.sub_areas(c, p).1.iter().all(|&w| w >= 0.0)
    }

    /// Cell `c`'s vertices and `w[k]`, twice the signed area of the sub-triangle of `p`
    /// opposite vertex `k` (all ≥ 0 inside).
    pub(super) fn sub_areas(&self, c: usize, p: [f64; 2]) -> ([[f64; 2]; 3], [f64; 3]) {
        let v = self.mesh.cells[c].map(|a| self.mesh.vertices[a]);
        let w = [
            cross(p, v[1], v[2]),
            cross(v[0], p, v[2]),
            cross(v[0], v[1], p),
        ];
        (v, w)
    }

    /// A cell containing `p` (up to about 1e-12 of the mesh's extent) and `p`'s barycentric
    /// coordinates in it; `None` outside the mesh.
    pub fn locate(&self, p: [f64; 2]) -> Option<(usize, [f64; 3])> {
        if !(p[0].is_finite() && p[1].is_finite()) {
            return None;
        }
        let s = self.slack;
        if p[0] < self.origin[0] - s
            || p[1] < self.origin[1] - s
            || p[0] > self.upper[0] + s
            || p[1] > self.upper[1] + s
        {
            return None;
        }
        let (i, j) = self.bucket(p);
        let b = j * self.nx + i;
        let mut best: Option<(f64, usize, [f64; 3])> = None;
        for &c in &self.items[self.start[b]..self.start[b + 1]] {
            let (v, w) = self.sub_areas(c, p);
            let twice_area = cross(v[0], v[1], v[2]);
            if w.iter().all(|&w| w >= 0.0) {
                // inside (the common case, decided before any square root)
                return Some((c, w.map(|x| x / twice_area)));
            }
            // distance outside edge k is −w[k] / |edge k|; compare without the division
            let inside = (0..3)
                .all(|k| w[k] >= 0.0 || -w[k] <= s * dist2(v[(k + 1) % 3], v[(k + 2) % 3]).sqrt());
            if !inside {
                continue;
            }
            let lambda = w.map(|x| x / twice_area);
            let worst = lambda[0].min(lambda[1]).min(lambda[2]);
            if best.is_none_or(|(w, _, _)| worst > w) {
                best = Some((worst, c, lambda));
            }
        }
        best.map(|(_, c, lambda)| (c, lambda))
    }
}

/// The distance from `p` to the segment from `a` to `b`.
fn segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let e = [b[0] - a[0], b[1] - a[1]];
    let length2 = e[0] * e[0] + e[1] * e[1];
    let t = if length2 > 0.0 {
        (((p[0] - a[0]) * e[0] + (p[1] - a[1]) * e[1]) / length2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    dist2(p, [a[0] + t * e[0], a[1] + t * e[1]]).sqrt()
}
