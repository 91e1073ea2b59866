//! Well-formed XML, or a problem in plain words at its place.
//!
//! The parser (`roxmltree`) refuses document type declarations, hence entities (billion
//! laughs, external entities). Its tokenizer recurses once per level of nesting, and so does
//! our comparison of repeated elements: nesting deeper than [`MAX_DEPTH`] is refused before
//! parsing, so that no input can overflow the stack.

use roxmltree::{Document, Error, ParsingOptions};

use crate::model::FormatIssue;

/// The deepest element nesting accepted. URDFs need about 5 levels (robot, link, visual,
/// geometry, mesh).
pub const MAX_DEPTH: usize = 100;

/// Parses `text`, refusing document type declarations and deep nesting.
pub(super) fn parse(text: &str) -> Result<Document<'_>, FormatIssue> {
    // The parser recurses once per level of nesting: check the depth before it runs.
    if let Some(at) = too_deep(text) {
        let (line, column) = position(text, at);
        return Err(FormatIssue {
            line,
            column,
            context: None,
            message: format!("elements are nested more than {MAX_DEPTH} levels deep"),
        });
    }
    let options = ParsingOptions {
        allow_dtd: false,
        ..ParsingOptions::default()
    };
    Document::parse_with_options(text, options).map_err(|e| plain(text, &e))
}

/// The byte offset of the first element nested deeper than [`MAX_DEPTH`], if any.
///
/// A scan of element starts and ends that skips comments, CDATA sections, processing
/// instructions, declarations and quoted attribute values the way the parser's tokenizer
/// does, so that up to the first place where the parser would stop with an error, the depth
/// seen here is the depth of the parser's recursion.
fn too_deep(text: &str) -> Option<usize> {
    let bytes = text.as_bytes();
    let skip_to = |from: usize, end: &str| {
        text[from..]
            .find(end)
            .map_or(bytes.len(), |i| from + i + end.len())
    };
    let mut depth = 0usize;
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] != b'<' {
            i += 1;
            continue;
        }
        let rest = &text[i..];
        if rest.starts_with("<!--") {
            i = skip_to(i + 4, "-->");
        } else if rest.starts_with("<![CDATA[") {
            i = skip_to(i + 9, "]]>");
        } else if rest.starts_with("<?") {
            i = skip_to(i + 2, "?>");
        } else if rest.starts_with("<!") {
            i = skip_to(i + 2, ">");
        } else if rest.starts_with("</") {
            depth = depth.saturating_sub(1);
            i = skip_to(i + 2, ">");
        } else {
            let (end, empty) = tag_end(bytes, i + 1);
            if !empty {
                depth += 1;
                if depth > MAX_DEPTH {
                    return Some(i);
                }
            }
            i = end;
        }
    }
    None
}

/// Where the start tag whose name begins at `from` ends (after its `>`), and whether it is
/// an empty-element tag (`/>`); quoted attribute values may hold `>` and `/`.
fn tag_end(bytes: &[u8], from: usize) -> (usize, bool) {
    let mut quote = None;
    let mut i = from;
    while i < bytes.len() {
        let c = bytes[i];
        match quote {
            Some(q) if c == q => quote = None,
            Some(_) => {}
            None if c == b'"' || c == b'\'' => quote = Some(c),
            None if c == b'>' => return (i + 1, i > from && bytes[i - 1] == b'/'),
            None => {}
        }
        i += 1;
    }
    (bytes.len(), false)
}

