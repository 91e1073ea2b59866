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
            Expr::Sign(a) => {
                let inner = self.paren(a, trig);
                Tok {
                    ts: quote!(#inner.signum()),
                    sum: false,
                    atom: false,
                }
            }
            Expr::Add(c, terms) => {
                // Positive terms first, so that the sum starts without a negation when it can.
                let mut parts: Vec<(bool, TokenStream)> = Vec::new();
                for (t, k) in terms {
                    let tt = self.expr(t, trig);
                    let body = if k.abs() == 1.0 {
                        tt.ts
                    } else {
                        let coef = lit(k.abs());
                        let inner = if tt.sum { paren(tt.ts) } else { tt.ts };
                        quote!(#coef * #inner)
                    };
                    parts.push((*k < 0.0, body));
                }
                if *c != 0.0 {
                    parts.push((*c < 0.0, lit(c.abs())));
                }
                parts.sort_by_key(|p| p.0);
                let mut ts = TokenStream::new();
                for (i, (neg, body)) in parts.into_iter().enumerate() {
                    ts = match (i, neg) {
                        (0, false) => body,
                        (0, true) => quote!(-#body),
                        (_, false) => quote!(#ts + #body),
                        (_, true) => quote!(#ts - #body),
                    };
                }
                Tok {
                    ts,
                    sum: true,
                    atom: false,
                }
            }
            Expr::Mul(factors) => {
                let mut num: Vec<TokenStream> = Vec::new();
                let mut den: Vec<TokenStream> = Vec::new();
                for (f, x) in factors {
                    let ft = self.expr(f, trig);
                    let raw = ft.ts.clone();
                    let base = if ft.sum { paren(ft.ts) } else { ft.ts };
                    let n = x.unsigned_abs() as usize;
                    let power = if n == 1 {
                        base
                    } else if ft.atom {
                        join_mul(std::iter::repeat_n(base, n).collect())
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
        }
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

fn join_mul(items: Vec<TokenStream>) -> TokenStream {
    let mut it = items.into_iter();
    let first = it.next().unwrap_or_else(|| quote!(T::one()));
    it.fold(first, |acc, x| quote!(#acc * #x))
}
