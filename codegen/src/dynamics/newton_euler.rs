//! Customized symbolic recursive algorithms: Newton-Euler for inverse dynamics, the bias and
//! gravity, and the composite-rigid-body algorithm for the mass matrix.
//!
//! These are the algorithms of Khalil and Kleinfinger's customized symbolic method (also behind
//! OpenSYMORO and RobCoGen), run on the CAS: every intermediate is an expression, so an entry of
//! a joint's geometry that is 0 or 1 disappears by constant folding, an axis-aligned joint gets
//! the cheap form of every product, and hash-consing shares what the recursion computes twice.
//! Everything is in body coordinates, with bodies described by their mass `m`, first moment
//! `h = m c` and rotational inertia `J` about the body-frame origin (which saves the transfers
//! to the centre of mass).

use super::CoordinateMap;
use crate::cas::{Graph, Id};
use crate::kinematics::{joint, Params};
use crate::model::{JointKind, Model};
use crate::spatial::{
    cross, cross_force, mat_add, mat_mul, mat_t_vec, mat_vec, motion_cross, skew_mul, skew_times,
    spatial_add, spatial_dot, spatial_scale, spatial_sub, transpose, vec_add, vec_scale, Spatial,
    M3, V3,
};

/// How a joint moves its body, for the recursions' velocity and acceleration steps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    /// One coordinate rotating the body about its axis.
    Revolute,
    /// One coordinate translating the body along its axis.
    Prismatic,
    /// A free flyer on the world (a floating base): six coordinates, the body's own velocity.
    Free,
}

/// Each body's placement relative to its parent and its inertia about its own origin.
///
/// Bodies are the model's, in its order, after the floating base (body 0) when the model has
/// one. Joint `i`'s velocity coordinates are `column[i]..column[i] + subspace[i].len()`.
#[derive(Clone, Debug)]
pub struct LocalModel {
    /// Parent from body rotation, `R_origin R_joint(q)` (world from base for a floating base).
    pub rotation: Vec<M3>,
    /// Body origin in parent coordinates (including a prismatic joint's travel).
    pub translation: Vec<V3>,
    /// Joint axis in body coordinates (zero for a free flyer).
    pub axis: Vec<V3>,
    /// How the joint moves its body.
    pub step: Vec<Step>,
    /// The joint's motion subspace in body axes (one column per velocity coordinate).
    pub subspace: Vec<Vec<Spatial>>,
    /// The joint's first velocity coordinate.
    pub column: Vec<usize>,
    pub parent: Vec<Option<usize>>,
    pub mass: Vec<Id>,
    /// First moment `m c`.
    pub first_moment: Vec<V3>,
    /// Rotational inertia about the body origin, `I_c + m (|c|^2 1 - c c^T)`.
    pub inertia: Vec<M3>,
    /// Rotor inertia of each joint: `M_ii += armature_i`, `tau_i += armature_i qdd_i` (zero for
    /// a free flyer).
    pub armature: Vec<Id>,
}

/// `J = I_c + m (c.c 1 - c c^T)`: the inertia about the origin.
fn inertia_about_origin(g: &mut Graph, m: Id, c: &V3, ic: &M3) -> M3 {
    let cc = g.dot(c, c);
    let mut j = *ic;
    for r in 0..3 {
        for k in 0..3 {
            let ck = g.mul(c[r], c[k]);
            let shift = if r == k { g.sub(cc, ck) } else { g.neg(ck) };
            let ms = g.mul(m, shift);
            j[r][k] = g.add(ic[r][k], ms);
        }
    }
    j
}

