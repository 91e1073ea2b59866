//! `Pose` composition, inversion and point transforms.
#![allow(clippy::needless_range_loop)] // index loops read like the math

use eomgen_runtime::Pose;
use proptest::prelude::*;

fn close(a: &[f64; 3], b: &[f64; 3], tol: f64) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol)
}

fn pose_close(a: &Pose<f64>, b: &Pose<f64>, tol: f64) -> bool {
    close(&a.translation, &b.translation, tol)
        && a.rotation
            .iter()
            .zip(&b.rotation)
            .all(|(r, s)| close(r, s, tol))
}

fn arb_pose() -> impl Strategy<Value = Pose<f64>> {
    (
        prop::array::uniform3(-5.0..5.0_f64),
        -4.0..4.0_f64,
        -4.0..4.0_f64,
        -4.0..4.0_f64,
    )
        .prop_map(|(t, r, p, y)| Pose::from_rpy(t, r, p, y))
}

#[test]
fn identity_and_constructors() {
    let id = Pose::<f64>::identity();
    assert_eq!(id.transform_point(&[1.0, 2.0, 3.0]), [1.0, 2.0, 3.0]);
    assert_eq!(id.inverse(), id);
    let t = Pose::from_translation([1.0, 2.0, 3.0]);
    assert_eq!(t.transform_point(&[1.0, 1.0, 1.0]), [2.0, 3.0, 4.0]);
    assert_eq!(t.transform_vector(&[1.0, 1.0, 1.0]), [1.0, 1.0, 1.0]);
    assert_eq!(Pose::new([1.0, 2.0, 3.0], id.rotation), t);
    let h = t.to_homogeneous();
    assert_eq!(h[0], [1.0, 0.0, 0.0, 1.0]);
    assert_eq!(h[3], [0.0, 0.0, 0.0, 1.0]);
}

#[test]
fn rpy_matches_urdf_convention() {
    // yaw of 90 degrees about z: x axis goes to y
    let p = Pose::from_rpy([0.0; 3], 0.0, 0.0, core::f64::consts::FRAC_PI_2);
    assert!(close(
        &p.transform_vector(&[1.0, 0.0, 0.0]),
        &[0.0, 1.0, 0.0],
        1e-15
    ));
    // roll of 90 degrees about x: y axis goes to z
    let p = Pose::from_rpy([0.0; 3], core::f64::consts::FRAC_PI_2, 0.0, 0.0);
    assert!(close(
        &p.transform_vector(&[0.0, 1.0, 0.0]),
        &[0.0, 0.0, 1.0],
        1e-15
    ));
    // roll then yaw (fixed axes): Rz(yaw) Rx(roll); z goes (by roll) to -y, then (by yaw) to +x
    let p = Pose::from_rpy(
        [0.0; 3],
        core::f64::consts::FRAC_PI_2,
        0.0,
        core::f64::consts::FRAC_PI_2,
    );
    assert!(close(
        &p.transform_vector(&[0.0, 0.0, 1.0]),
        &[1.0, 0.0, 0.0],
        1e-15
    ));
}

#[test]
fn f32_pose() {
    let p = Pose::<f32>::from_rpy([1.0, 2.0, 3.0], 0.3, -0.2, 1.1);
    let q = p
        .inverse()
        .transform_point(&p.transform_point(&[0.5, 0.25, -1.0]));
    assert!((q[0] - 0.5).abs() < 1e-5 && (q[1] - 0.25).abs() < 1e-5 && (q[2] + 1.0).abs() < 1e-5);
}

proptest! {
    #[test]
    fn compose_with_inverse_is_identity(a in arb_pose()) {
        let id = Pose::identity();
        prop_assert!(pose_close(&a.compose(&a.inverse()), &id, 1e-12));
        prop_assert!(pose_close(&a.inverse().compose(&a), &id, 1e-12));
        prop_assert!(pose_close(&a.inverse().inverse(), &a, 1e-12));
        prop_assert!(pose_close(&a.compose(&id), &a, 0.0));
        prop_assert!(pose_close(&id.compose(&a), &a, 0.0));
    }

    #[test]
    fn compose_is_associative_and_acts_like_nesting(
        a in arb_pose(), b in arb_pose(), c in arb_pose(),
        p in prop::array::uniform3(-3.0..3.0_f64),
    ) {
        prop_assert!(pose_close(&a.compose(&b).compose(&c), &a.compose(&b.compose(&c)), 1e-12));
        prop_assert!(close(
            &a.compose(&b).transform_point(&p),
            &a.transform_point(&b.transform_point(&p)),
            1e-12
        ));
        prop_assert_eq!(a * b, a.compose(&b));
        // (ab)^-1 = b^-1 a^-1
        prop_assert!(pose_close(&a.compose(&b).inverse(), &b.inverse().compose(&a.inverse()), 1e-12));
    }

    #[test]
    fn inverse_transforms_undo_transforms(a in arb_pose(), p in prop::array::uniform3(-3.0..3.0_f64)) {
        prop_assert!(close(&a.inverse_transform_point(&a.transform_point(&p)), &p, 1e-12));
        prop_assert!(close(&a.inverse().transform_point(&p), &a.inverse_transform_point(&p), 1e-12));
        prop_assert!(close(&a.inverse_transform_vector(&a.transform_vector(&p)), &p, 1e-12));
        // rotations preserve length
        let v = a.transform_vector(&p);
        let n = |x: &[f64; 3]| (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
        prop_assert!((n(&v) - n(&p)).abs() <= 1e-12);
    }

    #[test]
    fn homogeneous_matrix_acts_like_the_pose(a in arb_pose(), p in prop::array::uniform3(-3.0..3.0_f64)) {
        let h = a.to_homogeneous();
        let q: Vec<f64> = (0..3).map(|i| h[i][0] * p[0] + h[i][1] * p[1] + h[i][2] * p[2] + h[i][3]).collect();
        prop_assert!(close(&[q[0], q[1], q[2]], &a.transform_point(&p), 1e-12));
    }
}
