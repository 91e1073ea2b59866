//! The MPC kit's kinematics (issue 29) through compiled generated code: link velocities,
//! classical accelerations and Jacobian time variations, the configuration manifold and the
//! centroidal momentum rate of the panda (fixed base) and anymal (floating base), against
//! Pinocchio 4.1's values in `robots/panda.mpc.json` and `robots/floating/anymal.mpc.json`
//! (1e-9 relative, elementwise), and against central finite differences through `integrate`.

#![allow(clippy::needless_range_loop)]

use eomgen_tests::floating_reference::{flat, numbers, pick, robot_file, Order, Worst};
use eomgen_tests::robots::{anymal_mpc::*, panda_mpc::*};
use serde_json::Value;

const TOLERANCE: f64 = 1e-9;
/// Central differences with step `STEP`: truncation about `STEP^2`, rounding about
/// `1e-16 / STEP`, times the size of the derivatives.
const STEP: f64 = 1e-5;
const FD_TOLERANCE: f64 = 1e-6;

/// Elementwise `|a - b| / max(1, |b|)`.
fn elementwise(ours: &[f64], reference: &[f64]) -> f64 {
    assert_eq!(ours.len(), reference.len());
    ours.iter()
        .zip(reference)
        .map(|(a, b)| (a - b).abs() / b.abs().max(1.0))
        .fold(0.0, f64::max)
}

/// A robot generated with the kit, as the checks see it (links by name).
trait Kit<const NQ: usize, const NV: usize> {
    const FLOATING: bool;
    fn joint_names() -> Vec<&'static str>;
    fn link_names() -> Vec<&'static str>;
    fn jacobian(&self, link: &str, q: &[f64; NQ]) -> [[f64; NV]; 6];
    fn velocity(&self, link: &str, q: &[f64; NQ], v: &[f64; NV]) -> [f64; 6];
    fn acceleration(&self, link: &str, q: &[f64; NQ], v: &[f64; NV], a: &[f64; NV]) -> [f64; 6];
    fn jacobian_rate(&self, link: &str, q: &[f64; NQ], v: &[f64; NV]) -> [[f64; NV]; 6];
    fn integrate(&self, q: &[f64; NQ], v: &[f64; NV]) -> [f64; NQ];
    fn difference(&self, q0: &[f64; NQ], q1: &[f64; NQ]) -> [f64; NV];
    #[allow(clippy::type_complexity)]
    fn integrate_jacobians(
        &self,
        q: &[f64; NQ],
        v: &[f64; NV],
    ) -> ([[f64; NV]; NV], [[f64; NV]; NV]);
    #[allow(clippy::type_complexity)]
    fn difference_jacobians(
        &self,
        q0: &[f64; NQ],
        q1: &[f64; NQ],
    ) -> ([[f64; NV]; NV], [[f64; NV]; NV]);
    /// `integrate_jacobians_into` and `difference_jacobians_into`, into `m` in that order.
    fn jacobians_into(
        &self,
        states: (&[f64; NQ], &[f64; NV], &[f64; NQ]),
        m: &mut [[[f64; NV]; NV]; 4],
    );
}

