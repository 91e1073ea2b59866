//! The centre of mass, its Jacobian and the centroidal momentum map, from the composite
//! inertias of the recursive algorithms; and the contact points' Jacobian and drift.
//!
//! For every velocity coordinate `k` (a column `S_k` of the joint moving body `i`), the
//! composite body below the joint moving with `S_k` has momentum `(L_o, P) = I^C_i S_k` about
//! body `i`'s origin (the composite-rigid-body algorithm's force). In world axes, about the
//! centre of mass `G`: `P_w = R_i P`, `L_G = R_i L_o + (o_i - G) x P_w`. These columns are the
//! centroidal momentum map `A_g`, and `P_w / m` is the centre of mass Jacobian.

use super::catalogue::{Evaluation, Home, Input, Quantity, Shape};
use super::gravity_drift::{self, GravityDrift};
use super::newton_euler::{self, LocalModel, Terms};
use super::{flat, Derivation};
use crate::cas::{Graph, Id};
use crate::kinematics::joint::free_flyer_placement;
use crate::kinematics::{cross, mat_vec, vec_add, vec_scale, vec_sub, WorldKinematics, M3, V3};
use crate::model::{Model, Transform};
use std::collections::HashMap;

/// World rotation and origin of every body of the local model (the floating base first when
/// there is one).
fn body_poses(model: &Model, wk: &WorldKinematics) -> Vec<(M3, V3)> {
    let base = model
        .is_floating()
        .then_some((wk.root.rotation, wk.root.translation));
    base.into_iter()
        .chain(wk.rotation.iter().copied().zip(wk.position.iter().copied()))
        .collect()
}

/// The centre of mass, its Jacobian, the centroidal momentum map and the contact points'
/// Jacobian and drift, as expressions.
#[derive(Clone, Debug)]
pub struct Centroidal {
    /// Total mass of the moving bodies (the floating base included; a fixed root, welded to
    /// the world, is not counted, as in Pinocchio's `centerOfMass`).
    pub mass: Id,
    /// `sum m c` in world coordinates.
    pub first_moment: V3,
    /// The centre of mass in world coordinates.
    pub com: V3,
    /// 3 x nv.
    pub com_jacobian: Vec<Vec<Id>>,
    /// `A_g`, 6 x nv: linear momentum rows, then angular momentum about the centre of mass,
    /// world axes.
    pub map: Vec<Vec<Id>>,
    /// 3K x nv, world axes.
    pub contact_jacobian: Vec<Vec<Id>>,
    /// `Jdot v`, 3K, world axes.
    pub contact_drift: Vec<Id>,
    /// The same drift from the forward pass of `b + G`
    /// ([`GravityDrift`]), contact by contact.
    pub(crate) gravity_drift: Vec<GravityDrift>,
    /// Each contact's world placement (points, then frames), 12 entries each: the position,
    /// then the row-major rotation.
    pub contact_placements: Vec<Id>,
}

impl Centroidal {
    /// Everything for `model`, from its local model, world kinematics and velocity symbols;
    /// for a floating base, from the base's rows of the mass matrix `mass_matrix` too.
    pub fn new(
        g: &mut Graph,
        model: &Model,
        lm: &LocalModel,
        wk: &WorldKinematics,
        v: &[Id],
        mass_matrix: &[Vec<Id>],
    ) -> Centroidal {
        let poses = body_poses(model, wk);
        let (mass, first_moment, com, map, com_jacobian) = if model.is_floating() {
            from_base_rows(g, lm, wk, mass_matrix)
        } else {
            let mass = g.add_all(lm.mass.iter().copied());
            let mut first_moment = [g.zero(); 3];
            for (i, (r, o)) in poses.iter().enumerate() {
                // m c_world = m o + R h
                let rh = mat_vec(g, r, &lm.first_moment[i]);
                let mo = vec_scale(g, o, lm.mass[i]);
                let s = vec_add(g, &rh, &mo);
                first_moment = vec_add(g, &first_moment, &s);
            }
            let inv = g.powi(mass, -1);
            let com = vec_scale(g, &first_moment, inv);
            let (map, com_jacobian) = centroidal_map(g, lm, &poses, &com, inv);
            (mass, first_moment, com, map, com_jacobian)
        };
        let Contacts {
            jacobian: contact_jacobian,
            drift: contact_drift,
            placements: contact_placements,
            gravity_drift,
        } = contacts(g, model, lm, wk, &poses, v);
        Centroidal {
            mass,
            first_moment,
            com,
            com_jacobian,
            map,
            contact_jacobian,
            contact_drift,
            gravity_drift,
            contact_placements,
        }
    }
}

