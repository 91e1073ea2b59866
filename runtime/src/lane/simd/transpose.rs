//! [`Pack::pack`](super::Pack::pack) and [`Pack::unpack`](super::Pack::unpack) of `f64x4`
//! and `f32x8` by in-register transpositions of square blocks.
//!
//! A batch holds states one after another (`[[f64; N]]`); a vector holds one entry of `LANES`
//! states. Moving entry by entry between the two costs a load or a store per lane and entry
//! and, done through a lane index, a round trip through memory for each (an 18 x 18 `f32x8`
//! mass matrix spent three quarters of its batch time there). Here `W` consecutive entries of
//! `W` states (`W` = `LANES`) are `W` vectors: `W` loads of a run of each state (or of `W`
//! result vectors), a transposition by shuffles (8 for `f64x4`, 24 for `f32x8`), and `W`
//! stores. Entries past the last whole block go lane by lane. Without AVX the same blocks are
//! transposed lane by lane (the code path the tests exercise on every target).

use wide::{f32x8, f64x4};

/// `f` of each element of `a`, by a plain loop that is always inlined (array `map` is inlined
/// or not as the optimizer's budget falls: see [`pack_blocks`]).
#[inline(always)]
fn each_of<A: Copy, B: Copy + Default, const W: usize>(a: [A; W], f: impl Fn(A) -> B) -> [B; W] {
    let mut out = [B::default(); W];
    for (o, x) in out.iter_mut().zip(a) {
        *o = f(x);
    }
    out
}

/// Packs `states` (the whole runs of `v.len()` scalars it holds, up to `W`) into `v`: `W`
/// entries at a time by `transpose` (of `W` rows of `W` scalars, one per state, into the `W`
/// vectors of those entries), the rest by `new` (one vector from its `W` lanes). Lanes of
/// missing states are zero.
#[inline(always)]
fn pack_blocks<V: Copy, S: Copy + Default, const W: usize>(
    states: &[S],
    v: &mut [V],
    transpose: impl Fn(&[[S; W]; W]) -> [V; W],
    new: impl Fn([S; W]) -> V,
) {
    // Plain loops, not `core::array::from_fn`: it is inlined or not as the optimizer's budget
    // falls, and where it was not, each block was built on the stack by 32-byte stores that
    // the transposition's 64-byte loads could not take from the store buffer (the panda's
    // `f32x8` inverse dynamics batch 1.56 times as long).
    let n = v.len();
    let mut rows: [&[S]; W] = [&[]; W];
    for (l, row) in rows.iter_mut().enumerate() {
        *row = states.get(l * n..(l + 1) * n).unwrap_or_default();
    }
    let mut blocks = v.chunks_exact_mut(W);
    for (k, block) in (&mut blocks).enumerate() {
        let mut m = [[S::default(); W]; W];
        for (run, row) in m.iter_mut().zip(&rows) {
            if let Some(Ok(r)) = row.get(k * W..(k + 1) * W).map(<&[S; W]>::try_from) {
                *run = *r;
            }
        }
        for (o, x) in block.iter_mut().zip(transpose(&m)) {
            *o = x;
        }
    }
    let rest = blocks.into_remainder();
    let k = n - rest.len();
    for (j, o) in rest.iter_mut().enumerate() {
        let mut lanes = [S::default(); W];
        for (x, row) in lanes.iter_mut().zip(&rows) {
            *x = row.get(k + j).copied().unwrap_or_default();
        }
        *o = new(lanes);
    }
}

