//! Speed of the generated derivatives of the dynamics, f64, on the reference robots generated
//! with `Builder::derivatives` by `tests/build.rs`, named like `generated/benches/dynamics.rs`
//! (`<robot>/<function>`): compare with pinbench's computeRNEADerivatives and
//! computeABADerivatives on the same URDF in the same run.
//!
//!     RUSTFLAGS="-C target-cpu=native" cargo bench -p eomgen-tests --bench derivatives -- '^panda/'

#[path = "../../generated/benches/support/states.rs"]
mod states;

use criterion::{criterion_group, criterion_main, Criterion};
use eomgen_tests::robots::{
    allegro_derivatives::AllegroDerivatives, kinova_derivatives::KinovaDerivatives,
    panda_derivatives::PandaDerivatives, ur5_derivatives::Ur5Derivatives,
};
use states::{cycle, states};

macro_rules! bench_robot {
    ($c:expr, $group:literal, $ty:ty, $urdf:literal) => {{
        let robot = <$ty>::default();
        let states = states(&states::robot($urdf), &<$ty>::JOINT_NAMES);
        let mut g = $c.benchmark_group($group);
        cycle(&mut g, "inverse_dynamics", &states, |s| {
            robot.inverse_dynamics(&s.q, &s.qd, &s.qdd)
        });
        cycle(&mut g, "inverse_dynamics_derivatives", &states, |s| {
            robot.inverse_dynamics_derivatives(&s.q, &s.qd, &s.qdd)
        });
        cycle(&mut g, "forward_dynamics_derivatives", &states, |s| {
            robot.forward_dynamics_derivatives(&s.q, &s.qd, &s.tau)
        });
        cycle(&mut g, "mass_matrix_inverse", &states, |s| {
            robot.mass_matrix_inverse(&s.q)
        });
        g.finish();
    }};
}

fn ur5(c: &mut Criterion) {
    bench_robot!(c, "ur5", Ur5Derivatives, "ur5.urdf");
}

fn panda(c: &mut Criterion) {
    bench_robot!(c, "panda", PandaDerivatives, "panda.urdf");
}

fn kinova(c: &mut Criterion) {
    bench_robot!(c, "kinova", KinovaDerivatives, "kinova.urdf");
}

fn allegro_right_hand(c: &mut Criterion) {
    bench_robot!(
        c,
        "allegro_right_hand",
        AllegroDerivatives,
        "allegro_right_hand.urdf"
    );
}

criterion_group!(benches, ur5, panda, kinova, allegro_right_hand);
criterion_main!(benches);
