//! Printing expressions as plain text and LaTeX.
//!
//! Output depends only on the expressions, never on hash order or on the order in which the
//! graph was built: the terms of a sum are sorted by a key made from their printed text.

use super::graph::{Graph, Id, Node, Symbol, SymbolKind};
use super::schedule::{Expr, Program};

/// The output language.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Syntax {
    /// `2*m2*l1*cos(q2) + qd1^2`.
    #[default]
    Text,
    /// `2 m_{2} l_{1} \cos(q_{2}) + \dot{q}_{1}^{2}`.
    Latex,
}

/// How to print.
#[derive(Clone, Copy, Debug, Default)]
pub struct Style {
    pub syntax: Syntax,
    /// Significant digits of numbers; `None` prints the shortest text that reads back exactly.
    pub digits: Option<usize>,
}

/// Formats a number: integers without a fraction, others shortest round-trip or to `digits`
/// significant digits.
pub fn format_number(v: f64, digits: Option<usize>) -> String {
    if v.is_nan() {
        return "NaN".into();
    }
    if v.is_infinite() {
        return if v > 0.0 { "inf".into() } else { "-inf".into() };
    }
    if v == v.trunc() && v.abs() < 1e15 {
        return format!("{}", v as i64);
    }
    match digits {
        None => format!("{v:?}"),
        Some(d) => {
            let d = d.clamp(1, 17);
            let e = v.abs().log10().floor() as i32;
            if (-4..15).contains(&e) {
                let decimals = (d as i32 - 1 - e).max(0) as usize;
                let s = format!("{v:.decimals$}");
                trim_fraction(&s)
            } else {
                let s = format!("{:.*e}", d - 1, v);
                match s.split_once('e') {
                    Some((m, x)) => format!("{}e{}", trim_fraction(m), x),
                    None => s,
                }
            }
        }
    }
}

fn trim_fraction(s: &str) -> String {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s.to_string()
    }
}

/// Binding strength, to decide parentheses.
const SUM: u8 = 0;
const PRODUCT: u8 = 1;
const POWER: u8 = 2;
const ATOM: u8 = 3;

/// A printed fragment with its binding strength.
struct Frag {
    text: String,
    prec: u8,
}

/// The printer, generic over where leaves come from (graph nodes or program operands).
struct Printer<'a> {
    style: Style,
    symbol_name: &'a dyn Fn(u32) -> String,
}