impl LocalModel {
    /// The local model for position coordinates `q` (`model.nq()` of them).
    pub fn new(g: &mut Graph, model: &Model, params: &Params, q: &[Id]) -> LocalModel {
        let n = model.dof();
        let mut lm = LocalModel {
            rotation: Vec::with_capacity(n + 1),
            translation: Vec::with_capacity(n + 1),
            axis: Vec::with_capacity(n + 1),
            step: Vec::with_capacity(n + 1),
            subspace: Vec::with_capacity(n + 1),
            column: Vec::with_capacity(n + 1),
            parent: Vec::with_capacity(n + 1),
            mass: Vec::with_capacity(n + 1),
            first_moment: Vec::with_capacity(n + 1),
            inertia: Vec::with_capacity(n + 1),
            armature: Vec::with_capacity(n + 1),
        };
        let shift = usize::from(model.is_floating());
        if let Some((m, c, ic)) = &params.base {
            let placed = joint::free_flyer_placement(g, &q[..7]);
            lm.push_body(g, placed, (*m, *c, *ic), g.zero());
            lm.axis.push([g.zero(); 3]);
            lm.step.push(Step::Free);
            lm.subspace.push(joint::free_flyer_subspace(g));
            lm.column.push(0);
            lm.parent.push(None);
        }
        let (q_at, v_at) = (model.q_offsets(), model.v_offsets());
        for (i, joint) in model.joints.iter().enumerate() {
            let coords = &q[q_at[i]..q_at[i] + joint.kind.nq()];
            let placed = joint::body_in_parent(g, joint, &params.origin[i], coords);
            let inertial = (params.mass[i], params.com[i], params.inertia[i]);
            lm.push_body(g, placed, inertial, params.armature[i]);
            lm.axis.push(joint::axis(g, joint));
            lm.step.push(match joint.kind {
                JointKind::Floating => Step::Free,
                JointKind::Revolute | JointKind::Continuous => Step::Revolute,
                JointKind::Prismatic => Step::Prismatic,
            });
            lm.subspace.push(joint::subspace(g, joint));
            lm.column.push(v_at[i]);
            lm.parent.push(match joint.parent {
                Some(p) => Some(p + shift),
                None if shift == 1 => Some(0),
                None => None,
            });
        }
        lm
    }

    fn push_body(
        &mut self,
        g: &mut Graph,
        placed: joint::Placement,
        (m, c, ic): (Id, V3, M3),
        armature: Id,
    ) {
        self.rotation.push(placed.rotation);
        self.translation.push(placed.translation);
        self.mass.push(m);
        self.first_moment.push(vec_scale(g, &c, m));
        self.inertia.push(inertia_about_origin(g, m, &c, &ic));
        self.armature.push(armature);
    }

    /// Number of bodies.
    pub fn bodies(&self) -> usize {
        self.rotation.len()
    }

    /// Number of velocity coordinates.
    pub fn nv(&self) -> usize {
        self.column.last().map_or(0, |&c| c) + self.subspace.last().map_or(0, Vec::len)
    }

    /// Each velocity coordinate's parent coordinate in the tree of coordinates that the
    /// sparse factorizations walk: the previous column of its own joint, else the last column
    /// of the parent body's joint.
    pub fn coordinate_parents(&self) -> Vec<Option<usize>> {
        let mut out = Vec::with_capacity(self.nv());
        for i in 0..self.bodies() {
            let above = self.parent[i].map(|p| self.column[p] + self.subspace[p].len() - 1);
            out.push(above);
            out.extend((1..self.subspace[i].len()).map(|k| Some(self.column[i] + k - 1)));
        }
        out
    }

    fn dof(&self) -> usize {
        self.bodies()
    }

    /// Children of each body, in index order.
    fn children(&self) -> Vec<Vec<usize>> {
        let mut ch = vec![Vec::new(); self.dof()];
        for (i, p) in self.parent.iter().enumerate() {
            if let Some(p) = *p {
                ch[p].push(i);
            }
        }
        ch
    }

    /// Joint `i`'s velocity `S qd` in body axes for the velocity coordinates `qd`.
    fn joint_velocity(&self, g: &mut Graph, i: usize, qd: &[Id]) -> Spatial {
        let zero = [g.zero(); 3];
        let mut v = (zero, zero);
        for (k, s) in self.subspace[i].iter().enumerate() {
            let sq = spatial_scale(g, s, qd[self.column[i] + k]);
            v = spatial_add(g, &v, &sq);
        }
        v
    }
}

/// Which terms of `tau = M qdd + b + G` the recursion keeps.
#[derive(Clone, Copy, Debug)]
pub struct Terms<'a> {
    /// Joint velocities, or `None` for zero.
    pub qd: Option<&'a [Id]>,
    /// Joint accelerations, or `None` for zero.
    pub qdd: Option<&'a [Id]>,
    /// Gravity in world axes, or `None`.
    pub gravity: Option<V3>,
}

/// A body's motion in its own axes: angular velocity, angular acceleration and the classical
/// acceleration of its origin.
#[derive(Clone, Copy, Debug)]
pub struct BodyMotion {
    pub w: V3,
    pub dw: V3,
    pub acc: V3,
}

