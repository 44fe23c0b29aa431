//! The roles of a model's forms and parameters in the obstacle problem: which forms are
//! the stabilized system `B_h`, `L_h`, which are the energy `½ a(u,u) − ℓ(u)`, which
//! form is the stabilization `S` and which form bounds it (`C_I`), which parameter is α
//! and which the obstacle side `s`. The runtime derives C_I, α and the energy from them
//! without looking a name up.
//!
//! A model declares them (`system:`, `energy:`, `stabilization:`, `side:`); where a
//! section is left out, the conventional names are taken where the model has them with
//! the right kind (`B_h`/`L_h`; `a` and `ℓ`, `l` or `ell`; `α S against a` with `α` or
//! `alpha`; `s`), so that small models need not spell them out.

use crate::analysis::{Form, Symbols};
use crate::declaration::{Declaration, RolesDecl};
use crate::diagnostic::{closest, Diagnostic};
use syn::Ident;

/// The resolved roles, as indices into the generated `FORMS` and `PARAMS`.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Roles {
    /// `[B_h, L_h]`.
    pub system: Option<[usize; 2]>,
    /// `[a, ℓ]`.
    pub energy: Option<[usize; 2]>,
    /// `(α, S, a)`: parameter (if declared), stabilization form, the form bounding it.
    pub stabilization: Option<(Option<usize>, usize, usize)>,
    /// The side parameter.
    pub side: Option<usize>,
    /// `(field, data)`: the constrained field and the obstacle.
    pub obstacle: Option<(usize, usize)>,
    /// The order `p` of the operator whose residual the stabilization measures: the
    /// power of h in the stabilization's terms (`Σ_T h_T^p (…)`), or else the total
    /// derivative order of the energy's bilinear form; 0 where neither is known.
    pub order: u8,
}

