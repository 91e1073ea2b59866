//! Running a test of the current test binary in a separate process, to compare what two
//! processes print (determinism checks).
//!
//! The child is an ignored test, so that `cargo test` does not count it as a test that passed:
//! its parent runs it with `--ignored --exact NAME` and `EOMGEN_CHILD` set, and the child
//! prints its payload between `<<<` and `>>>`. Run any other way (`cargo test --
//! --include-ignored`), the child runs its parent's checks instead, so that it never passes
//! without checking anything.

// A test that includes this module may use only part of it.
#![allow(dead_code)]

/// The variable that marks a child process.
pub const CHILD_VAR: &str = "EOMGEN_CHILD";

/// True inside a child process started by [`run_child`].
pub fn is_child() -> bool {
    std::env::var_os(CHILD_VAR).is_some()
}

/// The body of a child test: in a child process started by [`run_child`], prints
/// `payload()`; anywhere else, runs `parent`, the test that starts the child.
pub fn child_main(payload: impl FnOnce() -> String, parent: impl FnOnce()) {
    if is_child() {
        print!("<<<{}>>>", payload());
    } else {
        parent();
    }
}

/// Runs the ignored test `test` (its module path, `concat!(module_path!(), "::NAME")`) in a new
/// process of this binary and returns its payload.
#[track_caller]
pub fn run_child(test: &str) -> String {
    // The test harness names a test by its path without the crate's name.
    let test = test.split_once("::").map_or(test, |(_crate, path)| path);
    let out = std::process::Command::new(std::env::current_exe().expect("test binary"))
        .args([
            "--ignored",
            "--exact",
            test,
            "--nocapture",
            "--test-threads=1",
        ])
        .env(CHILD_VAR, "1")
        .output()
        .expect("child runs");
    let text = String::from_utf8(out.stdout).expect("UTF-8 output");
    assert!(
        out.status.success(),
        "child `{test}` failed: {text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        text.contains("test result: ok. 1 passed"),
        "child `{test}` did not run exactly once: {text}"
    );
    let start = text.find("<<<").expect("child printed its payload") + 3;
    let end = text[start..].find(">>>").expect("payload end") + start;
    text[start..end].to_string()
}
