//! URDF reading: the only module that sees XML.
//!
//! [`load_file`] and [`load_str`] parse a URDF with the `urdf-rs` crate, turn it into a
//! format-neutral description and build the [`Model`] from it (fixed joints merged, joints
//! ordered, everything validated), shaped by [`ModelOptions`].
//!
//! # Semantics (those of Pinocchio's URDF parser)
//!
//! - The root link (the only link without a parent joint) is welded to the world. Links welded
//!   to it through fixed joints are part of the root too: they are [`Frame`](crate::model::Frame)s with no body, and
//!   their inertia never matters.
//! - Each revolute, continuous or prismatic joint moves one [`Body`](crate::model::Body): its child link plus every
//!   link welded to that child through fixed joints ([`Body::merged_links`](crate::model::Body::merged_links)). The merged
//!   inertia is the sum of the links' inertias, each rotated by its link placement and
//!   `<inertial><origin rpy>` and moved to the new centre of mass with the parallel-axis
//!   theorem, all in the body frame (the child link frame). Links without `<inertial>` are
//!   massless; a massless body has its centre of mass at the body-frame origin.
//! - A moving joint hanging off a welded link gets as origin the pose of that link in the body
//!   frame composed with the joint's own `<origin>`.
//! - Poses are `xyz` and `rpy` with `R = Rz(yaw) Ry(pitch) Rx(roll)`; the numbers are kept as
//!   computed (no snapping of almost-zero entries). Axes are normalized; a missing `<axis>` is
//!   `1 0 0`.
//! - Joint order: depth first from the root, the child joints of a link visited in increasing
//!   byte order of their names (the order of urdfdom's name-keyed map, hence Pinocchio's),
//!   unless [`ModelOptions::joint_order`] gives an explicit order. A parent joint always comes
//!   before its children.
//! - Mimic joints are independent joints, as in Pinocchio; the [`Mimic`]
//!   relation is kept for information only. Limits and `<dynamics damping friction>` are kept
//!   (the friction enters the dynamics only with [`ModelOptions::friction`]).
//! - `<collision>` boxes, cylinders and spheres give a link without `<inertial>` its inertia
//!   only with [`ModelOptions::inertia_from_collision`]; otherwise such a link is massless.
//!
//! # Validation
//!
//! Every problem is a [`ModelError`] whose message names the file and the offending link or
//! joint; nothing panics. See the variants for the exact rules; the less obvious choices:
//!
//! - Rotational inertias must be positive semi-definite: principal moments below
//!   `-1e-9 * trace` are an error. The triangle inequality (each principal moment at most the
//!   sum of the other two, with the same tolerance) is only enforced with
//!   [`ModelOptions::strict_inertia`]: real vendor files violate it (the Allegro hand's
//!   fingertips, by 11 %) and Pinocchio accepts them.
//! - Non-finite numbers are rejected wherever they are used: poses of joints and inertials,
//!   axes, masses, inertias, damping, friction and mimic coefficients, and the results of
//!   merging. Joint limits may be infinite (URDF 1.2 writes an omitted limit as infinity,
//!   meaning "unbounded") but not NaN.
//! - The singular-mass-matrix check ([`ModelError::MasslessSubtree`]) looks at the diagonal of
//!   the mass matrix at `q = 0`; see the variant for the exact rule.
//!
//! # Example
//!
//! ```
//! use eomgen::model::ModelOptions;
//! let urdf = r#"<robot name="pendulum">
//!   <link name="base"/>
//!   <link name="arm">
//!     <inertial>
//!       <origin xyz="0 0 -0.5"/>
//!       <mass value="1"/>
//!       <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.001"/>
//!     </inertial>
//!   </link>
//!   <joint name="swing" type="continuous">
//!     <parent link="base"/> <child link="arm"/> <axis xyz="0 1 0"/>
//!   </joint>
//! </robot>"#;
//! let model = eomgen::urdf::load_str(urdf, "pendulum.urdf", &ModelOptions::default()).unwrap();
//! assert_eq!(model.dof(), 1);
//! assert_eq!(model.bodies[0].mass, 1.0);
//! ```
//!
//! # urdf-rs quirks
//!
//! What urdf-rs 0.10 does with odd input, and what we add:
//! - A link without `<inertial>` gets an all-zero inertial: massless, as URDF says.
//! - A joint without `<limit>` gets all-zero limits; we report all-zero limits as no limits.
//! - Vectors (`xyz`, `rpy`, `axis`) silently skip words that are not numbers
//!   (`"1 x 2 3"` reads as `1 2 3`), and `NaN`/`inf` parse as numbers everywhere: the model
//!   stage rejects non-finite values.
//! - Empty names are accepted, and so is any root element name; the model stage rejects empty
//!   names.
//! - The XML tree is handled recursively, so deeply nested elements would overflow the stack
//!   (an abort, not a panic): we refuse nesting deeper than [`MAX_DEPTH`] before parsing.
//! - It panics when an element declares the reserved prefix `xmlns` (`xmlns:xmlns="..."`,
//!   found by fuzzing): we refuse that before parsing, and report any other panic of the parser
//!   as malformed XML.

