//! Computed-torque control of a UR5 in single precision on a Cortex-M4F.
//!
//! Each 1 ms tick the controller computes, with the eomgen-generated `Ur5<f32>`,
//!
//! ```text
//! u   = r''(t) + KP (r(t) - q) + KD (r'(t) - qd)      commanded acceleration
//! tau = M(q) u + b(q, qd) + g(q)                       computed torque
//! ```
//!
//! and the simulated plant (the same generated model) integrates `qdd = forward_dynamics(q, qd,
//! tau)` with semi-implicit Euler. `r` is a sum of sinusoids. The tracking error is reported
//! over semihosting, and the program exits with success only if, after the transient, every
//! joint's error stays below the bound derived below.
//!
//! # Why the error must converge, and to what
//! With an exact model `qdd = u`, so the error `e = r - q` obeys `e'' + KD e' + KP e = 0`:
//! critically damped (`KP = wn^2`, `KD = 2 wn`, `wn = 20 rad/s`), it decays like
//! `(1 + wn t) e^(-wn t)`. The initial error (0.1 rad, and up to 1.5 rad/s since the arm starts at
//! rest) is below 1e-15 rad after 2 s, when checking starts. What remains is bounded by three
//! disturbances, each passed through the error dynamics, whose impulse response
//! `t e^(-wn t)` is non-negative, so its peak gain from a bounded acceleration disturbance to
//! `e` is its DC gain `1 / KP`:
//!
//! 1. Time discretization. Semi-implicit Euler (`qd += dt u; q += dt qd`) against the exact
//!    reference gives, to first order in `dt`, `e'' + KD e' + KP e = -(dt/2) KD r''(t)` (the
//!    `r'''` terms of the velocity and position truncation errors cancel). With
//!    `|r''| <= A w^2` this is at most `(dt/2) KD A w^2 / KP` per joint: 2.25e-4 rad for the
//!    fastest joint (A = 0.5 rad, w = 3 rad/s), 2.5e-5 rad for the slowest.
//! 2. f32 model error. The controller's `M u + b + g` and the plant's `forward_dynamics` are
//!    both evaluated in f32, so `qdd - u` is not exactly zero. This program measures
//!    `|qdd - u|` every tick and fails if it exceeds `MODEL_BUDGET` = 0.02 rad/s^2, which
//!    contributes at most `MODEL_BUDGET / KP` = 5e-5 rad. The budget is a pessimistic estimate
//!    of the f32 round trip: relative precision 6e-8, amplified by the condition number of
//!    `M(q)` (below 1e3 for the UR5 here) and applied to accelerations `M^-1 tau` of up to
//!    ~100 rad/s^2, gives ~6e-3 rad/s^2. The measured maximum is about 6e-5 rad/s^2.
//! 3. f32 state rounding. Each step rounds `q` (|q| < 4 rad, so by at most half an ulp of 4,
//!    2.4e-7 rad) and `qd` (|qd| < 2 rad/s: 1.2e-7 rad/s). Worst case (always rounding the same
//!    way) that is a velocity disturbance of 2.4e-4 rad/s and an acceleration disturbance of
//!    1.2e-4 rad/s^2, i.e. at most `(KD 2.4e-4 + 1.2e-4) / KP` = 2.4e-5 rad.
//!
//! The bound per joint is the sum, plus 10% for the first-order approximations (`wn dt` =
//! 0.02): 3.3e-4 rad for the fastest joint. An error that does not converge (a wrong model, a
//! sign error, f32 trouble, a broken solver) exceeds it by orders of magnitude.
//!
//! # Timing
//! QEMU runs with `-icount shift=0`: its virtual clock advances 1 ns per executed instruction,
//! and the board's SysTick counts at 25 MHz of that clock, so one SysTick count is 40
//! instructions. The per-tick instruction counts printed are therefore QEMU's, a rough proxy
//! for Cortex-M4 cycles (most M4 instructions, FPU ones included, take one or two cycles).

#![no_std]
#![no_main]

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::{Peripherals, SYST};
use cortex_m_rt::entry;
use cortex_m_semihosting::{debug, hprintln};
use eomgen_generated::iris_simple::IrisSimple;
use eomgen_generated::ur5::Ur5;
use eomgen_runtime::prelude::*;
use panic_semihosting as _;

