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

/// Splits a name into words as the `heck` crate does: runs of ASCII letters and digits, cut
/// where a lowercase letter (or a digit after one) meets an uppercase letter (`linkTip` ->
/// `link`, `Tip`) and before the last capital of an acronym followed by a lowercase letter
/// (`URDFRobot` -> `URDF`, `Robot`). Every other character separates words; non-ASCII
/// characters become their code point (`é` -> `u00e9`) so that distinct names stay distinct as
/// far as possible.
fn words(name: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut run = String::new();
    for ch in name.chars() {
        if ch.is_ascii_alphanumeric() {
            run.push(ch);
            continue;
        }
        out.extend(case_words(&std::mem::take(&mut run)));
        if !ch.is_ascii() {
            out.push(format!("u{:04x}", ch as u32));
        }
    }
    out.extend(case_words(&run));
    out
}

/// The case of the letters read so far in a word (digits keep it).
#[derive(Clone, Copy, PartialEq)]
enum Case {
    Boundary,
    Lower,
    Upper,
}

/// Cuts a run of ASCII letters and digits at its case boundaries (see [`words`]).
fn case_words(run: &str) -> Vec<String> {
    let b = run.as_bytes();
    let mut cuts = vec![0];
    let mut mode = Case::Boundary;
    for i in 0..b.len() {
        let here = match b[i] {
            c if c.is_ascii_lowercase() => Case::Lower,
            c if c.is_ascii_uppercase() => Case::Upper,
            _ => mode,
        };
        let next = b.get(i + 1).copied().unwrap_or(b'_');
        if here == Case::Lower && next.is_ascii_uppercase() {
            // `linkTip`: a word ends after the lowercase letter.
            cuts.push(i + 1);
            mode = Case::Boundary;
        } else if mode == Case::Upper && b[i].is_ascii_uppercase() && next.is_ascii_lowercase() {
            // `URDFRobot`: the acronym ends before its last capital.
            cuts.push(i);
            mode = Case::Boundary;
        } else {
            mode = here;
        }
    }
    cuts.push(b.len());
    cuts.windows(2)
        .filter(|w| w[0] < w[1])
        .map(|w| run[w[0]..w[1]].to_string())
        .collect()
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

/// UpperCamelCase as the `heck` crate writes it: each word capitalized, the rest of it in
/// lowercase. `panda_link0` -> `PandaLink0`, `UF_ROBOT` -> `UfRobot`; `2dof planar` ->
/// `Robot2dofPlanar` with fallback `Robot`.
pub fn upper_camel(name: &str, fallback: &str) -> String {
    let s: String = words(name)
        .iter()
        .map(|w| {
            let lower = w.to_ascii_lowercase();
            let mut c = lower.chars();
            match c.next() {
                Some(f) => f.to_ascii_uppercase().to_string() + c.as_str(),
                None => String::new(),
            }
        })
        .collect();
    finish(s, fallback)
}

/// snake_case as the `heck` crate writes it: `Panda Arm` and `PandaArm` -> `panda_arm`;
/// fallback used when empty or starting with a digit.
pub fn snake(name: &str, fallback: &str) -> String {
    let s = words(name)
        .iter()
        .map(|w| w.to_ascii_lowercase())
        .collect::<Vec<_>>()
        .join("_");
    finish(s, fallback)
}

/// `text` made safe for a comment (see [`crate::wording::escape_controls`]).
pub fn comment_text(text: &str) -> String {
    crate::wording::escape_controls(text)
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
    fn case_follows_heck() {
        for (name, camel, snake_case) in [
            ("UF_ROBOT", "UfRobot", "uf_robot"),
            ("xArm7", "XArm7", "x_arm7"),
            ("URDFRobot", "UrdfRobot", "urdf_robot"),
            ("PandaArm", "PandaArm", "panda_arm"),
            ("link0Tip", "Link0Tip", "link0_tip"),
            ("ABC", "Abc", "abc"),
            ("j2n6s300_link_1", "J2n6s300Link1", "j2n6s300_link_1"),
            ("a-b", "AB", "a_b"),
            ("A1Bc", "A1Bc", "a1_bc"),
        ] {
            assert_eq!(upper_camel(name, "Robot"), camel, "{name}");
            assert_eq!(snake(name, "robot"), snake_case, "{name}");
        }
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
