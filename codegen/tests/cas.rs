//! The symbolic core: one test per simplification rule, property tests against a direct
//! evaluation of random expression trees, and a two-process determinism check.

use crate::child;

use eomgen::cas::{Graph, Id, Node, Order, Program, Style, SumFlattening, Syntax};
use proptest::prelude::*;

const NVARS: usize = 3;

/// A random expression, evaluated directly (no graph, no simplification) as the reference.
#[derive(Clone, Debug)]
enum Tree {
    Var(usize),
    Const(f64),
    Add(Box<Tree>, Box<Tree>),
    Sub(Box<Tree>, Box<Tree>),
    Mul(Box<Tree>, Box<Tree>),
    /// `a / (2 + sin b)`: a denominator that never vanishes.
    Div(Box<Tree>, Box<Tree>),
    Pow(Box<Tree>, i32),
    Sin(Box<Tree>),
    Cos(Box<Tree>),
    Neg(Box<Tree>),
    /// `1 / (2 + sin a)` through `Graph::recip`, a reciprocal that products keep as a factor.
    Recip(Box<Tree>),
}

impl Tree {
    fn eval(&self, x: &[f64]) -> f64 {
        match self {
            Tree::Var(i) => x[*i],
            Tree::Const(c) => *c,
            Tree::Add(a, b) => a.eval(x) + b.eval(x),
            Tree::Sub(a, b) => a.eval(x) - b.eval(x),
            Tree::Mul(a, b) => a.eval(x) * b.eval(x),
            Tree::Div(a, b) => a.eval(x) / (2.0 + b.eval(x).sin()),
            Tree::Pow(a, n) => a.eval(x).powi(*n),
            Tree::Sin(a) => a.eval(x).sin(),
            Tree::Cos(a) => a.eval(x).cos(),
            Tree::Neg(a) => -a.eval(x),
            Tree::Recip(a) => 1.0 / (2.0 + a.eval(x).sin()),
        }
    }

    fn build(&self, g: &mut Graph) -> Id {
        match self {
            Tree::Var(i) => g.q(*i),
            Tree::Const(c) => g.constant(*c),
            Tree::Add(a, b) => {
                let (a, b) = (a.build(g), b.build(g));
                g.add(a, b)
            }
            Tree::Sub(a, b) => {
                let (a, b) = (a.build(g), b.build(g));
                g.sub(a, b)
            }
            Tree::Mul(a, b) => {
                let (a, b) = (a.build(g), b.build(g));
                g.mul(a, b)
            }
            Tree::Div(a, b) => {
                let (a, b) = (a.build(g), b.build(g));
                let s = g.sin(b);
                let two = g.constant(2.0);
                let d = g.add(two, s);
                g.div(a, d)
            }
            Tree::Pow(a, n) => {
                let a = a.build(g);
                g.powi(a, *n)
            }
            Tree::Sin(a) => {
                let a = a.build(g);
                g.sin(a)
            }
            Tree::Cos(a) => {
                let a = a.build(g);
                g.cos(a)
            }
            Tree::Neg(a) => {
                let a = a.build(g);
                g.neg(a)
            }
            Tree::Recip(a) => {
                let a = a.build(g);
                let s = g.sin(a);
                let two = g.constant(2.0);
                let d = g.add(two, s);
                g.recip(d)
            }
        }
    }

    /// The same expression with the operands of every commutative node swapped.
    fn mirrored(&self) -> Tree {
        let m = |t: &Tree| Box::new(t.mirrored());
        match self {
            Tree::Add(a, b) => Tree::Add(m(b), m(a)),
            Tree::Mul(a, b) => Tree::Mul(m(b), m(a)),
            Tree::Sub(a, b) => Tree::Sub(m(a), m(b)),
            Tree::Div(a, b) => Tree::Div(m(a), m(b)),
            Tree::Pow(a, n) => Tree::Pow(m(a), *n),
            Tree::Sin(a) => Tree::Sin(m(a)),
            Tree::Cos(a) => Tree::Cos(m(a)),
            Tree::Neg(a) => Tree::Neg(m(a)),
            Tree::Recip(a) => Tree::Recip(m(a)),
            leaf => leaf.clone(),
        }
    }
}

