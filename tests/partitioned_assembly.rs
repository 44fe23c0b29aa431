//! Assembly over a part of the cells, one MPI rank's share of a partitioned mesh
//! (`Discretization::with_constraints_on`, `Domain::discretize_on`,
//! `boundary_multiplier::discretize_on`): summed over a partition of the cells, the
//! parts' LCPs must be the whole LCP entry by entry (`A`, `B`, the diagonal and the
//! blocks of `C`, `F`, `G`), with the supports, the rotated plate supports (Argyris on a
//! disk), the extra multiplier couplings (P2–P1disc) and the multipliers on boundary
//! edges (Signorini, P0 and P1) as the whole mesh has them. A multiplier on cells or on
//! boundary edges (P0) must also find each of its constraints on exactly one part,
//! complete there: what lets a rank evaluate its own constraints without communication.
//! The nodal method's levels are assembled in parts through the pipeline itself (a
//! recording solver). The parts are the cells `c ≡ r (mod 3)`, scattered over the
//! mesh, so that no part is a contiguous block that would hide a cell numbered wrongly.
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

use fem_forms::lcp::Lcp;
use fem_forms::obstacle::Discretization;
use fem_forms::problem::Domain;
use fem_forms::{Coefficients, Constraints, DataFn, Diagonal, Model, SystemDofs, TriangleMesh};
use std::collections::BTreeMap;

/// The blocks of an LCP as sums by entry.
#[derive(Default)]
struct Blocks {
    a: BTreeMap<(usize, usize), f64>,
    b: BTreeMap<(usize, usize), f64>,
    c: BTreeMap<usize, f64>,
    c_coupling: BTreeMap<(usize, usize), f64>,
    f: BTreeMap<usize, f64>,
    g: BTreeMap<usize, f64>,
}

impl Blocks {
    fn add(&mut self, lcp: &Lcp) {
        let (ptr, rows, values) = (
            lcp.a.symbolic().col_ptr(),
            lcp.a.symbolic().row_idx(),
            lcp.a.val(),
        );
        for j in 0..lcp.n() {
            for p in ptr[j]..ptr[j + 1] {
                *self.a.entry((rows[p], j)).or_default() += values[p];
            }
        }
        for (k, row) in lcp.b_rows.iter().enumerate() {
            for &(j, v) in row {
                *self.b.entry((k, j)).or_default() += v;
            }
        }
        for (k, &c) in lcp.c.iter().enumerate() {
            *self.c.entry(k).or_default() += c;
        }
        for (first, s, block) in lcp.c_blocks.blocks() {
            for i in 0..s {
                for j in (0..s).filter(|&j| j != i) {
                    *self.c_coupling.entry((first + i, first + j)).or_default() += block[i * s + j];
                }
            }
        }
        for (i, &f) in lcp.f.iter().enumerate() {
            *self.f.entry(i).or_default() += f;
        }
        for (k, &g) in lcp.g.iter().enumerate() {
            *self.g.entry(k).or_default() += g;
        }
    }
}

/// `sum` equals `whole` entry by entry, to rounding of the block's largest entry.
fn same<K: Ord + Copy + std::fmt::Debug>(
    what: &str,
    sum: &BTreeMap<K, f64>,
    whole: &BTreeMap<K, f64>,
) {
    let scale = whole.values().fold(0.0f64, |m, v| m.max(v.abs()));
    let keys: std::collections::BTreeSet<K> = sum.keys().chain(whole.keys()).copied().collect();
    for key in keys {
        let (s, w) = (
            sum.get(&key).copied().unwrap_or(0.0),
            whole.get(&key).copied().unwrap_or(0.0),
        );
        assert!(
            (s - w).abs() <= 1e-12 * scale.max(f64::MIN_POSITIVE),
            "{what} at {key:?}: the parts sum to {s:e}, the whole mesh has {w:e} (largest entry {scale:e})"
        );
    }
}

/// The parts `c ≡ r (mod 3)` of `cells` cells.
fn parts(cells: usize) -> Vec<Vec<usize>> {
    (0..3).map(|r| (r..cells).step_by(3).collect()).collect()
}

