//! Bodies beyond the operation budget, as a chain of non-inlined blocks.
//!
//! LLVM's SLP vectorizer schedules every basic block as a whole, at a cost that grows with the
//! square of the block's length; for the native CPU (`-C target-cpu=native`: wide vectors, and
//! the FMA intrinsic behind `Real::mul_add`, whose vector operands seed it) a straight-line
//! body of tens of thousands of operations took LLVM tens of minutes. A program over the budget
//! is therefore cut into consecutive blocks of about `budget` operations, each an
//! `#[inline(never)]` method, so that compile cost grows linearly with the program (RobCoGen's
//! generated code does the same per link, with explicit intermediate state):
//!
//! - a block reads what it needs of earlier blocks from a work array `w` at its start, computes
//!   its temporaries, writes the outputs it completes straight into the result `o`, and at its
//!   end writes into `w` the values later blocks read (the first block returns `w` instead);
//! - a slot of `w` is reused once the last block reading its value has run, so that `w` holds
//!   about as many values as cross one cut at a time;
//! - each joint angle's sine and cosine are computed once, in the first block that uses them,
//!   and travel like temporaries;
//! - the blocks write the caller's storage for the result (`eomgen_runtime::place`), not a
//!   local copied out at the end, and a quantity built on this one (forward-dynamics
//!   derivatives on inverse-dynamics derivatives) has them fill its own result's matrices
//!   (`{name}_fill`).

use std::collections::{BTreeMap, BTreeSet};

use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote, ToTokens};

use super::body::{chunked_lets, filled, shape_type, trig_lets};
use super::expr::Ctx;
use crate::cas::{Expr, Program};
use crate::dynamics::Shape;

/// What a split body needs to know of the function it belongs to.
pub(super) struct Split<'a> {
    /// The function's name; its blocks are `{name}_block_{k}`.
    pub name: &'a str,
    /// The function's parameters (`q: &[T; 9]`, ...), which every block takes too.
    pub params: &'a [TokenStream],
    /// Their names, to pass them on.
    pub args: &'a [Ident],
    /// The most operations one block may hold (a block holds at least one temporary).
    pub budget: usize,
    /// For a [`Shape::Matrix`] result, consecutive groups of its rows that `{name}_fill` takes
    /// as separate matrices (`o0`, `o1`, ...), so that a caller can have them written into
    /// different places; empty: the whole matrix (`o`).
    pub rows: &'a [usize],
    /// How many of the first [`Split::rows`] groups `{name}_fill` adds onto the matrices it is
    /// given (`+=`, the zero outputs skipped) instead of setting them: the contact partials'
    /// rows in `q`, added onto the inverse-dynamics derivatives where they lie.
    pub adds: usize,
    /// Another generated function has this one fill its result's storage (`{name}_fill`): the
    /// body is written in blocks even under the budget (one block then), so that the method
    /// exists and the result is not built in a local and copied.
    pub filled: bool,
}

/// A value crossing blocks: a temporary or a joint angle's sine or cosine.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Value {
    Temp(usize),
    /// Joint `.0`'s sine (`true`) or cosine.
    Trig(usize, bool),
}

impl Value {
    fn ident(self) -> Ident {
        match self {
            Value::Temp(k) => format_ident!("t{}", k),
            Value::Trig(i, true) => format_ident!("s{}", i),
            Value::Trig(i, false) => format_ident!("c{}", i),
        }
    }
}

/// The temporaries an expression reads.
fn temps_read(e: &Expr, out: &mut BTreeSet<usize>) {
    match e {
        Expr::Temp(t) => {
            out.insert(*t);
        }
        Expr::Const(_) | Expr::Input(_) => {}
        Expr::Add(_, ts) => ts.iter().for_each(|(t, _)| temps_read(t, out)),
        Expr::Mul(fs) => fs.iter().for_each(|(f, _)| temps_read(f, out)),
        Expr::Sin(a) | Expr::Cos(a) | Expr::Sqrt(a) | Expr::Sign(a) | Expr::Recip(a) => {
            temps_read(a, out)
        }
    }
}

