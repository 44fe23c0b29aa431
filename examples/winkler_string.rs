//! A model the product does not ship, solved through the library: a string on a Winkler
//! foundation over a flat obstacle (the model is in `winkler_string/model.rs`, its
//! closed-form contact solution in docs/mathematics.md). Run with
//! `cargo run --release --example winkler_string [cells] [tolerance]`: with a tolerance,
//! adaptively from `cells` cells with the estimator the macro derives from the forms.

// the model's names are Greek (α, λ, μ, ψ)
#![allow(confusable_idents, mixed_script_confusables, uncommon_codepoints)]

#[path = "winkler_string/model.rs"]
mod model;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let cells: usize = std::env::args().nth(1).map_or(Ok(256), |a| a.parse())?;
    let string = model::StringOnFoundation {
        half_length: 1.0,
        tension: 1.0,
        stiffness: 1.0,
        load: 4.0,
        depth: 0.5,
    };
    let solved = match std::env::args().nth(2) {
        Some(tolerance) => string.solve_adaptive(cells, tolerance.parse()?, None)?,
        None => string.solve(cells)?,
    };
    println!("contact set {:?}", solved.solution.contact_set());
    println!("{}", serde_json::to_string_pretty(&solved.report)?);
    Ok(())
}
