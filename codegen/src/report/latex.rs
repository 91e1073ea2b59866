//! The LaTeX writer: fragments to paste (`aligned` blocks, `%` comments for headings) or a
//! standalone document (each term an `align*` that may break across pages).

use std::fmt::Write as _;

use super::document::Document;
use super::section::Section;

/// `doc` as a complete document, `\documentclass` to `\end{document}`.
pub(super) fn document(doc: &Document) -> String {
    let (legend, legend_text) = (&doc.legend, &doc.legend_text);
    let mut out = String::new();
    latex_document(
        &mut out,
        &doc.name,
        &doc.intro,
        &doc.joints,
        &doc.sections,
        &doc.bodies,
    );
    if doc.has_legend() {
        let _ = writeln!(out, "\\section*{{Legend}}");
        for (a, b) in legend_text {
            let _ = writeln!(out, "${a}$: {}\n", tex_escape(b));
        }
        if !legend.is_empty() {
            align(&mut out, legend);
        }
    }
    let _ = writeln!(out, "\\end{{document}}");
    out
}

/// `doc` as fragments to paste.
pub(super) fn fragments(doc: &Document) -> String {
    let mut out = String::new();
    for l in &doc.intro {
        let _ = writeln!(out, "% {l}");
    }
    let _ = writeln!(out, "% Joints:");
    for (q, what) in &doc.joints {
        let _ = writeln!(out, "%   {q}: {what}");
    }
    for (s, body) in doc.sections.iter().zip(&doc.bodies) {
        let _ = writeln!(out, "\n% {}", s.title);
        for n in &s.notes {
            let _ = writeln!(out, "% {n}");
        }
        aligned(&mut out, body);
    }
    if doc.has_legend() {
        let _ = writeln!(out, "\n% Legend");
        for (a, b) in &doc.legend_text {
            let _ = writeln!(out, "% {a}: {b}");
        }
        if !doc.legend.is_empty() {
            aligned(&mut out, &doc.legend);
        }
    }
    out
}

/// The preamble, title, joints and terms of a standalone LaTeX document (the caller adds the
/// legend and `\end{document}`).
fn latex_document(
    out: &mut String,
    robot: &str,
    intro: &[String],
    joints: &[(String, String)],
    sections: &[Section],
    bodies: &[Vec<(String, String)>],
) {
    let _ = writeln!(out, "\\documentclass{{article}}");
    let _ = writeln!(out, "\\usepackage{{amsmath}}");
    let _ = writeln!(out, "\\allowdisplaybreaks");
    let _ = writeln!(out, "\\begin{{document}}");
    let _ = writeln!(
        out,
        "\\section*{{{}: equations of motion}}",
        tex_escape(robot)
    );
    for l in intro {
        let _ = writeln!(out, "{}\n", tex_escape(l));
    }
    let _ = writeln!(out, "\\begin{{itemize}}");
    for (q, what) in joints {
        let _ = writeln!(out, "\\item ${q}$: {}", tex_escape(what));
    }
    let _ = writeln!(out, "\\end{{itemize}}");
    for (s, body) in sections.iter().zip(bodies) {
        let _ = writeln!(out, "\\section*{{{}}}", tex_escape(&s.title));
        for n in &s.notes {
            let _ = writeln!(out, "{}\n", tex_escape(n));
        }
        if !body.is_empty() {
            align(out, body);
        }
    }
}

/// An `align*` block of `name &= formula` lines (may break across pages); a long formula
/// continues on further lines, broken between its top-level terms (TeX cannot set a line
/// wider than about 5.7 m, which a large robot's entries exceed).
pub(super) fn align(out: &mut String, lines: &[(String, String)]) {
    const WIDTH: usize = 120;
    let mut rows = Vec::new();
    for (a, b) in lines {
        for (k, chunk) in wrap_formula(b, WIDTH).into_iter().enumerate() {
            rows.push(match k {
                0 => format!("{a} &= {chunk}"),
                _ => format!("&\\quad {chunk}"),
            });
        }
    }
    let _ = writeln!(out, "\\begin{{align*}}");
    let _ = writeln!(out, "{}", rows.join(" \\\\\n"));
    let _ = writeln!(out, "\\end{{align*}}");
}

/// Splits a LaTeX formula before its top-level ` + ` and ` - ` (outside braces and
/// `\left`/`\right` pairs) into pieces of about `width` characters.
fn wrap_formula(b: &str, width: usize) -> Vec<String> {
    let mut pieces = Vec::new();
    let (mut depth, mut start) = (0i32, 0);
    let bytes = b.as_bytes();
    for (i, &c) in bytes.iter().enumerate() {
        match c {
            b'{' => depth += 1,
            b'}' => depth -= 1,
            b'\\' if b[i..].starts_with("\\left") => depth += 1,
            b'\\' if b[i..].starts_with("\\right") => depth -= 1,
            b' ' if depth == 0
                && i + 2 < bytes.len()
                && matches!(bytes[i + 1], b'+' | b'-')
                && bytes[i + 2] == b' '
                && i - start >= width =>
            {
                pieces.push(b[start..i].to_string());
                start = i + 1;
            }
            _ => {}
        }
    }
    pieces.push(b[start..].to_string());
    pieces
}

/// Text for LaTeX's text mode: its special characters escaped, control characters dropped.
pub(super) fn tex_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '\\' => out.push_str("\\textbackslash{}"),
            '&' | '%' | '$' | '#' | '_' | '{' | '}' => {
                out.push('\\');
                out.push(c);
            }
            '~' => out.push_str("\\textasciitilde{}"),
            '^' => out.push_str("\\textasciicircum{}"),
            c if c.is_control() => {}
            c => out.push(c),
        }
    }
    out
}

/// An `aligned` block of `name &= formula` lines.
pub(super) fn aligned(out: &mut String, lines: &[(String, String)]) {
    let _ = writeln!(out, "\\begin{{aligned}}");
    for (k, (a, b)) in lines.iter().enumerate() {
        let end = if k + 1 < lines.len() { " \\\\" } else { "" };
        let _ = writeln!(out, "{a} &= {b}{end}");
    }
    let _ = writeln!(out, "\\end{{aligned}}");
}
