//! `eomgen simulate` for a floating base (NQ = NV + 1): RK4 on the configuration manifold
//! (stages integrated from the step's start with the runtime's SE(3) `integrate_into`), with
//! M, b, G, the contact Jacobian and its drift from the library's evaluator, and the
//! contact forward dynamics solved densely each stage (as `eomgen_runtime::contact::solve`
//! does with fixed sizes).
//!
//! Controllers: none (free flight, or standing on the contacts unactuated), `stand` (PD on the
//! joints plus gravity compensation projected through the contacts: the contact forces of least
//! norm that hold the base's gravity, and the joint efforts that go with them) and `hover`
//! (computed torque on the base, a fully actuated thrust and torque, to a level pose at a
//! target position, with PD on the joints).

use std::fmt::Write as _;

use eomgen::evaluate::{Evaluator, State};
use eomgen::model::Model;
use eomgen::{Derived, Input};
use nalgebra::{DMatrix, DVector};

/// The controller closing the loop.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Controller {
    /// No effort at all.
    None,
    /// PD on the joints plus gravity compensation projected through the contacts.
    Stand,
    /// Computed torque on the base (a thrust and torque on it) and PD on the joints.
    Hover,
}

/// What to simulate.
pub struct Options {
    pub duration: f64,
    pub dt: f64,
    /// Initial position coordinates (NQ) and velocities (NV).
    pub q0: Vec<f64>,
    pub v0: Vec<f64>,
    /// Joint targets (one per joint).
    pub target: Vec<f64>,
    /// Where `hover` holds the base, level.
    pub base_target: [f64; 3],
    pub controller: Controller,
    /// Joint PD gains.
    pub kp: f64,
    pub kd: f64,
    /// Bandwidth of the base's computed torque for `hover` (rad/s).
    pub omega: f64,
}

/// The result: CSV, summary, and per sample the base position, the vertical contact forces,
/// the velocities (NV: the base's in its axes, then the joints'), the efforts (NV: the wrench
/// on the base, then the joints') and the total energy (J).
pub struct Outcome {
    pub csv: String,
    pub summary: String,
    pub times: Vec<f64>,
    pub base: Vec<Vec<f64>>,
    pub forces: Vec<Vec<f64>>,
    /// The joint positions (NQ - 7).
    pub joints: Vec<Vec<f64>>,
    pub velocities: Vec<Vec<f64>>,
    pub efforts: Vec<Vec<f64>>,
    pub energy: Vec<f64>,
    /// Whether friction or damping took energy out during the run (`--friction`).
    pub dissipative: bool,
}

/// Everything the dynamics needs at one state.
struct Terms {
    m: DMatrix<f64>,
    /// `b + G + F(v)`.
    h: DVector<f64>,
    gravity: DVector<f64>,
    /// 3K x NV and 3K.
    j: DMatrix<f64>,
    drift: DVector<f64>,
    energy: f64,
    /// Whether friction acts at this state.
    friction: bool,
}

/// The quantities [`terms`] reads, compiled once.
fn compile(derived: &Derived) -> Result<Evaluator, String> {
    let model = derived.model();
    // What `eval` prints that needs no accelerations: M, b, G, F and the energies.
    let at_state = |name: &&str| {
        derived
            .inputs(name)
            .is_some_and(|i| !i.contains(&Input::Qdd))
    };
    let printed = super::eval::printed(derived);
    let mut names: Vec<&str> = printed.iter().map(|n| n.name).filter(at_state).collect();
    if !model.contacts.is_empty() {
        names.extend(["contact_jacobian", "contact_drift"]);
    }
    derived.evaluator(&names).map_err(|e| e.to_string())
}

