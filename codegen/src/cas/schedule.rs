//! Straight-line programs: the outputs of a graph as a list of temporaries, then outputs.
//!
//! Every distinct subexpression reachable from the outputs is computed once. A node used more
//! than once gets a temporary; a node used once is written inline into its single user (up to a
//! small nesting depth, so that expressions stay readable and printing never recurses deeply).
//! Nodes that no output needs are dropped.

use std::collections::HashMap;
use std::fmt;

use super::eval::{powi, sign};
use super::graph::{Graph, Id, Node, Symbol, SymbolIndex};
use super::UnboundSymbol;

/// An expression of a straight-line program.
#[derive(Clone, Debug, PartialEq)]
pub enum Expr {
    Const(f64),
    /// A symbol, by its index in [`Program::symbols`].
    Input(SymbolIndex),
    /// An earlier temporary.
    Temp(usize),
    /// `constant + sum of coefficient * term`.
    Add(f64, Vec<(Expr, f64)>),
    /// Product of `factor ^ exponent`.
    Mul(Vec<(Expr, i32)>),
    Sin(Box<Expr>),
    Cos(Box<Expr>),
    Sqrt(Box<Expr>),
    Sign(Box<Expr>),
    /// `1 / a` ([`Node::Recip`](super::graph::Node::Recip)), one division.
    Recip(Box<Expr>),
}

/// Operation counts of a program, the cost model for generated code.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OpCount {
    /// Additions and subtractions.
    pub add: usize,
    /// Multiplications (including those of integer powers and coefficients).
    pub mul: usize,
    pub div: usize,
    pub sin: usize,
    pub cos: usize,
    pub sqrt: usize,
    pub sign: usize,
}

impl OpCount {
    /// All operations together.
    pub fn total(&self) -> usize {
        self.add + self.mul + self.div + self.sin + self.cos + self.sqrt + self.sign
    }
}

impl std::ops::AddAssign for OpCount {
    fn add_assign(&mut self, o: OpCount) {
        self.add += o.add;
        self.mul += o.mul;
        self.div += o.div;
        self.sin += o.sin;
        self.cos += o.cos;
        self.sqrt += o.sqrt;
        self.sign += o.sign;
    }
}

impl fmt::Display for OpCount {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} mul, {} add, {} div, {} sin, {} cos",
            self.mul, self.add, self.div, self.sin, self.cos
        )?;
        if self.sqrt > 0 {
            write!(f, ", {} sqrt", self.sqrt)?;
        }
        if self.sign > 0 {
            write!(f, ", {} sign", self.sign)?;
        }
        Ok(())
    }
}

impl Expr {
    /// Operations needed to evaluate this expression once its temporaries are known.
    pub fn ops(&self) -> OpCount {
        let mut n = OpCount::default();
        self.count(&mut n);
        n
    }

    fn count(&self, n: &mut OpCount) {
        match self {
            Expr::Const(_) | Expr::Input(_) | Expr::Temp(_) => {}
            Expr::Add(c, ts) => {
                n.add += ts.len() - 1 + usize::from(*c != 0.0);
                for (t, k) in ts {
                    n.mul += usize::from(k.abs() != 1.0);
                    t.count(n);
                }
            }
            Expr::Mul(fs) => {
                let (mut num, mut den) = (0usize, 0usize);
                for (f, e) in fs {
                    n.mul += e.unsigned_abs() as usize - 1;
                    if *e > 0 {
                        num += 1;
                    } else {
                        den += 1;
                    }
                    f.count(n);
                }
                n.mul += num.saturating_sub(1) + den.saturating_sub(1);
                n.div += usize::from(den > 0);
            }
            Expr::Sin(a) => {
                n.sin += 1;
                a.count(n)
            }
            Expr::Cos(a) => {
                n.cos += 1;
                a.count(n)
            }
            Expr::Sqrt(a) => {
                n.sqrt += 1;
                a.count(n)
            }
            Expr::Sign(a) => {
                n.sign += 1;
                a.count(n)
            }
            Expr::Recip(a) => {
                n.div += 1;
                a.count(n)
            }
        }
    }

