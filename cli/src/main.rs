//! The `eomgen` command line (clap): `generate`, `show`, `info`, `eval`, `simulate`. Run
//! `eomgen --help`. It is a crate of its own (`eomgen-cli`) so that build scripts depending on
//! the `eomgen` library compile none of its dependencies.
//!
//! Exit codes: 0 on success, 1 on bad input (one line on stderr, starting with
//! `eomgen: error:`), 2 on bad usage (clap's message). Nothing panics visibly: a panic would be
//! a bug, and is reported as one line too.

mod conditioning;
mod eval;
mod floating_base;
mod info;
mod plot;
mod progress;
mod simulate;
mod simulate_floating;
mod symplectic;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use clap::builder::PossibleValuesParser;
use clap::{Args, CommandFactory, Parser, Subcommand, ValueEnum};

use eomgen::dynamics::Derivation;
use eomgen::evaluate::State;
use eomgen::model::Model;
use eomgen::report::{self, Form, Format, ShowOptions, Term};
use eomgen::{Builder, Derived, ModelOptions, SymbolicParams};

#[derive(Parser, Debug)]
#[command(
    name = "eomgen",
    version,
    about = "Symbolic equations of motion for robots: URDF in, no_std Rust and readable equations out",
    long_about = "Symbolic equations of motion for robots: URDF in, no_std Rust and readable \
                  equations out.\n\nJoint coordinates q1, q2, ... follow the model's joint order: \
                  depth first from the root, the child joints of a link sorted by name \
                  (Pinocchio's order), unless --joint-order says otherwise. SI units throughout.\n\n\
                  Exit status: 0 on success, 1 on bad input (a message on stderr), 2 on bad usage."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Writes the Rust module for a robot (to stdout without -o), as a build script would.
    Generate(GenerateArgs),
    /// Prints the equations of motion for people: text, LaTeX or Markdown.
    Show(ShowArgs),
    /// Prints the kinematic tree, masses, operation counts and derivation time.
    Info(InfoArgs),
    /// Evaluates M, b, G, tau and the forward dynamics at one state, to check a model quickly.
    Eval(EvalArgs),
    /// Integrates the motion (RK4, through the CAS interpreter) and writes the trajectory as CSV.
    Simulate(SimulateArgs),
}

/// Options shared by every command that loads a model.
#[derive(Args, Debug)]
struct ModelArgs {
    /// Gravity in world axes, m/s^2.
    #[arg(
        long,
        value_name = "X,Y,Z",
        default_value = "0,0,-9.81",
        allow_hyphen_values = true,
        value_parser = parse_vec3
    )]
    gravity: [f64; 3],
    /// The order of the moving joints, by URDF name, every moving joint once, parents first
    /// [default: depth first, children by joint name]
    #[arg(long, value_name = "A,B,...", value_delimiter = ',')]
    joint_order: Option<Vec<String>>,
    /// Rotor inertia (armature) added to the mass matrix's diagonal, per joint: kg m^2
    /// (revolute) or kg (prismatic).
    #[arg(long, value_name = "JOINT=VALUE,...", value_delimiter = ',', value_parser = parse_armature)]
    armature: Vec<(String, f64)>,
    /// Includes the URDF's joint friction, <dynamics damping friction>, in the inverse and
    /// forward dynamics: tau = M qdd + b + G + damping qd + friction sign(qd) (no stiction).
    #[arg(long)]
    friction: bool,
    /// With --friction, replaces sign(qd) by qd / sqrt(qd^2 + EPS^2) (EPS in rad/s or m/s)
    /// [default: 0, the exact sign]
    #[arg(
        long,
        value_name = "EPS",
        default_value_t = 0.0,
        hide_default_value = true,
        allow_hyphen_values = true
    )]
    coulomb_smoothing: f64,
    /// Fills links without <inertial> from their <collision> boxes, cylinders and spheres, of
    /// this uniform density (kg/m^3); each filled link is reported on stderr.
    #[arg(long, value_name = "KG_PER_M3", allow_hyphen_values = true)]
    density: Option<f64>,
    /// Repairs a moving body's impossible rotational inertia (not positive semi-definite, or
    /// breaking the triangle inequality) instead of refusing the robot: its principal moments
    /// become their mean, as MuJoCo's balanceinertia does; each repair is reported on stderr.
    #[arg(long)]
    repair_inertia: bool,
    /// Lets the root link move freely (a floating base, as Pinocchio's free flyer): q = [base
    /// position (3), unit quaternion x, y, z, w (4), joints], velocities = [base linear, angular
    /// (base axes), joints]
    #[arg(long)]
    floating_base: bool,
    /// A 3D point contact at the origin of this link (repeatable, in order): adds
    /// contact_jacobian, contact_drift and contact_forward_dynamics
    #[arg(long = "contact", value_name = "LINK")]
    contacts: Vec<String>,
    /// A 6D contact at the frame of this link (repeatable, in order, after the points): its
    /// spatial acceleration is held, 6 rows (linear, then angular, world axes)
    #[arg(long = "contact-frame", value_name = "LINK")]
    contact_frames: Vec<String>,
    /// A 3D point contact at a position (m) in the frame of this link (repeatable, in order,
    /// after the --contact points)
    #[arg(long = "contact-at", value_name = "LINK:X,Y,Z", allow_hyphen_values = true, value_parser = parse_contact_at)]
    contacts_at: Vec<(String, [f64; 3])>,
    /// A joint without an actuator (repeatable): adds selection, ACTUATED_JOINT_NAMES and
    /// forward_dynamics_actuated; simulate applies no effort to it
    #[arg(long = "passive", value_name = "JOINT")]
    passive: Vec<String>,
    /// Honours the URDF's <mimic> tags: a mimic joint is no coordinate but follows the joint it
    /// mimics (multiplier x joint + offset); every quantity is in the independent joints
    #[arg(long)]
    mimic: bool,
    /// Refuse robots with more degrees of freedom than this.
    #[arg(long, value_name = "N", default_value_t = eomgen::DEFAULT_MAX_DOF)]
    max_dof: usize,
    /// Refuse robots whose derivation needs more expression graph nodes than this (each takes
    /// some 60 bytes).
    #[arg(long, value_name = "N", default_value_t = eomgen::DEFAULT_MAX_GRAPH_NODES)]
    max_graph_nodes: usize,
}

