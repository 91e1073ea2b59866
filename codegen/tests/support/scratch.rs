//! Scratch directories for tests, removed when the test ends, whether it passed or failed.
//!
//! Include it with `#[path = "support/scratch.rs"] mod scratch;` (from `tests/`) or
//! `#[path = "../../codegen/tests/support/scratch.rs"] mod scratch;` (from another crate's
//! `tests/`); the crate needs `tempfile` among its dev-dependencies.

use std::path::PathBuf;

/// A fresh, empty directory `PREFIX-XXXXXX` in the system's temporary directory, and its path.
/// Dropping the guard (the first of the two) removes the directory with everything in it, at the
/// end of the test or when it panics: bind it to a name (`let (_guard, dir) = ...`), not to `_`,
/// which drops it at once.
pub fn dir(prefix: &str) -> (tempfile::TempDir, PathBuf) {
    let guard = tempfile::Builder::new()
        .prefix(&format!("{prefix}-"))
        .tempdir()
        .expect("a scratch directory in the system's temporary directory");
    let path = guard.path().to_path_buf();
    (guard, path)
}
