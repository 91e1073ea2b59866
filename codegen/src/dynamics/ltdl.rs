//! Featherstone's tree `L^T D L` factorization of the mass matrix on the CAS: the factors, a
//! substitution through them, and the inverse as the symmetric product `L^-1 D^-1 L^-T`.
//!
//! Eliminating the coordinates in reverse order creates no fill-in on a kinematic tree: `M_ij`
//! is touched only when one of `i`, `j` is an ancestor of the other, so a branched robot's
//! chains stay independent (RBDA, tables 6.3 and 6.4). `M` is positive definite exactly when
//! every pivot `D_i` is positive. Each pivot is inverted once; everything else multiplies.
//!
//! Products are built without merging child products (`Graph::set_product_flattening`): an
//! entry of `L`, `M_ki / D_k`, is one value that every update of its row multiplies, where
//! merged each update was a product of three factors (`M_kj M_ki D_k^-1`), one multiplication
//! more. That was a tenth of the panda's forward-dynamics derivatives (10,172 -> 8,999
//! operations), a sixth of its `M^-1` (1,506 -> 1,246) and 9 % of anymal's forward dynamics
//! (4,717 -> 4,314).

use crate::cas::{Graph, Id, SumFlattening};

/// `M = L^T D L` over the coordinate tree `parent` (each coordinate after its parent): `L`
/// unit lower triangular with `L_ij` nonzero only for `j` an ancestor of `i`.
pub(crate) struct Factors {
    /// `D` on the diagonal, `L` below it (the entries of ancestors), `M` elsewhere.
    h: Vec<Vec<Id>>,
    /// `1 / D_i`.
    inv_d: Vec<Id>,
    /// Per coordinate, its ancestors, nearest first.
    ancestors: Vec<Vec<usize>>,
}

impl Factors {
    /// Factorizes `m` (only its lower triangle's tree entries are read).
    pub(crate) fn new(g: &mut Graph, parent: &[Option<usize>], m: &[Vec<Id>]) -> Factors {
        let n = m.len();
        // Merged sums: the updates of one entry by each descendant collect with `M`'s terms
        // (shared sums gave the forward dynamics 1 to 3 % more operations, here and below).
        let old = g.set_flattening(SumFlattening::Always);
        let old_products = g.set_product_flattening(false);
        let ancestors: Vec<Vec<usize>> = (0..n).map(|k| ancestors(parent, k)).collect();
        let mut h: Vec<Vec<Id>> = m.to_vec();
        let mut inv_d = vec![g.one(); n];
        for k in (0..n).rev() {
            inv_d[k] = g.recip(h[k][k]);
            for (s, &i) in ancestors[k].iter().enumerate() {
                let a = g.mul(h[k][i], inv_d[k]);
                for &j in &ancestors[k][s..] {
                    let p = g.mul(h[k][j], a);
                    h[i][j] = g.sub(h[i][j], p);
                }
                h[k][i] = a;
            }
        }
        g.set_flattening(old);
        g.set_product_flattening(old_products);
        Factors {
            h,
            inv_d,
            ancestors,
        }
    }

    /// The factors where the run-time tree passes keep them (`tree::ltdl_factor`'s layout):
    /// `D` on the diagonal, `L_ij` at `(i, j)` for `j` an ancestor of `i`, zero elsewhere.
    pub(crate) fn in_place(&self, g: &Graph) -> Vec<Vec<Id>> {
        let n = self.h.len();
        let mut m = vec![vec![g.zero(); n]; n];
        for (i, anc) in self.ancestors.iter().enumerate() {
            m[i][i] = self.h[i][i];
            for &j in anc {
                m[i][j] = self.h[i][j];
            }
        }
        m
    }

    /// The pivots `D`.
    pub(crate) fn pivots(&self) -> Vec<Id> {
        (0..self.h.len()).map(|i| self.h[i][i]).collect()
    }

