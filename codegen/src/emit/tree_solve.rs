//! The tree `L^T D L` factorization of the mass matrix and its substitution, unrolled for one
//! robot's tree: the same arithmetic as the runtime's `tree::ltdl_factor` and
//! `tree::ltdl_substitute`, with the tree walks done here, at generation time.
//!
//! At run time the walks up the tree are short loops of varying length, whose branches cost
//! more than the arithmetic on a humanoid (a floating base puts six coordinates above every
//! joint); unrolled, each update is one load, one fused multiply-add and one store at constant
//! indices. The code is about `sum over coordinates of depth^2 / 2` lines (3,400 for a 50-DoF
//! humanoid), small next to the mass matrix it factorizes.

use proc_macro2::{Literal, TokenStream};
use quote::quote;

use super::rust::usize_lit;
use crate::dynamics::ltdl::ancestors;

/// `fn ltdl_factor_unrolled(m, failures)`: factorizes `m` in place as `tree::ltdl_factor` does
/// (the factors in the same places, the same errors), pivots checked in elimination order.
pub(super) fn factor_fn(parents: &[Option<usize>], n: &Literal) -> TokenStream {
    let steps = (0..parents.len()).rev().map(|k| {
        let kl = usize_lit(k);
        let anc = ancestors(parents, k);
        let updates = anc.iter().enumerate().map(|(s, &ii)| {
            let il = usize_lit(ii);
            let inner = anc[s..].iter().map(|&jj| {
                let jl = usize_lit(jj);
                quote!(m[#il][#jl] = (-a).mul_add(m[#kl][#jl], m[#il][#jl]);)
            });
            quote! {
                let a = m[#kl][#il] * inv;
                #(#inner)*
                m[#kl][#il] = a;
            }
        });
        quote! {
            let d = m[#kl][#kl];
            <T as ::eomgen_runtime::Lane>::check_pivot(d, #kl, failures)?;
            let inv = T::one() / d;
            #(#updates)*
        }
    });
    quote! {
        /// `M = L^T D L` in place over this robot's tree (`eomgen_runtime::tree::ltdl_factor`
        /// unrolled): `D` on the diagonal, `L` below it; fails with the first pivot, last
        /// coordinate first, that is not finite or not positive (a vector of states records
        /// each lane's in `failures` instead, `eomgen_runtime::Lane::check_pivot`).
        #[inline(never)]
        fn ltdl_factor_unrolled(m: &mut [[T; #n]; #n], failures: &mut <T as ::eomgen_runtime::Lane>::Failures) -> ::core::result::Result<(), ::eomgen_runtime::FactorError> {
            #(#steps)*
            Ok(())
        }
    }
}

/// `fn ltdl_substitute_unrolled(m, b)`: solves `M x = b` with the factors of
/// `ltdl_factor_unrolled`, as `tree::ltdl_substitute` does.
pub(super) fn substitute_fn(parents: &[Option<usize>], n: &Literal) -> TokenStream {
    let up = (0..parents.len()).rev().flat_map(|i| {
        let il = usize_lit(i);
        ancestors(parents, i).into_iter().map(move |j| {
            let jl = usize_lit(j);
            quote!(x[#jl] = (-m[#il][#jl]).mul_add(x[#il], x[#jl]);)
        })
    });
    let down = (0..parents.len()).flat_map(|i| {
        let il = usize_lit(i);
        ancestors(parents, i).into_iter().map(move |j| {
            let jl = usize_lit(j);
            quote!(x[#il] = (-m[#il][#jl]).mul_add(x[#jl], x[#il]);)
        })
    });
    quote! {
        /// Solves `M x = b` with the factors of `ltdl_factor_unrolled`
        /// (`eomgen_runtime::tree::ltdl_substitute` unrolled).
        #[inline(never)]
        fn ltdl_substitute_unrolled(m: &[[T; #n]; #n], b: &[T; #n]) -> [T; #n] {
            let mut x = *b;
            #(#up)*
            for (i, xi) in x.iter_mut().enumerate() {
                *xi /= m[i][i];
            }
            #(#down)*
            x
        }
    }
}
