//! The check that keeps a crate's one test binary complete: with `autotests = false`, a test
//! file that neither the binary's root lists as a module nor `Cargo.toml` names as a `[[test]]`
//! of its own would never be compiled, and its tests would silently not run.

use std::path::Path;

/// Asserts that every `.rs` file of `crate_dir/tests` is a module of `root_source` (the test
/// binary's root, `mod NAME;`) or a `[[test]]` path of `crate_dir/Cargo.toml`.
pub fn assert_every_test_file_runs(crate_dir: &Path, root_source: &str) {
    let manifest = std::fs::read_to_string(crate_dir.join("Cargo.toml")).expect("Cargo.toml");
    let tests = crate_dir.join("tests");
    let mut missing = Vec::new();
    for entry in std::fs::read_dir(&tests).expect("the tests directory") {
        let name = entry.expect("a directory entry").file_name();
        let name = name.to_string_lossy();
        let Some(stem) = name.strip_suffix(".rs") else {
            continue;
        };
        let own_binary = manifest.contains(&format!("path = \"tests/{name}\""));
        let module = root_source
            .lines()
            .any(|l| l.trim() == format!("mod {stem};"));
        if !own_binary && !module {
            missing.push(name.to_string());
        }
    }
    assert!(
        missing.is_empty(),
        "test files in {} that no test binary compiles (add `mod NAME;` to tests/integration.rs): {missing:?}",
        tests.display()
    );
}
