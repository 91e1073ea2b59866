//! The flags of every command, as clap reads them: one `Args` struct per command, the
//! options shared by the commands that load a model, and the value enums. What the flags
//! mean for the library is in `options.rs`; how list values are read, in `values.rs`.

use std::path::PathBuf;

use clap::builder::PossibleValuesParser;
use clap::{Args, Parser, Subcommand, ValueEnum};
use eomgen::catalogue::NOTATIONS;

use super::values::{
    parse_armature, parse_contact_at, parse_indices, parse_numbers, parse_vec3, Indices, Numbers,
};

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
/// The command line: one subcommand.
pub(crate) struct Cli {
    #[command(subcommand)]
    pub(crate) command: Command,
}

#[derive(Subcommand, Debug)]
pub(crate) enum Command {
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
pub(crate) struct ModelArgs {
    /// Gravity in world axes, m/s^2.
    #[arg(
        long,
        value_name = "X,Y,Z",
        default_value = "0,0,-9.81",
        allow_hyphen_values = true,
        value_parser = parse_vec3
    )]
    pub(crate) gravity: [f64; 3],
    /// The order of the moving joints, by URDF name, every moving joint once, parents first
    /// [default: depth first, children by joint name]
    #[arg(long, value_name = "A,B,...", value_delimiter = ',')]
    pub(crate) joint_order: Option<Vec<String>>,
    /// Rotor inertia (armature) added to the mass matrix's diagonal, per joint: kg m^2
    /// (revolute) or kg (prismatic).
    #[arg(long, value_name = "JOINT=VALUE,...", value_delimiter = ',', value_parser = parse_armature)]
    pub(crate) armature: Vec<(String, f64)>,
    /// Includes the URDF's joint friction, <dynamics damping friction>, in the inverse and
    /// forward dynamics: tau = M qdd + b + G + damping qd + friction sign(qd) (no stiction).
    #[arg(long)]
    pub(crate) friction: bool,
    /// With --friction, replaces sign(qd) by qd / sqrt(qd^2 + EPS^2) (EPS in rad/s or m/s)
    /// [default: 0, the exact sign]
    #[arg(
        long,
        value_name = "EPS",
        default_value_t = 0.0,
        hide_default_value = true,
        allow_hyphen_values = true
    )]
    pub(crate) coulomb_smoothing: f64,
    /// Fills links without <inertial> from their <collision> boxes, cylinders and spheres, of
    /// this uniform density (kg/m^3); each filled link is reported on stderr.
    #[arg(long, value_name = "KG_PER_M3", allow_hyphen_values = true)]
    pub(crate) density: Option<f64>,
    /// Repairs a moving body's impossible rotational inertia (not positive semi-definite, or
    /// breaking the triangle inequality) instead of refusing the robot: its principal moments
    /// become their mean, as MuJoCo's balanceinertia does; each repair is reported on stderr.
    #[arg(long)]
    pub(crate) repair_inertia: bool,
    /// Lets the root link move freely (a floating base, as Pinocchio's free flyer): q = [base
    /// position (3), unit quaternion x, y, z, w (4), joints], velocities = [base linear, angular
    /// (base axes), joints]
    #[arg(long)]
    pub(crate) floating_base: bool,
    /// A 3D point contact at the origin of this link (repeatable, in order): adds
    /// contact_jacobian, contact_drift and contact_forward_dynamics
    #[arg(long = "contact", value_name = "LINK")]
    pub(crate) contacts: Vec<String>,
    /// A 6D contact at the frame of this link (repeatable, in order, after the points): its
    /// spatial acceleration is held, 6 rows (linear, then angular, world axes)
    #[arg(long = "contact-frame", value_name = "LINK")]
    pub(crate) contact_frames: Vec<String>,
    /// A 3D point contact at a position (m) in the frame of this link (repeatable, in order,
    /// after the --contact points)
    #[arg(long = "contact-at", value_name = "LINK:X,Y,Z", allow_hyphen_values = true, value_parser = parse_contact_at)]
    pub(crate) contacts_at: Vec<(String, [f64; 3])>,
    /// A joint without an actuator (repeatable): adds selection, ACTUATED_JOINT_NAMES and
    /// forward_dynamics_actuated; simulate applies no effort to it
    #[arg(long = "passive", value_name = "JOINT")]
    pub(crate) passive: Vec<String>,
    /// Honours the URDF's <mimic> tags: a mimic joint is no coordinate but follows the joint it
    /// mimics (multiplier x joint + offset); every quantity is in the independent joints
    #[arg(long)]
    pub(crate) mimic: bool,
    /// Refuse robots with more degrees of freedom than this.
    #[arg(long, value_name = "N", default_value_t = eomgen::DEFAULT_MAX_DOF)]
    pub(crate) max_dof: usize,
    /// Refuse robots whose derivation needs more expression graph nodes than this (each takes
    /// some 60 bytes).
    #[arg(long, value_name = "N", default_value_t = eomgen::DEFAULT_MAX_GRAPH_NODES)]
    pub(crate) max_graph_nodes: usize,
}

