//! The derivation: every quantity of a robot as expressions in one [`Graph`], by two routes,
//! and the [`catalogue`] of what generated code evaluates.
//!
//! - `lagrangian`: the closed forms (`M` from body Jacobians, `G = dV/dq`, Christoffel
//!   symbols), readable and the reference for the reports;
//! - [`newton_euler`]: the customized recursive algorithms (Newton-Euler, composite rigid
//!   bodies, Echeandia and Wensing's Coriolis matrix), far fewer operations;
//! - the fast forms ([`Fast`]): per quantity, whichever route needs fewer operations;
//! - [`catalogue`]: one [`Quantity`] per generated function, built from the fast forms.
//!
//! Rotor inertia (armature) adds to `M`'s diagonal; joint friction `F(qd)` (when the model
//! includes it) adds to `tau` and enters forward dynamics, but not `b`.

mod active_contacts;
pub mod base_parameters;
pub mod catalogue;
mod centroidal;
mod contact_derivatives;
pub mod coupling;
mod derivatives;
mod floating;
pub mod identification;
mod lagrangian;
mod mpc;
pub mod newton_euler;
pub mod projected;
mod quantities;
pub mod regressor;
pub mod rnea_derivatives;

use std::time::{Duration, Instant};

use crate::cas::{Graph, GraphFull, Id, Limits, Program};
use crate::kinematics::{const_v3, BodyKinematics, Params, WorldKinematics, M3, V3};
use crate::model::Model;

pub use catalogue::{ActiveContacts, Craig, Evaluation, Home, Input, Quantity, Shape};
pub use centroidal::Centroidal;
pub use coupling::CoordinateMap;
pub use identification::Identification;
pub use lagrangian::pairs;
pub use mpc::{FrameMotion, Manifold};

/// The pose of a body in its parent body's frame (the root's for a body whose parent is the
/// root), as expressions in the body's joint coordinate: `p_parent = rotation p + translation`.
#[derive(Clone, Debug)]
pub struct JointTransform {
    pub rotation: M3,
    pub translation: V3,
}

/// Pose and Jacobian of one URDF link frame, as closed-form expressions.
#[derive(Clone, Debug)]
pub struct FrameExprs {
    /// The URDF link name.
    pub name: String,
    /// World from link.
    pub rotation: M3,
    pub position: V3,
    /// 6 x N: rows vx, vy, vz, wx, wy, wz in world axes at the link origin.
    pub jacobian: Vec<Vec<Id>>,
}

