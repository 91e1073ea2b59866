//! The Lagrangian engine: closed-form M, Craig's B and C, G, the bias, the Coriolis matrix,
//! energies and frame kinematics of a [`Model`], as expressions in one [`Graph`].
//!
//! - `M(q) = sum over bodies of m Jv^T Jv + Jw^T I Jw`, with the Jacobians in body coordinates
//!   (see [`BodyKinematics`]) and only the joints on a body's path to the root: `M_ij = 0` when
//!   joints `i` and `j` are not on one path.
//! - `V = -sum m g.c`, `G = dV/dq`; `T = qd^T M qd / 2`.
//! - Christoffel symbols `G_ijk = (dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i) / 2`; Craig's
//!   centrifugal matrix `C_ij = G_ijj`, Coriolis matrix `B_i,(jk) = 2 G_ijk` (`j < k`, pairs in
//!   the order (0,1), (0,2), ..., (1,2), ...), the Coriolis matrix
//!   `C(q, qd)_ij = sum_k G_ijk qd_k` (so that `dM/dt - 2 C(q, qd)` is skew-symmetric), the
//!   bias `b = C(q, qd) qd` and `tau = M qdd + b + G + F(qd)`.
//! - Rotor inertia (armature) adds to `M`'s diagonal; joint friction `F(qd)` (when the model
//!   includes it) adds to `tau` and enters forward dynamics, but not `b`.

pub mod newton_euler;

use std::time::{Duration, Instant};

use crate::cas::{Graph, GraphFull, Id, Limits, Program};
use crate::kinematics::{
    const_v3, cross, mat_vec, vec_add, BodyKinematics, Params, WorldKinematics, M3, V3,
};
use crate::model::Model;

/// Pose and Jacobian of one URDF link frame.
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
    /// Degrees of freedom.
    pub dof: usize,
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
    /// One per URDF link, in the model's frame order.
    pub frames: Vec<FrameExprs>,
    /// The same quantities by the recursive algorithms.
    pub recursive: Recursive,
    /// For each function of generated code, the cheaper of the two routes.
    pub fast: Fast,
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
}

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
    /// Craig's `C(q)`: Christoffel symbols, or `1/2 d^2 b_i / dqd_j^2`.
    pub centrifugal: (Route, Vec<Vec<Id>>),
    /// Craig's `B(q)`: Christoffel symbols, or `d^2 b_i / dqd_j dqd_k`.
    pub coriolis_pairs: (Route, Vec<Vec<Id>>),
    pub kinetic_energy: Id,
    /// Joint efforts as symbols `tau_i` (inputs of forward dynamics).
    pub tau_in: Vec<Id>,
    /// `qdd = M^-1 (tau_in - b - G - F)`, with an unrolled sparse `L^T D L` solve.
    pub forward_dynamics: Vec<Id>,
    /// The pivots `D` of that factorization, all positive when `M` is positive definite.
    pub pivots: Vec<Id>,
}

fn cheaper<T: Clone>(g: &Graph, a: &T, b: &T, ids: impl Fn(&T) -> Vec<Id>) -> (Route, T) {
    let cost = |x: &T| Program::new(g, &ids(x)).ops().total();
    if cost(b) < cost(a) {
        (Route::Recursive, b.clone())
    } else {
        (Route::Lagrangian, a.clone())
    }
}

