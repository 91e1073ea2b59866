//! Physical validity of inertias: checked on the merged moving bodies, where the physics is;
//! links welded to the world only get a warning, as their inertia is never used.
//!
//! A rotational inertia is possible when its principal moments `a <= b <= c` are
//! non-negative and satisfy the triangle inequality `c <= a + b`, both up to a tolerance of
//! `1e-9 * trace + 1e-12 kg m^2`: relative, for the rounding of large merged bodies, and
//! absolute, so that the rounding noise of a point mass (moments of 1e-20 of either sign) passes.

use nalgebra::{Matrix3, SymmetricEigen};

use super::description::RobotDescription;
use super::errors::{moments_text, ModelError, ModelWarning};
use super::inertia::inertia_matrix;
use super::Model;

/// Relative tolerance (of the trace) of the checks.
const RELATIVE_TOLERANCE: f64 = 1e-9;
/// Absolute tolerance of the checks, kg m^2.
const ABSOLUTE_TOLERANCE: f64 = 1e-12;

/// What is wrong with a rotational inertia, in words, and its principal moments.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Violation {
    pub(super) reason: String,
    pub(super) moments: [f64; 3],
}

/// The principal moments of a finite symmetric matrix, smallest first; `None` if the eigen
/// solver does not converge.
fn principal_moments(inertia: &Matrix3<f64>) -> Option<[f64; 3]> {
    let scale = inertia.amax();
    if scale == 0.0 {
        return Some([0.0; 3]);
    }
    // Scaling keeps the eigen solver away from overflow.
    let eigen = SymmetricEigen::try_new(inertia / scale, f64::EPSILON, 1000)?;
    let mut m = [
        eigen.eigenvalues[0] * scale,
        eigen.eigenvalues[1] * scale,
        eigen.eigenvalues[2] * scale,
    ];
    m.sort_by(f64::total_cmp);
    Some(m)
}

/// `None` for a possible rotational inertia, else what is wrong with it.
pub(super) fn violation(inertia: &Matrix3<f64>) -> Option<Violation> {
    let Some(moments) = principal_moments(inertia) else {
        return Some(Violation {
            reason: "its principal moments cannot be computed".into(),
            moments: [f64::NAN; 3],
        });
    };
    let [a, b, c] = moments;
    let tolerance = RELATIVE_TOLERANCE * (a + b + c).max(0.0) + ABSOLUTE_TOLERANCE;
    let f = |x: f64| crate::cas::format_number(x, Some(6));
    let reason = if a < -tolerance {
        format!(
            "its rotational inertia is not positive semi-definite: principal moment {} < 0 \
             (principal moments {})",
            f(a),
            moments_text(&moments)
        )
    } else if c > a + b + tolerance {
        format!(
            "its principal moments {} break the triangle inequality {} <= {} + {}",
            moments_text(&moments),
            f(c),
            f(a),
            f(b)
        )
    } else {
        return None;
    };
    Some(Violation { reason, moments })
}

/// Checks every moving body: a negative mass is an error; an impossible rotational inertia is
/// an error, or with `repair` is replaced by its mean principal moment times the identity (as
/// MuJoCo's `balanceinertia` does) with a warning.
pub(super) fn check_bodies(
    model: &mut Model,
    file: &str,
    repair: bool,
    warnings: &mut Vec<ModelWarning>,
) -> Result<(), ModelError> {
    for body in model.bodies.iter_mut().chain(&mut model.base) {
        if body.mass < 0.0 {
            return Err(ModelError::NegativeMass {
                file: file.into(),
                link: body.name.clone(),
                mass: body.mass,
            });
        }
        let Some(v) = violation(&body.inertia) else {
            continue;
        };
        if !repair || !v.moments.iter().all(|m| m.is_finite()) {
            return Err(ModelError::InvalidInertia {
                file: file.into(),
                link: body.name.clone(),
                reason: format!(
                    "{}{}; the repair_inertia option (--repair-inertia) balances it",
                    v.reason,
                    merged_note(&body.merged_links)
                ),
            });
        }
        let mean = (v.moments.iter().sum::<f64>() / 3.0).max(0.0);
        body.inertia = Matrix3::identity() * mean;
        warnings.push(ModelWarning::InertiaRepaired {
            file: file.into(),
            link: body.name.clone(),
            reason: format!("{}{}", v.reason, merged_note(&body.merged_links)),
            before: v.moments,
            after: [mean; 3],
        });
    }
    Ok(())
}

