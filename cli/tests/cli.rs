//! The `eomgen` binary end to end: every command and format on the reference robots, snapshots
//! of the double pendulum's equations, exit codes and error messages, the textbook planar arm,
//! and the README's quick start.
//!
//! Snapshots live in `tests/snapshots/`; refresh them with
//! `EOMGEN_BLESS=1 cargo test -p eomgen-cli --test cli`.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use crate::support::scratch;

/// Reference robots in `tests/robots/` of the workspace.
const ROBOTS: [&str; 5] = [
    "double_pendulum",
    "ur5",
    "panda",
    "kinova",
    "allegro_right_hand",
];

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the workspace holds cli/")
        .to_path_buf()
}

fn robot(name: &str) -> String {
    format!("tests/robots/{name}.urdf")
}

fn reference(name: &str) -> serde_json::Value {
    let text = std::fs::read_to_string(workspace().join(format!("tests/robots/{name}.json")))
        .expect("reference JSON");
    serde_json::from_str(&text).expect("valid JSON")
}

/// Runs the binary from the workspace root.
fn eomgen(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_eomgen"))
        .args(args)
        .current_dir(workspace())
        .output()
        .expect("the binary runs")
}

/// Asserts success with nothing on stderr (no progress when piped); returns stdout.
#[track_caller]
fn ok(args: &[&str]) -> String {
    let out = eomgen(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "eomgen {args:?} failed ({:?}): {stderr}",
        out.status.code()
    );
    assert!(
        stderr.is_empty(),
        "eomgen {args:?} wrote to stderr: {stderr}"
    );
    String::from_utf8(out.stdout).expect("UTF-8 output")
}

/// Asserts exit status 1 with exactly one line on stderr and nothing on stdout; returns it.
#[track_caller]
fn bad_input(args: &[&str]) -> String {
    let out = eomgen(args);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(1), "eomgen {args:?}: {stderr}");
    assert!(out.stdout.is_empty(), "eomgen {args:?} wrote to stdout");
    assert_eq!(
        stderr.lines().count(),
        1,
        "eomgen {args:?}: not one line: {stderr}"
    );
    assert!(stderr.ends_with('\n'));
    assert!(stderr.starts_with("eomgen: error: "), "{stderr}");
    assert!(
        !stderr.contains("panicked") && !stderr.contains("backtrace"),
        "{stderr}"
    );
    stderr
}

/// Asserts exit status 2 (clap's usage error).
#[track_caller]
fn bad_usage(args: &[&str]) {
    let out = eomgen(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "eomgen {args:?}: {stderr}");
    assert!(out.stdout.is_empty());
    assert!(
        !stderr.is_empty() && !stderr.contains("panicked"),
        "{stderr}"
    );
}

fn path_str(p: &Path) -> &str {
    p.to_str().expect("UTF-8 temp path")
}

/// Compares with `tests/snapshots/<name>` byte for byte, or rewrites it with `EOMGEN_BLESS`.
#[track_caller]
fn snapshot(name: &str, actual: &str) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/snapshots")
        .join(name);
    if std::env::var_os("EOMGEN_BLESS").is_some() {
        std::fs::create_dir_all(path.parent().expect("dir")).expect("snapshot dir");
        std::fs::write(&path, actual).expect("write snapshot");
        return;
    }
    let expected = std::fs::read(&path).unwrap_or_else(|_| {
        panic!("missing snapshot {name}; create it with EOMGEN_BLESS=1 cargo test -p eomgen-cli --test cli")
    });
    if expected != actual.as_bytes() {
        let expected = String::from_utf8_lossy(&expected);
        let line = expected
            .lines()
            .zip(actual.lines())
            .position(|(a, b)| a != b)
            .unwrap_or(expected.lines().count().min(actual.lines().count()));
        panic!(
            "snapshot {name} differs at line {}:\n- {}\n+ {}\nrefresh with EOMGEN_BLESS=1 cargo test -p eomgen-cli --test cli",
            line + 1,
            expected.lines().nth(line).unwrap_or("<end>"),
            actual.lines().nth(line).unwrap_or("<end>")
        );
    }
}

#[test]
fn show_every_robot_in_every_format_and_form() {
    let titles = [
        "Mass matrix M(q)",
        "Craig's Coriolis matrix B(q)",
        "Craig's centrifugal matrix C(q)",
        "Gravity G(q) = dV/dq",
        "Bias b(q, qd)",
        "Coriolis matrix C(q, qd)",
        "Inverse dynamics tau",
        "Kinetic energy T",
        "Potential energy V",
    ];
    for name in ROBOTS {
        let json = reference(name);
        let joints = json["joints"].as_array().expect("joints");
        let dof = joints.len();
        let first = if dof <= 9 { "11" } else { "1,1" };
        for form in ["expanded", "program"] {
            for format in ["text", "latex", "markdown"] {
                let path = robot(name);
                let out = ok(&["show", &path, "--format", format, "--form", form]);
                for t in titles {
                    assert!(out.contains(t), "{name} {format} {form}: no `{t}`");
                }
                let (m11, tau) = match format {
                    "text" => (format!("\n  M{first} = "), format!("\n  tau{dof} = ")),
                    "latex" => (
                        format!("\nM_{{{first}}} &= "),
                        format!("\n\\tau_{{{dof}}} &= "),
                    ),
                    _ => (
                        format!("\nM_{{{first}}} &= "),
                        format!("\n\\tau_{{{dof}}} &= "),
                    ),
                };
                assert!(out.contains(&m11), "{name} {format} {form}: no {m11:?}");
                assert!(out.contains(&tau), "{name} {format} {form}: no {tau:?}");
                match format {
                    "text" => assert!(!out.contains("\\begin")),
                    "latex" => {
                        assert_eq!(
                            out.matches("\\begin{aligned}").count(),
                            out.matches("\\end{aligned}").count()
                        );
                        assert!(out
                            .lines()
                            .all(|l| !l.contains(" = ") || l.starts_with('%')));
                    }
                    _ => {
                        assert!(out.starts_with("# "));
                        assert!(out.contains("\n## Mass matrix M(q)\n"));
                        assert_eq!(out.matches("$$\n").count() % 2, 0);
                    }
                }
                // Every joint is named in the heading.
                for joint in joints {
                    assert!(out.contains(joint.as_str().expect("name")));
                }
            }
        }
    }
}

