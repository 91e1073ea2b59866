//! The contact problem's KKT system, factorized once and solved for many right-hand sides:
//! what contact dynamics, impulse dynamics and their derivatives share.
//!
//! With `M` the mass matrix and `J` the contact Jacobian (K rows, world axes), the system
//!
//! ```text
//! [ M  -J^T ] [ x ]   [ top    ]
//! [ J   0   ] [ f ] = [ bottom ]
//! ```
//!
//! is solved as `x_free = M^-1 top`, `f = (J M^-1 J^T)^-1 (bottom - J x_free)`,
//! `x = x_free + M^-1 J^T f`: one sparse `L^T D L` factorization of `M` over the joint tree
//! ([`crate::tree::ltdl_factor`]), `Y = M^-1 J^T`, and a Cholesky factorization of
//! `J M^-1 J^T` ([`Cholesky`]). Contact dynamics is one solve (`top = tau - h`,
//! `bottom = -drift`); its derivatives solve for whole matrices of right-hand sides
//! ([`ContactKkt::solve_columns`]), row by row so that the inner loops run over contiguous
//! columns. Everything lives in fixed-size arrays on the stack.

pub(crate) use crate::linalg::{axpy, combination_into, scaled};
use crate::linalg::{Cholesky, FactorError};
use crate::tree::{ltdl_factor, ltdl_substitute, TreePasses, Walked};
use crate::{Lane, Real};

/// The derivatives of contact forward dynamics (`contact_forward_dynamics_derivatives`), as
/// Pinocchio's `computeConstraintDynamicsDerivatives`: element `[i][j]` = d out_i / d in_j,
/// `q` perturbed in the tangent space (as `integrate`), forces on the robot in world axes.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct ContactDynamicsDerivatives<T, const NV: usize, const K: usize> {
    /// d a / d q, NV x NV.
    pub da_dq: [[T; NV]; NV],
    /// d a / d v, NV x NV.
    pub da_dv: [[T; NV]; NV],
    /// d a / d tau, NV x NV.
    pub da_dtau: [[T; NV]; NV],
    /// d f / d q, K x NV.
    pub df_dq: [[T; NV]; K],
    /// d f / d v, K x NV.
    pub df_dv: [[T; NV]; K],
    /// d f / d tau, K x NV.
    pub df_dtau: [[T; NV]; K],
}

impl<T: Lane, const NV: usize, const K: usize> ContactDynamicsDerivatives<T, NV, K> {
    /// Sets every entry to NaN, in place.
    pub fn fill_nan(&mut self) {
        let (a, f) = (T::nan(), T::nan());
        for m in [&mut self.da_dq, &mut self.da_dv, &mut self.da_dtau] {
            m.iter_mut().flatten().for_each(|x| *x = a);
        }
        for m in [&mut self.df_dq, &mut self.df_dv, &mut self.df_dtau] {
            m.iter_mut().flatten().for_each(|x| *x = f);
        }
    }

    /// NaN in every entry of the lanes that recorded a failure (nothing for a scalar, whose
    /// failure stops the computation before): what the methods without `try_` give a failed
    /// lane of a vector of states.
    pub fn nan_failed(&mut self, failures: &T::Failures) {
        for m in [&mut self.da_dq, &mut self.da_dv, &mut self.da_dtau] {
            crate::lane::nan_failed_in(m.as_flattened_mut(), failures);
        }
        for m in [&mut self.df_dq, &mut self.df_dv, &mut self.df_dtau] {
            crate::lane::nan_failed_in(m.as_flattened_mut(), failures);
        }
    }

    /// Adds the generated partials of contact forward dynamics (`R = NV + 2K` rows, see
    /// [`ContactKkt::contact_dynamics_derivatives`]) where
    /// [`ContactKkt::contact_dynamics_derivatives_in_place`] expects them: rows `0..NV` onto
    /// `da_dq` (which holds `d tau / dq` of inverse dynamics), rows `NV..NV + K` into `df_dq`,
    /// the last `K` into `df_dv`. Errors (`NonFinite` at pivot 0) when `R != NV + 2K`.
    pub fn add_partials<const R: usize>(
        &mut self,
        partials: &[[T; NV]; R],
    ) -> Result<(), FactorError> {
        if R != NV + 2 * K {
            return Err(FactorError::NonFinite { pivot: 0 });
        }
        for (t, p) in self.da_dq.iter_mut().zip(partials) {
            axpy(t, T::one(), p);
        }
        self.df_dq.copy_from_slice(&partials[NV..NV + K]);
        self.df_dv.copy_from_slice(&partials[NV + K..]);
        Ok(())
    }

    /// Every entry NaN (what the methods without `try_` return when the problem is singular).
    pub fn nan() -> Self {
        let (a, f) = ([[T::nan(); NV]; NV], [[T::nan(); NV]; K]);
        ContactDynamicsDerivatives {
            da_dq: a,
            da_dv: a,
            da_dtau: a,
            df_dq: f,
            df_dv: f,
            df_dtau: f,
        }
    }
}

/// The derivatives of impulse dynamics (`impulse_dynamics_derivatives`), as Pinocchio's
/// `computeImpulseDynamicsDerivatives` but of the velocity after the impact: `dv_dv` is
/// d v_after / d v_before (Pinocchio's derivative of the jump plus the identity). Element
/// `[i][j]` = d out_i / d in_j, `q` perturbed in the tangent space.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct ImpulseDynamicsDerivatives<T, const NV: usize, const K: usize> {
    /// d v_after / d q, NV x NV.
    pub dv_dq: [[T; NV]; NV],
    /// d v_after / d v_before, NV x NV.
    pub dv_dv: [[T; NV]; NV],
    /// d impulses / d q, K x NV.
    pub dimpulse_dq: [[T; NV]; K],
    /// d impulses / d v_before, K x NV.
    pub dimpulse_dv: [[T; NV]; K],
}

impl<T: Lane, const NV: usize, const K: usize> ImpulseDynamicsDerivatives<T, NV, K> {
    /// Sets every entry to NaN, in place.
    pub fn fill_nan(&mut self) {
        for m in [&mut self.dv_dq, &mut self.dv_dv] {
            m.iter_mut().flatten().for_each(|x| *x = T::nan());
        }
        for m in [&mut self.dimpulse_dq, &mut self.dimpulse_dv] {
            m.iter_mut().flatten().for_each(|x| *x = T::nan());
        }
    }

    /// NaN in every entry of the lanes that recorded a failure, as
    /// [`ContactDynamicsDerivatives::nan_failed`].
    pub fn nan_failed(&mut self, failures: &T::Failures) {
        for m in [&mut self.dv_dq, &mut self.dv_dv] {
            crate::lane::nan_failed_in(m.as_flattened_mut(), failures);
        }
        for m in [&mut self.dimpulse_dq, &mut self.dimpulse_dv] {
            crate::lane::nan_failed_in(m.as_flattened_mut(), failures);
        }
    }

    /// Sets the generated partials of impulse dynamics (`R = NV + K` rows, see
    /// [`ContactKkt::impulse_derivatives`]) where
    /// [`ContactKkt::impulse_derivatives_in_place`] expects them: rows `0..NV` into `dv_dq`, the
    /// last `K` into `dimpulse_dq`. Errors (`NonFinite` at pivot 0) when `R != NV + K`.
    pub fn set_partials<const R: usize>(
        &mut self,
        partials: &[[T; NV]; R],
    ) -> Result<(), FactorError> {
        if R != NV + K {
            return Err(FactorError::NonFinite { pivot: 0 });
        }
        self.dv_dq.copy_from_slice(&partials[..NV]);
        self.dimpulse_dq.copy_from_slice(&partials[NV..]);
        Ok(())
    }

    /// Every entry NaN.
    pub fn nan() -> Self {
        let (v, p) = ([[T::nan(); NV]; NV], [[T::nan(); NV]; K]);
        ImpulseDynamicsDerivatives {
            dv_dq: v,
            dv_dv: v,
            dimpulse_dq: p,
            dimpulse_dv: p,
        }
    }
}

