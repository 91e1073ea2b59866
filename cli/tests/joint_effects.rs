//! Joint effects on the command line: `--friction`, `--armature` and `--density` in `generate`,
//! `eval` and `info`, their warnings, and their bad values.

use crate::support;

use support::eomgen;

#[test]
fn command_line_flags_and_warnings() {
    let urdf = "tests/fixtures/joint_effects.urdf";
    let out = eomgen(&[
        "generate",
        urdf,
        "--friction",
        "--armature",
        "shoulder=0.2,elbow=0.05",
        "--density",
        "1000",
    ]);
    assert!(out.status.success());
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stdout.contains("pub fn friction(&self, qd: &[T; 2])"));
    assert!(stdout.contains("`shoulder` 0.2, `elbow` 0.05"));
    let warnings: Vec<&str> = stderr.lines().collect();
    assert_eq!(warnings.len(), 2, "{stderr}");
    assert!(warnings[0].starts_with("eomgen: warning: tests/fixtures/joint_effects.urdf: link `upper` has no <inertial>: mass 4 kg"));
    assert!(warnings[1].contains("link `camera`"));
    // eval: the friction and the rotor inertia at a state, by hand.
    let out = eomgen(&[
        "eval",
        urdf,
        "--q",
        "0.3,0.4",
        "--qd",
        "1,-2",
        "--friction",
        "--armature",
        "elbow=0.1",
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("friction F(qd) = [0.7, -0.25]"), "{stdout}");
    assert!(stdout.contains("inverse dynamics tau = M qdd + b + G + F"));
    // M22 = fore about the elbow, 0.01 + 1 * 0.15^2 = 0.0325, plus 0.1.
    assert!(stdout.contains(", 0.1325]"), "{stdout}");
    // info lists the effects per joint.
    let out = eomgen(&["info", urdf, "--armature", "shoulder=0.2"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains(
            "joint effects (damping, Coulomb friction, rotor inertia; friction left out of the \
             dynamics without --friction):\n  q1 shoulder: 0.5, 0.2, 0.2\n  q2 elbow: 0.1, 0.05, 0\n"
        ),
        "{stdout}"
    );
    // Bad values: exit 1 naming the joint, or 2 for malformed flags.
    let out = eomgen(&["generate", urdf, "--armature", "wrist=0.1"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("armature: joint `wrist` does not exist"));
    let out = eomgen(&["generate", urdf, "--armature", "shoulder"]);
    assert_eq!(out.status.code(), Some(2));
    let out = eomgen(&["info", urdf, "--density", "-5"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("density must be positive"));
}
