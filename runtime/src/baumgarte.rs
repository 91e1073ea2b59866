//! Baumgarte stabilization of the contact constraint, as Pinocchio's
//! `RigidConstraintModel::corrector`: with gains `kp`, `kd`, the constraint `J a + drift = 0`
//! becomes `J a + drift = -kd J v - kp e`, `e` the contacts' position error, so that a contact
//! that drifted from its reference (integration error) is pulled back instead of kept
//! accelerating at zero.

use crate::lane::{branch, Pack};
use crate::manifold::atan2_quadrant;
use crate::{Lane, Pose, Real};

/// The gains and each contact's reference placement (world) of Baumgarte stabilization, for a
/// robot of `C` contacts (points, then frames, as its `CONTACT_ROWS`), given to the generated
/// `contact_forward_dynamics_stabilized` at run time.
///
/// The position error `e` of a point contact (3 rows) is its world position minus the
/// reference's translation; of a 6D frame (6 rows: linear, then angular, as its Jacobian rows)
/// the origin's likewise, then the orientation error `log3(R R_ref^T)`, world axes (Pinocchio's
/// `log3(R_ref^T R)` of its `LOCAL` frames, turned to world axes; the reference rotation of a
/// point contact is ignored). The velocity error is `J v` (the reference stands still). A
/// frame's linear rows constrain its spatial acceleration (the drift's convention), so the law
/// on them is exact only where the frame does not rotate, as in Pinocchio. With `kp` and `kd`
/// zero, the correction is skipped: the result is the unstabilized one, to the bit.
///
/// ```
/// use eomgen_runtime::{Baumgarte, Pose};
/// // One point contact at (0, 0, 0.01), reference at the origin, at rest: the drift gains
/// // kp times the 1 cm error.
/// let b = Baumgarte::new(100.0_f64, 20.0, [Pose::identity()]);
/// let placement = [[0.0, 0.0, 0.01, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]];
/// let j = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// let mut drift = [0.0; 3];
/// b.correct_drift(&[3], &placement, &j, &[0.0; 3], &mut drift);
/// assert_eq!(drift, [0.0, 0.0, 1.0]);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Baumgarte<T, const C: usize> {
    /// Position gain (1/s^2).
    pub kp: T,
    /// Velocity gain (1/s).
    pub kd: T,
    /// Each contact's reference placement in the world.
    pub reference: [Pose<T>; C],
}

impl<T: Real, const C: usize> Baumgarte<T, C> {
    /// The same gains and references in every lane of `L` (what a batch of states shares).
    ///
    /// ```
    /// use eomgen_runtime::{Baumgarte, Pose};
    /// let b = Baumgarte::new(100.0_f64, 20.0, [Pose::identity()]);
    /// assert_eq!(b.in_lanes::<f64>(), b);
    /// ```
    pub fn in_lanes<L: Pack<Scalar = T>>(&self) -> Baumgarte<L, C> {
        let splat = |x: T| L::gather(|_| x);
        Baumgarte {
            kp: splat(self.kp),
            kd: splat(self.kd),
            reference: self.reference.map(|r| Pose {
                translation: r.translation.map(splat),
                rotation: r.rotation.map(|row| row.map(splat)),
            }),
        }
    }
}

impl<T: Lane, const C: usize> Baumgarte<T, C> {
    /// The gains and references.
    pub fn new(kp: T, kd: T, reference: [Pose<T>; C]) -> Self {
        Baumgarte { kp, kd, reference }
    }

    /// The gains, with each contact's reference where it is now: `placements` as the
    /// generated `contact_placements(q)` gives them.
    pub fn hold(kp: T, kd: T, placements: &[[T; 12]; C]) -> Self {
        Baumgarte::new(kp, kd, placements.map(|p| placement(&p)))
    }

