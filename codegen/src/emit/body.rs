//! Straight-line function bodies: a program's temporaries, then its outputs in their shape.

use std::collections::BTreeSet;

use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote};

use super::expr::Ctx;
use crate::cas::{Graph, Id, OpCount, Order, Program};
use crate::dynamics::Shape;

/// Temporaries per chunk of `let`s (see [`body`]).
const LET_CHUNK: usize = 64;

/// Straight-line body computing `outputs` in the given shape, and its operation count.
pub(super) fn body(
    g: &Graph,
    cx: &Ctx<'_>,
    outputs: &[Id],
    shape: Shape,
) -> (TokenStream, OpCount) {
    let program = Program::ordered(g, outputs, Order::Levels);
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
    let result = shaped(&outs, shape);
    (quote!(#(#pre)* #(#temps)* #result), program.ops())
}

/// Temporaries go in chunks: `let (t0, .., t63) = { let t0 = ..; ..; (t0, .., t63) };`.
/// Every `let` opens a lexical scope nested in the previous one, and LLVM's debug-info writer
/// recurses once per level: a few thousand plain `let`s in one function overflow rustc's stack
/// in debug builds. Chunking bounds the depth at chunks + chunk size.
fn chunked_lets(defs: &[(Ident, TokenStream)]) -> Vec<TokenStream> {
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

/// One `sin_cos` per joint angle the body uses, computed up front.
fn trig_lets(trig: &BTreeSet<(usize, bool)>) -> Vec<TokenStream> {
    let joints: BTreeSet<usize> = trig.iter().map(|t| t.0).collect();
    joints
        .iter()
        .map(|&i| {
            let (s, c) = (format_ident!("s{}", i), format_ident!("c{}", i));
            let (has_sin, has_cos) = (trig.contains(&(i, true)), trig.contains(&(i, false)));
            let i = Literal::usize_unsuffixed(i);
            match (has_sin, has_cos) {
                (true, true) => quote!(let (#s, #c) = q[#i].sin_cos();),
                (true, false) => quote!(let #s = q[#i].sin();),
                _ => quote!(let #c = q[#i].cos();),
            }
        })
        .collect()
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