/// Completes the system whose `M`'s `L^T D L` factors and contact Jacobian are in `factors`
/// and `j`: zeroes the inactive rows of `J`, writes `Y = M^-1 J^T` into `y` (row `k` a column)
/// and returns the Cholesky factor of `J M^-1 J^T` (the identity's rows and columns for
/// inactive rows). `P` substitutes through the factors. A pivot of `J M^-1 J^T` that fails is
/// pivot `N + k` ([`Lane::check_pivot`]: a scalar returns it, a vector records it in
/// `failures`).
fn factorize<P: TreePasses<T, N>, T: Lane, const N: usize, const K: usize>(
    factors: &[[T; N]; N],
    j: &mut [[T; N]; K],
    y: &mut [[T; N]; K],
    (parent, active): (&[Option<usize>; N], &[bool; K]),
    failures: &mut T::Failures,
) -> Result<Cholesky<T, K>, FactorError> {
    for (jk, on) in j.iter_mut().zip(active) {
        if !*on {
            *jk = [T::zero(); N];
        }
    }
    // Y^T = M^-1 J^T, all K columns in one substitution.
    let mut yt = [[T::zero(); K]; N];
    for (i, row) in yt.iter_mut().enumerate() {
        for (x, jk) in row.iter_mut().zip(j.iter()) {
            *x = jk[i];
        }
    }
    P::substitute_rows(factors, parent, &mut yt);
    for (k, yk) in y.iter_mut().enumerate() {
        for (y, row) in yk.iter_mut().zip(&yt) {
            *y = row[k];
        }
    }
    // J Y^T as N rank-one updates (column i of J times row i of Y^T): the K x K sums are
    // independent chains the processor overlaps, where K^2 / 2 dot products (a fifth of
    // impulse dynamics on a quadruped), and then K rows each gathered over N dependent
    // multiply-adds, were chains. Inactive rows of J are zero; their diagonal becomes one.
    let mut lambda = [[T::zero(); K]; K];
    for (i, yti) in yt.iter().enumerate() {
        for (lr, jr) in lambda.iter_mut().zip(j.iter()) {
            let s = jr[i];
            for (l, v) in lr.iter_mut().zip(yti) {
                *l = s.mul_add(*v, *l);
            }
        }
    }
    for (r, lr) in lambda.iter_mut().enumerate() {
        if !active[r] {
            lr[r] = T::one();
        }
    }
    // Exactly symmetric: the lower triangle mirrored.
    for c in 1..K {
        let (upper, lower) = lambda.split_at_mut(c);
        for (r, above) in upper.iter_mut().enumerate() {
            above[c] = lower[0][r];
        }
    }
    Cholesky::factor(lambda, N, failures)
}

/// The arrays of a factorized system, wherever they lie ([`ContactKkt`], or a result and a
/// [`KktStash`]).
///
/// The contact Jacobian is an argument of the methods that read it, not a part: the
/// derivatives' last solve writes over it while it reads the others.
struct Parts<'a, T, const N: usize, const K: usize> {
    factors: &'a [[T; N]; N],
    parent: &'a [Option<usize>; N],
    y: &'a [[T; N]; K],
    lambda: &'a Cholesky<T, K>,
    active: &'a [bool; K],
}

impl<T: Lane, const N: usize, const K: usize> Parts<'_, T, N, K> {
    /// [`ContactKkt::solve`] with the contact Jacobian `j`; `top = None` stands for zeros
    /// (impulse dynamics), whose substitution through `M` is skipped.
    fn solve(
        &self,
        j: &[[T; N]; K],
        top: Option<&[T; N]>,
        bottom: &[T; K],
        failures: &mut T::Failures,
    ) -> Result<([T; N], [T; K]), FactorError> {
        let substitute = |b: &[T; N]| ltdl_substitute(self.factors, self.parent, b);
        self.solve_with(j, top, bottom, substitute, failures)
    }

    /// [`Parts::solve`] with the caller's `M^-1 b` from the factors (`substitute`).
    fn solve_with(
        &self,
        j: &[[T; N]; K],
        top: Option<&[T; N]>,
        bottom: &[T; K],
        substitute: impl Fn(&[T; N]) -> [T; N],
        failures: &mut T::Failures,
    ) -> Result<([T; N], [T; K]), FactorError> {
        let mut x = match top {
            Some(top) => substitute(top),
            None => [T::zero(); N],
        };
        let mut b = *bottom;
        for ((bk, jk), on) in b.iter_mut().zip(j).zip(self.active) {
            *bk = if *on { *bk - dot(jk, &x) } else { T::zero() };
        }
        let f = self.lambda.solve(&b);
        for (yk, fk) in self.y.iter().zip(&f) {
            for (xi, yi) in x.iter_mut().zip(yk) {
                *xi += *yi * *fk;
            }
        }
        finite_solution(x, f, failures)
    }

    /// The solution for `(sign top, sign bottom)`, `sign` one or minus one: with
    /// `X0 = M^-1 top`, `F = Lambda^-1 sign (bottom - J X0)` and `X = sign X0 + Y F`.
    /// `P` substitutes through `M`'s factors; `Lambda^-1` is a product with `inverse` when
    /// given ([`Cholesky::inverse`]), else two triangular substitutions.
    fn solve_signed_columns_in_place<P: TreePasses<T, N>, const C: usize>(
        &self,
        (j, inverse): (&[[T; N]; K], Option<&[[T; K]; K]>),
        x: &mut [[T; C]; N],
        f: &mut [[T; C]; K],
        sign: T,
    ) {
        P::substitute_rows(self.factors, self.parent, x);
        for ((fk, jk), on) in f.iter_mut().zip(j).zip(self.active) {
            if !*on {
                *fk = [T::zero(); C];
                continue;
            }
            // Each row gathered in a local accumulator (kept in registers), not updated in
            // memory once per term: that form was vectorized across rows, with gathers.
            // The zeros of `J` (a contact's row is zero outside its chain) are skipped; on a
            // vector, where every lane's entry is zero.
            let mut acc = scaled(fk, sign);
            for (jki, xi) in jk.iter().zip(x.iter()) {
                if !jki.zero_in_every_lane() {
                    axpy(&mut acc, -sign * *jki, xi);
                }
            }
            *fk = acc;
        }
        self.lambda_apply(inverse, f);
        self.add_y_times(x, f, sign);
    }

    /// `Lambda^-1 B` in place: a product with `inverse`, or the triangular substitutions.
    fn lambda_apply<const C: usize>(&self, inverse: Option<&[[T; K]; K]>, b: &mut [[T; C]; K]) {
        match inverse {
            Some(inv) => times_columns(inv, b),
            None => self.lambda_solve_columns(b),
        }
    }

    /// `X = sign X + Y F` (`Y = M^-1 J^T`), row by row, each gathered in a local accumulator.
    fn add_y_times<const C: usize>(&self, x: &mut [[T; C]; N], f: &[[T; C]; K], sign: T) {
        for (i, xi) in x.iter_mut().enumerate() {
            let mut acc = scaled(xi, sign);
            for (yk, fk) in self.y.iter().zip(f.iter()) {
                axpy(&mut acc, yk[i], fk);
            }
            *xi = acc;
        }
    }

    /// [`ContactKkt::solve_identity_in_place`] with `M^-1` from the passes `P`.
    fn solve_identity_in_place_by<P: TreePasses<T, N>>(
        &self,
        inverse: Option<&[[T; K]; K]>,
        x: &mut [[T; N]; N],
        f: &mut [[T; N]; K],
    ) {
        P::inverse_into(self.factors, self.parent, x);
        for (fk, (yk, on)) in f.iter_mut().zip(self.y.iter().zip(self.active)) {
            *fk = if *on {
                scaled(yk, -T::one())
            } else {
                [T::zero(); N]
            };
        }
        self.lambda_apply(inverse, f);
        self.add_y_times(x, f, T::one());
    }

    /// `(J M^-1 J^T)^-1 B` for the K x C matrix `B`, in place.
    fn lambda_solve_columns<const C: usize>(&self, b: &mut [[T; C]; K]) {
        let l = self.lambda.l();
        // L y = b, then L^T x = y, each row gathered in a local accumulator.
        for (i, li) in l.iter().enumerate() {
            let (done, rest) = b.split_at_mut(i);
            let mut acc = rest[0];
            for (lik, bk) in li.iter().zip(done.iter()) {
                axpy(&mut acc, -*lik, bk);
            }
            scale(&mut acc, T::one() / li[i]);
            rest[0] = acc;
        }
        for i in (0..K).rev() {
            let (head, tail) = b.split_at_mut(i + 1);
            let mut acc = head[i];
            for (lk, bk) in l[i + 1..].iter().zip(tail.iter()) {
                axpy(&mut acc, -lk[i], bk);
            }
            scale(&mut acc, T::one() / l[i][i]);
            head[i] = acc;
        }
    }
}

/// What a [`ContactKkt`] keeps of itself while its two largest arrays lie in a result
/// ([`ContactKkt::set_up_in`]): the coordinate tree, `M^-1 J^T`, the factor of `J M^-1 J^T` and
/// the active rows (`8 K N + 16 N + 8 K^2` bytes where the system is `8 (N^2 + 2 K N)`).
#[derive(Clone, Copy, Debug)]
pub struct KktStash<T, const N: usize, const K: usize> {
    parent: [Option<usize>; N],
    y: [[T; N]; K],
    lambda: Cholesky<T, K>,
    active: [bool; K],
}

impl<T: Lane, const N: usize, const K: usize> KktStash<T, N, K> {
    /// A stash for the system of the coordinate tree `parent` and the contact rows `active`,
    /// before [`ContactKkt::set_up_in_stash_by`] sets it up (`Y` zero, `J M^-1 J^T` the
    /// identity).
    pub fn new(parent: &[Option<usize>; N], active: &[bool; K]) -> Self {
        KktStash {
            parent: *parent,
            y: [[T::zero(); N]; K],
            lambda: Cholesky::identity(),
            active: *active,
        }
    }

