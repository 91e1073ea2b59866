//! The projected Newton-Euler form: each body's share of `M` and `b`, derived from its own
//! Jacobians (`Derivation::projected_newton_euler`), sums to the mass matrix and the bias of
//! both routes (the closed Lagrangian form, and the recursive one generated code evaluates)
//! at random states, on the five reference robots and a robot with rotor inertia.

#![allow(clippy::needless_range_loop)]

use std::path::Path;

use eomgen::cas::{Id, SymbolKind};
use eomgen::dynamics::Derivation;
use eomgen::model::{Model, ModelOptions};

fn load(robot: &str, options: &ModelOptions) -> Model {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/robots")
        .join(format!("{robot}.urdf"));
    eomgen::urdf::load_file(&path, options).unwrap()
}

/// The largest entry of `a - b` relative to the largest entry of `b`.
fn relative(a: &[f64], b: &[f64]) -> f64 {
    let scale = b.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    let diff = a
        .iter()
        .zip(b)
        .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
    diff / scale
}

fn worst_error(robot: &str, options: &ModelOptions) -> f64 {
    let model = load(robot, options);
    let mut d = Derivation::new(&model);
    let terms = d.projected_newton_euler(&model);
    let n = d.dof;
    let zero = d.graph.zero();
    // The sums, symbolically.
    let mut m_sum = vec![vec![zero; n]; n];
    let mut b_sum = vec![zero; n];
    for t in &terms {
        for i in 0..n {
            for j in 0..n {
                m_sum[i][j] = d.graph.add(m_sum[i][j], t.mass_matrix[i][j]);
            }
            b_sum[i] = d.graph.add(b_sum[i], t.bias[i]);
        }
    }
    for (i, joint) in model.joints.iter().enumerate() {
        let ia = d.graph.constant(joint.armature);
        m_sum[i][i] = d.graph.add(m_sum[i][i], ia);
    }
    let flat = |m: &[Vec<Id>]| -> Vec<Id> { m.iter().flatten().copied().collect() };
    let groups: [Vec<Id>; 6] = [
        flat(&m_sum),
        flat(&d.mass_matrix),
        flat(&d.recursive.mass_matrix),
        b_sum,
        d.bias.clone(),
        d.recursive.bias.clone(),
    ];
    let outputs: Vec<Id> = groups.iter().flatten().copied().collect();
    let mut state = 0x1234_5678_u64 + n as u64;
    let mut uniform = |lo: f64, hi: f64| {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        lo + (hi - lo) * ((state >> 11) as f64 / (1u64 << 53) as f64)
    };
    let mut worst: f64 = 0.0;
    for _ in 0..20 {
        let q: Vec<f64> = (0..n).map(|_| uniform(-3.0, 3.0)).collect();
        let qd: Vec<f64> = (0..n).map(|_| uniform(-2.0, 2.0)).collect();
        let v = d
            .graph
            .eval(&outputs, |s| match s.kind {
                SymbolKind::Q(i) => Some(q[i]),
                SymbolKind::Qd(i) => Some(qd[i]),
                SymbolKind::Qdd(_) => Some(0.0),
                _ => d.params.iter().find(|p| p.0 == s.name).map(|p| p.2),
            })
            .unwrap();
        let (mm, b) = (n * n, n);
        let m_pne = &v[..mm];
        let m_closed = &v[mm..2 * mm];
        let m_crba = &v[2 * mm..3 * mm];
        let b_pne = &v[3 * mm..3 * mm + b];
        let b_closed = &v[3 * mm + b..3 * mm + 2 * b];
        let b_rnea = &v[3 * mm + 2 * b..];
        worst = worst
            .max(relative(m_pne, m_closed))
            .max(relative(m_pne, m_crba))
            .max(relative(b_pne, b_closed))
            .max(relative(b_pne, b_rnea));
    }
    worst
}

#[test]
fn body_shares_sum_to_the_mass_matrix_and_the_bias() {
    let plain = ModelOptions::default();
    let armature = ModelOptions {
        armature: vec![
            ("shoulder_pan_joint".into(), 0.5),
            ("wrist_2_joint".into(), 0.1),
        ],
        ..ModelOptions::default()
    };
    for (robot, options) in [
        ("double_pendulum", &plain),
        ("ur5", &plain),
        ("panda", &plain),
        ("kinova", &plain),
        ("allegro_right_hand", &plain),
        ("ur5", &armature),
    ] {
        let err = worst_error(robot, options);
        println!("{robot}: worst relative error {err:.2e}");
        assert!(
            err < 1e-12,
            "{robot}: the per-body sums are off by {err:.2e}"
        );
    }
}
