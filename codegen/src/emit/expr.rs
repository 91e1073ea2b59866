//! Expressions of a straight-line program as Rust tokens over `eomgen_runtime::Real`.

use std::collections::{BTreeMap, BTreeSet};

use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote};

use crate::cas::{Expr, Symbol, SymbolKind};

/// Turns program expressions into tokens.
pub(super) struct Ctx<'a> {
    pub symbols: &'a [Symbol],
    /// Parameter symbol index -> struct field.
    pub fields: &'a BTreeMap<u32, Ident>,
}

/// Tokens of an expression and whether it is a sum (needs parentheses inside a product).
pub(super) struct Tok {
    pub ts: TokenStream,
    pub sum: bool,
    /// A plain name or literal call, cheap to repeat.
    atom: bool,
}

pub(super) fn lit(v: f64) -> TokenStream {
    if v.is_nan() {
        return quote!(T::nan());
    }
    if v.is_infinite() {
        return if v > 0.0 {
            quote!(T::from_f64(f64::INFINITY))
        } else {
            quote!(T::from_f64(f64::NEG_INFINITY))
        };
    }
    if v == 0.0 {
        return quote!(T::zero());
    }
    if v == 1.0 {
        return quote!(T::one());
    }
    let l = Literal::f64_unsuffixed(v.abs());
    if v < 0.0 {
        quote!((-T::from_f64(#l)))
    } else {
        quote!(T::from_f64(#l))
    }
}

/// [`lit`] as the whole right-hand side of an assignment: a negative number without the
/// parentheses it needs inside an expression (`unused_parens` would flag them there).
pub(super) fn assigned_lit(v: f64) -> TokenStream {
    if v < 0.0 && v.is_finite() {
        let l = Literal::f64_unsuffixed(-v);
        quote!(-T::from_f64(#l))
    } else {
        lit(v)
    }
}

impl Ctx<'_> {
    fn input(&self, s: u32, trig: &mut BTreeSet<(usize, bool)>, sin: Option<bool>) -> TokenStream {
        let sym = &self.symbols[s as usize];
        let idx = |i: usize| Literal::usize_unsuffixed(i);
        match (sym.kind, sin) {
            (SymbolKind::Q(i), Some(is_sin)) => {
                trig.insert((i, is_sin));
                let name = if is_sin {
                    format_ident!("s{}", i)
                } else {
                    format_ident!("c{}", i)
                };
                quote!(#name)
            }
            (SymbolKind::Q(i), None) => {
                let i = idx(i);
                quote!(q[#i])
            }
            (SymbolKind::Qd(i), None) => {
                let i = idx(i);
                quote!(qd[#i])
            }
            (SymbolKind::Force(i), None) => {
                let i = idx(i);
                quote!(forces[#i])
            }
            (SymbolKind::Tau(i), None) => {
                let i = idx(i);
                quote!(tau[#i])
            }
            (SymbolKind::Qdd(i), None) => {
                let i = idx(i);
                quote!(qdd[#i])
            }
            (SymbolKind::Param, None) => {
                let f = &self.fields[&s];
                quote!(self.#f)
            }
            (_, Some(is_sin)) => {
                let inner = self.input(s, trig, None);
                if is_sin {
                    quote!(#inner.sin())
                } else {
                    quote!(#inner.cos())
                }
            }
        }
    }

    pub(super) fn expr(&self, e: &Expr, trig: &mut BTreeSet<(usize, bool)>) -> Tok {
        match e {
            Expr::Const(c) => Tok {
                ts: lit(*c),
                sum: false,
                atom: true,
            },
            Expr::Input(s) => Tok {
                ts: self.input(*s, trig, None),
                sum: false,
                atom: true,
            },
            Expr::Temp(t) => {
                let name = format_ident!("t{}", t);
                Tok {
                    ts: quote!(#name),
                    sum: false,
                    atom: true,
                }
            }
            Expr::Sin(a) | Expr::Cos(a) => {
                let is_sin = matches!(e, Expr::Sin(_));
                if let Expr::Input(s) = **a {
                    return Tok {
                        ts: self.input(s, trig, Some(is_sin)),
                        sum: false,
                        atom: true,
                    };
                }
                let inner = self.paren(a, trig);
                let ts = if is_sin {
                    quote!(#inner.sin())
                } else {
                    quote!(#inner.cos())
                };
                Tok {
                    ts,
                    sum: false,
                    atom: false,
                }
            }
            Expr::Sqrt(a) => {
                let inner = self.paren(a, trig);
                Tok {
                    ts: quote!(#inner.sqrt()),
                    sum: false,
                    atom: false,
                }
            }
            // Marked as a sum so that a product parenthesizes it: `x * (T::one() / d)`.
            Expr::Recip(a) => {
                let inner = self.paren(a, trig);
                Tok {
                    ts: quote!(T::one() / #inner),
                    sum: true,
                    atom: false,
                }
            }
            Expr::Sign(a) => {
                let inner = self.paren(a, trig);
                Tok {
                    ts: quote!(#inner.signum()),
                    sum: false,
                    atom: false,
                }
            }
            Expr::Add(c, terms) => self.sum(*c, terms, trig),
            Expr::Mul(factors) => self.product(factors, trig),
        }
    }

    /// A product of integer powers: the factors with a positive exponent over those with a
    /// negative one.
    fn product(&self, factors: &[(Expr, i32)], trig: &mut BTreeSet<(usize, bool)>) -> Tok {
        let mut num: Vec<TokenStream> = Vec::new();
        let mut den: Vec<TokenStream> = Vec::new();
        for (f, x) in factors {
            let ft = self.expr(f, trig);
            let raw = ft.ts.clone();
            let base = if ft.sum { paren(ft.ts) } else { ft.ts };
            let n = x.unsigned_abs() as usize;
            let power = if n == 1 {
                base
            } else if ft.atom && *x > 0 {
                join_mul(std::iter::repeat_n(base, n).collect())
            } else if ft.atom {
                // A divisor `t * t * t` needs its parentheses: `a / (t * t * t)`.
                paren(join_mul(std::iter::repeat_n(base, n).collect()))
            } else {
                // Evaluate a compound base once.
                let prod = join_mul(std::iter::repeat_n(quote!(b), n).collect());
                quote!({ let b = #raw; #prod })
            };
            if *x > 0 {
                num.push(power);
            } else {
                den.push(power);
            }
        }
        let n = if num.is_empty() {
            quote!(T::one())
        } else {
            join_mul(num)
        };
        let ts = match den.len() {
            0 => n,
            1 => {
                let d = &den[0];
                quote!(#n / #d)
            }
            _ => {
                let d = join_mul(den);
                quote!(#n / (#d))
            }
        };
        Tok {
            ts,
            sum: false,
            atom: false,
        }
    }

    /// A sum: the terms that are no product first (positive ones first, so that the sum starts
    /// without a negation when it can), then each product `k x y` folded in by a multiply-add,
    /// `T::mul_add(x, y, acc)`: one fused instruction where the target has one (the runtime's
    /// `Real::mul_add`), a multiplication and an addition elsewhere.
    fn sum(&self, c: f64, terms: &[(Expr, f64)], trig: &mut BTreeSet<(usize, bool)>) -> Tok {
        let mut plain: Vec<(bool, TokenStream)> = Vec::new();
        let mut products: Vec<(bool, Tok, Tok)> = Vec::new();
        for (t, k) in terms {
            match self.product_parts(t, *k, trig) {
                Some((x, y)) => products.push((*k < 0.0, x, y)),
                // A negated sum keeps its parentheses: `a - (x + y)`.
                None => {
                    let body = self.expr(t, trig);
                    let body = if *k < 0.0 {
                        parenthesized(body)
                    } else {
                        body.ts
                    };
                    plain.push((*k < 0.0, body));
                }
            }
        }
        if c != 0.0 {
            plain.push((c < 0.0, lit(c.abs())));
        }
        plain.sort_by_key(|p| p.0);
        let mut acc: Option<TokenStream> = None;
        for (neg, body) in plain {
            acc = Some(match (acc, neg) {
                (None, false) => body,
                (None, true) => quote!(-#body),
                (Some(a), false) => quote!(#a + #body),
                (Some(a), true) => quote!(#a - #body),
            });
        }
        for (neg, x, y) in products {
            acc = Some(match acc {
                None => {
                    let (x, y) = (parenthesized(x), parenthesized(y));
                    if neg {
                        quote!(-#x * #y)
                    } else {
                        quote!(#x * #y)
                    }
                }
                Some(a) => {
                    let x = if neg {
                        let x = parenthesized(x);
                        quote!(-#x)
                    } else {
                        x.ts
                    };
                    let y = y.ts;
                    quote!(T::mul_add(#x, #y, #a))
                }
            });
        }
        Tok {
            ts: acc.unwrap_or_else(|| lit(0.0)),
            sum: true,
            atom: false,
        }
    }

    /// A term `k t` of a sum as the two factors `(x, y)` of a product, magnitudes only: `|k|`
    /// and `t` for a coefficient other than one, else the first factor of a product `t` and the
    /// rest; `None` for a term that is no product (or holds a division).
    fn product_parts(
        &self,
        t: &Expr,
        k: f64,
        trig: &mut BTreeSet<(usize, bool)>,
    ) -> Option<(Tok, Tok)> {
        if k.abs() != 1.0 {
            let x = Tok {
                ts: lit(k.abs()),
                sum: false,
                atom: true,
            };
            return Some((x, self.expr(t, trig)));
        }
        let Expr::Mul(fs) = t else { return None };
        if fs.iter().any(|f| f.1 < 0) || (fs.len() == 1 && fs[0].1 == 1) {
            return None;
        }
        let mut rest = fs.clone();
        let first = rest[0].0.clone();
        if rest[0].1 == 1 {
            rest.remove(0);
        } else {
            rest[0].1 -= 1;
        }
        let y = match rest.as_slice() {
            [(only, 1)] => self.expr(only, trig),
            _ => self.expr(&Expr::Mul(rest), trig),
        };
        Some((self.expr(&first, trig), y))
    }

    fn paren(&self, e: &Expr, trig: &mut BTreeSet<(usize, bool)>) -> TokenStream {
        let t = self.expr(e, trig);
        if t.atom {
            t.ts
        } else {
            paren(t.ts)
        }
    }
}

fn paren(ts: TokenStream) -> TokenStream {
    quote!((#ts))
}

/// A factor's tokens, parenthesized when it is a sum.
fn parenthesized(t: Tok) -> TokenStream {
    if t.sum {
        paren(t.ts)
    } else {
        t.ts
    }
}

fn join_mul(items: Vec<TokenStream>) -> TokenStream {
    let mut it = items.into_iter();
    let first = it.next().unwrap_or_else(|| quote!(T::one()));
    it.fold(first, |acc, x| quote!(#acc * #x))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cas::{Graph, Program, SumFlattening};

    /// `a - (b + c)` with the inner sum kept as one term (as shared sums are): the emitted
    /// tokens keep its parentheses, where `a - b + c` would be another value.
    #[test]
    fn a_negated_sum_keeps_its_parentheses() {
        let mut g = Graph::new();
        g.set_flattening(SumFlattening::Shared);
        let (a, b, c) = (g.q(0), g.q(1), g.q(2));
        let bc = g.add(b, c);
        let e = g.sub(a, bc);
        let p = Program::new(&g, &[e]);
        let fields = BTreeMap::new();
        let ctx = Ctx {
            symbols: &p.symbols,
            fields: &fields,
        };
        let text = ctx.expr(&p.outputs[0], &mut BTreeSet::new()).ts.to_string();
        assert_eq!(text, "q [0] - (q [1] + q [2])");
    }
}
