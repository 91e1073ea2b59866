//! The tree kernels: the sparse `L^T D L` solve against the dense Cholesky solve, on a chain
//! (dense) and branched trees (zeros between branches, subtrees interleaved), its failures, and
//! the inverse and the many-column solve built on the same factors.

// Matrix code reads best with explicit indices.
#![allow(clippy::needless_range_loop)]

use eomgen_runtime::tree::{
    ltdl_factor, ltdl_inverse, ltdl_solve, ltdl_substitute, ltdl_substitute_rows,
};
use eomgen_runtime::{solve_spd, FactorError};
use proptest::prelude::*;

/// `A^T A + N I` restricted to a tree's sparsity: entries between joints on different branches
/// set to zero, then made diagonally dominant so that it stays positive definite.
fn tree_spd<const N: usize>(a: &[[f64; N]; N], parent: &[Option<usize>; N]) -> [[f64; N]; N] {
    let related = |i: usize, j: usize| {
        let on_path = |from: usize, to: usize| {
            let mut k = Some(from);
            while let Some(x) = k {
                if x == to {
                    return true;
                }
                k = parent[x];
            }
            false
        };
        on_path(i, j) || on_path(j, i)
    };
    let mut m = [[0.0; N]; N];
    for i in 0..N {
        for j in 0..N {
            if related(i, j) {
                m[i][j] = (0..N).map(|k| a[k][i] * a[k][j]).sum();
            }
        }
    }
    for i in 0..N {
        let off: f64 = (0..N).filter(|&j| j != i).map(|j| m[i][j].abs()).sum();
        m[i][i] += off + 1.0;
    }
    m
}

const BRANCHED: [Option<usize>; 6] = [None, Some(0), Some(1), Some(0), Some(3), Some(0)];
const CHAIN: [Option<usize>; 6] = [None, Some(0), Some(1), Some(2), Some(3), Some(4)];
/// Two branches whose coordinates alternate: the subtree of 1 is {1, 3, 5}, of 2 is {2, 4}.
const INTERLEAVED: [Option<usize>; 6] = [None, Some(0), Some(0), Some(1), Some(2), Some(3)];

proptest! {
    #[test]
    fn matches_the_dense_solve(a in prop::array::uniform6(prop::array::uniform6(-2.0..2.0_f64)),
                               b in prop::array::uniform6(-5.0..5.0_f64)) {
        for parent in [BRANCHED, CHAIN] {
            let m = tree_spd(&a, &parent);
            let dense = solve_spd(&m, &b).unwrap();
            let mut f = m;
            let sparse = ltdl_solve(&mut f, &parent, &b).unwrap();
            for i in 0..6 {
                prop_assert!((dense[i] - sparse[i]).abs() <= 1e-10 * (1.0 + dense[i].abs()),
                    "{parent:?}: {dense:?} vs {sparse:?}");
            }
        }
    }
}

proptest! {
    #[test]
    fn the_inverse_is_symmetric_and_inverts(
        a in prop::array::uniform6(prop::array::uniform6(-2.0..2.0_f64))) {
        for parent in [BRANCHED, CHAIN, INTERLEAVED] {
            let m = tree_spd(&a, &parent);
            let mut f = m;
            let inv = ltdl_inverse(&mut f, &parent).unwrap();
            for i in 0..6 {
                for j in 0..6 {
                    prop_assert_eq!(inv[i][j], inv[j][i]);
                    let p: f64 = (0..6).map(|k| m[i][k] * inv[k][j]).sum();
                    let e = if i == j { 1.0 } else { 0.0 };
                    prop_assert!((p - e).abs() <= 1e-12, "{parent:?}: (M M^-1)[{i}][{j}] = {p}");
                }
            }
        }
    }

    #[test]
    fn many_columns_solve_like_one(
        a in prop::array::uniform6(prop::array::uniform6(-2.0..2.0_f64)),
        b in prop::array::uniform6(prop::array::uniform3(-5.0..5.0_f64))) {
        for parent in [BRANCHED, CHAIN, INTERLEAVED] {
            let mut f = tree_spd(&a, &parent);
            ltdl_factor(&mut f, &parent).unwrap();
            let mut x = b;
            ltdl_substitute_rows(&f, &parent, &mut x);
            for c in 0..3 {
                let col = ltdl_substitute(&f, &parent, &core::array::from_fn(|i| b[i][c]));
                for i in 0..6 {
                    prop_assert!((x[i][c] - col[i]).abs() <= 1e-12 * (1.0 + col[i].abs()),
                        "{parent:?}: column {c}: {x:?} vs {col:?}");
                }
            }
        }
    }
}

#[test]
fn failures_name_their_pivot() {
    let a = [[0.5; 6]; 6];
    let m = tree_spd(&a, &BRANCHED);
    let mut bad = m;
    bad[4][4] = -1.0;
    assert_eq!(
        ltdl_solve(&mut bad, &BRANCHED, &[1.0; 6]),
        Err(FactorError::NotPositiveDefinite { pivot: 4 })
    );
    let mut bad = m;
    bad[2][2] = f64::NAN;
    assert_eq!(
        ltdl_solve(&mut bad, &BRANCHED, &[1.0; 6]),
        Err(FactorError::NonFinite { pivot: 2 })
    );
    let mut ok = m;
    let mut b = [1.0; 6];
    b[1] = f64::INFINITY;
    assert!(matches!(
        ltdl_solve(&mut ok, &BRANCHED, &b),
        Err(FactorError::NonFinite { .. })
    ));
    // A parent after its child is not a tree in joint order: refused, not indexed.
    let mut any = m;
    let wrong = [Some(1), None, Some(1), Some(0), Some(3), Some(0)];
    assert!(ltdl_solve(&mut any, &wrong, &[1.0; 6]).is_err());
}
