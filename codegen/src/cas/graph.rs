//! The expression graph: an arena of hash-consed nodes addressed by [`Id`].
//!
//! Every node is interned: building an expression that already exists returns the existing
//! [`Id`], so a subexpression is stored, differentiated, evaluated and emitted once. Children are
//! always created before their parents, so ascending `Id` order is a topological order — every
//! pass over the graph is a simple loop, never a recursion that could overflow the stack.
//!
//! Constructors simplify as they build (see [`Graph::sum`] and [`Graph::product`]): constants
//! fold, nested sums (as [`SumFlattening`] says) and products flatten, like terms and like
//! factors collect, and children are kept sorted by `Id`, so equal expressions built in
//! different orders get the same `Id`.

use std::collections::HashMap;
use std::hash::{BuildHasher, Hash, Hasher};

use hashbrown::HashTable;

/// Handle of a node in a [`Graph`]. Cheap to copy; only meaningful for the graph that made it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Id(u32);

impl Id {
    /// The position of the node in the arena.
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// An `f64` compared and hashed by its bits, with `-0.0` folded into `0.0` so that the two zeros
/// intern as one constant.
#[derive(Clone, Copy, Debug)]
pub struct Num(f64);

impl Num {
    /// Wraps a value, folding `-0.0` into `0.0`.
    pub fn new(v: f64) -> Num {
        Num(if v == 0.0 { 0.0 } else { v })
    }
    /// The value.
    pub fn get(self) -> f64 {
        self.0
    }
}

impl PartialEq for Num {
    fn eq(&self, other: &Num) -> bool {
        self.0.to_bits() == other.0.to_bits()
    }
}
impl Eq for Num {}
impl Hash for Num {
    fn hash<H: Hasher>(&self, h: &mut H) {
        self.0.to_bits().hash(h)
    }
}

/// What a symbol stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum SymbolKind {
    /// Joint position `q_i` (0-based index).
    Q(usize),
    /// Joint velocity `qd_i`.
    Qd(usize),
    /// Joint acceleration `qdd_i`.
    Qdd(usize),
    /// Joint effort `tau_i` (an input of forward dynamics).
    Tau(usize),
    /// Contact force `F_i` (an input of the contact derivatives' partials).
    Force(usize),
    /// Any other named quantity: a mass, a length, an offset.
    Param,
}

/// A symbol: a name for printing and a kind for time derivatives.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Symbol {
    pub name: String,
    pub kind: SymbolKind,
}

/// Index of a symbol in [`Graph::symbols`].
pub type SymbolIndex = u32;

/// A node. Sums and products are n-ary, with children sorted by `Id` and no duplicates.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Node {
    /// A number.
    Const(Num),
    /// A symbol, by its index in [`Graph::symbols`].
    Sym(SymbolIndex),
    /// `constant + sum of coefficient * term`. No term is a constant or a sum; no coefficient is
    /// zero; never a lone term with coefficient 1 and constant 0.
    Add(Num, Box<[(Id, Num)]>),
    /// Product of `factor ^ exponent`. No factor is a constant, a product or a scaled term;
    /// no exponent is zero; never a lone factor with exponent 1. Products carry no coefficient:
    /// `2xy` is the sum `2 * (xy)`.
    Mul(Box<[(Id, i32)]>),
    Sin(Id),
    Cos(Id),
    Sqrt(Id),
    /// -1, 0 or 1 (used for Coulomb friction).
    Sign(Id),
    /// `1 / a` as a value of its own: a product keeps it as a factor instead of merging it into
    /// a division, so that a reciprocal many products share (a factorization's pivot) is
    /// computed once and multiplied.
    Recip(Id),
}

impl Node {
    /// The children of this node, in order.
    pub fn children(&self) -> Children<'_> {
        match self {
            Node::Const(_) | Node::Sym(_) => Children::One(None),
            Node::Add(_, t) => Children::Terms(t.iter()),
            Node::Mul(f) => Children::Factors(f.iter()),
            Node::Sin(a) | Node::Cos(a) | Node::Sqrt(a) | Node::Sign(a) | Node::Recip(a) => {
                Children::One(Some(*a))
            }
        }
    }
}

