//! Equations for people: the derived quantities of a robot as plain text, LaTeX or Markdown.
//!
//! Two forms:
//! - [`Form::Expanded`]: each entry is one formula, expanded and simplified with the
//!   trigonometric identities of [`Graph::expand_trig`], with textbook short names
//!   (`s1 = sin(q1)`, `c12 = cos(q1 + q2)`) explained in a legend. Readable for small robots;
//!   a term whose expansion exceeds [`ShowOptions::max_terms`] falls back to the program form,
//!   with a note.
//! - [`Form::Program`]: the closed-form expressions as a straight-line program, shared
//!   temporaries `t0, t1, ...` first, then the entries. Compact enough for large robots.
//!
//! Output is deterministic: it depends only on the model and the options.
//!
//! ```
//! use eomgen::report::{render, Form, Format, ShowOptions, Term};
//! let urdf = r#"<robot name="pendulum">
//!   <link name="base"/>
//!   <link name="arm">
//!     <inertial>
//!       <origin xyz="0 0 -0.5"/> <mass value="2"/>
//!       <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.001"/>
//!     </inertial>
//!   </link>
//!   <joint name="swing" type="continuous">
//!     <parent link="base"/> <child link="arm"/> <axis xyz="0 1 0"/>
//!   </joint>
//! </robot>"#;
//! let model = eomgen::urdf::load_str(urdf, "pendulum.urdf", &Default::default()).unwrap();
//! let d = eomgen::dynamics::Derivation::new(&model);
//! let opts = ShowOptions { terms: vec![Term::MassMatrix, Term::Gravity], ..Default::default() };
//! let text = render(&model, &d, &opts).unwrap();
//! assert!(text.contains("M11 = 0.51\n"));
//! assert!(text.contains("G1 = 9.81*s1\n"));
//! assert!(text.contains("s1 = sin(q1)"));
//! ```

mod base_parameters;
pub mod forms;
mod trig;

/// Numbers as the reports write them: `digits` significant digits, or the shortest exact
/// decimals with `None`.
pub use crate::cas::format_number;
pub use base_parameters::render_base_parameters;

use std::collections::BTreeSet;
use std::fmt::Write as _;

use crate::cas::{Graph, Id, Node, Program, Style, SymbolKind, Syntax};
use crate::dynamics::{pairs, Derivation, Evaluation};
use crate::model::{JointKind, Model};

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
    fn title(self) -> (&'static str, &'static str) {
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

/// The output language.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Format {
    /// Plain text: `M11 = 2*m_link2*c2 + ...`.
    #[default]
    Text,
    /// LaTeX `aligned` blocks, with `%` comments for headings.
    Latex,
    /// Markdown with LaTeX display math (`$$`), as GitHub renders it.
    Markdown,
}

/// How entries are written.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Form {
    /// One simplified formula per entry.
    #[default]
    Expanded,
    /// Shared temporaries, then the entries.
    Program,
    /// `M` and `b` as sums of each body's share, from its Jacobians (projected Newton-Euler),
    /// expanded; [`ShowOptions::terms`] and [`ShowOptions::entry`] do not apply.
    ProjectedNewtonEuler,
    /// The Hamiltonian and Hamilton's equations, expanded; [`ShowOptions::terms`] and
    /// [`ShowOptions::entry`] do not apply.
    Hamiltonian,
}

/// What [`render`] prints.
#[derive(Clone, Debug)]
pub struct ShowOptions {
    /// The terms, printed in this order.
    pub terms: Vec<Term>,
    /// One entry only, 1-based: `[i, j]` for matrices (for `B`, `[i, column]` or `[i, j, k]`
    /// with the pair `j < k`), `[i]` for vectors. Needs exactly one term; not for `T` and `V`.
    pub entry: Option<Vec<usize>>,
    /// Plain text, LaTeX or Markdown.
    pub format: Format,
    /// Expanded formulas or a straight-line program.
    pub form: Form,
    /// Significant digits of numbers; `None` prints the shortest text that reads back exactly.
    pub digits: Option<usize>,
    /// Most terms an expansion may reach before the term falls back to the program form.
    pub max_terms: usize,
    /// The URDF's name for the heading (a file name, not a path, keeps output portable).
    pub source: Option<String>,
    /// With [`Format::Latex`]: a complete document (`\documentclass` to `\end{document}`,
    /// each term an `align*` that may break across pages) instead of fragments to paste.
    pub standalone: bool,
}

