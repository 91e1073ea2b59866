//! The derivatives of inverse dynamics, `d tau / d q` and `d tau / d qd`, by a customized
//! recursive algorithm after Carpentier and Mansard ("Analytical derivatives of rigid body
//! dynamics algorithms", RSS 2018: Pinocchio's `computeRNEADerivatives`), run on the CAS in body
//! axes like the rest of [`newton_euler`](super::newton_euler), so that the robot's structural
//! zeros and ones fold away and the result is straight-line code.
//!
//! With spatial body velocities `v_k`, accelerations `a_k` (gravity as an upward acceleration
//! of the base), inertias `I_k` about the body origins, forces `f_k = I_k a_k + v_k x* I_k v_k`,
//! and per subtree `i` the composite inertia `I^C_i`, its time derivative `dI^C_i/dt`, the
//! momentum `H^C_i` and the force `f^C_i` (so `tau_i = S_i . f^C_i`): moving joint `j` rotates
//! (or slides) its subtree, which in the subtree's own axes only re-expresses the parent's
//! velocity `v_p` and acceleration `a_p`. With `u2_j = v_p x S_j` (= `dS_j/dt`) and
//! `u1_j = a_p x S_j + v_p x u2_j`:
//!
//! - for `i` on the path from `j` to the root, `d tau_i / d q_j = S_i . g_j` and
//!   `d tau_i / d qd_j = S_i . c_j`, carried to body `i`'s axes, with
//!   `g_j = S_j x* f^C_j + I^C_j u1_j + dI^C_j/dt u2_j + u2_j x* H^C_j` and
//!   `c_j = dI^C_j/dt S_j + S_j x* H^C_j + I^C_j w_j`, `w_j = (v_p + v_j) x S_j` (`= 2 u2_j`
//!   for a joint of one column);
//! - for `i` below `j`, `d tau_i / d q_j = F_i . u1_j + G_i . u2_j` and
//!   `d tau_i / d qd_j = G_i . S_j + F_i . w_j`, with `F_i = I^C_i S_i` and
//!   `G_i = dI^C_i/dt S_i - S_i x* H^C_i` carried up to body `j`'s axes.
//!
//! A joint of several columns (a floating base's free flyer, `S` constant in body axes, its
//! position perturbed in the tangent space as Pinocchio's `integrate` does) follows the same
//! formulas column by column; between two columns of one joint, `d tau / d q` takes
//! `g_j - S_j x* f^C_j` (the joint's own axes move with it). With gravity, a free flyer's
//! position columns give zero and its rotation columns turn gravity in base axes.
//!
//! So `d tau / d qd = 2 C(q, qd)` (Echeandia and Wensing's recursion computes the same vectors
//! halved), plus the friction's `dF/dqd` on the diagonal; rotor inertia does not depend on `q`
//! or `qd`. The algorithm is `O(N d)` in the depth `d`: four spatial vectors carried up per
//! pair of a joint and its ancestor.

use super::newton_euler::{
    composites, inertia_times, inertia_to_parent, rotational_inertia_rate, transfer_spatial,
    velocities, Composite, LocalModel,
};
use crate::cas::{Graph, Id};
use crate::spatial::{
    cross, cross_force, mat_add, mat_t_vec, motion_cross, spatial_add, spatial_dot, spatial_scale,
    spatial_sub, vec_add, Spatial, M3, V3,
};

/// `d tau / d q` and `d tau / d qd`, element `[i][j]` = `d tau_i / d x_j`.
#[derive(Clone, Debug)]
pub struct InverseDynamicsDerivatives {
    pub dq: Vec<Vec<Id>>,
    pub dqd: Vec<Vec<Id>>,
}

/// A motion (velocity or acceleration) of body `i`'s parent, in the parent's axes, expressed
/// in body `i`'s axes: `(R^T w, R^T (u + w x t))`.
fn motion_to_child(g: &mut Graph, lm: &LocalModel, i: usize, m: &Spatial) -> Spatial {
    let r = &lm.rotation[i];
    let wt = cross(g, &m.0, &lm.translation[i]);
    let ut = vec_add(g, &m.1, &wt);
    (mat_t_vec(g, r, &m.0), mat_t_vec(g, r, &ut))
}

