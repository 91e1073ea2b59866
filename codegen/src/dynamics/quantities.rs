//! The catalogue's entries: what each generated function is, how it is computed, and its
//! expressions. One function per quantity; [`catalogue`] lists them in file order.

use super::catalogue::{Craig, Evaluation, Home, Input, Layout, Notation, Quantity, Shape};
use super::derivatives::Derivatives;
use super::{centroidal, flat, Derivation, Route};
use crate::cas::{Graph, Id, Program};
use crate::model::Model;

/// Flattened Craig forms are generated when their straight-line code is at most this many
/// operations; beyond, a loop over the columns of `C(q, qd)` costs `N` evaluations of it but
/// almost no code (the panda's flattened `B`, 14,000 operations, was 43 % of its file). A
/// 6-joint arm's `B` (3,400 operations) stays flattened: the loop would be 3.5 times slower.
pub const CRAIG_FLAT_MAX_OPS: usize = 8000;

const Q: &[Input] = &[Input::Q];
const Q_QD: &[Input] = &[Input::Q, Input::Qd];
const QD: &[Input] = &[Input::Qd];

/// The readable closed form of `m`, flattened, or of `v`.
fn matrix(m: &[Vec<Id>]) -> Option<Vec<Id>> {
    Some(flat(m))
}

/// How people write the quantities that have symbols, in the order `eomgen show` prints them.
pub static NOTATIONS: &[Notation] = &[
    Notation {
        name: "mass_matrix",
        text: "M",
        latex: "M",
        aliases: &["M"],
        title: "Mass matrix M(q)",
        definition: "Symmetric: entries below the diagonal are not shown.",
        layout: Layout::Symmetric,
        printed: |d| matrix(&d.mass_matrix),
    },
    Notation {
        name: "coriolis_pairs",
        text: "B",
        latex: "B",
        aliases: &["B"],
        title: "Craig's Coriolis matrix B(q)",
        definition: "B_i,jk multiplies qd_j qd_k (j < k): b = B(q) [qd qd] + C(q) [qd^2].",
        layout: Layout::Pairs,
        printed: |d| matrix(&d.coriolis_pairs),
    },
    Notation {
        name: "centrifugal",
        text: "C",
        latex: "C",
        aliases: &["C"],
        title: "Craig's centrifugal matrix C(q)",
        definition: "C_ij multiplies qd_j^2.",
        layout: Layout::Square,
        printed: |d| matrix(&d.centrifugal),
    },
    Notation {
        name: "gravity",
        text: "G",
        latex: "G",
        aliases: &["G"],
        title: "Gravity G(q) = dV/dq",
        definition: "",
        layout: Layout::Vector,
        printed: |d| Some(d.gravity.clone()),
    },
    Notation {
        name: "bias",
        text: "b",
        latex: "b",
        aliases: &["b"],
        title: "Bias b(q, qd) = B(q) [qd qd] + C(q) [qd^2]",
        definition: "Coriolis and centrifugal terms, without gravity.",
        layout: Layout::Vector,
        printed: |d| Some(d.bias.clone()),
    },
    Notation {
        name: "coriolis_matrix",
        text: "Cqd",
        latex: "C^{\\dot{q}}",
        aliases: &["coriolis"],
        title: "Coriolis matrix C(q, qd), Christoffel form",
        definition: "Cqd_ij = sum_k Gamma_ijk qd_k: b = C(q, qd) qd, and dM/dt - 2 C(q, qd) is \
                     skew-symmetric.",
        layout: Layout::Square,
        printed: |d| matrix(&d.coriolis_matrix),
    },
    Notation {
        name: "inverse_dynamics",
        text: "tau",
        latex: "\\tau",
        aliases: &["tau"],
        title: "Inverse dynamics tau = M(q) qdd + b(q, qd) + G(q)",
        definition: "",
        layout: Layout::Vector,
        printed: |d| Some(d.tau.clone()),
    },
    Notation {
        name: "friction",
        text: "F",
        latex: "F",
        aliases: &["F"],
        title: "Friction F(qd)",
        definition: "F_i = damping_i qd_i + friction_i sign(qd_i), supplied by the actuators.",
        layout: Layout::Vector,
        printed: |d| Some(d.friction.clone()),
    },
    Notation {
        name: "kinetic_energy",
        text: "T",
        latex: "T",
        aliases: &["T"],
        title: "Kinetic energy T = qd^T M(q) qd / 2",
        definition: "",
        layout: Layout::Scalar,
        printed: |d| Some(vec![d.kinetic_energy]),
    },
    Notation {
        name: "potential_energy",
        text: "V",
        latex: "V",
        aliases: &["V"],
        title: "Potential energy V = -sum over bodies of m g.c",
        definition: "",
        layout: Layout::Scalar,
        printed: |d| Some(vec![d.potential_energy]),
    },
    Notation {
        name: "inverse_dynamics_derivatives",
        text: "dtau_dq",
        latex: "\\partial\\tau",
        aliases: &["dtau_dq"],
        title: "Derivatives of inverse dynamics d tau / d q (q, qd, qdd)",
        definition: "dtau_i/dq_j: how joint effort i changes with joint position j.",
        layout: Layout::Partials,
        // d tau / d q, the first N x N of (d tau / d q, d tau / d qd).
        printed: |d| match d.quantity("inverse_dynamics_derivatives").map(|q| &q.eval) {
            Some(Evaluation::Exprs(ids)) => Some(ids[..d.dof * d.dof].to_vec()),
            _ => None,
        },
    },
];