impl Printer<'_> {
    fn latex(&self) -> bool {
        self.style.syntax == Syntax::Latex
    }

    fn wrap(&self, f: Frag, min: u8) -> String {
        if f.prec < min {
            if self.latex() {
                format!("\\left({}\\right)", f.text)
            } else {
                format!("({})", f.text)
            }
        } else {
            f.text
        }
    }

    fn num(&self, v: f64) -> Frag {
        let s = format_number(v, self.style.digits);
        let s = if self.latex() {
            match s.split_once('e') {
                Some((m, x)) => format!("{m} \\cdot 10^{{{}}}", x.trim_start_matches('+')),
                None => s,
            }
        } else {
            s
        };
        Frag {
            prec: if v < 0.0 { SUM } else { ATOM },
            text: s,
        }
    }

    fn symbol(&self, s: u32) -> Frag {
        Frag {
            text: (self.symbol_name)(s),
            prec: ATOM,
        }
    }

    fn func(&self, name: &str, arg: Frag) -> Frag {
        let text = if self.latex() {
            if name == "sqrt" {
                format!("\\sqrt{{{}}}", arg.text)
            } else {
                format!("\\{name}\\left({}\\right)", arg.text)
            }
        } else {
            format!("{name}({})", arg.text)
        };
        Frag { text, prec: ATOM }
    }

    fn pow(&self, base: Frag, e: i32) -> String {
        let b = self.wrap(base, ATOM);
        match (e, self.latex()) {
            (1, _) => b,
            (_, true) => format!("{b}^{{{e}}}"),
            (_, false) => format!("{b}^{e}"),
        }
    }

    fn product(&self, factors: Vec<(Frag, i32)>) -> Frag {
        let sep = if self.latex() { " " } else { "*" };
        let join = |fs: &[(Frag, i32)], neg: bool| -> Vec<String> {
            let mut parts = Vec::new();
            for (f, e) in fs {
                let e = if neg { -e } else { *e };
                let f = Frag {
                    text: f.text.clone(),
                    prec: f.prec,
                };
                parts.push(if e == 1 {
                    self.wrap(f, POWER)
                } else {
                    self.pow(f, e)
                });
            }
            parts.sort_by(|a, b| print_order(a).cmp(&print_order(b)));
            parts
        };
        let (num, den): (Vec<_>, Vec<_>) = factors.into_iter().partition(|(_, e)| *e > 0);
        let n = join(&num, false);
        let d = join(&den, true);
        let n_text = if n.is_empty() {
            "1".to_string()
        } else {
            n.join(sep)
        };
        if d.is_empty() {
            return Frag {
                text: n_text,
                prec: PRODUCT,
            };
        }
        let text = if self.latex() {
            format!("\\frac{{{}}}{{{}}}", n_text, d.join(sep))
        } else if d.len() == 1 {
            format!("{}/{}", n_text, d[0])
        } else {
            format!("{}/({})", n_text, d.join(sep))
        };
        Frag {
            text,
            prec: PRODUCT,
        }
    }

    /// `constant + sum k_i t_i`, terms sorted by their text.
    fn sum(&self, constant: f64, terms: Vec<(Frag, f64)>) -> Frag {
        let mut items: Vec<(bool, String)> = Vec::new(); // (negative, magnitude text)
        for (t, k) in terms {
            let mag = k.abs();
            let body = if mag == 1.0 {
                self.wrap(t, PRODUCT)
            } else {
                let c = format_number(mag, self.style.digits);
                let c = self.num(c.parse().unwrap_or(mag)).text;
                let sep = if self.latex() { " " } else { "*" };
                format!("{c}{sep}{}", self.wrap(t, PRODUCT))
            };
            items.push((k < 0.0, body));
        }
        items.sort_by(|a, b| {
            print_order(&a.1)
                .cmp(&print_order(&b.1))
                .then(a.0.cmp(&b.0))
        });
        if constant != 0.0 {
            items.push((
                constant < 0.0,
                format_number(constant.abs(), self.style.digits),
            ));
        }
        if items.len() == 1 && !items[0].0 {
            let (_, t) = items.pop().expect("one item");
            return Frag {
                text: t,
                prec: PRODUCT,
            };
        }
        let mut text = String::new();
        for (i, (neg, body)) in items.iter().enumerate() {
            match (i, neg) {
                (0, true) => text.push('-'),
                (0, false) => {}
                (_, true) => text.push_str(" - "),
                (_, false) => text.push_str(" + "),
            }
            text.push_str(body);
        }
        Frag { text, prec: SUM }
    }
}

/// Order of terms and factors in print: simpler (shorter, fewer functions) first, then by text.
fn print_order(s: &str) -> (usize, usize, &str) {
    let funcs = s.matches("sin").count() + s.matches("cos").count();
    (funcs, s.len(), s)
}

fn latex_symbol(name: &str) -> String {
    // q3 -> q_{3}, qd3 -> \dot{q}_{3}, qdd3 -> \ddot{q}_{3}, m_link -> m_{\mathrm{link}}
    let split = name.find(|c: char| c.is_ascii_digit() || c == '_');
    let (head, tail) = match split {
        Some(i) => (&name[..i], name[i..].trim_start_matches('_')),
        None => (name, ""),
    };
    let head = match head {
        "qd" => "\\dot{q}".to_string(),
        "qdd" => "\\ddot{q}".to_string(),
        h if h.len() > 1 => format!("\\mathrm{{{}}}", h.replace('_', "\\_")),
        h => h.to_string(),
    };
    if tail.is_empty() {
        head
    } else if tail.chars().all(|c| c.is_ascii_digit()) {
        format!("{head}_{{{tail}}}")
    } else {
        format!("{head}_{{\\mathrm{{{}}}}}", tail.replace('_', "\\_"))
    }
}

/// Each symbol's printed name in the given syntax.
fn symbol_names(symbols: &[Symbol], syntax: Syntax) -> Vec<String> {
    symbols
        .iter()
        .map(|s| match syntax {
            Syntax::Text => s.name.clone(),
            Syntax::Latex => latex_symbol(&s.name),
        })
        .collect()
}

