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

#[path = "support/states.rs"]
mod states;

use criterion::{criterion_group, criterion_main, Criterion};
use eomgen_generated::allegro_right_hand::{AllegroRightHand, AllegroRightHandLink};
use eomgen_generated::double_pendulum::{DoublePendulum, DoublePendulumLink};
use eomgen_generated::kinova::{Kinova, KinovaLink};
use eomgen_generated::panda::{Panda, PandaLink};
use eomgen_generated::ur5::{Ur5, Ur5Link};
use eomgen_runtime::Dynamics;
use states::{cycle, states};

/// Every `Dynamics` function and the inherent ones of one robot, in group `$group`.
macro_rules! bench_robot {
    ($c:expr, $group:literal, $ty:ty, $urdf:literal, $ee:expr) => {{
        let robot = <$ty>::default();
        let states = states(
            &states::robot($urdf),
            &<$ty as Dynamics<f64, { <$ty>::DOF }>>::JOINT_NAMES,
        );
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
