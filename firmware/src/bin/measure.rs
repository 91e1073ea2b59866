//! Stack use and instruction counts of every generated function, run under QEMU by
//! `measure.sh`, which also reads the flash size of each function from this ELF's symbols.
//!
//! One reference robot per build, selected by its cargo feature (`--features ur5`). Every
//! function of that robot, in f32 and in f64, gets a wrapper with a fixed
//! symbol name, `eomgen_<robot>_<scalar>_<function>`, that takes its inputs by reference and
//! writes its result through a pointer (so the wrapper adds no copy of its own). Wrappers are
//! `#[inline(never)]` and exported, so each one is a single symbol holding the function's code
//! (or calling the parts that the compiler kept out of line; `measure.sh` follows those calls),
//! and the compiler cannot specialize it for the inputs used here.
//!
//! For each wrapper this program
//! - paints the free stack below the current stack pointer with a pattern, calls the wrapper
//!   once, and finds the deepest word that no longer holds the pattern: the stack used by the
//!   call, including everything it calls (a word that a callee reserves but never writes is not
//!   seen, so this is exact up to such padding);
//! - counts the instructions of one call with SysTick under `-icount shift=0` (QEMU's virtual
//!   clock then advances 1 ns per instruction), calibrated at start-up against a loop of known
//!   length.
//!
//! Both figures have the cost of an empty call through the same path subtracted.
//! `link_pose` and `link_jacobian` take the link as an argument: their figures are the maximum
//! over all links. Each result is printed as one line,
//! `MEASURE <robot> <scalar> <function> <stack bytes> <instructions>`.

#![no_std]
#![no_main]

#[cfg(not(any(
    feature = "double_pendulum",
    feature = "ur5",
    feature = "panda",
    feature = "kinova",
    feature = "allegro_right_hand"
)))]
compile_error!("select the robot to measure with its cargo feature, e.g. `--features ur5`");

use core::arch::asm;
use core::hint::black_box;
use core::mem::MaybeUninit;
use core::ptr::{addr_of, read_volatile, write_volatile};

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::{Peripherals, SYST};
use cortex_m_rt::entry;
use cortex_m_semihosting::{debug, hprintln};
use eomgen_runtime::{Dynamics, Pose, Real};
use panic_semihosting as _;

/// How far below the stack pointer the stack is painted. Far more than any function uses; a
/// function that reaches the bottom is reported as failing.
const PAINT_DEPTH: usize = 512 * 1024;
const PAINT: u32 = 0xdead_beef;

/// The inputs of every wrapper: a state and an acceleration or effort.
pub struct State<T, const N: usize> {
    q: [T; N],
    qd: [T; N],
    /// `qdd` for `inverse_dynamics`, `tau` for `forward_dynamics`.
    x: [T; N],
}

/// A state away from zero, so that no term vanishes (angles of a few tenths of a radian).
fn state<T: Real, const N: usize>() -> State<T, N> {
    let f = |i: usize, a: f64, b: f64| T::from_f64(a * (i as f64 + 1.0).sin() + b);
    State {
        q: core::array::from_fn(|i| f(i, 0.7, 0.1)),
        qd: core::array::from_fn(|i| f(i + 3, 0.9, -0.2)),
        x: core::array::from_fn(|i| f(i + 7, 2.0, 0.5)),
    }
}

/// What a measured call is run with: `probe(&mut || wrapper(...))`.
type Probe<'a> = &'a mut dyn FnMut(&mut dyn FnMut());

/// One measured function: its name and how to call its wrapper for link `link` (ignored by
/// the functions without a link argument) under a probe.
struct Entry {
    robot: &'static str,
    scalar: &'static str,
    function: &'static str,
    links: usize,
    call: fn(usize, Probe),
}

/// Defines the wrapper of one function and returns its [`Entry`].
macro_rules! wrapper {
    ($module:ident, $n:literal, $t:ident, $name:ident, $out:ty, $links:expr,
     |$r:ident, $s:ident, $l:ident| $body:expr) => {{
        #[inline(never)]
        #[export_name = concat!("eomgen_", stringify!($module), "_", stringify!($t), "_", stringify!($name))]
        extern "C" fn wrapper($s: &State<$t, $n>, $l: usize, out: &mut MaybeUninit<$out>) {
            let $r = R::default();
            let _ = $l;
            out.write($body);
        }
        fn call(link: usize, probe: Probe) {
            let s = state::<$t, $n>();
            let mut out = MaybeUninit::<$out>::uninit();
            probe(&mut || wrapper(black_box(&s), black_box(link), black_box(&mut out)));
        }
        Entry {
            robot: stringify!($module),
            scalar: stringify!($t),
            function: stringify!($name),
            links: $links,
            call,
        }
    }};
}

