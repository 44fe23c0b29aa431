//! A complete obstacle solve against one factorization + solve of the same matrix.
//!
//! `cargo bench --bench vi_solve` prints, from 1k to 1M elements, the time of the whole
//! variational-inequality solve (assembly of every nested level, semismooth Newton,
//! post-processing excluded), the time of one sparse Cholesky (symbolic + numeric) and
//! solve of the final level's matrix `A` measured in the same run, their ratio, and the
//! Newton iterations on the final mesh.
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

#[path = "../tests/common/beams.rs"]
mod beams;

use fem_forms::lcp::cholesky::Cholesky;
use fem_forms::models::report::Settings;
use fem_forms::models::scenes::scene;
use std::time::Instant;

fn main() {
    fem_forms::allocator::keep_freed_memory();
    fem_forms::lcp::cholesky::factor_sequentially();
    let sizes = [1_000usize, 4_000, 16_000, 64_000, 256_000, 1_024_000];
    for (name, thickness) in [
        ("timoshenko-a", 1e-3),
        ("timoshenko-a", 1e-2),
        ("bernoulli-flat", 0.0),
    ] {
        println!(
            "{name}, q = 100{}",
            if thickness > 0.0 {
                format!(", t = {thickness}")
            } else {
                String::new()
            }
        );
        println!(
            "{:>9} {:>9} {:>11} {:>13} {:>7} {:>11} {:>8}",
            "elements", "unknowns", "VI solve s", "factor+solve", "ratio", "iterations", "levels"
        );
        for &n in &sizes {
            let (pair, alpha) = if thickness > 0.0 {
                ("p2-p2-p0", 1.0)
            } else {
                ("hermite-p0", 1e-2)
            };
            let request = Settings {
                parameters: if thickness > 0.0 {
                    beams::thickness(thickness)
                } else {
                    Vec::new()
                },
                alpha: Some(alpha),
                ..beams::settings(n, 100.0)
            };
            let report = match beams::solve(name, &request) {
                Ok(outcome) => outcome.report.solve,
                Err(e) => {
                    println!("{n:>9}  failed: {e}");
                    continue;
                }
            };
            let mut data = scene(name).unwrap();
            if thickness > 0.0 {
                data.thickness = thickness;
            }
            let d = beams::discretize_scene(&data, pair, n, 100.0, alpha).unwrap();
            let start = Instant::now();
            let pattern = d.lcp.a.symbolic().to_owned().unwrap();
            let factor = Cholesky::analyse(&pattern)
                .unwrap()
                .factor(&d.lcp.a)
                .unwrap();
            let x = factor.solve(&d.lcp.f).unwrap();
            let linear = start.elapsed().as_secs_f64();
            std::hint::black_box(x);
            println!(
                "{n:>9} {:>9} {:>11.4} {:>13.4} {:>7.2} {:>11} {:>8}",
                report.dofs,
                report.seconds,
                linear,
                report.seconds / linear,
                report.iterations,
                report.levels.len()
            );
        }
        println!();
    }
}
