//! Forward dynamics with point contacts held: the accelerations `a` and the contact forces `F`
//! of `M a + h = tau + J^T F`, `J a + drift = 0`.
//!
//! `M` is factorized once with the tree's sparse `L^T D L` ([`crate::tree::ltdl_factor`]);
//! then `W = L^-T J^T` (the first half of a substitution, all contact rows at once), the
//! contact-space inverse inertia `J M^-1 J^T = W^T D^-1 W` by Cholesky ([`Cholesky`]),
//! `F = -(J M^-1 J^T)^-1 (drift + J M^-1 (tau - h))` and `a = M^-1 (tau - h + J^T F)`: one
//! more substitution of one vector (generated code passes its unrolled one), not the K columns
//! of `M^-1 J^T`. Everything is in fixed-size arrays on the stack.

pub use crate::baumgarte::{log3, placement, Baumgarte};
use crate::kkt::{axpy, dot, finite_solution};
use crate::linalg::{Cholesky, FactorError};
use crate::tree::{ltdl_factor, ltdl_lower_rows, ltdl_substitute};
use crate::{Lane, Real};

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
    solve_factored_active(m, parent, free, j, drift, &[true; K])
}

/// [`solve_factored`] with only the contact rows `k` where `active[k]` holds: the others
/// are dropped from the problem (their rows of `J M^-1 J^T` and `J` replaced by the
/// identity's and zero), so that `a` is what the same solve gives for the active rows alone,
/// and the inactive rows' forces are zero. All rows inactive: `a = free`, the forward
/// dynamics without contacts. Each contact's rows come from [`row_mask`]. With every row
/// active it is [`solve_factored`], to the bit.
///
/// ```
/// use eomgen_runtime::contact::solve_factored_active;
/// // The point mass of `solve`, held only vertically: it falls freely along x.
/// let m = [[1.0_f64, 0.0], [0.0, 1.0]];
/// let j = [[1.0, 0.0], [0.0, 1.0]];
/// let free = [2.0, -9.81];
/// let (a, f) = solve_factored_active(&m, &[None, None], &free, &j, &[0.0; 2], &[false, true])
///     .unwrap();
/// assert_eq!((a[0], f[0]), (2.0, 0.0));
/// assert!(a[1].abs() < 1e-12 && (f[1] - 9.81).abs() < 1e-12);
/// ```
pub fn solve_factored_active<T: Real, const N: usize, const K: usize>(
    m: &[[T; N]; N],
    parent: &[Option<usize>; N],
    free: &[T; N],
    j: &[[T; N]; K],
    drift: &[T; K],
    active: &[bool; K],
) -> Result<([T; N], [T; K]), FactorError> {
    let substitute = |b: &[T; N]| ltdl_substitute(m, parent, b);
    solve_factored_active_with(m, parent, free, j, drift, active, substitute)
}

/// [`solve_factored_active`] with the caller's own `M^-1 b` from the factors in `m`
/// (`substitute`): generated code passes its unrolled substitution, for the one
/// `M^-1 J^T F` the solve needs.
///
/// ```
/// use eomgen_runtime::contact::solve_factored_active_with;
/// use eomgen_runtime::tree::ltdl_substitute;
/// // The point mass of `solve`, M = I already factorized.
/// let (m, parent) = ([[1.0_f64, 0.0], [0.0, 1.0]], [None, None]);
/// let j = [[1.0, 0.0], [0.0, 1.0]];
/// let substitute = |b: &[f64; 2]| ltdl_substitute(&m, &parent, b);
/// let (a, f) =
///     solve_factored_active_with(&m, &parent, &[0.0, -9.81], &j, &[0.0; 2], &[true; 2], substitute)
///         .unwrap();
/// assert!(a[1].abs() < 1e-12 && (f[1] - 9.81).abs() < 1e-12);
/// ```
pub fn solve_factored_active_with<T: Real, const N: usize, const K: usize>(
    m: &[[T; N]; N],
    parent: &[Option<usize>; N],
    free: &[T; N],
    j: &[[T; N]; K],
    drift: &[T; K],
    active: &[bool; K],
    substitute: impl Fn(&[T; N]) -> [T; N],
) -> Result<([T; N], [T; K]), FactorError> {
    let lower = |w: &mut [[T; K]; N]| ltdl_lower_rows(m, parent, w);
    solve_factored_active_by(m, free, j, drift, active, substitute, lower)
}

