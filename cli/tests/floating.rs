//! Floating bases on the command line: `--floating-base`, `--contact`, a URDF `floating` joint
//! from a world link, `eval` on a floating base, and one-line errors for bad requests.

use crate::support;

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
    let (_guard, dir) = scratch("floating-joint");
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
    // A `FloatingDynamics` method: in the trait impl, not `pub`.
    assert!(code.contains("    fn integrate(&self, q: &[T; 8], qd: &[T; 7], dt: T) -> [T; 8]"));
    assert!(!code.contains("pub fn integrate("));
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
    // A `Contacts` method: in the trait impl, not `pub`.
    assert!(code.contains("    fn contact_jacobian(&self, q: &[T; 19]) -> [[T; 18]; 6]"));
    assert!(!code.contains("pub fn contact_jacobian("));
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
        "--regressor",
        urdf,
    ]));
    assert!(
        e.contains("the regressor of a floating-base robot is not generated yet"),
        "{e}"
    );
    let e = one_line_error(&eomgen(&["eval", "--floating-base", urdf, "--q", "0"]));
    assert!(
        e.contains("--q has 1 value(s), but anymal has 19 position coordinates"),
        "{e}"
    );
}

/// `eval` on a floating base: Pinocchio's forward dynamics and bias, joints matched by name.
#[test]
fn eval_takes_a_floating_base() {
    let urdf = robot("floating/anymal");
    let doc = reference(&urdf);
    let refs: Vec<&str> = doc["joints"]
        .as_array()
        .unwrap()
        .iter()
        .map(|j| j.as_str().unwrap())
        .collect();
    let sample = &doc["samples"][1];
    let numbers = |k: &str| -> Vec<f64> {
        sample[k]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    // The header names our joint order; the state is written in it.
    let first = stdout(&eomgen(&[
        "eval",
        "--floating-base",
        urdf.to_str().unwrap(),
        "--q",
        &vec!["0"; 19].join(","),
    ]));
    let order: Vec<usize> = first
        .lines()
        .next()
        .unwrap()
        .split("joint order: ")
        .nth(1)
        .unwrap()
        .split(", ")
        .map(|n| refs.iter().position(|r| *r == n).unwrap())
        .collect();
    let ours = |v: &[f64], base: usize| -> String {
        let joints = order.iter().map(|&i| v[base + i]);
        let all: Vec<String> = v[..base]
            .iter()
            .copied()
            .chain(joints)
            .map(|x| x.to_string())
            .collect();
        all.join(",")
    };
    let (q, v, tau) = (numbers("q"), numbers("v"), numbers("tau_in"));
    let text = stdout(&eomgen(&[
        "eval",
        "--floating-base",
        urdf.to_str().unwrap(),
        "--q",
        &ours(&q, 7),
        "--qd",
        &ours(&v, 6),
        "--tau",
        &ours(&tau, 6),
    ]));
    for (label, key) in [
        (
            "forward dynamics a = M^-1 (tau_in - b - G) = ",
            "forward_dynamics",
        ),
        ("bias b(q, v) = ", "bias"),
    ] {
        let got = numbers_after(&text, label);
        let want: Vec<f64> = ours(&numbers(key), 6)
            .split(',')
            .map(|x| x.parse().unwrap())
            .collect();
        let scale = want.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        for (g, w) in got.iter().zip(&want) {
            assert!((g - w).abs() <= 1e-9 * scale, "{key}: {got:?} vs {want:?}");
        }
        assert_eq!(got.len(), 18, "{text}");
    }
}

/// The reference values beside a URDF (`NAME.json`).
fn reference(urdf: &std::path::Path) -> serde_json::Value {
    let text = std::fs::read_to_string(urdf.with_extension("json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// The numbers after `label` in `text`, up to the end of the line.
fn numbers_after(text: &str, label: &str) -> Vec<f64> {
    let rest = &text[text
        .find(label)
        .unwrap_or_else(|| panic!("no {label} in {text}"))
        + label.len()..];
    let line = rest.lines().next().unwrap_or("");
    line.split(|c: char| !(c.is_ascii_digit() || "-.e".contains(c)))
        .filter_map(|t| t.parse().ok())
        .collect()
}

#[test]
fn a_drone_hovers_to_its_target() {
    let (_guard, dir) = scratch("hover");
    let csv = dir.join("iris.csv");
    let plot = dir.join("iris.svg");
    let urdf = robot("floating/iris_simple");
    let out = stdout(&eomgen(&[
        "simulate",
        "--floating-base",
        urdf.to_str().unwrap(),
        "--controller",
        "hover",
        "--base",
        "0.2,-0.1,1,0.1,0,0,1",
        "--base-target",
        "0,0,1.5",
        "--omega",
        "4",
        "--duration",
        "3",
        "--csv",
        csv.to_str().unwrap(),
        "--plot",
        plot.to_str().unwrap(),
    ]));
    let end = numbers_after(&out, "m at t = 0, (");
    assert!(
        end[0].abs() < 1e-3 && end[1].abs() < 1e-3 && (end[2] - 1.5).abs() < 1e-3,
        "{out}"
    );
    let svg = std::fs::read_to_string(&plot).unwrap();
    assert!(svg.contains(">\niris: base position\n</text>"), "{svg}");
    let lines = svg
        .lines()
        .filter(|l| l.starts_with("<polyline") && l.contains("stroke-width=\"2\""));
    assert_eq!(lines.count(), 3, "x, y and z");
    // Without joints: the base's velocity, the hover's force on the base and the energy.
    for (file, label) in [
        ("iris-velocities.svg", "velocity (m/s)"),
        ("iris-efforts.svg", "force (N)"),
        ("iris-energy.svg", "not conserved by design"),
    ] {
        let svg = std::fs::read_to_string(dir.join(file)).unwrap();
        assert!(svg.contains(label), "{file}: {svg}");
    }
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(text.starts_with("t,base_x,base_y,base_z,base_qx,base_qy,base_qz,base_qw,base_vx"));
    // Numbers in their shortest form: round-off is written as `1.2e-17`, not `0.000...012`.
    for field in text.lines().skip(1).flat_map(|l| l.split(',')) {
        let x: f64 = field.parse().expect("a number");
        assert!(
            field.len() <= format!("{x}").len().min(format!("{x:e}").len()),
            "{field}"
        );
    }
}

#[test]
fn a_quadruped_stands_on_its_four_feet() {
    let (_guard, dir) = scratch("stand");
    let plot = dir.join("anymal.svg");
    let csv = dir.join("anymal.csv");
    let urdf = robot("floating/anymal");
    let mut args: Vec<String> = ["simulate", "--floating-base", urdf.to_str().unwrap()]
        .map(String::from)
        .to_vec();
    for foot in ["LF_FOOT", "RF_FOOT", "LH_FOOT", "RH_FOOT"] {
        args.extend(["--contact".to_string(), foot.to_string()]);
    }
    args.extend(
        [
            "--q0",
            "0,0.6,-1.2,0,-0.6,1.2,0,0.6,-1.2,0,-0.6,1.2",
            "--base",
            "0,0,0.5",
            "--controller",
            "stand",
            "--kp",
            "50",
            "--kd",
            "2",
            "--duration",
            "0.2",
            "--csv",
            csv.to_str().unwrap(),
            "--plot",
            plot.to_str().unwrap(),
        ]
        .map(String::from),
    );
    let out = stdout(&eomgen(&args));
    let residual = numbers_after(&out, "max |J a + Jdot v| = ");
    assert!(residual[0] < 1e-9, "{out}");
    // The four vertical forces carry the robot's weight (its mass from the generated gravity).
    let forces = numbers_after(&out, "vertical forces at the end: ");
    let weight: f64 = forces.iter().sum();
    assert!(
        forces.len() == 4 && forces.iter().all(|f| *f > 0.0),
        "{out}"
    );
    assert!(
        (weight - 30.4 * 9.81).abs() < 0.01 * weight,
        "{weight} N: {out}"
    );
    let end = numbers_after(&out, "m at t = 0, (");
    assert!((end[2] - 0.5).abs() < 1e-6, "{out}");
    let forces_plot = std::fs::read_to_string(dir.join("anymal-forces.svg")).unwrap();
    assert_eq!(forces_plot.matches(">\nLF_FOOT\n</text>").count(), 1);
    assert!(forces_plot.contains(">\nvertical force (N)\n</text>"));
    // With joints: their positions, velocities and efforts beside, and the energy.
    for (file, label) in [
        ("anymal-joints.svg", "position (rad)"),
        ("anymal-velocities.svg", "velocity (rad/s)"),
        ("anymal-efforts.svg", "effort (N m)"),
        ("anymal-energy.svg", "not conserved by design"),
    ] {
        let svg = std::fs::read_to_string(dir.join(file)).unwrap();
        assert!(svg.contains(label), "{file}");
        assert_eq!(
            svg.matches(">\nLF_HFE\n</text>").count(),
            usize::from(file != "anymal-energy.svg"),
            "{file}"
        );
    }
}

#[test]
fn floating_controllers_are_checked() {
    let urdf = robot("floating/iris_simple");
    let urdf = urdf.to_str().unwrap();
    let e = one_line_error(&eomgen(&[
        "simulate",
        "--floating-base",
        urdf,
        "--controller",
        "stand",
    ]));
    assert!(e.contains("give them with --contact LINK"), "{e}");
    let e = one_line_error(&eomgen(&[
        "simulate",
        "--floating-base",
        urdf,
        "--controller",
        "computed-torque",
    ]));
    assert!(
        e.contains("a floating base takes none, stand or hover"),
        "{e}"
    );
    let e = one_line_error(&eomgen(&[
        "simulate",
        robot("ur5").to_str().unwrap(),
        "--controller",
        "hover",
    ]));
    assert!(e.contains("are for a floating base"), "{e}");
}

/// `info` on floating joints below the root and a planar joint: a floating joint has no axis
/// and is labelled by its seven position coordinates (the joints after it by theirs), and the
/// massless bodies between a planar joint's steps carry the steps' names, not the child link's.
#[test]
fn info_shows_floating_and_planar_joints_as_they_are() {
    let rover = robot("joints/rover_pods");
    let text = stdout(&eomgen(&["info", rover.to_str().unwrap()]));
    assert!(
        text.contains("q6..q12 pod_free: floating -> pod, 2.2 kg"),
        "{text}"
    );
    assert!(text.contains("q13 pod_spin: revolute"), "{text}");
    assert!(
        text.contains("q15..q21 bob_free: floating -> bob, 0.7 kg"),
        "{text}"
    );
    assert!(!text.contains("floating about"), "{text}");
    assert!(
        text.contains("cart_planar.x: prismatic about (1, 0, 0) -> cart_planar.x, 0 kg"),
        "{text}"
    );
    assert!(
        text.contains("cart_planar.y: prismatic about (0, 1, 0) -> cart_planar.y, 0 kg"),
        "{text}"
    );
    assert!(text.contains("cart_planar.theta: continuous about (0, 0, 1) -> cart,"));
}

/// `eval` on a floating joint below the root (the crane's payload, `NQ` 10, `NV` 9; the
/// reference's joint order is ours): Pinocchio's inverse and forward dynamics, and a wrong
/// count says how many position coordinates the robot has.
#[test]
fn eval_takes_a_floating_joint_below_the_root() {
    let urdf = robot("joints/crane_payload");
    let doc = reference(&urdf);
    let sample = &doc["samples"][1];
    let numbers = |k: &str| -> Vec<f64> {
        let v = sample[k].as_array().unwrap();
        v.iter().map(|x| x.as_f64().unwrap()).collect()
    };
    let joined = |k: &str| -> String {
        let v: Vec<String> = numbers(k).iter().map(|x| x.to_string()).collect();
        v.join(",")
    };
    let path = urdf.to_str().unwrap();
    let (q, qd, qdd, tau) = (joined("q"), joined("qd"), joined("qdd"), joined("tau_in"));
    let text = stdout(&eomgen(&[
        "eval", path, "--q", &q, "--qd", &qd, "--qdd", &qdd, "--tau", &tau,
    ]));
    assert!(text.starts_with("crane_payload: 9 degrees of freedom, 10 position coordinates"));
    for (label, key) in [
        ("inverse dynamics tau = M qdd + b + G = ", "tau"),
        (
            "forward dynamics qdd = M^-1 (tau_in - b - G) = ",
            "forward_dynamics",
        ),
    ] {
        let (got, want) = (numbers_after(&text, label), numbers(key));
        let scale = want.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        assert_eq!(got.len(), want.len(), "{key}");
        for (g, w) in got.iter().zip(&want) {
            assert!((g - w).abs() <= 1e-9 * scale, "{key}: {got:?} vs {want:?}");
        }
    }
    let e = one_line_error(&eomgen(&["eval", path, "--q", "0.1"]));
    assert!(
        e.contains("--q has 1 value(s), but crane_payload has 10 position coordinates"),
        "{e}"
    );
}
