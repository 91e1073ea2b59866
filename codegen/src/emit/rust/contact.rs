//! The methods of contact and impulse dynamics that solve the contact problem's KKT system at
//! run time (`eomgen_runtime::ContactKkt`), each with its `try_` variant.

use proc_macro2::TokenStream;
use quote::quote;

use super::Emitter;
use crate::cas::Id;
use crate::dynamics::{Quantity, Shape};

impl Emitter<'_> {
    /// `let kkt = ...?;`: the KKT system at `q` from `mass_matrix` and `contact_jacobian`.
    fn kkt(&self) -> TokenStream {
        let (m, j) = (self.call("mass_matrix"), self.call("contact_jacobian"));
        quote! {
            let kkt = ::eomgen_runtime::ContactKkt::new(#m(self, q), &Self::PARENTS, #j(self, q))?;
        }
    }

    /// `try_contact_forward_dynamics_derivatives` and `contact_forward_dynamics_derivatives`
    /// (NaN on failure).
    pub(super) fn contact_dynamics_derivatives_fns(
        &mut self,
        q: &Quantity,
        h: &[Id],
    ) -> TokenStream {
        let (hb, ops) = self.straight(q, h, Shape::Vector(h.len()));
        let docs = Self::quantity_doc(q, Some(ops));
        let (n, nq, k) = (&self.n, &self.nq, &self.k);
        let kkt = self.kkt();
        let drift = self.call("contact_drift");
        let idd = self.call("inverse_dynamics_derivatives");
        let partials = self.call("contact_dynamics_partials");
        quote! {
            /// The derivatives of `contact_forward_dynamics_derivatives`, or why they do not
            /// exist: a pivot of M(q) (`pivot` < N) or of `J_c M^-1 J_c^T` (`pivot` - N, a
            /// rank-deficient contact Jacobian) that is not positive, or a non-finite result.
            pub fn try_contact_forward_dynamics_derivatives(&self, q: &[T; #nq], qd: &[T; #n], tau: &[T; #n]) -> ::core::result::Result<::eomgen_runtime::ContactDynamicsDerivatives<T, #n, #k>, ::eomgen_runtime::FactorError> {
                let h: [T; #n] = { #hb };
                let mut rhs = *tau;
                for (r, h) in rhs.iter_mut().zip(h) {
                    *r -= h;
                }
                let drift = #drift(self, q, qd);
                #kkt
                let (a, f) = kkt.solve(&rhs, &drift.map(|x| -x))?;
                let (did_dq, did_dv) = #idd(self, q, qd, &a);
                kkt.contact_dynamics_derivatives(&did_dq, &did_dv, &#partials(self, q, qd, &a, &f))
            }

            #docs
            pub fn contact_forward_dynamics_derivatives(&self, q: &[T; #nq], qd: &[T; #n], tau: &[T; #n]) -> ::eomgen_runtime::ContactDynamicsDerivatives<T, #n, #k> {
                self.try_contact_forward_dynamics_derivatives(q, qd, tau)
                    .unwrap_or_else(|_| ::eomgen_runtime::ContactDynamicsDerivatives::nan())
            }
        }
    }

    /// `try_impulse_dynamics` and `impulse_dynamics` (NaN on failure).
    pub(super) fn impulse_dynamics_fns(&mut self, q: &Quantity) -> TokenStream {
        let docs = Self::quantity_doc(q, None);
        let (n, nq, k) = (&self.n, &self.nq, &self.k);
        let kkt = self.kkt();
        quote! {
            /// The velocity after the impact and the impulses of `impulse_dynamics`, or why
            /// they do not exist: a pivot of M(q) (`pivot` < N) or of `J_c M^-1 J_c^T`
            /// (`pivot` - N, a rank-deficient contact Jacobian) that is not positive, or a
            /// non-finite result.
            pub fn try_impulse_dynamics(&self, q: &[T; #nq], qd: &[T; #n], restitution: T) -> ::core::result::Result<([T; #n], [T; #k]), ::eomgen_runtime::FactorError> {
                #kkt
                kkt.impulse(qd, restitution)
            }

            #docs
            pub fn impulse_dynamics(&self, q: &[T; #nq], qd: &[T; #n], restitution: T) -> ([T; #n], [T; #k]) {
                match self.try_impulse_dynamics(q, qd, restitution) {
                    Ok(x) => x,
                    Err(_) => ([T::nan(); #n], [T::nan(); #k]),
                }
            }
        }
    }

    /// `try_impulse_dynamics_derivatives` and `impulse_dynamics_derivatives` (NaN on failure).
    pub(super) fn impulse_dynamics_derivatives_fns(&mut self, q: &Quantity) -> TokenStream {
        let docs = Self::quantity_doc(q, None);
        let (n, nq, k) = (&self.n, &self.nq, &self.k);
        let kkt = self.kkt();
        let partials = self.call("impulse_dynamics_partials");
        quote! {
            /// The derivatives of `impulse_dynamics_derivatives`, or why they do not exist (as
            /// `try_impulse_dynamics`).
            pub fn try_impulse_dynamics_derivatives(&self, q: &[T; #nq], qd: &[T; #n], restitution: T) -> ::core::result::Result<::eomgen_runtime::ImpulseDynamicsDerivatives<T, #n, #k>, ::eomgen_runtime::FactorError> {
                #kkt
                let (after, p) = kkt.impulse(qd, restitution)?;
                let jump: [T; #n] = ::core::array::from_fn(|i| after[i] - qd[i]);
                let w: [T; #n] = ::core::array::from_fn(|i| after[i] + restitution * qd[i]);
                kkt.impulse_derivatives(restitution, &#partials(self, q, &w, &jump, &p))
            }

            #docs
            pub fn impulse_dynamics_derivatives(&self, q: &[T; #nq], qd: &[T; #n], restitution: T) -> ::eomgen_runtime::ImpulseDynamicsDerivatives<T, #n, #k> {
                self.try_impulse_dynamics_derivatives(q, qd, restitution)
                    .unwrap_or_else(|_| ::eomgen_runtime::ImpulseDynamicsDerivatives::nan())
            }
        }
    }
}
