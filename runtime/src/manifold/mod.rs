//! The configuration manifold of a robot, as Pinocchio's `difference`, `dIntegrate` and
//! `dDifference`: a fixed base's configurations form a vector space; a floating base's free
//! flyer moves along the SE(3) exponential, `integrate(q, v) = q exp6(v)` (see
//! [`crate::free_flyer::integrate`]), its joints as a vector space.
//!
//! Floating base: `q` = [position (3), unit quaternion x, y, z, w (4), joints], `v` =
//! [linear (3), angular (3), both in base axes, joints], `NQ = NV + 1`. Tangent vectors of the
//! base are [translation (3), rotation (3)] in base axes; Jacobians are `[i][j]` = d out_i /
//! d in_j, block diagonal with the base's 6 x 6 block and the joints' identity.
//!
//! Every function takes a [`Lane`]: a scalar ([`crate::Real`]), or a vector of states, one
//! per lane. Where the closed forms need a case (the quaternion's sign, a series near the
//! zero rotation, the arctangent's reduction) each lane takes its own by [`Lane::select`]; a
//! scalar evaluates only its case, so its values are those of plain branches, bit for bit.

mod atan;

pub(crate) use atan::atan2_quadrant;
mod into;
mod se3;

pub use into::{
    difference_jacobians_blocks_into, difference_jacobians_into, integrate_jacobians_blocks_into,
    integrate_jacobians_into, vector_difference_jacobians_into, vector_integrate_jacobians_into,
};

use crate::place::{self, Filled, Slot};
use crate::Lane;
use se3::{Relative, M6};

/// Two N x N matrices: the Jacobians in both arguments.
type Pair<T, const N: usize> = ([[T; N]; N], [[T; N]; N]);

/// `difference(q0, q1)`: the velocity that [`crate::free_flyer::integrate`] moves for unit time
/// to get from `q0` to `q1`, `log6(M0^-1 M1)` for the base and `q1 - q0` for the joints. `q1`'s
/// quaternion may have either sign.
///
/// ```
/// use eomgen_runtime::free_flyer::integrate;
/// use eomgen_runtime::manifold::difference;
/// let q = [0.1_f64, -0.2, 0.3, 0.0, 0.6, 0.0, 0.8, 0.5];
/// let v = [0.3, -0.1, 0.2, 0.4, -0.5, 0.6, 0.7];
/// let d: [f64; 7] = difference(&q, &integrate(&q, &v, 1.0));
/// assert!(d.iter().zip(&v).all(|(a, b)| (a - b).abs() < 1e-12));
/// ```
pub fn difference<T: Lane, const NQ: usize, const NV: usize>(
    q0: &[T; NQ],
    q1: &[T; NQ],
) -> [T; NV] {
    let mut out = [T::zero(); NV];
    if NQ < 7 || NV < 6 {
        return out;
    }
    let rel = Relative::new(q0, q1);
    out[..3].copy_from_slice(&rel.rho);
    out[3..6].copy_from_slice(&rel.phi);
    for k in 6..NV.min(NQ - 1) {
        out[k] = q1[k + 1] - q0[k + 1];
    }
    out
}

/// Pinocchio's `dIntegrate(q, v)` in `q` and in `v`: to first order
/// `integrate(integrate(q, e), v) = integrate(integrate(q, v), dq e)` and
/// `integrate(q, v + e) = integrate(integrate(q, v), dv e)`. The base's blocks are
/// `Ad(exp6(v))^-1` and the right Jacobian of `exp6` at `v`.
///
/// ```
/// use eomgen_runtime::manifold::integrate_jacobians;
/// let q = [0.0_f64, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.5];
/// let (dq, dv) = integrate_jacobians::<f64, 8, 7>(&q, &[0.0; 7]);
/// assert!((0..7).all(|i| dq[i][i] == 1.0 && dv[i][i] == 1.0));
/// ```
pub fn integrate_jacobians<T: Lane, const NQ: usize, const NV: usize>(
    q: &[T; NQ],
    v: &[T; NV],
) -> ([[T; NV]; NV], [[T; NV]; NV]) {
    let _ = q;
    let base = (NV >= 6).then(|| se3::integrate_jacobians(&v[..6]));
    identities_with(T::one(), T::one(), base.as_ref())
}