fn tree() -> impl Strategy<Value = Tree> {
    let leaf = prop_oneof![
        (0..NVARS).prop_map(Tree::Var),
        prop_oneof![Just(0.0), Just(1.0), Just(-1.0), Just(2.0), -3.0..3.0f64]
            .prop_map(Tree::Const),
    ];
    leaf.prop_recursive(5, 40, 2, |inner| {
        prop_oneof![
            (inner.clone(), inner.clone()).prop_map(|(a, b)| Tree::Add(Box::new(a), Box::new(b))),
            (inner.clone(), inner.clone()).prop_map(|(a, b)| Tree::Sub(Box::new(a), Box::new(b))),
            (inner.clone(), inner.clone()).prop_map(|(a, b)| Tree::Mul(Box::new(a), Box::new(b))),
            (inner.clone(), inner.clone()).prop_map(|(a, b)| Tree::Div(Box::new(a), Box::new(b))),
            (inner.clone(), 0..4i32).prop_map(|(a, n)| Tree::Pow(Box::new(a), n)),
            inner.clone().prop_map(|a| Tree::Sin(Box::new(a))),
            inner.clone().prop_map(|a| Tree::Cos(Box::new(a))),
            inner.clone().prop_map(|a| Tree::Neg(Box::new(a))),
            inner.prop_map(|a| Tree::Recip(Box::new(a))),
        ]
    })
}

fn point() -> impl Strategy<Value = Vec<f64>> {
    proptest::collection::vec(-1.5..1.5f64, NVARS)
}

fn eval(g: &Graph, e: &[Id], x: &[f64]) -> Vec<f64> {
    g.eval(e, |s| match s.kind {
        eomgen::cas::SymbolKind::Q(i) => x.get(i).copied(),
        _ => None,
    })
    .unwrap()
}