/// Newton-Euler's forward pass: every body's motion for the selected terms, root first,
/// calling `each` on each body as soon as its motion is known.
pub fn forward_pass(
    g: &mut Graph,
    lm: &LocalModel,
    terms: Terms<'_>,
    mut each: impl FnMut(&mut Graph, usize, &BodyMotion),
) -> Vec<BodyMotion> {
    let n = lm.dof();
    let zero = [g.zero(); 3];
    // Gravity enters as an upward acceleration of the base.
    let base_acc = match terms.gravity {
        Some(gv) => [0, 1, 2].map(|k| g.neg(gv[k])),
        None => zero,
    };
    let mut out: Vec<BodyMotion> = Vec::with_capacity(n);
    for i in 0..n {
        let (wp, dwp, ap) = match lm.parent[i] {
            Some(p) => (out[p].w, out[p].dw, out[p].acc),
            None => (zero, zero, base_acc),
        };
        let r = &lm.rotation[i];
        // Parent quantities in body axes.
        let wp_b = mat_t_vec(g, r, &wp);
        let dwp_b = mat_t_vec(g, r, &dwp);
        let a_origin = origin_acceleration(g, r, &lm.translation[i], (wp, dwp, ap));
        let parent = (wp_b, dwp_b, a_origin);
        let (col, a) = (lm.column[i], &lm.axis[i]);
        let (qd, qdd) = (terms.qd.map(|v| v[col]), terms.qdd.map(|v| v[col]));
        let (wi, dwi, ai) = match lm.step[i] {
            Step::Free => free_step(g, lm, i, terms, parent),
            Step::Revolute => revolute_step(g, a, qd, qdd, parent),
            Step::Prismatic => prismatic_step(g, a, qd, qdd, parent),
        };
        let motion = BodyMotion {
            w: wi,
            dw: dwi,
            acc: ai,
        };
        each(g, i, &motion);
        out.push(motion);
    }
    out
}

/// Recursive Newton-Euler: the generalized efforts for the selected terms (for a floating
/// base, first the force and torque on the base in base axes).
pub fn rnea(g: &mut Graph, lm: &LocalModel, terms: Terms<'_>) -> Vec<Id> {
    let n = lm.dof();
    let mut force: Vec<V3> = Vec::with_capacity(n);
    let mut moment: Vec<V3> = Vec::with_capacity(n);
    forward_pass(g, lm, terms, |g, i, motion| {
        let (wi, dwi, ai) = (motion.w, motion.dw, motion.acc);
        // F = m a + dw x h + w x (w x h);  N = J dw + w x (J w) + h x a   (about the origin)
        let h = &lm.first_moment[i];
        let j = &lm.inertia[i];
        let ma = vec_scale(g, &ai, lm.mass[i]);
        let dwh = cross(g, &dwi, h);
        let wh = cross(g, &wi, h);
        let wwh = cross(g, &wi, &wh);
        let f = [0, 1, 2].map(|k| g.add_all([ma[k], dwh[k], wwh[k]]));
        let jdw = mat_vec(g, j, &dwi);
        let jw = mat_vec(g, j, &wi);
        let wjw = cross(g, &wi, &jw);
        let ha = cross(g, h, &ai);
        let nm = [0, 1, 2].map(|k| g.add_all([jdw[k], wjw[k], ha[k]]));
        force.push(f);
        moment.push(nm);
    });
    // Backward: add each body's children, moved to its frame.
    let children = lm.children();
    let mut tau = vec![g.zero(); lm.nv()];
    for i in (0..n).rev() {
        for &c in &children[i] {
            let (fc, nc) = transfer(g, lm, c, &force[c], &moment[c]);
            force[i] = vec_add(g, &force[i], &fc);
            moment[i] = vec_add(g, &moment[i], &nc);
        }
        let col = lm.column[i];
        if lm.step[i] == Step::Free {
            // The wrench on the base: force, then torque about its origin.
            for k in 0..3 {
                tau[col + k] = force[i][k];
                tau[col + 3 + k] = moment[i][k];
            }
            continue;
        }
        tau[col] = if lm.step[i] == Step::Revolute {
            g.dot(&lm.axis[i], &moment[i])
        } else {
            g.dot(&lm.axis[i], &force[i])
        };
        // The rotor, spun up by the joint alone (its gyroscopic terms are neglected).
        if let Some(qdd) = terms.qdd {
            let rotor = g.mul(lm.armature[i], qdd[col]);
            tau[col] = g.add(tau[col], rotor);
        }
    }
    tau
}

/// The classical acceleration of a body's origin carried from its parent's, in body axes:
/// `R^T (a_p + dw_p x t + w_p x (w_p x t))`, the parent's motion `(w_p, dw_p, a_p)` in its axes.
fn origin_acceleration(g: &mut Graph, r: &M3, t: &V3, (wp, dwp, ap): (V3, V3, V3)) -> V3 {
    let c1 = cross(g, &dwp, t);
    let wt = cross(g, &wp, t);
    let c2 = cross(g, &wp, &wt);
    let s = [0, 1, 2].map(|k| g.add_all([ap[k], c1[k], c2[k]]));
    mat_t_vec(g, r, &s)
}