#[test]
fn show_is_deterministic_and_program_form_is_exact() {
    let path = robot("ur5");
    let a = ok(&["show", &path, "--term", "M,G", "--form", "program"]);
    let b = ok(&["show", &path, "--term", "M,G", "--form", "program"]);
    assert_eq!(a, b);
    assert!(a.contains("\n  t0 = "));
    // Expanded UR5 gravity uses the short names of angle sums.
    let g = ok(&["show", &path, "--term", "G"]);
    assert!(g.contains("s234 = sin(q2 + q3 + q4)"), "{g}");
}

#[test]
fn show_single_entries() {
    let path = robot("double_pendulum");
    let m12 = ok(&["show", &path, "--term", "M", "--entry", "1,2"]);
    let line = |text: &str, name: &str| -> String {
        text.lines()
            .find_map(|l| l.strip_prefix(&format!("  {name} = ")))
            .unwrap_or_else(|| panic!("no {name} in {text}"))
            .to_string()
    };
    let rhs = line(&m12, "M12");
    assert!(!m12.contains("M11") && !m12.contains("M22"));
    let m21 = ok(&["show", &path, "--term", "M", "--entry", "2,1"]);
    assert_eq!(line(&m21, "M21"), rhs);
    let by_column = ok(&["show", &path, "--term", "B", "--entry", "1,1"]);
    let by_pair = ok(&["show", &path, "--term", "B", "--entry", "1,2,1"]);
    assert_eq!(line(&by_column, "B1_12"), line(&by_pair, "B1_12"));
    // A structural zero is printed when asked for.
    assert_eq!(
        line(
            &ok(&["show", &path, "--term", "C", "--entry", "1,1"]),
            "C11"
        ),
        "0"
    );
    assert!(ok(&["show", &path, "--term", "G", "--entry", "2"]).contains("  G2 = "));
    assert!(ok(&["show", &path, "--term", "V"]).contains("  V = "));
    let latex = ok(&[
        "show", &path, "--term", "tau", "--entry", "1", "--format", "latex",
    ]);
    assert!(latex.contains("\\tau_{1} &= "));
    // Out of range, wrong shape, or a scalar: bad input.
    bad_input(&["show", &path, "--term", "M", "--entry", "3,1"]);
    bad_input(&["show", &path, "--term", "G", "--entry", "1,2"]);
    bad_input(&["show", &path, "--term", "B", "--entry", "1,2,2"]);
    bad_input(&["show", &path, "--term", "T", "--entry", "1"]);
    // --entry with several terms is bad usage.
    bad_usage(&["show", &path, "--entry", "1,2"]);
    bad_usage(&["show", &path, "--term", "M,G", "--entry", "1,2"]);
}

#[test]
fn show_symbolic_digits_and_model_options() {
    let path = robot("double_pendulum");
    let all = ok(&["show", &path, "--symbolic", "--term", "M"]);
    for p in ["m_link1", "m_link2", "Ixx_link1", "cz_link2", "z_joint2"] {
        assert!(all.contains(p), "{p} missing:\n{all}");
    }
    assert!(all.contains("  m_link2: mass of body link2 (URDF value 0.33238)"));
    let one = ok(&["show", &path, "--term", "M", "--symbolic", "link2"]);
    assert!(one.contains("m_link2") && !one.contains("m_link1"), "{one}");
    assert_eq!(one, ok(&["show", "--symbolic=link2", &path, "--term", "M"]));
    let e = bad_input(&["show", &path, "--symbolic", "nosuch"]);
    assert!(e.contains("nosuch"), "{e}");

    let three = ok(&["show", &path, "--term", "M", "--digits", "3"]);
    assert!(three.contains("  M22 = 0.00456\n"), "{three}");
    let exact = ok(&["show", &path, "--term", "M", "--digits", "0"]);
    assert!(exact.contains("shortest exact decimals"));
    assert!(!exact.contains("  M22 = 0.00456\n"));

    let sideways = ok(&["show", &path, "--term", "G", "--gravity", "0,-9.81,0"]);
    assert!(sideways.contains("gravity (0, -9.81, 0)"));
    assert_ne!(sideways, ok(&["show", &path, "--term", "G"]));
    bad_input(&["show", &path, "--joint-order", "joint2,joint1"]);
    // A tiny term limit forces the program form, with a note.
    let program = ok(&["show", &path, "--term", "G", "--max-terms", "1"]);
    assert!(program.contains("(Program form: the expansion of G1 exceeds 1 terms.)"));
    assert!(program.contains("  t0 = "));
}

