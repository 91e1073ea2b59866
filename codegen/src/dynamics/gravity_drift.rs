//! The contact drift from the forward pass that `b + G` runs, for programs that compute both.
//!
//! Newton-Euler's forward pass with gravity (`Recursive::bias_and_gravity`'s) gives each body
//! the classical acceleration of the pass without gravity (`Centroidal::contact_drift`'s) plus
//! gravity's upward acceleration in body axes, `R^T (-g)`, which moves with the body rigidly.
//! So a point's drift is `R accel + g` in world axes from that pass's `accel`, and straight-line
//! contact forward dynamics, which computes `b + G` anyway, gets its drift for a rotation and an
//! addition per contact instead of a second pass: anymal's (four feet) 8,635 -> 8,343
//! operations, 1,165 -> 1,125 ns; g1_29dof's (two 6D soles) 20,281 -> 19,663 operations. The
//! values equal `contact_drift`'s to rounding (the gravity terms cancel), which is why the
//! contact drift itself and everything differentiated from it keep the pass without gravity.

use super::centroidal::base_at_identity;
use super::newton_euler::{self, BodyMotion, LocalModel, Terms};
use super::Derivation;
use crate::cas::{Graph, Id, SumFlattening};
use crate::kinematics::joint::free_flyer_placement;
use crate::kinematics::{const_v3, cross, mat_t_vec, mat_vec, vec_add, vec_sub, M3, V3};
use crate::model::Model;

/// A contact's drift as Newton-Euler's forward pass with gravity sees it ([`forward_pass`]; the
/// contacts' derivation in `centroidal.rs` builds one per contact), the pass that `b + G` runs
/// (`Recursive::bias_and_gravity`): the body's classical acceleration there is the drift's
/// plus gravity's upward acceleration in body axes, `R^T (-g)`, so that in world axes the
/// point's drift is `R accel + g` (and in a floating base's axes `R_b^T (R accel + g)`). Built
/// from that pass's own expressions, the drift shares its kinematics with `b + G` in a program
/// that computes both (straight-line contact forward dynamics), where
/// [`Centroidal::contact_drift`](super::centroidal::Centroidal::contact_drift) repeats the pass
/// without gravity.
#[derive(Clone, Debug)]
pub struct GravityDrift {
    /// The body's world rotation `R` (a floating base's included); `None` for a contact on a
    /// fixed root, whose drift is zero.
    pub rotation: Option<M3>,
    /// The contact point's classical acceleration with gravity's, body axes.
    pub accel: V3,
    /// For a 6D contact frame: the body's angular velocity and acceleration (body axes) and the
    /// frame origin's linear velocity (world axes).
    pub frame: Option<(V3, V3, V3)>,
}

impl GravityDrift {
    /// A contact on a fixed root: it never moves.
    pub fn still(g: &mut Graph) -> GravityDrift {
        GravityDrift {
            rotation: None,
            accel: [g.zero(); 3],
            frame: None,
        }
    }
}

/// Newton-Euler's forward pass with gravity at the velocities `v`, built as `recursive` builds
/// `b + G`'s (shared sums), so that its nodes are that pass's.
pub(super) fn forward_pass(
    g: &mut Graph,
    model: &Model,
    lm: &LocalModel,
    v: &[Id],
) -> Vec<BodyMotion> {
    let gravity = Some(const_v3(g, &model.gravity));
    let old = g.set_flattening(SumFlattening::Shared);
    let terms = Terms {
        qd: Some(v),
        qdd: None,
        gravity,
    };
    let motions = newton_euler::forward_pass(g, lm, terms, |_, _, _| {});
    g.set_flattening(old);
    motions
}