/// Builds the LCP of every part of the cells and of the whole mesh, and checks that the
/// parts sum to the whole; with `one_part_per_constraint`, that each constraint's rows
/// of `B`, `C` and `G` are on one part only.
fn parts_sum_to_whole<G>(
    cells: usize,
    build: impl Fn(Option<&[usize]>) -> Discretization<G>,
    one_part_per_constraint: bool,
) {
    let whole = build(None);
    let mut sum = Blocks::default();
    let mut holders = vec![0usize; whole.lcp.m()];
    for part in parts(cells) {
        let d = build(Some(&part));
        assert_eq!((d.lcp.n(), d.lcp.m()), (whole.lcp.n(), whole.lcp.m()));
        sum.add(&d.lcp);
        for (k, holder) in holders.iter_mut().enumerate() {
            if !d.lcp.b_rows[k].is_empty() || d.lcp.c[k] != 0.0 || d.lcp.g[k] != 0.0 {
                *holder += 1;
            }
        }
    }
    let mut expected = Blocks::default();
    expected.add(&whole.lcp);
    same("A", &sum.a, &expected.a);
    same("B", &sum.b, &expected.b);
    same("diag C", &sum.c, &expected.c);
    same("C's couplings", &sum.c_coupling, &expected.c_coupling);
    same("F", &sum.f, &expected.f);
    same("G", &sum.g, &expected.g);
    assert!(
        !expected.b.is_empty() && expected.c.values().any(|&c| c != 0.0),
        "a case without constraints tests nothing"
    );
    if one_part_per_constraint {
        for (k, &holder) in holders.iter().enumerate() {
            assert_eq!(holder, 1, "constraint {k} is on {holder} parts");
        }
    }
}

fn load(_: &[f64]) -> f64 {
    -8.0
}

fn obstacle(x: &[f64]) -> f64 {
    -0.2 + 0.1 * x[0] - 0.05 * x.get(1).copied().unwrap_or(0.0)
}

fn boundary(x: &[f64]) -> f64 {
    0.01 * x[0]
}

/// A membrane on the unit square with `u = g` on the boundary: the supports' columns
/// move to `F` and `G` on every part that touches them.
fn membrane<M: Model>(one_part_per_constraint: bool) {
    let mesh = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 6, 6, Diagonal::Alternating).unwrap();
    let data: [(&str, &DataFn); 3] = [("f", &load), ("ψ", &obstacle), ("g", &boundary)];
    let c = Coefficients::new::<M>(&[("α", 0.1)], &data).unwrap();
    let build = |cells: Option<&[usize]>| {
        let dofs = SystemDofs::all::<M>(&mesh).unwrap();
        let constraints = fem_forms::obstacle::triangle::dirichlet_constraints_on::<M>(
            &mesh,
            &dofs,
            &c,
            &fem_forms::DirichletPart::All,
        )
        .unwrap();
        mesh.discretize_on::<M>(cells, &c, dofs, &constraints, &[])
            .unwrap()
    };
    parts_sum_to_whole(mesh.cell_count(), build, one_part_per_constraint);
}

#[test]
fn membrane_p1_p0_parts_sum_to_the_whole_lcp() {
    membrane::<fem_forms::models::membrane_p1_p0::Model>(true);
}

/// P1disc multipliers: three constraints per cell, coupled within it (blocks of `C`).
#[test]
fn membrane_p2_p1disc_parts_sum_to_the_whole_lcp() {
    membrane::<fem_forms::models::membrane_p2_p1disc::Model>(true);
}

