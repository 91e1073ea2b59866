//! The closed-form Lagrangian route: `M(q)` from body Jacobians, the energies, `G = dV/dq`,
//! and the Christoffel symbols behind Craig's `B(q)`, `C(q)`, the Coriolis matrix `C(q, qd)` and
//! the bias.
//!
//! - `M(q) = sum over bodies of m Jv^T Jv + Jw^T I Jw`, with the Jacobians in body coordinates
//!   (see [`BodyKinematics`]) and only the joints on a body's path to the root: `M_ij = 0` when
//!   joints `i` and `j` are not on one path.
//! - `V = -sum m g.c`, `G = dV/dq`; `T = qd^T M qd / 2`.
//! - Christoffel symbols `G_ijk = (dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i) / 2`; Craig's
//!   centrifugal matrix `C_ij = G_ijj`, Coriolis matrix `B_i,(jk) = 2 G_ijk` (`j < k`, pairs in
//!   the order (0,1), (0,2), ..., (1,2), ...), the Coriolis matrix
//!   `C(q, qd)_ij = sum_k G_ijk qd_k` (so that `dM/dt - 2 C(q, qd)` is skew-symmetric) and the
//!   bias `b = C(q, qd) qd`.

use super::{Clock, CoordinateMap, Coordinates};
use crate::cas::{Graph, GraphFull, Id};
use crate::kinematics::{const_v3, joint, BodyKinematics, Params, WorldKinematics};
use crate::model::Model;
use crate::spatial::{cross, mat_vec, vec_add, V3};

/// Every quantity in closed form, a candidate route wherever the velocities are the rates of the
/// positions (no floating base or floating joint): the reference for the reports.
pub(super) struct Closed {
    /// `M(q)`, in the coordinates (projected when joints are coupled).
    pub mass_matrix: Vec<Vec<Id>>,
    pub energies: Energies,
    pub christoffel: Christoffel,
    /// `tau = M qdd + b + G + F(qd)`.
    pub tau: Vec<Id>,
}

impl Closed {
    /// `M` from body Jacobians, the energies and `G = dV/dq`, the Christoffel symbols and
    /// `tau` (with the `friction` effort), each stage timed on `clock`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn derive(
        g: &mut Graph,
        model: &Model,
        params: &Params,
        map: &CoordinateMap,
        c: &Coordinates,
        world: &WorldKinematics,
        friction: &Friction,
        clock: &mut Clock,
    ) -> Result<Closed, GraphFull> {
        let body = BodyKinematics::new(g, model, params, &c.joint_q);
        g.check()?;
        clock.lap("kinematics");
        let joint_mass_matrix = mass_matrix(g, model, params, &body)?;
        let mass_matrix = map.project_matrix(g, &joint_mass_matrix, true);
        clock.lap("mass matrix");
        let grav = const_v3(g, &model.gravity);
        let energies = energies(g, params, world, &grav, &mass_matrix, &c.q, &c.qd);
        g.check()?;
        clock.lap("energies and gravity");
        let christoffel = christoffel(g, &mass_matrix, &c.q, &c.qd)?;
        clock.lap("Christoffel symbols");
        let tau = (0..c.q.len())
            .map(|i| {
                let mq = g.dot(&mass_matrix[i], &c.qdd);
                let (b, gr, f) = (
                    christoffel.bias[i],
                    energies.gravity[i],
                    friction.projected[i],
                );
                g.add_all([mq, b, gr, f])
            })
            .collect();
        Ok(Closed {
            mass_matrix,
            energies,
            christoffel,
            tau,
        })
    }
}

/// The joint friction effort `F(qd)` (zero for a floating base's and floating joints'
/// coordinates), per joint and in the coordinates.
pub(super) struct Friction {
    /// Per velocity coordinate of the joint tree.
    pub joint: Vec<Id>,
    /// Projected on the coordinates (the same without coupled joints).
    pub projected: Vec<Id>,
}

impl Friction {
    pub(super) fn new(
        g: &mut Graph,
        model: &Model,
        params: &Params,
        map: &CoordinateMap,
        joint_qd: &[Id],
    ) -> Friction {
        let base = model.base_nv();
        let mut joint = vec![g.zero(); base];
        joint.extend(joint_friction(g, model, params, &joint_qd[base..]));
        let projected = map.project(g, &joint);
        Friction { joint, projected }
    }
}

