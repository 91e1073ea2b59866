//! The joint torque regressor: `tau = Y(q, qd, qdd) pi`, linear in the standard inertial
//! parameters `pi` (and in the rotor inertia and friction coefficients when the model has
//! them).
//!
//! Each body's ten standard parameters are, as in Pinocchio and in the identification
//! literature (Khalil and Dombre's `M, MX, MY, MZ, XX, ...`): the mass `m`, the first moment
//! `m c` and the rotational inertia about the body frame's origin, in that frame's axes
//! (`J = I_c + m (|c|^2 1 - c c^T)`), in the order `m, m cx, m cy, m cz, Ixx, Ixy, Iyy, Ixz,
//! Iyz, Izz`. The body frame is the child link frame of the body's joint, fixed children
//! merged.
//!
//! Body `k`'s block of row `i` is `S_i . X_{i<-k}^* A_k(v_k, a_k)`, with `A_k` the 6 x 10 body
//! regressor, by two routes: [`differentiated`] runs the Newton-Euler recursion with every
//! parameter a symbol and differentiates `tau` in each (the columns of `A_k` carried up to
//! each ancestor as forces), [`projected`] carries each joint's motion subspace down to the
//! bodies below it instead (one motion transform per pair). The CAS keeps only what the
//! robot's geometry does not make zero, and the cheaper route is generated (the UR5's
//! regressor: 1,338 operations projected, 1,643 differentiated; the double pendulum's: 60 and
//! 33).

use crate::cas::{Graph, GraphFull, Id};
use crate::kinematics::Params;
use crate::model::Model;
use crate::spatial::{
    cross, cross_force, mat_t_vec, motion_cross, spatial_add, spatial_dot, spatial_scale, vec_add,
    Spatial, V3,
};

use super::lagrangian::joint_friction;
use super::newton_euler::{inertia_times, rnea, velocities, LocalModel, Terms};

/// The names of a body's ten standard parameters, in regressor order (`M_link2` is the mass of
/// body `link2`, `MX_link2` its first moment `m cx`, `XX_link2` its inertia `Ixx` about the
/// body frame's origin).
pub const BODY_PARAMETERS: [&str; 10] = ["M", "MX", "MY", "MZ", "XX", "XY", "YY", "XZ", "YZ", "ZZ"];

/// Index in [`BODY_PARAMETERS`] of the inertia entry `(a, b)` (symmetric).
pub fn inertia_index(a: usize, b: usize) -> usize {
    match (a.min(b), a.max(b)) {
        (0, 0) => 4,
        (0, 1) => 5,
        (1, 1) => 6,
        (0, 2) => 7,
        (1, 2) => 8,
        _ => 9,
    }
}

/// What a standard parameter belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Owner {
    /// Parameter `index` of [`BODY_PARAMETERS`] of body `body`.
    Body { body: usize, index: usize },
    /// Rotor inertia (armature) of a joint: `IA_joint`, column `qdd_i`.
    Armature(usize),
    /// Viscous friction coefficient of a joint: `FV_joint`, column `qd_i`.
    Viscous(usize),
    /// Coulomb friction coefficient of a joint: `FS_joint`, column `s(qd_i)`.
    Coulomb(usize),
}

/// One standard parameter: a symbol for the formulas people read, and its value in generated
/// code.
#[derive(Clone, Debug)]
pub struct Parameter {
    /// `M_link2`, `XX_link2`, `IA_joint2`, `FV_joint2`, `FS_joint2`.
    pub name: String,
    pub owner: Owner,
    /// The parameter as a symbol (only in formulas for people, never in generated code).
    pub symbol: Id,
    /// Its value from the model's parameters (numbers, or fields of the generated struct).
    pub value: Id,
}