impl Centroidal {
    /// The Jacobians' columns in the coordinates of `map` (`J G`, see
    /// [`super::coupling`]); unchanged without coupled joints.
    pub fn projected(self, g: &mut Graph, map: &super::CoordinateMap) -> Centroidal {
        if !map.is_coupled() {
            return self;
        }
        Centroidal {
            com_jacobian: map.project_columns(g, &self.com_jacobian),
            map: map.project_columns(g, &self.map),
            contact_jacobian: map.project_columns(g, &self.contact_jacobian),
            ..self
        }
    }
}

/// The centroidal quantities of a floating base from the base's rows of `M`: they are the
/// robot's momentum in base axes about the base origin, `(P_b; L_b) = M[0..6] v` (linear, then
/// angular). With `R` the base rotation, `p` its position, `h` the robot's first moment about
/// the base origin (base axes) and `c_b = h / m`: `com = p + R c_b`, and each column of `A_g`
/// is `(R P_b; R (L_b - c_b x P_b))`, far cheaper than moving every body's momentum to the
/// world.
#[allow(clippy::type_complexity)]
fn from_base_rows(
    g: &mut Graph,
    lm: &LocalModel,
    wk: &WorldKinematics,
    m: &[Vec<Id>],
) -> (Id, V3, V3, Vec<Vec<Id>>, Vec<Vec<Id>>) {
    let (mass, h) = newton_euler::root_composite(g, lm);
    let (r, p) = (&wk.root.rotation, &wk.root.translation);
    let inv = g.powi(mass, -1);
    let rh = mat_vec(g, r, &h);
    let mp = vec_scale(g, p, mass);
    let first_moment = vec_add(g, &mp, &rh);
    let com = vec_scale(g, &first_moment, inv);
    let cb = vec_scale(g, &h, inv);
    let nv = m.len();
    let mut ag = vec![vec![g.zero(); nv]; 6];
    for c in 0..nv {
        let pb = [m[0][c], m[1][c], m[2][c]];
        let lb = [m[3][c], m[4][c], m[5][c]];
        let cp = cross(g, &cb, &pb);
        let lg = vec_sub(g, &lb, &cp);
        let pw = mat_vec(g, r, &pb);
        let lw = mat_vec(g, r, &lg);
        for k in 0..3 {
            ag[k][c] = pw[k];
            ag[3 + k][c] = lw[k];
        }
    }
    let jcom = ag[..3]
        .iter()
        .map(|row| row.iter().map(|&x| g.mul(x, inv)).collect())
        .collect();
    (mass, first_moment, com, ag, jcom)
}

/// `A_g` (6 x nv: linear momentum rows, then angular momentum about the centre of mass, world
/// axes) and the centre of mass Jacobian `A_g[0..3] / m` (3 x nv).
fn centroidal_map(
    g: &mut Graph,
    lm: &LocalModel,
    poses: &[(M3, V3)],
    com: &V3,
    inv_mass: Id,
) -> (Vec<Vec<Id>>, Vec<Vec<Id>>) {
    let nv = lm.nv();
    let mut ag = vec![vec![g.zero(); nv]; 6];
    for (col, body, (moment, force)) in newton_euler::column_momenta(g, lm) {
        let (r, o) = &poses[body];
        let p = mat_vec(g, r, &force);
        let l = mat_vec(g, r, &moment);
        let lever = vec_sub(g, o, com);
        let shift = cross(g, &lever, &p);
        let lg = vec_add(g, &l, &shift);
        for k in 0..3 {
            ag[k][col] = p[k];
            ag[3 + k][col] = lg[k];
        }
    }
    let jcom = ag[..3]
        .iter()
        .map(|row| row.iter().map(|&x| g.mul(x, inv_mass)).collect())
        .collect();
    (ag, jcom)
}