impl ModelArgs {
    fn options(&self, symbolic: &Option<Vec<String>>) -> ModelOptions {
        // Every field, without `..Default::default()`: a new option has to be given a flag
        // (or a deliberate default) here.
        ModelOptions {
            gravity: self.gravity,
            joint_order: self.joint_order.clone(),
            symbolic: match symbolic {
                None => SymbolicParams::None,
                Some(v) if v.is_empty() => SymbolicParams::All,
                Some(v) => SymbolicParams::Links(v.clone()),
            },
            armature: self.armature.clone(),
            friction: self.friction,
            coulomb_smoothing: self.coulomb_smoothing,
            inertia_from_collision: self.density,
            repair_inertia: self.repair_inertia,
            floating_base: self.floating_base,
            contact_points: self.contacts.clone(),
            contact_frames: self.contact_frames.clone(),
            contact_points_at: self.contacts_at.clone(),
            passive_joints: self.passive.clone(),
            mimic_joints: self.mimic,
        }
    }

    /// A builder for `urdf` with these options and limits.
    fn builder(&self, urdf: &Path, symbolic: &Option<Vec<String>>) -> Builder {
        Builder::new(urdf)
            .model_options(self.options(symbolic))
            .max_dof(self.max_dof)
            .max_graph_nodes(self.max_graph_nodes)
    }
}

/// A library error, with the command-line flag that raises a limit instead of the Builder
/// option.
fn cli_error(e: eomgen::Error) -> Failure {
    match e {
        eomgen::Error::Limit {
            file,
            what,
            value,
            limit,
            raise,
        } => eomgen::Error::Limit {
            file,
            what,
            value,
            limit,
            raise: match raise {
                "Builder::max_dof" => "--max-dof",
                "Builder::max_graph_nodes" => "--max-graph-nodes",
                other => other,
            },
        }
        .into(),
        e => e.into(),
    }
}

fn parse_contact_at(s: &str) -> Result<(String, [f64; 3]), String> {
    let Some((link, at)) = s.rsplit_once(':') else {
        return Err(format!("expected LINK:X,Y,Z, got `{s}`"));
    };
    Ok((link.to_string(), parse_vec3(at)?))
}

fn parse_armature(s: &str) -> Result<(String, f64), String> {
    let Some((joint, value)) = s.split_once('=') else {
        return Err(format!("expected JOINT=VALUE, got `{s}`"));
    };
    match value.trim().parse::<f64>() {
        Ok(v) => Ok((joint.trim().to_string(), v)),
        Err(_) => Err(format!("`{value}` is not a number")),
    }
}