/// The roles of `declaration` among `forms` (the forms that generate code, in the order
/// of `FORMS`), with an error at the name for every declared role that does not fit.
pub fn resolve(
    declaration: &Declaration,
    symbols: &Symbols,
    forms: &[Form],
) -> (Roles, Vec<Diagnostic>) {
    let RolesDecl {
        system,
        energy,
        stabilization,
        side,
        obstacle,
    } = &declaration.roles;
    let mut errors = Vec::new();
    let form_names: Vec<&str> = forms.iter().map(|f| f.name.as_str()).collect();
    // `role`: the section and its example, e.g. "`system:` (`system: B_h, L_h;`)"
    let mut form = |ident: &Ident, arity: usize, role: &str| -> Option<usize> {
        let name = ident.to_string();
        match forms.iter().position(|f| f.name == name) {
            Some(i) if forms[i].arity() == arity => Some(i),
            Some(i) => {
                errors.push(Diagnostic::token(
                    ident.span(),
                    format!(
                        "`{name}` is {}, but {role} takes {} here",
                        kind(forms[i].arity()),
                        kind(arity)
                    ),
                ));
                None
            }
            None => {
                let hint = closest(&name, form_names.iter().copied())
                    .map(|s| format!("; did you mean `{s}`?"))
                    .unwrap_or_default();
                errors.push(
                    Diagnostic::token(
                        ident.span(),
                        format!("`{name}` is not a form of the model ({role}){hint}"),
                    )
                    .help("name a form defined in `forms:`"),
                );
                None
            }
        }
    };
    let both = |a: Option<usize>, b: Option<usize>| Some([a?, b?]);
    const SYSTEM: &str = "`system:` (`system: B_h, L_h;`)";
    const ENERGY: &str = "`energy:` (`energy: a, ℓ;`)";
    const STABILIZATION: &str = "`stabilization:` (`stabilization: α S against a;`)";
    let system = system
        .as_ref()
        .map(|(b, l)| both(form(b, 2, SYSTEM), form(l, 1, SYSTEM)));
    let energy = energy
        .as_ref()
        .map(|(a, l)| both(form(a, 2, ENERGY), form(l, 1, ENERGY)));
    let stabilization_forms = stabilization.as_ref().map(|s| {
        both(
            form(&s.form, 2, STABILIZATION),
            form(&s.against, 2, STABILIZATION),
        )
        .map(|[s, a]| (s, a))
    });
    let mut param = |ident: &Ident, role: &str| -> Option<usize> {
        let name = ident.to_string();
        let found = symbols.params.iter().position(|p| *p == name);
        if found.is_none() {
            let hint = closest(&name, symbols.params.iter().map(String::as_str))
                .map(|s| format!("; did you mean `{s}`?"))
                .unwrap_or_default();
            errors.push(
                Diagnostic::token(
                    ident.span(),
                    format!("`{name}` is not a parameter of the model ({role}){hint}"),
                )
                .help("declare it under `params:`"),
            );
        }
        found
    };
    let stabilization = stabilization
        .as_ref()
        .zip(stabilization_forms)
        .map(|(s, forms)| {
            let alpha = match &s.alpha {
                Some(a) => Some(param(a, "the stabilization parameter α")?),
                None => None,
            };
            Some((alpha, forms?.0, forms?.1))
        });
    let side = side.as_ref().map(|s| param(s, "the obstacle side s"));
    let obstacle = obstacle.as_ref().map(|(field, data)| {
        let (f, d) = (field.to_string(), data.to_string());
        let found_field = symbols.fields.iter().position(|x| x.name == f && !x.nonnegative);
        if found_field.is_none() {
            errors.push(
                Diagnostic::token(field.span(), format!("`{f}` is not a primal scalar field of the model (the constrained field of `obstacle:`)"))
                    .help("name an unknown declared under `unknowns:` that is not the multiplier"),
            );
        }
        let found_data = symbols.data.iter().position(|x| x.0 == d);
        if found_data.is_none() {
            errors.push(
                Diagnostic::token(data.span(), format!("`{d}` is not a data function of the model (the obstacle of `obstacle:`)"))
                    .help("declare it under `data:`"),
            );
        }
        Some((found_field?, found_data?))
    });
    let by_name = |name: &str, arity: usize| {
        forms
            .iter()
            .position(|f| f.name == name && f.arity() == arity)
    };
    let param_named = |names: &[&str]| {
        symbols
            .params
            .iter()
            .position(|p| names.contains(&p.as_str()))
    };
    let roles = Roles {
        system: system.unwrap_or_else(|| Some([by_name("B_h", 2)?, by_name("L_h", 1)?])),
        energy: energy.unwrap_or_else(|| {
            let load = ["ℓ", "l", "ell"].iter().find_map(|n| by_name(n, 1))?;
            Some([by_name("a", 2)?, load])
        }),
        stabilization: stabilization.unwrap_or_else(|| {
            Some((
                param_named(&["α", "alpha"]),
                by_name("S", 2)?,
                by_name("a", 2)?,
            ))
        }),
        side: side.unwrap_or_else(|| param_named(&["s"])),
        order: 0,
        obstacle: obstacle.unwrap_or_else(|| {
            let data = symbols
                .data
                .iter()
                .position(|d| d.0 == "ψ" || d.0 == "psi")?;
            let field = symbols
                .fields
                .iter()
                .position(|f| !f.nonnegative && (f.name == "u" || f.name == "w"))?;
            symbols
                .fields
                .iter()
                .any(|f| f.nonnegative)
                .then_some((field, data))
        }),
    };
    let order = roles
        .stabilization
        .map(|(_, s, _)| {
            forms[s]
                .terms
                .iter()
                .map(|t| t.h_power.max(0) as u8)
                .max()
                .unwrap_or(0)
        })
        .filter(|&p| p > 0)
        .or_else(|| {
            roles.energy.map(|[a, _]| {
                forms[a]
                    .terms
                    .iter()
                    .map(|t| t.args.iter().map(|a| a.order()).sum::<u8>())
                    .max()
                    .unwrap_or(0)
            })
        })
        .unwrap_or(0);
    (Roles { order, ..roles }, errors)
}

fn kind(arity: usize) -> &'static str {
    if arity == 2 {
        "a bilinear form"
    } else {
        "a linear form"
    }
}
