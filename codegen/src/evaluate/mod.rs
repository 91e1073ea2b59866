//! Numbers without compiling: the catalogue's quantities evaluated at a state, straight from
//! the derivation.
//!
//! Emission ([`crate::emit`]) and the reports ([`crate::report`]) are two back-ends of the
//! catalogue; this is the third. [`Derived`] (from [`Builder::derived`](crate::Builder::derived))
//! holds the model and its derivation; [`Derived::evaluator`] compiles the expressions of the
//! quantities asked for once into flat tapes, and [`Evaluator::evaluate`] runs them at each
//! state, composing what generated code composes at run time (a solve with `M`, `M^-1`,
//! Craig's matrices from Christoffel columns, the derivatives of forward dynamics, contact
//! forward dynamics) with dense factorizations. The `eomgen` command line's `eval` and
//! `simulate` are built on it.
//!
//! ```
//! use eomgen::evaluate::State;
//! let urdf = r#"<robot name="pendulum">
//!   <link name="base"/>
//!   <link name="arm"><inertial><mass value="2"/><origin xyz="0 0 -0.5"/>
//!     <inertia ixx="0" iyy="0" izz="0" ixy="0" ixz="0" iyz="0"/></inertial></link>
//!   <joint name="hinge" type="revolute"><parent link="base"/><child link="arm"/>
//!     <axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="10" velocity="5"/></joint>
//! </robot>"#;
//! let derived = eomgen::Builder::from_urdf_str(urdf, "pendulum.urdf").derived().unwrap();
//! let state = State::at_rest(vec![0.3], 1);
//! let values = derived.evaluate(&["mass_matrix", "gravity"], &state).unwrap();
//! assert!((values[0].data[0] - 2.0 * 0.25).abs() < 1e-12); // m l^2
//! assert!((values[1].data[0] - 2.0 * 9.81 * 0.5 * 0.3f64.sin()).abs() < 1e-12);
//! ```

mod plan;
mod solve;
mod tape;

use crate::dynamics::{Derivation, Input, Quantity, Shape};
use crate::model::Model;
use plan::Plan;

/// A robot's model and derivation, ready to evaluate (see the module documentation).
pub struct Derived {
    model: Model,
    derivation: Derivation,
}

/// A state: positions (`NQ`: a floating base's position and quaternion x, y, z, w first),
/// velocities, accelerations and efforts (`NV` each; a floating base's velocity in its own
/// axes first). Quantities read only their inputs; the others may stay zero.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct State {
    pub q: Vec<f64>,
    pub v: Vec<f64>,
    pub a: Vec<f64>,
    pub tau: Vec<f64>,
}

impl State {
    /// Positions `q`, with zero velocities, accelerations and efforts for `nv` coordinates.
    pub fn at_rest(q: Vec<f64>, nv: usize) -> State {
        State {
            q,
            v: vec![0.0; nv],
            a: vec![0.0; nv],
            tau: vec![0.0; nv],
        }
    }
}

/// One quantity's value.
#[derive(Clone, Debug, PartialEq)]
pub struct Value {
    /// The catalogue name (the generated method's name).
    pub name: &'static str,
    /// Its shape.
    pub shape: Shape,
    /// The numbers, row-major; a tuple's matrices one after the other.
    pub data: Vec<f64>,
}

impl Value {
    /// The rows of a matrix (a vector is one row per entry); the `k`-th matrix of a tuple
    /// with [`Value::matrix`].
    pub fn rows(&self) -> Vec<Vec<f64>> {
        self.matrix(0)
    }

    /// The `k`-th matrix of a tuple (`k = 0` for a single matrix), as rows.
    pub fn matrix(&self, k: usize) -> Vec<Vec<f64>> {
        let cols = match self.shape {
            Shape::Matrix(_, c) | Shape::Matrices(_, _, c) => c,
            Shape::Scalar | Shape::Vector(_) => 1,
        };
        let size = match self.shape {
            Shape::Matrices(_, r, c) => r * c,
            _ => self.data.len(),
        };
        self.data[k * size..(k + 1) * size]
            .chunks(cols.max(1))
            .map(<[f64]>::to_vec)
            .collect()
    }
}