    /// [`KktStash::solve_with`] on a vector of states ([`Lane`], one state per lane): a lane
    /// whose solution is not finite records its error in `failures` (a scalar returns it).
    pub fn solve_with_lanes(
        &self,
        d: &ContactDynamicsDerivatives<T, N, K>,
        (top, bottom): (&[T; N], &[T; K]),
        substitute: impl Fn(&[T; N]) -> [T; N],
        failures: &mut T::Failures,
    ) -> Result<([T; N], [T; K]), FactorError> {
        self.parts(d)
            .solve_with(&d.df_dtau, Some(top), bottom, substitute, failures)
    }

    /// The arrays of the system stashed in `d`, for [`Parts`]' methods.
    fn parts<'a>(&'a self, d: &'a ContactDynamicsDerivatives<T, N, K>) -> Parts<'a, T, N, K> {
        self.over(&d.da_dtau)
    }

    /// The stashed arrays with `M`'s factors `factors`.
    fn over<'a>(&'a self, factors: &'a [[T; N]; N]) -> Parts<'a, T, N, K> {
        Parts {
            factors,
            parent: &self.parent,
            y: &self.y,
            lambda: &self.lambda,
            active: &self.active,
        }
    }

    /// [`KktStash::contact_dynamics_derivatives_in_place_by`] on a vector of states: a lane
    /// with a non-finite derivative records its error in `failures` (a scalar returns it).
    #[inline(never)]
    pub fn contact_dynamics_derivatives_lanes<P: TreePasses<T, N>>(
        &self,
        d: &mut ContactDynamicsDerivatives<T, N, K>,
        failures: &mut T::Failures,
    ) -> Result<(), FactorError> {
        let ContactDynamicsDerivatives {
            da_dq,
            da_dv,
            da_dtau,
            df_dq,
            df_dv,
            df_dtau,
        } = d;
        let (minus, inverse) = (-T::one(), self.lambda.inverse());
        let parts = self.over(da_dtau);
        let system = (&*df_dtau, Some(&inverse));
        parts.solve_signed_columns_in_place::<P, N>(system, da_dq, df_dq, minus);
        parts.solve_signed_columns_in_place::<P, N>(system, da_dv, df_dv, minus);
        let factors = *da_dtau;
        self.over(&factors)
            .solve_identity_in_place_by::<P>(Some(&inverse), da_dtau, df_dtau);
        finite_derivatives(d, failures)
    }
}

impl<T: Real, const N: usize, const K: usize> KktStash<T, N, K> {
    /// [`ContactKkt::solve`] of the system set up in `d` by [`ContactKkt::set_up_in`].
    pub fn solve(
        &self,
        d: &ContactDynamicsDerivatives<T, N, K>,
        top: &[T; N],
        bottom: &[T; K],
    ) -> Result<([T; N], [T; K]), FactorError> {
        self.parts(d).solve(&d.df_dtau, Some(top), bottom, &mut ())
    }

    /// [`KktStash::solve`] with the caller's own `M^-1 b` from the factors in `d.da_dtau`
    /// (`substitute`): generated code passes its unrolled substitution.
    pub fn solve_with(
        &self,
        d: &ContactDynamicsDerivatives<T, N, K>,
        top: &[T; N],
        bottom: &[T; K],
        substitute: impl Fn(&[T; N]) -> [T; N],
    ) -> Result<([T; N], [T; K]), FactorError> {
        self.solve_with_lanes(d, (top, bottom), substitute, &mut ())
    }

    /// [`ContactKkt::contact_dynamics_derivatives_in_place`] of the system stashed in `d`,
    /// whose `da_dq`, `da_dv`, `df_dq` and `df_dv` hold the right-hand sides by then. The
    /// system is set up again in this function's own frame, so that it is never on the stack
    /// while the caller computes them.
    #[inline(never)]
    pub fn contact_dynamics_derivatives_in_place(
        &self,
        d: &mut ContactDynamicsDerivatives<T, N, K>,
    ) -> Result<(), FactorError> {
        self.contact_dynamics_derivatives_in_place_by::<Walked>(d)
    }

    /// [`KktStash::contact_dynamics_derivatives_in_place`] with the passes `P`, as
    /// [`ContactKkt::contact_dynamics_derivatives_in_place_by`]. The system's arrays in `d`
    /// are read where they lie; only `M`'s factors are copied, before the solve for `tau`
    /// writes `M^-1` over them.
    pub fn contact_dynamics_derivatives_in_place_by<P: TreePasses<T, N>>(
        &self,
        d: &mut ContactDynamicsDerivatives<T, N, K>,
    ) -> Result<(), FactorError> {
        self.contact_dynamics_derivatives_lanes::<P>(d, &mut ())
    }
}

/// The factorized KKT system of `N` velocity coordinates and `K` contact rows (module
/// documentation).
#[derive(Clone, Copy, Debug)]
pub struct ContactKkt<T, const N: usize, const K: usize> {
    /// The `L^T D L` factors of `M` ([`ltdl_factor`]).
    pub(crate) factors: [[T; N]; N],
    parent: [Option<usize>; N],
    /// The contact Jacobian.
    j: [[T; N]; K],
    /// Row `k` is `M^-1` times row `k` of `J` (a column of `Y = M^-1 J^T`).
    y: [[T; N]; K],
    /// `J M^-1 J^T` (the identity's rows and columns for inactive rows).
    lambda: Cholesky<T, K>,
    /// Which contact rows take part ([`ContactKkt::new_active`]).
    active: [bool; K],
}

impl<T: Real, const N: usize, const K: usize> ContactKkt<T, N, K> {
    /// Factorizes the system of the mass matrix `m`, whose coordinate `i` has the parent
    /// coordinate `parent[i]`, and the contact Jacobian `j`.
    ///
    /// Errors: a pivot of `M` that is not positive (`pivot < N`), or of `J M^-1 J^T` (pivot
    /// `N + k`: a rank-deficient `J`), or a non-finite one.
    pub fn new(
        m: [[T; N]; N],
        parent: &[Option<usize>; N],
        j: [[T; N]; K],
    ) -> Result<Self, FactorError> {
        Self::new_active(m, parent, j, &[true; K])
    }

    /// [`ContactKkt::new`] with only the contact rows `k` where `active[k]` holds (contacts
    /// switched at run time; [`crate::contact::row_mask`] gives the rows of a set of
    /// contacts): the inactive rows of `J` are zeroed and those of `J M^-1 J^T` replaced by
    /// the identity's, and every solve gives them zero forces, so that the solutions are those
    /// of the system of the active rows alone (inactive rows of `f` zero). Every row active:
    /// [`ContactKkt::new`], to the bit.
    ///
    /// ```
    /// use eomgen_runtime::ContactKkt;
    /// // A unit point mass in the plane, held vertically only: free along x.
    /// let j = [[1.0_f64, 0.0], [0.0, 1.0]];
    /// let kkt = ContactKkt::new_active([[1.0, 0.0], [0.0, 1.0]], &[None, None], j, &[false, true])
    ///     .unwrap();
    /// let (a, f) = kkt.solve(&[2.0, -9.81], &[0.0, 0.0]).unwrap();
    /// assert_eq!((a, f), ([2.0, 0.0], [0.0, 9.81]));
    /// ```
    pub fn new_active(
        m: [[T; N]; N],
        parent: &[Option<usize>; N],
        j: [[T; N]; K],
        active: &[bool; K],
    ) -> Result<Self, FactorError> {
        let mut kkt = Self::zeroed();
        kkt.set_up(
            |mm, jj| {
                *mm = m;
                *jj = j;
            },
            parent,
            active,
        )?;
        Ok(kkt)
    }

    /// [`ContactKkt::new_active`] in place, so that a caller keeps one copy of the system
    /// (about `8 N^2` bytes) rather than building it and moving it: `fill` writes the mass
    /// matrix and the contact Jacobian into the storage it is given, then the system is
    /// factorized there. On failure `self` holds a partial factorization and solves give
    /// garbage; set it up again before use.
    pub fn set_up(
        &mut self,
        fill: impl FnOnce(&mut [[T; N]; N], &mut [[T; N]; K]),
        parent: &[Option<usize>; N],
        active: &[bool; K],
    ) -> Result<(), FactorError> {
        let fill = |m: &mut [[T; N]; N], j: &mut _| {
            fill(m, j);
            ltdl_factor(m, parent)
        };
        self.set_up_factored(fill, parent, active)
    }

    /// [`ContactKkt::set_up`] for a `fill` that writes `M`'s `L^T D L` factors over the
    /// coordinate tree `parent` (as [`ltdl_factor`] leaves them), not `M`: a caller with a
    /// faster factorization of its own, as generated code has one unrolled for the robot's
    /// tree. An error of `fill` is returned as it is.
    ///
    /// ```
    /// use eomgen_runtime::{tree::ltdl_factor, ContactKkt};
    /// let (m, j, parent) = ([[2.0_f64, 0.5], [0.5, 1.0]], [[1.0, 1.0]], [None, Some(0)]);
    /// let kkt = ContactKkt::new(m, &parent, j).unwrap();
    /// let mut own = ContactKkt::zeroed();
    /// let fill = |mm: &mut [[f64; 2]; 2], jj: &mut [[f64; 2]; 1]| {
    ///     (*mm, *jj) = (m, j);
    ///     ltdl_factor(mm, &parent)
    /// };
    /// own.set_up_factored(fill, &parent, &[true]).unwrap();
    /// assert_eq!(own.solve(&[1.0, 2.0], &[0.5]), kkt.solve(&[1.0, 2.0], &[0.5]));
    /// ```
    pub fn set_up_factored(
        &mut self,
        fill: impl FnOnce(&mut [[T; N]; N], &mut [[T; N]; K]) -> Result<(), FactorError>,
        parent: &[Option<usize>; N],
        active: &[bool; K],
    ) -> Result<(), FactorError> {
        self.set_up_factored_by::<Walked>(fill, parent, active)
    }

