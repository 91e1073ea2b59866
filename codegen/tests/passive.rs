//! `Builder::passive_joints`: what is generated, and the errors naming the file and joint.

const URDF: &str = r#"<robot name="acrobot"><link name="base"/>
  <link name="upper"><inertial><origin xyz="0 0 -0.5"/><mass value="1"/>
  <inertia ixx="0.08" ixy="0" ixz="0" iyy="0.08" iyz="0" izz="0.001"/></inertial></link>
  <link name="lower"><inertial><origin xyz="0 0 -0.5"/><mass value="1"/>
  <inertia ixx="0.08" ixy="0" ixz="0" iyy="0.08" iyz="0" izz="0.001"/></inertial></link>
  <link name="tip"/>
  <joint name="shoulder" type="continuous"><parent link="base"/><child link="upper"/>
  <axis xyz="0 1 0"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="lower"/>
  <origin xyz="0 0 -1"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="10" velocity="5"/></joint>
  <joint name="tip_joint" type="fixed"><parent link="lower"/><child link="tip"/>
  <origin xyz="0 0 -1"/></joint></robot>"#;

fn generate(passive: &[&str]) -> Result<String, String> {
    eomgen::Builder::from_urdf_str(URDF, "acrobot.urdf")
        .passive_joints(passive)
        .generate()
        .map_err(|e| e.to_string())
}

#[test]
fn passive_elbow() {
    let source = generate(&["elbow"]).unwrap();
    for item in [
        "pub const NA: usize = 1;",
        r#"pub const ACTUATED_JOINT_NAMES: [&'static str; 1] = ["shoulder"];"#,
        "pub const ACTUATED_JOINTS: [usize; 1] = [0];",
        "pub const PASSIVE_JOINTS: [usize; 1] = [1];",
        "pub fn selection() -> [[T; 2]; 1]",
        "pub fn full_effort(tau_a: &[T; 1]) -> [T; 2]",
        "pub fn forward_dynamics_actuated(",
        "impl<T: ::eomgen_runtime::Lane> ::eomgen_runtime::Dynamics<T, 2> for Acrobot<T>",
        "--passive elbow",
    ] {
        assert!(source.contains(item), "missing {item}");
    }
    // Listing a joint twice counts once; the order of the list does not matter.
    assert!(generate(&["elbow", "elbow"]).unwrap() == source);
}

#[test]
fn no_passive_joint_generates_nothing_new() {
    let source = generate(&[]).unwrap();
    assert!(!source.contains("ACTUATED_JOINT_NAMES"));
    assert!(!source.contains("forward_dynamics_actuated"));
}

#[test]
fn errors_name_the_file_and_the_joint() {
    assert_eq!(
        generate(&["wrist"]).unwrap_err(),
        "acrobot.urdf: passive joints: joint `wrist` does not exist"
    );
    assert_eq!(
        generate(&["tip_joint"]).unwrap_err(),
        "acrobot.urdf: passive joints: joint `tip_joint` is fixed: only moving joints can be passive"
    );
    assert_eq!(
        generate(&["shoulder", "elbow"]).unwrap_err(),
        "acrobot.urdf: passive joints: every joint is passive (the last named: `elbow`): at least one must be actuated"
    );
    let floating = eomgen::Builder::from_urdf_str(URDF, "acrobot.urdf")
        .floating_base()
        .passive_joints(&["elbow"])
        .generate()
        .unwrap_err()
        .to_string();
    assert!(
        floating.starts_with("acrobot.urdf: passive joints: joint `elbow` cannot be made passive on a floating-base robot"),
        "{floating}"
    );
}
