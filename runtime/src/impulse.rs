//! Impulse dynamics: the velocity after an impact that the contacts absorb, and its
//! derivatives, through the contact problem's KKT system ([`ContactKkt`]).
//!
//! With restitution `e`, the impulses `p` (on the robot, world axes) and the velocity after
//! the impact `v+` satisfy `M (v+ - v) = J^T p` and `J v+ = -e J v`: the KKT system with
//! `top = 0`, `bottom = -(1 + e) J v` gives `(v+ - v, p)`.

use crate::contact::{contact_space, transpose_times};
use crate::kkt::{
    column_support, combination_into, dot, finite_rows, finite_solution, ContactKkt,
    ImpulseDynamicsDerivatives,
};
use crate::tree::{ltdl_lower_rows, TreePasses, Walked};
use crate::{FactorError, Lane, Real};

impl<T: Real, const N: usize, const K: usize> ContactKkt<T, N, K> {
    /// The velocity after the impact and the impulses, from the velocity before `v` and the
    /// restitution `e` (0: the contacts stop, 1: they bounce back at full speed).
    pub fn impulse(&self, v: &[T; N], e: T) -> Result<([T; N], [T; K]), FactorError> {
        self.impulse_lanes(v, e, &mut ())
    }

    /// The derivatives of [`ContactKkt::impulse`] at its solution, from the generated
    /// `partials` (`R = N + K` rows: `d(M dv - J^T p)/dq` at fixed `dv = v+ - v` and `p`, then
    /// `d(J w)/dq` at fixed `w = v+ + e v`). In `q`: `[M -J^T; J 0] [dv+; dp] = -partials`; in
    /// `v`: `dp/dv = -(1 + e) (J M^-1 J^T)^-1 J` and `dv+/dv = I + M^-1 J^T dp/dv`.
    ///
    /// Errors: `NonFinite` at the first row of `dv` (`pivot < N`) or `dp` (`N + k`) with a
    /// non-finite entry, or at `pivot` 0 when `R != N + K`.
    pub fn impulse_derivatives<const R: usize>(
        &self,
        e: T,
        partials: &[[T; N]; R],
    ) -> Result<ImpulseDynamicsDerivatives<T, N, K>, FactorError> {
        let mut d = ImpulseDynamicsDerivatives {
            dv_dq: [[T::zero(); N]; N],
            dv_dv: [[T::zero(); N]; N],
            dimpulse_dq: [[T::zero(); N]; K],
            dimpulse_dv: [[T::zero(); N]; K],
        };
        d.set_partials(partials)?;
        self.impulse_derivatives_in_place(e, &mut d)?;
        Ok(d)
    }

    /// [`ContactKkt::impulse_derivatives`] in `d`, which holds on entry what
    /// [`ImpulseDynamicsDerivatives::set_partials`] leaves: no matrix is copied, so that a caller
    /// can have them written straight into its result.
    pub fn impulse_derivatives_in_place(
        &self,
        e: T,
        d: &mut ImpulseDynamicsDerivatives<T, N, K>,
    ) -> Result<(), FactorError> {
        self.impulse_derivatives_in_place_by::<Walked>(e, d)
    }

    /// [`ContactKkt::impulse_derivatives_in_place`] with the substitutions through `M`'s
    /// factors from the passes `P` (generated code's own, unrolled for the robot's tree).
    pub fn impulse_derivatives_in_place_by<P: TreePasses<T, N>>(
        &self,
        e: T,
        d: &mut ImpulseDynamicsDerivatives<T, N, K>,
    ) -> Result<(), FactorError> {
        self.impulse_derivatives_lanes::<P>(e, d, &mut ())
    }
}

