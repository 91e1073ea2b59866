//! Contact forward dynamics and impulse dynamics as straight-line programs: the accelerations
//! and contact forces of `M a + h = tau + J^T f`, `J a + drift = 0`, and the velocity change
//! and impulses of `M dv = J^T p`, `J (v + dv) = -e J v`, with both factorizations on the CAS.
//!
//! The route is the run-time one (`eomgen_runtime::contact::solve_factored_active_by`) written
//! out for the robot: `M = L^T D L` over the joint tree, `W = L^-T J^T`, the contact-space
//! matrix `Lambda = W^T D^-1 W` (`J M^-1 J^T`), `f = -Lambda^-1 (drift + J M^-1 (tau - h))`
//! and `a = M^-1 (tau - h + J^T f)`, where `J M^-1 x = W^T D^-1 (L^-T x)` and
//! `a = L^-1 D^-1 (L^-T (tau - h) + W f)`: half a substitution is shared and the accelerations
//! without contacts are never formed. Written out, the zeros of `J` and `W` (a leg joint moves
//! its own foot only) are not multiplied, and the kinematics that `M`, `h`, `J` and the drift
//! share are computed once.
//!
//! `Lambda` is factorized as `L^T D L` too (no square roots), eliminating its rows first to
//! last as the run-time Cholesky factorization does, so that its pivots fail in the same
//! order: `D_k` is the square of the Cholesky factor's `k`-th diagonal entry.

use super::ltdl::Factors;
use crate::cas::{Graph, Id, Program};
use crate::kinematics::M3;

/// A straight-line contact or impulse dynamics.
pub(crate) struct FlatContact {
    /// The accelerations (or velocity changes, `N`), then the contact forces (or impulses,
    /// `K`).
    pub outputs: Vec<Id>,
    /// The pivots of `M`'s factorization (`N`), then those of `Lambda`'s (`K`): all positive
    /// exactly when `M` is positive definite and `J` has full row rank.
    pub pivots: Vec<Id>,
}

impl FlatContact {
    /// Whether the program (its outputs and pivots) holds at most `max_ops` operations.
    pub(crate) fn fits(&self, g: &Graph, max_ops: usize) -> bool {
        let all: Vec<Id> = self.outputs.iter().chain(&self.pivots).copied().collect();
        Program::new(g, &all).ops().total() <= max_ops
    }
}

/// Contact forward dynamics from `M` (over the coordinate tree `parents`), `h = b + G + F`,
/// the contact Jacobian `j` (`K` rows of `N`) and its drift `Jdot qd` (`K`), both in the axes
/// that `axes` turns into the world's (each three rows; the identity when `None`).
///
/// In a floating base's axes, `J` and the drift do not depend on the base's orientation: the
/// base's columns of `J` are `(I, -[p]x)` and nothing is turned into the world. `J M^-1 J^T`
/// turns as `R Lambda R^T` and the right-hand side as `R b`, so the forces are `R` times
/// those solved in base axes and `J^T f` is the same either way.
pub(crate) fn contact_forward_dynamics(
    g: &mut Graph,
    parents: &[Option<usize>],
    m: &[Vec<Id>],
    h: &[Id],
    (j, drift): (&[Vec<Id>], &[Id]),
    axes: Option<&M3>,
) -> FlatContact {
    let n = m.len();
    let old_products = g.set_product_flattening(false);
    let space = Space::new(g, parents, m, j);
    let rhs: Vec<Id> = (0..n)
        .map(|i| {
            let tau = g.tau(i);
            g.sub(tau, h[i])
        })
        .collect();
    // `J M^-1 x = W^T D^-1 L^-T x` and `a = M^-1 (tau - h + J^T f) = L^-1 D^-1 (L^-T (tau - h)
    // + W f)`: one substitution's second half, and the accelerations without contacts never
    // formed.
    let lowered = space.factors.lower(g, &rhs);
    let b: Vec<Id> = space
        .scaled
        .iter()
        .zip(drift)
        .map(|(row, &d)| {
            let jf = g.dot(row, &lowered);
            let s = g.add(d, jf);
            g.neg(s)
        })
        .collect();
    let (f, lambda_pivots) = solve_dense(g, &space.lambda, &b);
    let a = space.upper_plus_w(g, Some(&lowered), &f);
    let flat = space.finish(g, a, (f, lambda_pivots), axes);
    g.set_product_flattening(old_products);
    flat
}

/// Impulse dynamics at restitution zero, whose results `(dv, p)` the restitution `e` scales:
/// `p = -(1 + e) Lambda^-1 J v` and `v_after = v + M^-1 J^T p`, so generated code takes
/// `(1 + e) p0` and `v + (1 + e) dv0` from `p0 = -Lambda^-1 J v` and `dv0 = L^-1 D^-1 W p0`.
/// `J` is in the axes `axes` turns into the world's, as for [`contact_forward_dynamics`];
/// `v` are the velocity symbols.
pub(crate) fn impulse_dynamics(
    g: &mut Graph,
    parents: &[Option<usize>],
    m: &[Vec<Id>],
    j: &[Vec<Id>],
    v: &[Id],
    axes: Option<&M3>,
) -> FlatContact {
    let old_products = g.set_product_flattening(false);
    let space = Space::new(g, parents, m, j);
    let b: Vec<Id> = j
        .iter()
        .map(|row| {
            let jv = g.dot(row, v);
            g.neg(jv)
        })
        .collect();
    let (p, lambda_pivots) = solve_dense(g, &space.lambda, &b);
    let dv = space.upper_plus_w(g, None, &p);
    let flat = space.finish(g, dv, (p, lambda_pivots), axes);
    g.set_product_flattening(old_products);
    flat
}