/// Every derived quantity of a robot, as expressions in [`Derivation::graph`].
#[derive(Clone, Debug)]
pub struct Derivation {
    pub graph: Graph,
    /// Degrees of freedom: the number of velocity coordinates.
    pub dof: usize,
    /// The number of position coordinates (`dof`, or `dof + 1` with a floating base's
    /// quaternion).
    pub nq: usize,
    /// The joint symbols.
    pub q: Vec<Id>,
    pub qd: Vec<Id>,
    pub qdd: Vec<Id>,
    /// Symbolic parameters: (name, symbol, URDF value).
    pub params: Vec<(String, Id, f64)>,
    /// `M(q)`, full and symmetric (`mass_matrix[i][j]` and `[j][i]` are one node).
    pub mass_matrix: Vec<Vec<Id>>,
    /// `G(q)`.
    pub gravity: Vec<Id>,
    /// Craig's centrifugal matrix `C(q)`, N x N.
    pub centrifugal: Vec<Vec<Id>>,
    /// Craig's Coriolis matrix `B(q)`, N x N(N-1)/2.
    pub coriolis_pairs: Vec<Vec<Id>>,
    /// The Christoffel-form Coriolis matrix `C(q, qd)`.
    pub coriolis_matrix: Vec<Vec<Id>>,
    /// `b(q, qd) = C(q, qd) qd`: Coriolis and centrifugal, without gravity.
    pub bias: Vec<Id>,
    /// `tau = M qdd + b + G + F(qd)` (`F` only when the model includes friction).
    pub tau: Vec<Id>,
    /// The joint friction effort `F(qd)`, per joint `damping qd + friction s(qd)` with `s`
    /// the sign or its smoothed form ([`Model::coulomb_smoothing`]): what the actuators must
    /// supply against friction, whose torque on the joints is `-F`. All zero unless
    /// [`Model::include_friction`].
    pub friction: Vec<Id>,
    pub kinetic_energy: Id,
    pub potential_energy: Id,
    /// Per joint, its body's pose in the parent body's frame: what link poses and Jacobians
    /// compose along a chain.
    pub joint_transforms: Vec<JointTransform>,
    /// Each velocity coordinate's parent coordinate, for the sparse factorizations of `M`.
    pub coordinate_parents: Vec<Option<usize>>,
    /// The centre of mass, its Jacobian, the centroidal momentum map and the contacts.
    pub centroidal: Centroidal,
    /// The same quantities by the recursive algorithms.
    pub recursive: Recursive,
    /// For each function of generated code, the cheaper of the two routes.
    pub fast: Fast,
    /// What generated code evaluates, one entry per generated function.
    pub quantities: Vec<Quantity>,
    /// The regressor and the standard and base parameters, after
    /// [`Derivation::add_regressor`].
    pub identification: Option<Identification>,
    /// How long each stage took.
    pub timings: Vec<(&'static str, Duration)>,
}

/// `M`, `G`, `b` and `tau` by the customized symbolic recursive algorithms
/// ([`newton_euler`]): equal to the Lagrangian forms, but far fewer operations.
#[derive(Clone, Debug)]
pub struct Recursive {
    /// By the composite-rigid-body algorithm.
    pub mass_matrix: Vec<Vec<Id>>,
    /// By Newton-Euler with zero velocity and acceleration.
    pub gravity: Vec<Id>,
    /// By Newton-Euler with zero acceleration and no gravity.
    pub bias: Vec<Id>,
    /// `b + G` in one recursion (what forward dynamics needs).
    pub bias_and_gravity: Vec<Id>,
    /// Full inverse dynamics, friction included when the model includes it.
    pub tau: Vec<Id>,
    /// `C(q, qd)` by Echeandia and Wensing's `O(N^2)` recursion
    /// ([`newton_euler::coriolis`]).
    pub coriolis_matrix: Vec<Vec<Id>>,
    /// `T` from body velocities ([`newton_euler::kinetic_energy`]).
    pub kinetic_energy: Id,
}

impl Recursive {
    /// The joint tree's quantities in the coordinates of `map` (see [`coupling`]): efforts
    /// `G^T x`, matrices `G^T X G`; unchanged without coupled joints.
    fn projected(self, g: &mut Graph, map: &CoordinateMap) -> Recursive {
        if !map.is_coupled() {
            return self;
        }
        Recursive {
            mass_matrix: map.project_matrix(g, &self.mass_matrix, true),
            gravity: map.project(g, &self.gravity),
            bias: map.project(g, &self.bias),
            bias_and_gravity: map.project(g, &self.bias_and_gravity),
            tau: map.project(g, &self.tau),
            coriolis_matrix: map.project_matrix(g, &self.coriolis_matrix, false),
            kinetic_energy: self.kinetic_energy,
        }
    }
}

/// Which derivation a fast form comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Route {
    /// The closed-form Lagrangian expressions.
    Lagrangian,
    /// Newton-Euler or the composite-rigid-body algorithm.
    Recursive,
}

impl Route {
    /// A short description for documentation.
    pub fn describe(self, recursive: &str) -> String {
        match self {
            Route::Lagrangian => "closed-form Lagrangian expressions".to_string(),
            Route::Recursive => recursive.to_string(),
        }
    }
}

