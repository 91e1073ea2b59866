//! What loading can report: [`ModelError`] (a refusal), [`ModelWarning`] (a guess to check),
//! [`FormatIssue`] (a reader's problem), with the helpers that word them.

#[cfg(doc)]
use super::{Model, ModelOptions, SymbolicParams, MAX_MAGNITUDE};
use thiserror::Error;

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
pub(super) fn issue_lines(file: &str, issues: &[FormatIssue], more: usize) -> String {
    let mut lines: Vec<String> = issues.iter().map(|i| format!("{file}:{i}")).collect();
    if more > 0 {
        if let Some(last) = lines.last_mut() {
            last.push_str(&format!(" (and {more} more errors not shown)"));
        }
    }
    lines.join("\n")
}

pub(super) fn ignored_note(ignored: &[String]) -> String {
    if ignored.is_empty() {
        String::new()
    } else {
        format!(
            " (ignored, as it cannot be weighed: {})",
            ignored.join(", ")
        )
    }
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
pub(super) const MAX_NAMES_SHOWN: usize = 8;

/// `` `a`, `b`, `c` `` (with `separator`), the first [`MAX_NAMES_SHOWN`] names of a long list
/// followed by how many more there are, so that a message stays one readable line.
pub(super) fn name_list(names: &[String], separator: &str) -> String {
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
