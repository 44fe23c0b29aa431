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
use fem_reference::ElementKind;
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
    /// `[b, G]`: the constraint `b(v, μ) = (μ, sBv)`, `G(μ) = (μ, sψ)`.
    pub constraint: Option<[usize; 2]>,
    /// `(x, y)` parameter indices of each vector of parameters declared a unit vector
    /// (`unit: n_c;` for `n_c_x`, `n_c_y`): checked at run time, and sampled on the unit
    /// circle by the derived checks.
    pub unit: Vec<(usize, usize)>,
    /// Whether the strong form was derived from `a`, `ℓ` and `b`
    /// ([`crate::derived`]), so that the stabilization and the estimator were checked
    /// against it; set after the roles are resolved.
    pub strong_form: bool,
    /// The highest derivative of the constrained field (`obstacle:`) in the energy form
    /// `a`: the order `m` of its energy norm `|w|_m` (1 for a membrane and Timoshenko's
    /// deflection, 2 for plates and Euler–Bernoulli); 0 where unknown.
    pub constrained_order: u8,
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
        constraint,
        unit,
    } = &declaration.roles;
    let mut lookup = Lookup {
        forms,
        symbols,
        errors: Vec::new(),
    };
    let both = |a: Option<usize>, b: Option<usize>| Some([a?, b?]);
    const SYSTEM: &str = "`system:` (`system: B_h, L_h;`)";
    const ENERGY: &str = "`energy:` (`energy: a, ℓ;`)";
    const STABILIZATION: &str = "`stabilization:` (`stabilization: α S against a;`)";
    const CONSTRAINT: &str = "`constraint:` (`constraint: b, G;`)";
    let constraint = constraint.as_ref().map(|(b, g)| {
        let b = lookup.form(b, 2, CONSTRAINT);
        both(b, lookup.form(g, 1, CONSTRAINT))
    });
    let system = system.as_ref().map(|(b, l)| {
        let b = lookup.form(b, 2, SYSTEM);
        both(b, lookup.form(l, 1, SYSTEM))
    });
    let energy = energy.as_ref().map(|(a, l)| {
        let a = lookup.form(a, 2, ENERGY);
        both(a, lookup.form(l, 1, ENERGY))
    });
    let stabilization = stabilization.as_ref().map(|s| {
        let form = lookup.form(&s.form, 2, STABILIZATION);
        let against = lookup.form(&s.against, 2, STABILIZATION);
        let alpha = match &s.alpha {
            Some(a) => Some(lookup.param(a, "the stabilization parameter α")?),
            None => None,
        };
        Some((alpha, form?, against?))
    });
    let side = side
        .as_ref()
        .map(|s| lookup.param(s, "the obstacle side s"));
    let obstacle = obstacle
        .as_ref()
        .map(|(field, data)| lookup.obstacle(field, data));
    let unit = unit.iter().filter_map(|v| lookup.unit(v)).collect();
    let conventional = Conventional { forms, symbols };
    let roles = Roles {
        system: system.unwrap_or_else(|| conventional.system()),
        energy: energy.unwrap_or_else(|| conventional.energy()),
        stabilization: stabilization.unwrap_or_else(|| conventional.stabilization()),
        side: side.unwrap_or_else(|| conventional.param(&["s"])),
        order: 0,
        obstacle: obstacle.unwrap_or_else(|| conventional.obstacle()),
        constraint: constraint.unwrap_or_else(|| conventional.constraint()),
        unit,
        strong_form: false,
        constrained_order: 0,
    };
    let order = operator_order(&roles, forms);
    let constrained_order = constrained_order(&roles, symbols, forms);
    if roles.system.is_some() {
        lookup.continuous_multipliers(declaration);
    }
    (
        Roles {
            order,
            constrained_order,
            ..roles
        },
        lookup.errors,
    )
}