/// Per body, what the derivatives need from the forward pass and the composites.
struct Pass {
    /// Per column of each body's joint, `dS/dt = v_p x S`.
    u2: Vec<Vec<Spatial>>,
    /// Per column of each body's joint, `a_p x S + v_p x u2`.
    u1: Vec<Vec<Spatial>>,
    /// Per column of each body's joint, `(v_p + v) x S` with the body's own velocity `v`: how
    /// the subtree's accelerations change with the column's rate. It is `2 u2` for a joint of
    /// one column (`S x S = 0`), and differs for a free flyer, whose columns do not commute.
    w: Vec<Vec<Spatial>>,
    /// Composite force `f^C` and momentum `H^C`.
    force: Vec<Spatial>,
    momentum: Vec<Spatial>,
    /// Composite `dI^C/dt` as inertia parameters (first moment rate, rotational rate).
    rate_h: Vec<V3>,
    rate_j: Vec<M3>,
}

/// The forward pass (velocities, accelerations, body forces, momenta and inertia rates) and
/// the backward accumulation over subtrees. `qd` and `qdd` are velocity coordinates.
fn pass(g: &mut Graph, lm: &LocalModel, gravity: V3, qd: &[Id], qdd: &[Id]) -> Pass {
    let n = lm.bodies();
    let zero = [g.zero(); 3];
    let base_acc = (zero, gravity.map(|x| g.neg(x)));
    let vel = velocities(g, lm, qd);
    let mut acc: Vec<Spatial> = Vec::with_capacity(n);
    let mut out = Pass {
        u2: Vec::with_capacity(n),
        u1: Vec::with_capacity(n),
        w: Vec::with_capacity(n),
        force: Vec::with_capacity(n),
        momentum: Vec::with_capacity(n),
        rate_h: Vec::with_capacity(n),
        rate_j: Vec::with_capacity(n),
    };
    for i in 0..n {
        let vp = vel[i].parent;
        let ap = match lm.parent[i] {
            Some(p) => motion_to_child(g, lm, i, &acc[p]),
            None => motion_to_child(g, lm, i, &base_acc),
        };
        let mut a = ap;
        let v = vel[i].body;
        let one_column = lm.subspace[i].len() == 1;
        let (mut u1s, mut u2s, mut ws) = (Vec::new(), Vec::new(), Vec::new());
        for (k, s) in lm.subspace[i].iter().enumerate() {
            let col = lm.column[i] + k;
            let u2 = motion_cross(g, &vp, s);
            let aps = motion_cross(g, &ap, s);
            let vu = motion_cross(g, &vp, &u2);
            u1s.push(spatial_add(g, &aps, &vu));
            let sa = spatial_scale(g, s, qdd[col]);
            let ua = spatial_scale(g, &u2, qd[col]);
            let a_rel = spatial_add(g, &sa, &ua);
            a = spatial_add(g, &a, &a_rel);
            ws.push(if one_column {
                spatial_scale_const(g, &u2, 2.0)
            } else {
                let vs = motion_cross(g, &v, s);
                spatial_add(g, &u2, &vs)
            });
            u2s.push(u2);
        }
        out.u1.push(u1s);
        out.u2.push(u2s);
        out.w.push(ws);
        let (m, h, j) = (lm.mass[i], &lm.first_moment[i], &lm.inertia[i]);
        let mom = inertia_times(g, Some(m), h, j, &v);
        let ia = inertia_times(g, Some(m), h, j, &a);
        let vh = cross_force(g, &v, &mom);
        out.force.push(spatial_add(g, &ia, &vh));
        out.rate_j.push(rotational_inertia_rate(g, h, j, &v));
        out.rate_h.push(mom.1);
        out.momentum.push(mom);
        acc.push(a);
    }
    for c in (0..n).rev() {
        if let Some(p) = lm.parent[c] {
            let f = transfer_spatial(g, lm, c, &out.force[c]);
            out.force[p] = spatial_add(g, &out.force[p], &f);
            let h = transfer_spatial(g, lm, c, &out.momentum[c]);
            out.momentum[p] = spatial_add(g, &out.momentum[p], &h);
            let (rh, rj) = inertia_to_parent(g, lm, c, None, &out.rate_h[c], &out.rate_j[c]);
            out.rate_h[p] = vec_add(g, &out.rate_h[p], &rh);
            out.rate_j[p] = mat_add(g, &out.rate_j[p], &rj);
        }
    }
    out
}

