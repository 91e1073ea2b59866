//! `M^-1` and the forward-dynamics derivatives of a robot too large for straight-line ones,
//! through its tree at run time: the generated code unrolls the runtime's `tree` inverse for the
//! robot's tree (`emit::tree_solve`), and must compute what it computes on a branched tree
//! (anymal: a floating base's chain of six coordinates, then four legs). The generated
//! factorization rounds differently from `tree::ltdl_factor` (a reciprocal and fused
//! multiply-adds), so the two agree to rounding, not to the bit; a wrong or missing update of
//! a row would be off by far more.

use eomgen_runtime::tree::{
    ltdl_factor, ltdl_inverse_factored, ltdl_substitute, ltdl_substitute_rows,
};
use eomgen_tests::floating_reference::{flat, normwise, random_state, tangent_differences};
use eomgen_tests::robots::anymal_tree_route::AnymalTreeRoute;

const NV: usize = 18;
type Robot = AnymalTreeRoute<f64>;

/// Normwise relative agreement the unrolled passes must keep with the runtime's.
const TOLERANCE: f64 = 1e-12;

#[test]
fn the_generated_code_takes_the_tree_route() {
    let source = include_str!(concat!(env!("OUT_DIR"), "/anymal_tree_route.rs"));
    assert!(source.contains("fn ltdl_inverse_unrolled"));
    assert!(!source.contains("::eomgen_runtime::tree::ltdl_inverse_factored_into"));
}

/// `M`'s factors by the runtime's tree factorization.
fn factors(robot: &Robot, q: &[f64; NV + 1]) -> [[f64; NV]; NV] {
    let mut m = robot.mass_matrix(q);
    ltdl_factor(&mut m, &Robot::PARENTS).unwrap();
    m
}

#[test]
fn mass_matrix_inverse_is_the_runtime_one_and_inverts_m() {
    let robot = Robot::default();
    for seed in 0..6 {
        let (q, _, _) = random_state::<{ NV + 1 }, NV>(seed);
        let inverse = robot.mass_matrix_inverse(&q);
        let expected = ltdl_inverse_factored(&factors(&robot, &q), &Robot::PARENTS);
        let e = normwise(&flat(&inverse), &flat(&expected));
        assert!(e < TOLERANCE, "seed {seed}: {e:e}");
        let m = robot.mass_matrix(&q);
        let identity: [[f64; NV]; NV] = core::array::from_fn(|i| {
            core::array::from_fn(|j| (0..NV).map(|k| m[i][k] * inverse[k][j]).sum())
        });
        let unit: [[f64; NV]; NV] =
            core::array::from_fn(|i| core::array::from_fn(|j| f64::from(u8::from(i == j))));
        let e = normwise(&flat(&identity), &flat(&unit));
        assert!(e < 1e-10, "seed {seed}: |M M^-1 - I| {e:e}");
    }
}

#[test]
fn forward_dynamics_derivatives_are_the_runtime_ones() {
    let robot = Robot::default();
    for seed in 0..6 {
        let (q, v, tau) = random_state::<{ NV + 1 }, NV>(seed);
        let m = factors(&robot, &q);
        let h = robot.inverse_dynamics(&q, &v, &[0.0; NV]);
        let rhs: [f64; NV] = core::array::from_fn(|i| tau[i] - h[i]);
        let qdd = ltdl_substitute(&m, &Robot::PARENTS, &rhs);
        let (mut dq, mut dv) = robot.inverse_dynamics_derivatives(&q, &v, &qdd);
        for x in [&mut dq, &mut dv] {
            ltdl_substitute_rows(&m, &Robot::PARENTS, x);
            x.iter_mut().flatten().for_each(|e| *e = -*e);
        }
        let (gq, gv, inverse) = robot.forward_dynamics_derivatives(&q, &v, &tau);
        for (what, ours, runtime) in [("dq", gq, dq), ("dv", gv, dv)] {
            let e = normwise(&flat(&ours), &flat(&runtime));
            assert!(e < 1e-10, "seed {seed}: {what} {e:e}");
        }
        // `M^-1` from the symbolic factors of `forward_dynamics_partials`, against the one
        // from `mass_matrix`'s factors at run time: the same to rounding.
        let e = normwise(&flat(&inverse), &flat(&robot.mass_matrix_inverse(&q)));
        assert!(e < TOLERANCE, "seed {seed}: M^-1 {e:e}");
    }
}

#[test]
fn forward_dynamics_derivatives_match_central_differences() {
    let robot = Robot::default();
    let step = |q: &[f64; NV + 1], e: &[f64; NV], s: f64| robot.integrate(q, e, s);
    for seed in 1..4 {
        let (q, v, tau) = random_state::<{ NV + 1 }, NV>(seed);
        let (fd_q, fd_v) =
            tangent_differences(step, &q, &v, |q, v| robot.forward_dynamics(q, v, &tau));
        let (dq, dv, _) = robot.forward_dynamics_derivatives(&q, &v, &tau);
        for (what, ours, central) in [("d a / d q", dq, fd_q), ("d a / d v", dv, fd_v)] {
            let e = normwise(&flat(&ours), &flat(&central));
            assert!(e < 1e-6, "seed {seed}: {what} off by {e:e}");
        }
    }
}

/// `forward_dynamics_partials` against references it does not share code with: its factors
/// rebuild `M = L^T D L` (L unit lower triangular on the tree, `D` on the diagonal) as
/// `mass_matrix` gives it (checked against Pinocchio in `tests/floating.rs`), `L` has no entry
/// off the tree, and its `d tau` is `inverse_dynamics_derivatives` at the accelerations of
/// `forward_dynamics`.
#[test]
fn forward_dynamics_partials_rebuild_m_and_are_the_inverse_dynamics_derivatives() {
    let robot = Robot::default();
    for seed in 0..6 {
        let (q, v, tau) = random_state::<{ NV + 1 }, NV>(seed);
        let (dq, dv, factors) = robot.forward_dynamics_partials(&q, &v, &tau);
        let ancestor = |i: usize, j: usize| {
            let mut a = Robot::PARENTS[i];
            while let Some(p) = a {
                if p == j {
                    return true;
                }
                a = Robot::PARENTS[p];
            }
            false
        };
        let l = |i: usize, j: usize| match i.cmp(&j) {
            core::cmp::Ordering::Equal => 1.0,
            core::cmp::Ordering::Greater => factors[i][j],
            core::cmp::Ordering::Less => 0.0,
        };
        for (i, row) in factors.iter().enumerate() {
            for (j, x) in row.iter().enumerate() {
                if i != j && !ancestor(i, j) {
                    assert_eq!(*x, 0.0, "seed {seed}: L[{i}][{j}] off the tree");
                }
            }
        }
        let rebuilt: [[f64; NV]; NV] = core::array::from_fn(|i| {
            core::array::from_fn(|j| (0..NV).map(|k| l(k, i) * factors[k][k] * l(k, j)).sum())
        });
        let e = normwise(&flat(&rebuilt), &flat(&robot.mass_matrix(&q)));
        assert!(e < 1e-13, "seed {seed}: L^T D L against M {e:e}");
        let qdd = robot.forward_dynamics(&q, &v, &tau);
        let (want_q, want_v) = robot.inverse_dynamics_derivatives(&q, &v, &qdd);
        for (what, ours, want) in [("dq", dq, want_q), ("dv", dv, want_v)] {
            let e = normwise(&flat(&ours), &flat(&want));
            assert!(e < 1e-12, "seed {seed}: d tau / {what} {e:e}");
        }
    }
}