/// The declared roles' names looked up among the forms, parameters, fields and data,
/// with an error at each name that does not fit.
struct Lookup<'a> {
    forms: &'a [Form],
    symbols: &'a Symbols,
    errors: Vec<Diagnostic>,
}

impl Lookup<'_> {
    /// The form `ident` of `arity` (2 bilinear, 1 linear) for `role`: the section and
    /// its example, e.g. "`system:` (`system: B_h, L_h;`)".
    fn form(&mut self, ident: &Ident, arity: usize, role: &str) -> Option<usize> {
        let name = ident.to_string();
        let forms = self.forms;
        match forms.iter().position(|f| f.name == name) {
            Some(i) if forms[i].arity() == arity => Some(i),
            Some(i) => {
                self.errors.push(Diagnostic::token(
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
                let hint = closest(&name, forms.iter().map(|f| f.name.as_str()))
                    .map(|s| format!("; did you mean `{s}`?"))
                    .unwrap_or_default();
                self.errors.push(
                    Diagnostic::token(
                        ident.span(),
                        format!("`{name}` is not a form of the model ({role}){hint}"),
                    )
                    .help("name a form defined in `forms:`"),
                );
                None
            }
        }
    }

    /// The parameter `ident` for `role`.
    fn param(&mut self, ident: &Ident, role: &str) -> Option<usize> {
        let name = ident.to_string();
        let params = &self.symbols.params;
        let found = params.iter().position(|p| *p == name);
        if found.is_none() {
            let hint = closest(&name, params.iter().map(String::as_str))
                .map(|s| format!("; did you mean `{s}`?"))
                .unwrap_or_default();
            self.errors.push(
                Diagnostic::token(
                    ident.span(),
                    format!("`{name}` is not a parameter of the model ({role}){hint}"),
                )
                .help("declare it under `params:`"),
            );
        }
        found
    }

    /// An error at each continuous multiplier of a model that solves for it (`system:`)
    /// other than a P1 multiplier on a boundary part: the solvers eliminate a multiplier
    /// constrained coefficient-wise cell by cell. A P1 one on a boundary part (Signorini's
    /// `λ: P1` on Γ_C) is nonnegative pointwise iff its vertex values are, and the
    /// runtime gives it a DOF map on the part's vertices; a model without a system (the
    /// nodal method's) only reads its multiplier, the density of the nodal forces.
    fn continuous_multipliers(&mut self, declaration: &Declaration) {
        for u in &declaration.unknowns {
            let Some(e) = u.element else { continue };
            let boundary_p1 = e == ElementKind::P1 && !declaration.facets.is_empty();
            if u.nonnegative && e.is_continuous() && !boundary_p1 {
                self.errors.push(
                    Diagnostic::token(
                        u.element_name.span(),
                        format!("`{} >= 0` on a continuous {} field: a multiplier the system solves for, constrained coefficient-wise, must be discontinuous", u.name, e.name()),
                    )
                    .help("declare the multiplier as `λ: P0 >= 0` or `λ: P1disc >= 0` (or `λ: P1 >= 0` on a model with `facets:`, a boundary multiplier, or on a model without `system:`, the nodal method's force density)"),
                );
            }
        }
    }

    /// `unit: X`: the parameters `X_x` and `X_y`, declared under `params:`.
    fn unit(&mut self, ident: &Ident) -> Option<(usize, usize)> {
        let name = ident.to_string();
        let params = &self.symbols.params;
        let find = |axis: &str| params.iter().position(|p| *p == format!("{name}_{axis}"));
        let found = find("x").zip(find("y"));
        if found.is_none() {
            self.errors.push(
                Diagnostic::token(
                    ident.span(),
                    format!("`unit: {name}` names the vector of the parameters `{name}_x` and `{name}_y`, which are not both declared"),
                )
                .help(format!("declare them under `params:` (`params: …, {name}_x, {name}_y;`)")),
            );
        }
        found
    }

    /// `obstacle: field >= data`: a primal scalar field and a data function.
    fn obstacle(&mut self, field: &Ident, data: &Ident) -> Option<(usize, usize)> {
        let (f, d) = (field.to_string(), data.to_string());
        let found_field = self
            .symbols
            .fields
            .iter()
            .position(|x| x.name == f && !x.nonnegative);
        if found_field.is_none() {
            self.errors.push(
                Diagnostic::token(field.span(), format!("`{f}` is not a primal scalar field of the model (the constrained field of `obstacle:`)"))
                    .help("name an unknown declared under `unknowns:` that is not the multiplier"),
            );
        }
        let found_data = self.symbols.data.iter().position(|x| x.0 == d);
        if found_data.is_none() {
            self.errors.push(
                Diagnostic::token(
                    data.span(),
                    format!(
                        "`{d}` is not a data function of the model (the obstacle of `obstacle:`)"
                    ),
                )
                .help("declare it under `data:`"),
            );
        }
        Some((found_field?, found_data?))
    }
}

/// The roles a model that does not declare them has by the conventional names: `B_h`,
/// `L_h`; `a`, `ℓ`; `α S against a`; `s`; `u ≥ ψ` or `w ≥ ψ` beside a multiplier.
struct Conventional<'a> {
    forms: &'a [Form],
    symbols: &'a Symbols,
}

