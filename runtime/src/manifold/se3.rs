//! The free flyer's closed forms behind [`super`]: the SE(3) logarithm of the relative pose of
//! two configurations, and the 6 x 6 blocks of `dIntegrate` and `dDifference` (the inverse
//! adjoint, the right Jacobian of `exp6` and its inverse), built from 3 x 3 blocks.
//!
//! Every function of the rotation angle `theta` comes from the sine and cosine of its half:
//! the relative quaternion holds them already (scaled by its norm, which cancels), and
//! `dIntegrate` takes one `sin_cos` of `theta / 2`. Nothing normalizes a quaternion: the sine
//! and cosine of `M0^-1 M1`'s angle are scaled by `2 / |q|^2` instead. No rotation matrix is
//! formed where an identity spares it: `R^T v` from the quaternion, `J R^T` as the inverse of
//! the left Jacobian, `R^T t` as `Jr rho`.
//!
//! Values are negated by [`Lane::neg_exact`], not `-`, so that a vector of states has the
//! scalar's signed zeros in every lane.

use super::atan::atan2_quadrant;
use crate::free_flyer::quat_mul;
use crate::lane::{branch, Select};
use crate::tree::cross;
use crate::Lane;

pub(super) type M3<T> = [[T; 3]; 3];
pub(super) type M6<T> = [[T; 6]; 6];

/// `M0^-1 M1` of two free flyers' coordinates (7 entries each) and its logarithm
/// `log6 = (rho, phi)`.
pub(super) struct Relative<T> {
    /// The translation part of the logarithm.
    pub rho: [T; 3],
    /// The rotation vector, of angle `theta` in `[0, pi]`.
    pub phi: [T; 3],
    /// The relative quaternion (x, y, z, w), `w >= 0`, not normalized.
    quat: [T; 4],
    /// `|quat|^2`.
    n2: T,
    /// `|(x, y, z)|`: `sin(theta / 2)` times the norm, as `w` is `cos(theta / 2)` times it.
    s: T,
    /// `theta^2`.
    t2: T,
    /// `theta`.
    theta: T,
    /// `1 / theta` (infinite at the zero rotation, where the series are taken instead).
    r1: T,
    /// `c` of `V(phi)^-1 = I - phi^/2 + c phi^2`.
    c: T,
    /// The relative translation, in the axes of `q0`'s base.
    t: [T; 3],
}

impl<T: Lane> Relative<T> {
    /// The relative pose of the bases whose coordinates (position, quaternion x, y, z, w)
    /// start `q0` and `q1`; `q1`'s quaternion may have either sign.
    #[inline]
    pub(super) fn new(q0: &[T], q1: &[T]) -> Self {
        let f = T::from_f64;
        let a = [q0[3], q0[4], q0[5], q0[6]];
        let b = [q1[3], q1[4], q1[5], q1[6]];
        let quat = quat_mul(
            &[a[0].neg_exact(), a[1].neg_exact(), a[2].neg_exact(), a[3]],
            &b,
        );
        // The same rotation with w >= 0: its angle is in [0, pi].
        let flip = T::zero().gt(quat[3]);
        let quat = branch::<T, _>(flip, || quat.map(|x| x.neg_exact()), || quat);
        let w = quat[3];
        let s2 = quat[0] * quat[0] + quat[1] * quat[1] + quat[2] * quat[2];
        let n2 = s2 + w * w;
        let s = s2.sqrt();
        let theta = f(2.0) * atan2_quadrant(s, w);
        // Two reciprocals, each taken once: a division's latency sits on this chain.
        let (inv_s, r1) = (T::one() / s, T::one() / theta);
        // phi = (x, y, z) theta / s, free of the norm; its series near the zero rotation.
        let k = branch::<T, _>(
            (f(1e-12) * n2).gt(s2),
            || f(2.0) / w * (T::one() - s2 / (f(3.0) * w * w)),
            || theta * inv_s,
        );
        let phi = [quat[0] * k, quat[1] * k, quat[2] * k];
        let t2 = theta * theta;
        // c = 1/theta^2 - (1 + cos)/(2 theta sin) = 1/theta^2 - w/(2 theta s).
        let c = branch::<T, _>(
            f(1e-4).gt(t2),
            || f(1.0 / 12.0) + t2 / f(720.0) + t2 * t2 / f(30240.0),
            || r1 * (r1 - f(0.5) * w * inv_s),
        );
        let dp = [q1[0] - q0[0], q1[1] - q0[1], q1[2] - q0[2]];
        let t = unrotated(&a, &dp);
        let pt = cross(&phi, &t);
        let ppt = cross(&phi, &pt);
        let half = f(0.5);
        let entry = |i: usize| t[i] - half * pt[i] + c * ppt[i];
        let rho = [entry(0), entry(1), entry(2)];
        Self {
            rho,
            phi,
            quat,
            n2,
            s,
            t2,
            theta,
            r1,
            c,
            t,
        }
    }
}

