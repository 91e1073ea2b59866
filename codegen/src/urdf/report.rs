//! Collecting the problems of a file with their places: errors for what dynamics needs,
//! warnings for what it ignores.

use roxmltree::{Document, Node};

use crate::model::FormatIssue;

/// Where an element's problems belong and how serious they are.
#[derive(Clone, Debug)]
pub(super) struct Context {
    /// The link or joint, e.g. ``joint `elbow` ``.
    pub(super) owner: Option<String>,
    /// Errors if `true`, warnings if `false`.
    pub(super) strict: bool,
}

impl Context {
    /// Outside of any link or joint, strict.
    pub(super) fn top() -> Context {
        Context {
            owner: None,
            strict: true,
        }
    }

    /// Inside link or joint `owner`, strict.
    pub(super) fn owner(owner: String) -> Context {
        Context {
            owner: Some(owner),
            strict: true,
        }
    }

    /// The same owner, tolerant: problems become warnings.
    pub(super) fn tolerant(&self) -> Context {
        Context {
            owner: self.owner.clone(),
            strict: false,
        }
    }
}

/// The most warnings kept one by one; the rest are counted in one last warning.
const MAX_WARNINGS: usize = 10;

/// The problems found so far in one document.
pub(super) struct Report<'d, 'input> {
    doc: &'d Document<'input>,
    /// The byte offset where each line starts, to place problems quickly (the parser's own
    /// lookup counts from the start of the text each time).
    line_starts: Vec<usize>,
    /// The first errors, at most [`super::MAX_ERRORS`].
    pub(super) errors: Vec<FormatIssue>,
    /// Errors beyond [`super::MAX_ERRORS`].
    pub(super) more_errors: usize,
    pub(super) warnings: Vec<FormatIssue>,
    /// Warnings beyond [`MAX_WARNINGS`].
    pub(super) more_warnings: usize,
}

impl<'d, 'input> Report<'d, 'input> {
    pub(super) fn new(doc: &'d Document<'input>) -> Self {
        let text = doc.input_text();
        let line_starts = std::iter::once(0)
            .chain(text.match_indices('\n').map(|(i, _)| i + 1))
            .collect();
        Report {
            doc,
            line_starts,
            errors: Vec::new(),
            more_errors: 0,
            warnings: Vec::new(),
            more_warnings: 0,
        }
    }

    /// A problem at byte offset `pos`: an error or a warning, as `ctx` says.
    pub(super) fn at(&mut self, pos: usize, ctx: &Context, message: String) {
        let (list, cap, more) = if ctx.strict {
            (&self.errors, super::MAX_ERRORS, &mut self.more_errors)
        } else {
            (&self.warnings, MAX_WARNINGS, &mut self.more_warnings)
        };
        if list.len() >= cap {
            *more += 1;
            return;
        }
        let (line, column) = self.position(pos);
        let issue = FormatIssue {
            line,
            column,
            context: ctx.owner.clone(),
            message,
        };
        if ctx.strict {
            self.errors.push(issue);
        } else {
            self.warnings.push(issue);
        }
    }

    /// Line and column (from 1, in characters) of byte offset `pos`.
    fn position(&self, pos: usize) -> (u32, u32) {
        let line = self.line_starts.partition_point(|&start| start <= pos);
        let start = self.line_starts[line - 1];
        let text = self.doc.input_text();
        let column = text.get(start..pos).map_or(0, |s| s.chars().count()) + 1;
        (line as u32, column as u32)
    }

    /// `line:column` of element `node`, for messages that point to another place.
    pub(super) fn place(&self, node: Node) -> String {
        let (line, column) = self.position(node.range().start);
        format!("{line}:{column}")
    }

    /// A problem with element `node` as a whole.
    pub(super) fn element(&mut self, node: Node, ctx: &Context, message: String) {
        self.at(node.range().start, ctx, message);
    }

    /// A warning, whatever the context's strictness.
    pub(super) fn warning(&mut self, node: Node, ctx: &Context, message: String) {
        self.element(node, &ctx.tolerant(), message);
    }
}
