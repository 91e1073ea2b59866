//! `eomgen simulate`: integrates the equation of motion with RK4 or a symplectic method,
//! evaluating M, b and G through the library's evaluator (`eomgen::evaluate`: the command
//! line cannot compile the generated code), and writes the trajectory as CSV.
//!
//! The integrators and controllers mirror the runtime's (`rk4_step_closed_loop`, the
//! symplectic steps of `symplectic.rs`, `PdGravity`, `ComputedTorque`, `CollocatedPfl` in
//! `eomgen_runtime`), written again for a joint count known only at run time. With RK4 the
//! controller is re-evaluated at every stage (a continuous-time controller); the symplectic
//! methods hold its effort over each step. Passive joints (`--passive`) get no effort from any
//! controller: `tau = S^T S tau`.

use std::fmt::Write as _;

use eomgen::evaluate::{EvalError, State};
use eomgen::model::Model;
use nalgebra::{DMatrix, DVector};

use super::eval::{self, Terms};
use super::symplectic::{self, Method};

/// The controller closing the loop.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Controller {
    /// No effort: the robot moves under gravity alone.
    None,
    /// PD to the target with gravity compensation, `tau = Kp (q* - q) - Kd qd + G(q)`; with
    /// zero gains (the default) pure gravity compensation.
    GravityComp,
    /// Computed torque to the target, `tau = M (Kp e - Kd qd) + b + G`: critically damped
    /// at `omega` rad/s.
    ComputedTorque,
    /// Collocated partial feedback linearization (Spong) for one passive joint: the actuated
    /// joints follow `Kp (q* + swing atan(qd_u) - q) - Kd qd`, critically damped at `omega`.
    Pfl,
}

/// The integration method.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Integrator {
    Rk4,
    Symplectic(Method),
}

impl Integrator {
    /// The method's name, for the summary and the plots.
    pub fn name(self) -> &'static str {
        match self {
            Integrator::Rk4 => "RK4",
            Integrator::Symplectic(Method::SymplecticEuler) => "symplectic Euler",
            Integrator::Symplectic(Method::ImplicitMidpoint) => "implicit midpoint",
            Integrator::Symplectic(Method::Yoshida4) => "Yoshida 4",
        }
    }
}

/// What to simulate.
pub struct Options {
    pub duration: f64,
    pub dt: f64,
    pub q0: Vec<f64>,
    pub qd0: Vec<f64>,
    pub target: Vec<f64>,
    pub controller: Controller,
    /// Proportional and derivative gains for `GravityComp` (N m/rad, N m s/rad).
    pub kp: f64,
    pub kd: f64,
    /// Bandwidth of `ComputedTorque` and `Pfl` (rad/s).
    pub omega: f64,
    /// The swing-up gain of `Pfl` (rad).
    pub swing: f64,
    pub integrator: Integrator,
}

/// The result: the CSV text, a one-paragraph summary and the sampled trajectories.
pub struct Outcome {
    pub csv: String,
    pub summary: String,
    /// Sample times and, per sample, the joint positions, velocities and applied efforts, and
    /// the total energy (kinetic plus potential, J).
    pub times: Vec<f64>,
    pub positions: Vec<Vec<f64>>,
    pub velocities: Vec<Vec<f64>>,
    pub efforts: Vec<Vec<f64>>,
    pub energy: Vec<f64>,
    /// Whether friction or damping took energy out during the run (`--friction`).
    pub dissipative: bool,
}

/// Positions (rad, m) or velocities (rad/s, m/s) beyond this mean the integration diverged.
const DIVERGED: f64 = 1e8;

/// Why the accelerations at a state could not be computed.
enum StepError {
    /// The mass matrix's factorization failed (the evaluator's message names the pivot).
    MassMatrix(Option<EvalError>),
    /// The evaluator failed otherwise.
    Eval(String),
}

