//! The projected Newton-Euler form, body by body, for the reports (`eomgen show --form
//! projected-newton-euler`): each body's share of `M` and `b` from its own Jacobians, derived
//! independently of the routes generated code takes.
//!
//! With `J_P,i` the Jacobian of body `i`'s centre of mass (`dc_i/dq`), `J_R,i` its angular
//! Jacobian (the world axis of each revolute joint on its path, zero elsewhere),
//! `Theta_i = R_i I_i R_i^T` its inertia about the centre of mass in world axes and
//! `omega_i = J_R,i qd`:
//!
//! ```text
//! M = sum_i  J_P,i^T m_i J_P,i + J_R,i^T Theta_i J_R,i
//! b = sum_i  J_P,i^T m_i Jdot_P,i qd + J_R,i^T (Theta_i Jdot_R,i qd + omega_i x Theta_i omega_i)
//! ```
//!
//! plus the rotor inertias (armature) on `M`'s diagonal.

use crate::cas::{Graph, Id};
use crate::kinematics::{Params, WorldKinematics};
use crate::model::Model;
use crate::spatial::{cross, mat_mul, mat_vec, transpose, V3};

/// One body's share of the mass matrix and the bias.
#[derive(Clone, Debug)]
pub struct BodyTerms {
    /// The body's URDF link.
    pub link: String,
    /// `J_P^T m J_P + J_R^T Theta J_R`, N x N.
    pub mass_matrix: Vec<Vec<Id>>,
    /// `J_P^T m Jdot_P qd + J_R^T (Theta Jdot_R qd + omega x Theta omega)`.
    pub bias: Vec<Id>,
}

/// Every body's terms, in body (joint) order, for a fixed-base robot.
pub fn body_terms(g: &mut Graph, model: &Model, q: &[Id], qd: &[Id]) -> Vec<BodyTerms> {
    let n = model.dof();
    let params = Params::new(g, model);
    let world = WorldKinematics::new(g, model, &params, q);
    (0..model.bodies.len())
        .map(|b| {
            // J_P: 3 x N, J_R: 3 x N.
            let jp: Vec<Vec<Id>> = world.com[b]
                .iter()
                .map(|&c| q.iter().map(|&qj| g.diff(c, qj)).collect())
                .collect();
            let zero = g.zero();
            let jr: Vec<Vec<Id>> = (0..3)
                .map(|r| {
                    (0..n)
                        .map(|j| {
                            let moves =
                                model.is_ancestor(j, b) && model.joints[j].kind.is_revolute();
                            if moves {
                                world.axis[j][r]
                            } else {
                                zero
                            }
                        })
                        .collect()
                })
                .collect();
            let rot = world.rotation[b];
            let ri = mat_mul(g, &rot, &params.inertia[b]);
            let theta = mat_mul(g, &ri, &transpose(&rot));
            let m = params.mass[b];
            let times = |g: &mut Graph, j: &[Vec<Id>], x: &[Id]| -> V3 {
                [g.dot(&j[0], x), g.dot(&j[1], x), g.dot(&j[2], x)]
            };
            let jdot = |g: &mut Graph, j: &[Vec<Id>]| -> Vec<Vec<Id>> {
                j.iter().map(|row| g.time_derivative_many(row)).collect()
            };
            let jp_dot = jdot(g, &jp);
            let jr_dot = jdot(g, &jr);
            let omega = times(g, &jr, qd);
            let ap = times(g, &jp_dot, qd);
            let ar = times(g, &jr_dot, qd);
            let theta_omega = mat_vec(g, &theta, &omega);
            let gyro = cross(g, &omega, &theta_omega);
            let theta_ar = mat_vec(g, &theta, &ar);
            let moment: V3 = [0, 1, 2].map(|r| g.add(theta_ar[r], gyro[r]));
            let force: V3 = ap.map(|a| g.mul(m, a));
            let column = |j: usize, x: &[Vec<Id>]| -> V3 { [x[0][j], x[1][j], x[2][j]] };
            let mut mass_matrix = vec![vec![zero; n]; n];
            for i in 0..n {
                let (pi, ri) = (column(i, &jp), column(i, &jr));
                let theta_ri = mat_vec(g, &theta, &ri);
                for j in i..n {
                    let (pj, rj) = (column(j, &jp), column(j, &jr));
                    let translation = g.dot(&pi, &pj);
                    let translation = g.mul(m, translation);
                    let rotation = g.dot(&rj, &theta_ri);
                    let e = g.add(translation, rotation);
                    mass_matrix[i][j] = e;
                    mass_matrix[j][i] = e;
                }
            }
            let bias = (0..n)
                .map(|i| {
                    let (pi, ri) = (column(i, &jp), column(i, &jr));
                    let f = g.dot(&pi, &force);
                    let t = g.dot(&ri, &moment);
                    g.add(f, t)
                })
                .collect();
            BodyTerms {
                link: model.bodies[b].name.clone(),
                mass_matrix,
                bias,
            }
        })
        .collect()
}