/// Generated code without its banner's Regenerate line (which records the path as given).
fn code(source: &str) -> String {
    source
        .lines()
        .filter(|l| !l.starts_with("// Regenerate: "))
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn generate_matches_the_builder_and_writes_files() {
    for name in ROBOTS {
        let path = robot(name);
        let out = ok(&["generate", &path]);
        let expected = eomgen::Builder::new(workspace().join(&path))
            .generate()
            .expect("generates");
        // The same code; the banner's Regenerate line records the path as each was given it.
        assert!(
            code(&out) == code(&expected),
            "{name}: CLI and Builder differ"
        );
    }
    let (_guard, dir) = scratch("generate");
    let file = dir.join("pendulum.rs");
    let path = robot("double_pendulum");
    let stdout = ok(&[
        "generate",
        &path,
        "-o",
        path_str(&file),
        "--type-name",
        "Pendulum",
        "--module-name",
        "pendulum",
        "--gravity",
        "0,0,-9.80665",
        "--symbolic",
        "link2",
    ]);
    assert!(stdout.is_empty());
    let written = std::fs::read_to_string(&file).expect("written");
    assert!(written.starts_with("// @generated by eomgen"));
    assert!(written.contains("pub struct Pendulum<T = f64>"));
    assert!(written.contains("m_link2"));
    let e = bad_input(&["generate", &path, "--type-name", "not a type"]);
    assert!(e.contains("not a type"), "{e}");
    bad_input(&["generate", &path, "-o", path_str(&dir.join("missing/x.rs"))]);
}

/// `generate --regressor` is `Builder::regressor`, and `show --base-parameters` prints each
/// base parameter's formula (snapshots for the double pendulum in every format).
#[test]
fn identification_from_the_command_line() {
    let path = robot("ur5");
    let out = ok(&["generate", &path, "--regressor"]);
    let expected = eomgen::Builder::new(workspace().join(&path))
        .regressor()
        .generate()
        .expect("generates");
    assert!(code(&out) == code(&expected), "CLI and Builder differ");
    assert!(out.contains("--regressor -o ur5.rs"));
    assert!(out.contains("pub fn base_parameters(&self) -> [T; 36]"));
    let text = ok(&["show", &path, "--base-parameters"]);
    assert!(
        text.contains("36 base parameters of 60 standard parameters"),
        "{text}"
    );
    assert!(
        text.contains("  MZR_forearm_link = MZ_forearm_link + 0.39225*M_wrist_1_link"),
        "{text}"
    );
    let dp = robot("double_pendulum");
    for (format, file) in [("text", "txt"), ("latex", "tex"), ("markdown", "md")] {
        snapshot(
            &format!("double_pendulum_base_parameters.{file}"),
            &ok(&["show", &dp, "--base-parameters", "--format", format]),
        );
    }
    let document = ok(&[
        "show",
        &dp,
        "--base-parameters",
        "--format",
        "latex",
        "--standalone",
    ]);
    assert!(document.starts_with("\\documentclass") && document.ends_with("\\end{document}\n"));
    bad_usage(&["show", &dp, "--base-parameters", "--term", "M"]);
}

#[test]
fn info_describes_every_robot() {
    for name in ROBOTS {
        let json = reference(name);
        let joints = json["joints"].as_array().expect("joints");
        let out = ok(&["info", &robot(name)]);
        assert!(out.contains(&format!("degrees of freedom: {}\n", joints.len())));
        for (i, j) in joints.iter().enumerate() {
            let j = j.as_str().expect("joint name");
            assert!(
                out.contains(&format!(" q{} {j}: ", i + 1)),
                "{name}: {j}\n{out}"
            );
        }
        for f in [
            "mass_matrix",
            "gravity",
            "bias",
            "coriolis_matrix",
            "forward_dynamics",
        ] {
            assert!(
                out.contains(&format!("\n  {f} ")),
                "{name}: no op count of {f}"
            );
        }
        assert!(out.contains("moving mass: ") && out.contains("  derivation: "));
    }
    let panda = ok(&["info", &robot("panda")]);
    assert!(
        panda.contains("(merged: panda_link8, panda_hand, panda_hand_tcp)"),
        "{panda}"
    );
    assert!(panda.contains("mimics panda_finger_joint1"));
    let kinova = ok(&["info", &robot("kinova")]);
    assert!(kinova.contains(": continuous about "));
}

/// With contacts, `info` lists the functions composed at run time (impulse dynamics for a set
/// of active contacts, the configuration manifold) as `run time`, and the straight-line part
/// of the others with its count (the plain contact and impulse dynamics are straight-line).
#[test]
fn info_lists_the_run_time_functions() {
    let urdf = workspace().join("tests/robots/floating/anymal.urdf");
    let out = ok(&[
        "info",
        urdf.to_str().unwrap(),
        "--floating-base",
        "--contact",
        "LF_FOOT",
        "--contact",
        "RH_FOOT",
    ]);
    let line = |name: &str| -> &str {
        out.lines()
            .find(|l| l.split_whitespace().next() == Some(name))
            .unwrap_or_else(|| panic!("no line for {name}:\n{out}"))
    };
    for name in ["impulse_dynamics_active", "difference"] {
        assert!(line(name).ends_with("  run time"), "{}", line(name));
    }
    for name in [
        "contact_forward_dynamics",
        "impulse_dynamics",
        "contact_forward_dynamics_active",
        "contact_forward_dynamics_stabilized",
        "contact_placements",
    ] {
        assert!(line(name).contains(" total: "), "{}", line(name));
    }
}

/// `info --derivatives` lists the derivatives with the operation counts the generated code
/// documents (`generate --derivatives`); without the flag they are not derived.
#[test]
fn info_counts_the_derivatives_operations() {
    let urdf = robot("ur5");
    let out = ok(&["info", &urdf, "--derivatives"]);
    let code = ok(&["generate", &urdf, "--derivatives"]);
    for name in [
        "inverse_dynamics_derivatives",
        "mass_matrix_inverse",
        "forward_dynamics_derivatives",
    ] {
        let line = out
            .lines()
            .find(|l| l.split_whitespace().next() == Some(name))
            .unwrap_or_else(|| panic!("no line for {name}:\n{out}"));
        let counts = line.split(" total: ").nth(1).expect("operation counts");
        // The method's documentation ends with its operation count line.
        let method = code
            .split(&format!("fn {name}("))
            .next()
            .and_then(|before| before.rsplit("/// Operations: ").next())
            .and_then(|after| after.lines().next())
            .unwrap_or_else(|| panic!("no documented count for {name}"));
        assert_eq!(format!("{counts}."), method, "{name}");
    }
    let plain = ok(&["info", &urdf]);
    assert!(!plain.contains("inverse_dynamics_derivatives"), "{plain}");
}

fn numbers(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|x| x.as_f64().expect("number"))
        .collect()
}

