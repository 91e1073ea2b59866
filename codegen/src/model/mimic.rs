//! URDF mimic tags honoured ([`ModelOptions::mimic_joints`](super::ModelOptions::mimic_joints)): each joint's
//! coupling to the independent coordinate at the root of its mimic chain.

use std::collections::HashMap;

use super::description::{JointType, RobotDescription};
use super::errors::ModelError;
use super::{Coupling, Model};

/// Each moving joint's index by its name.
pub(super) fn joint_index(model: &Model) -> HashMap<&str, usize> {
    model
        .joints
        .iter()
        .enumerate()
        .map(|(i, j)| (j.name.as_str(), i))
        .collect()
}

/// The coupling of every joint with the URDF's mimic tags honoured (see
/// [`ModelOptions::mimic_joints`]): each mimic chain is followed to its root, an independent
/// joint, whose coordinate the joint follows with the chain's multipliers multiplied and
/// offsets composed. Coordinates are numbered in joint order.
pub(super) fn couplings(
    model: &Model,
    robot: &RobotDescription,
    file: &str,
) -> Result<Vec<Coupling>, ModelError> {
    let index = joint_index(model);
    check_mimics_move(robot, &index, file)?;
    let leader = direct_leaders(model, robot, &index, file)?;
    // Independent joints are the coordinates, in joint order.
    let mut coordinate = vec![usize::MAX; model.joints.len()];
    let mut next = 0;
    for (i, l) in leader.iter().enumerate() {
        if l.is_none() {
            coordinate[i] = next;
            next += 1;
        }
    }
    let mut out = Vec::with_capacity(model.joints.len());
    for i in 0..model.joints.len() {
        let (j, multiplier, offset) = follow_chain(model, &leader, i, file)?;
        out.push(Coupling {
            coordinate: coordinate[j],
            leader: (j != i).then_some(j),
            multiplier,
            offset,
        });
    }
    Ok(out)
}

/// A joint's direct leader in its mimic tag: `(leader joint, multiplier, offset)`.
type Leader = Option<(usize, f64, f64)>;

/// The error of a mimic tag that `joint` cannot honour following `leader`.
fn invalid_mimic(file: &str, joint: &str, leader: &str, reason: &str) -> ModelError {
    ModelError::InvalidMimic {
        file: file.into(),
        joint: joint.into(),
        leader: leader.into(),
        reason: reason.into(),
    }
}

/// A mimic tag on a joint that does not move (`index` holds the moving joints) is an error: it
/// has nothing to follow with.
fn check_mimics_move(
    robot: &RobotDescription,
    index: &HashMap<&str, usize>,
    file: &str,
) -> Result<(), ModelError> {
    for joint in &robot.joints {
        if let (Some(m), false) = (&joint.mimic, index.contains_key(joint.name.as_str())) {
            let kind = match &joint.joint_type {
                JointType::Unsupported(kind) => kind.clone(),
                _ => "fixed".to_string(),
            };
            let reason = format!(
                "but is a {kind} joint: only revolute, continuous and prismatic joints can mimic"
            );
            return Err(invalid_mimic(file, &joint.name, &m.joint, &reason));
        }
    }
    Ok(())
}

/// Each moving joint's direct leader `(joint, multiplier, offset)`, `None` for an independent
/// joint; a leader that does not exist or does not move is an error.
fn direct_leaders(
    model: &Model,
    robot: &RobotDescription,
    index: &HashMap<&str, usize>,
    file: &str,
) -> Result<Vec<Leader>, ModelError> {
    let mut leader = Vec::with_capacity(model.joints.len());
    for joint in &model.joints {
        let Some(m) = &joint.mimic else {
            leader.push(None);
            continue;
        };
        let Some(&l) = index.get(m.joint.as_str()) else {
            let reason = if robot.joints.iter().any(|j| j.name == m.joint) {
                "which does not move (a fixed joint): only a moving joint can be mimicked"
            } else {
                "which does not exist"
            };
            return Err(invalid_mimic(file, &joint.name, &m.joint, reason));
        };
        leader.push(Some((l, m.multiplier, m.offset)));
    }
    Ok(leader)
}

/// Joint `i`'s chain of leaders followed to its independent joint `j`: `(j, multiplier,
/// offset)` with `q_i = multiplier q_j + offset`. A chain that loops, or a composed multiplier
/// or offset that is not finite, is an error.
fn follow_chain(
    model: &Model,
    leader: &[Leader],
    i: usize,
    file: &str,
) -> Result<(usize, f64, f64), ModelError> {
    // q_i = k q_l + o, q_l = k' q_m + o', ... down to an independent joint.
    let (mut j, mut multiplier, mut offset) = (i, 1.0, 0.0);
    let mut chain = vec![i];
    while let Some((l, k, o)) = leader[j] {
        // q = multiplier (k q_l + o) + offset.
        offset += multiplier * o;
        multiplier *= k;
        if let Some(start) = chain.iter().position(|&c| c == l) {
            let joints = chain[start..]
                .iter()
                .chain([&l])
                .map(|&c| model.joints[c].name.clone())
                .collect();
            return Err(ModelError::MimicCycle {
                file: file.into(),
                joints,
            });
        }
        chain.push(l);
        j = l;
    }
    if !(multiplier.is_finite() && offset.is_finite()) {
        return Err(ModelError::NonFinite {
            file: file.into(),
            culprit: format!("joint `{}`", model.joints[i].name),
            field: "mimic multiplier or offset, composed along its mimic chain",
        });
    }
    Ok((j, multiplier, offset))
}