/// Every quantity generated code can evaluate for `model`, in file order. An entry may add the
/// expressions it needs to `d`'s graph.
pub fn catalogue(model: &Model, d: &mut Derivation) -> Vec<Quantity> {
    let notes = Notes::new(model);
    let mut out = vec![
        mass_matrix(d, &notes),
        gravity(d),
        bias(d),
        coriolis_matrix(d),
        inverse_dynamics(d, &notes),
        forward_dynamics(d, &notes),
        kinetic_energy(d, &notes),
        generalized_momentum(model, d, &notes),
        potential_energy(d),
    ];
    if model.velocities_are_rates() {
        out.push(craig(d, Craig::Centrifugal));
        out.push(craig(d, Craig::CoriolisPairs));
    }
    if model.include_friction {
        out.push(friction(model, d));
    }
    out.push(link_pose());
    out.push(link_jacobian(d.dof));
    out.extend(centroidal::quantities(model, d));
    out.extend(super::contact_derivatives::impulse_dynamics(model, d));
    out.extend(super::active_contacts::quantities(d));
    if !model.velocities_are_rates() {
        // Not the `Dynamics` trait (whose arrays are all N long): a floating base's methods go
        // to `FloatingDynamics` and `Contacts`; with floating joints below the root (whose
        // coordinates are not first), every method is inherent.
        for q in &mut out {
            q.home = if model.is_floating() {
                floating_home(q.name)
            } else {
                Home::Inherent
            };
        }
    }
    out
}

/// Where a floating base's quantity lives: not in the `Dynamics` trait (whose arrays are all
/// N long), but the runtime's `FloatingDynamics` and `Contacts` traits hold these; the others
/// are inherent methods.
fn floating_home(name: &str) -> Home {
    match name {
        "mass_matrix" | "gravity" | "bias" | "integrate" | "inverse_dynamics"
        | "forward_dynamics" => Home::FloatingDynamics,
        "contact_jacobian" | "contact_drift" | "contact_forward_dynamics" => Home::Contacts,
        _ => Home::Inherent,
    }
}

/// Remarks about joint effects that change what some functions mean.
struct Notes {
    friction: bool,
    armature: Vec<String>,
}

impl Notes {
    fn new(model: &Model) -> Notes {
        Notes {
            friction: model.include_friction,
            armature: model
                .joints
                .iter()
                .filter(|j| j.armature != 0.0)
                .map(|j| format!("`{}` {}", j.name.replace('`', "'"), j.armature))
                .collect(),
        }
    }

    fn friction(&self, what: &str) -> Vec<String> {
        if self.friction {
            vec![
                String::new(),
                format!("{what} the joint friction F(qd) of `friction`."),
            ]
        } else {
            Vec::new()
        }
    }

    fn armature(&self, what: &str) -> Vec<String> {
        if self.armature.is_empty() {
            Vec::new()
        } else {
            let list = self.armature.join(", ");
            vec![
                String::new(),
                format!("{what} rotor inertia (armature): {list}."),
            ]
        }
    }
}

fn route(r: Route, recursive: &str) -> String {
    format!("Route: {}.", r.describe(recursive))
}

fn lines(parts: &[&[String]]) -> Vec<String> {
    parts.iter().flat_map(|p| p.iter().cloned()).collect()
}

