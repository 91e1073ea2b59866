//! The format-neutral description of a robot as written, which readers (`crate::urdf`) fill
//! in: links, joints, poses and numbers exactly as in the file.

use nalgebra::{Matrix3, Vector3};

use super::shapes::Shape;
use super::validation::all_finite;
use super::{JointKind, Limits, Mimic, Transform};

/// A pose as written in a robot description: translation and roll-pitch-yaw angles.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Pose {
    pub(crate) xyz: [f64; 3],
    pub(crate) rpy: [f64; 3],
}

impl Pose {
    /// The transform `p_parent = R p_child + xyz` with `R = Rz(yaw) Ry(pitch) Rx(roll)`.
    pub(crate) fn to_transform(self) -> Transform {
        Transform {
            rotation: rpy_to_rotation(self.rpy),
            translation: Vector3::from(self.xyz),
        }
    }

    pub(super) fn is_finite(&self) -> bool {
        all_finite(&self.xyz) && all_finite(&self.rpy)
    }
}

/// `Rz(yaw) * Ry(pitch) * Rx(roll)`, the URDF convention.
pub(crate) fn rpy_to_rotation([roll, pitch, yaw]: [f64; 3]) -> Matrix3<f64> {
    let (sr, cr) = roll.sin_cos();
    let (sp, cp) = pitch.sin_cos();
    let (sy, cy) = yaw.sin_cos();
    Matrix3::new(
        cy * cp,
        cy * sp * sr - sy * cr,
        cy * sp * cr + sy * sr,
        sy * cp,
        sy * sp * sr + cy * cr,
        sy * sp * cr - cy * sr,
        -sp,
        cp * sr,
        cp * cr,
    )
}

/// A link's `<inertial>`: mass, centre-of-mass pose and inertia about the centre of mass in
/// the axes of that pose, as `[ixx, ixy, ixz, iyy, iyz, izz]` (tensor entries, not products of
/// inertia). All zero for a link without inertial data.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct InertialDescription {
    pub(crate) origin: Pose,
    pub(crate) mass: f64,
    pub(crate) inertia: [f64; 6],
}

/// One `<collision>` element as written: its pose in the link frame and its geometry, a
/// primitive that can be weighed or the name of one that cannot (`mesh`, `capsule`).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct CollisionDescription {
    pub(crate) origin: Pose,
    pub(crate) geometry: Result<Shape, &'static str>,
}

/// A link as written.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct LinkDescription {
    pub(crate) name: String,
    pub(crate) inertial: InertialDescription,
    pub(crate) collisions: Vec<CollisionDescription>,
}

/// The type of a joint as written.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum JointType {
    Fixed,
    Moving(JointKind),
    /// A URDF `planar` joint: the model holds it as the chain of one-coordinate joints that
    /// the joint model gives (`kinematics::joint::planar_steps`).
    Planar,
    /// A type we cannot model yet, by its URDF name (`spherical`).
    Unsupported(String),
}

/// A joint as written.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct JointDescription {
    pub(crate) name: String,
    pub(crate) joint_type: JointType,
    pub(crate) parent: String,
    pub(crate) child: String,
    pub(crate) origin: Pose,
    /// Not normalized; `[1, 0, 0]` when the file gives none.
    pub(crate) axis: [f64; 3],
    pub(crate) limits: Option<Limits>,
    pub(crate) damping: f64,
    pub(crate) friction: f64,
    pub(crate) mimic: Option<Mimic>,
}

/// A robot as written, before any validation.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct RobotDescription {
    pub(crate) name: String,
    pub(crate) links: Vec<LinkDescription>,
    pub(crate) joints: Vec<JointDescription>,
}