impl Conventional<'_> {
    fn form(&self, name: &str, arity: usize) -> Option<usize> {
        self.forms
            .iter()
            .position(|f| f.name == name && f.arity() == arity)
    }

    fn param(&self, names: &[&str]) -> Option<usize> {
        self.symbols
            .params
            .iter()
            .position(|p| names.contains(&p.as_str()))
    }

    fn system(&self) -> Option<[usize; 2]> {
        Some([self.form("B_h", 2)?, self.form("L_h", 1)?])
    }

    fn energy(&self) -> Option<[usize; 2]> {
        let load = ["ℓ", "l", "ell"].iter().find_map(|n| self.form(n, 1))?;
        Some([self.form("a", 2)?, load])
    }

    fn stabilization(&self) -> Option<(Option<usize>, usize, usize)> {
        Some((
            self.param(&["α", "alpha"]),
            self.form("S", 2)?,
            self.form("a", 2)?,
        ))
    }

    fn constraint(&self) -> Option<[usize; 2]> {
        let gap = self.form("G", 1).or_else(|| self.form("g", 1))?;
        Some([self.form("b", 2)?, gap])
    }

    fn obstacle(&self) -> Option<(usize, usize)> {
        let fields = &self.symbols.fields;
        let data = self
            .symbols
            .data
            .iter()
            .position(|d| d.0 == "ψ" || d.0 == "psi")?;
        let field = fields
            .iter()
            .position(|f| !f.nonnegative && (f.name == "u" || f.name == "w"))?;
        fields
            .iter()
            .any(|f| f.nonnegative)
            .then_some((field, data))
    }
}

/// The order `p` of the operator the stabilization measures ([`Roles::order`]): the
/// largest power of h in the stabilization's terms, else the largest total derivative
/// order of the energy's bilinear form's terms; 0 where neither is known.
fn operator_order(roles: &Roles, forms: &[Form]) -> u8 {
    roles
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
        .unwrap_or(0)
}

/// [`Roles::constrained_order`]: the largest derivative order of the constrained field's
/// arguments (trial or test) in the energy's bilinear form.
fn constrained_order(roles: &Roles, symbols: &Symbols, forms: &[Form]) -> u8 {
    let (Some((field, _)), Some([a, _])) = (roles.obstacle, roles.energy) else {
        return 0;
    };
    forms[a]
        .terms
        .iter()
        .flat_map(|t| t.args.iter())
        .filter(|x| symbols.field_of(x.symbol) == field)
        .map(|x| x.order())
        .max()
        .unwrap_or(0)
}

fn kind(arity: usize) -> &'static str {
    if arity == 2 {
        "a bilinear form"
    } else {
        "a linear form"
    }
}
