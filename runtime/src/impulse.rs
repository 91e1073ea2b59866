//! Impulse dynamics: the velocity after an impact that the contacts absorb, and its
//! derivatives, through the contact problem's KKT system ([`ContactKkt`]).
//!
//! With restitution `e`, the impulses `p` (on the robot, world axes) and the velocity after
//! the impact `v+` satisfy `M (v+ - v) = J^T p` and `J v+ = -e J v`: the KKT system with
//! `top = 0`, `bottom = -(1 + e) J v` gives `(v+ - v, p)`.

use crate::kkt::{axpy, dot, finite_rows, negate, ContactKkt, ImpulseDynamicsDerivatives};
use crate::{FactorError, Real};

impl<T: Real, const N: usize, const K: usize> ContactKkt<T, N, K> {
    /// The velocity after the impact and the impulses, from the velocity before `v` and the
    /// restitution `e` (0: the contacts stop, 1: they bounce back at full speed).
    pub fn impulse(&self, v: &[T; N], e: T) -> Result<([T; N], [T; K]), FactorError> {
        let k = -(T::one() + e);
        let bottom: [T; K] = core::array::from_fn(|r| k * dot(&self.jacobian()[r], v));
        let (mut dv, p) = self.solve_bottom(&bottom)?;
        for (x, vi) in dv.iter_mut().zip(v) {
            *x += *vi;
        }
        Ok((dv, p))
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
        negate(&mut d.dv_dq);
        negate(&mut d.dimpulse_dq);
        self.solve_columns_in_place(&mut d.dv_dq, &mut d.dimpulse_dq);
        d.dimpulse_dv = *self.jacobian();
        self.lambda_solve_columns(&mut d.dimpulse_dv);
        let k = -(T::one() + e);
        for x in d.dimpulse_dv.iter_mut().flatten() {
            *x *= k;
        }
        // I + Y dp/dv, each row gathered in a local accumulator.
        for (i, row) in d.dv_dv.iter_mut().enumerate() {
            let mut acc = [T::zero(); N];
            acc[i] = T::one();
            for (yk, pk) in self.inverse_inertia_rows().iter().zip(&d.dimpulse_dv) {
                axpy(&mut acc, yk[i], pk);
            }
            *row = acc;
        }
        finite_rows(&d.dv_dq, 0)?;
        finite_rows(&d.dv_dv, 0)?;
        finite_rows(&d.dimpulse_dq, N)?;
        finite_rows(&d.dimpulse_dv, N)?;
        Ok(())
    }
}
