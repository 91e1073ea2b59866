//! Generates the example robot, as a user's build script would: `$OUT_DIR/panda_arm.rs`
//! defines `PandaArm<T>` (7 joints) and `PandaArmLink`.

fn main() {
    eomgen::Builder::new("robots/panda_arm.urdf")
        .compile()
        .unwrap();
}
