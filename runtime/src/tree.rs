//! Compact kernels that generated code loops over where flattening every entry does not pay:
//! poses and Jacobians along a kinematic chain, and Craig's `B(q)` and `C(q)` from the columns
//! of the Christoffel-form Coriolis matrix.
//!
//! Generated code supplies what is specific to the robot (each joint's transform as
//! straight-line code, the joint axes, the chains from the root); the loops here are the same
//! for every robot, so a 48-joint robot costs no more code than its joints.

use crate::linalg::axpy;
use crate::{FactorError, Lane, Pose, Real};

/// How a joint moves its body, for Jacobian columns.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Motion {
    /// Rotation about the axis (revolute and continuous joints).
    Rotation,
    /// Translation along the axis (prismatic joints).
    Translation,
    /// A free flyer (a floating joint below the root): six velocity columns, the body's linear
    /// velocity then its angular velocity, both in its own axes; the axis is not used. Only
    /// [`chain_jacobian_columns`] places its columns.
    Free,
}

impl Motion {
    /// How many velocity columns a joint of this motion has: six for a free flyer, one
    /// otherwise.
    ///
    /// ```
    /// use eomgen_runtime::tree::Motion;
    /// assert_eq!((Motion::Rotation.columns(), Motion::Free.columns()), (1, 6));
    /// ```
    pub const fn columns(self) -> usize {
        match self {
            Motion::Rotation | Motion::Translation => 1,
            Motion::Free => 6,
        }
    }
}

/// A moving joint as the tree kernels see it: its unit axis in its body's frame and how it
/// moves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TreeJoint {
    /// The joint axis in the frame of the body it moves (the child link frame).
    pub axis: [f64; 3],
    /// Rotation or translation about that axis.
    pub motion: Motion,
}

/// The world pose of the body at the end of `path` (joint indices from the root), composing
/// `transform(j)`, the pose of body `j` in its parent's frame, along the chain.
///
/// ```
/// use eomgen_runtime::{tree::chain_pose, Pose};
/// // two joints, each 1 m along x from its parent
/// let step = |_j: usize| Pose::from_translation([1.0_f64, 0.0, 0.0]);
/// assert_eq!(chain_pose(&[0, 1], step).translation, [2.0, 0.0, 0.0]);
/// ```
#[inline]
pub fn chain_pose<T: Lane>(path: &[usize], transform: impl Fn(usize) -> Pose<T>) -> Pose<T> {
    let mut pose = Pose::identity();
    for &j in path {
        pose = pose.compose(&transform(j));
    }
    pose
}

/// The world pose of each body along `path` (at most `N`), and the world position of a frame at
/// `placement` in the last one.
#[inline]
fn chain_poses<T: Lane, const N: usize>(
    path: &[usize],
    transform: impl Fn(usize) -> Pose<T>,
    placement: &Pose<T>,
) -> ([Pose<T>; N], [T; 3]) {
    let mut bodies = [Pose::identity(); N];
    let mut pose = Pose::identity();
    for (k, &j) in path.iter().enumerate().take(N) {
        pose = pose.compose(&transform(j));
        bodies[k] = pose;
    }
    (bodies, pose.transform_point(&placement.translation))
}