/// `R^T v` for the rotation `R` of the unit quaternion `q` (x, y, z, w):
/// `v - 2 w (u x v) + 2 u x (u x v)`, `u = (x, y, z)`, without forming `R`.
fn unrotated<T: Lane>(q: &[T; 4], v: &[T; 3]) -> [T; 3] {
    let u = [q[0], q[1], q[2]];
    let uv = cross(&u, v);
    let uuv = cross(&u, &uv);
    let (w2, two) = (T::from_f64(2.0) * q[3], T::from_f64(2.0));
    [0, 1, 2].map(|i| v[i] - w2 * uv[i] + two * uuv[i])
}

/// The functions of a rotation vector's angle `theta` that the Jacobians use.
struct Coefficients<T> {
    /// `sin / theta`.
    sinc: T,
    /// `(1 - cos) / theta^2`.
    a: T,
    /// `(theta - sin) / theta^3`.
    b: T,
    /// `a'(theta) / theta`.
    da: T,
    /// `b'(theta) / theta`.
    db: T,
}

/// [`Coefficients`] from `theta^2`, `theta` and its reciprocal `r1`, `sin theta` and
/// `1 - cos theta`; their series where `theta^2 < 1e-4` (lane by lane).
#[inline]
fn coefficients<T: Lane>((t2, theta, r1): (T, T, T), sin: T, vers: T) -> Coefficients<T> {
    branch::<T, _>(
        T::from_f64(1e-4).gt(t2),
        || series(t2),
        || exact((theta, r1), sin, vers),
    )
}

impl<T: Lane> Select<T> for Coefficients<T> {
    #[inline(always)]
    fn select(mask: T::Mask, yes: Self, no: Self) -> Self {
        let pick = |a: T, b: T| T::select(mask, a, b);
        Coefficients {
            sinc: pick(yes.sinc, no.sinc),
            a: pick(yes.a, no.a),
            b: pick(yes.b, no.b),
            da: pick(yes.da, no.da),
            db: pick(yes.db, no.db),
        }
    }
}

/// [`Coefficients`] by their Taylor series in `theta^2`, to `theta^4`.
fn series<T: Lane>(t2: T) -> Coefficients<T> {
    let f = T::from_f64;
    let t4 = t2 * t2;
    Coefficients {
        sinc: T::one() - t2 / f(6.0) + t4 / f(120.0),
        a: f(0.5) - t2 / f(24.0) + t4 / f(720.0),
        b: f(1.0 / 6.0) - t2 / f(120.0) + t4 / f(5040.0),
        da: f(-1.0 / 12.0) + t2 / f(180.0) - t4 / f(6720.0),
        db: f(-1.0 / 60.0) + t2 / f(1260.0) - t4 / f(30240.0),
    }
}

/// [`Coefficients`] by their closed forms, from `theta` and `r1 = 1 / theta` (no division).
fn exact<T: Lane>((theta, r1): (T, T), sin: T, vers: T) -> Coefficients<T> {
    let f = T::from_f64;
    let r2 = r1 * r1;
    let r4 = r2 * r2;
    let gap = theta - sin;
    Coefficients {
        sinc: sin * r1,
        a: vers * r2,
        b: gap * r2 * r1,
        da: (theta * sin - f(2.0) * vers) * r4,
        db: (vers * theta - f(3.0) * gap) * r4 * r1,
    }
}

/// A free flyer's blocks of `dIntegrate` at its velocity `v` (6 entries):
/// `Ad(exp6(v))^-1` and the right Jacobian of `exp6` at `v`,
/// `[[Jr3, R^T D], [0, Jr3]]` with `Jr3 = I - a phi^ + b phi^2` and `D` the derivative of
/// `V(phi) rho` in `phi`.
pub(super) fn integrate_jacobians<T: Lane>(v: &[T]) -> (M6<T>, M6<T>) {
    let [rt, top, jr, q] = integrate_parts(v);
    (blocks(&rt, &top, &rt), blocks(&jr, &q, &jr))
}

