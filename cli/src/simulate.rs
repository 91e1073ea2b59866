//! `eomgen simulate`: integrates the equation of motion with RK4, evaluating M, b and G through
//! the CAS interpreter (the command line cannot compile the generated code), and writes the
//! trajectory as CSV.
//!
//! The integrator and controllers mirror the runtime's (`rk4_step_closed_loop`, `PdGravity`,
//! `ComputedTorque` in `eomgen_runtime`), written again for a joint count known only at run
//! time; the controller is re-evaluated at every RK4 stage (a continuous-time controller).

use std::fmt::Write as _;

use eomgen::dynamics::Derivation;
use eomgen::model::Model;

use super::eval;

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
    /// Bandwidth of `ComputedTorque` (rad/s).
    pub omega: f64,
}

/// The result: the CSV text, a one-paragraph summary and the joint trajectories.
pub struct Outcome {
    pub csv: String,
    pub summary: String,
    /// Sample times and, per sample, the joint positions.
    pub times: Vec<f64>,
    pub positions: Vec<Vec<f64>>,
}

/// Positions (rad, m) or velocities (rad/s, m/s) beyond this mean the integration diverged.
const DIVERGED: f64 = 1e8;

/// Why the accelerations at a state could not be computed.
enum StepError {
    /// The mass matrix's factorization failed at this pivot (1-based) of `of`.
    MassMatrix { pivot: usize, of: usize },
    /// The interpreter failed.
    Eval(String),
}