fn joined(v: &[f64]) -> String {
    v.iter()
        .map(|x| x.to_string())
        .collect::<Vec<_>>()
        .join(",")
}

/// `[a, b, c]` after the last ` = ` of the line starting with `prefix`.
fn parse_list(out: &str, prefix: &str) -> Vec<f64> {
    let line = out
        .lines()
        .find(|l| l.starts_with(prefix))
        .unwrap_or_else(|| panic!("no `{prefix}` in\n{out}"));
    parse_bracketed(line.rsplit(" = ").next().expect("value"))
}

fn parse_bracketed(s: &str) -> Vec<f64> {
    s.trim()
        .trim_start_matches('[')
        .trim_end_matches(']')
        .split(", ")
        .map(|x| x.parse().expect("a number"))
        .collect()
}

#[track_caller]
fn close(what: &str, a: &[f64], b: &[f64]) {
    assert_eq!(a.len(), b.len(), "{what}");
    for (x, y) in a.iter().zip(b) {
        assert!(
            (x - y).abs() <= 1e-9 * y.abs().max(1.0),
            "{what}: {x} vs {y}"
        );
    }
}

#[test]
fn eval_matches_the_reference_dynamics() {
    for name in ROBOTS {
        let json = reference(name);
        let s = &json["samples"][3];
        let n = json["joints"].as_array().expect("joints").len();
        let (q, qd, qdd, tau_in) = (
            joined(&numbers(&s["q"])),
            joined(&numbers(&s["qd"])),
            joined(&numbers(&s["qdd"])),
            joined(&numbers(&s["tau_in"])),
        );
        let path = robot(name);
        let out = ok(&[
            "eval", &path, "--q", &q, "--qd", &qd, "--qdd", &qdd, "--tau", &tau_in,
        ]);
        let rows: Vec<f64> = out
            .lines()
            .skip_while(|l| !l.starts_with("mass matrix M(q):"))
            .skip(1)
            .take(n)
            .flat_map(parse_bracketed)
            .collect();
        let m: Vec<f64> = s["mass_matrix"]
            .as_array()
            .expect("rows")
            .iter()
            .flat_map(numbers)
            .collect();
        close(&format!("{name} M"), &rows, &m);
        close(
            &format!("{name} b"),
            &parse_list(&out, "bias "),
            &numbers(&s["bias"]),
        );
        close(
            &format!("{name} G"),
            &parse_list(&out, "gravity "),
            &numbers(&s["gravity"]),
        );
        close(
            &format!("{name} tau"),
            &parse_list(&out, "inverse dynamics "),
            &numbers(&s["tau"]),
        );
        close(
            &format!("{name} qdd"),
            &parse_list(&out, "forward dynamics "),
            &numbers(&s["forward_dynamics"]),
        );
        close(
            &format!("{name} T"),
            &parse_list(&out, "kinetic energy "),
            &[s["kinetic_energy"].as_f64().expect("T")],
        );
    }
    // Velocities, accelerations and torques default to zero: then tau = G.
    let path = robot("double_pendulum");
    let out = ok(&["eval", &path, "--q", "-0.3,0.7", "--digits", "8"]);
    assert_eq!(
        parse_list(&out, "gravity "),
        parse_list(&out, "inverse dynamics ")
    );
    let e = bad_input(&["eval", &path, "--q", "0.1,0.2,0.3"]);
    assert!(
        e.contains("--q has 3 value(s), but 2dof_planar has 2 joint(s): joint1, joint2"),
        "{e}"
    );
    bad_input(&["eval", &path, "--q", "0,0", "--tau", "1"]);
}

