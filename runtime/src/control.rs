//! Joint-space controllers and task-space tools: [`PdGravity`] (PD with gravity
//! compensation), [`ComputedTorque`], [`CollocatedPfl`] (partial feedback linearization of a
//! robot with a passive joint), the Jacobian-transpose map [`wrench_to_torque`], and
//! manipulability ellipsoids ([`Ellipsoid`]) from a small panic-free symmetric eigen-solver
//! ([`SymmetricEigen`]).
//!
//! Jacobians are `6 × N` arrays as returned by generated `link_jacobian`: rows
//! `vx vy vz wx wy wz` (linear velocity, then angular velocity), one column per joint.

use crate::sim::State;
use crate::{Dynamics, Real};

/// A desired joint trajectory point: position, velocity and acceleration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Setpoint<T, const N: usize> {
    /// Desired positions.
    pub q: [T; N],
    /// Desired velocities.
    pub qd: [T; N],
    /// Desired accelerations (feed-forward; ignored by [`PdGravity`]).
    pub qdd: [T; N],
}

impl<T: Real, const N: usize> Setpoint<T, N> {
    /// A constant target: position `q`, zero velocity and acceleration.
    pub fn hold(q: [T; N]) -> Self {
        Setpoint {
            q,
            qd: [T::zero(); N],
            qdd: [T::zero(); N],
        }
    }
}

/// PD control with gravity compensation:
/// `tau = Kp (q* - q) + Kd (qd* - qd) + g(q)` with diagonal gains.
///
/// For a constant target and positive gains the closed loop is asymptotically stable (the
/// classical Takegaki-Arimoto result), but it does not track moving targets exactly; use
/// [`ComputedTorque`] for that.
///
/// ```
/// use eomgen_runtime::{Dynamics, Integrator, PdGravity, Setpoint, Simulator, State};
/// # struct Pendulum;
/// # impl Dynamics<f64, 1> for Pendulum {
/// #     const JOINT_NAMES: [&'static str; 1] = ["hinge"];
/// #     fn mass_matrix(&self, _: &[f64; 1]) -> [[f64; 1]; 1] { [[1.0]] }
/// #     fn gravity(&self, q: &[f64; 1]) -> [f64; 1] { [9.81 * q[0].sin()] }
/// #     fn bias(&self, _: &[f64; 1], _: &[f64; 1]) -> [f64; 1] { [0.0] }
/// #     fn coriolis_matrix(&self, _: &[f64; 1], _: &[f64; 1]) -> [[f64; 1]; 1] { [[0.0]] }
/// #     fn inverse_dynamics(&self, q: &[f64; 1], _: &[f64; 1], a: &[f64; 1]) -> [f64; 1] { [a[0] + 9.81 * q[0].sin()] }
/// #     fn forward_dynamics(&self, q: &[f64; 1], _: &[f64; 1], t: &[f64; 1]) -> [f64; 1] { [t[0] - 9.81 * q[0].sin()] }
/// #     fn kinetic_energy(&self, _: &[f64; 1], v: &[f64; 1]) -> f64 { 0.5 * v[0] * v[0] }
/// #     fn potential_energy(&self, q: &[f64; 1]) -> f64 { -9.81 * q[0].cos() }
/// # }
/// let pd = PdGravity { kp: [25.0], kd: [10.0] };
/// let target = Setpoint::hold([1.0]);
/// let mut sim = Simulator::new(&Pendulum, Integrator::Rk4, State::at_rest([0.0]), 1e-3);
/// let end = sim.run(5000, |_t, s| pd.torque(&Pendulum, s, &target));
/// assert!((end.q[0] - 1.0).abs() < 1e-6);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PdGravity<T, const N: usize> {
    /// Proportional gains (N·m/rad or N/m).
    pub kp: [T; N],
    /// Derivative gains (N·m·s/rad or N·s/m).
    pub kd: [T; N],
}