/// The forms generated code evaluates: per quantity, whichever route needs fewer operations.
#[derive(Clone, Debug)]
pub struct Fast {
    pub mass_matrix: (Route, Vec<Vec<Id>>),
    pub gravity: (Route, Vec<Id>),
    pub bias: (Route, Vec<Id>),
    pub tau: (Route, Vec<Id>),
    /// `C(q, qd)`: Christoffel symbols, or Echeandia and Wensing's `O(N^2)` recursion.
    pub coriolis_matrix: (Route, Vec<Vec<Id>>),
    /// Craig's `C(q)` as flattened expressions (Christoffel symbols, or
    /// `1/2 d^2 b_i / dqd_j^2`), for robots whose `B(q)` has at most [`CRAIG_FLAT_MAX_ENTRIES`] entries; larger
    /// robots evaluate it from the columns of `C(q, qd)` ([`Evaluation::CraigColumns`]).
    pub centrifugal: Option<(Route, Vec<Vec<Id>>)>,
    /// Craig's `B(q)` likewise (Christoffel symbols, or `d^2 b_i / dqd_j dqd_k`).
    pub coriolis_pairs: Option<(Route, Vec<Vec<Id>>)>,
    pub kinetic_energy: Id,
    /// Whether `kinetic_energy` is `qd^T M qd / 2` or the sum over body velocities.
    pub kinetic_energy_route: Route,
    /// Joint efforts as symbols `tau_i` (inputs of forward dynamics).
    pub tau_in: Vec<Id>,
    /// `h = b + G + F(qd)`, the right-hand side's part that forward dynamics subtracts.
    pub bias_gravity_friction: Vec<Id>,
    /// `qdd = M^-1 (tau_in - b - G - F)`, with an unrolled sparse `L^T D L` solve.
    pub forward_dynamics: Vec<Id>,
    /// The pivots `D` of that factorization, all positive when `M` is positive definite.
    pub pivots: Vec<Id>,
}

/// Robots whose Craig's `B(q)` has more entries than this (`N^2 (N-1) / 2`; 16 joints have
/// 1,920) never get flattened Craig forms: even when most entries are zero, each is code.
pub const CRAIG_FLAT_MAX_ENTRIES: usize = 2000;

/// Robots with a chain of more joints than this take the recursive route for `b`, `tau` and
/// `C(q, qd)` without comparing it with the Christoffel forms.
pub const CLOSED_FORM_MAX_DEPTH: usize = 12;

fn cheaper<T: Clone>(g: &Graph, a: &T, b: &T, ids: impl Fn(&T) -> Vec<Id>) -> (Route, T) {
    let cost = |x: &T| Program::new(g, &ids(x)).ops().total();
    if cost(b) < cost(a) {
        (Route::Recursive, b.clone())
    } else {
        (Route::Lagrangian, a.clone())
    }
}

fn flat(m: &[Vec<Id>]) -> Vec<Id> {
    m.iter().flatten().copied().collect()
}

/// Stage timings.
struct Clock {
    start: Instant,
    laps: Vec<(&'static str, Duration)>,
}

impl Clock {
    fn new() -> Clock {
        Clock {
            start: Instant::now(),
            laps: Vec::new(),
        }
    }

    fn lap(&mut self, name: &'static str) {
        let now = Instant::now();
        self.laps.push((name, now - self.start));
        self.start = now;
    }
}

/// The closed-form results the fast forms choose from.
struct Closed<'a> {
    mass_matrix: &'a [Vec<Id>],
    gravity: &'a [Id],
    bias: &'a [Id],
    tau: &'a [Id],
    coriolis_matrix: &'a [Vec<Id>],
    centrifugal: &'a [Vec<Id>],
    coriolis_pairs: &'a [Vec<Id>],
}

impl Derivation {
    /// Derives everything for `model`, with the default [`Limits`].
    ///
    /// # Panics
    /// When the expression graph exceeds [`Limits::max_nodes`] (only robots far beyond the
    /// default limit of degrees of freedom of [`Builder`](crate::Builder) get there); use
    /// [`Derivation::try_new`] to get an error instead.
    pub fn new(model: &Model) -> Derivation {
        Derivation::try_new(model, Limits::default()).unwrap_or_else(|e| panic!("{e}"))
    }