/// The four vectors that moving one velocity column `S` of body `j`'s joint contributes, in
/// body `j`'s axes (module documentation).
struct ColumnVectors {
    /// `I^C S`.
    f: Spatial,
    /// `dI^C/dt S - S x* H^C`.
    g: Spatial,
    /// `c = dI^C/dt S + S x* H^C + I^C w`: `d tau / d qd` against the ancestors' columns and
    /// the joint's own.
    c: Spatial,
    /// `I^C u1 + dI^C/dt u2 + u2 x* H^C`: `d tau / d q` against the joint's own columns (the
    /// subtree moves with the joint's own axes).
    own: Spatial,
    /// `S x* f^C + own`: `d tau / d q` against the ancestors' columns (which see the subtree's
    /// force turn).
    q: Spatial,
}

fn column_vectors(
    g: &mut Graph,
    comp: &Composite,
    p: &Pass,
    j: usize,
    k: usize,
    s: &Spatial,
) -> ColumnVectors {
    let (m, h, jc) = (Some(comp.mass[j]), &comp.h[j], &comp.j[j]);
    let (rh, rj) = (&p.rate_h[j], &p.rate_j[j]);
    let (u1, u2) = (&p.u1[j][k], &p.u2[j][k]);
    let f = inertia_times(g, m, h, jc, s);
    let rate_s = inertia_times(g, None, rh, rj, s);
    let sh = cross_force(g, s, &p.momentum[j]);
    let gv = spatial_sub(g, &rate_s, &sh);
    let iw = inertia_times(g, m, h, jc, &p.w[j][k]);
    let c0 = spatial_add(g, &rate_s, &sh);
    let c = spatial_add(g, &c0, &iw);
    let iu1 = inertia_times(g, m, h, jc, u1);
    let ru2 = inertia_times(g, None, rh, rj, u2);
    let u2h = cross_force(g, u2, &p.momentum[j]);
    let own0 = spatial_add(g, &iu1, &ru2);
    let own = spatial_add(g, &own0, &u2h);
    let sf = cross_force(g, s, &p.force[j]);
    let q = spatial_add(g, &sf, &own);
    ColumnVectors {
        f,
        g: gv,
        c,
        own,
        q,
    }
}

/// `d tau / d q` and `d tau / d qd` of `tau = M qdd + b + G + F(qd)` by the recursive
/// algorithm (module documentation), with gravity in root axes and the joint friction `F`
/// (zeros without friction), over velocity coordinates: a floating base's position is
/// perturbed in its tangent space (a displacement and a rotation in base axes, as Pinocchio's
/// `integrate`). `qdd` may be any expressions (forward dynamics' accelerations, for the
/// derivatives of forward dynamics).
pub fn inverse_dynamics_derivatives(
    g: &mut Graph,
    lm: &LocalModel,
    gravity: V3,
    qd: &[Id],
    qdd: &[Id],
    friction: &[Id],
) -> InverseDynamicsDerivatives {
    let mut r = rigid_derivatives(g, lm, gravity, qd, qdd);
    add_friction_rates(g, &mut r.dqd, friction, qd);
    r
}

/// Adds the joint friction's `dF_x / dqd_x` to the diagonal of `d tau / d qd`.
pub fn add_friction_rates(g: &mut Graph, dqd: &mut [Vec<Id>], friction: &[Id], qd: &[Id]) {
    for x in 0..dqd.len() {
        // No friction, nothing to differentiate (and `qd[x]` need not be a symbol then).
        let df = match g.as_const(friction[x]) {
            Some(_) => g.zero(),
            None => g.diff(friction[x], qd[x]),
        };
        dqd[x][x] = g.add(dqd[x][x], df);
    }
}

