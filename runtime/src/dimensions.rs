//! The sizes of a generated robot, whatever its scalar type.

/// The number of coordinates of a generated robot, for every scalar type `T`.
///
/// Generated types also have `DOF` (and, with a floating base, `NQ` and `NV`) as inherent
/// constants of their `f64` form, so that `Panda::DOF` needs no type parameter; this trait
/// gives the same constants for `Panda::<f32>::DOF` and in code generic over the scalar
/// (`Panda::<T>::DOF`). It is in the [prelude](crate::prelude).
///
/// ```
/// use eomgen_runtime::prelude::*;
///
/// // What eomgen generates for a robot of 6 joints (hand-written here).
/// pub struct Arm<T = f64>(core::marker::PhantomData<T>);
/// impl Arm<f64> {
///     pub const DOF: usize = 6;
/// }
/// impl<T: Real> Dimensions for Arm<T> {
///     const DOF: usize = 6;
///     const NQ: usize = 6;
///     const NV: usize = 6;
/// }
///
/// let q = [0.0_f64; Arm::DOF];
/// let q32 = [0.0_f32; Arm::<f32>::DOF];
/// fn zeros<T: Real>() -> usize {
///     Arm::<T>::NV
/// }
/// assert_eq!((q.len(), q32.len(), zeros::<f32>()), (6, 6, 6));
/// ```
pub trait Dimensions {
    /// Number of joint coordinates (velocity coordinates with a floating base).
    const DOF: usize;
    /// Number of position coordinates: `DOF` for a fixed base, 7 + joints with a floating
    /// base (position and unit quaternion).
    const NQ: usize;
    /// Number of velocity coordinates: `DOF`.
    const NV: usize;
}
