//! Passive joints (`Builder::passive_joints`): the generated selection matrix, actuated joint
//! names and `forward_dynamics_actuated`, and the acrobot (passive elbow) under the runtime's
//! collocated partial feedback linearization.

use eomgen_runtime::prelude::*;
use eomgen_runtime::{CollocatedPfl, Integrator, Setpoint, Simulator, State};
use eomgen_tests::robots::acrobot::Acrobot;
use eomgen_tests::robots::ur5_passive_wrist::Ur5PassiveWrist;

#[test]
fn selection_and_actuated_names() {
    type A = Acrobot<f64>;
    assert_eq!(<A as Dynamics<f64, 2>>::JOINT_NAMES, ["shoulder", "elbow"]);
    assert_eq!(A::ACTUATED_JOINT_NAMES, ["shoulder"]);
    assert_eq!(A::NA, 1);
    assert_eq!(A::ACTUATED_JOINTS, [0]);
    assert_eq!(A::PASSIVE_JOINTS, [1]);
    let s: [[f64; 2]; 1] = A::selection();
    assert_eq!(s, [[1.0, 0.0]]);
    assert_eq!(A::full_effort(&[3.5]), [3.5, 0.0]);

    type U = Ur5PassiveWrist<f64>;
    let names = <U as Dynamics<f64, 6>>::JOINT_NAMES;
    let s: [[f64; 6]; 4] = U::selection();
    for (k, row) in s.iter().enumerate() {
        let j = U::ACTUATED_JOINTS[k];
        assert_eq!(names[j], U::ACTUATED_JOINT_NAMES[k]);
        for (i, x) in row.iter().enumerate() {
            assert_eq!(*x, if i == j { 1.0 } else { 0.0 });
        }
    }
    // S^T tau_a is zero on the passive joints by construction.
    let full = U::full_effort(&[1.0, 2.0, 3.0, 4.0]);
    for &p in &U::PASSIVE_JOINTS {
        assert!(["wrist_1_joint", "wrist_3_joint"].contains(&names[p]));
        assert_eq!(full[p], 0.0);
    }
}

#[test]
fn forward_dynamics_actuated_is_forward_dynamics_of_the_full_effort() {
    let robot = Ur5PassiveWrist::<f64>::default();
    let q = [0.3, -1.0, 1.2, -0.4, 0.8, 0.1];
    let qd = [0.5, -0.2, 0.3, 1.0, -0.7, 0.4];
    let tau_a = [2.0, -15.0, 4.0, 0.5];
    let s: [[f64; 6]; 4] = Ur5PassiveWrist::<f64>::selection();
    let full: [f64; 6] = core::array::from_fn(|i| (0..4).map(|k| s[k][i] * tau_a[k]).sum());
    assert_eq!(
        robot.forward_dynamics_actuated(&q, &qd, &tau_a),
        robot.forward_dynamics(&q, &qd, &full)
    );
    // The passive joints' rows of the equation of motion have no effort.
    let qdd = robot.forward_dynamics_actuated(&q, &qd, &tau_a);
    let tau = robot.inverse_dynamics(&q, &qd, &qdd);
    for &p in &Ur5PassiveWrist::<f64>::PASSIVE_JOINTS {
        assert!(tau[p].abs() < 1e-10, "{tau:?}");
    }
}

/// The acrobot with a passive elbow under collocated PFL: the shoulder follows the
/// critically damped linear error dynamics exactly, the elbow gets no effort and swings.
#[test]
fn acrobot_under_collocated_pfl() {
    let robot = Acrobot::<f64>::default();
    let pfl = CollocatedPfl::critically_damped(Acrobot::<f64>::PASSIVE_JOINTS[0], 4.0);
    let target = Setpoint::hold([0.8, 0.0]);
    let mut sim = Simulator::new(&robot, Integrator::Rk4, State::at_rest([0.0, 0.0]), 1e-3);
    let mut elbow_range = (0.0_f64, 0.0_f64);
    for k in 1..=3000 {
        sim.run_continuous(1, |_t, s| {
            let tau = pfl.torque(&robot, s, &target);
            assert_eq!(tau[1], 0.0);
            tau
        });
        let t = k as f64 * 1e-3;
        // e(t) = e0 (1 + w t) exp(-w t) with e0 = 0.8, w = 4.
        let want = 0.8 - 0.8 * (1.0 + 4.0 * t) * (-4.0 * t).exp();
        assert!(
            (sim.state.q[0] - want).abs() < 1e-8,
            "t = {t}: {} vs {want}",
            sim.state.q[0]
        );
        elbow_range = (
            elbow_range.0.min(sim.state.q[1]),
            elbow_range.1.max(sim.state.q[1]),
        );
    }
    assert!(
        elbow_range.1 - elbow_range.0 > 0.5,
        "the elbow barely moved: {elbow_range:?}"
    );

    // Swing-up: the shoulder's target moves against the elbow's velocity and pumps energy in
    // (from hanging at -19.6 J towards upright at +19.6 J).
    let swing = CollocatedPfl {
        swing: -1.0,
        ..CollocatedPfl::critically_damped(1, 6.0)
    };
    let start = State::new([0.0, 0.1], [0.0, 0.0]);
    let e0 = start.energy(&robot);
    let mut sim = Simulator::new(&robot, Integrator::Rk4, start, 1e-3);
    let end = sim.run_continuous(10_000, |_t, s| {
        swing.torque(&robot, s, &Setpoint::hold([0.0, 0.0]))
    });
    assert!(end.is_finite());
    assert!(
        end.energy(&robot) > e0 + 5.0,
        "{} J -> {} J",
        e0,
        end.energy(&robot)
    );
}