/// Why a quantity has no value.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum EvalError {
    /// Not a quantity of this robot's catalogue.
    #[error("unknown quantity `{name}` (known: {known})")]
    Unknown { name: String, known: String },
    /// A quantity that needs more than a state.
    #[error("`{name}` cannot be evaluated here: {why}")]
    NotEvaluable { name: String, why: &'static str },
    /// A state vector of the wrong length.
    #[error("{what} has {got} value(s), but the robot has {expected}")]
    Length {
        what: &'static str,
        got: usize,
        expected: usize,
    },
    /// A factorization failed: `M(q)` (or, with contacts, `J_c M^-1 J_c^T`) is not positive
    /// definite at this state. `detail` names the pivot (1-based) and its joint.
    #[error("{robot}: {matrix} is not positive definite at this state {detail}")]
    NotPositiveDefinite {
        robot: String,
        matrix: &'static str,
        detail: String,
    },
    /// A bug in eomgen.
    #[error("internal error while evaluating (please report): {0}")]
    Internal(String),
}

/// Where each part of a state sits in the tapes' input: `q`, then `v`, `a`, `tau`.
#[derive(Clone, Copy, Debug)]
struct Layout {
    nq: usize,
    nv: usize,
}

impl Layout {
    fn v(self) -> usize {
        self.nq
    }
    fn a(self) -> usize {
        self.nq + self.nv
    }
    fn tau(self) -> usize {
        self.nq + 2 * self.nv
    }
    fn len(self) -> usize {
        self.nq + 3 * self.nv
    }
}

/// Quantities compiled once, evaluated at many states.
pub struct Evaluator {
    robot: String,
    coordinates: Vec<String>,
    layout: Layout,
    plans: Vec<(&'static str, Shape, Vec<Input>, Plan)>,
}

impl Derived {
    /// From a model and its derivation (what [`Builder::generate_with_report`] returns);
    /// prefer [`Builder::derived`].
    ///
    /// [`Builder::generate_with_report`]: crate::Builder::generate_with_report
    /// [`Builder::derived`]: crate::Builder::derived
    #[doc(hidden)]
    pub fn from_parts(model: Model, derivation: Derivation) -> Derived {
        Derived { model, derivation }
    }

    /// The robot's model.
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// The derivation, for the reports and the tests.
    #[doc(hidden)]
    pub fn derivation(&self) -> &Derivation {
        &self.derivation
    }

    /// How long each stage of the derivation took, in order.
    pub fn timings(&self) -> &[(&'static str, std::time::Duration)] {
        &self.derivation.timings
    }

    /// The number of nodes of the expression graph the derivation built.
    pub fn graph_nodes(&self) -> usize {
        self.derivation.graph.len()
    }

    /// The catalogue: every quantity generated code has for this robot and these options, in
    /// file order, by name.
    pub fn quantity_names(&self) -> Vec<&'static str> {
        self.derivation.quantities.iter().map(|q| q.name).collect()
    }

    /// The arguments of the quantity `name` (a catalogue name or a symbol), `None` if this
    /// robot has no such quantity.
    ///
    /// ```
    /// use eomgen::{Builder, Input};
    /// let urdf = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/robots/double_pendulum.urdf");
    /// let derived = Builder::new(urdf).derived().unwrap();
    /// assert_eq!(derived.inputs("tau"), Some(&[Input::Q, Input::Qd, Input::Qdd][..]));
    /// assert_eq!(derived.inputs("no_such_quantity"), None);
    /// ```
    pub fn inputs(&self, name: &str) -> Option<&'static [Input]> {
        let name = crate::catalogue::canonical(name);
        let q = self.derivation.quantities.iter().find(|q| q.name == name)?;
        Some(q.inputs)
    }

