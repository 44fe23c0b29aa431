//! SNESVI through the safe layer on a problem with a known answer, on however many
//! ranks `mpirun -n N` starts (`.ci/run`: 1, 2 and 3): the 1D obstacle problem
//! `−u'' = f` on (0, 1), `u(0) = u(1) = 0`, `u ≥ ψ`, by the 3-point scheme on n interior
//! nodes (multiplied by h², so that the residual and the distance to the obstacle have
//! one scale, which the semismooth method's Fischer–Burmeister function needs), each rank
//! assembling its own rows into a preallocated `MATMPIAIJ`. The answer is
//! compared with an independent solve of the same discrete problem (a primal–dual
//! active set method with the Thomas algorithm, in plain Rust on every rank): equal to
//! rounding on every rank count, both for `vinewtonrsls` and `vinewtonssls`. A SNES
//! stopped by its iteration limit is an error naming DIVERGED_MAX_IT.

use fem_petsc::{solve, Matrix, Petsc, Vector, VectorView};

const N: usize = 199;

/// A load that presses the middle onto the obstacle and lifts near the ends.
fn load(x: f64) -> f64 {
    -30.0 + 60.0 * (x - 0.5) * (x - 0.5)
}

fn obstacle(x: f64) -> f64 {
    -0.15 + 0.5 * (x - 0.5) * (x - 0.5)
}

/// The discrete problem's solution by a primal–dual active set method: on the inactive
/// nodes the tridiagonal system with the active nodes held at ψ, until the sets repeat.
fn active_set_solution() -> Vec<f64> {
    let h = 1.0 / (N + 1) as f64;
    let x = |i: usize| (i + 1) as f64 * h;
    let mut active = vec![false; N];
    let mut u = vec![0.0; N];
    for _ in 0..200 {
        // the tridiagonal system (2, −1, −1)/h² u = f on inactive nodes, u = ψ on active
        let (mut a, mut b, mut c, mut d) = (vec![0.0; N], vec![0.0; N], vec![0.0; N], vec![0.0; N]);
        for i in 0..N {
            if active[i] {
                b[i] = 1.0;
                d[i] = obstacle(x(i));
            } else {
                a[i] = if i > 0 { -1.0 / (h * h) } else { 0.0 };
                c[i] = if i + 1 < N { -1.0 / (h * h) } else { 0.0 };
                b[i] = 2.0 / (h * h);
                d[i] = load(x(i));
            }
        }
        for i in 1..N {
            let m = a[i] / b[i - 1];
            b[i] -= m * c[i - 1];
            d[i] -= m * d[i - 1];
        }
        u[N - 1] = d[N - 1] / b[N - 1];
        for i in (0..N - 1).rev() {
            u[i] = (d[i] - c[i] * u[i + 1]) / b[i];
        }
        // λ = K u − f on the active nodes; the next sets from min(λ, u − ψ) = 0
        let next: Vec<bool> = (0..N)
            .map(|i| {
                let left = if i > 0 { u[i - 1] } else { 0.0 };
                let right = if i + 1 < N { u[i + 1] } else { 0.0 };
                let lambda = (2.0 * u[i] - left - right) / (h * h) - load(x(i));
                lambda - (u[i] - obstacle(x(i))) > 0.0
            })
            .collect();
        if next == active {
            return u;
        }
        active = next;
    }
    panic!("the active set method did not settle");
}

