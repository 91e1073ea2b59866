//! The runtime's result structs of matrices (the contact and impulse derivatives) seen as the
//! run of their entries, field after field: what the batches unpack from SIMD lanes in one
//! transposition, as they unpack a matrix ([`crate::batch::scatter_contact_derivatives`]).
//! Copied field by field through a buffer, each row's wide reload of the transposition's
//! narrow stores stalled, and the scatter took a fifth of anymal's contact-derivative batch.
#![allow(unsafe_code)]

use crate::kkt::{ContactDynamicsDerivatives, ImpulseDynamicsDerivatives};

/// A `#[repr(C)]` struct whose fields are all arrays (or arrays of arrays) of `T`, `LEN`
/// entries in all.
///
/// # Safety
///
/// The implementor must be `#[repr(C)]` with only fields of type `[[T; C]; R]` (any `R`,
/// `C`), whose entries number `LEN`: it then has no padding (every field has `T`'s
/// alignment and a multiple of its size) and is laid out as `[T; LEN]`.
pub(crate) unsafe trait Entries<T>: Sized {
    /// The number of entries.
    const LEN: usize;
}

// SAFETY: `#[repr(C)]`, six fields of `[[T; NV]; _]`: three of `NV` rows, three of `K`.
unsafe impl<T, const NV: usize, const K: usize> Entries<T>
    for ContactDynamicsDerivatives<T, NV, K>
{
    const LEN: usize = 3 * NV * NV + 3 * K * NV;
}

// SAFETY: `#[repr(C)]`, four fields of `[[T; NV]; _]`: two of `NV` rows, two of `K`.
unsafe impl<T, const NV: usize, const K: usize> Entries<T>
    for ImpulseDynamicsDerivatives<T, NV, K>
{
    const LEN: usize = 2 * NV * NV + 2 * K * NV;
}

/// The entries of `d`, field after field, each field row by row.
pub(crate) fn of<T, D: Entries<T>>(d: &D) -> &[T] {
    const { assert!(core::mem::size_of::<D>() == D::LEN * core::mem::size_of::<T>()) };
    // SAFETY: `D` is laid out as `[T; LEN]` (`Entries`' contract, its size checked above), and
    // the slice borrows `d`.
    unsafe { core::slice::from_raw_parts((d as *const D).cast::<T>(), D::LEN) }
}

/// The entries of every element of `d`, one element after another.
pub(crate) fn of_each_mut<T, D: Entries<T>>(d: &mut [D]) -> &mut [T] {
    const { assert!(core::mem::size_of::<D>() == D::LEN * core::mem::size_of::<T>()) };
    // SAFETY: each `D` is laid out as `[T; LEN]` and a slice's elements are consecutive, so
    // `d` is `d.len() * LEN` consecutive `T`s, borrowed mutably for the slice's lifetime; any
    // value written into a `T` leaves every `D` valid.
    unsafe { core::slice::from_raw_parts_mut(d.as_mut_ptr().cast::<T>(), d.len() * D::LEN) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_entries_are_the_fields_in_order() {
        let mut d = ImpulseDynamicsDerivatives::<f64, 2, 1>::nan();
        d.dv_dq = [[1.0, 2.0], [3.0, 4.0]];
        d.dv_dv = [[5.0, 6.0], [7.0, 8.0]];
        d.dimpulse_dq = [[9.0, 10.0]];
        d.dimpulse_dv = [[11.0, 12.0]];
        let want: [f64; 12] = core::array::from_fn(|i| i as f64 + 1.0);
        assert_eq!(of(&d), &want[..]);
        let mut two = [d, d];
        of_each_mut(&mut two)[12] = -1.0;
        assert_eq!((two[1].dv_dq[0][0], two[0].dv_dq[0][0]), (-1.0, 1.0));
        let c = ContactDynamicsDerivatives::<f32, 3, 2>::nan();
        assert_eq!(of(&c).len(), 3 * 9 + 3 * 6);
    }
}
