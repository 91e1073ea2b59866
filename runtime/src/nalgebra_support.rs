//! Conversions between this crate's plain arrays and nalgebra's fixed-size types (feature
//! `nalgebra`).
//!
//! Our matrices are row-major `[[T; C]; R]` arrays (`m[i][j]` = row `i`, column `j`); nalgebra
//! stores column-major. These functions map entry `(i, j)` to entry `(i, j)`, so `m[i][j] ==
//! to_matrix(&m)[(i, j)]`, whatever the storage order.
//!
//! | ours | nalgebra | to nalgebra | back |
//! |---|---|---|---|
//! | `[[T; N]; N]` (mass matrix) | `SMatrix<T, N, N>` | [`to_matrix`] | [`from_matrix`] |
//! | `[[T; N]; 6]` (link Jacobian) | `SMatrix<T, 6, N>` | [`to_matrix`] | [`from_matrix`] |
//! | `[T; N]` (joint vector) | `SVector<T, N>` | [`to_vector`] | [`from_vector`] |
//! | [`Pose<T>`] | `Isometry3<T>` | `Isometry3::from`, [`Pose::to_isometry`] | `Pose::from`, [`Pose::from_isometry`] |
//!
//! ```
//! use eomgen_runtime::nalgebra_support::{from_vector, to_matrix, to_vector};
//!
//! let m = [[2.0_f64, 1.0], [1.0, 3.0]];
//! let sm = to_matrix(&m);
//! assert_eq!(sm[(0, 1)], 1.0);
//! let x = sm.cholesky().unwrap().solve(&to_vector(&[3.0, 4.0]));
//! let x: [f64; 2] = from_vector(&x);
//! assert!((x[0] - 1.0).abs() < 1e-12 && (x[1] - 1.0).abs() < 1e-12);
//! ```

use crate::Pose;
use nalgebra::{
    Isometry3, Matrix3, RealField, Rotation3, SMatrix, SVector, Scalar, Translation3,
    UnitQuaternion,
};

/// A row-major `[[T; C]; R]` array as an nalgebra `R×C` matrix (entry `(i, j)` = `m[i][j]`).
///
/// Covers the mass and Coriolis matrices (`[[T; N]; N]` → `SMatrix<T, N, N>`) and link
/// Jacobians (`[[T; N]; 6]` → `SMatrix<T, 6, N>`).
pub fn to_matrix<T: Scalar, const R: usize, const C: usize>(m: &[[T; C]; R]) -> SMatrix<T, R, C> {
    SMatrix::from_fn(|i, j| m[i][j].clone())
}

/// An nalgebra `R×C` matrix as a row-major `[[T; C]; R]` array (`m[i][j]` = entry `(i, j)`).
pub fn from_matrix<T: Scalar, const R: usize, const C: usize>(m: &SMatrix<T, R, C>) -> [[T; C]; R] {
    core::array::from_fn(|i| core::array::from_fn(|j| m[(i, j)].clone()))
}

/// A `[T; N]` array as an nalgebra column vector.
pub fn to_vector<T: Scalar, const N: usize>(v: &[T; N]) -> SVector<T, N> {
    SVector::from_fn(|i, _| v[i].clone())
}

/// An nalgebra column vector as a `[T; N]` array.
pub fn from_vector<T: Scalar, const N: usize>(v: &SVector<T, N>) -> [T; N] {
    core::array::from_fn(|i| v[i].clone())
}

impl<T: RealField + Copy> Pose<T> {
    /// The pose as an nalgebra isometry (same as `Isometry3::from(pose)`).
    ///
    /// The rotation matrix is assumed orthonormal (as generated poses are, to rounding); it is
    /// converted with `UnitQuaternion::from_rotation_matrix`, which renormalizes the quaternion.
    ///
    /// ```
    /// use eomgen_runtime::Pose;
    /// use nalgebra::{Isometry3, Point3};
    ///
    /// let pose = Pose::<f64>::from_rpy([1.0, 2.0, 3.0], 0.1, 0.2, 0.3);
    /// let iso: Isometry3<f64> = pose.into();
    /// let p = iso * Point3::new(0.5, -0.5, 0.25);
    /// let q = pose.transform_point(&[0.5, -0.5, 0.25]);
    /// assert!((p - Point3::from(q)).norm() < 1e-12);
    /// ```
    pub fn to_isometry(&self) -> Isometry3<T> {
        let r = &self.rotation;
        let m = Matrix3::new(
            r[0][0], r[0][1], r[0][2], r[1][0], r[1][1], r[1][2], r[2][0], r[2][1], r[2][2],
        );
        let rotation = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(m));
        let t = &self.translation;
        Isometry3::from_parts(Translation3::new(t[0], t[1], t[2]), rotation)
    }

    /// A pose from an nalgebra isometry (same as `Pose::from(iso)`).
    pub fn from_isometry(iso: &Isometry3<T>) -> Self {
        let r = iso.rotation.to_rotation_matrix();
        let t = &iso.translation.vector;
        Pose {
            translation: [t[0], t[1], t[2]],
            rotation: from_matrix(r.matrix()),
        }
    }
}

impl<T: RealField + Copy> From<Pose<T>> for Isometry3<T> {
    fn from(p: Pose<T>) -> Self {
        p.to_isometry()
    }
}

impl<T: RealField + Copy> From<Isometry3<T>> for Pose<T> {
    fn from(iso: Isometry3<T>) -> Self {
        Pose::from_isometry(&iso)
    }
}
