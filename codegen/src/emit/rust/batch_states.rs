//! The `NAME_batch` methods of the quantities that do not run on lanes (the stabilized form of
//! contacts switched at run time, whose Baumgarte correction branches on values):
//! the scalar method at each state in turn, the states spread over rayon's threads with the
//! runtime's `rayon` feature (`eomgen_runtime::batch::run_costed` of one state per vector).
//! Their code branches on values, so a state per lane is not possible; the batch form still
//! gives every catalogue method the same calling convention and the threads.

use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote};

use super::{usize_lit, Emitter};
use crate::dynamics::{ActiveContacts, Evaluation, Quantity};
use crate::emit::body::shape_type;

/// One parameter of a scalar method, in its place in the signature.
enum Param {
    /// A value every state shares (a restitution, a set of active contacts, gains), passed
    /// once to the batch method.
    Shared(Ident, TokenStream),
    /// An array of this length per state: a slice of them in the batch method.
    State(Ident, Literal),
}

/// A scalar method's parameters, and the types of its result's elements (one, or a tuple's).
struct StateSignature {
    params: Vec<Param>,
    outputs: Vec<TokenStream>,
}

impl Emitter<'_> {
    /// The `NAME_batch` of every method generated for `T: Real` alone.
    pub(super) fn state_batch_fns(&self) -> Vec<TokenStream> {
        self.quantities
            .iter()
            .filter(|q| !self.lanes.contains(q.name))
            .map(|q| self.state_batch_fn(q, &self.state_signature(q)))
            .collect()
    }

    /// The parameters and result elements of `q`'s scalar method, as its emitter writes them:
    /// its inputs, then what every state shares in the order the method takes it (a
    /// restitution, the active contacts, Baumgarte gains).
    fn state_signature(&self, q: &Quantity) -> StateSignature {
        let (n, k) = (&self.n, &self.k);
        let params = q
            .inputs
            .iter()
            .zip(Self::state_names(q))
            .map(|(i, name)| Param::State(name, self.input_len(*i).clone()))
            .chain(
                self.shared_values(q)
                    .into_iter()
                    .map(|(x, t)| Param::Shared(x, t)),
            )
            .collect();
        let outputs = match q.eval {
            Evaluation::ContactDynamicsDerivatives { .. }
            | Evaluation::ActiveContacts(ActiveContacts::Derivatives { .. }) => {
                vec![quote!(::eomgen_runtime::ContactDynamicsDerivatives<T, #n, #k>)]
            }
            Evaluation::ImpulseDynamicsDerivatives
            | Evaluation::ActiveContacts(ActiveContacts::ImpulseDerivatives) => {
                vec![quote!(::eomgen_runtime::ImpulseDynamicsDerivatives<T, #n, #k>)]
            }
            _ => self.result_shapes(q).into_iter().map(shape_type).collect(),
        };
        StateSignature { params, outputs }
    }

    /// `NAME_batch`: `q`'s scalar method at every state, one output slice per element of its
    /// result, the shared parameters passed once.
    fn state_batch_fn(&self, q: &Quantity, sig: &StateSignature) -> TokenStream {
        let f = format_ident!("{}_batch", q.name);
        let (path, ops) = (self.path(q.name), self.ops_per_state(q));
        let outs: Vec<Ident> = match sig.outputs.len() {
            1 => vec![format_ident!("out")],
            m => (0..m).map(|i| format_ident!("out_{}", i)).collect(),
        };
        let types = &sig.outputs;
        let decls = sig.params.iter().map(|p| match p {
            Param::Shared(name, ty) => quote!(#name: #ty),
            Param::State(name, len) => quote!(#name: &[[T; #len]]),
        });
        let args = sig.params.iter().map(|p| match p {
            Param::Shared(name, _) => quote!(#name),
            Param::State(name, _) => quote!(&#name[start]),
        });
        let states: Vec<&Ident> = sig
            .params
            .iter()
            .filter_map(|p| match p {
                Param::State(name, _) => Some(name),
                Param::Shared(..) => None,
            })
            .collect();
        let first = &outs[0];
        let checked = states
            .iter()
            .map(|a| a.to_string())
            .zip(&states)
            .map(|(s, a)| quote!((#s, #a.len())));
        let checked = checked.chain(outs[1..].iter().map(|o| {
            let s = o.to_string();
            quote!((#s, #o.len()))
        }));
        let (pattern, passed, store) = if outs.len() == 1 {
            let t = &types[0];
            (
                quote!(#first: &mut [#t]),
                quote!(#first),
                quote!(#first[0] = r;),
            )
        } else {
            let fields = (0..outs.len()).map(usize_lit);
            (
                quote!((#(#outs),*): (#(&mut [#types]),*)),
                quote!((#(#outs),*)),
                quote!(#(#outs[0] = r.#fields;)*),
            )
        };
        let doc = format!(
            " `{}` at every state: `{first}[i]` (or each `out_k[i]` of a tuple) from the inputs' \
             element `i`, the shared arguments the same for all. The scalar method state by \
             state (its code branches on values: no SIMD lanes), over threads with \
             `eomgen_runtime`'s `rayon` feature. An error, with nothing written, when a slice \
             holds another number of states than `{first}`.",
            q.name
        );
        quote! {
            #[doc = #doc]
            pub fn #f(&self, #(#decls,)* #(#outs: &mut [#types]),*) -> ::core::result::Result<(), ::eomgen_runtime::batch::BatchError> {
                ::eomgen_runtime::batch::check(#first.len(), &[#(#checked),*])?;
                ::eomgen_runtime::batch::run_costed(1, #ops, #passed, &|start: usize, #pattern| {
                    let r = #path(self, #(#args),*);
                    #store
                });
                Ok(())
            }
        }
    }
}
