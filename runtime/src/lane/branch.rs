//! Values chosen lane by lane where scalar code would branch on a value: [`branch`] evaluates
//! one side when every lane takes it (always, for a scalar) and both, merged by
//! [`Lane::select`], when the lanes disagree.

use super::Lane;

/// A value made of lanes of `T` that [`Lane::select`] merges entry by entry.
pub(crate) trait Select<T: Lane>: Sized {
    /// `yes` in the lanes of `mask`, `no` in the others, in every entry.
    fn select(mask: T::Mask, yes: Self, no: Self) -> Self;
}

impl<T: Lane> Select<T> for T {
    #[inline(always)]
    fn select(mask: T::Mask, yes: T, no: T) -> T {
        T::select(mask, yes, no)
    }
}

impl<T: Lane, const N: usize> Select<T> for [T; N] {
    #[inline(always)]
    fn select(mask: T::Mask, yes: Self, no: Self) -> Self {
        core::array::from_fn(|i| T::select(mask, yes[i], no[i]))
    }
}

/// `yes()` in the lanes of `mask`, `no()` in the others: only `yes()` when every lane is set,
/// only `no()` when none is (a scalar's `if`), both merged otherwise. A lane whose comparison
/// met a NaN is not set, as a scalar's `<` is false there.
#[inline(always)]
pub(crate) fn branch<T: Lane, X: Select<T>>(
    mask: T::Mask,
    yes: impl FnOnce() -> X,
    no: impl FnOnce() -> X,
) -> X {
    if T::all(mask) {
        yes()
    } else if !T::any(mask) {
        no()
    } else {
        X::select(mask, yes(), no())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_scalar_evaluates_one_side() {
        let calls = core::cell::Cell::new(0);
        let count = |x: f64| {
            calls.set(calls.get() + 1);
            x
        };
        let x: f64 = branch::<f64, _>(true, || 1.0, || count(2.0));
        let y: [f64; 2] = branch::<f64, _>(false, || [count(1.0); 2], || [2.0; 2]);
        assert_eq!((x, y, calls.get()), (1.0, [2.0; 2], 0));
    }

    #[cfg(feature = "simd")]
    #[test]
    fn lanes_that_disagree_take_each_their_side() {
        use wide::f64x4;
        let mask = f64x4::from([0.0, 2.0, f64::NAN, 3.0]).gt(f64x4::splat(1.0));
        let x = branch::<f64x4, _>(mask, || f64x4::splat(1.0), || f64x4::splat(-1.0));
        assert_eq!(x.to_array(), [-1.0, 1.0, -1.0, 1.0]);
    }
}
