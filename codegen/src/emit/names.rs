//! Turning URDF names into Rust identifiers that are always valid and never collide.
//!
//! URDF names are arbitrary strings: they may be Rust keywords, start with a digit, contain
//! punctuation, quotes or non-ASCII letters. Only the identifiers made here and string literals
//! escaped by `proc_macro2` reach generated code, so no name can break or inject into it.

use std::collections::{BTreeMap, BTreeSet};

/// Words that cannot be identifiers (strict and reserved keywords of every edition).
const KEYWORDS: &[&str] = &[
    "as", "async", "await", "break", "const", "continue", "crate", "dyn", "else", "enum", "extern",
    "false", "fn", "for", "gen", "if", "impl", "in", "let", "loop", "match", "mod", "move", "mut",
    "pub", "ref", "return", "self", "Self", "static", "struct", "super", "trait", "true", "type",
    "unsafe", "use", "where", "while", "abstract", "become", "box", "do", "final", "macro",
    "override", "priv", "try", "typeof", "unsized", "virtual", "yield", "union", "_",
];

/// Splits a name into ASCII alphanumeric words; every other character separates words.
/// Non-ASCII characters become their code point (`é` -> `u00e9`) so that distinct names stay
/// distinct as far as possible.
fn words(name: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    for ch in name.chars() {
        if ch.is_ascii_alphanumeric() {
            cur.push(ch);
        } else {
            if !cur.is_empty() {
                out.push(std::mem::take(&mut cur));
            }
            if !ch.is_ascii() {
                out.push(format!("u{:04x}", ch as u32));
            }
        }
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}

fn finish(mut s: String, fallback: &str) -> String {
    if s.is_empty() {
        s = fallback.to_string();
    }
    if s.starts_with(|c: char| c.is_ascii_digit()) {
        s = format!("{fallback}{s}");
    }
    if KEYWORDS.contains(&s.as_str()) {
        s.push('_');
    }
    s
}

/// `panda_link0` -> `PandaLink0`; `2dof planar` -> `Robot2dofPlanar` with fallback `Robot`.
pub fn upper_camel(name: &str, fallback: &str) -> String {
    let s: String = words(name)
        .iter()
        .map(|w| {
            let mut c = w.chars();
            match c.next() {
                Some(f) => f.to_ascii_uppercase().to_string() + c.as_str(),
                None => String::new(),
            }
        })
        .collect();
    finish(s, fallback)
}

/// `Panda Arm` -> `panda_arm`; fallback used when empty or starting with a digit.
pub fn snake(name: &str, fallback: &str) -> String {
    let s = words(name)
        .iter()
        .map(|w| w.to_ascii_lowercase())
        .collect::<Vec<_>>()
        .join("_");
    finish(s, fallback)
}

/// `text` made safe for a comment (doc comments included): control characters other than tab
/// (newlines, carriage returns) and the bidirectional-text controls that rustc refuses in
/// comments (`text_direction_codepoint_in_comment`, deny by default) are written as escapes
/// such as `\u{202e}`; everything else, `*/` included, is harmless in a line comment.
pub fn comment_text(text: &str) -> String {
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

/// Hands out identifiers unique within one scope, suffixing `_2`, `_3`, ... on collision.
#[derive(Default)]
pub struct Scope {
    taken: BTreeSet<String>,
    /// Per identifier that collided, the first suffix not yet tried: thousands of names that
    /// sanitize alike (`l!`, `l#`, ...) cost linear time, not quadratic.
    next_suffix: BTreeMap<String, usize>,
}

impl Scope {
    /// A scope in which `reserved` are already taken.
    pub fn with_reserved(reserved: &[&str]) -> Scope {
        Scope {
            taken: reserved.iter().map(|s| s.to_string()).collect(),
            next_suffix: BTreeMap::new(),
        }
    }

    /// Claims `ident`, or the first free suffixed variant.
    pub fn claim(&mut self, ident: String) -> String {
        if self.taken.insert(ident.clone()) {
            return ident;
        }
        // Suffixes below `first` were taken, and taken names stay taken: same result as
        // trying from 2.
        let first = self.next_suffix.get(&ident).copied().unwrap_or(2);
        let (k, claimed) = (first..)
            .map(|k| (k, format!("{ident}_{k}")))
            .find(|(_, c)| self.taken.insert(c.clone()))
            .expect("an unused suffix exists");
        self.next_suffix.insert(ident, k + 1);
        claimed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_become_valid_identifiers() {
        assert_eq!(upper_camel("panda_link0", "Link"), "PandaLink0");
        assert_eq!(upper_camel("link_3.0_tip", "Link"), "Link30Tip");
        assert_eq!(upper_camel("2dof_planar", "Robot"), "Robot2dofPlanar");
        assert_eq!(upper_camel("self", "Link"), "Self_");
        assert_eq!(upper_camel("", "Link"), "Link");
        assert_eq!(upper_camel("\"*/ evil", "Link"), "Evil");
        assert_eq!(upper_camel("bras_é", "Link"), "BrasU00e9");
        assert_eq!(snake("Panda Arm", "robot"), "panda_arm");
        assert_eq!(snake("fn", "robot"), "fn_");
        assert_eq!(snake("9lives", "robot"), "robot9lives");
    }

    #[test]
    fn comment_text_escapes_what_rustc_refuses_in_comments() {
        assert_eq!(comment_text("a */ b\tc"), "a */ b\tc");
        assert_eq!(comment_text("a\nb\rc"), "a\\u{a}b\\u{d}c");
        assert_eq!(comment_text("x\u{202e}y\u{2066}"), "x\\u{202e}y\\u{2066}");
        assert_eq!(comment_text("日本語 é"), "日本語 é");
    }

    #[test]
    fn collisions_get_suffixes() {
        let mut s = Scope::with_reserved(&["Link"]);
        assert_eq!(s.claim("Link".into()), "Link_2");
        assert_eq!(s.claim("A".into()), "A");
        assert_eq!(s.claim("A".into()), "A_2");
        assert_eq!(s.claim("A".into()), "A_3");
        // A suffixed name taken directly is skipped later.
        assert_eq!(s.claim("B_2".into()), "B_2");
        assert_eq!(s.claim("B".into()), "B");
        assert_eq!(s.claim("B".into()), "B_3");
        assert_eq!(s.claim("A_4".into()), "A_4");
        assert_eq!(s.claim("A".into()), "A_5");
    }
}
