//! Generated kernels against hand-coded element matrices and vectors: every block of
//! every form of the beam models, on many random cells and parameter values.
#![allow(mixed_script_confusables, confusable_idents, uncommon_codepoints)]

mod hand_coded;

use fem_forms::model::IntoFormIndex;
use fem_forms::models::{bernoulli, timoshenko_p1_full, timoshenko_p1_reduced, timoshenko_p2};
use fem_forms::{DataFn, Model};
use hand_coded::{HandElement, Setting, GAUSS5};
use proptest::prelude::*;

/// The generated element matrix of (test field, trial field) of `form`, zero if the
/// form has no such block (its terms were all dropped or never there).
fn generated_matrix<M: Model>(
    form: impl IntoFormIndex<M>,
    test: usize,
    trial: usize,
    st: Setting,
) -> Vec<Vec<f64>> {
    let f = M::form(form).unwrap();
    let (rows, cols) = (
        M::FIELDS[test].element.dof_count(),
        M::FIELDS[trial].element.dof_count(),
    );
    let mut out = vec![vec![0.0; cols]; rows];
    let params = params::<M>(st);
    let data: [&DataFn; 2] = [&|x: &[f64]| hand_coded::load(x[0]), &|x: &[f64]| {
        hand_coded::obstacle(x[0])
    }];
    if let Some(b) = M::FORMS[f]
        .blocks
        .iter()
        .position(|b| b.test_field == test && b.trial_field == Some(trial))
    {
        let mut flat = vec![0.0; rows * cols];
        M::element_matrix(f, b, &[st.x0, st.x0 + st.h], &params, &data, &mut flat);
        for i in 0..rows {
            out[i].copy_from_slice(&flat[i * cols..(i + 1) * cols]);
        }
    }
    out
}

fn generated_vector<M: Model>(form: impl IntoFormIndex<M>, test: usize, st: Setting) -> Vec<f64> {
    let f = M::form(form).unwrap();
    let rows = M::FIELDS[test].element.dof_count();
    let mut out = vec![0.0; rows];
    let params = params::<M>(st);
    let data: [&DataFn; 2] = [&|x: &[f64]| hand_coded::load(x[0]), &|x: &[f64]| {
        hand_coded::obstacle(x[0])
    }];
    if let Some(b) = M::FORMS[f].blocks.iter().position(|b| b.test_field == test) {
        M::element_vector(f, b, &[st.x0, st.x0 + st.h], &params, &data, &mut out);
    }
    out
}

/// The setting's parameters in `M`'s declaration order. The beam models share their
/// parameter names but not their handles, so generic code goes by name (the
/// run-time lookup a scene file uses) and checks that every name is known.
fn params<M: Model>(st: Setting) -> Vec<f64> {
    let mut values = vec![f64::NAN; M::PARAMS.len()];
    for (name, value) in [("t", st.t), ("α", st.alpha), ("s", st.s)] {
        if let Ok(i) = M::param(name) {
            values[i] = value;
        }
    }
    assert!(
        values.iter().all(|v| !v.is_nan()),
        "{}: unexpected parameter",
        M::NAME
    );
    values
}

/// max |generated − hand| / max |hand| over a block (absolute when the block is zero).
/// max |generated − hand| of an element vector, relative to the larger of its largest
/// entry and `h·max|data|`: an entry can be a small difference of integrals of size
/// h·|ψ| (`∫ sψμ` of a sign-changing ψ), whose rounding is relative to those integrals.
fn vector_difference(generated: &[f64], hand: &[f64], st: Setting) -> f64 {
    let data = [st.x0, st.x0 + 0.5 * st.h, st.x0 + st.h]
        .iter()
        .map(|&x| hand_coded::load(x).abs() + hand_coded::obstacle(x).abs())
        .fold(0.0f64, f64::max);
    let scale = hand
        .iter()
        .fold(0.0f64, |m, v| m.max(v.abs()))
        .max(st.h * data);
    let diff = generated
        .iter()
        .zip(hand)
        .fold(0.0f64, |m, (g, h)| m.max((g - h).abs()));
    diff / scale.max(f64::MIN_POSITIVE)
}

fn relative_difference(generated: &[Vec<f64>], hand: &[Vec<f64>]) -> f64 {
    let scale = hand.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    let diff = generated
        .iter()
        .flatten()
        .zip(hand.iter().flatten())
        .fold(0.0f64, |m, (g, h)| m.max((g - h).abs()));
    if scale > 0.0 {
        diff / scale
    } else {
        diff
    }
}

fn setting() -> impl Strategy<Value = Setting> {
    (
        -2.0f64..2.0,
        -3.0f64..0.3,
        -3.0f64..0.0,
        -2.0f64..1.0,
        prop::bool::ANY,
    )
        .prop_map(|(x0, log_h, log_t, log_alpha, below)| Setting {
            x0,
            h: 10f64.powf(log_h),
            t: 10f64.powf(log_t),
            alpha: 10f64.powf(log_alpha),
            s: if below { 1.0 } else { -1.0 },
        })
}

const MIDPOINT: [(f64, f64); 1] = [(0.0, 2.0)];