/// The standard parameters of `model` in regressor order: ten per body in joint order, then
/// the rotor inertia of each joint that has one, then the viscous and Coulomb coefficients of
/// every joint when the model includes friction.
pub fn standard_parameters(
    g: &mut Graph,
    model: &Model,
    lm: &LocalModel,
    params: &Params,
) -> Vec<Parameter> {
    let mut out = Vec::new();
    let mut push = |g: &mut Graph, head: &str, owner_name: &str, owner: Owner, value: Id| {
        let name = format!("{head}_{owner_name}");
        let symbol = g.param(&name);
        out.push(Parameter {
            name,
            owner,
            symbol,
            value,
        });
    };
    for (b, body) in model.bodies.iter().enumerate() {
        let j = &lm.inertia[b];
        let h = &lm.first_moment[b];
        let values = [
            lm.mass[b], h[0], h[1], h[2], j[0][0], j[0][1], j[1][1], j[0][2], j[1][2], j[2][2],
        ];
        for (index, (head, value)) in BODY_PARAMETERS.iter().zip(values).enumerate() {
            push(g, head, &body.name, Owner::Body { body: b, index }, value);
        }
    }
    for (i, joint) in model.joints.iter().enumerate() {
        if joint.armature != 0.0 {
            push(g, "IA", &joint.name, Owner::Armature(i), params.armature[i]);
        }
    }
    if model.include_friction {
        for (i, joint) in model.joints.iter().enumerate() {
            push(g, "FV", &joint.name, Owner::Viscous(i), params.damping[i]);
            push(g, "FS", &joint.name, Owner::Coulomb(i), params.coulomb[i]);
        }
    }
    out
}

/// What both routes to the regressor start from.
#[derive(Clone, Copy, Debug)]
pub struct Inputs<'a> {
    pub model: &'a Model,
    /// The recursions' local model, with the model's parameter values.
    pub lm: &'a LocalModel,
    pub params: &'a Params,
    /// The standard parameters ([`standard_parameters`]).
    pub parameters: &'a [Parameter],
    pub qd: &'a [Id],
    pub qdd: &'a [Id],
    /// Gravity in world axes.
    pub gravity: V3,
}

impl Inputs<'_> {
    /// The local model with every standard parameter a symbol (rotor inertia zero where the
    /// joint has none), and the joint friction effort with symbolic coefficients.
    fn symbolic(&self, g: &mut Graph) -> (LocalModel, Vec<Id>) {
        let mut lm = self.lm.clone();
        let mut params = self.params.clone();
        lm.armature = vec![g.zero(); lm.armature.len()];
        for p in self.parameters {
            match p.owner {
                Owner::Body { body, index: 0 } => lm.mass[body] = p.symbol,
                Owner::Body { body, index } if index <= 3 => {
                    lm.first_moment[body][index - 1] = p.symbol
                }
                Owner::Body { body, index } => {
                    for (a, row) in lm.inertia[body].iter_mut().enumerate() {
                        for (b, e) in row.iter_mut().enumerate() {
                            if inertia_index(a, b) == index {
                                *e = p.symbol;
                            }
                        }
                    }
                }
                Owner::Armature(i) => lm.armature[i] = p.symbol,
                Owner::Viscous(i) => params.damping[i] = p.symbol,
                Owner::Coulomb(i) => params.coulomb[i] = p.symbol,
            }
        }
        let friction = joint_friction(g, self.model, &params, self.qd);
        (lm, friction)
    }
}

/// The N x P regressor by projection (with gravity `grav`). Fails when the graph fills.
///
/// Row `i`, column block of body `k` (a descendant of joint `i`, or `i` itself):
/// `S_i^(k) . A_k`, with `S_i^(k)` joint `i`'s motion subspace carried down to body `k`'s frame
/// and `A_k` the 6 x 10 body regressor, `f_k = A_k pi_k` for the body's spatial force
/// `f = I a + v x* (I v)`: one motion transform per pair of a body and an ancestor.
pub fn projected(g: &mut Graph, inputs: &Inputs<'_>) -> Result<Vec<Vec<Id>>, GraphFull> {
    let (lm, qd, qdd) = (inputs.lm, inputs.qd, inputs.qdd);
    let motion = body_motions(g, lm, qd, qdd, inputs.gravity);
    let down = subspaces_down(g, lm);
    g.check()?;
    let zero = g.zero();
    let mut y = vec![vec![zero; inputs.parameters.len()]; qd.len()];
    let (_, friction) = inputs.symbolic(g);
    for (col, p) in inputs.parameters.iter().enumerate() {
        match p.owner {
            Owner::Body { body, index } => {
                let a = body_regressor_column(g, &motion[body], index);
                for &(i, s) in &down[body] {
                    y[i][col] = spatial_dot(g, &s, &a);
                }
            }
            Owner::Armature(i) => y[i][col] = qdd[i],
            Owner::Viscous(i) | Owner::Coulomb(i) => y[i][col] = g.diff(friction[i], p.symbol),
        }
    }
    g.check()?;
    Ok(y)
}

/// A body's velocity `v = (w, u)` (`u` the velocity of its origin) and spatial acceleration
/// `a = (dw, du - w x u)`, in its axes, with gravity as an upward acceleration of the root.
type Motion = (Spatial, Spatial);