impl<T: Lane, const N: usize, const K: usize> ContactKkt<T, N, K> {
    /// [`ContactKkt::impulse`] on a vector of states ([`Lane`], one state per lane, `e` each
    /// lane's restitution): a lane whose result is not finite records its error in `failures`
    /// (a scalar returns it).
    ///
    /// ```
    /// use eomgen_runtime::ContactKkt;
    /// // A unit point mass moving at (1, -2) hits the ground (its second coordinate) and stops.
    /// let m = [[1.0_f64, 0.0], [0.0, 1.0]];
    /// let kkt = ContactKkt::new(m, &[None, None], [[0.0, 1.0]]).unwrap();
    /// assert_eq!(kkt.impulse_lanes(&[1.0, -2.0], 0.0, &mut ()), Ok(([1.0, 0.0], [2.0])));
    /// ```
    pub fn impulse_lanes(
        &self,
        v: &[T; N],
        e: T,
        failures: &mut T::Failures,
    ) -> Result<([T; N], [T; K]), FactorError> {
        let k = -(T::one() + e);
        let bottom: [T; K] = core::array::from_fn(|r| k * dot(&self.jacobian()[r], v));
        let (mut dv, p) = self.solve_bottom_lanes(&bottom, failures)?;
        for (x, vi) in dv.iter_mut().zip(v) {
            *x += *vi;
        }
        Ok((dv, p))
    }

    /// [`ContactKkt::impulse_derivatives_in_place_by`] on a vector of states: a lane with a
    /// non-finite derivative records its error in `failures` (a scalar returns it).
    pub fn impulse_derivatives_lanes<P: TreePasses<T, N>>(
        &self,
        e: T,
        d: &mut ImpulseDynamicsDerivatives<T, N, K>,
        failures: &mut T::Failures,
    ) -> Result<(), FactorError> {
        let inverse = self.lambda_inverse();
        let (dv_dq, dp_dq) = (&mut d.dv_dq, &mut d.dimpulse_dq);
        self.solve_signed_columns_in_place::<P, N>(Some(&inverse), dv_dq, dp_dq, -T::one());
        // dp/dv = -(1 + e) Lambda^-1 J and I + Y dp/dv, on the columns where J is not zero
        // (dp/dv is zero elsewhere, and those columns of dv+/dv the identity's).
        let cols = column_support(self.jacobian());
        let k = -(T::one() + e);
        for (p, row) in d.dimpulse_dv.iter_mut().zip(&inverse) {
            combination_into(p, |m| k * row[m], self.jacobian(), cols.clone());
        }
        // Each row gathered in a local accumulator; the identity's one is added to the row
        // once written: set in the accumulator at a varying index, it kept the accumulator in
        // memory, whose wide reloads of narrow stores could not be forwarded.
        let y = self.inverse_inertia_rows();
        for (i, row) in d.dv_dv.iter_mut().enumerate() {
            combination_into(row, |k| y[k][i], &d.dimpulse_dv, cols.clone());
            row[i] += T::one();
        }
        finite_rows(&d.dv_dq, 0, failures)?;
        finite_rows(&d.dv_dv, 0, failures)?;
        finite_rows(&d.dimpulse_dq, N, failures)?;
        finite_rows(&d.dimpulse_dv, N, failures)?;
        Ok(())
    }
}

/// [`ContactKkt::impulse`] from `M`'s factors `m` (as [`crate::tree::ltdl_factor`] leaves
/// them over the coordinate tree `parent`) and the contact Jacobian `j`, with only the rows
/// of `active` taking part, and the caller's own `M^-1 b` (`substitute`; generated code passes
/// its unrolled substitution): `p = -(1 + e) (J M^-1 J^T)^-1 J v` and
/// `v+ = v + M^-1 J^T p`. No KKT system is built: `J M^-1 J^T` comes from half a
/// substitution of the contact rows ([`crate::contact::solve_factored_active_with`] likewise),
/// and `M^-1` meets the one vector `J^T p`, not the K columns of `M^-1 J^T`.
///
/// Errors as [`ContactKkt::impulse`], without the pivots of `M`.
///
/// ```
/// use eomgen_runtime::impulse::solve_factored_active_with;
/// use eomgen_runtime::tree::ltdl_substitute;
/// // A unit point mass in the plane moving at (1, -2), hitting the ground (y) inelastically.
/// let (m, parent) = ([[1.0_f64, 0.0], [0.0, 1.0]], [None, None]);
/// let substitute = |b: &[f64; 2]| ltdl_substitute(&m, &parent, b);
/// let (after, p) =
///     solve_factored_active_with(&m, &parent, &[[0.0, 1.0]], &[1.0, -2.0], 0.0, &[true], substitute)
///         .unwrap();
/// assert_eq!((after, p), ([1.0, 0.0], [2.0]));
/// ```
pub fn solve_factored_active_with<T: Real, const N: usize, const K: usize>(
    m: &[[T; N]; N],
    parent: &[Option<usize>; N],
    j: &[[T; N]; K],
    v: &[T; N],
    e: T,
    active: &[bool; K],
    substitute: impl Fn(&[T; N]) -> [T; N],
) -> Result<([T; N], [T; K]), FactorError> {
    let lower = |w: &mut [[T; K]; N]| ltdl_lower_rows(m, parent, w);
    solve_factored_active_by(m, j, v, e, active, substitute, lower)
}

