//! States per second of the generated dynamics three ways: the scalar code state by state on
//! one core (`scalar`), the `_batch` methods on the target's widest SIMD lanes on one core
//! (`batch`: `f64x4` and `f32x8` with AVX), and the same over every core (`threads`), for the
//! panda (9 coordinates) and anymal (floating base, 18), in `f64` and `f32`, and anymal's
//! contact forward dynamics and impulse dynamics on its four feet, with two of them switched on
//! at run time (`_active`), and the contact and impulse derivatives on four feet. Named
//! `batch-<robot>-<scalar>/<function>/<way>`; criterion prints states per second
//! (`thrpt`). Needs the `rayon` feature:
//!
//!     RUSTFLAGS="-C target-cpu=native" cargo bench -p eomgen-tests --features rayon --bench batch
//!
//! Every way evaluates the same 1024 random states (angles in [-pi, pi], a random unit
//! quaternion, velocities, accelerations and efforts in [-1, 1]); `EOMGEN_BATCH_STATES=128`
//! evaluates 128 instead (results that fit in a core's L2 cache).

use std::hint::black_box;

use criterion::measurement::WallTime;
use criterion::{criterion_group, criterion_main, BenchmarkGroup, Criterion, Throughput};
use eomgen_generated::panda::Panda;
use eomgen_runtime::batch::Batch;
use eomgen_runtime::prelude::*;
use eomgen_tests::robots::anymal::{Anymal, AnymalLink};
use eomgen_tests::robots::anymal_derivatives::AnymalDerivatives;
use eomgen_tests::robots::anymal_mpc::AnymalMpc;
use eomgen_tests::robots::panda_derivatives::PandaDerivatives;
use rayon::{ThreadPool, ThreadPoolBuilder};

/// States per call: `EOMGEN_BATCH_STATES` (1024 unless set). 1024 anymal mass matrices are
/// 2.6 MB in `f64`, more than a core's L2 cache: set it to 128 to time the batch in cache.
fn states_per_call() -> usize {
    std::env::var("EOMGEN_BATCH_STATES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1024)
}

/// `STATES` arrays of `N` numbers in [-scale, scale] (splitmix64 from `seed`).
fn states<S: Batch, const N: usize>(seed: u64, scale: f64) -> Vec<[S; N]> {
    let mut x = seed;
    let mut unit = move || {
        x = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = x;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    (0..states_per_call())
        .map(|_| core::array::from_fn(|_| S::from_f64(scale * unit())))
        .collect()
}

/// Floating-base configurations: a unit quaternion in entries 3..7.
fn configurations<S: Batch, const N: usize>(seed: u64) -> Vec<[S; N]> {
    let mut q = states::<S, N>(seed, std::f64::consts::PI);
    for s in &mut q {
        let n = s[3..7]
            .iter()
            .map(|x| x.to_f64().powi(2))
            .sum::<f64>()
            .sqrt();
        s[3..7]
            .iter_mut()
            .for_each(|x| *x = S::from_f64(x.to_f64() / n));
    }
    q
}

/// One pool of one thread (`batch`: rayon's joins run in turn) and one of every core.
struct Pools {
    one: ThreadPool,
    all: ThreadPool,
}

fn group<'c>(c: &'c mut Criterion, name: &str) -> BenchmarkGroup<'c, WallTime> {
    let mut g = c.benchmark_group(name);
    g.throughput(Throughput::Elements(states_per_call() as u64));
    g.sample_size(20);
    g.warm_up_time(std::time::Duration::from_millis(500));
    g.measurement_time(std::time::Duration::from_secs(2));
    g
}

/// Function `$name` three ways in group `$g`, into fresh outputs `$o` (each `states_per_call()` copies of
/// `$zero`): `$scalar` once per state `$i` on this thread, `$batch` run from inside the
/// one-thread pool and inside the pool of every core.
macro_rules! three_ways {
    ($g:ident, $pools:ident, $name:literal, ($($o:ident: $zero:expr),+), |$i:ident| $scalar:block, $batch:block) => {{
        let states = states_per_call();
        $(let mut $o = vec![$zero; states];)+
        $g.bench_function(concat!($name, "/scalar"), |b| b.iter(|| for $i in 0..states $scalar));
        $g.bench_function(concat!($name, "/batch"), |b| $pools.one.install(|| b.iter(|| $batch)));
        $g.bench_function(concat!($name, "/threads"), |b| $pools.all.install(|| b.iter(|| $batch)));
    }};
}