    /// Derives everything for `model` in a graph with the given limits, or fails as soon as
    /// the graph is full (checked after every stage and every joint's step within a stage, so
    /// that a robot too large for the limit costs little time and at most the limit's memory).
    pub fn try_new(model: &Model, limits: Limits) -> Result<Derivation, GraphFull> {
        if !model.velocities_are_rates() {
            return floating::derive(model, limits);
        }
        let mut clock = Clock::new();
        let mut g = Graph::with_limits(limits);
        // The coordinates' symbols, and the joints' coordinates as expressions of them (the
        // same symbols unless mimic joints follow others: see `coupling`).
        let map = CoordinateMap::new(model);
        let n = map.coordinates();
        let q: Vec<Id> = (0..n).map(|i| g.q(i)).collect();
        let qd: Vec<Id> = (0..n).map(|i| g.qd(i)).collect();
        let qdd: Vec<Id> = (0..n).map(|i| g.qdd(i)).collect();
        let (joint_q, joint_qd, joint_qdd) = (
            map.positions(&mut g, &q),
            map.rates(&mut g, &qd),
            map.rates(&mut g, &qdd),
        );
        let params = Params::new(&mut g, model);
        let world = WorldKinematics::new(&mut g, model, &params, &joint_q);
        g.check()?;
        let body = BodyKinematics::new(&mut g, model, &params, &joint_q);
        g.check()?;
        clock.lap("kinematics");

        let joint_mass_matrix = lagrangian::mass_matrix(&mut g, model, &params, &body)?;
        let mass_matrix = map.project_matrix(&mut g, &joint_mass_matrix, true);
        clock.lap("mass matrix");
        let grav = const_v3(&mut g, &model.gravity);
        let en = lagrangian::energies(&mut g, &params, &world, &grav, &mass_matrix, &q, &qd);
        g.check()?;
        clock.lap("energies and gravity");
        let ch = lagrangian::christoffel(&mut g, &mass_matrix, &q, &qd)?;
        clock.lap("Christoffel symbols");
        let joint_friction = lagrangian::joint_friction(&mut g, model, &params, &joint_qd);
        let friction = map.project(&mut g, &joint_friction);
        let tau: Vec<Id> = (0..n)
            .map(|i| {
                let mq = g.dot(&mass_matrix[i], &qdd);
                g.add_all([mq, ch.bias[i], en.gravity[i], friction[i]])
            })
            .collect();

        let lm = newton_euler::LocalModel::new(&mut g, model, &params, &joint_q);
        g.check()?;
        let joint_recursive = recursive(&mut g, &lm, grav, &joint_qd, &joint_qdd, &joint_friction)?;
        let recursive = joint_recursive.projected(&mut g, &map);
        clock.lap("recursive algorithms");
        let closed = Closed {
            mass_matrix: &mass_matrix,
            gravity: &en.gravity,
            bias: &ch.bias,
            tau: &tau,
            coriolis_matrix: &ch.coriolis_matrix,
            centrifugal: &ch.centrifugal,
            coriolis_pairs: &ch.coriolis_pairs,
        };
        let coordinate_parents = map.parents(model, lm.coordinate_parents());
        let fast = fast_forms(
            &mut g,
            model,
            &closed,
            &recursive,
            &friction,
            &qd,
            &coordinate_parents,
        )?;
        clock.lap("fast forms");
        let joint_transforms = (0..model.dof())
            .map(|i| JointTransform {
                rotation: lm.rotation[i],
                translation: lm.translation[i],
            })
            .collect();
        let centroidal = Centroidal::new(&mut g, model, &lm, &world, &joint_qd, &[]);
        let centroidal = centroidal.projected(&mut g, &map);
        g.check()?;
        let d = Derivation {
            graph: g,
            dof: n,
            nq: n,
            q,
            qd,
            qdd,
            params: params.symbols,
            mass_matrix,
            gravity: en.gravity,
            centrifugal: ch.centrifugal,
            coriolis_pairs: ch.coriolis_pairs,
            coriolis_matrix: ch.coriolis_matrix,
            bias: ch.bias,
            tau,
            friction,
            kinetic_energy: en.kinetic_energy,
            potential_energy: en.potential_energy,
            joint_transforms,
            coordinate_parents,
            centroidal,
            recursive,
            fast,
            quantities: Vec::new(),
            identification: None,
            timings: Vec::new(),
        };
        Ok(finish(d, model, clock))
    }

