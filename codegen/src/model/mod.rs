//! The kinematic tree that the derivation works on, independent of any file format.
//!
//! A [`Model`] is what is left of a URDF once fixed joints are merged: a list of moving
//! [`Joint`]s in a fixed order, one rigid [`Body`] per moving joint (the joint's child link with
//! everything welded to it), and a [`Frame`] for every URDF link so that kinematics can still
//! address each link by name.
//!
//! Conventions:
//! - the root link is welded to the world (its inertia never matters), or, with a floating
//!   base, moves freely: [`Model::base`] is its body, and the base's coordinates come first
//!   (`q`: position and unit quaternion x, y, z, w, 7 numbers; velocities: linear then
//!   angular, in base axes, 6 numbers);
//! - body `i` is moved by joint `i`; its frame is the child link frame of joint `i`;
//! - all quantities are in SI units (m, kg, kg m^2, rad).

use nalgebra::{Matrix3, Vector3};

mod build;
mod description;
mod errors;
mod inertia;
mod inertia_check;
mod joint_kinds;
mod merge;
mod mimic;
mod options;
mod ordering;
mod selections;
pub mod shapes;
mod tree;
mod validation;
pub use errors::{FormatIssue, ModelError, ModelWarning};
pub use options::{ModelOptions, SymbolicParams, MAX_MAGNITUDE};
// The format-neutral description that readers (`crate::urdf`) fill in.
pub(crate) use build::build_model;
pub(crate) use description::{
    CollisionDescription, InertialDescription, JointDescription, JointType, LinkDescription, Pose,
    RobotDescription,
};

/// A rigid transform: `p_parent = rotation * p_child + translation`.
#[derive(Clone, Debug, PartialEq)]
pub struct Transform {
    pub rotation: Matrix3<f64>,
    pub translation: Vector3<f64>,
}

impl Transform {
    pub fn identity() -> Self {
        Transform {
            rotation: Matrix3::identity(),
            translation: Vector3::zeros(),
        }
    }

    /// `self * other`: first `other`, then `self`.
    pub fn compose(&self, other: &Transform) -> Transform {
        Transform {
            rotation: self.rotation * other.rotation,
            translation: self.rotation * other.translation + self.translation,
        }
    }
}

/// The kind of a moving joint.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointKind {
    /// Rotation about `axis`, with position limits.
    Revolute,
    /// Rotation about `axis` without limits; still one angle (no cos/sin pair as coordinates).
    Continuous,
    /// Translation along `axis`.
    Prismatic,
    /// A free flyer below the root (URDF `floating`): the child moves freely in the joint
    /// frame, `q` = [position (3), unit quaternion x, y, z, w (4)] of the child in the joint
    /// frame, velocity = [linear (3), angular (3)] in the child's axes (Pinocchio's
    /// `JointModelFreeFlyer`). `axis` is not used.
    Floating,
}

impl JointKind {
    /// The URDF `type` the kind comes from (`revolute`, ...; a planar joint's steps are
    /// prismatic and continuous joints).
    pub fn urdf_name(self) -> &'static str {
        match self {
            JointKind::Revolute => "revolute",
            JointKind::Continuous => "continuous",
            JointKind::Prismatic => "prismatic",
            JointKind::Floating => "floating",
        }
    }

    /// Whether the joint rotates its body (revolute and continuous joints).
    pub fn is_revolute(self) -> bool {
        matches!(self, JointKind::Revolute | JointKind::Continuous)
    }

    /// How many position coordinates the joint has in `q` (see
    /// [`crate::kinematics::joint`] for what they mean).
    pub fn nq(self) -> usize {
        match self {
            JointKind::Revolute | JointKind::Continuous | JointKind::Prismatic => 1,
            JointKind::Floating => 7,
        }
    }

    /// How many velocity coordinates the joint has in `qd` (the columns of its motion
    /// subspace).
    pub fn nv(self) -> usize {
        match self {
            JointKind::Revolute | JointKind::Continuous | JointKind::Prismatic => 1,
            JointKind::Floating => 6,
        }
    }

    /// The names of the joint's velocity coordinates after its own name (`name.vx`, ...),
    /// empty for a joint of one coordinate, which is called by its name alone.
    pub fn coordinate_suffixes(self) -> &'static [&'static str] {
        match self {
            JointKind::Revolute | JointKind::Continuous | JointKind::Prismatic => &[],
            JointKind::Floating => &["vx", "vy", "vz", "wx", "wy", "wz"],
        }
    }
}

