//! Running a test of the current test binary in a separate process, to compare what two
//! processes print (determinism checks).
//!
//! The child test prints its payload between `<<<` and `>>>` when `EOMGEN_CHILD` is set, and
//! does nothing otherwise.

// A test that includes this module may use only part of it.
#![allow(dead_code)]

/// The variable that marks a child process.
pub const CHILD_VAR: &str = "EOMGEN_CHILD";

/// True inside a child process started by [`run_child`].
pub fn is_child() -> bool {
    std::env::var_os(CHILD_VAR).is_some()
}

/// Prints a child's payload.
pub fn emit(payload: &str) {
    print!("<<<{payload}>>>");
}

/// Runs the test named `test` of this binary in a new process and returns its payload.
pub fn run_child(test: &str) -> String {
    let out = std::process::Command::new(std::env::current_exe().expect("test binary"))
        .args(["--exact", test, "--nocapture", "--test-threads=1"])
        .env(CHILD_VAR, "1")
        .output()
        .expect("child runs");
    let text = String::from_utf8(out.stdout).expect("UTF-8 output");
    let start = text.find("<<<").expect("child printed its payload") + 3;
    let end = text[start..].find(">>>").expect("payload end") + start;
    text[start..end].to_string()
}
