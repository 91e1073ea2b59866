//! Conversions to and from nalgebra (run with `--features nalgebra`).
#![cfg(feature = "nalgebra")]
#![allow(clippy::needless_range_loop)] // index loops read like the math

use eomgen_runtime::nalgebra_support::{from_matrix, from_vector, to_matrix, to_vector};
use eomgen_runtime::{solve_spd, Pose};
use nalgebra::{Isometry3, Point3, SMatrix, SVector, Translation3, UnitQuaternion, Vector3};
use proptest::prelude::*;

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
fn entries_keep_their_row_and_column() {
    let m = [[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]];
    let sm: SMatrix<f64, 2, 3> = to_matrix(&m);
    assert_eq!(sm, SMatrix::<f64, 2, 3>::new(1.0, 2.0, 3.0, 4.0, 5.0, 6.0));
    assert_eq!(sm[(1, 0)], 4.0);
    let v: SVector<f32, 3> = to_vector(&[1.0, 2.0, 3.0]);
    assert_eq!(v, SVector::<f32, 3>::new(1.0, 2.0, 3.0));
}

#[test]
fn jacobian_shape_6_by_n() {
    let j: [[f64; 4]; 6] = core::array::from_fn(|i| core::array::from_fn(|k| (10 * i + k) as f64));
    let sj: SMatrix<f64, 6, 4> = to_matrix(&j);
    assert_eq!(sj[(5, 3)], 53.0);
    assert_eq!(sj.row(3)[2], 32.0);
    assert_eq!(from_matrix(&sj), j);
    // the twist of a joint-velocity vector
    let qd = [1.0, 0.0, 0.0, 0.0];
    assert_eq!(
        from_vector(&(sj * to_vector(&qd))),
        [0.0, 10.0, 20.0, 30.0, 40.0, 50.0]
    );
}

#[test]
fn pose_maps_to_the_expected_isometry() {
    let iso = Isometry3::from_parts(
        Translation3::new(1.0, 2.0, 3.0),
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), core::f64::consts::FRAC_PI_2),
    );
    let pose = Pose::from(iso);
    assert!((pose.rotation[1][0] - 1.0).abs() < 1e-15 && (pose.rotation[0][1] + 1.0).abs() < 1e-15);
    assert_eq!(pose.translation, [1.0, 2.0, 3.0]);
    let back: Isometry3<f64> = pose.into();
    assert!((back.to_homogeneous() - iso.to_homogeneous()).norm() < 1e-15);

    let p32 = Pose::<f32>::from_rpy([1.0, 2.0, 3.0], 0.1, 0.2, 0.3);
    let i32 = p32.to_isometry();
    let a = i32 * Point3::new(1.0_f32, 1.0, 1.0);
    let b = p32.transform_point(&[1.0, 1.0, 1.0]);
    assert!((a - Point3::from(b)).norm() < 1e-5);
}

proptest! {
    #[test]
    fn square_matrices_round_trip(m in prop::array::uniform::<_, 7>(prop::array::uniform::<_, 7>(-1e3..1e3_f64))) {
        let sm: SMatrix<f64, 7, 7> = to_matrix(&m);
        prop_assert_eq!(from_matrix(&sm), m);
        prop_assert_eq!(to_matrix(&from_matrix(&sm)), sm);
        for i in 0..7 {
            for j in 0..7 {
                prop_assert_eq!(sm[(i, j)], m[i][j]);
            }
        }
        let t: [[f64; 7]; 7] = from_matrix(&sm.transpose());
        prop_assert_eq!(t[2][5], m[5][2]);
    }

    #[test]
    fn jacobians_and_vectors_round_trip(
        j in prop::array::uniform::<_, 6>(prop::array::uniform::<_, 5>(-1e3..1e3_f32)),
        v in prop::array::uniform::<_, 5>(-1e3..1e3_f32),
    ) {
        let sj: SMatrix<f32, 6, 5> = to_matrix(&j);
        prop_assert_eq!(from_matrix(&sj), j);
        let sv: SVector<f32, 5> = to_vector(&v);
        prop_assert_eq!(from_vector(&sv), v);
    }

    #[test]
    fn poses_round_trip_and_act_alike(a in arb_pose(), p in prop::array::uniform3(-3.0..3.0_f64)) {
        let iso = a.to_isometry();
        let q = iso * Point3::from(p);
        let r = a.transform_point(&p);
        prop_assert!((q - Point3::from(r)).norm() < 1e-12);
        let back = Pose::from_isometry(&iso);
        for i in 0..3 {
            prop_assert!((back.translation[i] - a.translation[i]).abs() < 1e-12);
            for k in 0..3 {
                prop_assert!((back.rotation[i][k] - a.rotation[i][k]).abs() < 1e-12);
            }
        }
        // composition agrees with isometry multiplication
        let b = a.inverse();
        let ab = Isometry3::from(a.compose(&b));
        prop_assert!((ab.to_homogeneous() - Isometry3::identity().to_homogeneous()).norm() < 1e-12);
    }

    #[test]
    fn solve_spd_agrees_with_nalgebra_cholesky(
        a in prop::array::uniform::<_, 6>(prop::array::uniform::<_, 6>(-1.0..1.0_f64)),
        b in prop::array::uniform::<_, 6>(-10.0..10.0_f64),
    ) {
        let sa: SMatrix<f64, 6, 6> = to_matrix(&a);
        let m = sa * sa.transpose() + SMatrix::<f64, 6, 6>::identity() * 6.0;
        let ours = solve_spd(&from_matrix(&m), &b).unwrap();
        let theirs = from_vector(&m.cholesky().unwrap().solve(&to_vector(&b)));
        for i in 0..6 {
            prop_assert!((ours[i] - theirs[i]).abs() <= 1e-12 * (1.0 + theirs[i].abs()));
        }
    }
}
