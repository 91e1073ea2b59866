//! Contact and impulse dynamics and their derivatives (issue 29) through compiled generated
//! code: against Pinocchio's reference values (`robots/floating/NAME.mpc.json`:
//! `constraintDynamics`, `computeConstraintDynamicsDerivatives`, `impulseDynamics`,
//! `computeImpulseDynamicsDerivatives`), and against independent checks: central finite
//! differences through `integrate`, the centroidal momentum an impulse changes, and the
//! contact constraint after an impulse.

#![allow(clippy::needless_range_loop)]

use eomgen_runtime::prelude::*;
use eomgen_tests::floating_reference::{
    flat, normwise, numbers, pick, random_state, reference, Order, Worst,
};
use eomgen_tests::robots::anymal_at::{AnymalAt, AnymalAtLink};
use eomgen_tests::robots::anymal_mpc::{AnymalMpc, AnymalMpcLink};
#[cfg(heavy)]
use eomgen_tests::robots::g1_mpc::G1Mpc;
use serde_json::Value;

const NQ: usize = 19;
const NV: usize = 18;

/// Derivatives 1e-7 normwise, the dynamics themselves 1e-8, the contact Jacobian and drift
/// (kinematics) 1e-9.
fn tolerance(what: &str) -> f64 {
    if what.contains('/') {
        1e-7
    } else if what.starts_with("contact_") {
        1e-9
    } else {
        1e-8
    }
}

/// Every contact and impulse quantity of `$ty` at every sample of `$file`, against the
/// reference (the contact Jacobian and drift too).
macro_rules! check_mpc {
    ($file:literal, $ty:ty, $nq:literal, $nv:literal, $k:literal) => {{
        let doc = reference($file);
        let r = <$ty>::default();
        let o = Order::new(&doc, &<$ty>::JOINT_NAMES);
        let rows: Vec<usize> = (0..$k).collect();
        let mut worst = Worst::default();
        for s in doc["samples"].as_array().unwrap() {
            let q: [f64; $nq] = Order::arr(&o.q, &s["q"]);
            let v: [f64; $nv] = Order::arr(&o.v, &s["v"]);
            let tau: [f64; $nv] = Order::arr(&o.v, &s["tau"]);
            let rv = |x: &Value| o.v.iter().map(|&i| numbers(x)[i]).collect::<Vec<_>>();
            let jc = pick(&s["contact_jacobian"], &rows, &o.v);
            worst.note(
                "contact_jacobian",
                normwise(&flat(&r.contact_jacobian(&q)), &jc),
            );
            let drift = numbers(&s["contact_drift"]);
            worst.note("contact_drift", normwise(&r.contact_drift(&q, &v), &drift));
            let cfd = &s["contact_forward_dynamics"];
            let (a, f) = r.contact_forward_dynamics(&q, &v, &tau);
            worst.note("a", normwise(&a, &rv(&cfd["a"])));
            worst.note("forces", normwise(&f, &numbers(&cfd["forces"])));
            let d = r.contact_forward_dynamics_derivatives(&q, &v, &tau);
            let rd = &s["contact_forward_dynamics_derivatives"];
            for (name, ours) in [
                ("da/dq", &d.da_dq),
                ("da/dv", &d.da_dv),
                ("da/dtau", &d.da_dtau),
            ] {
                let key = name.replace('/', "_");
                worst.note(name, normwise(&flat(ours), &pick(&rd[&key], &o.v, &o.v)));
            }
            for (name, ours) in [
                ("df/dq", &d.df_dq),
                ("df/dv", &d.df_dv),
                ("df/dtau", &d.df_dtau),
            ] {
                let key = name.replace('/', "_");
                worst.note(name, normwise(&flat(ours), &pick(&rd[&key], &rows, &o.v)));
            }
            let impulses = s["impulse_dynamics"].as_array().unwrap();
            let derivatives = s["impulse_dynamics_derivatives"].as_array().unwrap();
            for (i, di) in impulses.iter().zip(derivatives) {
                let e = i["restitution"].as_f64().unwrap();
                let (after, p) = r.impulse_dynamics(&q, &v, e);
                worst.note("v_after", normwise(&after, &rv(&i["v_after"])));
                worst.note("impulses", normwise(&p, &numbers(&i["impulses"])));
                let d = r.impulse_dynamics_derivatives(&q, &v, e);
                worst.note(
                    "dv/dq",
                    normwise(&flat(&d.dv_dq), &pick(&di["dv_dq"], &o.v, &o.v)),
                );
                worst.note(
                    "dv/dv",
                    normwise(&flat(&d.dv_dv), &pick(&di["dv_dv"], &o.v, &o.v)),
                );
                let dp_dq = pick(&di["dimpulse_dq"], &rows, &o.v);
                worst.note("dimpulse/dq", normwise(&flat(&d.dimpulse_dq), &dp_dq));
                let dp_dv = pick(&di["dimpulse_dv"], &rows, &o.v);
                worst.note("dimpulse/dv", normwise(&flat(&d.dimpulse_dv), &dp_dv));
            }
        }
        worst.check($file, tolerance, 16);
    }};
}