#[derive(Args, Debug)]
struct GenerateArgs {
    /// The robot's URDF file.
    urdf: PathBuf,
    /// Write the module to this file (only if its content changed) instead of stdout.
    #[arg(short, long, value_name = "FILE")]
    output: Option<PathBuf>,
    /// The generated type, UpperCamelCase [default: the robot name in UpperCamelCase]
    #[arg(long, value_name = "T")]
    type_name: Option<String>,
    /// The module name, snake_case, used in the banner [default: the robot name in snake_case]
    #[arg(long, value_name = "M")]
    module_name: Option<String>,
    /// Keep masses, centres of mass, inertias and joint offsets as fields of the generated
    /// struct (Default holds the URDF's values): of every link, or of the links listed.
    #[arg(long, value_name = "LINK,...", num_args = 0..=1, value_delimiter = ',')]
    symbolic: Option<Vec<String>>,
    /// Generate only these functions (and those they call), e.g. inverse_dynamics,gravity
    /// [default: all]
    #[arg(long, value_name = "NAME,...", value_delimiter = ',')]
    only: Option<Vec<String>>,
    /// Also generate the derivatives of the dynamics: inverse_dynamics_derivatives,
    /// forward_dynamics_derivatives and mass_matrix_inverse
    #[arg(long)]
    derivatives: bool,
    /// Also generate identification: regressor, parameters, base_regressor and
    /// base_parameters (tau = Y(q, qd, qdd) pi, linear in the inertial parameters)
    #[arg(long)]
    regressor: bool,
    #[command(flatten)]
    model: ModelArgs,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum FormatArg {
    Text,
    Latex,
    Markdown,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum FormArg {
    /// Each entry as one simplified formula, with short names (s1, c12) in a legend.
    Expanded,
    /// Shared temporaries, then the entries: for large robots.
    Program,
    /// M and b as sums of each body's share, J_P^T m J_P + J_R^T Theta J_R and
    /// J_P^T m Jdot_P qd + J_R^T (Theta Jdot_R qd + omega x Theta omega), from the body's
    /// Jacobians (small fixed-base robots; --term does not apply)
    ProjectedNewtonEuler,
    /// The Hamiltonian H(q, p) = 1/2 p^T M^-1 p + V and Hamilton's equations (small
    /// fixed-base robots; --term does not apply)
    Hamiltonian,
}

const TERMS: [&str; 11] = [
    "M", "B", "C", "G", "b", "coriolis", "tau", "T", "V", "dtau_dq", "all",
];

#[derive(Args, Debug)]
struct ShowArgs {
    /// The robot's URDF file.
    urdf: PathBuf,
    /// What to print, one or several separated by commas: M (mass matrix), B (Craig's
    /// Coriolis matrix), C (Craig's centrifugal matrix), G (gravity), b (bias), coriolis
    /// (Coriolis matrix C(q, qd)), tau (inverse dynamics), T and V (energies), dtau_dq (see
    /// --derivatives), or all.
    #[arg(
        long,
        value_name = "TERM",
        default_value = "all",
        value_delimiter = ',',
        value_parser = PossibleValuesParser::new(TERMS),
        hide_possible_values = true
    )]
    term: Vec<String>,
    /// One entry of the term, 1-based: I,J for matrices (for B: I,COLUMN or I,J,K with the
    /// pair J < K), I for vectors.
    #[arg(long, value_name = "I,J", value_parser = parse_indices)]
    entry: Option<Indices>,
    /// Output language.
    #[arg(long, value_enum, default_value_t = FormatArg::Text)]
    format: FormatArg,
    /// With --format latex: a complete document that pdflatex compiles, instead of fragments
    #[arg(long)]
    standalone: bool,
    /// Keep masses, centres of mass, inertias and link lengths as named symbols instead of the
    /// URDF's numbers: of every link, or of the links listed (put the URDF first, or write
    /// --symbolic=LINK,...).
    #[arg(long, value_name = "LINK,...", num_args = 0..=1, value_delimiter = ',')]
    symbolic: Option<Vec<String>>,
    /// Significant digits of numbers; 0 prints the shortest exact decimals.
    #[arg(long, value_name = "N", default_value_t = 6)]
    digits: usize,
    /// Print d tau / d q, the derivatives of inverse dynamics in the joint positions (instead
    /// of every term, or after the terms of --term). For small robots: beyond 4,000 operations
    /// (the 9-joint panda has 5,800) it is an error.
    #[arg(long)]
    derivatives: bool,
    /// How entries are written.
    #[arg(long, value_enum, default_value_t = FormArg::Expanded)]
    form: FormArg,
    /// In expanded form, a term whose expansion exceeds N terms is shown in program form.
    #[arg(long, value_name = "N", default_value_t = 100)]
    max_terms: usize,
    /// Instead of the equations, print the base parameters for identification: the minimal
    /// set of combinations of inertial parameters that the dynamics depend on, each as its
    /// exact formula (with --friction and --armature, their coefficients too).
    #[arg(long, conflicts_with_all = ["term", "entry", "form"])]
    base_parameters: bool,
    #[command(flatten)]
    model: ModelArgs,
}