/// What [`contacts`] derives for every contact, in the contact rows' order.
struct Contacts {
    /// K x nv, world axes: the linear rows of each contact point's link Jacobian, then all six
    /// of each 6D contact frame's.
    jacobian: Vec<Vec<Id>>,
    /// The constrained acceleration at zero generalized acceleration: a point's classical
    /// acceleration (`Jdot v`), a frame's spatial acceleration (linear part: the origin's
    /// classical acceleration minus `omega x` its velocity, as Pinocchio's
    /// `getFrameAcceleration`), from Newton-Euler's forward pass without gravity.
    drift: Vec<Id>,
    /// Each contact's world placement (position, then row-major rotation).
    placements: Vec<Id>,
    /// The drift's parts from the forward pass with gravity (`b + G`'s).
    gravity_drift: Vec<GravityDrift>,
}

/// The contacts' Jacobian, drift, placements and drift from `b + G`'s pass ([`Contacts`]), with
/// `q`, `v` the coordinate symbols.
fn contacts(
    g: &mut Graph,
    model: &Model,
    lm: &LocalModel,
    wk: &WorldKinematics,
    poses: &[(M3, V3)],
    v: &[Id],
) -> Contacts {
    let shift = usize::from(model.is_floating());
    let terms = Terms {
        qd: Some(v),
        qdd: None,
        gravity: None,
    };
    let motions = newton_euler::forward_pass(g, lm, terms, |_, _, _| {});
    let with_gravity = gravity_drift::forward_pass(g, model, lm, v);
    let mut out = Contacts {
        jacobian: Vec::new(),
        drift: Vec::new(),
        placements: Vec::new(),
        gravity_drift: Vec::new(),
    };
    for (f, offset, six) in contact_list(model) {
        let rows = if six { 6 } else { 3 };
        let frame = &model.frames[f];
        let placement = Transform {
            rotation: frame.placement.rotation,
            translation: frame.placement.translation
                + frame.placement.rotation * nalgebra::Vector3::from(offset),
        };
        let (rotation, position) = wk.frame_pose(g, frame.body, &placement);
        out.placements.extend(position);
        out.placements.extend(rotation.iter().flatten());
        let full = wk.point_jacobian(g, model, frame.body, &position);
        let Some(body) = frame.body.map(|b| b + shift).or((shift == 1).then_some(0)) else {
            // On a fixed root: the frame never moves.
            out.jacobian.extend(full.into_iter().take(rows));
            out.drift.extend(vec![g.zero(); rows]);
            out.gravity_drift.push(GravityDrift::still(g));
            continue;
        };
        let t = [0, 1, 2].map(|k| g.constant(placement.translation[k]));
        let (m, r) = (&motions[body], &poses[body].0);
        let a = point_acceleration(g, m, &t);
        let classical = mat_vec(g, r, &a);
        // A frame's origin velocity, which its drift and its gravity drift's parts take.
        let velocity = if six {
            let w = mat_vec(g, r, &m.w);
            let velocity = [0, 1, 2].map(|k| g.dot(&full[k], v));
            let wv = cross(g, &w, &velocity);
            out.drift.extend(vec_sub(g, &classical, &wv));
            out.drift.extend(mat_vec(g, r, &m.dw));
            Some(velocity)
        } else {
            out.drift.extend(classical);
            None
        };
        let mg = &with_gravity[body];
        out.gravity_drift.push(GravityDrift {
            rotation: Some(*r),
            accel: point_acceleration(g, mg, &t),
            frame: velocity.map(|velocity| (mg.w, mg.dw, velocity)),
        });
        out.jacobian.extend(full.into_iter().take(rows));
    }
    out
}

/// The classical acceleration of the point `t` of a body (body axes) from the body's motion:
/// its origin's plus `dw x t + w x (w x t)`.
fn point_acceleration(g: &mut Graph, m: &newton_euler::BodyMotion, t: &V3) -> V3 {
    let dwt = cross(g, &m.dw, t);
    let wt = cross(g, &m.w, t);
    let wwt = cross(g, &m.w, &wt);
    [0, 1, 2].map(|k| g.add_all([m.acc[k], dwt[k], wwt[k]]))
}

const Q: &[Input] = &[Input::Q];

