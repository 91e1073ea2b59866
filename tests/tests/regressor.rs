//! `Builder::regressor` through compiled generated code: `regressor` and `parameters` against
//! Pinocchio's computeJointTorqueRegressor (`tests/robots/NAME.regressor.json`, 1e-9), the
//! base parameters reproducing the inverse dynamics (1e-9) and as many as the rank of the
//! stacked regressor over random states, and rotor inertia and friction as extra columns.

#![allow(clippy::needless_range_loop)]

use eomgen_tests::robots::{
    allegro_regressor, double_pendulum_regressor, joint_effects_regressor, kinova_regressor,
    panda_regressor, ur5_regressor,
};
use eomgen_tests::{JointMap, Lcg};
use nalgebra::DMatrix;
use serde_json::Value;

fn load(robot: &str) -> Value {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("robots")
        .join(format!("{robot}.regressor.json"));
    serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap()
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|e| e.as_f64().unwrap())
        .collect()
}

/// A random state: positions, velocities and accelerations.
fn state<const N: usize>(rng: &mut Lcg) -> ([f64; N], [f64; N], [f64; N]) {
    (
        core::array::from_fn(|_| rng.uniform(-3.0, 3.0)),
        core::array::from_fn(|_| rng.uniform(-2.0, 2.0)),
        core::array::from_fn(|_| rng.uniform(-2.0, 2.0)),
    )
}