fn body_motions(g: &mut Graph, lm: &LocalModel, qd: &[Id], qdd: &[Id], grav: V3) -> Vec<Motion> {
    let velocity = velocities(g, lm, qd);
    let up = [0, 1, 2].map(|k| g.neg(grav[k]));
    let root = ([g.zero(); 3], up);
    let mut acc: Vec<Spatial> = Vec::with_capacity(qd.len());
    for i in 0..qd.len() {
        let parent = lm.parent[i].map_or(root, |p| acc[p]);
        let moved = motion_to_body(g, lm, i, &parent);
        let s = lm.subspace[i][0];
        let sqdd = spatial_scale(g, &s, qdd[i]);
        let sqd = spatial_scale(g, &s, qd[i]);
        let bias = motion_cross(g, &velocity[i].parent, &sqd);
        let a = spatial_add(g, &moved, &sqdd);
        acc.push(spatial_add(g, &a, &bias));
    }
    velocity.iter().map(|v| v.body).zip(acc).collect()
}

/// A motion `(w, u)` of body `i`'s parent, in the parent's axes at its origin, in body `i`'s
/// axes at its origin: `(R^T w, R^T (u + w x t))`.
fn motion_to_body(g: &mut Graph, lm: &LocalModel, i: usize, m: &Spatial) -> Spatial {
    let r = &lm.rotation[i];
    let wt = cross(g, &m.0, &lm.translation[i]);
    let ut = vec_add(g, &m.1, &wt);
    (mat_t_vec(g, r, &m.0), mat_t_vec(g, r, &ut))
}

/// Per body `k`, the motion subspace of each joint on its path from the root, in body `k`'s
/// axes: `(joint, S_joint^(k))`.
fn subspaces_down(g: &mut Graph, lm: &LocalModel) -> Vec<Vec<(usize, Spatial)>> {
    let mut down: Vec<Vec<(usize, Spatial)>> = Vec::with_capacity(lm.parent.len());
    for k in 0..lm.parent.len() {
        let mut here = match lm.parent[k] {
            Some(p) => down[p]
                .clone()
                .iter()
                .map(|&(i, s)| (i, motion_to_body(g, lm, k, &s)))
                .collect(),
            None => Vec::new(),
        };
        here.push((k, lm.subspace[k][0]));
        down.push(here);
    }
    down
}

/// Column `index` of a body's 6 x 10 regressor: the body's spatial force `I a + v x* (I v)`
/// for the unit parameter `index` (mass, a first-moment component or an inertia entry).
fn body_regressor_column(g: &mut Graph, (v, a): &Motion, index: usize) -> Spatial {
    let (zero, one) = (g.zero(), g.one());
    let mut m = zero;
    let mut h = [zero; 3];
    let mut j = [[zero; 3]; 3];
    match index {
        0 => m = one,
        1..=3 => h[index - 1] = one,
        _ => {
            for r in 0..3 {
                for c in 0..3 {
                    if inertia_index(r, c) == index {
                        j[r][c] = one;
                    }
                }
            }
        }
    }
    let ia = inertia_times(g, Some(m), &h, &j, a);
    let iv = inertia_times(g, Some(m), &h, &j, v);
    let vf = cross_force(g, v, &iv);
    spatial_add(g, &ia, &vf)
}

/// The N x P regressor by differentiation: column `p` is `d tau / d pi_p` of the
/// Newton-Euler inverse dynamics run with every standard parameter a symbol, which carries
/// each of the ten columns of a body's regressor up to every ancestor as a force. Fails when
/// the graph fills.
pub fn differentiated(g: &mut Graph, inputs: &Inputs<'_>) -> Result<Vec<Vec<Id>>, GraphFull> {
    let (symbolic, friction) = inputs.symbolic(g);
    let terms = Terms {
        qd: Some(inputs.qd),
        qdd: Some(inputs.qdd),
        gravity: Some(inputs.gravity),
    };
    let rigid = rnea(g, &symbolic, terms);
    let tau: Vec<Id> = rigid
        .iter()
        .zip(&friction)
        .map(|(&t, &f)| g.add(t, f))
        .collect();
    g.check()?;
    let mut y = vec![Vec::with_capacity(inputs.parameters.len()); tau.len()];
    for p in inputs.parameters {
        let column = g.diff_many(&tau, p.symbol);
        for (row, c) in y.iter_mut().zip(column) {
            row.push(c);
        }
        g.check()?;
    }
    Ok(y)
}
