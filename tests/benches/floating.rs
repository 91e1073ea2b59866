//! Speed of the generated floating-base dynamics of anymal (18 velocity coordinates, four
//! point contacts at the feet; the derivatives from a second module), f64, named
//! `anymal/<function>` like the fixed-base benches of `eomgen-generated`. Compare with `pinbench robots/floating/anymal.urdf --free-flyer` in the
//! same run, both compiled for the native CPU:
//!
//!     RUSTFLAGS="-C target-cpu=native" cargo bench -p eomgen-tests --bench floating
//!
//! As pinbench does, each benchmark cycles through 1000 fixed random states (joint angles in
//! [-pi, pi], a random unit quaternion, velocities, accelerations and efforts in [-1, 1]),
//! passed through `black_box`.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use eomgen_runtime::prelude::*;
use eomgen_tests::robots::anymal::Anymal;
use eomgen_tests::robots::anymal_derivatives::AnymalDerivatives;

struct State {
    q: [f64; 19],
    v: [f64; 18],
    a: [f64; 18],
    tau: [f64; 18],
}

/// splitmix64 from a fixed seed.
fn states() -> Vec<State> {
    let mut x = 42_u64;
    let mut unit = move || {
        x = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = x;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    (0..1000)
        .map(|_| {
            let mut q: [f64; 19] = core::array::from_fn(|_| std::f64::consts::PI * unit());
            let n = (q[3..7].iter().map(|x| x * x).sum::<f64>()).sqrt();
            q[3..7].iter_mut().for_each(|x| *x /= n);
            State {
                q,
                v: core::array::from_fn(|_| unit()),
                a: core::array::from_fn(|_| unit()),
                tau: core::array::from_fn(|i| if i < 6 { 0.0 } else { unit() }),
            }
        })
        .collect()
}

fn anymal(c: &mut Criterion) {
    let r = Anymal::<f64>::default();
    let states = states();
    let mut g = c.benchmark_group("anymal");
    let mut bench = |name: &str, f: &dyn Fn(&State) -> f64| {
        g.bench_function(name, |b| {
            let mut k = 0;
            b.iter(|| {
                let s = black_box(&states[k]);
                k = (k + 1) % states.len();
                f(s)
            })
        });
    };
    bench("inverse_dynamics", &|s| {
        r.inverse_dynamics(&s.q, &s.v, &s.a)[0]
    });
    bench("mass_matrix", &|s| r.mass_matrix(&s.q)[0][0]);
    bench("bias_plus_gravity", &|s| {
        r.bias(&s.q, &s.v)[0] + r.gravity(&s.q)[0]
    });
    bench("gravity", &|s| r.gravity(&s.q)[0]);
    bench("coriolis_matrix", &|s| r.coriolis_matrix(&s.q, &s.v)[0][0]);
    bench("forward_dynamics", &|s| {
        r.forward_dynamics(&s.q, &s.v, &s.tau)[0]
    });
    bench("center_of_mass", &|s| r.center_of_mass(&s.q)[0]);
    bench("centroidal_map", &|s| r.centroidal_map(&s.q)[0][0]);
    bench("contact_forward_dynamics", &|s| {
        let (a, f) = r.contact_forward_dynamics(&s.q, &s.v, &s.tau);
        a[0] + f[0]
    });
    let d = AnymalDerivatives::<f64>::default();
    bench("inverse_dynamics_derivatives", &|s| {
        let (dq, dv) = d.inverse_dynamics_derivatives(&s.q, &s.v, &s.a);
        dq[0][0] + dv[17][17]
    });
    bench("forward_dynamics_derivatives", &|s| {
        let (dq, dv, minv) = d.forward_dynamics_derivatives(&s.q, &s.v, &s.tau);
        dq[0][0] + dv[17][17] + minv[0][17]
    });
    bench("mass_matrix_inverse", &|s| {
        d.mass_matrix_inverse(&s.q)[0][17]
    });
    g.finish();
}

criterion_group!(benches, anymal);
criterion_main!(benches);