/// [`solve_factored_active_with`] with the caller's own first half of the substitution too
/// (`lower`: `x <- L^-T x` for the K columns of `x`, as [`ltdl_lower_rows`] computes it from
/// the factors in `m`): generated code passes its passes unrolled for the robot's tree, and
/// the tree's parents are not needed.
///
/// ```
/// use eomgen_runtime::contact::solve_factored_active_by;
/// use eomgen_runtime::tree::{ltdl_lower_rows, ltdl_substitute};
/// // The point mass of `solve`, M = I already factorized.
/// let (m, parent) = ([[1.0_f64, 0.0], [0.0, 1.0]], [None, None]);
/// let j = [[1.0, 0.0], [0.0, 1.0]];
/// let substitute = |b: &[f64; 2]| ltdl_substitute(&m, &parent, b);
/// let lower = |w: &mut [[f64; 2]; 2]| ltdl_lower_rows(&m, &parent, w);
/// let (a, f) =
///     solve_factored_active_by(&m, &[0.0, -9.81], &j, &[0.0; 2], &[true; 2], substitute, lower)
///         .unwrap();
/// assert!(a[1].abs() < 1e-12 && (f[1] - 9.81).abs() < 1e-12);
/// ```
pub fn solve_factored_active_by<T: Real, const N: usize, const K: usize>(
    m: &[[T; N]; N],
    free: &[T; N],
    j: &[[T; N]; K],
    drift: &[T; K],
    active: &[bool; K],
    substitute: impl Fn(&[T; N]) -> [T; N],
    lower: impl FnOnce(&mut [[T; K]; N]),
) -> Result<([T; N], [T; K]), FactorError> {
    let system = (j, drift, active);
    solve_factored_active_lanes(m, free, system, substitute, lower, &mut ())
}

/// [`solve_factored_active_by`] on a vector of states ([`Lane`], one state per lane), with
/// the contact Jacobian, its drift and the active rows as one argument: a lane whose pivot of
/// `J M^-1 J^T` fails, or whose solution is not finite, records its error in `failures` and
/// holds garbage (a scalar returns the error at once, as [`solve_factored_active_by`]).
/// `active` is every lane's.
///
/// ```
/// use eomgen_runtime::contact::solve_factored_active_lanes;
/// use eomgen_runtime::tree::{ltdl_lower_rows, ltdl_substitute};
/// // The point mass of `solve`, M = I already factorized, with its contact switched off.
/// let (m, parent) = ([[1.0_f64, 0.0], [0.0, 1.0]], [None, None]);
/// let substitute = |b: &[f64; 2]| ltdl_substitute(&m, &parent, b);
/// let lower = |w: &mut [[f64; 1]; 2]| ltdl_lower_rows(&m, &parent, w);
/// let system = (&[[0.0, 1.0]], &[0.0], &[false]);
/// let (a, f) =
///     solve_factored_active_lanes(&m, &[0.0, -9.81], system, substitute, lower, &mut ()).unwrap();
/// assert_eq!((a, f), ([0.0, -9.81], [0.0]));
/// ```
pub fn solve_factored_active_lanes<T: Lane, const N: usize, const K: usize>(
    m: &[[T; N]; N],
    free: &[T; N],
    (j, drift, active): (&[[T; N]; K], &[T; K], &[bool; K]),
    substitute: impl Fn(&[T; N]) -> [T; N],
    lower: impl FnOnce(&mut [[T; K]; N]),
    failures: &mut T::Failures,
) -> Result<([T; N], [T; K]), FactorError> {
    let chol = contact_space(m, j, active, lower, failures)?;
    let mut b = [T::zero(); K];
    for k in 0..K {
        if active[k] {
            b[k] = -(drift[k] + dot(&j[k], free));
        }
    }
    let f = chol.solve(&b);
    // a = free + M^-1 (J^T f).
    let mut a = substitute(&transpose_times(j, &f, active));
    for (ai, fi) in a.iter_mut().zip(free) {
        *ai += *fi;
    }
    finite_solution(a, f, failures)
}