impl<T: Real, const N: usize> PdGravity<T, N> {
    /// The effort at `state` for `target` (its `qdd` is not used).
    pub fn torque<D: Dynamics<T, N>>(
        &self,
        robot: &D,
        state: &State<T, N>,
        target: &Setpoint<T, N>,
    ) -> [T; N] {
        let g = robot.gravity(&state.q);
        core::array::from_fn(|i| {
            self.kp[i] * (target.q[i] - state.q[i])
                + self.kd[i] * (target.qd[i] - state.qd[i])
                + g[i]
        })
    }
}

/// Computed-torque (inverse dynamics) control:
/// `tau = M(q) (qdd* + Kp e + Kd de) + C(q, qd) qd + g(q)` with `e = q* - q`, `de = qd* - qd`.
///
/// With an exact model the closed loop is `ë + Kd ė + Kp e = 0` in every joint, independent of
/// the robot's configuration; `Kp = ω²`, `Kd = 2ω` gives critical damping at bandwidth `ω`.
/// Evaluated as one [`Dynamics::inverse_dynamics`] call, which equals the formula above.
///
/// ```
/// use eomgen_runtime::{ComputedTorque, Setpoint, State};
/// # use eomgen_runtime::Dynamics;
/// # struct Mass;
/// # impl Dynamics<f64, 1> for Mass {
/// #     const JOINT_NAMES: [&'static str; 1] = ["x"];
/// #     fn mass_matrix(&self, _: &[f64; 1]) -> [[f64; 1]; 1] { [[2.0]] }
/// #     fn gravity(&self, _: &[f64; 1]) -> [f64; 1] { [0.0] }
/// #     fn bias(&self, _: &[f64; 1], _: &[f64; 1]) -> [f64; 1] { [0.0] }
/// #     fn coriolis_matrix(&self, _: &[f64; 1], _: &[f64; 1]) -> [[f64; 1]; 1] { [[0.0]] }
/// #     fn inverse_dynamics(&self, _: &[f64; 1], _: &[f64; 1], a: &[f64; 1]) -> [f64; 1] { [2.0 * a[0]] }
/// #     fn forward_dynamics(&self, _: &[f64; 1], _: &[f64; 1], t: &[f64; 1]) -> [f64; 1] { [t[0] / 2.0] }
/// #     fn kinetic_energy(&self, _: &[f64; 1], v: &[f64; 1]) -> f64 { v[0] * v[0] }
/// #     fn potential_energy(&self, _: &[f64; 1]) -> f64 { 0.0 }
/// # }
/// let ct = ComputedTorque::critically_damped([10.0]); // Kp = 100, Kd = 20
/// let tau = ct.torque(&Mass, &State::at_rest([0.0]), &Setpoint::hold([0.01]));
/// assert!((tau[0] - 2.0 * 100.0 * 0.01).abs() < 1e-12);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ComputedTorque<T, const N: usize> {
    /// Proportional gains (1/s²).
    pub kp: [T; N],
    /// Derivative gains (1/s).
    pub kd: [T; N],
}

impl<T: Real, const N: usize> ComputedTorque<T, N> {
    /// Gains `Kp = ω²`, `Kd = 2ω` per joint: critically damped error dynamics with natural
    /// frequency `ω` (rad/s).
    pub fn critically_damped(omega: [T; N]) -> Self {
        ComputedTorque {
            kp: core::array::from_fn(|i| omega[i] * omega[i]),
            kd: core::array::from_fn(|i| T::from_f64(2.0) * omega[i]),
        }
    }

    /// The commanded acceleration `qdd* + Kp e + Kd de`.
    pub fn acceleration(&self, state: &State<T, N>, target: &Setpoint<T, N>) -> [T; N] {
        core::array::from_fn(|i| {
            target.qdd[i]
                + self.kp[i] * (target.q[i] - state.q[i])
                + self.kd[i] * (target.qd[i] - state.qd[i])
        })
    }

