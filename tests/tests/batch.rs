//! The `_batch` methods and the generated code on SIMD lanes (`eomgen_runtime::Lane`, the
//! `simd` feature) against the scalar code, state by state: in `f64` bit for bit (a lane runs
//! the scalar code's operations, the joint angles' sines and cosines included, which both take
//! from `trig::sin_cos_f64_in`); in `f32` within 1e-5 relative to the result's size (`wide`'s
//! single-precision sine and cosine differ from `libm`'s in the last bits), bit for bit at zero
//! angles; with non-finite states next to finite ones, on fixed and floating bases.

use eomgen_generated::panda::Panda;
use eomgen_runtime::batch::{gather, scatter, scatter_matrix};
use eomgen_runtime::lane::Pack;
use eomgen_runtime::prelude::*;
use eomgen_runtime::{FactorError, LaneError};
use eomgen_tests::robots::{anymal_derivatives, joint_effects_full, panda_derivatives};
use wide::{f32x8, f64x4};

/// Deterministic numbers in [-1, 1).
struct Numbers(u64);

impl Numbers {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
    fn states<const N: usize>(&mut self, count: usize, scale: f64) -> Vec<[f64; N]> {
        (0..count)
            .map(|_| core::array::from_fn(|_| scale * self.next()))
            .collect()
    }
}

/// Anything with `f64` entries, flattened.
trait Flat {
    fn flat(&self) -> Vec<f64>;
}
impl Flat for f64 {
    fn flat(&self) -> Vec<f64> {
        vec![*self]
    }
}
impl Flat for Vec<f64> {
    fn flat(&self) -> Vec<f64> {
        self.clone()
    }
}
impl<const N: usize> Flat for [f64; N] {
    fn flat(&self) -> Vec<f64> {
        self.to_vec()
    }
}
impl<const R: usize, const C: usize> Flat for [[f64; C]; R] {
    fn flat(&self) -> Vec<f64> {
        self.iter().flatten().copied().collect()
    }
}
impl<const N: usize> Flat for [f32; N] {
    fn flat(&self) -> Vec<f64> {
        self.iter().map(|x| f64::from(*x)).collect()
    }
}
impl<const R: usize, const C: usize> Flat for [[f32; C]; R] {
    fn flat(&self) -> Vec<f64> {
        self.iter().flatten().map(|x| f64::from(*x)).collect()
    }
}

/// `got` equals `want` entry by entry: the same NaNs and infinities, and finite entries bit for
/// bit (`tol` 0) or within `tol` times the largest finite entry of `want` (at least 1).
fn assert_close<X: Flat>(what: &str, state: usize, got: &X, want: &X, tol: f64) {
    let (g, w) = (got.flat(), want.flat());
    let scale = w
        .iter()
        .filter(|x| x.is_finite())
        .fold(1.0_f64, |m, x| m.max(x.abs()));
    for (k, (a, b)) in g.iter().zip(&w).enumerate() {
        let same = if tol == 0.0 || !b.is_finite() {
            a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
        } else {
            (a - b).abs() <= tol * scale
        };
        assert!(
            same,
            "{what}, state {state}, entry {k}: batch {a}, scalar {b}"
        );
    }
}

/// Replaces a few states by non-finite ones next to finite ones: NaN in `q` of state 2, an
/// infinite velocity in state 5.
fn spoil<const N: usize, const V: usize>(q: &mut [[f64; N]], qd: &mut [[f64; V]]) {
    q[2][N - 1] = f64::NAN;
    qd[5][0] = f64::INFINITY;
}

const STATES: usize = 11; // not a multiple of any lane count: the last vector is partial

#[test]
fn panda_batch_equals_scalar_state_by_state() {
    let robot = Panda::<f64>::default();
    let mut n = Numbers(1);
    let (mut q, mut qd) = (n.states::<9>(STATES, 2.0), n.states::<9>(STATES, 1.0));
    let (qdd, tau) = (n.states::<9>(STATES, 1.0), n.states::<9>(STATES, 10.0));
    spoil(&mut q, &mut qd);
    let mut v = vec![[0.0; 9]; STATES];
    let mut m = vec![[[0.0; 9]; 9]; STATES];
    let mut e = vec![0.0; STATES];
    robot.inverse_dynamics_batch(&q, &qd, &qdd, &mut v).unwrap();
    for i in 0..STATES {
        let want = robot.inverse_dynamics(&q[i], &qd[i], &qdd[i]);
        assert_close("inverse_dynamics", i, &v[i], &want, 0.0);
    }
    robot.forward_dynamics_batch(&q, &qd, &tau, &mut v).unwrap();
    for i in 0..STATES {
        let want = robot.forward_dynamics(&q[i], &qd[i], &tau[i]);
        assert_close("forward_dynamics", i, &v[i], &want, 0.0);
    }
    robot.mass_matrix_batch(&q, &mut m).unwrap();
    for i in 0..STATES {
        assert_close("mass_matrix", i, &m[i], &robot.mass_matrix(&q[i]), 0.0);
    }
    robot.kinetic_energy_batch(&q, &qd, &mut e).unwrap();
    for i in 0..STATES {
        let want = robot.kinetic_energy(&q[i], &qd[i]);
        assert_close("kinetic_energy", i, &e[i], &want, 0.0);
    }
}

#[test]
fn batch_at_zero_angles_is_bit_for_bit() {
    let robot = Panda::<f64>::default();
    let mut n = Numbers(2);
    let q = vec![[0.0; 9]; STATES];
    let (qd, tau) = (n.states::<9>(STATES, 1.0), n.states::<9>(STATES, 10.0));
    let mut v = vec![[0.0; 9]; STATES];
    robot.forward_dynamics_batch(&q, &qd, &tau, &mut v).unwrap();
    for i in 0..STATES {
        let want = robot.forward_dynamics(&q[i], &qd[i], &tau[i]);
        assert_close("forward_dynamics", i, &v[i], &want, 0.0);
    }
}

