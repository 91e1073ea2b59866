//! An explicit joint order ([`ModelOptions::joint_order`](super::ModelOptions::joint_order)) applied to the merged model.

use super::description::RobotDescription;
use super::errors::ModelError;
use super::mimic::joint_index;
use super::{Body, Joint, Model};

/// Applies an explicit joint order (see [`ModelOptions::joint_order`]).
pub(super) fn reorder(
    model: &mut Model,
    robot: &RobotDescription,
    order: &[String],
    file: &str,
) -> Result<(), ModelError> {
    let error = |joint: &str, reason: String| ModelError::InvalidJointOrder {
        file: file.into(),
        joint: joint.into(),
        reason,
    };
    let n = model.joints.len();
    let index = joint_index(model);
    let mut new_index: Vec<Option<usize>> = vec![None; n];
    for (k, name) in order.iter().enumerate() {
        let Some(&old) = index.get(name.as_str()) else {
            let reason = if robot.joints.iter().any(|j| &j.name == name) {
                "is a fixed joint; list only moving joints"
            } else {
                "does not exist"
            };
            return Err(error(name, reason.into()));
        };
        if new_index[old].is_some() {
            return Err(error(name, "is listed more than once".into()));
        }
        new_index[old] = Some(k);
    }
    let mut permutation = Vec::with_capacity(n);
    for (old, new) in new_index.iter().enumerate() {
        match new {
            Some(new) => permutation.push(*new),
            None => {
                return Err(error(
                    &model.joints[old].name,
                    "is missing (every moving joint must be listed)".into(),
                ))
            }
        }
    }
    for (old, joint) in model.joints.iter().enumerate() {
        if let Some(p) = joint.parent {
            if permutation[p] > permutation[old] {
                return Err(error(
                    &joint.name,
                    format!(
                        "comes before its parent joint `{}`; parents must come first",
                        model.joints[p].name
                    ),
                ));
            }
        }
    }

    let mut slots: Vec<Option<(Joint, Body)>> = (0..n).map(|_| None).collect();
    for (old, (mut joint, body)) in model
        .joints
        .drain(..)
        .zip(model.bodies.drain(..))
        .enumerate()
    {
        joint.parent = joint.parent.map(|p| permutation[p]);
        slots[permutation[old]] = Some((joint, body));
    }
    for (joint, body) in slots.into_iter().flatten() {
        model.joints.push(joint);
        model.bodies.push(body);
    }
    for frame in &mut model.frames {
        frame.body = frame.body.map(|b| permutation[b]);
    }
    Ok(())
}