/// A simply supported Argyris plate on a polygonal disk: the supports along edges that
/// are not along x or y rotate the vertex DOFs (a congruence of `A`, rows of `B` spread
/// over the rotated group, extra unknowns eliminated into `F`).
#[test]
fn an_argyris_plate_on_a_disk_parts_sum_to_the_whole_lcp() {
    use fem_forms::models::kirchhoff::kirchhoff_argyris_p0::Model as M;
    use fem_forms::PlateSupport;
    let mesh = TriangleMesh::disk([0.0, 0.0], 1.0, 3).unwrap();
    let zero = |_: &[f64]| 0.0;
    let data: [(&str, &DataFn); 3] = [("f", &load), ("ψ", &obstacle), ("g", &zero)];
    let c =
        Coefficients::new::<M>(&[("D", 1.0), ("ν", 0.3), ("α", 1e-3), ("s", -1.0)], &data).unwrap();
    let build = |cells: Option<&[usize]>| {
        let dofs = SystemDofs::all::<M>(&mesh).unwrap();
        let mut constraints = Constraints::new();
        constraints
            .support_plate::<M>(
                &mesh,
                &dofs,
                "w",
                &fem_forms::DirichletPart::All,
                PlateSupport::SimplySupported,
            )
            .unwrap();
        assert!(
            !constraints.combinations().is_empty(),
            "the disk's supports rotate vertex DOFs"
        );
        mesh.discretize_on::<M>(cells, &c, dofs, &constraints, &[])
            .unwrap()
    };
    parts_sum_to_whole(mesh.cell_count(), build, true);
}

/// A clamped Timoshenko beam on an interval mesh.
#[test]
fn a_timoshenko_beam_parts_sum_to_the_whole_lcp() {
    use fem_forms::models::timoshenko::timoshenko_p2::Model as M;
    use fem_forms::{IntervalMesh, Side};
    let mesh = IntervalMesh::uniform(0.0, 1.0, 10).unwrap();
    let data: [(&str, &DataFn); 2] = [("f", &load), ("ψ", &obstacle)];
    let c = Coefficients::new::<M>(&[("t", 0.05), ("α", 0.1), ("s", -1.0)], &data).unwrap();
    let build = |cells: Option<&[usize]>| {
        let dofs = SystemDofs::all::<M>(&mesh).unwrap();
        let mut constraints = Constraints::new();
        for field in ["θ", "w"] {
            for side in [Side::Left, Side::Right] {
                constraints.clamp::<M>(&mesh, &dofs, field, side).unwrap();
            }
        }
        Discretization::with_constraints_on::<M>(&mesh, cells, &c, dofs, &constraints, "B_h", "L_h")
            .unwrap()
    };
    parts_sum_to_whole(mesh.cell_count(), build, true);
}

fn pressure(_: &[f64]) -> f64 {
    -5.0
}

fn gap(x: &[f64]) -> f64 {
    0.02 * (x[0] - 0.5) * (x[0] - 0.5)
}

/// Signorini contact with the multiplier on the bottom edges (marker 1), `u_x = 0` on
/// the left (marker 4): the facet terms go with their edge's cell.
fn signorini<M: Model>(one_part_per_constraint: bool) {
    use fem_forms::obstacle::boundary_multiplier::{discretize_on, primal_dofs};
    let mesh = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 6, 6, Diagonal::Alternating).unwrap();
    let data: [(&str, &DataFn); 2] = [("q", &pressure), ("g", &gap)];
    let c = Coefficients::new::<M>(
        &[
            ("μ_L", 400.0),
            ("λ_L", 600.0),
            ("α", 3e-4),
            ("n_c_x", 0.0),
            ("n_c_y", -1.0),
        ],
        &data,
    )
    .unwrap();
    let parts_markers = [vec![1], vec![3]];
    let build = |cells: Option<&[usize]>| {
        let dofs = primal_dofs::<M>(&mesh).unwrap();
        let mut constraints = Constraints::new();
        let (map, offset) = (dofs.map(0).unwrap(), dofs.offset(0).unwrap());
        for d in fem_forms::DirichletPart::Markers(vec![4]).dofs(map, &mesh) {
            constraints.fix_dof(offset + d, 0.0).unwrap();
        }
        discretize_on::<M>(&mesh, cells, &c, &parts_markers, dofs, &constraints).unwrap()
    };
    parts_sum_to_whole(mesh.cell_count(), build, one_part_per_constraint);
}

#[test]
fn signorini_p0_on_edges_parts_sum_to_the_whole_lcp() {
    signorini::<fem_forms::models::signorini::signorini_p1::Model>(true);
}

/// A P1 multiplier's constraint sits on a vertex shared by two contact edges: its rows
/// are split between their parts, and still sum to the whole.
#[test]
fn signorini_p1_on_edges_parts_sum_to_the_whole_lcp() {
    signorini::<fem_forms::models::signorini::signorini_p1_p1::Model>(false);
}