/// [`inverse_dynamics_derivatives`] of the rigid bodies alone (no friction): `d tau / d qd`
/// is then `d b / d qd`, and since the bias `b` is quadratic in the rates,
/// `b = 1/2 (d b / d qd) qd`.
pub fn rigid_derivatives(
    g: &mut Graph,
    lm: &LocalModel,
    gravity: V3,
    qd: &[Id],
    qdd: &[Id],
) -> InverseDynamicsDerivatives {
    let n = qd.len();
    let p = pass(g, lm, gravity, qd, qdd);
    let comp = composites(g, lm);
    let mut dq = vec![vec![g.zero(); n]; n];
    let mut dqd = vec![vec![g.zero(); n]; n];
    for j in 0..lm.bodies() {
        for (k, s) in lm.subspace[j].iter().enumerate() {
            let x = lm.column[j] + k;
            let mut v = column_vectors(g, &comp, &p, j, k, s);
            // The joint's own columns, this one included.
            for (kk, sk) in lm.subspace[j].iter().enumerate() {
                let y = lm.column[j] + kk;
                dq[y][x] = spatial_dot(g, sk, &v.own);
                dqd[y][x] = spatial_dot(g, sk, &v.c);
            }
            // The ancestors' columns, carried up one body at a time.
            let mut b = j;
            while let Some(i) = lm.parent[b] {
                for w in [&mut v.q, &mut v.c, &mut v.f, &mut v.g] {
                    *w = transfer_spatial(g, lm, b, w);
                }
                for (kk, si) in lm.subspace[i].iter().enumerate() {
                    let y = lm.column[i] + kk;
                    dq[y][x] = spatial_dot(g, si, &v.q);
                    dqd[y][x] = spatial_dot(g, si, &v.c);
                    let a = spatial_dot(g, &v.f, &p.u1[i][kk]);
                    let bb = spatial_dot(g, &v.g, &p.u2[i][kk]);
                    dq[x][y] = g.add(a, bb);
                    let a = spatial_dot(g, &v.g, si);
                    let bb = spatial_dot(g, &v.f, &p.w[i][kk]);
                    dqd[x][y] = g.add(a, bb);
                }
                b = i;
            }
        }
    }
    InverseDynamicsDerivatives { dq, dqd }
}

/// The gravity efforts `G(q)` over the joint tree's velocity columns, from the composite
/// inertias: gravity as an upward acceleration `a_g` of the base, carried to each body (a
/// rotation only), gives `G_i = S_i . (I^C_i a_g)`. The same composites as the recursion's, so
/// this costs one rotated vector and one product per body.
pub fn gravity_efforts(g: &mut Graph, lm: &LocalModel, gravity: V3) -> Vec<Id> {
    let base = ([g.zero(); 3], gravity.map(|x| g.neg(x)));
    let comp = composites(g, lm);
    let mut acc: Vec<Spatial> = Vec::with_capacity(lm.bodies());
    let mut out = vec![g.zero(); lm.nv()];
    for i in 0..lm.bodies() {
        let a = match lm.parent[i] {
            Some(p) => motion_to_child(g, lm, i, &acc[p]),
            None => motion_to_child(g, lm, i, &base),
        };
        let f = inertia_times(g, Some(comp.mass[i]), &comp.h[i], &comp.j[i], &a);
        for (k, s) in lm.subspace[i].iter().enumerate() {
            out[lm.column[i] + k] = spatial_dot(g, s, &f);
        }
        acc.push(a);
    }
    out
}

/// The bias `b(q, qd) = 1/2 (d b / d qd) qd` from the rigid bodies' `d tau / d qd` (`rates`,
/// [`rigid_derivatives`]): `b` is quadratic in the rates (Euler's theorem on homogeneous
/// functions), so no Newton-Euler pass at zero acceleration is needed for it.
pub fn bias_from_rates(g: &mut Graph, rates: &[Vec<Id>], qd: &[Id]) -> Vec<Id> {
    rates
        .iter()
        .map(|row| {
            let terms: Vec<(Id, f64)> = row
                .iter()
                .zip(qd)
                .map(|(&c, &v)| (g.mul(c, v), 0.5))
                .collect();
            g.sum(0.0, terms)
        })
        .collect()
}

