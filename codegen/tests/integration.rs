//! Every test file of this directory as one test binary (linked once, its tests run on every
//! core together): see `[[test]]` in Cargo.toml. `selections_compile` (ignored, run by CI by
//! name) stays a binary of its own.

#[path = "support/child.rs"]
mod child;

mod atomic;
mod cas;
mod catalogue;
mod determinism;
mod evaluate;
mod joint_effects;
mod limits;
mod messages;
mod mimic;
mod model;
mod passive;
mod projected;
mod regressor;
mod scaling;
mod selection;
mod urdf_reader;

#[path = "support/scratch.rs"]
mod scratch;
#[path = "support/test_files.rs"]
mod test_files;

#[test]
fn every_test_file_runs() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    test_files::assert_every_test_file_runs(dir, include_str!("integration.rs"));
}
