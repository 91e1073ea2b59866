//! The manifold's Jacobians written into the caller's matrices, their diagonal blocks only,
//! as Pinocchio's `dIntegrate` and `dDifference` write each joint's block of the matrix they
//! are given: a free flyer's 6 x 6 blocks and each other coordinate's diagonal entry. The
//! entries off those blocks are zero in the Jacobians and are left as they are, so the
//! matrices must hold zeros there (zeroed once, or written by an earlier call). A robot that
//! evaluates the Jacobians at every node of a horizon then writes its base's 72 entries and
//! one per joint, where [`super::integrate_jacobians`] writes `2 NV^2` (a 35-coordinate
//! humanoid's 19.6 kB).

use super::{put_block, se3, walk_blocks, Block, M6};
use crate::Lane;

/// [`super::integrate_jacobians`] into `dq` and `dv`, their diagonal blocks only (module
/// documentation): the entries off the blocks must be zero.
///
/// ```
/// use eomgen_runtime::manifold::{integrate_jacobians, integrate_jacobians_into};
/// let q = [0.1_f64, -0.2, 0.3, 0.0, 0.6, 0.0, 0.8, 0.5];
/// let v = [0.3, -0.1, 0.2, 0.4, -0.5, 0.6, 0.7];
/// let (mut dq, mut dv) = ([[0.0; 7]; 7], [[0.0; 7]; 7]);
/// integrate_jacobians_into(&q, &v, &mut dq, &mut dv);
/// assert_eq!((dq, dv), integrate_jacobians(&q, &v));
/// ```
pub fn integrate_jacobians_into<T: Lane, const NQ: usize, const NV: usize>(
    q: &[T; NQ],
    v: &[T; NV],
    dq: &mut [[T; NV]; NV],
    dv: &mut [[T; NV]; NV],
) {
    let _ = q;
    diagonal(dq, dv, T::one(), T::one());
    if NV >= 6 {
        se3::integrate_jacobians_at(&v[..6], (dq, dv), 0);
    }
}

/// [`super::difference_jacobians`] into `d0` and `d1`, their diagonal blocks only (module
/// documentation): the entries off the blocks must be zero.
///
/// ```
/// use eomgen_runtime::manifold::{difference_jacobians, difference_jacobians_into};
/// let q0 = [0.1_f64, -0.2, 0.3, 0.0, 0.6, 0.0, 0.8, 0.5];
/// let q1 = [0.4, 0.1, 0.2, 0.6, 0.0, 0.0, 0.8, -0.5];
/// let (mut d0, mut d1) = ([[0.0; 7]; 7], [[0.0; 7]; 7]);
/// difference_jacobians_into(&q0, &q1, &mut d0, &mut d1);
/// assert_eq!((d0, d1), difference_jacobians(&q0, &q1));
/// ```
pub fn difference_jacobians_into<T: Lane, const NQ: usize, const NV: usize>(
    q0: &[T; NQ],
    q1: &[T; NQ],
    d0: &mut [[T; NV]; NV],
    d1: &mut [[T; NV]; NV],
) {
    diagonal(d0, d1, -T::one(), T::one());
    if NQ >= 7 && NV >= 6 {
        let (b0, b1) = se3::difference_jacobians(q0, q1);
        put_block(d0, 0, &b0);
        put_block(d1, 0, &b1);
    }
}

/// [`super::integrate_jacobians_blocks`] into `dq` and `dv`, their diagonal blocks only
/// (module documentation), `free` as there.
pub fn integrate_jacobians_blocks_into<T: Lane, const NQ: usize, const NV: usize>(
    q: &[T; NQ],
    v: &[T; NV],
    free: &[(usize, usize)],
    dq: &mut [[T; NV]; NV],
    dv: &mut [[T; NV]; NV],
) {
    let _ = q;
    diagonal(dq, dv, T::one(), T::one());
    walk_blocks::<NQ, NV>(free, |block| {
        if let Block::Flyer(_, b) = block {
            se3::integrate_jacobians_at(&v[b..b + 6], (&mut *dq, &mut *dv), b);
        }
    });
}

/// [`super::difference_jacobians_blocks`] into `d0` and `d1`, their diagonal blocks only
/// (module documentation), `free` as there.
pub fn difference_jacobians_blocks_into<T: Lane, const NQ: usize, const NV: usize>(
    q0: &[T; NQ],
    q1: &[T; NQ],
    free: &[(usize, usize)],
    d0: &mut [[T; NV]; NV],
    d1: &mut [[T; NV]; NV],
) {
    diagonal(d0, d1, -T::one(), T::one());
    flyers_into::<NQ, NV, T>(free, (d0, d1), |a, _| {
        se3::difference_jacobians(&q0[a..a + 7], &q1[a..a + 7])
    });
}

/// Each free flyer's blocks `blocks(q index, v index)` of `free` on the diagonals of `x`
/// and `y` (`dDifference`'s: written whole, its 3 x 3 parts written in place made its dense
/// form slower, `se3::integrate_jacobians_at`).
fn flyers_into<const NQ: usize, const NV: usize, T: Lane>(
    free: &[(usize, usize)],
    (x, y): (&mut [[T; NV]; NV], &mut [[T; NV]; NV]),
    blocks: impl Fn(usize, usize) -> (M6<T>, M6<T>),
) {
    walk_blocks::<NQ, NV>(free, |block| {
        if let Block::Flyer(a, b) = block {
            let (bx, by) = blocks(a, b);
            put_block(x, b, &bx);
            put_block(y, b, &by);
        }
    });
}

