//! The configuration manifold of a robot, as Pinocchio's `difference`, `dIntegrate` and
//! `dDifference`: a fixed base's configurations form a vector space; a floating base's free
//! flyer moves along the SE(3) exponential, `integrate(q, v) = q exp6(v)` (see
//! [`crate::free_flyer::integrate`]), its joints as a vector space.
//!
//! Floating base: `q` = [position (3), unit quaternion x, y, z, w (4), joints], `v` =
//! [linear (3), angular (3), both in base axes, joints], `NQ = NV + 1`. Tangent vectors of the
//! base are [translation (3), rotation (3)] in base axes; Jacobians are `[i][j]` = d out_i /
//! d in_j, block diagonal with the base's 6 x 6 block and the joints' identity.

use crate::free_flyer::{exp_so3, quat_mul, rotation};
use crate::Real;

type M3<T> = [[T; 3]; 3];
type M6<T> = [[T; 6]; 6];
/// `(a, b, (a'/theta, b'/theta), c)` of [`coefficients`].
type Coefficients<T> = (T, T, (T, T), T);

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
pub fn difference<T: Real, const NQ: usize, const NV: usize>(
    q0: &[T; NQ],
    q1: &[T; NQ],
) -> [T; NV] {
    let mut out = [T::zero(); NV];
    if NQ < 7 || NV < 6 {
        return out;
    }
    let (rho, phi, _, _) = relative_log(q0, q1);
    out[..3].copy_from_slice(&rho);
    out[3..6].copy_from_slice(&phi);
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
pub fn integrate_jacobians<T: Real, const NQ: usize, const NV: usize>(
    q: &[T; NQ],
    v: &[T; NV],
) -> ([[T; NV]; NV], [[T; NV]; NV]) {
    let _ = q;
    if NV < 6 {
        return (identity(T::one()), identity(T::one()));
    }
    let (dq, dv) = flyer_integrate_jacobians(&v[..6]);
    (embed(&dq, T::one()), embed(&dv, T::one()))
}

/// A free flyer's blocks of [`integrate_jacobians`] at its velocity `v` (6 entries):
/// `Ad(exp6(v))^-1` and the right Jacobian of `exp6` at `v`.
fn flyer_integrate_jacobians<T: Real>(v: &[T]) -> (M6<T>, M6<T>) {
    let rho = [v[0], v[1], v[2]];
    let phi = [v[3], v[4], v[5]];
    let (quat, vmat) = exp_so3(&phi);
    let r = rotation(&quat);
    let t = mat_vec(&vmat, &rho);
    let dq = inverse_action(&r, &t);
    let dv = right_jacobian(&r, &rho, &phi, &coefficients(&phi));
    (dq, dv)
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
pub fn difference_jacobians<T: Real, const NQ: usize, const NV: usize>(
    q0: &[T; NQ],
    q1: &[T; NQ],
) -> ([[T; NV]; NV], [[T; NV]; NV]) {
    if NQ < 7 || NV < 6 {
        return (identity(-T::one()), identity(T::one()));
    }
    let (d0, d1) = flyer_difference_jacobians(q0, q1);
    (embed(&d0, -T::one()), embed(&d1, T::one()))
}

/// A free flyer's blocks of [`difference_jacobians`] from its coordinates in `q0` and `q1`
/// (the first 7 entries of each): `-Jlog6(M) Ad(M)^-1` and `Jlog6(M)`, `M = M0^-1 M1`.
fn flyer_difference_jacobians<T: Real>(q0: &[T], q1: &[T]) -> (M6<T>, M6<T>) {
    let (rho, phi, r, t) = relative_log(q0, q1);
    let jlog = inverse_right_jacobian(&r, &rho, &phi, &coefficients(&phi));
    let adinv = inverse_action(&r, &t);
    let mut d0 = [[T::zero(); 6]; 6];
    for (row, j) in d0.iter_mut().zip(&jlog) {
        for (c, x) in row.iter_mut().enumerate() {
            *x = -(0..6).fold(T::zero(), |s, k| s + j[k] * adinv[k][c]);
        }
    }
    (d0, jlog)
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
pub fn difference_blocks<T: Real, const NQ: usize, const NV: usize>(
    q0: &[T; NQ],
    q1: &[T; NQ],
    free: &[(usize, usize)],
) -> [T; NV] {
    let mut out = [T::zero(); NV];
    walk_blocks::<NQ, NV>(free, |block| match block {
        Block::Vector(qi, vi) => out[vi] = q1[qi] - q0[qi],
        Block::Flyer(a, b) => {
            let (rho, phi, _, _) = relative_log(&q0[a..a + 7], &q1[a..a + 7]);
            out[b..b + 3].copy_from_slice(&rho);
            out[b + 3..b + 6].copy_from_slice(&phi);
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
pub fn integrate_jacobians_blocks<T: Real, const NQ: usize, const NV: usize>(
    q: &[T; NQ],
    v: &[T; NV],
    free: &[(usize, usize)],
) -> ([[T; NV]; NV], [[T; NV]; NV]) {
    let _ = q;
    let (mut dq, mut dv) = (identity(T::one()), identity(T::one()));
    walk_blocks::<NQ, NV>(free, |block| {
        if let Block::Flyer(_, b) = block {
            let (bq, bv) = flyer_integrate_jacobians(&v[b..b + 6]);
            put_block(&mut dq, b, &bq);
            put_block(&mut dv, b, &bv);
        }
    });
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
pub fn difference_jacobians_blocks<T: Real, const NQ: usize, const NV: usize>(
    q0: &[T; NQ],
    q1: &[T; NQ],
    free: &[(usize, usize)],
) -> ([[T; NV]; NV], [[T; NV]; NV]) {
    let (mut d0, mut d1) = (identity(-T::one()), identity(T::one()));
    walk_blocks::<NQ, NV>(free, |block| {
        if let Block::Flyer(a, b) = block {
            let (b0, b1) = flyer_difference_jacobians(&q0[a..a + 7], &q1[a..a + 7]);
            put_block(&mut d0, b, &b0);
            put_block(&mut d1, b, &b1);
        }
    });
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
fn put_block<T: Real, const N: usize>(m: &mut [[T; N]; N], at: usize, block: &M6<T>) {
    for (row, b) in m[at..at + 6].iter_mut().zip(block) {
        row[at..at + 6].copy_from_slice(b);
    }
}

/// A fixed base's `difference`: `q1 - q0`.
pub fn vector_difference<T: Real, const N: usize>(q0: &[T; N], q1: &[T; N]) -> [T; N] {
    core::array::from_fn(|i| q1[i] - q0[i])
}

/// A fixed base's `dIntegrate` in `q` and `v`: `(I, I)`.
pub fn vector_integrate_jacobians<T: Real, const N: usize>() -> ([[T; N]; N], [[T; N]; N]) {
    (identity(T::one()), identity(T::one()))
}

/// A fixed base's `dDifference` in `q0` and `q1`: `(-I, I)`.
pub fn vector_difference_jacobians<T: Real, const N: usize>() -> ([[T; N]; N], [[T; N]; N]) {
    (identity(-T::one()), identity(T::one()))
}

/// `d` times the identity.
fn identity<T: Real, const N: usize>(d: T) -> [[T; N]; N] {
    let mut m = [[T::zero(); N]; N];
    for (i, row) in m.iter_mut().enumerate() {
        row[i] = d;
    }
    m
}

/// The base's 6 x 6 block in the top left corner, `d` on the rest of the diagonal.
fn embed<T: Real, const N: usize>(block: &M6<T>, d: T) -> [[T; N]; N] {
    let mut m = identity(d);
    for (row, b) in m.iter_mut().zip(block) {
        for (x, y) in row.iter_mut().zip(b) {
            *x = *y;
        }
    }
    m
}

/// `log6(M0^-1 M1)` of the bases of `q0` and `q1` as (translation part, rotation vector), and
/// the relative rotation and translation `(R, t)` of `M0^-1 M1`.
fn relative_log<T: Real>(q0: &[T], q1: &[T]) -> ([T; 3], [T; 3], M3<T>, [T; 3]) {
    let a = [q0[3], q0[4], q0[5], q0[6]];
    let b = [q1[3], q1[4], q1[5], q1[6]];
    let mut rel = quat_mul(&[-a[0], -a[1], -a[2], a[3]], &b);
    // The same rotation with w >= 0: its angle is in [0, pi].
    if rel[3] < T::zero() {
        rel = rel.map(|x| -x);
    }
    let norm = rel.iter().fold(T::zero(), |s, &x| s + x * x).sqrt();
    let rel = rel.map(|x| x / norm);
    let s2 = rel[0] * rel[0] + rel[1] * rel[1] + rel[2] * rel[2];
    let s = s2.sqrt();
    // theta / sin(theta / 2), with theta = 2 atan2(s, w); its series near s = 0.
    let k = if s2 < T::from_f64(1e-12) {
        T::from_f64(2.0) / rel[3] * (T::one() - s2 / (T::from_f64(3.0) * rel[3] * rel[3]))
    } else {
        T::from_f64(2.0) * s.atan2(rel[3]) / s
    };
    let phi = [rel[0] * k, rel[1] * k, rel[2] * k];
    let r0 = rotation(&a);
    let dp = [q1[0] - q0[0], q1[1] - q0[1], q1[2] - q0[2]];
    let t = [0, 1, 2].map(|c| r0[0][c] * dp[0] + r0[1][c] * dp[1] + r0[2][c] * dp[2]);
    // rho = V(phi)^-1 t, V^-1 = I - phi^/2 + c phi^2, c = 1/theta^2 - (1 + cos)/(2 theta sin)
    // = 1/theta^2 - w/(2 theta s) from the half angle (no trigonometry).
    let theta = k * s;
    let c = if s2 < T::from_f64(1e-4) {
        let t2 = theta * theta;
        T::from_f64(1.0 / 12.0) + t2 / T::from_f64(720.0) + t2 * t2 / T::from_f64(30240.0)
    } else {
        T::one() / (theta * theta) - rel[3] / (T::from_f64(2.0) * theta * s)
    };
    let h = hat(&phi);
    let h2 = mat_mul(&h, &h);
    let rho = [0, 1, 2].map(|i| {
        (0..3).fold(t[i], |acc, j| {
            acc + (-T::from_f64(0.5) * h[i][j] + c * h2[i][j]) * t[j]
        })
    });
    (rho, phi, rotation(&rel), t)
}

/// For the rotation vector `phi` of angle `theta`: `a = (1 - cos)/theta^2`,
/// `b = (theta - sin)/theta^3`, their derivatives in `theta` over `theta`, and
/// `c = 1/theta^2 - (1 + cos)/(2 theta sin)` (`V^-1 = I - phi^/2 + c phi^2`); series near 0.
fn coefficients<T: Real>(phi: &[T; 3]) -> Coefficients<T> {
    let t2 = phi[0] * phi[0] + phi[1] * phi[1] + phi[2] * phi[2];
    let f = T::from_f64;
    if t2 < f(1e-4) {
        let t4 = t2 * t2;
        return (
            f(0.5) - t2 / f(24.0) + t4 / f(720.0),
            f(1.0 / 6.0) - t2 / f(120.0) + t4 / f(5040.0),
            (
                f(-1.0 / 12.0) + t2 / f(180.0) - t4 / f(6720.0),
                f(-1.0 / 60.0) + t2 / f(1260.0) - t4 / f(30240.0),
            ),
            f(1.0 / 12.0) + t2 / f(720.0) + t4 / f(30240.0),
        );
    }
    let t = t2.sqrt();
    let (s, c) = t.sin_cos();
    let one = T::one();
    let a = (one - c) / t2;
    let b = (t - s) / (t2 * t);
    let da = (t * s - f(2.0) * (one - c)) / (t2 * t2);
    let db = ((one - c) * t - f(3.0) * (t - s)) / (t2 * t2 * t);
    let cc = one / t2 - (one + c) / (f(2.0) * t * s);
    (a, b, (da, db), cc)
}

/// The right Jacobian of `exp6` at `(rho, phi)`, whose rotation is `r`:
/// `[[Jr3, R^T D], [0, Jr3]]`, `Jr3 = I - a phi^ + b phi^2` and `D` the derivative of
/// `V(phi) rho` in `phi`.
fn right_jacobian<T: Real>(r: &M3<T>, rho: &[T; 3], phi: &[T; 3], k: &Coefficients<T>) -> M6<T> {
    let (a, b) = (k.0, k.1);
    let h = hat(phi);
    let h2 = mat_mul(&h, &h);
    let jr = combine(&h, &h2, -a, b);
    let q = mat_mul(&transpose(r), &dv_dphi(rho, phi, k));
    blocks(&jr, &q, &jr)
}

/// The inverse of [`right_jacobian`]: `[[Jr3^-1, -Jr3^-1 Q Jr3^-1], [0, Jr3^-1]]`, with
/// `Jr3^-1 = I + phi^/2 + c phi^2`.
fn inverse_right_jacobian<T: Real>(
    r: &M3<T>,
    rho: &[T; 3],
    phi: &[T; 3],
    k: &Coefficients<T>,
) -> M6<T> {
    let c = k.3;
    let h = hat(phi);
    let h2 = mat_mul(&h, &h);
    let inv = combine(&h, &h2, T::from_f64(0.5), c);
    let q = mat_mul(&transpose(r), &dv_dphi(rho, phi, k));
    let top = mat_mul(&mat_mul(&inv, &q), &inv).map(|row| row.map(|x| -x));
    blocks(&inv, &top, &inv)
}

/// `d (V(phi) rho) / d phi` with `V = I + a phi^ + b phi^2`:
/// `-a rho^ + (a'/theta) (phi x rho) phi^T + b ((phi.rho) I + phi rho^T - 2 rho phi^T)
/// + (b'/theta) (phi x (phi x rho)) phi^T`.
fn dv_dphi<T: Real>(rho: &[T; 3], phi: &[T; 3], k: &Coefficients<T>) -> M3<T> {
    let (a, b, (da, db), _) = *k;
    let h = hat(phi);
    let pr = mat_vec(&h, rho);
    let ppr = mat_vec(&h, &pr);
    let dot = phi[0] * rho[0] + phi[1] * rho[1] + phi[2] * rho[2];
    let rh = hat(rho);
    let mut d = [[T::zero(); 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            let id = if i == j { dot } else { T::zero() };
            let sym = id + phi[i] * rho[j] - T::from_f64(2.0) * rho[i] * phi[j];
            d[i][j] = -a * rh[i][j] + da * pr[i] * phi[j] + b * sym + db * ppr[i] * phi[j];
        }
    }
    d
}

/// `Ad((R, t))^-1 = [[R^T, -R^T t^], [0, R^T]]` on [linear; angular] vectors.
fn inverse_action<T: Real>(r: &M3<T>, t: &[T; 3]) -> M6<T> {
    let rt = transpose(r);
    let top = mat_mul(&rt, &hat(t)).map(|row| row.map(|x| -x));
    blocks(&rt, &top, &rt)
}

/// `[[a, b], [0, c]]`.
fn blocks<T: Real>(a: &M3<T>, b: &M3<T>, c: &M3<T>) -> M6<T> {
    let mut m = [[T::zero(); 6]; 6];
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] = a[i][j];
            m[i][3 + j] = b[i][j];
            m[3 + i][3 + j] = c[i][j];
        }
    }
    m
}

/// `I + x h + y h2`.
fn combine<T: Real>(h: &M3<T>, h2: &M3<T>, x: T, y: T) -> M3<T> {
    let mut m = [[T::zero(); 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            let id = if i == j { T::one() } else { T::zero() };
            m[i][j] = id + x * h[i][j] + y * h2[i][j];
        }
    }
    m
}

fn hat<T: Real>(w: &[T; 3]) -> M3<T> {
    let z = T::zero();
    [[z, -w[2], w[1]], [w[2], z, -w[0]], [-w[1], w[0], z]]
}

fn transpose<T: Real>(m: &M3<T>) -> M3<T> {
    core::array::from_fn(|i| core::array::from_fn(|j| m[j][i]))
}

fn mat_mul<T: Real>(a: &M3<T>, b: &M3<T>) -> M3<T> {
    core::array::from_fn(|i| {
        core::array::from_fn(|j| a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j])
    })
}

fn mat_vec<T: Real>(m: &M3<T>, v: &[T; 3]) -> [T; 3] {
    core::array::from_fn(|i| m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2])
}
