//! A counting global allocator proves that generated functions never touch the heap.

use std::hint::black_box;

use eomgen_tests::alloc_counter::{allocations, Counting};

use eomgen_runtime::Dynamics;
use eomgen_tests::robots::{
    allegro_right_hand, double_pendulum, joint_effects_full, joint_effects_smooth, kinova, panda,
    ur5,
};

#[global_allocator]
static GLOBAL: Counting = Counting;

macro_rules! exercise {
    ($module:ident, $ty:ident, $link:ident, $n:literal, $t:ty) => {{
        let robot = $module::$ty::<$t>::default();
        let q: [$t; $n] = core::array::from_fn(|i| 0.1 * i as $t);
        let qd: [$t; $n] = core::array::from_fn(|i| 0.2 - 0.05 * i as $t);
        let a = allocations(|| {
            black_box(robot.mass_matrix(black_box(&q)));
            black_box(robot.gravity(black_box(&q)));
            black_box(robot.bias(black_box(&q), black_box(&qd)));
            black_box(robot.coriolis_matrix(black_box(&q), black_box(&qd)));
            black_box(robot.inverse_dynamics(black_box(&q), black_box(&qd), black_box(&qd)));
            black_box(robot.forward_dynamics(black_box(&q), black_box(&qd), black_box(&qd)));
            black_box(robot.kinetic_energy(black_box(&q), black_box(&qd)));
            black_box(robot.potential_energy(black_box(&q)));
            black_box(robot.centrifugal(black_box(&q)));
            black_box(robot.coriolis_pairs(black_box(&q)));
            for link in $module::$link::ALL {
                black_box(robot.link_pose(link, black_box(&q)));
                black_box(robot.link_jacobian(link, black_box(&q)));
                black_box(link.name());
            }
        });
        assert_eq!(a, 0, "{} allocated {a} times", stringify!($ty));
    }};
}

#[test]
fn generated_functions_never_allocate() {
    // The counter works: a Vec allocates.
    assert!(allocations(|| drop(black_box(vec![1u8; 16]))) > 0);
    exercise!(double_pendulum, DoublePendulum, DoublePendulumLink, 2, f64);
    exercise!(ur5, Ur5, Ur5Link, 6, f64);
    exercise!(panda, Panda, PandaLink, 9, f64);
    exercise!(kinova, Kinova, KinovaLink, 6, f64);
    exercise!(
        allegro_right_hand,
        AllegroRightHand,
        AllegroRightHandLink,
        16,
        f64
    );
    exercise!(panda, Panda, PandaLink, 9, f32);
    // With friction and rotor inertia, and the friction term itself.
    exercise!(
        joint_effects_full,
        JointEffectsFull,
        JointEffectsFullLink,
        2,
        f64
    );
    let smooth = joint_effects_smooth::JointEffectsSmooth::<f32>::default();
    let full = joint_effects_full::JointEffectsFull::<f64>::default();
    let a = allocations(|| {
        black_box(smooth.friction(black_box(&[0.1, -0.2])));
        black_box(full.friction(black_box(&[0.1, 0.0])));
    });
    assert_eq!(a, 0);
}

/// Contact and impulse dynamics for a set of active contacts, stabilized or not, and their
/// derivatives (anymal on its four feet): no heap either.
#[test]
fn active_contact_functions_never_allocate() {
    use eomgen_runtime::{Baumgarte, Pose};
    use eomgen_tests::robots::anymal_mpc::AnymalMpc;
    let robot = AnymalMpc::<f64>::default();
    let mut q: [f64; 19] = core::array::from_fn(|i| 0.1 * i as f64);
    q[3..7].copy_from_slice(&[0.0, 0.0, 0.0, 1.0]);
    let v: [f64; 18] = core::array::from_fn(|i| 0.2 - 0.05 * i as f64);
    let active = [true, false, true, true];
    let b = Baumgarte::new(100.0, 20.0, [Pose::identity(); 4]);
    let a = allocations(|| {
        black_box(robot.contact_forward_dynamics_active(&q, &v, &v, black_box(&active)));
        black_box(robot.contact_forward_dynamics_stabilized(&q, &v, &v, &active, black_box(&b)));
        black_box(robot.contact_forward_dynamics_derivatives_active(&q, &v, &v, &active));
        black_box(robot.impulse_dynamics_active(&q, &v, 0.5, black_box(&active)));
        black_box(robot.impulse_dynamics_derivatives_active(&q, &v, 0.5, &active));
        black_box(robot.contact_placements(black_box(&q)));
    });
    assert_eq!(a, 0, "the active contact functions allocated {a} times");
}
