//! Generates the reference robots exactly as a user's build script would.

fn main() {
    for (file, module, ty) in [
        (
            "robots/double_pendulum.urdf",
            "double_pendulum",
            "DoublePendulum",
        ),
        ("robots/ur5.urdf", "ur5", "Ur5"),
        ("robots/panda.urdf", "panda", "Panda"),
        ("robots/kinova.urdf", "kinova", "Kinova"),
        (
            "robots/allegro_right_hand.urdf",
            "allegro_right_hand",
            "AllegroRightHand",
        ),
    ] {
        eomgen::Builder::new(file)
            .module_name(module)
            .type_name(ty)
            .compile()
            .unwrap();
    }
}