/// A part naming a cell the mesh does not have is refused with the cell's number.
#[test]
fn a_cell_beyond_the_mesh_is_refused() {
    use fem_forms::models::membrane_p1_p0::Model as M;
    let mesh = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 2, 2, Diagonal::Alternating).unwrap();
    let data: [(&str, &DataFn); 3] = [("f", &load), ("ψ", &obstacle), ("g", &boundary)];
    let c = Coefficients::new::<M>(&[("α", 0.1)], &data).unwrap();
    let dofs = SystemDofs::all::<M>(&mesh).unwrap();
    let error = mesh
        .discretize_on::<M>(Some(&[0, 8]), &c, dofs, &Constraints::new(), &[])
        .err()
        .expect("refused");
    assert!(error.to_string().contains("cell 8"), "{error}");
}

/// One process holding every cell, as a solver that partitions would see it: its
/// reductions change nothing.
struct OneProcess;

impl fem_forms::lcp::external::ExternalSolver for OneProcess {
    fn name(&self) -> &'static str {
        "one process"
    }

    fn solve(&self, _: &Lcp, _: Option<&[f64]>) -> fem_forms::Result<fem_forms::lcp::LcpSolution> {
        Err(fem_forms::Error::Input("a test of reductions only".into()))
    }
}

/// The measures of the whole LCP on a shared one (`Lcp::share`) are computed from
/// reduced sums, not the plain loops: on one process holding every cell they must be
/// the plain ones, exactly (the KKT and complementarity residuals, the multiplier
/// scale, the rounding estimates, the contact indicator), for P0 and P1disc
/// multipliers; and a native solver refuses a shared LCP.
#[test]
fn the_measures_of_a_shared_lcp_on_one_process_are_the_whole_ones() {
    use fem_forms::lcp::external::External;
    use fem_forms::lcp::Share;
    use fem_forms::obstacle::triangle::contact_indicator;
    use fem_forms::obstacle::{solve_lcp, ObstacleOptions};
    fn check<M: Model>() {
        let mesh =
            TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 6, 6, Diagonal::Alternating).unwrap();
        let data: [(&str, &DataFn); 3] = [("f", &load), ("ψ", &obstacle), ("g", &boundary)];
        // α below ½/C_I of P2 (0.1 makes a − αS indefinite there)
        let c = Coefficients::new::<M>(&[("α", 0.01)], &data).unwrap();
        let dofs = SystemDofs::all::<M>(&mesh).unwrap();
        let constraints = fem_forms::obstacle::triangle::dirichlet_constraints_on::<M>(
            &mesh,
            &dofs,
            &c,
            &fem_forms::DirichletPart::All,
        )
        .unwrap();
        let whole = mesh
            .discretize_on::<M>(None, &c, dofs, &constraints, &[])
            .unwrap()
            .lcp;
        let s = solve_lcp(&whole, None, ObstacleOptions::default()).unwrap();
        assert!(s.lambda.iter().any(|&l| l > 0.0), "contact somewhere");
        let mut shared = whole.clone();
        shared.share = Some(Share::new(External(Box::leak(Box::new(OneProcess)))));
        let (u, l) = (&s.u, &s.lambda);
        assert_eq!(shared.kkt_residual(u, l), whole.kkt_residual(u, l));
        assert_eq!(
            shared.complementarity_residual(u, l),
            whole.complementarity_residual(u, l)
        );
        assert_eq!(shared.multiplier_scale(), whole.multiplier_scale());
        assert_eq!(shared.primal_rounding(u, l), whole.primal_rounding(u, l));
        assert_eq!(shared.elimination_noise(l), whole.elimination_noise(l));
        assert_eq!(
            contact_indicator(&shared, u, l),
            contact_indicator(&whole, u, l)
        );
        let refused = solve_lcp(&shared, None, ObstacleOptions::default()).expect_err("refused");
        assert!(refused.to_string().contains("partitioned"), "{refused}");
    }
    check::<fem_forms::models::membrane_p1_p0::Model>();
    check::<fem_forms::models::membrane_p2_p1disc::Model>();
}

