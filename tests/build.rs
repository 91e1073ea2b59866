//! Generates the reference robots, and two bad-input robots, exactly as a user's build script
//! would.

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
        // Bad-input robots: an ill-conditioned mass matrix, and names that try to break out
        // of comments and strings (compiled for real here, with rustc's default lints).
        ("urdf/light_tip.urdf", "light_tip", "LightTip"),
        (
            "../codegen/tests/urdf/hostile/names.urdf",
            "hostile_names",
            "HostileNames",
        ),
    ] {
        eomgen::Builder::new(file)
            .module_name(module)
            .type_name(ty)
            .compile()
            .unwrap();
    }
}