/// Pinocchio's `dDifference(q0, q1)` in `q0` and in `q1`. With `M = M0^-1 M1` and
/// `Jlog6(M)` the inverse of the right Jacobian of `exp6` at `log6(M)`, the base's blocks are
/// `-Jlog6(M) Ad(M)^-1` and `Jlog6(M)`; the joints' `-I` and `I`.
///
/// ```
/// use eomgen_runtime::manifold::difference_jacobians;
/// let q = [0.0_f64, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.5];
/// let (d0, d1) = difference_jacobians::<f64, 8, 7>(&q, &q);
/// assert!((0..7).all(|i| d0[i][i] == -1.0 && d1[i][i] == 1.0));
/// ```
pub fn difference_jacobians<T: Lane, const NQ: usize, const NV: usize>(
    q0: &[T; NQ],
    q1: &[T; NQ],
) -> ([[T; NV]; NV], [[T; NV]; NV]) {
    let base = (NQ >= 7 && NV >= 6).then(|| se3::difference_jacobians(q0, q1));
    identities_with(-T::one(), T::one(), base.as_ref())
}

/// [`difference`] for free flyers anywhere in `q` (floating joints below the root): each
/// `(q0, v0)` of `free` (ascending) is a free flyer whose 7 position coordinates start at `q0`
/// and 6 velocity coordinates at `v0`, its part `log6(M0^-1 M1)`; every other coordinate's
/// is `q1 - q0`. As [`crate::free_flyer::integrate_blocks`] reads `free`.
///
/// ```
/// use eomgen_runtime::free_flyer::integrate_blocks;
/// use eomgen_runtime::manifold::difference_blocks;
/// // a revolute joint, then a free flyer
/// let q = [0.5_f64, 0.1, -0.2, 0.3, 0.0, 0.6, 0.0, 0.8];
/// let v = [0.7, 0.3, -0.1, 0.2, 0.4, -0.5, 0.6];
/// let d: [f64; 7] = difference_blocks(&q, &integrate_blocks(&q, &v, 1.0, &[(1, 1)]), &[(1, 1)]);
/// assert!(d.iter().zip(&v).all(|(a, b)| (a - b).abs() < 1e-12));
/// ```
pub fn difference_blocks<T: Lane, const NQ: usize, const NV: usize>(
    q0: &[T; NQ],
    q1: &[T; NQ],
    free: &[(usize, usize)],
) -> [T; NV] {
    let mut out = [T::zero(); NV];
    walk_blocks::<NQ, NV>(free, |block| match block {
        Block::Vector(qi, vi) => out[vi] = q1[qi] - q0[qi],
        Block::Flyer(a, b) => {
            let rel = Relative::new(&q0[a..a + 7], &q1[a..a + 7]);
            out[b..b + 3].copy_from_slice(&rel.rho);
            out[b + 3..b + 6].copy_from_slice(&rel.phi);
        }
    });
    out
}

/// [`integrate_jacobians`] for free flyers anywhere in `q`, `free` as in
/// [`difference_blocks`]: each free flyer's 6 x 6 blocks on the diagonal, the identity for
/// every other coordinate.
///
/// ```
/// use eomgen_runtime::manifold::integrate_jacobians_blocks;
/// let q = [0.5_f64, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0];
/// let (dq, dv) = integrate_jacobians_blocks::<f64, 8, 7>(&q, &[0.0; 7], &[(1, 1)]);
/// assert!((0..7).all(|i| dq[i][i] == 1.0 && dv[i][i] == 1.0));
/// ```
pub fn integrate_jacobians_blocks<T: Lane, const NQ: usize, const NV: usize>(
    q: &[T; NQ],
    v: &[T; NV],
    free: &[(usize, usize)],
) -> ([[T; NV]; NV], [[T; NV]; NV]) {
    let (mut dq, mut dv) = ([[T::zero(); NV]; NV], [[T::zero(); NV]; NV]);
    integrate_jacobians_blocks_into(q, v, free, &mut dq, &mut dv);
    (dq, dv)
}

/// [`difference_jacobians`] for free flyers anywhere in `q`, `free` as in
/// [`difference_blocks`]: each free flyer's 6 x 6 blocks on the diagonal, `-I` and `I` for
/// every other coordinate.
///
/// ```
/// use eomgen_runtime::manifold::difference_jacobians_blocks;
/// let q = [0.5_f64, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0];
/// let (d0, d1) = difference_jacobians_blocks::<f64, 8, 7>(&q, &q, &[(1, 1)]);
/// assert!((0..7).all(|i| d0[i][i] == -1.0 && d1[i][i] == 1.0));
/// ```
pub fn difference_jacobians_blocks<T: Lane, const NQ: usize, const NV: usize>(
    q0: &[T; NQ],
    q1: &[T; NQ],
    free: &[(usize, usize)],
) -> ([[T; NV]; NV], [[T; NV]; NV]) {
    let (mut d0, mut d1) = ([[T::zero(); NV]; NV], [[T::zero(); NV]; NV]);
    difference_jacobians_blocks_into(q0, q1, free, &mut d0, &mut d1);
    (d0, d1)
}

