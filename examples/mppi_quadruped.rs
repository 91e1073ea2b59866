//! MPPI on a quadruped standing on its four feet: `SAMPLES` noisy joint-torque sequences over
//! `HORIZON` steps, each rolled out with the feet held (contact forward dynamics, `M a + b + g =
//! S^T tau + J^T F`, `J a + Jdot v = 0`) and semi-implicit Euler on the configuration manifold
//! (`integrate`: the base on SE(3)), scored by how far the trunk is from a lower height and how
//! much it moves, and averaged with weights `exp(-cost / lambda)` into the next nominal torques.
//! A fixed contact schedule, as a sampling-based MPC of a standing or crouching robot runs it
//! every control period.
//!
//! The rollouts run twice: state by state with the scalar `contact_forward_dynamics` and
//! `integrate`, and all samples at once per step with `contact_forward_dynamics_batch` and
//! `integrate_batch` (SIMD lanes: `f64x4` with AVX; over every core with the `rayon` feature).
//! Both give the same costs (the lanes compute what the scalar code computes, bit for bit), the
//! mean cost falls from one iteration to the next, and the times are printed.
//!
//!     RUSTFLAGS="-C target-cpu=native" cargo run --release --example mppi_quadruped
//!     RUSTFLAGS="-C target-cpu=native" cargo run --release --example mppi_quadruped --features rayon

#[path = "mppi/common.rs"]
mod common;

use common::{iterate, noise, update};
use eomgen_examples::anymal::{Anymal, STANDING};
use eomgen_runtime::prelude::*;
use eomgen_runtime::StandOnContacts;

const SAMPLES: usize = 256;
const HORIZON: usize = 40;
const DT: f64 = 0.005;
/// The trunk's target height (m): 5 cm below the standing pose's.
const HEIGHT: f64 = 0.45;
/// The torque noise (N m).
const NOISE: f64 = 10.0;
/// MPPI's temperature: the cost difference that weighs a sample `1/e` of the best one.
const LAMBDA: f64 = 0.5;

/// Sample `k`'s efforts at step `t`: the nominal joint torques plus noise, none on the base.
fn torque(nominal: &[[f64; 18]], eps: &[f64], k: usize, t: usize) -> [f64; 18] {
    core::array::from_fn(|j| match j {
        0..6 => 0.0,
        _ => nominal[t][j] + NOISE * eps[(k * HORIZON + t) * 12 + j - 6],
    })
}

/// The trunk's squared height error and a little of every velocity.
fn cost(q: &[f64; 19], v: &[f64; 18]) -> f64 {
    100.0 * (q[2] - HEIGHT).powi(2) + 1e-3 * v.iter().map(|x| x * x).sum::<f64>()
}

/// Every sample's cost, state by state.
fn scalar(robot: &Anymal<f64>, nominal: &[[f64; 18]], eps: &[f64]) -> Vec<f64> {
    (0..SAMPLES)
        .map(|k| {
            let (mut q, mut v, mut total) = (STANDING, [0.0; 18], 0.0);
            for t in 0..HORIZON {
                let (a, _) = robot.contact_forward_dynamics(&q, &v, &torque(nominal, eps, k, t));
                for (vi, ai) in v.iter_mut().zip(a) {
                    *vi += DT * ai;
                }
                q = robot.integrate(&q, &v, DT);
                total += cost(&q, &v);
            }
            total
        })
        .collect()
}

/// Every sample's cost, all samples per step through the batch methods.
fn batch(robot: &Anymal<f64>, nominal: &[[f64; 18]], eps: &[f64]) -> Vec<f64> {
    let (mut q, mut v) = (vec![STANDING; SAMPLES], vec![[0.0; 18]; SAMPLES]);
    let (mut tau, mut a) = (vec![[0.0; 18]; SAMPLES], vec![[0.0; 18]; SAMPLES]);
    let (mut forces, mut next) = (vec![[0.0; 12]; SAMPLES], vec![[0.0; 19]; SAMPLES]);
    let mut total = vec![0.0; SAMPLES];
    for t in 0..HORIZON {
        for (k, tk) in tau.iter_mut().enumerate() {
            *tk = torque(nominal, eps, k, t);
        }
        robot
            .contact_forward_dynamics_batch(&q, &v, &tau, &mut a, &mut forces)
            .expect("slices of SAMPLES states");
        for (vk, ak) in v.iter_mut().zip(&a) {
            for (vi, ai) in vk.iter_mut().zip(ak) {
                *vi += DT * ai;
            }
        }
        robot
            .integrate_batch(&q, &v, DT, &mut next)
            .expect("slices of SAMPLES states");
        core::mem::swap(&mut q, &mut next);
        for (c, (q, v)) in total.iter_mut().zip(q.iter().zip(&v)) {
            *c += cost(q, v);
        }
    }
    total
}

fn main() {
    let robot = Anymal::<f64>::default();
    // Start from the torques that hold the standing pose (gravity through the contacts).
    let hold = StandOnContacts {
        target: STANDING,
        kp: 0.0,
        kd: 0.0,
    };
    let mut nominal = vec![hold.torque(&robot, &STANDING, &[0.0; 18]); HORIZON];
    println!(
        "anymal on four feet: {SAMPLES} samples x {HORIZON} steps of contact forward dynamics \
         ({} states per iteration)",
        SAMPLES * HORIZON
    );
    let mut means = Vec::new();
    for iteration in 0..6 {
        let eps = noise(iteration + 1, SAMPLES * HORIZON * 12);
        let (costs, mean) = iterate(
            iteration,
            0.0,
            || scalar(&robot, &nominal, &eps),
            || batch(&robot, &nominal, &eps),
        );
        means.push(mean);
        nominal = update(HORIZON, &costs, LAMBDA, |k, t| torque(&nominal, &eps, k, t));
    }
    assert!(
        means.iter().all(|m| m.is_finite()) && means[means.len() - 1] < 0.8 * means[0],
        "MPPI did not lower the cost: {means:?}"
    );
}
