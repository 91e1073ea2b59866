//! Rust source for one robot: a generic struct with one inherent method per quantity of the
//! derivation's catalogue, the runtime's `Dynamics` trait delegating to them, and the link
//! enum with the tables link kinematics walks.
//!
//! One emitter method per generated item, as prost-build's code generator does it: the
//! parameter fields, the link enum, each kind of [`Evaluation`], the trait implementation.

mod batch;
mod contact;
mod items;
mod links;
mod methods;
mod mpc;
mod solve;
mod traits;

use std::collections::BTreeSet;

use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote};

use super::expr::Ctx;
use super::names::comment_text;
use crate::cas::{Graph, OpCount};
use crate::dynamics::{Derivation, Evaluation, Home, Quantity};
use crate::model::Model;
use items::{fields, Fields};
use traits::Trait;

/// What the emitted file is called and says about itself.
#[derive(Clone, Debug)]
pub struct EmitOptions {
    /// The generated type, e.g. `Panda`; the link enum is `PandaLink`.
    pub type_name: String,
    /// The URDF's file name (no directories: output must not depend on where files live).
    pub source_name: String,
    /// How to regenerate the file, for the banner.
    pub regenerate: String,
    /// The most operations one generated function body may hold; longer bodies are split
    /// into non-inlined blocks (`Builder::max_function_ops`).
    pub max_function_ops: usize,
    /// The same for the derivatives' bodies, `Derivation::derivative_quantities`
    /// (`Builder::max_derivative_function_ops`).
    pub max_derivative_function_ops: usize,
}

