//! The options that name joints or links of the merged model: rotor inertia, passive joints,
//! contact links and the links whose parameters become symbols.

use super::description::RobotDescription;
use super::errors::ModelError;
use super::options::SymbolicParams;
use super::Model;

/// Sets [`Joint::armature`] from [`ModelOptions::armature`].
pub(super) fn set_armature(
    model: &mut Model,
    robot: &RobotDescription,
    armature: &[(String, f64)],
    file: &str,
) -> Result<(), ModelError> {
    for (name, value) in armature {
        let error = |reason: String| ModelError::InvalidArmature {
            file: file.into(),
            joint: name.clone(),
            reason,
        };
        let Some(joint) = model.joints.iter_mut().find(|j| &j.name == name) else {
            return Err(error(
                if robot.joints.iter().any(|j| &j.name == name) {
                    "is a fixed joint: only moving joints have rotor inertia"
                } else {
                    "does not exist"
                }
                .into(),
            ));
        };
        if !value.is_finite() {
            return Err(error(format!("has a non-finite value ({value})")));
        }
        if *value < 0.0 {
            return Err(error(format!("has a negative value ({value})")));
        }
        joint.armature += value;
    }
    Ok(())
}

/// The indices (in joint order, ascending) of the joints named passive.
pub(super) fn passive_joints(
    model: &Model,
    robot: &RobotDescription,
    names: &[String],
    file: &str,
) -> Result<Vec<usize>, ModelError> {
    let error = |reason: String| ModelError::InvalidPassiveJoints {
        file: file.into(),
        reason,
    };
    if names.is_empty() {
        return Ok(Vec::new());
    }
    if model.is_floating() {
        return Err(error(format!(
            "joint `{}` cannot be made passive on a floating-base robot (not supported yet: \
             the base is already unactuated)",
            names[0]
        )));
    }
    let mut passive = Vec::new();
    for name in names {
        let Some(i) = model.joints.iter().position(|j| &j.name == name) else {
            return Err(error(if robot.joints.iter().any(|j| &j.name == name) {
                format!("joint `{name}` is fixed: only moving joints can be passive")
            } else {
                format!("joint `{name}` does not exist")
            }));
        };
        if !passive.contains(&i) {
            passive.push(i);
        }
    }
    if passive.len() == model.joints.len() {
        return Err(error(format!(
            "every joint is passive (the last named: `{}`): at least one must be actuated",
            names[names.len() - 1]
        )));
    }
    passive.sort_unstable();
    Ok(passive)
}

/// The frame index of each contact link, in order.
pub(super) fn contact_frames(
    model: &Model,
    links: &[String],
    file: &str,
) -> Result<Vec<usize>, ModelError> {
    links
        .iter()
        .map(|name| {
            model
                .frames
                .iter()
                .position(|f| &f.name == name)
                .ok_or_else(|| ModelError::UnknownContactLink {
                    file: file.into(),
                    link: name.clone(),
                })
        })
        .collect()
}

/// Sets [`Body::symbolic`] and [`Joint::symbolic_origin`] as requested.
pub(super) fn mark_symbolic(
    model: &mut Model,
    symbolic: &SymbolicParams,
    file: &str,
) -> Result<(), ModelError> {
    match symbolic {
        SymbolicParams::None => {}
        SymbolicParams::All => {
            model.bodies.iter_mut().for_each(|b| b.symbolic = true);
            model
                .joints
                .iter_mut()
                .for_each(|j| j.symbolic_origin = true);
        }
        SymbolicParams::Links(links) => {
            for name in links {
                let Some(frame) = model.frames.iter().find(|f| &f.name == name) else {
                    return Err(ModelError::UnknownSymbolicLink {
                        file: file.into(),
                        link: name.clone(),
                    });
                };
                if let Some(b) = frame.body {
                    model.bodies[b].symbolic = true;
                    model.joints[b].symbolic_origin = true;
                }
            }
        }
    }
    Ok(())
}