impl Graph {
    /// Prints one expression.
    pub fn print(&self, e: Id, style: Style) -> String {
        let names = symbol_names(self.symbols(), style.syntax);
        let lookup = |s: u32| names[s as usize].clone();
        let p = Printer {
            style,
            symbol_name: &lookup,
        };
        // Iterative over the reachable nodes (children first): no deep recursion.
        let order = self.reachable(&[e]);
        let mut out: Vec<Option<Frag>> = Vec::with_capacity(order.len());
        let slot = |id: Id| order.binary_search(&id).expect("reachable");
        for &id in &order {
            let take = |out: &Vec<Option<Frag>>, c: Id| {
                let f = out[slot(c)].as_ref().expect("child first");
                Frag {
                    text: f.text.clone(),
                    prec: f.prec,
                }
            };
            let f = match self.node(id) {
                Node::Const(c) => p.num(c.get()),
                Node::Sym(s) => p.symbol(*s),
                Node::Add(c, ts) => p.sum(
                    c.get(),
                    ts.iter().map(|(t, k)| (take(&out, *t), k.get())).collect(),
                ),
                Node::Mul(fs) => p.product(fs.iter().map(|(f, x)| (take(&out, *f), *x)).collect()),
                Node::Sin(a) => p.func("sin", take(&out, *a)),
                Node::Cos(a) => p.func("cos", take(&out, *a)),
                Node::Sqrt(a) => p.func("sqrt", take(&out, *a)),
                Node::Recip(a) => p.product(vec![(take(&out, *a), -1)]),
                Node::Sign(a) => p.func(
                    if style.syntax == Syntax::Latex {
                        "operatorname{sign}"
                    } else {
                        "sign"
                    },
                    take(&out, *a),
                ),
            };
            out.push(Some(f));
        }
        out[slot(e)].take().expect("root").text
    }

    /// True when `e` depends on a joint position, velocity or acceleration.
    pub fn depends_on_state(&self, e: Id) -> bool {
        self.reachable(&[e]).iter().any(|&id| match self.node(id) {
            Node::Sym(s) => self.symbols()[*s as usize].kind != SymbolKind::Param,
            _ => false,
        })
    }
}

impl Program {
    /// Prints a program as `name = expression` lines: temporaries `t0, t1, ...`, then the outputs
    /// under the given names.
    pub fn print(&self, output_names: &[String], style: Style) -> String {
        let names = symbol_names(&self.symbols, style.syntax);
        let lookup = |s: u32| names[s as usize].clone();
        let p = Printer {
            style,
            symbol_name: &lookup,
        };
        let temp = |k: usize| match style.syntax {
            Syntax::Text => format!("t{k}"),
            Syntax::Latex => format!("t_{{{k}}}"),
        };
        let mut s = String::new();
        let (assign, end) = match style.syntax {
            Syntax::Text => (" = ", "\n"),
            Syntax::Latex => (" &= ", " \\\\\n"),
        };
        for (k, e) in self.temps.iter().enumerate() {
            s.push_str(&format!(
                "{}{}{}{}",
                temp(k),
                assign,
                print_expr(&p, e, &temp).text,
                end
            ));
        }
        for (name, e) in output_names.iter().zip(&self.outputs) {
            s.push_str(&format!(
                "{}{}{}{}",
                name,
                assign,
                print_expr(&p, e, &temp).text,
                end
            ));
        }
        s
    }
}

fn print_expr(p: &Printer<'_>, e: &Expr, temp: &dyn Fn(usize) -> String) -> Frag {
    match e {
        Expr::Const(c) => p.num(*c),
        Expr::Input(s) => p.symbol(*s),
        Expr::Temp(t) => Frag {
            text: temp(*t),
            prec: ATOM,
        },
        Expr::Add(c, ts) => p.sum(
            *c,
            ts.iter()
                .map(|(t, k)| (print_expr(p, t, temp), *k))
                .collect(),
        ),
        Expr::Mul(fs) => p.product(
            fs.iter()
                .map(|(f, x)| (print_expr(p, f, temp), *x))
                .collect(),
        ),
        Expr::Sin(a) => p.func("sin", print_expr(p, a, temp)),
        Expr::Cos(a) => p.func("cos", print_expr(p, a, temp)),
        Expr::Sqrt(a) => p.func("sqrt", print_expr(p, a, temp)),
        Expr::Recip(a) => p.product(vec![(print_expr(p, a, temp), -1)]),
        Expr::Sign(a) => p.func("sign", print_expr(p, a, temp)),
    }
}
