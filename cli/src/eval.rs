//! `eomgen eval`: the derived quantities at one numeric state, through the library's
//! evaluator (`eomgen::evaluate`), which `simulate` and `info` share: compiled once per robot,
//! run at every state.

use std::fmt::Write as _;

use eomgen::evaluate::{EvalError, Evaluator, State, Value};
use eomgen::model::Model;
use eomgen::Derived;

use eomgen::report::format_number;

/// Everything `eval` prints (and `simulate` reads).
pub struct Values {
    pub mass_matrix: Vec<Vec<f64>>,
    pub bias: Vec<f64>,
    pub gravity: Vec<f64>,
    /// Inverse dynamics at the state's accelerations.
    pub tau: Vec<f64>,
    /// The joint friction effort `F(qd)`, zero unless the model includes friction.
    pub friction: Vec<f64>,
    pub kinetic_energy: f64,
    pub potential_energy: f64,
    /// The Christoffel-form Coriolis matrix `C(q, qd)`, when asked for ([`Terms::new`]).
    pub coriolis: Vec<Vec<f64>>,
}

/// The quantities of [`Values`] and forward dynamics, compiled once.
pub struct Terms {
    at_state: Evaluator,
    forward: Evaluator,
    friction: bool,
    coriolis: bool,
}

const NAMES: [&str; 6] = [
    "mass_matrix",
    "bias",
    "gravity",
    "inverse_dynamics",
    "kinetic_energy",
    "potential_energy",
];

/// The numbers of the quantity `name` among `values` (empty if it was not asked for).
pub fn data<'a>(values: &'a [Value], name: &str) -> &'a [f64] {
    values
        .iter()
        .find(|v| v.name == name)
        .map_or(&[], |v| v.data.as_slice())
}

impl Terms {
    /// Compiles the terms of `derived`'s robot (with `C(q, qd)` when `coriolis`).
    pub fn new(derived: &Derived, coriolis: bool) -> Result<Terms, String> {
        let friction = derived.model().include_friction;
        let mut names = NAMES.to_vec();
        names.extend(friction.then_some("friction"));
        names.extend(coriolis.then_some("coriolis_matrix"));
        let compile = |names: &[&str]| derived.evaluator(names).map_err(|e| e.to_string());
        Ok(Terms {
            at_state: compile(&names)?,
            forward: compile(&["forward_dynamics"])?,
            friction,
            coriolis,
        })
    }

    /// The terms at `s`.
    pub fn at(&self, s: &State) -> Result<Values, String> {
        let v = self.at_state.evaluate(s).map_err(|e| e.to_string())?;
        let n = s.v.len();
        let rows = |x: &[f64]| x.chunks(n.max(1)).map(<[f64]>::to_vec).collect();
        Ok(Values {
            mass_matrix: rows(data(&v, "mass_matrix")),
            bias: data(&v, "bias").to_vec(),
            gravity: data(&v, "gravity").to_vec(),
            tau: data(&v, "inverse_dynamics").to_vec(),
            friction: if self.friction {
                data(&v, "friction").to_vec()
            } else {
                vec![0.0; n]
            },
            kinetic_energy: data(&v, "kinetic_energy")[0],
            potential_energy: data(&v, "potential_energy")[0],
            coriolis: if self.coriolis {
                rows(data(&v, "coriolis_matrix"))
            } else {
                Vec::new()
            },
        })
    }

    /// The accelerations at `s` under its efforts `s.tau`: `M^-1 (tau - b - G - F)`; an error
    /// names the pivot and joint where `M` is not positive definite.
    pub fn forward_dynamics(&self, s: &State) -> Result<Vec<f64>, EvalError> {
        let mut v = self.forward.evaluate(s)?;
        Ok(v.remove(0).data)
    }
}

/// Evaluates the terms and the forward dynamics (at `s.tau`) once.
pub fn evaluate(derived: &Derived, s: &State) -> Result<(Values, Vec<f64>), String> {
    let terms = Terms::new(derived, false)?;
    let values = terms.at(s)?;
    let qdd = terms.forward_dynamics(s).map_err(|e| e.to_string())?;
    Ok((values, qdd))
}

fn list(v: &[f64], digits: Option<usize>) -> String {
    let items: Vec<String> = v.iter().map(|&x| format_number(x, digits)).collect();
    format!("[{}]", items.join(", "))
}

/// The header line: the robot, its coordinates and their order.
fn header(model: &Model) -> String {
    let names = model.coordinate_names().join(", ");
    if model.is_floating() {
        format!(
            "{}: floating base and {} joints, {} velocity coordinates; q = base position (3), \
             quaternion x y z w (4), then the joints; v = base linear and angular velocity in \
             base axes (6), then the joints; joint order: {names}",
            model.name,
            model.coordinates(),
            model.coordinates() + 6
        )
    } else {
        format!(
            "{}: {} degrees of freedom; joint order: {names}",
            model.name,
            model.coordinates()
        )
    }
}

/// The text `eval` prints: the state, the terms and the forward dynamics `qdd` at `s.tau`.
pub fn print(model: &Model, s: &State, v: &Values, qdd: &[f64], digits: Option<usize>) -> String {
    let mut out = header(model);
    out.push('\n');
    let (qd, a) = if model.is_floating() {
        ("v", "a")
    } else {
        ("qd", "qdd")
    };
    let _ = writeln!(out, "q = {}", list(&s.q, digits));
    let _ = writeln!(out, "{qd} = {}", list(&s.v, digits));
    let _ = writeln!(out, "{a} = {}", list(&s.a, digits));
    let _ = writeln!(out, "tau_in = {}", list(&s.tau, digits));
    let _ = writeln!(out, "\nmass matrix M(q):");
    for row in &v.mass_matrix {
        let _ = writeln!(out, "  {}", list(row, digits));
    }
    let _ = writeln!(out, "bias b(q, {qd}) = {}", list(&v.bias, digits));
    let _ = writeln!(out, "gravity G(q) = {}", list(&v.gravity, digits));
    let f = if model.include_friction {
        let _ = writeln!(out, "friction F({qd}) = {}", list(&v.friction, digits));
        " + F"
    } else {
        ""
    };
    let _ = writeln!(
        out,
        "inverse dynamics tau = M {a} + b + G{f} = {}",
        list(&v.tau, digits)
    );
    let f = if model.include_friction { " - F" } else { "" };
    let _ = writeln!(
        out,
        "forward dynamics {a} = M^-1 (tau_in - b - G{f}) = {}",
        list(qdd, digits)
    );
    let _ = writeln!(
        out,
        "kinetic energy T = {}",
        format_number(v.kinetic_energy, digits)
    );
    let _ = writeln!(
        out,
        "potential energy V = {}",
        format_number(v.potential_energy, digits)
    );
    out
}