#[derive(Args, Debug)]
struct InfoArgs {
    /// The robot's URDF file.
    urdf: PathBuf,
    #[command(flatten)]
    model: ModelArgs,
}

#[derive(Args, Debug)]
struct EvalArgs {
    /// The robot's URDF file.
    urdf: PathBuf,
    /// Joint positions (rad or m), one per joint, separated by commas; with --floating-base
    /// the base's position and unit quaternion x, y, z, w first (NQ = 7 + joints).
    #[arg(long, value_name = "Q1,Q2,...", allow_hyphen_values = true, value_parser = parse_numbers)]
    q: Numbers,
    /// Joint velocities; with --floating-base the base's linear and angular velocity in its own
    /// axes first [default: 0]
    #[arg(long, value_name = "QD1,...", allow_hyphen_values = true, value_parser = parse_numbers)]
    qd: Option<Numbers>,
    /// Joint accelerations for the inverse dynamics [default: 0]
    #[arg(long, value_name = "QDD1,...", allow_hyphen_values = true, value_parser = parse_numbers)]
    qdd: Option<Numbers>,
    /// Joint torques (N m) or forces (N) for the forward dynamics [default: 0]
    #[arg(long, value_name = "TAU1,...", allow_hyphen_values = true, value_parser = parse_numbers)]
    tau: Option<Numbers>,
    /// Significant digits of numbers; 0 prints the shortest exact decimals.
    #[arg(long, value_name = "N", default_value_t = 0)]
    digits: usize,
    #[command(flatten)]
    model: ModelArgs,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum ControllerArg {
    /// No effort: the robot moves under gravity alone.
    None,
    /// tau = G(q) + Kp (target - q) - Kd qd (pure gravity compensation with the default zero gains).
    GravityComp,
    /// Computed torque to the target, critically damped at --omega.
    ComputedTorque,
    /// Collocated partial feedback linearization (Spong) for one passive joint (--passive):
    /// the actuated joints go to the target, critically damped at --omega, their target moved
    /// by --swing times atan of the passive joint's velocity (swing-up); no effort on the
    /// passive joint.
    Pfl,
    /// Floating base on contacts: PD on the joints (--kp, --kd) plus gravity compensation
    /// projected through the contacts.
    Stand,
    /// Floating base: computed torque on the base (thrust and torque) to a level pose at
    /// --base-target, critically damped at --omega; PD on the joints.
    Hover,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum IntegratorArg {
    /// Classical Runge-Kutta, fourth order (the controller re-evaluated at every stage).
    Rk4,
    /// Symplectic Euler on Hamilton's equations, first order (fixed-point iterations; the
    /// effort held over each step).
    SymplecticEuler,
    /// The implicit midpoint rule on Hamilton's equations: second order, symplectic.
    ImplicitMidpoint,
    /// Yoshida's fourth-order composition of three implicit midpoint steps: symplectic.
    Yoshida4,
}

#[derive(Args, Debug)]
struct SimulateArgs {
    /// The robot's URDF file.
    urdf: PathBuf,
    /// Simulated time (s).
    #[arg(long, value_name = "S", default_value_t = 1.0)]
    duration: f64,
    /// Time step (s).
    #[arg(long, value_name = "H", default_value_t = 1e-3)]
    dt: f64,
    /// Initial joint positions [default: 0]
    #[arg(long, value_name = "Q1,Q2,...", allow_hyphen_values = true, value_parser = parse_numbers)]
    q0: Option<Numbers>,
    /// Initial joint velocities [default: 0]
    #[arg(long, value_name = "QD1,...", allow_hyphen_values = true, value_parser = parse_numbers)]
    qd0: Option<Numbers>,
    /// Target joint positions of the controller [default: the initial positions]
    #[arg(long, value_name = "Q1,...", allow_hyphen_values = true, value_parser = parse_numbers)]
    target: Option<Numbers>,
    /// The controller closing the loop.
    #[arg(long, value_enum, default_value_t = ControllerArg::None)]
    controller: ControllerArg,
    /// Proportional gain of gravity-comp (N m/rad or N/m).
    #[arg(long, value_name = "KP", default_value_t = 0.0)]
    kp: f64,
    /// Derivative gain of gravity-comp (N m s/rad or N s/m).
    #[arg(long, value_name = "KD", default_value_t = 0.0)]
    kd: f64,
    /// Bandwidth of computed-torque and pfl (rad/s): Kp = omega^2, Kd = 2 omega.
    #[arg(long, value_name = "RAD_PER_S", default_value_t = 10.0)]
    omega: f64,
    /// Swing-up gain of pfl (rad): the actuated joints' target moves by SWING atan(qd_passive);
    /// its sign depends on the robot (negative for an arm with a passive elbow).
    #[arg(
        long,
        value_name = "SWING",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    swing: f64,
    /// The integration method (a floating base takes RK4 only).
    #[arg(long, value_enum, default_value_t = IntegratorArg::Rk4)]
    integrator: IntegratorArg,
    /// Writes the CSV (t, q_*, qd_*, tau_* per joint; each number the shortest text that reads
    /// back exactly) to FILE and a summary to stdout, instead of the CSV to stdout.
    #[arg(long, value_name = "FILE")]
    csv: Option<PathBuf>,
    /// Also plots the run, as SVG or PNG by FILE's extension: the joint positions against time
    /// to FILE, and beside it FILE-velocities, FILE-efforts and FILE-energy (the energy drift).
    /// With a floating base, FILE has the base position, FILE-forces the vertical contact
    /// forces and FILE-joints the joint positions.
    #[arg(long, value_name = "FILE.svg|FILE.png")]
    plot: Option<PathBuf>,
    /// With --floating-base: the base's initial position and orientation (a unit quaternion
    /// x, y, z, w) [default: 0,0,0,0,0,0,1]
    #[arg(long, value_name = "X,Y,Z[,QX,QY,QZ,QW]", allow_hyphen_values = true, value_parser = parse_numbers)]
    base: Option<Numbers>,
    /// With --controller hover: where the base is held, level [default: its initial position]
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true, value_parser = parse_numbers)]
    base_target: Option<Numbers>,
    #[command(flatten)]
    model: ModelArgs,
}

