//! A link frame's velocity, classical acceleration and Jacobian time variation, walked along
//! its chain at run time from the per-joint transforms generated code supplies (as
//! [`crate::tree::chain_jacobian`] does for the Jacobian), in Pinocchio's
//! `LOCAL_WORLD_ALIGNED` convention: spatial vectors are [linear (3), angular (3)] at the
//! frame's origin, in world axes.
//!
//! The rates are those of the joint tree's velocity columns: a floating base's six (linear,
//! then angular velocity in base axes), and per joint one, or six for a free flyer below the
//! root ([`Motion::Free`]: its body's linear, then angular velocity relative to its parent,
//! in its own axes), in joint order.

use crate::tree::{cross, Motion, TreeJoint};
use crate::{Lane, Pose};

/// A frame on a kinematic chain, as generated code describes it.
///
/// With a floating base, body 0 is the base (moved by the free flyer, velocity columns 0 to 5)
/// and body `b >= 1` is moved by `joints[b - 1]`; without one, body `j` is moved by
/// `joints[j]`. A joint's columns follow those of the joints before it (one each, six for a
/// [`Motion::Free`] joint) and the base's six.
#[derive(Clone, Copy, Debug)]
pub struct Chain<'a, T, F> {
    /// The bodies from the root to the frame's body.
    pub path: &'a [usize],
    /// Every joint's axis and motion.
    pub joints: &'a [TreeJoint],
    /// Whether body 0 is a floating base.
    pub floating: bool,
    /// The pose of body `b` in its parent body's frame (a floating base's in the world).
    pub transform: F,
    /// The frame's pose in the last body of `path`.
    pub placement: Pose<T>,
}

/// A body's world pose, angular velocity, velocity of its origin, angular acceleration and
/// classical acceleration of its origin, all in world axes.
#[derive(Clone, Copy, Debug)]
struct State<T> {
    pose: Pose<T>,
    w: [T; 3],
    v: [T; 3],
    dw: [T; 3],
    a: [T; 3],
}

impl<T: Lane> State<T> {
    /// The world (or a fixed root): at rest.
    fn rest() -> State<T> {
        let z = [T::zero(); 3];
        State {
            pose: Pose::identity(),
            w: z,
            v: z,
            dw: z,
            a: z,
        }
    }
}

