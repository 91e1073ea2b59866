//! Large results written where the caller keeps them, not built in a local and copied out.
//!
//! Rust returns a large value through a pointer to the caller's storage, but a function that
//! fills its result through `&mut` (as generated code split into blocks does) builds it in a
//! local first and copies it out at the end: a derivative of a 50-DoF robot (40 kB) then takes
//! twice its size of stack. [`build`] hands the filling function a [`Slot`] (the caller's
//! storage, not yet initialized) instead: when that function is not inlined, the compiler
//! passes the caller's storage through, with no local copy and no second zero fill.
//!
//! A [`Slot`] can only be filled with zeros first ([`Slot::fill`]), which returns the
//! [`Filled`] proof that [`build`] requires back, so safe code cannot observe uninitialized
//! memory.
//!
//! ```
//! use eomgen_runtime::place::{build, Filled, Slot};
//!
//! #[inline(never)]
//! fn squares<'b>(slot: Slot<'b, [[f64; 3]; 3]>) -> Filled<'b> {
//!     let (m, filled) = slot.fill();
//!     for (i, row) in m.iter_mut().enumerate() {
//!         row[i] = (i * i) as f64;
//!     }
//!     filled
//! }
//!
//! let m = build(squares);
//! assert_eq!(m, [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 4.0]]);
//! ```
//!
//! A proof fits only its own slot, so a filling function cannot skip the fill by returning
//! another's:
//!
//! ```compile_fail
//! use eomgen_runtime::place::{Filled, Slot};
//! fn steal<'a, 'b>(slot: Slot<'a, [f64; 1]>) -> Filled<'b> {
//!     slot.fill().1
//! }
//! ```
#![allow(unsafe_code)]

use core::marker::PhantomData;
use core::mem::MaybeUninit;
use core::ptr::addr_of_mut;

use crate::kkt::{ContactDynamicsDerivatives, ImpulseDynamicsDerivatives};
use crate::Lane;

/// An invariant lifetime: `'b` names one call of [`build`] and no other.
type Brand<'b> = PhantomData<fn(&'b ()) -> &'b ()>;

/// The caller's storage for a result of type `R`, not yet initialized; [`Slot::fill`] gives
/// access to it. Only [`build`] makes one.
pub struct Slot<'b, R> {
    value: &'b mut MaybeUninit<R>,
    brand: Brand<'b>,
}

/// Proof that the [`Slot`] of the same `'b` was filled: what a filling function returns.
pub struct Filled<'b> {
    brand: Brand<'b>,
}

impl<'b, R: Zeroed> Slot<'b, R> {
    /// Fills the storage with zeros, in place, and gives it back initialized, with the proof
    /// that [`build`] needs.
    #[inline]
    pub fn fill(self) -> (&'b mut R, Filled<'b>) {
        let value = R::zero_in(self.value);
        (value, Filled { brand: self.brand })
    }
}

/// The result `fill` writes into the caller's storage.
///
/// `fill` receives the storage as a [`Slot`] and must return the [`Filled`] of that slot,
/// which only [`Slot::fill`] gives; mark `fill` (or the function it calls with the slot)
/// `#[inline(never)]` so that the storage is the caller's and is not copied.
#[inline(always)]
pub fn build<R: Zeroed>(fill: impl for<'b> FnOnce(Slot<'b, R>) -> Filled<'b>) -> R {
    let mut value = MaybeUninit::uninit();
    let _filled = fill(Slot {
        value: &mut value,
        brand: PhantomData,
    });
    // SAFETY: `fill` returned a `Filled<'b>` for a lifetime `'b` of its own (the closure is
    // generic over it, and `Brand` is invariant), which only `Slot::fill` on the slot made
    // above creates; `Slot::fill` initialized every byte of `value` through `Zeroed::zero_in`.
    unsafe { value.assume_init() }
}

