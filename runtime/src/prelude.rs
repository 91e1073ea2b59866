//! Everything code that uses a generated robot needs in scope, in one line:
//!
//! ```
//! use eomgen_runtime::prelude::*;
//! ```
//!
//! It brings [`Dynamics`] (the trait every generated robot implements, so that
//! `robot.mass_matrix(&q)` resolves), [`Hamiltonian`] (`robot.momentum(&q, &qd)`,
//! `robot.hamilton(&q, &p, &tau)` on every robot that implements `Dynamics`), [`Real`] (the
//! scalar trait, for code generic over `f32` and `f64`), and the types generated methods return: [`Pose`] (from `link_pose`),
//! [`FactorError`] (from `try_forward_dynamics`), [`LaneError`] (from
//! `try_forward_dynamics_lanes`) and [`BatchError`] (from the `_batch` methods); for floating-base robots
//! [`FloatingDynamics`] and, with contact points, [`Contacts`] (and the derivatives' types
//! [`ContactDynamicsDerivatives`], [`ImpulseDynamicsDerivatives`], and [`Baumgarte`], the
//! stabilization `contact_forward_dynamics_stabilized` takes, and [`TreePasses`], which robots
//! with contact or impulse derivatives implement with their unrolled solves); and
//! [`Dimensions`] (`DOF`, `NQ`, `NV` for any scalar type).
//!
//! The prelude is part of the public API: items are added to it only in minor versions and
//! never removed outside a major one.

pub use crate::batch::BatchError;
pub use crate::tree::TreePasses;
pub use crate::{
    Baumgarte, ContactDynamicsDerivatives, Contacts, Dimensions, Dynamics, FactorError,
    FloatingDynamics, Hamiltonian, ImpulseDynamicsDerivatives, LaneError, Pose, Real,
};
