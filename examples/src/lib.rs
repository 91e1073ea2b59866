//! The robot of eomgen's examples: the Franka Emika Panda arm, 7 revolute joints with the
//! gripper held closed, generated from `robots/panda_arm.urdf` by this crate's `build.rs`.
//!
//! Run the examples from the repository root:
//!
//! ```sh
//! cargo run --example computed_torque       # track a joint target in simulation (f64)
//! cargo run --example gravity_compensation  # hold a pose against gravity (f32)
//! cargo run --example task_space_force      # push with the hand: tau = J^T F
//! cargo run --example quadruped_stand       # a floating-base quadruped standing on its feet
//! cargo run --example quadruped_mpc         # an MPC step (iLQR) lifting a foot of the quadruped
//! cargo run --example identify              # base inertial parameters of a UR5 from noisy torques
//! cargo run --release --example mppi_rollout  # MPPI rollouts: scalar vs batch (SIMD lanes, threads)
//! cargo run --release --example mppi_quadruped  # MPPI of the quadruped on its feet, in batches
//! ```
//!
//! `Ur5` (6 joints, `robots/ur5.urdf`) is generated with identification: `regressor`,
//! `parameters`, `base_regressor` and `base_parameters`.
//!
//! ```
//! use eomgen_examples::{PandaArm, PandaArmLink};
//! use eomgen_runtime::prelude::*;
//!
//! let robot = PandaArm::<f64>::default();
//! let q = [0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.8];
//! let hand: Pose<f64> = robot.link_pose(PandaArmLink::PandaHand, &q);
//! assert!(hand.translation[2] > 0.3);
//! assert_eq!(PandaArm::<f64>::JOINT_NAMES.len(), 7);
//! ```

#![no_std]

include!(concat!(env!("OUT_DIR"), "/panda_arm.rs"));

/// ANYmal, a quadruped, with a floating base and a point contact at each foot (`LF_FOOT`,
/// `RF_FOOT`, `LH_FOOT`, `RH_FOOT`, in that order), generated from the workspace's
/// `tests/robots/floating/anymal.urdf`.
pub mod anymal {
    include!(concat!(env!("OUT_DIR"), "/anymal.rs"));

    /// A standing configuration: base 0.5 m above the ground, level; knees bent.
    pub const STANDING: [f64; 19] = [
        0.0, 0.0, 0.5, 0.0, 0.0, 0.0, 1.0, // base position, quaternion x y z w
        0.0, 0.6, -1.2, 0.0, -0.6, 1.2, 0.0, 0.6, -1.2, 0.0, -0.6, 1.2, // LF, LH, RF, RH
    ];
}

/// ANYmal again, generated with only what an MPC step calls (`Builder::quantities`): contact
/// forward dynamics and its derivatives for a set of active feet (the same feet, in the same
/// order), `integrate`, `difference` and their Jacobians.
pub mod anymal_mpc {
    include!(concat!(env!("OUT_DIR"), "/anymal_mpc.rs"));
}

/// The UR5 arm with identification, generated from `robots/ur5.urdf`.
pub mod ur5 {
    include!(concat!(env!("OUT_DIR"), "/ur5.rs"));
}
pub use ur5::Ur5;

/// A comfortable start configuration (rad): elbow bent, hand pointing down.
pub const READY: [f64; 7] = [0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.8];