/// A list of numbers from the command line.
#[derive(Clone, Debug)]
struct Numbers(Vec<f64>);

/// A list of 1-based indices.
#[derive(Clone, Debug)]
struct Indices(Vec<usize>);

fn parse_numbers(s: &str) -> Result<Numbers, String> {
    let items: Vec<&str> = s
        .split(|c: char| c == ',' || c.is_whitespace())
        .filter(|t| !t.is_empty())
        .collect();
    if items.is_empty() {
        return Err("expected numbers separated by commas".into());
    }
    items
        .iter()
        .map(|t| match t.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(format!("`{t}` is not a finite number")),
        })
        .collect::<Result<Vec<f64>, String>>()
        .map(Numbers)
}

fn parse_vec3(s: &str) -> Result<[f64; 3], String> {
    let v = parse_numbers(s)?.0;
    <[f64; 3]>::try_from(v.as_slice()).map_err(|_| format!("expected 3 numbers, got {}", v.len()))
}

fn parse_indices(s: &str) -> Result<Indices, String> {
    let items: Result<Vec<usize>, String> = s
        .split(',')
        .map(|t| match t.trim().parse::<usize>() {
            Ok(i) if i >= 1 => Ok(i),
            _ => Err(format!("`{t}` is not an index (1, 2, ...)")),
        })
        .collect();
    let items = items?;
    if items.len() > 3 {
        return Err("expected at most 3 indices".into());
    }
    Ok(Indices(items))
}

/// A failure to report on stderr with exit status 1.
struct Failure(String);

impl<E: std::fmt::Display> From<E> for Failure {
    fn from(e: E) -> Failure {
        Failure(e.to_string())
    }
}

/// Entry point of the binary.
fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            let _ = e.print();
            return ExitCode::from(e.exit_code().clamp(0, 255) as u8);
        }
    };
    // A panic is a bug: report it in one line, without a backtrace.
    std::panic::set_hook(Box::new(|_| {}));
    let result = std::panic::catch_unwind(|| run(cli)).unwrap_or_else(|payload| {
        let what = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic".into());
        Err(Failure(format!("internal error: {what} (please report)")))
    });
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure(message)) => {
            // One line per line of the message (a file's format errors come one per line),
            // and no control or bidirectional-text characters from names in the URDF reach
            // the terminal.
            for line in message.lines().filter(|l| !l.trim().is_empty()) {
                let line = line.split_whitespace().collect::<Vec<_>>().join(" ");
                let line = terminal_safe(&line);
                let _ = writeln!(std::io::stderr(), "eomgen: error: {line}");
            }
            ExitCode::from(1)
        }
    }
}

/// Writes to stdout; a closed pipe (`eomgen show ... | head`) is not an error.
/// Control characters other than newline and tab, and bidirectional-text controls, from names
/// in a URDF must not drive the terminal: each is written as an escape such as `\u{1b}`.
fn terminal_safe(text: &str) -> String {
    text.split('\n')
        .map(eomgen::emit::names::comment_text)
        .collect::<Vec<_>>()
        .join("\n")
}