use std::path::Path;

use crate::model::shapes::Shape;
use crate::model::{
    build_model, CollisionDescription, InertialDescription, JointDescription, JointKind, JointType,
    Limits, LinkDescription, Mimic, Model, ModelError, ModelOptions, Pose, RobotDescription,
};

/// The deepest element nesting accepted. URDFs need about 5 levels (robot, link, visual,
/// geometry, mesh); the parser recurses once per level.
pub const MAX_DEPTH: usize = 100;

/// Reads and loads a URDF file; errors name the file as `path` displays.
pub fn load_file(path: impl AsRef<Path>, options: &ModelOptions) -> Result<Model, ModelError> {
    let path = path.as_ref();
    let file = path.display().to_string();
    match std::fs::read_to_string(path) {
        Ok(text) => load_str(&text, &file, options),
        Err(source) => Err(ModelError::Io { file, source }),
    }
}

/// Loads a URDF from its text; `origin` names it in error messages (usually a file name).
pub fn load_str(text: &str, origin: &str, options: &ModelOptions) -> Result<Model, ModelError> {
    let xml_error = |message: String| ModelError::Xml {
        file: origin.into(),
        message,
    };
    check_depth(text).map_err(xml_error)?;
    // A panic inside the parser is its bug, but for our caller it is bad input all the same.
    let robot = match std::panic::catch_unwind(|| urdf_rs::read_from_string(text)) {
        Ok(parsed) => parsed.map_err(|e| xml_error(e.to_string()))?,
        Err(panic) => {
            let what = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown".into());
            return Err(xml_error(format!("the URDF parser failed ({what})")));
        }
    };
    build_model(&describe(&robot), origin, options)
}

/// urdf-rs's structures as a format-neutral description, numbers untouched.
fn describe(robot: &urdf_rs::Robot) -> RobotDescription {
    let pose = |p: &urdf_rs::Pose| Pose {
        xyz: p.xyz.0,
        rpy: p.rpy.0,
    };
    let links = robot
        .links
        .iter()
        .map(|link| {
            let i = &link.inertial;
            let t = &i.inertia;
            let collisions = link
                .collision
                .iter()
                .map(|c| {
                    use urdf_rs::Geometry as G;
                    let geometry = match &c.geometry {
                        G::Box { size } => Ok(Shape::Box { size: size.0 }),
                        G::Cylinder { radius, length } => Ok(Shape::Cylinder {
                            radius: *radius,
                            length: *length,
                        }),
                        G::Sphere { radius } => Ok(Shape::Sphere { radius: *radius }),
                        G::Capsule { .. } => Err("capsule"),
                        G::Mesh { .. } => Err("mesh"),
                    };
                    CollisionDescription {
                        origin: pose(&c.origin),
                        geometry,
                    }
                })
                .collect();
            LinkDescription {
                name: link.name.clone(),
                inertial: InertialDescription {
                    origin: pose(&i.origin),
                    mass: i.mass.value,
                    inertia: [t.ixx, t.ixy, t.ixz, t.iyy, t.iyz, t.izz],
                },
                collisions,
            }
        })
        .collect();
    let joints = robot
        .joints
        .iter()
        .map(|joint| {
            use urdf_rs::JointType as U;
            let joint_type = match joint.joint_type {
                U::Revolute => JointType::Moving(JointKind::Revolute),
                U::Continuous => JointType::Moving(JointKind::Continuous),
                U::Prismatic => JointType::Moving(JointKind::Prismatic),
                U::Fixed => JointType::Fixed,
                U::Floating => JointType::Unsupported("floating".into()),
                U::Planar => JointType::Unsupported("planar".into()),
                U::Spherical => JointType::Unsupported("spherical".into()),
            };
            let l = &joint.limit;
            // urdf-rs cannot tell an absent <limit> from an all-zero one; neither limits anything.
            let limits = [l.lower, l.upper, l.effort, l.velocity]
                .iter()
                .any(|&x| x != 0.0)
                .then_some(Limits {
                    lower: l.lower,
                    upper: l.upper,
                    effort: l.effort,
                    velocity: l.velocity,
                });
            let dynamics = joint.dynamics.as_ref();
            JointDescription {
                name: joint.name.clone(),
                joint_type,
                parent: joint.parent.link.clone(),
                child: joint.child.link.clone(),
                origin: pose(&joint.origin),
                axis: joint.axis.xyz.0,
                limits,
                damping: dynamics.map_or(0.0, |d| d.damping),
                friction: dynamics.map_or(0.0, |d| d.friction),
                mimic: joint.mimic.as_ref().map(|m| Mimic {
                    joint: m.joint.clone(),
                    multiplier: m.multiplier.unwrap_or(1.0),
                    offset: m.offset.unwrap_or(0.0),
                }),
            }
        })
        .collect();
    RobotDescription {
        name: robot.name.clone(),
        links,
        joints,
    }
}

