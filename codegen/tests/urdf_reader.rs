//! The URDF reader: strict where dynamics reads, tolerant of markup it never reads, every
//! problem at its line and column, all the errors of a file at once.

use eomgen::model::{ModelError, ModelOptions, ModelWarning};
use eomgen::urdf::{load_str, load_str_with_warnings, MAX_ERRORS};

const FILE: &str = "r.urdf";

/// A one-joint arm; `tip_extra` goes inside the moving link, `joint_extra` inside the joint,
/// `top` at the end of the robot. Line numbers in the tests count from this layout.
fn arm(tip_extra: &str, joint_extra: &str, top: &str) -> String {
    format!(
        r#"<robot name="r">
  <link name="base"/>
  <link name="tip">
    <inertial><origin xyz="0 0 0.1"/><mass value="1"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    {tip_extra}
  </link>
  <joint name="elbow" type="revolute">
    <parent link="base"/><child link="tip"/>
    {joint_extra}
  </joint>
  {top}
</robot>"#
    )
}

/// Loads `text`, expecting success; returns the warnings as text.
fn warnings(text: &str) -> Vec<String> {
    let model = load_str(text, FILE, &ModelOptions::default()).unwrap();
    model.warnings.iter().map(|w| w.to_string()).collect()
}

/// Loads `text`, expecting format errors; returns their lines.
fn errors(text: &str) -> Vec<String> {
    match load_str(text, FILE, &ModelOptions::default()) {
        Err(e @ ModelError::Format { .. }) => e.to_string().lines().map(String::from).collect(),
        other => panic!("expected format errors, got {other:?}"),
    }
}

#[test]
fn markup_dynamics_never_reads_gives_warnings_with_places() {
    // The markup that made real robots fail: a texture without a file (icub), a material in a
    // geometry (racecar), a mesh scale of four numbers (racecar_differential), unknown
    // elements.
    let visual = r#"<visual><geometry><mesh filename="a.stl" scale="1 1 1 1"/><material name="m"/></geometry>
      <material name="skin"><texture/><color rgba="1 0 0"/></material></visual>"#;
    let top = r#"<gazebo reference="tip"/><transmission name="t"/><camera/>"#;
    let w = warnings(&arm(visual, "<calibration rising=\"0\"/>", top));
    let expected = [
        "r.urdf:6:53: link `tip`: <mesh scale>: `1 1 1 1` holds 4 number(s) where 3 are expected",
        "r.urdf:6:63: link `tip`: unknown element <material> in <geometry> ignored",
        "r.urdf:7:29: link `tip`: <texture> has no `filename` attribute",
        "r.urdf:7:52: link `tip`: <color rgba>: `1 0 0` holds 3 number(s) where 4 are expected",
        "r.urdf:13:52: unknown element <camera> in <robot> ignored",
    ];
    assert_eq!(w, expected);
}

#[test]
fn identical_repeats_warn_and_conflicting_ones_are_errors() {
    let twice = r#"<axis xyz="0 1 0"/>
    <axis xyz="0 1 0"/>"#;
    let w = warnings(&arm("", twice, ""));
    assert_eq!(
        w,
        ["r.urdf:11:5: joint `elbow`: <axis> repeated with the same content (first at 10:5): ignored"]
    );
    // Attribute order does not matter.
    let origins = r#"<origin xyz="1 0 0" rpy="0 0 1"/><origin rpy="0 0 1" xyz="1 0 0"/>"#;
    assert_eq!(warnings(&arm("", origins, "")).len(), 1);
    let conflict = twice.replacen("0 1 0", "0 0 1", 1);
    assert_eq!(
        errors(&arm("", &conflict, "")),
        ["r.urdf:11:5: joint `elbow`: a second <axis> with different content (the first is at 10:5)"]
    );
}

