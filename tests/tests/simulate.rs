//! Simulation and control with the runtime's integrators and controllers on the generated
//! reference robots: energy conservation, computed-torque tracking, manipulability duality.

#![allow(clippy::needless_range_loop)] // index loops read like the formulas

use std::hint::black_box;

use eomgen_tests::alloc_counter::{allocations, Counting};

use eomgen_runtime::{
    wrench_to_torque, ComputedTorque, Dynamics, Ellipsoid, Integrator, PdGravity, Setpoint,
    Simulator, State, WithJointEffects,
};
use eomgen_tests::robots::double_pendulum::DoublePendulum;
use eomgen_tests::robots::panda::{Panda, PandaLink};
use eomgen_tests::robots::ur5::{Ur5, Ur5Link};

/// Runs the passive double pendulum from `initial` with RK4 (or semi-implicit Euler) at 1 ms
/// for 10 s. Returns `(max |E(t) - E(0)|, max kinetic energy, E(0))` over every step.
fn passive_drift(integrator: Integrator, initial: State<f64, 2>) -> (f64, f64, f64) {
    let robot = DoublePendulum::<f64>::default();
    let e0 = initial.energy(&robot);
    let mut sim = Simulator::new(&robot, integrator, initial, 1e-3);
    let (mut drift, mut k_max): (f64, f64) = (0.0, 0.0);
    for _ in 0..10_000 {
        sim.step(&[0.0; 2]);
        drift = drift.max((sim.state.energy(&robot) - e0).abs());
        k_max = k_max.max(robot.kinetic_energy(&sim.state.q, &sim.state.qd));
    }
    assert!(sim.state.is_finite());
    (drift, k_max, e0)
}

/// Passive double pendulum, RK4 at 1 ms for 10 s: the total energy is conserved to < 1e-6
/// relative, at every step.
///
/// In this URDF `q = 0` is the upright (inverted) position and `q1 = pi` hangs down. The
/// potential's zero (centres of mass at the world origin) is arbitrary, so the drift is taken
/// relative to both `|E(0)|` and the largest kinetic energy reached (the energy that is
/// exchanged with the potential). The start — link 1 swung 1.34 rad from hanging, link 2 bent
/// 1.2 rad, both moving — gives a large non-linear swing.
///
/// A harder case, falling from 0.4 rad off upright and whirling chaotically through the bottom
/// (peak joint speeds above 20 rad/s), drifts by a few 1e-6 at this step: printed and bounded
/// at 1e-5 to document the step's limit.
#[test]
fn double_pendulum_rk4_conserves_energy() {
    let swing = State::new([1.8, 1.2], [1.0, 2.0]);
    let (drift, k_max, e0) = passive_drift(Integrator::Rk4, swing);
    let (rel_k, rel_e) = (drift / k_max, drift / e0.abs());
    eprintln!(
        "double pendulum RK4, swing: E0 = {e0:.4e} J, max kinetic {k_max:.4e} J, \
         max |E - E0| = {drift:.3e} J: relative to max kinetic {rel_k:.3e}, to |E0| {rel_e:.3e}"
    );
    assert!(rel_k < 1e-6 && rel_e < 1e-6);

    let (euler, _, _) = passive_drift(Integrator::SemiImplicitEuler, swing);
    eprintln!(
        "double pendulum semi-implicit Euler, swing: relative to max kinetic {:.3e}",
        euler / k_max
    );
    // First order: far larger (tens of percent here), which is why the test uses RK4.
    assert!(euler > 100.0 * drift);

    let fall = State::new([0.4, -0.9], [0.0, 0.0]);
    let (drift, k_max, e0) = passive_drift(Integrator::Rk4, fall);
    eprintln!(
        "double pendulum RK4, chaotic fall: E0 = {e0:.4e} J, max kinetic {k_max:.4e} J, \
         relative drift to max kinetic {:.3e}",
        drift / k_max
    );
    assert!(drift / k_max < 1e-5);
}