/// A catalogue entry with an inherent home and a one-sentence route.
pub(super) fn quantity(
    name: &'static str,
    inputs: &'static [Input],
    shape: Shape,
    doc: &[&str],
    route: &str,
    eval: Evaluation,
) -> Quantity {
    Quantity {
        name,
        inputs,
        shape,
        home: Home::Inherent,
        doc: doc.iter().map(|s| s.to_string()).collect(),
        route: format!("Route: {route}."),
        eval,
    }
}

/// The catalogue's centre of mass quantities (every robot), the centroidal map and `integrate`
/// (floating bases) and the contact quantities (robots with contact points).
pub(super) fn quantities(model: &Model, d: &mut Derivation) -> Vec<Quantity> {
    let mut out = center_of_mass_quantities(model, d);
    if !d.centroidal.contact_drift.is_empty() {
        out.extend(contact_quantities(model, d));
    }
    if !model.velocities_are_rates() {
        out.push(integrate(model, d));
    }
    out
}

/// `center_of_mass`, its Jacobian and, on a floating base, the centroidal map.
fn center_of_mass_quantities(model: &Model, d: &Derivation) -> Vec<Quantity> {
    let (nv, c) = (d.dof, &d.centroidal);
    let from_momenta = "each coordinate's composite-body momentum (the composite-rigid-body algorithm's), moved to the world";
    let mut out = vec![
        quantity(
            "center_of_mass",
            Q,
            Shape::Vector(3),
            &["The centre of mass of the moving bodies in world coordinates (a fixed root link, welded to the world, is not counted)."],
            "the bodies' centres of mass by forward kinematics",
            Evaluation::Exprs(c.com.to_vec()),
        ),
        quantity(
            "center_of_mass_jacobian",
            Q,
            Shape::Matrix(3, nv),
            &["The Jacobian of `center_of_mass`, 3 x N, world axes."],
            from_momenta,
            Evaluation::Exprs(flat(&c.com_jacobian)),
        ),
    ];
    if model.is_floating() {
        out.push(quantity(
            "centroidal_map",
            Q,
            Shape::Matrix(6, nv),
            &[
                "The centroidal momentum map A_g, 6 x N: `A_g v` = [linear momentum; angular momentum about",
                "the centre of mass], world axes.",
            ],
            from_momenta,
            Evaluation::Exprs(flat(&c.map)),
        ));
    }
    out
}

/// The contact rows' order, for the contact quantities' documentation: the contact points, the
/// points at an offset in their link frames, then the 6D contact frames.
fn contact_order(model: &Model) -> String {
    let names = |frames: &[usize]| -> String {
        let names: Vec<String> = frames
            .iter()
            .map(|&f| format!("`{}`", model.frames[f].name.replace('`', "'")))
            .collect();
        names.join(", ")
    };
    let mut order = String::new();
    if !model.contacts.is_empty() {
        order = format!(
            "Contact points, 3 rows each, in this order: {}.",
            names(&model.contacts)
        );
    }
    if !model.contact_points_at.is_empty() {
        let at: Vec<String> = model
            .contact_points_at
            .iter()
            .map(|&(f, p)| {
                let name = model.frames[f].name.replace('`', "'");
                format!("`{name}` at ({}, {}, {})", p[0], p[1], p[2])
            })
            .collect();
        order += &format!(
            "{}ontact points in link frames, 3 rows each: {}.",
            if order.is_empty() { "C" } else { " Then c" },
            at.join(", ")
        );
    }
    if !model.contact_frames.is_empty() {
        order += &format!(
            "{}6D contact frames, 6 rows each (linear, then angular; the drift is the frame's spatial acceleration), in this order: {}.",
            if order.is_empty() { "" } else { " Then " },
            names(&model.contact_frames)
        );
    }
    order
}

/// Every contact in the contact rows' order: its frame, the point's offset in the frame, and
/// whether it is a 6D frame (points at frame origins, points at an offset, then 6D frames).
pub(super) fn contact_list(model: &Model) -> impl Iterator<Item = (usize, [f64; 3], bool)> + '_ {
    let origin = [0.0; 3];
    let points = model.contacts.iter().map(move |&f| (f, origin, false));
    let at = model.contact_points_at.iter().map(|&(f, p)| (f, p, false));
    let frames = model.contact_frames.iter().map(move |&f| (f, origin, true));
    points.chain(at).chain(frames)
}

