//! Mass properties of common solid shapes: rotational inertia about the centre of mass, in
//! the shape's own axes, with the URDF `<geometry>` conventions (a cylinder's axis is its z
//! axis, a box is centred with edges along x, y, z).
//!
//! Used to fill in a link's inertia when only its geometry is known, and as textbook checks.
//! All quantities are SI (kg, m, kg m^2); the shape is uniform (constant density).
//!
//! ```
//! use eomgen::model::shapes::{parallel_axis, Shape};
//!
//! // A 2 kg rod of 0.6 m along z: m L² / 12 across it about its centre ...
//! let rod = Shape::Rod { length: 0.6 }.inertia(2.0);
//! assert!((rod[(0, 0)] - 0.06).abs() < 1e-15);
//! // ... and m L² / 3 about one end.
//! let end = parallel_axis(&rod, 2.0, &nalgebra::Vector3::new(0.0, 0.0, 0.3));
//! assert!((end[(0, 0)] - 0.24).abs() < 1e-15);
//! ```

use nalgebra::{Matrix3, Vector3};

use super::Transform;

/// A uniform solid shape, in its own frame centred at its centre of mass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// A box with edge lengths `size` along x, y and z (URDF `<box size>`).
    Box {
        /// Edge lengths (m).
        size: [f64; 3],
    },
    /// A solid cylinder about the z axis (URDF `<cylinder>`).
    Cylinder {
        /// Radius (m).
        radius: f64,
        /// Length along z (m).
        length: f64,
    },
    /// A solid sphere (URDF `<sphere>`).
    Sphere {
        /// Radius (m).
        radius: f64,
    },
    /// A thin rod along z: a cylinder of negligible radius (no volume, so no density-based
    /// mass).
    Rod {
        /// Length along z (m).
        length: f64,
    },
}

impl Shape {
    /// The volume (m^3); zero for a [`Shape::Rod`].
    pub fn volume(&self) -> f64 {
        match *self {
            Shape::Box { size } => size[0] * size[1] * size[2],
            Shape::Cylinder { radius, length } => std::f64::consts::PI * radius * radius * length,
            Shape::Sphere { radius } => 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3),
            Shape::Rod { .. } => 0.0,
        }
    }

    /// The mass of the shape filled with material of `density` (kg/m^3).
    pub fn mass(&self, density: f64) -> f64 {
        density * self.volume()
    }

    /// The rotational inertia about the centre of mass, in the shape's axes, for a total
    /// `mass` (kg). Diagonal: the shape's axes are its principal axes.
    pub fn inertia(&self, mass: f64) -> Matrix3<f64> {
        let d = match *self {
            Shape::Box { size: [x, y, z] } => Vector3::new(
                mass * (y * y + z * z) / 12.0,
                mass * (x * x + z * z) / 12.0,
                mass * (x * x + y * y) / 12.0,
            ),
            Shape::Cylinder { radius, length } => {
                let across = mass * (3.0 * radius * radius + length * length) / 12.0;
                Vector3::new(across, across, mass * radius * radius / 2.0)
            }
            Shape::Sphere { radius } => Vector3::repeat(2.0 / 5.0 * mass * radius * radius),
            Shape::Rod { length } => {
                let across = mass * length * length / 12.0;
                Vector3::new(across, across, 0.0)
            }
        };
        Matrix3::from_diagonal(&d)
    }
}

/// The parallel-axis (Huygens-Steiner) theorem: the inertia about a point displaced by
/// `offset` from the centre of mass, `I + m (|d|² 1 - d dᵀ)`, for a body of `mass` with
/// inertia `inertia` about its centre of mass (same axes).
pub fn parallel_axis(inertia: &Matrix3<f64>, mass: f64, offset: &Vector3<f64>) -> Matrix3<f64> {
    inertia + mass * (Matrix3::identity() * offset.norm_squared() - offset * offset.transpose())
}

/// The inertia `R I Rᵀ` of a body with inertia `inertia` in frame B, expressed in frame A where
/// `rotation` maps B coordinates to A coordinates (`p_A = R p_B`).
pub fn rotate_inertia(inertia: &Matrix3<f64>, rotation: &Matrix3<f64>) -> Matrix3<f64> {
    rotation * inertia * rotation.transpose()
}

/// Mass, centre of mass and rotational inertia about the centre of mass, in one frame.
#[derive(Clone, Debug, PartialEq)]
pub struct MassProperties {
    /// Total mass (kg).
    pub mass: f64,
    /// Centre of mass (m).
    pub com: Vector3<f64>,
    /// Inertia about `com`, in the frame's axes (kg m^2).
    pub inertia: Matrix3<f64>,
}