fn emit(text: &str) -> Result<(), Failure> {
    let mut out = std::io::stdout().lock();
    let text = terminal_safe(text);
    match out.write_all(text.as_bytes()).and_then(|_| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(Failure(format!("cannot write to stdout: {e}")))
        }
        _ => Ok(()),
    }
}

/// The file name of a path, for headings (never a full path of this machine).
fn file_name(p: &Path) -> String {
    p.file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_else(|| p.display().to_string())
}

/// Loads the model of `b`, printing its warnings on stderr whether loading succeeds or not.
fn load(b: &Builder) -> Result<Model, Failure> {
    let (model, warnings) = b.model_with_warnings();
    warn(&warnings);
    Ok(model?)
}

/// Prints the model's warnings on stderr, one line each.
fn warn(warnings: &[eomgen::model::ModelWarning]) {
    warn_lines(warnings.iter().map(|w| w.to_string()));
}

/// Prints warnings on stderr, one line each.
fn warn_lines(warnings: impl IntoIterator<Item = String>) {
    for w in warnings {
        let line = w.split_whitespace().collect::<Vec<_>>().join(" ");
        let line = terminal_safe(&line);
        let _ = writeln!(std::io::stderr(), "eomgen: warning: {line}");
    }
}

/// Derives within the limits of `b` (degrees of freedom, graph size).
fn derive(b: &Builder, model: &Model) -> Result<Derivation, Failure> {
    let label = format!(
        "deriving the equations of {} ({} joints)",
        model.name,
        model.dof()
    );
    progress::run(&label, || b.derive(model)).map_err(cli_error)
}

/// [`derive`] for the evaluator (`eval`, `simulate`, `info`'s conditioning samples).
fn derived(b: &Builder, model: Model) -> Result<Derived, Failure> {
    let label = format!(
        "deriving the equations of {} ({} joints)",
        model.name,
        model.dof()
    );
    progress::run(&label, || b.derived_from(model)).map_err(cli_error)
}

fn run(cli: Cli) -> Result<(), Failure> {
    match cli.command {
        Command::Generate(a) => generate(a),
        Command::Show(a) => show(a),
        Command::Info(a) => info_cmd(a),
        Command::Eval(a) => eval_cmd(a),
        Command::Simulate(a) => simulate_cmd(a),
    }
}

fn generate(a: GenerateArgs) -> Result<(), Failure> {
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
    let (generated, _, _) =
        progress::run(&label, || b.generate_with_report()).map_err(cli_error)?;
    match &a.output {
        Some(path) => {
            eomgen::write_if_changed(path, generated.source.as_bytes())?;
            Ok(())
        }
        None => emit(&generated.source),
    }
}

