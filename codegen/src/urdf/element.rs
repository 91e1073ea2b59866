//! Reading one element: its URDF children, attributes as numbers and vectors, its `<origin>`,
//! each problem reported at its place.

use roxmltree::Node;

use super::report::{Context, Report};
use super::values;
use crate::model::Pose;

/// Whether `node` is the URDF element `name`: an element of that local name without a
/// namespace prefix (`<xacro:include>` is not `<include>`).
pub(super) fn is(node: Node, name: &str) -> bool {
    node.is_element()
        && node.tag_name().name() == name
        && node.tag_name().namespace() == node.default_namespace()
}

/// The element as written in messages: `<name>`, with its prefix when it has one.
pub(super) fn tag(node: Node) -> String {
    let name = node.tag_name().name();
    match node.tag_name().namespace() {
        Some(ns) if Some(ns) != node.default_namespace() => {
            let prefix = node.lookup_prefix(ns).unwrap_or("?");
            format!("<{prefix}:{name}>")
        }
        _ => format!("<{name}>"),
    }
}

/// The element children of `node`.
pub(super) fn elements<'a, 'i>(node: Node<'a, 'i>) -> impl Iterator<Item = Node<'a, 'i>> {
    node.children().filter(|c| c.is_element())
}

/// Warns about each element child of `node` that is not one of `known` (nor one of `silent`,
/// which are known and deliberately ignored).
pub(super) fn warn_unknown(node: Node, known: &[&str], ctx: &Context, report: &mut Report) {
    for child in elements(node) {
        if !known.iter().any(|k| is(child, k)) {
            report.warning(
                child,
                ctx,
                format!("unknown element {} in {} ignored", tag(child), tag(node)),
            );
        }
    }
}

/// The first child `name` of `node`, if any. A later one with the same content is a warning;
/// one with different content is a problem (an error when `ctx` is strict).
pub(super) fn single<'a, 'i>(
    node: Node<'a, 'i>,
    name: &str,
    ctx: &Context,
    report: &mut Report,
) -> Option<Node<'a, 'i>> {
    let mut found = elements(node).filter(|c| is(*c, name));
    let first = found.next()?;
    for other in found {
        let at = report.place(first);
        if same(first, other) {
            report.warning(
                other,
                ctx,
                format!("<{name}> repeated with the same content (first at {at}): ignored"),
            );
        } else {
            report.element(
                other,
                ctx,
                format!("a second <{name}> with different content (the first is at {at})"),
            );
        }
    }
    Some(first)
}

/// Whether two elements have the same name, attributes (in any order) and element children.
/// Nesting is bounded by [`super::MAX_DEPTH`], checked before reading.
fn same(a: Node, b: Node) -> bool {
    a.tag_name() == b.tag_name()
        && attributes(a) == attributes(b)
        && elements(a).count() == elements(b).count()
        && elements(a).zip(elements(b)).all(|(x, y)| same(x, y))
}

/// The attributes of `n` as sorted (name, value) pairs.
fn attributes<'a>(n: Node<'a, '_>) -> Vec<(&'a str, &'a str)> {
    let mut v: Vec<(&str, &str)> = n.attributes().map(|x| (x.name(), x.value())).collect();
    v.sort_unstable();
    v
}

/// The text of attribute `attr`; a missing one is a problem.
pub(super) fn required<'a>(
    node: Node<'a, '_>,
    attr: &str,
    ctx: &Context,
    report: &mut Report,
) -> Option<&'a str> {
    let value = node.attribute(attr);
    if value.is_none() {
        report.element(
            node,
            ctx,
            format!("{} has no `{attr}` attribute", tag(node)),
        );
    }
    value
}

/// Attribute `attr` parsed by `parse`: `default` when absent (a problem when there is no
/// default), `None` after a problem.
fn parsed<T>(
    node: Node,
    attr: &str,
    default: Option<T>,
    parse: impl Fn(&str) -> Result<T, String>,
    ctx: &Context,
    report: &mut Report,
) -> Option<T> {
    let Some(a) = node.attribute_node(attr) else {
        if default.is_none() {
            required(node, attr, ctx, report);
        }
        return default;
    };
    match parse(a.value()) {
        Ok(v) => Some(v),
        Err(why) => {
            let name = node.tag_name().name();
            report.at(
                a.range_value().start,
                ctx,
                format!("<{name} {attr}>: {why}"),
            );
            None
        }
    }
}

/// A number attribute (see [`parsed`]).
pub(super) fn number(
    node: Node,
    attr: &str,
    default: Option<f64>,
    ctx: &Context,
    report: &mut Report,
) -> Option<f64> {
    parsed(node, attr, default, values::number, ctx, report)
}

/// An attribute of `N` numbers (see [`parsed`]).
pub(super) fn vector<const N: usize>(
    node: Node,
    attr: &str,
    default: Option<[f64; N]>,
    ctx: &Context,
    report: &mut Report,
) -> Option<[f64; N]> {
    parsed(node, attr, default, values::numbers::<N>, ctx, report)
}

/// The `<origin xyz rpy>` child of `node`: the identity when absent, and in place of values
/// that do not parse (already reported).
pub(super) fn origin(node: Node, ctx: &Context, report: &mut Report) -> Pose {
    let Some(o) = single(node, "origin", ctx, report) else {
        return Pose::default();
    };
    warn_unknown(o, &[], ctx, report);
    Pose {
        xyz: vector(o, "xyz", Some([0.0; 3]), ctx, report).unwrap_or_default(),
        rpy: vector(o, "rpy", Some([0.0; 3]), ctx, report).unwrap_or_default(),
    }
}
