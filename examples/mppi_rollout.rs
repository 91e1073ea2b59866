//! An MPPI-style rollout of a 7-joint arm: `SAMPLES` noisy torque sequences over `HORIZON`
//! steps, each rolled out by forward dynamics and semi-implicit Euler, scored by how far the
//! arm ends from a target, and averaged with weights `exp(-cost / lambda)` into the next
//! nominal torques, as sampling-based model-predictive control does every control period.
//!
//! The rollout is run twice: state by state with the scalar `forward_dynamics`, and all samples
//! at once per step with `forward_dynamics_batch` (SIMD lanes: `f64x4` with AVX; over every
//! core with the `rayon` feature). Both give the same costs (to rounding: `wide`'s sine and
//! cosine differ from `libm`'s in the last bits), and the times are printed.
//!
//!     RUSTFLAGS="-C target-cpu=native" cargo run --release --example mppi_rollout
//!     RUSTFLAGS="-C target-cpu=native" cargo run --release --example mppi_rollout --features rayon

#[path = "mppi/common.rs"]
mod common;

use common::{iterate, noise, update};
use eomgen_examples::{PandaArm, READY};
use eomgen_runtime::prelude::*;

const SAMPLES: usize = 512;
const HORIZON: usize = 50;
const DT: f64 = 0.01;
const TARGET: [f64; 7] = [0.5, 0.2, -0.3, -1.8, 0.4, 1.6, 0.0];

/// Sample `k`'s torques at step `t`: the nominal torques plus noise (N m).
fn torque(nominal: &[[f64; 7]], eps: &[f64], k: usize, t: usize) -> [f64; 7] {
    core::array::from_fn(|j| nominal[t][j] + 5.0 * eps[(k * HORIZON + t) * 7 + j])
}

/// Squared distance from the target, and a little velocity.
fn cost(q: &[f64; 7], qd: &[f64; 7]) -> f64 {
    (0..7)
        .map(|j| (q[j] - TARGET[j]).powi(2) + 1e-3 * qd[j] * qd[j])
        .sum()
}

/// One semi-implicit Euler step of every state.
fn step(q: &mut [[f64; 7]], qd: &mut [[f64; 7]], qdd: &[[f64; 7]]) {
    for ((q, qd), a) in q.iter_mut().zip(qd.iter_mut()).zip(qdd) {
        for j in 0..7 {
            qd[j] += DT * a[j];
            q[j] += DT * qd[j];
        }
    }
}

/// Every sample's cost, state by state.
fn scalar(robot: &PandaArm<f64>, nominal: &[[f64; 7]], eps: &[f64]) -> Vec<f64> {
    (0..SAMPLES)
        .map(|k| {
            let (mut q, mut qd, mut total) = (READY, [0.0; 7], 0.0);
            for t in 0..HORIZON {
                let qdd = robot.forward_dynamics(&q, &qd, &torque(nominal, eps, k, t));
                step(
                    core::slice::from_mut(&mut q),
                    core::slice::from_mut(&mut qd),
                    &[qdd],
                );
                total += cost(&q, &qd);
            }
            total
        })
        .collect()
}

/// Every sample's cost, all samples per step through `forward_dynamics_batch`.
fn batch(robot: &PandaArm<f64>, nominal: &[[f64; 7]], eps: &[f64]) -> Vec<f64> {
    let (mut q, mut qd) = (vec![READY; SAMPLES], vec![[0.0; 7]; SAMPLES]);
    let (mut tau, mut qdd) = (vec![[0.0; 7]; SAMPLES], vec![[0.0; 7]; SAMPLES]);
    let mut total = vec![0.0; SAMPLES];
    for t in 0..HORIZON {
        for (k, tk) in tau.iter_mut().enumerate() {
            *tk = torque(nominal, eps, k, t);
        }
        robot
            .forward_dynamics_batch(&q, &qd, &tau, &mut qdd)
            .expect("slices of SAMPLES states");
        step(&mut q, &mut qd, &qdd);
        for (c, (q, qd)) in total.iter_mut().zip(q.iter().zip(&qd)) {
            *c += cost(q, qd);
        }
    }
    total
}

fn main() {
    let robot = PandaArm::<f64>::default();
    // Start from gravity compensation at the start configuration.
    let mut nominal = vec![robot.gravity(&READY); HORIZON];
    println!(
        "{SAMPLES} samples x {HORIZON} steps of forward dynamics ({} states per iteration)",
        SAMPLES * HORIZON
    );
    for iteration in 0..5 {
        let eps = noise(iteration + 1, SAMPLES * HORIZON * 7);
        let (costs, _) = iterate(
            iteration,
            1e-9,
            || scalar(&robot, &nominal, &eps),
            || batch(&robot, &nominal, &eps),
        );
        nominal = update(HORIZON, &costs, 10.0, |k, t| torque(&nominal, &eps, k, t));
    }
}