/// A part of a configuration: one coordinate of a vector space (its position and velocity
/// index), or a free flyer (its first position and velocity index).
#[derive(Clone, Copy)]
enum Block {
    Vector(usize, usize),
    Flyer(usize, usize),
}

/// Walks a configuration of `NQ` positions and `NV` velocities in order, a [`Block`] at a
/// time, the free flyers from `free` (ascending, as [`difference_blocks`] reads it). A block
/// that does not fit ends the walk.
fn walk_blocks<const NQ: usize, const NV: usize>(
    free: &[(usize, usize)],
    mut visit: impl FnMut(Block),
) {
    let (mut qi, mut vi) = (0, 0);
    for &(q0, v0) in free {
        if q0 + 7 > NQ || v0 + 6 > NV || v0 < vi || q0 < qi || q0 - qi != v0 - vi {
            return;
        }
        while vi < v0 {
            visit(Block::Vector(qi, vi));
            (qi, vi) = (qi + 1, vi + 1);
        }
        visit(Block::Flyer(q0, v0));
        (qi, vi) = (q0 + 7, v0 + 6);
    }
    while qi < NQ && vi < NV {
        visit(Block::Vector(qi, vi));
        (qi, vi) = (qi + 1, vi + 1);
    }
}

/// `block` on the diagonal of `m`, from row and column `at`.
fn put_block<T: Lane, const N: usize>(m: &mut [[T; N]; N], at: usize, block: &M6<T>) {
    for (row, b) in m[at..at + 6].iter_mut().zip(block) {
        row[at..at + 6].copy_from_slice(b);
    }
}

/// A fixed base's `difference`: `q1 - q0`.
pub fn vector_difference<T: Lane, const N: usize>(q0: &[T; N], q1: &[T; N]) -> [T; N] {
    core::array::from_fn(|i| q1[i] - q0[i])
}

/// A fixed base's `dIntegrate` in `q` and `v`: `(I, I)`.
pub fn vector_integrate_jacobians<T: Lane, const N: usize>() -> ([[T; N]; N], [[T; N]; N]) {
    identities_with(T::one(), T::one(), None)
}

/// A fixed base's `dDifference` in `q0` and `q1`: `(-I, I)`.
pub fn vector_difference_jacobians<T: Lane, const N: usize>() -> ([[T; N]; N], [[T; N]; N]) {
    identities_with(-T::one(), T::one(), None)
}

/// `a` and `b` times the identity, each with its block of `base` (if any) in the top left
/// corner, written where the caller keeps the result ([`crate::place`]): built in a local
/// and moved there, the matrices were copied, which cost more than the free flyer's
/// arithmetic.
#[inline(always)]
fn identities_with<T: Lane, const N: usize>(
    a: T,
    b: T,
    base: Option<&(M6<T>, M6<T>)>,
) -> ([[T; N]; N], [[T; N]; N]) {
    place::build(|slot| write_identities(slot, a, b, base))
}

