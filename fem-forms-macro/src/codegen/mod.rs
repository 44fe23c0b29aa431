//! Kernel IR → the generated Rust module.
//!
//! The driver (this file) writes what every model has — the `Model` type and its
//! `runtime::Model` impl, one module of kernels per form, the typed handles — and asks
//! the cell's backend for each block kernel:
//! - `backend.rs`: the interface a cell kind implements ([`backend::CellBackend`]);
//! - `emit.rs`: the cell-independent parts of a kernel, among them the one quadrature
//!   and data-loop emitter;
//! - `interval.rs`, `triangle.rs`: the backends.
//!
//! Files depend in one direction only: `backend` ← `emit` ← backends ← driver.

mod backend;
mod curved;
mod emit;
mod estimator;
mod estimator_interval;
mod facet;
mod interval;
mod triangle;

use crate::analysis::{Block, Form, Symbols};
use crate::declaration::Declaration;
use backend::CellBackend;
use fem_reference::CellKind;
use proc_macro2::{Ident, Span, TokenStream};
use quote::quote;

/// The backend of a cell kind.
fn backend(cell: Option<CellKind>) -> &'static dyn CellBackend {
    match cell {
        Some(CellKind::Triangle) => &triangle::Triangle,
        // An unknown cell is a compile error reported before code generation.
        _ => &interval::Interval,
    }
}

/// The match arms of the `Model` impl's dispatch to the block kernels.
#[derive(Default)]
struct Dispatch {
    matrix: Vec<TokenStream>,
    add: Vec<TokenStream>,
    vector: Vec<TokenStream>,
    /// The arms of `element_matrix_on_cell` and `element_vector_on_cell`, emitted only
    /// when a block has a transformed element (`transformed`), so that the code of
    /// other models stays as it was.
    matrix_on_cell: Vec<TokenStream>,
    vector_on_cell: Vec<TokenStream>,
    transformed: bool,
    /// The arms of `element_matrix_curved` and `element_vector_curved` (triangles only).
    matrix_curved: Vec<TokenStream>,
    vector_curved: Vec<TokenStream>,
    /// `FACET_PARTS`, `FACET_BLOCKS` and the facet dispatch (`facet.rs`; empty without
    /// `facets:`).
    facet_items: TokenStream,
    /// `HAS_ESTIMATOR` and the indicator dispatch (`estimator.rs`; empty without
    /// `estimator:`).
    estimator_items: TokenStream,
}

/// What the driver generates for one form.
struct FormCode {
    /// The module of its kernels.
    module: TokenStream,
    /// Its `FormInfo`.
    info: TokenStream,
}

