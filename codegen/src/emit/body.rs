//! Straight-line function bodies: a program's temporaries, then its outputs in their shape.

use std::collections::BTreeSet;

use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote};

use super::expr::Ctx;
use super::split::{split_body, Split};
use crate::cas::{Graph, Id, OpCount, Order, Program};
use crate::dynamics::Shape;

/// Programs of more operations than this are scheduled depth first ([`Order::Depth`]) rather
/// than by levels: on the panda's derivatives (7,000 and 13,000 operations) level order kept so
/// many values live that the compiled code was 4 % and 13 % slower.
const DEPTH_ORDER_MIN_OPS: usize = 6000;

/// Temporaries per chunk of `let`s (see [`body`]).
const LET_CHUNK: usize = 64;

/// A function body and what it costs.
pub(super) struct Body {
    /// Statements ending in the result.
    pub code: TokenStream,
    pub ops: OpCount,
    /// The non-inlined blocks the body calls when it was split ([`split_body`]), for the
    /// inherent impl.
    pub blocks: Vec<TokenStream>,
}

/// Straight-line body computing `outputs` in the given shape, and its operation count; split
/// into blocks of at most `split.budget` operations when over it.
pub(super) fn body(
    g: &Graph,
    cx: &Ctx<'_>,
    outputs: &[Id],
    shape: Shape,
    split: Option<&Split<'_>>,
) -> Body {
    let program = Program::ordered(g, outputs, Order::Levels);
    let ops = program.ops();
    let over = split.filter(|s| s.filled || ops.total() > s.budget);
    let program = scheduled(g, outputs, program, over.is_some());
    if let Some(split) = over {
        let (code, blocks) = split_body(cx, &program, shape, split);
        return Body { code, ops, blocks };
    }
    let (lets, outs) = statements(cx, &program);
    let result = shaped(&outs, shape);
    Body {
        code: quote!(#lets #result),
        ops,
        blocks: Vec::new(),
    }
}

/// `program` (in level order), or the same outputs depth first when it is large or `split`.
fn scheduled(g: &Graph, outputs: &[Id], program: Program, split: bool) -> Program {
    if split || program.ops().total() > DEPTH_ORDER_MIN_OPS {
        Program::ordered(g, outputs, Order::Depth)
    } else {
        program
    }
}

/// A program's statements (the sines and cosines, then the temporaries) and its outputs'
/// expressions.
fn statements(cx: &Ctx<'_>, program: &Program) -> (TokenStream, Vec<TokenStream>) {
    let mut trig = BTreeSet::new();
    let defs: Vec<(Ident, TokenStream)> = program
        .temps
        .iter()
        .enumerate()
        .map(|(k, e)| (format_ident!("t{}", k), cx.expr(e, &mut trig).ts))
        .collect();
    let temps = chunked_lets(&defs);
    let outs: Vec<TokenStream> = program
        .outputs
        .iter()
        .map(|e| cx.expr(e, &mut trig).ts)
        .collect();
    let pre = trig_lets(&trig);
    (quote!(#(#pre)* #(#temps)*), outs)
}

/// Entries per `Pack::unpack_run` of [`unpacked_body`]: a whole number of vectors of four and
/// of eight lanes.
const RUN: usize = 8;

/// [`body`]'s program for a vector of states (`T: Pack`), ending in the writing of its result
/// run by run into one slice of states per matrix of `shape`, `out` or `out_0`, `out_1`, ...
/// (`&mut [[[T::Scalar; C]; R]]`, one matrix per state), by `Pack::unpack_run` on the
/// outputs' expressions: the result never goes through an array of vectors. The same
/// operations as [`body`], so the same bits per lane. (Each run written as soon as its
/// temporaries were computed, instead of at the end, was no faster.)
pub(super) fn unpacked_body(g: &Graph, cx: &Ctx<'_>, outputs: &[Id], shape: Shape) -> TokenStream {
    let program = Program::ordered(g, outputs, Order::Levels);
    let program = scheduled(g, outputs, program, false);
    let (lets, outs) = statements(cx, &program);
    let (k, size) = match shape {
        Shape::Matrices(k, r, c) => (k, r * c),
        _ => (1, outs.len()),
    };
    let runs = outs
        .chunks(size.max(1))
        .take(k)
        .enumerate()
        .flat_map(|(m, entries)| {
            let out = if k == 1 {
                format_ident!("out")
            } else {
                format_ident!("out_{}", m)
            };
            entries.chunks(RUN).enumerate().map(move |(r, run)| {
                let at = Literal::usize_unsuffixed(r * RUN);
                quote!(::eomgen_runtime::lane::Pack::unpack_run(&[#(#run),*], #out, #at);)
            })
        });
    quote!(#lets #(#runs)*)
}

/// Temporaries go in chunks: `let (t0, .., t63) = { let t0 = ..; ..; (t0, .., t63) };`.
/// Every `let` opens a lexical scope nested in the previous one, and LLVM's debug-info writer
/// recurses once per level: a few thousand plain `let`s in one function overflow rustc's stack
/// in debug builds. Chunking bounds the depth at chunks + chunk size.
pub(super) fn chunked_lets(defs: &[(Ident, TokenStream)]) -> Vec<TokenStream> {
    if defs.len() <= LET_CHUNK {
        return defs
            .iter()
            .map(|(name, v)| quote!(let #name = #v;))
            .collect();
    }
    defs.chunks(LET_CHUNK)
        .map(|chunk| {
            let names: Vec<&Ident> = chunk.iter().map(|(n, _)| n).collect();
            let lets = chunk.iter().map(|(name, v)| quote!(let #name = #v;));
            quote!(let (#(#names),*,) = { #(#lets)* (#(#names),*,) };)
        })
        .collect()
}

/// The sine and cosine of every joint angle the body uses, computed up front: one
/// `Lane::sin_cos_many` call for all of them (vector instructions for `f64`,
/// `eomgen_runtime::trig`), also for a single angle, so that the blocks of a split body,
/// which each take the angles they read first, compute the same bits as the whole body. The
/// sine or cosine that nothing reads is bound to `_`.
pub(super) fn trig_lets(trig: &BTreeSet<(usize, bool)>) -> Vec<TokenStream> {
    let joints: Vec<usize> = trig
        .iter()
        .map(|t| t.0)
        .collect::<BTreeSet<usize>>()
        .into_iter()
        .collect();
    let name = |i: usize, is_sin: bool| {
        if trig.contains(&(i, is_sin)) {
            let prefix = if is_sin { "s" } else { "c" };
            let id = format_ident!("{}{}", prefix, i);
            quote!(#id)
        } else {
            quote!(_)
        }
    };
    let sines: Vec<TokenStream> = joints.iter().map(|&i| name(i, true)).collect();
    let cosines: Vec<TokenStream> = joints.iter().map(|&i| name(i, false)).collect();
    let angles: Vec<TokenStream> = joints
        .iter()
        .map(|&i| {
            let i = Literal::usize_unsuffixed(i);
            quote!(q[#i])
        })
        .collect();
    if joints.is_empty() {
        return Vec::new();
    }
    vec![quote! {
        let ([#(#sines),*], [#(#cosines),*]) = <T as ::eomgen_runtime::Lane>::sin_cos_many([#(#angles),*]);
    }]
}

/// A straight-line body whose outputs hold when every pivot is positive: the outputs and the
/// pivots in one program, then the value of `shape`, or NaN in every entry when a pivot is not
/// positive and finite (in every lane where one is not, for a vector of states).
pub(super) fn factored_body(
    g: &Graph,
    cx: &Ctx<'_>,
    outputs: &[Id],
    pivots: &[Id],
    shape: Shape,
    split: Option<&Split<'_>>,
) -> Body {
    let all: Vec<Id> = outputs.iter().chain(pivots).copied().collect();
    let Body {
        code: b,
        ops,
        blocks,
    } = body(g, cx, &all, Shape::Vector(all.len()), split);
    let len = Literal::usize_unsuffixed(all.len());
    let index = |k: usize| {
        let k = Literal::usize_unsuffixed(k);
        quote!(o[#k])
    };
    let pivots = (outputs.len()..all.len()).map(index);
    let result = shaped(&(0..outputs.len()).map(index).collect::<Vec<_>>(), shape);
    let nan = filled(quote!(T::nan()), shape);
    // A scalar stops at its first bad pivot; a vector of states NaNs the lanes that had one.
    let checked = quote! {
        let o: [T; #len] = { #b };
        let mut failures: <T as ::eomgen_runtime::Lane>::Failures = ::core::default::Default::default();
        if ::eomgen_runtime::lane::check_pivots(&[#(#pivots),*], &mut failures).is_err() {
            return #nan;
        }
        let o = ::eomgen_runtime::lane::nan_failed(o, &failures);
        #result
    };
    Body {
        code: checked,
        ops,
        blocks,
    }
}

/// A value of `shape` with `x` in every entry.
pub(super) fn filled(x: TokenStream, shape: Shape) -> TokenStream {
    let lit = Literal::usize_unsuffixed;
    match shape {
        Shape::Scalar => x,
        Shape::Vector(n) => {
            let n = lit(n);
            quote!([#x; #n])
        }
        Shape::Matrix(r, c) => {
            let (r, c) = (lit(r), lit(c));
            quote!([[#x; #c]; #r])
        }
        Shape::Matrices(k, r, c) => {
            let each = std::iter::repeat_n(filled(x, Shape::Matrix(r, c)), k);
            quote!((#(#each),*))
        }
    }
}

/// The outputs as a scalar, an array or an array of rows.
fn shaped(outs: &[TokenStream], shape: Shape) -> TokenStream {
    match shape {
        Shape::Scalar => outs[0].clone(),
        Shape::Vector(_) => quote!([#(#outs),*]),
        Shape::Matrix(rows, 0) => {
            let empty = std::iter::repeat_n(quote!([]), rows);
            quote!([#(#empty),*])
        }
        Shape::Matrix(_, cols) => {
            let rows = outs.chunks(cols).map(|r| quote!([#(#r),*]));
            quote!([#(#rows),*])
        }
        Shape::Matrices(_, rows, cols) => {
            let each = outs
                .chunks((rows * cols).max(1))
                .map(|m| shaped(m, Shape::Matrix(rows, cols)));
            quote!((#(#each),*))
        }
    }
}

/// The Rust type of a value of `shape`.
pub(super) fn shape_type(shape: Shape) -> TokenStream {
    let lit = Literal::usize_unsuffixed;
    match shape {
        Shape::Scalar => quote!(T),
        Shape::Vector(n) => {
            let n = lit(n);
            quote!([T; #n])
        }
        Shape::Matrix(r, c) => {
            let (r, c) = (lit(r), lit(c));
            quote!([[T; #c]; #r])
        }
        Shape::Matrices(k, r, c) => {
            let one = shape_type(Shape::Matrix(r, c));
            let all = std::iter::repeat_n(one, k);
            quote!((#(#all),*))
        }
    }
}
