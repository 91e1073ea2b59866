//! Joint friction and rotor inertia on top of any rigid-body model: [`WithJointEffects`].

use crate::{solve_spd_or_nan, Dynamics, Real};

/// A robot's rigid-body dynamics `D` plus, per joint, rotor inertia (armature), viscous
/// damping and Coulomb friction, itself a [`Dynamics`] so that the integrators and controllers
/// use it unchanged.
///
/// The equation of motion becomes
///
/// ```text
/// (M(q) + diag(armature)) qdd + C(q, qd) qd + g(q) + viscous ∘ qd + coulomb ∘ sign(qd) = tau
/// ```
///
/// - `armature` (kg m² or kg): the reflected rotor inertia `gear_ratio² × I_rotor`, added to
///   `M`'s diagonal and to the kinetic energy; being constant it adds no Coriolis term.
/// - `viscous` (N m s/rad or N s/m) and `coulomb` (N m or N): the URDF's
///   `<dynamics damping friction>`. The friction effort `-(viscous qd + coulomb sign(qd))`
///   opposes motion, so inverse dynamics must supply it ([`inverse_dynamics`] adds it) and
///   forward dynamics loses it. `sign(0) = 0` ([`Real::signum`]): a joint at rest feels no
///   Coulomb friction, so stiction is not modelled, and the discontinuity at `qd = 0` limits
///   the accuracy of fixed-step integration there.
///
/// [`bias`](Dynamics::bias) and [`coriolis_matrix`](Dynamics::coriolis_matrix) stay those of
/// `D` (pure Coriolis and centrifugal terms); the friction is only in the inverse and forward
/// dynamics. The potential energy is `D`'s.
///
/// [`inverse_dynamics`]: Dynamics::inverse_dynamics
///
/// ```
/// use eomgen_runtime::{Dynamics, WithJointEffects};
/// # struct Wheel;
/// # impl Dynamics<f64, 1> for Wheel {
/// #     const JOINT_NAMES: [&'static str; 1] = ["axle"];
/// #     fn mass_matrix(&self, _: &[f64; 1]) -> [[f64; 1]; 1] { [[0.5]] }
/// #     fn gravity(&self, _: &[f64; 1]) -> [f64; 1] { [0.0] }
/// #     fn bias(&self, _: &[f64; 1], _: &[f64; 1]) -> [f64; 1] { [0.0] }
/// #     fn coriolis_matrix(&self, _: &[f64; 1], _: &[f64; 1]) -> [[f64; 1]; 1] { [[0.0]] }
/// #     fn inverse_dynamics(&self, _: &[f64; 1], _: &[f64; 1], a: &[f64; 1]) -> [f64; 1] { [0.5 * a[0]] }
/// #     fn forward_dynamics(&self, _: &[f64; 1], _: &[f64; 1], t: &[f64; 1]) -> [f64; 1] { [t[0] / 0.5] }
/// #     fn kinetic_energy(&self, _: &[f64; 1], v: &[f64; 1]) -> f64 { 0.25 * v[0] * v[0] }
/// #     fn potential_energy(&self, _: &[f64; 1]) -> f64 { 0.0 }
/// # }
/// // A wheel of 0.5 kg m² on a motor with 0.1 kg m² reflected rotor inertia, 0.2 N m s/rad
/// // damping and 0.3 N m Coulomb friction, spinning at 2 rad/s.
/// let drive = WithJointEffects {
///     robot: Wheel,
///     armature: [0.1],
///     viscous: [0.2],
///     coulomb: [0.3],
/// };
/// assert_eq!(drive.mass_matrix(&[0.0]), [[0.6]]);
/// // Accelerating at 1 rad/s² takes 0.6 + 0.2 × 2 + 0.3 = 1.3 N m.
/// let tau = drive.inverse_dynamics(&[0.0], &[2.0], &[1.0]);
/// assert!((tau[0] - 1.3).abs() < 1e-12);
/// assert!((drive.forward_dynamics(&[0.0], &[2.0], &tau)[0] - 1.0).abs() < 1e-12);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WithJointEffects<D, T, const N: usize> {
    /// The rigid-body model.
    pub robot: D,
    /// Rotor inertia per joint, added to the mass matrix's diagonal (kg m² or kg).
    pub armature: [T; N],
    /// Viscous damping per joint (N m s/rad or N s/m).
    pub viscous: [T; N],
    /// Coulomb friction per joint (N m or N).
    pub coulomb: [T; N],
}

impl<D, T: Real, const N: usize> WithJointEffects<D, T, N> {
    /// `robot` with no armature and no friction (then identical to `robot`).
    pub fn new(robot: D) -> Self {
        WithJointEffects {
            robot,
            armature: [T::zero(); N],
            viscous: [T::zero(); N],
            coulomb: [T::zero(); N],
        }
    }

    /// The friction effort `viscous ∘ qd + coulomb ∘ sign(qd)` that the actuators must supply
    /// to keep the joints moving (the joints feel its negative).
    pub fn friction(&self, qd: &[T; N]) -> [T; N] {
        core::array::from_fn(|i| self.viscous[i] * qd[i] + self.coulomb[i] * qd[i].signum())
    }
}

impl<D: Dynamics<T, N>, T: Real, const N: usize> Dynamics<T, N> for WithJointEffects<D, T, N> {
    const JOINT_NAMES: [&'static str; N] = D::JOINT_NAMES;

    fn mass_matrix(&self, q: &[T; N]) -> [[T; N]; N] {
        let mut m = self.robot.mass_matrix(q);
        for (i, row) in m.iter_mut().enumerate() {
            row[i] += self.armature[i];
        }
        m
    }

    fn gravity(&self, q: &[T; N]) -> [T; N] {
        self.robot.gravity(q)
    }

    fn bias(&self, q: &[T; N], qd: &[T; N]) -> [T; N] {
        self.robot.bias(q, qd)
    }

    fn coriolis_matrix(&self, q: &[T; N], qd: &[T; N]) -> [[T; N]; N] {
        self.robot.coriolis_matrix(q, qd)
    }

    fn inverse_dynamics(&self, q: &[T; N], qd: &[T; N], qdd: &[T; N]) -> [T; N] {
        let tau = self.robot.inverse_dynamics(q, qd, qdd);
        let f = self.friction(qd);
        core::array::from_fn(|i| tau[i] + self.armature[i] * qdd[i] + f[i])
    }

    fn forward_dynamics(&self, q: &[T; N], qd: &[T; N], tau: &[T; N]) -> [T; N] {
        let (h, g, f) = (
            self.robot.bias(q, qd),
            self.robot.gravity(q),
            self.friction(qd),
        );
        let rhs = core::array::from_fn(|i| tau[i] - h[i] - g[i] - f[i]);
        solve_spd_or_nan(&self.mass_matrix(q), &rhs)
    }

    fn kinetic_energy(&self, q: &[T; N], qd: &[T; N]) -> T {
        let mut e = self.robot.kinetic_energy(q, qd);
        for (a, v) in self.armature.iter().zip(qd) {
            e += T::from_f64(0.5) * *a * *v * *v;
        }
        e
    }

    fn potential_energy(&self, q: &[T; N]) -> T {
        self.robot.potential_energy(q)
    }
}