    /// [`ContactKkt::set_up_factored`] with `M^-1 J^T` from the passes `P` (generated code's
    /// own, unrolled for the robot's tree; [`Walked`]: the runtime's).
    ///
    /// ```
    /// use eomgen_runtime::tree::{ltdl_factor, Walked};
    /// use eomgen_runtime::ContactKkt;
    /// let (m, j, parent) = ([[2.0_f64, 0.5], [0.5, 1.0]], [[1.0, 1.0]], [None, Some(0)]);
    /// let fill = |mm: &mut [[f64; 2]; 2], jj: &mut [[f64; 2]; 1]| {
    ///     (*mm, *jj) = (m, j);
    ///     ltdl_factor(mm, &parent)
    /// };
    /// let mut kkt = ContactKkt::zeroed();
    /// kkt.set_up_factored_by::<Walked>(fill, &parent, &[true]).unwrap();
    /// // The derivatives in tau: da/dtau = M^-1 - Y (J M^-1 J^T)^-1 Y^T, whose J row is zero.
    /// let (mut x, mut f) = ([[0.0; 2]; 2], [[0.0; 2]; 1]);
    /// kkt.solve_identity_in_place(&mut x, &mut f);
    /// let jx: Vec<f64> = (0..2).map(|c| x[0][c] + x[1][c]).collect();
    /// assert!(jx.iter().all(|v| v.abs() < 1e-15));
    /// let walked = ContactKkt::new(m, &parent, j).unwrap();
    /// assert_eq!(kkt.solve(&[1.0, 2.0], &[0.5]), walked.solve(&[1.0, 2.0], &[0.5]));
    /// ```
    pub fn set_up_factored_by<P: TreePasses<T, N>>(
        &mut self,
        fill: impl FnOnce(&mut [[T; N]; N], &mut [[T; N]; K]) -> Result<(), FactorError>,
        parent: &[Option<usize>; N],
        active: &[bool; K],
    ) -> Result<(), FactorError> {
        self.set_up_factored_lanes::<P>(|m, j, _| fill(m, j), (parent, active), &mut ())
    }

    /// [`ContactKkt::set_up`] with the system's two largest arrays in the parts of `d` that
    /// [`ContactKkt::contact_dynamics_derivatives_in_place`] only writes: `M`'s factors in
    /// `da_dtau`, `J` in `df_dtau`; the rest is returned. A caller then never holds the system
    /// (on a 50-coordinate humanoid with two soles, 25 kB) on its stack while it computes the
    /// inverse-dynamics derivatives and the partials into `d`'s other fields.
    ///
    /// ```
    /// use eomgen_runtime::{ContactDynamicsDerivatives, ContactKkt};
    /// let (m, j) = ([[2.0_f64, 0.5], [0.5, 1.0]], [[1.0, 1.0]]);
    /// let kkt = ContactKkt::new(m, &[None, Some(0)], j).unwrap();
    /// let mut d = ContactDynamicsDerivatives::<f64, 2, 1>::nan();
    /// let fill = |mm: &mut [[f64; 2]; 2], jj: &mut [[f64; 2]; 1]| (*mm, *jj) = (m, j);
    /// let stash = ContactKkt::set_up_in(&mut d, fill, &[None, Some(0)], &[true]).unwrap();
    /// assert_eq!(stash.solve(&d, &[1.0, 2.0], &[0.5]), kkt.solve(&[1.0, 2.0], &[0.5]));
    /// ```
    pub fn set_up_in(
        d: &mut ContactDynamicsDerivatives<T, N, K>,
        fill: impl FnOnce(&mut [[T; N]; N], &mut [[T; N]; K]),
        parent: &[Option<usize>; N],
        active: &[bool; K],
    ) -> Result<KktStash<T, N, K>, FactorError> {
        let fill = |m: &mut [[T; N]; N], j: &mut _| {
            fill(m, j);
            ltdl_factor(m, parent)
        };
        Self::set_up_in_factored(d, fill, parent, active)
    }

    /// [`ContactKkt::set_up_in`] for a `fill` that writes `M`'s factors, as
    /// [`ContactKkt::set_up_factored`].
    ///
    /// ```
    /// use eomgen_runtime::{tree::ltdl_factor, ContactDynamicsDerivatives, ContactKkt};
    /// let (m, j, parent) = ([[2.0_f64, 0.5], [0.5, 1.0]], [[1.0, 1.0]], [None, Some(0)]);
    /// let kkt = ContactKkt::new(m, &parent, j).unwrap();
    /// let mut d = ContactDynamicsDerivatives::<f64, 2, 1>::nan();
    /// let fill = |mm: &mut [[f64; 2]; 2], jj: &mut [[f64; 2]; 1]| {
    ///     (*mm, *jj) = (m, j);
    ///     ltdl_factor(mm, &parent)
    /// };
    /// let stash = ContactKkt::set_up_in_factored(&mut d, fill, &parent, &[true]).unwrap();
    /// assert_eq!(stash.solve(&d, &[1.0, 2.0], &[0.5]), kkt.solve(&[1.0, 2.0], &[0.5]));
    /// ```
    pub fn set_up_in_factored(
        d: &mut ContactDynamicsDerivatives<T, N, K>,
        fill: impl FnOnce(&mut [[T; N]; N], &mut [[T; N]; K]) -> Result<(), FactorError>,
        parent: &[Option<usize>; N],
        active: &[bool; K],
    ) -> Result<KktStash<T, N, K>, FactorError> {
        Self::set_up_in_factored_by::<Walked>(d, fill, parent, active)
    }

    /// [`ContactKkt::set_up_in_factored`] with `M^-1 J^T` from the passes `P`, as
    /// [`ContactKkt::set_up_factored_by`].
    pub fn set_up_in_factored_by<P: TreePasses<T, N>>(
        d: &mut ContactDynamicsDerivatives<T, N, K>,
        fill: impl FnOnce(&mut [[T; N]; N], &mut [[T; N]; K]) -> Result<(), FactorError>,
        parent: &[Option<usize>; N],
        active: &[bool; K],
    ) -> Result<KktStash<T, N, K>, FactorError> {
        let mut stash = KktStash::new(parent, active);
        Self::set_up_in_stash_by::<P>(d, &mut stash, fill)?;
        Ok(stash)
    }

    /// [`ContactKkt::set_up_in_factored_by`] into the caller's `stash` (from
    /// [`KktStash::new`], which says the system's tree and active rows): the stash is not
    /// returned, so a caller keeping it in its own frame copies none of its 3 kB (a
    /// quadruped's) on the way.
    ///
    /// ```
    /// use eomgen_runtime::{tree::{ltdl_factor, Walked}, ContactDynamicsDerivatives, ContactKkt, KktStash};
    /// let (m, j, parent) = ([[2.0_f64, 0.5], [0.5, 1.0]], [[1.0, 1.0]], [None, Some(0)]);
    /// let mut d = ContactDynamicsDerivatives::<f64, 2, 1>::nan();
    /// let mut stash = KktStash::new(&parent, &[true]);
    /// let fill = |mm: &mut [[f64; 2]; 2], jj: &mut [[f64; 2]; 1]| {
    ///     (*mm, *jj) = (m, j);
    ///     ltdl_factor(mm, &parent)
    /// };
    /// ContactKkt::set_up_in_stash_by::<Walked>(&mut d, &mut stash, fill).unwrap();
    /// let kkt = ContactKkt::new(m, &parent, j).unwrap();
    /// assert_eq!(stash.solve(&d, &[1.0, 2.0], &[0.5]), kkt.solve(&[1.0, 2.0], &[0.5]));
    /// ```
    pub fn set_up_in_stash_by<P: TreePasses<T, N>>(
        d: &mut ContactDynamicsDerivatives<T, N, K>,
        stash: &mut KktStash<T, N, K>,
        fill: impl FnOnce(&mut [[T; N]; N], &mut [[T; N]; K]) -> Result<(), FactorError>,
    ) -> Result<(), FactorError> {
        Self::set_up_in_stash_lanes::<P>(d, stash, |m, j, _| fill(m, j), &mut ())
    }

    /// The system that [`ContactKkt::set_up_in`] left in `d` and `stash`.
    pub fn from_stash(stash: &KktStash<T, N, K>, d: &ContactDynamicsDerivatives<T, N, K>) -> Self {
        ContactKkt {
            factors: d.da_dtau,
            parent: stash.parent,
            j: d.df_dtau,
            y: stash.y,
            lambda: stash.lambda,
            active: stash.active,
        }
    }