/// Unpacks `v` into the whole runs of `v.len()` scalars of `states` (up to `W`): `W` entries
/// at a time by `transpose` (of `W` vectors into `W` rows, one per state), the rest by `lanes`.
#[inline(always)]
fn unpack_blocks<V: Copy, S: Copy, const W: usize>(
    v: &[V],
    states: &mut [S],
    transpose: impl Fn(&[V; W]) -> [[S; W]; W],
    lanes: impl Fn(V) -> [S; W],
) {
    let n = v.len();
    if n == 0 {
        return;
    }
    // For four lanes, four blocks transposed before any is stored, then each state's four
    // runs stored one after another (a contiguous run of 4 W scalars per state): storing
    // each block's W runs to W states in turn interleaved W output streams (anymal's `f64x4`
    // mass matrix batch: 13 % more states per second). Eight lanes keep one block at a time:
    // four blocks of 8 x 8 do not fit in the registers (13 % fewer states per second).
    let grouped = if W <= 4 { v.len() / (4 * W) * 4 * W } else { 0 };
    let (grouped, tail) = v.split_at(grouped);
    for (g, group) in grouped.chunks_exact(4 * W).enumerate() {
        let mut blocks = group
            .chunks_exact(W)
            .filter_map(|b| <&[V; W]>::try_from(b).ok())
            .map(&transpose);
        let (Some(r0), Some(r1), Some(r2), Some(r3)) =
            (blocks.next(), blocks.next(), blocks.next(), blocks.next())
        else {
            continue;
        };
        let rows = [r0, r1, r2, r3];
        for (l, state) in states.chunks_exact_mut(n).enumerate().take(W) {
            for (b, rows) in rows.iter().enumerate() {
                let at = (4 * g + b) * W;
                if let Some(Ok(run)) = state.get_mut(at..at + W).map(<&mut [S; W]>::try_from) {
                    *run = rows[l];
                }
            }
        }
    }
    let done = v.len() - tail.len();
    let blocks = tail.chunks_exact(W);
    let rest = blocks.remainder();
    for (k, block) in blocks.enumerate() {
        let Ok(block) = <&[V; W]>::try_from(block) else {
            continue;
        };
        let rows = transpose(block);
        for (state, row) in states.chunks_exact_mut(n).zip(rows) {
            let run = state.get_mut(done + k * W..done + (k + 1) * W);
            if let Some(Ok(run)) = run.map(<&mut [S; W]>::try_from) {
                *run = row;
            }
        }
    }
    let k = n - rest.len();
    for (j, x) in rest.iter().enumerate() {
        for (state, y) in states.chunks_exact_mut(n).zip(lanes(*x)) {
            if let Some(o) = state.get_mut(k + j) {
                *o = y;
            }
        }
    }
}

/// Unpacks the run `v` of entries `at..at + v.len()` of the `R x C` matrices of the first
/// `W` states of `states`: `W` entries at a time by `transpose`, the rest by `lanes`
/// ([`Pack::unpack_run`](super::Pack::unpack_run)). A whole vector of states, the usual case,
/// goes through an array of `W` states, whose stores need no test of how many states there
/// are (such tests were a sixth of anymal's `f64x4` mass matrix batch); fewer states, lane by
/// lane.
#[inline(always)]
fn unpack_run_blocks<V: Copy, S: Copy, const W: usize, const R: usize, const C: usize>(
    (v, states, at): (&[V], &mut [[[S; C]; R]], usize),
    transpose: impl Fn(&[V; W]) -> [[S; W]; W],
    lanes: impl Fn(V) -> [S; W],
) {
    let Some(Ok(states)) = states.get_mut(..W).map(<&mut [[[S; C]; R]; W]>::try_from) else {
        return unpack_run_lanes(v, states, at, lanes);
    };
    // The entries past the matrix's end are dropped.
    let v = v.get(..(R * C).saturating_sub(at)).unwrap_or(v);
    let blocks = v.chunks_exact(W);
    let rest = blocks.remainder();
    for (k, block) in blocks.enumerate() {
        let Ok(block) = <&[V; W]>::try_from(block) else {
            continue;
        };
        let from = at + k * W;
        for (state, row) in states.iter_mut().zip(transpose(block)) {
            let run = state.as_flattened_mut().get_mut(from..from + W);
            if let Some(Ok(run)) = run.map(<&mut [S; W]>::try_from) {
                *run = row;
            }
        }
    }
    unpack_run_lanes(rest, states, at + v.len() - rest.len(), lanes);
}

/// The run `v` at `at` of each state of `states` lane by lane (up to `W` states). The same
/// as the runtime's `lane::unpack_run_each`, but on `lanes`' arrays: calling that one instead,
/// anymal's `f32x8` mass matrix batch compiled to 13,155 instructions against 9,969 and gave
/// 21.3 to 22.4 million states per second against 23.4 (and out of line, behind `#[cold]`,
/// the spills around the calls made both batches a third slower).
#[inline(always)]
fn unpack_run_lanes<V: Copy, S: Copy, const W: usize, const R: usize, const C: usize>(
    v: &[V],
    states: &mut [[[S; C]; R]],
    at: usize,
    lanes: impl Fn(V) -> [S; W],
) {
    for (j, x) in v.iter().enumerate() {
        for (state, y) in states.iter_mut().zip(lanes(*x)) {
            if let Some(o) = state.as_flattened_mut().get_mut(at + j) {
                *o = y;
            }
        }
    }
}