    /// The effort at `state` for `target`.
    pub fn torque<D: Dynamics<T, N>>(
        &self,
        robot: &D,
        state: &State<T, N>,
        target: &Setpoint<T, N>,
    ) -> [T; N] {
        let a = self.acceleration(state, target);
        robot.inverse_dynamics(&state.q, &state.qd, &a)
    }
}

/// Collocated partial feedback linearization (Spong 1994) of a robot with one passive joint:
/// the actuated joints follow `qdd_a = v`, a computed-torque law, while the passive joint
/// moves as its own equation of motion lets it.
///
/// With `u` the passive joint and `a` the actuated ones, the passive row of
/// `M qdd + h = S^T tau_a` (`h = b + g`, zero effort on `u`) gives
/// `qdd_u = -(h_u + M_ua v) / M_uu`; the actuated efforts are then `tau_a = M_a· qdd + h_a`.
/// This needs only `M_uu > 0`, true for any physical robot (the collocated case: Spong's
/// "strong inertial coupling" condition is for the non-collocated one).
///
/// The commanded acceleration of each actuated joint is
/// `v = qdd* + kp (q* + swing atan(qd_u) - q) + kd (qd* - qd)`: with `swing = 0` it tracks
/// the target; otherwise the actuated joints' targets move with the passive joint's velocity,
/// Spong's energy-pumping swing-up law `q* + (2 α / π) atan(qd_u)`, whose sign depends on the
/// robot (negative for a two-link arm with a passive elbow hanging at `q = 0`: from hanging
/// still, `swing = -1`, `ω = 6` brings the eomgen acrobot from -19.6 J to about -2 J within
/// 10 s, `tests/tests/underactuated.rs`).
///
/// [`torque`](CollocatedPfl::torque) returns the full effort `S^T tau_a`, exactly zero on the
/// passive joint. A passive index out of range, or `M_uu` not positive, gives NaN efforts.
///
/// ```
/// # mod generated { include!("../../generated/src/double_pendulum.rs"); }
/// # use generated::DoublePendulum;
/// use eomgen_runtime::prelude::*;
/// use eomgen_runtime::{CollocatedPfl, Integrator, Setpoint, Simulator, State};
///
/// // The double pendulum with a passive elbow (joint 1): the shoulder goes to 0.5 rad.
/// let robot = DoublePendulum::<f64>::default();
/// let pfl = CollocatedPfl::critically_damped(1, 5.0);
/// let target = Setpoint::hold([0.5, 0.0]);
/// let mut sim = Simulator::new(&robot, Integrator::Rk4, State::at_rest([0.0, 0.0]), 1e-3);
/// let end = sim.run_continuous(3000, |_t, s| {
///     let tau = pfl.torque(&robot, s, &target);
///     assert_eq!(tau[1], 0.0); // S^T tau_a: nothing on the passive joint
///     tau
/// });
/// assert!((end.q[0] - 0.5).abs() < 1e-3);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CollocatedPfl<T> {
    /// The index of the passive joint.
    pub passive: usize,
    /// Proportional gain of the actuated joints (1/s²).
    pub kp: T,
    /// Derivative gain of the actuated joints (1/s).
    pub kd: T,
    /// The swing-up gain (rad): the actuated joints' targets move by
    /// `swing atan(qd_u)`; 0 to track the target only.
    pub swing: T,
}

impl<T: Real> CollocatedPfl<T> {
    /// Tracking without swing-up, `kp = ω²`, `kd = 2ω`: the actuated joints' error is
    /// critically damped at `ω` rad/s.
    pub fn critically_damped(passive: usize, omega: T) -> Self {
        CollocatedPfl {
            passive,
            kp: omega * omega,
            kd: T::from_f64(2.0) * omega,
            swing: T::zero(),
        }
    }

