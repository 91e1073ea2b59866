//! The catalogue of bad input: malformed, hostile and oversized URDFs. Every case must end in a
//! one-line error that names the file and the culprit, or, for hostile but legal names, in
//! generated Rust that parses and that no name can break out of. Never a panic, a hang or a
//! stack overflow; the whole catalogue runs in seconds.
//!
//! Fixtures that read better as files are in `tests/urdf/hostile/`; the rest are built here.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;
use std::time::{Duration, Instant};

use proc_macro2::{TokenStream, TokenTree};

/// A link with a plausible inertial.
fn link(name: &str) -> String {
    format!(
        r#"<link name="{name}"><inertial><origin xyz="0 0 0.1"/><mass value="1"/>
        <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>"#
    )
}

/// A link whose inertial has the given attributes: `mass` and the inertia's six entries.
fn link_with(name: &str, origin: &str, mass: &str, inertia: [&str; 6]) -> String {
    let [ixx, ixy, ixz, iyy, iyz, izz] = inertia;
    format!(
        r#"<link name="{name}"><inertial><origin {origin}/><mass value="{mass}"/>
        <inertia ixx="{ixx}" ixy="{ixy}" ixz="{ixz}" iyy="{iyy}" iyz="{iyz}" izz="{izz}"/>
        </inertial></link>"#
    )
}

/// A joint; `extra` goes inside the element (axis, limit, origin).
fn joint(name: &str, kind: &str, parent: &str, child: &str, extra: &str) -> String {
    format!(
        r#"<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>
        {extra}</joint>"#
    )
}

fn robot(parts: &[String]) -> String {
    format!("<robot name=\"r\">\n{}\n</robot>", parts.concat())
}

/// A two-link arm, base welded to the world, with `extra` in the joint and `tip` as the
/// moving link.
fn arm(extra: &str, tip: String) -> String {
    robot(&[
        link("base"),
        tip,
        joint("shoulder", "revolute", "base", "tip", extra),
    ])
}

const UNIT: [&str; 6] = ["0.01", "0", "0", "0.01", "0", "0.01"];

/// A chain of `n` links joined by joints of type `kind`, every link with mass.
fn chain(n: usize, kind: &str) -> String {
    let mut parts = vec![link("l0")];
    for i in 1..=n {
        parts.push(link(&format!("l{i}")));
        parts.push(joint(
            &format!("j{i}"),
            kind,
            &format!("l{}", i - 1),
            &format!("l{i}"),
            r#"<axis xyz="0 1 0"/><origin xyz="0 0 0.1"/>"#,
        ));
    }
    robot(&parts)
}

fn fixture(name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/urdf/hostile")
        .join(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// What a case must give.
enum Expect {
    /// An error whose message contains every one of these (besides the file name).
    Error(&'static [&'static str]),
    /// A format error: the message starts with `file:line:column: ` and contains every one of
    /// these.
    Located(&'static [&'static str]),
    /// Generated code (checked by [`check_safe_source`]).
    Code,
}
use Expect::{Code, Error, Located};

