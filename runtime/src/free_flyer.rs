//! A floating base's configuration space: `q` = [position in world (3), unit quaternion
//! x, y, z, w (4), joints], velocities `v` = [linear (3), angular (3), both in base axes,
//! joints], as Pinocchio's free flyer.

use crate::lane::branch;
use crate::tree::{cross, Motion, TreeJoint};
use crate::{Lane, Pose};

/// `q (+) v dt`: the base moved along the SE(3) exponential of its body-frame velocity for
/// `dt` (exact for a constant twist; the quaternion stays unit up to rounding and is
/// renormalized), the joints by `v dt`. `NQ = NV + 1`.
///
/// ```
/// use eomgen_runtime::free_flyer::integrate;
/// // Turning at 1 rad/s about z while moving at 1 m/s along the base's x: a quarter circle.
/// let q = [0.0_f64, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0];
/// let v = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0];
/// let q1 = integrate(&q, &v, core::f64::consts::FRAC_PI_2);
/// assert!((q1[0] - 1.0).abs() < 1e-12 && (q1[1] - 1.0).abs() < 1e-12);
/// assert!((q1[5] - q1[6]).abs() < 1e-12); // 90 degrees about z
/// ```
pub fn integrate<T: Lane, const NQ: usize, const NV: usize>(
    q: &[T; NQ],
    v: &[T; NV],
    dt: T,
) -> [T; NQ] {
    let mut out = *q;
    integrate_into(q, v, dt, &mut out);
    out
}

/// [`integrate`] on slices (`q.len() == out.len() == v.len() + 1`), for sizes known only at
/// run time. Entries beyond the shortest of the three are left alone.
pub fn integrate_into<T: Lane>(q: &[T], v: &[T], dt: T, out: &mut [T]) {
    if q.len() < 7 || v.len() < 6 || out.len() < 7 {
        return;
    }
    let w = [v[3] * dt, v[4] * dt, v[5] * dt];
    let u = [v[0] * dt, v[1] * dt, v[2] * dt];
    let (dq, vmat) = exp_so3(&w);
    // Translation: p + R V(w) u, with V the left Jacobian of SO(3).
    let r = rotation(&[q[3], q[4], q[5], q[6]]);
    let vu = mul(&vmat, &u);
    let ru = mul(&r, &vu);
    for k in 0..3 {
        out[k] = q[k] + ru[k];
    }
    // Rotation: q * exp(w), renormalized.
    let p = [q[3], q[4], q[5], q[6]];
    let mut n = quat_mul(&p, &dq);
    let norm = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2] + n[3] * n[3]).sqrt();
    for x in n.iter_mut() {
        *x /= norm;
    }
    out[3..7].copy_from_slice(&n);
    for k in 6..v.len().min(q.len() - 1).min(out.len() - 1) {
        out[k + 1] = q[k + 1] + v[k] * dt;
    }
}

/// [`integrate`] for free flyers anywhere in `q`: each `(q0, v0)` of `free` (ascending) is a
/// free flyer whose 7 position coordinates start at `q0` and 6 velocity coordinates at `v0`
/// (floating joints below the root); every other coordinate moves by `v dt`.
///
/// ```
/// use eomgen_runtime::free_flyer::integrate_blocks;
/// // a revolute joint, then a free flyer at rest
/// let q = [0.5_f64, 1.0, 2.0, 3.0, 0.0, 0.0, 0.0, 1.0];
/// let v = [0.1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
/// let q1: [f64; 8] = integrate_blocks(&q, &v, 2.0, &[(1, 1)]);
/// assert_eq!(q1, [0.7, 1.0, 2.0, 3.0, 0.0, 0.0, 0.0, 1.0]);
/// ```
pub fn integrate_blocks<T: Lane, const NQ: usize, const NV: usize>(
    q: &[T; NQ],
    v: &[T; NV],
    dt: T,
    free: &[(usize, usize)],
) -> [T; NQ] {
    let mut out = *q;
    let (mut qi, mut vi) = (0, 0);
    let vector_part = |out: &mut [T; NQ], qi: &mut usize, vi: &mut usize, end: usize| {
        while *vi < end && *qi < NQ && *vi < NV {
            out[*qi] = q[*qi] + v[*vi] * dt;
            *qi += 1;
            *vi += 1;
        }
    };
    for &(q0, v0) in free {
        vector_part(&mut out, &mut qi, &mut vi, v0);
        if q0 + 7 > NQ || v0 + 6 > NV {
            return out;
        }
        integrate_into(&q[q0..q0 + 7], &v[v0..v0 + 6], dt, &mut out[q0..q0 + 7]);
        (qi, vi) = (q0 + 7, v0 + 6);
    }
    vector_part(&mut out, &mut qi, &mut vi, NV);
    out
}

/// The rotation of a unit quaternion (x, y, z, w).
pub fn rotation<T: Lane>(q: &[T; 4]) -> [[T; 3]; 3] {
    rotation_scaled(q, T::from_f64(2.0))
}

