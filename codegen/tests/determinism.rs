//! The same URDF and options give byte-identical output in separate processes.

use crate::child;

use std::path::PathBuf;

const ROBOTS: [&str; 5] = [
    "double_pendulum",
    "ur5",
    "panda",
    "kinova",
    "allegro_right_hand",
];

fn urdf(robot: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/robots")
        .join(format!("{robot}.urdf"))
}

/// FNV-1a: a stable digest to pass between processes.
fn digest(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf29ce484222325u64, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x100000001b3)
    })
}

fn generate_all() -> String {
    let mut out: String = ROBOTS
        .iter()
        .map(|r| {
            let src = eomgen::Builder::new(urdf(r)).generate().unwrap();
            format!("{r} {} {:016x}\n", src.len(), digest(src.as_bytes()))
        })
        .collect();
    // Identification samples random states to find the base parameters: seeded, so the same.
    let src = eomgen::Builder::new(urdf("allegro_right_hand"))
        .regressor()
        .quantities(["base_parameters"])
        .generate()
        .unwrap();
    out += &format!("base {} {:016x}\n", src.len(), digest(src.as_bytes()));
    // Mimic joints honoured: the coupling's projections and the coordinates' parents.
    let src = eomgen::Builder::new(urdf("panda"))
        .mimic_joints()
        .generate()
        .unwrap();
    out += &format!("mimic {} {:016x}\n", src.len(), digest(src.as_bytes()));
    out
}

/// The child process of `every_reference_robot_generates_identical_bytes_in_two_processes`,
/// which runs it; run directly, it runs that test.
#[test]
#[ignore = "the child process of every_reference_robot_generates_identical_bytes_in_two_processes, which runs it"]
fn child_process_generates() {
    child::child_main(
        generate_all,
        every_reference_robot_generates_identical_bytes_in_two_processes,
    );
}

#[test]
fn every_reference_robot_generates_identical_bytes_in_two_processes() {
    let run = || child::run_child(concat!(module_path!(), "::child_process_generates"));
    let (a, b) = (run(), run());
    assert_eq!(a.lines().count(), ROBOTS.len() + 2);
    assert_eq!(a, b);
    assert_eq!(a, generate_all(), "and identical to this process");
}
