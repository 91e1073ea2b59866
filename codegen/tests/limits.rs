//! Robots beyond the generator's limits are refused with a message that names the limit and
//! how to raise it.

use std::path::PathBuf;

fn urdf(robot: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/robots")
        .join(format!("{robot}.urdf"))
}

#[test]
fn robots_beyond_the_joint_limit_are_refused_with_the_way_to_raise_it() {
    let err = eomgen::Builder::new(urdf("panda"))
        .max_dof(8)
        .generate()
        .unwrap_err();
    let msg = err.to_string();
    assert!(
        matches!(
            err,
            eomgen::Error::Limit {
                value: 9,
                limit: 8,
                ..
            }
        ),
        "{msg}"
    );
    assert!(
        msg.contains("panda.urdf") && msg.contains("Builder::max_dof"),
        "{msg}"
    );
    assert!(eomgen::Builder::new(urdf("panda"))
        .max_dof(9)
        .generate()
        .is_ok());
}
