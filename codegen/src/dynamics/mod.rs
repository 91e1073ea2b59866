//! The derivation: every quantity of a robot as expressions in one [`Graph`], by two routes,
//! and the [`catalogue`] of what generated code evaluates.
//!
//! - `lagrangian`: the closed forms (`M` from body Jacobians, `G = dV/dq`, Christoffel
//!   symbols), readable and the reference for the reports, where the velocities are the rates
//!   of the positions (no floating base or floating joint: there every quantity takes the
//!   recursive route, in the same derivation);
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
mod contact_flat;
pub mod coupling;
mod derivatives;
mod fast;
mod gravity_drift;
pub mod identification;
mod lagrangian;
pub(crate) mod ltdl;
mod mpc;
pub mod newton_euler;
pub mod projected;
mod quantities;
pub mod regressor;
pub mod rnea_derivatives;

use std::time::{Duration, Instant};

use crate::cas::{Graph, GraphFull, Id, Limits, SumFlattening};
use crate::kinematics::{const_v3, Params, WorldKinematics, M3, V3};
use crate::model::Model;
use lagrangian::{Closed, Friction};

pub use catalogue::{ActiveContacts, Craig, Evaluation, Home, Input, Quantity, Shape};
pub use centroidal::{Centroidal, CONTACT_FORWARD_DYNAMICS_FLAT_MAX_OPS};
pub use coupling::CoordinateMap;
pub use fast::{Fast, Route, CLOSED_FORM_MAX_DEPTH, CRAIG_FLAT_MAX_ENTRIES};
pub use identification::Identification;
pub use lagrangian::pairs;
pub use mpc::{FrameMotion, Manifold};
pub use quantities::{
    DERIVATIVES_FLAT_MAX_OPS, FORWARD_DYNAMICS_PARTIALS_MAX_OPS, MASS_MATRIX_INVERSE_FLAT_DIVISOR,
};

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
    /// The names of the quantities [`Derivation::add_derivatives`] added, whose bodies take
    /// the derivatives' operation budget (`Builder::max_derivative_function_ops`).
    pub derivative_quantities: std::collections::BTreeSet<&'static str>,
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

/// The coordinates' symbols, and the joints' coordinates as expressions of them (the same
/// symbols unless mimic joints follow others: see `coupling`).
struct Coordinates {
    q: Vec<Id>,
    qd: Vec<Id>,
    qdd: Vec<Id>,
    joint_q: Vec<Id>,
    joint_qd: Vec<Id>,
    joint_qdd: Vec<Id>,
}

impl Coordinates {
    fn new(g: &mut Graph, map: &CoordinateMap) -> Coordinates {
        let (nq, nv) = (map.positions_len(), map.coordinates());
        let q: Vec<Id> = (0..nq).map(|i| g.q(i)).collect();
        let qd: Vec<Id> = (0..nv).map(|i| g.qd(i)).collect();
        let qdd: Vec<Id> = (0..nv).map(|i| g.qdd(i)).collect();
        let (joint_q, joint_qd, joint_qdd) =
            (map.positions(g, &q), map.rates(g, &qd), map.rates(g, &qdd));
        Coordinates {
            q,
            qd,
            qdd,
            joint_q,
            joint_qd,
            joint_qdd,
        }
    }
}

/// The forms [`Derivation`] shows people: the closed Lagrangian forms where there are any,
/// else the recursive ones (a floating base or floating joints: no Craig's matrices).
struct Forms {
    mass_matrix: Vec<Vec<Id>>,
    gravity: Vec<Id>,
    centrifugal: Vec<Vec<Id>>,
    coriolis_pairs: Vec<Vec<Id>>,
    coriolis_matrix: Vec<Vec<Id>>,
    bias: Vec<Id>,
    tau: Vec<Id>,
    kinetic_energy: Id,
    potential_energy: Id,
}