/// `a x b`.
pub(crate) fn cross<T: Lane>(a: &[T; 3], b: &[T; 3]) -> [T; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The 6 x N Jacobian (rows vx, vy, vz, wx, wy, wz in world axes) of a frame at `placement` in
/// the body at the end of `path`, with `transform(j)` the pose of body `j` in its parent's
/// frame. Columns of joints off the path are zero.
///
/// ```
/// use eomgen_runtime::tree::{chain_jacobian, Motion, TreeJoint};
/// use eomgen_runtime::Pose;
/// // one revolute joint about z, the frame 1 m along the body's x axis
/// let joints = [TreeJoint { axis: [0.0, 0.0, 1.0], motion: Motion::Rotation }];
/// let tip = Pose::from_translation([1.0_f64, 0.0, 0.0]);
/// let j = chain_jacobian(&[0], &joints, |_| Pose::identity(), &tip);
/// assert_eq!(j, [[0.0], [1.0], [0.0], [0.0], [0.0], [1.0]]);
/// ```
pub fn chain_jacobian<T: Lane, const N: usize>(
    path: &[usize],
    joints: &[TreeJoint; N],
    transform: impl Fn(usize) -> Pose<T>,
    placement: &Pose<T>,
) -> [[T; N]; 6] {
    let (bodies, point) = chain_poses::<T, N>(path, transform, placement);
    let mut jac = [[T::zero(); N]; 6];
    for (k, &j) in path.iter().enumerate().take(N) {
        let Some(joint) = joints.get(j) else { continue };
        let a = joint.axis.map(T::from_f64);
        let z = bodies[k].transform_vector(&a);
        let (lin, ang) = match joint.motion {
            Motion::Rotation => {
                let o = bodies[k].translation;
                let r = [point[0] - o[0], point[1] - o[1], point[2] - o[2]];
                (cross(&z, &r), z)
            }
            Motion::Translation => (z, [T::zero(); 3]),
            // One column per joint cannot hold a free flyer's six.
            Motion::Free => continue,
        };
        for r in 0..3 {
            jac[r][j] = lin[r];
            jac[3 + r][j] = ang[r];
        }
    }
    jac
}

/// [`chain_jacobian`] for joints of any kind: joint `j`'s velocity columns start at
/// `columns[j]` (one for a revolute or prismatic joint, six for a [`Motion::Free`] joint:
/// its body's linear velocity, then its angular velocity about the body origin, both in body
/// axes).
///
/// ```
/// use eomgen_runtime::tree::{chain_jacobian_columns, Motion, TreeJoint};
/// use eomgen_runtime::Pose;
/// // a revolute joint about z, then a free flyer 1 m along x; the frame at the flyer's origin
/// let joints = [
///     TreeJoint { axis: [0.0, 0.0, 1.0], motion: Motion::Rotation },
///     TreeJoint { axis: [0.0; 3], motion: Motion::Free },
/// ];
/// let step = |j: usize| if j == 1 { Pose::from_translation([1.0_f64, 0.0, 0.0]) } else { Pose::identity() };
/// let j: [[f64; 7]; 6] = chain_jacobian_columns(&[0, 1], &joints, &[0, 1], step, &Pose::identity());
/// assert_eq!(j[1][0], 1.0); // the revolute joint moves the point along y
/// assert_eq!(j[0][1], 1.0); // the flyer's linear x column
/// assert_eq!(j[5][6], 1.0); // its angular z column
/// ```
pub fn chain_jacobian_columns<T: Lane, const NJ: usize, const NV: usize>(
    path: &[usize],
    joints: &[TreeJoint; NJ],
    columns: &[usize; NJ],
    transform: impl Fn(usize) -> Pose<T>,
    placement: &Pose<T>,
) -> [[T; NV]; 6] {
    let (bodies, point) = chain_poses::<T, NJ>(path, transform, placement);
    let mut jac = [[T::zero(); NV]; 6];
    let mut put = |col: usize, lin: [T; 3], ang: [T; 3]| {
        if col < NV {
            for r in 0..3 {
                jac[r][col] = lin[r];
                jac[3 + r][col] = ang[r];
            }
        }
    };
    for (k, &j) in path.iter().enumerate().take(NJ) {
        let (Some(joint), Some(&col)) = (joints.get(j), columns.get(j)) else {
            continue;
        };
        let body = &bodies[k];
        let o = body.translation;
        let lever = [point[0] - o[0], point[1] - o[1], point[2] - o[2]];
        let zero = [T::zero(); 3];
        match joint.motion {
            Motion::Rotation => {
                let z = body.transform_vector(&joint.axis.map(T::from_f64));
                put(col, cross(&z, &lever), z);
            }
            Motion::Translation => put(
                col,
                body.transform_vector(&joint.axis.map(T::from_f64)),
                zero,
            ),
            Motion::Free => {
                for a in 0..3 {
                    let e = [0, 1, 2].map(|r| body.rotation[r][a]);
                    put(col + a, e, zero);
                    put(col + 3 + a, cross(&e, &lever), e);
                }
            }
        }
    }
    jac
}

/// A matrix over a robot's joints (columns: joints, as [`chain_jacobian`] gives them) in the
/// robot's coordinates when some joints follow others (URDF mimic joints): joint `j` moves
/// at `coupling[j].1` times the rate of coordinate `coupling[j].0`, so column `c` of the
/// result is the sum of the columns of its joints times their multipliers (`J G`).
///
/// ```
/// use eomgen_runtime::tree::couple_columns;
/// // three joints; the third follows the first at twice its rate
/// let j = [[1.0_f64, 2.0, 3.0]];
/// let reduced: [[f64; 2]; 1] = couple_columns(&j, &[(0, 1.0), (1, 1.0), (0, 2.0)]);
/// assert_eq!(reduced, [[7.0, 2.0]]);
/// ```
pub fn couple_columns<T: Lane, const R: usize, const NJ: usize, const N: usize>(
    joints: &[[T; NJ]; R],
    coupling: &[(usize, f64); NJ],
) -> [[T; N]; R] {
    let mut out = [[T::zero(); N]; R];
    for (row, joint_row) in out.iter_mut().zip(joints) {
        for (&(c, k), &x) in coupling.iter().zip(joint_row) {
            if let Some(entry) = row.get_mut(c) {
                *entry += T::from_f64(k) * x;
            }
        }
    }
    out
}

/// The column of the pair `(j, k)`, `j < k`, in Craig's order (0,1), (0,2), ..., (1,2), ...
#[inline]
pub const fn pair_index(n: usize, j: usize, k: usize) -> usize {
    j * n - j * (j + 1) / 2 + (k - j - 1)
}

/// Craig's centrifugal matrix `C(q)` from the Christoffel-form Coriolis matrix:
/// `C_ij = Gamma_ijj = C(q, e_j)_ij`, with `coriolis(v)` the Coriolis matrix at velocity `v`
/// (linear in `v`). Costs `N` evaluations of `coriolis`.
///
/// ```
/// use eomgen_runtime::tree::centrifugal_from_coriolis;
/// // a 1-joint system with C(q, qd) = [[2 qd]]: Gamma_000 = 2
/// let c = centrifugal_from_coriolis(|v: &[f64; 1]| [[2.0 * v[0]]]);
/// assert_eq!(c, [[2.0]]);
/// ```
pub fn centrifugal_from_coriolis<T: Lane, const N: usize>(
    coriolis: impl Fn(&[T; N]) -> [[T; N]; N],
) -> [[T; N]; N] {
    let mut out = [[T::zero(); N]; N];
    let mut e = [T::zero(); N];
    for j in 0..N {
        e[j] = T::one();
        let c = coriolis(&e);
        e[j] = T::zero();
        for i in 0..N {
            out[i][j] = c[i][j];
        }
    }
    out
}

/// Craig's Coriolis matrix `B(q)` (`N x P`, `P = N (N - 1) / 2`, pairs in
/// [`pair_index`] order) from the Christoffel-form Coriolis matrix:
/// `B_i,(j,k) = Gamma_ijk + Gamma_ikj` with `Gamma_ijk = C(q, e_k)_ij`. Costs `N` evaluations
/// of `coriolis`. `P` must be `N (N - 1) / 2`; other entries stay zero.
///
/// ```
/// use eomgen_runtime::tree::coriolis_pairs_from_coriolis;
/// // C(q, qd) = [[qd1, qd0], [0, 0]]: b_0 = 2 qd0 qd1, so B_0,(0,1) = 2
/// let b = coriolis_pairs_from_coriolis::<f64, 2, 1>(|v| [[v[1], v[0]], [0.0, 0.0]]);
/// assert_eq!(b, [[2.0], [0.0]]);
/// ```
pub fn coriolis_pairs_from_coriolis<T: Lane, const N: usize, const P: usize>(
    coriolis: impl Fn(&[T; N]) -> [[T; N]; N],
) -> [[T; P]; N] {
    let mut out = [[T::zero(); P]; N];
    let mut e = [T::zero(); N];
    for k in 0..N {
        e[k] = T::one();
        let c = coriolis(&e);
        e[k] = T::zero();
        for (i, row) in out.iter_mut().enumerate() {
            for (a, &gamma) in c[i].iter().enumerate() {
                let p = match a.cmp(&k) {
                    core::cmp::Ordering::Less => pair_index(N, a, k),
                    core::cmp::Ordering::Greater => pair_index(N, k, a),
                    core::cmp::Ordering::Equal => continue,
                };
                if let Some(x) = row.get_mut(p) {
                    *x += gamma;
                }
            }
        }
    }
    out
}

/// Factorizes the mass matrix of a kinematic tree in place as `L^T D L`, Featherstone's
/// factorization in reverse joint order, which creates no fill-in: `M_ij` is touched only when
/// one of `i`, `j` is an ancestor of the other (`parent[i]` is joint `i`'s parent joint, `None`
/// at the root; a parent comes before its children). Afterwards `m[i][i]` holds `D` and
/// `m[i][j]` (`j` an ancestor of `i`) holds `L`.
///
/// Fails with the first pivot, in elimination order (last joint first), that is not finite or
/// not positive.
pub fn ltdl_factor<T: Real, const N: usize>(
    m: &mut [[T; N]; N],
    parent: &[Option<usize>; N],
) -> Result<(), FactorError> {
    // Parents precede children, so every index below is in range.
    if parent
        .iter()
        .enumerate()
        .any(|(i, p)| p.is_some_and(|p| p >= i))
    {
        return Err(FactorError::NonFinite { pivot: 0 });
    }
    let mut anc = [0_usize; N];
    let mut row = [T::zero(); N];
    for k in (0..N).rev() {
        let d = m[k][k];
        if !d.is_finite() {
            return Err(FactorError::NonFinite { pivot: k });
        }
        if d <= T::zero() {
            return Err(FactorError::NotPositiveDefinite { pivot: k });
        }
        // k's ancestors, nearest first, and row k's entries there: gathered once, so that the
        // updates below are independent of each other (no walk up the tree inside them).
        let mut len = 0;
        let mut i = parent[k];
        while let Some(ii) = i {
            anc[len] = ii;
            row[len] = m[k][ii];
            len += 1;
            i = parent[ii];
        }
        for s in 0..len {
            let ii = anc[s];
            let a = row[s] / d;
            let target = &mut m[ii];
            for t in s..len {
                let v = row[t] * a;
                target[anc[t]] -= v;
            }
            m[k][ii] = a;
        }
    }
    Ok(())
}

/// Solves `M x = b` with the factors of [`ltdl_factor`] (`m` as it left it).
pub fn ltdl_substitute<T: Lane, const N: usize>(
    m: &[[T; N]; N],
    parent: &[Option<usize>; N],
    b: &[T; N],
) -> [T; N] {
    let mut x = *b;
    for i in (0..N).rev() {
        let mut j = parent[i];
        while let Some(jj) = j {
            let v = m[i][jj] * x[i];
            x[jj] -= v;
            j = parent[jj];
        }
    }
    for (i, xi) in x.iter_mut().enumerate() {
        *xi /= m[i][i];
    }
    for i in 0..N {
        let mut j = parent[i];
        while let Some(jj) = j {
            let v = m[i][jj] * x[jj];
            x[i] -= v;
            j = parent[jj];
        }
    }
    x
}

/// Solves `M x = b` for the mass matrix of a kinematic tree ([`ltdl_factor`], then
/// [`ltdl_substitute`]); `m` is overwritten by the factors. Fails like [`ltdl_factor`], or
/// with the first component of `x` that is not finite.
///
/// ```
/// use eomgen_runtime::tree::ltdl_solve;
/// // a two-joint chain
/// let mut m = [[2.0_f64, 0.5], [0.5, 1.0]];
/// let x = ltdl_solve(&mut m, &[None, Some(0)], &[2.5, 1.5]).unwrap();
/// assert!((x[0] - 1.0).abs() < 1e-12 && (x[1] - 1.0).abs() < 1e-12);
/// ```
pub fn ltdl_solve<T: Real, const N: usize>(
    m: &mut [[T; N]; N],
    parent: &[Option<usize>; N],
    b: &[T; N],
) -> Result<[T; N], FactorError> {
    ltdl_factor(m, parent)?;
    let x = ltdl_substitute(m, parent, b);
    match x.iter().position(|v| !v.is_finite()) {
        Some(pivot) => Err(FactorError::NonFinite { pivot }),
        None => Ok(x),
    }
}

/// The inverse of a tree's mass matrix: one factorization ([`ltdl_factor`]), then
/// [`ltdl_inverse_factored`]. `m` is overwritten by the factors. Fails like [`ltdl_factor`].
///
/// ```
/// use eomgen_runtime::tree::ltdl_inverse;
/// let mut m = [[2.0_f64, 0.0], [0.0, 4.0]];
/// assert_eq!(ltdl_inverse(&mut m, &[None, None]).unwrap(), [[0.5, 0.0], [0.0, 0.25]]);
/// ```
pub fn ltdl_inverse<T: Real, const N: usize>(
    m: &mut [[T; N]; N],
    parent: &[Option<usize>; N],
) -> Result<[[T; N]; N], FactorError> {
    ltdl_factor(m, parent)?;
    Ok(ltdl_inverse_factored(m, parent))
}

/// For each coordinate `i`, one past the largest coordinate of its subtree: the subtree of `i`
/// lies within `i..ends[i]` (parents precede children; other coordinates may lie in between).
fn subtree_ends<const N: usize>(parent: &[Option<usize>; N]) -> [usize; N] {
    let mut ends: [usize; N] = core::array::from_fn(|i| i + 1);
    for i in (0..N).rev() {
        let end = ends[i];
        if let Some(e) = parent[i].and_then(|p| ends.get_mut(p)) {
            *e = (*e).max(end);
        }
    }
    ends
}

/// `M^-1` from the factors of [`ltdl_factor`] (`m` as it left it): [`ltdl_substitute_rows`] on
/// the identity, with the structure it keeps (`L^-T` has row `i` nonzero only over `i`'s
/// subtree, and only the upper triangle of the result is formed, then mirrored: the result is
/// exactly symmetric). Every step is a scaled row, in chunks of [`CHUNK`] columns, gathered
/// into another, so the cost is at most `N` times the sum of the coordinates' depths.
///
/// ```
/// use eomgen_runtime::tree::{ltdl_factor, ltdl_inverse_factored};
/// let parent = [None, Some(0)];
/// let mut m = [[2.0_f64, 0.5], [0.5, 1.0]];
/// ltdl_factor(&mut m, &parent).unwrap();
/// let inv = ltdl_inverse_factored(&m, &parent);
/// let expected = [[1.0 / 1.75, -0.5 / 1.75], [-0.5 / 1.75, 2.0 / 1.75]];
/// for (row, e) in inv.iter().zip(&expected) {
///     assert!(row.iter().zip(e).all(|(x, y)| (x - y).abs() < 1e-15));
/// }
/// ```
pub fn ltdl_inverse_factored<T: Lane, const N: usize>(
    m: &[[T; N]; N],
    parent: &[Option<usize>; N],
) -> [[T; N]; N] {
    let mut x = [[T::zero(); N]; N];
    ltdl_inverse_factored_into(m, parent, &mut x);
    x
}

/// [`ltdl_inverse_factored`] written into `x` (whatever it held), for callers that keep the
/// result in place rather than on their stack twice.
///
/// ```
/// use eomgen_runtime::tree::{ltdl_factor, ltdl_inverse_factored, ltdl_inverse_factored_into};
/// let parent = [None, Some(0)];
/// let mut m = [[2.0_f64, 0.5], [0.5, 1.0]];
/// ltdl_factor(&mut m, &parent).unwrap();
/// let mut x = [[f64::NAN; 2]; 2];
/// ltdl_inverse_factored_into(&m, &parent, &mut x);
/// assert_eq!(x, ltdl_inverse_factored(&m, &parent));
/// ```
pub fn ltdl_inverse_factored_into<T: Lane, const N: usize>(
    m: &[[T; N]; N],
    parent: &[Option<usize>; N],
    x: &mut [[T; N]; N],
) {
    // The identity is not written first: the pass starts each row from its unit row itself.
    pull_from_subtrees::<T, N, N, true>(m, parent, x);
    pull_from_ancestors::<T, N, N, true>(m, parent, x);
    // The upper triangle mirrored, so that the result is exactly symmetric.
    for i in 1..N {
        let (upper, lower) = x.split_at_mut(i);
        for (j, above) in upper.iter().enumerate() {
            lower[0][j] = above[i];
        }
    }
}

/// Solves `M X = B` for the `C` columns of `x` (`B` on entry, `X` on return), with the factors
/// of [`ltdl_factor`] (`m` as it left it): [`ltdl_substitute`] on all columns at once, each
/// step a scaled row of `x` subtracted from another (vector operations over the `C` columns).
///
/// ```
/// use eomgen_runtime::tree::{ltdl_factor, ltdl_substitute_rows};
/// let parent = [None, Some(0)];
/// let mut m = [[2.0_f64, 0.5], [0.5, 1.0]];
/// ltdl_factor(&mut m, &parent).unwrap();
/// let mut x = [[2.5, 2.0, 0.0], [1.5, 0.5, 1.75]];
/// ltdl_substitute_rows(&m, &parent, &mut x);
/// let expected = [[1.0, 1.0, -0.5], [1.0, 0.0, 2.0]];
/// for (row, e) in x.iter().zip(&expected) {
///     assert!(row.iter().zip(e).all(|(x, y)| (x - y).abs() < 1e-15));
/// }
/// ```
pub fn ltdl_substitute_rows<T: Lane, const N: usize, const C: usize>(
    m: &[[T; N]; N],
    parent: &[Option<usize>; N],
    x: &mut [[T; C]; N],
) {
    pull_from_subtrees::<T, N, C, false>(m, parent, x);
    pull_from_ancestors::<T, N, C, false>(m, parent, x);
}

/// The first half of [`ltdl_substitute_rows`]: `x <- L^-T x` (from the leaves up), for
/// products that need only `L^-T J^T` (`J M^-1 J^T = W^T D^-1 W` with `W = L^-T J^T`).
///
/// ```
/// use eomgen_runtime::tree::{ltdl_factor, ltdl_lower_rows};
/// let parent = [None, Some(0)];
/// let mut m = [[2.0_f64, 0.5], [0.5, 1.0]];
/// ltdl_factor(&mut m, &parent).unwrap(); // L[1][0] = 0.5
/// let mut x = [[1.0], [2.0]];
/// ltdl_lower_rows(&m, &parent, &mut x);
/// assert_eq!(x, [[0.0], [2.0]]);
/// ```
pub fn ltdl_lower_rows<T: Lane, const N: usize, const C: usize>(
    m: &[[T; N]; N],
    parent: &[Option<usize>; N],
    x: &mut [[T; C]; N],
) {
    pull_from_subtrees::<T, N, C, false>(m, parent, x);
}

/// The passes over the `L^T D L` factors of a mass matrix (as [`ltdl_factor`] leaves them over
/// the coordinate tree `parent`) that solves with many right-hand sides make: the KKT
/// system's ([`crate::ContactKkt`]'s `_by` methods) in contact and impulse derivatives.
/// [`Walked`] walks the tree at run time; generated code implements the trait on the robot's
/// type with the same passes unrolled for its tree (the walks and branches done at generation
/// time), and passes itself.
///
/// ```
/// use eomgen_runtime::tree::{ltdl_factor, TreePasses, Walked};
/// let parent = [None, Some(0)];
/// let mut m = [[2.0_f64, 0.5], [0.5, 1.0]];
/// ltdl_factor(&mut m, &parent).unwrap();
/// let mut x = [[2.0, 0.5], [0.5, 1.0]]; // M itself: M^-1 M = I
/// Walked::substitute_rows(&m, &parent, &mut x);
/// let identity = [[1.0, 0.0], [0.0, 1.0]];
/// assert!(x.iter().flatten().zip(identity.iter().flatten()).all(|(a, b)| (a - b).abs() < 1e-15));
/// ```
pub trait TreePasses<T: Lane, const N: usize> {
    /// `x <- M^-1 x` for the `C` columns of `x`, as [`ltdl_substitute_rows`].
    fn substitute_rows<const C: usize>(
        m: &[[T; N]; N],
        parent: &[Option<usize>; N],
        x: &mut [[T; C]; N],
    );
    /// `M^-1` into `x`, whatever it held, as [`ltdl_inverse_factored_into`].
    fn inverse_into(m: &[[T; N]; N], parent: &[Option<usize>; N], x: &mut [[T; N]; N]);
}

/// [`TreePasses`] by the loops of this module over `parent`.
#[derive(Clone, Copy, Debug, Default)]
pub struct Walked;

impl<T: Lane, const N: usize> TreePasses<T, N> for Walked {
    fn substitute_rows<const C: usize>(
        m: &[[T; N]; N],
        parent: &[Option<usize>; N],
        x: &mut [[T; C]; N],
    ) {
        ltdl_substitute_rows(m, parent, x);
    }

    fn inverse_into(m: &[[T; N]; N], parent: &[Option<usize>; N], x: &mut [[T; N]; N]) {
        ltdl_inverse_factored_into(m, parent, x);
    }
}

/// `L^-T`: row `a` of `x` less `L[k][a]` times row `k` for every `k` of its subtree, from the
/// last row up (those rows final by then). Each row is gathered in one accumulator, read once
/// and written once ("pull"), rather than updated once per descendant ("push"): repeated
/// read-modify-writes of the same row stall on store forwarding, and on a 50-DoF humanoid the
/// push form took twice as long.
///
/// A row's updates go from its last descendant to its first: the rows finished first come
/// first, and the nearest rows, finished just before, last, so that the processor gathers the
/// rest while those are still being computed (a floating base's six rows gather from every
/// joint below them: in the other order each waited for the one below it). Generated code
/// unrolls the same order, to the bit: anymal's forward-dynamics derivatives 3.35 -> 3.18 us.
///
/// `SPARSE`: `x` is the identity, whatever it holds on entry (each row starts from its unit row,
/// and is written whole), and row `k` keeps its support `k..ends[k]` through this pass, so only
/// the chunks of columns there are gathered.
fn pull_from_subtrees<T: Lane, const N: usize, const C: usize, const SPARSE: bool>(
    m: &[[T; N]; N],
    parent: &[Option<usize>; N],
    x: &mut [[T; C]; N],
) {
    let ends = subtree_ends(parent);
    // `inside[k]`: `k` lies in the subtree of the row being gathered (rows between `a` and
    // `ends[a]` may belong to other subtrees when the order is not depth first).
    let mut inside = [false; N];
    for a in (0..N).rev() {
        for k in a + 1..ends[a] {
            inside[k] =
                parent[k].is_some_and(|p| p == a || (p > a && inside.get(p) == Some(&true)));
        }
        let mut acc = if SPARSE { unit_row(a) } else { x[a] };
        for k in (a + 1..ends[a]).rev().filter(|&k| inside[k]) {
            if SPARSE {
                sub_scaled_chunks(&mut acc, &x[k], m[k][a], k..ends[k]);
            } else {
                axpy(&mut acc, -m[k][a], &x[k]);
            }
        }
        x[a] = acc;
    }
}

/// Row `a` of the identity, `C` columns.
fn unit_row<T: Lane, const C: usize>(a: usize) -> [T; C] {
    let mut row = [T::zero(); C];
    if let Some(x) = row.get_mut(a) {
        *x = T::one();
    }
    row
}

/// `D^-1`, then `L^-1`: row `i` of `x` less `L[i][a]` times row `a` for every
/// ancestor `a`, from the first row down, gathered in one accumulator per row (see
/// [`pull_from_subtrees`]), the root's row first and the parent's (finished last) last.
///
/// `UPPER`: only the columns from `i` on are needed in row `i` (a symmetric result, mirrored
/// afterwards), so only the chunks of columns there are gathered; the columns before `i` in
/// the first chunk hold partial sums.
fn pull_from_ancestors<T: Lane, const N: usize, const C: usize, const UPPER: bool>(
    m: &[[T; N]; N],
    parent: &[Option<usize>; N],
    x: &mut [[T; C]; N],
) {
    // Each row's ancestors, parent first (at most N: a cycle cannot loop).
    let mut chain = [0; N];
    for i in 0..N {
        let mut acc = x[i];
        // One division per row rather than per column.
        let inv = T::one() / m[i][i];
        acc.iter_mut().for_each(|v| *v *= inv);
        let mut len = 0;
        let mut a = parent[i];
        while let (Some(aa), Some(slot)) = (a, chain.get_mut(len)) {
            *slot = aa;
            len += 1;
            a = parent.get(aa).copied().flatten();
        }
        for &aa in chain.iter().take(len).rev() {
            let Some(row) = x.get(aa) else { continue };
            if UPPER {
                sub_scaled_chunks(&mut acc, row, m[i][aa], i..C);
            } else {
                axpy(&mut acc, -m[i][aa], row);
            }
        }
        x[i] = acc;
    }
}

/// Columns per chunk of the passes of [`ltdl_inverse_factored_into`]: an update of a row
/// covers only the chunks that overlap the columns it can change. Generated code that unrolls
/// the inverse chunks its updates the same way, so that its result is this one's to the bit.
///
/// Two columns: the compiler vectorizes the unrolled updates its own way whatever the chunk,
/// and narrow chunks leave it less needless work. Chunks of 8 (an AVX-512 register of `f64`),
/// 4, 2 and 1, alternated (28 November 2026, native): anymal's `mass_matrix_inverse` 672,
/// 609, 585 and 647 ns; g1's 2.43 us at 8, 2.35 at 2; talos's the same within 1 %.
pub const CHUNK: usize = 2;

/// `acc -= k row` ([`axpy`]) on the chunks of [`CHUNK`] columns that overlap `columns` only (a loop of
/// constant length, so that the compiler still unrolls it and keeps `acc` in registers).
#[inline(always)]
fn sub_scaled_chunks<T: Lane, const C: usize>(
    acc: &mut [T; C],
    row: &[T; C],
    k: T,
    columns: core::ops::Range<usize>,
) {
    let k = -k;
    for c in 0..C.div_ceil(CHUNK) {
        let lo = c * CHUNK;
        if lo + CHUNK > columns.start && lo < columns.end {
            for j in lo..(lo + CHUNK).min(C) {
                acc[j] = k.mul_add(row[j], acc[j]);
            }
        }
    }
}

/// `-a b` for square matrices, the product forward-dynamics derivatives need
/// (`d qdd / d x = -M^-1 d tau / d x`).
pub fn neg_mat_mul<T: Lane, const N: usize>(a: &[[T; N]; N], b: &[[T; N]; N]) -> [[T; N]; N] {
    let mut out = [[T::zero(); N]; N];
    for (i, row) in out.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            let mut s = T::zero();
            for k in 0..N {
                s += a[i][k] * b[k][j];
            }
            *x = -s;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A floating base's six coordinates, then two limbs interleaved (not depth first) and a
    /// branch: the orders `ltdl_inverse_factored` must handle.
    const PARENT: [Option<usize>; 13] = [
        None,
        Some(0),
        Some(1),
        Some(2),
        Some(3),
        Some(4),
        Some(5),
        Some(5),
        Some(6),
        Some(7),
        Some(8),
        Some(9),
        Some(8),
    ];

    /// Symmetric positive definite, nonzero exactly where one coordinate is above the other.
    fn matrix() -> [[f64; 13]; 13] {
        let above = |i: usize, j: usize| {
            let mut k = PARENT[i];
            while let Some(p) = k {
                if p == j {
                    return true;
                }
                k = PARENT[p];
            }
            false
        };
        core::array::from_fn(|i| {
            core::array::from_fn(|j| match () {
                _ if i == j => 3.0 + 0.25 * i as f64,
                _ if above(i, j) || above(j, i) => 0.2 + 0.03 * (i * j % 7) as f64,
                _ => 0.0,
            })
        })
    }

    #[test]
    fn inverse_of_a_branched_tree_out_of_depth_first_order() {
        let m = matrix();
        let mut f = m;
        ltdl_factor(&mut f, &PARENT).unwrap();
        let inv = ltdl_inverse_factored(&f, &PARENT);
        for (i, row) in m.iter().enumerate() {
            for (j, column) in inv.iter().enumerate() {
                // `inv` is symmetric: its row `j` is its column `j`.
                let p: f64 = row.iter().zip(column).map(|(a, b)| a * b).sum();
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((p - want).abs() < 1e-14, "({i}, {j}): {p}");
                assert_eq!(inv[i][j], inv[j][i]);
            }
        }
    }
}