#[test]
fn anymal_contact_and_impulse_dynamics_match_pinocchio() {
    check_mpc!("anymal.mpc.json", AnymalMpc<f64>, 19, 18, 12);
}

/// 6D contacts at both soles.
#[test]
#[cfg(heavy)] // EOMGEN_TEST_HEAVY=1: g1 is the largest module of the tests
fn g1_contact_and_impulse_dynamics_match_pinocchio() {
    check_mpc!("g1_29dof.mpc.json", G1Mpc<f64>, 36, 35, 12);
}

/// A repeatable state (`random_state`).
fn state(seed: u64) -> ([f64; NQ], [f64; NV], [f64; NV]) {
    random_state(seed)
}

/// Central differences of `f` (R outputs) in each tangent direction of `q`, in `v` and in
/// `tau`, as three R x NV matrices (flat, row-major).
fn central<const R: usize>(
    r: &AnymalMpc<f64>,
    (q, v, tau): ([f64; NQ], [f64; NV], [f64; NV]),
    f: impl Fn(&[f64; NQ], &[f64; NV], &[f64; NV]) -> [f64; R],
) -> [Vec<f64>; 3] {
    let h = 1e-6;
    let mut out = [vec![0.0; R * NV], vec![0.0; R * NV], vec![0.0; R * NV]];
    for j in 0..NV {
        let mut e = [0.0; NV];
        e[j] = h;
        let minus = e.map(|x| -x);
        let plus_minus = [
            (r.integrate(&q, &e, 1.0), v, tau),
            (r.integrate(&q, &minus, 1.0), v, tau),
            (q, core::array::from_fn(|i| v[i] + e[i]), tau),
            (q, core::array::from_fn(|i| v[i] - e[i]), tau),
            (q, v, core::array::from_fn(|i| tau[i] + e[i])),
            (q, v, core::array::from_fn(|i| tau[i] - e[i])),
        ];
        for (x, pair) in plus_minus.chunks(2).enumerate() {
            let (a, b) = (
                f(&pair[0].0, &pair[0].1, &pair[0].2),
                f(&pair[1].0, &pair[1].1, &pair[1].2),
            );
            for i in 0..R {
                out[x][i * NV + j] = (a[i] - b[i]) / (2.0 * h);
            }
        }
    }
    out
}

#[test]
fn anymal_contact_dynamics_derivatives_equal_central_differences() {
    let r = AnymalMpc::<f64>::default();
    for seed in 1..4 {
        let x = state(seed);
        let (q, v, tau) = x;
        let d = r.contact_forward_dynamics_derivatives(&q, &v, &tau);
        let [da_dq, da_dv, da_dtau] =
            central(&r, x, |q, v, t| r.contact_forward_dynamics(q, v, t).0);
        let [df_dq, df_dv, df_dtau] =
            central(&r, x, |q, v, t| r.contact_forward_dynamics(q, v, t).1);
        for (what, ours, fd) in [
            ("da/dq", flat(&d.da_dq), da_dq),
            ("da/dv", flat(&d.da_dv), da_dv),
            ("da/dtau", flat(&d.da_dtau), da_dtau),
            ("df/dq", flat(&d.df_dq), df_dq),
            ("df/dv", flat(&d.df_dv), df_dv),
            ("df/dtau", flat(&d.df_dtau), df_dtau),
        ] {
            let e = normwise(&ours, &fd);
            assert!(e < 1e-6, "seed {seed}: {what} off by {e:e}");
        }
    }
}

