//! The evaluator (`Builder::derived`, `eomgen::evaluate`) against Pinocchio's values in
//! `tests/robots/`: every quantity that `eomgen eval` and `simulate` read, the run-time
//! compositions (forward dynamics, `M^-1`, its derivatives, Craig's matrices from Christoffel
//! columns, contact forward dynamics on a floating base), and its errors.

use eomgen::evaluate::{EvalError, State};
use eomgen::{Builder, Derived};
use serde_json::Value;

fn robots(path: &str) -> String {
    format!("{}/../tests/robots/{path}", env!("CARGO_MANIFEST_DIR"))
}

fn reference(path: &str) -> Value {
    serde_json::from_str(&std::fs::read_to_string(robots(path)).unwrap()).unwrap()
}

fn numbers(v: &Value) -> Vec<f64> {
    match v {
        Value::Array(a) => a.iter().flat_map(numbers).collect(),
        Value::Number(n) => vec![n.as_f64().unwrap()],
        _ => panic!("not a number: {v}"),
    }
}

/// Our velocity coordinate `i` is the reference's `perm[i]` (a floating base's six first).
fn permutation(derived: &Derived, doc: &Value) -> Vec<usize> {
    let refs: Vec<&str> = doc["joints"]
        .as_array()
        .unwrap()
        .iter()
        .map(|j| j.as_str().unwrap())
        .collect();
    let model = derived.model();
    let base = if model.is_floating() { 6 } else { 0 };
    let joints = model
        .coordinate_names()
        .into_iter()
        .map(|n| base + refs.iter().position(|r| *r == n).unwrap());
    (0..base).chain(joints).collect()
}

/// Reorders a reference vector (`rows` = 1) or row-major matrix into our coordinates; `cols`
/// permuted with `pc` (None: unpermuted).
fn ours(reference: &[f64], pr: Option<&[usize]>, pc: Option<&[usize]>, cols: usize) -> Vec<f64> {
    let rows = reference.len() / cols;
    let r = |i: usize| pr.map_or(i, |p| p[i]);
    let c = |j: usize| pc.map_or(j, |p| p[j]);
    (0..rows)
        .flat_map(|i| (0..cols).map(move |j| (i, j)))
        .map(|(i, j)| reference[cols * r(i) + c(j)])
        .collect()
}

fn assert_close(what: &str, got: &[f64], want: &[f64], tol: f64) {
    assert_eq!(got.len(), want.len(), "{what}: length");
    let scale = want.iter().fold(1.0f64, |m, x| m.max(x.abs()));
    let err = got
        .iter()
        .zip(want)
        .fold(0.0f64, |m, (g, w)| m.max((g - w).abs()));
    assert!(
        err <= tol * scale,
        "{what}: error {err:e} (scale {scale:e})"
    );
}

#[test]
fn a_fixed_base_matches_pinocchio_with_craig_matrices_by_columns() {
    let doc = reference("panda.json");
    let derived = Builder::new(robots("panda.urdf")).derived().unwrap();
    let p = permutation(&derived, &doc);
    let n = p.len();
    let names = [
        "mass_matrix",
        "gravity",
        "bias",
        "coriolis_matrix",
        "inverse_dynamics",
        "forward_dynamics",
        "kinetic_energy",
        "potential_energy",
        "centrifugal",
        "coriolis_pairs",
    ];
    let evaluator = derived.evaluator(&names).unwrap();
    let mut with_craig = 0;
    for s in doc["samples"].as_array().unwrap() {
        let vec = |k: &str| ours(&numbers(&s[k]), Some(&p), None, 1);
        let state = State {
            q: vec("q"),
            v: vec("qd"),
            a: vec("qdd"),
            tau: vec("tau_in"),
        };
        let values = evaluator.evaluate(&state).unwrap();
        let wants = [
            ours(&numbers(&s["mass_matrix"]), Some(&p), Some(&p), n),
            vec("gravity"),
            vec("bias"),
            ours(&numbers(&s["coriolis_matrix"]), Some(&p), Some(&p), n),
            vec("tau"),
            vec("forward_dynamics"),
            numbers(&s["kinetic_energy"]),
            numbers(&s["potential_energy"]),
        ];
        // Samples with velocities in every joint carry Craig's matrices.
        let mut craig = Vec::new();
        if let (Some(c), Some(b)) = (s.get("centrifugal"), s.get("coriolis_pairs")) {
            craig.push(ours(&numbers(c), Some(&p), Some(&p), n));
            // The pair columns (j, k), j < k, follow the joints' order: kept when ours is theirs.
            assert!(p.iter().enumerate().all(|(i, &r)| i == r));
            craig.push(numbers(b));
            with_craig += 1;
        }
        for ((value, want), name) in values.iter().zip(wants.iter().chain(&craig)).zip(names) {
            assert_eq!(value.name, name);
            assert_close(name, &value.data, want, 1e-9);
        }
    }
    assert!(with_craig > 0);
}