/// The message for a failed step at time `t` of a run with step `dt`: at the initial state
/// the model is at fault; later, a mass matrix that was positive definite at the start can
/// only fail on a state that the integration blew up (M depends on q through sines and
/// cosines, which lose all precision or become NaN for huge or infinite angles).
fn step_message(e: StepError, name: &str, t: f64, dt: f64) -> String {
    match e {
        StepError::Eval(message) => message,
        StepError::MassMatrix(Some(e)) if t == 0.0 => {
            format!("{e} (the initial state: check --q0)")
        }
        StepError::MassMatrix(None) if t == 0.0 => format!(
            "{name}: the mass matrix is not positive definite at the initial state: check the \
             inertias and --q0"
        ),
        StepError::MassMatrix(_) => diverged(t, dt),
    }
}

/// The integration diverged at `t`: what to do about it.
pub(crate) fn diverged(t: f64, dt: f64) -> String {
    format!(
        "the integration diverged at t = {t} s (the state became non-finite or exploded): the \
         step is too large for the system's fastest dynamics (stiff friction on a light link, \
         high gains); try a smaller --dt than {dt}"
    )
}

/// The state `(q, qd)` with efforts `tau` (and no accelerations).
fn state(q: &[f64], qd: &[f64], tau: Vec<f64>) -> State {
    State {
        q: q.to_vec(),
        v: qd.to_vec(),
        a: vec![0.0; qd.len()],
        tau,
    }
}

/// What one evaluation gives: the controller's effort, the resulting acceleration, the total
/// energy and whether friction acts.
struct Step {
    tau: Vec<f64>,
    qdd: Vec<f64>,
    energy: f64,
    friction: bool,
}

/// The controller's effort and the resulting acceleration at `(q, qd)`.
fn step_eval(
    model: &Model,
    terms: &Terms,
    o: &Options,
    q: &[f64],
    qd: &[f64],
) -> Result<Step, StepError> {
    let n = q.len();
    let v = terms
        .at(&state(q, qd, vec![0.0; n]))
        .map_err(StepError::Eval)?;
    // The effort friction takes (zero unless the model includes it, `--friction`).
    let friction = &v.friction;
    let tau: Vec<f64> = match o.controller {
        Controller::None => vec![0.0; n],
        Controller::GravityComp => (0..n)
            .map(|i| o.kp * (o.target[i] - q[i]) - o.kd * qd[i] + v.gravity[i])
            .collect(),
        Controller::ComputedTorque => {
            let (kp, kd) = (o.omega * o.omega, 2.0 * o.omega);
            let a: Vec<f64> = (0..n)
                .map(|i| kp * (o.target[i] - q[i]) - kd * qd[i])
                .collect();
            (0..n)
                .map(|i| {
                    (0..n).map(|j| v.mass_matrix[i][j] * a[j]).sum::<f64>()
                        + v.bias[i]
                        + v.gravity[i]
                        + friction[i]
                })
                .collect()
        }
        Controller::Pfl => pfl(model, o, &v, q, qd),
    };
    let mut tau = tau;
    for &p in &model.passive {
        tau[p] = 0.0;
    }
    let rhs: Vec<f64> = (0..n)
        .map(|i| tau[i] - v.bias[i] - v.gravity[i] - friction[i])
        .collect();
    let qdd = match solve_mass(&v.mass_matrix, &rhs) {
        Ok(qdd) if qdd.iter().all(|x| x.is_finite()) => qdd,
        // Only on failure: the evaluator's forward dynamics names the pivot and joint.
        _ => {
            return Err(match terms.forward_dynamics(&state(q, qd, tau)) {
                Err(e @ EvalError::NotPositiveDefinite { .. }) => StepError::MassMatrix(Some(e)),
                Err(e) => StepError::Eval(e.to_string()),
                Ok(_) => StepError::MassMatrix(None),
            })
        }
    };
    Ok(Step {
        tau,
        qdd,
        energy: v.kinetic_energy + v.potential_energy,
        friction: friction.iter().any(|f| *f != 0.0),
    })
}

