//! The options that shape a [`Model`](super::Model) ([`ModelOptions`], [`SymbolicParams`]) and
//! the largest number accepted in the equations.

#[cfg(doc)]
use super::{Body, Joint, Model, ModelError, ModelWarning};

/// The largest magnitude accepted for a number that enters the equations (lengths, angles,
/// masses, inertias, damping, friction, gravity). Far beyond any robot in SI units, and small
/// enough that the products in the equations (a mass times a squared length, summed over
/// thousands of links) stay far from overflowing.
pub const MAX_MAGNITUDE: f64 = 1e15;

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