fn mass_matrix(d: &Derivation, notes: &Notes) -> Quantity {
    let (r, m) = &d.fast.mass_matrix;
    Quantity {
        name: "mass_matrix",
        inputs: Q,
        shape: Shape::Matrix(d.dof, d.dof),
        home: Home::Dynamics,
        doc: lines(&[
            &["The joint-space mass matrix M(q), symmetric positive definite.".into()],
            &notes.armature("The diagonal includes"),
        ]),
        route: route(*r, "composite-rigid-body algorithm"),
        eval: Evaluation::Exprs(flat(m)),
    }
}

fn gravity(d: &Derivation) -> Quantity {
    let (r, v) = &d.fast.gravity;
    Quantity {
        name: "gravity",
        inputs: Q,
        shape: Shape::Vector(d.dof),
        home: Home::Dynamics,
        doc: vec!["The generalized gravity force G(q) = dV/dq.".into()],
        route: route(*r, "Newton-Euler"),
        eval: Evaluation::Exprs(v.clone()),
    }
}

fn bias(d: &Derivation) -> Quantity {
    let (r, v) = &d.fast.bias;
    Quantity {
        name: "bias",
        inputs: Q_QD,
        shape: Shape::Vector(d.dof),
        home: Home::Dynamics,
        doc: vec![
            "The Coriolis and centrifugal effort b(q, qd) = C(q, qd) qd, without gravity.".into(),
        ],
        route: route(*r, "Newton-Euler"),
        eval: Evaluation::Exprs(v.clone()),
    }
}

fn coriolis_matrix(d: &Derivation) -> Quantity {
    let (r, m) = &d.fast.coriolis_matrix;
    Quantity {
        name: "coriolis_matrix",
        inputs: Q_QD,
        shape: Shape::Matrix(d.dof, d.dof),
        home: Home::Dynamics,
        doc: vec![
            "The Christoffel-form Coriolis matrix C(q, qd): C qd = b, dM/dt - 2C skew-symmetric."
                .into(),
        ],
        route: route(
            *r,
            "Echeandia and Wensing's O(N^2) recursion on composite inertias and momenta",
        ),
        eval: Evaluation::Exprs(flat(m)),
    }
}

fn inverse_dynamics(d: &Derivation, notes: &Notes) -> Quantity {
    let (r, v) = &d.fast.tau;
    Quantity {
        name: "inverse_dynamics",
        inputs: &[Input::Q, Input::Qd, Input::Qdd],
        shape: Shape::Vector(d.dof),
        home: Home::Dynamics,
        doc: lines(&[
            &["Inverse dynamics: tau = M(q) qdd + b(q, qd) + G(q).".into()],
            &notes.friction("`tau = M qdd + b + G + F(qd)`: includes"),
            &notes.armature("M includes"),
        ]),
        route: route(*r, "Newton-Euler"),
        eval: Evaluation::Exprs(v.clone()),
    }
}

/// Forward dynamics unrolled into straight-line code when that is at most this many
/// operations (one block of `max_function_ops`'s default until November 2026); beyond, `M` from `mass_matrix`
/// and the tree's factorization unrolled for the robot, at run time. A 48-joint chain's
/// unrolled solve and second copy of `M` were 49k lines of its 172k, and g1_29dof's
/// straight-line forward dynamics (15,963 operations, two blocks) took 2.49 us against
/// 2.25 us composed (2.16 us as one block of 16,000, at a build's memory).
pub const FORWARD_DYNAMICS_FLAT_MAX_OPS: usize = 8_000;

fn forward_dynamics(d: &Derivation, notes: &Notes) -> Quantity {
    let unrolled: Vec<Id> = d
        .fast
        .forward_dynamics
        .iter()
        .chain(&d.fast.pivots)
        .copied()
        .collect();
    let (route, eval) = if ops(&d.graph, &unrolled) <= FORWARD_DYNAMICS_FLAT_MAX_OPS {
        (
            "Route: M and b + G as in `mass_matrix` and `bias`, then an unrolled L^T D L solve without fill-in.",
            Evaluation::ForwardDynamics {
                accelerations: d.fast.forward_dynamics.clone(),
                pivots: d.fast.pivots.clone(),
            },
        )
    } else {
        (
            "Route: M from `mass_matrix`, b + G by Newton-Euler, then the sparse L^T D L factorization over the joint tree, unrolled for this robot, and its substitution.",
            Evaluation::ForwardDynamicsSolve {
                h: d.fast.bias_gravity_friction.clone(),
            },
        )
    };
    Quantity {
        name: "forward_dynamics",
        inputs: &[Input::Q, Input::Qd, Input::Tau],
        shape: Shape::Vector(d.dof),
        home: Home::Dynamics,
        doc: lines(&[
            &[
                "Forward dynamics: qdd = M(q)^-1 (tau - b(q, qd) - G(q)).".into(),
                String::new(),
                "Returns NaN in every entry when M(q) is not positive definite (it cannot be for a valid".into(),
                "model and finite inputs); `try_forward_dynamics` says which pivot failed.".into(),
            ],
            &notes.friction("`qdd = M^-1 (tau - b - G - F(qd))`: includes"),
            &notes.armature("M includes"),
        ]),
        route: route.into(),
        eval,
    }
}

