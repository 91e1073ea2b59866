//! What a model-predictive controller evaluates per node besides the dynamics (issue 29):
//! link frames' velocities, classical accelerations and Jacobian time variations (run-time
//! walks along each link's chain, as `link_jacobian`), the configuration manifold
//! (`difference` and the Jacobians of `integrate` and `difference`, run-time kernels), and a
//! floating base's centroidal momentum rate (straight-line code).
//!
//! Conventions are Pinocchio's `LOCAL_WORLD_ALIGNED`: a spatial vector is [linear (3),
//! angular (3)] at the frame's origin, in world axes.

use super::catalogue::{Evaluation, Input, Quantity, Shape};
use super::centroidal::quantity;
use super::newton_euler::JointTree;
use super::newton_euler::{self, Terms};
use super::Derivation;
use crate::cas::Id;
use crate::kinematics::{cross, joint, mat_vec, vec_add, vec_sub};
use crate::model::Model;

/// A link frame's motion, from a walk along its chain at run time (`eomgen_runtime::frame`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameMotion {
    /// `link_velocity`.
    Velocity,
    /// `link_acceleration` (classical).
    Acceleration,
    /// `link_jacobian_time_variation`.
    JacobianTimeVariation,
}

/// A function of the configuration manifold (`eomgen_runtime::manifold`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Manifold {
    /// `difference(q0, q1)`.
    Difference,
    /// `integrate_jacobians(q, v)`.
    IntegrateJacobians,
    /// `difference_jacobians(q0, q1)`.
    DifferenceJacobians,
}

/// Appends the kit's entries to the catalogue of `d` (after the centroidal quantities and
/// `integrate`), deriving the centroidal momentum rate of a floating base.
pub(super) fn add(d: &mut Derivation, model: &Model) {
    let rate = model
        .is_floating()
        .then(|| centroidal_momentum_rate(d, model));
    let n = d.dof;
    let mut out = frame_motions(n);
    out.extend(manifold(model, n));
    if let Some(rate) = rate {
        out.push(quantity(
            "centroidal_momentum_rate",
            &[Input::Q, Input::Qd, Input::Qdd],
            Shape::Vector(6),
            &[
                "The rate of the centroidal momentum, `dh/dt = A_g qdd + dA_g/dt qd`: the rate of the linear",
                "momentum, then of the angular momentum about the centre of mass, world axes (Pinocchio's",
                "`computeCentroidalMomentumTimeVariation`, its `dhg`).",
            ],
            "Newton-Euler without gravity gives the base's rows, the rate of the robot's momentum at the base origin in base axes, moved to the world and the centre of mass",
            Evaluation::Exprs(rate),
        ));
    }
    d.quantities.extend(out);
}

/// `dh_G/dt`: Newton-Euler without gravity; its base rows are the rate of the momentum
/// (force, then torque about the base origin, base axes), since every body's `I a + v x* I v`
/// is the rate of its momentum. In world axes `F = R f`, and about the (moving) centre of mass
/// `N_G = R n + (p - c) x F` (the centre of mass moves along the momentum).
fn centroidal_momentum_rate(d: &mut Derivation, model: &Model) -> Vec<Id> {
    let g = &mut d.graph;
    // The same nodes as the derivation's (the graph is hash-consed).
    let JointTree { map, lm, .. } = JointTree::new(g, model, &d.q);
    let qd = map.rates(g, &d.qd);
    let qdd = map.rates(g, &d.qdd);
    let terms = Terms {
        qd: Some(&qd),
        qdd: Some(&qdd),
        gravity: None,
    };
    let tau = newton_euler::rnea(g, &lm, terms);
    let base = joint::free_flyer_placement(g, &d.q[..7]);
    let force = mat_vec(g, &base.rotation, &[tau[0], tau[1], tau[2]]);
    let moment = mat_vec(g, &base.rotation, &[tau[3], tau[4], tau[5]]);
    let lever = vec_sub(g, &base.translation, &d.centroidal.com);
    let shift = cross(g, &lever, &force);
    let about_com = vec_add(g, &moment, &shift);
    force.into_iter().chain(about_com).collect()
}