/// The mass properties of a body made of uniform solid `parts` of one `density` (kg/m^3), each
/// placed in the body frame by its pose (`p_body = rotation * p_shape + translation`, as a URDF
/// `<collision><origin>`): the way to fill in a link whose `<inertial>` is missing from its
/// `<collision>` primitives. Overlaps are counted twice.
///
/// `None` when the parts have no volume (no parts, only rods, or zero sizes): no mass to
/// place.
///
/// ```
/// use eomgen::model::shapes::{mass_properties, Shape};
/// use eomgen::model::Transform;
///
/// // Two 10 cm cubes of water side by side along x make a 20 x 10 x 10 cm box.
/// let cube = Shape::Box { size: [0.1; 3] };
/// let mut left = Transform::identity();
/// left.translation.x = -0.05;
/// let mut right = Transform::identity();
/// right.translation.x = 0.05;
/// let p = mass_properties(&[(cube, left), (cube, right)], 1000.0).unwrap();
/// let whole = Shape::Box { size: [0.2, 0.1, 0.1] }.inertia(2.0);
/// assert!((p.mass - 2.0).abs() < 1e-12 && p.com.norm() < 1e-15);
/// assert!((p.inertia - whole).norm() < 1e-15);
/// ```
pub fn mass_properties(parts: &[(Shape, Transform)], density: f64) -> Option<MassProperties> {
    let mass: f64 = parts.iter().map(|(s, _)| s.mass(density)).sum();
    if !(mass > 0.0 && mass.is_finite()) {
        return None;
    }
    let com = parts
        .iter()
        .map(|(s, pose)| s.mass(density) * pose.translation)
        .sum::<Vector3<f64>>()
        / mass;
    let inertia = parts
        .iter()
        .map(|(s, pose)| {
            let m = s.mass(density);
            let about_own_com = rotate_inertia(&s.inertia(m), &pose.rotation);
            parallel_axis(&about_own_com, m, &(pose.translation - com))
        })
        .sum();
    Some(MassProperties { mass, com, inertia })
}

