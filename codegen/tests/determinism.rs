//! The same URDF and options give byte-identical output in separate processes.

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
    ROBOTS
        .iter()
        .map(|r| {
            let src = eomgen::Builder::new(urdf(r)).generate().unwrap();
            format!("{r} {} {:016x}\n", src.len(), digest(src.as_bytes()))
        })
        .collect()
}

#[test]
fn child_process_generates() {
    if std::env::var_os("EOMGEN_DETERMINISM_CHILD").is_some() {
        print!("<<<{}>>>", generate_all());
    }
}

#[test]
fn every_reference_robot_generates_identical_bytes_in_two_processes() {
    let run = || {
        let out = std::process::Command::new(std::env::current_exe().unwrap())
            .args([
                "--exact",
                "child_process_generates",
                "--nocapture",
                "--test-threads=1",
            ])
            .env("EOMGEN_DETERMINISM_CHILD", "1")
            .output()
            .unwrap();
        let text = String::from_utf8(out.stdout).unwrap();
        let start = text.find("<<<").expect("child printed") + 3;
        text[start..text.find(">>>").unwrap()].to_string()
    };
    let (a, b) = (run(), run());
    assert_eq!(a.lines().count(), ROBOTS.len());
    assert_eq!(a, b);
    assert_eq!(a, generate_all(), "and identical to this process");
}
