//! Forward dynamics that solves at run time (a robot too deep to unroll the solve): inverse
//! dynamics of its accelerations gives back the efforts, and failures are reported.

use eomgen_runtime::FactorError;
use eomgen_tests::robots::chain28::Chain28;

const N: usize = 28;

#[test]
fn the_generated_code_takes_the_runtime_route() {
    let source = include_str!(concat!(env!("OUT_DIR"), "/chain28.rs"));
    assert!(source.contains("fn ltdl_factor_unrolled"));
    assert!(source.contains("Self::ltdl_substitute_unrolled(&m, &rhs)"));
}

#[test]
fn inverse_dynamics_of_forward_dynamics_is_the_identity() {
    let robot = Chain28::<f64>::default();
    let mut worst: f64 = 0.0;
    for s in 0..8 {
        let q: [f64; N] = core::array::from_fn(|i| (0.37 * (i + s) as f64).sin());
        let qd: [f64; N] = core::array::from_fn(|i| 0.5 * (0.23 * (i * s) as f64).cos());
        let tau: [f64; N] = core::array::from_fn(|i| (1.0 + i as f64) * (0.61 * s as f64).sin());
        let qdd = robot.try_forward_dynamics(&q, &qd, &tau).unwrap();
        let back = robot.inverse_dynamics(&q, &qd, &qdd);
        let scale = tau.iter().fold(1.0_f64, |m, t| m.max(t.abs()));
        for i in 0..N {
            worst = worst.max((back[i] - tau[i]).abs() / scale);
        }
    }
    assert!(worst < 1e-9, "worst relative residual {worst:e}");
}

#[test]
fn non_finite_input_is_reported() {
    let robot = Chain28::<f64>::default();
    let q = [0.1; N];
    let mut tau = [0.0; N];
    tau[3] = f64::NAN;
    let err = robot.try_forward_dynamics(&q, &[0.0; N], &tau).unwrap_err();
    assert!(matches!(err, FactorError::NonFinite { .. }), "{err:?}");
    assert!(robot.forward_dynamics(&q, &[0.0; N], &tau)[0].is_nan());
    let mut q = [0.1; N];
    q[5] = f64::INFINITY;
    assert!(robot
        .try_forward_dynamics(&q, &[0.0; N], &[0.0; N])
        .is_err());
}