/// The entries of every function of one robot and scalar type.
macro_rules! robot {
    ($module:ident, $ty:ident, $link:ident, $n:literal, $t:ident) => {{
        type R = eomgen_generated::$module::$ty<$t>;
        type L = eomgen_generated::$module::$link;
        const ALL_LINKS: usize = L::ALL.len();
        [
            wrapper! { $module, $n, $t, mass_matrix, [[$t; $n]; $n], 1, |r, s, l| r.mass_matrix(&s.q) },
            wrapper! { $module, $n, $t, gravity, [$t; $n], 1, |r, s, l| r.gravity(&s.q) },
            wrapper! { $module, $n, $t, bias, [$t; $n], 1, |r, s, l| r.bias(&s.q, &s.qd) },
            wrapper! { $module, $n, $t, coriolis_matrix, [[$t; $n]; $n], 1, |r, s, l| r.coriolis_matrix(&s.q, &s.qd) },
            wrapper! { $module, $n, $t, inverse_dynamics, [$t; $n], 1, |r, s, l| r.inverse_dynamics(&s.q, &s.qd, &s.x) },
            wrapper! { $module, $n, $t, forward_dynamics, [$t; $n], 1, |r, s, l| r.forward_dynamics(&s.q, &s.qd, &s.x) },
            wrapper! { $module, $n, $t, kinetic_energy, $t, 1, |r, s, l| r.kinetic_energy(&s.q, &s.qd) },
            wrapper! { $module, $n, $t, potential_energy, $t, 1, |r, s, l| r.potential_energy(&s.q) },
            wrapper! { $module, $n, $t, centrifugal, [[$t; $n]; $n], 1, |r, s, l| r.centrifugal(&s.q) },
            wrapper! { $module, $n, $t, coriolis_pairs, [[$t; $n * ($n - 1) / 2]; $n], 1, |r, s, l| r.coriolis_pairs(&s.q) },
            wrapper! { $module, $n, $t, link_pose, Pose<$t>, ALL_LINKS, |r, s, l| r.link_pose(L::ALL[l], &s.q) },
            wrapper! { $module, $n, $t, link_jacobian, [[$t; $n]; 6], ALL_LINKS, |r, s, l| r.link_jacobian(L::ALL[l], &s.q) },
        ]
    }};
}

/// A wrapper that computes nothing, called like the others: the baseline.
#[inline(never)]
#[export_name = "eomgen_null"]
extern "C" fn null_wrapper(_s: &State<f32, 2>, _l: usize, out: &mut MaybeUninit<f32>) {
    out.write(0.0);
}

fn null_call(link: usize, probe: Probe) {
    let s = state::<f32, 2>();
    let mut out = MaybeUninit::<f32>::uninit();
    probe(&mut || null_wrapper(black_box(&s), black_box(link), black_box(&mut out)));
}

extern "C" {
    /// The lowest address the stack may grow to (end of `.bss`), from cortex-m-rt's `link.x`.
    static _stack_end: u32;
}

/// The stack bytes used by `f()`, measured by painting. `None` if it used the whole painted
/// region (it may have used more).
#[inline(never)]
fn stack_use(f: &mut dyn FnMut()) -> Option<usize> {
    let sp: usize;
    // SAFETY: reads the stack pointer.
    unsafe { asm!("mov {}, sp", out(reg) sp, options(nomem, nostack, preserves_flags)) };
    let limit = addr_of!(_stack_end) as usize;
    let bottom = sp
        .saturating_sub(PAINT_DEPTH)
        .max(limit.next_multiple_of(4));
    // SAFETY: the words between the end of `.bss` and the stack pointer belong to no one: they
    // are the unused part of the stack, and nothing (no interrupt is enabled) pushes onto it
    // while this function runs except the call of `f` itself.
    unsafe {
        for a in (bottom..sp).step_by(4) {
            write_volatile(a as *mut u32, PAINT);
        }
    }
    f();
    // SAFETY: as above.
    let lowest = (bottom..sp)
        .step_by(4)
        .find(|&a| unsafe { read_volatile(a as *const u32) } != PAINT)
        .unwrap_or(sp);
    (lowest > bottom).then_some(sp - lowest)
}

/// SysTick counts taken by `reps` calls of `f` (SysTick counts down from 2^24 - 1 and wraps;
/// the counts measured here are far below 2^24).
#[inline(never)]
fn systick_counts(f: &mut dyn FnMut(), reps: u32) -> u32 {
    let start = SYST::get_current();
    for _ in 0..reps {
        f();
    }
    start.wrapping_sub(SYST::get_current()) & 0x00ff_ffff
}

/// Instructions per SysTick count: times a loop of a known number of instructions.
fn calibrate() -> f64 {
    const ITERATIONS: u32 = 1_000_000;
    let start = SYST::get_current();
    // SAFETY: a register-only countdown loop, two instructions per iteration.
    unsafe {
        asm!("2:", "subs {0}, {0}, #1", "bne 2b", inout(reg) ITERATIONS => _,
            options(nomem, nostack));
    }
    let counts = start.wrapping_sub(SYST::get_current()) & 0x00ff_ffff;
    2.0 * ITERATIONS as f64 / counts as f64
}

