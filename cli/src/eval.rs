//! `eomgen eval`: the derived quantities at one numeric state, through the library's
//! evaluator (`eomgen::evaluate`), which `simulate` and `info` share: compiled once per robot,
//! run at every state. What it prints follows from the catalogue ([`printed`]).

use std::fmt::Write as _;

use eomgen::catalogue::{self, Layout, Notation, NOTATIONS};
use eomgen::evaluate::{EvalError, Evaluator, State, Value};
use eomgen::model::Model;
use eomgen::Derived;

use eomgen::report::format_number;

/// The quantity whose equation `eval` prints, `tau = M qdd + b + G + F` from its terms.
const INVERSE_DYNAMICS: &str = "inverse_dynamics";
/// The solve of that equation for the accelerations, printed after it.
const FORWARD_DYNAMICS: &str = "forward_dynamics";

/// The quantities `eval` prints at a state, from the catalogue: those with a [`Notation`] that
/// are the mass matrix, a vector or a number (not Craig's matrices, `C(q, qd)` or the
/// derivatives) and that this robot has. The terms of the equation of motion come first, in the
/// order the inverse dynamics' definition names them (others, such as friction, after), then
/// the inverse dynamics, then the numbers (the energies).
pub fn printed(derived: &Derived) -> Vec<&'static Notation> {
    let names = derived.quantity_names();
    let tau = catalogue::notation(INVERSE_DYNAMICS).map_or("", |n| n.title);
    let rank = |n: &Notation| match n.layout {
        _ if n.name == INVERSE_DYNAMICS => (1, 0),
        Layout::Scalar => (2, 0),
        _ => (0, tau.find(&format!(" {}(", n.text)).unwrap_or(usize::MAX)),
    };
    let mut out: Vec<&'static Notation> = NOTATIONS
        .iter()
        .filter(|n| {
            matches!(
                n.layout,
                Layout::Symmetric | Layout::Vector | Layout::Scalar
            )
        })
        .filter(|n| names.contains(&n.name))
        .collect();
    out.sort_by_key(|n| rank(n));
    out
}

/// What `simulate` reads of the quantities [`printed`], by name.
pub struct Values {
    pub mass_matrix: Vec<Vec<f64>>,
    pub bias: Vec<f64>,
    pub gravity: Vec<f64>,
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
        let mut names: Vec<&str> = printed(derived).iter().map(|n| n.name).collect();
        names.extend(coriolis.then_some("coriolis_matrix"));
        let compile = |names: &[&str]| derived.evaluator(names).map_err(|e| e.to_string());
        Ok(Terms {
            at_state: compile(&names)?,
            forward: compile(&[FORWARD_DYNAMICS])?,
            friction,
            coriolis,
        })
    }

    /// The values of the quantities [`printed`] (and `C(q, qd)` when asked for) at `s`.
    pub fn values(&self, s: &State) -> Result<Vec<Value>, String> {
        self.at_state.evaluate(s).map_err(|e| e.to_string())
    }

    /// The terms at `s`.
    pub fn at(&self, s: &State) -> Result<Values, String> {
        let v = self.values(s)?;
        let n = s.v.len();
        let rows = |x: &[f64]| x.chunks(n.max(1)).map(<[f64]>::to_vec).collect();
        Ok(Values {
            mass_matrix: rows(data(&v, "mass_matrix")),
            bias: data(&v, "bias").to_vec(),
            gravity: data(&v, "gravity").to_vec(),
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

/// Evaluates the quantities [`printed`] and the forward dynamics (at `s.tau`) once.
pub fn evaluate(derived: &Derived, s: &State) -> Result<(Vec<Value>, Vec<f64>), String> {
    let terms = Terms::new(derived, false)?;
    let values = terms.values(s)?;
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
    } else if !model.velocities_are_rates() {
        format!(
            "{}: {} degrees of freedom, {} position coordinates; a floating joint's q = position \
             (3), quaternion x y z w (4) of its child, its qd = linear and angular velocity in \
             the child's axes (6); joint order: {names}",
            model.name,
            model.nv(),
            model.nq()
        )
    } else {
        format!(
            "{}: {} degrees of freedom; joint order: {names}",
            model.name,
            model.coordinates()
        )
    }
}

/// What `eval` prints before a quantity's value: its notation's label, lower case, with the
/// velocities called `qd` (`bias b(q, qd)`, on a floating base `bias b(q, v)`).
fn label(n: &Notation, qd: &str) -> String {
    let label = n.label().replace("qd)", &format!("{qd})"));
    let mut chars = label.chars();
    chars.next().map_or(String::new(), |c| {
        c.to_lowercase().chain(chars).collect::<String>()
    })
}

/// The text `eval` prints: the state, the quantities [`printed`] (`values`, in that order),
/// and the forward dynamics `qdd` at `s.tau` after the inverse dynamics.
pub fn print(
    model: &Model,
    s: &State,
    values: &[Value],
    qdd: &[f64],
    digits: Option<usize>,
) -> String {
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
    let _ = writeln!(out);
    // The equation's terms printed so far: the mass matrix's symbol, then the vectors'.
    let (mut m, mut vectors) = ("M", Vec::new());
    for v in values {
        let Some(n) = catalogue::notation(v.name) else {
            continue;
        };
        let label = label(n, qd);
        match n.layout {
            Layout::Symmetric => {
                let _ = writeln!(out, "{label}:");
                for row in v.rows() {
                    let _ = writeln!(out, "  {}", list(&row, digits));
                }
                m = n.text;
            }
            Layout::Scalar => {
                let _ = writeln!(out, "{label} = {}", format_number(v.data[0], digits));
            }
            _ if n.name == INVERSE_DYNAMICS => {
                let plus: String = vectors.iter().map(|t| format!(" + {t}")).collect();
                let minus: String = vectors.iter().map(|t| format!(" - {t}")).collect();
                let (tau, qdd) = (list(&v.data, digits), list(qdd, digits));
                let _ = writeln!(out, "{label} = {m} {a}{plus} = {tau}");
                let _ = writeln!(out, "forward dynamics {a} = {m}^-1 (tau_in{minus}) = {qdd}");
            }
            _ => {
                let _ = writeln!(out, "{label} = {}", list(&v.data, digits));
                vectors.push(n.text);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The double pendulum's printed quantities: the equation's terms in the order the inverse
    /// dynamics' definition names them, the inverse dynamics, the energies; with friction, its
    /// term after the others.
    #[test]
    fn printed_follows_the_catalogue_in_the_equations_order() {
        let urdf = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../tests/robots/double_pendulum.urdf"
        );
        let names = |b: eomgen::Builder| -> Vec<&str> {
            printed(&b.derived().unwrap())
                .iter()
                .map(|n| n.name)
                .collect()
        };
        let rigid = [
            "mass_matrix",
            "bias",
            "gravity",
            "inverse_dynamics",
            "kinetic_energy",
            "potential_energy",
        ];
        assert_eq!(names(eomgen::Builder::new(urdf)), rigid);
        let mut with_friction = rigid.to_vec();
        with_friction.insert(3, "friction");
        assert_eq!(
            names(eomgen::Builder::new(urdf).friction(true)),
            with_friction
        );
    }
}
