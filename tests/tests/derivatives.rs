//! `Builder::derivatives` through compiled generated code: against Pinocchio's
//! computeRNEADerivatives and computeABADerivatives (`tests/robots/NAME.derivatives.json`,
//! normwise: 1e-8 for inverse dynamics, 1e-7 for forward dynamics and M^-1), against central
//! finite differences of the compiled inverse and forward dynamics, and `M M^-1 = I`.

#![allow(clippy::needless_range_loop)]

#[cfg(unshipped)]
use eomgen_tests::robots::xarm7_derivatives;
use eomgen_tests::robots::{
    allegro_derivatives, joint_effects_derivatives, kinova_derivatives, panda_derivatives,
    ur5_derivatives,
};
use eomgen_tests::JointMap;
use serde_json::Value;

fn load(robot: &str) -> Value {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("robots")
        .join(format!("{robot}.derivatives.json"));
    serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap()
}

fn vector<const N: usize>(map: &JointMap, v: &Value) -> [f64; N] {
    let x: Vec<f64> = v
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e.as_f64().unwrap())
        .collect();
    let ours = map.to_ours(&x);
    core::array::from_fn(|i| ours[i])
}

/// A reference matrix in our joint order.
fn matrix<const N: usize>(map: &JointMap, v: &Value) -> [[f64; N]; N] {
    let rows: Vec<Vec<f64>> = v
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            r.as_array()
                .unwrap()
                .iter()
                .map(|e| e.as_f64().unwrap())
                .collect()
        })
        .collect();
    let mut out = [[0.0; N]; N];
    for a in 0..N {
        for b in 0..N {
            out[map.ours[a]][map.ours[b]] = rows[a][b];
        }
    }
    out
}

/// `|got - want|_F / max(1, |want|_F)`.
fn normwise<const N: usize>(got: &[[f64; N]; N], want: &[[f64; N]; N]) -> f64 {
    let (mut d, mut w) = (0.0, 0.0);
    for i in 0..N {
        for j in 0..N {
            d += (got[i][j] - want[i][j]).powi(2);
            w += want[i][j].powi(2);
        }
    }
    d.sqrt() / w.sqrt().max(1.0)
}

macro_rules! check_robot {
    ($name:literal, $module:ident, $ty:ident, $n:literal) => {{
        const N: usize = $n;
        let robot = $module::$ty::<f64>::default();
        let doc = load($name);
        let reference: Vec<String> = doc["joints"]
            .as_array()
            .unwrap()
            .iter()
            .map(|j| j.as_str().unwrap().to_string())
            .collect();
        let map = JointMap::new(&reference, &$module::$ty::<f64>::JOINT_NAMES);
        let mut worst = [0.0_f64; 5];
        for s in doc["samples"].as_array().unwrap() {
            let (q, qd, qdd, tau_in): ([f64; N], [f64; N], [f64; N], [f64; N]) = (
                vector(&map, &s["q"]),
                vector(&map, &s["qd"]),
                vector(&map, &s["qdd"]),
                vector(&map, &s["tau_in"]),
            );
            let (dq, dqd) = robot.inverse_dynamics_derivatives(&q, &qd, &qdd);
            let (fq, fqd, minv) = robot.forward_dynamics_derivatives(&q, &qd, &tau_in);
            let errors = [
                normwise(&dq, &matrix(&map, &s["dtau_dq"])),
                normwise(&dqd, &matrix(&map, &s["dtau_dqd"])),
                normwise(&fq, &matrix(&map, &s["dfd_dq"])),
                normwise(&fqd, &matrix(&map, &s["dfd_dqd"])),
                normwise(&minv, &matrix(&map, &s["mass_matrix_inverse"])),
            ];
            for k in 0..5 {
                worst[k] = worst[k].max(errors[k]);
            }
            // The same M^-1, computed by another straight-line program (rounding apart).
            let alone = robot.mass_matrix_inverse(&q);
            assert!(
                normwise(&minv, &alone) < 1e-12,
                "{}: {minv:?} vs {alone:?}",
                $name
            );
        }
        assert!(
            worst[0] < 1e-8 && worst[1] < 1e-8,
            "{}: inverse dynamics {worst:?}",
            $name
        );
        assert!(
            worst[2] < 1e-7 && worst[3] < 1e-7 && worst[4] < 1e-7,
            "{}: forward dynamics {worst:?}",
            $name
        );
        finite_differences::<N>(
            $name,
            |q, qd, a| robot.inverse_dynamics(q, qd, a),
            |q, qd, a| robot.inverse_dynamics_derivatives(q, qd, a),
        );
        let q: [f64; N] = core::array::from_fn(|i| 0.3 * (i as f64 + 1.0).sin());
        let (m, minv) = (
            mass_matrix_from_inverse_dynamics(&robot, &q),
            robot.mass_matrix_inverse(&q),
        );
        for i in 0..N {
            for j in 0..N {
                let p: f64 = (0..N).map(|k| m[i][k] * minv[k][j]).sum();
                let want = if i == j { 1.0 } else { 0.0 };
                assert!(
                    (p - want).abs() < 1e-9,
                    "{}: (M M^-1)[{i}][{j}] = {p}",
                    $name
                );
            }
        }
    }};
}

/// M through the derivatives of inverse dynamics in `qdd` (the robots here are generated with
/// only the derivative functions): `M = d tau / d qdd`, by exact differences since tau is linear
/// in qdd.
fn mass_matrix_from_inverse_dynamics<R, const N: usize>(robot: &R, q: &[f64; N]) -> [[f64; N]; N]
where
    R: InverseDynamics<N>,
{
    let zero = [0.0; N];
    let base = robot.tau(q, &zero, &zero);
    let mut m = [[0.0; N]; N];
    for j in 0..N {
        let mut e = zero;
        e[j] = 1.0;
        let t = robot.tau(q, &zero, &e);
        for i in 0..N {
            m[i][j] = t[i] - base[i];
        }
    }
    m
}