fn main() {
    let petsc = Petsc::initialize("-snes_rtol 1e-12 -snes_atol 1e-13 -ksp_rtol 1e-14")
        .expect("PETSc starts");
    let (rank, size) = (petsc.rank(), petsc.size());
    let h = 1.0 / (N + 1) as f64;
    // rows split as evenly as PETSc would: the first N mod size ranks take one more
    let local = N / size + usize::from(rank < N % size);
    let mut x = Vector::new(&petsc, local).unwrap();
    let rows = x.ownership().unwrap();
    assert_eq!(rows.len(), local);
    let neighbours = |i: usize| [i.checked_sub(1), Some(i), (i + 1 < N).then_some(i + 1)];
    let (diagonal, off): (Vec<usize>, Vec<usize>) = rows
        .clone()
        .map(|i| {
            let columns: Vec<usize> = neighbours(i).into_iter().flatten().collect();
            let inside = columns.iter().filter(|c| rows.contains(c)).count();
            (inside, columns.len() - inside)
        })
        .unzip();
    let mut k = Matrix::new(&petsc, &diagonal, &off).unwrap();
    let mut f = Vector::new(&petsc, local).unwrap();
    let mut lower = Vector::new(&petsc, local).unwrap();
    let mut upper = Vector::new(&petsc, local).unwrap();
    for i in rows.clone() {
        let xi = (i + 1) as f64 * h;
        for (j, v) in neighbours(i).into_iter().zip([-1.0, 2.0, -1.0]) {
            if let Some(j) = j {
                k.add(&[i], &[j], &[v]).unwrap();
            }
        }
        f.set(&[i], &[h * h * load(xi)], false).unwrap();
        lower.set(&[i], &[obstacle(xi)], false).unwrap();
        upper
            .set(&[i], &[fem_petsc::sys::FEM_PETSC_INFINITY], false)
            .unwrap();
        x.set(&[i], &[0.0], false).unwrap();
    }
    for v in [&mut f, &mut lower, &mut upper, &mut x] {
        v.assemble().unwrap();
    }
    k.assemble().unwrap();
    let expected = active_set_solution();
    let residual = |x: &VectorView, r: &mut VectorView| {
        k.multiply(x, r)?;
        r.axpy(-1.0, &VectorView::of(&f))
    };

    for (kind, options) in [
        ("vinewtonrsls", ""),
        ("vinewtonssls", "-snes_type vinewtonssls"),
    ] {
        if !options.is_empty() {
            petsc.insert_options(options).unwrap();
        }
        let mut start = Vector::new(&petsc, local).unwrap();
        for i in rows.clone() {
            start.set(&[i], &[0.0], false).unwrap();
        }
        start.assemble().unwrap();
        let converged = solve(&k, Box::new(residual), Some((&lower, &upper)), &mut start)
            .unwrap_or_else(|e| panic!("{kind} on {size} ranks: {e}"));
        let u = start.gather().unwrap();
        let difference = u
            .iter()
            .zip(&expected)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        if difference >= 1e-8 && rank == 0 {
            let worst = (0..N)
                .max_by(|&a, &b| {
                    (u[a] - expected[a])
                        .abs()
                        .total_cmp(&(u[b] - expected[b]).abs())
                })
                .unwrap();
            eprintln!(
                "worst at {worst}: {} vs {}, ψ = {}",
                u[worst],
                expected[worst],
                obstacle((worst + 1) as f64 * h)
            );
            eprintln!("first: {:?}", &u[..5]);
        }
        assert!(
            difference < 1e-8,
            "{kind} on {size} ranks differs from the active set solution by {difference}"
        );
        let touching = u
            .iter()
            .enumerate()
            .filter(|(i, v)| (**v - obstacle((i + 1) as f64 * h)).abs() < 1e-12)
            .count();
        assert!(touching > N / 4, "{kind}: {touching} nodes in contact");
        if rank == 0 {
            println!(
                "{kind} on {size} ranks, {touching} nodes in contact: {} after {} iterations ({} linear), max difference {difference:.1e}",
                converged.reason, converged.iterations, converged.linear_iterations
            );
        }
    }

    // an iteration limit that stops the solve is an error naming it, not an answer
    petsc
        .insert_options("-snes_type vinewtonrsls -snes_max_it 1")
        .unwrap();
    let mut start = Vector::new(&petsc, local).unwrap();
    for i in rows.clone() {
        start.set(&[i], &[0.0], false).unwrap();
    }
    start.assemble().unwrap();
    let error = solve(&k, Box::new(residual), Some((&lower, &upper)), &mut start)
        .expect_err("one iteration does not find the contact set");
    assert!(error.message.contains("DIVERGED_MAX_IT"), "{error}");
    if rank == 0 {
        println!("snes_vi: ok on {size} ranks");
    }
}
