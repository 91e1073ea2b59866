//! Operation counts against the number of joints: inverse dynamics (customized symbolic
//! Newton-Euler) must grow linearly on a serial chain.

#[path = "support/chain.rs"]
mod chain;

use eomgen::cas::Program;
use eomgen::dynamics::Derivation;

fn inverse_dynamics_ops(n: usize) -> usize {
    let urdf = chain::serial_chain_urdf(n);
    let model = eomgen::urdf::load_str(&urdf, "chain.urdf", &Default::default()).unwrap();
    let d = Derivation::new(&model);
    Program::new(&d.graph, &d.fast.tau.1).ops().total()
}

#[test]
fn inverse_dynamics_operations_grow_linearly() {
    let ops: Vec<usize> = (4..=12).map(inverse_dynamics_ops).collect();
    let steps: Vec<i64> = ops.windows(2).map(|w| w[1] as i64 - w[0] as i64).collect();
    // Every joint past the first few adds the same work: constant steps, within 5%.
    let typical = steps[steps.len() - 1];
    for (k, s) in steps.iter().enumerate() {
        assert!(
            (s - typical).abs() * 20 <= typical,
            "step {} of {:?} in {:?}",
            k,
            steps,
            ops
        );
    }
    // Twelve more joints cost twelve such steps, not more.
    let extra = inverse_dynamics_ops(24) as i64 - ops[ops.len() - 1] as i64;
    assert!(
        (extra - 12 * typical).abs() * 20 <= 12 * typical,
        "24 joints: +{extra} over 12, step {typical}"
    );
}

#[test]
fn the_synthetic_chain_is_a_valid_robot_at_every_length_up_to_the_default_limit() {
    for n in [1, 27, 40, eomgen::DEFAULT_MAX_DOF] {
        let urdf = chain::serial_chain_urdf(n);
        let model = eomgen::urdf::load_str(&urdf, "chain.urdf", &Default::default())
            .unwrap_or_else(|e| panic!("chain of {n}: {e}"));
        assert_eq!(model.dof(), n);
    }
}
