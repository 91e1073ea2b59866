//! The quantities `show` prints, from their catalogue [`Notation`]: which are asked for, and
//! their entries (`M12`, `B1_23`, `tau2`, `dtau1/dq2`) with the expressions of a derivation.

use super::{ReportError, DTAU_DQ_MAX_OPS};
use crate::cas::{Id, Program, Syntax};
use crate::dynamics::catalogue::{Layout, Notation, NOTATIONS};
use crate::dynamics::{pairs, Derivation};

/// The printed quantities named in `names` (generated names or their symbols, `all` for every
/// quantity but the derivatives), each once, in the order asked; `Err` with the first unknown
/// name.
pub fn resolve(names: &[String]) -> Result<Vec<&'static Notation>, String> {
    let mut out: Vec<&'static Notation> = Vec::new();
    for name in names {
        let found: Vec<&'static Notation> = if name == "all" {
            NOTATIONS
                .iter()
                .filter(|n| n.layout != Layout::Partials)
                .collect()
        } else {
            let n = NOTATIONS.iter().find(|n| n.is_named(name));
            vec![n.ok_or_else(|| name.clone())?]
        };
        for n in found {
            if !out.iter().any(|o| o.name == n.name) {
                out.push(n);
            }
        }
    }
    Ok(out)
}

/// The printed expressions of `n`, or why they cannot be printed: not derived (derivatives
/// without `Builder::derivatives`), or too large (derivatives over [`DTAU_DQ_MAX_OPS`]).
fn printed(d: &Derivation, n: &Notation) -> Result<Vec<Id>, ReportError> {
    let Some(ids) = (n.printed)(d) else {
        return Err(ReportError::Derivatives(
            "d tau / d q was not derived: derive with Builder::derivatives (show --derivatives)"
                .to_string(),
        ));
    };
    if n.layout == Layout::Partials {
        let ops = Program::new(&d.graph, &ids).ops().total();
        if ops > DTAU_DQ_MAX_OPS {
            return Err(ReportError::Derivatives(format!(
                "d tau / d q is too large to print ({ops} operations, more than {DTAU_DQ_MAX_OPS}): \
                 generate it as code with `eomgen generate --derivatives`"
            )));
        }
    }
    Ok(ids)
}

/// The number of columns of `n`'s printed matrix for `dof` joints.
fn columns(n: &Notation, dof: usize) -> usize {
    match n.layout {
        Layout::Pairs => dof * dof.saturating_sub(1) / 2,
        _ => dof,
    }
}

/// Every entry of a quantity: 0-based indices (`[i, j, k]` for Craig's pairs) and expression.
pub(super) fn all_entries(
    d: &Derivation,
    n: &Notation,
) -> Result<Vec<(Vec<usize>, Id)>, ReportError> {
    let ids = printed(d, n)?;
    let (dof, cols) = (d.dof, columns(n, d.dof));
    let at = |i: usize, j: usize| ids[i * cols + j];
    Ok(match n.layout {
        Layout::Scalar => vec![(vec![], ids[0])],
        Layout::Vector => ids.iter().enumerate().map(|(i, &e)| (vec![i], e)).collect(),
        Layout::Symmetric | Layout::Square | Layout::Partials => {
            let upper = n.layout == Layout::Symmetric;
            (0..dof)
                .flat_map(|i| {
                    let from = if upper { i } else { 0 };
                    (from..dof).map(move |j| (vec![i, j], at(i, j)))
                })
                .collect()
        }
        Layout::Pairs => {
            let pl = pairs(dof);
            (0..dof)
                .flat_map(|i| {
                    let pl = &pl;
                    (0..cols).map(move |p| (vec![i, pl[p].0, pl[p].1], at(i, p)))
                })
                .collect()
        }
    })
}

