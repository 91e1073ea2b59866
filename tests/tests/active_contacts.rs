//! Contacts switched at run time and Baumgarte stabilization (issue 29): anymal's `_active`
//! methods against the same robot generated with the active feet alone, no contact against
//! forward dynamics, every contact against the plain methods (to the bit, but contact forward
//! dynamics and impulse dynamics, whose plain methods may be straight-line programs); the stabilized
//! constraint `J a + drift = -kd J v - kp e` on anymal's points and g1's 6D soles; and the
//! runtime's contact solver called from user code with the generated `PARENTS`.

#![allow(clippy::needless_range_loop)]

use eomgen_runtime::contact::{placement, solve};
use eomgen_runtime::prelude::*;
use eomgen_tests::floating_reference::{flat, normwise, random_state};
use eomgen_tests::robots::anymal_mpc::AnymalMpc;
use eomgen_tests::robots::anymal_two_feet::AnymalTwoFeet;
#[cfg(heavy)]
use eomgen_tests::robots::g1_mpc::G1Mpc;

const NQ: usize = 19;
const NV: usize = 18;

/// Rows 0..3 and 9..12 of anymal's twelve (its first and last feet).
const KEPT: [usize; 6] = [0, 1, 2, 9, 10, 11];
const TWO: [bool; 4] = [true, false, false, true];

/// The rows `KEPT` of `m`, and whether the others are all exactly zero.
fn kept(m: &[[f64; NV]; 12]) -> (Vec<f64>, bool) {
    let zero = (0..12)
        .filter(|r| !KEPT.contains(r))
        .all(|r| m[r].iter().all(|x| *x == 0.0));
    (KEPT.iter().flat_map(|&r| m[r]).collect(), zero)
}

/// The same for a vector of forces.
fn kept_vec(f: &[f64; 12]) -> (Vec<f64>, bool) {
    let zero = (0..12).filter(|r| !KEPT.contains(r)).all(|r| f[r] == 0.0);
    (KEPT.iter().map(|&r| f[r]).collect(), zero)
}

#[test]
fn anymal_active_contacts_equal_the_robot_generated_with_them_alone() {
    let (r, two) = (AnymalMpc::<f64>::default(), AnymalTwoFeet::<f64>::default());
    let mut worst: f64 = 0.0;
    let mut note = |what: &str, ours: &[f64], alone: &[f64]| {
        let e = normwise(ours, alone);
        assert!(e < 1e-12, "{what} off by {e:e}");
        worst = worst.max(e);
    };
    for seed in 1..6 {
        let (q, v, tau) = random_state::<NQ, NV>(seed);
        let (a, f) = r.contact_forward_dynamics_active(&q, &v, &tau, &TWO);
        let (a2, f2) = two.contact_forward_dynamics(&q, &v, &tau);
        note("a", &a, &a2);
        let (f, zero) = kept_vec(&f);
        assert!(zero, "seed {seed}: forces of inactive feet");
        note("forces", &f, &f2);
        let d = r.contact_forward_dynamics_derivatives_active(&q, &v, &tau, &TWO);
        let d2 = two.contact_forward_dynamics_derivatives(&q, &v, &tau);
        note("da/dq", &flat(&d.da_dq), &flat(&d2.da_dq));
        note("da/dv", &flat(&d.da_dv), &flat(&d2.da_dv));
        note("da/dtau", &flat(&d.da_dtau), &flat(&d2.da_dtau));
        for (what, ours, alone) in [
            ("df/dq", &d.df_dq, &d2.df_dq),
            ("df/dv", &d.df_dv, &d2.df_dv),
            ("df/dtau", &d.df_dtau, &d2.df_dtau),
        ] {
            let (rows, zero) = kept(ours);
            assert!(zero, "seed {seed}: {what} of inactive feet");
            note(what, &rows, &flat(alone));
        }
        for e in [0.0, 0.6] {
            let (after, p) = r.impulse_dynamics_active(&q, &v, e, &TWO);
            let (after2, p2) = two.impulse_dynamics(&q, &v, e);
            note("v_after", &after, &after2);
            let (p, zero) = kept_vec(&p);
            assert!(zero, "seed {seed}: impulses of inactive feet");
            note("impulses", &p, &p2);
            let d = r.impulse_dynamics_derivatives_active(&q, &v, e, &TWO);
            let d2 = two.impulse_dynamics_derivatives(&q, &v, e);
            note("dv/dq", &flat(&d.dv_dq), &flat(&d2.dv_dq));
            note("dv/dv", &flat(&d.dv_dv), &flat(&d2.dv_dv));
            for (what, ours, alone) in [
                ("dimpulse/dq", &d.dimpulse_dq, &d2.dimpulse_dq),
                ("dimpulse/dv", &d.dimpulse_dv, &d2.dimpulse_dv),
            ] {
                let (rows, zero) = kept(ours);
                assert!(zero, "seed {seed}: {what} of inactive feet");
                note(what, &rows, &flat(alone));
            }
        }
    }
    println!("worst normwise difference from the two-feet robot: {worst:e}");
}

