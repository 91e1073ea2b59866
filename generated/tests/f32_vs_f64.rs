//! Single precision is good enough for firmware: on every reference state of every robot, each
//! generated function evaluated in `f32` agrees with the same function in `f64` to
//! `|a32 - a64| <= 1e-3 * max(1, |a64|)`.
//!
//! This compares the two instantiations of the generated code with each other (not with
//! Pinocchio, which `eomgen-tests` does), so it isolates the rounding error of `f32` arithmetic
//! (and of rounding the inputs to `f32`) from modelling errors. The `f64` side gets the states
//! exactly as stored in `tests/robots/<robot>.json`; the `f32` side gets them rounded.

#![allow(clippy::needless_range_loop)]

use std::path::PathBuf;

use eomgen_generated::{allegro_right_hand, double_pendulum, kinova, panda, ur5};
use eomgen_runtime::{Dynamics, Pose};
use serde_json::Value;

const TOL: f64 = 1e-3;

/// The reference file `tests/robots/<robot>.json` of the workspace.
fn load(robot: &str) -> Value {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join("tests")
        .join("robots")
        .join(format!("{robot}.json"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// `sample[key]` as a fixed-size `f64` array.
fn vector<const N: usize>(sample: &Value, key: &str) -> [f64; N] {
    let v = sample[key]
        .as_array()
        .unwrap_or_else(|| panic!("sample has no array `{key}`"));
    assert_eq!(v.len(), N, "`{key}` has {} entries, expected {N}", v.len());
    core::array::from_fn(|i| v[i].as_f64().expect("a number"))
}

fn to_f32<const N: usize>(v: &[f64; N]) -> [f32; N] {
    v.map(|x| x as f32)
}

/// Collects the comparisons of one robot: the worst relative error and every failure.
struct Compare {
    robot: &'static str,
    worst: f64,
    worst_at: String,
    failures: Vec<String>,
}

impl Compare {
    fn new(robot: &'static str) -> Self {
        Compare {
            robot,
            worst: 0.0,
            worst_at: String::new(),
            failures: Vec::new(),
        }
    }

    fn value(&mut self, what: impl Fn() -> String, a32: f32, a64: f64) {
        let err = (a32 as f64 - a64).abs() / a64.abs().max(1.0);
        // A NaN on either side fails too.
        if err.is_nan() || err > TOL {
            self.failures.push(format!(
                "{}: f32 {a32:e} vs f64 {a64:e} (rel {err:.2e})",
                what()
            ));
        }
        if err > self.worst || err.is_nan() {
            self.worst = err;
            self.worst_at = what();
        }
    }

    fn vector<const N: usize>(&mut self, what: &str, s: usize, a32: &[f32; N], a64: &[f64; N]) {
        for i in 0..N {
            self.value(|| format!("#{s} {what}[{i}]"), a32[i], a64[i]);
        }
    }

    fn matrix<const R: usize, const C: usize>(
        &mut self,
        what: &str,
        s: usize,
        a32: &[[f32; C]; R],
        a64: &[[f64; C]; R],
    ) {
        for i in 0..R {
            for j in 0..C {
                self.value(|| format!("#{s} {what}[{i}][{j}]"), a32[i][j], a64[i][j]);
            }
        }
    }

    fn pose(&mut self, what: &str, s: usize, a32: &Pose<f32>, a64: &Pose<f64>) {
        self.vector(
            &format!("{what}.translation"),
            s,
            &a32.translation,
            &a64.translation,
        );
        self.matrix(&format!("{what}.rotation"), s, &a32.rotation, &a64.rotation);
    }

    fn finish(self, checked_samples: usize) {
        println!(
            "{}: {checked_samples} samples, worst relative error {:.3e} at {}",
            self.robot, self.worst, self.worst_at
        );
        assert!(checked_samples > 0, "{}: no samples", self.robot);
        assert!(
            self.failures.is_empty(),
            "{}: {} values differ by more than {TOL} relative:\n{}",
            self.robot,
            self.failures.len(),
            self.failures.join("\n")
        );
    }
}

macro_rules! f32_vs_f64 {
    ($test:ident, $name:literal, $module:ident, $ty:ident, $link:ident, $n:literal) => {
        #[test]
        fn $test() {
            let r32 = $module::$ty::<f32>::default();
            let r64 = $module::$ty::<f64>::default();
            let reference = load($name);
            let joints: Vec<&str> = reference["joints"]
                .as_array()
                .expect("`joints`")
                .iter()
                .map(|j| j.as_str().expect("a joint name"))
                .collect();
            // The generated order is the reference order, so samples need no permutation.
            assert_eq!(
                joints,
                <$module::$ty<f64> as Dynamics<f64, $n>>::JOINT_NAMES
            );

            let samples = reference["samples"].as_array().expect("`samples`");
            let mut c = Compare::new($name);
            for (s, sample) in samples.iter().enumerate() {
                let q: [f64; $n] = vector(sample, "q");
                let qd: [f64; $n] = vector(sample, "qd");
                let qdd: [f64; $n] = vector(sample, "qdd");
                let tau_in: [f64; $n] = vector(sample, "tau_in");
                let (q32, qd32, qdd32, tau32) =
                    (to_f32(&q), to_f32(&qd), to_f32(&qdd), to_f32(&tau_in));

                c.matrix(
                    "mass_matrix",
                    s,
                    &r32.mass_matrix(&q32),
                    &r64.mass_matrix(&q),
                );
                c.vector("gravity", s, &r32.gravity(&q32), &r64.gravity(&q));
                c.vector("bias", s, &r32.bias(&q32, &qd32), &r64.bias(&q, &qd));
                c.matrix(
                    "coriolis_matrix",
                    s,
                    &r32.coriolis_matrix(&q32, &qd32),
                    &r64.coriolis_matrix(&q, &qd),
                );
                c.vector(
                    "inverse_dynamics",
                    s,
                    &r32.inverse_dynamics(&q32, &qd32, &qdd32),
                    &r64.inverse_dynamics(&q, &qd, &qdd),
                );
                c.vector(
                    "forward_dynamics",
                    s,
                    &r32.forward_dynamics(&q32, &qd32, &tau32),
                    &r64.forward_dynamics(&q, &qd, &tau_in),
                );
                c.value(
                    || format!("#{s} kinetic_energy"),
                    r32.kinetic_energy(&q32, &qd32),
                    r64.kinetic_energy(&q, &qd),
                );
                c.value(
                    || format!("#{s} potential_energy"),
                    r32.potential_energy(&q32),
                    r64.potential_energy(&q),
                );
                c.matrix(
                    "centrifugal",
                    s,
                    &r32.centrifugal(&q32),
                    &r64.centrifugal(&q),
                );
                c.matrix(
                    "coriolis_pairs",
                    s,
                    &r32.coriolis_pairs(&q32),
                    &r64.coriolis_pairs(&q),
                );
                for link in $module::$link::ALL {
                    let name = link.name();
                    c.pose(
                        &format!("link_pose({name})"),
                        s,
                        &r32.link_pose(link, &q32),
                        &r64.link_pose(link, &q),
                    );
                    c.matrix(
                        &format!("link_jacobian({name})"),
                        s,
                        &r32.link_jacobian(link, &q32),
                        &r64.link_jacobian(link, &q),
                    );
                }
            }
            c.finish(samples.len());
        }
    };
}

f32_vs_f64!(
    double_pendulum_f32_matches_f64,
    "double_pendulum",
    double_pendulum,
    DoublePendulum,
    DoublePendulumLink,
    2
);
f32_vs_f64!(ur5_f32_matches_f64, "ur5", ur5, Ur5, Ur5Link, 6);
f32_vs_f64!(panda_f32_matches_f64, "panda", panda, Panda, PandaLink, 9);
f32_vs_f64!(
    kinova_f32_matches_f64,
    "kinova",
    kinova,
    Kinova,
    KinovaLink,
    6
);
f32_vs_f64!(
    allegro_right_hand_f32_matches_f64,
    "allegro_right_hand",
    allegro_right_hand,
    AllegroRightHand,
    AllegroRightHandLink,
    16
);