/// A revolute joint's step about `axis`: `w = w_p + a qd`, `dw = dw_p + a qdd + w_p x a qd`;
/// the origin's acceleration is the parent's carried over.
fn revolute_step(
    g: &mut Graph,
    axis: &V3,
    qd: Option<Id>,
    qdd: Option<Id>,
    (wp, dwp, a_origin): (V3, V3, V3),
) -> (V3, V3, V3) {
    let wi = plus_axis(g, wp, axis, qd);
    let mut dwi = plus_axis(g, dwp, axis, qdd);
    if let Some(v) = qd {
        let c = cross_axis(g, &wp, axis, v);
        dwi = vec_add(g, &dwi, &c);
    }
    (wi, dwi, a_origin)
}

/// A prismatic joint's step along `axis`: the parent's rotation, and the origin's acceleration
/// plus `a qdd + 2 w_p x a qd`.
fn prismatic_step(
    g: &mut Graph,
    axis: &V3,
    qd: Option<Id>,
    qdd: Option<Id>,
    (wp, dwp, a_origin): (V3, V3, V3),
) -> (V3, V3, V3) {
    let mut ai = plus_axis(g, a_origin, axis, qdd);
    if let Some(v) = qd {
        let c = cross_axis(g, &wp, axis, v);
        let two = g.constant(2.0);
        let c2 = vec_scale(g, &c, two);
        ai = vec_add(g, &ai, &c2);
    }
    (wp, dwp, ai)
}

/// `x + axis s`, or `x` when `s` is zero (`None`).
fn plus_axis(g: &mut Graph, x: V3, axis: &V3, s: Option<Id>) -> V3 {
    match s {
        Some(v) => {
            let aq = vec_scale(g, axis, v);
            vec_add(g, &x, &aq)
        }
        None => x,
    }
}

/// `w x (axis qd)`.
fn cross_axis(g: &mut Graph, w: &V3, axis: &V3, qd: Id) -> V3 {
    let aq = vec_scale(g, axis, qd);
    cross(g, w, &aq)
}

/// Newton-Euler's forward step for a free flyer (a floating base, or a floating joint below
/// the root), from its parent's motion in its axes: angular velocity `w_p`, angular
/// acceleration `dw_p`, and `a_origin`, the classical acceleration of the parent's point at
/// the body origin (for a floating base, gravity's upward acceleration). With the joint's
/// velocity `(v, w)` and acceleration `(dv, dw)` in body axes (relative to the parent):
/// `w_b = w_p + w`, `dw_b = dw_p + dw + w_p x w`, and the origin's classical acceleration
/// `a_origin + dv + (w + 2 w_p) x v` (relative, then Coriolis).
fn free_step(
    g: &mut Graph,
    lm: &LocalModel,
    i: usize,
    terms: Terms<'_>,
    (wp, dwp, a_origin): (V3, V3, V3),
) -> (V3, V3, V3) {
    let col = lm.column[i];
    let zero = [g.zero(); 3];
    let part = |x: Option<&[Id]>, k: usize| {
        x.map_or(zero, |x| [x[col + k], x[col + k + 1], x[col + k + 2]])
    };
    let (v, w) = (part(terms.qd, 0), part(terms.qd, 3));
    let (dv, dw) = (part(terms.qdd, 0), part(terms.qdd, 3));
    let wb = vec_add(g, &wp, &w);
    let pw = cross(g, &wp, &w);
    let dwb = [0, 1, 2].map(|k| g.add_all([dwp[k], dw[k], pw[k]]));
    let two = g.constant(2.0);
    let wp2 = vec_scale(g, &wp, two);
    let turn = vec_add(g, &w, &wp2);
    let wv = cross(g, &turn, &v);
    let acc = [0, 1, 2].map(|k| g.add_all([a_origin[k], dv[k], wv[k]]));
    (wb, dwb, acc)
}

/// A force `f` and moment `n` (about body `c`'s origin, in its axes) expressed in the parent's
/// axes about the parent's origin.
fn transfer(g: &mut Graph, lm: &LocalModel, c: usize, f: &V3, n: &V3) -> (V3, V3) {
    let fp = mat_vec(g, &lm.rotation[c], f);
    let np = mat_vec(g, &lm.rotation[c], n);
    let tf = cross(g, &lm.translation[c], &fp);
    (fp, vec_add(g, &np, &tf))
}

