//! `eomgen show --format latex --standalone`: a complete document whose environments balance,
//! with text escaped and long formulas broken into lines; compiled by pdflatex where it is
//! installed.

use crate::support;

use support::{eomgen, robot, scratch, stdout_of};

fn standalone(name: &str, extra: &[&str]) -> String {
    let urdf = robot(name);
    let mut args = vec![
        "show",
        urdf.to_str().unwrap(),
        "--format",
        "latex",
        "--standalone",
    ];
    args.extend(extra);
    stdout_of(&args)
}

#[test]
fn the_document_is_complete_and_balanced() {
    let tex = standalone("double_pendulum", &[]);
    assert!(tex.starts_with("\\documentclass{article}\n"));
    assert!(tex.trim_end().ends_with("\\end{document}"));
    let opened = tex.matches("\\begin{align*}").count();
    assert!(opened >= 9, "one block per term and the legend: {opened}");
    assert_eq!(opened, tex.matches("\\end{align*}").count());
    assert!(
        !tex.contains("aligned"),
        "fragments use aligned, documents align*"
    );
    // The robot's name, 2dof_planar, is text: its underscore is escaped.
    assert!(tex.contains("2dof\\_planar"), "{}", &tex[..300]);
}

#[test]
fn long_formulas_are_broken_between_terms() {
    let tex = standalone("ur5", &["--term", "M"]);
    let longest = tex.lines().map(str::len).max().unwrap();
    assert!(longest < 400, "a line of {longest} characters");
    assert!(tex.contains("&\\quad "), "continuation lines");
}

#[test]
fn pdflatex_compiles_it_where_installed() {
    let Ok(status) = std::process::Command::new("pdflatex")
        .arg("--version")
        .output()
    else {
        eprintln!("pdflatex is not installed: compiling the document is not checked here");
        return;
    };
    assert!(status.status.success());
    let (_guard, dir) = scratch("latex");
    std::fs::write(dir.join("ur5.tex"), standalone("ur5", &[])).unwrap();
    // The base parameters' document too (long formulas, names with underscores).
    let base = standalone("ur5", &["--base-parameters"]);
    std::fs::write(dir.join("ur5_base.tex"), base).unwrap();
    for file in ["ur5.tex", "ur5_base.tex"] {
        let out = std::process::Command::new("pdflatex")
            .args(["-interaction=nonstopmode", "-halt-on-error", file])
            .current_dir(&dir)
            .output()
            .unwrap();
        let log = String::from_utf8_lossy(&out.stdout).into_owned();
        assert!(
            out.status.success(),
            "{file}: {}",
            &log[log.len().saturating_sub(2000)..]
        );
    }
}

#[test]
fn standalone_needs_latex() {
    let urdf = robot("double_pendulum");
    let out = eomgen(&["show", urdf.to_str().unwrap(), "--standalone"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--standalone makes a LaTeX document"));
}
