//! Building a [`Model`] from a format-neutral robot description: validation, fixed-joint
//! merging, joint ordering and the options that shape the result.
//!
//! The URDF reader ([`crate::urdf`]) turns XML into a [`RobotDescription`] holding names, poses
//! and numbers exactly as written; everything else happens here, so that another input format
//! would only need its own reader.
//!
//! The semantics (merging, ordering, validation rules) are documented for users in
//! [`crate::urdf`].

use std::collections::HashMap;

use nalgebra::{Matrix3, Vector3};
use thiserror::Error;

use super::inertia_check;
use super::joint_kinds;
use super::shapes::{mass_properties, Shape};
use super::{Body, Coupling, Frame, Joint, JointKind, Limits, Mimic, Model, Transform};

/// The largest magnitude accepted for a number that enters the equations (lengths, angles,
/// masses, inertias, damping, friction, gravity). Far beyond any robot in SI units, and small
/// enough that the products in the equations (a mass times a squared length, summed over
/// thousands of links) stay far from overflowing.
pub const MAX_MAGNITUDE: f64 = 1e15;

/// Relative tolerance below which a revolute joint's subtree inertia about its axis counts as
/// zero (relative to the trace of the subtree inertia about the joint origin).
const SINGULAR_TOLERANCE: f64 = 1e-12;

/// Options that shape a [`Model`].
#[derive(Clone, Debug, PartialEq)]
pub struct ModelOptions {
    /// Gravity in world axes (m/s^2); `[0, 0, -9.81]` by default.
    pub gravity: [f64; 3],
    /// An explicit order of the moving joints, by URDF name (to match a controller's wiring).
    /// It must list every moving joint exactly once, and a joint's parent joint must come
    /// before it; otherwise loading fails with [`ModelError::InvalidJointOrder`]. `None` (the
    /// default) keeps the depth-first order described in [`crate::urdf`].
    pub joint_order: Option<Vec<String>>,
    /// Which inertial parameters (and joint offsets) become symbols.
    pub symbolic: SymbolicParams,
    /// Repairs the rotational inertia of a moving body that is not positive semi-definite or
    /// breaks the triangle inequality, instead of refusing the robot with
    /// [`ModelError::InvalidInertia`]: like MuJoCo's `balanceinertia`, its principal moments
    /// are all set to their mean (zero if the mean is negative). Each repair is reported as a
    /// [`ModelWarning::InertiaRepaired`]. `false` by default.
    pub repair_inertia: bool,
    /// Rotor inertia (armature) per moving joint, by URDF name: kg m^2 for a revolute joint
    /// (the reflected rotor inertia, gear ratio squared times the rotor's inertia), kg for a
    /// prismatic one. Added to the joint's diagonal entry of the mass matrix, hence to the
    /// inverse and forward dynamics and the kinetic energy. A name listed twice adds up. An
    /// unknown or fixed joint, or a negative or non-finite value, is
    /// [`ModelError::InvalidArmature`]. Empty by default.
    pub armature: Vec<(String, f64)>,
    /// Includes the joint friction of the URDF's `<dynamics damping friction>` in the inverse
    /// and forward dynamics: the joints feel `-(damping qd + friction sign(qd))`, so that
    /// `tau = M qdd + b + G + damping qd + friction sign(qd)`. `false` by default.
    pub friction: bool,
    /// With [`ModelOptions::friction`], replaces `sign(qd)` in the Coulomb term by the smooth
    /// `qd / sqrt(qd^2 + eps^2)` with `eps` this velocity (rad/s or m/s), so that integrators
    /// do not step across a discontinuity. 0 (the default) keeps the exact sign
    /// (`sign(0) = 0`). Must be finite and non-negative ([`ModelError::InvalidOption`]).
    pub coulomb_smoothing: f64,
    /// Fills the inertia of links without `<inertial>` (a missing one is described as all
    /// zeros, so a link whose mass and inertia are all zero counts as missing) from their
    /// `<collision>` boxes, cylinders and spheres, made of a uniform material of this density
    /// (kg/m^3), each placed by its `<origin>` (overlaps count twice). Every filled link gets a
    /// [`ModelWarning::InertiaFromCollision`]; a link whose collision geometry has no such
    /// primitive (only meshes or capsules) stays massless with a
    /// [`ModelWarning::NoCollisionPrimitive`]. Links welded to the root are skipped (their
    /// inertia never matters). `None` (the default) leaves such links massless. The density
    /// must be positive and finite ([`ModelError::InvalidOption`]).
    pub inertia_from_collision: Option<f64>,
    /// Lets the root link move freely (a free-flyer root, as Pinocchio's
    /// `JointModelFreeFlyer`): the model gains [`Model::base`], the root link's body, whose
    /// six velocity coordinates come before the joints'. A URDF whose root is a massless
    /// world link attached to the robot by a `floating` joint means the same. `false` by
    /// default.
    pub floating_base: bool,
    /// Links with a 3D point contact at their origin, in the order of the contact quantities
    /// (`contact_jacobian` rows, contact forces). Links merged into their parent by fixed joints
    /// keep their own names (feet usually are such links). Empty by default.
    pub contact_points: Vec<String>,
    /// Links with a 6D contact (a foot's sole held flat): the link frame's spatial acceleration
    /// is held (6 rows: linear, then angular, world axes at the link origin). Their rows come
    /// after the points'. Empty by default.
    pub contact_frames: Vec<String>,
    /// 3D point contacts at a position in a link's frame (a sole's corners), in order: their
    /// rows come after those of [`ModelOptions::contact_points`], before the frames'. Empty by
    /// default.
    pub contact_points_at: Vec<(String, [f64; 3])>,
    /// Moving joints without an actuator, by URDF name (the acrobot's elbow, a cart-pole's
    /// pole, a passive wrist or toe): the equation of motion becomes `M qdd + b + G = S^T
    /// tau_a` with `S` the `NA x N` selection matrix of the actuated joints
    /// ([`Model::passive`]). An unknown or fixed joint, every joint passive, or a floating
    /// base is [`ModelError::InvalidPassiveJoints`]. A name listed twice counts once. Empty by
    /// default.
    pub passive_joints: Vec<String>,
    /// Honours the URDF's `<mimic joint multiplier offset>` tags: a mimic joint is no
    /// coordinate of its own, its value is `multiplier * (the mimicked joint) + offset`, and
    /// every quantity is in the remaining, independent coordinates ([`Model::coupling`]). A
    /// mimic of a mimic follows the root of the chain (multipliers multiplied, offsets
    /// composed). A mimic of a missing or fixed joint, a mimic tag on a fixed joint and a cycle
    /// of mimics are errors ([`ModelError::InvalidMimic`], [`ModelError::MimicCycle`]).
    /// `false` by default: mimic joints are independent joints, as in Pinocchio.
    pub mimic_joints: bool,
}

