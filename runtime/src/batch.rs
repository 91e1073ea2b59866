//! Many states per call: what the generated `NAME_batch` methods are built on.
//!
//! A generated `NAME_batch(&self, inputs..., outputs...)` evaluates `NAME` at every state of
//! its input slices (one array per state) and writes one result per state. It packs the
//! states into the widest SIMD lanes the target supports ([`Batch::Lanes`]: with the `simd`
//! feature, `f64x4` and `f32x8` where AVX is enabled at compile time, `f64x2` and `f32x4` with
//! SSE2, NEON or WebAssembly SIMD; one state at a time otherwise), fills the last, partial
//! vector with copies of its last state, never allocates, asks the processor for the next
//! vector's result memory while the current one computes ([`Outputs::prefetch`]), and with the
//! `rayon` feature (host only) spreads the vectors over rayon's threads. Slices of different
//! lengths are an error ([`BatchError`]), checked before anything is written.
//!
//! ```
//! # mod generated { include!("../../generated/src/double_pendulum.rs"); }
//! # use generated::DoublePendulum;
//! use eomgen_runtime::prelude::*;
//!
//! let robot = DoublePendulum::<f64>::default();
//! let q = [[0.1, 0.2], [0.3, -0.4], [1.0, 2.0]];
//! let mut m = [[[0.0; 2]; 2]; 3];
//! robot.mass_matrix_batch(&q, &mut m).unwrap();
//! assert_eq!(m[1], robot.mass_matrix(&q[1]));
//!
//! let mut short = [[[0.0; 2]; 2]; 2];
//! assert!(robot.mass_matrix_batch(&q, &mut short).is_err());
//! ```

use core::fmt;

use crate::entries;
use crate::lane::Pack;
use crate::{ContactDynamicsDerivatives, ImpulseDynamicsDerivatives, Pose, Real};

/// A scalar whose generated methods have `_batch` versions: `f64` and `f32`.
pub trait Batch: Real + Send + Sync {
    /// The widest vector of this scalar the target supports (the scalar itself without the
    /// `simd` feature or without SIMD instructions).
    type Lanes: Pack<Scalar = Self> + Send + Sync;
}

#[cfg(all(feature = "simd", target_feature = "avx"))]
mod widest {
    pub type F64 = wide::f64x4;
    pub type F32 = wide::f32x8;
}
#[cfg(all(
    feature = "simd",
    not(target_feature = "avx"),
    any(
        target_feature = "sse2",
        target_feature = "neon",
        target_feature = "simd128"
    )
))]
mod widest {
    pub type F64 = wide::f64x2;
    pub type F32 = wide::f32x4;
}
#[cfg(not(all(
    feature = "simd",
    any(
        target_feature = "avx",
        target_feature = "sse2",
        target_feature = "neon",
        target_feature = "simd128"
    )
)))]
mod widest {
    pub type F64 = f64;
    pub type F32 = f32;
}

impl Batch for f64 {
    type Lanes = widest::F64;
}
impl Batch for f32 {
    type Lanes = widest::F32;
}

/// Input and output slices of a batch call that do not hold the same number of states.
///
/// ```
/// use eomgen_runtime::batch::BatchError;
///
/// let e = BatchError { argument: "qd", len: 3, expected: 4 };
/// assert_eq!(e.to_string(), "batch argument `qd` holds 3 states, the output 4");
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BatchError {
    /// The argument's name.
    pub argument: &'static str,
    /// How many states it holds.
    pub len: usize,
    /// How many the (first) output slice holds.
    pub expected: usize,
}

impl fmt::Display for BatchError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "batch argument `{}` holds {} states, the output {}",
            self.argument, self.len, self.expected
        )
    }
}

#[cfg(feature = "std")]
impl std::error::Error for BatchError {}