/// Collocated partial feedback linearization for the (single) passive joint `u`: `v` on the
/// actuated joints, `qdd_u = -(h_u + M_ua v) / M_uu`, `tau = M qdd + h` (zero on `u`).
fn pfl(model: &Model, o: &Options, v: &eval::Values, q: &[f64], qd: &[f64]) -> Vec<f64> {
    let n = q.len();
    let Some(&u) = model.passive.first() else {
        return vec![0.0; n];
    };
    let h: Vec<f64> = (0..n)
        .map(|i| v.bias[i] + v.gravity[i] + v.friction[i])
        .collect();
    let (kp, kd) = (o.omega * o.omega, 2.0 * o.omega);
    let lead = o.swing * qd[u].atan();
    let mut a: Vec<f64> = (0..n)
        .map(|i| kp * (o.target[i] + lead - q[i]) - kd * qd[i])
        .collect();
    a[u] = 0.0;
    let m = &v.mass_matrix;
    a[u] = -(h[u] + (0..n).map(|j| m[u][j] * a[j]).sum::<f64>()) / m[u][u];
    (0..n)
        .map(|i| (0..n).map(|j| m[i][j] * a[j]).sum::<f64>() + h[i])
        .collect()
}

/// `M`, `h = b + G + F` and `C(q, qd)`.
type HamiltonTerms = (Vec<Vec<f64>>, Vec<f64>, Vec<Vec<f64>>);

/// `M(q)` and the momentum rate `pd = tau - h + (C + C^T) qd` for the symplectic methods.
fn hamilton_terms(terms: &Terms, q: &[f64], qd: &[f64]) -> Result<HamiltonTerms, StepError> {
    let n = q.len();
    let v = terms
        .at(&state(q, qd, vec![0.0; n]))
        .map_err(StepError::Eval)?;
    let h = (0..n)
        .map(|i| v.bias[i] + v.gravity[i] + v.friction[i])
        .collect();
    Ok((v.mass_matrix, h, v.coriolis))
}

/// `x` with `M x = b`, by Cholesky (nalgebra).
fn solve_mass(m: &[Vec<f64>], b: &[f64]) -> Result<Vec<f64>, StepError> {
    let n = b.len();
    let m = DMatrix::from_fn(n, n, |i, j| m[i][j]);
    let chol = m.cholesky().ok_or(StepError::MassMatrix(None))?;
    let x = chol.solve(&DVector::from_column_slice(b));
    Ok(x.iter().copied().collect())
}

fn axpy(a: &[f64], h: f64, b: &[f64]) -> Vec<f64> {
    a.iter().zip(b).map(|(x, y)| x + h * y).collect()
}

fn row(out: &mut String, t: f64, q: &[f64], qd: &[f64], tau: &[f64]) {
    out.push_str(&csv_number(t));
    for &x in q.iter().chain(qd).chain(tau) {
        out.push(',');
        out.push_str(&csv_number(x));
    }
    out.push('\n');
}

/// A number as the CSV writes it: the shortest decimal digits that read back to the same
/// `f64`, in exponent form when that is shorter (`-3.074e-16`, `1e-5`, `2.5e20`) and positional
/// otherwise (`0.25`, `-1.8`, `120`).
pub fn csv_number(x: f64) -> String {
    // Both forms print the shortest digits that round-trip; they differ only in layout.
    let positional = format!("{x}");
    let exponent = format!("{x:e}");
    if exponent.len() < positional.len() {
        exponent
    } else {
        positional
    }
}

/// The number of steps, `round(duration / dt)`, or why the options are invalid.
fn step_count(o: &Options) -> Result<u64, String> {
    let valid = o.dt > 0.0 && o.dt.is_finite() && o.duration >= 0.0 && o.duration.is_finite();
    if !valid {
        return Err("--dt must be positive and --duration non-negative".into());
    }
    let steps = (o.duration / o.dt).round();
    if steps > 1e8 {
        return Err(format!(
            "{steps} steps: choose a larger --dt or a shorter --duration"
        ));
    }
    Ok(steps as u64)
}

