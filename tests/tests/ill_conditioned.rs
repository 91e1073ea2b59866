//! Forward dynamics on an ill-conditioned mass matrix: a three-joint arm whose last link weighs
//! 1e-12 kg (`urdf/light_tip.urdf`, condition number about 1e14).
//!
//! The behaviour, as documented in the README: the generated `L^T D L` factorization runs from
//! the leaves to the root, so the tiny pivot of the light link is computed without
//! cancellation; in `f64` and `f32` the answer is finite and satisfies `M qdd + b + G = tau`.
//! When a pivot is not positive or not finite, or the solution is not finite (non-finite
//! input), `try_forward_dynamics` reports it as a `FactorError` naming the pivot or component,
//! and `forward_dynamics` returns all NaN, never a partial answer. A link with no mass at all
//! is refused when the model is built.

use eomgen_runtime::{Dynamics, FactorError};
use eomgen_tests::robots::light_tip::LightTip;

/// States `(q, qd, qdd)` spread over the joint ranges.
fn states() -> Vec<([f64; 3], [f64; 3], [f64; 3])> {
    (0..20)
        .map(|k| {
            let t = k as f64;
            (
                [
                    (0.7 * t).sin() * 2.5,
                    (1.3 * t).cos() * 2.0,
                    (0.4 * t).sin() * 3.0,
                ],
                [
                    (0.9 * t).cos(),
                    (0.5 * t).sin() * 2.0,
                    (1.7 * t).cos() * 3.0,
                ],
                [
                    (1.1 * t).sin() * 4.0,
                    (0.3 * t).cos(),
                    (2.1 * t).sin() * 5.0,
                ],
            )
        })
        .collect()
}

/// The residual `|M qdd + b + G - tau|`, relative to the size of the terms, per joint.
fn residual<T: eomgen_runtime::Real>(
    robot: &LightTip<T>,
    q: &[T; 3],
    qd: &[T; 3],
    qdd: &[T; 3],
    tau: &[T; 3],
) -> [f64; 3] {
    let m = robot.mass_matrix(q);
    let h = robot.bias(q, qd);
    let g = robot.gravity(q);
    let mut out = [0.0; 3];
    for i in 0..3 {
        let mut sum = h[i].to_f64() + g[i].to_f64() - tau[i].to_f64();
        let mut scale = h[i].to_f64().abs() + g[i].to_f64().abs() + tau[i].to_f64().abs();
        for j in 0..3 {
            let term = m[i][j].to_f64() * qdd[j].to_f64();
            sum += term;
            scale += term.abs();
        }
        out[i] = sum.abs() / scale.max(f64::MIN_POSITIVE);
    }
    out
}

#[test]
fn the_mass_matrix_is_ill_conditioned() {
    let robot = LightTip::<f64>::default();
    let m = robot.mass_matrix(&[0.3, -0.5, 0.2]);
    // The light link's own diagonal entry is some 14 orders below the arm's.
    assert!(m[2][2] > 0.0 && m[2][2] < 1e-14, "{}", m[2][2]);
    assert!(m[0][0] > 0.1, "{}", m[0][0]);
}

#[test]
fn f64_forward_dynamics_is_finite_and_consistent() {
    let robot = LightTip::<f64>::default();
    for (q, qd, qdd) in states() {
        let tau = robot.inverse_dynamics(&q, &qd, &qdd);
        let solved = robot
            .try_forward_dynamics(&q, &qd, &tau)
            .unwrap_or_else(|e| panic!("q = {q:?}: {e}"));
        assert!(solved.iter().all(|x| x.is_finite()), "{solved:?}");
        assert_eq!(solved, robot.forward_dynamics(&q, &qd, &tau));
        let r = residual(&robot, &q, &qd, &solved, &tau);
        assert!(r.iter().all(|&r| r < 1e-12), "q = {q:?}: residual {r:?}");
        // Even the light link's acceleration is recovered: its pivot is exact.
        for i in 0..3 {
            assert!(
                (solved[i] - qdd[i]).abs() <= 1e-6 * (1.0 + qdd[i].abs()),
                "q = {q:?}: qdd {solved:?} vs {qdd:?}"
            );
        }
    }
}

#[test]
fn f32_forward_dynamics_is_finite_and_consistent() {
    let robot = LightTip::<f32>::default();
    let f32s = |v: [f64; 3]| v.map(|x| x as f32);
    for (q, qd, qdd) in states() {
        let (q, qd, qdd) = (f32s(q), f32s(qd), f32s(qdd));
        let tau = robot.inverse_dynamics(&q, &qd, &qdd);
        match robot.try_forward_dynamics(&q, &qd, &tau) {
            Ok(solved) => {
                assert!(solved.iter().all(|x| x.is_finite()), "{solved:?}");
                let r = residual(&robot, &q, &qd, &solved, &tau);
                assert!(r.iter().all(|&r| r < 1e-4), "q = {q:?}: residual {r:?}");
            }
            Err(e) => panic!("q = {q:?}: f32 factorization failed at pivot {}", e.pivot()),
        }
    }
}

#[test]
fn non_finite_input_is_reported_never_silent() {
    let robot = LightTip::<f64>::default();
    let (q, qd, tau) = ([0.3, -0.5, 0.2], [0.1, 0.2, 0.3], [1.0, 2.0, 0.001]);
    let cases = [
        // The first angle does not enter M(q) of this arm, only G(q): the solve catches it.
        ([f64::NAN, 0.0, 0.0], qd, tau),
        ([0.0, f64::INFINITY, 0.0], qd, tau),
        ([0.0, 0.0, f64::NAN], qd, tau),
        (q, [0.0, f64::NAN, 0.0], tau),
        (q, qd, [0.0, 0.0, f64::INFINITY]),
    ];
    for (q, qd, tau) in cases {
        let err = robot.try_forward_dynamics(&q, &qd, &tau).unwrap_err();
        assert!(
            matches!(err, FactorError::NonFinite { .. }),
            "{q:?} {qd:?} {tau:?}: {err:?}"
        );
        // The infallible form returns all NaN: never a mix of numbers and NaN.
        assert!(robot
            .forward_dynamics(&q, &qd, &tau)
            .iter()
            .all(|x| x.is_nan()));
    }
}

#[test]
fn a_massless_tip_is_refused_when_the_model_is_built() {
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("urdf/light_tip.urdf"),
    )
    .unwrap();
    let massless = text.replace("1e-12", "0").replace("1e-16", "0");
    assert_ne!(massless, text);
    let err = eomgen::Builder::from_urdf_str(&massless, "massless_tip.urdf")
        .generate()
        .unwrap_err();
    let msg = err.to_string();
    assert!(
        msg.starts_with("massless_tip.urdf: joint `wrist`") && msg.contains("singular"),
        "{msg}"
    );
}
