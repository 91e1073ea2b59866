//! Generates the example robots, as a user's build script would: `$OUT_DIR/panda_arm.rs`
//! defines `PandaArm<T>` (7 joints) and `PandaArmLink`; `$OUT_DIR/anymal.rs` the quadruped
//! `Anymal<T>` with a floating base and point contacts at its four feet; `$OUT_DIR/ur5.rs`
//! defines `Ur5<T>` (6 joints) with identification (`regressor`, `base_regressor`,
//! `base_parameters`); `$OUT_DIR/anymal_mpc.rs` the quadruped again as `AnymalMpc<T>`, with
//! only what an MPC step needs: contact dynamics with its derivatives, for a set of active
//! feet, and the configuration manifold.

fn main() {
    eomgen::Builder::new("robots/panda_arm.urdf")
        .compile()
        .unwrap();
    eomgen::Builder::new("../tests/robots/floating/anymal.urdf")
        .floating_base()
        .contact_points(&["LF_FOOT", "RF_FOOT", "LH_FOOT", "RH_FOOT"])
        .compile()
        .unwrap();
    eomgen::Builder::new("../tests/robots/floating/anymal.urdf")
        .floating_base()
        .contact_points(&["LF_FOOT", "RF_FOOT", "LH_FOOT", "RH_FOOT"])
        .derivatives()
        .module_name("anymal_mpc")
        .type_name("AnymalMpc")
        .quantities([
            "contact_forward_dynamics_active",
            "contact_forward_dynamics_derivatives_active",
            "integrate",
            "difference",
            "integrate_jacobians",
            "difference_jacobians",
        ])
        .compile()
        .unwrap();
    eomgen::Builder::new("robots/ur5.urdf")
        .type_name("Ur5")
        .regressor()
        .compile()
        .unwrap();
}