/// `Ok` when every `(name, len)` of `slices` has `expected` states.
///
/// ```
/// use eomgen_runtime::batch::check;
/// assert!(check(2, &[("q", 2), ("qd", 2)]).is_ok());
/// assert_eq!(check(2, &[("q", 2), ("qd", 1)]).unwrap_err().argument, "qd");
/// ```
pub fn check(expected: usize, slices: &[(&'static str, usize)]) -> Result<(), BatchError> {
    match slices.iter().find(|(_, len)| *len != expected) {
        Some(&(argument, len)) => Err(BatchError {
            argument,
            len,
            expected,
        }),
        None => Ok(()),
    }
}

/// States `start..start + LANES` of `x` in the lanes of one array (lanes past the end of `x`
/// repeat its last state; zeros if `x` is empty). A whole vector of states is packed by
/// [`Pack::pack`] (an in-register transposition for `f64x4` and `f32x8` on AVX).
///
/// ```
/// use eomgen_runtime::batch::{gather, scatter};
/// let x = [[1.0_f64, 2.0], [3.0, 4.0]];
/// let v: [f64; 2] = gather(&x, 1); // one lane: state 1
/// let mut out = [[0.0; 2]; 1];
/// scatter(&v, &mut out);
/// assert_eq!(out, [[3.0, 4.0]]);
/// ```
#[inline(always)]
pub fn gather<L: Pack, const N: usize>(x: &[[L::Scalar; N]], start: usize) -> [L; N] {
    if let Some(full) = x.get(start..start + L::LANES) {
        let mut v = [L::zero(); N];
        L::pack(full.as_flattened(), &mut v);
        return v;
    }
    let zero = <L::Scalar as Real>::zero();
    let last = x.len().saturating_sub(1);
    core::array::from_fn(|i| L::gather(|l| x.get((start + l).min(last)).map_or(zero, |s| s[i])))
}

/// Lanes `0..out.len()` of an array of lanes, one array per state (see [`gather`]), by
/// [`Pack::unpack`]: each state's result written as one contiguous run.
#[inline(always)]
pub fn scatter<L: Pack, const N: usize>(v: &[L; N], out: &mut [[L::Scalar; N]]) {
    L::unpack(v, out.as_flattened_mut());
}

/// Lanes `0..out.len()` of a matrix of lanes, one matrix per state (by [`Pack::unpack`] of
/// the row-major entries).
///
/// ```
/// use eomgen_runtime::batch::scatter_matrix;
/// let mut out = [[[0.0_f64; 2]; 1]; 1];
/// scatter_matrix(&[[1.0, 2.0]], &mut out);
/// assert_eq!(out, [[[1.0, 2.0]]]);
/// ```
#[inline(always)]
pub fn scatter_matrix<L: Pack, const R: usize, const C: usize>(
    v: &[[L; C]; R],
    out: &mut [[[L::Scalar; C]; R]],
) {
    L::unpack(v.as_flattened(), out.as_flattened_mut().as_flattened_mut());
}

/// Lanes `0..out.len()` of contact-dynamics derivatives, one result per state: the six
/// matrices unpacked as one run of entries, as [`scatter_matrix`] unpacks a matrix.
///
/// ```
/// use eomgen_runtime::{batch::scatter_contact_derivatives, ContactDynamicsDerivatives};
/// let d = ContactDynamicsDerivatives::<f64, 1, 1>::nan();
/// let mut out = [ContactDynamicsDerivatives { da_dq: [[0.5]], ..d }];
/// scatter_contact_derivatives(&d, &mut out);
/// assert!(out[0].da_dq[0][0].is_nan());
/// ```
#[inline(always)]
pub fn scatter_contact_derivatives<L: Pack, const N: usize, const K: usize>(
    d: &ContactDynamicsDerivatives<L, N, K>,
    out: &mut [ContactDynamicsDerivatives<L::Scalar, N, K>],
) {
    L::unpack(entries::of(d), entries::of_each_mut(out));
}

/// Lanes `0..out.len()` of impulse-dynamics derivatives, one result per state (as
/// [`scatter_contact_derivatives`]).
#[inline(always)]
pub fn scatter_impulse_derivatives<L: Pack, const N: usize, const K: usize>(
    d: &ImpulseDynamicsDerivatives<L, N, K>,
    out: &mut [ImpulseDynamicsDerivatives<L::Scalar, N, K>],
) {
    L::unpack(entries::of(d), entries::of_each_mut(out));
}

/// Lane `l` of the pose `p` into element `l` of `out` (at most `L::LANES` elements).
///
/// ```
/// use eomgen_runtime::{batch::scatter_pose, Pose};
/// let mut out = [Pose::identity(); 1];
/// scatter_pose(&Pose::from_translation([1.0_f64, 2.0, 3.0]), &mut out);
/// assert_eq!(out[0].translation, [1.0, 2.0, 3.0]);
/// ```
#[inline(always)]
pub fn scatter_pose<L: Pack>(p: &Pose<L>, out: &mut [Pose<L::Scalar>]) {
    for (l, o) in out.iter_mut().enumerate() {
        *o = Pose {
            translation: p.translation.map(|x| x.lane(l)),
            rotation: p.rotation.map(|row| row.map(|x| x.lane(l))),
        };
    }
}

/// Lanes `0..out.len()` of one number of lanes.
///
/// ```
/// use eomgen_runtime::batch::scatter_scalar;
/// let mut out = [0.0_f64; 1];
/// scatter_scalar(2.5, &mut out);
/// assert_eq!(out, [2.5]);
/// ```
#[inline(always)]
pub fn scatter_scalar<L: Pack>(v: L, out: &mut [L::Scalar]) {
    for (o, y) in out.iter_mut().zip(v.lanes().as_ref()) {
        *o = *y;
    }
}

/// The output slices of a batch call, cut together into chunks of states: one slice or a
/// tuple of two or three.
///
/// ```
/// use eomgen_runtime::batch::Outputs;
/// let (mut a, mut b) = ([1, 2, 3], [4, 5, 6]);
/// let ((a0, b0), (a1, _)) = (&mut a[..], &mut b[..]).split_at(1);
/// assert_eq!((a0.states(), b0[0], a1.states()), (1, 4, 2));
/// ```
pub trait Outputs: Send + Sized {
    /// The number of states (of the first slice).
    fn states(&self) -> usize;
    /// The first `mid` states and the rest.
    fn split_at(self, mid: usize) -> (Self, Self);
    /// Asks the processor to fetch the memory of the first `states` states of every slice,
    /// about to be written ([`run`] calls it for the next chunk while the current one
    /// computes). A hint only: nothing by default.
    #[inline(always)]
    fn prefetch(&self, states: usize) {
        let _ = states;
    }
}

impl<A: Send> Outputs for &mut [A] {
    #[inline(always)]
    fn states(&self) -> usize {
        self.len()
    }
    #[inline(always)]
    fn split_at(self, mid: usize) -> (Self, Self) {
        self.split_at_mut(mid.min(<[A]>::len(self)))
    }
    #[inline(always)]
    fn prefetch(&self, states: usize) {
        crate::prefetch::lines_of(&self[..states.min(self.len())]);
    }
}

macro_rules! tuple_outputs {
    ($($o:ident $i:tt),+) => {
        impl<$($o: Outputs),+> Outputs for ($($o,)+) {
            #[inline(always)]
            fn states(&self) -> usize {
                self.0.states()
            }
            #[inline(always)]
            fn split_at(self, mid: usize) -> (Self, Self) {
                $(let $o = self.$i.split_at(mid);)+
                (($($o.0,)+), ($($o.1,)+))
            }
            #[inline(always)]
            fn prefetch(&self, states: usize) {
                $(self.$i.prefetch(states);)+
            }
        }
    };
}
#[allow(non_snake_case)]
mod tuples {
    use super::Outputs;
    tuple_outputs!(A 0, B 1);
    tuple_outputs!(A 0, B 1, C 2);
}

/// Calls `f(start, chunk)` on consecutive chunks of `lanes` states of `out` (the last may be
/// shorter), `start` the index of the chunk's first state; on rayon's threads with the `rayon`
/// feature, in order on the calling thread without.
///
/// ```
/// use eomgen_runtime::batch::run;
/// let mut out = [0usize; 5];
/// run(2, &mut out[..], &|start, chunk: &mut [usize]| {
///     for (k, x) in chunk.iter_mut().enumerate() {
///         *x = start + k;
///     }
/// });
/// assert_eq!(out, [0, 1, 2, 3, 4]);
/// ```
#[inline]
pub fn run<O: Outputs>(lanes: usize, out: O, f: &(impl Fn(usize, O) + Sync)) {
    run_costed(lanes, usize::MAX, out, f);
}

/// The arithmetic (states times operations per state) below which a call from outside
/// rayon's pools stays on the calling thread: waking a pool thread from there costs some
/// 20 us (anymal's contact forward dynamics, `examples/mppi_quadruped.rs`: 64 states, 25 us on
/// one thread, took 30 to 47 us on two), a million operations about 50 us on lanes.
#[cfg(feature = "rayon")]
const OUTSIDE_MIN_OPS: usize = 1_000_000;

/// [`run`] for a method of `ops` operations per state (generated code passes its operation
/// count; `usize::MAX` when unknown): called from outside rayon's pools, a call of less
/// arithmetic than a thread's wake-up is worth runs on the calling thread.
#[inline]
pub fn run_costed<O: Outputs>(lanes: usize, ops: usize, out: O, f: &(impl Fn(usize, O) + Sync)) {
    let lanes = lanes.max(1);
    #[cfg(feature = "rayon")]
    if rayon::current_thread_index().is_some() {
        parallel(0, lanes, out, f);
    } else if out.states().saturating_mul(ops) < OUTSIDE_MIN_OPS {
        sequential(0, lanes, out, f);
    } else {
        from_outside(lanes, out, f);
    }
    #[cfg(not(feature = "rayon"))]
    {
        let _ = ops;
        sequential(0, lanes, out, f);
    }
}

/// [`run`] called from a thread outside rayon's pools (a program's main thread). `join` there
/// hands the whole call to a pool thread and blocks until it is done, and that thread wakes a
/// second one to take half: a quadruped's 256-sample rollout (`examples/mppi_quadruped.rs`) was
/// slower on two threads than on one. Instead the calling thread and `current_num_threads - 1`
/// pool threads take runs of `GRAIN` vectors from the front in turn, so that the calling thread
/// starts at once and a pool thread that wakes late takes less. (Fixed parts, one per thread,
/// waited for the late one: anymal's contact forward dynamics, 256 states 20 us apart, 107 us
/// a call against 70 us.)
#[cfg(feature = "rayon")]
fn from_outside<O: Outputs>(lanes: usize, out: O, f: &(impl Fn(usize, O) + Sync)) {
    let vectors = out.states().div_ceil(lanes);
    let threads = rayon::current_num_threads();
    if vectors <= GRAIN || threads < 2 {
        return sequential(0, lanes, out, f);
    }
    let rest = std::sync::Mutex::new((0usize, Some(out)));
    let take = || {
        let mut guard = rest.lock().unwrap_or_else(|e| e.into_inner());
        let (start, left) = &mut *guard;
        let o = left.take()?;
        if o.states() == 0 {
            return None;
        }
        let (part, more) = o.split_at(GRAIN * lanes);
        let at = *start;
        *start += GRAIN * lanes;
        *left = Some(more);
        Some((at, part))
    };
    let work = || {
        while let Some((at, part)) = take() {
            sequential(at, lanes, part, f);
        }
    };
    rayon::in_place_scope(|scope| {
        for _ in 1..threads {
            scope.spawn(|_| work());
        }
        work();
    });
}

/// [`run`] on the calling thread. The next chunk's results are fetched while the current one
/// computes ([`Outputs::prefetch`]): a vector's results are written in one burst, and where
/// they lie beyond the L2 cache the burst waited on its fetches (anymal's `f64x4` mass matrix
/// batch, 1024 states, Intel Xeon: 11 to 31 % less time a call in alternated rounds).
fn sequential<O: Outputs>(mut start: usize, lanes: usize, mut out: O, f: &impl Fn(usize, O)) {
    while out.states() > 0 {
        let (chunk, rest) = out.split_at(lanes);
        rest.prefetch(lanes);
        f(start, chunk);
        start += lanes;
        out = rest;
    }
}

/// States per task below which [`parallel`] stops splitting, in vectors.
#[cfg(feature = "rayon")]
const GRAIN: usize = 8;

/// [`run`] on rayon's threads: halves of whole vectors joined until `GRAIN` vectors are left.
#[cfg(feature = "rayon")]
fn parallel<O: Outputs>(start: usize, lanes: usize, out: O, f: &(impl Fn(usize, O) + Sync)) {
    let vectors = out.states().div_ceil(lanes);
    if vectors <= GRAIN {
        return sequential(start, lanes, out, f);
    }
    let mid = vectors / 2 * lanes;
    let (a, b) = out.split_at(mid);
    rayon::join(
        || parallel(start, lanes, a, f),
        || parallel(start + mid, lanes, b, f),
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chunks_cover_every_state_once_in_order() {
        for n in [0, 1, 3, 4, 5, 17, 100] {
            let mut out = [0usize; 100];
            let cells: &mut [usize] = &mut out[..n];
            run(4, cells, &|start, chunk: &mut [usize]| {
                for (k, c) in chunk.iter_mut().enumerate() {
                    *c = start + k + 1;
                }
            });
            assert!(out[..n].iter().enumerate().all(|(i, v)| *v == i + 1));
            assert!(out[n..].iter().all(|v| *v == 0));
        }
    }

    /// From a thread outside rayon's pools and from inside one, every state once, with its
    /// own index.
    #[cfg(feature = "rayon")]
    #[test]
    fn threads_cover_every_state_once_from_outside_and_inside_the_pool() {
        let fill = |n: usize| {
            let mut out = std::vec![0usize; n];
            run(4, &mut out[..], &|start, chunk: &mut [usize]| {
                for (k, c) in chunk.iter_mut().enumerate() {
                    *c += start + k + 1;
                }
            });
            out
        };
        for n in [0, 5, 32, 33, 100, 1001] {
            let want: std::vec::Vec<usize> = (1..=n).collect();
            assert_eq!(std::thread::spawn(move || fill(n)).join().unwrap(), want);
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(3)
                .build()
                .unwrap();
            assert_eq!(pool.install(|| fill(n)), want);
        }
    }

    #[test]
    fn gather_repeats_the_last_state_past_the_end() {
        let x = [[1.0_f64, 2.0], [3.0, 4.0]];
        let v: [f64; 2] = gather(&x, 1);
        assert_eq!(v, [3.0, 4.0]);
        assert_eq!(check(2, &[("q", 2), ("qd", 3)]).unwrap_err().argument, "qd");
    }
}