/// A parser error as an issue: plain words, and the place (the end of the text when the
/// text ends too early, the declaration for a DTD).
fn plain(text: &str, e: &Error) -> FormatIssue {
    let end = || position(text, text.len());
    let ((line, column), message) = match e {
        Error::DtdDetected => (
            position(text, text.find("<!DOCTYPE").unwrap_or(0)),
            "document type declarations (<!DOCTYPE ...>) and their entities are not accepted"
                .to_string(),
        ),
        Error::NoRootNode => (end(), "no XML element: this is not a URDF".into()),
        Error::UnexpectedEndOfStream | Error::UnclosedRootNode => (
            end(),
            "the text ends before every element is closed (truncated?)".into(),
        ),
        Error::UnexpectedCloseTag(expected, actual, _) => (
            (e.pos().row, e.pos().col),
            format!("</{actual}> closes <{expected}>: not well-formed XML"),
        ),
        Error::NonXmlChar(c, _) => (
            (e.pos().row, e.pos().col),
            format!("the character {c:?} cannot appear in XML"),
        ),
        Error::UnexpectedXmlnsUri(_) | Error::InvalidElementNamePrefix(_) => (
            (e.pos().row, e.pos().col),
            "the reserved prefix `xmlns` cannot be declared (`xmlns:xmlns`) or used".into(),
        ),
        other => {
            // The parser's own words, without its " at line:column".
            let words = other.to_string();
            let words = words
                .rsplit_once(" at ")
                .map_or(words.as_str(), |(w, _)| w)
                .to_string();
            (
                (other.pos().row, other.pos().col),
                format!("not well-formed XML: {words}"),
            )
        }
    };
    FormatIssue {
        line,
        column,
        context: None,
        message,
    }
}

/// Line and column (from 1, in characters) of byte offset `at` of `text`.
fn position(text: &str, at: usize) -> (u32, u32) {
    let before = &text[..at.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let start = before.rfind('\n').map_or(0, |i| i + 1);
    let column = before[start..].chars().count() + 1;
    (line as u32, column as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn issue(text: &str) -> FormatIssue {
        parse(text).map(|_| ()).unwrap_err()
    }

    #[test]
    fn depth_is_limited() {
        let nested = |d: usize| format!("{}{}", "<a>".repeat(d), "</a>".repeat(d));
        assert!(parse(&nested(MAX_DEPTH)).is_ok());
        let e = issue(&nested(MAX_DEPTH + 1));
        assert_eq!((e.line, e.column), (1, 3 * MAX_DEPTH as u32 + 1));
        assert!(e.message.contains("nested more than 100"), "{}", e.message);
        // Unclosed elements count too: the parser recurses before it finds the end.
        assert!(too_deep(&"<a>".repeat(100_000)).is_some());
        // Siblings, empty elements and attributes holding '>' and '/' do not accumulate.
        let flat = format!(
            "<r>{}</r>",
            r#"<b/><c x="/>" y='>'></c><d ></d >"#.repeat(MAX_DEPTH + 1)
        );
        assert!(parse(&flat).is_ok());
        // Comments, CDATA and processing instructions hide their '<'.
        for (open, close) in [("<!--", "-->"), ("<![CDATA[", "]]>"), ("<?pi ", "?>")] {
            let hidden = format!("<r>{open}{}{close}</r>", "<a>".repeat(MAX_DEPTH + 1));
            assert_eq!(too_deep(&hidden), None, "{open}");
        }
    }

    #[test]
    fn errors_are_placed_and_plain() {
        let e = issue("<robot>\n  <link name=\"a\">\n</robot>");
        assert_eq!((e.line, e.column), (3, 1));
        assert!(
            e.message.contains("</robot> closes <link>"),
            "{}",
            e.message
        );
        let e = issue("<robot>\n  <link>");
        assert_eq!((e.line, e.column), (2, 9));
        assert!(e.message.contains("truncated"), "{}", e.message);
        let e = issue("<?xml version=\"1.0\"?>\n<!DOCTYPE r [<!ENTITY a \"b\">]><r/>");
        assert_eq!((e.line, e.column), (2, 1));
        assert!(e.message.contains("document type"), "{}", e.message);
        assert!(issue("").message.contains("no XML element"));
    }

    #[test]
    fn positions_count_characters() {
        assert_eq!(position("ab\ncdé", 7), (2, 4));
        assert_eq!(position("", 0), (1, 1));
    }
}
