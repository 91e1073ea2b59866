//! Inertial parameters: a link's inertia as a mass, centre of mass and rotational inertia that
//! combine across welded links, and inertias filled from collision shapes.

use nalgebra::{Matrix3, Vector3};

use super::description::{InertialDescription, JointType, LinkDescription, Pose, RobotDescription};
use super::errors::{ModelError, ModelWarning};
use super::shapes::{mass_properties, Shape};
use super::tree::Tree;
use super::validation::is_missing;
use super::{Body, Transform};

/// The robot with the inertia of every link that lacks one (and moves) computed from its
/// collision primitives, warning about each.
pub(super) fn fill_inertias(
    robot: &RobotDescription,
    tree: &Tree,
    density: f64,
    file: &str,
    warnings: &mut Vec<ModelWarning>,
) -> Result<RobotDescription, ModelError> {
    let welded = welded_to_root(robot, tree);
    let mut filled = robot.clone();
    for (link, welded) in filled.links.iter_mut().zip(welded) {
        if welded || !is_missing(&link.inertial) || link.collisions.is_empty() {
            continue;
        }
        let (parts, ignored) = collision_primitives(link, file)?;
        fill_from_primitives(link, parts, ignored, density, file, warnings);
    }
    Ok(filled)
}

/// Which links are welded to the root (through fixed joints only): they never move.
fn welded_to_root(robot: &RobotDescription, tree: &Tree) -> Vec<bool> {
    let mut welded = vec![false; robot.links.len()];
    welded[tree.root] = true;
    for &j in &tree.order {
        let (parent, child) = tree.ends[j];
        welded[child] = welded[parent] && robot.joints[j].joint_type == JointType::Fixed;
    }
    welded
}

/// Collision primitives, each placed in its link's frame.
type Primitives = Vec<(Shape, Transform)>;

/// A link's collision primitives placed in its frame, and what it has that is no primitive
/// (meshes); a primitive of negative or non-finite size, or a non-finite origin, is an error.
fn collision_primitives(
    link: &LinkDescription,
    file: &str,
) -> Result<(Primitives, Vec<String>), ModelError> {
    let invalid = |reason: String| ModelError::InvalidCollision {
        file: file.into(),
        link: link.name.clone(),
        reason,
    };
    let mut parts = Vec::new();
    let mut ignored = Vec::new();
    for c in &link.collisions {
        match c.geometry {
            Ok(shape) => {
                let sizes: Vec<f64> = match shape {
                    Shape::Box { size } => size.to_vec(),
                    Shape::Cylinder { radius, length } => vec![radius, length],
                    Shape::Sphere { radius } => vec![radius],
                    Shape::Rod { length } => vec![length],
                };
                if !sizes.iter().all(|x| x.is_finite() && *x >= 0.0) {
                    return Err(invalid(format!(
                        "geometry: sizes must be finite and non-negative, not {sizes:?}"
                    )));
                }
                if !c.origin.is_finite() {
                    return Err(invalid("origin: not finite".into()));
                }
                parts.push((shape, c.origin.to_transform()));
            }
            Err(kind) => ignored.push(kind.to_string()),
        }
    }
    Ok((parts, ignored))
}

