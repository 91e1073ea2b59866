//! The tree `L^T D L` factorization of the mass matrix, unrolled for one robot's tree: the same
//! arithmetic as the runtime's `tree::ltdl_factor`, with the tree walks done here, at generation
//! time (about `sum over coordinates of depth^2 / 2` updates: 3,400 for a 50-DoF humanoid).
//!
//! On a small tree every entry the factorization touches is a local, loaded just before its
//! first update and stored right after its last. Updated in place instead, each of a floating
//! base's 21 entries takes one load, fused multiply-add and store per joint below it, and each
//! load waits for the store before it: anymal's factorization took 155 ns that way and 106 ns
//! in locals. On a humanoid the locals no longer fit the registers and spill (talos's `M^-1`
//! 3 to 5 % slower), so trees of more than [`LOCALS_MAX_ENTRIES`] entries update `m` in place.

use std::collections::{HashMap, HashSet};

use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};

use super::rust::usize_lit;
use crate::dynamics::ltdl::ancestors;

/// The most entries (`M_ij` for `j` equal to `i` or one of its ancestors) a tree's
/// factorization keeps in locals: a quadruped has 117, b1-z1 (a quadruped with an arm) 187,
/// g1_29dof 341, talos_full_v2 567.
pub(crate) const LOCALS_MAX_ENTRIES: usize = 256;