/// The one entry named by a 1-based `entry`.
pub(super) fn one_entry(
    d: &Derivation,
    n: &Notation,
    entry: &[usize],
) -> Result<(Vec<usize>, Id), ReportError> {
    let dof = d.dof;
    let err = |reason: String| ReportError::InvalidEntry {
        entry: entry
            .iter()
            .map(|i| i.to_string())
            .collect::<Vec<_>>()
            .join(","),
        reason,
    };
    let np = columns(n, dof);
    let in_range = |i: usize, len: usize| (1..=len).contains(&i);
    let idx: Vec<usize> = entry.iter().map(|i| i.wrapping_sub(1)).collect();
    let label = n.aliases.first().copied().unwrap_or(n.name);
    match (n.layout, entry) {
        (Layout::Scalar, _) => Err(err(format!(
            "given, but {label} is a scalar: leave out --entry"
        ))),
        (Layout::Vector, &[i]) if in_range(i, dof) => Ok((idx.clone(), printed(d, n)?[idx[0]])),
        (Layout::Vector, _) => Err(err(format!(
            "is not an entry of {label}: give one index from 1 to {dof}"
        ))),
        (Layout::Symmetric | Layout::Square | Layout::Partials, &[i, j])
            if in_range(i, dof) && in_range(j, dof) =>
        {
            Ok((idx.clone(), printed(d, n)?[idx[0] * dof + idx[1]]))
        }
        (Layout::Symmetric | Layout::Square | Layout::Partials, _) => Err(err(format!(
            "is not an entry of {label}: give I,J with both from 1 to {dof}"
        ))),
        (Layout::Pairs, &[i, p]) if in_range(i, dof) && in_range(p, np) => {
            let (j, k) = pairs(dof)[p - 1];
            Ok((vec![i - 1, j, k], printed(d, n)?[(i - 1) * np + p - 1]))
        }
        (Layout::Pairs, &[i, j, k])
            if in_range(i, dof) && in_range(j, dof) && in_range(k, dof) && j != k =>
        {
            let (j, k) = (j.min(k) - 1, j.max(k) - 1);
            let p = pairs(dof)
                .iter()
                .position(|&x| x == (j, k))
                .expect("a pair");
            Ok((vec![i - 1, j, k], printed(d, n)?[(i - 1) * np + p]))
        }
        (Layout::Pairs, _) => Err(err(format!(
            "is not an entry of {label}: give I,P (row 1 to {dof}, column 1 to {np}) or I,J,K \
             (the pair J < K)"
        ))),
    }
}

/// The printed name of an entry: `M12`, `B1_23`, `G1`, `tau2`, `T` (text) or `M_{12}` (LaTeX);
/// with more than 9 joints, matrix indices are separated (`M1,12`).
pub(super) fn entry_name(n: &Notation, idx: &[usize], dof: usize, syntax: Syntax) -> String {
    let latex = syntax == Syntax::Latex;
    if n.layout == Layout::Partials {
        return partial_name(idx, latex);
    }
    let compact = dof <= 9;
    let base = if latex { n.latex } else { n.text };
    let sub = match idx {
        [] => return base.to_string(),
        [i] => (i + 1).to_string(),
        [i, j] if compact => format!("{}{}", i + 1, j + 1),
        [i, j] => format!("{},{}", i + 1, j + 1),
        [i, j, k] if compact && !latex => format!("{}_{}{}", i + 1, j + 1, k + 1),
        [i, j, k] if compact => format!("{},{}{}", i + 1, j + 1, k + 1),
        [i, j, k] => format!("{},({},{})", i + 1, j + 1, k + 1),
        _ => unreachable!("entries have at most three indices"),
    };
    if latex {
        format!("{base}_{{{sub}}}")
    } else {
        format!("{base}{sub}")
    }
}

/// `dtau1/dq2` (text) or `\partial\tau_{1}/\partial q_{2}` (LaTeX).
fn partial_name(idx: &[usize], latex: bool) -> String {
    let (i, j) = (idx[0] + 1, idx[1] + 1);
    if latex {
        format!("\\partial\\tau_{{{i}}}/\\partial q_{{{j}}}")
    } else {
        format!("dtau{i}/dq{j}")
    }
}