    fn eval(&self, inputs: &[f64], temps: &[f64]) -> f64 {
        match self {
            Expr::Const(c) => *c,
            Expr::Input(s) => inputs[*s as usize],
            Expr::Temp(t) => temps[*t],
            Expr::Add(c, ts) => ts
                .iter()
                .fold(*c, |acc, (t, k)| acc + k * t.eval(inputs, temps)),
            Expr::Mul(fs) => fs
                .iter()
                .fold(1.0, |acc, (f, e)| acc * powi(f.eval(inputs, temps), *e)),
            Expr::Sin(a) => a.eval(inputs, temps).sin(),
            Expr::Cos(a) => a.eval(inputs, temps).cos(),
            Expr::Sqrt(a) => a.eval(inputs, temps).sqrt(),
            Expr::Recip(a) => 1.0 / a.eval(inputs, temps),
            Expr::Sign(a) => sign(a.eval(inputs, temps)),
        }
    }
}

/// Temporaries in dependency order, then outputs.
#[derive(Clone, Debug, PartialEq)]
pub struct Program {
    /// `temps[k]` may use inputs and `temps[..k]`.
    pub temps: Vec<Expr>,
    pub outputs: Vec<Expr>,
    /// The graph's symbol table, for naming inputs.
    pub symbols: Vec<Symbol>,
}

/// Deepest nesting of single-use nodes written inline.
const MAX_INLINE_DEPTH: u32 = 4;

/// The order of a program's temporaries (the operations are the same either way).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Order {
    /// As the expressions were built: each step of a derivation stays together, for reading.
    #[default]
    Creation,
    /// By level (the longest path from the inputs), then creation: independent chains are
    /// interleaved, so that an out-of-order processor finds work while a long dependency chain
    /// (a force carried up a kinematic chain, say) waits on its previous step. For generated
    /// code.
    Levels,
    /// Depth first from each output in turn: a temporary is computed just before its first
    /// use, so that few values are live at once. For long programs (thousands of operations),
    /// where level order keeps so many values live that the compiled code spends its time
    /// spilling registers.
    Depth,
}

impl Program {
    /// Schedules `outputs` of `graph` in creation order.
    pub fn new(graph: &Graph, outputs: &[Id]) -> Program {
        Program::ordered(graph, outputs, Order::Creation)
    }

    /// Schedules `outputs` of `graph` with its temporaries in `order`.
    pub fn ordered(graph: &Graph, outputs: &[Id], order_by: Order) -> Program {
        let nodes = Nodes::new(graph, outputs);
        let visit = nodes.visit(outputs, order_by);
        let uses = nodes.uses(outputs);
        let mut w = Writer {
            repr: vec![None; nodes.order.len()],
            temps: Vec::new(),
            den_uses: shared_denominators(graph, &nodes.order),
            recips: HashMap::new(),
        };
        for k in visit {
            let (e, depth) = w.node_expr(&nodes, k);
            let is_leaf = depth == 0;
            w.repr[k] = Some(if is_leaf || (uses[k] <= 1 && depth <= MAX_INLINE_DEPTH) {
                (e, depth)
            } else {
                w.temps.push(e);
                (Expr::Temp(w.temps.len() - 1), 0)
            });
        }
        let outputs = outputs
            .iter()
            .map(|&o| w.repr[nodes.slot(o)].clone().expect("reachable").0)
            .collect();
        Program {
            temps: w.temps,
            outputs,
            symbols: graph.symbols().to_vec(),
        }
    }

    /// Operation count of the whole program.
    pub fn ops(&self) -> OpCount {
        let mut n = OpCount::default();
        for e in self.temps.iter().chain(&self.outputs) {
            n += e.ops();
        }
        n
    }

