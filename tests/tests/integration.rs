//! Every test file of this directory as one test binary (linked once, its tests run on every
//! core together): see `[[test]]` in Cargo.toml. A test file listed here is a module; the ones
//! that install a global allocator stay binaries of their own.

mod active_contacts;
mod batch;
mod contact_dynamics;
mod derivatives;
mod dimensions;
mod floating;
mod floating_prelude;
mod generated;
mod hamiltonian;
mod ill_conditioned;
mod joint_effects;
mod joints;
mod lagrangian;
mod mimic;
mod mpc_kinematics;
mod regressor;
mod runtime_solve;
mod selection;
mod split;
mod tree_passes;
mod tree_route;
mod underactuated;

#[path = "../../codegen/tests/support/test_files.rs"]
mod test_files;

#[test]
fn every_test_file_runs() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    test_files::assert_every_test_file_runs(dir, include_str!("integration.rs"));
}