/// Instructions of one call of `f` (less `baseline`), repeated enough times that the SysTick
/// resolution is below one part in a thousand.
fn instructions(f: &mut dyn FnMut(), per_count: f64, baseline: f64) -> f64 {
    let once = systick_counts(f, 1).max(1);
    let reps = (2000 / once).clamp(1, 1000);
    let counts = systick_counts(f, reps);
    counts as f64 * per_count / reps as f64 - baseline
}

fn run() -> bool {
    let mut core = Peripherals::take().expect("peripherals taken once");
    core.SYST.set_clock_source(SystClkSource::Core);
    core.SYST.set_reload(0x00ff_ffff);
    core.SYST.clear_current();
    core.SYST.enable_counter();

    let per_count = calibrate();
    hprintln!(
        "CALIBRATION instructions per SysTick count: {:.3}",
        per_count
    );

    // The overhead of the measuring path itself: the same path to a wrapper that does nothing.
    let (mut stack_baseline, mut instr_baseline) = (0, 0.0);
    null_call(0, &mut |f| stack_baseline = stack_use(f).unwrap_or(0));
    null_call(0, &mut |f| instr_baseline = instructions(f, per_count, 0.0));
    hprintln!(
        "BASELINE stack {} bytes, {:.0} instructions",
        stack_baseline,
        instr_baseline
    );

    measure_robots(per_count, (stack_baseline, instr_baseline))
}

/// Measures the robot this build was made for (its cargo feature), in f32 then f64; false if
/// an entry overflowed the painted stack.
fn measure_robots(per_count: f64, baseline: (usize, f64)) -> bool {
    let mut ok = true;
    // One robot per build (a cargo feature each; see Cargo.toml), f32 then f64.
    #[cfg(feature = "double_pendulum")]
    {
        ok &= measure(
            &robot!(double_pendulum, DoublePendulum, DoublePendulumLink, 2, f32),
            per_count,
            baseline,
        );
        ok &= measure(
            &robot!(double_pendulum, DoublePendulum, DoublePendulumLink, 2, f64),
            per_count,
            baseline,
        );
    }
    #[cfg(feature = "ur5")]
    {
        ok &= measure(&robot!(ur5, Ur5, Ur5Link, 6, f32), per_count, baseline);
        ok &= measure(&robot!(ur5, Ur5, Ur5Link, 6, f64), per_count, baseline);
    }
    #[cfg(feature = "panda")]
    {
        ok &= measure(
            &robot!(panda, Panda, PandaLink, 9, f32),
            per_count,
            baseline,
        );
        ok &= measure(
            &robot!(panda, Panda, PandaLink, 9, f64),
            per_count,
            baseline,
        );
    }
    #[cfg(feature = "kinova")]
    {
        ok &= measure(
            &robot!(kinova, Kinova, KinovaLink, 6, f32),
            per_count,
            baseline,
        );
        ok &= measure(
            &robot!(kinova, Kinova, KinovaLink, 6, f64),
            per_count,
            baseline,
        );
    }
    #[cfg(feature = "allegro_right_hand")]
    {
        ok &= measure(
            &robot!(
                allegro_right_hand,
                AllegroRightHand,
                AllegroRightHandLink,
                16,
                f32
            ),
            per_count,
            baseline,
        );
        ok &= measure(
            &robot!(
                allegro_right_hand,
                AllegroRightHand,
                AllegroRightHandLink,
                16,
                f64
            ),
            per_count,
            baseline,
        );
    }
    ok
}

/// Measures and prints every entry; false if one overflowed the painted stack.
fn measure(
    entries: &[Entry],
    per_count: f64,
    (stack_baseline, instr_baseline): (usize, f64),
) -> bool {
    let mut ok = true;
    for e in entries {
        let (mut stack, mut instr) = (0usize, 0.0f64);
        for link in 0..e.links {
            let mut used = None;
            (e.call)(link, &mut |f| used = Some(stack_use(f)));
            match used.flatten() {
                Some(bytes) => stack = stack.max(bytes - stack_baseline),
                None => {
                    hprintln!(
                        "{} {} {}: uses more than {} bytes of stack",
                        e.robot,
                        e.scalar,
                        e.function,
                        PAINT_DEPTH
                    );
                    ok = false;
                }
            }
            let mut count = 0.0;
            (e.call)(link, &mut |f| {
                count = instructions(f, per_count, instr_baseline)
            });
            instr = instr.max(count);
        }
        hprintln!(
            "MEASURE {} {} {} {} {:.0}",
            e.robot,
            e.scalar,
            e.function,
            stack,
            instr
        );
    }
    ok
}

#[entry]
fn main() -> ! {
    let ok = run();
    debug::exit(if ok {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
    loop {
        cortex_m::asm::bkpt();
    }
}