fn check_timoshenko<M: Model>(
    elements: [HandElement; 3],
    shear_rule: &[(f64, f64)],
    st: Setting,
) -> Result<(), TestCaseError> {
    for form in ["a", "b", "S", "B_h"] {
        for test in 0..3 {
            for trial in 0..3 {
                let g = generated_matrix::<M>(form, test, trial, st);
                let h = hand_coded::timoshenko_matrix(form, &elements, test, trial, st, shear_rule);
                let d = relative_difference(&g, &h);
                prop_assert!(
                    d <= 1e-12,
                    "{} {form} ({test},{trial}) {st:?}: {d:e}\n{g:?}\n{h:?}",
                    M::NAME
                );
            }
        }
    }
    for form in ["ℓ", "ℓ_S", "g", "L_h"] {
        for test in 0..3 {
            let g = generated_vector::<M>(form, test, st);
            let h = hand_coded::timoshenko_vector(form, &elements, test, st);
            let d = vector_difference(&g, &h, st);
            prop_assert!(
                d <= 1e-12,
                "{} {form} ({test}) {st:?}: {d:e}\n{g:?}\n{h:?}",
                M::NAME
            );
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn timoshenko_p2_kernels_match_hand_coded(st in setting()) {
        check_timoshenko::<timoshenko_p2::Model>([HandElement::P2, HandElement::P2, HandElement::P0], &GAUSS5, st)?;
    }

    #[test]
    fn timoshenko_p1_reduced_kernels_match_hand_coded(st in setting()) {
        check_timoshenko::<timoshenko_p1_reduced::Model>([HandElement::P1, HandElement::P1, HandElement::P0], &MIDPOINT, st)?;
    }

    #[test]
    fn timoshenko_p1_full_kernels_match_hand_coded(st in setting()) {
        check_timoshenko::<timoshenko_p1_full::Model>([HandElement::P1, HandElement::P1, HandElement::P0], &GAUSS5, st)?;
    }

    #[test]
    fn bernoulli_kernels_match_hand_coded(st in setting()) {
        type M = bernoulli::Model;
        for form in ["a", "b", "S", "B_h"] {
            for test in 0..2 {
                for trial in 0..2 {
                    let g = generated_matrix::<M>(form, test, trial, st);
                    let h = hand_coded::bernoulli_matrix(form, test, trial, st);
                    let d = relative_difference(&g, &h);
                    prop_assert!(d <= 1e-12, "bernoulli {form} ({test},{trial}) {st:?}: {d:e}\n{g:?}\n{h:?}");
                }
            }
        }
        for form in ["ℓ", "ℓ_S", "g", "L_h"] {
            for test in 0..2 {
                let g = generated_vector::<M>(form, test, st);
                let h = hand_coded::bernoulli_vector(form, test, st);
                let d = vector_difference(&g, &h, st);
                prop_assert!(d <= 1e-12, "bernoulli {form} ({test}) {st:?}: {d:e}\n{g:?}\n{h:?}");
            }
        }
    }

    /// The closed forms the benchmark races against are the same matrices.
    #[test]
    fn closed_forms_of_the_benchmark_match(st in setting()) {
        let x = [st.x0, st.x0 + st.h];
        let p = [st.t, st.alpha, st.s];
        let d: [&DataFn; 2] = [&|x: &[f64]| hand_coded::load(x[0]), &|x: &[f64]| hand_coded::obstacle(x[0])];
        type Block3 = [[f64; 3]; 3];
        let pairs: [(Block3, Block3); 3] = [
            (timoshenko_p2::a::matrix_η_θ(&x, &p, &d), hand_coded::timoshenko_p2_a_eta_theta(&x, st.t)),
            (timoshenko_p2::a::matrix_η_w(&x, &p, &d), hand_coded::timoshenko_p2_a_eta_w(st.t)),
            (timoshenko_p2::a::matrix_v_w(&x, &p, &d), hand_coded::timoshenko_p2_a_v_w(&x, st.t)),
        ];
        for (g, h) in pairs {
            let d = relative_difference(&g.map(|r| r.to_vec()), &h.map(|r| r.to_vec()));
            prop_assert!(d <= 1e-13, "{d:e}");
        }
        let g = bernoulli::a::matrix_v_w(&x, &[st.alpha, st.s], &d);
        let d4 = relative_difference(&g.map(|r| r.to_vec()), &hand_coded::bernoulli_a(&x).map(|r| r.to_vec()));
        prop_assert!(d4 <= 1e-13, "{d4:e}");
        let f = |x: &[f64]| hand_coded::load(x[0]);
        let g = timoshenko_p2::ℓ::vector_v(&x, &p, &d);
        let dl = relative_difference(&[g.to_vec()], &[hand_coded::p2_load(&x, &f).to_vec()]);
        prop_assert!(dl <= 1e-13, "{dl:e}");
    }
}

#[test]
fn forms_drop_the_terms_that_vanish_for_their_elements() {
    // θ''' ≡ 0 for P2 and P1, w'''' ≡ 0 for Hermite cubics: S keeps only (μ, λ).
    for (name, form) in [
        (
            "timoshenko_p2",
            timoshenko_p2::Model::FORMS[timoshenko_p2::S::INDEX],
        ),
        ("bernoulli", bernoulli::Model::FORMS[bernoulli::S::INDEX]),
    ] {
        assert_eq!(form.blocks.len(), 1, "{name}: {:?}", form.blocks);
        assert_eq!(form.dropped_terms, 3, "{name}");
    }
    // Reduced integration uses one point; exact terms need no run-time quadrature.
    let a = timoshenko_p1_reduced::Model::FORMS[timoshenko_p1_reduced::a::INDEX];
    assert!(a.blocks.iter().all(|b| b.quadrature_points <= 1));
}