/// Mass, first moment and rotational inertia of each composite body (a body and everything
/// below it), about the body origin in body axes.
pub(crate) struct Composite {
    pub mass: Vec<Id>,
    pub h: Vec<V3>,
    pub j: Vec<M3>,
}

/// Moves a body's inertia parameters `(m, h, J)` about its origin (in its axes) to the parent's
/// origin and axes: `J_O = R J R^T - m [t]^2 - [t][R h] - [R h][t]`, `h_O = R h + m t`. With
/// `m = None` the same map moves the time derivative of an inertia (whose mass part is zero).
pub(crate) fn inertia_to_parent(
    g: &mut Graph,
    lm: &LocalModel,
    c: usize,
    m: Option<Id>,
    h: &V3,
    j: &M3,
) -> (V3, M3) {
    let r = lm.rotation[c];
    let t = lm.translation[c];
    let rh = mat_vec(g, &r, h);
    let rj = mat_mul(g, &r, j);
    let rt = transpose(&r);
    let rjr = mat_mul(g, &rj, &rt);
    let th = skew_mul(g, &t, &rh);
    let ht = skew_mul(g, &rh, &t);
    let tt = skew_mul(g, &t, &t);
    // The result is symmetric: build the upper triangle and mirror it, as the two triangles
    // would be different expressions of one value.
    let mut out = [[g.zero(); 3]; 3];
    for a in 0..3 {
        for b in a..3 {
            let mtt = match m {
                Some(m) => g.mul(m, tt[a][b]),
                None => g.zero(),
            };
            out[a][b] = g.sum(
                0.0,
                [
                    (rjr[a][b], 1.0),
                    (mtt, -1.0),
                    (th[a][b], -1.0),
                    (ht[a][b], -1.0),
                ],
            );
            out[b][a] = out[a][b];
        }
    }
    let h_o = match m {
        Some(m) => {
            let mt = vec_scale(g, &t, m);
            vec_add(g, &rh, &mt)
        }
        None => rh,
    };
    (h_o, out)
}

pub(crate) fn composites(g: &mut Graph, lm: &LocalModel) -> Composite {
    let n = lm.dof();
    let children = lm.children();
    let mut mass = lm.mass.clone();
    let mut h = lm.first_moment.clone();
    let mut jm = lm.inertia.clone();
    for i in (0..n).rev() {
        for &c in &children[i] {
            let (hc, jc) = inertia_to_parent(g, lm, c, Some(mass[c]), &h[c], &jm[c]);
            jm[i] = mat_add(g, &jm[i], &jc);
            h[i] = vec_add(g, &h[i], &hc);
            mass[i] = g.add(mass[i], mass[c]);
        }
    }
    Composite { mass, h, j: jm }
}

/// The momentum-like product `I v` for inertia parameters `(m, h, J)` about the origin:
/// moment `J w + h x u`, force `w x h + m u` (with `m = None` for an inertia derivative).
pub(crate) fn inertia_times(g: &mut Graph, m: Option<Id>, h: &V3, j: &M3, v: &Spatial) -> Spatial {
    let (w, u) = v;
    let jw = mat_vec(g, j, w);
    let hu = cross(g, h, u);
    let wh = cross(g, w, h);
    let moment = vec_add(g, &jw, &hu);
    let force = match m {
        Some(m) => {
            let mu = vec_scale(g, u, m);
            vec_add(g, &wh, &mu)
        }
        None => wh,
    };
    (moment, force)
}

/// Composite-rigid-body algorithm: the upper triangle of `M(q)` (mirrored into a full matrix).
pub fn crba(g: &mut Graph, lm: &LocalModel) -> Vec<Vec<Id>> {
    let nv = lm.nv();
    let comp = composites(g, lm);
    let mut m = vec![vec![g.zero(); nv]; nv];
    for i in 0..lm.dof() {
        for (ci, s) in lm.subspace[i].iter().enumerate() {
            let col = lm.column[i] + ci;
            // Force and moment on composite body i for a unit rate of this coordinate.
            let mut force = inertia_times(g, Some(comp.mass[i]), &comp.h[i], &comp.j[i], s);
            let own = &lm.subspace[i][..=ci];
            for (k, sk) in own.iter().enumerate() {
                let e = spatial_dot(g, sk, &force);
                m[lm.column[i] + k][col] = e;
                m[col][lm.column[i] + k] = e;
            }
            m[col][col] = g.add(m[col][col], lm.armature[i]);
            let mut j = i;
            while let Some(p) = lm.parent[j] {
                force = transfer_spatial(g, lm, j, &force);
                for (k, sp) in lm.subspace[p].iter().enumerate() {
                    let e = spatial_dot(g, sp, &force);
                    m[lm.column[p] + k][col] = e;
                    m[col][lm.column[p] + k] = e;
                }
                j = p;
            }
        }
    }
    m
}