fn add<T: Lane>(a: &[T; 3], b: &[T; 3]) -> [T; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn sub<T: Lane>(a: &[T; 3], b: &[T; 3]) -> [T; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn scale<T: Lane>(a: &[T; 3], k: T) -> [T; 3] {
    [a[0] * k, a[1] * k, a[2] * k]
}

/// Entry `i` of `x`, zero beyond its end.
fn at<T: Lane>(x: &[T], i: usize) -> T {
    x.get(i).copied().unwrap_or_else(T::zero)
}

/// A free flyer's body state `s` (its pose, and its parent's motion carried to its origin)
/// with the joint's own motion added: velocity `(lin, ang)` and acceleration `(dlin, dang)`
/// in its axes from columns `col..col + 6`. Relative to the parent, the origin moves at
/// `R lin` and accelerates at `R (dlin + ang x lin)`, the body turns at `R ang` and
/// accelerates at `R dang`; the parent's rotation `w_p` adds `2 w_p x R lin` (Coriolis) and
/// `w_p x R ang` (`pw`, the parent's angular velocity).
fn free_step<T: Lane>(s: &mut State<T>, pw: &[T; 3], col: usize, qd: &[T], qdd: Option<&[T]>) {
    let part = |x: &[T], k: usize| [at(x, col + k), at(x, col + k + 1), at(x, col + k + 2)];
    let (lin, ang) = (part(qd, 0), part(qd, 3));
    let (v_rel, w_rel) = (s.pose.transform_vector(&lin), s.pose.transform_vector(&ang));
    s.v = add(&s.v, &v_rel);
    s.w = add(&s.w, &w_rel);
    if let Some(qdd) = qdd {
        let (dlin, dang) = (part(qdd, 0), part(qdd, 3));
        let dw = add(&s.pose.transform_vector(&dang), &cross(pw, &w_rel));
        s.dw = add(&s.dw, &dw);
        let a_rel = s.pose.transform_vector(&add(&dlin, &cross(&ang, &lin)));
        let coriolis = scale(&cross(pw, &v_rel), T::from_f64(2.0));
        s.a = add(&s.a, &add(&a_rel, &coriolis));
    }
}

impl<T: Lane, F: Fn(usize) -> Pose<T>> Chain<'_, T, F> {
    /// The first velocity column and joint of body `b`, unless it is a floating base.
    fn joint(&self, b: usize) -> Option<(usize, TreeJoint)> {
        let j = if self.floating { b.checked_sub(1)? } else { b };
        let before: usize = self
            .joints
            .get(..j)?
            .iter()
            .map(|t| t.motion.columns())
            .sum();
        Some((
            before + 6 * usize::from(self.floating),
            *self.joints.get(j)?,
        ))
    }

    /// The floating base's state from its rates (base axes) `qd`, `qdd`.
    fn base(&self, qd: &[T], qdd: &[T]) -> State<T> {
        let pose = (self.transform)(0);
        let lin = [at(qd, 0), at(qd, 1), at(qd, 2)];
        let ang = [at(qd, 3), at(qd, 4), at(qd, 5)];
        let dlin = [at(qdd, 0), at(qdd, 1), at(qdd, 2)];
        let dang = [at(qdd, 3), at(qdd, 4), at(qdd, 5)];
        State {
            pose,
            w: pose.transform_vector(&ang),
            v: pose.transform_vector(&lin),
            dw: pose.transform_vector(&dang),
            a: pose.transform_vector(&add(&dlin, &cross(&ang, &lin))),
        }
    }

    /// Body `b`'s state in place of its parent's `s`; without `qdd`, the accelerations stay
    /// as they are (zero from the rest). Updated field by field where it lies: built whole and
    /// moved, the state was stored in narrow parts and copied back by wide loads, which cannot
    /// be forwarded (a stall per body).
    fn step(&self, s: &mut State<T>, b: usize, qd: &[T], qdd: Option<&[T]>) {
        if self.floating && b == 0 {
            *s = self.base(qd, qdd.unwrap_or(&[]));
            return;
        }
        let (parent, pw, pdw) = (s.pose, s.w, s.dw);
        s.pose = parent.compose(&(self.transform)(b));
        let r = sub(&s.pose.translation, &parent.translation);
        let wr = cross(&pw, &r);
        s.v = add(&s.v, &wr);
        if qdd.is_some() {
            s.a = add(&s.a, &add(&cross(&pdw, &r), &cross(&pw, &wr)));
        }
        match self.joint(b) {
            Some((col, joint)) if joint.motion == Motion::Free => free_step(s, &pw, col, qd, qdd),
            Some((col, joint)) => {
                let y = qdd.map(|qdd| at(qdd, col));
                joint_step(s, &pw, joint, at(qd, col), y);
            }
            None => {}
        }
    }

    /// The last body's state, calling `visit(b, state)` for every body `b` of the path.
    fn walk(
        &self,
        qd: &[T],
        qdd: Option<&[T]>,
        mut visit: impl FnMut(usize, &State<T>),
    ) -> State<T> {
        let mut s = State::rest();
        for &b in self.path {
            self.step(&mut s, b, qd, qdd);
            visit(b, &s);
        }
        s
    }

    /// The frame's origin relative to the last body's origin, world axes.
    fn lever(&self, last: &State<T>) -> [T; 3] {
        last.pose.transform_vector(&self.placement.translation)
    }
}

/// A revolute or prismatic joint's body state `s` (its pose, and its parent's motion carried
/// to its origin) with the joint's own motion added: rate `x` and, with accelerations, `y`
/// (`pw`, the parent's angular velocity).
fn joint_step<T: Lane>(s: &mut State<T>, pw: &[T; 3], joint: TreeJoint, x: T, y: Option<T>) {
    let z = s.pose.transform_vector(&joint.axis.map(T::from_f64));
    let (rotates, zx) = (joint.motion == Motion::Rotation, scale(&z, x));
    if rotates {
        s.w = add(&s.w, &zx);
    } else {
        s.v = add(&s.v, &zx);
    }
    if let Some(y) = y {
        let zy = scale(&z, y);
        let wz = cross(pw, &zx);
        if rotates {
            s.dw = add(&s.dw, &add(&zy, &wz));
        } else {
            s.a = add(&s.a, &add(&zy, &scale(&wz, T::from_f64(2.0))));
        }
    }
}

/// The frame's spatial velocity (Pinocchio's `getFrameVelocity`, `LOCAL_WORLD_ALIGNED`) at the
/// tree rates `qd`.
///
/// ```
/// use eomgen_runtime::frame::{velocity, Chain};
/// use eomgen_runtime::tree::{Motion, TreeJoint};
/// use eomgen_runtime::Pose;
/// // one revolute joint about z, the frame 1 m along the body's x axis, turning at 2 rad/s
/// let joints = [TreeJoint { axis: [0.0, 0.0, 1.0], motion: Motion::Rotation }];
/// let chain = Chain { path: &[0], joints: &joints, floating: false, transform: |_| Pose::identity(), placement: Pose::from_translation([1.0_f64, 0.0, 0.0]) };
/// assert_eq!(velocity(&chain, &[2.0]), [0.0, 2.0, 0.0, 0.0, 0.0, 2.0]);
/// ```
pub fn velocity<T: Lane, F: Fn(usize) -> Pose<T>>(chain: &Chain<'_, T, F>, qd: &[T]) -> [T; 6] {
    let s = chain.walk(qd, None, |_, _| {});
    let v = add(&s.v, &cross(&s.w, &chain.lever(&s)));
    [v[0], v[1], v[2], s.w[0], s.w[1], s.w[2]]
}

/// The frame's classical acceleration (Pinocchio's `getFrameClassicalAcceleration`,
/// `LOCAL_WORLD_ALIGNED`): the acceleration of its origin and its angular acceleration, at
/// the tree rates `qd` and their derivatives `qdd`.
///
/// ```
/// use eomgen_runtime::frame::{acceleration, Chain};
/// use eomgen_runtime::tree::{Motion, TreeJoint};
/// use eomgen_runtime::Pose;
/// // turning at 2 rad/s, 1 m from the axis: 4 m/s^2 towards it
/// let joints = [TreeJoint { axis: [0.0, 0.0, 1.0], motion: Motion::Rotation }];
/// let chain = Chain { path: &[0], joints: &joints, floating: false, transform: |_| Pose::identity(), placement: Pose::from_translation([1.0_f64, 0.0, 0.0]) };
/// assert_eq!(acceleration(&chain, &[2.0], &[0.0]), [-4.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
/// ```
pub fn acceleration<T: Lane, F: Fn(usize) -> Pose<T>>(
    chain: &Chain<'_, T, F>,
    qd: &[T],
    qdd: &[T],
) -> [T; 6] {
    let s = chain.walk(qd, Some(qdd), |_, _| {});
    let r = chain.lever(&s);
    let wr = cross(&s.w, &r);
    let a = add(&s.a, &add(&cross(&s.dw, &r), &cross(&s.w, &wr)));
    [a[0], a[1], a[2], s.dw[0], s.dw[1], s.dw[2]]
}

/// The time derivative of the frame's 6 x N Jacobian (Pinocchio's
/// `getFrameJacobianTimeVariation`, `LOCAL_WORLD_ALIGNED`) at the tree rates `qd`: a column
/// `(z x (p - o); z)` of a rotation about the axis `z` through `o` changes at
/// `(dz x (p - o) + z x (dp - do); dz)`, one `(z; 0)` of a translation at `(dz; 0)`, with
/// `dz = w x z` (`w` the angular velocity of the body moved).
///
/// ```
/// use eomgen_runtime::frame::{jacobian_time_variation, Chain};
/// use eomgen_runtime::tree::{Motion, TreeJoint};
/// use eomgen_runtime::Pose;
/// // the column (-y, x, 0; 0, 0, 1) of a point at angle t turns: its rate is (-x, -y, 0) w
/// let joints = [TreeJoint { axis: [0.0, 0.0, 1.0], motion: Motion::Rotation }];
/// let chain = Chain { path: &[0], joints: &joints, floating: false, transform: |_| Pose::identity(), placement: Pose::from_translation([1.0_f64, 0.0, 0.0]) };
/// let dj: [[f64; 1]; 6] = jacobian_time_variation(&chain, &[2.0]);
/// assert_eq!(dj, [[-2.0], [0.0], [0.0], [0.0], [0.0], [0.0]]);
/// ```
pub fn jacobian_time_variation<T: Lane, F: Fn(usize) -> Pose<T>, const N: usize>(
    chain: &Chain<'_, T, F>,
    qd: &[T; N],
) -> [[T; N]; 6] {
    let mut bodies = [(0, State::rest()); N];
    let mut count = 0;
    let last = chain.walk(qd, None, |b, s| {
        if let Some(slot) = bodies.get_mut(count) {
            *slot = (b, *s);
            count += 1;
        }
    });
    let lever = chain.lever(&last);
    let p = add(&last.pose.translation, &lever);
    let dp = add(&last.v, &cross(&last.w, &lever));
    let mut out = [[T::zero(); N]; 6];
    let mut put = |col: usize, lin: [T; 3], ang: [T; 3]| {
        for k in 0..3 {
            if let Some(x) = out[k].get_mut(col) {
                *x = lin[k];
            }
            if let Some(x) = out[3 + k].get_mut(col) {
                *x = ang[k];
            }
        }
    };
    // A rotation's column about the axis `z` through the origin of `s`.
    let rotation = |s: &State<T>, z: &[T; 3]| {
        let dz = cross(&s.w, z);
        let r = sub(&p, &s.pose.translation);
        let lin = add(&cross(&dz, &r), &cross(z, &sub(&dp, &s.v)));
        (lin, dz)
    };
    let zero = [T::zero(); 3];
    // A free flyer's six columns from `col`: translations, then rotations, along and about
    // its body's axes `e`, which turn with the body.
    let free = |col: usize, s: &State<T>, put: &mut dyn FnMut(usize, [T; 3], [T; 3])| {
        for k in 0..3 {
            let e = [0, 1, 2].map(|r| s.pose.rotation[r][k]);
            put(col + k, cross(&s.w, &e), zero);
            let (lin, ang) = rotation(s, &e);
            put(col + 3 + k, lin, ang);
        }
    };
    for (b, s) in bodies.iter().take(count) {
        if chain.floating && *b == 0 {
            free(0, s, &mut put);
        } else if let Some((col, joint)) = chain.joint(*b) {
            let z = s.pose.transform_vector(&joint.axis.map(T::from_f64));
            match joint.motion {
                Motion::Rotation => {
                    let (lin, ang) = rotation(s, &z);
                    put(col, lin, ang);
                }
                Motion::Translation => put(col, cross(&s.w, &z), zero),
                Motion::Free => free(col, s, &mut put),
            }
        }
    }
    out
}

/// The joint tree's rates from a robot's coordinates when some joints follow others (URDF
/// mimic joints, the `COUPLING` table of generated code): velocity column `j` moves at
/// `coupling[j].1` times the rate of coordinate `coupling[j].0`.
///
/// ```
/// use eomgen_runtime::frame::tree_rates;
/// // three joints; the third follows the first at twice its rate
/// let rates: [f64; 3] = tree_rates(&[1.0, 5.0], &[(0, 1.0), (1, 1.0), (0, 2.0)]);
/// assert_eq!(rates, [1.0, 5.0, 2.0]);
/// ```
pub fn tree_rates<T: Lane, const N: usize>(qd: &[T], coupling: &[(usize, f64); N]) -> [T; N] {
    coupling.map(|(c, k)| T::from_f64(k) * at(qd, c))
}
