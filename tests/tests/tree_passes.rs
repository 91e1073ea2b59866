//! The passes over `M`'s tree factors that a robot with contact or impulse derivatives
//! generates (`impl TreePasses`, `emit::tree_solve`) compute what the runtime's loops over
//! the tree compute (`tree::Walked`), to the bit: the same operations in the same order, the
//! walks of the tree done at generation time. anymal's tree branches (a floating base's chain
//! of six coordinates, then four legs), so a row updated from a wrong subtree or ancestor, or
//! an update missing, shows.

use eomgen_runtime::prelude::*;
use eomgen_runtime::tree::{ltdl_factor, Walked};
use eomgen_tests::floating_reference::random_state;
use eomgen_tests::robots::anymal::Anymal;
use eomgen_tests::robots::anymal_mpc::AnymalMpc;

const NV: usize = 18;
type Robot = AnymalMpc<f64>;

/// `M`'s factors at a random configuration (`M` from the robot generated whole: the same
/// tree).
fn factors(seed: u64) -> [[f64; NV]; NV] {
    let (q, _, _) = random_state::<{ NV + 1 }, NV>(seed);
    let mut m = Anymal::<f64>::default().mass_matrix(&q);
    ltdl_factor(&mut m, &Robot::PARENTS).unwrap();
    m
}

/// Every entry of `x` within 1e-9 of the identity's.
fn assert_identity(x: &[[f64; NV]; NV], what: &str) {
    for (i, row) in x.iter().enumerate() {
        for (j, v) in row.iter().enumerate() {
            let unit = f64::from(u8::from(i == j));
            assert!((v - unit).abs() < 1e-9, "{what}: [{i}][{j}] = {v}");
        }
    }
}

/// `C` columns of numbers in [-1, 1].
fn columns<const C: usize>(seed: u64) -> [[f64; C]; NV] {
    let (_, v, a) = random_state::<{ NV + 1 }, NV>(seed + 100);
    core::array::from_fn(|i| core::array::from_fn(|j| v[(i + j) % NV] - a[(i * j) % NV]))
}

fn substitutions_agree<const C: usize>() {
    for seed in 0..4 {
        let m = factors(seed);
        let (mut unrolled, mut walked) = (columns::<C>(seed), columns::<C>(seed));
        <Robot as TreePasses<f64, NV>>::substitute_rows(&m, &Robot::PARENTS, &mut unrolled);
        <Walked as TreePasses<f64, NV>>::substitute_rows(&m, &Robot::PARENTS, &mut walked);
        assert_eq!(unrolled, walked, "seed {seed}, {C} columns");
        assert_ne!(
            unrolled,
            columns::<C>(seed),
            "seed {seed}: nothing substituted"
        );
    }
}

/// Independently of the runtime: `M^-1` times `M`'s own columns is the identity.
#[test]
fn the_substitution_of_m_gives_the_identity() {
    for seed in 0..4 {
        let (q, _, _) = random_state::<{ NV + 1 }, NV>(seed);
        let mut x = Anymal::<f64>::default().mass_matrix(&q);
        <Robot as TreePasses<f64, NV>>::substitute_rows(&factors(seed), &Robot::PARENTS, &mut x);
        assert_identity(&x, &format!("seed {seed}: M^-1 M"));
    }
}

#[test]
fn the_substitution_of_many_columns_is_the_runtime_one() {
    // The contact rows (K = 12) and the derivatives' columns (N = 18), and one column.
    substitutions_agree::<12>();
    substitutions_agree::<NV>();
    substitutions_agree::<1>();
}

#[test]
fn the_inverse_is_the_runtime_one_and_inverts_m() {
    for seed in 0..4 {
        let m = factors(seed);
        let (mut unrolled, mut walked) = ([[f64::NAN; NV]; NV], [[0.0; NV]; NV]);
        <Robot as TreePasses<f64, NV>>::inverse_into(&m, &Robot::PARENTS, &mut unrolled);
        <Walked as TreePasses<f64, NV>>::inverse_into(&m, &Robot::PARENTS, &mut walked);
        assert_eq!(unrolled, walked, "seed {seed}");
        let (q, _, _) = random_state::<{ NV + 1 }, NV>(seed);
        let mass = Anymal::<f64>::default().mass_matrix(&q);
        let product: [[f64; NV]; NV] = core::array::from_fn(|i| {
            core::array::from_fn(|j| (0..NV).map(|k| mass[i][k] * unrolled[k][j]).sum())
        });
        assert_identity(&product, &format!("seed {seed}: M M^-1"));
    }
}
