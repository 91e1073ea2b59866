//! A simulation whose integration blows up says so and suggests a smaller `--dt`, instead of
//! blaming the mass matrix.

use crate::support;

use support::{eomgen, one_line_error, scratch};

/// A pendulum with a very light link on a heavily damped joint: damping / inertia is about 1e6 1/s,
/// far beyond what RK4 at 1 ms can integrate.
const STIFF: &str = r#"<robot name="stiff">
  <link name="base"/>
  <link name="arm"><inertial><origin xyz="0 0 -0.1"/><mass value="0.0001"/>
    <inertia ixx="1e-7" ixy="0" ixz="0" iyy="1e-7" iyz="0" izz="1e-7"/></inertial></link>
  <joint name="hinge" type="continuous"><parent link="base"/><child link="arm"/>
    <axis xyz="0 1 0"/><dynamics damping="1"/></joint>
</robot>"#;

fn simulate(dt: &str) -> std::process::Output {
    // A directory of its own for each call (the two tests run in parallel), removed on return.
    let (_guard, dir) = scratch(&format!("divergence-{dt}"));
    let path = dir.join("stiff.urdf");
    std::fs::write(&path, STIFF).unwrap();
    let path = path.to_str().unwrap().to_string();
    eomgen(&[
        "simulate",
        &path,
        "--friction",
        "--q0",
        "0.5",
        "--duration",
        "0.01",
        "--dt",
        dt,
    ])
}

#[test]
fn a_diverged_integration_suggests_a_smaller_step() {
    let stderr = one_line_error(&simulate("1e-3"));
    assert!(
        stderr.contains("the integration diverged at t = ") && stderr.contains("smaller --dt"),
        "{stderr}"
    );
    assert!(!stderr.contains("positive definite"), "{stderr}");
}

#[test]
fn a_small_enough_step_integrates_the_same_robot() {
    let out = simulate("1e-6");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}
