//! eomgen: symbolic equations of motion for robots.
//!
//! eomgen reads a robot's URDF, derives its rigid-body dynamics with its own small computer
//! algebra system ([`cas`]) and emits allocation-free `no_std` Rust that the
//! `eomgen-runtime` crate supports.
//!
//! The pipeline, one module per stage:
//! [`urdf`] (the only module that sees XML) → [`model`] (kinematic tree, merged fixed links) →
//! [`kinematics`] and [`dynamics`] (closed-form expressions in the [`cas`]) → emission.

// Matrix code reads best with explicit indices.
#![allow(clippy::needless_range_loop)]

pub mod cas;
pub mod dynamics;
pub mod kinematics;
pub mod model;
pub mod urdf;
