//! Generates the example robots, as a user's build script would: `$OUT_DIR/panda_arm.rs`
//! defines `PandaArm<T>` (7 joints) and `PandaArmLink`; `$OUT_DIR/anymal.rs` the quadruped
//! `Anymal<T>` with a floating base and point contacts at its four feet.

fn main() {
    eomgen::Builder::new("robots/panda_arm.urdf")
        .compile()
        .unwrap();
    eomgen::Builder::new("robots/anymal.urdf")
        .floating_base()
        .contact_points(&["LF_FOOT", "RF_FOOT", "LH_FOOT", "RH_FOOT"])
        .compile()
        .unwrap();
}