#[derive(Args, Debug)]
pub(crate) struct GenerateArgs {
    /// The robot's URDF file.
    pub(crate) urdf: PathBuf,
    /// Write the module to this file (only if its content changed) instead of stdout.
    #[arg(short, long, value_name = "FILE")]
    pub(crate) output: Option<PathBuf>,
    /// The generated type, UpperCamelCase [default: the robot name in UpperCamelCase]
    #[arg(long, value_name = "T")]
    pub(crate) type_name: Option<String>,
    /// The module name, snake_case, used in the banner [default: the robot name in snake_case]
    #[arg(long, value_name = "M")]
    pub(crate) module_name: Option<String>,
    /// Keep masses, centres of mass, inertias and joint offsets as fields of the generated
    /// struct (Default holds the URDF's values): of every link, or of the links listed.
    #[arg(long, value_name = "LINK,...", num_args = 0..=1, value_delimiter = ',')]
    pub(crate) symbolic: Option<Vec<String>>,
    /// Generate only these functions (and those they call), e.g. inverse_dynamics,gravity
    /// [default: all]
    #[arg(long, value_name = "NAME,...", value_delimiter = ',')]
    pub(crate) only: Option<Vec<String>>,
    /// Also generate the derivatives of the dynamics: inverse_dynamics_derivatives,
    /// forward_dynamics_derivatives and mass_matrix_inverse
    #[arg(long)]
    pub(crate) derivatives: bool,
    /// Also generate identification: regressor, parameters, base_regressor and
    /// base_parameters (tau = Y(q, qd, qdd) pi, linear in the inertial parameters)
    #[arg(long)]
    pub(crate) regressor: bool,
    #[command(flatten)]
    pub(crate) model: ModelArgs,
}

/// `show --format`.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub(crate) enum FormatArg {
    Text,
    Latex,
    Markdown,
}

/// `show --form`.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub(crate) enum FormArg {
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

/// The names `show --term` accepts: every printed quantity's name and symbols, and `all`.
fn term_names() -> Vec<&'static str> {
    let mut names: Vec<&'static str> = NOTATIONS
        .iter()
        .flat_map(|n| std::iter::once(n.name).chain(n.aliases.iter().copied()))
        .collect();
    names.push("all");
    names
}

/// `show --term`'s help: the quantities with their symbols, from the catalogue.
fn term_help() -> String {
    let list: Vec<String> = NOTATIONS
        .iter()
        .map(|n| format!("{} ({})", n.name, n.aliases.join(", ")))
        .collect();
    format!(
        "What to print, one or several separated by commas, by name or symbol: {}; or all \
         (every one but the derivatives, which --derivatives adds)",
        list.join(", ")
    )
}