/// The contact space of `M` and `J`: `M`'s factors, `W = L^-T J^T` (by rows of `W^T`),
/// `W^T D^-1` and `Lambda = J M^-1 J^T = W^T D^-1 W`.
struct Space {
    factors: Factors,
    w: Vec<Vec<Id>>,
    scaled: Vec<Vec<Id>>,
    lambda: Vec<Vec<Id>>,
}

impl Space {
    fn new(g: &mut Graph, parents: &[Option<usize>], m: &[Vec<Id>], j: &[Vec<Id>]) -> Space {
        let factors = Factors::new(g, parents, m);
        let w: Vec<Vec<Id>> = j.iter().map(|row| factors.lower(g, row)).collect();
        let scaled: Vec<Vec<Id>> = w
            .iter()
            .map(|row| {
                let inv_d = factors.inverse_pivots();
                row.iter().zip(inv_d).map(|(&x, &d)| g.mul(x, d)).collect()
            })
            .collect();
        let lambda = gram(g, &scaled, &w);
        Space {
            factors,
            w,
            scaled,
            lambda,
        }
    }

    /// The program's results: `n` values per coordinate, then the contact rows `f` turned
    /// into the world's axes by `axes`; the pivots of `M`'s factorization, then `lambda`'s.
    fn finish(
        &self,
        g: &mut Graph,
        n: Vec<Id>,
        (f, lambda_pivots): (Vec<Id>, Vec<Id>),
        axes: Option<&M3>,
    ) -> FlatContact {
        let f = super::centroidal::turn_rows(g, axes, &f);
        let pivots = self.factors.pivots().into_iter().chain(lambda_pivots);
        FlatContact {
            outputs: n.into_iter().chain(f).collect(),
            pivots: pivots.collect(),
        }
    }

    /// `L^-1 D^-1 (x + W f)` (`x` zero when `None`): `M^-1 (y + J^T f)` for `x = L^-T y`.
    fn upper_plus_w(&self, g: &mut Graph, x: Option<&[Id]>, f: &[Id]) -> Vec<Id> {
        let n = self.factors.pivots().len();
        let sum: Vec<Id> = (0..n)
            .map(|i| {
                let terms = self.w.iter().zip(f).map(|(wr, &fr)| g.mul(wr[i], fr));
                let terms: Vec<Id> = x.map(|x| x[i]).into_iter().chain(terms).collect();
                g.add_all(terms)
            })
            .collect();
        self.factors.upper(g, &sum)
    }
}

/// `W^T D^-1 W` from the rows of `W^T` (`w`) and of `W^T D^-1` (`scaled`), symmetric (each
/// entry below the diagonal is the node above it).
fn gram(g: &mut Graph, scaled: &[Vec<Id>], w: &[Vec<Id>]) -> Vec<Vec<Id>> {
    let k = w.len();
    let mut out = vec![vec![g.zero(); k]; k];
    for r in 0..k {
        for c in 0..=r {
            out[r][c] = g.dot(&scaled[r], &w[c]);
            out[c][r] = out[r][c];
        }
    }
    out
}

/// `A^-1 b` for a symmetric positive definite `A` by its dense `L^T D L` factorization,
/// eliminating row 0 first, and the pivots in that order.
fn solve_dense(g: &mut Graph, a: &[Vec<Id>], b: &[Id]) -> (Vec<Id>, Vec<Id>) {
    let k = a.len();
    // [`Factors`] eliminates the last coordinate first: reversed, row 0 goes first, and a
    // chain makes every earlier coordinate an ancestor (a dense factorization).
    let rev = |i: usize| k - 1 - i;
    let reversed: Vec<Vec<Id>> = (0..k)
        .map(|r| (0..k).map(|c| a[rev(r)][rev(c)]).collect())
        .collect();
    let chain: Vec<Option<usize>> = (0..k).map(|i| i.checked_sub(1)).collect();
    let factors = Factors::new(g, &chain, &reversed);
    let rb: Vec<Id> = (0..k).map(|r| b[rev(r)]).collect();
    let x = factors.solve(g, &rb);
    let pivots = factors.pivots();
    (
        (0..k).map(|r| x[rev(r)]).collect(),
        (0..k).map(|r| pivots[rev(r)]).collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_dense_solve_inverts_and_reports_pivots_in_cholesky_order() {
        let values = [[4.0, 1.0, 0.5], [1.0, 3.0, 0.2], [0.5, 0.2, 2.0]];
        let mut g = Graph::new();
        let a: Vec<Vec<Id>> = values
            .iter()
            .map(|row| row.iter().map(|&v| g.constant(v)).collect())
            .collect();
        let b: Vec<Id> = [1.0, -2.0, 0.5].iter().map(|&v| g.constant(v)).collect();
        let (x, pivots) = solve_dense(&mut g, &a, &b);
        let all: Vec<Id> = x.iter().chain(&pivots).copied().collect();
        let v = Program::new(&g, &all).eval(|_| None).unwrap();
        for (i, row) in values.iter().enumerate() {
            let ax: f64 = row.iter().zip(&v).map(|(a, x)| a * x).sum();
            assert!((ax - [1.0, -2.0, 0.5][i]).abs() < 1e-14, "row {i}: {ax}");
        }
        // Cholesky's first pivot is A_00, its second A_11 - A_10^2 / A_00.
        assert_eq!(v[3], 4.0);
        assert!((v[4] - (3.0 - 1.0 / 4.0)).abs() < 1e-15);
    }
}