/// Iterator over a node's children.
pub enum Children<'a> {
    Terms(std::slice::Iter<'a, (Id, Num)>),
    Factors(std::slice::Iter<'a, (Id, i32)>),
    One(Option<Id>),
}

impl Iterator for Children<'_> {
    type Item = Id;
    fn next(&mut self) -> Option<Id> {
        match self {
            Children::Terms(t) => t.next().map(|x| x.0),
            Children::Factors(f) => f.next().map(|x| x.0),
            Children::One(o) => o.take(),
        }
    }
}

/// A fixed, seedless hasher (FxHash): hashing never depends on the process, and nothing iterates
/// the table anyway, so no hash order can reach any output.
#[derive(Clone, Copy, Default)]
pub(crate) struct FxBuild;
pub(crate) struct FxHasher(u64);

impl BuildHasher for FxBuild {
    type Hasher = FxHasher;
    fn build_hasher(&self) -> FxHasher {
        FxHasher(0)
    }
}

impl Hasher for FxHasher {
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut buf = [0u8; 8];
            buf[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(buf));
        }
    }
    fn write_u64(&mut self, v: u64) {
        self.0 = (self.0.rotate_left(5) ^ v).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
    fn write_u32(&mut self, v: u32) {
        self.write_u64(v as u64)
    }
    fn write_usize(&mut self, v: usize) {
        self.write_u64(v as u64)
    }
    fn finish(&self) -> u64 {
        self.0
    }
}

/// The default of [`Limits::max_nodes`].
pub const DEFAULT_MAX_NODES: usize = 50_000_000;

/// Limits that keep a runaway derivation from exhausting memory.
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    /// Most nodes a graph may hold (at least 2: the constants 0 and 1 are always there, and
    /// never more than `u32::MAX`). A graph that is full stops growing instead of panicking:
    /// see [`Graph::check`].
    pub max_nodes: usize,
    /// Sums and products with more children than this are not flattened into their parents
    /// (they stay one term or factor), which keeps building linear in the graph's size.
    pub max_flatten: usize,
}

impl Default for Limits {
    fn default() -> Self {
        // About 3 GB of nodes at the worst; a 48-joint arm needs a few million.
        Limits {
            max_nodes: DEFAULT_MAX_NODES,
            max_flatten: 128,
        }
    }
}

/// How [`Graph::sum`] treats an input that is itself a sum of several terms.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SumFlattening {
    /// Merged into the new sum (up to [`Limits::max_flatten`] terms): like terms collect
    /// across levels, but a sum that several parents use is computed again inside each.
    #[default]
    Always,
    /// Kept as one term, computed once however many sums use it, unless it has a term in
    /// common with another input (then merged, so that the like terms collect). A negation
    /// `-s` is merged, so that a sum and its negation share their terms. On the recursive
    /// algorithms of a 29-joint humanoid this is 40 % fewer operations.
    Shared,
}

/// A graph ran into [`Limits::max_nodes`]: the expressions built since are wrong.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("the expression graph needs more than its limit of {max_nodes} nodes ({nodes} requested)")]
pub struct GraphFull {
    /// The limit in force.
    pub max_nodes: usize,
    /// The nodes held plus the nodes refused: a lower bound of what the work needed.
    pub nodes: usize,
}

/// The arena of interned nodes and the symbol table.
#[derive(Clone)]
pub struct Graph {
    nodes: Vec<Node>,
    memo: HashTable<Id>,
    symbols: Vec<Symbol>,
    limits: Limits,
    /// Nodes that could not be created because the graph was full.
    refused: usize,
    /// How sums built from now on treat child sums.
    flattening: SumFlattening,
    /// Whether products built from now on merge the factors of child products.
    flatten_products: bool,
}

impl Default for Graph {
    fn default() -> Self {
        Graph::new()
    }
}

impl std::fmt::Debug for Graph {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "Graph({} nodes, {} symbols)",
            self.nodes.len(),
            self.symbols.len()
        )
    }
}

fn hash_node(n: &Node) -> u64 {
    FxBuild.hash_one(n)
}

impl Graph {
    /// An empty graph with default [`Limits`].
    pub fn new() -> Graph {
        Graph::with_limits(Limits::default())
    }

