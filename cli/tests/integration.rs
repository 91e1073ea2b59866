//! Every test file of this directory as one test binary (linked once, its tests run on every
//! core together): see `[[test]]` in Cargo.toml.

mod support;

mod atomic;
mod cli;
mod cli_simulate;
mod floating;
mod hostile;
mod joint_effects;
mod latex_document;
mod limits;
mod plots;
mod regenerate;
mod show_derivatives;
mod simulate_divergence;
mod urdf_reader;

#[path = "../../codegen/tests/support/scratch.rs"]
mod scratch;
#[path = "../../codegen/tests/support/test_files.rs"]
mod test_files;

#[test]
fn every_test_file_runs() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    test_files::assert_every_test_file_runs(dir, include_str!("integration.rs"));
}