/// A solver that gives this process the cells `c ≡ part (mod 3)` of each level it is
/// asked to partition (all of them for `None`) and records the LCPs it is handed:
/// a whole one (the coarsest level, never partitioned) it solves natively as the nodal
/// LCP it is, a part it records and refuses, which ends the solve there.
struct Recording {
    part: Option<usize>,
    lcps: std::sync::Mutex<Vec<Lcp>>,
}

impl fem_forms::lcp::external::ExternalSolver for Recording {
    fn name(&self) -> &'static str {
        "recording"
    }

    fn partition(
        &self,
        graph: &fem_forms::lcp::external::CellGraph,
    ) -> fem_forms::Result<Option<Vec<usize>>> {
        Ok(self
            .part
            .map(|r| (r..graph.cell_count()).step_by(3).collect()))
    }

    fn solve(
        &self,
        lcp: &Lcp,
        start: Option<&[f64]>,
    ) -> fem_forms::Result<fem_forms::lcp::LcpSolution> {
        self.lcps.lock().unwrap().push(lcp.clone());
        if lcp.share.is_some() {
            return Err(fem_forms::Error::Input("a part, recorded".into()));
        }
        // the nodal LCP: B = I, C = 0, G = ψ
        fem_forms::obstacle::nodal::nodal_active_set_level(
            &lcp.a,
            &lcp.f,
            &lcp.g,
            start,
            500,
            &[],
            true,
        )
    }
}

/// The nodal method assembled in parts (`problem::nodal`, each process its cells of
/// every level but the coarsest): over the parts `c ≡ r (mod 3)` of the second level,
/// the parts' `A` and `F` sum to the whole level's, and each constraint `U_k ≥ ψ_k` is
/// on exactly one part (its row `e_k` and `G_k = ψ_k` there), so the parts' LCPs sum to
/// the whole nodal LCP. Checked to fail when every part owns every node.
#[test]
fn the_nodal_methods_parts_sum_to_the_whole_lcp() {
    use fem_forms::lcp::external::External;
    use fem_forms::obstacle::{ObstacleOptions, VariationalSolver};
    use fem_forms::problem::{Problem, SolveOptions};
    type M = fem_forms::models::membrane_p1::Model;
    fn level_lcp(part: Option<usize>) -> Lcp {
        let coarse =
            TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 4, 4, Diagonal::Alternating).unwrap();
        let fine = coarse.refine_uniformly();
        let solver: &'static Recording = Box::leak(Box::new(Recording {
            part,
            lcps: Default::default(),
        }));
        let outcome = Problem::<M, TriangleMesh>::new(vec![coarse, fine])
            .nodal(&obstacle)
            .data("f", &load)
            .data("ψ", &obstacle)
            .data("g", &boundary)
            .boundary_data(fem_forms::DirichletPart::All)
            .options(SolveOptions {
                obstacle: ObstacleOptions {
                    solver: VariationalSolver::External(External(solver)),
                    ..ObstacleOptions::default()
                },
                ..SolveOptions::default()
            })
            .solve();
        match (&outcome, part) {
            (Ok(_), None) => {}
            (Err(e), Some(_)) => assert!(e.to_string().contains("a part, recorded"), "{e}"),
            (Err(e), None) => panic!("the whole solve: {e}"),
            (Ok(_), Some(r)) => panic!("part {r} solved"),
        }
        let mut lcps = solver.lcps.lock().unwrap();
        assert_eq!(lcps.len(), 2, "the coarse level whole, then the fine one");
        assert!(lcps[0].share.is_none(), "the coarsest level is whole");
        lcps.pop().unwrap()
    }
    let whole = level_lcp(None);
    assert!(whole.share.is_none());
    let mut sum = Blocks::default();
    let mut holders = vec![0usize; whole.m()];
    for r in 0..3 {
        let part = level_lcp(Some(r));
        assert!(part.share.is_some(), "part {r} is shared");
        assert_eq!((part.n(), part.m()), (whole.n(), whole.m()));
        sum.add(&part);
        for (k, row) in part.b_rows.iter().enumerate() {
            if !row.is_empty() {
                assert_eq!(row, [(k, 1.0)], "part {r}: constraint {k}");
                holders[k] += 1;
            } else {
                assert_eq!(
                    part.g[k], 0.0,
                    "part {r}: G of constraint {k} it does not hold"
                );
            }
        }
    }
    let mut expected = Blocks::default();
    expected.add(&whole);
    same("A", &sum.a, &expected.a);
    same("B", &sum.b, &expected.b);
    same("F", &sum.f, &expected.f);
    same("G", &sum.g, &expected.g);
    assert!(sum.c.values().all(|&c| c == 0.0));
    assert!(whole.g.iter().any(|&g| g != 0.0), "an obstacle somewhere");
    for (k, &holder) in holders.iter().enumerate() {
        assert_eq!(holder, 1, "constraint {k} is on {holder} parts");
    }
}