#[test]
fn every_error_of_a_file_comes_at_once_each_at_its_place() {
    let text = r#"<robot name="r">
  <link name="base"/>
  <link name="tip"><inertial><mass value="1,5"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0"/></inertial></link>
  <joint name="torso_to_rightleg" type="revolute">
    <parent link="base"/><child link="tip"/>
    <limit lower="-1.57." upper="1.57" effort="1" velocity="1"/>
  </joint>
  <joint name="j2" type="hinge"><parent link="tip"/></joint>
</robot>"#;
    assert_eq!(
        errors(text),
        [
            "r.urdf:3:43: link `tip`: <mass value>: `1,5` is not a number",
            "r.urdf:4:5: link `tip`: <inertia> has no `izz` attribute",
            "r.urdf:7:19: joint `torso_to_rightleg`: <limit lower>: `-1.57.` is not a number",
            "r.urdf:9:3: joint `j2`: <joint> has no <child>",
            "r.urdf:9:26: joint `j2`: unknown joint type `hinge` (revolute, continuous, \
             prismatic, fixed, floating, planar or spherical expected)",
        ]
    );
}

#[test]
fn errors_are_capped_and_counted() {
    let bad_links: String = (0..MAX_ERRORS + 5)
        .map(|i| format!("<link name=\"l{i}\"><inertial><mass/></inertial></link>\n"))
        .collect();
    let text = format!("<robot name=\"r\">\n{bad_links}</robot>");
    let err = load_str(&text, FILE, &ModelOptions::default()).unwrap_err();
    let ModelError::Format { issues, more, .. } = &err else {
        panic!("{err}");
    };
    // Each link lacks its <inertia> and its mass value: two errors per link.
    assert_eq!(
        (issues.len(), *more),
        (MAX_ERRORS, 2 * (MAX_ERRORS + 5) - MAX_ERRORS)
    );
    let lines: Vec<String> = err.to_string().lines().map(String::from).collect();
    assert_eq!(lines.len(), MAX_ERRORS);
    assert!(lines[0].starts_with("r.urdf:2:"), "{}", lines[0]);
    assert!(lines[MAX_ERRORS - 1].ends_with("(and 30 more errors not shown)"));
}

#[test]
fn warnings_survive_a_refusal() {
    // A warning from the markup, then a refusal for a massless joint that --density helps.
    let text = r#"<robot name="r">
  <link name="base"/>
  <link name="tip"><visual><geometry><mesh/></geometry></visual>
    <collision><geometry><box size="0.1 0.1 0.5"/></geometry></collision></link>
  <joint name="elbow" type="revolute"><parent link="base"/><child link="tip"/></joint>
</robot>"#;
    let (result, warnings) = load_str_with_warnings(text, FILE, &ModelOptions::default());
    let err = result.unwrap_err().to_string();
    assert!(
        err.contains("joint `elbow` moves nothing")
            && err.contains("`tip` in its subtree have no <inertial> but a <collision>")
            && err.contains("--density"),
        "{err}"
    );
    assert!(
        matches!(&warnings[..], [ModelWarning::Markup { issue, .. }]
            if issue.message == "<mesh> has no `filename` attribute" && issue.line == 3),
        "{warnings:?}"
    );
    // With the density, it loads and no longer suggests it.
    let options = ModelOptions {
        inertia_from_collision: Some(1000.0),
        ..ModelOptions::default()
    };
    let model = load_str(text, FILE, &options).unwrap();
    assert_eq!(model.warnings.len(), 2, "{:?}", model.warnings);
}

#[test]
fn namespaced_elements_are_not_urdf_elements() {
    // A leftover xacro element is unknown markup, even when its local name is `link`.
    let top = r#"<xacro:link xmlns:xacro="http://www.ros.org/wiki/xacro" name="ghost"/>"#;
    let model = load_str(&arm("", "", top), FILE, &ModelOptions::default()).unwrap();
    assert_eq!(model.frames.len(), 2);
    assert!(model.warnings[0]
        .to_string()
        .contains("unknown element <xacro:link> in <robot> ignored"));
}
