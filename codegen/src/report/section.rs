//! A printed term: its entries expanded with the trigonometric identities (rounding noise
//! dropped), or as a straight-line program when an expansion grows too large.

use super::term::{all_entries, entry_name, one_entry};
use super::{Form, ReportError, ShowOptions, NOISE};
use crate::cas::{Graph, Id, Node, SymbolKind, Syntax};
use crate::dynamics::catalogue::{Layout, Notation};
use crate::dynamics::Derivation;

/// True when `e` contains a parameter symbol.
fn has_param(g: &Graph, e: Id) -> bool {
    g.reachable(&[e]).iter().any(|&id| match g.node(id) {
        Node::Sym(s) => g.symbols()[*s as usize].kind == SymbolKind::Param,
        _ => false,
    })
}

/// Drops the numeric terms of an expanded sum that are below [`NOISE`] times its largest
/// numeric coefficient. Returns the new expression and how many terms went.
fn drop_noise(g: &mut Graph, e: Id) -> (Id, usize) {
    let (c, ts) = match g.node(e) {
        Node::Add(c, ts) => (c.get(), ts.to_vec()),
        _ => return (e, 0),
    };
    let numeric: Vec<bool> = ts.iter().map(|(t, _)| !has_param(g, *t)).collect();
    let scale = ts
        .iter()
        .zip(&numeric)
        .filter(|(_, &n)| n)
        .map(|((_, k), _)| k.get().abs())
        .fold(c.abs(), f64::max);
    let tol = NOISE * scale;
    let mut dropped = 0;
    let mut kept = Vec::with_capacity(ts.len());
    for ((t, k), &n) in ts.iter().zip(&numeric) {
        if n && k.get().abs() < tol {
            dropped += 1;
        } else {
            kept.push((*t, k.get()));
        }
    }
    let c = if c != 0.0 && c.abs() < tol {
        dropped += 1;
        0.0
    } else {
        c
    };
    if dropped == 0 {
        return (e, 0);
    }
    (g.sum(c, kept), dropped)
}

/// One printed term.
pub(super) struct Section {
    pub(super) title: String,
    /// Expanded entries (name, expression), or the program form.
    pub(super) body: Body,
    pub(super) notes: Vec<String>,
}

pub(super) enum Body {
    Expanded(Vec<(String, Id)>),
    Program(Vec<String>, Vec<Id>),
}

impl Section {
    pub(super) fn roots(&self) -> Vec<Id> {
        match &self.body {
            Body::Expanded(v) => v.iter().map(|x| x.1).collect(),
            Body::Program(_, ids) => ids.clone(),
        }
    }
}

/// Builds one section: selects entries, expands them or schedules a program.
pub(super) fn section(
    g: &mut Graph,
    d: &Derivation,
    term: &Notation,
    opts: &ShowOptions,
    syntax: Syntax,
    dropped: &mut usize,
) -> Result<Section, ReportError> {
    let single = opts.entry.is_some();
    let entries = match &opts.entry {
        Some(e) => vec![one_entry(d, term, e)?],
        None => all_entries(d, term)?,
    };
    let mut notes = Vec::new();
    let definition = term.definition;
    // A single entry of M needs no word on its symmetry.
    let skip = definition.is_empty() || (single && term.layout == Layout::Symmetric);
    if !skip {
        notes.push(definition.to_string());
    }
    let structural: Vec<Entry> = entries
        .into_iter()
        .filter(|(_, e)| single || g.as_const(*e) != Some(0.0))
        .map(|(idx, e)| Entry {
            name: entry_name(term, &idx, d.dof, syntax),
            text: entry_name(term, &idx, d.dof, Syntax::Text),
            expr: e,
        })
        .collect();
    let omitted_zero = !single && structural.len() < all_entries(d, term)?.len();
    let title = term.title.to_string();
    build_section(
        g,
        title,
        notes,
        structural,
        opts,
        single,
        omitted_zero,
        dropped,
    )
}

/// An entry to print: its name in the document's syntax and in plain text (for notes), and
/// its expression.
pub(super) struct Entry {
    pub(super) name: String,
    pub(super) text: String,
    pub(super) expr: Id,
}

/// A section of `entries` under `title`: expanded (the zeros left out unless `single`), or in
/// program form when an expansion exceeds [`ShowOptions::max_terms`] (a note says which).
#[allow(clippy::too_many_arguments)]
pub(super) fn build_section(
    g: &mut Graph,
    title: String,
    mut notes: Vec<String>,
    structural: Vec<Entry>,
    opts: &ShowOptions,
    single: bool,
    mut omitted_zero: bool,
    dropped: &mut usize,
) -> Result<Section, ReportError> {
    let mut body = None;
    if opts.form != Form::Program {
        let mut out = Vec::with_capacity(structural.len());
        let mut noise = 0;
        let mut too_large = None;
        for entry in &structural {
            let Ok(x) = g.expand_trig(entry.expr, opts.max_terms) else {
                too_large = Some(entry.text.clone());
                break;
            };
            let (x, k) = drop_noise(g, x);
            noise += k;
            if single || g.as_const(x) != Some(0.0) {
                out.push((entry.name.clone(), x));
            } else {
                omitted_zero = true;
            }
        }
        match too_large {
            None => {
                *dropped += noise;
                body = Some(Body::Expanded(out));
            }
            Some(culprit) => notes.push(format!(
                "Program form: the expansion of {culprit} exceeds {} terms.",
                opts.max_terms
            )),
        }
    }
    let body = match body {
        Some(b) => b,
        None => {
            let names = structural.iter().map(|e| e.name.clone()).collect();
            let ids = structural.iter().map(|e| e.expr).collect();
            Body::Program(names, ids)
        }
    };
    let empty = match &body {
        Body::Expanded(v) => v.is_empty(),
        Body::Program(_, ids) => ids.is_empty(),
    };
    if empty {
        notes.push("Every entry is 0.".to_string());
    } else if omitted_zero {
        notes.push("Entries not listed are 0.".to_string());
    }
    g.check()?;
    Ok(Section { title, body, notes })
}
