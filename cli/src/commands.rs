//! The commands: each reads its flags, calls the library and writes its output.

use std::path::Path;
use std::time::Instant;

use clap::{CommandFactory, ValueEnum};

use eomgen::catalogue::{self, Layout};
use eomgen::evaluate::{State, Value};
use eomgen::model::Model;
use eomgen::report::{self, Form, Format, ShowOptions};
use eomgen::Builder;

use crate::flags::{
    cli_error, Cli, ControllerArg, EvalArgs, FormArg, FormatArg, GenerateArgs, InfoArgs,
    IntegratorArg, Numbers, ShowArgs, SimulateArgs,
};
use crate::{
    conditioning, derived, emit, eval, file_name, info, load, plot, progress, simulate,
    simulate_floating, symplectic, warn_lines, Failure,
};

pub(crate) fn generate(a: GenerateArgs) -> Result<(), Failure> {
    let mut b = a.model.builder(&a.urdf, &a.symbolic);
    if let Some(t) = &a.type_name {
        b = b.type_name(t);
    }
    if let Some(m) = &a.module_name {
        b = b.module_name(m);
    }
    if let Some(only) = &a.only {
        b = b.quantities(only);
    }
    if a.derivatives {
        b = b.derivatives();
    }
    if a.regressor {
        b = b.regressor();
    }
    // Fail fast on bad input, before a long derivation.
    let model = load(&b)?;
    let label = format!(
        "deriving and emitting {} ({} joints)",
        model.name,
        model.dof()
    );
    let (generated, _) = progress::run(&label, || b.generate_derived()).map_err(cli_error)?;
    match &a.output {
        Some(path) => {
            eomgen::write_if_changed(path, generated.source.as_bytes())?;
            Ok(())
        }
        None => emit(&generated.source),
    }
}

/// The quantities `show` prints: `--term` (plus the inverse dynamics derivatives with
/// `--derivatives`), each once in the order asked. Exits on flags that conflict with them.
fn show_terms(a: &ShowArgs) -> Vec<String> {
    let mut terms = a.term.clone();
    if a.derivatives {
        if a.term == ["all"] {
            terms.clear();
        }
        terms.push("inverse_dynamics_derivatives".to_string());
    }
    // Each quantity once, in the order asked.
    let mut seen: Vec<String> = Vec::new();
    terms.retain(|t| {
        let name = catalogue::canonical(t).to_string();
        let new = !seen.contains(&name);
        seen.push(name);
        new
    });
    if a.standalone && !matches!(a.format, FormatArg::Latex) {
        Cli::command()
            .error(
                clap::error::ErrorKind::ArgumentConflict,
                "--standalone makes a LaTeX document: it needs --format latex",
            )
            .exit();
    }
    if a.entry.is_some() && (terms.len() != 1 || terms[0] == "all") {
        Cli::command()
            .error(
                clap::error::ErrorKind::ArgumentConflict,
                "--entry needs exactly one --term (M, B, C, G, b, coriolis, tau or dtau_dq)",
            )
            .exit();
    }
    terms
}

/// The report's options from `show`'s flags, for the quantities `terms`.
fn show_options(a: &ShowArgs, terms: Vec<String>) -> ShowOptions {
    ShowOptions {
        terms,
        entry: a.entry.as_ref().map(|e| e.0.clone()),
        format: match a.format {
            FormatArg::Text => Format::Text,
            FormatArg::Latex => Format::Latex,
            FormatArg::Markdown => Format::Markdown,
        },
        form: match a.form {
            FormArg::Expanded => Form::Expanded,
            FormArg::Program => Form::Program,
            FormArg::ProjectedNewtonEuler => Form::ProjectedNewtonEuler,
            FormArg::Hamiltonian => Form::Hamiltonian,
        },
        digits: (a.digits > 0).then_some(a.digits),
        max_terms: a.max_terms,
        source: Some(file_name(&a.urdf)),
        standalone: a.standalone,
    }
}