fn kinetic_energy(d: &Derivation, notes: &Notes) -> Quantity {
    Quantity {
        name: "kinetic_energy",
        inputs: Q_QD,
        shape: Shape::Scalar,
        home: Home::Dynamics,
        doc: lines(&[
            &["The kinetic energy T = qd^T M(q) qd / 2.".into()],
            &notes.armature("Includes the"),
        ]),
        route: match d.fast.kinetic_energy_route {
            Route::Lagrangian => "Route: the quadratic form of `mass_matrix`.".into(),
            Route::Recursive => "Route: a sum over body velocities, O(N).".into(),
        },
        eval: Evaluation::Exprs(vec![d.fast.kinetic_energy]),
    }
}

fn generalized_momentum(model: &Model, d: &mut Derivation, notes: &Notes) -> Quantity {
    let p = super::newton_euler::generalized_momentum(&mut d.graph, model, &d.q, &d.qd);
    Quantity {
        name: "generalized_momentum",
        inputs: Q_QD,
        shape: Shape::Vector(d.dof),
        home: Home::Inherent,
        doc: lines(&[
            &[
                "The generalized momentum p = M(q) qd = dT/dqd (a momentum observer's measurement).".into(),
            ],
            &notes.armature("M includes"),
        ]),
        route: "Route: Newton-Euler at rest without gravity, with qd as the accelerations, O(N).".into(),
        eval: Evaluation::Exprs(p),
    }
}

fn potential_energy(d: &Derivation) -> Quantity {
    Quantity {
        name: "potential_energy",
        inputs: Q,
        shape: Shape::Scalar,
        home: Home::Dynamics,
        doc: vec!["The gravitational potential energy V = -sum m g.c, zero with every centre of mass at the origin.".into()],
        route: "Route: centres of mass by forward kinematics.".into(),
        eval: Evaluation::Exprs(vec![d.potential_energy]),
    }
}

/// Flattened when the straight-line code is small, else a loop over Christoffel columns.
fn craig(d: &Derivation, which: Craig) -> Quantity {
    let n = d.dof;
    let np = n * n.saturating_sub(1) / 2;
    let (name, shape, flat_form, doc) = match which {
        Craig::Centrifugal => (
            "centrifugal",
            Shape::Matrix(n, n),
            &d.fast.centrifugal,
            "Craig's centrifugal matrix C(q): `b = B(q) [qd qd] + C(q) [qd^2]`.".to_string(),
        ),
        Craig::CoriolisPairs => (
            "coriolis_pairs",
            Shape::Matrix(n, np),
            &d.fast.coriolis_pairs,
            format!("Craig's Coriolis matrix B(q), N x N(N-1)/2 = {n} x {np}, columns for qd_j qd_k with j < k in the order (0,1), (0,2), ..., (1,2), ..."),
        ),
    };
    let small = flat_form
        .as_ref()
        .filter(|(_, m)| ops(&d.graph, &flat(m)) <= CRAIG_FLAT_MAX_OPS);
    let (route_line, eval) = match small {
        Some((r, m)) => (
            route(*r, "second velocity derivatives of the Newton-Euler bias"),
            Evaluation::Exprs(flat(m)),
        ),
        None => (
            format!("Route: Christoffel symbols Gamma_ijk = C(q, e_k)_ij from {n} evaluations of `coriolis_matrix`."),
            Evaluation::CraigColumns(which),
        ),
    };
    Quantity {
        name,
        inputs: Q,
        shape,
        home: Home::Inherent,
        doc: vec![doc],
        route: route_line,
        eval,
    }
}

