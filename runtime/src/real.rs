//! The scalar trait used by generated code.

use crate::lane::Arithmetic;
use core::fmt::Debug;

/// A real scalar type that generated dynamics code can be instantiated with.
///
/// Implemented for [`f32`] (microcontrollers with a single-precision FPU) and [`f64`] (host).
/// `core` provides no transcendental functions, so the implementations call [`libm`]; on the
/// host the results may differ from `std`'s in the last bit.
///
/// The trait is not sealed: it can be implemented for other scalar types (dual numbers for
/// automatic differentiation, interval types, ...) as long as they behave like real numbers.
///
/// Generated code calls these methods inside long straight-line functions, so the f32/f64
/// implementations are `#[inline(always)]`.
///
/// ```
/// use eomgen_runtime::Real;
///
/// fn pendulum_torque<T: Real>(m: T, l: T, q: T) -> T {
///     m * T::from_f64(9.81) * l * q.sin()
/// }
///
/// assert!((pendulum_torque(1.0_f64, 1.0, 0.5) - 9.81 * 0.5_f64.sin()).abs() < 1e-12);
/// assert!((pendulum_torque(1.0_f32, 1.0, 0.5) - 4.703_f32).abs() < 1e-3);
/// assert_eq!(0.0_f64.signum(), 1.0); // std: +0 has sign +1 ...
/// assert_eq!(Real::signum(0.0_f64), 0.0); // ... Real: 0 has sign 0
/// ```
pub trait Real:
    Copy + Clone + PartialEq + PartialOrd + Debug + Default + Arithmetic + 'static
{
    /// Converts an `f64` (rounding to nearest for `f32`). Generated code writes every numeric
    /// constant as `T::from_f64(..)`; for `f32` and `f64` this folds to a constant.
    fn from_f64(v: f64) -> Self;
    /// Converts to `f64` (exact for `f32` and `f64`).
    fn to_f64(self) -> f64;
    /// The additive identity, `0`.
    fn zero() -> Self;
    /// The multiplicative identity, `1`.
    fn one() -> Self;
    /// A quiet NaN ("not a number"), used to report failures without panicking.
    fn nan() -> Self;
    /// The machine epsilon: the difference between 1 and the next larger representable number.
    fn epsilon() -> Self;
    /// Sine (argument in radians).
    fn sin(self) -> Self;
    /// Cosine (argument in radians).
    fn cos(self) -> Self;
    /// Sine and cosine at once, `(sin(self), cos(self))`; cheaper than two calls.
    fn sin_cos(self) -> (Self, Self);
    /// The sines and the cosines of every element of `x`: generated code calls this once, with
    /// every joint angle it needs. By default [`Real::sin_cos`] element by element; `f64`
    /// computes the whole array with vector instructions ([`crate::trig::sin_cos_f64`]).
    ///
    /// ```
    /// use eomgen_runtime::Real;
    /// let (s, c) = <f64 as Real>::sin_cos_many([0.5, -1.0]);
    /// assert!((s[0] - 0.5_f64.sin()).abs() < 1e-15 && (c[1] - 1.0_f64.cos()).abs() < 1e-15);
    /// ```
    #[inline(always)]
    fn sin_cos_many<const K: usize>(x: [Self; K]) -> ([Self; K], [Self; K]) {
        crate::trig::each(x, Self::sin_cos)
    }
    /// Four-quadrant arctangent of `self / x` (`self` is y), in `[-pi, pi]`.
    fn atan2(self, x: Self) -> Self;
    /// Square root; NaN for negative arguments.
    fn sqrt(self) -> Self;
    /// Absolute value.
    fn abs(self) -> Self;
    /// Sign of `self`: `1` if positive, `-1` if negative, and **zero at zero**.
    ///
    /// Unlike `f64::signum` (which gives `1.0` for `+0.0` and `-1.0` for `-0.0`), this returns
    /// `self` unchanged when it is `±0` (or NaN). eomgen uses it for Coulomb friction,
    /// `tau_f = mu * sign(qd)`, where a joint at rest must get no friction torque.
    fn signum(self) -> Self;
    /// `1 / self`.
    fn recip(self) -> Self;
    /// The smaller of `self` and `other`; if one of them is NaN, the other is returned.
    fn min(self, other: Self) -> Self;
    /// The larger of `self` and `other`; if one of them is NaN, the other is returned.
    fn max(self, other: Self) -> Self;
    /// `self * a + b`.
    ///
    /// Not guaranteed to be fused (single rounding): the `f32`/`f64` implementations fuse it into
    /// one instruction on x86-64 compiled with the `fma` target feature (as with
    /// `-C target-cpu=native` on any recent processor) and use a plain multiply and add
    /// elsewhere, because `libm`'s exact fused version is a slow software routine on targets
    /// without an FMA instruction. Generated code folds every product of a sum in with it.
    fn mul_add(self, a: Self, b: Self) -> Self;
    /// `true` unless `self` is infinite or NaN.
    fn is_finite(self) -> bool;
}