/// A report's failure, naming the URDF and what to do about it.
fn show_failure(urdf: &Path, e: report::ReportError) -> Failure {
    match e {
        report::ReportError::GraphFull(full) => Failure(format!(
            "{}: {full} while expanding the equations for print: raise it with \
             --max-graph-nodes, or print with --form program",
            urdf.display()
        )),
        report::ReportError::Derivatives(why) => Failure(format!("{}: {why}", urdf.display())),
        report::ReportError::TooLarge(why) => Failure(format!("{}: {why}", urdf.display())),
        e => e.into(),
    }
}

pub(crate) fn show(a: ShowArgs) -> Result<(), Failure> {
    let terms = show_terms(&a);
    let mut b = a.model.builder(&a.urdf, &a.symbolic);
    if a.base_parameters {
        b = b.regressor();
    }
    let partials =
        |t: &String| catalogue::notation(t).is_some_and(|n| n.layout == Layout::Partials);
    if terms.iter().any(partials) {
        b = b.derivatives();
    }
    let model = load(&b)?;
    let derived = derived(&b, model)?;
    let opts = show_options(&a, terms);
    let text = progress::run("printing the equations", || {
        if a.base_parameters {
            report::print_base_parameters(&derived, &opts)
        } else {
            report::print(&derived, &opts)
        }
    })
    .map_err(|e| show_failure(&a.urdf, e))?;
    emit(&text)
}

pub(crate) fn info_cmd(a: InfoArgs) -> Result<(), Failure> {
    let b = a.model.builder(&a.urdf, &None);
    let b = if a.derivatives { b.derivatives() } else { b };
    let start = Instant::now();
    let model = load(&b)?;
    let load_time = start.elapsed();
    let label = format!(
        "deriving and emitting {} ({} joints)",
        model.name,
        model.dof()
    );
    let start = Instant::now();
    let (generated, derived) = progress::run(&label, || b.generate_derived()).map_err(cli_error)?;
    let derive: std::time::Duration = derived.timings().iter().map(|t| t.1).sum();
    let emit_time = start.elapsed().saturating_sub(derive + load_time);
    warn_lines(conditioning::sampled_warnings(&derived));
    emit(&info::print(
        &derived,
        &generated,
        &file_name(&a.urdf),
        load_time,
        emit_time,
    ))
}

/// The CSV to `path` and the summary to stdout, or the CSV to stdout.
pub(crate) fn csv_or_summary(path: Option<&Path>, csv: &str, summary: &str) -> Result<(), Failure> {
    match path {
        Some(path) => {
            std::fs::write(path, csv)
                .map_err(|e| Failure(format!("cannot write {}: {e}", path.display())))?;
            emit(summary)
        }
        None => emit(csv),
    }
}

/// `simulate` for a floating base: initial state, controller, run, plots.
pub(crate) fn simulate_floating_cmd(
    a: SimulateArgs,
    b: Builder,
    model: Model,
) -> Result<(), Failure> {
    if !matches!(a.integrator, IntegratorArg::Rk4) {
        return Err(Failure(format!(
            "{}: a floating base is simulated with RK4 only (--integrator rk4)",
            model.name
        )));
    }
    let (nj, nv) = (model.dof(), model.nv());
    let count = |flag: &str, v: Option<Numbers>, n: usize, default: Vec<f64>| match v {
        None => Ok(default),
        Some(Numbers(v)) if v.len() == n => Ok(v),
        Some(Numbers(v)) => Err(Failure(format!(
            "{flag} has {} value(s), but {} needs {n} with a floating base",
            v.len(),
            model.name
        ))),
    };
    let joints = count("--q0", a.q0, nj, vec![0.0; nj])?;
    let mut q0 = initial_base(a.base)?;
    q0.extend(&joints);
    let controller = floating_controller(a.controller, &model)?;
    let base_target = match a.base_target {
        None => [q0[0], q0[1], q0[2]],
        Some(Numbers(v)) if v.len() == 3 => [v[0], v[1], v[2]],
        Some(Numbers(v)) => {
            return Err(Failure(format!(
                "--base-target has {} value(s): give X,Y,Z",
                v.len()
            )))
        }
    };
    let options = simulate_floating::Options {
        base_target,
        duration: a.duration,
        dt: a.dt,
        v0: count("--qd0", a.qd0, nv, vec![0.0; nv])?,
        target: count("--target", a.target, nj, joints)?,
        q0,
        controller,
        kp: a.kp,
        kd: a.kd,
        omega: a.omega,
    };
    if let Some(path) = &a.plot {
        plot::Format::of(path).map_err(Failure)?;
    }
    let derived = derived(&b, model.clone())?;
    let outcome = simulate_floating::run(&derived, &options).map_err(Failure)?;
    if let Some(path) = &a.plot {
        plot::floating_plots(path, &model, &options, &outcome).map_err(Failure)?;
    }
    csv_or_summary(a.csv.as_deref(), &outcome.csv, &outcome.summary)
}