    /// Runs the program; `value` gives each symbol's number (only symbols the program uses are
    /// asked for).
    pub fn eval(
        &self,
        mut value: impl FnMut(&Symbol) -> Option<f64>,
    ) -> Result<Vec<f64>, UnboundSymbol> {
        let mut used = vec![false; self.symbols.len()];
        fn mark(e: &Expr, used: &mut [bool]) {
            match e {
                Expr::Input(s) => used[*s as usize] = true,
                Expr::Const(_) | Expr::Temp(_) => {}
                Expr::Add(_, ts) => ts.iter().for_each(|(t, _)| mark(t, used)),
                Expr::Mul(fs) => fs.iter().for_each(|(f, _)| mark(f, used)),
                Expr::Sin(a) | Expr::Cos(a) | Expr::Sqrt(a) | Expr::Sign(a) | Expr::Recip(a) => {
                    mark(a, used)
                }
            }
        }
        for e in self.temps.iter().chain(&self.outputs) {
            mark(e, &mut used);
        }
        let mut inputs = vec![0.0; self.symbols.len()];
        for (i, s) in self.symbols.iter().enumerate() {
            if used[i] {
                inputs[i] = value(s).ok_or_else(|| UnboundSymbol(s.name.clone()))?;
            }
        }
        let mut temps = Vec::with_capacity(self.temps.len());
        for e in &self.temps {
            let v = e.eval(&inputs, &temps);
            temps.push(v);
        }
        Ok(self
            .outputs
            .iter()
            .map(|e| e.eval(&inputs, &temps))
            .collect())
    }
}

/// The reachable unit sums of a program: constant 0, coefficients +-1, two or more terms.
struct UnitSums {
    /// By their terms with the first coefficient made positive: (sum, the sign undoing that).
    exact: HashMap<Vec<(Id, bool)>, (Id, f64)>,
    /// Each sum's terms with unit coefficients.
    terms: Vec<(Id, Vec<(Id, f64)>)>,
    /// For each term, the sums (indices into `terms`) that hold it, at most
    /// `MAX_CANDIDATES` of them.
    by_term: HashMap<Id, Vec<usize>>,
}

/// Sums looked at per term when searching for a reusable part of a sum, which bounds the
/// search on graphs where one term appears in thousands of sums.
const MAX_CANDIDATES: usize = 32;

impl UnitSums {
    fn new(graph: &Graph, order: &[Id]) -> UnitSums {
        let mut u = UnitSums {
            exact: HashMap::new(),
            terms: Vec::new(),
            by_term: HashMap::new(),
        };
        for &id in order {
            if let Node::Add(c, ts) = graph.node(id) {
                if c.get() == 0.0 && ts.len() >= 2 && ts.iter().all(|t| t.1.get().abs() == 1.0) {
                    let terms: Vec<(Id, f64)> = ts.iter().map(|t| (t.0, t.1.get())).collect();
                    let (key, sign) = unit_key(&terms);
                    u.exact.entry(key).or_insert((id, sign));
                    for &(t, _) in &terms {
                        let list = u.by_term.entry(t).or_default();
                        if list.len() < MAX_CANDIDATES {
                            list.push(u.terms.len());
                        }
                    }
                    u.terms.push((id, terms));
                }
            }
        }
        u
    }

    /// The terms of sum `id` with unit sums standing in for terms they hold: per group of terms
    /// of one coefficient magnitude, the whole group if it is a unit sum, else the largest unit
    /// sums inside it, one after another.
    fn plan(&self, id: Id, terms: impl Iterator<Item = (Id, f64)>) -> Vec<(Id, f64)> {
        let terms: Vec<(Id, f64)> = terms.collect();
        let mut mags: Vec<f64> = Vec::new();
        for &(_, k) in &terms {
            if !mags.contains(&k.abs()) {
                mags.push(k.abs());
            }
        }
        let mut out = Vec::with_capacity(terms.len());
        for mag in mags {
            // The group as unit terms, in `Id` order (as the node keeps them).
            let mut group: Vec<(Id, f64)> = terms
                .iter()
                .filter(|t| t.1.abs() == mag)
                .map(|&(t, k)| (t, k / mag))
                .collect();
            while group.len() >= 2 {
                let found = match self.exact.get(&unit_key(&group).0) {
                    Some(&(u, _)) if u != id => Some(u),
                    _ => self.largest_inside(id, &group),
                };
                let Some(u) = found else { break };
                // The sign relating the group's terms to the unit sum's.
                let u_terms = &self.terms[self.index_of(u)].1;
                let first = u_terms[0];
                let g_first = group.iter().find(|t| t.0 == first.0).expect("inside").1;
                let sign = g_first * first.1;
                group.retain(|t| u_terms.binary_search_by_key(&t.0, |x| x.0).is_err());
                out.push((u, mag * sign));
            }
            out.extend(group.into_iter().map(|(t, k)| (t, k * mag)));
        }
        out
    }

