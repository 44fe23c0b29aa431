//! fem-forms model files, one DSL file per model (docs/mathematics.md has the mathematics).
//!
//! Each model declares its fields, parameters, data and the stabilized forms
//! `B_h = a − b − bᵀ − α S_h` and `L_h = ℓ − ⟨sψ, μ⟩ − α ℓ_S` of the obstacle problem.
#![warn(missing_docs)]
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

pub mod choice;
pub mod contact_scenes;
pub mod data;
pub mod euler_bernoulli;
pub mod families;
pub mod family;
pub mod geometry;
pub mod hertz;
pub mod kirchhoff;
pub mod membrane;
pub mod membrane_scenes;
pub mod mindlin;
pub mod plate_scenes;
pub mod report;
pub mod run;
pub mod scene;
pub mod scene_file;
pub mod signorini;
pub mod timoshenko;
pub mod vector_forms;
pub mod winkler;

pub use euler_bernoulli::bernoulli;
pub use membrane::{membrane_p1, membrane_p1_p0, membrane_p2_p0, membrane_p2_p1disc};
pub use timoshenko::{timoshenko_p1_full, timoshenko_p1_reduced, timoshenko_p2};
pub mod scenes;

#[cfg(test)]
mod roles {
    //! Every shipped model declares its roles, and they name the forms and parameters
    //! the mathematics gives them (docs/mathematics.md §1).
    use fem_runtime::Model;

    fn check<M: Model>(side: bool, obstacle: Option<(&str, &str)>) {
        let form = |i: usize| M::FORMS[i].name;
        let [b, l] = M::SYSTEM.expect("system");
        assert_eq!((form(b), form(l)), ("B_h", "L_h"), "{}", M::NAME);
        let [a, load] = M::ENERGY.expect("energy");
        assert_eq!((form(a), form(load)), ("a", "ℓ"), "{}", M::NAME);
        let s = M::STABILIZATION.expect("stabilization");
        assert_eq!((form(s.form), form(s.against)), ("S", "a"), "{}", M::NAME);
        assert_eq!(s.alpha.map(|p| M::PARAMS[p]), Some("α"), "{}", M::NAME);
        assert_eq!(
            M::SIDE.map(|p| M::PARAMS[p]),
            side.then_some("s"),
            "{}",
            M::NAME
        );
        let named = M::OBSTACLE.map(|[f, d]| (M::FIELDS[f].name, M::DATA[d]));
        assert_eq!(named, obstacle, "{}", M::NAME);
    }

    #[test]
    fn shipped_models_declare_their_roles() {
        check::<crate::membrane_p1_p0::Model>(false, Some(("u", "ψ")));
        check::<crate::membrane_p2_p0::Model>(false, Some(("u", "ψ")));
        check::<crate::membrane_p2_p1disc::Model>(false, Some(("u", "ψ")));
        check::<crate::bernoulli::Model>(true, Some(("w", "ψ")));
        check::<crate::timoshenko_p2::Model>(true, Some(("w", "ψ")));
        check::<crate::timoshenko_p1_reduced::Model>(true, Some(("w", "ψ")));
        check::<crate::timoshenko_p1_full::Model>(true, Some(("w", "ψ")));
        check::<crate::mindlin::mindlin_stenberg::Model>(true, Some(("w", "ψ")));
        check::<crate::mindlin::mindlin_plain_p1::Model>(true, Some(("w", "ψ")));
        check::<crate::kirchhoff::kirchhoff_argyris_p0::Model>(true, Some(("w", "ψ")));
        check::<crate::kirchhoff::kirchhoff_morley_p0::Model>(true, Some(("w", "ψ")));
        check::<crate::signorini::signorini_p1::Model>(false, None);
        check::<crate::signorini::signorini_p2_p1::Model>(false, None);
        // the nodal method's model has an energy and nothing else
        type Nodal = crate::membrane_p1::Model;
        assert!(Nodal::SYSTEM.is_none() && Nodal::STABILIZATION.is_none());
        assert!(Nodal::ENERGY.is_some());
    }
}