#[test]
fn bad_input_gives_one_line_and_status_1() {
    let (_guard, dir) = scratch("bad-input");
    let write = |name: &str, text: &str| -> String {
        let p = dir.join(name);
        std::fs::write(&p, text).expect("write");
        path_str(&p).to_string()
    };
    let malformed = write(
        "malformed.urdf",
        "<robot name=\"x\">\n  <link name=\"a\">\n",
    );
    let dangling = write(
        "dangling.urdf",
        r#"<robot name="x"><link name="a"/><link name="b"/>
           <joint name="j" type="revolute"><parent link="a"/><child link="c"/>
           <axis xyz="0 0 1"/></joint></robot>"#,
    );
    let not_xml = write("binary.urdf", "\u{0}\u{1}garbage\n\nmore");
    let missing = path_str(&dir.join("missing.urdf")).to_string();
    for file in [
        &malformed,
        &dangling,
        &not_xml,
        &missing,
        &"tests/robots".to_string(),
    ] {
        for cmd in ["show", "info", "generate"] {
            let e = bad_input(&[cmd, file]);
            let shown = Path::new(file).file_name().expect("name").to_string_lossy();
            assert!(
                e.contains(&*shown),
                "{cmd} {file}: the message should name the file: {e}"
            );
        }
        bad_input(&["eval", file, "--q", "0"]);
    }
    let e = bad_input(&["show", &dangling]);
    assert!(e.contains('c'), "{e}");
}

#[test]
fn bad_usage_gives_status_2() {
    let path = robot("double_pendulum");
    bad_usage(&[]);
    bad_usage(&["frobnicate"]);
    bad_usage(&["show"]);
    bad_usage(&["show", &path, "--format", "pdf"]);
    bad_usage(&["show", &path, "--form", "compact"]);
    bad_usage(&["show", &path, "--term", "Q"]);
    bad_usage(&["show", &path, "--entry", "0,1"]);
    bad_usage(&["show", &path, "--digits", "many"]);
    bad_usage(&["show", &path, "--gravity", "1,2"]);
    bad_usage(&["show", &path, "--no-such-flag"]);
    bad_usage(&["eval", &path]);
    bad_usage(&["eval", &path, "--q", "a,b"]);
    bad_usage(&["eval", &path, "--q", "nan,0"]);
    bad_usage(&["generate"]);
}

#[test]
fn help_documents_every_command_and_flag() {
    let top = ok(&["--help"]);
    for c in ["generate", "show", "info", "eval"] {
        assert!(top.contains(c), "{top}");
    }
    assert!(ok(&["--version"]).starts_with("eomgen "));
    let cases: [(&str, &[&str]); 4] = [
        (
            "generate",
            &[
                "--output",
                "--type-name",
                "--module-name",
                "--gravity",
                "--joint-order",
                "--symbolic",
                "--derivatives",
                "--regressor",
            ],
        ),
        (
            "show",
            &[
                "--term",
                "--entry",
                "--format",
                "--symbolic",
                "--digits",
                "--form",
                "--max-terms",
                "--base-parameters",
            ],
        ),
        ("info", &["--gravity", "--joint-order"]),
        ("eval", &["--q", "--qd", "--qdd", "--tau", "--digits"]),
    ];
    for (cmd, flags) in cases {
        let help = ok(&[cmd, "--help"]);
        for f in flags {
            assert!(
                help.contains(f),
                "`eomgen {cmd} --help` does not document {f}"
            );
        }
        // Each flag states its default once.
        let mut options: Vec<String> = Vec::new();
        for line in help.lines() {
            match options.last_mut() {
                Some(option) if !line.trim_start().starts_with('-') => option.push_str(line),
                _ => options.push(line.to_string()),
            }
        }
        for option in options {
            assert!(
                option.matches("[default:").count() <= 1,
                "`eomgen {cmd} --help` repeats a default: {option}"
            );
        }
    }
}

#[test]
fn snapshots_of_the_double_pendulum() {
    let path = robot("double_pendulum");
    snapshot("double_pendulum.txt", &ok(&["show", &path]));
    snapshot(
        "double_pendulum.tex",
        &ok(&["show", &path, "--format", "latex"]),
    );
    snapshot(
        "double_pendulum.md",
        &ok(&["show", &path, "--format", "markdown"]),
    );
    snapshot(
        "double_pendulum_symbolic.txt",
        &ok(&["show", &path, "--symbolic", "--term", "M,C,G"]),
    );
}

/// A planar two-link arm: joints about z, link 1 of length l1 (the x offset of joint 2), centres
/// of mass on the links' x axes at lc1 and lc2, gravity along -y.
const PLANAR: &str = r#"<robot name="planar_two_link">
  <link name="base"/>
  <link name="link1">
    <inertial>
      <origin xyz="0.4 0 0"/>
      <mass value="2"/>
      <inertia ixx="0.05" ixy="0" ixz="0" iyy="0.05" iyz="0" izz="0.1"/>
    </inertial>
  </link>
  <link name="link2">
    <inertial>
      <origin xyz="0.3 0 0"/>
      <mass value="1.5"/>
      <inertia ixx="0.025" ixy="0" ixz="0" iyy="0.025" iyz="0" izz="0.05"/>
    </inertial>
  </link>
  <joint name="joint1" type="continuous">
    <parent link="base"/> <child link="link1"/> <axis xyz="0 0 1"/>
  </joint>
  <joint name="joint2" type="continuous">
    <parent link="link1"/> <child link="link2"/> <origin xyz="1 0 0"/> <axis xyz="0 0 1"/>
  </joint>
</robot>
"#;

/// A small deterministic generator (xorshift64*), uniform in `[lo, hi)`.
struct Rng(u64);

impl Rng {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let bits = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11;
        lo + (hi - lo) * (bits as f64 / (1u64 << 53) as f64)
    }
}