#[derive(Args, Debug)]
pub(crate) struct ShowArgs {
    /// The robot's URDF file.
    pub(crate) urdf: PathBuf,
    #[arg(
        long,
        help = term_help(),
        value_name = "TERM",
        default_value = "all",
        value_delimiter = ',',
        value_parser = PossibleValuesParser::new(term_names()),
        hide_possible_values = true
    )]
    pub(crate) term: Vec<String>,
    /// One entry of the term, 1-based: I,J for matrices (for B: I,COLUMN or I,J,K with the
    /// pair J < K), I for vectors.
    #[arg(long, value_name = "I,J", value_parser = parse_indices)]
    pub(crate) entry: Option<Indices>,
    /// Output language.
    #[arg(long, value_enum, default_value_t = FormatArg::Text)]
    pub(crate) format: FormatArg,
    /// With --format latex: a complete document that pdflatex compiles, instead of fragments
    #[arg(long)]
    pub(crate) standalone: bool,
    /// Keep masses, centres of mass, inertias and link lengths as named symbols instead of the
    /// URDF's numbers: of every link, or of the links listed (put the URDF first, or write
    /// --symbolic=LINK,...).
    #[arg(long, value_name = "LINK,...", num_args = 0..=1, value_delimiter = ',')]
    pub(crate) symbolic: Option<Vec<String>>,
    /// Significant digits of numbers; 0 prints the shortest exact decimals.
    #[arg(long, value_name = "N", default_value_t = 6)]
    pub(crate) digits: usize,
    /// Print d tau / d q, the derivatives of inverse dynamics in the joint positions (instead
    /// of every term, or after the terms of --term). For small robots: beyond 4,000 operations
    /// (the 9-joint panda has 5,800) it is an error.
    #[arg(long)]
    pub(crate) derivatives: bool,
    /// How entries are written.
    #[arg(long, value_enum, default_value_t = FormArg::Expanded)]
    pub(crate) form: FormArg,
    /// In expanded form, a term whose expansion exceeds N terms is shown in program form.
    #[arg(long, value_name = "N", default_value_t = 100)]
    pub(crate) max_terms: usize,
    /// Instead of the equations, print the base parameters for identification: the minimal
    /// set of combinations of inertial parameters that the dynamics depend on, each as its
    /// exact formula (with --friction and --armature, their coefficients too).
    #[arg(long, conflicts_with_all = ["term", "entry", "form"])]
    pub(crate) base_parameters: bool,
    #[command(flatten)]
    pub(crate) model: ModelArgs,
}

#[derive(Args, Debug)]
pub(crate) struct InfoArgs {
    /// The robot's URDF file.
    pub(crate) urdf: PathBuf,
    /// Also derive the derivatives of the dynamics (as generate --derivatives) and list their
    /// operation counts: inverse_dynamics_derivatives, mass_matrix_inverse and
    /// forward_dynamics_derivatives, and with contacts the contact and impulse derivatives
    #[arg(long)]
    pub(crate) derivatives: bool,
    #[command(flatten)]
    pub(crate) model: ModelArgs,
}

#[derive(Args, Debug)]
pub(crate) struct EvalArgs {
    /// The robot's URDF file.
    pub(crate) urdf: PathBuf,
    /// Joint positions (rad or m), one per joint, separated by commas; with --floating-base
    /// the base's position and unit quaternion x, y, z, w first (NQ = 7 + joints).
    #[arg(long, value_name = "Q1,Q2,...", allow_hyphen_values = true, value_parser = parse_numbers)]
    pub(crate) q: Numbers,
    /// Joint velocities; with --floating-base the base's linear and angular velocity in its own
    /// axes first [default: 0]
    #[arg(long, value_name = "QD1,...", allow_hyphen_values = true, value_parser = parse_numbers)]
    pub(crate) qd: Option<Numbers>,
    /// Joint accelerations for the inverse dynamics [default: 0]
    #[arg(long, value_name = "QDD1,...", allow_hyphen_values = true, value_parser = parse_numbers)]
    pub(crate) qdd: Option<Numbers>,
    /// Joint torques (N m) or forces (N) for the forward dynamics [default: 0]
    #[arg(long, value_name = "TAU1,...", allow_hyphen_values = true, value_parser = parse_numbers)]
    pub(crate) tau: Option<Numbers>,
    /// Significant digits of numbers; 0 prints the shortest exact decimals.
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub(crate) digits: usize,
    #[command(flatten)]
    pub(crate) model: ModelArgs,
}

