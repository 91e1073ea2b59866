//! Fixed-size, allocation-free, panic-free solvers for symmetric positive definite systems.
//!
//! Both factorizations read only the **lower triangle** (`m[i][j]` with `i >= j`) of the
//! matrix, which is assumed symmetric; the strict upper triangle is ignored. Every pivot is
//! checked: a pivot that is not finite or not strictly positive stops the factorization with a
//! [`FactorError`] naming it. Because every input entry of the lower triangle feeds some later
//! pivot, a NaN or infinity anywhere in the lower triangle is always reported, and a successful
//! factorization has only finite entries.

use crate::{Lane, Real};
use core::fmt;

/// `y += a x`, entry by entry, fused: the row operation of the tree and contact solves, which
/// keep `y` in a local accumulator (registers) while they gather into it.
#[inline(always)]
pub(crate) fn axpy<T: Lane, const C: usize>(y: &mut [T; C], a: T, x: &[T; C]) {
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi = a.mul_add(*xi, *yi);
    }
}

/// Columns per window of [`combination_into`]: one 512-bit register of `f64`.
const WINDOW: usize = 8;

/// `out = sum_k a(k) x[k]` over the rows `x[k]`, computed in the columns `cols` only (zero in
/// the others, where the caller knows every row is zero): windows of [`WINDOW`] columns, each
/// gathered in a local accumulator over all `k` and stored into `out`, the last window moved
/// back inside the row (its columns computed twice, the same way). With `N < WINDOW`, every
/// column. `out` is written in place: a local row copied out afterwards was read back by
/// loads that straddled the windows' stores, which the processor cannot forward.
#[inline(always)]
pub(crate) fn combination_into<T: Lane, const N: usize, const K: usize>(
    out: &mut [T; N],
    a: impl Fn(usize) -> T,
    x: &[[T; N]; K],
    cols: core::ops::Range<usize>,
) {
    *out = [T::zero(); N];
    if N < WINDOW {
        for (k, xk) in x.iter().enumerate() {
            axpy(out, a(k), xk);
        }
        return;
    }
    let mut s = cols.start;
    while s < cols.end {
        let at = s.min(N - WINDOW);
        let mut acc = [T::zero(); WINDOW];
        for (k, xk) in x.iter().enumerate() {
            if let Some(Ok(w)) = xk.get(at..at + WINDOW).map(<&[T; WINDOW]>::try_from) {
                axpy(&mut acc, a(k), w);
            }
        }
        if let Some(o) = out.get_mut(at..at + WINDOW) {
            o.copy_from_slice(&acc);
        }
        s = at + WINDOW;
    }
}

/// `a x`, by a loop the compiler vectorizes in place: `x.map(|v| a * v)` on a long array was
/// left a call of `array::try_map` writing to memory, whose result, read back by wider loads,
/// stalled on store forwarding (a tenth of a humanoid's contact derivatives).
#[inline(always)]
pub(crate) fn scaled<T: Lane, const C: usize>(x: &[T; C], a: T) -> [T; C] {
    let mut y = *x;
    for v in y.iter_mut() {
        *v = a * *v;
    }
    y
}

/// Why a matrix could not be factorized.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FactorError {
    /// Pivot `pivot` (0-based row/column index) was zero or negative: the matrix is not
    /// (numerically) positive definite.
    NotPositiveDefinite {
        /// The 0-based index of the offending pivot.
        pivot: usize,
    },
    /// Pivot `pivot` was NaN or infinite: the matrix holds a non-finite value (in row `pivot`
    /// or an earlier row of its lower triangle), or its factorization overflowed. From a
    /// generated `try_forward_dynamics`, also: component `pivot` of the solution is not finite
    /// (a non-finite right-hand side).
    NonFinite {
        /// The 0-based index of the offending pivot.
        pivot: usize,
    },
}

impl FactorError {
    /// The 0-based index of the pivot at which the factorization stopped.
    pub fn pivot(&self) -> usize {
        match *self {
            FactorError::NotPositiveDefinite { pivot } | FactorError::NonFinite { pivot } => pivot,
        }
    }
}

