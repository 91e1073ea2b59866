//! The other forms of the equations (`eomgen show --form projected-newton-euler` and
//! `--form hamiltonian`): sections for [`super::render`] built from the per-body terms of
//! [`crate::dynamics::projected`] and from Hamilton's equations.

use super::{build_section, entry_name, Entry, ReportError, Section, ShowOptions};
use crate::cas::{Graph, Id, Program, Syntax};
use crate::dynamics::catalogue::notation;
use crate::dynamics::{projected, Derivation};
use crate::model::Model;

/// The forms print expanded formulas for small robots only: beyond this many operations in
/// their straight-line program (the 6-joint UR5's per-body terms take some 9,000), `show`
/// refuses with a one-line error.
pub const FORMS_MAX_OPS: usize = 20_000;

fn refuse_large(g: &Graph, model: &Model, ids: &[Id], form: &str) -> Result<(), ReportError> {
    let ops = Program::new(g, ids).ops().total();
    if ops > FORMS_MAX_OPS {
        return Err(ReportError::TooLarge(format!(
            "{}: the {form} form takes {ops} operations, more than the {FORMS_MAX_OPS} that \
             are printed: it is for small robots (print M and b with --term, or generate code)",
            model.name
        )));
    }
    Ok(())
}

fn matrix_entries(g: &Graph, m: &[Vec<Id>], dof: usize, syntax: Syntax) -> Vec<Entry> {
    let mass_matrix = notation("mass_matrix").expect("the mass matrix's notation");
    let mut out = Vec::new();
    for (i, row) in m.iter().enumerate() {
        for (j, &e) in row.iter().enumerate().skip(i) {
            if g.as_const(e) != Some(0.0) {
                out.push(Entry {
                    name: entry_name(mass_matrix, &[i, j], dof, syntax),
                    text: entry_name(mass_matrix, &[i, j], dof, Syntax::Text),
                    expr: e,
                });
            }
        }
    }
    out
}

/// The nonzero entries of `v`, named `base.0` + index in text, `base.1`_{index} in LaTeX.
fn vector_entries(g: &Graph, v: &[Id], base: (&str, &str), syntax: Syntax) -> Vec<Entry> {
    let name = |i: usize, syntax: Syntax| {
        let sub = (i + 1).to_string();
        match syntax {
            Syntax::Latex => format!("{}_{{{sub}}}", base.1),
            _ => format!("{}{sub}", base.0),
        }
    };
    v.iter()
        .enumerate()
        .filter(|(_, e)| g.as_const(**e) != Some(0.0))
        .map(|(i, &e)| Entry {
            name: name(i, syntax),
            text: name(i, Syntax::Text),
            expr: e,
        })
        .collect()
}

/// `M` and `b` as sums over the bodies: each body's share, then the rotor inertias.
pub(super) fn projected_newton_euler(
    g: &mut Graph,
    model: &Model,
    d: &Derivation,
    opts: &ShowOptions,
    syntax: Syntax,
    dropped: &mut usize,
) -> Result<Vec<Section>, ReportError> {
    if model.is_coupled() {
        return Err(ReportError::TooLarge(format!(
            "{}: the projected Newton-Euler form is not printed with mimic joints yet (drop \
             --mimic to see each body's share in the joints' coordinates)",
            model.name
        )));
    }
    let terms = projected::body_terms(g, model, &d.q, &d.qd);
    let all: Vec<Id> = terms
        .iter()
        .flat_map(|t| t.mass_matrix.iter().flatten().chain(&t.bias).copied())
        .collect();
    refuse_large(g, model, &all, "projected Newton-Euler")?;
    let mut sections = Vec::new();
    let count = terms.len();
    for (k, t) in terms.iter().enumerate() {
        let ctx = (d.dof, opts, syntax);
        sections.extend(body_sections(g, t, (k, count), ctx, dropped)?);
    }
    let notes = sum_notes(model, count);
    sections.push(build_section(
        g,
        "Sum over the bodies".to_string(),
        notes,
        Vec::new(),
        opts,
        false,
        false,
        dropped,
    )?);
    // An empty section's note says "Every entry is 0.": not meant here.
    if let Some(last) = sections.last_mut() {
        last.notes.retain(|n| n != "Every entry is 0.");
    }
    Ok(sections)
}

/// The sections of body `k` (0-based) of `count`: its share of `M` and of `b`. `ctx` holds the
/// joint count, the options and the syntax.
fn body_sections(
    g: &mut Graph,
    t: &projected::BodyTerms,
    (k, count): (usize, usize),
    (dof, opts, syntax): (usize, &ShowOptions, Syntax),
    dropped: &mut usize,
) -> Result<[Section; 2], ReportError> {
    let body = format!("body {} of {count}, link `{}`", k + 1, t.link);
    let mut section = |g: &mut Graph, title: String, note: String, entries: Vec<Entry>, omitted| {
        build_section(g, title, vec![note], entries, opts, false, omitted, dropped)
    };
    let note = format!(
        "M^({}) = J_P^T m J_P + J_R^T Theta J_R: J_P the Jacobian of the centre of mass, \
         J_R the angular Jacobian, Theta the inertia about the centre of mass in world axes \
         (symmetric: the upper triangle is listed).",
        k + 1
    );
    let entries = matrix_entries(g, &t.mass_matrix, dof, syntax);
    let omitted = entries.len() < dof * (dof + 1) / 2;
    let mass = section(
        g,
        format!("Mass matrix, share of {body}"),
        note,
        entries,
        omitted,
    )?;
    let note = format!(
        "b^({}) = J_P^T m Jdot_P qd + J_R^T (Theta Jdot_R qd + omega x Theta omega), \
         omega = J_R qd.",
        k + 1
    );
    let entries = vector_entries(g, &t.bias, ("b", "b"), syntax);
    let omitted = entries.len() < dof;
    let bias = section(g, format!("Bias, share of {body}"), note, entries, omitted)?;
    Ok([mass, bias])
}