/// `d t / d x_var` by central differences of the tree itself.
fn central_difference(t: &Tree, x: &[f64], var: usize) -> f64 {
    let h = 1e-5;
    let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
    xp[var] += h;
    xm[var] -= h;
    (t.eval(&xp) - t.eval(&xm)) / (2.0 * h)
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn simplified_graph_evaluates_like_the_tree(t in tree(), x in point()) {
        let mut g = Graph::new();
        let e = t.build(&mut g);
        let want = t.eval(&x);
        prop_assume!(want.is_finite() && want.abs() < 1e8);
        let got = eval(&g, &[e], &x)[0];
        prop_assert!(close(got, want, 1e-9), "{} vs {}", got, want);
    }

    /// Shared sums (kept whole unless their terms collect) change the expressions' shape, not
    /// their value: the graph and its program evaluate like the tree, derivatives included.
    #[test]
    fn shared_sums_evaluate_like_the_tree(t in tree(), x in point(), var in 0..NVARS) {
        let mut g = Graph::new();
        g.set_flattening(SumFlattening::Shared);
        let e = t.build(&mut g);
        let v = g.q(var);
        let de = g.diff(e, v);
        let want = t.eval(&x);
        prop_assume!(want.is_finite() && want.abs() < 1e8);
        let got = eval(&g, &[e], &x)[0];
        prop_assert!(close(got, want, 1e-9), "{} vs {}", got, want);
        let p = Program::new(&g, &[e, de]);
        let run = p.eval(|s| match s.kind { eomgen::cas::SymbolKind::Q(i) => x.get(i).copied(), _ => None }).unwrap();
        prop_assert!(close(run[0], want, 1e-9), "program {} vs {}", run[0], want);
        let fd = central_difference(&t, &x, var);
        prop_assume!(fd.is_finite() && fd.abs() < 1e4);
        prop_assert!(close(run[1], fd, 1e-4), "d/dq{}: {} vs {}", var, run[1], fd);
    }

    #[test]
    fn derivative_matches_central_differences(t in tree(), x in point(), var in 0..NVARS) {
        let mut g = Graph::new();
        let e = t.build(&mut g);
        let v = g.q(var);
        let de = g.diff(e, v);
        let fd = central_difference(&t, &x, var);
        prop_assume!(fd.is_finite() && fd.abs() < 1e4);
        let got = eval(&g, &[de], &x)[0];
        prop_assert!(close(got, fd, 1e-4), "d/dq{}: {} vs {}", var, got, fd);
    }

    #[test]
    fn program_evaluates_like_the_graph(ts in proptest::collection::vec(tree(), 1..6), x in point()) {
        let mut g = Graph::new();
        let outs: Vec<Id> = ts.iter().map(|t| t.build(&mut g)).collect();
        // Share work between outputs, as dynamics do.
        let q0 = g.q(0);
        let d: Vec<Id> = g.diff_many(&outs, q0);
        let all: Vec<Id> = outs.iter().chain(&d).copied().collect();
        let want = eval(&g, &all, &x);
        let p = Program::new(&g, &all);
        let levels = Program::ordered(&g, &all, Order::Levels);
        // The same operations, in another order.
        prop_assert_eq!(p.ops(), levels.ops());
        prop_assert_eq!(p.temps.len(), levels.temps.len());
        for p in [p, levels] {
            let got = p.eval(|s| match s.kind { eomgen::cas::SymbolKind::Q(i) => x.get(i).copied(), _ => None }).unwrap();
            for (a, b) in got.iter().zip(&want) {
                prop_assert!(a == b || (a.is_nan() && b.is_nan()) || close(*a, *b, 1e-12), "{} vs {}", a, b);
            }
        }
    }

    #[test]
    fn equal_expressions_built_in_different_orders_share_an_id(t in tree()) {
        let mut g = Graph::new();
        // Build the mirror first, so leaves are created in a different order.
        let b = t.mirrored().build(&mut g);
        let a = t.build(&mut g);
        prop_assert_eq!(a, b);
    }

    #[test]
    fn expansion_and_trig_rules_keep_the_value(t in tree(), x in point()) {
        let mut g = Graph::new();
        let e = t.build(&mut g);
        let want = eval(&g, &[e], &x)[0];
        prop_assume!(want.is_finite() && want.abs() < 1e6);
        if let Ok(s) = g.expand_trig(e, 2000) {
            let got = eval(&g, &[s], &x)[0];
            prop_assert!(close(got, want, 1e-8), "{} vs {}", got, want);
        }
    }

    #[test]
    fn substitution_equals_evaluating_at_the_value(t in tree(), x in point()) {
        let mut g = Graph::new();
        let e = t.build(&mut g);
        let q1 = g.q(1);
        let v = g.constant(x[1]);
        let s = g.substitute(&[e], &[(q1, v)].into_iter().collect())[0];
        prop_assert!(!g.depends_on(s, q1));
        let want = eval(&g, &[e], &x)[0];
        prop_assume!(want.is_finite());
        let got = eval(&g, &[s], &x)[0];
        prop_assert!(close(got, want, 1e-12), "{} vs {}", got, want);
    }

    #[test]
    fn time_derivative_follows_a_trajectory(t in tree(), x in point(), v in point(), a in point()) {
        // q(t) = x + v t + a t^2 / 2, qd = v + a t.
        let mut g = Graph::new();
        let q_expr = t.build(&mut g);
        // The expression in q and qd: f(q) * qd_0 + q_expr.
        let qd0 = g.qd(0);
        let e = { let m = g.mul(q_expr, qd0); g.add(m, q_expr) };
        let de = g.time_derivative(e);
        let at = |tt: f64| -> f64 {
            let q: Vec<f64> = (0..NVARS).map(|i| x[i] + v[i] * tt + 0.5 * a[i] * tt * tt).collect();
            let qd0 = v[0] + a[0] * tt;
            t.eval(&q) * qd0 + t.eval(&q)
        };
        let h = 1e-5;
        let fd = (at(h) - at(-h)) / (2.0 * h);
        prop_assume!(fd.is_finite() && fd.abs() < 1e4);
        let got = g.eval(&[de], |s| match s.kind {
            eomgen::cas::SymbolKind::Q(i) => Some(x[i]),
            eomgen::cas::SymbolKind::Qd(i) => Some(v[i]),
            eomgen::cas::SymbolKind::Qdd(i) => Some(a[i]),
            _ => None,
        }).unwrap()[0];
        prop_assert!(close(got, fd, 1e-4), "{} vs {}", got, fd);
    }
}

