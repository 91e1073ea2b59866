//! The derivatives of the dynamics that [`Derivation::add_derivatives`](super::Derivation)
//! adds: inverse dynamics by the recursion of [`rnea_derivatives`](super::rnea_derivatives),
//! and `M^-1` and forward dynamics through one `L^T D L` factorization of `M`, as straight-line
//! expressions that share `M`, its factorization and the accelerations.
//!
//! Forward dynamics `qdd(q, qd, tau)` satisfies `tau = ID(q, qd, qdd)`, so
//! `d qdd / d x = -M^-1 d ID / d x` at `qdd = FD(q, qd, tau)` for `x` = `q` or `qd`, and
//! `d qdd / d tau = M^-1`: each column is one more substitution through the factorization.

use super::lagrangian::Friction;
use super::ltdl::Factors;
use super::newton_euler::JointTree;
use super::rnea_derivatives::{
    add_friction_rates, bias_from_rates, gravity_efforts, rigid_derivatives,
    InverseDynamicsDerivatives,
};
use super::Derivation;
use crate::cas::{Graph, Id};
use crate::kinematics::const_v3;
use crate::model::Model;

/// The expressions of the three generated derivative functions.
#[derive(Clone, Debug)]
pub struct Derivatives {
    /// `(d tau / d q, d tau / d qd)` at the inputs `(q, qd, qdd)`.
    pub inverse: InverseDynamicsDerivatives,
    /// `M^-1`, row-major.
    pub mass_matrix_inverse: Vec<Vec<Id>>,
    /// `(d qdd / d q, d qdd / d qd)` at the inputs `(q, qd, tau)`; the third matrix of
    /// `forward_dynamics_derivatives` is [`Derivatives::mass_matrix_inverse`].
    pub forward: InverseDynamicsDerivatives,
    /// The pivots of the factorization of `M`: every expression above is valid when all are
    /// positive.
    pub pivots: Vec<Id>,
    /// `(d tau / d q, d tau / d qd)` at the forward dynamics' accelerations: the right-hand
    /// sides of [`Derivatives::forward`], before `-M^-1`.
    pub at_forward: InverseDynamicsDerivatives,
    /// The factors of `M` in the run-time passes' layout ([`Factors::in_place`]).
    pub factors: Vec<Vec<Id>>,
}

/// Derives the three functions for `model` in `d`'s graph.
///
/// With coupled joints (mimic joints, see [`super::coupling`]) the recursion runs over the
/// joint tree at the joints' coordinates and is projected, `G^T (d tau / d x) G`: the joints'
/// coordinates are affine in the robot's (`G` constant), so the chain rule is exact. The
/// friction's part, diagonal in the joints but not in the coordinates, is differentiated in
/// the coordinates.
pub fn derive(d: &mut Derivation, model: &Model) -> Derivatives {
    let g = &mut d.graph;
    let JointTree { params, map, lm } = JointTree::new(g, model, &d.q);
    let joint_qd = map.rates(g, &d.qd);
    let grav = const_v3(g, &model.gravity);
    let m = &d.fast.mass_matrix.1;
    let parents = d.coordinate_parents.clone();
    // Per velocity column of the joint tree (none on a floating base's six). With mimic joints
    // the friction is differentiated in the coordinates instead, after the projection.
    let joint_friction = if map.is_coupled() {
        vec![g.zero(); joint_qd.len()]
    } else {
        Friction::new(g, model, &params, &map, &joint_qd).joint
    };
    // The rigid bodies' derivatives (in the coordinates), then the friction's.
    let rigid = |g: &mut Graph, qdd: &[Id]| {
        let joint_qdd = map.rates(g, qdd);
        let r = rigid_derivatives(g, &lm, grav, &joint_qd, &joint_qdd);
        if !map.is_coupled() {
            return r;
        }
        let dq = map.project_matrix(g, &r.dq, false);
        let dqd = map.project_matrix(g, &r.dqd, false);
        InverseDynamicsDerivatives { dq, dqd }
    };
    let with_friction = |g: &mut Graph, mut r: InverseDynamicsDerivatives| {
        if !map.is_coupled() {
            add_friction_rates(g, &mut r.dqd, &joint_friction, &joint_qd);
            return r;
        }
        for (i, row) in r.dqd.iter_mut().enumerate() {
            for (j, x) in row.iter_mut().enumerate() {
                let df = g.diff(d.friction[i], d.qd[j]);
                *x = g.add(*x, df);
            }
        }
        r
    };
    let inverse = rigid(g, &d.qdd);
    let rates = inverse.dqd.clone();
    let inverse = with_friction(g, inverse);
    let factors = Factors::new(g, &parents, m);
    let mass_matrix_inverse = factors.inverse(g);
    let pivots = factors.pivots();
    let joint_gravity = gravity_efforts(g, &lm, grav);
    let gravity = map.project(g, &joint_gravity);
    let rhs = forward_rhs(g, &d.fast.tau_in, &rates, &d.qd, &gravity, &d.friction);
    let qdd = factors.solve(g, &rhs);
    let at_fd = rigid(g, &qdd);
    let at_fd = with_friction(g, at_fd);
    let neg = |g: &mut Graph, a: &[Vec<Id>]| -> Vec<Vec<Id>> {
        a.iter()
            .map(|row| row.iter().map(|&x| g.neg(x)).collect())
            .collect()
    };
    let rhs_q = neg(g, &at_fd.dq);
    let rhs_qd = neg(g, &at_fd.dqd);
    let forward = InverseDynamicsDerivatives {
        dq: solve_columns(g, &factors, &rhs_q),
        dqd: solve_columns(g, &factors, &rhs_qd),
    };
    Derivatives {
        inverse,
        mass_matrix_inverse,
        forward,
        pivots,
        factors: factors.in_place(g),
        at_forward: at_fd,
    }
}

/// The right-hand side of forward dynamics, `tau - b - G - F`, from what the recursion
/// computes anyway: `b = 1/2 (d b / d qd) qd` (`b` is quadratic in the rates; `rates` is the
/// rigid bodies' `d tau / d qd`) and `G` from its composite inertias, instead of a second
/// Newton-Euler pass for `b + G`: the panda's forward-dynamics derivatives 8,999 -> 8,447
/// operations, anymal's `forward_dynamics_partials` 11,726 -> 10,736.
fn forward_rhs(
    g: &mut Graph,
    tau: &[Id],
    rates: &[Vec<Id>],
    qd: &[Id],
    gravity: &[Id],
    friction: &[Id],
) -> Vec<Id> {
    let bias = bias_from_rates(g, rates, qd);
    (0..tau.len())
        .map(|i| {
            let h = g.add(gravity[i], friction[i]);
            let rest = g.sub(tau[i], h);
            g.sub(rest, bias[i])
        })
        .collect()
}

/// `M^-1 B` column by column through the tree `L^T D L` factors of `M`.
fn solve_columns(g: &mut Graph, factors: &Factors, b: &[Vec<Id>]) -> Vec<Vec<Id>> {
    let n = b.len();
    let mut out = vec![vec![g.zero(); n]; n];
    for j in 0..n {
        let col: Vec<Id> = (0..n).map(|i| b[i][j]).collect();
        for (i, x) in factors.solve(g, &col).into_iter().enumerate() {
            out[i][j] = x;
        }
    }
    out
}