/// The panda's inverse dynamics, mass matrix, forward dynamics and inverse-dynamics
/// derivatives.
fn panda<S: Batch>(c: &mut Criterion, pools: &Pools, label: &str) {
    let (robot, d) = (Panda::<S>::default(), PandaDerivatives::<S>::default());
    let q = states::<S, 9>(1, std::f64::consts::PI);
    let (qd, qdd) = (states::<S, 9>(2, 1.0), states::<S, 9>(3, 1.0));
    let (v, m) = ([S::zero(); 9], [[S::zero(); 9]; 9]);
    let mut g = group(c, &format!("batch-panda-{label}"));
    three_ways!(g, pools, "inverse_dynamics", (o: v), |i| {
        o[i] = robot.inverse_dynamics(black_box(&q[i]), &qd[i], &qdd[i]);
    }, {
        robot.inverse_dynamics_batch(black_box(&q), &qd, &qdd, &mut o).unwrap()
    });
    three_ways!(g, pools, "mass_matrix", (o: m), |i| {
        o[i] = robot.mass_matrix(black_box(&q[i]));
    }, {
        robot.mass_matrix_batch(black_box(&q), &mut o).unwrap()
    });
    three_ways!(g, pools, "forward_dynamics", (o: v), |i| {
        o[i] = robot.forward_dynamics(black_box(&q[i]), &qd[i], &qdd[i]);
    }, {
        robot.forward_dynamics_batch(black_box(&q), &qd, &qdd, &mut o).unwrap()
    });
    three_ways!(g, pools, "inverse_dynamics_derivatives", (a: m, b: m), |i| {
        (a[i], b[i]) = d.inverse_dynamics_derivatives(black_box(&q[i]), &qd[i], &qdd[i]);
    }, {
        d.inverse_dynamics_derivatives_batch(black_box(&q), &qd, &qdd, &mut a, &mut b).unwrap()
    });
}

/// anymal's inverse dynamics, mass matrix, forward dynamics and inverse-dynamics derivatives.
fn anymal<S: Batch>(c: &mut Criterion, pools: &Pools, label: &str) {
    let robot = AnymalDerivatives::<S>::default();
    let q = configurations::<S, 19>(4);
    let (v, a) = (states::<S, 18>(5, 1.0), states::<S, 18>(6, 1.0));
    let (z, m) = ([S::zero(); 18], [[S::zero(); 18]; 18]);
    let mut g = group(c, &format!("batch-anymal-{label}"));
    three_ways!(g, pools, "inverse_dynamics", (o: z), |i| {
        o[i] = robot.inverse_dynamics(black_box(&q[i]), &v[i], &a[i]);
    }, {
        robot.inverse_dynamics_batch(black_box(&q), &v, &a, &mut o).unwrap()
    });
    three_ways!(g, pools, "mass_matrix", (o: m), |i| {
        o[i] = robot.mass_matrix(black_box(&q[i]));
    }, {
        robot.mass_matrix_batch(black_box(&q), &mut o).unwrap()
    });
    three_ways!(g, pools, "forward_dynamics", (o: z), |i| {
        o[i] = robot.forward_dynamics(black_box(&q[i]), &v[i], &a[i]);
    }, {
        robot.forward_dynamics_batch(black_box(&q), &v, &a, &mut o).unwrap()
    });
    three_ways!(g, pools, "inverse_dynamics_derivatives", (x: m, y: m), |i| {
        (x[i], y[i]) = robot.inverse_dynamics_derivatives(black_box(&q[i]), &v[i], &a[i]);
    }, {
        robot.inverse_dynamics_derivatives_batch(black_box(&q), &v, &a, &mut x, &mut y).unwrap()
    });
}

/// anymal standing on its four feet: contact forward dynamics and impulse dynamics (each one
/// straight-line program, on lanes), and a foot's pose.
fn anymal_contacts<S: Batch>(c: &mut Criterion, pools: &Pools, label: &str) {
    let robot = Anymal::<S>::default();
    let q = configurations::<S, 19>(7);
    let (v, tau) = (states::<S, 18>(8, 1.0), states::<S, 18>(9, 10.0));
    let e = S::from_f64(0.2);
    let (z, f) = ([S::zero(); 18], [S::zero(); 12]);
    let mut g = group(c, &format!("batch-anymal-contacts-{label}"));
    three_ways!(g, pools, "contact_forward_dynamics", (a: z, b: f), |i| {
        (a[i], b[i]) = robot.contact_forward_dynamics(black_box(&q[i]), &v[i], &tau[i]);
    }, {
        robot.contact_forward_dynamics_batch(black_box(&q), &v, &tau, &mut a, &mut b).unwrap()
    });
    let foot = AnymalLink::RhFoot;
    three_ways!(g, pools, "link_pose", (p: Pose::identity()), |i| {
        p[i] = robot.link_pose(foot, black_box(&q[i]));
    }, {
        robot.link_pose_batch(foot, black_box(&q), &mut p).unwrap()
    });
    three_ways!(g, pools, "impulse_dynamics", (a: z, b: f), |i| {
        (a[i], b[i]) = robot.impulse_dynamics(black_box(&q[i]), &v[i], e);
    }, {
        robot.impulse_dynamics_batch(black_box(&q), &v, e, &mut a, &mut b).unwrap()
    });
}