/// `k s` for a number `k`.
fn spatial_scale_const(g: &mut Graph, s: &Spatial, k: f64) -> Spatial {
    (s.0.map(|x| g.scale(x, k)), s.1.map(|x| g.scale(x, k)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cas::Program;
    use crate::dynamics::Derivation;
    use crate::kinematics::const_v3;
    use crate::kinematics::Params;

    /// The recursion equals symbolic differentiation of the inverse dynamics, at a state.
    fn check(builder: crate::Builder) {
        let model = builder.model().unwrap();
        let mut d = Derivation::new(&model);
        let n = d.dof;
        let g = &mut d.graph;
        let params = Params::new(g, &model);
        let lm = LocalModel::new(g, &model, &params, &d.q);
        let grav = const_v3(g, &model.gravity);
        let r = inverse_dynamics_derivatives(g, &lm, grav, &d.qd, &d.qdd, &d.friction);
        let tau = d.fast.tau.1.clone();
        let mut want = Vec::new();
        let mut got = Vec::new();
        for j in 0..n {
            let dq = g.diff_many(&tau, d.q[j]);
            let dqd = g.diff_many(&tau, d.qd[j]);
            for i in 0..n {
                want.extend([dq[i], dqd[i]]);
                got.extend([r.dq[i][j], r.dqd[i][j]]);
            }
        }
        let value = |s: &crate::cas::Symbol| {
            let k: f64 = s.name.bytes().map(f64::from).sum();
            Some((k * 0.37).sin())
        };
        let w = Program::new(g, &want).eval(value).unwrap();
        let o = Program::new(g, &got).eval(value).unwrap();
        for (k, (a, b)) in w.iter().zip(&o).enumerate() {
            assert!((a - b).abs() < 1e-9 * (1.0 + a.abs()), "{k}: {a} vs {b}");
        }
    }

    /// What forward dynamics' derivatives take from the recursion instead of a second
    /// Newton-Euler pass: `G` from the composites and `b = 1/2 (d b / d qd) qd`, equal to the
    /// fast forms' gravity and bias at a state.
    fn check_gravity_and_bias(builder: crate::Builder) {
        let model = builder.model().unwrap();
        let mut d = Derivation::new(&model);
        let g = &mut d.graph;
        let params = Params::new(g, &model);
        let lm = LocalModel::new(g, &model, &params, &d.q);
        let grav = const_v3(g, &model.gravity);
        let r = rigid_derivatives(g, &lm, grav, &d.qd, &d.qdd);
        let gravity = gravity_efforts(g, &lm, grav);
        let bias = bias_from_rates(g, &r.dqd, &d.qd);
        let want: Vec<Id> = d
            .fast
            .gravity
            .1
            .iter()
            .chain(&d.fast.bias.1)
            .copied()
            .collect();
        let got: Vec<Id> = gravity.iter().chain(&bias).copied().collect();
        let value = |s: &crate::cas::Symbol| {
            let k: f64 = s.name.bytes().map(f64::from).sum();
            Some((k * 0.29).cos())
        };
        let w = Program::new(g, &want).eval(value).unwrap();
        let o = Program::new(g, &got).eval(value).unwrap();
        assert!(
            w.iter().any(|x| x.abs() > 1e-3),
            "a state with gravity and bias"
        );
        for (k, (a, b)) in w.iter().zip(&o).enumerate() {
            assert!((a - b).abs() < 1e-9 * (1.0 + a.abs()), "{k}: {a} vs {b}");
        }
    }

    #[test]
    fn gravity_and_bias_from_the_recursion() {
        let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/");
        check_gravity_and_bias(crate::Builder::new(format!("{root}robots/panda.urdf")));
        check_gravity_and_bias(
            crate::Builder::new(format!("{root}robots/floating/anymal.urdf")).floating_base(),
        );
    }

    #[test]
    fn equals_differentiated_inverse_dynamics() {
        let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/");
        check(crate::Builder::new(format!("{root}robots/panda.urdf")));
        check(
            crate::Builder::new(format!("{root}fixtures/joint_effects.urdf"))
                .inertia_from_collision(1000.0)
                .armature([("shoulder", 0.2), ("elbow", 0.05)])
                .friction(true)
                .coulomb_smoothing(0.05),
        );
    }
}