/// The mass and first moment (about the origin, in the axes of body 0) of the whole tree below
/// body 0: a floating base's composite body, the robot.
pub fn root_composite(g: &mut Graph, lm: &LocalModel) -> (Id, V3) {
    let comp = composites(g, lm);
    (comp.mass[0], comp.h[0])
}

/// For every velocity coordinate, in order: the coordinate, the body its joint moves, and the
/// momentum `I^C S` (moment about the body origin, then force, body axes) of the composite
/// body below the joint moving with a unit rate of that coordinate.
pub fn column_momenta(g: &mut Graph, lm: &LocalModel) -> Vec<(usize, usize, Spatial)> {
    let comp = composites(g, lm);
    let mut out = Vec::with_capacity(lm.nv());
    for i in 0..lm.dof() {
        for (k, s) in lm.subspace[i].iter().enumerate() {
            let m = inertia_times(g, Some(comp.mass[i]), &comp.h[i], &comp.j[i], s);
            out.push((lm.column[i] + k, i, m));
        }
    }
    out
}

/// A body's velocity and its parent's, both in the body's axes (angular, then the velocity of
/// the body origin).
#[derive(Clone, Copy, Debug)]
pub struct Velocity {
    /// The parent body's velocity, moved to this body's frame.
    pub parent: Spatial,
    /// This body's: the parent's plus `S qd`.
    pub body: Spatial,
}

/// Every body's velocity, from the root out.
pub fn velocities(g: &mut Graph, lm: &LocalModel, qd: &[Id]) -> Vec<Velocity> {
    let zero = [g.zero(); 3];
    let mut out: Vec<Velocity> = Vec::with_capacity(lm.dof());
    for i in 0..lm.dof() {
        let (wp, up) = match lm.parent[i] {
            Some(p) => out[p].body,
            None => (zero, zero),
        };
        let r = &lm.rotation[i];
        let wt = cross(g, &wp, &lm.translation[i]);
        let ut = vec_add(g, &up, &wt);
        let parent = (mat_t_vec(g, r, &wp), mat_t_vec(g, r, &ut));
        let sq = match lm.subspace[i].as_slice() {
            [s] => spatial_scale(g, s, qd[lm.column[i]]),
            _ => lm.joint_velocity(g, i, qd),
        };
        let body = spatial_add(g, &parent, &sq);
        out.push(Velocity { parent, body });
    }
    out
}

/// The kinetic energy `T = 1/2 sum_b (m u.u + 2 u.(w x h) + w.J w)` over body velocities
/// `(w, u)` (origin velocity `u`), with the first moment `h` and the inertia `J` about the body
/// origin: `O(N)` where `qd^T M qd / 2` is `O(N^2)`. Rotor inertia adds `Ia qd^2 / 2`.
pub fn kinetic_energy(g: &mut Graph, lm: &LocalModel, qd: &[Id]) -> Id {
    let vel = velocities(g, lm, qd);
    let mut terms = Vec::with_capacity(3 * lm.dof());
    for (i, v) in vel.iter().enumerate() {
        let (w, u) = v.body;
        let uu = g.dot(&u, &u);
        terms.push((g.mul(lm.mass[i], uu), 0.5));
        let wh = cross(g, &w, &lm.first_moment[i]);
        terms.push((g.dot(&u, &wh), 1.0));
        let jw = mat_vec(g, &lm.inertia[i], &w);
        terms.push((g.dot(&w, &jw), 0.5));
        if lm.step[i] != Step::Free {
            let q2 = g.powi(qd[lm.column[i]], 2);
            terms.push((g.mul(lm.armature[i], q2), 0.5));
        }
    }
    g.sum(0.0, terms)
}

/// The joint tree at the coordinates `q`, as every recursion after the derivation's own needs
/// it: the parameters, the map from the coordinates to the joints' (see `coupling`) and the
/// local model. Built anywhere, it is the same nodes (the graph is hash-consed).
pub(super) struct JointTree {
    pub params: Params,
    pub map: CoordinateMap,
    pub lm: LocalModel,
}

