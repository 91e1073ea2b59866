//! The sines and cosines of all of a robot's joint angles at once, in code the compiler turns
//! into SIMD instructions.
//!
//! Generated functions start with the sine and cosine of every joint angle they use. One call
//! of `libm::sincos` per angle costs about as much as the rest of a floating quadruped's
//! `inverse_dynamics` or `mass_matrix` (a third of their time, measured on anymal's twelve
//! joints), and it branches on the argument's size, so that the calls cannot share vector
//! instructions. [`sin_cos_f64`] computes every angle of an array with the same branch-free
//! steps: Cody and Waite's reduction by `pi/2` in three parts of `pi/2` (exact products for
//! the angles joints reach), then fdlibm's polynomials for the sine and the cosine on
//! `[-pi/4, pi/4]` and the quadrant's swap and signs. The loop over the array compiles to
//! vector instructions (eight angles per instruction with AVX-512, four with AVX2, two with
//! SSE2 or NEON). An array holding an angle of magnitude [`REDUCED_MAX`] or more, or an
//! infinite one, is computed by `libm` instead, angle by angle.
//!
//! Accuracy: for angles below [`REDUCED_MAX`], within `f64::EPSILON` of `libm`'s result, and
//! within two units in the last place of it for angles below `pi/4`, where the sine is small
//! (the unit tests sweep both). NaN gives NaN.

// The constants are fdlibm's, digit for digit as published (more digits than an f64 holds).
#![allow(clippy::excessive_precision)]

/// `pi/2` in three parts (fdlibm's `pio2_1`, `pio2_2`, `pio2_3`): the first two have 33
/// significant bits, so `k * PIO2_1` and `k * PIO2_2` are exact for `|k| < 2^20`.
const PIO2_1: f64 = 1.570_796_326_734_125_614_17e+00;
const PIO2_2: f64 = 6.077_100_506_303_965_976_60e-11;
const PIO2_3: f64 = 2.022_266_248_711_166_455_80e-21;

/// fdlibm's `__kernel_sin` coefficients on `[-pi/4, pi/4]`.
const S1: f64 = -1.666_666_666_666_663_243_48e-01;
const S2: f64 = 8.333_333_333_322_489_461_24e-03;
const S3: f64 = -1.984_126_982_985_794_931_34e-04;
const S4: f64 = 2.755_731_370_707_006_767_89e-06;
const S5: f64 = -2.505_076_025_340_686_341_95e-08;
const S6: f64 = 1.589_690_995_211_550_102_21e-10;

/// fdlibm's `__kernel_cos` coefficients on `[-pi/4, pi/4]`.
const C1: f64 = 4.166_666_666_666_660_190_37e-02;
const C2: f64 = -1.388_888_888_887_410_957_49e-03;
const C3: f64 = 2.480_158_728_947_672_941_78e-05;
const C4: f64 = -2.755_731_435_139_066_330_35e-07;
const C5: f64 = 2.087_572_321_298_174_827_90e-09;
const C6: f64 = -1.135_964_755_778_819_482_65e-11;

/// `1.5 * 2^52`: adding it rounds a number below `2^51` in magnitude to an integer, which
/// then stands in the low bits of the sum's representation.
const ROUNDER: f64 = 6_755_399_441_055_744.0;

/// Angles (radians) from this magnitude on are reduced by `libm`: below it, the reduction's
/// quadrant count stays far below `2^20`, and the three-part reduction keeps the reduced
/// angle's absolute error below `1e-20`.
pub const REDUCED_MAX: f64 = 1.0e5;

/// The sign bit of an `f64`.
const SIGN: u64 = 1 << 63;

/// `(sin x_i, cos x_i)` by `sin_cos` element by element: the default of
/// [`crate::Real::sin_cos_many`] and [`crate::Lane::sin_cos_many`], and `f32`'s.
///
/// A plain loop, not `core`'s array `map`, whose `try_map` is inlined or not as the optimizer's
/// budget falls: where it was not, the sines and cosines of the `f32x8` lanes went through an
/// out-of-line copy of each array (the panda's `f32x8` inverse dynamics batch, with the
/// transposition's own `from_fn` fixed as well: 33.6 -> 37.0 million states per second).
#[inline(always)]
pub(crate) fn each<T: Copy, const K: usize>(
    x: [T; K],
    sin_cos: impl Fn(T) -> (T, T),
) -> ([T; K], [T; K]) {
    let (mut s, mut c) = (x, x);
    for (i, xi) in x.into_iter().enumerate() {
        (s[i], c[i]) = sin_cos(xi);
    }
    (s, c)
}

/// `a * b + c`, one instruction where the target has FMA.
#[inline(always)]
fn fma(a: f64, b: f64, c: f64) -> f64 {
    <f64 as crate::Real>::mul_add(a, b, c)
}

/// `(sin x, cos x)` for `|x| < REDUCED_MAX` (or NaN), branch-free. The polynomials are
/// evaluated by Estrin's scheme (powers of `z = r^2` in parallel) rather than Horner's, which
/// halves the chain of dependent operations: the joint angles' sines and cosines are the first
/// thing every generated function waits for.
#[inline(always)]
fn reduced(x: f64) -> (f64, f64) {
    let t = fma(x, core::f64::consts::FRAC_2_PI, ROUNDER);
    let quadrant = t.to_bits();
    let k = t - ROUNDER;
    let r = fma(-k, PIO2_3, fma(-k, PIO2_2, fma(-k, PIO2_1, x)));
    let z = r * r;
    let z2 = z * z;
    let sin_poly = fma(z2, fma(z2, fma(z, S6, S5), fma(z, S4, S3)), fma(z, S2, S1));
    let sin = fma(r * z, sin_poly, r);
    let cos_poly = fma(z2, fma(z2, fma(z, C6, C5), fma(z, C4, C3)), fma(z, C2, C1));
    let half = 0.5 * z;
    let w = 1.0 - half;
    let cos = w + fma(z2, cos_poly, (1.0 - w) - half);
    // x = k pi/2 + r: the quadrant k mod 4 swaps the two and sets their signs.
    let (s, c) = if quadrant & 1 == 1 {
        (cos, sin)
    } else {
        (sin, cos)
    };
    let s = if quadrant & 2 == 2 { -s } else { s };
    let c = if quadrant.wrapping_add(1) & 2 == 2 {
        -c
    } else {
        c
    };
    (s, c)
}