/// Joints of the UR5.
const N: usize = 6;
/// Control and integration period: 1 kHz, a common rate for joint-level control.
const DT: f32 = 1e-3;
/// Simulated duration: 4 s.
const TICKS: u32 = 4000;
/// Error checking starts after the transient has died out (2 s = 40 time constants).
const CHECK_FROM: u32 = 2000;
/// Closed-loop natural frequency, rad/s; `WN * DT` = 0.02 keeps the discretization small.
const WN: f32 = 20.0;
const KP: f32 = WN * WN;
const KD: f32 = 2.0 * WN;

/// The reference `r_i(t) = CENTER_i + AMPLITUDE_i sin(OMEGA_i t)`: a typical UR5 working pose
/// (elbow bent, wrist down) with every joint swinging at its own frequency.
const CENTER: [f32; N] = [0.0, -1.2, 1.4, -1.8, -1.5, 0.0];
const AMPLITUDE: [f32; N] = [0.5; N];
const OMEGA: [f32; N] = [1.0, 1.4, 1.8, 2.2, 2.6, 3.0];
/// The arm starts at rest, this far from the reference.
const INITIAL_OFFSET: [f32; N] = [0.1, -0.1, 0.1, -0.1, 0.1, -0.1];

/// Allowed `|qdd - u|` (plant acceleration minus commanded), rad/s^2: see the crate docs.
const MODEL_BUDGET: f32 = 0.02;
/// Worst-case f32 rounding of the state per step: half an ulp of 4 rad and of 2 rad/s.
const Q_ROUNDING: f32 = 2.4e-7;
const QD_ROUNDING: f32 = 1.2e-7;
/// SysTick counts per executed instruction under `-icount shift=0` (25 MHz vs 1 GHz).
const INSTRUCTIONS_PER_SYSTICK: u32 = 40;

/// The tracking-error bound for joint `i` after the transient (crate docs, items 1 to 3).
fn error_bound(i: usize) -> f32 {
    let w2 = OMEGA[i] * OMEGA[i];
    let discretization = 0.5 * DT * KD * AMPLITUDE[i] * w2 / KP;
    let model = MODEL_BUDGET / KP;
    let rounding = (KD * Q_ROUNDING / DT + QD_ROUNDING / DT) / KP;
    1.1 * (discretization + model + rounding)
}

/// `(r(t), r'(t), r''(t))`.
fn reference(t: f32) -> ([f32; N], [f32; N], [f32; N]) {
    let (mut r, mut rd, mut rdd) = ([0.0; N], [0.0; N], [0.0; N]);
    for i in 0..N {
        let (s, c) = (OMEGA[i] * t).sin_cos();
        r[i] = CENTER[i] + AMPLITUDE[i] * s;
        rd[i] = AMPLITUDE[i] * OMEGA[i] * c;
        rdd[i] = -AMPLITUDE[i] * OMEGA[i] * OMEGA[i] * s;
    }
    (r, rd, rdd)
}

/// Computed torque: `tau = M(q) u + b(q, qd) + g(q)`.
fn computed_torque(robot: &Ur5<f32>, q: &[f32; N], qd: &[f32; N], u: &[f32; N]) -> [f32; N] {
    let m = robot.mass_matrix(q);
    let b = robot.bias(q, qd);
    let g = robot.gravity(q);
    let mut tau = [0.0; N];
    for i in 0..N {
        let mut mu = 0.0;
        for j in 0..N {
            mu += m[i][j] * u[j];
        }
        tau[i] = mu + b[i] + g[i];
    }
    tau
}

/// SysTick counts since `start` (it counts down from 2^24 - 1 and wraps).
fn elapsed(start: u32) -> u32 {
    start.wrapping_sub(SYST::get_current()) & 0x00ff_ffff
}

fn max_abs(v: &[f32; N]) -> f32 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