impl JointTree {
    pub(super) fn new(g: &mut Graph, model: &Model, q: &[Id]) -> JointTree {
        let params = Params::new(g, model);
        let map = CoordinateMap::new(model);
        let joint_q = map.positions(g, q);
        let lm = LocalModel::new(g, model, &params, &joint_q);
        JointTree { params, map, lm }
    }
}

/// The generalized momentum `p = M(q) qd = dT/dqd` in `O(N)`: Newton-Euler with the velocities
/// in place of the accelerations, at rest and without gravity (`M x` is inverse dynamics at
/// zero velocity with accelerations `x`), projected on the coordinates (see `coupling`). A
/// momentum observer's measurement; with a floating base its first six entries are the
/// robot's linear and angular momentum in base axes about the base origin.
pub fn generalized_momentum(g: &mut Graph, model: &Model, q: &[Id], qd: &[Id]) -> Vec<Id> {
    let tree = JointTree::new(g, model, q);
    let joint_qd = tree.map.rates(g, qd);
    let at_rest = Terms {
        qd: None,
        qdd: Some(&joint_qd),
        gravity: None,
    };
    let p = rnea(g, &tree.lm, at_rest);
    tree.map.project(g, &p)
}

/// The time derivative of a body's rotational inertia about its origin (in its axes, first
/// moment `h`), for body velocity `(w, u)`:
/// `dJ/dt = [w]J - J[w] + 2 (h.u) 1 - u h^T - h u^T`. (The first moment's derivative is the
/// linear momentum `w x h + m u`; the mass is constant.)
pub(crate) fn rotational_inertia_rate(g: &mut Graph, h: &V3, j: &M3, v: &Spatial) -> M3 {
    let (w, u) = v;
    let hu = g.dot(h, u);
    let wj = skew_times(g, w, j);
    let mut d = [[g.zero(); 3]; 3];
    for a in 0..3 {
        for b in a..3 {
            // ([w]J)_ab - (J[w])_ab = ([w]J)_ab + ([w]J)_ba, as J is symmetric.
            let uh = g.mul(u[a], h[b]);
            let hu_ab = g.mul(h[a], u[b]);
            let mut terms = vec![(wj[a][b], 1.0), (wj[b][a], 1.0), (uh, -1.0), (hu_ab, -1.0)];
            if a == b {
                terms.push((hu, 2.0));
            }
            d[a][b] = g.sum(0.0, terms);
            d[b][a] = d[a][b];
        }
    }
    d
}

