use super::*;
use crate::assembly::boundary::{Constraints, Reduction};
use crate::assembly::dof_map::{DofMap, SystemDofs};
use crate::element::mapping::Affine;
use crate::mesh::{Diagonal, TriangleMesh};
use crate::model::Model;
use faer::sparse::{SparseColMat, Triplet};

crate::model! {
    /// −Δu = f with P1 (only its DOF layout is used here).
    pub mod laplace_p1 on triangle {
        unknowns: u: P1;
        tests: v;
        data: f: 1, g;
        boundary: u = g;
        forms: "
            a(u;v) = ∫ ∇u·∇v
            ℓ(v)   = ∫ f v
        ";
    }
}

crate::model! {
    /// −Δu = f with P2.
    pub mod laplace_p2 on triangle {
        unknowns: u: P2;
        tests: v;
        data: f: 1, g;
        boundary: u = g;
        forms: "
            a(u;v) = ∫ ∇u·∇v
            ℓ(v)   = ∫ f v
        ";
    }
}

crate::model! {
    /// A P3 field and a P0 multiplier, for the prolongation of a two-field system.
    pub mod mixed_p3_p0 on triangle {
        unknowns: u: P3, λ: P0 >= 0;
        tests: v, μ;
        forms: "
            B_h(u,λ;v,μ) = ∫ ∇u·∇v − ∫ v λ − ∫ u μ
            L_h(v,μ)     = ∫ v
        ";
    }
}

fn unit_square(n: usize, diagonal: Diagonal) -> TriangleMesh {
    TriangleMesh::rectangle(0.0, 1.0, 0.0, 1.0, n, n, diagonal).unwrap()
}

/// `levels` nested meshes, coarse (2 × 2 squares) to fine, by uniform refinement.
fn hierarchy(levels: usize, diagonal: Diagonal) -> Vec<TriangleMesh> {
    let mut meshes = vec![unit_square(2, diagonal)];
    for _ in 1..levels {
        let next = meshes.last().unwrap().refine_uniformly();
        meshes.push(next);
    }
    meshes
}

/// The stiffness matrix `∫ ∇φ_i·∇φ_j` of one field, assembled here from the reference
/// basis and the affine map (independent of the generated kernels).
fn stiffness(mesh: &TriangleMesh, map: &DofMap) -> SparseMatrix {
    let basis = map.element().triangle_basis();
    let gradients: Vec<[fem_reference::triangle::Polynomial2; 2]> = basis
        .iter()
        .map(|phi| [phi.derivative(1, 0), phi.derivative(0, 1)])
        .collect();
    let rule = fem_reference::triangle::TriangleRule::exact_for_degree(2 * map.element().degree());
    let mut triplets = Vec::new();
    for c in 0..mesh.cell_count() {
        let cell = Affine::of(mesh, c);
        let dofs = map.cell_dofs(c);
        for (q, &xi) in rule.points.iter().enumerate() {
            let w = rule.weights[q] * cell.det;
            let g: Vec<[f64; 2]> = gradients
                .iter()
                .map(|[gx, gy]| cell.gradient([gx.eval(xi), gy.eval(xi)]))
                .collect();
            for (i, gi) in g.iter().enumerate() {
                for (j, gj) in g.iter().enumerate() {
                    let v = w * (gi[0] * gj[0] + gi[1] * gj[1]);
                    triplets.push(Triplet::new(dofs[i], dofs[j], v));
                }
            }
        }
    }
    SparseColMat::try_new_from_triplets(map.dof_count(), map.dof_count(), &triplets).unwrap()
}

/// A Dirichlet Laplacian level: DOFs, reduction and reduced matrix.
struct Laplace {
    dofs: SystemDofs,
    reduction: Reduction,
    a: SparseMatrix,
}

fn laplace<M: Model>(mesh: &TriangleMesh) -> Laplace {
    let dofs = SystemDofs::all::<M>(mesh).unwrap();
    let map = dofs.map(0).unwrap();
    let mut constraints = Constraints::new();
    for d in map.boundary_dofs(mesh) {
        constraints.fix_dof(d, 0.0).unwrap();
    }
    let reduction = constraints.reduction(dofs.dof_count()).unwrap();
    let a = reduction.matrix(&stiffness(mesh, map));
    Laplace { dofs, reduction, a }
}

/// The fine matrix and the prolongations (fine to coarse) of a Dirichlet Laplacian on
/// nested meshes, and the level data.
fn laplace_hierarchy<M: Model>(meshes: &[TriangleMesh]) -> (Vec<Laplace>, Vec<SparseMatrix>) {
    let levels: Vec<Laplace> = meshes.iter().map(laplace::<M>).collect();
    let mut prolongations = Vec::new();
    for l in (1..meshes.len()).rev() {
        let parents = parents_by_location(&meshes[l - 1], &meshes[l]).unwrap();
        let coarse = NestedLevel {
            mesh: &meshes[l - 1],
            dofs: &levels[l - 1].dofs,
            reduction: Some(&levels[l - 1].reduction),
        };
        let fine = NestedLevel {
            mesh: &meshes[l],
            dofs: &levels[l].dofs,
            reduction: Some(&levels[l].reduction),
        };
        prolongations.push(prolongation(&coarse, &fine, &parents).unwrap());
    }
    (levels, prolongations)
}