impl Default for ShowOptions {
    /// Every term, plain text, expanded, 6 significant digits, at most 100 terms per entry.
    fn default() -> Self {
        ShowOptions {
            terms: Term::ALL.to_vec(),
            entry: None,
            format: Format::Text,
            form: Form::Expanded,
            digits: Some(6),
            max_terms: 100,
            source: None,
            standalone: false,
        }
    }
}

/// Why [`render`] could not print.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ReportError {
    /// `entry` does not name an entry of the term.
    #[error("entry {entry} {reason}")]
    InvalidEntry { entry: String, reason: String },
    /// `d tau / d q` was asked for but not derived, or is too large to print.
    #[error("{0}")]
    Derivatives(String),
    /// Expanding the equations for print ran into the expression graph's node limit.
    #[error("{0} while expanding the equations for print: try --form program")]
    GraphFull(#[from] crate::cas::GraphFull),
    /// A form of the equations is too large to print (see [`forms::FORMS_MAX_OPS`]), or not
    /// available for the robot.
    #[error("{0}")]
    TooLarge(String),
}

/// In an expanded numeric entry, terms below this fraction of the entry's largest coefficient
/// are rounding noise (from rotations like `rpy="0 0 1.5708"`) and are not printed.
pub const NOISE: f64 = 1e-12;

