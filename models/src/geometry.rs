//! The meshes of a scene's [`Domain`]: the levels of nested iteration for `--mesh-size
//! N`, one implementation per kind of mesh the runtime solves on, and what a finished
//! solve gives back for charts and ParaView.

use crate::scene::{Domain, Part};
use fem_runtime::element::triangle::{TriangleBasis, TriangleField};
use fem_runtime::mesh::triangle::QuadraticGeometry;
use fem_runtime::obstacle::ObstacleSolution;
use fem_runtime::problem::Domain as MeshKind;
use fem_runtime::reference::triangle::TriangleRule;
use fem_runtime::{
    CurvedTriangleMesh, DataFn, DirichletPart, Error, IntervalMesh, Model, Result, TriangleMesh,
};

/// Largest N of a generated mesh: the memory estimate refuses sizes well below it on
/// every pair; this bound keeps the estimate's arithmetic and a typo's 10¹⁸ out of the
/// mesh generators.
pub const MAX_MESH_SIZE: usize = 1 << 26;

/// Most uniform refinements of a Gmsh mesh (`4^k` times its triangles).
pub const MAX_REFINEMENTS: usize = 8;

/// The check a solve makes of the finest mesh's cell count before any mesh is built
/// (the memory estimate): an error refuses the size.
pub type CellBudget<'a> = &'a dyn Fn(f64) -> Result<()>;

/// A kind of mesh a scene can be solved on.
pub trait Geometry: MeshKind {
    /// The meshes for size `n` on `domain`, coarsest first: `n` halved while it stays
    /// even and at least `coarsest` (without `nested`, `n` alone); a Gmsh file and its
    /// `n` uniform refinements. `budget` sees the finest mesh's cell count first (a
    /// file's after reading it, before refining). `load` is the load magnitude solved
    /// at, which a generated mesh may be graded to.
    ///
    /// # Errors
    /// A domain this kind of mesh does not cover, a size out of range, the budget's
    /// refusal, and the mesh generators' and the Gmsh reader's errors.
    fn levels(
        domain: &Domain,
        n: usize,
        nested: bool,
        coarsest: usize,
        load: Option<f64>,
        budget: CellBudget,
    ) -> Result<Vec<Self>>;

    /// The runtime's part of the named boundary parts on this mesh.
    ///
    /// # Errors
    /// A name the mesh does not have (the message lists those it has).
    fn part(&self, part: &Part) -> Result<DirichletPart> {
        match part {
            Part::All => Ok(DirichletPart::All),
            Part::Named(names) => {
                let names: Vec<&str> = names.iter().map(String::as_str).collect();
                Ok(DirichletPart::Markers(self.part_markers(&names)?))
            }
        }
    }

    /// The value of `field` of a solution at the point `x`, where `x` lies in the mesh.
    fn value_at(solution: &ObstacleSolution<Self>, field: usize, x: &[f64]) -> Option<f64>;

    /// `∫ u_h` of `field` over the domain.
    fn integral(solution: &ObstacleSolution<Self>, field: usize) -> f64;

    /// The measure of the domain: its length or area.
    fn total_measure(&self) -> f64;

    /// Warnings for the named boundary parts that hold interior edges (embedded curves):
    /// a boundary part holds boundary edges only, so nothing is imposed on them.
    fn interior_part_warnings(&self, names: &[String]) -> Vec<String> {
        let _ = names;
        Vec::new()
    }

    /// The sampled fields of a solution for charts and ParaView.
    fn fields<M: Model>(solution: &ObstacleSolution<Self>, psi: &DataFn) -> Fields;

    /// The mesh as straight triangles, where it is one (not an interval mesh, not curved
    /// cells): what boundary resultants are evaluated on.
    fn straight(&self) -> Option<&TriangleMesh> {
        None
    }

