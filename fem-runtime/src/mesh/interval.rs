//! Interval meshes: uniform, graded, and refined by bisection.

use crate::error::{Error, Result};

/// A mesh of an interval: strictly increasing vertices; cell `c` is
/// `[vertices[c], vertices[c + 1]]`.
#[derive(Clone, Debug, PartialEq)]
pub struct IntervalMesh {
    vertices: Vec<f64>,
}

impl IntervalMesh {
    /// A mesh with the given vertices; every cell must have positive, finite length.
    pub fn new(vertices: Vec<f64>) -> Result<Self> {
        if vertices.len() < 2 {
            return Err(Error::Mesh(format!(
                "an interval mesh needs at least two vertices, got {}",
                vertices.len()
            )));
        }
        if let Some(i) = vertices.iter().position(|x| !x.is_finite()) {
            return Err(Error::Mesh(format!("vertex {i} is {}", vertices[i])));
        }
        for (c, pair) in vertices.windows(2).enumerate() {
            let h = pair[1] - pair[0];
            if h <= 0.0 {
                return Err(Error::Mesh(format!(
                    "cell {c} = [{}, {}] has {} length {h}",
                    pair[0],
                    pair[1],
                    if h == 0.0 { "zero" } else { "negative" }
                )));
            }
        }
        Ok(Self { vertices })
    }

    /// `n` equal cells on `[a, b]`.
    pub fn uniform(a: f64, b: f64, n: usize) -> Result<Self> {
        if n == 0 {
            return Err(Error::Mesh("a mesh needs at least one cell".into()));
        }
        Self::new(
            (0..=n)
                .map(|i| {
                    if i == n {
                        b
                    } else {
                        a + (b - a) * i as f64 / n as f64
                    }
                })
                .collect(),
        )
    }

    /// `n` cells on `[a, b]` graded towards both ends: `x = a + (b−a) g(i/n)` with
    /// `g(s) = ½(2s)^γ` on the left half and symmetric on the right (`γ = 1` is uniform).
    pub fn graded(a: f64, b: f64, n: usize, grading: f64) -> Result<Self> {
        if !(grading >= 1.0 && grading.is_finite()) {
            return Err(Error::Mesh(format!(
                "grading exponent {grading} must be ≥ 1"
            )));
        }
        if n == 0 {
            return Err(Error::Mesh("a mesh needs at least one cell".into()));
        }
        let g = |s: f64| {
            if s <= 0.5 {
                0.5 * (2.0 * s).powf(grading)
            } else {
                1.0 - 0.5 * (2.0 * (1.0 - s)).powf(grading)
            }
        };
        Self::new(
            (0..=n)
                .map(|i| {
                    if i == n {
                        b
                    } else {
                        a + (b - a) * g(i as f64 / n as f64)
                    }
                })
                .collect(),
        )
    }

    /// Bisects the marked cells (indices may repeat; out-of-range ones are an error).
    pub fn refine(&self, marked: &[usize]) -> Result<Self> {
        let mut mark = vec![false; self.cell_count()];
        for &c in marked {
            *mark.get_mut(c).ok_or_else(|| {
                Error::Mesh(format!(
                    "cannot refine cell {c}: the mesh has {} cells",
                    self.cell_count()
                ))
            })? = true;
        }
        let mut vertices = Vec::with_capacity(self.vertices.len() + marked.len());
        for (c, &marked) in mark.iter().enumerate() {
            let [x0, x1] = self.cell(c);
            vertices.push(x0);
            if marked {
                vertices.push(0.5 * (x0 + x1));
            }
        }
        vertices.push(*self.vertices.last().unwrap());
        Self::new(vertices)
    }

    /// Bisects every cell.
    pub fn refine_uniformly(&self) -> Self {
        let all: Vec<usize> = (0..self.cell_count()).collect();
        self.refine(&all)
            .expect("bisecting a valid mesh gives a valid mesh")
    }

    /// The mesh with every coordinate multiplied by `factor > 0` (the same cells): the
    /// rounding experiment solves on it ([`crate::problem`]).
    ///
    /// # Errors
    /// A factor that is not positive and finite.
    pub fn scaled(&self, factor: f64) -> Result<Self> {
        Self::new(self.vertices.iter().map(|x| x * factor).collect())
    }

    /// The vertices, increasing.
    pub fn vertices(&self) -> &[f64] {
        &self.vertices
    }

    /// Number of cells.
    pub fn cell_count(&self) -> usize {
        self.vertices.len() - 1
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.vertices.len()
    }

    /// End points of cell `c`.
    #[inline]
    pub fn cell(&self, c: usize) -> [f64; 2] {
        [self.vertices[c], self.vertices[c + 1]]
    }

    /// Length of cell `c`.
    pub fn h(&self, c: usize) -> f64 {
        self.vertices[c + 1] - self.vertices[c]
    }

    /// Largest cell length.
    pub fn max_h(&self) -> f64 {
        (0..self.cell_count())
            .map(|c| self.h(c))
            .fold(0.0, f64::max)
    }

    /// The cell containing `x` (the left one at a vertex), or `None` outside the mesh.
    pub fn locate(&self, x: f64) -> Option<usize> {
        let (a, b) = (self.vertices[0], *self.vertices.last().unwrap());
        if !(a..=b).contains(&x) {
            return None;
        }
        let i = self.vertices.partition_point(|&v| v < x);
        Some(i.saturating_sub(1).min(self.cell_count() - 1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_meshes_are_errors() {
        assert!(IntervalMesh::new(vec![0.0, 0.5, 0.5, 1.0]).is_err());
        assert!(IntervalMesh::new(vec![0.0, 0.6, 0.5, 1.0])
            .unwrap_err()
            .to_string()
            .contains("negative"));
        assert!(IntervalMesh::new(vec![0.0, f64::NAN]).is_err());
        assert!(IntervalMesh::uniform(0.0, 1.0, 0).is_err());
        assert!(IntervalMesh::uniform(1.0, 0.0, 4).is_err());
        assert!(IntervalMesh::graded(0.0, 1.0, 4, 0.5).is_err());
    }

    #[test]
    fn refinement_bisects() {
        let m = IntervalMesh::uniform(0.0, 1.0, 4).unwrap();
        let r = m.refine(&[1, 1, 3]).unwrap();
        assert_eq!(r.vertices(), &[0.0, 0.25, 0.375, 0.5, 0.75, 0.875, 1.0]);
        assert!(m.refine(&[4]).is_err());
        assert_eq!(m.refine_uniformly().cell_count(), 8);
        let g = IntervalMesh::graded(0.0, 1.0, 8, 2.0).unwrap();
        assert!(g.h(0) < g.h(3) && (g.h(0) - g.h(7)).abs() < 1e-15);
    }

    #[test]
    fn locate_finds_the_cell() {
        let m = IntervalMesh::uniform(0.0, 1.0, 4).unwrap();
        assert_eq!(m.locate(0.0), Some(0));
        assert_eq!(m.locate(0.3), Some(1));
        assert_eq!(m.locate(0.5), Some(1));
        assert_eq!(m.locate(1.0), Some(3));
        assert_eq!(m.locate(1.1), None);
    }
}
