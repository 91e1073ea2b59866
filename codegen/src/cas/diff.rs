//! Differentiation and substitution, memoized over the graph.
//!
//! Each pass visits every node reachable from its roots once, in ascending `Id` order (children
//! before parents), so its work is proportional to the size of the graph, never to the size of
//! the expanded expression tree, and no recursion can overflow the stack.

use std::collections::HashMap;

use super::graph::{FxBuild, Graph, Id, Node, SymbolIndex, SymbolKind};

impl Graph {
    /// `d e / d x` for a symbol node `x`.
    ///
    /// # Panics
    /// If `x` is not a symbol.
    pub fn diff(&mut self, e: Id, x: Id) -> Id {
        self.diff_many(&[e], x)[0]
    }

    /// `d e / d x` for several expressions sharing one memo.
    ///
    /// # Panics
    /// If `x` is not a symbol.
    pub fn diff_many(&mut self, roots: &[Id], x: Id) -> Vec<Id> {
        let sx = self
            .as_symbol(x)
            .expect("diff: the variable must be a symbol");
        let one = self.one();
        let zero = self.zero();
        self.derive(roots, |_, s| if s == sx { one } else { zero })
    }

    /// The derivatives of several expressions along a direction in which each symbol node
    /// `x` of `rates` moves at the rate `dx` (an expression; symbols not listed stay fixed):
    /// `sum_x de/dx dx`, for perturbations that are not along one coordinate (a floating
    /// base's tangent space).
    ///
    /// # Panics
    /// If a listed `x` is not a symbol.
    pub fn derivative_along_many(&mut self, roots: &[Id], rates: &[(Id, Id)]) -> Vec<Id> {
        let rates: Vec<(SymbolIndex, Id)> = rates
            .iter()
            .map(|&(x, dx)| (self.as_symbol(x).expect("derivative_along: a symbol"), dx))
            .collect();
        let zero = self.zero();
        self.derive(roots, |_, s| {
            rates.iter().find(|r| r.0 == s).map_or(zero, |r| r.1)
        })
    }

    /// The total time derivative, with `d q_i/dt = qd_i` and `d qd_i/dt = qdd_i`. Parameters are
    /// constant in time; accelerations have no derivative here (treated as constant).
    pub fn time_derivative(&mut self, e: Id) -> Id {
        self.time_derivative_many(&[e])[0]
    }

    /// Time derivatives of several expressions sharing one memo.
    pub fn time_derivative_many(&mut self, roots: &[Id]) -> Vec<Id> {
        self.derive(roots, |g, s| match g.symbols()[s as usize].kind {
            SymbolKind::Q(i) => g.qd(i),
            SymbolKind::Qd(i) => g.qdd(i),
            SymbolKind::Qdd(_) | SymbolKind::Tau(_) | SymbolKind::Force(_) | SymbolKind::Param => {
                g.zero()
            }
        })
    }

    /// The chain rule over the graph, with `leaf(symbol)` giving the derivative of each symbol.
    fn derive(
        &mut self,
        roots: &[Id],
        mut leaf: impl FnMut(&mut Graph, SymbolIndex) -> Id,
    ) -> Vec<Id> {
        let order = self.reachable(roots);
        let mut d: HashMap<Id, Id, FxBuild> =
            HashMap::with_capacity_and_hasher(order.len(), FxBuild);
        let zero = self.zero();
        for &id in &order {
            let node = self.node(id).clone();
            let get = |d: &HashMap<Id, Id, FxBuild>, c: Id| d[&c];
            let r = match node {
                Node::Const(_) => zero,
                Node::Sym(s) => leaf(self, s),
                Node::Add(_, terms) => {
                    let ts: Vec<(Id, f64)> =
                        terms.iter().map(|&(t, k)| (get(&d, t), k.get())).collect();
                    self.sum(0.0, ts)
                }
                Node::Mul(factors) => {
                    // d(prod f_i^e_i) = sum_i e_i f_i^(e_i - 1) f_i' prod_{j != i} f_j^e_j
                    let mut terms = Vec::new();
                    for (i, &(f, e)) in factors.iter().enumerate() {
                        let df = get(&d, f);
                        if df == zero {
                            continue;
                        }
                        let mut fs: Vec<(Id, i32)> = factors.to_vec();
                        fs[i].1 = e - 1;
                        fs.push((df, 1));
                        let t = self.product(fs);
                        terms.push((t, e as f64));
                    }
                    self.sum(0.0, terms)
                }
                Node::Sin(a) => {
                    let da = get(&d, a);
                    if da == zero {
                        zero
                    } else {
                        let c = self.cos(a);
                        self.mul(c, da)
                    }
                }
                Node::Cos(a) => {
                    let da = get(&d, a);
                    if da == zero {
                        zero
                    } else {
                        let s = self.sin(a);
                        let p = self.mul(s, da);
                        self.neg(p)
                    }
                }
                Node::Sqrt(a) => {
                    let da = get(&d, a);
                    if da == zero {
                        zero
                    } else {
                        let p = self.product([(da, 1), (id, -1)]);
                        self.scale(p, 0.5)
                    }
                }
                // d(1/a) = -a' (1/a)^2.
                Node::Recip(a) => {
                    let da = get(&d, a);
                    if da == zero {
                        zero
                    } else {
                        let p = self.product([(da, 1), (id, 2)]);
                        self.neg(p)
                    }
                }
                // Piecewise constant; its derivative is zero almost everywhere.
                Node::Sign(_) => zero,
            };
            d.insert(id, r);
        }
        roots.iter().map(|r| d[r]).collect()
    }

    /// Replaces symbols by expressions (or numbers, as constant nodes) throughout `roots`,
    /// re-simplifying as it rebuilds.
    pub fn substitute(&mut self, roots: &[Id], map: &HashMap<Id, Id>) -> Vec<Id> {
        let order = self.reachable(roots);
        let mut s: HashMap<Id, Id, FxBuild> =
            HashMap::with_capacity_and_hasher(order.len(), FxBuild);
        for &id in &order {
            let node = self.node(id).clone();
            let r = match node {
                Node::Const(_) => id,
                Node::Sym(_) => *map.get(&id).unwrap_or(&id),
                Node::Add(c, terms) => {
                    let ts: Vec<(Id, f64)> = terms.iter().map(|&(t, k)| (s[&t], k.get())).collect();
                    self.sum(c.get(), ts)
                }
                Node::Mul(factors) => {
                    let fs: Vec<(Id, i32)> = factors.iter().map(|&(f, e)| (s[&f], e)).collect();
                    self.product(fs)
                }
                Node::Sin(a) => self.sin(s[&a]),
                Node::Cos(a) => self.cos(s[&a]),
                Node::Sqrt(a) => self.sqrt(s[&a]),
                Node::Sign(a) => self.sign(s[&a]),
                Node::Recip(a) => self.recip(s[&a]),
            };
            s.insert(id, r);
        }
        roots.iter().map(|r| s[r]).collect()
    }
}