/// The pairs `(j, k)`, `j < k`, in Craig's order.
pub fn pairs(n: usize) -> Vec<(usize, usize)> {
    (0..n)
        .flat_map(|j| (j + 1..n).map(move |k| (j, k)))
        .collect()
}

/// The energies and gravity of the closed-form route.
pub(super) struct Energies {
    pub gravity: Vec<Id>,
    pub kinetic_energy: Id,
    pub potential_energy: Id,
}

/// `V = -sum m g.c`, `G = dV/dq`, `T = qd^T M qd / 2`.
pub(super) fn energies(
    g: &mut Graph,
    params: &Params,
    world: &WorldKinematics,
    grav: &V3,
    mass_matrix: &[Vec<Id>],
    q: &[Id],
    qd: &[Id],
) -> Energies {
    let pe_terms: Vec<(Id, f64)> = world
        .com
        .iter()
        .enumerate()
        .map(|(b, c)| {
            let gc = g.dot(grav, c);
            (g.mul(params.mass[b], gc), -1.0)
        })
        .collect();
    let potential_energy = g.sum(0.0, pe_terms);
    let gravity = q.iter().map(|&qi| g.diff(potential_energy, qi)).collect();
    Energies {
        gravity,
        kinetic_energy: quadratic_form(g, mass_matrix, qd),
        potential_energy,
    }
}

/// `x^T M x / 2`.
pub(super) fn quadratic_form(g: &mut Graph, m: &[Vec<Id>], x: &[Id]) -> Id {
    let mx: Vec<Id> = m.iter().map(|row| g.dot(row, x)).collect();
    let xmx = g.dot(x, &mx);
    g.scale(xmx, 0.5)
}

/// Craig's forms, the Christoffel-form Coriolis matrix and the bias, from the Christoffel
/// symbols of `M`.
pub(super) struct Christoffel {
    pub centrifugal: Vec<Vec<Id>>,
    pub coriolis_pairs: Vec<Vec<Id>>,
    pub coriolis_matrix: Vec<Vec<Id>>,
    pub bias: Vec<Id>,
}

/// The Christoffel symbols of `mass_matrix`, contracted into Craig's `C(q)` and `B(q)`, the
/// Coriolis matrix `C(q, qd)` and the bias `b = B [qd qd] + C [qd^2]`.
pub(super) fn christoffel(
    g: &mut Graph,
    mass_matrix: &[Vec<Id>],
    q: &[Id],
    qd: &[Id],
) -> Result<Christoffel, GraphFull> {
    let n = q.len();
    // dM/dq_k for the upper triangle, one memoized pass per joint.
    let upper: Vec<(usize, usize)> = (0..n).flat_map(|i| (i..n).map(move |j| (i, j))).collect();
    let roots: Vec<Id> = upper.iter().map(|&(i, j)| mass_matrix[i][j]).collect();
    let mut dm = vec![vec![vec![g.zero(); n]; n]; n]; // dm[k][i][j] = dM_ij / dq_k
    for k in 0..n {
        let d = g.diff_many(&roots, q[k]);
        for (&(i, j), &e) in upper.iter().zip(&d) {
            dm[k][i][j] = e;
            dm[k][j][i] = e;
        }
        g.check()?;
    }
    // 2 G_ijk = dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i
    let two_christoffel = |g: &mut Graph, i: usize, j: usize, k: usize| -> Id {
        g.sum(
            0.0,
            [(dm[k][i][j], 1.0), (dm[j][i][k], 1.0), (dm[i][j][k], -1.0)],
        )
    };
    let mut centrifugal = vec![vec![g.zero(); n]; n];
    let mut coriolis_pairs = vec![Vec::new(); n];
    let mut coriolis_matrix = vec![vec![g.zero(); n]; n];
    let pair_list = pairs(n);
    for i in 0..n {
        for j in 0..n {
            let c2 = two_christoffel(g, i, j, j);
            centrifugal[i][j] = g.scale(c2, 0.5);
        }
        for &(j, k) in &pair_list {
            let b = two_christoffel(g, i, j, k);
            coriolis_pairs[i].push(b);
        }
        for j in 0..n {
            let terms: Vec<(Id, f64)> = (0..n)
                .map(|k| {
                    let c2 = two_christoffel(g, i, j, k);
                    (g.mul(c2, qd[k]), 0.5)
                })
                .collect();
            coriolis_matrix[i][j] = g.sum(0.0, terms);
        }
        g.check()?;
    }
    let bias = craig_bias(g, &centrifugal, &coriolis_pairs, qd);
    g.check()?;
    Ok(Christoffel {
        centrifugal,
        coriolis_pairs,
        coriolis_matrix,
        bias,
    })
}