macro_rules! kit {
    ($ty:ident, $link:ident, $nq:literal, $nv:literal, $floating:literal, $integrate:expr) => {
        impl Kit<$nq, $nv> for $ty<f64> {
            const FLOATING: bool = $floating;
            fn joint_names() -> Vec<&'static str> {
                $ty::<f64>::JOINT_NAMES.to_vec()
            }
            fn link_names() -> Vec<&'static str> {
                $link::ALL.iter().map(|l| l.name()).collect()
            }
            fn jacobian(&self, link: &str, q: &[f64; $nq]) -> [[f64; $nv]; 6] {
                self.link_jacobian(find(&$link::ALL, |l| l.name(), link), q)
            }
            fn velocity(&self, link: &str, q: &[f64; $nq], v: &[f64; $nv]) -> [f64; 6] {
                self.link_velocity(find(&$link::ALL, |l| l.name(), link), q, v)
            }
            fn acceleration(
                &self,
                link: &str,
                q: &[f64; $nq],
                v: &[f64; $nv],
                a: &[f64; $nv],
            ) -> [f64; 6] {
                self.link_acceleration(find(&$link::ALL, |l| l.name(), link), q, v, a)
            }
            fn jacobian_rate(&self, link: &str, q: &[f64; $nq], v: &[f64; $nv]) -> [[f64; $nv]; 6] {
                self.link_jacobian_time_variation(find(&$link::ALL, |l| l.name(), link), q, v)
            }
            fn integrate(&self, q: &[f64; $nq], v: &[f64; $nv]) -> [f64; $nq] {
                let f: fn(&$ty<f64>, &[f64; $nq], &[f64; $nv]) -> [f64; $nq] = $integrate;
                f(self, q, v)
            }
            fn difference(&self, q0: &[f64; $nq], q1: &[f64; $nq]) -> [f64; $nv] {
                $ty::difference(self, q0, q1)
            }
            fn integrate_jacobians(
                &self,
                q: &[f64; $nq],
                v: &[f64; $nv],
            ) -> ([[f64; $nv]; $nv], [[f64; $nv]; $nv]) {
                $ty::integrate_jacobians(self, q, v)
            }
            fn difference_jacobians(
                &self,
                q0: &[f64; $nq],
                q1: &[f64; $nq],
            ) -> ([[f64; $nv]; $nv], [[f64; $nv]; $nv]) {
                $ty::difference_jacobians(self, q0, q1)
            }
            fn jacobians_into(
                &self,
                (q, v, q1): (&[f64; $nq], &[f64; $nv], &[f64; $nq]),
                m: &mut [[[f64; $nv]; $nv]; 4],
            ) {
                let [a, b, c, d] = m;
                $ty::integrate_jacobians_into(self, q, v, a, b);
                $ty::difference_jacobians_into(self, q, q1, c, d);
            }
        }
    };
}

fn find<L: Copy>(all: &[L], name: impl Fn(L) -> &'static str, wanted: &str) -> L {
    *all.iter().find(|&&l| name(l) == wanted).unwrap()
}

kit!(PandaMpc, PandaMpcLink, 9, 9, false, |_, q, v| {
    core::array::from_fn(|i| q[i] + v[i])
});
kit!(AnymalMpc, AnymalMpcLink, 19, 18, true, |r, q, v| r
    .integrate(q, v, 1.0));

/// Every sample's link motion and manifold functions against the reference.
fn against_reference<R: Kit<NQ, NV>, const NQ: usize, const NV: usize>(
    r: &R,
    doc: &Value,
) -> Worst {
    let o = Order::with_base(doc, &R::joint_names(), R::FLOATING);
    let all6: Vec<usize> = (0..6).collect();
    let mut worst = Worst::default();
    let samples = doc["samples"].as_array().unwrap();
    assert_eq!(samples.len(), 8);
    for s in samples {
        let q: [f64; NQ] = Order::arr(&o.q, &s["q"]);
        let q1: [f64; NQ] = Order::arr(&o.q, &s["q1"]);
        let v: [f64; NV] = Order::arr(&o.v, &s["v"]);
        let a: [f64; NV] = Order::arr(&o.v, &s["a"]);
        let links = s["links"].as_object().unwrap();
        assert!(!links.is_empty());
        for (name, l) in links {
            let vel = r.velocity(name, &q, &v);
            worst.note(
                "link_velocity",
                elementwise(&vel, &numbers(&l["link_velocity"])),
            );
            let acc = r.acceleration(name, &q, &v, &a);
            worst.note(
                "link_acceleration",
                elementwise(&acc, &numbers(&l["link_acceleration"])),
            );
            let dj = flat(&r.jacobian_rate(name, &q, &v));
            let reference = pick(&l["link_jacobian_time_variation"], &all6, &o.v);
            worst.note("link_jacobian_time_variation", elementwise(&dj, &reference));
        }
        let diff = r.difference(&q, &q1);
        let reference: Vec<f64> = o.v.iter().map(|&i| numbers(&s["difference"])[i]).collect();
        worst.note("difference", elementwise(&diff, &reference));
        let (dq, dv) = r.integrate_jacobians(&q, &v);
        let ij = &s["integrate_jacobians"];
        worst.note(
            "integrate_jacobians",
            elementwise(&flat(&dq), &pick(&ij["dq"], &o.v, &o.v)),
        );
        worst.note(
            "integrate_jacobians",
            elementwise(&flat(&dv), &pick(&ij["dv"], &o.v, &o.v)),
        );
        let (d0, d1) = r.difference_jacobians(&q, &q1);
        let dj = &s["difference_jacobians"];
        worst.note(
            "difference_jacobians",
            elementwise(&flat(&d0), &pick(&dj["dq0"], &o.v, &o.v)),
        );
        worst.note(
            "difference_jacobians",
            elementwise(&flat(&d1), &pick(&dj["dq1"], &o.v, &o.v)),
        );
    }
    worst
}

