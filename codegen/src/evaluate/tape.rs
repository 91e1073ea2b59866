//! A tape: the part of the expression graph that some outputs need, compiled once into a flat
//! list of instructions over numbered slots, then run as often as wanted with new inputs.
//!
//! Compiling walks the graph once (symbols bound to input positions or to numbers); running is
//! a loop over the instructions with no lookups, so a simulation that evaluates `M`, `b` and `G`
//! at every stage does not search the graph each time.

use crate::cas::eval::{powi, sign};
use crate::cas::{Graph, Id, Node, Symbol};

/// Where a symbol's number comes from when the tape runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Binding {
    /// Position in the input slice given to [`Tape::run`].
    Input(usize),
    /// A number fixed when the tape is compiled (a parameter at its URDF value).
    Value(f64),
}

#[derive(Clone, Debug)]
enum Op {
    Const(f64),
    Input(usize),
    /// `constant + sum of coefficient * slot` over `terms[start..end]`.
    Add(f64, usize, usize),
    /// Product of `slot ^ exponent` over `factors[start..end]`.
    Mul(usize, usize),
    Sin(usize),
    Cos(usize),
    Sqrt(usize),
    Sign(usize),
    Recip(usize),
}

/// Straight-line code for some outputs of a graph; see the module documentation.
#[derive(Clone, Debug)]
pub(crate) struct Tape {
    ops: Vec<Op>,
    terms: Vec<(usize, f64)>,
    factors: Vec<(usize, i32)>,
    outputs: Vec<usize>,
}

impl Tape {
    /// Compiles the outputs; `bind` says where each symbol's number comes from (`None`: the
    /// symbol cannot be evaluated, and its name is the error); a binding to a position at or
    /// beyond `inputs`, the length of the slice [`Tape::run`] will get, is refused too.
    pub(crate) fn new(
        g: &Graph,
        outputs: &[Id],
        inputs: usize,
        mut bind: impl FnMut(&Symbol) -> Option<Binding>,
    ) -> Result<Tape, String> {
        let order = g.reachable(outputs);
        let slot = |id: Id| order.binary_search(&id).expect("child is reachable");
        let mut tape = Tape {
            ops: Vec::with_capacity(order.len()),
            terms: Vec::new(),
            factors: Vec::new(),
            outputs: outputs.iter().map(|&o| slot(o)).collect(),
        };
        for &id in &order {
            let op = match g.node(id) {
                Node::Const(c) => Op::Const(c.get()),
                Node::Sym(s) => {
                    let sym = &g.symbols()[*s as usize];
                    match bind(sym) {
                        Some(Binding::Input(i)) if i < inputs => Op::Input(i),
                        Some(Binding::Value(v)) => Op::Const(v),
                        _ => return Err(sym.name.clone()),
                    }
                }
                Node::Add(c, ts) => {
                    let start = tape.terms.len();
                    tape.terms
                        .extend(ts.iter().map(|(t, k)| (slot(*t), k.get())));
                    Op::Add(c.get(), start, tape.terms.len())
                }
                Node::Mul(fs) => {
                    let start = tape.factors.len();
                    tape.factors.extend(fs.iter().map(|(f, e)| (slot(*f), *e)));
                    Op::Mul(start, tape.factors.len())
                }
                Node::Sin(a) => Op::Sin(slot(*a)),
                Node::Cos(a) => Op::Cos(slot(*a)),
                Node::Sqrt(a) => Op::Sqrt(slot(*a)),
                Node::Recip(a) => Op::Recip(slot(*a)),
                Node::Sign(a) => Op::Sign(slot(*a)),
            };
            tape.ops.push(op);
        }
        Ok(tape)
    }

    /// Runs the tape on `input` (as long as promised to [`Tape::new`]; shorter input reads
    /// as NaN) and returns the outputs in the order they were given.
    pub(crate) fn run(&self, input: &[f64]) -> Vec<f64> {
        let mut v = vec![0.0f64; self.ops.len()];
        for k in 0..self.ops.len() {
            v[k] = match self.ops[k] {
                Op::Const(c) => c,
                Op::Input(i) => input.get(i).copied().unwrap_or(f64::NAN),
                Op::Add(c, s, e) => self.terms[s..e]
                    .iter()
                    .fold(c, |acc, &(t, k)| acc + k * v[t]),
                Op::Mul(s, e) => self.factors[s..e]
                    .iter()
                    .fold(1.0, |acc, &(f, x)| acc * powi(v[f], x)),
                Op::Sin(a) => v[a].sin(),
                Op::Cos(a) => v[a].cos(),
                Op::Sqrt(a) => v[a].sqrt(),
                Op::Recip(a) => 1.0 / v[a],
                Op::Sign(a) => sign(v[a]),
            };
        }
        self.outputs.iter().map(|&o| v[o]).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cas::SymbolKind;

    #[test]
    fn runs_like_the_interpreter() {
        let mut g = Graph::new();
        let x = g.symbol("x", SymbolKind::Q(0));
        let m = g.symbol("m", SymbolKind::Param);
        let s = g.sin(x);
        let two = g.constant(2.0);
        let sx = g.mul(s, x);
        let p = g.mul(sx, m);
        let out = g.add(p, two);
        let bind = |s: &Symbol| match s.kind {
            SymbolKind::Q(i) => Some(Binding::Input(i)),
            SymbolKind::Param => Some(Binding::Value(3.0)),
            _ => None,
        };
        let tape = Tape::new(&g, &[out, x], 1, bind).unwrap();
        for x0 in [0.0, 0.7, -2.5] {
            let want = g
                .eval(&[out, x], |s| match s.kind {
                    SymbolKind::Q(_) => Some(x0),
                    _ => Some(3.0),
                })
                .unwrap();
            assert_eq!(tape.run(&[x0]), want);
        }
    }

    #[test]
    fn an_unbound_symbol_is_named() {
        let mut g = Graph::new();
        let x = g.symbol("tau_1", SymbolKind::Tau(0));
        let err = Tape::new(&g, &[x], 0, |_| None).unwrap_err();
        assert_eq!(err, "tau_1");
        // Bound to a position beyond the inputs: refused too.
        let err = Tape::new(&g, &[x], 0, |_| Some(Binding::Input(0))).unwrap_err();
        assert_eq!(err, "tau_1");
    }
}