/// Position, velocity and effort limits of a joint, as written in the URDF.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Limits {
    pub lower: f64,
    pub upper: f64,
    pub effort: f64,
    pub velocity: f64,
}

/// A URDF `<mimic>` relation: the joint's coordinate is `multiplier * (joint's) + offset`.
/// Kept for information unless [`ModelOptions::mimic_joints`] is set, which makes the joint
/// follow its leader (see [`Coupling`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Mimic {
    pub joint: String,
    pub multiplier: f64,
    pub offset: f64,
}

/// How a joint's coordinate follows the robot's independent coordinates:
/// `q_joint = multiplier * q[coordinate] + offset`, so that `qd_joint = multiplier *
/// qd[coordinate]` (and likewise for accelerations). An independent joint is its own
/// coordinate with multiplier 1 and offset 0; a mimic joint
/// ([`ModelOptions::mimic_joints`]) follows the coordinate of the joint at the root of its
/// mimic chain.
///
/// The map from coordinates to joint velocities is the constant matrix `G` (one row per
/// joint, `G[joint][coordinate] = multiplier`): every quantity in the coordinates is the
/// joint tree's projected, `tau = G^T tau_joints`, `M = G^T M_joints G`, `J = J_joints G`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coupling {
    /// The coordinate (an index into the joints' part of `q`) the joint follows.
    pub coordinate: usize,
    /// The joint behind that coordinate (the root of the mimic chain), `None` for an
    /// independent joint.
    pub leader: Option<usize>,
    pub multiplier: f64,
    pub offset: f64,
}

impl Coupling {
    /// An independent joint: coordinate `i` itself.
    pub fn independent(i: usize) -> Coupling {
        Coupling {
            coordinate: i,
            leader: None,
            multiplier: 1.0,
            offset: 0.0,
        }
    }

    /// Whether the joint is its coordinate unchanged (multiplier 1, offset 0).
    pub fn is_identity(&self) -> bool {
        self.multiplier == 1.0 && self.offset == 0.0
    }
}

/// A moving joint.
#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    /// The URDF name.
    pub name: String,
    pub kind: JointKind,
    /// Index of the parent body, `None` when the parent is the root (welded to the world).
    pub parent: Option<usize>,
    /// Pose of the joint frame at q = 0 in the parent body's frame (URDF `<origin>`, with any
    /// fixed joints between the parent body and this joint folded in).
    pub origin: Transform,
    /// Unit axis in the joint frame.
    pub axis: Vector3<f64>,
    pub limits: Option<Limits>,
    /// Viscous damping (N m s / rad or N s / m), from `<dynamics damping>`.
    pub damping: f64,
    /// Coulomb friction (N m or N), from `<dynamics friction>`.
    pub friction: f64,
    /// Rotor inertia (armature, kg m^2 or kg) added to this joint's diagonal entry of the mass
    /// matrix, from [`ModelOptions::armature`]; 0 unless set.
    pub armature: f64,
    pub mimic: Option<Mimic>,
    /// Whether the translation of `origin` should be a symbol instead of its number.
    pub symbolic_origin: bool,
}

/// The rigid body moved by one joint: its child link and every link welded to it.
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    /// The URDF name of the joint's child link; for the massless bodies between the steps of
    /// a joint of several (a planar joint's `base.x` and `base.y`), the step's joint name.
    pub name: String,
    /// Total mass (kg).
    pub mass: f64,
    /// Centre of mass in the body frame (m).
    pub com: Vector3<f64>,
    /// Rotational inertia about the centre of mass, in body-frame axes (kg m^2), symmetric.
    pub inertia: Matrix3<f64>,
    /// The URDF links merged into this body (the child link first).
    pub merged_links: Vec<String>,
    /// Whether mass, centre of mass and inertia should be symbols instead of numbers.
    pub symbolic: bool,
}

