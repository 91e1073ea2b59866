//! Forward kinematics in the CAS: poses of bodies and link frames, joint axes, Jacobians.
//!
//! Each joint angle enters through exactly one `sin`/`cos` pair. Constant rotations (URDF
//! origins and axes) fold into the products, and their entries within `1e-9` of 0 or ±1 are
//! snapped, so that the zeros of a robot's geometry vanish from the expressions instead of
//! carrying tiny terms through every product: `rpy = "1.570796325 0 0"` (pi/2 to nine
//! decimals, as exporters write it) has a cosine of `4.9e-12`, which is meant as 0. The change
//! to any result is of the order of 1e-9 relative, below the precision URDF numbers carry.
//!
//! - [`joint`]: the joint model (how each kind of joint places its body);
//! - `params` ([`Params`]): the model's parameters as numbers or symbols;
//! - here: world and body-frame kinematics built on both.

pub mod joint;
mod params;

pub use params::Params;
// The vector algebra lived here before it had a module of its own.
pub use crate::spatial::{
    const_m3, const_v3, cross, mat_mul, mat_t_vec, mat_vec, snap, vec_add, vec_scale, vec_sub, M3,
    V3,
};
pub use joint::axis_rotation;

use crate::cas::{Graph, Id};
use crate::model::{Model, Transform};

/// World poses of every body and the world axis and origin of every joint.
#[derive(Clone, Debug)]
pub struct WorldKinematics {
    /// World from body `i`: rotation and position of the body frame.
    pub rotation: Vec<M3>,
    pub position: Vec<V3>,
    /// Joint `i`'s unit axis in world axes.
    pub axis: Vec<V3>,
    /// Joint `i`'s origin (a point on its axis) in world coordinates.
    pub origin: Vec<V3>,
    /// Each body's centre of mass in world coordinates.
    pub com: Vec<V3>,
    /// The root's placement in the world: the identity, or a floating base's pose.
    pub root: joint::Placement,
    /// Whether the root is a floating base.
    pub floating: bool,
}

impl WorldKinematics {
    /// Forward kinematics from the root.
    pub fn new(g: &mut Graph, model: &Model, params: &Params, q: &[Id]) -> WorldKinematics {
        let n = model.dof();
        let root = if model.is_floating() {
            joint::free_flyer_placement(g, &q[..7])
        } else {
            joint::Placement {
                rotation: const_m3(g, &nalgebra::Matrix3::identity()),
                translation: [g.zero(); 3],
            }
        };
        let offsets = model.q_offsets();
        let mut wk = WorldKinematics {
            rotation: Vec::with_capacity(n),
            position: Vec::with_capacity(n),
            axis: Vec::with_capacity(n),
            origin: Vec::with_capacity(n),
            com: Vec::with_capacity(n),
            root,
            floating: model.is_floating(),
        };
        for (i, j) in model.joints.iter().enumerate() {
            let parent = match j.parent {
                Some(p) => joint::Placement {
                    rotation: wk.rotation[p],
                    translation: wk.position[p],
                },
                None => root,
            };
            let origin = joint::origin(g, j, &params.origin[i]);
            // The joint frame in the world, then the body in it.
            let frame = joint::compose(g, &parent, &origin);
            let motion = joint::motion(g, j, &q[offsets[i]..offsets[i] + j.kind.nq()]);
            let body = joint::compose(g, &frame, &motion);
            let a = joint::axis(g, j);
            let z = mat_vec(g, &frame.rotation, &a);
            let rc = mat_vec(g, &body.rotation, &params.com[i]);
            let c = vec_add(g, &body.translation, &rc);
            wk.rotation.push(body.rotation);
            wk.position.push(body.translation);
            wk.axis.push(z);
            wk.origin.push(frame.translation);
            wk.com.push(c);
        }
        wk
    }

    /// World pose of a frame welded to `body` (`None`: the root) with a constant placement.
    pub fn frame_pose(
        &self,
        g: &mut Graph,
        body: Option<usize>,
        placement: &Transform,
    ) -> (M3, V3) {
        let rp = const_m3(g, &placement.rotation);
        let tp = [0, 1, 2].map(|k| g.constant(placement.translation[k]));
        let (rb, pb) = match body {
            None if !self.floating => return (rp, tp),
            None => (self.root.rotation, self.root.translation),
            Some(b) => (self.rotation[b], self.position[b]),
        };
        let r = mat_mul(g, &rb, &rp);
        let off = mat_vec(g, &rb, &tp);
        (r, vec_add(g, &pb, &off))
    }

