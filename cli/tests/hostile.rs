//! Bad and hostile URDFs on the command line: one line on stderr naming the file, exit status 1,
//! and no control or bidirectional-text characters from names reaching the terminal.
//! (`codegen/tests/catalogue.rs` checks the library's answer to the whole catalogue.)

use crate::support;

use support::{eomgen, one_line_error, scratch, workspace};

const LINK: &str = r#"<inertial><mass value="1"/>
  <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>"#;

/// A robot of `links` (each with a plausible inertial) and raw joint elements.
fn urdf(links: &[&str], joints: &str) -> String {
    let links: String = links
        .iter()
        .map(|l| format!("<link name=\"{l}\">{LINK}</link>"))
        .collect();
    format!("<robot name=\"r\">{links}{joints}</robot>")
}

/// `<joint>` of `kind` from `parent` to `child`.
fn joint(name: &str, kind: &str, parent: &str, child: &str) -> String {
    format!(
        "<joint name=\"{name}\" type=\"{kind}\"><parent link=\"{parent}\"/>\
         <child link=\"{child}\"/><axis xyz=\"0 1 0\"/></joint>"
    )
}

/// Bad inputs, by name (also their file name).
fn cases() -> Vec<(&'static str, String)> {
    let hostile = |f: &str| {
        std::fs::read_to_string(workspace().join("codegen/tests/urdf/hostile").join(f)).unwrap()
    };
    let names: Vec<String> = (0..=10_000).map(|i| format!("l{i}")).collect();
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    let chain: String = (1..=10_000)
        .map(|i| joint(&format!("j{i}"), "revolute", names[i - 1], names[i]))
        .collect();
    let escape = "b\u{9b}31mX\u{202e}";
    vec![
        ("empty", String::new()),
        ("billion_laughs", hostile("billion_laughs.urdf")),
        (
            "deep_nesting",
            format!("<robot>{}", "<link>".repeat(100_000)),
        ),
        (
            "nan_mass",
            urdf(&["a"], "").replace("<mass value=\"1\"/>", "<mass value=\"NaN\"/>"),
        ),
        (
            "pure_cycle",
            urdf(
                &["a", "b"],
                &(joint("j1", "revolute", "a", "b") + &joint("j2", "revolute", "b", "a")),
            ),
        ),
        ("many_roots", urdf(&names, "")),
        (
            "spherical_joint",
            urdf(&["a", "b"], &joint("j", "spherical", "a", "b")),
        ),
        ("revolute_chain_10000", urdf(&names, &chain)),
        ("terminal_escapes", urdf(&[escape, escape], "")),
    ]
}

fn is_terminal_control(c: char) -> bool {
    c.is_control() || ('\u{202a}'..='\u{202e}').contains(&c)
}

#[test]
fn bad_input_gives_one_line_naming_the_file() {
    let (_guard, dir) = scratch("hostile");
    for (name, text) in cases() {
        let path = dir.join(format!("{name}.urdf"));
        std::fs::write(&path, text).unwrap();
        let out = eomgen(&[std::ffi::OsStr::new("generate"), path.as_os_str()]);
        let stderr = one_line_error(&out);
        assert!(stderr.contains(&format!("{name}.urdf")), "{name}: {stderr}");
        assert!(!stderr.contains("internal error"), "{name}: {stderr}");
        assert!(
            !stderr
                .trim_end_matches('\n')
                .chars()
                .any(is_terminal_control),
            "{name}: {stderr:?}"
        );
        if name == "revolute_chain_10000" {
            // The command line names its own flag for the limit.
            assert!(stderr.contains("--max-dof"), "{stderr}");
        }
    }
}

#[test]
fn names_printed_on_stdout_cannot_drive_the_terminal() {
    let (_guard, dir) = scratch("escapes");
    let path = dir.join("escapes.urdf");
    let name = "tip\u{9b}2J\u{85}\u{202e}x";
    std::fs::write(
        &path,
        urdf(&["base", name], &joint(name, "revolute", "base", name)),
    )
    .unwrap();
    for command in ["info", "show", "generate"] {
        let out = eomgen(&[std::ffi::OsStr::new(command), path.as_os_str()]);
        assert!(
            out.status.success(),
            "{command}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(
            !stdout.chars().any(|c| c != '\n' && is_terminal_control(c)),
            "{command}: {stdout:?}"
        );
    }
}