/// The Christoffel-consistent Coriolis matrix `C(q, qd)` in `O(N^2)`, after Echeandia and
/// Wensing's recursive algorithm (the one behind Pinocchio's `computeCoriolisMatrix`), in body
/// axes.
///
/// With `S_i` the joint subspaces, `v_k` the body velocities, `I_k` the inertias and
/// `B_k = 1/2 ((v_k x*) I_k - I_k (v_k x) + (I_k v_k) xbar*)`, the matrix is
/// `C = sum_k J_k^T (I_k dJ_k/dt + B_k J_k)`. Summed over a subtree, with `I^C` the composite
/// inertia, `dI^C/dt` its time derivative and `H^C` the composite momentum, joint `j` needs
/// three force-like vectors:
/// `f1 = I^C dS_j/dt + 1/2 dI^C/dt S_j + 1/2 S_j x* H^C` (so `B^C S_j`'s symmetric half is
/// `1/2 dI^C/dt S_j` and its skew half `1/2 S_j x* H^C`), `f2 = I^C S_j` and
/// `f3 = (B^C)^T S_j = 1/2 dI^C/dt S_j - 1/2 S_j x* H^C`. Then for every `i` on the path from
/// `j` to the root, `C_ij = S_i . f1` and `C_ji = dS_i/dt . f2 + S_i . f3`, with the vectors
/// moved to body `i`'s axes.
pub fn coriolis(g: &mut Graph, lm: &LocalModel, qd: &[Id]) -> Vec<Vec<Id>> {
    let n = lm.dof();
    // Body velocities (angular, origin) and the joint subspaces' time derivatives:
    // dS/dt = v x S; for a one-column joint S x S = 0 lets the parent's velocity stand in for
    // the body's.
    let moved = velocities(g, lm, qd);
    let vel: Vec<Spatial> = moved.iter().map(|m| m.body).collect();
    let sdot: Vec<Vec<Spatial>> = (0..n)
        .map(|i| {
            let v = match lm.subspace[i].len() {
                1 => moved[i].parent,
                _ => moved[i].body,
            };
            lm.subspace[i]
                .iter()
                .map(|s| motion_cross(g, &v, s))
                .collect()
        })
        .collect();
    // Per body, both halved (with halved inertia parameters, so that no product by 1/2 is
    // left for run time): the momentum H = I v, and dI/dt's parameters: dh/dt (the linear
    // momentum) and dJ/dt = [w]J - J[w] + 2 (h.u) 1 - u h^T - h u^T.
    let mut mom: Vec<Spatial> = Vec::with_capacity(n);
    let mut dj: Vec<M3> = Vec::with_capacity(n);
    for k in 0..n {
        let (w, u) = vel[k];
        let m = g.scale(lm.mass[k], 0.5);
        let h = lm.first_moment[k].map(|x| g.scale(x, 0.5));
        let j = lm.inertia[k].map(|row| row.map(|x| g.scale(x, 0.5)));
        mom.push(inertia_times(g, Some(m), &h, &j, &(w, u)));
        dj.push(rotational_inertia_rate(g, &h, &j, &(w, u)));
    }
    // Composites, leaves first: inertia, and the halved derivative and momentum.
    let comp = composites(g, lm);
    let children = lm.children();
    let mut dh: Vec<V3> = mom.iter().map(|m| m.1).collect();
    for i in (0..n).rev() {
        for &c in &children[i] {
            let (dhc, djc) = inertia_to_parent(g, lm, c, None, &dh[c], &dj[c]);
            dj[i] = mat_add(g, &dj[i], &djc);
            dh[i] = vec_add(g, &dh[i], &dhc);
            let moved = transfer_spatial(g, lm, c, &mom[c]);
            mom[i] = spatial_add(g, &mom[i], &moved);
        }
    }
    let nv = lm.nv();
    let mut c = vec![vec![g.zero(); nv]; nv];
    for j in 0..n {
        for (cj, s) in lm.subspace[j].iter().enumerate() {
            let col = lm.column[j] + cj;
            let (m, h, jc) = (Some(comp.mass[j]), &comp.h[j], &comp.j[j]);
            let mut f2 = inertia_times(g, m, h, jc, s);
            let isd = inertia_times(g, m, h, jc, &sdot[j][cj]);
            let dis = inertia_times(g, None, &dh[j], &dj[j], s);
            let sh = cross_force(g, s, &mom[j]);
            let sym = spatial_add(g, &isd, &dis);
            let mut f1 = spatial_add(g, &sym, &sh);
            let mut f3 = spatial_sub(g, &dis, &sh);
            // The joint's own columns, then every ancestor's.
            for (ck, sk) in lm.subspace[j].iter().enumerate() {
                c[lm.column[j] + ck][col] = spatial_dot(g, sk, &f1);
            }
            let mut k = j;
            while let Some(i) = lm.parent[k] {
                f1 = transfer_spatial(g, lm, k, &f1);
                f2 = transfer_spatial(g, lm, k, &f2);
                f3 = transfer_spatial(g, lm, k, &f3);
                for (ci, si) in lm.subspace[i].iter().enumerate() {
                    let row = lm.column[i] + ci;
                    c[row][col] = spatial_dot(g, si, &f1);
                    let a = spatial_dot(g, &sdot[i][ci], &f2);
                    let b = spatial_dot(g, si, &f3);
                    c[col][row] = g.add(a, b);
                }
                k = i;
            }
        }
    }
    c
}

/// A (moment, force) pair of body `c` moved to its parent (see [`transfer`]).
pub(crate) fn transfer_spatial(g: &mut Graph, lm: &LocalModel, c: usize, f: &Spatial) -> Spatial {
    let (fp, np) = transfer(g, lm, c, &f.1, &f.0);
    (np, fp)
}

/// Solves `M x = rhs` symbolically by Featherstone's `L^T D L` factorization in reverse joint
/// order, which for a kinematic tree creates no fill-in: `M_ij` is only touched when one of `i`,
/// `j` is an ancestor of the other, so a branched robot's independent chains stay independent
/// (RBDA, tables 6.3 and 6.4). Returns `x`, straight-line expressions with `n` divisions (one per pivot, `super::ltdl`), and
/// the pivots `D`: `M` is positive definite exactly when every pivot is positive.
pub fn ltdl_solve(
    g: &mut Graph,
    parent: &[Option<usize>],
    m: &[Vec<Id>],
    rhs: &[Id],
) -> (Vec<Id>, Vec<Id>) {
    let factors = super::ltdl::Factors::new(g, parent, m);
    (factors.solve(g, rhs), factors.pivots())
}
