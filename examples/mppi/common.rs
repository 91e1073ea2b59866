//! What the MPPI examples share (`mppi_rollout`, `mppi_quadruped`): deterministic noise, the
//! cost-weighted update of the nominal efforts, and the iterations that time the scalar and
//! the batch rollouts and check that they agree.

use std::time::Instant;

/// Deterministic noise in [-1, 1) (splitmix64).
pub fn noise(seed: u64, len: usize) -> Vec<f64> {
    let mut x = seed;
    (0..len)
        .map(|_| {
            x = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = x;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^= z >> 31;
            (z >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        })
        .collect()
}

/// MPPI's update of the nominal sequence: the samples' efforts `effort(k, t)` at each of
/// `horizon` steps, averaged with weights `exp(-(cost - best) / lambda)`.
pub fn update<const N: usize>(
    horizon: usize,
    costs: &[f64],
    lambda: f64,
    effort: impl Fn(usize, usize) -> [f64; N],
) -> Vec<[f64; N]> {
    let best = costs.iter().fold(f64::INFINITY, |m, c| m.min(*c));
    let weights: Vec<f64> = costs.iter().map(|c| (-(c - best) / lambda).exp()).collect();
    let sum: f64 = weights.iter().sum();
    (0..horizon)
        .map(|t| {
            let mut mean = [0.0; N];
            for (k, w) in weights.iter().enumerate() {
                for (m, e) in mean.iter_mut().zip(effort(k, t)) {
                    *m += w * e;
                }
            }
            mean.map(|m| m / sum)
        })
        .collect()
}

/// Iteration `iteration`: the costs of every sample `scalar()` and `batch()` give, timed,
/// which must agree within `tolerance` (relative); prints a row and returns the batch's costs
/// and their mean.
pub fn iterate(
    iteration: u64,
    tolerance: f64,
    scalar: impl FnOnce() -> Vec<f64>,
    batch: impl FnOnce() -> Vec<f64>,
) -> (Vec<f64>, f64) {
    if iteration == 0 {
        println!("iteration   mean cost   scalar (ms)   batch (ms)   speed-up   max |difference|");
    }
    let start = Instant::now();
    let a = scalar();
    let scalar_time = start.elapsed().as_secs_f64();
    let start = Instant::now();
    let b = batch();
    let batch_time = start.elapsed().as_secs_f64();
    let difference = a
        .iter()
        .zip(&b)
        .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs() / x.abs().max(1.0)));
    assert!(
        difference <= tolerance,
        "scalar and batch rollouts differ: {difference}"
    );
    let mean = b.iter().sum::<f64>() / b.len() as f64;
    println!(
        "{iteration:9}   {mean:9.4}   {:11.1}   {:10.1}   {:8.2}   {difference:.1e}",
        1e3 * scalar_time,
        1e3 * batch_time,
        scalar_time / batch_time
    );
    (b, mean)
}
