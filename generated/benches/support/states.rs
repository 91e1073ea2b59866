//! Benchmark states shared by `dynamics.rs` and the workspace's derivative benchmarks: like
//! pinbench, a fixed set of random states (q uniform within the URDF joint limits, [-pi, pi]
//! where there are none; qd, qdd and tau uniform in [-1, 1]) cycled through `black_box`.

use std::hint::black_box;
use std::path::{Path, PathBuf};

use criterion::BenchmarkGroup;

/// A reference robot's URDF, in the workspace's `tests/robots/` (the including crate is one of
/// the workspace's).
pub fn robot(urdf: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/robots")
        .join(urdf)
}

/// As many states as pinbench uses.
const STATES: usize = 1000;

/// One random state of an `N`-joint robot.
pub struct State<const N: usize> {
    pub q: [f64; N],
    pub qd: [f64; N],
    pub qdd: [f64; N],
    pub tau: [f64; N],
}

/// splitmix64: a fixed seed gives the same states on every run, without a `rand` dependency.
struct Rng(u64);

impl Rng {
    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }

    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    fn symmetric<const N: usize>(&mut self) -> [f64; N] {
        core::array::from_fn(|_| self.uniform(-1.0, 1.0))
    }
}

/// `STATES` random states of the robot whose coordinates are `joint_names`, with q within the
/// limits of the URDF at `path` (read through eomgen's own model loader).
pub fn states<const N: usize>(path: &Path, joint_names: &[&str; N]) -> Vec<State<N>> {
    let urdf = path.display();
    let model = eomgen::Builder::new(path)
        .model()
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let pi = core::f64::consts::PI;
    let bounds: [(f64, f64); N] = core::array::from_fn(|i| {
        let joint = model
            .joints
            .iter()
            .find(|j| j.name == joint_names[i])
            .unwrap_or_else(|| panic!("{urdf}: no joint {}", joint_names[i]));
        match &joint.limits {
            // Continuous joints carry no position limits, and infinite limits mean none.
            Some(l) if l.lower.is_finite() && l.upper.is_finite() && l.lower < l.upper => {
                (l.lower, l.upper)
            }
            _ => (-pi, pi),
        }
    });
    let mut rng = Rng(42);
    (0..STATES)
        .map(|_| State {
            q: core::array::from_fn(|i| rng.uniform(bounds[i].0, bounds[i].1)),
            qd: rng.symmetric(),
            qdd: rng.symmetric(),
            tau: rng.symmetric(),
        })
        .collect()
}

/// Benchmarks `f` on the states in turn, like pinbench's loop.
pub fn cycle<const N: usize, R>(
    group: &mut BenchmarkGroup<'_, criterion::measurement::WallTime>,
    name: &str,
    states: &[State<N>],
    mut f: impl FnMut(&State<N>) -> R,
) {
    group.bench_function(name, |b| {
        let mut k = 0;
        b.iter(|| {
            let s = black_box(&states[k]);
            k += 1;
            if k == states.len() {
                k = 0;
            }
            f(s)
        })
    });
}