impl Default for ModelOptions {
    fn default() -> Self {
        ModelOptions {
            gravity: [0.0, 0.0, -9.81],
            joint_order: None,
            symbolic: SymbolicParams::None,
            repair_inertia: false,
            armature: Vec::new(),
            friction: false,
            coulomb_smoothing: 0.0,
            inertia_from_collision: None,
            floating_base: false,
            contact_points: Vec::new(),
            contact_frames: Vec::new(),
            contact_points_at: Vec::new(),
            mimic_joints: false,
            passive_joints: Vec::new(),
        }
    }
}

/// Something loading had to guess or leave out; the model is usable, but a person should
/// check it. Every message starts with the file name and names the link.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum ModelWarning {
    /// A link without `<inertial>` got its mass, centre of mass and inertia from its
    /// `<collision>` primitives ([`ModelOptions::inertia_from_collision`]).
    #[error(
        "{file}: link `{link}` has no <inertial>: mass {} kg, centre of mass and inertia \
         computed from {primitives} <collision> primitive(s) at a density of {density} \
         kg/m^3{}",
        crate::cas::format_number(*.mass, Some(6)),
        ignored_note(.ignored)
    )]
    InertiaFromCollision {
        file: String,
        link: String,
        /// The computed mass (kg).
        mass: f64,
        /// Boxes, cylinders and spheres used.
        primitives: usize,
        density: f64,
        /// Collision geometry that could not be used (`mesh`, `capsule`).
        ignored: Vec<String>,
    },
    /// A link without `<inertial>` whose `<collision>` geometry has no box, cylinder or
    /// sphere: it stays massless.
    #[error(
        "{file}: link `{link}` has no <inertial>, and its <collision> geometry ({}) has no \
         box, cylinder or sphere to compute one from: the link stays massless",
        .ignored.join(", ")
    )]
    NoCollisionPrimitive {
        file: String,
        link: String,
        /// The collision geometry found (`mesh`, `capsule`).
        ignored: Vec<String>,
    },
    /// Markup that dynamics never reads (visual geometry, materials, unknown elements) is
    /// malformed or unknown, or an element is given twice with the same content: ignored.
    #[error("{file}:{issue}")]
    Markup { file: String, issue: FormatIssue },
    /// A link welded to the world has an impossible mass or inertia; it never moves, so its
    /// inertia never enters the dynamics and is ignored.
    #[error(
        "{file}: link `{link}` is welded to the world, so its inertia is never used: ignoring \
         that {reason}"
    )]
    WeldedInertia {
        file: String,
        link: String,
        reason: String,
    },
    /// [`ModelOptions::repair_inertia`] replaced a moving body's impossible rotational
    /// inertia.
    #[error(
        "{file}: link `{link}`: {reason}; repaired (as MuJoCo's balanceinertia does) to \
         principal moments {}",
        moments_text(.after)
    )]
    InertiaRepaired {
        file: String,
        /// The body's link (the child link of its joint).
        link: String,
        /// What was wrong.
        reason: String,
        /// The principal moments before and after the repair (kg m^2), smallest first.
        before: [f64; 3],
        after: [f64; 3],
    },
}

/// Principal moments as `a, b, c kg m^2`.
pub(crate) fn moments_text(m: &[f64; 3]) -> String {
    let f = |x: f64| crate::cas::format_number(x, Some(6));
    format!("{}, {}, {} kg m^2", f(m[0]), f(m[1]), f(m[2]))
}

/// A problem at a place in a file: its line and column (from 1), the link or joint it is in
/// (if any) and what is wrong, in plain words. Displays as `line:column: context: message`.
#[derive(Clone, Debug, PartialEq)]
pub struct FormatIssue {
    pub line: u32,
    pub column: u32,
    /// The link or joint, e.g. ``joint `elbow` ``; `None` outside of both.
    pub context: Option<String>,
    pub message: String,
}

