//! Function bodies split into non-inlined blocks (`Builder::max_function_ops`) compute what the
//! same robots generated whole compute, bit for bit: the blocks hold the same operations in the
//! same expressions, and only pass intermediate values through memory.

use eomgen_runtime::prelude::*;
use eomgen_tests::robots::anymal::Anymal;
use eomgen_tests::robots::anymal_split::{AnymalSplit, AnymalSplitLink};
use eomgen_tests::robots::ur5_derivatives::Ur5Derivatives;
use eomgen_tests::robots::ur5_split::Ur5Split;
use eomgen_tests::Lcg;

/// Asserts two results equal bit for bit (NaN equal to NaN).
fn same<const N: usize>(what: &str, a: &[f64; N], b: &[f64; N]) {
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        assert!(
            x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()),
            "{what}[{i}]: split {x:e}, whole {y:e}"
        );
    }
}

fn same_rows<const R: usize, const C: usize>(what: &str, a: &[[f64; C]; R], b: &[[f64; C]; R]) {
    for (r, (x, y)) in a.iter().zip(b).enumerate() {
        same(&format!("{what}[{r}]"), x, y);
    }
}

#[test]
fn split_derivatives_equal_whole_ones() {
    let (split, whole) = (Ur5Split::<f64>::default(), Ur5Derivatives::<f64>::default());
    // Splitting at 60 operations gives many blocks to each derivative function.
    let source = include_str!(concat!(env!("OUT_DIR"), "/ur5_split.rs"));
    assert!(source.contains("fn inverse_dynamics_derivatives_block_9("));
    assert!(source.contains("fn forward_dynamics_derivatives_block_9("));
    let mut rng = Lcg(7);
    for _ in 0..20 {
        let mut v = || core::array::from_fn::<f64, 6, _>(|_| rng.uniform(-3.0, 3.0));
        let (q, qd, qdd) = (v(), v(), v());
        same(
            "tau",
            &split.inverse_dynamics(&q, &qd, &qdd),
            &whole.inverse_dynamics(&q, &qd, &qdd),
        );
        let (a, b) = (
            split.inverse_dynamics_derivatives(&q, &qd, &qdd),
            whole.inverse_dynamics_derivatives(&q, &qd, &qdd),
        );
        same_rows("dtau_dq", &a.0, &b.0);
        same_rows("dtau_dqd", &a.1, &b.1);
        let (a, b) = (
            split.forward_dynamics_derivatives(&q, &qd, &qdd),
            whole.forward_dynamics_derivatives(&q, &qd, &qdd),
        );
        same_rows("dqdd_dq", &a.0, &b.0);
        same_rows("dqdd_dqd", &a.1, &b.1);
        same_rows("dqdd_dtau", &a.2, &b.2);
        same_rows(
            "M^-1",
            &split.mass_matrix_inverse(&q),
            &whole.mass_matrix_inverse(&q),
        );
    }
    // A non-finite input stays in its lanes of the result, as in the whole function.
    let mut q = [0.3; 6];
    q[2] = f64::NAN;
    let (a, b) = (
        split.inverse_dynamics_derivatives(&q, &[0.1; 6], &[0.2; 6]),
        whole.inverse_dynamics_derivatives(&q, &[0.1; 6], &[0.2; 6]),
    );
    same_rows("dtau_dq (NaN q)", &a.0, &b.0);
}

#[test]
fn split_floating_base_equals_whole_one() {
    let (split, whole) = (AnymalSplit::<f64>::default(), Anymal::<f64>::default());
    let mut rng = Lcg(11);
    for _ in 0..20 {
        let mut q: [f64; 19] = core::array::from_fn(|_| rng.uniform(-1.0, 1.0));
        let norm = q[3..7].iter().map(|x| x * x).sum::<f64>().sqrt();
        q[3..7].iter_mut().for_each(|x| *x /= norm);
        let mut v = || core::array::from_fn::<f64, 18, _>(|_| rng.uniform(-2.0, 2.0));
        let (qd, a) = (v(), v());
        same_rows("M", &split.mass_matrix(&q), &whole.mass_matrix(&q));
        same("g", &split.gravity(&q), &whole.gravity(&q));
        same("b", &split.bias(&q, &qd), &whole.bias(&q, &qd));
        same(
            "tau",
            &split.inverse_dynamics(&q, &qd, &a),
            &whole.inverse_dynamics(&q, &qd, &a),
        );
        same(
            "qdd",
            &split.forward_dynamics(&q, &qd, &a),
            &whole.forward_dynamics(&q, &qd, &a),
        );
        same_rows(
            "C",
            &split.coriolis_matrix(&q, &qd),
            &whole.coriolis_matrix(&q, &qd),
        );
        same_rows("A_g", &split.centroidal_map(&q), &whole.centroidal_map(&q));
        same_rows(
            "J_c",
            &split.contact_jacobian(&q),
            &whole.contact_jacobian(&q),
        );
        same(
            "drift",
            &split.contact_drift(&q, &qd),
            &whole.contact_drift(&q, &qd),
        );
        let (x, y) = (
            split.contact_forward_dynamics(&q, &qd, &a),
            whole.contact_forward_dynamics(&q, &qd, &a),
        );
        same("contact qdd", &x.0, &y.0);
        same("contact forces", &x.1, &y.1);
        let (ts, tw) = (split.kinetic_energy(&q, &qd), whole.kinetic_energy(&q, &qd));
        assert_eq!(ts.to_bits(), tw.to_bits(), "kinetic energy");
        for (link, other) in AnymalSplitLink::ALL
            .iter()
            .zip(eomgen_tests::robots::anymal::AnymalLink::ALL)
        {
            same_rows(
                "link jacobian",
                &split.link_jacobian(*link, &q),
                &whole.link_jacobian(other, &q),
            );
        }
    }
}