/// [`identities_with`]'s filling, not inlined so that the slot stays the caller's storage.
#[inline(never)]
fn write_identities<'s, T: Lane, const N: usize>(
    slot: Slot<'s, Pair<T, N>>,
    a: T,
    b: T,
    base: Option<&(M6<T>, M6<T>)>,
) -> Filled<'s> {
    let (m, filled) = slot.fill();
    for i in 0..N {
        m.0[i][i] = a;
        m.1[i][i] = b;
    }
    if let Some((x, y)) = base {
        for i in 0..6 {
            m.0[i][..6].copy_from_slice(&x[i]);
            m.1[i][..6].copy_from_slice(&y[i]);
        }
    }
    filled
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::free_flyer::integrate;

    type Q = [f64; 8];
    type V = [f64; 7];

    /// A base at a generic pose and one joint.
    const Q0: Q = [0.3, -0.2, 0.5, 0.1, -0.7, 0.2, 0.67, 0.4];

    /// Velocities whose rotation angles reach every branch: zero, below the series
    /// thresholds, moderate, and close to pi.
    fn velocities() -> [V; 5] {
        [0.0, 1e-9, 3e-3, 0.8, 3.1].map(|angle| {
            let axis = [0.48, -0.6, 0.64];
            [
                0.4,
                -0.3,
                0.2,
                axis[0] * angle,
                axis[1] * angle,
                axis[2] * angle,
                0.9,
            ]
        })
    }

    fn unit_quaternion(q: &Q) -> Q {
        let n = (q[3] * q[3] + q[4] * q[4] + q[5] * q[5] + q[6] * q[6]).sqrt();
        let mut out = *q;
        out[3..7].iter_mut().for_each(|x| *x /= n);
        out
    }

    fn close(a: &[f64], b: &[f64], tol: f64, what: &str) {
        let scale = b.iter().fold(1.0_f64, |m, x| m.max(x.abs()));
        for (i, (x, y)) in a.iter().zip(b).enumerate() {
            assert!((x - y).abs() <= tol * scale, "{what}[{i}]: {x} vs {y}");
        }
    }

    /// `(f(h) - f(-h)) / 2h` as a column.
    fn central(f: impl Fn(f64) -> V) -> V {
        let h = 1e-6;
        let (p, m) = (f(h), f(-h));
        core::array::from_fn(|i| (p[i] - m[i]) / (2.0 * h))
    }

    fn step(j: usize, h: f64) -> V {
        core::array::from_fn(|i| if i == j { h } else { 0.0 })
    }

    fn column(m: &[V; 7], j: usize) -> V {
        core::array::from_fn(|i| m[i][j])
    }

    #[test]
    fn difference_inverts_integrate() {
        let q0 = unit_quaternion(&Q0);
        for v in velocities() {
            let q1 = integrate(&q0, &v, 1.0);
            close(&difference::<f64, 8, 7>(&q0, &q1), &v, 1e-12, "difference");
            // Either sign of the quaternion, any norm near one.
            let mut q1 = q1;
            q1[3..7].iter_mut().for_each(|x| *x *= -1.0000001);
            close(&difference::<f64, 8, 7>(&q0, &q1), &v, 1e-12, "-q1");
        }
    }

    #[test]
    fn integrate_jacobians_match_finite_differences() {
        let q = unit_quaternion(&Q0);
        for v in velocities() {
            let (dq, dv) = integrate_jacobians::<f64, 8, 7>(&q, &v);
            let at = integrate(&q, &v, 1.0);
            for j in 0..7 {
                let by_q = central(|h| {
                    difference(&at, &integrate(&integrate(&q, &step(j, h), 1.0), &v, 1.0))
                });
                close(&column(&dq, j), &by_q, 1e-8, "d/dq");
                let by_v = central(|h| {
                    let w: V = core::array::from_fn(|i| v[i] + step(j, h)[i]);
                    difference(&at, &integrate(&q, &w, 1.0))
                });
                close(&column(&dv, j), &by_v, 1e-8, "d/dv");
            }
        }
    }

    #[test]
    fn difference_jacobians_match_finite_differences() {
        let q0 = unit_quaternion(&Q0);
        for v in velocities() {
            let q1 = integrate(&q0, &v, 1.0);
            let (d0, d1) = difference_jacobians::<f64, 8, 7>(&q0, &q1);
            for j in 0..7 {
                let by_q0 = central(|h| difference(&integrate(&q0, &step(j, h), 1.0), &q1));
                close(&column(&d0, j), &by_q0, 1e-7, "d/dq0");
                let by_q1 = central(|h| difference(&q0, &integrate(&q1, &step(j, h), 1.0)));
                close(&column(&d1, j), &by_q1, 1e-7, "d/dq1");
            }
        }
    }
}

/// The functions on vectors of states against the scalar code, lane by lane.
#[cfg(all(test, feature = "simd"))]
mod lanes {
    use super::*;
    use crate::free_flyer::integrate;
    use crate::lane::Pack;
    use wide::f64x4;

    /// `q0`, `q1` and `v` of a root free flyer and a joint.
    type State = ([f64; 8], [f64; 8], [f64; 7]);

    /// A root free flyer and a joint (8, 7) per lane: the same rotation in `q0` and `q1`
    /// (the zero rotation, series; signed zeros), a tiny and a moderate one, `q1`'s
    /// quaternion negated in all three, and a NaN state; the velocities' angles zero, small
    /// and moderate.
    fn states() -> [State; 4] {
        let q0 = [0.3, -0.2, 0.5, 0.1, -0.7, 0.2, 0.67, 0.4];
        let v = |angle: f64| {
            [
                0.4,
                -0.3,
                0.2,
                0.48 * angle,
                -0.6 * angle,
                0.64 * angle,
                0.9,
            ]
        };
        let negated = |mut q: [f64; 8]| {
            q[3..7].iter_mut().for_each(|x| *x = -*x);
            q
        };
        let mut nan = q0;
        nan[4] = f64::NAN;
        [
            (q0, negated(q0), v(0.0)),
            (q0, negated(integrate(&q0, &v(1e-7), 1.0)), v(1e-3)),
            (q0, negated(integrate(&q0, &v(0.8), 1.0)), v(0.8)),
            (nan, q0, v(f64::NAN)),
        ]
    }