#[test]
fn derivatives_in_batches_fixed_and_floating() {
    let robot = panda_derivatives::PandaDerivatives::<f64>::default();
    let mut n = Numbers(3);
    let (mut q, mut qd) = (n.states::<9>(STATES, 2.0), n.states::<9>(STATES, 1.0));
    let tau = n.states::<9>(STATES, 10.0);
    spoil(&mut q, &mut qd);
    let z = [[0.0; 9]; 9];
    let (mut a, mut b, mut c) = (vec![z; STATES], vec![z; STATES], vec![z; STATES]);
    robot
        .forward_dynamics_derivatives_batch(&q, &qd, &tau, &mut a, &mut b, &mut c)
        .unwrap();
    for i in 0..STATES {
        let want = robot.forward_dynamics_derivatives(&q[i], &qd[i], &tau[i]);
        assert_close("d qdd / dq", i, &a[i], &want.0, 0.0);
        assert_close("d qdd / dqd", i, &b[i], &want.1, 0.0);
        assert_close("M^-1", i, &c[i], &want.2, 0.0);
    }

    let robot = anymal_derivatives::AnymalDerivatives::<f64>::default();
    let (mut q, mut v) = (n.states::<19>(STATES, 1.0), n.states::<18>(STATES, 1.0));
    for s in &mut q {
        let norm = s[3..7].iter().map(|x| x * x).sum::<f64>().sqrt();
        s[3..7].iter_mut().for_each(|x| *x /= norm);
    }
    let a = n.states::<18>(STATES, 1.0);
    spoil(&mut q, &mut v);
    let z = [[0.0; 18]; 18];
    let (mut dq, mut dv) = (vec![z; STATES], vec![z; STATES]);
    robot
        .inverse_dynamics_derivatives_batch(&q, &v, &a, &mut dq, &mut dv)
        .unwrap();
    let mut acc = vec![[0.0; 18]; STATES];
    robot.forward_dynamics_batch(&q, &v, &a, &mut acc).unwrap();
    // Written run by run from the lanes' straight-line body (`mass_matrix_unpacked`).
    let mut m = vec![z; STATES];
    robot.mass_matrix_batch(&q, &mut m).unwrap();
    for i in 0..STATES {
        assert_close(
            "floating mass_matrix",
            i,
            &m[i],
            &robot.mass_matrix(&q[i]),
            0.0,
        );
    }
    let mut next = vec![[0.0; 19]; STATES];
    robot.integrate_batch(&q, &v, 0.01, &mut next).unwrap();
    for i in 0..STATES {
        let want = robot.inverse_dynamics_derivatives(&q[i], &v[i], &a[i]);
        assert_close("d tau / dq", i, &dq[i], &want.0, 0.0);
        assert_close("d tau / dv", i, &dv[i], &want.1, 0.0);
        let want = robot.forward_dynamics(&q[i], &v[i], &a[i]);
        assert_close("floating forward_dynamics", i, &acc[i], &want, 0.0);
        let want = robot.integrate(&q[i], &v[i], 0.01);
        assert_close("integrate", i, &next[i], &want, 0.0);
    }
}

#[test]
fn coulomb_friction_sign_per_lane() {
    let robot = joint_effects_full::JointEffectsFull::<f64>::default();
    let mut n = Numbers(4);
    let q = n.states::<2>(STATES, 1.0);
    let mut qd = n.states::<2>(STATES, 1.0);
    // At rest, moving either way, and -0: the sign is taken lane by lane.
    (qd[0], qd[1], qd[3]) = ([0.0, 0.0], [-0.0, 1e-300], [-1.0, 0.0]);
    let qdd = n.states::<2>(STATES, 1.0);
    let mut tau = vec![[0.0; 2]; STATES];
    robot
        .inverse_dynamics_batch(&q, &qd, &qdd, &mut tau)
        .unwrap();
    for i in 0..STATES {
        let want = robot.inverse_dynamics(&q[i], &qd[i], &qdd[i]);
        assert_close("inverse_dynamics with friction", i, &tau[i], &want, 0.0);
    }
}

#[test]
fn lanes_of_four_doubles_and_eight_floats() {
    let mut n = Numbers(5);
    let (q, qd, tau) = (
        n.states::<9>(8, 2.0),
        n.states::<9>(8, 1.0),
        n.states::<9>(8, 10.0),
    );
    let lanes =
        |x: &[[f64; 9]]| -> [f64x4; 9] { core::array::from_fn(|j| f64x4::gather(|l| x[l][j])) };
    let robot = Panda::<f64>::default();
    let wide = robot.in_lanes::<f64x4>();
    let got = wide.forward_dynamics(&lanes(&q), &lanes(&qd), &lanes(&tau));
    for l in 0..4 {
        let one: [f64; 9] = core::array::from_fn(|j| got[j].lane(l));
        let want = robot.forward_dynamics(&q[l], &qd[l], &tau[l]);
        assert_close("f64x4 forward_dynamics", l, &one, &want, 0.0);
    }
    // Eight states in single precision, against the scalar f32 code.
    let robot32 = Panda::<f32>::default();
    let wide32 = robot32.in_lanes::<f32x8>();
    let lanes32 = |x: &[[f64; 9]]| -> [f32x8; 9] {
        core::array::from_fn(|j| f32x8::gather(|l| x[l][j] as f32))
    };
    let f32s = |x: &[f64; 9]| -> [f32; 9] { x.map(|v| v as f32) };
    let got = wide32.inverse_dynamics(&lanes32(&q), &lanes32(&qd), &lanes32(&tau));
    for l in 0..8 {
        let one: [f64; 9] = core::array::from_fn(|j| got[j].lane(l) as f64);
        let want = robot32.inverse_dynamics(&f32s(&q[l]), &f32s(&qd[l]), &f32s(&tau[l]));
        assert_close(
            "f32x8 inverse_dynamics",
            l,
            &one,
            &want.map(f64::from),
            1e-5,
        );
    }
}

#[test]
fn a_failed_lane_is_named_and_the_others_are_unaffected() {
    let robot = Panda::<f64>::default();
    let wide = robot.in_lanes::<f64x4>();
    let mut n = Numbers(6);
    let (mut q, qd, tau) = (
        n.states::<9>(4, 2.0),
        n.states::<9>(4, 1.0),
        n.states::<9>(4, 10.0),
    );
    q[2][4] = f64::NAN;
    let lanes =
        |x: &[[f64; 9]]| -> [f64x4; 9] { core::array::from_fn(|j| f64x4::gather(|l| x[l][j])) };
    let err = wide
        .try_forward_dynamics_lanes(&lanes(&q), &lanes(&qd), &lanes(&tau))
        .unwrap_err();
    let scalar = robot
        .try_forward_dynamics(&q[2], &qd[2], &tau[2])
        .unwrap_err();
    assert_eq!(
        err,
        LaneError {
            lane: 2,
            error: scalar
        }
    );
    assert!(matches!(scalar, FactorError::NonFinite { .. }));
    let got = wide.forward_dynamics(&lanes(&q), &lanes(&qd), &lanes(&tau));
    for l in 0..4 {
        let one: [f64; 9] = core::array::from_fn(|j| got[j].lane(l));
        assert_eq!(one.iter().all(|x| x.is_nan()), l == 2, "lane {l}");
    }
}

#[test]
fn mismatched_lengths_are_an_error_and_nothing_is_written() {
    let robot = Panda::<f64>::default();
    let (q, qd) = (vec![[0.1; 9]; 4], vec![[0.0; 9]; 3]);
    let mut tau = vec![[7.0; 9]; 4];
    let e = robot
        .inverse_dynamics_batch(&q, &qd, &q, &mut tau)
        .unwrap_err();
    assert_eq!((e.argument, e.len, e.expected), ("qd", 3, 4));
    assert!(tau.iter().flatten().all(|x| *x == 7.0));
    let mut empty: Vec<[f64; 9]> = Vec::new();
    robot
        .inverse_dynamics_batch(&[], &[], &[], &mut empty)
        .unwrap();
}

