//! Forward kinematics in the CAS: poses of bodies and link frames, joint axes, Jacobians.
//!
//! Each joint angle enters through exactly one `sin`/`cos` pair. Constant rotations (URDF
//! origins and axes) fold into the products, and their entries within `1e-9` of 0 or ±1 are
//! snapped, so that the zeros of a robot's geometry vanish from the expressions instead of
//! carrying tiny terms through every product: `rpy = "1.570796325 0 0"` (pi/2 to nine
//! decimals, as exporters write it) has a cosine of `4.9e-12`, which is meant as 0. The change
//! to any result is of the order of 1e-9 relative, below the precision URDF numbers carry.

use nalgebra::{Matrix3, Vector3};

use crate::cas::{Graph, Id};
use crate::model::{JointKind, Model, Transform};

/// A 3-vector of expressions.
pub type V3 = [Id; 3];
/// A 3x3 matrix of expressions, row-major.
pub type M3 = [[Id; 3]; 3];

/// Snaps rotation-matrix entries that are 0 or ±1 up to rounding.
pub fn snap(v: f64) -> f64 {
    const EPS: f64 = 1e-9;
    for target in [0.0, 1.0, -1.0] {
        if (v - target).abs() < EPS {
            return target;
        }
    }
    v
}

/// The symbols and constants of a model's parameters, and where they come from.
#[derive(Clone, Debug)]
pub struct Params {
    /// Per body: mass, centre of mass (body frame), rotational inertia about the centre of mass.
    pub mass: Vec<Id>,
    pub com: Vec<V3>,
    pub inertia: Vec<M3>,
    /// Per joint: translation of the joint origin in the parent body frame.
    pub origin: Vec<V3>,
    /// Per joint: rotor inertia (armature), added to the mass matrix's diagonal.
    pub armature: Vec<Id>,
    /// Per joint: viscous damping and Coulomb friction coefficients (zero unless the model
    /// includes friction).
    pub damping: Vec<Id>,
    pub coulomb: Vec<Id>,
    /// Every symbolic parameter: (symbol name, node, the URDF's value), in creation order.
    pub symbols: Vec<(String, Id, f64)>,
}

impl Params {
    /// Numbers from the model, or symbols where the model asks for them. A parameter whose URDF
    /// value is exactly zero stays a structural zero even when symbolic.
    pub fn new(g: &mut Graph, model: &Model) -> Params {
        let mut symbols = Vec::new();
        let mut value = |g: &mut Graph, symbolic: bool, name: String, v: f64| -> Id {
            if symbolic && v != 0.0 {
                let id = g.param(&name);
                symbols.push((name, id, v));
                id
            } else {
                g.constant(v)
            }
        };
        let (mut mass, mut com, mut inertia, mut origin) = (vec![], vec![], vec![], vec![]);
        for b in &model.bodies {
            let s = b.symbolic;
            let n = &b.name;
            mass.push(value(g, s, format!("m_{n}"), b.mass));
            com.push(
                [0, 1, 2].map(|k| value(g, s, format!("c{}_{n}", ["x", "y", "z"][k]), b.com[k])),
            );
            let mut i = [[g.zero(); 3]; 3];
            for r in 0..3 {
                for c in r..3 {
                    let axes = ["x", "y", "z"];
                    let id = value(
                        g,
                        s,
                        format!("I{}{}_{n}", axes[r], axes[c]),
                        b.inertia[(r, c)],
                    );
                    i[r][c] = id;
                    i[c][r] = id;
                }
            }
            inertia.push(i);
        }
        for j in &model.joints {
            let t = j.origin.translation;
            let s = j.symbolic_origin;
            let n = &j.name;
            origin
                .push([0, 1, 2].map(|k| value(g, s, format!("{}_{n}", ["x", "y", "z"][k]), t[k])));
        }
        // Joint parameters after every geometric one, so that adding them leaves the order of
        // existing fields alone; zero values stay structural zeros.
        let (mut armature, mut damping, mut coulomb) = (vec![], vec![], vec![]);
        for j in &model.joints {
            let (s, n) = (j.symbolic_origin, &j.name);
            armature.push(value(g, s, format!("Ia_{n}"), j.armature));
            let (d, f) = if model.include_friction {
                (j.damping, j.friction)
            } else {
                (0.0, 0.0)
            };
            damping.push(value(g, s, format!("damping_{n}"), d));
            coulomb.push(value(g, s, format!("friction_{n}"), f));
        }
        Params {
            mass,
            com,
            inertia,
            origin,
            armature,
            damping,
            coulomb,
            symbols,
        }
    }
}