/// anymal trotting: contact forward dynamics and impulse dynamics with two diagonal feet of
/// four, the set passed at run time (`_active`, on lanes: the runtime's solves over every lane
/// at once).
fn anymal_active<S: Batch>(c: &mut Criterion, pools: &Pools, label: &str) {
    let robot = AnymalMpc::<S>::default();
    let q = configurations::<S, 19>(13);
    let (v, tau) = (states::<S, 18>(14, 1.0), states::<S, 18>(15, 10.0));
    let (z, f) = ([S::zero(); 18], [S::zero(); 12]);
    let trot = [true, false, false, true];
    let mut g = group(c, &format!("batch-anymal-contacts-{label}"));
    three_ways!(g, pools, "contact_forward_dynamics_active", (a: z, b: f), |i| {
        (a[i], b[i]) = robot.contact_forward_dynamics_active(black_box(&q[i]), &v[i], &tau[i], &trot);
    }, {
        robot.contact_forward_dynamics_active_batch(black_box(&q), &v, &tau, &trot, &mut a, &mut b).unwrap()
    });
    let e = S::from_f64(0.2);
    three_ways!(g, pools, "impulse_dynamics_active", (a: z, b: f), |i| {
        (a[i], b[i]) = robot.impulse_dynamics_active(black_box(&q[i]), &v[i], e, &trot);
    }, {
        robot.impulse_dynamics_active_batch(black_box(&q), &v, e, &trot, &mut a, &mut b).unwrap()
    });
}

/// anymal's contact forward dynamics and impulse dynamics derivatives (four feet), on lanes
/// like the rest (the runtime's KKT solves over every lane at once).
fn anymal_contact_derivatives<S: Batch>(c: &mut Criterion, pools: &Pools, label: &str) {
    let robot = AnymalMpc::<S>::default();
    let q = configurations::<S, 19>(10);
    let (v, tau) = (states::<S, 18>(11, 1.0), states::<S, 18>(12, 10.0));
    let (q0, v0) = (configurations::<S, 19>(10)[0], [S::zero(); 18]);
    let zero = robot.contact_forward_dynamics_derivatives(&q0, &v0, &v0);
    let mut g = group(c, &format!("batch-anymal-contact-derivatives-{label}"));
    three_ways!(g, pools, "contact_forward_dynamics_derivatives", (d: zero), |i| {
        d[i] = robot.contact_forward_dynamics_derivatives(black_box(&q[i]), &v[i], &tau[i]);
    }, {
        robot.contact_forward_dynamics_derivatives_batch(black_box(&q), &v, &tau, &mut d).unwrap()
    });
    let e = S::from_f64(0.2);
    let zero = robot.impulse_dynamics_derivatives(&q0, &v0, e);
    three_ways!(g, pools, "impulse_dynamics_derivatives", (d: zero), |i| {
        d[i] = robot.impulse_dynamics_derivatives(black_box(&q[i]), &v[i], e);
    }, {
        robot.impulse_dynamics_derivatives_batch(black_box(&q), &v, e, &mut d).unwrap()
    });
}

fn batch(c: &mut Criterion) {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let pools = Pools {
        one: ThreadPoolBuilder::new().num_threads(1).build().unwrap(),
        all: ThreadPoolBuilder::new().num_threads(cores).build().unwrap(),
    };
    panda::<f64>(c, &pools, "f64");
    anymal::<f64>(c, &pools, "f64");
    panda::<f32>(c, &pools, "f32");
    anymal::<f32>(c, &pools, "f32");
    anymal_contacts::<f64>(c, &pools, "f64");
    anymal_contacts::<f32>(c, &pools, "f32");
    anymal_active::<f64>(c, &pools, "f64");
    anymal_active::<f32>(c, &pools, "f32");
    anymal_contact_derivatives::<f64>(c, &pools, "f64");
    anymal_contact_derivatives::<f32>(c, &pools, "f32");
}

criterion_group!(benches, batch);
criterion_main!(benches);
