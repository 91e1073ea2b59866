//! `<joint>`: every part dynamics reads (type, links, origin, axis, limits, dynamics, mimic)
//! strictly.

use roxmltree::Node;

use super::element::{self, number, single, vector};
use super::report::{Context, Report};
use crate::model::{JointDescription, JointKind, JointType, Limits, Mimic};

/// The children a joint may have; `calibration` and `safety_controller` are not read.
const KNOWN: [&str; 9] = [
    "origin",
    "parent",
    "child",
    "axis",
    "limit",
    "dynamics",
    "mimic",
    "calibration",
    "safety_controller",
];

/// A `<joint>` element; `None` after a problem that leaves nothing to describe (reported).
pub(super) fn read(node: Node, report: &mut Report) -> Option<JointDescription> {
    let name = element::required(node, "name", &Context::top(), report)?;
    let ctx = Context::owner(format!("joint `{name}`"));
    element::warn_unknown(node, &KNOWN, &ctx, report);
    let joint_type = joint_type(node, &ctx, report);
    let parent = link_of(node, "parent", &ctx, report);
    let child = link_of(node, "child", &ctx, report);
    let origin = element::origin(node, &ctx, report);
    // A planar joint without an axis moves in its frame's xy plane (as Pinocchio reads it).
    let default_axis = match joint_type {
        Some(JointType::Planar) => [0.0, 0.0, 1.0],
        _ => [1.0, 0.0, 0.0],
    };
    let axis = match single(node, "axis", &ctx, report) {
        Some(a) => {
            element::warn_unknown(a, &[], &ctx, report);
            vector(a, "xyz", Some(default_axis), &ctx, report)
        }
        None => Some(default_axis),
    };
    let limits = single(node, "limit", &ctx, report).map(|l| limit(l, &ctx, report));
    let (damping, friction) = match single(node, "dynamics", &ctx, report) {
        Some(d) => {
            element::warn_unknown(d, &[], &ctx, report);
            (
                number(d, "damping", Some(0.0), &ctx, report),
                number(d, "friction", Some(0.0), &ctx, report),
            )
        }
        None => (Some(0.0), Some(0.0)),
    };
    let mimic = single(node, "mimic", &ctx, report).map(|m| mimic(m, &ctx, report));
    Some(JointDescription {
        name: name.to_string(),
        joint_type: joint_type?,
        parent: parent?.to_string(),
        child: child?.to_string(),
        origin,
        axis: axis?,
        // An all-zero <limit> limits nothing, as with the former reader (urdf-rs), which
        // could not tell it from none.
        limits: limits.flatten().filter(|l| {
            [l.lower, l.upper, l.effort, l.velocity]
                .iter()
                .any(|&x| x != 0.0)
        }),
        damping: damping?,
        friction: friction?,
        mimic: mimic.flatten(),
    })
}

/// The `type` attribute.
fn joint_type(node: Node, ctx: &Context, report: &mut Report) -> Option<JointType> {
    let text = element::required(node, "type", ctx, report)?;
    Some(match text {
        "revolute" => JointType::Moving(JointKind::Revolute),
        "continuous" => JointType::Moving(JointKind::Continuous),
        "prismatic" => JointType::Moving(JointKind::Prismatic),
        "fixed" => JointType::Fixed,
        "floating" => JointType::Moving(JointKind::Floating),
        "planar" => JointType::Planar,
        "spherical" => JointType::Unsupported(text.into()),
        other => {
            let at = node
                .attribute_node("type")
                .map_or(node.range().start, |a| a.range_value().start);
            report.at(
                at,
                ctx,
                format!(
                    "unknown joint type `{other}` (revolute, continuous, prismatic, fixed, \
                     floating, planar or spherical expected)"
                ),
            );
            return None;
        }
    })
}

/// The `link` of the `<parent>` or `<child>` element, which must be there.
fn link_of<'a>(
    node: Node<'a, '_>,
    role: &str,
    ctx: &Context,
    report: &mut Report,
) -> Option<&'a str> {
    let Some(e) = single(node, role, ctx, report) else {
        report.element(node, ctx, format!("<joint> has no <{role}>"));
        return None;
    };
    element::warn_unknown(e, &[], ctx, report);
    element::required(e, "link", ctx, report)
}

/// `<limit>`: `lower`, `upper` and `effort` default to 0; `velocity` is required.
fn limit(node: Node, ctx: &Context, report: &mut Report) -> Option<Limits> {
    element::warn_unknown(node, &[], ctx, report);
    let lower = number(node, "lower", Some(0.0), ctx, report);
    let upper = number(node, "upper", Some(0.0), ctx, report);
    let effort = number(node, "effort", Some(0.0), ctx, report);
    let velocity = number(node, "velocity", None, ctx, report);
    Some(Limits {
        lower: lower?,
        upper: upper?,
        effort: effort?,
        velocity: velocity?,
    })
}

/// `<mimic joint multiplier offset>`: the joint is required, the factors default to 1 and 0.
fn mimic(node: Node, ctx: &Context, report: &mut Report) -> Option<Mimic> {
    element::warn_unknown(node, &[], ctx, report);
    let joint = element::required(node, "joint", ctx, report);
    let multiplier = number(node, "multiplier", Some(1.0), ctx, report);
    let offset = number(node, "offset", Some(0.0), ctx, report);
    Some(Mimic {
        joint: joint?.to_string(),
        multiplier: multiplier?,
        offset: offset?,
    })
}