/// The notes of the closing section: `M` and `b` as the sums of the bodies' shares, and the
/// rotor inertias.
fn sum_notes(model: &Model, count: usize) -> Vec<String> {
    let shares: Vec<String> = (1..=count).map(|k| format!("M^({k})")).collect();
    let biases: Vec<String> = (1..=count).map(|k| format!("b^({k})")).collect();
    let armature: Vec<String> = model
        .joints
        .iter()
        .enumerate()
        .filter(|(_, j)| j.armature != 0.0)
        .map(|(i, j)| format!("{} on M{}{}", j.armature, i + 1, i + 1))
        .collect();
    let mut notes = vec![
        format!("M = {}", shares.join(" + ")),
        format!("b = {}", biases.join(" + ")),
    ];
    if !armature.is_empty() {
        notes.push(format!(
            "M also has the rotor inertias (armature) on its diagonal: {}.",
            armature.join(", ")
        ));
    }
    notes.push("The equation of motion: M qdd + b + G = tau (print G with --term G).".to_string());
    notes
}

/// `H(q, p) = 1/2 p^T M^-1 p + V`, and Hamilton's equations with `pd` written out in `q` and
/// `qd = M^-1 p`: `pd_k = tau_k + dT/dq_k - dV/dq_k` (`dT/dq_k = (C^T qd)_k`).
pub(super) fn hamiltonian(
    g: &mut Graph,
    model: &Model,
    d: &Derivation,
    opts: &ShowOptions,
    syntax: Syntax,
    dropped: &mut usize,
) -> Result<Vec<Section>, ReportError> {
    let n = d.dof;
    let m = &d.mass_matrix;
    let momentum: Vec<Id> = m.iter().map(|row| g.dot(row, &d.qd)).collect();
    let pd = momentum_rate(g, d);
    let mut all: Vec<Id> = m.iter().flatten().copied().collect();
    all.extend(&pd);
    all.push(d.potential_energy);
    refuse_large(g, model, &all, "Hamiltonian")?;
    let entries = matrix_entries(g, m, n, syntax);
    let omitted = entries.len() < n * (n + 1) / 2;
    let mut sections = vec![build_section(
        g,
        "Hamiltonian H(q, p) = 1/2 p^T M(q)^-1 p + V(q)".to_string(),
        vec![
            "The total energy T + V in the generalized momentum p = M(q) qd; M(q), symmetric \
             (the upper triangle is listed):"
                .to_string(),
        ],
        entries,
        opts,
        false,
        omitted,
        dropped,
    )?];
    sections.push(build_section(
        g,
        "Potential energy".to_string(),
        Vec::new(),
        vec![potential_entry(d, syntax)],
        opts,
        true,
        false,
        dropped,
    )?);
    sections.push(build_section(
        g,
        "Generalized momentum p = M(q) qd".to_string(),
        Vec::new(),
        vector_entries(g, &momentum, ("p", "p"), syntax),
        opts,
        false,
        false,
        dropped,
    )?);
    let entries = vector_entries(g, &pd, ("pd", "\\dot{p}"), syntax);
    let omitted = entries.len() < n;
    sections.push(build_section(
        g,
        "Hamilton's equations".to_string(),
        vec![
            "qd = dH/dp = M(q)^-1 p, and pd = -dH/dq + tau = tau + C(q, qd)^T qd - G(q), \
             written out with qd = M(q)^-1 p; the middle term is dT/dq at fixed qd."
                .to_string(),
        ],
        entries,
        opts,
        false,
        omitted,
        dropped,
    )?);
    Ok(sections)
}

/// Hamilton's `pd_k = tau_k + dT/dq_k - dV/dq_k` in `q` and `qd`.
fn momentum_rate(g: &mut Graph, d: &Derivation) -> Vec<Id> {
    (0..d.dof)
        .map(|k| {
            let dt = g.diff(d.kinetic_energy, d.q[k]);
            let tau = g.tau(k);
            let with_tau = g.add(tau, dt);
            g.sub(with_tau, d.gravity[k])
        })
        .collect()
}

/// The potential energy `V` as an entry.
fn potential_entry(d: &Derivation, syntax: Syntax) -> Entry {
    Entry {
        name: entry_name(
            notation("potential_energy").expect("the potential energy's notation"),
            &[],
            d.dof,
            syntax,
        ),
        text: "V".to_string(),
        expr: d.potential_energy,
    }
}
