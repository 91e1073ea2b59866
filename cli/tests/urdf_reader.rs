//! The URDF reader's errors and its inertia repair through the command line: one line per
//! error, each at its line and column; `--repair-inertia` loads an impossible inertia with a
//! warning.

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

/// Runs `eomgen ARGS FILE` on `text` written to a scratch file named `name` (in a scratch
/// directory removed on return).
fn cli(name: &str, text: &str, args: &[&str]) -> std::process::Output {
    let (_guard, dir) = crate::support::scratch("reader");
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    std::process::Command::new(env!("CARGO_BIN_EXE_eomgen"))
        .args(args)
        .arg(&path)
        .output()
        .unwrap()
}

#[test]
fn the_cli_prints_each_error_on_its_own_line_and_repairs_on_request() {
    let two_errors = arm(
        "",
        r#"<axis xyz="0 1"/><limit lower="x" velocity="1"/>"#,
        "",
    );
    let out = cli("two.urdf", &two_errors, &["info"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1));
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 2, "{stderr}");
    assert!(
        lines[0].starts_with("eomgen: error: ")
            && lines[0].contains("two.urdf:10:16: joint `elbow`: <axis xyz>"),
        "{stderr}"
    );
    assert!(
        lines[1].contains("two.urdf:10:36: joint `elbow`: <limit lower>: `x` is not a number"),
        "{stderr}"
    );

    let impossible = arm("", "", "").replace(r#"izz="0.01""#, r#"izz="0.03""#);
    let out = cli("impossible.urdf", &impossible, &["info"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("link `tip` has an impossible inertia")
            && stderr.contains("0.03 <= 0.01 + 0.01")
            && stderr.contains("--repair-inertia"),
        "{stderr}"
    );
    let out = cli(
        "impossible.urdf",
        &impossible,
        &["info", "--repair-inertia"],
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.starts_with("eomgen: warning: ")
            && stderr.contains("repaired (as MuJoCo's balanceinertia does) to principal moments 0.0166667, 0.0166667, 0.0166667 kg m^2"),
        "{stderr}"
    );
}