/// Every URDF link, addressable as a frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// The URDF link name.
    pub name: String,
    /// The body this link is welded to, `None` for the root.
    pub body: Option<usize>,
    /// Pose of the link frame in that body's frame (in the world frame for the root).
    pub placement: Transform,
}

/// A robot ready for derivation.
#[derive(Clone, Debug, PartialEq)]
pub struct Model {
    /// The URDF `<robot name>`.
    pub name: String,
    /// The root link's name.
    pub root: String,
    /// Gravity in world axes (m/s^2).
    pub gravity: Vector3<f64>,
    /// Moving joints; joint `i` moves body `i`. A parent body always precedes its children.
    pub joints: Vec<Joint>,
    pub bodies: Vec<Body>,
    /// The root link's body (with every link welded to it) when the root moves freely
    /// ([`ModelOptions::floating_base`]); `None` when it is welded to the world.
    pub base: Option<Body>,
    /// One frame per URDF link, in the URDF's link order.
    pub frames: Vec<Frame>,
    /// The frames (indices into [`Model::frames`]) with a 3D point contact at their origin
    /// ([`ModelOptions::contact_points`]), in order.
    pub contacts: Vec<usize>,
    /// The frames with a 6D contact ([`ModelOptions::contact_frames`]), in order: their rows
    /// follow the points'.
    pub contact_frames: Vec<usize>,
    /// The point contacts at a position in a link's frame
    /// ([`ModelOptions::contact_points_at`]): the link's frame and the position, in order; their
    /// rows follow those of [`Model::contacts`].
    pub contact_points_at: Vec<(usize, [f64; 3])>,
    /// The joints without an actuator ([`ModelOptions::passive_joints`]), as indices into
    /// [`Model::joints`], ascending; empty when every joint is actuated.
    pub passive: Vec<usize>,
    /// Whether the joint friction (`damping qd + friction sign(qd)` per joint) is part of the
    /// inverse and forward dynamics ([`ModelOptions::friction`]).
    pub include_friction: bool,
    /// The velocity (rad/s or m/s) below which Coulomb friction is smoothed
    /// ([`ModelOptions::coulomb_smoothing`]); 0 for the exact sign.
    pub coulomb_smoothing: f64,
    /// What loading had to guess, for the user to check (see [`ModelWarning`]).
    pub warnings: Vec<ModelWarning>,
    /// Per joint, the coordinate it follows ([`Coupling`]): joint `i` is coordinate `i`
    /// unless [`ModelOptions::mimic_joints`] makes mimic joints follow their leaders.
    pub coupling: Vec<Coupling>,
}

impl Model {
    /// The indices of the actuated joints, ascending: the rows of the selection matrix `S`.
    pub fn actuated(&self) -> Vec<usize> {
        (0..self.joints.len())
            .filter(|i| !self.passive.contains(i))
            .collect()
    }

    /// Degrees of freedom.
    pub fn dof(&self) -> usize {
        self.joints.len()
    }

    /// Whether some joints follow others ([`Model::coupling`]): the robot then has fewer
    /// coordinates ([`Model::coordinates`]) than joints.
    pub fn is_coupled(&self) -> bool {
        self.coupling.iter().any(|c| c.leader.is_some())
    }

    /// The number of the joints' velocity coordinates: one per independent joint of one
    /// coordinate ([`Model::dof`] without mimic joints), six per floating joint.
    pub fn coordinates(&self) -> usize {
        self.coordinate_joints()
            .into_iter()
            .map(|j| self.joints[j].kind.nv())
            .sum()
    }

    /// The joint behind each coordinate, in coordinate order: the independent joints.
    pub fn coordinate_joints(&self) -> Vec<usize> {
        (0..self.joints.len())
            .filter(|&i| self.coupling.get(i).is_none_or(|c| c.leader.is_none()))
            .collect()
    }