#[test]
fn the_derivatives_of_forward_dynamics_and_the_inverse_match_pinocchio() {
    // The panda's forward-dynamics derivatives are composed at run time, the UR5's
    // straight-line (quantities::FORWARD_DYNAMICS_FLAT_SOLVES_MAX_OPS).
    for robot in ["panda", "ur5"] {
        forward_dynamics_derivatives_match(robot);
    }
}

fn forward_dynamics_derivatives_match(robot: &str) {
    let doc = reference(&format!("{robot}.derivatives.json"));
    let derived = Builder::new(robots(&format!("{robot}.urdf")))
        .derivatives()
        .derived()
        .unwrap();
    let p = permutation(&derived, &doc);
    let n = p.len();
    let names = ["forward_dynamics_derivatives", "mass_matrix_inverse"];
    let evaluator = derived.evaluator(&names).unwrap();
    for s in doc["samples"].as_array().unwrap() {
        let vec = |k: &str| ours(&numbers(&s[k]), Some(&p), None, 1);
        let mat = |k: &str| ours(&numbers(&s[k]), Some(&p), Some(&p), n);
        let state = State {
            q: vec("q"),
            v: vec("qd"),
            a: Vec::new(),
            tau: vec("tau_in"),
        };
        let values = evaluator.evaluate(&state).unwrap();
        let fd = &values[0];
        assert_close("d qdd/dq", &fd.matrix(0).concat(), &mat("dfd_dq"), 1e-7);
        assert_close("d qdd/dqd", &fd.matrix(1).concat(), &mat("dfd_dqd"), 1e-7);
        assert_close(
            "M^-1 (tuple)",
            &fd.matrix(2).concat(),
            &mat("mass_matrix_inverse"),
            1e-7,
        );
        assert_close("M^-1", &values[1].data, &mat("mass_matrix_inverse"), 1e-7);
    }
}

#[test]
fn a_floating_base_with_contacts_matches_pinocchio() {
    let doc = reference("floating/anymal.json");
    let feet: Vec<&str> = doc["contact_frames"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_str().unwrap())
        .collect();
    let derived = Builder::new(robots("floating/anymal.urdf"))
        .floating_base()
        .contact_points(&feet)
        .derived()
        .unwrap();
    let pv = permutation(&derived, &doc);
    let pq: Vec<usize> = (0..7).chain(pv[6..].iter().map(|i| i + 1)).collect();
    let nv = pv.len();
    let names = [
        "mass_matrix",
        "bias",
        "contact_forward_dynamics",
        "forward_dynamics",
    ];
    let evaluator = derived.evaluator(&names).unwrap();
    let mut checked = 0;
    for s in doc["samples"].as_array().unwrap() {
        let vec = |k: &str| ours(&numbers(&s[k]), Some(&pv), None, 1);
        let state = State {
            q: ours(&numbers(&s["q"]), Some(&pq), None, 1),
            v: vec("v"),
            a: Vec::new(),
            tau: vec("tau_in"),
        };
        let values = evaluator.evaluate(&state).unwrap();
        assert_close(
            "M",
            &values[0].data,
            &ours(&numbers(&s["mass_matrix"]), Some(&pv), Some(&pv), nv),
            1e-9,
        );
        assert_close("b", &values[1].data, &vec("bias"), 1e-9);
        assert_close(
            "forward dynamics",
            &values[3].data,
            &vec("forward_dynamics"),
            1e-9,
        );
        let cfd = &s["contact_forward_dynamics"];
        if cfd.is_null() {
            continue;
        }
        let mut want = ours(&numbers(&cfd["a"]), Some(&pv), None, 1);
        want.extend(numbers(&cfd["forces"]));
        assert_close("contact forward dynamics", &values[2].data, &want, 1e-8);
        checked += 1;
    }
    assert!(checked > 0);
}

#[test]
fn errors_name_the_quantity_the_length_and_the_joint() {
    let derived = Builder::new(robots("double_pendulum.urdf"))
        .derived()
        .unwrap();
    let err = derived.evaluator(&["mass_matrx"]).err().unwrap();
    assert!(
        matches!(&err, EvalError::Unknown { name, known } if name == "mass_matrx" && known.contains("mass_matrix"))
    );
    let err = derived.evaluator(&["link_pose"]).err().unwrap();
    assert!(matches!(err, EvalError::NotEvaluable { .. }));
    // `gravity` reads q only: the other vectors may be empty, q may not be short.
    let gravity = derived.evaluator(&["gravity"]).unwrap();
    let q_only = State {
        q: vec![0.1, 0.2],
        ..State::default()
    };
    assert_eq!(gravity.evaluate(&q_only).unwrap()[0].data.len(), 2);
    let short = State {
        q: vec![0.1],
        ..State::default()
    };
    assert_eq!(
        gravity.evaluate(&short).unwrap_err().to_string(),
        "q has 1 value(s), but the robot has 2"
    );
    let err = derived
        .evaluate(
            &["forward_dynamics"],
            &State::at_rest(vec![0.0, f64::NAN], 2),
        )
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("the mass matrix is not positive definite"),
        "{err}"
    );
    assert!(err.contains("pivot 1 of 2, joint `"), "{err}");
}