#[test]
fn panda_matches_pinocchio() {
    let doc = robot_file("panda.mpc.json");
    let worst = against_reference(&PandaMpc::<f64>::default(), &doc);
    worst.check("panda", |_| TOLERANCE, 1);
}

#[test]
fn anymal_matches_pinocchio() {
    let doc = robot_file("floating/anymal.mpc.json");
    let r = AnymalMpc::<f64>::default();
    let mut worst = against_reference(&r, &doc);
    let o = Order::new(&doc, &AnymalMpc::<f64>::JOINT_NAMES);
    for s in doc["samples"].as_array().unwrap() {
        let q: [f64; 19] = Order::arr(&o.q, &s["q"]);
        let v: [f64; 18] = Order::arr(&o.v, &s["v"]);
        let a: [f64; 18] = Order::arr(&o.v, &s["a"]);
        let rate = r.centroidal_momentum_rate(&q, &v, &a);
        let reference = numbers(&s["centroidal_momentum_rate"]);
        worst.note("centroidal_momentum_rate", elementwise(&rate, &reference));
    }
    worst.check("anymal", |_| TOLERANCE, 1);
}

/// The reference file's states in our order: (q, v, a, q1).
#[allow(clippy::type_complexity)]
fn states<R: Kit<NQ, NV>, const NQ: usize, const NV: usize>(
    doc: &Value,
) -> Vec<([f64; NQ], [f64; NV], [f64; NV], [f64; NQ])> {
    let o = Order::with_base(doc, &R::joint_names(), R::FLOATING);
    doc["samples"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| {
            (
                Order::arr(&o.q, &s["q"]),
                Order::arr(&o.v, &s["v"]),
                Order::arr(&o.v, &s["a"]),
                Order::arr(&o.q, &s["q1"]),
            )
        })
        .collect()
}

/// `(f(h) - f(-h)) / 2h` at `h = STEP`.
fn central(f: impl Fn(f64) -> Vec<f64>) -> Vec<f64> {
    let (plus, minus) = (f(STEP), f(-STEP));
    plus.iter()
        .zip(&minus)
        .map(|(p, m)| (p - m) / (2.0 * STEP))
        .collect()
}

/// `x + h e_j`.
fn nudge<const N: usize>(x: &[f64; N], j: usize, h: f64) -> [f64; N] {
    let mut y = *x;
    y[j] += h;
    y
}

/// `e_j h`.
fn unit<const N: usize>(j: usize, h: f64) -> [f64; N] {
    nudge(&[0.0; N], j, h)
}

/// Column `j` of a matrix.
fn column<const N: usize>(m: &[[f64; N]; N], j: usize) -> Vec<f64> {
    m.iter().map(|row| row[j]).collect()
}

