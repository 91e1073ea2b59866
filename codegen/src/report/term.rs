//! The quantities `show` prints as terms: their names, headings, and entries (`M12`,
//! `B1_23`, `tau2`) with the expressions of a derivation.

use super::{ReportError, DTAU_DQ_MAX_OPS};
use crate::cas::{Id, Program, Syntax};
use crate::dynamics::{pairs, Derivation, Evaluation};

/// A derived quantity that can be printed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Term {
    /// `M(q)`, printed as its upper triangle.
    MassMatrix,
    /// Craig's Coriolis matrix `B(q)`, N x N(N-1)/2.
    CoriolisPairs,
    /// Craig's centrifugal matrix `C(q)`, N x N.
    Centrifugal,
    /// `G(q)`.
    Gravity,
    /// `b(q, qd)`: Coriolis and centrifugal terms without gravity.
    Bias,
    /// The Christoffel-form Coriolis matrix `C(q, qd)`.
    CoriolisMatrix,
    /// `tau = M qdd + b + G`.
    Tau,
    /// Kinetic energy `T`.
    KineticEnergy,
    /// Potential energy `V`.
    PotentialEnergy,
    /// The derivatives of inverse dynamics in the joint positions, `d tau / d q` (needs a
    /// derivation with [`Derivation::add_derivatives`]; not in [`Term::ALL`]).
    DtauDq,
}

impl Term {
    /// Every term, in print order.
    pub const ALL: [Term; 9] = [
        Term::MassMatrix,
        Term::CoriolisPairs,
        Term::Centrifugal,
        Term::Gravity,
        Term::Bias,
        Term::CoriolisMatrix,
        Term::Tau,
        Term::KineticEnergy,
        Term::PotentialEnergy,
    ];

    /// The command-line name: `M`, `B`, `C`, `G`, `b`, `coriolis`, `tau`, `T`, `V`, `dtau_dq`.
    pub fn label(self) -> &'static str {
        match self {
            Term::MassMatrix => "M",
            Term::CoriolisPairs => "B",
            Term::Centrifugal => "C",
            Term::Gravity => "G",
            Term::Bias => "b",
            Term::CoriolisMatrix => "coriolis",
            Term::Tau => "tau",
            Term::KineticEnergy => "T",
            Term::PotentialEnergy => "V",
            Term::DtauDq => "dtau_dq",
        }
    }

    /// Parses a [`Term::label`] (case matters: `B` and `b` differ) or a long name such as
    /// `mass_matrix`, `coriolis_pairs`, `centrifugal`, `gravity`, `bias`, `coriolis_matrix`,
    /// `kinetic_energy`, `potential_energy`; and `dtau_dq`.
    pub fn parse(s: &str) -> Option<Term> {
        let long = [
            "mass_matrix",
            "coriolis_pairs",
            "centrifugal",
            "gravity",
            "bias",
            "coriolis_matrix",
            "tau",
            "kinetic_energy",
            "potential_energy",
        ];
        Term::ALL
            .iter()
            .zip(long)
            .find(|(t, l)| t.label() == s || *l == s)
            .map(|(t, _)| *t)
            .or((s == Term::DtauDq.label()).then_some(Term::DtauDq))
    }

    /// Heading and the sentence that defines the term.
    pub(super) fn title(self) -> (&'static str, &'static str) {
        match self {
            Term::MassMatrix => (
                "Mass matrix M(q)",
                "Symmetric: entries below the diagonal are not shown.",
            ),
            Term::CoriolisPairs => (
                "Craig's Coriolis matrix B(q)",
                "B_i,jk multiplies qd_j qd_k (j < k): b = B(q) [qd qd] + C(q) [qd^2].",
            ),
            Term::Centrifugal => ("Craig's centrifugal matrix C(q)", "C_ij multiplies qd_j^2."),
            Term::Gravity => ("Gravity G(q) = dV/dq", ""),
            Term::Bias => (
                "Bias b(q, qd) = B(q) [qd qd] + C(q) [qd^2]",
                "Coriolis and centrifugal terms, without gravity.",
            ),
            Term::CoriolisMatrix => (
                "Coriolis matrix C(q, qd), Christoffel form",
                "Cqd_ij = sum_k Gamma_ijk qd_k: b = C(q, qd) qd, and dM/dt - 2 C(q, qd) is \
                 skew-symmetric.",
            ),
            Term::Tau => ("Inverse dynamics tau = M(q) qdd + b(q, qd) + G(q)", ""),
            Term::KineticEnergy => ("Kinetic energy T = qd^T M(q) qd / 2", ""),
            Term::PotentialEnergy => ("Potential energy V = -sum over bodies of m g.c", ""),
            Term::DtauDq => (
                "Derivatives of inverse dynamics d tau / d q (q, qd, qdd)",
                "dtau_i/dq_j: how joint effort i changes with joint position j.",
            ),
        }
    }
}