/// The arm's dynamics derived by hand (Spong, Hutchinson and Vidyasagar, section 7.4):
///
/// Centres of mass: `p1 = lc1 (c1, s1)`, `p2 = l1 (c1, s1) + lc2 (c12, s12)`.
/// Velocities: `v1 = lc1 qd1 (-s1, c1)`,
/// `v2 = l1 qd1 (-s1, c1) + lc2 (qd1 + qd2) (-s12, c12)`, so
/// `|v2|^2 = l1^2 qd1^2 + lc2^2 (qd1 + qd2)^2 + 2 l1 lc2 qd1 (qd1 + qd2) c2`.
/// Angular velocities `w1 = qd1`, `w2 = qd1 + qd2` about z.
/// `T = (m1 |v1|^2 + m2 |v2|^2 + I1 w1^2 + I2 w2^2) / 2 = qd^T M qd / 2` gives
/// `M11 = I1 + I2 + m1 lc1^2 + m2 (l1^2 + lc2^2 + 2 l1 lc2 c2)`,
/// `M12 = I2 + m2 (lc2^2 + l1 lc2 c2)`, `M22 = I2 + m2 lc2^2`.
/// Christoffel symbols `G_ijk = (dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i) / 2` with
/// `h = -m2 l1 lc2 s2` (only `q2` appears): `G_111 = 0`, `G_112 = G_121 = dM11/dq2 / 2 = h`,
/// `G_122 = dM12/dq2 - dM22/dq1 / 2 = h`, `G_211 = dM21/dq1 - dM11/dq2 / 2 = -h`,
/// `G_212 = G_221 = (dM21/dq2 + dM22/dq1 - dM12/dq2) / 2 = 0`, `G_222 = 0`.
/// Hence Craig's `C = [[0, h], [-h, 0]]`, `B = [[2h], [0]]`, the Coriolis matrix
/// `C(q, qd) = [[h qd2, h (qd1 + qd2)], [-h qd1, 0]]` and `b = (h qd2^2 + 2 h qd1 qd2, -h qd1^2)`.
/// `V = g (m1 lc1 s1 + m2 (l1 s1 + lc2 s12))`, so `G1 = g ((m1 lc1 + m2 l1) c1 + m2 lc2 c12)` and
/// `G2 = g m2 lc2 c12`.
struct Hand {
    m: [[f64; 2]; 2],
    c: [[f64; 2]; 2],
    b: [f64; 2],
    cqd: [[f64; 2]; 2],
    bias: [f64; 2],
    g: [f64; 2],
    tau: [f64; 2],
    t: f64,
    v: f64,
}

#[allow(clippy::too_many_arguments)]
fn by_hand(
    [m1, lc1, i1, m2, lc2, i2, l1]: [f64; 7],
    q: [f64; 2],
    qd: [f64; 2],
    qdd: [f64; 2],
    grav: f64,
) -> Hand {
    let (s1, c1) = q[0].sin_cos();
    let (s2, c2) = q[1].sin_cos();
    let (s12, c12) = (q[0] + q[1]).sin_cos();
    let m11 = i1 + i2 + m1 * lc1 * lc1 + m2 * (l1 * l1 + lc2 * lc2 + 2.0 * l1 * lc2 * c2);
    let m12 = i2 + m2 * (lc2 * lc2 + l1 * lc2 * c2);
    let m22 = i2 + m2 * lc2 * lc2;
    let h = -m2 * l1 * lc2 * s2;
    let m = [[m11, m12], [m12, m22]];
    let cqd = [[h * qd[1], h * (qd[0] + qd[1])], [-h * qd[0], 0.0]];
    let bias = [
        h * qd[1] * qd[1] + 2.0 * h * qd[0] * qd[1],
        -h * qd[0] * qd[0],
    ];
    let g = [
        grav * ((m1 * lc1 + m2 * l1) * c1 + m2 * lc2 * c12),
        grav * m2 * lc2 * c12,
    ];
    let tau = [0, 1].map(|i| m[i][0] * qdd[0] + m[i][1] * qdd[1] + bias[i] + g[i]);
    let t = 0.5
        * (0..2)
            .flat_map(|i| (0..2).map(move |j| (i, j)))
            .map(|(i, j)| qd[i] * m[i][j] * qd[j])
            .sum::<f64>();
    let v = grav * (m1 * lc1 * s1 + m2 * (l1 * s1 + lc2 * s12));
    Hand {
        m,
        c: [[0.0, h], [-h, 0.0]],
        b: [2.0 * h, 0.0],
        cqd,
        bias,
        g,
        tau,
        t,
        v,
    }
}