/// `count` states of `n` entries, one after another, with NaN and infinities between finite
/// entries.
fn run_of_states(n: usize, count: usize, numbers: &mut Numbers) -> Vec<f64> {
    (0..n * count)
        .map(|k| match k % 11 {
            3 => f64::NAN,
            7 => f64::NEG_INFINITY,
            _ => numbers.next(),
        })
        .collect()
}

/// `Pack::pack` and `Pack::unpack` of `L` against lane-by-lane packing: every run length
/// (whole transposed blocks and the entries past them), whole and partial vectors, NaN lanes
/// next to finite ones, bit for bit.
fn pack_round_trip<L: Pack>(from: impl Fn(f64) -> L::Scalar) {
    let mut numbers = Numbers(7);
    for n in [1, 2, 3, 4, 5, 7, 8, 9, 17, 19, 81] {
        for count in 0..=L::LANES {
            let states: Vec<L::Scalar> = run_of_states(n, count, &mut numbers)
                .into_iter()
                .map(&from)
                .collect();
            let mut v = vec![L::from_f64(5.0); n];
            L::pack(&states, &mut v);
            for (j, x) in v.iter().enumerate() {
                for l in 0..L::LANES {
                    let want = states.get(l * n + j).copied().unwrap_or(from(0.0));
                    let got = x.lane(l);
                    assert_eq!(
                        got.to_f64().to_bits(),
                        want.to_f64().to_bits(),
                        "pack n {n}, {count} states, entry {j}, lane {l}"
                    );
                }
            }
            // Unpacking writes exactly the states the slice holds, lane l into state l.
            let full = run_of_states(n, L::LANES, &mut numbers);
            let v: Vec<L> = (0..n)
                .map(|j| L::gather(|l| from(full[l * n + j])))
                .collect();
            let mut out = vec![from(-2.0); n * count + 1];
            L::unpack(&v, &mut out[..n * count]);
            for (k, got) in out.iter().enumerate() {
                let want = if k < n * count {
                    from(full[k])
                } else {
                    from(-2.0)
                };
                assert_eq!(
                    got.to_f64().to_bits(),
                    want.to_f64().to_bits(),
                    "unpack n {n}, {count} states, scalar {k}"
                );
            }
        }
    }
}