impl std::fmt::Display for FormatIssue {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}: ", self.line, self.column)?;
        if let Some(context) = &self.context {
            write!(f, "{context}: ")?;
        }
        write!(f, "{}", self.message)
    }
}

/// The lines of [`ModelError::Format`]: one per issue, each starting with `file:line:column`.
fn issue_lines(file: &str, issues: &[FormatIssue], more: usize) -> String {
    let mut lines: Vec<String> = issues.iter().map(|i| format!("{file}:{i}")).collect();
    if more > 0 {
        if let Some(last) = lines.last_mut() {
            last.push_str(&format!(" (and {more} more errors not shown)"));
        }
    }
    lines.join("\n")
}

fn ignored_note(ignored: &[String]) -> String {
    if ignored.is_empty() {
        String::new()
    } else {
        format!(
            " (ignored, as it cannot be weighed: {})",
            ignored.join(", ")
        )
    }
}

/// Which bodies get symbolic inertial parameters ([`Body::symbolic`]) and which joints a
/// symbolic origin ([`Joint::symbolic_origin`]).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum SymbolicParams {
    /// Every parameter is a number.
    #[default]
    None,
    /// Every body and every joint origin is symbolic.
    All,
    /// The bodies containing these URDF links (as child link or as a merged link) are symbolic,
    /// and so are the origins of the joints moving them. A name that is not a link is an error
    /// ([`ModelError::UnknownSymbolicLink`]); links welded to the root are accepted and have no
    /// effect, as the root's inertia never matters.
    Links(Vec<String>),
}

