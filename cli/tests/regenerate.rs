//! The "Regenerate:" line of a generated file is a command that, pasted into a shell in the
//! crate root, writes the same file.

use std::process::Command;

/// The banner's command, without its trailing comment, split into arguments (the options here
/// need no shell quoting).
fn regenerate_command(source: &str) -> Vec<String> {
    let line = source
        .lines()
        .find_map(|l| l.strip_prefix("// Regenerate: "))
        .expect("a Regenerate line");
    let command = line.split("  #").next().unwrap();
    command.split_whitespace().map(String::from).collect()
}

#[test]
fn the_regenerate_line_reproduces_the_file() {
    // Paths relative to this crate's root, where the test and the command run.
    let builder = eomgen::Builder::new("../tests/fixtures/joint_effects.urdf")
        .type_name("Arm")
        .module_name("arm")
        .gravity([0.0, -9.81, 0.0])
        .friction(true)
        .armature([("shoulder", 0.2)])
        .inertia_from_collision(1000.0)
        .regressor()
        .max_dof(12);
    let source = builder.generate().unwrap();
    let args = regenerate_command(&source);
    assert_eq!(args[..2], ["eomgen", "generate"], "{args:?}");
    // Write to stdout instead of `-o arm.rs`.
    let o = args.iter().position(|a| a == "-o").expect("-o");
    assert_eq!(args[o + 1], "arm.rs");
    let out = Command::new(env!("CARGO_BIN_EXE_eomgen"))
        .args(&args[1..o])
        .args(&args[o + 2..])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let regenerated = String::from_utf8(out.stdout).unwrap();
    let first_difference = regenerated
        .lines()
        .zip(source.lines())
        .find(|(a, b)| a != b);
    assert!(
        regenerated == source,
        "{args:?}: first difference {first_difference:?}"
    );
}