    /// The position error `e` (K rows, world axes) of the contacts at `placements` (the
    /// generated `contact_placements(q)`), each contact `c` owning `rows[c]` rows (3: a point,
    /// 6: a frame; the generated `CONTACT_ROWS`).
    pub fn position_error<const K: usize>(
        &self,
        rows: &[usize; C],
        placements: &[[T; 12]; C],
    ) -> [T; K] {
        let mut e = [T::zero(); K];
        let mut at: usize = 0;
        for ((n, p), r) in rows.iter().zip(placements).zip(&self.reference) {
            let mut error = [T::zero(); 6];
            for k in 0..3 {
                error[k] = p[k] - r.translation[k];
            }
            if *n == 6 {
                let now = placement(p).rotation;
                let relative = mul_transposed(&now, &r.rotation);
                error[3..].copy_from_slice(&log3(&relative));
            }
            for (k, x) in error.iter().take(*n).enumerate() {
                if let Some(out) = e.get_mut(at.saturating_add(k)) {
                    *out = *x;
                }
            }
            at = at.saturating_add(*n);
        }
        e
    }

    /// Adds `kd J v + kp e` to `drift`, so that the constraint `J a + drift = 0` becomes
    /// Baumgarte's; nothing when both gains are zero.
    pub fn correct_drift<const N: usize, const K: usize>(
        &self,
        rows: &[usize; C],
        placements: &[[T; 12]; C],
        j: &[[T; N]; K],
        v: &[T; N],
        drift: &mut [T; K],
    ) {
        if self.kp.zero_in_every_lane() && self.kd.zero_in_every_lane() {
            return;
        }
        let e: [T; K] = self.position_error(rows, placements);
        for ((d, jk), ek) in drift.iter_mut().zip(j).zip(&e) {
            let mut jv = T::zero();
            for (x, y) in jk.iter().zip(v) {
                jv += *x * *y;
            }
            *d += self.kd * jv + self.kp * *ek;
        }
    }
}

/// The [`Pose`] of one row of the generated `contact_placements(q)`: the world position (3),
/// then the row-major world rotation (9).
pub fn placement<T: Lane>(row: &[T; 12]) -> Pose<T> {
    Pose {
        translation: [row[0], row[1], row[2]],
        rotation: core::array::from_fn(|i| core::array::from_fn(|k| row[3 + 3 * i + k])),
    }
}

/// `a b^T`.
fn mul_transposed<T: Lane>(a: &[[T; 3]; 3], b: &[[T; 3]; 3]) -> [[T; 3]; 3] {
    core::array::from_fn(|i| {
        core::array::from_fn(|k| a[i][0] * b[k][0] + a[i][1] * b[k][1] + a[i][2] * b[k][2])
    })
}

/// The rotation vector of `r` (SO(3)'s logarithm), through its unit quaternion (Shepperd's
/// method: accurate at every angle, up to pi). On a vector of states ([`Lane`]) each lane
/// takes its own case.
///
/// ```
/// use eomgen_runtime::contact::log3;
/// let (s, c) = (0.3_f64.sin(), 0.3_f64.cos());
/// let w = log3(&[[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]);
/// assert!((w[2] - 0.3).abs() < 1e-15 && w[0] == 0.0 && w[1] == 0.0);
/// ```
pub fn log3<T: Lane>(r: &[[T; 3]; 3]) -> [T; 3] {
    let q = shepperd(r);
    let one = T::one();
    let sign = T::select(T::zero().gt(q[3]), -one, one);
    let (x, y, z, w) = (q[0] * sign, q[1] * sign, q[2] * sign, q[3] * sign);
    let s = (x * x + y * y + z * z).sqrt();
    // theta = 2 atan2(s, w), s and w >= 0; the vector is (x, y, z) theta / s (2 / w as s -> 0).
    let two = T::from_f64(2.0);
    let k = branch(
        s.gt(T::epsilon() * (s + w)),
        || two * atan2_quadrant(s, w) / s,
        || two / w,
    );
    [x * k, y * k, z * k]
}

