//! Which generated methods run on vectors of states (`eomgen_runtime::Lane`): those whose
//! code is arithmetic, pivot checks and the runtime kernels that take a `Lane`, and whose
//! callees do too (contact forward dynamics and impulse dynamics when each is one straight-line
//! program, and then contact forward dynamics and impulse dynamics with active contacts, whose
//! runtime solves take a `Lane`; link kinematics, whose runtime kernels walk chains of poses;
//! the configuration manifold, whose kernels select each lane's case; the contact and impulse
//! derivatives, whose KKT solves take a `Lane`; contact and impulse dynamics solved at run
//! time, as their `_active` forms, and the stabilized form). They live in the `impl<T: Lane>`
//! blocks.

use std::collections::BTreeSet;

use super::traits::Trait;
use super::Emitter;
use crate::dynamics::{ActiveContacts, Evaluation, Quantity};

/// Whether a quantity's own evaluation runs on lanes (its callees aside).
fn evaluation_on_lanes(q: &Quantity) -> bool {
    matches!(
        q.eval,
        Evaluation::Exprs(_)
            | Evaluation::CraigColumns(_)
            | Evaluation::ForwardDynamics { .. }
            | Evaluation::ForwardDynamicsSolve { .. }
            | Evaluation::MassMatrixInverse
            | Evaluation::Factored { .. }
            | Evaluation::ForwardDynamicsDerivatives { .. }
            | Evaluation::Integrate
            | Evaluation::Manifold(_)
            | Evaluation::ContactForwardDynamics { .. }
            | Evaluation::ContactForwardDynamicsFlat { .. }
            | Evaluation::ImpulseDynamics
            | Evaluation::ImpulseDynamicsFlat { .. }
            | Evaluation::LinkPose
            | Evaluation::LinkJacobian
            | Evaluation::FrameMotion(_)
            | Evaluation::ContactDynamicsDerivatives { .. }
            | Evaluation::ImpulseDynamicsDerivatives
            | Evaluation::ActiveContacts(
                ActiveContacts::Dynamics { .. }
                    | ActiveContacts::Stabilized { .. }
                    | ActiveContacts::Impulse
                    | ActiveContacts::Derivatives { .. }
                    | ActiveContacts::ImpulseDerivatives
            )
    )
}

impl Emitter<'_> {
    /// The quantities generated for every `T: Lane`: those whose evaluation runs on lanes,
    /// whose callees are such quantities, and whose trait (if any) holds only such quantities
    /// (an impl has one bound for all its methods).
    pub(super) fn lane_quantities(&self) -> BTreeSet<&'static str> {
        let mut on: BTreeSet<&'static str> = self
            .quantities
            .iter()
            .filter(|q| evaluation_on_lanes(q))
            .map(|q| q.name)
            .collect();
        loop {
            let off: Vec<&'static str> = self
                .quantities
                .iter()
                .filter(|q| on.contains(q.name))
                .filter(|q| {
                    let callees = q.needs().iter().all(|n| on.contains(n));
                    let home = self.trait_of(q.name);
                    let trait_on = home.is_none_or(|t| self.trait_on_lanes(t, &on));
                    !(callees && trait_on)
                })
                .map(|q| q.name)
                .collect();
            if off.is_empty() {
                return on;
            }
            for name in off {
                on.remove(name);
            }
        }
    }

    /// Whether every method of trait `t` is in `on`.
    fn trait_on_lanes(&self, t: Trait, on: &BTreeSet<&'static str>) -> bool {
        let members = self.quantities.iter().filter(|q| {
            self.trait_of(q.name) == Some(t)
                || (t == Trait::Contacts && self.trait_of(&format!("try_{}", q.name)) == Some(t))
        });
        members.into_iter().all(|q| on.contains(q.name))
    }

    /// The bound of an impl holding methods on lanes or not.
    pub(super) fn bound(lanes: bool) -> proc_macro2::TokenStream {
        if lanes {
            quote::quote!(::eomgen_runtime::Lane)
        } else {
            quote::quote!(::eomgen_runtime::Real)
        }
    }

    /// Whether trait `t`'s impl is generated for every `T: Lane`.
    pub(super) fn trait_lanes(&self, t: Trait) -> bool {
        self.trait_on_lanes(t, &self.lanes)
    }
}