    /// Compiles the quantities `names` (catalogue names, as the generated methods, or their
    /// symbols: `M`, `tau`; see [`crate::catalogue`]).
    pub fn evaluator(&self, names: &[&str]) -> Result<Evaluator, EvalError> {
        let d = &self.derivation;
        let layout = Layout {
            nq: d.nq,
            nv: d.dof,
        };
        let find =
            |name: &str| -> Option<&Quantity> { d.quantities.iter().find(|q| q.name == name) };
        let plans = names
            .iter()
            .map(|&name| {
                let q =
                    find(crate::catalogue::canonical(name)).ok_or_else(|| EvalError::Unknown {
                        name: name.to_string(),
                        known: self.quantity_names().join(", "),
                    })?;
                let plan = Plan::new(d, layout, q, &find)?;
                Ok((q.name, q.shape, q.inputs.to_vec(), plan))
            })
            .collect::<Result<_, EvalError>>()?;
        Ok(Evaluator {
            robot: self.model.name.clone(),
            coordinates: self.model.velocity_names(),
            layout,
            plans,
        })
    }

    /// Compiles and evaluates `names` at `state` once; for many states, keep an
    /// [`Derived::evaluator`].
    pub fn evaluate(&self, names: &[&str], state: &State) -> Result<Vec<Value>, EvalError> {
        self.evaluator(names)?.evaluate(state)
    }
}

impl Evaluator {
    /// The values of the compiled quantities at `state`, in the order they were asked for.
    pub fn evaluate(&self, state: &State) -> Result<Vec<Value>, EvalError> {
        let values = self.input(state)?;
        let x = plan::Input {
            layout: self.layout,
            values: &values,
        };
        self.plans
            .iter()
            .map(|(name, shape, _, plan)| {
                let data = plan.run(&x).map_err(|e| self.not_positive(e))?;
                Ok(Value {
                    name,
                    shape: *shape,
                    data,
                })
            })
            .collect()
    }

    /// The state's vectors in one slice, lengths checked against the inputs the compiled
    /// quantities read (an unread vector may be empty).
    fn input(&self, s: &State) -> Result<Vec<f64>, EvalError> {
        let Layout { nq, nv } = self.layout;
        let reads = |i: Input| self.plans.iter().any(|p| p.2.contains(&i));
        let mut out = Vec::with_capacity(self.layout.len());
        for (what, v, len, input) in [
            ("q", &s.q, nq, Input::Q),
            ("v", &s.v, nv, Input::Qd),
            ("a", &s.a, nv, Input::Qdd),
            ("tau", &s.tau, nv, Input::Tau),
        ] {
            match v.len() {
                l if l == len => out.extend(v),
                0 if !reads(input) => out.extend(std::iter::repeat_n(0.0, len)),
                got => {
                    return Err(EvalError::Length {
                        what,
                        got,
                        expected: len,
                    })
                }
            }
        }
        Ok(out)
    }

    fn not_positive(&self, e: solve::NotPositive) -> EvalError {
        let robot = self.robot.clone();
        if e.contact_space {
            return EvalError::NotPositiveDefinite {
                robot,
                matrix: "the contact-space inertia J_c M^-1 J_c^T",
                detail: format!(
                    "(pivot {}): the contact Jacobian is rank-deficient",
                    e.pivot + 1
                ),
            };
        }
        // A floating base's six velocity coordinates come before the joints.
        let base = self.layout.nv - self.coordinates.len();
        let at = match e.pivot.checked_sub(base) {
            Some(j) => format!("joint `{}`", self.coordinates[j]),
            None => "the floating base".to_string(),
        };
        EvalError::NotPositiveDefinite {
            robot,
            matrix: "the mass matrix",
            detail: format!(
                "(pivot {} of {}, {at}): check the masses and inertias",
                e.pivot + 1,
                self.layout.nv
            ),
        }
    }
}
