//! Joint friction and rotor inertia in compiled generated code (`fixtures/joint_effects.urdf`,
//! generated three ways by the build script): the friction term against hand values, the
//! generated effects against the runtime's `WithJointEffects` over the rigid robot, inverse and
//! forward dynamics inverting each other, and a damped simulation losing energy at every step.

#![allow(clippy::needless_range_loop)]

use eomgen_runtime::{Dynamics, Integrator, Simulator, State, WithJointEffects};
use eomgen_tests::robots::joint_effects::JointEffects;
use eomgen_tests::robots::joint_effects_full::JointEffectsFull;
use eomgen_tests::robots::joint_effects_smooth::JointEffectsSmooth;

/// shoulder, elbow: rotor inertia, damping and Coulomb friction, as the build script and the
/// URDF give them.
const ARMATURE: [f64; 2] = [0.2, 0.05];
const DAMPING: [f64; 2] = [0.5, 0.1];
const COULOMB: [f64; 2] = [0.2, 0.05];

/// Deterministic states, with a joint at rest in the first.
fn states() -> Vec<([f64; 2], [f64; 2], [f64; 2])> {
    let mut x = 0.61_f64;
    let mut next = move || {
        x = (x * 5.77 + 0.137).fract();
        4.0 * x - 2.0
    };
    let mut out: Vec<_> = (0..8)
        .map(|_| ([next(), next()], [next(), next()], [next(), next()]))
        .collect();
    out[0].1[1] = 0.0;
    out
}

#[test]
fn friction_matches_hand_values() {
    let full = JointEffectsFull::<f64>::default();
    assert_eq!(full.friction(&[1.0, -2.0]), [0.5 + 0.2, -0.2 - 0.05]);
    assert_eq!(full.friction(&[-0.3, 0.0]), [-0.15 - 0.2, 0.0]);
    assert_eq!(full.friction(&[0.0, 0.0]), [0.0, 0.0]);
    // Smoothed: s(v) = v / sqrt(v^2 + 0.05^2).
    let smooth = JointEffectsSmooth::<f64>::default().friction(&[0.05, -0.2]);
    let want = [
        0.5 * 0.05 + 0.2 * 0.05 / (2.0 * 0.0025_f64).sqrt(),
        0.1 * -0.2 + 0.05 * -0.2 / (0.04_f64 + 0.0025).sqrt(),
    ];
    for i in 0..2 {
        assert!(
            (smooth[i] - want[i]).abs() < 1e-15,
            "{smooth:?} != {want:?}"
        );
    }
    // In f32 too.
    let f = JointEffectsFull::<f32>::default().friction(&[1.0, -2.0]);
    assert!((f[0] - 0.7).abs() < 1e-6 && (f[1] + 0.25).abs() < 1e-6);
}

#[test]
fn generated_effects_equal_the_runtime_wrapper() {
    let full = JointEffectsFull::<f64>::default();
    let wrapped = WithJointEffects {
        robot: JointEffects::<f64>::default(),
        armature: ARMATURE,
        viscous: DAMPING,
        coulomb: COULOMB,
    };
    let close = |a: f64, b: f64, what: &str| {
        assert!(
            (a - b).abs() <= 1e-12 * b.abs().max(1.0),
            "{what}: {a} vs {b}"
        );
    };
    for (q, qd, qdd) in states() {
        let (m, mw) = (full.mass_matrix(&q), wrapped.mass_matrix(&q));
        let rigid = JointEffects::<f64>::default().mass_matrix(&q);
        for i in 0..2 {
            for j in 0..2 {
                close(m[i][j], mw[i][j], "M");
                // Exactly the rotor inertia on the diagonal, nothing elsewhere.
                let extra = if i == j { ARMATURE[i] } else { 0.0 };
                assert!((m[i][j] - rigid[i][j] - extra).abs() < 1e-15);
            }
        }
        let tau = full.inverse_dynamics(&q, &qd, &qdd);
        let tau_w = wrapped.inverse_dynamics(&q, &qd, &qdd);
        let tau_in = [0.3, -0.7];
        let (a, aw) = (
            full.forward_dynamics(&q, &qd, &tau_in),
            wrapped.forward_dynamics(&q, &qd, &tau_in),
        );
        let (f, fw) = (full.friction(&qd), wrapped.friction(&qd));
        let (b, bw) = (full.bias(&q, &qd), wrapped.bias(&q, &qd));
        for i in 0..2 {
            close(tau[i], tau_w[i], "inverse dynamics");
            close(a[i], aw[i], "forward dynamics");
            close(f[i], fw[i], "friction");
            close(b[i], bw[i], "bias (no friction in it)");
        }
        close(
            full.kinetic_energy(&q, &qd),
            wrapped.kinetic_energy(&q, &qd),
            "kinetic energy",
        );
        close(
            full.potential_energy(&q),
            wrapped.potential_energy(&q),
            "potential energy",
        );
    }
}

