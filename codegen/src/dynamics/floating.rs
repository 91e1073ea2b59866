//! The derivation of a floating-base robot: the recursive algorithms on the local model whose
//! body 0 is the base, moved by a free flyer (`q`: 7 position coordinates, `v`: 6 velocity
//! coordinates in base axes, as Pinocchio's `JointModelFreeFlyer`).
//!
//! The closed Lagrangian forms do not apply (the base's velocity coordinates are not the time
//! derivatives of its position coordinates), so every quantity takes the recursive route, and
//! Craig's velocity-product matrices are not generated.

use super::{
    finish, lagrangian, newton_euler, recursive, Centroidal, Clock, CoordinateMap, Derivation,
    Fast, JointTransform, Route,
};
use crate::cas::{Graph, GraphFull, Id, Limits};
use crate::kinematics::{const_v3, Params, WorldKinematics};
use crate::model::Model;

/// Derives every quantity of a floating-base `model`. With coupled joints (mimic joints) the
/// joint tree runs in the joints' coordinates and is projected, as for a fixed base (see
/// `coupling`): the base's coordinates are never coupled.
pub(super) fn derive(model: &Model, limits: Limits) -> Result<Derivation, GraphFull> {
    let mut clock = Clock::new();
    let mut g = Graph::with_limits(limits);
    let map = CoordinateMap::new(model);
    let (nq, nv) = (map.positions_len(), map.coordinates());
    let q: Vec<Id> = (0..nq).map(|i| g.q(i)).collect();
    let qd: Vec<Id> = (0..nv).map(|i| g.qd(i)).collect();
    let qdd: Vec<Id> = (0..nv).map(|i| g.qdd(i)).collect();
    let (joint_q, joint_qd, joint_qdd) = (
        map.positions(&mut g, &q),
        map.rates(&mut g, &qd),
        map.rates(&mut g, &qdd),
    );
    let params = Params::new(&mut g, model);
    let world = WorldKinematics::new(&mut g, model, &params, &joint_q);
    let lm = newton_euler::LocalModel::new(&mut g, model, &params, &joint_q);
    g.check()?;
    clock.lap("kinematics");
    let grav = const_v3(&mut g, &model.gravity);
    let base = model.base_nv();
    let mut joint_friction = vec![g.zero(); base];
    joint_friction.extend(lagrangian::joint_friction(
        &mut g,
        model,
        &params,
        &joint_qd[base..],
    ));
    let friction = map.project(&mut g, &joint_friction);
    let joint_rec = recursive(&mut g, &lm, grav, &joint_qd, &joint_qdd, &joint_friction)?;
    // The centroidal quantities from the base's rows of the joint tree's M, then projected.
    let centroidal = Centroidal::new(
        &mut g,
        model,
        &lm,
        &world,
        &joint_qd,
        &joint_rec.mass_matrix,
    );
    let centroidal = centroidal.projected(&mut g, &map);
    let rec = joint_rec.projected(&mut g, &map);
    clock.lap("recursive algorithms");
    let potential_energy = {
        // V = -sum m g.c
        let gc = g.dot(&grav, &centroidal.first_moment);
        g.neg(gc)
    };
    let tau_in: Vec<Id> = (0..nv).map(|i| g.tau(i)).collect();
    let h: Vec<Id> = (0..nv)
        .map(|i| g.add(rec.bias_and_gravity[i], friction[i]))
        .collect();
    let rhs: Vec<Id> = (0..nv).map(|i| g.sub(tau_in[i], h[i])).collect();
    let parents = map.parents(model, lm.coordinate_parents());
    let (forward_dynamics, pivots) =
        newton_euler::ltdl_solve(&mut g, &parents, &rec.mass_matrix, &rhs);
    g.check()?;
    clock.lap("forward dynamics and centroidal quantities");
    let r = Route::Recursive;
    let fast = Fast {
        mass_matrix: (r, rec.mass_matrix.clone()),
        gravity: (r, rec.gravity.clone()),
        bias: (r, rec.bias.clone()),
        tau: (r, rec.tau.clone()),
        coriolis_matrix: (r, rec.coriolis_matrix.clone()),
        centrifugal: None,
        coriolis_pairs: None,
        kinetic_energy: rec.kinetic_energy,
        kinetic_energy_route: r,
        tau_in,
        bias_gravity_friction: h,
        forward_dynamics,
        pivots,
    };
    let joint_transforms = (0..lm.bodies())
        .map(|i| JointTransform {
            rotation: lm.rotation[i],
            translation: lm.translation[i],
        })
        .collect();
    let d = Derivation {
        graph: g,
        dof: nv,
        nq,
        q,
        qd,
        qdd,
        params: params.symbols,
        mass_matrix: rec.mass_matrix.clone(),
        gravity: rec.gravity.clone(),
        centrifugal: Vec::new(),
        coriolis_pairs: Vec::new(),
        coriolis_matrix: rec.coriolis_matrix.clone(),
        bias: rec.bias.clone(),
        tau: rec.tau.clone(),
        friction,
        kinetic_energy: rec.kinetic_energy,
        potential_energy,
        joint_transforms,
        coordinate_parents: parents,
        identification: None,
        centroidal,
        recursive: rec,
        fast,
        quantities: Vec::new(),
        timings: Vec::new(),
    };
    Ok(finish(d, model, clock))
}