/// The storage of a result of `K` matrices of `R x C` entries, to be written entry by entry
/// in order, without zeros first ([`Outputs::entries`]): what a function that writes every
/// entry of its result, row by row through each matrix in turn, takes instead of a zeroed
/// [`Slot`]. Made by [`Slot::outputs`] (the caller's uninitialized storage) or [`refill`]
/// (matrices already initialized).
///
/// ```
/// use eomgen_runtime::place::{build, Filled, Outputs, Slot};
///
/// #[inline(never)]
/// fn counting<'b>(out: Outputs<'b, f64, 2, 1, 2>) -> Filled<'b> {
///     let mut e = out.entries();
///     for k in 0..3 {
///         e.put(k as f64 + 1.0);
///     }
///     e.finish() // the entry not written is zero
/// }
///
/// let (a, b) = build(|slot: Slot<'_, ([[f64; 2]; 1], [[f64; 2]; 1])>| counting(slot.outputs()));
/// assert_eq!((a, b), ([[1.0, 2.0]], [[3.0, 0.0]]));
/// ```
pub struct Outputs<'b, T, const K: usize, const R: usize, const C: usize> {
    /// The first entry of each matrix.
    parts: [*mut T; K],
    brand: Brand<'b>,
}

/// The entries of [`Outputs`] being written, the next one at `next` (counted through all
/// matrices).
pub struct Entries<'b, T, const K: usize, const R: usize, const C: usize> {
    parts: [*mut T; K],
    next: usize,
    brand: Brand<'b>,
}

impl<'b, T: Lane, const K: usize, const R: usize, const C: usize> Outputs<'b, T, K, R, C> {
    /// Starts at the first entry. Called in the function that writes the entries (inlined), the
    /// position of every entry is known to the compiler: each [`Entries::put`] is one store.
    #[inline(always)]
    pub fn entries(self) -> Entries<'b, T, K, R, C> {
        Entries {
            parts: self.parts,
            next: 0,
            brand: self.brand,
        }
    }
}

impl<'b, T: Lane, const K: usize, const R: usize, const C: usize> Entries<'b, T, K, R, C> {
    /// Writes the next entry (row by row, matrix after matrix); past the last, nothing.
    #[inline(always)]
    pub fn put(&mut self, x: T) {
        let len = R * C;
        if len == 0 || self.next >= K * len {
            return;
        }
        let (k, i) = (self.next / len, self.next % len);
        // SAFETY: `parts[k]` is the first of the `R * C` consecutive `T`s of matrix `k`
        // (arrays have no padding), in storage borrowed mutably for `'b` (`Slot::outputs`,
        // `refill`); `i < R * C`. Writing a value never de-initializes anything.
        unsafe { self.parts[k].add(i).write(x) };
        self.next += 1;
    }

    /// Zeros over the entries not written yet, and the proof that the storage is filled.
    #[inline(always)]
    pub fn finish(mut self) -> Filled<'b> {
        while self.next < K * R * C {
            self.put(T::zero());
        }
        Filled { brand: self.brand }
    }
}

impl<'b, T: Lane, const R: usize, const C: usize> Slot<'b, [[T; C]; R]> {
    /// The storage as [`Outputs`] of one matrix, to be written entry by entry.
    #[inline(always)]
    pub fn outputs(self) -> Outputs<'b, T, 1, R, C> {
        Outputs {
            parts: [self.value.as_mut_ptr().cast::<T>()],
            brand: self.brand,
        }
    }
}

impl<'b, T: Lane, const R: usize, const C: usize> Slot<'b, ([[T; C]; R], [[T; C]; R])> {
    /// The storage as [`Outputs`] of two matrices, the first written first.
    #[inline(always)]
    pub fn outputs(self) -> Outputs<'b, T, 2, R, C> {
        let p = self.value.as_mut_ptr();
        // SAFETY (both): fields of the tuple `p` points to, borrowed mutably for `'b`.
        let parts = unsafe {
            [
                addr_of_mut!((*p).0).cast::<T>(),
                addr_of_mut!((*p).1).cast::<T>(),
            ]
        };
        Outputs {
            parts,
            brand: self.brand,
        }
    }
}

impl<'b, T: Lane, const R: usize, const C: usize>
    Slot<'b, ([[T; C]; R], [[T; C]; R], [[T; C]; R])>
{
    /// The storage as [`Outputs`] of three matrices, in order.
    #[inline(always)]
    pub fn outputs(self) -> Outputs<'b, T, 3, R, C> {
        let p = self.value.as_mut_ptr();
        // SAFETY (all): fields of the tuple `p` points to, borrowed mutably for `'b`.
        let parts = unsafe {
            [
                addr_of_mut!((*p).0).cast::<T>(),
                addr_of_mut!((*p).1).cast::<T>(),
                addr_of_mut!((*p).2).cast::<T>(),
            ]
        };
        Outputs {
            parts,
            brand: self.brand,
        }
    }
}