/// A smooth joint reference: `q*(t) = c + a sin(w t + p)` per joint, with its derivatives.
fn sine_reference<const N: usize>(
    c: &[f64; N],
    a: &[f64; N],
    w: &[f64; N],
    t: f64,
) -> Setpoint<f64, N> {
    let p = |i: usize| w[i] * t + 0.3 * i as f64;
    Setpoint {
        q: core::array::from_fn(|i| c[i] + a[i] * p(i).sin()),
        qd: core::array::from_fn(|i| a[i] * w[i] * p(i).cos()),
        qdd: core::array::from_fn(|i| -a[i] * w[i] * w[i] * p(i).sin()),
    }
}

/// Computed torque with the exact panda model (all nine joints, fingers included) starting
/// 0.05 rad (5 mm for the fingers) off a sinusoidal reference: after 2 s the error is below
/// 1e-6. Critically damped at 20 rad/s, the initial error has decayed by `41 e^-40`; what
/// remains is the integration and zero-order-hold error, measured in the printout.
#[test]
fn panda_computed_torque_tracks_reference() {
    let robot = Panda::<f64>::default();
    let c = [0.0, -0.5, 0.0, -2.0, 0.0, 1.5, 0.8, 0.02, 0.02];
    let a = [0.3, 0.2, 0.3, 0.3, 0.4, 0.3, 0.5, 0.005, 0.005];
    let w = [1.0, 1.5, 2.0, 1.2, 2.5, 1.8, 3.0, 2.0, 2.0];
    let start = sine_reference(&c, &a, &w, 0.0);
    let offset: [f64; 9] = core::array::from_fn(|i| if i < 7 { 0.05 } else { 0.005 });
    let initial = State::new(core::array::from_fn(|i| start.q[i] + offset[i]), start.qd);
    let ct = ComputedTorque::critically_damped([20.0; 9]);
    let dt = 1e-3;
    let mut sampled = Simulator::new(&robot, Integrator::Rk4, initial, dt);
    let end = sampled.run(2000, |t, s| {
        ct.torque(&robot, s, &sine_reference(&c, &a, &w, t))
    });
    assert!(end.is_finite());
    let want = sine_reference(&c, &a, &w, sampled.time());
    let sampled_err = (0..9).fold(0.0_f64, |m, i| m.max((end.q[i] - want.q[i]).abs()));
    eprintln!("panda computed torque sampled at 1 kHz (zero-order hold): max |q - q*| after 2 s = {sampled_err:.3e}");
    // The hold lags the control by about dt/2: an error of order dt, bounded but well above
    // the continuous-time controller's.
    assert!(sampled_err < 1e-3, "sampled tracking error {sampled_err:e}");

    let mut sim = Simulator::new(&robot, Integrator::Rk4, initial, dt);
    let mut peak_torque: f64 = 0.0;
    let end = sim.run_continuous(2000, |t, s| {
        let tau = ct.torque(&robot, s, &sine_reference(&c, &a, &w, t));
        peak_torque = peak_torque.max(tau.iter().fold(0.0, |m: f64, x| m.max(x.abs())));
        tau
    });
    assert!(end.is_finite());
    let want = sine_reference(&c, &a, &w, sim.time());
    let err = (0..9).fold(0.0_f64, |m, i| m.max((end.q[i] - want.q[i]).abs()));
    eprintln!(
        "panda computed torque: t = {} s, max |q - q*| = {err:.3e}, peak |tau| = {peak_torque:.1}",
        sim.time()
    );
    assert!((sim.time() - 2.0).abs() < 1e-12);
    assert!(err < 1e-6, "tracking error {err:e}");
}

