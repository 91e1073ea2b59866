//! URDF reading: the only module that sees XML.
//!
//! [`load_file`] and [`load_str`] parse a URDF (XML through the `roxmltree` crate, every
//! element and attribute read here, with its place in the file), turn it into a
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
//! - Mimic joints are independent joints, as in Pinocchio; the [`Mimic`](crate::model::Mimic)
//!   relation is kept for information, unless [`ModelOptions::mimic_joints`] makes each follow
//!   the joint it mimics ([`Model::coupling`](crate::model::Model::coupling)). Limits and `<dynamics damping friction>` are kept
//!   (the friction enters the dynamics only with [`ModelOptions::friction`]).
//! - `<collision>` boxes, cylinders and spheres give a link without `<inertial>` its inertia
//!   only with [`ModelOptions::inertia_from_collision`]; otherwise such a link is massless.
//!
//! # Reading: strict where physics is at stake, tolerant elsewhere
//!
//! What dynamics reads is read strictly: `<link>` names, `<inertial>` (`<origin>`,
//! `<mass value>` and the six entries of `<inertia>`), `<joint>` (name, type, `<parent>`,
//! `<child>`, `<origin>`, `<axis>`, `<limit>`, `<dynamics>`, `<mimic>`) and the shapes of
//! `<collision>` (which [`ModelOptions::inertia_from_collision`] weighs). A problem there (a
//! missing element or attribute, a number that does not parse, a vector with the wrong count,
//! an unknown joint type, an element given twice with different content) is an error.
//! Everything else is read tolerantly: `<visual>`, `<material>` (colours, textures), mesh
//! files and scales, `<gazebo>`, `<transmission>`, `<sensor>`, PyBullet's `<contact>` in a
//! link and a `<material>` in a collision are ignored; unknown elements give at
//! most a [`ModelWarning::Markup`], never a refusal; so does an element repeated with the same
//! content.
//!
//! Every problem names the file, the line and column, and the link or joint it is in, in plain
//! words: `robot.urdf:12:24: joint `knee`: <limit lower>: `-1.57.` is not a number`. All
//! the errors of a file come at once ([`ModelError::Format`], one per line, at most
//! [`MAX_ERRORS`]).
//!
//! The XML parser refuses document type declarations, hence entities (no billion laughs, no
//! external files), and we refuse nesting deeper than [`MAX_DEPTH`].
//!
//! # Validation
//!
//! Every problem is a [`ModelError`] whose message names the file and the offending link or
//! joint; nothing panics. See the variants for the exact rules; the less obvious choices:
//!
//! - Inertias are checked where the physics is: on each moving body, its links merged. Its
//!   mass must not be negative, and its rotational inertia must be positive semi-definite and
//!   satisfy the triangle inequality (each principal moment at most the sum of the other
//!   two), both up to `1e-9 * trace + 1e-12 kg m^2`, so that the rounding noise of a point
//!   mass passes. A violation is [`ModelError::InvalidInertia`], naming the link and the
//!   inequality; [`ModelOptions::repair_inertia`] repairs it instead, with a warning.
//!   Links welded to the world never move: an impossible inertia there is only a
//!   [`ModelWarning::WeldedInertia`].
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
//! Two details kept from the reader this one replaced: a link without `<inertial>` is
//! massless, described as all zeros (so an all-zero `<inertial>` counts as missing for
//! [`ModelOptions::inertia_from_collision`]), and an all-zero `<limit>` means no limits.

mod element;
mod geometry;
mod joint;
mod link;
mod markup;
mod report;
mod robot;
mod values;
mod xml;

use std::path::Path;

use crate::model::{build_model, FormatIssue, Model, ModelError, ModelOptions, ModelWarning};
pub use xml::MAX_DEPTH;

/// The most errors of a file reported one by one; [`ModelError::Format`] counts the rest.
pub const MAX_ERRORS: usize = 20;

/// Reads and loads a URDF file; errors name the file as `path` displays.
pub fn load_file(path: impl AsRef<Path>, options: &ModelOptions) -> Result<Model, ModelError> {
    load_file_with_warnings(path, options).0
}

/// Loads a URDF from its text; `origin` names it in error messages (usually a file name).
pub fn load_str(text: &str, origin: &str, options: &ModelOptions) -> Result<Model, ModelError> {
    load_str_with_warnings(text, origin, options).0
}

/// [`load_file`], and the warnings, which a refusal keeps too (on success they are also in
/// [`Model::warnings`]).
pub fn load_file_with_warnings(
    path: impl AsRef<Path>,
    options: &ModelOptions,
) -> (Result<Model, ModelError>, Vec<ModelWarning>) {
    let path = path.as_ref();
    let file = path.display().to_string();
    match std::fs::read_to_string(path) {
        Ok(text) => load_str_with_warnings(&text, &file, options),
        Err(source) => (Err(ModelError::Io { file, source }), Vec::new()),
    }
}

/// [`load_str`], and the warnings, which a refusal keeps too (on success they are also in
/// [`Model::warnings`]).
pub fn load_str_with_warnings(
    text: &str,
    origin: &str,
    options: &ModelOptions,
) -> (Result<Model, ModelError>, Vec<ModelWarning>) {
    let mut warnings = Vec::new();
    let result = describe(text, origin, &mut warnings)
        .and_then(|robot| build_model(&robot, origin, options, &mut warnings));
    (result, warnings)
}

/// The robot as written, every markup warning added to `warnings`; all the format errors at
/// once.
fn describe(
    text: &str,
    file: &str,
    warnings: &mut Vec<ModelWarning>,
) -> Result<crate::model::RobotDescription, ModelError> {
    let format_error = |issues: Vec<FormatIssue>, more| ModelError::Format {
        file: file.into(),
        issues,
        more,
    };
    let doc = xml::parse(text).map_err(|issue| format_error(vec![issue], 0))?;
    let mut report = report::Report::new(&doc);
    let robot = robot::read(&doc, &mut report);
    // In file order.
    for list in [&mut report.errors, &mut report.warnings] {
        list.sort_by_key(|i| (i.line, i.column));
    }
    let markup = |issue| ModelWarning::Markup {
        file: file.into(),
        issue,
    };
    warnings.extend(report.warnings.drain(..).map(markup));
    if report.more_warnings > 0 {
        let last = warnings.pop();
        if let Some(ModelWarning::Markup { mut issue, .. }) = last {
            issue.message += &format!(" (and {} more such warnings)", report.more_warnings);
            warnings.push(markup(issue));
        }
    }
    if !report.errors.is_empty() {
        return Err(format_error(
            std::mem::take(&mut report.errors),
            report.more_errors,
        ));
    }
    Ok(robot)
}
