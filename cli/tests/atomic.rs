//! `eomgen generate -o FILE` writes atomically: an error at any stage leaves an existing output
//! file byte-identical, with its modification time and no temporary file beside it.

use crate::support;

use support::{eomgen, listing, mtime, one_line_error, robot, scratch, workspace};

#[test]
fn the_cli_leaves_the_previous_output_untouched_on_error() {
    let (_guard, dir) = scratch("atomic");
    let output = dir.join("robot.rs");
    let bad_file = dir.join("bad.urdf");
    // A URDF refused by the parser.
    let hostile = workspace().join("codegen/tests/urdf/hostile/billion_laughs.urdf");
    std::fs::copy(hostile, &bad_file).unwrap();
    let generate = |urdf: &std::path::Path, extra: &[&str]| {
        let mut args: Vec<&std::ffi::OsStr> = vec![
            "generate".as_ref(),
            urdf.as_os_str(),
            "-o".as_ref(),
            output.as_os_str(),
        ];
        args.extend(extra.iter().map(std::ffi::OsStr::new));
        eomgen(&args)
    };
    let ok = generate(&robot("double_pendulum"), &[]);
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    let before = std::fs::read(&output).unwrap();
    let written = mtime(&output);
    for (urdf, extra) in [
        (bad_file.clone(), &[][..]),
        (robot("ur5"), &["--max-dof", "2"][..]),
        (robot("ur5"), &["--max-graph-nodes", "1000"][..]),
        (robot("ur5"), &["--type-name", "not a type"][..]),
    ] {
        one_line_error(&generate(&urdf, extra));
        assert_eq!(std::fs::read(&output).unwrap(), before, "{extra:?}");
        assert_eq!(mtime(&output), written, "{extra:?}");
        assert_eq!(listing(&dir), ["bad.urdf", "robot.rs"], "{extra:?}");
    }
}
