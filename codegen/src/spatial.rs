//! Vector and spatial algebra on expressions: 3-vectors and 3x3 matrices of [`Id`]s, and
//! spatial vectors (an angular and a linear part, for motions and forces) in body axes.
//!
//! Every operation builds its result in the [`Graph`], whose constructors fold constants: a
//! product with a structural zero or one costs nothing, which is how a robot's geometry
//! specializes the algorithms built on these.

use nalgebra::{Matrix3, Vector3};

use crate::cas::{Graph, Id};

/// A 3-vector of expressions.
pub type V3 = [Id; 3];
/// A 3x3 matrix of expressions, row-major.
pub type M3 = [[Id; 3]; 3];

/// A spatial vector in body axes: (angular, linear) for a motion, (moment about the body
/// origin, force) for a force.
pub type Spatial = (V3, V3);

/// Snaps rotation-matrix entries that are 0 or ±1 up to rounding (see [`crate::kinematics`]).
pub fn snap(v: f64) -> f64 {
    const EPS: f64 = 1e-9;
    for target in [0.0, 1.0, -1.0] {
        if (v - target).abs() < EPS {
            return target;
        }
    }
    v
}

/// A rotation matrix with its entries snapped ([`snap`]) when the snapped matrix is still a
/// rotation (orthonormal to 1e-12); otherwise unchanged. Snapping one small entry of a
/// genuine rotation (a product of two small angles, 4e-10) would make it non-orthogonal by as
/// much, an error heavy bodies multiply.
pub fn snap_rotation(m: &Matrix3<f64>) -> Matrix3<f64> {
    let snapped = m.map(snap);
    let off = (snapped * snapped.transpose() - Matrix3::identity()).amax();
    if off <= 1e-12 {
        snapped
    } else {
        *m
    }
}

/// Constant rotation matrix into the graph, snapped ([`snap_rotation`]).
pub fn const_m3(g: &mut Graph, m: &Matrix3<f64>) -> M3 {
    let m = snap_rotation(m);
    let mut out = [[g.zero(); 3]; 3];
    for (r, row) in out.iter_mut().enumerate() {
        for (c, e) in row.iter_mut().enumerate() {
            *e = g.constant(m[(r, c)]);
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

pub fn spatial_dot(g: &mut Graph, a: &Spatial, b: &Spatial) -> Id {
    let x = g.dot(&a.0, &b.0);
    let y = g.dot(&a.1, &b.1);
    g.add(x, y)
}

/// `v x* f` for a motion `v` and a force `f`: `(w x n + u x f, w x f)`.
pub fn cross_force(g: &mut Graph, v: &Spatial, f: &Spatial) -> Spatial {
    let wn = cross(g, &v.0, &f.0);
    let uf = cross(g, &v.1, &f.1);
    let wf = cross(g, &v.0, &f.1);
    (vec_add(g, &wn, &uf), wf)
}

pub fn spatial_add(g: &mut Graph, a: &Spatial, b: &Spatial) -> Spatial {
    (vec_add(g, &a.0, &b.0), vec_add(g, &a.1, &b.1))
}

pub fn spatial_sub(g: &mut Graph, a: &Spatial, b: &Spatial) -> Spatial {
    (vec_sub(g, &a.0, &b.0), vec_sub(g, &a.1, &b.1))
}

pub fn mat_add(g: &mut Graph, a: &M3, b: &M3) -> M3 {
    [0, 1, 2].map(|r| [0, 1, 2].map(|c| g.add(a[r][c], b[r][c])))
}

/// `[w] J`: the cross-product matrix of `w` times `J`.
pub fn skew_times(g: &mut Graph, w: &V3, j: &M3) -> M3 {
    let cols = [0, 1, 2].map(|c| {
        let col = [j[0][c], j[1][c], j[2][c]];
        cross(g, w, &col)
    });
    [0, 1, 2].map(|r| [0, 1, 2].map(|c| cols[c][r]))
}

pub fn transpose(r: &M3) -> M3 {
    [0, 1, 2].map(|a| [0, 1, 2].map(|b| r[b][a]))
}

/// `[a] [b]` for cross-product matrices: `[a][b] v = a x (b x v)`, which is `b a^T - (a.b) 1`.
pub fn skew_mul(g: &mut Graph, a: &V3, b: &V3) -> M3 {
    let ab = g.dot(a, b);
    let mut out = [[g.zero(); 3]; 3];
    for r in 0..3 {
        for c in 0..3 {
            let ba = g.mul(b[r], a[c]);
            out[r][c] = if r == c { g.sub(ba, ab) } else { ba };
        }
    }
    out
}

/// `v x m` for motions `v = (w, u)` and `m = (a, b)`: `(w x a, w x b + u x a)`.
pub fn motion_cross(g: &mut Graph, v: &Spatial, m: &Spatial) -> Spatial {
    let wa = cross(g, &v.0, &m.0);
    let wb = cross(g, &v.0, &m.1);
    let ua = cross(g, &v.1, &m.0);
    (wa, vec_add(g, &wb, &ua))
}

/// `k s` for an expression `k`.
pub fn spatial_scale(g: &mut Graph, s: &Spatial, k: Id) -> Spatial {
    (vec_scale(g, &s.0, k), vec_scale(g, &s.1, k))
}