/// Numerical rank, with NumPy's default tolerance (largest singular value times the
/// dimension times machine epsilon) raised to 1e-8 relative, as the contract check uses.
fn rank(rows: &[Vec<f64>]) -> usize {
    let m = DMatrix::from_fn(rows.len(), rows[0].len(), |i, j| rows[i][j]);
    let scale = m.amax().max(1.0) * (m.nrows().max(m.ncols()) as f64);
    m.rank(1e-8 * scale)
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Checks `regressor x parameters = base_regressor x base_parameters = inverse_dynamics` at
/// `count` random states and returns the rows of both regressors there.
macro_rules! random_identities {
    ($name:expr, $robot:expr, $n:expr, $params:expr, $base:expr, $count:expr) => {{
        let mut rng = Lcg(0x0123_4567_89ab_cdef);
        let (mut full, mut reduced) = (Vec::new(), Vec::new());
        for _ in 0..$count {
            let (q, qd, qdd) = state::<{ $n }>(&mut rng);
            let (y, yb, tau) = (
                $robot.regressor(&q, &qd, &qdd),
                $robot.base_regressor(&q, &qd, &qdd),
                $robot.inverse_dynamics(&q, &qd, &qdd),
            );
            for i in 0..$n {
                let scale = tau[i].abs().max(1.0);
                let e = (dot(&y[i], $params) - tau[i]).abs() / scale;
                assert!(e < 1e-9, "{}: Y pi off by {e:e} at a random state", $name);
                let e = (dot(&yb[i], $base) - tau[i]).abs() / scale;
                assert!(
                    e < 1e-9,
                    "{}: Y_b pi_b off by {e:e} at a random state",
                    $name
                );
                full.push(y[i].to_vec());
                reduced.push(yb[i].to_vec());
            }
        }
        (full, reduced)
    }};
}

macro_rules! check_robot {
    ($name:literal, $module:ident, $ty:ident, $n:literal) => {{
        const N: usize = $n;
        type R = $module::$ty<f64>;
        let robot = R::default();
        let doc = load($name);
        let reference: Vec<String> = doc["joints"]
            .as_array()
            .unwrap()
            .iter()
            .map(|j| j.as_str().unwrap().to_string())
            .collect();
        let map = JointMap::new(&reference, &R::JOINT_NAMES);
        // The reference's column of our column `c`: blocks of ten follow the joints.
        let column = |c: usize| 10 * map.ours.iter().position(|&o| o == c / 10).unwrap() + c % 10;
        let params = robot.parameters();
        let want = numbers(&doc["parameters"]);
        assert_eq!(params.len(), 10 * N);
        for c in 0..10 * N {
            let w = want[column(c)];
            assert!(
                (params[c] - w).abs() <= 1e-9 * w.abs().max(1.0),
                "{}: parameter {} = {}, Pinocchio {w}",
                $name,
                R::PARAMETER_NAMES[c],
                params[c]
            );
        }
        let base = robot.base_parameters();
        let mut worst = [0.0_f64; 2];
        for s in doc["samples"].as_array().unwrap() {
            let state = |k: &str| -> [f64; N] {
                let v = map.to_ours(&numbers(&s[k]));
                core::array::from_fn(|i| v[i])
            };
            let (q, qd, qdd, tau) = (state("q"), state("qd"), state("qdd"), state("tau"));
            let y = robot.regressor(&q, &qd, &qdd);
            let rows: Vec<Vec<f64>> = s["regressor"]
                .as_array()
                .unwrap()
                .iter()
                .map(numbers)
                .collect();
            let scale = rows.iter().flatten().fold(1.0_f64, |m, x| m.max(x.abs()));
            for (k, row) in rows.iter().enumerate() {
                for c in 0..10 * N {
                    let e = (y[map.ours[k]][c] - row[column(c)]).abs() / scale;
                    worst[0] = worst[0].max(e);
                }
            }
            let yb = robot.base_regressor(&q, &qd, &qdd);
            for i in 0..N {
                let e = (dot(&yb[i], &base) - tau[i]).abs() / tau[i].abs().max(1.0);
                worst[1] = worst[1].max(e);
            }
        }
        assert!(
            worst[0] < 1e-9,
            "{}: regressor differs from Pinocchio's by {:e}",
            $name,
            worst[0]
        );
        assert!(
            worst[1] < 1e-9,
            "{}: base regressor x base parameters differs from tau by {:e}",
            $name,
            worst[1]
        );
        // Minimal: as many base parameters as the rank of the full regressor, and exact on
        // random states too.
        let (full, reduced) = random_identities!($name, robot, N, &params, &base, 20 + 20 / N);
        let p = base.len();
        assert_eq!(rank(&full), p, "{}: rank of the regressor", $name);
        assert_eq!(
            rank(&reduced),
            p,
            "{}: the base regressor has full column rank",
            $name
        );
        assert_eq!(R::BASE_PARAMETER_NAMES.len(), p);
        assert_eq!(R::BODY_NAMES.len(), N);
        p
    }};
}

#[test]
fn double_pendulum_matches_pinocchio() {
    let p = check_robot!(
        "double_pendulum",
        double_pendulum_regressor,
        DoublePendulumRegressor,
        2
    );
    assert_eq!(p, 6);
}

#[test]
fn ur5_matches_pinocchio() {
    check_robot!("ur5", ur5_regressor, Ur5Regressor, 6);
}

#[test]
fn panda_matches_pinocchio() {
    check_robot!("panda", panda_regressor, PandaRegressor, 9);
}

#[test]
fn kinova_matches_pinocchio() {
    check_robot!("kinova", kinova_regressor, KinovaRegressor, 6);
}

#[test]
fn allegro_hand_matches_pinocchio() {
    check_robot!(
        "allegro_right_hand",
        allegro_regressor,
        AllegroRegressor,
        16
    );
}

/// The double pendulum's base parameters are the textbook ones: its two joints are parallel
/// (x) and horizontal, so each body keeps its inertia about the axis and its first moments
/// across it, and the second body's mass goes to the first.
#[test]
fn double_pendulum_base_parameters_are_the_textbook_ones() {
    type R = double_pendulum_regressor::DoublePendulumRegressor<f64>;
    assert_eq!(
        R::BASE_PARAMETER_NAMES,
        [
            "MY_link1",
            "MZR_link1",
            "XXR_link1",
            "MY_link2",
            "MZ_link2",
            "XX_link2"
        ]
    );
    let (p, b) = (R::default().parameters(), R::default().base_parameters());
    let name = |n: &str| p[R::PARAMETER_NAMES.iter().position(|x| *x == n).unwrap()];
    // Joint 2 sits 0.1 m along z from joint 1: MZR1 = MZ1 + 0.1 M2, XXR1 = XX1 + 0.1^2 M2.
    assert!((b[1] - (name("MZ_link1") + 0.1 * name("M_link2"))).abs() < 1e-15);
    assert!((b[2] - (name("XX_link1") + 0.01 * name("M_link2"))).abs() < 1e-15);
}

/// Rotor inertia and friction are parameters too: the regressor has their columns after the
/// bodies', and both regressors reproduce the inverse dynamics with them.
#[test]
fn joint_effects_are_extra_parameters() {
    type R = joint_effects_regressor::JointEffectsRegressor<f64>;
    const N: usize = 2;
    let robot = R::default();
    let params = robot.parameters();
    let names = R::PARAMETER_NAMES;
    assert_eq!(params.len(), 10 * N + 2 + 2 * N, "{names:?}");
    assert_eq!(&names[10 * N..10 * N + 2], &["IA_shoulder", "IA_elbow"]);
    assert!(names[10 * N + 2..]
        .iter()
        .all(|n| n.starts_with("FV_") || n.starts_with("FS_")));
    assert_eq!(params[10 * N], 0.2);
    let base = robot.base_parameters();
    let (rows, _) = random_identities!("joint effects", robot, N, &params, &base, 40);
    assert_eq!(rank(&rows), base.len());
}