/// Block of each temporary: consecutive runs of at most `budget` operations, each cut where the
/// fewest temporaries are live (computed before it and read after it) among the places that
/// leave the block at least half the budget, so that little crosses through `w`.
fn cut(program: &Program, budget: usize) -> Vec<usize> {
    let n = program.temps.len();
    let ops: Vec<usize> = program.temps.iter().map(|e| e.ops().total()).collect();
    let live = live_after(program);
    let mut of_temp = vec![0; n];
    let (mut start, mut block) = (0, 0);
    while start < n {
        // The block is start..=end: the end with the fewest live values once half full.
        let (mut acc, mut end) = (0, start);
        let mut best: Option<usize> = None;
        for k in start..n {
            if k > start && acc + ops[k] > budget {
                break;
            }
            acc += ops[k];
            end = k;
            if 2 * acc >= budget && best.is_none_or(|b| live[k] <= live[b]) {
                best = Some(k);
            }
        }
        let end = if end + 1 == n {
            end
        } else {
            best.unwrap_or(end)
        };
        of_temp[start..=end].iter_mut().for_each(|b| *b = block);
        (start, block) = (end + 1, block + 1);
    }
    of_temp
}

/// For each temporary `k`, how many of `temps[..=k]` are read after it (by a later temporary
/// or by an output, which comes after every temporary it reads).
fn live_after(program: &Program) -> Vec<usize> {
    let n = program.temps.len();
    // The last temporary (or output, as the last temporary it reads) that reads each one.
    let mut last: Vec<usize> = (0..n).collect();
    let mut read = BTreeSet::new();
    for (k, e) in program.temps.iter().enumerate() {
        read.clear();
        temps_read(e, &mut read);
        read.iter().for_each(|&t| last[t] = last[t].max(k));
    }
    for e in &program.outputs {
        read.clear();
        temps_read(e, &mut read);
        // An output goes in the block of the last temporary it reads, so it keeps the others
        // live until that one.
        let at = read.iter().max().copied();
        read.iter()
            .for_each(|&t| last[t] = last[t].max(at.unwrap_or(t)));
    }
    let mut delta = vec![0i64; n + 1];
    for (k, &l) in last.iter().enumerate() {
        if l > k {
            delta[k] += 1;
            delta[l] -= 1;
        }
    }
    let mut live = Vec::with_capacity(n);
    let mut count = 0i64;
    for d in &delta[..n] {
        count += d;
        live.push(count as usize);
    }
    live
}

/// One block's code before the values crossing blocks are placed in `w`.
struct Block {
    /// Temporaries and output assignments.
    code: Vec<TokenStream>,
    /// Trig values it reads.
    trig: BTreeSet<(usize, bool)>,
    /// Values of earlier blocks it reads.
    reads: BTreeSet<Value>,
}

