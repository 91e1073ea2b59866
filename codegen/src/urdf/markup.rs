//! Markup that dynamics never reads, checked tolerantly: `<visual>` and `<material>`. Their
//! problems are warnings that name the element and its place, never a refusal.

use roxmltree::Node;

use super::element::{self, elements, is, single};
use super::geometry;
use super::report::{Context, Report};

/// A `<visual>` element.
pub(super) fn visual(node: Node, ctx: &Context, report: &mut Report) {
    let ctx = ctx.tolerant();
    element::warn_unknown(node, &["origin", "geometry", "material"], &ctx, report);
    element::origin(node, &ctx, report);
    match single(node, "geometry", &ctx, report) {
        Some(g) => {
            geometry::read(g, &ctx, report);
        }
        None => report.element(node, &ctx, "<visual> has no <geometry>".into()),
    }
    if let Some(m) = single(node, "material", &ctx, report) {
        material(m, &ctx, report);
    }
}

/// A `<material>` element, at the top level or in a `<visual>`: a name, and optionally a
/// colour (four numbers) and a texture (a file name).
pub(super) fn material(node: Node, ctx: &Context, report: &mut Report) {
    let ctx = ctx.tolerant();
    element::warn_unknown(node, &["color", "texture"], &ctx, report);
    element::required(node, "name", &ctx, report);
    for child in elements(node) {
        if is(child, "color") {
            element::vector::<4>(child, "rgba", None, &ctx, report);
        } else if is(child, "texture") {
            element::required(child, "filename", &ctx, report);
        }
    }
}
