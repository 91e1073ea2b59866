//! Validation of a description and of a merged model: finite numbers within range, sane option
//! values, and no moving joint whose subtree moves no inertia.

use super::description::{InertialDescription, JointType, Pose, RobotDescription};
use super::errors::{name_list, ModelError};
use super::inertia::Inertia;
use super::options::{ModelOptions, MAX_MAGNITUDE};
use super::{JointKind, Model};

/// Relative tolerance below which a revolute joint's subtree inertia about its axis counts as
/// zero (relative to the trace of the subtree inertia about the joint origin).
pub(super) const SINGULAR_TOLERANCE: f64 = 1e-12;

/// Rejects option values out of range.
pub(super) fn check_options(options: &ModelOptions, file: &str) -> Result<(), ModelError> {
    if !all_finite(&options.gravity) {
        return Err(ModelError::NonFinite {
            file: file.into(),
            culprit: "options".into(),
            field: "gravity",
        });
    }
    if let Some(&value) = options.gravity.iter().find(|x| x.abs() > MAX_MAGNITUDE) {
        return Err(ModelError::OutOfRange {
            file: file.into(),
            culprit: "options".into(),
            field: "gravity",
            value,
        });
    }
    let invalid = |option, reason: String| ModelError::InvalidOption {
        file: file.into(),
        option,
        reason,
    };
    let s = options.coulomb_smoothing;
    if !(s.is_finite() && s >= 0.0) {
        return Err(invalid(
            "coulomb_smoothing",
            format!("the velocity must be finite and non-negative, not {s}"),
        ));
    }
    if let Some(rho) = options.inertia_from_collision {
        if !(rho.is_finite() && rho > 0.0) {
            return Err(invalid(
                "inertia_from_collision",
                format!("the density must be positive and finite, not {rho} kg/m^3"),
            ));
        }
    }
    Ok(())
}

pub(super) fn all_finite(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// Rejects non-finite and out-of-range numbers wherever they are used, and zero axes.
pub(super) fn check_numbers(robot: &RobotDescription, file: &str) -> Result<(), ModelError> {
    let non_finite = |culprit: String, field| ModelError::NonFinite {
        file: file.into(),
        culprit,
        field,
    };
    // Finite and within MAX_MAGNITUDE; `culprit` is built only on failure.
    let check = |culprit: &dyn Fn() -> String, field, values: &[f64]| {
        if !all_finite(values) {
            return Err(non_finite(culprit(), field));
        }
        match values.iter().find(|x| x.abs() > MAX_MAGNITUDE) {
            Some(&value) => Err(ModelError::OutOfRange {
                file: file.into(),
                culprit: culprit(),
                field,
                value,
            }),
            None => Ok(()),
        }
    };
    let pose = |p: &Pose| [p.xyz, p.rpy].concat();
    for link in &robot.links {
        let culprit = || format!("link `{}`", link.name);
        let inertial = &link.inertial;
        check(&culprit, "inertial origin", &pose(&inertial.origin))?;
        check(&culprit, "mass", &[inertial.mass])?;
        check(&culprit, "inertia", &inertial.inertia)?;
    }
    for joint in &robot.joints {
        let culprit = || format!("joint `{}`", joint.name);
        check(&culprit, "origin", &pose(&joint.origin))?;
        if joint.joint_type == JointType::Fixed {
            continue;
        }
        // The axis is normalized: only its direction matters.
        if !all_finite(&joint.axis) {
            return Err(non_finite(culprit(), "axis"));
        }
        if joint.axis.iter().all(|&x| x == 0.0) {
            return Err(ModelError::ZeroAxis {
                file: file.into(),
                joint: joint.name.clone(),
            });
        }
        // Infinite limits mean "unbounded" (URDF 1.2); NaN means nothing.
        if let Some(l) = &joint.limits {
            if [l.lower, l.upper, l.effort, l.velocity]
                .iter()
                .any(|x| x.is_nan())
            {
                return Err(non_finite(culprit(), "limit"));
            }
        }
        check(&culprit, "damping", &[joint.damping])?;
        check(&culprit, "friction", &[joint.friction])?;
        if let Some(m) = &joint.mimic {
            if !(m.multiplier.is_finite() && m.offset.is_finite()) {
                return Err(non_finite(culprit(), "mimic multiplier or offset"));
            }
        }
    }
    Ok(())
}

/// Rejects moving joints whose diagonal entry of the mass matrix is zero at `q = 0` (see
/// [`ModelError::MasslessSubtree`]).
pub(super) fn check_singular(
    model: &Model,
    robot: &RobotDescription,
    options: &ModelOptions,
    file: &str,
) -> Result<(), ModelError> {
    let n = model.joints.len();
    let mut subtree: Vec<Inertia> = model
        .bodies
        .iter()
        .map(|b| Inertia {
            mass: b.mass,
            com: b.com,
            inertia: b.inertia,
        })
        .collect();
    // Children have larger indices than their parents: accumulate from the leaves.
    for i in (0..n).rev() {
        if let Some(p) = model.joints[i].parent {
            let moved = subtree[i].transformed(&model.joints[i].origin);
            subtree[p] = subtree[p].combine(&moved);
        }
    }
    for (i, (joint, inertia)) in model.joints.iter().zip(&subtree).enumerate() {
        let moves_inertia = if joint.kind.is_revolute() {
            let about = inertia.about_origin();
            let axial = (joint.axis.transpose() * about * joint.axis)[0];
            axial > SINGULAR_TOLERANCE * about.trace()
        } else if joint.kind == JointKind::Floating {
            // Every direction of rotation about the centre of mass must meet inertia.
            let tolerance = SINGULAR_TOLERANCE * inertia.inertia.trace();
            inertia.mass > 0.0 && inertia.inertia.symmetric_eigenvalues().min() > tolerance
        } else {
            inertia.mass > 0.0
        };
        // Rotor inertia alone makes the diagonal entry positive.
        let moves_inertia = moves_inertia || joint.armature > 0.0;
        if !moves_inertia {
            return Err(ModelError::MasslessSubtree {
                file: file.into(),
                joint: joint.name.clone(),
                hint: massless_hint(model, robot, options, i),
            });
        }
    }
    Ok(())
}

/// What may help joint `i`, which moves nothing: filling the links of its subtree that have no
/// `<inertial>` from their collision shapes, when that option is off and such links have some.
pub(super) fn massless_hint(
    model: &Model,
    robot: &RobotDescription,
    options: &ModelOptions,
    i: usize,
) -> String {
    if options.inertia_from_collision.is_some() {
        return String::new();
    }
    let fillable: Vec<String> = (i..model.dof())
        .filter(|&k| model.is_ancestor(i, k))
        .flat_map(|k| &model.bodies[k].merged_links)
        .filter_map(|name| robot.links.iter().find(|l| &l.name == name))
        .filter(|l| is_missing(&l.inertial) && !l.collisions.is_empty())
        .map(|l| l.name.clone())
        .collect();
    if fillable.is_empty() {
        return String::new();
    }
    format!(
        "; {} in its subtree have no <inertial> but a <collision>: the inertia_from_collision \
         option (--density on the command line) fills them from their collision shapes",
        name_list(&fillable, ", ")
    )
}

/// Whether a link has no inertial data: all zero, as a missing one is described.
pub(super) fn is_missing(inertial: &InertialDescription) -> bool {
    inertial.mass == 0.0 && inertial.inertia.iter().all(|&x| x == 0.0)
}
