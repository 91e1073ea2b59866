//! A floating-base robot's `FloatingDynamics` and `Contacts` methods are reached through the
//! prelude, as a fixed base's `Dynamics` methods are: `use eomgen_runtime::prelude::*;` (what
//! the README says to write) is used, not reported as an unused import. They used to be
//! inherent methods too, which Rust prefers, leaving the import unused.

#![deny(unused_imports)]

use eomgen_runtime::prelude::*;
use eomgen_tests::robots::anymal::Anymal;

#[test]
fn floating_and_contact_methods_come_from_the_prelude() {
    let r = Anymal::<f64>::default();
    let mut q = [0.0; Anymal::NQ];
    q[6] = 1.0;
    let v = [0.0; Anymal::NV];
    let m = r.mass_matrix(&q);
    let g = r.gravity(&q);
    let b = r.bias(&q, &v);
    assert!(m[0][0] > 0.0 && g.iter().all(|x| x.is_finite()));
    assert!(b.iter().all(|x| *x == 0.0));
    // Holding the base up against gravity: no acceleration.
    let a = r.forward_dynamics(&q, &v, &g);
    assert!(a.iter().all(|x| x.abs() < 1e-9), "{a:?}");
    let tau = r.inverse_dynamics(&q, &v, &a);
    assert!(tau.iter().zip(&g).all(|(t, g)| (t - g).abs() < 1e-9));
    assert_eq!(r.integrate(&q, &v, 0.1), q);
    let j = r.contact_jacobian(&q);
    let drift = r.contact_drift(&q, &v);
    assert_eq!(j.len(), drift.len());
    let (qdd, f) = r
        .try_contact_forward_dynamics(&q, &v, &[0.0; Anymal::NV])
        .unwrap();
    assert!(qdd.iter().chain(&f).all(|x| x.is_finite()));
}
