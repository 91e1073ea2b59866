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

use crate::cas::{Graph, Id};
use crate::kinematics::{
    axis_rotation, const_m3, const_v3, cross, mat_mul, mat_t_vec, mat_vec, vec_add, vec_scale,
    Params, M3, V3,
};
use crate::model::{JointKind, Model};

/// Each body's placement relative to its parent and its inertia about its own origin.
#[derive(Clone, Debug)]
pub struct LocalModel {
    /// Parent from body rotation, `R_origin R_joint(q)`.
    pub rotation: Vec<M3>,
    /// Body origin in parent coordinates (including a prismatic joint's travel).
    pub translation: Vec<V3>,
    /// Joint axis in body coordinates.
    pub axis: Vec<V3>,
    pub revolute: Vec<bool>,
    pub parent: Vec<Option<usize>>,
    pub mass: Vec<Id>,
    /// First moment `m c`.
    pub first_moment: Vec<V3>,
    /// Rotational inertia about the body origin, `I_c + m (|c|^2 1 - c c^T)`.
    pub inertia: Vec<M3>,
    /// Rotor inertia of each joint: `M_ii += armature_i`, `tau_i += armature_i qdd_i`.
    pub armature: Vec<Id>,
}

impl LocalModel {
    pub fn new(g: &mut Graph, model: &Model, params: &Params, q: &[Id]) -> LocalModel {
        let n = model.dof();
        let mut lm = LocalModel {
            rotation: Vec::with_capacity(n),
            translation: Vec::with_capacity(n),
            axis: Vec::with_capacity(n),
            revolute: Vec::with_capacity(n),
            parent: Vec::with_capacity(n),
            mass: params.mass.clone(),
            first_moment: Vec::with_capacity(n),
            inertia: Vec::with_capacity(n),
            armature: params.armature.clone(),
        };
        for (i, joint) in model.joints.iter().enumerate() {
            let ro = const_m3(g, &joint.origin.rotation);
            let a = const_v3(g, &joint.axis);
            let (rot, trans) = match joint.kind {
                JointKind::Revolute | JointKind::Continuous => {
                    let rj = axis_rotation(g, &joint.axis, q[i]);
                    (mat_mul(g, &ro, &rj), params.origin[i])
                }
                JointKind::Prismatic => {
                    let ra = mat_vec(g, &ro, &a);
                    let slide = vec_scale(g, &ra, q[i]);
                    (ro, vec_add(g, &params.origin[i], &slide))
                }
            };
            lm.rotation.push(rot);
            lm.translation.push(trans);
            lm.axis.push(a);
            lm.revolute.push(joint.kind.is_revolute());
            lm.parent.push(joint.parent);
            let m = params.mass[i];
            let c = params.com[i];
            lm.first_moment.push(vec_scale(g, &c, m));
            // J = I_c + m (c.c 1 - c c^T)
            let cc = g.dot(&c, &c);
            let mut j = params.inertia[i];
            for r in 0..3 {
                for k in 0..3 {
                    let ck = g.mul(c[r], c[k]);
                    let shift = if r == k { g.sub(cc, ck) } else { g.neg(ck) };
                    let ms = g.mul(m, shift);
                    j[r][k] = g.add(params.inertia[i][r][k], ms);
                }
            }
            lm.inertia.push(j);
        }
        lm
    }

