//! Coupled joints (URDF mimic joints, [`ModelOptions::mimic_joints`]): the joint tree keeps
//! one coordinate per joint for kinematics and the recursions, but those coordinates are
//! expressions of the robot's independent coordinates, `q_joint = k q[c] + o`, `qd_joint = k
//! qd[c]`, `qdd_joint = k qdd[c]` ([`Coupling`]). With `G` the constant map from coordinates
//! to joint velocities (`G[joint][c] = k`), every quantity in the coordinates is the joint
//! tree's projected: efforts `G^T tau`, matrices `G^T M G` (Christoffel symbols are a tensor
//! under a constant `G`, so `C(q, qd)` projects the same way), Jacobians `J G`.
//!
//! Without coupled joints every function here returns its input unchanged and creates no
//! expression, so that the derivation (and the generated code) stays what it was.
//!
//! [`ModelOptions::mimic_joints`]: crate::model::ModelOptions::mimic_joints

use crate::cas::{Graph, Id};
use crate::model::{Coupling, Model};

/// The map between a model's joints and its coordinates.
#[derive(Clone, Debug)]
pub struct CoordinateMap {
    /// Per joint, its coordinate (in the joints' part), multiplier and offset.
    coupling: Vec<Coupling>,
    /// The number of the joints' coordinates.
    coordinates: usize,
    /// A floating base's position and velocity coordinates before the joints' (7 and 6, or
    /// none), never coupled.
    base_q: usize,
    base_v: usize,
    /// The number of position coordinates (7 per free flyer, then one per coordinate: mimic
    /// joints never involve a floating joint).
    positions: usize,
    /// Whether some joint follows another.
    coupled: bool,
}

impl CoordinateMap {
    /// The map of `model`'s coordinates (a floating base's first, never coupled, then the
    /// joints').
    pub fn new(model: &Model) -> CoordinateMap {
        CoordinateMap {
            coupling: model.coupling.clone(),
            coordinates: model.coordinates(),
            base_q: model.base_nq(),
            base_v: model.base_nv(),
            positions: model.nq() - (model.dof() - model.coordinate_joints().len()),
            coupled: model.is_coupled(),
        }
    }

    /// Whether some joint follows another: projections then do something.
    pub fn is_coupled(&self) -> bool {
        self.coupled
    }

    /// The number of velocity coordinates (a floating base's six, then the joints').
    pub fn coordinates(&self) -> usize {
        self.base_v + self.coordinates
    }

    /// The number of position coordinates (a floating base's seven, then the joints').
    pub fn positions_len(&self) -> usize {
        self.positions
    }

    /// The joints' positions for the coordinates' positions `q`: `k q[c] + o` (a floating
    /// base's first, unchanged).
    pub fn positions(&self, g: &mut Graph, q: &[Id]) -> Vec<Id> {
        if !self.coupled {
            return q.to_vec();
        }
        let (base, joints) = q.split_at(self.base_q);
        let mut out = base.to_vec();
        out.extend(self.coupling.iter().map(|c| {
            if c.is_identity() {
                joints[c.coordinate]
            } else {
                g.sum(c.offset, [(joints[c.coordinate], c.multiplier)])
            }
        }));
        out
    }

    /// The joints' rates (velocities, accelerations) for the coordinates' `x`: `k x[c]` (a
    /// floating base's first, unchanged).
    pub fn rates(&self, g: &mut Graph, x: &[Id]) -> Vec<Id> {
        if !self.coupled {
            return x.to_vec();
        }
        let (base, joints) = x.split_at(self.base_v);
        let mut out = base.to_vec();
        out.extend(self.coupling.iter().map(|c| {
            if c.multiplier == 1.0 {
                joints[c.coordinate]
            } else {
                g.scale(joints[c.coordinate], c.multiplier)
            }
        }));
        out
    }

    /// `G^T v` for a vector `v` over the velocity coordinates of the joint tree (efforts):
    /// per coordinate, the sum of its joints' entries times their multipliers (a floating
    /// base's first, unchanged).
    pub fn project(&self, g: &mut Graph, v: &[Id]) -> Vec<Id> {
        if !self.coupled {
            return v.to_vec();
        }
        let (base, joints) = v.split_at(self.base_v);
        let mut out = base.to_vec();
        out.extend((0..self.coordinates).map(|c| {
            let terms: Vec<(Id, f64)> = self
                .coupling
                .iter()
                .zip(joints)
                .filter(|(k, _)| k.coordinate == c)
                .map(|(k, &x)| (x, k.multiplier))
                .collect();
            g.sum(0.0, terms)
        }));
        out
    }

    /// `A G` for a matrix `A` whose columns are the velocity coordinates of the joint tree
    /// (Jacobians).
    pub fn project_columns(&self, g: &mut Graph, a: &[Vec<Id>]) -> Vec<Vec<Id>> {
        if !self.coupled {
            return a.to_vec();
        }
        a.iter().map(|row| self.project(g, row)).collect()
    }

    /// `G^T A` for a matrix `A` whose rows are the velocity coordinates of the joint tree
    /// (regressors).
    pub fn project_rows(&self, g: &mut Graph, a: &[Vec<Id>]) -> Vec<Vec<Id>> {
        if !self.coupled {
            return a.to_vec();
        }
        let columns = a.first().map_or(0, Vec::len);
        let mut out = vec![Vec::with_capacity(columns); self.coordinates()];
        for p in 0..columns {
            let column: Vec<Id> = a.iter().map(|row| row[p]).collect();
            for (row, x) in out.iter_mut().zip(self.project(g, &column)) {
                row.push(x);
            }
        }
        out
    }

