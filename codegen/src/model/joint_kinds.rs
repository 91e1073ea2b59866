//! The URDF joint kinds of several coordinates, as the model holds them, and what they cannot
//! be combined with yet.
//!
//! - `planar`: `q = [x, y, theta]`, the child's translation in the joint frame's xy plane,
//!   then its rotation about the joint frame's z axis, with `qd = dq/dt`. That is exactly the
//!   chain of a prismatic joint along x, a prismatic joint along y and a revolute joint about
//!   z ([`planar_steps`]), so the model holds it as those three one-coordinate joints
//!   (`name.x`, `name.y`, `name.theta`, the first two moving massless bodies named after
//!   them, `name.x` and `name.y`, the last the child link's): every algorithm
//!   and the closed Lagrangian forms then apply unchanged. The plane is the joint frame's xy
//!   plane (Pinocchio's reading); another plane comes from the joint origin's rpy.
//! - `floating` below the root: one joint of kind [`JointKind::Floating`] (seven position and
//!   six velocity coordinates, see `kinematics::joint`). A `floating` joint from a massless
//!   root link that has no other joint is the floating base instead
//!   ([`super::ModelOptions::floating_base`]).

use nalgebra::Vector3;

use super::description::{JointType, RobotDescription};
use super::errors::ModelError;
use super::options::ModelOptions;
use super::{JointKind, Model};

/// One elementary joint of a joint kind's chain.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Step {
    /// What the step's name adds to the URDF joint's (`x` gives `name.x`); `None` for a
    /// joint that is its own single step.
    pub(crate) suffix: Option<&'static str>,
    pub(crate) kind: JointKind,
    /// Unit axis in the joint frame.
    pub(crate) axis: Vector3<f64>,
}

/// A planar joint as its chain: translation along the joint frame's x axis, then its y axis,
/// then rotation about its z axis (`q = [x, y, theta]`).
pub(crate) fn planar_steps() -> Vec<Step> {
    vec![
        Step {
            suffix: Some("x"),
            kind: JointKind::Prismatic,
            axis: Vector3::x(),
        },
        Step {
            suffix: Some("y"),
            kind: JointKind::Prismatic,
            axis: Vector3::y(),
        },
        Step {
            suffix: Some("theta"),
            kind: JointKind::Continuous,
            axis: Vector3::z(),
        },
    ]
}

/// Rejects a planar joint whose axis is not the joint frame's z axis (the plane's
/// coordinates would be ambiguous).
pub(crate) fn check_description(robot: &RobotDescription, file: &str) -> Result<(), ModelError> {
    for joint in &robot.joints {
        let a = joint.axis;
        let along_z = a[0] == 0.0 && a[1] == 0.0 && a[2] > 0.0;
        if joint.joint_type == JointType::Planar && !along_z {
            return Err(ModelError::UnsupportedJointUse {
                file: file.into(),
                joint: joint.name.clone(),
                kind: "planar",
                reason: format!(
                    "its axis ({} {} {}) is not 0 0 1: eomgen moves a planar joint in its \
                     frame's xy plane (as Pinocchio); turn the plane with the joint origin's rpy",
                    a[0], a[1], a[2]
                ),
            });
        }
    }
    Ok(())
}

/// Rejects the options that cannot handle a floating joint below the root yet, naming the
/// joint and the option.
pub(crate) fn check_options(
    model: &Model,
    options: &ModelOptions,
    file: &str,
) -> Result<(), ModelError> {
    let Some(&first) = model.floating_joints().first() else {
        return Ok(());
    };
    let joint = &model.joints[first];
    let refuse = |reason: &str| {
        Err(ModelError::UnsupportedJointUse {
            file: file.into(),
            joint: joint.name.clone(),
            kind: "floating (a free flyer below the root)",
            reason: reason.into(),
        })
    };
    let with = |option: &str| format!("{option} is not supported with it yet");
    if model.is_floating() {
        return refuse(&with("a floating base (floating_base)"));
    }
    if options.mimic_joints && model.joints.iter().any(|j| j.mimic.is_some()) {
        return refuse(&with("mimic_joints"));
    }
    if !options.passive_joints.is_empty() {
        return refuse(&with("passive_joints"));
    }
    let contacts = !options.contact_points.is_empty()
        || !options.contact_frames.is_empty()
        || !options.contact_points_at.is_empty();
    if contacts {
        return refuse(&with("contact_points, contact_points_at or contact_frames"));
    }
    for j in model.floating_joints() {
        let joint = &model.joints[j];
        if joint.armature != 0.0 {
            return Err(ModelError::UnsupportedJointUse {
                file: file.into(),
                joint: joint.name.clone(),
                kind: "floating",
                reason: "armature (rotor inertia) applies to joints of one coordinate".into(),
            });
        }
        if options.friction && (joint.damping != 0.0 || joint.friction != 0.0) {
            return Err(ModelError::UnsupportedJointUse {
                file: file.into(),
                joint: joint.name.clone(),
                kind: "floating",
                reason: "its <dynamics> damping and friction are not supported with the \
                         friction option"
                    .into(),
            });
        }
    }
    Ok(())
}