impl Forms {
    fn new(
        g: &mut Graph,
        closed: Option<Closed>,
        rec: &Recursive,
        centroidal: &Centroidal,
        grav: V3,
    ) -> Forms {
        if let Some(c) = closed {
            return Forms {
                mass_matrix: c.mass_matrix,
                gravity: c.energies.gravity,
                centrifugal: c.christoffel.centrifugal,
                coriolis_pairs: c.christoffel.coriolis_pairs,
                coriolis_matrix: c.christoffel.coriolis_matrix,
                bias: c.christoffel.bias,
                tau: c.tau,
                kinetic_energy: c.energies.kinetic_energy,
                potential_energy: c.energies.potential_energy,
            };
        }
        // V = -sum m g.c
        let gc = g.dot(&grav, &centroidal.first_moment);
        Forms {
            mass_matrix: rec.mass_matrix.clone(),
            gravity: rec.gravity.clone(),
            centrifugal: Vec::new(),
            coriolis_pairs: Vec::new(),
            coriolis_matrix: rec.coriolis_matrix.clone(),
            bias: rec.bias.clone(),
            tau: rec.tau.clone(),
            kinetic_energy: rec.kinetic_energy,
            potential_energy: g.neg(gc),
        }
    }
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
        let mut clock = Clock::new();
        let mut g = Graph::with_limits(limits);
        let map = CoordinateMap::new(model);
        let c = Coordinates::new(&mut g, &map);
        let params = Params::new(&mut g, model);
        let world = WorldKinematics::new(&mut g, model, &params, &c.joint_q);
        let friction = Friction::new(&mut g, model, &params, &map, &c.joint_qd);
        g.check()?;
        // The closed Lagrangian forms are a candidate route only where the velocities are the
        // rates of the positions (not with a floating base's or floating joint's quaternion).
        let closed = match model.velocities_are_rates() {
            true => Some(Closed::derive(
                &mut g, model, &params, &map, &c, &world, &friction, &mut clock,
            )?),
            false => None,
        };
        // From here on a sum used by several others is computed once (see SumFlattening):
        // the recursions reuse each body's sums in its children and in the backward pass.
        g.set_flattening(SumFlattening::Shared);
        let lm = newton_euler::LocalModel::new(&mut g, model, &params, &c.joint_q);
        g.check()?;
        if closed.is_none() {
            clock.lap("kinematics");
        }
        let grav = const_v3(&mut g, &model.gravity);
        let joint_rec = recursive(
            &mut g,
            &lm,
            grav,
            &c.joint_qd,
            &c.joint_qdd,
            &friction.joint,
        )?;
        // A floating base's centroidal quantities come from the base's rows of the joint tree's M.
        let joint_mass_matrix = joint_rec.mass_matrix.clone();
        let rec = joint_rec.projected(&mut g, &map);
        clock.lap("recursive algorithms");
        let coordinate_parents = map.parents(model, lm.coordinate_parents());
        let (qd, parents) = (&c.qd, &coordinate_parents);
        let f = &friction.projected;
        let fast = fast::fast_forms(&mut g, model, closed.as_ref(), &rec, f, qd, parents)?;
        clock.lap("fast forms");
        let m = &joint_mass_matrix;
        // The centre of mass sums every body's first moment: merged sums collect its terms.
        let old = g.set_flattening(SumFlattening::Always);
        let centroidal = Centroidal::new(&mut g, model, &lm, &world, &c.joint_qd, m);
        let centroidal = centroidal.projected(&mut g, &map);
        g.set_flattening(old);
        g.check()?;
        let forms = Forms::new(&mut g, closed, &rec, &centroidal, grav);
        let joint_transforms = (0..lm.bodies())
            .map(|i| JointTransform {
                rotation: lm.rotation[i],
                translation: lm.translation[i],
            })
            .collect();
        let d = Derivation {
            graph: g,
            dof: c.qd.len(),
            nq: c.q.len(),
            q: c.q,
            qd: c.qd,
            qdd: c.qdd,
            params: params.symbols,
            mass_matrix: forms.mass_matrix,
            gravity: forms.gravity,
            centrifugal: forms.centrifugal,
            coriolis_pairs: forms.coriolis_pairs,
            coriolis_matrix: forms.coriolis_matrix,
            bias: forms.bias,
            tau: forms.tau,
            friction: friction.projected,
            kinetic_energy: forms.kinetic_energy,
            potential_energy: forms.potential_energy,
            joint_transforms,
            coordinate_parents,
            centroidal,
            recursive: rec,
            fast,
            quantities: Vec::new(),
            derivative_quantities: Default::default(),
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
        self.add_derivatives_flat_up_to(model, quantities::DERIVATIVES_FLAT_MAX_OPS)
    }