#[test]
fn constants_fold() {
    let mut g = Graph::new();
    let (a, b) = (g.constant(2.0), g.constant(3.5));
    let s = g.add(a, b);
    assert_eq!(g.as_const(s), Some(5.5));
    let p = g.mul(a, b);
    assert_eq!(g.as_const(p), Some(7.0));
    let z = g.constant(0.0);
    let c = g.cos(z);
    assert_eq!(c, g.one());
    let m0 = g.constant(-0.0);
    assert_eq!(m0, g.zero(), "-0 and 0 are one constant");
}

#[test]
fn adding_zero_and_multiplying_by_one_or_zero() {
    let mut g = Graph::new();
    let x = g.q(0);
    let (zero, one) = (g.zero(), g.one());
    assert_eq!(g.add(x, zero), x);
    assert_eq!(g.mul(x, one), x);
    assert_eq!(g.mul(x, zero), zero);
    assert_eq!(g.powi(x, 0), one);
    assert_eq!(g.powi(x, 1), x);
}

#[test]
fn like_terms_collect() {
    let mut g = Graph::new();
    let x = g.q(0);
    let two_x = g.scale(x, 2.0);
    let three_x = g.scale(x, 3.0);
    let s = g.add(two_x, three_x);
    assert_eq!(s, g.scale(x, 5.0));
    assert_eq!(g.sub(s, s), g.zero());
    // x - x inside a longer sum cancels too.
    let y = g.q(1);
    let a = g.add(x, y);
    assert_eq!(g.sub(a, x), y);
}

#[test]
fn like_factors_collect() {
    let mut g = Graph::new();
    let x = g.q(0);
    let xx = g.mul(x, x);
    assert_eq!(xx, g.powi(x, 2));
    assert!(matches!(g.node(xx), Node::Mul(f) if f[..] == [(x, 2)]));
    assert_eq!(g.div(x, x), g.one());
    let x3 = g.mul(xx, x);
    assert_eq!(g.div(x3, xx), x);
}

#[test]
fn coefficients_move_out_of_products() {
    let mut g = Graph::new();
    let (x, y) = (g.q(0), g.q(1));
    let tx = g.scale(x, 2.0);
    let ty = g.scale(y, 3.0);
    let p = g.mul(tx, ty);
    let xy = g.mul(x, y);
    assert_eq!(p, g.scale(xy, 6.0));
}

#[test]
fn sums_and_products_flatten_and_commute() {
    let mut g = Graph::new();
    let (x, y, z) = (g.q(0), g.q(1), g.q(2));
    let xy = g.add(x, y);
    let a = g.add(xy, z);
    let yz = g.add(z, y);
    let b = g.add(x, yz);
    assert_eq!(a, b);
    let xy = g.mul(y, x);
    let a = g.mul(xy, z);
    let zy = g.mul(z, y);
    let b = g.mul(zy, x);
    assert_eq!(a, b);
}

#[test]
fn sine_is_odd_and_cosine_even() {
    let mut g = Graph::new();
    let x = g.q(0);
    let mx = g.neg(x);
    let s = g.sin(mx);
    let sx = g.sin(x);
    assert_eq!(s, g.neg(sx));
    assert_eq!(g.cos(mx), g.cos(x));
}

#[test]
fn pythagoras_simplifies_to_one() {
    let mut g = Graph::new();
    let x = g.q(0);
    let (s, c) = (g.sin(x), g.cos(x));
    let (s2, c2) = (g.powi(s, 2), g.powi(c, 2));
    let e = g.add(s2, c2);
    assert_eq!(g.expand_trig(e, 100).unwrap(), g.one());
    // With a common factor and coefficient: 3 m sin^2 + 3 m cos^2 = 3 m.
    let m = g.param("m");
    let (ms2, mc2) = (g.mul(m, s2), g.mul(m, c2));
    let l = g.sum(0.0, [(ms2, 3.0), (mc2, 3.0)]);
    let want = g.scale(m, 3.0);
    assert_eq!(g.expand_trig(l, 100).unwrap(), want);
}

