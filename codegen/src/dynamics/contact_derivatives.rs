//! Contact and impulse dynamics with their derivatives: the partial derivatives generated code
//! needs, as straight-line expressions, and the catalogue entries that solve the contact
//! problem's KKT system at run time (`eomgen_runtime::ContactKkt`).
//!
//! Contact forward dynamics solves `M a + h - J^T f = tau`, `J a + drift = 0`. Differentiating
//! in `x` (`q` in its tangent space, or `v`) at the solution gives the KKT system
//! `[M -J^T; J 0] [da; df] = -[d/dx (ID(q, v, a) - J^T f); d/dx (J a + drift)]`, the
//! derivatives taken at fixed `a` and `f`. `d ID / dx` is `inverse_dynamics_derivatives`;
//! the rest, `d(-J^T f)/dq`, `d(J a + drift)/dq` and `d drift/dv`, is generated here
//! (`contact_dynamics_partials`) by differentiating the contact Jacobian and drift along each
//! tangent direction of `q` ([`Graph::derivative_along_many`]), with the contact forces as
//! symbols ([`Graph::force`]). They involve only the contacts' chains, so they are small.
//! With a floating base they are taken in the base's axes (`J^T f = J_b^T (R^T f)`,
//! `J a + drift = R (J_b a + drift_b)`, `centroidal::contacts_in_base_axes`), where the
//! base's rotation is one factor instead of a part of every entry of `J`.
//!
//! Impulse dynamics solves `M (v+ - v) - J^T p = 0`, `J (v+ + e v) = 0`; its `q`-partials
//! (`impulse_dynamics_partials`) are `d(M x)/dq` (Newton-Euler's derivatives at zero velocity
//! and gravity, `x = v+ - v`) plus `d(-J^T p)/dq`, and `d(J w)/dq` (`w = v+ + e v`).

use super::catalogue::{Evaluation, Input, Quantity, Shape};
use super::centroidal::{quantity, turn_rows};
use super::newton_euler::JointTree;
use super::rnea_derivatives::inverse_dynamics_derivatives;
use super::{flat, Derivation};
use crate::cas::{Graph, Id};
use crate::kinematics::{joint, M3};
use crate::model::Model;

/// The partial derivatives of the contact and impulse problems, as stacked matrices (rows
/// below, N columns: the velocity coordinates).
#[derive(Clone, Debug)]
pub struct ContactPartials {
    /// `d(-J^T f)/dq` (N rows), `d(J qdd + drift)/dq` (K rows), `d drift/dqd` (K rows), with
    /// `qdd` and `f` (the `force` symbols) held fixed.
    pub contact: Vec<Vec<Id>>,
    /// `d(M qdd - J^T f)/dq` (N rows), `d(J qd)/dq` (K rows), with `qdd`, `qd`, `f` fixed.
    pub impulse: Vec<Vec<Id>>,
}

/// Per velocity coordinate, the rate of each position symbol when `q` moves along it as
/// Pinocchio's `integrate` moves it: a floating base's translation in base axes (`dp = R e_k`)
/// and rotation in base axes (`d quat = quat (x) (e_k / 2, 0)`), then the joints' coordinates.
fn tangent_directions(g: &mut Graph, model: &Model, q: &[Id], nv: usize) -> Vec<Vec<(Id, Id)>> {
    let mut out = Vec::with_capacity(nv);
    let (base_nq, base_nv) = if model.is_floating() { (7, 6) } else { (0, 0) };
    if model.is_floating() {
        let r = joint::free_flyer_placement(g, &q[..7]).rotation;
        for k in 0..3 {
            out.push((0..3).map(|i| (q[i], r[i][k])).collect());
        }
        let v = [q[3], q[4], q[5]];
        let w = q[6];
        for k in 0..3 {
            // vector part (w e_k + v x e_k) / 2, scalar part -v_k / 2
            let mut rates: Vec<(Id, Id)> = (0..3)
                .map(|i| {
                    let (a, b) = ((i + 1) % 3, (i + 2) % 3);
                    let cross = if b == k {
                        g.scale(v[a], 0.5)
                    } else if a == k {
                        g.scale(v[b], -0.5)
                    } else {
                        g.zero()
                    };
                    let own = if i == k { g.scale(w, 0.5) } else { g.zero() };
                    (v[i], g.add(cross, own))
                })
                .collect();
            rates.push((w, g.scale(v[k], -0.5)));
            out.push(rates);
        }
    }
    for j in 0..nv - base_nv {
        out.push(vec![(q[base_nq + j], g.one())]);
    }
    out
}

/// `d(M(q) x)/dq` for the symbols `x` (here `qdd`): Newton-Euler's derivatives at zero
/// velocity and gravity, projected onto the coordinates when joints are coupled.
fn mass_times_derivative(g: &mut Graph, model: &Model, q: &[Id], x: &[Id]) -> Vec<Vec<Id>> {
    let JointTree { map, lm, .. } = JointTree::new(g, model, q);
    let joint_x = map.rates(g, x);
    let zero3 = [g.zero(); 3];
    let zeros = vec![g.zero(); joint_x.len()];
    let r = inverse_dynamics_derivatives(g, &lm, zero3, &zeros, &joint_x, &zeros);
    if map.is_coupled() {
        map.project_matrix(g, &r.dq, false)
    } else {
        r.dq
    }
}