/// Lends `K` matrices that hold values already (fields of a larger result, say) to `fill` as
/// [`Outputs`], which writes them entry by entry as it would write a [`Slot`]'s storage.
#[inline(always)]
pub fn refill<T: Lane, const K: usize, const R: usize, const C: usize>(
    matrices: [&mut [[T; C]; R]; K],
    fill: impl for<'b> FnOnce(Outputs<'b, T, K, R, C>) -> Filled<'b>,
) {
    let parts = matrices.map(|m| m.as_mut_ptr().cast::<T>());
    let _filled = fill(Outputs {
        parts,
        brand: PhantomData,
    });
}

mod sealed {
    pub trait Sealed {}
}

/// Results [`build`] can fill: arrays and matrices of a [`Lane`], pairs and triples of them,
/// and the derivatives of contact and impulse dynamics. Sealed: [`build`] relies on `zero_in`
/// initializing everything.
pub trait Zeroed: sealed::Sealed + Sized {
    /// Writes zeros over all of `slot` and returns it initialized.
    fn zero_in(slot: &mut MaybeUninit<Self>) -> &mut Self;
}

impl<T: Lane, const N: usize> sealed::Sealed for [T; N] {}
impl<T: Lane, const N: usize> Zeroed for [T; N] {
    #[inline]
    fn zero_in(slot: &mut MaybeUninit<Self>) -> &mut Self {
        let p = slot.as_mut_ptr().cast::<T>();
        for k in 0..N {
            // SAFETY: `[T; N]` is N consecutive `T`s, so `p.add(k)` stays inside the slot.
            unsafe { p.add(k).write(T::zero()) };
        }
        // SAFETY: every element was written above.
        unsafe { slot.assume_init_mut() }
    }
}

impl<T: Lane, const R: usize, const C: usize> sealed::Sealed for [[T; C]; R] {}
impl<T: Lane, const R: usize, const C: usize> Zeroed for [[T; C]; R] {
    #[inline]
    fn zero_in(slot: &mut MaybeUninit<Self>) -> &mut Self {
        let p = slot.as_mut_ptr().cast::<T>();
        for k in 0..R * C {
            // SAFETY: `[[T; C]; R]` is R * C consecutive `T`s (arrays have no padding).
            unsafe { p.add(k).write(T::zero()) };
        }
        // SAFETY: every element was written above.
        unsafe { slot.assume_init_mut() }
    }
}

/// Field `$f` of the tuple behind `$p` (a `*mut` tuple) as an uninitialized slot.
macro_rules! field_slot {
    ($p:expr, $f:tt) => {
        // SAFETY: the field lies inside the tuple `$p` points to, which is borrowed mutably
        // for as long as the slot lives; `MaybeUninit<X>` has the layout of `X`.
        unsafe { as_slot(addr_of_mut!((*$p).$f)) }
    };
}

/// The place `p` points to as an uninitialized slot of its type.
///
/// # Safety
/// `p` points into storage that is mutably borrowed for `'a` and nothing else accesses.
unsafe fn as_slot<'a, X>(p: *mut X) -> &'a mut MaybeUninit<X> {
    // SAFETY: the caller's; `MaybeUninit<X>` has the layout of `X`.
    unsafe { &mut *p.cast::<MaybeUninit<X>>() }
}

impl<A: Zeroed, B: Zeroed> sealed::Sealed for (A, B) {}
impl<A: Zeroed, B: Zeroed> Zeroed for (A, B) {
    #[inline]
    fn zero_in(slot: &mut MaybeUninit<Self>) -> &mut Self {
        let p = slot.as_mut_ptr();
        A::zero_in(field_slot!(p, 0));
        B::zero_in(field_slot!(p, 1));
        // SAFETY: both fields were initialized above (a pair of these types has no padding
        // that needs initializing: padding bytes are never read as values).
        unsafe { slot.assume_init_mut() }
    }
}

impl<A: Zeroed, B: Zeroed, C: Zeroed> sealed::Sealed for (A, B, C) {}
impl<A: Zeroed, B: Zeroed, C: Zeroed> Zeroed for (A, B, C) {
    #[inline]
    fn zero_in(slot: &mut MaybeUninit<Self>) -> &mut Self {
        let p = slot.as_mut_ptr();
        A::zero_in(field_slot!(p, 0));
        B::zero_in(field_slot!(p, 1));
        C::zero_in(field_slot!(p, 2));
        // SAFETY: every field was initialized above.
        unsafe { slot.assume_init_mut() }
    }
}

