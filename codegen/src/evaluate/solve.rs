//! The factorizations the evaluator composes at run time, as generated code does with the
//! runtime's kernels: `M^-1` times a right-hand side, `M^-1` itself and the contact problem.
//! Dense (nalgebra), with the failing pivot reported so that errors can name the joint.

use nalgebra::{DMatrix, DVector};

/// A matrix that is not positive definite: the 0-based index of its first non-positive (or
/// non-finite) pivot, and which matrix it was.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct NotPositive {
    pub(crate) pivot: usize,
    pub(crate) contact_space: bool,
}

/// The Cholesky factor `L` (`M = L L^T`) of a symmetric positive definite matrix.
pub(crate) struct Factor(DMatrix<f64>);

impl Factor {
    /// Factorizes `m` (row-major, `n x n`); `Err` with the first pivot that is not positive
    /// and finite.
    pub(crate) fn new(m: &[f64], n: usize) -> Result<Factor, usize> {
        let mut l = DMatrix::<f64>::zeros(n, n);
        for i in 0..n {
            for j in 0..=i {
                let s = m[n * i + j] - (0..j).map(|k| l[(i, k)] * l[(j, k)]).sum::<f64>();
                if i == j {
                    // NaN fails the comparison too.
                    if !(s > 0.0 && s.is_finite()) {
                        return Err(i);
                    }
                    l[(i, i)] = s.sqrt();
                } else {
                    l[(i, j)] = s / l[(j, j)];
                }
            }
        }
        Ok(Factor(l))
    }

    fn solve_columns(&self, mut b: DMatrix<f64>) -> DMatrix<f64> {
        self.0.solve_lower_triangular_mut(&mut b);
        self.0.tr_solve_lower_triangular_mut(&mut b);
        b
    }

    /// `M^-1 b`.
    pub(crate) fn solve(&self, b: &[f64]) -> Vec<f64> {
        let x = self.solve_columns(DMatrix::from_column_slice(b.len(), 1, b));
        x.iter().copied().collect()
    }

    /// `M^-1`, row-major.
    pub(crate) fn inverse(&self) -> Vec<f64> {
        let n = self.0.nrows();
        row_major(&self.solve_columns(DMatrix::identity(n, n)))
    }

    /// `M^-1 B` for `B` row-major with `cols` columns; the result row-major.
    pub(crate) fn solve_matrix(&self, b: &[f64], cols: usize) -> Vec<f64> {
        let n = self.0.nrows();
        row_major(&self.solve_columns(DMatrix::from_row_slice(n, cols, b)))
    }
}

fn row_major(m: &DMatrix<f64>) -> Vec<f64> {
    m.transpose().iter().copied().collect()
}

/// The accelerations and contact forces of `M a = rhs + J^T F`, `J a + drift = 0` (`J` row-major,
/// `K x N`), as `eomgen_runtime::contact::solve` computes them.
pub(crate) fn contact(
    m: &[f64],
    rhs: &[f64],
    j: &[f64],
    drift: &[f64],
) -> Result<(Vec<f64>, Vec<f64>), NotPositive> {
    let (n, k) = (rhs.len(), drift.len());
    let mf = Factor::new(m, n).map_err(|pivot| NotPositive {
        pivot,
        contact_space: false,
    })?;
    let jm = DMatrix::from_row_slice(k, n, j);
    let free = DVector::from_vec(mf.solve(rhs));
    // Y = M^-1 J^T, n x k.
    let y = DMatrix::from_row_slice(n, k, &mf.solve_matrix(&row_major(&jm.transpose()), k));
    let lambda = &jm * &y;
    let lf = Factor::new(&row_major(&lambda), k).map_err(|pivot| NotPositive {
        pivot,
        contact_space: true,
    })?;
    let b: Vec<f64> = (0..k)
        .map(|r| -(drift[r] + jm.row(r).dot(&free.transpose())))
        .collect();
    let f = DVector::from_vec(lf.solve(&b));
    let a = free + y * &f;
    Ok((a.iter().copied().collect(), f.iter().copied().collect()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_and_inverts_a_positive_definite_matrix() {
        let m = [4.0, 2.0, 0.4, 2.0, 3.0, 0.5, 0.4, 0.5, 2.0];
        let f = Factor::new(&m, 3).unwrap();
        let x = [1.0, -2.0, 0.5];
        let b: Vec<f64> = (0..3)
            .map(|i| (0..3).map(|j| m[3 * i + j] * x[j]).sum())
            .collect();
        for (got, want) in f.solve(&b).iter().zip(x) {
            assert!((got - want).abs() < 1e-14);
        }
        let inv = f.inverse();
        for i in 0..3 {
            for j in 0..3 {
                let e: f64 = (0..3).map(|k| m[3 * i + k] * inv[3 * k + j]).sum();
                assert!((e - f64::from(u8::from(i == j))).abs() < 1e-14);
            }
        }
    }

    #[test]
    fn names_the_failing_pivot() {
        assert_eq!(Factor::new(&[1.0, 2.0, 2.0, 1.0], 2).err(), Some(1));
        assert_eq!(Factor::new(&[0.0, 0.0, 0.0, 1.0], 2).err(), Some(0));
        assert_eq!(Factor::new(&[1.0, 0.0, 0.0, f64::NAN], 2).err(), Some(1));
    }

    #[test]
    fn a_held_point_mass_carries_its_weight() {
        let (a, f) = contact(
            &[1.0, 0.0, 0.0, 1.0],
            &[0.0, -9.81],
            &[1.0, 0.0, 0.0, 1.0],
            &[0.0, 0.0],
        )
        .unwrap();
        assert!(a.iter().all(|x| x.abs() < 1e-15));
        assert!((f[1] - 9.81).abs() < 1e-12 && f[0].abs() < 1e-15);
        // Two identical rows: the contact-space matrix is singular at its second pivot.
        let err = contact(
            &[1.0, 0.0, 0.0, 1.0],
            &[0.0, 0.0],
            &[0.0, 1.0, 0.0, 1.0],
            &[0.0, 0.0],
        );
        assert_eq!(
            err.unwrap_err(),
            NotPositive {
                pivot: 1,
                contact_space: true
            }
        );
    }
}
