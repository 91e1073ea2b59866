//! The arctangent of the first quadrant, for the angle of a relative rotation.
//!
//! `difference` waits on `atan2(|v|, w)` of a quaternion with `w >= 0`: `libm::atan2` spent a
//! third of its time in argument checks and in branches on the argument's size. Here both
//! arguments are known non-negative, so one comparison swaps them into `lo <= hi`, a second
//! picks the reduced argument (`lo / hi`, or `(lo - hi) / (lo + hi)` around `pi/4`: one
//! division either way, `|z| <= tan(pi/8)`), and fdlibm's odd polynomial of `atan` on
//! `|z| < 7/16` finishes. Both choices are lane-wise selections, not branches, so that a
//! vector of states ([`crate::Lane`]) takes each lane's own. Accuracy: within a few units in the last place of `libm::atan2`
//! (the unit test sweeps the quadrant).

// fdlibm's coefficients, digit for digit as published (more digits than an f64 holds).
#![allow(clippy::excessive_precision)]

use crate::Lane;

/// fdlibm's `atan` coefficients `aT[0..11]`, valid for `|z| < 7/16`.
const AT: [f64; 11] = [
    3.333_333_333_333_293_180_27e-01,
    -1.999_999_999_987_648_324_76e-01,
    1.428_571_427_250_346_637_11e-01,
    -1.111_111_040_546_235_578_80e-01,
    9.090_887_133_436_506_561_96e-02,
    -7.691_876_205_044_829_994_95e-02,
    6.661_073_137_387_531_206_69e-02,
    -5.833_570_133_790_573_486_45e-02,
    4.976_877_994_615_932_360_17e-02,
    -3.653_157_274_421_691_552_70e-02,
    1.628_582_011_536_578_236_23e-02,
];

/// `tan(pi/8)`: above it, the argument is reduced around `pi/4`.
const TAN_PI_8: f64 = 0.414_213_562_373_095_048_80;

/// `atan2(y, x)` for `y >= 0` and `x >= 0`, not both zero: the angle in `[0, pi/2]`, lane by
/// lane (the swap and the reduction selected per lane, no branch on a value).
#[inline]
pub(crate) fn atan2_quadrant<T: Lane>(y: T, x: T) -> T {
    let f = T::from_f64;
    let swap = y.gt(x);
    let (lo, hi) = (T::select(swap, x, y), T::select(swap, y, x));
    // atan(lo / hi) in [0, pi/4], around 0 or around pi/4.
    let near = lo.gt(f(TAN_PI_8) * hi);
    let num = T::select(near, lo - hi, lo);
    let den = T::select(near, lo + hi, hi);
    let base = T::select(near, f(core::f64::consts::FRAC_PI_4), T::zero());
    let z = num / den;
    let a = base + atan_small(z);
    T::select(swap, f(core::f64::consts::FRAC_PI_2) - a, a)
}

/// `atan(z)` for `|z| < 7/16`: `z - z (z^2 P(z^4) + z^4 Q(z^4))`, the odd and even halves of
/// the polynomial in parallel (Estrin's scheme on `w = z^4`).
#[inline(always)]
fn atan_small<T: Lane>(z: T) -> T {
    let c = |i: usize| T::from_f64(AT[i]);
    let z2 = z * z;
    let w = z2 * z2;
    let w2 = w * w;
    let odd = (c(0) + w * c(2)) + w2 * ((c(4) + w * c(6)) + w2 * (c(8) + w * c(10)));
    let even = (c(1) + w * c(3)) + w2 * ((c(5) + w * c(7)) + w2 * c(9));
    z - z * (z2 * odd + w * even)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Within 4 ulp of `libm::atan2` over the quadrant, near both axes and the diagonal.
    #[test]
    fn matches_libm_over_the_quadrant() {
        let mut worst = 0.0_f64;
        for i in 0..=20_000 {
            let angle = core::f64::consts::FRAC_PI_2 * i as f64 / 20_000.0;
            for scale in [1e-3, 1.0, 7.5] {
                let (y, x) = (scale * angle.sin().abs(), scale * angle.cos().abs());
                let want = libm::atan2(y, x);
                let got = atan2_quadrant(y, x);
                let ulp = (want.abs() * f64::EPSILON).max(f64::MIN_POSITIVE);
                worst = worst.max((got - want).abs() / ulp);
            }
        }
        for (y, x) in [
            (0.0, 1.0),
            (1.0, 0.0),
            (1e-300, 1.0),
            (1.0, 1.0),
            (3e-9, 0.99),
        ] {
            let ulp = (libm::atan2(y, x) * f64::EPSILON).max(f64::MIN_POSITIVE);
            worst = worst.max((atan2_quadrant(y, x) - libm::atan2(y, x)).abs() / ulp);
        }
        assert!(worst <= 4.0, "worst {worst} ulp");
    }

    #[test]
    fn f32_within_its_epsilon() {
        for i in 0..=1000 {
            let angle = core::f32::consts::FRAC_PI_2 * i as f32 / 1000.0;
            let (y, x) = (angle.sin().abs(), angle.cos().abs());
            let got = atan2_quadrant(y, x);
            assert!((got - y.atan2(x)).abs() <= 4.0 * f32::EPSILON, "{y} {x}");
        }
    }
}