/// The message for a failed step at time `t` of a run with step `dt`: at the initial state
/// the model is at fault; later, a mass matrix that was positive definite at the start can
/// only fail on a state that the integration blew up (M depends on q through sines and
/// cosines, which lose all precision or become NaN for huge or infinite angles).
fn step_message(e: StepError, name: &str, t: f64, dt: f64) -> String {
    match e {
        StepError::Eval(message) => message,
        StepError::MassMatrix { pivot, of } if t == 0.0 => format!(
            "{name}: the mass matrix is not positive definite at the initial state (pivot \
             {pivot} of {of}): check the inertias and --q0"
        ),
        StepError::MassMatrix { .. } => diverged(t, dt),
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

/// M, b, G and the energies at `(q, qd)`.
fn terms(model: &Model, d: &Derivation, q: &[f64], qd: &[f64]) -> Result<eval::Values, String> {
    let n = q.len();
    eval::evaluate(
        model,
        d,
        &eval::State {
            q: q.to_vec(),
            qd: qd.to_vec(),
            qdd: vec![0.0; n],
            tau: vec![0.0; n],
        },
    )
}

/// The controller's effort and the resulting acceleration at `(q, qd)`.
fn step_eval(
    model: &Model,
    d: &Derivation,
    o: &Options,
    q: &[f64],
    qd: &[f64],
) -> Result<(Vec<f64>, Vec<f64>), StepError> {
    let n = q.len();
    let v = terms(model, d, q, qd).map_err(StepError::Eval)?;
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
    };
    let rhs: Vec<f64> = (0..n)
        .map(|i| tau[i] - v.bias[i] - v.gravity[i] - friction[i])
        .collect();
    let qdd = eval::cholesky_solve(&v.mass_matrix, &rhs).map_err(|k| StepError::MassMatrix {
        pivot: k + 1,
        of: n,
    })?;
    Ok((tau, qdd))
}

fn axpy(a: &[f64], h: f64, b: &[f64]) -> Vec<f64> {
    a.iter().zip(b).map(|(x, y)| x + h * y).collect()
}

fn row(out: &mut String, t: f64, q: &[f64], qd: &[f64], tau: &[f64]) {
    let _ = write!(out, "{t}");
    for x in q.iter().chain(qd).chain(tau) {
        let _ = write!(out, ",{x}");
    }
    out.push('\n');
}

/// Runs the simulation: `round(duration / dt)` RK4 steps.
pub fn run(model: &Model, d: &Derivation, o: &Options) -> Result<Outcome, String> {
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
    let steps = steps as u64;
    let names = model.coordinate_names();
    let mut csv = String::from("t");
    for prefix in ["q", "qd", "tau"] {
        for name in &names {
            let _ = write!(csv, ",{prefix}_{name}");
        }
    }
    csv.push('\n');
    let (mut q, mut qd) = (o.q0.clone(), o.qd0.clone());
    let e = |q: &[f64], qd: &[f64]| -> Result<f64, String> {
        let v = terms(model, d, q, qd)?;
        Ok(v.kinetic_energy + v.potential_energy)
    };
    let e0 = e(&q, &qd)?;
    let h = o.dt;
    let (mut times, mut positions) = (Vec::new(), Vec::new());
    let fail = |e: StepError, t: f64| step_message(e, &model.name, t, h);
    for k in 0..steps {
        let t = k as f64 * h;
        let (tau, a1) = step_eval(model, d, o, &q, &qd).map_err(|e| fail(e, t))?;
        row(&mut csv, t, &q, &qd, &tau);
        times.push(t);
        positions.push(q.clone());
        let v1 = qd.clone();
        let stage = |q: &[f64], v: &[f64]| step_eval(model, d, o, q, v).map_err(|e| fail(e, t + h));
        let (q2, v2) = (axpy(&q, h / 2.0, &v1), axpy(&qd, h / 2.0, &a1));
        let (_, a2) = stage(&q2, &v2)?;
        let (q3, v3) = (axpy(&q, h / 2.0, &v2), axpy(&qd, h / 2.0, &a2));
        let (_, a3) = stage(&q3, &v3)?;
        let (q4, v4) = (axpy(&q, h, &v3), axpy(&qd, h, &a3));
        let (_, a4) = stage(&q4, &v4)?;
        for i in 0..q.len() {
            q[i] += h / 6.0 * (v1[i] + 2.0 * (v2[i] + v3[i]) + v4[i]);
            qd[i] += h / 6.0 * (a1[i] + 2.0 * (a2[i] + a3[i]) + a4[i]);
        }
        if q.iter()
            .chain(&qd)
            .any(|x| !x.is_finite() || x.abs() >= DIVERGED)
        {
            return Err(diverged(t + h, h));
        }
    }
    let t_end = steps as f64 * h;
    let (tau, _) = step_eval(model, d, o, &q, &qd).map_err(|e| fail(e, t_end))?;
    row(&mut csv, t_end, &q, &qd, &tau);
    times.push(t_end);
    positions.push(q.clone());
    let e_end = e(&q, &qd)?;
    let fmt = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x:.6}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut summary = format!(
        "{}: {} RK4 steps of {h} s to t = {t_end} s\nq  = [{}]\nqd = [{}]\n",
        model.name,
        steps,
        fmt(&q),
        fmt(&qd)
    );
    if o.controller == Controller::None {
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
    Ok(Outcome {
        csv,
        summary,
        times,
        positions,
    })
}

/// Escapes text for SVG/XML.
fn xml(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// An SVG line plot of every joint position against time: one `<polyline>` per joint (class
/// `trajectory`, attribute `data-joint` with the joint's name), a frame with the time and
/// position ranges, and a legend. Written by hand to keep the command line free of a plotting
/// dependency; at most about 2000 points per line.
pub fn svg(title: &str, joints: &[&str], times: &[f64], positions: &[Vec<f64>]) -> String {
    const PALETTE: [&str; 10] = [
        "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
        "#bcbd22", "#17becf",
    ];
    let (w, h, left, right, top, bottom) = (900.0, 480.0, 70.0, 170.0, 40.0, 50.0);
    let (pw, ph) = (w - left - right, h - top - bottom);
    let t_max = times.last().copied().unwrap_or(0.0).max(f64::MIN_POSITIVE);
    let t_min = times.first().copied().unwrap_or(0.0).min(t_max);
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for q in positions.iter().flatten().filter(|x| x.is_finite()) {
        lo = lo.min(*q);
        hi = hi.max(*q);
    }
    // No finite sample at all: an arbitrary range.
    if lo > hi {
        (lo, hi) = (-1.0, 1.0);
    }
    if hi - lo < 1e-9 {
        (lo, hi) = (lo - 0.5, hi + 0.5);
    }
    let x = |t: f64| left + pw * (t - t_min) / (t_max - t_min).max(f64::MIN_POSITIVE);
    let y = |q: f64| top + ph * (hi - q) / (hi - lo);
    let stride = (times.len() / 2000).max(1);
    let mut out = String::new();
    let _ = writeln!(
        out,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" \
         viewBox=\"0 0 {w} {h}\" font-family=\"sans-serif\" font-size=\"12\">"
    );
    let _ = writeln!(out, "<rect width=\"{w}\" height=\"{h}\" fill=\"white\"/>");
    let _ = writeln!(
        out,
        "<text x=\"{}\" y=\"24\" text-anchor=\"middle\" font-size=\"15\">{}</text>",
        left + pw / 2.0,
        xml(title)
    );
    let _ = writeln!(
        out,
        "<rect x=\"{left}\" y=\"{top}\" width=\"{pw}\" height=\"{ph}\" fill=\"none\" \
         stroke=\"black\"/>"
    );
    let labels = [
        (left, h - bottom + 18.0, "start", format!("{t_min} s")),
        (left + pw, h - bottom + 18.0, "end", format!("{t_max} s")),
        (left + pw / 2.0, h - 12.0, "middle", "time (s)".to_string()),
        (left - 6.0, top + 4.0, "end", format!("{hi:.4}")),
        (left - 6.0, top + ph, "end", format!("{lo:.4}")),
        (left - 6.0, top + ph / 2.0, "end", "q (rad, m)".to_string()),
    ];
    for (lx, ly, anchor, text) in labels {
        let _ = writeln!(
            out,
            "<text x=\"{lx}\" y=\"{ly}\" text-anchor=\"{anchor}\">{}</text>",
            xml(&text)
        );
    }
    for (j, name) in joints.iter().enumerate() {
        let color = PALETTE[j % PALETTE.len()];
        let mut points = String::new();
        let samples = times.iter().zip(positions).enumerate();
        for (k, (t, q)) in samples {
            let keep = k % stride == 0 || k + 1 == times.len();
            if let (true, Some(qj)) = (keep, q.get(j).filter(|v| v.is_finite())) {
                let _ = write!(points, "{:.2},{:.2} ", x(*t), y(*qj));
            }
        }
        let _ = writeln!(
            out,
            "<polyline class=\"trajectory\" data-joint=\"{}\" fill=\"none\" \
             stroke=\"{color}\" stroke-width=\"1.5\" points=\"{}\"/>",
            xml(name),
            points.trim_end()
        );
        let ly = top + 14.0 + 18.0 * j as f64;
        let lx = w - right + 12.0;
        let _ = writeln!(
            out,
            "<line x1=\"{lx}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"{color}\" \
             stroke-width=\"3\"/><text x=\"{}\" y=\"{ly}\">{}</text>",
            ly - 4.0,
            lx + 20.0,
            ly - 4.0,
            lx + 26.0,
            xml(name)
        );
    }
    out.push_str("</svg>\n");
    out
}