fn terms(ev: &Evaluator, q: &[f64], v: &[f64]) -> Result<Terms, String> {
    let nv = v.len();
    let state = State {
        q: q.to_vec(),
        v: v.to_vec(),
        ..State::default()
    };
    let values = ev.evaluate(&state).map_err(|e| e.to_string())?;
    let get = |name: &str| super::eval::data(&values, name).to_vec();
    let (b, g) = (get("bias"), get("gravity"));
    let f = match get("friction") {
        f if f.is_empty() => vec![0.0; nv],
        f => f,
    };
    let drift = get("contact_drift");
    let (e, k3) = (
        get("kinetic_energy")[0] + get("potential_energy")[0],
        drift.len(),
    );
    Ok(Terms {
        m: DMatrix::from_row_slice(nv, nv, &get("mass_matrix")),
        h: DVector::from_fn(nv, |i, _| b[i] + g[i] + f[i]),
        gravity: DVector::from_vec(g),
        j: DMatrix::from_row_slice(k3, nv, &get("contact_jacobian")),
        drift: DVector::from_vec(drift),
        energy: e,
        friction: f.iter().any(|x| *x != 0.0),
    })
}

/// Accelerations and contact forces of `M a + h = tau + J^T F`, `J a + drift = 0`.
fn accelerations(t: &Terms, tau: &DVector<f64>) -> Option<(DVector<f64>, DVector<f64>)> {
    let chol = t.m.clone().cholesky()?;
    let free = chol.solve(&(tau - &t.h));
    if t.j.nrows() == 0 {
        return Some((free, DVector::zeros(0)));
    }
    let y = chol.solve(&t.j.transpose());
    let lambda = &t.j * &y;
    let rhs = -(&t.drift + &t.j * &free);
    let forces = lambda.cholesky()?.solve(&rhs);
    Some((free + y * &forces, forces))
}

/// The effort of the controller at `(q, v)`.
fn control(o: &Options, t: &Terms, q: &[f64], v: &[f64]) -> DVector<f64> {
    let nv = v.len();
    let mut tau = DVector::zeros(nv);
    let pd = |i: usize| o.kp * (o.target[i - 6] - q[i + 1]) - o.kd * v[i];
    match o.controller {
        Controller::None => {}
        Controller::Stand => {
            // Least-norm contact forces holding the base's gravity rows, J_b^T F = G_b.
            let jb_t = t.j.columns(0, 6).transpose();
            let pinv = jb_t
                .pseudo_inverse(1e-9)
                .unwrap_or_else(|_| DMatrix::zeros(0, 0));
            let gb = t.gravity.rows(0, 6).into_owned();
            let f = if pinv.ncols() == 6 {
                pinv * gb
            } else {
                DVector::zeros(t.j.nrows())
            };
            let comp = &t.gravity - t.j.transpose() * f;
            for i in 6..nv {
                tau[i] = comp[i] + pd(i);
            }
        }
        Controller::Hover => {
            let (wn, z) = (o.omega, 2.0 * o.omega);
            let r = eomgen_runtime::free_flyer::rotation(&[q[3], q[4], q[5], q[6]]);
            let mut a = DVector::zeros(nv);
            // World position error and velocity; the wanted acceleration in base axes.
            let vw: Vec<f64> = (0..3)
                .map(|i| (0..3).map(|k| r[i][k] * v[k]).sum())
                .collect();
            let aw: Vec<f64> = (0..3)
                .map(|i| wn * wn * (o.base_target[i] - q[i]) - z * vw[i])
                .collect();
            // Attitude error from level: twice the quaternion's vector part (small-angle).
            let e = attitude_error(&q[3..7]);
            for i in 0..3 {
                a[i] = (0..3).map(|k| r[k][i] * aw[k]).sum();
                a[3 + i] = -wn * wn * e[i] - z * v[3 + i];
            }
            for i in 6..nv {
                a[i] = pd(i);
            }
            tau = &t.m * a + &t.h;
        }
    }
    tau
}

/// The attitude error from level, `2 vec(q)` with the sign of the scalar part (twice the
/// half-angle's sine: the rotation vector for small angles), in base axes.
fn attitude_error(q: &[f64]) -> [f64; 3] {
    let sign = if q[3] < 0.0 { -2.0 } else { 2.0 };
    [sign * q[0], sign * q[1], sign * q[2]]
}

