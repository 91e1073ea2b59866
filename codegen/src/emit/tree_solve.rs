//! The substitution through the tree `L^T D L` factors of the mass matrix (`super::tree_factor`),
//! unrolled for one robot's tree: the same arithmetic as the runtime's `tree::ltdl_substitute`,
//! with the tree walks done here, at generation time.
//!
//! At run time the walks up the tree are short loops of varying length, whose branches cost
//! more than the arithmetic on a humanoid (a floating base puts six coordinates above every
//! joint); unrolled, each update is one load, one fused multiply-add and one store at constant
//! indices.
//!
//! The same for the passes over many columns: `M^-1` (`tree::ltdl_inverse_factored_into`'s
//! two passes, each row of the result gathered in registers from its subtree, then from its
//! ancestors), `L^-T` of the contact rows (`tree::ltdl_lower_rows`) and the substitution of
//! many columns (`tree::ltdl_substitute_rows`, the KKT systems' of the contact and impulse
//! derivatives, through the robot's `tree::TreePasses`), in `#[inline(never)]` parts of at
//! most [`PART_UPDATES`] row updates.

use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};

use super::rust::usize_lit;
use crate::dynamics::ltdl::ancestors;

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
    // Each row's ancestors root first and parent last: the parent's value is finished last,
    // so the rest of the row's sum is gathered while it is computed.
    let down = (0..parents.len()).flat_map(|i| {
        let il = usize_lit(i);
        ancestors(parents, i).into_iter().rev().map(move |j| {
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

/// Columns per chunk of the runtime's `tree` passes (`eomgen_runtime::tree::CHUNK`, which the
/// library does not depend on; a unit test holds the two equal): the inverse below updates
/// whole chunks as they do, so that its result is theirs to the bit.
const CHUNK: usize = 2;

/// Row updates per generated function of the passes below: one function of 50 rows and 760
/// updates (a 50-DoF humanoid's inverse) took a frame of 28 kB, most of it the compiler's
/// spills, and ran a quarter slower than in parts.
const PART_UPDATES: usize = 128;

/// The columns one update of a row covers.
#[derive(Clone, Copy)]
enum Span {
    /// Columns `lo..hi`, whole chunks of [`CHUNK`] (the last cut at the matrix's size).
    Chunks(usize, usize),
    /// All `C` columns of a function generic over `C`.
    All,
}

impl Span {
    /// The chunks of `n` columns that overlap `start..end`.
    fn chunks(start: usize, end: usize, n: usize) -> Span {
        Span::Chunks(start / CHUNK * CHUNK, (end.div_ceil(CHUNK) * CHUNK).min(n))
    }
}

/// One update of a row: `m[row][col]` times row `k` of `x`, over `span`.
struct Update {
    row: usize,
    col: usize,
    k: usize,
    span: Span,
}

/// `x[target]` from `init` (`None`: the row as it is) and its updates, gathered in a local
/// accumulator (kept in registers) and written once, as the runtime's `tree` passes do.
fn gather(target: usize, init: Option<TokenStream>, updates: &[Update]) -> TokenStream {
    let t = usize_lit(target);
    let init = match (init, updates.is_empty()) {
        (None, true) => return TokenStream::new(),
        (Some(init), true) => return quote!(x[#t] = #init;),
        (init, false) => init.unwrap_or_else(|| quote!(x[#t])),
    };
    let steps = updates.iter().map(|u| {
        let (r, c, k) = (usize_lit(u.row), usize_lit(u.col), usize_lit(u.k));
        let columns = match u.span {
            Span::Chunks(lo, hi) => {
                let (lo, hi) = (usize_lit(lo), usize_lit(hi));
                quote!(#lo..#hi)
            }
            Span::All => quote!(0..C),
        };
        quote! {
            let f = -m[#r][#c];
            for j in #columns {
                acc[j] = f.mul_add(x[#k][j], acc[j]);
            }
        }
    });
    quote! {
        {
            let mut acc = #init;
            #(#steps)*
            x[#t] = acc;
        }
    }
}

/// `L^-T` (from the leaves up): row `a` less `L[k][a]` times row `k` for each `k` of its
/// subtree, last first (the nearest rows, finished last, are gathered last), over `span(k)`;
/// `init(a)` its starting value (`None`: the row as it is). The runtime's
/// `pull_from_subtrees`.
fn from_subtrees(
    parents: &[Option<usize>],
    init: impl Fn(usize) -> Option<TokenStream>,
    span: impl Fn(usize) -> Span,
) -> Vec<(usize, TokenStream)> {
    let ends = subtree_ends(parents);
    (0..parents.len())
        .rev()
        .map(|a| {
            let updates: Vec<Update> = (a + 1..ends[a])
                .rev()
                .filter(|&k| ancestors(parents, k).contains(&a))
                .map(|k| Update {
                    row: k,
                    col: a,
                    k,
                    span: span(k),
                })
                .collect();
            (updates.len(), gather(a, init(a), &updates))
        })
        .collect()
}

/// `D^-1`, then `L^-1` (from the root down): row `i` scaled by `one / D[i]`, less `L[i][a]`
/// times row `a` for each ancestor `a`, the root first and the parent last, over `span(i)`. The
/// runtime's `pull_from_ancestors` when `one` is `1`; `-1` flips every operation's sign, so the
/// result is negated to the bit.
fn from_ancestors(
    parents: &[Option<usize>],
    one: &TokenStream,
    span: impl Fn(usize) -> Span,
) -> Vec<(usize, TokenStream)> {
    (0..parents.len())
        .map(|i| {
            let il = usize_lit(i);
            let updates: Vec<Update> = ancestors(parents, i)
                .into_iter()
                .rev()
                .map(|a| Update {
                    row: i,
                    col: a,
                    k: a,
                    span: span(i),
                })
                .collect();
            let init = quote! {{
                let mut row = x[#il];
                let inv = #one / m[#il][#il];
                for v in row.iter_mut() {
                    *v *= inv;
                }
                row
            }};
            (updates.len(), gather(i, Some(init), &updates))
        })
        .collect()
}

/// Parameters a pass's functions take besides `m` and `x` (`params`, such as `, one: T`) and
/// the arguments that pass them on (`args`, such as `, one`); none by default.
#[derive(Default)]
struct Extra {
    params: TokenStream,
    args: TokenStream,
}

/// The rows `(updates, code)` as functions `name_0`, `name_1`, ... of at most
/// [`PART_UPDATES`] updates each (a row with more is a function alone), with the signature
/// `x` (the type of the matrix the rows update), `generics` and `extra` (more parameters and
/// the arguments that pass them on, each list with its leading comma): the functions and the
/// calls of them in order.
fn in_parts(
    name: &str,
    generics: TokenStream,
    turbofish: TokenStream,
    x: TokenStream,
    extra: &Extra,
    n: &Literal,
    rows: Vec<(usize, TokenStream)>,
) -> (TokenStream, TokenStream) {
    let Extra { params, args } = extra;
    let mut parts: Vec<Vec<TokenStream>> = Vec::new();
    let mut size = 0;
    for (updates, code) in rows {
        match parts.last_mut() {
            Some(last) if size + updates <= PART_UPDATES => {
                last.push(code);
                size += updates;
            }
            _ => {
                parts.push(vec![code]);
                size = updates;
            }
        }
    }
    let functions: Vec<_> = (0..parts.len())
        .map(|p| format_ident!("{}_{}", name, p))
        .collect();
    let bodies = functions.iter().zip(&parts).map(|(f, rows)| {
        quote! {
            #[inline(never)]
            fn #f #generics(m: &[[T; #n]; #n], x: &mut #x #params) {
                #(#rows)*
            }
        }
    });
    (
        quote!(#(#bodies)*),
        quote!(#(Self::#functions #turbofish(m, x #args);)*),
    )
}

/// `fn ltdl_inverse_unrolled(m, x)`: `M^-1` into `x` from the factors of
/// `ltdl_factor_unrolled`, as `tree::ltdl_inverse_factored_into` computes it (the same
/// operations in the same order, so the same result to the bit), with its walks of the tree
/// and its choice of chunks done here: at run time each update of a row tested up to seven
/// chunks for overlap and branched on the tree, and on a 50-DoF humanoid those tests, not
/// the arithmetic, were most of the inverse's time (talos `mass_matrix_inverse` 6.9 -> 4.6 us).
pub(super) fn inverse_fn(parents: &[Option<usize>], n: &Literal) -> TokenStream {
    let size = parents.len();
    let ends = subtree_ends(parents);
    let unit = |a: usize| {
        let al = usize_lit(a);
        Some(quote! {{
            let mut unit = [T::zero(); #n];
            unit[#al] = T::one();
            unit
        }})
    };
    let mut rows = from_subtrees(parents, unit, |k| Span::chunks(k, ends[k], size));
    rows.extend(from_ancestors(parents, &quote!(T::one()), |i| {
        Span::chunks(i, size, size)
    }));
    let x = quote!([[T; #n]; #n]);
    let none = Extra::default();
    let (parts, calls) = in_parts("ltdl_inverse_part", quote!(), quote!(), x, &none, n, rows);
    quote! {
        #parts
        /// `M^-1` from the factors of `ltdl_factor_unrolled`, whatever `x` held
        /// (`eomgen_runtime::tree::ltdl_inverse_factored_into` unrolled): `L^-T` from the
        /// identity, then `D^-1` and `L^-1` on the upper triangle, mirrored.
        #[inline(never)]
        fn ltdl_inverse_unrolled(m: &[[T; #n]; #n], x: &mut [[T; #n]; #n]) {
            #calls
            for i in 1..#n {
                let (upper, lower) = x.split_at_mut(i);
                for (j, above) in upper.iter().enumerate() {
                    lower[0][j] = above[i];
                }
            }
        }
    }
}

/// `fn ltdl_lower_rows_unrolled::<C>(m, x)`: `x <- L^-T x` for the `C` columns of `x`, the
/// first half of the substitution (`J M^-1 J^T = W^T D^-1 W` with `W = L^-T J^T` needs no
/// more), as `tree::ltdl_lower_rows` computes it (to the bit), the tree walks done here.
pub(super) fn lower_rows_fn(parents: &[Option<usize>], n: &Literal) -> TokenStream {
    let rows = from_subtrees(parents, |_| None, |_| Span::All);
    let doc = "`x <- L^-T x` for the `C` columns of `x` with the factors of \
               `ltdl_factor_unrolled` (`eomgen_runtime::tree::ltdl_lower_rows` unrolled).";
    columns_fn("ltdl_lower_rows", doc, n, &Extra::default(), rows)
}

/// `fn ltdl_upper_rows_unrolled::<C>(m, x, one)`: `x <- one L^-1 D^-1 x` for the `C` columns of
/// `x`, the second half of the substitution after `ltdl_lower_rows_unrolled` (the two together
/// are `tree::ltdl_substitute_rows`, to the bit, with `one` = 1; `one` = -1 negates the result,
/// to the bit, for the cost of none), the tree walks done here.
pub(super) fn upper_rows_fn(parents: &[Option<usize>], n: &Literal) -> TokenStream {
    let rows = from_ancestors(parents, &quote!(one), |_| Span::All);
    let doc = "`x <- one L^-1 D^-1 x` for the `C` columns of `x` with the factors of \
               `ltdl_factor_unrolled` (the second pass of \
               `eomgen_runtime::tree::ltdl_substitute_rows` unrolled; `one` = -1 negates it).";
    let one = Extra {
        params: quote!(, one: T),
        args: quote!(, one),
    };
    columns_fn("ltdl_upper_rows", doc, n, &one, rows)
}

/// `fn NAME_unrolled::<C>(m, x, extra...)` documented by `doc`, calling the parts
/// (`NAME_part_0`, ...) that hold `rows` over all `C` columns of `x`, passing `extra` on.
fn columns_fn(
    name: &str,
    doc: &str,
    n: &Literal,
    extra: &Extra,
    rows: Vec<(usize, TokenStream)>,
) -> TokenStream {
    let generics = quote!(<const C: usize>);
    let x = quote!([[T; C]; #n]);
    let part = format!("{name}_part");
    let (parts, calls) = in_parts(&part, generics, quote!(::<C>), x, extra, n, rows);
    let f = format_ident!("{}_unrolled", name);
    let params = &extra.params;
    quote! {
        #parts
        #[doc = #doc]
        #[inline(never)]
        fn #f<const C: usize>(m: &[[T; #n]; #n], x: &mut [[T; C]; #n] #params) {
            #calls
        }
    }
}

/// One past the last coordinate of each coordinate's subtree (parents before children).
fn subtree_ends(parents: &[Option<usize>]) -> Vec<usize> {
    let mut ends: Vec<usize> = (1..=parents.len()).collect();
    for i in (0..parents.len()).rev() {
        if let Some(p) = parents[i] {
            ends[p] = ends[p].max(ends[i]);
        }
    }
    ends
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chunks_are_the_runtimes() {
        assert_eq!(CHUNK, eomgen_runtime::tree::CHUNK);
    }
}