#[test]
fn anymal_impulse_dynamics_derivatives_equal_central_differences() {
    let r = AnymalMpc::<f64>::default();
    for seed in 4..7 {
        let x = state(seed);
        let (q, v, _) = x;
        for e in [0.0, 0.7] {
            let d = r.impulse_dynamics_derivatives(&q, &v, e);
            let [dv_dq, dv_dv, _] = central(&r, x, |q, v, _| r.impulse_dynamics(q, v, e).0);
            let [dp_dq, dp_dv, _] = central(&r, x, |q, v, _| r.impulse_dynamics(q, v, e).1);
            for (what, ours, fd) in [
                ("dv/dq", flat(&d.dv_dq), dv_dq),
                ("dv/dv", flat(&d.dv_dv), dv_dv),
                ("dimpulse/dq", flat(&d.dimpulse_dq), dp_dq),
                ("dimpulse/dv", flat(&d.dimpulse_dv), dp_dv),
            ] {
                let err = normwise(&ours, &fd);
                assert!(err < 1e-6, "seed {seed}, e {e}: {what} off by {err:e}");
            }
        }
    }
}

/// An impulse changes the centroidal momentum by the impulses (linear: their sum; angular about
/// the centre of mass: their moments), and leaves the contacts moving at `-e` times their
/// velocity before.
#[test]
fn anymal_impulses_change_momentum_and_hold_the_contacts() {
    let r = AnymalMpc::<f64>::default();
    let feet = ["LF_FOOT", "RF_FOOT", "LH_FOOT", "RH_FOOT"];
    for seed in 7..12 {
        let (q, v, _) = state(seed);
        let (ag, com, j) = (
            r.centroidal_map(&q),
            r.center_of_mass(&q),
            r.contact_jacobian(&q),
        );
        for e in [0.0, 0.5, 1.0] {
            let (after, p) = r.impulse_dynamics(&q, &v, e);
            let mut change = [0.0; 6];
            for (x, row) in change.iter_mut().zip(&ag) {
                *x = (0..NV).map(|c| row[c] * (after[c] - v[c])).sum();
            }
            let mut want = [0.0; 6];
            for (c, foot) in feet.iter().enumerate() {
                let link = *AnymalMpcLink::ALL
                    .iter()
                    .find(|l| l.name() == *foot)
                    .unwrap();
                let at = r.link_pose(link, &q).translation;
                let lever = [at[0] - com[0], at[1] - com[1], at[2] - com[2]];
                let pc = [p[3 * c], p[3 * c + 1], p[3 * c + 2]];
                let moment = [
                    lever[1] * pc[2] - lever[2] * pc[1],
                    lever[2] * pc[0] - lever[0] * pc[2],
                    lever[0] * pc[1] - lever[1] * pc[0],
                ];
                for k in 0..3 {
                    want[k] += pc[k];
                    want[3 + k] += moment[k];
                }
            }
            let err = normwise(&change, &want);
            assert!(err < 1e-10, "seed {seed}, e {e}: momentum off by {err:e}");
            for (k, row) in j.iter().enumerate() {
                let before: f64 = (0..NV).map(|c| row[c] * v[c]).sum();
                let now: f64 = (0..NV).map(|c| row[c] * after[c]).sum();
                let err = (now + e * before).abs() / before.abs().max(1.0);
                assert!(
                    err < 1e-10,
                    "seed {seed}, e {e}: contact row {k} moves: {now} vs {before}"
                );
            }
        }
    }
}

/// A non-finite configuration: the `try_` variants report it and the plain ones give NaN.
#[test]
fn anymal_non_finite_state_is_reported() {
    let r = AnymalMpc::<f64>::default();
    let (mut q, v, tau) = state(3);
    q[8] = f64::NAN;
    assert!(r
        .try_contact_forward_dynamics_derivatives(&q, &v, &tau)
        .is_err());
    assert!(r.try_impulse_dynamics(&q, &v, 0.0).is_err());
    assert!(r.try_impulse_dynamics_derivatives(&q, &v, 0.0).is_err());
    assert!(r.contact_forward_dynamics_derivatives(&q, &v, &tau).da_dq[0][0].is_nan());
    assert!(r.impulse_dynamics(&q, &v, 0.0).1[0].is_nan());
    assert!(r.impulse_dynamics_derivatives(&q, &v, 0.0).dimpulse_dv[0][0].is_nan());
    assert!(r.try_contact_forward_dynamics(&q, &v, &tau).is_err());
    assert!(r.contact_forward_dynamics(&q, &v, &tau).1[0].is_nan());
}

/// A non-finite effort leaves `M` and `J M^-1 J^T` whole: the straight-line contact forward
/// dynamics and the run-time route (the `_active` variant, every contact on) report the same
/// first non-finite acceleration.
#[test]
fn anymal_non_finite_effort_is_reported_as_the_run_time_route_does() {
    let r = AnymalMpc::<f64>::default();
    let (q, v, mut tau) = state(4);
    for (i, bad) in [(17, f64::NAN), (9, f64::INFINITY)] {
        tau[i] = bad;
        let flat = r.try_contact_forward_dynamics(&q, &v, &tau).unwrap_err();
        let solved = r
            .try_contact_forward_dynamics_active(&q, &v, &tau, &[true; 4])
            .unwrap_err();
        assert_eq!(flat, solved);
        assert!(matches!(
            flat,
            eomgen_runtime::FactorError::NonFinite { .. }
        ));
    }
}