    fn dof(&self) -> usize {
        self.rotation.len()
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

/// Recursive Newton-Euler: the joint efforts for the selected terms.
pub fn rnea(g: &mut Graph, lm: &LocalModel, terms: Terms<'_>) -> Vec<Id> {
    let n = lm.dof();
    let zero = [g.zero(); 3];
    // Gravity enters as an upward acceleration of the base.
    let base_acc = match terms.gravity {
        Some(gv) => [0, 1, 2].map(|k| g.neg(gv[k])),
        None => zero,
    };
    let mut w: Vec<V3> = Vec::with_capacity(n);
    let mut dw: Vec<V3> = Vec::with_capacity(n);
    let mut acc: Vec<V3> = Vec::with_capacity(n);
    let mut force: Vec<V3> = Vec::with_capacity(n);
    let mut moment: Vec<V3> = Vec::with_capacity(n);
    for i in 0..n {
        let (wp, dwp, ap) = match lm.parent[i] {
            Some(p) => (w[p], dw[p], acc[p]),
            None => (zero, zero, base_acc),
        };
        let r = &lm.rotation[i];
        let t = &lm.translation[i];
        let a = &lm.axis[i];
        let qd = terms.qd.map(|v| v[i]);
        let qdd = terms.qdd.map(|v| v[i]);
        // Parent quantities in body axes.
        let wp_b = mat_t_vec(g, r, &wp);
        let dwp_b = mat_t_vec(g, r, &dwp);
        // Acceleration of the body origin, carried from the parent: a_p + dw_p x t + w_p x (w_p x t).
        let a_origin = {
            let c1 = cross(g, &dwp, t);
            let wt = cross(g, &wp, t);
            let c2 = cross(g, &wp, &wt);
            let s = [0, 1, 2].map(|k| g.add_all([ap[k], c1[k], c2[k]]));
            mat_t_vec(g, r, &s)
        };
        let (wi, dwi, ai) = if lm.revolute[i] {
            let wi = match qd {
                Some(v) => {
                    let aq = vec_scale(g, a, v);
                    vec_add(g, &wp_b, &aq)
                }
                None => wp_b,
            };
            let mut dwi = dwp_b;
            if let Some(v) = qdd {
                let aq = vec_scale(g, a, v);
                dwi = vec_add(g, &dwi, &aq);
            }
            if let Some(v) = qd {
                let aq = vec_scale(g, a, v);
                let c = cross(g, &wp_b, &aq);
                dwi = vec_add(g, &dwi, &c);
            }
            (wi, dwi, a_origin)
        } else {
            let mut ai = a_origin;
            if let Some(v) = qdd {
                let aq = vec_scale(g, a, v);
                ai = vec_add(g, &ai, &aq);
            }
            if let Some(v) = qd {
                let aq = vec_scale(g, a, v);
                let c = cross(g, &wp_b, &aq);
                let two = g.constant(2.0);
                let c2 = vec_scale(g, &c, two);
                ai = vec_add(g, &ai, &c2);
            }
            (wp_b, dwp_b, ai)
        };
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
        w.push(wi);
        dw.push(dwi);
        acc.push(ai);
        force.push(f);
        moment.push(nm);
    }
    // Backward: add each body's children, moved to its frame.
    let children = lm.children();
    let mut tau = vec![g.zero(); n];
    for i in (0..n).rev() {
        for &c in &children[i] {
            let (fc, nc) = transfer(g, lm, c, &force[c], &moment[c]);
            force[i] = vec_add(g, &force[i], &fc);
            moment[i] = vec_add(g, &moment[i], &nc);
        }
        tau[i] = if lm.revolute[i] {
            g.dot(&lm.axis[i], &moment[i])
        } else {
            g.dot(&lm.axis[i], &force[i])
        };
        // The rotor, spun up by the joint alone (its gyroscopic terms are neglected).
        if let Some(qdd) = terms.qdd {
            let rotor = g.mul(lm.armature[i], qdd[i]);
            tau[i] = g.add(tau[i], rotor);
        }
    }
    tau
}

/// A force `f` and moment `n` (about body `c`'s origin, in its axes) expressed in the parent's
/// axes about the parent's origin.
fn transfer(g: &mut Graph, lm: &LocalModel, c: usize, f: &V3, n: &V3) -> (V3, V3) {
    let fp = mat_vec(g, &lm.rotation[c], f);
    let np = mat_vec(g, &lm.rotation[c], n);
    let tf = cross(g, &lm.translation[c], &fp);
    (fp, vec_add(g, &np, &tf))
}

/// Composite-rigid-body algorithm: the upper triangle of `M(q)` (mirrored into a full matrix).
pub fn crba(g: &mut Graph, lm: &LocalModel) -> Vec<Vec<Id>> {
    let n = lm.dof();
    let children = lm.children();
    // Composite mass, first moment and inertia about each body origin, leaves first.
    let mut mass = lm.mass.clone();
    let mut h = lm.first_moment.clone();
    let mut jm = lm.inertia.clone();
    for i in (0..n).rev() {
        for &c in &children[i] {
            let r = lm.rotation[c];
            let t = lm.translation[c];
            // Child's composite about its origin -> about the parent origin, parent axes:
            // J_O = R J R^T - m [t]^2 - [t][R h] - [R h][t];  h_O = R h + m t.
            let rh = mat_vec(g, &r, &h[c]);
            let rj = mat_mul(g, &r, &jm[c]);
            let rt = transpose(&r);
            let rjr = mat_mul(g, &rj, &rt);
            let mt = vec_scale(g, &t, mass[c]);
            let tt = skew_mul(g, &t, &t);
            let th = skew_mul(g, &t, &rh);
            let ht = skew_mul(g, &rh, &t);
            for a in 0..3 {
                for b in 0..3 {
                    let mtt = g.mul(mass[c], tt[a][b]);
                    jm[i][a][b] = g.sum(
                        0.0,
                        [
                            (jm[i][a][b], 1.0),
                            (rjr[a][b], 1.0),
                            (mtt, -1.0),
                            (th[a][b], -1.0),
                            (ht[a][b], -1.0),
                        ],
                    );
                }
            }
            h[i] = [0, 1, 2].map(|k| g.add_all([h[i][k], rh[k], mt[k]]));
            mass[i] = g.add(mass[i], mass[c]);
        }
    }
    let mut m = vec![vec![g.zero(); n]; n];
    for i in 0..n {
        let a = lm.axis[i];
        // Force and moment on composite body i for a unit rate of joint i.
        let (mut f, mut nm) = if lm.revolute[i] {
            (cross(g, &a, &h[i]), mat_vec(g, &jm[i], &a))
        } else {
            (vec_scale(g, &a, mass[i]), cross(g, &h[i], &a))
        };
        let own = if lm.revolute[i] {
            g.dot(&a, &nm)
        } else {
            g.dot(&a, &f)
        };
        m[i][i] = g.add(own, lm.armature[i]);
        let mut j = i;
        while let Some(p) = lm.parent[j] {
            let (fp, np) = transfer(g, lm, j, &f, &nm);
            f = fp;
            nm = np;
            let e = if lm.revolute[p] {
                g.dot(&lm.axis[p], &nm)
            } else {
                g.dot(&lm.axis[p], &f)
            };
            m[p][i] = e;
            m[i][p] = e;
            j = p;
        }
    }
    m
}

fn transpose(r: &M3) -> M3 {
    [0, 1, 2].map(|a| [0, 1, 2].map(|b| r[b][a]))
}

/// `[a] [b]` for cross-product matrices: `[a][b] v = a x (b x v)`, which is `b a^T - (a.b) 1`.
fn skew_mul(g: &mut Graph, a: &V3, b: &V3) -> M3 {
    let ab = g.dot(a, b);
    let mut out = [[g.zero(); 3]; 3];
    for r in 0..3 {
        for c in 0..3 {
            let ba = g.mul(b[r], a[c]);
            out[r][c] = if r == c { g.sub(ba, ab) } else { ba };
        }
    }
    out
}

/// Solves `M x = rhs` symbolically by Featherstone's `L^T D L` factorization in reverse joint
/// order, which for a kinematic tree creates no fill-in: `M_ij` is only touched when one of `i`,
/// `j` is an ancestor of the other, so a branched robot's independent chains stay independent
/// (RBDA, tables 6.3 and 6.4). Returns `x`, straight-line expressions with `n` divisions, and
/// the pivots `D`: `M` is positive definite exactly when every pivot is positive.
pub fn ltdl_solve(
    g: &mut Graph,
    parent: &[Option<usize>],
    m: &[Vec<Id>],
    rhs: &[Id],
) -> (Vec<Id>, Vec<Id>) {
    let n = m.len();
    let mut h: Vec<Vec<Id>> = m.to_vec();
    for k in (0..n).rev() {
        let mut i = parent[k];
        while let Some(ii) = i {
            let a = g.div(h[k][ii], h[k][k]);
            let mut j = Some(ii);
            while let Some(jj) = j {
                let p = g.mul(h[k][jj], a);
                h[ii][jj] = g.sub(h[ii][jj], p);
                j = parent[jj];
            }
            h[k][ii] = a;
            i = parent[ii];
        }
    }
    let mut x = rhs.to_vec();
    for i in (0..n).rev() {
        let mut j = parent[i];
        while let Some(jj) = j {
            let p = g.mul(h[i][jj], x[i]);
            x[jj] = g.sub(x[jj], p);
            j = parent[jj];
        }
    }
    for i in 0..n {
        x[i] = g.div(x[i], h[i][i]);
    }
    for i in 0..n {
        let mut j = parent[i];
        while let Some(jj) = j {
            let p = g.mul(h[i][jj], x[jj]);
            x[i] = g.sub(x[i], p);
            j = parent[jj];
        }
    }
    let pivots = (0..n).map(|i| h[i][i]).collect();
    (x, pivots)
}
