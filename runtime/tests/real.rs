//! The `Real` implementations for f32 and f64.

use eomgen_runtime::Real;
use proptest::prelude::*;

fn generic_checks<T: Real>(tol: f64) {
    assert_eq!(T::zero().to_f64(), 0.0);
    assert_eq!(T::one().to_f64(), 1.0);
    assert_eq!(T::default(), T::zero());
    assert!(!T::nan().is_finite());
    assert!(T::nan() != T::nan());
    assert!(!(T::one() / T::zero()).is_finite());
    assert!(T::one().is_finite());

    // sign(0) = 0, for both zeros; NaN stays NaN
    assert_eq!(T::zero().signum(), T::zero());
    assert_eq!((-T::zero()).signum(), T::zero());
    assert_eq!(T::from_f64(2.5).signum(), T::one());
    assert_eq!(T::from_f64(-1e-30).signum(), -T::one());
    assert_eq!((T::one() / T::zero()).signum(), T::one());
    assert!(T::nan().signum() != T::nan().signum());

    assert_eq!(T::from_f64(-3.0).abs(), T::from_f64(3.0));
    assert_eq!(T::from_f64(9.0).sqrt(), T::from_f64(3.0));
    assert!(!T::from_f64(-1.0).sqrt().is_finite());
    assert_eq!(T::from_f64(4.0).recip(), T::from_f64(0.25));
    assert_eq!(
        T::from_f64(2.0).mul_add(T::from_f64(3.0), T::one()),
        T::from_f64(7.0)
    );
    assert_eq!(T::one().min(T::from_f64(2.0)), T::one());
    assert_eq!(T::one().max(T::from_f64(2.0)), T::from_f64(2.0));
    assert_eq!(T::nan().max(T::one()), T::one());
    assert!(T::epsilon() > T::zero() && T::one() + T::epsilon() > T::one());

    let half_pi = T::from_f64(core::f64::consts::FRAC_PI_2);
    assert!((half_pi.sin().to_f64() - 1.0).abs() < tol);
    assert!(half_pi.cos().to_f64().abs() < tol);
    assert!((T::one().atan2(T::one()).to_f64() - core::f64::consts::FRAC_PI_4).abs() < tol);
    assert!((T::one().atan2(-T::one()).to_f64() - 3.0 * core::f64::consts::FRAC_PI_4).abs() < tol);
}

#[test]
fn f64_basics() {
    generic_checks::<f64>(1e-15);
}

#[test]
fn f32_basics() {
    generic_checks::<f32>(1e-6);
}

#[test]
fn from_f64_rounds_to_nearest_f32() {
    assert_eq!(<f32 as Real>::from_f64(0.1), 0.1_f32);
    assert_eq!(<f32 as Real>::from_f64(9.81), 9.81_f32);
    assert_eq!(<f64 as Real>::from_f64(0.1), 0.1);
}

proptest! {
    #[test]
    fn f64_trig_matches_std(x in -100.0_f64..100.0) {
        let (s, c) = Real::sin_cos(x);
        prop_assert_eq!(s, Real::sin(x));
        prop_assert_eq!(c, Real::cos(x));
        prop_assert!((s - x.sin()).abs() <= 1e-15);
        prop_assert!((c - x.cos()).abs() <= 1e-15);
        prop_assert!((Real::sqrt(x.abs()) - x.abs().sqrt()).abs() <= 1e-15 * x.abs().sqrt());
    }

    #[test]
    fn f32_trig_is_close_to_f64(x in -100.0_f32..100.0) {
        let (s, c) = Real::sin_cos(x);
        prop_assert_eq!(s, Real::sin(x));
        prop_assert_eq!(c, Real::cos(x));
        // correctly rounded within about 1 ulp of the exact value of the f32 argument
        prop_assert!((f64::from(s) - f64::from(x).sin()).abs() <= 1.2e-7);
        prop_assert!((f64::from(c) - f64::from(x).cos()).abs() <= 1.2e-7);
    }

    #[test]
    fn signum_matches_std_away_from_zero(x in any::<f64>().prop_filter("nonzero", |x| *x != 0.0 && !x.is_nan())) {
        prop_assert_eq!(Real::signum(x), x.signum());
        let y = x as f32; // may round to zero or overflow to infinity
        let expected = if y == 0.0 { 0.0 } else { y.signum() };
        prop_assert_eq!(Real::signum(y), expected);
    }
}