macro_rules! impl_real {
    ($t:ty, $sin:path, $cos:path, $sincos:path, $many:path, $atan2:path, $sqrt:path,
     $fabs:path, $fmin:path, $fmax:path, $fma:path) => {
        impl Real for $t {
            #[inline(always)]
            fn from_f64(v: f64) -> Self {
                v as $t
            }
            #[inline(always)]
            fn to_f64(self) -> f64 {
                self as f64
            }
            #[inline(always)]
            fn zero() -> Self {
                0.0
            }
            #[inline(always)]
            fn one() -> Self {
                1.0
            }
            #[inline(always)]
            fn nan() -> Self {
                <$t>::NAN
            }
            #[inline(always)]
            fn epsilon() -> Self {
                <$t>::EPSILON
            }
            #[inline(always)]
            fn sin(self) -> Self {
                $sin(self)
            }
            #[inline(always)]
            fn cos(self) -> Self {
                $cos(self)
            }
            #[inline(always)]
            fn sin_cos(self) -> (Self, Self) {
                $sincos(self)
            }
            #[inline(always)]
            fn sin_cos_many<const K: usize>(x: [Self; K]) -> ([Self; K], [Self; K]) {
                $many(x)
            }
            #[inline(always)]
            fn atan2(self, x: Self) -> Self {
                $atan2(self, x)
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                $sqrt(self)
            }
            #[inline(always)]
            fn abs(self) -> Self {
                $fabs(self)
            }
            #[inline(always)]
            fn signum(self) -> Self {
                if self > 0.0 {
                    1.0
                } else if self < 0.0 {
                    -1.0
                } else {
                    self
                }
            }
            #[inline(always)]
            fn recip(self) -> Self {
                1.0 / self
            }
            #[inline(always)]
            fn min(self, other: Self) -> Self {
                $fmin(self, other)
            }
            #[inline(always)]
            fn max(self, other: Self) -> Self {
                $fmax(self, other)
            }
            #[inline(always)]
            fn mul_add(self, a: Self, b: Self) -> Self {
                $fma(self, a, b)
            }
            #[inline(always)]
            fn is_finite(self) -> bool {
                <$t>::is_finite(self)
            }
        }
    };
}

impl_real!(
    f32,
    libm::sinf,
    libm::cosf,
    libm::sincosf,
    sin_cos_each,
    libm::atan2f,
    libm::sqrtf,
    libm::fabsf,
    libm::fminf,
    libm::fmaxf,
    fused::f32
);
impl_real!(
    f64,
    libm::sin,
    libm::cos,
    libm::sincos,
    crate::trig::sin_cos_f64,
    libm::atan2,
    libm::sqrt,
    libm::fabs,
    libm::fmin,
    libm::fmax,
    fused::f64
);

/// `f32`'s [`Real::sin_cos_many`]: `libm::sincosf` element by element (single precision
/// mostly runs on microcontrollers, whose FPU has no vector unit and no double precision).
#[inline(always)]
fn sin_cos_each<const K: usize>(x: [f32; K]) -> ([f32; K], [f32; K]) {
    crate::trig::each(x, libm::sincosf)
}

/// `x * a + b`, fused where the target has an FMA instruction, known at compile time.
///
/// Stable Rust cannot call the FMA intrinsics without `unsafe` (the `fma` feature enabled for
/// the whole crate does not count as the caller's), nor fuse a multiply and an add any other
/// way: this module is the crate's one exemption from `unsafe_code`, for two calls whose only
/// precondition (the CPU has FMA) the `cfg` establishes.
///
/// The fused versions are `#[inline]`, not `#[inline(always)]`: LLVM inlines `always` functions
/// before it simplifies them, so each call brought the intrinsics' unsimplified `__m128d`
/// temporaries (about ten stack slots) into the caller, and promoting tens of thousands of them
/// to registers in one long generated function took LLVM's `PromoteMemToReg` tens of minutes
/// (anymal's derivatives, `-C target-cpu=native`). Inlined after simplification, each call is
/// one `vfmadd` instruction, and the same crate builds in about 20 s.
#[allow(unsafe_code)]
mod fused {
    #[cfg(all(target_arch = "x86_64", target_feature = "fma"))]
    #[inline]
    pub fn f64(x: f64, a: f64, b: f64) -> f64 {
        use core::arch::x86_64::{_mm_cvtsd_f64, _mm_fmadd_sd, _mm_set_sd};
        // SAFETY: the `fma` target feature is enabled at compile time (the `cfg` above).
        unsafe { _mm_cvtsd_f64(_mm_fmadd_sd(_mm_set_sd(x), _mm_set_sd(a), _mm_set_sd(b))) }
    }

    #[cfg(all(target_arch = "x86_64", target_feature = "fma"))]
    #[inline]
    pub fn f32(x: f32, a: f32, b: f32) -> f32 {
        use core::arch::x86_64::{_mm_cvtss_f32, _mm_fmadd_ss, _mm_set_ss};
        // SAFETY: the `fma` target feature is enabled at compile time (the `cfg` above).
        unsafe { _mm_cvtss_f32(_mm_fmadd_ss(_mm_set_ss(x), _mm_set_ss(a), _mm_set_ss(b))) }
    }

    #[cfg(not(all(target_arch = "x86_64", target_feature = "fma")))]
    #[inline(always)]
    pub fn f64(x: f64, a: f64, b: f64) -> f64 {
        x * a + b
    }

    #[cfg(not(all(target_arch = "x86_64", target_feature = "fma")))]
    #[inline(always)]
    pub fn f32(x: f32, a: f32, b: f32) -> f32 {
        x * a + b
    }
}
