//! `eomgen show --derivatives`: d tau / d q printed for small robots in every format, checked
//! against central differences of `eomgen eval`, and refused in one line for large ones.

use crate::support;

use support::{eomgen, robot, stdout_of};

fn show(name: &str, extra: &[&str]) -> String {
    let urdf = robot(name);
    let mut args = vec!["show", urdf.to_str().unwrap(), "--derivatives"];
    args.extend(extra);
    stdout_of(&args)
}

/// The inverse dynamics `tau` that `eomgen eval` prints at `q` (zero velocity and acceleration).
fn tau(q: [f64; 2]) -> [f64; 2] {
    let urdf = robot("double_pendulum");
    let q = format!("{},{}", q[0], q[1]);
    let out = eomgen(&["eval", urdf.to_str().unwrap(), "--q", &q]);
    let text = String::from_utf8(out.stdout).unwrap();
    let line = text
        .lines()
        .find(|l| l.starts_with("inverse dynamics tau"))
        .expect("tau line");
    let list = line.rsplit_once('[').unwrap().1.trim_end_matches(']');
    let v: Vec<f64> = list.split(", ").map(|x| x.parse().unwrap()).collect();
    [v[0], v[1]]
}

#[test]
fn double_pendulum_entries_in_every_format() {
    let text = show("double_pendulum", &[]);
    for name in ["dtau1/dq1", "dtau1/dq2", "dtau2/dq1", "dtau2/dq2"] {
        assert!(text.contains(&format!("  {name} = ")), "{name}:\n{text}");
    }
    assert!(text.contains("Derivatives of inverse dynamics d tau / d q"));
    assert!(
        !text.contains("Mass matrix"),
        "only d tau / d q by default:\n{text}"
    );
    let latex = show("double_pendulum", &["--format", "latex"]);
    assert!(
        latex.contains("\\partial\\tau_{1}/\\partial q_{2} &= "),
        "{latex}"
    );
    let markdown = show("double_pendulum", &["--format", "markdown"]);
    assert!(markdown.contains("$$"), "{markdown}");
    let program = show("double_pendulum", &["--form", "program"]);
    assert!(program.contains("dtau2/dq2 = "), "{program}");
    let both = show("double_pendulum", &["--term", "M"]);
    assert!(
        both.contains("M11 = ") && both.contains("dtau1/dq1 = "),
        "{both}"
    );
}

/// `dtau2/dq1` of the double pendulum is `a*c12 + b*s12` (gravity alone): its printed
/// coefficients agree with central differences of the inverse dynamics `eval` prints.
#[test]
fn printed_entry_matches_finite_differences() {
    let text = show("double_pendulum", &["--entry", "2,1", "--digits", "0"]);
    let line = text
        .lines()
        .find(|l| l.trim_start().starts_with("dtau2/dq1 = "))
        .expect("the entry");
    let formula = line.split_once(" = ").unwrap().1.replace(" - ", " + -");
    let mut a = 0.0;
    let mut b = 0.0;
    for term in formula.split(" + ") {
        let (k, f) = term.split_once('*').expect("coefficient*function");
        let k: f64 = k.parse().unwrap();
        match f {
            "c12" => a += k,
            "s12" => b += k,
            other => panic!("unexpected factor {other} in {formula}"),
        }
    }
    let h = 1e-6;
    for q in [[0.3_f64, 0.5], [-1.2, 2.0]] {
        let printed = a * (q[0] + q[1]).cos() + b * (q[0] + q[1]).sin();
        let (plus, minus) = (tau([q[0] + h, q[1]]), tau([q[0] - h, q[1]]));
        let numeric = (plus[1] - minus[1]) / (2.0 * h);
        assert!(
            (printed - numeric).abs() < 1e-6,
            "{printed} vs {numeric} at {q:?}"
        );
    }
}

#[test]
fn six_joint_arms_print_and_the_panda_is_refused_in_one_line() {
    let ur5 = show("ur5", &["--form", "program"]);
    assert!(ur5.contains("dtau6/dq5 = "), "{ur5}");
    let urdf = robot("panda");
    let out = eomgen(&["show", urdf.to_str().unwrap(), "--derivatives"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("panda.urdf: d tau / d q is too large to print")
            && err.contains("eomgen generate --derivatives"),
        "{err}"
    );
}