/// [`solve_factored_active_with`] with the caller's own first half of the substitution too
/// (`lower`: `x <- L^-T x` for the K columns of `x`, as [`ltdl_lower_rows`] computes it from
/// the factors in `m`): generated code passes its passes unrolled for the robot's tree.
///
/// ```
/// use eomgen_runtime::impulse::solve_factored_active_by;
/// use eomgen_runtime::tree::{ltdl_lower_rows, ltdl_substitute};
/// // The point mass of `solve_factored_active_with`, hitting the ground inelastically.
/// let (m, parent) = ([[1.0_f64, 0.0], [0.0, 1.0]], [None, None]);
/// let substitute = |b: &[f64; 2]| ltdl_substitute(&m, &parent, b);
/// let lower = |w: &mut [[f64; 1]; 2]| ltdl_lower_rows(&m, &parent, w);
/// let (after, p) =
///     solve_factored_active_by(&m, &[[0.0, 1.0]], &[1.0, -2.0], 0.0, &[true], substitute, lower)
///         .unwrap();
/// assert_eq!((after, p), ([1.0, 0.0], [2.0]));
/// ```
pub fn solve_factored_active_by<T: Real, const N: usize, const K: usize>(
    m: &[[T; N]; N],
    j: &[[T; N]; K],
    v: &[T; N],
    e: T,
    active: &[bool; K],
    substitute: impl Fn(&[T; N]) -> [T; N],
    lower: impl FnOnce(&mut [[T; K]; N]),
) -> Result<([T; N], [T; K]), FactorError> {
    solve_factored_active_lanes(m, (j, active), (v, e), substitute, lower, &mut ())
}

/// [`solve_factored_active_by`] on a vector of states ([`Lane`], one state per lane), with
/// the contact Jacobian and the active rows, then the velocity and the restitution, as one
/// argument each: a lane whose pivot of `J M^-1 J^T` fails, or whose result is not finite,
/// records its error in `failures` and holds garbage (a scalar returns the error at once, as
/// [`solve_factored_active_by`]). `active` is every lane's.
///
/// ```
/// use eomgen_runtime::impulse::solve_factored_active_lanes;
/// use eomgen_runtime::tree::{ltdl_lower_rows, ltdl_substitute};
/// // The point mass of `solve_factored_active_with`, bouncing back at half its speed.
/// let (m, parent) = ([[1.0_f64, 0.0], [0.0, 1.0]], [None, None]);
/// let substitute = |b: &[f64; 2]| ltdl_substitute(&m, &parent, b);
/// let lower = |w: &mut [[f64; 1]; 2]| ltdl_lower_rows(&m, &parent, w);
/// let contact = (&[[0.0, 1.0]], &[true]);
/// let (after, p) =
///     solve_factored_active_lanes(&m, contact, (&[1.0, -2.0], 0.5), substitute, lower, &mut ())
///         .unwrap();
/// assert_eq!((after, p), ([1.0, 1.0], [3.0]));
/// ```
pub fn solve_factored_active_lanes<T: Lane, const N: usize, const K: usize>(
    m: &[[T; N]; N],
    (j, active): (&[[T; N]; K], &[bool; K]),
    (v, e): (&[T; N], T),
    substitute: impl Fn(&[T; N]) -> [T; N],
    lower: impl FnOnce(&mut [[T; K]; N]),
    failures: &mut T::Failures,
) -> Result<([T; N], [T; K]), FactorError> {
    let chol = contact_space(m, j, active, lower, failures)?;
    let k = -(T::one() + e);
    let mut bottom = [T::zero(); K];
    for ((b, jr), on) in bottom.iter_mut().zip(j).zip(active) {
        if *on {
            *b = k * dot(jr, v);
        }
    }
    let p = chol.solve(&bottom);
    let (mut after, p) = finite_solution(substitute(&transpose_times(j, &p, active)), p, failures)?;
    for (x, vi) in after.iter_mut().zip(v) {
        *x += *vi;
    }
    Ok((after, p))
}