/// The compiled inverse dynamics of a generated robot, whatever its type.
trait InverseDynamics<const N: usize> {
    fn tau(&self, q: &[f64; N], qd: &[f64; N], qdd: &[f64; N]) -> [f64; N];
}

macro_rules! inverse_dynamics {
    ($($module:ident :: $ty:ident, $n:literal;)*) => {$(
        impl InverseDynamics<$n> for $module::$ty<f64> {
            fn tau(&self, q: &[f64; $n], qd: &[f64; $n], qdd: &[f64; $n]) -> [f64; $n] {
                self.inverse_dynamics(q, qd, qdd)
            }
        }
    )*};
}

inverse_dynamics! {
    ur5_derivatives::Ur5Derivatives, 6;
    panda_derivatives::PandaDerivatives, 9;
    kinova_derivatives::KinovaDerivatives, 6;
    allegro_derivatives::AllegroDerivatives, 16;
}

#[cfg(unshipped)]
inverse_dynamics! {
    xarm7_derivatives::Xarm7Derivatives, 7;
}

/// Central differences (step 1e-6) of inverse dynamics against its derivatives, at a few
/// states, to 1e-6 relative.
fn finite_differences<const N: usize>(
    name: &str,
    tau: impl Fn(&[f64; N], &[f64; N], &[f64; N]) -> [f64; N],
    derivatives: impl Fn(&[f64; N], &[f64; N], &[f64; N]) -> ([[f64; N]; N], [[f64; N]; N]),
) {
    let h = 1e-6;
    for s in 0..3 {
        let f = s as f64;
        let q: [f64; N] = core::array::from_fn(|i| (0.7 * i as f64 + f).sin());
        let qd: [f64; N] = core::array::from_fn(|i| (0.3 * i as f64 - f).cos());
        let qdd: [f64; N] = core::array::from_fn(|i| 0.5 * (1.1 * i as f64 + f).sin());
        let (dq, dqd) = derivatives(&q, &qd, &qdd);
        for j in 0..N {
            let (mut qp, mut qm, mut vp, mut vm) = (q, q, qd, qd);
            qp[j] += h;
            qm[j] -= h;
            vp[j] += h;
            vm[j] -= h;
            let (tqp, tqm) = (tau(&qp, &qd, &qdd), tau(&qm, &qd, &qdd));
            let (tvp, tvm) = (tau(&q, &vp, &qdd), tau(&q, &vm, &qdd));
            for i in 0..N {
                let nq = (tqp[i] - tqm[i]) / (2.0 * h);
                let nv = (tvp[i] - tvm[i]) / (2.0 * h);
                assert!(
                    (nq - dq[i][j]).abs() < 1e-6 * (1.0 + nq.abs()),
                    "{name} dtau{i}/dq{j}: {} vs {nq}",
                    dq[i][j]
                );
                assert!(
                    (nv - dqd[i][j]).abs() < 1e-6 * (1.0 + nv.abs()),
                    "{name} dtau{i}/dqd{j}: {} vs {nv}",
                    dqd[i][j]
                );
            }
        }
    }
}

/// A robot that is not one of the five reference robots (example-robot-data's xArm 7, whose
/// reference the shared tool computed with Pinocchio), held to the same tolerances. Opt-in:
/// `EOMGEN_TEST_UNSHIPPED=1 cargo test -p eomgen-tests --test derivatives` (its module is large).
#[cfg(unshipped)]
#[test]
fn an_arm_we_do_not_ship_matches_pinocchio() {
    check_robot!("xarm7", xarm7_derivatives, Xarm7Derivatives, 7);
}

/// With joint friction (Coulomb smoothed) and rotor inertia, both derivatives against central
/// differences of the compiled inverse and forward dynamics.
#[test]
fn friction_and_rotor_inertia_enter_the_derivatives() {
    use joint_effects_derivatives::JointEffectsDerivatives as Robot;
    const N: usize = 2;
    let robot = Robot::<f64>::default();
    finite_differences::<N>(
        "joint_effects",
        |q, qd, a| robot.inverse_dynamics(q, qd, a),
        |q, qd, a| robot.inverse_dynamics_derivatives(q, qd, a),
    );
    let fd_derivatives = |q: &[f64; N], qd: &[f64; N], tau: &[f64; N]| {
        let (dq, dqd, _) = robot.forward_dynamics_derivatives(q, qd, tau);
        (dq, dqd)
    };
    finite_differences::<N>(
        "joint_effects forward dynamics",
        |q, qd, tau| robot.forward_dynamics(q, qd, tau),
        fd_derivatives,
    );
    // Friction is a function of qd alone, so d tau / d qd carries its slope on the diagonal.
    let (_, dqd) = robot.inverse_dynamics_derivatives(&[0.1, 0.2], &[0.0, 0.0], &[0.0, 0.0]);
    let (_, dqd_far) = robot.inverse_dynamics_derivatives(&[0.1, 0.2], &[3.0, 0.0], &[0.0, 0.0]);
    assert!(
        dqd[0][0] > dqd_far[0][0],
        "the smoothed Coulomb slope at rest: {dqd:?}"
    );
}

#[test]
fn derivatives_match_pinocchio_finite_differences_and_invert_m() {
    check_robot!("ur5", ur5_derivatives, Ur5Derivatives, 6);
    check_robot!("panda", panda_derivatives, PandaDerivatives, 9);
    check_robot!("kinova", kinova_derivatives, KinovaDerivatives, 6);
    check_robot!(
        "allegro_right_hand",
        allegro_derivatives,
        AllegroDerivatives,
        16
    );
}