impl Outcome {
    /// An empty outcome whose CSV holds the header row for the model's coordinates.
    fn new(model: &Model) -> Outcome {
        let names = model.velocity_names();
        let mut csv = String::from("t");
        for prefix in ["q", "qd", "tau"] {
            for name in &names {
                let _ = write!(csv, ",{prefix}_{name}");
            }
        }
        csv.push('\n');
        Outcome {
            csv,
            summary: String::new(),
            times: Vec::new(),
            positions: Vec::new(),
            velocities: Vec::new(),
            efforts: Vec::new(),
            energy: Vec::new(),
            dissipative: false,
        }
    }

    /// Appends the sample at `t`: a CSV row and the trajectories.
    fn record(&mut self, t: f64, q: &[f64], qd: &[f64], s: &Step) {
        row(&mut self.csv, t, q, qd, &s.tau);
        self.times.push(t);
        self.positions.push(q.to_vec());
        self.velocities.push(qd.to_vec());
        self.efforts.push(s.tau.clone());
        self.energy.push(s.energy);
        self.dissipative |= s.friction;
    }
}

/// One RK4 step of `h` from `(q, qd)`, whose first stage `first` is already evaluated.
fn rk4_step(
    model: &Model,
    terms: &Terms,
    o: &Options,
    (q, qd): (&mut [f64], &mut [f64]),
    first: Step,
    h: f64,
) -> Result<(), StepError> {
    let a1 = first.qdd;
    let v1 = qd.to_vec();
    let stage = |q: &[f64], v: &[f64]| step_eval(model, terms, o, q, v).map(|s| s.qdd);
    let (q2, v2) = (axpy(q, h / 2.0, &v1), axpy(qd, h / 2.0, &a1));
    let a2 = stage(&q2, &v2)?;
    let (q3, v3) = (axpy(q, h / 2.0, &v2), axpy(qd, h / 2.0, &a2));
    let a3 = stage(&q3, &v3)?;
    let (q4, v4) = (axpy(q, h, &v3), axpy(qd, h, &a3));
    let a4 = stage(&q4, &v4)?;
    for i in 0..q.len() {
        q[i] += h / 6.0 * (v1[i] + 2.0 * (v2[i] + v3[i]) + v4[i]);
        qd[i] += h / 6.0 * (a1[i] + 2.0 * (a2[i] + a3[i]) + a4[i]);
    }
    Ok(())
}

/// One step of the symplectic `method` of `h` from `(q, qd)` with the effort `tau` held.
fn symplectic_step(
    terms: &Terms,
    method: Method,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
    h: f64,
) -> Result<(Vec<f64>, Vec<f64>), StepError> {
    let n = q.len();
    let mass = |q: &[f64]| -> Result<Vec<Vec<f64>>, StepError> {
        Ok(hamilton_terms(terms, q, &vec![0.0; n])?.0)
    };
    let rate = |q: &[f64], qd: &[f64], tau: &[f64]| -> Result<Vec<f64>, StepError> {
        let (_, hh, c) = hamilton_terms(terms, q, qd)?;
        Ok((0..n)
            .map(|k| tau[k] - hh[k] + (0..n).map(|j| (c[k][j] + c[j][k]) * qd[j]).sum::<f64>())
            .collect())
    };
    let solve = |m: &[Vec<f64>], b: &[f64]| solve_mass(m, b);
    let sys = symplectic::System {
        mass: &mass,
        rate: &rate,
        solve: &solve,
    };
    symplectic::step(&sys, method, q, qd, tau, h)
}