/// `forward_dynamics(inverse_dynamics(qdd)) = qdd` with friction on, exact and smoothed.
fn round_trip<D: Dynamics<f64, 2>>(robot: &D) -> f64 {
    let mut worst: f64 = 0.0;
    for (q, qd, qdd) in states() {
        let tau = robot.inverse_dynamics(&q, &qd, &qdd);
        let back = robot.forward_dynamics(&q, &qd, &tau);
        for i in 0..2 {
            worst = worst.max((back[i] - qdd[i]).abs());
        }
    }
    worst
}

#[test]
fn inverse_and_forward_dynamics_invert_each_other_with_friction() {
    let exact = round_trip(&JointEffectsFull::<f64>::default());
    let smooth = round_trip(&JointEffectsSmooth::<f64>::default());
    eprintln!("round trip with friction: exact sign {exact:.1e}, smoothed {smooth:.1e} rad/s^2");
    assert!(exact < 1e-12 && smooth < 1e-12);
    // Friction shows: the same effort accelerates the rigid robot (with the same rotor
    // inertia) differently.
    let full = JointEffectsFull::<f64>::default();
    let (q, qd) = ([0.3, 0.4], [1.0, -2.0]);
    let tau = full.inverse_dynamics(&q, &qd, &[0.0, 0.0]);
    let rigid = WithJointEffects {
        robot: JointEffects::<f64>::default(),
        armature: ARMATURE,
        viscous: [0.0; 2],
        coulomb: [0.0; 2],
    };
    let rigid_tau = rigid.inverse_dynamics(&q, &qd, &[0.0, 0.0]);
    assert!((tau[0] - rigid_tau[0] - 0.7).abs() < 1e-12);
    assert!((tau[1] - rigid_tau[1] + 0.25).abs() < 1e-12);
    assert!(full.try_forward_dynamics(&q, &qd, &tau).is_ok());
}

/// Passive motion from near hanging with RK4 at 1 ms for 10 s: returns the energy at the start
/// and end and the largest increase over one step.
fn passive<D: Dynamics<f64, 2>>(robot: &D) -> (f64, f64, f64) {
    let start = State::new([2.2, -0.8], [0.0, 1.5]);
    let mut sim = Simulator::new(robot, Integrator::Rk4, start, 1e-3);
    let e0 = start.energy(robot);
    let (mut e, mut worst_rise) = (e0, f64::NEG_INFINITY);
    for _ in 0..10_000 {
        sim.step(&[0.0; 2]);
        let next = sim.state.energy(robot);
        worst_rise = worst_rise.max(next - e);
        e = next;
    }
    assert!(sim.state.is_finite());
    (e0, e, worst_rise)
}

#[test]
fn damping_loses_energy_at_every_step() {
    // Smoothed Coulomb friction: dE/dt = -qd^T F(qd) < 0 whenever the arm moves.
    let (e0, end, rise) = passive(&JointEffectsSmooth::<f64>::default());
    eprintln!(
        "smoothed friction: E {e0:.6} J -> {end:.6} J after 10 s ({:.4} % of the energy above \
         hanging still lost), largest one-step change {rise:.2e} J",
        100.0 * (e0 - end) / (e0 - passive_floor())
    );
    assert!(rise <= 0.0, "energy rose by {rise:e} J in one step");
    assert!(e0 - end > 1.0, "{e0} -> {end}");
    // Exact sign: the same, up to the integrator's error where a velocity crosses zero and the
    // RK4 stages straddle the discontinuity (measured: a few 1e-9 J, against 6.7 J lost).
    let (e0x, endx, risex) = passive(&JointEffectsFull::<f64>::default());
    eprintln!(
        "exact-sign friction: E {e0x:.6} J -> {endx:.6} J, largest one-step change {risex:.2e} J"
    );
    assert!(risex <= 1e-8, "energy rose by {risex:e} J in one step");
    assert!(e0x - endx > 1.0);
    // Without friction (rotor inertia alone) RK4 keeps the energy.
    let rigid = WithJointEffects {
        robot: JointEffects::<f64>::default(),
        armature: ARMATURE,
        viscous: [0.0; 2],
        coulomb: [0.0; 2],
    };
    let (e0r, endr, _) = passive(&rigid);
    eprintln!("no friction: E {e0r:.9} J -> {endr:.9} J");
    assert!((endr - e0r).abs() < 1e-6 * e0r.abs().max(1.0));
}

/// The potential energy hanging straight down, the least the arm can reach.
fn passive_floor() -> f64 {
    JointEffectsSmooth::<f64>::default().potential_energy(&[std::f64::consts::PI, 0.0])
}
