//! The Markdown writer: headings, a table of the coordinates, LaTeX display math (`$$`) as
//! GitHub renders it, and a table for the legend.

use std::fmt::Write as _;

use super::document::Document;
use super::latex::aligned;

/// `doc` as Markdown.
pub(super) fn write(doc: &Document) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "# {}: equations of motion\n", md_escape(&doc.name));
    for l in &doc.intro {
        let _ = writeln!(out, "{}", md_escape(l));
    }
    let _ = writeln!(out, "\n| coordinate | joint |\n| --- | --- |");
    for (q, what) in &doc.joints {
        let _ = writeln!(out, "| ${q}$ | {} |", md_escape(what));
    }
    for (s, body) in doc.sections.iter().zip(&doc.bodies) {
        let _ = writeln!(out, "\n## {}\n", s.title);
        for n in &s.notes {
            let _ = writeln!(out, "{}\n", md_escape(n));
        }
        if !body.is_empty() {
            let _ = writeln!(out, "$$");
            aligned(&mut out, body);
            let _ = writeln!(out, "$$");
        }
    }
    if doc.has_legend() {
        let _ = writeln!(out, "\n## Legend\n\n| symbol | meaning |\n| --- | --- |");
        for (a, b) in &doc.legend {
            let _ = writeln!(out, "| ${a}$ | ${b}$ |");
        }
        for (a, b) in &doc.legend_text {
            let a = if a.starts_with("qd_i") {
                "$\\dot{q}_i$, $\\ddot{q}_i$".to_string()
            } else {
                format!("${a}$")
            };
            let _ = writeln!(out, "| {a} | {} |", md_escape(b));
        }
    }
    out
}

/// Escapes what Markdown would interpret in prose and table cells: `|`, `*`, backticks,
/// backslashes, `<`, and `_` unless it sits inside a word (`qd_j` stays readable).
pub(super) fn md_escape(s: &str) -> String {
    let chars: Vec<char> = s.chars().collect();
    let mut out = String::with_capacity(s.len());
    for (k, &c) in chars.iter().enumerate() {
        let inside_word = k > 0
            && chars[k - 1].is_alphanumeric()
            && chars.get(k + 1).is_some_and(|n| n.is_alphanumeric());
        let special = matches!(c, '|' | '*' | '`' | '\\' | '<') || (c == '_' && !inside_word);
        if special {
            out.push('\\');
        }
        out.push(c);
    }
    out
}
