//! Rigid transforms.

use crate::Lane;

/// A rigid transform: the pose of a frame (typically a link) expressed in a reference frame
/// (typically the world), "world from link".
///
/// A point with coordinates `p` in the link frame has world coordinates
/// `rotation * p + translation`. `rotation` is a row-major 3×3 rotation matrix
/// (`rotation[i][j]` is row `i`, column `j`; its columns are the link axes in world
/// coordinates) and `translation` is the link origin in world coordinates.
///
/// ```
/// use eomgen_runtime::Pose;
///
/// // a link 1 m up the world z axis, rotated a quarter turn about z
/// let world_from_link = Pose {
///     translation: [0.0, 0.0, 1.0],
///     rotation: [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
/// };
/// assert_eq!(world_from_link.transform_point(&[1.0, 0.0, 0.0]), [0.0, 1.0, 1.0]);
///
/// let link_from_world = world_from_link.inverse();
/// let p = link_from_world.transform_point(&[0.0, 1.0, 1.0]);
/// assert_eq!(p, [1.0, 0.0, 0.0]);
/// assert_eq!(world_from_link.compose(&link_from_world), Pose::identity());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose<T> {
    /// The origin of the child frame in parent coordinates.
    pub translation: [T; 3],
    /// The row-major rotation matrix from child to parent coordinates.
    pub rotation: [[T; 3]; 3],
}

#[inline(always)]
fn mat_vec<T: Lane>(r: &[[T; 3]; 3], v: &[T; 3]) -> [T; 3] {
    [
        r[0][0] * v[0] + r[0][1] * v[1] + r[0][2] * v[2],
        r[1][0] * v[0] + r[1][1] * v[1] + r[1][2] * v[2],
        r[2][0] * v[0] + r[2][1] * v[1] + r[2][2] * v[2],
    ]
}

#[inline(always)]
fn mat_t_vec<T: Lane>(r: &[[T; 3]; 3], v: &[T; 3]) -> [T; 3] {
    [
        r[0][0] * v[0] + r[1][0] * v[1] + r[2][0] * v[2],
        r[0][1] * v[0] + r[1][1] * v[1] + r[2][1] * v[2],
        r[0][2] * v[0] + r[1][2] * v[1] + r[2][2] * v[2],
    ]
}

impl<T> Pose<T> {
    /// A pose from its parts.
    #[inline]
    pub const fn new(translation: [T; 3], rotation: [[T; 3]; 3]) -> Self {
        Pose {
            translation,
            rotation,
        }
    }
}

impl<T: Lane> Pose<T> {
    /// The identity transform (no translation, no rotation).
    #[inline]
    pub fn identity() -> Self {
        let (o, z) = (T::one(), T::zero());
        Pose {
            translation: [z; 3],
            rotation: [[o, z, z], [z, o, z], [z, z, o]],
        }
    }

    /// A pure translation.
    #[inline]
    pub fn from_translation(translation: [T; 3]) -> Self {
        Pose {
            translation,
            ..Self::identity()
        }
    }

    /// A pure rotation (row-major matrix).
    #[inline]
    pub fn from_rotation(rotation: [[T; 3]; 3]) -> Self {
        Pose {
            translation: [T::zero(); 3],
            rotation,
        }
    }

    /// The rotation of URDF's `rpy` attribute: `Rz(yaw) * Ry(pitch) * Rx(roll)` (roll about the
    /// fixed x axis first, then pitch about fixed y, then yaw about fixed z).
    pub fn from_rpy(translation: [T; 3], roll: T, pitch: T, yaw: T) -> Self {
        let (sr, cr) = roll.sin_cos();
        let (sp, cp) = pitch.sin_cos();
        let (sy, cy) = yaw.sin_cos();
        Pose {
            translation,
            rotation: [
                [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                [-sp, cp * sr, cp * cr],
            ],
        }
    }

    /// Maps a point from child to parent coordinates: `rotation * p + translation`.
    #[inline]
    pub fn transform_point(&self, p: &[T; 3]) -> [T; 3] {
        let r = mat_vec(&self.rotation, p);
        [
            r[0] + self.translation[0],
            r[1] + self.translation[1],
            r[2] + self.translation[2],
        ]
    }

    /// Maps a free vector (direction, velocity, force) from child to parent coordinates:
    /// `rotation * v`.
    #[inline]
    pub fn transform_vector(&self, v: &[T; 3]) -> [T; 3] {
        mat_vec(&self.rotation, v)
    }

    /// Maps a point from parent to child coordinates: `rotationᵀ (p - translation)`; the same as
    /// `self.inverse().transform_point(p)`, without forming the inverse.
    #[inline]
    pub fn inverse_transform_point(&self, p: &[T; 3]) -> [T; 3] {
        let d = [
            p[0] - self.translation[0],
            p[1] - self.translation[1],
            p[2] - self.translation[2],
        ];
        mat_t_vec(&self.rotation, &d)
    }

    /// Maps a free vector from parent to child coordinates: `rotationᵀ v`.
    #[inline]
    pub fn inverse_transform_vector(&self, v: &[T; 3]) -> [T; 3] {
        mat_t_vec(&self.rotation, v)
    }

    /// The composition `self ∘ other`: if `self` is "a from b" and `other` is "b from c", the
    /// result is "a from c" (`result.transform_point(p) == self.transform_point(&other.transform_point(p))`).
    #[inline]
    pub fn compose(&self, other: &Pose<T>) -> Pose<T> {
        let a = &self.rotation;
        let b = &other.rotation;
        let mut rotation = [[T::zero(); 3]; 3];
        for (i, row) in rotation.iter_mut().enumerate() {
            for (j, x) in row.iter_mut().enumerate() {
                *x = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
            }
        }
        Pose {
            translation: self.transform_point(&other.translation),
            rotation,
        }
    }

    /// The inverse transform ("link from world" for a "world from link" pose), assuming
    /// `rotation` is orthonormal: `(rotationᵀ, -rotationᵀ translation)`.
    pub fn inverse(&self) -> Pose<T> {
        let r = &self.rotation;
        let rotation = [
            [r[0][0], r[1][0], r[2][0]],
            [r[0][1], r[1][1], r[2][1]],
            [r[0][2], r[1][2], r[2][2]],
        ];
        let t = mat_vec(&rotation, &self.translation);
        Pose {
            translation: [-t[0], -t[1], -t[2]],
            rotation,
        }
    }

    /// The 4×4 homogeneous matrix `[[R, t], [0, 1]]`, row-major.
    pub fn to_homogeneous(&self) -> [[T; 4]; 4] {
        let (r, t) = (&self.rotation, &self.translation);
        let (o, z) = (T::one(), T::zero());
        [
            [r[0][0], r[0][1], r[0][2], t[0]],
            [r[1][0], r[1][1], r[1][2], t[1]],
            [r[2][0], r[2][1], r[2][2], t[2]],
            [z, z, z, o],
        ]
    }
}

impl<T: Lane> core::ops::Mul for Pose<T> {
    type Output = Pose<T>;
    /// `a * b` is [`a.compose(&b)`](Pose::compose).
    #[inline]
    fn mul(self, rhs: Pose<T>) -> Pose<T> {
        self.compose(&rhs)
    }
}
