//! `<link>`: read strictly where dynamics looks (`<inertial>`, the shapes of `<collision>`),
//! tolerantly elsewhere.

use roxmltree::Node;

use super::element::{self, elements, is, number, single};
use super::report::{Context, Report};
use super::{geometry, markup};
use crate::model::{CollisionDescription, InertialDescription, LinkDescription};

/// A `<link>` element; `None` when it has no name (reported).
pub(super) fn read(node: Node, report: &mut Report) -> Option<LinkDescription> {
    let name = element::required(node, "name", &Context::top(), report)?;
    let ctx = Context::owner(format!("link `{name}`"));
    // PyBullet's `<contact>` (friction and stiffness of the link's contacts) is known and has
    // nothing for rigid-body dynamics.
    element::warn_unknown(
        node,
        &["inertial", "visual", "collision", "contact"],
        &ctx,
        report,
    );
    let inertial = match single(node, "inertial", &ctx, report) {
        Some(i) => inertial(i, &ctx, report),
        None => InertialDescription::default(),
    };
    let mut collisions = Vec::new();
    for child in elements(node) {
        if is(child, "collision") {
            collisions.extend(collision(child, &ctx, report));
        } else if is(child, "visual") {
            markup::visual(child, &ctx, report);
        }
    }
    Some(LinkDescription {
        name: name.to_string(),
        inertial,
        collisions,
    })
}

/// `<inertial>`: an optional `<origin>`, `<mass value>` and `<inertia>` with its six entries,
/// all required. Values that do not parse are reported and read as zero.
fn inertial(node: Node, ctx: &Context, report: &mut Report) -> InertialDescription {
    element::warn_unknown(node, &["origin", "mass", "inertia"], ctx, report);
    let origin = element::origin(node, ctx, report);
    let child = |name: &str, report: &mut Report| {
        let found = single(node, name, ctx, report);
        if found.is_none() {
            report.element(node, ctx, format!("<inertial> has no <{name}>"));
        }
        found
    };
    let mass = child("mass", report);
    let tensor = child("inertia", report);
    let mass = mass.and_then(|m| {
        element::warn_unknown(m, &[], ctx, report);
        number(m, "value", None, ctx, report)
    });
    let mut inertia = [0.0; 6];
    if let Some(t) = tensor {
        element::warn_unknown(t, &[], ctx, report);
        for (slot, attr) in inertia
            .iter_mut()
            .zip(["ixx", "ixy", "ixz", "iyy", "iyz", "izz"])
        {
            *slot = number(t, attr, None, ctx, report).unwrap_or(0.0);
        }
    }
    InertialDescription {
        origin,
        mass: mass.unwrap_or(0.0),
        inertia,
    }
}

/// `<collision>`: an optional `<origin>` and a `<geometry>`; `None` after a problem.
fn collision(node: Node, ctx: &Context, report: &mut Report) -> Option<CollisionDescription> {
    // Some exporters give collisions a `<material>` (as visuals have): known, no dynamics.
    element::warn_unknown(node, &["origin", "geometry", "material"], ctx, report);
    let origin = element::origin(node, ctx, report);
    let Some(g) = single(node, "geometry", ctx, report) else {
        report.element(node, ctx, "<collision> has no <geometry>".into());
        return None;
    };
    Some(CollisionDescription {
        origin,
        geometry: geometry::read(g, ctx, report)?,
    })
}