/// Evaluates `solved` as each part `c ≡ r (mod 3)` of a partition would
/// (`Discretization::cells`, `Lcp::share`; the reductions of one process, so each part's
/// own sums come back) and checks that the parts add up to the whole mesh's evaluation:
/// each cell's indicator (its residual terms, half of each interior edge's, its contact
/// terms), the squares of the residual estimate η and of ‖u_h‖_a, and the squared error
/// norms against `exact`. `data` by name, `markers` the model's boundary parts.
fn evaluation_parts_sum_to_whole<M: Model>(
    mut solved: fem_forms::problem::Solved<M, TriangleMesh>,
    data: &[(&str, &DataFn)],
    markers: &[Vec<u32>],
    exact: &fem_forms::problem::Exact,
) {
    use fem_forms::lcp::external::External;
    use fem_forms::lcp::Share;
    use fem_forms::problem::Domain;
    let ordered: Vec<&DataFn> = M::DATA
        .iter()
        .map(|d| {
            data.iter()
                .find(|(name, _)| name == d)
                .unwrap_or_else(|| panic!("data {d}"))
                .1
        })
        .collect();
    let field = M::constrained_field();
    let evaluate = |solution: &fem_forms::obstacle::ObstacleSolution<TriangleMesh>| {
        let estimate = fem_forms::adaptivity::triangle_estimate::<M, _>(
            solution,
            &solved.params,
            &ordered,
            Some(1.0),
            markers,
        )
        .unwrap();
        let errors = TriangleMesh::errors(solution, field, exact);
        let square = |x: Option<f64>| x.expect("measured").powi(2);
        let squares = [
            estimate.residual.powi(2),
            estimate.energy_norm.powi(2),
            square(errors.l2),
            square(errors.h1),
            square(errors.h2),
            errors.multiplier.map_or(0.0, |m| m * m),
        ];
        (estimate.indicators, squares)
    };
    let (whole_indicators, whole) = evaluate(&solved.solution);
    assert!(
        whole_indicators.iter().any(|&i| i > 0.0)
            && whole[..5].iter().all(|&s| s > 0.0)
            && (whole[5] > 0.0) == exact.multiplier.is_some(),
        "a case that measures nothing tests nothing: {whole:?}"
    );
    let cells = solved.solution.discretization.mesh.cell_count();
    let mut indicators = vec![0.0; cells];
    let mut sums = [0.0; 6];
    for part in parts(cells) {
        let d = &mut solved.solution.discretization;
        d.cells = Some(part);
        d.lcp.share = Some(Share::new(External(&OneProcess)));
        let (i, s) = evaluate(&solved.solution);
        for (sum, x) in indicators.iter_mut().zip(&i) {
            *sum += x;
        }
        for (sum, x) in sums.iter_mut().zip(&s) {
            *sum += x;
        }
    }
    let largest = whole_indicators.iter().fold(0.0f64, |m, x| m.max(*x));
    for (c, (sum, expected)) in indicators.iter().zip(&whole_indicators).enumerate() {
        assert!(
            (sum - expected).abs() <= 1e-12 * largest,
            "cell {c}: the parts' indicators sum to {sum}, the whole's is {expected}"
        );
    }
    let names = [
        "η²",
        "‖u_h‖_a²",
        "L² error²",
        "H¹ error²",
        "H² error²",
        "λ error²",
    ];
    for ((name, sum), expected) in names.iter().zip(sums).zip(whole) {
        assert!(
            (sum - expected).abs() <= 1e-12 * expected.abs().max(1e-300),
            "{name}: the parts sum to {sum}, the whole's is {expected}"
        );
    }
}