/// `Zeroed` for a struct of `Zeroed` fields, field by field.
macro_rules! zeroed_struct {
    ($name:ident { $($field:ident),* }) => {
        impl<T: Lane, const NV: usize, const K: usize> sealed::Sealed for $name<T, NV, K> {}
        impl<T: Lane, const NV: usize, const K: usize> Zeroed for $name<T, NV, K> {
            #[inline]
            fn zero_in(slot: &mut MaybeUninit<Self>) -> &mut Self {
                let p = slot.as_mut_ptr();
                $(Zeroed::zero_in(field_slot!(p, $field));)*
                // SAFETY: every field was initialized above.
                unsafe { slot.assume_init_mut() }
            }
        }
    };
}

zeroed_struct!(ContactDynamicsDerivatives {
    da_dq,
    da_dv,
    da_dtau,
    df_dq,
    df_dv,
    df_dtau
});
zeroed_struct!(ImpulseDynamicsDerivatives {
    dv_dq,
    dv_dv,
    dimpulse_dq,
    dimpulse_dv
});

#[cfg(test)]
mod tests {
    use super::*;

    #[inline(never)]
    fn pair<'b>(slot: Slot<'b, ([f64; 2], [[f32; 2]; 3])>) -> Filled<'b> {
        let ((v, m), filled) = slot.fill();
        v[1] = 2.0;
        m[2][0] = 5.0;
        filled
    }

    #[test]
    fn a_pair_is_zero_where_not_written() {
        let (v, m) = build(pair);
        assert_eq!(v, [0.0, 2.0]);
        assert_eq!(m, [[0.0, 0.0], [0.0, 0.0], [5.0, 0.0]]);
    }

    #[inline(never)]
    fn numbered<'b>(out: Outputs<'b, f32, 2, 2, 3>, count: usize) -> Filled<'b> {
        let mut e = out.entries();
        for k in 0..count {
            e.put(k as f32 + 1.0);
        }
        e.finish()
    }

    #[test]
    fn outputs_are_written_in_order_and_the_rest_is_zero() {
        type Pair = ([[f32; 3]; 2], [[f32; 3]; 2]);
        for count in [0, 5, 12, 20] {
            let (a, b) = build(|slot: Slot<'_, Pair>| numbered(slot.outputs(), count));
            let flat = a.iter().chain(&b).flatten();
            for (k, &x) in flat.enumerate() {
                let want = if k < count { k as f32 + 1.0 } else { 0.0 };
                assert_eq!(x, want, "entry {k} of {count} put");
            }
        }
    }

    #[test]
    fn refill_writes_matrices_that_hold_values() {
        let (mut a, mut b) = ([[9.0f32; 3]; 2], [[9.0f32; 3]; 2]);
        refill([&mut a, &mut b], |out| numbered(out, 7));
        assert_eq!(a, [[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]);
        assert_eq!(b, [[7.0, 0.0, 0.0], [0.0, 0.0, 0.0]]);
        let mut m = [[0.5f64; 2]; 1];
        refill([&mut m], |out| {
            let mut e = out.entries();
            e.put(1.5);
            e.finish()
        });
        assert_eq!(m, [[1.5, 0.0]]);
        type Three = ([[f64; 1]; 1], [[f64; 1]; 1], [[f64; 1]; 1]);
        let t = build(|slot: Slot<'_, Three>| {
            let mut e = slot.outputs().entries();
            e.put(1.0);
            e.put(2.0);
            e.put(3.0);
            e.put(4.0); // past the end: nothing
            e.finish()
        });
        assert_eq!(t, ([[1.0]], [[2.0]], [[3.0]]));
    }

    type Triple = ([f64; 1], [f64; 2], [[f64; 1]; 1]);

    #[test]
    fn a_triple_is_filled_in_place() {
        let (a, b, c) = build(|slot: Slot<'_, Triple>| {
            let ((a, b, c), filled) = slot.fill();
            a[0] = 1.0;
            b[1] = 2.0;
            c[0][0] = 3.0;
            filled
        });
        assert_eq!((a, b, c), ([1.0], [0.0, 2.0], [[3.0]]));
    }
}
