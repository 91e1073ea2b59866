//! The `NAME_batch` methods: each method generated for every `T: Lane` evaluated at many
//! states per call, packed into the target's widest lanes (`eomgen_runtime::batch`).

use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote};

use super::items::Fields;
use super::traits::Trait;
use super::{allow_lints, usize_lit, Emitter};
use crate::cas::OpCount;
use crate::dynamics::{ActiveContacts, Evaluation, Quantity, Shape};
use crate::emit::body::shape_type;

/// The most operations per entry of its result for which a quantity's batch method writes the
/// states' results from its own copy of the straight-line body ([`Emitter::unpacks`]): an
/// 18 x 18 mass matrix of `f64x4` is 10 kB, which the lanes' method wrote and the unpacking
/// read back (anymal, 1,010 operations for 324 entries: 9.0 -> 10.3 million states per
/// second in `f64x4`, 17.5 -> 23 in `f32x8`); a Coriolis matrix (the panda's: 2,606
/// operations for 81 entries) would add 2,600 lines to the file for little.
const UNPACKED_MAX_OPS_PER_ENTRY: usize = 8;

/// The lane type of a batch method: the widest vector of `T`.
fn lanes() -> TokenStream {
    quote!(<T as ::eomgen_runtime::batch::Batch>::Lanes)
}

/// The type of one state's value of `shape`, with `T` for its scalar.
fn element(shape: Shape) -> TokenStream {
    shape_type(shape)
}

/// A batch method's output slices: their names (`out`, or `out_0`, ... for a tuple), the type
/// of one state's value in each, and the statements scattering the lanes' result `r` into them.
struct Outs {
    names: Vec<Ident>,
    types: Vec<TokenStream>,
    scatters: Vec<TokenStream>,
}

