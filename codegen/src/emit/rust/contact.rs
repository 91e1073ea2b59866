//! The methods of contact and impulse dynamics that solve the contact problem's KKT system at
//! run time (`eomgen_runtime::ContactKkt`), each with its `try_` variant; and their `_active`
//! variants, which take the set of active contacts (`active: &[bool; C]`).

use proc_macro2::{Ident, TokenStream};
use quote::{format_ident, quote};

use super::{usize_lit, Emitter};
use crate::cas::{Id, OpCount};
use crate::dynamics::{Quantity, Shape};

/// The `try_` doc of contact forward dynamics with active contacts, around its name.
const ACTIVE_WHY: (&str, &str) = (
    "The accelerations and contact forces of",
    ", or why they do not exist: a pivot of M(q) (`pivot` < N) or of the active rows' `J_c M^-1 J_c^T` (`pivot` - N) that is not positive, or non-finite input.",
);

/// The names and extra argument of a method with or without a set of active contacts.
struct Signature {
    name: Ident,
    try_name: Ident,
    /// `, active: &[bool; C]` or nothing.
    param: TokenStream,
    /// `, active` or nothing.
    arg: TokenStream,
    /// The first line of the `try_` method's documentation.
    why: String,
}

impl Emitter<'_> {
    /// The method `q.name` and its `try_` variant; with `active: &[bool; C]` last when `active`.
    /// The `try_` method's documentation starts with `before`, the name, then `after`.
    fn signature(&self, q: &Quantity, active: bool, (before, after): (&str, &str)) -> Signature {
        let c = usize_lit(self.contact_rows.len());
        let (param, arg) = if active {
            (quote!(, active: &[bool; #c]), quote!(, active))
        } else {
            (TokenStream::new(), TokenStream::new())
        };
        Signature {
            name: format_ident!("{}", q.name),
            try_name: format_ident!("try_{}", q.name),
            param,
            arg,
            why: format!(" {before} `{}`{after}", q.name),
        }
    }

    /// `let kkt = ...;`, a reference to the KKT system at `q` from `mass_matrix` and
    /// `contact_jacobian` (of the contacts of `active` when `active`), returning the error
    /// from the enclosing function when it cannot be factorized (on a vector of states, each
    /// lane's recorded in the enclosing function's `failures`). A non-inlined `contact_kkt`
    /// (or `contact_kkt_active`) returns the system unfactored into the caller's frame, made
    /// by `ContactKkt::unfactored` of the results of `mass_matrix` and `contact_jacobian`,
    /// which are written where they stay; the caller factorizes it there
    /// (`ContactKkt::factor_lanes`). Nothing of it is zeroed first or moved.
    fn kkt(&mut self, active: bool) -> TokenStream {
        let (n, nq, k) = (self.n.clone(), self.nq.clone(), self.k.clone());
        let kkt_ty = quote!(::eomgen_runtime::ContactKkt<T, #n, #k>);
        let (m, j) = (self.call("mass_matrix"), self.call("contact_jacobian"));
        let rows = self.active_rows(active);
        let body = quote! {
            ::eomgen_runtime::ContactKkt::unfactored(#m(self, q), #j(self, q), (&Self::PARENTS, &#rows))
        };
        let (helper, call, item) = if active {
            let c = usize_lit(self.contact_rows.len());
            (
                "contact_kkt_active",
                quote!(self.contact_kkt_active(q, active)),
                quote! {
                    /// The KKT system for the contacts of `active` at `q`, not factorized.
                    #[inline(never)]
                    fn contact_kkt_active(&self, q: &[T; #nq], active: &[bool; #c]) -> #kkt_ty {
                        #body
                    }
                },
            )
        } else {
            (
                "contact_kkt",
                quote!(self.contact_kkt(q)),
                quote! {
                    /// The KKT system for every contact at `q`, not factorized.
                    #[inline(never)]
                    fn contact_kkt(&self, q: &[T; #nq]) -> #kkt_ty {
                        #body
                    }
                },
            )
        };
        if self.helpers.insert(helper) {
            self.blocks.push(item);
        }
        // M factorized by the robot's unrolled L^T D L (`emit/tree_solve.rs`), not by the
        // runtime's loops over the tree.
        quote! {
            let mut kkt = #call;
            kkt.factor_lanes::<Self>(|m, failures| Self::ltdl_factor_unrolled(m, failures), failures)?;
            let kkt = &kkt;
        }
    }

    /// The closure that writes `M`'s factors and `J_c` at `q` into a KKT system's storage
    /// (`ContactKkt::set_up_in_stash_lanes`: `M`'s pivots checked with the failures it is
    /// given), and the contact rows that take part: every one, or those of the contacts of
    /// `active`.
    fn kkt_inputs(&self, active: bool) -> (TokenStream, TokenStream) {
        let (m, j) = (self.call("mass_matrix"), self.call("contact_jacobian"));
        let fill = quote!(|m, j, failures| {
            *m = #m(self, q);
            *j = #j(self, q);
            Self::ltdl_factor_unrolled(m, failures)
        });
        (fill, self.active_rows(active))
    }

    /// The contact rows that take part: every one, or those of the contacts of `active`.
    pub(super) fn active_rows(&self, active: bool) -> TokenStream {
        let k = &self.k;
        if active {
            quote!(::eomgen_runtime::contact::row_mask(
                &Self::CONTACT_ROWS,
                active
            ))
        } else {
            quote!([true; #k])
        }
    }

    /// `h` (`b + G`, and friction) of the `_active` contact methods: its straight-line code is
    /// emitted once, in the private `active_contact_bias(q, qd, tau)` that they all call, and
    /// counted under each method's name. The block calling it, and the operations.
    fn active_bias(&mut self, q: &Quantity, h: &[Id]) -> (TokenStream, OpCount) {
        let call = quote!(Self::active_contact_bias(self, q, qd, tau));
        if let Some(ops) = self.active_bias_ops {
            self.counts.push((q.name.to_string(), ops));
            return (call, ops);
        }
        let (hb, ops) = self.straight(q, h, Shape::Vector(h.len()));
        let (n, nq) = (&self.n, &self.nq);
        self.blocks.push(quote! {
            /// `b + G` (and joint friction) at `(q, qd)`: what the `_active` contact methods
            /// subtract from `tau` (`tau` unused but by split blocks).
            fn active_contact_bias(&self, q: &[T; #nq], qd: &[T; #n], tau: &[T; #n]) -> [T; #n] { #hb }
        });
        self.active_bias_ops = Some(ops);
        (call, ops)
    }

    /// `contact_forward_dynamics_stabilized`, which takes an `eomgen_runtime::Baumgarte` after
    /// `active`, for every `T: Lane` as `contact_forward_dynamics_active`, with the drift
    /// corrected first.
    pub(super) fn contact_stabilized_fns(&mut self, q: &Quantity, h: &[Id]) -> TokenStream {
        self.contact_active_lanes_fns(q, h, true)
    }

    /// `contact_forward_dynamics_active` for every `T: Lane` where its callees are (one state
    /// per lane; `active` every lane's): `contact_forward_dynamics_active_checked` records
    /// each lane's failed pivot or non-finite result
    /// (`eomgen_runtime::contact::solve_factored_active_lanes`), `try_` gives the lowest
    /// failed lane's error, `try_contact_forward_dynamics_active_lanes` says which lane, and
    /// the plain method gives NaN in the failed lanes alone.
    pub(super) fn contact_active_checked_fns(&mut self, q: &Quantity, h: &[Id]) -> TokenStream {
        self.contact_active_lanes_fns(q, h, false)
    }

    /// Contact forward dynamics with active contacts, Baumgarte-stabilized when `stabilized`
    /// (an `eomgen_runtime::Baumgarte` after `active`, which corrects the drift).
    fn contact_active_lanes_fns(
        &mut self,
        q: &Quantity,
        h: &[Id],
        stabilized: bool,
    ) -> TokenStream {
        let (hb, ops) = self.active_bias(q, h);
        let docs = Self::quantity_doc(q, Some(ops));
        let (n, nq) = (&self.n, &self.nq);
        let c = usize_lit(self.contact_rows.len());
        let why = self.signature(q, true, ACTIVE_WHY).why;
        let why = format!("{why} On a vector of states, the lowest failed lane's error.");
        let free = self.free_accelerations_recording(&hb, quote!(&mut failures));
        let (j, drift) = (self.call("contact_jacobian"), self.call("contact_drift"));
        let (gains, gains_arg, correct) = if stabilized {
            let placements = self.call("contact_placements");
            (
                quote!(, baumgarte: &::eomgen_runtime::Baumgarte<T, #c>),
                quote!(, baumgarte),
                quote!(baumgarte.correct_drift(&Self::CONTACT_ROWS, &#placements(self, q), &j, qd, &mut drift);),
            )
        } else {
            Default::default()
        };
        let drift_let = if stabilized {
            quote!(let mut drift)
        } else {
            quote!(let drift)
        };
        let params = quote!(q: &[T; #nq], qd: &[T; #n], tau: &[T; #n], active: &[bool; #c] #gains);
        let solve = self.contact_solve_lanes(self.active_rows(true));
        let body = quote! {
            #free
            let j = #j(self, q);
            #drift_let = #drift(self, q, qd);
            #correct
            #solve
        };
        let args = quote!(q, qd, tau, active #gains_arg);
        let what = "accelerations and forces";
        self.lane_checked_fns(q.name, (params, args), (why, what, docs), body)
    }

    /// The statements that solve every lane's contact problem with `m` (`M`'s factors), `free`,
    /// `j` and `drift` in scope, the contact rows `rows` taking part
    /// (`eomgen_runtime::contact::solve_factored_active_lanes`), ending in
    /// `Ok((result, failures))`: what contact forward dynamics solved at run time and its
    /// `_active` and `_stabilized` forms share.
    pub(super) fn contact_solve_lanes(&self, rows: TokenStream) -> TokenStream {
        let (n, k) = (&self.n, &self.k);
        quote! {
            let rows = #rows;
            let substitute = |b: &[T; #n]| Self::ltdl_substitute_unrolled(&m, b);
            let lower = |w: &mut [[T; #k]; #n]| Self::ltdl_lower_rows_unrolled(&m, w);
            let system = (&j, &drift, &rows);
            let x = ::eomgen_runtime::contact::solve_factored_active_lanes(&m, &free, system, substitute, lower, &mut failures)?;
            Ok((x, failures))
        }
    }

    /// `try_contact_forward_dynamics_derivatives` and `contact_forward_dynamics_derivatives`
    /// (NaN on failure), or their `_active` variants.
    pub(super) fn contact_dynamics_derivatives_fns(
        &mut self,
        q: &Quantity,
        h: &[Id],
        active: bool,
    ) -> TokenStream {
        let (hb, ops) = if active {
            self.active_bias(q, h)
        } else {
            self.straight(q, h, Shape::Vector(h.len()))
        };
        let docs = Self::quantity_doc(q, Some(ops));
        let (n, nq, k) = (self.n.clone(), self.nq.clone(), self.k.clone());
        let s = self.signature(q, active, ("The derivatives of", ", or why they do not"));
        let (name, param) = (&s.name, &s.param);
        let (fill, rows) = self.kkt_inputs(active);
        let drift = self.call("contact_drift");
        let id_derivatives = self.id_derivatives_into(quote!(d.da_dq), quote!(d.da_dv), quote!(a));
        // The partials' blocks add their rows in `q` onto `d.da_dq` (the inverse-dynamics
        // derivatives) and write their contact rows straight into `d` (a body that its callers
        // fill is always written in blocks: `methods.rs`, `FILLED`).
        debug_assert!(self.split.contains("contact_dynamics_partials"));
        let partials = crate::emit::split::fill_name("contact_dynamics_partials");
        let ty = quote!(::eomgen_runtime::ContactDynamicsDerivatives<T, #n, #k>);
        let [into, solve, stage] =
            ["into", "solve", "partials"].map(|s| format_ident!("{}_{}", name, s));
        let stash = quote!(::eomgen_runtime::KktStash<T, #n, #k>);
        let err = quote!(::eomgen_runtime::FactorError);
        let failures = quote!(<T as ::eomgen_runtime::Lane>::Failures);
        // The KKT system's arrays lie in `d` (`ContactKkt::set_up_in`) until their last use,
        // never in a frame that the inverse-dynamics derivatives or the partials run below.
        self.blocks.push(quote! {
            /// The derivatives written into `d` (which holds garbage on failure).
            fn #into(&self, q: &[T; #nq], qd: &[T; #n], tau: &[T; #n] #param, d: &mut #ty, failures: &mut #failures) -> ::core::result::Result<(), #err> {
                let h: [T; #n] = { #hb };
                let mut rhs = *tau;
                for (r, h) in rhs.iter_mut().zip(h) {
                    *r -= h;
                }
                let drift = #drift(self, q, qd);
                let mut stash = <#stash>::new(&Self::PARENTS, &#rows);
                let (a, f) = self.#solve(q, &rhs, &drift, d, &mut stash, failures)?;
                #id_derivatives
                self.#stage(q, qd, &a, &f, d)?;
                stash.contact_dynamics_derivatives_lanes::<Self>(d, failures)
            }

            /// The accelerations and forces, with the KKT system set up in `d` and `stash`.
            #[inline(never)]
            fn #solve(&self, q: &[T; #nq], rhs: &[T; #n], drift: &[T; #k], d: &mut #ty, stash: &mut #stash, failures: &mut #failures) -> ::core::result::Result<([T; #n], [T; #k]), #err> {
                ::eomgen_runtime::ContactKkt::set_up_in_stash_lanes::<Self>(d, stash, #fill, failures)?;
                let substitute = |b: &[T; #n]| Self::ltdl_substitute_unrolled(&d.da_dtau, b);
                stash.solve_with_lanes(d, (rhs, &drift.map(|x| -x)), substitute, failures)
            }

            /// The partials added to `d` in a frame of their own.
            #[inline(never)]
            fn #stage(&self, q: &[T; #nq], qd: &[T; #n], a: &[T; #n], f: &[T; #k], d: &mut #ty) -> ::core::result::Result<(), #err> {
                self.#partials(q, qd, a, f, &mut d.da_dq, &mut d.df_dq, &mut d.df_dv);
                Ok(())
            }
        });
        let params = [
            ("q", quote!(&[T; #nq])),
            ("qd", quote!(&[T; #n])),
            ("tau", quote!(&[T; #n])),
        ];
        let why_more = " exist: a pivot of M(q) (`pivot` < N) or of `J_c M^-1 J_c^T` (`pivot` - N, a rank-deficient contact Jacobian) that is not positive, or a non-finite result.";
        self.derivative_fns(&s, (&into, &ty), &params, (docs, why_more))
    }

    /// `{name}_in_slot` (not `_in_place`: a split body of `name` has that one), for the
    /// inherent impl, which fills the caller's storage for the result of `into` (a fallible
    /// `fn(&self, params..., extra, d: &mut ty, failures)`) through `eomgen_runtime::place`:
    /// NaN, and the error in `err`, on failure (on a vector of states, in the failed lanes, and
    /// the lowest one's error). `params` are `(name, type)`. Returns the `try_` method (the
    /// lowest failed lane's error), `try_{name}_lanes` (which lane) and the plain one (NaN),
    /// `why` and `why_more` starting the `try_` method's documentation.
    fn derivative_fns(
        &mut self,
        s: &Signature,
        (into, ty): (&Ident, &TokenStream),
        params: &[(&str, TokenStream)],
        (docs, why_more): (TokenStream, &str),
    ) -> TokenStream {
        let (name, try_name, param, arg, why) = (&s.name, &s.try_name, &s.param, &s.arg, &s.why);
        let in_place = format_ident!("{}_in_slot", name);
        let try_lanes = format_ident!("{}_lanes", try_name);
        let args: Vec<Ident> = params.iter().map(|(n, _)| format_ident!("{}", n)).collect();
        let decls: Vec<TokenStream> = params
            .iter()
            .zip(&args)
            .map(|((_, t), a)| quote!(#a: #t))
            .collect();
        let lane_err = quote!(::eomgen_runtime::LaneError);
        self.blocks.push(quote! {
            #[inline(never)]
            fn #in_place<'b>(&self, #(#decls,)* err: &mut ::core::option::Option<#lane_err> #param, slot: ::eomgen_runtime::place::Slot<'b, #ty>) -> ::eomgen_runtime::place::Filled<'b> {
                let (d, filled) = slot.fill();
                let mut failures = ::core::default::Default::default();
                match self.#into(#(#args),* #arg, d, &mut failures) {
                    Err(error) => {
                        d.fill_nan();
                        *err = Some(#lane_err { lane: 0, error });
                    }
                    Ok(()) => {
                        d.nan_failed(&failures);
                        *err = <T as ::eomgen_runtime::Lane>::first_failure(&failures);
                    }
                }
                filled
            }
        });
        let build = |err: TokenStream| quote!(::eomgen_runtime::place::build(|slot| self.#in_place(#(#args,)* #err #arg, slot)));
        let (with_err, without) = (build(quote!(&mut err)), build(quote!(&mut None)));
        let lanes_doc = format!(" `{try_name}` on a vector of states (`eomgen_runtime::Lane`, one state per lane; a scalar is lane 0): the derivatives of every lane, or the lowest lane that failed, with that lane's own error.");
        quote! {
            #[doc = #why]
            #[doc = #why_more]
            /// On a vector of states, the lowest failed lane's error.
            pub fn #try_name(&self, #(#decls),* #param) -> ::core::result::Result<#ty, ::eomgen_runtime::FactorError> {
                self.#try_lanes(#(#args),* #arg).map_err(|e| e.error)
            }

            #[doc = #lanes_doc]
            pub fn #try_lanes(&self, #(#decls),* #param) -> ::core::result::Result<#ty, #lane_err> {
                let mut err = None;
                let d = #with_err;
                match err {
                    None => Ok(d),
                    Some(e) => Err(e),
                }
            }

            #docs
            pub fn #name(&self, #(#decls),* #param) -> #ty {
                #without
            }
        }
    }

    /// `try_impulse_dynamics` and `impulse_dynamics` solved at run time, for every `T: Lane`
    /// as their `_active` variants ([`Emitter::impulse_active_checked_fns`]), every row
    /// active.
    pub(super) fn impulse_dynamics_fns(&mut self, q: &Quantity) -> TokenStream {
        self.impulse_checked_fns(q, false)
    }

    /// `impulse_dynamics_active` for every `T: Lane` where its callees are, as
    /// `contact_forward_dynamics_active` (`Emitter::contact_active_checked_fns`): its
    /// `_checked` method records each lane's failure
    /// (`eomgen_runtime::impulse::solve_factored_active_lanes`).
    pub(super) fn impulse_active_checked_fns(&mut self, q: &Quantity) -> TokenStream {
        self.impulse_checked_fns(q, true)
    }

    /// Impulse dynamics solved at run time with every contact, or with those of `active`.
    fn impulse_checked_fns(&mut self, q: &Quantity, active: bool) -> TokenStream {
        let docs = Self::quantity_doc(q, None);
        let (n, nq, k) = (&self.n, &self.nq, &self.k);
        let (m, j) = (self.call("mass_matrix"), self.call("contact_jacobian"));
        let s = self.signature(q, active, (" ", ""));
        let (param, arg) = (&s.param, &s.arg);
        let params = quote!(q: &[T; #nq], qd: &[T; #n], restitution: T #param);
        let which = if active { "the active rows' " } else { "" };
        let why = format!(
            " The velocity after the impact and the impulses of `{}`, or why they do not exist: \
             a pivot of M(q) (`pivot` < N) or of {which}`J_c M^-1 J_c^T` (`pivot` - \
             N) that is not positive, or a non-finite result. On a vector of states, the lowest \
             failed lane's error.",
            q.name
        );
        let rows = self.active_rows(active);
        let body = quote! {
            // M's factors and J_c, no KKT system: M^-1 meets the one vector J_c^T p.
            let mut m = #m(self, q);
            let j = #j(self, q);
            Self::ltdl_factor_unrolled(&mut m, &mut failures)?;
            let substitute = |b: &[T; #n]| Self::ltdl_substitute_unrolled(&m, b);
            let lower = |w: &mut [[T; #k]; #n]| Self::ltdl_lower_rows_unrolled(&m, w);
            let rows = #rows;
            let x = ::eomgen_runtime::impulse::solve_factored_active_lanes(&m, (&j, &rows), (qd, restitution), substitute, lower, &mut failures)?;
            Ok((x, failures))
        };
        let args = quote!(q, qd, restitution #arg);
        let what = "velocity and impulses";
        self.lane_checked_fns(q.name, (params, args), (why, what, docs), body)
    }

    /// `try_impulse_dynamics` and `impulse_dynamics` from one straight-line program at
    /// restitution zero (`Evaluation::ImpulseDynamicsFlat`), scaled by `1 + e`, generated for
    /// every `T: Lane` as contact forward dynamics' (`impulse_dynamics_checked` records each
    /// lane's failure; `impulse_dynamics` gives NaN in the failed lanes alone).
    pub(super) fn impulse_flat_fns(
        &mut self,
        q: &Quantity,
        outputs: &[Id],
        pivots: &[Id],
    ) -> TokenStream {
        let flat = self.flat_program(q, outputs, pivots);
        let (program, piv, dv, p) = (&flat.program, &flat.pivots, &flat.first, &flat.rows);
        let (n, nq, k) = (self.n.clone(), self.nq.clone(), self.k.clone());
        let (docs, lane) = (
            Self::quantity_doc(q, Some(flat.ops)),
            quote!(::eomgen_runtime::lane),
        );
        let failures = quote!(<T as ::eomgen_runtime::Lane>::Failures);
        let params = quote!(q: &[T; #nq], qd: &[T; #n], restitution: T);
        let args = quote!(q, qd, restitution);
        let wrappers = self.lane_pair_fns("impulse_dynamics", params, args, docs);
        quote! {
            /// The velocity after the impact and the impulses of `impulse_dynamics`, or why
            /// they do not exist: a pivot of M(q) (`pivot` < N) or of `J_c M^-1 J_c^T`
            /// (`pivot` - N, a rank-deficient contact Jacobian) that is not positive, or a
            /// non-finite result. On a vector of states, the lowest failed lane's error.
            pub fn try_impulse_dynamics(&self, q: &[T; #nq], qd: &[T; #n], restitution: T) -> ::core::result::Result<([T; #n], [T; #k]), ::eomgen_runtime::FactorError> {
                let (x, failures) = self.impulse_dynamics_checked(q, qd, restitution)?;
                #lane::lanes_ok::<_, T>(x, &failures).map_err(|e| e.error)
            }

            /// The velocity and impulses, and each lane's failure (a scalar returns its first
            /// at once).
            fn impulse_dynamics_checked(&self, q: &[T; #nq], qd: &[T; #n], restitution: T) -> ::core::result::Result<(([T; #n], [T; #k]), #failures), ::eomgen_runtime::FactorError> {
                let mut failures: #failures = ::core::default::Default::default();
                #program
                #lane::check_pivots(&[#(#piv),*], &mut failures)?;
                let s = T::one() + restitution;
                let jump = [#(s * #dv,)* #(s * #p),*];
                #lane::check_finite(&jump, &mut failures)?;
                let after: [T; #n] = ::core::array::from_fn(|i| qd[i] + jump[i]);
                let p: [T; #k] = ::core::array::from_fn(|i| jump[#n + i]);
                Ok(((after, p), failures))
            }

            #wrappers
        }
    }

    /// `try_impulse_dynamics_derivatives` and `impulse_dynamics_derivatives` (NaN on
    /// failure), or their `_active` variants.
    pub(super) fn impulse_dynamics_derivatives_fns(
        &mut self,
        q: &Quantity,
        active: bool,
    ) -> TokenStream {
        let docs = Self::quantity_doc(q, None);
        let (n, nq, k) = (self.n.clone(), self.nq.clone(), self.k.clone());
        let kkt = self.kkt(active);
        let s = self.signature(
            q,
            active,
            ("The derivatives of", ", or why they do not exist (as"),
        );
        let (name, param) = (&s.name, &s.param);
        let ty = quote!(::eomgen_runtime::ImpulseDynamicsDerivatives<T, #n, #k>);
        // The partials' blocks write their two row groups straight into `d` (a body that its
        // callers fill is always written in blocks: `methods.rs`, `FILLED`).
        debug_assert!(self.split.contains("impulse_dynamics_partials"));
        let fill = crate::emit::split::fill_name("impulse_dynamics_partials");
        let set_partials = quote! {
            self.#fill(q, w, jump, p, &mut d.dv_dq, &mut d.dimpulse_dq);
            Ok(())
        };
        let (into, stage) = (
            format_ident!("{}_into", name),
            format_ident!("{}_partials", name),
        );
        self.blocks.push(quote! {
            /// The derivatives written into `d` (which holds garbage on failure).
            fn #into(&self, q: &[T; #nq], qd: &[T; #n], restitution: T #param, d: &mut #ty, failures: &mut <T as ::eomgen_runtime::Lane>::Failures) -> ::core::result::Result<(), ::eomgen_runtime::FactorError> {
                #kkt
                let (after, p) = kkt.impulse_lanes(qd, restitution, failures)?;
                let jump: [T; #n] = ::core::array::from_fn(|i| after[i] - qd[i]);
                let w: [T; #n] = ::core::array::from_fn(|i| after[i] + restitution * qd[i]);
                self.#stage(q, &w, &jump, &p, d)?;
                kkt.impulse_derivatives_lanes::<Self>(restitution, d, failures)
            }

            /// The partials set in `d` in a frame of their own.
            #[inline(never)]
            fn #stage(&self, q: &[T; #nq], w: &[T; #n], jump: &[T; #n], p: &[T; #k], d: &mut #ty) -> ::core::result::Result<(), ::eomgen_runtime::FactorError> {
                #set_partials
            }
        });
        let params = [
            ("q", quote!(&[T; #nq])),
            ("qd", quote!(&[T; #n])),
            ("restitution", quote!(T)),
        ];
        let why_more = " `try_impulse_dynamics`).";
        self.derivative_fns(&s, (&into, &ty), &params, (docs, why_more))
    }
}
