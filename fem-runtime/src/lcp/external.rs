//! Complementarity solvers that live outside this crate: PETSc's SNES and SNESVI driven
//! over MPI (the `fem-petsc` crate) plugs in here, so that the one pipeline (problem,
//! nested levels, report, estimators, output) runs unchanged around it.
//!
//! An [`ExternalSolver`] receives each level's LCP
//! `A U − Bᵀ Λ = F, 0 ≤ Λ ⊥ B U + C Λ − G ≥ 0` ([`Lcp`]) and the primal start that
//! nested iteration prolonged from the coarser level, and returns `(U, Λ)`; the caller
//! checks the answer by its KKT residual as it checks its own solvers'.

use super::{Lcp, LcpSolution};
use crate::error::Result;

/// A solver of one LCP outside this crate, chosen by
/// [`crate::obstacle::VariationalSolver::External`].
pub trait ExternalSolver: Send + Sync {
    /// Its name in reports (`"petsc"`).
    fn name(&self) -> &'static str;

    /// Solves `lcp` from the primal unknowns `start` (nested iteration's prolonged
    /// solution; `None`: the solver's own start).
    ///
    /// # Errors
    /// A problem the solver does not take, and a solve that does not converge (named by
    /// the solver's reason), never an unconverged answer.
    fn solve(&self, lcp: &Lcp, start: Option<&[f64]>) -> Result<LcpSolution>;

    /// Marks the solves that follow as serving `purpose`, for the solver's own records
    /// (a report that lists its solves says which gave the answer); by default nothing.
    fn set_purpose(&self, purpose: Purpose) {
        let _ = purpose;
    }

    /// The number of solves recorded so far: a mark for [`ExternalSolver::relabel`]; by
    /// default 0 (no records).
    fn recorded(&self) -> usize {
        0
    }

    /// Marks the recorded solves `records` (marks of [`ExternalSolver::recorded`]) as
    /// serving `purpose`: a probe of the model choice that it takes as the answer; by
    /// default nothing.
    fn relabel(&self, records: std::ops::Range<usize>, purpose: Purpose) {
        let _ = (records, purpose);
    }

    /// This process's cells of a partition of a mesh's cells, where the solver runs on
    /// several processes that each assemble their own cells (`Ok(None)`, the default:
    /// every process assembles the whole LCP). `graph` is the cells' adjacency through
    /// shared facets. Every process calls it, with the same graph, on the thread that
    /// set the solver up.
    ///
    /// # Errors
    /// The partitioner's.
    fn partition(&self, graph: &CellGraph) -> Result<Option<Vec<usize>>> {
        let _ = graph;
        Ok(None)
    }

    /// `values` summed entry by entry over the solver's processes, in place (every
    /// process calls it with the same length); by default one process: unchanged.
    fn sum(&self, values: &mut [f64]) {
        let _ = values;
    }

    /// The largest of `value` over the solver's processes; by default `value`.
    fn max(&self, value: f64) -> f64 {
        value
    }
}

/// The adjacency of a mesh's cells through shared facets (edges of triangles, vertices
/// of intervals), in compressed rows: cell `c`'s neighbours are
/// `neighbours[offsets[c]..offsets[c + 1]]`, ascending. The graph a partitioner cuts.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct CellGraph {
    /// Row starts, one per cell and one past the last.
    pub offsets: Vec<usize>,
    /// The neighbours, row after row.
    pub neighbours: Vec<usize>,
}

impl CellGraph {
    /// The graph of `mesh`: two cells are neighbours where they share a facet (as many
    /// vertices as the cell's dimension). A mesh without vertex numbers has no edges.
    pub fn of<G: crate::mesh::Mesh>(mesh: &G) -> Self {
        let kind = mesh.cell_kind();
        let (corners, shared) = (kind.vertex_count(), kind.dimension());
        let cells = mesh.cell_count();
        let mut facets: Vec<([usize; 2], usize)> = Vec::with_capacity(cells * corners);
        let mut v = [0usize; 3];
        for c in 0..cells {
            if !mesh.cell_vertex_numbers_into(c, &mut v[..corners]) {
                return Self {
                    offsets: vec![0; cells + 1],
                    neighbours: Vec::new(),
                };
            }
            for skip in 0..corners {
                // the facet opposite corner `skip`: its vertices sorted, padded
                let mut key = [usize::MAX; 2];
                let mut at = 0;
                for (i, &x) in v[..corners].iter().enumerate() {
                    if i != skip && at < shared {
                        key[at] = x;
                        at += 1;
                    }
                }
                if key[0] > key[1] && shared == 2 {
                    key.swap(0, 1);
                }
                facets.push((key, c));
            }
        }
        facets.sort_unstable();
        let mut rows = vec![Vec::new(); cells];
        for pair in facets.windows(2) {
            if pair[0].0 == pair[1].0 && pair[0].1 != pair[1].1 {
                rows[pair[0].1].push(pair[1].1);
                rows[pair[1].1].push(pair[0].1);
            }
        }
        let mut offsets = Vec::with_capacity(cells + 1);
        offsets.push(0);
        let mut neighbours = Vec::new();
        for mut row in rows {
            row.sort_unstable();
            row.dedup();
            neighbours.extend(row);
            offsets.push(neighbours.len());
        }
        Self {
            offsets,
            neighbours,
        }
    }

    /// The number of cells.
    pub fn cell_count(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }
}

/// What an LCP solve serves, as an [`ExternalSolver`]'s records name it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Purpose {
    /// The answer: the levels of a nested solve, each level of an adaptive one, and a
    /// probe the model choice takes as its answer (relabelled).
    #[default]
    Answer,
    /// A probe of the model choice (a candidate on a coarse mesh).
    Probe,
    /// The rounding experiment's solves on the mesh moved in its last bits.
    RoundingExperiment,
}

impl Purpose {
    /// Its name in reports (`answer`, `probe`, `rounding experiment`).
    pub fn name(self) -> &'static str {
        match self {
            Purpose::Answer => "answer",
            Purpose::Probe => "probe",
            Purpose::RoundingExperiment => "rounding experiment",
        }
    }
}

/// A handle on an [`ExternalSolver`] that lives for the whole process (a solver set up
/// once by the command line, e.g. PETSc after `MPI_Init`); compared by identity.
#[derive(Clone, Copy)]
pub struct External(pub &'static dyn ExternalSolver);

impl std::fmt::Debug for External {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "External({})", self.0.name())
    }
}

impl PartialEq for External {
    fn eq(&self, other: &Self) -> bool {
        std::ptr::addr_eq(self.0, other.0)
    }
}

impl Eq for External {}
