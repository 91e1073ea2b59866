//! Short names for the sines and cosines of joint angles: `s1 = sin(q1)`, `c12 = cos(q1 + q2)`,
//! `c2m1 = cos(q2 - q1)`, as in robotics textbooks.
//!
//! The names are substituted in the printed text rather than in the graph, so that the printer
//! keeps ordering terms as it does for `sin` and `cos` (trigonometric factors last).

use std::collections::BTreeMap;

use crate::cas::{Graph, Id, Node, Style, SymbolKind, Syntax};

/// Legend order: number of angles, `(joint, negative)` of each angle, cosine after sine.
type Key = (usize, Vec<(usize, bool)>, bool);

/// One shortened atom.
#[derive(Clone, Debug)]
pub(crate) struct ShortName {
    key: Key,
    /// The atom as the printer writes it (`cos(q1 + q2)`), in the document's syntax.
    long: String,
    /// The replacement (`c12`, `c_{12}`).
    short: String,
    /// The atom in the document's syntax, for the legend.
    pub meaning: String,
}

impl ShortName {
    /// The short name in the document's syntax.
    pub fn short(&self) -> &str {
        &self.short
    }
}

/// The joint angles of a `sin`/`cos` argument that is a sum of joint angles with coefficients
/// ±1: `(joint index, negative)`, positive angles first, each group ascending.
fn angles(g: &Graph, arg: Id) -> Option<Vec<(usize, bool)>> {
    let joint = |id: Id| match g.node(id) {
        Node::Sym(s) => match g.symbols()[*s as usize].kind {
            SymbolKind::Q(i) => Some(i),
            _ => None,
        },
        _ => None,
    };
    let mut out = match g.node(arg) {
        Node::Sym(_) => vec![(joint(arg)?, false)],
        Node::Add(c, ts) if c.get() == 0.0 => {
            let mut v = Vec::with_capacity(ts.len());
            for (t, k) in ts.iter() {
                let neg = if k.get() == 1.0 {
                    false
                } else if k.get() == -1.0 {
                    true
                } else {
                    return None;
                };
                v.push((joint(*t)?, neg));
            }
            v
        }
        _ => return None,
    };
    out.sort_by_key(|&(i, neg)| (neg, i));
    Some(out)
}

/// Short names for every `sin`/`cos` of joint angles reachable from `roots`, in legend order.
/// `compact` (at most 9 joints) writes indices as bare digits (`c12`); otherwise they are
/// separated (`c1_12`).
pub(crate) fn short_names(g: &Graph, roots: &[Id], style: Style, compact: bool) -> Vec<ShortName> {
    let latex = style.syntax == Syntax::Latex;
    let mut found: BTreeMap<Key, ShortName> = BTreeMap::new();
    for id in g.reachable(roots) {
        let (is_sin, arg) = match g.node(id) {
            Node::Sin(a) => (true, *a),
            Node::Cos(a) => (false, *a),
            _ => continue,
        };
        let Some(list) = angles(g, arg) else { continue };
        let mut index = String::new();
        for (k, &(i, neg)) in list.iter().enumerate() {
            let sep = match (neg, latex, compact) {
                (true, true, _) => "-",
                (true, false, _) => "m",
                (false, true, false) if k > 0 => ",",
                (false, false, false) if k > 0 => "_",
                _ => "",
            };
            index.push_str(sep);
            index.push_str(&(i + 1).to_string());
        }
        let letter = if is_sin { "s" } else { "c" };
        let short = if latex {
            format!("{letter}_{{{index}}}")
        } else {
            format!("{letter}{index}")
        };
        let long = g.print(id, style);
        let key = (list.len(), list.clone(), !is_sin);
        found.insert(
            key.clone(),
            ShortName {
                key,
                meaning: long.clone(),
                long,
                short,
            },
        );
    }
    let mut names: Vec<ShortName> = found.into_values().collect();
    names.sort_by(|a, b| a.key.cmp(&b.key));
    names
}

/// Replaces every shortened atom in `text` by its short name. Longer atoms go first, so that
/// no atom is replaced inside another.
pub(crate) fn shorten(text: &str, names: &[ShortName]) -> String {
    let mut order: Vec<&ShortName> = names.iter().collect();
    order.sort_by(|a, b| b.long.len().cmp(&a.long.len()).then(a.key.cmp(&b.key)));
    let mut out = text.to_string();
    for n in order {
        if out.contains(&n.long) {
            out = out.replace(&n.long, &n.short);
        }
    }
    out
}