/// Why a robot description could not become a [`Model`]. Every message starts with the file
/// name and names the offending link or joint.
// Debug prints the Display message: see `debug_display.rs`.
#[derive(Error)]
pub enum ModelError {
    /// The file could not be read (or is not UTF-8).
    #[error("{file}: cannot read the file: {source}")]
    Io {
        file: String,
        #[source]
        source: std::io::Error,
    },
    /// The text is not well-formed XML or not a URDF. The URDF reader reports these as
    /// [`ModelError::Format`], with their places; this variant is for errors without one.
    #[error("{file}: malformed URDF: {message}")]
    Xml { file: String, message: String },
    /// The text is not well-formed XML, or not a URDF where dynamics needs it (missing or
    /// unknown required elements or attributes, numbers that do not parse, elements given
    /// twice with different content, nesting too deep). All the problems of the file, up to a
    /// cap (`more` counts those left out), one per line: `file:line:column: context: what`.
    #[error("{}", issue_lines(.file, .issues, *.more))]
    Format {
        file: String,
        issues: Vec<FormatIssue>,
        more: usize,
    },
    /// A joint of a kind that an option cannot handle yet (a floating joint below the root
    /// with mimic joints, passive joints, contacts, rotor inertia or friction; a planar joint
    /// whose plane is not its frame's xy plane).
    #[error("{file}: joint `{joint}` is {kind}: {reason}")]
    UnsupportedJointUse {
        file: String,
        joint: String,
        kind: &'static str,
        reason: String,
    },
    /// The robot has no links at all.
    #[error("{file}: the robot has no links")]
    NoLinks { file: String },
    /// A link or joint has an empty name (counted from 1 in file order).
    #[error("{file}: {element} number {index} has an empty name")]
    EmptyName {
        file: String,
        element: &'static str,
        index: usize,
    },
    /// Two links have the same name.
    #[error("{file}: link `{link}` is defined more than once")]
    DuplicateLink { file: String, link: String },
    /// Two joints have the same name.
    #[error("{file}: joint `{joint}` is defined more than once")]
    DuplicateJoint { file: String, joint: String },
    /// A spherical joint: not supported yet.
    #[error(
        "{file}: joint `{joint}` is {joint_type}, which is not supported \
         (only revolute, continuous, prismatic, planar, floating and fixed joints are)"
    )]
    UnsupportedJoint {
        file: String,
        joint: String,
        joint_type: String,
    },
    /// A joint names a parent or child link that does not exist.
    #[error("{file}: joint `{joint}` has {role} link `{link}`, which does not exist")]
    MissingLink {
        file: String,
        joint: String,
        /// `"parent"` or `"child"`.
        role: &'static str,
        link: String,
    },
    /// A link is the child of two joints.
    #[error(
        "{file}: link `{link}` has two parents: it is the child of joints `{first}` and `{second}`"
    )]
    MultipleParents {
        file: String,
        link: String,
        first: String,
        second: String,
    },
    /// More than one link has no parent joint.
    #[error("{file}: the robot has several root links (links without a parent joint): {}", name_list(.roots, ", "))]
    MultipleRoots { file: String, roots: Vec<String> },
    /// The joints form a cycle (listed from parent to child; the last link is the parent of the
    /// first).
    #[error("{file}: the links {} form a cycle", name_list(.links, " -> "))]
    Cycle { file: String, links: Vec<String> },
    /// A number that matters is NaN or infinite.
    #[error("{file}: {culprit}: {field} is not a finite number")]
    NonFinite {
        file: String,
        /// The link, joint or option, e.g. ``joint `elbow` ``.
        culprit: String,
        field: &'static str,
    },
    /// A number that matters is finite but larger in magnitude than [`MAX_MAGNITUDE`].
    #[error(
        "{file}: {culprit}: {field} holds {value:e}, beyond the largest magnitude accepted (1e15)"
    )]
    OutOfRange {
        file: String,
        /// The link, joint or option, e.g. ``joint `elbow` ``.
        culprit: String,
        field: &'static str,
        value: f64,
    },
    /// A moving joint's axis is the zero vector.
    #[error("{file}: joint `{joint}` has a zero axis")]
    ZeroAxis { file: String, joint: String },
    /// A moving body's mass (its links' masses added up) is negative.
    #[error("{file}: link `{link}` has a negative mass ({mass})")]
    NegativeMass {
        file: String,
        link: String,
        mass: f64,
    },
    /// A moving body's rotational inertia (its links merged) is not positive semi-definite or
    /// breaks the triangle inequality, by more than `1e-9 * trace + 1e-12 kg m^2`; `link` is
    /// the body's link and `reason` names the violated inequality.
    /// [`ModelOptions::repair_inertia`] repairs it instead.
    #[error("{file}: link `{link}` has an impossible inertia: {reason}")]
    InvalidInertia {
        file: String,
        link: String,
        reason: String,
    },
    /// No revolute, continuous or prismatic joint: nothing to derive.
    #[error("{file}: the robot has no moving joint (revolute, continuous or prismatic)")]
    NoMovingJoint { file: String },
    /// A moving joint whose own diagonal entry of the mass matrix is zero at `q = 0`, so that
    /// the mass matrix is singular there: for a prismatic joint, the bodies it moves (its
    /// subtree) have no mass; for a revolute or continuous joint, the subtree's rotational
    /// inertia about the joint axis at `q = 0`, masses off the axis included, is zero (below
    /// `1e-12` of the trace of the subtree inertia about the joint origin). This is a necessary
    /// condition for an invertible mass matrix, not a sufficient one (for example, two
    /// consecutive coaxial revolute joints whose first body is massless pass the check). A
    /// joint with rotor inertia ([`ModelOptions::armature`]) always passes. `hint` suggests
    /// what may help (empty, or starting with `; `).
    #[error(
        "{file}: joint `{joint}` moves nothing with inertia (its subtree is massless, or for a \
         revolute joint has no inertia about the axis): the mass matrix would be singular{hint}"
    )]
    MasslessSubtree {
        file: String,
        joint: String,
        hint: String,
    },
    /// [`ModelOptions::joint_order`] names an unknown or fixed joint, repeats or omits a moving
    /// joint, or puts a joint before its parent joint.
    #[error("{file}: joint_order: joint `{joint}` {reason}")]
    InvalidJointOrder {
        file: String,
        joint: String,
        reason: String,
    },
    /// [`SymbolicParams::Links`] names a link that does not exist.
    #[error("{file}: symbolic parameters requested for link `{link}`, which does not exist")]
    UnknownSymbolicLink { file: String, link: String },
    /// [`ModelOptions::contact_points`] or [`ModelOptions::contact_frames`] names a link that
    /// does not exist.
    #[error("{file}: contact point requested at link `{link}`, which does not exist")]
    UnknownContactLink { file: String, link: String },
    /// [`ModelOptions::armature`] names a joint that does not exist or is fixed, or gives a
    /// negative or non-finite value.
    #[error("{file}: armature: joint `{joint}` {reason}")]
    InvalidArmature {
        file: String,
        joint: String,
        reason: String,
    },
    /// [`ModelOptions::passive_joints`] names a joint that does not exist or is fixed, leaves
    /// no joint actuated, or is given for a floating-base robot.
    #[error("{file}: passive joints: {reason}")]
    InvalidPassiveJoints { file: String, reason: String },
    /// With [`ModelOptions::mimic_joints`], a `<mimic>` tag that cannot be honoured: it names
    /// a joint that does not exist or does not move, or sits on a joint that does not move.
    #[error("{file}: joint `{joint}` mimics `{leader}`, {reason}")]
    InvalidMimic {
        file: String,
        joint: String,
        leader: String,
        reason: String,
    },
    /// With [`ModelOptions::mimic_joints`], joints that mimic each other in a cycle.
    #[error("{file}: the mimic joints {} form a cycle: none of them is a coordinate", name_list(.joints, " -> "))]
    MimicCycle { file: String, joints: Vec<String> },
    /// A numeric option is out of its range (for example a density that is not positive).
    #[error("{file}: option {option}: {reason}")]
    InvalidOption {
        file: String,
        option: &'static str,
        reason: String,
    },
    /// A collision primitive needed to fill a link's inertia has a negative or non-finite size
    /// or pose.
    #[error("{file}: link `{link}` has an invalid <collision> {reason}")]
    InvalidCollision {
        file: String,
        link: String,
        reason: String,
    },
}

/// At most this many names in one message.
const MAX_NAMES_SHOWN: usize = 8;

