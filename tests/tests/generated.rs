//! The compiled generated code (from this crate's build script) against Pinocchio's reference
//! values: every function of the contract, all five robots, every sample; f64 to 1e-9 and f32
//! to 1e-3 relative.

#![allow(clippy::needless_range_loop)]

use eomgen_runtime::Dynamics;
use eomgen_tests::robots::{allegro_right_hand, double_pendulum, kinova, panda, ur5};
use eomgen_tests::{load, Checker, JointMap};

/// Converts a reference-ordered state to our order, as a fixed-size array.
fn arr<T: eomgen_runtime::Real, const N: usize>(map: &JointMap, v: &[f64]) -> [T; N] {
    let ours = map.to_ours(v);
    core::array::from_fn(|i| T::from_f64(ours[i]))
}

macro_rules! check_robot {
    ($name:literal, $module:ident, $ty:ident, $link:ident, $n:literal, $t:ty, $tol:expr) => {{
        type R = $module::$ty<$t>;
        let robot = R::default();
        let reference = load($name);
        let map = JointMap::new(&reference.joints, &<R as Dynamics<$t, $n>>::JOINT_NAMES);
        let o = &map.ours;
        let mut c = Checker::new($tol);
        let f = |x: $t| x as f64;
        for (s, sm) in reference.samples.iter().enumerate() {
            let q: [$t; $n] = arr(&map, &sm.q);
            let qd: [$t; $n] = arr(&map, &sm.qd);
            let qdd: [$t; $n] = arr(&map, &sm.qdd);
            let tau_in: [$t; $n] = arr(&map, &sm.tau_in);
            let m = robot.mass_matrix(&q);
            let g = robot.gravity(&q);
            let b = robot.bias(&q, &qd);
            let cm = robot.coriolis_matrix(&q, &qd);
            let tau = robot.inverse_dynamics(&q, &qd, &qdd);
            let fd = robot.forward_dynamics(&q, &qd, &tau_in);
            for i in 0..$n {
                for j in 0..$n {
                    c.check(
                        || format!("#{s} M[{i}][{j}]"),
                        f(m[o[i]][o[j]]),
                        sm.mass_matrix[i][j],
                    );
                    c.check(
                        || format!("#{s} C[{i}][{j}]"),
                        f(cm[o[i]][o[j]]),
                        sm.coriolis_matrix[i][j],
                    );
                }
                c.check(|| format!("#{s} g[{i}]"), f(g[o[i]]), sm.gravity[i]);
                c.check(|| format!("#{s} b[{i}]"), f(b[o[i]]), sm.bias[i]);
                c.check(|| format!("#{s} tau[{i}]"), f(tau[o[i]]), sm.tau[i]);
            }
            for i in 0..$n {
                c.check(
                    || format!("#{s} forward_dynamics[{i}]"),
                    f(fd[o[i]]),
                    sm.forward_dynamics[i],
                );
            }
            c.check(
                || format!("#{s} T"),
                f(robot.kinetic_energy(&q, &qd)),
                sm.kinetic_energy,
            );
            // p = M qd (Pinocchio's M), and qd . p = 2 T.
            let p = robot.generalized_momentum(&q, &qd);
            for i in 0..$n {
                let want: f64 = (0..$n).map(|j| sm.mass_matrix[i][j] * sm.qd[j]).sum();
                c.check(|| format!("#{s} p[{i}]"), f(p[o[i]]), want);
            }
            let qd_p: f64 = (0..$n).map(|i| f(qd[i]) * f(p[i])).sum();
            c.check(|| format!("#{s} qd.p"), qd_p, 2.0 * sm.kinetic_energy);
            c.check(
                || format!("#{s} V"),
                f(robot.potential_energy(&q)),
                sm.potential_energy,
            );
            if let (Some(cf), Some(cp)) = (&sm.centrifugal, &sm.coriolis_pairs) {
                let ccf = robot.centrifugal(&q);
                let ccp = robot.coriolis_pairs(&q);
                for i in 0..$n {
                    for j in 0..$n {
                        c.check(
                            || format!("#{s} Craig C[{i}][{j}]"),
                            f(ccf[o[i]][o[j]]),
                            cf[i][j],
                        );
                    }
                    let mut p = 0;
                    for a in 0..$n {
                        for bb in a + 1..$n {
                            c.check(
                                || format!("#{s} Craig B[{i}][({a},{bb})]"),
                                f(ccp[o[i]][map.pair(a, bb)]),
                                cp[i][p],
                            );
                            p += 1;
                        }
                    }
                }
            }
            assert_eq!($module::$link::ALL.len(), sm.frames.len());
            for link in $module::$link::ALL {
                let want = &sm.frames[link.name()];
                let pose = robot.link_pose(link, &q);
                let jac = robot.link_jacobian(link, &q);
                for k in 0..3 {
                    c.check(
                        || format!("#{s} {} p[{k}]", link.name()),
                        f(pose.translation[k]),
                        want.position[k],
                    );
                    for mm in 0..3 {
                        c.check(
                            || format!("#{s} {} R[{k}][{mm}]", link.name()),
                            f(pose.rotation[k][mm]),
                            want.rotation[k][mm],
                        );
                    }
                }
                for r in 0..6 {
                    for j in 0..$n {
                        c.check(
                            || format!("#{s} {} J[{r}][{j}]", link.name()),
                            f(jac[r][o[j]]),
                            want.jacobian[r][j],
                        );
                    }
                }
            }
        }
        c.finish(concat!($name, " ", stringify!($t)));
    }};
}

#[test]
fn double_pendulum_matches_pinocchio() {
    check_robot!(
        "double_pendulum",
        double_pendulum,
        DoublePendulum,
        DoublePendulumLink,
        2,
        f64,
        1e-9
    );
}

#[test]
fn ur5_matches_pinocchio() {
    check_robot!("ur5", ur5, Ur5, Ur5Link, 6, f64, 1e-9);
}

#[test]
fn panda_matches_pinocchio() {
    check_robot!("panda", panda, Panda, PandaLink, 9, f64, 1e-9);
}

#[test]
fn kinova_matches_pinocchio() {
    check_robot!("kinova", kinova, Kinova, KinovaLink, 6, f64, 1e-9);
}

#[test]
fn allegro_hand_matches_pinocchio() {
    check_robot!(
        "allegro_right_hand",
        allegro_right_hand,
        AllegroRightHand,
        AllegroRightHandLink,
        16,
        f64,
        1e-9
    );
}

#[test]
fn single_precision_matches_pinocchio_to_1e_3() {
    check_robot!(
        "double_pendulum",
        double_pendulum,
        DoublePendulum,
        DoublePendulumLink,
        2,
        f32,
        1e-3
    );
    check_robot!("ur5", ur5, Ur5, Ur5Link, 6, f32, 1e-3);
    check_robot!("panda", panda, Panda, PandaLink, 9, f32, 1e-3);
    check_robot!("kinova", kinova, Kinova, KinovaLink, 6, f32, 1e-3);
    check_robot!(
        "allegro_right_hand",
        allegro_right_hand,
        AllegroRightHand,
        AllegroRightHandLink,
        16,
        f32,
        1e-3
    );
}