#[test]
fn textbook_planar_two_link_arm() {
    use eomgen::cas::SymbolKind;
    let options = eomgen::ModelOptions {
        symbolic: eomgen::SymbolicParams::All,
        gravity: [0.0, -9.81, 0.0],
        ..Default::default()
    };
    let model = eomgen::urdf::load_str(PLANAR, "planar.urdf", &options).expect("valid URDF");
    let d = eomgen::dynamics::Derivation::new(&model);
    // Our names for the textbook's m1, lc1, I1, m2, lc2, I2, l1; zero parameters stay zeros.
    let names = [
        "m_link1",
        "cx_link1",
        "Izz_link1",
        "m_link2",
        "cx_link2",
        "Izz_link2",
        "x_joint2",
    ];
    let mut symbols: Vec<&str> = d.params.iter().map(|p| p.0.as_str()).collect();
    symbols.sort_unstable();
    // The links are flat discs (a possible inertia needs Ixx + Iyy >= Izz); rotating about z
    // only, their Ixx and Iyy never enter the equations.
    let discs = ["Ixx_link1", "Iyy_link1", "Ixx_link2", "Iyy_link2"];
    let mut expected = [names.as_slice(), &discs].concat();
    expected.sort_unstable();
    assert_eq!(symbols, expected);

    let mut outputs = Vec::new();
    outputs.extend(d.mass_matrix.iter().flatten());
    outputs.extend(d.centrifugal.iter().flatten());
    outputs.extend(d.coriolis_pairs.iter().flatten());
    outputs.extend(d.coriolis_matrix.iter().flatten());
    outputs.extend(&d.bias);
    outputs.extend(&d.gravity);
    outputs.extend(&d.tau);
    outputs.push(d.kinetic_energy);
    outputs.push(d.potential_energy);
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for _ in 0..50 {
        let p = [
            rng.uniform(0.5, 3.0),
            rng.uniform(0.1, 0.6),
            rng.uniform(0.01, 0.3),
            rng.uniform(0.5, 3.0),
            rng.uniform(0.1, 0.6),
            rng.uniform(0.01, 0.3),
            rng.uniform(0.5, 1.5),
        ];
        let q = [rng.uniform(-3.2, 3.2), rng.uniform(-3.2, 3.2)];
        let qd = [rng.uniform(-2.0, 2.0), rng.uniform(-2.0, 2.0)];
        let qdd = [rng.uniform(-5.0, 5.0), rng.uniform(-5.0, 5.0)];
        let v = d
            .graph
            .eval(&outputs, |s| match s.kind {
                SymbolKind::Q(i) => Some(q[i]),
                SymbolKind::Qd(i) => Some(qd[i]),
                SymbolKind::Qdd(i) => Some(qdd[i]),
                SymbolKind::Param => names
                    .iter()
                    .position(|n| *n == s.name)
                    .map(|k| p[k])
                    .or_else(|| discs.contains(&s.name.as_str()).then_some(0.05)),
                #[allow(unreachable_patterns)]
                _ => None,
            })
            .expect("every symbol bound");
        let h = by_hand(p, q, qd, qdd, 9.81);
        let mut want = Vec::new();
        want.extend(h.m.iter().flatten());
        want.extend(h.c.iter().flatten());
        want.extend(h.b);
        want.extend(h.cqd.iter().flatten());
        want.extend(h.bias);
        want.extend(h.g);
        want.extend(h.tau);
        want.push(h.t);
        want.push(h.v);
        for (k, (a, b)) in v.iter().zip(&want).enumerate() {
            assert!(
                (a - b).abs() <= 1e-12 * b.abs().max(1.0),
                "output {k}: derived {a}, by hand {b} (params {p:?}, q {q:?})"
            );
        }
    }

    // The printed equations show the textbook structure.
    let (_guard, dir) = scratch("planar");
    let file = dir.join("planar.urdf");
    std::fs::write(&file, PLANAR).expect("write");
    let out = ok(&[
        "show",
        path_str(&file),
        "--symbolic",
        "--gravity",
        "0,-9.81,0",
        "--term",
        "M,B,C,G",
    ]);
    let line = |name: &str| -> &str {
        out.lines()
            .find_map(|l| l.strip_prefix(&format!("  {name} = ")))
            .unwrap_or_else(|| panic!("no {name} in\n{out}"))
    };
    let m11 = line("M11");
    assert!(
        m11.contains(" + 2*m_link2*cx_link2*x_joint2*c2"),
        "M11 should show 2 m2 l1 lc2 cos(q2): {m11}"
    );
    assert_eq!(
        m11,
        "Izz_link1 + Izz_link2 + m_link1*cx_link1^2 + m_link2*cx_link2^2 + m_link2*x_joint2^2 \
         + 2*m_link2*cx_link2*x_joint2*c2"
    );
    assert_eq!(
        line("M12"),
        "Izz_link2 + m_link2*cx_link2^2 + m_link2*cx_link2*x_joint2*c2"
    );
    assert_eq!(line("M22"), "Izz_link2 + m_link2*cx_link2^2");
    assert_eq!(line("B1_12"), "-2*m_link2*cx_link2*x_joint2*s2");
    assert_eq!(line("C12"), "-m_link2*cx_link2*x_joint2*s2");
    assert_eq!(line("C21"), "m_link2*cx_link2*x_joint2*s2");
    assert_eq!(
        line("G1"),
        "9.81*m_link1*cx_link1*c1 + 9.81*m_link2*x_joint2*c1 + 9.81*m_link2*cx_link2*c12"
    );
    assert!(out.contains("  c2 = cos(q2)\n") && out.contains("  c12 = cos(q1 + q2)\n"));
    assert!(out.contains("  x_joint2: origin of joint joint2 in its parent's frame, x coordinate"));
}

/// The README's quick start: exactly two commands, the first runs eomgen on a bundled robot
/// (here through the built binary, from the workspace root), the second is the test command CI
/// runs.
#[test]
fn readme_quick_start_works() {
    let readme = std::fs::read_to_string(workspace().join("README.md")).expect("README.md");
    let section = readme
        .split("\n## ")
        .find(|s| s.starts_with("Quick start"))
        .expect("a `## Quick start` section");
    let block = section
        .split("```")
        .nth(1)
        .expect("a code block in the quick start");
    let commands: Vec<&str> = block
        .lines()
        .skip(1) // the info string
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
        .collect();
    assert_eq!(commands.len(), 2, "{commands:?}");
    assert_eq!(commands[1], "cargo test --workspace");
    let args: Vec<&str> = commands[0]
        .strip_prefix("cargo run -p eomgen-cli -- ")
        .expect("the first command runs eomgen through cargo")
        .split_whitespace()
        .collect();
    let out = ok(&args);
    assert!(out.contains("  M11 = "), "{out}");
    // The sample in the README is what the binary prints.
    let sample = ok(&["show", "tests/robots/double_pendulum.urdf", "--term", "M,G"]);
    for line in sample
        .lines()
        .filter(|l| l.starts_with("  M") || l.starts_with("  G"))
    {
        assert!(readme.contains(line), "README sample is stale: {line}");
    }
}