/// The lints generated code may trip: long literals, `x * -1.0` and the like.
fn allow_lints() -> TokenStream {
    quote!(#[allow(unused_variables, clippy::approx_constant, clippy::excessive_precision, clippy::unreadable_literal, clippy::neg_multiply, clippy::double_parens, clippy::identity_op, clippy::needless_range_loop, clippy::let_and_return, clippy::type_complexity, clippy::too_many_arguments)])
}

/// Documentation attributes, one per line.
fn doc(lines: &[String]) -> TokenStream {
    let attrs = lines.iter().map(|l| {
        let text = format!(" {}", comment_text(l));
        quote!(#[doc = #text])
    });
    quote!(#(#attrs)*)
}

pub(super) fn usize_lit(n: usize) -> Literal {
    Literal::usize_unsuffixed(n)
}

/// The state of emitting one file: what the methods read (model, graph, catalogue, sizes) and
/// what they leave for the file (operation counts, split blocks, trait bodies).
struct Emitter<'a> {
    model: &'a Model,
    graph: &'a Graph,
    quantities: &'a [Quantity],
    cx: Ctx<'a>,
    ty: Ident,
    link_ty: Ident,
    /// The number of velocity coordinates (the length of `qd`, `qdd`, `tau`).
    n: Literal,
    /// The number of position coordinates (the length of `q`).
    nq: Literal,
    /// Whether the root is a floating base.
    floating: bool,
    /// The number of contact rows (the length of a `forces` argument).
    k: Literal,
    /// Each velocity coordinate's parent coordinate.
    parents: Vec<Option<usize>>,
    /// Each contact's number of rows (3: a point, 6: a frame), in the contacts' order.
    contact_rows: Vec<usize>,
    /// The operations of `active_contact_bias`, once it is emitted (`rust/contact.rs`).
    active_bias_ops: Option<OpCount>,
    /// Whether every `Dynamics` method is generated, so that the trait is implemented (and
    /// its methods live there rather than in the inherent impl).
    in_trait: bool,
    /// `try_forward_dynamics`, which stays inherent when `forward_dynamics` is the trait's.
    try_forward_dynamics: TokenStream,
    /// `try_forward_dynamics_lanes` and the checked solve behind both, with `forward_dynamics`.
    forward_dynamics_lanes: TokenStream,
    /// Whether a floating base's six `FloatingDynamics` methods are all generated, so that the
    /// trait is implemented (and its methods live there rather than in the inherent impl).
    floating_trait: bool,
    /// The number of contact rows (3K) when a floating base implements `Contacts` (its three
    /// methods live there rather than in the inherent impl).
    contacts_trait: Option<Literal>,
    /// `try_contact_forward_dynamics`, for the `Contacts` impl.
    try_contact_forward_dynamics: TokenStream,
    counts: Vec<(String, OpCount)>,
    /// The most operations of one function body ([`Split`]).
    budget: usize,
    /// The same for the derivatives' bodies, and their names.
    derivative_budget: usize,
    derivatives: &'a BTreeSet<&'static str>,
    /// The blocks of split bodies, for the inherent impl.
    blocks: Vec<TokenStream>,
    /// The quantities whose bodies were split, which have a `{name}_fill` method.
    split: BTreeSet<String>,
    /// Private helper methods already in `blocks` (emitted once for several callers).
    helpers: BTreeSet<&'static str>,
}

/// The generated methods by where they go: the inherent impl for every `T: Lane` (with the
/// blocks of their split bodies), and the trait impls.
#[derive(Default)]
struct Methods {
    items: Vec<TokenStream>,
    trait_methods: Vec<TokenStream>,
    floating_methods: Vec<TokenStream>,
    contact_methods: Vec<TokenStream>,
}

/// Each contact's number of rows: 3 for the points (at link origins, then at positions), 6 for
/// the frames.
fn contact_rows(model: &Model) -> Vec<usize> {
    let points = model.contacts.len() + model.contact_points_at.len();
    let frames = model.contact_frames.len();
    std::iter::repeat_n(3, points)
        .chain(std::iter::repeat_n(6, frames))
        .collect()
}

/// Emits the whole file (unformatted tokens; see [`super::format`]) and the operation count of
/// each straight-line function.
pub fn emit_tokens(
    model: &Model,
    d: &Derivation,
    opts: &EmitOptions,
) -> (TokenStream, Vec<(String, OpCount)>) {
    let fields = fields(d);
    let mut e = Emitter {
        model,
        graph: &d.graph,
        quantities: &d.quantities,
        cx: Ctx {
            symbols: d.graph.symbols(),
            fields: &fields.by_symbol,
        },
        ty: format_ident!("{}", opts.type_name),
        link_ty: format_ident!("{}Link", opts.type_name),
        n: usize_lit(d.dof),
        nq: usize_lit(d.nq),
        floating: model.is_floating(),
        k: usize_lit(d.centroidal.contact_drift.len()),
        parents: d.coordinate_parents.clone(),
        contact_rows: contact_rows(model),
        active_bias_ops: None,
        // The catalogue leaves a trait's methods in it only when all are generated.
        in_trait: d.quantities.iter().any(|q| q.home == Home::Dynamics),
        try_forward_dynamics: TokenStream::new(),
        forward_dynamics_lanes: TokenStream::new(),
        floating_trait: d
            .quantities
            .iter()
            .any(|q| q.home == Home::FloatingDynamics),
        contacts_trait: d
            .quantities
            .iter()
            .any(|q| q.home == Home::Contacts)
            .then(|| usize_lit(d.centroidal.contact_drift.len())),
        try_contact_forward_dynamics: TokenStream::new(),
        counts: Vec::new(),
        budget: opts.max_function_ops,
        derivative_budget: opts.max_derivative_function_ops,
        derivatives: &d.derivative_quantities,
        blocks: Vec::new(),
        split: BTreeSet::new(),
        helpers: BTreeSet::new(),
    };
    let tokens = e.file(&fields, d);
    (tokens, e.counts)
}

impl Emitter<'_> {
    /// Whether link kinematics is generated (the link enum and its tables).
    fn has_frames(&self) -> bool {
        self.quantities.iter().any(|q| {
            matches!(
                q.eval,
                Evaluation::LinkPose | Evaluation::LinkJacobian | Evaluation::FrameMotion(_)
            )
        })
    }

    /// Every quantity's method, and the blocks of split bodies, by where they go.
    fn methods(&mut self) -> Methods {
        let mut m = Methods::default();
        for q in self.quantities {
            let before = self.blocks.len();
            let tokens = self.quantity_fn(q);
            m.items.extend(self.blocks.drain(before..));
            match self.trait_of(q.name) {
                Some(Trait::Dynamics) => m.trait_methods.push(tokens),
                Some(Trait::Floating) => m.floating_methods.push(tokens),
                Some(Trait::Contacts) => m.contact_methods.push(tokens),
                None => m.items.push(tokens),
            }
            if q.name == "forward_dynamics" {
                m.items
                    .push(std::mem::take(&mut self.forward_dynamics_lanes));
            }
        }
        m.contact_methods
            .push(self.try_contact_forward_dynamics.clone());
        m
    }

    /// The whole file: the type, its inherent impl with one method per quantity, the trait
    /// impls.
    fn file(&mut self, fields: &Fields, d: &Derivation) -> TokenStream {
        let strukt = self.struct_def(fields);
        let links = if self.has_frames() {
            self.link_enum()
        } else {
            TokenStream::new()
        };
        let Methods {
            items,
            trait_methods,
            floating_methods,
            contact_methods,
        } = self.methods();
        let frames = if self.has_frames() {
            self.frame_support(d)
        } else {
            TokenStream::new()
        };
        let trait_impl = self.trait_impl(&trait_methods);
        let floating_impls = self.floating_impls(&floating_methods, &contact_methods);
        let (ty, allow) = (&self.ty, allow_lints());
        let try_fd = &self.try_forward_dynamics;
        let parents = self.parents_const();
        let passes = self.tree_passes_impl();
        let identification = super::identification::constants(d, self.quantities);
        let actuation = super::actuation::items(
            self.model,
            self.has("forward_dynamics")
                .then(|| self.call("forward_dynamics")),
        );
        let joint_names = self.joint_names_const();
        let sizes = self.sizes();
        let limits = mpc::limit_constants(self.model);
        let blocks = &self.blocks;
        let batch = self.batch_impl(fields);
        quote! {
            #strukt
            #links
            #sizes
            #allow
            impl<T: ::eomgen_runtime::Lane> #ty<T> {
                #parents
                #joint_names
                #limits
                #identification
                #actuation
                #(#items)*
                #(#blocks)*
                #frames
            }
            // `try_forward_dynamics` returns the first failure at once, which a vector of
            // states cannot (`try_forward_dynamics_lanes` says which lane failed).
            #allow
            impl<T: ::eomgen_runtime::Real> #ty<T> {
                #try_fd
            }
            #trait_impl
            #floating_impls
            #passes
            #batch
        }
    }
}