/// Values of `q` at every DOF node of `dofs` (fields stacked).
fn interpolate(mesh: &TriangleMesh, dofs: &SystemDofs, q: &dyn Fn([f64; 2]) -> f64) -> Vec<f64> {
    let mut out = vec![0.0; dofs.dof_count()];
    for &f in dofs.fields() {
        let offset = dofs.offset(f).unwrap();
        for (d, x) in dofs.map(f).unwrap().nodes(mesh).into_iter().enumerate() {
            out[offset + d] = q(x);
        }
    }
    out
}

fn max_difference(x: &[f64], y: &[f64]) -> f64 {
    x.iter()
        .zip(y)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
}

/// Prolongation of a global polynomial of the element's degree reproduces it at every
/// fine node, after uniform and after local refinement: P1, P2, and a two-field P3 + P0
/// system (a constant on both fields, a cubic on the P3 rows).
#[test]
fn prolongation_reproduces_polynomials_of_the_degree() {
    let quadratic = |[x, y]: [f64; 2]| 0.3 + x - 2.0 * y + 1.5 * x * x - 0.7 * x * y + 2.0 * y * y;
    let linear = |[x, y]: [f64; 2]| 0.3 + x - 2.0 * y;
    for diagonal in [Diagonal::Right, Diagonal::Alternating, Diagonal::Crossed] {
        let coarse = unit_square(3, diagonal);
        let uniform = coarse.refine_uniformly();
        let uniform_parents = parents_by_location(&coarse, &uniform).unwrap();
        let (local, local_parents) = coarse.refine(&[0, 4, 5]).unwrap();
        // the located parents agree with the ones refinement records
        assert_eq!(parents_by_location(&coarse, &local).unwrap(), local_parents);
        for (fine, parents) in [(&uniform, &uniform_parents), (&local, &local_parents)] {
            fn check<M: Model>(
                coarse: &TriangleMesh,
                fine: &TriangleMesh,
                parents: &[usize],
                q: &dyn Fn([f64; 2]) -> f64,
            ) {
                let (dc, df) = (
                    SystemDofs::all::<M>(coarse).unwrap(),
                    SystemDofs::all::<M>(fine).unwrap(),
                );
                let p = prolongation(
                    &NestedLevel {
                        mesh: coarse,
                        dofs: &dc,
                        reduction: None,
                    },
                    &NestedLevel {
                        mesh: fine,
                        dofs: &df,
                        reduction: None,
                    },
                    parents,
                )
                .unwrap();
                assert_eq!((p.nrows(), p.ncols()), (df.dof_count(), dc.dof_count()));
                let fine_values = crate::lcp::cholesky::multiply(&p, &interpolate(coarse, &dc, q));
                let error = max_difference(&fine_values, &interpolate(fine, &df, q));
                assert!(error < 1e-13, "{}: error {error:e}", M::NAME);
            }
            check::<laplace_p1::Model>(&coarse, fine, parents, &linear);
            check::<laplace_p2::Model>(&coarse, fine, parents, &quadratic);
            // P3 and P0 on one system: a constant is exact for both, a cubic for P3 is
            // checked on its own rows
            check::<mixed_p3_p0::Model>(&coarse, fine, parents, &|_| 2.5);
            let cubic = |[x, y]: [f64; 2]| x * x * x - 2.0 * x * y * y + y - 0.5;
            let (dc, df) = (
                SystemDofs::all::<mixed_p3_p0::Model>(&coarse).unwrap(),
                SystemDofs::all::<mixed_p3_p0::Model>(fine).unwrap(),
            );
            let p = prolongation(
                &NestedLevel {
                    mesh: &coarse,
                    dofs: &dc,
                    reduction: None,
                },
                &NestedLevel {
                    mesh: fine,
                    dofs: &df,
                    reduction: None,
                },
                parents,
            )
            .unwrap();
            let fine_values =
                crate::lcp::cholesky::multiply(&p, &interpolate(&coarse, &dc, &cubic));
            let u = df.range(0).unwrap();
            let error = max_difference(&fine_values[u.clone()], &interpolate(fine, &df, &cubic)[u]);
            assert!(error < 1e-13, "P3: error {error:e}");
        }
    }
}

/// A P1 function that is not linear is not reproduced by an interpolation of the wrong
/// degree: the check above can fail (a P1 prolongation of a quadratic is off at edge
/// midpoints by `h²/8 · ∂²q`).
#[test]
fn prolongation_of_p1_is_not_exact_for_quadratics() {
    let coarse = unit_square(2, Diagonal::Right);
    let fine = coarse.refine_uniformly();
    let parents = parents_by_location(&coarse, &fine).unwrap();
    let (dc, df) = (
        SystemDofs::all::<laplace_p1::Model>(&coarse).unwrap(),
        SystemDofs::all::<laplace_p1::Model>(&fine).unwrap(),
    );
    let p = prolongation(
        &NestedLevel {
            mesh: &coarse,
            dofs: &dc,
            reduction: None,
        },
        &NestedLevel {
            mesh: &fine,
            dofs: &df,
            reduction: None,
        },
        &parents,
    )
    .unwrap();
    let q = |[x, _]: [f64; 2]| x * x;
    let fine_values = crate::lcp::cholesky::multiply(&p, &interpolate(&coarse, &dc, &q));
    // a midpoint of a horizontal coarse edge of length ½: error (½)²/4 = 1/16
    let error = max_difference(&fine_values, &interpolate(&fine, &df, &q));
    assert!((error - 1.0 / 16.0).abs() < 1e-14, "{error}");
}

