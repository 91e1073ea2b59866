//! A counting global allocator proves that generated functions never touch the heap.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::hint::black_box;
use std::sync::atomic::{AtomicUsize, Ordering};

use eomgen_runtime::Dynamics;
use eomgen_tests::robots::{allegro_right_hand, double_pendulum, kinova, panda, ur5};

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

thread_local! {
    // Only this thread's allocations count: the test harness allocates on its own threads.
    static COUNTING: Cell<bool> = const { Cell::new(false) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if COUNTING.with(Cell::get) {
            ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        }
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if COUNTING.with(Cell::get) {
            ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        }
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations made by `f` on this thread.
fn allocations(f: impl FnOnce()) -> usize {
    let before = ALLOCATIONS.load(Ordering::SeqCst);
    COUNTING.with(|c| c.set(true));
    f();
    COUNTING.with(|c| c.set(false));
    ALLOCATIONS.load(Ordering::SeqCst) - before
}

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
}
