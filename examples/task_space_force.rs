//! Task-space force: the joint torques that make the hand push with a force, `tau = J^T F`.
//!
//! `link_jacobian` gives the hand's 6 x 7 Jacobian (rows vx, vy, vz, wx, wy, wz in world axes)
//! and the runtime's `wrench_to_torque` maps a wrench `F` (force in N, moment in N m) to the
//! static joint torques that exert it; adding `G(q)` also holds the arm's weight. The example
//! checks the result by virtual work: moving joint `i` by a small `dq` moves the hand by `dx`,
//! and `tau_i dq` must equal `F . dx`.
//!
//! Run it with `cargo run --example task_space_force`.

use eomgen_examples::{PandaArm, PandaArmLink, READY};
use eomgen_runtime::prelude::*;
use eomgen_runtime::wrench_to_torque;

fn main() {
    let robot = PandaArm::<f64>::default();
    let hand = PandaArmLink::PandaHand;
    let q = READY;
    // Press down on a table with 20 N.
    let wrench = [0.0, 0.0, -20.0, 0.0, 0.0, 0.0];
    let jacobian = robot.link_jacobian(hand, &q);
    let tau_force = wrench_to_torque(&jacobian, &wrench);
    let gravity = robot.gravity(&q);
    println!("joint            J^T F (N m)   + G(q) (N m)   virtual work check");
    let h = 1e-6;
    let mut worst = 0.0_f64;
    for (i, name) in PandaArm::<f64>::JOINT_NAMES.iter().enumerate() {
        // dx of the hand for a small motion of joint i alone, from the poses.
        let mut moved = q;
        moved[i] += h;
        let (a, b) = (robot.link_pose(hand, &q), robot.link_pose(hand, &moved));
        let work: f64 = (0..3)
            .map(|k| wrench[k] * (b.translation[k] - a.translation[k]) / h)
            .sum();
        worst = worst.max((work - tau_force[i]).abs());
        println!(
            "{name:14} {:13.4}   {:12.4}   {work:18.4}",
            tau_force[i],
            tau_force[i] + gravity[i]
        );
    }
    println!("largest virtual-work mismatch: {worst:.1e} N m");
    assert!(worst < 1e-4, "J^T F disagrees with virtual work by {worst}");
}