    fn index_of(&self, u: Id) -> usize {
        self.terms
            .binary_search_by_key(&u, |t| t.0)
            .expect("a unit sum")
    }

    /// The largest unit sum other than `id` whose terms all lie in `group` with the same
    /// relative signs (ties: the earliest), if any.
    fn largest_inside(&self, id: Id, group: &[(Id, f64)]) -> Option<Id> {
        let sign_in_group = |t: Id| -> Option<f64> {
            group
                .binary_search_by_key(&t, |x| x.0)
                .ok()
                .map(|i| group[i].1)
        };
        let mut best: Option<(usize, Id)> = None;
        for &(t, _) in group {
            for &i in self.by_term.get(&t).into_iter().flatten() {
                let (u, ref ut) = self.terms[i];
                if u == id || ut.len() >= group.len() || best.is_some_and(|b| b.0 >= ut.len()) {
                    continue;
                }
                let Some(s0) = sign_in_group(ut[0].0) else {
                    continue;
                };
                let rel = s0 * ut[0].1;
                if ut.iter().all(|&(x, k)| sign_in_group(x) == Some(rel * k)) {
                    best = Some((ut.len(), u));
                }
            }
        }
        best.map(|b| b.1)
    }
}

/// The terms of a unit sum with its first coefficient made positive, and the sign that undoes
/// it.
fn unit_key(terms: &[(Id, f64)]) -> (Vec<(Id, bool)>, f64) {
    let sign = if terms[0].1 < 0.0 { -1.0 } else { 1.0 };
    let key = terms.iter().map(|&(t, k)| (t, k * sign > 0.0)).collect();
    (key, sign)
}

/// `k a + k b - k c` -> `k (a + b - c)`: terms whose coefficients share a magnitude get it
/// once, saving a multiplication per term. Groups keep the order of their first term.
fn factor_coefficients(constant: f64, terms: Vec<(Expr, f64)>) -> Expr {
    let mut groups: Vec<(f64, Vec<(Expr, f64)>)> = Vec::new();
    let mut index: HashMap<u64, usize> = HashMap::with_capacity(terms.len());
    for (e, k) in terms {
        let mag = k.abs();
        let unit = if k < 0.0 { -1.0 } else { 1.0 };
        match index.get(&mag.to_bits()) {
            Some(&g) => groups[g].1.push((e, unit)),
            None => {
                index.insert(mag.to_bits(), groups.len());
                groups.push((mag, vec![(e, unit)]));
            }
        }
    }
    let mut out = Vec::with_capacity(groups.len());
    for (mag, mut members) in groups {
        if members.len() == 1 || mag == 1.0 {
            out.extend(members.into_iter().map(|(e, u)| (e, u * mag)));
        } else {
            // Lead with a positive term where possible, so the inner sum needs no negation.
            let sign = if members.iter().all(|m| m.1 < 0.0) {
                -1.0
            } else {
                1.0
            };
            for m in members.iter_mut() {
                m.1 *= sign;
            }
            out.push((Expr::Add(0.0, members), sign * mag));
        }
    }
    Expr::Add(constant, out)
}

/// The nodes reachable from a program's outputs, with the terms each sum is written with.
struct Nodes<'g> {
    graph: &'g Graph,
    /// The reachable nodes by `Id` (children first).
    order: Vec<Id>,
    /// Per node of `order`: a sum's terms once it reuses unit sums; `None` for other nodes.
    plans: Vec<Option<Vec<(Id, f64)>>>,
}

