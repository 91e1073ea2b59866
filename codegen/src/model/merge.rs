//! Fixed joints merged: one body per moving joint (its child link and every link welded to
//! it), a frame per link, and each joint kind's steps (`joint_kinds`) as model joints.

use nalgebra::{Matrix3, Vector3};

use super::description::{
    InertialDescription, JointDescription, JointType, LinkDescription, RobotDescription,
};
use super::errors::ModelError;
use super::inertia::Inertia;
use super::joint_kinds;
use super::options::ModelOptions;
use super::tree::Tree;
use super::validation::all_finite;
use super::{Body, Coupling, Frame, Joint, Model, Transform};

/// Where a link sits: the body it is welded to (`None` for the root) and its pose there.
#[derive(Clone)]
pub(super) struct Attachment {
    pub(super) body: Option<usize>,
    pub(super) placement: Transform,
}

/// The bodies and joints made so far, the root's welded links, and where each link sits.
struct Merged {
    joints: Vec<Joint>,
    bodies: Vec<Body>,
    inertias: Vec<Inertia>,
    root_inertia: Inertia,
    root_links: Vec<String>,
    attach: Vec<Attachment>,
}

/// Walks the tree depth first, creating a body per moving joint and lumping every link welded
/// through fixed joints into its body.
pub(super) fn merge(
    robot: &RobotDescription,
    tree: &Tree,
    file: &str,
    options: &ModelOptions,
    floating: bool,
) -> Result<Model, ModelError> {
    let root_link = &robot.links[tree.root];
    let mut m = Merged {
        joints: Vec::new(),
        bodies: Vec::new(),
        inertias: Vec::new(),
        root_inertia: Inertia::of_link(&root_link.inertial, &Transform::identity()),
        root_links: vec![root_link.name.clone()],
        attach: vec![
            Attachment {
                body: None,
                placement: Transform::identity(),
            };
            robot.links.len()
        ],
    };
    for &j in &tree.order {
        let joint = &robot.joints[j];
        let (parent, child) = tree.ends[j];
        // The walk reaches a joint after its parent link, so `attach[parent]` is final.
        let above = m.attach[parent].clone();
        let placement = above.placement.compose(&joint.origin.to_transform());
        let child_link = &robot.links[child];
        let steps = match &joint.joint_type {
            JointType::Moving(kind) => vec![joint_kinds::Step {
                suffix: None,
                kind: *kind,
                axis: normalized(joint.axis),
            }],
            JointType::Planar => joint_kinds::planar_steps(),
            JointType::Fixed | JointType::Unsupported(_) => {
                m.weld(
                    child,
                    &child_link.inertial,
                    &child_link.name,
                    above.body,
                    placement,
                );
                continue;
            }
        };
        let last = m.push_steps(joint, child_link, above.body, placement, steps);
        m.attach[child] = Attachment {
            body: Some(last),
            placement: Transform::identity(),
        };
    }
    m.finish(robot, tree, file, options, floating)
}

impl Merged {
    /// A joint's steps (one for a joint of one kind, three for a planar joint) as model joints,
    /// each moving a body: the first at the joint's origin, each next one at its
    /// predecessor's body origin, the last body the child link's (the others massless).
    /// Returns the last body.
    fn push_steps(
        &mut self,
        joint: &JointDescription,
        child: &LinkDescription,
        mut parent: Option<usize>,
        placement: Transform,
        steps: Vec<joint_kinds::Step>,
    ) -> usize {
        let last = steps.len() - 1;
        let empty = InertialDescription::default();
        for (k, step) in steps.into_iter().enumerate() {
            let b = self.joints.len();
            let name = match step.suffix {
                Some(suffix) => format!("{}.{suffix}", joint.name),
                None => joint.name.clone(),
            };
            // The last body is the child link's; the massless ones before it are named after
            // their step (`base.x`), not after a link they do not hold.
            let (body, links, inertial) = if k == last {
                (
                    child.name.clone(),
                    vec![child.name.clone()],
                    &child.inertial,
                )
            } else {
                (name.clone(), Vec::new(), &empty)
            };
            self.joints.push(Joint {
                name,
                kind: step.kind,
                parent,
                origin: if k == 0 {
                    placement.clone()
                } else {
                    Transform::identity()
                },
                axis: step.axis,
                limits: (last == 0).then(|| joint.limits.clone()).flatten(),
                damping: joint.damping,
                friction: joint.friction,
                armature: 0.0,
                mimic: joint.mimic.clone(),
                symbolic_origin: false,
            });
            self.bodies.push(Body {
                name: body,
                mass: 0.0,
                com: Vector3::zeros(),
                inertia: Matrix3::zeros(),
                merged_links: links,
                symbolic: false,
            });
            self.inertias
                .push(Inertia::of_link(inertial, &Transform::identity()));
            parent = Some(b);
        }
        self.joints.len() - 1
    }

