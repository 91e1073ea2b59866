//! Floating bases on the command line: `--floating-base`, `--contact`, a URDF `floating` joint
//! from a world link, and the commands that do not take a floating base yet saying so.

mod support;

use support::{eomgen, one_line_error, robot, scratch};

fn stdout(out: &std::process::Output) -> String {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout.clone()).unwrap()
}

/// Two links hanging from each other, the first attached to a massless world link by a
/// floating joint.
const TWO_LINKS: &str = r#"<robot name="two_links">
  <link name="world"/>
  <link name="trunk"><inertial><origin xyz="0 0 0.1"/><mass value="2"/>
    <inertia ixx="0.02" ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.04"/></inertial></link>
  <link name="arm"><inertial><origin xyz="0 0 -0.2"/><mass value="0.5"/>
    <inertia ixx="0.004" ixy="0" ixz="0" iyy="0.004" iyz="0" izz="0.001"/></inertial></link>
  <joint name="free" type="floating"><parent link="world"/><child link="trunk"/></joint>
  <joint name="hinge" type="revolute"><parent link="trunk"/><child link="arm"/>
    <axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="10" velocity="3"/></joint>
</robot>"#;

#[test]
fn show_prints_the_floating_equations_of_a_drone() {
    let urdf = robot("floating/iris_simple");
    let text = stdout(&eomgen(&[
        "show",
        "--floating-base",
        urdf.to_str().unwrap(),
    ]));
    assert!(text.contains("S^T tau + J_c(q)^T F_c"), "{text}");
    assert!(text.contains("base orientation, unit quaternion x, y, z, w"));
    // Six velocity coordinates, no joint: tau has six rows and no Craig matrices.
    assert!(
        text.contains("tau6 = ") && !text.contains("tau7 = "),
        "{text}"
    );
    assert!(!text.contains("Craig"), "{text}");
}

#[test]
fn a_floating_joint_from_a_world_link_floats() {
    let dir = scratch("floating-joint");
    let path = dir.join("two_links.urdf");
    std::fs::write(&path, TWO_LINKS).unwrap();
    let path = path.to_str().unwrap();
    let info = stdout(&eomgen(&["info", path]));
    assert!(
        info.contains("degrees of freedom: 1 joints + 6 of the floating base (NQ 8, NV 7)"),
        "{info}"
    );
    assert!(info.contains("trunk (floating base, 2 kg)"), "{info}");
    let shown = stdout(&eomgen(&["show", "--term", "tau", path]));
    assert!(shown.contains("tau7 = "), "{shown}");
    let code = stdout(&eomgen(&["generate", path]));
    assert!(code.contains("pub const NQ: usize = 8;"));
    assert!(code.contains("pub fn integrate(&self, q: &[T; 8], qd: &[T; 7], dt: T) -> [T; 8]"));
}

#[test]
fn contacts_are_generated_and_regenerate_line_carries_them() {
    let urdf = robot("floating/anymal");
    let code = stdout(&eomgen(&[
        "generate",
        "--floating-base",
        "--contact",
        "LF_FOOT",
        "--contact",
        "RH_FOOT",
        "--only",
        "contact_forward_dynamics",
        urdf.to_str().unwrap(),
    ]));
    assert!(code.contains("--floating-base --contact LF_FOOT --contact RH_FOOT"));
    assert!(code.contains("pub fn contact_forward_dynamics("));
    assert!(code.contains(") -> ([T; 18], [T; 6])"));
    assert!(code.contains("pub fn contact_jacobian(&self, q: &[T; 19]) -> [[T; 18]; 6]"));
}

#[test]
fn bad_floating_requests_get_one_line_errors() {
    let urdf = robot("floating/anymal");
    let urdf = urdf.to_str().unwrap();
    let e = one_line_error(&eomgen(&[
        "generate",
        "--floating-base",
        "--contact",
        "LF_TOE",
        urdf,
    ]));
    assert!(
        e.contains("contact point requested at link `LF_TOE`, which does not exist"),
        "{e}"
    );
    let e = one_line_error(&eomgen(&[
        "generate",
        "--floating-base",
        "--derivatives",
        urdf,
    ]));
    assert!(
        e.contains("derivatives of a floating-base robot are not generated yet"),
        "{e}"
    );
    let e = one_line_error(&eomgen(&["eval", "--floating-base", urdf, "--q", "0"]));
    assert!(e.contains("does not handle a floating base yet"), "{e}");
}
