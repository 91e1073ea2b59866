//! `sin` and `cos` of an `f64` together, inlined: the generated code takes one `sin_cos` per
//! joint angle, a sizeable share of a call (twelve on a quadruped). The argument is reduced
//! to `[-pi/4, pi/4]` by a three-part Cody-Waite subtraction of the nearest multiple of `pi/2`
//! (exact products for `|x| <= 1e5`), then fdlibm's minimax polynomials (`__kernel_sin`,
//! `__kernel_cos`, accurate to about an ulp) give both values. Larger or non-finite arguments
//! go to `libm::sincos`.

// The constants are fdlibm's, digit for digit as published.
#![allow(clippy::excessive_precision)]

/// pi/2 in three parts: 33 + 33 bits and the rest (fdlibm's `pio2_1`, `pio2_2`, `pio2_3`).
const PIO2_1: f64 = 1.570_796_326_734_125_614_17e0;
const PIO2_2: f64 = 6.077_100_506_303_965_976_6e-11;
const PIO2_3: f64 = 2.022_266_248_711_166_455_8e-21;
/// 1.5 * 2^52: adding it rounds to the nearest integer and leaves it in the low mantissa bits.
const ROUNDER: f64 = 6_755_399_441_055_744.0;

const S1: f64 = -1.666_666_666_666_663_243_48e-1;
const S2: f64 = 8.333_333_333_322_489_461_24e-3;
const S3: f64 = -1.984_126_982_985_794_931_34e-4;
const S4: f64 = 2.755_731_370_707_006_767_89e-6;
const S5: f64 = -2.505_076_025_340_686_341_95e-8;
const S6: f64 = 1.589_690_995_211_550_102_21e-10;

const C1: f64 = 4.166_666_666_666_660_190_37e-2;
const C2: f64 = -1.388_888_888_887_410_957_49e-3;
const C3: f64 = 2.480_158_728_947_672_941_78e-5;
const C4: f64 = -2.755_731_435_139_066_330_35e-7;
const C5: f64 = 2.087_572_321_298_174_827_9e-9;
const C6: f64 = -1.135_964_755_778_819_482_65e-11;

/// `(sin x, cos x)`.
#[inline(always)]
pub(crate) fn sin_cos(x: f64) -> (f64, f64) {
    if x.is_nan() || x.abs() > 1.0e5 {
        return libm::sincos(x);
    }
    let t = x * core::f64::consts::FRAC_2_PI + ROUNDER;
    let quadrant = t.to_bits() & 3;
    let n = t - ROUNDER;
    let r = ((x - n * PIO2_1) - n * PIO2_2) - n * PIO2_3;
    let z = r * r;
    let s = r + z * r * (S1 + z * (S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)))));
    let poly = z * (C1 + z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * C6)))));
    let hz = 0.5 * z;
    let w = 1.0 - hz;
    let c = w + (((1.0 - w) - hz) + z * poly);
    match quadrant {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

#[cfg(test)]
mod tests {
    use super::sin_cos;

    /// Against libm over a million arguments up to 1e5 and the special ones: within two ulps of
    /// 1 (absolute, the values are at most 1 in size).
    #[test]
    fn matches_libm() {
        let mut x = 0x2545_f491_4f6c_dd1d_u64;
        let mut worst: f64 = 0.0;
        let mut check = |a: f64| {
            let (s, c) = sin_cos(a);
            let (s0, c0) = libm::sincos(a);
            worst = worst.max((s - s0).abs()).max((c - c0).abs());
        };
        for k in 0..1_000_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let u = (x >> 11) as f64 / (1u64 << 53) as f64;
            let scale = [4.0, 40.0, 1e5][k % 3];
            check((2.0 * u - 1.0) * scale);
        }
        for a in [
            0.0,
            -0.0,
            1e-300,
            core::f64::consts::FRAC_PI_4,
            core::f64::consts::FRAC_PI_2,
            core::f64::consts::PI,
            1e5,
            -1e5,
            355.0,
        ] {
            check(a);
        }
        assert!(worst <= 4.5e-16, "worst difference {worst:e}");
        assert!(sin_cos(f64::NAN).0.is_nan() && sin_cos(f64::INFINITY).1.is_nan());
        assert_eq!(sin_cos(1e300), libm::sincos(1e300));
    }
}
