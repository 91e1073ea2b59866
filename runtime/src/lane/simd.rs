//! [`Lane`] and [`Pack`] for `wide`'s vectors (the `simd` feature).
//!
//! `wide` builds on stable Rust and `no_std`, and picks its instructions at compile time from
//! the target features (`-C target-cpu=native`): AVX for `f64x4` and `f32x8`, SSE2 or NEON for
//! `f64x2` and `f32x4`, and plain arrays elsewhere. Its `mul_add` fuses exactly when
//! [`Real::mul_add`](crate::Real::mul_add) does on x86-64 (the `fma` feature), its arithmetic
//! and square root are IEEE's, so a lane computes what the scalar code computes, bit for bit.
//! `-x` is `wide`'s `0 - x`, which differs from a scalar's negation in the sign of a zero (and
//! of a NaN); [`Lane::neg_exact`] flips the sign bit as the scalar does. Sines and cosines:
//! the `f64` vectors' [`Lane::sin_cos_many`] (every joint angle of generated code) runs the
//! scalar `f64` kernel, [`crate::trig::sin_cos_f64_in`], on all lanes at once, bit for bit
//! again; single sines and cosines, and the `f32` vectors', are `wide`'s polynomial
//! approximations, which differ from `libm`'s in the last bits.

use super::{pack_each, scalar_check, unpack_each, unpack_run_each, Lane, LaneError, Pack};
use crate::FactorError;
use wide::{f32x4, f32x8, f64x2, f64x4};

mod transpose;

macro_rules! impl_lane {
    ($v:ident, $s:ident, $n:literal, $pack:path, $unpack:path, $run:path, $many:path) => {
        impl Lane for $v {
            const LANES: usize = $n;
            type Mask = $v;
            type Failures = [Option<FactorError>; $n];
            #[inline(always)]
            fn from_f64(v: f64) -> Self {
                $v::splat(v as $s)
            }
            #[inline(always)]
            fn zero() -> Self {
                $v::ZERO
            }
            #[inline(always)]
            fn one() -> Self {
                $v::ONE
            }
            #[inline(always)]
            fn nan() -> Self {
                $v::splat($s::NAN)
            }
            #[inline(always)]
            fn sin(self) -> Self {
                $v::sin(self)
            }
            #[inline(always)]
            fn cos(self) -> Self {
                $v::cos(self)
            }
            #[inline(always)]
            fn sin_cos(self) -> (Self, Self) {
                $v::sin_cos(self)
            }
            #[inline(always)]
            fn sin_cos_many<const K: usize>(x: [Self; K]) -> ([Self; K], [Self; K]) {
                $many(x)
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                $v::sqrt(self)
            }
            #[inline(always)]
            fn abs(self) -> Self {
                $v::abs(self)
            }
            #[inline(always)]
            fn signum(self) -> Self {
                let zero = $v::ZERO;
                let negative = <$v as Lane>::select(zero.gt(self), -$v::ONE, self);
                <$v as Lane>::select(self.gt(zero), $v::ONE, negative)
            }
            #[inline(always)]
            fn recip(self) -> Self {
                $v::ONE / self
            }
            #[inline(always)]
            fn mul_add(self, a: Self, b: Self) -> Self {
                $v::mul_add(self, a, b)
            }
            #[inline(always)]
            fn neg_exact(self) -> Self {
                self ^ $v::splat(-0.0)
            }
            #[inline(always)]
            fn epsilon() -> Self {
                $v::splat($s::EPSILON)
            }
            #[inline(always)]
            fn finite(self) -> $v {
                $v::is_finite(self)
            }
            #[inline(always)]
            fn gt(self, other: Self) -> $v {
                wide::CmpGt::cmp_gt(self, other)
            }
            #[inline(always)]
            fn select(mask: $v, yes: Self, no: Self) -> Self {
                mask.blend(yes, no)
            }
            #[inline(always)]
            fn check_pivot(
                d: Self,
                pivot: usize,
                failures: &mut Self::Failures,
            ) -> Result<(), FactorError> {
                if (d.finite() & d.gt($v::ZERO)).all() {
                    return Ok(());
                }
                record(failures, d.to_array(), |x| {
                    scalar_check(x.is_finite(), x > 0.0, true, pivot)
                });
                Ok(())
            }
            #[inline(always)]
            fn check_finite(
                x: Self,
                index: usize,
                failures: &mut Self::Failures,
            ) -> Result<(), FactorError> {
                if x.finite().all() {
                    return Ok(());
                }
                record(failures, x.to_array(), |x| {
                    scalar_check(x.is_finite(), true, false, index)
                });
                Ok(())
            }
            #[inline(always)]
            fn failed(failures: &Self::Failures) -> $v {
                let set = <$s>::from_bits(!0);
                $v::new(failures.map(|f| if f.is_some() { set } else { 0.0 }))
            }
            #[inline(always)]
            fn any(mask: $v) -> bool {
                mask.any()
            }
            #[inline(always)]
            fn all(mask: $v) -> bool {
                mask.all()
            }
            #[inline(always)]
            fn first_failure(failures: &Self::Failures) -> Option<LaneError> {
                first(failures)
            }
        }

        impl Pack for $v {
            type Scalar = $s;
            #[inline(always)]
            fn gather(f: impl FnMut(usize) -> $s) -> Self {
                $v::new(core::array::from_fn(f))
            }
            #[inline(always)]
            fn lane(self, l: usize) -> $s {
                self.to_array()[l % $n]
            }
            type Array = [$s; $n];
            #[inline(always)]
            fn lanes(self) -> [$s; $n] {
                self.to_array()
            }
            #[inline(always)]
            fn pack(states: &[$s], v: &mut [Self]) {
                $pack(states, v);
            }
            #[inline(always)]
            fn unpack(v: &[Self], states: &mut [$s]) {
                $unpack(v, states);
            }
            #[inline(always)]
            fn unpack_run<const R: usize, const C: usize>(
                v: &[Self],
                states: &mut [[[$s; C]; R]],
                at: usize,
            ) {
                $run(v, states, at);
            }
        }
    };
}

