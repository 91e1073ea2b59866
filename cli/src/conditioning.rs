//! Near-singular mass matrices: a warning when `M(q)` is so badly conditioned that the forward
//! dynamics loses most of its digits.
//!
//! The estimate is the ratio of the largest to the smallest pivot of `M = L D L^T` (no
//! pivoting, joints in the model's order): cheap, and a small pivot also says which joint's
//! motion is (nearly) without inertia once its ancestors are accounted for. `info` looks at a
//! few states spread over the joint ranges, `eval` at the state asked for.

use eomgen::evaluate::State;
use eomgen::model::{JointKind, Model};
use eomgen::report::format_number;
use eomgen::Derived;

/// Condition estimates above this are warned about: with 16 significant digits in `f64`,
/// fewer than 6 are left in the accelerations.
pub const WARN_ABOVE: f64 = 1e10;

/// The states `info` samples: `q = 0` and this many more.
const SAMPLES: usize = 4;

/// Joints whose pivot is within this factor of the smallest are named.
const NAMED_WITHIN: f64 = 1e3;

/// The most joints named in a warning.
const MAX_NAMED: usize = 6;

/// The pivots `D` of `M = L D L^T`, in joint order; stops at the first pivot that is not
/// positive and finite, which it includes.
pub fn ldl_pivots(m: &[Vec<f64>]) -> Vec<f64> {
    let n = m.len();
    let mut l = vec![vec![0.0; n]; n];
    let mut d = Vec::with_capacity(n);
    for j in 0..n {
        let pivot = m[j][j] - (0..j).map(|k| l[j][k] * l[j][k] * d[k]).sum::<f64>();
        d.push(pivot);
        if !(pivot.is_finite() && pivot > 0.0) {
            break;
        }
        for i in j + 1..n {
            l[i][j] = (m[i][j] - (0..j).map(|k| l[i][k] * l[j][k] * d[k]).sum::<f64>()) / pivot;
        }
    }
    d
}

/// The condition estimate of `m` and the joints with the smallest pivots, or `None` when it
/// is not above [`WARN_ABOVE`].
pub fn near_singular(m: &[Vec<f64>]) -> Option<(f64, Vec<usize>)> {
    let d = ldl_pivots(m);
    let largest = d.iter().copied().fold(0.0, f64::max);
    let smallest = d.iter().copied().fold(f64::INFINITY, f64::min);
    let estimate = if smallest > 0.0 && d.len() == m.len() {
        largest / smallest
    } else {
        f64::INFINITY
    };
    if estimate <= WARN_ABOVE {
        return None;
    }
    let threshold = smallest.max(0.0) * NAMED_WITHIN;
    let mut weak: Vec<usize> = (0..d.len()).filter(|&i| d[i] <= threshold).collect();
    weak.sort_by(|&a, &b| d[a].total_cmp(&d[b]));
    weak.truncate(MAX_NAMED);
    weak.sort_unstable();
    Some((estimate, weak))
}

/// The warning for `m` at the state described by `at`, if it is near singular.
pub fn warning(model: &Model, m: &[Vec<f64>], at: &str) -> Option<String> {
    let (estimate, weak) = near_singular(m)?;
    let names: Vec<String> = weak
        .iter()
        .map(|&i| format!("`{}`", model.velocity_names()[i]))
        .collect();
    let estimate = if estimate.is_finite() {
        format!("condition estimate {}", format_number(estimate, Some(2)))
    } else {
        "a pivot that is not positive".to_string()
    };
    Some(format!(
        "{}: the mass matrix is near singular {at} ({estimate} from its LDL pivots; the \
         smallest pivots are those of {}): forward dynamics there is unreliable; check the \
         masses and inertias of the bodies these joints move",
        model.name,
        names.join(", ")
    ))
}

/// The warnings of `info`: the worst of the sampled states, if any is near singular.
pub fn sampled_warnings(derived: &Derived) -> Vec<String> {
    let model = derived.model();
    // The joints' conditioning: a floating base's (or floating joint's) mass matrix is
    // checked at evaluation.
    if !model.velocities_are_rates() {
        return Vec::new();
    }
    let n = model.coordinates();
    let mass = match derived.evaluator(&["mass_matrix"]) {
        Ok(m) => m,
        Err(e) => return vec![e.to_string()],
    };
    let mut rng = 0x2545_f491_4f6c_dd1d_u64;
    let mut worst: Option<(f64, String)> = None;
    for k in 0..=SAMPLES {
        let q: Vec<f64> = if k == 0 {
            vec![0.0; n]
        } else {
            model
                .coordinate_joints()
                .into_iter()
                .map(|j| sample(&model.joints[j], &mut rng))
                .collect()
        };
        let m = match mass.evaluate(&State::at_rest(q, n)) {
            Ok(v) => v[0].rows(),
            Err(e) => return vec![e.to_string()],
        };
        let Some((estimate, _)) = near_singular(&m) else {
            continue;
        };
        if worst.as_ref().is_some_and(|w| w.0 >= estimate) {
            continue;
        }
        let at = if k == 0 {
            "at q = 0".to_string()
        } else {
            format!("at sampled state {k} of {SAMPLES}")
        };
        if let Some(text) = warning(model, &m, &at) {
            worst = Some((estimate, text));
        }
    }
    worst.into_iter().map(|w| w.1).collect()
}

/// A joint position within the joint's limits (or a default range), from a xorshift stream.
fn sample(joint: &eomgen::model::Joint, state: &mut u64) -> f64 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    let u = (*state >> 11) as f64 / (1u64 << 53) as f64;
    let (lo, hi) = match (&joint.limits, joint.kind) {
        (Some(l), JointKind::Revolute | JointKind::Prismatic)
            if l.lower.is_finite() && l.upper.is_finite() && l.lower < l.upper =>
        {
            (l.lower, l.upper)
        }
        (_, JointKind::Prismatic) => (-0.1, 0.1),
        _ => (-std::f64::consts::PI, std::f64::consts::PI),
    };
    lo + u * (hi - lo)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pivots_of_a_known_factorization() {
        // M = L D L^T with L = [[1, 0], [0.5, 1]], D = [4, 2].
        let m = vec![vec![4.0, 2.0], vec![2.0, 3.0]];
        assert_eq!(ldl_pivots(&m), vec![4.0, 2.0]);
        assert_eq!(near_singular(&m), None);
    }

    #[test]
    fn near_singular_matrices_name_the_weak_joints() {
        // The second joint moves almost nothing of its own.
        let m = vec![
            vec![1.0, 0.5, 0.0],
            vec![0.5, 0.25 + 1e-13, 0.0],
            vec![0.0, 0.0, 2.0],
        ];
        let (estimate, weak) = near_singular(&m).unwrap();
        assert!(estimate > 1e12 && estimate < 1e14, "{estimate}");
        assert_eq!(weak, vec![1]);
        // Singular or indefinite: an infinite estimate, the failing pivot named.
        let singular = vec![vec![1.0, 1.0], vec![1.0, 1.0]];
        assert_eq!(near_singular(&singular), Some((f64::INFINITY, vec![1])));
    }
}