    /// Solves the system for one right-hand side `(top, bottom)`: `(x, f)`. Contact forward
    /// dynamics is `solve(tau - h, -drift)`; a non-finite component of `x` (`pivot < N`) or
    /// `f` (`N + k`) is an error.
    pub fn solve(&self, top: &[T; N], bottom: &[T; K]) -> Result<([T; N], [T; K]), FactorError> {
        self.parts().solve(&self.j, Some(top), bottom, &mut ())
    }

    /// [`ContactKkt::solve`] with `top = 0`: `x = M^-1 J^T f`, with no substitution of the
    /// zeros through `M` (impulse dynamics' system).
    pub fn solve_bottom(&self, bottom: &[T; K]) -> Result<([T; N], [T; K]), FactorError> {
        self.solve_bottom_lanes(bottom, &mut ())
    }
}

impl<T: Lane, const N: usize, const K: usize> ContactKkt<T, N, K> {
    /// A system of zeros, for [`ContactKkt::set_up`] to set up where it lies.
    pub fn zeroed() -> Self {
        ContactKkt {
            factors: [[T::zero(); N]; N],
            parent: [None; N],
            j: [[T::zero(); N]; K],
            y: [[T::zero(); N]; K],
            lambda: Cholesky::identity(),
            active: [true; K],
        }
    }

    /// [`ContactKkt::set_up_factored_by`] on a vector of states ([`Lane`], one state per lane):
    /// `fill` writes `M`'s factors and `J` and checks `M`'s pivots with the `failures` it is
    /// given; a lane whose pivot of `J M^-1 J^T` fails records it there (pivot `N + k`; a
    /// scalar returns it) and holds garbage.
    ///
    /// ```
    /// use eomgen_runtime::{tree::{ltdl_factor, Walked}, ContactKkt, FactorError};
    /// // A unit point mass in the plane, its second coordinate held (a scalar's failures: `()`).
    /// let (parent, mut kkt) = ([None, None], ContactKkt::<f64, 2, 1>::zeroed());
    /// let fill = |m: &mut [[f64; 2]; 2], j: &mut [[f64; 2]; 1], _: &mut ()| {
    ///     (*m, *j) = ([[1.0, 0.0], [0.0, 1.0]], [[0.0, 1.0]]);
    ///     ltdl_factor(m, &parent)
    /// };
    /// kkt.set_up_factored_lanes::<Walked>(fill, (&parent, &[true]), &mut ()).unwrap();
    /// assert_eq!(kkt.solve(&[1.0, -9.81], &[0.0]), Ok(([1.0, 0.0], [9.81])));
    /// ```
    pub fn set_up_factored_lanes<P: TreePasses<T, N>>(
        &mut self,
        fill: impl FnOnce(
            &mut [[T; N]; N],
            &mut [[T; N]; K],
            &mut T::Failures,
        ) -> Result<(), FactorError>,
        (parent, active): (&[Option<usize>; N], &[bool; K]),
        failures: &mut T::Failures,
    ) -> Result<(), FactorError> {
        fill(&mut self.factors, &mut self.j, failures)?;
        (self.parent, self.active) = (*parent, *active);
        self.complete::<P>(failures)
    }

    /// The system of the mass matrix `m` and the contact Jacobian `j`, not yet factorized
    /// ([`ContactKkt::factor_lanes`] does that), over the coordinate tree `parent` with the
    /// contact rows of `active`.
    ///
    /// Made where it is returned to, with `m` and `j` the results of the calls that compute
    /// them, no array of the system is written twice: a system zeroed first and then filled
    /// ([`ContactKkt::zeroed`], [`ContactKkt::set_up_factored_lanes`]) wrote `M` and `J`
    /// three times, a humanoid's 30 kB (3 % of g1's impulse derivatives).
    ///
    /// ```
    /// use eomgen_runtime::{tree::{ltdl_factor, Walked}, ContactKkt};
    /// // A unit point mass in the plane, its second coordinate held.
    /// let parent = [None, None];
    /// let m = [[1.0_f64, 0.0], [0.0, 1.0]];
    /// let mut kkt = ContactKkt::unfactored(m, [[0.0, 1.0]], (&parent, &[true]));
    /// kkt.factor_lanes::<Walked>(|m, _: &mut ()| ltdl_factor(m, &parent), &mut ()).unwrap();
    /// assert_eq!(kkt.solve(&[1.0, -9.81], &[0.0]), Ok(([1.0, 0.0], [9.81])));
    /// ```
    #[inline(always)]
    pub fn unfactored(
        m: [[T; N]; N],
        j: [[T; N]; K],
        (parent, active): (&[Option<usize>; N], &[bool; K]),
    ) -> Self {
        ContactKkt {
            factors: m,
            parent: *parent,
            j,
            y: [[T::zero(); N]; K],
            lambda: Cholesky::identity(),
            active: *active,
        }
    }

    /// Factorizes a system made by [`ContactKkt::unfactored`]: `factor` factorizes `M` in
    /// place (its pivots checked with the `failures` it is given), then `J M^-1 J^T`, whose
    /// failed pivot is `N + k` (a scalar returns it; a vector records it in `failures`, and
    /// that lane holds garbage).
    pub fn factor_lanes<P: TreePasses<T, N>>(
        &mut self,
        factor: impl FnOnce(&mut [[T; N]; N], &mut T::Failures) -> Result<(), FactorError>,
        failures: &mut T::Failures,
    ) -> Result<(), FactorError> {
        factor(&mut self.factors, failures)?;
        self.complete::<P>(failures)
    }

    /// [`factorize`] where the system lies, `M`'s factors and `J` in place: `Y` and the
    /// factor of `J M^-1 J^T` (what [`ContactKkt::set_up_factored_lanes`] and
    /// [`ContactKkt::factor_lanes`] both finish with).
    fn complete<P: TreePasses<T, N>>(
        &mut self,
        failures: &mut T::Failures,
    ) -> Result<(), FactorError> {
        let ContactKkt {
            factors,
            parent,
            j,
            y,
            lambda,
            active,
        } = self;
        *lambda = factorize::<P, T, N, K>(factors, j, y, (parent, active), failures)?;
        Ok(())
    }

    /// [`ContactKkt::set_up_in_stash_by`] on a vector of states, as
    /// [`ContactKkt::set_up_factored_lanes`].
    pub fn set_up_in_stash_lanes<P: TreePasses<T, N>>(
        d: &mut ContactDynamicsDerivatives<T, N, K>,
        stash: &mut KktStash<T, N, K>,
        fill: impl FnOnce(
            &mut [[T; N]; N],
            &mut [[T; N]; K],
            &mut T::Failures,
        ) -> Result<(), FactorError>,
        failures: &mut T::Failures,
    ) -> Result<(), FactorError> {
        fill(&mut d.da_dtau, &mut d.df_dtau, failures)?;
        let (m, j, y) = (&mut d.da_dtau, &mut d.df_dtau, &mut stash.y);
        let tree = (&stash.parent, &stash.active);
        stash.lambda = factorize::<P, T, N, K>(m, j, y, tree, failures)?;
        Ok(())
    }

    /// Which contact rows take part (all of them for [`ContactKkt::new`]).
    pub fn active(&self) -> &[bool; K] {
        &self.active
    }

    /// The contact Jacobian the system was built with (inactive rows zeroed).
    pub fn jacobian(&self) -> &[[T; N]; K] {
        &self.j
    }

    /// [`ContactKkt::solve_bottom`] on a vector of states: a lane whose solution is not finite
    /// records its error in `failures` (a scalar returns it).
    pub(crate) fn solve_bottom_lanes(
        &self,
        bottom: &[T; K],
        failures: &mut T::Failures,
    ) -> Result<([T; N], [T; K]), FactorError> {
        self.parts().solve(&self.j, None, bottom, failures)
    }