/// The catalogue: a name (also the file name in messages), the URDF text and the outcome.
fn catalogue() -> Vec<(&'static str, String, Expect)> {
    let nan_origin = r#"xyz="0 0 0.1""#;
    vec![
        // Not a URDF at all.
        ("empty", String::new(), Located(&["no XML element"])),
        ("blank", " \n\t ".into(), Located(&["no XML element"])),
        (
            "not_xml",
            "robot: {name: r}".into(),
            Located(&["not well-formed XML"]),
        ),
        (
            "truncated",
            robot(&[link("base")])[..40].into(),
            Located(&["2:24: ", "truncated"]),
        ),
        (
            "binary",
            "\u{0}\u{1}<\u{7f}>\u{fffd}".into(),
            Located(&["1:1: ", "not well-formed XML"]),
        ),
        (
            "no_links",
            "<robot name=\"r\"/>".into(),
            Error(&["no links"]),
        ),
        (
            "only_links",
            robot(&[link("base")]),
            Error(&["no moving joint"]),
        ),
        // XML attacks.
        (
            "billion_laughs",
            fixture("billion_laughs.urdf"),
            Located(&["2:1: ", "document type declarations"]),
        ),
        (
            "external_entity",
            fixture("external_entity.urdf"),
            Located(&["2:1: ", "entities are not accepted"]),
        ),
        (
            // Made the former XML parser panic; harmless to this one.
            "xmlns_prefix_declared",
            robot(&[link("base")]).replace(
                "<robot name=\"r\">",
                "<robot name=\"r\" xmlns:xmlns=\"http://www.ros.org/wiki/xacro\">",
            ),
            Error(&["no moving joint"]),
        ),
        (
            // Unclosed: the parser's tokenizer would recurse 100,000 levels deep.
            "deep_nesting",
            format!("<robot name=\"r\">{}", "<link>".repeat(100_000)),
            Located(&["1:611: ", "nested more than 100 levels"]),
        ),
        (
            "deep_nesting_closed",
            format!(
                "<robot name=\"r\">{}{}</robot>",
                "<gazebo>".repeat(100_000),
                "</gazebo>".repeat(100_000)
            ),
            Located(&["1:809: ", "nested more than 100 levels"]),
        ),
        // Numbers.
        (
            "huge_mass",
            arm("", link_with("tip", nan_origin, "1e308", UNIT)),
            Error(&["link `tip`", "mass holds 1e308", "largest magnitude"]),
        ),
        (
            "overflowing_number",
            arm(r#"<origin xyz="1e400 0 0"/>"#, link("tip")),
            Error(&["joint `shoulder`", "origin", "not a finite number"]),
        ),
        (
            "subnormal_mass",
            arm("", link_with("tip", nan_origin, "1e-320", UNIT)),
            Code,
        ),
        (
            "nan_origin",
            arm(r#"<origin xyz="0 NaN 0"/>"#, link("tip")),
            Error(&["joint `shoulder`", "origin", "not a finite number"]),
        ),
        (
            "nan_mass",
            arm("", link_with("tip", nan_origin, "NaN", UNIT)),
            Error(&["link `tip`", "mass", "not a finite number"]),
        ),
        (
            "inf_inertia",
            arm(
                "",
                link_with("tip", nan_origin, "1", ["inf", "0", "0", "1", "0", "1"]),
            ),
            Error(&["link `tip`", "inertia", "not a finite number"]),
        ),
        (
            "nan_inertial_origin",
            arm("", link_with("tip", r#"rpy="nan 0 0""#, "1", UNIT)),
            Error(&["link `tip`", "not a finite number"]),
        ),
        (
            "inf_axis",
            arm(r#"<axis xyz="0 -inf 0"/>"#, link("tip")),
            Error(&["joint `shoulder`", "axis", "not a finite number"]),
        ),
        (
            "nan_limit",
            arm(
                r#"<limit lower="nan" upper="1" effort="1" velocity="1"/>"#,
                link("tip"),
            ),
            Error(&["joint `shoulder`", "limit is not a finite number"]),
        ),
        (
            "infinite_limits",
            arm(
                r#"<limit lower="-inf" upper="inf" effort="1" velocity="inf"/>"#,
                link("tip"),
            ),
            Code,
        ),
        (
            "not_a_number",
            arm("", link_with("tip", nan_origin, "heavy", UNIT)),
            Located(&["link `tip`: <mass value>: `heavy` is not a number"]),
        ),
        // Missing pieces.
        (
            "link_without_name",
            robot(&[link("base"), "<link/>".into()]),
            Located(&["<link> has no `name` attribute"]),
        ),
        (
            "joint_without_type",
            robot(&[
                link("base"),
                link("tip"),
                r#"<joint name="j"><parent link="base"/><child link="tip"/></joint>"#.into(),
            ]),
            Located(&["joint `j`: <joint> has no `type` attribute"]),
        ),
        (
            "joint_without_child",
            robot(&[
                link("base"),
                link("tip"),
                r#"<joint name="j" type="revolute"><parent link="base"/></joint>"#.into(),
            ]),
            Located(&["joint `j`: <joint> has no <child>"]),
        ),
        (
            "mass_without_value",
            arm("", link("tip").replace(r#"<mass value="1"/>"#, "<mass/>")),
            Located(&["link `tip`: <mass> has no `value` attribute"]),
        ),
        (
            "empty_joint_name",
            robot(&[
                link("base"),
                link("tip"),
                joint("", "revolute", "base", "tip", ""),
            ]),
            Error(&["joint number 1", "empty name"]),
        ),
        // Structure.
        (
            "dangling_child",
            robot(&[link("base"), joint("j", "revolute", "base", "ghost", "")]),
            Error(&["joint `j`", "child link `ghost`", "does not exist"]),
        ),
        (
            "dangling_parent",
            robot(&[link("tip"), joint("j", "revolute", "ghost", "tip", "")]),
            Error(&["joint `j`", "parent link `ghost`", "does not exist"]),
        ),
        (
            "cycle",
            robot(&[
                link("base"),
                link("a"),
                link("b"),
                joint("j0", "revolute", "base", "a", ""),
                joint("j1", "revolute", "a", "b", ""),
                joint("j2", "revolute", "b", "a", ""),
            ]),
            Error(&["two parents", "`a`"]),
        ),
        (
            "pure_cycle",
            robot(&[
                link("a"),
                link("b"),
                joint("j1", "revolute", "a", "b", ""),
                joint("j2", "revolute", "b", "a", ""),
            ]),
            Error(&["form a cycle", "`a`", "`b`"]),
        ),
        (
            "self_loop",
            robot(&[
                link("base"),
                link("a"),
                joint("j", "revolute", "a", "a", ""),
            ]),
            Error(&["`a`"]),
        ),
        (
            "several_roots",
            robot(&[
                link("base"),
                link("tip"),
                link("stray"),
                joint("j", "revolute", "base", "tip", ""),
            ]),
            Error(&["several root links", "`base`", "`stray`"]),
        ),
        (
            "two_parents",
            robot(&[
                link("base"),
                link("tip"),
                joint("j1", "revolute", "base", "tip", ""),
                joint("j2", "revolute", "base", "tip", ""),
            ]),
            Error(&["link `tip` has two parents", "`j1`", "`j2`"]),
        ),
        (
            "duplicate_link",
            robot(&[
                link("base"),
                link("tip"),
                link("tip"),
                joint("j", "revolute", "base", "tip", ""),
            ]),
            Error(&["link `tip` is defined more than once"]),
        ),
        (
            "duplicate_joint",
            robot(&[
                link("base"),
                link("a"),
                link("b"),
                joint("j", "revolute", "base", "a", ""),
                joint("j", "revolute", "a", "b", ""),
            ]),
            Error(&["joint `j` is defined more than once"]),
        ),
        // Physics.
        (
            "zero_axis",
            arm(r#"<axis xyz="0 0 0"/>"#, link("tip")),
            Error(&["joint `shoulder` has a zero axis"]),
        ),
        (
            "negative_mass",
            arm("", link_with("tip", nan_origin, "-1", UNIT)),
            Error(&["link `tip` has a negative mass"]),
        ),
        (
            "indefinite_inertia",
            arm(
                "",
                link_with("tip", nan_origin, "1", ["1", "2", "0", "1", "0", "1"]),
            ),
            Error(&["link `tip` has an impossible inertia"]),
        ),
        (
            "triangle_inequality",
            arm(
                "",
                link_with("tip", nan_origin, "1", ["1", "0", "0", "1", "0", "2.5"]),
            ),
            Error(&[
                "link `tip`",
                "triangle inequality 2.5 <= 1 + 1",
                "--repair-inertia",
            ]),
        ),
        (
            "conflicting_axes",
            arm(r#"<axis xyz="0 1 0"/><axis xyz="0 0 1"/>"#, link("tip")),
            Located(&["joint `shoulder`: a second <axis> with different content"]),
        ),
        (
            "short_vector",
            arm(r#"<origin xyz="0 1"/>"#, link("tip")),
            Located(&["joint `shoulder`: <origin xyz>: `0 1` holds 2 number(s)"]),
        ),
        (
            "massless_subtree",
            robot(&[
                link("base"),
                link("a"),
                "<link name=\"hand\"/>".into(),
                "<link name=\"finger\"/>".into(),
                joint("j1", "revolute", "base", "a", r#"<axis xyz="0 1 0"/>"#),
                joint("wrist", "revolute", "a", "hand", r#"<origin xyz="0 0 1"/>"#),
                joint("pin", "fixed", "hand", "finger", ""),
            ]),
            Error(&["joint `wrist`", "mass matrix would be singular"]),
        ),
        (
            "massless_prismatic",
            robot(&[
                link("base"),
                "<link name=\"slider\"/>".into(),
                joint("slide", "prismatic", "base", "slider", ""),
            ]),
            Error(&["joint `slide`", "singular"]),
        ),
        (
            "point_mass_on_axis",
            arm(
                r#"<axis xyz="0 0 1"/>"#,
                link_with("tip", "", "1", ["0", "0", "0", "0", "0", "0"]),
            ),
            Error(&["joint `shoulder`", "singular"]),
        ),
        // Joint types.
        (
            "floating_joint",
            robot(&[
                link("base"),
                link("tip"),
                joint("free", "floating", "base", "tip", ""),
            ]),
            // A free flyer below a root welded to the world (the root has mass).
            Code,
        ),
        (
            "planar_joint",
            robot(&[
                link("base"),
                link("tip"),
                joint("flat", "planar", "base", "tip", ""),
            ]),
            Code,
        ),
        (
            "planar_joint_off_axis",
            robot(&[
                link("base"),
                link("tip"),
                joint("flat", "planar", "base", "tip", r#"<axis xyz="1 0 0"/>"#),
            ]),
            Error(&["joint `flat` is planar", "axis (1 0 0) is not 0 0 1"]),
        ),
        (
            "spherical_joint",
            robot(&[
                link("base"),
                link("tip"),
                joint("ball", "spherical", "base", "tip", ""),
            ]),
            Error(&["joint `ball` is spherical", "not supported"]),
        ),
        (
            "unknown_joint_type",
            robot(&[
                link("base"),
                link("tip"),
                joint("j", "hinge", "base", "tip", ""),
            ]),
            Located(&["joint `j`: unknown joint type `hinge`"]),
        ),
        // Size.
        (
            "revolute_chain_10000",
            chain(10_000, "revolute"),
            Error(&[
                "10000 degrees of freedom",
                "limit of 64",
                "Builder::max_dof",
            ]),
        ),
        (
            "fixed_chain_10000",
            {
                // 10,000 welded links behind one moving joint: merged into one body.
                let text = chain(10_000, "fixed");
                text.replacen(
                    r#"name="j1" type="fixed""#,
                    r#"name="j1" type="revolute""#,
                    1,
                )
            },
            Code,
        ),
        (
            "many_roots",
            robot(
                &(0..10_000)
                    .map(|i| link(&format!("l{i}")))
                    .collect::<Vec<_>>(),
            ),
            Error(&["several root links", "`l0`", "9992 more"]),
        ),
        (
            "long_cycle",
            {
                let mut parts: Vec<String> = (0..5_000).map(|i| link(&format!("l{i}"))).collect();
                for i in 0..5_000 {
                    let (a, b) = (format!("l{i}"), format!("l{}", (i + 1) % 5_000));
                    parts.push(joint(&format!("j{i}"), "revolute", &a, &b, ""));
                }
                robot(&parts)
            },
            Error(&["form a cycle", "4992 more"]),
        ),
        (
            "terminal_escapes",
            robot(&[link("b\u{9b}31mX\u{202e}"), link("b\u{9b}31mX\u{202e}")]),
            Error(&["is defined more than once"]),
        ),
        // Hostile but legal names.
        ("hostile_names", fixture("names.urdf"), Code),
        (
            "colliding_names",
            robot(&[
                link("base"),
                link("a-b"),
                link("a_b"),
                link("a b"),
                link("A B"),
                joint("j-1", "revolute", "base", "a-b", r#"<axis xyz="0 1 0"/>"#),
                joint("j_1", "revolute", "a-b", "a_b", r#"<axis xyz="0 1 0"/>"#),
                joint("j 1", "revolute", "a_b", "a b", r#"<axis xyz="0 1 0"/>"#),
                joint("J 1", "revolute", "a b", "A B", r#"<axis xyz="0 1 0"/>"#),
            ]),
            Code,
        ),
        (
            "colliding_names_10000",
            {
                // 10,000 names that all sanitize to `L` (words are alphanumeric runs), welded
                // to the base of a one-joint arm.
                let punct: Vec<char> = "!#$%()*+,-./:;=?@[]^_{|}~".chars().collect();
                let name = |mut i: usize| {
                    let mut s = String::from("l");
                    for _ in 0..3 {
                        s.push(punct[i % punct.len()]);
                        i /= punct.len();
                    }
                    s
                };
                let mut parts = vec![link("base"), link("tip")];
                parts.push(joint("j", "revolute", "base", "tip", ""));
                for i in 0..10_000 {
                    parts.push(format!("<link name=\"{}\"/>", name(i)));
                    parts.push(joint(&format!("w{i}"), "fixed", "base", &name(i), ""));
                }
                robot(&parts)
            },
            Code,
        ),
        (
            "keyword_names",
            robot(&[
                link("self"),
                link("fn"),
                link("Self"),
                link("_"),
                joint("type", "revolute", "self", "fn", r#"<axis xyz="0 1 0"/>"#),
                joint("impl", "revolute", "fn", "Self", r#"<axis xyz="0 1 0"/>"#),
                joint("r#", "revolute", "Self", "_", r#"<axis xyz="0 1 0"/>"#),
            ])
            .replace("name=\"r\"", "name=\"crate\""),
            Code,
        ),
    ]
}

/// The marker that hostile names try to smuggle into generated code as an identifier.
const MARKER: &str = "pwned";

/// The generated source must parse, and no hostile name may have become code: `MARKER` may
/// appear inside string literals (doc comments included, which the tokenizer turns into
/// `#[doc = "..."]`), never as an identifier.
fn check_safe_source(case: &str, source: &str) -> Result<(), String> {
    syn::parse_file(source).map_err(|e| format!("{case}: generated code does not parse: {e}"))?;
    // Outside string literals (where they are escaped), these can only be in comments, where
    // rustc refuses them: bidirectional-text controls (a deny-by-default lint) and bare CR.
    let bidi = |c: char| matches!(c, '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}');
    if let Some(c) = source.chars().find(|&c| bidi(c) || c == '\r') {
        return Err(format!("{case}: raw {c:?} in the generated code"));
    }
    let tokens: TokenStream = source
        .parse()
        .map_err(|e| format!("{case}: generated code does not tokenize: {e}"))?;
    let mut stack: Vec<TokenTree> = tokens.into_iter().collect();
    while let Some(t) = stack.pop() {
        match t {
            TokenTree::Group(g) => stack.extend(g.stream()),
            TokenTree::Ident(i) if i == MARKER => {
                return Err(format!("{case}: a name broke out into code: `{i}`"))
            }
            _ => {}
        }
    }
    Ok(())
}

/// CPU time of the calling thread (Linux), so that a busy machine does not fail the time
/// limits; wall-clock time elsewhere.
struct Clock(Option<Duration>, Instant);

impl Clock {
    fn thread_cpu() -> Option<Duration> {
        let stat = std::fs::read_to_string("/proc/thread-self/stat").ok()?;
        // Fields after the parenthesized command name: state is field 3, utime 14, stime 15.
        let rest = &stat[stat.rfind(')')? + 2..];
        let fields: Vec<&str> = rest.split(' ').collect();
        let ticks: u64 =
            fields.get(11)?.parse::<u64>().ok()? + fields.get(12)?.parse::<u64>().ok()?;
        // The kernel reports in USER_HZ, 100 on every Linux platform Rust supports.
        Some(Duration::from_millis(ticks * 10))
    }
    fn start() -> Clock {
        Clock(Clock::thread_cpu(), Instant::now())
    }
    fn elapsed(&self) -> Duration {
        match (self.0, Clock::thread_cpu()) {
            (Some(a), Some(b)) => b.saturating_sub(a),
            _ => self.1.elapsed(),
        }
    }
}

/// Whether `msg` starts with `file:line:column: `.
fn starts_with_place(msg: &str, file: &str) -> bool {
    let Some(rest) = msg.strip_prefix(&format!("{file}:")) else {
        return false;
    };
    let mut parts = rest.splitn(3, ':');
    let number =
        |p: Option<&str>| p.is_some_and(|p| !p.is_empty() && p.bytes().all(|b| b.is_ascii_digit()));
    number(parts.next()) && number(parts.next()) && parts.next().is_some_and(|r| r.starts_with(' '))
}

/// Runs one case in-process; `Err` describes what went wrong.
fn run(case: &str, text: &str, expect: &Expect) -> Result<(), String> {
    let file = format!("{case}.urdf");
    let start = Clock::start();
    let outcome = catch_unwind(AssertUnwindSafe(|| {
        eomgen::Builder::from_urdf_str(text, &file).generate()
    }))
    .map_err(|p| {
        let what = p
            .downcast_ref::<String>()
            .cloned()
            .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_default();
        format!("{case}: panicked: {what}")
    })?;
    let elapsed = start.elapsed();
    // The largest cases take about 4 s; names colliding after sanitizing used to take
    // quadratic time.
    if elapsed > Duration::from_secs(8) {
        return Err(format!("{case}: took {elapsed:?}"));
    }
    match (outcome, expect) {
        (Err(e), Error(parts) | Located(parts)) => {
            let msg = e.to_string();
            let located = matches!(expect, Located(_));
            if located != starts_with_place(&msg, &file) {
                return Err(format!(
                    "{case}: message should start with the file{}: {msg}",
                    if located { ":line:column" } else { " alone" }
                ));
            }
            if !located && !msg.starts_with(&format!("{file}: ")) {
                return Err(format!(
                    "{case}: message does not start with the file: {msg}"
                ));
            }
            if msg.contains('\n') || msg.len() > 1_000 {
                return Err(format!("{case}: message not one short line: {msg}"));
            }
            match parts.iter().find(|p| !msg.contains(**p)) {
                Some(p) => Err(format!("{case}: message lacks {p:?}: {msg}")),
                None => Ok(()),
            }
        }
        (Ok(source), Code) => check_safe_source(case, &source),
        (Ok(_), Error(parts) | Located(parts)) => {
            Err(format!("{case}: generated code, expected error {parts:?}"))
        }
        (Err(e), Code) => Err(format!("{case}: expected code, got: {e}")),
    }
}

#[test]
fn every_catalogue_case_gives_a_clear_error_or_safe_code() {
    let cases = catalogue();
    assert!(cases.len() >= 30, "{} cases", cases.len());
    let start = Clock::start();
    // Each case derives and checks a robot of its own: on every core (the test's unoptimized
    // build would otherwise leave the others idle for seconds).
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let chunk = cases.len().div_ceil(threads);
    let failures: Vec<String> = std::thread::scope(|s| {
        let workers: Vec<_> = cases
            .chunks(chunk)
            .map(|part| {
                s.spawn(move || {
                    part.iter()
                        .filter_map(|(name, text, expect)| run(name, text, expect).err())
                        .collect::<Vec<String>>()
                })
            })
            .collect();
        workers
            .into_iter()
            .flat_map(|w| w.join().expect("a catalogue worker"))
            .collect()
    });
    // Long messages are failures in themselves; show their start only.
    let shown: Vec<String> = failures
        .iter()
        .map(|f| f.chars().take(400).collect())
        .collect();
    assert!(
        failures.is_empty(),
        "{} of {} cases failed:\n{}",
        failures.len(),
        cases.len(),
        shown.join("\n")
    );
    assert!(
        start.elapsed() < Duration::from_secs(30),
        "{:?}",
        start.elapsed()
    );
}

#[test]
fn the_safety_check_catches_breakouts() {
    let clean = "/// a `pwned` name\nconst A: &str = \"pwned\";\n";
    assert!(check_safe_source("clean", clean).is_ok());
    for broken in [
        "// name\npub fn pwned() {}\n",
        "/* name */ pub fn pwned() {} /* */\n",
        "const A: &str = \"\"; pub fn pwned() {}\n",
        "const A: &str = \"x\";\nconst pwned: u8 = 0;\n",
    ] {
        assert!(check_safe_source("broken", broken).is_err(), "{broken}");
    }
}

#[test]
fn hostile_names_stay_data_with_symbolic_parameters() {
    // Symbolic parameters put link and joint names into field documentation.
    let source = eomgen::Builder::from_urdf_str(&fixture("names.urdf"), "names.urdf")
        .symbolic(eomgen::SymbolicParams::All)
        .generate()
        .unwrap();
    check_safe_source("names_symbolic", &source).unwrap();
    // Identification puts them into parameter names, base-parameter formulas and constants.
    let source = eomgen::Builder::from_urdf_str(&fixture("names.urdf"), "names.urdf")
        .symbolic(eomgen::SymbolicParams::All)
        .friction(true)
        .regressor()
        .generate()
        .unwrap();
    check_safe_source("names_regressor", &source).unwrap();
}

#[test]
fn a_robot_called_t_does_not_take_the_type_parameter_name() {
    // `pub struct T<T = f64>` would not compile.
    let urdf = arm("", link("tip")).replace("name=\"r\"", "name=\"t\"");
    let source = eomgen::Builder::from_urdf_str(&urdf, "t.urdf")
        .generate()
        .unwrap();
    assert!(source.contains("pub struct TRobot<T = f64>"));
    let err = eomgen::Builder::from_urdf_str(&urdf, "t.urdf")
        .type_name("T")
        .generate()
        .unwrap_err();
    assert!(matches!(err, eomgen::Error::InvalidName { .. }), "{err}");
}

#[test]
fn case_names_are_unique() {
    let mut names: Vec<&str> = catalogue().iter().map(|c| c.0).collect();
    names.sort_unstable();
    let before = names.len();
    names.dedup();
    assert_eq!(before, names.len());
}

/// Hostile names stay data: each appears verbatim in the `name()` of its link (as a string
/// literal), while the identifiers are sanitized and distinct.
#[test]
fn hostile_names_survive_as_data() {
    let source = eomgen::Builder::from_urdf_str(&fixture("names.urdf"), "names.urdf")
        .generate()
        .unwrap();
    let file = syn::parse_file(&source).unwrap();
    let mut literals = Vec::new();
    let mut stack: Vec<TokenTree> = quote::quote!(#file).into_iter().collect();
    while let Some(t) = stack.pop() {
        match t {
            TokenTree::Group(g) => stack.extend(g.stream()),
            TokenTree::Literal(l) => {
                if let Ok(syn::Lit::Str(s)) = syn::parse_str::<syn::Lit>(&l.to_string()) {
                    literals.push(s.value());
                }
            }
            _ => {}
        }
    }
    let model = eomgen::Builder::from_urdf_str(&fixture("names.urdf"), "names.urdf")
        .model()
        .unwrap();
    for frame in &model.frames {
        assert!(
            literals.contains(&frame.name),
            "link name {:?} is not a string literal of the output",
            frame.name
        );
    }
    for joint in &model.joints {
        assert!(
            literals.contains(&joint.name),
            "joint name {:?} is not a string literal of the output",
            joint.name
        );
    }
}