/// The rotation of the quaternion `q` (x, y, z, w) of squared norm `n2`, given `two = 2 / n2`:
/// no square root, no normalization.
pub(crate) fn rotation_scaled<T: Lane>(q: &[T; 4], two: T) -> [[T; 3]; 3] {
    let (x, y, z, w) = (q[0], q[1], q[2], q[3]);
    let one = T::one();
    [
        [
            one - two * (y * y + z * z),
            two * (x * y - z * w),
            two * (x * z + y * w),
        ],
        [
            two * (x * y + z * w),
            one - two * (x * x + z * z),
            two * (y * z - x * w),
        ],
        [
            two * (x * z - y * w),
            two * (y * z + x * w),
            one - two * (x * x + y * y),
        ],
    ]
}

/// The unit quaternion of the rotation vector `w` and the left Jacobian `V(w)` of SO(3)
/// (series near zero).
pub(crate) fn exp_so3<T: Lane>(w: &[T; 3]) -> ([T; 4], [[T; 3]; 3]) {
    let t2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
    let t = t2.sqrt();
    let half = T::from_f64(0.5);
    let ([s], [c]) = T::sin_cos_many([t * half]);
    // sin(t/2)/t, (1 - cos t)/t^2, (t - sin t)/t^3: the series where t^2 < 1e-8 (lane-wise
    // for a vector of states, each lane from its own branch).
    let series = || {
        [
            half - t2 / T::from_f64(48.0),
            half - t2 / T::from_f64(24.0),
            T::from_f64(1.0 / 6.0) - t2 / T::from_f64(120.0),
        ]
    };
    // sin t = 2 sin(t/2) cos(t/2) and 1 - cos t = 2 sin(t/2)^2: no second sine and cosine
    // (and no cancellation in 1 - cos t).
    let exact = || {
        let two = T::from_f64(2.0);
        let st = two * s * c;
        [s / t, two * s * s / t2, (t - st) / (t2 * t)]
    };
    let [k, a, b] = branch::<T, _>(T::from_f64(1e-8).gt(t2), series, exact);
    let quat = [w[0] * k, w[1] * k, w[2] * k, c];
    let kx = [
        [T::zero(), -w[2], w[1]],
        [w[2], T::zero(), -w[0]],
        [-w[1], w[0], T::zero()],
    ];
    let mut v = [[T::zero(); 3]; 3];
    for r in 0..3 {
        for col in 0..3 {
            let k2 = kx[r][0] * kx[0][col] + kx[r][1] * kx[1][col] + kx[r][2] * kx[2][col];
            let id = if r == col { T::one() } else { T::zero() };
            v[r][col] = id + a * kx[r][col] + b * k2;
        }
    }
    (quat, v)
}

pub(crate) fn quat_mul<T: Lane>(a: &[T; 4], b: &[T; 4]) -> [T; 4] {
    let (ax, ay, az, aw) = (a[0], a[1], a[2], a[3]);
    let (bx, by, bz, bw) = (b[0], b[1], b[2], b[3]);
    [
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    ]
}

fn mul<T: Lane>(m: &[[T; 3]; 3], v: &[T; 3]) -> [T; 3] {
    [0, 1, 2].map(|r| m[r][0] * v[0] + m[r][1] * v[1] + m[r][2] * v[2])
}

/// The 6 x NV Jacobian (linear rows, then angular, world axes, at the frame's origin) of a frame
/// on a floating-base robot: `path` lists bodies from the base (body 0), `joints[b - 1]` moves
/// body `b`, `transform(b)` is body `b`'s pose in its parent's (the base's in the world), and
/// `placement` the frame's pose in the last body. The base's six columns come first, then one
/// per joint.
pub fn chain_jacobian<T: Lane, const NJ: usize, const NV: usize>(
    path: &[usize],
    joints: &[TreeJoint; NJ],
    transform: impl Fn(usize) -> Pose<T>,
    placement: &Pose<T>,
) -> [[T; NV]; 6] {
    let mut poses = [Pose::identity(); NV];
    let mut pose = Pose::identity();
    for (k, &b) in path.iter().enumerate().take(NV) {
        pose = pose.compose(&transform(b));
        poses[k] = pose;
    }
    let point = pose.transform_point(&placement.translation);
    let mut jac = [[T::zero(); NV]; 6];
    let base = poses[0];
    let lever = |o: &[T; 3]| [point[0] - o[0], point[1] - o[1], point[2] - o[2]];
    let r = lever(&base.translation);
    for k in 0..3.min(NV) {
        let e = [
            base.rotation[0][k],
            base.rotation[1][k],
            base.rotation[2][k],
        ];
        let lin = cross(&e, &r);
        for row in 0..3 {
            jac[row][k] = e[row];
            jac[row][3 + k] = lin[row];
            jac[3 + row][3 + k] = e[row];
        }
    }
    for (k, &b) in path.iter().enumerate().skip(1).take(NV) {
        let Some(joint) = joints.get(b - 1) else {
            continue;
        };
        let col = 5 + b;
        if col >= NV {
            continue;
        }
        let z = poses[k].transform_vector(&joint.axis.map(T::from_f64));
        let (lin, ang) = match joint.motion {
            Motion::Rotation => (cross(&z, &lever(&poses[k].translation)), z),
            Motion::Translation => (z, [T::zero(); 3]),
            // Floating joints below a floating base are refused at generation.
            Motion::Free => continue,
        };
        for row in 0..3 {
            jac[row][col] = lin[row];
            jac[3 + row][col] = ang[row];
        }
    }
    jac
}