impl fmt::Display for FactorError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            FactorError::NotPositiveDefinite { pivot } => write!(
                f,
                "matrix is not positive definite: pivot {pivot} is zero or negative"
            ),
            FactorError::NonFinite { pivot } => write!(
                f,
                "pivot or solution component {pivot} is not finite (NaN or infinite input, or overflow)"
            ),
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for FactorError {}

/// The dot product of the first `len` entries of `a` and `b` (no bounds checks: `zip` and
/// `take` stop at the shorter length).
#[inline(always)]
fn dot_prefix<T: Lane, const N: usize>(a: &[T; N], b: &[T; N], len: usize) -> T {
    let mut s = T::zero();
    for (x, y) in a.iter().zip(b.iter()).take(len) {
        s += *x * *y;
    }
    s
}

/// The `L D Lᵀ` factorization of a symmetric positive definite `N×N` matrix, with `L` unit lower
/// triangular and `D` diagonal.
///
/// Needs no square root (a single division per row and one per solve), which makes it the
/// cheapest choice on microcontrollers; [`solve_spd`] uses it. A positive definite matrix has
/// all pivots `D_j > 0`; [`Ldlt::new`] fails on the first pivot that is not finite or not
/// positive.
///
/// Only the lower triangle of the input is read; the matrix is assumed symmetric. A NaN or
/// infinity anywhere in that triangle gives an error ([`FactorError::NonFinite`], unless an
/// earlier pivot already failed).
///
/// ```
/// use eomgen_runtime::{FactorError, Ldlt};
///
/// let m = [[4.0_f64, 2.0], [2.0, 3.0]];
/// let f = Ldlt::new(m).unwrap();
/// let x = f.solve(&[6.0, 5.0]);
/// assert!((x[0] - 1.0).abs() < 1e-12 && (x[1] - 1.0).abs() < 1e-12);
/// assert_eq!(f.d(), &[4.0, 2.0]);
///
/// let singular = [[1.0_f64, 1.0], [1.0, 1.0]];
/// assert_eq!(Ldlt::new(singular), Err(FactorError::NotPositiveDefinite { pivot: 1 }));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ldlt<T, const N: usize> {
    /// Strictly lower part holds `L` (unit diagonal implied); diagonal and upper part unused
    /// (kept zero).
    l: [[T; N]; N],
    /// The pivots `D_j`, all finite and positive.
    d: [T; N],
    /// `1 / D_j`.
    d_inv: [T; N],
}

impl<T: Real, const N: usize> Ldlt<T, N> {
    /// Factorizes `m` (lower triangle read). Errors on the first pivot that is not finite or
    /// not strictly positive.
    pub fn new(m: [[T; N]; N]) -> Result<Self, FactorError> {
        let (l, d, d_inv) = ldlt_factor(&m, &mut ())?;
        Ok(Ldlt { l, d, d_inv })
    }

    /// The unit lower triangular factor `L` (row-major; ones on the diagonal, zeros above).
    pub fn l(&self) -> [[T; N]; N] {
        let mut l = self.l;
        for (i, row) in l.iter_mut().enumerate() {
            for (j, x) in row.iter_mut().enumerate() {
                if i == j {
                    *x = T::one();
                }
            }
        }
        l
    }

    /// The diagonal `D` (all entries finite and positive).
    pub fn d(&self) -> &[T; N] {
        &self.d
    }

    /// The determinant of the factorized matrix, `Π D_j` (may overflow to infinity).
    pub fn determinant(&self) -> T {
        let mut p = T::one();
        for x in self.d.iter() {
            p *= *x;
        }
        p
    }

    /// Overwrites `b` with the solution `x` of `M x = b`.
    pub fn solve_in_place(&self, b: &mut [T; N]) {
        ldlt_substitute(&self.l, &self.d_inv, b);
    }

    /// The solution `x` of `M x = b`.
    pub fn solve(&self, b: &[T; N]) -> [T; N] {
        let mut x = *b;
        self.solve_in_place(&mut x);
        x
    }
}