/// The floating base's initial position and orientation from `--base` (X,Y,Z, or with a
/// quaternion that is normalized), at the origin and level without it.
fn initial_base(base: Option<Numbers>) -> Result<Vec<f64>, Failure> {
    let mut q0 = vec![0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0];
    match base {
        None => {}
        Some(Numbers(v)) if v.len() == 3 => q0[..3].copy_from_slice(&v),
        Some(Numbers(v)) if v.len() == 7 => {
            let n = v[3..].iter().map(|x| x * x).sum::<f64>().sqrt();
            if n == 0.0 || !n.is_finite() {
                return Err(Failure("--base: the quaternion is zero".into()));
            }
            q0[..3].copy_from_slice(&v[..3]);
            q0[3..]
                .iter_mut()
                .zip(&v[3..])
                .for_each(|(o, x)| *o = x / n);
        }
        Some(Numbers(v)) => {
            return Err(Failure(format!(
                "--base has {} value(s): give X,Y,Z or X,Y,Z,QX,QY,QZ,QW",
                v.len()
            )))
        }
    }
    Ok(q0)
}

/// The controller of a floating-base run: none, stand (needs contacts) or hover.
fn floating_controller(
    controller: ControllerArg,
    model: &Model,
) -> Result<simulate_floating::Controller, Failure> {
    Ok(match controller {
        ControllerArg::None => simulate_floating::Controller::None,
        ControllerArg::Stand if model.contacts.is_empty() => {
            return Err(Failure(format!(
            "{}: --controller stand holds the robot on its contacts: give them with --contact LINK",
            model.name
        )))
        }
        ControllerArg::Stand => simulate_floating::Controller::Stand,
        ControllerArg::Hover => simulate_floating::Controller::Hover,
        other => {
            return Err(Failure(format!(
            "{}: --controller {} is for a fixed base; a floating base takes none, stand or hover",
            model.name,
            other
                .to_possible_value()
                .map(|v| v.get_name().to_string())
                .unwrap_or_default()
        )))
        }
    })
}

pub(crate) fn eval_cmd(a: EvalArgs) -> Result<(), Failure> {
    let b = a.model.builder(&a.urdf, &None);
    let model = load(&b)?;
    let joints = model.coordinate_names().join(", ");
    // Velocity coordinates: the base's six, then the independent joints' (mimic joints
    // follow); one position more per quaternion.
    let nv = model.coordinates() + 6 * usize::from(model.is_floating());
    let nq = nv + (model.nq() - model.nv());
    let which = |n: usize| if n == nq { "position" } else { "velocity" };
    let check = |flag: &str, v: Option<Numbers>, n: usize| -> Result<Vec<f64>, Failure> {
        match v {
            None => Ok(vec![0.0; n]),
            Some(Numbers(v)) if v.len() == n => Ok(v),
            Some(Numbers(v)) if model.is_floating() => Err(Failure(format!(
                "{flag} has {} value(s), but {} has {n} {} coordinates (the floating base's \
                 first; joints: {joints})",
                v.len(),
                model.name,
                which(n)
            ))),
            Some(Numbers(v)) if nq != nv => Err(Failure(format!(
                "{flag} has {} value(s), but {} has {n} {} coordinates (7 positions and 6 \
                 velocities for a floating joint; joints: {joints})",
                v.len(),
                model.name,
                which(n)
            ))),
            Some(Numbers(v)) => Err(Failure(format!(
                "{flag} has {} value(s), but {} has {n} joint(s): {joints}",
                v.len(),
                model.name
            ))),
        }
    };
    let state = State {
        q: check("--q", Some(a.q), nq)?,
        v: check("--qd", a.qd, nv)?,
        a: check("--qdd", a.qdd, nv)?,
        tau: check("--tau", a.tau, nv)?,
    };
    let derived = derived(&b, model)?;
    let (values, qdd) = eval::evaluate(&derived, &state).map_err(Failure)?;
    let model = derived.model();
    if model.velocities_are_rates() {
        let mass_matrix = values.iter().find(|v| v.name == "mass_matrix");
        let rows = mass_matrix.map(Value::rows).unwrap_or_default();
        warn_lines(conditioning::warning(model, &rows, "at this state"));
    }
    let digits = (a.digits > 0).then_some(a.digits);
    emit(&eval::print(model, &state, &values, &qdd, digits))
}