    /// A link welded (by a fixed joint) to `body` (`None`: the root) at `placement`.
    fn weld(
        &mut self,
        link: usize,
        inertial: &InertialDescription,
        name: &str,
        body: Option<usize>,
        placement: Transform,
    ) {
        let part = Inertia::of_link(inertial, &placement);
        match body {
            Some(b) => {
                self.bodies[b].merged_links.push(name.to_string());
                self.inertias[b] = self.inertias[b].combine(&part);
            }
            None => {
                self.root_links.push(name.to_string());
                self.root_inertia = self.root_inertia.combine(&part);
            }
        }
        self.attach[link] = Attachment { body, placement };
    }

    /// The model: bodies' inertias set, the floating base's body, a frame per link, checked
    /// finite.
    fn finish(
        mut self,
        robot: &RobotDescription,
        tree: &Tree,
        file: &str,
        options: &ModelOptions,
        floating: bool,
    ) -> Result<Model, ModelError> {
        for (body, inertia) in self.bodies.iter_mut().zip(&self.inertias) {
            inertia.set(body);
        }
        let root_link = &robot.links[tree.root];
        let base = floating.then(|| {
            let mut base = Body {
                name: root_link.name.clone(),
                mass: 0.0,
                com: Vector3::zeros(),
                inertia: Matrix3::zeros(),
                merged_links: self.root_links,
                symbolic: false,
            };
            self.root_inertia.set(&mut base);
            base
        });
        let frames: Vec<Frame> = robot
            .links
            .iter()
            .zip(self.attach)
            .map(|(link, a)| Frame {
                name: link.name.clone(),
                body: a.body,
                placement: a.placement,
            })
            .collect();
        check_finite(&self.bodies, &base, &self.joints, &frames, file)?;
        let joints_len = self.joints.len();
        Ok(Model {
            name: robot.name.clone(),
            root: root_link.name.clone(),
            gravity: Vector3::from(options.gravity),
            joints: self.joints,
            bodies: self.bodies,
            base,
            frames,
            contacts: Vec::new(),
            contact_frames: Vec::new(),
            contact_points_at: Vec::new(),
            passive: Vec::new(),
            include_friction: options.friction,
            coulomb_smoothing: options.coulomb_smoothing,
            warnings: Vec::new(),
            coupling: (0..joints_len).map(Coupling::independent).collect(),
        })
    }
}

/// Finite inputs can still overflow when composed: every body's inertia, joint origin and
/// frame placement must be finite.
fn check_finite(
    bodies: &[Body],
    base: &Option<Body>,
    joints: &[Joint],
    frames: &[Frame],
    file: &str,
) -> Result<(), ModelError> {
    let non_finite = |culprit: String, field| ModelError::NonFinite {
        file: file.into(),
        culprit,
        field,
    };
    let transform_finite =
        |t: &Transform| all_finite(t.rotation.as_slice()) && all_finite(t.translation.as_slice());
    for body in bodies.iter().chain(base) {
        if !(body.mass.is_finite()
            && all_finite(body.com.as_slice())
            && all_finite(body.inertia.as_slice()))
        {
            return Err(non_finite(
                format!("body of link `{}`", body.name),
                "inertia after merging fixed links",
            ));
        }
    }
    for joint in joints {
        if !transform_finite(&joint.origin) {
            return Err(non_finite(
                format!("joint `{}`", joint.name),
                "origin after merging fixed links",
            ));
        }
    }
    for frame in frames {
        if !transform_finite(&frame.placement) {
            return Err(non_finite(format!("link `{}`", frame.name), "placement"));
        }
    }
    Ok(())
}

/// The unit vector along a finite, non-zero `axis`, scaled first so that tiny or huge
/// components neither underflow nor overflow.
pub(super) fn normalized(axis: [f64; 3]) -> Vector3<f64> {
    let v = Vector3::from(axis);
    let v = v / v.amax();
    v / v.norm()
}
