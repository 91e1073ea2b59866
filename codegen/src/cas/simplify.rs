//! Simplification beyond what the constructors do: expansion into a sum of monomials, and the
//! trigonometric identities that make printed equations readable.
//!
//! The constructors in [`graph`](super::graph) never distribute products over sums: expansion can
//! multiply the size of an expression, and generated code is faster factored. For people, though,
//! `2 l1 lc2 m2 cos(q2)` reads better than the factored form of the same number, so printing
//! expands and then applies
//! - `k r sin(a)^2 + k r cos(a)^2 = k r` (Pythagoras, for any common rest `r`), and
//! - `k r cos(a) cos(b) - k r sin(a) sin(b) = k r cos(a + b)`, with the `cos(a - b)`,
//!   `sin(a + b)` and `sin(a - b)` forms alike.
//!
//! Numeric coefficients are matched with a relative tolerance of `1e-12`, since the same number
//! reached through different sums can differ in its last bits.

use std::collections::{BTreeMap, HashMap};

use super::graph::{Graph, Id, Node};

/// A monomial: atoms (symbols, functions, non-expandable powers) with exponents, sorted by atom.
type Mono = Vec<(Id, i32)>;
/// A polynomial: monomial to coefficient. A `BTreeMap` so that every pass is deterministic.
type Poly = BTreeMap<Mono, f64>;

/// The expansion would exceed this many terms.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("expansion exceeds {0} terms")]
pub struct TooLarge(pub usize);

const REL_TOL: f64 = 1e-12;

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= REL_TOL * a.abs().max(b.abs())
}