#[test]
fn angle_sums_combine() {
    let mut g = Graph::new();
    let (a, b) = (g.q(0), g.q(1));
    let (sa, ca, sb, cb) = (g.sin(a), g.cos(a), g.sin(b), g.cos(b));
    let cc = g.mul(ca, cb);
    let ss = g.mul(sa, sb);
    let e = g.sub(cc, ss);
    let ab = g.add(a, b);
    assert_eq!(g.expand_trig(e, 100).unwrap(), g.cos(ab));
    let sc = g.mul(sa, cb);
    let cs = g.mul(ca, sb);
    let e = g.add(sc, cs);
    assert_eq!(g.expand_trig(e, 100).unwrap(), g.sin(ab));
    let e = g.add(cc, ss);
    let amb = g.sub(a, b);
    assert_eq!(g.expand_trig(e, 100).unwrap(), g.cos(amb));
}

#[test]
fn planar_arm_kinetic_term_prints_with_cos_q2() {
    // |d p2 / d q1|^2 for p2 = l1 (c1, s1) + l2 (c12, s12), written with products of c1, c2...
    let mut g = Graph::new();
    let (q1, q2) = (g.q(0), g.q(1));
    let (l1, l2) = (g.param("l1"), g.param("l2"));
    let (s1, c1, s2, c2) = (g.sin(q1), g.cos(q1), g.sin(q2), g.cos(q2));
    let c12 = {
        let a = g.mul(c1, c2);
        let b = g.mul(s1, s2);
        g.sub(a, b)
    };
    let s12 = {
        let a = g.mul(s1, c2);
        let b = g.mul(c1, s2);
        g.add(a, b)
    };
    let x = {
        let a = g.mul(l1, c1);
        let b = g.mul(l2, c12);
        g.add(a, b)
    };
    let y = {
        let a = g.mul(l1, s1);
        let b = g.mul(l2, s12);
        g.add(a, b)
    };
    let dx = g.diff(x, q1);
    let dy = g.diff(y, q1);
    let e = g.dot(&[dx, dy], &[dx, dy]);
    let s = g.expand_trig(e, 1000).unwrap();
    assert_eq!(
        g.print(s, Style::default()),
        "l1^2 + l2^2 + 2*l1*l2*cos(q2)"
    );
    let latex = g.print(
        s,
        Style {
            syntax: Syntax::Latex,
            digits: None,
        },
    );
    assert_eq!(
        latex,
        "l_{1}^{2} + l_{2}^{2} + 2 l_{1} l_{2} \\cos\\left(q_{2}\\right)"
    );
}

#[test]
fn differentiation_is_memoized_over_shared_subexpressions() {
    // f_{k+1} = sin(f_k) cos(f_k): the tree doubles at every step, the graph grows linearly.
    let mut g = Graph::new();
    let x = g.q(0);
    let mut f = x;
    for _ in 0..200 {
        let s = g.sin(f);
        let c = g.cos(f);
        f = g.mul(s, c);
    }
    let before = g.len();
    let d = g.diff(f, x);
    assert!(
        g.len() - before < 20 * 200,
        "derivative added {} nodes",
        g.len() - before
    );
    assert!(g.eval(&[d], |_| Some(0.5)).unwrap()[0].is_finite());
}

#[test]
fn programs_compute_each_subexpression_once_and_count_operations() {
    let mut g = Graph::new();
    let (x, y) = (g.q(0), g.q(1));
    let s = g.sin(x);
    let a = g.mul(s, y); // used twice: a temporary
    let o1 = g.add(a, x);
    let o2 = g.scale(a, 3.0);
    let unused = g.cos(y);
    let p = Program::new(&g, &[o1, o2]);
    assert_eq!(p.temps.len(), 1, "{:?}", p.temps);
    let n = p.ops();
    assert_eq!((n.sin, n.cos, n.mul, n.add), (1, 0, 2, 1));
    let text = p.print(&["o1".into(), "o2".into()], Style::default());
    assert_eq!(
        text,
        "t0 = y*sin(x)\no1 = q1 + t0\no2 = 3*t0\n"
            .replace("y", "q2")
            .replace("(x)", "(q1)")
    );
    let _ = unused;
}

/// Terms of a sum (a lone term for anything else).
fn terms(g: &Graph, e: Id) -> Vec<(Id, f64)> {
    match g.node(e) {
        Node::Add(_, ts) => ts.iter().map(|(t, k)| (*t, k.get())).collect(),
        _ => vec![(e, 1.0)],
    }
}