/// Refuses element nesting deeper than [`MAX_DEPTH`], and a declaration of the reserved
/// `xmlns` prefix (`xmlns:xmlns="..."`), which XML forbids and which makes urdf-rs's
/// re-serialization of the tree panic (found by fuzzing).
///
/// A transcription of the tokenizer of the XML parser that urdf-rs uses (RustyXML), reduced to
/// element starts and ends and attribute names, so that it sees exactly what that parser
/// builds. Where that parser reports an error we stop: it never gets further.
fn check_depth(text: &str) -> Result<(), String> {
    #[derive(Clone, Copy)]
    enum State {
        Outside,
        TagOpened,
        /// Inside `<? ... ?>`; `true` once a `?` was seen (the parser never resets it).
        Instruction(bool),
        TagName,
        CloseTagName,
        InTag,
        /// `true` after whitespace inside the name.
        AttrName(bool),
        ExpectDelimiter,
        AttrValue(u8),
        ExpectClose,
        ExpectSpaceOrClose,
        Exclamation,
        CdataOpening(usize),
        /// The number of `]` just seen.
        Cdata(usize),
        CommentOpening,
        /// The number of `-` just seen.
        Comment(usize),
        CommentEnd,
        Doctype(usize),
    }
    use State::*;
    let is_space = |c: u8| matches!(c, b' ' | b'\t' | b'\r' | b'\n');
    let mut depth = 0usize;
    let mut state = Outside;
    let mut attr_start = 0;
    // Bytes rather than chars: non-ASCII characters never play a role in any state.
    for (i, &c) in text.as_bytes().iter().enumerate() {
        let mut opened = false;
        state = match (state, c) {
            (Outside, b'<') => TagOpened,
            (Outside, _) => Outside,
            (TagOpened, b'?') => Instruction(false),
            (TagOpened, b'!') => Exclamation,
            (TagOpened, b'/') => CloseTagName,
            (TagOpened, _) => TagName,
            (Instruction(_), b'?') => Instruction(true),
            (Instruction(true), b'>') => Outside,
            (Instruction(seen), _) => Instruction(seen),
            (TagName | InTag, b'/') => {
                opened = true;
                ExpectClose
            }
            (TagName | InTag, b'>') => {
                opened = true;
                Outside
            }
            (TagName, c) if is_space(c) => InTag,
            (TagName, _) => TagName,
            (InTag, c) if is_space(c) => InTag,
            (InTag, _) => {
                attr_start = i;
                AttrName(false)
            }
            (AttrName(_), b'=') => {
                if text[attr_start..i].trim_end() == "xmlns:xmlns" {
                    return Err(
                        "the reserved prefix `xmlns` cannot be declared (`xmlns:xmlns`)".into(),
                    );
                }
                ExpectDelimiter
            }
            (AttrName(_), c) if is_space(c) => AttrName(true),
            (AttrName(false), _) => AttrName(false),
            (AttrName(true), _) => return Ok(()),
            (ExpectDelimiter, b'"' | b'\'') => AttrValue(c),
            (ExpectDelimiter, c) if is_space(c) => ExpectDelimiter,
            (ExpectDelimiter, _) => return Ok(()),
            (AttrValue(delimiter), c) if c == delimiter => InTag,
            (AttrValue(delimiter), _) => AttrValue(delimiter),
            (ExpectClose, b'>') => {
                depth = depth.saturating_sub(1);
                Outside
            }
            (ExpectClose, _) => return Ok(()),
            (CloseTagName, b'>') => {
                depth = depth.saturating_sub(1);
                Outside
            }
            (CloseTagName, c) if is_space(c) => {
                depth = depth.saturating_sub(1);
                ExpectSpaceOrClose
            }
            (CloseTagName, _) => CloseTagName,
            (ExpectSpaceOrClose, b'>') => Outside,
            (ExpectSpaceOrClose, c) if is_space(c) => ExpectSpaceOrClose,
            (ExpectSpaceOrClose, _) => return Ok(()),
            (Exclamation, b'-') => CommentOpening,
            (Exclamation, b'[') => CdataOpening(0),
            (Exclamation, b'D') => Doctype(0),
            (Exclamation, _) => return Ok(()),
            (CdataOpening(k), c) if c == b"CDATA["[k] => {
                if k == 5 {
                    Cdata(0)
                } else {
                    CdataOpening(k + 1)
                }
            }
            (CdataOpening(_), _) => return Ok(()),
            (Cdata(k), b']') => Cdata(k + 1),
            (Cdata(k), b'>') if k >= 2 => Outside,
            (Cdata(_), _) => Cdata(0),
            (CommentOpening, b'-') => Comment(0),
            (CommentOpening, _) => return Ok(()),
            (Comment(1), b'-') => CommentEnd,
            (Comment(k), b'-') => Comment(k + 1),
            (Comment(_), _) => Comment(0),
            (CommentEnd, b'>') => Outside,
            (CommentEnd, _) => return Ok(()),
            (Doctype(k), c) if k < 6 => {
                if c == b"OCTYPE"[k] {
                    Doctype(k + 1)
                } else {
                    return Ok(());
                }
            }
            (Doctype(6), c) if is_space(c) => Doctype(7),
            (Doctype(6), _) => return Ok(()),
            (Doctype(_), b'>') => Outside,
            (Doctype(k), _) => Doctype(k),
        };
        if opened {
            depth += 1;
            if depth > MAX_DEPTH {
                return Err(format!(
                    "elements are nested more than {MAX_DEPTH} levels deep"
                ));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn depth_counts_elements_only() {
        let nested = |d: usize| format!("{}{}", "<a>".repeat(d), "</a>".repeat(d));
        assert!(check_depth(&nested(MAX_DEPTH)).is_ok());
        assert!(check_depth(&nested(MAX_DEPTH + 1)).is_err());
        // Siblings, self-closing tags, attributes with '>' and '/' and closing tags with
        // trailing spaces do not accumulate.
        let flat = r#"<r x="a>/b"><b/><c y='>'/><d></d ></r>"#.repeat(MAX_DEPTH + 1);
        assert!(check_depth(&flat).is_ok());
        // Comments, CDATA and processing instructions hide their '<'.
        for wrap in [("<!--", "-->"), ("<![CDATA[", "]]>"), ("<?pi ", "?>")] {
            let hidden = format!("{}{}{}", wrap.0, "<a>".repeat(MAX_DEPTH + 1), wrap.1);
            assert!(check_depth(&hidden).is_ok(), "{}", wrap.0);
        }
        let doctype = format!("<!DOCTYPE robot>{}", nested(MAX_DEPTH));
        assert!(check_depth(&doctype).is_ok());
        // A processing instruction ends at the first '>' after any '?', as in the parser.
        let pi = format!("<?a? >{}", "<a>".repeat(MAX_DEPTH + 1));
        assert!(check_depth(&pi).is_err());
    }
}
