//! Speed of the generated dynamics of the five reference robots, f64.
//!
//! Every benchmark is named `<robot>/<function>` (criterion group / function, so its results are
//! in `target/criterion/<robot>/<function>/new/estimates.json`), e.g. `panda/inverse_dynamics`.
//! `scripts/compare-pinocchio` runs them robot by robot, alternating with Pinocchio's pinbench.
//!
//!     cargo bench -p eomgen-generated --bench dynamics -- '^panda/'
//!
//! Like pinbench, each benchmark cycles through a fixed set of random states (q uniform within
//! the URDF joint limits, [-pi, pi] where there are none; qd, qdd and tau uniform in [-1, 1]),
//! passed through `black_box`, so that neither constant folding nor a branch predictor that has
//! learned one input can flatter the figures.

use std::hint::black_box;
use std::path::PathBuf;

use criterion::{criterion_group, criterion_main, BenchmarkGroup, Criterion};
use eomgen_generated::allegro_right_hand::{AllegroRightHand, AllegroRightHandLink};
use eomgen_generated::double_pendulum::{DoublePendulum, DoublePendulumLink};
use eomgen_generated::kinova::{Kinova, KinovaLink};
use eomgen_generated::panda::{Panda, PandaLink};
use eomgen_generated::ur5::{Ur5, Ur5Link};
use eomgen_runtime::Dynamics;

/// As many states as pinbench uses.
const STATES: usize = 1000;

/// One random state of an `N`-joint robot.
struct State<const N: usize> {
    q: [f64; N],
    qd: [f64; N],
    qdd: [f64; N],
    tau: [f64; N],
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
/// limits of the URDF `robots/<urdf>` (read through eomgen's own model loader).
fn states<const N: usize>(urdf: &str, joint_names: &[&str; N]) -> Vec<State<N>> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("robots")
        .join(urdf);
    let model = eomgen::Builder::new(&path)
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
fn cycle<const N: usize, R>(
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

/// Every `Dynamics` function and the inherent ones of one robot, in group `$group`.
macro_rules! bench_robot {
    ($c:expr, $group:literal, $ty:ty, $urdf:literal, $ee:expr) => {{
        let robot = <$ty>::default();
        let states = states($urdf, &<$ty as Dynamics<f64, { <$ty>::DOF }>>::JOINT_NAMES);
        let mut g = $c.benchmark_group($group);
        cycle(&mut g, "mass_matrix", &states, |s| robot.mass_matrix(&s.q));
        cycle(&mut g, "gravity", &states, |s| robot.gravity(&s.q));
        cycle(&mut g, "bias", &states, |s| robot.bias(&s.q, &s.qd));
        cycle(&mut g, "coriolis_matrix", &states, |s| {
            robot.coriolis_matrix(&s.q, &s.qd)
        });
        cycle(&mut g, "inverse_dynamics", &states, |s| {
            robot.inverse_dynamics(&s.q, &s.qd, &s.qdd)
        });
        cycle(&mut g, "forward_dynamics", &states, |s| {
            robot.forward_dynamics(&s.q, &s.qd, &s.tau)
        });
        cycle(&mut g, "kinetic_energy", &states, |s| {
            robot.kinetic_energy(&s.q, &s.qd)
        });
        cycle(&mut g, "potential_energy", &states, |s| {
            robot.potential_energy(&s.q)
        });
        // The link is a constant, as in a controller's call: only the state varies. It is the
        // frame pinbench takes its Jacobian of (Pinocchio's last frame, a distal link).
        cycle(&mut g, "link_pose", &states, |s| robot.link_pose($ee, &s.q));
        cycle(&mut g, "link_jacobian", &states, |s| {
            robot.link_jacobian($ee, &s.q)
        });
        cycle(&mut g, "centrifugal", &states, |s| robot.centrifugal(&s.q));
        cycle(&mut g, "coriolis_pairs", &states, |s| {
            robot.coriolis_pairs(&s.q)
        });
        g.finish();
    }};
}

fn double_pendulum(c: &mut Criterion) {
    bench_robot!(
        c,
        "double_pendulum",
        DoublePendulum,
        "double_pendulum.urdf",
        DoublePendulumLink::Link2
    );
}

fn ur5(c: &mut Criterion) {
    bench_robot!(c, "ur5", Ur5, "ur5.urdf", Ur5Link::Tool0);
}

fn panda(c: &mut Criterion) {
    bench_robot!(c, "panda", Panda, "panda.urdf", PandaLink::PandaHandTcp);
}

fn kinova(c: &mut Criterion) {
    bench_robot!(
        c,
        "kinova",
        Kinova,
        "kinova.urdf",
        KinovaLink::J2s6s200LinkFingerTip2
    );
}

fn allegro_right_hand(c: &mut Criterion) {
    bench_robot!(
        c,
        "allegro_right_hand",
        AllegroRightHand,
        "allegro_right_hand.urdf",
        AllegroRightHandLink::Link110Tip
    );
}

criterion_group!(
    benches,
    double_pendulum,
    ur5,
    panda,
    kinova,
    allegro_right_hand
);
criterion_main!(benches);