/// The quaternion (x, y, z, w) of `r`, up to a nonzero factor, from the largest of its
/// squares: the case of the largest of the trace and the diagonal entries, the earlier one on a
/// tie (the trace's when it is at least every diagonal entry, else the largest diagonal
/// entry's). Lane by lane: from the last case, each earlier one is taken where its value is at
/// least the best so far (`!(best > v)`, which differs from `v >= best` only where a NaN makes
/// every case NaN). The four cases cost twelve additions.
fn shepperd<T: Lane>(r: &[[T; 3]; 3]) -> [T; 4] {
    let one = T::one();
    let trace = r[0][0] + r[1][1] + r[2][2];
    let cases = [
        (
            trace,
            [
                r[2][1] - r[1][2],
                r[0][2] - r[2][0],
                r[1][0] - r[0][1],
                one + trace,
            ],
        ),
        (
            r[0][0],
            [
                one + r[0][0] - r[1][1] - r[2][2],
                r[0][1] + r[1][0],
                r[0][2] + r[2][0],
                r[2][1] - r[1][2],
            ],
        ),
        (
            r[1][1],
            [
                r[0][1] + r[1][0],
                one + r[1][1] - r[0][0] - r[2][2],
                r[1][2] + r[2][1],
                r[0][2] - r[2][0],
            ],
        ),
        (
            r[2][2],
            [
                r[0][2] + r[2][0],
                r[1][2] + r[2][1],
                one + r[2][2] - r[0][0] - r[1][1],
                r[1][0] - r[0][1],
            ],
        ),
    ];
    let (mut best, mut q) = cases[3];
    for (v, case) in cases[..3].iter().rev() {
        let keep = best.gt(*v);
        q = core::array::from_fn(|i| T::select(keep, q[i], case[i]));
        best = T::select(keep, best, *v);
    }
    q
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::free_flyer::rotation;

    #[test]
    fn log3_inverts_the_exponential_at_every_angle() {
        for (axis, angle) in [
            ([1.0, 0.0, 0.0], 1e-9),
            ([0.6, 0.0, 0.8], 0.7),
            ([0.0, 0.6, -0.8], 2.5),
            ([0.48, 0.6, 0.64], 3.1),
        ] {
            let (s, c) = (0.5_f64 * angle).sin_cos();
            let r = rotation(&[axis[0] * s, axis[1] * s, axis[2] * s, c]);
            let w = log3(&r);
            for k in 0..3 {
                assert!((w[k] - axis[k] * angle).abs() < 1e-12, "{angle}: {w:?}");
            }
        }
    }

    /// Four rotations taking each of Shepperd's cases (the trace's, then the largest diagonal
    /// entry's: x, y, z) and the series near zero, on four lanes at once: each lane's is the
    /// scalar's, bit for bit.
    #[cfg(feature = "simd")]
    #[test]
    fn log3_on_lanes_takes_each_lanes_case() {
        use wide::f64x4;
        let cases = [
            ([0.6, 0.0, 0.8], 1e-9),
            ([1.0, 0.0, 0.0], 3.0),
            ([0.0, 0.8, -0.6], 3.1),
            ([0.0, 0.6, -0.8], 3.1),
        ];
        let rs = cases.map(|(axis, angle)| {
            let (s, c) = (0.5_f64 * angle).sin_cos();
            rotation(&[axis[0] * s, axis[1] * s, axis[2] * s, c])
        });
        let case = |r: &[[f64; 3]; 3]| {
            let (d, t) = ([r[0][0], r[1][1], r[2][2]], r[0][0] + r[1][1] + r[2][2]);
            if d.iter().all(|x| t >= *x) {
                0
            } else {
                1 + (0..3)
                    .find(|&i| d[i + 1..].iter().all(|x| d[i] >= *x))
                    .unwrap()
            }
        };
        assert_eq!(rs.map(|r| case(&r)), [0, 1, 2, 3]);
        let lanes: [[f64x4; 3]; 3] =
            core::array::from_fn(|i| core::array::from_fn(|k| f64x4::from(rs.map(|r| r[i][k]))));
        let w = log3(&lanes);
        for (l, r) in rs.iter().enumerate() {
            let want = log3(r);
            let got = w.map(|x| x.to_array()[l]);
            assert_eq!(got.map(f64::to_bits), want.map(f64::to_bits), "lane {l}");
        }
    }

    #[test]
    fn a_frame_error_has_its_translation_then_its_rotation_vector() {
        let (s, c) = 0.1_f64.sin_cos();
        let rz = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]];
        let mut row = [0.0; 12];
        row[..3].copy_from_slice(&[1.0, 2.0, 3.0]);
        for i in 0..3 {
            row[3 + 3 * i..6 + 3 * i].copy_from_slice(&rz[i]);
        }
        let b = Baumgarte::new(1.0, 0.0, [Pose::from_translation([1.0, 2.0, 2.5])]);
        let e: [f64; 6] = b.position_error(&[6], &[row]);
        let want = [0.0, 0.0, 0.5, 0.0, 0.0, 0.1];
        assert!(
            e.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-15),
            "{e:?}"
        );
    }
}