    /// The joint accelerations the controller imposes at `state`: `v` on the actuated joints,
    /// and on the passive one what its equation of motion then gives.
    pub fn acceleration<D: Dynamics<T, N>, const N: usize>(
        &self,
        robot: &D,
        state: &State<T, N>,
        target: &Setpoint<T, N>,
    ) -> [T; N] {
        let u = self.passive;
        if u >= N {
            return [T::nan(); N];
        }
        let lead = self.swing * state.qd[u].atan2(T::one());
        let mut a: [T; N] = core::array::from_fn(|i| {
            target.qdd[i]
                + self.kp * (target.q[i] + lead - state.q[i])
                + self.kd * (target.qd[i] - state.qd[i])
        });
        a[u] = T::zero();
        let m = robot.mass_matrix(&state.q);
        let h = robot.inverse_dynamics(&state.q, &state.qd, &[T::zero(); N]);
        if m[u][u] <= T::zero() || !m[u][u].is_finite() {
            return [T::nan(); N];
        }
        let mut coupled = h[u];
        for j in 0..N {
            coupled = m[u][j].mul_add(a[j], coupled);
        }
        a[u] = -coupled / m[u][u];
        a
    }

    /// The full joint effort `S^T tau_a` at `state` for `target` (the passive joint's entries
    /// of `target` are ignored): zero on the passive joint.
    pub fn torque<D: Dynamics<T, N>, const N: usize>(
        &self,
        robot: &D,
        state: &State<T, N>,
        target: &Setpoint<T, N>,
    ) -> [T; N] {
        let a = self.acceleration(robot, state, target);
        let mut tau = robot.inverse_dynamics(&state.q, &state.qd, &a);
        if self.passive < N {
            tau[self.passive] = T::zero();
        }
        tau
    }
}

/// The joint efforts `tau = Jᵀ F` that balance a wrench `F = (fx, fy, fz, mx, my, mz)` applied
/// at a link (force in N, moment in N·m, both in the frame of the Jacobian's rows): the static
/// effort needed to *exert* `F` on the environment.
///
/// `jacobian` is `6 × N` with rows `vx vy vz wx wy wz`, so `Fᵀ (J qd)` is the power and the
/// map is its transpose.
///
/// ```
/// use eomgen_runtime::wrench_to_torque;
///
/// // A planar arm of one revolute joint about z with its tip 0.5 m along x:
/// // v = (0, 0.5, 0) qd, w = (0, 0, 1) qd.
/// let j = [[0.0], [0.5], [0.0], [0.0], [0.0], [1.0]];
/// // Pushing with 10 N along y at the tip needs 5 N·m.
/// assert_eq!(wrench_to_torque(&j, &[0.0, 10.0, 0.0, 0.0, 0.0, 0.0]), [5.0]);
/// ```
pub fn wrench_to_torque<T: Real, const N: usize>(
    jacobian: &[[T; N]; 6],
    wrench: &[T; 6],
) -> [T; N] {
    core::array::from_fn(|j| {
        let mut s = T::zero();
        for (row, f) in jacobian.iter().zip(wrench) {
            s += row[j] * *f;
        }
        s
    })
}

/// `A Aᵀ` for the `K × N` matrix made of the first `K` rows of a `6 × N` Jacobian (`K <= 6`:
/// 3 for the linear-velocity rows, 6 for all).
fn gram<T: Real, const K: usize, const N: usize>(jacobian: &[[T; N]; 6]) -> [[T; K]; K] {
    core::array::from_fn(|a| {
        core::array::from_fn(|b| {
            let (ra, rb) = (&jacobian[a], &jacobian[b]);
            let mut s = T::zero();
            for j in 0..N {
                s += ra[j] * rb[j];
            }
            s
        })
    })
}