/// `contact_jacobian`, `contact_drift` and `contact_forward_dynamics` (robots with contacts).
fn contact_quantities(model: &Model, d: &mut Derivation) -> [Quantity; 3] {
    let (route, forward) =
        contact_forward_dynamics(model, d, CONTACT_FORWARD_DYNAMICS_FLAT_MAX_OPS);
    let (nv, c) = (d.dof, &d.centroidal);
    let k3 = c.contact_drift.len();
    let order = contact_order(model);
    [
        quantity(
            "contact_jacobian",
            Q,
            Shape::Matrix(k3, nv),
            &["The contact points' Jacobian J_c, 3K x N: linear velocity of each contact link's origin,", "world axes.", "", &order],
            "joint axes and origins by forward kinematics",
            Evaluation::Exprs(flat(&c.contact_jacobian)),
        ),
        quantity(
            "contact_drift",
            &[Input::Q, Input::Qd],
            Shape::Vector(k3),
            &["`Jdot_c qd`: the contact points' acceleration at zero generalized acceleration, world axes.", "", &order],
            "Newton-Euler's forward pass without acceleration and gravity",
            Evaluation::Exprs(c.contact_drift.clone()),
        ),
        quantity(
            "contact_forward_dynamics",
            &[Input::Q, Input::Qd, Input::Tau],
            Shape::Vector(nv + k3),
            &[
                "Forward dynamics with the contact points held: the accelerations and the contact forces",
                "(on the robot, world axes) of `M qdd + b + G = tau + J_c^T F`, `J_c qdd + Jdot_c qd = 0`.",
                "",
                "NaN in every entry when M(q) is not positive definite or J_c is rank-deficient;",
                "`try_contact_forward_dynamics` says why.",
            ],
            route,
            forward,
        ),
    ]
}

/// A floating base's contact Jacobian and drift in the base's axes, and the base's rotation
/// `R` that turns them into the world's (`J_c = R J_b`, `drift = R drift_b`, each three rows:
/// a point's, or a 6D frame's linear or angular part); `None` without a floating base. They
/// are the world's expressions with the base's quaternion (x, y, z, w) at the identity: the
/// contacts move with the base, so nothing else in them depends on its orientation (nor on
/// its position), and the base's columns of `J_b` are `(I, -[p]x)`.
pub(super) fn contacts_in_base_axes(
    model: &Model,
    d: &mut Derivation,
) -> Option<(Vec<Vec<Id>>, Vec<Id>, M3)> {
    if !model.is_floating() {
        return None;
    }
    let c = &d.centroidal;
    let (n, k) = (d.dof, c.contact_drift.len());
    let all: Vec<Id> = c
        .contact_jacobian
        .iter()
        .flatten()
        .chain(&c.contact_drift)
        .copied()
        .collect();
    let g = &mut d.graph;
    let at_identity = base_at_identity(g, &d.q);
    let based = g.substitute(&all, &at_identity);
    let j = based[..k * n].chunks(n).map(<[Id]>::to_vec).collect();
    let drift = based[k * n..].to_vec();
    Some((j, drift, free_flyer_placement(g, &d.q[..7]).rotation))
}

/// The floating base's quaternion (x, y, z, w) of `q` at the identity, as a substitution: what
/// turns an expression in world axes of a point moving with the base into base axes.
pub(super) fn base_at_identity(g: &mut Graph, q: &[Id]) -> HashMap<Id, Id> {
    let (zero, one) = (g.zero(), g.one());
    [(q[3], zero), (q[4], zero), (q[5], zero), (q[6], one)]
        .into_iter()
        .collect()
}

/// The contact Jacobian and drift in the axes they are solved in, and the rotation that turns
/// those axes into the world's: a floating base's ([`contacts_in_base_axes`]), or the world's
/// own (`None`).
pub(super) fn contacts_in_solving_axes(
    model: &Model,
    d: &mut Derivation,
) -> (Vec<Vec<Id>>, Vec<Id>, Option<M3>) {
    match contacts_in_base_axes(model, d) {
        Some((j, drift, r)) => (j, drift, Some(r)),
        None => {
            let c = &d.centroidal;
            (c.contact_jacobian.clone(), c.contact_drift.clone(), None)
        }
    }
}