/// Checks that the velocity and force ellipsoids of `jac` (translational 3 x 3 and full
/// 6 x 6) share axes with reciprocal radii, and that each matches its definition: the velocity
/// semi-axis `r a` is reached by a unit joint speed, the force semi-axis `a / r` needs unit
/// joint effort. Returns the largest deviation.
fn check_duality<const N: usize, const K: usize>(
    jac: &[[f64; N]; 6],
    v: &Ellipsoid<f64, K>,
    f: &Ellipsoid<f64, K>,
) -> f64 {
    let mut worst: f64 = 0.0;
    for k in 0..K {
        let (a, r) = (v.axes[k], v.radii[k]);
        assert!(r > 1e-3, "test state too close to a singularity");
        // Same axis up to sign.
        let dot: f64 = (0..K).map(|i| a[i] * f.axes[k][i]).sum();
        worst = worst.max((dot.abs() - 1.0).abs());
        worst = worst.max((r * f.radii[k] - 1.0).abs());
        // Velocity: qd = Jkᵀ a / r has unit norm and gives J qd = r a.
        let qd: [f64; N] =
            core::array::from_fn(|j| (0..K).map(|i| jac[i][j] * a[i]).sum::<f64>() / r);
        let norm: f64 = qd.iter().map(|x| x * x).sum::<f64>().sqrt();
        worst = worst.max((norm - 1.0).abs());
        for i in 0..K {
            let vi: f64 = (0..N).map(|j| jac[i][j] * qd[j]).sum();
            worst = worst.max((vi - r * a[i]).abs());
        }
        // Force: the wrench F = rf a (zero beyond the first K rows) needs |Jᵀ F| = 1.
        let mut wrench = [0.0; 6];
        for i in 0..K {
            wrench[i] = f.radii[k] * f.axes[k][i];
        }
        let tau = wrench_to_torque(jac, &wrench);
        let norm: f64 = tau.iter().map(|x| x * x).sum::<f64>().sqrt();
        worst = worst.max((norm - 1.0).abs());
    }
    worst
}

macro_rules! manipulability {
    ($robot:expr, $link:expr, $states:expr) => {{
        let robot = $robot;
        let mut worst: f64 = 0.0;
        for q in $states {
            let jac = robot.link_jacobian($link, &q);
            let (v3, f3) = (
                Ellipsoid::velocity_translational(&jac),
                Ellipsoid::force_translational(&jac),
            );
            worst = worst.max(check_duality(&jac, &v3, &f3));
            let (v6, f6) = (Ellipsoid::velocity(&jac), Ellipsoid::force(&jac));
            worst = worst.max(check_duality(&jac, &v6, &f6));
            // Yoshikawa's measure sqrt(det(Jv Jvᵀ)) is the product of the velocity radii.
            assert!(v3.radii_product() > 0.0);
        }
        worst
    }};
}

#[test]
fn manipulability_ellipsoids_are_dual() {
    let ur5 = manipulability!(
        Ur5::<f64>::default(),
        Ur5Link::Tool0,
        [
            [0.1, -1.2, 1.4, -1.0, -1.5, 0.3],
            [1.0, -0.6, 0.9, 0.4, 1.1, -0.7],
            [-2.0, -1.9, 2.2, -2.5, 0.6, 2.0],
        ]
    );
    let panda = manipulability!(
        Panda::<f64>::default(),
        PandaLink::PandaHandTcp,
        [
            [0.0, -0.5, 0.0, -2.0, 0.0, 1.5, 0.8, 0.02, 0.02],
            [0.7, 0.3, -0.6, -1.4, 0.9, 2.1, -1.2, 0.01, 0.03],
            [-1.5, 1.0, 1.2, -2.6, -2.0, 0.5, 2.0, 0.0, 0.0],
        ]
    );
    eprintln!("manipulability duality: worst deviation ur5 {ur5:.3e}, panda {panda:.3e}");
    assert!(ur5 < 1e-10 && panda < 1e-10);
}

