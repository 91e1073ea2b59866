//! The plain-text writer: the introduction, `name = formula` lines under each heading, the
//! legend.

use std::fmt::Write as _;

use super::document::Document;

/// `doc` as plain text.
pub(super) fn write(doc: &Document) -> String {
    let mut out = String::new();
    for l in &doc.intro {
        let _ = writeln!(out, "{l}");
    }
    let _ = writeln!(out, "Joints:");
    for (q, what) in &doc.joints {
        let _ = writeln!(out, "  {q}: {what}");
    }
    for (s, body) in doc.sections.iter().zip(&doc.bodies) {
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
        for (a, b) in &doc.legend {
            let _ = writeln!(out, "  {a} = {b}");
        }
        for (a, b) in &doc.legend_text {
            let _ = writeln!(out, "  {a}: {b}");
        }
    }
    out
}