    /// A view of `field` of a solution on straight triangles ([`Geometry::straight`]).
    fn straight_view(solution: &ObstacleSolution<Self>, field: usize) -> Option<TriangleField<'_>> {
        let _ = (solution, field);
        None
    }
}

/// The fields of a solved scene, sampled for output.
#[derive(Clone, Debug)]
pub enum Fields {
    /// On an interval: every primal field and ψ at `x`, the multiplier per cell.
    Interval {
        /// Sample points.
        x: Vec<f64>,
        /// `(name, values at x)` of each primal field, the constrained one first.
        fields: Vec<(&'static str, Vec<f64>)>,
        /// ψ at x.
        psi: Vec<f64>,
        /// Cell midpoints.
        cell_x: Vec<f64>,
        /// The multiplier per cell.
        lambda: Vec<f64>,
    },
    /// On triangles (curved ones as their straight cells): vertex and cell values.
    Triangles {
        /// The (straight) mesh.
        mesh: TriangleMesh,
        /// `(name, value per vertex)`: the constrained field and ψ.
        vertex: Vec<(&'static str, Vec<f64>)>,
        /// `(name, value per cell)`: λ_h at the centroid and the contact share.
        cell: Vec<(&'static str, Vec<f64>)>,
    },
}

impl Fields {
    /// Writes the fields on triangles as a ParaView `.vtu` file at `path`: the vertex
    /// fields as point data, the cell fields as cell data.
    ///
    /// # Errors
    /// [`fem_runtime::Error::Input`] for fields on an interval, and
    /// [`fem_runtime::io::vtk::write_vtu`]'s.
    pub fn write_vtu(&self, path: &std::path::Path) -> fem_runtime::Result<()> {
        let Fields::Triangles { mesh, vertex, cell } = self else {
            return Err(fem_runtime::Error::Input(
                "a .vtu holds fields on triangles; these are on an interval".into(),
            ));
        };
        let vertex: Vec<(&str, &[f64])> = vertex.iter().map(|(n, v)| (*n, v.as_slice())).collect();
        let cell: Vec<(&str, &[f64])> = cell.iter().map(|(n, v)| (*n, v.as_slice())).collect();
        fem_runtime::io::vtk::write_vtu(path, mesh, &vertex, &cell)
    }
}

/// The halving sizes `n, n/2, …` down to `coarsest`, coarsest first (`n` alone without
/// `nested`); `even` keeps every level even (the L-shape needs even N).
pub fn halving_sizes(n: usize, nested: bool, coarsest: usize, even: bool) -> Vec<usize> {
    let mut sizes = vec![n];
    while nested
        && sizes[0] % 2 == 0
        && sizes[0] / 2 >= coarsest.max(1)
        && (!even || (sizes[0] / 2) % 2 == 0)
    {
        sizes.insert(0, sizes[0] / 2);
    }
    sizes
}

fn size_error(n: usize, what: &str) -> Error {
    Error::Input(format!(
        "--mesh-size {n} is out of range for {what} (1 to {MAX_MESH_SIZE})"
    ))
}

impl Geometry for IntervalMesh {
    fn levels(
        domain: &Domain,
        n: usize,
        nested: bool,
        coarsest: usize,
        _load: Option<f64>,
        budget: CellBudget,
    ) -> Result<Vec<Self>> {
        let &Domain::Interval { start, end } = domain else {
            return Err(Error::Input(format!(
                "the {} is not an interval: a model on intervals cannot be solved on it",
                domain.describe()
            )));
        };
        if n == 0 || n > MAX_MESH_SIZE {
            return Err(size_error(n, "an interval's elements"));
        }
        budget(n as f64)?;
        halving_sizes(n, nested, coarsest, false)
            .into_iter()
            .map(|k| IntervalMesh::uniform(start, end, k))
            .collect()
    }

    fn total_measure(&self) -> f64 {
        let v = self.vertices();
        v[v.len() - 1] - v[0]
    }

    fn value_at(solution: &ObstacleSolution<Self>, field: usize, x: &[f64]) -> Option<f64> {
        solution.view(field).at(x[0], 0)
    }

    fn integral(solution: &ObstacleSolution<Self>, field: usize) -> f64 {
        let view = solution.view(field);
        let mesh = &solution.discretization.mesh;
        // Gauss–Legendre with 4 points: exact to degree 7, beyond every interval element
        let rule = fem_runtime::gauss_legendre(4);
        (0..mesh.cell_count())
            .map(|c| {
                let [a, b] = mesh.cell(c);
                let h = b - a;
                rule.points
                    .iter()
                    .zip(&rule.weights)
                    .map(|(&t, &w)| w * h * view.at(a + t * h, 0).unwrap_or(0.0))
                    .sum::<f64>()
            })
            .sum()
    }

    fn fields<M: Model>(solution: &ObstacleSolution<Self>, psi: &DataFn) -> Fields {
        let mesh = &solution.discretization.mesh;
        let cells = mesh.cell_count();
        let (a, b) = (
            mesh.vertices()[0],
            mesh.vertices()[mesh.vertices().len() - 1],
        );
        let samples = 8 * cells.min(512) + 1;
        let x: Vec<f64> = (0..samples)
            .map(|i| a + (b - a) * i as f64 / (samples - 1) as f64)
            .collect();
        let multiplier = solution.discretization.multiplier_field;
        // the constrained field first (charts draw ψ beside it), then the others
        let first = M::constrained_field();
        let fields = std::iter::once(first)
            .chain((0..M::FIELDS.len()).filter(|&f| f != multiplier && f != first))
            .map(|f| {
                let view = solution.view(f);
                let values = x
                    .iter()
                    .map(|&x| view.at(x, 0).unwrap_or(f64::NAN))
                    .collect();
                (M::FIELDS[f].name, values)
            })
            .collect();
        // by position: bisection appends a refined mesh's cells out of order, and a chart
        // joining them in storage order crossed itself
        let mut cells_by_x: Vec<(f64, f64)> = (0..cells)
            .map(|c| 0.5 * (mesh.cell(c)[0] + mesh.cell(c)[1]))
            .zip(solution.multiplier().iter().copied())
            .collect();
        cells_by_x.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (cell_x, lambda) = cells_by_x.into_iter().unzip();
        Fields::Interval {
            psi: x.iter().map(|&x| psi(&[x])).collect(),
            fields,
            cell_x,
            lambda,
            x,
        }
    }
}

impl Geometry for TriangleMesh {
    fn straight(&self) -> Option<&TriangleMesh> {
        Some(self)
    }

    fn straight_view(solution: &ObstacleSolution<Self>, field: usize) -> Option<TriangleField<'_>> {
        Some(solution.view(field))
    }

    fn levels(
        domain: &Domain,
        n: usize,
        nested: bool,
        coarsest: usize,
        load: Option<f64>,
        budget: CellBudget,
    ) -> Result<Vec<Self>> {
        match domain {
            Domain::Gmsh(path) => gmsh_levels(path, n, nested, budget),
            Domain::Refined { mesh, .. } => refined_levels((**mesh).clone(), n, nested, budget),
            Domain::Generated(generator) => {
                if n == 0 || n > generator.max_size {
                    return Err(Error::Input(format!(
                        "--mesh-size {n} ({}) is out of range (1 to {})",
                        generator.size_meaning, generator.max_size
                    )));
                }
                let mesh = (generator.build)(n, load)?;
                budget(mesh.cell_count() as f64)?;
                Ok(vec![mesh])
            }
            Domain::Disk { curved: true, .. } => Err(Error::Input(
                "a curved disk is solved on curved triangles".into(),
            )),
            _ => {
                let even = matches!(domain, Domain::LShape);
                if n == 0 || n > MAX_MESH_SIZE {
                    return Err(size_error(n, &domain.describe()));
                }
                if even && n % 2 != 0 {
                    return Err(Error::Input(format!(
                        "the L-shape needs an even --mesh-size, got {n}"
                    )));
                }
                budget(structured_cells(domain, n))?;
                use rayon::prelude::*;
                // the coarser levels on the second core while the finest builds
                halving_sizes(n, nested, coarsest, even)
                    .into_par_iter()
                    .map(|k| structured(domain, k))
                    .collect()
            }
        }
    }

    /// The part's markers, checked: `all` is the keyword for the whole boundary (a mesh
    /// with a part of that name would make `all` and `["all"]` mean different sets
    /// under one printed name), a list names at least one part, and every part listed
    /// holds boundary edges of its own (an interior curve or an empty group would
    /// otherwise be reported as held and hold nothing).
    fn part(&self, part: &Part) -> Result<DirichletPart> {
        let domain = || format!("{} triangles", self.cell_count());
        let Part::Named(names) = part else {
            return Ok(DirichletPart::All);
        };
        if names.is_empty() {
            return Err(Error::Input(
                "no boundary part is chosen: choose at least one part".into(),
            ));
        }
        let markers_of = |names: &[&str]| {
            self.boundary_part_markers(names).map_err(|e| match e {
                Error::Input(message) => {
                    // `["all"]`: the keyword is a plain string, not a name in a list
                    let keyword = if names.contains(&"all") && message.contains("`all`") {
                        "; \"all\" (the whole boundary) is a keyword on its own, `dirichlet = \"all\"` in a scene file, not a name in a list"
                    } else {
                        ""
                    };
                    Error::Input(format!("{message} ({}){keyword}", domain()))
                }
                other => other,
            })
        };
        let all: Vec<&str> = names.iter().map(String::as_str).collect();
        let markers = markers_of(&all)?;
        if names.len() > 1 {
            for name in &all {
                let own = DirichletPart::Markers(markers_of(&[name])?);
                if own.edge_count(self) == 0 {
                    return Err(Error::Input(format!(
                        "the boundary part `{name}` holds no boundary edge of the mesh ({}): an interior curve or an empty group cannot carry a condition; remove it from the list",
                        domain()
                    )));
                }
            }
        }
        let part = DirichletPart::Markers(markers);
        if part.edge_count(self) == 0 {
            let listed: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
            return Err(Error::Input(format!(
                "the boundary parts {} hold no boundary edge of the mesh ({}): the condition would hold nowhere; refused",
                listed.join(", "),
                domain()
            )));
        }
        Ok(part)
    }

    fn value_at(solution: &ObstacleSolution<Self>, field: usize, x: &[f64]) -> Option<f64> {
        point_value(&solution.view(field), x)
    }

    fn integral(solution: &ObstacleSolution<Self>, field: usize) -> f64 {
        solution.view(field).integral()
    }

    fn total_measure(&self) -> f64 {
        (0..self.cell_count()).map(|c| self.area(c)).sum()
    }

    fn interior_part_warnings(&self, names: &[String]) -> Vec<String> {
        self.interior_edges_of(names)
            .into_iter()
            .map(|(name, count)| {
                format!(
                    "the boundary part `{name}` has {count} edge(s) inside the domain (an embedded curve); a boundary part holds boundary edges only, so nothing is imposed on them"
                )
            })
            .collect()
    }

    fn fields<M: Model>(solution: &ObstacleSolution<Self>, psi: &DataFn) -> Fields {
        let mut fields = triangle_fields::<M, _>(solution, &solution.discretization.mesh, psi);
        if let (Fields::Triangles { cell, .. }, fem_runtime::obstacle::Multipliers::Nodal) =
            (&mut fields, &solution.discretization.multipliers)
        {
            let (shares, _) = fem_runtime::problem::nodal::contact_shares(solution, psi);
            cell.push((
                "lambda",
                fem_runtime::problem::nodal::force_density(solution),
            ));
            cell.push(("contact", shares));
        }
        fields
    }
}

impl Geometry for CurvedTriangleMesh {
    fn levels(
        domain: &Domain,
        n: usize,
        nested: bool,
        coarsest: usize,
        _load: Option<f64>,
        budget: CellBudget,
    ) -> Result<Vec<Self>> {
        let &Domain::Disk {
            centre,
            radius,
            curved: true,
        } = domain
        else {
            return Err(Error::Input(format!(
                "the {} has no curved boundary: it is solved on straight triangles",
                domain.describe()
            )));
        };
        if n == 0 || n > MAX_MESH_SIZE {
            return Err(size_error(n, "a disk's rings"));
        }
        budget(structured_cells(domain, n))?;
        halving_sizes(n, nested, coarsest, false)
            .into_iter()
            .map(|k| {
                let mesh = TriangleMesh::disk(centre, radius, k)?;
                let geometry = QuadraticGeometry::circle(&mesh, centre, radius)?;
                CurvedTriangleMesh::new(mesh, geometry)
            })
            .collect()
    }

    fn part(&self, part: &Part) -> Result<DirichletPart> {
        self.mesh().part(part)
    }

    fn value_at(solution: &ObstacleSolution<Self>, field: usize, x: &[f64]) -> Option<f64> {
        point_value(&solution.view(field), x)
    }

    /// The isoparametric field is its reference polynomial on each cell, so the integral
    /// is `Σ_T ∫_T̂ u(ξ) |det J(ξ)| dξ`, with a rule two degrees above the field's for the
    /// map's Jacobian (a polynomial of degree 2 on quadratic cells).
    fn integral(solution: &ObstacleSolution<Self>, field: usize) -> f64 {
        let view = solution.view(field);
        let basis = TriangleBasis::new(view.map.element());
        let rule = TriangleRule::exact_for_degree(view.map.element().degree() + 2);
        let mesh = &solution.discretization.mesh;
        (0..mesh.mesh().cell_count())
            .map(|c| {
                let map = mesh.cell_map(c);
                rule.integrate(|xi| view.value(&basis, c, xi) * map.det(xi).abs())
            })
            .sum()
    }

    fn total_measure(&self) -> f64 {
        let rule = TriangleRule::exact_for_degree(2);
        (0..self.mesh().cell_count())
            .map(|c| {
                let map = self.cell_map(c);
                rule.integrate(|xi| map.det(xi).abs())
            })
            .sum()
    }

    fn interior_part_warnings(&self, names: &[String]) -> Vec<String> {
        self.mesh().interior_part_warnings(names)
    }

    fn fields<M: Model>(solution: &ObstacleSolution<Self>, psi: &DataFn) -> Fields {
        triangle_fields::<M, _>(solution, solution.discretization.mesh.mesh(), psi)
    }
}

/// The value of a triangle field at `x` (located in the straight cells).
fn point_value(view: &TriangleField, x: &[f64]) -> Option<f64> {
    let basis = TriangleBasis::new(view.map.element());
    let locator = fem_runtime::mesh::triangle::PointLocator::new(view.mesh);
    view.at(&basis, &locator, [x[0], x[1]])
}

/// The cells of the structured mesh of `domain` for size `n`.
fn structured_cells(domain: &Domain, n: usize) -> f64 {
    let n = n as f64;
    match domain {
        Domain::Rectangle { cells, .. } => 2.0 * n * n * (cells[0] * cells[1]) as f64,
        Domain::LShape => 1.5 * n * n,
        Domain::Disk { .. } => 6.0 * n * n,
        _ => 0.0,
    }
}

/// A structured mesh of a generated domain for size `n`.
fn structured(domain: &Domain, n: usize) -> Result<TriangleMesh> {
    match domain {
        &Domain::Rectangle {
            x,
            y,
            cells,
            diagonal,
        } => TriangleMesh::rectangle(x[0], x[1], y[0], y[1], n * cells[0], n * cells[1], diagonal),
        Domain::LShape => TriangleMesh::l_shape(n / 2),
        &Domain::Disk { centre, radius, .. } => TriangleMesh::disk(centre, radius, n),
        other => Err(Error::Input(format!(
            "the {} has no structured mesh",
            other.describe()
        ))),
    }
}

/// The levels of a Gmsh mesh: the file's mesh and its `refinements` uniform refinements
/// (all of them for nested iteration, else the finest only).
fn gmsh_levels(
    path: &std::path::Path,
    refinements: usize,
    nested: bool,
    budget: CellBudget,
) -> Result<Vec<TriangleMesh>> {
    // refused before the file is read
    check_refinements(
        refinements,
        "a Gmsh mesh (--msh, or a scene file's mesh.file)",
    )?;
    let mesh = fem_runtime::mesh::gmsh::read_msh(path)?;
    // the file's own cells first, so a refusal names corners the user wrote
    mesh.quality().check(&mesh).map_err(|e| match e {
        Error::Mesh(m) => Error::Mesh(format!("{}: {m}", path.display())),
        other => other,
    })?;
    refined_levels(mesh, refinements, nested, budget)
}

/// Refuses more than [`MAX_REFINEMENTS`] uniform refinements of `what`.
fn check_refinements(refinements: usize, what: &str) -> Result<()> {
    if refinements > MAX_REFINEMENTS {
        return Err(Error::Input(format!(
            "--mesh-size {refinements} on {what} means {refinements} uniform refinements of it (4^{refinements} times the triangles); at most {MAX_REFINEMENTS}"
        )));
    }
    Ok(())
}

/// `mesh` and its `refinements` uniform refinements (all of them for nested iteration,
/// else the finest only), the budget asked before refining.
fn refined_levels(
    mesh: TriangleMesh,
    refinements: usize,
    nested: bool,
    budget: CellBudget,
) -> Result<Vec<TriangleMesh>> {
    check_refinements(refinements, "the scene's mesh")?;
    budget(mesh.cell_count() as f64 * 4f64.powi(refinements as i32))?;
    let mut levels = vec![mesh];
    for _ in 0..refinements {
        let finer = levels.last().expect("a level").refine_uniformly();
        levels.push(finer);
    }
    if !nested {
        levels.drain(..levels.len() - 1);
    }
    Ok(levels)
}

/// The vertex and cell fields of a triangle solution: the constrained field and ψ at the
/// vertices of the straight mesh, λ_h at the centroids and the contact shares.
fn triangle_fields<M: Model, G: MeshKind>(
    solution: &ObstacleSolution<G>,
    mesh: &TriangleMesh,
    psi: &DataFn,
) -> Fields {
    let d = &solution.discretization;
    let field = M::OBSTACLE.map_or(0, |[f, _]| f);
    let mut vertex = vec![(M::FIELDS[field].name, G::field_at_vertices(solution, field))];
    vertex.push(("psi", mesh.vertices().iter().map(|x| psi(x)).collect()));
    let mut cell = Vec::new();
    if matches!(d.multipliers, fem_runtime::obstacle::Multipliers::Cells) {
        let lambda = solution.multiplier_values();
        let dofs = d.dofs.map(d.multiplier_field).expect("the multiplier");
        let per_cell = dofs.cell_dofs(0).len().max(1);
        let mean: Vec<f64> = (0..mesh.cell_count())
            .map(|c| {
                let ds = dofs.cell_dofs(c);
                ds.iter().map(|&k| lambda[k]).sum::<f64>() / per_cell as f64
            })
            .collect();
        cell.push(("lambda", mean));
        cell.push(("contact", solution.contact_shares()));
    } else if let Some((mean, shares)) = G::boundary_contact_cells(solution) {
        cell.push(("lambda", mean));
        cell.push(("contact", shares));
    }
    Fields::Triangles {
        mesh: mesh.clone(),
        vertex,
        cell,
    }
}