/// `b = B [qd qd] + C [qd^2]`: the Craig form shares work with the matrices.
fn craig_bias(g: &mut Graph, centrifugal: &[Vec<Id>], pairs_b: &[Vec<Id>], qd: &[Id]) -> Vec<Id> {
    let n = qd.len();
    let pair_list = pairs(n);
    (0..n)
        .map(|i| {
            let mut terms = Vec::new();
            for j in 0..n {
                let sq = g.powi(qd[j], 2);
                terms.push(g.mul(centrifugal[i][j], sq));
            }
            for (p, &(j, k)) in pair_list.iter().enumerate() {
                let v = g.mul(qd[j], qd[k]);
                terms.push(g.mul(pairs_b[i][p], v));
            }
            g.add_all(terms)
        })
        .collect()
}

/// The joint friction effort `F_i = damping_i qd_i + coulomb_i s(qd_i)`, with `s = sign` or,
/// for a smoothing velocity `eps > 0`, `s(v) = v / sqrt(v^2 + eps^2)`; zeros unless the model
/// includes friction.
pub(super) fn joint_friction(g: &mut Graph, model: &Model, params: &Params, qd: &[Id]) -> Vec<Id> {
    let eps = model.coulomb_smoothing;
    let mut out = Vec::with_capacity(qd.len());
    for (i, joint) in model.joints.iter().enumerate() {
        let at = out.len();
        if !model.include_friction || joint.kind.nv() != 1 {
            // A floating joint has no friction (the model refuses one that asks for it).
            out.extend((0..joint.kind.nv()).map(|_| g.zero()));
            continue;
        }
        let viscous = g.mul(params.damping[i], qd[at]);
        let s = if eps > 0.0 {
            let v2 = g.powi(qd[at], 2);
            let r = g.sum(eps * eps, [(v2, 1.0)]);
            let root = g.sqrt(r);
            g.div(qd[at], root)
        } else {
            g.sign(qd[at])
        };
        let coulomb = g.mul(params.coulomb[i], s);
        out.push(g.add(viscous, coulomb));
    }
    out
}

/// `M_jk = sum_b m_b v_bj . v_bk + u_bj^T I_b u_bk` over bodies `b` below both joints, with
/// `u` the angular and `v` the linear velocity of `b`'s centre of mass per unit joint rate, in
/// body coordinates.
pub(super) fn mass_matrix(
    g: &mut Graph,
    model: &Model,
    params: &Params,
    body: &BodyKinematics,
) -> Result<Vec<Vec<Id>>, GraphFull> {
    let n = model.dof();
    let mut terms: Vec<Vec<Vec<Id>>> = vec![vec![Vec::new(); n]; n];
    for b in 0..n {
        let path = model.path_to_root(b);
        let m = params.mass[b];
        let inertia = &params.inertia[b];
        // Per joint on the path: (u, I u, v).
        let jac: Vec<(Option<V3>, Option<V3>, V3)> = path
            .iter()
            .map(|&j| {
                let axis = body.axis[b][j].expect("path joint");
                if joint::rotates(&model.joints[j]) {
                    let off = body.offset[b][j].expect("path joint");
                    let r = vec_add(g, &params.com[b], &off);
                    let v = cross(g, &axis, &r);
                    let iu = mat_vec(g, inertia, &axis);
                    (Some(axis), Some(iu), v)
                } else {
                    (None, None, axis)
                }
            })
            .collect();
        for (x, &j) in path.iter().enumerate() {
            for (y, &k) in path.iter().enumerate().skip(x) {
                let vv = g.dot(&jac[x].2, &jac[y].2);
                let lin = g.mul(m, vv);
                terms[j][k].push(lin);
                if let (Some(u), Some(iu)) = (jac[x].0, jac[y].1) {
                    let rot = g.dot(&u, &iu);
                    terms[j][k].push(rot);
                }
            }
        }
        g.check()?;
    }
    for j in 0..n {
        terms[j][j].push(params.armature[j]);
    }
    let mut mm = vec![vec![g.zero(); n]; n];
    for j in 0..n {
        for k in j..n {
            let e = g.add_all(std::mem::take(&mut terms[j][k]));
            mm[j][k] = e;
            mm[k][j] = e;
        }
    }
    Ok(mm)
}