/// `fn ltdl_factor_unrolled(m, failures)`: factorizes `m` in place as `tree::ltdl_factor` does
/// (the factors in the same places, the same errors), pivots checked in elimination order.
pub(super) fn factor_fn(parents: &[Option<usize>], n: &Literal) -> TokenStream {
    let steps = steps(parents);
    let body = if entries(parents) <= LOCALS_MAX_ENTRIES {
        in_locals(&steps)
    } else {
        let body = steps.iter().map(|step| step.tokens(&element));
        quote!(#(#body)*)
    };
    quote! {
        /// `M = L^T D L` in place over this robot's tree (`eomgen_runtime::tree::ltdl_factor`
        /// unrolled): `D` on the diagonal, `L` below it; fails with the first pivot, last
        /// coordinate first, that is not finite or not positive (a vector of states records
        /// each lane's in `failures` instead, `eomgen_runtime::Lane::check_pivot`).
        #[inline(never)]
        fn ltdl_factor_unrolled(m: &mut [[T; #n]; #n], failures: &mut <T as ::eomgen_runtime::Lane>::Failures) -> ::core::result::Result<(), ::eomgen_runtime::FactorError> {
            #body
            Ok(())
        }
    }
}

/// An entry `(i, j)` of `m`: `j` is `i` or one of its ancestors.
type Entry = (usize, usize);

/// How many entries the factorization touches.
fn entries(parents: &[Option<usize>]) -> usize {
    (0..parents.len())
        .map(|i| 1 + ancestors(parents, i).len())
        .sum()
}

/// One statement of the factorization, in elimination order.
enum Step {
    /// Check pivot `k` and invert it (`inv`).
    Pivot(usize),
    /// `a = m[k][i] * inv`, `m[i][j] -= a m[k][j]` for each `j` of `columns`, `m[k][i] = a`.
    Row {
        k: usize,
        i: usize,
        columns: Vec<usize>,
    },
}

/// Coordinates last first, each pivot followed by its ancestors' rows, nearest first.
fn steps(parents: &[Option<usize>]) -> Vec<Step> {
    let mut steps = Vec::new();
    for k in (0..parents.len()).rev() {
        steps.push(Step::Pivot(k));
        let anc = ancestors(parents, k);
        for (s, &i) in anc.iter().enumerate() {
            let columns = anc[s..].to_vec();
            steps.push(Step::Row { k, i, columns });
        }
    }
    steps
}

impl Step {
    /// The entries it reads, then those it writes.
    fn entries(&self) -> Vec<Entry> {
        match self {
            Step::Pivot(k) => vec![(*k, *k)],
            Step::Row { k, i, columns } => std::iter::once((*k, *i))
                .chain(columns.iter().map(|&j| (*k, j)))
                .chain(self.written())
                .collect(),
        }
    }

    /// The entries it writes.
    fn written(&self) -> Vec<Entry> {
        match self {
            Step::Pivot(_) => Vec::new(),
            Step::Row { k, i, columns } => std::iter::once((*k, *i))
                .chain(columns.iter().map(|&j| (*i, j)))
                .collect(),
        }
    }

    /// The statement, entries named by `at`.
    fn tokens(&self, at: &impl Fn(Entry) -> TokenStream) -> TokenStream {
        match *self {
            Step::Pivot(k) => {
                let (d, kl) = (at((k, k)), usize_lit(k));
                quote! {
                    let d = #d;
                    <T as ::eomgen_runtime::Lane>::check_pivot(d, #kl, failures)?;
                    let inv = T::one() / d;
                }
            }
            Step::Row { k, i, ref columns } => {
                let ki = at((k, i));
                let updates = columns.iter().map(|&j| {
                    let (ij, kj) = (at((i, j)), at((k, j)));
                    quote!(#ij = (-a).mul_add(#kj, #ij);)
                });
                quote! {
                    let a = #ki * inv;
                    #(#updates)*
                    #ki = a;
                }
            }
        }
    }
}

/// `m[i][j]`.
fn element((i, j): Entry) -> TokenStream {
    let (il, jl) = (usize_lit(i), usize_lit(j));
    quote!(m[#il][#jl])
}

/// The local `m_i_j`.
fn local((i, j): Entry) -> TokenStream {
    let v = format_ident!("m_{}_{}", i, j);
    quote!(#v)
}

/// The steps on locals: each entry loaded from `m` before the step that first touches it and,
/// if written, stored back after the step that last does.
fn in_locals(steps: &[Step]) -> TokenStream {
    let mut last = HashMap::new();
    let mut written = HashSet::new();
    for (t, step) in steps.iter().enumerate() {
        for e in step.entries() {
            last.insert(e, t);
        }
        written.extend(step.written());
    }
    let mut loaded = HashSet::new();
    let mut body = Vec::new();
    for (t, step) in steps.iter().enumerate() {
        for e in step.entries() {
            if loaded.insert(e) {
                let (v, m) = (local(e), element(e));
                let binding = if written.contains(&e) {
                    quote!(mut #v)
                } else {
                    v
                };
                body.push(quote!(let #binding = #m;));
            }
        }
        body.push(step.tokens(&local));
        for e in step.entries() {
            if last.get(&e) == Some(&t) && written.contains(&e) {
                last.remove(&e);
                let (v, m) = (local(e), element(e));
                body.push(quote!(#m = #v;));
            }
        }
    }
    quote!(#(#body)*)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A floating base (six coordinates in a chain) with two legs of two joints.
    fn biped() -> Vec<Option<usize>> {
        let mut p = vec![None, Some(0), Some(1), Some(2), Some(3), Some(4)];
        p.extend([Some(5), Some(6), Some(5), Some(8)]);
        p
    }

    #[test]
    fn every_entry_is_loaded_once_and_each_written_one_stored_once() {
        let code = in_locals(&steps(&biped())).to_string();
        let parents = biped();
        for i in 0..parents.len() {
            for j in std::iter::once(i).chain(ancestors(&parents, i)) {
                let load = format!("= m [{i}] [{j}] ;");
                let store = format!("m [{i}] [{j}] = m_{i}_{j} ;");
                assert_eq!(code.matches(&load).count(), 1, "load of ({i}, {j})");
                let stores = code.matches(&store).count();
                // Every entry but a leaf's diagonal (a pivot only read) is written.
                let leaf_pivot = i == j && !parents.contains(&Some(i));
                assert_eq!(stores, usize::from(!leaf_pivot), "store of ({i}, {j})");
            }
        }
    }

    #[test]
    fn a_store_follows_the_last_step_that_touches_the_entry() {
        let code = in_locals(&steps(&biped())).to_string();
        // The base's first entry is the last pivot: stored after its check, at the very end.
        let store = code.find("m [0] [0] = m_0_0 ;").unwrap();
        let check = code.find("check_pivot (d , 0 ,").unwrap();
        assert!(check < store);
        // The base's triangle, then each leg's two rows of seven and eight entries.
        assert_eq!(entries(&biped()), 21 + 2 * (7 + 8));
    }
}