/// `link`'s inertial from `parts` at `density`, with the warning that says so; a link with
/// nothing to weigh (no primitive, or only primitives of zero volume) stays massless, warned.
fn fill_from_primitives(
    link: &mut LinkDescription,
    parts: Primitives,
    mut ignored: Vec<String>,
    density: f64,
    file: &str,
    warnings: &mut Vec<ModelWarning>,
) {
    match mass_properties(&parts, density) {
        Some(p) => {
            let i = (p.inertia + p.inertia.transpose()) * 0.5;
            link.inertial = InertialDescription {
                origin: Pose {
                    xyz: p.com.into(),
                    rpy: [0.0; 3],
                },
                mass: p.mass,
                inertia: [
                    i[(0, 0)],
                    i[(0, 1)],
                    i[(0, 2)],
                    i[(1, 1)],
                    i[(1, 2)],
                    i[(2, 2)],
                ],
            };
            warnings.push(ModelWarning::InertiaFromCollision {
                file: file.into(),
                link: link.name.clone(),
                mass: p.mass,
                primitives: parts.len(),
                density,
                ignored,
            });
        }
        None if parts.is_empty() => warnings.push(ModelWarning::NoCollisionPrimitive {
            file: file.into(),
            link: link.name.clone(),
            ignored,
        }),
        // Primitives of zero volume: nothing to weigh either.
        None => {
            ignored.extend(parts.iter().map(|_| "primitive of zero volume".to_string()));
            warnings.push(ModelWarning::NoCollisionPrimitive {
                file: file.into(),
                link: link.name.clone(),
                ignored,
            })
        }
    }
}

pub(super) fn inertia_matrix(&[ixx, ixy, ixz, iyy, iyz, izz]: &[f64; 6]) -> Matrix3<f64> {
    Matrix3::new(ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz)
}

/// Mass, centre of mass and rotational inertia about the centre of mass, in one frame.
#[derive(Clone, Debug)]
pub(super) struct Inertia {
    pub(super) mass: f64,
    pub(super) com: Vector3<f64>,
    pub(super) inertia: Matrix3<f64>,
}

impl Inertia {
    /// A link's inertia expressed in a frame where the link frame has pose `placement`.
    pub(super) fn of_link(inertial: &InertialDescription, placement: &Transform) -> Inertia {
        let frame = placement.compose(&inertial.origin.to_transform());
        Inertia {
            mass: inertial.mass,
            com: frame.translation,
            inertia: frame.rotation
                * inertia_matrix(&inertial.inertia)
                * frame.rotation.transpose(),
        }
    }

    /// The same inertia seen from a frame where the current frame has pose `t`.
    pub(super) fn transformed(&self, t: &Transform) -> Inertia {
        Inertia {
            mass: self.mass,
            com: t.rotation * self.com + t.translation,
            inertia: t.rotation * self.inertia * t.rotation.transpose(),
        }
    }

    /// The lumped inertia of two rigidly attached parts (same frame). With
    /// `d = c1 - c2` and `M = m1 + m2`, the inertia about the new centre of mass is
    /// `I1 + I2 + (m1 m2 / M) (|d|^2 E - d d^T)` (parallel-axis theorem, as in Pinocchio).
    pub(super) fn combine(&self, other: &Inertia) -> Inertia {
        let mass = self.mass + other.mass;
        let inertia = self.inertia + other.inertia;
        // Massless parts leave the centre of mass exactly where it was.
        let (com, inertia) = if mass == 0.0 {
            (Vector3::zeros(), inertia)
        } else if other.mass == 0.0 {
            (self.com, inertia)
        } else if self.mass == 0.0 {
            (other.com, inertia)
        } else {
            let d = self.com - other.com;
            (
                (self.com * self.mass + other.com * other.mass) / mass,
                inertia + shift(&d) * (self.mass * other.mass / mass),
            )
        };
        Inertia { mass, com, inertia }
    }

    /// Stores mass, centre of mass and (exactly symmetric) inertia in `body`.
    pub(super) fn set(&self, body: &mut Body) {
        body.mass = self.mass;
        body.com = if self.mass > 0.0 {
            self.com
        } else {
            Vector3::zeros()
        };
        // Exactly symmetric, whatever the rounding of the rotations.
        body.inertia = (self.inertia + self.inertia.transpose()) * 0.5;
    }

    /// The rotational inertia about the frame origin.
    pub(super) fn about_origin(&self) -> Matrix3<f64> {
        self.inertia + shift(&self.com) * self.mass
    }
}

/// `|d|^2 E - d d^T`: the parallel-axis term per unit mass.
pub(super) fn shift(d: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::identity() * d.norm_squared() - d * d.transpose()
}