    /// The closed-form world pose and Jacobian of every URDF link frame, in the model's
    /// frame order (generated code composes [`Derivation::joint_transforms`] at run time
    /// instead; these are for checks and reports).
    pub fn frames(&mut self, model: &Model) -> Vec<FrameExprs> {
        let g = &mut self.graph;
        let params = Params::new(g, model);
        let map = CoordinateMap::new(model);
        let q = map.positions(g, &self.q);
        let world = WorldKinematics::new(g, model, &params, &q);
        model
            .frames
            .iter()
            .map(|f| {
                let (rotation, position) = world.frame_pose(g, f.body, &f.placement);
                let joint_jacobian = world.point_jacobian(g, model, f.body, &position);
                let jacobian = map.project_columns(g, &joint_jacobian);
                FrameExprs {
                    name: f.name.clone(),
                    rotation,
                    position,
                    jacobian,
                }
            })
            .collect()
    }

    /// Adds the derivatives of the dynamics to the catalogue: `inverse_dynamics_derivatives`
    /// by the recursive algorithm of [`rnea_derivatives`], `mass_matrix_inverse` and
    /// `forward_dynamics_derivatives` through one factorization of `M` (see `derivatives.rs`);
    /// with contacts, the derivatives of contact and impulse dynamics
    /// (`contact_derivatives.rs`).
    /// Fails when the graph fills.
    pub fn add_derivatives(&mut self, model: &Model) -> Result<(), GraphFull> {
        let derived = derivatives::derive(self, model);
        self.graph.check()?;
        let extra = quantities::derivatives(self, &derived);
        self.quantities.extend(extra);
        if !self.centroidal.contact_drift.is_empty() {
            let partials = contact_derivatives::derive(self, model);
            self.graph.check()?;
            let extra = contact_derivatives::quantities(self, &partials);
            self.quantities.extend(extra);
            let extra = active_contacts::derivatives(self);
            self.quantities.extend(extra);
        }
        Ok(())
    }

    /// Each body's share of `M` and `b` by the projected Newton-Euler form, from its own
    /// Jacobians ([`projected`]; fixed base only): what `eomgen show --form
    /// projected-newton-euler` prints. The shares sum to `M` (without rotor inertia) and `b`.
    pub fn projected_newton_euler(&mut self, model: &Model) -> Vec<projected::BodyTerms> {
        projected::body_terms(&mut self.graph, model, &self.q, &self.qd)
    }

    /// The catalogue entry called `name`.
    pub fn quantity(&self, name: &str) -> Option<&Quantity> {
        self.quantities.iter().find(|q| q.name == name)
    }

    /// Lagrange's equations formed directly from `L = T - V`:
    /// `d/dt (dL/dqd_i) - dL/dq_i + F_i`, an independent route to `tau` for cross-checks (the
    /// friction `F` is a non-conservative generalized force, zero unless included).
    pub fn lagrange_equations(&mut self) -> Vec<Id> {
        let g = &mut self.graph;
        let lagrangian = g.sub(self.kinetic_energy, self.potential_energy);
        (0..self.dof)
            .map(|i| {
                let p = g.diff(lagrangian, self.qd[i]);
                let dp = g.time_derivative(p);
                let dl = g.diff(lagrangian, self.q[i]);
                g.sum(0.0, [(dp, 1.0), (dl, -1.0), (self.friction[i], 1.0)])
            })
            .collect()
    }