/// Eigenvalues and eigenvectors of a small symmetric matrix, by the cyclic Jacobi method.
///
/// Fixed-size, allocation-free and panic-free: at most [`MAX_SWEEPS`](Self::MAX_SWEEPS)
/// sweeps of rotations; a non-finite input gives non-finite output rather than a panic. Only the
/// matrix's symmetric part is used (`(A + Aᵀ)/2`). Eigenvalues come sorted in decreasing
/// order; `vectors[k]` is the unit eigenvector of `values[k]`, and the vectors are orthonormal.
///
/// ```
/// use eomgen_runtime::SymmetricEigen;
///
/// let e = SymmetricEigen::new([[2.0_f64, 1.0], [1.0, 2.0]]);
/// assert!((e.values[0] - 3.0).abs() < 1e-12 && (e.values[1] - 1.0).abs() < 1e-12);
/// let v = e.vectors[0];
/// assert!((v[0].abs() - 0.5_f64.sqrt()).abs() < 1e-12 && (v[0] - v[1]).abs() < 1e-12);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SymmetricEigen<T, const K: usize> {
    /// Eigenvalues, largest first.
    pub values: [T; K],
    /// `vectors[k]`: the unit eigenvector of `values[k]`.
    pub vectors: [[T; K]; K],
}

impl<T: Real, const K: usize> SymmetricEigen<T, K> {
    /// The most Jacobi sweeps performed; convergence is quadratic, so matrices up to 6 × 6
    /// need well under 10 in double precision.
    pub const MAX_SWEEPS: usize = 50;

    /// Decomposes `a` (its symmetric part).
    pub fn new(a: [[T; K]; K]) -> Self {
        let half = T::from_f64(0.5);
        let mut m: [[T; K]; K] =
            core::array::from_fn(|i| core::array::from_fn(|j| half * (a[i][j] + a[j][i])));
        // v accumulates the rotations: its columns are the eigenvectors.
        let mut v: [[T; K]; K] = core::array::from_fn(|i| {
            core::array::from_fn(|j| if i == j { T::one() } else { T::zero() })
        });
        let eps = T::epsilon();
        for _ in 0..Self::MAX_SWEEPS {
            let (mut off, mut total) = (T::zero(), T::zero());
            for (i, row) in m.iter().enumerate() {
                for (j, x) in row.iter().enumerate() {
                    total += *x * *x;
                    if i != j {
                        off += *x * *x;
                    }
                }
            }
            // Off-diagonal mass negligible against the whole; NaN stops at once (the output
            // is then NaN too).
            if off <= eps * eps * total || !off.is_finite() {
                break;
            }
            for p in 0..K {
                for q in p + 1..K {
                    let apq = m[p][q];
                    if apq == T::zero() {
                        continue;
                    }
                    // The rotation angle phi zeroing m[p][q]: cot(2 phi) = theta; t = tan(phi)
                    // is the smaller root of t² + 2 theta t - 1 = 0 (|phi| <= pi/4, stable).
                    let theta = (m[q][q] - m[p][p]) / (T::from_f64(2.0) * apq);
                    let sign = if theta >= T::zero() {
                        T::one()
                    } else {
                        -T::one()
                    };
                    let t = sign / (theta.abs() + (theta * theta + T::one()).sqrt());
                    // theta² overflowing gives t = 0: no rotation needed at that precision.
                    let t = if t.is_finite() { t } else { T::zero() };
                    let c = (t * t + T::one()).sqrt().recip();
                    let s = t * c;
                    // m <- Rᵀ m R, v <- v R with R the rotation in the (p, q) plane.
                    for row in m.iter_mut() {
                        let (mkp, mkq) = (row[p], row[q]);
                        row[p] = c * mkp - s * mkq;
                        row[q] = s * mkp + c * mkq;
                    }
                    // Rows p and q (p < q) at once.
                    let (upper, lower) = m.split_at_mut(q);
                    for (mpk, mqk) in upper[p].iter_mut().zip(lower[0].iter_mut()) {
                        let (a, b) = (*mpk, *mqk);
                        *mpk = c * a - s * b;
                        *mqk = s * a + c * b;
                    }
                    for row in v.iter_mut() {
                        let (vkp, vkq) = (row[p], row[q]);
                        row[p] = c * vkp - s * vkq;
                        row[q] = s * vkp + c * vkq;
                    }
                }
            }
        }
        let mut values: [T; K] = core::array::from_fn(|i| m[i][i]);
        let mut vectors: [[T; K]; K] = core::array::from_fn(|k| core::array::from_fn(|i| v[i][k]));
        // Selection sort, largest first (K is tiny).
        for i in 0..K {
            let mut best = i;
            for j in i + 1..K {
                if values[j] > values[best] {
                    best = j;
                }
            }
            values.swap(i, best);
            vectors.swap(i, best);
        }
        SymmetricEigen { values, vectors }
    }
}

