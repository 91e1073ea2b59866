//! Gravity compensation on `f32`, as on a microcontroller.
//!
//! The same generated `PandaArm`, instantiated as `PandaArm<f32>`: each control tick sends
//! `tau = G(q)`, the torque that holds the arm's weight, so that it floats where it is. Without
//! it the arm falls.
//!
//! Run it with `cargo run --example gravity_compensation`.

use eomgen_examples::{PandaArm, READY};
use eomgen_runtime::prelude::*;
use eomgen_runtime::{Integrator, Simulator, State};

/// Simulates 1 s at a 1 kHz control rate with `torque` and returns the largest joint drift.
fn drift(robot: &PandaArm<f32>, torque: impl Fn(&State<f32, 7>) -> [f32; 7]) -> f32 {
    let start = READY.map(|q| q as f32);
    let mut sim = Simulator::new(robot, Integrator::Rk4, State::at_rest(start), 1e-3);
    let end = sim.run(1000, |_t, s| torque(s));
    end.q
        .iter()
        .zip(&start)
        .fold(0.0, |m, (q, q0)| m.max((q - q0).abs()))
}

fn main() {
    let robot = PandaArm::<f32>::default();
    let q = READY.map(|q| q as f32);
    let g = robot.gravity(&q);
    println!("gravity torques at the ready pose (N m, f32):");
    for (name, tau) in PandaArm::<f32>::JOINT_NAMES.iter().zip(g) {
        println!("  {name:14} {tau:9.4}");
    }
    let held = drift(&robot, |s| robot.gravity(&s.q));
    let fallen = drift(&robot, |_| [0.0; 7]);
    println!("largest joint drift after 1 s: {held:.2e} rad compensated, {fallen:.3} rad without");
    assert!(
        held < 1e-3,
        "gravity compensation let the arm drift by {held} rad"
    );
    assert!(fallen > 0.1, "the uncompensated arm should fall");
}