/// The summary: the final state, and the energy drift (no controller or PFL) or the final
/// tracking error (the other controllers).
fn summary(
    model: &Model,
    o: &Options,
    steps: u64,
    q: &[f64],
    qd: &[f64],
    energy: (f64, f64),
) -> String {
    let h = o.dt;
    let t_end = steps as f64 * h;
    let (e0, e_end) = energy;
    let fmt = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x:.6}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut summary = format!(
        "{}: {} {} steps of {h} s to t = {t_end} s\nq  = [{}]\nqd = [{}]\n",
        model.name,
        steps,
        o.integrator.name(),
        fmt(q),
        fmt(qd)
    );
    if matches!(o.controller, Controller::None | Controller::Pfl) {
        let _ = writeln!(
            summary,
            "energy: {e0:.9e} J at t = 0, {e_end:.9e} J at the end (change {:.3e} J)",
            e_end - e0
        );
    } else {
        let err = (0..q.len())
            .map(|i| (q[i] - o.target[i]).abs())
            .fold(0.0, f64::max);
        let _ = writeln!(summary, "max |q - target| at the end: {err:.3e}");
    }
    summary
}

/// Runs the simulation: `round(duration / dt)` steps of the chosen integrator.
pub fn run(model: &Model, terms: &Terms, o: &Options) -> Result<Outcome, String> {
    let steps = step_count(o)?;
    let (mut q, mut qd) = (o.q0.clone(), o.qd0.clone());
    let h = o.dt;
    let mut out = Outcome::new(model);
    let fail = |e: StepError, t: f64| step_message(e, &model.name, t, h);
    for k in 0..steps {
        let t = k as f64 * h;
        let first = step_eval(model, terms, o, &q, &qd).map_err(|e| fail(e, t))?;
        out.record(t, &q, &qd, &first);
        match o.integrator {
            Integrator::Rk4 => rk4_step(model, terms, o, (&mut q, &mut qd), first, h),
            Integrator::Symplectic(method) => {
                symplectic_step(terms, method, &q, &qd, &first.tau, h).map(|next| (q, qd) = next)
            }
        }
        .map_err(|e| fail(e, t + h))?;
        if q.iter()
            .chain(&qd)
            .any(|x| !x.is_finite() || x.abs() >= DIVERGED)
        {
            return Err(diverged(t + h, h));
        }
    }
    let t_end = steps as f64 * h;
    let last = step_eval(model, terms, o, &q, &qd).map_err(|e| fail(e, t_end))?;
    out.record(t_end, &q, &qd, &last);
    out.summary = summary(model, o, steps, &q, &qd, (out.energy[0], last.energy));
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::csv_number;

    #[test]
    fn csv_numbers_are_shortest_and_read_back_exactly() {
        assert_eq!(csv_number(-3.074e-16), "-3.074e-16");
        assert_eq!(csv_number(1e-5), "1e-5");
        assert_eq!(csv_number(2.5e20), "2.5e20");
        assert_eq!(csv_number(0.25), "0.25");
        assert_eq!(csv_number(-1.8), "-1.8");
        assert_eq!(csv_number(120.0), "120");
        assert_eq!(csv_number(0.0), "0");
        assert_eq!(csv_number(0.1 + 0.2), "0.30000000000000004");
        let mut x = 1.234_567_890_123_456_7e-300_f64;
        let mut values = vec![0.0, -0.0, f64::MIN_POSITIVE, 5e-324, f64::MAX, -f64::MAX];
        while x < 1e300 {
            values.extend([x, -x, x * std::f64::consts::PI, 1.0 / x]);
            x *= 7.3;
        }
        for v in values {
            let s = csv_number(v);
            let back: f64 = s.parse().expect("a number");
            assert_eq!(back.to_bits(), v.to_bits(), "{v:?} printed as {s}");
            assert!(
                s.len() <= format!("{v}").len() && s.len() <= format!("{v:e}").len(),
                "{s}"
            );
        }
    }
}
