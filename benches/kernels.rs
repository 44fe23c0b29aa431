//! Generated kernels against hand-coded ones, and 1D assembly throughput.
//!
//! `cargo bench --bench kernels` prints, for each block, the ratio of generated to
//! hand-coded kernel time (measured in the same run, interleaved, median of rounds;
//! target ≤ 1.05) and ns per element, then assembly throughput in elements per second.
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

#[path = "../tests/hand_coded/mod.rs"]
mod hand_coded;

use fem_forms::models::{bernoulli, timoshenko_p2};
use fem_forms::{Coefficients, DataFn, IntervalMesh, MatrixAssembler, Model, SystemDofs};
use std::hint::black_box;
use std::time::Instant;

const CELLS: usize = 200_000;
const ROUNDS: usize = 15;

fn cells() -> Vec<[f64; 2]> {
    // A deterministic spread of lengths (the kernels' cost does not depend on them).
    let mut state = 0x2545_f491_4f6c_dd1du64;
    (0..CELLS)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let u = (state >> 11) as f64 / (1u64 << 53) as f64;
            let x0 = 2.0 * u - 1.0;
            [x0, x0 + 1e-3 + u * 0.1]
        })
        .collect()
}

/// Seconds for one pass of `kernel` over all cells (its output summed so it is kept).
fn time_pass<const R: usize, const C: usize>(
    cells: &[[f64; 2]],
    kernel: &dyn Fn(&[f64; 2]) -> [[f64; C]; R],
) -> f64 {
    let start = Instant::now();
    let mut sum = 0.0;
    for x in cells {
        let k = kernel(black_box(x));
        sum += k[0][0] + k[R - 1][C - 1];
    }
    black_box(sum);
    start.elapsed().as_secs_f64()
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Runs both kernels alternately and prints their ratio.
fn race<const R: usize, const C: usize>(
    name: &str,
    cells: &[[f64; 2]],
    generated: &dyn Fn(&[f64; 2]) -> [[f64; C]; R],
    hand: &dyn Fn(&[f64; 2]) -> [[f64; C]; R],
) -> f64 {
    let (mut g, mut h) = (Vec::new(), Vec::new());
    for round in 0..ROUNDS {
        // alternate the order so that neither always runs on a warmer cache
        if round % 2 == 0 {
            g.push(time_pass(cells, generated));
            h.push(time_pass(cells, hand));
        } else {
            h.push(time_pass(cells, hand));
            g.push(time_pass(cells, generated));
        }
    }
    let (g, h) = (median(g), median(h));
    let ratio = g / h;
    println!(
        "{name:<34} generated {:>7.2} ns/element   hand-coded {:>7.2} ns/element   ratio {ratio:.3}",
        g / cells.len() as f64 * 1e9,
        h / cells.len() as f64 * 1e9
    );
    ratio
}

fn main() {
    let cells = cells();
    let t = 1e-3;
    let p = [t, 1.0, 1.0];
    let f = |x: &[f64]| hand_coded::load(x[0]);
    let psi = |x: &[f64]| hand_coded::obstacle(x[0]);
    let d: [&DataFn; 2] = [&f, &psi];
    println!("Kernels: {CELLS} cells, median of {ROUNDS} interleaved rounds");
    let mut ratios = vec![
        race(
            "timoshenko_p2 a (η,θ)",
            &cells,
            &|x| timoshenko_p2::a::matrix_η_θ(x, &p, &d),
            &|x| hand_coded::timoshenko_p2_a_eta_theta(x, black_box(t)),
        ),
        race(
            "timoshenko_p2 a (η,w)",
            &cells,
            &|x| timoshenko_p2::a::matrix_η_w(x, &p, &d),
            &|_| hand_coded::timoshenko_p2_a_eta_w(black_box(t)),
        ),
        race(
            "timoshenko_p2 a (v,w)",
            &cells,
            &|x| timoshenko_p2::a::matrix_v_w(x, &p, &d),
            &|x| hand_coded::timoshenko_p2_a_v_w(x, black_box(t)),
        ),
        race(
            "bernoulli a (v,w)",
            &cells,
            &|x| bernoulli::a::matrix_v_w(x, &[1.0, 1.0], &d),
            &hand_coded::bernoulli_a,
        ),
    ];
    ratios.push(race::<1, 3>(
        "timoshenko_p2 ℓ (v), data f",
        &cells,
        &|x| [timoshenko_p2::ℓ::vector_v(x, &p, &d)],
        &|x| [hand_coded::p2_load(x, &f)],
    ));
    let worst = ratios.iter().copied().fold(0.0, f64::max);
    println!("worst generated/hand-coded ratio {worst:.3} (target ≤ 1.05)\n");

    println!("Assembly (pattern built once, values refilled):");
    for n in [10_000usize, 1_000_000] {
        assembly::<timoshenko_p2::Model>("timoshenko_p2 a (θ,w)", &["θ", "w"], n);
        assembly::<bernoulli::Model>("bernoulli a (w)", &["w"], n);
        assembly::<timoshenko_p2::Model>("timoshenko_p2 B_h (θ,w,λ)", &["θ", "w", "λ"], n);
    }
}

fn assembly<M: Model>(name: &str, fields: &[&str], n: usize) {
    let form = if fields.len() == 3 { "B_h" } else { "a" };
    let mesh = IntervalMesh::uniform(0.0, 1.0, n).unwrap();
    let dofs = SystemDofs::named::<M>(&mesh, fields).unwrap();
    let f = |_: &[f64]| 1.0;
    let params: Vec<(&str, f64)> = M::PARAMS
        .iter()
        .map(|&p| (p, if p == "t" { 1e-3 } else { 1.0 }))
        .collect();
    let data: Vec<(&str, &DataFn)> = M::DATA.iter().map(|&d| (d, &f as &DataFn)).collect();
    let coefficients = Coefficients::new::<M>(&params, &data).unwrap();
    let start = Instant::now();
    let assembler = MatrixAssembler::new::<M>(form, &mesh, &dofs).unwrap();
    let pattern = start.elapsed().as_secs_f64();
    let mut values = Vec::new();
    let mut times = Vec::new();
    for _ in 0..5 {
        let start = Instant::now();
        assembler
            .assemble_values::<M>(&mesh, &coefficients, &mut values)
            .unwrap();
        times.push(start.elapsed().as_secs_f64());
    }
    let t = median(times);
    println!(
        "{name:<28} {n:>8} elements: pattern {:>8.1} ms, assembly {:>8.2} ms = {:>6.1} M elements/s",
        pattern * 1e3,
        t * 1e3,
        n as f64 / t / 1e6
    );
}