/// A non-finite velocity leaves `M` and `J M^-1 J^T` whole: the straight-line impulse dynamics
/// and the run-time route (`_active`, every contact on) report the same first non-finite
/// result, and agree on finite ones at every restitution.
#[test]
fn anymal_impulse_dynamics_agrees_with_the_run_time_route() {
    let r = AnymalMpc::<f64>::default();
    let (q, mut v, _) = state(5);
    for e in [0.0, 0.3, 1.0] {
        let (after, p) = r.impulse_dynamics(&q, &v, e);
        let (after_a, p_a) = r.impulse_dynamics_active(&q, &v, e, &[true; 4]);
        assert!(normwise(&after, &after_a) < 1e-12 && normwise(&p, &p_a) < 1e-12);
    }
    v[12] = f64::NAN;
    let flat = r.try_impulse_dynamics(&q, &v, 0.5).unwrap_err();
    let solved = r
        .try_impulse_dynamics_active(&q, &v, 0.5, &[true; 4])
        .unwrap_err();
    assert_eq!(flat, solved);
}

/// Contact points at a position in a link frame (`Builder::contact_point_at`): at the origin
/// they are the link's point contact; elsewhere the point moves with the link (`v_p = v_o +
/// omega x r`), and the drift is the time derivative of `J v` along the motion.
#[test]
fn anymal_contact_points_at_positions_in_link_frames() {
    let (r, at) = (AnymalMpc::<f64>::default(), AnymalAt::<f64>::default());
    let rh = *AnymalAtLink::ALL
        .iter()
        .find(|l| l.name() == "RH_FOOT")
        .unwrap();
    let offset = [0.05, -0.02, 0.01];
    for seed in 12..16 {
        let (q, v, tau) = state(seed);
        let (j, ja) = (r.contact_jacobian(&q), at.contact_jacobian(&q));
        let (drift, drift_at) = (r.contact_drift(&q, &v), at.contact_drift(&q, &v));
        // The first three feet: at their origins.
        assert!(normwise(&flat(&ja)[..9 * NV], &flat(&j)[..9 * NV]) < 1e-14);
        assert!(normwise(&drift_at[..9], &drift[..9]) < 1e-14);
        // The fourth: its velocity is the link origin's plus omega x (R offset).
        let (link_j, pose) = (at.link_jacobian(rh, &q), at.link_pose(rh, &q));
        let rp: Vec<f64> = (0..3)
            .map(|i| (0..3).map(|k| pose.rotation[i][k] * offset[k]).sum())
            .collect();
        for c in 0..NV {
            let w = [link_j[3][c], link_j[4][c], link_j[5][c]];
            let wr = [
                w[1] * rp[2] - w[2] * rp[1],
                w[2] * rp[0] - w[0] * rp[2],
                w[0] * rp[1] - w[1] * rp[0],
            ];
            for i in 0..3 {
                let want = link_j[i][c] + wr[i];
                assert!(
                    (ja[9 + i][c] - want).abs() < 1e-13,
                    "seed {seed}: J[{}][{c}]",
                    9 + i
                );
            }
        }
        // Jdot v by central differences of J v along q moving at v.
        let h = 1e-6;
        let jv = |q: &[f64; NQ]| -> Vec<f64> {
            at.contact_jacobian(q)
                .iter()
                .map(|row| (0..NV).map(|c| row[c] * v[c]).sum())
                .collect()
        };
        let (plus, minus) = (jv(&at.integrate(&q, &v, h)), jv(&at.integrate(&q, &v, -h)));
        let fd: Vec<f64> = plus
            .iter()
            .zip(&minus)
            .map(|(p, m)| (p - m) / (2.0 * h))
            .collect();
        let e = normwise(&drift_at, &fd);
        assert!(e < 1e-6, "seed {seed}: drift off by {e:e}");
        // The contact forces hold the offset point.
        let (a, _) = at.contact_forward_dynamics(&q, &v, &tau);
        for k in 9..12 {
            let acc: f64 = (0..NV).map(|c| ja[k][c] * a[c]).sum::<f64>() + drift_at[k];
            assert!(
                acc.abs() < 1e-9,
                "seed {seed}: row {k} accelerates at {acc}"
            );
        }
    }
}
