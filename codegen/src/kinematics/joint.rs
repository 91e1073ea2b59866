//! The joint model: how each kind of joint places its body, as expressions in its
//! coordinates.
//!
//! A moving joint places its body (the child link frame) in its parent body's frame in two
//! steps: its constant origin (the URDF `<origin>`, fixed joints folded in), then its motion in
//! the joint frame, a function of the joint's `nq` position coordinates. Its velocity enters
//! through the motion subspace `S`, `nv` spatial columns in body axes. Kinematics, the
//! recursive algorithms and the Lagrangian route all ask this module, so that a new kind of
//! joint (a free-flying base: nq 7, nv 6) is one more arm in each function here, not a new
//! branch in every algorithm.
//!
//! | kind | nq | nv | motion in the joint frame | subspace `S` (angular; linear) |
//! |---|---|---|---|---|
//! | revolute, continuous | 1 | 1 | rotation by `q` about `a` | `(a; 0)` |
//! | prismatic | 1 | 1 | translation by `q a` | `(0; a)` |
//! | floating (free flyer, a floating base or below the root) | 7 | 6 | translation `q[0..3]`, rotation by the unit quaternion `q[3..7]` (x, y, z, w) | the six unit columns, linear first |
//! | planar | 3 | 3 | the chain prismatic `x`, prismatic `y`, revolute about `z` (`model::joint_kinds`) | one column per step |
//!
//! Revolute and prismatic joints integrate as `q + v dt`; a continuous joint's coordinate is
//! its angle. The free flyer's velocity is its body's own (linear velocity of its origin, then
//! angular velocity, both in the body's axes, relative to the joint frame), as Pinocchio's
//! `JointModelFreeFlyer`; it integrates on SE(3) (`eomgen_runtime::free_flyer::integrate`,
//! `integrate_blocks` below the root).

use crate::cas::{Graph, Id};
use crate::model::{Joint, JointKind};
use crate::spatial::{
    const_m3, const_v3, mat_mul, mat_vec, snap, vec_add, vec_scale, Spatial, M3, V3,
};

/// A rigid placement as expressions: `p_outer = rotation p_inner + translation`.
#[derive(Clone, Copy, Debug)]
pub struct Placement {
    pub rotation: M3,
    pub translation: V3,
}

/// The joint's constant origin in its parent body's frame: the URDF rotation (snapped) and
/// `translation`, which may hold symbols.
pub fn origin(g: &mut Graph, joint: &Joint, translation: &V3) -> Placement {
    Placement {
        rotation: const_m3(g, &joint.origin.rotation),
        translation: *translation,
    }
}

/// The unit axis in the joint (and body) frame, snapped.
pub fn axis(g: &mut Graph, joint: &Joint) -> V3 {
    const_v3(g, &joint.axis)
}

/// The body's placement in the joint frame, for the joint's position coordinates `q`
/// (`joint.kind.nq()` of them).
pub fn motion(g: &mut Graph, joint: &Joint, q: &[Id]) -> Placement {
    debug_assert_eq!(q.len(), joint.kind.nq(), "joint {}", joint.name);
    let zero = [g.zero(); 3];
    match joint.kind {
        JointKind::Revolute | JointKind::Continuous => Placement {
            rotation: axis_rotation(g, &joint.axis, q[0]),
            translation: zero,
        },
        JointKind::Prismatic => {
            let a = axis(g, joint);
            Placement {
                rotation: identity(g),
                translation: vec_scale(g, &a, q[0]),
            }
        }
        JointKind::Floating => free_flyer_placement(g, q),
    }
}

/// The body's placement in its parent body's frame: origin, then motion.
pub fn body_in_parent(g: &mut Graph, joint: &Joint, translation: &V3, q: &[Id]) -> Placement {
    let o = origin(g, joint, translation);
    let m = motion(g, joint, q);
    compose(g, &o, &m)
}

/// `outer ∘ inner`.
pub fn compose(g: &mut Graph, outer: &Placement, inner: &Placement) -> Placement {
    let rotation = mat_mul(g, &outer.rotation, &inner.rotation);
    let moved = mat_vec(g, &outer.rotation, &inner.translation);
    Placement {
        rotation,
        translation: vec_add(g, &outer.translation, &moved),
    }
}

