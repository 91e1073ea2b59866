//! eomgen's checked-in output for the five reference robots, a `#![no_std]` crate.
//!
//! Each module is generated from the URDF of the same name in the workspace's `tests/robots/`
//! (beside Pinocchio's reference values for it, which `tests/` checks it against). Do not edit them:
//! `tests/golden.rs` regenerates every file in memory and fails on any difference; refresh
//! them with `EOMGEN_BLESS=1 cargo test -p eomgen-generated --test golden`.
//!
//! ```
//! use eomgen_generated::panda::{Panda, PandaLink};
//! use eomgen_runtime::Dynamics;
//! let robot = Panda::<f64>::default();
//! let q = [0.0; 9];
//! let m = robot.mass_matrix(&q);
//! assert!(m[0][0] > 0.0);
//! let hand = robot.link_pose(PandaLink::PandaHand, &q);
//! assert!(hand.translation[2] > 0.5);
//! ```

#![no_std]

// Formatted by eomgen (prettyplease), not rustfmt: the golden test compares bytes.
#[rustfmt::skip]
pub mod allegro_right_hand;
#[rustfmt::skip]
pub mod double_pendulum;
#[rustfmt::skip]
pub mod iris_simple;
#[rustfmt::skip]
pub mod kinova;
#[rustfmt::skip]
pub mod panda;
#[rustfmt::skip]
pub mod ur5;

/// The floating-base robots of this crate (generated with `Builder::floating_base`): (module,
/// type name, URDF file in the workspace's `tests/robots/`).
pub const FLOATING_ROBOTS: [(&str, &str, &str); 1] =
    [("iris_simple", "IrisSimple", "floating/iris_simple.urdf")];

/// The robots of this crate: (module, type name, URDF file in the workspace's `tests/robots/`).
pub const ROBOTS: [(&str, &str, &str); 5] = [
    ("double_pendulum", "DoublePendulum", "double_pendulum.urdf"),
    ("ur5", "Ur5", "ur5.urdf"),
    ("panda", "Panda", "panda.urdf"),
    ("kinova", "Kinova", "kinova.urdf"),
    (
        "allegro_right_hand",
        "AllegroRightHand",
        "allegro_right_hand.urdf",
    ),
];