fn ops(g: &Graph, outputs: &[Id]) -> usize {
    Program::new(g, outputs).ops().total()
}

fn friction(model: &Model, d: &Derivation) -> Quantity {
    let smoothing = if model.coulomb_smoothing > 0.0 {
        format!(
            "`s(v) = v / sqrt(v^2 + eps^2)`, the sign smoothed below `eps = {}` (rad/s or m/s)",
            model.coulomb_smoothing
        )
    } else {
        "`s(v) = sign(v)`, 0 at rest (no stiction)".to_string()
    };
    let coefficients: Vec<String> = model
        .joints
        .iter()
        .map(|j| {
            let name = j.name.replace('`', "'");
            format!("`{name}`: damping {}, friction {}", j.damping, j.friction)
        })
        .collect();
    Quantity {
        name: "friction",
        inputs: QD,
        shape: Shape::Vector(d.dof),
        home: Home::Inherent,
        doc: vec![
            "Joint friction effort `F(qd)`, per joint `damping qd + friction s(qd)` from the URDF's".into(),
            format!("`<dynamics damping friction>`, with {smoothing}."),
            "The effort the actuators must supply against friction (the joints feel `-F`); it is".into(),
            "part of `inverse_dynamics` and `forward_dynamics`, not of `bias`.".into(),
            String::new(),
            format!("Coefficients: {}.", coefficients.join("; ")),
        ],
        route: "Route: per joint, from the joint's velocity alone.".into(),
        eval: Evaluation::Exprs(d.friction.clone()),
    }
}

fn link_pose() -> Quantity {
    Quantity {
        name: "link_pose",
        inputs: Q,
        shape: Shape::Vector(12),
        home: Home::Inherent,
        doc: vec!["Pose of a link frame in the world (root) frame.".into()],
        route: "Route: each joint's transform composed along the link's chain from the root."
            .into(),
        eval: Evaluation::LinkPose,
    }
}

fn link_jacobian(n: usize) -> Quantity {
    Quantity {
        name: "link_jacobian",
        inputs: Q,
        shape: Shape::Matrix(6, n),
        home: Home::Inherent,
        doc: vec!["The 6 x N Jacobian of a link frame: rows vx, vy, vz, wx, wy, wz in world axes, at the link origin.".into()],
        route: "Route: joint axes and origins along the link's chain, from the same transforms as `link_pose`.".into(),
        eval: Evaluation::LinkJacobian,
    }
}

/// `forward_dynamics_derivatives` is straight-line code (sharing `M`, its factorization and the
/// accelerations) up to this many operations by default, `mass_matrix_inverse` up to this
/// divided by [`MASS_MATRIX_INVERSE_FLAT_DIVISOR`] ([`crate::Builder::derivatives_flat_max_ops`]);
/// beyond, they are composed at run time: the forward-dynamics derivatives from
/// `forward_dynamics_partials` (still one straight-line body up to `-M^-1`,
/// [`FORWARD_DYNAMICS_PARTIALS_MAX_OPS`]) or from `mass_matrix`, `inverse_dynamics` and
/// `inverse_dynamics_derivatives`, and the tree's passes; `M^-1` from `mass_matrix`.
///
/// Since the composed route's inverse is unrolled over the tree too, it is the faster one from
/// a quadruped's size on: anymal's forward-dynamics derivatives (36,088 operations flat) took
/// 4.60 us composed against 5.07 us flat; the panda's (12,751) 1.96 us against 1.69 us, and its
/// `M^-1` (1,378) 256 ns against 165 ns (27 November 2026, native, alternated).
pub const DERIVATIVES_FLAT_MAX_OPS: usize = 20_000;

/// `mass_matrix_inverse` alone is straight-line code up to the derivatives' limit divided by
/// this (2,000 operations by default). Its flat form shares nothing with other outputs, where
/// the forward-dynamics derivatives' shares `M`'s factorization and the accelerations, so the
/// composed route (the tree's inverse unrolled) wins sooner: anymal's `M^-1` (5,569 operations
/// flat) took 787 ns flat against 698 ns composed, the panda's (1,390) 165 ns against 256 ns
/// (27 November 2026, native). Once the symbolic factorization kept each entry of `L` whole,
/// anymal's flat form fell to 3,976 operations, under the 4,000 of a divisor of 5, and took
/// 698 ns against 543 ns composed with the factorization in locals (28 November 2026).
pub const MASS_MATRIX_INVERSE_FLAT_DIVISOR: usize = 10;

