//! One method per quantity: the dispatch on its [`Evaluation`], its signature and
//! documentation, and the straight-line bodies (split beyond the budget, `emit/split.rs`).

use proc_macro2::{Ident, TokenStream};
use quote::{format_ident, quote};

use super::{doc, usize_lit, Emitter};
use crate::cas::{Id, OpCount};
use crate::dynamics::{ActiveContacts, Craig, Evaluation, Input, Manifold, Quantity, Shape};
use crate::emit::body::{body, factored_body, shape_type, Body};
use crate::emit::split::Split;

/// The quantities whose callers have them write into the callers' own results
/// (`{name}_fill`): the inverse-dynamics derivatives (the composed forward-dynamics
/// derivatives', the contact derivatives') and the impulse and contact partials (the impulse
/// and contact derivatives').
const FILLED: [&str; 4] = [
    "inverse_dynamics_derivatives",
    "impulse_dynamics_partials",
    "forward_dynamics_partials",
    "contact_dynamics_partials",
];

impl Emitter<'_> {
    pub(super) fn quantity_fn(&mut self, q: &Quantity) -> TokenStream {
        match &q.eval {
            Evaluation::Exprs(ids) => self.exprs_fn(q, ids),
            Evaluation::CraigColumns(which) => self.craig_fn(q, *which),
            Evaluation::ForwardDynamics { .. } | Evaluation::ForwardDynamicsSolve { .. } => {
                self.forward_dynamics_fns(q)
            }
            Evaluation::LinkPose => self.link_pose_fn(q),
            Evaluation::LinkJacobian => self.link_jacobian_fn(q),
            Evaluation::MassMatrixInverse => self.mass_matrix_inverse_fn(q),
            Evaluation::ForwardDynamicsDerivatives { partials } => {
                self.forward_dynamics_derivatives_fn(q, *partials)
            }
            Evaluation::ContactForwardDynamics { .. }
            | Evaluation::ContactForwardDynamicsFlat { .. } => self.contact_forward_dynamics_fns(q),
            Evaluation::Integrate => self.integrate_fn(q),
            Evaluation::FrameMotion(m) => self.frame_motion_fn(q, *m),
            Evaluation::Manifold(m) => self.manifold_fn(q, *m),
            Evaluation::ContactDynamicsDerivatives { h } => {
                self.contact_dynamics_derivatives_fns(q, h, false)
            }
            Evaluation::ImpulseDynamics => self.impulse_dynamics_fns(q),
            Evaluation::ImpulseDynamicsFlat { outputs, pivots } => {
                self.impulse_flat_fns(q, outputs, pivots)
            }
            Evaluation::ImpulseDynamicsDerivatives => {
                self.impulse_dynamics_derivatives_fns(q, false)
            }
            Evaluation::ActiveContacts(a) => self.active_contacts_fns(q, a),
            Evaluation::Factored { outputs, pivots } => self.factored_fn(q, outputs, pivots),
        }
    }

    /// The methods of a set of active contacts ([`ActiveContacts`]).
    pub(super) fn active_contacts_fns(&mut self, q: &Quantity, a: &ActiveContacts) -> TokenStream {
        match a {
            ActiveContacts::Dynamics { h } => self.contact_active_checked_fns(q, h),
            ActiveContacts::Stabilized { h } => self.contact_stabilized_fns(q, h),
            ActiveContacts::Derivatives { h } => self.contact_dynamics_derivatives_fns(q, h, true),
            ActiveContacts::Impulse => self.impulse_active_checked_fns(q),
            ActiveContacts::ImpulseDerivatives => self.impulse_dynamics_derivatives_fns(q, true),
        }
    }

    /// The arguments `q: &[T; N], ...` of a quantity.
    pub(super) fn args(&self, inputs: &[Input]) -> Vec<TokenStream> {
        inputs
            .iter()
            .map(|i| {
                let (name, len) = (format_ident!("{}", i.name()), self.input_len(*i));
                quote!(#name: &[T; #len])
            })
            .collect()
    }

    /// The length of an argument's array: `NQ` for `q`, `K` for the contact forces, else `N`.
    pub(super) fn input_len(&self, i: Input) -> &proc_macro2::Literal {
        match i {
            Input::Q => &self.nq,
            Input::Forces => &self.k,
            _ => &self.n,
        }
    }

    /// The names `q, qd, ...` of a quantity's arguments.
    pub(super) fn arg_names(inputs: &[Input]) -> Vec<Ident> {
        inputs
            .iter()
            .map(|i| format_ident!("{}", i.name()))
            .collect()
    }

    /// The names of `q`'s per-state arguments, as its method's signature has them: the
    /// manifold's own (`q0, q1`; `q, v`), else those of its inputs. Both kinds of batch
    /// method take their slices under these names.
    pub(super) fn state_names(q: &Quantity) -> Vec<Ident> {
        let names: &[&str] = match q.eval {
            Evaluation::Manifold(Manifold::IntegrateJacobians) => &["q", "v"],
            Evaluation::Manifold(_) => &["q0", "q1"],
            _ => return Self::arg_names(q.inputs),
        };
        names.iter().map(|x| format_ident!("{}", x)).collect()
    }

    pub(super) fn quantity_doc(q: &Quantity, ops: Option<OpCount>) -> TokenStream {
        let mut lines = q.doc.clone();
        lines.push(String::new());
        lines.push(q.route.clone());
        if let Some(ops) = ops {
            lines.push(format!("Operations: {ops}."));
        }
        doc(&lines)
    }

    /// Straight-line code for `outputs`, counted under `q`'s name.
    pub(super) fn straight(
        &mut self,
        q: &Quantity,
        outputs: &[Id],
        shape: Shape,
    ) -> (TokenStream, OpCount) {
        let (params, args) = (self.args(q.inputs), Self::arg_names(q.inputs));
        let rows = Self::row_groups(q.name, shape);
        let mut split = self.split(q.name, &params, &args);
        split.rows = &rows;
        split.adds = Self::added_groups(q.name, &rows);
        let b = body(self.graph, &self.cx, outputs, shape, Some(&split));
        self.counts.push((q.name.to_string(), b.ops));
        if !b.blocks.is_empty() {
            self.split.insert(q.name.to_string());
        }
        self.blocks.extend(b.blocks);
        (b.code, b.ops)
    }

    /// How a body of the function `name` is split beyond the budget.
    pub(super) fn split<'s>(
        &self,
        name: &'s str,
        params: &'s [TokenStream],
        args: &'s [Ident],
    ) -> Split<'s> {
        Split {
            name,
            params,
            args,
            budget: if self.derivatives.contains(name) {
                self.derivative_budget
            } else {
                self.budget
            },
            rows: &[],
            adds: 0,
            filled: self.filled_by_another(name),
        }
    }

    /// Whether another generated function has the body of `name` fill its own result's
    /// storage ([`Split::filled`]): a quantity of [`FILLED`] that another quantity of the
    /// selection needs ([`Quantity::needs`]). Built in a local and copied out, talos's impulse
    /// partials (22 kB) took its impulse derivatives beyond a 64 KiB stack.
    fn filled_by_another(&self, name: &str) -> bool {
        FILLED.contains(&name) && self.quantities.iter().any(|q| q.needs().contains(&name))
    }

    /// The row groups a split body of `name` fills separately ([`Split::rows`]): the impulse
    /// partials' `N` rows in `q` and `K` contact rows, which `impulse_dynamics_derivatives`
    /// has written straight into two matrices of its result; the contact partials' `N` rows in
    /// `q` and two groups of `K` contact rows, which `contact_forward_dynamics_derivatives`
    /// adds onto its inverse-dynamics derivatives and writes into two matrices of its result
    /// (built in a local, copied and added, they were a tenth of anymal's derivatives).
    pub(super) fn row_groups(name: &str, shape: Shape) -> Vec<usize> {
        match (name, shape) {
            ("impulse_dynamics_partials", Shape::Matrix(r, c)) if r > c => vec![c, r - c],
            ("contact_dynamics_partials", Shape::Matrix(r, c)) if r > c && (r - c) % 2 == 0 => {
                vec![c, (r - c) / 2, (r - c) / 2]
            }
            _ => Vec::new(),
        }
    }

    /// How many of the first `rows` groups of `name`'s `{name}_fill` add onto their matrices
    /// ([`Split::adds`]): the contact partials' rows in `q`.
    fn added_groups(name: &str, rows: &[usize]) -> usize {
        usize::from(name == "contact_dynamics_partials" && !rows.is_empty())
    }

    pub(super) fn exprs_fn(&mut self, q: &Quantity, ids: &[Id]) -> TokenStream {
        let (b, ops) = self.straight(q, ids, q.shape);
        self.plain_fn(q, ops, b)
    }

    /// Straight-line code whose outputs hold when the factorization's pivots are positive.
    pub(super) fn factored_fn(
        &mut self,
        q: &Quantity,
        outputs: &[Id],
        pivots: &[Id],
    ) -> TokenStream {
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
    pub(super) fn plain_fn(&self, q: &Quantity, ops: OpCount, body: TokenStream) -> TokenStream {
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
    pub(super) fn craig_fn(&mut self, q: &Quantity, which: Craig) -> TokenStream {
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

    pub(super) fn integrate_fn(&mut self, q: &Quantity) -> TokenStream {
        let docs = Self::quantity_doc(q, None);
        let (n, nq, vis) = (&self.n, &self.nq, self.vis(q.name));
        let body = if self.floating {
            quote!(::eomgen_runtime::free_flyer::integrate(q, qd, dt))
        } else {
            let blocks = self.free_blocks();
            quote!(::eomgen_runtime::free_flyer::integrate_blocks(q, qd, dt, #blocks))
        };
        quote! {
            #docs
            #vis fn integrate(&self, q: &[T; #nq], qd: &[T; #n], dt: T) -> [T; #nq] {
                #body
            }
        }
    }

    /// The floating joints below the root as the runtime's `_blocks` kernels read them:
    /// `&[(first position, first velocity coordinate), ...]`.
    pub(super) fn free_blocks(&self) -> TokenStream {
        let (q_at, v_at) = (self.model.q_offsets(), self.model.v_offsets());
        let blocks = self.model.floating_joints().into_iter().map(|j| {
            let (a, b) = (usize_lit(q_at[j]), usize_lit(v_at[j]));
            quote!((#a, #b))
        });
        quote!(&[#(#blocks),*])
    }
}