    /// The time derivative of the mass matrix, `dM/dt` (in `q` and `qd`).
    pub fn mass_matrix_derivative(&mut self) -> Vec<Vec<Id>> {
        let flat: Vec<Id> = self.mass_matrix.iter().flatten().copied().collect();
        let d = self.graph.time_derivative_many(&flat);
        d.chunks(self.dof).map(|r| r.to_vec()).collect()
    }
}

/// `d` with its catalogue and the stage timings.
fn finish(mut d: Derivation, model: &Model, mut clock: Clock) -> Derivation {
    d.quantities = quantities::catalogue(model, &d);
    mpc::add(&mut d, model);
    clock.lap("catalogue");
    d.timings = clock.laps;
    d
}

/// The recursive algorithms on the local model: CRBA, Newton-Euler for gravity, bias, `b + G`
/// and inverse dynamics (plus friction), and the Coriolis matrix.
fn recursive(
    g: &mut Graph,
    lm: &newton_euler::LocalModel,
    grav: V3,
    qd: &[Id],
    qdd: &[Id],
    friction: &[Id],
) -> Result<Recursive, GraphFull> {
    use newton_euler::Terms;
    let gv = Some(grav);
    let (qd_s, qdd_s) = (Some(qd), Some(qdd));
    let crba = newton_euler::crba(g, lm);
    g.check()?;
    let rnea = |g: &mut Graph, qd, qdd, gravity| {
        let r = newton_euler::rnea(g, lm, Terms { qd, qdd, gravity });
        g.check().map(|_| r)
    };
    let gravity = rnea(g, None, None, gv)?;
    let bias = rnea(g, qd_s, None, None)?;
    let bias_and_gravity = rnea(g, qd_s, None, gv)?;
    let tau = rnea(g, qd_s, qdd_s, gv)?;
    let coriolis_matrix = newton_euler::coriolis(g, lm, qd);
    let kinetic_energy = newton_euler::kinetic_energy(g, lm, qd);
    g.check()?;
    let tau = tau
        .iter()
        .zip(friction)
        .map(|(&t, &f)| g.add(t, f))
        .collect();
    Ok(Recursive {
        mass_matrix: crba,
        gravity,
        bias,
        bias_and_gravity,
        tau,
        coriolis_matrix,
        kinetic_energy,
    })
}

