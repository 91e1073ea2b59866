//! Reading the floating-base reference files (`robots/floating/NAME.json`,
//! `NAME.mpc.json`): Pinocchio's joint order matched to ours by name, matrices picked in our
//! order, and the normwise error the tolerances are stated in.

use serde_json::Value;

/// `robots/floating/{file}`, parsed.
pub fn reference(file: &str) -> Value {
    let path = format!("{}/robots/floating/{file}", env!("CARGO_MANIFEST_DIR"));
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
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
    /// The order of a reference file's `joints` against ours (`JOINT_NAMES`).
    pub fn new(doc: &Value, ours: &[&str]) -> Order {
        let refs: Vec<&str> = doc["joints"]
            .as_array()
            .unwrap()
            .iter()
            .map(|j| j.as_str().unwrap())
            .collect();
        let pos = |n: &&str| refs.iter().position(|r| r == n).unwrap();
        Order {
            q: (0..7).chain(ours.iter().map(|n| 7 + pos(n))).collect(),
            v: (0..6).chain(ours.iter().map(|n| 6 + pos(n))).collect(),
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