/// The 4 x 4 transposition: lane `l` of vector `i` to lane `i` of vector `l` (4 unpacks, 4
/// lane permutations).
#[cfg(target_feature = "avx")]
#[inline(always)]
fn transpose4(v: &[f64x4; 4]) -> [f64x4; 4] {
    use safe_arch::{m256d, permute2z_m256d, unpack_hi_m256d, unpack_lo_m256d};
    let m = each_of(*v, |x| m256d::from_array(x.to_array()));
    // [a0 b0 a2 b2], [a1 b1 a3 b3], [c0 d0 c2 d2], [c1 d1 c3 d3]
    let (ab0, ab1) = (unpack_lo_m256d(m[0], m[1]), unpack_hi_m256d(m[0], m[1]));
    let (cd0, cd1) = (unpack_lo_m256d(m[2], m[3]), unpack_hi_m256d(m[2], m[3]));
    let t = [
        permute2z_m256d::<0x20>(ab0, cd0),
        permute2z_m256d::<0x20>(ab1, cd1),
        permute2z_m256d::<0x31>(ab0, cd0),
        permute2z_m256d::<0x31>(ab1, cd1),
    ];
    each_of(t, |x| f64x4::new(x.to_array()))
}

/// The 4 x 4 transposition, lane by lane (no AVX: `f64x4` is two halves or an array).
#[cfg(not(target_feature = "avx"))]
#[inline(always)]
fn transpose4(v: &[f64x4; 4]) -> [f64x4; 4] {
    let a = v.map(f64x4::to_array);
    core::array::from_fn(|l| f64x4::new([a[0][l], a[1][l], a[2][l], a[3][l]]))
}

/// [`Pack::pack`](super::Pack::pack) of `f64x4`.
#[inline(always)]
pub(super) fn pack_f64x4(states: &[f64], v: &mut [f64x4]) {
    pack_blocks(
        states,
        v,
        |m| transpose4(&each_of(*m, f64x4::new)),
        f64x4::new,
    );
}

/// [`Pack::unpack`](super::Pack::unpack) of `f64x4`.
#[inline(always)]
pub(super) fn unpack_f64x4(v: &[f64x4], states: &mut [f64]) {
    unpack_blocks(
        v,
        states,
        |b| each_of(transpose4(b), f64x4::to_array),
        f64x4::to_array,
    );
}

/// [`Pack::unpack_run`](super::Pack::unpack_run) of `f64x4`.
#[inline(always)]
pub(super) fn unpack_run_f64x4<const R: usize, const C: usize>(
    v: &[f64x4],
    states: &mut [[[f64; C]; R]],
    at: usize,
) {
    unpack_run_blocks(
        (v, states, at),
        |b| each_of(transpose4(b), f64x4::to_array),
        f64x4::to_array,
    );
}

/// [`Pack::pack`](super::Pack::pack) of `f32x8` (`wide`'s transposition: shuffles on AVX,
/// lane by lane elsewhere).
#[inline(always)]
pub(super) fn pack_f32x8(states: &[f32], v: &mut [f32x8]) {
    pack_blocks(
        states,
        v,
        |m| f32x8::transpose(each_of(*m, f32x8::new)),
        f32x8::new,
    );
}

/// [`Pack::unpack`](super::Pack::unpack) of `f32x8`.
#[inline(always)]
pub(super) fn unpack_f32x8(v: &[f32x8], states: &mut [f32]) {
    unpack_blocks(
        v,
        states,
        |b| each_of(f32x8::transpose(*b), f32x8::to_array),
        f32x8::to_array,
    );
}

/// [`Pack::unpack_run`](super::Pack::unpack_run) of `f32x8`.
#[inline(always)]
pub(super) fn unpack_run_f32x8<const R: usize, const C: usize>(
    v: &[f32x8],
    states: &mut [[[f32; C]; R]],
    at: usize,
) {
    unpack_run_blocks(
        (v, states, at),
        |b| each_of(f32x8::transpose(*b), f32x8::to_array),
        f32x8::to_array,
    );
}