/// ` (merged with `b`, `c`)` for a body of several links.
fn merged_note(links: &[String]) -> String {
    if links.len() <= 1 {
        return String::new();
    }
    let rest: Vec<String> = links[1..].iter().map(|l| format!("`{l}`")).collect();
    format!(" (with the links welded to it: {})", rest.join(", "))
}

/// Warns about each link welded to the world (a link of no body) whose mass is negative or
/// whose rotational inertia is impossible: it never moves, so it carries no dynamics.
pub(super) fn warn_welded(
    robot: &RobotDescription,
    model: &Model,
    file: &str,
    warnings: &mut Vec<ModelWarning>,
) {
    // `model.frames` follows the links of `robot` one to one. A floating base's links move:
    // their merged body is checked with the others.
    for (link, frame) in robot.links.iter().zip(&model.frames) {
        if frame.body.is_some() || model.is_floating() {
            continue;
        }
        let inertial = &link.inertial;
        let reason = if inertial.mass < 0.0 {
            Some(format!("its mass is negative ({})", inertial.mass))
        } else {
            violation(&inertia_matrix(&inertial.inertia)).map(|v| v.reason)
        };
        if let Some(reason) = reason {
            warnings.push(ModelWarning::WeldedInertia {
                file: file.into(),
                link: link.name.clone(),
                reason,
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    fn diag(a: f64, b: f64, c: f64) -> Matrix3<f64> {
        Matrix3::from_diagonal(&Vector3::new(a, b, c))
    }

    #[test]
    fn possible_inertias_pass() {
        assert_eq!(violation(&Matrix3::zeros()), None);
        assert_eq!(violation(&diag(1.0, 1.0, 2.0)), None); // flat plate: equality
        assert_eq!(violation(&diag(0.0, 1.0, 1.0)), None); // thin rod
        assert_eq!(violation(&diag(-1e-12, 1.0, 1.0)), None); // relative rounding
        assert_eq!(violation(&diag(1.0, 1.0, 2.0 + 1e-12)), None);
        // Rounding noise of a point mass: absolute tolerance.
        assert_eq!(violation(&diag(-1e-20, 1e-35, 3e-20)), None);
        // Huge but finite: no overflow inside the eigen solver.
        assert_eq!(violation(&diag(1e307, 1e308, 1e308)), None);
    }

    #[test]
    fn impossible_inertias_are_named() {
        let v = violation(&diag(1.0, 1.0, 2.5)).unwrap();
        assert!(
            v.reason.contains("triangle inequality 2.5 <= 1 + 1"),
            "{}",
            v.reason
        );
        assert_eq!(v.moments, [1.0, 1.0, 2.5]);
        let v = violation(&diag(-1e-3, 1.0, 1.0)).unwrap();
        assert!(
            v.reason.contains("not positive semi-definite"),
            "{}",
            v.reason
        );
        // Indefinite off-diagonal case: eigenvalues 1 - 2, 1, 1 + 2.
        let m = Matrix3::new(1.0, 2.0, 0.0, 2.0, 1.0, 0.0, 0.0, 0.0, 1.0);
        assert!(violation(&m).unwrap().reason.contains("semi-definite"));
        // Beyond the absolute tolerance on a tiny body.
        assert!(violation(&diag(1e-10, 1e-10, 1e-9)).is_some());
    }
}
