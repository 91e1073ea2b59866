//! Rust source for one robot: a generic struct with one inherent method per quantity of the
//! derivation's catalogue, the runtime's `Dynamics` trait delegating to them, and the link
//! enum with the tables link kinematics walks.
//!
//! One emitter method per generated item, as prost-build's code generator does it: the
//! parameter fields, the link enum, each kind of [`Evaluation`], the trait implementation.

mod contact;

use std::collections::{BTreeMap, BTreeSet};

use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote};

use super::body::{body, factored_body, shape_type, Body};
use super::expr::{lit, Ctx};
use super::names::{comment_text, snake, upper_camel, Scope};
use super::split::Split;
use crate::cas::{Graph, Id, OpCount};
use crate::dynamics::{
    ActiveContacts, Craig, Derivation, Evaluation, Home, Input, Quantity, Shape,
};
use crate::kinematics::snap;
use crate::model::{JointKind, Model, Transform};
use crate::spatial::snap_rotation;

mod mpc;

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
}

/// The lints generated code may trip: long literals, `x * -1.0` and the like.
fn allow_lints() -> TokenStream {
    quote!(#[allow(unused_variables, clippy::approx_constant, clippy::excessive_precision, clippy::unreadable_literal, clippy::neg_multiply, clippy::double_parens, clippy::identity_op, clippy::needless_range_loop, clippy::let_and_return, clippy::type_complexity, clippy::too_many_arguments)])
}

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

/// The parameters of a derivation as struct fields: definitions, defaults, and the map from
/// parameter symbol to field for expressions.
struct Fields {
    defs: Vec<TokenStream>,
    defaults: Vec<TokenStream>,
    by_symbol: BTreeMap<u32, Ident>,
}

fn fields(d: &Derivation) -> Fields {
    let mut scope = Scope::with_reserved(&["_marker"]);
    let mut f = Fields {
        defs: Vec::new(),
        defaults: Vec::new(),
        by_symbol: BTreeMap::new(),
    };
    for (name, id, value) in &d.params {
        let sym = d.graph.as_symbol(*id).expect("parameter symbol");
        let field = format_ident!("{}", scope.claim(snake(name, "p")));
        let docline = format!(
            " `{}` ({} {}).",
            comment_text(&name.replace('`', "'")),
            crate::report::value_source(name),
            value
        );
        f.defs.push(quote!(#[doc = #docline] pub #field: T,));
        let l = lit(*value);
        f.defaults.push(quote!(#field: #l,));
        f.by_symbol.insert(sym, field);
    }
    f
}

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
    /// The blocks of split bodies, for the inherent impl.
    blocks: Vec<TokenStream>,
    /// The quantities whose bodies were split, which have a `{name}_fill` method.
    split: BTreeSet<String>,
    /// Private helper methods already in `blocks` (emitted once for several callers).
    helpers: BTreeSet<&'static str>,
}

/// How many methods the runtime's `Dynamics` trait has.
const TRAIT_METHODS: usize = 8;

/// The methods of the runtime's `FloatingDynamics` trait.
const FLOATING_METHODS: [&str; 6] = [
    "mass_matrix",
    "gravity",
    "bias",
    "integrate",
    "inverse_dynamics",
    "forward_dynamics",
];

/// The methods of the runtime's `Contacts` trait.
const CONTACT_METHODS: [&str; 3] = [
    "contact_jacobian",
    "contact_drift",
    "try_contact_forward_dynamics",
];

/// The runtime trait whose impl holds a generated method.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Trait {
    /// `Dynamics` (fixed base).
    Dynamics,
    /// `FloatingDynamics`.
    Floating,
    /// `Contacts` (floating base).
    Contacts,
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
        in_trait: d
            .quantities
            .iter()
            .filter(|q| q.home == Home::Dynamics)
            .count()
            == TRAIT_METHODS,
        try_forward_dynamics: TokenStream::new(),
        floating_trait: model.is_floating()
            && FLOATING_METHODS
                .iter()
                .all(|f| d.quantities.iter().any(|q| q.name == *f)),
        contacts_trait: (model.is_floating()
            && !d.centroidal.contact_drift.is_empty()
            && d.quantities
                .iter()
                .any(|q| q.name == "contact_forward_dynamics"))
        .then(|| usize_lit(d.centroidal.contact_drift.len())),
        try_contact_forward_dynamics: TokenStream::new(),
        counts: Vec::new(),
        budget: opts.max_function_ops,
        blocks: Vec::new(),
        split: BTreeSet::new(),
        helpers: BTreeSet::new(),
    };
    let tokens = e.file(&fields, d);
    (tokens, e.counts)
}

impl Emitter<'_> {
    fn has_frames(&self) -> bool {
        self.quantities.iter().any(|q| {
            matches!(
                q.eval,
                Evaluation::LinkPose | Evaluation::LinkJacobian | Evaluation::FrameMotion(_)
            )
        })
    }

    fn file(&mut self, fields: &Fields, d: &Derivation) -> TokenStream {
        let strukt = self.struct_def(fields);
        let links = if self.has_frames() {
            self.link_enum()
        } else {
            TokenStream::new()
        };
        let quantities = self.quantities;
        let mut methods = Vec::new();
        let mut trait_methods = Vec::new();
        let mut floating_methods = Vec::new();
        let mut contact_methods = Vec::new();
        for q in quantities {
            let tokens = self.quantity_fn(q);
            match self.trait_of(q.name) {
                Some(Trait::Dynamics) => trait_methods.push(tokens),
                Some(Trait::Floating) => floating_methods.push(tokens),
                Some(Trait::Contacts) => contact_methods.push(tokens),
                None => methods.push(tokens),
            }
        }
        contact_methods.push(self.try_contact_forward_dynamics.clone());
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
        let nj = usize_lit(self.model.coordinates());
        let identification = super::identification::constants(d, self.quantities);
        let actuation = super::actuation::items(
            self.model,
            self.has("forward_dynamics")
                .then(|| self.call("forward_dynamics")),
        );
        // Without the trait, the joint order still has to be said.
        let joint_names = if self.in_trait {
            TokenStream::new()
        } else {
            let names = self
                .model
                .coordinate_names()
                .into_iter()
                .map(|name| Literal::string(&name));
            let what = if self.floating {
                "The URDF names of the joints, in the order of the joint part of every array (after the base's coordinates)."
            } else {
                "The URDF names of the joint coordinates, in the order of every array."
            };
            quote! {
                #[doc = #what]
                pub const JOINT_NAMES: [&'static str; #nj] = [#(#names),*];
            }
        };
        let sizes = self.sizes();
        let limits = mpc::limit_constants(self.model);
        let blocks = &self.blocks;
        quote! {
            #strukt
            #links
            #sizes
            #allow
            impl<T: ::eomgen_runtime::Real> #ty<T> {
                #parents
                #joint_names
                #limits
                #identification
                #actuation
                #try_fd
                #(#methods)*
                #frames
                #(#blocks)*
            }
            #trait_impl
            #floating_impls
        }
    }

    /// `DOF` (and `NQ`, `NV` with a floating base) as inherent constants of the `f64` type, so
    /// that `Robot::DOF` needs no type parameter, and the runtime's `Dimensions` for every
    /// scalar type (`Robot::<f32>::DOF`, generic code).
    fn sizes(&self) -> TokenStream {
        let (ty, n, nq) = (&self.ty, &self.n, &self.nq);
        let floating = if self.floating {
            quote! {
                /// Number of position coordinates: the base's 7 (position, unit quaternion x, y, z, w), then the joints'.
                pub const NQ: usize = #nq;
                /// Number of velocity coordinates: the base's 6 (linear, then angular velocity, base axes), then the joints'.
                pub const NV: usize = #n;
            }
        } else if !self.model.velocities_are_rates() {
            quote! {
                /// Number of position coordinates: 7 per floating joint (position, unit quaternion x, y, z, w), 1 per other joint.
                pub const NQ: usize = #nq;
                /// Number of velocity coordinates: 6 per floating joint (linear, then angular velocity, its body's axes), 1 per other joint.
                pub const NV: usize = #n;
            }
        } else {
            TokenStream::new()
        };
        quote! {
            impl #ty<f64> {
                /// Number of joint coordinates (velocity coordinates with a floating base).
                pub const DOF: usize = #n;
                #floating
            }
            impl<T: ::eomgen_runtime::Real> ::eomgen_runtime::Dimensions for #ty<T> {
                const DOF: usize = #n;
                const NQ: usize = #nq;
                const NV: usize = #n;
            }
        }
    }

    /// The runtime trait whose impl holds the generated method `name`, if any (else it is
    /// inherent).
    fn trait_of(&self, name: &str) -> Option<Trait> {
        if self.floating {
            if self.floating_trait && FLOATING_METHODS.contains(&name) {
                Some(Trait::Floating)
            } else if self.contacts_trait.is_some() && CONTACT_METHODS.contains(&name) {
                Some(Trait::Contacts)
            } else {
                None
            }
        } else {
            let dynamics = self
                .quantities
                .iter()
                .any(|q| q.name == name && q.home == Home::Dynamics);
            (self.in_trait && dynamics).then_some(Trait::Dynamics)
        }
    }

    /// `pub` in the inherent impl; nothing in a trait's.
    fn vis(&self, name: &str) -> TokenStream {
        if self.trait_of(name).is_some() {
            TokenStream::new()
        } else {
            quote!(pub)
        }
    }

    fn struct_def(&self, fields: &Fields) -> TokenStream {
        let mut lines = vec![format!(
            "Rigid-body dynamics of `{}` ({} joints{}), generated by eomgen.",
            self.model.name.replace('`', "'"),
            self.model.dof(),
            if self.floating { ", floating base" } else { "" }
        )];
        if self.model.is_coupled() {
            lines.extend(coupling_doc(self.model));
        }
        if !self.floating && !self.model.velocities_are_rates() {
            lines.extend([
                String::new(),
                "Floating joints (as Pinocchio's free flyer, below the root): each has `q` = [position of its".into(),
                "child in the joint frame (3), unit quaternion x, y, z, w (4)] (`NQ` in all) and velocities =".into(),
                "[linear (3), angular (3)] in the child's axes (`NV` in all); `JOINT_NAMES` has one entry per".into(),
                "velocity coordinate. Move along them with `integrate`.".into(),
            ]);
        }
        if self.floating {
            lines.extend([
                String::new(),
                "Floating base (as Pinocchio's free flyer): `q` = [base position in world (3), unit quaternion".into(),
                "x, y, z, w (4), joints] (`NQ`); `qd`, `qdd` = [base linear velocity (3), angular velocity (3),".into(),
                "both in base axes, joints] (`NV`); efforts = [force (3), torque (3) on the base in base axes,".into(),
                "joints]: a robot's own efforts are zero on the base.".into(),
            ]);
        }
        lines.extend([
            String::new(),
            "Generic over the scalar type (`f64` by default, `f32` for single-precision firmware)."
                .into(),
            "`Default` holds the URDF's parameter values.".into(),
        ]);
        let type_doc = doc(&lines);
        let (ty, defs, defaults) = (&self.ty, &fields.defs, &fields.defaults);
        quote! {
            #type_doc
            #[derive(Clone, Copy, Debug, PartialEq)]
            pub struct #ty<T = f64> {
                #(#defs)*
                _marker: ::core::marker::PhantomData<T>,
            }

            impl<T: ::eomgen_runtime::Real> ::core::default::Default for #ty<T> {
                fn default() -> Self {
                    #ty { #(#defaults)* _marker: ::core::marker::PhantomData }
                }
            }
        }
    }

    /// The link enum's variant names, in URDF order.
    fn link_variants(&self) -> Vec<Ident> {
        let mut scope = Scope::with_reserved(&["ALL"]);
        self.model
            .frames
            .iter()
            .map(|f| format_ident!("{}", scope.claim(upper_camel(&f.name, "Link"))))
            .collect()
    }

    fn link_enum(&self) -> TokenStream {
        let variants = self.link_variants();
        let names = self.model.frames.iter().map(|f| Literal::string(&f.name));
        let count = usize_lit(variants.len());
        let link_ty = &self.link_ty;
        let link_doc = doc(&[format!(
            "The URDF links of [`{}`], one variant per link.",
            self.ty
        )]);
        quote! {
            #link_doc
            #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
            pub enum #link_ty {
                #(#variants),*
            }

            impl #link_ty {
                /// Every link, in URDF order.
                pub const ALL: [#link_ty; #count] = [#(#link_ty::#variants),*];

                /// The URDF name of the link.
                pub const fn name(self) -> &'static str {
                    match self {
                        #(#link_ty::#variants => #names),*
                    }
                }
            }
        }
    }

    /// The arguments `q: &[T; N], ...` of a quantity.
    fn args(&self, inputs: &[Input]) -> Vec<TokenStream> {
        inputs
            .iter()
            .map(|i| {
                let name = format_ident!("{}", i.name());
                let len = match i {
                    Input::Q => &self.nq,
                    Input::Forces => &self.k,
                    _ => &self.n,
                };
                quote!(#name: &[T; #len])
            })
            .collect()
    }

    /// Straight-line code for `outputs`, counted under `q`'s name.
    fn straight(&mut self, q: &Quantity, outputs: &[Id], shape: Shape) -> (TokenStream, OpCount) {
        let (params, args) = (self.args(q.inputs), Self::arg_names(q.inputs));
        let rows = Self::row_groups(q.name, shape);
        let mut split = self.split(q.name, &params, &args);
        split.rows = &rows;
        let b = body(self.graph, &self.cx, outputs, shape, Some(&split));
        self.counts.push((q.name.to_string(), b.ops));
        if !b.blocks.is_empty() {
            self.split.insert(q.name.to_string());
        }
        self.blocks.extend(b.blocks);
        (b.code, b.ops)
    }

    /// How a body of the function `name` is split beyond the budget.
    fn split<'s>(&self, name: &'s str, params: &'s [TokenStream], args: &'s [Ident]) -> Split<'s> {
        Split {
            name,
            params,
            args,
            budget: self.budget,
            rows: &[],
        }
    }

    /// The row groups a split body of `name` fills separately ([`Split::rows`]): the impulse
    /// partials' `N` rows in `q` and `K` contact rows, which `impulse_dynamics_derivatives`
    /// has written straight into two matrices of its result.
    fn row_groups(name: &str, shape: Shape) -> Vec<usize> {
        match (name, shape) {
            ("impulse_dynamics_partials", Shape::Matrix(r, c)) if r > c => vec![c, r - c],
            _ => Vec::new(),
        }
    }

    /// The names `q, qd, ...` of a quantity's arguments.
    fn arg_names(inputs: &[Input]) -> Vec<Ident> {
        inputs
            .iter()
            .map(|i| format_ident!("{}", i.name()))
            .collect()
    }

    fn quantity_doc(q: &Quantity, ops: Option<OpCount>) -> TokenStream {
        let mut lines = q.doc.clone();
        lines.push(String::new());
        lines.push(q.route.clone());
        if let Some(ops) = ops {
            lines.push(format!("Operations: {ops}."));
        }
        doc(&lines)
    }

    fn quantity_fn(&mut self, q: &Quantity) -> TokenStream {
        match &q.eval {
            Evaluation::Exprs(ids) => self.exprs_fn(q, ids),
            Evaluation::CraigColumns(which) => self.craig_fn(q, *which),
            Evaluation::ForwardDynamics { .. } | Evaluation::ForwardDynamicsSolve { .. } => {
                self.forward_dynamics_fns(q)
            }
            Evaluation::LinkPose => self.link_pose_fn(q),
            Evaluation::LinkJacobian => self.link_jacobian_fn(q),
            Evaluation::MassMatrixInverse => self.mass_matrix_inverse_fn(q),
            Evaluation::ForwardDynamicsDerivatives => self.forward_dynamics_derivatives_fn(q),
            Evaluation::ContactForwardDynamics { h } => self.contact_forward_dynamics_fns(q, h),
            Evaluation::Integrate => self.integrate_fn(q),
            Evaluation::FrameMotion(m) => self.frame_motion_fn(q, *m),
            Evaluation::Manifold(m) => self.manifold_fn(q, *m),
            Evaluation::ContactDynamicsDerivatives { h } => {
                self.contact_dynamics_derivatives_fns(q, h, false)
            }
            Evaluation::ImpulseDynamics => self.impulse_dynamics_fns(q, false),
            Evaluation::ImpulseDynamicsDerivatives => {
                self.impulse_dynamics_derivatives_fns(q, false)
            }
            Evaluation::ActiveContacts(a) => self.active_contacts_fns(q, a),
            Evaluation::Factored { outputs, pivots } => self.factored_fn(q, outputs, pivots),
        }
    }

    /// The methods of a set of active contacts ([`ActiveContacts`]).
    fn active_contacts_fns(&mut self, q: &Quantity, a: &ActiveContacts) -> TokenStream {
        match a {
            ActiveContacts::Dynamics { h } => self.contact_active_fns(q, h, false),
            ActiveContacts::Stabilized { h } => self.contact_active_fns(q, h, true),
            ActiveContacts::Derivatives { h } => self.contact_dynamics_derivatives_fns(q, h, true),
            ActiveContacts::Impulse => self.impulse_dynamics_fns(q, true),
            ActiveContacts::ImpulseDerivatives => self.impulse_dynamics_derivatives_fns(q, true),
        }
    }

    fn exprs_fn(&mut self, q: &Quantity, ids: &[Id]) -> TokenStream {
        let (b, ops) = self.straight(q, ids, q.shape);
        self.plain_fn(q, ops, b)
    }

    /// Straight-line code whose outputs hold when the factorization's pivots are positive.
    fn factored_fn(&mut self, q: &Quantity, outputs: &[Id], pivots: &[Id]) -> TokenStream {
        let (params, args) = (self.args(q.inputs), Self::arg_names(q.inputs));
        let split = self.split(q.name, &params, &args);
        let Body {
            code: b,
            ops,
            blocks,
        } = factored_body(self.graph, &self.cx, outputs, pivots, q.shape, Some(&split));
        self.counts.push((q.name.to_string(), ops));
        self.blocks.extend(blocks);
        self.plain_fn(q, ops, b)
    }

    /// The method of `q` taking its inputs, with `body` (counted `ops`).
    fn plain_fn(&self, q: &Quantity, ops: OpCount, body: TokenStream) -> TokenStream {
        let docs = Self::quantity_doc(q, Some(ops));
        let (name, args, ret) = (
            format_ident!("{}", q.name),
            self.args(q.inputs),
            shape_type(q.shape),
        );
        let vis = self.vis(q.name);
        quote! {
            #docs
            #vis fn #name(&self, #(#args),*) -> #ret { #body }
        }
    }

    /// Craig's `C(q)` or `B(q)` from `N` Christoffel columns of `coriolis_matrix`.
    fn craig_fn(&mut self, q: &Quantity, which: Craig) -> TokenStream {
        let docs = Self::quantity_doc(q, None);
        let (name, ret) = (format_ident!("{}", q.name), shape_type(q.shape));
        let n = &self.n;
        let coriolis = self.call("coriolis_matrix");
        let kernel = match which {
            Craig::Centrifugal => quote!(centrifugal_from_coriolis),
            Craig::CoriolisPairs => quote!(coriolis_pairs_from_coriolis),
        };
        quote! {
            #docs
            pub fn #name(&self, q: &[T; #n]) -> #ret {
                ::eomgen_runtime::tree::#kernel(|v: &[T; #n]| #coriolis(self, q, v))
            }
        }
    }

    /// The body of an unrolled `try_forward_dynamics`: accelerations and pivots in one
    /// straight-line program, the pivots checked.
    fn unrolled_solve(&mut self, q: &Quantity, acc: &[Id], piv: &[Id]) -> (TokenStream, OpCount) {
        let dof = acc.len();
        let outputs: Vec<Id> = acc.iter().chain(piv).copied().collect();
        let (b, ops) = self.straight(q, &outputs, Shape::Vector(2 * dof));
        let len = usize_lit(2 * dof);
        let x = (0..dof).map(|i| {
            let i = usize_lit(i);
            quote!(o[#i])
        });
        let pivots = (0..dof).map(|i| {
            let i = usize_lit(dof + i);
            quote!(o[#i])
        });
        let body = quote! {
            let o: [T; #len] = { #b };
            let pivots = [#(#pivots),*];
            for (pivot, d) in pivots.iter().enumerate() {
                if !d.is_finite() {
                    return Err(::eomgen_runtime::FactorError::NonFinite { pivot });
                }
                if *d <= T::zero() {
                    return Err(::eomgen_runtime::FactorError::NotPositiveDefinite { pivot });
                }
            }
            let qdd = [#(#x),*];
            for (pivot, x) in qdd.iter().enumerate() {
                if !x.is_finite() {
                    return Err(::eomgen_runtime::FactorError::NonFinite { pivot });
                }
            }
            Ok(qdd)
        };
        (body, ops)
    }

    /// The body of a `try_forward_dynamics` that solves at run time: `M` from `mass_matrix`,
    /// `h` straight-line, the runtime's tree `L^T D L` over the joints' parents.
    fn runtime_solve(&mut self, q: &Quantity, h: &[Id]) -> (TokenStream, OpCount) {
        let (hb, ops) = self.straight(q, h, Shape::Vector(h.len()));
        let n = &self.n;
        let mass_matrix = self.call("mass_matrix");
        let body = quote! {
            let mut m = #mass_matrix(self, q);
            let h: [T; #n] = { #hb };
            let mut rhs = *tau;
            for (r, h) in rhs.iter_mut().zip(h) {
                *r -= h;
            }
            Self::ltdl_factor_unrolled(&mut m)?;
            let x = Self::ltdl_substitute_unrolled(&m, &rhs);
            match x.iter().position(|v| !v.is_finite()) {
                Some(pivot) => Err(::eomgen_runtime::FactorError::NonFinite { pivot }),
                None => Ok(x),
            }
        };
        (body, ops)
    }

    /// `try_forward_dynamics`, which reports a failed pivot, and `forward_dynamics`, which
    /// gives NaN then.
    fn forward_dynamics_fns(&mut self, q: &Quantity) -> TokenStream {
        let (body, ops) = match &q.eval {
            Evaluation::ForwardDynamics {
                accelerations,
                pivots,
            } => self.unrolled_solve(q, accelerations, pivots),
            Evaluation::ForwardDynamicsSolve { h } => self.runtime_solve(q, h),
            _ => unreachable!("forward_dynamics_fns on another evaluation"),
        };
        let docs = Self::quantity_doc(q, Some(ops));
        let (n, nq, vis) = (&self.n, &self.nq, self.vis(q.name));
        self.try_forward_dynamics = quote! {
            /// Forward dynamics `qdd = M(q)^-1 (tau - b(q, qd) - G(q))`, or which pivot of the
            /// `L^T D L` factorization of M(q) was not positive (a non-physical model or
            /// non-finite input); see `forward_dynamics` for the route and operation count.
            /// `Ok` holds only finite numbers: a non-finite component `i` of the solution (from
            /// a non-finite `qd` or `tau`, or a `q` that leaves M(q) finite) is reported as
            /// `FactorError::NonFinite { pivot: i }`.
            pub fn try_forward_dynamics(&self, q: &[T; #nq], qd: &[T; #n], tau: &[T; #n]) -> ::core::result::Result<[T; #n], ::eomgen_runtime::FactorError> {
                #body
            }
        };
        quote! {
            #docs
            #vis fn forward_dynamics(&self, q: &[T; #nq], qd: &[T; #n], tau: &[T; #n]) -> [T; #n] {
                match self.try_forward_dynamics(q, qd, tau) {
                    Ok(qdd) => qdd,
                    Err(_) => [T::nan(); #n],
                }
            }
        }
    }

    /// The path that calls the generated function `name` from inside the impls: through the
    /// trait when it is a trait method there. Every generated function that calls another does
    /// so through here, and the callee is one of its `Quantity::needs`, so that a selection
    /// (`catalogue::select`) brings it.
    fn call(&self, name: &str) -> TokenStream {
        debug_assert!(self.has(name), "`{name}` is called but not generated");
        self.path(name)
    }

    /// The path of the generated method `name` (see [`Self::call`]).
    fn path(&self, name: &str) -> TokenStream {
        let (f, n, nq) = (format_ident!("{}", name), &self.n, &self.nq);
        match self.trait_of(name) {
            Some(Trait::Dynamics) => quote!(<Self as ::eomgen_runtime::Dynamics<T, #n>>::#f),
            Some(Trait::Floating) => {
                quote!(<Self as ::eomgen_runtime::FloatingDynamics<T, #nq, #n>>::#f)
            }
            Some(Trait::Contacts) => {
                let k3 = self.contacts_trait.as_ref();
                quote!(<Self as ::eomgen_runtime::Contacts<T, #nq, #n, #k3>>::#f)
            }
            None => quote!(Self::#f),
        }
    }

    /// Whether some quantity is evaluated in one of these ways.
    fn any_eval(&self, which: impl Fn(&Evaluation) -> bool) -> bool {
        self.quantities.iter().any(|q| which(&q.eval))
    }

    /// The run-time tree solves' helpers, each only where a quantity calls it: `PARENTS`
    /// (each joint's parent joint, for the runtime's tree kernels and `ContactKkt`; public with
    /// `mass_matrix`, for users' own solves), `CONTACT_ROWS` (with `contact_jacobian`), and
    /// the robot's unrolled factorization and substitution (`emit/tree_solve.rs`).
    fn parents_const(&self) -> TokenStream {
        use Evaluation as E;
        let n = &self.n;
        let table = self.has("mass_matrix")
            || self.any_eval(|e| {
                matches!(
                    e,
                    E::MassMatrixInverse
                        | E::ForwardDynamicsDerivatives
                        | E::ContactForwardDynamics { .. }
                        | E::ContactDynamicsDerivatives { .. }
                        | E::ImpulseDynamics
                        | E::ImpulseDynamicsDerivatives
                        | E::ActiveContacts(_)
                )
            });
        let table = if table {
            let parents = self.parents.iter().map(|p| match p {
                Some(p) => {
                    let p = usize_lit(*p);
                    quote!(Some(#p))
                }
                None => quote!(None),
            });
            quote! {
                /// Each coordinate's parent coordinate (`None`: the root), parents first: the
                /// joints' parents (a floating base's six coordinates form a chain). The sparsity
                /// of `mass_matrix` that the runtime's tree solves take (`eomgen_runtime::tree`,
                /// `eomgen_runtime::contact::solve`, `eomgen_runtime::ContactKkt`).
                pub const PARENTS: [Option<usize>; #n] = [#(#parents),*];
            }
        } else {
            TokenStream::new()
        };
        let rows = if self.has("contact_jacobian") {
            let c = usize_lit(self.contact_rows.len());
            let rows = self.contact_rows.iter().map(|r| usize_lit(*r));
            quote! {
                /// Each contact's number of rows in `contact_jacobian`, `contact_drift` and the
                /// forces (3: a point, 6: a frame), in the contacts' order: points, then frames.
                /// The `active` flags of the `_active` methods follow this order
                /// (`eomgen_runtime::contact::row_mask` turns them into rows).
                pub const CONTACT_ROWS: [usize; #c] = [#(#rows),*];
            }
        } else {
            TokenStream::new()
        };
        let solves = |e: &Evaluation| {
            matches!(
                e,
                E::ForwardDynamicsSolve { .. }
                    | E::ContactForwardDynamics { .. }
                    | E::ForwardDynamicsDerivatives
                    | E::ActiveContacts(
                        ActiveContacts::Dynamics { .. } | ActiveContacts::Stabilized { .. }
                    )
            )
        };
        let factor = if self.any_eval(|e| solves(e) || matches!(e, E::MassMatrixInverse)) {
            super::tree_solve::factor_fn(&self.parents, n)
        } else {
            TokenStream::new()
        };
        let substitute = if self.any_eval(solves) {
            super::tree_solve::substitute_fn(&self.parents, n)
        } else {
            TokenStream::new()
        };
        quote! {
            #table
            #rows
            #factor
            #substitute
        }
    }

    fn mass_matrix_inverse_fn(&mut self, q: &Quantity) -> TokenStream {
        let docs = Self::quantity_doc(q, None);
        let (n, nq, mass_matrix) = (&self.n, &self.nq, self.call("mass_matrix"));
        self.blocks.push(quote! {
            #[inline(never)]
            fn mass_matrix_inverse_in_place<'b>(&self, q: &[T; #nq], slot: ::eomgen_runtime::place::Slot<'b, [[T; #n]; #n]>) -> ::eomgen_runtime::place::Filled<'b> {
                let (o, filled) = slot.fill();
                let mut m = #mass_matrix(self, q);
                match Self::ltdl_factor_unrolled(&mut m) {
                    Ok(()) => ::eomgen_runtime::tree::ltdl_inverse_factored_into(&m, &Self::PARENTS, o),
                    Err(_) => o.iter_mut().flatten().for_each(|v| *v = T::nan()),
                }
                filled
            }
        });
        quote! {
            #docs
            pub fn mass_matrix_inverse(&self, q: &[T; #nq]) -> [[T; #n]; #n] {
                ::eomgen_runtime::place::build(|slot| self.mass_matrix_inverse_in_place(q, slot))
            }
        }
    }

    /// `(d qdd/dq, d qdd/dqd, M^-1)` through one factorization of `M`: `qdd` solves
    /// `M qdd = tau - h` with `h = inverse_dynamics(q, qd, 0)`, then `d tau/dq` and `d tau/dqd`
    /// there from `inverse_dynamics_derivatives`, both solves at once per matrix
    /// (`tree::ltdl_substitute_rows`), and `M^-1` from the same factors. Everything is written
    /// into the caller's storage (`eomgen_runtime::place`), the derivatives of tau by
    /// `inverse_dynamics_derivatives_fill` where that function was split.
    fn forward_dynamics_derivatives_fn(&mut self, q: &Quantity) -> TokenStream {
        let docs = Self::quantity_doc(q, None);
        let (n, nq) = (&self.n, &self.nq);
        let id = self.call("inverse_dynamics");
        let mass_matrix = self.call("mass_matrix");
        let id_derivatives = self.id_derivatives_into(quote!(*dq), quote!(*dqd), quote!(qdd));
        let matrix = quote!([[T; #n]; #n]);
        self.blocks.push(quote! {
            #[inline(never)]
            fn forward_dynamics_derivatives_in_place<'b>(&self, q: &[T; #nq], qd: &[T; #n], tau: &[T; #n], slot: ::eomgen_runtime::place::Slot<'b, (#matrix, #matrix, #matrix)>) -> ::eomgen_runtime::place::Filled<'b> {
                let ((dq, dqd, inverse), filled) = slot.fill();
                let mut m = #mass_matrix(self, q);
                if Self::ltdl_factor_unrolled(&mut m).is_err() {
                    for v in dq.iter_mut().chain(dqd.iter_mut()).chain(inverse.iter_mut()).flatten() {
                        *v = T::nan();
                    }
                    return filled;
                }
                let mut rhs = *tau;
                for (r, h) in rhs.iter_mut().zip(#id(self, q, qd, &[T::zero(); #n])) {
                    *r -= h;
                }
                let qdd = Self::ltdl_substitute_unrolled(&m, &rhs);
                #id_derivatives
                for x in [&mut *dq, &mut *dqd] {
                    ::eomgen_runtime::tree::ltdl_substitute_rows(&m, &Self::PARENTS, x);
                    for v in x.iter_mut().flatten() {
                        *v = -*v;
                    }
                }
                ::eomgen_runtime::tree::ltdl_inverse_factored_into(&m, &Self::PARENTS, inverse);
                filled
            }
        });
        quote! {
            #docs
            pub fn forward_dynamics_derivatives(&self, q: &[T; #nq], qd: &[T; #n], tau: &[T; #n]) -> (#matrix, #matrix, #matrix) {
                ::eomgen_runtime::place::build(|slot| self.forward_dynamics_derivatives_in_place(q, qd, tau, slot))
            }
        }
    }

    /// `let mut m = ...; let free = ...;`: `M(q)` factorized by the unrolled tree `L^T D L`
    /// (returning its error) and the accelerations without contacts `M^-1 (tau - h)`, `h` by
    /// the straight-line block `hb`.
    fn free_accelerations(&self, hb: &TokenStream) -> TokenStream {
        let (n, m) = (&self.n, self.call("mass_matrix"));
        quote! {
            let mut m = #m(self, q);
            let h: [T; #n] = { #hb };
            let mut rhs = *tau;
            for (r, h) in rhs.iter_mut().zip(h) {
                *r -= h;
            }
            Self::ltdl_factor_unrolled(&mut m)?;
            let free = Self::ltdl_substitute_unrolled(&m, &rhs);
        }
    }

    /// Statements writing `inverse_dynamics_derivatives` at `(q, qd, &qdd)` into the places
    /// `dq` and `dqd` (of type `[[T; N]; N]`): through its `_fill` method when its body was
    /// split, so that it is not built in a local and copied. It is emitted before the
    /// quantities that call this (catalogue order).
    fn id_derivatives_into(
        &self,
        dq: TokenStream,
        dqd: TokenStream,
        qdd: TokenStream,
    ) -> TokenStream {
        if self.split.contains("inverse_dynamics_derivatives") {
            let fill = super::split::fill_name("inverse_dynamics_derivatives");
            quote!(self.#fill(q, qd, &#qdd, &mut #dq, &mut #dqd);)
        } else {
            debug_assert!(self
                .counts
                .iter()
                .any(|(c, _)| c == "inverse_dynamics_derivatives"));
            let f = self.call("inverse_dynamics_derivatives");
            quote!((#dq, #dqd) = #f(self, q, qd, &#qdd);)
        }
    }

    /// `try_contact_forward_dynamics` and `contact_forward_dynamics` (NaN on failure).
    fn contact_forward_dynamics_fns(&mut self, q: &Quantity, h: &[Id]) -> TokenStream {
        let (hb, ops) = self.straight(q, h, Shape::Vector(h.len()));
        let docs = Self::quantity_doc(q, Some(ops));
        let (n, nq) = (&self.n, &self.nq);
        let k3 = usize_lit(q.shape.len() - h.len());
        let free = self.free_accelerations(&hb);
        let (j, drift) = (self.call("contact_jacobian"), self.call("contact_drift"));
        let try_vis = self.vis("try_contact_forward_dynamics");
        let try_cfd = self.path("try_contact_forward_dynamics");
        let try_fn = quote! {
            /// The accelerations and contact forces of `contact_forward_dynamics`, or why they
            /// do not exist: a pivot of M(q) (`pivot` < N) or of `J_c M^-1 J_c^T` (`pivot` - N,
            /// a rank-deficient contact Jacobian) that is not positive, or non-finite input.
            #try_vis fn try_contact_forward_dynamics(&self, q: &[T; #nq], qd: &[T; #n], tau: &[T; #n]) -> ::core::result::Result<([T; #n], [T; #k3]), ::eomgen_runtime::FactorError> {
                #free
                ::eomgen_runtime::contact::solve_factored(&m, &Self::PARENTS, &free, &#j(self, q), &#drift(self, q, qd))
            }
        };
        let inherent_try = if self.trait_of("try_contact_forward_dynamics").is_some() {
            self.try_contact_forward_dynamics = try_fn;
            TokenStream::new()
        } else {
            try_fn
        };
        quote! {
            #inherent_try

            #docs
            pub fn contact_forward_dynamics(&self, q: &[T; #nq], qd: &[T; #n], tau: &[T; #n]) -> ([T; #n], [T; #k3]) {
                match #try_cfd(self, q, qd, tau) {
                    Ok(x) => x,
                    Err(_) => ([T::nan(); #n], [T::nan(); #k3]),
                }
            }
        }
    }

    fn integrate_fn(&mut self, q: &Quantity) -> TokenStream {
        let docs = Self::quantity_doc(q, None);
        let (n, nq, vis) = (&self.n, &self.nq, self.vis(q.name));
        let body = if self.floating {
            quote!(::eomgen_runtime::free_flyer::integrate(q, qd, dt))
        } else {
            let (q_at, v_at) = (self.model.q_offsets(), self.model.v_offsets());
            let blocks = self.model.floating_joints().into_iter().map(|j| {
                let (a, b) = (usize_lit(q_at[j]), usize_lit(v_at[j]));
                quote!((#a, #b))
            });
            quote!(::eomgen_runtime::free_flyer::integrate_blocks(q, qd, dt, &[#(#blocks),*]))
        };
        quote! {
            #docs
            #vis fn integrate(&self, q: &[T; #nq], qd: &[T; #n], dt: T) -> [T; #nq] {
                #body
            }
        }
    }

    fn link_pose_fn(&mut self, q: &Quantity) -> TokenStream {
        let docs = Self::quantity_doc(q, None);
        let (link_ty, nq) = (&self.link_ty, &self.nq);
        quote! {
            #docs
            pub fn link_pose(&self, link: #link_ty, q: &[T; #nq]) -> ::eomgen_runtime::Pose<T> {
                let (path, placement) = Self::link_frame(link);
                ::eomgen_runtime::tree::chain_pose(path, |j| self.joint_transform(j, q)).compose(&placement)
            }
        }
    }

    fn link_jacobian_fn(&mut self, q: &Quantity) -> TokenStream {
        let docs = Self::quantity_doc(q, None);
        let (link_ty, n, nq) = (&self.link_ty, &self.n, &self.nq);
        let kernel = if self.floating {
            quote!(::eomgen_runtime::free_flyer::chain_jacobian)
        } else {
            quote!(::eomgen_runtime::tree::chain_jacobian)
        };
        if !self.model.floating_joints().is_empty() {
            // Joints of several columns: each joint's first column from a table.
            let columns = self.model.v_offsets().into_iter().map(usize_lit);
            let nj = usize_lit(self.model.joints.len());
            return quote! {
                #docs
                pub fn link_jacobian(&self, link: #link_ty, q: &[T; #nq]) -> [[T; #n]; 6] {
                    const COLUMNS: [usize; #nj] = [#(#columns),*];
                    let (path, placement) = Self::link_frame(link);
                    ::eomgen_runtime::tree::chain_jacobian_columns(path, &Self::TREE_JOINTS, &COLUMNS, |j| self.joint_transform(j, q), &placement)
                }
            };
        }
        if self.model.is_coupled() {
            // Columns per joint (after a floating base's six), then summed into the
            // coordinates' (`J G`).
            let nj = usize_lit(self.model.nv());
            return quote! {
                #docs
                pub fn link_jacobian(&self, link: #link_ty, q: &[T; #nq]) -> [[T; #n]; 6] {
                    let (path, placement) = Self::link_frame(link);
                    let joints: [[T; #nj]; 6] = #kernel(path, &Self::TREE_JOINTS, |j| self.joint_transform(j, q), &placement);
                    ::eomgen_runtime::tree::couple_columns(&joints, &Self::COUPLING)
                }
            };
        }
        quote! {
            #docs
            pub fn link_jacobian(&self, link: #link_ty, q: &[T; #nq]) -> [[T; #n]; 6] {
                let (path, placement) = Self::link_frame(link);
                #kernel(path, &Self::TREE_JOINTS, |j| self.joint_transform(j, q), &placement)
            }
        }
    }

    /// What link kinematics walks: each joint's transform as straight-line code, the joint
    /// axes, and per link its chain from the root and its placement in its body.
    fn frame_support(&mut self, d: &Derivation) -> TokenStream {
        let (nj, nq) = (usize_lit(self.model.joints.len()), &self.nq);
        let arms: Vec<TokenStream> = d
            .joint_transforms
            .iter()
            .enumerate()
            .map(|(j, t)| {
                let mut outs: Vec<Id> = t.translation.to_vec();
                outs.extend(t.rotation.iter().flatten());
                let b = body(self.graph, &self.cx, &outs, Shape::Vector(12), None).code;
                let j = usize_lit(j);
                quote!(#j => { let o = { #b }; ::eomgen_runtime::Pose { translation: [o[0], o[1], o[2]], rotation: [[o[3], o[4], o[5]], [o[6], o[7], o[8]], [o[9], o[10], o[11]]] } })
            })
            .collect();
        let joints = self.model.joints.iter().map(|j| {
            let axis = j.axis.map(snap);
            let [x, y, z] = [0, 1, 2].map(|k| f64_literal(axis[k]));
            let motion = match j.kind {
                JointKind::Floating => quote!(Free),
                JointKind::Revolute | JointKind::Continuous => quote!(Rotation),
                JointKind::Prismatic => quote!(Translation),
            };
            quote!(::eomgen_runtime::tree::TreeJoint { axis: [#x, #y, #z], motion: ::eomgen_runtime::tree::Motion::#motion })
        });
        let link_arms = self.link_frame_arms();
        let link_ty = &self.link_ty;
        // The joint axes and the coupling are read by `link_jacobian` and the frames' motion
        // alone: without them, a `link_pose` selection would carry unused constants (rustc's
        // `dead_code` warning).
        let jacobian = self.quantities.iter().any(|q| {
            matches!(
                q.eval,
                Evaluation::LinkJacobian | Evaluation::FrameMotion(_)
            )
        });
        let coupling = if jacobian && self.model.is_coupled() {
            let v0 = self.model.base_nv();
            let base = (0..v0).map(|i| (i, 1.0));
            let joints = self
                .model
                .coupling
                .iter()
                .map(|c| (v0 + c.coordinate, c.multiplier));
            let entries = base.chain(joints).map(|(i, k)| {
                let (i, k) = (usize_lit(i), f64_literal(k));
                quote!((#i, #k))
            });
            let nv = usize_lit(self.model.nv());
            quote! {
                /// Per velocity column of the joint tree (a floating base's six, then one per
                /// joint), the coordinate it follows and its multiplier (its rate is the
                /// multiplier times the coordinate's).
                const COUPLING: [(usize, f64); #nv] = [#(#entries),*];
            }
        } else {
            TokenStream::new()
        };
        let tree_joints = if jacobian {
            quote! {
                /// Each joint's axis (in the frame of the body it moves) and motion.
                const TREE_JOINTS: [::eomgen_runtime::tree::TreeJoint; #nj] = [#(#joints),*];
            }
        } else {
            TokenStream::new()
        };
        quote! {
            #tree_joints
            #coupling

            /// The pose of body `j` in its parent body's frame (a floating base is body 0).
            fn joint_transform(&self, j: usize, q: &[T; #nq]) -> ::eomgen_runtime::Pose<T> {
                match j {
                    #(#arms)*
                    _ => ::eomgen_runtime::Pose::identity(),
                }
            }

            /// A link's chain of joints from the root and its placement in the last body.
            fn link_frame(link: #link_ty) -> (&'static [usize], ::eomgen_runtime::Pose<T>) {
                match link { #(#link_arms)* }
            }
        }
    }

    fn link_frame_arms(&self) -> Vec<TokenStream> {
        let link_ty = &self.link_ty;
        self.model
            .frames
            .iter()
            .zip(self.link_variants())
            .map(|(f, v)| {
                // Bodies from the root; a floating base is body 0, before the joints' bodies.
                let shift = usize::from(self.floating);
                let base = self.floating.then_some(0);
                let path: Vec<Literal> = match f.body {
                    Some(b) => base
                        .into_iter()
                        .chain(self.model.path_to_root(b).into_iter().map(|j| j + shift))
                        .map(usize_lit)
                        .collect(),
                    None => base.into_iter().map(usize_lit).collect(),
                };
                let pose = constant_pose(&f.placement);
                quote!(#link_ty::#v => (&[#(#path),*], #pose),)
            })
            .collect()
    }

    /// `impl Dynamics` with its methods, when every one of them is generated.
    fn trait_impl(&self, methods: &[TokenStream]) -> TokenStream {
        if !self.in_trait {
            return TokenStream::new();
        }
        let names = self
            .model
            .coordinate_names()
            .into_iter()
            .map(|name| Literal::string(&name));
        let (ty, n, allow) = (&self.ty, &self.n, allow_lints());
        quote! {
            #allow
            impl<T: ::eomgen_runtime::Real> ::eomgen_runtime::Dynamics<T, #n> for #ty<T> {
                const JOINT_NAMES: [&'static str; #n] = [#(#names),*];
                #(#methods)*
            }
        }
    }
}

impl Emitter<'_> {
    fn has(&self, name: &str) -> bool {
        self.quantities.iter().any(|q| q.name == name)
    }

    /// A floating-base robot's `FloatingDynamics` implementation (when its methods are all
    /// generated) and `Contacts` (with contact points and `contact_forward_dynamics`), holding
    /// those methods.
    fn floating_impls(&self, floating: &[TokenStream], contacts: &[TokenStream]) -> TokenStream {
        if !self.floating {
            return TokenStream::new();
        }
        let (ty, n, nq, allow) = (&self.ty, &self.n, &self.nq, allow_lints());
        let mut out = TokenStream::new();
        if self.floating_trait {
            out.extend(quote! {
                #allow
                impl<T: ::eomgen_runtime::Real> ::eomgen_runtime::FloatingDynamics<T, #nq, #n> for #ty<T> {
                    #(#floating)*
                }
            });
        }
        if let Some(k3) = &self.contacts_trait {
            out.extend(quote! {
                #allow
                impl<T: ::eomgen_runtime::Real> ::eomgen_runtime::Contacts<T, #nq, #n, #k3> for #ty<T> {
                    #(#contacts)*
                }
            });
        }
        out
    }
}

/// The type documentation's paragraph on mimic joints: which joints follow which coordinate.
fn coupling_doc(model: &Model) -> Vec<String> {
    let mut lines = vec![
        String::new(),
        format!(
            "Mimic joints follow other joints (URDF `<mimic>`, honoured): the {} coordinates are the independent",
            model.coordinates()
        ),
        "joints (`JOINT_NAMES`), and every quantity is in them (efforts `G^T tau`, `M = G^T M_joints G`,".into(),
        "Jacobians `J G`, with `q_joint = multiplier q_coordinate + offset`):".into(),
    ];
    let names = model.coordinate_names();
    for (j, c) in model.joints.iter().zip(&model.coupling) {
        if c.leader.is_some() {
            lines.push(format!(
                "- `{}` = {} `{}` + {}",
                j.name.replace('`', "'"),
                c.multiplier,
                names[c.coordinate].replace('`', "'"),
                c.offset
            ));
        }
    }
    lines
}

/// A constant pose as `Pose { .. }` with `T::from_f64` literals (rotation entries snapped).
fn constant_pose(t: &Transform) -> TokenStream {
    let tr = (0..3).map(|k| lit(t.translation[k]));
    let rotation = snap_rotation(&t.rotation);
    let rows = (0..3).map(|r| {
        let row = (0..3).map(|c| lit(rotation[(r, c)]));
        quote!([#(#row),*])
    });
    quote!(::eomgen_runtime::Pose { translation: [#(#tr),*], rotation: [#(#rows),*] })
}

/// An `f64` literal, negative ones as a negation.
fn f64_literal(v: f64) -> TokenStream {
    let l = Literal::f64_unsuffixed(v.abs());
    if v < 0.0 {
        quote!(-#l)
    } else {
        quote!(#l)
    }
}
