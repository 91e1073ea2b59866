//! Numeric evaluation: an interpreter over the graph.

use super::graph::{Graph, Id, Node, Symbol};

/// A symbol met during evaluation that the caller gave no value for.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("no value for symbol `{0}`")]
pub struct UnboundSymbol(pub String);

/// Applies `x ^ e` for an integer exponent.
pub(crate) fn powi(x: f64, e: i32) -> f64 {
    match e {
        1 => x,
        2 => x * x,
        -1 => 1.0 / x,
        _ => x.powi(e),
    }
}

/// Applies the sign function: -1, 0 or 1 (NaN stays NaN).
pub(crate) fn sign(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        x * 0.0
    }
}

impl Graph {
    /// Evaluates many outputs at once. `value` gives each symbol's number; every node reachable
    /// from `outputs` is computed exactly once.
    pub fn eval(
        &self,
        outputs: &[Id],
        mut value: impl FnMut(&Symbol) -> Option<f64>,
    ) -> Result<Vec<f64>, UnboundSymbol> {
        let order = self.reachable(outputs);
        // Dense slots for the reachable nodes, found by binary search in `order`.
        let slot = |id: Id| order.binary_search(&id).expect("child is reachable");
        let mut v = vec![0.0f64; order.len()];
        for (k, &id) in order.iter().enumerate() {
            v[k] = match self.node(id) {
                Node::Const(c) => c.get(),
                Node::Sym(s) => {
                    let sym = &self.symbols()[*s as usize];
                    value(sym).ok_or_else(|| UnboundSymbol(sym.name.clone()))?
                }
                Node::Add(c, ts) => ts
                    .iter()
                    .fold(c.get(), |acc, (t, k)| acc + k.get() * v[slot(*t)]),
                Node::Mul(fs) => fs
                    .iter()
                    .fold(1.0, |acc, (f, e)| acc * powi(v[slot(*f)], *e)),
                Node::Sin(a) => v[slot(*a)].sin(),
                Node::Cos(a) => v[slot(*a)].cos(),
                Node::Sqrt(a) => v[slot(*a)].sqrt(),
                Node::Recip(a) => 1.0 / v[slot(*a)],
                Node::Sign(a) => sign(v[slot(*a)]),
            };
        }
        Ok(outputs.iter().map(|&o| v[slot(o)]).collect())
    }
}
