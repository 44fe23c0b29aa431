//! fem-forms: a form compiler and solver for stabilized finite element methods of
//! obstacle and contact problems of thin structures.
//!
//! This crate re-exports the runtime ([`fem_runtime`]), the `model!` macro that compiles
//! model files, and the model files and scenes of [`fem_models`]; it adds the beam scene
//! solver ([`beams`]), the Signorini contact scenes ([`signorini`]), the studies (each kind once in [`studies`], the families' sides in [`beam_studies`] and
//! [`membrane_studies`]) and charts ([`plot`]) behind the CLI.
#![warn(missing_docs)]
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

pub mod accuracy;
pub mod allocator;
pub mod beam_studies;
pub mod beams;
pub mod kirchhoff_studies;
pub mod locking;
pub mod membrane_studies;
pub mod membranes;
pub mod plate_studies;
pub mod plot;
pub mod registry_studies;
pub mod studies;

pub use fem_models as models;
pub use fem_runtime::*;

/// The smallest size a non-zero load may have (see the runtime's).
pub use fem_runtime::problem::MIN_DATA_SIZE;

pub use fem_runtime::problem::number;

/// Warnings for the boundary parts `names` (chosen under the scene-file key `key`) whose
/// Gmsh groups hold interior edges (embedded curves): a boundary part holds boundary
/// edges only, so a condition the user put on an interior wire is not imposed there (a
/// group `sides` of left, right and the line y = 0 acts as left and right alone).
pub fn interior_curve_warnings<S: AsRef<str>>(
    key: &str,
    mesh: &TriangleMesh,
    names: &[S],
) -> Vec<String> {
    mesh.interior_edges_of(names)
        .into_iter()
        .map(|(name, count)| {
            format!(
                "{key}: the group `{name}` has {count} edge(s) inside the domain (an embedded curve); a boundary part holds boundary edges only, so nothing is imposed on them"
            )
        })
        .collect()
}

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