/// Nested conforming spaces: the Galerkin operator `PᵀA_fP` of the fine Dirichlet
/// stiffness matrix is the coarse stiffness matrix assembled directly (an identity
/// that needs the prolongation, the reductions and the triple product all right).
#[test]
fn galerkin_operator_is_the_coarse_stiffness_matrix() {
    fn check<M: Model>() {
        let meshes = hierarchy(3, Diagonal::Alternating);
        let (levels, prolongations) = laplace_hierarchy::<M>(&meshes);
        let mg = Multigrid::new(
            levels[2].a.clone(),
            prolongations,
            MultigridOptions::default(),
        )
        .unwrap();
        assert_eq!(mg.level_count(), 3);
        for l in 1..3 {
            let galerkin = mg.operator(l).unwrap().to_dense();
            let direct = levels[2 - l].a.to_dense();
            let scale = direct.norm_max();
            let difference = (&galerkin - &direct).norm_max();
            assert!(
                difference < 1e-13 * scale,
                "{} level {l}: {difference:e}",
                M::NAME
            );
        }
    }
    check::<laplace_p1::Model>();
    check::<laplace_p2::Model>();
}

/// PCG iterations to 1e-10 for a hierarchy of each depth, and the largest relative
/// difference from the Cholesky solution. The right-hand side is the load `f = 1`
/// lumped to the nodes plus a fixed pseudo-random part (all frequencies present).
fn pcg_runs<M: Model>(
    depths: std::ops::RangeInclusive<usize>,
    active: Option<f64>,
    sweeps: usize,
) -> Vec<(usize, usize, f64)> {
    let meshes = hierarchy(*depths.end(), Diagonal::Right);
    let (levels, prolongations) = laplace_hierarchy::<M>(&meshes);
    let mut out = Vec::new();
    for depth in depths {
        let fine = &levels[depth - 1];
        let n = fine.a.nrows();
        let mut a = fine.a.clone();
        if let Some(weight) = active {
            a = with_active_set(&a, weight, depth as u64);
        }
        // prolongations are stored fine to coarse for the deepest hierarchy
        let skip = levels.len() - depth;
        let ps = prolongations[skip..].to_vec();
        let mg = Multigrid::new(
            a.clone(),
            ps,
            MultigridOptions {
                sweeps,
                ..Default::default()
            },
        )
        .unwrap();
        let mut seed = 12345u64;
        let b: Vec<f64> = (0..n)
            .map(|_| 1.0 / n as f64 + 0.5 / n as f64 * (random(&mut seed) - 0.5))
            .collect();
        let solution = mg.pcg(&b, 1e-10, 100).unwrap();
        let direct = crate::lcp::cholesky::solve_spd(&a, &b).unwrap();
        let scale = direct.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let difference = max_difference(&solution.x, &direct) / scale;
        // the residual is the true one, not only the recurrence's
        let ax = crate::lcp::cholesky::multiply(&a, &solution.x);
        let residual: f64 = ax
            .iter()
            .zip(&b)
            .map(|(p, q)| (p - q) * (p - q))
            .sum::<f64>()
            .sqrt()
            / b.iter().map(|v| v * v).sum::<f64>().sqrt();
        assert!(
            residual < 2e-10,
            "{} depth {depth}: residual {residual:e}",
            M::NAME
        );
        out.push((n, solution.iterations, difference));
    }
    out
}

/// Uniform in (0, 1) from a 64-bit LCG (Knuth's MMIX constants).
fn random(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*state >> 11) as f64 / (1u64 << 53) as f64
}