    /// `G^T M G` for a matrix over the joints; `symmetric`: `M` is, and the result's
    /// `[i][j]` and `[j][i]` are then one expression.
    pub fn project_matrix(&self, g: &mut Graph, m: &[Vec<Id>], symmetric: bool) -> Vec<Vec<Id>> {
        if !self.coupled {
            return m.to_vec();
        }
        let n = self.coordinates();
        let mg = self.project_columns(g, m);
        let mut out = vec![vec![g.zero(); n]; n];
        for d in 0..n {
            let column: Vec<Id> = mg.iter().map(|row| row[d]).collect();
            let projected = self.project(g, &column);
            for (c, x) in projected.into_iter().enumerate() {
                if !symmetric || c <= d {
                    out[c][d] = x;
                }
            }
        }
        if symmetric {
            for c in 0..n {
                for d in 0..c {
                    out[c][d] = out[d][c];
                }
            }
        }
        out
    }

    /// Each coordinate's parent coordinate for the sparse `L^T D L` factorizations of
    /// `G^T M G` (which eliminate the last coordinate first): the elimination tree of its
    /// sparsity. `M_joints[a][b]` can be non-zero when `a` and `b` lie on one path from the
    /// root, so coordinates `c` and `d` are coupled when some joint of `c` and some joint of `d`
    /// are. Where the coordinates still form a tree (a mimic within one chain) this is that
    /// tree and the factorization has no fill-in; a mimic across branches joins them into
    /// a chain where it must.
    pub fn parents(&self, model: &Model, joint_parents: Vec<Option<usize>>) -> Vec<Option<usize>> {
        if !self.coupled {
            return joint_parents;
        }
        let n = self.coordinates();
        // Each coordinate's joints; a floating base's coordinates have none and are coupled
        // with every coordinate (the base is every joint's ancestor).
        let joints: Vec<Vec<usize>> = (0..n)
            .map(|c| match c.checked_sub(self.base_v) {
                Some(c) => (0..self.coupling.len())
                    .filter(|&j| self.coupling[j].coordinate == c)
                    .collect(),
                None => Vec::new(),
            })
            .collect();
        let base = |c: usize| c < self.base_v;
        let related = |a: usize, b: usize| model.is_ancestor(a, b) || model.is_ancestor(b, a);
        // pattern[k][i], i < k: the filled lower triangle.
        let mut pattern = vec![vec![false; n]; n];
        for k in 0..n {
            for i in 0..k {
                pattern[k][i] = base(k)
                    || base(i)
                    || joints[k]
                        .iter()
                        .any(|&a| joints[i].iter().any(|&b| related(a, b)));
            }
        }
        let mut parents = vec![None; n];
        for k in (0..n).rev() {
            let Some(p) = (0..k).rev().find(|&i| pattern[k][i]) else {
                continue;
            };
            parents[k] = Some(p);
            // Eliminating k fills in between its parent and its other neighbours.
            for i in 0..p {
                if pattern[k][i] {
                    pattern[p][i] = true;
                }
            }
        }
        parents
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::ModelOptions;

    fn model(urdf: &str) -> Model {
        let options = ModelOptions {
            mimic_joints: true,
            ..ModelOptions::default()
        };
        crate::urdf::load_str(urdf, "t.urdf", &options).unwrap()
    }

    fn link(name: &str) -> String {
        format!(
            r#"<link name="{name}"><inertial><origin xyz="0.1 0 0"/><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>"#
        )
    }

    fn joint(name: &str, parent: &str, child: &str, mimic: &str) -> String {
        format!(
            r#"<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/><origin xyz="0.2 0 0"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>{mimic}</joint>"#
        )
    }

    /// Two branches `a1 -> a2` and `b1 -> b2` from the root.
    fn branches(mimic: &str) -> Model {
        let mut text = String::from(r#"<robot name="t"><link name="root"/>"#);
        for l in ["la1", "la2", "lb1", "lb2"] {
            text += &link(l);
        }
        text += &joint("a1", "root", "la1", "");
        text += &joint("a2", "la1", "la2", "");
        text += &joint("b1", "root", "lb1", "");
        text += &joint("b2", "lb1", "lb2", mimic);
        text += "</robot>";
        model(&text)
    }

    #[test]
    fn a_mimic_within_a_chain_keeps_the_tree() {
        let m = branches(r#"<mimic joint="b1" multiplier="2"/>"#);
        let map = CoordinateMap::new(&m);
        assert_eq!(map.coordinates(), 3);
        let parents = map.parents(&m, Vec::new());
        assert_eq!(parents, vec![None, Some(0), None]);
    }

    #[test]
    fn a_mimic_across_branches_joins_them() {
        let m = branches(r#"<mimic joint="a2" multiplier="-1" offset="0.3"/>"#);
        let map = CoordinateMap::new(&m);
        // Coordinates a1, a2, b1; b2 follows a2, so b1 is coupled with a2 and a1.
        let parents = map.parents(&m, Vec::new());
        assert_eq!(parents, vec![None, Some(0), Some(1)]);
        assert_eq!(m.coupling[3].coordinate, 1);
        assert_eq!(m.coupling[3].leader, Some(1));
    }
}