/// `d tau / d q` is printed when its straight-line program has at most this many operations
/// (the 6-joint UR5 and Kinova arms have about 1,500 and 3,200, the 9-joint panda 5,800);
/// beyond, `show` refuses it with an error that points to generated code.
pub const DTAU_DQ_MAX_OPS: usize = 4000;

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
fn all_entries(d: &Derivation, term: Term) -> Result<Vec<(Vec<usize>, Id)>, ReportError> {
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
fn one_entry(d: &Derivation, term: Term, entry: &[usize]) -> Result<(Vec<usize>, Id), ReportError> {
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
fn entry_name(term: Term, idx: &[usize], dof: usize, syntax: Syntax) -> String {
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
struct Section {
    title: String,
    /// Expanded entries (name, expression), or the program form.
    body: Body,
    notes: Vec<String>,
}

enum Body {
    Expanded(Vec<(String, Id)>),
    Program(Vec<String>, Vec<Id>),
}

impl Section {
    fn roots(&self) -> Vec<Id> {
        match &self.body {
            Body::Expanded(v) => v.iter().map(|x| x.1).collect(),
            Body::Program(_, ids) => ids.clone(),
        }
    }
}

/// Builds one section: selects entries, expands them or schedules a program.
fn section(
    g: &mut Graph,
    d: &Derivation,
    term: Term,
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
    let (_, definition) = term.title();
    // A single entry of M needs no word on its symmetry.
    let skip = definition.is_empty() || (single && term == Term::MassMatrix);
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
    let title = term.title().0.to_string();
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
struct Entry {
    name: String,
    text: String,
    expr: Id,
}

/// A section of `entries` under `title`: expanded (the zeros left out unless `single`), or in
/// program form when an expansion exceeds [`ShowOptions::max_terms`] (a note says which).
#[allow(clippy::too_many_arguments)]
fn build_section(
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

/// What a parameter symbol stands for, from its name (see [`crate::kinematics::Params`]).
fn describe_param(name: &str) -> String {
    let Some((head, owner)) = name.split_once('_') else {
        return "a parameter".to_string();
    };
    match head {
        "m" => format!("mass of body {owner}"),
        "cx" | "cy" | "cz" => format!(
            "centre of mass of body {owner}, {} coordinate in its frame",
            &head[1..]
        ),
        h if h.starts_with('I') && h.len() == 3 => {
            format!("inertia {h} of body {owner} about its centre of mass, in its frame")
        }
        "x" | "y" | "z" => {
            format!("origin of joint {owner} in its parent's frame, {head} coordinate")
        }
        "Ia" => format!("rotor inertia (armature) of joint {owner}"),
        "damping" => format!("viscous damping of joint {owner}"),
        "friction" => format!("Coulomb friction of joint {owner}"),
        _ => "a parameter".to_string(),
    }
}

/// Where a parameter's default value comes from: the URDF, or an option for rotor inertia.
pub(crate) fn value_source(name: &str) -> &'static str {
    if name.starts_with("Ia_") {
        "armature option value"
    } else {
        "URDF value"
    }
}

fn kind_name(k: JointKind) -> &'static str {
    k.urdf_name()
}

/// A vector as `(1, 0, 0)`.
fn vec3(v: &nalgebra::Vector3<f64>, digits: Option<usize>) -> String {
    format!(
        "({}, {}, {})",
        format_number(v[0], digits),
        format_number(v[1], digits),
        format_number(v[2], digits)
    )
}

/// How formulas are printed for `opts`: LaTeX syntax for LaTeX and Markdown.
fn style_of(opts: &ShowOptions) -> Style {
    let syntax = match opts.format {
        Format::Text => Syntax::Text,
        Format::Latex | Format::Markdown => Syntax::Latex,
    };
    Style {
        syntax,
        digits: opts.digits,
    }
}

/// [`ShowOptions::entry`] cannot be printed, for `reason`.
fn invalid_entry(opts: &ShowOptions, reason: &str) -> ReportError {
    ReportError::InvalidEntry {
        entry: opts
            .entry
            .iter()
            .flatten()
            .map(|i| i.to_string())
            .collect::<Vec<_>>()
            .join(","),
        reason: reason.to_string(),
    }
}

/// Prints the chosen terms of a derived robot.
///
/// The heading lists the joints (`q1` is the first joint of the model's order); then each
/// term, under a heading with its definition; then a legend of the short names and symbolic
/// parameters used. Entries that are structurally 0 are not listed (a note says so), unless
/// [`ShowOptions::entry`] asks for one.
///
/// With [`Form::ProjectedNewtonEuler`] or [`Form::Hamiltonian`], prints that form of the
/// equations instead of the terms (fixed-base robots, at most [`forms::FORMS_MAX_OPS`]
/// operations, else [`ReportError::TooLarge`]).
///
/// Fails when [`ShowOptions::entry`] names no entry of the term (or is given with other than
/// exactly one term, or with another form), and when expanding the entries for print fills the
/// expression graph ([`ReportError::GraphFull`]).
pub fn render(model: &Model, d: &Derivation, opts: &ShowOptions) -> Result<String, ReportError> {
    if opts.entry.is_some() && opts.terms.len() != 1 {
        return Err(invalid_entry(opts, "needs exactly one term"));
    }
    let style = style_of(opts);
    let syntax = style.syntax;
    let mut g = d.graph.clone();
    let mut dropped = 0;
    let other_form = matches!(opts.form, Form::ProjectedNewtonEuler | Form::Hamiltonian);
    if other_form && opts.entry.is_some() {
        return Err(invalid_entry(
            opts,
            "is not for the projected Newton-Euler and Hamiltonian forms",
        ));
    }
    if other_form && model.is_floating() {
        return Err(ReportError::TooLarge(format!(
            "{}: the projected Newton-Euler and Hamiltonian forms are printed for fixed-base \
             robots only",
            model.name
        )));
    }
    let sections = match opts.form {
        Form::ProjectedNewtonEuler => {
            forms::projected_newton_euler(&mut g, model, d, opts, syntax, &mut dropped)?
        }
        Form::Hamiltonian => forms::hamiltonian(&mut g, model, d, opts, syntax, &mut dropped)?,
        Form::Expanded | Form::Program => {
            let mut sections = Vec::with_capacity(opts.terms.len());
            // Craig's velocity products need qd = dq/dt, which a floating base's velocities are not.
            let craig = |t: &Term| matches!(t, Term::CoriolisPairs | Term::Centrifugal);
            for &term in opts
                .terms
                .iter()
                .filter(|t| !(model.is_floating() && craig(t)))
            {
                let mut s = section(&mut g, d, term, opts, syntax, &mut dropped)?;
                if term == Term::Tau && model.include_friction {
                    let sign = if model.coulomb_smoothing > 0.0 {
                        format!(
                            "qd_i / sqrt(qd_i^2 + {}^2)",
                            format_number(model.coulomb_smoothing, opts.digits)
                        )
                    } else {
                        "sign(qd_i)".to_string()
                    };
                    s.notes.push(format!(
                        "Plus the joint friction F_i = damping_i qd_i + friction_i {sign}."
                    ));
                }
                sections.push(s);
                g.check()?;
            }
            sections
        }
    };
    let expanded_roots: Vec<Id> = sections
        .iter()
        .filter(|s| matches!(s.body, Body::Expanded(_)))
        .flat_map(|s| s.roots())
        .collect();
    let short = trig::short_names(&g, &expanded_roots, style, d.dof <= 9);
    let all_roots: Vec<Id> = sections.iter().flat_map(|s| s.roots()).collect();
    let used: BTreeSet<Id> = g.reachable(&all_roots).into_iter().collect();
    let params: Vec<(String, String)> = d
        .params
        .iter()
        .filter(|p| used.contains(&p.1))
        .map(|(name, id, v)| {
            let what = format!(
                "{} ({} {})",
                describe_param(name),
                value_source(name),
                format_number(*v, None)
            );
            (g.print(*id, style), what)
        })
        .collect();
    let uses_rates = used.iter().any(|&id| match g.node(id) {
        Node::Sym(s) => matches!(
            g.symbols()[*s as usize].kind,
            SymbolKind::Qd(_) | SymbolKind::Qdd(_)
        ),
        _ => false,
    });

    // The formulas of each section, as `(name, formula)` lines in the document's syntax.
    let bodies: Vec<Vec<(String, String)>> = sections
        .iter()
        .map(|s| match &s.body {
            Body::Expanded(v) => v
                .iter()
                .map(|(name, e)| (name.clone(), trig::shorten(&g.print(*e, style), &short)))
                .collect(),
            Body::Program(names, ids) => {
                let text = Program::new(&g, ids).print(names, style);
                let sep = if syntax == Syntax::Latex {
                    " &= "
                } else {
                    " = "
                };
                text.lines()
                    .map(|l| {
                        let l = l.trim_end_matches(" \\\\");
                        match l.split_once(sep) {
                            Some((a, b)) => (a.to_string(), b.to_string()),
                            None => (String::new(), l.to_string()),
                        }
                    })
                    .collect()
            }
        })
        .collect();

    let source = opts.source.as_deref().unwrap_or("URDF");
    let numbers = match opts.digits {
        Some(k) => format!("{k} significant digits"),
        None => "shortest exact decimals".to_string(),
    };
    let mut intro = vec![format!(
        "{} ({source}): {} degrees of freedom, gravity {} m/s^2.",
        model.name,
        d.dof,
        vec3(&model.gravity, opts.digits)
    )];
    intro.push(if params.is_empty() {
        format!("Numbers are the URDF's values, printed with {numbers}.")
    } else {
        format!(
            "Symbolic parameters are listed in the legend; other numbers are the URDF's \
             values, printed with {numbers}."
        )
    });
    if model.is_floating() {
        intro.extend(floating_intro(model));
    }
    if dropped > 0 {
        intro.push(format!(
            "Expanded entries omit {dropped} numeric term(s) below {NOISE:e} times the largest \
             of their entry (rounding noise; --form program shows every term)."
        ));
    }
    let q0 = model.base_nq();
    let mut joints: Vec<(String, String)> = Vec::new();
    if model.is_floating() {
        let q = |i: usize| g.print(d.q[i], style);
        let base = [
            (
                format!("{}, {}, {}", q(0), q(1), q(2)),
                "base position in the world",
            ),
            (
                format!("{}, {}, {}, {}", q(3), q(4), q(5), q(6)),
                "base orientation, unit quaternion x, y, z, w",
            ),
        ];
        joints.extend(base.map(|(q, w)| (q, w.to_string())));
    }
    joints.extend(model.joints.iter().enumerate().map(|(i, j)| {
        let coupling = model.coupling.get(i).copied();
        let index = coupling.map_or(i, |c| c.coordinate);
        let q = g.print(d.q[q0 + index], style);
        let mut what = format!(
            "{}, {} about {}",
            j.name,
            kind_name(j.kind),
            vec3(&j.axis, opts.digits)
        );
        // A mimic joint follows its coordinate: no symbol of its own.
        let q = match coupling {
            Some(c) if c.leader.is_some() => {
                let _ = write!(
                    what,
                    ", mimic joint: {} {q} + {}",
                    format_number(c.multiplier, opts.digits),
                    format_number(c.offset, opts.digits)
                );
                "mimic".to_string()
            }
            _ => q,
        };
        if j.armature != 0.0 {
            let _ = write!(
                what,
                ", rotor inertia {}",
                format_number(j.armature, opts.digits)
            );
        }
        if model.include_friction {
            let _ = write!(
                what,
                ", damping {}, friction {}",
                format_number(j.damping, opts.digits),
                format_number(j.friction, opts.digits)
            );
        }
        (q, what)
    }));
    let legend: Vec<(String, String)> = short
        .iter()
        .map(|s| (s.short().to_string(), s.meaning.clone()))
        .collect();
    let mut legend_text: Vec<(String, String)> = Vec::new();
    if uses_rates {
        legend_text.push((
            "qd_i, qdd_i".into(),
            "velocity and acceleration of q_i".into(),
        ));
    }
    for (sym, what) in &params {
        legend_text.push((sym.clone(), what.clone()));
    }

    let mut out = String::new();
    match opts.format {
        Format::Text => {
            for l in &intro {
                let _ = writeln!(out, "{l}");
            }
            let _ = writeln!(out, "Joints:");
            for (q, what) in &joints {
                let _ = writeln!(out, "  {q}: {what}");
            }
            for (s, body) in sections.iter().zip(&bodies) {
                let _ = writeln!(out, "\n{}:", s.title);
                for n in &s.notes {
                    let _ = writeln!(out, "  ({n})");
                }
                for (name, f) in body {
                    let _ = writeln!(out, "  {name} = {f}");
                }
            }
            if !legend.is_empty() || !legend_text.is_empty() {
                let _ = writeln!(out, "\nLegend:");
                for (a, b) in &legend {
                    let _ = writeln!(out, "  {a} = {b}");
                }
                for (a, b) in &legend_text {
                    let _ = writeln!(out, "  {a}: {b}");
                }
            }
        }
        Format::Latex if opts.standalone => {
            latex_document(&mut out, &model.name, &intro, &joints, &sections, &bodies);
            if !legend.is_empty() || !legend_text.is_empty() {
                let _ = writeln!(out, "\\section*{{Legend}}");
                for (a, b) in &legend_text {
                    let _ = writeln!(out, "${a}$: {}\n", tex_escape(b));
                }
                if !legend.is_empty() {
                    align(&mut out, &legend);
                }
            }
            let _ = writeln!(out, "\\end{{document}}");
        }
        Format::Latex => {
            for l in &intro {
                let _ = writeln!(out, "% {l}");
            }
            let _ = writeln!(out, "% Joints:");
            for (q, what) in &joints {
                let _ = writeln!(out, "%   {q}: {what}");
            }
            for (s, body) in sections.iter().zip(&bodies) {
                let _ = writeln!(out, "\n% {}", s.title);
                for n in &s.notes {
                    let _ = writeln!(out, "% {n}");
                }
                aligned(&mut out, body);
            }
            if !legend.is_empty() || !legend_text.is_empty() {
                let _ = writeln!(out, "\n% Legend");
                for (a, b) in &legend_text {
                    let _ = writeln!(out, "% {a}: {b}");
                }
                if !legend.is_empty() {
                    aligned(&mut out, &legend);
                }
            }
        }
        Format::Markdown => {
            let _ = writeln!(out, "# {}: equations of motion\n", md_escape(&model.name));
            for l in &intro {
                let _ = writeln!(out, "{}", md_escape(l));
            }
            let _ = writeln!(out, "\n| coordinate | joint |\n| --- | --- |");
            for (q, what) in &joints {
                let _ = writeln!(out, "| ${q}$ | {} |", md_escape(what));
            }
            for (s, body) in sections.iter().zip(&bodies) {
                let _ = writeln!(out, "\n## {}\n", s.title);
                for n in &s.notes {
                    let _ = writeln!(out, "{}\n", md_escape(n));
                }
                if !body.is_empty() {
                    let _ = writeln!(out, "$$");
                    aligned(&mut out, body);
                    let _ = writeln!(out, "$$");
                }
            }
            if !legend.is_empty() || !legend_text.is_empty() {
                let _ = writeln!(out, "\n## Legend\n\n| symbol | meaning |\n| --- | --- |");
                for (a, b) in &legend {
                    let _ = writeln!(out, "| ${a}$ | ${b}$ |");
                }
                for (a, b) in &legend_text {
                    let a = if a.starts_with("qd_i") {
                        "$\\dot{q}_i$, $\\ddot{q}_i$".to_string()
                    } else {
                        format!("${a}$")
                    };
                    let _ = writeln!(out, "| {a} | {} |", md_escape(b));
                }
            }
        }
    }
    Ok(out)
}

/// What the equations of a floating-base robot are, for the introduction.
fn floating_intro(model: &Model) -> Vec<String> {
    let nv = model.base_nv() + model.coordinates();
    vec![
        format!(
            "Floating base (a free flyer): M(q) qdd + b(q, qd) + G(q) = S^T tau + J_c(q)^T F_c, with {nv} \
             velocity coordinates: the first three are the base's linear velocity and the next three \
             its angular velocity, both in base axes, then the joints' rates follow."
        ),
        "The first six rows of tau are the force and torque on the base in base axes: S^T tau is zero there \
         (the robot's own efforts act on the joints only), so those rows are balanced by contact \
         forces J_c^T F_c (or thrust)."
            .to_string(),
    ]
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
fn align(out: &mut String, lines: &[(String, String)]) {
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
fn tex_escape(s: &str) -> String {
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
fn aligned(out: &mut String, lines: &[(String, String)]) {
    let _ = writeln!(out, "\\begin{{aligned}}");
    for (k, (a, b)) in lines.iter().enumerate() {
        let end = if k + 1 < lines.len() { " \\\\" } else { "" };
        let _ = writeln!(out, "{a} &= {b}{end}");
    }
    let _ = writeln!(out, "\\end{{aligned}}");
}

/// Escapes what Markdown would interpret in prose and table cells: `|`, `*`, backticks,
/// backslashes, `<`, and `_` unless it sits inside a word (`qd_j` stays readable).
fn md_escape(s: &str) -> String {
    let chars: Vec<char> = s.chars().collect();
    let mut out = String::with_capacity(s.len());
    for (k, &c) in chars.iter().enumerate() {
        let inside_word = k > 0
            && chars[k - 1].is_alphanumeric()
            && chars.get(k + 1).is_some_and(|n| n.is_alphanumeric());
        let special = matches!(c, '|' | '*' | '`' | '\\' | '<') || (c == '_' && !inside_word);
        if special {
            out.push('\\');
        }
        out.push(c);
    }
    out
}