/// What a closed-loop run of the UR5 leaves to check: its final state, the worst tracking error
/// per joint after the transient, the worst `|qdd - u|`, and the SysTick counts of the
/// controller and the plant (sums and maxima over the ticks).
struct Tracking {
    q: [f32; N],
    qd: [f32; N],
    worst: [f32; N],
    worst_model: f32,
    controller: (u64, u32),
    plant: (u64, u32),
}

/// Runs the computed-torque loop for `TICKS` ticks from the reference's start plus
/// `INITIAL_OFFSET`, at rest, printing the tracking error every half second.
fn track(robot: &Ur5<f32>) -> Tracking {
    let (r0, _, _) = reference(0.0);
    let mut run = Tracking {
        q: core::array::from_fn(|i| r0[i] + INITIAL_OFFSET[i]),
        qd: [0.0; N],
        worst: [0.0; N],
        worst_model: 0.0,
        controller: (0, 0),
        plant: (0, 0),
    };
    for k in 0..TICKS {
        let t = k as f32 * DT;
        let (r, rd, rdd) = reference(t);
        let e: [f32; N] = core::array::from_fn(|i| r[i] - run.q[i]);
        let ed: [f32; N] = core::array::from_fn(|i| rd[i] - run.qd[i]);

        if k >= CHECK_FROM {
            for (w, ei) in run.worst.iter_mut().zip(&e) {
                *w = w.max(ei.abs());
            }
        }
        if k % 500 == 0 {
            hprintln!(
                "t = {:.3} s  max|e| = {:.3e} rad  max|e'| = {:.3e} rad/s",
                t,
                max_abs(&e),
                max_abs(&ed)
            );
        }

        let start = SYST::get_current();
        let u: [f32; N] = core::array::from_fn(|i| rdd[i] + KP * e[i] + KD * ed[i]);
        let tau = computed_torque(robot, &run.q, &run.qd, &u);
        let controller = elapsed(start);

        let start = SYST::get_current();
        let qdd = robot.forward_dynamics(&run.q, &run.qd, &tau);
        let plant = elapsed(start);

        for i in 0..N {
            run.worst_model = run.worst_model.max((qdd[i] - u[i]).abs());
            run.qd[i] += DT * qdd[i];
            run.q[i] += DT * run.qd[i];
        }
        run.controller = (
            run.controller.0 + controller as u64,
            run.controller.1.max(controller),
        );
        run.plant = (run.plant.0 + plant as u64, run.plant.1.max(plant));
    }
    run
}

fn run() -> bool {
    let mut core = Peripherals::take().expect("peripherals taken once");
    core.SYST.set_clock_source(SystClkSource::Core);
    core.SYST.set_reload(0x00ff_ffff);
    core.SYST.clear_current();
    core.SYST.enable_counter();

    hprintln!(
        "eomgen firmware: computed-torque control of Ur5<f32>, {} joints, dt = {} s, {} ticks, \
         KP = {}, KD = {}",
        N,
        DT,
        TICKS,
        KP,
        KD
    );
    let run = track(&Ur5::<f32>::default());
    let (r, _, _) = reference(TICKS as f32 * DT);
    let final_error: [f32; N] = core::array::from_fn(|i| r[i] - run.q[i]);
    hprintln!(
        "t = {:.3} s  max|e| = {:.3e} rad (final)",
        TICKS as f32 * DT,
        max_abs(&final_error)
    );
    report(&run)
}