/// The `L D Lᵀ` factors `(L, D, D⁻¹)` of `m` (lower triangle read), each pivot checked by
/// [`Lane::check_pivot`]: a scalar stops at its first bad pivot, a vector of states records
/// each lane's in `failures` and carries on.
#[allow(clippy::type_complexity)]
fn ldlt_factor<T: Lane, const N: usize>(
    m: &[[T; N]; N],
    failures: &mut T::Failures,
) -> Result<([[T; N]; N], [T; N], [T; N]), FactorError> {
    let mut l = [[T::zero(); N]; N];
    let mut d = [T::zero(); N];
    let mut d_inv = [T::zero(); N];
    // Work row: w[k] = L[j][k] * D[k] for k < j.
    let mut w = [T::zero(); N];
    for j in 0..N {
        // w = L[j][..j] * D[..j]
        for ((wk, lk), dk) in w.iter_mut().zip(l[j].iter()).zip(d.iter()).take(j) {
            *wk = *lk * *dk;
        }
        let dj = m[j][j] - dot_prefix(&w, &l[j], j);
        T::check_pivot(dj, j, failures)?;
        let inv = T::one() / dj;
        d[j] = dj;
        d_inv[j] = inv;
        for i in (j + 1)..N {
            let s = dot_prefix(&l[i], &w, j);
            l[i][j] = (m[i][j] - s) * inv;
        }
    }
    Ok((l, d, d_inv))
}

/// Overwrites `b` with the solution of `L D Lᵀ x = b` (`L` strictly lower, unit diagonal).
fn ldlt_substitute<T: Lane, const N: usize>(l: &[[T; N]; N], d_inv: &[T; N], b: &mut [T; N]) {
    // L y = b (forward; unit diagonal)
    for i in 0..N {
        let s = dot_prefix(&l[i], b, i);
        b[i] -= s;
    }
    // D z = y
    for (x, inv) in b.iter_mut().zip(d_inv.iter()) {
        *x *= *inv;
    }
    // Lᵀ x = z (backward; unit diagonal)
    for i in (0..N).rev() {
        let mut s = T::zero();
        for (row, bk) in l.iter().zip(b.iter()).skip(i + 1) {
            s += row[i] * *bk;
        }
        b[i] -= s;
    }
}

/// The Cholesky factorization `M = L Lᵀ` of a symmetric positive definite `N×N` matrix, with `L`
/// lower triangular with a positive diagonal; like nalgebra's `Cholesky`, but fixed-size,
/// `no_std` and returning an error instead of panicking.
///
/// Costs `N` square roots more than [`Ldlt`]; use it when the factor `L` itself is wanted
/// (e.g. to draw correlated noise, or for the Cholesky of the mass matrix in operational-space
/// control). The pivots checked are `L_jj²`.
///
/// Only the lower triangle of the input is read; the matrix is assumed symmetric. A NaN or
/// infinity anywhere in that triangle gives an error ([`FactorError::NonFinite`], unless an
/// earlier pivot already failed).
///
/// ```
/// use eomgen_runtime::{Cholesky, FactorError};
///
/// let m = [[4.0_f64, 2.0], [2.0, 5.0]];
/// let c = Cholesky::new(m).unwrap();
/// assert_eq!(c.l(), &[[2.0, 0.0], [1.0, 2.0]]);
/// assert_eq!(c.solve(&[6.0, 7.0]), [1.0, 1.0]);
///
/// let with_nan = [[1.0_f64, 0.0], [f64::NAN, 1.0]];
/// assert_eq!(Cholesky::new(with_nan), Err(FactorError::NonFinite { pivot: 1 }));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cholesky<T, const N: usize> {
    /// Lower triangular factor, zeros above the diagonal.
    l: [[T; N]; N],
    /// `1 / L_jj`.
    diag_inv: [T; N],
}

impl<T: Real, const N: usize> Cholesky<T, N> {
    /// Factorizes `m` (lower triangle read). Errors on the first pivot `L_jj²` that is not
    /// finite or not strictly positive.
    pub fn new(m: [[T; N]; N]) -> Result<Self, FactorError> {
        Self::factor(m, 0, &mut ())
    }
}