    /// The URDF names of the coordinates' joints, in coordinate order: one entry per
    /// independent joint (a floating joint's six coordinates have one name here; see
    /// [`Model::velocity_names`] for one per coordinate).
    pub fn coordinate_names(&self) -> Vec<&str> {
        self.coordinate_joints()
            .into_iter()
            .map(|j| self.joints[j].name.as_str())
            .collect()
    }

    /// The names of the joints' velocity coordinates, in coordinate order (what `JOINT_NAMES`
    /// lists): a joint's URDF name, or for a joint of several coordinates one entry per
    /// coordinate, `name.suffix` ([`JointKind::coordinate_suffixes`]).
    pub fn velocity_names(&self) -> Vec<String> {
        let mut out = Vec::new();
        for j in self.coordinate_joints() {
            let joint = &self.joints[j];
            match joint.kind.coordinate_suffixes() {
                [] => out.push(joint.name.clone()),
                suffixes => out.extend(suffixes.iter().map(|s| format!("{}.{s}", joint.name))),
            }
        }
        out
    }

    /// Whether the velocity coordinates are the time derivatives of the position coordinates
    /// (no floating base, no floating joint): the closed Lagrangian forms then apply.
    pub fn velocities_are_rates(&self) -> bool {
        self.nq() == self.nv()
    }

    /// The joints of several velocity coordinates that move on a manifold (floating joints
    /// below the root), by index.
    pub fn floating_joints(&self) -> Vec<usize> {
        (0..self.joints.len())
            .filter(|&j| self.joints[j].kind == JointKind::Floating)
            .collect()
    }

    /// Each joint's first position coordinate in `q` (after a floating base's seven).
    pub fn q_offsets(&self) -> Vec<usize> {
        self.offsets(self.base_nq(), JointKind::nq)
    }

    /// Each joint's first velocity coordinate in `qd` (after a floating base's six).
    pub fn v_offsets(&self) -> Vec<usize> {
        self.offsets(self.base_nv(), JointKind::nv)
    }

    /// The running sum of `size` over the joints, from `start`.
    fn offsets(&self, start: usize, size: fn(JointKind) -> usize) -> Vec<usize> {
        let mut at = start;
        self.joints
            .iter()
            .map(|j| {
                at += size(j.kind);
                at - size(j.kind)
            })
            .collect()
    }

    /// Whether the root link moves freely ([`Model::base`]).
    pub fn is_floating(&self) -> bool {
        self.base.is_some()
    }

    /// Number of position coordinates: 7 for a floating base (position and unit quaternion),
    /// then one per joint.
    pub fn nq(&self) -> usize {
        self.base_nq() + self.joints.iter().map(|j| j.kind.nq()).sum::<usize>()
    }

    /// Number of velocity coordinates: 6 for a floating base, then one per joint.
    pub fn nv(&self) -> usize {
        self.base_nv() + self.joints.iter().map(|j| j.kind.nv()).sum::<usize>()
    }

    /// Position coordinates of the base before the joints' (7 floating, else 0).
    pub fn base_nq(&self) -> usize {
        if self.is_floating() {
            7
        } else {
            0
        }
    }

    /// Velocity coordinates of the base before the joints' (6 floating, else 0).
    pub fn base_nv(&self) -> usize {
        if self.is_floating() {
            6
        } else {
            0
        }
    }

    /// The chain of joints from the root to joint `i`, root first, `i` last.
    pub fn path_to_root(&self, i: usize) -> Vec<usize> {
        let mut path = vec![i];
        let mut j = i;
        while let Some(p) = self.joints[j].parent {
            path.push(p);
            j = p;
        }
        path.reverse();
        path
    }

    /// True when joint `a` lies on the path from the root to joint `b` (or `a == b`).
    pub fn is_ancestor(&self, a: usize, b: usize) -> bool {
        let mut j = Some(b);
        while let Some(k) = j {
            if k == a {
                return true;
            }
            j = self.joints[k].parent;
        }
        false
    }
}
