//! The document `render` writes, whatever the format: an introduction, the coordinates, the
//! sections with their formulas in the document's syntax, and a legend. Each format's writer
//! (`text.rs`, `latex.rs`, `markdown.rs`) only lays it out.

use std::collections::BTreeSet;
use std::fmt::Write as _;

use super::section::{Body, Section};
use super::trig::{self, ShortName};
use super::{ShowOptions, NOISE};
use crate::cas::{format_number, Graph, Id, Node, Program, Style, SymbolKind, Syntax};
use crate::dynamics::Derivation;
use crate::model::{JointKind, Model};
pub(super) use crate::wording::value_source;

/// What is printed, in the document's syntax.
pub(super) struct Document {
    /// The robot's name, for headings.
    pub(super) name: String,
    /// Sentences on the robot, the numbers and what was left out.
    pub(super) intro: Vec<String>,
    /// Per coordinate: its symbol and what it is.
    pub(super) joints: Vec<(String, String)>,
    /// The sections (titles and notes).
    pub(super) sections: Vec<Section>,
    /// Per section, its `(name, formula)` lines.
    pub(super) bodies: Vec<Vec<(String, String)>>,
    /// The short names (`s1`, `c12`) and what they stand for.
    pub(super) legend: Vec<(String, String)>,
    /// The other symbols (rates, parameters) and what they are.
    pub(super) legend_text: Vec<(String, String)>,
}

impl Document {
    /// The document of `sections` of `model`'s derivation `d`, their expressions in `g`;
    /// `dropped` numeric terms were left out as rounding noise.
    pub(super) fn new(
        g: &Graph,
        model: &Model,
        d: &Derivation,
        sections: Vec<Section>,
        opts: &ShowOptions,
        dropped: usize,
    ) -> Document {
        let style = super::style_of(opts);
        let expanded_roots: Vec<Id> = sections
            .iter()
            .filter(|s| matches!(s.body, Body::Expanded(_)))
            .flat_map(|s| s.roots())
            .collect();
        let short = trig::short_names(g, &expanded_roots, style, d.dof <= 9);
        let (params, uses_rates) = symbols_used(g, d, &sections, style);
        let bodies = bodies(g, &sections, &short, style);
        let mut legend_text: Vec<(String, String)> = Vec::new();
        if uses_rates {
            legend_text.push((
                "qd_i, qdd_i".into(),
                "velocity and acceleration of q_i".into(),
            ));
        }
        legend_text.extend(params.iter().cloned());
        Document {
            name: model.name.clone(),
            intro: intro(model, d, opts, !params.is_empty(), dropped),
            joints: joints(g, model, d, opts, style),
            sections,
            bodies,
            legend: short
                .iter()
                .map(|s| (s.short().to_string(), s.meaning.clone()))
                .collect(),
            legend_text,
        }
    }

    /// Whether there is a legend to print.
    pub(super) fn has_legend(&self) -> bool {
        !self.legend.is_empty() || !self.legend_text.is_empty()
    }
}

/// The parameters the sections use (symbol, what it is) and whether they use rates.
fn symbols_used(
    g: &Graph,
    d: &Derivation,
    sections: &[Section],
    style: Style,
) -> (Vec<(String, String)>, bool) {
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

    (params, uses_rates)
}

/// The formulas of each section, as `(name, formula)` lines in the document's syntax.
fn bodies(
    g: &Graph,
    sections: &[Section],
    short: &[ShortName],
    style: Style,
) -> Vec<Vec<(String, String)>> {
    let syntax = style.syntax;
    sections
        .iter()
        .map(|s| match &s.body {
            Body::Expanded(v) => v
                .iter()
                .map(|(name, e)| (name.clone(), trig::shorten(&g.print(*e, style), short)))
                .collect(),
            Body::Program(names, ids) => {
                let text = Program::new(g, ids).print(names, style);
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
        .collect()
}

/// The introduction: the robot, how numbers are printed, a floating base's equations, and
/// how many noise terms were left out.
fn intro(
    model: &Model,
    d: &Derivation,
    opts: &ShowOptions,
    symbolic: bool,
    dropped: usize,
) -> Vec<String> {
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
    intro.push(if !symbolic {
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
    intro
}

/// Per coordinate, its symbol and what it is: a floating base's position and quaternion, then
/// the joints (a mimic joint with the coordinate it follows).
fn joints(
    g: &Graph,
    model: &Model,
    d: &Derivation,
    opts: &ShowOptions,
    style: Style,
) -> Vec<(String, String)> {
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
    joints
}

/// What a parameter symbol stands for, from its name (see [`crate::kinematics::Params`]).
pub(super) fn describe_param(name: &str) -> String {
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

/// The name of a kind of joint.
pub(super) fn kind_name(k: JointKind) -> &'static str {
    k.urdf_name()
}

/// A vector as `(1, 0, 0)`.
pub(super) fn vec3(v: &nalgebra::Vector3<f64>, digits: Option<usize>) -> String {
    format!(
        "({}, {}, {})",
        format_number(v[0], digits),
        format_number(v[1], digits),
        format_number(v[2], digits)
    )
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