#[test]
fn mimic_joints_on_the_command_line() {
    let panda = robot("panda");
    // info says how to honour the tag, and what honouring it does.
    let plain = ok(&["info", &panda]);
    assert!(
        plain.contains("--mimic (Builder::mimic_joints()"),
        "{plain}"
    );
    let honoured = ok(&["info", &panda, "--mimic"]);
    assert!(
        honoured.contains("degrees of freedom: 8 (9 moving joints, 1 of them mimic joints"),
        "{honoured}"
    );
    assert!(honoured.contains("mimic panda_finger_joint2: prismatic"));
    assert!(honoured.contains("(mimics panda_finger_joint1: follows q8 x 1 + 0)"));
    // eval in the 8 coordinates, against Pinocchio with the mimic tag honoured.
    let text = std::fs::read_to_string(workspace().join("tests/robots/panda.mimic.json"))
        .expect("reference JSON");
    let json: serde_json::Value = serde_json::from_str(&text).expect("valid JSON");
    let s = &json["samples"][3];
    let (q, qd, qdd, tau_in) = (
        joined(&numbers(&s["q"])),
        joined(&numbers(&s["qd"])),
        joined(&numbers(&s["qdd"])),
        joined(&numbers(&s["tau_in"])),
    );
    let out = ok(&[
        "eval", &panda, "--mimic", "--q", &q, "--qd", &qd, "--qdd", &qdd, "--tau", &tau_in,
    ]);
    assert!(out.starts_with("panda: 8 degrees of freedom; joint order: panda_joint1, "));
    assert!(out.contains(", panda_finger_joint1\n"), "{out}");
    close(
        "panda --mimic tau",
        &parse_list(&out, "inverse dynamics "),
        &numbers(&s["tau"]),
    );
    close(
        "panda --mimic qdd",
        &parse_list(&out, "forward dynamics "),
        &numbers(&s["forward_dynamics"]),
    );
    let e = bad_input(&["eval", &panda, "--mimic", "--q", &joined(&[0.0; 9])]);
    assert!(e.contains("has 8 joint(s)"), "{e}");
    // show: the reduced equations, the mimic joint described by its coordinate.
    let shown = ok(&["show", &panda, "--mimic", "--term", "G"]);
    assert!(shown.contains("8 degrees of freedom"), "{shown}");
    assert!(
        shown.contains(
            "mimic: panda_finger_joint2, prismatic about (0, -1, 0), mimic joint: 1 q8 + 0"
        ),
        "{shown}"
    );
}

/// `--form projected-newton-euler` and `--form hamiltonian` print the double pendulum as a
/// person writes them (snapshots in every format), and refuse a robot too large to print in
/// one line.
#[test]
fn show_other_forms() {
    let path = robot("double_pendulum");
    for (form, stem) in [
        (
            "projected-newton-euler",
            "double_pendulum_projected_newton_euler",
        ),
        ("hamiltonian", "double_pendulum_hamiltonian"),
    ] {
        for (format, ext) in [("text", "txt"), ("latex", "tex"), ("markdown", "md")] {
            let out = ok(&["show", &path, "--form", form, "--format", format]);
            snapshot(&format!("{stem}.{ext}"), &out);
        }
    }
    let text = ok(&["show", &path, "--form", "projected-newton-euler"]);
    for section in [
        "Mass matrix, share of body 1 of 2, link `link1`:",
        "Bias, share of body 2 of 2, link `link2`:",
        "(M = M^(1) + M^(2))",
    ] {
        assert!(text.contains(section), "no {section:?}");
    }
    let text = ok(&["show", &path, "--form", "hamiltonian"]);
    assert!(text.contains("\n  pd1 = tau1 + "), "{text}");
    // A 14-joint chain whose axes alternate is beyond what is printed.
    let mut urdf = String::from(r#"<robot name="chain"><link name="l0"/>"#);
    for i in 1..=14 {
        let axis = ["1 0 0", "0 1 0", "0 0 1"][i % 3];
        urdf.push_str(&format!(
            r#"<link name="l{i}"><inertial><origin xyz="0.1 0.02 0.3"/><mass value="1"/><inertia ixx="0.01" ixy="0.001" ixz="0" iyy="0.02" iyz="0" izz="0.015"/></inertial></link><joint name="j{i}" type="revolute"><parent link="l{}"/><child link="l{i}"/><origin xyz="0 0.1 0.4" rpy="0.1 0 0"/><axis xyz="{axis}"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>"#,
            i - 1
        ));
    }
    urdf.push_str("</robot>");
    let (_guard, dir) = scratch("chain14");
    let chain = dir.join("chain14.urdf");
    std::fs::write(&chain, urdf).expect("write");
    let err = bad_input(&["show", path_str(&chain), "--form", "projected-newton-euler"]);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("the projected Newton-Euler form takes"),
        "{err}"
    );
    assert!(err.contains("it is for small robots"), "{err}");
    // With mimic joints the per-body shares are refused, not printed wrong.
    let panda = robot("panda");
    let err = bad_input(&[
        "show",
        &panda,
        "--mimic",
        "--form",
        "projected-newton-euler",
    ]);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("not printed with mimic joints yet"), "{err}");
}