#[cfg(test)]
mod tests {
    //! Each expectation is the textbook formula written out here, independently of the
    //! implementation, or a property (limits, integration) the formula must satisfy.

    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * b.abs().max(1.0)
    }

    #[test]
    fn solid_cylinder_about_and_across_its_axis() {
        let (m, r, h) = (3.0, 0.2, 0.5);
        let i = Shape::Cylinder {
            radius: r,
            length: h,
        }
        .inertia(m);
        // About the axis: (1/2) m r²; across, through the centre: (1/12) m (3 r² + h²).
        assert!(close(i[(2, 2)], 0.5 * 3.0 * 0.04));
        assert!(close(i[(0, 0)], 3.0 * (3.0 * 0.04 + 0.25) / 12.0));
        assert!(close(i[(1, 1)], i[(0, 0)]));
        assert_eq!(i[(0, 1)], 0.0);
        // Across, about an end face diameter: (1/4) m r² + (1/3) m h².
        let end = parallel_axis(&i, m, &Vector3::new(0.0, 0.0, h / 2.0));
        assert!(close(end[(0, 0)], 0.25 * m * r * r + m * h * h / 3.0));
        // Volume and density: pi r² h.
        let shape = Shape::Cylinder {
            radius: r,
            length: h,
        };
        assert!(close(
            shape.mass(1000.0),
            1000.0 * std::f64::consts::PI * 0.04 * 0.5
        ));
    }

    #[test]
    fn box_sphere_and_rod() {
        let b = Shape::Box {
            size: [0.1, 0.2, 0.4],
        }
        .inertia(6.0);
        // (1/12) m (b² + c²) per axis.
        assert!(close(b[(0, 0)], 0.5 * (0.04 + 0.16)));
        assert!(close(b[(1, 1)], 0.5 * (0.01 + 0.16)));
        assert!(close(b[(2, 2)], 0.5 * (0.01 + 0.04)));
        // A cube: (1/6) m a².
        let c = Shape::Box { size: [0.3; 3] }.inertia(2.0);
        assert!(close(c[(1, 1)], 2.0 * 0.09 / 6.0));
        // Solid sphere: (2/5) m r², volume (4/3) pi r³.
        let s = Shape::Sphere { radius: 0.1 };
        assert!(close(s.inertia(5.0)[(0, 0)], 0.4 * 5.0 * 0.01));
        assert!(close(s.volume(), 4.0 * std::f64::consts::PI * 0.001 / 3.0));
        // Thin rod: (1/12) m L² across its centre, (1/3) m L² about an end, 0 about its axis.
        let rod = Shape::Rod { length: 1.2 }.inertia(0.5);
        assert!(close(rod[(0, 0)], 0.5 * 1.44 / 12.0));
        assert_eq!(rod[(2, 2)], 0.0);
        let end = parallel_axis(&rod, 0.5, &Vector3::new(0.0, 0.0, 0.6));
        assert!(close(end[(1, 1)], 0.5 * 1.44 / 3.0));
        assert_eq!(Shape::Rod { length: 1.0 }.volume(), 0.0);
    }

    #[test]
    fn limits_and_invariants() {
        // A cylinder of vanishing radius is a rod; one of vanishing length a disc
        // ((1/4) m r² across).
        let thin = Shape::Cylinder {
            radius: 0.0,
            length: 0.7,
        }
        .inertia(1.5);
        assert_eq!(thin, Shape::Rod { length: 0.7 }.inertia(1.5));
        let disc = Shape::Cylinder {
            radius: 0.3,
            length: 0.0,
        }
        .inertia(2.0);
        assert!(close(disc[(0, 0)], 0.25 * 2.0 * 0.09));
        // Perpendicular-axis theorem for the flat plate (box of zero height): Izz = Ixx + Iyy.
        let plate = Shape::Box {
            size: [0.4, 0.25, 0.0],
        }
        .inertia(1.0);
        assert!(close(plate[(2, 2)], plate[(0, 0)] + plate[(1, 1)]));
        // The trace is invariant under rotation and the result stays symmetric.
        let r = nalgebra::Rotation3::from_euler_angles(0.3, -0.7, 1.1).into_inner();
        let b = Shape::Box {
            size: [0.1, 0.2, 0.4],
        }
        .inertia(6.0);
        let rb = rotate_inertia(&b, &r);
        assert!(close(rb.trace(), b.trace()));
        assert!((rb - rb.transpose()).norm() < 1e-15);
    }

    #[test]
    fn combined_parts_rotated_and_offset() {
        // A cylinder lying along y (rotated +90 degrees about x), 0.3 m above the origin: its
        // axis inertia (1/2) m r² moves to the y axis; the com is at its centre.
        let (r, h, rho) = (0.05, 0.4, 2700.0);
        let cyl = Shape::Cylinder {
            radius: r,
            length: h,
        };
        let m = rho * std::f64::consts::PI * r * r * h;
        let pose = Transform {
            rotation: nalgebra::Rotation3::from_axis_angle(
                &Vector3::x_axis(),
                std::f64::consts::FRAC_PI_2,
            )
            .into_inner(),
            translation: Vector3::new(0.0, 0.0, 0.3),
        };
        let p = mass_properties(&[(cyl, pose)], rho).unwrap();
        assert!(close(p.mass, m));
        assert!((p.com - Vector3::new(0.0, 0.0, 0.3)).norm() < 1e-15);
        assert!(close(p.inertia[(1, 1)], 0.5 * m * r * r));
        assert!(close(p.inertia[(0, 0)], m * (3.0 * r * r + h * h) / 12.0));
        assert!(close(p.inertia[(2, 2)], m * (3.0 * r * r + h * h) / 12.0));
        assert!(p.inertia[(0, 1)].abs() < 1e-15 && p.inertia[(1, 2)].abs() < 1e-15);
        // A dumbbell: two spheres at ±d on x; across x: 2 (2/5 m r² + m d²).
        let ball = Shape::Sphere { radius: 0.02 };
        let at = |x: f64| Transform {
            rotation: Matrix3::identity(),
            translation: Vector3::new(x, 0.0, 0.0),
        };
        let p = mass_properties(&[(ball, at(-0.1)), (ball, at(0.1))], 8000.0).unwrap();
        let mb = 8000.0 * 4.0 / 3.0 * std::f64::consts::PI * 0.02_f64.powi(3);
        assert!(close(
            p.inertia[(1, 1)],
            2.0 * (0.4 * mb * 0.0004 + mb * 0.01)
        ));
        assert!(close(p.inertia[(0, 0)], 2.0 * 0.4 * mb * 0.0004));
        // Nothing to weigh.
        assert_eq!(mass_properties(&[], 1000.0), None);
        assert_eq!(
            mass_properties(&[(Shape::Rod { length: 1.0 }, at(0.0))], 1000.0),
            None
        );
    }

    #[test]
    fn box_inertia_matches_numerical_integration() {
        // Midpoint rule over a 40³ grid: ∫ (y² + z²) dm for a uniform box.
        let (size, m) = ([0.3, 0.5, 0.2], 4.0);
        let n = 40;
        let dm = m / (n * n * n) as f64;
        let mut ixx = 0.0;
        for i in 0..n {
            for j in 0..n {
                let y = ((j as f64 + 0.5) / n as f64 - 0.5) * size[1];
                let z = ((i as f64 + 0.5) / n as f64 - 0.5) * size[2];
                ixx += n as f64 * dm * (y * y + z * z);
            }
        }
        let want = Shape::Box { size }.inertia(m)[(0, 0)];
        // The midpoint rule is off by O(1/n²).
        assert!((ixx - want).abs() < 1e-3 * want);
    }
}