/// One evaluation: accelerations, effort, contact forces, energy and whether friction acts at
/// `(q, v)`.
type Eval = (DVector<f64>, DVector<f64>, DVector<f64>, f64, bool);

fn evaluate(
    ev: &Evaluator,
    o: &Options,
    name: &str,
    q: &[f64],
    v: &[f64],
    t: f64,
) -> Result<Eval, String> {
    let terms = terms(ev, q, v)?;
    let tau = control(o, &terms, q, v);
    match accelerations(&terms, &tau) {
        Some((a, f)) if a.iter().chain(f.iter()).all(|x| x.is_finite()) => {
            Ok((a, tau, f, terms.energy, terms.friction))
        }
        _ if t == 0.0 => Err(format!(
            "{name}: the mass matrix or the contacts' J M^-1 J^T is not positive definite at \
             the initial state (contacts that cannot all hold?)"
        )),
        _ => Err(super::simulate::diverged(t, o.dt)),
    }
}

fn integrate(q: &[f64], v: &[f64], h: f64) -> Vec<f64> {
    let mut out = q.to_vec();
    eomgen_runtime::free_flyer::integrate_into(q, v, h, &mut out);
    out
}

fn axpy(a: &DVector<f64>, h: f64, b: &DVector<f64>) -> DVector<f64> {
    a + b * h
}

/// One RK4 step of `h` on the configuration manifold from `(q, v)`, whose first stage's
/// accelerations `a1` are already evaluated; the stages are evaluated at time `t`.
fn rk4_step(
    ev: &Evaluator,
    o: &Options,
    name: &str,
    (q, v): (&[f64], &DVector<f64>),
    a1: &DVector<f64>,
    t: f64,
    h: f64,
) -> Result<(Vec<f64>, DVector<f64>), String> {
    let stage = |dq: &DVector<f64>, dt: f64, v: &DVector<f64>| {
        evaluate(
            ev,
            o,
            name,
            &integrate(q, dq.as_slice(), dt),
            v.as_slice(),
            t,
        )
        .map(|e| e.0)
    };
    let v2 = axpy(v, h / 2.0, a1);
    let a2 = stage(v, h / 2.0, &v2)?;
    let v3 = axpy(v, h / 2.0, &a2);
    let a3 = stage(&v2, h / 2.0, &v3)?;
    let v4 = axpy(v, h, &a3);
    let a4 = stage(&v3, h, &v4)?;
    let mean_v = (v + &v2 * 2.0 + &v3 * 2.0 + &v4) / 6.0;
    let mean_a = (a1 + &a2 * 2.0 + &a3 * 2.0 + &a4) / 6.0;
    Ok((integrate(q, mean_v.as_slice(), h), axpy(v, h, &mean_a)))
}

/// Runs the simulation.
pub fn run(derived: &Derived, o: &Options) -> Result<Outcome, String> {
    let (model, ev) = (derived.model(), &compile(derived)?);
    let nq = model.coordinates() + 7;
    let steps = (o.duration / o.dt).round().max(1.0) as usize;
    let mut q = o.q0.clone();
    let mut v = DVector::from_vec(o.v0.clone());
    let k3 = 3 * model.contacts.len();
    let mut out = Outcome {
        csv: header(model, nq, v.len(), k3),
        summary: String::new(),
        times: Vec::new(),
        base: Vec::new(),
        forces: Vec::new(),
        joints: Vec::new(),
        velocities: Vec::new(),
        efforts: Vec::new(),
        energy: Vec::new(),
        dissipative: false,
    };
    let (mut worst_contact, mut e0, mut e_end) = (0.0_f64, 0.0, 0.0);
    for step in 0..=steps {
        let t = step as f64 * o.dt;
        let (a1, tau, f, energy, friction) = evaluate(ev, o, &model.name, &q, v.as_slice(), t)?;
        if step == 0 {
            e0 = energy;
        }
        e_end = energy;
        out.energy.push(energy);
        out.dissipative |= friction;
        if k3 > 0 {
            let terms = terms(ev, &q, v.as_slice())?;
            let res = &terms.j * &a1 + &terms.drift;
            worst_contact = worst_contact.max(res.amax());
        }
        record(&mut out, t, &q, &v, &tau, &f);
        if step == steps {
            break;
        }
        let h = o.dt;
        (q, v) = rk4_step(ev, o, &model.name, (&q, &v), &a1, t, h)?;
        if q.iter()
            .chain(v.iter())
            .any(|x| !x.is_finite() || x.abs() > 1e8)
        {
            return Err(super::simulate::diverged(t + h, o.dt));
        }
    }
    out.summary = summary(model, o, &out, worst_contact, e0, e_end, k3);
    Ok(out)
}