#[test]
fn shared_sums_stay_one_term_unless_they_collect() {
    let mut g = Graph::new();
    g.set_flattening(SumFlattening::Shared);
    let (a, b, c, d) = (g.q(0), g.q(1), g.q(2), g.q(3));
    let s = g.add(a, b);
    // Used by two sums, computed once: 3 additions, not 4.
    let x = g.add(s, c);
    let y = g.add(s, d);
    let mut want = vec![(s, 1.0), (c, 1.0)];
    want.sort_by_key(|t| t.0);
    assert_eq!(terms(&g, x), want);
    let n = Program::new(&g, &[x, y]).ops();
    assert_eq!((n.add, n.mul), (3, 0));
    // A sum that shares a term with another input merges and collects: (a + b) - a = b.
    assert_eq!(g.sub(s, a), b);
    // A scaled sum stays one term; a negation merges, so that it shares the terms.
    let scaled = g.scale(s, 2.5);
    assert_eq!(terms(&g, scaled), vec![(s, 2.5)]);
    let neg = g.neg(s);
    assert_eq!(terms(&g, neg), vec![(a, -1.0), (b, -1.0)]);
    // Always: every small sum merges into its parent, as before.
    assert_eq!(
        g.set_flattening(SumFlattening::Always),
        SumFlattening::Shared
    );
    let z = g.add(s, d);
    assert_eq!(terms(&g, z).len(), 3);
}

#[test]
fn a_product_kept_whole_is_computed_once_for_every_product_that_uses_it() {
    let mut g = Graph::new();
    let (a, b, c, d) = (g.q(0), g.q(1), g.q(2), g.q(3));
    assert!(g.set_product_flattening(false));
    let ab = g.mul(a, b);
    // (a b) c and (a b) d: 3 multiplications, `a b` once.
    let (x, y) = (g.mul(ab, c), g.mul(ab, d));
    assert_eq!(Program::new(&g, &[x, y]).ops().mul, 3);
    // Merged (the default), each is a product of three factors: 4 multiplications.
    assert!(!g.set_product_flattening(true));
    let (x, y) = (g.mul(ab, c), g.mul(ab, d));
    assert_eq!(Program::new(&g, &[x, y]).ops().mul, 4);
    // Either way, like factors and constants still collect within one product.
    let aa = g.mul(a, a);
    assert_eq!(g.node(aa), &Node::Mul(vec![(a, 2)].into_boxed_slice()));
}

#[test]
fn a_scaled_copy_of_a_sum_reuses_the_sum() {
    let mut g = Graph::new();
    let (a, b, c, d) = (g.q(0), g.q(1), g.q(2), g.q(3));
    let ab = g.mul(a, b);
    // u = ab + c - d; the graph distributes 2.5 into the terms of the second sum.
    let u = g.sum(0.0, [(ab, 1.0), (c, 1.0), (d, -1.0)]);
    let su = g.scale(u, 2.5);
    let v = g.add(su, a); // 2.5 ab + 2.5 c - 2.5 d + a
                          // Made before the unit sum it matches (negated): -3 ab - 3 c + 3 d + b.
    let w = g.sum(0.0, [(ab, -3.0), (c, -3.0), (d, 3.0), (b, 1.0)]);
    let x = g.mul(u, a);
    let outputs = [w, v, x];
    let p = Program::new(&g, &outputs);
    let n = p.ops();
    // u: 2 adds and ab's product; v and w: one scale and one add each; x: one product.
    assert_eq!((n.add, n.mul), (4, 4), "{}", p.print(&[], Style::default()));
    let at = [0.3, -1.2, 0.7, 2.1];
    let got = p
        .eval(|s| match s.kind {
            eomgen::cas::SymbolKind::Q(i) => at.get(i).copied(),
            _ => None,
        })
        .unwrap();
    let want = eval(&g, &outputs, &at);
    for (x, y) in got.iter().zip(&want) {
        assert!(close(*x, *y, 1e-14), "{got:?} {want:?}");
    }
    // A sum that holds u's terms among others adds u once: ab + c - d + 2 b -> u + 2 b.
    let y = g.sum(0.0, [(ab, 1.0), (c, 1.0), (d, -1.0), (b, 2.0)]);
    let p = Program::new(&g, &[y, x]);
    let n = p.ops();
    assert_eq!((n.add, n.mul), (3, 3), "{}", p.print(&[], Style::default()));
}

