//! Forward dynamics with point contacts held: the accelerations `a` and the contact forces `F`
//! of `M a + h = tau + J^T F`, `J a + drift = 0`.
//!
//! `M` is factorized once with the tree's sparse `L^T D L` ([`crate::tree::ltdl_factor`]);
//! then `Y = M^-1 J^T` (one substitution of all contact rows at once,
//! [`crate::tree::ltdl_substitute_rows`]), the contact-space inverse inertia
//! `J M^-1 J^T` by Cholesky ([`Cholesky`]), `F = -(J M^-1 J^T)^-1 (drift + J M^-1 (tau - h))`
//! and `a = M^-1 (tau - h) + Y F`. Everything is in fixed-size arrays on the stack.

use crate::linalg::{Cholesky, FactorError};
use crate::tree::{ltdl_factor, ltdl_substitute, ltdl_substitute_rows};
use crate::Real;

/// Solves the contact forward dynamics for `rhs = tau - h` (`h = b + G`, friction included),
/// the contact Jacobian `j` (K rows, world axes) and its drift `Jdot v`. `m` (the mass matrix)
/// is overwritten by its factorization; `parent` is each coordinate's parent coordinate.
///
/// Errors: a pivot of `M` that is not positive (`pivot < N`), a rank-deficient `J` (pivot
/// `N + k` of `J M^-1 J^T`), or a non-finite result (`NonFinite` at the offending component,
/// counted the same way).
///
/// ```
/// use eomgen_runtime::contact::solve;
/// // A unit point mass in the plane held at the origin: gravity is balanced by the contact.
/// let mut m = [[1.0_f64, 0.0], [0.0, 1.0]];
/// let rhs = [0.0, -9.81]; // tau - h: gravity pulls down
/// let j = [[1.0, 0.0], [0.0, 1.0]];
/// let (a, f) = solve(&mut m, &[None, None], &rhs, &j, &[0.0, 0.0]).unwrap();
/// assert_eq!(a, [0.0, 0.0]);
/// assert!((f[1] - 9.81).abs() < 1e-12);
/// ```
pub fn solve<T: Real, const N: usize, const K: usize>(
    m: &mut [[T; N]; N],
    parent: &[Option<usize>; N],
    rhs: &[T; N],
    j: &[[T; N]; K],
    drift: &[T; K],
) -> Result<([T; N], [T; K]), FactorError> {
    ltdl_factor(m, parent)?;
    let free = ltdl_substitute(m, parent, rhs);
    solve_factored(m, parent, &free, j, drift)
}

/// [`solve`] after its first steps: `m` holds the factors of [`ltdl_factor`] and `free` is
/// `M^-1 (tau - h)`, the accelerations without contacts (generated code factorizes with its
/// own unrolled copy of [`ltdl_factor`]). Fails like [`solve`], without the pivots of `M`.
///
/// ```
/// use eomgen_runtime::contact::solve_factored;
/// // The point mass of `solve`, M = I already factorized: free = tau - h.
/// let m = [[1.0_f64, 0.0], [0.0, 1.0]];
/// let j = [[1.0, 0.0], [0.0, 1.0]];
/// let (a, f) = solve_factored(&m, &[None, None], &[0.0, -9.81], &j, &[0.0, 0.0]).unwrap();
/// assert_eq!(a, [0.0, 0.0]);
/// assert!((f[1] - 9.81).abs() < 1e-12);
/// ```
pub fn solve_factored<T: Real, const N: usize, const K: usize>(
    m: &[[T; N]; N],
    parent: &[Option<usize>; N],
    free: &[T; N],
    j: &[[T; N]; K],
    drift: &[T; K],
) -> Result<([T; N], [T; K]), FactorError> {
    // Y = M^-1 J^T (N x K), all K columns in one substitution.
    let mut y = [[T::zero(); K]; N];
    for (i, yi) in y.iter_mut().enumerate() {
        for (yik, jk) in yi.iter_mut().zip(j) {
            *yik = jk[i];
        }
    }
    ltdl_substitute_rows(m, parent, &mut y);
    let mut lambda = [[T::zero(); K]; K];
    for (jr, lr) in j.iter().zip(lambda.iter_mut()) {
        for (jri, yi) in jr.iter().zip(&y) {
            for (l, yic) in lr.iter_mut().zip(yi) {
                *l = jri.mul_add(*yic, *l);
            }
        }
    }
    let shift = |e: FactorError| match e {
        FactorError::NotPositiveDefinite { pivot } => {
            FactorError::NotPositiveDefinite { pivot: N + pivot }
        }
        FactorError::NonFinite { pivot } => FactorError::NonFinite { pivot: N + pivot },
    };
    let chol = Cholesky::new(lambda).map_err(shift)?;
    let mut b = [T::zero(); K];
    for k in 0..K {
        b[k] = -(drift[k] + dot(&j[k], free));
    }
    let f = chol.solve(&b);
    let mut a = *free;
    for (ai, yi) in a.iter_mut().zip(&y) {
        for (yik, fk) in yi.iter().zip(&f) {
            *ai = yik.mul_add(*fk, *ai);
        }
    }
    if let Some(pivot) = a.iter().position(|x| !x.is_finite()) {
        return Err(FactorError::NonFinite { pivot });
    }
    if let Some(k) = f.iter().position(|x| !x.is_finite()) {
        return Err(FactorError::NonFinite { pivot: N + k });
    }
    Ok((a, f))
}

fn dot<T: Real, const N: usize>(a: &[T; N], b: &[T; N]) -> T {
    let mut s = T::zero();
    for (x, y) in a.iter().zip(b) {
        s += *x * *y;
    }
    s
}