/// The `BlockInfo` of a block.
fn block_info(
    block: &Block,
    symbols: &Symbols,
    points: usize,
    runtime: &TokenStream,
) -> TokenStream {
    let test_field = block.test_field;
    let trial_field = match block.trial_field {
        Some(f) => quote!(::core::option::Option::Some(#f)),
        None => quote!(::core::option::Option::None),
    };
    let description = emit::describe_block(block, symbols);
    quote! {
        #runtime::BlockInfo {
            test_field: #test_field,
            trial_field: #trial_field,
            quadrature_points: #points,
            terms: #description,
        }
    }
}

/// The kernels module and `FormInfo` of form `form_index`, adding its dispatch arms.
fn form_code(
    backend: &dyn CellBackend,
    form_index: usize,
    form: &Form,
    symbols: &Symbols,
    runtime: &TokenStream,
    dispatch: &mut Dispatch,
) -> FormCode {
    let form_ident = Ident::new(&form.name, Span::call_site());
    let mut functions = Vec::new();
    let mut block_infos = Vec::new();
    for (block_index, block) in form.blocks.iter().enumerate() {
        let code = emit::block_kernel(backend, block, symbols, runtime, &form.name);
        functions.push(code.function);
        block_infos.push(block_info(block, symbols, code.quadrature_points, runtime));
        let name = emit::block_ident(block, symbols);
        if emit::is_transformed(block, symbols) {
            // Without global numbers (`element_matrix`), edges are oriented by the local
            // vertex numbers, as on a cell numbered increasingly.
            dispatch.transformed = true;
            if block.trial_field.is_some() {
                dispatch.add.push(quote! {
                    (#form_index, #block_index) => #runtime::kernel::add_matrices_on_cells(mesh, positions, stride, offset, values, |x, g| #form_ident::#name(x, g, p, d)),
                });
                dispatch.matrix.push(quote! {
                    (#form_index, #block_index) => #runtime::kernel::store_matrix(&#form_ident::#name(x, &[0, 1, 2], p, d), out),
                });
                dispatch.matrix_on_cell.push(quote! {
                    (#form_index, #block_index) => #runtime::kernel::store_matrix(&#form_ident::#name(x, g, p, d), out),
                });
            } else {
                dispatch.vector.push(quote! {
                    (#form_index, #block_index) => #runtime::kernel::store_vector(&#form_ident::#name(x, &[0, 1, 2], p, d), out),
                });
                dispatch.vector_on_cell.push(quote! {
                    (#form_index, #block_index) => #runtime::kernel::store_vector(&#form_ident::#name(x, g, p, d), out),
                });
            }
        } else if block.trial_field.is_some() {
            dispatch.matrix_on_cell.push(quote! {
                (#form_index, #block_index) => #runtime::kernel::store_matrix(&#form_ident::#name(x, p, d), out),
            });
            dispatch.add.push(quote! {
                (#form_index, #block_index) => #runtime::kernel::add_matrices(mesh, positions, stride, offset, values, |x| #form_ident::#name(x, p, d)),
            });
            dispatch.matrix.push(quote! {
                (#form_index, #block_index) => #runtime::kernel::store_matrix(&#form_ident::#name(x, p, d), out),
            });
        } else {
            dispatch.vector_on_cell.push(quote! {
                (#form_index, #block_index) => #runtime::kernel::store_vector(&#form_ident::#name(x, p, d), out),
            });
            dispatch.vector.push(quote! {
                (#form_index, #block_index) => #runtime::kernel::store_vector(&#form_ident::#name(x, p, d), out),
            });
        }
    }
    if backend.cell_variant() == "Triangle" {
        curved_code(form_index, form, symbols, runtime, dispatch, &mut functions);
    }
    functions.extend(facet_modules(form, symbols, runtime));
    let source = &form.source;
    let arity = form.arity();
    let dropped = form.dropped;
    let doc = format!(" Kernels of `{}`.", form.source);
    let dropped_doc = format!(
        " {} term(s) vanish for the chosen elements and were dropped.",
        form.dropped
    );
    let module = quote! {
        #[doc = #doc]
        #[doc = #dropped_doc]
        pub mod #form_ident {
            use super::*;
            /// Index of this form in `Model::FORMS`.
            pub const INDEX: usize = #form_index;
            /// The definition as written in the model file.
            pub const SOURCE: &str = #source;
            #(#functions)*
        }
    };
    let name = &form.name;
    let info = quote! {
        #runtime::FormInfo {
            name: #name,
            source: #source,
            arity: #arity,
            dropped_terms: #dropped,
            blocks: &[#(#block_infos),*],
        }
    };
    FormCode { module, info }
}

/// One module per boundary part a form integrates over (`on_Γ_C`), holding the facet
/// kernels of its blocks (`codegen/facet.rs`).
fn facet_modules(form: &Form, symbols: &Symbols, runtime: &TokenStream) -> Vec<TokenStream> {
    (0..symbols.facets.len())
        .filter_map(|part| {
            let kernels: Vec<TokenStream> = form
                .facet_blocks
                .iter()
                .filter(|(p, _)| *p == part)
                .map(|(_, block)| {
                    facet::facet_kernel(block, symbols, runtime, &form.name, &symbols.facets[part])
                })
                .collect();
            if kernels.is_empty() {
                return None;
            }
            let module = facet::part_ident(&symbols.facets[part]);
            let doc = format!(
                " Facet kernels of `{}` on the edges of the boundary part `{}`.",
                form.name, symbols.facets[part]
            );
            Some(quote! {
                #[doc = #doc]
                pub mod #module {
                    use super::*;
                    #(#kernels)*
                }
            })
        })
        .collect()
}

/// The curved kernels of a form's blocks (appended to `functions`) and their dispatch
/// arms: a kernel, or an error naming the form and block where there is none.
fn curved_code(
    form_index: usize,
    form: &Form,
    symbols: &Symbols,
    runtime: &TokenStream,
    dispatch: &mut Dispatch,
    functions: &mut Vec<TokenStream>,
) {
    let form_ident = Ident::new(&form.name, Span::call_site());
    for (block_index, block) in form.blocks.iter().enumerate() {
        let arms = if block.trial_field.is_some() {
            &mut dispatch.matrix_curved
        } else {
            &mut dispatch.vector_curved
        };
        if let Some(reason) = curved::refusal(block, symbols) {
            let test = &symbols.fields[block.test_field].test_name;
            let what = match block.trial_field {
                Some(f) => format!("block ({test}, {})", symbols.fields[f].name),
                None => format!("block {test}"),
            };
            let message = format!(
                "form `{}`, {what}: no kernel on curved cells: {reason}",
                form.name
            );
            arms.push(quote! {
                (#form_index, #block_index) => ::core::result::Result::Err(#runtime::Error::Input(::std::string::String::from(#message))),
            });
            continue;
        }
        functions.push(curved::curved_kernel(block, symbols, runtime, &form.name));
        let name = curved::curved_ident(block, symbols);
        let store = if block.trial_field.is_some() {
            quote!(store_matrix)
        } else {
            quote!(store_vector)
        };
        arms.push(quote! {
            (#form_index, #block_index) => {
                #runtime::kernel::#store(&#form_ident::#name(x, p, d), out);
                ::core::result::Result::Ok(())
            }
        });
    }
}

/// The model's doc comment as one line (`Model::DESCRIPTION`).
fn description(declaration: &Declaration) -> String {
    declaration
        .attrs
        .iter()
        .filter_map(|a| match &a.meta {
            syn::Meta::NameValue(nv) if nv.path.is_ident("doc") => match &nv.value {
                syn::Expr::Lit(syn::ExprLit {
                    lit: syn::Lit::Str(s),
                    ..
                }) => Some(s.value().trim().to_string()),
                _ => None,
            },
            _ => None,
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// One typed handle: `pub const name: runtime::Kind<super::Model> = runtime::Kind::new(index);`.
fn handle(name: &str, kind: &str, index: usize, doc: &str, runtime: &TokenStream) -> TokenStream {
    let ident = Ident::new(name, Span::call_site());
    let kind = Ident::new(kind, Span::call_site());
    quote! {
        #[doc = #doc]
        pub const #ident: #runtime::model::#kind<super::Model> = #runtime::model::#kind::new(#index);
    }
}

/// The modules `forms`, `fields`, `params` and `data` of typed handles: a misspelled
/// name is a compile error, and a handle of one model cannot be passed to another.
fn handles(symbols: &Symbols, forms: &[Form], runtime: &TokenStream) -> TokenStream {
    let forms = forms
        .iter()
        .enumerate()
        .map(|(i, f)| handle(&f.name, "FormId", i, &format!(" `{}`", f.source), runtime));
    let fields = symbols.fields.iter().enumerate().flat_map(|(i, f)| {
        let component = f.component.map_or(String::new(), |(v, axis)| {
            format!(
                " Component {} of the vector field `{}`.",
                ["x", "y"][axis.min(1)],
                symbols.vectors[v].name
            )
        });
        [
            handle(
                &f.name,
                "FieldId",
                i,
                &format!(" Unknown `{}` ({}).{component}", f.name, f.element.name()),
                runtime,
            ),
            handle(
                &f.test_name,
                "FieldId",
                i,
                &format!(
                    " Test function `{}`: the field of `{}`.",
                    f.test_name, f.name
                ),
                runtime,
            ),
        ]
    });
    let vectors = symbols.vectors.iter().flat_map(|v| {
        let indices: Vec<usize> = (v.first_field..v.first_field + v.components).collect();
        let n = indices.len();
        let doc = |name: &str, what: &str| {
            format!(" The fields of the components of {what} `{name}`, by axis.")
        };
        [
            (v.name.clone(), doc(&v.name, "the vector field")),
            (
                v.test_name.clone(),
                doc(&v.test_name, &format!("the test function of `{}`:", v.name)),
            ),
        ]
        .map(|(name, doc)| {
            let ident = Ident::new(&name, Span::call_site());
            quote! {
                #[doc = #doc]
                pub const #ident: [#runtime::model::FieldId<super::Model>; #n] =
                    [#(#runtime::model::FieldId::new(#indices)),*];
            }
        })
    });
    let params = symbols
        .params
        .iter()
        .enumerate()
        .map(|(i, p)| handle(p, "ParamId", i, &format!(" Parameter `{p}`."), runtime));
    let data = symbols
        .data
        .iter()
        .enumerate()
        .map(|(i, (d, _))| handle(d, "DataId", i, &format!(" Data function `{d}`."), runtime));
    let parts = symbols
        .facets
        .iter()
        .enumerate()
        .map(|(i, p)| handle(p, "PartId", i, &format!(" Boundary part `{p}`."), runtime));
    quote! {
        /// Typed handles of the forms, for `Model::form` and the functions that take a form.
        pub mod forms {
            #(#forms)*
        }
        /// Typed handles of the fields, by unknown or by test function.
        pub mod fields {
            #(#fields)*
            #(#vectors)*
        }
        /// Typed handles of the parameters, for `Coefficients::from_ids`.
        pub mod params {
            #(#params)*
        }
        /// Typed handles of the data functions, for `Coefficients::from_ids`.
        pub mod data {
            #(#data)*
        }
        /// Typed handles of the boundary parts the forms integrate over (`facets:`).
        pub mod facets {
            #(#parts)*
        }
    }
}

/// The entries of `Model::DIRICHLET` and of `Model::FIELDS`.
fn field_tables(
    declaration: &Declaration,
    symbols: &Symbols,
) -> (Vec<TokenStream>, Vec<TokenStream>) {
    let runtime = &declaration.runtime;
    let dirichlet = declaration
        .dirichlet
        .iter()
        .map(|(field, data)| {
            // Both names were checked against the declaration before code generation.
            let f = symbols
                .fields
                .iter()
                .position(|x| *field == x.name)
                .unwrap_or(0);
            let g = symbols.data.iter().position(|x| *data == x.0).unwrap_or(0);
            quote!((#f, #g))
        })
        .collect();
    let field_infos = symbols
        .fields
        .iter()
        .map(|f| {
            let (name, test, nonnegative) = (&f.name, &f.test_name, f.nonnegative);
            let element = Ident::new(&format!("{:?}", f.element), Span::call_site());
            quote! {
                #runtime::FieldInfo {
                    name: #name,
                    test_name: #test,
                    element: #runtime::ElementKind::#element,
                    nonnegative: #nonnegative,
                }
            }
        })
        .collect();
    (dirichlet, field_infos)
}

/// The role constants of the `Model` impl (`SYSTEM`, `ENERGY`, `STABILIZATION`, `SIDE`).
fn role_items(roles: &crate::roles::Roles, runtime: &TokenStream) -> TokenStream {
    let pair = |p: Option<[usize; 2]>| match p {
        Some([a, b]) => quote!(::core::option::Option::Some([#a, #b])),
        None => quote!(::core::option::Option::None),
    };
    let system = pair(roles.system);
    let energy = pair(roles.energy);
    let constraint = pair(roles.constraint);
    let stabilization = match roles.stabilization {
        Some((alpha, form, against)) => {
            let alpha = match alpha {
                Some(a) => quote!(::core::option::Option::Some(#a)),
                None => quote!(::core::option::Option::None),
            };
            quote! {
            ::core::option::Option::Some(#runtime::model::StabilizationRole {
                alpha: #alpha,
                form: #form,
                against: #against,
            })
            }
        }
        None => quote!(::core::option::Option::None),
    };
    let side = match roles.side {
        Some(s) => quote!(::core::option::Option::Some(#s)),
        None => quote!(::core::option::Option::None),
    };
    let obstacle = match roles.obstacle {
        Some((field, data)) => quote!(::core::option::Option::Some([#field, #data])),
        None => quote!(::core::option::Option::None),
    };
    let order = roles.order;
    let constrained_order = roles.constrained_order;
    let strong_form = roles.strong_form;
    // emitted only when there is one, so that models without keep their code
    let unit = (!roles.unit.is_empty()).then(|| {
        let pairs = roles.unit.iter().map(|&(x, y)| quote!((#x, #y)));
        quote!(const UNIT_PARAMS: &'static [(usize, usize)] = &[#(#pairs),*];)
    });
    quote! {
        #unit
        const ORDER: u8 = #order;
        const CONSTRAINED_ORDER: u8 = #constrained_order;
        const STRONG_FORM: bool = #strong_form;
        const OBSTACLE: ::core::option::Option<[usize; 2]> = #obstacle;
        const SYSTEM: ::core::option::Option<[usize; 2]> = #system;
        const ENERGY: ::core::option::Option<[usize; 2]> = #energy;
        const CONSTRAINT: ::core::option::Option<[usize; 2]> = #constraint;
        const STABILIZATION: ::core::option::Option<#runtime::model::StabilizationRole> = #stabilization;
        const SIDE: ::core::option::Option<usize> = #side;
    }
}

/// The `runtime::Model` impl: names, fields, forms and the dispatch to the kernels.
fn model_impl(
    declaration: &Declaration,
    symbols: &Symbols,
    backend: &dyn CellBackend,
    form_infos: &[TokenStream],
    dispatch: &Dispatch,
    roles: &crate::roles::Roles,
) -> TokenStream {
    let runtime = &declaration.runtime;
    let role_items = role_items(roles, runtime);
    let model_name = declaration.name.to_string();
    let np = symbols.params.len();
    let nd = symbols.data.len();
    let cell = Ident::new(backend.cell_variant(), Span::call_site());
    let coordinates = backend.coordinates();
    let cell_text = backend.coordinates_message();
    let (dirichlet, field_infos) = field_tables(declaration, symbols);
    let params = &symbols.params;
    let data = symbols.data.iter().map(|d| &d.0);
    let description = description(declaration);
    // Emitted only when there is one, so that models without keep their code.
    let positive = (!symbols.positive.is_empty()).then(|| {
        let positive = &symbols.positive;
        quote!(const POSITIVE_PARAMS: &'static [usize] = &[#(#positive),*];)
    });
    let Dispatch {
        matrix,
        add,
        vector,
        matrix_on_cell,
        vector_on_cell,
        transformed,
        matrix_curved,
        vector_curved,
        facet_items,
        estimator_items,
    } = dispatch;
    let on_cell = transformed.then(|| {
        quote! {
            fn element_matrix_on_cell(
                form: usize,
                block: usize,
                vertices: &[f64],
                global: &[usize],
                params: &[f64],
                data: &[&#runtime::DataFn],
                out: &mut [f64],
            ) {
                let x: &[f64; #coordinates] = vertices.try_into().expect(#cell_text);
                let g: &[usize; 3] = global.try_into().expect("a triangle has three vertex numbers");
                let p: &[f64; #np] = params.try_into().expect("parameter count checked by the runtime");
                let d: &[&#runtime::DataFn; #nd] = data.try_into().expect("data count checked by the runtime");
                match (form, block) {
                    #(#matrix_on_cell)*
                    _ => panic!("{}: form {} has no bilinear block {}", #model_name, form, block),
                }
            }

            fn element_vector_on_cell(
                form: usize,
                block: usize,
                vertices: &[f64],
                global: &[usize],
                params: &[f64],
                data: &[&#runtime::DataFn],
                out: &mut [f64],
            ) {
                let x: &[f64; #coordinates] = vertices.try_into().expect(#cell_text);
                let g: &[usize; 3] = global.try_into().expect("a triangle has three vertex numbers");
                let p: &[f64; #np] = params.try_into().expect("parameter count checked by the runtime");
                let d: &[&#runtime::DataFn; #nd] = data.try_into().expect("data count checked by the runtime");
                match (form, block) {
                    #(#vector_on_cell)*
                    _ => panic!("{}: form {} has no linear block {}", #model_name, form, block),
                }
            }
        }
    });
    // Triangle models only: interval models keep the trait's default (an error), and
    // their generated code stays as it was.
    let curved = (backend.cell_variant() == "Triangle").then(|| {
        let nodes_message = "a curved triangle has twelve node coordinates (six nodes), not ";
        let signature = |name: Ident| {
            quote! {
                fn #name(
                    form: usize,
                    block: usize,
                    nodes: &[f64],
                    params: &[f64],
                    data: &[&#runtime::DataFn],
                    out: &mut [f64],
                ) -> #runtime::Result<()>
            }
        };
        let matrix = signature(Ident::new("element_matrix_curved", Span::call_site()));
        let vector = signature(Ident::new("element_vector_curved", Span::call_site()));
        let prelude = quote! {
            let x: &[f64; 12] = match nodes.try_into() {
                ::core::result::Result::Ok(x) => x,
                ::core::result::Result::Err(_) => {
                    return ::core::result::Result::Err(#runtime::Error::Input(::std::format!("{}{}", #nodes_message, nodes.len())));
                }
            };
            let p: &[f64; #np] = params.try_into().expect("parameter count checked by the runtime");
            let d: &[&#runtime::DataFn; #nd] = data.try_into().expect("data count checked by the runtime");
        };
        quote! {
            #[allow(unused_variables)]
            #matrix {
                #prelude
                match (form, block) {
                    #(#matrix_curved)*
                    _ => ::core::result::Result::Err(#runtime::Error::Input(::std::format!("{}: form {} has no bilinear block {}", #model_name, form, block))),
                }
            }

            #[allow(unused_variables)]
            #vector {
                #prelude
                match (form, block) {
                    #(#vector_curved)*
                    _ => ::core::result::Result::Err(#runtime::Error::Input(::std::format!("{}: form {} has no linear block {}", #model_name, form, block))),
                }
            }
        }
    });
    quote! {
        impl #runtime::Model for Model {
            const NAME: &'static str = #model_name;
            const DESCRIPTION: &'static str = #description;
            const CELL: #runtime::CellKind = #runtime::CellKind::#cell;
            const DIRICHLET: &'static [(usize, usize)] = &[#(#dirichlet),*];
            const FIELDS: &'static [#runtime::FieldInfo] = &[#(#field_infos),*];
            const PARAMS: &'static [&'static str] = &[#(#params),*];
            const DATA: &'static [&'static str] = &[#(#data),*];
            const FORMS: &'static [#runtime::FormInfo] = &[#(#form_infos),*];
            #positive
            #role_items

            fn element_matrix(
                form: usize,
                block: usize,
                vertices: &[f64],
                params: &[f64],
                data: &[&#runtime::DataFn],
                out: &mut [f64],
            ) {
                let x: &[f64; #coordinates] = vertices.try_into().expect(#cell_text);
                let p: &[f64; #np] = params.try_into().expect("parameter count checked by the runtime");
                let d: &[&#runtime::DataFn; #nd] = data.try_into().expect("data count checked by the runtime");
                match (form, block) {
                    #(#matrix)*
                    _ => panic!("{}: form {} has no bilinear block {}", #model_name, form, block),
                }
            }

            fn add_element_matrices<G: #runtime::mesh::Mesh>(
                form: usize,
                block: usize,
                mesh: &G,
                params: &[f64],
                data: &[&#runtime::DataFn],
                positions: &[#runtime::kernel::Position],
                stride: usize,
                offset: usize,
                values: &mut #runtime::kernel::Accumulator,
            ) {
                let p: &[f64; #np] = params.try_into().expect("parameter count checked by the runtime");
                let d: &[&#runtime::DataFn; #nd] = data.try_into().expect("data count checked by the runtime");
                match (form, block) {
                    #(#add)*
                    _ => panic!("{}: form {} has no bilinear block {}", #model_name, form, block),
                }
            }

            fn element_vector(
                form: usize,
                block: usize,
                vertices: &[f64],
                params: &[f64],
                data: &[&#runtime::DataFn],
                out: &mut [f64],
            ) {
                let x: &[f64; #coordinates] = vertices.try_into().expect(#cell_text);
                let p: &[f64; #np] = params.try_into().expect("parameter count checked by the runtime");
                let d: &[&#runtime::DataFn; #nd] = data.try_into().expect("data count checked by the runtime");
                match (form, block) {
                    #(#vector)*
                    _ => panic!("{}: form {} has no linear block {}", #model_name, form, block),
                }
            }

            #on_cell

            #curved

            #facet_items

            #estimator_items
        }
    }
}

/// The whole generated module.
pub fn generate(
    declaration: &Declaration,
    symbols: &Symbols,
    forms: &[Form],
    roles: &crate::roles::Roles,
    estimator: Option<&crate::estimator::Estimator>,
) -> TokenStream {
    let runtime = &declaration.runtime;
    let backend = backend(declaration.cell);
    let mut dispatch = Dispatch::default();
    let (form_modules, form_infos): (Vec<TokenStream>, Vec<TokenStream>) = forms
        .iter()
        .enumerate()
        .map(|(i, form)| {
            let code = form_code(backend, i, form, symbols, runtime, &mut dispatch);
            (code.module, code.info)
        })
        .unzip();
    dispatch.facet_items =
        facet::model_items(symbols, forms, runtime, &declaration.name.to_string());
    let interval = declaration.cell != Some(CellKind::Triangle);
    let estimator_module = estimator.map(|e| {
        if interval {
            estimator_interval::module(e, symbols, runtime)
        } else {
            estimator::module(e, symbols, runtime)
        }
    });
    if let Some(e) = estimator {
        dispatch.estimator_items =
            estimator::model_items(symbols, e, runtime, &declaration.name.to_string(), interval);
    }
    let model_impl = model_impl(declaration, symbols, backend, &form_infos, &dispatch, roles);
    let handles = handles(symbols, forms, runtime);
    let module = &declaration.name;
    let vis = &declaration.vis;
    let attrs = &declaration.attrs;
    let np = symbols.params.len();
    let nd = symbols.data.len();
    quote! {
        #(#attrs)*
        #[allow(non_snake_case, non_upper_case_globals, mixed_script_confusables, confusable_idents, uncommon_codepoints, clippy::all)]
        #vis mod #module {
            /// The model: its fields, parameters, data and forms, and the dispatch to its kernels.
            #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
            pub struct Model;

            /// Number of runtime parameters.
            pub const PARAMS: usize = #np;
            /// Number of data functions.
            pub const DATA: usize = #nd;

            #handles

            #(#form_modules)*

            #estimator_module

            #model_impl
        }
    }
}