/// An ellipsoid centred at the origin: principal semi-axes `radii[k] * axes[k]`.
///
/// The manipulability ellipsoids of a Jacobian `J`:
/// - velocity: the task velocities `J qd` reachable with `|qd| <= 1`, axes the eigenvectors of
///   `J Jᵀ` and radii the square roots of its eigenvalues `λ_k`;
/// - force: the wrenches `F` with `|Jᵀ F| <= 1`, the same axes and radii `1 / sqrt(λ_k)`
///   (infinite along a singular direction: there the structure takes the load, no effort is
///   needed).
///
/// The two are dual: where the arm moves fast it pushes weakly. The translational (3 × 3)
/// ellipsoids, in m/s and N, are the usual ones to look at; the full 6 × 6 ones mix units
/// (m/s with rad/s, N with N·m) and depend on that choice of units.
///
/// ```
/// use eomgen_runtime::Ellipsoid;
///
/// // Two joints moving the tip along x at 2 m/s per rad/s and along y at 0.5.
/// let j = [[2.0_f64, 0.0], [0.0, 0.5], [0.0, 0.0], [0.0, 0.0], [0.0, 0.0], [1.0, 1.0]];
/// let v = Ellipsoid::velocity_translational(&j);
/// let f = Ellipsoid::force_translational(&j);
/// assert!((v.radii[0] - 2.0).abs() < 1e-12 && v.axes[0][0].abs() > 0.999_999);
/// // Same axes in the same order, reciprocal radii: along x, the fast direction, force is weak.
/// assert!((f.radii[0] - 0.5).abs() < 1e-12 && f.axes[0] == v.axes[0]);
/// assert_eq!(v.radii[2], 0.0); // no motion along z ...
/// assert!(f.radii[2].is_infinite()); // ... and any force along z is held by the structure
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ellipsoid<T, const K: usize> {
    /// Semi-axis lengths, `radii[k]` along `axes[k]`.
    pub radii: [T; K],
    /// Unit principal directions (orthonormal).
    pub axes: [[T; K]; K],
}

impl<T: Real, const K: usize> Ellipsoid<T, K> {
    /// The image of the unit ball under `A` given the shape matrix `S = A Aᵀ`: radii
    /// `sqrt(λ_k(S))` (negative round-off clamped to 0), largest first.
    pub fn from_shape_matrix(s: [[T; K]; K]) -> Self {
        let e = SymmetricEigen::new(s);
        Ellipsoid {
            radii: core::array::from_fn(|k| e.values[k].max(T::zero()).sqrt()),
            axes: e.vectors,
        }
    }

    /// The set `{x : xᵀ Q x <= 1}` for a positive semi-definite `Q`: radii `1 / sqrt(λ_k(Q))`
    /// (infinite for a zero eigenvalue), smallest first: index `k` matches
    /// [`from_shape_matrix`](Self::from_shape_matrix) of the same matrix, with reciprocal
    /// radius.
    pub fn from_quadratic_form(q: [[T; K]; K]) -> Self {
        let e = SymmetricEigen::new(q);
        Ellipsoid {
            radii: core::array::from_fn(|k| e.values[k].max(T::zero()).sqrt().recip()),
            axes: e.vectors,
        }
    }