/// `-J^T f` (one entry per column of `J`).
fn minus_transpose_times(g: &mut Graph, jac: &[Vec<Id>], f: &[Id]) -> Vec<Id> {
    let n = jac.first().map_or(0, Vec::len);
    (0..n)
        .map(|c| {
            let column: Vec<Id> = jac.iter().map(|row| row[c]).collect();
            let jf = g.dot(&column, f);
            g.neg(jf)
        })
        .collect()
}

/// `J a + drift` and `J v` for the accelerations and velocities `(a, v)`.
fn contact_rows(
    g: &mut Graph,
    jac: &[Vec<Id>],
    drift: &[Id],
    (a, v): (&[Id], &[Id]),
) -> (Vec<Id>, Vec<Id>) {
    let acc = jac
        .iter()
        .zip(drift)
        .map(|(row, &dr)| {
            let ja = g.dot(row, a);
            g.add(ja, dr)
        })
        .collect();
    let vel = jac.iter().map(|row| g.dot(row, v)).collect();
    (acc, vel)
}

/// Derives the partials for `model`'s contacts in `d`'s graph.
pub fn derive(d: &mut Derivation, model: &Model) -> ContactPartials {
    let n = d.dof;
    let (jac, drift, r) = super::centroidal::contacts_in_solving_axes(model, d);
    let (q, qd, qdd) = (d.q.clone(), d.qd.clone(), d.qdd.clone());
    // In a floating base's axes: `J_c^T f = J_b^T (R^T f)`, `J_c a + drift = R (J_b a +
    // drift_b)`, `J_c v = R J_b v`. Differentiated, the base's rotation is one factor where
    // each entry of `J_c` carried it (a third of anymal's partials).
    let g = &mut d.graph;
    let rt: Option<M3> = r.map(|r| core::array::from_fn(|i| core::array::from_fn(|j| r[j][i])));
    let f: Vec<Id> = (0..drift.len()).map(|i| g.force(i)).collect();
    let fb = turn_rows(g, rt.as_ref(), &f);
    let (acc, vel) = contact_rows(g, &jac, &drift, (&qdd, &qd));
    let mut roots = minus_transpose_times(g, &jac, &fb);
    roots.extend(turn_rows(g, r.as_ref(), &acc));
    roots.extend(turn_rows(g, r.as_ref(), &vel));
    let drift = turn_rows(g, r.as_ref(), &drift);
    let k = drift.len();
    let zero = g.zero();
    let mut contact = vec![vec![zero; n]; n + 2 * k];
    let mut impulse = vec![vec![zero; n]; n + k];
    for (c, direction) in tangent_directions(g, model, &q, n).iter().enumerate() {
        let dr = g.derivative_along_many(&roots, direction);
        for i in 0..n + k {
            contact[i][c] = dr[i];
        }
        for r in 0..k {
            impulse[n + r][c] = dr[n + k + r];
        }
    }
    for (c, &v) in qd.iter().enumerate() {
        let dr = g.diff_many(&drift, v);
        for r in 0..k {
            contact[n + k + r][c] = dr[r];
        }
    }
    let mx = mass_times_derivative(g, model, &q, &qdd);
    for i in 0..n {
        for c in 0..n {
            impulse[i][c] = g.add(mx[i][c], contact[i][c]);
        }
    }
    ContactPartials { contact, impulse }
}

const PARTIAL_INPUTS: &[Input] = &[Input::Q, Input::Qd, Input::Qdd, Input::Forces];

/// `impulse_dynamics` (robots with contacts), in the catalogue after the contact quantities.
pub(super) fn impulse_dynamics(model: &Model, d: &mut Derivation) -> Option<Quantity> {
    let (n, k) = (d.dof, d.centroidal.contact_drift.len());
    if k == 0 {
        return None;
    }
    let max_ops = super::CONTACT_FORWARD_DYNAMICS_FLAT_MAX_OPS;
    let (route, eval) = impulse_dynamics_route(model, d, max_ops);
    Some(quantity(
        "impulse_dynamics",
        &[Input::Q, Input::Qd],
        Shape::Vector(n + k),
        &[
            "Impulse dynamics: the velocity after an impact at the contacts and the contact impulses",
            "(on the robot, world axes) of `M (v_after - qd) = J_c^T p`, `J_c v_after = -e J_c qd`,",
            "from the velocity before `qd` and the restitution `e` (0: the contacts stop).",
            "",
            "NaN in every entry when M(q) is not positive definite or J_c is rank-deficient;",
            "`try_impulse_dynamics` says why.",
        ],
        route,
        eval,
    ))
}