/// The motion subspace: `nv` spatial columns (angular; linear) in body axes
/// (`joint.kind.nv()` of them).
pub fn subspace(g: &mut Graph, joint: &Joint) -> Vec<Spatial> {
    let a = axis(g, joint);
    let zero = [g.zero(); 3];
    match joint.kind {
        JointKind::Revolute | JointKind::Continuous => vec![(a, zero)],
        JointKind::Prismatic => vec![(zero, a)],
        JointKind::Floating => free_flyer_subspace(g),
    }
}

/// Whether the joint rotates its body (its subspace has an angular part): what the algorithms
/// that still treat rotation and translation apart ask, instead of matching joint kinds.
pub fn rotates(joint: &Joint) -> bool {
    match joint.kind {
        JointKind::Revolute | JointKind::Continuous | JointKind::Floating => true,
        JointKind::Prismatic => false,
    }
}

/// A free flyer's placement of the base in the world: translation `q[0..3]` and the rotation of
/// the unit quaternion `q[3..7]` = (x, y, z, w), in the form that assumes unit length (as
/// Pinocchio's), so that it is exact for unit quaternions and polynomial in `q`.
pub fn free_flyer_placement(g: &mut Graph, q: &[Id]) -> Placement {
    debug_assert_eq!(q.len(), 7);
    let (x, y, z, w) = (q[3], q[4], q[5], q[6]);
    let p = |g: &mut Graph, a: Id, b: Id| g.mul(a, b);
    let (xx, yy, zz) = (p(g, x, x), p(g, y, y), p(g, z, z));
    let (xy, xz, yz) = (p(g, x, y), p(g, x, z), p(g, y, z));
    let (xw, yw, zw) = (p(g, x, w), p(g, y, w), p(g, z, w));
    let diag = |g: &mut Graph, a: Id, b: Id| g.sum(1.0, [(a, -2.0), (b, -2.0)]);
    let off = |g: &mut Graph, a: Id, b: Id, sign: f64| g.sum(0.0, [(a, 2.0), (b, 2.0 * sign)]);
    let rotation = [
        [diag(g, yy, zz), off(g, xy, zw, -1.0), off(g, xz, yw, 1.0)],
        [off(g, xy, zw, 1.0), diag(g, xx, zz), off(g, yz, xw, -1.0)],
        [off(g, xz, yw, -1.0), off(g, yz, xw, 1.0), diag(g, xx, yy)],
    ];
    Placement {
        rotation,
        translation: [q[0], q[1], q[2]],
    }
}

/// A free flyer's motion subspace in base axes: the six unit columns, linear velocity first
/// (`(0; e_k)`), then angular (`(e_k; 0)`).
pub fn free_flyer_subspace(g: &mut Graph) -> Vec<Spatial> {
    let (o, z) = (g.one(), g.zero());
    let unit = |k: usize| [0, 1, 2].map(|i| if i == k { o } else { z });
    let zero = [z; 3];
    (0..3)
        .map(|k| (zero, unit(k)))
        .chain((0..3).map(|k| (unit(k), zero)))
        .collect()
}

fn identity(g: &mut Graph) -> M3 {
    let (o, z) = (g.one(), g.zero());
    [[o, z, z], [z, o, z], [z, z, o]]
}

/// Rotation by angle `q` about the unit axis `a` (Rodrigues: `I + s K + (1 - c) K^2`), with one
/// `sin`/`cos` pair of `q`.
pub fn axis_rotation(g: &mut Graph, a: &nalgebra::Vector3<f64>, q: Id) -> M3 {
    let (s, c) = (g.sin(q), g.cos(q));
    let one_minus_c = g.sum(1.0, [(c, -1.0)]);
    let a = [snap(a[0]), snap(a[1]), snap(a[2])];
    let k = [[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]];
    let mut out = [[g.zero(); 3]; 3];
    for r in 0..3 {
        for col in 0..3 {
            let k2: f64 = (0..3).map(|m| k[r][m] * k[m][col]).sum();
            let id = if r == col { 1.0 } else { 0.0 };
            out[r][col] = g.sum(id, [(s, k[r][col]), (one_minus_c, k2)]);
        }
    }
    out
}
