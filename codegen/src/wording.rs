//! Words both back-ends of the catalogue write, generated code's comments and the reports for
//! people: text from a URDF made safe to print, and where a parameter's value comes from.

/// `text` made safe for a terminal or a comment (doc comments included): control characters
/// other than tab (newlines, carriage returns) and the bidirectional-text controls that rustc
/// refuses in comments (`text_direction_codepoint_in_comment`, deny by default) are written as
/// escapes such as `\u{202e}`; everything else, `*/` included, is harmless in a line comment.
pub fn escape_controls(text: &str) -> String {
    let bidi = |c: char| matches!(c, '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}');
    text.chars()
        .map(|c| {
            if (c.is_control() && c != '\t') || bidi(c) {
                format!("\\u{{{:x}}}", c as u32)
            } else {
                c.to_string()
            }
        })
        .collect()
}

/// Where a parameter's default value comes from: the URDF, or an option for rotor inertia
/// (parameter `Ia_<joint>`).
pub(crate) fn value_source(name: &str) -> &'static str {
    if name.starts_with("Ia_") {
        "armature option value"
    } else {
        "URDF value"
    }
}