/// Through `integrate` and `difference`: `difference(q, integrate(q, v)) = v`, and central
/// differences of both in the tangent spaces against their Jacobians.
fn manifold_checks<R: Kit<NQ, NV>, const NQ: usize, const NV: usize>(r: &R, doc: &Value) -> Worst {
    let mut worst = Worst::default();
    // The `_into` forms write into matrices zeroed once and then holding the previous state's.
    let mut into = [[[0.0; NV]; NV]; 4];
    for (q, v, _, q1) in states::<R, NQ, NV>(doc) {
        // A displacement of moderate size (the samples' velocities reach 10 rad/s).
        let small = v.map(|x| 0.1 * x);
        let back = r.difference(&q, &r.integrate(&q, &small));
        worst.note(
            "difference(q, integrate(q, v)) = v",
            elementwise(&back, &small),
        );
        let end = r.integrate(&q, &small);
        let (dq, dv) = r.integrate_jacobians(&q, &small);
        let (d0, d1) = r.difference_jacobians(&q, &q1);
        r.jacobians_into((&q, &small, &q1), &mut into);
        assert_eq!(into, [dq, dv, d0, d1], "the _into forms");
        let base = r.difference(&q, &q1);
        for j in 0..NV {
            let fd = central(|h| {
                let moved = r.integrate(&r.integrate(&q, &unit(j, h)), &small);
                r.difference(&end, &moved).to_vec()
            });
            worst.note("integrate_jacobians dq", elementwise(&fd, &column(&dq, j)));
            let fd = central(|h| {
                r.difference(&end, &r.integrate(&q, &nudge(&small, j, h)))
                    .to_vec()
            });
            worst.note("integrate_jacobians dv", elementwise(&fd, &column(&dv, j)));
            let fd = central(|h| {
                let d = r.difference(&r.integrate(&q, &unit(j, h)), &q1);
                d.iter().zip(&base).map(|(x, y)| x - y).collect()
            });
            worst.note(
                "difference_jacobians dq0",
                elementwise(&fd, &column(&d0, j)),
            );
            let fd = central(|h| r.difference(&q, &r.integrate(&q1, &unit(j, h))).to_vec());
            worst.note(
                "difference_jacobians dq1",
                elementwise(&fd, &column(&d1, j)),
            );
        }
    }
    worst
}

/// Along the motion `q(t) = integrate(q, v t)`, `v(t) = v + a t`, every link's: the rate of
/// `link_jacobian` is `link_jacobian_time_variation`, the rate of `link_velocity` is
/// `link_acceleration`; and `link_velocity = J v`, `link_acceleration = J a + dJ/dt v`.
fn frame_checks<R: Kit<NQ, NV>, const NQ: usize, const NV: usize>(r: &R, doc: &Value) -> Worst {
    let mut worst = Worst::default();
    for (q, v, a, _) in states::<R, NQ, NV>(doc) {
        let at = |h: f64| {
            (
                r.integrate(&q, &v.map(|x| x * h)),
                core::array::from_fn(|i| v[i] + a[i] * h),
            )
        };
        for link in R::link_names() {
            let dj = r.jacobian_rate(link, &q, &v);
            let fd = central(|h| flat(&r.jacobian(link, &at(h).0)));
            worst.note("d link_jacobian / dt", elementwise(&fd, &flat(&dj)));
            let acc = r.acceleration(link, &q, &v, &a);
            let fd = central(|h| {
                let (qh, vh) = at(h);
                r.velocity(link, &qh, &vh).to_vec()
            });
            worst.note("d link_velocity / dt", elementwise(&fd, &acc));
            let j = r.jacobian(link, &q);
            let jv: Vec<f64> = (0..6)
                .map(|k| (0..NV).map(|c| j[k][c] * v[c]).sum())
                .collect();
            worst.note("J v", elementwise(&r.velocity(link, &q, &v), &jv));
            let ja: Vec<f64> = (0..6)
                .map(|k| (0..NV).map(|c| j[k][c] * a[c] + dj[k][c] * v[c]).sum())
                .collect();
            worst.note("J a + dJ v", elementwise(&acc, &ja));
        }
    }
    worst
}

#[test]
fn panda_manifold_matches_finite_differences() {
    let doc = robot_file("panda.mpc.json");
    manifold_checks(&PandaMpc::<f64>::default(), &doc).check("panda", |_| FD_TOLERANCE, 1);
}

#[test]
fn anymal_manifold_matches_finite_differences() {
    let doc = robot_file("floating/anymal.mpc.json");
    manifold_checks(&AnymalMpc::<f64>::default(), &doc).check("anymal", |_| FD_TOLERANCE, 1);
}

#[test]
fn panda_link_motion_matches_finite_differences() {
    let doc = robot_file("panda.mpc.json");
    frame_checks(&PandaMpc::<f64>::default(), &doc).check("panda", |_| FD_TOLERANCE, 1);
}

#[test]
fn anymal_link_motion_matches_finite_differences() {
    let doc = robot_file("floating/anymal.mpc.json");
    frame_checks(&AnymalMpc::<f64>::default(), &doc).check("anymal", |_| FD_TOLERANCE, 1);
}