/// The pairs `(j, k)`, `j < k`, in Craig's order.
pub fn pairs(n: usize) -> Vec<(usize, usize)> {
    (0..n)
        .flat_map(|j| (j + 1..n).map(move |k| (j, k)))
        .collect()
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
        let mut timings = Vec::new();
        let mut clock = Instant::now();
        let mut lap = |name: &'static str, timings: &mut Vec<(&'static str, Duration)>| {
            let now = Instant::now();
            timings.push((name, now - clock));
            clock = now;
        };
        let mut g = Graph::with_limits(limits);
        let n = model.dof();
        let q: Vec<Id> = (0..n).map(|i| g.q(i)).collect();
        let qd: Vec<Id> = (0..n).map(|i| g.qd(i)).collect();
        let qdd: Vec<Id> = (0..n).map(|i| g.qdd(i)).collect();
        let params = Params::new(&mut g, model);

        let world = WorldKinematics::new(&mut g, model, &params, &q);
        g.check()?;
        let body = BodyKinematics::new(&mut g, model, &params, &q);
        g.check()?;
        lap("kinematics", &mut timings);

        let mass_matrix = mass_matrix(&mut g, model, &params, &body)?;
        lap("mass matrix", &mut timings);

        let grav = const_v3(&mut g, &model.gravity);
        let mut pe_terms = Vec::with_capacity(n);
        for (b, c) in world.com.iter().enumerate() {
            let gc = g.dot(&grav, c);
            let t = g.mul(params.mass[b], gc);
            pe_terms.push((t, -1.0));
        }
        let potential_energy = g.sum(0.0, pe_terms);
        let gravity: Vec<Id> = q.iter().map(|&qi| g.diff(potential_energy, qi)).collect();
        let mqd: Vec<Id> = (0..n).map(|i| g.dot(&mass_matrix[i], &qd)).collect();
        let qd_mqd = g.dot(&qd, &mqd);
        let kinetic_energy = g.scale(qd_mqd, 0.5);
        g.check()?;
        lap("energies and gravity", &mut timings);

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
                let c2 = two_christoffel(&mut g, i, j, j);
                centrifugal[i][j] = g.scale(c2, 0.5);
            }
            for &(j, k) in &pair_list {
                let b = two_christoffel(&mut g, i, j, k);
                coriolis_pairs[i].push(b);
            }
            for j in 0..n {
                let terms: Vec<(Id, f64)> = (0..n)
                    .map(|k| {
                        let c2 = two_christoffel(&mut g, i, j, k);
                        (g.mul(c2, qd[k]), 0.5)
                    })
                    .collect();
                coriolis_matrix[i][j] = g.sum(0.0, terms);
            }
            g.check()?;
        }
        // b = B [qd qd] + C [qd^2]: the Craig form shares work with the matrices above.
        let bias: Vec<Id> = (0..n)
            .map(|i| {
                let mut terms = Vec::new();
                for j in 0..n {
                    let sq = g.powi(qd[j], 2);
                    terms.push(g.mul(centrifugal[i][j], sq));
                }
                for (p, &(j, k)) in pair_list.iter().enumerate() {
                    let v = g.mul(qd[j], qd[k]);
                    terms.push(g.mul(coriolis_pairs[i][p], v));
                }
                g.add_all(terms)
            })
            .collect();
        g.check()?;
        lap("Christoffel symbols", &mut timings);

        let friction = joint_friction(&mut g, model, &params, &qd);
        let tau: Vec<Id> = (0..n)
            .map(|i| {
                let mq = g.dot(&mass_matrix[i], &qdd);
                g.add_all([mq, bias[i], gravity[i], friction[i]])
            })
            .collect();

        let mut frames = Vec::with_capacity(model.frames.len());
        for f in &model.frames {
            let (rotation, position) = world.frame_pose(&mut g, f.body, &f.placement);
            let jacobian = world.point_jacobian(&mut g, model, f.body, &position);
            frames.push(FrameExprs {
                name: f.name.clone(),
                rotation,
                position,
                jacobian,
            });
            g.check()?;
        }
        lap("frames", &mut timings);

        let lm = newton_euler::LocalModel::new(&mut g, model, &params, &q);
        g.check()?;
        let gv = Some(grav);
        use newton_euler::Terms;
        let (qd_s, qdd_s) = (Some(qd.as_slice()), Some(qdd.as_slice()));
        let crba = newton_euler::crba(&mut g, &lm);
        g.check()?;
        let rnea = |g: &mut Graph, qd, qdd, gravity| {
            let r = newton_euler::rnea(g, &lm, Terms { qd, qdd, gravity });
            g.check().map(|_| r)
        };
        let recursive = Recursive {
            mass_matrix: crba,
            gravity: rnea(&mut g, None, None, gv)?,
            bias: rnea(&mut g, qd_s, None, None)?,
            bias_and_gravity: rnea(&mut g, qd_s, None, gv)?,
            tau: rnea(&mut g, qd_s, qdd_s, gv)?,
            coriolis_matrix: newton_euler::coriolis(&mut g, &lm, &qd),
        };
        g.check()?;
        let recursive = Recursive {
            tau: (0..n)
                .map(|i| g.add(recursive.tau[i], friction[i]))
                .collect(),
            ..recursive
        };
        lap("recursive algorithms", &mut timings);

        let flat = |m: &Vec<Vec<Id>>| -> Vec<Id> { m.iter().flatten().copied().collect() };
        let vec = |v: &Vec<Id>| v.clone();
        let mm = cheaper(&g, &mass_matrix, &recursive.mass_matrix, flat);
        let gr = cheaper(&g, &gravity, &recursive.gravity, vec);
        let bi = cheaper(&g, &bias, &recursive.bias, vec);
        let tq = cheaper(&g, &tau, &recursive.tau, vec);
        // h = b + G: one recursion, or the sum of the cheaper closed forms.
        let lag_h: Vec<Id> = (0..n).map(|i| g.add(bi.1[i], gr.1[i])).collect();
        let (_, h) = cheaper(&g, &lag_h, &recursive.bias_and_gravity, vec);
        let h: Vec<Id> = (0..n).map(|i| g.add(h[i], friction[i])).collect();
        let tau_in: Vec<Id> = (0..n).map(|i| g.tau(i)).collect();
        let rhs: Vec<Id> = (0..n).map(|i| g.sub(tau_in[i], h[i])).collect();
        let parents: Vec<Option<usize>> = model.joints.iter().map(|j| j.parent).collect();
        let (forward_dynamics, pivots) = newton_euler::ltdl_solve(&mut g, &parents, &mm.1, &rhs);
        // Craig's forms from second velocity derivatives of the Newton-Euler bias (b is quadratic
        // in qd).
        let mut db: Vec<Vec<Id>> = Vec::with_capacity(n);
        for j in 0..n {
            db.push(g.diff_many(&recursive.bias, qd[j]));
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
        let mut cf_rec = vec![vec![g.zero(); n]; n];
        let mut cp_rec = vec![Vec::new(); n];
        for i in 0..n {
            for j in 0..n {
                cf_rec[i][j] = g.scale(second(j, j, i), 0.5);
            }
            for &(j, k) in &pair_list {
                cp_rec[i].push(second(k, j, i));
            }
        }
        let cm = cheaper(&g, &coriolis_matrix, &recursive.coriolis_matrix, flat);
        let cf = cheaper(&g, &centrifugal, &cf_rec, flat);
        let cp = cheaper(&g, &coriolis_pairs, &cp_rec, flat);
        let mqd_fast: Vec<Id> = (0..n).map(|i| g.dot(&mm.1[i], &qd)).collect();
        let t2 = g.dot(&qd, &mqd_fast);
        let kinetic_energy_fast = g.scale(t2, 0.5);
        let fast = Fast {
            mass_matrix: mm,
            gravity: gr,
            bias: bi,
            tau: tq,
            coriolis_matrix: cm,
            centrifugal: cf,
            coriolis_pairs: cp,
            kinetic_energy: kinetic_energy_fast,
            tau_in,
            forward_dynamics,
            pivots,
        };
        g.check()?;
        lap("fast forms", &mut timings);

        Ok(Derivation {
            graph: g,
            dof: n,
            q,
            qd,
            qdd,
            params: params.symbols,
            mass_matrix,
            gravity,
            centrifugal,
            coriolis_pairs,
            coriolis_matrix,
            bias,
            tau,
            friction,
            kinetic_energy,
            potential_energy,
            frames,
            recursive,
            fast,
            timings,
        })
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

/// The joint friction effort `F_i = damping_i qd_i + coulomb_i s(qd_i)`, with `s = sign` or,
/// for a smoothing velocity `eps > 0`, `s(v) = v / sqrt(v^2 + eps^2)`; zeros unless the model
/// includes friction.
fn joint_friction(g: &mut Graph, model: &Model, params: &Params, qd: &[Id]) -> Vec<Id> {
    let eps = model.coulomb_smoothing;
    (0..model.dof())
        .map(|i| {
            if !model.include_friction {
                return g.zero();
            }
            let viscous = g.mul(params.damping[i], qd[i]);
            let s = if eps > 0.0 {
                let v2 = g.powi(qd[i], 2);
                let r = g.sum(eps * eps, [(v2, 1.0)]);
                let root = g.sqrt(r);
                g.div(qd[i], root)
            } else {
                g.sign(qd[i])
            };
            let coulomb = g.mul(params.coulomb[i], s);
            g.add(viscous, coulomb)
        })
        .collect()
}

/// `M_jk = sum_b m_b v_bj . v_bk + u_bj^T I_b u_bk` over bodies `b` below both joints, with
/// `u` the angular and `v` the linear velocity of `b`'s centre of mass per unit joint rate, in
/// body coordinates.
fn mass_matrix(
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
                if model.joints[j].kind.is_revolute() {
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
