//! The scalar abstraction generated code is written against: a [`Lane`] is one number (every
//! [`Real`], with [`LANES`](Lane::LANES) = 1) or a SIMD vector of numbers (with the `simd`
//! feature: `wide`'s `f64x2`, `f64x4`, `f32x4`, `f32x8`), one robot state per lane.
//!
//! Generated code branches nowhere on values except to check the pivots of a factorization and
//! the finiteness of a solve's result. Those checks go through [`Lane::check_pivot`] and
//! [`Lane::check_finite`]: a scalar returns the error at once (as the code always did), a vector
//! records each lane's first failure in its [`Lane::Failures`] and carries on, and the failed
//! lanes' results are set to NaN at the end ([`nan_failed`]), the other lanes unaffected. A
//! `try_..._lanes` method reports the lowest failed lane as a [`LaneError`].
//!
//! ```
//! use eomgen_runtime::lane::{check_pivots, nan_failed, Lane};
//!
//! fn reciprocals<T: Lane>(d: [T; 2]) -> [T; 2] {
//!     let mut failures = T::Failures::default();
//!     if check_pivots(&d, &mut failures).is_err() {
//!         return [T::nan(); 2]; // a scalar stops at its first bad pivot
//!     }
//!     nan_failed([d[0].recip(), d[1].recip()], &failures)
//! }
//! assert_eq!(reciprocals([2.0_f64, 4.0]), [0.5, 0.25]);
//! assert!(reciprocals([2.0_f64, -4.0])[0].is_nan());
//! ```

use core::fmt::{self, Debug};
use core::ops::{Add, AddAssign, Div, DivAssign, Mul, MulAssign, Neg, Sub, SubAssign};

use crate::{FactorError, Real};