/// A fixed base's [`super::vector_integrate_jacobians`] into `dq` and `dv`: ones on their
/// diagonals, the rest left as it is (zero).
pub fn vector_integrate_jacobians_into<T: Lane, const N: usize>(
    dq: &mut [[T; N]; N],
    dv: &mut [[T; N]; N],
) {
    diagonal(dq, dv, T::one(), T::one());
}

/// A fixed base's [`super::vector_difference_jacobians`] into `d0` and `d1`: minus one and
/// one on their diagonals, the rest left as it is (zero).
pub fn vector_difference_jacobians_into<T: Lane, const N: usize>(
    d0: &mut [[T; N]; N],
    d1: &mut [[T; N]; N],
) {
    diagonal(d0, d1, -T::one(), T::one());
}

/// `a` and `b` on the diagonals of `x` and `y`.
fn diagonal<T: Lane, const N: usize>(x: &mut [[T; N]; N], y: &mut [[T; N]; N], a: T, b: T) {
    for (i, (rx, ry)) in x.iter_mut().zip(y.iter_mut()).enumerate() {
        rx[i] = a;
        ry[i] = b;
    }
}

#[cfg(test)]
mod tests {
    use super::super::{difference_jacobians, integrate_jacobians, integrate_jacobians_blocks};
    use super::*;

    /// A revolute joint, a free flyer below it, then two joints (the flyer's blocks at
    /// velocity coordinate 1).
    const FREE: [(usize, usize); 1] = [(1, 1)];

    fn states() -> ([f64; 10], [f64; 10], [f64; 9]) {
        let q0 = [0.5, 0.1, -0.2, 0.3, 0.0, 0.6, 0.0, 0.8, -0.4, 1.2];
        let q1 = [0.7, 0.4, 0.1, 0.2, 0.6, 0.0, 0.0, 0.8, 0.3, -0.1];
        let v = [0.7, 0.3, -0.1, 0.2, 0.4, -0.5, 0.6, 0.2, -0.9];
        (q0, q1, v)
    }

    /// `a I` and `b I`, with the 6 x 6 blocks `x` and `y` from row and column 1 (the flyer of
    /// [`FREE`]).
    fn expected(a: f64, b: f64, (x, y): ([[f64; 6]; 6], [[f64; 6]; 6])) -> [[[f64; 9]; 9]; 2] {
        let unit =
            |s: f64| core::array::from_fn(|i| core::array::from_fn(|j| s * f64::from(i == j)));
        let mut m: [[[f64; 9]; 9]; 2] = [unit(a), unit(b)];
        for i in 0..6 {
            m[0][1 + i][1..7].copy_from_slice(&x[i]);
            m[1][1 + i][1..7].copy_from_slice(&y[i]);
        }
        m
    }

    #[test]
    fn written_into_zeros_they_equal_the_whole_jacobians() {
        let (q0, q1, v) = states();
        // The flyer below the root: the identity around the root flyer's blocks, the
        // latter from the dense root forms on the flyer's own coordinates.
        let (f0, f1): ([f64; 7], [f64; 7]) = (
            core::array::from_fn(|i| q0[i + 1]),
            core::array::from_fn(|i| q1[i + 1]),
        );
        let fv: [f64; 6] = core::array::from_fn(|i| v[i + 1]);
        let (mut a, mut b) = ([[0.0; 9]; 9], [[0.0; 9]; 9]);
        integrate_jacobians_blocks_into(&q0, &v, &FREE, &mut a, &mut b);
        assert_eq!([a, b], expected(1.0, 1.0, integrate_jacobians(&f0, &fv)));
        difference_jacobians_blocks_into(&q0, &q1, &FREE, &mut a, &mut b);
        assert_eq!([a, b], expected(-1.0, 1.0, difference_jacobians(&f0, &f1)));
        // A root free flyer (the first 7 positions and 6 velocities) and a joint, and a fixed
        // base.
        let (r0, r1): ([f64; 8], [f64; 8]) = (
            core::array::from_fn(|i| q0[i + 1]),
            core::array::from_fn(|i| q1[i + 1]),
        );
        let w: [f64; 7] = core::array::from_fn(|i| v[i + 1]);
        let (mut c, mut d) = ([[0.0; 7]; 7], [[0.0; 7]; 7]);
        integrate_jacobians_into(&r0, &w, &mut c, &mut d);
        assert_eq!((c, d), integrate_jacobians(&r0, &w));
        difference_jacobians_into(&r0, &r1, &mut c, &mut d);
        assert_eq!((c, d), difference_jacobians(&r0, &r1));
        vector_difference_jacobians_into(&mut c, &mut d);
        assert!((0..7).all(|i| c[i][i] == -1.0 && d[i][i] == 1.0));
    }

    #[test]
    fn only_the_diagonal_blocks_are_written() {
        let (q0, q1, v) = states();
        let mark = 7.25;
        let (mut a, mut b) = ([[mark; 9]; 9], [[mark; 9]; 9]);
        integrate_jacobians_blocks_into(&q0, &v, &FREE, &mut a, &mut b);
        let (wa, wb) = integrate_jacobians_blocks(&q0, &v, &FREE);
        // Coordinates 1..7 are the flyer's block; every other one is its own block.
        let block = |i: usize| if (1..7).contains(&i) { 1 } else { i + 10 };
        for i in 0..9 {
            for j in 0..9 {
                let (x, y) = if block(i) == block(j) {
                    (wa[i][j], wb[i][j])
                } else {
                    (mark, mark)
                };
                assert_eq!((a[i][j], b[i][j]), (x, y), "({i}, {j})");
            }
        }
        vector_integrate_jacobians_into(&mut a, &mut b);
        difference_jacobians_blocks_into(&q0, &q1, &FREE, &mut a, &mut b);
        assert_eq!(a[0][5], mark);
        assert_eq!(a[8][8], -1.0);
    }
}