/// A composed `forward_dynamics_derivatives` takes `d tau` at the forward dynamics'
/// accelerations and `M`'s factors from `forward_dynamics_partials`, one straight-line body,
/// up to this many operations (one block of the default
/// [`crate::Builder::max_derivative_function_ops`]): anymal's (12,196 operations) took 2,735 ns
/// against 2,862 ns from `mass_matrix`, `inverse_dynamics` and `inverse_dynamics_derivatives`,
/// each computing the kinematics again. Beyond, it takes those: the body holds a second copy of
/// the inverse-dynamics derivatives, which on a humanoid cost more to build than they save
/// (g1_29dof, 41,076 operations: 12.09 -> 12.25 us, native build 34 -> 41 s; talos_full_v2,
/// 63,000: 22.9 -> 23.3 us, 48 -> 65 s and 1.8 -> 2.2 GiB; 28 November 2026).
pub const FORWARD_DYNAMICS_PARTIALS_MAX_OPS: usize = 24_000;

/// The straight-line forward-dynamics derivatives' substitutions and `M^-1` (their operations
/// beyond `forward_dynamics_partials`) up to this many operations; beyond, the columns are
/// solved by the unrolled passes over the tree, which run across the columns in vector
/// registers, from `forward_dynamics_partials`. Measured both ways (native, alternated,
/// 28 November 2026; operations of that share, then the composed route's time over the
/// straight-line one): the UR5 834, 1.23; the Kinova 860, 0.94; the allegro hand 1,046, 1.17;
/// the xArm 7 1,389, 1.01; the panda 2,666, 0.93 (1,168 -> 1,083 ns).
pub const FORWARD_DYNAMICS_FLAT_SOLVES_MAX_OPS: usize = 2_000;