/// `Pack::unpack_run` of `L` against lane-by-lane writing: runs of every length from 1 to 9
/// (whole transposed blocks and the entries past them) at several offsets of a 3 x 5 matrix,
/// runs reaching past its end (dropped), whole and partial vectors of states, NaN lanes next to
/// finite ones, bit for bit; nothing else of the states is written.
fn unpack_run_writes_its_entries<L: Pack>(from: impl Fn(f64) -> L::Scalar) {
    let mut numbers = Numbers(9);
    for len in 1..=9 {
        for at in [0, 1, 4, 7, 13] {
            for count in 0..=L::LANES {
                let full = run_of_states(len, L::LANES, &mut numbers);
                let v: Vec<L> = (0..len)
                    .map(|j| L::gather(|l| from(full[l * len + j])))
                    .collect();
                let mut states = vec![[[from(-2.0); 5]; 3]; count + 1];
                L::unpack_run(&v, &mut states[..count], at);
                for (l, state) in states.iter().enumerate() {
                    for (k, got) in state.as_flattened().iter().enumerate() {
                        let want = match k.checked_sub(at) {
                            Some(j) if j < len && l < count => from(full[l * len + j]),
                            _ => from(-2.0),
                        };
                        assert_eq!(
                            got.to_f64().to_bits(),
                            want.to_f64().to_bits(),
                            "run of {len} at {at}, {count} states: state {l}, entry {k}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn unpack_run_transposes_whole_and_partial_vectors() {
    unpack_run_writes_its_entries::<f64x4>(|x| x);
    unpack_run_writes_its_entries::<f32x8>(|x| x as f32);
    unpack_run_writes_its_entries::<wide::f64x2>(|x| x);
    unpack_run_writes_its_entries::<f64>(|x| x);
}

#[test]
fn pack_and_unpack_transpose_whole_and_partial_vectors() {
    pack_round_trip::<f64x4>(|x| x);
    pack_round_trip::<f32x8>(|x| x as f32);
    pack_round_trip::<wide::f64x2>(|x| x);
    pack_round_trip::<f64>(|x| x);
}

#[test]
fn gather_and_scatter_of_four_doubles_partial_last_vector() {
    let mut n = Numbers(8);
    let mut x = n.states::<9>(6, 1.0);
    x[4][8] = f64::NAN;
    // States 4 and 5, then two copies of state 5 past the end.
    let v: [f64x4; 9] = gather(&x, 4);
    for (j, e) in v.iter().enumerate() {
        let want = [x[4][j], x[5][j], x[5][j], x[5][j]];
        assert_eq!(e.to_array().map(f64::to_bits), want.map(f64::to_bits));
    }
    let mut out = vec![[7.0; 9]; 3];
    scatter(&v, &mut out[..2]);
    assert_eq!(out[0].map(f64::to_bits), x[4].map(f64::to_bits));
    assert_eq!(out[1], x[5]);
    assert_eq!(out[2], [7.0; 9]);
    let m: [[f64x4; 18]; 18] = core::array::from_fn(|r| {
        core::array::from_fn(|c| f64x4::gather(|l| (100 * l + 18 * r + c) as f64))
    });
    for count in 0..=4 {
        let mut out = vec![[[-1.0; 18]; 18]; 4];
        scatter_matrix(&m, &mut out[..count]);
        for (l, s) in out.iter().enumerate() {
            for (r, row) in s.iter().enumerate() {
                for (c, e) in row.iter().enumerate() {
                    let want = if l < count {
                        (100 * l + 18 * r + c) as f64
                    } else {
                        -1.0
                    };
                    assert_eq!(*e, want, "{count} states: state {l} ({r}, {c})");
                }
            }
        }
    }
}

/// `count` floating-base states of anymal: unit quaternions, joints within a radian.
fn anymal_states(n: &mut Numbers, count: usize) -> (Vec<[f64; 19]>, Vec<[f64; 18]>) {
    let (mut q, v) = (n.states::<19>(count, 1.0), n.states::<18>(count, 1.0));
    for s in &mut q {
        let norm = s[3..7].iter().map(|x| x * x).sum::<f64>().sqrt();
        s[3..7].iter_mut().for_each(|x| *x /= norm);
    }
    (q, v)
}

/// `$robot`'s contact forward dynamics and impulse dynamics (restitution `$e`) in batches
/// equal its scalar methods bit for bit, at `STATES` anymal states from `$seed` with NaN and
/// infinite ones ([`spoil`]); gives the states `(q, v, tau)`.
macro_rules! contact_batches_equal_the_scalar_code {
    ($robot:expr, $seed:expr, $e:expr) => {{
        let (robot, e) = (&$robot, $e);
        let mut n = Numbers($seed);
        let (mut q, mut v) = anymal_states(&mut n, STATES);
        spoil(&mut q, &mut v);
        let tau = n.states::<18>(STATES, 20.0);
        let (mut a, mut f) = (vec![[0.0; 18]; STATES], vec![[0.0; 12]; STATES]);
        robot
            .contact_forward_dynamics_batch(&q, &v, &tau, &mut a, &mut f)
            .unwrap();
        let (mut after, mut p) = (vec![[0.0; 18]; STATES], vec![[0.0; 12]; STATES]);
        robot
            .impulse_dynamics_batch(&q, &v, e, &mut after, &mut p)
            .unwrap();
        for i in 0..STATES {
            let (want_a, want_f) = robot.contact_forward_dynamics(&q[i], &v[i], &tau[i]);
            assert_close("contact accelerations", i, &a[i], &want_a, 0.0);
            assert_close("contact forces", i, &f[i], &want_f, 0.0);
            assert!(want_a.iter().all(|x| x.is_finite()) == (i != 2 && i != 5));
            let (want_v, want_p) = robot.impulse_dynamics(&q[i], &v[i], e);
            assert_close("velocity after the impact", i, &after[i], &want_v, 0.0);
            assert_close("impulses", i, &p[i], &want_p, 0.0);
        }
        (q, v, tau)
    }};
}

#[test]
fn contact_and_impulse_dynamics_in_batches_equal_the_scalar_code() {
    use eomgen_tests::robots::anymal::Anymal;
    let robot = Anymal::<f64>::default();
    let (q, v, _) = contact_batches_equal_the_scalar_code!(robot, 10, 0.3);
    let mut j = vec![[[0.0; 18]; 12]; STATES];
    robot.contact_jacobian_batch(&q, &mut j).unwrap();
    let mut drift = vec![[0.0; 12]; STATES];
    robot.contact_drift_batch(&q, &v, &mut drift).unwrap();
    for i in 0..STATES {
        let want = robot.contact_jacobian(&q[i]);
        assert_close("contact_jacobian", i, &j[i], &want, 0.0);
        let want = robot.contact_drift(&q[i], &v[i]);
        assert_close("contact_drift", i, &drift[i], &want, 0.0);
    }
}

#[test]
fn a_failed_contact_lane_is_named_and_the_others_are_unaffected() {
    use eomgen_tests::robots::anymal::Anymal;
    let robot = Anymal::<f64>::default();
    let wide = robot.in_lanes::<f64x4>();
    let mut n = Numbers(11);
    let (mut q, v) = anymal_states(&mut n, 4);
    let tau = n.states::<18>(4, 20.0);
    q[1][9] = f64::NAN;
    let (ql, vl, tl): ([f64x4; 19], [f64x4; 18], [f64x4; 18]) =
        (gather(&q, 0), gather(&v, 0), gather(&tau, 0));
    let err = wide
        .try_contact_forward_dynamics_lanes(&ql, &vl, &tl)
        .unwrap_err();
    let scalar = robot
        .try_contact_forward_dynamics(&q[1], &v[1], &tau[1])
        .unwrap_err();
    assert_eq!(
        err,
        LaneError {
            lane: 1,
            error: scalar
        }
    );
    // The trait's `try_` reports the same lane's error.
    assert_eq!(
        wide.try_contact_forward_dynamics(&ql, &vl, &tl),
        Err(scalar)
    );
    let err = wide
        .try_impulse_dynamics_lanes(&ql, &vl, f64x4::splat(0.0))
        .unwrap_err();
    let scalar = robot.try_impulse_dynamics(&q[1], &v[1], 0.0).unwrap_err();
    assert_eq!(
        err,
        LaneError {
            lane: 1,
            error: scalar
        }
    );
    let (a, f) = wide.contact_forward_dynamics(&ql, &vl, &tl);
    for l in 0..4 {
        let one: Vec<f64> = a.iter().chain(&f).map(|x| x.lane(l)).collect();
        assert_eq!(one.iter().all(|x| x.is_nan()), l == 1, "lane {l}");
        let (want_a, want_f) = robot.contact_forward_dynamics(&q[l], &v[l], &tau[l]);
        let want: Vec<f64> = want_a.iter().chain(&want_f).copied().collect();
        assert_close("f64x4 contact forward dynamics", l, &one, &want, 0.0);
    }
}

/// Four anymal states from `seed` of which lane 1 fails in M's factorization (NaN in `q`)
/// and lane 3 in its result (an infinite velocity): `(q, v, tau)` per state, and the same
/// on four `f64` lanes.
#[allow(clippy::type_complexity)]
fn four_lanes_two_failing(
    seed: u64,
) -> (
    (Vec<[f64; 19]>, Vec<[f64; 18]>, Vec<[f64; 18]>),
    ([f64x4; 19], [f64x4; 18], [f64x4; 18]),
) {
    let mut n = Numbers(seed);
    let (mut q, mut v) = anymal_states(&mut n, 4);
    let tau = n.states::<18>(4, 20.0);
    q[1][9] = f64::NAN;
    v[3][10] = f64::INFINITY;
    let lanes = (gather(&q, 0), gather(&v, 0), gather(&tau, 0));
    ((q, v, tau), lanes)
}

/// `err` is lane 1's own error (`scalar(1)`'s), and of the scalar calls only lanes 1 and 3
/// fail ([`four_lanes_two_failing`]).
fn lane_one_named<X>(err: LaneError, scalar: impl Fn(usize) -> Result<X, FactorError>) {
    let first = scalar(1).err().expect("lane 1 fails");
    assert_eq!(
        err,
        LaneError {
            lane: 1,
            error: first
        }
    );
    assert!(scalar(3).is_err() && scalar(0).is_ok() && scalar(2).is_ok());
}

#[test]
fn active_contacts_on_four_lanes_name_the_failed_lane() {
    use eomgen_tests::robots::anymal_mpc::AnymalMpc;
    let robot = AnymalMpc::<f64>::default();
    let wide = robot.in_lanes::<f64x4>();
    let ((q, v, tau), (ql, vl, tl)) = four_lanes_two_failing(14);
    let active = [true, false, true, true];
    let err = wide
        .try_contact_forward_dynamics_active_lanes(&ql, &vl, &tl, &active)
        .unwrap_err();
    let scalar =
        |l: usize| robot.try_contact_forward_dynamics_active(&q[l], &v[l], &tau[l], &active);
    let first = scalar(1).unwrap_err();
    assert_eq!(
        err,
        LaneError {
            lane: 1,
            error: first
        }
    );
    assert_eq!(
        wide.try_contact_forward_dynamics_active(&ql, &vl, &tl, &active),
        Err(first)
    );
    assert!(scalar(3).is_err() && scalar(0).is_ok() && scalar(2).is_ok());
    let (a, f) = wide.contact_forward_dynamics_active(&ql, &vl, &tl, &active);
    for l in 0..4 {
        let one: Vec<f64> = a.iter().chain(&f).map(|x| x.lane(l)).collect();
        assert_eq!(one.iter().all(|x| x.is_nan()), l == 1 || l == 3, "lane {l}");
        let (want_a, want_f) =
            robot.contact_forward_dynamics_active(&q[l], &v[l], &tau[l], &active);
        let want: Vec<f64> = want_a.iter().chain(&want_f).copied().collect();
        assert_close(
            "f64x4 contact forward dynamics, two feet",
            l,
            &one,
            &want,
            0.0,
        );
        // The inactive foot's forces are zero where the lane did not fail.
        if l % 2 == 0 {
            assert!(want_f[3..6].iter().all(|x| *x == 0.0), "lane {l}");
        }
    }
    // Impulse dynamics at the same feet: lane 1 fails in M, lane 3 (its velocity infinite) in
    // its result.
    let e = 0.4;
    let err = wide
        .try_impulse_dynamics_active_lanes(&ql, &vl, f64x4::splat(e), &active)
        .unwrap_err();
    let scalar = |l: usize| robot.try_impulse_dynamics_active(&q[l], &v[l], e, &active);
    lane_one_named(err, scalar);
    let (after, p) = wide.impulse_dynamics_active(&ql, &vl, f64x4::splat(e), &active);
    for l in 0..4 {
        let one: Vec<f64> = after.iter().chain(&p).map(|x| x.lane(l)).collect();
        assert_eq!(one.iter().all(|x| x.is_nan()), l == 1 || l == 3, "lane {l}");
        let (want_v, want_p) = robot.impulse_dynamics_active(&q[l], &v[l], e, &active);
        let want: Vec<f64> = want_v.iter().chain(&want_p).copied().collect();
        assert_close("f64x4 impulse dynamics, two feet", l, &one, &want, 0.0);
    }
    // Baumgarte-stabilized, each foot's reference off its position: the same lanes fail.
    let reference = [eomgen_runtime::Pose::from_translation([0.3, -0.2, 0.0]); 4];
    let gains = eomgen_runtime::Baumgarte::new(100.0, 20.0, reference);
    let wide_gains = gains.in_lanes::<f64x4>();
    let err = wide
        .try_contact_forward_dynamics_stabilized_lanes(&ql, &vl, &tl, &active, &wide_gains)
        .unwrap_err();
    lane_one_named(err, |l| {
        robot.try_contact_forward_dynamics_stabilized(&q[l], &v[l], &tau[l], &active, &gains)
    });
    let (a, f) = wide.contact_forward_dynamics_stabilized(&ql, &vl, &tl, &active, &wide_gains);
    for l in 0..4 {
        let one: Vec<f64> = a.iter().chain(&f).map(|x| x.lane(l)).collect();
        assert_eq!(one.iter().all(|x| x.is_nan()), l == 1 || l == 3, "lane {l}");
        let (want_a, want_f) =
            robot.contact_forward_dynamics_stabilized(&q[l], &v[l], &tau[l], &active, &gains);
        let want: Vec<f64> = want_a.iter().chain(&want_f).copied().collect();
        assert_close("f64x4 stabilized contact dynamics", l, &one, &want, 0.0);
    }
}

/// The contact and impulse derivatives (every contact, and a set of active ones) on four
/// lanes: a lane failing in `M`'s factorization and one failing in its result (an infinite
/// velocity) are NaN and named, the others equal the scalar code bit for bit.
#[test]
fn derivatives_on_four_lanes_name_the_failed_lane() {
    use eomgen_runtime::batch::{scatter_contact_derivatives, scatter_impulse_derivatives};
    use eomgen_tests::robots::anymal_mpc::AnymalMpc;
    let robot = AnymalMpc::<f64>::default();
    let wide = robot.in_lanes::<f64x4>();
    let ((q, v, tau), (ql, vl, tl)) = four_lanes_two_failing(16);
    let (active, e) = ([true, false, true, true], 0.3);
    let failed = |l: usize, all_nan: bool| {
        assert_eq!(all_nan, l == 1 || l == 3, "lane {l}");
    };
    let nan = |x: &[f64]| x.iter().all(|y| y.is_nan());

    let err = wide
        .try_contact_forward_dynamics_derivatives_lanes(&ql, &vl, &tl)
        .unwrap_err();
    let scalar = |l: usize| robot.try_contact_forward_dynamics_derivatives(&q[l], &v[l], &tau[l]);
    lane_one_named(err, scalar);
    let mut got = vec![robot.contact_forward_dynamics_derivatives(&q[0], &v[0], &tau[0]); 4];
    scatter_contact_derivatives(
        &wide.contact_forward_dynamics_derivatives(&ql, &vl, &tl),
        &mut got,
    );
    for (l, d) in got.iter().enumerate() {
        failed(l, nan(&d.flat()));
        let want = robot.contact_forward_dynamics_derivatives(&q[l], &v[l], &tau[l]);
        assert_close("f64x4 contact derivatives", l, d, &want, 0.0);
    }
    let d = wide.contact_forward_dynamics_derivatives_active(&ql, &vl, &tl, &active);
    scatter_contact_derivatives(&d, &mut got);
    for (l, d) in got.iter().enumerate() {
        failed(l, nan(&d.flat()));
        let want =
            robot.contact_forward_dynamics_derivatives_active(&q[l], &v[l], &tau[l], &active);
        assert_close("f64x4 contact derivatives, three feet", l, d, &want, 0.0);
    }

    let el = f64x4::splat(e);
    let err = wide
        .try_impulse_dynamics_derivatives_lanes(&ql, &vl, el)
        .unwrap_err();
    let scalar = |l: usize| robot.try_impulse_dynamics_derivatives(&q[l], &v[l], e);
    assert_eq!(
        err,
        LaneError {
            lane: 1,
            error: scalar(1).unwrap_err()
        }
    );
    assert_eq!(
        wide.try_impulse_dynamics_derivatives(&ql, &vl, el)
            .unwrap_err(),
        scalar(1).unwrap_err()
    );
    let mut got = vec![robot.impulse_dynamics_derivatives(&q[0], &v[0], e); 4];
    scatter_impulse_derivatives(&wide.impulse_dynamics_derivatives(&ql, &vl, el), &mut got);
    for (l, d) in got.iter().enumerate() {
        failed(l, nan(&d.flat()));
        let want = robot.impulse_dynamics_derivatives(&q[l], &v[l], e);
        assert_close("f64x4 impulse derivatives", l, d, &want, 0.0);
    }
    let d = wide.impulse_dynamics_derivatives_active(&ql, &vl, el, &active);
    scatter_impulse_derivatives(&d, &mut got);
    for (l, d) in got.iter().enumerate() {
        failed(l, nan(&d.flat()));
        let want = robot.impulse_dynamics_derivatives_active(&q[l], &v[l], e, &active);
        assert_close("f64x4 impulse derivatives, three feet", l, d, &want, 0.0);
    }
}

/// Contact forward dynamics and impulse dynamics solved at run time (the route of robots over
/// the straight-line budget) on lanes: their batches equal the scalar code bit for bit with
/// NaN and infinite states between finite ones, four lanes name their failed lane, and the
/// values are the straight-line programs' to rounding.
#[test]
fn contact_dynamics_solved_at_run_time_on_lanes() {
    use eomgen_tests::robots::{anymal_mpc::AnymalMpc, anymal_solved::AnymalSolved};
    let source = include_str!(concat!(env!("OUT_DIR"), "/anymal_solved.rs"));
    assert!(source.contains("contact::solve_factored_active_lanes"));
    assert!(source.contains("impulse::solve_factored_active_lanes"));
    let (robot, flat) = (AnymalSolved::<f64>::default(), AnymalMpc::<f64>::default());
    let (q, v, tau) = contact_batches_equal_the_scalar_code!(robot, 17, 0.2);
    for i in 0..STATES {
        let (want_a, want_f) = robot.contact_forward_dynamics(&q[i], &v[i], &tau[i]);
        let (flat_a, flat_f) = flat.contact_forward_dynamics(&q[i], &v[i], &tau[i]);
        assert_close("solved against flat", i, &want_a, &flat_a, 1e-9);
        assert_close("solved against flat", i, &want_f, &flat_f, 1e-9);
    }
    let wide = robot.in_lanes::<f64x4>();
    let ((q, v, tau), (ql, vl, tl)) = four_lanes_two_failing(18);
    let err = wide
        .try_contact_forward_dynamics_lanes(&ql, &vl, &tl)
        .unwrap_err();
    lane_one_named(err, |l| {
        robot.try_contact_forward_dynamics(&q[l], &v[l], &tau[l])
    });
    let err = wide
        .try_impulse_dynamics_lanes(&ql, &vl, f64x4::splat(0.2))
        .unwrap_err();
    lane_one_named(err, |l| robot.try_impulse_dynamics(&q[l], &v[l], 0.2));
    let (a, f) = wide.contact_forward_dynamics(&ql, &vl, &tl);
    for l in 0..4 {
        let one: Vec<f64> = a.iter().chain(&f).map(|x| x.lane(l)).collect();
        assert_eq!(one.iter().all(|x| x.is_nan()), l == 1 || l == 3, "lane {l}");
        let (want_a, want_f) = robot.contact_forward_dynamics(&q[l], &v[l], &tau[l]);
        let want: Vec<f64> = want_a.iter().chain(&want_f).copied().collect();
        assert_close("f64x4 solved contact dynamics", l, &one, &want, 0.0);
    }
}

/// The contact derivatives' batch in `f32` (`f32x8` with AVX) is as accurate as
/// the scalar `f32` code: `wide`'s sines and cosines differ from `libm`'s in the last bits,
/// which the KKT solves amplify, so each is measured against the `f64` code at the same
/// inputs, NaN where the scalar's is.
#[test]
fn contact_derivatives_in_f32_batches_are_as_accurate_as_the_scalar_code() {
    use eomgen_tests::robots::anymal_mpc::AnymalMpc;
    let (robot, exact) = (AnymalMpc::<f32>::default(), AnymalMpc::<f64>::default());
    let mut n = Numbers(19);
    let (mut q, mut v) = anymal_states(&mut n, STATES);
    spoil(&mut q, &mut v);
    let tau = n.states::<18>(STATES, 20.0);
    let single =
        |x: &[[f64; 18]]| -> Vec<[f32; 18]> { x.iter().map(|s| s.map(|y| y as f32)).collect() };
    let q32: Vec<[f32; 19]> = q.iter().map(|s| s.map(|y| y as f32)).collect();
    let (v32, tau32) = (single(&v), single(&tau));
    let mut d =
        vec![robot.contact_forward_dynamics_derivatives(&q32[0], &v32[0], &tau32[0]); STATES];
    robot
        .contact_forward_dynamics_derivatives_batch(&q32, &v32, &tau32, &mut d)
        .unwrap();
    let mut worst: [f64; 2] = [0.0; 2];
    for i in 0..STATES {
        let scalar = robot.contact_forward_dynamics_derivatives(&q32[i], &v32[i], &tau32[i]);
        let back = |s: &[f32; 18]| s.map(f64::from);
        let qi: [f64; 19] = q32[i].map(f64::from);
        let want =
            exact.contact_forward_dynamics_derivatives(&qi, &back(&v32[i]), &back(&tau32[i]));
        let (w, b, s) = (want.flat(), d[i].flat(), scalar.flat());
        let scale = w
            .iter()
            .filter(|x| x.is_finite())
            .fold(1.0_f64, |m, x| m.max(x.abs()));
        for (k, ((w, b), s)) in w.iter().zip(&b).zip(&s).enumerate() {
            assert_eq!(
                b.is_nan(),
                s.is_nan(),
                "state {i}, entry {k}: batch {b}, scalar {s}"
            );
            if w.is_finite() {
                worst[0] = worst[0].max((b - w).abs() / scale);
                worst[1] = worst[1].max((s - w).abs() / scale);
            }
        }
    }
    assert!(
        worst[0] <= 4.0 * worst[1] && worst[0] < 1e-3,
        "batch {}, scalar {}",
        worst[0],
        worst[1]
    );
}

/// Both `_active` batches on lanes equal the scalar methods, with NaN and infinite states
/// between finite ones, and a set of contacts other than the one-contact-off sets above.
#[test]
fn active_contact_batches_equal_the_scalar_code() {
    use eomgen_tests::robots::anymal_mpc::AnymalMpc;
    let robot = AnymalMpc::<f64>::default();
    let mut n = Numbers(15);
    let (mut q, mut v) = anymal_states(&mut n, STATES);
    spoil(&mut q, &mut v);
    let tau = n.states::<18>(STATES, 20.0);
    for active in [[false, true, true, false], [true; 4], [false; 4]] {
        let (mut a, mut f) = (vec![[0.0; 18]; STATES], vec![[0.0; 12]; STATES]);
        robot
            .contact_forward_dynamics_active_batch(&q, &v, &tau, &active, &mut a, &mut f)
            .unwrap();
        let (mut after, mut p) = (vec![[0.0; 18]; STATES], vec![[0.0; 12]; STATES]);
        robot
            .impulse_dynamics_active_batch(&q, &v, 0.2, &active, &mut after, &mut p)
            .unwrap();
        for i in 0..STATES {
            let (want_a, want_f) =
                robot.contact_forward_dynamics_active(&q[i], &v[i], &tau[i], &active);
            assert_close("active accelerations", i, &a[i], &want_a, 0.0);
            assert_close("active forces", i, &f[i], &want_f, 0.0);
            let (want_v, want_p) = robot.impulse_dynamics_active(&q[i], &v[i], 0.2, &active);
            assert_close("velocity after an impact", i, &after[i], &want_v, 0.0);
            assert_close("active impulses", i, &p[i], &want_p, 0.0);
            assert!(want_a.iter().all(|x| x.is_finite()) == (i != 2 && i != 5));
        }
    }
}

impl<T: Copy, const N: usize, const K: usize> Flat
    for eomgen_runtime::ContactDynamicsDerivatives<T, N, K>
where
    [[T; N]; N]: Flat,
    [[T; N]; K]: Flat,
{
    fn flat(&self) -> Vec<f64> {
        [self.da_dq, self.da_dv, self.da_dtau]
            .iter()
            .flat_map(Flat::flat)
            .chain(
                [self.df_dq, self.df_dv, self.df_dtau]
                    .iter()
                    .flat_map(Flat::flat),
            )
            .collect()
    }
}

impl<T: Copy, const N: usize, const K: usize> Flat
    for eomgen_runtime::ImpulseDynamicsDerivatives<T, N, K>
where
    [[T; N]; N]: Flat,
    [[T; N]; K]: Flat,
{
    fn flat(&self) -> Vec<f64> {
        [self.dv_dq, self.dv_dv]
            .iter()
            .flat_map(Flat::flat)
            .chain(
                [self.dimpulse_dq, self.dimpulse_dv]
                    .iter()
                    .flat_map(Flat::flat),
            )
            .collect()
    }
}

impl Flat for eomgen_runtime::Pose<f64> {
    fn flat(&self) -> Vec<f64> {
        self.translation
            .iter()
            .chain(self.rotation.as_flattened())
            .copied()
            .collect()
    }
}

/// `got[i]` equals `want(i)` bit for bit at every state.
fn each_state<X: Flat>(what: &str, got: &[X], want: impl Fn(usize) -> X) {
    each_state_within(what, got, want, 0.0);
}

/// `got[i]` equals `want(i)` at every state, as [`assert_close`] with `tol`.
fn each_state_within<X: Flat>(what: &str, got: &[X], want: impl Fn(usize) -> X, tol: f64) {
    for (i, g) in got.iter().enumerate() {
        assert_close(what, i, g, &want(i), tol);
    }
}

/// The MPC kit's batches on anymal's four feet (link kinematics, contact forward dynamics
/// with active contacts and stabilized, the contact and impulse derivatives) equal the scalar
/// methods, with NaN and infinite states between finite ones.
#[test]
fn mpc_kit_batches_equal_the_scalar_code() {
    use eomgen_runtime::{Baumgarte, ContactDynamicsDerivatives, ImpulseDynamicsDerivatives};
    use eomgen_tests::robots::anymal_mpc::{AnymalMpc, AnymalMpcLink};
    let robot = AnymalMpc::<f64>::default();
    let mut n = Numbers(12);
    let (mut q, mut v) = anymal_states(&mut n, STATES);
    let a = n.states::<18>(STATES, 1.0);
    spoil(&mut q, &mut v);
    let link = AnymalMpcLink::LfFoot;
    let (z6, zm) = ([0.0; 6], [[0.0; 18]; 18]);
    let mut six = vec![z6; STATES];
    robot
        .link_acceleration_batch(link, &q, &v, &a, &mut six)
        .unwrap();
    each_state("link_acceleration", &six, |i| {
        robot.link_acceleration(link, &q[i], &v[i], &a[i])
    });
    let mut poses = vec![eomgen_runtime::Pose::identity(); STATES];
    robot.link_pose_batch(link, &q, &mut poses).unwrap();
    each_state("link_pose", &poses, |i| robot.link_pose(link, &q[i]));

    let tau = n.states::<18>(STATES, 20.0);
    let zk = [[0.0; 18]; 12];
    let cdd = ContactDynamicsDerivatives {
        da_dq: zm,
        da_dv: zm,
        da_dtau: zm,
        df_dq: zk,
        df_dv: zk,
        df_dtau: zk,
    };
    let mut d = vec![cdd; STATES];
    robot
        .contact_forward_dynamics_derivatives_batch(&q, &v, &tau, &mut d)
        .unwrap();
    each_state("contact derivatives", &d, |i| {
        robot.contact_forward_dynamics_derivatives(&q[i], &v[i], &tau[i])
    });
    let idd = ImpulseDynamicsDerivatives {
        dv_dq: zm,
        dv_dv: zm,
        dimpulse_dq: zk,
        dimpulse_dv: zk,
    };
    let mut d = vec![idd; STATES];
    robot
        .impulse_dynamics_derivatives_batch(&q, &v, 0.2, &mut d)
        .unwrap();
    each_state("impulse derivatives", &d, |i| {
        robot.impulse_dynamics_derivatives(&q[i], &v[i], 0.2)
    });
    // Two feet of four, shared by every state.
    let active = [true, false, false, true];
    let (mut acc, mut f) = (vec![[0.0; 18]; STATES], vec![[0.0; 12]; STATES]);
    robot
        .contact_forward_dynamics_active_batch(&q, &v, &tau, &active, &mut acc, &mut f)
        .unwrap();
    each_state("active accelerations", &acc, |i| {
        robot
            .contact_forward_dynamics_active(&q[i], &v[i], &tau[i], &active)
            .0
    });
    each_state("active forces", &f, |i| {
        robot
            .contact_forward_dynamics_active(&q[i], &v[i], &tau[i], &active)
            .1
    });
    let reference = [eomgen_runtime::Pose::from_translation([0.3, -0.2, 0.0]); 4];
    let gains = Baumgarte::new(100.0, 20.0, reference);
    robot
        .contact_forward_dynamics_stabilized_batch(&q, &v, &tau, &active, &gains, &mut acc, &mut f)
        .unwrap();
    each_state("stabilized forces", &f, |i| {
        robot
            .contact_forward_dynamics_stabilized(&q[i], &v[i], &tau[i], &active, &gains)
            .1
    });
}

#[test]
fn link_kinematics_on_four_lanes_equals_the_scalar_code() {
    use eomgen_tests::robots::anymal_mpc::{AnymalMpc, AnymalMpcLink};
    let robot = AnymalMpc::<f64>::default();
    let wide = robot.in_lanes::<f64x4>();
    let mut n = Numbers(13);
    let (q, v) = anymal_states(&mut n, 4);
    let a = n.states::<18>(4, 1.0);
    let (ql, vl, al): ([f64x4; 19], [f64x4; 18], [f64x4; 18]) =
        (gather(&q, 0), gather(&v, 0), gather(&a, 0));
    for link in [AnymalMpcLink::Base, AnymalMpcLink::RhFoot] {
        let pose = wide.link_pose(link, &ql);
        let jac = wide.link_jacobian(link, &ql);
        let vel = wide.link_velocity(link, &ql, &vl);
        let acc = wide.link_acceleration(link, &ql, &vl, &al);
        let jdot = wide.link_jacobian_time_variation(link, &ql, &vl);
        for l in 0..4 {
            let lane6 = |x: &[f64x4; 6]| x.map(|e| e.lane(l));
            let lane_m = |m: &[[f64x4; 18]; 6]| m.map(|r| r.map(|e| e.lane(l)));
            let want = robot.link_pose(link, &q[l]);
            assert_eq!(pose.translation.map(|e| e.lane(l)), want.translation);
            assert_eq!(pose.rotation.map(|r| r.map(|e| e.lane(l))), want.rotation);
            assert_eq!(lane_m(&jac), robot.link_jacobian(link, &q[l]), "lane {l}");
            assert_eq!(lane6(&vel), robot.link_velocity(link, &q[l], &v[l]));
            let want = robot.link_acceleration(link, &q[l], &v[l], &a[l]);
            assert_eq!(lane6(&acc), want, "lane {l}");
            let want = robot.link_jacobian_time_variation(link, &q[l], &v[l]);
            assert_eq!(lane_m(&jdot), want, "lane {l}");
        }
    }
}

/// `q0`, `q1` and `v` of every state of a manifold batch.
type ManifoldStates<const NQ: usize, const NV: usize> =
    (Vec<[f64; NQ]>, Vec<[f64; NQ]>, Vec<[f64; NV]>);

/// Manifold states around `q` and `v` (states of `STATES`), each special one next to ordinary
/// ones in its vector of lanes: `q1` is `integrate(q0, v)` with its quaternions (those starting
/// at `quats`) negated in every other state, and in state 1 `q0` itself (the zero rotation:
/// series, signed zeros), in 2 `q0` negated, in 3 a rotation of about 1e-7 rad away (the
/// series of the rotation vector), in 5 one of about 3e-3 rad (the series of `V^-1` and of the
/// Jacobians) next to a NaN in `q0` of state 4 and an infinite velocity and `q1` in state 6;
/// velocities of zero angle in state 8 and of about 1e-3 rad (series) in state 9.
fn manifold_states<const NQ: usize, const NV: usize>(
    (mut q0, mut v): (Vec<[f64; NQ]>, Vec<[f64; NV]>),
    quats: &[usize],
    integrate: impl Fn(&[f64; NQ], &[f64; NV], f64) -> [f64; NQ],
) -> ManifoldStates<NQ, NV> {
    let negated = |mut q: [f64; NQ]| {
        for &w in quats {
            q[w..w + 4].iter_mut().for_each(|x| *x = -*x);
        }
        q
    };
    v[8] = [0.0; NV];
    v[9] = v[9].map(|x| 1e-3 * x);
    let mut q1: Vec<[f64; NQ]> = (0..STATES)
        .map(|i| integrate(&q0[i], &v[i], 1.0))
        .enumerate()
        .map(|(i, q)| if i % 2 == 1 { negated(q) } else { q })
        .collect();
    (q1[1], q1[2]) = (q0[1], negated(q0[2]));
    q1[3] = integrate(&q0[3], &v[3].map(|x| 1e-7 * x), 1.0);
    q1[5] = integrate(&q0[5], &v[5].map(|x| 3e-3 * x), 1.0);
    q0[4][quats.first().map_or(0, |w| w + 1)] = f64::NAN;
    (v[6][NV - 1], q1[6][NQ - 1]) = (f64::INFINITY, f64::INFINITY);
    (q0, q1, v)
}

/// The three manifold batches of `$robot` (`difference`, `integrate_jacobians`,
/// `difference_jacobians`) in `$t` against its scalar methods state by state: bit for bit,
/// `integrate_jacobians` within `$tol` (its sine and cosine: `wide`'s in `f32`). The outputs
/// start marked, so that an entry a batch leaves alone shows.
macro_rules! manifold_batches_equal_the_scalar_code {
    ($robot:expr, $t:ty, $states:expr, $tol:expr) => {{
        let robot = &$robot;
        let what = |name: &str| format!("{name} ({})", stringify!($t));
        let (q0, q1, v) = &$states;
        let (q0, q1, v) = (q0.iter(), q1.iter(), v.iter());
        let q0: Vec<_> = q0.map(|s| s.map(|x| x as $t)).collect();
        let q1: Vec<_> = q1.map(|s| s.map(|x| x as $t)).collect();
        let v: Vec<_> = v.map(|s| s.map(|x| x as $t)).collect();
        let mut d = vec![v[0].map(|_| 7.25); STATES];
        robot.difference_batch(&q0, &q1, &mut d).unwrap();
        each_state(&what("difference"), &d, |i| {
            robot.difference(&q0[i], &q1[i])
        });
        let mark = robot
            .integrate_jacobians(&q0[0], &v[0])
            .0
            .map(|r| r.map(|_| 7.25));
        let (mut a, mut b) = (vec![mark; STATES], vec![mark; STATES]);
        robot
            .integrate_jacobians_batch(&q0, &v, &mut a, &mut b)
            .unwrap();
        let want = |i: usize| robot.integrate_jacobians(&q0[i], &v[i]);
        each_state_within(&what("integrate_jacobians q"), &a, |i| want(i).0, $tol);
        each_state_within(&what("integrate_jacobians v"), &b, |i| want(i).1, $tol);
        let (mut a, mut b) = (vec![mark; STATES], vec![mark; STATES]);
        robot
            .difference_jacobians_batch(&q0, &q1, &mut a, &mut b)
            .unwrap();
        let want = |i: usize| robot.difference_jacobians(&q0[i], &q1[i]);
        each_state(&what("difference_jacobians q0"), &a, |i| want(i).0);
        each_state(&what("difference_jacobians q1"), &b, |i| want(i).1);
        let e = robot.difference_batch(&q0, &q1[1..], &mut d).unwrap_err();
        assert_eq!((e.argument, e.len, e.expected), ("q1", STATES - 1, STATES));
    }};
}

/// The manifold's batches on lanes, in `f64` and `f32`: a fixed base (the panda), a floating
/// base (anymal) and floating joints below the root (`rover_pods`), with the special states
/// of [`manifold_states`].
#[test]
fn manifold_batches_on_lanes_equal_the_scalar_code() {
    use super::joints::{quaternion_starts, rover_pods::RoverPods, rover_state};
    use eomgen_tests::robots::anymal_mpc::AnymalMpc;
    let mut n = Numbers(14);
    let vector = |q: &[f64; 9], v: &[f64; 9], t: f64| -> [f64; 9] {
        core::array::from_fn(|i| q[i] + t * v[i])
    };
    let panda = (n.states::<9>(STATES, 1.0), n.states::<9>(STATES, 1.0));
    let panda = manifold_states(panda, &[], vector);
    manifold_batches_equal_the_scalar_code!(Panda::<f64>::default(), f64, panda, 0.0);
    manifold_batches_equal_the_scalar_code!(Panda::<f32>::default(), f32, panda, 0.0);
    let anymal = AnymalMpc::<f64>::default();
    let along = |q: &[f64; 19], v: &[f64; 18], t: f64| anymal.integrate(q, v, t);
    let states = manifold_states(anymal_states(&mut n, STATES), &[3], along);
    manifold_batches_equal_the_scalar_code!(anymal, f64, states, 0.0);
    let anymal32 = AnymalMpc::<f32>::default();
    manifold_batches_equal_the_scalar_code!(anymal32, f32, states, 1e-5);
    let rover = RoverPods::<f64>::default();
    let rovers: (Vec<_>, Vec<_>) = (0..STATES as u64)
        .map(|seed| rover_state(seed + 40))
        .map(|(q, v, _)| (q, v))
        .unzip();
    let along = |q: &[f64; 21], v: &[f64; 19], t: f64| rover.integrate(q, v, t);
    let states = manifold_states(rovers, &quaternion_starts(), along);
    manifold_batches_equal_the_scalar_code!(rover, f64, states, 0.0);
}