/// `tau = Jᵀ F` is the effort that exerts `F`: its power with any joint velocity equals the
/// wrench's power with the resulting twist.
#[test]
fn wrench_torque_is_power_consistent() {
    let robot = Ur5::<f64>::default();
    let q = [0.3, -1.0, 1.2, -0.4, 0.8, 0.1];
    let qd = [0.5, -0.2, 0.9, 1.1, -0.7, 0.3];
    let jac = robot.link_jacobian(Ur5Link::Tool0, &q);
    let wrench = [3.0, -1.0, 2.0, 0.5, -0.25, 0.75];
    let tau = wrench_to_torque(&jac, &wrench);
    let joint_power: f64 = (0..6).map(|j| tau[j] * qd[j]).sum();
    let twist: [f64; 6] = core::array::from_fn(|r| (0..6).map(|j| jac[r][j] * qd[j]).sum());
    let task_power: f64 = (0..6).map(|r| wrench[r] * twist[r]).sum();
    assert!((joint_power - task_power).abs() < 1e-12);
}

/// PD with gravity compensation regulates the panda to a constant target (Takegaki-Arimoto):
/// from 0.1 rad (2 mm on the fingers) off, the error is below 1e-5 after 6 s.
#[test]
fn panda_pd_gravity_regulates() {
    let robot = Panda::<f64>::default();
    let target = Setpoint::hold([0.2, -0.3, 0.1, -1.8, 0.2, 1.6, 0.5, 0.02, 0.02]);
    let initial = State::at_rest(core::array::from_fn(|i| {
        target.q[i] + if i < 7 { 0.1 } else { 0.002 }
    }));
    // Gains scaled to each joint's inertia: the wrist and the gram-weight fingers need soft
    // damping, or their fast closed-loop poles leave RK4's stability region at 1 ms steps.
    let pd = PdGravity {
        kp: [100.0, 100.0, 100.0, 100.0, 20.0, 20.0, 10.0, 10.0, 10.0],
        kd: [10.0, 10.0, 10.0, 10.0, 2.0, 2.0, 1.0, 0.2, 0.2],
    };
    let mut sim = Simulator::new(&robot, Integrator::Rk4, initial, 1e-3);
    let end = sim.run(6000, |_t, s| pd.torque(&robot, s, &target));
    let err = (0..9).fold(0.0_f64, |m, i| m.max((end.q[i] - target.q[i]).abs()));
    let start = (0..9).fold(0.0_f64, |m, i| m.max((initial.q[i] - target.q[i]).abs()));
    eprintln!("panda PD + gravity: max |q - q*| {start:.3e} at 0 s, {err:.3e} after 6 s");
    assert!(end.is_finite() && start > 0.05);
    assert!(err < 1e-5, "regulation error {err:e}");
}

