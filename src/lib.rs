//! fem-forms: a form compiler and solver for stabilized finite element methods of
//! obstacle and contact problems of thin structures.
//!
//! This crate re-exports the runtime ([`fem_runtime`]), the `model!` macro that compiles
//! model files, and the model files, scenes and the one solve of [`fem_models`]; it adds
//! what the CLI needs on top: the studies (each kind once in [`studies`], over the one
//! solve in [`registry_studies`]; locking once in [`locking`]; the λ-scatter of a plate
//! on a flat obstacle in [`lambda_scatter`]), the accuracy table of the default job
//! ([`accuracy`]) and charts ([`plot`]).
#![warn(missing_docs)]
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

pub mod accuracy;
pub mod adaptivity_study;
pub mod allocator;
pub mod choice_study;
pub mod lambda_scatter;
pub mod locking;
pub mod plot;
pub mod registry_studies;
pub mod report_page;
pub mod studies;

pub use fem_models as models;
pub use fem_runtime::*;

/// The smallest size a non-zero load may have (see the runtime's).
pub use fem_runtime::problem::MIN_DATA_SIZE;

pub use fem_runtime::problem::number;

/// A table line with every `NaN` cell (a difference or rate not defined on the first
/// rows, a quantity without a value) shown as `-`, keeping the columns aligned.
pub fn dash_nan(line: String) -> String {
    line.replace("NaN", "  -")
}

#[cfg(test)]
mod tests {
    #[test]
    fn reports_print_extreme_numbers_in_scientific_notation() {
        assert_eq!(super::number(1e-300), "1e-300");
        assert_eq!(super::number(-2.5e7), "-2.5e7");
        assert_eq!(super::number(20.0), "20");
        assert_eq!(super::number(0.0), "0");
        assert_eq!(super::number(0.005), "0.005");
    }

    #[test]
    fn undefined_table_cells_are_dashes_of_the_same_width() {
        let line = format!("{:>6.2} {:>6.2}", f64::NAN, 1.5);
        assert_eq!(super::dash_nan(line), "     -   1.50");
    }
}