#[test]
fn level_order_interleaves_independent_chains() {
    let mut g = Graph::new();
    // Two chains x -> x^2 y -> (x^2 y)^2 y ..., each step used twice so that it is a temporary.
    let chain = |g: &mut Graph, x: Id, y: Id| -> Vec<Id> {
        let mut v = vec![x];
        for _ in 0..4 {
            let last = *v.last().unwrap();
            let sq = g.mul(last, last);
            let next = g.mul(sq, y);
            let shifted = g.add(next, last);
            v.push(shifted);
        }
        v
    };
    let (x0, x1, y) = (g.q(0), g.q(1), g.q(2));
    let a = chain(&mut g, x0, y);
    let b = chain(&mut g, x1, y);
    let outputs = [a[4], b[4]];
    let names = ["a".to_string(), "b".to_string()];
    let created = Program::new(&g, &outputs).print(&names, Style::default());
    let levels = Program::ordered(&g, &outputs, Order::Levels).print(&names, Style::default());
    // Which chain each temporary belongs to: chain a reads q1 or a temporary of chain a.
    let chains = |text: &str| -> Vec<bool> {
        let mut of_a: Vec<bool> = Vec::new();
        for line in text.lines().filter(|l| l.starts_with('t')) {
            let (_, rhs) = line.split_once(" = ").unwrap();
            let reads_a = rhs.contains("q1")
                || (0..of_a.len()).any(|t| of_a[t] && rhs.contains(&format!("t{t}")));
            of_a.push(reads_a);
        }
        of_a
    };
    // Creation order finishes chain a before it starts b; level order alternates.
    let (created, levels) = (chains(&created), chains(&levels));
    assert_eq!(created.len(), 6);
    assert_eq!(created, [true, true, true, false, false, false]);
    assert_eq!(levels, [true, false, true, false, true, false]);
}

#[test]
fn numbers_print_shortest_or_to_digits() {
    use eomgen::cas::format_number;
    assert_eq!(format_number(2.0, None), "2");
    assert_eq!(format_number(0.1, None), "0.1");
    assert_eq!(format_number(1e-20, None), "1e-20");
    assert_eq!(format_number(0.123456789, Some(3)), "0.123");
    assert_eq!(format_number(123456.789, Some(3)), "123457");
    assert_eq!(format_number(1.5e-7, Some(2)), "1.5e-7");
}

/// Prints a fixed set of expressions; run in two child processes by the test below.
fn determinism_sample() -> String {
    let mut g = Graph::new();
    let mut out = String::new();
    let qs: Vec<Id> = (0..4).map(|i| g.q(i)).collect();
    let m = g.param("m");
    let mut acc = m;
    for &q in &qs {
        let s = g.sin(q);
        let c = g.cos(q);
        let t = g.mul(acc, s);
        acc = g.add(t, c);
    }
    let d = g.diff_many(&[acc], qs[2]);
    for e in [acc, d[0]] {
        out.push_str(&g.print(e, Style::default()));
        out.push('\n');
        out.push_str(&g.print(
            e,
            Style {
                syntax: Syntax::Latex,
                digits: Some(4),
            },
        ));
        out.push('\n');
    }
    out.push_str(
        &Program::new(&g, &[acc, d[0]]).print(&["a".into(), "b".into()], Style::default()),
    );
    out
}

/// The child process of `printing_is_byte_identical_across_processes`, which runs it; run
/// directly, it runs that test.
#[test]
#[ignore = "the child process of printing_is_byte_identical_across_processes, which runs it"]
fn determinism_child() {
    child::child_main(
        determinism_sample,
        printing_is_byte_identical_across_processes,
    );
}

#[test]
fn printing_is_byte_identical_across_processes() {
    let run = || child::run_child(concat!(module_path!(), "::determinism_child"));
    let (a, b) = (run(), run());
    assert!(!a.is_empty());
    assert_eq!(a, b);
    assert_eq!(a, determinism_sample());
}