fn mono_mul(a: &Mono, b: &Mono) -> Mono {
    let mut out: Mono = Vec::with_capacity(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() || j < b.len() {
        let next = match (a.get(i), b.get(j)) {
            (Some(x), Some(y)) if x.0 == y.0 => {
                i += 1;
                j += 1;
                (x.0, x.1 + y.1)
            }
            (Some(x), Some(y)) if x.0 < y.0 => {
                i += 1;
                *x
            }
            (Some(x), None) => {
                i += 1;
                *x
            }
            (_, Some(y)) => {
                j += 1;
                *y
            }
            (None, None) => unreachable!(),
        };
        if next.1 != 0 {
            out.push(next);
        }
    }
    out
}

/// `m * atom^delta`.
fn mono_shift(m: &Mono, atom: Id, delta: i32) -> Mono {
    mono_mul(m, &vec![(atom, delta)])
}

fn poly_add(acc: &mut Poly, p: &Poly, k: f64) {
    for (m, c) in p {
        *acc.entry(m.clone()).or_insert(0.0) += k * c;
    }
}

fn poly_mul(a: &Poly, b: &Poly, limit: usize) -> Result<Poly, TooLarge> {
    if a.len() * b.len() > limit {
        return Err(TooLarge(limit));
    }
    let mut out = Poly::new();
    for (ma, ca) in a {
        for (mb, cb) in b {
            *out.entry(mono_mul(ma, mb)).or_insert(0.0) += ca * cb;
        }
    }
    Ok(out)
}

fn atom(id: Id) -> Poly {
    Poly::from([(vec![(id, 1)], 1.0)])
}

impl Graph {
    /// Expands `e` into a sum of monomials, applies the trigonometric identities above, and
    /// rebuilds it. Fails when an intermediate polynomial would exceed `max_terms` terms.
    pub fn expand_trig(&mut self, e: Id, max_terms: usize) -> Result<Id, TooLarge> {
        let mut p = self.expand_poly(e, max_terms)?;
        self.trig_rules(&mut p);
        Ok(self.rebuild(&p))
    }

    /// Expands `e` into a sum of monomials (no trigonometric rules).
    pub fn expand(&mut self, e: Id, max_terms: usize) -> Result<Id, TooLarge> {
        let p = self.expand_poly(e, max_terms)?;
        Ok(self.rebuild(&p))
    }

    fn expand_poly(&mut self, e: Id, limit: usize) -> Result<Poly, TooLarge> {
        let order = self.reachable(&[e]);
        let mut memo: HashMap<Id, Poly> = HashMap::new();
        for &id in &order {
            let p = match self.node(id).clone() {
                Node::Const(c) => {
                    if c.get() == 0.0 {
                        Poly::new()
                    } else {
                        Poly::from([(Vec::new(), c.get())])
                    }
                }
                Node::Sym(_)
                | Node::Sin(_)
                | Node::Cos(_)
                | Node::Sqrt(_)
                | Node::Sign(_)
                | Node::Recip(_) => atom(id),
                Node::Add(c, ts) => {
                    let mut acc = Poly::new();
                    if c.get() != 0.0 {
                        acc.insert(Vec::new(), c.get());
                    }
                    for (t, k) in ts.iter() {
                        poly_add(&mut acc, &memo[t], k.get());
                    }
                    acc
                }
                Node::Mul(fs) => {
                    let mut acc = Poly::from([(Vec::new(), 1.0)]);
                    for &(f, x) in fs.iter() {
                        let pf = &memo[&f];
                        let factor = if x > 0 {
                            let mut r = pf.clone();
                            for _ in 1..x {
                                r = poly_mul(&r, pf, limit)?;
                            }
                            r
                        } else if pf.len() == 1 {
                            // A single monomial inverts exactly.
                            let (m, c) = pf.iter().next().expect("one term");
                            let inv: Mono = m.iter().map(|&(a, y)| (a, y * x)).collect();
                            Poly::from([(inv, c.powi(x))])
                        } else {
                            // A sum in a denominator stays an atom.
                            let base = self.rebuild(pf);
                            Poly::from([(vec![(base, x)], 1.0)])
                        };
                        acc = poly_mul(&acc, &factor, limit)?;
                    }
                    acc
                }
            };
            let mut p = p;
            p.retain(|_, c| *c != 0.0);
            if p.len() > limit {
                return Err(TooLarge(limit));
            }
            memo.insert(id, p);
        }
        Ok(memo.remove(&e).unwrap_or_default())
    }

    fn rebuild(&mut self, p: &Poly) -> Id {
        let mut terms = Vec::with_capacity(p.len());
        for (m, c) in p {
            let t = self.product(m.iter().copied());
            terms.push((t, *c));
        }
        self.sum(0.0, terms)
    }

    /// The argument of `sin`/`cos` atoms.
    fn trig_arg(&self, a: Id) -> Option<(bool, Id)> {
        match self.node(a) {
            Node::Sin(x) => Some((true, *x)),
            Node::Cos(x) => Some((false, *x)),
            _ => None,
        }
    }

    fn trig_rules(&mut self, p: &mut Poly) {
        while self.pythagoras(p) || self.angle_sum(p) {}
    }

    /// One application of `k r sin^2 + k r cos^2 = k r`; false when none applies.
    fn pythagoras(&mut self, p: &mut Poly) -> bool {
        let mut found = None;
        'search: for (m, &k) in p.iter() {
            for &(a, e) in m {
                if e < 2 {
                    continue;
                }
                if let Some((true, x)) = self.trig_arg(a) {
                    let c = self.cos(x);
                    let partner = mono_shift(&mono_shift(m, a, -2), c, 2);
                    if let Some(&k2) = p.get(&partner) {
                        if close(k, k2) {
                            found = Some((m.clone(), partner, mono_shift(m, a, -2), k));
                            break 'search;
                        }
                    }
                }
            }
        }
        match found {
            Some((m1, m2, rest, k)) => {
                p.remove(&m1);
                p.remove(&m2);
                let slot = p.entry(rest.clone()).or_insert(0.0);
                *slot += k;
                if *slot == 0.0 {
                    p.remove(&rest);
                }
                true
            }
            None => false,
        }
    }

    /// One application of an angle-sum rule; false when none applies.
    fn angle_sum(&mut self, p: &mut Poly) -> bool {
        let mut found = None;
        'search: for (m, &k) in p.iter() {
            // Pairs of distinct trig atoms in m.
            let trig: Vec<(Id, bool, Id)> = m
                .iter()
                .filter_map(|&(a, _)| self.trig_arg(a).map(|(s, x)| (a, s, x)))
                .collect();
            for (i, &(a1, s1, x1)) in trig.iter().enumerate() {
                for &(a2, s2, x2) in &trig[i + 1..] {
                    if x1 == x2 {
                        continue;
                    }
                    let rest = mono_shift(&mono_shift(m, a1, -1), a2, -1);
                    // The partner swaps sin and cos on both atoms.
                    let b1 = if s1 { self.cos(x1) } else { self.sin(x1) };
                    let b2 = if s2 { self.cos(x2) } else { self.sin(x2) };
                    let partner = mono_shift(&mono_shift(&rest, b1, 1), b2, 1);
                    let Some(&k2) = p.get(&partner) else { continue };
                    let result = match (s1, s2) {
                        // cos cos with sin sin: cos(x1 + x2) when k2 = -k, cos(x1 - x2) when k2 = k
                        (false, false) if close(k2, -k) => Some((false, 1.0)),
                        (false, false) if close(k2, k) => Some((false, -1.0)),
                        // sin x1 cos x2 with cos x1 sin x2: sin(x1 + x2) / sin(x1 - x2)
                        (true, false) if close(k2, k) => Some((true, 1.0)),
                        (true, false) if close(k2, -k) => Some((true, -1.0)),
                        (false, true) if close(k2, k) => Some((true, 1.0)),
                        (false, true) if close(k2, -k) => Some((true, -2.0)),
                        _ => None,
                    };
                    if let Some((is_sin, sign)) = result {
                        found = Some((m.clone(), partner, rest, k, is_sin, sign, x1, x2));
                        break 'search;
                    }
                }
            }
        }
        let Some((m1, m2, rest, k, is_sin, sign, x1, x2)) = found else {
            return false;
        };
        p.remove(&m1);
        p.remove(&m2);
        // sign: 1 -> x1 + x2; -1 -> x1 - x2; -2 -> x2 - x1 (cos x1 sin x2 - sin x1 cos x2).
        let arg = match sign as i32 {
            1 => self.add(x1, x2),
            -1 => self.sub(x1, x2),
            _ => self.sub(x2, x1),
        };
        let f = if is_sin { self.sin(arg) } else { self.cos(arg) };
        // sin/cos may have pulled out a sign: fold it into the coefficient.
        let (kf, core) = self.split_coefficient(f);
        let mono = mono_shift(&rest, core, 1);
        let slot = p.entry(mono.clone()).or_insert(0.0);
        *slot += k * kf;
        if *slot == 0.0 {
            p.remove(&mono);
        }
        true
    }
}
