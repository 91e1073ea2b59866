//! `<geometry>`: the shape of a collision (read strictly: `--density` weighs it) or of a
//! visual (read tolerantly: dynamics never uses it).

use roxmltree::Node;

use super::element::{self, elements, is, number, single, tag, vector};
use super::report::{Context, Report};
use crate::model::shapes::Shape;

/// The shapes URDF knows; `capsule` is an extension some files use.
const SHAPES: [&str; 5] = ["box", "cylinder", "sphere", "mesh", "capsule"];

/// The shape in `<geometry>` element `node`: a primitive that can be weighed or the name of
/// one that cannot (`mesh`, `capsule`); `None` after a problem.
pub(super) fn read(
    node: Node,
    ctx: &Context,
    report: &mut Report,
) -> Option<Result<Shape, &'static str>> {
    element::warn_unknown(node, &SHAPES, ctx, report);
    let shapes: Vec<Node> = elements(node)
        .filter(|c| SHAPES.iter().any(|s| is(*c, s)))
        .collect();
    let Some(&first) = shapes.first() else {
        report.element(node, ctx, "<geometry> holds no shape".into());
        return None;
    };
    // A second shape is handled like any repeated element.
    single(node, first.tag_name().name(), ctx, report);
    if let Some(other) = shapes.iter().find(|s| s.tag_name() != first.tag_name()) {
        report.element(
            *other,
            ctx,
            format!("<geometry> holds a second shape, {}", tag(*other)),
        );
    }
    element::warn_unknown(first, &[], ctx, report);
    shape(first, ctx, report)
}

/// One shape element.
fn shape(node: Node, ctx: &Context, report: &mut Report) -> Option<Result<Shape, &'static str>> {
    let num = |attr: &str, report: &mut Report| number(node, attr, None, ctx, report);
    Some(match node.tag_name().name() {
        "box" => Ok(Shape::Box {
            size: vector(node, "size", None, ctx, report)?,
        }),
        "cylinder" => {
            let radius = num("radius", report);
            let length = num("length", report);
            Ok(Shape::Cylinder {
                radius: radius?,
                length: length?,
            })
        }
        "sphere" => Ok(Shape::Sphere {
            radius: num("radius", report)?,
        }),
        "capsule" => {
            let radius = num("radius", report);
            let length = num("length", report);
            radius.and(length)?;
            Err("capsule")
        }
        _ => {
            mesh(node, ctx, report);
            Err("mesh")
        }
    })
}

/// A mesh is never weighed: its problems are warnings even in a collision.
fn mesh(node: Node, ctx: &Context, report: &mut Report) {
    let ctx = ctx.tolerant();
    element::required(node, "filename", &ctx, report);
    vector::<3>(node, "scale", Some([1.0; 3]), &ctx, report);
}