/// A number or a vector of numbers that generated code can be instantiated with: the
/// arithmetic, the few functions the generated expressions call, and lane-wise comparison and
/// selection in place of branches.
///
/// Every [`Real`] is a `Lane` of one lane (a blanket implementation, so types implementing
/// `Real` need nothing more). With the `simd` feature, `wide::f64x2`, `f64x4`, `f32x4` and
/// `f32x8` are lanes too.
///
/// ```
/// use eomgen_runtime::Lane;
///
/// fn hypot<T: Lane>(x: T, y: T) -> T {
///     x.mul_add(x, y * y).sqrt()
/// }
/// assert_eq!(hypot(3.0_f64, 4.0), 5.0);
/// ```
pub trait Lane: Copy + Debug + Default + Arithmetic + 'static {
    /// The number of lanes (1 for a scalar).
    const LANES: usize;
    /// A lane-wise truth value (`bool` for a scalar).
    type Mask: Copy + Debug;
    /// Each lane's first failure in a checked computation: `()` for a scalar, which stops at
    /// its first failure instead ([`Lane::check_pivot`]).
    type Failures: Copy + Debug + Default;
    /// `v` in every lane (rounded to nearest for single precision).
    fn from_f64(v: f64) -> Self;
    /// `0` in every lane.
    fn zero() -> Self;
    /// `1` in every lane.
    fn one() -> Self;
    /// A quiet NaN in every lane.
    fn nan() -> Self;
    /// Sine (radians), lane-wise.
    fn sin(self) -> Self;
    /// Cosine (radians), lane-wise.
    fn cos(self) -> Self;
    /// `(sin(self), cos(self))`, lane-wise.
    fn sin_cos(self) -> (Self, Self);
    /// The sines and the cosines of every element of `x` ([`Real::sin_cos_many`] for a
    /// scalar; `wide`'s `f64` vectors run [`crate::trig::sin_cos_f64_in`] on all their lanes at
    /// once, as the scalar `f64` does; [`Lane::sin_cos`] element by element by default).
    #[inline(always)]
    fn sin_cos_many<const K: usize>(x: [Self; K]) -> ([Self; K], [Self; K]) {
        crate::trig::each(x, Self::sin_cos)
    }
    /// Square root, lane-wise; NaN for negative lanes.
    fn sqrt(self) -> Self;
    /// Absolute value, lane-wise.
    fn abs(self) -> Self;
    /// The sign, lane-wise: `1` if positive, `-1` if negative, the lane itself at `±0` and NaN
    /// (as [`Real::signum`]: a joint at rest gets no Coulomb friction).
    fn signum(self) -> Self;
    /// `1 / self`, lane-wise.
    fn recip(self) -> Self;
    /// `self * a + b`, fused where [`Real::mul_add`] is (an FMA instruction at compile time).
    fn mul_add(self, a: Self, b: Self) -> Self;
    /// `-self`, lane-wise, with its sign bit flipped in every lane as a scalar's `-` flips it:
    /// `-0` for `+0`. `wide`'s vectors implement `-x` as `0 - x`, which gives `+0` for `+0`
    /// (and keeps a NaN's sign); code that must match the scalar's signed zeros in every lane
    /// negates through here. A scalar's is its `-`.
    ///
    /// ```
    /// use eomgen_runtime::Lane;
    /// assert!(0.0_f64.neg_exact().is_sign_negative());
    /// ```
    #[inline(always)]
    fn neg_exact(self) -> Self {
        -self
    }
    /// The machine epsilon of a lane's scalar (`f64::EPSILON`, or `f32::EPSILON` for the
    /// vectors of `f32`), in every lane.
    ///
    /// ```
    /// use eomgen_runtime::Lane;
    /// assert_eq!(<f32 as Lane>::epsilon(), f32::EPSILON);
    /// ```
    #[inline(always)]
    fn epsilon() -> Self {
        Self::from_f64(f64::EPSILON)
    }
    /// Lanes that are neither infinite nor NaN.
    fn finite(self) -> Self::Mask;
    /// Lanes where `self > other` (false where either is NaN).
    fn gt(self, other: Self) -> Self::Mask;
    /// `yes` in the lanes of `mask`, `no` in the others.
    fn select(mask: Self::Mask, yes: Self, no: Self) -> Self;
    /// Checks pivot number `pivot` of a factorization, `d`, in every lane: a scalar returns
    /// the error at once ([`FactorError::NonFinite`] if `d` is not finite, else
    /// [`FactorError::NotPositiveDefinite`] unless `d > 0`); a vector records the error of each
    /// lane that had none yet in `failures` and returns `Ok`.
    fn check_pivot(d: Self, pivot: usize, failures: &mut Self::Failures)
        -> Result<(), FactorError>;
    /// Checks that component `index` of a solution, `x`, is finite in every lane (as
    /// [`Lane::check_pivot`], with [`FactorError::NonFinite`]).
    fn check_finite(
        x: Self,
        index: usize,
        failures: &mut Self::Failures,
    ) -> Result<(), FactorError>;
    /// The lanes that recorded a failure.
    fn failed(failures: &Self::Failures) -> Self::Mask;
    /// Whether any lane of `mask` is set.
    fn any(mask: Self::Mask) -> bool;
    /// Whether every lane of `mask` is set.
    fn all(mask: Self::Mask) -> bool;
    /// The lowest lane that recorded a failure, with its error.
    fn first_failure(failures: &Self::Failures) -> Option<LaneError>;
    /// Whether `self` is zero in every lane (no lane NaN, infinite or anything but zero): a
    /// multiply-add by it changes no lane of a sum, so sparse kernels skip it. A scalar
    /// compares once.
    ///
    /// ```
    /// use eomgen_runtime::Lane;
    /// assert!(0.0_f64.zero_in_every_lane() && !f64::NAN.zero_in_every_lane());
    /// ```
    #[inline(always)]
    fn zero_in_every_lane(self) -> bool {
        !Self::any(self.abs().gt(Self::zero())) && Self::all(self.finite())
    }
}

/// The operators of [`Real`] and [`Lane`]: `+ - * /`, their assignments and negation, all
/// on `Self`. Implemented for every type that has them.
///
/// ```
/// fn twice<T: eomgen_runtime::Arithmetic + Copy>(x: T) -> T {
///     x + x
/// }
/// assert_eq!(twice(1.5_f32), 3.0);
/// ```
pub trait Arithmetic:
    Sized
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
    + DivAssign
{
}