#[test]
fn anymal_without_active_contacts_is_forward_dynamics() {
    let r = AnymalMpc::<f64>::default();
    let none = [false; 4];
    for seed in 6..10 {
        let (q, v, tau) = random_state::<NQ, NV>(seed);
        let (a, f) = r.contact_forward_dynamics_active(&q, &v, &tau, &none);
        let e = normwise(&a, &r.forward_dynamics(&q, &v, &tau));
        assert!(e < 1e-12, "seed {seed}: accelerations off by {e:e}");
        assert_eq!(f, [0.0; 12]);
        let (after, p) = r.impulse_dynamics_active(&q, &v, 0.3, &none);
        assert_eq!((after, p), (v, [0.0; 12]));
    }
}

/// Every contact active: the plain methods. Contact forward dynamics and impulse dynamics are
/// solved at run time with a set of contacts and as straight-line programs without (anymal's
/// are), so those agree to rounding; the derivatives are the same operations, to the bit.
#[test]
fn anymal_every_contact_active_is_the_plain_methods_to_the_bit() {
    let r = AnymalMpc::<f64>::default();
    let all = [true; 4];
    for seed in 10..13 {
        let (q, v, tau) = random_state::<NQ, NV>(seed);
        let (a, f) = r.contact_forward_dynamics(&q, &v, &tau);
        let active = r.contact_forward_dynamics_active(&q, &v, &tau, &all);
        let (ea, ef) = (normwise(&active.0, &a), normwise(&active.1, &f));
        assert!(ea < 1e-12 && ef < 1e-12, "seed {seed}: {ea:e}, {ef:e}");
        assert_eq!(
            r.contact_forward_dynamics_derivatives_active(&q, &v, &tau, &all),
            r.contact_forward_dynamics_derivatives(&q, &v, &tau)
        );
        let (after, p) = r.impulse_dynamics(&q, &v, 0.4);
        let impulse = r.impulse_dynamics_active(&q, &v, 0.4, &all);
        let (ea, ep) = (normwise(&impulse.0, &after), normwise(&impulse.1, &p));
        assert!(ea < 1e-12 && ep < 1e-12, "seed {seed}: {ea:e}, {ep:e}");
        assert_eq!(
            r.impulse_dynamics_derivatives_active(&q, &v, 0.4, &all),
            r.impulse_dynamics_derivatives(&q, &v, 0.4)
        );
        // Baumgarte with zero gains, whatever the references.
        let off = Baumgarte::new(0.0, 0.0, [Pose::from_translation([1.0, 2.0, 3.0]); 4]);
        assert_eq!(
            r.contact_forward_dynamics_stabilized(&q, &v, &tau, &all, &off),
            active
        );
    }
}

/// `J a + drift` (K rows).
fn constrained<const N: usize, const K: usize>(
    j: &[[f64; N]; K],
    drift: &[f64; K],
    a: &[f64; N],
) -> [f64; K] {
    core::array::from_fn(|k| drift[k] + (0..N).map(|c| j[k][c] * a[c]).sum::<f64>())
}

/// Baumgarte on anymal's feet: at rest with the references 1 cm off, each held foot
/// accelerates at `-kp` times its error; moving, `J a + drift = -kd J v - kp e`.
#[test]
fn anymal_baumgarte_pulls_displaced_feet_back() {
    let r = AnymalMpc::<f64>::default();
    let (kp, kd) = (400.0, 40.0);
    let active = [true, true, false, true];
    for seed in 13..16 {
        let (q, v, tau) = random_state::<NQ, NV>(seed);
        let placements = r.contact_placements(&q);
        let mut reference = placements.map(|p| placement(&p));
        let shift = [0.01, -0.005, 0.008];
        for (c, pose) in reference.iter_mut().enumerate() {
            pose.translation[c % 3] += shift[c % 3];
        }
        let b = Baumgarte::new(kp, kd, reference);
        let j = r.contact_jacobian(&q);
        for v in [[0.0; NV], v] {
            let (a, f) = r.contact_forward_dynamics_stabilized(&q, &v, &tau, &active, &b);
            let acc = constrained(&j, &r.contact_drift(&q, &v), &a);
            for c in 0..4 {
                for i in 0..3 {
                    let k = 3 * c + i;
                    if !active[c] {
                        assert_eq!(f[k], 0.0);
                        continue;
                    }
                    let jv: f64 = (0..NV).map(|x| j[k][x] * v[x]).sum();
                    let error = placements[c][i] - reference[c].translation[i];
                    let want = -kd * jv - kp * error;
                    assert!(
                        (acc[k] - want).abs() < 1e-9 * want.abs().max(1.0),
                        "seed {seed}, row {k}: {} vs {want}",
                        acc[k]
                    );
                }
            }
        }
    }
}

