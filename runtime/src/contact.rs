//! Forward dynamics with point contacts held: the accelerations `a` and the contact forces `F`
//! of `M a + h = tau + J^T F`, `J a + drift = 0`.
//!
//! `M` is factorized once with the tree's sparse `L^T D L` ([`crate::tree::ltdl_factor`]);
//! then `Y = M^-1 J^T` (one substitution per contact row), the contact-space inverse inertia
//! `J M^-1 J^T` by Cholesky (through [`ContactKkt`]), `F = -(J M^-1 J^T)^-1 (drift + J M^-1 (tau - h))`
//! and `a = M^-1 (tau - h) + Y F`. Everything is in fixed-size arrays on the stack.

use crate::kkt::ContactKkt;
use crate::linalg::FactorError;
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
    let kkt = ContactKkt::new(*m, parent, *j)?;
    *m = kkt.factors;
    kkt.solve(rhs, &drift.map(|x| -x))
}