/// `A + D` with `D_ii = weight · A_ii` on a pseudo-random third of the DOFs: the shape
/// of the Newton Hessian's active-set term `Bᵀ C_I⁻¹ B` for a nodal constraint.
fn with_active_set(a: &SparseMatrix, weight: f64, seed: u64) -> SparseMatrix {
    let mut state = seed;
    let d = sparse::diagonal(a);
    let mut triplets = Vec::new();
    for j in 0..a.ncols() {
        let (col_ptr, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
        for k in col_ptr[j]..col_ptr[j + 1] {
            triplets.push(Triplet::new(rows[k], j, vals[k]));
        }
        if random(&mut state) < 1.0 / 3.0 {
            triplets.push(Triplet::new(j, j, weight * d[j].unwrap()));
        }
    }
    SparseColMat::try_new_from_triplets(a.nrows(), a.ncols(), &triplets).unwrap()
}

fn check_bounded(name: &str, runs: &[(usize, usize, f64)]) {
    eprintln!("{name}: (unknowns, PCG iterations, difference from Cholesky) {runs:?}");
    for &(n, iterations, difference) in runs {
        assert!(
            iterations <= 15,
            "{name}: {iterations} iterations at n = {n}"
        );
        assert!(
            difference < 1e-9,
            "{name}: {difference:e} from Cholesky at n = {n}"
        );
    }
    let [.., (_, before), (_, last)] = runs.iter().map(|r| (r.0, r.1)).collect::<Vec<_>>()[..]
    else {
        panic!("at least two depths")
    };
    assert!(
        last <= before + 2,
        "{name}: iterations grow {before} → {last}"
    );
}

#[test]
fn pcg_iterations_are_bounded_for_the_p1_laplacian() {
    check_bounded("P1", &pcg_runs::<laplace_p1::Model>(4..=7, None, 1));
}

#[test]
fn pcg_iterations_are_bounded_for_the_p2_laplacian() {
    check_bounded("P2", &pcg_runs::<laplace_p2::Model>(4..=6, None, 1));
}

/// The active-set term of the Newton Hessian of the P1–P0 membrane, `Bᵀ C_I⁻¹ B` with
/// `B ~ |T|` and `C ~ α h²|T|`, is of the order of `A`'s diagonal over `α`: weight 10,
/// one sweep (measured: P1 9, 11, 12, 13; P2 12, 14, 14 — bounded, but the P1 count
/// still creeps up by one a level). Weight 10⁴ makes the chosen nodes nearly Dirichlet
/// nodes scattered at random, a coefficient jump at every other node that linear
/// interpolation does not see (harder than a contiguous contact set): one sweep reaches
/// 18 for P2 at 16129 unknowns, two sweeps give P1 7, 9, 9, 10 and P2 10, 12, 13.
#[test]
fn pcg_iterations_are_bounded_with_an_active_set_term() {
    check_bounded(
        "P1 + active 10",
        &pcg_runs::<laplace_p1::Model>(4..=7, Some(10.0), 1),
    );
    check_bounded(
        "P2 + active 10",
        &pcg_runs::<laplace_p2::Model>(4..=6, Some(10.0), 1),
    );
    check_bounded(
        "P1 + active 1e4",
        &pcg_runs::<laplace_p1::Model>(4..=7, Some(1e4), 2),
    );
    check_bounded(
        "P2 + active 1e4",
        &pcg_runs::<laplace_p2::Model>(4..=6, Some(1e4), 2),
    );
}

/// Without the coarse correction (one level) the same PCG needs many more iterations
/// on the fine level: the bounded counts above come from the hierarchy.
#[test]
fn one_level_is_much_slower() {
    let meshes = hierarchy(6, Diagonal::Right);
    let fine = laplace::<laplace_p1::Model>(&meshes[5]);
    let n = fine.a.nrows();
    let b = vec![1.0 / n as f64; n];
    // a Cholesky "multigrid" of one level converges in one iteration
    let direct = Multigrid::new(fine.a.clone(), Vec::new(), MultigridOptions::default()).unwrap();
    assert_eq!(direct.pcg(&b, 1e-10, 5).unwrap().iterations, 1);
    let prolongations = laplace_hierarchy::<laplace_p1::Model>(&meshes).1;
    let deep = Multigrid::new(fine.a.clone(), prolongations, MultigridOptions::default()).unwrap();
    assert_eq!(deep.level_count(), 6);
    let deep_iterations = deep.pcg(&b, 1e-10, 100).unwrap().iterations;
    // symmetric Gauss–Seidel alone as the preconditioner needs O(h⁻¹) iterations
    let mut iterations = 0;
    let mut x = vec![0.0; n];
    let mut r = b.clone();
    let ginv = inverse_diagonal(&fine.a, 0).unwrap();
    let precondition = |r: &[f64]| {
        let mut z = vec![0.0; n];
        sparse::gauss_seidel(&fine.a, &ginv, r, &mut z, true);
        sparse::gauss_seidel(&fine.a, &ginv, r, &mut z, false);
        z
    };
    let mut z = precondition(&r);
    let mut p = z.clone();
    let mut rz = dot(&r, &z);
    let nb = norm(&b);
    while norm(&r) > 1e-10 * nb && iterations < 1000 {
        let q = crate::lcp::cholesky::multiply(&fine.a, &p);
        let alpha = rz / dot(&p, &q);
        for i in 0..n {
            x[i] += alpha * p[i];
            r[i] -= alpha * q[i];
        }
        z = precondition(&r);
        let next = dot(&r, &z);
        for i in 0..n {
            p[i] = z[i] + next / rz * p[i];
        }
        rz = next;
        iterations += 1;
    }
    assert!(
        iterations > 4 * deep_iterations,
        "Gauss–Seidel-PCG {iterations}, multigrid-PCG {deep_iterations}"
    );
}

#[test]
fn bad_inputs_are_errors() {
    let meshes = hierarchy(2, Diagonal::Right);
    let (levels, prolongations) = laplace_hierarchy::<laplace_p1::Model>(&meshes);
    let a = levels[1].a.clone();
    let zero = MultigridOptions {
        sweeps: 0,
        ..Default::default()
    };
    assert!(Multigrid::new(a.clone(), prolongations.clone(), zero).is_err());
    let no_correction = MultigridOptions {
        coarse_corrections: 0,
        ..Default::default()
    };
    assert!(Multigrid::new(a.clone(), prolongations.clone(), no_correction).is_err());
    // a prolongation for another level
    let wrong = vec![prolongations[0].clone(), prolongations[0].clone()];
    let message = Multigrid::new(a.clone(), wrong, MultigridOptions::default())
        .err()
        .unwrap()
        .to_string();
    assert!(message.contains("prolongation 1"), "{message}");
    // an indefinite matrix
    let negative = SparseColMat::try_new_from_triplets(
        a.nrows(),
        a.ncols(),
        &(0..a.nrows())
            .map(|i| Triplet::new(i, i, -1.0))
            .collect::<Vec<_>>(),
    )
    .unwrap();
    assert!(Multigrid::new(negative, Vec::new(), MultigridOptions::default()).is_err());
    // a non-symmetric matrix
    let mut entries = Vec::new();
    for j in 0..a.ncols() {
        let (col_ptr, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
        for k in col_ptr[j]..col_ptr[j + 1] {
            let skew = if rows[k] < j { 0.1 } else { 0.0 };
            entries.push(Triplet::new(rows[k], j, vals[k] + skew));
        }
    }
    let skewed = SparseColMat::try_new_from_triplets(a.nrows(), a.ncols(), &entries).unwrap();
    let message = Multigrid::new(skewed, prolongations.clone(), MultigridOptions::default())
        .err()
        .unwrap()
        .to_string();
    assert!(message.contains("not symmetric"), "{message}");
    let mg = Multigrid::new(a.clone(), prolongations, MultigridOptions::default()).unwrap();
    let mut x = vec![0.0; a.nrows()];
    assert!(mg.v_cycle(&[1.0], &mut x).is_err());
    assert!(mg.v_cycle(&vec![1.0; a.nrows()], &mut [0.0]).is_err());
    assert!(mg.pcg(&[1.0], 1e-10, 10).is_err());
    assert!(mg.pcg(&vec![f64::NAN; a.nrows()], 1e-10, 10).is_err());
    assert!(mg.pcg(&vec![1.0; a.nrows()], 0.0, 10).is_err());
    assert!(mg.pcg(&vec![1.0; a.nrows()], 1e-14, 1).is_err());
    assert_eq!(
        mg.pcg(&vec![0.0; a.nrows()], 1e-10, 10).unwrap().iterations,
        0
    );
    // prolongation inputs: parents of the wrong length or out of range, a field missing
    let d0 = SystemDofs::all::<laplace_p1::Model>(&meshes[0]).unwrap();
    let d1 = SystemDofs::all::<laplace_p1::Model>(&meshes[1]).unwrap();
    let d2 = SystemDofs::all::<laplace_p2::Model>(&meshes[0]).unwrap();
    let coarse = NestedLevel {
        mesh: &meshes[0],
        dofs: &d0,
        reduction: None,
    };
    let fine = NestedLevel {
        mesh: &meshes[1],
        dofs: &d1,
        reduction: None,
    };
    assert!(prolongation(&coarse, &fine, &[0]).is_err());
    assert!(prolongation(&coarse, &fine, &vec![99; meshes[1].cell_count()]).is_err());
    let other = NestedLevel {
        mesh: &meshes[0],
        dofs: &d2,
        reduction: None,
    };
    let parents = parents_by_location(&meshes[0], &meshes[1]).unwrap();
    assert!(prolongation(&other, &fine, &parents).is_err());
    // a reduction of another system
    let foreign = Constraints::new().reduction(d0.dof_count()).unwrap();
    let reduced = NestedLevel {
        mesh: &meshes[1],
        dofs: &d1,
        reduction: Some(&foreign),
    };
    let message = prolongation(&coarse, &reduced, &parents)
        .err()
        .unwrap()
        .to_string();
    assert!(message.contains("reduction is for"), "{message}");
    let outside = TriangleMesh::rectangle(2.0, 3.0, 0.0, 1.0, 1, 1, Diagonal::Right).unwrap();
    assert!(parents_by_location(&meshes[0], &outside).is_err());
}

/// The coarse operators kept up to date by [`Multigrid::add_coarse_term`] equal the
/// Galerkin products recomputed from scratch (to 1e-12 of the largest entry) after
/// several changes of an "active set" of cell terms `u S uᵀ`: rank-one terms (a diagonal
/// `C`) and rank-two ones with a full symmetric `S` (a block of `C`), supported on one
/// fine cell's free DOFs, switched on and off at random as a Newton iteration does.
#[test]
fn updated_coarse_operators_are_the_recomputed_ones() {
    fn check<M: Model>(levels: usize) {
        let meshes = hierarchy(levels, Diagonal::Right);
        let (data, prolongations) = laplace_hierarchy::<M>(&meshes);
        let fine = data.last().unwrap();
        let mesh = meshes.last().unwrap();
        let map = fine.dofs.map(0).unwrap();
        let mut state = 7;
        // one term per fine cell: its columns (free DOFs of the cell, random weights) and S
        type Term = (Vec<Vec<(usize, f64)>>, Vec<f64>);
        let terms: Vec<Term> = (0..mesh.cell_count())
            .map(|c| {
                let free: Vec<usize> = map
                    .cell_dofs(c)
                    .iter()
                    .filter_map(|&d| fine.reduction.free_index(d))
                    .collect();
                let mut column = || -> Vec<(usize, f64)> {
                    free.iter()
                        .map(|&i| (i, 0.5 + random(&mut state)))
                        .collect()
                };
                if c % 3 == 0 {
                    let (u, v) = (column(), column());
                    // SPD: diagonal dominant
                    let off = random(&mut state);
                    (vec![u, v], vec![2.0 + off, off, off, 3.0])
                } else {
                    (vec![column()], vec![1.0 + 10.0 * random(&mut state)])
                }
            })
            .collect();
        let n = fine.a.nrows();
        let hessian = |active: &[bool]| -> SparseMatrix {
            let (col_ptr, rows, vals) = (
                fine.a.symbolic().col_ptr(),
                fine.a.symbolic().row_idx(),
                fine.a.val(),
            );
            let mut triplets: Vec<Triplet<usize, usize, f64>> = (0..n)
                .flat_map(|j| {
                    (col_ptr[j]..col_ptr[j + 1]).map(move |k| Triplet::new(rows[k], j, vals[k]))
                })
                .collect();
            for ((columns, s), _) in terms.iter().zip(active).filter(|(_, &on)| on) {
                let q = columns.len();
                for (x, u) in columns.iter().enumerate() {
                    for (y, v) in columns.iter().enumerate() {
                        for &(i, ui) in u {
                            for &(j, vj) in v {
                                triplets.push(Triplet::new(i, j, s[x * q + y] * ui * vj));
                            }
                        }
                    }
                }
            }
            SparseColMat::try_new_from_triplets(n, n, &triplets).unwrap()
        };
        let mut active: Vec<bool> = (0..terms.len()).map(|_| random(&mut state) < 0.3).collect();
        let options = MultigridOptions::default();
        let mut mg = Multigrid::new(hessian(&active), prolongations.clone(), options).unwrap();
        for round in 0..4 {
            let previous = active.clone();
            for flag in active.iter_mut() {
                if random(&mut state) < 0.2 {
                    *flag = !*flag;
                }
            }
            for ((columns, s), (&was, &is)) in terms.iter().zip(previous.iter().zip(&active)) {
                if was != is {
                    let sign = if is { 1.0 } else { -1.0 };
                    let s: Vec<f64> = s.iter().map(|v| sign * v).collect();
                    let columns: Vec<&[(usize, f64)]> = columns.iter().map(|c| &c[..]).collect();
                    mg.add_coarse_term(&columns, &s).unwrap();
                }
            }
            let h = hessian(&active);
            mg.reset_fine(&h).unwrap();
            let fresh = Multigrid::new(h, prolongations.clone(), options).unwrap();
            for l in 0..mg.level_count() {
                let (updated, expected) = (mg.operator(l).unwrap(), fresh.operator(l).unwrap());
                assert_eq!(updated.symbolic().col_ptr(), expected.symbolic().col_ptr());
                assert_eq!(updated.symbolic().row_idx(), expected.symbolic().row_idx());
                let scale = expected.val().iter().fold(0.0f64, |m, v| m.max(v.abs()));
                let worst = updated
                    .val()
                    .iter()
                    .zip(expected.val())
                    .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
                assert!(
                    worst <= 1e-12 * scale,
                    "{} round {round} level {l}: updated operator off by {worst:e} of {scale:e}",
                    M::NAME
                );
            }
            // the updated hierarchy still preconditions: CG reaches the tolerance
            let b: Vec<f64> = (0..n).map(|_| random(&mut state) - 0.5).collect();
            let pcg = mg.pcg(&b, 1e-10, 60).unwrap();
            let reference = fresh.pcg(&b, 1e-10, 60).unwrap();
            assert!(pcg.iterations.abs_diff(reference.iterations) <= 1);
        }
        // terms outside the hierarchy's order are refused
        assert!(mg.add_coarse_term(&[&[(n, 1.0)]], &[1.0]).is_err());
        assert!(mg.add_coarse_term(&[&[(0, 1.0)]], &[1.0, 2.0]).is_err());
    }
    check::<laplace_p1::Model>(4);
    check::<laplace_p2::Model>(4);
}

/// The free–free block taken from the all-DOF prolongation is the prolongation built
/// with both reductions (pattern and values, bitwise), for P1 and P2 with Dirichlet
/// boundaries; a prolongation of another shape is refused.
#[test]
fn reduced_prolongation_is_the_prolongation_between_reduced_levels() {
    fn check<M: Model>(meshes: &[TriangleMesh]) {
        let (coarse_mesh, fine_mesh) = (&meshes[1], &meshes[2]);
        let (coarse, fine) = (laplace::<M>(coarse_mesh), laplace::<M>(fine_mesh));
        let parents = parents_by_location(coarse_mesh, fine_mesh).unwrap();
        fn level<'a>(mesh: &'a TriangleMesh, level: &'a Laplace, reduced: bool) -> NestedLevel<'a> {
            NestedLevel {
                mesh,
                dofs: &level.dofs,
                reduction: reduced.then_some(&level.reduction),
            }
        }
        let all = prolongation(
            &level(coarse_mesh, &coarse, false),
            &level(fine_mesh, &fine, false),
            &parents,
        )
        .unwrap();
        let direct = prolongation(
            &level(coarse_mesh, &coarse, true),
            &level(fine_mesh, &fine, true),
            &parents,
        )
        .unwrap();
        let filtered = reduced_prolongation(&all, &coarse.reduction, &fine.reduction).unwrap();
        assert!(direct.val().len() < all.val().len());
        assert_eq!(
            (filtered.nrows(), filtered.ncols()),
            (direct.nrows(), direct.ncols())
        );
        assert_eq!(filtered.symbolic().col_ptr(), direct.symbolic().col_ptr());
        assert_eq!(filtered.symbolic().row_idx(), direct.symbolic().row_idx());
        assert_eq!(filtered.val(), direct.val());
        let e = reduced_prolongation(&all, &fine.reduction, &coarse.reduction).unwrap_err();
        assert!(e.to_string().contains("reductions of"), "{e}");
    }
    let meshes = hierarchy(3, Diagonal::Right);
    check::<laplace_p1::Model>(&meshes);
    check::<laplace_p2::Model>(&meshes);
}

/// Checks every coarse operator of `mg` against the Galerkin products of `fine` with
/// `truncated` (the hierarchy as first built) whose finest rows outside `kept` are
/// emptied: equal to 1e-12 of the largest entry where both DOFs have a kept fine DOF
/// under them, unit rows where not (exactly zero in the products), no entry of the
/// products missing. Returns how many coarse DOFs lost their support.
fn check_emptied(
    name: &str,
    mg: &Multigrid,
    fine: &SparseMatrix,
    mut truncated: Vec<SparseMatrix>,
    kept: &[bool],
) -> usize {
    {
        let (symbolic, values) = truncated[0].parts_mut();
        for (v, &i) in values.iter_mut().zip(symbolic.row_idx()) {
            if !kept[i] {
                *v = 0.0;
            }
        }
    }
    let mut reference = fine.clone();
    let mut dead_total = 0;
    for (l, p) in truncated.iter().enumerate() {
        reference = sparse::galerkin(&reference, p);
        let updated = mg.operator(l + 1).unwrap();
        assert_eq!(updated.nrows(), reference.nrows());
        let (r_ptr, r_rows) = (
            reference.symbolic().col_ptr(),
            reference.symbolic().row_idx(),
        );
        let (u_ptr, u_rows) = (updated.symbolic().col_ptr(), updated.symbolic().row_idx());
        let dead: Vec<bool> = sparse::diagonal(&reference)
            .iter()
            .map(|d| d.is_none_or(|d| d == 0.0))
            .collect();
        dead_total += dead.iter().filter(|&&d| d).count();
        let scale = reference.val().iter().fold(0.0f64, |m, v| m.max(v.abs()));
        // the updated pattern holds the reference's (the old fine operator coupled
        // more), entries outside it are zero
        for j in 0..reference.ncols() {
            let column = &r_rows[r_ptr[j]..r_ptr[j + 1]];
            let range = u_ptr[j]..u_ptr[j + 1];
            for (&i, &got) in u_rows[range.clone()].iter().zip(&updated.val()[range]) {
                let want = if dead[i] || dead[j] {
                    if i == j {
                        1.0
                    } else {
                        0.0
                    }
                } else {
                    column
                        .binary_search(&i)
                        .map_or(0.0, |at| reference.val()[r_ptr[j] + at])
                };
                assert!(
                    (got - want).abs() <= 1e-12 * scale,
                    "{name} level {}: entry ({i}, {j}) is {got}, expected {want}",
                    l + 1
                );
            }
            for &i in column {
                assert!(
                    u_rows[u_ptr[j]..u_ptr[j + 1]].binary_search(&i).is_ok(),
                    "{name} level {}: entry ({i}, {j}) missing",
                    l + 1
                );
            }
        }
    }
    dead_total
}

/// `a` with the rows and columns of the `fixed` DOFs decoupled (their diagonal kept):
/// the nodal method's reduced matrix.
fn decoupled(a: &SparseMatrix, fixed: &[bool]) -> SparseMatrix {
    let (col_ptr, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    let triplets: Vec<Triplet<usize, usize, f64>> = (0..a.ncols())
        .flat_map(|j| {
            (col_ptr[j]..col_ptr[j + 1])
                .filter(move |&k| rows[k] == j || !(fixed[rows[k]] || fixed[j]))
                .map(move |k| Triplet::new(rows[k], j, vals[k]))
        })
        .collect();
    SparseColMat::try_new_from_triplets(a.nrows(), a.ncols(), &triplets).unwrap()
}

/// A hierarchy truncated on one active set and then, by `truncate_fine`, on more
/// nodes has the Galerkin operators of the finest prolongation with those rows emptied
/// (computed here by the products, same coarse numbering), to 1e-12; its coarse DOFs
/// left without a kept fine DOF under them (exactly zero there) are unit rows; nodes
/// freed again stay truncated; and it still preconditions CG on the new matrix.
#[test]
fn truncating_further_gives_the_galerkin_operators_of_the_emptied_prolongation() {
    use crate::obstacle::nodal::truncated_hierarchy;
    fn check<M: Model>(levels: usize) {
        let meshes = hierarchy(levels, Diagonal::Right);
        let (data, prolongations) = laplace_hierarchy::<M>(&meshes);
        let a = &data.last().unwrap().a;
        let n = a.nrows();
        let mut state = 11;
        // a contact set in a disc, as an obstacle makes it, and a few more nodes
        let nodes = data
            .last()
            .unwrap()
            .dofs
            .map(0)
            .unwrap()
            .nodes(meshes.last().unwrap());
        let free = data.last().unwrap().reduction.free();
        let first: Vec<bool> = free
            .iter()
            .map(|&d| {
                let [x, y] = nodes[d];
                (x - 0.4).powi(2) + (y - 0.5).powi(2) < 0.09
            })
            .collect();
        // the disc grown (coarse DOFs inside lose their whole support), a few nodes
        // more, a few freed again
        let mut second: Vec<bool> = free
            .iter()
            .map(|&d| {
                let [x, y] = nodes[d];
                (x - 0.4).powi(2) + (y - 0.5).powi(2) < 0.16
            })
            .collect();
        for flag in second.iter_mut() {
            let r = random(&mut state);
            if r < 0.08 {
                *flag = true;
            } else if *flag && r < 0.2 {
                // freed again
                *flag = false;
            }
        }
        let options = MultigridOptions::default();
        let truncated = truncated_hierarchy(&prolongations, &first);
        let mut mg =
            Multigrid::new_symmetric(decoupled(a, &first), truncated.clone(), options).unwrap();
        let mut kept: Vec<bool> = first.iter().map(|&f| !f).collect();
        let removed: Vec<usize> = (0..n).filter(|&i| second[i] && kept[i]).collect();
        assert!(!removed.is_empty());
        let fine = decoupled(a, &second);
        mg.truncate_fine(a, &mut kept, &removed).unwrap();
        mg.replace_fine(fine.clone()).unwrap();
        for i in 0..n {
            assert_eq!(kept[i], !(first[i] || second[i]), "node {i}");
        }
        // the reference: the same prolongations with the rows of `removed` emptied
        let dead_total = check_emptied(M::NAME, &mg, &fine, truncated, &kept);
        assert!(
            dead_total > 0,
            "{}: no coarse DOF lost its support",
            M::NAME
        );
        let b: Vec<f64> = (0..n).map(|_| random(&mut state) - 0.5).collect();
        let fresh = Multigrid::new_symmetric(
            fine.clone(),
            truncated_hierarchy(&prolongations, &second),
            options,
        )
        .unwrap();
        let updated = mg.pcg(&b, 1e-10, 60).unwrap();
        let rebuilt = fresh.pcg(&b, 1e-10, 60).unwrap();
        assert!(
            updated.iterations <= rebuilt.iterations + 3,
            "{}: {} CG iterations with the updated hierarchy, {} with a new one",
            M::NAME,
            updated.iterations,
            rebuilt.iterations
        );
        // a second update on the updated hierarchy: the disc grown again
        let third: Vec<bool> = free
            .iter()
            .zip(&second)
            .map(|(&d, &was)| {
                let [x, y] = nodes[d];
                was || (x - 0.4).powi(2) + (y - 0.5).powi(2) < 0.2
            })
            .collect();
        let before = kept.clone();
        let removed: Vec<usize> = (0..n).filter(|&i| third[i] && kept[i]).collect();
        assert!(!removed.is_empty());
        let fine = decoupled(a, &third);
        mg.truncate_fine(a, &mut kept, &removed).unwrap();
        mg.replace_fine(fine.clone()).unwrap();
        let name = format!("{} second update", M::NAME);
        check_emptied(
            &name,
            &mg,
            &fine,
            truncated_hierarchy(&prolongations, &first),
            &kept,
        );
        assert!(kept.iter().zip(&before).all(|(&k, &b)| !k || b));
        // sizes that do not fit are refused
        assert!(mg.truncate_fine(a, &mut vec![true; n + 1], &[]).is_err());
        assert!(mg.truncate_fine(a, &mut kept, &[n]).is_err());
    }
    check::<laplace_p1::Model>(5);
    check::<laplace_p2::Model>(4);
}

/// A one-level hierarchy (a factorization of its matrix's pattern) refuses a new fine
/// operator, and gives that operator back, not the one it was built on.
#[test]
fn a_one_level_hierarchy_gives_back_the_refused_fine_operator() {
    let meshes = hierarchy(3, Diagonal::Right);
    let (data, _) = laplace_hierarchy::<laplace_p1::Model>(&meshes);
    let a = data.last().unwrap().a.clone();
    let n = a.nrows();
    let fixed: Vec<bool> = (0..n).map(|i| i % 3 == 0).collect();
    let mut mg = Multigrid::new(a.clone(), Vec::new(), MultigridOptions::default()).unwrap();
    let mut kept = vec![true; n];
    assert!(mg.truncate_fine(&a, &mut kept, &[0]).is_ok());
    let next = decoupled(&a, &fixed);
    assert!(mg.replace_fine(next.clone()).is_err());
    let back = mg.into_fine();
    assert_eq!(back.symbolic().row_idx(), next.symbolic().row_idx());
    assert_eq!(back.val(), next.val());
}
