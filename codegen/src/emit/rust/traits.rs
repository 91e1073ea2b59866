//! Which runtime trait holds each generated method (`Dynamics`, `FloatingDynamics`,
//! `Contacts`, or none: inherent), the path that calls a method from inside the impls, and
//! the trait implementations.

use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};

use super::{allow_lints, Emitter};
use crate::dynamics::{Evaluation, Home};

/// The runtime trait whose impl holds a generated method.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Trait {
    /// `Dynamics` (fixed base).
    Dynamics,
    /// `FloatingDynamics`.
    Floating,
    /// `Contacts` (floating base).
    Contacts,
}

impl Emitter<'_> {
    /// The runtime trait whose impl holds the generated method `name`, if any (else it is
    /// inherent).
    /// The catalogue says it ([`Home`]); of contact forward dynamics, `Contacts` holds the
    /// `try_` method (`try_contact_forward_dynamics`), and the method itself is inherent.
    pub(super) fn trait_of(&self, name: &str) -> Option<Trait> {
        let (quantity, try_) = match name.strip_prefix("try_") {
            Some(n) => (n, true),
            None => (name, false),
        };
        let q = self.quantities.iter().find(|q| q.name == quantity)?;
        let solved = matches!(
            q.eval,
            Evaluation::ContactForwardDynamics { .. }
                | Evaluation::ContactForwardDynamicsFlat { .. }
        );
        if solved != try_ {
            return None;
        }
        match q.home {
            Home::Dynamics => Some(Trait::Dynamics),
            Home::FloatingDynamics => Some(Trait::Floating),
            Home::Contacts => Some(Trait::Contacts),
            Home::Inherent => None,
        }
    }

    /// `pub` in the inherent impl; nothing in a trait's.
    pub(super) fn vis(&self, name: &str) -> TokenStream {
        if self.trait_of(name).is_some() {
            TokenStream::new()
        } else {
            quote!(pub)
        }
    }

    pub(super) fn has(&self, name: &str) -> bool {
        self.quantities.iter().any(|q| q.name == name)
    }

    /// The path that calls the generated function `name` from inside the impls: through the
    /// trait when it is a trait method there. Every generated function that calls another does
    /// so through here, and the callee is one of its `Quantity::needs`, so that a selection
    /// (`catalogue::select`) brings it.
    pub(super) fn call(&self, name: &str) -> TokenStream {
        debug_assert!(self.has(name), "`{name}` is called but not generated");
        self.path(name)
    }

    /// The path of the generated method `name` (see [`Self::call`]).
    pub(super) fn path(&self, name: &str) -> TokenStream {
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

    /// `impl Dynamics` with its methods, when every one of them is generated: for every
    /// `T: Lane` when they all run on lanes.
    pub(super) fn trait_impl(&self, methods: &[TokenStream]) -> TokenStream {
        if !self.in_trait {
            return TokenStream::new();
        }
        let names = self
            .model
            .velocity_names()
            .into_iter()
            .map(|name| Literal::string(&name));
        let (ty, n, allow) = (&self.ty, &self.n, allow_lints());
        quote! {
            #allow
            impl<T: ::eomgen_runtime::Lane> ::eomgen_runtime::Dynamics<T, #n> for #ty<T> {
                const JOINT_NAMES: [&'static str; #n] = [#(#names),*];
                #(#methods)*
            }
        }
    }

    /// A floating-base robot's `FloatingDynamics` implementation (when its methods are all
    /// generated) and `Contacts` (with contact points and `contact_forward_dynamics`), holding
    /// those methods.
    pub(super) fn floating_impls(
        &self,
        floating: &[TokenStream],
        contacts: &[TokenStream],
    ) -> TokenStream {
        if !self.floating {
            return TokenStream::new();
        }
        let (ty, n, nq, allow) = (&self.ty, &self.n, &self.nq, allow_lints());
        let mut out = TokenStream::new();
        if self.floating_trait {
            out.extend(quote! {
                #allow
                impl<T: ::eomgen_runtime::Lane> ::eomgen_runtime::FloatingDynamics<T, #nq, #n> for #ty<T> {
                    #(#floating)*
                }
            });
        }
        if let Some(k3) = &self.contacts_trait {
            out.extend(quote! {
                #allow
                impl<T: ::eomgen_runtime::Lane> ::eomgen_runtime::Contacts<T, #nq, #n, #k3> for #ty<T> {
                    #(#contacts)*
                }
            });
        }
        out
    }
}