/// `r` times each three entries of `v` (a vector of contact rows turned between axes); `v`
/// itself when `r` is `None` (the axes are the world's).
pub(super) fn turn_rows(g: &mut Graph, r: Option<&M3>, v: &[Id]) -> Vec<Id> {
    let Some(r) = r else {
        return v.to_vec();
    };
    v.chunks(3)
        .flat_map(|x| mat_vec(g, r, &[x[0], x[1], x[2]]))
        .collect()
}

/// The largest straight-line contact forward dynamics generated (operations, with its
/// pivots); beyond, `M`, `J_c` and the drift come from their own functions and the contact
/// system is solved at run time (`eomgen_runtime::contact::solve_factored_active_by`).
/// Straight-line was faster on every robot measured (native, alternated, run-time route ->
/// straight-line): anymal (8,635 operations) 1,645 -> 1,305 ns, b1-z1 (a quadruped with an
/// arm, 10,878) 2,167 -> 1,620 ns, g1_29dof (two 6D soles, 21,352) 3,796 -> 3,071 ns,
/// talos_full_v2 (two 6D soles, 27,735) 5,119 -> 4,138 ns.
pub const CONTACT_FORWARD_DYNAMICS_FLAT_MAX_OPS: usize = 32_000;

/// `contact_forward_dynamics`'s route and evaluation: straight-line up to `flat_max_ops`
/// operations (by default [`CONTACT_FORWARD_DYNAMICS_FLAT_MAX_OPS`]), else solved at run time.
pub(super) fn contact_forward_dynamics(
    model: &Model,
    d: &mut Derivation,
    flat_max_ops: usize,
) -> (&'static str, Evaluation) {
    let run_time = (
        "M from `mass_matrix`, b + G by Newton-Euler, J_c and its drift, then the unrolled L^T D L of M, a Cholesky factorization of J_c M^-1 J_c^T and one more substitution (eomgen_runtime::contact::solve_factored_active_by, with the first half of the substitution unrolled too)",
        Evaluation::ContactForwardDynamics {
            h: d.fast.bias_gravity_friction.clone(),
        },
    );
    if flat_max_ops == 0 {
        return run_time;
    }
    let (j, _, axes) = contacts_in_solving_axes(model, d);
    // The drift from `b + G`'s forward pass, which the program computes anyway.
    let drift = super::gravity_drift::in_solving_axes(model, d);
    let flat = super::contact_flat::contact_forward_dynamics(
        &mut d.graph,
        &d.coordinate_parents,
        &d.fast.mass_matrix.1,
        &d.fast.bias_gravity_friction,
        (&j, &drift),
        axes.as_ref(),
    );
    if flat.fits(&d.graph, flat_max_ops) {
        (
            "one straight-line program: M and b + G as in `mass_matrix` and `bias`, J_c and its drift (in the floating base's axes, the forces turned into the world's at the end), the unrolled L^T D L of M, W = L^-T J_c^T, J_c M^-1 J_c^T = W^T D^-1 W and its L^T D L, without the zeros of J_c",
            Evaluation::ContactForwardDynamicsFlat {
                outputs: flat.outputs,
                pivots: flat.pivots,
            },
        )
    } else {
        run_time
    }
}

/// `integrate`: the floating base's SE(3) exponential, or each floating joint's.
fn integrate(model: &Model, d: &Derivation) -> Quantity {
    let (what, how) = if model.is_floating() {
        (
            "the base along the SE(3) exponential (the quaternion stays unit), the joints by `qd dt`.",
            "eomgen_runtime::free_flyer::integrate",
        )
    } else {
        (
            "each floating joint along the SE(3) exponential (its quaternion stays unit), the others by `qd dt`.",
            "eomgen_runtime::free_flyer::integrate_blocks over the floating joints' coordinates",
        )
    };
    quantity(
        "integrate",
        &[Input::Q, Input::Qd],
        Shape::Vector(d.nq),
        &[
            "`q (+) qd dt`: the configuration reached from `q` moving at constant velocity `qd` for `dt`:",
            what,
        ],
        how,
        Evaluation::Integrate,
    )
}