impl_lane!(
    f64x2,
    f64,
    2,
    pack_each,
    unpack_each,
    unpack_run_each,
    sin_cos_flat
);
impl_lane!(
    f64x4,
    f64,
    4,
    transpose::pack_f64x4,
    transpose::unpack_f64x4,
    transpose::unpack_run_f64x4,
    sin_cos_flat
);
impl_lane!(
    f32x4,
    f32,
    4,
    pack_each,
    unpack_each,
    unpack_run_each,
    sin_cos_wide
);
impl_lane!(
    f32x8,
    f32,
    8,
    transpose::pack_f32x8,
    transpose::unpack_f32x8,
    transpose::unpack_run_f32x8,
    sin_cos_wide
);

/// The `f64` vectors' [`Lane::sin_cos_many`]: every lane of every element by
/// [`crate::trig::sin_cos_f64_in`], as one slice of `f64` (its loop runs on the widest vectors
/// the target has, eight angles per instruction with AVX-512), so that each lane gets the
/// scalar `f64` code's sines and cosines, bit for bit. The vectors are read and written in
/// place, as `f64`s: copying them to arrays of `f64` and back (four-lane stores read by
/// eight-lane loads, which the store buffer cannot forward) took a tenth of the panda's
/// `f64x4` mass matrix batch.
#[inline(always)]
fn sin_cos_flat<V: Lane + bytemuck::Pod, const K: usize>(x: [V; K]) -> ([V; K], [V; K]) {
    let (mut s, mut c) = ([V::zero(); K], [V::zero(); K]);
    crate::trig::sin_cos_f64_in(
        bytemuck::cast_slice(&x),
        bytemuck::cast_slice_mut(&mut s),
        bytemuck::cast_slice_mut(&mut c),
    );
    (s, c)
}

/// The `f32` vectors' [`Lane::sin_cos_many`]: `wide`'s `sin_cos`, element by element.
#[inline(always)]
fn sin_cos_wide<V: Lane, const K: usize>(x: [V; K]) -> ([V; K], [V; K]) {
    crate::trig::each(x, V::sin_cos)
}

/// Records, in each lane without a failure yet, the failure `check` finds in its value.
#[cold]
fn record<S: Copy, const N: usize>(
    failures: &mut [Option<FactorError>; N],
    values: [S; N],
    check: impl Fn(S) -> Option<FactorError>,
) {
    for (f, x) in failures.iter_mut().zip(values) {
        if f.is_none() {
            *f = check(x);
        }
    }
}

/// The lowest lane with a failure.
fn first<const N: usize>(failures: &[Option<FactorError>; N]) -> Option<LaneError> {
    failures
        .iter()
        .enumerate()
        .find_map(|(lane, f)| f.map(|error| LaneError { lane, error }))
}