pub(crate) fn simulate_cmd(a: SimulateArgs) -> Result<(), Failure> {
    let b = a.model.builder(&a.urdf, &None);
    let model = load(&b)?;
    if model.is_floating() && model.is_coupled() {
        return Err(Failure(format!(
            "{}: `eomgen simulate` does not handle mimic joints on a floating base yet: \
             generate the code (eomgen generate --floating-base --mimic) and call it",
            model.name
        )));
    }
    if model.is_floating() {
        return simulate_floating_cmd(a, b, model);
    }
    if matches!(a.controller, ControllerArg::Stand | ControllerArg::Hover) {
        return Err(Failure(format!(
            "{}: --controller stand and hover are for a floating base (--floating-base)",
            model.name
        )));
    }
    if matches!(a.controller, ControllerArg::Pfl) && model.passive.len() != 1 {
        return Err(Failure(format!(
            "{}: --controller pfl needs exactly one passive joint (--passive JOINT), not {}",
            a.urdf.display(),
            model.passive.len()
        )));
    }
    let n = model.coordinates();
    let check = |flag: &str, v: Option<Numbers>, default: &[f64]| -> Result<Vec<f64>, Failure> {
        match v {
            None => Ok(default.to_vec()),
            Some(Numbers(v)) if v.len() == n => Ok(v),
            Some(Numbers(v)) => Err(Failure(format!(
                "{flag} has {} value(s), but {} has {n} joint(s)",
                v.len(),
                model.name
            ))),
        }
    };
    let q0 = check("--q0", a.q0, &vec![0.0; n])?;
    let options = simulate::Options {
        duration: a.duration,
        dt: a.dt,
        qd0: check("--qd0", a.qd0, &vec![0.0; n])?,
        target: check("--target", a.target, &q0)?,
        q0,
        controller: match a.controller {
            ControllerArg::GravityComp => simulate::Controller::GravityComp,
            ControllerArg::ComputedTorque => simulate::Controller::ComputedTorque,
            ControllerArg::Pfl => simulate::Controller::Pfl,
            _ => simulate::Controller::None,
        },
        kp: a.kp,
        kd: a.kd,
        omega: a.omega,
        swing: a.swing,
        integrator: match a.integrator {
            IntegratorArg::Rk4 => simulate::Integrator::Rk4,
            IntegratorArg::SymplecticEuler => {
                simulate::Integrator::Symplectic(symplectic::Method::SymplecticEuler)
            }
            IntegratorArg::ImplicitMidpoint => {
                simulate::Integrator::Symplectic(symplectic::Method::ImplicitMidpoint)
            }
            IntegratorArg::Yoshida4 => {
                simulate::Integrator::Symplectic(symplectic::Method::Yoshida4)
            }
        },
    };
    if let Some(path) = &a.plot {
        plot::Format::of(path).map_err(Failure)?;
    }
    let derived = derived(&b, model.clone())?;
    let symplectic = matches!(options.integrator, simulate::Integrator::Symplectic(_));
    let terms = eval::Terms::new(&derived, symplectic).map_err(Failure)?;
    let outcome = simulate::run(&model, &terms, &options).map_err(Failure)?;
    if let Some(path) = &a.plot {
        plot::fixed_plots(path, &model, &options, &outcome).map_err(Failure)?;
    }
    csv_or_summary(a.csv.as_deref(), &outcome.csv, &outcome.summary)
}