/// `impulse_dynamics`'s route and evaluation: one straight-line program at restitution zero
/// (`contact_flat::impulse_dynamics`, scaled by `1 + e` at run time) up to `flat_max_ops`
/// operations, else solved at run time.
pub(super) fn impulse_dynamics_route(
    model: &Model,
    d: &mut Derivation,
    flat_max_ops: usize,
) -> (&'static str, Evaluation) {
    let run_time = (
        "M from `mass_matrix`, J_c from `contact_jacobian`, then the unrolled L^T D L of M, a Cholesky factorization of J_c M^-1 J_c^T and one more substitution (eomgen_runtime::impulse::solve_factored_active_by, with the first half of the substitution unrolled too)",
        Evaluation::ImpulseDynamics,
    );
    if flat_max_ops == 0 {
        return run_time;
    }
    let (j, _, axes) = super::centroidal::contacts_in_solving_axes(model, d);
    let flat = super::contact_flat::impulse_dynamics(
        &mut d.graph,
        &d.coordinate_parents,
        &d.fast.mass_matrix.1,
        &j,
        &d.qd,
        axes.as_ref(),
    );
    if flat.fits(&d.graph, flat_max_ops) {
        (
            "one straight-line program at restitution zero, scaled by 1 + e: M as in `mass_matrix`, J_c (in the floating base's axes, the impulses turned into the world's at the end), the unrolled L^T D L of M, W = L^-T J_c^T, J_c M^-1 J_c^T = W^T D^-1 W and its L^T D L, without the zeros of J_c",
            Evaluation::ImpulseDynamicsFlat {
                outputs: flat.outputs,
                pivots: flat.pivots,
            },
        )
    } else {
        run_time
    }
}

/// The derivative entries of robots with contacts ([`Derivation::add_derivatives`]).
pub(super) fn quantities(d: &Derivation, p: &ContactPartials) -> Vec<Quantity> {
    let (n, k) = (d.dof, d.centroidal.contact_drift.len());
    if k == 0 {
        return Vec::new();
    }
    let tangent = "q perturbed in its tangent space, as `integrate`.";
    vec![
        quantity(
            "contact_dynamics_partials",
            PARTIAL_INPUTS,
            Shape::Matrix(n + 2 * k, n),
            &[
                "What `contact_forward_dynamics_derivatives` adds to `inverse_dynamics_derivatives`, stacked",
                "(N + 2K) x N: d(-J_c^T forces)/dq (N rows), d(J_c qdd + Jdot_c qd)/dq (K rows) and",
                "d(Jdot_c qd)/dqd (K rows), at fixed `qdd` and `forces` (world axes), with",
                tangent,
            ],
            "the contact Jacobian and drift differentiated along each tangent direction",
            Evaluation::Exprs(flat(&p.contact)),
        ),
        quantity(
            "contact_forward_dynamics_derivatives",
            &[Input::Q, Input::Qd, Input::Tau],
            Shape::Matrices(3, n + k, n),
            &[
                "The derivatives of `contact_forward_dynamics` (accelerations `a` and forces `f`) in `q`",
                "(tangent space, as `integrate`), `qd` and `tau`: Pinocchio's",
                "`computeConstraintDynamicsDerivatives`, forces on the robot in world axes.",
                "",
                "NaN in every entry when M(q) is not positive definite or J_c is rank-deficient;",
                "`try_contact_forward_dynamics_derivatives` says why.",
            ],
            "the accelerations and forces by `eomgen_runtime::ContactKkt`, `inverse_dynamics_derivatives` there plus `contact_dynamics_partials`, then the KKT system solved for every column",
            Evaluation::ContactDynamicsDerivatives {
                h: d.fast.bias_gravity_friction.clone(),
            },
        ),
        quantity(
            "impulse_dynamics_partials",
            PARTIAL_INPUTS,
            Shape::Matrix(n + k, n),
            &[
                "What `impulse_dynamics_derivatives` differentiates, stacked (N + K) x N:",
                "d(M qdd - J_c^T forces)/dq (N rows) and d(J_c qd)/dq (K rows), at fixed `qdd`, `qd`,",
                "`forces`, with",
                tangent,
            ],
            "Newton-Euler's derivatives at zero velocity and gravity, and the contact Jacobian differentiated along each tangent direction",
            Evaluation::Exprs(flat(&p.impulse)),
        ),
        quantity(
            "impulse_dynamics_derivatives",
            &[Input::Q, Input::Qd],
            Shape::Matrices(2, n + k, n),
            &[
                "The derivatives of `impulse_dynamics` (velocity after the impact, impulses) in `q` (tangent",
                "space, as `integrate`) and the velocity before: Pinocchio's",
                "`computeImpulseDynamicsDerivatives`, except that `dv_dv` is d v_after / d v_before",
                "(Pinocchio's derivative of the jump plus the identity).",
                "",
                "NaN in every entry when M(q) is not positive definite or J_c is rank-deficient;",
                "`try_impulse_dynamics_derivatives` says why.",
            ],
            "`impulse_dynamics` by `eomgen_runtime::ContactKkt`, `impulse_dynamics_partials` there, then the KKT system solved for every column",
            Evaluation::ImpulseDynamicsDerivatives,
        ),
    ]
}
