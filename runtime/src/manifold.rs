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
    let rho = [v[0], v[1], v[2]];
    let phi = [v[3], v[4], v[5]];
    let (quat, vmat) = exp_so3(&phi);
    let r = rotation(&quat);
    let t = mat_vec(&vmat, &rho);
    let dq = embed(&inverse_action(&r, &t), T::one());
    let dv = embed(
        &right_jacobian(&r, &rho, &phi, &coefficients(&phi)),
        T::one(),
    );
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
    let (rho, phi, r, t) = relative_log(q0, q1);
    let jlog = inverse_right_jacobian(&r, &rho, &phi, &coefficients(&phi));
    let adinv = inverse_action(&r, &t);
    let mut d0 = [[T::zero(); 6]; 6];
    for (row, j) in d0.iter_mut().zip(&jlog) {
        for (c, x) in row.iter_mut().enumerate() {
            *x = -(0..6).fold(T::zero(), |s, k| s + j[k] * adinv[k][c]);
        }
    }
    (embed(&d0, -T::one()), embed(&jlog, T::one()))
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
fn relative_log<T: Real, const NQ: usize>(
    q0: &[T; NQ],
    q1: &[T; NQ],
) -> ([T; 3], [T; 3], M3<T>, [T; 3]) {
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
