//! A robot generated with only some quantities (`Builder::quantities`) is a working subset:
//! the selected functions, as inherent methods, match Pinocchio like the full robot's do.

use eomgen_tests::robots::panda_selected::PandaSelected;
use eomgen_tests::{load, Checker, JointMap};

#[test]
fn selected_functions_match_pinocchio() {
    let robot = PandaSelected::<f64>::default();
    let reference = load("panda");
    let names = PandaSelected::<f64>::JOINT_NAMES;
    let map = JointMap::new(&reference.joints, &names);
    let arr = |v: &[f64]| -> [f64; 9] {
        let ours = map.to_ours(v);
        core::array::from_fn(|i| ours[i])
    };
    let mut c = Checker::new(1e-9);
    let mut craig_checked = 0;
    for (s, sm) in reference.samples.iter().enumerate() {
        let (q, qd, qdd) = (arr(&sm.q), arr(&sm.qd), arr(&sm.qdd));
        let tau = robot.inverse_dynamics(&q, &qd, &qdd);
        let g = robot.gravity(&q);
        for i in 0..9 {
            let o = map.ours[i];
            c.check(|| format!("#{s} tau[{i}]"), tau[o], sm.tau[i]);
            c.check(|| format!("#{s} G[{i}]"), g[o], sm.gravity[i]);
        }
        if let Some(cp) = &sm.coriolis_pairs {
            let b = robot.coriolis_pairs(&q);
            for i in 0..9 {
                for (p, want) in cp[i].iter().enumerate() {
                    let (j, k) = eomgen::dynamics::pairs(9)[p];
                    let ours = map.pair(j, k);
                    c.check(|| format!("#{s} B[{i}][{p}]"), b[map.ours[i]][ours], *want);
                }
            }
            craig_checked += 1;
        }
    }
    assert!(
        craig_checked > 0,
        "the reference has Craig's B for some samples"
    );
    c.finish("panda with selected quantities");
}