impl<'g> Nodes<'g> {
    fn new(graph: &'g Graph, outputs: &[Id]) -> Nodes<'g> {
        let order = graph.reachable(outputs);
        // Sums that are unit combinations, `a + b - c`, are reused by other sums that hold the
        // same terms with one coefficient magnitude: `k a + k b - k c + d` (the graph
        // distributes constant factors into sums and flattens sums into sums) becomes
        // `k t + d`, saving the additions.
        let units = UnitSums::new(graph, &order);
        let plans = order
            .iter()
            .map(|&id| match graph.node(id) {
                Node::Add(_, ts) => Some(units.plan(id, ts.iter().map(|t| (t.0, t.1.get())))),
                _ => None,
            })
            .collect();
        Nodes {
            graph,
            order,
            plans,
        }
    }

    /// The position of reachable node `id` in `order`.
    fn slot(&self, id: Id) -> usize {
        self.order.binary_search(&id).expect("reachable")
    }

    /// The children of node `k` of `order` as written: a sum's planned terms.
    fn kids(&self, k: usize) -> Vec<Id> {
        match &self.plans[k] {
            Some(terms) => terms.iter().map(|t| t.0).collect(),
            None => self.graph.node(self.order[k]).children().collect(),
        }
    }

    /// How often each node is used: by its parents and as an output.
    fn uses(&self, outputs: &[Id]) -> Vec<u32> {
        let mut uses = vec![0u32; self.order.len()];
        for k in 0..self.order.len() {
            for c in self.kids(k) {
                uses[self.slot(c)] += 1;
            }
        }
        for &o in outputs {
            uses[self.slot(o)] += 1;
        }
        uses
    }

    /// The nodes (positions in `order`) in the order their expressions are written.
    fn visit(&self, outputs: &[Id], order_by: Order) -> Vec<usize> {
        let len = self.order.len();
        // Scheduling order: by `Id` (children first), except that a reused unit sum created
        // after its user moves just before it, after whatever it reuses in turn.
        let mut visit: Vec<usize> = Vec::with_capacity(len);
        let mut placed = vec![false; len];
        let starts: Vec<usize> = match order_by {
            Order::Depth => outputs.iter().map(|&o| self.slot(o)).collect(),
            _ => (0..len).collect(),
        };
        for k in starts {
            let mut stack = vec![(k, false)];
            while let Some((j, ready)) = stack.pop() {
                if placed[j] {
                    continue;
                }
                if ready {
                    placed[j] = true;
                    visit.push(j);
                    continue;
                }
                stack.push((j, true));
                for c in self.kids(j) {
                    let sc = self.slot(c);
                    if !placed[sc] {
                        stack.push((sc, false));
                    }
                }
            }
        }
        if order_by == Order::Levels {
            let mut level = vec![0u32; len];
            let mut position = vec![0usize; len];
            for (p, &k) in visit.iter().enumerate() {
                let deepest = self.kids(k).iter().map(|&c| level[self.slot(c)]).max();
                level[k] = deepest.map_or(0, |l| l + 1);
                position[k] = p;
            }
            visit.sort_by_key(|&k| (level[k], position[k]));
        }
        visit
    }
}

/// The denominator of a product: its factors with a negative exponent.
fn den_key(fs: &[(Id, i32)]) -> Vec<(Id, i32)> {
    fs.iter().filter(|f| f.1 < 0).copied().collect()
}

/// How many products of `order` share each denominator. Denominators shared by several
/// products get one reciprocal temporary: a division costs as much as ten multiplications.
fn shared_denominators(graph: &Graph, order: &[Id]) -> HashMap<Vec<(Id, i32)>, usize> {
    let mut den_uses: HashMap<Vec<(Id, i32)>, usize> = HashMap::new();
    for &id in order {
        if let Node::Mul(fs) = graph.node(id) {
            let key = den_key(fs);
            if !key.is_empty() && key.len() < fs.len() {
                *den_uses.entry(key).or_insert(0) += 1;
            }
        }
    }
    den_uses
}

/// A program being written.
struct Writer {
    /// For each reachable node: its expression when used (a leaf, a temp, or inline), and
    /// the nesting depth of that inline expression.
    repr: Vec<Option<(Expr, u32)>>,
    temps: Vec<Expr>,
    /// How many products share each denominator, and the temporaries holding the
    /// reciprocals written so far.
    den_uses: HashMap<Vec<(Id, i32)>, usize>,
    recips: HashMap<Vec<(Id, i32)>, usize>,
}

impl Writer {
    /// The expression of child `c`, written before its parent.
    fn sub(&self, nodes: &Nodes, c: Id) -> (Expr, u32) {
        self.repr[nodes.slot(c)]
            .clone()
            .expect("child before parent")
    }

