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