    /// Generates `contact_forward_dynamics` and `impulse_dynamics` as straight-line programs
    /// only up to `flat_max_ops` operations each, solving them at run time beyond
    /// ([`crate::Builder::contact_forward_dynamics_flat_max_ops`]; the catalogue's default is
    /// [`CONTACT_FORWARD_DYNAMICS_FLAT_MAX_OPS`]). Nothing changes without
    /// contacts. Fails when the graph fills.
    pub fn set_contact_forward_dynamics_flat_max_ops(
        &mut self,
        model: &Model,
        flat_max_ops: usize,
    ) -> Result<(), GraphFull> {
        for name in ["contact_forward_dynamics", "impulse_dynamics"] {
            let Some(at) = self.quantities.iter().position(|q| q.name == name) else {
                continue;
            };
            let (route, eval) = match name {
                "impulse_dynamics" => {
                    contact_derivatives::impulse_dynamics_route(model, self, flat_max_ops)
                }
                _ => centroidal::contact_forward_dynamics(model, self, flat_max_ops),
            };
            self.graph.check()?;
            let q = &mut self.quantities[at];
            (q.route, q.eval) = (format!("Route: {route}."), eval);
        }
        Ok(())
    }

    /// [`Derivation::add_derivatives`] with `M^-1` and the forward-dynamics derivatives
    /// straight-line up to `flat_max_ops` operations each
    /// ([`crate::Builder::derivatives_flat_max_ops`]).
    pub fn add_derivatives_flat_up_to(
        &mut self,
        model: &Model,
        flat_max_ops: usize,
    ) -> Result<(), GraphFull> {
        // Shared sums, as for the recursive algorithms the derivatives differentiate.
        let old = self.graph.set_flattening(SumFlattening::Shared);
        let added = self.add_derivative_stages(model, flat_max_ops);
        self.graph.set_flattening(old);
        added
    }

    /// The stages of [`Derivation::add_derivatives_flat_up_to`].
    fn add_derivative_stages(
        &mut self,
        model: &Model,
        flat_max_ops: usize,
    ) -> Result<(), GraphFull> {
        let derived = derivatives::derive(self, model);
        self.graph.check()?;
        let extra = quantities::derivatives(self, &derived, flat_max_ops);
        self.add_derivative_quantities(extra);
        if !self.centroidal.contact_drift.is_empty() {
            let partials = contact_derivatives::derive(self, model);
            self.graph.check()?;
            let extra = contact_derivatives::quantities(self, &partials);
            self.add_derivative_quantities(extra);
            let extra = active_contacts::derivatives(self);
            self.add_derivative_quantities(extra);
        }
        Ok(())
    }

    /// Appends `extra` to the catalogue as derivatives ([`Derivation::derivative_quantities`]).
    fn add_derivative_quantities(&mut self, extra: Vec<Quantity>) {
        self.derivative_quantities
            .extend(extra.iter().map(|q| q.name));
        self.quantities.extend(extra);
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
    d.quantities = quantities::catalogue(model, &mut d);
    mpc::add(&mut d, model);
    // Reports and later stages that do not choose for themselves see the graph's default.
    d.graph.set_flattening(SumFlattening::Always);
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
