//! Building a [`Model`] from a format-neutral robot description: validation, fixed-joint
//! merging, joint ordering and the options that shape the result, in that order, each stage in
//! a file of its own (`tree`, `validation`, `inertia`, `merge`, `selections`, `ordering`,
//! `mimic`, `joint_kinds`).
//!
//! The URDF reader ([`crate::urdf`]) turns XML into a [`RobotDescription`] holding names, poses
//! and numbers exactly as written; everything else happens here, so that another input format
//! would only need its own reader.
//!
//! The semantics (merging, ordering, validation rules) are documented for users in
//! [`crate::urdf`].

use super::description::RobotDescription;
use super::errors::{ModelError, ModelWarning};
use super::inertia::fill_inertias;
use super::merge::merge;
use super::mimic::couplings;
use super::options::ModelOptions;
use super::ordering::reorder;
use super::selections::{contact_frames, mark_symbolic, passive_joints, set_armature};
use super::tree::{without_world_floating_joint, Tree};
use super::validation::{check_numbers, check_options, check_singular};
use super::Model;
use super::{inertia_check, joint_kinds};

/// Validates `robot` and builds its [`Model`]; `file` names the source in error messages.
/// Warnings go to `warnings` as they arise, so that they survive a refusal; the model gets a
/// copy of them all.
pub(crate) fn build_model(
    robot: &RobotDescription,
    file: &str,
    options: &ModelOptions,
    warnings: &mut Vec<ModelWarning>,
) -> Result<Model, ModelError> {
    let (unwelded, floating_joint) = without_world_floating_joint(robot);
    let robot = unwelded.as_ref().unwrap_or(robot);
    let floating = options.floating_base || floating_joint;
    let tree = Tree::new(robot, file)?;
    joint_kinds::check_description(robot, file)?;
    check_numbers(robot, file)?;
    check_options(options, file)?;
    let filled;
    let robot = match options.inertia_from_collision {
        Some(density) => {
            filled = fill_inertias(robot, &tree, density, file, warnings)?;
            // Huge primitives give huge masses.
            check_numbers(&filled, file)?;
            &filled
        }
        None => robot,
    };
    let mut model = merge(robot, &tree, file, options, floating)?;
    inertia_check::warn_welded(robot, &model, file, warnings);
    if model.joints.is_empty() && model.base.is_none() {
        return Err(ModelError::NoMovingJoint { file: file.into() });
    }
    inertia_check::check_bodies(&mut model, file, options.repair_inertia, warnings)?;
    set_armature(&mut model, robot, &options.armature, file)?;
    joint_kinds::check_options(&model, options, file)?;
    check_singular(&model, robot, options, file)?;
    if let Some(order) = &options.joint_order {
        reorder(&mut model, robot, order, file)?;
    }
    mark_symbolic(&mut model, &options.symbolic, file)?;
    model.contacts = contact_frames(&model, &options.contact_points, file)?;
    model.contact_frames = contact_frames(&model, &options.contact_frames, file)?;
    let at: Vec<String> = options
        .contact_points_at
        .iter()
        .map(|(l, _)| l.clone())
        .collect();
    let offsets = options.contact_points_at.iter().map(|(_, p)| *p);
    model.contact_points_at = contact_frames(&model, &at, file)?
        .into_iter()
        .zip(offsets)
        .collect();
    model.passive = passive_joints(&model, robot, &options.passive_joints, file)?;
    if options.mimic_joints {
        model.coupling = couplings(&model, robot, file)?;
    }
    if let (Some(&p), true) = (model.passive.first(), model.is_coupled()) {
        return Err(ModelError::InvalidPassiveJoints {
            file: file.into(),
            reason: format!(
                "joint `{}`: passive joints cannot be combined with mimic joints yet",
                model.joints[p].name
            ),
        });
    }
    model.warnings = warnings.clone();
    Ok(model)
}

#[cfg(test)]
mod tests {
    use nalgebra::{Matrix3, Vector3};

    use super::super::description::rpy_to_rotation;
    use super::super::inertia::Inertia;
    use super::super::merge::normalized;
    use super::super::tree::find_cycle;

    fn rot_x(a: f64) -> Matrix3<f64> {
        let (s, c) = a.sin_cos();
        Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
    }
    fn rot_y(a: f64) -> Matrix3<f64> {
        let (s, c) = a.sin_cos();
        Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
    }
    fn rot_z(a: f64) -> Matrix3<f64> {
        let (s, c) = a.sin_cos();
        Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
    }

    #[test]
    fn rpy_is_z_then_y_then_x() {
        let (r, p, y) = (0.3, -1.1, 2.5);
        let expected = rot_z(y) * rot_y(p) * rot_x(r);
        assert!((rpy_to_rotation([r, p, y]) - expected).amax() < 1e-15);
    }

    #[test]
    fn combine_matches_sum_about_a_common_point() {
        let a = Inertia {
            mass: 2.0,
            com: Vector3::new(0.1, -0.2, 0.3),
            inertia: Matrix3::new(0.3, 0.01, 0.0, 0.01, 0.2, 0.02, 0.0, 0.02, 0.25),
        };
        let b = Inertia {
            mass: 0.5,
            com: Vector3::new(-0.4, 0.0, 1.0),
            inertia: Matrix3::from_diagonal(&Vector3::new(0.01, 0.02, 0.03)),
        };
        let c = a.combine(&b);
        assert_eq!(c.mass, 2.5);
        assert!((c.com - (a.com * 2.0 + b.com * 0.5) / 2.5).amax() < 1e-15);
        // Inertia about the frame origin is additive.
        assert!((c.about_origin() - (a.about_origin() + b.about_origin())).amax() < 1e-14);
    }

    #[test]
    fn combine_of_massless_parts_keeps_rotational_inertia() {
        let a = Inertia {
            mass: 0.0,
            com: Vector3::new(1.0, 2.0, 3.0),
            inertia: Matrix3::identity(),
        };
        let c = a.combine(&a);
        assert_eq!(c.mass, 0.0);
        assert_eq!(c.com, Vector3::zeros());
        assert_eq!(c.inertia, Matrix3::identity() * 2.0);
    }

    #[test]
    fn normalized_handles_extreme_axes() {
        assert_eq!(normalized([0.0, 0.0, 5e-324]), Vector3::new(0.0, 0.0, 1.0));
        assert_eq!(normalized([1e308, 0.0, 0.0]), Vector3::new(1.0, 0.0, 0.0));
        let v = normalized([1e308, 1e308, 0.0]);
        assert!((v.norm() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn cycle_is_found_from_a_hanging_link() {
        // Links 0 -> 1 -> 2 -> 1 (a cycle) with 3 hanging below 2.
        let ends = [(1, 2), (2, 1), (2, 3)];
        let parent_joint = [None, Some(1), Some(0), Some(2)];
        assert_eq!(find_cycle(3, &parent_joint, &ends), vec![1, 2]);
    }
}