/// [`integrate_jacobians`] written straight into rows and columns `at..at + 6` of `dq` and
/// `dv` (the same values): the two 6 x 6 blocks are neither built nor copied, which took a
/// fifth of `integrate_jacobians_into` (anymal 84 -> 66 ns, a 35-coordinate humanoid 101 ->
/// 72 ns).
pub(super) fn integrate_jacobians_at<T: Lane, const N: usize>(
    v: &[T],
    (dq, dv): (&mut [[T; N]; N], &mut [[T; N]; N]),
    at: usize,
) {
    let [rt, top, jr, q] = integrate_parts(v);
    put(dq, at, &rt, &top);
    put(dv, at, &jr, &q);
}

/// `[[a, b], [0, a]]` into rows and columns `at..at + 6` of `m`.
#[inline(always)]
fn put<T: Lane, const N: usize>(m: &mut [[T; N]; N], at: usize, a: &M3<T>, b: &M3<T>) {
    let Some(rows) = m.get_mut(at..at + 6) else {
        return;
    };
    let (upper, lower) = rows.split_at_mut(3);
    for i in 0..3 {
        if let Some(row) = upper[i].get_mut(at..at + 6) {
            row[..3].copy_from_slice(&a[i]);
            row[3..].copy_from_slice(&b[i]);
        }
        if let Some(row) = lower[i].get_mut(at..at + 6) {
            row[..3].copy_from_slice(&[T::zero(); 3]);
            row[3..].copy_from_slice(&a[i]);
        }
    }
}

/// The 3 x 3 blocks of [`integrate_jacobians`]: `R^T`, the inverse action's corner, `Jr3` and
/// `R^T D`.
#[inline(always)]
fn integrate_parts<T: Lane>(v: &[T]) -> [M3<T>; 4] {
    let f = T::from_f64;
    let rho = [v[0], v[1], v[2]];
    let phi = [v[3], v[4], v[5]];
    let t2 = phi[0] * phi[0] + phi[1] * phi[1] + phi[2] * phi[2];
    let theta = t2.sqrt();
    let ([sh], [ch]) = T::sin_cos_many([theta * f(0.5)]);
    let r1 = T::one() / theta;
    let k = coefficients((t2, theta, r1), f(2.0) * sh * ch, f(2.0) * sh * sh);
    let h = hat(&phi);
    let h2 = hat_squared(&phi, t2);
    // R^T = I - sinc phi^ + a phi^2, and the inverse action's corner -R^T t^ = -(R^T t)^ R^T
    // with R^T t = R^T Jl rho = Jr rho (Jl = R Jr): t itself is never formed.
    let rt = combine(&h, &h2, k.sinc.neg_exact(), k.a);
    let jr = combine(&h, &h2, k.a.neg_exact(), k.b);
    let top = negated(&hat_times(&mat_vec(&jr, &rho), &rt));
    let q = mat_mul(&rt, &dv_dphi(&rho, &phi, &k));
    [rt, top, jr, q]
}

/// A free flyer's blocks of `dDifference` from its coordinates in `q0` and `q1` (7 entries
/// each): `-Jlog6(M) Ad(M)^-1` and `Jlog6(M)`, `M = M0^-1 M1`, `Jlog6` the inverse of the
/// right Jacobian, `[[J, -J Q J], [0, J]]` with `J = Jr3^-1 = I + phi^/2 + c phi^2` and
/// `Q = R^T D`. With `P = J R^T`, the first is `[[-P, P t^ + J Q J R^T], [0, -P]]`.
///
/// `P` is the inverse of the left Jacobian (`Jl = R Jr`), `I - phi^/2 + c phi^2`, so that
/// `J Q = P D` and `J Q J R^T = (P D) P`: the relative rotation `R` is never formed.
pub(super) fn difference_jacobians<T: Lane>(q0: &[T], q1: &[T]) -> (M6<T>, M6<T>) {
    let rel = Relative::new(q0, q1);
    let two_n2 = T::from_f64(2.0) / rel.n2;
    let (s, w) = (rel.s, rel.quat[3]);
    let k = coefficients((rel.t2, rel.theta, rel.r1), two_n2 * s * w, two_n2 * s * s);
    let h = hat(&rel.phi);
    let h2 = hat_squared(&rel.phi, rel.t2);
    let half = T::from_f64(0.5);
    let j = combine(&h, &h2, half, rel.c);
    let p = combine(&h, &h2, -half, rel.c);
    let jq = mat_mul(&p, &dv_dphi(&rel.rho, &rel.phi, &k));
    let jqj = mat_mul(&jq, &j);
    let pt = times_hat(&p, &rel.t);
    let jqp = mat_mul(&jq, &p);
    let d0_top = each(|i, c| pt[i][c] + jqp[i][c]);
    let minus_p = negated(&p);
    (
        blocks(&minus_p, &d0_top, &minus_p),
        blocks(&j, &negated(&jqj), &j),
    )
}

