//! Cache hints for the batch runner: fetch the lines a call is about to write.
//!
//! A batch call writes each vector of states' results in one burst (anymal's mass matrix in
//! `f64x4`: 324 stores, 10 kB, to four states' matrices). Where the results lie beyond the
//! core's L2 cache, every line written must first be fetched, and a burst of fetches waits on
//! the processor's few outstanding misses: on an Intel Xeon (Emerald Rapids) the `f64x4` batch
//! of 1024 anymal mass matrices ran slower than the scalar code, and fetching the next vector's
//! lines while the current one computes took 11 to 31 % off it in alternated rounds
//! (`docs/performance-log.md`, 29 November, late evening). On other targets the hint is
//! nothing.
//!
//! This module holds one of the crate's `unsafe` blocks: `_mm_prefetch` takes a raw pointer.
//! A prefetch instruction never faults and changes no memory or register the program can
//! see (an address that is not mapped is dropped), so any pointer value is sound; these are
//! the lines of a slice the caller holds anyway.

/// Bytes per cache line (x86-64).
const LINE: usize = 64;

/// The lines of `bytes` bytes from address `at`: how far the first line starts before `at`,
/// and how many lines there are (none for no bytes).
fn span(at: usize, bytes: usize) -> (usize, usize) {
    if bytes == 0 {
        return (0, 0);
    }
    let back = at % LINE;
    (back, (back + bytes).div_ceil(LINE))
}

/// Asks the processor to bring every cache line of `items` into its L1 data cache (where
/// [`hint`] is nothing, the loop compiles to nothing).
#[inline(always)]
pub(crate) fn lines_of<A>(items: &[A]) {
    let start = items.as_ptr().cast::<i8>();
    let (back, lines) = span(start as usize, core::mem::size_of_val(items));
    let first = start.wrapping_sub(back);
    for k in 0..lines {
        hint(first.wrapping_add(k * LINE));
    }
}

/// One line's prefetch (`prefetcht0`, SSE: every x86-64 processor).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn hint(line: *const i8) {
    use core::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
    // SAFETY: a prefetch never faults and has no effect the program can observe (module
    // documentation); the address is only a hint.
    #[allow(unsafe_code)]
    unsafe {
        _mm_prefetch::<_MM_HINT_T0>(line);
    }
}

/// Elsewhere no hint (stable Rust has no prefetch intrinsic for the other targets).
#[cfg(not(target_arch = "x86_64"))]
#[inline(always)]
fn hint(_line: *const i8) {}

#[cfg(test)]
mod tests {
    use super::{lines_of, span};

    #[test]
    fn every_line_from_the_first_byte_to_the_last() {
        assert_eq!(span(0, 0), (0, 0));
        assert_eq!(span(4096, 64), (0, 1));
        assert_eq!(span(4096 + 63, 2), (63, 2));
        // One of anymal's mass matrices at an allocation's usual 16 bytes past a line.
        assert_eq!(span(4096 + 16, 2592), (16, 41));
        assert_eq!(span(4096 + 48, 2592), (48, 42));
    }

    #[test]
    fn hints_leave_the_data_alone() {
        let data: [[f64; 18]; 5] = core::array::from_fn(|i| [i as f64; 18]);
        lines_of(&data[..]);
        lines_of(&data[1..3]);
        lines_of::<u8>(&[]);
        assert!(data
            .iter()
            .enumerate()
            .all(|(i, r)| r.iter().all(|x| *x == i as f64)));
    }
}
