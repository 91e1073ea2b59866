//! Generates, exactly as a user's build script would, the robots the tests call: the reference
//! robots with each option under test (the reference robots themselves are generated once, in
//! `eomgen-generated`), a small arm with joint friction, rotor inertia and an inertia filled from
//! its collision box, and two bad-input robots.

#[path = "../codegen/tests/support/chain.rs"]
mod chain;

fn main() {
    // Independent of each other, so run on every core (the largest first): after a change to
    // eomgen, this script is on the path of every test of the crate.
    run_parallel(&[
        contact_dynamics,
        derivatives,
        floating,
        mimic,
        split,
        regressors,
        joint_effects,
        deep_chain,
        tree_route,
        underactuated,
        mpc_kinematics,
        bad_input,
        selected,
        joint_kinds,
    ]);
}

/// Runs each of `parts` once, on as many threads as the machine has cores; a panic in one is
/// the build script's.
fn run_parallel(parts: &[fn()]) {
    use std::sync::atomic::{AtomicUsize, Ordering};
    let next = AtomicUsize::new(0);
    let workers = std::thread::available_parallelism().map_or(1, |n| n.get());
    std::thread::scope(|s| {
        for _ in 0..workers.min(parts.len()) {
            s.spawn(|| {
                while let Some(part) = parts.get(next.fetch_add(1, Ordering::Relaxed)) {
                    part();
                }
            });
        }
    });
}