    /// An empty graph with the given limits.
    pub fn with_limits(limits: Limits) -> Graph {
        let mut g = Graph {
            nodes: Vec::new(),
            memo: HashTable::new(),
            symbols: Vec::new(),
            limits,
            refused: 0,
            flattening: SumFlattening::Always,
            flatten_products: true,
        };
        // 0 and 1 first, whatever the limit: they are the most common children, and a full
        // graph answers with 0.
        for v in [0.0, 1.0] {
            let node = Node::Const(Num::new(v));
            let h = hash_node(&node);
            let id = Id(g.nodes.len() as u32);
            g.nodes.push(node);
            let nodes = &g.nodes;
            g.memo
                .insert_unique(h, id, |&i| hash_node(&nodes[i.index()]));
        }
        g
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// True for a graph with no nodes (never the case: 0 and 1 are always there).
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The node behind an `Id`.
    pub fn node(&self, id: Id) -> &Node {
        &self.nodes[id.index()]
    }

    /// The symbol table.
    pub fn symbols(&self) -> &[Symbol] {
        &self.symbols
    }

    /// The limits in force.
    pub fn limits(&self) -> Limits {
        self.limits
    }

    /// `Err` once the graph has run into [`Limits::max_nodes`].
    ///
    /// A full graph never panics and never grows: every node it cannot create is replaced by
    /// the constant 0, so that work in progress finishes quickly, but with wrong results. Long
    /// computations call this between steps and give up on `Err`; nothing built since the
    /// limit was hit may be used.
    pub fn check(&self) -> Result<(), GraphFull> {
        if self.refused == 0 {
            Ok(())
        } else {
            Err(GraphFull {
                max_nodes: self.limits.max_nodes,
                nodes: self.nodes.len().saturating_add(self.refused),
            })
        }
    }

    /// Interns a node that is already canonical; in a full graph, answers the constant 0 for
    /// a new node (see [`Graph::check`]).
    fn intern(&mut self, node: Node) -> Id {
        let h = hash_node(&node);
        let nodes = &self.nodes;
        if let Some(&id) = self.memo.find(h, |&id| nodes[id.index()] == node) {
            return id;
        }
        if self.nodes.len() >= self.limits.max_nodes.min(u32::MAX as usize) {
            self.refused = self.refused.saturating_add(1);
            return self.zero();
        }
        let id = Id(self.nodes.len() as u32);
        self.nodes.push(node);
        let nodes = &self.nodes;
        self.memo
            .insert_unique(h, id, |&i| hash_node(&nodes[i.index()]));
        id
    }

    /// A constant. NaN and infinities are stored as they are; `-0.0` becomes `0.0`.
    pub fn constant(&mut self, v: f64) -> Id {
        self.intern(Node::Const(Num::new(v)))
    }

    /// The constant 0.
    pub fn zero(&self) -> Id {
        Id(0)
    }

    /// The constant 1.
    pub fn one(&self) -> Id {
        Id(1)
    }

    /// The value of a constant node.
    pub fn as_const(&self, id: Id) -> Option<f64> {
        match self.node(id) {
            Node::Const(c) => Some(c.get()),
            _ => None,
        }
    }

    /// The symbol of that name and kind, created on first use.
    pub fn symbol(&mut self, name: &str, kind: SymbolKind) -> Id {
        let index = match self
            .symbols
            .iter()
            .position(|s| s.name == name && s.kind == kind)
        {
            Some(i) => i,
            None => {
                self.symbols.push(Symbol {
                    name: name.to_string(),
                    kind,
                });
                self.symbols.len() - 1
            }
        };
        self.intern(Node::Sym(index as SymbolIndex))
    }

    /// Joint position `q_i`, printed `q{i+1}`.
    pub fn q(&mut self, i: usize) -> Id {
        self.symbol(&format!("q{}", i + 1), SymbolKind::Q(i))
    }

    /// Joint velocity `qd_i`, printed `qd{i+1}`.
    pub fn qd(&mut self, i: usize) -> Id {
        self.symbol(&format!("qd{}", i + 1), SymbolKind::Qd(i))
    }

    /// Joint acceleration `qdd_i`, printed `qdd{i+1}`.
    pub fn qdd(&mut self, i: usize) -> Id {
        self.symbol(&format!("qdd{}", i + 1), SymbolKind::Qdd(i))
    }

    /// Joint effort `tau_i`, printed `tau{i+1}`.
    pub fn tau(&mut self, i: usize) -> Id {
        self.symbol(&format!("tau{}", i + 1), SymbolKind::Tau(i))
    }

    /// A contact force `F_i` (an input of the contact derivatives' partials), printed
    /// `force{i+1}`; generated code reads it from its `forces` argument.
    pub fn force(&mut self, i: usize) -> Id {
        self.symbol(&format!("force{}", i + 1), SymbolKind::Force(i))
    }

    /// A named parameter.
    pub fn param(&mut self, name: &str) -> Id {
        self.symbol(name, SymbolKind::Param)
    }

    /// The symbol index of a symbol node.
    pub fn as_symbol(&self, id: Id) -> Option<SymbolIndex> {
        match self.node(id) {
            Node::Sym(s) => Some(*s),
            _ => None,
        }
    }

    /// `constant + sum of coefficient * term`, simplified: constants fold, nested sums flatten
    /// (those [`Graph::flattening`] merges), like terms collect (`2x + 3x = 5x`), zero terms
    /// vanish.
    pub fn sum(&mut self, constant: f64, terms: impl IntoIterator<Item = (Id, f64)>) -> Id {
        let mut c = constant;
        let mut flat: Vec<(Id, f64)> = Vec::new();
        let terms = terms.into_iter().filter(|t| t.1 != 0.0);
        if self.flattening == SumFlattening::Always {
            for (id, k) in terms {
                self.push_term(&mut c, &mut flat, (id, k), true);
            }
        } else {
            let terms: Vec<(Id, f64)> = terms.collect();
            let merge = self.merged_inputs(constant, &terms);
            for (&term, merge) in terms.iter().zip(merge) {
                self.push_term(&mut c, &mut flat, term, merge);
            }
        }
        flat.sort_unstable_by_key(|t| t.0);
        let mut merged: Vec<(Id, Num)> = Vec::with_capacity(flat.len());
        for (id, k) in flat {
            match merged.last_mut() {
                Some(last) if last.0 == id => last.1 = Num::new(last.1.get() + k),
                _ => merged.push((id, Num::new(k))),
            }
        }
        merged.retain(|t| t.1.get() != 0.0);
        match merged.as_slice() {
            [] => self.constant(c),
            [(id, k)] if c == 0.0 && k.get() == 1.0 => *id,
            _ => self.intern(Node::Add(Num::new(c), merged.into_boxed_slice())),
        }
    }

    /// Adds `k * id` to a sum being built: a constant to `c`, a small child sum's terms when
    /// `merge` says so (and it is at most [`Limits::max_flatten`] terms), else the term.
    fn push_term(&self, c: &mut f64, flat: &mut Vec<(Id, f64)>, (id, k): (Id, f64), merge: bool) {
        match &self.nodes[id.index()] {
            Node::Const(v) => *c += k * v.get(),
            Node::Add(c2, ts) if merge && ts.len() <= self.limits.max_flatten => {
                *c += k * c2.get();
                flat.extend(ts.iter().map(|&(t, kt)| (t, k * kt.get())));
            }
            _ => flat.push((id, k)),
        }
    }

    /// Which inputs of a sum are child sums to merge into it under
    /// [`SumFlattening::Shared`]. A child sum of more than [`Limits::max_flatten`] terms stays
    /// one term: merging it into every parent would make building quadratic in its size.
    fn merged_inputs(&self, constant: f64, terms: &[(Id, f64)]) -> Vec<bool> {
        let max = self.limits.max_flatten;
        let child = |id: Id| match &self.nodes[id.index()] {
            Node::Add(_, ts) if ts.len() <= max => Some(ts),
            _ => None,
        };
        let mut merge: Vec<bool> = terms.iter().map(|t| child(t.0).is_some()).collect();
        let negation = constant == 0.0 && terms.len() == 1 && terms[0].1 == -1.0;
        if negation {
            return merge;
        }
        // Scaled terms merge; a sum of several terms only when it collects.
        let several = |id: Id| child(id).is_some_and(|ts| ts.len() > 1);
        if !terms.iter().any(|t| several(t.0)) {
            return merge;
        }
        let mut seen: HashMap<Id, u32, FxBuild> = HashMap::with_hasher(FxBuild);
        for &(id, _) in terms {
            match child(id).filter(|ts| ts.len() > 1) {
                Some(ts) => ts.iter().for_each(|t| *seen.entry(t.0).or_default() += 1),
                None => *seen.entry(id).or_default() += 1,
            }
        }
        for (m, &(id, _)) in merge.iter_mut().zip(terms) {
            if let Some(ts) = child(id).filter(|ts| ts.len() > 1) {
                *m = ts.iter().any(|t| seen[&t.0] > 1);
            }
        }
        merge
    }

    /// Sets how sums built from now on treat child sums ([`SumFlattening`]) and returns the
    /// previous setting. Values are the same either way; only the expressions' shape, and so
    /// the operation count of generated code, differ.
    pub fn set_flattening(&mut self, f: SumFlattening) -> SumFlattening {
        std::mem::replace(&mut self.flattening, f)
    }

    /// Sets whether products built from now on merge the factors of child products (`x (y z)`
    /// as `x y z`, the default) or keep a child product as one factor, computed once however
    /// many products use it; returns the previous setting.
    pub fn set_product_flattening(&mut self, on: bool) -> bool {
        std::mem::replace(&mut self.flatten_products, on)
    }

    /// How sums treat child sums now.
    pub fn flattening(&self) -> SumFlattening {
        self.flattening
    }

    /// Product of `factor ^ exponent`, simplified: constants fold into a coefficient, nested
    /// products flatten, like factors collect (`x * x = x^2`, `x / x = 1`), anything times 0 is 0.
    pub fn product(&mut self, factors: impl IntoIterator<Item = (Id, i32)>) -> Id {
        let mut coef = 1.0f64;
        let mut flat: Vec<(Id, i32)> = Vec::new();
        let mut work: Vec<(Id, i32)> = factors.into_iter().collect();
        while let Some((id, e)) = work.pop() {
            if e == 0 {
                continue;
            }
            // A sum whose first term is negative enters as -1 times its negation, so that
            // `x y` and `x (-y)` share one sum `y` (computed once, the sign in the coefficient).
            if self.negative_sum(id) {
                coef *= (-1.0f64).powi(e);
                let pos = self.scale(id, -1.0);
                work.push((pos, e));
                continue;
            }
            match &self.nodes[id.index()] {
                Node::Const(v) => coef *= v.get().powi(e),
                Node::Mul(fs) if self.flatten_products && fs.len() <= self.limits.max_flatten => {
                    work.extend(fs.iter().map(|&(f, fe)| (f, fe * e)))
                }
                // A scaled term k * t: pull k into the coefficient.
                Node::Add(c0, ts) if c0.get() == 0.0 && ts.len() == 1 => {
                    coef *= ts[0].1.get().powi(e);
                    work.push((ts[0].0, e));
                }
                _ => flat.push((id, e)),
            }
        }
        if coef == 0.0 {
            return self.zero();
        }
        flat.sort_unstable_by_key(|f| f.0);
        let mut merged: Vec<(Id, i32)> = Vec::with_capacity(flat.len());
        for (id, e) in flat {
            match merged.last_mut() {
                Some(last) if last.0 == id => last.1 += e,
                _ => merged.push((id, e)),
            }
        }
        merged.retain(|f| f.1 != 0);
        let core = match merged.as_slice() {
            [] => return self.constant(coef),
            [(id, 1)] => *id,
            _ => self.intern(Node::Mul(merged.into_boxed_slice())),
        };
        self.scale(core, coef)
    }

    /// Whether `id` is a sum of several terms (or a term and a constant) whose first term has a
    /// negative coefficient, small enough that its negation is flattened.
    fn negative_sum(&self, id: Id) -> bool {
        match &self.nodes[id.index()] {
            Node::Add(c, ts) => {
                (ts.len() > 1 || c.get() != 0.0)
                    && ts.len() <= self.limits.max_flatten
                    && ts[0].1.get() < 0.0
            }
            _ => false,
        }
    }

    /// `k * a`.
    pub fn scale(&mut self, a: Id, k: f64) -> Id {
        if k == 1.0 {
            a
        } else {
            self.sum(0.0, [(a, k)])
        }
    }

    /// `a + b`.
    pub fn add(&mut self, a: Id, b: Id) -> Id {
        self.sum(0.0, [(a, 1.0), (b, 1.0)])
    }

    /// `a - b`.
    pub fn sub(&mut self, a: Id, b: Id) -> Id {
        self.sum(0.0, [(a, 1.0), (b, -1.0)])
    }

    /// `-a`.
    pub fn neg(&mut self, a: Id) -> Id {
        self.scale(a, -1.0)
    }

    /// `a * b`.
    pub fn mul(&mut self, a: Id, b: Id) -> Id {
        self.product([(a, 1), (b, 1)])
    }

    /// `a / b` (`b^-1` as a factor; `x / x` simplifies to 1 without asking whether x is zero).
    pub fn div(&mut self, a: Id, b: Id) -> Id {
        self.product([(a, 1), (b, -1)])
    }

    /// `a ^ n` for an integer `n`.
    pub fn powi(&mut self, a: Id, n: i32) -> Id {
        self.product([(a, n)])
    }

    /// Sum of several expressions.
    pub fn add_all(&mut self, items: impl IntoIterator<Item = Id>) -> Id {
        self.sum(0.0, items.into_iter().map(|i| (i, 1.0)))
    }

    /// Splits `k * t` into `(k, t)`; anything else is `(1, a)`.
    pub fn split_coefficient(&self, a: Id) -> (f64, Id) {
        match self.node(a) {
            Node::Add(c, ts) if c.get() == 0.0 && ts.len() == 1 => (ts[0].1.get(), ts[0].0),
            _ => (1.0, a),
        }
    }

    /// `sin a`; folds constants and pulls out a negative coefficient (`sin(-x) = -sin x`).
    pub fn sin(&mut self, a: Id) -> Id {
        if let Some(v) = self.as_const(a) {
            return self.constant(v.sin());
        }
        let (k, _) = self.split_coefficient(a);
        if k < 0.0 {
            let pos = self.neg(a);
            let s = self.intern(Node::Sin(pos));
            return self.neg(s);
        }
        self.intern(Node::Sin(a))
    }

    /// `cos a`; folds constants and drops a negative coefficient (`cos(-x) = cos x`).
    pub fn cos(&mut self, a: Id) -> Id {
        if let Some(v) = self.as_const(a) {
            return self.constant(v.cos());
        }
        let (k, _) = self.split_coefficient(a);
        if k < 0.0 {
            let pos = self.neg(a);
            return self.intern(Node::Cos(pos));
        }
        self.intern(Node::Cos(a))
    }

    /// `1 / a` kept apart from products ([`Node::Recip`]); folds constants.
    pub fn recip(&mut self, a: Id) -> Id {
        if let Some(v) = self.as_const(a) {
            return self.constant(1.0 / v);
        }
        self.intern(Node::Recip(a))
    }

    /// `sqrt a`; folds constants.
    pub fn sqrt(&mut self, a: Id) -> Id {
        if let Some(v) = self.as_const(a) {
            return self.constant(v.sqrt());
        }
        self.intern(Node::Sqrt(a))
    }

    /// `sign a` (-1, 0 or 1); folds constants.
    pub fn sign(&mut self, a: Id) -> Id {
        if let Some(v) = self.as_const(a) {
            let s = if v > 0.0 {
                1.0
            } else if v < 0.0 {
                -1.0
            } else {
                0.0
            };
            return self.constant(s);
        }
        self.intern(Node::Sign(a))
    }

    /// Dot product of two vectors of expressions.
    pub fn dot(&mut self, a: &[Id], b: &[Id]) -> Id {
        let terms: Vec<Id> = a.iter().zip(b).map(|(&x, &y)| self.mul(x, y)).collect();
        self.add_all(terms)
    }

    /// Ids of every node reachable from `roots`, ascending (so children before parents).
    ///
    /// Costs time in proportion to the nodes reached, not to the size of the graph: a robot
    /// with thousands of links asks for thousands of small programs from one big graph.
    pub fn reachable(&self, roots: &[Id]) -> Vec<Id> {
        // Children precede parents: nothing reachable lies above the highest root.
        let top = roots.iter().map(|r| r.index() + 1).max().unwrap_or(0);
        let mut seen = vec![false; top];
        let mut found = Vec::new();
        let mut stack: Vec<Id> = roots.to_vec();
        while let Some(id) = stack.pop() {
            if std::mem::replace(&mut seen[id.index()], true) {
                continue;
            }
            found.push(id);
            stack.extend(self.node(id).children().filter(|c| !seen[c.index()]));
        }
        found.sort_unstable();
        found
    }

    /// True when `e` contains the symbol node `x`.
    pub fn depends_on(&self, e: Id, x: Id) -> bool {
        // Children precede parents, so nothing above x can be below it.
        if e < x {
            return false;
        }
        self.reachable(&[e]).binary_search(&x).is_ok()
    }
}