/// The output slices of a quantity whose value holds one element of each of `shapes`.
fn outputs(shapes: Vec<Shape>) -> Outs {
    let names: Vec<Ident> = match shapes.len() {
        1 => vec![format_ident!("out")],
        k => (0..k).map(|i| format_ident!("out_{}", i)).collect(),
    };
    let scatters = shapes
        .iter()
        .zip(&names)
        .enumerate()
        .map(|(k, (s, o))| {
            let r = if shapes.len() == 1 {
                quote!(r)
            } else {
                let k = usize_lit(k);
                quote!(r.#k)
            };
            match s {
                Shape::Scalar => quote!(::eomgen_runtime::batch::scatter_scalar(#r, #o);),
                Shape::Vector(_) => quote!(::eomgen_runtime::batch::scatter(&#r, #o);),
                _ => quote!(::eomgen_runtime::batch::scatter_matrix(&#r, #o);),
            }
        })
        .collect();
    Outs {
        types: shapes.iter().map(|s| element(*s)).collect(),
        names,
        scatters,
    }
}

/// The element shapes of a value of `shape`: the matrices of a tuple, or the value itself.
pub(super) fn elements(shape: Shape) -> Vec<Shape> {
    match shape {
        Shape::Matrices(k, r, c) => vec![Shape::Matrix(r, c); k],
        s => vec![s],
    }
}

/// The number shared by every state that a method of this evaluation takes after its inputs:
/// `integrate`'s time step, the impulse methods' restitution.
pub(super) fn shared_scalar(eval: &Evaluation) -> Option<Ident> {
    match eval {
        Evaluation::Integrate => Some(format_ident!("dt")),
        Evaluation::ImpulseDynamics
        | Evaluation::ImpulseDynamicsFlat { .. }
        | Evaluation::ImpulseDynamicsDerivatives
        | Evaluation::ActiveContacts(
            ActiveContacts::Impulse | ActiveContacts::ImpulseDerivatives,
        ) => Some(format_ident!("restitution")),
        _ => None,
    }
}

impl Emitter<'_> {
    /// The element shapes of `q`'s value: contact forward dynamics and impulse dynamics (all
    /// their forms) give a pair of vectors (`N` velocity coordinates, `K` contact rows).
    pub(super) fn result_shapes(&self, q: &Quantity) -> Vec<Shape> {
        match q.eval {
            Evaluation::ContactForwardDynamics { .. }
            | Evaluation::ContactForwardDynamicsFlat { .. }
            | Evaluation::ImpulseDynamics
            | Evaluation::ImpulseDynamicsFlat { .. }
            | Evaluation::ActiveContacts(
                ActiveContacts::Dynamics { .. }
                | ActiveContacts::Stabilized { .. }
                | ActiveContacts::Impulse,
            ) => {
                let n = self.parents.len();
                vec![Shape::Vector(n), Shape::Vector(q.shape.len() - n)]
            }
            _ => elements(q.shape),
        }
    }

    /// `impl<T: Batch>` with `in_lanes` and one `_batch` method per quantity on lanes.
    pub(super) fn batch_impl(&self, fields: &Fields) -> TokenStream {
        let (ty, allow) = (&self.ty, allow_lints());
        let names: Vec<&Ident> = fields.by_symbol.values().collect();
        let methods = self.quantities.iter().map(|q| self.batch_fn(q));
        let unpacked: Vec<TokenStream> = self
            .quantities
            .iter()
            .filter(|q| self.unpacks(q))
            .map(|q| self.unpacked_fn(q))
            .collect();
        let unpacked = (!unpacked.is_empty()).then(|| {
            quote! {
                #allow
                impl<T: ::eomgen_runtime::lane::Pack> #ty<T> {
                    #(#unpacked)*
                }
            }
        });
        quote! {
            #unpacked
            #allow
            impl<T: ::eomgen_runtime::batch::Batch> #ty<T> {
                /// This robot's parameters in every lane of `L` (a vector of states such as
                /// `wide::f64x4`, with `eomgen_runtime`'s `simd` feature): the robot whose
                /// methods evaluate one state per lane.
                pub fn in_lanes<L: ::eomgen_runtime::lane::Pack<Scalar = T>>(&self) -> #ty<L> {
                    #ty {
                        #(#names: <L as ::eomgen_runtime::Lane>::from_f64(::eomgen_runtime::Real::to_f64(self.#names)),)*
                        _marker: ::core::marker::PhantomData,
                    }
                }
                #(#methods)*
            }
        }
    }

    /// Whether `q`'s batch method computes each vector of states by `{name}_unpacked`, which
    /// writes the states' results straight from the straight-line body
    /// ([`crate::emit::body::unpacked_body`]) instead of through the lanes' result: matrices
    /// from one body that is not split, outside the derivatives, of at most `N x N` entries
    /// and [`UNPACKED_MAX_OPS_PER_ENTRY`] operations per entry. The body is a second copy of
    /// the quantity's, which each user's crate parses and checks: it pays where the result is
    /// large for its arithmetic (a mass matrix), not for a Coriolis matrix or Craig's `B(q)`.
    fn unpacks(&self, q: &Quantity) -> bool {
        let entries = q.shape.len();
        let n = self.parents.len();
        let small =
            |ops: OpCount| entries <= n * n && ops.total() <= UNPACKED_MAX_OPS_PER_ENTRY * entries;
        matches!(q.eval, Evaluation::Exprs(_))
            && matches!(q.shape, Shape::Matrix(..) | Shape::Matrices(..))
            && !self.split.contains(q.name)
            && !self.derivatives.contains(q.name)
            && self
                .counts
                .iter()
                .any(|(name, ops)| name == q.name && small(*ops))
    }

    /// `fn {name}_unpacked(&self, inputs..., out...)` for `T: Pack`: `q`'s straight-line body
    /// on one vector of states, writing each state's result into `out` (row-major, one state
    /// after another; one slice per matrix of a tuple).
    fn unpacked_fn(&self, q: &Quantity) -> TokenStream {
        let Evaluation::Exprs(ids) = &q.eval else {
            return TokenStream::new();
        };
        let f = format_ident!("{}_unpacked", q.name);
        let params = self.args(q.inputs);
        let outs = outputs(elements(q.shape)).names;
        let (r, c) = match q.shape {
            Shape::Matrix(r, c) | Shape::Matrices(_, r, c) => (usize_lit(r), usize_lit(c)),
            _ => return TokenStream::new(),
        };
        let body = crate::emit::body::unpacked_body(self.graph, &self.cx, ids, q.shape);
        quote! {
            fn #f(&self, #(#params,)* #(#outs: &mut [[[<T as ::eomgen_runtime::lane::Pack>::Scalar; #c]; #r]]),*) {
                #body
            }
        }
    }

    /// `q`'s operations per state for `eomgen_runtime::batch::run_costed`: the count of a
    /// straight-line program, else `usize::MAX` (a solve or kinematics at run time, whose
    /// count, if any, is only its straight-line part: no call of it is taken as too cheap to
    /// spread over threads).
    pub(super) fn ops_per_state(&self, q: &Quantity) -> TokenStream {
        let straight = matches!(
            q.eval,
            Evaluation::Exprs(_)
                | Evaluation::ForwardDynamics { .. }
                | Evaluation::ContactForwardDynamicsFlat { .. }
                | Evaluation::ImpulseDynamicsFlat { .. }
                | Evaluation::Factored { .. }
        );
        let count = self.counts.iter().find(|(name, _)| name == q.name);
        match count {
            Some((_, ops)) if straight => {
                let ops = Literal::usize_unsuffixed(ops.total());
                quote!(#ops)
            }
            _ => quote!(::core::primitive::usize::MAX),
        }
    }

    /// The path of method `name` on the robot of lanes.
    fn lane_path(&self, name: &str) -> TokenStream {
        let (ty, f, n, nq, l) = (
            &self.ty,
            format_ident!("{}", name),
            &self.n,
            &self.nq,
            lanes(),
        );
        match self.trait_of(name) {
            Some(Trait::Dynamics) => quote!(<#ty<#l> as ::eomgen_runtime::Dynamics<#l, #n>>::#f),
            Some(Trait::Floating) => {
                quote!(<#ty<#l> as ::eomgen_runtime::FloatingDynamics<#l, #nq, #n>>::#f)
            }
            Some(Trait::Contacts) => {
                let k = &self.k;
                quote!(<#ty<#l> as ::eomgen_runtime::Contacts<#l, #nq, #n, #k>>::#f)
            }
            _ => quote!(#ty::<#l>::#f),
        }
    }

    /// `NAME_batch(&self, inputs: &[[T; _]]..., outputs: &mut [_]...)`.
    fn batch_fn(&self, q: &Quantity) -> TokenStream {
        let f = format_ident!("{}_batch", q.name);
        let inputs = Self::state_names(q);
        let input_types = q.inputs.iter().map(|i| self.input_len(*i));
        let Outs {
            names: outs,
            types: out_types,
            scatters,
        } = self.batch_outs(q);
        let Shared {
            link_param,
            params: shared_params,
            to_lanes,
            args: shared_args,
        } = self.shared_params(q);
        let call_args = shared_args.0.into_iter().chain(
            inputs
                .iter()
                .map(|i| quote!(&::eomgen_runtime::batch::gather(#i, start)))
                .chain(shared_args.1),
        );
        let path = self.lane_path(q.name);
        let first = &outs[0];
        let checked = inputs.iter().chain(&outs[1..]).map(|a| {
            let name = a.to_string();
            quote!((#name, #a.len()))
        });
        let (pattern, passed) = if outs.len() == 1 {
            let t = &out_types[0];
            (quote!(#first: &mut [#t]), quote!(#first))
        } else {
            (
                quote!((#(#outs),*): (#(&mut [#out_types]),*)),
                quote!((#(#outs),*)),
            )
        };
        let doc = format!(
            " `{}` at every state: `out[i]` (or each `out_k[i]` of a tuple) from the inputs' \
             element `i`, several states per vector of the target's widest SIMD lanes \
             (`eomgen_runtime::batch`; over threads with its `rayon` feature). An error, with \
             nothing written, when a slice holds another number of states than `{}`.",
            q.name, first
        );
        let (l, ops) = (lanes(), self.ops_per_state(q));
        let evaluate = if self.unpacks(q) {
            let f = format_ident!("{}_unpacked", q.name);
            quote! {
                robot.#f(#(#call_args,)* #(#outs),*);
            }
        } else {
            quote! {
                let r = #path(&robot, #(#call_args),*);
                #(#scatters)*
            }
        };
        quote! {
            #[doc = #doc]
            pub fn #f(&self, #link_param #(#inputs: &[[T; #input_types]],)* #shared_params #(#outs: &mut [#out_types]),*) -> ::core::result::Result<(), ::eomgen_runtime::batch::BatchError> {
                ::eomgen_runtime::batch::check(#first.len(), &[#(#checked),*])?;
                let robot = self.in_lanes::<#l>();
                #to_lanes
                ::eomgen_runtime::batch::run_costed(<#l as ::eomgen_runtime::Lane>::LANES, #ops, #passed, &|start: usize, #pattern| {
                    #evaluate
                });
                Ok(())
            }
        }
    }

    /// `q`'s output slices: a pose, a result struct of the runtime, or arrays and matrices.
    fn batch_outs(&self, q: &Quantity) -> Outs {
        match q.eval {
            Evaluation::LinkPose => Outs {
                names: vec![format_ident!("out")],
                types: vec![quote!(::eomgen_runtime::Pose<T>)],
                scatters: vec![quote!(::eomgen_runtime::batch::scatter_pose(&r, out);)],
            },
            Evaluation::ContactDynamicsDerivatives { .. }
            | Evaluation::ActiveContacts(ActiveContacts::Derivatives { .. }) => {
                self.derivatives_out("ContactDynamicsDerivatives", "scatter_contact_derivatives")
            }
            Evaluation::ImpulseDynamicsDerivatives
            | Evaluation::ActiveContacts(ActiveContacts::ImpulseDerivatives) => {
                self.derivatives_out("ImpulseDynamicsDerivatives", "scatter_impulse_derivatives")
            }
            _ => outputs(self.result_shapes(q)),
        }
    }

    /// The output slice of a result struct of the runtime (`ty`, of `N` velocity coordinates
    /// and `K` contact rows), with the runtime's function `scatter` unpacking its lanes.
    fn derivatives_out(&self, ty: &str, scatter: &str) -> Outs {
        let (n, k) = (&self.n, &self.k);
        let (ty, scatter) = (format_ident!("{}", ty), format_ident!("{}", scatter));
        Outs {
            names: vec![format_ident!("out")],
            types: vec![quote!(::eomgen_runtime::#ty<T, #n, #k>)],
            scatters: vec![quote!(::eomgen_runtime::batch::#scatter(&r, out);)],
        }
    }

    /// What every state of `q`'s batch shares, passed once: link kinematics' link (first),
    /// and after the inputs a restitution or time step (turned into lanes once) and the active
    /// contacts, in the order the scalar method takes them.
    fn shared_params(&self, q: &Quantity) -> Shared {
        let link = matches!(
            q.eval,
            Evaluation::LinkPose | Evaluation::LinkJacobian | Evaluation::FrameMotion(_)
        );
        let (link_param, link_arg) = if link {
            let t = &self.link_ty;
            (quote!(link: #t,), Some(quote!(link)))
        } else {
            (TokenStream::new(), None)
        };
        let (names, types): (Vec<Ident>, Vec<TokenStream>) =
            self.shared_values(q).into_iter().unzip();
        let params = quote!(#(#names: #types,)*);
        let l = lanes();
        let to_lanes = shared_scalar(&q.eval).map(|x| {
            quote!(let #x = <#l as ::eomgen_runtime::Lane>::from_f64(::eomgen_runtime::Real::to_f64(#x));)
        });
        // Baumgarte's gains and references, the same in every lane.
        let gains = names
            .iter()
            .any(|x| x == "baumgarte")
            .then(|| quote!(let baumgarte = &baumgarte.in_lanes::<#l>();));
        let to_lanes = to_lanes.into_iter().chain(gains).collect();
        let after = names.iter().map(|x| quote!(#x)).collect();
        Shared {
            link_param,
            params,
            to_lanes,
            args: (link_arg, after),
        }
    }

    /// What every state of `q` shares after its inputs, in the order its scalar method takes
    /// them, with their types: a time step or restitution, the active contacts, Baumgarte's
    /// gains. Both kinds of batch pass them once.
    pub(super) fn shared_values(&self, q: &Quantity) -> Vec<(Ident, TokenStream)> {
        let c = usize_lit(self.contact_rows.len());
        let mut out: Vec<(Ident, TokenStream)> = shared_scalar(&q.eval)
            .map(|x| (x, quote!(T)))
            .into_iter()
            .collect();
        if matches!(q.eval, Evaluation::ActiveContacts(_)) {
            out.push((format_ident!("active"), quote!(&[bool; #c])));
        }
        if matches!(
            q.eval,
            Evaluation::ActiveContacts(ActiveContacts::Stabilized { .. })
        ) {
            let gains = quote!(&::eomgen_runtime::Baumgarte<T, #c>);
            out.push((format_ident!("baumgarte"), gains));
        }
        out
    }
}

/// [`Emitter::shared_params`]' parameters, statements and arguments.
struct Shared {
    /// The link parameter, before the inputs.
    link_param: TokenStream,
    /// The parameters after the inputs.
    params: TokenStream,
    /// What turns them into lanes.
    to_lanes: TokenStream,
    /// The arguments before the inputs, and after them.
    args: (Option<TokenStream>, Vec<TokenStream>),
}