    /// `1 / D`.
    pub(crate) fn inverse_pivots(&self) -> &[Id] {
        &self.inv_d
    }

    /// `M^-1 rhs`: `L^-T`, `D^-1`, `L^-1`.
    pub(crate) fn solve(&self, g: &mut Graph, rhs: &[Id]) -> Vec<Id> {
        let x = self.lower(g, rhs);
        self.upper(g, &x)
    }

    /// `L^-T rhs`: the first half of [`Factors::solve`], each coordinate's value passed up to
    /// its ancestors from the leaves.
    pub(crate) fn lower(&self, g: &mut Graph, rhs: &[Id]) -> Vec<Id> {
        let old_products = g.set_product_flattening(false);
        let mut x = rhs.to_vec();
        for i in (0..self.h.len()).rev() {
            for &j in &self.ancestors[i] {
                let p = g.mul(self.h[i][j], x[i]);
                x[j] = g.sub(x[j], p);
            }
        }
        g.set_product_flattening(old_products);
        x
    }

    /// `L^-1 D^-1 x`: the second half of [`Factors::solve`], from the root down.
    pub(crate) fn upper(&self, g: &mut Graph, x: &[Id]) -> Vec<Id> {
        let n = self.h.len();
        let old_products = g.set_product_flattening(false);
        let mut x = x.to_vec();
        for i in 0..n {
            x[i] = g.mul(x[i], self.inv_d[i]);
            for &j in &self.ancestors[i] {
                let p = g.mul(self.h[i][j], x[j]);
                x[i] = g.sub(x[i], p);
            }
        }
        g.set_product_flattening(old_products);
        x
    }

    /// `M^-1 = X D^-1 X^T` with `X = L^-1`, whose row `i` is nonzero only in the columns of
    /// `i` and its ancestors: entry `(i, j)` sums over the coordinates above both, computed
    /// once for `i <= j` and mirrored, so the result is exactly symmetric. About
    /// `sum(depth^2) / 2` operations for `X` and one product per common ancestor of each pair
    /// for the entries, a third of solving the columns of the identity one by one on a
    /// floating quadruped.
    pub(crate) fn inverse(&self, g: &mut Graph) -> Vec<Vec<Id>> {
        let n = self.h.len();
        let old = g.set_flattening(SumFlattening::Always);
        let old_products = g.set_product_flattening(false);
        // x[i][s]: X_{i, k} for the s-th of `i`'s coordinates (itself, then its ancestors).
        let mut x: Vec<Vec<Id>> = Vec::with_capacity(n);
        for i in 0..n {
            let above = &self.ancestors[i];
            let mut row = vec![g.one()];
            for (s, &k) in above.iter().enumerate() {
                // X_ik = -sum over a on the path from i's parent up to k of L_ia X_ak.
                let terms: Vec<Id> = above[..=s]
                    .iter()
                    .map(|&a| {
                        let pos = self.ancestors[a].iter().position(|&b| b == k);
                        let xak = pos.map_or(g.one(), |p| x[a][p + 1]);
                        g.mul(self.h[i][a], xak)
                    })
                    .collect();
                let sum = g.add_all(terms);
                row.push(g.neg(sum));
            }
            x.push(row);
        }
        let mut inv = vec![vec![g.zero(); n]; n];
        for i in 0..n {
            // Y_ik = X_ik / D_k over i's coordinates.
            let scaled: Vec<(usize, Id)> = self
                .coordinates(i)
                .zip(&x[i])
                .map(|(k, &v)| (k, g.mul(v, self.inv_d[k])))
                .collect();
            for j in i..n {
                let pairs: Vec<(Id, Id)> = self
                    .coordinates(j)
                    .zip(&x[j])
                    .filter_map(|(k, &xjk)| {
                        let (_, yik) = scaled.iter().find(|(kk, _)| *kk == k)?;
                        Some((*yik, xjk))
                    })
                    .collect();
                let terms: Vec<Id> = pairs.into_iter().map(|(y, xj)| g.mul(y, xj)).collect();
                let e = g.add_all(terms);
                inv[i][j] = e;
                inv[j][i] = e;
            }
        }
        g.set_flattening(old);
        g.set_product_flattening(old_products);
        inv
    }

