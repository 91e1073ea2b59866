//! Hamilton's form (`eomgen_runtime::Hamiltonian`, composed from the generated functions)
//! against the Lagrangian form of the compiled reference robots, and the symplectic
//! integrators' energy behaviour over long runs.

#![allow(clippy::needless_range_loop)]

use std::cell::Cell;

use eomgen_runtime::prelude::*;
use eomgen_runtime::{Integrator, State};
use eomgen_tests::robots::{allegro_right_hand, double_pendulum, kinova, panda, ur5};
use eomgen_tests::Lcg;

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// The largest normwise relative error of Hamilton's equations against the Lagrangian form
/// over `samples` random states: `qd = M^-1 p` and `pd = tau - g + C(q, qd)^T qd`, and
/// `H = T + V`.
fn worst_error<R: Dynamics<f64, N>, const N: usize>(robot: &R, samples: usize) -> f64 {
    let mut rng = Lcg(0x5eed + N as u64);
    let mut worst: f64 = 0.0;
    for _ in 0..samples {
        let q: [f64; N] = core::array::from_fn(|_| rng.uniform(-1.5, 1.5));
        let qd: [f64; N] = core::array::from_fn(|_| rng.uniform(-2.0, 2.0));
        let tau: [f64; N] = core::array::from_fn(|_| rng.uniform(-5.0, 5.0));
        let p = robot.momentum(&q, &qd);
        let m = robot.mass_matrix(&q);
        let mqd: Vec<f64> = (0..N)
            .map(|i| (0..N).map(|j| m[i][j] * qd[j]).sum())
            .collect();
        let dp: Vec<f64> = (0..N).map(|i| p[i] - mqd[i]).collect();
        worst = worst.max(norm(&dp) / norm(&mqd));

        let (qd2, pd) = robot.hamilton(&q, &p, &tau);
        let dqd: Vec<f64> = (0..N).map(|i| qd2[i] - qd[i]).collect();
        worst = worst.max(norm(&dqd) / norm(&qd));

        let g = robot.gravity(&q);
        let c = robot.coriolis_matrix(&q, &qd);
        let want: Vec<f64> = (0..N)
            .map(|k| tau[k] - g[k] + (0..N).map(|i| c[i][k] * qd[i]).sum::<f64>())
            .collect();
        let scale = norm(&tau) + norm(&g) + norm(&want);
        let dpd: Vec<f64> = (0..N).map(|k| pd[k] - want[k]).collect();
        worst = worst.max(norm(&dpd) / scale);

        let e = robot.kinetic_energy(&q, &qd) + robot.potential_energy(&q);
        let scale = robot.kinetic_energy(&q, &qd).abs() + robot.potential_energy(&q).abs();
        worst = worst.max((robot.hamiltonian(&q, &p) - e).abs() / scale);
    }
    worst
}

#[test]
fn hamilton_agrees_with_the_lagrangian_form_on_the_reference_robots() {
    let worst = [
        (
            "double_pendulum",
            worst_error(&double_pendulum::DoublePendulum::<f64>::default(), 50),
        ),
        ("ur5", worst_error(&ur5::Ur5::<f64>::default(), 50)),
        ("panda", worst_error(&panda::Panda::<f64>::default(), 50)),
        ("kinova", worst_error(&kinova::Kinova::<f64>::default(), 50)),
        (
            "allegro_right_hand",
            worst_error(&allegro_right_hand::AllegroRightHand::<f64>::default(), 50),
        ),
    ];
    for (name, err) in worst {
        println!("{name}: worst relative error {err:.2e}");
        assert!(err < 1e-12, "{name}: Hamilton's equations off by {err:.2e}");
    }
}

/// `d/dt p` from Hamilton's equations is the derivative of `M(q(t)) qd(t)` along the motion
/// (central differences of the momentum along an RK4 trajectory).
#[test]
fn momentum_rate_is_the_time_derivative_of_the_momentum() {
    let robot = panda::Panda::<f64>::default();
    let tau = [1.0, -2.0, 0.5, 1.5, -0.3, 0.2, 0.1, 0.0, 0.0];
    let s = State::new([0.1, -0.4, 0.2, -1.8, 0.3, 1.2, 0.4, 0.02, 0.02], [0.5; 9]);
    let h = 1e-4;
    let before = eomgen_runtime::rk4_step(&robot, &s, &tau, -h);
    let after = eomgen_runtime::rk4_step(&robot, &s, &tau, h);
    let (pb, pa) = (
        robot.momentum(&before.q, &before.qd),
        robot.momentum(&after.q, &after.qd),
    );
    let (_, pd) = robot.hamilton(&s.q, &robot.momentum(&s.q, &s.qd), &tau);
    for k in 0..9 {
        let fd = (pa[k] - pb[k]) / (2.0 * h);
        assert!(
            (fd - pd[k]).abs() < 1e-6 * (1.0 + pd[k].abs()),
            "{k}: {fd} vs {pd:?}"
        );
    }
}

/// Counts `mass_matrix` calls, one per fixed-point iteration of the implicit midpoint rule
/// (through `hamilton`) plus two per step (the momentum at the start, the velocity at the
/// end).
struct Counting<'a, R> {
    robot: &'a R,
    calls: Cell<u64>,
}