/// Constant matrix into the graph, snapped.
pub fn const_m3(g: &mut Graph, m: &Matrix3<f64>) -> M3 {
    let mut out = [[g.zero(); 3]; 3];
    for (r, row) in out.iter_mut().enumerate() {
        for (c, e) in row.iter_mut().enumerate() {
            *e = g.constant(snap(m[(r, c)]));
        }
    }
    out
}

/// Constant vector into the graph, snapped (for unit axes).
pub fn const_v3(g: &mut Graph, v: &Vector3<f64>) -> V3 {
    [0, 1, 2].map(|k| g.constant(snap(v[k])))
}

/// `a * b`.
pub fn mat_mul(g: &mut Graph, a: &M3, b: &M3) -> M3 {
    let mut out = [[g.zero(); 3]; 3];
    for r in 0..3 {
        for c in 0..3 {
            out[r][c] = g.dot(&a[r], &[b[0][c], b[1][c], b[2][c]]);
        }
    }
    out
}

/// `a * v`.
pub fn mat_vec(g: &mut Graph, a: &M3, v: &V3) -> V3 {
    [0, 1, 2].map(|r| g.dot(&a[r], v))
}

/// `a^T * v`.
pub fn mat_t_vec(g: &mut Graph, a: &M3, v: &V3) -> V3 {
    [0, 1, 2].map(|c| g.dot(&[a[0][c], a[1][c], a[2][c]], v))
}

/// `a + b`.
pub fn vec_add(g: &mut Graph, a: &V3, b: &V3) -> V3 {
    [0, 1, 2].map(|k| g.add(a[k], b[k]))
}

/// `a - b`.
pub fn vec_sub(g: &mut Graph, a: &V3, b: &V3) -> V3 {
    [0, 1, 2].map(|k| g.sub(a[k], b[k]))
}

/// `k * a` for an expression `k`.
pub fn vec_scale(g: &mut Graph, a: &V3, k: Id) -> V3 {
    [0, 1, 2].map(|i| g.mul(a[i], k))
}

/// `a x b`.
pub fn cross(g: &mut Graph, a: &V3, b: &V3) -> V3 {
    let mut c = |i: usize, j: usize| {
        let p = g.mul(a[i], b[j]);
        let m = g.mul(a[j], b[i]);
        g.sub(p, m)
    };
    [c(1, 2), c(2, 0), c(0, 1)]
}

/// Rotation by angle `q` about the unit axis `a` (Rodrigues: `I + s K + (1 - c) K^2`), with one
/// `sin`/`cos` pair of `q`.
pub fn axis_rotation(g: &mut Graph, a: &Vector3<f64>, q: Id) -> M3 {
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
}