impl<T> Arithmetic for T where
    T: Add<Output = T>
        + Sub<Output = T>
        + Mul<Output = T>
        + Div<Output = T>
        + Neg<Output = T>
        + AddAssign
        + SubAssign
        + MulAssign
        + DivAssign
{
}

/// Why one lane of a lane-wise checked computation (a `try_..._lanes` method) failed: the
/// lane (0-based; always 0 for a scalar) and its own error, the one the scalar code gives on
/// that lane's inputs.
///
/// ```
/// use eomgen_runtime::{FactorError, LaneError};
///
/// let e = LaneError { lane: 2, error: FactorError::NotPositiveDefinite { pivot: 1 } };
/// assert_eq!(e.to_string(), "lane 2: matrix is not positive definite: pivot 1 is zero or negative");
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct LaneError {
    /// The 0-based lane (state within the vector) that failed.
    pub lane: usize,
    /// That lane's error.
    pub error: FactorError,
}

impl fmt::Display for LaneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "lane {}: {}", self.lane, self.error)
    }
}

#[cfg(feature = "std")]
impl std::error::Error for LaneError {}

/// [`Lane::check_pivot`] on every pivot, in order.
#[inline(always)]
pub fn check_pivots<T: Lane, const P: usize>(
    pivots: &[T; P],
    failures: &mut T::Failures,
) -> Result<(), FactorError> {
    for (pivot, d) in pivots.iter().enumerate() {
        T::check_pivot(*d, pivot, failures)?;
    }
    Ok(())
}

/// [`Lane::check_finite`] on every component of `x`, in order.
///
/// ```
/// use eomgen_runtime::{lane::check_finite, FactorError};
/// assert_eq!(check_finite(&[1.0_f64, f64::NAN], &mut ()), Err(FactorError::NonFinite { pivot: 1 }));
/// ```
#[inline(always)]
pub fn check_finite<T: Lane, const N: usize>(
    x: &[T; N],
    failures: &mut T::Failures,
) -> Result<(), FactorError> {
    for (index, v) in x.iter().enumerate() {
        T::check_finite(*v, index, failures)?;
    }
    Ok(())
}

/// `o` with NaN in the lanes that recorded a failure (`o` itself for a scalar, whose failures
/// stop the computation before).
#[inline(always)]
pub fn nan_failed<T: Lane, const L: usize>(o: [T; L], failures: &T::Failures) -> [T; L] {
    let failed = T::failed(failures);
    if !T::any(failed) {
        return o;
    }
    o.map(|x| T::select(failed, T::nan(), x))
}

/// [`nan_failed`] in place, on the entries of `x` (a flattened matrix, say).
///
/// ```
/// let mut m = [[1.0_f64, 2.0], [3.0, 4.0]];
/// eomgen_runtime::lane::nan_failed_in::<f64>(m.as_flattened_mut(), &()); // a scalar: no failures
/// assert_eq!(m, [[1.0, 2.0], [3.0, 4.0]]);
/// ```
#[inline]
pub fn nan_failed_in<T: Lane>(x: &mut [T], failures: &T::Failures) {
    let failed = T::failed(failures);
    if T::any(failed) {
        for v in x {
            *v = T::select(failed, T::nan(), *v);
        }
    }
}

/// `Ok(x)` when no lane failed, else the lowest failed lane ([`Lane::first_failure`]).
///
/// ```
/// assert_eq!(eomgen_runtime::lane::lanes_ok::<_, f64>(7, &()), Ok(7));
/// ```
#[inline(always)]
pub fn lanes_ok<X, T: Lane>(x: X, failures: &T::Failures) -> Result<X, LaneError> {
    match T::first_failure(failures) {
        Some(e) => Err(e),
        None => Ok(x),
    }
}

/// The error of one value checked as a pivot (`pivot: true`) or as a solution component.
#[inline(always)]
fn scalar_check(finite: bool, positive: bool, pivot: bool, at: usize) -> Option<FactorError> {
    if !finite {
        Some(FactorError::NonFinite { pivot: at })
    } else if pivot && !positive {
        Some(FactorError::NotPositiveDefinite { pivot: at })
    } else {
        None
    }
}