/// Per quantity the cheaper route, forward dynamics by an unrolled `L^T D L` solve on the
/// cheaper `M`, and (for small robots) flattened Craig forms.
fn fast_forms(
    g: &mut Graph,
    model: &Model,
    closed: &Closed<'_>,
    rec: &Recursive,
    friction: &[Id],
    qd: &[Id],
    parents: &[Option<usize>],
) -> Result<Fast, GraphFull> {
    let n = qd.len();
    let vec = |v: &Vec<Id>| v.clone();
    let fl = |m: &Vec<Vec<Id>>| flat(m);
    let mm = cheaper(g, &closed.mass_matrix.to_vec(), &rec.mass_matrix, fl);
    let gr = cheaper(g, &closed.gravity.to_vec(), &rec.gravity, vec);
    // On chains longer than a dozen joints the Christoffel forms of b, tau and C(q, qd) are
    // never the cheaper ones, and merely costing them (scheduling millions of nodes) took most
    // of a 64-joint chain's generation time. (A branched hand of short fingers keeps them.)
    let depth = (0..model.dof())
        .map(|i| model.path_to_root(i).len())
        .max()
        .unwrap_or(0);
    let small = depth <= CLOSED_FORM_MAX_DEPTH;
    let choose = |g: &Graph, closed: &[Id], recursive: &Vec<Id>| {
        if small {
            cheaper(g, &closed.to_vec(), recursive, vec)
        } else {
            (Route::Recursive, recursive.clone())
        }
    };
    let bi = choose(g, closed.bias, &rec.bias);
    let tq = choose(g, closed.tau, &rec.tau);
    // h = b + G: one recursion, or the sum of the cheaper closed forms.
    let lag_h: Vec<Id> = (0..n).map(|i| g.add(bi.1[i], gr.1[i])).collect();
    let (_, h) = cheaper(g, &lag_h, &rec.bias_and_gravity, vec);
    let h: Vec<Id> = (0..n).map(|i| g.add(h[i], friction[i])).collect();
    let tau_in: Vec<Id> = (0..n).map(|i| g.tau(i)).collect();
    let rhs: Vec<Id> = (0..n).map(|i| g.sub(tau_in[i], h[i])).collect();
    let (forward_dynamics, pivots) = newton_euler::ltdl_solve(g, parents, &mm.1, &rhs);
    let cm = if small {
        cheaper(
            g,
            &closed.coriolis_matrix.to_vec(),
            &rec.coriolis_matrix,
            fl,
        )
    } else {
        (Route::Recursive, rec.coriolis_matrix.clone())
    };
    let (centrifugal, coriolis_pairs) = if n * n * n.saturating_sub(1) / 2 <= CRAIG_FLAT_MAX_ENTRIES
    {
        let (cf, cp) = craig_from_bias(g, &rec.bias, qd)?;
        (
            Some(cheaper(g, &closed.centrifugal.to_vec(), &cf, fl)),
            Some(cheaper(g, &closed.coriolis_pairs.to_vec(), &cp, fl)),
        )
    } else {
        (None, None)
    };
    let quadratic = lagrangian::quadratic_form(g, &mm.1, qd);
    let (kinetic_energy_route, ke) = cheaper(g, &vec![quadratic], &vec![rec.kinetic_energy], vec);
    let kinetic_energy = ke[0];
    g.check()?;
    Ok(Fast {
        mass_matrix: mm,
        gravity: gr,
        bias: bi,
        tau: tq,
        coriolis_matrix: cm,
        centrifugal,
        coriolis_pairs,
        kinetic_energy,
        kinetic_energy_route,
        tau_in,
        bias_gravity_friction: h,
        forward_dynamics,
        pivots,
    })
}

/// Craig's `C(q)` and `B(q)` from second velocity derivatives of the Newton-Euler bias (`b` is
/// quadratic in `qd`): `C_ij = 1/2 d^2 b_i / dqd_j^2`, `B_i,(jk) = d^2 b_i / dqd_j dqd_k`.
#[allow(clippy::type_complexity)]
fn craig_from_bias(
    g: &mut Graph,
    bias: &[Id],
    qd: &[Id],
) -> Result<(Vec<Vec<Id>>, Vec<Vec<Id>>), GraphFull> {
    let n = qd.len();
    let mut db: Vec<Vec<Id>> = Vec::with_capacity(n);
    for j in 0..n {
        db.push(g.diff_many(bias, qd[j]));
        g.check()?;
    }
    // d2[k][j][i] = d^2 b_i / dqd_j dqd_k, one memoized pass per k over every first derivative.
    let db_flat: Vec<Id> = db.iter().flatten().copied().collect();
    let mut d2: Vec<Vec<Id>> = Vec::with_capacity(n);
    for k in 0..n {
        d2.push(g.diff_many(&db_flat, qd[k]));
        g.check()?;
    }
    let second = |k: usize, j: usize, i: usize| d2[k][j * n + i];
    let mut cf = vec![vec![g.zero(); n]; n];
    let mut cp = vec![Vec::new(); n];
    for i in 0..n {
        for j in 0..n {
            cf[i][j] = g.scale(second(j, j, i), 0.5);
        }
        for &(j, k) in &pairs(n) {
            cp[i].push(second(k, j, i));
        }
    }
    Ok((cf, cp))
}