    /// The expression of node `k` of `nodes.order` and its nesting depth.
    fn node_expr(&mut self, nodes: &Nodes, k: usize) -> (Expr, u32) {
        let sub = |c: Id| self.sub(nodes, c);
        match nodes.graph.node(nodes.order[k]) {
            Node::Const(c) => (Expr::Const(c.get()), 0),
            Node::Sym(s) => (Expr::Input(*s), 0),
            Node::Add(c, _) => {
                let parts: Vec<((Expr, u32), f64)> = nodes.plans[k]
                    .iter()
                    .flatten()
                    .map(|&(t, k)| (sub(t), k))
                    .collect();
                let d = parts.iter().map(|p| p.0 .1).max().unwrap_or(0) + 1;
                (
                    factor_coefficients(
                        c.get(),
                        parts.into_iter().map(|((e, _), k)| (e, k)).collect(),
                    ),
                    d + 1,
                )
            }
            Node::Mul(fs) if self.den_uses.get(&den_key(fs)).is_some_and(|&u| u >= 2) => {
                self.shared_quotient(nodes, fs)
            }
            Node::Mul(fs) => {
                let parts: Vec<((Expr, u32), i32)> =
                    fs.iter().map(|(f, e)| (sub(*f), *e)).collect();
                product(parts)
            }
            Node::Sin(a) => unary(sub(*a), Expr::Sin),
            Node::Cos(a) => unary(sub(*a), Expr::Cos),
            Node::Sqrt(a) => unary(sub(*a), Expr::Sqrt),
            Node::Recip(a) => unary(sub(*a), Expr::Recip),
            Node::Sign(a) => unary(sub(*a), Expr::Sign),
        }
    }

    /// A product whose denominator other products share: its numerator times the
    /// denominator's reciprocal, a temporary written at its first use.
    fn shared_quotient(&mut self, nodes: &Nodes, fs: &[(Id, i32)]) -> (Expr, u32) {
        let key = den_key(fs);
        let r = match self.recips.get(&key) {
            Some(&r) => r,
            None => {
                let den = key
                    .iter()
                    .map(|(f, e)| (self.sub(nodes, *f).0, *e))
                    .collect();
                self.temps.push(Expr::Mul(den));
                self.recips.insert(key, self.temps.len() - 1);
                self.temps.len() - 1
            }
        };
        let mut parts: Vec<((Expr, u32), i32)> = fs
            .iter()
            .filter(|f| f.1 > 0)
            .map(|(f, e)| (self.sub(nodes, *f), *e))
            .collect();
        parts.push(((Expr::Temp(r), 0), 1));
        product(parts)
    }
}

/// The product of `parts` (expressions with their depths, and exponents) and its depth.
fn product(parts: Vec<((Expr, u32), i32)>) -> (Expr, u32) {
    let d = parts.iter().map(|p| p.0 .1).max().unwrap_or(0) + 1;
    (
        Expr::Mul(parts.into_iter().map(|((e, _), x)| (e, x)).collect()),
        d,
    )
}

fn unary((e, d): (Expr, u32), f: fn(Box<Expr>) -> Expr) -> (Expr, u32) {
    (f(Box::new(e)), d + 1)
}