/// The derivatives of the dynamics ([`Derivation::add_derivatives`]): inverse dynamics
/// (straight-line), `M^-1` and forward dynamics (straight-line, or composed at run time when
/// that is large).
pub fn derivatives(d: &Derivation, x: &Derivatives, flat_max_ops: usize) -> Vec<Quantity> {
    let n = d.dof;
    let mut both = flat(&x.inverse.dq);
    both.extend(flat(&x.inverse.dqd));
    let minv = flat(&x.mass_matrix_inverse);
    let mut fd = flat(&x.forward.dq);
    fd.extend(flat(&x.forward.dqd));
    fd.extend(&minv);
    // Straight-line when the body's operations (the pivots' included) `fit`.
    let factored = |outputs: Vec<Id>, fits: &dyn Fn(usize) -> bool| {
        let all: Vec<Id> = outputs.iter().chain(&x.pivots).copied().collect();
        fits(ops(&d.graph, &all)).then(|| Evaluation::Factored {
            outputs,
            pivots: x.pivots.clone(),
        })
    };
    let minv_limit = flat_max_ops / MASS_MATRIX_INVERSE_FLAT_DIVISOR;
    let (minv_route, minv_eval) = match factored(minv, &|n| n <= minv_limit) {
        Some(e) => ("Route: M as in `mass_matrix`, an unrolled L^T D L factorization without fill-in, one substitution per column.", e),
        None => ("Route: M from `mass_matrix`, the sparse L^T D L factorization over the joint tree, unrolled for this robot, then L^-1 D^-1 L^-T over the tree, unrolled too (eomgen_runtime::tree::ltdl_inverse_factored's operations, in parts of at most 128 row updates).", Evaluation::MassMatrixInverse),
    };
    let mut partials = flat(&x.at_forward.dq);
    partials.extend(flat(&x.at_forward.dqd));
    partials.extend(flat(&x.factors));
    // Within the limit, and the share beyond the partials (substitutions and `M^-1`) too.
    let partials_ops = ops(&d.graph, &partials);
    let fd_fits = |n: usize| {
        n <= flat_max_ops && n.saturating_sub(partials_ops) <= FORWARD_DYNAMICS_FLAT_SOLVES_MAX_OPS
    };
    let (fd_route, fd_eval) = match factored(fd, &fd_fits) {
        Some(e) => ("Route: qdd from the factorization of M, with b = 1/2 (d tau / d qd) qd and G from the recursion's composite inertias, `inverse_dynamics_derivatives` at (q, qd, qdd), then -M^-1 times them by substitutions through the one unrolled factorization of M, all in one straight-line body.", e),
        None if partials_ops <= FORWARD_DYNAMICS_PARTIALS_MAX_OPS => ("Route: `forward_dynamics_partials` (d tau / d q and d tau / d qd at qdd = FD(q, qd, tau), and M's factors), then -M^-1 times them by substitutions of all columns at once (the passes of eomgen_runtime::tree::ltdl_substitute_rows, unrolled for this robot's tree), and M^-1 from the same factors, unrolled over the tree (eomgen_runtime::tree::ltdl_inverse_factored's operations).", Evaluation::ForwardDynamicsDerivatives { partials: true }),
        None => ("Route: one factorization of M (from `mass_matrix`, the tree L^T D L unrolled): qdd from it and `inverse_dynamics` at zero acceleration, `inverse_dynamics_derivatives` at (q, qd, qdd), then -M^-1 times them by substitutions of all columns at once (the passes of eomgen_runtime::tree::ltdl_substitute_rows, unrolled for this robot's tree), and M^-1 from the same factors, unrolled over the tree (eomgen_runtime::tree::ltdl_inverse_factored's operations).", Evaluation::ForwardDynamicsDerivatives { partials: false }),
    };
    let from_partials = matches!(
        fd_eval,
        Evaluation::ForwardDynamicsDerivatives { partials: true }
    );
    let mut out = vec![
        Quantity {
            name: "inverse_dynamics_derivatives",
            inputs: &[Input::Q, Input::Qd, Input::Qdd],
            shape: Shape::Matrices(2, n, n),
            home: Home::Inherent,
            doc: vec![
                "The derivatives of inverse dynamics: (d tau / d q, d tau / d qd), element `[i][j]` =".into(),
                "d tau_i / d x_j, friction and rotor inertia included when generated.".into(),
            ],
            route: "Route: Carpentier and Mansard's recursive derivatives of Newton-Euler, customized (d tau / d qd = 2 C(q, qd) + dF/dqd).".into(),
            eval: Evaluation::Exprs(both),
        },
        Quantity {
            name: "mass_matrix_inverse",
            inputs: Q,
            shape: Shape::Matrix(n, n),
            home: Home::Inherent,
            doc: vec![
                "The inverse of the mass matrix, M(q)^-1 (NaN in every entry when M(q) is not".into(),
                "positive definite).".into(),
            ],
            route: minv_route.into(),
            eval: minv_eval,
        },
        Quantity {
            name: "forward_dynamics_derivatives",
            inputs: &[Input::Q, Input::Qd, Input::Tau],
            shape: Shape::Matrices(3, n, n),
            home: Home::Inherent,
            doc: vec![
                "The derivatives of forward dynamics qdd(q, qd, tau): (d qdd / d q, d qdd / d qd,".into(),
                "d qdd / d tau = M^-1) (NaN in every entry when M(q) is not positive definite).".into(),
            ],
            route: fd_route.into(),
            eval: fd_eval,
        },
    ];
    if from_partials {
        out.insert(2, forward_dynamics_partials(n, partials));
    }
    out
}

/// What the run-time route of `forward_dynamics_derivatives` solves, in one straight-line body
/// that shares the kinematics, `M` and its factorization between the forward dynamics'
/// accelerations and the inverse-dynamics derivatives there.
fn forward_dynamics_partials(n: usize, outputs: Vec<Id>) -> Quantity {
    Quantity {
        name: "forward_dynamics_partials",
        inputs: &[Input::Q, Input::Qd, Input::Tau],
        shape: Shape::Matrices(3, n, n),
        home: Home::Inherent,
        doc: vec![
            "What `forward_dynamics_derivatives` solves: (d tau / d q, d tau / d qd) at the".into(),
            "accelerations qdd = FD(q, qd, tau), and the tree L^T D L factors of M(q) (D on the".into(),
            "diagonal, L_ij below it where j is an ancestor of i, zero elsewhere: the layout of".into(),
            "`eomgen_runtime::tree::ltdl_factor`). Valid when every pivot D_i is positive; then".into(),
            "d qdd / dx = -M^-1 d tau / dx.".into(),
        ],
        route: "Route: qdd by an unrolled L^T D L solve (b = 1/2 (d tau / d qd) qd and G from the recursion's composite inertias, no second Newton-Euler pass), then Carpentier and Mansard's recursive derivatives of Newton-Euler there, one straight-line body.".into(),
        eval: Evaluation::Exprs(outputs),
    }
}