impl<T: Real> Lane for T {
    const LANES: usize = 1;
    type Mask = bool;
    type Failures = ();
    #[inline(always)]
    fn from_f64(v: f64) -> Self {
        <T as Real>::from_f64(v)
    }
    #[inline(always)]
    fn zero() -> Self {
        <T as Real>::zero()
    }
    #[inline(always)]
    fn one() -> Self {
        <T as Real>::one()
    }
    #[inline(always)]
    fn nan() -> Self {
        <T as Real>::nan()
    }
    #[inline(always)]
    fn epsilon() -> Self {
        <T as Real>::epsilon()
    }
    #[inline(always)]
    fn sin(self) -> Self {
        Real::sin(self)
    }
    #[inline(always)]
    fn cos(self) -> Self {
        Real::cos(self)
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        Real::sin_cos(self)
    }
    #[inline(always)]
    fn sin_cos_many<const K: usize>(x: [Self; K]) -> ([Self; K], [Self; K]) {
        <T as Real>::sin_cos_many(x)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Real::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        Real::abs(self)
    }
    #[inline(always)]
    fn signum(self) -> Self {
        Real::signum(self)
    }
    #[inline(always)]
    fn recip(self) -> Self {
        Real::recip(self)
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        Real::mul_add(self, a, b)
    }
    #[inline(always)]
    fn finite(self) -> bool {
        Real::is_finite(self)
    }
    #[inline(always)]
    fn gt(self, other: Self) -> bool {
        self > other
    }
    #[inline(always)]
    fn select(mask: bool, yes: Self, no: Self) -> Self {
        if mask {
            yes
        } else {
            no
        }
    }
    #[inline(always)]
    fn check_pivot(d: Self, pivot: usize, _: &mut ()) -> Result<(), FactorError> {
        let positive = d > <T as Real>::zero();
        scalar_check(Real::is_finite(d), positive, true, pivot).map_or(Ok(()), Err)
    }
    #[inline(always)]
    fn check_finite(x: Self, index: usize, _: &mut ()) -> Result<(), FactorError> {
        scalar_check(Real::is_finite(x), true, false, index).map_or(Ok(()), Err)
    }
    #[inline(always)]
    fn failed(_: &()) -> bool {
        false
    }
    #[inline(always)]
    fn zero_in_every_lane(self) -> bool {
        self == T::zero()
    }
    #[inline(always)]
    fn any(mask: bool) -> bool {
        mask
    }
    #[inline(always)]
    fn all(mask: bool) -> bool {
        mask
    }
    #[inline(always)]
    fn first_failure(_: &()) -> Option<LaneError> {
        None
    }
}

