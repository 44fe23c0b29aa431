//! A model the product does not ship, solved through the library: a string on a Winkler
//! foundation over a flat obstacle (the model is in `winkler_string/model.rs`, its
//! closed-form contact solution in docs/mathematics.md). Run with
//! `cargo run --release --example winkler_string [cells] [output.json]`.

// the model's names are Greek (α, λ, μ, ψ)
#![allow(confusable_idents, mixed_script_confusables, uncommon_codepoints)]

#[path = "winkler_string/model.rs"]
mod model;

use model::Problem;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let cells: usize = args.next().map_or(Ok(256), |arg| arg.parse())?;
    let output = args.next().unwrap_or_else(|| "winkler_string.json".into());
    let problem = Problem {
        half_length: 1.0,
        tension: 1.0,
        stiffness: 1.0,
        load: 4.0,
        depth: 0.5,
        alpha: 0.1,
    };
    let solved = problem.solve(cells)?;
    let contact_set = solved.solution.contact_set();
    let force = solved.solution.total_contact_force();
    println!(
        "cells {cells}, C_I = {:.3e}, α = {}",
        solved.inverse_constant, problem.alpha
    );
    println!("energy ½a(u,u) − ℓ(u) = {:.10}", solved.energy);
    println!("contact set {contact_set:?}");
    println!("∫λ_h = {force:.10}");
    let json = serde_json::json!({
        "cells": cells,
        "energy": solved.energy,
        "contact_set": contact_set,
        "total_contact_force": force,
    });
    std::fs::write(&output, serde_json::to_string_pretty(&json)?)?;
    println!("wrote {output}");
    Ok(())
}