/// The contact drift in the axes that [`contacts_in_solving_axes`] solves in, built from
/// [`GravityDrift`] (the same values as its drift, to rounding): in a floating base's axes each
/// point's is `R_bi accel + R_b^T g`, with `R_bi` the body's rotation in base axes (the world's
/// at the identity quaternion, as [`contacts_in_base_axes`] takes `J`) and `R_b` the base's; in
/// world axes `R accel + g`. A 6D frame's linear rows subtract `w x v` (its angular velocity
/// and origin velocity in those axes), its angular rows are `R dw`.
///
/// [`contacts_in_solving_axes`]: super::centroidal::contacts_in_solving_axes
/// [`contacts_in_base_axes`]: super::centroidal::contacts_in_base_axes
pub(super) fn in_solving_axes(model: &Model, d: &mut Derivation) -> Vec<Id> {
    let g = &mut d.graph;
    let gv = const_v3(g, &model.gravity);
    let (at_identity, gravity) = if model.is_floating() {
        let map = base_at_identity(g, &d.q);
        let rb = free_flyer_placement(g, &d.q[..7]).rotation;
        (Some(map), mat_t_vec(g, &rb, &gv))
    } else {
        (None, gv)
    };
    let mut drift = Vec::new();
    for part in &d.centroidal.gravity_drift {
        let rows = if part.frame.is_some() { 6 } else { 3 };
        let Some(world) = part.rotation else {
            drift.extend(vec![g.zero(); rows]);
            continue;
        };
        let velocity = part.frame.map_or([g.zero(); 3], |f| f.2);
        let (r, velocity) = match &at_identity {
            Some(map) => {
                let all: Vec<Id> = world.iter().flatten().chain(&velocity).copied().collect();
                let b = g.substitute(&all, map);
                let r = [0, 1, 2].map(|i| [0, 1, 2].map(|k| b[3 * i + k]));
                (r, [b[9], b[10], b[11]])
            }
            None => (world, velocity),
        };
        let ra = mat_vec(g, &r, &part.accel);
        let classical = vec_add(g, &ra, &gravity);
        match part.frame {
            None => drift.extend(classical),
            Some((w, dw, _)) => {
                let w = mat_vec(g, &r, &w);
                let wv = cross(g, &w, &velocity);
                drift.extend(vec_sub(g, &classical, &wv));
                drift.extend(mat_vec(g, &r, &dw));
            }
        }
    }
    drift
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cas::{Node, Program, Symbol};
    use crate::dynamics::centroidal::contacts_in_solving_axes;

    /// The drift from `b + G`'s pass equals the drift without gravity in the axes both are
    /// solved in, at a state with a unit quaternion (on which the cancellation rests).
    fn check(builder: crate::Builder) {
        let model = builder.model().unwrap();
        let mut d = Derivation::new(&model);
        let quaternion: Vec<String> = if model.is_floating() {
            d.q[3..7]
                .iter()
                .map(|&q| match d.graph.node(q) {
                    Node::Sym(s) => d.graph.symbols()[*s as usize].name.clone(),
                    _ => unreachable!("a symbol"),
                })
                .collect()
        } else {
            Vec::new()
        };
        let (_, want, _) = contacts_in_solving_axes(&model, &mut d);
        let got = in_solving_axes(&model, &mut d);
        assert_eq!(want.len(), got.len());
        let unit = [0.3_f64, -0.5, 0.1, 0.8];
        let norm = unit.iter().map(|x| x * x).sum::<f64>().sqrt();
        let value = |s: &Symbol| match quaternion.iter().position(|n| *n == s.name) {
            Some(k) => Some(unit[k] / norm),
            None => Some((s.name.bytes().map(f64::from).sum::<f64>() * 0.37).sin()),
        };
        let w = Program::new(&d.graph, &want).eval(value).unwrap();
        let o = Program::new(&d.graph, &got).eval(value).unwrap();
        let scale = w.iter().fold(1.0_f64, |m, x| m.max(x.abs()));
        for (k, (a, b)) in w.iter().zip(&o).enumerate() {
            assert!((a - b).abs() < 1e-12 * scale, "row {k}: {a} vs {b}");
        }
    }

    #[test]
    fn a_floating_base_drift_from_the_gravity_pass_is_the_drift() {
        check(
            crate::Builder::new("../tests/robots/floating/anymal.urdf")
                .floating_base()
                .contact_points(&["LF_FOOT", "RH_FOOT"])
                .contact_point_at("LH_SHANK", [0.1, -0.02, 0.3])
                .contact_frames(&["RF_SHANK"]),
        );
    }

    #[test]
    fn a_fixed_base_drift_from_the_gravity_pass_is_the_drift() {
        let panda = || {
            crate::Builder::new("../tests/robots/panda.urdf")
                .contact_points(&["panda_hand", "panda_rightfinger"])
                .contact_point_at("panda_link5", [0.05, 0.0, -0.1])
                .contact_frames(&["panda_leftfinger"])
        };
        check(panda());
        // The second finger coupled to the first: `b + G` projected, the drift in joint rates.
        check(panda().mimic_joints());
    }
}