/// `` `a`, `b`, `c` `` (with `separator`), the first [`MAX_NAMES_SHOWN`] names of a long list
/// followed by how many more there are, so that a message stays one readable line.
fn name_list(names: &[String], separator: &str) -> String {
    let mut shown: Vec<String> = names
        .iter()
        .take(MAX_NAMES_SHOWN)
        .map(|n| format!("`{n}`"))
        .collect();
    if names.len() > MAX_NAMES_SHOWN {
        shown.push(format!("... ({} more)", names.len() - MAX_NAMES_SHOWN));
    }
    shown.join(separator)
}

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

    fn is_finite(&self) -> bool {
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

/// Rejects option values out of range.
fn check_options(options: &ModelOptions, file: &str) -> Result<(), ModelError> {
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

/// Sets [`Joint::armature`] from [`ModelOptions::armature`].
fn set_armature(
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

/// The robot with the inertia of every link that lacks one (and moves) computed from its
/// collision primitives, warning about each.
fn fill_inertias(
    robot: &RobotDescription,
    tree: &Tree,
    density: f64,
    file: &str,
    warnings: &mut Vec<ModelWarning>,
) -> Result<RobotDescription, ModelError> {
    // Links welded to the root (through fixed joints only) never move: skip them.
    let mut welded = vec![false; robot.links.len()];
    welded[tree.root] = true;
    for &j in &tree.order {
        let (parent, child) = tree.ends[j];
        welded[child] = welded[parent] && robot.joints[j].joint_type == JointType::Fixed;
    }
    let mut filled = robot.clone();
    for (link, welded) in filled.links.iter_mut().zip(welded) {
        if welded || !is_missing(&link.inertial) || link.collisions.is_empty() {
            continue;
        }
        let invalid = |reason: String| ModelError::InvalidCollision {
            file: file.into(),
            link: link.name.clone(),
            reason,
        };
        let mut parts = Vec::new();
        let mut ignored = Vec::new();
        for c in &link.collisions {
            match c.geometry {
                Ok(shape) => {
                    let sizes: Vec<f64> = match shape {
                        Shape::Box { size } => size.to_vec(),
                        Shape::Cylinder { radius, length } => vec![radius, length],
                        Shape::Sphere { radius } => vec![radius],
                        Shape::Rod { length } => vec![length],
                    };
                    if !sizes.iter().all(|x| x.is_finite() && *x >= 0.0) {
                        return Err(invalid(format!(
                            "geometry: sizes must be finite and non-negative, not {sizes:?}"
                        )));
                    }
                    if !c.origin.is_finite() {
                        return Err(invalid("origin: not finite".into()));
                    }
                    parts.push((shape, c.origin.to_transform()));
                }
                Err(kind) => ignored.push(kind.to_string()),
            }
        }
        match mass_properties(&parts, density) {
            Some(p) => {
                let i = (p.inertia + p.inertia.transpose()) * 0.5;
                link.inertial = InertialDescription {
                    origin: Pose {
                        xyz: p.com.into(),
                        rpy: [0.0; 3],
                    },
                    mass: p.mass,
                    inertia: [
                        i[(0, 0)],
                        i[(0, 1)],
                        i[(0, 2)],
                        i[(1, 1)],
                        i[(1, 2)],
                        i[(2, 2)],
                    ],
                };
                warnings.push(ModelWarning::InertiaFromCollision {
                    file: file.into(),
                    link: link.name.clone(),
                    mass: p.mass,
                    primitives: parts.len(),
                    density,
                    ignored,
                });
            }
            None if parts.is_empty() => warnings.push(ModelWarning::NoCollisionPrimitive {
                file: file.into(),
                link: link.name.clone(),
                ignored,
            }),
            // Primitives of zero volume: nothing to weigh either.
            None => {
                ignored.extend(parts.iter().map(|_| "primitive of zero volume".to_string()));
                warnings.push(ModelWarning::NoCollisionPrimitive {
                    file: file.into(),
                    link: link.name.clone(),
                    ignored,
                })
            }
        }
    }
    Ok(filled)
}

fn all_finite(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// The validated structure: link indices per joint, the root and the depth-first joint order.
struct Tree {
    /// `(parent link, child link)` of each joint, indices into `robot.links`.
    ends: Vec<(usize, usize)>,
    root: usize,
    /// All joints (fixed ones included), depth first from the root, siblings by name.
    order: Vec<usize>,
}

impl Tree {
    fn new(robot: &RobotDescription, file: &str) -> Result<Tree, ModelError> {
        if robot.links.is_empty() {
            return Err(ModelError::NoLinks { file: file.into() });
        }
        let mut link_index = HashMap::new();
        for (i, link) in robot.links.iter().enumerate() {
            if link.name.is_empty() {
                return Err(ModelError::EmptyName {
                    file: file.into(),
                    element: "link",
                    index: i + 1,
                });
            }
            if link_index.insert(link.name.as_str(), i).is_some() {
                return Err(ModelError::DuplicateLink {
                    file: file.into(),
                    link: link.name.clone(),
                });
            }
        }
        let mut joint_names = HashMap::new();
        for (i, joint) in robot.joints.iter().enumerate() {
            if joint.name.is_empty() {
                return Err(ModelError::EmptyName {
                    file: file.into(),
                    element: "joint",
                    index: i + 1,
                });
            }
            if joint_names.insert(joint.name.as_str(), i).is_some() {
                return Err(ModelError::DuplicateJoint {
                    file: file.into(),
                    joint: joint.name.clone(),
                });
            }
        }
        for joint in &robot.joints {
            if let JointType::Unsupported(kind) = &joint.joint_type {
                return Err(ModelError::UnsupportedJoint {
                    file: file.into(),
                    joint: joint.name.clone(),
                    joint_type: kind.clone(),
                });
            }
        }
        let lookup = |joint: &JointDescription, link: &str, role| {
            link_index
                .get(link)
                .copied()
                .ok_or_else(|| ModelError::MissingLink {
                    file: file.into(),
                    joint: joint.name.clone(),
                    role,
                    link: link.into(),
                })
        };
        let mut ends = Vec::with_capacity(robot.joints.len());
        for joint in &robot.joints {
            ends.push((
                lookup(joint, &joint.parent, "parent")?,
                lookup(joint, &joint.child, "child")?,
            ));
        }

        let n = robot.links.len();
        let mut parent_joint: Vec<Option<usize>> = vec![None; n];
        let mut children: Vec<Vec<usize>> = vec![Vec::new(); n];
        for (j, &(parent, child)) in ends.iter().enumerate() {
            if let Some(first) = parent_joint[child] {
                return Err(ModelError::MultipleParents {
                    file: file.into(),
                    link: robot.links[child].name.clone(),
                    first: robot.joints[first].name.clone(),
                    second: robot.joints[j].name.clone(),
                });
            }
            parent_joint[child] = Some(j);
            children[parent].push(j);
        }
        let roots: Vec<usize> = (0..n).filter(|&l| parent_joint[l].is_none()).collect();
        if roots.len() > 1 {
            return Err(ModelError::MultipleRoots {
                file: file.into(),
                roots: roots.iter().map(|&l| robot.links[l].name.clone()).collect(),
            });
        }
        let cycle_error = |start: usize| ModelError::Cycle {
            file: file.into(),
            links: find_cycle(start, &parent_joint, &ends)
                .into_iter()
                .map(|l| robot.links[l].name.clone())
                .collect(),
        };
        let Some(&root) = roots.first() else {
            return Err(cycle_error(0));
        };

        for list in &mut children {
            list.sort_by(|&a, &b| robot.joints[a].name.cmp(&robot.joints[b].name));
        }
        // Iterative depth-first walk: a long chain must not overflow the stack.
        let mut visited = vec![false; n];
        visited[root] = true;
        let mut order = Vec::with_capacity(robot.joints.len());
        let mut stack: Vec<usize> = children[root].iter().rev().copied().collect();
        while let Some(j) = stack.pop() {
            order.push(j);
            let child = ends[j].1;
            visited[child] = true;
            stack.extend(children[child].iter().rev());
        }
        if let Some(unreached) = visited.iter().position(|&v| !v) {
            return Err(cycle_error(unreached));
        }
        Ok(Tree { ends, root, order })
    }
}

/// The cycle above `start`, a link unreachable from the root: every link on its chain of
/// parents has a parent, so the chain loops. Returned from parent to child.
fn find_cycle(start: usize, parent_joint: &[Option<usize>], ends: &[(usize, usize)]) -> Vec<usize> {
    let mut chain = Vec::new();
    let mut seen = HashMap::new();
    let mut link = start;
    loop {
        if let Some(&pos) = seen.get(&link) {
            let mut cycle = chain.split_off(pos);
            cycle.reverse();
            return cycle;
        }
        seen.insert(link, chain.len());
        chain.push(link);
        match parent_joint[link] {
            Some(j) => link = ends[j].0,
            // Unreachable for links cut off from the root; report the chain rather than panic.
            None => {
                chain.reverse();
                return chain;
            }
        }
    }
}

/// Rejects non-finite and out-of-range numbers wherever they are used, and zero axes.
fn check_numbers(robot: &RobotDescription, file: &str) -> Result<(), ModelError> {
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

pub(super) fn inertia_matrix(&[ixx, ixy, ixz, iyy, iyz, izz]: &[f64; 6]) -> Matrix3<f64> {
    Matrix3::new(ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz)
}

/// Mass, centre of mass and rotational inertia about the centre of mass, in one frame.
#[derive(Clone, Debug)]
struct Inertia {
    mass: f64,
    com: Vector3<f64>,
    inertia: Matrix3<f64>,
}

impl Inertia {
    /// A link's inertia expressed in a frame where the link frame has pose `placement`.
    fn of_link(inertial: &InertialDescription, placement: &Transform) -> Inertia {
        let frame = placement.compose(&inertial.origin.to_transform());
        Inertia {
            mass: inertial.mass,
            com: frame.translation,
            inertia: frame.rotation
                * inertia_matrix(&inertial.inertia)
                * frame.rotation.transpose(),
        }
    }

    /// The same inertia seen from a frame where the current frame has pose `t`.
    fn transformed(&self, t: &Transform) -> Inertia {
        Inertia {
            mass: self.mass,
            com: t.rotation * self.com + t.translation,
            inertia: t.rotation * self.inertia * t.rotation.transpose(),
        }
    }

    /// The lumped inertia of two rigidly attached parts (same frame). With
    /// `d = c1 - c2` and `M = m1 + m2`, the inertia about the new centre of mass is
    /// `I1 + I2 + (m1 m2 / M) (|d|^2 E - d d^T)` (parallel-axis theorem, as in Pinocchio).
    fn combine(&self, other: &Inertia) -> Inertia {
        let mass = self.mass + other.mass;
        let inertia = self.inertia + other.inertia;
        // Massless parts leave the centre of mass exactly where it was.
        let (com, inertia) = if mass == 0.0 {
            (Vector3::zeros(), inertia)
        } else if other.mass == 0.0 {
            (self.com, inertia)
        } else if self.mass == 0.0 {
            (other.com, inertia)
        } else {
            let d = self.com - other.com;
            (
                (self.com * self.mass + other.com * other.mass) / mass,
                inertia + shift(&d) * (self.mass * other.mass / mass),
            )
        };
        Inertia { mass, com, inertia }
    }

    /// Stores mass, centre of mass and (exactly symmetric) inertia in `body`.
    fn set(&self, body: &mut Body) {
        body.mass = self.mass;
        body.com = if self.mass > 0.0 {
            self.com
        } else {
            Vector3::zeros()
        };
        // Exactly symmetric, whatever the rounding of the rotations.
        body.inertia = (self.inertia + self.inertia.transpose()) * 0.5;
    }

    /// The rotational inertia about the frame origin.
    fn about_origin(&self) -> Matrix3<f64> {
        self.inertia + shift(&self.com) * self.mass
    }
}

/// `|d|^2 E - d d^T`: the parallel-axis term per unit mass.
fn shift(d: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::identity() * d.norm_squared() - d * d.transpose()
}

/// Where a link sits: the body it is welded to (`None` for the root) and its pose there.
#[derive(Clone)]
struct Attachment {
    body: Option<usize>,
    placement: Transform,
}

/// Walks the tree depth first, creating a body per moving joint and lumping every link welded
/// through fixed joints into its body.
fn merge(
    robot: &RobotDescription,
    tree: &Tree,
    file: &str,
    options: &ModelOptions,
    floating: bool,
) -> Result<Model, ModelError> {
    let root_link = &robot.links[tree.root];
    let mut root_inertia = Inertia::of_link(&root_link.inertial, &Transform::identity());
    let mut root_links = vec![root_link.name.clone()];
    let mut attach = vec![
        Attachment {
            body: None,
            placement: Transform::identity(),
        };
        robot.links.len()
    ];
    let mut joints: Vec<Joint> = Vec::new();
    let mut bodies: Vec<Body> = Vec::new();
    let mut inertias: Vec<Inertia> = Vec::new();
    for &j in &tree.order {
        let joint = &robot.joints[j];
        let (parent, child) = tree.ends[j];
        // The walk reaches a joint after its parent link, so `attach[parent]` is final.
        let above = attach[parent].clone();
        let placement = above.placement.compose(&joint.origin.to_transform());
        let child_link = &robot.links[child];
        let steps = match &joint.joint_type {
            JointType::Moving(kind) => vec![joint_kinds::Step {
                suffix: None,
                kind: *kind,
                axis: normalized(joint.axis),
            }],
            JointType::Planar => joint_kinds::planar_steps(),
            JointType::Fixed | JointType::Unsupported(_) => Vec::new(),
        };
        if !steps.is_empty() {
            let last = steps.len() - 1;
            let mut parent = above.body;
            for (k, step) in steps.into_iter().enumerate() {
                let b = joints.len();
                // The steps of a planar joint: the first at the joint's origin, each next one
                // at its predecessor's body origin; the last body is the child link's.
                joints.push(Joint {
                    name: match step.suffix {
                        Some(suffix) => format!("{}.{suffix}", joint.name),
                        None => joint.name.clone(),
                    },
                    kind: step.kind,
                    parent,
                    origin: if k == 0 {
                        placement.clone()
                    } else {
                        Transform::identity()
                    },
                    axis: step.axis,
                    limits: (last == 0).then(|| joint.limits.clone()).flatten(),
                    damping: joint.damping,
                    friction: joint.friction,
                    armature: 0.0,
                    mimic: joint.mimic.clone(),
                    symbolic_origin: false,
                });
                let links = if k == last {
                    vec![child_link.name.clone()]
                } else {
                    Vec::new()
                };
                bodies.push(Body {
                    name: child_link.name.clone(),
                    mass: 0.0,
                    com: Vector3::zeros(),
                    inertia: Matrix3::zeros(),
                    merged_links: links,
                    symbolic: false,
                });
                let empty = InertialDescription::default();
                let inertial = if k == last {
                    &child_link.inertial
                } else {
                    &empty
                };
                inertias.push(Inertia::of_link(inertial, &Transform::identity()));
                parent = Some(b);
            }
            attach[child] = Attachment {
                body: parent,
                placement: Transform::identity(),
            };
            continue;
        }
        match &joint.joint_type {
            JointType::Moving(_) | JointType::Planar => {}
            JointType::Fixed | JointType::Unsupported(_) => {
                let part = Inertia::of_link(&child_link.inertial, &placement);
                match above.body {
                    Some(b) => {
                        bodies[b].merged_links.push(child_link.name.clone());
                        inertias[b] = inertias[b].combine(&part);
                    }
                    None => {
                        root_links.push(child_link.name.clone());
                        root_inertia = root_inertia.combine(&part);
                    }
                }
                attach[child] = Attachment {
                    body: above.body,
                    placement,
                };
            }
        }
    }

    for (body, inertia) in bodies.iter_mut().zip(inertias) {
        inertia.set(body);
    }
    let base = floating.then(|| {
        let mut base = Body {
            name: root_link.name.clone(),
            mass: 0.0,
            com: Vector3::zeros(),
            inertia: Matrix3::zeros(),
            merged_links: root_links,
            symbolic: false,
        };
        root_inertia.set(&mut base);
        base
    });
    let frames: Vec<Frame> = robot
        .links
        .iter()
        .zip(attach)
        .map(|(link, a)| Frame {
            name: link.name.clone(),
            body: a.body,
            placement: a.placement,
        })
        .collect();

    // Finite inputs can still overflow when composed.
    let non_finite = |culprit: String, field| ModelError::NonFinite {
        file: file.into(),
        culprit,
        field,
    };
    let transform_finite =
        |t: &Transform| all_finite(t.rotation.as_slice()) && all_finite(t.translation.as_slice());
    for body in bodies.iter().chain(&base) {
        if !(body.mass.is_finite()
            && all_finite(body.com.as_slice())
            && all_finite(body.inertia.as_slice()))
        {
            return Err(non_finite(
                format!("body of link `{}`", body.name),
                "inertia after merging fixed links",
            ));
        }
    }
    for joint in &joints {
        if !transform_finite(&joint.origin) {
            return Err(non_finite(
                format!("joint `{}`", joint.name),
                "origin after merging fixed links",
            ));
        }
    }
    for frame in &frames {
        if !transform_finite(&frame.placement) {
            return Err(non_finite(format!("link `{}`", frame.name), "placement"));
        }
    }

    let joints_len = joints.len();
    Ok(Model {
        name: robot.name.clone(),
        root: robot.links[tree.root].name.clone(),
        gravity: Vector3::from(options.gravity),
        joints,
        bodies,
        base,
        frames,
        contacts: Vec::new(),
        contact_frames: Vec::new(),
        contact_points_at: Vec::new(),
        passive: Vec::new(),
        include_friction: options.friction,
        coulomb_smoothing: options.coulomb_smoothing,
        warnings: Vec::new(),
        coupling: (0..joints_len).map(Coupling::independent).collect(),
    })
}

/// The indices (in joint order, ascending) of the joints named passive.
fn passive_joints(
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

/// Each moving joint's index by its name.
fn joint_index(model: &Model) -> HashMap<&str, usize> {
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
fn couplings(
    model: &Model,
    robot: &RobotDescription,
    file: &str,
) -> Result<Vec<Coupling>, ModelError> {
    let index = joint_index(model);
    let invalid = |joint: &str, leader: &str, reason: &str| ModelError::InvalidMimic {
        file: file.into(),
        joint: joint.into(),
        leader: leader.into(),
        reason: reason.into(),
    };
    // A mimic tag on a joint that does not move has nothing to follow with.
    for joint in &robot.joints {
        if let (Some(m), false) = (&joint.mimic, index.contains_key(joint.name.as_str())) {
            let kind = match &joint.joint_type {
                JointType::Unsupported(kind) => kind.clone(),
                _ => "fixed".to_string(),
            };
            let reason = format!(
                "but is a {kind} joint: only revolute, continuous and prismatic joints can mimic"
            );
            return Err(invalid(&joint.name, &m.joint, &reason));
        }
    }
    // Each joint's direct leader.
    let mut leader: Vec<Option<(usize, f64, f64)>> = Vec::with_capacity(model.joints.len());
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
            return Err(invalid(&joint.name, &m.joint, reason));
        };
        leader.push(Some((l, m.multiplier, m.offset)));
    }
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
        // Follow the chain: q_i = k q_l + o, q_l = k' q_m + o', ... down to an independent joint.
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
        let culprit = || format!("joint `{}`", model.joints[i].name);
        if !(multiplier.is_finite() && offset.is_finite()) {
            return Err(ModelError::NonFinite {
                file: file.into(),
                culprit: culprit(),
                field: "mimic multiplier or offset, composed along its mimic chain",
            });
        }
        out.push(Coupling {
            coordinate: coordinate[j],
            leader: (j != i).then_some(j),
            multiplier,
            offset,
        });
    }
    Ok(out)
}

/// The frame index of each contact link, in order.
fn contact_frames(model: &Model, links: &[String], file: &str) -> Result<Vec<usize>, ModelError> {
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

/// A robot whose root is a massless link (conventionally `world`) attached to the real root by a
/// single `floating` joint, without that link and joint: the real root then floats. `None`
/// (and `false`) when the robot has no such joint.
fn without_world_floating_joint(robot: &RobotDescription) -> (Option<RobotDescription>, bool) {
    let is_child = |link: &str| robot.joints.iter().any(|j| j.child == link);
    let floating = robot.joints.iter().position(|j| {
        j.joint_type == JointType::Moving(JointKind::Floating)
            && !is_child(&j.parent)
            && robot.joints.iter().filter(|o| o.parent == j.parent).count() == 1
    });
    let Some(f) = floating else {
        return (None, false);
    };
    let world = robot.joints[f].parent.clone();
    let Some(w) = robot.links.iter().position(|l| l.name == world) else {
        return (None, false);
    };
    if robot.links[w].inertial.mass != 0.0 {
        return (None, false);
    }
    let mut out = robot.clone();
    out.joints.remove(f);
    out.links.remove(w);
    (Some(out), true)
}

/// The unit vector along a finite, non-zero `axis`, scaled first so that tiny or huge
/// components neither underflow nor overflow.
fn normalized(axis: [f64; 3]) -> Vector3<f64> {
    let v = Vector3::from(axis);
    let v = v / v.amax();
    v / v.norm()
}

/// Rejects moving joints whose diagonal entry of the mass matrix is zero at `q = 0` (see
/// [`ModelError::MasslessSubtree`]).
fn check_singular(
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
fn massless_hint(
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
fn is_missing(inertial: &InertialDescription) -> bool {
    inertial.mass == 0.0 && inertial.inertia.iter().all(|&x| x == 0.0)
}

/// Applies an explicit joint order (see [`ModelOptions::joint_order`]).
fn reorder(
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

/// Sets [`Body::symbolic`] and [`Joint::symbolic_origin`] as requested.
fn mark_symbolic(
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

#[cfg(test)]
mod tests {
    use super::*;

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
