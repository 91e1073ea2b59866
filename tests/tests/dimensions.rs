//! The sizes of generated robots: `Robot::DOF` without a type parameter (the `f64` form), and
//! `Dimensions` through the prelude for every scalar and in generic code.

use eomgen_runtime::prelude::*;
use eomgen_tests::robots::{anymal::Anymal, panda::Panda};

/// What generic code over the scalar sees.
fn sizes<T: Real>() -> (usize, usize, usize) {
    (Panda::<T>::DOF, Anymal::<T>::NQ, Anymal::<T>::NV)
}

#[test]
fn dof_needs_no_type_parameter() {
    let q = [0.0; Panda::DOF];
    let r = Panda::default();
    assert_eq!(r.mass_matrix(&q).len(), 9);
    let base = [0.0; Anymal::NQ];
    let v = [0.0; Anymal::NV];
    assert_eq!((base.len(), v.len(), Anymal::DOF), (19, 18, 18));
}

#[test]
fn dimensions_hold_for_every_scalar() {
    let q = [0.0_f32; Panda::<f32>::DOF];
    assert_eq!(Panda::<f32>::default().gravity(&q).len(), 9);
    assert_eq!(sizes::<f32>(), (9, 19, 18));
    assert_eq!(sizes::<f64>(), (Panda::DOF, Anymal::NQ, Anymal::NV));
    assert_eq!(<Panda as Dimensions>::NQ, <Panda as Dimensions>::NV);
}