    /// Entries equal bit for bit, any NaN equal to any NaN (Rust fixes no NaN's sign).
    fn same(lanes: &[f64x4], scalar: &[f64], l: usize, what: &str) {
        for (k, (x, y)) in lanes.iter().zip(scalar).enumerate() {
            let x = x.lane(l);
            let ok = x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan());
            assert!(ok, "{what}, lane {l}, entry {k}: {x} vs {y}");
        }
    }

    #[test]
    fn each_lane_is_the_scalar_code() {
        let s = states();
        let gather = |f: fn(&State) -> &[f64]| -> [f64x4; 8] {
            core::array::from_fn(|j| f64x4::gather(|l| f(&s[l]).get(j).copied().unwrap_or(0.0)))
        };
        let (q0, q1, v8) = (gather(|x| &x.0), gather(|x| &x.1), gather(|x| &x.2));
        let v: [f64x4; 7] = core::array::from_fn(|j| v8[j]);
        let d: [f64x4; 7] = difference(&q0, &q1);
        let ij = integrate_jacobians::<f64x4, 8, 7>(&q0, &v);
        let dj = difference_jacobians::<f64x4, 8, 7>(&q0, &q1);
        // The same flyer below a joint, on the `_blocks` path.
        let shift = |x: &[f64x4]| -> [f64x4; 9] {
            core::array::from_fn(|i| if i == 0 { f64x4::ONE } else { x[i - 1] })
        };
        let (p0, p1) = (shift(&q0), shift(&q1));
        let w: [f64x4; 8] = core::array::from_fn(|i| shift(&v8)[i]);
        let db: [f64x4; 8] = difference_blocks(&p0, &p1, &[(1, 1)]);
        let djb = difference_jacobians_blocks::<f64x4, 9, 8>(&p0, &p1, &[(1, 1)]);
        let ijb = integrate_jacobians_blocks::<f64x4, 9, 8>(&p0, &w, &[(1, 1)]);
        for (l, (a, b, u)) in s.iter().enumerate() {
            same(&d, &difference::<f64, 8, 7>(a, b), l, "difference");
            let (x, y) = integrate_jacobians::<f64, 8, 7>(a, u);
            same(
                ij.0.as_flattened(),
                x.as_flattened(),
                l,
                "integrate_jacobians q",
            );
            same(
                ij.1.as_flattened(),
                y.as_flattened(),
                l,
                "integrate_jacobians v",
            );
            let (x, y) = difference_jacobians::<f64, 8, 7>(a, b);
            same(
                dj.0.as_flattened(),
                x.as_flattened(),
                l,
                "difference_jacobians q0",
            );
            same(
                dj.1.as_flattened(),
                y.as_flattened(),
                l,
                "difference_jacobians q1",
            );
            let lane = |x: &[f64x4]| -> [f64; 9] { core::array::from_fn(|i| x[i].lane(l)) };
            let (a, b) = (lane(&p0), lane(&p1));
            let u: [f64; 8] = core::array::from_fn(|i| w[i].lane(l));
            same(
                &db,
                &difference_blocks::<f64, 9, 8>(&a, &b, &[(1, 1)]),
                l,
                "blocks",
            );
            let (x, y) = difference_jacobians_blocks::<f64, 9, 8>(&a, &b, &[(1, 1)]);
            same(
                djb.0.as_flattened(),
                x.as_flattened(),
                l,
                "difference_jacobians_blocks",
            );
            same(
                djb.1.as_flattened(),
                y.as_flattened(),
                l,
                "difference_jacobians_blocks",
            );
            let (x, y) = integrate_jacobians_blocks::<f64, 9, 8>(&a, &u, &[(1, 1)]);
            same(
                ijb.0.as_flattened(),
                x.as_flattened(),
                l,
                "integrate_jacobians_blocks",
            );
            same(
                ijb.1.as_flattened(),
                y.as_flattened(),
                l,
                "integrate_jacobians_blocks",
            );
        }
    }
}
