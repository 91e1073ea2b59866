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
//! use eomgen::report::{print, ShowOptions};
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
//! let derived = eomgen::Builder::from_urdf_str(urdf, "pendulum.urdf").derived().unwrap();
//! let terms = vec!["mass_matrix".to_string(), "G".to_string()]; // a name or a symbol
//! let opts = ShowOptions { terms, ..Default::default() };
//! let text = print(&derived, &opts).unwrap();
//! assert!(text.contains("M11 = 0.51\n"));
//! assert!(text.contains("G1 = 9.81*s1\n"));
//! assert!(text.contains("s1 = sin(q1)"));
//! ```

mod base_parameters;
mod document;
pub mod forms;
mod latex;
mod markdown;
mod section;
mod term;
mod text;
mod trig;

/// Numbers as the reports write them: `digits` significant digits, or the shortest exact
/// decimals with `None`.
pub use crate::cas::format_number;
/// Text from a URDF (names) made safe for a terminal: control and bidirectional-text
/// characters written as escapes such as `\u{1b}`.
pub use crate::wording::escape_controls;
pub use base_parameters::render_base_parameters;

use crate::cas::{Graph, Style, Syntax};
use crate::dynamics::Derivation;
use crate::model::Model;
use document::Document;
use section::{build_section, section, Entry, Section};
use term::entry_name;

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
    /// The quantities, printed in this order: their generated names (`mass_matrix`) or symbols
    /// (`M`, `tau`; see the catalogue's notations), `all` for every one but the derivatives,
    /// `inverse_dynamics_derivatives` (or `dtau_dq`) for `d tau / d q`. A quantity the
    /// derivation does not have (Craig's matrices with a floating base) is left out.
    pub terms: Vec<String>,
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
            terms: vec!["all".to_string()],
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
    /// [`ShowOptions::terms`] names no quantity with a notation.
    #[error("unknown quantity `{0}` to print")]
    UnknownQuantity(String),
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

/// Prints the chosen quantities of a derived robot ([`crate::Builder::derived`]); see
/// [`render`] for what is printed and when it fails.
///
/// ```
/// let derived = eomgen::Builder::new("../tests/robots/double_pendulum.urdf").derived().unwrap();
/// let opts = eomgen::report::ShowOptions { terms: vec!["tau".into()], ..Default::default() };
/// let text = eomgen::report::print(&derived, &opts).unwrap();
/// assert!(text.contains("Inverse dynamics tau = M(q) qdd + b(q, qd) + G(q)"));
/// ```
pub fn print(derived: &crate::Derived, opts: &ShowOptions) -> Result<String, ReportError> {
    render(derived.model(), derived.derivation(), opts)
}

/// The base parameters of a derived robot (derived with [`crate::Builder::regressor`]); see
/// [`render_base_parameters`].
pub fn print_base_parameters(
    derived: &crate::Derived,
    opts: &ShowOptions,
) -> Result<String, ReportError> {
    render_base_parameters(derived.model(), derived.derivation(), opts)
}

/// Prints the chosen terms of a model and its derivation; prefer [`print`].
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
#[doc(hidden)]
pub fn render(model: &Model, d: &Derivation, opts: &ShowOptions) -> Result<String, ReportError> {
    if opts.entry.is_some() && (opts.terms.len() != 1 || opts.terms[0] == "all") {
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
            term_sections(&mut g, model, d, opts, syntax, &mut dropped)?
        }
    };
    let doc = Document::new(&g, model, d, sections, opts, dropped);
    Ok(match opts.format {
        Format::Text => text::write(&doc),
        Format::Latex if opts.standalone => latex::document(&doc),
        Format::Latex => latex::fragments(&doc),
        Format::Markdown => markdown::write(&doc),
    })
}

/// The sections of [`ShowOptions::terms`], in order, the friction of `tau` noted.
fn term_sections(
    g: &mut Graph,
    model: &Model,
    d: &Derivation,
    opts: &ShowOptions,
    syntax: Syntax,
    dropped: &mut usize,
) -> Result<Vec<Section>, ReportError> {
    let notations = term::resolve(&opts.terms).map_err(ReportError::UnknownQuantity)?;
    let mut sections = Vec::with_capacity(notations.len());
    for term in notations {
        // Not generated for this robot (Craig's matrices need qd = dq/dt, which a floating
        // base's velocities are not); the derivatives, when not derived, say so.
        if d.quantity(term.name).is_none() && (term.printed)(d).is_some() {
            continue;
        }
        let mut s = section(g, d, term, opts, syntax, dropped)?;
        if term.name == "inverse_dynamics" && model.include_friction {
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
    Ok(sections)
}