impl<T: Lane, const N: usize> Cholesky<T, N> {
    /// The factorization of the identity.
    pub(crate) fn identity() -> Self {
        let mut l = [[T::zero(); N]; N];
        for (i, row) in l.iter_mut().enumerate() {
            row[i] = T::one();
        }
        Cholesky {
            l,
            diag_inv: [T::one(); N],
        }
    }

    /// [`Cholesky::new`] on a vector of states: pivot `j` is checked as pivot `offset + j`
    /// ([`Lane::check_pivot`]: a scalar returns its error at once, a vector records it in
    /// `failures` and goes on, NaN then filling that lane).
    pub(crate) fn factor(
        m: [[T; N]; N],
        offset: usize,
        failures: &mut T::Failures,
    ) -> Result<Self, FactorError> {
        let mut l = [[T::zero(); N]; N];
        let mut diag_inv = [T::zero(); N];
        for j in 0..N {
            let d = m[j][j] - dot_prefix(&l[j], &l[j], j);
            T::check_pivot(d, offset + j, failures)?;
            // `1 / L_jj = L_jj / d`: the division starts with the square root instead of after
            // it, which takes a division's latency off each column's critical path.
            let (ljj, r) = (d.sqrt(), T::one() / d);
            let inv = ljj * r;
            l[j][j] = ljj;
            diag_inv[j] = inv;
            for i in (j + 1)..N {
                let s = dot_prefix(&l[i], &l[j], j);
                l[i][j] = (m[i][j] - s) * inv;
            }
        }
        Ok(Cholesky { l, diag_inv })
    }

    /// The lower triangular factor `L` (row-major, zeros above the diagonal).
    pub fn l(&self) -> &[[T; N]; N] {
        &self.l
    }

    /// The determinant of the factorized matrix, `Π L_jj²` (may overflow to infinity).
    pub fn determinant(&self) -> T {
        let mut p = T::one();
        for (j, row) in self.l.iter().enumerate() {
            if let Some(x) = row.get(j) {
                p *= *x * *x;
            }
        }
        p
    }

    /// Overwrites `b` with the solution `x` of `M x = b`.
    pub fn solve_in_place(&self, b: &mut [T; N]) {
        // L y = b by columns: each y_j, once final, taken from the entries below it; then
        // L^T x = y by rows of L: each x_k taken from the entries above it. Independent
        // multiply-adds, where a dot product per entry was a chain of dependent ones.
        for j in 0..N {
            let y = b[j] * self.diag_inv[j];
            b[j] = y;
            for (bi, row) in b.iter_mut().zip(&self.l).skip(j + 1) {
                *bi = (-row[j]).mul_add(y, *bi);
            }
        }
        for k in (0..N).rev() {
            let x = b[k] * self.diag_inv[k];
            b[k] = x;
            for (bi, lki) in b.iter_mut().zip(&self.l[k]).take(k) {
                *bi = (-*lki).mul_add(x, *bi);
            }
        }
    }

    /// The solution `x` of `M x = b`.
    pub fn solve(&self, b: &[T; N]) -> [T; N] {
        let mut x = *b;
        self.solve_in_place(&mut x);
        x
    }