    /// The system's arrays, for [`Parts`]' methods.
    fn parts(&self) -> Parts<'_, T, N, K> {
        Parts {
            factors: &self.factors,
            parent: &self.parent,
            y: &self.y,
            lambda: &self.lambda,
            active: &self.active,
        }
    }

    /// Solves the system for `C` right-hand sides at once, the columns of `top` (N x C) and
    /// `bottom` (K x C): `(X, F)`, N x C and K x C, one solution per column.
    pub fn solve_columns<const C: usize>(
        &self,
        top: &[[T; C]; N],
        bottom: &[[T; C]; K],
    ) -> ([[T; C]; N], [[T; C]; K]) {
        let (mut x, mut f) = (*top, *bottom);
        self.solve_columns_in_place(&mut x, &mut f);
        (x, f)
    }

    /// [`ContactKkt::solve_columns`] in place: `x` holds `top` on entry and `X` on return,
    /// `f` holds `bottom` and then `F`.
    pub fn solve_columns_in_place<const C: usize>(&self, x: &mut [[T; C]; N], f: &mut [[T; C]; K]) {
        self.solve_signed_columns_in_place::<Walked, C>(None, x, f, T::one());
    }

    /// [`ContactKkt::solve_columns_in_place`] for the negated right-hand sides `(-top,
    /// -bottom)` (what derivatives solve for: minus the partials), the signs applied on the
    /// way rather than in a pass over the inputs of their own.
    pub fn solve_negated_columns_in_place<const C: usize>(
        &self,
        x: &mut [[T; C]; N],
        f: &mut [[T; C]; K],
    ) {
        self.solve_signed_columns_in_place::<Walked, C>(None, x, f, -T::one());
    }

    /// The solution for `(sign top, sign bottom)`, `sign` one or minus one
    /// ([`Parts::solve_signed_columns_in_place`]), `Lambda^-1` a product with `inverse` when
    /// given.
    pub(crate) fn solve_signed_columns_in_place<P: TreePasses<T, N>, const C: usize>(
        &self,
        inverse: Option<&[[T; K]; K]>,
        x: &mut [[T; C]; N],
        f: &mut [[T; C]; K],
        sign: T,
    ) {
        self.parts()
            .solve_signed_columns_in_place::<P, C>((&self.j, inverse), x, f, sign);
    }

    /// `(J M^-1 J^T)^-1`, exactly symmetric ([`Cholesky::inverse`]): what the derivatives
    /// multiply their columns by.
    pub(crate) fn lambda_inverse(&self) -> [[T; K]; K] {
        self.lambda.inverse()
    }

    /// The system's solution for `top = I`, `bottom = 0` (its derivatives in `tau`), written
    /// into `x` (N x N) and `f` (K x N): `x = M^-1 + Y F` and `F = -(J M^-1 J^T)^-1 Y^T`, since
    /// `J M^-1 = Y^T`. `M^-1` comes from [`crate::tree::ltdl_inverse_factored_into`], which
    /// uses the identity's sparsity and the symmetry, and `J M^-1` is not formed again.
    pub fn solve_identity_in_place(&self, x: &mut [[T; N]; N], f: &mut [[T; N]; K]) {
        self.parts()
            .solve_identity_in_place_by::<Walked>(None, x, f);
    }

    /// `(J M^-1 J^T)^-1 B` for the K x C matrix `B`, in place.
    pub fn lambda_solve_columns<const C: usize>(&self, b: &mut [[T; C]; K]) {
        self.parts().lambda_solve_columns(b);
    }

    /// `M^-1 X` for the N x C matrix `X`, in place, through the tree factors
    /// ([`crate::tree::ltdl_substitute_rows`]).
    pub fn substitute_columns<const C: usize>(&self, x: &mut [[T; C]; N]) {
        crate::tree::ltdl_substitute_rows(&self.factors, &self.parent, x);
    }

    /// Row `k` of `J M^-1` (`Y^T`).
    pub fn inverse_inertia_rows(&self) -> &[[T; N]; K] {
        &self.y
    }
}

/// The columns `lo..hi` outside which every row of `j` is zero (an empty range for a zero
/// `j`). A contact Jacobian is zero in the columns of the joints that move no contact (a
/// humanoid's arms and waist for its soles: 17 of its 35 columns), and the products with it
/// skip them. Found from the ends inwards, so a typical Jacobian costs a few compares.
pub(crate) fn column_support<T: Lane, const N: usize, const K: usize>(
    j: &[[T; N]; K],
) -> core::ops::Range<usize> {
    let nonzero = |c: &usize| j.iter().any(|row| !row[*c].zero_in_every_lane());
    let lo = (0..N).find(nonzero).unwrap_or(N);
    let hi = (lo..N).rev().find(nonzero).map_or(lo, |c| c + 1);
    lo..hi
}

/// `a . b`. Inlined where it is called: bounded by `Lane`, the optimizer had stopped inlining
/// it (96 calls in the batch bench's binary, none before), in the contact solves' loops too.
#[inline]
pub(crate) fn dot<T: crate::Lane, const N: usize>(a: &[T; N], b: &[T; N]) -> T {
    // Eight partial sums, one per lane of a vector: one long chain of dependent additions was
    // a twentieth of a humanoid's impulse dynamics (twelve of them, 35 terms each).
    let mut part = [T::zero(); 8];
    let (ca, cb) = (a.chunks_exact(8), b.chunks_exact(8));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (xa, xb) in ca.zip(cb) {
        for ((p, x), y) in part.iter_mut().zip(xa).zip(xb) {
            *p = x.mul_add(*y, *p);
        }
    }
    for ((p, x), y) in part.iter_mut().zip(ra).zip(rb) {
        *p = x.mul_add(*y, *p);
    }
    let (lo, hi) = part.split_at(4);
    let quad: [T; 4] = core::array::from_fn(|i| lo[i] + hi[i]);
    (quad[0] + quad[2]) + (quad[1] + quad[3])
}

/// `B <- A B` for the K x K matrix `A` and the K x C matrix `B`: each row of the product
/// gathered in a local accumulator, the rows independent of each other.
pub(crate) fn times_columns<T: Lane, const K: usize, const C: usize>(
    a: &[[T; K]; K],
    b: &mut [[T; C]; K],
) {
    let src = *b;
    for (out, row) in b.iter_mut().zip(a) {
        let mut acc = [T::zero(); C];
        for (ak, bk) in row.iter().zip(&src) {
            axpy(&mut acc, *ak, bk);
        }
        *out = acc;
    }
}

fn scale<T: Lane, const C: usize>(y: &mut [T; C], a: T) {
    for yi in y.iter_mut() {
        *yi *= a;
    }
}

/// `(x, f)` if every entry is finite; else `NonFinite` at the first bad one of `x` (`pivot <
/// N`) or of `f` (`N + k`): how the system's solvers report a non-finite solution. On a vector
/// of states ([`crate::Lane`]) each lane's is recorded in `failures` instead.
pub(crate) fn finite_solution<T: crate::Lane, const N: usize, const K: usize>(
    x: [T; N],
    f: [T; K],
    failures: &mut T::Failures,
) -> Result<([T; N], [T; K]), FactorError> {
    crate::lane::check_finite(&x, failures)?;
    for (k, fk) in f.iter().enumerate() {
        T::check_finite(*fk, N + k, failures)?;
    }
    Ok((x, f))
}

/// `NonFinite` at the first row of `d`'s matrices with a non-finite entry: of `da_*` (`pivot
/// < N`) or `df_*` (`N + k`), in the order `dq`, `dv`, `tau`.
fn finite_derivatives<T: Lane, const N: usize, const K: usize>(
    d: &ContactDynamicsDerivatives<T, N, K>,
    failures: &mut T::Failures,
) -> Result<(), FactorError> {
    for m in [&d.da_dq, &d.da_dv, &d.da_dtau] {
        finite_rows(m, 0, failures)?;
    }
    for m in [&d.df_dq, &d.df_dv, &d.df_dtau] {
        finite_rows(m, N, failures)?;
    }
    Ok(())
}

/// `NonFinite` at `offset` plus the first row of `m` with a non-finite entry.
pub(crate) fn finite_rows<T: Lane, const C: usize, const R: usize>(
    m: &[[T; C]; R],
    offset: usize,
    failures: &mut T::Failures,
) -> Result<(), FactorError> {
    // `0 x` is zero for a finite `x` and NaN otherwise, and NaN stays in a sum: one pass of
    // multiply-adds the compiler vectorizes, without a branch per entry (a fortieth of a
    // quadruped's contact derivatives went to the comparisons). The rows are checked one by
    // one only when the sum says one is not finite (on a vector, in some lane).
    let (zero, mut sum) = (T::zero(), [T::zero(); C]);
    for row in m {
        for (s, x) in sum.iter_mut().zip(row) {
            *s = zero.mul_add(*x, *s);
        }
    }
    if sum.iter().all(|s| s.zero_in_every_lane()) {
        return Ok(());
    }
    for (i, row) in m.iter().enumerate() {
        for x in row {
            T::check_finite(*x, offset + i, failures)?;
        }
    }
    Ok(())
}

impl<T: Real, const N: usize, const K: usize> ContactKkt<T, N, K> {
    /// The derivatives of contact forward dynamics at its solution `(a, f)`, from the
    /// derivatives of inverse dynamics at `(q, v, a)` (`did_dq`, `did_dv`) and the generated
    /// `partials` (`R = N + 2K` rows: `d(-J^T f)/dq` at fixed `f`, `d(J a + drift)/dq` at fixed
    /// `a`, `d drift/dv`). Differentiating `M a + h - J^T f = tau`, `J a + drift = 0`:
    /// `[M -J^T; J 0] [da; df] = [-(did_dx + d(-J^T f)/dx); -d(J a + drift)/dx]` for `x = q`,
    /// `v`, and `[I; 0]` for `tau`.
    ///
    /// Errors: `NonFinite` at the first row of `da` (`pivot < N`) or `df` (`N + k`) with a
    /// non-finite entry, or at `pivot` 0 when `R != N + 2K`.
    pub fn contact_dynamics_derivatives<const R: usize>(
        &self,
        did_dq: &[[T; N]; N],
        did_dv: &[[T; N]; N],
        partials: &[[T; N]; R],
    ) -> Result<ContactDynamicsDerivatives<T, N, K>, FactorError> {
        let mut d = ContactDynamicsDerivatives {
            da_dq: *did_dq,
            da_dv: *did_dv,
            da_dtau: [[T::zero(); N]; N],
            df_dq: [[T::zero(); N]; K],
            df_dv: [[T::zero(); N]; K],
            df_dtau: [[T::zero(); N]; K],
        };
        d.add_partials(partials)?;
        self.contact_dynamics_derivatives_in_place(&mut d)?;
        Ok(d)
    }