impl<R: Dynamics<f64, 2>> Dynamics<f64, 2> for Counting<'_, R> {
    const JOINT_NAMES: [&'static str; 2] = R::JOINT_NAMES;
    fn mass_matrix(&self, q: &[f64; 2]) -> [[f64; 2]; 2] {
        self.calls.set(self.calls.get() + 1);
        self.robot.mass_matrix(q)
    }
    fn gravity(&self, q: &[f64; 2]) -> [f64; 2] {
        self.robot.gravity(q)
    }
    fn bias(&self, q: &[f64; 2], qd: &[f64; 2]) -> [f64; 2] {
        self.robot.bias(q, qd)
    }
    fn coriolis_matrix(&self, q: &[f64; 2], qd: &[f64; 2]) -> [[f64; 2]; 2] {
        self.robot.coriolis_matrix(q, qd)
    }
    fn inverse_dynamics(&self, q: &[f64; 2], qd: &[f64; 2], qdd: &[f64; 2]) -> [f64; 2] {
        self.robot.inverse_dynamics(q, qd, qdd)
    }
    fn forward_dynamics(&self, q: &[f64; 2], qd: &[f64; 2], tau: &[f64; 2]) -> [f64; 2] {
        self.robot.forward_dynamics(q, qd, tau)
    }
    fn kinetic_energy(&self, q: &[f64; 2], qd: &[f64; 2]) -> f64 {
        self.robot.kinetic_energy(q, qd)
    }
    fn potential_energy(&self, q: &[f64; 2]) -> f64 {
        self.robot.potential_energy(q)
    }
}

/// The worst relative energy error `|E - E0| / |E0|` over `steps` unforced steps, and the
/// final one.
fn energy_error<R: Dynamics<f64, 2>>(
    robot: &R,
    integrator: Integrator,
    start: State<f64, 2>,
    dt: f64,
    steps: usize,
) -> (f64, f64) {
    let e0 = start.energy(robot);
    let mut s = start;
    let mut worst: f64 = 0.0;
    for _ in 0..steps {
        s = integrator.step(robot, &s, &[0.0, 0.0], dt);
        worst = worst.max(((s.energy(robot) - e0) / e0).abs());
    }
    (worst, ((s.energy(robot) - e0) / e0).abs())
}

/// The acceptance of the symplectic integrators (README, "Integrators"): the reference double
/// pendulum released from rest 0.3 rad away from hanging straight down in each joint
/// (`q = (pi + 0.3, -0.3)`; it hangs at `q1 = pi`), 10^5 steps of 3 ms (300 s), no effort.
/// RK4's energy error drifts past 1e-6 relative and keeps growing; the implicit midpoint
/// rule's and Yoshida's fourth-order composition's stay bounded below it.
#[test]
fn symplectic_integrators_keep_the_energy_where_rk4_drifts() {
    let robot = double_pendulum::DoublePendulum::<f64>::default();
    let start = State::new([core::f64::consts::PI + 0.3, -0.3], [0.0, 0.0]);
    let (dt, steps) = (3e-3, 100_000);
    // Four independent runs of 10^5 steps: one thread each.
    let run =
        |integrator| std::thread::spawn(move || energy_error(&robot, integrator, start, dt, steps));
    let (rk4, y4, euler) = (
        run(Integrator::Rk4),
        run(Integrator::Yoshida4),
        run(Integrator::SymplecticEuler),
    );
    let counting = Counting {
        robot: &robot,
        calls: Cell::new(0),
    };
    let (mid, mid_final) = energy_error(&counting, Integrator::ImplicitMidpoint, start, dt, steps);
    let iterations = (counting.calls.get() - 2 * steps as u64) as f64 / steps as f64;
    let joined = |h: std::thread::JoinHandle<(f64, f64)>| h.join().expect("no panic");
    let ((rk4, rk4_final), (y4, y4_final), (euler, euler_final)) =
        (joined(rk4), joined(y4), joined(euler));
    println!("relative energy error over {steps} steps of {dt} s (worst, final):");
    println!("  rk4               {rk4:.3e} {rk4_final:.3e}");
    println!("  implicit-midpoint {mid:.3e} {mid_final:.3e} ({iterations:.2} iterations per step)");
    println!("  yoshida4          {y4:.3e} {y4_final:.3e}");
    println!("  symplectic-euler  {euler:.3e} {euler_final:.3e}");
    assert!(rk4_final > 1e-6, "RK4 drifted only {rk4_final:.3e}");
    assert!(mid < 1e-6, "implicit midpoint: {mid:.3e}");
    assert!(y4 < 1e-6, "Yoshida 4: {y4:.3e}");
    assert!(mid < rk4_final && y4 < rk4_final);
    // First order: bounded, but of order dt.
    assert!(euler < 1e-2, "symplectic Euler: {euler:.3e}");
    assert!(
        (2.0..=12.0).contains(&iterations),
        "{iterations} iterations per step"
    );
}

/// The symplectic steps give NaN, not a panic, when the mass matrix cannot be factorized.
#[test]
fn symplectic_steps_fail_with_nan() {
    let robot = double_pendulum::DoublePendulum::<f64>::default();
    let bad = State::new([f64::NAN, 0.0], [0.0, 0.0]);
    for integrator in [
        Integrator::SymplecticEuler,
        Integrator::ImplicitMidpoint,
        Integrator::Yoshida4,
    ] {
        let s = integrator.step(&robot, &bad, &[0.0, 0.0], 1e-3);
        assert!(!s.is_finite(), "{integrator:?}");
    }
}