fn exact_value(x: &[f64]) -> f64 {
    x[0] * x[1] - 0.1
}

fn exact_gradient(x: &[f64]) -> [f64; 2] {
    [x[1], x[0]]
}

fn exact_hessian(_: &[f64]) -> [[f64; 2]; 2] {
    [[0.0, 1.0], [1.0, 0.0]]
}

fn exact_multiplier(x: &[f64]) -> f64 {
    1.0 + x[0]
}

const EXACT: fem_forms::problem::Exact<'static> = fem_forms::problem::Exact {
    value: &exact_value,
    gradient: Some(&exact_gradient),
    hessian: Some(&exact_hessian),
    multiplier: Some(&exact_multiplier),
};

/// The membrane of [`membrane`] solved whole, then evaluated in parts.
fn membrane_evaluated_in_parts<M: Model>() {
    use fem_forms::problem::Problem;
    let mesh = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 6, 6, Diagonal::Alternating).unwrap();
    let data: [(&str, &DataFn); 3] = [("f", &load), ("ψ", &obstacle), ("g", &boundary)];
    let solved = Problem::<M, TriangleMesh>::new(vec![mesh])
        .data("f", &load)
        .data("ψ", &obstacle)
        .data("g", &boundary)
        .boundary_data(fem_forms::DirichletPart::All)
        .solve()
        .unwrap();
    assert!(solved.report.total_contact_force > 0.0, "contact somewhere");
    evaluation_parts_sum_to_whole(solved, &data, &[], &EXACT);
}

/// The estimate and the error norms over each process's own cells add up to the whole
/// mesh's (what lets each MPI rank evaluate only its cells, the report's numbers then
/// reduced): P0 multipliers. Checked to fail when every part evaluates every cell and
/// when an interior edge is counted by both its cells' parts.
#[test]
fn membrane_p1_p0_evaluation_parts_sum_to_the_whole() {
    membrane_evaluated_in_parts::<fem_forms::models::membrane_p1_p0::Model>();
}

/// P2 displacements and P1disc multipliers (the contact terms' defect per cell).
#[test]
fn membrane_p2_p1disc_evaluation_parts_sum_to_the_whole() {
    membrane_evaluated_in_parts::<fem_forms::models::membrane_p2_p1disc::Model>();
}

/// Signorini contact (the multiplier on the bottom edges, P0): the boundary parts'
/// indicators and the contact terms of a multiplier on edges go with their edge's cell.
#[test]
fn signorini_evaluation_parts_sum_to_the_whole() {
    use fem_forms::models::signorini::signorini_p1::Model as M;
    use fem_forms::problem::{Condition, Problem};
    let mesh = TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, 6, 6, Diagonal::Alternating).unwrap();
    let pressure = |_: &[f64]| 50.0;
    let data: [(&str, &DataFn); 2] = [("q", &pressure), ("g", &gap)];
    let solved = Problem::<M, TriangleMesh>::new(vec![mesh])
        .param("μ_L", 400.0)
        .param("λ_L", 600.0)
        .param("n_c_x", 0.0)
        .param("n_c_y", -1.0)
        .data("q", &pressure)
        .data("g", &gap)
        .part("Γ_C", vec![1])
        .part("Γ_N", vec![3])
        // held without contact (the native solver starts from zero): u_x = 0 on the
        // left, u_y = 0 on the right
        .support(
            fem_forms::DirichletPart::Markers(vec![4]),
            "u_x",
            Condition::Zero,
        )
        .support(
            fem_forms::DirichletPart::Markers(vec![2]),
            "u_y",
            Condition::Zero,
        )
        .solve()
        .unwrap();
    assert!(solved.report.total_contact_force > 0.0, "contact somewhere");
    let exact = fem_forms::problem::Exact {
        multiplier: None,
        ..EXACT
    };
    evaluation_parts_sum_to_whole(solved, &data, &[vec![1], vec![3]], &exact);
}