    /// [`ContactKkt::contact_dynamics_derivatives`] in `d`, which holds on entry what
    /// [`ContactDynamicsDerivatives::add_partials`] leaves (after `d.da_dq` and `d.da_dv` were
    /// set to the derivatives of inverse dynamics): no matrix is copied, so that a caller can
    /// have them written straight into its result.
    pub fn contact_dynamics_derivatives_in_place(
        &self,
        d: &mut ContactDynamicsDerivatives<T, N, K>,
    ) -> Result<(), FactorError> {
        self.contact_dynamics_derivatives_in_place_by::<Walked>(d)
    }

    /// [`ContactKkt::contact_dynamics_derivatives_in_place`] with the substitutions and
    /// `M^-1` from the passes `P` (generated code's own, unrolled for the robot's tree).
    pub fn contact_dynamics_derivatives_in_place_by<P: TreePasses<T, N>>(
        &self,
        d: &mut ContactDynamicsDerivatives<T, N, K>,
    ) -> Result<(), FactorError> {
        let (minus, inverse) = (-T::one(), self.lambda.inverse());
        let (parts, system) = (self.parts(), (&self.j, Some(&inverse)));
        parts.solve_signed_columns_in_place::<P, N>(system, &mut d.da_dq, &mut d.df_dq, minus);
        parts.solve_signed_columns_in_place::<P, N>(system, &mut d.da_dv, &mut d.df_dv, minus);
        parts.solve_identity_in_place_by::<P>(Some(&inverse), &mut d.da_dtau, &mut d.df_dtau);
        finite_derivatives(d, &mut ())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A three-coordinate chain and two contact rows.
    fn system() -> ContactKkt<f64, 3, 2> {
        let m = [[4.0, 1.0, 0.5], [1.0, 3.0, 0.25], [0.5, 0.25, 2.0]];
        let j = [[1.0, 0.0, 2.0], [0.0, 1.0, -1.0]];
        ContactKkt::new(m, &[None, Some(0), Some(1)], j).unwrap()
    }

    #[test]
    fn finite_rows_finds_the_first_row_with_a_non_finite_entry() {
        let mut m = [[1.0, -2.0, 3.5], [0.0, -0.0, 1e300], [4.0, 5.0, 6.0]];
        assert_eq!(finite_rows(&m, 7, &mut ()), Ok(()));
        for (bad, row) in [(f64::INFINITY, 2), (f64::NEG_INFINITY, 1), (f64::NAN, 0)] {
            m[row][1] = bad;
            assert_eq!(
                finite_rows(&m, 7, &mut ()),
                Err(FactorError::NonFinite { pivot: 7 + row })
            );
        }
        // Entries that overflow only when summed are finite.
        assert_eq!(finite_rows(&[[f64::MAX], [f64::MAX]], 0, &mut ()), Ok(()));
    }

    /// The derivatives solved where a stash left the system (`d`) equal those of the system
    /// itself, to the bit.
    #[test]
    fn the_stash_solves_as_the_system_does() {
        let kkt = system();
        let (m, j, parent) = (
            [[4.0, 1.0, 0.5], [1.0, 3.0, 0.25], [0.5, 0.25, 2.0]],
            [[1.0, 0.0, 2.0], [0.0, 1.0, -1.0]],
            [None, Some(0), Some(1)],
        );
        let partials: [[f64; 3]; 7] =
            core::array::from_fn(|r| core::array::from_fn(|c| (r * 3 + c) as f64 * 0.1 - 0.7));
        let (did_dq, did_dv) = (
            [[0.5, 0.1, 0.0], [0.1, 0.2, 0.3], [0.0, 0.3, 0.4]],
            [[0.2; 3]; 3],
        );
        let want = kkt
            .contact_dynamics_derivatives(&did_dq, &did_dv, &partials)
            .unwrap();
        let mut d = ContactDynamicsDerivatives::<f64, 3, 2>::nan();
        let fill = |mm: &mut [[f64; 3]; 3], jj: &mut [[f64; 3]; 2]| {
            (*mm, *jj) = (m, j);
            crate::tree::ltdl_factor(mm, &parent)
        };
        let stash = ContactKkt::set_up_in_factored(&mut d, fill, &parent, &[true; 2]).unwrap();
        (d.da_dq, d.da_dv) = (did_dq, did_dv);
        d.add_partials(&partials).unwrap();
        stash.contact_dynamics_derivatives_in_place(&mut d).unwrap();
        assert_eq!(d, want);
        // Independently of either route, the `tau` block solves `[M -J^T; J 0] [X; F] = [I;
        // 0]`, and the `q` block `[M -J^T; J 0] [X; F] = -[did_dq + P_top; P_middle]`.
        for c in 0..3 {
            for i in 0..3 {
                let mx: f64 = (0..3).map(|k| m[i][k] * d.da_dtau[k][c]).sum();
                let jf: f64 = (0..2).map(|k| j[k][i] * d.df_dtau[k][c]).sum();
                let want = if i == c { 1.0 } else { 0.0 };
                assert!(Real::abs(mx - jf - want) < 1e-14, "tau ({i}, {c})");
                let mx: f64 = (0..3).map(|k| m[i][k] * d.da_dq[k][c]).sum();
                let jf: f64 = (0..2).map(|k| j[k][i] * d.df_dq[k][c]).sum();
                let rhs = -(did_dq[i][c] + partials[i][c]);
                assert!(Real::abs(mx - jf - rhs) < 1e-13, "q ({i}, {c})");
            }
            for r in 0..2 {
                let ja: f64 = (0..3).map(|k| j[r][k] * d.da_dtau[k][c]).sum();
                assert!(Real::abs(ja) < 1e-14, "tau row {r}, column {c}");
                let ja: f64 = (0..3).map(|k| j[r][k] * d.da_dq[k][c]).sum();
                assert!(Real::abs(ja + partials[3 + r][c]) < 1e-13, "q row {r}");
            }
        }
    }

    /// A system made unfactored and factorized where it lies is the one `new` makes, to the
    /// bit, inactive rows included; a pivot of `M` or of `J M^-1 J^T` that fails is named.
    #[test]
    fn an_unfactored_system_factorizes_as_new_does() {
        let (m, j, parent) = (
            [[4.0, 1.0, 0.5], [1.0, 3.0, 0.25], [0.5, 0.25, 2.0]],
            [[1.0, 0.0, 2.0], [0.0, 1.0, -1.0]],
            [None, Some(0), Some(1)],
        );
        let factor = |m: &mut [[f64; 3]; 3], _: &mut ()| crate::tree::ltdl_factor(m, &parent);
        let (top, bottom) = ([1.0, -2.0, 0.5], [0.25, -1.0]);
        for active in [[true, true], [false, true]] {
            let mut kkt = ContactKkt::unfactored(m, j, (&parent, &active));
            kkt.factor_lanes::<Walked>(factor, &mut ()).unwrap();
            let want = ContactKkt::new_active(m, &parent, j, &active).unwrap();
            let (x, f) = kkt.solve(&top, &bottom).unwrap();
            assert_eq!(Ok((x, f)), want.solve(&top, &bottom));
            assert_eq!(kkt.inverse_inertia_rows(), want.inverse_inertia_rows());
            // Independently: `M x - J^T f = top`, `J x = bottom` on the active rows, `f` zero
            // on the others.
            for i in 0..3 {
                let mx: f64 = (0..3).map(|c| m[i][c] * x[c]).sum();
                let jf: f64 = (0..2).map(|r| j[r][i] * f[r]).sum();
                assert!(
                    Real::abs(mx - jf - top[i]) < 1e-14,
                    "row {i} of M x - J^T f"
                );
            }
            for r in 0..2 {
                let jx: f64 = (0..3).map(|c| j[r][c] * x[c]).sum();
                let ok = if active[r] {
                    Real::abs(jx - bottom[r]) < 1e-14
                } else {
                    f[r] == 0.0
                };
                assert!(ok, "contact row {r}");
            }
        }
        // A zero row of `J`: pivot N + 1 of `J M^-1 J^T` is zero.
        let mut singular = ContactKkt::unfactored(m, [j[0], [0.0; 3]], (&parent, &[true; 2]));
        let err = singular.factor_lanes::<Walked>(factor, &mut ());
        assert_eq!(err, Err(FactorError::NotPositiveDefinite { pivot: 4 }));
        let mut not_positive = m;
        not_positive[2][2] = -1.0;
        let mut bad = ContactKkt::unfactored(not_positive, j, (&parent, &[true; 2]));
        let err = bad.factor_lanes::<Walked>(factor, &mut ());
        assert_eq!(err, Err(FactorError::NotPositiveDefinite { pivot: 2 }));
    }

    #[test]
    fn solving_columns_equals_solving_each() {
        let kkt = system();
        let top = [[1.0, -2.0], [0.5, 3.0], [-1.0, 0.25]];
        let bottom = [[2.0, 0.0], [-1.0, 1.5]];
        let (x, f) = kkt.solve_columns(&top, &bottom);
        for c in 0..2 {
            let (xc, fc) = kkt
                .solve(&top.map(|r| r[c]), &bottom.map(|r| r[c]))
                .unwrap();
            for i in 0..3 {
                assert!(Real::abs(x[i][c] - xc[i]) < 1e-14);
            }
            for k in 0..2 {
                assert!(Real::abs(f[k][c] - fc[k]) < 1e-14);
            }
        }
    }

    /// An inactive row drops out: the solutions of the remaining row's system alone, with
    /// zero force on the inactive one, for one and many right-hand sides and the impulse.
    #[test]
    fn inactive_rows_solve_the_system_of_the_active_ones() {
        let m = [[4.0, 1.0, 0.5], [1.0, 3.0, 0.25], [0.5, 0.25, 2.0]];
        let parent = [None, Some(0), Some(1)];
        let j = [[1.0, 0.0, 2.0], [0.0, 1.0, -1.0]];
        let masked = ContactKkt::new_active(m, &parent, j, &[false, true]).unwrap();
        let alone = ContactKkt::new(m, &parent, [j[1]]).unwrap();
        let top = [1.0, 0.5, -1.0];
        let (x, f) = masked.solve(&top, &[7.0, 2.0]).unwrap();
        let (xa, fa) = alone.solve(&top, &[2.0]).unwrap();
        assert_eq!(f[0], 0.0);
        assert!(Real::abs(f[1] - fa[0]) < 1e-14);
        assert!(x.iter().zip(&xa).all(|(a, b)| Real::abs(a - b) < 1e-14));
        let (xc, fc) = masked.solve_columns(&top.map(|t| [t, -t]), &[[3.0, 1.0], [2.0, -2.0]]);
        assert_eq!(fc[0], [0.0, 0.0]);
        assert!((0..3).all(|i| Real::abs(xc[i][0] - x[i]) < 1e-14));
        let v = [0.3, -0.2, 0.5];
        let ((after, p), (after_a, pa)) = (
            masked.impulse(&v, 0.5).unwrap(),
            alone.impulse(&v, 0.5).unwrap(),
        );
        assert_eq!(p[0], 0.0);
        assert!(Real::abs(p[1] - pa[0]) < 1e-14);
        assert!(after
            .iter()
            .zip(&after_a)
            .all(|(a, b)| Real::abs(a - b) < 1e-14));
        // All rows inactive: the free solution.
        let none = ContactKkt::new_active(m, &parent, j, &[false; 2]).unwrap();
        let (free, zero) = none.solve(&top, &[1.0, 1.0]).unwrap();
        let solo = ContactKkt::<f64, 3, 0>::new(m, &parent, []).unwrap();
        assert_eq!((free, zero), (solo.solve(&top, &[]).unwrap().0, [0.0; 2]));
    }

    #[test]
    fn a_point_mass_bounces_off_the_ground() {
        // Unit mass in the plane hitting the ground (y) at 2 m/s, restitution 0.5.
        let kkt = ContactKkt::new([[1.0, 0.0], [0.0, 1.0]], &[None, None], [[0.0, 1.0]]).unwrap();
        let (after, p) = kkt.impulse(&[1.0, -2.0], 0.5).unwrap();
        assert_eq!((after, p), ([1.0, 1.0], [3.0]));
        let singular = ContactKkt::new([[1.0, 0.0], [0.0, 1.0]], &[None, None], [[0.0; 2]]);
        assert_eq!(
            singular.unwrap_err(),
            FactorError::NotPositiveDefinite { pivot: 2 }
        );
    }

    /// `N x N` symmetric positive definite, a chain's (parent `i - 1`), by a fixed recipe.
    fn chain_inertia<const N: usize>() -> [[f64; N]; N] {
        core::array::from_fn(|i| {
            core::array::from_fn(|j| {
                let d = i.abs_diff(j) as f64;
                if i == j {
                    N as f64 + 1.0 + 0.1 * i as f64
                } else {
                    0.5 / (1.0 + d) * if (i + j) % 3 == 0 { -1.0 } else { 1.0 }
                }
            })
        })
    }

    /// The inverse by Gauss-Jordan elimination (no pivoting: for positive definite `a`).
    #[allow(clippy::needless_range_loop)]
    fn inverse<const N: usize>(a: &[[f64; N]; N]) -> [[f64; N]; N] {
        let (mut a, mut x) = (*a, [[0.0; N]; N]);
        (0..N).for_each(|i| x[i][i] = 1.0);
        for c in 0..N {
            let p = a[c][c];
            for k in 0..N {
                a[c][k] /= p;
                x[c][k] /= p;
            }
            for r in (0..N).filter(|r| *r != c) {
                let f = a[r][c];
                for k in 0..N {
                    a[r][k] -= f * a[c][k];
                    x[r][k] -= f * x[c][k];
                }
            }
        }
        x
    }

    #[test]
    fn the_column_support_is_the_span_of_the_nonzero_columns() {
        let z = 0.0;
        assert_eq!(column_support(&[[z, 1.0, z, z], [z, z, -2.0, z]]), 1..3);
        assert_eq!(column_support(&[[f64::NAN, z, z, z]]), 0..1);
        assert_eq!(column_support(&[[z, z, z, -0.0]]), 4..4);
        assert_eq!(column_support(&[[z; 4]; 0]), 4..4);
        assert_eq!(column_support(&[[z, z, z, 5.0]]), 3..4);
    }

    #[test]
    fn a_combination_on_the_support_equals_the_whole_one() {
        // Rows zero outside columns `lo..hi`; every window position, the last moved back.
        for (lo, hi) in [(0, 11), (2, 6), (9, 11), (3, 4), (5, 5)] {
            let x: [[f64; 11]; 3] = core::array::from_fn(|k| {
                core::array::from_fn(|c| {
                    if (lo..hi).contains(&c) {
                        (k * 11 + c) as f64 * 0.37 - 2.0
                    } else {
                        0.0
                    }
                })
            });
            let a = |k: usize| 1.5 - k as f64;
            let mut whole = [0.0; 11];
            for (k, xk) in x.iter().enumerate() {
                axpy(&mut whole, a(k), xk);
            }
            let mut part = [f64::NAN; 11];
            combination_into(&mut part, a, &x, lo..hi);
            assert_eq!(part, whole, "columns {lo}..{hi}");
        }
        // Fewer columns than a window: all of them.
        let mut small = [f64::NAN; 3];
        combination_into(
            &mut small,
            |k| k as f64 + 1.0,
            &[[1.0, 0.0, 2.0], [0.5, 0.0, 0.0]],
            0..0,
        );
        assert_eq!(small, [2.0, 0.0, 2.0]);
    }

    #[test]
    #[allow(clippy::needless_range_loop)] // the formulas' indices, as written
    fn impulse_derivatives_in_v_equal_the_dense_formulas() {
        // 11 coordinates, the contact rows zero outside columns 2..7 (a limb's).
        const N: usize = 11;
        let m = chain_inertia::<N>();
        let parent: [Option<usize>; N] = core::array::from_fn(|i| i.checked_sub(1));
        let j: [[f64; N]; 2] = core::array::from_fn(|k| {
            core::array::from_fn(|c| match c {
                2..=6 => (c as f64 - 3.5 * k as f64).sin() + 0.2,
                _ => 0.0,
            })
        });
        let kkt = ContactKkt::new(m, &parent, j).unwrap();
        let e = 0.3;
        let d = kkt.impulse_derivatives(e, &[[0.0; N]; N + 2]).unwrap();
        // dp/dv = -(1 + e) (J M^-1 J^T)^-1 J, dv+/dv = I + M^-1 J^T dp/dv, densely.
        let mi = inverse(&m);
        let y: [[f64; N]; 2] = core::array::from_fn(|k| {
            core::array::from_fn(|c| (0..N).map(|i| mi[c][i] * j[k][i]).sum())
        });
        let lambda: [[f64; 2]; 2] = core::array::from_fn(|a| {
            core::array::from_fn(|b| (0..N).map(|i| j[a][i] * y[b][i]).sum())
        });
        let li = inverse(&lambda);
        for r in 0..2 {
            for c in 0..N {
                let dp: f64 = -(1.0 + e) * (0..2).map(|k| li[r][k] * j[k][c]).sum::<f64>();
                assert!(
                    Real::abs(d.dimpulse_dv[r][c] - dp) < 1e-12,
                    "dp/dv[{r}][{c}]"
                );
            }
        }
        for i in 0..N {
            for c in 0..N {
                let id = if i == c { 1.0 } else { 0.0 };
                let dv = id + (0..2).map(|k| y[k][i] * d.dimpulse_dv[k][c]).sum::<f64>();
                assert!(Real::abs(d.dv_dv[i][c] - dv) < 1e-12, "dv+/dv[{i}][{c}]");
            }
        }
        // Outside the contact's columns: dp/dv zero, dv+/dv the identity's columns.
        for c in [0, 1, 7, 10] {
            assert!((0..2).all(|r| d.dimpulse_dv[r][c] == 0.0));
            assert!((0..N).all(|i| d.dv_dv[i][c] == if i == c { 1.0 } else { 0.0 }));
        }
    }
}
