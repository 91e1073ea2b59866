//! The plain-text writer: the introduction, `name = formula` lines under each heading, the
//! legend.

use std::fmt::Write as _;

use super::document::Document;

/// `doc` as plain text.
pub(super) fn write(doc: &Document) -> String {
    let (intro, joints, sections, bodies, legend, legend_text) = (
        &doc.intro,
        &doc.joints,
        &doc.sections,
        &doc.bodies,
        &doc.legend,
        &doc.legend_text,
    );
    let mut out = String::new();
    for l in intro {
        let _ = writeln!(out, "{l}");
    }
    let _ = writeln!(out, "Joints:");
    for (q, what) in joints {
        let _ = writeln!(out, "  {q}: {what}");
    }
    for (s, body) in sections.iter().zip(bodies) {
        let _ = writeln!(out, "\n{}:", s.title);
        for n in &s.notes {
            let _ = writeln!(out, "  ({n})");
        }
        for (name, f) in body {
            let _ = writeln!(out, "  {name} = {f}");
        }
    }
    if doc.has_legend() {
        let _ = writeln!(out, "\nLegend:");
        for (a, b) in legend {
            let _ = writeln!(out, "  {a} = {b}");
        }
        for (a, b) in legend_text {
            let _ = writeln!(out, "  {a}: {b}");
        }
    }
    out
}