/// `d tau / d q` of a derivation with derivatives, row-major, or why it cannot be printed.
fn dtau_dq(d: &Derivation) -> Result<Vec<Vec<Id>>, ReportError> {
    let n = d.dof;
    let Some(Evaluation::Exprs(ids)) = d.quantity("inverse_dynamics_derivatives").map(|q| &q.eval)
    else {
        return Err(ReportError::Derivatives(
            "d tau / d q was not derived: derive with Builder::derivatives (show --derivatives)"
                .to_string(),
        ));
    };
    let dq = &ids[..n * n];
    let ops = Program::new(&d.graph, dq).ops().total();
    if ops > DTAU_DQ_MAX_OPS {
        return Err(ReportError::Derivatives(format!(
            "d tau / d q is too large to print ({ops} operations, more than {DTAU_DQ_MAX_OPS}): \
             generate it as code with `eomgen generate --derivatives`"
        )));
    }
    Ok(dq.chunks(n.max(1)).map(|r| r.to_vec()).collect())
}

/// Every entry of a term: 0-based indices (`[i, j, k]` for `B`) and expression.
pub(super) fn all_entries(
    d: &Derivation,
    term: Term,
) -> Result<Vec<(Vec<usize>, Id)>, ReportError> {
    let n = d.dof;
    let square = |m: &Vec<Vec<Id>>, upper: bool| -> Vec<(Vec<usize>, Id)> {
        (0..n)
            .flat_map(|i| {
                let from = if upper { i } else { 0 };
                (from..n).map(move |j| (vec![i, j], m[i][j]))
            })
            .collect()
    };
    let vector = |v: &Vec<Id>| -> Vec<(Vec<usize>, Id)> {
        v.iter().enumerate().map(|(i, &e)| (vec![i], e)).collect()
    };
    Ok(match term {
        Term::MassMatrix => square(&d.mass_matrix, true),
        Term::Centrifugal => square(&d.centrifugal, false),
        Term::CoriolisMatrix => square(&d.coriolis_matrix, false),
        Term::CoriolisPairs => {
            let pl = pairs(n);
            (0..n)
                .flat_map(|i| {
                    pl.iter()
                        .enumerate()
                        .map(move |(p, &(j, k))| (vec![i, j, k], d.coriolis_pairs[i][p]))
                })
                .collect()
        }
        Term::Gravity => vector(&d.gravity),
        Term::Bias => vector(&d.bias),
        Term::Tau => vector(&d.tau),
        Term::KineticEnergy => vec![(vec![], d.kinetic_energy)],
        Term::PotentialEnergy => vec![(vec![], d.potential_energy)],
        Term::DtauDq => square(&dtau_dq(d)?, false),
    })
}