/// Baumgarte on g1's 6D soles, at rest: the left sole 1 cm and 0.05 rad (about z) off its
/// reference accelerates at `-kp` times that error (linear and angular, world axes); the right
/// sole, inactive, gets no wrench.
#[test]
#[cfg(heavy)] // EOMGEN_TEST_HEAVY=1: g1 is the largest module of the tests
fn g1_baumgarte_turns_a_sole_back() {
    let r = G1Mpc::<f64>::default();
    let (q, _, tau) = random_state::<36, 35>(21);
    let v = [0.0; 35];
    let placements = r.contact_placements(&q);
    let now = placement(&placements[0]);
    let (s, c) = 0.05_f64.sin_cos();
    let rz = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]];
    // R_ref = Rz^T R: then log3(R R_ref^T) = log3(Rz) = (0, 0, 0.05).
    let rotation = core::array::from_fn(|i| {
        core::array::from_fn(|k| (0..3).map(|m| rz[m][i] * now.rotation[m][k]).sum())
    });
    let mut translation = now.translation;
    translation[2] -= 0.01;
    let reference = [
        Pose {
            translation,
            rotation,
        },
        placement(&placements[1]),
    ];
    let kp = 100.0;
    let b = Baumgarte::new(kp, 10.0, reference);
    let (a, f) = r.contact_forward_dynamics_stabilized(&q, &v, &tau, &[true, false], &b);
    let acc = constrained(&r.contact_jacobian(&q), &r.contact_drift(&q, &v), &a);
    let want = [0.0, 0.0, -kp * 0.01, 0.0, 0.0, -kp * 0.05];
    for k in 0..6 {
        assert!(
            (acc[k] - want[k]).abs() < 1e-9,
            "row {k}: {} vs {}",
            acc[k],
            want[k]
        );
        assert_eq!(f[6 + k], 0.0);
    }
}

/// What a user does with the runtime alone: `eomgen_runtime::contact::solve` on the generated
/// mass matrix (and its public `PARENTS`), `tau - h`, contact Jacobian and drift, equals the
/// generated `contact_forward_dynamics`.
#[test]
fn a_user_solves_anymal_contact_dynamics_with_the_runtime() {
    let r = AnymalMpc::<f64>::default();
    for seed in 16..20 {
        let (q, v, tau) = random_state::<NQ, NV>(seed);
        let mut m = r.mass_matrix(&q);
        let h = r.inverse_dynamics(&q, &v, &[0.0; NV]);
        let rhs: [f64; NV] = core::array::from_fn(|i| tau[i] - h[i]);
        let (j, drift) = (r.contact_jacobian(&q), r.contact_drift(&q, &v));
        let (a, f) = solve(&mut m, &AnymalMpc::<f64>::PARENTS, &rhs, &j, &drift).unwrap();
        let (a0, f0) = r.contact_forward_dynamics(&q, &v, &tau);
        assert!(normwise(&a, &a0) < 1e-12 && normwise(&f, &f0) < 1e-12);
        // The runtime's own row mask from the generated rows of each contact.
        let rows: [bool; 12] =
            eomgen_runtime::contact::row_mask(&AnymalMpc::<f64>::CONTACT_ROWS, &TWO);
        assert_eq!(rows.iter().filter(|x| **x).count(), 6);
    }
}

/// The same methods on `f32`.
#[test]
fn anymal_active_contacts_run_on_f32() {
    let r = AnymalMpc::<f32>::default();
    let (q, v, tau) = random_state::<NQ, NV>(30);
    let (q, v, tau) = (
        q.map(|x| x as f32),
        v.map(|x| x as f32),
        tau.map(|x| x as f32),
    );
    let (a, f) = r.contact_forward_dynamics_active(&q, &v, &tau, &TWO);
    let (a64, _) = AnymalMpc::<f64>::default().contact_forward_dynamics_active(
        &q.map(f64::from),
        &v.map(f64::from),
        &tau.map(f64::from),
        &TWO,
    );
    let a: Vec<f64> = a.iter().map(|x| f64::from(*x)).collect();
    assert!(normwise(&a, &a64) < 1e-3 && f[3] == 0.0);
}

/// A non-finite state: the `try_` variants say so.
#[test]
fn anymal_active_non_finite_state_is_reported() {
    let r = AnymalMpc::<f64>::default();
    let (mut q, v, tau) = random_state::<NQ, NV>(31);
    q[9] = f64::NAN;
    assert!(r
        .try_contact_forward_dynamics_active(&q, &v, &tau, &TWO)
        .is_err());
    assert!(r
        .try_contact_forward_dynamics_derivatives_active(&q, &v, &tau, &TWO)
        .is_err());
    assert!(r.try_impulse_dynamics_active(&q, &v, 0.0, &TWO).is_err());
    assert!(r
        .try_impulse_dynamics_derivatives_active(&q, &v, 0.0, &TWO)
        .is_err());
    let b = Baumgarte::new(1.0, 1.0, [Pose::identity(); 4]);
    assert!(r
        .try_contact_forward_dynamics_stabilized(&q, &v, &tau, &TWO, &b)
        .is_err());
}
