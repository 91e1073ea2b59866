//! Computed-torque control of a 7-joint arm in simulation.
//!
//! `PandaArm` is generated from a URDF by this crate's `build.rs`. The controller computes
//! `tau = M(q) (Kp e - Kd qd) + b(q, qd) + G(q)` with one `inverse_dynamics` call, and the
//! simulator integrates the arm's forward dynamics with RK4. With an exact model every joint's
//! error decays like a critically damped spring, whatever the arm's configuration.
//!
//! Run it with `cargo run --example computed_torque`.

use eomgen_examples::{PandaArm, READY};
use eomgen_runtime::prelude::*;
use eomgen_runtime::{ComputedTorque, Integrator, Setpoint, Simulator, State};

fn main() {
    let robot = PandaArm::<f64>::default();
    let target = Setpoint::hold([0.5, 0.2, -0.3, -1.8, 0.4, 1.6, 0.0]);
    // Bandwidth 10 rad/s: Kp = 100 1/s^2, Kd = 20 1/s.
    let controller = ComputedTorque::critically_damped([10.0; 7]);
    let mut sim = Simulator::new(&robot, Integrator::Rk4, State::at_rest(READY), 1e-3);
    println!("t (s)   max |q - q*| (rad)   max |tau| (N m)   kinetic energy (J)");
    let mut error = f64::INFINITY;
    for _ in 0..10 {
        let state = sim.run(100, |_t, s| controller.torque(&robot, s, &target));
        let tau = controller.torque(&robot, &state, &target);
        error = max_abs_difference(&state.q, &target.q);
        let effort = tau.iter().fold(0.0_f64, |m, t| m.max(t.abs()));
        let energy = robot.kinetic_energy(&state.q, &state.qd);
        println!(
            "{:5.1}   {error:18.6}   {effort:15.3}   {energy:18.6}",
            sim.time()
        );
    }
    // A critically damped error at 10 rad/s shrinks by (1 + 10 t) e^(-10 t): 5e-4 at t = 1 s.
    let initial = max_abs_difference(&READY, &target.q);
    assert!(error < 1e-3 * initial, "the arm did not converge: {error}");
    println!("converged: error {error:.2e} rad after {} s", sim.time());
}

fn max_abs_difference(a: &[f64; 7], b: &[f64; 7]) -> f64 {
    a.iter().zip(b).fold(0.0, |m, (x, y)| m.max((x - y).abs()))
}