/// The one entry named by a 1-based `entry`.
pub(super) fn one_entry(
    d: &Derivation,
    term: Term,
    entry: &[usize],
) -> Result<(Vec<usize>, Id), ReportError> {
    let n = d.dof;
    let text = entry
        .iter()
        .map(|i| i.to_string())
        .collect::<Vec<_>>()
        .join(",");
    let err = |reason: String| ReportError::InvalidEntry {
        entry: text.clone(),
        reason,
    };
    let np = n * n.saturating_sub(1) / 2;
    let in_range = |i: usize, len: usize| (1..=len).contains(&i);
    let idx: Vec<usize> = entry.iter().map(|i| i.wrapping_sub(1)).collect();
    match (term, entry) {
        (Term::KineticEnergy | Term::PotentialEnergy, _) => Err(err(format!(
            "given, but {} is a scalar: leave out --entry",
            term.label()
        ))),
        (Term::Gravity | Term::Bias | Term::Tau, &[i]) if in_range(i, n) => {
            let v = match term {
                Term::Gravity => &d.gravity,
                Term::Bias => &d.bias,
                _ => &d.tau,
            };
            Ok((idx.clone(), v[idx[0]]))
        }
        (Term::Gravity | Term::Bias | Term::Tau, _) => Err(err(format!(
            "is not an entry of {}: give one index from 1 to {n}",
            term.label()
        ))),
        (Term::MassMatrix | Term::Centrifugal | Term::CoriolisMatrix, &[i, j])
            if in_range(i, n) && in_range(j, n) =>
        {
            let m = match term {
                Term::MassMatrix => &d.mass_matrix,
                Term::Centrifugal => &d.centrifugal,
                _ => &d.coriolis_matrix,
            };
            Ok((idx.clone(), m[idx[0]][idx[1]]))
        }
        (Term::DtauDq, &[i, j]) if in_range(i, n) && in_range(j, n) => {
            Ok((idx.clone(), dtau_dq(d)?[idx[0]][idx[1]]))
        }
        (Term::MassMatrix | Term::Centrifugal | Term::CoriolisMatrix | Term::DtauDq, _) => {
            Err(err(format!(
                "is not an entry of {}: give I,J with both from 1 to {n}",
                term.label()
            )))
        }
        (Term::CoriolisPairs, &[i, p]) if in_range(i, n) && in_range(p, np) => {
            let (j, k) = pairs(n)[p - 1];
            Ok((vec![i - 1, j, k], d.coriolis_pairs[i - 1][p - 1]))
        }
        (Term::CoriolisPairs, &[i, j, k])
            if in_range(i, n) && in_range(j, n) && in_range(k, n) && j != k =>
        {
            let (j, k) = (j.min(k) - 1, j.max(k) - 1);
            let p = pairs(n).iter().position(|&x| x == (j, k)).expect("a pair");
            Ok((vec![i - 1, j, k], d.coriolis_pairs[i - 1][p]))
        }
        (Term::CoriolisPairs, _) => Err(err(format!(
            "is not an entry of B: give I,P (row 1 to {n}, column 1 to {np}) or I,J,K (the \
             pair J < K)"
        ))),
    }
}

/// The printed name of an entry: `M12`, `B1_23`, `G1`, `tau2`, `T` (text) or `M_{12}` (LaTeX);
/// with more than 9 joints, matrix indices are separated (`M1,12`).
pub(super) fn entry_name(term: Term, idx: &[usize], dof: usize, syntax: Syntax) -> String {
    let latex = syntax == Syntax::Latex;
    let compact = dof <= 9;
    let one = |i: usize| (i + 1).to_string();
    let pair = |a: usize, b: usize| {
        if compact {
            format!("{}{}", a + 1, b + 1)
        } else {
            format!("{},{}", a + 1, b + 1)
        }
    };
    let base = match (term, latex) {
        (Term::MassMatrix, _) => "M",
        (Term::CoriolisPairs, _) => "B",
        (Term::Centrifugal, _) => "C",
        (Term::CoriolisMatrix, false) => "Cqd",
        (Term::CoriolisMatrix, true) => "C^{\\dot{q}}",
        (Term::Gravity, _) => "G",
        (Term::Bias, _) => "b",
        (Term::Tau, false) => "tau",
        (Term::Tau, true) => "\\tau",
        (Term::KineticEnergy, _) => "T",
        (Term::PotentialEnergy, _) => "V",
        (Term::DtauDq, _) => return dtau_dq_name(idx, latex),
    };
    let sub = match idx {
        [] => return base.to_string(),
        [i] => one(*i),
        [i, j] => pair(*i, *j),
        [i, j, k] => {
            if compact && !latex {
                format!("{}_{}{}", i + 1, j + 1, k + 1)
            } else if compact {
                format!("{},{}{}", i + 1, j + 1, k + 1)
            } else {
                format!("{},({},{})", i + 1, j + 1, k + 1)
            }
        }
        _ => unreachable!("entries have at most three indices"),
    };
    if latex {
        format!("{base}_{{{sub}}}")
    } else {
        format!("{base}{sub}")
    }
}

/// `dtau1/dq2` (text) or `\partial\tau_{1}/\partial q_{2}` (LaTeX).
fn dtau_dq_name(idx: &[usize], latex: bool) -> String {
    let (i, j) = (idx[0] + 1, idx[1] + 1);
    if latex {
        format!("\\partial\\tau_{{{i}}}/\\partial q_{{{j}}}")
    } else {
        format!("dtau{i}/dq{j}")
    }
}