fn show(a: ShowArgs) -> Result<(), Failure> {
    let mut terms = Vec::new();
    for t in &a.term {
        match Term::parse(t) {
            Some(t) => terms.push(t),
            None => terms.extend(Term::ALL),
        }
    }
    if a.derivatives {
        if a.term == ["all"] {
            terms.clear();
        }
        terms.push(Term::DtauDq);
    }
    // Each term once, in the order asked.
    let mut seen = Vec::new();
    terms.retain(|t| {
        let new = !seen.contains(t);
        seen.push(*t);
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
    if a.entry.is_some() && terms.len() != 1 {
        Cli::command()
            .error(
                clap::error::ErrorKind::ArgumentConflict,
                "--entry needs exactly one --term (M, B, C, G, b, coriolis, tau or dtau_dq)",
            )
            .exit();
    }
    let mut b = a.model.builder(&a.urdf, &a.symbolic);
    if a.base_parameters {
        b = b.regressor();
    }
    if terms.contains(&Term::DtauDq) {
        b = b.derivatives();
    }
    let model = load(&b)?;
    let d = derive(&b, &model)?;
    let opts = ShowOptions {
        terms,
        entry: a.entry.map(|e| e.0),
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
    };
    let text = progress::run("printing the equations", || {
        if a.base_parameters {
            report::render_base_parameters(&model, &d, &opts)
        } else {
            report::render(&model, &d, &opts)
        }
    })
    .map_err(|e| match e {
        report::ReportError::GraphFull(full) => Failure(format!(
            "{}: {full} while expanding the equations for print: raise it with \
             --max-graph-nodes, or print with --form program",
            a.urdf.display()
        )),
        report::ReportError::Derivatives(why) => Failure(format!("{}: {why}", a.urdf.display())),
        report::ReportError::TooLarge(why) => Failure(format!("{}: {why}", a.urdf.display())),
        e => e.into(),
    })?;
    emit(&text)
}

fn info_cmd(a: InfoArgs) -> Result<(), Failure> {
    let b = a.model.builder(&a.urdf, &None);
    let start = Instant::now();
    let model = load(&b)?;
    let load_time = start.elapsed();
    let label = format!(
        "deriving and emitting {} ({} joints)",
        model.name,
        model.dof()
    );
    let start = Instant::now();
    let (generated, model, d) =
        progress::run(&label, || b.generate_with_report()).map_err(cli_error)?;
    let derive: std::time::Duration = d.timings.iter().map(|t| t.1).sum();
    let emit_time = start.elapsed().saturating_sub(derive + load_time);
    warn_lines(conditioning::sampled_warnings(&Derived::from_parts(
        model.clone(),
        d.clone(),
    )));
    emit(&info::print(
        &model,
        &d,
        &generated,
        &file_name(&a.urdf),
        load_time,
        emit_time,
    ))
}

/// The CSV to `path` and the summary to stdout, or the CSV to stdout.
fn csv_or_summary(path: Option<&Path>, csv: &str, summary: &str) -> Result<(), Failure> {
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
fn simulate_floating_cmd(a: SimulateArgs, b: Builder, model: Model) -> Result<(), Failure> {
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
    let mut q0 = vec![0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0];
    match a.base {
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
    q0.extend(&joints);
    let controller = match a.controller {
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
    };
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
        floating_plots(path, &model, &options, &outcome).map_err(Failure)?;
    }
    csv_or_summary(a.csv.as_deref(), &outcome.csv, &outcome.summary)
}

fn eval_cmd(a: EvalArgs) -> Result<(), Failure> {
    let b = a.model.builder(&a.urdf, &None);
    let model = load(&b)?;
    let joints = model.coordinate_names().join(", ");
    let floating = usize::from(model.is_floating());
    let nv = model.coordinates() + 6 * floating;
    let nq = nv + floating;
    let check = |flag: &str, v: Option<Numbers>, n: usize| -> Result<Vec<f64>, Failure> {
        match v {
            None => Ok(vec![0.0; n]),
            Some(Numbers(v)) if v.len() == n => Ok(v),
            Some(Numbers(v)) if floating == 1 => Err(Failure(format!(
                "{flag} has {} value(s), but {} has {n} {} coordinates (the floating base's \
                 first; joints: {joints})",
                v.len(),
                model.name,
                if n == nq { "position" } else { "velocity" }
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
    if !model.is_floating() {
        warn_lines(conditioning::warning(
            model,
            &values.mass_matrix,
            "at this state",
        ));
    }
    let digits = (a.digits > 0).then_some(a.digits);
    emit(&eval::print(model, &state, &values, &qdd, digits))
}

fn simulate_cmd(a: SimulateArgs) -> Result<(), Failure> {
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
        fixed_plots(path, &model, &options, &outcome).map_err(Failure)?;
    }
    csv_or_summary(a.csv.as_deref(), &outcome.csv, &outcome.summary)
}

/// The title of the energy plot: whether the run should conserve energy.
fn energy_title(
    name: &str,
    integrator: &str,
    controlled: bool,
    dissipative: bool,
    dt: f64,
) -> String {
    match (controlled, dissipative) {
        (true, _) => format!("{name}: energy (controlled run: not conserved by design)"),
        (false, true) => format!("{name}: energy (damped run: not conserved by design)"),
        (false, false) => format!("{name}: energy drift of {integrator} (dt = {dt} s)"),
    }
}

/// The plots of a fixed-base run: positions to `path`, velocities, efforts and energy beside.
fn fixed_plots(
    path: &Path,
    model: &Model,
    o: &simulate::Options,
    out: &simulate::Outcome,
) -> Result<(), String> {
    let name = &model.name;
    // One series per coordinate: with mimic joints, the independent joints.
    let joints = model.coordinate_joints();
    let names: Vec<String> = joints
        .iter()
        .map(|&j| model.joints[j].name.clone())
        .collect();
    let rotating: Vec<bool> = joints
        .iter()
        .map(|&j| model.joints[j].kind.is_revolute())
        .collect();
    let controlled = o.controller != simulate::Controller::None;
    let (energy, series, y_label) = plot::energy_drift(&out.energy);
    let figure = |title: String, y_label: String, names: Vec<String>, values| plot::Figure {
        title,
        y_label,
        names,
        times: &out.times,
        values,
    };
    let efforts = if controlled {
        format!("{name}: joint efforts of the controller")
    } else {
        format!("{name}: joint efforts (no controller: none applied)")
    };
    plot::write_all(&[
        (
            path.to_path_buf(),
            figure(
                format!("{name}: joint positions"),
                format!("position ({})", plot::unit(&rotating, "rad", "m")),
                names.clone(),
                &out.positions,
            ),
        ),
        (
            plot::sibling(path, "velocities"),
            figure(
                format!("{name}: joint velocities"),
                format!("velocity ({})", plot::unit(&rotating, "rad/s", "m/s")),
                names.clone(),
                &out.velocities,
            ),
        ),
        (
            plot::sibling(path, "efforts"),
            figure(
                efforts,
                format!("effort ({})", plot::unit(&rotating, "N m", "N")),
                names,
                &out.efforts,
            ),
        ),
        (
            plot::sibling(path, "energy"),
            figure(
                energy_title(name, o.integrator.name(), controlled, out.dissipative, o.dt),
                y_label.to_string(),
                vec![series.to_string()],
                &energy,
            ),
        ),
    ])
}

/// The plots of a floating-base run: the base position to `path`; beside it the vertical
/// contact forces, the joint positions, the velocities and efforts (the joints', or the
/// base's without joints) and the energy.
fn floating_plots(
    path: &Path,
    model: &Model,
    o: &simulate_floating::Options,
    out: &simulate_floating::Outcome,
) -> Result<(), String> {
    let name = &model.name;
    let nj = out.joints.first().map_or(0, Vec::len);
    let joints: Vec<String> = model
        .joints
        .iter()
        .take(nj)
        .map(|j| j.name.clone())
        .collect();
    let rotating: Vec<bool> = model
        .joints
        .iter()
        .take(nj)
        .map(|j| j.kind.is_revolute())
        .collect();
    let nv = 6 + nj;
    let controlled = o.controller != simulate_floating::Controller::None;
    let xyz = |prefix: &str| ["x", "y", "z"].map(|c| format!("{prefix}{c}")).to_vec();
    let (energy, series, energy_label) = plot::energy_drift(&out.energy);
    let base_v = plot::columns(&out.velocities, 0..3);
    let joint_v = plot::columns(&out.velocities, 6..nv);
    let base_f = plot::columns(&out.efforts, 0..3);
    let joint_f = plot::columns(&out.efforts, 6..nv);
    let figure = |title: String, y_label: &str, names: Vec<String>, values| plot::Figure {
        title,
        y_label: y_label.to_string(),
        names,
        times: &out.times,
        values,
    };
    let mut figures = vec![(
        path.to_path_buf(),
        figure(
            format!("{name}: base position"),
            "position (m)",
            xyz(""),
            &out.base,
        ),
    )];
    if !model.contacts.is_empty() {
        let feet = model
            .contacts
            .iter()
            .map(|&f| model.frames[f].name.clone())
            .collect();
        figures.push((
            plot::sibling(path, "forces"),
            figure(
                format!("{name}: vertical contact forces"),
                "vertical force (N)",
                feet,
                &out.forces,
            ),
        ));
    }
    if nj > 0 {
        let unit = |a, l| plot::unit(&rotating, a, l);
        figures.extend([
            (
                plot::sibling(path, "joints"),
                figure(
                    format!("{name}: joint positions"),
                    &format!("position ({})", unit("rad", "m")),
                    joints.clone(),
                    &out.joints,
                ),
            ),
            (
                plot::sibling(path, "velocities"),
                figure(
                    format!("{name}: joint velocities"),
                    &format!("velocity ({})", unit("rad/s", "m/s")),
                    joints.clone(),
                    &joint_v,
                ),
            ),
            (
                plot::sibling(path, "efforts"),
                figure(
                    format!("{name}: joint efforts"),
                    &format!("effort ({})", unit("N m", "N")),
                    joints,
                    &joint_f,
                ),
            ),
        ]);
    } else {
        figures.push((
            plot::sibling(path, "velocities"),
            figure(
                format!("{name}: base linear velocity (base axes)"),
                "velocity (m/s)",
                xyz("v"),
                &base_v,
            ),
        ));
        if controlled {
            figures.push((
                plot::sibling(path, "efforts"),
                figure(
                    format!("{name}: force on the base (base axes)"),
                    "force (N)",
                    xyz("f"),
                    &base_f,
                ),
            ));
        }
    }
    figures.push((
        plot::sibling(path, "energy"),
        figure(
            energy_title(name, "RK4", controlled, out.dissipative, o.dt),
            energy_label,
            vec![series.to_string()],
            &energy,
        ),
    ));
    plot::write_all(&figures)
}
