//! The fixed-size SPD solvers: accuracy on random SPD systems, and errors (never panics) on
//! everything else.
#![allow(clippy::needless_range_loop)] // index loops read like the math

use eomgen_runtime::{solve_spd, solve_spd_or_nan, Cholesky, FactorError, Ldlt, Real};
use proptest::prelude::*;

/// `A Aᵀ + n I`, symmetric positive definite with eigenvalues >= n.
fn spd<T: Real, const N: usize>(a: &[[T; N]; N]) -> [[T; N]; N] {
    let mut m = [[T::zero(); N]; N];
    for i in 0..N {
        for j in 0..N {
            for k in 0..N {
                m[i][j] += a[i][k] * a[j][k];
            }
        }
        m[i][i] += T::from_f64(N as f64);
    }
    m
}

fn mat_vec<T: Real, const N: usize>(m: &[[T; N]; N], x: &[T; N]) -> [T; N] {
    let mut y = [T::zero(); N];
    for i in 0..N {
        for j in 0..N {
            y[i] += m[i][j] * x[j];
        }
    }
    y
}

fn inf_norm<T: Real, const N: usize>(x: &[T; N]) -> f64 {
    x.iter().map(|v| v.to_f64().abs()).fold(0.0, f64::max)
}

/// `‖M x - b‖∞ / (‖M‖∞ ‖x‖∞ + ‖b‖∞)`, computed in f64.
fn relative_residual<T: Real, const N: usize>(m: &[[T; N]; N], x: &[T; N], b: &[T; N]) -> f64 {
    let m64: [[f64; N]; N] = core::array::from_fn(|i| core::array::from_fn(|j| m[i][j].to_f64()));
    let x64: [f64; N] = core::array::from_fn(|i| x[i].to_f64());
    let b64: [f64; N] = core::array::from_fn(|i| b[i].to_f64());
    let r = mat_vec(&m64, &x64);
    let r: [f64; N] = core::array::from_fn(|i| r[i] - b64[i]);
    let m_norm = m64
        .iter()
        .map(|row| row.iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    inf_norm(&r) / (m_norm * inf_norm(&x64) + inf_norm(&b64))
}

/// Solves with all three entry points and checks the residuals and factors.
fn check_solves<T: Real, const N: usize>(
    a: &[[T; N]; N],
    b: &[T; N],
    tol: f64,
) -> Result<(), TestCaseError> {
    let m = spd(a);
    let ldlt = Ldlt::new(m).map_err(|e| TestCaseError::fail(format!("ldlt: {e}")))?;
    let chol = Cholesky::new(m).map_err(|e| TestCaseError::fail(format!("cholesky: {e}")))?;
    let x1 = ldlt.solve(b);
    let x2 = chol.solve(b);
    let x3 = solve_spd(&m, b).map_err(|e| TestCaseError::fail(format!("solve_spd: {e}")))?;
    prop_assert_eq!(x1, x3);
    prop_assert_eq!(solve_spd_or_nan(&m, b), x3);
    let mut x4 = *b;
    chol.solve_in_place(&mut x4);
    prop_assert_eq!(x2, x4);
    for x in [&x1, &x2] {
        let r = relative_residual(&m, x, b);
        prop_assert!(r <= tol, "residual {:e} > {:e} (N = {})", r, tol, N);
    }

    // The factors reproduce M: L Lᵀ and L D Lᵀ.
    let l = chol.l();
    let lu = ldlt.l();
    let d = ldlt.d();
    let scale = inf_norm(&core::array::from_fn::<f64, N, _>(|i| m[i][i].to_f64()));
    for i in 0..N {
        prop_assert!(d[i] > T::zero());
        prop_assert_eq!(lu[i][i], T::one());
        for j in 0..N {
            if j > i {
                prop_assert_eq!(l[i][j], T::zero());
                prop_assert_eq!(lu[i][j], T::zero());
            }
            let mut llt = 0.0;
            let mut ldlt_ij = 0.0;
            for k in 0..N {
                llt += l[i][k].to_f64() * l[j][k].to_f64();
                ldlt_ij += lu[i][k].to_f64() * d[k].to_f64() * lu[j][k].to_f64();
            }
            prop_assert!((llt - m[i][j].to_f64()).abs() <= tol * scale);
            prop_assert!((ldlt_ij - m[i][j].to_f64()).abs() <= tol * scale);
        }
    }
    let det_c = chol.determinant().to_f64();
    let det_l = ldlt.determinant().to_f64();
    prop_assert!((det_c - det_l).abs() <= 1e3 * tol * det_l.abs());
    Ok(())
}

fn arb_matrix<const N: usize>() -> impl Strategy<Value = [[f64; N]; N]> {
    prop::array::uniform(prop::array::uniform(-1.0..1.0_f64))
}

fn arb_vector<const N: usize>() -> impl Strategy<Value = [f64; N]> {
    prop::array::uniform(-10.0..10.0_f64)
}

fn to_f32<const N: usize>(a: &[[f64; N]; N]) -> [[f32; N]; N] {
    core::array::from_fn(|i| core::array::from_fn(|j| a[i][j] as f32))
}

/// Errors must name the first bad pivot; for a matrix whose leading `k×k` block is SPD and whose
/// pivot `k` is bad, that is `k`.
fn expect_err<const N: usize>(
    m: &[[f64; N]; N],
    expected: FactorError,
) -> Result<(), TestCaseError> {
    prop_assert_eq!(Ldlt::new(*m).err(), Some(expected));
    prop_assert_eq!(Cholesky::new(*m).err(), Some(expected));
    prop_assert_eq!(solve_spd(m, &[1.0; N]).err(), Some(expected));
    prop_assert!(solve_spd_or_nan(m, &[1.0; N]).iter().all(|x| x.is_nan()));
    let m32 = to_f32(m);
    prop_assert_eq!(Ldlt::new(m32).err(), Some(expected));
    prop_assert_eq!(Cholesky::new(m32).err(), Some(expected));
    Ok(())
}

fn arb_non_finite() -> impl Strategy<Value = f64> {
    prop_oneof![Just(f64::NAN), Just(f64::INFINITY), Just(f64::NEG_INFINITY)]
}

macro_rules! spd_tests {
    ($($name:ident: $n:literal),* $(,)?) => {$(
        mod $name {
            use super::*;
            proptest! {
                #[test]
                fn solves_random_spd_systems(a in arb_matrix::<$n>(), b in arb_vector::<$n>()) {
                    check_solves(&a, &b, 1e-14)?;
                    check_solves(&to_f32(&a), &core::array::from_fn(|i| b[i] as f32), 1e-6)?;
                }

                #[test]
                fn f32_solution_is_close_to_f64(a in arb_matrix::<$n>(), b in arb_vector::<$n>()) {
                    let x64 = solve_spd(&spd(&a), &b).unwrap();
                    let x32 = solve_spd(&spd(&to_f32(&a)), &core::array::from_fn(|i| b[i] as f32)).unwrap();
                    for i in 0..$n {
                        prop_assert!((f64::from(x32[i]) - x64[i]).abs() <= 1e-5 * inf_norm(&x64));
                    }
                }

                #[test]
                fn negative_diagonal_fails_at_its_pivot(a in arb_matrix::<$n>(), k in 0usize..$n, neg in 0.0..10.0_f64) {
                    let mut m = spd(&a);
                    m[k][k] = -neg; // pivot k <= m[k][k] <= 0, pivots before k unchanged
                    expect_err(&m, FactorError::NotPositiveDefinite { pivot: k })?;
                }

                #[test]
                fn negative_definite_fails_at_pivot_0(a in arb_matrix::<$n>()) {
                    let m = spd(&a).map(|row| row.map(|x| -x));
                    expect_err(&m, FactorError::NotPositiveDefinite { pivot: 0 })?;
                }

                #[test]
                fn non_finite_in_lower_triangle_fails_at_its_row(
                    a in arb_matrix::<$n>(), i in 0usize..$n, j in 0usize..$n, bad in arb_non_finite(),
                ) {
                    let (i, j) = (i.max(j), i.min(j));
                    let mut m = spd(&a);
                    m[i][j] = bad;
                    m[j][i] = bad;
                    expect_err(&m, FactorError::NonFinite { pivot: i })?;
                }

                #[test]
                fn strict_upper_triangle_is_ignored(
                    a in arb_matrix::<$n>(), i in 0usize..$n, j in 0usize..$n, b in arb_vector::<$n>(),
                ) {
                    let m = spd(&a);
                    let mut junk = m;
                    if i < j {
                        junk[i][j] = f64::NAN;
                    }
                    prop_assert_eq!(solve_spd(&junk, &b), solve_spd(&m, &b));
                    prop_assert_eq!(Cholesky::new(junk), Cholesky::new(m));
                }

                #[test]
                fn arbitrary_matrices_never_panic(
                    m in prop::array::uniform::<_, $n>(prop::array::uniform::<_, $n>(proptest::num::f64::ANY)),
                    b in prop::array::uniform::<_, $n>(proptest::num::f64::ANY),
                ) {
                    let _ = solve_spd_or_nan(&m, &b);
                    let _ = solve_spd(&to_f32(&m), &core::array::from_fn(|i| b[i] as f32));
                    if let Ok(c) = Cholesky::new(m) {
                        prop_assert!(c.l().iter().flatten().all(|x| x.is_finite()));
                        let _ = c.solve(&b);
                    }
                    if let Ok(f) = Ldlt::new(m) {
                        prop_assert!(f.l().iter().flatten().all(|x| x.is_finite()));
                        prop_assert!(f.d().iter().all(|x| x.is_finite() && *x > 0.0));
                        let _ = f.solve(&b);
                    }
                }

                #[test]
                fn scaled_spd_matrices_never_panic(a in arb_matrix::<$n>(), e in -320i32..320, b in arb_vector::<$n>()) {
                    let s = 10f64.powi(e);
                    let m = spd(&a).map(|row| row.map(|x| x * s));
                    match solve_spd(&m, &b) {
                        Ok(x) => prop_assert!(Ldlt::new(m).is_ok() && x.len() == $n),
                        Err(err) => prop_assert!(err.pivot() < $n),
                    }
                    let m32 = to_f32(&m);
                    if let Err(err) = solve_spd(&m32, &[1.0; $n]) {
                        prop_assert!(err.pivot() < $n);
                    }
                }
            }
        }
    )*};
}

spd_tests! {
    n1: 1,
    n2: 2,
    n3: 3,
    n6: 6,
    n7: 7,
    n9: 9,
}

#[test]
fn empty_system() {
    let f = Ldlt::<f64, 0>::new([]).unwrap();
    assert_eq!(f.solve(&[]), []);
    assert_eq!(f.determinant(), 1.0);
    assert_eq!(Cholesky::<f32, 0>::new([]).unwrap().solve(&[]), []);
}

#[test]
fn singular_matrices_fail_at_the_zero_pivot() {
    // v vᵀ with v = (1, 2, 3): rank 1, pivot 1 is exactly zero
    let v = [1.0_f64, 2.0, 3.0];
    let m: [[f64; 3]; 3] = core::array::from_fn(|i| core::array::from_fn(|j| v[i] * v[j]));
    assert_eq!(
        Ldlt::new(m).err(),
        Some(FactorError::NotPositiveDefinite { pivot: 1 })
    );
    assert_eq!(
        Cholesky::new(m).err(),
        Some(FactorError::NotPositiveDefinite { pivot: 1 })
    );
    assert_eq!(
        solve_spd(&[[0.0_f32; 3]; 3], &[1.0; 3]),
        Err(FactorError::NotPositiveDefinite { pivot: 0 })
    );
    let diag = [
        [1.0, 0.0, 0.0, 0.0],
        [0.0, 2.0, 0.0, 0.0],
        [0.0, 0.0, -3.0, 0.0],
        [0.0, 0.0, 0.0, 4.0],
    ];
    assert_eq!(
        solve_spd(&diag, &[1.0; 4]),
        Err(FactorError::NotPositiveDefinite { pivot: 2 })
    );
}

#[test]
fn diagonal_and_small_systems() {
    let diag = [[2.0, 0.0, 0.0], [0.0, 4.0, 0.0], [0.0, 0.0, 8.0]];
    assert_eq!(solve_spd(&diag, &[2.0, 2.0, 2.0]), Ok([1.0, 0.5, 0.25]));
    assert_eq!(Ldlt::new(diag).unwrap().determinant(), 64.0);
    assert!((Cholesky::new(diag).unwrap().determinant() - 64.0).abs() < 1e-12); // via sqrt(2)²
    assert_eq!(Ldlt::new(diag).unwrap().d(), &[2.0, 4.0, 8.0]);
}

#[test]
fn errors_display_and_name_the_pivot() {
    let e = FactorError::NotPositiveDefinite { pivot: 3 };
    assert_eq!(e.pivot(), 3);
    assert_eq!(
        e.to_string(),
        "matrix is not positive definite: pivot 3 is zero or negative"
    );
    let e = FactorError::NonFinite { pivot: 0 };
    assert_eq!(e.pivot(), 0);
    assert!(e
        .to_string()
        .contains("pivot or solution component 0 is not finite"));
}

#[test]
fn errors_name_the_first_bad_pivot_in_f32() {
    let m = [[1.0_f32, 0.0, 0.0], [0.0, f32::NAN, 0.0], [0.0, 0.0, -1.0]];
    assert_eq!(
        Ldlt::new(m).err(),
        Some(FactorError::NonFinite { pivot: 1 })
    );
    assert_eq!(
        Cholesky::new(m).err(),
        Some(FactorError::NonFinite { pivot: 1 })
    );
}