    /// `M^-1`, exactly symmetric: `X^T X` with `X = L^-1`. Where many right-hand sides are
    /// solved, a product with it is independent multiply-adds, where each substitution is a
    /// chain of dependent ones (a quadruped's contact derivatives solve 48 columns with its
    /// 12 x 12 contact-space matrix).
    ///
    /// ```
    /// use eomgen_runtime::Cholesky;
    /// let c = Cholesky::new([[4.0_f64, 2.0], [2.0, 5.0]]).unwrap();
    /// assert_eq!(c.inverse(), [[0.3125, -0.125], [-0.125, 0.25]]);
    /// ```
    pub fn inverse(&self) -> [[T; N]; N] {
        // X = L^-1 row by row: X_i = (e_i - sum over k < i of L_ik X_k) / L_ii. `e_i` is
        // built whole: a one stored at index `i` and read back by wide loads stalled on store
        // forwarding.
        let mut x = [[T::zero(); N]; N];
        for i in 0..N {
            let (done, rest) = x.split_at_mut(i);
            let mut row: [T; N] =
                core::array::from_fn(|c| if c == i { T::one() } else { T::zero() });
            for (lik, xk) in self.l[i].iter().zip(done.iter()) {
                axpy(&mut row, -*lik, xk);
            }
            rest[0] = scaled(&row, self.diag_inv[i]);
        }
        // (X^T X)_rc = sum over k of X_kr X_kc, zero for k < r: row r from the rows k >= r.
        // Entry (c, r) is the same sum: the same products in the same order, after exact
        // zeros (X_kr = 0 for k < r), so the result is symmetric to the bit without the lower
        // triangle copied over the upper (whose narrow stores the callers' wide loads of the
        // rows then stalled on).
        let mut inv = [[T::zero(); N]; N];
        for (r, out) in inv.iter_mut().enumerate() {
            for xk in &x[r..] {
                axpy(out, xk[r], xk);
            }
        }
        inv
    }
}

/// Solves `M x = b` for a symmetric positive definite `M` (lower triangle read) with an
/// [`Ldlt`] factorization.
///
/// ```
/// use eomgen_runtime::{solve_spd, FactorError};
///
/// let m = [[2.0_f32, 1.0], [1.0, 2.0]];
/// let x = solve_spd(&m, &[3.0, 3.0]).unwrap();
/// assert!((x[0] - 1.0).abs() < 1e-6 && (x[1] - 1.0).abs() < 1e-6);
///
/// let indefinite = [[1.0_f32, 0.0], [0.0, -1.0]];
/// assert_eq!(solve_spd(&indefinite, &[1.0, 1.0]), Err(FactorError::NotPositiveDefinite { pivot: 1 }));
/// ```
pub fn solve_spd<T: Real, const N: usize>(
    m: &[[T; N]; N],
    b: &[T; N],
) -> Result<[T; N], FactorError> {
    Ldlt::new(*m).map(|f| f.solve(b))
}

/// Like [`solve_spd`], but reports failure as an all-NaN result instead of an error: the form
/// generated `forward_dynamics` uses, since its signature returns a plain array. On a vector
/// of states ([`Lane`]), NaN in the lanes that failed only.
///
/// ```
/// use eomgen_runtime::solve_spd_or_nan;
///
/// assert_eq!(solve_spd_or_nan(&[[2.0_f64]], &[1.0]), [0.5]);
/// assert!(solve_spd_or_nan(&[[0.0_f64]], &[1.0])[0].is_nan());
/// ```
#[inline]
pub fn solve_spd_or_nan<T: Lane, const N: usize>(m: &[[T; N]; N], b: &[T; N]) -> [T; N] {
    let mut failures = T::Failures::default();
    match ldlt_factor(m, &mut failures) {
        Ok((l, _, d_inv)) => {
            let mut x = *b;
            ldlt_substitute(&l, &d_inv, &mut x);
            crate::lane::nan_failed(x, &failures)
        }
        Err(_) => [T::nan(); N],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cholesky_inverse_is_symmetric_to_the_bit_and_inverts() {
        const N: usize = 12;
        let m: [[f64; N]; N] = core::array::from_fn(|i| {
            core::array::from_fn(|j| match i == j {
                true => 6.0 + i as f64,
                false => ((i + j) * 7 % 11) as f64 / 11.0 - 0.5,
            })
        });
        let inv = Cholesky::new(m).unwrap().inverse();
        for (r, row) in inv.iter().enumerate() {
            for (c, x) in row.iter().enumerate() {
                assert_eq!(x.to_bits(), inv[c][r].to_bits(), "({r}, {c})");
                let p: f64 = (0..N).map(|k| m[r][k] * inv[k][c]).sum();
                let id = if r == c { 1.0 } else { 0.0 };
                assert!((p - id).abs() < 1e-14, "(M M^-1)[{r}][{c}] = {p}");
            }
        }
    }
}