fn header(model: &Model, nq: usize, nv: usize, k3: usize) -> String {
    let mut cols = vec!["t".to_string()];
    let base_q = ["x", "y", "z", "qx", "qy", "qz", "qw"];
    let base_v = ["vx", "vy", "vz", "wx", "wy", "wz"];
    cols.extend(base_q.iter().map(|c| format!("base_{c}")));
    cols.extend(
        model
            .joints
            .iter()
            .take(nq - 7)
            .map(|j| format!("q_{}", j.name)),
    );
    cols.extend(base_v.iter().map(|c| format!("base_{c}")));
    cols.extend(
        model
            .joints
            .iter()
            .take(nv - 6)
            .map(|j| format!("qd_{}", j.name)),
    );
    cols.extend(["fx", "fy", "fz", "mx", "my", "mz"].map(|c| format!("tau_base_{c}")));
    cols.extend(
        model
            .joints
            .iter()
            .take(nv - 6)
            .map(|j| format!("tau_{}", j.name)),
    );
    for &f in &model.contacts {
        let name = &model.frames[f].name;
        cols.extend(["x", "y", "z"].map(|c| format!("force_{name}_{c}")));
    }
    debug_assert_eq!(cols.len(), 1 + nq + 2 * nv + k3);
    format!("{}\n", cols.join(","))
}

fn record(
    out: &mut Outcome,
    t: f64,
    q: &[f64],
    v: &DVector<f64>,
    tau: &DVector<f64>,
    f: &DVector<f64>,
) {
    let mut line = crate::simulate::csv_number(t);
    for &x in q.iter().chain(v.iter()).chain(tau.iter()).chain(f.iter()) {
        line.push(',');
        line.push_str(&crate::simulate::csv_number(x));
    }
    out.csv.push_str(&line);
    out.csv.push('\n');
    out.times.push(t);
    out.base.push(q[..3].to_vec());
    out.forces
        .push(f.iter().skip(2).step_by(3).copied().collect());
    out.joints.push(q[7..].to_vec());
    out.velocities.push(v.iter().copied().collect());
    out.efforts.push(tau.iter().copied().collect());
}

fn summary(
    model: &Model,
    o: &Options,
    out: &Outcome,
    worst_contact: f64,
    e0: f64,
    e_end: f64,
    k3: usize,
) -> String {
    let mut s = String::new();
    let first = &out.base[0];
    let last = out.base.last().unwrap_or(first);
    let _ = writeln!(
        s,
        "{}: floating base, {} steps of {} s; base position ({:.6}, {:.6}, {:.6}) m at t = 0, \
         ({:.6}, {:.6}, {:.6}) m at the end",
        model.name,
        out.times.len() - 1,
        o.dt,
        first[0],
        first[1],
        first[2],
        last[0],
        last[1],
        last[2]
    );
    if k3 > 0 {
        let fz: Vec<String> = out
            .forces
            .last()
            .map(|f| f.iter().map(|x| format!("{x:.3}")).collect())
            .unwrap_or_default();
        let _ = writeln!(
            s,
            "contacts: max |J a + Jdot v| = {worst_contact:.3e} m/s^2; vertical forces at the \
             end: {} N",
            fz.join(", ")
        );
    }
    if o.controller == Controller::None {
        let _ = writeln!(
            s,
            "energy: {e0:.9e} J at t = 0, {e_end:.9e} J at the end (change {:.3e} J)",
            e_end - e0
        );
    }
    s
}
