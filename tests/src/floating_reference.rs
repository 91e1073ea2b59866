//! Reading the floating-base reference files (`robots/floating/NAME.json`,
//! `NAME.mpc.json`): Pinocchio's joint order matched to ours by name, matrices picked in our
//! order, and the normwise error the tolerances are stated in.

use serde_json::Value;

/// `robots/floating/{file}`, parsed.
pub fn reference(file: &str) -> Value {
    robot_file(&format!("floating/{file}"))
}

/// `robots/{path}`, parsed (a fixed-base robot's file, or one under `floating/`).
pub fn robot_file(path: &str) -> Value {
    let path = format!("{}/robots/{path}", env!("CARGO_MANIFEST_DIR"));
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Elementwise `|a - b| / max(1, |b|)` of ours against the reference's (equal lengths).
pub fn elementwise(ours: &[f64], reference: &[f64]) -> f64 {
    assert_eq!(ours.len(), reference.len());
    ours.iter()
        .zip(reference)
        .map(|(a, b)| (a - b).abs() / b.abs().max(1.0))
        .fold(0.0, f64::max)
}

/// Every number of a (nested) array, in order.
pub fn numbers(v: &Value) -> Vec<f64> {
    match v {
        Value::Array(a) => a.iter().flat_map(numbers).collect(),
        Value::Number(n) => vec![n.as_f64().unwrap()],
        _ => panic!("not a number: {v}"),
    }
}

/// Our coordinate `i` is the reference's `q[i]`, `v[i]` (base first, joints matched by name).
pub struct Order {
    pub q: Vec<usize>,
    pub v: Vec<usize>,
}

impl Order {
    /// The order of a floating-base reference file's `joints` against ours (`JOINT_NAMES`).
    pub fn new(doc: &Value, ours: &[&str]) -> Order {
        Order::with_base(doc, ours, true)
    }

    /// [`Order::new`] for a floating (base coordinates first) or a fixed base.
    pub fn with_base(doc: &Value, ours: &[&str], floating: bool) -> Order {
        let refs: Vec<&str> = doc["joints"]
            .as_array()
            .unwrap()
            .iter()
            .map(|j| j.as_str().unwrap())
            .collect();
        let pos = |n: &&str| refs.iter().position(|r| r == n).unwrap();
        let (bq, bv) = if floating { (7, 6) } else { (0, 0) };
        Order {
            q: (0..bq).chain(ours.iter().map(|n| bq + pos(n))).collect(),
            v: (0..bv).chain(ours.iter().map(|n| bv + pos(n))).collect(),
        }
    }

    /// A reference vector in our order.
    pub fn arr<const N: usize>(map: &[usize], v: &Value) -> [f64; N] {
        let v = numbers(v);
        core::array::from_fn(|i| v[map[i]])
    }
}

/// `max |a - b| / max(1, max |b|)`.
pub fn normwise(ours: &[f64], reference: &[f64]) -> f64 {
    assert_eq!(ours.len(), reference.len());
    let scale = reference.iter().fold(1.0_f64, |m, x| m.max(x.abs()));
    ours.iter()
        .zip(reference)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
        / scale
}

/// A repeatable floating-base state: base position and joints in [-1, 1], a unit quaternion
/// (entries 3..7), velocities in [-1, 1] and efforts in [-10, 10].
pub fn random_state<const NQ: usize, const NV: usize>(
    seed: u64,
) -> ([f64; NQ], [f64; NV], [f64; NV]) {
    let mut x = seed;
    let mut next = move || {
        x = x
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (x >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    let mut q: [f64; NQ] = core::array::from_fn(|_| next());
    let n = (q[3] * q[3] + q[4] * q[4] + q[5] * q[5] + q[6] * q[6]).sqrt();
    for k in 3..7 {
        q[k] /= n;
    }
    let v = core::array::from_fn(|_| next());
    let tau = core::array::from_fn(|_| 10.0 * next());
    (q, v, tau)
}

/// Central differences (step `1e-6`) of `f` in each tangent direction of the configuration
/// `q` (moved by `integrate`, a generated robot's) and of the velocity `v`: the two NV x NV
/// matrices of its derivatives, column `k` along direction `k`.
pub fn tangent_differences<const NQ: usize, const NV: usize>(
    integrate: impl Fn(&[f64; NQ], &[f64; NV], f64) -> [f64; NQ],
    q: &[f64; NQ],
    v: &[f64; NV],
    f: impl Fn(&[f64; NQ], &[f64; NV]) -> [f64; NV],
) -> ([[f64; NV]; NV], [[f64; NV]; NV]) {
    let h = 1e-6;
    let (mut dq, mut dv) = ([[0.0; NV]; NV], [[0.0; NV]; NV]);
    for k in 0..NV {
        let e: [f64; NV] = core::array::from_fn(|i| if i == k { h } else { 0.0 });
        let (qp, qm) = (integrate(q, &e, 1.0), integrate(q, &e, -1.0));
        let (vp, vm): ([f64; NV], [f64; NV]) = (
            core::array::from_fn(|i| v[i] + e[i]),
            core::array::from_fn(|i| v[i] - e[i]),
        );
        let (fqp, fqm, fvp, fvm) = (f(&qp, v), f(&qm, v), f(q, &vp), f(q, &vm));
        for i in 0..NV {
            dq[i][k] = (fqp[i] - fqm[i]) / (2.0 * h);
            dv[i][k] = (fvp[i] - fvm[i]) / (2.0 * h);
        }
    }
    (dq, dv)
}

/// A reference matrix's rows `rows` and columns `cols`, flat.
pub fn pick(m: &Value, rows: &[usize], cols: &[usize]) -> Vec<f64> {
    let m: Vec<Vec<f64>> = m.as_array().unwrap().iter().map(numbers).collect();
    rows.iter()
        .flat_map(|&r| cols.iter().map(move |&c| (r, c)))
        .map(|(r, c)| m[r][c])
        .collect()
}

/// A matrix, flat (row-major).
pub fn flat<const R: usize, const C: usize>(m: &[[f64; C]; R]) -> Vec<f64> {
    m.iter().flatten().copied().collect()
}

/// The worst error of each quantity over the samples, checked against its tolerance.
#[derive(Default)]
pub struct Worst(pub Vec<(String, f64)>);

impl Worst {
    /// Keeps the larger of `e` and the worst so far of `what`.
    pub fn note(&mut self, what: &str, e: f64) {
        match self.0.iter_mut().find(|w| w.0 == what) {
            Some(w) => w.1 = w.1.max(e),
            None => self.0.push((what.to_string(), e)),
        }
    }

    /// Prints each worst error and fails on one beyond `limit(quantity)` (NaN included) or on
    /// fewer than `at_least` quantities checked.
    pub fn check(&self, robot: &str, limit: impl Fn(&str) -> f64, at_least: usize) {
        for (what, e) in &self.0 {
            println!("{robot}: {what} {e:.2e}");
            assert!(*e <= limit(what), "{robot}: {what} off by {e:e}");
        }
        assert!(
            self.0.len() >= at_least,
            "{robot}: only {} checked",
            self.0.len()
        );
    }
}