    /// The volume-like measure `Π radii` (Yoshikawa's manipulability `sqrt(det(J Jᵀ))` for a
    /// velocity ellipsoid).
    pub fn radii_product(&self) -> T {
        self.radii.iter().fold(T::one(), |p, r| p * *r)
    }
}

impl<T: Real> Ellipsoid<T, 3> {
    /// The translational velocity manipulability ellipsoid of `jacobian` (rows `vx vy vz` only),
    /// in m/s per unit joint speed.
    pub fn velocity_translational<const N: usize>(jacobian: &[[T; N]; 6]) -> Self {
        Self::from_shape_matrix(gram(jacobian))
    }

    /// The translational force manipulability ellipsoid: forces `F` (N) with `|Jvᵀ F| <= 1`.
    pub fn force_translational<const N: usize>(jacobian: &[[T; N]; 6]) -> Self {
        Self::from_quadratic_form(gram(jacobian))
    }
}

impl<T: Real> Ellipsoid<T, 6> {
    /// The full (twist) velocity manipulability ellipsoid, axes in `vx vy vz wx wy wz`.
    pub fn velocity<const N: usize>(jacobian: &[[T; N]; 6]) -> Self {
        Self::from_shape_matrix(gram(jacobian))
    }

    /// The full (wrench) force manipulability ellipsoid, axes in `fx fy fz mx my mz`.
    pub fn force<const N: usize>(jacobian: &[[T; N]; 6]) -> Self {
        Self::from_quadratic_form(gram(jacobian))
    }
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)] // index loops read like the formulas
mod tests {
    use super::*;

    /// A deterministic, well-spread symmetric test matrix.
    fn sym6(seed: f64) -> [[f64; 6]; 6] {
        let mut a = [[0.0; 6]; 6];
        for i in 0..6 {
            for j in 0..=i {
                let x = libm::sin(seed * (1.0 + i as f64) + 0.7 * j as f64 + (i * j) as f64);
                a[i][j] = x;
                a[j][i] = x;
            }
        }
        a
    }

    #[test]
    fn jacobi_reconstructs_the_matrix() {
        for seed in [0.3, 1.1, 2.9, 7.0] {
            let a = sym6(seed);
            let e = SymmetricEigen::new(a);
            for i in 0..6 {
                for j in 0..6 {
                    let dot: f64 = (0..6).map(|k| e.vectors[i][k] * e.vectors[j][k]).sum();
                    let want = if i == j { 1.0 } else { 0.0 };
                    assert!((dot - want).abs() < 1e-13, "orthonormality {i} {j}: {dot}");
                    let rec: f64 = (0..6)
                        .map(|k| e.values[k] * e.vectors[k][i] * e.vectors[k][j])
                        .sum();
                    assert!((rec - a[i][j]).abs() < 1e-13, "A[{i}][{j}]");
                }
            }
            assert!(e.values.windows(2).all(|w| w[0] >= w[1]));
        }
    }

    #[test]
    fn jacobi_handles_degenerate_and_bad_input() {
        let z = SymmetricEigen::new([[0.0_f64; 3]; 3]);
        assert_eq!(z.values, [0.0; 3]);
        let i = SymmetricEigen::new([[1.0_f32, 0.0], [0.0, 1.0]]);
        assert_eq!(i.values, [1.0, 1.0]);
        let n = SymmetricEigen::new([[f64::NAN, 1.0], [1.0, 0.0]]);
        assert!(n.values.iter().any(|x| x.is_nan()));
        let inf = SymmetricEigen::new([[f64::INFINITY, 1.0], [1.0, 0.0]]);
        assert!(inf.values.iter().any(|x| !x.is_finite()));
        let big = SymmetricEigen::new([[1e300_f64, 1e-300], [1e-300, -1e300]]);
        assert_eq!(big.values, [1e300, -1e300]);
    }
}