/// The runtime is generic over the scalar: computed torque on the ur5 in f32 converges too.
#[test]
fn ur5_computed_torque_in_f32() {
    let robot = Ur5::<f32>::default();
    let target = Setpoint::hold([0.3_f32, -1.0, 1.2, -0.8, -1.3, 0.5]);
    let initial = State::at_rest([0.1_f32, -1.2, 1.4, -1.0, -1.5, 0.3]);
    let ct = ComputedTorque::critically_damped([10.0_f32; 6]);
    let mut sim = Simulator::new(&robot, Integrator::SemiImplicitEuler, initial, 1e-3);
    let end = sim.run(3000, |_t, s| ct.torque(&robot, s, &target));
    assert!(end.is_finite());
    let err = (0..6).fold(0.0_f32, |m, i| m.max((end.q[i] - target.q[i]).abs()));
    eprintln!(
        "ur5 computed torque in f32, semi-implicit Euler: max |q - q*| after 3 s = {err:.3e}"
    );
    assert!(err < 1e-4, "f32 error {err:e}");
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Simulation steps, controllers and ellipsoids never touch the heap.
#[test]
fn simulation_and_control_do_not_allocate() {
    let robot = Panda::<f64>::default();
    let target = Setpoint::hold([0.0, -0.5, 0.0, -2.0, 0.0, 1.5, 0.8, 0.02, 0.02]);
    let ct = ComputedTorque::critically_damped([20.0; 9]);
    let pd = PdGravity {
        kp: [50.0; 9],
        kd: [5.0; 9],
    };
    let made = allocations(|| {
        let mut sim = Simulator::new(&robot, Integrator::Rk4, State::at_rest(target.q), 1e-3);
        sim.run(5, |_t, s| ct.torque(&robot, s, &target));
        sim.run_continuous(5, |_t, s| pd.torque(&robot, s, &target));
        sim.integrator = Integrator::SemiImplicitEuler;
        sim.run(5, |_t, s| pd.torque(&robot, s, &target));
        let jac = robot.link_jacobian(PandaLink::PandaHandTcp, &sim.state.q);
        black_box(Ellipsoid::velocity(black_box(&jac)));
        black_box(Ellipsoid::force_translational(black_box(&jac)));
        black_box(wrench_to_torque(&jac, &[1.0; 6]));
        black_box(sim.state);
    });
    assert_eq!(made, 0);
}

/// Armature and friction: on the ur5, inverse and forward dynamics stay inverse to each other,
/// the mass matrix gains the armature on its diagonal and inverse dynamics the friction; a
/// damped passive double pendulum loses energy at the rate `qdᵀ K qd`.
#[test]
fn armature_and_friction() {
    let robot = WithJointEffects {
        robot: Ur5::<f64>::default(),
        armature: [0.5, 0.5, 0.4, 0.1, 0.1, 0.1],
        viscous: [2.0, 2.0, 1.0, 0.5, 0.5, 0.5],
        coulomb: [1.0, 1.0, 0.8, 0.3, 0.3, 0.3],
    };
    let (q, qd, qdd) = (
        [0.3, -1.0, 1.2, -0.4, 0.8, 0.1],
        [0.5, -0.2, 0.9, 1.1, -0.7, 0.3],
        [1.0, -2.0, 0.5, 0.0, 3.0, -1.0],
    );
    let tau = robot.inverse_dynamics(&q, &qd, &qdd);
    let back = robot.forward_dynamics(&q, &qd, &tau);
    for i in 0..6 {
        assert!((back[i] - qdd[i]).abs() < 1e-9, "joint {i}");
    }
    let (m, m0) = (robot.mass_matrix(&q), robot.robot.mass_matrix(&q));
    for i in 0..6 {
        for j in 0..6 {
            let extra = if i == j { robot.armature[i] } else { 0.0 };
            assert!((m[i][j] - m0[i][j] - extra).abs() < 1e-15);
        }
    }
    let plain = robot.robot.inverse_dynamics(&q, &qd, &qdd);
    for i in 0..6 {
        let want = plain[i]
            + robot.armature[i] * qdd[i]
            + robot.viscous[i] * qd[i]
            + robot.coulomb[i] * qd[i].signum();
        assert!((tau[i] - want).abs() < 1e-12);
    }

    let damped = WithJointEffects {
        robot: DoublePendulum::<f64>::default(),
        armature: [1e-3, 1e-3],
        viscous: [2e-3, 1e-3],
        coulomb: [0.0, 0.0],
    };
    let mut sim = Simulator::new(
        &damped,
        Integrator::Rk4,
        State::new([1.8, 1.2], [1.0, 2.0]),
        1e-4,
    );
    let mut e = sim.state.energy(&damped);
    for _ in 0..2000 {
        let qd = sim.state.qd;
        sim.step(&[0.0; 2]);
        let e_next = sim.state.energy(&damped);
        let qd_mid: [f64; 2] = core::array::from_fn(|i| 0.5 * (qd[i] + sim.state.qd[i]));
        // dE/dt = -qdᵀ K qd, to the order of the step.
        let rate = -(0..2)
            .map(|i| damped.viscous[i] * qd_mid[i] * qd_mid[i])
            .sum::<f64>();
        assert!(e_next <= e + 1e-12);
        assert!(((e_next - e) / 1e-4 - rate).abs() < 1e-3 * rate.abs().max(1e-3));
        e = e_next;
    }
}