/// Bad-input robots: an ill-conditioned mass matrix, and names that try to break out of
/// comments and strings (compiled for real here, with rustc's default lints).
fn bad_input() {
    for (file, module, ty) in [
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

/// What a firmware that needs inverse dynamics alone generates (plus Craig's B, which brings
/// the Coriolis matrix it loops over).
fn selected() {
    eomgen::Builder::new("robots/panda.urdf")
        .module_name("panda_selected")
        .type_name("PandaSelected")
        .quantities(["inverse_dynamics", "gravity", "coriolis_pairs"])
        .compile()
        .unwrap();
}

/// `fixtures/joint_effects.urdf` three ways: rigid only, with friction and armature, and with
/// smoothed Coulomb friction. Its upper arm's inertia comes from its collision box; the two
/// warnings that produces (the filled link and a mesh-only one) are expected, so they are
/// checked here instead of printed by `compile()` on every build.
fn joint_effects() {
    let urdf = "fixtures/joint_effects.urdf";
    println!("cargo:rerun-if-changed={urdf}");
    let out_dir = std::path::PathBuf::from(std::env::var_os("OUT_DIR").unwrap());
    let base = || {
        eomgen::Builder::new(urdf)
            .inertia_from_collision(1000.0)
            .armature([("shoulder", 0.2), ("elbow", 0.05)])
    };
    for (module, ty, builder) in [
        (
            "joint_effects",
            "JointEffects",
            eomgen::Builder::new(urdf).inertia_from_collision(1000.0),
        ),
        (
            "joint_effects_full",
            "JointEffectsFull",
            base().friction(true),
        ),
        (
            "joint_effects_smooth",
            "JointEffectsSmooth",
            base().friction(true).coulomb_smoothing(0.05),
        ),
    ] {
        let (generated, model, _) = builder.type_name(ty).generate_with_report().unwrap();
        let warned: Vec<String> = model.warnings.iter().map(|w| w.to_string()).collect();
        assert!(
            warned.len() == 2 && warned[0].contains("`upper`") && warned[1].contains("`camera`"),
            "unexpected warnings: {warned:?}"
        );
        let path = out_dir.join(format!("{module}.rs"));
        eomgen::write_if_changed(&path, generated.source.as_bytes()).unwrap();
    }
}

/// A 28-joint serial chain, deep enough that forward dynamics solves at run time instead of
/// unrolling (only the functions the tests call, to keep the build small).
fn deep_chain() {
    let out_dir = std::path::PathBuf::from(std::env::var_os("OUT_DIR").unwrap());
    let urdf = chain::write_serial_chain(&out_dir, 28).unwrap();
    eomgen::Builder::new(&urdf)
        .module_name("chain28")
        .type_name("Chain28")
        .quantities(["forward_dynamics", "inverse_dynamics"])
        .compile()
        .unwrap();
}

/// What the anymal derivative robots generate (`tests/floating.rs`, `tests/tree_route.rs`): the
/// derivatives and what their checks call.
const ANYMAL_DERIVATIVES: [&str; 7] = [
    "inverse_dynamics",
    "forward_dynamics",
    "mass_matrix",
    "integrate",
    "inverse_dynamics_derivatives",
    "forward_dynamics_derivatives",
    "mass_matrix_inverse",
];

/// The floating-base reference robots: anymal standing on its four feet (contacts), and the same
/// without gravity (for momentum conservation); the iris drone (a free body, no joints) is in
/// `eomgen-generated`.
fn floating() {
    let feet = ["LF_FOOT", "RF_FOOT", "LH_FOOT", "RH_FOOT"];
    let anymal = || {
        eomgen::Builder::new("robots/floating/anymal.urdf")
            .floating_base()
            .contact_points(&feet)
    };
    anymal()
        .module_name("anymal")
        .type_name("Anymal")
        .compile()
        .unwrap();
    anymal()
        .gravity([0.0; 3])
        .module_name("anymal_weightless")
        .type_name("AnymalWeightless")
        .quantities([
            "forward_dynamics",
            "centroidal_map",
            "kinetic_energy",
            "integrate",
        ])
        .compile()
        .unwrap();
    // The derivatives with a floating base, q perturbed in its tangent space.
    eomgen::Builder::new("robots/floating/anymal.urdf")
        .floating_base()
        .derivatives()
        .module_name("anymal_derivatives")
        .type_name("AnymalDerivatives")
        .quantities(ANYMAL_DERIVATIVES)
        .compile()
        .unwrap();
}

/// anymal with `M^-1` and the forward-dynamics derivatives composed at run time through the
/// tree (`derivatives_flat_max_ops(0)`: the route of robots too large for straight-line
/// ones), for `tests/tree_route.rs`: a branched tree (a base and four legs).
fn tree_route() {
    eomgen::Builder::new("robots/floating/anymal.urdf")
        .floating_base()
        .derivatives()
        .derivatives_flat_max_ops(0)
        .module_name("anymal_tree_route")
        .type_name("AnymalTreeRoute")
        .quantities(ANYMAL_DERIVATIVES)
        .compile()
        .unwrap();
}

/// Contact and impulse dynamics with their derivatives (anymal on its four feet), only what
/// `tests/contact_dynamics.rs` calls.
fn contact_dynamics() {
    eomgen::Builder::new("robots/floating/anymal.urdf")
        .floating_base()
        .contact_points(&["LF_FOOT", "RF_FOOT", "LH_FOOT", "RH_FOOT"])
        .derivatives()
        .module_name("anymal_mpc")
        .type_name("AnymalMpc")
        .quantities(
            [
                "contact_forward_dynamics",
                "contact_forward_dynamics_derivatives",
                "impulse_dynamics",
                "impulse_dynamics_derivatives",
                "integrate",
                "center_of_mass",
                "link_pose",
                // Contacts switched at run time (tests/active_contacts.rs).
                "forward_dynamics",
                "inverse_dynamics",
                "contact_forward_dynamics_active",
                "contact_forward_dynamics_stabilized",
                "contact_forward_dynamics_derivatives_active",
                "impulse_dynamics_active",
                "impulse_dynamics_derivatives_active",
            ]
            .into_iter()
            .chain(ANYMAL_KINEMATICS),
        )
        .compile()
        .unwrap();
    // Two of the four feet (the first and the last), what `AnymalMpc`'s `_active` methods
    // must reproduce with the other two switched off.
    eomgen::Builder::new("robots/floating/anymal.urdf")
        .floating_base()
        .contact_points(&["LF_FOOT", "RH_FOOT"])
        .derivatives()
        .module_name("anymal_two_feet")
        .type_name("AnymalTwoFeet")
        .quantities([
            "contact_forward_dynamics",
            "contact_forward_dynamics_derivatives",
            "impulse_dynamics",
            "impulse_dynamics_derivatives",
        ])
        .compile()
        .unwrap();
    // Contact and impulse dynamics solved at run time (the route of robots over the
    // straight-line budget), on the same four feet (`tests/batch.rs`).
    eomgen::Builder::new("robots/floating/anymal.urdf")
        .floating_base()
        .contact_points(&["LF_FOOT", "RF_FOOT", "LH_FOOT", "RH_FOOT"])
        .contact_forward_dynamics_flat_max_ops(0)
        .module_name("anymal_solved")
        .type_name("AnymalSolved")
        .quantities(["contact_forward_dynamics", "impulse_dynamics"])
        .compile()
        .unwrap();
    // Contact points away from a link's origin: the last foot's 5 cm off.
    eomgen::Builder::new("robots/floating/anymal.urdf")
        .floating_base()
        .contact_points(&["LF_FOOT", "RF_FOOT"])
        .contact_point_at("LH_FOOT", [0.0; 3])
        .contact_point_at("RH_FOOT", [0.05, -0.02, 0.01])
        .module_name("anymal_at")
        .type_name("AnymalAt")
        .quantities([
            "contact_forward_dynamics",
            "link_jacobian",
            "link_pose",
            "integrate",
        ])
        .compile()
        .unwrap();
    humanoid_contacts();
}

/// Opt-in (`EOMGEN_TEST_HEAVY=1`, sets `cfg(heavy)`): 6D contacts at both soles of the g1
/// humanoid (only what the tests call). Its module is the largest of the tests (8.9 MB, 36 % of
/// all the generated code they compiled): too slow to compile on every test run.
fn humanoid_contacts() {
    if !opt_in("EOMGEN_TEST_HEAVY", "heavy") {
        return;
    }
    eomgen::Builder::new("robots/floating/g1_29dof.urdf")
        .floating_base()
        .contact_frames(&["left_ankle_roll_link", "right_ankle_roll_link"])
        .derivatives()
        .module_name("g1_mpc")
        .type_name("G1Mpc")
        .quantities([
            "contact_jacobian",
            "contact_drift",
            "contact_forward_dynamics",
            "contact_forward_dynamics_derivatives",
            "impulse_dynamics",
            "impulse_dynamics_derivatives",
            "contact_forward_dynamics_stabilized",
        ])
        .compile()
        .unwrap();
}

/// The reference robots with the derivatives of their dynamics and what those call.
fn derivatives() {
    for (file, module, ty) in [
        ("robots/ur5.urdf", "ur5_derivatives", "Ur5Derivatives"),
        ("robots/panda.urdf", "panda_derivatives", "PandaDerivatives"),
        (
            "robots/kinova.urdf",
            "kinova_derivatives",
            "KinovaDerivatives",
        ),
        (
            "robots/allegro_right_hand.urdf",
            "allegro_derivatives",
            "AllegroDerivatives",
        ),
    ] {
        with_derivatives(file, module, ty);
    }
    unshipped_derivatives();
    // Friction (smoothed, so that it is differentiable) and rotor inertia enter the
    // derivatives: checked against finite differences only (Pinocchio has neither).
    eomgen::Builder::new("fixtures/joint_effects.urdf")
        .module_name("joint_effects_derivatives")
        .type_name("JointEffectsDerivatives")
        .inertia_from_collision(1000.0)
        .armature([("shoulder", 0.2), ("elbow", 0.05)])
        .friction(true)
        .coulomb_smoothing(0.05)
        .derivatives()
        .quantities([
            "inverse_dynamics",
            "forward_dynamics",
            "inverse_dynamics_derivatives",
            "forward_dynamics_derivatives",
        ])
        .generate()
        .map(|source| {
            let out = std::path::PathBuf::from(std::env::var_os("OUT_DIR").unwrap());
            eomgen::write_if_changed(&out.join("joint_effects_derivatives.rs"), source.as_bytes())
                .unwrap();
        })
        .unwrap();
}

/// The reference robots with identification (and the inverse dynamics it must reproduce), and
/// the joint-effects arm with rotor inertia and friction as extra parameters.
fn regressors() {
    let only = [
        "inverse_dynamics",
        "regressor",
        "parameters",
        "base_regressor",
        "base_parameters",
    ];
    for (file, module, ty) in [
        (
            "robots/double_pendulum.urdf",
            "double_pendulum_regressor",
            "DoublePendulumRegressor",
        ),
        ("robots/ur5.urdf", "ur5_regressor", "Ur5Regressor"),
        ("robots/panda.urdf", "panda_regressor", "PandaRegressor"),
        ("robots/kinova.urdf", "kinova_regressor", "KinovaRegressor"),
        (
            "robots/allegro_right_hand.urdf",
            "allegro_regressor",
            "AllegroRegressor",
        ),
    ] {
        eomgen::Builder::new(file)
            .module_name(module)
            .type_name(ty)
            .regressor()
            .quantities(only)
            .compile()
            .unwrap();
    }
    let out_dir = std::path::PathBuf::from(std::env::var_os("OUT_DIR").unwrap());
    let (generated, _, _) = eomgen::Builder::new("fixtures/joint_effects.urdf")
        .inertia_from_collision(1000.0)
        .armature([("shoulder", 0.2), ("elbow", 0.05)])
        .friction(true)
        .type_name("JointEffectsRegressor")
        .regressor()
        .quantities(only)
        .generate_with_report()
        .unwrap();
    let path = out_dir.join("joint_effects_regressor.rs");
    eomgen::write_if_changed(&path, generated.source.as_bytes()).unwrap();
}

/// Opt-in (`EOMGEN_TEST_UNSHIPPED=1`, sets `cfg(unshipped)`): the derivatives of a 7-joint arm
/// that is not one of the five reference robots, example-robot-data's xArm 7. Its joint frames
/// are rotated by `rpy="1.5708 0 0"`, four decimals, so no entry is exactly 0 and its module is
/// large (110,000 lines, 10 MB): too slow to compile on every test run.
fn unshipped_derivatives() {
    if !opt_in("EOMGEN_TEST_UNSHIPPED", "unshipped") {
        return;
    }
    with_derivatives("robots/xarm7.urdf", "xarm7_derivatives", "Xarm7Derivatives");
}

/// Whether the environment variable `var` asks for an opt-in part of the tests; if so, the
/// crate is compiled with `cfg(name)` (declared either way, for rustc's `unexpected_cfgs`).
fn opt_in(var: &str, name: &str) -> bool {
    println!("cargo::rustc-check-cfg=cfg({name})");
    println!("cargo:rerun-if-env-changed={var}");
    let on = std::env::var_os(var).is_some();
    if on {
        println!("cargo:rustc-cfg={name}");
    }
    on
}

/// Robots with passive joints (`Builder::passive_joints`): the acrobot with its elbow passive,
/// and the panda with its last finger passive (the harness's choice: the last joint).
fn underactuated() {
    let urdf = "fixtures/acrobot.urdf";
    println!("cargo:rerun-if-changed={urdf}");
    eomgen::Builder::new(urdf)
        .module_name("acrobot")
        .type_name("Acrobot")
        .passive_joints(&["elbow"])
        .compile()
        .unwrap();
    eomgen::Builder::new("robots/ur5.urdf")
        .module_name("ur5_passive_wrist")
        .type_name("Ur5PassiveWrist")
        .passive_joints(&["wrist_1_joint", "wrist_3_joint"])
        .compile()
        .unwrap();
}

/// `file` with the derivatives of its dynamics, inverse dynamics and what those call.
fn with_derivatives(file: &str, module: &str, ty: &str) {
    derivatives_builder(file, module, ty).compile().unwrap();
}

/// The builder of [`with_derivatives`].
fn derivatives_builder(file: &str, module: &str, ty: &str) -> eomgen::Builder {
    eomgen::Builder::new(file)
        .module_name(module)
        .type_name(ty)
        .derivatives()
        .quantities([
            "inverse_dynamics",
            "inverse_dynamics_derivatives",
            "forward_dynamics_derivatives",
            "mass_matrix_inverse",
        ])
}

/// Mimic joints honoured (`Builder::mimic_joints`): the panda (its second finger follows the
/// first) against Pinocchio, and `fixtures/mimic_tree.urdf` (multipliers, offsets, a chain, a
/// prismatic and a cross-branch mimic) with joint friction and rotor inertia on mimic joints,
/// against the same tree generated without the option (every joint a coordinate).
fn mimic() {
    let tree = "fixtures/mimic_tree.urdf";
    println!("cargo:rerun-if-changed={tree}");
    let effects = |b: eomgen::Builder| {
        b.friction(true).coulomb_smoothing(0.05).armature([
            ("a2", 0.01),
            ("b2", 0.02),
            ("j1", 0.05),
        ])
    };
    for (module, ty, builder) in [
        (
            "panda_mimic",
            "PandaMimic",
            eomgen::Builder::new("robots/panda.urdf")
                .mimic_joints()
                .derivatives()
                .regressor(),
        ),
        (
            "mimic_tree",
            "MimicTree",
            effects(eomgen::Builder::new(tree))
                .mimic_joints()
                .derivatives()
                .regressor(),
        ),
        (
            "mimic_tree_full",
            "MimicTreeFull",
            effects(eomgen::Builder::new(tree)).regressor(),
        ),
        (
            "mimic_tree_floating",
            "MimicTreeFloating",
            eomgen::Builder::new(tree)
                .floating_base()
                .contact_points(&["tip", "lb2"])
                .mimic_joints(),
        ),
        (
            "mimic_tree_floating_full",
            "MimicTreeFloatingFull",
            eomgen::Builder::new(tree)
                .floating_base()
                .contact_points(&["tip", "lb2"]),
        ),
    ] {
        builder.module_name(module).type_name(ty).compile().unwrap();
    }
}

/// Bodies split into many blocks (`Builder::max_function_ops`), for comparison with the same
/// robots generated whole: the ur5's derivatives and anymal on its feet.
fn split() {
    derivatives_builder("robots/ur5.urdf", "ur5_split", "Ur5Split")
        .max_function_ops(60)
        .compile()
        .unwrap();
    eomgen::Builder::new("robots/floating/anymal.urdf")
        .floating_base()
        .contact_points(&["LF_FOOT", "RF_FOOT", "LH_FOOT", "RH_FOOT"])
        .module_name("anymal_split")
        .type_name("AnymalSplit")
        .max_function_ops(150)
        .compile()
        .unwrap();
}

/// The MPC kit's kinematics (frame motion, the configuration manifold, the centroidal momentum
/// rate) of the panda and anymal, with the functions their checks compare with.
fn mpc_kinematics() {
    let kit = [
        "link_jacobian",
        "link_velocity",
        "link_acceleration",
        "link_jacobian_time_variation",
        "difference",
        "integrate_jacobians",
        "difference_jacobians",
    ];
    eomgen::Builder::new("robots/panda.urdf")
        .module_name("panda_mpc")
        .type_name("PandaMpc")
        .quantities(kit)
        .compile()
        .unwrap();
    // anymal's kinematics are in `anymal_mpc` with its contact dynamics (`contact_dynamics`).
}

/// The MPC kit's kinematics that `tests/mpc_kinematics.rs` calls on anymal (besides the contact
/// functions of `contact_dynamics`, in the same module).
const ANYMAL_KINEMATICS: [&str; 9] = [
    "link_jacobian",
    "link_velocity",
    "link_acceleration",
    "link_jacobian_time_variation",
    "difference",
    "integrate_jacobians",
    "difference_jacobians",
    "centroidal_map",
    "centroidal_momentum_rate",
];

/// Planar joints and floating joints below the root (`tests/joints.rs`).
fn joint_kinds() {
    for name in ["mobile_manipulator", "crane_payload", "rover_pods"] {
        let urdf = format!("robots/joints/{name}.urdf");
        eomgen::Builder::new(&urdf).derivatives().compile().unwrap();
    }
}
