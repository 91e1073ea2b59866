//! The items of an underactuated robot ([`crate::Builder::passive_joints`]): the actuated
//! joints, the selection matrix `S` (`NA x N`) and forward dynamics from the actuated efforts
//! alone, `qdd = FD(q, qd, S^T tau_a)`, composed from the generated `forward_dynamics`.

use proc_macro2::{Literal, TokenStream};
use quote::quote;

use super::rust::usize_lit;
use crate::model::Model;

/// The associated items, empty when every joint is actuated. `forward_dynamics` is the path
/// that calls the generated forward dynamics, `None` when it is not generated.
pub fn items(model: &Model, forward_dynamics: Option<TokenStream>) -> TokenStream {
    if model.passive.is_empty() {
        return TokenStream::new();
    }
    let n = usize_lit(model.joints.len());
    let actuated = model.actuated();
    let na = usize_lit(actuated.len());
    let np = usize_lit(model.passive.len());
    let names = actuated
        .iter()
        .map(|&i| Literal::string(&model.joints[i].name));
    let indices = actuated.iter().map(|&i| usize_lit(i));
    let passive = model.passive.iter().map(|&i| usize_lit(i));
    let passive_names: Vec<String> = model
        .passive
        .iter()
        .map(|&i| format!("`{}`", model.joints[i].name.replace('`', "'")))
        .collect();
    let passive_doc = format!(
        " The passive joints ({}), as indices into the joint arrays, ascending.",
        passive_names.join(", ")
    );
    let rows = actuated.iter().map(|&a| {
        let row = (0..model.joints.len()).map(|j| {
            if j == a {
                quote!(T::one())
            } else {
                quote!(T::zero())
            }
        });
        quote!([#(#row),*])
    });
    // S^T tau_a: each joint's effort, the actuated joint's own or zero.
    let full = (0..model.joints.len()).map(|j| match actuated.iter().position(|&a| a == j) {
        Some(k) => {
            let k = usize_lit(k);
            quote!(tau_a[#k])
        }
        None => quote!(T::zero()),
    });
    let fd = forward_dynamics.map(|call| {
        quote! {
            /// Forward dynamics of the underactuated robot, `qdd = M(q)^-1 (S^T tau_a - b - G)`,
            /// from the efforts of the actuated joints alone (in the order of
            /// `ACTUATED_JOINT_NAMES`); the passive joints get no effort.
            ///
            /// Route: `forward_dynamics` at `full_effort(tau_a)`.
            pub fn forward_dynamics_actuated(&self, q: &[T; #n], qd: &[T; #n], tau_a: &[T; #na]) -> [T; #n] {
                #call(self, q, qd, &Self::full_effort(tau_a))
            }
        }
    });
    quote! {
        /// Number of actuated joints: the rows of `selection()`.
        pub const NA: usize = #na;
        /// The URDF names of the actuated joints, in the order of `tau_a` (the joint order
        /// without the passive joints).
        pub const ACTUATED_JOINT_NAMES: [&'static str; #na] = [#(#names),*];
        /// The actuated joints, as indices into the joint arrays, ascending.
        pub const ACTUATED_JOINTS: [usize; #na] = [#(#indices),*];
        #[doc = #passive_doc]
        pub const PASSIVE_JOINTS: [usize; #np] = [#(#passive),*];
        /// The selection matrix `S`, `NA x N`: row `k` is the unit row of the `k`-th actuated
        /// joint, so that the equation of motion is `M qdd + b + G = S^T tau_a` and `S^T tau_a`
        /// is zero on every passive joint.
        pub fn selection() -> [[T; #n]; #na] {
            [#(#rows),*]
        }
        /// The full joint effort `S^T tau_a` of the actuated efforts `tau_a`: zero on every
        /// passive joint.
        pub fn full_effort(tau_a: &[T; #na]) -> [T; #n] {
            [#(#full),*]
        }
        #fd
    }
}