    /// `i` and its ancestors, nearest first.
    fn coordinates(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        core::iter::once(i).chain(self.ancestors[i].iter().copied())
    }
}

/// `k`'s ancestors in `parent`, nearest first.
pub(crate) fn ancestors(parent: &[Option<usize>], k: usize) -> Vec<usize> {
    let mut out = Vec::new();
    let mut i = parent[k];
    while let Some(p) = i {
        out.push(p);
        i = parent[p];
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cas::{Program, SymbolKind};

    /// A floating-base-like tree: a chain of three, then two branches of two.
    fn tree() -> Vec<Option<usize>> {
        vec![None, Some(0), Some(1), Some(2), Some(3), Some(2), Some(5)]
    }

    /// A symmetric positive definite matrix with the tree's sparsity, as numbers.
    fn matrix(parent: &[Option<usize>]) -> Vec<Vec<f64>> {
        let n = parent.len();
        let related = |i: usize, j: usize| {
            ancestors(parent, i).contains(&j) || ancestors(parent, j).contains(&i)
        };
        (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| match () {
                        _ if i == j => 4.0 + i as f64,
                        _ if related(i, j) => 0.3 + 0.1 * (i + j) as f64 / n as f64,
                        _ => 0.0,
                    })
                    .collect()
            })
            .collect()
    }

    #[test]
    fn each_update_is_one_multiplication_and_one_addition() {
        // A chain of three on symbols: two reciprocals (D_2, D_1; the root's is not used), the
        // three entries of L one product each, four updates of the lower triangle (M_11, M_10,
        // M_00 by coordinate 2, M_00 by 1) a product and a subtraction each. Merging products,
        // the updates took 4 more multiplications (`M_21 M_21 / D_2` is a square and a product).
        let parent = [None, Some(0), Some(1)];
        let mut g = Graph::new();
        let m: Vec<Vec<Id>> = (0..3)
            .map(|i| {
                (0..3)
                    .map(|j| g.symbol(&format!("m{}{}", i.max(j), i.min(j)), SymbolKind::Param))
                    .collect()
            })
            .collect();
        let f = Factors::new(&mut g, &parent, &m);
        let outputs: Vec<Id> = f.in_place(&g).into_iter().flatten().collect();
        let ops = Program::new(&g, &outputs).ops();
        assert_eq!((ops.div, ops.mul, ops.add), (2, 3 + 4, 4));
    }

    #[test]
    fn inverse_and_solve_invert_the_matrix() {
        let parent = tree();
        let n = parent.len();
        let values = matrix(&parent);
        let mut g = Graph::new();
        let m: Vec<Vec<Id>> = values
            .iter()
            .map(|row| row.iter().map(|&v| g.constant(v)).collect())
            .collect();
        let f = Factors::new(&mut g, &parent, &m);
        let inv = f.inverse(&mut g);
        let rhs: Vec<Id> = (0..n).map(|i| g.constant(1.0 + i as f64)).collect();
        let x = f.solve(&mut g, &rhs);
        let flat: Vec<Id> = inv.iter().flatten().chain(&x).copied().collect();
        let v = Program::new(&g, &flat).eval(|_| None).unwrap();
        for i in 0..n {
            for j in 0..n {
                let p: f64 = (0..n).map(|k| values[i][k] * v[k * n + j]).sum();
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((p - want).abs() < 1e-14, "({i}, {j}): {p}");
            }
            let p: f64 = (0..n).map(|k| values[i][k] * v[n * n + k]).sum();
            assert!((p - (1.0 + i as f64)).abs() < 1e-13, "row {i}: {p}");
        }
    }
}