/// `(sin x_i, cos x_i)` for every element of `x`, as two arrays (module documentation).
///
/// ```
/// use eomgen_runtime::trig::sin_cos_f64;
/// let (s, c) = sin_cos_f64([0.0, 1.0, -2.5, 1.0e6]);
/// for (i, x) in [0.0_f64, 1.0, -2.5, 1.0e6].iter().enumerate() {
///     assert!((s[i] - x.sin()).abs() <= 2e-16 && (c[i] - x.cos()).abs() <= 2e-16);
/// }
/// ```
#[inline(always)]
pub fn sin_cos_f64<const K: usize>(x: [f64; K]) -> ([f64; K], [f64; K]) {
    let (mut s, mut c) = ([0.0; K], [0.0; K]);
    sin_cos_f64_in(&x, &mut s, &mut c);
    (s, c)
}

/// [`sin_cos_f64`] on slices: `s[i], c[i] = sin x[i], cos x[i]` for `i` below the shortest
/// length. The vector lanes' [`crate::Lane::sin_cos_many`] run it on all their lanes at once
/// (an array of `f64x4` is one slice of `f64`), so that a lane computes what the scalar code
/// computes, bit for bit, with the widest vector instructions the target has.
///
/// ```
/// use eomgen_runtime::trig::{sin_cos_f64, sin_cos_f64_in};
/// let x = [0.25, -3.0, 7.5];
/// let (mut s, mut c) = ([0.0; 3], [0.0; 3]);
/// sin_cos_f64_in(&x, &mut s, &mut c);
/// assert_eq!((s, c), sin_cos_f64(x));
/// ```
#[inline(always)]
pub fn sin_cos_f64_in(x: &[f64], s: &mut [f64], c: &mut [f64]) {
    for ((x, s), c) in x.iter().zip(&mut *s).zip(&mut *c) {
        (*s, *c) = reduced(*x);
    }
    // The largest magnitude's bits (non-negative floats order as their bits; NaN above
    // infinity): one vector reduction instead of a comparison and branch per angle.
    let largest = x.iter().fold(0, |m: u64, x| m.max(x.to_bits() & !SIGN));
    if largest >= REDUCED_MAX.to_bits() {
        for ((x, s), c) in x.iter().zip(s).zip(c) {
            if libm::fabs(*x) >= REDUCED_MAX {
                (*s, *c) = libm::sincos(*x);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn within_epsilon_of_libm_below_the_limit() {
        let mut worst: f64 = 0.0;
        let mut x = -REDUCED_MAX * 0.999;
        while x < REDUCED_MAX {
            let xs = [x, x * 1e-3, x * 1e-7, -x * 0.37, x + 0.5];
            let (s, c) = sin_cos_f64(xs);
            for (i, v) in xs.iter().enumerate() {
                let (ls, lc) = libm::sincos(*v);
                worst = worst.max(libm::fabs(s[i] - ls)).max(libm::fabs(c[i] - lc));
            }
            x += 0.731;
        }
        assert!(worst <= f64::EPSILON, "{worst}");
    }

    #[test]
    fn small_angles_within_two_units_of_libm() {
        let mut x = 1e-300;
        while x < core::f64::consts::FRAC_PI_4 {
            let (s, c) = sin_cos_f64([x, -x]);
            let (ls, lc) = libm::sincos(x);
            assert!(
                libm::fabs(s[0] - ls) <= 2.0 * f64::EPSILON * libm::fabs(ls),
                "{x}"
            );
            assert_eq!(s[1], -s[0]);
            assert!(libm::fabs(c[0] - lc) <= 2.0 * f64::EPSILON * lc, "{x}");
            x *= 1.01;
        }
    }

    #[test]
    fn quadrant_edges_and_special_values() {
        let pi = core::f64::consts::PI;
        let xs = [
            0.0,
            -0.0,
            pi / 4.0,
            pi / 2.0,
            pi,
            1.5 * pi,
            2.0 * pi,
            -pi / 2.0,
            1e-300,
        ];
        let (s, c) = sin_cos_f64(xs);
        for (i, v) in xs.iter().enumerate() {
            let (ls, lc) = libm::sincos(*v);
            assert!(libm::fabs(s[i] - ls) <= f64::EPSILON, "sin {v}");
            assert!(libm::fabs(c[i] - lc) <= f64::EPSILON, "cos {v}");
        }
        let (s, c) = sin_cos_f64([f64::NAN, 1.0]);
        assert!(s[0].is_nan() && c[0].is_nan());
        assert!(libm::fabs(s[1] - libm::sin(1.0)) <= f64::EPSILON);
        // An infinite or very large angle sends the array to libm.
        let (s, c) = sin_cos_f64([f64::INFINITY, 1.0, 3.0e7]);
        assert!(s[0].is_nan() && c[0].is_nan());
        assert_eq!((s[2], c[2]), libm::sincos(3.0e7));
    }
}