/// `link_velocity`, `link_acceleration` and `link_jacobian_time_variation`.
fn frame_motions(n: usize) -> Vec<Quantity> {
    let walk = "each body's pose, velocity and acceleration walked along the link's chain from the same transforms as `link_pose` (eomgen_runtime::frame)";
    vec![
        quantity(
            "link_velocity",
            &[Input::Q, Input::Qd],
            Shape::Vector(6),
            &["The spatial velocity of a link frame: the velocity of its origin, then its angular velocity,", "world axes (Pinocchio's `getFrameVelocity`, LOCAL_WORLD_ALIGNED); `link_jacobian` times `qd`."],
            walk,
            Evaluation::FrameMotion(FrameMotion::Velocity),
        ),
        quantity(
            "link_acceleration",
            &[Input::Q, Input::Qd, Input::Qdd],
            Shape::Vector(6),
            &["The classical acceleration of a link frame: the acceleration of its origin, then its angular", "acceleration, world axes (Pinocchio's `getFrameClassicalAcceleration`, LOCAL_WORLD_ALIGNED);", "`J qdd + dJ/dt qd`."],
            walk,
            Evaluation::FrameMotion(FrameMotion::Acceleration),
        ),
        quantity(
            "link_jacobian_time_variation",
            &[Input::Q, Input::Qd],
            Shape::Matrix(6, n),
            &["The time derivative of `link_jacobian` at velocity `qd`, 6 x N, rows as `link_jacobian`", "(Pinocchio's `getFrameJacobianTimeVariation`, LOCAL_WORLD_ALIGNED)."],
            walk,
            Evaluation::FrameMotion(FrameMotion::JacobianTimeVariation),
        ),
    ]
}

/// `difference`, `integrate_jacobians` and `difference_jacobians`.
fn manifold(model: &Model, n: usize) -> Vec<Quantity> {
    let (space, kernels) = if model.is_floating() {
        (
            "The base moves along the SE(3) exponential (`integrate(q, v, 1) = q exp6(v)`), the joints as a vector space.",
            "the base's block in closed form (SE(3) logarithm, adjoint, right Jacobian of exp6 and its inverse), identity for the joints (eomgen_runtime::manifold)",
        )
    } else if !model.velocities_are_rates() {
        (
            "Each floating joint moves along the SE(3) exponential (its block of `integrate(q, v, 1)` is `q_j exp6(v_j)`), the other joints as a vector space.",
            "each floating joint's block in closed form (SE(3) logarithm, adjoint, right Jacobian of exp6 and its inverse), identity for the other joints (eomgen_runtime::manifold, the `_blocks` kernels)",
        )
    } else {
        (
            "The configurations of a fixed base form a vector space.",
            "the vector space's (eomgen_runtime::manifold)",
        )
    };
    let jacobians = Shape::Matrices(2, n, n);
    vec![
        quantity(
            "difference",
            &[Input::Q, Input::Q],
            Shape::Vector(n),
            &["`difference(q0, q1)`: the velocity that moves `q0` to `q1` in unit time, so that", "`integrate(q0, difference(q0, q1), 1) = q1` (Pinocchio's `difference`). A floating base's", "quaternions may have either sign.", "", space],
            kernels,
            Evaluation::Manifold(Manifold::Difference),
        ),
        quantity(
            "integrate_jacobians",
            &[Input::Q, Input::Qd],
            jacobians,
            &["The Jacobians of `integrate(q, v, 1)` in `q` and in `v`, q perturbed in its tangent space", "(Pinocchio's `dIntegrate`, ARG0 and ARG1); element `[i][j]` = d out_i / d in_j.", "", space],
            kernels,
            Evaluation::Manifold(Manifold::IntegrateJacobians),
        ),
        quantity(
            "difference_jacobians",
            &[Input::Q, Input::Q],
            jacobians,
            &["The Jacobians of `difference(q0, q1)` in `q0` and in `q1`, both perturbed in their tangent", "spaces (Pinocchio's `dDifference`, ARG0 and ARG1); element `[i][j]` = d out_i / d in_j.", "", space],
            kernels,
            Evaluation::Manifold(Manifold::DifferenceJacobians),
        ),
    ]
}