/// Prints the checks of a run (a finite state, each joint's error within its bound, the model
/// round trip within its budget) and the instruction counts; whether every check held.
fn report(run: &Tracking) -> bool {
    // A NaN anywhere propagates to the state for good (and `max` above skips NaNs).
    let mut ok = run.q.iter().chain(run.qd.iter()).all(|x| x.is_finite());
    if !ok {
        hprintln!(
            "the state is not finite: q = {:?}, qd = {:?}",
            run.q,
            run.qd
        );
    }
    hprintln!(
        "after the transient (t >= {} s), per joint: max|e| / bound",
        CHECK_FROM as f32 * DT
    );
    for (i, (name, worst)) in <Ur5<f32> as Dynamics<f32, N>>::JOINT_NAMES
        .iter()
        .zip(run.worst)
        .enumerate()
    {
        let bound = error_bound(i);
        let joint_ok = worst <= bound;
        ok &= joint_ok;
        hprintln!(
            "  {:<20} {:.3e} / {:.3e} rad  {}",
            name,
            worst,
            bound,
            if joint_ok { "ok" } else { "EXCEEDED" }
        );
    }
    let model_ok = run.worst_model <= MODEL_BUDGET;
    ok &= model_ok;
    hprintln!(
        "max |qdd - u| (f32 model round trip) = {:.3e} rad/s^2, budget {:.1e}  {}",
        run.worst_model,
        MODEL_BUDGET,
        if model_ok { "ok" } else { "EXCEEDED" }
    );
    let per_tick = |counts: u64| counts * INSTRUCTIONS_PER_SYSTICK as u64 / TICKS as u64;
    hprintln!(
        "instructions per tick (QEMU icount): controller (M, b, g, M u) {} avg / {} max, \
         plant (forward_dynamics) {} avg / {} max",
        per_tick(run.controller.0),
        run.controller.1 * INSTRUCTIONS_PER_SYSTICK,
        per_tick(run.plant.0),
        run.plant.1 * INSTRUCTIONS_PER_SYSTICK
    );
    hprintln!(
        "tracking error {:.3e} rad at start, {:.3e} rad worst after {} s: {}",
        max_abs(&INITIAL_OFFSET),
        run.worst.iter().fold(0.0_f32, |m, x| m.max(*x)),
        CHECK_FROM as f32 * DT,
        if ok { "PASS" } else { "FAIL" }
    );
    ok
}

/// A floating base in f32: the iris drone (one free body) hovers back to the origin from 0.2 m
/// away and tilted by 0.2 rad, under a wrench controller that is computed torque on the base,
/// `tau = inverse_dynamics(q, v, a_des)` with `a_des` a PD on position and attitude; the plant
/// integrates `forward_dynamics` with semi-implicit Euler on SE(3) (`integrate`). Passes when the
/// position error is below 1 mm after 3 s and the quaternion stays unit.
fn hover() -> bool {
    let drone = IrisSimple::<f32>::default();
    // A 0.2 rad tilt about x: the quaternion (sin 0.1, 0, 0, cos 0.1).
    let (s, c) = 0.1_f32.sin_cos();
    let mut q = [0.2, -0.1, 0.15, s, 0.0, 0.0, c];
    let mut v = [0.0_f32; 6];
    let (kp, kd) = (16.0_f32, 8.0_f32);
    for _ in 0..3000 {
        // World position error and velocity, then the wanted acceleration in base axes.
        let r = eomgen_runtime::free_flyer::rotation(&[q[3], q[4], q[5], q[6]]);
        let vw: [f32; 3] = core::array::from_fn(|i| (0..3).map(|k| r[i][k] * v[k]).sum());
        let aw: [f32; 3] = core::array::from_fn(|i| -kp * q[i] - kd * vw[i]);
        let sign = if q[6] < 0.0 { -1.0 } else { 1.0 };
        let mut a = [0.0_f32; 6];
        for i in 0..3 {
            a[i] = (0..3).map(|k| r[k][i] * aw[k]).sum();
            a[3 + i] = -kp * 2.0 * sign * q[3 + i] - kd * v[3 + i];
        }
        let tau = drone.inverse_dynamics(&q, &v, &a);
        let qdd = drone.forward_dynamics(&q, &v, &tau);
        for i in 0..6 {
            v[i] += DT * qdd[i];
        }
        q = drone.integrate(&q, &v, DT);
    }
    let error = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
    let norm = q[3..7].iter().map(|x| x * x).sum::<f32>();
    let ok = error < 1e-3 && (norm - 1.0).abs() < 1e-5 && q[3..6].iter().all(|x| x.abs() < 1e-3);
    hprintln!(
        "floating base (iris, f32): position error {:.2e} m after 3 s, |quaternion|^2 - 1 = {:.1e}: {}",
        error,
        norm - 1.0,
        if ok { "PASS" } else { "FAIL" }
    );
    ok
}

#[entry]
fn main() -> ! {
    let ok = run() & hover();
    debug::exit(if ok {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
    // Only reached without a debugger or semihosting host.
    loop {
        cortex_m::asm::bkpt();
    }
}