/// The Cholesky factor of `J M^-1 J^T = W^T D^-1 W` with `W = L^-T J^T` (the inactive rows of
/// `J` as zero; the identity's rows and columns for them), from `M`'s factors `m` and `lower`
/// (`x <- L^-T x`, [`ltdl_lower_rows`]): half the substitution that `M^-1 J^T` would take.
///
/// Errors: a pivot of `J M^-1 J^T` that is not positive or not finite (pivot `N + k`; on a
/// vector, recorded in `failures`).
pub(crate) fn contact_space<T: Lane, const N: usize, const K: usize>(
    m: &[[T; N]; N],
    j: &[[T; N]; K],
    active: &[bool; K],
    lower: impl FnOnce(&mut [[T; K]; N]),
    failures: &mut T::Failures,
) -> Result<Cholesky<T, K>, FactorError> {
    let mut w = [[T::zero(); K]; N];
    for (i, wi) in w.iter_mut().enumerate() {
        for ((wik, jk), on) in wi.iter_mut().zip(j).zip(active) {
            if *on {
                *wik = jk[i];
            }
        }
    }
    lower(&mut w);
    // W^T D^-1 W as N rank-one updates, one per coordinate: the K x K sums are independent
    // chains the processor overlaps (gathered row by row, each row was a chain of N dependent
    // multiply-adds, and they were a sixth of a quadruped's contact dynamics).
    // A coordinate's row of `W` is zero in the contact rows outside its subtree (a leg joint
    // moves its own foot only): those rows of the update are skipped, on a vector where every
    // lane's entry is zero. (A non-finite entry still reaches `lambda`: through its own row,
    // onto the diagonal.)
    let mut lambda = [[T::zero(); K]; K];
    for (i, wi) in w.iter().enumerate() {
        let d = T::one() / m[i][i];
        for (lr, wir) in lambda.iter_mut().zip(wi) {
            if wir.zero_in_every_lane() {
                continue;
            }
            let s = *wir * d;
            for (l, x) in lr.iter_mut().zip(wi) {
                *l = s.mul_add(*x, *l);
            }
        }
    }
    for (r, lr) in lambda.iter_mut().enumerate() {
        if !active[r] {
            lr[r] = T::one();
        }
    }
    Cholesky::factor(lambda, N, failures)
}

/// `J^T f` over the rows of `active` only.
pub(crate) fn transpose_times<T: Lane, const N: usize, const K: usize>(
    j: &[[T; N]; K],
    f: &[T; K],
    active: &[bool; K],
) -> [T; N] {
    let mut out = [T::zero(); N];
    for ((jk, fk), on) in j.iter().zip(f).zip(active) {
        if *on {
            axpy(&mut out, *fk, jk);
        }
    }
    out
}

/// The contact rows (`K` of them) of the contacts (`C`) that `active` switches on, each
/// contact `c` owning the next `rows[c]` rows (3 for a point, 6 for a frame: a generated
/// robot's `CONTACT_ROWS`). Rows beyond the sum of `rows` stay inactive; contacts beyond `K`
/// rows are cut.
///
/// ```
/// use eomgen_runtime::contact::row_mask;
/// let rows: [bool; 9] = row_mask(&[3, 6], &[false, true]);
/// assert_eq!(rows, [false, false, false, true, true, true, true, true, true]);
/// ```
pub fn row_mask<const C: usize, const K: usize>(
    rows: &[usize; C],
    active: &[bool; C],
) -> [bool; K] {
    let mut out = [false; K];
    let mut at: usize = 0;
    for (n, on) in rows.iter().zip(active) {
        let end = at.saturating_add(*n).min(K);
        if *on {
            for x in &mut out[at..end] {
                *x = true;
            }
        }
        at = end;
    }
    out
}
