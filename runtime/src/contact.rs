//! Forward dynamics with point contacts held: the accelerations `a` and the contact forces `F`
//! of `M a + h = tau + J^T F`, `J a + drift = 0`.
//!
//! `M` is factorized once with the tree's sparse `L^T D L` ([`crate::tree::ltdl_factor`]);
//! then `Y = M^-1 J^T` (one substitution per contact row), the contact-space inverse inertia
//! `J M^-1 J^T` by Cholesky ([`Cholesky`]), `F = -(J M^-1 J^T)^-1 (drift + J M^-1 (tau - h))`
//! and `a = M^-1 (tau - h) + Y F`. Everything is in fixed-size arrays on the stack.

use crate::linalg::{Cholesky, FactorError};
use crate::tree::{ltdl_factor, ltdl_substitute};
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
    // Y = M^-1 J^T, column k of Y is M^-1 times row k of J.
    let mut y = [[T::zero(); N]; K];
    for (yk, jk) in y.iter_mut().zip(j) {
        *yk = ltdl_substitute(m, parent, jk);
    }
    let mut lambda = [[T::zero(); K]; K];
    for r in 0..K {
        for c in 0..K {
            lambda[r][c] = dot(&j[r], &y[c]);
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
        b[k] = -(drift[k] + dot(&j[k], &free));
    }
    let f = chol.solve(&b);
    let mut a = free;
    for (yk, fk) in y.iter().zip(&f) {
        for (ai, yi) in a.iter_mut().zip(yk) {
            *ai += *yi * *fk;
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
