//! Hamilton's form of the equation of motion, composed at run time from any [`Dynamics`].

use crate::{Dynamics, Ldlt, Real};

/// Hamilton's equations of a robot, for every [`Dynamics`] implementation (generated or
/// hand-written; brought into scope by `use eomgen_runtime::prelude::*;`).
///
/// With the generalized momentum `p = M(q) qd` and the Hamiltonian
/// `H(q, p) = ½ pᵀ M(q)⁻¹ p + V(q)` (kinetic plus potential energy):
///
/// ```text
/// qd = ∂H/∂p = M(q)⁻¹ p
/// pd = -∂H/∂q + tau = C(q, qd)ᵀ qd - g(q) + tau
/// ```
///
/// with `C` the Christoffel-form Coriolis matrix ([`Dynamics::coriolis_matrix`]): at fixed `p`,
/// `∂H/∂q_k = -½ qdᵀ (∂M/∂q_k) qd + ∂V/∂q_k`, and `(Cᵀ qd)_k = ½ qdᵀ (∂M/∂q_k) qd`.
///
/// Everything is composed from the generated functions, with no code of its own in the
/// generated file: `momentum` is `M qd`, `velocity_from_momentum` an `L D Lᵀ` solve, and
/// `hamilton` evaluates `pd = tau - h(q, qd) + (C + Cᵀ) qd` with `h = inverse_dynamics(q, qd,
/// 0)` (`b + g`, plus the joint friction `F(qd)` when the robot was generated with it, which
/// then enters as the non-conservative force it is) and `b = C qd`: `(C + Cᵀ) qd = Ṁ qd`.
///
/// A mass matrix that cannot be factorized (a non-physical model or non-finite input) gives
/// NaN in every component, as [`Dynamics::forward_dynamics`] does; nothing panics or allocates.
///
/// ```
/// # mod generated { include!("../../generated/src/double_pendulum.rs"); }
/// # use generated::DoublePendulum;
/// use eomgen_runtime::prelude::*;
///
/// let robot = DoublePendulum::<f64>::default();
/// let (q, qd, tau) = ([0.3, -0.2], [1.0, 0.5], [0.1, 0.0]);
/// let p = robot.momentum(&q, &qd);
/// let (qd2, pd) = robot.hamilton(&q, &p, &tau);
/// assert!((qd2[0] - qd[0]).abs() < 1e-12 && (qd2[1] - qd[1]).abs() < 1e-12);
/// // H is the total energy.
/// let e = robot.kinetic_energy(&q, &qd) + robot.potential_energy(&q);
/// assert!((robot.hamiltonian(&q, &p) - e).abs() < 1e-12);
/// // pd = d/dt (M qd) = M qdd + Mdot qd.
/// let qdd = robot.forward_dynamics(&q, &qd, &tau);
/// let c = robot.coriolis_matrix(&q, &qd);
/// let m = robot.mass_matrix(&q);
/// for k in 0..2 {
///     let mqdd: f64 = (0..2).map(|j| m[k][j] * qdd[j]).sum();
///     let mdot_qd: f64 = (0..2).map(|j| (c[k][j] + c[j][k]) * qd[j]).sum();
///     assert!((pd[k] - (mqdd + mdot_qd)).abs() < 1e-12);
/// }
/// ```
pub trait Hamiltonian<T, const N: usize> {
    /// The generalized momentum `p = M(q) qd`.
    fn momentum(&self, q: &[T; N], qd: &[T; N]) -> [T; N];

    /// The velocity of a momentum, `qd = M(q)⁻¹ p = ∂H/∂p` (NaN in every component when
    /// `M(q)` cannot be factorized).
    fn velocity_from_momentum(&self, q: &[T; N], p: &[T; N]) -> [T; N];

    /// The Hamiltonian `H(q, p) = ½ pᵀ M(q)⁻¹ p + V(q)`, the total energy.
    fn hamiltonian(&self, q: &[T; N], p: &[T; N]) -> T;

    /// Hamilton's equations with the effort `tau`: `(qd, pd) = (∂H/∂p, -∂H/∂q + tau)`, i.e.
    /// `qd = M(q)⁻¹ p` and `pd = C(q, qd)ᵀ qd - g(q) + tau` (minus the friction effort `F(qd)`
    /// when generated with it).
    fn hamilton(&self, q: &[T; N], p: &[T; N], tau: &[T; N]) -> ([T; N], [T; N]);
}

impl<T: Real, const N: usize, D: Dynamics<T, N> + ?Sized> Hamiltonian<T, N> for D {
    fn momentum(&self, q: &[T; N], qd: &[T; N]) -> [T; N] {
        let m = self.mass_matrix(q);
        core::array::from_fn(|i| dot(&m[i], qd))
    }

    fn velocity_from_momentum(&self, q: &[T; N], p: &[T; N]) -> [T; N] {
        match Ldlt::new(self.mass_matrix(q)) {
            Ok(f) => f.solve(p),
            Err(_) => [T::nan(); N],
        }
    }

    fn hamiltonian(&self, q: &[T; N], p: &[T; N]) -> T {
        let qd = self.velocity_from_momentum(q, p);
        T::from_f64(0.5) * dot(p, &qd) + self.potential_energy(q)
    }

    fn hamilton(&self, q: &[T; N], p: &[T; N], tau: &[T; N]) -> ([T; N], [T; N]) {
        let qd = self.velocity_from_momentum(q, p);
        (qd, momentum_rate(self, q, &qd, tau))
    }
}

/// `pd = tau - h(q, qd) + (C + Cᵀ) qd` at a known velocity.
pub(crate) fn momentum_rate<T: Real, D: Dynamics<T, N> + ?Sized, const N: usize>(
    robot: &D,
    q: &[T; N],
    qd: &[T; N],
    tau: &[T; N],
) -> [T; N] {
    let c = robot.coriolis_matrix(q, qd);
    let h = robot.inverse_dynamics(q, qd, &[T::zero(); N]);
    core::array::from_fn(|k| {
        let mut mdot_qd = T::zero();
        for j in 0..N {
            mdot_qd = (c[k][j] + c[j][k]).mul_add(qd[j], mdot_qd);
        }
        tau[k] - h[k] + mdot_qd
    })
}

fn dot<T: Real, const N: usize>(a: &[T; N], b: &[T; N]) -> T {
    a.iter()
        .zip(b)
        .fold(T::zero(), |acc, (x, y)| x.mul_add(*y, acc))
}