/// The centroidal momentum `h = A_g v` along the motion changes at `centroidal_momentum_rate`.
#[test]
fn anymal_centroidal_momentum_rate_matches_finite_differences() {
    let doc = robot_file("floating/anymal.mpc.json");
    let r = AnymalMpc::<f64>::default();
    let mut worst = Worst::default();
    for (q, v, a, _) in states::<AnymalMpc<f64>, 19, 18>(&doc) {
        let fd = central(|h| {
            let qh = r.integrate(&q, &v.map(|x| x * h), 1.0);
            let ag = r.centroidal_map(&qh);
            (0..6)
                .map(|k| (0..18).map(|c| ag[k][c] * (v[c] + a[c] * h)).sum())
                .collect()
        });
        let rate = r.centroidal_momentum_rate(&q, &v, &a);
        worst.note("centroidal_momentum_rate", elementwise(&fd, &rate));
    }
    worst.check("anymal", |_| FD_TOLERANCE, 1);
}

/// `f32` instances compile and agree with `f64` (single precision).
#[test]
fn f32_instances_agree() {
    let (r32, r64) = (AnymalMpc::<f32>::default(), AnymalMpc::<f64>::default());
    let doc = robot_file("floating/anymal.mpc.json");
    let (q, v, a, q1) = states::<AnymalMpc<f64>, 19, 18>(&doc)[1];
    let (q32, v32, a32, q132) = (
        q.map(|x| x as f32),
        v.map(|x| x as f32),
        a.map(|x| x as f32),
        q1.map(|x| x as f32),
    );
    let link = AnymalMpcLink::ALL[AnymalMpcLink::ALL.len() - 1];
    let pairs: [(Vec<f32>, Vec<f64>); 5] = [
        (
            r32.link_acceleration(link, &q32, &v32, &a32).to_vec(),
            r64.link_acceleration(link, &q, &v, &a).to_vec(),
        ),
        (
            flat32(&r32.link_jacobian_time_variation(link, &q32, &v32)),
            flat(&r64.link_jacobian_time_variation(link, &q, &v)),
        ),
        (
            r32.difference(&q32, &q132).to_vec(),
            r64.difference(&q, &q1).to_vec(),
        ),
        (
            flat32(&r32.difference_jacobians(&q32, &q132).0),
            flat(&r64.difference_jacobians(&q, &q1).0),
        ),
        (
            r32.centroidal_momentum_rate(&q32, &v32, &a32).to_vec(),
            r64.centroidal_momentum_rate(&q, &v, &a).to_vec(),
        ),
    ];
    for (single, double) in pairs {
        let single: Vec<f64> = single.iter().map(|&x| f64::from(x)).collect();
        let scale = double.iter().fold(1.0_f64, |m, x| m.max(x.abs()));
        let e = elementwise(&single, &double) / scale;
        assert!(e < 1e-4, "f32 against f64: {e:e}");
    }
}

fn flat32<const R: usize, const C: usize>(m: &[[f32; C]; R]) -> Vec<f32> {
    m.iter().flatten().copied().collect()
}

#[test]
fn joint_limits_are_the_urdf_s() {
    // panda.urdf: panda_joint1 <limit effort="87" lower="-2.8973" upper="2.8973" velocity="2.1750"/>
    let i = PandaMpc::<f64>::JOINT_NAMES
        .iter()
        .position(|n| *n == "panda_joint1")
        .unwrap();
    assert_eq!(PandaMpc::<f64>::POSITION_LIMITS[i], (-2.8973, 2.8973));
    assert_eq!(PandaMpc::<f64>::VELOCITY_LIMITS[i], 2.175);
    assert_eq!(PandaMpc::<f64>::EFFORT_LIMITS[i], 87.0);
    // anymal.urdf: every joint <limit effort="80" lower="-9.42" upper="9.42" velocity="15"/>;
    // the floating base's six coordinates have none and are not listed.
    assert_eq!(AnymalMpc::<f64>::POSITION_LIMITS, [(-9.42, 9.42); 12]);
    assert_eq!(AnymalMpc::<f64>::VELOCITY_LIMITS, [15.0; 12]);
    assert_eq!(AnymalMpc::<f64>::EFFORT_LIMITS, [80.0; 12]);
}