impl WorldKinematics {
    /// Forward kinematics from the root.
    pub fn new(g: &mut Graph, model: &Model, params: &Params, q: &[Id]) -> WorldKinematics {
        let n = model.dof();
        let ident = const_m3(g, &Matrix3::identity());
        let zero = [g.zero(); 3];
        let mut wk = WorldKinematics {
            rotation: Vec::with_capacity(n),
            position: Vec::with_capacity(n),
            axis: Vec::with_capacity(n),
            origin: Vec::with_capacity(n),
            com: Vec::with_capacity(n),
        };
        for (i, joint) in model.joints.iter().enumerate() {
            let (rp, pp) = match joint.parent {
                Some(p) => (wk.rotation[p], wk.position[p]),
                None => (ident, zero),
            };
            let ro = const_m3(g, &joint.origin.rotation);
            let pre = mat_mul(g, &rp, &ro);
            let off = mat_vec(g, &rp, &params.origin[i]);
            let o = vec_add(g, &pp, &off);
            let a = const_v3(g, &joint.axis);
            let z = mat_vec(g, &pre, &a);
            let (r, p) = match joint.kind {
                JointKind::Revolute | JointKind::Continuous => {
                    let rj = axis_rotation(g, &joint.axis, q[i]);
                    (mat_mul(g, &pre, &rj), o)
                }
                JointKind::Prismatic => {
                    let d = vec_scale(g, &z, q[i]);
                    (pre, vec_add(g, &o, &d))
                }
            };
            let rc = mat_vec(g, &r, &params.com[i]);
            let c = vec_add(g, &p, &rc);
            wk.rotation.push(r);
            wk.position.push(p);
            wk.axis.push(z);
            wk.origin.push(o);
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
        match body {
            None => (rp, tp),
            Some(b) => {
                let r = mat_mul(g, &self.rotation[b], &rp);
                let off = mat_vec(g, &self.rotation[b], &tp);
                (r, vec_add(g, &self.position[b], &off))
            }
        }
    }

    /// The 6 x N Jacobian (linear rows, then angular, world axes) of a point `p` (world
    /// coordinates) rigidly attached to `body`.
    pub fn point_jacobian(
        &self,
        g: &mut Graph,
        model: &Model,
        body: Option<usize>,
        p: &V3,
    ) -> Vec<Vec<Id>> {
        let n = model.dof();
        let mut jac = vec![vec![g.zero(); n]; 6];
        let Some(b) = body else { return jac };
        for j in model.path_to_root(b) {
            let z = self.axis[j];
            let (lin, ang) = if model.joints[j].kind.is_revolute() {
                let r = vec_sub(g, p, &self.origin[j]);
                (cross(g, &z, &r), z)
            } else {
                (z, [g.zero(); 3])
            };
            for k in 0..3 {
                jac[k][j] = lin[k];
                jac[3 + k][j] = ang[k];
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
        let zero = [g.zero(); 3];
        for (b, joint) in model.joints.iter().enumerate() {
            let a = const_v3(g, &joint.axis);
            let ro = const_m3(g, &joint.origin.rotation);
            // Relative rotation parent -> body: R_origin * R_joint(q).
            let (rel, slide) = match joint.kind {
                JointKind::Revolute | JointKind::Continuous => {
                    let rj = axis_rotation(g, &joint.axis, q[b]);
                    (mat_mul(g, &ro, &rj), zero)
                }
                JointKind::Prismatic => {
                    // The body slides along the axis: in parent axes, R_origin a q.
                    let ra = mat_vec(g, &ro, &a);
                    (ro, vec_scale(g, &ra, q[b]))
                }
            };
            if let Some(p) = joint.parent {
                // Translation from the parent body origin to this body origin, parent axes.
                let t = vec_add(g, &params.origin[b], &slide);
                for j in model.path_to_root(p) {
                    let pa = axis[p][j].expect("ancestor axis");
                    let po = offset[p][j].expect("ancestor offset");
                    axis[b][j] = Some(mat_t_vec(g, &rel, &pa));
                    let sum = vec_add(g, &t, &po);
                    offset[b][j] = Some(mat_t_vec(g, &rel, &sum));
                }
            }
            axis[b][b] = Some(a);
            offset[b][b] = Some(match joint.kind {
                JointKind::Prismatic => vec_scale(g, &a, q[b]),
                _ => zero,
            });
        }
        BodyKinematics { axis, offset }
    }
}