/// The blocks of an over-budget `program` and the body calling them in turn. The body ends in
/// the result, of `shape`.
pub(super) fn split_body(
    cx: &Ctx<'_>,
    program: &Program,
    shape: Shape,
    split: &Split<'_>,
) -> (TokenStream, Vec<TokenStream>) {
    let of_temp = cut(program, split.budget);
    let count = of_temp.last().map_or(1, |b| b + 1);
    let mut blocks: Vec<Block> = (0..count)
        .map(|_| Block {
            code: Vec::new(),
            trig: BTreeSet::new(),
            reads: BTreeSet::new(),
        })
        .collect();
    // Temporaries, each in its block.
    let mut defs: Vec<Vec<(Ident, TokenStream)>> = vec![Vec::new(); count];
    for (k, e) in program.temps.iter().enumerate() {
        let b = of_temp[k];
        let ts = cx.expr(e, &mut blocks[b].trig).ts;
        defs[b].push((format_ident!("t{}", k), ts));
        blocks[b].reads.extend(earlier_temps(e, b, &of_temp));
    }
    for (b, d) in defs.iter().enumerate() {
        blocks[b].code = chunked_lets(d);
    }
    // Outputs, each in the block of the last temporary it reads; in order through
    // `place::Outputs` when one block writes them all ([`sequential`]).
    let seq = sequential(count, shape, split.rows);
    if seq.is_some() {
        blocks[0].code.push(quote!(let mut e = out.entries();));
    }
    for (j, e) in program.outputs.iter().enumerate() {
        let mut read = BTreeSet::new();
        temps_read(e, &mut read);
        let b = read.iter().map(|&t| of_temp[t]).max().unwrap_or(0);
        let ts = match e {
            Expr::Const(c) => super::expr::assigned_lit(*c),
            _ => cx.expr(e, &mut blocks[b].trig).ts,
        };
        let place = output_place(shape, j, split.rows);
        if seq.is_some() {
            blocks[b].code.push(quote!(e.put(#ts);));
        } else if row_group(shape, j, split.rows).is_some_and(|(g, _)| g < split.adds) {
            if !matches!(e, Expr::Const(c) if *c == 0.0) {
                blocks[b].code.push(quote!(#place += #ts;));
            }
        } else {
            blocks[b].code.push(quote!(#place = #ts;));
        }
        blocks[b].reads.extend(earlier_temps(e, b, &of_temp));
    }
    let out = match seq {
        Some(outputs) => Out::InOrder(outputs),
        None => Out::Params(out_params(shape, split.rows).1),
    };
    let first_trig = trig_homes(&mut blocks);
    let home = |v: Value| match v {
        Value::Temp(t) => of_temp[t],
        Value::Trig(i, _) => first_trig[&i],
    };
    let (slots, width) = place_values(&blocks, home);
    let mut items: Vec<TokenStream> = blocks
        .iter()
        .enumerate()
        .map(|(b, block)| {
            let writes: Vec<Value> = slots.keys().filter(|&&v| home(v) == b).copied().collect();
            block_fn(b, block, &slots, &writes, width, split, &out)
        })
        .collect();
    let in_order = matches!(out, Out::InOrder(_));
    let (body, drivers) = drive(split, count, width, shape, in_order);
    items.extend(drivers);
    (body, items)
}

/// The body of a split function and the methods calling its blocks in turn: `{name}_fill`
/// (given the result's storage, every output of which the blocks write) and, where the result
/// is an array or a pair or triple of matrices, `{name}_in_place`, which fills the caller's
/// storage through `eomgen_runtime::place` so that the result is not built in a local and
/// copied out (a derivative of a 50-DoF robot is 40 kB).
fn drive(
    split: &Split<'_>,
    count: usize,
    width: usize,
    shape: Shape,
    in_order: bool,
) -> (TokenStream, Vec<TokenStream>) {
    let (args, params) = (split.args, split.params);
    let (outs, out_params) = out_params(shape, split.rows);
    let mut work = work_array(width);
    let first = block_name(split.name, 0);
    // One block writing the entries in order ([`sequential`]) is lent the matrices.
    let calls = if in_order {
        vec![
            quote!(::eomgen_runtime::place::refill([#(#outs),*], |out| self.#first(#(#args,)* &mut w, out));),
        ]
    } else {
        let starts = starts_work(0, width, in_order);
        if starts {
            work = quote!(let mut w = self.#first(#(#args,)* #(#outs),*););
        }
        (usize::from(starts)..count)
            .map(|b| {
                let f = block_name(split.name, b);
                quote!(self.#f(#(#args,)* &mut w, #(#outs),*);)
            })
            .collect()
    };
    let fill = fill_name(split.name);
    // Not inlined: its work array then lives only while the blocks run, not in the frame of a
    // caller that goes on to other work (contact dynamics derivatives).
    let fill_fn = quote! {
        #[inline(never)]
        fn #fill(&self, #(#params,)* #(#out_params),*) {
            #work
            #(#calls)*
        }
    };
    if !in_place(shape) {
        let zero = filled(quote!(T::zero()), shape);
        let body = quote! {
            let mut o = #zero;
            self.#fill(#(#args,)* &mut o);
            o
        };
        return (body, vec![fill_fn]);
    }
    let in_place = format_ident!("{}_in_place", split.name);
    let ret = shape_type(shape);
    let call = quote!(self.#fill(#(#args,)* #(#outs),*););
    let fill_call = match shape {
        Shape::Matrices(..) => quote!(let (#(#outs),*) = o; #call),
        Shape::Matrix(..) if !split.rows.is_empty() => row_groups(split.rows, call),
        _ => call,
    };
    let fill_slot = if in_order {
        quote!(#work self.#first(#(#args,)* &mut w, slot.outputs()))
    } else {
        quote!(let (o, filled) = slot.fill(); #fill_call filled)
    };
    let in_place_fn = quote! {
        #[inline(never)]
        fn #in_place<'b>(&self, #(#params,)* slot: ::eomgen_runtime::place::Slot<'b, #ret>) -> ::eomgen_runtime::place::Filled<'b> {
            #fill_slot
        }
    };
    let body = quote!(::eomgen_runtime::place::build(|slot| self.#in_place(#(#args,)* slot)));
    (body, vec![fill_fn, in_place_fn])
}

/// `eomgen_runtime::place::Outputs<'b, T, K, R, C>` for a result of `shape` written by one
/// block (`count`), entry after entry, instead of into storage zeroed first: a matrix or two
/// or three, not split in row groups. Zeroing anymal's inverse-dynamics derivatives (5.2 kB)
/// first took 4 % of their time.
fn sequential(count: usize, shape: Shape, rows: &[usize]) -> Option<TokenStream> {
    let lit = Literal::usize_unsuffixed;
    let (k, r, c) = match shape {
        Shape::Matrix(r, c) => (1, r, c),
        Shape::Matrices(k, r, c) if (2..=3).contains(&k) => (k, r, c),
        _ => return None,
    };
    (count == 1 && rows.is_empty()).then(|| {
        let (k, r, c) = (lit(k), lit(r), lit(c));
        quote!(::eomgen_runtime::place::Outputs<'b, T, #k, #r, #c>)
    })
}

/// Where a block writes the outputs it computes.
enum Out {
    /// Into the matrices these parameters declare (`o`, or `o0`, `o1`, ...), by index.
    Params(Vec<TokenStream>),
    /// Entry after entry into `out`, of this `place::Outputs` type ([`sequential`]).
    InOrder(TokenStream),
}

/// The blocks' work array `w` of `width` values.
fn work_array(width: usize) -> TokenStream {
    if width == 0 {
        quote!(let mut w: [T; 0] = [];)
    } else {
        let width = Literal::usize_unsuffixed(width);
        quote!(let mut w = [T::zero(); #width];)
    }
}

/// Whether `eomgen_runtime::place` can hold a result of `shape` (its `Zeroed` types).
fn in_place(shape: Shape) -> bool {
    match shape {
        Shape::Scalar => false,
        Shape::Vector(_) | Shape::Matrix(..) => true,
        Shape::Matrices(k, ..) => (2..=3).contains(&k),
    }
}

/// The method filling the result of the split function `name` in place (see [`drive`]): its
/// parameters are the function's, then one `&mut` per matrix of a [`Shape::Matrices`] result
/// (`o0`, `o1`, ...) or the whole result (`o`).
pub(super) fn fill_name(name: &str) -> Ident {
    format_ident!("{}_fill", name)
}

/// `call` with `o0`, `o1`, ... bound to the consecutive groups of `rows` rows of the matrix
/// `o` (`split_first_chunk_mut`, which cannot fail here: the groups sum to its rows).
fn row_groups(rows: &[usize], call: TokenStream) -> TokenStream {
    rows.iter().enumerate().rev().fold(call, |inner, (g, &n)| {
        let (o, n) = (format_ident!("o{}", g), Literal::usize_unsuffixed(n));
        let rest = if g == 0 {
            quote!(o)
        } else {
            format_ident!("rest{}", g - 1).into_token_stream()
        };
        let next = format_ident!("rest{}", g);
        quote! {
            if let Some((#o, #next)) = #rest.split_first_chunk_mut::<#n>() {
                let _ = &#next;
                #inner
            }
        }
    })
}

/// The output parameters of blocks and of `{name}_fill`: their names and declarations.
fn out_params(shape: Shape, rows: &[usize]) -> (Vec<Ident>, Vec<TokenStream>) {
    match shape {
        Shape::Matrix(_, c) if !rows.is_empty() => rows
            .iter()
            .enumerate()
            .map(|(g, &n)| {
                let one = shape_type(Shape::Matrix(n, c));
                let o = format_ident!("o{}", g);
                (o.clone(), quote!(#o: &mut #one))
            })
            .unzip(),
        Shape::Matrices(k, r, c) => {
            let one = shape_type(Shape::Matrix(r, c));
            (0..k)
                .map(|m| {
                    let o = format_ident!("o{}", m);
                    (o.clone(), quote!(#o: &mut #one))
                })
                .unzip()
        }
        _ => {
            let ret = shape_type(shape);
            (vec![format_ident!("o")], vec![quote!(o: &mut #ret)])
        }
    }
}

/// The temporaries `e` reads that blocks before block `b` compute.
fn earlier_temps(e: &Expr, b: usize, of_temp: &[usize]) -> Vec<Value> {
    let mut read = BTreeSet::new();
    temps_read(e, &mut read);
    read.into_iter()
        .filter(|&t| of_temp[t] < b)
        .map(Value::Temp)
        .collect()
}

fn block_name(name: &str, b: usize) -> Ident {
    format_ident!("{}_block_{}", name, b)
}

/// Each joint angle's first block (the one that computes its sine and cosine); the blocks
/// after it read them.
fn trig_homes(blocks: &mut [Block]) -> BTreeMap<usize, usize> {
    let mut first = BTreeMap::new();
    for (b, block) in blocks.iter().enumerate() {
        for &(i, _) in &block.trig {
            first.entry(i).or_insert(b);
        }
    }
    for (b, block) in blocks.iter_mut().enumerate() {
        let later: Vec<Value> = block
            .trig
            .iter()
            .filter(|t| first[&t.0] < b)
            .map(|&(i, s)| Value::Trig(i, s))
            .collect();
        block.reads.extend(later);
    }
    first
}

/// Slots of `w` for the values read by a later block than their own, reused once their last
/// reader has run; and the number of slots.
fn place_values(
    blocks: &[Block],
    home: impl Fn(Value) -> usize,
) -> (BTreeMap<Value, usize>, usize) {
    // Each crossing value's last reader.
    let mut last: BTreeMap<Value, usize> = BTreeMap::new();
    for (b, block) in blocks.iter().enumerate() {
        for &v in &block.reads {
            last.insert(v, b);
        }
    }
    let mut by_home: BTreeMap<usize, Vec<Value>> = BTreeMap::new();
    for &v in last.keys() {
        by_home.entry(home(v)).or_default().push(v);
    }
    let (mut slots, mut free, mut busy) = (BTreeMap::new(), BTreeSet::new(), Vec::new());
    let mut width = 0;
    for (b, values) in by_home {
        // Reads come first in a block, writes last: a slot read for the last time in block b
        // can take a value block b writes.
        busy.retain(|&(end, slot)| {
            let done = end <= b;
            if done {
                free.insert(slot);
            }
            !done
        });
        for v in values {
            let slot = free.pop_first().unwrap_or_else(|| {
                width += 1;
                width - 1
            });
            slots.insert(v, slot);
            busy.push((last[&v], slot));
        }
    }
    (slots, width)
}

/// Block `b` as an `#[inline(never)]` method.
fn block_fn(
    b: usize,
    block: &Block,
    slots: &BTreeMap<Value, usize>,
    writes: &[Value],
    width: usize,
    split: &Split<'_>,
    out: &Out,
) -> TokenStream {
    let slot = |v: &Value| Literal::usize_unsuffixed(slots[v]);
    let reads = block.reads.iter().map(|v| {
        let (name, s) = (v.ident(), slot(v));
        quote!(let #name = w[#s];)
    });
    // Sines and cosines computed here: those this block uses and does not read, and those it
    // writes for later blocks.
    let mut computed: BTreeSet<(usize, bool)> = block
        .trig
        .iter()
        .filter(|&&(i, s)| !block.reads.contains(&Value::Trig(i, s)))
        .copied()
        .collect();
    computed.extend(writes.iter().filter_map(|v| match *v {
        Value::Trig(i, s) => Some((i, s)),
        Value::Temp(_) => None,
    }));
    let trig = trig_lets(&computed);
    let block_writes = writes;
    let writes = writes.iter().map(|v| {
        let (name, s) = (v.ident(), slot(v));
        quote!(w[#s] = #name;)
    });
    let code = &block.code;
    let (name, params) = (block_name(split.name, b), split.params);
    if let Out::Params(outs) = out {
        if starts_work(b, width, false) {
            debug_assert!(block.reads.is_empty());
            let at = block_writes.iter().map(|v| (slots[v], v.ident())).collect();
            let body = quote!(#(#trig)* #(#code)*);
            return first_block_fn(&name, params, outs, body, (width, &at));
        }
    }
    let width = Literal::usize_unsuffixed(width);
    let outs = match out {
        Out::Params(outs) => outs,
        Out::InOrder(outputs) => {
            return quote! {
                #[inline(never)]
                fn #name<'b>(&self, #(#params,)* w: &mut [T; #width], out: #outputs) -> ::eomgen_runtime::place::Filled<'b> {
                    #(#reads)*
                    #(#trig)*
                    #(#code)*
                    #(#writes)*
                    e.finish()
                }
            };
        }
    };
    quote! {
        #[inline(never)]
        fn #name(&self, #(#params,)* w: &mut [T; #width], #(#outs),*) {
            #(#reads)*
            #(#trig)*
            #(#code)*
            #(#writes)*
        }
    }
}

/// Whether block `b` returns the work array (of `width` values) instead of writing into one:
/// the first of several blocks, unless one block writes the entries in order. The work array
/// then starts as that block's values, not as zeros overwritten (anymal's contact forward
/// dynamics zeroed 323 values, 2 % of its time).
fn starts_work(b: usize, width: usize, in_order: bool) -> bool {
    b == 0 && width > 0 && !in_order
}

/// The first block `name` of [`starts_work`]: `body` (its temporaries and outputs, written into
/// `outs`), then the work array of `width` values, each slot its value of `at` or zero.
fn first_block_fn(
    name: &Ident,
    params: &[TokenStream],
    outs: &[TokenStream],
    body: TokenStream,
    (width, at): (usize, &BTreeMap<usize, Ident>),
) -> TokenStream {
    let entries = (0..width).map(|s| match at.get(&s) {
        Some(name) => quote!(#name),
        None => quote!(T::zero()),
    });
    let width = Literal::usize_unsuffixed(width);
    quote! {
        #[inline(never)]
        fn #name(&self, #(#params,)* #(#outs),*) -> [T; #width] {
            #body
            [#(#entries),*]
        }
    }
}

/// The row group of [`Split::rows`] that output `j` of a [`Shape::Matrix`] result falls in,
/// and its row in that group; `None` without groups.
fn row_group(shape: Shape, j: usize, rows: &[usize]) -> Option<(usize, usize)> {
    let Shape::Matrix(_, c) = shape else {
        return None;
    };
    if rows.is_empty() || c == 0 {
        return None;
    }
    let (mut i, mut g) = (j / c, 0);
    while g + 1 < rows.len() && i >= rows[g] {
        i -= rows[g];
        g += 1;
    }
    Some((g, i))
}

/// Where flat output `j` of a result of `shape` goes in `o`.
fn output_place(shape: Shape, j: usize, rows: &[usize]) -> TokenStream {
    let lit = Literal::usize_unsuffixed;
    match shape {
        Shape::Matrix(_, c) if !rows.is_empty() => {
            let (g, i) = row_group(shape, j, rows).unwrap_or((0, j / c));
            let (o, i, col) = (format_ident!("o{}", g), lit(i), lit(j % c));
            quote!(#o[#i][#col])
        }
        Shape::Scalar => quote!(*o),
        Shape::Vector(_) => {
            let j = lit(j);
            quote!(o[#j])
        }
        Shape::Matrix(_, c) => {
            let (i, j) = (lit(j / c), lit(j % c));
            quote!(o[#i][#j])
        }
        Shape::Matrices(_, r, c) => {
            let (m, e) = (format_ident!("o{}", j / (r * c)), j % (r * c));
            let (i, j) = (lit(e / c), lit(e % c));
            quote!(#m[#i][#j])
        }
    }
}