/// A [`Lane`] of [`LANES`](Lane::LANES) scalars: states are gathered into it and scattered out
/// lane by lane. Every [`Real`] is one of one lane; with the `simd` feature, so are `wide`'s
/// vectors.
///
/// ```
/// use eomgen_runtime::lane::Pack;
///
/// let x = f64::gather(|l| 0.5 + l as f64);
/// assert_eq!((x, x.lane(0), x.lanes()), (0.5, 0.5, [0.5]));
/// ```
pub trait Pack: Lane {
    /// The scalar of one lane.
    type Scalar: Real;
    /// The value whose lane `l` is `f(l)`, for `l` in `0..LANES`.
    fn gather(f: impl FnMut(usize) -> Self::Scalar) -> Self;
    /// Lane `l` (`l < LANES`; a larger `l` gives lane `l % LANES`).
    fn lane(self, l: usize) -> Self::Scalar;
    /// Every lane, in order (`[Scalar; LANES]`).
    type Array: AsRef<[Self::Scalar]>;
    /// Every lane, in order: cheaper than [`Pack::lane`] for each.
    fn lanes(self) -> Self::Array;
    /// Packs the states stored one after another in `states`, `v.len()` scalars each, into
    /// `v`: lane `l` of `v[j]` is `states[l * v.len() + j]`. Lanes whose state `states` does
    /// not hold whole are zero. `f64x4` and `f32x8` on AVX transpose blocks of 4 x 4 (8 x 8)
    /// in registers: one load per state and block instead of one per lane and entry.
    ///
    /// ```
    /// use eomgen_runtime::lane::Pack;
    ///
    /// let mut v = [0.0_f64; 3];
    /// f64::pack(&[1.0, 2.0, 3.0], &mut v); // one lane: one state of three entries
    /// assert_eq!(v, [1.0, 2.0, 3.0]);
    /// ```
    #[inline(always)]
    fn pack(states: &[Self::Scalar], v: &mut [Self]) {
        pack_each(states, v);
    }
    /// The inverse of [`Pack::pack`]: lane `l` of `v[j]` into `states[l * v.len() + j]`, for
    /// the first `LANES` states that `states` holds whole (fewer for a partial last vector).
    ///
    /// ```
    /// use eomgen_runtime::lane::Pack;
    ///
    /// let mut states = [0.0_f64; 2];
    /// f64::unpack(&[1.5, 2.5], &mut states);
    /// assert_eq!(states, [1.5, 2.5]);
    /// ```
    #[inline(always)]
    fn unpack(v: &[Self], states: &mut [Self::Scalar]) {
        unpack_each(v, states);
    }
    /// The run `v` of the entries `at..at + v.len()` (row-major) of the `R x C` matrices of the
    /// first `LANES` states of `states`: lane `l` of `v[j]` goes to entry `at + j` of
    /// `states[l]` (entries past the matrix's end are dropped). A generated batch method
    /// writes its result run by run as its last statements compute it, so that the result
    /// never goes through an array of vectors; with `R`, `C` and `at` constants, no index is
    /// checked at run time.
    ///
    /// ```
    /// use eomgen_runtime::lane::Pack;
    ///
    /// let mut states = [[[0.0_f64; 2]; 2]];
    /// f64::unpack_run(&[1.5, 2.5], &mut states, 1);
    /// assert_eq!(states, [[[0.0, 1.5], [2.5, 0.0]]]);
    /// ```
    #[inline(always)]
    fn unpack_run<const R: usize, const C: usize>(
        v: &[Self],
        states: &mut [[[Self::Scalar; C]; R]],
        at: usize,
    ) {
        unpack_run_each(v, states, at);
    }
}

/// [`Pack::pack`] lane by lane (what vectors without a transposition of their own use).
#[inline(always)]
pub(crate) fn pack_each<L: Pack>(states: &[L::Scalar], v: &mut [L]) {
    let n = v.len();
    let zero = <L::Scalar as Real>::zero();
    for (j, x) in v.iter_mut().enumerate() {
        *x = L::gather(|l| {
            let whole = states.len() / n.max(1) > l;
            states.get(l * n + j).filter(|_| whole).map_or(zero, |s| *s)
        });
    }
}

/// [`Pack::unpack`] lane by lane: each vector's lanes read once.
#[inline(always)]
pub(crate) fn unpack_each<L: Pack>(v: &[L], states: &mut [L::Scalar]) {
    let n = v.len();
    if n == 0 {
        return;
    }
    for (j, x) in v.iter().enumerate() {
        for (state, y) in states.chunks_exact_mut(n).zip(x.lanes().as_ref()) {
            if let Some(o) = state.get_mut(j) {
                *o = *y;
            }
        }
    }
}

/// [`Pack::unpack_run`] lane by lane.
#[inline(always)]
pub(crate) fn unpack_run_each<L: Pack, const R: usize, const C: usize>(
    v: &[L],
    states: &mut [[[L::Scalar; C]; R]],
    at: usize,
) {
    for (j, x) in v.iter().enumerate() {
        for (state, y) in states.iter_mut().zip(x.lanes().as_ref()) {
            if let Some(o) = state.as_flattened_mut().get_mut(at + j) {
                *o = *y;
            }
        }
    }
}

impl<T: Real> Pack for T {
    type Scalar = T;
    #[inline(always)]
    fn gather(mut f: impl FnMut(usize) -> T) -> T {
        f(0)
    }
    #[inline(always)]
    fn lane(self, _: usize) -> T {
        self
    }
    type Array = [T; 1];
    #[inline(always)]
    fn lanes(self) -> [T; 1] {
        [self]
    }
}

mod branch;
#[cfg(feature = "simd")]
mod simd;

pub(crate) use branch::{branch, Select};
