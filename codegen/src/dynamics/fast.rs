//! The fast forms: per quantity of generated code, whichever route needs fewer operations
//! (closed Lagrangian forms or the recursive algorithms), and forward dynamics by an unrolled
//! sparse `L^T D L` solve on the cheaper `M`.

use super::lagrangian::{self, pairs, Closed};
use super::{flat, newton_euler, Recursive};
use crate::cas::{Graph, GraphFull, Id, Program};
use crate::model::Model;

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
    /// robots evaluate it from the columns of `C(q, qd)` ([`Evaluation::CraigColumns`](super::Evaluation::CraigColumns)).
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

/// Per quantity the cheaper route, forward dynamics by an unrolled `L^T D L` solve on the
/// cheaper `M`, and (for small robots) flattened Craig forms. Without closed forms (velocities
/// that are not the rates of the positions) every quantity takes the recursive route.
pub(super) fn fast_forms(
    g: &mut Graph,
    model: &Model,
    closed: Option<&Closed>,
    rec: &Recursive,
    friction: &[Id],
    qd: &[Id],
    parents: &[Option<usize>],
) -> Result<Fast, GraphFull> {
    let Some(closed) = closed else {
        return Ok(recursive_forms(g, rec, friction, parents));
    };
    let n = qd.len();
    let vec = |v: &Vec<Id>| v.clone();
    let fl = |m: &Vec<Vec<Id>>| flat(m);
    let mm = cheaper(g, &closed.mass_matrix, &rec.mass_matrix, fl);
    let gr = cheaper(g, &closed.energies.gravity, &rec.gravity, vec);
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
    let bi = choose(g, &closed.christoffel.bias, &rec.bias);
    let tq = choose(g, &closed.tau, &rec.tau);
    // h = b + G: one recursion, or the sum of the cheaper closed forms.
    let lag_h: Vec<Id> = (0..n).map(|i| g.add(bi.1[i], gr.1[i])).collect();
    let (_, h) = cheaper(g, &lag_h, &rec.bias_and_gravity, vec);
    let forward = Forward::new(g, &h, friction, parents, &mm.1);
    let cm = if small {
        cheaper(
            g,
            &closed.christoffel.coriolis_matrix,
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
            Some(cheaper(g, &closed.christoffel.centrifugal, &cf, fl)),
            Some(cheaper(g, &closed.christoffel.coriolis_pairs, &cp, fl)),
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
        tau_in: forward.tau_in,
        bias_gravity_friction: forward.h,
        forward_dynamics: forward.qdd,
        pivots: forward.pivots,
    })
}

/// Every quantity by the recursive algorithms: the fast forms when there are no closed forms to
/// compare them with (a floating base, floating joints). Craig's matrices are not generated.
fn recursive_forms(
    g: &mut Graph,
    rec: &Recursive,
    friction: &[Id],
    parents: &[Option<usize>],
) -> Fast {
    let forward = Forward::new(
        g,
        &rec.bias_and_gravity,
        friction,
        parents,
        &rec.mass_matrix,
    );
    let r = Route::Recursive;
    Fast {
        mass_matrix: (r, rec.mass_matrix.clone()),
        gravity: (r, rec.gravity.clone()),
        bias: (r, rec.bias.clone()),
        tau: (r, rec.tau.clone()),
        coriolis_matrix: (r, rec.coriolis_matrix.clone()),
        centrifugal: None,
        coriolis_pairs: None,
        kinetic_energy: rec.kinetic_energy,
        kinetic_energy_route: r,
        tau_in: forward.tau_in,
        bias_gravity_friction: forward.h,
        forward_dynamics: forward.qdd,
        pivots: forward.pivots,
    }
}

/// Forward dynamics `qdd = M^-1 (tau_in - h)` with `h = b + G + F(qd)`.
struct Forward {
    tau_in: Vec<Id>,
    h: Vec<Id>,
    qdd: Vec<Id>,
    pivots: Vec<Id>,
}

impl Forward {
    /// From `b + G` (`bias_and_gravity`), the friction effort and `M`, by the unrolled sparse
    /// `L^T D L` solve over the coordinate tree (`parents`).
    fn new(
        g: &mut Graph,
        bias_and_gravity: &[Id],
        friction: &[Id],
        parents: &[Option<usize>],
        mass_matrix: &[Vec<Id>],
    ) -> Forward {
        let n = friction.len();
        let h: Vec<Id> = (0..n)
            .map(|i| g.add(bias_and_gravity[i], friction[i]))
            .collect();
        let tau_in: Vec<Id> = (0..n).map(|i| g.tau(i)).collect();
        let rhs: Vec<Id> = (0..n).map(|i| g.sub(tau_in[i], h[i])).collect();
        let (qdd, pivots) = newton_euler::ltdl_solve(g, parents, mass_matrix, &rhs);
        Forward {
            tau_in,
            h,
            qdd,
            pivots,
        }
    }
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