/// `simulate --controller`.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub(crate) enum ControllerArg {
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

/// `simulate --integrator`.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub(crate) enum IntegratorArg {
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
pub(crate) struct SimulateArgs {
    /// The robot's URDF file.
    pub(crate) urdf: PathBuf,
    /// Simulated time (s).
    #[arg(long, value_name = "S", default_value_t = 1.0)]
    pub(crate) duration: f64,
    /// Time step (s).
    #[arg(long, value_name = "H", default_value_t = 1e-3)]
    pub(crate) dt: f64,
    /// Initial joint positions [default: 0]
    #[arg(long, value_name = "Q1,Q2,...", allow_hyphen_values = true, value_parser = parse_numbers)]
    pub(crate) q0: Option<Numbers>,
    /// Initial joint velocities [default: 0]
    #[arg(long, value_name = "QD1,...", allow_hyphen_values = true, value_parser = parse_numbers)]
    pub(crate) qd0: Option<Numbers>,
    /// Target joint positions of the controller [default: the initial positions]
    #[arg(long, value_name = "Q1,...", allow_hyphen_values = true, value_parser = parse_numbers)]
    pub(crate) target: Option<Numbers>,
    /// The controller closing the loop.
    #[arg(long, value_enum, default_value_t = ControllerArg::None)]
    pub(crate) controller: ControllerArg,
    /// Proportional gain of gravity-comp (N m/rad or N/m).
    #[arg(long, value_name = "KP", default_value_t = 0.0)]
    pub(crate) kp: f64,
    /// Derivative gain of gravity-comp (N m s/rad or N s/m).
    #[arg(long, value_name = "KD", default_value_t = 0.0)]
    pub(crate) kd: f64,
    /// Bandwidth of computed-torque and pfl (rad/s): Kp = omega^2, Kd = 2 omega.
    #[arg(long, value_name = "RAD_PER_S", default_value_t = 10.0)]
    pub(crate) omega: f64,
    /// Swing-up gain of pfl (rad): the actuated joints' target moves by SWING atan(qd_passive);
    /// its sign depends on the robot (negative for an arm with a passive elbow).
    #[arg(
        long,
        value_name = "SWING",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    pub(crate) swing: f64,
    /// The integration method (a floating base takes RK4 only).
    #[arg(long, value_enum, default_value_t = IntegratorArg::Rk4)]
    pub(crate) integrator: IntegratorArg,
    /// Writes the CSV (t, q_*, qd_*, tau_* per joint; each number the shortest text that reads
    /// back exactly) to FILE and a summary to stdout, instead of the CSV to stdout.
    #[arg(long, value_name = "FILE")]
    pub(crate) csv: Option<PathBuf>,
    /// Also plots the run, as SVG or PNG by FILE's extension: the joint positions against time
    /// to FILE, and beside it FILE-velocities, FILE-efforts and FILE-energy (the energy drift).
    /// With a floating base, FILE has the base position, FILE-forces the vertical contact
    /// forces and FILE-joints the joint positions.
    #[arg(long, value_name = "FILE.svg|FILE.png")]
    pub(crate) plot: Option<PathBuf>,
    /// With --floating-base: the base's initial position and orientation (a unit quaternion
    /// x, y, z, w) [default: 0,0,0,0,0,0,1]
    #[arg(long, value_name = "X,Y,Z[,QX,QY,QZ,QW]", allow_hyphen_values = true, value_parser = parse_numbers)]
    pub(crate) base: Option<Numbers>,
    /// With --controller hover: where the base is held, level [default: its initial position]
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true, value_parser = parse_numbers)]
    pub(crate) base_target: Option<Numbers>,
    #[command(flatten)]
    pub(crate) model: ModelArgs,
}