    /// The 6 x N Jacobian (linear rows, then angular, world axes) of a point `p` (world
    /// coordinates) rigidly attached to `body`: per joint on its path, its world axis (and, for
    /// a rotating joint, the axis crossed with the lever arm to `p`).
    pub fn point_jacobian(
        &self,
        g: &mut Graph,
        model: &Model,
        body: Option<usize>,
        p: &V3,
    ) -> Vec<Vec<Id>> {
        let nv = model.nv();
        let mut jac = vec![vec![g.zero(); nv]; 6];
        if model.is_floating() {
            // The base's columns: its linear velocity, then its angular velocity about its
            // origin, both in base axes.
            let r = vec_sub(g, p, &self.root.translation);
            for k in 0..3 {
                let e = [0, 1, 2].map(|row| self.root.rotation[row][k]);
                let lin = cross(g, &e, &r);
                for row in 0..3 {
                    jac[row][k] = e[row];
                    jac[row][3 + k] = lin[row];
                    jac[3 + row][3 + k] = e[row];
                }
            }
        }
        let Some(b) = body else { return jac };
        let columns = model.v_offsets();
        for j in model.path_to_root(b) {
            if model.joints[j].kind == crate::model::JointKind::Floating {
                // A free flyer's columns: its body's linear velocity, then its angular
                // velocity about the body origin, both in body axes.
                let r = vec_sub(g, p, &self.position[j]);
                for k in 0..3 {
                    let e = [0, 1, 2].map(|row| self.rotation[j][row][k]);
                    let lin = cross(g, &e, &r);
                    for row in 0..3 {
                        jac[row][columns[j] + k] = e[row];
                        jac[row][columns[j] + 3 + k] = lin[row];
                        jac[3 + row][columns[j] + 3 + k] = e[row];
                    }
                }
                continue;
            }
            let z = self.axis[j];
            let (lin, ang) = if joint::rotates(&model.joints[j]) {
                let r = vec_sub(g, p, &self.origin[j]);
                (cross(g, &z, &r), z)
            } else {
                (z, [g.zero(); 3])
            };
            for k in 0..3 {
                jac[k][columns[j]] = lin[k];
                jac[3 + k][columns[j]] = ang[k];
            }
        }
        jac
    }
}

/// Velocity kinematics in body coordinates, the compact route to the mass matrix.
///
/// For a body `b` and a joint `j` on its path to the root, `axis[b][j]` is joint `j`'s axis and
/// `offset[b][j]` the vector from joint `j`'s origin to body `b`'s origin, both in body `b`'s
/// axes. They follow from the parent's by one relative rotation, so each is a few operations
/// instead of a product of world rotations.
#[derive(Clone, Debug)]
pub struct BodyKinematics {
    pub axis: Vec<Vec<Option<V3>>>,
    pub offset: Vec<Vec<Option<V3>>>,
}

impl BodyKinematics {
    pub fn new(g: &mut Graph, model: &Model, params: &Params, q: &[Id]) -> BodyKinematics {
        let n = model.dof();
        let mut axis: Vec<Vec<Option<V3>>> = vec![vec![None; n]; n];
        let mut offset: Vec<Vec<Option<V3>>> = vec![vec![None; n]; n];
        let offsets = model.q_offsets();
        for (b, j) in model.joints.iter().enumerate() {
            let coords = &q[offsets[b]..offsets[b] + j.kind.nq()];
            let rel = joint::body_in_parent(g, j, &params.origin[b], coords);
            if let Some(p) = j.parent {
                for k in model.path_to_root(p) {
                    let pa = axis[p][k].expect("ancestor axis");
                    let po = offset[p][k].expect("ancestor offset");
                    axis[b][k] = Some(mat_t_vec(g, &rel.rotation, &pa));
                    let sum = vec_add(g, &rel.translation, &po);
                    offset[b][k] = Some(mat_t_vec(g, &rel.rotation, &sum));
                }
            }
            axis[b][b] = Some(joint::axis(g, j));
            // The body origin's offset from the joint origin: the joint's own translation.
            offset[b][b] = Some(joint::motion(g, j, coords).translation);
        }
        BodyKinematics { axis, offset }
    }
}