/// `d (V(phi) rho) / d phi` with `V = I + a phi^ + b phi^2`:
/// `-a rho^ + (a'/theta) (phi x rho) phi^T + b ((phi.rho) I + phi rho^T - 2 rho phi^T)
/// + (b'/theta) (phi x (phi x rho)) phi^T`.
fn dv_dphi<T: Lane>(rho: &[T; 3], phi: &[T; 3], k: &Coefficients<T>) -> M3<T> {
    let pr = cross(phi, rho);
    let ppr = cross(phi, &pr);
    let dot = phi[0] * rho[0] + phi[1] * rho[1] + phi[2] * rho[2];
    let rh = hat(rho);
    let two = T::from_f64(2.0);
    each(|i, j| {
        let id = if i == j { dot } else { T::zero() };
        let sym = id + phi[i] * rho[j] - two * rho[i] * phi[j];
        k.a.neg_exact() * rh[i][j] + (k.da * pr[i] + k.db * ppr[i]) * phi[j] + k.b * sym
    })
}

/// `[[a, b], [0, c]]`.
fn blocks<T: Lane>(a: &M3<T>, b: &M3<T>, c: &M3<T>) -> M6<T> {
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
fn combine<T: Lane>(h: &M3<T>, h2: &M3<T>, x: T, y: T) -> M3<T> {
    each(|i, j| {
        let id = if i == j { T::one() } else { T::zero() };
        id + x * h[i][j] + y * h2[i][j]
    })
}

/// The 3 x 3 matrix of `entry(i, j)`, written out (no closure calls left for the optimizer to
/// inline, as `core::array::from_fn`'s were not).
#[inline(always)]
fn each<T: Lane>(entry: impl Fn(usize, usize) -> T) -> M3<T> {
    let mut m = [[T::zero(); 3]; 3];
    for (i, row) in m.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = entry(i, j);
        }
    }
    m
}

fn hat<T: Lane>(w: &[T; 3]) -> M3<T> {
    let z = T::zero();
    let m = |x: T| x.neg_exact();
    [[z, m(w[2]), w[1]], [w[2], z, m(w[0])], [m(w[1]), w[0], z]]
}

/// `hat(w)^2 = w w^T - |w|^2 I`, given `t2 = |w|^2`.
fn hat_squared<T: Lane>(w: &[T; 3], t2: T) -> M3<T> {
    each(|i, j| {
        let d = if i == j { t2 } else { T::zero() };
        w[i] * w[j] - d
    })
}

fn negated<T: Lane>(m: &M3<T>) -> M3<T> {
    each(|i, j| m[i][j].neg_exact())
}

fn mat_mul<T: Lane>(a: &M3<T>, b: &M3<T>) -> M3<T> {
    each(|i, j| a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j])
}

/// `m t^`: each row of `m` crossed with `t` (`x^T t^ = (x cross t)^T`), without the products
/// by the zeros of `t^`.
fn times_hat<T: Lane>(m: &M3<T>, t: &[T; 3]) -> M3<T> {
    let rows = [cross(&m[0], t), cross(&m[1], t), cross(&m[2], t)];
    each(|i, j| rows[i][j])
}

/// `u^ m`: each column of `m` crossed by `u`.
fn hat_times<T: Lane>(u: &[T; 3], m: &M3<T>) -> M3<T> {
    let column = |j: usize| cross(u, &[m[0][j], m[1][j], m[2][j]]);
    let cols = [column(0), column(1), column(2)];
    each(|i, j| cols[j][i])
}

fn mat_vec<T: Lane>(m: &M3<T>, v: &[T; 3]) -> [T; 3] {
    let row = |i: usize| m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2];
    [row(0), row(1), row(2)]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The series and the closed forms agree where one hands over to the other.
    #[test]
    fn series_meets_closed_forms() {
        for t2 in [0.6e-4_f64, 1e-4] {
            let theta = t2.sqrt();
            let (s, c) = theta.sin_cos();
            let (x, y) = (series(t2), exact((theta, 1.0 / theta), s, 1.0 - c));
            for (a, b, tol) in [
                (x.sinc, y.sinc, 1e-14),
                (x.a, y.a, 1e-11),
                (x.b, y.b, 1e-9),
                (x.da, y.da, 1e-7),
                (x.db, y.db, 1e-5),
            ] {
                assert!((a - b).abs() <= tol * b.abs(), "{a} vs {b} at {t2}");
            }
        }
    }
}
