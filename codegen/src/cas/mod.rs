//! The symbolic core: a small computer-algebra system specialised for rigid-body dynamics.
//!
//! - [`graph`]: the hash-consed expression arena and its simplifying constructors;
//! - [`diff`]: differentiation, time derivatives and substitution, memoized over the graph;
//! - [`eval`]: numeric evaluation;
//! - [`simplify`]: expansion and trigonometric identities, for readable equations;
//! - [`schedule`]: straight-line programs (temporaries, outputs, operation counts);
//! - [`mod@print`]: plain text and LaTeX.
//!
//! ```
//! use eomgen::cas::{Graph, Style};
//! let mut g = Graph::new();
//! let q = g.q(0);
//! let s = g.sin(q);
//! let c = g.cos(q);
//! let e = g.mul(s, c); // sin(q1) cos(q1)
//! let de = g.diff(e, q); // cos^2 - sin^2
//! let v = g.eval(&[de], |_| Some(0.3)).unwrap();
//! assert!((v[0] - (0.6f64).cos()).abs() < 1e-15);
//! assert_eq!(g.print(e, Style::default()), "cos(q1)*sin(q1)");
//! ```

pub mod diff;
pub mod eval;
pub mod graph;
pub mod print;
pub mod schedule;
pub mod simplify;

pub use eval::UnboundSymbol;
pub use graph::{
    Graph, GraphFull, Id, Limits, Node, Num, SumFlattening, Symbol, SymbolIndex, SymbolKind,
};
pub use print::{format_number, Style, Syntax};
pub use schedule::{Expr, OpCount, Order, Program};
pub use simplify::TooLarge;
