//! The messages a build script shows: `.compile().unwrap()` prints an error's `Debug` form,
//! which reads exactly as its one-line `Display`.

use std::panic::{catch_unwind, AssertUnwindSafe};

const NO_LINKS: &str = r#"<robot name="r"></robot>"#;

/// The message `unwrap()` panics with, as a build script would print it.
fn unwrap_message(f: impl FnOnce()) -> String {
    let payload = catch_unwind(AssertUnwindSafe(f)).expect_err("unwrap panics");
    payload
        .downcast_ref::<String>()
        .cloned()
        .expect("unwrap formats its message")
}

#[test]
fn debug_reads_as_display_for_builder_errors() {
    let builder = eomgen::Builder::from_urdf_str(NO_LINKS, "nolinks.urdf");
    let err = builder.generate().unwrap_err();
    assert_eq!(format!("{err:?}"), "nolinks.urdf: the robot has no links");
    assert_eq!(format!("{err:?}"), err.to_string());
    let err = eomgen::Builder::new("missing.urdf").model().unwrap_err();
    assert_eq!(format!("{err:?}"), err.to_string());
    assert!(format!("{err:?}").starts_with("missing.urdf: "), "{err:?}");
    let pendulum = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../tests/robots/double_pendulum.urdf"
    );
    let err = eomgen::Builder::new(pendulum)
        .type_name("not a type")
        .generate()
        .unwrap_err();
    assert_eq!(format!("{err:?}"), err.to_string());
    assert!(format!("{err:?}").starts_with("invalid type name `not a type`"));
}

#[test]
fn debug_reads_as_display_for_model_errors() {
    let err = eomgen::urdf::load_str(NO_LINKS, "nolinks.urdf", &Default::default()).unwrap_err();
    assert_eq!(format!("{err:?}"), "nolinks.urdf: the robot has no links");
}

#[test]
fn unwrap_in_a_build_script_prints_the_readable_line() {
    let message = unwrap_message(|| {
        eomgen::Builder::from_urdf_str(NO_LINKS, "nolinks.urdf")
            .out_dir(std::env::temp_dir())
            .compile()
            .unwrap();
    });
    assert!(
        message.ends_with(": nolinks.urdf: the robot has no links"),
        "{message}"
    );
    assert!(!message.contains("NoLinks"), "{message}");
}
