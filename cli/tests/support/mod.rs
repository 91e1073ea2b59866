//! Helpers shared by the command line's tests: where the workspace is, running the binary, and
//! scratch directories.

#![allow(dead_code)] // Each test file uses some of them.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::SystemTime;

/// The workspace root, which holds `cli/` and the reference robots in `tests/robots/`.
pub fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the workspace holds cli/")
        .to_path_buf()
}

/// The URDF of a reference robot, by name.
pub fn robot(name: &str) -> PathBuf {
    workspace().join(format!("tests/robots/{name}.urdf"))
}

/// Runs the binary from the workspace root.
pub fn eomgen<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_eomgen"))
        .args(args)
        .current_dir(workspace())
        .output()
        .expect("the binary runs")
}

/// Runs the binary and returns its standard output, which it must end with success.
pub fn stdout_of<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> String {
    let out = eomgen(args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// A fresh scratch directory for one test, `eomgen-cli-TEST-XXXXXX`, and its path: the directory
/// is removed when the guard is dropped, pass or fail (see `scratch::dir`).
pub fn scratch(test: &str) -> (tempfile::TempDir, PathBuf) {
    crate::scratch::dir(&format!("eomgen-cli-{test}"))
}

/// The names of the files in `dir`, sorted.
pub fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

pub fn mtime(path: &Path) -> SystemTime {
    std::fs::metadata(path).unwrap().modified().unwrap()
}

/// Asserts exit status 1 with exactly one line on stderr, starting `eomgen: error: `, and
/// nothing on stdout; returns the line.
#[track_caller]
pub fn one_line_error(out: &Output) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(out.stdout.is_empty(), "wrote to stdout: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "not one line: {stderr}");
    assert!(stderr.starts_with("eomgen: error: "), "{stderr}");
    stderr
}
