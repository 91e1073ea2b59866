//! The methods that solve with `M(q)`: forward dynamics (unrolled, or the tree `L^T D L` at
//! run time), `M^-1`, the forward-dynamics derivatives and contact forward dynamics; and the
//! constants and helpers those solves read (`PARENTS`, `CONTACT_ROWS`, the unrolled
//! factorization).

use proc_macro2::{Literal, TokenStream};
use quote::quote;

use super::{usize_lit, Emitter};
use crate::cas::{Id, OpCount};
use crate::dynamics::{ActiveContacts, Evaluation, Quantity, Shape};

impl Emitter<'_> {
    /// `try_forward_dynamics`, which reports a failed pivot, and `forward_dynamics`, which
    /// gives NaN then.
    pub(super) fn forward_dynamics_fns(&mut self, q: &Quantity) -> TokenStream {
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
        let failures = quote!(<T as ::eomgen_runtime::Lane>::Failures);
        self.try_forward_dynamics = quote! {
            /// Forward dynamics `qdd = M(q)^-1 (tau - b(q, qd) - G(q))`, or which pivot of the
            /// `L^T D L` factorization of M(q) was not positive (a non-physical model or
            /// non-finite input); see `forward_dynamics` for the route and operation count.
            /// `Ok` holds only finite numbers: a non-finite component `i` of the solution (from
            /// a non-finite `qd` or `tau`, or a `q` that leaves M(q) finite) is reported as
            /// `FactorError::NonFinite { pivot: i }`.
            pub fn try_forward_dynamics(&self, q: &[T; #nq], qd: &[T; #n], tau: &[T; #n]) -> ::core::result::Result<[T; #n], ::eomgen_runtime::FactorError> {
                self.forward_dynamics_checked(q, qd, tau).map(|(qdd, _)| qdd)
            }
        };
        self.forward_dynamics_lanes = quote! {
            /// `try_forward_dynamics` on a vector of states (`eomgen_runtime::Lane`, one state
            /// per lane; a scalar is lane 0): the accelerations of every lane, or the lowest
            /// lane whose factorization or solution failed, with that lane's own error.
            pub fn try_forward_dynamics_lanes(&self, q: &[T; #nq], qd: &[T; #n], tau: &[T; #n]) -> ::core::result::Result<[T; #n], ::eomgen_runtime::LaneError> {
                match self.forward_dynamics_checked(q, qd, tau) {
                    Ok((qdd, failures)) => ::eomgen_runtime::lane::lanes_ok::<_, T>(qdd, &failures),
                    Err(error) => Err(::eomgen_runtime::LaneError { lane: 0, error }),
                }
            }
            /// The accelerations and each lane's failure (a scalar returns its first at once).
            fn forward_dynamics_checked(&self, q: &[T; #nq], qd: &[T; #n], tau: &[T; #n]) -> ::core::result::Result<([T; #n], #failures), ::eomgen_runtime::FactorError> {
                let mut failures: #failures = ::core::default::Default::default();
                #body
            }
        };
        quote! {
            #docs
            #vis fn forward_dynamics(&self, q: &[T; #nq], qd: &[T; #n], tau: &[T; #n]) -> [T; #n] {
                match self.forward_dynamics_checked(q, qd, tau) {
                    Ok((qdd, failures)) => ::eomgen_runtime::lane::nan_failed(qdd, &failures),
                    Err(_) => [T::nan(); #n],
                }
            }
        }
    }

    /// The body of an unrolled `try_forward_dynamics`: accelerations and pivots in one
    /// straight-line program, the pivots checked.
    pub(super) fn unrolled_solve(
        &mut self,
        q: &Quantity,
        acc: &[Id],
        piv: &[Id],
    ) -> (TokenStream, OpCount) {
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
            ::eomgen_runtime::lane::check_pivots(&[#(#pivots),*], &mut failures)?;
            let qdd = [#(#x),*];
            ::eomgen_runtime::lane::check_finite(&qdd, &mut failures)?;
            Ok((qdd, failures))
        };
        (body, ops)
    }

    /// The body of a `try_forward_dynamics` that solves at run time: `M` from `mass_matrix`,
    /// `h` straight-line, the runtime's tree `L^T D L` over the joints' parents.
    pub(super) fn runtime_solve(&mut self, q: &Quantity, h: &[Id]) -> (TokenStream, OpCount) {
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
            Self::ltdl_factor_unrolled(&mut m, &mut failures)?;
            let x = Self::ltdl_substitute_unrolled(&m, &rhs);
            ::eomgen_runtime::lane::check_finite(&x, &mut failures)?;
            Ok((x, failures))
        };
        (body, ops)
    }

    /// Whether some quantity is evaluated in one of these ways.
    pub(super) fn any_eval(&self, which: impl Fn(&Evaluation) -> bool) -> bool {
        self.quantities.iter().any(|q| which(&q.eval))
    }

    /// The run-time tree solves' helpers, each only where a quantity calls it: `PARENTS`
    /// (each joint's parent joint, for the runtime's tree kernels and `ContactKkt`; public with
    /// `mass_matrix`, for users' own solves), `CONTACT_ROWS` (with `contact_jacobian`), and
    /// the robot's unrolled factorization and substitution (`emit/tree_solve.rs`).
    pub(super) fn parents_const(&self) -> TokenStream {
        let table = self.parents_table();
        let rows = self.contact_rows_const();
        let helpers = self.tree_helpers();
        quote! {
            #table
            #rows
            #helpers
        }
    }

    /// `PARENTS`, with `mass_matrix` or a quantity whose run-time solve walks the tree.
    fn parents_table(&self) -> TokenStream {
        if !(self.has("mass_matrix") || self.any_eval(reads_parents)) {
            return TokenStream::new();
        }
        let n = &self.n;
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
    }

    /// `CONTACT_ROWS`, with `contact_jacobian`.
    fn contact_rows_const(&self) -> TokenStream {
        if !self.has("contact_jacobian") {
            return TokenStream::new();
        }
        let c = usize_lit(self.contact_rows.len());
        let rows = self.contact_rows.iter().map(|r| usize_lit(*r));
        quote! {
            /// Each contact's number of rows in `contact_jacobian`, `contact_drift` and the
            /// forces (3: a point, 6: a frame), in the contacts' order: points, then frames.
            /// The `active` flags of the `_active` methods follow this order
            /// (`eomgen_runtime::contact::row_mask` turns them into rows).
            pub const CONTACT_ROWS: [usize; #c] = [#(#rows),*];
        }
    }

    /// The unrolled passes over `M`'s tree factors (`emit/tree_solve.rs`), each where a
    /// quantity calls it: the factorization, one substitution, `M^-1`, and the two halves of
    /// a substitution of many columns.
    fn tree_helpers(&self) -> TokenStream {
        use crate::emit::{tree_factor, tree_solve};
        let (parents, n) = (&self.parents, &self.n);
        // The KKT systems of the contact and impulse derivatives take every pass over many
        // columns from the robot's `TreePasses` (`tree_passes_impl`); the forward-dynamics
        // derivatives solve for the 2 N columns of d tau/dq and d tau/dqd.
        let passes = self.any_eval(kkt_derivatives);
        let columns =
            passes || self.any_eval(|e| matches!(e, Evaluation::ForwardDynamicsDerivatives { .. }));
        let factor = self.any_eval(|e| substitutes(e) || sets_up_kkt(e));
        let factor = factor.then(|| tree_factor::factor_fn(parents, n));
        let substitute = self.any_eval(substitutes);
        let substitute = substitute.then(|| tree_solve::substitute_fn(parents, n));
        let inverse = passes || self.any_eval(inverts);
        let inverse = inverse.then(|| tree_solve::inverse_fn(parents, n));
        let lower_rows = columns || self.any_eval(lowers);
        let lower_rows = lower_rows.then(|| tree_solve::lower_rows_fn(parents, n));
        let upper_rows = columns.then(|| tree_solve::upper_rows_fn(parents, n));
        quote! {
            #factor
            #substitute
            #inverse
            #lower_rows
            #upper_rows
        }
    }

    /// `impl TreePasses for` the robot's type, with its unrolled passes (`emit/tree_solve.rs`),
    /// where the contact or impulse derivatives solve KKT systems for many columns
    /// (`ContactKkt::..._by::<Self>`).
    pub(super) fn tree_passes_impl(&self) -> TokenStream {
        if !self.any_eval(kkt_derivatives) {
            return TokenStream::new();
        }
        let (ty, n) = (&self.ty, &self.n);
        quote! {
            /// The passes over `M`'s tree factors of the contact and impulse derivatives'
            /// KKT systems, unrolled for this robot's tree.
            impl<T: ::eomgen_runtime::Lane> ::eomgen_runtime::tree::TreePasses<T, #n> for #ty<T> {
                #[inline(always)]
                fn substitute_rows<const C: usize>(m: &[[T; #n]; #n], _: &[Option<usize>; #n], x: &mut [[T; C]; #n]) {
                    Self::ltdl_lower_rows_unrolled::<C>(m, x);
                    Self::ltdl_upper_rows_unrolled::<C>(m, x, T::one());
                }
                #[inline(always)]
                fn inverse_into(m: &[[T; #n]; #n], _: &[Option<usize>; #n], x: &mut [[T; #n]; #n]) {
                    Self::ltdl_inverse_unrolled(m, x);
                }
            }
        }
    }

    pub(super) fn mass_matrix_inverse_fn(&mut self, q: &Quantity) -> TokenStream {
        let docs = Self::quantity_doc(q, None);
        let (n, nq, mass_matrix) = (&self.n, &self.nq, self.call("mass_matrix"));
        self.blocks.push(quote! {
            #[inline(never)]
            fn mass_matrix_inverse_in_place<'b>(&self, q: &[T; #nq], slot: ::eomgen_runtime::place::Slot<'b, [[T; #n]; #n]>) -> ::eomgen_runtime::place::Filled<'b> {
                let (o, filled) = slot.fill();
                let mut m = #mass_matrix(self, q);
                let mut failures = ::core::default::Default::default();
                match Self::ltdl_factor_unrolled(&mut m, &mut failures) {
                    Ok(()) => {
                        Self::ltdl_inverse_unrolled(&m, o);
                        ::eomgen_runtime::lane::nan_failed_in::<T>(o.as_flattened_mut(), &failures);
                    }
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

    /// `(d qdd/dq, d qdd/dqd, M^-1)` through one factorization of `M`: `d tau/dq`, `d tau/dqd`
    /// at the forward dynamics' accelerations and `M`'s factors (from
    /// `forward_dynamics_partials` with `partials`, else [`Emitter::fd_composed_parts`]), then
    /// `-M^-1` times both matrices, all columns at once (the two passes of
    /// `tree::ltdl_substitute_rows`, unrolled for the tree: `ltdl_lower_rows_unrolled` and
    /// `ltdl_upper_rows_unrolled`), and `M^-1` from the same factors. Everything is written
    /// into the caller's storage (`eomgen_runtime::place`): `d tau` by the `_fill` method of
    /// the function that computes it.
    pub(super) fn forward_dynamics_derivatives_fn(
        &mut self,
        q: &Quantity,
        partials: bool,
    ) -> TokenStream {
        let docs = Self::quantity_doc(q, None);
        let (n, nq) = (&self.n, &self.nq);
        let nan = quote! {
            for v in dq.iter_mut().chain(dqd.iter_mut()).chain(inverse.iter_mut()).flatten() {
                *v = T::nan();
            }
            return filled;
        };
        let parts = if partials {
            Self::fd_partials_parts(n, &nan)
        } else {
            self.fd_composed_parts(&nan)
        };
        let matrix = quote!([[T; #n]; #n]);
        self.blocks.push(quote! {
            #[inline(never)]
            fn forward_dynamics_derivatives_in_place<'b>(&self, q: &[T; #nq], qd: &[T; #n], tau: &[T; #n], slot: ::eomgen_runtime::place::Slot<'b, (#matrix, #matrix, #matrix)>) -> ::eomgen_runtime::place::Filled<'b> {
                let ((dq, dqd, inverse), filled) = slot.fill();
                #parts
                // -M^-1 d tau: the upper pass's `-1` negates, to the bit.
                for x in [&mut *dq, &mut *dqd] {
                    Self::ltdl_lower_rows_unrolled::<#n>(&m, x);
                    Self::ltdl_upper_rows_unrolled::<#n>(&m, x, -T::one());
                }
                Self::ltdl_inverse_unrolled(&m, inverse);
                for x in [dq, dqd, inverse] {
                    ::eomgen_runtime::lane::nan_failed_in::<T>(x.as_flattened_mut(), &failures);
                }
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

    /// Statements leaving `M`'s factors in `m`, `d tau` in `*dq` and `*dqd`, and the lanes
    /// whose pivots failed in `failures` (a scalar runs `nan` at a bad pivot): from
    /// `forward_dynamics_partials`, one straight-line body, written into `dq`, `dqd` and `m`.
    fn fd_partials_parts(n: &Literal, nan: &TokenStream) -> TokenStream {
        let partials = crate::emit::split::fill_name("forward_dynamics_partials");
        quote! {
            let mut m = [[T::zero(); #n]; #n];
            self.#partials(q, qd, tau, dq, dqd, &mut m);
            let mut failures = ::core::default::Default::default();
            let pivots: [T; #n] = ::core::array::from_fn(|i| m[i][i]);
            if ::eomgen_runtime::lane::check_pivots(&pivots, &mut failures).is_err() {
                #nan
            }
        }
    }

    /// [`Emitter::fd_partials_parts`]'s statements from other generated functions: `M` from
    /// `mass_matrix` factorized by the unrolled tree `L^T D L`, `qdd` from it and
    /// `inverse_dynamics(q, qd, 0)`, then `inverse_dynamics_derivatives` there (through its
    /// `_fill` method).
    fn fd_composed_parts(&self, nan: &TokenStream) -> TokenStream {
        let n = &self.n;
        let id = self.call("inverse_dynamics");
        let mass_matrix = self.call("mass_matrix");
        let id_derivatives = self.id_derivatives_into(quote!(*dq), quote!(*dqd), quote!(qdd));
        quote! {
            let mut m = #mass_matrix(self, q);
            let mut failures = ::core::default::Default::default();
            if Self::ltdl_factor_unrolled(&mut m, &mut failures).is_err() {
                #nan
            }
            let mut rhs = *tau;
            for (r, h) in rhs.iter_mut().zip(#id(self, q, qd, &[T::zero(); #n])) {
                *r -= h;
            }
            let qdd = Self::ltdl_substitute_unrolled(&m, &rhs);
            #id_derivatives
        }
    }

    /// `let mut m = ...; let free = ...;`: `M(q)` factorized by the unrolled tree `L^T D L`
    /// and the accelerations without contacts `M^-1 (tau - h)`, `h` by the straight-line block
    /// `hb`; `M`'s pivots checked into `failures` (an expression of type
    /// `&mut <T as Lane>::Failures`: a scalar returns its error, a vector records its lanes').
    pub(super) fn free_accelerations_recording(
        &self,
        hb: &TokenStream,
        failures: TokenStream,
    ) -> TokenStream {
        let (n, m) = (&self.n, self.call("mass_matrix"));
        quote! {
            let mut m = #m(self, q);
            let h: [T; #n] = { #hb };
            let mut rhs = *tau;
            for (r, h) in rhs.iter_mut().zip(h) {
                *r -= h;
            }
            Self::ltdl_factor_unrolled(&mut m, #failures)?;
            let free = Self::ltdl_substitute_unrolled(&m, &rhs);
        }
    }

    /// Statements writing `inverse_dynamics_derivatives` at `(q, qd, &qdd)` into the places
    /// `dq` and `dqd` (of type `[[T; N]; N]`) through its `_fill` method, so that it is not
    /// built in a local and copied: a body that its callers fill is always written in blocks
    /// (`methods.rs`, `FILLED`), and it is emitted before them (catalogue order).
    pub(super) fn id_derivatives_into(
        &self,
        dq: TokenStream,
        dqd: TokenStream,
        qdd: TokenStream,
    ) -> TokenStream {
        debug_assert!(self.split.contains("inverse_dynamics_derivatives"));
        let fill = crate::emit::split::fill_name("inverse_dynamics_derivatives");
        quote!(self.#fill(q, qd, &#qdd, &mut #dq, &mut #dqd);)
    }

    /// `try_contact_forward_dynamics` and `contact_forward_dynamics` (NaN on failure).
    pub(super) fn contact_forward_dynamics_fns(&mut self, q: &Quantity) -> TokenStream {
        match &q.eval {
            Evaluation::ContactForwardDynamics { h } => self.contact_runtime_fns(q, h),
            Evaluation::ContactForwardDynamicsFlat { outputs, pivots } => {
                self.contact_flat_fns(q, outputs, pivots)
            }
            _ => unreachable!("contact_forward_dynamics_fns on another evaluation"),
        }
    }

    /// `try_contact_forward_dynamics` with `body`: kept for the `Contacts` impl when the trait
    /// holds it (an empty stream returned), else returned as an inherent method.
    fn try_contact_forward_dynamics_fn(&mut self, body: TokenStream) -> TokenStream {
        let (n, nq, k) = (&self.n, &self.nq, &self.k);
        let try_vis = self.vis("try_contact_forward_dynamics");
        let try_fn = quote! {
            /// The accelerations and contact forces of `contact_forward_dynamics`, or why they
            /// do not exist: a pivot of M(q) (`pivot` < N) or of `J_c M^-1 J_c^T` (`pivot` - N,
            /// a rank-deficient contact Jacobian) that is not positive, or non-finite input.
            #try_vis fn try_contact_forward_dynamics(&self, q: &[T; #nq], qd: &[T; #n], tau: &[T; #n]) -> ::core::result::Result<([T; #n], [T; #k]), ::eomgen_runtime::FactorError> {
                #body
            }
        };
        if self.trait_of("try_contact_forward_dynamics").is_some() {
            self.try_contact_forward_dynamics = try_fn;
            TokenStream::new()
        } else {
            try_fn
        }
    }

    /// The methods of a straight-line contact forward dynamics, generated for every
    /// `T: Lane` (one state per lane) by [`Emitter::contact_checked_fns`]. The pivots are
    /// checked before the results, as the run-time route does: a non-finite acceleration `i`
    /// is `NonFinite { pivot: i }`, a force `k` `NonFinite { pivot: N + k }`.
    fn contact_flat_fns(&mut self, q: &Quantity, outputs: &[Id], pivots: &[Id]) -> TokenStream {
        let FlatProgram {
            program,
            pivots: piv,
            first: a,
            rows: f,
            ops,
        } = self.flat_program(q, outputs, pivots);
        let lane = quote!(::eomgen_runtime::lane);
        let body = quote! {
            #program
            #lane::check_pivots(&[#(#piv),*], &mut failures)?;
            #lane::check_finite(&[#(#a,)* #(#f),*], &mut failures)?;
            Ok((([#(#a),*], [#(#f),*]), failures))
        };
        self.contact_checked_fns(q, ops, body)
    }

    /// Contact forward dynamics solved at run time, for every `T: Lane` as the straight-line
    /// program's ([`Emitter::contact_checked_fns`]): `M` factorized by the unrolled tree
    /// `L^T D L`, `h` straight-line, `J_c` and its drift from their functions, then every
    /// lane's contact problem at once (`eomgen_runtime::contact::solve_factored_active_lanes`,
    /// every row active).
    fn contact_runtime_fns(&mut self, q: &Quantity, h: &[Id]) -> TokenStream {
        let (hb, ops) = self.straight(q, h, Shape::Vector(h.len()));
        let free = self.free_accelerations_recording(&hb, quote!(&mut failures));
        let (j, drift) = (self.call("contact_jacobian"), self.call("contact_drift"));
        let solve = self.contact_solve_lanes(self.active_rows(false));
        let body = quote! {
            #free
            let j = #j(self, q);
            let drift = #drift(self, q, qd);
            #solve
        };
        self.contact_checked_fns(q, ops, body)
    }

    /// `contact_forward_dynamics_checked` with `body` (which records each lane's failure in
    /// `failures` and ends with `Ok((result, failures))`),
    /// `try_contact_forward_dynamics_lanes`, `contact_forward_dynamics` (NaN in the failed
    /// lanes alone) and `try_contact_forward_dynamics` (the lowest failed lane's error).
    fn contact_checked_fns(
        &mut self,
        q: &Quantity,
        ops: OpCount,
        body: TokenStream,
    ) -> TokenStream {
        let docs = Self::quantity_doc(q, Some(ops));
        let (n, nq, k) = (self.n.clone(), self.nq.clone(), self.k.clone());
        let failures = quote!(<T as ::eomgen_runtime::Lane>::Failures);
        let lane = quote!(::eomgen_runtime::lane);
        let try_fn = self.try_contact_forward_dynamics_fn(quote! {
            let (x, failures) = self.contact_forward_dynamics_checked(q, qd, tau)?;
            #lane::lanes_ok::<_, T>(x, &failures).map_err(|e| e.error)
        });
        let params = quote!(q: &[T; #nq], qd: &[T; #n], tau: &[T; #n]);
        let wrappers =
            self.lane_pair_fns("contact_forward_dynamics", params, quote!(q, qd, tau), docs);
        quote! {
            #try_fn

            /// The accelerations and forces, and each lane's failure (a scalar returns its
            /// first at once).
            fn contact_forward_dynamics_checked(&self, q: &[T; #nq], qd: &[T; #n], tau: &[T; #n]) -> ::core::result::Result<(([T; #n], [T; #k]), #failures), ::eomgen_runtime::FactorError> {
                let mut failures: #failures = ::core::default::Default::default();
                #body
            }

            #wrappers
        }
    }
}

impl Emitter<'_> {
    /// `try_{name}_lanes` (the lowest failed lane, `LaneError`) and `{name}` (NaN in the failed
    /// lanes alone, documented by `docs`), both over `{name}_checked(args)`, which gives a pair
    /// of vectors (`N` velocity coordinates, `K` contact rows) and each lane's failures.
    pub(super) fn lane_pair_fns(
        &self,
        name: &str,
        params: TokenStream,
        args: TokenStream,
        docs: TokenStream,
    ) -> TokenStream {
        let (n, k, lane) = (&self.n, &self.k, quote!(::eomgen_runtime::lane));
        let f = quote::format_ident!("{}", name);
        let (try_lanes, checked) = (
            quote::format_ident!("try_{}_lanes", name),
            quote::format_ident!("{}_checked", name),
        );
        let doc = format!(
            " `try_{name}` on a vector of states (`eomgen_runtime::Lane`, one state per lane; a \
             scalar is lane 0): the results of every lane, or the lowest lane whose \
             factorization or result failed, with that lane's own error."
        );
        let result = quote!(([T; #n], [T; #k]));
        quote! {
            #[doc = #doc]
            pub fn #try_lanes(&self, #params) -> ::core::result::Result<#result, ::eomgen_runtime::LaneError> {
                match self.#checked(#args) {
                    Ok((x, failures)) => #lane::lanes_ok::<_, T>(x, &failures),
                    Err(error) => Err(::eomgen_runtime::LaneError { lane: 0, error }),
                }
            }

            #docs
            pub fn #f(&self, #params) -> #result {
                match self.#checked(#args) {
                    Ok(((x, y), failures)) => (#lane::nan_failed(x, &failures), #lane::nan_failed(y, &failures)),
                    Err(_) => ([T::nan(); #n], [T::nan(); #k]),
                }
            }
        }
    }

    /// A pair-valued method on every `T: Lane` from the body of its `{name}_checked(params)`
    /// (which declares `failures`, fills it and ends in `Ok(((x, y), failures))`): `try_{name}`
    /// (the lowest failed lane's error, documented by `why`), the checked method itself (its
    /// `what` in the doc), and [`Emitter::lane_pair_fns`]' `try_{name}_lanes` and `{name}`.
    pub(super) fn lane_checked_fns(
        &self,
        name: &str,
        (params, args): (TokenStream, TokenStream),
        (why, what, docs): (String, &str, TokenStream),
        body: TokenStream,
    ) -> TokenStream {
        let (n, k, lane) = (&self.n, &self.k, quote!(::eomgen_runtime::lane));
        let failures = quote!(<T as ::eomgen_runtime::Lane>::Failures);
        let try_name = quote::format_ident!("try_{}", name);
        let checked = quote::format_ident!("{}_checked", name);
        let doc =
            format!(" The {what}, and each lane's failure (a scalar returns its first at once).");
        let wrappers = self.lane_pair_fns(name, params.clone(), args.clone(), docs);
        quote! {
            #[doc = #why]
            pub fn #try_name(&self, #params) -> ::core::result::Result<([T; #n], [T; #k]), ::eomgen_runtime::FactorError> {
                let (x, failures) = self.#checked(#args)?;
                #lane::lanes_ok::<_, T>(x, &failures).map_err(|e| e.error)
            }

            #[doc = #doc]
            fn #checked(&self, #params) -> ::core::result::Result<(([T; #n], [T; #k]), #failures), ::eomgen_runtime::FactorError> {
                let mut failures: #failures = ::core::default::Default::default();
                #body
            }

            #wrappers
        }
    }

    /// The straight-line program of a contact or impulse dynamics (`contact_flat`): `let o`
    /// holding its pivots then its results, and the entries of `o` that hold each.
    pub(super) fn flat_program(
        &mut self,
        q: &Quantity,
        outputs: &[Id],
        pivots: &[Id],
    ) -> FlatProgram {
        // The pivots first: scheduled depth first from them, the factorizations come before
        // the right-hand sides (`h`, the drift), whose values are then not live across them
        // (anymal's contact forward dynamics 2 % faster, alternated).
        let all: Vec<Id> = pivots.iter().chain(outputs).copied().collect();
        let (b, ops) = self.straight(q, &all, Shape::Vector(all.len()));
        let len = usize_lit(all.len());
        let at = |range: core::ops::Range<usize>| -> Vec<TokenStream> {
            range
                .map(|i| {
                    let i = usize_lit(i);
                    quote!(o[#i])
                })
                .collect()
        };
        let (n, k, p) = (
            self.parents.len(),
            outputs.len() - self.parents.len(),
            pivots.len(),
        );
        FlatProgram {
            program: quote!(let o: [T; #len] = { #b };),
            pivots: at(0..p),
            first: at(p..p + n),
            rows: at(p + n..p + n + k),
            ops,
        }
    }
}

/// A straight-line contact or impulse dynamics ([`Emitter::flat_program`]).
pub(super) struct FlatProgram {
    /// `let o = ...;`.
    pub program: TokenStream,
    /// The entries of `o` that hold the factorizations' pivots, for `check_pivots`.
    pub pivots: Vec<TokenStream>,
    /// The entries of `o` per velocity coordinate (accelerations, or velocity changes).
    pub first: Vec<TokenStream>,
    /// The entries per contact row (forces, or impulses).
    pub rows: Vec<TokenStream>,
    pub ops: OpCount,
}

/// The evaluations whose KKT systems take the robot's `TreePasses`.
fn kkt_derivatives(e: &Evaluation) -> bool {
    matches!(
        e,
        Evaluation::ContactDynamicsDerivatives { .. }
            | Evaluation::ImpulseDynamicsDerivatives
            | Evaluation::ActiveContacts(
                ActiveContacts::Derivatives { .. } | ActiveContacts::ImpulseDerivatives
            )
    )
}

/// Whether an evaluation's run-time solve reads `PARENTS` (the runtime's tree kernels or
/// `ContactKkt`).
fn reads_parents(e: &Evaluation) -> bool {
    use Evaluation as E;
    matches!(
        e,
        E::MassMatrixInverse
            | E::ForwardDynamicsDerivatives { .. }
            | E::ContactForwardDynamics { .. }
            | E::ContactDynamicsDerivatives { .. }
            | E::ImpulseDynamics
            | E::ImpulseDynamicsDerivatives
            | E::ActiveContacts(_)
    )
}

/// Whether an evaluation substitutes through `M`'s unrolled factors: forward dynamics, and
/// contact dynamics, impulse dynamics, the contact derivatives for their one `M^-1 b` each,
/// and the forward-dynamics derivatives that do not take `M`'s factors from
/// `forward_dynamics_partials`.
fn substitutes(e: &Evaluation) -> bool {
    use Evaluation as E;
    matches!(
        e,
        E::ForwardDynamicsSolve { .. }
            | E::ContactForwardDynamics { .. }
            | E::ForwardDynamicsDerivatives { partials: false }
            | E::ImpulseDynamics
            | E::ContactDynamicsDerivatives { .. }
            | E::ActiveContacts(
                ActiveContacts::Dynamics { .. }
                    | ActiveContacts::Stabilized { .. }
                    | ActiveContacts::Impulse
                    | ActiveContacts::Derivatives { .. }
            )
    )
}

/// Whether an evaluation sets up a KKT system (`ContactKkt::set_up_factored`), which takes
/// `M`'s factors from the unrolled factorization.
fn sets_up_kkt(e: &Evaluation) -> bool {
    use Evaluation as E;
    matches!(
        e,
        E::MassMatrixInverse
            | E::ContactDynamicsDerivatives { .. }
            | E::ImpulseDynamics
            | E::ImpulseDynamicsDerivatives
            | E::ActiveContacts(_)
    )
}

/// Whether an evaluation forms `M^-1` from the factors.
fn inverts(e: &Evaluation) -> bool {
    matches!(
        e,
        Evaluation::MassMatrixInverse | Evaluation::ForwardDynamicsDerivatives { .. }
    )
}

/// Whether an evaluation forms `W = L^-T J^T` for `J M^-1 J^T`: contact and impulse dynamics.
fn lowers(e: &Evaluation) -> bool {
    matches!(
        e,
        Evaluation::ContactForwardDynamics { .. }
            | Evaluation::ImpulseDynamics
            | Evaluation::ActiveContacts(
                ActiveContacts::Dynamics { .. }
                    | ActiveContacts::Stabilized { .. }
                    | ActiveContacts::Impulse
            )
    )
}
